"""Slip under the normal load alone on the Cattaneo–Mindlin scene, read from the checkpoints of
``bench_mindlin.py --part energy --checkpoint DIR`` runs (no FE solve: serial, seconds).

    .venv/bin/python benchmarks/bench_normal_load_slip.py DIR [DIR ...] [--increment N] [--each]
        [--branch]

For each checkpoint directory, at the end of the normal load (or at increment N, 1-based): the
vertices in contact (p > 1e-3 p_max), those that slip, the innermost slipping one's r / a_Hertz
(a_Hertz at the FE force), and per band of r / a_Hertz the mean radial shear / mu p0 and the
largest |t| / (mu p) against the continuum's (Spence's problem under Goodman's approximation,
``rough_contact.frictional_hertz``, 400 rings: the continuum has no slip here, its annulus is
~1e-21 a). ``--each``: first one line per normal-load increment (vertices in contact, slipping,
the innermost slipping one's r / a_Hertz). ``--branch``: then the first loading branch (after
the normal load up to t = 1.25, the first quarter cycle): Q / mu P, Mindlin's
(1 - Q / mu P)^(1/3), the area estimate sqrt(1 - A_slip / A_contact) (vertex weights) and its
error, and the innermost slipping vertex's r / a_Hertz. docs/mindlin_dual.md (session 20) quotes
the tables.
"""

from __future__ import annotations

import argparse
import os

import numpy as np

from _common import normal_load_profile
from bench_mindlin import E, MU, NU, R, beta_over_mu
from rough_contact.references import hertz_radius, stick_ratio
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
    ap.add_argument("--branch", action="store_true",
                    help="also the first loading branch's area estimate of c / a")
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
        if args.branch:
            _branch(d, pts)


def _branch(d, pts):
    """The first loading branch's area estimate and innermost slipping vertex (--branch)."""
    t, P, Q = mindlin.checkpointed_forces(d)
    print(f"  {'Q/muP':>7} {'c/a CM':>7} {'area':>7} {'error':>8} {'innermost':>9}")
    for i in np.flatnonzero((t > 1.0 + 1e-9) & (t <= 1.25 + 1e-9)):
        on, slip = pts.contact[i], pts.slipping[i]
        area = np.sqrt(1.0 - pts.weight[slip].sum() / pts.weight[on].sum())
        cm = float(stick_ratio(abs(Q[i]), MU, P[i]))
        a = hertz_radius(P[i], R, E / (1.0 - NU**2))
        inner = pts.r[slip].min() / a if slip.any() else float("nan")
        print(f"  {abs(Q[i]) / (MU * P[i]):7.4f} {cm:7.4f} {area:7.4f} {area / cm - 1:+8.4f} "
              f"{inner:9.4f}")


if __name__ == "__main__":
    main()
