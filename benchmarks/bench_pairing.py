"""Non-matching interfaces: patch-test accuracy of the pairings, and their cost at scale.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_pairing.py
        [--part accuracy|points|cost|all]
        [--points 10000 50000 200000] [--pairings conforming projection mortar moderate]
    ... --part newton [--points 10000 50000]  (also under mpirun -n 2)

Part "accuracy": two blocks meshed independently (``separate_blocks``), uniform pressure
p = 80 MPa on top, bilateral linear penalty 1e6 MPa/mm, lower block E/2: largest pointwise
|p - 80| / 80 at the interface points with weight > 0, for the Gauss-point projection
(``pairing="projection"``, facet rule of degree 2 x order, and a richer rule) and the
segment-to-segment integration (``pairing="mortar"``, triangle rule of degree 2 x order on the
pieces).

Part "points": the interface points of the accuracy part's meshes (set-up only): the Gauss
projection's (rule of degree 2 x order), the mortar's points (pieces x triangle rule of degree
2 x order, points with weight) and its point slots (every first facet padded to the largest
count with weight-0 copies: the law is evaluated at every slot), and the ratios to the
projection's points.

Part "cost": thin hexahedral blocks (Q1, one element layer each, facet rule of degree 2: 4 points
per facet) with about N interface points; equal element sizes (the conforming pairing applies)
and sizes 5:7 (non-matching). Per pairing: set-up time of ``ContactInterface`` (pairing included),
and the time of one interface residual + Jacobian assembly (law: Coulomb penalty) next to
DOLFINx's assembly of the bulk elasticity Jacobian of the same mesh — a Newton iteration costs at
least the bulk assembly plus a linear solve, so the ratio is an upper bound of the interface's
share. "moderate" is the projection with ``sliding="moderate"``: its last column is the time of
one re-pairing (``begin_increment`` of a sliding pairing: projection on the deformed surfaces,
new operator and scatter), paid once
per increment. Serial. Units: mm, N, MPa, s.

Part "newton": the interface's share of complete Newton iterations (residual and Jacobian
assembly of the interface against the wall time of the whole solve: bulk copy, interface,
linear solves) on blocks 1 x 1 x 0.25 mm of Q1 hexahedra (two layers each at equal sizes),
80 MPa on top, Coulomb penalty mu = 0.3, one load step from rest with the default solver; and
for "moderate" the time of one re-pairing after it.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.scenes.meshes.blocks import separate_blocks
from rough_contact.solver.snes import SNESSolver

E, NU, P = 2.0e5, 0.25, 80.0


def _roller(V, scene, name, comp):
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, scene.facet_tags.find(scene.tag(name)))
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


def patch_error(cell_type, order, size_lower, size_upper, first, pairing, degree):
    scene = separate_blocks(h1=1.0, h2=0.5, size_lower=size_lower, size_upper=size_upper,
                            order=order, cell_type=cell_type)
    V = compat.vector_space(scene.mesh, order)
    bcs = [_roller(V, scene, "x0", 0), _roller(V, scene, "y0", 1),
           _roller(V, scene, "bottom", 2)]
    a, b = scene.contact_pair if first == "upper" else scene.contact_pair[::-1]
    ci = ContactInterface(V, scene.facet_tags, a, b, law=LinearPenalty(1e6), bcs=bcs,
                          quadrature_degree=degree, pairing=pairing)
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(0.5 * E, NU)}
    problem = ContactProblem(V, mats, bcs, [SurfaceLoad(scene.tag("top"), traction=[0, 0, -P])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="bench_pairing_")
    problem.set_load_factor(1.0)
    solver.solve()
    ci.evaluate(problem.u)
    pf = ci.point_fields()
    real = pf.weight > 0
    err = MPI.COMM_WORLD.allreduce(float(np.abs(pf.pressure[real] - P).max(initial=0.0)),
                                   op=MPI.MAX) / P
    n = MPI.COMM_WORLD.allreduce(int(real.sum()), op=MPI.SUM)
    solver.destroy()
    return err, n


def points():
    cases = [("tetrahedron", 1, 0.2, 0.28, "upper"), ("tetrahedron", 2, 0.2, 0.28, "upper"),
             ("tetrahedron", 1, 0.3, 0.1, "lower"), ("tetrahedron", 1, 0.1, 0.3, "lower"),
             ("hexahedron", 1, 1 / 5, 1 / 7, "upper"), ("hexahedron", 2, 1 / 5, 1 / 7, "upper"),
             ("hexahedron", 1, 1 / 3, 1 / 9, "upper"), ("hexahedron", 1, 1 / 3, 1 / 9, "lower")]
    PETSc.Sys.Print("interface points: Gauss projection (degree 2k) and mortar (degree 2k)")
    PETSc.Sys.Print(f"{'cells':>5} {'P':>2} {'h_low':>6} {'h_up':>6} {'first':>6} "
                    f"{'proj pts':>9} {'mortar pts':>10} {'slots':>7} {'pts/proj':>8} "
                    f"{'slots/proj':>10}")
    law = LinearPenalty(1e6)
    for ct, order, hl, hu, first in cases:
        scene = separate_blocks(h1=1.0, h2=0.5, size_lower=hl, size_upper=hu, order=order,
                                cell_type=ct)
        V = compat.vector_space(scene.mesh, order)
        a, b = scene.contact_pair if first == "upper" else scene.contact_pair[::-1]
        proj, mortar = (ContactInterface(V, scene.facet_tags, a, b, law=law,
                                         quadrature_degree=2 * order, pairing=p)
                        for p in ("projection", "mortar"))
        n_p, n_m, n_s = proj.n_points_global, mortar.n_points_global, mortar.n_slots_global
        PETSc.Sys.Print(f"{ct[:5]:>5} {order:2d} {hl:6.3f} {hu:6.3f} {first:>6} {n_p:9d} "
                        f"{n_m:10d} {n_s:7d} {n_m / n_p:8.1f} {n_s / n_p:10.1f}")


def accuracy():
    cases = [("tetrahedron", 1, 0.2, 0.28, "upper"), ("tetrahedron", 2, 0.2, 0.28, "upper"),
             ("tetrahedron", 1, 0.3, 0.1, "lower"), ("tetrahedron", 1, 0.1, 0.3, "lower"),
             ("hexahedron", 1, 1 / 5, 1 / 7, "upper"), ("hexahedron", 2, 1 / 5, 1 / 7, "upper"),
             ("hexahedron", 1, 1 / 3, 1 / 9, "upper"), ("hexahedron", 1, 1 / 3, 1 / 9, "lower")]
    PETSc.Sys.Print("patch test: max |p - p_applied| / p_applied at the interface points")
    PETSc.Sys.Print(f"{'cells':>5} {'P':>2} {'h_low':>6} {'h_up':>6} {'first':>6} "
                    f"{'Gauss 2k':>10} {'pts':>6} {'Gauss 4k+2':>10} {'pts':>6} "
                    f"{'mortar 2k':>10} {'pts':>6}")
    for ct, order, hl, hu, first in cases:
        row = [patch_error(ct, order, hl, hu, first, "projection", 2 * order),
               patch_error(ct, order, hl, hu, first, "projection", 4 * order + 2),
               patch_error(ct, order, hl, hu, first, "mortar", 2 * order)]
        PETSc.Sys.Print(f"{ct[:5]:>5} {order:2d} {hl:6.3f} {hu:6.3f} {first:>6} " + " ".join(
            f"{e:10.2e} {n:6d}" for e, n in row))


def _meshes(points):
    """(target points, label, elements per side of the lower and of the upper block) of the
    cost and Newton tables: equal meshes, and 5:7."""
    for n_target in points:
        n_side = int(round(np.sqrt(n_target / 4.0)))
        for label, n_up in (("equal", n_side), ("5:7", int(round(n_side * 7 / 5)))):
            yield n_target, label, n_side, n_up


def _coulomb_interface(V, scene, pairing, bcs=()):
    """The rough-free Coulomb penalty interface of the tables; ``pairing`` "moderate" is the
    projection pairing with ``sliding="moderate"`` (re-paired on the deformed surfaces)."""
    law = SoftplusPenalty(1e6, 1e-6, k_tangential=1e6, friction=0.3)
    return ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                            pairing="projection" if pairing == "moderate" else pairing,
                            sliding="moderate" if pairing == "moderate" else "small")


def cost(points, only=None):
    PETSc.Sys.Print("\ncost (serial, Q1 hexahedra, 4 points per first facet, Coulomb penalty)")
    PETSc.Sys.Print(f"{'target':>7} {'meshes':>9} {'pairing':>10} {'points':>8} {'groups':>7} "
                    f"{'set-up s':>8} {'R+J s':>7} {'bulk J s':>8} {'R+J/bulk':>8} "
                    f"{'re-pair s':>9}")
    for n_target, label, n_side, n_up in _meshes(points):
        scene = separate_blocks(h1=1.0 / n_side, h2=1.0 / n_side, size_lower=1.0 / n_side,
                                size_upper=1.0 / n_up, cell_type="hexahedron")
        V = compat.vector_space(scene.mesh, 1)
        u = fem.Function(V)
        u.interpolate(lambda x: 1e-4 * np.stack([np.sin(x[0]), np.cos(x[1]), x[2] - 0.5]))
        du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        eps = ufl.sym(ufl.grad(du))
        lmbda, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
        a = fem.form(ufl.inner(2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(3),
                               ufl.sym(ufl.grad(v))) * ufl.dx)
        pairings = ["conforming", "projection", "mortar", "moderate"] if label == "equal" \
            else ["projection", "mortar", "moderate"]
        for pairing in [p for p in pairings if only is None or p in only]:
            t0 = time.perf_counter()
            ci = _coulomb_interface(V, scene, pairing)
            t_setup = time.perf_counter() - t0
            A = ci.create_matrix(a)
            b = compat.create_petsc_vector(V)
            t0 = time.perf_counter()
            A.zeroEntries()
            dolfinx.fem.petsc.assemble_matrix(A, a)
            t_bulk = time.perf_counter() - t0
            times = []
            for k in range(3):      # a new u each time: the law is evaluated every time
                u.x.array[:] *= 1.0 + 1e-3
                u.x.scatter_forward()
                t0 = time.perf_counter()
                b.set(0.0)
                ci.evaluate(u)
                ci.assemble_residual(b)
                ci.evaluate(u)
                ci.assemble_jacobian(A)
                times.append(time.perf_counter() - t0)
            A.assemble()
            t_if = min(times)
            t_re = float("nan")
            if pairing == "moderate":   # sliding = 'moderate': projection on the deformed
                t0 = time.perf_counter()  # surfaces, new operator and scatter
                ci.commit()       # a converged increment: the next one re-pairs
                ci.begin_increment(u)
                t_re = time.perf_counter() - t0
            PETSc.Sys.Print(f"{n_target:7d} {label:>9} {pairing:>10} {ci.n_points_global:8d} "
                            f"{ci.n_groups:7d} {t_setup:8.2f} {t_if:7.3f} {t_bulk:8.3f} "
                            f"{t_if / t_bulk:8.2f} {t_re:9.2f}")
            A.destroy()
            b.destroy()


def newton(points, only=None):
    """Interface share of real Newton iterations: two blocks 1 x 1 x 0.25 mm (Q1, 2 element
    layers each), 80 MPa on top, lower bottom on rollers, rough-free Coulomb penalty (mu = 0.3),
    solved at full load from rest with the default linear solver."""
    PETSc.Sys.Print("\nNewton iterations (Q1, 4 points per first facet, Coulomb penalty, "
                    f"{MPI.COMM_WORLD.size} rank(s))")
    PETSc.Sys.Print(f"{'target':>7} {'meshes':>6} {'pairing':>10} {'points':>8} {'DOFs':>8} "
                    f"{'Newton':>6} {'total s':>7} {'bulk s':>7} {'iface s':>7} {'share':>6} "
                    f"{'re-pair s':>9} {'solver':>14}")
    for n_target, label, n_side, n_up in _meshes(points):
        for pairing in [p for p in ("projection", "mortar", "moderate")
                        if only is None or p in only]:
            scene = separate_blocks(h1=0.25, h2=0.25, size_lower=1.0 / n_side,
                                    size_upper=1.0 / n_up, cell_type="hexahedron")
            V = compat.vector_space(scene.mesh, 1)
            bcs = [_roller(V, scene, "x0", 0), _roller(V, scene, "y0", 1),
                   _roller(V, scene, "bottom", 2)]
            ci = _coulomb_interface(V, scene, pairing, bcs)
            mats = {scene.tag("upper"): Material(E, NU),
                    scene.tag("lower"): Material(0.5 * E, NU)}
            problem = ContactProblem(V, mats, bcs, [SurfaceLoad(scene.tag("top"),
                                                                traction=[0, 0, -P])],
                                     cell_tags=scene.cell_tags,
                                     facet_tags=scene.facet_tags, interface=ci)
            solver = SNESSolver(problem, prefix="bench_newton_")
            problem.set_load_factor(1.0)
            problem.reset_timings()
            t0 = MPI.Wtime()
            result = solver.solve()
            total = MPI.Wtime() - t0
            t = problem.timings
            iface = t["interface_residual"] + t["interface_jacobian"]
            t_re = float("nan")
            if pairing == "moderate":
                t0 = MPI.Wtime()
                ci.commit()
                problem.begin_increment()
                t_re = MPI.Wtime() - t0
            PETSc.Sys.Print(f"{n_target:7d} {label:>6} {pairing:>10} "
                            f"{ci.n_points_global:8d} {problem.num_dofs:8d} "
                            f"{result.iterations:6d} {total:7.2f} {t['bulk']:7.2f} "
                            f"{iface:7.2f} {iface / total:6.1%} {t_re:9.2f} "
                            f"{solver.linear_solver:>14}")
            solver.destroy()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=["accuracy", "points", "cost", "newton", "all"],
                    default="all")
    ap.add_argument("--points", type=int, nargs="+", default=[10000, 50000, 200000])
    ap.add_argument("--pairings", nargs="+", default=None,
                    choices=["conforming", "projection", "mortar", "moderate"])
    args = ap.parse_args(argv)
    if args.part in ("accuracy", "all"):
        accuracy()
    if args.part in ("points", "all"):
        points()
    if args.part in ("cost", "all"):
        cost(args.points, args.pairings)
    if args.part in ("newton", "all"):
        newton(args.points, args.pairings)


if __name__ == "__main__":
    main()
