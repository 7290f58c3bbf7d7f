# # Statistical vs boundary-element normal law of one rough surface
#
# For one surface this tool builds, side by side,
#
# * the statistical laws of this package (asperity sums, :mod:`rough_contact.micro.population`):
#   the strongly anisotropic elastic model (52)-(55), its elasto-plastic version (78)-(88) and
#   McCool's equivalent Greenwood-Williamson model, all from the five spectral moments;
# * the boundary-element laws (:mod:`rough_contact.micro.bem`): exact elastic contact of the surface
#   itself, and its saturated variant (pressure capped at the flow pressure c_h H of the
#   statistical model's fully plastic asperities, eq 66),
#
# and prints and plots p, A/A0 and k = -dp/dh against h/sigma and against the load, the ratios
# statistical/BEM at equal separation and at equal load, and the load range over which each
# statistical law agrees with the BEM law within a tolerance.
#
# The surface is either one of the example surfaces (``--surface``; spectral moments only, so
# the BEM law averages Gaussian realisations of the assumed spectrum, docs/bem.md), spectral
# moments (``--moments m00 m20 m02 m40 m04`` in the paper's um convention), or a measured height
# map (``--height-map file.npy --dx STEP --unit um``: the statistical laws use its moments, the
# BEM law the map itself, ``--boundary mirror`` for a non-periodic measurement).
#
# Units: mm, N, MPa inside; separations printed as h/sigma, sigma = sqrt(m00).
#
# The BEM reference is the mean over Gaussian realisations of the spectrum. Defaults: 64
# realisations of one roll-off period at 8 px per shortest wavelength (180 x 180 px for the
# example surfaces), random phases at fixed amplitudes, solved two at a time, A/A0 by
# Richardson extrapolation. One realisation scatters by 35 % (p at equal separation), 14 %
# (A/A0 at equal load) and 21 % (k at equal load) at A/A0 = 1 % (anisotropic example surface,
# 48 realisations, benchmarks/bench_bem_scatter.py, docs/bem.md "Realisation scatter"), so the
# standard error of the mean of 64 is 4.4 %, 1.7 % and 2.6 % there and smaller at heavier
# loads. The comparison loads include the one where the BEM A/A0 = 1 %, and the 95 %
# confidence interval of the BEM mean is printed at each. This costs about 7 s of wall time
# per realisation and law on the 2 cores of the test machine (measured while it was loaded;
# elastic and saturated BEM, so ~15 min; results are cached). ``--quick`` (8 realisations,
# ~2-3 min) has standard errors of 12.5 %, 4.8 % and 7.5 % at A/A0 = 1 %, <= 5 % from
# A/A0 ~ 10 %.
#
# Run: ``bash run.sh python demos/compare_laws.py --surface anisotropic [--quick] [--tol 0.1]
# [--realisations 64] [--ppw 8] [--psi 0.35] [--workers 2] [--out results/compare]``.
#
# The work is done by the library, ``rough_contact.micro.law_comparison``; this script is its
# command line.

import argparse
import os
import sys

import numpy as np

from rough_contact.micro import bem, law_comparison
from rough_contact.surface import example_surfaces


def source_from_args(args):
    """The surface named on the command line -> (source for compare, label)."""
    if args.height_map:
        data = np.load(args.height_map)
        z = data["z"] if isinstance(data, np.lib.npyio.NpzFile) else data
        if args.dx is None:
            raise SystemExit("--height-map needs --dx (sampling step, in --unit)")
        return (law_comparison.source_from_height_map(z, args.dx, args.dy, unit=args.unit,
                                                      boundary=args.boundary),
                os.path.basename(args.height_map))
    if args.moments:
        return (law_comparison.source_from_moments(args.moments, args.hurst, args.plateau),
                "moments " + " ".join(f"{v:g}" for v in args.moments))
    return law_comparison.source_from_example(args.surface), args.surface


