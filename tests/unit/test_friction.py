"""Slip-hardening friction (paper 8.1, 8.2): material-point drivers, return map, tangents."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from rough_contact.interface.friction import (
    FrictionInput,
    IsotropicSlipHardening,
    OrthotropicSlipHardening,
    continuum_tangent,
    directional_coefficient,
    limit_coefficient,
    traction_angle,
)


def mu_axis(mu_m, mu_o, n, kappa):
    """(89)/(90)/(119) written out independently."""
    return mu_m * (1.0 - (1.0 - mu_o) * np.exp(-n * kappa))


class Point:
    """Friction-level material point at constant pressure p and stiffnesses kt (2,)."""

    def __init__(self, law, p, kt, m=1):
        self.law, self.p, self.kt = law, np.full(m, p), np.tile(np.asarray(kt, float), (m, 1))
        self.sp = np.zeros((m, 2))
        self.kap = np.zeros((m, 2))
        self.path = np.zeros(m)

    def step(self, s):
        s = np.atleast_2d(np.asarray(s, float))
        r = self.law.evaluate(FrictionInput.from_pairs(
            s - self.sp, self.kt, np.zeros_like(self.kt), self.p, np.zeros_like(self.p), self.kap,
            self.path))
        self.sp = self.sp + r.plastic_increment
        self.kap = self.kap + np.abs(r.plastic_increment)
        self.path = self.path + np.hypot(*r.plastic_increment.T)
        return r


LAW = OrthotropicSlipHardening(mu_macro=(0.3, 0.5), mu_initial_ratio=(0.5, 0.6),
                               hardening=(275.0, 120.0), potential_axes=(0.125, 0.2))


@pytest.mark.parametrize("axis", [0, 1])
def test_monotonic_sliding_along_an_axis_follows_hardening_curve(axis):
    p, kt = 2.0, (4000.0, 6000.0)
    pt = Point(LAW, p, kt)
    s_path = np.linspace(0, 0.03, 301)
    onset = p * LAW.mu_macro[axis] * LAW.mu_initial_ratio[axis] / kt[axis]
    for s in s_path[1:]:
        jump = np.zeros(2)
        jump[axis] = s
        r = pt.step(jump)
        t = r.traction[0, axis]
        assert r.traction[0, 1 - axis] == 0.0
        if s <= onset * (1 - 1e-9):
            assert not r.slipping[0] and t == pytest.approx(kt[axis] * s, rel=1e-14)
            continue
        assert r.slipping[0] or s <= onset * (1 + 1e-9)
        # oracle: t = p mu(kappa), kappa = s - t/k  (slip along one axis only), solved by brentq
        mm, mo, n = LAW.mu_macro[axis], LAW.mu_initial_ratio[axis], LAW.hardening[axis]
        t_ref = brentq(lambda tt: tt - p * mu_axis(mm, mo, n, s - tt / kt[axis]), 0, kt[axis] * s,
                       xtol=1e-15, rtol=1e-15)
        assert t == pytest.approx(t_ref, rel=1e-12)
        # and the state reproduces (89)/(90) as a function of the plastic slip
        assert pt.sp[0, axis] == pytest.approx(s - t / kt[axis], rel=1e-12, abs=1e-16)
        assert t / p == pytest.approx(mu_axis(mm, mo, n, pt.kap[0, axis]), rel=1e-12)


def test_uniaxial_result_independent_of_step_size():
    p, kt = 1.0, (3000.0, 3000.0)
    one, many = Point(LAW, p, kt), Point(LAW, p, kt)
    r1 = one.step([0.02, 0.0])
    for s in np.linspace(0, 0.02, 57)[1:]:
        rn = many.step([s, 0.0])
    np.testing.assert_allclose(r1.traction, rn.traction, rtol=1e-12)
    np.testing.assert_allclose(one.sp, many.sp, rtol=1e-12)


@pytest.mark.parametrize("theta_deg", [10, 30, 45, 60, 80, 135, 200, 300])
def test_sliding_at_angle_obeys_eq118_and_yield(theta_deg):
    p, kt = 1.5, (5000.0, 3500.0)
    pt = Point(LAW, p, kt)
    th = np.radians(theta_deg)
    direction = np.array([np.cos(th), np.sin(th)])
    nux, nuy = LAW.potential_axes
    slipped = 0
    for s in np.linspace(0, 0.02, 81)[1:]:
        kap_old = pt.kap.copy()
        r = pt.step(s * direction)
        if not r.slipping[0]:
            continue
        slipped += 1
        dsp = r.plastic_increment[0]
        alpha = np.arctan2(dsp[1], dsp[0])
        beta = np.arctan2(r.traction[0, 1], r.traction[0, 0])
        # (118): tan(beta) = tan(alpha) (nu_y/nu_x)^2, same quadrant
        assert np.tan(beta) == pytest.approx(np.tan(alpha) * (nuy / nux) ** 2, rel=1e-10)
        assert np.cos(beta) * np.cos(alpha) > 0
        assert traction_angle(alpha, nux, nuy) == pytest.approx(beta, abs=1e-12)
        # on the slip ellipse (91) with mu from (89)-(90) at the accumulated slip
        mu = [mu_axis(LAW.mu_macro[i], LAW.mu_initial_ratio[i], LAW.hardening[i], pt.kap[0, i])
              for i in range(2)]
        f = np.hypot(r.traction[0, 0] / mu[0], r.traction[0, 1] / mu[1]) - p
        assert abs(f) <= 1e-12 * p
        assert np.hypot(*r.traction[0]) / p == pytest.approx(limit_coefficient(*mu, beta), rel=1e-12)
        assert np.all(pt.kap >= kap_old)
        assert r.traction[0] @ dsp >= 0.0
    assert slipped > 50


def test_associated_rule_matches_directional_coefficient_115():
    law = OrthotropicSlipHardening(mu_macro=(0.2, 0.6), potential_exponent=1.0)  # nu = mu
    for th in np.radians([5, 25, 50, 70, 85]):
        pt = Point(law, 1.0, (1e4, 1e4))
        r = pt.step(0.01 * np.array([np.cos(th), np.sin(th)]))
        dsp = r.plastic_increment[0]
        alpha = np.arctan2(dsp[1], dsp[0])
        assert np.hypot(*r.traction[0]) == pytest.approx(directional_coefficient(0.2, 0.6, alpha),
                                                         rel=1e-12)


def test_circle_potential_gives_coaxial_slip():
    law = OrthotropicSlipHardening(mu_macro=(0.2, 0.6), potential_exponent=0.0)
    pt = Point(law, 1.0, (1e4, 2e4))
    r = pt.step([0.01, 0.02])
    dsp = r.plastic_increment[0]
    cross = dsp[0] * r.traction[0][1] - dsp[1] * r.traction[0][0]     # z of the 2D cross product
    assert cross == pytest.approx(0.0, abs=1e-14 * np.hypot(*dsp))


@pytest.mark.parametrize("law", [
    LAW, IsotropicSlipHardening(0.4, 0.5, 300.0)], ids=["ortho", "iso"])
def test_stick_unload_reverse(law):
    p, kt = 1.0, (4000.0, 4000.0)
    pt = Point(law, p, kt)
    # small load: stick
    r = pt.step([1e-6, 0.0])
    assert not r.slipping[0] and r.traction[0, 0] == pytest.approx(4000 * 1e-6)
    s_max = 0.01
    hist = []
    for s in np.concatenate([np.linspace(0, s_max, 41)[1:], np.linspace(s_max, -s_max, 801)[1:]]):
        kap_old, path_old = pt.kap.copy(), pt.path.copy()
        r = pt.step([s, 0.0])
        hist.append((s, r.traction[0, 0], r.slipping[0]))
        assert np.all(pt.kap >= kap_old) and np.all(pt.path >= path_old)  # no reversal of hardening
    hist = np.array(hist)
    t_peak = hist[39, 1]
    # unloading starts elastically (stick) with slope kT
    assert not hist[40, 2]
    assert hist[40, 1] == pytest.approx(t_peak - 4000 * (s_max - hist[40, 0]), rel=1e-12)
    # the traction changes sign while the total slip is still positive (paper, section 9.2)
    i_sign = np.flatnonzero(hist[40:, 1] < 0)[0] + 40
    assert hist[i_sign, 0] > 0
    # reverse slip against the hardened coefficient (no softening on reversal)
    assert hist[-1, 2] and hist[-1, 1] < 0 and abs(hist[-1, 1]) >= t_peak * (1 - 1e-12)


def test_isotropic_zero_deviation_and_radial_vs_general():
    iso = IsotropicSlipHardening(0.35, 0.4, 500.0)
    rng = np.random.default_rng(3)
    m = 500
    e = rng.normal(size=(m, 2)) * 1e-3
    kap = np.zeros((m, 2))
    path = rng.uniform(0, 0.005, m)
    p = rng.uniform(0.1, 3, m)
    kt = np.full((m, 2), 3000.0)
    r = iso.evaluate(FrictionInput.from_pairs(e, kt, np.zeros_like(kt), p, np.zeros(m), kap, path))
    s = r.slipping
    assert s.sum() > 100
    cross = r.traction[s, 0] * r.plastic_increment[s, 1] - r.traction[s, 1] * r.plastic_increment[s, 0]
    assert np.abs(cross).max() <= 1e-14 * np.abs(r.traction[s]).max() * np.abs(r.plastic_increment[s]).max()
    # radial closed form (kTx == kTy) equals the general scalar map (kTx != kTy by 1 ulp-ish)
    kt2 = kt.copy()
    kt2[:, 1] *= 1 + 1e-13
    r2 = iso.evaluate(FrictionInput.from_pairs(e, kt2, np.zeros_like(kt), p, np.zeros(m), kap,
                                               path))
    np.testing.assert_allclose(r2.traction, r.traction, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(r2.tangent, r.tangent, rtol=1e-8, atol=1e-6)


def test_isotropic_equals_orthotropic_for_slip_along_axis():
    """Along x, per-axis and path hardening coincide: the two laws must agree."""
    iso = IsotropicSlipHardening(0.4, 0.5, 300.0)
    ort = OrthotropicSlipHardening((0.4, 0.4), (0.5, 0.5), (300.0, 300.0))
    a, b = Point(iso, 2.0, (5e3, 5e3)), Point(ort, 2.0, (5e3, 5e3))
    for s in np.linspace(0, 0.01, 30)[1:]:
        ra, rb = a.step([s, 0]), b.step([s, 0])
        np.testing.assert_allclose(ra.traction, rb.traction, rtol=1e-12)


def test_symmetry_swap_axes_and_asymmetry_of_kt():
    law = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.6), (275.0, 120.0), potential_axes=(0.1, 0.3))
    swapped = OrthotropicSlipHardening((0.5, 0.3), (0.6, 0.5), (120.0, 275.0), potential_axes=(0.3, 0.1))
    a, b = Point(law, 1.0, (3e3, 5e3)), Point(swapped, 1.0, (5e3, 3e3))
    for s in np.linspace(0, 0.01, 40)[1:]:
        ra = a.step([s, 0.4 * s])
        rb = b.step([0.4 * s, s])
        np.testing.assert_allclose(ra.traction[:, ::-1], rb.traction, rtol=1e-12, atol=1e-15)
    # symmetric parameters, same stiffness: x and y behave alike; kTx != kTy breaks it
    sym = OrthotropicSlipHardening((0.5, 0.5), (0.5, 0.5), (275.0, 275.0), potential_axes=(0.125, 0.125))
    px, py = Point(sym, 1.0, (0.7e4, 0.7e4)), Point(sym, 1.0, (0.7e4, 0.7e4))
    qx, qy = Point(sym, 1.0, (0.7e4, 1.0e4)), Point(sym, 1.0, (0.7e4, 1.0e4))
    for s in np.linspace(0, 1e-4, 21)[1:]:
        rx, ry = px.step([s, 0]), py.step([0, s])
        assert rx.traction[0, 0] == pytest.approx(ry.traction[0, 1], rel=1e-14)
        ux, uy = qx.step([s, 0]), qy.step([0, s])
    # stiffer along y: the same total slip gives more traction and more plastic slip along y
    assert uy.traction[0, 1] > ux.traction[0, 0]
    assert qy.sp[0, 1] > qx.sp[0, 0]


# ---------------------------------------------------------------------------- tangents
def _random_problem(rng, m, scale_e=1e-3):
    z = np.column_stack([rng.uniform(-1e-3, 1e-3, m), rng.normal(size=(m, 2)) * scale_e])
    kap = rng.uniform(0, 0.01, (m, 2))
    path = rng.uniform(0, 0.01, m)
    return z, kap, path


def _eval(law, z, kap, path, c, l=1e-3, p0=5.0):
    """Friction at jumps z = (g, e_x, e_y) with p = p0 exp(-g/l), kT = c kN(g)."""
    g = z[:, 0]
    p = p0 * np.exp(-g / l)
    kn = p / l
    dk = -kn / l
    return law.evaluate(FrictionInput.from_pairs(z[:, 1:], c * kn[:, None], c * dk[:, None], p,
                                                 kn, kap, path))


LAWS = {
    "ortho_fixed": OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (200.0, 50.0), potential_axes=(0.1, 0.2)),
    "ortho_k": OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (200.0, 50.0), potential_exponent=0.5),
    "ortho_perfect": OrthotropicSlipHardening((0.3, 0.5), potential_axes=(1.0, 3.0)),
    "iso": IsotropicSlipHardening(0.4, 0.5, 300.0),
    "iso_perfect": IsotropicSlipHardening(0.4),
}


@pytest.mark.parametrize("name", sorted(LAWS))
@pytest.mark.parametrize("c", [(0.7, 1.0), (0.7, 0.7)])
def test_algorithmic_tangent_equals_central_difference(name, c):
    law, c = LAWS[name], np.array(c)
    rng = np.random.default_rng(11)
    z, kap, path = _random_problem(rng, 3000, 3e-4)
    r = _eval(law, z, kap, path, c)
    # keep points away from the stick/slip switch (the map is only piecewise smooth)
    f_trial = _eval(law, z, kap, path, c)  # same call; recompute trial f below
    kn = 5 * np.exp(-z[:, 0] / 1e-3) / 1e-3
    ttr = c * kn[:, None] * z[:, 1:]
    if isinstance(law, OrthotropicSlipHardening):
        mu, _ = law.coefficients(kap)
        ntr = np.hypot(ttr[:, 0] / mu[:, 0], ttr[:, 1] / mu[:, 1])
    else:
        mu, _ = law.coefficient(path)
        ntr = np.hypot(*ttr.T) / mu
    p = 5 * np.exp(-z[:, 0] / 1e-3)
    keep = np.abs(ntr / p - 1) > 1e-4
    assert r.slipping[keep].sum() > 200 and (~r.slipping[keep]).sum() > 200
    del f_trial
    D = r.tangent
    for j in range(3):
        h = 1e-8 * (1e-3 if j == 0 else 3e-4)
        zp, zm = z.copy(), z.copy()
        zp[:, j] += h
        zm[:, j] -= h
        fd = (_eval(law, zp, kap, path, c).traction - _eval(law, zm, kap, path, c).traction) / (2 * h)
        scale = np.abs(D).max(axis=(1, 2))
        err = np.abs(fd - D[:, :, j]).max(axis=1) / scale
        assert err[keep].max() <= 1e-6, (name, j, err[keep].max())


@pytest.mark.parametrize("name", sorted(LAWS))
def test_after_return_f_zero_and_dissipation_nonnegative(name):
    law = LAWS[name]
    rng = np.random.default_rng(5)
    z, kap, path = _random_problem(rng, 4000)
    z[:, 1:] *= 10.0 ** rng.uniform(-6, 6, (4000, 1))  # slip increments over 12 decades
    r = _eval(law, z, kap, path, np.array([0.7, 1.0]))
    p = 5 * np.exp(-z[:, 0] / 1e-3)
    s = r.slipping
    assert s.sum() > 1000
    if isinstance(law, OrthotropicSlipHardening):
        f = law.slip_function(r.traction, p, kap + np.abs(r.plastic_increment))
    else:
        f = law.slip_function(r.traction, p, path + np.hypot(*r.plastic_increment.T))
    assert np.abs(f[s]).max() <= 1e-12 * p[s].max() and np.all(np.abs(f[s]) <= 1e-12 * p[s])
    assert np.all(f[~s] <= 0)
    assert np.all(np.einsum("ij,ij->i", r.traction, r.plastic_increment) >= 0)


def test_continuum_tangent_is_small_increment_limit():
    """(107)-(110) is the limit of the algorithmic tangent for a vanishing slip increment."""
    law = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (200.0, 50.0), potential_axes=(0.1, 0.2))
    rng = np.random.default_rng(2)
    m = 50
    th = rng.uniform(0, 2 * np.pi, m)
    p = np.full(m, 2.0)
    kt = np.column_stack([np.full(m, 4e3), np.full(m, 6e3)])
    kap = rng.uniform(0, 0.005, (m, 2))
    mu, dmu = law.coefficients(kap)
    # a trial state just outside the yield ellipse, along a direction theta
    t_on = p[:, None] * np.column_stack([np.cos(th), np.sin(th)]) * limit_coefficient(
        mu[:, 0], mu[:, 1], th)[:, None]
    for delta, tol in [(1e-4, 2e-3), (1e-6, 2e-5)]:
        e = t_on * (1 + delta) / kt
        r = law.evaluate(FrictionInput.from_pairs(e, kt, np.zeros_like(kt), p, np.zeros(m), kap,
                                                  np.zeros(m)))
        assert r.slipping.all()
        mu1, dmu1 = law.coefficients(kap + np.abs(r.plastic_increment))
        Dc = continuum_tangent(r.traction, p, np.full(m, 1e4), kt, mu1, dmu1, law.potential_axes)
        # compare tangential rows w.r.t. slips (normal coupling: use kn = 1e4 in both)
        r_kn = law.evaluate(FrictionInput.from_pairs(e, kt, np.zeros_like(kt), p, np.full(m, 1e4),
                                                     kap, np.zeros(m)))
        diff = np.abs(Dc[:, 1:, :] - r_kn.tangent).max(axis=(1, 2)) / np.abs(Dc).max(axis=(1, 2))
        assert diff.max() <= tol, (delta, diff.max())


# ---------------------------------------------------------------------------- extremes
def test_extreme_parameters_stay_finite():
    rng = np.random.default_rng(7)
    m = 300
    for mu_m in (1e-6, 1e-2, 10.0):
        for nu_ratio in (1e-3, 1.0, 1e3):
            for n in (0.0, 1.0, 1e6):
                for c in ((1e-6, 1e-6), (1e-6, 1e3), (1e3, 1.0)):
                    for law in (OrthotropicSlipHardening((mu_m, 2 * mu_m), (0.3, 0.9), (n, n / 2),
                                                         potential_axes=(1.0, nu_ratio)),
                                IsotropicSlipHardening(mu_m, 0.3, n)):
                        e = rng.normal(size=(m, 2)) * 10.0 ** rng.uniform(-9, 3, (m, 1))
                        p = 10.0 ** rng.uniform(-30, 2, m)
                        p[:5] = 5e-324
                        p[5:8] = 0.0
                        kn = 10.0 ** rng.uniform(-3, 6, m)
                        kt = np.asarray(c) * kn[:, None]
                        kap = rng.uniform(0, 1e-2, (m, 2))
                        path = kap.sum(axis=1)
                        r = law.evaluate(FrictionInput.from_pairs(e, kt, -kt, p, kn, kap, path))
                        for arr in (r.traction, r.tangent, r.plastic_increment):
                            assert np.isfinite(arr).all(), (mu_m, nu_ratio, n, c)
                        if isinstance(law, OrthotropicSlipHardening):
                            f = law.slip_function(r.traction, p, kap + np.abs(r.plastic_increment))
                            mu_max = max(law.mu_macro)
                        else:
                            f = law.slip_function(r.traction, p, path + np.hypot(*r.plastic_increment.T))
                            mu_max = law.mu_macro
                        assert np.all(f <= 1e-11 * p * max(1.0, mu_max) + 1e-300), (mu_m, nu_ratio, n, c)


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, name", [
    (dict(mu_macro=(-0.1, 0.2)), "mu_macro"),
    (dict(mu_macro=(0.0, 0.2)), "mu_macro"),
    (dict(mu_macro=(0.1, np.nan)), "mu_macro"),
    (dict(mu_macro=(0.1, 0.2), mu_initial_ratio=(0.0, 1.0)), "mu_initial_ratio"),
    (dict(mu_macro=(0.1, 0.2), mu_initial_ratio=(0.5, 1.5)), "mu_initial_ratio"),
    (dict(mu_macro=(0.1, 0.2), hardening=(-1.0, 0.0)), "hardening"),
    (dict(mu_macro=(0.1, 0.2), potential_axes=(0.0, 1.0)), "potential_axes"),
    (dict(mu_macro=(0.1, 0.2, 0.3)), "mu_macro"),
    (dict(mu_macro=(0.1, 0.2), potential_axes=(1, 1), potential_exponent=1.0), "potential"),
])
def test_bad_orthotropic_parameters(kwargs, name):
    with pytest.raises(ValueError, match=name):
        OrthotropicSlipHardening(**kwargs)


@pytest.mark.parametrize("args, name", [
    ((-0.1,), "mu_macro"), ((0.1, 0.0), "mu_initial_ratio"), ((0.1, 1.01), "mu_initial_ratio"),
    ((0.1, 0.5, -3.0), "hardening"), ((np.inf,), "mu_macro"),
])
def test_bad_isotropic_parameters(args, name):
    with pytest.raises(ValueError, match=name):
        IsotropicSlipHardening(*args)


def test_bad_return_map_inputs():
    law = LAWS["ortho_fixed"]
    m = 4
    good = dict(elastic_slip=np.zeros((m, 2)), kt=np.ones((m, 2)), dkt=np.zeros((m, 2)),
                pressure=np.ones(m), kn=np.ones(m), accumulated_slip=np.zeros((m, 2)),
                slip_path=np.zeros(m))
    for key, bad in [("elastic_slip", np.zeros((m, 3))), ("kt", np.ones(m)), ("pressure", np.ones((m, 1))),
                     ("accumulated_slip", np.zeros((m + 1, 2))), ("slip_path", np.zeros((m, 2))),
                     ("kn", np.ones(m + 1)), ("dkt", np.zeros((2, m)))]:
        with pytest.raises(ValueError, match=key):
            law.evaluate(FrictionInput.from_pairs(**{**good, key: bad}))
    with pytest.raises(ValueError, match="pressure"):
        law.evaluate(FrictionInput.from_pairs(**{**good, "pressure": -np.ones(m)}))
    with pytest.raises(ValueError, match="kt"):
        law.evaluate(FrictionInput.from_pairs(**{**good, "kt": np.zeros((m, 2))}))


def test_nonconvergence_is_reported(monkeypatch):
    import rough_contact.interface.friction as fr

    monkeypatch.setattr(fr, "_MAX_ITER", 1)
    law = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (200.0, 50.0), potential_axes=(0.1, 0.2))
    m = 10
    e = np.column_stack([np.linspace(1e-3, 2e-3, m), np.linspace(-1e-3, 1e-3, m)])
    with pytest.raises(fr.ReturnMappingError, match=r"did not converge at \d+ of 10 slipping points"):
        law.evaluate(FrictionInput.from_pairs(
            e, np.full((m, 2), 1e4), np.zeros((m, 2)), np.ones(m), np.zeros(m),
            np.zeros((m, 2)), np.zeros(m)))
