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
from bench_mindlin import E, MU, NU, R, beta_over_mu
from rough_contact.references import hertz_radius
from rough_contact.scenes import mindlin


def _slip_line(pts, i, P):
    """(Hertz's radius at P [mm], the summary of increment i: vertices in contact, slipping,
    the innermost slipping one's r / a_Hertz)."""
    a = hertz_radius(P, R, E / (1.0 - NU**2))
    on, slip = pts.contact[i], pts.slipping[i]
    inner = pts.r[slip].min() / a if slip.any() else float("nan")
    return a, (f"{int(on.sum())} vertices in contact, {int(slip.sum())} slip, innermost at "
               f"r / a_Hertz = {inner:.4f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+", help="checkpoint directories of bench_mindlin.py runs")
    ap.add_argument("--increment", type=int, default=None,
                    help="1-based increment (default: the last of the normal load, t = 1)")
    ap.add_argument("--each", action="store_true",
                    help="also one line per increment of the normal load")
    args = ap.parse_args(argv)
    for d in args.dirs:
        t, P, pts = mindlin.checkpointed_points(d)
        if args.each:
            for j in np.flatnonzero(t <= 1.0 + 1e-9):
                print(f"{os.path.basename(d)}: increment {j + 1} (t = {t[j]:g}): "
                      f"{_slip_line(pts, j, P[j])[1]}")
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
        a, line = _slip_line(pts, i, P[i])
        print(f"{os.path.basename(d)}: increment {i + 1} (t = {t[i]:g}), P = {P[i]:.4g} N, "
              f"{line}")
        print("\n".join(normal_load_profile(pts, i, a, MU, beta_over_mu())))


if __name__ == "__main__":
    main()
