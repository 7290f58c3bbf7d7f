"""Alart–Curnier's semismooth Newton with the tractions condensed through the dual basis
(``SemismoothNewton``; rough_contact.fem.condensation; docs/exact_contact_newton.md).

* Patch test: two blocks pressed by a uniform pressure, Coulomb mu = 0.3, conforming P1,
  mortar P1 and conforming Q1: every vertex carries the pressure to round-off, the gap is closed,
  no shear; a linear problem once the contact set is right: at most 2 Newton iterations per
  increment; serial = 2 ranks.
* The condensed Jacobian equals central differences of the condensed residual at a state
  with open, sticking and slipping vertices (mortar P1, non-matching meshes).
* GetFEM's flat punch on a coarse mesh (P1, mu = 0.2, loading and unloading): the same
  dissipation history and vertex tractions as the multipliers updated inside Newton
  (``NewtonAugmentedLagrangian``, a different iteration whose fixed point is the same up to
  its softplus smoothing), in fewer Newton iterations; serial = 2 ranks.
* P2/Q2 with the quadratic dual basis (``basis="dual_quadratic"``: a point at every node of
  the first surface, rows combined by T; docs/exact_contact_newton.md, section 4): the same
  patch test (conforming and mortar P2, conforming Q2) and the Jacobian check (mortar P2).
* Refusals: the standard basis; the first-order dual basis on P2, the quadratic on P1.

Run serial and in parallel:
    .venv/bin/python -m pytest tests/fem/test_semismooth.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_semismooth.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem import compat
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian, SemismoothNewton
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.solver.loading import load_path, load_unload_factors
from rough_contact.solver.snes import SNESSolver

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared checks
from interface_checks import blocks_on_rollers, central_difference  # noqa: E402

E, NU, PRESSURE, MU = 2.0e5, 0.25, 80.0, 0.3
LAW = SoftplusPenalty(1e6, 1e-7, k_tangential=1e6, friction=MU)



def _blocks(comm, pairing, cell_type="tetrahedron", order=1, basis="dual", shear=0.0):
    scene, V, bcs = blocks_on_rollers(comm, pairing, order, cell_type)
    ci = NodalContactInterface(V, scene.facet_tags, *scene.contact_pair, law=LAW, bcs=bcs,
                               quadrature_degree=2 * order, pairing=pairing, basis=basis,
                               enforcement=SemismoothNewton())
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(E, NU)}
    problem = ContactProblem(V, mats, bcs,
                             [SurfaceLoad(scene.tag("top"), traction=[shear, 0, -PRESSURE])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    return problem, ci


def _patch(comm, pairing, cell_type, order=1, basis="dual"):
    problem, ci = _blocks(comm, pairing, cell_type, order=order, basis=basis)
    solver = SNESSolver(problem, prefix="test_semismooth_")
    incs = list(load_path(problem, solver, [0.5, 1.0], verbose=False))
    pf = ci.point_fields()
    x = np.concatenate(comm.allgather(ci.point_coordinates()))
    order = np.lexsort(x.T)
    out = dict(incs=incs, force=ci.contact_force(),
               pressure=np.concatenate(comm.allgather(pf.pressure))[order],
               shear=np.concatenate(comm.allgather(pf.shear))[order],
               gap=np.concatenate(comm.allgather(pf.gap))[order],
               slipping=comm.allreduce(int(pf.slipping.sum()), op=MPI.SUM))
    solver.destroy()
    return out


PATCH = [("conforming", "tetrahedron", 1, "dual"), ("mortar", "tetrahedron", 1, "dual"),
         ("conforming", "hexahedron", 1, "dual"),
         ("conforming", "tetrahedron", 2, "dual_quadratic"),
         ("mortar", "tetrahedron", 2, "dual_quadratic"),
         ("conforming", "hexahedron", 2, "dual_quadratic")]


@pytest.mark.parametrize("pairing,cell,order,basis", PATCH,
                         ids=lambda c: c if isinstance(c, str) else f"P{c}")
def test_patch_exact_and_rank_independent(pairing, cell, order, basis):
    """P1/Q1 with the dual basis; P2/Q2 with the quadratic dual basis (a point at every
    first-surface node, the rows combined by T)."""
    world = _patch(MPI.COMM_WORLD, pairing, cell, order, basis)
    assert all(i.cutbacks == 0 and i.newton_total <= 2 for i in world["incs"])
    np.testing.assert_allclose(world["pressure"], PRESSURE, rtol=0, atol=1e-9 * PRESSURE)
    assert np.max(np.abs(world["shear"])) <= 1e-9 * PRESSURE and world["slipping"] == 0
    assert np.max(np.abs(world["gap"])) <= 1e-14      # closed exactly (mm; u ~ 1e-4 mm)
    np.testing.assert_allclose(world["force"], [0.0, 0.0, PRESSURE], atol=1e-9 * PRESSURE)
    serial = _patch(MPI.COMM_SELF, pairing, cell, order, basis)
    np.testing.assert_allclose(world["pressure"], serial["pressure"], rtol=0,
                               atol=1e-10 * PRESSURE)


@pytest.mark.parametrize("order,basis", [(1, "dual"), (2, "dual_quadratic")])
def test_condensed_jacobian_against_finite_differences(order, basis):
    """J v = (H(u + e v) - H(u - e v)) / 2e at a state with open, sticking and slipping
    vertices (a random displacement near the contact state; no branch changes within e)."""
    comm = MPI.COMM_WORLD
    problem, ci = _blocks(comm, "mortar", order=order, basis=basis)
    problem.set_load_factor(1.0)
    rng = np.random.default_rng(7 + comm.rank)
    x = problem.solution_vector().copy()
    xyz = problem.owned_dof_coordinates()
    u = x.array.reshape(-1, 3)
    u[:, 2] = (-1e-4 * (xyz[:, 2] + 0.5) + 1e-3 * (xyz[:, 2] > 0.0) * (xyz[:, 0] - 0.5)
               + 1e-6 * rng.standard_normal(u.shape[0]))      # tilted: open where x > 0.5
    u[:, 0] = 1e-6 * rng.standard_normal(u.shape[0])
    compat.set_bc(x, problem.bcs)
    b = x.duplicate()
    problem.F(None, x, b)
    branches = ci._condensed_iterate
    n_open, n_slip, n_stick = (comm.allreduce(int(a.sum()), op=MPI.SUM) for a in (
        ~branches.contact, branches.slipping, branches.contact & ~branches.slipping))
    assert n_open > 0 and n_slip > 0 and n_stick > 0, (n_open, n_slip, n_stick)
    problem.J(None, x, problem.A, problem.A)
    v = x.duplicate()
    v.array[:] = rng.standard_normal(v.array.size)
    compat.set_bc(v, problem.bcs)      # Newton never moves a Dirichlet DOF (rollers at 0)
    Jv = x.duplicate()
    problem.A.mult(v, Jv)

    def same_branches():
        same = (np.array_equal(ci._condensed_iterate.contact, branches.contact)
                and np.array_equal(ci._condensed_iterate.slipping, branches.slipping))
        assert comm.allreduce(int(not same), op=MPI.SUM) == 0

    fd = central_difference(lambda xs, bs: problem.F(None, xs, bs), x, v, 1e-9,
                            check=same_branches).array
    scale = comm.allreduce(float(np.abs(fd).max(initial=0.0)), op=MPI.MAX)
    err = comm.allreduce(float(np.abs(fd - Jv.array).max(initial=0.0)), op=MPI.MAX)
    assert err <= 1e-6 * scale


def _punch(enforcement, comm=MPI.COMM_WORLD, snes_rtol=None):
    """The coarse punch of tests/fem/test_nodal_ssn.py: dissipation per increment, vertex
    tractions at the end, Newton iterations. ``snes_rtol`` overrides the solver's relative
    tolerance (1e-9 by default, which leaves the answer uncertain at that level)."""
    from rough_contact.scenes import flat_punch
    law = SoftplusPenalty(k_normal=1e7, width=2.5e-9, k_tangential=1e7, friction=0.2)
    m = flat_punch.build(comm, mesh_size=20.0, contact_size=2.0, order=1,
                         load_half_width=10.0, law=law, steps=4, points="nodal", basis="dual",
                         enforcement=enforcement, prefix="test_semismooth_punch_",
                         solver_options=dict(linear_solver="mumps"),
                         solver_defaults=None if snes_rtol is None else {"snes_rtol": snes_rtol})
    incs = list(load_path(m.problem, m.solver, load_unload_factors(4, 3, final_factor=0.25)))
    pf = m.interface.point_fields()
    x = np.concatenate(comm.allgather(m.interface.point_coordinates()))
    order = np.lexsort(x.T)
    t = np.concatenate(comm.allgather(np.column_stack([pf.pressure, pf.shear])))[order]
    m.solver.destroy()
    return (np.array([i.dissipation for i in incs]), t, sum(i.newton_total for i in incs),
            sum(i.cutbacks for i in incs))


@pytest.fixture(scope="module")
def punch_ssn():
    return _punch(SemismoothNewton())


def test_punch_same_answer_as_in_newton_multipliers(punch_ssn):
    D, t, newton, cutbacks = punch_ssn
    D_a, t_a, newton_a, _ = _punch(NewtonAugmentedLagrangian(tolerance=1e-8, max_updates=30))
    assert cutbacks == 0 and D[-1] > 0.0
    np.testing.assert_allclose(D, D_a, rtol=1e-5, atol=1e-6 * D_a[-1])
    np.testing.assert_allclose(t, t_a, rtol=0, atol=1e-5 * np.abs(t_a).max())
    assert newton < newton_a


def test_punch_rank_independent():
    # The default relative tolerance (1e-9) stops Newton once the residual is 1e-9 of its
    # start, so two partitions may stop at answers that differ at that level (measured: 6e-10
    # relative on DOLFINx 0.9). Converging both to round-off (one more quadratic iteration)
    # makes the comparison measure the partition, not the stopping test.
    D, t, _, _ = _punch(SemismoothNewton(), snes_rtol=1e-13)
    D_s, t_s, _, _ = _punch(SemismoothNewton(), MPI.COMM_SELF, snes_rtol=1e-13)
    np.testing.assert_allclose(D, D_s, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(t, t_s, rtol=0, atol=1e-10 * np.abs(t_s).max())


@pytest.mark.parametrize("order,basis,match", [(1, "standard", "basis = 'standard'"),
                                               (2, "dual", "displacement degree 2"),
                                               (1, "dual_quadratic", "displacement degree 1")])
def test_refused(order, basis, match):
    with pytest.raises(ValueError, match=match):
        _blocks(MPI.COMM_WORLD, "conforming", order=order, basis=basis)


def test_direct_solver_at_any_size_and_amg_refused():
    """The condensed system has constraint rows without an elastic diagonal: the size rule
    keeps MUMPS above its threshold, and an AMG set is refused naming it (hypre's GMRES
    diverged at the punch's first solve)."""
    problem, _ = _blocks(MPI.COMM_WORLD, "conforming")
    assert problem.condensed
    solver = SNESSolver(problem, prefix="test_semismooth_size_", dof_threshold=0)
    assert solver.option_set == "mumps"
    solver.destroy()
    for name in ("hypre", "gamg"):
        with pytest.raises(ValueError, match=f"linear solver = '{name}' is invalid for the "
                                             "semismooth"):
            SNESSolver(problem, prefix="test_semismooth_amg_", linear_solver=name)
