"""Checkpoints of a load path: write after every converged increment, resume a stopped run.

``load_path(..., checkpoint=DIR)`` writes, after every converged (committed) increment and
before it is yielded, everything the stepping needs to continue exactly: the displacement, the
interface's committed law state and accumulated dissipation, the load factor, the position in
the list of load factors (index, current increment size, cutbacks) and the secant predictor's
previous state (the displacement, and for an augmented-Lagrangian law the multipliers the
last increment started from). ``load_path(..., resume=DIR)`` restores it into a freshly built
problem (same mesh, same number of ranks, same law) and continues; the resumed run reproduces
the uninterrupted one to round-off (tests/fem/test_checkpoint.py).

Output writers given as ``load_path(..., outputs=[...])`` (:class:`ResumableOutput`, e.g.
``ResultWriter``) are part of the checkpoint: the checkpoint of increment k is written when the
caller's loop asks for increment k + 1, i.e. after the loop body has written k's output, and
holds each writer's state; on resume every writer is restored to it, so the resumed run
continues the same files (``rough_contact.solver.output``).

Atomicity: two slots ``slot0/`` and ``slot1/`` are written alternately (one ``rank<r>.pkl`` per
rank, then ``meta.json``); the file ``LATEST`` naming the complete slot is replaced atomically
(``os.replace``) only after every rank has written and flushed its file. A run killed at any
moment leaves ``LATEST`` pointing at a complete slot.

Refused with a clear error: a directory without a checkpoint, a different number of ranks,
another mesh (DOF count or a checksum of the DOF coordinates differ), another partition (no rank
held this rank's DOFs, in this local order, when the checkpoint was written: DOLFINx's
partitioner can give another partition for a second build of the same mesh in one process; the
same parts handed to the ranks in another order, as DOLFINx 0.9 does between processes, are
accepted: each rank reads the file of the rank that held its part), another law
(type or number of interface points), or a load-factor list that does not match the saved one.
"""

from __future__ import annotations

import json
import os
import pickle
from dataclasses import dataclass
from typing import Optional, Protocol, Sequence, runtime_checkable

import numpy as np
from mpi4py import MPI

__all__ = ["ResumableOutput", "CheckpointState", "has_checkpoint", "CheckpointError", "signature", "write_checkpoint",
           "read_checkpoint"]


class CheckpointError(ValueError):
    """A checkpoint that cannot be resumed into this problem (the message says why)."""


@runtime_checkable
class ResumableOutput(Protocol):
    """An output writer whose files a resumed run continues."""

    def checkpoint_state(self) -> object:
        """This rank's state after the last written increment (picklable)."""

    def restore(self, state: object) -> None:
        """Continue from ``state`` (collective): trim the files back to it."""


@dataclass
class CheckpointState:
    """The load path's position (identical on every rank) and this rank's arrays."""

    step: int
    index: int
    delta: float
    cutbacks: int
    load_factor: float
    lam_previous: Optional[float]
    u_previous: Optional[np.ndarray]
    factors: list


def signature(problem) -> dict:
    """What identifies the problem a checkpoint belongs to (collective)."""
    x = problem.owned_dof_coordinates()
    local = float(np.round(x, 9).sum() + 7.0 * np.round(x ** 2, 9).sum())
    ci = problem.interface
    return dict(
        ranks=problem.comm.size, num_dofs=int(problem.num_dofs),
        dof_checksum=float(problem.comm.allreduce(local, op=MPI.SUM)),
        law=None if ci is None else type(ci.law).__name__,
        n_points=0 if ci is None else int(ci.n_points_global))


def write_checkpoint(directory: str, problem, state: CheckpointState, sig: dict,
                     outputs: Sequence[ResumableOutput] = ()) -> None:
    """Write one checkpoint (collective); ``sig`` = :func:`signature` of the problem (computed
    once), ``outputs`` the writers whose state is saved with it. See the module for the layout
    and atomicity."""
    comm = problem.comm
    if comm.rank == 0:
        os.makedirs(directory, exist_ok=True)
    comm.Barrier()
    latest = _latest(directory) if comm.rank == 0 else None
    slot = comm.bcast("slot1" if latest == "slot0" else "slot0", root=0)
    path = os.path.join(directory, slot)
    if comm.rank == 0:
        os.makedirs(path, exist_ok=True)
        for name in os.listdir(path):                      # stale files of an older checkpoint
            os.remove(os.path.join(path, name))
    comm.Barrier()
    ci = problem.interface
    data = dict(u=problem.local_solution_values().copy(), u_previous=state.u_previous,
                partition=_local_checksum(problem),
                interface=None if ci is None else ci.state(),
                outputs=[o.checkpoint_state() for o in outputs])
    with open(os.path.join(path, f"rank{comm.rank}.pkl"), "wb") as f:
        pickle.dump(data, f, protocol=pickle.HIGHEST_PROTOCOL)
        f.flush()
        os.fsync(f.fileno())
    partitions = comm.gather(data["partition"].tolist(), root=0)
    comm.Barrier()
    if comm.rank == 0:
        meta = dict(signature=sig, partitions=partitions, step=state.step, index=state.index,
                    delta=state.delta, cutbacks=state.cutbacks, load_factor=state.load_factor,
                    lam_previous=state.lam_previous, factors=list(map(float, state.factors)))
        with open(os.path.join(path, "meta.json"), "w") as f:
            json.dump(meta, f)
            f.flush()
            os.fsync(f.fileno())
        tmp = os.path.join(directory, "LATEST.tmp")
        with open(tmp, "w") as f:
            f.write(slot)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, os.path.join(directory, "LATEST"))
    comm.Barrier()


