"""Multipliers updated inside the Newton iteration
(``rough_contact.interface.enforcement.NewtonAugmentedLagrangian`` on the nodal point set;
docs/exact_contact_newton.md: experimental, not faster than Uzawa's route on the punch yet).

* Patch test: two blocks pressed together by a uniform pressure, Coulomb friction mu = 0.3,
  conforming P1 and mortar P2: every vertex carries the pressure exactly (the shifted penalty
  would leave k |g| ~ p without the multiplier updates: checked on the gap), no shear, no
  slip; the multipliers were updated inside the Newton iteration; serial = 2 ranks to 1e-10.
* Bad arguments are refused with the quantity, its value and the valid range.
* The scenes' ``basis`` argument (flat punch, Mindlin) reaches the nodal interface: on the
  punch's conforming P1 pairing the dual basis couples a vertex to its partner alone (two
  nodes per row), the standard one to its facet patch; bad values are refused.

Run serial and in parallel:
    .venv/bin/python -m pytest tests/fem/test_nodal_ssn.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_nodal_ssn.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.enforcement import (AugmentedLagrangian, NewtonAugmentedLagrangian,
                                                 Penalty)
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared checks
from interface_checks import blocks_on_rollers  # noqa: E402

E, NU, PRESSURE, MU = 2.0e5, 0.25, 80.0, 0.3
K = 1e6          # penalty k_N = k_T [MPa/mm]



def _patch(comm, pairing, order, basis="standard", cell_type="tetrahedron"):
    """Uniform pressure on the top of two blocks on rollers, one increment."""
    scene, V, bcs = blocks_on_rollers(comm, pairing, order, cell_type)
    law = SoftplusPenalty(K, 1e-7, k_tangential=K, friction=MU)
    ci = NodalContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                               quadrature_degree=2 * order, pairing=pairing, basis=basis,
                               enforcement=NewtonAugmentedLagrangian(tolerance=1e-9,
                                                                     max_updates=50))
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(E, NU)}
    problem = ContactProblem(V, mats, bcs,
                             [SurfaceLoad(scene.tag("top"), traction=[0, 0, -PRESSURE])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="test_ssn_")
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    pf = ci.point_fields()
    c = scene.mesh.comm
    x = np.concatenate(c.allgather(ci.point_coordinates()))
    order_ = np.lexsort(x.T)
    out = dict(
        incs=incs, updates=c.allreduce(ci.newton_updates, op=MPI.MAX),
        force=ci.contact_force(),
        pressure=np.concatenate(c.allgather(pf.pressure))[order_],
        shear=np.concatenate(c.allgather(pf.shear))[order_],
        gap=np.concatenate(c.allgather(pf.gap))[order_],
        slipping=c.allreduce(int(pf.slipping.sum()), op=MPI.SUM),
        width=c.allreduce(ci.nodal.B.shape[2] // 3 if ci.n_points else 0, op=MPI.MAX))
    solver.destroy()
    return out


PATCH = [("conforming", 1, "standard", "tetrahedron"), ("mortar", 2, "standard", "tetrahedron"),
         ("conforming", 1, "dual", "tetrahedron"), ("mortar", 1, "dual", "tetrahedron"),
         ("mortar", 2, "dual", "tetrahedron"), ("mortar", 1, "dual", "hexahedron")]


@pytest.mark.parametrize("case", PATCH, ids=lambda c: f"{c[0]}-P{c[1]}-{c[2]}-{c[3][:3]}")
def test_patch_exact_and_rank_independent(case):
    """Exact transmission of a uniform pressure (the standard and the dual vertex weights
    are both partitions of unity); serial = 2 ranks."""
    pairing, order, basis, cell = case
    world = _patch(MPI.COMM_WORLD, pairing, order, basis, cell)
    assert world["incs"][-1].cutbacks == 0
    assert world["updates"] > 0                     # the route was taken
    np.testing.assert_allclose(world["pressure"], PRESSURE, rtol=0, atol=1e-8 * PRESSURE)
    assert np.max(np.abs(world["shear"])) <= 1e-8 * PRESSURE and world["slipping"] == 0
    # the penalty alone would leave k |g| = p - p(0); exact: the gap closes
    assert np.max(K * np.abs(world["gap"])) <= 1e-6 * PRESSURE
    np.testing.assert_allclose(world["force"], [0.0, 0.0, PRESSURE], atol=1e-8 * PRESSURE)
    if basis == "dual" and pairing == "conforming" and order == 1:
        assert world["width"] == 2      # node to node: the vertex and its partner only
    serial = _patch(MPI.COMM_SELF, pairing, order, basis, cell)
    np.testing.assert_allclose(world["pressure"], serial["pressure"], rtol=0,
                               atol=1e-10 * PRESSURE)
    np.testing.assert_allclose(world["force"], serial["force"], rtol=0, atol=1e-10 * PRESSURE)


@pytest.mark.parametrize("kwargs,name", [(dict(residual_ratio=-0.1), "residual_ratio"),
                                         (dict(residual_ratio=2.0), "residual_ratio"),
                                         (dict(first_iteration=-1), "first_iteration"),
                                         (dict(tolerance=0.0), "augmentation tolerance")])
def test_bad_arguments(kwargs, name):
    with pytest.raises(ValueError, match=name):
        NewtonAugmentedLagrangian(**kwargs)


def _punch(enforcement, comm=MPI.COMM_WORLD, basis="standard"):
    """GetFEM's flat punch on a coarse mesh, P1, Coulomb mu = 0.2, 4 loading and 3
    unloading increments: dissipation per increment, vertex tractions at the end, exactness
    at the peak (largest k_T |s - s_p| over the sticking vertices / largest traction)."""
    from rough_contact.scenes import flat_punch
    from rough_contact.solver.loading import load_unload_factors
    k = 1e7
    law = SoftplusPenalty(k_normal=k, width=2.5e-9, k_tangential=k, friction=0.2)
    m = flat_punch.build(comm, mesh_size=20.0, contact_size=2.0, order=1,
                         load_half_width=10.0, law=law, steps=4, points="nodal", basis=basis,
                         enforcement=enforcement, prefix="test_ssn_punch_",
                         solver_options=dict(linear_solver="mumps"))
    assert m.interface.basis == basis
    D, stick_err = [], None
    for inc in load_path(m.problem, m.solver, load_unload_factors(4, 3, final_factor=0.25)):
        D.append(inc.dissipation)
        if inc.load_factor == 1.0:
            pf = m.interface.point_fields()
            stick = pf.contact & ~pf.slipping
            vals = np.array([np.max(k * np.linalg.norm((pf.slip - pf.plastic_slip)[stick],
                                                       axis=1), initial=0.0),
                             np.max(np.hypot(pf.pressure, np.linalg.norm(pf.shear, axis=1)),
                                    initial=0.0), float(stick.sum())])
            vals = np.array([comm.allreduce(vals[0], op=MPI.MAX),
                             comm.allreduce(vals[1], op=MPI.MAX),
                             comm.allreduce(vals[2], op=MPI.SUM)])
            stick_err = (vals[0] / vals[1], vals[2])
    pf = m.interface.point_fields()
    x = np.concatenate(comm.allgather(m.interface.point_coordinates()))
    order_ = np.lexsort(x.T)
    t = np.concatenate(comm.allgather(np.column_stack([pf.pressure, pf.shear])))[order_]
    m.solver.destroy()
    return np.array(D), t, stick_err


@pytest.fixture(scope="module", params=["standard", "dual"])
def punch_newton(request):
    return request.param, _punch(NewtonAugmentedLagrangian(tolerance=1e-8, max_updates=30),
                                 basis=request.param)


def test_punch_same_answer_as_uzawa(punch_newton):
    """Uzawa's route (a Newton solve per multiplier update) reaches the same dissipation
    history and vertex tractions; the sticking vertices do not slip elastically; the plain
    penalty's dissipation differs by more than the agreement asked (the check can fail)."""
    basis, (D, t, (stick_err, n_stick)) = punch_newton
    D_u, t_u, _ = _punch(AugmentedLagrangian(tolerance=1e-8, max_updates=30), basis=basis)
    assert n_stick > 0 and D[-1] > 0.0
    assert stick_err <= 1e-7
    np.testing.assert_allclose(D, D_u, rtol=1e-5, atol=1e-6 * D_u[-1])
    np.testing.assert_allclose(t, t_u, rtol=0, atol=1e-5 * np.abs(t_u).max())
    D_p, _, _ = _punch(Penalty(), basis=basis)
    assert abs(D_p[-1] - D_u[-1]) > 1e-3 * D_u[-1]