def main(argv=None):
    ap = argparse.ArgumentParser(description="Statistical vs BEM normal law of one surface",
                                 allow_abbrev=False)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--surface", default="anisotropic", choices=list(example_surfaces()))
    g.add_argument("--moments", nargs=5, type=float, metavar=("m00", "m20", "m02", "m40", "m04"),
                   help="spectral moments, um convention")
    g.add_argument("--height-map", help=".npy (2D heights) or .npz with key z")
    ap.add_argument("--dx", type=float, help="height-map step along axis 0, in --unit")
    ap.add_argument("--dy", type=float, help="step along axis 1 (default dx)")
    ap.add_argument("--unit", default="um", choices=["um", "mm", "m"])
    ap.add_argument("--boundary", default="mirror", choices=["periodic", "mirror", "window"])
    ap.add_argument("--hurst", type=float, default=0.8, help="assumed spectrum (moments only)")
    ap.add_argument("--plateau", type=float, default=2.0, help="assumed roll-off q_r/q_l")
    ap.add_argument("--E-star", type=float, default=law_comparison.E_STAR, help="effective modulus [MPa]")
    ap.add_argument("--nu", type=float, default=law_comparison.NU)
    ap.add_argument("--psi", type=float, default=0.35, help="plasticity index (69)")
    ap.add_argument("--no-plastic", action="store_true", help="skip the elasto-plastic laws")
    ap.add_argument("--tol", type=float, default=0.1, help="agreement tolerance [-]")
    ap.add_argument("--realisations", type=int, default=None,
                    help="BEM realisations (default 64; 8 with --quick)")
    ap.add_argument("--quick", action="store_true",
                    help="8 realisations (~2-3 min): standard error of the BEM mean ~12 %% at "
                    "A/A0 = 1 %% instead of <= 5 %%")
    ap.add_argument("--amplitudes", default="fixed", choices=["fixed", "random"],
                    help="realisations: random phases at fixed amplitudes (less scatter) or "
                    "Gaussian random fields")
    ap.add_argument("--workers", type=int, default=2, help="realisations solved in parallel")
    ap.add_argument("--ppw", type=float, default=8.0, help="pixels per shortest wavelength")
    ap.add_argument("--periods", type=int, default=1, help="roll-off wavelengths per side")
    ap.add_argument("--pressures", type=int, default=12)
    ap.add_argument("--area-range", nargs=2, type=float, default=(0.003, 0.3))
    ap.add_argument("--backend", default=None, choices=["tamaas", "numpy"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--resolution-check", action="store_true",
                    help="height map: also solve the map sub-sampled by 2 and report the change")
    ap.add_argument("--out", default="results/compare_laws")
    args = ap.parse_args(argv)
    source, label = source_from_args(args)
    if args.resolution_check:
        if source["kind"] != "map":
            raise SystemExit("--resolution-check needs --height-map")
        r = bem.resolution_check(source["z"], source["dx"], source["dy"], E_star=args.E_star,
                                 nu=args.nu, boundary=source["boundary"], backend=args.backend)
        print(f"resolution check (map vs map sub-sampled by 2, elastic BEM): max change of p(h) "
              f"{r['p']:.2%}, k(h) {r['k']:.2%}, A/A0(h) {r['a']:.2%} (the full map's own "
              "discretisation error is roughly 2-4x smaller, docs/bem.md)")
    return law_comparison.compare(source, E_star=args.E_star, nu=args.nu, psi=args.psi, tol=args.tol,
                   realisations=args.realisations or (8 if args.quick else 64), ppw=args.ppw,
                   periods=args.periods, amplitudes=args.amplitudes, workers=args.workers,
                   n_pressures=args.pressures, area_range=tuple(args.area_range),
                   backend=args.backend, seed=args.seed, plastic=not args.no_plastic,
                   out=args.out, label=label)


if __name__ == "__main__":
    main(sys.argv[1:])
