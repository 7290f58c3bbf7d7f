"""Penalty laws: tangents against central finite differences, limits, purity, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from rough_contact.interface.contract import (ConvergenceError, MultiplierLaw, NewtonTangentLaw,
                                              SoftenableLaw)
from rough_contact.interface.enforcement import AugmentedLagrangian
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.interface.state import InterfaceState


def fd_tangent(law, jump, committed, h=1e-7):
    n = jump.shape[0]
    D = np.zeros((n, 3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        tp = law.evaluate(jump + e, committed).traction
        tm = law.evaluate(jump - e, committed).traction
        D[:, :, j] = (tp - tm) / (2 * h)
    return D


def check_contract(res, n):
    res.check(n)
    assert res.traction.shape == (n, 3)
    assert res.tangent.shape == (n, 3, 3)
    assert res.dissipation.shape == (n,)
    assert res.area_fraction.shape == (n,)
    assert res.contact.shape == (n,) and res.contact.dtype == bool
    assert res.slipping.shape == (n,) and res.slipping.dtype == bool
    assert len(res.state) == n


@pytest.mark.parametrize("unilateral", [False, True])
def test_linear_penalty_tangent_and_values(unilateral):
    rng = np.random.default_rng(0)
    law = LinearPenalty(k_normal=1e3, k_tangential=2e2, unilateral=unilateral)
    jump = rng.uniform(-1e-2, 1e-2, (50, 3))
    jump[np.abs(jump[:, 0]) < 1e-5, 0] = 1e-3  # keep away from the kink at g = 0
    st = law.initial_state(50)
    res = law.evaluate(jump, st)
    check_contract(res, 50)
    np.testing.assert_allclose(res.tangent, fd_tangent(law, jump, st), rtol=1e-6, atol=1e-6)
    closed = jump[:, 0] < 0
    np.testing.assert_allclose(res.traction[closed, 0], 1e3 * jump[closed, 0])
    if unilateral:
        assert np.all(res.traction[~closed] == 0.0)
    else:
        np.testing.assert_allclose(res.traction[~closed, 0], 1e3 * jump[~closed, 0])
    np.testing.assert_array_equal(res.contact, closed)
    assert np.all(np.diagonal(res.tangent, axis1=1, axis2=2) >= 0)


def test_softplus_normal_limits():
    law = SoftplusPenalty(k_normal=1e4, width=1e-4)
    p, k = law.normal(np.array([-1e-2, 0.0, 1e-2]))
    # deep contact: linear penalty p = -k g (up to w ln 2 < 1e-30 relative error here)
    np.testing.assert_allclose(p[0], 1e4 * 1e-2, rtol=1e-12)
    np.testing.assert_allclose(k[0], 1e4, rtol=1e-12)
    np.testing.assert_allclose(p[1], 1e4 * 1e-4 * np.log(2.0), rtol=1e-14)
    np.testing.assert_allclose(k[1], 0.5e4, rtol=1e-14)
    assert p[2] < 1e-35 and k[2] < 1e-35


@pytest.mark.parametrize("slip", [False, True])
def test_softplus_friction_tangent_fd(slip):
    rng = np.random.default_rng(1)
    n = 40
    law = SoftplusPenalty(k_normal=1e4, width=1e-3, k_tangential=5e3, friction=0.3)
    jump = np.column_stack(
        [rng.uniform(-3e-3, 1e-3, n), rng.uniform(-1, 1, (n, 2)) * (1e-3 if slip else 1e-6)]
    )
    committed = InterfaceState(rng.uniform(-1, 1, (n, 2)) * 1e-7, np.zeros((n, 2)), np.zeros(n))
    res = law.evaluate(jump, committed)
    check_contract(res, n)
    if slip:
        assert res.slipping.sum() >= n // 4
    else:
        assert not res.slipping.any()
    np.testing.assert_allclose(
        res.tangent, fd_tangent(law, jump, committed, h=1e-9), rtol=1e-5, atol=1e-3
    )


def test_softplus_return_map_consistency_and_purity():
    rng = np.random.default_rng(2)
    n = 30
    law = SoftplusPenalty(k_normal=1e4, width=1e-3, k_tangential=5e3, friction=0.4)
    jump = np.column_stack([rng.uniform(-3e-3, 0, n), rng.uniform(-1e-3, 1e-3, (n, 2))])
    committed = law.initial_state(n)
    before = committed.plastic_slip.copy()
    res = law.evaluate(jump, committed)
    np.testing.assert_array_equal(committed.plastic_slip, before)  # committed untouched
    p = -res.traction[:, 0]
    s = res.slipping
    assert s.any()
    # on slip the traction lies on the Coulomb cone; elsewhere inside it
    np.testing.assert_allclose(np.linalg.norm(res.traction[s, 1:], axis=1), 0.4 * p[s], rtol=1e-12)
    assert np.all(np.linalg.norm(res.traction[~s, 1:], axis=1) <= 0.4 * p[~s] * (1 + 1e-12))
    # elastic part of the slip carries the traction: t_T = k_T (s - s_p)
    np.testing.assert_allclose(
        res.traction[:, 1:], 5e3 * (jump[:, 1:] - res.state.plastic_slip), rtol=1e-10, atol=1e-12
    )
    assert np.all(res.dissipation >= 0) and np.all(res.dissipation[s] > 0)
    # the trial state records the slip magnitudes of the step
    dsp = res.state.plastic_slip - committed.plastic_slip
    np.testing.assert_allclose(res.state.accumulated_slip, np.abs(dsp), rtol=1e-12)
    np.testing.assert_allclose(res.state.slip_path, np.hypot(*dsp.T), rtol=1e-12)
    # re-evaluating from the trial state at the same jump is elastic (nothing more slips)
    again = law.evaluate(jump, res.state)
    assert not again.slipping.any()
    assert np.all(again.dissipation == 0.0)
    np.testing.assert_allclose(again.traction, res.traction, rtol=1e-10, atol=1e-12)


def test_bad_input():
    with pytest.raises(ValueError, match="k_normal"):
        LinearPenalty(k_normal=-1.0)
    with pytest.raises(ValueError, match="width"):
        SoftplusPenalty(k_normal=1.0, width=0.0)
    with pytest.raises(ValueError, match="friction"):
        SoftplusPenalty(k_normal=1.0, width=1.0, friction=np.nan)
    law = LinearPenalty(k_normal=1.0)
    with pytest.raises(ValueError, match="shape"):
        law.evaluate(np.zeros((3, 2)), law.initial_state(3))
    with pytest.raises(ValueError, match="committed"):
        law.evaluate(np.zeros((3, 3)), law.initial_state(2))
    # a non-finite jump is a diverging global iterate: a convergence failure (cutback)
    with pytest.raises(ConvergenceError, match=r"not finite at 1 of 2 points \(first index 1\)"):
        law.evaluate(np.array([[0.0, 0, 0], [np.nan, 0, 0]]), law.initial_state(2))


def test_softplus_newton_tangent_reversal():
    """newton_tangent adds the secant stiffness along m only at slipping points whose trial
    direction reversed since the previous Jacobian; traction and history are the law's."""
    law = SoftplusPenalty(k_normal=1e4, width=1e-4, k_tangential=1e4, friction=0.3)
    committed = law.initial_state(4)
    # points 0, 1 slipping (+x, -x), point 2 slipping along +y, point 3 sticking (tiny slip)
    jump = np.array([[-1e-2, 5e-3, 0.0], [-1e-2, -5e-3, 0.0], [-1e-2, 0.0, 5e-3],
                     [-1e-2, 1e-8, 0.0]])
    res = law.evaluate(jump, committed)
    assert res.slipping.tolist() == [True, True, True, False]
    t0, memo = law.newton_tangent(jump, committed, res, None)
    assert t0 is res.tangent                                 # first Jacobian: consistent
    np.testing.assert_allclose(memo, [[1, 0], [-1, 0], [0, 1], [1, 0]])
    previous = np.array([[-1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    t1, _ = law.newton_tangent(jump, committed, res, previous)
    p, _ = law.normal(jump[:, 0])
    secant = law.k_tangential * law.friction * p[0] / (law.k_tangential * 5e-3)
    expected = res.tangent.copy()
    expected[0, 1, 1] += secant                              # reversed and slipping: +x x +x
    np.testing.assert_allclose(t1, expected, rtol=1e-12, atol=0)
    assert np.array_equal(res.tangent, law.evaluate(jump, committed).tangent)   # pure
    off = SoftplusPenalty(k_normal=1e4, width=1e-4, k_tangential=1e4, friction=0.3,
                          reversal_stiffness=0.0)
    t2, _ = off.newton_tangent(jump, committed, off.evaluate(jump, committed), previous)
    np.testing.assert_array_equal(t2, res.tangent)
    with pytest.raises(ValueError, match="reversal_stiffness"):
        SoftplusPenalty(k_normal=1e4, width=1e-4, reversal_stiffness=-1.0)


def _multipliers(rng, n, scale=1.0):
    """A state with random plastic slip and random multipliers (pressure >= 0)."""
    st = SoftplusPenalty(k_normal=1e4, width=1e-3).initial_state(n)
    st.plastic_slip[:] = rng.uniform(-1, 1, (n, 2)) * 1e-6
    lam = np.column_stack([rng.uniform(0.5, 2, n), rng.uniform(-0.05, 0.05, (n, 2))]) * scale
    return st, lam


@pytest.mark.parametrize("slip", [False, True])
def test_shifted_tangent_fd_and_shifted_penalty(slip):
    """The law shifted by multipliers: the plain law with the gap shifted by lambda_N / k_N and
    the trial traction by lambda_T (tau = lambda_T + k_T (s - s_p)); its tangent matches
    central differences, and the update of the augmented Lagrangian takes its tractions as the
    next multipliers."""
    rng = np.random.default_rng(11)
    n = 40
    kn, kt, mu, w = 1e4, 5e3, 0.3, 1e-3
    plain = SoftplusPenalty(k_normal=kn, width=w, k_tangential=kt, friction=mu)
    committed, lam = _multipliers(rng, n)
    law = plain.with_multipliers(lam)
    assert isinstance(plain, MultiplierLaw) and isinstance(law, NewtonTangentLaw)
    jump = np.column_stack([rng.uniform(-3e-4, 0.0, n),
                            rng.uniform(-1, 1, (n, 2)) * (1e-3 if slip else 1e-7)])
    res = law.evaluate(jump, committed)
    check_contract(res, n)
    assert res.slipping.sum() >= n // 4 if slip else not res.slipping.any()
    np.testing.assert_allclose(res.tangent, fd_tangent(law, jump, committed, h=1e-9),
                               rtol=1e-5, atol=1e-3)
    # the same numbers from the normal function and a hand-written radial return
    p_expected, _ = plain.normal(jump[:, 0] - lam[:, 0] / kn)
    np.testing.assert_allclose(-res.traction[:, 0], p_expected, rtol=1e-13)
    tau = lam[:, 1:] + kt * (jump[:, 1:] - committed.plastic_slip)
    cap = mu * p_expected
    scale = np.minimum(1.0, cap / np.linalg.norm(tau, axis=1))
    np.testing.assert_allclose(res.traction[:, 1:], tau * scale[:, None], rtol=1e-12,
                               atol=1e-15)
    update = AugmentedLagrangian.update(lam, res)
    np.testing.assert_array_equal(update.multipliers[:, 0], -res.traction[:, 0])
    np.testing.assert_array_equal(update.multipliers[:, 1:], res.traction[:, 1:])


def test_augmented_fixed_point_is_exact_coulomb():
    """Where the multipliers equal the tractions they produce, the constraints hold exactly:
    no elastic slip (s = s_p after the step) and, in contact, k_N g = 0 up to the softplus
    smoothing. Stick: the point has not moved since the committed state (s = s_p,n)."""
    plain = SoftplusPenalty(k_normal=1e4, width=1e-9, k_tangential=5e3, friction=0.5)
    st = plain.initial_state(2)
    st.plastic_slip[:] = [[1e-3, 0.0], [2e-3, -1e-3]]
    # point 0 sticks with a traction inside the cone, point 1 slips along +x by 1e-4 mm
    lam = np.array([[2.0, 0.3, -0.4], [2.0, 1.0, 0.0]])
    jump = np.array([[0.0, 1e-3, 0.0], [0.0, 2e-3 + 1e-4, -1e-3]])
    res = plain.with_multipliers(lam).evaluate(jump, st)
    assert res.slipping.tolist() == [False, True]
    np.testing.assert_allclose(res.traction, [[-2.0, 0.3, -0.4], [-2.0, 1.0, 0.0]], rtol=1e-12)
    update = AugmentedLagrangian.update(lam, res)
    np.testing.assert_allclose(update.change, 0.0, atol=1e-12)          # a fixed point
    np.testing.assert_allclose(res.state.plastic_slip, jump[:, 1:], rtol=0, atol=1e-15)
    np.testing.assert_allclose(res.dissipation, [0.0, 1.0 * 1e-4], rtol=1e-10)
    # the update takes the trial tractions as multipliers
    moved = jump + np.array([[-1e-5, 2e-6, 0.0], [0.0, 0.0, 0.0]])
    res2 = plain.with_multipliers(lam).evaluate(moved, st)
    update = AugmentedLagrangian.update(lam, res2)
    np.testing.assert_array_equal(update.multipliers[:, 0], -res2.traction[:, 0])
    np.testing.assert_array_equal(update.multipliers[:, 1:], res2.traction[:, 1:])
    np.testing.assert_allclose(update.change,
                               np.linalg.norm(update.multipliers - lam, axis=1))
    assert update.change[0] == pytest.approx(np.hypot(1e4 * 1e-5, 5e3 * 2e-6), rel=1e-6)
    assert lam[0, 0] == 2.0           # pure


def test_augmented_control_and_bad_input():
    plain = SoftplusPenalty(k_normal=1e4, width=1e-4)
    assert type(plain.initial_state(3)) is InterfaceState
    c = AugmentedLagrangian(tolerance=1e-4, max_updates=7)
    assert (c.tolerance, c.max_updates) == (1e-4, 7)
    for kwargs, match in (({"tolerance": 0.0}, "augmentation tolerance"),
                          ({"tolerance": 1.0}, "augmentation tolerance"),
                          ({"max_updates": 0}, "max_updates = 0 is invalid"),
                          ({"max_updates": 2.5}, "max_updates = 2.5 is invalid"),
                          ({"max_updates": True}, "max_updates = True is invalid")):
        with pytest.raises(ValueError, match=match):
            AugmentedLagrangian(**kwargs)
    # the multipliers must match the points; a law that cannot be shifted is refused
    with pytest.raises(ValueError, match="multipliers of shape"):
        plain.with_multipliers(np.zeros((3, 3))).evaluate(np.zeros((2, 3)),
                                                          InterfaceState.zeros(2))
    with pytest.raises(TypeError, match="MultiplierLaw"):
        AugmentedLagrangian().check_law(LinearPenalty(1e3))


def test_augmented_extrapolate():
    """The secant predictor of the multipliers: lambda + r (lambda - lambda_previous), the
    pressure kept >= 0; pure."""
    prev = np.array([[1.0, 0.1, 0.0], [0.5, 0.0, 0.0]])
    now = np.array([[2.0, 0.3, -0.1], [0.2, 0.0, 0.0]])
    new = AugmentedLagrangian.extrapolate(now, prev, 0.5)
    np.testing.assert_allclose(new, [[2.5, 0.4, -0.15], [0.05, 0.0, 0.0]])
    np.testing.assert_allclose(AugmentedLagrangian.extrapolate(now, prev, 1.0)[1],
                               [0.0, 0.0, 0.0])
    assert now[0, 0] == 2.0


def test_softplus_counts_slip_only_in_contact():
    """Issue 24, item 8: a point out of contact (p = 0: the softplus underflows 745 smoothing
    lengths away) with a tangential jump is open, not slipping. Coulomb's cone at p = 0 is the
    point t_T = 0: the traction vanishes there and the plastic slip follows the jump, but the
    point carries no friction, so it must not be counted as slipping. Points in contact past
    the cone slip; the slip count never exceeds the contact count (also with multipliers)."""
    law = SoftplusPenalty(k_normal=1e4, width=1e-4, k_tangential=1e4, friction=0.3)
    jump = np.array([[1.0, 2e-3, -1e-3],       # far open, sheared: p = 0 exactly
                     [1.0, 0.0, 0.0],          # far open, no shear
                     [-1e-2, 5e-2, 0.0],       # in contact, |tau| = 500 > mu p = 30: slips
                     [-1e-2, 1e-4, 0.0]])      # in contact, |tau| = 1 < 30: sticks
    committed = InterfaceState.zeros(4)
    for multipliers in (None, np.zeros((4, 3))):
        res = law.evaluate(jump, committed, multipliers)
        check_contract(res, 4)
        assert res.pressure[0] == 0.0 and res.pressure[1] == 0.0
        np.testing.assert_array_equal(res.contact, [False, False, True, True])
        np.testing.assert_array_equal(res.slipping, [False, False, True, False])
        np.testing.assert_array_equal(res.traction[0], 0.0)          # the cone at p = 0
        np.testing.assert_allclose(res.state.plastic_slip[0], jump[0, 1:], rtol=1e-12)
        assert res.dissipation[0] == 0.0
    rng = np.random.default_rng(4)
    many = np.column_stack([rng.uniform(-2e-3, 2e-1, 500), rng.normal(0, 3e-4, (500, 2))])
    res = law.evaluate(many, InterfaceState.zeros(500))
    assert not np.any(res.slipping & ~res.contact)
    assert 0 < res.slipping.sum() < res.contact.sum() < 500


def test_softened_law():
    """SoftplusPenalty.softened(f): k_N, k_T / f, width x f; p(0) = k_N w ln 2 and the
    friction unchanged; pressures deep in contact from the closed form k_N (-g) / f."""
    law = SoftplusPenalty(k_normal=1e9, width=2.5e-11, k_tangential=5e8, friction=0.3)
    soft = law.softened(100.0)
    assert isinstance(soft, SoftenableLaw) and isinstance(law, SoftenableLaw)
    assert (soft.k_normal, soft.k_tangential) == (1e7, 5e6)
    assert soft.width == pytest.approx(2.5e-9, rel=1e-15)
    assert (soft.friction, soft.reversal_stiffness) == (law.friction, law.reversal_stiffness)
    p0, _ = law.normal(np.zeros(1))
    p0s, _ = soft.normal(np.zeros(1))
    assert p0s[0] == pytest.approx(1e9 * 2.5e-11 * np.log(2.0), rel=1e-12)
    assert p0s[0] == pytest.approx(p0[0], rel=1e-12)
    g = np.array([-1e-5])                    # 4000 widths deep: p = k (-g) to round-off
    assert soft.normal(g)[0][0] == pytest.approx(1e7 * 1e-5, rel=1e-12)
    assert law.softened(1.0) == law
    for bad in (0.5, float("nan"), "10"):
        with pytest.raises(ValueError, match="softening factor"):
            law.softened(bad)


def test_stiffness_factor_scales_the_shifted_penalty():
    """with_multipliers(lambda, f) is the penalty with k_N, k_T x f and the width / f, shifted
    (the same law built directly), and f = 1 is the law's own; a bad factor is refused."""
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3)
    rng = np.random.default_rng(5)
    n = 50
    jump = np.column_stack([rng.uniform(-2e-3, 1e-3, n), rng.normal(0, 1e-3, (n, 2))])
    st = law.initial_state(n)
    lam = np.column_stack([rng.uniform(0, 5, n), rng.normal(0, 1, (n, 2))])
    built = SoftplusPenalty(3e4, 1e-3 / 3, k_tangential=1.5e4, friction=0.3)
    r = law.with_multipliers(lam, 3.0).evaluate(jump, st)
    r_ref = built.with_multipliers(lam).evaluate(jump, st)
    np.testing.assert_allclose(r.traction, r_ref.traction, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(r.tangent, r_ref.tangent, rtol=1e-13, atol=1e-9)
    r1 = law.with_multipliers(lam).evaluate(jump, st)
    np.testing.assert_array_equal(law.with_multipliers(lam, 1.0).evaluate(jump, st).traction,
                                  r1.traction)
    with pytest.raises(ValueError, match="stiffness_factor"):
        law.with_multipliers(lam, 0.0)


def test_tangential_factor_is_each_point_with_its_own_kt():
    """with_multipliers(lambda, f, tangential_factor=g) with g one per point: each point
    evaluates as the law built with k_T x g_i (and f on everything; a separate SoftplusPenalty
    per value of g, evaluated on its own points): traction, tangent, plastic slip and the
    Newton tangent with a reversal; the normal part is that of the law without g; bad
    per-point factors are refused."""
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3)
    rng = np.random.default_rng(8)
    n = 60
    jump = np.column_stack([rng.uniform(-2e-3, 1e-3, n), rng.normal(0, 1e-3, (n, 2))])
    st = law.initial_state(n)
    st.plastic_slip[:] = rng.normal(0, 1e-4, (n, 2))
    lam = np.column_stack([rng.uniform(0, 5, n), rng.normal(0, 1, (n, 2))])
    values = np.array([0.5, 2.0, 7.0])
    g = values[rng.integers(0, 3, n)]
    shifted = law.with_multipliers(lam, 3.0, g)
    r = shifted.evaluate(jump, st)
    previous = -rng.normal(size=(n, 2))          # reversed directions at about half the points
    tan, _ = shifted.newton_tangent(jump, st, r, previous)
    slipping = 0
    for v in values:
        i = np.flatnonzero(g == v)
        built = SoftplusPenalty(3e4, 1e-3 / 3, k_tangential=1.5e4 * v, friction=0.3)
        sub = InterfaceState.zeros(i.size)
        sub.plastic_slip[:] = st.plastic_slip[i]
        ref = built.with_multipliers(lam[i]).evaluate(jump[i], sub)
        np.testing.assert_allclose(r.traction[i], ref.traction, rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(r.tangent[i], ref.tangent, rtol=1e-13, atol=1e-9)
        np.testing.assert_allclose(r.state.plastic_slip[i], ref.state.plastic_slip,
                                   rtol=1e-13, atol=1e-18)
        np.testing.assert_array_equal(r.slipping[i], ref.slipping)
        ref_tan, _ = built.with_multipliers(lam[i]).newton_tangent(jump[i], sub, ref,
                                                                   previous[i])
        np.testing.assert_allclose(tan[i], ref_tan, rtol=1e-13, atol=1e-9)
        slipping += int(ref.slipping.sum())
    assert 0 < slipping < n                       # both branches were compared
    np.testing.assert_array_equal(r.traction[:, 0], law.with_multipliers(lam, 3.0)
                                  .evaluate(jump, st).traction[:, 0])
    for bad, match in ((g[:-1], r"shape \(59,\) for 60 points"),
                       (np.where(np.arange(n) == 3, 0.0, g), r"tangential_factor\[3\] = 0.0"),
                       (np.where(np.arange(n) == 4, np.nan, g),
                        r"tangential_factor\[4\] = nan"),
                       ("x", "tangential_factor")):
        with pytest.raises(ValueError, match=match):
            law.with_multipliers(lam, 1.0, bad)


def test_reference_spacing_scales_the_penalty_with_the_point_spacing():
    """AugmentedLagrangian(reference_spacing=h): the law at each point is the one with the
    tangential factor h / h_j (and stiffness_factor on everything); without the points'
    spacing, or with a bad reference, it is refused."""
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3)
    rng = np.random.default_rng(9)
    n = 20
    jump = np.column_stack([rng.uniform(-2e-3, 1e-3, n), rng.normal(0, 1e-3, (n, 2))])
    st = law.initial_state(n)
    lam = np.column_stack([rng.uniform(0, 5, n), rng.normal(0, 1, (n, 2))])
    spacing = rng.uniform(0.01, 0.05, n)
    enf = AugmentedLagrangian(reference_spacing=0.05, stiffness_factor=3.0)
    r = enf.law_for(law, lam, spacing).evaluate(jump, st)
    ref = law.with_multipliers(lam, 3.0, 0.05 / spacing).evaluate(jump, st)
    np.testing.assert_array_equal(r.traction, ref.traction)
    with pytest.raises(ValueError, match="only the nodal point set knows"):
        enf.law_for(law, lam, None)
    plain = AugmentedLagrangian().law_for(law, lam, spacing).evaluate(jump, st)
    np.testing.assert_array_equal(plain.traction, law.with_multipliers(lam).evaluate(
        jump, st).traction)                       # no reference: the spacing is not used
    for bad in (0.0, -1.0, np.nan, "0.05"):
        with pytest.raises(ValueError, match="reference_spacing"):
            AugmentedLagrangian(reference_spacing=bad)
