"""Worker for tests/demos/test_multiprocess.py (run under mpirun): the checkpoint test's
preload + cyclic rough-law program, uninterrupted ("full"), writing checkpoints ("checkpointed",
printing each converged step and this rank's PID), or resumed from a directory ("resume").
Writes the final figures as JSON (rank 0). Usage: checkpoint_worker.py MODE DIR OUT.json"""

import json
import os
import sys

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.scenes import flat_punch
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import preload_then_cyclic
from rough_contact.solver.snes import SNESSolver

PROGRAM = preload_then_cyclic(preload_steps=2, cycles=2, steps_per_cycle=8)


def model():
    comm = MPI.COMM_WORLD
    scene = two_blocks(lx=2.0, ly=2.0, h1=1.0, h2=1.0, mesh_size=0.5, order=1)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    clamp = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), fem.locate_dofs_topological(
        V, 2, scene.facet_tags.find(scene.tag("bottom"))), V)
    law, _ = flat_punch.make_law(comm, case="b", normal_law="elastic", seating_pressure=5.0)
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


def main(mode, directory, out):
    comm = MPI.COMM_WORLD
    problem, solver = model()
    kwargs = {"checkpoint": directory} if mode == "checkpointed" else \
        {"resume": directory} if mode == "resume" else {}
    pids = comm.gather(os.getpid(), root=0)
    if mode == "checkpointed" and comm.rank == 0:
        print("PIDS " + " ".join(str(p) for p in pids), flush=True)
    last = first = None
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False, **kwargs):
        last = inc
        first = inc.step if first is None else first
        if mode == "checkpointed" and comm.rank == 0:
            print(f"STEP {inc.step}", flush=True)
    u = problem.u.x.array
    n_own = problem.V.dofmap.index_map.size_local * 3
    unorm = np.sqrt(comm.allreduce(float(np.dot(u[:n_own], u[:n_own])), op=MPI.SUM))
    umax = comm.allreduce(float(np.abs(u[:n_own]).max(initial=0.0)), op=MPI.MAX)
    if comm.rank == 0:
        with open(out, "w") as f:
            json.dump(dict(first=first, step=last.step, D=last.dissipation, F=last.contact_force.tolist(),
                           unorm=unorm, umax=umax), f)
    solver.destroy()


if __name__ == "__main__":
    main(*sys.argv[1:4])
