"""Issue 23: the normal law with memory against today's reversible law.

Prints three tables:
  1. sphere limit: residual ratios of the consistent construction vs the (unverified) EKK fit;
  2. throughput on 1e5 points (half of them unloading): HistoryNormalLaw.evaluate_history
     against NormalLaw.evaluate (reversible), with all outputs (p, k, A/A0), without A/A0
     (against a NormalLaw without area) and with dk/dh; each for Newton-like calls (the same
     h_min, h moved between calls by N(0, 1e-3 sigma); also 0.1 sigma with all outputs: the
     law remembers what h_min alone decides, and a point's cell polynomial in x while it
     stays in its x cell) and for a first call with a new h_min; and the whole InterfaceLaw
     (friction on) with the reversible and the history normal law (the same committed
     state, the normal jump moved by 1e-3 sigma between calls);
  3. (--table) the build of the loading table and of the history table: wall and CPU time
     (the machine is shared: CPU time is the figure that does not depend on the other jobs),
     direct-sum points, rows x x-knots, the build's own check errors (x direction, h_min
     direction), k >= 0 on a dense sample, data changed by the monotone projection; and the
     table's error against the direct sums at 4 x --random-rows (default 48) random points off
     the grid (x <= 4, where p >= 1e-12 p_load(h_min)), with the table's quadrature (n_quad,
     n_t, n_zeta) and a finer one (n_quad 24, n_t 24, n_zeta 32): max, median and 99th
     percentile over the points of the largest relative error of p, k, A/A0.

  4. (--convergence) the direct unloading sums p, k, A/A0 against the number of nodes
     (n_quad of the (zeta, K) shape rule at n_t 24; n_t of the height rule at n_quad 24),
     relative to n_quad 40 / n_t 48, on three rows h_min = -3, 0, 3 sigma and unloading
     distances up to 6.75 sigma; and the values against the independent nested-quad
     reference (benchmarks/unloading_reference.py) at the points listed in REFERENCE.

Usage: .venv/bin/python benchmarks/bench_unloading.py [--rtol 1e-3] [--psi 1.0] [--table]
       [--convergence] [--n-quad 16] [--n-t 16] [--max-points 20000] [--random-rows 12]
"""
import argparse
import dataclasses
import math
import pickle
import time

import numpy as np

from rough_contact.interface.friction import IsotropicSlipHardening
from rough_contact.interface.history import HistoryNormalLaw
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.normal import NormalLaw
from rough_contact.interface.tangential import TangentialStiffness
from rough_contact.micro import unloading as U
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)

# (h_min/sigma, u/sigma): (p [MPa], k [MPa/mm], A/A0) from benchmarks/unloading_reference.py
# at epsrel 1e-7 (psi = 1, E* = 1.14e5 MPa); recompute with
#   PYTHONPATH=. python benchmarks/unloading_reference.py S_MIN X 1e-7
REFERENCE = {
    (0.0, 1.0): (6.25580463e+01, 5.89893577e+05, 4.82540382e-02),
    (-1.0, 3.0): (5.90130848e-01, 1.08527540e+04, 8.44866135e-04),
}


def convergence(mat):
    sig = S1.rq
    xs = np.array([0.0, 0.3, 1.0, 2.0, 3.0, 5.0, 6.75])
    print("\ndirect unloading sums: max relative difference of p, k, A/A0 over u/sigma in "
          f"{list(xs)} to the finest rule")
    print(f"{'h_min/sigma':>11s} {'rule':>16s} {'p':>9s} {'k':>9s} {'A/A0':>9s} {'s':>6s}")
    for s_min in (-3.0, 0.0, 3.0):
        hm = s_min * sig
        base = np.array(U._row_sums(S1, mat, hm, xs * sig, 40, 24)[:3])
        for n in (8, 12, 16, 24, 32):
            t = time.perf_counter()
            r = np.array(U._row_sums(S1, mat, hm, xs * sig, n, 24)[:3])
            e = np.max(np.abs(r / base - 1), axis=1)
            print(f"{s_min:11.1f} {'n_quad %d' % n:>16s} {e[0]:9.1e} {e[1]:9.1e} {e[2]:9.1e} "
                  f"{time.perf_counter() - t:6.1f}")
        base = np.array(U._row_sums(S1, mat, hm, xs * sig, 24, 48)[:3])
        for n in (8, 12, 16, 24, 32):
            r = np.array(U._row_sums(S1, mat, hm, xs * sig, 24, n)[:3])
            e = np.max(np.abs(r / base - 1), axis=1)
            print(f"{s_min:11.1f} {'n_t %d' % n:>16s} {e[0]:9.1e} {e[1]:9.1e} {e[2]:9.1e}")
    print("\nagainst the independent nested quad (relative differences of p, k, A/A0)")
    for (s_min, x), ref in REFERENCE.items():
        for n in (12, 16, 24, 32):
            r = np.array(U._row_sums(S1, mat, s_min * sig, np.array([x * sig]), n, 24)[:3])[:, 0]
            e = r / np.array(ref) - 1
            print(f"h_min = {s_min:4.1f} sigma, u = {x:4.2f} sigma, n_quad {n:2d}: "
                  f"{e[0]:9.1e} {e[1]:9.1e} {e[2]:9.1e}")


