"""One asperity: elliptic integrals, eccentricity, shape factors, Hertz, CEB/ZMC (eqs 27-77)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from rough_contact.micro import asperity as asp
from rough_contact.micro.asperity import AsperityMaterial


def test_abramowitz_stegun_approximations_within_stated_error():
    m1 = np.concatenate([np.logspace(-14, -1, 400), np.linspace(0.1, 1.0, 400)])
    K, E = asp.elliptic_integrals(m1, "as")
    Kx, Ex = special.ellipkm1(m1), special.ellipe(1 - m1)
    assert np.max(np.abs(K - Kx)) <= asp.AS_K_MAX_ERROR   # (36): |eps| <= 3e-5
    assert np.max(np.abs(E - Ex)) <= asp.AS_E_MAX_ERROR   # (38): |eps| <= 4e-5


def test_exact_elliptic_integrals_against_mpmath():
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 30
    for m1 in (1.0, 0.7, 0.1, 1e-3, 1e-12):
        K, E = asp.elliptic_integrals(np.array([m1]))
        m = 1 - mpmath.mpf(m1)
        assert K[0] == pytest.approx(float(mpmath.ellipk(m)), rel=1e-13)   # (28)
        assert E[0] == pytest.approx(float(mpmath.ellipe(m)), rel=1e-13)   # (48)


def test_eccentricity_inversion_roundtrip_and_symmetry():
    lam = np.exp(np.linspace(-300, 0, 301))
    e1 = asp.eccentricity_from_lambda(lam)
    assert np.all((e1 > 0) & (e1 <= 1))
    assert np.allclose(np.log(asp.lambda_from_e1(e1)), np.log(lam), rtol=0, atol=1e-12)
    assert np.allclose(asp.eccentricity_from_lambda(1.0 / lam), e1, rtol=1e-14)   # b > a
    # the cached spline ("table") used by the population sums
    lam2 = np.exp(np.linspace(-340, 0, 5001))
    t = asp.eccentricity_from_lambda(lam2, method="table")
    b = asp.eccentricity_from_lambda(lam2)
    assert np.max(np.abs(np.log(t) - np.log(b))) < 1e-9


def test_small_e1_expansion_32_and_paper_fit_33():
    # (31)-(32): lambda^2 = e1^2 (ln(4/e1) - 1) to O(e1^4 ln e1) for small e1
    e1 = np.array([1e-6, 1e-4])
    lam = asp.lambda_from_e1(e1)
    assert np.allclose(lam**2, e1**2 * (np.log(4 / e1) - 1), rtol=1e-6)
    # (33) is a rough fit: within 4 % of the exact inversion of (27) for 0.05 <= lambda <= 0.2
    # only (17 % off at lambda = 0.01, 35 % at 0.4); clipped to (0, 1] from lambda = 0.556
    lam = np.array([0.05, 0.1, 0.2])
    assert np.allclose(asp.eccentricity_from_lambda(lam, "paper"),
                       asp.eccentricity_from_lambda(lam), rtol=0.04)
    paper = asp.eccentricity_from_lambda(np.array([0.6, 0.757, 0.8, 0.99, 1.5]), "paper")
    assert np.all((paper > 0) & (paper <= 1)) and paper[1] == 1.0 and paper[2] == 1.0


def test_hertz_limit_f1_f2_and_ceb_limit_f3_f4():
    e1 = np.array([1.0, 1 - 1e-12, 1 - 1e-8, 1 - 1e-5])
    for el in ("exact",):
        f1, f2, f3, f4, KE = asp.shape_factors(e1, el)
        for f in (f1, f2, f3, f4):
            assert np.allclose(f, 1.0, atol=2e-5), f    # Hertz (46)-(47), CEB (58)
        assert KE[0] == pytest.approx((math.pi / 2) ** 2)
    f1, f2, f3, f4, _ = asp.shape_factors(np.array([1.0]), "as")
    for f in (f1, f2, f3, f4):
        assert abs(f[0] - 1.0) < 1e-4                   # A&S at the circle: its own 3e-5 error
    # f3, f4 stay finite and continuous across the series switch (m = 0.05)
    e1 = np.sqrt(1 - np.array([0.0499999, 0.0500001]))
    _, _, f3, f4, _ = asp.shape_factors(e1)
    assert abs(f3[0] - f3[1]) < 1e-6 and abs(f4[0] - f4[1]) < 1e-6


@pytest.mark.parametrize("ratio", [1.0, 0.9, 0.5, 0.1, 0.01])
def test_elliptic_hertz_against_johnson(ratio):
    """Johnson, Contact Mechanics, 4.2: ellipse a >= b, e^2 = 1 - b^2/a^2,
    A' = p0 b (K - E)/(E* a^2 e^2), B' = p0 (E - (b/a)^2 K)/(E* b e^2), delta = p0 b K/E*,
    P = (2/3) pi a b p0, for the gap z = A' x^2 + B' y^2."""
    E_star, p0, a = 2.0e5, 1500.0, 0.01
    b = ratio * a
    m = 1 - ratio**2
    K, E = special.ellipk(m), special.ellipe(m)
    if m > 0:
        Ap = p0 * b * (K - E) / (E_star * a**2 * m)
        Bp = p0 * (E - ratio**2 * K) / (E_star * b * m)
    else:
        Ap = Bp = p0 * math.pi / (4 * E_star * a)
    delta = p0 * b * K / E_star
    P = 2.0 / 3.0 * math.pi * a * b * p0
    kx, ky = 2 * Ap, 2 * Bp
    kappa = 0.5 * (kx + ky)                                   # (43)
    lam = math.sqrt(kx / ky)                                  # (27): lambda^2 = b_geo^2/a_geo^2
    e1 = asp.eccentricity_from_lambda(np.array([lam]))[0]
    assert e1 == pytest.approx(ratio, rel=1e-10)              # contact axis ratio B/A
    f1, f2, f3, f4, KE = asp.shape_factors(np.array([e1]))
    assert asp.hertz_area(delta, kappa, f1)[0] == pytest.approx(math.pi * a * b, rel=1e-9)
    assert asp.hertz_load(delta, kappa, f2, E_star)[0] == pytest.approx(P, rel=1e-9)
    # (62): maximum pressure p0 = (3/2) W/A = E* sqrt(kappa delta)/sqrt(K E)
    assert E_star * math.sqrt(kappa * delta / KE[0]) == pytest.approx(p0, rel=1e-9)
    # (54) is dW/domega
    d = 1e-6 * delta
    fd = (asp.hertz_load(delta + d, kappa, f2, E_star) - asp.hertz_load(delta - d, kappa, f2, E_star)) / (2 * d)
    assert asp.hertz_stiffness(delta, kappa, f2, E_star)[0] == pytest.approx(fd[0], rel=1e-7)


def test_critical_interference_gives_yield_pressure():
    mat = AsperityMaterial(E_star=1.14e5, nu=0.3, H=6000.0, Y=2070.0)
    kappa, e1 = 7.0, np.array([0.3])
    _, _, _, _, KE = asp.shape_factors(e1)
    wc = asp.critical_interference(kappa, KE, mat.yield_pressure, mat.E_star)
    pm = mat.E_star * np.sqrt(kappa * wc / KE)                # (62)
    assert pm[0] == pytest.approx(mat.K_Y * 2070.0, rel=1e-12)  # (63)
    assert mat.K_Y == pytest.approx(1.282 + 1.158 * 0.3)        # (64); "K = 1.62" of the captions


@pytest.mark.parametrize("e1", [1.0, 0.4, 0.02])
def test_zmc_transition_continuity_and_stiffness(e1):
    mat = AsperityMaterial(E_star=1.14e5, nu=0.3, H=6000.0)
    kappa = 7.0
    r0 = asp.asperity_response(np.array([1e-9]), kappa, np.array([e1]), mat)
    wc, wp = float(r0["omega_c"][0]), float(r0["omega_p"][0])
    eps = 1e-9
    f = lambda w: asp.asperity_response(np.asarray(w, float), kappa, np.array([e1]), mat)  # noqa: E731
    # area continuous at omega_c and omega_p (ZMC smoothstep); load continuous at omega_p
    a = f([wc * (1 - eps), wc * (1 + eps), wp * (1 - eps), wp * (1 + eps)])
    assert a["area"][0] == pytest.approx(a["area"][1], rel=1e-6)
    assert a["area"][2] == pytest.approx(a["area"][3], rel=1e-6)
    assert a["load"][2] == pytest.approx(a["load"][3], rel=1e-6)
    # load jump at omega_c: (2/3) K_nu H A - W_e (zero only if K_Y Y = K_nu H)
    assert a["load"][1] - a["load"][0] == pytest.approx(a["jump"][0], rel=1e-5)
    # fully plastic (61), (67): A = 2 pi f3 omega/kappa, W = ch H A
    _, _, f3, _, _ = asp.shape_factors(np.array([e1]))
    pl = f([3 * wp])
    assert pl["area"][0] == pytest.approx(2 * math.pi * f3[0] * 3 * wp / kappa, rel=1e-12)
    assert pl["load"][0] == pytest.approx(0.967 * 6000.0 * pl["area"][0], rel=1e-12)
    # mean pressure (75) runs from (2/3) K_nu H at omega_c to ch H at omega_p
    pa, _ = asp.zmc_mean_pressure(np.array([wc, wp]), wc, mat)
    assert pa[0] == pytest.approx(2 / 3 * mat.K_nu * 6000.0) and pa[1] == pytest.approx(0.967 * 6000.0)
    # stiffness = dW/domega inside each regime
    for w in (0.5 * wc, 2 * wc, 10 * wc, 44 * wc, 60 * wc):
        d = 1e-6 * w
        fd = (f([w + d])["load"] - f([w - d])["load"]) / (2 * d)
        assert f([w])["stiffness"][0] == pytest.approx(fd[0], rel=1e-6)


def test_material_conventions_and_errors():
    m = AsperityMaterial(E_star=1e5, H=3000.0)
    assert m.yield_pressure == pytest.approx(2 / math.pi * 3000.0)   # K_Y Y = (2/pi) H
    m = AsperityMaterial(E_star=1e5, Y=1000.0)
    assert m.H == pytest.approx(1000.0 / 0.354)                     # Tabor (68)
    assert m.K_nu == pytest.approx(0.454 + 0.41 * 0.3)
    with pytest.raises(ValueError, match="nu"):
        AsperityMaterial(E_star=1e5, nu=0.5, H=1.0)
    with pytest.raises(ValueError, match="nu"):
        AsperityMaterial(E_star=1e5, nu=-1.0, H=1.0)
    with pytest.raises(ValueError, match="E_star"):
        AsperityMaterial(E_star=-1.0, H=1.0)
    with pytest.raises(ValueError, match="H"):
        AsperityMaterial(E_star=1e5, H=0.0)
    with pytest.raises(ValueError, match="Y"):
        AsperityMaterial(E_star=1e5, H=1.0, Y=float("nan"))
    with pytest.raises(ValueError, match="psi"):
        AsperityMaterial(E_star=1e5, H=1.0, psi=1.0)
    with pytest.raises(ValueError, match="psi"):
        AsperityMaterial(E_star=1e5)
    with pytest.raises(ValueError, match="omega_p_ratio"):
        AsperityMaterial(E_star=1e5, H=1.0, omega_p_ratio=1.0)
    with pytest.raises(ValueError, match="surface"):
        AsperityMaterial(E_star=1e5, psi=1.0).resolve()
    with pytest.raises(ValueError, match="lambda"):
        asp.eccentricity_from_lambda(np.array([0.0]))
    with pytest.raises(ValueError, match="method"):
        asp.eccentricity_from_lambda(np.array([0.5]), method="guess")
    with pytest.raises(ValueError, match="m1"):
        asp.elliptic_integrals(np.array([0.0]))
    with pytest.raises(ValueError, match="NaN"):
        asp.shape_factors(np.array([np.nan]))


def test_hermite_shape_table_against_the_exact_inversion():
    # table="hermite" (the advisor's numpy-only table) against the shape factors at the exact
    # inversion of (27) by bisection (an independent route): within 2e-7 on [e^-40, 1], exact
    # beyond; lambda > 1 maps to 1/lambda; the spline default is untouched
    rng = np.random.default_rng(3)
    lam = np.exp(np.concatenate([-rng.uniform(0.0, 40.0, 2000), -rng.uniform(0.0, 1e-3, 200),
                                 [0.0, -1e-12, -39.999999, -40.0, -40.000001, -120.0]]))
    f1, f2, f3, _, KE = asp.shape_factors(asp.eccentricity_from_lambda(lam))
    exact = np.stack([f1, f2, f3, KE])
    fast = np.stack(asp.shape_factors_from_lambda(lam, table="hermite"))
    assert np.max(np.abs(fast / exact - 1.0)) < 2e-7
    assert np.allclose(np.stack(asp.shape_factors_from_lambda(1.0 / lam, table="hermite")),
                       fast, rtol=1e-12, atol=0)
    spline = np.stack(asp.shape_factors_from_lambda(lam))
    assert np.max(np.abs(spline / exact - 1.0)) < 1e-9
    with pytest.raises(ValueError, match="table = 'cubic'"):
        asp.shape_factors_from_lambda(lam, table="cubic")
