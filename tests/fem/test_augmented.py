"""Augmented-Lagrangian (Uzawa) enforcement of a penalty law, ``AugmentedLagrangian()``: exact
stick and exact contact against a clamped elastic block solved without any contact code,
penalty independence on the Coulomb punch, and the multipliers restored after a failed step.
Serial and on 2 ranks (every figure compared is partition-independent)."""

from __future__ import annotations

import contextlib
import warnings

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem

from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.enforcement import AugmentedLagrangian, Penalty
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes import flat_punch
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.solver.loading import LoadStepError, load_path, load_unload_factors
from rough_contact.solver.snes import SNESSolver

E, NU, H = 1.0e3, 0.0, 0.5          # MPa, -, mm
P, Q, MU = 1.0, 0.05, 1.0           # pressure and shear on the top [MPa], friction


def _block(order):
    scene = block_on_plane(lx=1.0, ly=1.0, h=H, mesh_size=0.25, order=order)
    V = compat.vector_space(scene.mesh, order)
    return scene, V


def _load(scene):
    return [SurfaceLoad(scene.tag("top"), traction=[Q, 0.0, -P])]


def _clamped(scene, V):
    """The block with its bottom clamped (u = 0): the exact-stick, exact-contact solution,
    computed by a linear solve without any contact code."""
    facets = scene.facet_tags.find(scene.tag("contact"))
    bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType),
                         fem.locate_dofs_topological(V, 2, facets), V)
    problem = ContactProblem(V, Material(E, NU), [bc], _load(scene),
                             facet_tags=scene.facet_tags)
    solver = SNESSolver(problem, prefix="aug_clamped_")
    problem.set_load_factor(1.0)
    assert solver.solve().converged
    solver.destroy()
    return problem.u


def _on_plane(scene, V, augmented, k, **kwargs):
    law = SoftplusPenalty(k_normal=k, width=1e-6 * P / k, k_tangential=k, friction=MU)
    enforcement = AugmentedLagrangian(**kwargs) if augmented else Penalty()
    order = compat.element_degree(V)
    if order == 1:
        ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law,
                              rigid_plane=scene.rigid_plane, quadrature="vertex",
                              enforcement=enforcement)
    else:
        # 6 Gauss points per P2 facet: over-constrained where stick ends (the interface warns);
        # this block sticks everywhere, so the exact solution is still reached
        expected = (pytest.warns(UserWarning, match="constraints lock") if augmented
                    else contextlib.nullcontext())
        with expected:
            ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law,
                                  rigid_plane=scene.rigid_plane, quadrature_degree=2 * order,
                                  enforcement=enforcement)
    problem = ContactProblem(V, Material(E, NU), [], _load(scene), facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="aug_plane_")
    return problem, solver, ci


def _max_diff(u, v):
    n = u.function_space.dofmap.index_map.size_local * 3
    d = np.max(np.abs(u.x.array[:n] - v.x.array[:n]), initial=0.0)
    return u.function_space.mesh.comm.allreduce(d, op=MPI.MAX)


def _max_abs(u):
    n = u.function_space.dofmap.index_map.size_local * 3
    return u.function_space.mesh.comm.allreduce(np.max(np.abs(u.x.array[:n]), initial=0.0),
                                                op=MPI.MAX)


