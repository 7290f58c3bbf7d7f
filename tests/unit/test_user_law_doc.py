"""The worked example of docs/writing_a_law.md: extracted from the page, run and checked.

Checks against things the example did not write itself: the contract (LawResult.check,
InterfaceLawProtocol), central finite differences of the traction, Coulomb's cone and Coulomb's
work (steady sliding dissipates mu p per unit slip), purity and the failure types.
"""

from __future__ import annotations

import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from rough_contact.interface.contract import (ConvergenceError, InterfaceLawProtocol,
                                              LawResult)
from rough_contact.interface.state import InterfaceState, StatePair

DOC = Path(__file__).resolve().parents[2] / "docs" / "writing_a_law.md"


def load_example() -> types.ModuleType:
    """The page's single ```python block, executed as a module (dataclasses need one)."""
    blocks = re.findall(r"^```python\n(.*?)^```", DOC.read_text(encoding="utf-8"),
                        flags=re.S | re.M)
    assert len(blocks) == 1, f"{DOC.name} must hold exactly one python block, has {len(blocks)}"
    mod = types.ModuleType("writing_a_law_example")
    mod.__file__ = str(DOC)
    sys.modules[mod.__name__] = mod
    exec(compile(blocks[0], str(DOC), "exec"), mod.__dict__)
    return mod


@pytest.fixture(scope="module")
def example():
    return load_example()


P0, L, MU, C, G_OPEN = 1.0, 1e-3, 0.4, 0.7, 2e-3


@pytest.fixture(scope="module")
def law(example):
    return example.ExponentialCoulombLaw(p0=P0, length=L, mu=MU, kt_over_kn=C, g_open=G_OPEN)


def random_state(rng, n, scale=1e-4):
    return InterfaceState(rng.normal(size=(n, 2)) * scale, rng.uniform(0, 5 * scale, (n, 2)),
                          rng.uniform(0, 5 * scale, n))


def closed_jumps(rng, st, slip_scale):
    """Jumps in compression (closure 0.2-5 decay lengths) around the committed plastic slip."""
    n = len(st)
    g = G_OPEN - L * rng.uniform(0.2, 5.0, n)
    return np.column_stack([g, st.plastic_slip + rng.normal(size=(n, 2)) * slip_scale])


def away_from_switch(law, jump, st, band=1e-4):
    """Points whose trial |t_T|/(mu p) is not within `band` of 1 (the stick/slip switch)."""
    p, k, _ = law.normal(jump[:, 0])
    tau = C * k * np.hypot(*(jump[:, 1:] - st.plastic_slip).T)
    return np.abs(tau / (MU * p) - 1.0) > band


