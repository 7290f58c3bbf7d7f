"""SoftplusPenalty.reversal_stiffness (the Newton-step tangent at points whose slip direction
reversed, docs/coulomb.md): the same converged path as the consistent tangent, fewer Newton
iterations, serial and in parallel."""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem import compat
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import load_path, load_unload_factors

N_LOAD = 8
MESH = (10.0, 1.2)   # (mesh size, contact size) [mm]


def _run(reversal_stiffness):
    k = 1e7
    law = SoftplusPenalty(k_normal=k, width=1e-2 * 2.5 / k, k_tangential=k, friction=0.2,
                          reversal_stiffness=reversal_stiffness)
    m = flat_punch.build(MPI.COMM_WORLD, mesh_size=MESH[0], contact_size=MESH[1], order=1,
                         load_half_width=10.0, law=law, steps=N_LOAD)
    factors = load_unload_factors(N_LOAD, N_LOAD - 1, final_factor=1.0 / N_LOAD)
    incs = list(load_path(m.problem, m.solver, factors, verbose=False))
    # partition-independent (two builds may partition the mesh differently)
    u = np.array([compat.petsc_vector(m.problem.u).norm(n) for n in (PETSc.NormType.NORM_1,
                                                      PETSc.NormType.NORM_2,
                                                      PETSc.NormType.NORM_INFINITY)])
    m.solver.destroy()
    return incs, u



def test_reversal_stiffness_same_path_fewer_iterations():
    a, ua = _run(0.0)      # consistent tangent everywhere
    b, ub = _run(1.0)      # the default
    assert [i.load_factor for i in a] == [i.load_factor for i in b]
    assert sum(i.cutbacks for i in a) == sum(i.cutbacks for i in b) == 0
    for x, y in zip(a, b):
        np.testing.assert_allclose(y.contact_force, x.contact_force, rtol=0,
                                   atol=1e-9 * abs(x.contact_force[2]))
        assert y.dissipation == pytest.approx(x.dissipation, rel=1e-9, abs=1e-18)
    np.testing.assert_allclose(ub, ua, rtol=1e-9, atol=0)   # |u|_1, |u|_2, |u|_inf at the end
    assert sum(i.newton_total for i in b) < sum(i.newton_total for i in a)
