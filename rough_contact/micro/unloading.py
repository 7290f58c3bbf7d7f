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
import numpy as np

from . import population as _pop
from .asperity import (AsperityMaterial, critical_interference, shape_factors, zmc_area,
                       zmc_mean_pressure)

__all__ = ["summit_loading", "recovered_interference", "summit_unloading", "ekk_residual_ratio",
           "population_unloading"]

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
    """p, k, a, -da/dh at (h_min + u, h_min) for one h_min [mm] and an array u >= 0 [mm]."""
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
    out = [np.zeros(tau.shape[0]) for _ in range(4)]
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
                with np.errstate(divide="ignore", invalid="ignore"):
                    out[3] += np.sum(g * np.where((xi > 0) & (de > 0), A / de, 0.0), axis=1)
    Ds = surface.summit_density
    return out[0] * Ds, out[1] * Ds, out[2] * Ds, out[3] * Ds


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
            vals = _row_sums(surface, mat, hm, u[sl], n_quad, n_t)[:3]
            for r, v in zip(res, vals):
                r[sl] = v
    for i in np.flatnonzero(lower):
        vals = _row_sums(surface, mat, h[i], np.zeros(1), n_quad, n_t)[:3]
        for r, v in zip(res, vals):
            r[i] = v[0]
    return tuple(r.reshape(np.shape(h)) for r in res)
