"""Newton's penalty continuation (``rough_contact.solver.snes.Continuation``) on the stiff
Coulomb penalty law: a coarse flat punch at k = 1e9 MPa/mm whose unloading step plain Newton
cannot solve (the line search crawls, every cutback too: LoadStepError) completes with the
continuation, and where plain Newton converges the continuation converges to the same
solution. Serial and on 2 ranks."""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import LoadStepError, load_path
from rough_contact.solver.snes import Continuation

K = 1e9                       # [MPa/mm], ~3000 E/h on this mesh
MESH = (10.0, 1.2)            # (mesh size, contact size) [mm]
FACTORS = [0.25, 0.5, 0.75, 1.0, 0.75, 0.5]
MIN_INCREMENT = 0.2           # one halving of the 0.25 unloading step is below it


def _model(continuation):
    law = SoftplusPenalty(k_normal=K, width=1e-2 * 2.5 / K, k_tangential=K, friction=0.2)
    return flat_punch.build(MPI.COMM_WORLD, mesh_size=MESH[0], contact_size=MESH[1], order=1,
                            load_half_width=10.0, law=law, steps=4,
                            solver_options=dict(continuation=continuation))


def _follow(m):
    incs = []
    try:
        for inc in load_path(m.problem, m.solver, FACTORS, verbose=False,
                             min_increment=MIN_INCREMENT):
            incs.append(inc)
    except LoadStepError as exc:
        return incs, exc
    finally:
        m.solver.destroy()
    return incs, None


def test_stiff_coulomb_unloading_converges_with_continuation():
    plain, error = _follow(_model(None))
    # plain Newton fails at every cutback: in the second unloading step on DOLFINx 0.5.2's
    # mesh, already in the first increment on 0.9's (gmsh 4.13 meshes the punch differently)
    assert error is not None
    assert [i.load_factor for i in plain] == FACTORS[:len(plain)]
    assert error.last_converged == (plain[-1].load_factor if plain else 0.0)

    # continuation at every solve (after=0), so that the steps plain Newton solved are
    # solved through the softened laws too
    cont, error = _follow(_model(Continuation(factors=(100.0, 10.0), after=0)))
    assert error is None
    assert [i.load_factor for i in cont] == FACTORS
    assert sum(i.cutbacks for i in cont) == 0
    for a, b in zip(plain, cont):
        # the same solution where plain Newton converged (Newton tolerance rtol 1e-9)
        np.testing.assert_allclose(b.contact_force, a.contact_force, rtol=0,
                                   atol=1e-7 * abs(a.applied_force[2]))
        assert b.dissipation == pytest.approx(a.dissipation, rel=1e-6)
    for inc in cont:
        # equilibrium: the interface carries the applied load
        np.testing.assert_allclose(inc.contact_force[2], -inc.applied_force[2],
                                   rtol=1e-7)
    assert cont[-1].dissipation > cont[3].dissipation > 0.0


def test_continuation_bad_input():
    with pytest.raises(ValueError, match="continuation factors"):
        Continuation(factors=(10.0, 100.0))
    with pytest.raises(ValueError, match="continuation factor 0"):
        Continuation(factors=(0.5,))
    with pytest.raises(ValueError, match="after"):
        Continuation(after=-1)


def test_set_softening_needs_a_softenable_law():
    from rough_contact.interface.penalty import LinearPenalty
    m = flat_punch.build(MPI.COMM_WORLD, mesh_size=20.0, contact_size=5.0, order=1,
                         load_half_width=10.0, law=LinearPenalty(1e7, 1e7, unilateral=True),
                         steps=1)
    itf = m.interface
    assert not itf.softenable
    with pytest.raises(TypeError, match="cannot be softened"):
        itf.set_softening(10.0)
    with pytest.raises(ValueError, match="softening factor"):
        itf.set_softening(0.5)
    itf.set_softening(1.0)          # the law itself: always allowed
    assert itf.softening == 1.0
    m.solver.destroy()
