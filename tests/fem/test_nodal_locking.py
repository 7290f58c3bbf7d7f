"""No locking: exact frictionless contact of a rigid paraboloid on a nearly incompressible
(nu = 0.49) P2 block, with the nodal point set (``NodalContactInterface``), against the plain
penalty route's k -> infinity limit on the same mesh; the per-quadrature-point augmented
Lagrangian (6 exact constraints per P2 facet) locks on the same problem: its multiplier
iteration does not converge. Serial and 2 ranks.

Reference (not this module's code): ``ContactInterface`` with the penalty ``SoftplusPenalty`` at
k = 1e9 and 1e10 MPa/mm on the Gauss points, extrapolated to k -> infinity as F(k) = F_inf + c/k
(a penalty adds the compliance 1/k in series; the stiff penalty does not lock on this mesh:
its force rises with k by the expected 1/k amount).
"""

from __future__ import annotations

import warnings

import pytest
from mpi4py import MPI

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.interface.enforcement import AugmentedLagrangian, Penalty
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import indented_block
from rough_contact.scenes.mindlin import ParaboloidIndenter
from rough_contact.solver.loading import LoadStepError, load_path
from rough_contact.solver.snes import SNESSolver

E, NU, RADIUS, DELTA = 2.0e5, 0.49, 10.0, 4e-3     # MPa, -, mm, mm


@pytest.fixture(scope="module")
def scene():
    s = indented_block(half_width=1.0, height=1.0, mesh_size=0.5, contact_size=0.05,
                       transition=0.5, refined_radius=0.3, order=2, comm=MPI.COMM_WORLD)
    V = vector_space(s.mesh, 2)
    bcs = [fix(V, s.facet_tags, s.tag("symmetry_x"), 0),
           fix(V, s.facet_tags, s.tag("symmetry_y"), 1)]
    return s, V, bcs


def _force(scene, route, k):
    """Indenter force of the whole block [N] (4 x the quarter's bottom reaction)."""
    s, V, bcs = scene
    law = SoftplusPenalty(k, 1e-6 * DELTA)
    enforcement = Penalty() if route == "penalty" else AugmentedLagrangian(1e-4, 15)
    kind = NodalContactInterface if route == "nodal" else ContactInterface
    with warnings.catch_warnings():          # the per-point route warns that it locks
        warnings.simplefilter("ignore", UserWarning)
        ci = kind(V, s.facet_tags, s.tag("contact"), law=law, rigid=ParaboloidIndenter(RADIUS),
                  bcs=bcs, quadrature_degree=4, enforcement=enforcement)
    problem = ContactProblem(
        V, Material(E, NU), bcs, facet_tags=s.facet_tags, interface=ci,
        prescribed=[PrescribedDisplacement(s.tag("bottom"), (0.0, 0.0, DELTA), (0, 1, 2))])
    solver = SNESSolver(problem, prefix="test_locking_")
    try:
        list(load_path(problem, solver, [1.0], verbose=False, min_increment=1.0))
        return 4.0 * problem.reaction(s.tag("bottom"))[2]
    finally:
        solver.destroy()


def test_nodal_exact_contact_does_not_lock(scene):
    f9, f10 = _force(scene, "penalty", 1e9), _force(scene, "penalty", 1e10)
    limit = f10 + (f10 - f9) / 9.0
    assert 0.0 < f10 - f9 < 0.01 * f10           # the penalty converges like 1/k
    nodal = _force(scene, "nodal", 1e8)
    assert abs(nodal / limit - 1.0) < 0.01, (nodal, limit)
    with pytest.raises(LoadStepError, match="multipliers still moved"):
        _force(scene, "perpoint", 1e8)
