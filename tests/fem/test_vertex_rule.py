"""The nodal ("vertex") interface quadrature and the secant predictor (serial and 2 ranks).

Vertex rule: weights are the facet area shared equally by its vertices, so it integrates
linear fields exactly on triangles (checked against closed-form integrals of 1, x, y),
transmits a uniform jump exactly (force = k jump area), gives the same Jacobian as a central
finite difference of its residual (stick and slip), evaluates the law once per node (points of
neighbouring facets at one node see the same jump), and is refused for P2.

Secant predictor: the rough-law punch (P1 coarse, friction case b) gives the same increments
with ``predictor="secant"`` as with ``"none"`` to the Newton tolerance, with fewer iterations.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.solver.loading import load_path, load_unload_factors

from test_contact import (LOWER_TOP, UPPER_BOTTOM, fd_check, interpolate_bodies,  # noqa: E402
                          smooth_field, two_blocks, vec_copy)


def _interface(law, n=(3, 2, 1), size=(1.3, 0.7, 0.4), degree=1):
    msh, tags = two_blocks(MPI.COMM_WORLD, n=n, size=size)
    V = compat.vector_space(msh, degree)
    return V, ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=law, quadrature="vertex")


def test_vertex_rule_integrates_linear_fields_exactly():
    Lx, Ly = 1.3, 0.7
    V, ci = _interface(LinearPenalty(1.0))
    x, w = ci.point_coordinates(), ci.point_weights()
    comm = MPI.COMM_WORLD
    got = comm.allreduce(np.array([w.sum(), w @ x[:, 0], w @ x[:, 1]]), op=MPI.SUM)
    exact = [Lx * Ly, Lx**2 / 2 * Ly, Lx * Ly**2 / 2]
    np.testing.assert_allclose(got, exact, rtol=1e-13)
    # 3 points per triangle, all at vertices of the structured patch
    assert ci.n_points_global == 3 * 2 * 3 * 2
    grid = np.round(x[:, :2] / [Lx / 3, Ly / 2], 9)
    np.testing.assert_allclose(grid, np.round(grid), atol=1e-8)


def test_vertex_rule_uniform_jump_and_one_state_per_node():
    kn, kt = 3e3, 1e3
    V, ci = _interface(LinearPenalty(kn, kt))
    d = np.array([2e-3, -1e-3, -5e-4])
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: np.outer(d * up, np.ones(x.shape[1])))
    ci.evaluate(u)
    np.testing.assert_allclose(ci.contact_force(), np.array([kt * d[0], kt * d[1], kn * d[2]])
                               * 1.3 * 0.7, rtol=1e-12)
    # a smooth field: every point at one node has the same jump (nodal evaluation)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, 1e-3))
    jump = ci.jump(u)
    key = np.round(ci.point_coordinates(), 10)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    for node in range(inverse.max(initial=-1) + 1):     # (a rank may own no point)
        same = jump[inverse == node]
        np.testing.assert_allclose(same, np.broadcast_to(same[:1], same.shape), atol=1e-15)


@pytest.mark.parametrize("regime", ["stick", "slip"])
def test_vertex_rule_jacobian_finite_difference(regime):
    mu, scale = (0.3, 1e-6) if regime == "stick" else (0.05, 2e-3)
    V, ci = _interface(SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=mu), n=(2, 3, 1))
    u = fem.Function(V)
    interpolate_bodies(u, lambda x, up: smooth_field(x, up, scale))
    x = vec_copy(V, u)
    n_slip = MPI.COMM_WORLD.allreduce(int(ci.evaluate(x).slipping.sum()))
    assert (n_slip == 0) if regime == "stick" else (n_slip > ci.n_points_global // 2)
    assert fd_check(ci, V, x, 1e-9 * scale / 1e-3, np.random.default_rng(3)) < 1e-6


def test_vertex_rule_is_refused_for_p2_and_bad_names():
    with pytest.raises(ValueError, match="quadrature = 'vertex' needs a degree-1 space"):
        _interface(LinearPenalty(1.0), degree=2)
    msh, tags = two_blocks(MPI.COMM_WORLD)
    V = compat.vector_space(msh, 1)
    with pytest.raises(ValueError, match="quadrature = 'lobatto' is invalid"):
        ContactInterface(V, tags, LOWER_TOP, UPPER_BOTTOM, law=LinearPenalty(1.0),
                         quadrature="lobatto")


def test_secant_predictor_same_result_fewer_iterations():
    from rough_contact.scenes import flat_punch

    out = {}
    for pred in ("none", "secant"):
        m = flat_punch.build(MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.5, order=1,
                             case="b", normal_law="elastic", steps=4)
        out[pred] = list(load_path(m.problem, m.solver, load_unload_factors(4, 3),
                                   verbose=False, predictor=pred))
        m.solver.destroy()
    a, b = out["none"], out["secant"]
    assert [i.load_factor for i in a] == [i.load_factor for i in b]
    for x, y in zip(a, b):
        np.testing.assert_allclose(y.contact_force, x.contact_force, rtol=0,
                                   atol=1e-7 * abs(x.contact_force[2]))
        assert y.dissipation == pytest.approx(x.dissipation, rel=1e-6, abs=1e-15)
    assert sum(i.iterations for i in b) < sum(i.iterations for i in a)
    m = flat_punch.build(MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.5, order=1,
                         case="none", normal_law="elastic", steps=2)
    with pytest.raises(ValueError, match="predictor = 'tangent' is invalid: it must be one of "
                       "secant, none"):
        next(load_path(m.problem, m.solver, [0.5], predictor="tangent"))
