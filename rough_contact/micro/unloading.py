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
* optional ``residual="ekk"``: omega_res from a sphere fit attributed to Etsion-Kligerman-Kadin
  (2005) (see :func:`ekk_residual_ratio`: coefficients recalled, NOT verified against the
  paper, and most likely a garbled Jackson-Chusoipin-Green fit; provisional).
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
           "jcg_residual_ratio", "population_unloading"]

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


def _omega_star(omega_max_star, name="omega_max_star"):
    w = np.asarray(omega_max_star, dtype=float)
    if np.any(~np.isfinite(w) | (w < 0)):
        raise ValueError(f"{name} = {omega_max_star!r} (omega_max/omega_c) is invalid: "
                         "valid range [0, inf)")
    return w


def ekk_residual_ratio(omega_max_star):
    """omega_res/omega_max after unloading a sphere from omega_max_star = omega_max/omega_c.

    PROVISIONAL, NOT the verified Etsion-Kligerman-Kadin (2005) fit. The form evaluated is
    1.02 [1 - (w* + 5.9)^(-0.54)] [1 - (w*)^(-0.14)] for w* >= 1 (0 below), as recalled when
    the option was written. The EKK paper's text could not be retrieved to check it. Its first
    factor carries the constants 1.02, 5.9 and -0.54 of the Jackson-Chusoipin-Green (2005) fit
    (:func:`jcg_residual_ratio`, 1.02 [1 - ((w* + 5.9)/6.9)^(-0.54)]) without JCG's
    normalisation by 6.9, so the recalled form is most likely a garbled JCG fit attributed to
    EKK (docs/unloading_literature.md). Kept unchanged (no verified replacement) for the
    provisional option residual="ekk" only. Elliptic summits: w* uses the summit's own
    omega_c, and the ratio is taken as the sphere's at the same w* (docs/unloading.md).
    """
    w = _omega_star(omega_max_star)
    ws = np.maximum(w, 1.0)
    r = 1.02 * (1.0 - (ws + 5.9) ** -0.54) * (1.0 - ws ** -0.14)
    return np.where(w <= 1.0, 0.0, np.clip(r, 0.0, 1.0))


def jcg_residual_ratio(omega_max_star):
    """Jackson-Chusoipin-Green (2005) residual interference of a hemisphere (comparison only).

    omega_res/omega_max = 1.02 [1 - ((w* + 5.9)/6.9)^(-0.54)], w* = omega_max/omega_c >= 1
    (0 below: elastic, reversible); J. Tribol. 127 (2005) 484, elastic-perfectly plastic FE,
    omega_c of Jackson-Green (C = 1.295 exp(0.736 nu)). Read from a public implementation, not
    from the paper (docs/unloading_literature.md). Not used by any law of this package.
    """
    w = _omega_star(omega_max_star)
    ws = np.maximum(w, 1.0)
    return np.where(w <= 1.0, 0.0, 1.02 * (1.0 - ((ws + 5.9) / 6.9) ** -0.54))


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
# population sums (the table's model)
# ---------------------------------------------------------------------------------------------
_SCAN = 24            # scan points per zeta node that locate the curvature window
_SCAN_T = 6           # height nodes per half-panel of the scan
_LOG_CUT = 34.0       # windows keep the integrand above exp(-34) of its maximum


