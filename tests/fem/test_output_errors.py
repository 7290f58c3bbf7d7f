"""Output to a full disk stops with one clear error naming the file and the cause, on every
rank (issue 24, item 6; serial and 2 ranks).

A full disk is simulated without root: the free space the writers see
(``rough_contact.io.files.free_bytes``) is patched, and the writers' own calls (DOLFINx's
``XDMFFile``, ``h5py.File``, ``os.fsync``) are patched to fail with ENOSPC the way they fail on a
full file system (checked by hand on a 1 MB tmpfs: docs/output.md).

* the free space is checked before a step is written: too little raises ``OutputWriteError``
  naming the files, the free space and the step's size, and nothing of the step is written
  (an HDF5 file that runs out of space half-way cannot even be closed);
* a write that fails all the same (DOLFINx's "Failed to close HDF5 file.", h5py's OSError, an
  ENOSPC from the CSV's atomic write) raises ``OutputWriteError`` naming the file and "no space
  left on device"; the CSV and interface files, written by rank 0, raise on every rank.
"""

from __future__ import annotations

import errno
import os
from types import SimpleNamespace

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem, mesh
from rough_contact.fem import compat
from rough_contact.io import OutputWriteError, ResultWriter
from rough_contact.io import files as files_module
from rough_contact.io import results as results_module


def _increment(step):
    zero = dict(target=1.0, iterations=1, residual=0.0, n_points=0, n_active=0, n_slipping=0,
                real_area=0.0, dissipation=0.0, cutbacks=0, wall_time=0.0, n_beyond_validity=0,
                newton_total=1, linear_iterations=1, linear_total=1, failed_attempts=0,
                augmentations=0, normal_dissipation=0.0, normal_dissipation_step=0.0)
    return SimpleNamespace(step=step, load_factor=0.5 * step, applied_force=np.zeros(3),
                           contact_force=np.zeros(3), **zero)


@pytest.fixture
def outdir(tmp_path_factory):
    comm = MPI.COMM_WORLD
    return comm.bcast(str(tmp_path_factory.mktemp("full")) if comm.rank == 0 else None)


def _u():
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 4, 4, 4)
    u = fem.Function(compat.vector_space(msh, 1), name="u")
    u.x.array[:] = 1.0
    return u


def _steps(path):
    if not os.path.exists(path):
        return 0
    return open(path).read().count("<Time ")


def test_too_little_free_space_is_refused_before_writing(outdir, monkeypatch):
    writer = ResultWriter(outdir, MPI.COMM_WORLD, u=_u())
    writer.write(_increment(1))
    monkeypatch.setattr(files_module, "free_bytes", lambda path: 20_000)
    with pytest.raises(OutputWriteError, match=(
            r"cannot write increment 2 to displacement.h5, history.csv in .*: no space left "
            r"on device \(20 kB free on the file system of .*, the step needs about")):
        writer.write(_increment(2))
    assert _steps(os.path.join(outdir, "displacement.xdmf")) == 1     # step 2 not begun
    assert open(os.path.join(outdir, "history.csv")).read().count("\n") == 2


class _FullDiskXDMF:
    """DOLFINx's XDMFFile on a full disk: the write reaches HDF5, whose close fails."""

    def __init__(self, comm, path, mode):
        pass

    def write_mesh(self, msh):
        pass

    def write_function(self, u, t):
        pass

    def close(self):
        raise RuntimeError("Failed to close HDF5 file.")


def test_failed_hdf5_write_names_the_file_and_the_cause(outdir, monkeypatch):
    writer = ResultWriter(outdir, MPI.COMM_WORLD, u=_u())
    monkeypatch.setattr(results_module, "XDMFFile", _FullDiskXDMF)
    real_free = files_module.free_bytes
    monkeypatch.setattr(files_module, "free_bytes",
                        lambda path: 0 if "displacement" in os.fspath(path) else real_free(path))
    with pytest.raises(OutputWriteError) as err:
        writer.write(_increment(1))
    h5 = os.path.join(outdir, "displacement.h5")
    assert str(err.value).startswith(f"cannot write {h5}: no space left on device (0 bytes "
                                     "free on the file system of")
    assert err.value.errno == errno.ENOSPC
    assert isinstance(err.value.__cause__, RuntimeError)       # HDF5's words are kept


def _enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_csv_on_a_full_disk_fails_on_every_rank(outdir, monkeypatch):
    """history.csv is written by rank 0 alone: its failure is raised on every rank, and the
    temporary file of the atomic write is removed."""
    writer = ResultWriter(outdir, MPI.COMM_WORLD)
    monkeypatch.setattr(files_module.os, "fsync", _enospc)
    csv_path = os.path.join(outdir, "history.csv")
    with pytest.raises(OutputWriteError, match=f"cannot write {csv_path}: no space left on "
                       "device"):
        writer.write(_increment(1))
    assert not [f for f in os.listdir(outdir) if ".tmp" in f]


def test_interface_h5_on_a_full_disk_fails_on_every_rank(outdir, monkeypatch):
    """interface.h5 (h5py, rank 0): an OSError of h5py with HDF5's errno text."""
    import h5py

    from rough_contact.interface.penalty import LinearPenalty
    from rough_contact.scenes.meshes.blocks import two_blocks
    from rough_contact.scenes.setup import clamped_pair

    scene = two_blocks(h1=0.5, h2=0.5, mesh_size=0.5, order=1)
    V = compat.vector_space(scene.mesh, 1)
    _, ci = clamped_pair(scene, V, LinearPenalty(1e3))
    ci.evaluate(fem.Function(V))
    writer = ResultWriter(outdir, MPI.COMM_WORLD, interface=ci)

    def full(*args, **kwargs):
        raise OSError("Unable to create file (file write failed: errno = 28, error message = "
                      "'No space left on device')")

    monkeypatch.setattr(h5py, "File", full)
    h5 = os.path.join(outdir, "interface.h5")
    with pytest.raises(OutputWriteError, match=f"cannot write {h5}: no space left on device"):
        writer.write(_increment(1))
