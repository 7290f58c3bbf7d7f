"""Sums over the summit population: real area, load and stiffness vs separation.

Implements the elastic model (52)-(55), the elasto-plastic model (78)-(85) with the exact
stiffness -dW/dh (the Leibniz form of (88), corrected as ``docs/equations.md`` explains: a
boundary term at omega_c where the asperity load jumps), the bearing areas AG (24) and AB
(25), and McCool's equivalent Greenwood-Williamson model (the "GW" columns of Tables 1-2).

Units: separation h of the mean planes in mm; pressures W/A0 in MPa; stiffness per nominal
area k_N = -d(W/A0)/dh in MPa/mm; area fractions A/A0 dimensionless.

Integration scheme (why it is not a Gauss-Legendre box). With r = sqrt(mu) (w4, w6) the
population integral of an asperity quantity Q(omega; w4, w6) is

    Dsum * integral_{r4,r6>0} r4 r6 exp(-|r|^2/2) integral_0^inf Q(sqrt(m00 mu) t) phi(t + d) dt,
    d = l - (sqrt(b1) r4 + sqrt(b2) r6)/sqrt(mu),  l = h/sqrt(m00 mu),

phi the standard normal density (t = w1 - l). The weight is narrow (width sqrt(mu)) along
p = (sqrt(b1) r4 + sqrt(b2) r6)/sqrt(b1 + b2) and has width 1 along the orthogonal q, so
the outer integral uses the rotated coordinates (p, q):
  * p: Gauss-Legendre on up to three panels (split where d = +-12) inside a window found
    per separation from the log-concave bound -p^2/2 + 3 ln p + ln F_1(l - k p) (the window
    keeps everything above exp(-50) of the maximum); so the domain follows mu -> 0 and l;
  * q: three Gauss-Legendre panels over the wedge r4, r6 > 0 (clipped to |q| <= 10), split
    at q = 0 (peak of exp(-q^2/2)) and at the ray of circular asperities (kx = ky), where
    the shape factors have a kink; the edge panels are mapped u -> 2u - u^2 to smooth the
    sqrt-type behaviour at the wedge edges;
  * t (inner, elastic model): closed forms F_n(d) = int_0^inf t^n phi(t + d) dt via
    parabolic-cylinder functions (Gauss-Hermite for d < -10, asymptotic series for d > 30);
  * t (inner, elasto-plastic model): Gauss-Legendre in v = sqrt(t) on four panels split at
    omega_c*, omega_p* (regime boundaries) and at the peak t = -d of phi, inside the window
    where phi(t + d) > exp(-72) phi_max. Each panel lies in one asperity regime and is summed
    with that regime's formula only: elastic and plastic panels through the moments
    sum_t wt v^n (n = 0..3; omega = sqrt(m00 mu) v^2), the ZMC formula at the nodes of the
    transition panels alone.
The shape factors f1, f2, f3 and K E at the nodes come from a cached cubic spline in
ln(lambda) of the exact values (relative error < 4e-12; with ``elliptic="as"`` f3 differs
from the direct A&S value by up to 6e-5, the size of the A&S error itself).
``n_quad`` is the number of Gauss-Legendre nodes per panel. Measured maximum relative error
against n_quad = 96 over h in [-5, 60] sigma on the surfaces of Tables 1 and 2 (wherever
W/A0 > 1e-300): elastic model, default n_quad = 32: 3e-8 (W/A0, k_N, A/A0); n_quad = 24:
6e-5; n_quad = 16: 1.5e-2 (the worst points are in the far tail, s > 20). Elasto-plastic
model: see :func:`elasto_plastic`. Speed (measured on the 2 shared cores, load ~5):
elastic, 200 separations, n_quad = 32: 0.5-1.2 s; elasto-plastic, 100 separations,
n_quad = 24: 0.7 s CPU (~7 ms per separation; 45 ms before the per-regime panels; chunks of
1e5 (p, q) nodes, peak memory ~150 MB).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import special

from .asperity import (AsperityMaterial, eccentricity_from_lambda, shape_factors,
                       shape_factors_from_lambda)
from ..surface import SpectralMoments
from ..validation import check_integer, check_scalar

__all__ = ["PopulationResult", "elastic", "elasto_plastic", "elasto_plastic_and_elastic",
           "greenwood_williamson",
           "bearing_area", "bearing_area_ratio", "F_n", "log_F_n"]

_L_WINDOW = 50.0   # window keeps integrand above exp(-50) of its maximum (p direction)
_Q_MAX = 10.0      # |q| clip (exp(-50))
_D_SPLIT = 12.0    # p panels split where d = +-12
_Q_POW = 2
_T_WIDTH = 12.0    # t window: phi(t + d) above exp(-72) of its maximum


@dataclass(frozen=True)
class PopulationResult:
    """Population sums at separations h (all arrays of the shape of h).

    Attributes:
        area_fraction: real contact area per nominal area A/A0 [-].
        pressure: load per nominal area W/A0 [MPa].
        stiffness: k_N = -d(W/A0)/dh [MPa/mm].
        area_elastic, area_transition, area_plastic: split of area_fraction by asperity
            regime (elasto-plastic model only; None otherwise) [-].
        pressure_elastic, pressure_transition, pressure_plastic: split of pressure [MPa].
    """

    area_fraction: np.ndarray
    pressure: np.ndarray
    stiffness: np.ndarray
    area_elastic: np.ndarray | None = None
    area_transition: np.ndarray | None = None
    area_plastic: np.ndarray | None = None
    pressure_elastic: np.ndarray | None = None
    pressure_transition: np.ndarray | None = None
    pressure_plastic: np.ndarray | None = None


# ---------------------------------------------------------------------------------------
# F_n(d) = int_0^inf t^n phi(t + d) dt = E[(Z - d)_+^n]
# ---------------------------------------------------------------------------------------

@lru_cache(maxsize=4)
def _hermite(n=96):
    z, w = np.polynomial.hermite_e.hermegauss(n)
    return z, w / math.sqrt(2 * math.pi)


def log_F_n(n: float, d):
    """log F_n(d), F_n(d) = int_0^inf t^n phi(t + d) dt, for n > -1, any real d.

    d < -10: Gauss-Hermite expectation of (Z - d)_+^n; -10 <= d <= 30:
    Gamma(n+1) exp(-d^2/4) D_{-n-1}(d)/sqrt(2 pi) (scipy pbdv, ~1e-13 relative);
    d > 30: asymptotic series of D_{-n-1} (3 terms, < 1e-9 relative).
    """
    d = np.asarray(d, dtype=float)
    out = np.empty(d.shape)
    lg = special.gammaln(n + 1.0) - 0.5 * math.log(2 * math.pi)
    lo = d < -10.0
    hi = d > 30.0
    mid = ~(lo | hi)
    if np.any(mid):
        dm = d[mid]
        D, _ = special.pbdv(-n - 1.0, dm)
        out[mid] = lg - dm * dm / 4.0 + np.log(D)
    if np.any(hi):
        x = d[hi]
        v = -n - 1.0
        x2 = 1.0 / (x * x)
        ser = (1.0 - v * (v - 1) / 2.0 * x2 + v * (v - 1) * (v - 2) * (v - 3) / 8.0 * x2**2
               - v * (v - 1) * (v - 2) * (v - 3) * (v - 4) * (v - 5) / 48.0 * x2**3)
        out[hi] = lg - x * x / 2.0 + v * np.log(x) + np.log(ser)
    if np.any(lo):
        z, w = _hermite()
        a = z[None, :] - d[lo][:, None]
        out[lo] = np.log(np.sum(w * np.where(a > 0, a, 0.0) ** n, axis=1))
    return out


def _log_F1_closed(d):
    """log F_1(d) = log(phi(d) - d Q(d)) in closed form (erfcx), for the window search:
    F_1 = exp(-d^2/2) (1/sqrt(2 pi) - d/2 erfcx(d/sqrt 2)); the bracket loses ~d^2 eps
    to cancellation for d > 0 (1e-12 at d = 30), and d > 60 takes the asymptotic
    phi(d)/d^2 (1 - 3/d^2 + 15/d^4). ~5x cheaper than :func:`log_F_n` (pbdv)."""
    d = np.asarray(d, float)
    big = d > 60.0
    ds = np.where(big, 0.0, d)
    c = 1.0 / math.sqrt(2.0 * math.pi)
    with np.errstate(divide="ignore"):
        core = np.log(np.maximum(c - 0.5 * ds * special.erfcx(ds / math.sqrt(2.0)), 1e-300))
        x2 = 1.0 / np.where(big, d * d, 1.0)
        asym = (math.log(c) - 2.0 * np.log(np.where(big, d, 1.0))
                + np.log1p(-3.0 * x2 + 15.0 * x2 * x2))
    return np.where(big, asym, core) - 0.5 * d * d


def _log_F_half_pair(d):
    """(log F_3/2(d), log F_1/2(d)) from one parabolic-cylinder call where -10 <= d <= 30:
    pbdv(-5/2, d) gives D_-5/2 and its derivative, and D_-3/2 = d/2 D_-5/2 - D'_-5/2
    (DLMF 12.8.3); outside, :func:`log_F_n`."""
    d = np.asarray(d, dtype=float)
    o32, o12 = np.empty(d.shape), np.empty(d.shape)
    mid = (d >= -10.0) & (d <= 30.0)
    if np.any(mid):
        dm = d[mid]
        D, Dp = special.pbdv(-2.5, dm)
        c = -dm * dm / 4.0 - 0.5 * math.log(2 * math.pi)
        o32[mid] = special.gammaln(2.5) + c + np.log(D)
        o12[mid] = special.gammaln(1.5) + c + np.log(0.5 * dm * D - Dp)
    out = ~mid
    if np.any(out):
        o32[out] = log_F_n(1.5, d[out])
        o12[out] = log_F_n(0.5, d[out])
    return o32, o12


def F_n(n: float, d):
    """F_n(d) = int_0^inf t^n phi(t + d) dt (underflows to 0 for d > ~38)."""
    return np.exp(log_F_n(n, d))


# ---------------------------------------------------------------------------------------
# Validation helpers
# ---------------------------------------------------------------------------------------

def _check_h(h):
    h = np.asarray(h, dtype=float)
    if np.any(~np.isfinite(h)):
        raise ValueError("h contains NaN/inf: separations must be finite numbers [mm]")
    return h


def _separations(surface: SpectralMoments, h):
    """Checked separations ``h`` [mm] of the population sums: (h's shape, the flat
    l = h / sqrt(m00 mu) [-], sqrt(m00 mu) [mm], the summit density D_s)."""
    h = _check_h(h)
    smu = math.sqrt(surface.m00 * surface.mu)
    return h.shape, h.ravel() / smu, smu, surface.summit_density


def _check_nquad(n):
    return check_integer("n_quad", n, lo=4, hi=400)


@lru_cache(maxsize=16)
def _gl01(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


# ---------------------------------------------------------------------------------------
# Outer (p, q) quadrature
# ---------------------------------------------------------------------------------------

def _p_windows(l, k, window_tol=0.0):
    """Integration window [pa, pb] in p for each l (vectorised log-concave search).

    ``window_tol`` > 0 stops the mode search and the edge bisection once every bracket is
    narrower than it (in p, a standard-normal variable); 0 (default): to the fixed point of
    the iteration. An edge off by 1e-3 moves log G there by ~1e-2 at a level 50 below the
    peak: the window's content is unchanged, only the quadrature nodes shift.

    log G(p) = -p^2/2 + 3 ln p + ln F_1(l - k p) is concave in p > 0 (F_1 is log-concave),
    a bound on the shape of the integrand (the q-integral grows at most like p^3). The
    window is where log G > max log G - 50; concavity with the -p^2/2 term bounds it to
    mode +- 10.
    """
    l = np.asarray(l, dtype=float)
    k = np.broadcast_to(np.asarray(k, dtype=float), l.shape)   # a scalar or one per l
    if l.size == 0:
        return np.zeros(l.shape), np.zeros(l.shape)
    l2, k2 = np.concatenate([l, l]), np.concatenate([k, k])

    log_F1 = (lambda d: log_F_n(1.0, d)) if window_tol <= 0.0 else _log_F1_closed

    def logG(p):
        ll, kk = (l, k) if p.size == l.size else (l2, k2)
        p = np.maximum(p, 1e-300)
        return -0.5 * p * p + 3.0 * np.log(p) + log_F1(ll - kk * p)

    # Both points of a golden-section step, and both edges of the window, go through one call
    # of logG (elementwise: the same numbers as separate calls, at half the calls; the fixed
    # overhead of a call dominates for the few separations of a small table or the advisor).
    n = l.size
    a = np.zeros_like(l)
    b = np.maximum(l, 0.0) / k + 6.0      # the mode lies below p_l + 3
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(100):                   # golden-section search of the mode
        if window_tol > 0.0 and np.max(b - a) < window_tol:
            break
        c = b - g * (b - a)
        e = a + g * (b - a)
        G = logG(np.concatenate([c, e]))
        left = G[:n] > G[n:]
        a_new = np.where(left, a, c)
        b_new = np.where(left, e, b)
        if np.array_equal(a_new, a) and np.array_equal(b_new, b):
            break                          # a fixed point: further steps change nothing
        a, b = a_new, b_new
    pm = 0.5 * (a + b)
    target = np.concatenate([logG(pm) - _L_WINDOW] * 2)
    half = math.sqrt(2.0 * _L_WINDOW) + 1e-3
    # lower edge in [pm - half, pm] (first n entries), upper edge in [pm, pm + half]
    lo = np.concatenate([np.maximum(pm - half, 0.0), pm])
    hi = np.concatenate([pm, pm + half])
    lower = np.arange(2 * n) < n
    for _ in range(60):
        if window_tol > 0.0 and np.max(hi - lo) < window_tol:
            break
        mid = 0.5 * (lo + hi)
        above = logG(mid) > target
        # the lower edge moves down while above the target, the upper edge up
        move_hi = above == lower
        lo_new = np.where(move_hi, lo, mid)
        hi_new = np.where(move_hi, mid, hi)
        if np.array_equal(lo_new, lo) and np.array_equal(hi_new, hi):
            break
        lo, hi = lo_new, hi_new
    if window_tol > 0.0:
        # the brackets' midpoints: a lower edge bracketed by [0, window_tol) must not fall on
        # p = 0 (zero curvature, where the elasto-plastic boundary term is 0 * inf)
        mid = 0.5 * (lo + hi)
        return mid[:n], mid[n:]
    return lo[:n], hi[n:]


def _outer_nodes(surface: SpectralMoments, l, n_quad, n_p=None, window_tol=0.0, windows=None):
    """Nodes and weights of the (p, q) rule for each separation.

    ``windows``: the p windows (pa, pb) of ``l`` when already found (``_p_windows``).

    Returns arrays of shape (n_h, n_p, n_q): r4, r6, d (= l - k p), log of the Gaussian
    weight times r4 r6 times the quadrature weights (ln of it, -inf where it vanishes).
    """
    b1, b2, mu = surface.beta1, surface.beta2, surface.mu
    B = b1 + b2
    sb1, sb2, sB = math.sqrt(b1), math.sqrt(b2), math.sqrt(B)
    k = sB / math.sqrt(mu)
    pa, pb = _p_windows(l, k, window_tol) if windows is None else windows
    # p panels split at d = +-12 (p = (l -+ 12)/k)
    cuts = np.stack([pa, np.clip((l - _D_SPLIT) / k, pa, pb), np.clip((l + _D_SPLIT) / k, pa, pb), pb],
                    axis=-1)
    u, w = _gl01(n_quad if n_p is None else n_p)
    lo_, hi_ = cuts[:, :-1, None], cuts[:, 1:, None]           # (n_h, 3, 1)
    p = (lo_ + (hi_ - lo_) * u).reshape(len(l), -1)            # (n_h, 3 n)
    wp = ((hi_ - lo_) * w).reshape(len(l), -1)
    # q panels between q_a < min(q_c, 0) < max(q_c, 0) < q_b: q_c is the ray of circular
    # asperities (kx = ky), where the shape factors have a kink (they depend on |lambda - 1|);
    # q = 0 is the peak of exp(-q^2/2). The outer panels are clustered at the wedge edges,
    # where the integrand behaves like sqrt(distance).
    u, w = _gl01(n_quad)
    qa = np.maximum(-(sb2 / sb1) * p, -_Q_MAX)
    qb = np.minimum((sb1 / sb2) * p, _Q_MAX)
    rc = math.sqrt(surface.m40 / surface.m04)
    qc = np.clip(p * (rc * sb1 - sb2) / (sb1 + rc * sb2), qa, qb)
    q1 = np.minimum(qc, 0.0)
    q2 = np.maximum(qc, 0.0)
    s = 1.0 - (1.0 - u) ** _Q_POW                              # clusters at the wedge edge
    ds = _Q_POW * (1.0 - u) ** (_Q_POW - 1)
    E_ = lambda x: x[..., None]  # noqa: E731
    q = np.concatenate([E_(q1) + E_(qa - q1) * s, E_(q1) + E_(q2 - q1) * u,
                        E_(q2) + E_(qb - q2) * s], axis=-1)                     # (n_h, n_p, 3n)
    wq = np.concatenate([E_(q1 - qa) * ds * w, E_(q2 - q1) * w, E_(qb - q2) * ds * w], axis=-1)
    p3 = p[..., None]
    r4 = (sb1 * p3 - sb2 * q) / sB
    r6 = (sb2 * p3 + sb1 * q) / sB
    r4 = np.maximum(r4, 0.0)
    r6 = np.maximum(r6, 0.0)
    with np.errstate(divide="ignore"):
        logw = (np.log(wp)[..., None] + np.log(wq) + np.log(r4) + np.log(r6)
                - 0.5 * (p3 * p3 + q * q))
    d = (l[:, None] - k * p)
    return r4, r6, d, logw


def _asperity_shape(surface, r4, r6, elliptic, eccentricity, shape_table="spline"):
    """kappa_m (44) [1/mm], e1, shape factors at the (r4, r6) nodes (r4, r6 > 0).

    ``shape_table``: the interpolant of the exact shape factors (``eccentricity="exact"``),
    see :func:`~rough_contact.micro.asperity.shape_factors_from_lambda`'s ``table``."""
    s40, s04 = math.sqrt(surface.m40), math.sqrt(surface.m04)
    kx = np.maximum(r4 * s40, 1e-300)   # principal curvatures w4 sqrt(m40 mu) etc. [1/mm]
    ky = np.maximum(r6 * s04, 1e-300)
    kappa = 0.5 * (kx + ky)
    # lambda^2 = b^2/a^2 = kx/ky; the shape factors are symmetric, use lambda <= 1
    lam = np.exp(-0.5 * np.abs(np.log(kx) - np.log(ky)))
    if eccentricity == "exact":
        f1, f2, f3, KE = shape_factors_from_lambda(lam, elliptic, shape_table)
    elif eccentricity == "paper":
        e1 = eccentricity_from_lambda(lam, method="paper")
        f1, f2, f3, _, KE = shape_factors(e1, elliptic)
    else:
        raise ValueError(f"eccentricity = {eccentricity!r} is invalid: valid values are 'exact', 'paper'")
    return kappa, kx, ky, f1, f2, f3, KE


