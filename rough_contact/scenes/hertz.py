"""A sphere pressed into a block, against Hertz's solution: a rigid sphere (``run``), or an
elastic sphere meshed independently of the block (``run_elastic``, non-matching interface).

Quarter block [0, L]^2 x [-H, 0] (``indented_block``), symmetry on x = 0 and y = 0, the bottom
pushed up by u_z = delta (``PrescribedDisplacement``), a ``RigidSphere`` of radius R touching the
top at the origin, frictionless stiff linear penalty (``LinearPenalty``, unilateral). The total
force P is the bottom reaction (x 4). Hertz (rigid sphere on an elastic half-space,
E* = E / (1 - nu^2)): contact radius a^3 = 3 P R / (4 E*), peak pressure p0 = 3 P / (2 pi a^2),
p(r) = p0 sqrt(1 - r^2 / a^2). The FE a and p0 come from a least-squares fit of p^2 against r^2
over the interface points with p > 0.3 p_max (p^2 = p0^2 - (p0/a)^2 r^2 is linear in r^2), which
keeps the contact edge out of the fit; the pointwise error of p is reported by radius band.
The block is finite (L = H = 20 a by default): the relation a(P) does not involve the block's
far-field compliance (unlike the approach), so it is compared directly.

Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.fem.rigid import RigidSphere
from rough_contact.interface.penalty import LinearPenalty
from rough_contact.io import gather_points
from rough_contact.scenes.meshes.blocks import indented_block
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

__all__ = ["run", "run_elastic"]


def run(contact_size=0.04, order=1, radius=10.0, delta=4e-3, E=2.0e5, nu=0.3, half_width=4.0,
        height=4.0, mesh_size=1.0, penalty=1e8, steps=2, quadrature="gauss",
        comm=MPI.COMM_WORLD) -> dict:
    """Indent; return Hertz's and the FE's P, a, p0 and pointwise errors. Collective."""
    scene = indented_block(half_width=half_width, height=height, mesh_size=mesh_size,
                           contact_size=contact_size, transition=1.0, order=order, comm=comm)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", order))
    fdim = 2

    def dofs(name, comp):
        return fem.locate_dofs_topological(V.sub(comp), fdim,
                                           scene.facet_tags.find(scene.tag(name)))

    zero = PETSc.ScalarType(0.0)
    bcs = [fem.dirichletbc(zero, dofs("symmetry_x", 0), V.sub(0)),
           fem.dirichletbc(zero, dofs("symmetry_y", 1), V.sub(1))]
    sphere = RigidSphere((0.0, 0.0, radius), radius)
    ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=LinearPenalty(
        penalty, unilateral=True), rigid=sphere, bcs=bcs, quadrature_degree=2 * order,
        quadrature=quadrature,
        grain_direction=(1.0, 0.0, 0.0))
    bottom = scene.tag("bottom")
    problem = ContactProblem(V, Material(E, nu), bcs, facet_tags=scene.facet_tags, interface=ci,
                             prescribed=[PrescribedDisplacement(bottom, (0.0, 0.0, delta), (2,))])
    solver = SNESSolver(problem, prefix="hertz_")
    for inc in load_path(problem, solver, [(i + 1) / steps for i in range(steps)],
                         verbose=False):
        pass
    P = 4.0 * problem.reaction(bottom)[2]
    out = _compare_with_hertz(comm, ci, P, E / (1.0 - nu**2), radius)
    solver.destroy()
    if out is not None:
        out.update(dofs=problem.num_dofs, contact_size=contact_size, order=order,
                   quadrature=quadrature)
    return comm.bcast(out, root=0)


def _compare_with_hertz(comm, ci: ContactInterface, P: float, E_star: float,
                        radius: float) -> dict | None:
    """Hertz's a, p0 for the total force P against the FE fit and pointwise errors (rank 0
    returns the dict, the others None). Collective."""
    pf = ci.point_fields()
    real = pf.weight > 0
    pts, f = gather_points(comm, ci.point_coordinates()[real],
                           {"p": pf.pressure[real], "w": pf.weight[real]})
    if comm.rank != 0:
        return None
    a_h = (3.0 * P * radius / (4.0 * E_star)) ** (1.0 / 3.0)
    p0_h = 3.0 * P / (2.0 * np.pi * a_h**2)
    r = np.hypot(pts[:, 0], pts[:, 1])
    p = f["p"]
    fit = p > 0.3 * p.max()
    slope, icpt = np.polyfit(r[fit] ** 2, p[fit] ** 2, 1)
    p0_fe = float(np.sqrt(icpt))
    a_fe = float(np.sqrt(-icpt / slope))
    p_h = p0_h * np.sqrt(np.clip(1.0 - (r / a_h) ** 2, 0.0, None))
    bands = [(0.0, 0.5), (0.5, 0.8), (0.8, 0.95), (0.95, 1.05)]
    band_err = {}
    for lo, hi in bands:
        m = (r >= lo * a_h) & (r < hi * a_h)
        band_err[f"{lo:g}-{hi:g} a"] = float(np.abs(p[m] - p_h[m]).max() / p0_h) if m.any() \
            else float("nan")
    return dict(points=int(len(p)), P=float(P), a_hertz=float(a_h), a_fe=a_fe,
                p0_hertz=float(p0_h), p0_fe=p0_fe, a_error=a_fe / a_h - 1.0,
                p0_error=p0_fe / p0_h - 1.0, force_from_p=float(4.0 * np.dot(p, f["w"])),
                band_error=band_err)


def run_elastic(contact_size=0.04, order=2, radius=10.0, approach=6e-3, E=2.0e5, nu=0.3,
                size_ratio=0.7, penalty=1e8, steps=2, pairing="mortar", mesh_size=1.0,
                quadrature="gauss", comm=MPI.COMM_WORLD) -> dict:
    """An elastic sphere (same material as the block) meshed independently of the block,
    pressed by moving its top down by ``approach`` [mm]; frictionless stiff penalty across the
    non-matching interface (``pairing``: "mortar" or "projection"; ``quadrature="vertex"``
    with the projection and P1: node-to-surface). Hertz with
    1/E* = 2 (1 - nu^2) / E and the sphere's radius (the block is flat). Collective.

    Returns:
        Hertz's and the FE's P, a, p0, the pointwise errors by band of r / a, the DOFs and the
        force balance |P_top - P_bottom| / P (rank-independent dict on every rank).
    """
    from rough_contact.scenes.meshes.blocks import sphere_on_block

    scene = sphere_on_block(radius=radius, contact_size=contact_size, size_ratio=size_ratio,
                            mesh_size=mesh_size, order=order, comm=comm)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", order))

    def dofs(name, comp):
        return fem.locate_dofs_topological(V.sub(comp), 2,
                                           scene.facet_tags.find(scene.tag(name)))

    zero = PETSc.ScalarType(0.0)
    bcs = [fem.dirichletbc(zero, dofs("symmetry_x", 0), V.sub(0)),
           fem.dirichletbc(zero, dofs("symmetry_y", 1), V.sub(1))]
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair,
                          law=LinearPenalty(penalty, unilateral=True), bcs=bcs,
                          quadrature_degree=2 * order, pairing=pairing, search_radius=0.2,
                          quadrature=quadrature)
    top = scene.tag("sphere_top")
    problem = ContactProblem(V, Material(E, nu), bcs, facet_tags=scene.facet_tags,
                             interface=ci, prescribed=[
                                 PrescribedDisplacement(top, (0.0, 0.0, -approach), (2,)),
                                 PrescribedDisplacement(scene.tag("bottom"), (0.0, 0.0, 0.0),
                                                        (2,))])
    solver = SNESSolver(problem, prefix="hertz_elastic_")
    for inc in load_path(problem, solver, [(i + 1) / steps for i in range(steps)],
                         verbose=False):
        pass
    P = -4.0 * problem.reaction(top)[2]
    P_bottom = 4.0 * problem.reaction(scene.tag("bottom"))[2]
    out = _compare_with_hertz(comm, ci, P, E / (2.0 * (1.0 - nu**2)), radius)
    solver.destroy()
    if out is not None:
        out.update(dofs=problem.num_dofs, contact_size=contact_size, order=order,
                   pairing=pairing, quadrature=quadrature, balance=abs(P - P_bottom) / P)
    return comm.bcast(out, root=0)
