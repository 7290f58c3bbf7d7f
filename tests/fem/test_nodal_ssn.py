"""Multipliers updated inside the Newton iteration
(``rough_contact.interface.enforcement.NewtonAugmentedLagrangian`` on the nodal point set;
docs/exact_contact_newton.md: experimental, not faster than Uzawa's route on the punch yet).

* Patch test: two blocks pressed together by a uniform pressure, Coulomb friction mu = 0.3,
  conforming P1 and mortar P2: every vertex carries the pressure exactly (the shifted penalty
  would leave k |g| ~ p without the multiplier updates: checked on the gap), no shear, no
  slip; the multipliers were updated inside the Newton iteration; serial = 2 ranks to 1e-10.
* Bad arguments are refused with the quantity, its value and the valid range.

Run serial and in parallel:
    .venv/bin/python -m pytest tests/fem/test_nodal_ssn.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_nodal_ssn.py
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import separate_blocks, two_blocks
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

E, NU, PRESSURE, MU = 2.0e5, 0.25, 80.0, 0.3
K = 1e6          # penalty k_N = k_T [MPa/mm]


def _roller(V, scene, name, comp):
    facets = scene.facet_tags.find(scene.tag(name))
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, facets)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


def _patch(comm, pairing, order):
    """Uniform pressure on the top of two blocks on rollers, one increment."""
    if pairing == "conforming":
        scene = two_blocks(h1=1.0, h2=0.5, mesh_size=0.3, order=order, comm=comm)
    else:
        scene = separate_blocks(h1=1.0, h2=0.5, size_lower=0.2, size_upper=0.28, order=order,
                                comm=comm)
    V = compat.vector_space(scene.mesh, order)
    bcs = [_roller(V, scene, "x0", 0), _roller(V, scene, "y0", 1),
           _roller(V, scene, "bottom", 2)]
    law = SoftplusPenalty(K, 1e-7, k_tangential=K, friction=MU)
    ci = NodalContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                               quadrature_degree=2 * order, pairing=pairing,
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
        slipping=c.allreduce(int(pf.slipping.sum()), op=MPI.SUM))
    solver.destroy()
    return out


@pytest.mark.parametrize("pairing,order", [("conforming", 1), ("mortar", 2)])
def test_patch_exact_and_rank_independent(pairing, order):
    world = _patch(MPI.COMM_WORLD, pairing, order)
    assert world["incs"][-1].cutbacks == 0
    assert world["updates"] > 0                     # the route was taken
    np.testing.assert_allclose(world["pressure"], PRESSURE, rtol=0, atol=1e-8 * PRESSURE)
    assert np.max(np.abs(world["shear"])) <= 1e-8 * PRESSURE and world["slipping"] == 0
    # the penalty alone would leave k |g| = p - p(0); exact: the gap closes
    assert np.max(K * np.abs(world["gap"])) <= 1e-6 * PRESSURE
    np.testing.assert_allclose(world["force"], [0.0, 0.0, PRESSURE], atol=1e-8 * PRESSURE)
    serial = _patch(MPI.COMM_SELF, pairing, order)
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