@pytest.mark.parametrize("order", [1, 2])
def test_exact_stick_and_contact_equal_the_clamped_block(order):
    """A block pressed on a rigid plane with friction mu = 1 and sheared by Q = 0.05 P sticks
    everywhere, so with exact constraints its displacement is that of the block with a clamped
    bottom. The penalty alone (k = 50 E / h_mesh: its compliance is 1 % of the block's) misses
    it by its elastic slip and penetration; the augmented Lagrangian with the same k reaches it
    to the multiplier tolerance. P1 with the vertex rule, P2 with the Gauss rule."""
    scene, V = _block(order)     # one mesh for all runs: the DOF layouts agree on every rank
    reference = _clamped(scene, V)
    scale = _max_abs(reference)
    k = 50.0 * E / 0.25
    errors = {}
    for augmented in (False, True):
        # the tolerance must stay above the Newton solves' own accuracy (rtol 1e-9 of the
        # step's first residual): the multiplier changes stall at about 1e-9
        extra = dict(tolerance=1e-7, max_updates=60) if augmented else {}
        problem, solver, ci = _on_plane(scene, V, augmented, k, **extra)
        incs = list(load_path(problem, solver, [1.0], verbose=False))
        assert incs[-1].n_slipping == 0 and incs[-1].n_active == incs[-1].n_points
        assert (incs[-1].augmentations > 0) == augmented
        # force balance: the interface carries the applied load
        np.testing.assert_allclose(incs[-1].contact_force, [-Q, 0.0, P], rtol=0, atol=1e-9)
        errors[augmented] = _max_diff(problem.u, reference) / scale
        solver.destroy()
    assert errors[False] > 3e-3                       # the penalty's compliance shows
    assert errors[True] < 1e-8, errors


N_LOAD = 6
PUNCH = (10.0, 1.2)   # (mesh size, contact size) [mm]


def _punch(k, augmented, mu=0.5, predictor="secant"):
    law = SoftplusPenalty(k_normal=k, width=1e-2 * 2.5 / k, k_tangential=k, friction=mu)
    enforcement = AugmentedLagrangian(tolerance=1e-4) if augmented else Penalty()
    m = flat_punch.build(MPI.COMM_WORLD, mesh_size=PUNCH[0], contact_size=PUNCH[1], order=1,
                         load_half_width=10.0, law=law, steps=N_LOAD, quadrature="vertex",
                         enforcement=enforcement)
    factors = load_unload_factors(N_LOAD, N_LOAD - 1, final_factor=1.0 / N_LOAD)
    incs = list(load_path(m.problem, m.solver, factors, verbose=False, predictor=predictor))
    m.solver.destroy()
    return incs


def test_penalty_independent_coulomb_punch():
    """GetFEM's flat punch (coarse, mu = 0.5, vertex rule), 6 + 5 increments: the dissipation
    and the slip counts of the augmented law do not move when the penalty is multiplied by
    10, while those of the plain penalty move by several per cent; the augmented results
    agree with the plain penalty's k -> infinity limit (Richardson, first order in 1/k)."""
    aug = {k: _punch(k, True) for k in (1e6, 1e7)}
    plain = {k: _punch(k, False) for k in (1e8, 1e9)}
    for incs in list(aug.values()) + list(plain.values()):
        assert sum(i.cutbacks for i in incs) == 0
    d_aug = {k: np.array([i.dissipation for i in v]) for k, v in aug.items()}
    d_plain = {k: np.array([i.dissipation for i in v]) for k, v in plain.items()}
    end = d_aug[1e7][-1]
    assert end > 0.0
    assert abs(d_aug[1e6][-1] / end - 1.0) < 2e-3
    assert abs(d_plain[1e8][-1] / d_plain[1e9][-1] - 1.0) > 5 * abs(d_aug[1e6][-1] / end - 1.0)
    limit = d_plain[1e9] + (d_plain[1e9] - d_plain[1e8]) / 9.0   # D(k) ~ D_inf + c / k
    np.testing.assert_allclose(d_aug[1e7][-1], limit[-1], rtol=3e-3)
    slips = [[i.n_slipping for i in v] for v in aug.values()]
    assert max(abs(a - b) for a, b in zip(*slips)) <= 0.01 * aug[1e7][0].n_points
    # the multipliers' secant predictor saves solves, not accuracy
    cold = _punch(1e7, True, predictor="none")
    assert cold[-1].dissipation == pytest.approx(end, rel=1e-3)
    assert sum(i.newton_total for i in aug[1e7]) < sum(i.newton_total for i in cold)
    assert sum(i.augmentations for i in aug[1e7]) < sum(i.augmentations for i in cold)


