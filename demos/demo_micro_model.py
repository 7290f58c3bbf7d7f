# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # The rough-surface micro-model of Buczkowski & Kleiber (2009), sections 2-7
#
# What is computed (pure numpy/scipy, no FE):
#
# * Tables 1 and 2: real contact area A/A0 [%] and nominal pressure W/A0 [MPa] of the
#   strongly anisotropic elastic model (52)-(53) and of McCool's equivalent
#   Greenwood-Williamson model, vs the dimensionless separation s = h/sqrt(m00);
# * Table 3: Mindlin's ratio kN/kT (96)-(97) (from ``rough_contact.interface.tangential``);
# * Fig. 3: bearing-area ratio AG/AB (24)-(25) vs s;
# * Fig. 4: shape factors f1(e), f2(e) (46)-(47);
# * Figs. 5-6: plastic share Ap/A and real mean pressure W/(A H) vs W/(H A0) for several
#   plasticity indices psi (78)-(85);
# * Figs. 7-8: elastic (55) and elasto-plastic (exact -dW/dh) normal stiffness vs W/A0 for
#   m00 = 0.0625, 0.3125, 0.625 um^2 at psi = 0.35 and 0.5.
#
# Units: moments in the paper's um convention at input, everything else mm, N, MPa;
# stiffness per nominal area in MPa/mm (= N/mm^3). Material convention: psi given, the
# hardness follows from (69), H = sqrt(sigma kappa_m) E*/psi, and K_Y Y = (2/pi) H, the
# reading under which the paper's nondimensional critical interference (74) holds (the
# captions' Y = 2070 MPa is not used by (74)).
#
# Run: ``.venv/bin/python demos/demo_micro_model.py [--out DIR] [--docs] [--quick]``.

from __future__ import annotations

import argparse
import os
import shutil
import time

import numpy as np

from rough_contact.micro import population as pop
from rough_contact.micro.asperity import AsperityMaterial, shape_factors
from rough_contact.interface.tangential import normal_to_tangential_ratio
from rough_contact.surface import SpectralMoments

