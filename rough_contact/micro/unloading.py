"""Asperity plasticity remembered: unloading/reloading of one summit and of the summit population.

Issue 23, items 1-2 (pure numpy; the FE layer comes later). Readings, sources and limits are in
``docs/unloading.md``.

Single summit (elliptic paraboloid, mean curvature kappa_m, contact axis ratio e1, shape
factors f1, f2, f3 of ``asperity.py``). Loading follows the paper (Hertz (46)-(47) below
omega_c, Zhao-Maietta-Chang (75)-(77) up to omega_p, fully plastic (61), (67) beyond). After
a largest interference omega_max with load P_m = P(omega_max) and area A_m = A(omega_max):

* the summit unloads elastically from its flattened shape, read as an elliptic Hertz contact
  of a paraboloid with the same axis ratio and a *flatter* (smaller) mean curvature kappa_r,
  measured from the residual interference omega_res:

      P_u(omega) = P_m x^(3/2),  A_u(omega) = A_m x,  k_u = dP_u/domega = 1.5 P_m x^(1/2)/delta_e,
      x = (omega - omega_res)/delta_e in [0, 1],  delta_e = omega_max - omega_res;
      P_u = A_u = k_u = 0 for omega <= omega_res.

* delta_e (the recovered interference) follows from requiring that the Hertz contact of the
  flattened shape carries P_m on the *same* contact ellipse A_m at omega_max ("consistent"
  reading, the default):  delta_e = 1.5 P_m/S(A_m),  S(A) = 2 E* (f2/sqrt(f1)) sqrt(A/pi)
  = pi E* a/K(e) (the elastic stiffness of a contact ellipse of area A, semi-major axis a).
  Then the initial unloading slope is the elastic contact stiffness of the loaded ellipse
  (exact for any elastic unloading that starts on the loaded contact area) and
  kappa_r = f1 pi delta_e/A_m. For omega_max <= omega_c this gives delta_e = omega_max,
  omega_res = 0 exactly: the elastic summit is reversible. delta_e is clipped to omega_max
  (omega_res >= 0).
* optional ``residual="ekk"``: omega_res from the Etsion-Kligerman-Kadin (2005) sphere fit
  (see :func:`ekk_residual_ratio`; coefficients recalled, NOT verified against the paper).
* reloading (omega_res < omega <= omega_max) follows the same elastic curve; beyond omega_max
  the loading branch, and omega_max grows.

Population: a point of the interface with smallest separation h_min so far has every summit of
height z at omega_max = z - h_min; at separation h >= h_min its interference is omega = z - h.
p(h, h_min), k = -dp/dh at fixed h_min, a = A/A0 are population sums over the summit heights and
curvatures (the paper's density (18)). For h <= h_min the point is loading: h_min := h.

Units: lengths mm, curvatures 1/mm, pressures/moduli MPa, loads N, stiffness of one summit N/mm,
population stiffness MPa/mm. Surface moments as ``SpectralMoments`` (um convention at its API).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from . import population as _pop
from .asperity import (AsperityMaterial, critical_interference, shape_factors, zmc_area,
                       zmc_mean_pressure)
from ..validation import check_scalar

__all__ = ["summit_loading", "recovered_interference", "summit_unloading", "ekk_residual_ratio",
           "population_unloading", "HistoryNormalLaw"]

_RESIDUAL = ("consistent", "ekk")


# ---------------------------------------------------------------------------------------------
# single summit
# ---------------------------------------------------------------------------------------------
def _loading(W, kappa, f1, f2, f3, wc, wp, mat: AsperityMaterial):
    """Paper's loading law at interference W [mm]: (area [mm^2], load [N], dP/dW [N/mm]).

    Broadcasting in all arguments; the same regimes as ``asperity.asperity_response``.
    """
    W = np.maximum(W, 0.0)
    Es, H, ch = mat.E_star, mat.H, mat.ch
    c = np.pi / kappa
    g2 = f2 / np.sqrt(kappa)
    Ae, We, ke = f1 * c * W, 4.0 / 3.0 * Es * g2 * W ** 1.5, 2.0 * Es * g2 * np.sqrt(W)
    Aep, dAep = zmc_area(W, kappa, f1, f3, wc, wp)
    pa, dpa = zmc_mean_pressure(np.clip(W, wc, wp), wc, mat)
    Ap = 2.0 * f3 * c * W
    el = W < wc
    pl = W >= wp
    A = np.where(el, Ae, np.where(pl, Ap, Aep))
    P = np.where(el, We, np.where(pl, ch * H * Ap, Aep * pa))
    k = np.where(el, ke, np.where(pl, ch * H * 2.0 * f3 * c, dAep * pa + Aep * dpa))
    return A, P, k


def _delta_e(W, A, P, f1, f2, Es):
    """Recovered interference delta_e = min(W, 1.5 P/S(A)) [mm] ("consistent" reading)."""
    S = 2.0 * Es * (f2 / np.sqrt(f1)) * np.sqrt(A / np.pi)
    with np.errstate(divide="ignore", invalid="ignore"):
        de = np.where(S > 0, 1.5 * P / S, 0.0)
    return np.minimum(de, W)


def ekk_residual_ratio(omega_max_star):
    """omega_res/omega_max after unloading a sphere from omega_max_star = omega_max/omega_c.

    The Etsion-Kligerman-Kadin (2005) fit in the form
    1.02 [1 - (w* + 5.9)^(-0.54)] [1 - (w*)^(-0.14)] for w* >= 1 (0 below), stated by its
    authors for 1 <= w* <= 110 (their loading law: Kogut-Etsion, elastic-linear-hardening FE).
    The coefficients are the form as recalled: the paper's text could not be retrieved to check
    them (docs/unloading.md says what was checked and what is uncertain); the option is
    provisional. Elliptic summits: w* uses the summit's own omega_c, and the ratio is taken as
    the sphere's at the same w* (reading stated in docs/unloading.md).
    """
    w = np.asarray(omega_max_star, dtype=float)
    ws = np.maximum(w, 1.0)
    r = 1.02 * (1.0 - (ws + 5.9) ** -0.54) * (1.0 - ws ** -0.14)
    return np.where(w <= 1.0, 0.0, np.clip(r, 0.0, 1.0))


def _resolve(kappa_m, e1, material, elliptic):
    mat = material
    if mat.H is None:
        raise ValueError("material is not resolved (hardness H unknown): call "
                         "material.resolve(surface) first")
    kappa = np.asarray(kappa_m, dtype=float)
    if np.any(~np.isfinite(kappa) | (kappa <= 0)):
        raise ValueError(f"kappa_m = {kappa_m!r} 1/mm is invalid: valid range (0, inf)")
    f1, f2, f3, _, KE = shape_factors(e1, elliptic)
    wc = critical_interference(kappa, KE, mat.yield_pressure, mat.E_star)
    return kappa, f1, f2, f3, wc, mat.omega_p_ratio * wc


def summit_loading(omega, kappa_m, e1, material: AsperityMaterial, elliptic: str = "exact"):
    """Loading branch of one summit: dict area [mm^2], load [N], stiffness [N/mm], omega_c [mm]."""
    kappa, f1, f2, f3, wc, wp = _resolve(kappa_m, e1, material, elliptic)
    A, P, k = _loading(np.asarray(omega, float), kappa, f1, f2, f3, wc, wp, material)
    return {"area": A, "load": P, "stiffness": k, "omega_c": wc, "omega_p": wp}


def recovered_interference(omega_max, kappa_m, e1, material: AsperityMaterial,
                           residual: str = "consistent", elliptic: str = "exact"):
    """(omega_res, delta_e) [mm] after a largest interference omega_max [mm] >= 0.

    residual="consistent": delta_e = min(omega_max, 1.5 P_m/S(A_m)) (module docstring);
    residual="ekk": omega_res = ekk_residual_ratio(omega_max/omega_c) omega_max.
    """
    if residual not in _RESIDUAL:
        raise ValueError(f"residual = {residual!r} is invalid: valid values are {_RESIDUAL}")
    W = np.asarray(omega_max, dtype=float)
    if np.any(~np.isfinite(W) | (W < 0)):
        raise ValueError(f"omega_max = {omega_max!r} mm is invalid: valid range [0, inf)")
    kappa, f1, f2, f3, wc, wp = _resolve(kappa_m, e1, material, elliptic)
    A, P, _ = _loading(W, kappa, f1, f2, f3, wc, wp, material)
    if residual == "consistent":
        de = np.where(W < wc, W, _delta_e(W, A, P, f1, f2, material.E_star))
    else:
        de = W * (1.0 - ekk_residual_ratio(W / wc))
    return W - de, de


def summit_unloading(omega, omega_max, kappa_m, e1, material: AsperityMaterial,
                     residual: str = "consistent", elliptic: str = "exact"):
    """Response of one summit at interference omega after a largest interference omega_max.

    Args:
        omega: interference [mm] (any real; <= omega_res gives zeros).
        omega_max: largest interference reached so far [mm] >= 0; where omega > omega_max the
            summit is loading (the loading branch is returned, omega_max := omega).
        kappa_m: mean curvature (44) [1/mm] > 0; e1: contact axis ratio B/A in (0, 1].
        material: resolved AsperityMaterial; residual: "consistent" or "ekk".
    Returns:
        dict: load [N], stiffness dP/domega [N/mm], area [mm^2], omega_res [mm],
        delta_e [mm], loading (bool: on the loading branch). Broadcast shapes.
    """
    omega = np.asarray(omega, dtype=float)
    if np.any(np.isnan(omega)):
        raise ValueError("omega contains NaN: valid range (-inf, inf) mm")
    Wm = np.maximum(np.asarray(omega_max, dtype=float), omega)
    Wm = np.maximum(Wm, 0.0)
    kappa, f1, f2, f3, wc, wp = _resolve(kappa_m, e1, material, elliptic)
    Am, Pm, km = _loading(Wm, kappa, f1, f2, f3, wc, wp, material)
    w_res, de = recovered_interference(Wm, kappa_m, e1, material, residual, elliptic)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.clip(np.where(de > 0, (omega - w_res) / de, 0.0), 0.0, 1.0)
        ku = np.where(de > 0, 1.5 * Pm * np.sqrt(x) / de, 0.0)
    loading = omega >= Wm
    return {"load": Pm * x ** 1.5, "area": Am * x,
            "stiffness": np.where(loading & (omega > 0), km, ku),
            "omega_res": w_res, "delta_e": de, "loading": loading}


# ---------------------------------------------------------------------------------------------
# population sums (the table's model): shape nodes of population._outer_nodes, inner
# Gauss-Legendre over the summit height with the edges of the unloading law as panel ends
# ---------------------------------------------------------------------------------------------
def _invert_delta_e(tau, tc, tp, kappa, f1, f2, f3, wc, wp, mat, smu, n_iter=48):
    """Smallest t2 >= tc with delta_e(smu t2) >= smu tau on the ZMC/plastic branch (t units).

    delta_e is increasing on [omega_c, inf) (checked in the tests); plastic branch in closed
    form (delta_e = C sqrt(W)), the ZMC branch by bisection.
    """
    Es = mat.E_star
    # plastic: delta_e = 1.5 ch H A/S(A) = C_p sqrt(W)
    Cp = 1.5 * mat.ch * mat.H * math.sqrt(math.pi) / (2.0 * Es) * np.sqrt(f1) / f2 \
        * np.sqrt(2.0 * np.pi * f3 / kappa)
    tpl = (tau * smu) ** 2 / (Cp * Cp) / smu
    Ap, Pp, _ = _loading(wp, kappa, f1, f2, f3, wc, wp, mat)
    dep = _delta_e(wp, Ap, Pp, f1, f2, Es)
    Ac, Pc, _ = _loading(wc * (1 + 1e-12), kappa, f1, f2, f3, wc, wp, mat)
    dec = _delta_e(wc, Ac, Pc, f1, f2, Es)
    lo = np.broadcast_to(tc, np.broadcast(tau, tc).shape).copy()
    hi = np.broadcast_to(tp, lo.shape).copy()
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        A, P, _ = _loading(smu * mid, kappa, f1, f2, f3, wc, wp, mat)
        up = _delta_e(smu * mid, A, P, f1, f2, Es) < smu * tau
        lo = np.where(up, mid, lo)
        hi = np.where(up, hi, mid)
    t2 = np.where(smu * tau <= dec, tc, np.where(smu * tau >= dep, np.maximum(tpl, tp), hi))
    return t2


def _row_sums(surface, mat, h_min, u, n_quad, n_t):
    """p, k, a at (h_min + u, h_min) for one h_min [mm] and an array u >= 0 [mm]."""
    smu = math.sqrt(surface.m00 * surface.mu)
    l = np.array([h_min / smu])
    r4, r6, d, logw = _pop._outer_nodes(surface, l, n_quad, n_quad)
    kappa, _, _, f1, f2, f3, KE = _pop._asperity_shape(surface, r4, r6, "exact", "exact")
    keep = np.isfinite(logw) & (logw > np.max(logw) - 60.0)
    S = lambda x: np.broadcast_to(x, logw.shape)[keep][None, :]   # noqa: E731  (1, n_s)
    kappa, f1, f2, f3, KE = S(kappa), S(f1), S(f2), S(f3), S(KE)
    dd = S(d[..., None])
    ex = np.exp(S(logw))
    Es = mat.E_star
    wc = KE * (mat.yield_pressure / Es) ** 2 / kappa
    wp = mat.omega_p_ratio * wc
    tc, tp = wc / smu, wp / smu
    tau = (np.asarray(u, float) / smu)[:, None]                       # (n_u, 1)
    t_lo = np.maximum(0.0, -dd - 12.0)
    t_hi = np.where(dd <= 0, -dd + 12.0, -dd + np.sqrt(dd * dd + 144.0))
    tpk = -dd
    t2 = _invert_delta_e(tau, tc, tp, kappa, f1, f2, f3, wc, wp, mat, smu)
    x, w = _pop._gl01(n_t)
    out = [np.zeros(tau.shape[0]) for _ in range(3)]
    # panels: (start of sqrt substitution, panel lower, panel upper)
    panels = [(tau, np.maximum(tau, t_lo), np.minimum(tc, t_hi)),            # elastic summits
              (t2, np.maximum(t2, t_lo), np.minimum(tp, t_hi)),              # ZMC
              (np.maximum(t2, tp), np.maximum(np.maximum(t2, tp), t_lo), t_hi)]  # plastic
    for t0, a, b in panels:
        b = np.maximum(a, b)
        va, vb = np.sqrt(np.maximum(a - t0, 0.0)), np.sqrt(np.maximum(b - t0, 0.0))
        vpk = np.clip(np.sqrt(np.maximum(tpk - t0, 0.0)), va, vb)
        for lo, hi in ((va, vpk), (vpk, vb)):
            for j in range(n_t):
                v = lo + (hi - lo) * x[j]
                t = t0 + v * v
                jac = 2.0 * v * (hi - lo) * w[j]
                W = smu * t
                A, P, _ = _loading(W, kappa, f1, f2, f3, wc, wp, mat)
                de = np.where(W < wc, W, _delta_e(W, A, P, f1, f2, Es))
                with np.errstate(divide="ignore", invalid="ignore"):
                    xi = np.clip(np.where(de > 0, 1.0 - smu * tau / de, 0.0), 0.0, 1.0)
                    kk = np.where(de > 0, 1.5 * P * np.sqrt(xi) / de, 0.0)
                g = ex * jac * np.exp(-0.5 * (t + dd) ** 2) / math.sqrt(2 * math.pi)
                out[0] += np.sum(g * P * xi ** 1.5, axis=1)
                out[1] += np.sum(g * kk, axis=1)
                out[2] += np.sum(g * A * xi, axis=1)
    Ds = surface.summit_density
    return out[0] * Ds, out[1] * Ds, out[2] * Ds


def population_unloading(surface, material: AsperityMaterial, h, h_min, n_quad: int = 12,
                         n_t: int = 12):
    """Population sums p [MPa], k = -dp/dh at fixed h_min [MPa/mm], A/A0 [-] at (h, h_min).

    The direct (untabulated) model of :class:`HistoryNormalLaw`. h_min scalar [mm]; h array
    [mm]; h < h_min is the loading branch (h_min := h there, k is then the unloading stiffness
    at h_min = h, not the loading one: the table takes the loading branch from ``NormalLaw``).
    Reading: ``residual="consistent"``.
    """
    mat = material.resolve(surface)
    h = np.atleast_1d(np.asarray(h, dtype=float))
    hm = float(h_min)
    res = [np.empty(h.size) for _ in range(3)]
    lower = h < hm
    u = np.where(lower, 0.0, h - hm)
    # rows: distinct h_min (loading points each have their own)
    if (~lower).any():
        idx = np.flatnonzero(~lower)
        for c in range(0, idx.size, 64):
            sl = idx[c:c + 64]
            vals = _row_sums(surface, mat, hm, u[sl], n_quad, n_t)
            for r, v in zip(res, vals):
                r[sl] = v
    for i in np.flatnonzero(lower):
        vals = _row_sums(surface, mat, h[i], np.zeros(1), n_quad, n_t)
        for r, v in zip(res, vals):
            r[i] = v[0]
    return tuple(r.reshape(np.shape(h)) for r in res)


# ---------------------------------------------------------------------------------------------
# the tabulated law
# ---------------------------------------------------------------------------------------------
def _h_basis(t):
    """Cubic Hermite basis (h00, h01, h10, h11) and their t-derivatives."""
    t2, t3 = t * t, t * t * t
    H = (2 * t3 - 3 * t2 + 1, -2 * t3 + 3 * t2, t3 - 2 * t2 + t, t3 - t2)
    dH = (6 * t2 - 6 * t, -6 * t2 + 6 * t, 3 * t2 - 4 * t + 1, 3 * t2 - 2 * t)
    return H, dH


def _fd_rows(v, dx):
    """d v/d x along axis 0 on a uniform grid: central, one-sided 3-point at the ends."""
    d = np.empty_like(v)
    d[1:-1] = (v[2:] - v[:-2]) / (2 * dx)
    if v.shape[0] >= 3:
        d[0] = (-3 * v[0] + 4 * v[1] - v[2]) / (2 * dx)
        d[-1] = (3 * v[-1] - 4 * v[-2] + v[-3]) / (2 * dx)
    else:
        d[0] = d[-1] = (v[-1] - v[0]) / dx
    return d


@dataclass(frozen=True, eq=False)
class HistoryNormalLaw:
    """Irreversible normal law p(h, h_min), k(h, h_min) = -dp/dh, A/A0(h, h_min).

    Build with :meth:`elasto_plastic` (table, see docs/unloading.md) or :meth:`elastic`
    (exactly reversible: the loading ``NormalLaw`` itself, h_min ignored).

    Table (elasto-plastic): the loading branch is a ``NormalLaw`` (``loading``); the unloading
    branch is stored as rho(h_min, s) = ln p(h, h_min) - ln p(h_min, h_min) with
    s = (h - h_min)/(h_end - h_min) in [0, 1] (h_end = loading.h_table_end), as a bicubic
    Hermite surface on a uniform h_min grid x an adaptive s grid: s-slopes are the model's
    stiffness (d rho/ds = -k/p (h_end - h_min)), h_min-slopes finite differences. k is the
    exact s-derivative of the interpolant (consistent tangent at fixed h_min). ln(A/A0) is
    interpolated the same way with finite-difference s-slopes. Beyond s = 1 the cubic taper
    of ``NormalLaw``; h_min above h_end: reversible (nothing is plastic there); h_min below the
    loading table (the penalty continuation): the unloading shape of the first row.
    """

    loading: object
    rtol: float | None
    _hm: np.ndarray | None = None       # (n_m,) uniform h_min knots [mm]
    _s: np.ndarray | None = None        # (n_s,) s knots
    _R: tuple | None = None             # (rho, rho_s, rho_m, rho_ms) each (n_m, n_s)
    _RA: tuple | None = None            # same for ln(a) - ln(a0)
    info: dict = field(default_factory=dict)

    # ------------------------------------------------------------ constructors
    @classmethod
    def elastic(cls, surface, E_star: float, rtol: float = 1e-4, **kwargs) -> "HistoryNormalLaw":
        """Elastic population: the reversible ``NormalLaw.elastic`` (h_min has no effect)."""
        from .interface.normal import NormalLaw
        t0 = time.perf_counter()
        law = NormalLaw.elastic(surface, E_star, rtol, **kwargs)
        return cls(loading=law, rtol=rtol, info={"build_seconds": time.perf_counter() - t0,
                                                  "reversible": True})

    @classmethod
    def elasto_plastic(cls, surface, material: AsperityMaterial, rtol: float = 1e-4, *,
                       loading=None, n_quad: int = 16, n_t: int = 16, n_rows: int = 8,
                       n_s: int = 8, floor: float = 1e-8, max_rounds: int = 12,
                       max_seconds: float = 600.0, strict: bool = True) -> "HistoryNormalLaw":
        """Table of the elasto-plastic population with memory (reading "consistent").

        Args:
            surface: SpectralMoments; material: AsperityMaterial (psi resolved on surface).
            rtol: relative accuracy of p, k, A/A0 of the unloading branch against the direct
                sums (:func:`population_unloading` with the same n_quad, n_t) at the check
                points (s-midpoints of knot rows, h_min-midpoint rows at s knots), in
                [1e-8, 0.1]; errors relative to max(value, floor * value at u = 0).
            loading: a prebuilt ``NormalLaw.elasto_plastic`` of the same surface/material
                (its build time is then not counted); None builds one at rtol.
            n_quad, n_t: quadrature of the direct sums (shape rule / height nodes per panel).
            n_rows, n_s: initial numbers of h_min and s intervals.
            floor: relative floor of the error measure (pressures below floor * p(h_min)
                are controlled in absolute terms only).
            strict: False returns the table of the last round when rtol or the budget is not
                met (info["worst_checkpoint_error"] says what was reached).
        Raises:
            ValueError: bad arguments; RuntimeError: rtol not reached within max_rounds or
                max_seconds (message: reached accuracy and where).
        """
        from .interface.normal import NormalLaw
        t0 = time.perf_counter()
        rtol = check_scalar("rtol", rtol, lo=1e-8, hi=0.1, lo_open=False, hi_open=False)
        floor = check_scalar("floor", floor, lo=0.0, hi=1e-2)
        mat = material.resolve(surface)
        if loading is None:
            loading = NormalLaw.elasto_plastic(surface, mat, rtol)
        t_load = time.perf_counter() - t0
        t1 = time.perf_counter()
        hL, hE = loading.h_min, loading.h_table_end
        cache = {}
        n_eval = [0]

        def rows(hms, s):
            """model rho, d rho/ds, ln a - ln a0 at rows hms and s values (cached)."""
            out = np.empty((3, len(hms), len(s)))
            for i, hm in enumerate(hms):
                key = float(hm)
                have = cache.setdefault(key, {})
                need = [x for x in s if float(x) not in have]
                if need:
                    L = hE - hm
                    ss = np.array(need)
                    allu = np.concatenate([[0.0], ss * L])
                    p, k, a = _row_sums(surface, mat, hm, allu, n_quad, n_t)
                    n_eval[0] += allu.size
                    p0, a0 = p[0], a[0]
                    pc = np.maximum(p[1:], 1e-300)
                    for x, pv, kv, av in zip(need, pc, k[1:], np.maximum(a[1:], 1e-300)):
                        have[float(x)] = (math.log(pv / p0), -kv / pv * L,
                                          math.log(av / a0), pv / p0, kv * L / p0, av / a0)
                for j, x in enumerate(s):
                    out[:, i, j] = have[float(x)][:3]
            return out

        def errors(hms, s_chk, rho_i, drho_i, la_i):
            """relative errors of p, k, a at check points against the model."""
            m = rows(hms, s_chk)
            P, Pi = np.exp(m[0]), np.exp(rho_i)
            K, Ki = -m[1] * P, -drho_i * Pi
            A, Ai = np.exp(m[2]), np.exp(la_i)
            e = [np.abs(Pi - P) / np.maximum(P, floor), np.abs(Ki - K) / np.maximum(K, floor * K.max()),
                 np.abs(Ai - A) / np.maximum(A, floor)]
            return np.maximum.reduce(e)

        hm = np.linspace(hL, hE, n_rows + 1)[:-1]       # the row at h_end itself is empty
        s = np.linspace(0.0, 1.0, n_s + 1)
        worst = np.inf
        for rnd in range(max_rounds):
            if time.perf_counter() - t1 > max_seconds:
                if not strict:
                    break
                raise RuntimeError(f"HistoryNormalLaw: max_seconds = {max_seconds} s exceeded "
                                   f"at rtol = {rtol}; reached {worst:.2g}")
            R, RA = cls._surface(rows(hm, s), hm, s)
            # (i) s-midpoints on the knot rows
            sm = 0.5 * (s[:-1] + s[1:])
            rho_i, drho_i, la_i = cls._patch(R, RA, hm, s, np.repeat(hm[:, None], sm.size, 1),
                                             np.broadcast_to(sm, (hm.size, sm.size)))
            e_s = errors(hm, sm, rho_i, drho_i, la_i)          # (n_m, n_s-1)
            # (ii) h_min-midpoint rows at s knots (and s midpoints)
            hmid = 0.5 * (hm[:-1] + hm[1:])
            sc = np.sort(np.concatenate([s, sm]))
            rho_i, drho_i, la_i = cls._patch(R, RA, hm, s, np.repeat(hmid[:, None], sc.size, 1),
                                             np.broadcast_to(sc, (hmid.size, sc.size)))
            e_m = errors(hmid, sc, rho_i, drho_i, la_i)
            worst = max(e_s.max(), e_m.max())
            bad_s = (e_s > 0.5 * rtol).any(axis=0)
            bad_m = (e_m > 0.5 * rtol).any()
            if not bad_s.any() and not bad_m:
                break
            if bad_s.any():
                s = np.sort(np.concatenate([s, sm[bad_s]]))
            if bad_m:
                hm = np.sort(np.concatenate([hm, hmid]))
        else:
            if strict:
                raise RuntimeError(f"HistoryNormalLaw: rtol = {rtol} not reached in {max_rounds} "
                                   f"rounds (reached {worst:.2g}); loosen rtol or raise max_rounds")
        R, RA = cls._surface(rows(hm, s), hm, s)
        info = {"build_seconds": time.perf_counter() - t0, "loading_seconds": t_load,
                "history_seconds": time.perf_counter() - t1, "rows": hm.size, "s_knots": s.size,
                "model_points": n_eval[0], "worst_checkpoint_error": float(worst),
                "n_quad": n_quad, "n_t": n_t, "floor": floor, "reversible": False}
        return cls(loading=loading, rtol=rtol, _hm=hm, _s=s, _R=R, _RA=RA, info=info)

    @staticmethod
    def _surface(m, hm, s):
        """Bicubic Hermite data from model rows m = (rho, d rho/ds, ln a - ln a0)."""
        from .interface.normal import _limited_slopes
        rho, rs = m[0], m[1]
        dm = hm[1] - hm[0] if hm.size > 1 else 1.0
        la = m[2]
        las = np.stack([_limited_slopes(s, row) for row in la])
        R = (rho, rs, _fd_rows(rho, dm), _fd_rows(rs, dm))
        RA = (la, las, _fd_rows(la, dm), _fd_rows(las, dm))
        return R, RA

    @staticmethod
    def _patch(R, RA, hm, s, H, S):
        """Evaluate (rho, d rho/ds, ln a - ln a0) at rows H (clipped to the grid) and s = S."""
        n_m = hm.size
        dm = hm[1] - hm[0] if n_m > 1 else 1.0
        x = np.clip((H - hm[0]) / dm, 0.0, n_m - 1)
        i = np.minimum(x.astype(np.intp), max(n_m - 2, 0))
        tm = x - i
        j = np.clip(np.searchsorted(s, S, side="right") - 1, 0, s.size - 2)
        ds = s[j + 1] - s[j]
        ts = (S - s[j]) / ds
        Hm, _ = _h_basis(tm)
        Hs, dHs = _h_basis(ts)
        i1 = np.minimum(i + 1, n_m - 1)
        res = []
        for (v, vs, vm, vms), deriv in ((R, True), (RA, False)):
            acc = 0.0
            dacc = 0.0
            for ia, wa, wad in ((i, Hm[0], Hm[2]), (i1, Hm[1], Hm[3])):
                for jb, wb, wbd, dwb, dwbd in ((j, Hs[0], Hs[2], dHs[0], dHs[2]),
                                                (j + 1, Hs[1], Hs[3], dHs[1], dHs[3])):
                    f = v[ia, jb] * wa + dm * vm[ia, jb] * wad
                    fs = vs[ia, jb] * wa + dm * vms[ia, jb] * wad
                    acc = acc + f * wb + ds * fs * wbd
                    if deriv:
                        dacc = dacc + (f * dwb + ds * fs * dwbd) / ds
            res.append(acc)
            if deriv:
                res.append(dacc)
        return res[0], res[1], res[2]

    # ------------------------------------------------------------ evaluation
    def evaluate(self, h, h_min):
        """(p [MPa], k = -dp/dh at fixed h_min [MPa/mm], A/A0 [-]) at separations h, history h_min.

        Args:
            h: separations [mm] (finite or +inf); h_min: smallest separation reached so far [mm]
                (broadcast with h). Where h <= h_min the point is loading (h_min := h, the
                caller commits min(h_min, h)) and the loading ``NormalLaw`` is returned.
        """
        h = np.asarray(h, dtype=float)
        hmn = np.asarray(h_min, dtype=float)
        if np.isnan(h).any() or np.isnan(hmn).any():
            raise ValueError("h or h_min contains NaN: valid range (-inf, inf] mm")
        h, hmn = np.broadcast_arrays(h, hmn)
        shape = h.shape
        h, hmn = h.ravel(), hmn.ravel()
        p, k, a = (v.ravel().copy() for v in self.loading.evaluate(np.minimum(h, hmn)
                                                                   if self._R is None else h))
        if self._R is None:                     # reversible (elastic)
            return p.reshape(shape), k.reshape(shape), a.reshape(shape)
        hL, hE = self.loading.h_min, self.loading.h_table_end
        un = np.flatnonzero((h > hmn) & (hmn < hE))
        if un.size:
            hu, hmu = h[un], hmn[un]
            p0, _, a0 = self.loading.evaluate(hmu)
            L = hE - np.maximum(hmu, hL)
            S = (hu - hmu) / L
            Sc = np.minimum(S, 1.0)
            rho, drho, la = self._patch(self._R, self._RA, self._hm, self._s,
                                        np.maximum(hmu, hL), Sc)
            pu = p0 * np.exp(rho)
            ku = -pu * drho / L
            au = a0 * np.exp(la)
            tp = S > 1.0
            if tp.any():                        # cubic taper (as NormalLaw) beyond s = 1
                Lt = 3.0 * pu[tp] / np.maximum(ku[tp], 1e-300)
                t = np.clip((hu[tp] - (hmu[tp] + L[tp])) / Lt, 0.0, 1.0)
                kk = 3.0 * pu[tp] / Lt * (1 - t) ** 2
                pu[tp] = pu[tp] * (1 - t) ** 3
                au[tp] = au[tp] * (1 - t) ** 3
                ku[tp] = kk
            p[un], k[un], a[un] = pu, ku, au
        return p.reshape(shape), k.reshape(shape), a.reshape(shape)
