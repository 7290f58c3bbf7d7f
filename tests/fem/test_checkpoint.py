"""Checkpoint and resume of a load path (serial and 2 ranks).

Reference: the same program run without interruption. Two blocks with the paper's rough law
(slip-hardening friction, case b), a preload and one tangential cycle of +-2 um (slip, hardening:
history matters). A run that writes checkpoints is stopped after 6 increments; a freshly built
problem resumes from the directory: its increments must equal the uninterrupted run's
(displacement to 1e-12 of its maximum, dissipation and contact forces to 1e-12 relative), and the
step numbers continue. A checkpoint of another problem, other load factors, or an empty
directory are refused with a clear error. Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.scenes import flat_punch
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.solver.checkpoint import CheckpointError
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import preload_then_cyclic
from rough_contact.solver.snes import SNESSolver

PROGRAM = preload_then_cyclic(preload_steps=2, cycles=1, steps_per_cycle=8)
_NORMAL = {}


def _model(mesh_size=0.5):
    comm = MPI.COMM_WORLD
    scene = two_blocks(lx=2.0, ly=2.0, h1=1.0, h2=1.0, mesh_size=mesh_size, order=1)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    clamp = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), fem.locate_dofs_topological(
        V, 2, scene.facet_tags.find(scene.tag("bottom"))), V)
    law, normal = flat_punch.make_law(comm, case="b", normal_law="elastic", seating_pressure=5.0,
                                      normal=_NORMAL.get("n"))
    _NORMAL["n"] = normal
    first, second = scene.contact_pair
    ci = ContactInterface(V, scene.facet_tags, first, second, law=law, bcs=[clamp])
    top = scene.tag("top")
    problem = ContactProblem(
        V, Material(flat_punch.E, flat_punch.NU), [clamp],
        [SurfaceLoad(top, force=(0.0, 0.0, -40.0), channel="preload")],
        facet_tags=scene.facet_tags, interface=ci, seating_tag=first, seating_stiffness=1e3,
        prescribed=[PrescribedDisplacement(top, (2e-3, 0.0, 0.0), (0,), channel="cyclic")],
        programs=PROGRAM.channels)
    return problem, SNESSolver(problem, prefix="ck_")


def _record(problem, inc):
    return dict(step=inc.step, lam=inc.load_factor, u=problem.u.x.array.copy(),
                D=inc.dissipation, F=inc.contact_force.copy())


def test_resume_reproduces_the_uninterrupted_run(tmp_path):
    directory = MPI.COMM_WORLD.bcast(str(tmp_path / "ckpt"), root=0)
    problem, solver = _model()
    reference = [_record(problem, i) for i in load_path(problem, solver, PROGRAM.times,
                                                        verbose=False)]
    solver.destroy()
    assert reference[-1]["D"] > 0.0                      # the cycle slipped: history matters

    problem, solver = _model()
    first = []
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False, checkpoint=directory):
        first.append(_record(problem, inc))
        if len(first) == 6:
            break                                        # the run stops here
    solver.destroy()

    problem, solver = _model()
    resumed = [_record(problem, i) for i in load_path(problem, solver, PROGRAM.times,
                                                      verbose=False, resume=directory)]
    solver.destroy()
    assert [r["step"] for r in resumed] == list(range(7, len(reference) + 1))
    assert [r["lam"] for r in resumed] == [r["lam"] for r in reference[6:]]
    scale = max(np.abs(r["u"]).max() for r in reference)
    for got, ref in zip(resumed, reference[6:]):
        np.testing.assert_allclose(got["u"], ref["u"], rtol=0, atol=1e-12 * scale)
        assert got["D"] == pytest.approx(ref["D"], rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(got["F"], ref["F"], rtol=1e-12, atol=1e-12 * abs(ref["F"][2]))


def test_resume_refuses_another_problem(tmp_path):
    directory = MPI.COMM_WORLD.bcast(str(tmp_path / "ckpt"), root=0)
    problem, solver = _model()
    for inc in load_path(problem, solver, PROGRAM.times[:2], verbose=False,
                         checkpoint=directory):
        pass
    solver.destroy()
    other, solver = _model(mesh_size=0.35)
    with pytest.raises(CheckpointError, match="written by another problem .*num_dofs"):
        next(load_path(other, solver, PROGRAM.times[:2], resume=directory))
    solver.destroy()
    problem, solver = _model()
    with pytest.raises(CheckpointError, match=r"load factors given \(3\) differ from those of "
                       r"the checkpointed run \(2\)"):
        next(load_path(problem, solver, PROGRAM.times[:3], resume=directory))
    empty = MPI.COMM_WORLD.bcast(str(tmp_path / "none"), root=0)
    with pytest.raises(CheckpointError, match="holds no checkpoint"):
        next(load_path(problem, solver, PROGRAM.times[:2], resume=empty))
    solver.destroy()
