"""Large sliding: what the pairing costs within an increment.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_sliding.py [--points 10000 50000]
        [--slides 1]

Two blocks 1 x 1 mm meshed independently with Q1 hexahedra, two element layers each, equal
element sizes (the projection pairing, which sliding needs, also on equal meshes), 4 points per
first facet: the upper block pressed with 80 MPa (one increment), then its top moved 2
element lengths along x in one increment (``--slides N``: N such increments, the table is
the last) with ``sliding="large"`` (Coulomb penalty mu = 0.3).
Table per size: interface points, DOFs, Newton iterations and re-pairings of the slide
increment (fixed-point iterations, the last one the check that found the pairing converged),
its wall time, the time of the pairing in it (projections on the deformed surfaces, new jump
operators and scatters) and of the matrix rebuilds the new partners needed (new pattern, bulk
values: assembled once more at a run's first rebuild and kept, copied at the later ones), and
their shares of the increment. Units: mm, N, MPa, s. Serial or under mpirun.
"""

from __future__ import annotations

import argparse

from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.boundary import fix
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import separate_blocks
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import LoadProgram
from rough_contact.solver.snes import SNESSolver

E, NU, P = 2.0e5, 0.25, 80.0


def _roller(V, scene, name, comp):
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, scene.facet_tags.find(scene.tag(name)))
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


def run(n_target: int, slides: int = 1) -> tuple:
    n = int(round((n_target / 4.0) ** 0.5))          # elements per side
    h = 1.0 / n
    scene = separate_blocks(h1=2 * h, h2=2 * h, size_lower=h, size_upper=h,
                            cell_type="hexahedron")
    V = compat.vector_space(scene.mesh, 1)
    bcs = [_roller(V, scene, "y0", 1), fix(V, scene.facet_tags, scene.tag("bottom"))]
    law = SoftplusPenalty(1e6, 1e-6, k_tangential=1e6, friction=0.3)
    upper, lower = scene.contact_pair
    ci = ContactInterface(V, scene.facet_tags, upper, lower, law=law, bcs=bcs,
                          pairing="projection", sliding="large")
    timer = {"pairing": 0.0, "rebuild": 0.0}
    install, repair = ci._install, ci._repair

    def timed(f, key):
        def g(*a):
            t0 = MPI.Wtime()
            out = f(*a)
            timer[key] += MPI.Wtime() - t0
            return out
        return g

    ci._install, ci._repair = timed(install, "pairing"), timed(repair, "pairing")
    prog = LoadProgram({"press": lambda t: min(t, 1.0),
                        "slide": lambda t: max(t - 1.0, 0.0)},
                       [1.0 + j for j in range(slides + 1)])
    problem = ContactProblem(
        V, {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(E, NU)},
        bcs, [SurfaceLoad(scene.tag("top"), traction=[0, 0, -P],
                                         channel="press")],
        cell_tags=scene.cell_tags, facet_tags=scene.facet_tags, interface=ci,
        prescribed=[PrescribedDisplacement(scene.tag("top"), (2 * h, 0.0, 0.0), (0,),
                                           channel="slide")], programs=prog.channels)
    rebuild = problem.rebuild_matrices
    problem.rebuild_matrices = timed(rebuild, "rebuild")
    solver = SNESSolver(problem, prefix="bench_sliding_")
    incs = []
    for inc in load_path(problem, solver, prog.times, verbose=False, friction_check=False):
        incs.append((inc, timer["pairing"], timer["rebuild"], ci.n_fixed_point))
        timer["pairing"] = timer["rebuild"] = 0.0
    inc, t_pair, t_rebuild, n_fp = incs[-1]
    n_fp -= incs[0][3]
    solver.destroy()
    return (n_target, ci.n_points_global, problem.num_dofs, inc.iterations, n_fp,
            inc.wall_time, t_pair, t_rebuild)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, nargs="+", default=[10000, 50000])
    ap.add_argument("--slides", type=int, default=1,
                    help="slide increments of 2 element lengths each; the table is the last "
                    "one (from the second on, a rebuild copies the kept bulk matrix)")
    args = ap.parse_args(argv)
    if args.slides < 1:
        ap.error(f"--slides {args.slides} is invalid: it must be >= 1")
    PETSc.Sys.Print(f"large sliding, slide increment ({MPI.COMM_WORLD.size} rank(s))")
    PETSc.Sys.Print(f"{'target':>7} {'points':>8} {'DOFs':>8} {'Newton':>6} {'re-pairs':>8} "
                    f"{'increment s':>11} {'pairing s':>9} {'share':>6} {'rebuild s':>9} "
                    f"{'share':>6}")
    for n in args.points:
        row = run(n, args.slides)
        PETSc.Sys.Print(f"{row[0]:7d} {row[1]:8d} {row[2]:8d} {row[3]:6d} {row[4]:8d} "
                        f"{row[5]:11.2f} {row[6]:9.2f} {100 * row[6] / row[5]:5.1f}% "
                        f"{row[7]:9.2f} {100 * row[7] / row[5]:5.1f}%")


if __name__ == "__main__":
    main()
