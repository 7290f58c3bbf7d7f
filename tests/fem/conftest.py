"""Collective clean-up between FE tests.

PETSc objects on a parallel communicator (a SNES with MUMPS, matrices, vectors) must be destroyed
on every rank at the same point: MUMPS's clean-up is collective. Python's cyclic garbage collector
runs when a rank has allocated enough objects, which differs between ranks (rank 0 builds the gmsh
models), so an object kept alive by a reference cycle — a test's traceback after an expected
exception, a closure around a solver — could be destroyed on one rank in the middle of another
test's collective, and the ranks would wait for each other forever. Here the automatic collector
is off during the FE tests, and every rank collects, and PETSc empties its garbage of parallel
objects, after each test, together.
"""

from __future__ import annotations

import gc

import pytest
from mpi4py import MPI
from petsc4py import PETSc


@pytest.fixture(autouse=True, scope="session")
def _no_automatic_gc():
    gc.disable()
    yield
    gc.enable()


@pytest.fixture(autouse=True)
def _collect_together():
    yield
    MPI.COMM_WORLD.barrier()
    gc.collect()
    PETSc.garbage_cleanup(MPI.COMM_WORLD)
    MPI.COMM_WORLD.barrier()