def test_failed_updates_restore_the_multipliers():
    """More multiplier updates than allowed is a convergence failure: the step is reverted
    (multipliers included) and cut back, and finally a LoadStepError names the cause."""
    problem, solver, ci = _on_plane(*_block(1), True, 0.1 * E / H,
                                    tolerance=1e-12, max_updates=2)
    before = ci.history.multipliers.copy()
    with pytest.raises(LoadStepError, match="augmented Lagrangian: the multipliers still moved"):
        list(load_path(problem, solver, [1.0], verbose=False, min_increment=0.3))
    np.testing.assert_array_equal(ci.history.multipliers, before)
    solver.destroy()


def test_checkpoint_keeps_the_multipliers(tmp_path):
    """A run stopped after two increments and resumed from its checkpoint ends where the
    uninterrupted run ends, to round-off: the multipliers (which start each increment) are
    part of the checkpoint. With a loose multiplier tolerance the converged state depends on
    where the multipliers start, so losing them would show far above round-off."""
    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path / "ckpt"), root=0)
    scene, V = _block(1)
    factors = [0.4, 0.8, 1.0, 0.6, 0.9]
    k = 50.0 * E / 0.25
    opts = dict(tolerance=1e-2, max_updates=60)

    problem, solver, _ = _on_plane(scene, V, True, k, **opts)
    ref = list(load_path(problem, solver, factors, verbose=False))
    u_ref = problem.u.x.array.copy()
    solver.destroy()

    problem, solver, _ = _on_plane(scene, V, True, k, **opts)
    list(load_path(problem, solver, factors, verbose=False, checkpoint=directory, max_steps=2))
    solver.destroy()
    problem, solver, ci = _on_plane(scene, V, True, k, **opts)
    resumed = list(load_path(problem, solver, factors, verbose=False, resume=directory))
    solver.destroy()
    assert [i.step for i in resumed] == [3, 4, 5]
    assert [i.augmentations for i in resumed] == [i.augmentations for i in ref[2:]]
    n = V.dofmap.index_map.size_local * 3
    err = comm.allreduce(np.max(np.abs(problem.u.x.array[:n] - u_ref[:n]), initial=0.0),
                         op=MPI.MAX)
    assert err <= 1e-12 * _max_abs(problem.u)
    # a fresh start of the last three increments (multipliers from zero) differs visibly
    problem, solver, _ = _on_plane(scene, V, True, k, **opts)
    list(load_path(problem, solver, factors[2:], verbose=False))
    solver.destroy()
    fresh = comm.allreduce(np.max(np.abs(problem.u.x.array[:n] - u_ref[:n]), initial=0.0),
                           op=MPI.MAX)
    assert fresh > 1e3 * max(err, 1e-16 * _max_abs(problem.u))


@pytest.mark.parametrize("order", [1, 2])
def test_overconstraining_gauss_rule_warns(order):
    """Exact constraints at more points per facet than surface nodes per facet (P1: 3 Gauss
    points against 0.5 nodes; P2: 3 against 2) lock: the interface warns and names the
    remedy. The vertex rule (P1), a 1-point rule (P2) and a plain penalty do not warn."""
    scene, V = _block(order)
    law = SoftplusPenalty(k_normal=1e5, width=1e-9, k_tangential=1e5, friction=MU)
    remedy = "use quadrature='vertex'" if order == 1 else "at most 2 point"
    with pytest.warns(UserWarning, match=remedy):
        ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law,
                         rigid_plane=scene.rigid_plane, quadrature_degree=2,
                         enforcement=AugmentedLagrangian())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law,
                         rigid_plane=scene.rigid_plane, enforcement=AugmentedLagrangian(),
                         **({"quadrature": "vertex"} if order == 1 else {"quadrature_degree": 1}))
        ContactInterface(V, scene.facet_tags, scene.tag("contact"),
                         law=SoftplusPenalty(k_normal=1e5, width=1e-9),
                         rigid_plane=scene.rigid_plane, quadrature_degree=2)
