"""Load programs: a normal preload held while a prescribed tangential displacement cycles
(serial and 2 ranks).

Two blocks (1 x 1 x 0.5 mm each, P1), the lower one clamped at its bottom, the upper one pressed
by P = 100 N on its top (channel "preload") and driven by u_x = a w(t) on its top (channel
"cyclic", triangle wave, a = 3 um: gross slip), isotropic Coulomb friction mu = 0.3 with a stiff penalty.
References: Coulomb's law (the tangential reaction cannot exceed mu P and reaches it in gross
slip), force balance (the normal interface force equals P at every increment), and the energy
balance of a closed steady cycle (the loop area of the reaction vs the imposed displacement,
integrated with the trapezoidal rule, equals the frictional dissipation of that cycle reported
by the interface: the elastic energy is the same at the start and end of the cycle).
Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.io.plotting import loop_energies
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.scenes.setup import clamped_pair, preload_then_drive
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import cycle_index, cycle_summary, preload_then_cyclic
from rough_contact.solver.snes import SNESSolver

MU, P, AMPLITUDE = 0.3, 100.0, 3e-3


def _run(steps_per_cycle):
    scene = two_blocks(h1=0.5, h2=0.5, mesh_size=0.25, order=1)
    V = compat.vector_space(scene.mesh, 1)
    clamp, ci = clamped_pair(scene, V, SoftplusPenalty(k_normal=1e7, width=1e-9,
                                                       k_tangential=1e7, friction=MU))
    top = scene.tag("top")
    program = preload_then_cyclic(preload_steps=2, cycles=2, steps_per_cycle=steps_per_cycle)
    problem = preload_then_drive(scene, V, Material(2e5, 0.3), clamp, ci, top, P, AMPLITUDE,
                                 "cyclic", program.channels)
    solver = SNESSolver(problem, prefix="lp_")
    rows = []
    for inc in load_path(problem, solver, program.times, verbose=False):
        rows.append((inc.load_factor, problem.scales["cyclic"] * AMPLITUDE,
                     problem.reaction(top)[0], inc.contact_force[2], inc.dissipation))
    solver.destroy()
    return program, np.array(rows)


def test_program_channels_and_bad_input():
    p = preload_then_cyclic(preload_steps=2, cycles=1, steps_per_cycle=8, amplitude=0.5)
    assert p.times[:2] == [0.5, 1.0] and len(p.times) == 2 + 8
    assert [p.channels["preload"](t) for t in (0.5, 1.0, 1.5)] == [0.5, 1.0, 1.0]
    np.testing.assert_allclose([p.channels["cyclic"](t) for t in p.times[2:]],
                               [0.25, 0.5, 0.25, 0.0, -0.25, -0.5, -0.25, 0.0], atol=1e-15)
    np.testing.assert_array_equal(cycle_index(p.times, p), [0, 0] + [1] * 8)
    with pytest.raises(ValueError, match="cycles = 0 is invalid"):
        preload_then_cyclic(2, 0, 8)
    with pytest.raises(ValueError, match="steps_per_cycle = 6 is invalid: it must be a multiple "
                       "of 4"):
        preload_then_cyclic(2, 1, 6)
    with pytest.raises(ValueError, match="shape = 'square' is invalid"):
        preload_then_cyclic(2, 1, 8, shape="square")


def test_programs_for_unknown_channels_are_refused():
    scene = two_blocks(h1=0.5, h2=0.5, mesh_size=0.5, order=1)
    V = compat.vector_space(scene.mesh, 1)
    with pytest.raises(ValueError, match=r"programs given for channel\(s\) \['cyclc'\] that no "
                       r"load or prescribed displacement uses; channels in use: \['preload'\]"):
        ContactProblem(V, Material(2e5, 0.3), [], [SurfaceLoad(scene.tag("top"),
                                                               force=(0, 0, -1),
                                                               channel="preload")],
                       facet_tags=scene.facet_tags, programs={"cyclc": lambda t: t})


def test_preload_then_tangential_cycles_coulomb():
    program, r = _run(steps_per_cycle=32)
    t, u, fx, fz, diss = r.T
    k = cycle_index(t, program)
    # the preload is held: normal interface force = P at every increment (force balance)
    np.testing.assert_allclose(fz[k > 0], P, rtol=1e-8)
    # Coulomb: |F_x| <= mu P always, = mu P in gross slip (at the extremes of the cycle)
    assert np.all(np.abs(fx) <= MU * P * (1 + 1e-6))
    extremes = np.isclose(np.abs(u), AMPLITUDE)
    np.testing.assert_allclose(np.abs(fx[extremes & (k == 2)]), MU * P, rtol=1e-6)
    # energy of the steady second cycle: loop area = dissipation of the cycle
    start = int(np.flatnonzero(k == 1)[-1])       # end of cycle 1 = start of cycle 2
    end = len(t) - 1
    loop = loop_energies(u, fx, [start, end])[0]    # work of the drive's force on the block
    dissipated = diss[end] - diss[start]
    assert dissipated > 0.5 * 4 * MU * P * AMPLITUDE      # gross slip over most of the cycle
    # trapezoidal loop vs return-map dissipation: -1.6 %, -0.26 %, -0.08 % at 16, 32, 64
    # increments per cycle (second order; measured with this scene)
    assert abs(loop - dissipated) <= 5e-3 * dissipated
    summary = cycle_summary(t, program, u, fx, diss)
    assert [c["cycle"] for c in summary] == [1, 2]
    assert summary[1]["loop_energy"] == pytest.approx(loop, rel=1e-12)
    assert summary[1]["dissipated"] == pytest.approx(dissipated, rel=1e-12)
    # gross slip: F swings between -mu P and +mu P over 2 a
    assert summary[1]["secant_stiffness"] == pytest.approx(2 * MU * P / (2 * AMPLITUDE),
                                                           rel=1e-6)
