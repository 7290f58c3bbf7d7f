"""The elasto-plastic population sums, evaluated panel by panel with each regime's own formula
(moments of v for the elastic and plastic panels), against the all-regime evaluation at every
node (the formula of the sums before the panel split, kept here as the reference)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from rough_contact.micro import population as pop
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)   # Table 1
S2 = SpectralMoments(m00=3.0, m20=1.0, m02=81.0, m40=1.0, m04=6561.0)           # Table 2
FIELDS = ("area_fraction", "pressure", "stiffness", "area_elastic", "area_transition",
          "area_plastic", "pressure_elastic", "pressure_transition", "pressure_plastic")


def _reference(surface, material, h, n_quad, n_t=None):
    """All three regimes' formulas at every (p, q, t) node, masked by the node's regime.

    Returns (elasto-plastic sums by FIELDS, elastic sums (A, W, K)), each (len(h),)."""
    mat = material.resolve(surface)
    l = np.asarray(h, float) / math.sqrt(surface.m00 * surface.mu)
    smu, Ds = math.sqrt(surface.m00 * surface.mu), surface.summit_density
    Es, H, ch, R = mat.E_star, mat.H, mat.ch, mat.omega_p_ratio
    slope = H * (ch - 2.0 * mat.K_nu / 3.0) / math.log(R)
    n_t = max(16, (2 * n_quad) // 3) if n_t is None else n_t
    u, w = pop._gl01(n_t)
    r4, r6, d, logw = pop._outer_nodes(surface, l, n_quad, (3 * n_quad) // 2)
    kappa, _, _, f1, f2, f3, KE = pop._asperity_shape(surface, r4, r6, "exact", "exact")
    wc = KE * (mat.yield_pressure / Es) ** 2 / kappa
    wp = R * wc
    tc, tp = wc / smu, wp / smu
    dd = d[..., None]
    t_lo = np.maximum(0.0, -dd - pop._T_WIDTH)
    t_hi = np.where(dd <= 0, -dd + pop._T_WIDTH, -dd + np.sqrt(dd * dd + pop._T_WIDTH**2))
    v_lo, v_hi = np.sqrt(t_lo), np.sqrt(t_hi)
    g2 = f2 / np.sqrt(kappa)
    jump = f1 * np.pi / kappa * wc * (2.0 / 3.0 * mat.K_nu * H) - 4.0 / 3.0 * Es * g2 * wc**1.5
    in_win = (tc >= t_lo) & (tc <= t_hi)
    phi_c = np.where(in_win, np.exp(-0.5 * (tc + dd) ** 2) / math.sqrt(2 * math.pi), 0.0)
    ex = np.exp(logw)
    K_jump = np.sum(ex * jump * phi_c / smu, axis=(1, 2))
    cuts = np.broadcast_arrays(v_lo, np.clip(np.sqrt(tc), v_lo, v_hi),
                               np.clip(np.sqrt(tp), v_lo, v_hi),
                               np.clip(np.sqrt(np.maximum(-dd, 0.0)), v_lo, v_hi), v_hi)
    bp = np.sort(np.stack(cuts, axis=-1), axis=-1)
    a, b = bp[..., :-1, None], bp[..., 1:, None]
    v = (a + (b - a) * u).reshape(bp.shape[:-1] + (-1,))
    t = v * v
    om = smu * t
    wt = (2.0 * (b - a) * w).reshape(v.shape) * v * np.exp(
        -0.5 * (t + dd[..., None]) ** 2 - 0.5 * math.log(2 * math.pi))
    X = lambda x: x[..., None]  # noqa: E731
    wc_, wp_, f1_, f3_, g2_, ca = X(wc), X(wp), X(f1), X(f3), X(g2), X(np.pi / kappa)
    el, pl = om < wc_, om >= wp_
    tr = ~(el | pl)
    A_el, W_el, k_el = f1_ * ca * om, 4.0 / 3.0 * Es * g2_ * om**1.5, 2.0 * Es * g2_ * np.sqrt(om)
    x = np.clip((om - wc_) / (wp_ - wc_), 0.0, 1.0)
    S, dS = x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x) / (wp_ - wc_)
    fa = f1_ + (2.0 * f3_ - f1_) * S
    A_tr = ca * om * fa
    dA = ca * (fa + om * (2.0 * f3_ - f1_) * dS)
    pa = ch * H - slope * np.log(np.clip(wp_ / np.maximum(om, wp_ / R), 1.0, R))
    W_tr, k_tr = A_tr * pa, dA * pa + A_tr * slope / np.maximum(om, 1e-300)
    A_pl = 2.0 * f3_ * ca * om
    W_pl, k_pl = ch * H * A_pl, ch * H * 2.0 * f3_ * ca * np.ones_like(om)

    def total(val):
        return Ds * np.sum(ex * np.sum(val * wt, axis=-1), axis=(1, 2))

    Ae, At, Ap = (total(np.where(m, x, 0)) for m, x in ((el, A_el), (tr, A_tr), (pl, A_pl)))
    We, Wt, Wp = (total(np.where(m, x, 0)) for m, x in ((el, W_el), (tr, W_tr), (pl, W_pl)))
    K = total(np.where(el, k_el, np.where(pl, k_pl, k_tr))) + Ds * K_jump
    ep = dict(zip(FIELDS, (Ae + At + Ap, We + Wt + Wp, K, Ae, At, Ap, We, Wt, Wp)))
    return ep, (total(A_el), total(W_el), total(k_el))


def _rel(x, y):
    return np.max(np.abs(x - y) / np.maximum(np.abs(y), 1e-300))


@pytest.mark.parametrize("surface, psi, s, regimes", [
    (S1, 1.0, [-3.0, -1.2, 0.0, 1.5, 4.0, 9.0], "etp"),   # the table's surface and psi
    (S1, 0.3, [-2.0, 0.5, 3.0], "et"),                    # no fully plastic summits
    (S2, 10.0, [-3.0, 0.0, 2.5, 6.0], "etp"),
])
def test_panel_sums_equal_the_all_regime_evaluation(surface, psi, s, regimes):
    mat = AsperityMaterial(E_star=1.14e5, psi=psi)
    h = np.array(s) * surface.rq
    got = pop.elasto_plastic(surface, mat, h)
    ref, _ = _reference(surface, mat, h, 24)
    for r, f in zip("etp", ("area_elastic", "area_transition", "area_plastic")):
        assert (ref[f].max() > 0.0) == (r in regimes), f   # the regimes the case exercises
    for f in FIELDS:
        assert _rel(getattr(got, f), ref[f]) < 1e-12, f


def test_elastic_sums_on_the_same_nodes_equal_the_all_node_evaluation():
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0)
    h = np.array([-2.0, 0.0, 2.0, 5.0]) * S1.rq
    ep, el = pop.elasto_plastic_and_elastic(S1, mat, h, n_quad=12, n_t=10)
    ref, (A, W, K) = _reference(S1, mat, h, 12, n_t=10)
    for f in ("area_fraction", "pressure", "stiffness"):
        assert _rel(getattr(ep, f), ref[f]) < 1e-12, f
    for got, want in ((el.area_fraction, A), (el.pressure, W), (el.stiffness, K)):
        assert _rel(got, want) < 1e-12


@pytest.mark.parametrize("window_tol", [0.0, 1e-3])
def test_no_separations_give_empty_sums(window_tol):
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0)
    ep, el = pop.elasto_plastic_and_elastic(S1, mat, np.zeros((0, 2)), window_tol=window_tol)
    for r in (ep, el, pop.elasto_plastic(S1, mat, [])):
        assert r.pressure.size == r.stiffness.size == r.area_fraction.size == 0
    assert ep.pressure.shape == el.stiffness.shape == (0, 2)