def has_checkpoint(directory: str, comm: MPI.Comm = MPI.COMM_WORLD) -> bool:
    """Whether ``directory`` holds a complete checkpoint (collective: rank 0 decides)."""
    return bool(comm.bcast(_latest(directory) is not None if comm.rank == 0 else None, root=0))


def _local_checksum(problem) -> np.ndarray:
    """(count, checksum, order checksum) of this rank's owned DOF coordinates and interface
    points: which part of the mesh a rank holds, and in which local order."""
    x = np.round(problem.owned_dof_coordinates(), 9)
    ci = problem.interface
    xp = np.zeros((0, 3)) if ci is None else np.round(ci.point_coordinates(), 9)
    order = (np.arange(1, len(x) + 1) @ (x @ [1.0, 3.0, 7.0])
             + np.arange(1, len(xp) + 1) @ (xp @ [1.0, 3.0, 7.0]))
    return np.array([float(x.shape[0]), float(x.sum() + 7.0 * (x ** 2).sum()), float(order)])


def _partition_source(comm, partitions, mine: np.ndarray) -> Optional[int]:
    """The rank whose saved part equals this rank's (this rank itself if it does), or None
    (no rank held it, or two ranks would read the same file); collective."""
    if partitions is None or len(partitions) != comm.size:
        return None
    saved = [np.asarray(p, dtype=float) for p in partitions]
    match = [r for r, p in enumerate(saved)
             if p.shape == mine.shape and np.allclose(p, mine, rtol=1e-12, atol=1e-9)]
    source = comm.rank if comm.rank in match else (match[0] if match else None)
    sources = comm.allgather(source)
    if source is not None and sources.count(source) > 1:
        return None
    return source


def _latest(directory: str) -> Optional[str]:
    try:
        with open(os.path.join(directory, "LATEST")) as f:
            return f.read().strip()
    except FileNotFoundError:
        return None


def read_checkpoint(directory: str, problem, factors,
                    outputs: Sequence[ResumableOutput] = ()) -> CheckpointState:
    """Restore the latest checkpoint of ``directory`` into ``problem`` (collective): the
    displacement, the interface's committed state and dissipation, the load factor, and the
    state of each of ``outputs`` (the same writers, in the same order, as when it was written).

    Raises:
        CheckpointError: see the module.
    """
    comm = problem.comm
    slot = _latest(directory) if comm.rank == 0 else None
    slot = comm.bcast(slot, root=0)
    if slot is None:
        raise CheckpointError(f"restart directory {directory!r} holds no checkpoint (no LATEST "
                              "file): nothing to resume")
    path = os.path.join(directory, slot)
    meta = None
    if comm.rank == 0:
        with open(os.path.join(path, "meta.json")) as f:
            meta = json.load(f)
    meta = comm.bcast(meta, root=0)
    mine = signature(problem)
    saved = meta["signature"]
    diff = [f"{k}: checkpoint {saved[k]!r}, this problem {mine[k]!r}" for k in saved
            if (saved[k] != mine[k] if k != "dof_checksum"
                else not np.isclose(saved[k], mine[k], rtol=1e-12, atol=1e-9))]
    if diff:
        raise CheckpointError(f"restart directory {directory!r} was written by another problem "
                              f"(mesh, partition or law differ): {'; '.join(diff)}")
    factors = [float(f) for f in factors]
    if factors != meta["factors"]:
        raise CheckpointError(f"the load factors given ({len(factors)}) differ from those of the "
                              f"checkpointed run ({len(meta['factors'])}): resume with the same "
                              "load path")
    with open(os.path.join(path, f"rank{comm.rank}.pkl"), "rb") as f:
        own = pickle.load(f)
    # the same partition: every rank must hold the DOFs (in the same local order) that some rank
    # held when the checkpoint was written. DOLFINx 0.9 may hand the same parts to the ranks in
    # another order in a fresh process: a rank then takes the data of the rank that held its
    # part (the output writers' state stays with the rank); a different partition is refused.
    source = _partition_source(comm, meta.get("partitions"), _local_checksum(problem))
    data = own
    if source is not None and source != comm.rank:
        with open(os.path.join(path, f"rank{source}.pkl"), "rb") as f:
            data = pickle.load(f)
    same = source is not None and data["u"].shape == problem.local_solution_values().shape
    if not comm.allreduce(same, op=MPI.LAND):
        bad = comm.allgather(None if same else comm.rank)
        raise CheckpointError(
            f"restart directory {directory!r}: the mesh is partitioned differently from the "
            f"checkpointed run (rank(s) {[r for r in bad if r is not None]} hold other DOFs); "
            "build the mesh the same way on the same number of ranks (a fresh process building "
            "the same scenes in the same order does)")
    saved_outputs = own.get("outputs", [])
    if len(saved_outputs) != len(outputs):
        raise CheckpointError(f"the checkpoint in {directory!r} holds the state of "
                              f"{len(saved_outputs)} output writer(s), {len(outputs)} were given: "
                              "resume with the same outputs")
    problem.local_solution_values()[:] = data["u"]
    problem.scatter_solution()
    problem.set_load_factor(meta["load_factor"])
    ci = problem.interface
    if ci is not None and ci.restore(data["interface"]):   # a sliding pairing's partners
        problem.rebuild_matrices()
    for writer, saved in zip(outputs, saved_outputs):
        writer.restore(saved)
    return CheckpointState(step=meta["step"], index=meta["index"], delta=meta["delta"],
                           cutbacks=meta["cutbacks"], load_factor=meta["load_factor"],
                           lam_previous=meta["lam_previous"], u_previous=data["u_previous"],
                           factors=factors)
