"""Grid convergence of the BEM normal law: p(h), k(h), A/A0(h) vs pixels per shortest wavelength.

For each example surface (rough_contact.surface.spectrum.example_surfaces) and each seed
(``--seeds``, three by default) one Gaussian realisation is generated on the finest grid and
sub-sampled by 2, 4, ... (the same band-limited surface, coarser pixels). Each grid is solved at
the same mean pressures (A/A0 about 1 % to 20 %); the laws are compared with the finest one at
its separations (p, k, A/A0 at equal h) and at equal load (separation shift in units of the rms
height sigma). The pixel-counted A/A0 and its Richardson estimate 2 A(grid) - A(grid/2) are
compared with the Richardson estimate of the two finest grids. The table gives, per surface and
grid, the worst error over the seeds; the summary states the coarsest grid at which p(h) and
k(h) are within 1 % of the finest grid on *every* seed. Prints a table, writes CSV and a figure.

    bash run.sh python benchmarks/bench_bem_convergence.py                 # quick (~10 min)
    bash run.sh python benchmarks/bench_bem_convergence.py --full          # ppw up to 16/32
    bash run.sh python benchmarks/bench_bem_convergence.py --surfaces paper --ppw 2 4 8

Results are cached on disk (rough_contact.micro.bem.default_cache_dir()); --no-cache recomputes.
Units: mm, MPa; ppw = pixels per shortest wavelength 2 pi/q_s of the spectrum.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
import warnings

import numpy as np
from _common import write_csv

from rough_contact.micro import bem
from rough_contact.surface.spectrum import _next_smooth, example_surfaces, fit_spectrum

E_STAR = 1.067e5   # MPa: two steel bodies (E = 200 GPa, nu = 0.25), the paper's punch
NU = 0.25

QUICK = {"isotropic": [2, 4, 8, 16], "anisotropic": [2, 4, 8, 16], "self-affine": [2, 4, 8]}
FULL = {"isotropic": [2, 4, 8, 16, 32], "anisotropic": [2, 4, 8, 16, 32],
        "self-affine": [2, 4, 8, 16], "paper": [2, 4, 8]}


def grids(spec, ppws, periods=1):
    """One grid per ppw, each a 2^k sub-sampling of the finest: [(ppw_actual, step, n)]."""
    ppws = sorted(ppws)
    f = int(round(ppws[-1] / ppws[0]))
    n_min = math.ceil(periods * ppws[-1] * spec.q_s / spec.q_l / f)
    n_fine = f * _next_smooth(n_min)
    out = []
    for p in ppws:
        step = int(round(ppws[-1] / p))
        n = n_fine // step
        out.append((n / (periods * spec.q_s / spec.q_l), step, n))
    return n_fine, out


def run_surface(name, ppws, seed, n_p, backend, cache):
    """One realisation (seed) on every grid: (rows, laws)."""
    m, shape = example_surfaces()[name]
    spec = fit_spectrum(m, shape)
    n_fine, levels = grids(spec, ppws)
    (_, _), (Lx, Ly) = spec.grid(ppws[-1])
    z_fine = spec.realisation((n_fine, n_fine), (Lx, Ly), seed)
    pressures = bem.default_pressures(E_STAR, math.sqrt(m.m20 + m.m02), area_range=(0.01, 0.2),
                                      n=n_p)
    sigma = math.sqrt(m.m00)
    laws = []
    for ppw, step, n in levels:
        z = np.ascontiguousarray(z_fine[::step, ::step])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", bem.HeightMapWarning)   # coarse levels warn, on purpose
            t0 = time.perf_counter()
            c = bem.bem_curves(z, Lx / n, Ly / n, E_star=E_STAR, nu=NU, pressures=pressures,
                               backend=backend, tangential=False, cache=cache)
            dt = time.perf_counter() - t0
        laws.append((ppw, n, bem.law_from_curves(c), c, dt))
        print(f"  {name:12s} seed {seed} ppw {ppw:5.2f}  grid {n:5d}^2  {dt:7.1f} s"
              f"{' (cached)' if c.cached[0] else ''}", flush=True)
    ref = laws[-1][2]
    h = ref.separation
    # A/A0 of every level at the reference's separations; Richardson of consecutive levels
    a_lv = [law.normal.evaluate(h)[2] for _, _, law, _, _ in laws]
    a_rich = [None] + [2 * a_lv[i] - a_lv[i - 1] for i in range(1, len(laws))]
    a_best = a_rich[-1] if len(laws) > 1 else a_lv[-1]
    rows = []
    for i, (ppw, n, law, c, dt) in enumerate(laws):
        p, k, a = law.normal.evaluate(h)
        rows.append(dict(
            surface=name, seed=seed, ppw=round(ppw, 3), grid=n,
            time_s=round(float(c.build_time[0]), 2), cached=bool(c.cached[0]),
            p_err=float(np.max(np.abs(p / ref.pressure - 1))),
            k_err=float(np.max(np.abs(k / ref.stiffness - 1))),
            a_err=float(np.max(np.abs(a / ref.area_fraction - 1))),
            a_pixel_bias=float(np.max(a / a_best - 1)),
            a_richardson_err=float(np.max(np.abs(a_rich[i] / a_best - 1)))
            if a_rich[i] is not None else float("nan"),
            dh_sigma=float(np.max(np.abs(c.separation[0] - ref.curves.separation[0])) / sigma),
            a_min=float(ref.area_fraction.min()), a_max=float(ref.area_fraction.max())))
    return rows, laws


def aggregate(rows):
    """Worst error over the seeds per (surface, grid); times and ranges of the first seed."""
    keys = ("p_err", "k_err", "a_err", "a_pixel_bias", "a_richardson_err", "dh_sigma")
    out = []
    for name in dict.fromkeys(r["surface"] for r in rows):
        for n in dict.fromkeys(r["grid"] for r in rows if r["surface"] == name):
            rs = [r for r in rows if r["surface"] == name and r["grid"] == n]
            w = dict(rs[0])
            for k in keys:
                vals = [r[k] for r in rs if np.isfinite(r[k])]
                w[k] = float(np.max(vals)) if vals else float("nan")
            w["seeds"] = len(rs)
            out.append(w)
    return out


def summary(worst, names, n_seeds):
    """One sentence per surface: the coarsest grid meeting 1 % for p(h) and k(h) on every seed."""
    lines = []
    for name in names:
        rs = [r for r in worst if r["surface"] == name]
        cand = rs[:-1]                                         # the finest is the reference
        ok = [r for r in cand if r["p_err"] <= 0.01 and r["k_err"] <= 0.01]
        if ok:
            r = ok[0]
            lines.append(f"{name}: p(h) and k(h) are within 1 % of the finest grid "
                         f"({rs[-1]['ppw']:.1f} px per shortest wavelength) from {r['ppw']:.1f} px "
                         f"per shortest wavelength (grid {r['grid']}^2) on all {n_seeds} "
                         f"realisation(s) (worst: p {r['p_err']:.2%}, k {r['k_err']:.2%})")
        else:
            r = cand[-1] if cand else rs[-1]
            lines.append(f"{name}: p(h) and k(h) are not within 1 % of the finest grid on all "
                         f"{n_seeds} realisation(s) at any coarser grid (at {r['ppw']:.1f} px per "
                         f"shortest wavelength, worst: p {r['p_err']:.2%}, k {r['k_err']:.2%})")
    return lines


def figure(all_rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), sharey=True)
    for ax, key, title in zip(axes, ("p_err", "k_err", "a_err"),
                              ("pressure p(h)", "stiffness k(h)", "area A/A0(h)")):
        for name in dict.fromkeys(r["surface"] for r in all_rows):
            rs = [r for r in all_rows if r["surface"] == name][:-1]   # finest is the reference
            ax.loglog([r["ppw"] for r in rs], [max(r[key], 1e-6) for r in rs], "o-", label=name)
        ax.axhline(0.01, color="k", lw=0.8, ls="--")
        ax.set_xlabel("pixels per shortest wavelength")
        ax.set_title(f"max |{title} / finest - 1|", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("relative difference to the finest grid")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--surfaces", nargs="+", default=None, choices=list(FULL))
    ap.add_argument("--ppw", nargs="+", type=float, default=None,
                    help="pixels per shortest wavelength (finest last is the reference)")
    ap.add_argument("--full", action="store_true", help="finer reference grids (~30 min)")
    ap.add_argument("--pressures", type=int, default=6, help="number of mean pressures")
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3],
                    help="realisations (the claims hold for every one)")
    ap.add_argument("--backend", default="numpy", choices=["tamaas", "numpy"],
                    help="identical results (tests); numpy is the faster here (bench_bem_cost.py)")
    ap.add_argument("--no-cache", action="store_true")
    ap.add_argument("--csv", default="docs/bem_convergence.csv")
    ap.add_argument("--figure", default="docs/figures/bem_convergence.png")
    args = ap.parse_args(argv)
    plan = FULL if args.full else QUICK
    names = args.surfaces or list(plan)
    rows = []
    for name in names:
        ppws = args.ppw or plan.get(name, [2, 4, 8])
        for seed in args.seeds:
            r, _ = run_surface(name, ppws, seed, args.pressures, args.backend,
                               not args.no_cache)
            rows += r
    worst = aggregate(rows)
    print(f"\nGrid convergence of the BEM law (E* = {E_STAR:g} MPa, {len(args.seeds)} "
          f"realisation(s): seeds {args.seeds}, {args.pressures} pressures, A/A0 of the finest "
          "grid given per surface); errors are the max over the load range relative to the "
          "finest grid (last row of each surface), worst over the seeds. 'A pixel' and 'A Rich.': "
          "pixel count and Richardson 2 A(grid) - A(grid/2) against the Richardson estimate of "
          "the two finest grids\n")
    hdr = (f"{'surface':12s} {'ppw':>6s} {'grid':>6s} {'time s':>8s} {'p(h)':>9s} {'k(h)':>9s} "
           f"{'A(h)':>9s} {'A pixel':>9s} {'A Rich.':>9s} {'|dh|/sigma':>11s}  A/A0 range")
    print(hdr)
    print("-" * len(hdr))
    for r in worst:
        print(f"{r['surface']:12s} {r['ppw']:6.2f} {r['grid']:6d} {r['time_s']:8.1f} "
              f"{r['p_err']:9.2e} {r['k_err']:9.2e} {r['a_err']:9.2e} {r['a_pixel_bias']:9.2e} "
              f"{r['a_richardson_err']:9.2e} {r['dh_sigma']:11.2e}  "
              f"{r['a_min']:.3f}-{r['a_max']:.3f}")
    print()
    for line in summary(worst, names, len(args.seeds)):
        print(line)
    if args.csv:
        write_csv(args.csv, rows)
    if args.figure:
        os.makedirs(os.path.dirname(args.figure) or ".", exist_ok=True)
        figure(worst, args.figure)
        print(f"figure: {args.figure}")
    return rows


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
