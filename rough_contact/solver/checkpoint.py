"""Checkpoints of a load path: write after every converged increment, resume a stopped run.

``load_path(..., checkpoint=DIR)`` writes, after every converged (committed) increment and
before it is yielded, everything the stepping needs to continue exactly: the displacement, the
interface's committed law state and accumulated dissipation, the load factor, the position in
the list of load factors (index, current increment size, cutbacks) and the secant predictor's
previous state (the displacement, and for an augmented-Lagrangian law the multipliers the
last increment started from). ``load_path(..., resume=DIR)`` restores it into a freshly built
problem and continues; the resumed run reproduces the uninterrupted one to round-off
(tests/fem/test_checkpoint.py).

The state is stored by keys that do not depend on the partition: every displacement node by
its index in the arrays the mesh was built from, or for a P2 midside node by its edge's two end
vertices' indices (``ContactProblem.owned_node_keys``), every interface point by its
coordinates. A restart finds its own nodes and points among those all ranks saved, so it may
run on another partition of the same mesh or on another number of ranks
(tests/demos/test_multiprocess.py: written on 2 ranks, resumed on 1, and the reverse, for the
rough-law program on P1 and the Mindlin scene on P2). Where no such keys exist (a displacement
space whose nodes are neither the geometry's nor P2 on simplices, e.g. Q2 or degree 3; a
sliding pairing; a law state that is not a dataclass of per-point arrays) the checkpoint is
bound to its
partition: each rank must hold the DOFs, in the same local order, that some rank held (the same
parts in another rank order are accepted), on the same number of ranks.

Output writers given as ``load_path(..., outputs=[...])`` (:class:`ResumableOutput`, e.g.
``ResultWriter``) are part of the checkpoint: the checkpoint of increment k is written when the
caller's loop asks for increment k + 1, i.e. after the loop body has written k's output, and
holds each writer's state; on resume every writer is restored to it, so the resumed run
continues the same files (``rough_contact.solver.output``). Rank r of the resumed run restores
the state rank r saved (rank 0's if the checkpoint has fewer ranks).

What the checkpoint belongs to is recorded in ``meta.json``: the mesh (DOF count, a checksum of
the DOF coordinates, the number of interface points) and a fingerprint of the problem
(``ContactProblem.describe``, ``rough_contact.fingerprint``): the interface law's parameters,
the pairing, the quadrature rule, the enforcement, the load program (each channel's scale at
every load factor), the loads and the materials; floats as written (``repr``), arrays by a hash.

Atomicity: two slots ``slot0/`` and ``slot1/`` are written alternately (one ``rank<r>.pkl`` per
rank, then ``meta.json``); the file ``LATEST`` naming the complete slot is replaced atomically
(``os.replace``) only after every rank has written and flushed its file. A run killed at any
moment leaves ``LATEST`` pointing at a complete slot.

Refused with a clear error naming what differs: a directory without a checkpoint, a checkpoint
of an earlier format, another mesh, another law, pairing, quadrature, enforcement, load program,
loads or materials (each differing parameter named with both values), a load-factor list that
does not match the saved one, and, for a checkpoint bound to its partition, another partition
or number of ranks.
"""

from __future__ import annotations

import json
import os
import pickle
from dataclasses import dataclass
from typing import Optional, Protocol, Sequence, runtime_checkable

import numpy as np
from mpi4py import MPI

from rough_contact.fingerprint import differences
from rough_contact.interface.state import is_pointwise, take_points

__all__ = ["ResumableOutput", "CheckpointState", "has_checkpoint", "saved_outputs",
           "CheckpointError", "signature",
           "write_checkpoint", "read_checkpoint", "FORMAT"]

FORMAT = 2     # 2: state by partition-independent keys, the problem's fingerprint

# the fingerprint's parts, as an error message names them
_PARTS = (("interface.law", "interface law"), ("interface.pairing", "pairing"),
          ("interface.quadrature", "quadrature"), ("interface.enforcement", "enforcement"),
          ("program", "load program"), ("loads", "loads"), ("materials", "materials"))


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


