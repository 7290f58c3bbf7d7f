"""A rough joint under fretting: preload, then tangential cycles at several amplitudes.

Two 2 x 2 x 1 mm blocks with the paper's rough interface (slip-hardening friction), a 10 MPa
preload held, then sinusoidal displacement cycles u_x = a sin(2 pi t) of the upper block's top.
Per amplitude the last cycle is reported as a fretting study does: delta*, F*, the dissipated
energy E_d (loop area), the energy ratio A = E_d / (4 F* delta*), the largest slipping share of
the contact area and the regime (stick / partial slip / gross slip).

Run (serially, or on several ranks with MPI; the results do not depend on the rank count):

    python3 demos/demo_fretting.py [--amplitudes 0.5 1 4] [--cycles 3] ...
    mpirun -n 2 python3 demos/demo_fretting.py [options]

PETSc options take the prefix fret_ (one dash), e.g. -fret_snes_monitor,
-fret_snes_rtol 1e-10, or -fret_linear_solver mumps. The default linear solver here is
mumps_lagged: MUMPS factors reused over 3 Newton iterations with GMRES on top (half the time of
a fresh factorisation per iteration, same Newton iterations and results; a restart then
reproduces the run to the Newton tolerance, not to round-off: -fret_linear_solver mumps for
that). Progress: one line per cycle (rank 0, flushed); --verbose adds one per increment.

Writes in DIR (--outdir): fretting_map.csv (per amplitude: delta*, F*, E_d, A, slip share,
regime), cycles.csv (every cycle), loop_a<amplitude>um.csv (per increment: u_x, F_x,
dissipation, slipping share), a<amplitude>um/interface.xdmf (interface fields per increment,
ParaView), fretting.png, fretting_loops.png (last loop per amplitude, N and um),
fretting_map.png (A and slip share vs amplitude) and loop_largest.png (every cycle of the
largest amplitude). The library function is rough_contact.scenes.fretting.run.
"""

import argparse
import sys

import petsc4py
from _common import parse_known


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 allow_abbrev=False)
    ap.add_argument("--amplitudes", type=float, nargs="+", default=[0.5, 1.0, 4.0],
                    help="tangential displacement amplitudes [um] (default: 0.5 1 4)")
    ap.add_argument("--cycles", type=int, default=3, help="cycles per amplitude (default 3)")
    ap.add_argument("--steps-per-cycle", type=int, default=32,
                    help="increments per cycle, a multiple of 4 (default 32: with the sine wave "
                    "the increments are finest at the turning points, where slip starts)")
    ap.add_argument("--wave", default="sine", choices=["sine", "triangle"],
                    help="shape of the displacement cycle (default sine)")
    ap.add_argument("--pressure", type=float, default=10.0, help="nominal preload [MPa]")
    ap.add_argument("--mesh-size", type=float, default=0.12,
                    help="element size [mm] (0.12: 16 089 DOFs at P1; 0.5: 1 290)")
    ap.add_argument("--order", type=int, default=1, choices=[1, 2])
    ap.add_argument("--outdir", default="results/fretting")
    ap.add_argument("--no-xdmf", action="store_true", help="do not write interface.xdmf")
    ap.add_argument("--verbose", action="store_true", help="one line per increment")
    ck = ap.add_mutually_exclusive_group()
    ck.add_argument("--checkpoint", default=None, metavar="CKDIR",
                    help="write a checkpoint after every converged increment into CKDIR")
    ck.add_argument("--restart", default=None, metavar="CKDIR",
                    help="continue a stopped run (same options and ranks) from CKDIR: finished "
                    "amplitudes are read back, the interrupted one continues")
    args, rest = parse_known(ap, sys.argv[1:] if argv is None else argv)
    # PETSc options (one dash, prefix fret_) must reach PETSc before dolfinx is imported.
    # Default linear solver: mumps_lagged (see the help text; docs/loading.md).
    if not any(a.startswith("-fret_linear_solver") for a in rest):
        rest += ["-fret_linear_solver", "mumps_lagged"]
    petsc4py.init([sys.argv[0]] + rest)
    from rough_contact.scenes import fretting
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    fretting.run(args.amplitudes, outdir=args.outdir, cycles=args.cycles,
                 steps_per_cycle=args.steps_per_cycle, wave=args.wave, pressure=args.pressure,
                 mesh_size=args.mesh_size, order=args.order, checkpoint=args.checkpoint,
                 restart=args.restart, xdmf=not args.no_xdmf, overwrite=True,
                 verbose=args.verbose)


if __name__ == "__main__":
    main()