def test_punch_rank_independent(punch_newton):
    """Serial = all ranks to 1e-10 (dissipation history, vertex tractions)."""
    basis, (D, t, _) = punch_newton
    D_s, t_s, _ = _punch(NewtonAugmentedLagrangian(tolerance=1e-8, max_updates=30),
                         MPI.COMM_SELF, basis)
    np.testing.assert_allclose(D, D_s, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(t, t_s, rtol=0, atol=1e-10 * np.abs(t_s).max())


def _row_width(interface, comm):
    """Largest number of nodes in a vertex's weighted jump, over all ranks."""
    n = interface.nodal.B.shape[2] // 3 if interface.n_points else 0
    return comm.allreduce(n, op=MPI.MAX)


def test_scene_basis_reaches_interface():
    """flat_punch.build(basis=) builds the nodal interface on that basis: dual = node to node
    on the conforming pairing (2 nodes per row, as the vertex rule), standard = the facet
    patch on both sides (more)."""
    from rough_contact.scenes import flat_punch
    law = SoftplusPenalty(k_normal=1e7, width=2.5e-9, k_tangential=1e7, friction=0.2)
    comm = MPI.COMM_WORLD
    widths = {}
    for basis in ("standard", "dual"):
        m = flat_punch.build(comm, mesh_size=20.0, contact_size=2.0, order=1,
                             load_half_width=10.0, law=law, steps=4, points="nodal",
                             basis=basis, prefix="test_ssn_basis_")
        assert isinstance(m.interface, NodalContactInterface)
        assert m.interface.basis == basis
        widths[basis] = _row_width(m.interface, comm)
        m.solver.destroy()
    assert widths["dual"] == 2
    assert widths["standard"] > 2


@pytest.mark.parametrize("kwargs,match", [
    (dict(points="nodal", basis="biorthogonal"), "basis = 'biorthogonal' is invalid"),
    (dict(points="quadrature", basis="dual"), "basis = 'dual' is invalid with points"),
    (dict(points="vertex"), "points = 'vertex' is invalid")])
def test_scene_bad_basis(kwargs, match):
    """Refused before any mesh is built, naming the quantity, its value and the choices."""
    from rough_contact.scenes import flat_punch, mindlin
    with pytest.raises(ValueError, match=match):
        flat_punch.build(MPI.COMM_WORLD, law="penalty", **kwargs)
    with pytest.raises(ValueError, match=match):
        mindlin.run(**kwargs)


def test_mindlin_enforcement_and_augmented_refused():
    """mindlin.run(enforcement=...) with augmented=True is ambiguous: refused before any mesh
    is built, naming both quantities."""
    from rough_contact.scenes import mindlin
    with pytest.raises(ValueError, match="enforcement = .* with augmented = True is invalid"):
        mindlin.run(points="nodal", basis="dual", augmented=True,
                    enforcement=NewtonAugmentedLagrangian(1e-4))


@pytest.mark.parametrize("facet, cell, area", [("triangle6", "triangle", 0.5),
                                               ("quadrilateral9", "quadrilateral", 1.0)])
def test_quadratic_dual_is_biorthogonal_to_basix_functions(facet, cell, area):
    """The quadratic dual basis against basix's own P2/Q2 functions, integrated by a rule
    exact for their products (the hand-written mass matrices and DOF order are what is checked):
    int psi_i Ntilde_k = delta_ik int Ntilde_k, the psi_i sum to 1, the modified functions
    integrate to positive weights (2/15 and 1/5 of the triangle's area; the 9-node
    quadrilateral's 1/36, 1/9, 4/9 unmodified)."""
    import basix
    from rough_contact.fem.nodal import quadratic_dual
    T, A = quadratic_dual(facet)
    ct = getattr(basix.CellType, cell)
    X, w = basix.make_quadrature(ct, 8)
    N = basix.create_element(basix.ElementFamily.P, ct, 2,
                             basix.LagrangeVariant.equispaced).tabulate(0, X)[0, :, :, 0].T
    Nt, psi = T @ N, A @ T @ N
    m = Nt @ w
    np.testing.assert_allclose((psi * w) @ Nt.T, np.diag(m), atol=1e-14)
    np.testing.assert_allclose(psi.sum(axis=0), 1.0, atol=1e-13)
    np.testing.assert_allclose(Nt.sum(axis=0), 1.0, atol=1e-13)
    expect = ([2 / 15] * 3 + [1 / 5] * 3 if facet == "triangle6"
              else [1 / 36] * 4 + [1 / 9] * 4 + [4 / 9])
    np.testing.assert_allclose(m / area, expect, rtol=1e-13)
    with pytest.raises(ValueError, match="facet = 'triangle3' is invalid"):
        quadratic_dual("triangle3")


def test_punch_reference_spacing_same_answer_and_spacing():
    """``NewtonAugmentedLagrangian(reference_spacing=h)`` (the penalty scaled by h / h_j at
    each vertex) reaches the fixed point of the uniform penalty: the same dissipation history
    and vertex tractions, serially and on all ranks; the vertex spacing h_j of the punch's
    contact surface (mesh size 2 mm there) has its median within 25 % of 2 mm. The
    quadrature point set, which has no spacing, refuses it."""
    from rough_contact.scenes import flat_punch
    enf = NewtonAugmentedLagrangian(tolerance=1e-8, max_updates=30, reference_spacing=2.0)
    D_u, t_u, _ = _punch(NewtonAugmentedLagrangian(tolerance=1e-8, max_updates=30),
                         MPI.COMM_SELF, "dual")
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        D, t, (stick_err, n_stick) = _punch(enf, comm, "dual")
        assert n_stick > 0 and stick_err <= 1e-7
        np.testing.assert_allclose(D, D_u, rtol=1e-5, atol=1e-6 * D_u[-1])
        np.testing.assert_allclose(t, t_u, rtol=0, atol=1e-5 * np.abs(t_u).max())
    law = SoftplusPenalty(k_normal=1e7, width=2.5e-9, k_tangential=1e7, friction=0.2)
    m = flat_punch.build(MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.0, order=1,
                         load_half_width=10.0, law=law, steps=4, points="nodal", basis="dual",
                         enforcement=enf, prefix="test_ssn_spacing_")
    h = np.concatenate(MPI.COMM_WORLD.allgather(m.interface.point_spacing))
    m.solver.destroy()
    assert h.size > 20 and 0.75 * 2.0 < np.median(h) < 1.25 * 2.0, np.median(h)
    with pytest.raises(ValueError, match="only the nodal point set knows"):
        flat_punch.build(MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.0, order=1,
                         load_half_width=10.0, law=law, steps=4, points="quadrature",
                         enforcement=enf, prefix="test_ssn_spacing_q_")
