"""A tangential load beyond what friction can carry stops with a clear error instead of a
cutback spiral (serial and 2 ranks).

Two blocks (P1); the upper one is held only by the interface (Coulomb penalty, mu = 0.3): a
normal preload P is applied, then a tangential force ramps to Q_max on its top. Q_max = 0.2 P:
the program converges. Q_max = 0.5 P: the step at Q = 0.375 P (> mu P = 0.3 P) cannot converge
and ``load_path`` raises FrictionCapacityError naming 0.375 P, the capacity 0.3 P and the excess
(25 %), at once (no cutback). With the normal load applied by a prescribed displacement of the
top (no applied normal force), the capacity is mu times the normal force the interface carries,
checked against the reaction of the prescribed displacement (issue 24, item 9: it was
0.3 x 5e-17 N). Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.scenes.setup import clamped_pair
from rough_contact.solver.loading import FrictionCapacityError, load_path
from rough_contact.solver.snes import SNESSolver
from rough_contact.scenes.defaults import SEATING_STIFFNESS

MU, P = 0.3, 100.0
TIMES = [0.5, 1.0, 1.25, 1.5, 1.75, 2.0]


def _model(q_max):
    scene = two_blocks(h1=0.5, h2=0.5, mesh_size=0.5, order=1)
    V = compat.vector_space(scene.mesh, 1)
    clamp, ci = clamped_pair(scene, V, SoftplusPenalty(k_normal=1e7, width=1e-9,
                                                       k_tangential=1e7, friction=MU))
    top = scene.tag("top")
    problem = ContactProblem(
        V, Material(2e5, 0.3), [clamp],
        [SurfaceLoad(top, force=(0.0, 0.0, -P), channel="preload"),
         SurfaceLoad(top, force=(q_max, 0.0, 0.0), channel="shear")],
        facet_tags=scene.facet_tags, interface=ci, seating_tag=ci.first_tag,
        seating_stiffness=SEATING_STIFFNESS,
        programs={"preload": lambda t: min(t, 1.0), "shear": lambda t: max(t - 1.0, 0.0)})
    return problem, SNESSolver(problem, prefix="fc_")


def test_tangential_load_within_friction_converges():
    problem, solver = _model(0.2 * P)
    incs = list(load_path(problem, solver, TIMES, verbose=False))
    assert [i.load_factor for i in incs] == TIMES
    np.testing.assert_allclose(incs[-1].contact_force[:2], [-0.2 * P, 0.0], atol=1e-6 * P)
    solver.destroy()


def test_tangential_load_beyond_friction_stops_with_the_excess():
    problem, solver = _model(0.5 * P)
    done = []
    with pytest.raises(FrictionCapacityError, match=(
            r"load step to load factor 1.75 .* applied tangential force 37.5 N exceeds what "
            r"friction can carry, mu_max x normal force = 0.3 x 100 N = 30 N, by 7.5 N \(25 %\): "
            r"the body slides")) as err:
        for inc in load_path(problem, solver, TIMES, verbose=False):
            done.append(inc)
    assert [i.load_factor for i in done] == [0.5, 1.0, 1.25, 1.5]     # no cutback before
    assert err.value.tangential == pytest.approx(37.5) and err.value.capacity == pytest.approx(30)
    assert err.value.last_converged == 1.5
    solver.destroy()


def test_capacity_under_a_prescribed_normal_displacement():
    """The top is pressed by u_z = -5e-4 mm (a prescribed displacement: the applied normal force
    is 0) and pushed along x by a force ramping to 50 N: the step that cannot converge reports
    mu times the normal force the interface carried at the last converged increment, which is
    the z reaction of the prescribed top there."""
    scene = two_blocks(h1=0.5, h2=0.5, mesh_size=0.5, order=1)
    V = compat.vector_space(scene.mesh, 1)
    clamp, ci = clamped_pair(scene, V, SoftplusPenalty(k_normal=1e7, width=1e-9,
                                                       k_tangential=1e7, friction=MU))
    top = scene.tag("top")
    problem = ContactProblem(
        V, Material(2e5, 0.3), [clamp], [SurfaceLoad(top, force=(50.0, 0.0, 0.0),
                                                     channel="shear")],
        facet_tags=scene.facet_tags, interface=ci, seating_tag=ci.first_tag,
        seating_stiffness=SEATING_STIFFNESS,
        prescribed=[PrescribedDisplacement(top, (0.0, 0.0, -5e-4), (2,), channel="preload")],
        programs={"preload": lambda t: min(t, 1.0), "shear": lambda t: max(t - 1.0, 0.0)})
    solver = SNESSolver(problem, prefix="fcd_")
    done, reactions = [], []
    with pytest.raises(FrictionCapacityError, match="exceeds what friction can carry") as err:
        for inc in load_path(problem, solver, TIMES, verbose=False):
            done.append(inc)
            reactions.append(problem.reaction(top)[2])
    carried = abs(reactions[-1])
    assert carried > 10.0                               # pressed: tens of newtons
    assert err.value.capacity == pytest.approx(MU * carried, rel=1e-6)
    assert err.value.tangential == pytest.approx(50.0 * (err.value.load_factor - 1.0))
    assert err.value.tangential > err.value.capacity
    assert err.value.last_converged == done[-1].load_factor
    assert f"x {carried:.6g} N" in str(err.value)
    solver.destroy()
