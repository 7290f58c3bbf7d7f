"""Slip under the normal load alone on the Cattaneo–Mindlin scene, read from the checkpoints of
``bench_mindlin.py --part energy --checkpoint DIR`` runs (no FE solve: serial, seconds).

    .venv/bin/python benchmarks/bench_normal_load_slip.py DIR [DIR ...] [--increment N] [--each]

For each checkpoint directory, at the end of the normal load (or at increment N, 1-based): the
vertices in contact (p > 1e-3 p_max), those that slip, the innermost slipping one's r / a_Hertz
(a_Hertz at the FE force), and per band of r / a_Hertz the mean radial shear / mu p0 and the
largest |t| / (mu p) against the continuum's (Spence's problem under Goodman's approximation,
``rough_contact.frictional_hertz``, 400 rings: the continuum has no slip here, its annulus is
~1e-21 a). ``--each``: first one line per normal-load increment (vertices in contact, slipping,
the innermost slipping one's r / a_Hertz). docs/mindlin_dual.md (session 20) quotes the tables.
"""

from __future__ import annotations

import argparse
import os

import numpy as np

from _common import normal_load_profile
from rough_contact.frictional_hertz import coupling_parameter
from rough_contact.references import hertz_radius
from rough_contact.scenes import mindlin

E, NU, MU, R = 2.0e5, 0.49, 0.3, 10.0           # the scene of bench_mindlin.py


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+", help="checkpoint directories of bench_mindlin.py runs")
    ap.add_argument("--increment", type=int, default=None,
                    help="1-based increment (default: the last of the normal load, t = 1)")
    ap.add_argument("--each", action="store_true",
                    help="also one line per increment of the normal load")
    args = ap.parse_args(argv)
    beta_mu = abs(coupling_parameter(np.inf, 0.3, E, NU)) / MU
    E_star = E / (1.0 - NU**2)
    for d in args.dirs:
        t, P, pts = mindlin.checkpointed_points(d)
        if args.each:
            for j in np.flatnonzero(t <= 1.0 + 1e-9):
                on, slip = pts.contact[j], pts.slipping[j]
                a_j = hertz_radius(P[j], R, E_star)
                inner = pts.r[slip].min() / a_j if slip.any() else float("nan")
                print(f"{os.path.basename(d)}: increment {j + 1} (t = {t[j]:g}): "
                      f"{int(on.sum())} in contact, {int(slip.sum())} slip, innermost at "
                      f"r / a_Hertz = {inner:.4f}")
        if args.increment is None:
            done = np.flatnonzero(np.abs(t - 1.0) < 1e-9)
            if done.size == 0:
                print(f"{os.path.basename(d)}: the normal load is not finished "
                      f"({t.size} increments, t = {t[-1]:g})")
                continue
            i = int(done[0])
        else:
            if not 1 <= args.increment <= t.size:
                raise SystemExit(f"--increment {args.increment} is invalid: the checkpoint in "
                                 f"{d} has increments 1 ... {t.size}")
            i = args.increment - 1
        a = hertz_radius(P[i], R, E_star)
        on, slip = pts.contact[i], pts.slipping[i]
        inner = pts.r[slip].min() / a if slip.any() else float("nan")
        print(f"{os.path.basename(d)}: increment {i + 1} (t = {t[i]:g}), P = {P[i]:.4g} N, "
              f"{int(on.sum())} vertices in contact, {int(slip.sum())} slip, innermost at "
              f"r / a_Hertz = {inner:.4f}")
        print("\n".join(normal_load_profile(pts, i, a, MU, beta_mu)))


if __name__ == "__main__":
    main()