def signature(problem, factors: Sequence[float]) -> dict:
    """What identifies the problem a checkpoint belongs to (collective): the mesh (DOF count,
    DOF coordinate checksum, interface points) and the problem's fingerprint
    (``problem.describe(factors)``)."""
    x = problem.owned_dof_coordinates()
    local = float(np.round(x, 9).sum() + 7.0 * np.round(x ** 2, 9).sum())
    ci = problem.interface
    return dict(
        ranks=problem.comm.size, num_dofs=int(problem.num_dofs),
        dof_checksum=float(problem.comm.allreduce(local, op=MPI.SUM)),
        n_points=0 if ci is None else int(ci.n_points_global),
        fingerprint=problem.describe([float(f) for f in factors]))


def _keyed(problem) -> bool:
    """Whether this problem's state can be stored by partition-independent keys (collective)."""
    ci = problem.interface
    ok = problem.owned_node_keys() is not None and (
        ci is None or (ci.history.pairing is None and is_pointwise(ci.history.law.committed)))
    return bool(problem.comm.allreduce(ok, op=MPI.LAND))


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
    keyed = _keyed(problem)
    data = dict(u=problem.local_solution_values().copy(), u_previous=state.u_previous,
                partition=_local_checksum(problem),
                interface=None if ci is None else ci.state(),
                outputs=[o.checkpoint_state() for o in outputs])
    if keyed:    # owned nodes by key (u_previous is the owned part already), points by position
        data.update(keys=problem.owned_node_keys(), x=problem.owned_dof_coordinates().copy(),
                    u_owned=problem.owned_solution_values().copy(),
                    points=None if ci is None else _point_keys(ci))
    with open(os.path.join(path, f"rank{comm.rank}.pkl"), "wb") as f:
        pickle.dump(data, f, protocol=pickle.HIGHEST_PROTOCOL)
        f.flush()
        os.fsync(f.fileno())
    partitions = comm.gather(data["partition"].tolist(), root=0)
    comm.Barrier()
    if comm.rank == 0:
        meta = dict(format=FORMAT, signature=sig, keyed=keyed, partitions=partitions,
                    step=state.step, index=state.index, delta=state.delta,
                    cutbacks=state.cutbacks, load_factor=state.load_factor,
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


def saved_outputs(directory: str) -> list:
    """The states of the outputs saved with the latest checkpoint in ``directory``
    (``ResumableOutput.checkpoint_state``, in the order the run passed them), as rank 0 wrote
    them; a plain file read, no communicator: for outputs that are the same on every rank
    (e.g. the Mindlin scene's per-increment record), to inspect a run without resuming it.

    Raises:
        CheckpointError: ``directory`` holds no complete checkpoint.
    """
    slot = _latest(directory)
    if slot is None:
        raise CheckpointError(f"directory {directory!r} holds no complete checkpoint (no LATEST)")
    with open(os.path.join(directory, slot, "rank0.pkl"), "rb") as f:
        return pickle.load(f)["outputs"]


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


def _check_fingerprint(directory: str, saved: dict, mine: dict) -> None:
    """Refuse another law, pairing, quadrature, enforcement, program, loads or materials,
    naming every differing parameter (identical on every rank: no collective needed)."""
    found = []
    for key, label in _PARTS:
        a, b = saved, mine
        for part in key.split("."):
            a = a.get(part) if isinstance(a, dict) else None
            b = b.get(part) if isinstance(b, dict) else None
        diff = differences(a, b)
        if diff:
            found.append(f"{label} differs: {'; '.join(diff)}")
    if found:
        raise CheckpointError(f"restart directory {directory!r} was written by another problem "
                              f"setup; refused, because " + " | ".join(found))


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
    if meta.get("format") != FORMAT:
        raise CheckpointError(f"restart directory {directory!r} holds a checkpoint of format "
                              f"{meta.get('format', 1)!r}; this version reads format {FORMAT} "
                              "only (it records the problem's fingerprint): rerun from the start")
    factors = [float(f) for f in factors]
    mine = signature(problem, factors)
    saved = meta["signature"]
    diff = [f"{k}: checkpoint {saved[k]!r}, this problem {mine[k]!r}"
            for k in ("num_dofs", "n_points") if saved[k] != mine[k]]
    if not np.isclose(saved["dof_checksum"], mine["dof_checksum"], rtol=1e-12, atol=1e-9):
        diff.append(f"dof_checksum: checkpoint {saved['dof_checksum']!r}, this problem "
                    f"{mine['dof_checksum']!r}")
    if diff:
        raise CheckpointError(f"restart directory {directory!r} was written by another problem "
                              f"(another mesh): {'; '.join(diff)}")
    if factors != meta["factors"]:
        raise CheckpointError(f"the load factors given ({len(factors)}) differ from those of the "
                              f"checkpointed run ({len(meta['factors'])}): resume with the same "
                              "load path")
    _check_fingerprint(directory, saved["fingerprint"], mine["fingerprint"])
    n_saved = int(saved["ranks"])
    if meta["keyed"] and _keyed(problem):
        files = []
        for r in range(n_saved):
            with open(os.path.join(path, f"rank{r}.pkl"), "rb") as f:
                files.append(pickle.load(f))
        own = files[comm.rank if comm.rank < n_saved else 0]
        u_previous = _restore_by_keys(directory, problem, files)
    else:
        own, u_previous = _restore_same_partition(directory, problem, path, meta, n_saved)
    saved_outputs = own.get("outputs", [])
    if len(saved_outputs) != len(outputs):
        raise CheckpointError(f"the checkpoint in {directory!r} holds the state of "
                              f"{len(saved_outputs)} output writer(s), {len(outputs)} were given: "
                              "resume with the same outputs")
    problem.set_load_factor(meta["load_factor"])
    for writer, state in zip(outputs, saved_outputs):
        writer.restore(state)
    return CheckpointState(step=meta["step"], index=meta["index"], delta=meta["delta"],
                           cutbacks=meta["cutbacks"], load_factor=meta["load_factor"],
                           lam_previous=meta["lam_previous"], u_previous=u_previous,
                           factors=factors)


def _restore_by_keys(directory: str, problem, files: list) -> Optional[np.ndarray]:
    """Take this rank's nodes and points out of every saved rank's data (collective); returns
    the owned part of the secant predictor's previous displacement (or None)."""
    comm, ci = problem.comm, problem.interface
    keys = np.concatenate([d["keys"] for d in files])
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    mine = problem.owned_node_keys()
    if len(keys):
        pos = np.minimum(np.searchsorted(sorted_keys, mine), len(keys) - 1)
        found, idx = sorted_keys[pos] == mine, order[pos]
    else:
        found, idx = np.zeros(len(mine), dtype=bool), np.zeros(len(mine), dtype=np.int64)
    x = np.concatenate([d["x"] for d in files])
    scale = max(1.0, float(np.abs(x).max(initial=0.0)))
    same = bool(np.all(found)) and np.allclose(x[idx], problem.owned_dof_coordinates(),
                                               rtol=0.0, atol=1e-9 * scale)
    bs = next((d["u_owned"].size // len(d["keys"]) for d in files if len(d["keys"])), 1)
    if ci is not None:
        points = np.concatenate([d["points"] for d in files])
        j, ok_points = _match_points(points, _point_keys(ci))
        same = same and ok_points
    if not comm.allreduce(bool(same), op=MPI.LAND):
        raise CheckpointError(
            f"restart directory {directory!r}: the saved nodes or interface points do not cover "
            "this problem's (another mesh built from other input arrays?); rank(s) "
            f"{[r for r, s in enumerate(comm.allgather(bool(same))) if not s]} miss some")
    u = np.concatenate([d["u_owned"].reshape(-1, bs) for d in files])
    problem.owned_solution_values()[:] = u[idx].reshape(-1)
    problem.scatter_solution()
    u_previous = None
    if files[0]["u_previous"] is not None:
        up = np.concatenate([np.asarray(d["u_previous"]).reshape(-1, bs) for d in files])
        u_previous = up[idx].reshape(-1).copy()
    if ci is not None:
        states = [d["interface"] for d in files]

        def joined(name):
            parts = [s.get(name) for s in states]
            return None if parts[0] is None else np.concatenate(parts, axis=0)[j]

        restored = dict(committed=take_points([s["committed"] for s in states], j),
                        dissipated=joined("dissipated"),
                        normal_dissipated=joined("normal_dissipated"),
                        multipliers=joined("multipliers"),
                        multipliers_before=joined("multipliers_before"), pairing=None)
        if ci.restore(restored):
            problem.rebuild_matrices()
    return u_previous


def _point_keys(ci) -> np.ndarray:
    """(n, 6) partition-independent keys of this rank's interface points: the point's position
    and its facet's centroid (the points of a facet in order). The position alone is not a
    key: the vertex rule puts a point of every facet at each shared vertex."""
    x = np.asarray(ci.point_coordinates(), dtype=float)
    n_qp = max(int(ci.n_qp), 1)
    centroid = np.repeat(x.reshape(-1, n_qp, 3).mean(axis=1), n_qp, axis=0)
    return np.hstack([x, centroid])


def _match_points(saved: np.ndarray, mine: np.ndarray):
    """For each of ``mine`` (m, 6) (:func:`_point_keys`), the index of the saved point with
    the same key (within 1e-9 of the extent); (indices, all matched one to one). Points with
    equal keys (a slot-filling copy of a point of the same facet, weight 0, same history)
    are matched in the order they come."""
    if len(mine) == 0:
        return np.zeros(0, dtype=np.int64), True
    if len(saved) == 0:
        return np.zeros(len(mine), dtype=np.int64), False
    tol = 1e-9 * max(1.0, float(np.ptp(saved[:, :3], axis=0).max()))

    def rows(keys):
        q = np.floor(np.asarray(keys) / tol + 0.5).astype(np.int64)
        order = np.lexsort(q.T[::-1])
        qs = q[order]
        new = np.ones(len(qs), dtype=bool)
        new[1:] = np.any(qs[1:] != qs[:-1], axis=1)
        start = np.maximum.accumulate(np.where(new, np.arange(len(qs)), 0))
        occurrence = np.empty(len(qs), dtype=np.int64)
        occurrence[order] = np.arange(len(qs)) - start     # rank among equal keys
        return np.hstack([q, occurrence[:, None]])

    a, b = rows(saved), rows(mine)
    view = np.dtype((np.void, a.dtype.itemsize * a.shape[1]))
    av = np.ascontiguousarray(a).view(view).ravel()
    bv = np.ascontiguousarray(b).view(view).ravel()
    order = np.argsort(av, kind="stable")
    pos = np.minimum(np.searchsorted(av[order], bv), len(av) - 1)
    j = order[pos]
    ok = bool(np.all(av[j] == bv)) and len(np.unique(j)) == len(j)
    return np.asarray(j, dtype=np.int64), ok


def _restore_same_partition(directory: str, problem, path: str, meta: dict, n_saved: int):
    """The partition-bound restore: every rank must hold a part some rank held (collective).
    Returns (this rank's own saved data, u_previous)."""
    comm = problem.comm
    if n_saved != comm.size:
        raise CheckpointError(
            f"restart directory {directory!r} was written on {n_saved} rank(s), this run has "
            f"{comm.size}: its state is bound to its partition (no partition-independent keys: "
            "a space other than the geometry's degree or P2 on simplices, a sliding pairing or a "
            "law state that is not a dataclass of per-point arrays); resume on the same number "
            "of ranks")
    with open(os.path.join(path, f"rank{comm.rank}.pkl"), "rb") as f:
        own = pickle.load(f)
    # the same partition: every rank must hold the DOFs (in the same local order) that some rank
    # held when the checkpoint was written; the same parts in another rank order are accepted
    # (a rank then takes the data of the rank that held its part).
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
            f"checkpointed run (rank(s) {[r for r in bad if r is not None]} hold other DOFs) and "
            "the checkpoint is bound to its partition (see rough_contact.solver.checkpoint)")
    problem.local_solution_values()[:] = data["u"]
    problem.scatter_solution()
    ci = problem.interface
    if ci is not None and ci.restore(data["interface"]):   # a sliding pairing's partners
        problem.rebuild_matrices()
    return own, data["u_previous"]
