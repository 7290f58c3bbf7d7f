"""Worker of test_demos.py::test_uncaught_exception_on_some_ranks_aborts: ranks that fail with
an uncaught exception under ``abort_on_uncaught_exception`` (1 s grace).

    mpirun -n 2 python failing_ranks.py all|one

``all``: every rank raises the same ValueError; ``one``: rank 1 raises, rank 0 waits in a
barrier it never leaves unless the job is aborted. mpi4py only (no dolfinx).
"""

import sys

from mpi4py import MPI

from rough_contact.solver.parallel import abort_on_uncaught_exception

abort_on_uncaught_exception(grace=1.0)
comm = MPI.COMM_WORLD
if sys.argv[1] == "all" or comm.rank == 1:
    raise ValueError(f"steps = 0 is invalid (rank {comm.rank} of {comm.size})")
comm.barrier()