E_STAR = 1.14e5  # MPa
TABLE1_SURFACE = dict(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
TABLE2_SURFACE = dict(m00=3.0, m20=1.0, m02=81.0, m40=1.0, m04=6561.0)
TABLE1 = np.array([  # s, A% GW, A% aniso, W GW, W aniso
    [1.0, 5.1497, 6.1222, 86.5534, 93.3897], [1.5, 2.2210, 2.5424, 34.1470, 36.5963],
    [2.0, 0.7908, 0.8673, 11.1922, 11.9003], [2.5, 0.2286, 0.2394, 2.9972, 3.1613],
    [3.0, 0.0529, 0.0529, 0.6470, 0.6778], [3.5, 0.0097, 0.0093, 0.1114, 0.1162]])
TABLE2 = np.array([
    [2.0, 1.0525, 0.9280, 2105.97, 2877.81], [2.5, 0.3185, 0.2589, 580.16, 796.57],
    [3.0, 0.0733, 0.0570, 122.56, 175.17], [3.5, 0.0126, 0.0099, 19.476, 30.435],
    [4.0, 0.00159, 0.00135, 2.2942, 4.1568], [4.5, 0.000146, 0.000143, 0.1981, 0.4397]])
TABLE3 = np.array([  # B^2/A^2, nu = 0, 1/4, 1/2
    [1e-3, 1.0, 1.06874, 1.20622], [1e-2, 1.0, 1.08920, 1.26759], [1e-1, 1.0, 1.12167, 1.36502],
    [1e0, 1.0, 1.16667, 1.5], [1e1, 1.0, 1.21166, 1.63497], [1e2, 1.0, 1.24413, 1.73241],
    [1e3, 1.0, 1.26459, 1.79378]])


def rel(a, b):
    return a / b - 1.0


# ## Tables 1 and 2

def print_tables_1_2():
    out = {}
    for name, moments, table in (("Table 1 (alpha = 10)", TABLE1_SURFACE, TABLE1),
                                 ("Table 2 (alpha = 3)", TABLE2_SURFACE, TABLE2)):
        s = SpectralMoments(**moments)
        h = table[:, 0] * s.rq
        gw = pop.greenwood_williamson(s, E_STAR, h)
        an = pop.elastic(s, E_STAR, h)
        print(f"\n{name}: alpha1 = {s.alpha1:.4g}, alpha2 = {s.alpha2:.4g}, mu = {s.mu:.4g}")
        print("   s |  A/A0 GW [%]  paper    rel   | A/A0 aniso [%]  paper    rel   |"
              "  W/A0 GW [MPa]  paper    rel   | W/A0 aniso [MPa] paper    rel")
        for i, row in enumerate(table):
            cols = [(100 * gw.area_fraction[i], row[1]), (100 * an.area_fraction[i], row[2]),
                    (gw.pressure[i], row[3]), (an.pressure[i], row[4])]
            txt = " | ".join(f"{v:11.5g} {p:9.5g} {rel(v, p):+7.2%}" for v, p in cols)
            print(f" {row[0]:3.1f} | {txt}")
        out[name] = (gw, an)
    return out


def print_table_3():
    print("\nTable 3: kN/kT (Mindlin, (96)-(97)); B along the tangential force")
    print("  B^2/A^2 |  nu=0    paper   rel    |  nu=1/4  paper   rel    |  nu=1/2  paper   rel")
    for row in TABLE3:
        vals = [float(normal_to_tangential_ratio(row[0], nu)) for nu in (0.0, 0.25, 0.5)]
        txt = " | ".join(f"{v:7.5f} {p:7.5f} {rel(v, p):+.1e}" for v, p in zip(vals, row[1:]))
        print(f"  {row[0]:7.0e} | {txt}")


# ## Figures

def fig3_bearing(plt, out):
    s_grid = np.linspace(-1.0, 10.0, 111)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for moments, mk, lab in ((dict(m00=3., m20=1., m02=81., m40=1., m04=6561.), "s", "m00 = 3 (alpha = 3)"),
                             (dict(m00=12., m20=1., m02=81., m40=1., m04=6561.), "^", "m00 = 12 (alpha = 12)"),
                             (TABLE1_SURFACE, "x", "m00 = 0.0625 (alpha = 10)")):
        s = SpectralMoments(**moments)
        ax.plot(s_grid, pop.bearing_area_ratio(s, s_grid), marker=mk, markevery=10, label=lab)
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("s = h / sqrt(m00)")
    ax.set_ylabel("AG / AB")
    ax.set_title("Fig. 3: bearing area of the asperity model / Gaussian")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "micro_fig3_bearing_area_ratio.png"), dpi=120)
    plt.close(fig)


def fig4_shape(plt, out):
    e = np.linspace(0.0, 0.999, 400)
    f1, f2, f3, f4, _ = shape_factors(np.sqrt(1 - e**2))
    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.plot(e, f1, label="f1 (area)")
    ax.plot(e, f2, label="f2 (load)")
    ax.plot(e, f3, "--", label="f3 (plastic area)")
    ax.plot(e, f4, "--", label="f4")
    ax.set_ylim(0, 3)
    ax.set_xlabel("eccentricity e of the contact ellipse")
    ax.set_ylabel("shape factor")
    ax.set_title("Fig. 4: f1(e), f2(e) (and f3, f4 of (59)-(60))")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "micro_fig4_shape_factors.png"), dpi=120)
    plt.close(fig)


PSIS = (0.3, 0.5, 0.7, 1.0, 2.0, 5.0, 20.0)


def figs5_6(plt, out, n_quad, n_h):
    s = SpectralMoments(**TABLE1_SURFACE)
    h = np.linspace(-1.5, 4.0, n_h) * s.rq
    fig5, ax5 = plt.subplots(figsize=(7.2, 4.2))
    fig6, ax6 = plt.subplots(figsize=(7.2, 4.2))
    summary = {}
    for psi in PSIS:
        mat = AsperityMaterial.from_plasticity_index(s, psi, E_STAR)
        r = pop.elasto_plastic(s, mat, h, n_quad=n_quad)
        x = r.pressure / mat.H
        ok = r.pressure > 0
        line, = ax5.semilogx(x[ok], (r.area_plastic / r.area_fraction)[ok], label=f"psi = {psi:g}")
        ax5.semilogx(x[ok], ((r.area_plastic + r.area_transition) / r.area_fraction)[ok], "--",
                     color=line.get_color())
        ax6.semilogx(x[ok], (r.pressure / (r.area_fraction * mat.H))[ok], label=f"psi = {psi:g}")
        summary[psi] = (x, r.area_plastic / r.area_fraction, r.pressure / (r.area_fraction * mat.H),
                        (r.area_transition / r.area_fraction))
    for ax, fig, name, ylab, title in (
            (ax5, fig5, "micro_fig5_plastic_area_share.png", "Ap / A (solid), (Aep + Ap) / A (dashed)",
             "Fig. 5: plastic share of the real area"),
            (ax6, fig6, "micro_fig6_real_mean_pressure.png", "W / (A H)", "Fig. 6: real mean pressure / H")):
        ax.set_xlabel("W / (H A0)")
        ax.set_ylabel(ylab)
        ax.set_title(title + " (Table 1 surface)")
        ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))
        fig.tight_layout()
        fig.savefig(os.path.join(out, name), dpi=120)
        plt.close(fig)
    return summary


