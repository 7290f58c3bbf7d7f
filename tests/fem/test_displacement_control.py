"""Displacement control: prescribed displacements scaled by the load factor, the lifting
recomputed at every change, reactions on the prescribed surface (serial and 2 ranks).

References: (1) linear elasticity is linear: a block clamped at the bottom and loaded by a
force F on its top has a top displacement u_F; prescribing u_F on the top instead must give the
same field and a reaction equal to F, at every load factor (the problem is built at load factor
0, so a lifting computed once — the bug this replaces — gives a wrong answer at 1).
(2) Force balance of the punch pressed by a prescribed displacement of its top: the reaction
there equals minus the interface force on the punch.
Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem, mesh as dmesh
from rough_contact.fem import compat
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver
from rough_contact.scenes.defaults import SEATING_STIFFNESS

BOTTOM, TOP = 1, 2
F = np.array([30.0, -20.0, -100.0])       # force on the top at load factor 1 [N]


def _block(order=2):
    msh = dmesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [2.0, 1.0, 1.0]], [4, 2, 3],
                           dmesh.CellType.tetrahedron)
    msh.topology.create_connectivity(2, 3)
    facets = dmesh.exterior_facet_indices(msh.topology)
    mid = dmesh.compute_midpoints(msh, 2, facets)
    vals = np.zeros(facets.size, dtype=np.int32)
    vals[np.isclose(mid[:, 2], 0.0)] = BOTTOM
    vals[np.isclose(mid[:, 2], 1.0)] = TOP
    keep = vals > 0
    tags = dmesh.meshtags(msh, 2, facets[keep], vals[keep])
    V = compat.vector_space(msh, order)
    clamp = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType),
                            fem.locate_dofs_topological(V, 2, tags.find(BOTTOM)), V)
    return V, tags, clamp


def _solve(problem, lam):
    solver = SNESSolver(problem, prefix="dc_")
    problem.set_load_factor(lam)
    res = solver.solve()
    solver.destroy()
    assert res.converged
    return problem.u.x.array.copy()


@pytest.mark.parametrize("order", [1, 2])
def test_prescribed_displacement_reproduces_the_force_case(order):
    V, tags, clamp = _block(order)
    force_case = ContactProblem(V, Material(1e3, 0.3), [clamp], [SurfaceLoad(TOP, force=F)],
                                facet_tags=tags)
    u_force = _solve(force_case, 1.0)
    u_top = force_case.u

    disp = ContactProblem(V, Material(1e3, 0.3), [clamp],
                          prescribed=[PrescribedDisplacement(TOP, u_top)], facet_tags=tags)
    assert disp.load_factor == 0.0
    scale = np.abs(u_force).max()
    for lam in (0.5, 1.0):                    # the lifting follows every change
        u = _solve(disp, lam)
        np.testing.assert_allclose(u, lam * u_force, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(disp.reaction(TOP), lam * F, rtol=1e-8,
                                   atol=1e-8 * np.abs(F).max())


def test_uniform_and_partial_components_and_errors():
    V, tags, clamp = _block(1)
    # only u_z prescribed on the top: a uniaxial-like compression; the free components relax
    p = ContactProblem(V, Material(1e3, 0.3), [clamp],
                       prescribed=[PrescribedDisplacement(TOP, (0.0, 0.0, -1e-3), (2,))],
                       facet_tags=tags)
    _solve(p, 1.0)
    r = p.reaction(TOP)
    assert r[0] == 0.0 and r[1] == 0.0 and r[2] < 0.0       # x, y free: no reaction there
    # the same load factor twice, then back: reactions scale linearly
    _solve(p, 0.25)
    np.testing.assert_allclose(p.reaction(TOP)[2], 0.25 * r[2], rtol=1e-8)
    with pytest.raises(ValueError, match="reaction: tag 1 carries no PrescribedDisplacement; "
                       r"prescribed tags: \[2\]"):
        p.reaction(BOTTOM)
    with pytest.raises(ValueError, match=r"PrescribedDisplacement\(tag=7\): no facet carries "
                       r"tag 7; tags present: \[1, 2\]"):
        ContactProblem(V, Material(1e3, 0.3), [clamp],
                       prescribed=[PrescribedDisplacement(7, (0, 0, 1e-3))], facet_tags=tags)
    with pytest.raises(ValueError, match=r"components = \(2, 3\) is invalid"):
        PrescribedDisplacement(TOP, (0, 0, 1), (2, 3))
    with pytest.raises(ValueError, match=r"value\[2\] = nan mm is invalid: it must be finite"):
        PrescribedDisplacement(TOP, (0, 0, np.nan))


def test_punch_pressed_by_displacement_balances_the_interface():
    from rough_contact.fem.contact import ContactInterface
    from rough_contact.scenes import flat_punch

    ps = flat_punch.quarter_punch(MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.5, order=1,
                                  load_half_width=10.0)
    scene = ps.scene
    law, _ = flat_punch.make_law(MPI.COMM_WORLD, case="b", normal_law="elastic",
                                 seating_pressure=0.1)
    first, second = scene.contact_pair
    ci = ContactInterface(ps.V, scene.facet_tags, first, second, law=law, bcs=ps.bcs)
    E, NU = flat_punch.E, flat_punch.NU
    load = scene.tag("load")
    problem = ContactProblem(
        ps.V, {scene.tag("punch"): Material(E, NU), scene.tag("foundation"): Material(E, NU)},
        ps.bcs, cell_tags=scene.cell_tags, facet_tags=scene.facet_tags, interface=ci,
        seating_tag=first, seating_stiffness=SEATING_STIFFNESS,
        prescribed=[PrescribedDisplacement(load, (0.0, 0.0, -2e-4), (2,))])
    solver = SNESSolver(problem, prefix="dcp_")
    incs = list(load_path(problem, solver, [0.25, 0.5, 1.0], verbose=False))
    assert [i.load_factor for i in incs] == [0.25, 0.5, 1.0]
    r = problem.reaction(load)
    fz = incs[-1].contact_force[2]
    assert fz > 10.0                                  # pressed: a real contact force [N]
    assert abs(r[2] + fz) <= 1e-8 * abs(fz)           # reaction balances the interface
    solver.destroy()
