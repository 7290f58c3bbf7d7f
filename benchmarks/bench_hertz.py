"""Sphere on an elastic block vs Hertz: contact radius, peak pressure and pointwise pressure
error by radius band under mesh refinement (rough_contact.scenes.hertz).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_hertz.py [--levels 0.08 0.04 0.02]
        [--orders 1 2] [--rules vertex gauss] [--penalty 1e8]
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_hertz.py --elastic
        [--levels 0.08 0.04 0.02] [--orders 2] [--pairings mortar projection]
        (P1 with the projection uses the nodal rule, quadrature="vertex", unless --rules gauss)

Without ``--elastic``: a rigid sphere. With ``--elastic``: an elastic sphere segment (same
material, R = 10 mm) meshed independently of the block (sphere elements 0.7 x the block's),
pressed by moving its top down by 6 um; the interface is non-matching (``pairing``).

R = 10 mm, E = 200 GPa, nu = 0.3, quarter block 4 x 4 x 4 mm, bottom pushed up by 4 um (a ~ 0.2
mm). Errors are FE / Hertz - 1 for a and p0 (fitted on p > 0.3 p_max), and max |p - p_Hertz| / p0
per band of r / a. Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import time

from petsc4py import PETSc

from rough_contact.scenes import hertz


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=float, nargs="+", default=[0.08, 0.04, 0.02],
                    help="element sizes at the contact [mm]")
    ap.add_argument("--orders", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rules", nargs="+", default=["vertex", "gauss"])
    ap.add_argument("--penalty", type=float, default=1e8)
    ap.add_argument("--elastic", action="store_true",
                    help="elastic sphere meshed separately (non-matching interface)")
    ap.add_argument("--pairings", nargs="+", default=["mortar", "projection"])
    args = ap.parse_args(argv)
    if args.elastic:
        return elastic(args)
    PETSc.Sys.Print(f"{'size':>5} {'P':>2} {'rule':>6} {'DOFs':>7} {'P [N]':>8} {'a err':>7} "
                    f"{'p0 err':>7} {'<0.5a':>6} {'0.5-0.8':>7} {'0.8-0.95':>8} {'0.95-1.05':>9} "
                    f"{'time s':>6}")
    for order in args.orders:
        for rule in args.rules:
            if rule == "vertex" and order != 1:
                continue
            for cs in args.levels:
                t0 = time.perf_counter()
                r = hertz.run(contact_size=cs, order=order, quadrature=rule,
                              penalty=args.penalty)
                b = list(r.band_error.values())
                PETSc.Sys.Print(f"{cs:5.3f} {order:2d} {rule:>6} {r.dofs:7d} {r.P:8.2f} "
                                f"{100 * r.a_error:6.2f}% {100 * r.p0_error:6.2f}% "
                                f"{100 * b[0]:5.1f}% {100 * b[1]:6.1f}% {100 * b[2]:7.1f}% "
                                f"{100 * b[3]:8.1f}% {time.perf_counter() - t0:6.1f}")


def elastic(args):
    PETSc.Sys.Print(f"{'size':>5} {'P':>2} {'pairing':>10} {'DOFs':>7} {'P [N]':>8} {'a err':>7} "
                    f"{'p0 err':>7} {'<0.5a':>6} {'0.5-0.8':>7} {'0.8-0.95':>8} {'0.95-1.05':>9} "
                    f"{'balance':>8} {'time s':>6}")
    orders = args.orders if args.orders != [1, 2] else [2]
    for order in orders:
        for pairing in args.pairings:
            rule = "vertex" if (order == 1 and pairing == "projection"
                                and "vertex" in args.rules) else "gauss"
            for cs in args.levels:
                t0 = time.perf_counter()
                r = hertz.run_elastic(contact_size=cs, order=order, pairing=pairing,
                                      penalty=args.penalty, quadrature=rule)
                b = list(r.band_error.values())
                PETSc.Sys.Print(f"{cs:5.3f} {order:2d} {pairing[:4] + '/' + rule[:4]:>10} "
                                f"{r.dofs:7d} "
                                f"{r.P:8.2f} {100 * r.a_error:6.2f}% "
                                f"{100 * r.p0_error:6.2f}% {100 * b[0]:5.1f}% "
                                f"{100 * b[1]:6.1f}% {100 * b[2]:7.1f}% {100 * b[3]:8.1f}% "
                                f"{r.balance:8.1e} {time.perf_counter() - t0:6.1f}")


if __name__ == "__main__":
    main()
