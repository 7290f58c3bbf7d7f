"""Speed and accuracy of the tabulated normal law (rough_contact.interface.normal.NormalLaw).

Prints three tables:
  1. evaluate throughput [million points/s] with and without curvature, for several batch sizes;
     measured in CPU time of this process (per core: the machine may be shared) and wall time;
  2. table build time, number of intervals and model evaluations vs rtol;
  3. max relative error of p, k, A/A0 against the direct population integral at random points
     of the table range (not the build's check points), in units of rtol.

Usage:
    .venv/bin/python benchmarks/bench_normal_law.py                       # GW model (fast)
    .venv/bin/python benchmarks/bench_normal_law.py --models gw,elastic   # + elastic population
    .venv/bin/python benchmarks/bench_normal_law.py --models elasto_plastic --rtols 1e-3,1e-4

Surface: Table 1 of the paper (m00 = 0.0625 um^2, ...), E* = 1.14e5 MPa, psi = 0.35.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from rough_contact.micro import population
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.interface.normal import NormalLaw
from rough_contact.surface import SpectralMoments

SURFACE = SpectralMoments(0.0625, 8e-5, 8e-4, 1.04e-6, 1.04e-4, unit="um")
E_STAR = 1.14e5
MATERIAL = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)


def builders(n_quad):
    kw = {} if n_quad is None else {"n_quad": n_quad}
    return {
        "gw": (lambda rtol, check: NormalLaw.greenwood_williamson(SURFACE, E_STAR, rtol,
                                                                  check=check),
               lambda h: population.greenwood_williamson(SURFACE, E_STAR, h)),
        "elastic": (lambda rtol, check: NormalLaw.elastic(SURFACE, E_STAR, rtol, check=check,
                                                          **kw),
                    lambda h: population.elastic(SURFACE, E_STAR, h, **kw)),
        "elasto_plastic": (lambda rtol, check: NormalLaw.elasto_plastic(SURFACE, MATERIAL, rtol,
                                                                        check=check, **kw),
                           lambda h: population.elasto_plastic(SURFACE, MATERIAL, h, **kw)),
    }


def throughput(law, n, curvature, min_time=0.3):
    """Points per second (CPU time, wall time) for batches of n points spread over all regions."""
    rng = np.random.default_rng(0)
    span = law.h_max - law.h_min
    # 80 % in the table, 10 % below validity, 10 % open (typical of a contact patch with margin)
    h = np.concatenate([rng.uniform(law.h_min, law.h_table_end, int(0.8 * n)),
                        rng.uniform(law.h_min - 0.2 * span, law.h_min, n // 10),
                        rng.uniform(law.h_max, law.h_max + 0.2 * span, n - int(0.8 * n) - n // 10)])
    rng.shuffle(h)
    law.evaluate(h, curvature)
    reps = 0
    c0, w0 = time.process_time(), time.perf_counter()
    while True:
        law.evaluate(h, curvature)
        reps += 1
        c, w = time.process_time() - c0, time.perf_counter() - w0
        if w >= min_time and reps >= 3:
            break
    return reps * n / c, reps * n / w


def main(argv=None):
    ap = argparse.ArgumentParser(allow_abbrev=False, description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="gw", help="comma list of gw, elastic, elasto_plastic")
    ap.add_argument("--rtols", default="1e-3,1e-4,1e-5,1e-6", help="comma list of rtol")
    ap.add_argument("--check", default="midpoint", choices=["midpoint", "quarter"])
    ap.add_argument("--n-quad", type=int, default=None, help="population quadrature nodes")
    ap.add_argument("--n-err", type=int, default=400, help="random points for the error check")
    args = ap.parse_args(argv)
    rtols = [float(r) for r in args.rtols.split(",")]
    table = builders(args.n_quad)
    laws = {}
    print("## table build vs rtol  (check mode: %s)" % args.check)
    print(f"{'model':>15} {'rtol':>8} {'build s':>8} {'(CPU s)':>8} {'intervals':>9} {'model evals':>11} "
          f"{'KiB':>6} {'h_min/rq':>9} {'h_max/rq':>9} | max err/rtol: {'p':>6} {'k':>6} {'a':>6}")
    for name in args.models.split(","):
        build, direct = table[name]
        for rtol in rtols:
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                law = build(rtol, args.check)
            except ValueError as e:
                print(f"{name:>15} {rtol:8.0e}  failed: {e}")
                continue
            tb, cb = time.perf_counter() - t0, time.process_time() - c0
            laws[(name, rtol)] = law
            nbytes = sum(getattr(law, f).nbytes for f in ("knots", "_qc", "_ac", "_inv", "_next",
                                                          "_lut"))
            h = np.random.default_rng(1).uniform(law.h_min, law.h_table_end, args.n_err)
            r = direct(h)
            p, k, a = law.evaluate(h)
            errs = [np.max(np.abs(x / y - 1)) / rtol for x, y in
                    ((p, r.pressure), (k, r.stiffness), (a, r.area_fraction))]
            rq = SURFACE.rq
            print(f"{name:>15} {rtol:8.0e} {tb:8.2f} {cb:8.2f} {law.n_intervals:9d} "
                  f"{law.info['model_evaluations']:11d} {nbytes / 1024:6.1f} "
                  f"{law.h_min / rq:9.3f} {law.h_max / rq:9.3f} |               "
                  f"{errs[0]:6.3f} {errs[1]:6.3f} {errs[2]:6.3f}")
    if not laws:
        return
    law = laws[max(laws, key=lambda key: laws[key].n_intervals)]
    print(f"\n## evaluate throughput [million points/s] ({law!r})")
    print("   80 % table / 10 % below validity / 10 % open; CPU = per core, wall = as measured")
    print(f"{'n points':>10} {'p,k,a CPU':>10} {'p,k,a wall':>11} {'+dk/dh CPU':>11} "
          f"{'+dk/dh wall':>12}")
    for n in (1_000, 10_000, 100_000, 1_000_000):
        c0, w0 = throughput(law, n, False)
        c1, w1 = throughput(law, n, True)
        print(f"{n:10d} {c0 / 1e6:10.1f} {w0 / 1e6:11.1f} {c1 / 1e6:11.1f} {w1 / 1e6:12.1f}")


if __name__ == "__main__":
    main()
