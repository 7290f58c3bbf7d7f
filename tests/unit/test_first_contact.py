"""SoftplusPenalty(first_contact="closure"): a point open at the last commit starts to stick
where it is at the end of the increment it closes in (no elastic predictor in that increment),
against hand-written values and central differences; the closed flag of InterfaceState."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from rough_contact.interface.enforcement import SemismoothNewton
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.interface.state import (HistoryInterfaceState, InterfaceState, keep_points,
                                           take_points)

KN, W, KT, MU = 1e4, 1e-3, 5e3, 0.3


def _fd(law, jump, committed, h=1e-9):
    D = np.zeros((jump.shape[0], 3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        D[:, :, j] = (law.evaluate(jump + e, committed).traction
                      - law.evaluate(jump - e, committed).traction) / (2 * h)
    return D


def _setup(rng, n):
    committed = InterfaceState(rng.uniform(-1, 1, (n, 2)) * 1e-6, np.zeros((n, 2)), np.zeros(n),
                               closed=rng.uniform(size=n) < 0.5)
    jump = np.column_stack([rng.uniform(-3e-3, -1e-4, n), rng.uniform(-1, 1, (n, 2)) * 1e-3])
    return committed, jump


@pytest.mark.parametrize("with_multipliers", [False, True])
def test_a_closing_point_has_no_elastic_predictor_and_the_others_are_unchanged(with_multipliers):
    rng = np.random.default_rng(3)
    n = 60
    committed, jump = _setup(rng, n)
    plain = SoftplusPenalty(KN, W, k_tangential=KT, friction=MU, first_contact="closure")
    default = SoftplusPenalty(KN, W, k_tangential=KT, friction=MU)
    lam = None
    if with_multipliers:
        # tangential multipliers inside the cone at some points, beyond it at others
        lam = np.column_stack([rng.uniform(0.5, 2.0, n), rng.uniform(-1, 1, (n, 2)) * 4.0])
        law, ref = plain.with_multipliers(lam), default.with_multipliers(lam)
    else:
        law, ref = plain, default
    res, old = law.evaluate(jump, committed), ref.evaluate(jump, committed)
    fresh = ~committed.closed
    assert fresh.any() and (~fresh).any()
    # points closed at the commit: exactly the default law
    np.testing.assert_array_equal(res.traction[~fresh], old.traction[~fresh])
    np.testing.assert_array_equal(res.tangent[~fresh], old.tangent[~fresh])
    np.testing.assert_array_equal(res.state.plastic_slip[~fresh], old.state.plastic_slip[~fresh])
    # closing points: tau = lambda_T (0 without multipliers), returned onto the cone if beyond
    p = -res.traction[:, 0]
    np.testing.assert_array_equal(p, -old.traction[:, 0])
    tau = np.zeros((n, 2)) if lam is None else lam[:, 1:].copy()
    norm = np.linalg.norm(tau, axis=1)
    scale = np.minimum(1.0, np.divide(MU * p, norm, out=np.ones(n), where=norm > 0))
    np.testing.assert_allclose(res.traction[fresh, 1:], (tau * scale[:, None])[fresh],
                               rtol=1e-12, atol=1e-15)
    # and they start from where they are: s_p = s, less the returned part
    ret = fresh & (scale < 1.0)
    np.testing.assert_allclose(res.state.plastic_slip[fresh & ~ret], jump[fresh & ~ret, 1:],
                               rtol=0, atol=0)
    if with_multipliers:
        assert ret.any() and (fresh & ~ret).any()
        m = tau[ret] / norm[ret, None]
        np.testing.assert_allclose(
            res.state.plastic_slip[ret],
            jump[ret, 1:] + ((norm[ret] - MU * p[ret]) / KT)[:, None] * m, rtol=1e-12)
    # the tangent is the derivative of this traction (no tangential stiffness where fresh)
    np.testing.assert_allclose(res.tangent, _fd(law, jump, committed), rtol=1e-5, atol=1e-3)
    assert np.all(res.tangent[fresh, 1:, 1:] == 0.0)


def test_the_point_sticks_from_its_closing_position_in_the_next_increment():
    law = SoftplusPenalty(KN, W, k_tangential=KT, friction=MU, first_contact="closure")
    st = law.initial_state(1)                  # virgin: open
    s1 = np.array([[-1e-3, 2e-6, -1e-6]])
    r1 = law.evaluate(s1, st)
    assert r1.state.closed[0] and not r1.slipping[0]
    np.testing.assert_array_equal(r1.traction[0, 1:], 0.0)
    s2 = s1 + np.array([[0.0, 3e-7, 1e-7]])
    r2 = law.evaluate(s2, r1.state)           # closed now: stick from s1
    np.testing.assert_allclose(r2.traction[0, 1:], KT * (s2[0, 1:] - s1[0, 1:]), rtol=1e-12)
    # the default law sticks it where it was before it touched (s_p = 0 here)
    dflt = SoftplusPenalty(KN, W, k_tangential=KT, friction=MU)
    r = dflt.evaluate(s1, dflt.initial_state(1))
    np.testing.assert_allclose(r.traction[0, 1:], KT * s1[0, 1:], rtol=1e-12)


def test_closed_is_the_pressure_at_zero_gap_or_more():
    law = SoftplusPenalty(KN, W, k_tangential=KT, friction=MU)
    assert law.closing_pressure() == pytest.approx(KN * W * np.log(2.0), rel=1e-15)
    g = np.array([-1e-3, -1e-9, 1e-9, 1e-3])
    res = law.evaluate(np.column_stack([g, np.zeros((4, 2))]), law.initial_state(4))
    np.testing.assert_array_equal(res.state.closed, [True, True, False, False])
    # softening and a stiffness factor keep k_N w, hence the threshold
    assert law.softened(10.0).closing_pressure() == pytest.approx(law.closing_pressure())
    shifted = law.with_multipliers(np.zeros((4, 3)), 7.0)
    assert shifted.law.closing_pressure() == pytest.approx(law.closing_pressure())
    lin = LinearPenalty(KN, unilateral=True)
    r = lin.evaluate(np.column_stack([g, np.zeros((4, 2))]), lin.initial_state(4))
    np.testing.assert_array_equal(r.state.closed, g < 0)


def test_bad_first_contact_and_semismooth_newton_are_refused():
    with pytest.raises(ValueError, match="first_contact = 'end' is invalid"):
        SoftplusPenalty(KN, W, first_contact="end")
    with pytest.raises(ValueError, match="first_contact = 'closure' is not available"):
        SemismoothNewton().check_law(SoftplusPenalty(KN, W, KT, MU, first_contact="closure"))
    SemismoothNewton().check_law(SoftplusPenalty(KN, W, KT, MU))


def test_the_closed_flag_travels_with_the_state():
    st = HistoryInterfaceState.zeros(4)
    st.closed[[1, 3]] = True
    assert st.copy().closed.tolist() == [False, True, False, True]
    trial = st.copy()
    trial.closed[:] = [True, False, True, False]
    kept = keep_points(trial, st, np.array([True, False, False, True]))
    assert kept.closed.tolist() == [False, False, True, True]
    joined = take_points([st, trial], np.array([7, 1]))
    assert joined.closed.tolist() == [False, True]
    with pytest.raises(ValueError, match="closed must be a bool array"):
        InterfaceState(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2), closed=np.zeros(2))
    with pytest.raises(ValueError, match="closed must be an ndarray of shape"):
        InterfaceState(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2),
                       closed=np.zeros(3, bool))
    # a state pickled before the flag existed (an older checkpoint) comes back all open
    old = InterfaceState.zeros(3)
    del old.__dict__["closed"]
    back = pickle.loads(pickle.dumps(old))
    assert back.closed.dtype == bool and not back.closed.any()
