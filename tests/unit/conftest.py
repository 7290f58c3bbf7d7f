"""Fixtures shared by the unit tests."""

from __future__ import annotations

import subprocess
import sys

import pytest

FE_STACK = ("dolfinx", "ufl", "petsc4py", "basix", "mpi4py", "gmsh")


@pytest.fixture
def imports_without():
    """``imports_without(modules, also=())``: import ``modules`` in a fresh interpreter and fail
    if that loaded any of the FE/MPI stack (``FE_STACK``) or of the further modules ``also``."""

    def check(modules, also=()):
        code = ("import importlib, sys\n"
                f"for name in {list(modules)!r}:\n"
                "    importlib.import_module(name)\n"
                f"bad = {set(FE_STACK) | set(also)!r} & set(sys.modules)\n"
                "assert not bad, bad\n")
        subprocess.run([sys.executable, "-c", code], check=True)

    return check


def pytest_addoption(parser):
    parser.addoption("--run-slow", action="store_true", default=False,
                     help="also run the tests marked slow (minutes each: independent "
                          "quadratures of the summit population)")


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: takes minutes; run with --run-slow")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--run-slow"):
        return
    skip = pytest.mark.skip(reason="slow (minutes): run with --run-slow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
