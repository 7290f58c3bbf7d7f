"""Benchmark: the flat punch (paper section 9.2) at several mesh sizes, Newton cost split.

Prints, per mesh: DOFs, interface points, Newton iterations per increment, and the time per
Newton iteration split into bulk (copy of the cached stiffness + matrix-vector products),
interface (law kernel + element vectors/matrices + insertion), and linear solve (PETSc's
KSPSolve + PCSetUp events; PCSetUp, the factorisation / multigrid set-up, is also shown alone).
Set-up (mesh, interface pairing, one bulk assembly) is reported separately.

Run serial and on 2 ranks:

    python3 benchmarks/bench_contact_solve.py --sizes small medium
    mpirun -n 2 python3 benchmarks/bench_contact_solve.py --sizes small medium large

Sizes (quarter punch, tetrahedra; the linear solver is the SNESSolver default, MUMPS LU up to
30 k DOFs and hypre-preconditioned GMRES above; change with -rc_linear_solver, --dof-threshold
and single -rc_ options, docs/solver.md; benchmarks/bench_solver.py compares the sets):
    small   P1, mesh 10 mm, contact 1.0 mm     (~3k DOFs)
    medium  P2, mesh 5 mm,  contact 0.5 mm     (~88k DOFs)
    large   P2, mesh 3.5 mm, contact 0.35 mm   (>200k DOFs)
Custom: --custom MESH,CONTACT,ORDER (repeatable).  Units: mm, N, MPa; times in s.
"""

from __future__ import annotations

import argparse
import logging
import sys


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--sizes", nargs="+", default=["small", "medium"],
                        choices=["small", "medium", "large"])
    parser.add_argument("--custom", action="append", default=[],
                        help="MESH,CONTACT,ORDER, e.g. 5,0.5,2")
    parser.add_argument("--steps", type=int, default=2,
                        help="load increments to 1000 N (the last one slips at the edge)")
    parser.add_argument("--case", default="b", choices=["a", "b", "c", "none"])
    parser.add_argument("--dof-threshold", type=int, default=None)
    return parser.parse_known_args(argv)


import petsc4py  # noqa: E402

if __name__ == "__main__":
    ARGS, PETSC_ARGS = parse_args(sys.argv[1:])
    petsc4py.init([sys.argv[0]] + PETSC_ARGS)

from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.scenes import flat_punch as demo  # noqa: E402

from rough_contact.solver.loading import load_path  # noqa: E402

logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

SIZES = {"small": (10.0, 1.0, 1), "medium": (5.0, 0.5, 2), "large": (3.5, 0.35, 2)}


def bench_one(comm, mesh_size, contact_size, order, steps, case, dof_threshold, prefix):
    # Each mesh gets its own prefix (the solver's defaults, which depend on the size, live in
    # the options database); options given on the command line with -rc_ apply to all.
    opts = PETSc.Options()
    for key, value in opts.getAll().items():
        if key.startswith("rc_"):
            opts.setValue(prefix + key[3:], value)
    t0 = MPI.Wtime()
    m = demo.build(comm=comm, mesh_size=mesh_size, contact_size=contact_size, order=order,
                   steps=steps, case=case, prefix=prefix, dof_threshold=dof_threshold,
                   normal_law="elastic")  # table set-up ~1 s; per-iteration cost is the same
    setup = MPI.Wtime() - t0
    problem, solver = m.problem, m.solver
    problem.reset_timings()
    ksp_event, pc_event = PETSc.Log.Event("KSPSolve"), PETSc.Log.Event("PCSetUp")
    ksp0, pc0 = ksp_event.getPerfInfo()["time"], pc_event.getPerfInfo()["time"]
    t1 = MPI.Wtime()
    its = []
    factors = [(i + 1) / steps for i in range(steps)]
    for inc in load_path(problem, solver, factors, verbose=False):
        its.append(inc.iterations)
    solve = MPI.Wtime() - t1
    n_it = max(sum(its), 1)
    ksp = comm.allreduce(ksp_event.getPerfInfo()["time"] - ksp0, op=MPI.MAX)
    pcs = comm.allreduce(pc_event.getPerfInfo()["time"] - pc0, op=MPI.MAX)
    tm = {k: comm.allreduce(v, op=MPI.MAX) for k, v in problem.timings.items()}
    row = dict(dofs=problem.num_dofs, points=m.interface.n_points_global, its=its,
               setup=setup, bulk_setup=problem.setup_time, total=solve,
               bulk=tm["bulk"] / n_it,
               interface=(tm["interface_residual"] + tm["interface_jacobian"]) / n_it,
               linear=(ksp + pcs) / n_it, pcsetup=pcs / n_it, solver=solver.linear_solver,
               slipping=inc.n_slipping)
    solver.destroy()
    return row


def main(sizes=("small", "medium"), custom=(), steps=2, case="b", dof_threshold=None,
         comm=MPI.COMM_WORLD):
    PETSc.Log.begin()  # needed for the KSPSolve / PCSetUp event times
    configs = [(name, *SIZES[name]) for name in sizes]
    for spec in custom:
        ms, cs, order = spec.split(",")
        configs.append((spec, float(ms), float(cs), int(order)))
    PETSc.Sys.Print(f"flat punch, {comm.size} rank(s), {steps} increments to 1000 N, friction "
                    f"case {case}; times in s (max over ranks), per Newton iteration unless "
                    "noted", comm=comm)
    head = (f"{'size':>8} {'P':>2} {'DOFs':>8} {'points':>7} {'Newton its/inc':>15} "
            f"{'set-up':>7} {'K asm':>6} {'bulk/it':>8} {'intf/it':>8} {'solve/it':>9} "
            f"{'(PCSetUp)':>9} {'total':>7}  solver")
    PETSc.Sys.Print(head, comm=comm)
    rows = []
    for i, (name, ms, cs, order) in enumerate(configs):
        r = bench_one(comm, ms, cs, order, steps, case, dof_threshold, prefix=f"bench{i}_")
        rows.append((name, order, r))
        PETSc.Sys.Print(
            f"{name:>8} {order:>2} {r['dofs']:>8d} {r['points']:>7d} "
            f"{','.join(str(k) for k in r['its']):>15} {r['setup']:7.2f} {r['bulk_setup']:6.2f} "
            f"{r['bulk']:8.4f} {r['interface']:8.4f} {r['linear']:9.3f} {r['pcsetup']:9.3f} "
            f"{r['total']:7.2f}  {r['solver']}", comm=comm)
    return rows


if __name__ == "__main__":
    main(ARGS.sizes, ARGS.custom, ARGS.steps, ARGS.case, ARGS.dof_threshold)
