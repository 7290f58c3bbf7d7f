"""Realisation scatter of the BEM law vs cell size: what compare_laws.py's defaults rest on.

For one example surface, ``--realisations`` Gaussian realisations of its spectrum are solved for
each cell size (``--periods``: roll-off wavelengths per side; ppw pixels per shortest
wavelength) at the same mean pressures, as ``rough_contact.micro.law_comparison.compare`` does
(elastic BEM, Richardson area, no tangential stiffness). Printed per cell size, at the pressures
where the mean law has A/A0 = 1, 3, 10, 30 %:

* the scatter of one realisation, 1 std / mean: of p at equal separation (what
  ``compare_laws.py`` prints as "realisation scatter") and of A/A0 and k at equal load;
* the standard error of the mean of ``n`` realisations, std / sqrt(n), for the ``n`` that
  compare_laws.py would use (``--use``), the uncertainty of the BEM reference.

    bash run.sh python benchmarks/bench_bem_scatter.py --periods 1 --realisations 8
    bash run.sh python benchmarks/bench_bem_scatter.py --periods 1 --realisations 48 \
        --amplitudes fixed --use 48           # the compare_laws.py default (~10 min, 2 cores)

Units: mm, MPa. Results are cached (rough_contact.micro.bem.default_cache_dir()).
"""
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings

import numpy as np
from _common import write_csv

from rough_contact.micro import bem
from rough_contact.micro.law_comparison import E_STAR, NU
from rough_contact.surface.spectrum import example_surfaces

TARGETS = (0.01, 0.03, 0.1, 0.3)


def scatter(law: bem.BEMLaw, targets=TARGETS):
    """Rows of per-realisation scatter at the pressures where the mean A/A0 = target."""
    c = law.curves
    a_r = c.area_fraction_extrapolated if c.area_fraction_extrapolated is not None \
        else c.area_fraction                                            # (n_r, n_p)
    k_r = c.stiffness
    lp = np.log(c.pressure)
    rows = []
    a_mean = a_r.mean(axis=0)
    for t in targets:
        if not a_mean.min() <= t <= a_mean.max():
            continue
        lpt = np.interp(math.log(t), np.log(a_mean), lp)
        a_t = np.array([np.interp(lpt, lp, a) for a in a_r])
        k_t = np.array([np.interp(lpt, lp, k) for k in k_r])
        h = law.normal.separation_for_pressure(np.array([math.exp(lpt)]))
        ps = float(np.interp(h[0], law.separation, law.pressure_std / law.pressure))
        rows.append(dict(target_area=t, p_MPa=math.exp(lpt),
                         std_p_at_h=ps, std_a_at_p=float(a_t.std(ddof=1) / a_t.mean()),
                         std_k_at_p=float(k_t.std(ddof=1) / k_t.mean())))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--surface", default="anisotropic", choices=list(example_surfaces()))
    ap.add_argument("--periods", nargs="+", type=int, default=[1, 2, 4])
    ap.add_argument("--ppw", type=float, default=8.0)
    ap.add_argument("--realisations", type=int, default=8)
    ap.add_argument("--use", nargs="+", type=int, default=None,
                    help="realisations compare_laws would average, per --periods entry "
                    "(default: --realisations)")
    ap.add_argument("--pressures", type=int, default=10)
    ap.add_argument("--amplitudes", default="random", choices=["random", "fixed"],
                    help="Gaussian random fields, or random phases at fixed moduli")
    ap.add_argument("--backend", default="numpy", choices=["tamaas", "numpy"])
    ap.add_argument("--workers", type=int, default=2, help="realisations in parallel")
    ap.add_argument("--csv", default="docs/bem_scatter.csv")
    args = ap.parse_args(argv)
    m, shape = example_surfaces()[args.surface]
    use = args.use or [args.realisations] * len(args.periods)
    out = []
    for P, n_use in zip(args.periods, use):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", bem.HeightMapWarning)
            law = bem.bem_law_from_moments(
                m, shape=shape, E_star=E_STAR, nu=NU, n_realisations=args.realisations,
                pixels_per_wavelength=args.ppw, periods=P, n_pressures=args.pressures,
                area_range=(0.003, 0.3), backend=args.backend, tangential=False,
                area_extrapolation=True, amplitudes=args.amplitudes, workers=args.workers)
        dt = time.perf_counter() - t0
        grid = law.info["grid"]
        for r in scatter(law):
            r.update(surface=args.surface, amplitudes=args.amplitudes, periods=P, grid=f"{grid[0]}x{grid[1]}",
                     realisations=args.realisations, n_mean=n_use,
                     se_p_at_h=r["std_p_at_h"] / math.sqrt(n_use),
                     se_a_at_p=r["std_a_at_p"] / math.sqrt(n_use),
                     se_k_at_p=r["std_k_at_p"] / math.sqrt(n_use),
                     time_per_realisation_s=float(np.mean(law.curves.build_time)),
                     cached=int(law.info["cached"]))
            out.append(r)
        print(f"  periods {P}: grid {grid}, {args.realisations} realisations, {dt:.1f} s "
              f"({law.info['cached']} cached)", flush=True)
    print(f"\nRealisation scatter of the elastic BEM law, '{args.surface}' surface, ppw "
          f"{args.ppw:g}, {args.amplitudes} amplitudes, E* = {E_STAR:g} MPa (1 std / mean over {args.realisations} "
          "realisations; se = std/sqrt(n_mean), the standard error of compare_laws' mean)\n")
    hdr = (f"{'periods':>7s} {'grid':>9s} {'A/A0':>5s} {'p MPa':>8s} | {'1 realisation: p(h)':>19s} "
           f"{'A(p)':>6s} {'k(p)':>6s} | {'n':>3s} {'se p(h)':>8s} {'A(p)':>6s} {'k(p)':>6s} | "
           f"{'s/real.':>7s}")
    print(hdr + "\n" + "-" * len(hdr))
    for r in out:
        print(f"{r['periods']:7d} {r['grid']:>9s} {r['target_area']:5.2f} {r['p_MPa']:8.3g} | "
              f"{r['std_p_at_h']:19.1%} {r['std_a_at_p']:6.1%} {r['std_k_at_p']:6.1%} | "
              f"{r['n_mean']:3d} {r['se_p_at_h']:8.1%} {r['se_a_at_p']:6.1%} "
              f"{r['se_k_at_p']:6.1%} | {r['time_per_realisation_s']:7.1f}")
    if args.csv:
        write_csv(args.csv, out)
    return out


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
