"""Benchmark: the linear solver option sets on the P2 flat punch, cost per Newton iteration.

For each mesh size and each option set of ``rough_contact.solver.snes.LINEAR_SOLVERS`` the
quarter punch (rough law, elastic asperities, friction case b) is loaded to 1000 N in
``--steps`` increments (the last one slips at the punch edge). One table row per Newton
iteration:

    asm bulk   copy of the cached stiffness + the K x products of the residuals [s]
    asm intf   interface law + element matrices/vectors + insertion [s]
    PC set-up  PETSc event PCSetUp (factorisation / AMG hierarchy) [s]
    solve      PETSc event KSPSolve (Krylov iterations + preconditioner applications) [s]
    wall       wall time of the whole iteration [s]
    CPU        CPU time of the whole iteration, summed over ranks [s] (on a shared machine
               the fair figure: wall times grow when other jobs take the cores)
    lin its    Krylov iterations (1 for LU)
    |F|        residual norm after the iteration [N]
    RSS        resident memory now / peak (VmHWM) of the process, summed over ranks [MB]

then a summary per (size, set): Newton and linear iterations, wall and CPU time (summed over
ranks) per Newton iteration. Wall times are the maximum over ranks; the PETSc event times
(PC set-up, solve) are wall times.

Peak memory is per process and never goes down: for a clean memory figure run ONE size and
ONE set per invocation (that is how docs/solver.md quotes them). Examples:

    python3 benchmarks/bench_solver.py --sizes medium --sets mumps gamg hypre
    mpirun -n 2 python3 benchmarks/bench_solver.py --sizes large --sets hypre
    python3 benchmarks/bench_solver.py --sizes medium --sets gamg -rc_ksp_rtol 1e-10

Sizes (quarter punch, tetrahedra, P2 unless noted):
    small   P1, mesh 10 mm, contact 1.0 mm      (~3 k DOFs)
    medium  P2, mesh 5 mm, contact 0.5 mm       (~88 k DOFs)
    large   P2, mesh 3.5 mm, contact 0.35 mm    (~228 k DOFs)
    huge    P2, mesh 2.1 mm, contact 0.21 mm    (~1 M DOFs; see docs/solver.md for memory)
Custom: --custom MESH,CONTACT,ORDER[,tet|hex] (repeatable; hex: hexahedra, Q1/Q2). Options
-rc_* apply to every run (they are copied to each run's own prefix). Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import logging
import resource
import sys
import time


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--sizes", nargs="*", default=["small"],
                        choices=["small", "medium", "large", "huge"])
    parser.add_argument("--custom", action="append", default=[],
                        help="MESH,CONTACT,ORDER[,tet|hex], e.g. 5,0.5,2 or 5,0.5,1,hex")
    parser.add_argument("--sets", nargs="+", default=["mumps", "gamg", "hypre"],
                        help="option sets of LINEAR_SOLVERS (mumps, gamg, hypre, krylov)")
    parser.add_argument("--steps", type=int, default=2,
                        help="load increments to 1000 N (run: all of them)")
    parser.add_argument("--increments", type=int, default=None,
                        help="stop after this many increments (default: all --steps)")
    parser.add_argument("--near-nullspace", default="global", choices=["global", "per_body"])
    parser.add_argument("--quiet", action="store_true", help="summary only, no per-iteration rows")
    return parser.parse_known_args(argv)


import petsc4py  # noqa: E402

if __name__ == "__main__":
    ARGS, PETSC_ARGS = parse_args(sys.argv[1:])
    petsc4py.init([sys.argv[0]] + PETSC_ARGS)

from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.scenes import flat_punch as punch  # noqa: E402
from rough_contact.solver.loading import load_path  # noqa: E402

logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

SIZES = {"small": (10.0, 1.0, 1), "medium": (5.0, 0.5, 2), "large": (3.5, 0.35, 2),
         "huge": (2.1, 0.21, 2)}


def memory_mb():
    """(current RSS, peak RSS) of this process [MB] from /proc/self/status."""
    now = peak = float("nan")
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    now = int(line.split()[1]) / 1024.0
                elif line.startswith("VmHWM:"):
                    peak = int(line.split()[1]) / 1024.0
    except OSError:  # not Linux: the peak from getrusage (kB on Linux, bytes on macOS)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return now, peak


class IterationLog:
    """SNES monitor recording the cost of every Newton iteration (collective)."""

    def __init__(self, comm, problem, snes):
        self.comm, self.problem, self.snes = comm, problem, snes
        self.ksp_event = PETSc.Log.Event("KSPSolve")
        self.pc_event = PETSc.Log.Event("PCSetUp")
        self.rows = []
        self.increment = 0
        self._last = self._snapshot()

    def _snapshot(self):
        tm = self.problem.timings
        return dict(bulk=tm["bulk"],
                    intf=tm["interface_residual"] + tm["interface_jacobian"],
                    ksp=self.ksp_event.getPerfInfo()["time"],
                    pc=self.pc_event.getPerfInfo()["time"],
                    cpu=time.process_time(), wall=MPI.Wtime())

    def __call__(self, snes, its, norm):
        now = self._snapshot()
        if its == 0:  # start of a solve (also a retried one): no linear solve yet
            self._last = now
            self.lin0 = 0
            return
        d = {k: now[k] - self._last[k] for k in now}
        self._last = now
        lin = snes.getLinearSolveIterations()
        mem_now, mem_peak = memory_mb()
        c = self.comm
        row = dict(increment=self.increment, it=its,
                   bulk=c.allreduce(d["bulk"], op=MPI.MAX),
                   intf=c.allreduce(d["intf"], op=MPI.MAX),
                   pc=c.allreduce(d["pc"], op=MPI.MAX),
                   # KSPSetUp (and the PCSetUp in it) is logged outside KSPSolve
                   solve=c.allreduce(d["ksp"], op=MPI.MAX),
                   cpu=c.allreduce(d["cpu"], op=MPI.SUM),
                   wall=c.allreduce(d["wall"], op=MPI.MAX),
                   lin=lin - self.lin0, norm=float(norm),
                   rss=c.allreduce(mem_now, op=MPI.SUM), peak=c.allreduce(mem_peak, op=MPI.SUM))
        self.lin0 = lin
        self.rows.append(row)


def bench_one(comm, punch_scene, option_set, steps, increments, near_nullspace, prefix,
              quiet):
    # Options given with -rc_ apply to every run: copy them to this run's prefix.
    opts = PETSc.Options()
    for key, value in opts.getAll().items():
        if key.startswith("rc_"):
            opts.setValue(prefix + key[3:], value)
    m = punch.build(comm=comm, punch_scene=punch_scene, steps=steps, case="b",
                    normal_law="elastic", prefix=prefix,
                    solver_options=dict(linear_solver=option_set, near_nullspace=near_nullspace))
    problem, solver = m.problem, m.solver
    problem.reset_timings()
    log = IterationLog(comm, problem, solver.snes)
    solver.snes.setMonitor(log)
    factors = [(i + 1) / steps for i in range(steps)][:increments]
    t0, c0 = MPI.Wtime(), time.process_time()
    incs = []
    for inc in load_path(problem, solver, factors, verbose=False):
        incs.append(inc)
        log.increment = len(incs)
    wall = MPI.Wtime() - t0
    cpu = comm.allreduce(time.process_time() - c0, op=MPI.SUM)
    if not quiet:
        for r in log.rows:
            PETSc.Sys.Print(
                f"{option_set:>7} {r['increment'] + 1:>4d} {r['it']:>3d} {r['bulk']:9.3f} "
                f"{r['intf']:9.3f} {r['pc']:9.2f} {r['solve']:8.2f} {r['wall']:8.2f} {r['cpu']:8.2f} "
                f"{r['lin']:7d} "
                f"{r['norm']:10.3e} {r['rss']:8.0f} {r['peak']:8.0f}", comm=comm)
    n_newton = sum(i.iterations for i in incs)
    summary = dict(set=option_set, solver=solver.linear_solver, dofs=problem.num_dofs,
                   newton=[i.iterations for i in incs],
                   linear=sum(r["lin"] for r in log.rows),
                   wall_it=wall / max(n_newton, 1), cpu_it=cpu / max(n_newton, 1),
                   pc_it=sum(r["pc"] for r in log.rows) / max(n_newton, 1),
                   solve_it=sum(r["solve"] for r in log.rows) / max(n_newton, 1),
                   peak=max((r["peak"] for r in log.rows), default=float("nan")),
                   fz=incs[-1].contact_force[2] if incs else float("nan"))
    solver.destroy()
    return summary


def main(sizes=("small",), custom=(), sets=("mumps", "gamg", "hypre"), steps=2, increments=None,
         near_nullspace="global", quiet=False, comm=MPI.COMM_WORLD):
    PETSc.Log.begin()  # needed for the KSPSolve / PCSetUp event times
    configs = [(name, *SIZES[name]) for name in sizes]
    configs = [c + ("tetrahedron",) for c in configs]
    for spec in custom:
        fields = spec.split(",")
        ms, cs, order = fields[:3]
        cell = {"tet": "tetrahedron", "hex": "hexahedron"}[fields[3] if len(fields) > 3
                                                           else "tet"]
        configs.append((spec, float(ms), float(cs), int(order), cell))
    summaries = []
    for name, ms, cs, order, cell in configs:
        t0 = MPI.Wtime()
        scene = punch.quarter_punch(comm, mesh_size=ms, contact_size=cs, order=order,
                                    cell_type=cell)
        n = scene.V.dofmap.index_map.size_global * 3
        element = ("Q" if cell == "hexahedron" else "P") + str(order)
        PETSc.Sys.Print(f"\nflat punch {name} (mesh {ms} mm, contact {cs} mm, {element}): "
                        f"{n} DOFs, "
                        f"{comm.size} rank(s), {steps} increments to 1000 N; mesh "
                        f"{MPI.Wtime() - t0:.1f} s; times per Newton iteration [s] (max over "
                        "ranks), memory summed over ranks [MB]", comm=comm)
        if not quiet:
            PETSc.Sys.Print(f"{'set':>7} {'inc':>4} {'it':>3} {'asm bulk':>9} {'asm intf':>9} "
                            f"{'PC set-up':>9} {'solve':>8} {'wall':>8} {'CPU':>8} {'lin its':>7} {'|F| [N]':>10} "
                            f"{'RSS':>8} {'peak RSS':>8}", comm=comm)
        for k, option_set in enumerate(sets):
            s = bench_one(comm, scene, option_set, steps, increments, near_nullspace,
                          f"bs{len(summaries)}_", quiet)
            s["size"] = name
            summaries.append(s)
    PETSc.Sys.Print(f"\nsummary ({comm.size} rank(s); per Newton iteration: wall [s], CPU summed "
                    "over ranks [s], PC set-up and solve [s]; peak RSS summed over ranks [MB])",
                    comm=comm)
    PETSc.Sys.Print(f"{'size':>8} {'DOFs':>8} {'set':>7} {'Newton its':>12} {'lin its':>7} "
                    f"{'wall/it':>8} {'CPU/it':>8} {'PC/it':>7} {'solve/it':>8} {'peak':>7} "
                    f"{'Fz [N]':>19}  solver", comm=comm)
    for s in summaries:
        PETSc.Sys.Print(
            f"{s['size']:>8} {s['dofs']:>8d} {s['set']:>7} "
            f"{','.join(str(k) for k in s['newton']):>12} {s['linear']:>7d} {s['wall_it']:8.2f} "
            f"{s['cpu_it']:8.2f} {s['pc_it']:7.2f} {s['solve_it']:8.2f} {s['peak']:7.0f} "
            f"{s['fz']:19.12e}  {s['solver']}", comm=comm)
    return summaries


if __name__ == "__main__":
    main(ARGS.sizes, ARGS.custom, ARGS.sets, ARGS.steps, ARGS.increments, ARGS.near_nullspace,
         ARGS.quiet)
