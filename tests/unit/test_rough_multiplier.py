"""The rough law as a MultiplierLaw (issue 22): only the friction trial traction is shifted.

``InterfaceLaw.with_multipliers(lambda)`` gives t_trial = lambda_T + K_T(h) (s - s_p), the same
return map otherwise (slip hardening, orthotropic ellipse, non-associated potential), and the
unshifted normal law p(h). Checked here against things the shifted code does not compute
itself:

* zero multipliers give the plain law bit for bit; the normal row, the area fraction, the
  contact flags and the normal memory are the plain law's for any multipliers;
* the shifted trial traction is the plain law's trial traction with the committed plastic
  slip moved by -lambda_T / K_T(h) (K_T from the normal law directly): same traction, same
  plastic increments and hardening (the plain law's return map is the oracle);
* stick: t_T = lambda_T + c kN(h) (s - s_p) in closed form; slip: the slip criterion holds
  with the hardened coefficients, Delta s_p = e - (t_T - lambda_T) / K_T;
* the consistent tangent against central finite differences of the shifted law: stick, slip
  and mixed, isotropic (radial and kTx != kTy) and orthotropic (fixed potential axes and the
  k-form) with hardening, with and without open points, and a normal law with memory;
* the release limit (p vanishing against the trial traction) with a shift;
* a spring in series with one interface point: the augmented-Lagrangian iteration
  lambda <- t converges with the error ratio K_b / (K_b + K_T) to rigid stick (s = s_p), and
  to |t| = mu p in slip, while the pressure stays p(h);
* a frictionless law's ``with_multipliers`` is the law itself; bad multipliers are refused.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rough_contact.interface.contract import InterfaceLawProtocol, MultiplierLaw
from rough_contact.interface.enforcement import AugmentedLagrangian
from rough_contact.interface.friction import IsotropicSlipHardening, OrthotropicSlipHardening
from rough_contact.interface.law import InterfaceLaw, ShiftedInterfaceLaw
from rough_contact.interface.state import InterfaceState
from rough_contact.interface.tangential import TangentialStiffness

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared stand-in laws
from law_test_helpers import (ExponentialNormal, QuadraticNormal,  # noqa: E402
                              fd_check, random_state, trial_ratio)


ORTHO = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (275.0, 100.0),
                                 potential_axes=(0.125, 0.2))
ORTHO_K = OrthotropicSlipHardening((0.5, 0.3), (0.5, 0.6), (275.0, 100.0),
                                   potential_exponent=0.5)
ISO = IsotropicSlipHardening(0.4, 0.5, 275.0)
TS = TangentialStiffness((0.7, 1.0))
TS_ISO = TangentialStiffness((0.7, 0.7))
FRICTIONS = {"ortho": ORTHO, "ortho_k": ORTHO_K, "iso": ISO}


def multipliers_for(law, jump, rng, size):
    """lambda_N = p(h) (what the enforcement passes), lambda_T of magnitude up to ``size`` x
    mu p in random directions (mu: the smallest initial coefficient)."""
    p = law.normal.evaluate(law.h0 + jump[:, 0])[0]
    f = law.friction
    mu = np.min(np.multiply(f.mu_macro, f.mu_initial_ratio))
    ang = rng.uniform(0, 2 * np.pi, p.size)
    amp = size * rng.uniform(0.2, 1.0, p.size) * mu * p
    return np.column_stack([p, amp * np.cos(ang), amp * np.sin(ang)])


def test_protocols_and_frictionless_is_the_law_itself():
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    assert isinstance(law, MultiplierLaw)
    shifted = law.with_multipliers(np.zeros((4, 3)))
    assert isinstance(shifted, ShiftedInterfaceLaw) and isinstance(shifted, InterfaceLawProtocol)
    assert shifted.max_friction_coefficient() == law.max_friction_coefficient()
    assert isinstance(shifted.initial_state(4), InterfaceState)
    frictionless = InterfaceLaw(QuadraticNormal(), h0=1e-3)
    assert frictionless.with_multipliers(np.ones((4, 3))) is frictionless


@pytest.mark.parametrize("name", list(FRICTIONS))
def test_zero_multipliers_are_the_plain_law_and_normal_is_untouched(name):
    """Zero multipliers: bit-identical to evaluate. Any multipliers: the normal row, area
    fraction and contact flags are the plain law's bit for bit (mixed open/closed points)."""
    friction = FRICTIONS[name]
    law = InterfaceLaw(QuadraticNormal(), TS_ISO if name == "iso" else TS, friction,
                       h0=1.5e-3)
    rng = np.random.default_rng(3)
    n = 400
    st = random_state(rng, n)
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(
                                -6, -3, (n, 1))])
    plain = law.evaluate(jump, st)
    zero = law.with_multipliers(np.zeros((n, 3))).evaluate(jump, st)
    for field in ("traction", "tangent", "dissipation", "area_fraction", "contact", "slipping"):
        np.testing.assert_array_equal(getattr(zero, field), getattr(plain, field), err_msg=field)
    np.testing.assert_array_equal(zero.state.plastic_slip, plain.state.plastic_slip)
    assert 0 < plain.contact.sum() < n and 0 < plain.slipping.sum()

    lam = multipliers_for(law, jump, rng, 2.0)
    lam[:, 0] = rng.uniform(0, 50.0, n)        # lambda_N is not used, whatever it is
    shifted = law.with_multipliers(lam).evaluate(jump, st)
    np.testing.assert_array_equal(shifted.traction[:, 0], plain.traction[:, 0])
    np.testing.assert_array_equal(shifted.tangent[:, 0, :], plain.tangent[:, 0, :])
    np.testing.assert_array_equal(shifted.area_fraction, plain.area_fraction)
    np.testing.assert_array_equal(shifted.contact, plain.contact)
    # open points: no traction, no tangent, history kept, whatever lambda_T
    op = ~plain.contact
    assert np.all(shifted.traction[op] == 0) and np.all(shifted.tangent[op] == 0)
    np.testing.assert_array_equal(shifted.state.plastic_slip[op], st.plastic_slip[op])
    assert not np.array_equal(shifted.traction[:, 1:], plain.traction[:, 1:])