def test_contract_and_values(law):
    assert isinstance(law, InterfaceLawProtocol)
    rng = np.random.default_rng(0)
    n = 300
    st = random_state(rng, n)
    jump = closed_jumps(rng, st, 3e-4)
    jump[:50, 0] = G_OPEN + rng.uniform(1e-6, 1e-3, 50)  # open points
    before = st.copy()
    r = law.evaluate(jump, st)
    assert isinstance(r, LawResult)
    r.check(n)
    for name in ("plastic_slip", "accumulated_slip", "slip_path"):  # pure: nothing written
        np.testing.assert_array_equal(getattr(st, name), getattr(before, name))
    # the normal law as the page states it, written independently here
    x = (G_OPEN - jump[50:, 0]) / L
    np.testing.assert_allclose(r.pressure[50:], P0 * (np.exp(x) - 1 - x), rtol=1e-9)
    np.testing.assert_allclose(r.tangent[50:, 0, 0], P0 / L * (np.exp(x) - 1), rtol=1e-12)
    # open points: no traction, no tangent, history unchanged, not slipping
    assert not r.contact[:50].any() and not r.slipping[:50].any()
    assert np.all(r.traction[:50] == 0) and np.all(r.tangent[:50] == 0)
    np.testing.assert_array_equal(r.state.plastic_slip[:50], st.plastic_slip[:50])
    assert r.contact[50:].all() and 30 < r.slipping.sum() < n - 80
    # Coulomb's cone: f = |t_T| - mu p <= 0 everywhere, = 0 on slip
    f = np.hypot(r.traction[:, 1], r.traction[:, 2]) - MU * r.pressure
    assert np.all(f <= 1e-12 * MU * r.pressure)
    np.testing.assert_allclose(f[r.slipping], 0.0, atol=1e-12 * MU * r.pressure.max())
    # dissipation increment = t_T . Delta s_p >= 0, zero where nothing slips
    dsp = r.state.plastic_slip - st.plastic_slip
    np.testing.assert_allclose(r.dissipation, np.einsum("ij,ij->i", r.traction[:, 1:], dsp),
                               rtol=1e-12, atol=1e-30)
    assert np.all(r.dissipation >= 0) and np.all(r.dissipation[~r.slipping] == 0)
    assert np.all(r.dissipation[r.slipping] > 0)
    # slip is collinear with the traction (radial return) and the elastic part carries it
    tt = r.traction[:, 1:]
    cross = tt[:, 0] * dsp[:, 1] - tt[:, 1] * dsp[:, 0]
    assert np.all(np.abs(cross) <= 1e-12 * np.hypot(*tt.T) * np.hypot(*dsp.T))
    kt = C * r.tangent[:, 0, 0]
    e_after = jump[:, 1:] - r.state.plastic_slip
    np.testing.assert_allclose(tt[50:], kt[50:, None] * e_after[50:], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(r.state.slip_path - st.slip_path, np.hypot(*dsp.T), rtol=1e-12,
                               atol=1e-30)
    np.testing.assert_allclose(r.state.accumulated_slip - st.accumulated_slip, np.abs(dsp),
                               rtol=1e-12, atol=1e-30)
    assert np.all((r.area_fraction >= 0) & (r.area_fraction <= 1))
    # re-evaluating from the trial state at the same jump is elastic (nothing more slips)
    again = law.evaluate(jump, r.state)
    assert not again.slipping.any()
    np.testing.assert_allclose(again.traction, r.traction, rtol=1e-10, atol=1e-14)


@pytest.mark.parametrize("regime", ["stick", "slip", "mixed"])
def test_tangent_against_central_differences(law, regime):
    rng = np.random.default_rng({"stick": 1, "slip": 2, "mixed": 3}[regime])
    n = 400
    st = random_state(rng, n)
    scale = {"stick": 1e-7, "slip": 1e-2, "mixed": 2e-4}[regime]
    jump = closed_jumps(rng, st, scale)
    keep = away_from_switch(law, jump, st)
    r = law.evaluate(jump, st)
    frac = r.slipping[keep].mean()
    assert {"stick": frac == 0, "slip": frac > 0.97, "mixed": 0.2 < frac < 0.8}[regime], frac
    D = r.tangent
    worst = 0.0
    for j in range(3):
        h = 1e-7 * max(np.abs(jump[:, j]).max(), L)
        jp, jm = jump.copy(), jump.copy()
        jp[:, j] += h
        jm[:, j] -= h
        fd = (law.evaluate(jp, st).traction - law.evaluate(jm, st).traction) / (2 * h)
        err = np.abs(fd - D[:, :, j]).max(axis=1) / np.abs(D).max(axis=(1, 2))
        worst = max(worst, err[keep].max())
    assert worst <= 1e-6, worst
    # the normal coupling is there: dt_T/dg != 0 (through kT(g) in stick, mu p(g) in slip)
    assert np.all(np.abs(D[keep, 1:, 0]).max(axis=1) > 0)


def test_steady_sliding_dissipates_coulomb_work(law):
    """At constant g, once sliding, every slip increment ds dissipates mu p ds (Coulomb)."""
    g = G_OPEN - 2 * L
    p = P0 * (np.exp(2.0) - 3.0)
    pair = StatePair(law.initial_state(1))
    direction = np.array([0.6, 0.8])
    s_values = np.linspace(0, 2e-3, 201)[1:]
    slipped = []
    for s in s_values:
        r = law.evaluate(np.array([[g, *(s * direction)]]), pair.committed)
        pair.update(r)
        pair.commit()
        slipped.append(r.slipping[0])
    slipped = np.array(slipped)
    assert not slipped[0] and slipped[-1]
    first = int(np.argmax(slipped))
    # total slip beyond the stick limit, all plastic: s_end - s_stick with s_stick = mu p/kT
    kt = C * P0 / L * (np.exp(2.0) - 1.0)
    work = MU * p * (s_values[-1] - MU * p / kt)
    assert pair.dissipated[0] == pytest.approx(work, rel=1e-10)
    np.testing.assert_allclose(pair.committed.plastic_slip[0],
                               (s_values[-1] - MU * p / kt) * direction, rtol=1e-10)
    assert first > 0


def test_opening_keeps_history_and_releases_traction(law):
    pair = StatePair(law.initial_state(1))
    for s in np.linspace(0, 1e-3, 11)[1:]:
        pair.update(law.evaluate(np.array([[G_OPEN - L, s, 0.0]]), pair.committed))
        pair.commit()
    sp = pair.committed.plastic_slip.copy()
    assert sp[0, 0] > 0
    r = law.evaluate(np.array([[G_OPEN + 1e-4, 5e-3, 1e-3]]), pair.committed)
    assert not r.contact[0] and np.all(r.traction == 0) and np.all(r.tangent == 0)
    np.testing.assert_array_equal(r.state.plastic_slip, sp)
    assert r.dissipation[0] == 0.0


def test_empty_rank_and_failures(law, example):
    r = law.evaluate(np.zeros((0, 3)), law.initial_state(0))
    r.check(0)
    st = law.initial_state(2)
    with pytest.raises(ConvergenceError, match=r"not finite at 1 of 2 points \(first index 1\)"):
        law.evaluate(np.array([[0.0, 0.0, 0.0], [np.inf, 0.0, 0.0]]), st)
    with pytest.raises(ConvergenceError, match="closure"):
        law.evaluate(np.array([[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]), st)  # 1000 decay lengths
    with pytest.raises(ValueError, match="shape"):
        law.evaluate(np.zeros((2, 2)), st)
    with pytest.raises(ValueError, match="committed"):
        law.evaluate(np.zeros((3, 3)), st)
    with pytest.raises(ValueError, match="InterfaceState"):
        law.evaluate(np.zeros((2, 3)), object())
    for kwargs, name in ((dict(p0=0.0), "p0"), (dict(length=-1.0), "length"),
                         (dict(mu=np.nan), "mu"), (dict(kt_over_kn=0.0), "kt_over_kn"),
                         (dict(g_open=-1e-3), "g_open")):
        args = dict(p0=P0, length=L, mu=MU)
        args.update(kwargs)
        with pytest.raises(ValueError, match=name):
            example.ExponentialCoulombLaw(**args)
