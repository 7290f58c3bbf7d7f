"""Nodal (vertex) interface points obtained through the mortar integrals
(``rough_contact.fem.nodal.NodalContactInterface``).

* Patch test: a uniform pressure crosses a conforming and a non-matching (mortar) interface
  exactly, P1 and P2 tetrahedra (and Q1/Q2 hexahedra on the mortar route), frictionless penalty
  with different block stiffnesses (the blocks slide laterally) and Coulomb friction with exact
  (augmented-Lagrangian) enforcement: every vertex carries p to round-off. The exact solution
  (uniform stress, linear displacements) lies in every FE space, so any error is the method's.
* The vertex weights m_j = int N_j dA sum to the nominal area and the vertex rows are the
  derivative of the residual (finite differences), serial = 2 ranks to 1e-10.

Run serial and in parallel:
    .venv/bin/python -m pytest tests/fem/test_nodal.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_nodal.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.enforcement import AugmentedLagrangian, Penalty
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared checks
from interface_checks import (blocks_on_rollers, interpolate_two_bodies,  # noqa: E402
                              residual_jacobian_figures)

E, NU, PRESSURE = 2.0e5, 0.25, 80.0


def _patch(mesh, order, pairing, friction, cell_type="tetrahedron", comm=MPI.COMM_WORLD):
    """Uniform pressure on the top of two blocks on rollers; (largest pressure error / p,
    largest shear / p, contact force, slipping vertices, nominal area, interface)."""
    scene, V, bcs = blocks_on_rollers(comm, mesh, order, cell_type)
    if friction:      # same material: no lateral slide, exact stick and contact
        law = SoftplusPenalty(1e6, 1e-7, k_tangential=1e6, friction=0.3)
        enforcement, E_lower = AugmentedLagrangian(tolerance=1e-9, max_updates=50), E
    else:             # the lower block twice as soft: the blocks slide against each other
        law, enforcement, E_lower = LinearPenalty(1e6), Penalty(), 0.5 * E
    ci = NodalContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                               quadrature_degree=2 * order, pairing=pairing,
                               enforcement=enforcement)
    assert ci.pairing_used == pairing
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(E_lower, NU)}
    problem = ContactProblem(V, mats, bcs,
                             [SurfaceLoad(scene.tag("top"), traction=[0, 0, -PRESSURE])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="test_nodal_")
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    assert incs[-1].cutbacks == 0
    pf = ci.point_fields()
    c = scene.mesh.comm
    p_err = c.allreduce(float(np.max(np.abs(pf.pressure - PRESSURE), initial=0.0)), op=MPI.MAX)
    s_err = c.allreduce(float(np.max(np.abs(pf.shear), initial=0.0)), op=MPI.MAX)
    slipping = c.allreduce(int(pf.slipping.sum()), op=MPI.SUM)
    out = (p_err / PRESSURE, s_err / PRESSURE, ci.contact_force(), slipping, ci.nominal_area(),
           ci)
    solver.destroy()
    return out


PATCH = [("conforming", 1, "conforming"), ("conforming", 2, "conforming"),
         ("nonmatching", 1, "mortar"), ("nonmatching", 2, "mortar"),
         ("conforming", 2, "conforming", "hexahedron"),
         ("nonmatching", 1, "mortar", "hexahedron"), ("nonmatching", 2, "mortar", "hexahedron")]


@pytest.mark.parametrize("case", PATCH, ids=lambda c: f"{c[2]}-{'Q' if len(c) > 3 else 'P'}{c[1]}")
@pytest.mark.parametrize("friction", [False, True], ids=["frictionless", "coulomb-exact"])
def test_patch_uniform_pressure_is_transmitted_exactly(case, friction):
    mesh, order, pairing, *cell = case
    p_err, s_err, force, slipping, area, ci = _patch(mesh, order, pairing, friction, *cell)
    assert p_err <= 1e-8
    assert abs(area - 1.0) <= 1e-10                  # sum of m_j: the whole face
    np.testing.assert_allclose(force, [0.0, 0.0, PRESSURE], atol=1e-8 * PRESSURE)
    if friction:
        assert s_err <= 1e-8 and slipping == 0
    # one point per vertex of the first surface: as many constraints as surface vertices
    assert ci.n_points_global < ci.comm.allreduce(ci.quadrature_points.n_points, op=MPI.SUM)


def _figures(comm, pairing, order, fd=False):
    """Force, residual and Jacobian norms, real and nominal area at a smooth non-uniform
    displacement with friction; optionally the finite-difference error of the Jacobian."""
    scene, V, _ = blocks_on_rollers(comm, pairing, order)
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.2)
    ci = NodalContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law,
                               quadrature_degree=2 * order, pairing=pairing)
    u = fem.Function(V)
    interpolate_two_bodies(u, scene)
    return residual_jacobian_figures(ci, u, V, fd)


@pytest.mark.parametrize("pairing,order", [("conforming", 2), ("mortar", 1), ("mortar", 2)])
def test_rank_independent_and_jacobian(pairing, order):
    """Vertices shared by facets of several ranks are summed on their owner: the same figures
    on all ranks and on one (1e-10); the assembled Jacobian is the derivative of the
    assembled residual."""
    world, fd_err = _figures(MPI.COMM_WORLD, pairing, order, fd=True)
    serial, _ = _figures(MPI.COMM_SELF, pairing, order)
    np.testing.assert_allclose(world, serial, rtol=1e-10)
    assert abs(world[-1] - 1.0) <= 1e-10
    assert fd_err < 1e-6


@pytest.mark.parametrize("cell", ["tetrahedron", "hexahedron"])
def test_vertex_functions_in_the_p2_facet_basis(cell):
    """N_j = sum_k M_kj phi_k: the first-order vertex function of vertex j at every closure
    node of a P2 triangle is the node's barycentric coordinate; on a Q2 square 1 at j, 1/2 at
    the mid-nodes of the edges through j, 1/4 at the centre node (bilinear), 0 elsewhere; the
    N_j sum to 1 at every node."""
    import dolfinx
    from rough_contact.fem.nodal import vertex_shape_matrix
    kind = getattr(dolfinx.mesh.CellType, cell)
    msh = dolfinx.mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1, kind)
    V = compat.vector_space(msh, 2)
    M, vclose = vertex_shape_matrix(V)
    X = np.asarray(V.element.basix_element.points)
    closure = np.array(V.element.basix_element.entity_closure_dofs[2])
    for lf in range(closure.shape[0]):
        nodes = X[closure[lf]]                      # (n_close, 3) reference coordinates
        corners = nodes[vclose[lf]]                 # (nv, 3)
        for k, x in enumerate(nodes):
            d = np.linalg.norm(corners - x, axis=1)
            expected = np.zeros(corners.shape[0])
            if corners.shape[0] == 3:               # barycentric coordinates of x
                A = np.vstack([corners.T, np.ones(3)])
                expected = np.linalg.lstsq(A, np.append(x, 1.0), rcond=None)[0]
            elif np.min(d) < 1e-12:                 # a square's vertex node
                expected[np.argmin(d)] = 1.0
            else:                                   # a square's mid-node or centre: equal
                near = np.isclose(d, d.min())       # shares of the nearest corners
                expected[near] = 1.0 / near.sum()
            np.testing.assert_allclose(M[lf, k], expected, atol=1e-12)
        np.testing.assert_allclose(M[lf].sum(axis=1), 1.0, atol=1e-12)