def figs7_8(plt, out, n_quad, n_h):
    base = dict(TABLE1_SURFACE)
    results = {}
    for psi, fname, figno in ((0.35, "micro_fig7_stiffness_psi035.png", 7),
                              (0.5, "micro_fig8_stiffness_psi05.png", 8)):
        fig, ax = plt.subplots(figsize=(6, 4.4))
        for m00, mk, col in ((0.0625, "^", "C0"), (0.3125, "x", "C1"), (0.625, "s", "C2")):
            s = SpectralMoments(**dict(base, m00=m00))
            h = np.linspace(-1.5, 4.0, n_h) * s.rq
            el = pop.elastic(s, E_STAR, h, n_quad=max(n_quad, 24))
            mat = AsperityMaterial.from_plasticity_index(s, psi, E_STAR)
            ep = pop.elasto_plastic(s, mat, h, n_quad=n_quad)
            ax.loglog(el.pressure, el.stiffness, "-", marker=mk, markevery=6, color=col,
                      label=f"elastic, m00 = {m00:g}")
            ax.loglog(ep.pressure, ep.stiffness, "--", marker=mk, markevery=6, color=col, mfc="none",
                      label=f"elasto-plastic, m00 = {m00:g}")
            # the captions' literal Y = 2070 MPa (with H from psi): K_Y Y != (2/pi) H
            epy = pop.elasto_plastic(s, AsperityMaterial(E_star=E_STAR, H=mat.H, Y=2070.0), h,
                                     n_quad=n_quad)
            ax.loglog(epy.pressure, epy.stiffness, ":", color=col, lw=1,
                      label=f"elasto-plastic, Y = 2070 MPa, m00 = {m00:g}")
            results[(psi, m00)] = (el, ep, s, mat, epy)
        ax.set_xlabel("W / A0 [MPa]")
        ax.set_ylabel("k_N [MPa/mm]")
        ax.set_xlim(1e-2, 1e3)
        ax.set_title(f"Fig. {figno}: normal stiffness, psi = {psi:g}")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(out, fname), dpi=120)
        plt.close(fig)
    return results


def interp_at_load(res, W):
    """k_N at the nominal pressure W [MPa] (log-log interpolation along the curve)."""
    p, k = res.pressure[::-1], res.stiffness[::-1]
    ok = p > 0
    return float(np.exp(np.interp(np.log(W), np.log(p[ok]), np.log(k[ok]))))


