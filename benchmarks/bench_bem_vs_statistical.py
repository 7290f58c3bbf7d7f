"""Statistical vs BEM normal law on the example surfaces: ratios over the load range.

For each surface of rough_contact.surface.spectrum.example_surfaces (isotropic Gaussian, strongly
anisotropic, broadband self-affine; optionally the paper's surface) this runs
rough_contact.micro.law_comparison's ``compare`` (statistical elastic, GW and - with ``--plastic`` - the
elasto-plastic law against the elastic / saturated BEM law, realisations averaged at equal
separation) and prints and saves the ratios statistical/BEM of p, A/A0 and k at equal separation
(and A/A0, k at equal load) over the load range, with the load ranges of agreement.

    bash run.sh python benchmarks/bench_bem_vs_statistical.py --csv /tmp/q.csv --figdir /tmp
        # quick: 8 realisations of one roll-off period (~7 min; large sampling error)
    bash run.sh python benchmarks/bench_bem_vs_statistical.py --periods 2 --realisations 12 \
        --tangential            # the docs/bem.md results (~1 h on one busy core)

Writes docs/bem_vs_statistical.csv, docs/figures/bem_vs_statistical.png and one
docs/figures/bem_compare_<surface>.png per surface.
"""
from __future__ import annotations

import argparse
import os

import numpy as np
from _common import write_csv

from rough_contact.micro import law_comparison as compare_laws
from rough_contact.surface.spectrum import example_surfaces

PPW = {"isotropic": 8.0, "anisotropic": 8.0, "self-affine": 4.0, "paper": 4.0}
SE = {"p_at_h": "se_p", "a_at_h": "se_a", "k_at_h": "se_k", "a_at_p": "se_a", "k_at_p": "se_k"}