@pytest.mark.parametrize("name", list(FRICTIONS))
def test_shift_is_a_moved_plastic_slip(name):
    """t_trial = lambda_T + K_T (s - s_p) = K_T (s - (s_p - lambda_T / K_T)): the plain law
    at the committed state with s_p moved by -lambda_T / K_T(h) gives the same traction, the
    same plastic increments and hardening (K_T = c kN(h) from the normal law)."""
    friction = FRICTIONS[name]
    ts = TS_ISO if name == "iso" else TS
    law = InterfaceLaw(ExponentialNormal(), ts, friction, h0=1e-3)
    rng = np.random.default_rng(11)
    n = 500
    st = random_state(rng, n)
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * 2e-4])
    lam = multipliers_for(law, jump, rng, 1.5)
    r = law.with_multipliers(lam).evaluate(jump, st)
    k = law.normal.evaluate(law.h0 + jump[:, 0])[1]
    kt = np.array(ts.kt_over_kn) * k[:, None]
    moved = st.copy()
    moved.plastic_slip[:] = st.plastic_slip - lam[:, 1:] / kt
    ref = law.evaluate(jump, moved)
    assert 0.1 < r.slipping.mean() < 0.9
    np.testing.assert_array_equal(r.slipping, ref.slipping)
    scale = np.abs(ref.traction[:, 1:]).max()
    np.testing.assert_allclose(r.traction, ref.traction, rtol=1e-11, atol=1e-13 * scale)
    np.testing.assert_allclose(r.tangent[:, :, 1:], ref.tangent[:, :, 1:], rtol=1e-9,
                               atol=1e-11 * np.abs(ref.tangent).max())
    dsp = r.state.plastic_slip - st.plastic_slip
    dsp_ref = ref.state.plastic_slip - moved.plastic_slip
    np.testing.assert_allclose(dsp, dsp_ref, rtol=1e-9, atol=1e-12 * np.abs(dsp_ref).max())
    np.testing.assert_allclose(r.state.accumulated_slip - st.accumulated_slip,
                               ref.state.accumulated_slip - moved.accumulated_slip,
                               rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(r.dissipation, ref.dissipation, rtol=1e-9,
                               atol=1e-12 * ref.dissipation.max())


@pytest.mark.parametrize("name", list(FRICTIONS))
def test_closed_forms_stick_and_slip(name):
    """Stick: t_T = lambda_T + c kN(h) (s - s_p) exactly. Slip: on the criterion with the
    hardened coefficients (kappa + |Delta s_p|), Delta s_p = e - (t_T - lambda_T) / K_T,
    dissipation t_T . Delta s_p >= 0."""
    friction = FRICTIONS[name]
    ts = TS_ISO if name == "iso" else TS
    law = InterfaceLaw(ExponentialNormal(), ts, friction, h0=1e-3)
    rng = np.random.default_rng(5)
    n = 400
    st = random_state(rng, n)
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * 3e-4])
    lam = multipliers_for(law, jump, rng, 1.5)
    r = law.with_multipliers(lam).evaluate(jump, st)
    p, k, _ = law.normal.evaluate(law.h0 + jump[:, 0])
    kt = np.array(ts.kt_over_kn) * k[:, None]
    e = jump[:, 1:] - st.plastic_slip
    stick, slip = ~r.slipping, r.slipping
    assert stick.sum() > 50 and slip.sum() > 50
    np.testing.assert_allclose(r.traction[stick, 1:], lam[stick, 1:] + kt[stick] * e[stick],
                               rtol=1e-13, atol=1e-13 * np.abs(lam[:, 1:]).max())
    # the trial point lies outside the criterion exactly where the law slips
    np.testing.assert_array_equal(trial_ratio(law, jump, st, lam[:, 1:]) > 1.0, slip)
    dsp = r.state.plastic_slip - st.plastic_slip
    np.testing.assert_allclose(dsp[slip], e[slip] - (r.traction[slip, 1:] - lam[slip, 1:])
                               / kt[slip], rtol=1e-8, atol=1e-12 * np.abs(dsp).max())
    if isinstance(friction, OrthotropicSlipHardening):
        f = friction.slip_function(r.traction[slip, 1:], p[slip],
                                   r.state.accumulated_slip[slip])
        np.testing.assert_allclose(r.state.accumulated_slip - st.accumulated_slip, np.abs(dsp),
                                   rtol=1e-12)
    else:
        f = friction.slip_function(r.traction[slip, 1:], p[slip], r.state.slip_path[slip])
        np.testing.assert_allclose(r.state.slip_path - st.slip_path, np.hypot(*dsp.T),
                                   rtol=1e-12)
        # circular potential: slip along the traction, traction along the trial traction
        # (radial return with kTx = kTy)
        ttr = lam[slip, 1:] + kt[slip] * e[slip]
        cross = ttr[:, 0] * r.traction[slip, 2] - ttr[:, 1] * r.traction[slip, 1]
        assert np.abs(cross).max() <= 1e-12 * np.abs(ttr).max() * np.abs(r.traction).max()
    assert np.abs(f).max() <= 1e-10 * p[slip].max()
    assert np.all(r.dissipation >= 0.0) and np.all(r.dissipation[stick] == 0.0)


