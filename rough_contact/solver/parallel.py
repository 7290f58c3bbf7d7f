"""MPI helpers for entry scripts (demos, benchmarks)."""

from __future__ import annotations

import sys

from mpi4py import MPI


def abort_on_uncaught_exception(comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Make an uncaught exception on one rank abort the whole job.

    Otherwise the other ranks wait forever in the next collective. For ``__main__`` blocks only:
    library code and tests must not change ``sys.excepthook``.
    """
    def hook(exc_type, exc, tb):
        sys.__excepthook__(exc_type, exc, tb)
        sys.stderr.flush()
        comm.Abort(1)

    sys.excepthook = hook