def claims(s5, r78):
    print("\nQualitative claims of the paper, checked on these results:")
    # Figs 5-6
    for psi in (0.3, 0.5, 1.0, 2.0, 20.0):
        x, ap, wah, at = s5[psi]
        i = np.argmax(x)
        j = np.argmin(np.abs(np.log(np.maximum(x, 1e-300)) - np.log(1e-4)))
        print(f"  psi = {psi:5g}: Ap/A = {ap[j]:.3g} at W/HA0 ~ {x[j]:.1e}, {ap[i]:.3g} at the largest "
              f"load W/HA0 = {x[i]:.2e}; (Aep+Ap)/A = {ap[j] + at[j]:.3g} and {ap[i] + at[i]:.3g}; "
              f"W/AH in [{np.nanmin(wah[x > 0]):.3f}, {np.nanmax(wah[x > 0]):.3f}]")
    # Figs 7-8
    for psi in (0.35, 0.5):
        for W in (1.0, 10.0, 100.0):
            ks = [interp_at_load(r78[(psi, m)][0], W) for m in (0.0625, 0.3125, 0.625)]
            kp = [interp_at_load(r78[(psi, m)][1], W) for m in (0.0625, 0.3125, 0.625)]
            ky = [interp_at_load(r78[(psi, m)][4], W) for m in (0.0625, 0.3125, 0.625)]
            print(f"  psi = {psi}: at W/A0 = {W:5g} MPa (m00 = 0.0625, 0.3125, 0.625) elastic kN = "
                  + ", ".join(f"{k:.3e}" for k in ks)
                  + "; EP/elastic = " + ", ".join(f"{a / b:.4f}" for a, b in zip(kp, ks))
                  + "; EP(Y=2070)/elastic = " + ", ".join(f"{a / b:.3f}" for a, b in zip(ky, ks)))
    # curvature / slope insensitivity (abstract): scale m40, m04 (resp. m20, m02) at fixed m00
    base = SpectralMoments(**TABLE1_SURFACE)
    ref = pop.elastic(base, E_STAR, np.linspace(-1.5, 4, 45) * base.rq)
    print("  sensitivity of the elastic kN at W/A0 = 10 MPa to the curvature / slope moments:")
    for lab, kw in (("m40, m04 x 2", dict(m40=2.08e-6, m04=2.08e-4)),
                    ("m40, m04 x 1/2", dict(m40=0.52e-6, m04=0.52e-4)),
                    ("m20, m02 x 1.2", dict(m20=9.6e-5, m02=9.6e-4))):
        s = SpectralMoments(**dict(TABLE1_SURFACE, **kw))
        r = pop.elastic(s, E_STAR, np.linspace(-1.5, 4, 45) * s.rq)
        print(f"    {lab:15s}: kN / kN_ref = {interp_at_load(r, 10.0) / interp_at_load(ref, 10.0):.3f}")
    for lab, m00 in (("m00 x 5", 0.3125), ("m00 x 10", 0.625)):
        s = SpectralMoments(**dict(TABLE1_SURFACE, m00=m00))
        r = pop.elastic(s, E_STAR, np.linspace(-1.5, 4, 45) * s.rq)
        print(f"    {lab:15s}: kN / kN_ref = {interp_at_load(r, 10.0) / interp_at_load(ref, 10.0):.3f}")


def timing():
    s = SpectralMoments(**TABLE1_SURFACE)
    h = np.linspace(-5, 60, 200) * s.summit_sigma
    pop.elastic(s, E_STAR, h[:2])  # warm the cached splines
    t = time.perf_counter()
    pop.elastic(s, E_STAR, h)
    te = time.perf_counter() - t
    mat = AsperityMaterial.from_plasticity_index(s, 1.0, E_STAR)
    t = time.perf_counter()
    pop.elasto_plastic(s, mat, h[::2])
    tp = time.perf_counter() - t
    print(f"\nTiming: elastic population, 200 separations (n_quad = 32): {te:.2f} s; "
          f"elasto-plastic, 100 separations (n_quad = 24): {tp:.2f} s")


def main(out="results/micro_model", docs=False, quick=False):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(out, exist_ok=True)
    print_tables_1_2()
    print_table_3()
    n_quad, n_h = (12, 23) if quick else (20, 45)
    fig3_bearing(plt, out)
    fig4_shape(plt, out)
    s5 = figs5_6(plt, out, n_quad, n_h)
    r78 = figs7_8(plt, out, n_quad, n_h)
    claims(s5, r78)
    if not quick:
        timing()
    if docs:
        dst = os.path.join("docs", "figures")
        os.makedirs(dst, exist_ok=True)
        for f in sorted(os.listdir(out)):
            if f.startswith("micro_") and f.endswith(".png"):
                shutil.copy(os.path.join(out, f), os.path.join(dst, f))
    print(f"\nfigures written to {out}" + (" and docs/figures" if docs else ""))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, allow_abbrev=False)
    ap.add_argument("--out", default="results/micro_model")
    ap.add_argument("--docs", action="store_true", help="also copy the PNGs to docs/figures/")
    ap.add_argument("--quick", action="store_true", help="coarser quadrature and grids (tests)")
    args = ap.parse_args()
    main(args.out, args.docs, args.quick)
