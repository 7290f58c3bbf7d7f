"""Worker for tests/demos/test_multiprocess.py (run under mpirun): the checkpoint test's
preload + cyclic rough-law program, uninterrupted ("full"), writing checkpoints ("checkpointed",
printing each converged step and this rank's PID), or resumed from a directory ("resume").
Every mode writes its results (ResultWriter) into OUT.json's name without the suffix + "_out";
"checkpointed" and "resume" share DIR + "_out". Writes the final figures as JSON (rank 0).
A fourth argument N makes a "checkpointed" run stop after N increments (its checkpoint written).
The displacement is P1, or P2 on the same (affine) mesh with RC_WORKER_DEGREE=2 in the
environment.
Usage: checkpoint_worker.py MODE DIR OUT.json [N]"""

import json
import os
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).parents[1] / "fem"))
import test_checkpoint  # noqa: E402  (the checkpoint test's model, with a longer program)

from rough_contact.io import ResultWriter  # noqa: E402
from rough_contact.solver.loading import load_path  # noqa: E402
from rough_contact.solver.program import preload_then_cyclic  # noqa: E402

PROGRAM = test_checkpoint.PROGRAM = preload_then_cyclic(preload_steps=2, cycles=2,
                                                        steps_per_cycle=8)


def model():
    return test_checkpoint._model(degree=int(os.environ.get("RC_WORKER_DEGREE", "1")))


def main(mode, directory, out, stop_after=None):
    comm = MPI.COMM_WORLD
    problem, solver = model()
    kwargs = {"checkpoint": directory} if mode == "checkpointed" else \
        {"resume": directory} if mode == "resume" else {}
    if stop_after is not None:
        kwargs["max_steps"] = int(stop_after)
    pids = comm.gather(os.getpid(), root=0)
    if mode == "checkpointed" and comm.rank == 0:
        print("PIDS " + " ".join(str(p) for p in pids), flush=True)
    outdir = str(directory) + "_out" if mode != "full" else os.path.splitext(out)[0] + "_out"
    writer = ResultWriter(outdir, comm, u=problem.u, interface=problem.interface,
                          resume=mode == "resume")
    last = first = None
    for inc in load_path(problem, solver, PROGRAM.times, verbose=False, outputs=[writer],
                         **kwargs):
        writer.write(inc)
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
    main(*sys.argv[1:5])
