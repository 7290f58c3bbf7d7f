"""MPI helpers for entry scripts (demos, benchmarks)."""

from __future__ import annotations

import sys
import time
import traceback

from mpi4py import MPI

__all__ = ["abort_on_uncaught_exception"]


def abort_on_uncaught_exception(comm: MPI.Comm = MPI.COMM_WORLD, grace: float = 10.0) -> None:
    """Make an uncaught exception end the whole job, with its message as the last line.

    Collective (call it on every rank at start-up: it duplicates ``comm``). For ``__main__``
    blocks only: library code and tests must not change ``sys.excepthook``.

    On an uncaught exception a rank waits up to ``grace`` seconds [s] for the other ranks in a
    non-blocking barrier of its own communicator:

    * every rank failed (a bad input, or any error the library raises on all ranks together,
      ``rough_contact.fem.collective``): nobody waits in a collective, so there is no need to
      abort. Rank 0 prints the other ranks' messages that differ from its own, then its own
      traceback, whose last line is the message (and repeats that line on standard output,
      so that a log of the output ends with it); the other ranks print nothing; every rank
      exits with status 1 and MPI is finalised normally (no MPI_ABORT banner after the
      message). Open MPI's ``mpirun`` still adds a note that a process exited with a
      non-zero status unless it runs with ``-q`` (``--quiet``).
    * some ranks did not fail within ``grace``: they would wait forever in their next
      collective, so the failing rank prints its traceback and calls ``MPI_Abort`` (Open MPI
      prints its banner after the message).
    """
    if grace < 0.0:
        raise ValueError(f"grace = {grace!r} s is invalid: it must be >= 0")
    together = comm.Dup()

    def hook(exc_type, exc, tb):
        text = "".join(traceback.format_exception(exc_type, exc, tb))
        last = traceback.format_exception_only(exc_type, exc)[-1].strip()
        sys.stdout.flush()
        if together.size == 1:
            sys.stderr.write(text)
            sys.stderr.flush()
            return                                  # Python exits with status 1
        request = together.Ibarrier()
        deadline = time.monotonic() + grace
        while not request.Test():
            if time.monotonic() > deadline:         # some rank is elsewhere: abort them all
                sys.stderr.write(text)
                sys.stderr.flush()
                comm.Abort(1)
            time.sleep(0.005)
        lines = together.gather(last, root=0)
        if together.rank == 0:
            others = [f"rank {r}: {line}" for r, line in enumerate(lines)
                      if r > 0 and line != last]
            head = ("the other ranks failed too:\n  " + "\n  ".join(others) + "\n"
                    if others else "")
            sys.stderr.write(f"{head}error on all {together.size} ranks; rank 0:\n{text}")
            sys.stderr.flush()
            print(f"error: {last}", flush=True)     # the last line of the output log too

    sys.excepthook = hook
