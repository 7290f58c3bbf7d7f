"""A rough joint under fretting: preload, then tangential cycles at several amplitudes.

    bash run.sh python demos/demo_fretting.py [--amplitudes 0.5 1 4] [--cycles 3]
        [--steps-per-cycle 16] [--pressure 10] [--mesh-size 0.12] [--order 1] [--outdir DIR]
        [--checkpoint CKDIR | --restart CKDIR] [-fret_<PETSc option> ...]
    mpirun -n 2 .venv/bin/python demos/demo_fretting.py

Writes DIR/cycles.csv (per amplitude and cycle: loop energy, interface dissipation, secant
stiffness), DIR/loop_a<amplitude>um.csv (per increment: u_x, F_x, dissipation), DIR/fretting.png (loops; energy per cycle vs amplitude, log-log) and
DIR/loop_largest.png. The library function is rough_contact.scenes.fretting.run.
"""

import argparse
import sys

import petsc4py
from _common import parse_known


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--amplitudes", type=float, nargs="+", default=[0.5, 1.0, 4.0],
                    help="tangential displacement amplitudes [um]")
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--steps-per-cycle", type=int, default=16)
    ap.add_argument("--pressure", type=float, default=10.0, help="nominal preload [MPa]")
    ap.add_argument("--mesh-size", type=float, default=0.12,
                    help="element size [mm] (0.12: 16 089 DOFs at P1; 0.5: 1 290)")
    ap.add_argument("--order", type=int, default=1, choices=[1, 2])
    ap.add_argument("--outdir", default="results/fretting")
    ck = ap.add_mutually_exclusive_group()
    ck.add_argument("--checkpoint", default=None, metavar="CKDIR",
                    help="write a checkpoint after every converged increment into CKDIR")
    ck.add_argument("--restart", default=None, metavar="CKDIR",
                    help="continue a stopped run (same options and ranks) from CKDIR: finished "
                    "amplitudes are read back, the interrupted one continues")
    args, rest = parse_known(ap, sys.argv[1:] if argv is None else argv)
    # PETSc options (one dash, prefix fret_, e.g. -fret_linear_solver mumps_lagged) must reach
    # PETSc before dolfinx is imported
    # Default: MUMPS factors lagged over 3 Newton iterations with GMRES on top — half the time
    # of a fresh factorisation per iteration with the same Newton iterations and results here
    # (docs/loading.md); a restart then reproduces the run to the Newton tolerance, not to
    # round-off (the lag's position is not checkpointed): -fret_linear_solver mumps for that.
    if not any(a.startswith("-fret_linear_solver") for a in rest):
        rest += ["-fret_linear_solver", "mumps_lagged"]
    petsc4py.init([sys.argv[0]] + rest)
    from rough_contact.scenes import fretting

    fretting.run(args.amplitudes, outdir=args.outdir, cycles=args.cycles,
                 steps_per_cycle=args.steps_per_cycle, pressure=args.pressure,
                 mesh_size=args.mesh_size, order=args.order, checkpoint=args.checkpoint,
                 restart=args.restart)


if __name__ == "__main__":
    main()
