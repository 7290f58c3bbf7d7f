"""Spence's slip annulus under a rising normal load (rough_contact.frictional_hertz): c/a
against beta/mu, its ring convergence, and the annulus of the Cattaneo–Mindlin scene.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_spence_annulus.py
        [--ratios 0.5 0.6 0.7 0.8 1 1.5 2 3] [--rings 200 400 800] [--nu 0.49] [--mu 0.3]
        [--fit-max 1]

Prints, per beta/mu and ring count, c/a at the end of the loading, its spread over the loading
from a = 0.4 on (self-similarity), whether the slip zone is one outer annulus at every
increment from a = 0.4 on ("one ann"), the CPU time; then a straight-line fit of ln(1 - c/a)
against mu/beta over the finest rings' resolved rows (1 - c/a at least 3 ring widths, beta/mu
<= --fit-max: the thin-annulus regime) and its
value at the scene's beta/mu (rigid sphere on an elastic block with --nu and --mu): the
annulus width that the fit predicts, to be compared with the scene's element size.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rough_contact.frictional_hertz import coupling_parameter, slip_annulus


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ratios", type=float, nargs="+",
                    default=[0.5, 0.6, 0.7, 0.8, 1.0, 1.5, 2.0, 3.0], help="beta / mu values")
    ap.add_argument("--rings", type=int, nargs="+", default=[200, 400, 800])
    ap.add_argument("--nu", type=float, default=0.49, help="the block's Poisson ratio")
    ap.add_argument("--mu", type=float, default=0.3, help="friction coefficient")
    ap.add_argument("--fit-max", type=float, default=1.0,
                    help="fit only the rows with beta/mu <= this (the thin-annulus regime)")
    args = ap.parse_args(argv)
    beta = abs(coupling_parameter(np.inf, 0.3, 2.0e5, args.nu))
    scene = beta / args.mu
    print(f"scene: rigid sphere on nu = {args.nu:g}: beta = {beta:.5f}, mu = {args.mu:g}, "
          f"beta/mu = {scene:.4f}")
    print(f"{'beta/mu':>8} {'rings':>6} {'c/a':>8} {'1-c/a':>9} {'spread':>8} {'one ann':>7} "
          f"{'CPU s':>7}")
    finest = {}
    for ratio in [scene] + list(args.ratios):
        for n in args.rings:
            t0 = time.process_time()
            res = slip_annulus(ratio, rings=n)
            cpu = time.process_time() - t0
            late = res.stick_ratio[res.a >= 0.4]
            c = res.stick_ratio[-1]
            # one annulus: the innermost slipping ring starts where the outermost stuck ends
            one = np.allclose(res.inner_slip_ratio[res.a >= 0.4], late, atol=1e-12)
            print(f"{ratio:8.4f} {n:6d} {c:8.4f} {1 - c:9.2e} {np.ptp(late):8.4f} "
                  f"{'yes' if one else 'NO':>7} {cpu:7.1f}")
        finest[ratio] = (c, n)
    rows = [(1.0 / r, np.log(1.0 - c)) for r, (c, n) in finest.items()
            if r != scene and r <= args.fit_max and 1.0 - c >= 3.0 / n]
    if len(rows) >= 2:
        x, y = np.array(rows).T
        slope, icpt = np.polyfit(x, y, 1)
        width = np.exp(icpt + slope / scene)
        print(f"fit over {len(rows)} rows (mu/beta {x.min():.2f} ... {x.max():.2f}): "
              f"ln(1 - c/a) = {icpt:.3f} {slope:+.3f} mu/beta; "
              f"at the scene's mu/beta = {1 / scene:.2f}: 1 - c/a = {width:.1e}")
    else:
        print("fewer than 2 resolved rows: no fit")


if __name__ == "__main__":
    main()
