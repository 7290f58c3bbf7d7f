"""One elliptic-paraboloid asperity against a rigid flat (paper sections 3, 5 and 6).

Contents:
    * complete elliptic integrals K, E: exact (scipy ``ellipkm1``/``ellipe``) or the paper's
      Abramowitz & Stegun polynomial approximations (36)-(39);
    * the contact-ellipse eccentricity from the geometric axis ratio lambda = b/a, eq (27):
      exact inversion (vectorised bisection in log e1, lambda > 1 mapped to 1/lambda) or
      the paper's approximation (33) clipped to (0, 1];
    * shape factors f1, f2 (46)-(47) and f3, f4 (59)-(60) with their e -> 0 limits;
    * elliptic Hertz area, load and stiffness (46), (47), (54);
    * critical interference (65), the Zhao-Maietta-Chang elasto-plastic transition (75)-(77)
      and the fully plastic area/load (61), (67).

Notation: m = e^2 (elliptic parameter, scipy's convention), m1 = 1 - m = e1^2 with
e1 = B/A <= 1 the axis ratio of the contact ellipse (30).

Units: lengths in mm, curvatures in mm^-1, moduli / pressures in MPa, loads in N,
stiffness dW/domega in N/mm.

Material constants (``AsperityMaterial``): ``K_Y = 1.282 + 1.158 nu`` is the maximum
contact pressure coefficient at first yield, p_m = K_Y Y (63)-(64) (the "K = 1.62" of the
paper's figure captions is K_Y at nu = 0.3); ``K_nu = 0.454 + 0.41 nu`` enters the
elasto-plastic mean pressure (75); ``ch = 0.967`` is the fully plastic pressure coefficient
(66); ``omega_p/omega_c = 45``. The hardness H and yield strength Y are related either as
the user gives them, or (when only one is given) by the paper's conventions: from H,
``K_Y Y = (2/pi) H`` (the only reading under which the paper's nondimensional critical
interference (74)/(87) follows from (65), (69), (70); see ``docs/equations.md``); from Y,
Tabor's ``Y = 0.354 H`` (68).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import special

from ..validation import check_scalar

__all__ = [
    "AsperityMaterial", "elliptic_integrals", "eccentricity_from_lambda", "lambda_from_e1",
    "shape_factors", "shape_factors_from_lambda", "hertz_area", "hertz_load", "hertz_stiffness", "critical_interference",
    "zmc_mean_pressure", "zmc_area", "plastic_area", "plastic_load", "asperity_response",
]

# Abramowitz & Stegun 17.3.34 / 17.3.36, as printed in eqs (37), (39). A&S gives
# a2 = 0.1077812 for E; the paper prints 0.10778112 (a typo) -- we use A&S's value.
_AS_K = (1.3862944, 0.1119723, 0.0725296, 0.5, 0.1213478, 0.0288729)
_AS_E = (1.0, 0.4630151, 0.1077812, 0.0, 0.2452727, 0.0412496)
AS_K_MAX_ERROR = 3e-5  # stated |eps(m)| bounds of (36), (38)
AS_E_MAX_ERROR = 4e-5

_LOG_E1_MIN = -350.0   # e1 >= e^-350 so that m1 = e1^2 stays a normal double
_M_SERIES = 0.05       # below this m the 0/0 combinations use their power series
_HERMITE_KNOTS = 2001  # knots of the numpy-only shape-factor table (table="hermite"),
_HERMITE_U_MIN = -40.0  # uniform in ln(lambda) on [-40, 0]


def _as_array(x, name):
    x = np.asarray(x, dtype=float)
    if np.any(np.isnan(x)):
        raise ValueError(f"{name} contains NaN: it must be a finite number")
    return x


def elliptic_integrals(m1, method: str = "exact"):
    """Complete elliptic integrals K and E as functions of the complementary parameter.

    Args:
        m1: complementary parameter m1 = 1 - e^2 = e1^2 in (0, 1], array [-]. Passing m1
            (not m) keeps full accuracy for very eccentric ellipses (m1 -> 0).
        method: "exact" (scipy.special.ellipkm1 / ellipe) or "as" (A&S polynomial
            approximations (36)-(39), |error| <= 3e-5 (K) and 4e-5 (E)).
    Returns:
        (K, E) arrays, shape of m1.
    """
    m1 = _as_array(m1, "m1")
    if np.any((m1 <= 0) | (m1 > 1)):
        raise ValueError(f"m1 in [{m1.min()}, {m1.max()}] is invalid: valid range is (0, 1]")
    if method == "exact":
        return special.ellipkm1(m1), special.ellipe(1.0 - m1)
    if method == "as":
        L = -np.log(m1)
        a0, a1, a2, b0, b1, b2 = _AS_K
        K = a0 + m1 * (a1 + a2 * m1) + (b0 + m1 * (b1 + b2 * m1)) * L
        a0, a1, a2, b0, b1, b2 = _AS_E
        E = a0 + m1 * (a1 + a2 * m1) + m1 * (b1 + b2 * m1) * L
        return K, E
    raise ValueError(f"method = {method!r} is invalid: valid methods are 'exact' and 'as'")


@lru_cache(maxsize=1)
def _series_coefficients(n: int = 24):
    """Power-series coefficients (in m) of (K - E)/m and (E - (1 - m) K)/m, times 2/pi."""
    cK = np.empty(n + 2)
    cK[0] = 1.0
    for k in range(1, n + 2):
        cK[k] = cK[k - 1] * ((2 * k - 1) / (2 * k)) ** 2
    ks = np.arange(n + 2)
    cE = -cK / (2 * ks - 1)
    # (K - E) = sum_k (cK_k - cE_k) m^k, k >= 1 -> divided by m: index shift
    kme = (cK - cE)[1:n + 1]
    # E - (1-m) K = sum_k (cE_k - cK_k + cK_{k-1}) m^k, k >= 1
    g = (cE[1:n + 1] - cK[1:n + 1] + cK[0:n])
    return kme, g


def _G_H(m1, K, E):
    """G = (E - m1 K)/m and Hh = (K - E)/m, exact series for small m (0/0 at m = 0)."""
    m = 1.0 - m1
    small = m < _M_SERIES
    with np.errstate(divide="ignore", invalid="ignore"):
        G = (E - m1 * K) / m
        Hh = (K - E) / m
    if np.any(small):
        kme, g = _series_coefficients()
        ms = m[small]
        G = np.array(G, copy=True)
        Hh = np.array(Hh, copy=True)
        G[small] = np.polynomial.polynomial.polyval(ms, g) * (np.pi / 2)
        Hh[small] = np.polynomial.polynomial.polyval(ms, kme) * (np.pi / 2)
    return G, Hh


def lambda_from_e1(e1):
    """Geometric axis ratio lambda = b/a <= 1 from the contact axis ratio e1 = B/A, eq (27).

    lambda^2 = (1 - e^2)(K - E)/(E - (1 - e^2) K), exact K, E (series near the circle).

    Args:
        e1: contact-ellipse axis ratio in (0, 1] [-].
    Returns:
        lambda in (0, 1], shape of e1.
    """
    e1 = np.clip(_as_array(e1, "e1"), math.exp(_LOG_E1_MIN), 1.0)
    m1 = e1 * e1
    K, E = elliptic_integrals(m1, "exact")
    G, Hh = _G_H(m1, K, E)
    return np.sqrt(m1 * Hh / G)


def _log_lambda_of_log_e1(y):
    return np.log(lambda_from_e1(np.exp(y)))


def _canonical_lambda(lam):
    lam = _as_array(lam, "lambda")
    if np.any(lam <= 0) or np.any(~np.isfinite(lam)):
        raise ValueError("lambda (axis ratio b/a) must be finite and > 0")
    return np.where(lam > 1.0, 1.0 / lam, lam)


def eccentricity_from_lambda(lam, method: str = "exact", iterations: int = 64):
    """Contact-ellipse axis ratio e1 = B/A = sqrt(1 - e^2) from lambda = b/a.

    lambda > 1 (b > a) is mapped to 1/lambda: the shape factors are symmetric under swapping
    the axes.

    Args:
        lam: geometric axis ratio b/a > 0, array [-].
        method: "exact" -- inversion of (27) by vectorised bisection in log e1 on
            [-350, 0] (``iterations`` halvings, 64 give ~2e-17 in log e1);
            "paper" -- eq (33), e1 = 0.4777 lambda/(1 - 1.3211 lambda), clipped to (0, 1]
            (it has a pole at lambda = 0.757 and exceeds 1 from lambda = 0.556);
            "table" -- a cached cubic spline of the exact inversion (used by the population
            sums for speed; |error in log e1| < 1e-9, checked in the tests).
    Returns:
        e1 in (0, 1], shape of lam.
    """
    lam = _canonical_lambda(lam)
    if method == "paper":
        with np.errstate(divide="ignore", invalid="ignore"):
            e1 = 0.4777 * lam / (1.0 - 1.3211 * lam)
        e1 = np.where((e1 <= 0) | (e1 > 1) | ~np.isfinite(e1), 1.0, e1)
        return np.maximum(e1, math.exp(_LOG_E1_MIN))
    if method == "table":
        return np.exp(_log_e1_table(np.log(lam)))
    if method != "exact":
        raise ValueError(f"method = {method!r} is invalid: valid methods are 'exact', 'paper', 'table'")
    target = np.log(lam)
    lo = np.full(lam.shape, _LOG_E1_MIN)
    hi = np.zeros(lam.shape)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        below = _log_lambda_of_log_e1(mid) < target  # lambda(e1) increases with e1
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.exp(0.5 * (lo + hi))


@lru_cache(maxsize=1)
def _inverse_spline():
    from scipy.interpolate import CubicSpline
    t = np.linspace(0.0, 1.0, 6001)
    y = _LOG_E1_MIN * t**2  # dense near the circle (y -> 0), where lambda(e1) bends most
    y = y[::-1]
    u = _log_lambda_of_log_e1(y)
    u[-1] = 0.0
    return CubicSpline(u, y), u[0]


def _log_e1_table(log_lam):
    spline, u_min = _inverse_spline()
    log_lam = np.minimum(log_lam, 0.0)
    out = spline(np.maximum(log_lam, u_min))
    return np.clip(out, _LOG_E1_MIN, 0.0)


@lru_cache(maxsize=4)
def _shape_spline(elliptic: str):
    from scipy.interpolate import CubicSpline
    spline, _ = _inverse_spline()
    u = spline.x
    e1 = np.exp(spline(u))
    f1, f2, f3, _, KE = shape_factors(e1, elliptic)
    y = np.log(np.stack([f1, f2, f3, KE], axis=-1))
    return CubicSpline(u, y, axis=0), u[0]


@lru_cache(maxsize=4)
def _shape_hermite(elliptic: str, n: int = _HERMITE_KNOTS, u_min: float = _HERMITE_U_MIN):
    """A numpy-only cubic Hermite table of ln(f1, f2, f3, KE) in u = ln(lambda) on
    [u_min, 0], knots (nearly) uniform in u so that a point's interval is found by
    arithmetic, not by a search.

    lambda (27) and the shape factors are explicit in e1, so the knots are placed in e1: a
    dense explicit map u(log e1) (quadratic in log e1, dense near the circle) is interpolated
    to the log e1 of uniformly spaced u, where lambda and the shape factors are then
    evaluated exactly (the knots are exact; only their spacing is uniform to ~1e-6 of a
    cell, which moves a point's local coordinate outside [0, 1] by as little). Slopes:
    second-order three-point differences.

    Returns:
        (u of the knots, 1/(knot spacing) per interval, coefficients (4 functions x 4
        powers, n - 1) of the cubic in the local coordinate of each interval).
    """
    from .tables import hermite_coeffs, hermite_eval, limited_slopes

    y_dense = (_LOG_E1_MIN * np.linspace(0.0, 1.0, 2001) ** 2)[::-1]
    u_dense = _log_lambda_of_log_e1(y_dense)
    u_dense[-1] = 0.0
    y, _ = hermite_eval(u_dense, y_dense, limited_slopes(u_dense, y_dense),
                        np.linspace(u_min, 0.0, n))
    y[-1] = 0.0
    u = _log_lambda_of_log_e1(y)
    u[-1] = 0.0
    f1, f2, f3, _, KE = shape_factors(np.exp(y), elliptic)
    Y = np.log(np.stack([f1, f2, f3, KE]))                       # (4, n)
    a, b = np.diff(u)[:-1], np.diff(u)[1:]                       # left and right spacings
    D = np.empty_like(Y)
    D[:, 1:-1] = (-b / (a * (a + b)) * Y[:, :-2] + (b - a) / (a * b) * Y[:, 1:-1]
                  + a / (b * (a + b)) * Y[:, 2:])
    for e, (i0, i1, i2) in ((0, (0, 1, 2)), (-1, (-1, -2, -3))):   # one-sided, 2nd order
        h1, h2 = u[i1] - u[i0], u[i2] - u[i0]
        D[:, e] = (-(h1 + h2) / (h1 * h2) * Y[:, i0] + h2 / (h1 * (h2 - h1)) * Y[:, i1]
                   - h1 / (h2 * (h2 - h1)) * Y[:, i2])
    dx = np.diff(u)
    C = np.moveaxis(hermite_coeffs(Y[:, :-1], Y[:, 1:], D[:, :-1], D[:, 1:], dx), 0, 1)
    return u, 1.0 / dx, np.ascontiguousarray(C.reshape(16, -1))


def _shape_factors_hermite(x, elliptic: str, n_f: int = 4):
    """ln of the first ``n_f`` of (f1, f2, f3, KE) at u = ln(lambda) in [u_min, 0] by the
    cubic Hermite table: an array (n_f, *x.shape)."""
    from .tables import horner

    u, inv, C = _shape_hermite(elliptic)
    xf = np.clip(np.ravel(x), u[0], 0.0)
    i = ((xf - u[0]) * ((u.size - 1) / -u[0])).astype(np.intp)
    np.clip(i, 0, u.size - 2, out=i)
    t = (xf - u[i]) * inv[i]
    c = C[:4 * n_f, i].reshape(n_f, 4, -1)
    y = horner(np.moveaxis(c, 1, 0), t)
    return y.reshape((n_f,) + np.shape(x))


def shape_factors_from_lambda(lam, elliptic: str = "exact", table: str = "spline"):
    """(f1, f2, f3, KE) from the geometric axis ratio lambda (exact inversion of (27)).

    Interpolates the exact values in ln(lambda); lambda > 1 is mapped to 1/lambda. Used by
    the population sums.

    Args:
        lam: geometric axis ratio b/a > 0, array [-].
        elliptic: "exact" or "as", as in :func:`shape_factors`.
        table: "spline" (default) -- a cached scipy cubic spline on 6001 knots (relative
            error < 1e-9, checked in the tests); "hermite" -- a numpy-only cubic Hermite
            table on 2001 knots uniform in ln(lambda) over [-40, 0] with three-point slopes
            (relative error < 2e-7, checked in the tests; lambda < e^-40 exact), cheaper to
            set up (about 1 ms, and no import of scipy.interpolate): for the advisor's
            coarse estimates.
    """
    lam = _canonical_lambda(lam)
    if table == "hermite":
        x = np.log(lam)
        y = np.exp(_shape_factors_hermite(x, elliptic))
        far = x < _HERMITE_U_MIN            # beyond the table (lambda < 4e-18): exact
        if np.any(far):
            f1, f2, f3, _, KE = shape_factors(eccentricity_from_lambda(lam[far]), elliptic)
            y[:, far] = np.stack([f1, f2, f3, KE])
        return y[0], y[1], y[2], y[3]
    if table != "spline":
        raise ValueError(f"table = {table!r} is invalid: valid tables are 'spline', 'hermite'")
    spline, u_min = _shape_spline(elliptic)
    y = spline(np.clip(np.log(lam), u_min, 0.0))
    y = np.exp(y)
    return y[..., 0], y[..., 1], y[..., 2], y[..., 3]


def shape_factors(e1, elliptic: str = "exact"):
    """Shape factors of the elliptic contact and K(e) E(e).

    f1 = E/(K e1)                     area (46)
    f2 = pi E^(1/2)/(2 K^(3/2) e1)    load (47)
    f3 = E e^2/(2 e1 (E - e1^2 K))    plastic area (59)
    f4 = 2 (E - e1^2 K)/(K e^2)       (60)
    All equal 1 for a circle (e1 = 1); f3, f4 use the exact series of their 0/0 ratios for
    e^2 < 0.05 whatever ``elliptic`` is.

    Args:
        e1: contact axis ratio B/A in (0, 1] [-].
        elliptic: "exact" or "as" (A&S approximations (36)-(39)).
    Returns:
        (f1, f2, f3, f4, KE) arrays of the shape of e1; KE = K(e) E(e) enters (65).
    """
    e1 = _as_array(e1, "e1")
    m1 = np.clip(e1 * e1, math.exp(2 * _LOG_E1_MIN), 1.0)
    e1 = np.sqrt(m1)
    K, E = elliptic_integrals(m1, elliptic)
    Kx, Ex = (K, E) if elliptic == "exact" else elliptic_integrals(m1, "exact")
    G, _ = _G_H(m1, Kx, Ex)
    if elliptic != "exact":  # A&S away from the circle, exact series near it
        with np.errstate(divide="ignore", invalid="ignore"):
            Ga = (E - m1 * K) / (1.0 - m1)
        G = np.where(1.0 - m1 < _M_SERIES, G, Ga)
        # at the circle (36)-(39) do not give K = E = pi/2 exactly; f1, f2 inherit 3e-5 errors
    f1 = E / (K * e1)
    f2 = np.pi * np.sqrt(E) / (2.0 * K**1.5 * e1)
    f3 = E / (2.0 * e1 * G)
    f4 = 2.0 * G / K
    return f1, f2, f3, f4, K * E


# ---------------------------------------------------------------------------------------
# Material
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class AsperityMaterial:
    """Elasto-plastic asperity material (sections 5-6).

    Args:
        E_star: effective (contact) modulus E*, eq (42) [MPa], > 0.
        nu: Poisson ratio in (-1, 0.5) [-] (enters K_Y, K_nu).
        H: indentation hardness [MPa] (> 0), or None.
        Y: yield strength [MPa] (> 0), or None.
        psi: plasticity index (69) [-] (> 0), or None: H is then derived from the surface,
            H = sqrt(sigma kappa_m) E*/psi, when the material is resolved against a surface.
        ch: fully plastic mean pressure coefficient, p = ch H, eq (66) [-].
        omega_p_ratio: omega_p/omega_c, end of the elasto-plastic range [-] (> 1).
        K_Y: first-yield pressure coefficient p_m = K_Y Y (63); None -> 1.282 + 1.158 nu (64).
        K_nu: coefficient of (75); None -> 0.454 + 0.41 nu.

    Exactly one of H, psi must be given, Y optionally. Missing Y follows the paper's
    convention K_Y Y = (2/pi) H (the reading under which (74) follows from (65), (69), (70));
    with only Y given, H = Y/0.354 (Tabor, (68)).
    """

    E_star: float
    nu: float = 0.3
    H: float | None = None
    Y: float | None = None
    psi: float | None = None
    ch: float = 0.967
    omega_p_ratio: float = 45.0
    K_Y: float | None = None
    K_nu: float | None = None

    def __post_init__(self):
        def pos(name, v, unit=""):
            return None if v is None else check_scalar(name, v, lo=0.0, unit=unit)
        object.__setattr__(self, "E_star", pos("E_star", self.E_star, "MPa"))
        nu = check_scalar("nu", self.nu, lo=-1.0, hi=0.5)
        object.__setattr__(self, "nu", nu)
        for name, unit in (("H", "MPa"), ("Y", "MPa"), ("psi", ""), ("ch", ""), ("K_Y", ""),
                           ("K_nu", "")):
            object.__setattr__(self, name, pos(name, getattr(self, name), unit))
        object.__setattr__(self, "omega_p_ratio",
                           check_scalar("omega_p_ratio", self.omega_p_ratio, lo=1.0))
        if self.H is not None and self.psi is not None:
            raise ValueError("H and psi are both given: give only one (psi determines H via (69))")
        if self.H is None and self.psi is None and self.Y is None:
            raise ValueError("H, Y and psi are all None: give the hardness H, the yield strength Y "
                             "or the plasticity index psi")
        if self.K_Y is None:
            object.__setattr__(self, "K_Y", 1.282 + 1.158 * nu)
        if self.K_nu is None:
            object.__setattr__(self, "K_nu", 0.454 + 0.41 * nu)
        if self.H is None and self.psi is None:
            object.__setattr__(self, "H", self.Y / 0.354)

    @classmethod
    def from_plasticity_index(cls, surface, psi: float, E_star: float, **kwargs) -> "AsperityMaterial":
        """Material with H chosen so that the surface has plasticity index psi (69)."""
        H = surface.hardness_for_plasticity_index(E_star, psi)
        return cls(E_star=E_star, H=H, **kwargs)

    def resolve(self, surface=None) -> "AsperityMaterial":
        """Return a material with H set (from psi and the surface if needed)."""
        if self.H is not None:
            return self
        if surface is None:
            raise ValueError("psi is given but no surface: the hardness H = sqrt(sigma kappa_m) E*/psi "
                             "needs the surface statistics")
        H = surface.hardness_for_plasticity_index(self.E_star, self.psi)
        return AsperityMaterial(E_star=self.E_star, nu=self.nu, H=H, Y=self.Y, ch=self.ch,
                                omega_p_ratio=self.omega_p_ratio, K_Y=self.K_Y, K_nu=self.K_nu)

    @property
    def yield_pressure(self) -> float:
        """First-yield maximum Hertz pressure p_m = K_Y Y [MPa]; (2/pi) H when Y is None."""
        if self.H is None:
            raise ValueError("the material is not resolved (H unknown): call resolve(surface)")
        if self.Y is not None:
            return self.K_Y * self.Y
        return 2.0 / math.pi * self.H


# ---------------------------------------------------------------------------------------
# Single asperity laws. omega: interference [mm]; kappa_m: mean curvature (44) [1/mm].
# ---------------------------------------------------------------------------------------

def hertz_area(omega, kappa_m, f1):
    """Elastic contact area A = f1 pi omega/kappa_m [mm^2], eq (46)."""
    return f1 * np.pi * np.maximum(omega, 0.0) / kappa_m


def hertz_load(omega, kappa_m, f2, E_star):
    """Elastic load W = (4/3) f2 E* kappa_m^(-1/2) omega^(3/2) [N], eq (47)."""
    return 4.0 / 3.0 * f2 * E_star * np.maximum(omega, 0.0) ** 1.5 / np.sqrt(kappa_m)


def hertz_stiffness(omega, kappa_m, f2, E_star):
    """Elastic stiffness dW/domega = 2 f2 E* kappa_m^(-1/2) omega^(1/2) [N/mm], eq (54)."""
    return 2.0 * f2 * E_star * np.sqrt(np.maximum(omega, 0.0) / kappa_m)


def critical_interference(kappa_m, KE, yield_pressure, E_star):
    """omega_c = K E (K_Y Y/E*)^2/kappa_m [mm], eq (65); yield_pressure = K_Y Y [MPa]."""
    return KE * (yield_pressure / E_star) ** 2 / kappa_m


def zmc_mean_pressure(omega, omega_c, material: AsperityMaterial):
    """Elasto-plastic mean pressure (75) [MPa] and its derivative d pa/d omega [MPa/mm].

    pa = H [ch - (ch - 2 K_nu/3) ln(omega_p/omega)/ln(omega_p/omega_c)],
    omega_p = omega_p_ratio * omega_c (denominator read as ln omega_p - ln omega_c).
    """
    H, ch, R = material.H, material.ch, material.omega_p_ratio
    slope = H * (ch - 2.0 * material.K_nu / 3.0) / math.log(R)
    om = np.maximum(omega, 1e-300)
    pa = ch * H - slope * np.log(R * omega_c / om)
    return pa, slope / om


def zmc_area(omega, kappa_m, f1, f3, omega_c, omega_p):
    """Elasto-plastic area (76) [mm^2] and dA/domega [mm].

    A = pi omega/kappa_m [f1 + (2 f3 - f1) S(x)], S = 3x^2 - 2x^3,
    x = (omega - omega_c)/(omega_p - omega_c) clipped to [0, 1].
    """
    dw = omega_p - omega_c
    x = np.clip((omega - omega_c) / dw, 0.0, 1.0)
    S = x * x * (3.0 - 2.0 * x)
    dS = 6.0 * x * (1.0 - x) / dw
    c = np.pi / kappa_m
    A = c * omega * (f1 + (2.0 * f3 - f1) * S)
    dA = c * (f1 + (2.0 * f3 - f1) * S) + c * omega * (2.0 * f3 - f1) * dS
    return A, dA


def plastic_area(omega, kappa_m, f3):
    """Fully plastic area A = 2 pi f3 omega/kappa_m [mm^2], eq (61)."""
    return 2.0 * np.pi * f3 * np.maximum(omega, 0.0) / kappa_m


def plastic_load(omega, kappa_m, f3, material: AsperityMaterial):
    """Fully plastic load W = ch H A [N], eq (67)."""
    return material.ch * material.H * plastic_area(omega, kappa_m, f3)


def asperity_response(omega, kappa_m, e1, material: AsperityMaterial | None = None,
                      E_star: float | None = None, elliptic: str = "exact"):
    """Area, load and stiffness of one asperity; elastic or elasto-plastic (ZMC).

    Regimes: elastic omega < omega_c (46)-(47); transition omega_c <= omega < omega_p
    (75)-(77); fully plastic omega >= omega_p (61), (67). Broadcasting arrays.

    Args:
        omega: interference [mm].
        kappa_m: mean curvature of the asperity (44) [1/mm].
        e1: contact axis ratio B/A in (0, 1] [-].
        material: resolved AsperityMaterial (H known); None -> purely elastic with E_star.
        E_star: effective modulus for the purely elastic case [MPa].
        elliptic: "exact" or "as".
    Returns:
        dict with "area" [mm^2], "load" [N], "stiffness" dW/domega [N/mm] (regular part),
        "omega_c", "omega_p" [mm] and "jump" = W(omega_c+) - W(omega_c-) [N] (the load
        jumps at omega_c unless (2/3) K_nu H equals the elastic mean pressure (2/3) K_Y Y).
    """
    f1, f2, f3, _, KE = shape_factors(e1, elliptic)
    omega = np.asarray(omega, dtype=float)
    if material is None:
        if E_star is None:
            raise ValueError("E_star is None: give a material or E_star for the elastic response")
        Es = float(E_star)
        return {"area": hertz_area(omega, kappa_m, f1), "load": hertz_load(omega, kappa_m, f2, Es),
                "stiffness": hertz_stiffness(omega, kappa_m, f2, Es)}
    mat = material
    if mat.H is None:
        raise ValueError("material is not resolved (H unknown): call material.resolve(surface)")
    Es = mat.E_star
    wc = critical_interference(kappa_m, KE, mat.yield_pressure, Es)
    wp = mat.omega_p_ratio * wc
    Ae, We, ke = hertz_area(omega, kappa_m, f1), hertz_load(omega, kappa_m, f2, Es), \
        hertz_stiffness(omega, kappa_m, f2, Es)
    Aep, dAep = zmc_area(omega, kappa_m, f1, f3, wc, wp)
    pa, dpa = zmc_mean_pressure(omega, wc, mat)
    Ap = plastic_area(omega, kappa_m, f3)
    Wp = mat.ch * mat.H * Ap
    kp = mat.ch * mat.H * 2.0 * np.pi * f3 / kappa_m
    el = omega < wc
    pl = omega >= wp
    area = np.where(el, Ae, np.where(pl, Ap, Aep))
    load = np.where(el, We, np.where(pl, Wp, Aep * pa))
    stiff = np.where(el, ke, np.where(pl, kp, dAep * pa + Aep * dpa))
    Ac = hertz_area(wc, kappa_m, f1)
    jump = Ac * (2.0 / 3.0 * mat.K_nu * mat.H) - hertz_load(wc, kappa_m, f2, Es)
    return {"area": area, "load": load, "stiffness": stiff, "omega_c": wc, "omega_p": wp,
            "jump": jump * np.ones_like(area)}