CASES = [("ortho", TS), ("ortho_k", TS), ("iso", TS_ISO), ("iso", TS)]


@pytest.mark.parametrize("name,ts", CASES, ids=["ortho", "ortho_k", "iso_radial", "iso_general"])
@pytest.mark.parametrize("regime", ["stick", "slip", "mixed"])
@pytest.mark.parametrize("normal", ["exponential", "quadratic"])
def test_tangent_matches_central_differences(name, ts, regime, normal):
    """The shifted law's consistent tangent (incl. the g-column through kN(h), kT(h) and p(h))
    against central differences; points within 1e-4 of the stick/slip switch are left out.
    The quadratic normal law opens some points (the law's gathered path)."""
    friction = FRICTIONS[name]
    nl = ExponentialNormal() if normal == "exponential" else QuadraticNormal()
    law = InterfaceLaw(nl, ts, friction, h0=1e-3 if normal == "exponential" else 1.5e-3)
    rng = np.random.default_rng(42)
    n = 500
    st = random_state(rng, n)
    scale = {"stick": 1e-7, "slip": 3e-3, "mixed": 1e-4}[regime]
    size = {"stick": 0.9, "slip": 3.0, "mixed": 1.2}[regime]
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3 if normal == "exponential" else 8e-4, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * scale])
    lam = multipliers_for(law, jump, rng, size)
    shifted = law.with_multipliers(lam)
    ratio = trial_ratio(law, jump, st, lam[:, 1:])
    p = law.normal.evaluate(law.h0 + jump[:, 0])[0]
    keep = (np.abs(ratio - 1.0) > 1e-4) & (p > 0)
    # points close to opening (h near h_max) are kinks of the quadratic law: leave them out
    if normal == "quadratic":
        keep &= law.h0 + jump[:, 0] < nl.h_max - 1e-5
    r = fd_check(shifted, jump, st, keep)
    frac = r.slipping[keep].mean()
    assert {"stick": frac == 0.0, "slip": frac > 0.97, "mixed": 0.1 < frac < 0.9}[regime], frac
    assert np.abs(r.tangent[keep, 1:, 0]).max() > 0       # coupling to the normal jump
    if normal == "quadratic":
        assert 0 < r.contact.sum() < n


