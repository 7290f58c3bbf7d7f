"""The rough law's friction with exact stick on the flat punch (issue 22): the same scene with
the paper's tangential micro-compliance (``Penalty()``) and with rigid stick
(``AugmentedLagrangian`` / ``NewtonAugmentedLagrangian`` with ``stiffness_factor``).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_rough_exact_stick.py
        [--routes penalty newton uzawa] [--factor 10] [--tol 1e-6] [--steps 8]

Quarter punch of the library (``flat_punch.build``: P2, 20 / 2 mm, Table 1's surface, the
elastic asperity law), nodal points on the dual basis, ``steps`` loading and ``steps - 1``
unloading increments to 1/steps of the load. Per route: DOFs, Newton iterations, the
dissipation at the peak and at the end, the vertices slipping at the peak, the largest elastic
slip |s - s_p| of the sticking vertices at the peak, CPU time (rank 0). Units: mm, N, s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.interface.enforcement import (AugmentedLagrangian, NewtonAugmentedLagrangian,
                                                 Penalty)
from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import load_path, load_unload_factors


def run(route: str, factor: float, tol: float, steps: int) -> dict:
    enforcement = {"penalty": lambda: Penalty(),
                   "newton": lambda: NewtonAugmentedLagrangian(tol, 60, stiffness_factor=factor),
                   "uzawa": lambda: AugmentedLagrangian(tol, 60, stiffness_factor=factor)}[route]()
    c0 = time.process_time()
    m = flat_punch.build(MPI.COMM_WORLD, normal_law="elastic", points="nodal", basis="dual",
                         enforcement=enforcement, steps=steps)
    comm = m.problem.mesh.comm
    out = dict(route=route, dofs=m.problem.num_dofs, newton=0)
    for inc in load_path(m.problem, m.solver, load_unload_factors(steps, steps - 1,
                                                                  final_factor=1 / steps),
                         verbose=False):
        out["newton"] += inc.newton_total
        if abs(inc.load_factor - 1.0) < 1e-12:
            pf = m.interface.point_fields()
            stick = pf.contact & ~pf.slipping
            e = np.linalg.norm(pf.slip - pf.plastic_slip, axis=1)
            out["D_peak"] = inc.dissipation
            out["slip"] = comm.allreduce(int(pf.slipping.sum()), op=MPI.SUM)
            out["points"] = comm.allreduce(int(pf.slipping.size), op=MPI.SUM)
            out["e_stick"] = comm.allreduce(float(e[stick].max(initial=0.0)), op=MPI.MAX)
    out["D_end"] = inc.dissipation
    out["cpu"] = time.process_time() - c0
    m.solver.destroy()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--routes", nargs="+", default=["penalty", "newton", "uzawa"],
                    choices=["penalty", "newton", "uzawa"])
    ap.add_argument("--factor", type=float, default=10.0, help="enforcement stiffness_factor")
    ap.add_argument("--tol", type=float, default=1e-6, help="augmentation tolerance")
    ap.add_argument("--steps", type=int, default=8)
    args = ap.parse_args(argv)
    if args.steps < 2:
        ap.error(f"--steps {args.steps} is invalid: it must be >= 2")
    PETSc.Sys.Print(f"{'route':>8} {'DOFs':>6} {'Newton':>6} {'D peak':>11} {'D end':>11} "
                    f"{'slip/pts':>8} {'|s-s_p| stick':>13} {'CPU s':>6}")
    for route in args.routes:
        r = run(route, args.factor, args.tol, args.steps)
        PETSc.Sys.Print(f"{r['route']:>8} {r['dofs']:6d} {r['newton']:6d} {r['D_peak']:11.4e} "
                        f"{r['D_end']:11.4e} {r['slip']:>3d}/{r['points']:<4d} "
                        f"{r['e_stick']:13.2e} {r['cpu']:6.1f}")


if __name__ == "__main__":
    main()