def rates(fns, n, reps=40):
    """Points per CPU second of each function, best of reps, the functions interleaved (the
    machine is shared: the best CPU time is the least disturbed by the other jobs)."""
    best = [np.inf] * len(fns)
    for f in fns:
        f()
    for _ in range(reps):
        for i, f in enumerate(fns):
            c = time.process_time()
            f()
            best[i] = min(best[i], time.process_time() - c)
    return [n / b for b in best]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--psi", type=float, default=1.0)
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--convergence", action="store_true")
    ap.add_argument("--n-quad", type=int, default=16)
    ap.add_argument("--n-t", type=int, default=16)
    ap.add_argument("--random-rows", type=int, default=12,
                    help="random h_min rows of the accuracy check (4 random x each)")
    ap.add_argument("--max-points", type=int, default=20000,
                    help="direct-sum budget of the history table (strict=False: the last table)")
    a = ap.parse_args()
    mat = AsperityMaterial(E_star=1.14e5, H=2000.0)
    wc = float(U.summit_loading(0.0, 20.0, 1.0, mat)["omega_c"])
    print("w*_max   w_res/w_max (consistent)   EKK fit (unverified)")
    for ws in (1.0, 2.0, 10.0, 45.0, 110.0, 1000.0):
        r, _ = U.recovered_interference(ws * wc, 20.0, 1.0, mat)
        print(f"{ws:7.1f}   {float(r) / (ws * wc):8.4f}                   "
              f"{float(U.ekk_residual_ratio(ws)):8.4f}")

    mat = AsperityMaterial(E_star=1.14e5, psi=a.psi).resolve(S1)
    if a.convergence:
        convergence(mat)
    t, c = time.perf_counter(), time.process_time()
    load = NormalLaw.elasto_plastic(S1, mat, a.rtol)
    t_load, c_load = time.perf_counter() - t, time.process_time() - c
    print(f"\nloading NormalLaw.elasto_plastic (rtol {a.rtol:g}): {t_load:.1f} s wall, "
          f"{c_load:.1f} s CPU, {load.info['model_evaluations']} population evaluations")
    if a.table:
        t, c = time.perf_counter(), time.process_time()
        law = HistoryNormalLaw.elasto_plastic(S1, mat, a.rtol, loading=load, n_quad=a.n_quad,
                                              n_t=a.n_t, max_points=a.max_points,
                                              strict=False)
        tb, cb = time.perf_counter() - t, time.process_time() - c
        inf = law.info
        print(f"history table (rtol {a.rtol:g}, n_quad {a.n_quad}, n_t {a.n_t}): {tb:.1f} s "
              f"wall, {cb:.1f} s CPU; {inf['rows']} rows x {inf['x_knots']} x-knots "
              f"(X = {inf['X']:.2f} sigma), {inf['model_points']} direct-sum points; check "
              f"errors x {inf['worst_error_x']:.2g}, h_min {inf['worst_error_h_min']:.2g} "
              f"(converged: {inf['converged']}); k >= 0 on 2e5 points: {inf['k_nonnegative']}; "
              f"monotone projection changed {inf['monotone_projection_changes']} data")
        print(f"total (loading + history): {t_load + tb:.1f} s wall, {c_load + cb:.1f} s CPU")
        print("refinement (stage, check error, direct-sum points so far[, sparse check, "
              "embedded estimate]):", "; ".join(
                  " ".join(f"{v:.3g}" if isinstance(v, float) else str(v) for v in lv)
                  for lv in inf["levels"]))
        sig = S1.rq
        print(f"table vs direct sums at {4 * a.random_rows} random points (x <= 4): max, "
              "median relative error of the worst of p, k, A/A0")
        for nq, nt, nz in ((a.n_quad, a.n_t, inf["n_zeta"]), (24, 24, 32)):
            rng = np.random.default_rng(3)
            errs = []
            for hmi in rng.uniform(load.h_min, load.h_table_end, a.random_rows):
                x = rng.uniform(0.0, 4.0, 4)
                p, k, ar, _ = U._row_sums(S1, mat, hmi, np.concatenate([[0.0], x * sig]), nq,
                                          nt, nz)
                pt, kt, at = law.evaluate_history(hmi + x * sig, np.full(4, hmi))
                use = p[1:] >= 1e-12 * p[0]
                e = np.max([np.abs(pt / p[1:] - 1), np.abs(kt / k[1:] - 1),
                            np.abs(at / ar[1:] - 1)], axis=0)
                errs.extend(e[use])
            print(f"  sums at n_quad {nq}, n_t {nt}, n_zeta {nz}: max {np.max(errs):.2g}, median "
                  f"{np.median(errs):.2g}, 99th percentile {np.percentile(errs, 99):.2g} "
                  f"({len(errs)} points above the tail)")
    else:
        law = HistoryNormalLaw(loading=load, rtol=a.rtol)   # reversible stand-in (no table)
        print("(no --table: the history-law throughput below is that of the reversible path)")

    n = 100_000
    rng = np.random.default_rng(0)
    h = rng.uniform(load.h_min, load.h_max, n)
    hm = h - rng.uniform(-0.5, 0.5, n) * (load.h_max - load.h_min)   # half the points unloading
    # Newton-like calls: the same h_min, h moved between calls by N(0, step sigma) (8 arrays
    # in turn); late iterations move by ~1e-3 sigma, a predictor by more
    sig = S1.rq

    def moving(step, k=8):
        hs = [h + rng.normal(0.0, step * sig, n) for _ in range(k)]
        it = [0]

        def nxt():
            it[0] += 1
            return hs[it[0] % k]
        return nxt

    print(f"\n{'throughput on 1e5 points (CPU time, best of 40)':56s} points/s   % of reversible")
    cold = pickle.loads(pickle.dumps(law))         # a copy that never remembers h_min
    # one copy per row below: what a law remembers is that of its own last call
    lw = [pickle.loads(pickle.dumps(law)) for _ in range(4)]

    def first(**kw):
        cold._memo.clear()
        return cold.evaluate_history(h, hm, **kw)

    load_na = dataclasses.replace(load, has_area=False)
    m = [moving(1e-3) for _ in range(6)] + [moving(0.1)]
    rows = [("NormalLaw.evaluate(h)", lambda: load.evaluate(m[0]()), None),
            ("evaluate_history, same h_min, h moved 1e-3 sigma",
             lambda: lw[0].evaluate_history(m[1](), hm), 0),
            ("evaluate_history, same h_min, h moved 0.1 sigma",
             lambda: lw[1].evaluate_history(m[6](), hm), 0),
            ("evaluate_history, first call with this h_min", first, 0),
            ("NormalLaw without area", lambda: load_na.evaluate(m[2]()), None),
            ("evaluate_history(area=False), same h_min, 1e-3 sigma",
             lambda: lw[2].evaluate_history(m[3](), hm, area=False), 4),
            ("evaluate_history(area=False), first call", lambda: first(area=False), 4),
            ("NormalLaw.evaluate(h, curvature=True)", lambda: load.evaluate(m[4](), True), None),
            ("evaluate_history(curvature=True), same h_min, 1e-3 sigma",
             lambda: lw[3].evaluate_history(m[5](), hm, True), 7),
            ("evaluate_history(curvature=True), first call", lambda: first(curvature=True), 7)]
    r = rates([f for _, f, _ in rows], n)
    for (name, _, ref), ri in zip(rows, r):
        print(f"{name:56s} {ri:9.3g}   {100 * ri / r[ref] if ref is not None else 100:3.0f}")
    fr = dict(tangential=TangentialStiffness((0.7, 1.0)),
              friction=IsotropicSlipHardening(0.4, 0.5, 275.0), h0=0.0)
    jumps = [np.stack([h + rng.normal(0.0, 1e-3 * sig, n), rng.normal(0, 1e-5, n),
                       rng.normal(0, 1e-5, n)], 1) for _ in range(8)]
    L0 = InterfaceLaw(normal=load, **fr)
    s0 = L0.initial_state(n)
    L1 = InterfaceLaw(normal=law, **fr)
    s1 = L1.initial_state(n)
    s1.h_min[:] = hm
    c0, c1 = [0], [0]

    def step(L, s, c):
        c[0] += 1
        return L.evaluate(jumps[c[0] % 8], s)
    r0, r1 = rates([lambda: step(L0, s0, c0), lambda: step(L1, s1, c1)], n, 10)
    print(f"{'InterfaceLaw.evaluate, reversible normal':56s} {r0:9.3g}   100")
    print(f"{'InterfaceLaw.evaluate, normal with memory':56s} {r1:9.3g}   {100 * r1 / r0:3.0f}")


if __name__ == "__main__":
    main()