def figure(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [("p_at_h", "p, equal h"), ("a_at_h", "A/A0, equal h"), ("k_at_h", "k, equal h"),
            ("a_at_p", "A/A0, equal load"), ("k_at_p", "k, equal load")]
    fig, ax = plt.subplots(len(results), len(keys), figsize=(15, 3.0 * len(results)),
                           squeeze=False, sharey=True)
    for i, (surf, res) in enumerate(results.items()):
        for j, (key, lab) in enumerate(keys):
            a = ax[i, j]
            for name, st in (("statistical elastic", "C0o-"), ("GW (McCool)", "C2s:"),
                             ("statistical elasto-plastic", "C1^--")):
                rows = [r for r in res["rows"] if r["law"] == name]
                if not rows:
                    continue
                x = np.array([r["p [MPa]"] for r in rows])
                y = np.array([r[key] for r in rows])
                se = np.array([r[SE[key]] for r in rows])
                a.semilogx(x, y, st, ms=3, label=name)
                # sampling uncertainty of the BEM mean (+- 1 standard error)
                a.fill_between(x, y / (1 + se), y / np.maximum(1 - se, 0.05), color=st[:2],
                               alpha=0.12, lw=0)
            a.axhline(1.0, color="k", lw=0.8)
            a.axhspan(0.9, 1.1, color="0.85", zorder=0)
            a.grid(True, which="both", alpha=0.3)
            if i == 0:
                a.set_title(f"statistical / BEM: {lab}", fontsize=9)
            if i == len(results) - 1:
                a.set_xlabel("mean pressure p [MPa]")
            if j == 0:
                a.set_ylabel(f"{surf}\nratio")
    for i in range(len(results)):
        ax[i, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--surfaces", nargs="+", default=["isotropic", "anisotropic", "self-affine"],
                    choices=list(example_surfaces()))
    ap.add_argument("--realisations", type=int, default=8)
    ap.add_argument("--ppw", type=float, default=None, help="default: 8 (4 for broadband)")
    ap.add_argument("--pressures", type=int, default=10)
    ap.add_argument("--plastic", nargs="*", default=["anisotropic"],
                    help="surfaces on which the elasto-plastic law is also compared with the "
                    "saturated BEM law (default: anisotropic; none: --plastic)")
    ap.add_argument("--psi", type=float, default=2.0,
                    help="plasticity index for --plastic (the paper's 0.35 is elastic here)")
    ap.add_argument("--tangential", nargs="*", default=["anisotropic"],
                    help="surfaces on which the stick tangential stiffness is also computed")
    ap.add_argument("--periods", type=int, default=1,
                    help="roll-off wavelengths per side of each realisation")
    ap.add_argument("--tol", type=float, default=0.1)
    ap.add_argument("--backend", default=None, choices=["tamaas", "numpy"])
    ap.add_argument("--csv", default="docs/bem_vs_statistical.csv")
    ap.add_argument("--figdir", default="docs/figures")
    args = ap.parse_args(argv)
    results = {}
    for surf in args.surfaces:
        m, shape = example_surfaces()[surf]
        print(f"\n=== {surf} ===", flush=True)
        res = compare_laws.compare(
            dict(kind="moments", moments=m, shape=shape), psi=args.psi, tol=args.tol,
            realisations=args.realisations, ppw=args.ppw or PPW[surf], periods=args.periods,
            tangential=surf in args.tangential,
            n_pressures=args.pressures, area_range=(0.002, 0.4), backend=args.backend,
            plastic=surf in args.plastic, out=None, verbose=False, label=surf,
            # the settings of the docs/bem.md study (before fixed amplitudes and the
            # Richardson area existed): Gaussian random fields, pixel-counted area
            amplitudes="random", area_extrapolation=False, workers=1)
        rows = []
        for r in res["ratios"]:
            rows.append({"surface": surf, "law": r["law"], "p [MPa]": r["p [MPa]"],
                         "h/sigma": r["h/sigma (BEM)"], "stat valid": r["stat valid"],
                         "p_at_h": r["p ratio at equal h"], "a_at_h": r["A ratio at equal h"],
                         "k_at_h": r["k ratio at equal h"], "a_at_p": r["A ratio at equal p"],
                         "k_at_p": r["k ratio at equal p"],
                         "dh_sigma_at_p": r["dh/sigma at equal p"], "se_p": r["se p"],
                         "se_a": r["se A"], "se_k": r["se k"]})
        b = res["bem"]["BEM elastic"]
        results[surf] = dict(rows=rows, agree=res["agree"], info=b.info,
                             scatter=(float(np.max(b.pressure_std / b.pressure)),
                                      float(np.max(b.area_std / b.area_fraction)),
                                      float(np.max(b.stiffness_std / b.stiffness))),
                             tangential=(np.mean(b.tangential_ratio, axis=0)
                                         if np.isfinite(b.tangential_ratio).all()
                                         else np.full(2, np.nan)),
                             area=(float(b.area_fraction.min()), float(b.area_fraction.max())),
                             time=(res["time_stat"], res["time_bem"]))
        if args.figdir:
            os.makedirs(args.figdir, exist_ok=True)
            laws = dict(res["stat"])
            laws.update({k: v.normal for k, v in res["bem"].items()})
            compare_laws.plot(laws, {"BEM elastic": b}, res["sigma"], res["pressures"],
                              os.path.join(args.figdir, f"bem_compare_{surf}.png"),
                              f"{surf}: statistical vs BEM (band: +-1 std over "
                              f"{b.info['realisations']} realisations, {b.info['grid'][0]}^2 px)")
    # ---- print
    print("\nStatistical / BEM ratios (BEM: mean of the realisations at equal separation); "
          "'valid': statistical law inside its validity range; s.e.: relative standard error "
          "of the BEM mean (realisation std / sqrt(n)), the sampling uncertainty of the ratios")
    hdr = (f"{'surface':12s} {'law':22s} {'p [MPa]':>8s} {'h/sig':>6s} {'valid':>5s} "
           f"{'p(h)':>6s} {'A(h)':>6s} {'k(h)':>6s} {'A(p)':>6s} {'k(p)':>6s} {'dh/sig':>7s}"
           f"  {'s.e. p/A/k':>14s}")
    print(hdr)
    print("-" * len(hdr))
    all_rows = []
    for surf, res in results.items():
        for r in res["rows"]:
            all_rows.append(r)
            print(f"{surf:12s} {r['law'][:22]:22s} {r['p [MPa]']:8.3g} {r['h/sigma']:6.2f} "
                  f"{r['stat valid']:>5s} {r['p_at_h']:6.3f} {r['a_at_h']:6.3f} "
                  f"{r['k_at_h']:6.3f} {r['a_at_p']:6.3f} {r['k_at_p']:6.3f} "
                  f"{r['dh_sigma_at_p']:7.3f}  {r['se_p']:4.2f}/{r['se_a']:4.2f}/{r['se_k']:4.2f}")
    print(f"\nLoad ranges [MPa] of agreement within {args.tol:.0%}:")
    for surf, res in results.items():
        i = res["info"]
        print(f"  {surf} (BEM {i['grid'][0]}^2 px, {i['realisations']} realisations, A/A0 "
              f"{res['area'][0]:.3g}-{res['area'][1]:.3g}; scatter 1 std p/A/k "
              f"{res['scatter'][0]:.2f}/{res['scatter'][1]:.2f}/{res['scatter'][2]:.2f}; "
              + (f"kT/kN x/y {res['tangential'][0]:.3f}/{res['tangential'][1]:.3f}; "
                 if np.isfinite(res['tangential']).all() else "")
              + f"build: statistical {res['time'][0]:.0f} s, BEM {i['build_time_s']:.0f} s "
              f"when computed, {i['cached']} of {i['realisations']} from the cache now)")
        for name, rng in res["agree"].items():
            txt = {q: "-" if r is None else f"{r[0]:.3g}-{r[1]:.3g}" for q, r in rng.items()}
            print(f"    {name:28s} k(p): {txt['k_at_p']:>13s}  A(p): {txt['a_at_p']:>13s}  "
                  f"p(h): {txt['p_at_h']:>13s}  all: {txt['all']:>13s}")
    if args.csv:
        write_csv(args.csv, all_rows)
    if args.figdir:
        figure(results, os.path.join(args.figdir, "bem_vs_statistical.png"))
        print(f"figures: {args.figdir}/bem_vs_statistical.png, bem_compare_<surface>.png")


if __name__ == "__main__":
    main()
