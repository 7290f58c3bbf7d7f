"""A sphere pressed into a block, against Hertz's solution: a rigid sphere (``run``), or an
elastic sphere meshed independently of the block (``run_elastic``, non-matching interface).

Quarter block [0, L]^2 x [-H, 0] (``indented_block``), symmetry on x = 0 and y = 0, the bottom
pushed up by u_z = delta (``PrescribedDisplacement``), a ``RigidSphere`` of radius R touching the
top at the origin, frictionless stiff linear penalty (``LinearPenalty``, unilateral). The total
force P is the bottom reaction (x 4). Hertz (rigid sphere on an elastic half-space,
E* = E / (1 - nu^2)): contact radius a^3 = 3 P R / (4 E*), peak pressure p0 = 3 P / (2 pi a^2),
p(r) = p0 sqrt(1 - r^2 / a^2) (:mod:`rough_contact.references`). The FE a and p0 come from a least-squares fit of p^2 against r^2
over the interface points with p > 0.3 p_max (p^2 = p0^2 - (p0/a)^2 r^2 is linear in r^2), which
keeps the contact edge out of the fit; the pointwise error of p is reported by radius band.
The block is finite (L = H = 20 a by default): the relation a(P) does not involve the block's
far-field compliance (unlike the approach), so it is compared directly.

Units: mm, N, MPa.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.fem.rigid import RigidSphere
from rough_contact.interface.penalty import LinearPenalty
from rough_contact.io import gather_points
from rough_contact.references import hertz_peak_pressure, hertz_pressure, hertz_radius
from rough_contact.scenes.defaults import GRAIN_X, INDENTER_PENALTY, quadrature_degree
from rough_contact.scenes.meshes.blocks import indented_block
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

__all__ = ["HertzComparison", "run", "run_elastic"]


@dataclass(frozen=True)
class HertzComparison:
    """The FE contact against Hertz's solution for the same total force (identical on every
    rank).

    Attributes:
        points: interface points with a nonzero weight.
        P: total normal force (whole model) [N].
        a_hertz, a_fe: contact radius of Hertz and of the FE fit [mm].
        p0_hertz, p0_fe: peak pressure of Hertz and of the FE fit [MPa].
        a_error, p0_error: a_fe / a_hertz - 1, p0_fe / p0_hertz - 1 [-].
        force_from_p: the FE pressure integrated over the interface (whole model) [N].
        band_error: {"lo-hi a": max |p_fe - p_hertz| / p0_hertz over lo a <= r < hi a} [-].
        dofs: global number of DOFs.
        contact_size: element size at the contact [mm]; order: element order.
        quadrature: interface rule ("gauss" or "vertex").
        pairing: the elastic sphere's pairing ("mortar", "projection"); None for the rigid one.
        balance: |P_top - P_bottom| / P of the elastic sphere; None for the rigid one.
    """

    points: int
    P: float
    a_hertz: float
    a_fe: float
    p0_hertz: float
    p0_fe: float
    a_error: float
    p0_error: float
    force_from_p: float
    band_error: dict
    dofs: int
    contact_size: float
    order: int
    quadrature: str
    pairing: Optional[str] = None
    balance: Optional[float] = None


def _symmetry_bcs(V, scene) -> list:
    """u_x = 0 on x = 0 and u_y = 0 on y = 0 (the quarter model's symmetry planes)."""
    return [fix(V, scene.facet_tags, scene.tag("symmetry_x"), 0),
            fix(V, scene.facet_tags, scene.tag("symmetry_y"), 1)]


def run(contact_size=0.04, order=1, radius=10.0, delta=4e-3, E=2.0e5, nu=0.3, half_width=4.0,
        height=4.0, mesh_size=1.0, penalty=INDENTER_PENALTY, steps=2, quadrature="gauss",
        comm=MPI.COMM_WORLD) -> HertzComparison:
    """Indent; return Hertz's and the FE's P, a, p0 and pointwise errors. Collective."""
    scene = indented_block(half_width=half_width, height=height, mesh_size=mesh_size,
                           contact_size=contact_size, transition=1.0, order=order, comm=comm)
    V = vector_space(scene.mesh, order)
    bcs = _symmetry_bcs(V, scene)
    sphere = RigidSphere((0.0, 0.0, radius), radius)
    ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=LinearPenalty(
        penalty, unilateral=True), rigid=sphere, bcs=bcs,
        quadrature_degree=quadrature_degree(order), quadrature=quadrature,
        grain_direction=GRAIN_X)
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
    return HertzComparison(**comm.bcast(out, root=0), dofs=problem.num_dofs,
                           contact_size=contact_size, order=order, quadrature=quadrature)


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
    a_h = hertz_radius(P, radius, E_star)
    p0_h = hertz_peak_pressure(P, a_h)
    r = np.hypot(pts[:, 0], pts[:, 1])
    p = f["p"]
    fit = p > 0.3 * p.max()
    slope, icpt = np.polyfit(r[fit] ** 2, p[fit] ** 2, 1)
    p0_fe = float(np.sqrt(icpt))
    a_fe = float(np.sqrt(-icpt / slope))
    p_h = hertz_pressure(r, p0_h, a_h)
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
                size_ratio=0.7, penalty=INDENTER_PENALTY, steps=2, pairing="mortar",
                mesh_size=1.0, quadrature="gauss", comm=MPI.COMM_WORLD) -> HertzComparison:
    """An elastic sphere (same material as the block) meshed independently of the block,
    pressed by moving its top down by ``approach`` [mm]; frictionless stiff penalty across the
    non-matching interface (``pairing``: "mortar" or "projection"; ``quadrature="vertex"``
    with the projection and P1: node-to-surface). Hertz with
    1/E* = 2 (1 - nu^2) / E and the sphere's radius (the block is flat). Collective.

    Returns:
        :class:`HertzComparison` with ``pairing`` and the force balance ``balance``
        (identical on every rank).
    """
    from rough_contact.scenes.meshes.blocks import sphere_on_block

    scene = sphere_on_block(radius=radius, contact_size=contact_size, size_ratio=size_ratio,
                            mesh_size=mesh_size, order=order, comm=comm)
    V = vector_space(scene.mesh, order)
    bcs = _symmetry_bcs(V, scene)
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair,
                          law=LinearPenalty(penalty, unilateral=True), bcs=bcs,
                          quadrature_degree=quadrature_degree(order), pairing=pairing,
                          search_radius=0.2, quadrature=quadrature)
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
    return HertzComparison(**comm.bcast(out, root=0), dofs=problem.num_dofs,
                           contact_size=contact_size, order=order, quadrature=quadrature,
                           pairing=pairing, balance=abs(P - P_bottom) / P)
