"""Composed interface law: contract, purity, open/closed points, consistent tangent, history."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rough_contact.interface.contract import ConvergenceError, LawResult
from rough_contact.interface.friction import IsotropicSlipHardening, OrthotropicSlipHardening
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.state import InterfaceState, StatePair
from rough_contact.interface.tangential import TangentialStiffness

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared stand-in laws
from law_test_helpers import (ExponentialNormal, QuadraticNormal,  # noqa: E402
                              fd_check, random_state, trial_ratio)

ORTHO = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (275.0, 100.0), potential_axes=(0.125, 0.2))
ISO = IsotropicSlipHardening(0.4, 0.5, 275.0)
TS = TangentialStiffness((0.7, 1.0))


def test_contract_and_purity():
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    rng = np.random.default_rng(0)
    n = 200
    st = random_state(rng, n)
    before = st.copy()
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n), rng.normal(size=(n, 2)) * 3e-4])
    r = law.evaluate(jump, st)
    assert isinstance(r, LawResult)
    r.check(n)
    assert r.traction.shape == (n, 3) and r.tangent.shape == (n, 3, 3)
    for arr in (r.dissipation, r.area_fraction, r.contact, r.slipping, r.pressure):
        assert arr.shape == (n,)
    p, k, a = ExponentialNormal().evaluate(1e-3 + jump[:, 0])
    np.testing.assert_allclose(r.traction[:, 0], -p, rtol=1e-15)
    np.testing.assert_allclose(r.tangent[:, 0, 0], k, rtol=1e-15)
    np.testing.assert_allclose(r.area_fraction, a)
    assert np.all(r.tangent[:, 0, 1:] == 0.0)
    assert r.contact.all() and 20 < r.slipping.sum() < n - 20
    for name in ("plastic_slip", "accumulated_slip", "slip_path"):
        np.testing.assert_array_equal(getattr(st, name), getattr(before, name))  # not mutated
    # the trial state carries exactly the increments
    dsp = r.state.plastic_slip - st.plastic_slip
    np.testing.assert_allclose(r.dissipation, np.einsum("ij,ij->i", r.traction[:, 1:], dsp), rtol=1e-12)
    assert np.all(r.dissipation >= 0) and np.all(r.dissipation[~r.slipping] == 0)
    np.testing.assert_allclose(r.state.accumulated_slip - st.accumulated_slip, np.abs(dsp), rtol=1e-12)
    np.testing.assert_allclose(r.state.slip_path - st.slip_path, np.hypot(*dsp.T), rtol=1e-12)
    # evaluating twice gives the same answer (pure)
    r2 = law.evaluate(jump, st)
    np.testing.assert_array_equal(r.traction, r2.traction)


def test_frictionless_law():
    law = InterfaceLaw(QuadraticNormal(), h0=1e-3)
    jump = np.array([[0.0, 1e-3, -2e-3], [2e-3, 0.0, 0.0], [-5e-4, 3.0, 4.0]])
    st = law.initial_state(3)
    r = law.evaluate(jump, st)
    assert np.all(r.traction[:, 1:] == 0) and np.all(r.tangent[:, 1:, :] == 0)
    np.testing.assert_allclose(r.traction[:, 0], [-1e6 * 1e-6, 0.0, -1e6 * 1.5e-3**2])
    np.testing.assert_array_equal(r.contact, [True, False, True])
    assert not r.slipping.any() and np.all(r.dissipation == 0)


def test_open_points_release_elastic_slip_and_keep_history():
    law = InterfaceLaw(QuadraticNormal(), TS, ORTHO, h0=1e-3)
    pair = StatePair(law.initial_state(1))
    # close and slide far: plastic slip builds up
    for s in np.linspace(0, 2e-3, 21)[1:]:
        r = law.evaluate(np.array([[0.0, s, 0.5 * s]]), pair.committed)
        pair.update(r)
        pair.commit()
    sp = pair.committed.plastic_slip.copy()
    kap = pair.committed.accumulated_slip.copy()
    assert r.slipping[0] and np.all(np.abs(sp) > 0)
    # open the gap: no traction, no tangent, history untouched
    r = law.evaluate(np.array([[1.5e-3, 5e-3, 0.0]]), pair.committed)
    assert not r.contact[0] and np.all(r.traction == 0) and np.all(r.tangent == 0)
    np.testing.assert_array_equal(r.state.plastic_slip, sp)
    np.testing.assert_array_equal(r.state.accumulated_slip, kap)
    # close again at a new slip: t_T = K_T (s - s_p) with the kept s_p (elastic part released)
    s_new = sp[0] + np.array([1e-6, -1e-6])
    r = law.evaluate(np.array([[0.0, *s_new]]), pair.committed)
    p, k, _ = QuadraticNormal().evaluate(np.array([1e-3]))
    assert not r.slipping[0]
    np.testing.assert_allclose(r.traction[0, 1:], np.array(TS.kt_over_kn) * k[0] * (s_new - sp[0]), rtol=1e-9)


def test_near_zero_pressure_is_finite():
    normal = QuadraticNormal()
    law = InterfaceLaw(normal, TS, ORTHO, h0=normal.h_max)
    g = -np.array([0.0, 1e-300, 1e-160, 1e-100, 1e-20, 1e-12, 1e-8])  # p from 0 to 1e-10 MPa
    jump = np.column_stack([g, np.full(g.size, 1e-3), np.full(g.size, -2e-3)])
    r = law.evaluate(jump, law.initial_state(g.size))
    assert np.isfinite(r.traction).all() and np.isfinite(r.tangent).all()
    assert not r.contact[0] and r.contact[-1]
    mu, _ = ORTHO.coefficients(r.state.accumulated_slip)
    f = np.hypot(r.traction[:, 1] / mu[:, 0], r.traction[:, 2] / mu[:, 1]) - r.pressure
    assert np.all(f <= 1e-12 * r.pressure + 1e-300)


def _away_from_switch(law, jump, st, band=1e-4):
    """Points whose trial slip function is not within `band` (relative) of the switch."""
    return np.abs(trial_ratio(law, jump, st, 0.0) - 1) > band


@pytest.mark.parametrize("friction", [ORTHO, ISO], ids=["ortho", "iso"])
@pytest.mark.parametrize("ts", [TS, TangentialStiffness((0.7, 0.7))], ids=["kt_aniso", "kt_iso"])
@pytest.mark.parametrize("regime", ["stick", "slip", "mixed"])
def test_consistent_tangent_fd(friction, ts, regime):
    law = InterfaceLaw(ExponentialNormal(), ts, friction, h0=1e-3)
    rng = np.random.default_rng(42)
    n = 600
    st = random_state(rng, n)
    scale = {"stick": 1e-6, "slip": 3e-3, "mixed": 3e-4}[regime]
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * scale])
    keep = _away_from_switch(law, jump, st)
    r = fd_check(law, jump, st, keep)
    frac = r.slipping[keep].mean()
    assert {"stick": frac == 0, "slip": frac > 0.97, "mixed": 0.1 < frac < 0.9}[regime], frac
    # coupling to the normal jump is present (dt_T/dg != 0) where there is traction
    assert np.abs(r.tangent[keep, 1:, 0]).max() > 0


@pytest.fixture(scope="module")
def real_normal():
    from rough_contact.interface.normal import NormalLaw

    def model(h):  # any smooth model: the real interpolating NormalLaw is what is tested
        p = 5.0 * np.exp(-h / 1e-3) * (1 + 0.3 * np.sin(h / 7e-4))
        k = 5.0 * np.exp(-h / 1e-3) * ((1 + 0.3 * np.sin(h / 7e-4)) / 1e-3 - 0.3 * np.cos(h / 7e-4) / 7e-4)
        return p, k, np.full_like(h, 0.1) * np.exp(-h / 1e-3)
    return NormalLaw.from_model(model, (-1e-3, 1e-2), rtol=1e-6)


@pytest.mark.parametrize("friction", [ORTHO, ISO], ids=["ortho", "iso"])
def test_consistent_tangent_fd_with_real_normal_law(real_normal, friction):
    law = InterfaceLaw(real_normal, TS, friction).with_seating(2.0)
    assert real_normal.evaluate(np.array([law.h0]))[0][0] == pytest.approx(2.0, rel=1e-10)
    rng = np.random.default_rng(1)
    kn = real_normal.knots
    i = rng.integers(0, np.searchsorted(kn, 3e-3), 400)
    h = 0.5 * (kn[i] + kn[i + 1])  # interval midpoints: dk/dh jumps at knots
    st = random_state(rng, h.size)
    jump = np.column_stack([h - law.h0, st.plastic_slip + rng.normal(size=(h.size, 2)) * 3e-4])
    keep = _away_from_switch(law, jump, st)
    r = fd_check(law, jump, st, keep, rel_step=1e-9 / 3e-3)
    assert 0.1 < r.slipping[keep].mean() < 0.9


def test_material_point_through_law():
    """Normal load then tangential sliding: |t_T| never exceeds the ellipse, hardening grows."""
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO).with_seating(1.0)
    pair = StatePair(law.initial_state(1))
    total = 0.0
    for s in np.linspace(0, 5e-3, 51)[1:]:
        r = law.evaluate(np.array([[-2e-4, s, s]]), pair.committed)
        pair.update(r)
        pair.commit()
        total += r.dissipation[0]
        mu, _ = ORTHO.coefficients(pair.committed.accumulated_slip)
        assert np.hypot(*(r.traction[0, 1:] / mu[0])) <= r.pressure[0] * (1 + 1e-12)
    assert pair.dissipated[0] == pytest.approx(total, rel=1e-12)
    assert total > 0


@pytest.mark.parametrize("friction", [ORTHO, ISO, None], ids=["ortho", "iso", "none"])
def test_empty_rank(friction):
    law = InterfaceLaw(ExponentialNormal(), TS, friction, h0=1e-3)
    r = law.evaluate(np.zeros((0, 3)), law.initial_state(0))
    assert r.traction.shape == (0, 3) and r.tangent.shape == (0, 3, 3) and len(r.state) == 0


def _result(state, dissipation):
    """A LawResult carrying a given trial state and dissipation increment (other fields zero)."""
    n = len(state)
    return LawResult(np.zeros((n, 3)), np.zeros((n, 3, 3)), state, np.asarray(dissipation, float),
                     np.zeros(n), np.zeros(n, bool), np.zeros(n, bool))


def test_state_pair_commit_revert():
    pair = StatePair(InterfaceState.zeros(3))
    trial = pair.trial.copy()
    trial.plastic_slip[:] = 1.0
    pair.update(_result(trial, [1.0, 2.0, 3.0]))
    pair.revert()  # drops the trial state AND its dissipation
    assert np.all(pair.trial.plastic_slip == 0)
    pair.commit()
    np.testing.assert_array_equal(pair.dissipated, 0.0)
    assert np.all(pair.committed.plastic_slip == 0)
    pair.update(_result(trial, [1.0, 2.0, 3.0]))
    pair.update(_result(trial, [0.5, 0.0, 0.25]))  # a line search: the last evaluation counts
    np.testing.assert_array_equal(pair.dissipated, 0.0)  # nothing before commit
    pair.commit()
    np.testing.assert_array_equal(pair.dissipated, [0.5, 0.0, 0.25])
    assert np.all(pair.committed.plastic_slip == 1.0)
    pair.committed.plastic_slip[0] = 7.0  # commit made a copy
    assert trial.plastic_slip[0, 0] == 1.0
    pair.commit()  # a second commit without a new evaluation adds nothing
    np.testing.assert_array_equal(pair.dissipated, [0.5, 0.0, 0.25])
    pair.update(_result(trial, [1.0, 1.0, 1.0]))
    pair.commit()
    np.testing.assert_array_equal(pair.dissipated, [1.5, 1.0, 1.25])
    with pytest.raises(ValueError, match="points"):
        pair.update(_result(InterfaceState.zeros(4), np.zeros(4)))
    with pytest.raises(ValueError, match="LawResult"):
        pair.update(InterfaceState.zeros(3))
    with pytest.raises(ValueError, match="plastic_slip"):
        InterfaceState(np.zeros(3), np.zeros((3, 2)), np.zeros(3))
    with pytest.raises(ValueError, match="slip_path"):
        InterfaceState(np.zeros((3, 2)), np.zeros((3, 2)), np.zeros(2))


def test_bad_law_input():
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    st = law.initial_state(2)
    with pytest.raises(ValueError, match="jump"):
        law.evaluate(np.zeros((2, 2)), st)
    with pytest.raises(ConvergenceError, match=r"jump is not finite at 1 of 2 points \(first index 0\)"):
        law.evaluate(np.array([[0.0, np.nan, 0.0], [0, 0, 0]]), st)
    with pytest.raises(ValueError, match="committed"):
        law.evaluate(np.zeros((3, 3)), st)
    with pytest.raises(ValueError, match="h0"):
        InterfaceLaw(ExponentialNormal(), TS, ORTHO).evaluate(np.zeros((2, 3)), st)
    with pytest.raises(ValueError, match="h0"):
        InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=np.inf)
    with pytest.raises(ValueError, match="tangential"):
        InterfaceLaw(ExponentialNormal(), None, ORTHO, h0=0.0)
    with pytest.raises(ValueError, match="friction"):
        InterfaceLaw(ExponentialNormal(), TS, "coulomb", h0=0.0)
    with pytest.raises(ValueError, match="normal"):
        InterfaceLaw(object(), TS, ORTHO, h0=0.0)
    with pytest.raises(ValueError, match="p_seat"):
        law.with_seating(-1.0)

    class NoInverse:  # a normal law without p -> h: fine with h0, not with with_seating
        evaluate = ExponentialNormal().evaluate

    assert InterfaceLaw(NoInverse(), TS, ORTHO, h0=1e-3).evaluate(np.zeros((2, 3)), st).contact.all()
    with pytest.raises(ValueError, match="separation_for_pressure"):
        InterfaceLaw(NoInverse(), TS, ORTHO).with_seating(1.0)
    with pytest.raises(ValueError, match="n_pts"):
        law.initial_state(-1)
