"""PETSc options database: scoped defaults under one prefix, and the unused-option report.

PETSc keeps ONE options database per process. A library that writes its defaults into it and
leaves them there changes every later object with the same prefix (a second solver would
inherit the first one's absolute tolerance). Here defaults are written only where the user
gave nothing, only for as long as PETSc reads them, and removed afterwards
(:func:`default_options`); options the user gave are never touched.

Options that were given but never read by any PETSc object (typically a mistyped name such as
``-rc_snes_monitr``) are found with PETSc's own bookkeeping (``PetscOptionsLeftGet``, the
facility behind ``-options_left``); petsc4py 3.18 does not expose it, so
:func:`unused_options` calls it through ``ctypes`` on the libpetsc that petsc4py loaded.
See ``docs/design.md`` ("PETSc options").
"""

from __future__ import annotations

import contextlib
import ctypes
import glob
import os
from typing import Iterator, Mapping

import numpy as np
import petsc4py
from petsc4py import PETSc

__all__ = ["set_default_options", "remove_options", "default_options", "unused_options"]


def set_default_options(prefix: str, defaults: Mapping[str, object]) -> list[str]:
    """Write ``defaults`` under ``prefix`` where the database holds no value yet.

    Returns:
        The full names (with prefix, without the dash) that were written; the caller removes
        them with :func:`remove_options` once PETSc has read them.
    """
    opts = PETSc.Options()
    written = []
    for key, value in defaults.items():
        name = prefix + key
        if not opts.hasName(name):
            opts.setValue(name, value)
            written.append(name)
    return written


def remove_options(names: list[str]) -> None:
    """Delete ``names`` (full names without the dash) from the options database."""
    opts = PETSc.Options()
    for name in names:
        opts.delValue(name)


@contextlib.contextmanager
def default_options(prefix: str, defaults: Mapping[str, object]) -> Iterator[list[str]]:
    """Context in which ``defaults`` are in the database under ``prefix`` (where absent).

    On exit exactly the options written on entry are removed, also after an exception.
    Wrap both ``setFromOptions`` and the solves in it: some options are read only when PETSc
    sets a preconditioner up (e.g. the multigrid level smoothers ``mg_levels_*``).

    Yields:
        The names written.
    """
    written = set_default_options(prefix, defaults)
    try:
        yield written
    finally:
        remove_options(written)


def unused_options(prefix: str = "") -> list[str]:
    """Options of this process's database under ``prefix`` that no PETSc object has read.

    Args:
        prefix: only names starting with it are returned ("" = all).

    Returns:
        Names without the leading dash, in the database's order.

    Raises:
        RuntimeError: the PETSc library petsc4py uses cannot be queried.
    """
    lib, int_t = _petsc_library()
    n = int_t(0)
    names = ctypes.POINTER(ctypes.c_char_p)()
    values = ctypes.POINTER(ctypes.c_char_p)()
    ierr = lib.PetscOptionsLeftGet(None, ctypes.byref(n), ctypes.byref(names),
                                   ctypes.byref(values))
    if ierr:
        raise RuntimeError(f"PetscOptionsLeftGet failed with PETSc error code {ierr}")
    try:
        left = [names[i].decode() for i in range(n.value)]
    finally:
        lib.PetscOptionsLeftRestore(None, ctypes.byref(n), ctypes.byref(names),
                                    ctypes.byref(values))
    return [name for name in left if name.startswith(prefix)]


_LIBRARY: list = []  # the loaded (library, PetscInt ctype), filled once


def _petsc_library():
    """The libpetsc that petsc4py runs on, and the ctype of PetscInt.

    The library is found from petsc4py's configuration and checked to share petsc4py's
    options database (a probe option set through petsc4py must be visible), so a second,
    different PETSc on the machine cannot give a silently empty report.
    """
    if _LIBRARY:
        return _LIBRARY[0]
    config = petsc4py.get_config()
    libdir = os.path.join(config["PETSC_DIR"], config["PETSC_ARCH"], "lib")
    candidates = sorted(glob.glob(os.path.join(libdir, "libpetsc*.so*")))
    if not candidates:
        raise RuntimeError(f"no libpetsc*.so in {libdir} (petsc4py.get_config()); cannot list "
                           "unused PETSc options")
    lib = ctypes.CDLL(candidates[0])
    int_t = ctypes.c_int64 if np.dtype(PETSc.IntType).itemsize == 8 else ctypes.c_int32
    lib.PetscOptionsLeftGet.restype = ctypes.c_int
    lib.PetscOptionsLeftRestore.restype = ctypes.c_int
    lib.PetscOptionsHasName.restype = ctypes.c_int
    probe = "rc_probe_shared_options_database"
    opts = PETSc.Options()
    opts.setValue(probe, "1")
    found = ctypes.c_int(0)
    try:
        ierr = lib.PetscOptionsHasName(None, None, ("-" + probe).encode(), ctypes.byref(found))
    finally:
        opts.delValue(probe)
    if ierr or not found.value:
        raise RuntimeError(f"{candidates[0]} is not the PETSc library petsc4py uses (its "
                           "options database does not see petsc4py's options)")
    _LIBRARY.append((lib, int_t))
    return _LIBRARY[0]