def _invert_delta_e(tau, tc, tp, kappa, f1, f2, f3, wc, wp, mat, smu, n_iter=40):
    """Smallest t2 >= tc with delta_e(smu t2) >= smu tau on the ZMC/plastic branch (t units).

    delta_e is increasing on [omega_c, inf) (checked in the tests); plastic branch in closed
    form (delta_e = C sqrt(W)), the ZMC branch (only where it is needed) by Newton's method
    with the exact derivative of delta_e = 1.5 pa sqrt(A)/c_S, kept inside a shrinking
    bracket (a step leaving it is replaced by the bisection), from the secant of the
    bracket; at most n_iter steps, stopped when every step is below 1e-10 of t (quadratic
    convergence: t is then at round-off; 4-5 steps). Steps below ~1e-11 cannot be asked for:
    f has round-off noise of ~1e-11 of the target (the log of ZMC's mean pressure).
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
    shape = np.broadcast(tau, tc).shape
    hi = np.broadcast_to(tp, shape).copy()
    zmc = (smu * tau > dec) & (smu * tau < dep)
    if zmc.any():
        Z = lambda x: np.broadcast_to(x, shape)[zmc]   # noqa: E731
        ka, g1, g2, g3, c, p_, ta = Z(kappa), Z(f1), Z(f2), Z(f3), Z(wc), Z(wp), Z(tau)
        lo_, hi_ = Z(tc).copy(), Z(tp).copy()
        target = smu * ta
        flo, fhi = Z(dec) - target, Z(dep) - target          # < 0 and > 0
        cS = 2.0 * Es * (g2 / np.sqrt(g1)) / math.sqrt(math.pi)        # S(A) = cS sqrt(A)
        t = lo_ - flo * (hi_ - lo_) / (fhi - flo)
        act = np.arange(t.size)          # not converged yet (each point on its own: the
        for _ in range(n_iter):          # result does not depend on the other points)
            ti, lo_i, hi_i = t[act], lo_[act], hi_[act]
            A, dA = zmc_area(smu * ti, ka[act], g1[act], g3[act], c[act], p_[act])
            pa, dpa = zmc_mean_pressure(smu * ti, c[act], mat)      # ZMC branch only
            sA = np.sqrt(A)
            f = 1.5 * pa * sA / cS[act] - target[act]
            df = 1.5 * smu / cS[act] * (dpa * sA + 0.5 * pa * dA / sA)   # d delta_e/dt
            up = f < 0
            lo_i = np.where(up, ti, lo_i)
            hi_i = np.where(up, hi_i, ti)
            with np.errstate(divide="ignore", invalid="ignore"):
                tn = ti - f / df
            out = ~((tn >= lo_i) & (tn <= hi_i))               # also NaN
            tn[out] = 0.5 * (lo_i[out] + hi_i[out])
            t[act], lo_[act], hi_[act] = tn, lo_i, hi_i
            act = act[np.abs(tn - ti) > 1e-10 * ti]
            if not act.size:
                break
        hi[zmc] = t
    return np.where(smu * tau <= dec, tc, np.where(smu * tau >= dep, np.maximum(tpl, tp), hi))


class _Coords:
    """Shape coordinates of the unloading sums for one surface and material.

    A summit's principal curvatures are kx = r4 sqrt(m40), ky = r6 sqrt(m04) (r = sqrt(mu) w,
    w4, w6 the paper's normalised curvatures). The sums use K = kx + ky = 2 kappa_m [1/mm] and
    zeta = ky/K in (0, 1): the axis ratio lambda^2 = kx/ky = (1 - zeta)/zeta, and so every
    shape factor, depends on zeta alone, and at fixed zeta omega_c, delta_e(omega_c+) and
    delta_e(omega_p) are all proportional to 1/K. The curvatures at which the unloading
    integrand changes branch (omega_c = u, delta_e(omega_c+) = u, delta_e(omega_p) = u) are
    therefore known in closed form on every zeta line and are made panel ends.
    dr4 dr6 = K/(sqrt(m40) sqrt(m04)) dK dzeta.
    """

    def __init__(self, surface, mat):
        self.s40, self.s04 = math.sqrt(surface.m40), math.sqrt(surface.m04)
        self.sb1, self.sb2 = math.sqrt(surface.beta1), math.sqrt(surface.beta2)
        self.smu = math.sqrt(surface.m00 * surface.mu)
        self.rmu = math.sqrt(surface.mu)
        self.surface, self.mat = surface, mat

    def r(self, K, zeta):
        return K * (1.0 - zeta) / self.s40, K * zeta / self.s04

    def loading_window(self, l, zeta):
        """[K_a, K_b] per zeta: the loading population's window (``population._p_windows``
        along the zeta ray, whose integrand has the same -p^2/2 + 3 ln p + ln F_1 bound)."""
        a = np.hypot((1.0 - zeta) / self.s40, zeta / self.s04)
        b = (self.sb1 * (1.0 - zeta) / self.s40 + self.sb2 * zeta / self.s04) / self.rmu
        pa, pb = _pop._p_windows(np.full(zeta.shape, l), b / a)
        return pa / a, pb / a


def _node_integrals(C, l, tau, K, zeta, n_t):
    """Height integrals at the shape nodes (K, zeta) times the shape density and Jacobian.

    tau, K, zeta broadcastable arrays. Returns (P, dP, A, A/delta_e) of their broadcast shape,
    per unit dK dzeta, without the summit density. Height t = loading interference at h_min
    over sqrt(m00 mu); the summits touching at h = h_min + tau sqrt(m00 mu) are those with
    delta_e(omega_max) > u: t > tau (elastic, t < t_c) or t > t2 (ZMC/plastic, t2 the inverse
    of delta_e). Panels: elastic [tau, t_c], ZMC [t2, t_p], plastic [max(t2, t_p), t_hi], each
    in v = sqrt(t - start) and split at the peak t = -d of the Gaussian; a panel is evaluated
    only at the nodes where it is not empty.
    """
    mat, smu = C.mat, C.smu
    tau, K, zeta = np.broadcast_arrays(tau, K, zeta)
    shape = K.shape
    tau, K, zeta = tau.ravel(), K.ravel(), zeta.ravel()
    r4, r6 = C.r(K, zeta)
    r4, r6 = np.maximum(r4, 1e-300), np.maximum(r6, 1e-300)
    kappa, _, _, f1, f2, f3, KE = _pop._asperity_shape(C.surface, r4, r6, "exact", "exact")
    Es = mat.E_star
    wc = KE * (mat.yield_pressure / Es) ** 2 / kappa
    wp = mat.omega_p_ratio * wc
    tc, tp = wc / smu, wp / smu
    dd = l - (C.sb1 * r4 + C.sb2 * r6) / C.rmu
    with np.errstate(divide="ignore"):
        pref = (np.log(r4 * r6 * K / (C.s40 * C.s04)) - 0.5 * (r4 * r4 + r6 * r6)
                - 0.5 * math.log(2 * math.pi))
    t_hi = np.where(dd <= 0, -dd + 12.0, -dd + np.sqrt(dd * dd + 144.0))
    t2 = _invert_delta_e(tau, tc, tp, kappa, f1, f2, f3, wc, wp, mat, smu)
    x, w = _pop._gl01(n_t)
    out = [np.zeros(K.size) for _ in range(4)]
    t2p = np.maximum(t2, tp)
    # each height panel lies in one regime of the loading law (elastic, ZMC, plastic): the
    # summit's (A, P, delta_e) are evaluated with that regime's formula only
    for regime, t0, b in ((0, tau, np.minimum(tc, t_hi)), (1, t2, np.minimum(tp, t_hi)),
                          (2, t2p, t_hi)):
        live = np.flatnonzero(b > t0)
        if not live.size:
            continue
        T0, ta, ka, g1, g2, g3, c, q, dl, pr = (a.take(live) for a in (
            t0, tau, kappa, f1, f2, f3, wc, wp, dd, pref))
        vb = np.sqrt(b.take(live) - T0)
        vpk = np.clip(np.sqrt(np.maximum(-dl - T0, 0.0)), 0.0, vb)
        acc = [np.zeros(live.size) for _ in range(4)]
        cA = np.pi / ka
        # per-node constants of the regime's (A, P, delta_e) (asperity.zmc_area,
        # zmc_mean_pressure and the plastic law, written out: the height loop is the hot path)
        if regime == 0:
            cP = 4.0 / 3.0 * Es * g2 / np.sqrt(ka)
            cAe = g1 * cA
        else:   # delta_e = 1.5 P/S(A), S(A) = cS sqrt(A)
            rcS = 1.5 / (2.0 * Es * (g2 / np.sqrt(g1)) / math.sqrt(math.pi))
        if regime == 1:
            # A = cA W (f1 + (2 f3 - f1) S(y)), S = 3 y^2 - 2 y^3, y = (W - wc)/(wp - wc)
            # in [0, 1]; pa = ch H - slope ln(R wc/W), W clipped to [wc, wp]
            idw = 1.0 / (q - c)
            d31 = 2.0 * g3 - g1
            R = mat.omega_p_ratio
            slope = mat.H * (mat.ch - 2.0 * mat.K_nu / 3.0) / math.log(R)
            lRc = np.log(R * c)
        elif regime == 2:
            cAp = 2.0 * g3 * cA
            chH = mat.ch * mat.H
        uta = smu * ta
        for lo, hi in ((0.0, vpk), (vpk, vb)):
            span2 = 2.0 * (hi - lo)
            for j in range(n_t):
                v = lo + (hi - lo) * x[j]
                t = T0 + v * v
                jac = v * span2 * w[j]
                W = smu * t
                if regime == 0:
                    A = cAe * W
                    P = cP * W * np.sqrt(W)
                    de = np.maximum(W, 1e-300)        # W = 0 only at a node of weight 0
                else:
                    if regime == 1:
                        y = (W - c) * idw
                        np.clip(y, 0.0, 1.0, out=y)
                        A = cA * W * (g1 + d31 * (y * y * (3.0 - 2.0 * y)))
                        P = A * (slope * (np.log(np.clip(W, c, q)) - lRc) + mat.ch * mat.H)
                    else:
                        A = cAp * W
                        P = chH * A
                    de = rcS * P / np.sqrt(A)
                    np.minimum(de, W, out=de)
                ide = 1.0 / de
                xi = uta * ide                        # 1 - xi in (0, 1] inside the panel
                np.subtract(1.0, xi, out=xi)
                np.maximum(xi, 0.0, out=xi)
                ide[xi <= 0] = 0.0
                sx = np.sqrt(xi)
                tt = t + dl
                tt *= tt
                tt *= -0.5
                tt += pr
                g = np.exp(tt, out=tt)
                g *= jac
                gA = g * A
                g *= P                                # g P
                sx *= g                               # g P sqrt(xi)
                acc[0] += sx * xi
                acc[1] += sx * ide
                acc[2] += gA * xi
                acc[3] += gA * ide
        acc[1] *= 1.5
        for o, a in zip(out, acc):
            o[live] += a
    return [o.reshape(shape) for o in out]


def _branch_curvatures(C, tau, zeta):
    """K at which omega_c, delta_e(omega_c+), delta_e(omega_p) equal u = tau sqrt(m00 mu),
    per zeta (each of them is c(zeta)/K)."""
    mat, Es = C.mat, C.mat.E_star
    K1 = np.ones(np.broadcast(tau, zeta).shape)
    r4, r6 = C.r(K1, zeta)
    kappa, _, _, f1, f2, f3, KE = _pop._asperity_shape(C.surface, r4, r6, "exact", "exact")
    wc = KE * (mat.yield_pressure / Es) ** 2 / kappa               # at K = 1/mm
    wp = mat.omega_p_ratio * wc
    Ac, Pc, _ = _loading(wc * (1 + 1e-12), kappa, f1, f2, f3, wc, wp, mat)
    Ap, Pp, _ = _loading(wp, kappa, f1, f2, f3, wc, wp, mat)
    u = np.maximum(tau * C.smu, 1e-300)
    return (wc / u, _delta_e(wc, Ac, Pc, f1, f2, Es) / u, _delta_e(wp, Ap, Pp, f1, f2, Es) / u)


def _rule(n, a, b, mode):
    """Gauss-Legendre on [a, b] (arrays (..., 1)); mode 'lo'/'hi' clusters the nodes at that
    end by a cubic map (edge singularities of the shape factors), None: plain."""
    u, w = _pop._gl01(n)
    if mode == "lo":
        s, ds = u ** 3, 3.0 * u * u
    elif mode == "hi":
        s, ds = 1.0 - (1.0 - u) ** 3, 3.0 * (1.0 - u) ** 2
    else:
        s, ds = u, np.ones_like(u)
    return a + (b - a) * s, (b - a) * ds * w


def _row_sums(surface, mat, h_min, u, n_quad, n_t, n_zeta=None):
    """p, k, a, -da/dh at (h_min + u, h_min) for one h_min [mm] and an array u >= 0 [mm].

    Outer rule in (zeta, K) (``_Coords``): zeta on (0, 1/2) and (1/2, 1) (the circular ray
    splits them; n_zeta nodes each (None: n_quad), clustered at the wedge edges: high above
    the mean plane the zeta integrand peaks sharply near the edges, e.g. at zeta ~ 0.9 at
    h_min = 7.35 sigma, where 16 nodes leave 3e-4 to 9e-4 (psi 1 to 2) and 24 nodes 1e-6 to
    4e-6); per zeta node, K on the
    window where the unloading integrand itself lives (a scan of ``_SCAN`` points inside the
    loading window, keeping the integrand above exp(-_LOG_CUT) of its maximum on that line,
    widened by one scan cell: at large u only tall, flat summits still touch, far from where
    the loading integrand lives), cut at the three branch curvatures and at the scan's peak,
    n_quad nodes per panel; height: ``_node_integrals`` (n_t nodes per half-panel).
    """
    C = _Coords(surface, mat)
    l = h_min / C.smu
    tau = (np.asarray(u, float) / C.smu)[:, None]                 # (n_u, 1)
    n_u = tau.shape[0]
    nz = n_quad if n_zeta is None else n_zeta
    z, wz = zip(_rule(nz, np.zeros(1), np.full(1, 0.5), "lo"),
                _rule(nz, np.full(1, 0.5), np.ones(1), "hi"))
    zeta = np.concatenate(z)                                      # (2n,)
    wz = np.concatenate(wz)
    Ka, Kb = C.loading_window(l, zeta)
    # scan: live K range per (tau, zeta)
    s = (np.arange(_SCAN) + 0.5) / _SCAN
    Ks = Ka[:, None] + (Kb - Ka)[:, None] * s                     # (2n, S)
    vals = _node_integrals(C, l, tau, Ks.reshape(1, -1), np.repeat(zeta, _SCAN)[None, :],
                           _SCAN_T)
    live = np.zeros((n_u, zeta.size, _SCAN), bool)
    peak = np.zeros((n_u, zeta.size))
    for q, v in enumerate(vals):
        v = v.reshape(n_u, zeta.size, _SCAN)
        m = v.max(axis=2, keepdims=True)
        live |= (v > 0) & (v >= m * math.exp(-_LOG_CUT))
        if q == 0:
            peak = np.take_along_axis(Ks[None], v.argmax(axis=2)[..., None], 2)[..., 0]
    idx = np.arange(_SCAN)
    first = np.where(live, idx, _SCAN).min(axis=2)
    last = np.where(live, idx, -1).max(axis=2)
    dK = (Kb - Ka) / _SCAN
    none = last < first
    K0 = np.where(none, Ka, np.maximum(Ka, Ka + dK * (first - 1)))
    K1 = np.where(none, Kb, np.minimum(Kb, Ka + dK * (last + 2)))
    Kc, Kd, Kp = _branch_curvatures(C, tau, zeta[None, :])         # (n_u, 2n)
    cuts = np.sort(np.stack([K0, np.clip(Kc, K0, K1), np.clip(Kd, K0, K1),
                             np.clip(Kp, K0, K1), np.clip(peak, K0, K1), K1], -1), -1)
    a, b = cuts[..., :-1, None], cuts[..., 1:, None]               # (n_u, 2n, 5, 1)
    Kn, wK = _rule(n_quad, a, b, None)                             # (n_u, 2n, 5, n)
    Zn = np.broadcast_to(zeta[None, :, None, None], Kn.shape).ravel()
    Tn = np.broadcast_to(tau[:, :, None, None], Kn.shape).ravel()
    row = np.broadcast_to(np.arange(n_u)[:, None, None, None], Kn.shape).ravel()
    wt = (wK * wz[None, :, None, None]).ravel()
    use = np.flatnonzero(wt > 0)                     # empty panels (coinciding cuts) dropped
    vals = _node_integrals(C, l, Tn[use], Kn.ravel()[use], Zn[use], n_t)
    Ds = surface.summit_density
    return tuple(np.bincount(row[use], v * wt[use], minlength=n_u) * Ds for v in vals)


def population_unloading(surface, material: AsperityMaterial, h, h_min, n_quad: int = 16,
                         n_t: int = 24, n_zeta=None):
    """Population sums p [MPa], k = -dp/dh at fixed h_min [MPa/mm], A/A0 [-] at (h, h_min).

    The direct (untabulated) model of :class:`HistoryNormalLaw`. h_min scalar [mm]; h array
    [mm]; h < h_min is the loading branch (h_min := h there, k is then the unloading stiffness
    at h_min = h, not the loading one: the table takes the loading branch from ``NormalLaw``).
    n_zeta: zeta nodes per half (None: n_quad; see ``_row_sums``). Reading:
    ``residual="consistent"``.
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
            vals = _row_sums(surface, mat, hm, u[sl], n_quad, n_t, n_zeta)[:3]
            for r, v in zip(res, vals):
                r[sl] = v
    for i in np.flatnonzero(lower):
        vals = _row_sums(surface, mat, h[i], np.zeros(1), n_quad, n_t, n_zeta)[:3]
        for r, v in zip(res, vals):
            r[i] = v[0]
    return tuple(r.reshape(np.shape(h)) for r in res)
