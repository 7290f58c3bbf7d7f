"""Issue 23 item 3: the normal history h_min in the interface law (commit, revert, checkpoint,
consistent tangent, normal dissipation).

The interface machinery is checked with a closed-form irreversible law (tests/memory_law.py,
shared with the FE tests; not the table): loading p_L(h) = c exp(-h/lam); unloading from h_min along
p = p_L(h_min) (1 - (h - h_min)/delta)^(3/2) (zero beyond h_min + delta). Its dissipation has
the closed form D(h_min) = int p_L - int p_u = c exp(-h_min/lam) (lam - 2 delta/5), and the
loop integral of p dh over a cycle is computed here by an independent trapezoid rule along
the path.
"""
from __future__ import annotations

import pickle
import sys
from pathlib import Path

import numpy as np
import pytest

from rough_contact.interface.history import HistoryNormalLaw, HistoryNormalLawProtocol
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.normal import NormalLaw
from rough_contact.interface.state import (HistoryInterfaceState, InterfaceHistory,
                                           InterfaceState, StatePair)
from rough_contact.interface.friction import IsotropicSlipHardening
from rough_contact.interface.tangential import TangentialStiffness
from rough_contact.surface import SpectralMoments

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: the shared stand-in law
from memory_law import C, DELTA, LAM, MemoryLaw as ClosedFormHistoryLaw  # noqa: E402


def _law(friction=False):
    normal = ClosedFormHistoryLaw()
    if not friction:
        return InterfaceLaw(normal=normal, h0=0.0)
    return InterfaceLaw(normal=normal, tangential=TangentialStiffness((0.7, 1.0)),
                        friction=IsotropicSlipHardening(0.4, 0.5, 275.0), h0=0.0)


def test_protocol_and_state_type():
    law = _law()
    assert isinstance(law.normal, HistoryNormalLawProtocol) and law.has_normal_memory
    st = law.initial_state(4)
    assert isinstance(st, HistoryInterfaceState) and np.all(np.isinf(st.h_min))
    with pytest.raises(ValueError, match="HistoryInterfaceState"):
        law.evaluate(np.zeros((4, 3)), InterfaceState.zeros(4))
    with pytest.raises(ValueError, match="h_min"):
        HistoryInterfaceState(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2), np.zeros(3))


def test_load_unload_reload_path_commit_and_loop_dissipation():
    """Load to g = -2 mm/1000, unload to +1e-3, reload to -2e-3, load further to -3e-3:
    h_min follows the committed minimum; the unloading/reloading branch is one curve; the
    summed normal dissipation equals both the closed form D(h_min) and the loop integral of
    p dh (independent trapezoid along the path plus the recoverable energy)."""
    law = _law()
    pair = StatePair(law.initial_state(1))
    g_path = np.concatenate([np.linspace(0.0, -2e-3, 201), np.linspace(-2e-3, 1e-3, 301)[1:],
                             np.linspace(1e-3, -2e-3, 301)[1:], np.linspace(-2e-3, -3e-3, 101)[1:]])
    P = []
    for g in g_path:
        res = law.evaluate(np.array([[g, 0.0, 0.0]]), pair.committed)
        pair.update(res)
        pair.commit()
        P.append(res.pressure[0])
    P = np.array(P)
    assert pair.committed.h_min[0] == pytest.approx(-3e-3, abs=1e-15)
    # unloading and reloading coincide (same g on both branches)
    un = P[201:501]
    re = P[501:801][::-1]
    np.testing.assert_allclose(un[:-1], re[1:], rtol=1e-12)   # the two g grids differ by round-off
    # dissipation: closed form ...
    D = law.normal_dissipated(pair.committed)[0]
    assert pair.normal_dissipated[0] == pytest.approx(D, rel=1e-12)
    assert D == pytest.approx(C * np.exp(3e-3 / LAM) * (LAM - 0.4 * DELTA), rel=1e-12)
    # ... and the work put in minus the energy recoverable from the final state
    work = C * LAM - np.trapz(P, g_path)   # virgin approach from h = inf to 0, then the path
    x = np.linspace(0.0, DELTA, 20001)
    p_end = C * np.exp(3e-3 / LAM) * (1 - x / DELTA) ** 1.5
    recover = np.trapz(p_end, x)
    assert work - recover == pytest.approx(D, rel=2e-4)


@pytest.mark.parametrize("friction", [False, True])
def test_consistent_tangent_on_both_branches(friction):
    law = _law(friction)
    st = law.initial_state(3)
    st.h_min[:] = [-1e-3, -1e-3, -1e-3]
    st.plastic_slip[:] = 0.0
    jump = np.array([[-1.5e-3, 1e-5, -2e-5],      # loading (below h_min)
                     [-0.6e-3, 2e-6, 1e-6],       # unloading branch
                     [0.2e-3, 1e-6, 0.0]])        # unloading branch, far
    res = law.evaluate(jump, st)
    eps = 1e-9
    for c in range(3):
        dj = np.zeros_like(jump)
        dj[:, c] = eps
        tp = law.evaluate(jump + dj, st).traction
        tm = law.evaluate(jump - dj, st).traction
        fd = (tp - tm) / (2 * eps)
        np.testing.assert_allclose(res.tangent[:, :, c], fd, rtol=2e-5, atol=1e-6 * np.abs(fd).max())