def test_tangent_with_normal_memory():
    """With a normal law with memory (the shared closed-form stand-in, tests/memory_law.py:
    loading and unloading branches) the normal part, h_min and the normal dissipation are the
    plain law's bit for bit, and the shifted tangent matches central differences."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from memory_law import MemoryLaw

    law = InterfaceLaw(MemoryLaw(), TS, ORTHO, h0=0.0)
    rng = np.random.default_rng(8)
    n = 300
    st = law.initial_state(n)
    st.h_min[:] = -1e-3
    jump = np.column_stack([rng.uniform(-1.6e-3, 1e-4, n), rng.normal(size=(n, 2)) * 2e-5])
    lam = multipliers_for(law, jump, rng, 1.2)
    ref = law.evaluate(jump, st)
    shifted = law.with_multipliers(lam)
    r = shifted.evaluate(jump, st)
    np.testing.assert_array_equal(r.traction[:, 0], ref.traction[:, 0])
    np.testing.assert_array_equal(r.tangent[:, 0], ref.tangent[:, 0])
    np.testing.assert_array_equal(r.state.h_min, ref.state.h_min)
    np.testing.assert_array_equal(r.normal_dissipation, ref.normal_dissipation)
    h = jump[:, 0]
    p = law.normal.evaluate_history(h, st.h_min)[0]
    keep = (np.abs(h - st.h_min) > 1e-5) & (p > 0)         # off the branch switch
    keep &= np.abs(trial_ratio_history(law, jump, st, lam[:, 1:]) - 1.0) > 1e-4
    r = fd_check(shifted, jump, st, keep, rel_step=1e-8)
    assert 0.1 < r.slipping[keep].mean() < 0.9
    assert (h[keep] > st.h_min[keep]).sum() > 50 and (h[keep] < st.h_min[keep]).sum() > 50


def trial_ratio_history(law, jump, st, lam_t):
    """As :func:`trial_ratio` for a normal law with memory, without the unloading branch's k_T
    scale (the law has no reversal stiffness): kN from evaluate_history."""
    p, k = law.normal.evaluate_history(jump[:, 0], st.h_min)[:2]
    c = np.array(law.tangential.kt_over_kn)
    ttr = lam_t + c * k[:, None] * (jump[:, 1:] - st.plastic_slip)
    mu, _ = law.friction.coefficients(st.accumulated_slip)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.hypot(ttr[:, 0] / mu[:, 0], ttr[:, 1] / mu[:, 1]) / p


def test_release_limit_with_shift():
    """p vanishing against the trial traction (p / |t_trial| < 1e-16): the closed-form release
    with the shifted trial traction: t_T = p times the trial direction on the criterion,
    Delta s_p = e - (t_T - lambda_T) / K_T, finite everywhere."""
    normal = QuadraticNormal(h_max=0.0)
    law = InterfaceLaw(normal, TS_ISO, IsotropicSlipHardening(0.4), h0=0.0)
    g = -np.array([1e-150, 1e-100, 1e-20])          # p = 1e-294 ... 1e-34 MPa
    n = g.size
    e = np.array([[1e-6, -2e-6]] * n)
    lam = np.array([[0.0, 1.0, 2.0]] * n)
    jump = np.column_stack([g, e])
    st = law.initial_state(n)
    r = law.with_multipliers(lam).evaluate(jump, st)
    p, k, _ = normal.evaluate(law.h0 + g)
    kt = 0.7 * k
    ttr = lam[:, 1:] + kt[:, None] * e
    assert np.isfinite(r.traction).all() and np.isfinite(r.tangent).all()
    assert r.contact.all() and r.slipping.all()
    m = ttr / np.linalg.norm(ttr, axis=1)[:, None]
    np.testing.assert_allclose(r.traction[:, 1:], 0.4 * p[:, None] * m, rtol=1e-12)
    dsp = r.state.plastic_slip
    np.testing.assert_allclose(dsp, e + (lam[:, 1:] - r.traction[:, 1:]) / kt[:, None],
                               rtol=1e-12)


@pytest.mark.parametrize("factor", [1.0, 10.0], ids=["own_kt", "kt_x10"])
@pytest.mark.parametrize("kb_over_kt,drive", [(0.5, 0.6), (4.0, 0.6), (1.0, 1.5)],
                         ids=["soft_body_stick", "stiff_body_stick", "slip"])
def test_spring_in_series_converges_to_rigid_stick(kb_over_kt, drive, factor):
    """One interface point in series with a body spring K_b pulled by a displacement U
    (tangential balance K_b (U - s) = t_x(s) at a fixed normal gap), solved exactly per
    multiplier update (bisection: t_x is monotone in s), lambda <- t by the enforcement's
    update. Penalty: s = K_b U / (K_b + K_T) (the rough law's compliance). Exact stick: the
    lambda error falls by K_b / (K_b + K_T) per update and s -> s_p = 0, t_x = K_b U; in slip
    t_x -> mu p and the slip is all plastic. The pressure is p(h) throughout. With the
    enforcement's stiffness factor f the shifted law's K_T is f K_T: the same fixed point,
    reached at the rate K_b / (K_b + f K_T)."""
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    g = -2e-4
    p, k, _ = law.normal.evaluate(np.array([law.h0 + g]))
    kt = 0.7 * k[0]
    kb = kb_over_kt * kt
    mu0 = 0.3 * 0.5                     # committed mu_x (virgin)
    U = drive * mu0 * p[0] / kb         # exact stick's K_b U = drive x mu p
    st = law.initial_state(1)

    def solve(lawx):
        lo, hi = -1.0, U + 1.0          # residual K_b (U - s) - t(s) decreasing in s
        for _ in range(80):             # to the resolution of s
            s = 0.5 * (lo + hi)
            t = lawx.evaluate(np.array([[g, s, 0.0]]), st).traction[0, 1]
            lo, hi = (s, hi) if kb * (U - s) - t > 0 else (lo, s)
        return s, lawx.evaluate(np.array([[g, s, 0.0]]), st)

    s_pen, r_pen = solve(law)
    lam = np.zeros((1, 3))
    errs = []
    rate_expected = kb / (kb + factor * kt)
    for _ in range(int(np.log(1e-12) / np.log(rate_expected)) + 5):
        s, r = solve(law.with_multipliers(lam, factor))
        np.testing.assert_array_equal(r.traction[:, 0], -p)      # normal untouched
        update = AugmentedLagrangian.update(lam, r)
        lam = update.multipliers
        errs.append(update.change[0])
    e_el = s - r.state.plastic_slip[0, 0]
    if drive < 1.0:
        np.testing.assert_allclose(s_pen, kb * U / (kb + kt), rtol=1e-10)
        assert not r_pen.slipping[0] and not r.slipping[0]
        # geometric convergence with the ratio K_b / (K_b + K_T) (the change of the updates)
        n = 5 if factor == 1.0 else 3     # the changes reach round-off sooner at x10
        rate = np.array(errs[2:2 + n]) / np.array(errs[1:1 + n])
        np.testing.assert_allclose(rate, rate_expected, rtol=1e-6)
        assert abs(s) <= 1e-9 * s_pen                          # rigid stick
        np.testing.assert_allclose(r.traction[0, 1], kb * U, rtol=1e-9)
    else:
        assert r.slipping[0]
        assert abs(factor * kt * e_el) <= 1e-9 * abs(r.traction[0, 1])   # all plastic
        mu_x = ORTHO.coefficients(r.state.accumulated_slip)[0][0, 0]
        np.testing.assert_allclose(r.traction[0, 1], mu_x * p[0], rtol=1e-10)


@pytest.mark.parametrize("lam,match", [
    (np.zeros((4, 2)), r"multipliers must have shape \(n, 3\).*\(4, 2\)"),
    (np.zeros(3), r"multipliers must have shape \(n, 3\).*\(3,\)"),
    (np.array([[0.0, np.nan, 0.0]] * 4), r"multipliers are not finite at 4 of 4 points"),
    (np.array([[0.0, 0.0, 0.0], [np.inf, 0.0, 0.0]]), r"not finite at 1 of 2 .*first index 1"),
    (np.array([[1.0, 0.0, 0.0], [-0.5, 0.0, 0.0]]),
     r"lambda_N, a contact pressure\) = -0.5 MPa at point 1 is invalid: it must be >= 0"),
    ("abc", r"multipliers .* must be an \(n, 3\) array"),
])
@pytest.mark.parametrize("friction", [ORTHO, None], ids=["friction", "frictionless"])
def test_bad_multipliers(lam, match, friction):
    law = InterfaceLaw(ExponentialNormal(), TS if friction else None, friction, h0=1e-3)
    with pytest.raises(ValueError, match=match):
        law.with_multipliers(lam)


def test_multipliers_for_other_points():
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    shifted = law.with_multipliers(np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"multipliers hold 5 points; the jump has 3"):
        shifted.evaluate(np.zeros((3, 3)), law.initial_state(3))


@pytest.mark.parametrize("factor", [0.0, -1.0, np.nan, "x"])
def test_bad_stiffness_factor(factor):
    """A stiffness factor that is not a positive number is refused, naming it."""
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    with pytest.raises((ValueError, TypeError), match="stiffness_factor"):
        law.with_multipliers(np.zeros((2, 3)), factor)
    with pytest.raises((ValueError, TypeError), match="stiffness_factor"):
        AugmentedLagrangian(stiffness_factor=factor)


@pytest.mark.parametrize("regime", ["stick", "slip", "mixed"])
def test_stiffness_factor_is_the_law_with_a_stiffer_kt(regime):
    """The shifted law with the stiffness factor f = 7 is the same law built with c x 7 and
    shifted with factor 1 (an independent construction: traction, tangent and state equal to
    round-off), its normal part is the unscaled law's, and its tangent matches central
    differences."""
    f = 7.0
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    ref = InterfaceLaw(ExponentialNormal(),
                       TangentialStiffness(tuple(f * c for c in TS.kt_over_kn)), ORTHO,
                       h0=1e-3)
    rng = np.random.default_rng(7)
    n = 400
    st = random_state(rng, n)
    scale = {"stick": 1e-8, "slip": 3e-4, "mixed": 3e-5}[regime]
    size = {"stick": 0.9, "slip": 3.0, "mixed": 1.2}[regime]
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * scale])
    lam = multipliers_for(law, jump, rng, size)
    shifted = law.with_multipliers(lam, f)
    r, r_ref = shifted.evaluate(jump, st), ref.with_multipliers(lam).evaluate(jump, st)
    np.testing.assert_allclose(r.traction, r_ref.traction, rtol=1e-14, atol=0)
    np.testing.assert_allclose(r.tangent, r_ref.tangent, rtol=1e-13, atol=0)
    np.testing.assert_allclose(r.state.plastic_slip, r_ref.state.plastic_slip, rtol=1e-14,
                               atol=0)
    np.testing.assert_array_equal(r.traction[:, 0], law.evaluate(jump, st).traction[:, 0])
    keep = np.abs(trial_ratio(ref, jump, st, lam[:, 1:]) - 1.0) > 1e-4
    frac = r.slipping[keep].mean()
    assert {"stick": frac == 0.0, "slip": frac > 0.97, "mixed": 0.1 < frac < 0.9}[regime], frac
    fd_check(shifted, jump, st, keep)


def test_tangential_factor_is_each_point_with_its_own_kt():
    """A tangential factor per point: each point evaluates as the law with that point's factor
    given as the stiffness factor (the factor moves from c to the stiffness, a different
    product order, hence 1e-12 and not bit equality); its tangent matches central
    differences; the normal part is untouched."""
    law = InterfaceLaw(ExponentialNormal(), TS, ORTHO, h0=1e-3)
    rng = np.random.default_rng(12)
    n = 300
    st = random_state(rng, n)
    jump = np.column_stack([rng.uniform(-1e-3, 1e-3, n),
                            st.plastic_slip + rng.normal(size=(n, 2)) * 3e-5])
    lam = multipliers_for(law, jump, rng, 1.2)
    values = np.array([1.0, 4.0, 30.0])
    g = values[rng.integers(0, 3, n)]
    shifted = law.with_multipliers(lam, 2.0, g)
    r = shifted.evaluate(jump, st)
    for v in values:
        i = np.flatnonzero(g == v)
        sub = InterfaceState(st.plastic_slip[i], st.accumulated_slip[i], st.slip_path[i])
        ref = law.with_multipliers(lam[i], 2.0 * v).evaluate(jump[i], sub)
        np.testing.assert_allclose(r.traction[i], ref.traction, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(r.tangent[i], ref.tangent, rtol=1e-12, atol=1e-9)
        np.testing.assert_array_equal(r.slipping[i], ref.slipping)
    np.testing.assert_array_equal(r.traction[:, 0], law.evaluate(jump, st).traction[:, 0])
    assert 0.1 < r.slipping[r.contact].mean() < 0.9
    keep = np.abs(trial_ratio(law, jump, st, lam[:, 1:]) - 1.0) > 1e-4
    fd_check(shifted, jump, st, keep)
    with pytest.raises(ValueError, match=r"tangential_factor\[0\] = -1.0"):
        law.with_multipliers(lam, 1.0, -np.ones(n))
