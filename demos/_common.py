"""What the demos share: their command line (the script's options, everything else for PETSc)
and their start-up order (PETSc's options in before dolfinx is imported; an uncaught exception on
one rank aborting all of them).

The demos import it as ``_common`` (Python puts a script's own folder first on ``sys.path``).
"""

from __future__ import annotations

import sys

from rough_contact.advisor import RESULTS_ALL  # pure numpy: safe before PETSc's options

DOF_THRESHOLD_HELP = ("above this many DOFs the default linear solver is AMG-preconditioned "
                      "GMRES, else MUMPS (default: the solver's measured threshold, "
                      "docs/solver.md; -rc_linear_solver mumps|gamg|hypre picks one outright)")


def add_law_auto_arguments(parser, choices, default, rough_help, where):
    """The ``--law`` option of a scene demo (its own ``choices`` plus ``auto``: the law advisor,
    docs/advisor.md) and the advisor's ``--tolerance`` and ``--results``. ``where``: where the
    report is written (e.g. "OUTDIR/advice.txt, advice.json")."""
    parser.add_argument("--law", default=default, choices=list(choices) + ["auto"],
                        help=f"{rough_help}, or auto: the law advisor picks the cheapest normal "
                        "law within --tolerance of the full model over the run's pressures "
                        f"(report printed and written to {where}; docs/advisor.md)")
    parser.add_argument("--tolerance", type=float, default=0.05,
                        help="--law auto: accepted relative difference from the full model in "
                        "each of --results (docs/advisor.md)")
    parser.add_argument("--results", nargs="+", choices=RESULTS_ALL, default=list(RESULTS_ALL),
                        metavar="RESULT",
                        help="--law auto: the FE results held within --tolerance, any of "
                        f"{', '.join(RESULTS_ALL)} (default: all; force ~ the stiffness k at "
                        "equal pressure, area ~ A/A0, approach ~ the interface approach, "
                        "dissipation ~ the frictional dissipation, estimated from k)")


def law_auto_options(args) -> dict:
    """The advisor's keyword arguments of the scene's ``run`` from the parsed options."""
    return {"tolerance": args.tolerance, "advise_results": tuple(args.results)}


def parse_known(parser, argv):
    """``(options, rest)``: the script's options and what ``parser`` does not know, for PETSc.
    PETSc options have one dash; a double-dash leftover is a mistyped option of the script."""
    args, rest = parser.parse_known_args(argv)
    bad = [a for a in rest if a.startswith("--")]
    if bad:
        parser.error(f"unrecognized arguments: {' '.join(bad)}")
    return args, rest


def start(parse_args):
    """Parse ``sys.argv`` with ``parse_args(argv) -> (options, petsc_options)``, hand the PETSc
    options to PETSc (before dolfinx is imported: import the library after this), and make an
    uncaught exception on one rank abort all ranks. Returns the script's options."""
    import petsc4py

    args, petsc_args = parse_args(sys.argv[1:])
    petsc4py.init([sys.argv[0]] + petsc_args)
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    return args