def test_revert_drops_the_trial_h_min_and_checkpoint_roundtrip():
    law = _law()
    hist = InterfaceHistory(law.initial_state(2))
    res = law.evaluate(np.array([[-1e-3, 0, 0], [5e-3, 0, 0]]), hist.law.committed)
    hist.law.update(res)
    hist.commit()
    np.testing.assert_array_equal(hist.law.committed.h_min, [-1e-3, 5e-3])
    res = law.evaluate(np.array([[-2e-3, 0, 0], [-1e-3, 0, 0]]), hist.law.committed)
    assert res.normal_dissipation[0] > 0 and res.normal_dissipation[1] > 0
    hist.law.update(res)
    hist.revert()
    np.testing.assert_array_equal(hist.law.committed.h_min, [-1e-3, 5e-3])
    np.testing.assert_array_equal(hist.law.trial.h_min, [-1e-3, 5e-3])
    d_before = hist.law.normal_dissipated.copy()
    blob = pickle.dumps(hist.state())
    other = InterfaceHistory(law.initial_state(2))
    other.restore(pickle.loads(blob))
    np.testing.assert_array_equal(other.law.committed.h_min, [-1e-3, 5e-3])
    np.testing.assert_array_equal(other.law.normal_dissipated, d_before)
    assert isinstance(other.law.committed, HistoryInterfaceState)
    # a state written before the normal history existed restores with zero normal dissipation
    old = hist.state()
    del old["normal_dissipated"]
    other.restore(old)
    np.testing.assert_array_equal(other.law.normal_dissipated, 0.0)


S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)


def test_elastic_history_law_is_exactly_reversible():
    """Elastic population with memory: any history gives bit-for-bit the reversible law."""
    hist = HistoryNormalLaw.elastic(S1, 1.14e5, rtol=1e-3)
    rev = NormalLaw.elastic(S1, 1.14e5, rtol=1e-3)
    sig = S1.rq
    h = np.linspace(-0.3, 6.0, 400) * sig
    for hm in (-0.4 * sig, 0.5 * sig, 3 * sig, np.inf):
        a = hist.evaluate_history(h, np.full_like(h, hm), curvature=True)
        b = rev.evaluate(h, curvature=True)
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(hist.normal_dissipation(h), 0.0)
    law = InterfaceLaw(normal=hist, h0=0.0)
    st = law.initial_state(h.size)
    st.h_min[:] = -0.4 * sig
    r1 = law.evaluate(np.stack([h, 0 * h, 0 * h], 1), st)
    r0 = InterfaceLaw(normal=rev, h0=0.0).evaluate(np.stack([h, 0 * h, 0 * h], 1),
                                                   InterfaceState.zeros(h.size))
    np.testing.assert_array_equal(r1.traction, r0.traction)
    np.testing.assert_array_equal(r1.normal_dissipation, 0.0)


def _coarse_table():
    """A deliberately coarse elasto-plastic history table (a few hundred direct-sum points,
    strict=False): its mechanics do not depend on its accuracy."""
    from rough_contact.micro.asperity import AsperityMaterial
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0).resolve(S1)
    loading = NormalLaw.elasto_plastic(S1, mat, rtol=1e-2, n_quad=8)
    return HistoryNormalLaw.elasto_plastic(S1, mat, 1e-2, loading=loading, n_quad=8, n_t=16,
                                           n_zeta=8, n_rows=3, n_x=2)


@pytest.mark.slow    # ~5-15 s: a loading NormalLaw and a few hundred direct population sums
def test_table_mechanics_continuity_tangent_energy():
    """The tabulated law: p and A/A0 continuous at the reversal (the branch starts at the
    loading law's value exactly), k the exact derivative of p on the unloading branch (FD),
    unloading stiffer than loading at h_min, and D(h_min) = work of loading minus the energy
    recoverable on the branch, the latter integrated here by a trapezoid rule over
    evaluate_history (not the table's own Gauss sums)."""
    law = _coarse_table()
    assert not law.reversible and law.info["model_points"] > 0
    sig = S1.rq
    hms = np.array([-0.3, 0.5, 2.0, 4.0]) * sig
    p0, k0, a0 = law.loading.evaluate(hms)
    p, k, a = law.evaluate_history(hms, hms)
    np.testing.assert_array_equal(p, p0)          # h == h_min is the loading branch
    eps = 1e-9 * sig
    pu, ku, au = law.evaluate_history(hms + eps, hms)
    np.testing.assert_allclose(pu, p0, rtol=1e-6)
    np.testing.assert_allclose(au, a0, rtol=1e-6)
    assert np.all(ku > k0)
    # FD tangent on the branch
    h = hms[:, None] + np.array([0.05, 0.5, 1.5, 3.0]) * sig
    H = np.broadcast_to(hms[:, None], h.shape)
    _, k, _ = law.evaluate_history(h, H)
    d = 1e-6 * sig
    fd = (law.evaluate_history(h - d, H)[0] - law.evaluate_history(h + d, H)[0]) / (2 * d)
    np.testing.assert_allclose(k, fd, rtol=1e-5)
    # dissipation at the table's rows (where D is computed; between rows it is interpolated):
    # D = W_load - E_rec, each integrated independently here
    from rough_contact.interface.history import _row_h
    for hm in _row_h(np.arange(2) / law._n_m, law._hm0, law._span, law._beta):
        hh = np.linspace(hm, law.h_max + 2 * sig, 200001)
        W = np.trapz(law.loading.evaluate(hh)[0], hh)
        E = np.trapz(law.evaluate_history(hh, np.full_like(hh, hm))[0], hh)
        assert float(law.normal_dissipation(np.array([hm]))[0]) == pytest.approx(W - E, rel=1e-3)
    D = law.normal_dissipation(np.linspace(-0.4, 7.0, 300) * sig)
    assert np.all(D >= 0) and np.all(np.diff(D) <= 1e-15 * D.max())