def _chunks(n_h, per_h, budget=1_500_000):
    step = max(1, budget // max(per_h, 1))
    for i in range(0, n_h, step):
        yield slice(i, min(n_h, i + step))


# ---------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------

def elastic(surface: SpectralMoments, E_star: float, h, n_quad: int = 32,
            elliptic: str = "exact", eccentricity: str = "exact",
            window_tol: float = 0.0, shape_table: str = "spline",
            inner: str = "pbdv") -> PopulationResult:
    """Elastic anisotropic population, eqs (52), (53), (55).

    Args:
        surface: spectral moments (mm-based).
        E_star: effective modulus [MPa].
        h: separations of the mean planes [mm], any shape.
        n_quad: Gauss-Legendre nodes per panel (see module docstring for accuracy).
        elliptic: "exact" or "as" (A&S (36)-(39)) for K, E in f1, f2.
        eccentricity: "exact" (inversion of (27)) or "paper" (eq (33), clipped).
        window_tol: > 0 ends the search of the p window at that bracket width (a cheaper
            search for coarse estimates, e.g. 1e-3 in ``rough_contact.advisor``); 0: to the
            fixed point (see ``_p_windows``).
        shape_table: "spline" (default) or "hermite": the interpolant of the exact shape
            factors (:func:`~rough_contact.micro.asperity.shape_factors_from_lambda`, its
            ``table``; "hermite" is within 1e-7 of the spline and needs no scipy.interpolate:
            for the advisor's first call of a process).
        inner: the closed forms of the inner t integrals: "pbdv" (default) -- one
            :func:`log_F_n` (scipy ``pbdv``) per order; "recurrence" -- F_3/2 and F_1/2 from
            one ``pbdv`` call (D_-3/2 = x/2 D_-5/2 - D'_-5/2) and F_1 in closed form
            (erfcx): half the cost, within 1e-13 of the default for F_3/2 and F_1/2 and
            1e-8 for F_1 (the advisor's estimates).
    Returns:
        PopulationResult (area_fraction, pressure [MPa], stiffness [MPa/mm]) shaped like h.
    """
    E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
    n_quad = _check_nquad(n_quad)
    if inner not in ("pbdv", "recurrence"):
        raise ValueError(f"inner = {inner!r} is invalid: valid values are 'pbdv', 'recurrence'")
    shape, l, smu, Ds = _separations(surface, h)
    A = np.zeros(l.size)
    W = np.zeros(l.size)
    Kn = np.zeros(l.size)
    per_h = 3 * n_quad * 3 * n_quad
    for sl in _chunks(l.size, per_h):
        r4, r6, d, logw = _outer_nodes(surface, l[sl], n_quad, window_tol=window_tol)
        kappa, _, _, f1, f2, _, _ = _asperity_shape(surface, r4, r6, elliptic, eccentricity,
                                                    shape_table)
        if inner == "recurrence":
            F1 = _log_F1_closed(d)[..., None]
            F32, F12 = (x[..., None] for x in _log_F_half_pair(d))
        else:
            F1 = log_F_n(1.0, d)[..., None]
            F32 = log_F_n(1.5, d)[..., None]
            F12 = log_F_n(0.5, d)[..., None]
        A[sl] = np.sum(f1 / kappa * np.exp(logw + F1), axis=(1, 2))
        g2 = f2 / np.sqrt(kappa)
        W[sl] = np.sum(g2 * np.exp(logw + F32), axis=(1, 2))
        Kn[sl] = np.sum(g2 * np.exp(logw + F12), axis=(1, 2))
    A *= np.pi * Ds * smu
    W *= 4.0 / 3.0 * Ds * E_star * smu**1.5
    Kn *= 2.0 * Ds * E_star * smu**0.5
    return PopulationResult(A.reshape(shape), W.reshape(shape), Kn.reshape(shape))


def elasto_plastic(surface: SpectralMoments, material: AsperityMaterial, h, n_quad: int = 24,
                   elliptic: str = "exact", eccentricity: str = "exact",
                   n_t: int | None = None) -> PopulationResult:
    """Elasto-plastic anisotropic population (78)-(85), exact stiffness -dW/dh.

    Each asperity is elastic below omega_c (65), follows the Zhao-Maietta-Chang transition
    (75)-(77) up to omega_p = omega_p_ratio omega_c and is fully plastic beyond (61), (67).
    The stiffness is the exact derivative: population sum of dW_i/domega plus the boundary
    term [W_i(omega_c+) - W_i(omega_c-)] * density at omega = omega_c (the corrected (88)).

    Args:
        surface: spectral moments.
        material: AsperityMaterial (psi is resolved against ``surface``).
        h: separations [mm], any shape.
        n_quad: Gauss-Legendre nodes per panel (q, t; 1.5x along p). Measured with the
            default 24 against n_quad = 40 on the surfaces of Tables 1-2, psi in {0.3, 1, 10},
            h in [-5, 60] sigma: pressure and area <= 6e-6, stiffness <= 6e-5 relative.
        elliptic, eccentricity: as in :func:`elastic`.
        n_t: nodes per panel of the inner t integral (default max(16, 2 n_quad/3); with 16
            the t rule alone is accurate to 4e-6).
    Returns:
        PopulationResult with the regime split fields filled.
    """
    return _elasto_plastic(surface, material, h, n_quad, elliptic, eccentricity, n_t, False)[0]


def elasto_plastic_and_elastic(surface: SpectralMoments, material: AsperityMaterial, h,
                               n_quad: int = 24, n_t: int | None = None,
                               window_tol: float = 0.0, shape_table: str = "spline"):
    """The elasto-plastic sums and the purely elastic ones on the same quadrature nodes.

    The elastic result uses the elasto-plastic quadrature (inner t rule instead of the closed
    forms of :func:`elastic`): with a coarse rule both carry nearly the same quadrature error,
    which cancels in their ratio (what ``rough_contact.advisor`` compares). Arguments as in
    :func:`elasto_plastic`; ``window_tol`` and ``shape_table`` as in :func:`elastic`.

    Returns:
        (elasto-plastic PopulationResult, elastic PopulationResult).
    """
    return _elasto_plastic(surface, material, h, n_quad, "exact", "exact", n_t, True,
                           window_tol, shape_table)


_EP_KEYS = ("Ae", "At", "Ap", "We", "Wt", "Wp", "K")
_PQ_BUDGET = 100_000    # (h, p, q) nodes per chunk of separations (4 t panels each)
_PANEL_BLOCK = 4096     # t panels per block of the inner sums (~65k nodes, 0.5 MB per array)
_LOG_SQRT_2PI = 0.5 * math.log(2 * math.pi)


def _panel_nodes(a, b, d, u, w):
    """Nodes v and weights wt = dt phi(t + d) (dt = 2 v dv) of the t panels [a, b] in v."""
    wd = b - a
    v = a[:, None] + wd[:, None] * u
    s = v * v + d[:, None]
    wt = (2.0 * wd)[:, None] * w * v
    wt *= np.exp(-0.5 * s * s - _LOG_SQRT_2PI)
    return v, wt


def _panel_moments(a, b, d, u, w):
    """(4, n) moments M_n = sum_t wt v^n, n = 0..3, of the t panels [a, b] (1-D arrays)."""
    M = np.empty((4, a.size))
    for s in range(0, a.size, _PANEL_BLOCK):
        j = slice(s, s + _PANEL_BLOCK)
        v, y = _panel_nodes(a[j], b[j], d[j], u, w)
        M[0, j] = y.sum(axis=1)
        for n in (1, 2, 3):
            y *= v
            M[n, j] = y.sum(axis=1)
    return M


def _transition_sums(a, b, u, w, smu, R, chH, slope, d, f1, f3, c_area, wc, wp):
    """sum_t wt (A, W, -dW/domega) of the ZMC transition (75)-(77) over the t panels [a, b]."""
    out = np.empty((3, a.size))
    for s in range(0, a.size, _PANEL_BLOCK):
        j = slice(s, s + _PANEL_BLOCK)
        v, wt = _panel_nodes(a[j], b[j], d[j], u, w)
        om = smu * (v * v)
        X = lambda x: x[j, None]  # noqa: E731
        wc_, wp_, f1_, f3_, c_ = X(wc), X(wp), X(f1), X(f3), X(c_area)
        x = np.clip((om - wc_) / (wp_ - wc_), 0.0, 1.0)
        S = x * x * (3.0 - 2.0 * x)
        dS = 6.0 * x * (1.0 - x) / (wp_ - wc_)
        fa = f1_ + (2.0 * f3_ - f1_) * S
        A = c_ * om * fa
        dA = c_ * (fa + om * (2.0 * f3_ - f1_) * dS)
        pa = chH - slope * np.log(np.clip(wp_ / np.maximum(om, wp_ / R), 1.0, R))   # (75)
        out[0, j] = np.sum(A * wt, axis=1)
        out[1, j] = np.sum(A * pa * wt, axis=1)
        out[2, j] = np.sum((dA * pa + A * slope / np.maximum(om, 1e-300)) * wt, axis=1)
    return out[0], out[1], out[2]


def _elasto_plastic(surface, material, h, n_quad, elliptic, eccentricity, n_t, elastic_too,
                    window_tol=0.0, shape_table="spline"):
    """The elasto-plastic sums (and the elastic ones on the same nodes when ``elastic_too``).

    The inner t rule has four panels per (h, p, q) node, split at omega_c*, omega_p* and the
    peak of phi: every panel lies in one regime of the asperity law, so each is summed with its
    own regime's formula only. The elastic and plastic asperity quantities are powers of
    v = sqrt(t) times factors constant over the panel (omega = sqrt(m00 mu) v^2), so those
    panels need only the moments sum_t wt v^n, n = 0..3; the ZMC formula (logarithm, clipped
    cubic) is evaluated on the transition panels alone. Panels of zero width and (p, q) nodes
    of zero weight are skipped (they add exact zeros).
    """
    mat = material.resolve(surface)
    n_quad = _check_nquad(n_quad)
    shape, l, smu, Ds = _separations(surface, h)
    Es, H, ch, R = mat.E_star, mat.H, mat.ch, mat.omega_p_ratio
    pY = mat.yield_pressure
    chH = ch * H
    slope = H * (ch - 2.0 * mat.K_nu / 3.0) / math.log(R)
    out = {k: np.zeros(l.size) for k in _EP_KEYS}
    both = {k: np.zeros(l.size) for k in ("A", "W", "K")}   # all-elastic sums (elastic_too)
    n_t = max(16, (2 * n_quad) // 3) if n_t is None else _check_nquad(n_t)
    u, w = _gl01(n_t)
    # 1.5x more nodes along p: in deep contact the elastic/transition boundary of the flat
    # (small-p) asperities is a narrow feature in p (measured: 2e-4 -> 2e-5 at h = -5 sigma)
    n_p = (3 * n_quad) // 2
    # the p windows of all separations in one vectorised search: fewer calls than one search
    # per chunk, and with window_tol = 0 (to the fixed point, elementwise) the same windows;
    # with window_tol > 0 the search stops on the widest bracket of the call
    windows = _p_windows(l, math.sqrt(surface.beta1 + surface.beta2) / math.sqrt(surface.mu),
                         window_tol)
    n_pq = 3 * n_p * 3 * n_quad
    for sl in _chunks(l.size, n_pq, budget=_PQ_BUDGET):
        r4, r6, d, logw = _outer_nodes(surface, l[sl], n_quad, n_p, window_tol,
                                       windows=(windows[0][sl], windows[1][sl]))
        kappa, _, _, f1, f2, f3, KE = _asperity_shape(surface, r4, r6, elliptic, eccentricity,
                                                      shape_table)
        ex = np.exp(logw)
        d = np.broadcast_to(d[..., None], r4.shape)      # (n_h, n_p, n_q)
        wc = KE * (pY / Es) ** 2 / kappa          # (65) [mm]
        wp = R * wc
        tc, tp = wc / smu, wp / smu                # nondimensional omega_c*, omega_p*
        t_lo = np.maximum(0.0, -d - _T_WIDTH)
        t_hi = np.where(d <= 0, -d + _T_WIDTH, -d + np.sqrt(d * d + _T_WIDTH**2))
        v_lo, v_hi = np.sqrt(t_lo), np.sqrt(t_hi)
        vc, vp = np.sqrt(tc), np.sqrt(tp)
        c_area = np.pi / kappa                     # A = c_area * omega * (...)
        g2 = f2 / np.sqrt(kappa)
        # boundary term of -dW/dh at omega_c, where the asperity load jumps by
        # (2/3) K_nu H A_e(omega_c) - W_e(omega_c) (only where the window reaches omega_c)
        jump = f1 * c_area * wc * (2.0 / 3.0 * mat.K_nu * H) - 4.0 / 3.0 * Es * g2 * wc**1.5
        in_win = (tc >= t_lo) & (tc <= t_hi)
        phi_c = np.where(in_win, np.exp(-0.5 * (tc + d) ** 2) / math.sqrt(2 * math.pi), 0.0)
        out["K"][sl] += np.sum(ex * (jump * phi_c / smu), axis=(1, 2))
        # panels in v between the regime boundaries and the peak of phi (t = -d)
        vpk = np.sqrt(np.maximum(-d, 0.0))
        bp = np.sort(np.stack([v_lo, np.clip(vc, v_lo, v_hi), np.clip(vp, v_lo, v_hi),
                               np.clip(vpk, v_lo, v_hi), v_hi], axis=-1), axis=-1)
        a, b = bp[..., :-1], bp[..., 1:]                         # (n_h, n_p, n_q, 4)
        # each panel lies in one regime: [a, b] is below vc, between vc and vp, or above vp
        vm = 0.5 * (a + b)
        el = vm < vc[..., None]
        pl = vm >= vp[..., None]
        live = (b > a) & (ex > 0.0)[..., None]
        tr = live & ~(el | pl)
        # per-panel sums (flat over (h, p, q, panel)); dead panels stay zero
        panels = {key: np.zeros(a.size) for key in _EP_KEYS}
        # elastic and plastic panels (all live panels when the elastic sums are asked for too):
        # omega = smu v^2, so their sums are moments M_n = sum_t wt v^n
        sel = live if elastic_too else live & (el | pl)
        idx = np.flatnonzero(sel)
        node = idx // 4                            # the (h, p, q) node of each panel (flat)
        M = _panel_moments(a.ravel()[idx], b.ravel()[idx], d.ravel()[node], u, w)
        is_el, is_pl = el.ravel()[idx], pl.ravel()[idx]
        f1i, f3i, g2i, cai = (x.ravel()[node] for x in (f1, f3, g2, c_area))
        A_el = f1i * cai * smu * M[2]
        W_el = 4.0 / 3.0 * Es * g2i * smu**1.5 * M[3]
        k_el = 2.0 * Es * g2i * math.sqrt(smu) * M[1]
        A_pl = 2.0 * f3i * cai * smu * M[2]
        panels["Ae"][idx] = np.where(is_el, A_el, 0.0)
        panels["We"][idx] = np.where(is_el, W_el, 0.0)
        panels["Ap"][idx] = np.where(is_pl, A_pl, 0.0)
        panels["Wp"][idx] = np.where(is_pl, chH * A_pl, 0.0)
        panels["K"][idx] = np.where(is_el, k_el,
                                    np.where(is_pl, chH * 2.0 * f3i * cai * M[0], 0.0))
        if elastic_too:
            epanels = {key: np.zeros(a.size) for key in ("A", "W", "K")}
            for key, val in (("A", A_el), ("W", W_el), ("K", k_el)):
                epanels[key][idx] = val
        # transition (ZMC) panels: the full formula at their nodes
        idx = np.flatnonzero(tr)
        if idx.size:
            node = idx // 4
            At, Wt, Kt = _transition_sums(a.ravel()[idx], b.ravel()[idx], u, w, smu, R, chH,
                                          slope, *(x.ravel()[node] for x in (d, f1, f3, c_area,
                                                                             wc, wp)))
            panels["At"][idx] = At
            panels["Wt"][idx] = Wt
            panels["K"][idx] = Kt
        for key, val in panels.items():
            out[key][sl] += np.sum(ex * np.sum(val.reshape(a.shape), axis=-1), axis=(1, 2))
        if elastic_too:
            for key, val in epanels.items():
                both[key][sl] += np.sum(ex * np.sum(val.reshape(a.shape), axis=-1), axis=(1, 2))
    res = {k: (v * Ds).reshape(shape) for k, v in out.items()}
    A = res["Ae"] + res["At"] + res["Ap"]
    W = res["We"] + res["Wt"] + res["Wp"]
    ep = PopulationResult(A, W, res["K"], res["Ae"], res["At"], res["Ap"],
                          res["We"], res["Wt"], res["Wp"])
    if not elastic_too:
        return ep, None
    return ep, PopulationResult(*((both[k] * Ds).reshape(shape) for k in ("A", "W", "K")))


def greenwood_williamson(surface: SpectralMoments, E_star: float, h) -> PopulationResult:
    """McCool's equivalent isotropic Greenwood-Williamson model (GW columns of Tables 1-2).

    m2 = sqrt(m20 m02), m4 = sqrt(m40 m04), alpha = m00 m4/m2^2,
    eta = m4/(6 pi sqrt(3) m2), R = 0.375 sqrt(pi/m4), sigma_s^2 = (1 - 0.8968/alpha) m00,
    y_s = 4 sqrt(m00/(pi alpha)), d* = (h - y_s)/sigma_s,
    A/A0 = pi eta R sigma_s F1(d*), W/A0 = (4/3) eta E* R^(1/2) sigma_s^(3/2) F_{3/2}(d*),
    k_N = 2 eta E* R^(1/2) sigma_s^(1/2) F_{1/2}(d*)  (exact -dW/dh).

    Args:
        surface: spectral moments; E_star [MPa]; h separations [mm].
    """
    E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
    h = _check_h(h)
    m2 = math.sqrt(surface.m20 * surface.m02)
    m4 = math.sqrt(surface.m40 * surface.m04)
    alpha = surface.m00 * m4 / m2**2
    if alpha <= 0.8968:
        raise ValueError(f"GW equivalent alpha = {alpha:.6g} is invalid: it must exceed 0.8968")
    eta = m4 / (6.0 * math.pi * math.sqrt(3.0) * m2)
    R = 0.375 * math.sqrt(math.pi / m4)
    ss = math.sqrt((1.0 - 0.8968 / alpha) * surface.m00)
    ys = 4.0 * math.sqrt(surface.m00 / (math.pi * alpha))
    ds = (h - ys) / ss
    A = math.pi * eta * R * ss * F_n(1.0, ds)
    W = 4.0 / 3.0 * eta * E_star * math.sqrt(R) * ss**1.5 * F_n(1.5, ds)
    K = 2.0 * eta * E_star * math.sqrt(R) * math.sqrt(ss) * F_n(0.5, ds)
    return PopulationResult(A, W, K)


def _log_bearing_AG(surface: SpectralMoments, s, n_quad):
    """ln AG(s) (24) with s = h/sqrt(m00)."""
    s = _check_h(s)
    shape = s.shape
    mu = surface.mu
    l = s.ravel() / math.sqrt(mu)
    out = np.empty(l.size)
    geo = 2.0 * math.pi * surface.summit_density * math.sqrt(surface.m00 * mu) \
        / (surface.m40 * surface.m04) ** 0.25
    for sl in _chunks(l.size, 9 * n_quad * n_quad):
        r4, r6, d, logw = _outer_nodes(surface, l[sl], n_quad)
        with np.errstate(divide="ignore"):
            lg = logw + log_F_n(1.0, d)[..., None] - 0.5 * (np.log(r4) + np.log(r6))
        m = np.max(lg, axis=(1, 2), keepdims=True)
        m = np.where(np.isfinite(m), m, 0.0)
        out[sl] = m[:, 0, 0] + np.log(np.sum(np.exp(lg - m), axis=(1, 2)))
    return (out + math.log(geo)).reshape(shape)


def bearing_area(surface: SpectralMoments, s, n_quad: int = 48):
    """Bearing areas vs s = h/sqrt(m00): (AG (24) of the asperity model, AB (25) Gaussian).

    Both are fractions of the nominal area [-] and underflow to 0 only where the true values
    are below ~1e-308; use :func:`bearing_area_ratio` for the ratio at large s.
    """
    n_quad = _check_nquad(n_quad)
    s = _check_h(s)
    AB = 0.5 * special.erfc(s / math.sqrt(2.0))
    return np.exp(_log_bearing_AG(surface, s, n_quad)), AB


def bearing_area_ratio(surface: SpectralMoments, s, n_quad: int = 48):
    """AG/AB vs s = h/sqrt(m00), computed in log space (no underflow at large s)."""
    n_quad = _check_nquad(n_quad)
    s = _check_h(s)
    return np.exp(_log_bearing_AG(surface, s, n_quad) - special.log_ndtr(-s))
