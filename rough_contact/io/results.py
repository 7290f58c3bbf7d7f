"""Results on disk: displacement XDMF, interface point clouds, one CSV row per increment.

Units: mm, N, MPa (columns and fields carry their unit in the name).

Everything is written so that a crash never leaves a corrupt file and every converged increment
that was written stays readable:

* ``displacement.xdmf/.h5``: DOLFINx ``XDMFFile``, reopened in append mode and closed at every
  step (so the HDF5 file is flushed and the XML index rewritten per step).
* ``interface.xdmf/.h5``: the contact surface as facets with the interface fields per increment
  (``rough_contact.io.interface_output.InterfaceWriter``; ``interface_points.xdmf`` holds the
  exact quadrature-point values), ParaView shows it by default (``docs/output.md``).
* Time values are the load factor while the load rises from 0, then the load path's length
  (``pseudo_time``): ParaView's time axis follows the load, never the step number.
* The folder holds exactly one run: earlier results make the writer refuse, or with
  ``overwrite=True`` they are removed first (``rough_contact.io.files.prepare_output_dir``).
* ``history.csv``: one row per converged increment, rewritten atomically
  (``rough_contact.io.files.atomic_write``).
* Restart (``load_path(..., checkpoint=, outputs=[writer])``): the writer's state (CSV rows,
  load factors, the number of XDMF steps) is saved in every checkpoint
  (:meth:`ResultWriter.checkpoint_state`); a writer built with ``resume=True`` leaves the folder
  alone and :meth:`ResultWriter.restore` cuts every file back to the checkpointed step (steps a
  killed run wrote after its last checkpoint are dropped from the XML index and their HDF5
  datasets deleted), so the resumed run's increments continue the same files: one CSV, one
  XDMF time series per file. An HDF5 file damaged by a kill in the middle of its write is
  moved aside (``*.damaged``) and its series restarts at the resumed step, with a warning.
"""

from __future__ import annotations

import contextlib
import csv
import ctypes
import hashlib
import io
import os
import warnings
import xml.etree.ElementTree as ET
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from dolfinx import fem
from dolfinx.io import XDMFFile
from rough_contact.fem import compat
from rough_contact.fem.collective import run_on_root
from rough_contact.io.files import (atomic_write, atomic_write_text, check_free_space,
                                   parse_xdmf, prepare_output_dir,
                                   write_failure)
from rough_contact.io.interface_output import InterfaceWriter, pseudo_time

__all__ = ["ResultWriter", "CsvRecorder", "gather_points", "truncate_time_series"]


def gather_points(comm: MPI.Comm, points: np.ndarray, fields: dict, root: int = 0):
    """Gather per-rank point coordinates (n, 3) and fields {name: (n,) or (n, k)} to ``root``.

    Returns:
        ``(points, fields)`` concatenated in rank order on ``root``; ``(None, None)`` elsewhere.
    """
    points = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
    allp = comm.gather(points, root=root)
    allf = comm.gather({k: np.asarray(v, dtype=float) for k, v in fields.items()}, root=root)
    if comm.rank != root:
        return None, None
    pts = np.concatenate(allp, axis=0)
    out = {}
    for key in fields:
        parts = [np.asarray(f[key]) for f in allf]
        trailing = next((a.shape[1:] for a in parts if a.size), parts[0].shape[1:])
        parts = [a.reshape((len(p),) + trailing) for a, p in zip(parts, allp)]
        out[key] = np.concatenate(parts, axis=0)
    return pts, out




def truncate_time_series(path: str, n_keep: int) -> bool:
    """Cut the DOLFINx XDMF time series ``path`` back to its first ``n_keep`` steps (serial).

    Every temporal collection keeps its first ``n_keep`` grids; the HDF5 datasets of the dropped
    grids are deleted (DOLFINx refuses to write a dataset that exists), and the XML is rewritten
    atomically. Returns False when the files cannot be continued (missing, or an unreadable XML
    or HDF5 file, e.g. a kill during its write): they are then moved aside as ``*.damaged`` and
    the caller starts the series afresh.
    """
    import h5py

    folder = os.path.dirname(path) or "."
    h5_path = os.path.splitext(path)[0] + ".h5"
    if not os.path.exists(path):
        return False
    try:
        root = parse_xdmf(path)
        dropped, kept = set(), set()
        for series in root.iter("Grid"):
            if series.get("CollectionType") != "Temporal":
                continue
            for k, grid in enumerate(list(series.findall("Grid"))):
                items = {it.text.strip() for it in grid.iter("DataItem")
                         if it.get("Format") == "HDF"}
                if k < n_keep:
                    kept |= items
                else:
                    dropped |= items
                    series.remove(grid)
        with h5py.File(h5_path, "a") as h5:
            for item in sorted(dropped - kept):
                name, _, dataset = item.partition(":")
                if os.path.join(folder, name) == h5_path and dataset in h5:
                    del h5[dataset]
            for item in kept:                     # every kept step must be readable
                name, _, dataset = item.partition(":")
                if os.path.join(folder, name) == h5_path:
                    h5[dataset].shape             # noqa: B018 -- raises if missing/damaged
    except (ET.ParseError, OSError, KeyError) as exc:
        for f in (path, h5_path):
            if os.path.exists(f):
                os.replace(f, f + ".damaged")
        warnings.warn(f"{path} could not be continued ({type(exc).__name__}: {exc}); moved "
                      "aside as *.damaged, the time series restarts at the resumed step",
                      RuntimeWarning, stacklevel=2)
        return False
    text = ET.tostring(root, encoding="unicode")
    atomic_write_text(path, '<?xml version="1.0"?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n'
                      + text + "\n")
    return True


_CSV_COLUMNS = [
    ("step", "step"), ("load_factor", "load_factor"), ("target", "target"),
    ("newton_its", "iterations"), ("residual_N", "residual"), ("n_points", "n_points"),
    ("n_active", "n_active"), ("n_slipping", "n_slipping"), ("real_area_mm2", "real_area"),
    ("dissipation_Nmm", "dissipation"), ("cutbacks", "cutbacks"), ("wall_time_s", "wall_time"),
    ("n_beyond_validity", "n_beyond_validity"),
    ("newton_its_spent", "newton_total"), ("linear_its", "linear_iterations"),
    ("linear_its_spent", "linear_total"), ("failed_attempts", "failed_attempts"),
    ("al_updates", "augmentations"),
    ("normal_dissipation_Nmm", "normal_dissipation"),
    ("normal_dissipation_step_Nmm", "normal_dissipation_step"),
]


class ResultWriter:
    """Write displacement, interface fields on the contact surface and a CSV history per increment.

    Args:
        outdir: output directory (created; it must not hold an earlier run's results unless
            ``overwrite``).
        comm: communicator.
        u: displacement function (written to ``displacement.xdmf``), or ``None``.
        interface: the contact interface whose fields go to ``interface.xdmf``, or ``None``.
        points: also write the exact quadrature-point values (``interface_points.xdmf``).
        extra_columns: names of extra CSV columns filled from ``write(..., extra=)``.
        overwrite: remove an earlier run's results from ``outdir`` instead of refusing.
        extra_patterns: file-name patterns (regular expressions) of the caller's own outputs in
            ``outdir`` that belong to a run (e.g. its figures), removed or refused alike.

    Raises:
        OutputExistsError: ``outdir`` holds an earlier run's results and ``overwrite`` is False.
    """

    def __init__(self, outdir: str, comm: MPI.Comm, u=None, interface=None, *,
                 points: bool = True, extra_columns: tuple = (), overwrite: bool = False,
                 extra_patterns: Sequence[str] = (), resume: bool = False):
        self.outdir = os.fspath(outdir)
        self.comm = comm
        if resume:       # the files belong to the run being resumed: restore() trims them
            self.removed = []
            if comm.rank == 0:
                os.makedirs(self.outdir, exist_ok=True)
            comm.Barrier()
        else:
            self.removed = prepare_output_dir(self.outdir, comm, overwrite=overwrite,
                                              extra_patterns=extra_patterns)
        self.u = u
        self.interface_writer = (None if interface is None
                                 else InterfaceWriter(self.outdir, interface, points=points,
                                                      resume=resume))
        self.extra_columns = tuple(extra_columns)
        self.rows: list = []
        self.load_factors: list = []
        self._u_out = None
        self._xdmf_started = False
        self._xdmf_steps = 0
        self._mesh_name: Optional[str] = None    # None: the file's first mesh (see restore)
        self._mesh_written = True
        if u is not None:
            msh = u.function_space.mesh
            degree = compat.geometry_degree(msh)
            V = u.function_space
            if compat.element_degree(V) == degree:
                self._u_out = u
            else:  # XDMF needs the geometry's degree
                self._u_out = fem.Function(compat.vector_space(msh, degree), name=u.name)
        self.csv_path = os.path.join(self.outdir, "history.csv")
        self.u_path = os.path.join(self.outdir, "displacement.xdmf")
        self._layout_now = self._layout()
        # interface points and facets of all ranks (for the free-space estimate)
        n_local = 0 if interface is None else len(interface.point_weights())
        self._interface_slots = comm.allreduce(
            0 if interface is None else n_local + n_local // max(interface.n_qp, 1), op=MPI.SUM)

    # ------------------------------------------------------------------ displacement
    def _write_displacement(self, t: float) -> None:
        if self._u_out is not self.u:
            self._u_out.interpolate(self.u)
        mode = "a" if self._xdmf_started else "w"
        msh = self.u.function_space.mesh
        if not self._xdmf_started:
            self._mesh_name, self._mesh_written = None, True
        xdmf = None
        try:
            with _quiet_hdf5():
                xdmf = XDMFFile(self.comm, self.u_path, mode)
                if not self._xdmf_started:
                    xdmf.write_mesh(msh)
                if self._mesh_name is None:
                    xdmf.write_function(self._u_out, t)
                else:       # a resumed run on another partition: its own mesh grid (restore)
                    if not self._mesh_written:
                        name, msh.name = msh.name, self._mesh_name
                        try:
                            xdmf.write_mesh(msh)
                        finally:
                            msh.name = name
                        self._mesh_written = True
                    xdmf.write_function(
                        self._u_out, t,
                        mesh_xpath=f"/Xdmf/Domain/Grid[@Name='{self._mesh_name}'][1]")
                xdmf.close()
        except RuntimeError as exc:
            # HDF5 failed (e.g. the disk ran full during the write). No collective here: a
            # rank of DOLFINx's writer may fail while another goes on into the writer's next
            # collective, so agreeing on the failure would hang; each failing rank raises the
            # clear error (an entry script's abort_on_uncaught_exception ends the job).
            if xdmf is not None:
                _never_destroy(xdmf)
            raise write_failure(os.path.splitext(self.u_path)[0] + ".h5", exc) from exc
        self._xdmf_started = True
        self._xdmf_steps += 1

    def _layout(self) -> str:
        """Digest of the order in which the displacement file's mesh lists the geometry nodes
        (collective): it depends on the partition, and a function's values follow it."""
        if self.u is None:
            return ""
        mine = compat.geometry_input_indices(self.u.function_space.mesh)
        every = self.comm.gather(mine, root=0)
        digest = None
        if self.comm.rank == 0:
            digest = hashlib.sha256(np.concatenate(every).astype(np.int64).tobytes()).hexdigest()
        return self.comm.bcast(digest, root=0)

    def _bytes_per_step(self) -> int:
        """An upper estimate of what one :meth:`write` adds to the folder [bytes]: the
        displacement values (and the mesh at the first step), the interface's facet and point
        fields (at most 24 values each; 20 are written), 25 % for HDF5's own records and 128 kB
        for the CSV and XML indexes."""
        n = 0
        if self.u is not None:
            V = self._u_out.function_space
            n += 8 * V.dofmap.index_map.size_global * V.dofmap.index_map_bs
            if not self._xdmf_started:
                msh = V.mesh
                n += 8 * 3 * msh.geometry.index_map().size_global
                n += 8 * msh.topology.index_map(msh.topology.dim).size_global * \
                    compat.geometry_dofmap(msh).shape[1]
        n += 8 * 24 * self._interface_slots
        return int(1.25 * n) + 128 * 1024

    # ------------------------------------------------------------------ restart
    def checkpoint_state(self) -> dict:
        """What :meth:`restore` needs to continue these files (this rank's, picklable)."""
        return dict(rows=list(self.rows), load_factors=list(self.load_factors),
                    xdmf_steps=self._xdmf_steps, layout=self._layout_now,
                    mesh_name=self._mesh_name,
                    interface=None if self.interface_writer is None
                    else self.interface_writer.checkpoint_state())

    def restore(self, state: dict) -> None:
        """Continue from :meth:`checkpoint_state` (collective): cut the CSV, the displacement
        series and the interface files back to the checkpointed step."""
        self.rows = list(state["rows"])
        self.load_factors = list(state["load_factors"])
        if self.comm.rank == 0 and self.rows:
            self._flush_csv()
        if self.u is not None:
            n = int(state["xdmf_steps"])
            ok = run_on_root(self.comm, lambda: truncate_time_series(self.u_path, n)) if n else \
                False
            self._xdmf_started = ok
            self._xdmf_steps = n if ok else 0
            # the file's functions follow the node order of the mesh grid they point to; on
            # another partition (or number of ranks) the next steps get a mesh grid of their own
            self._mesh_name, self._mesh_written = state.get("mesh_name"), True
            if ok and state.get("layout") != self._layout_now:
                name = f"mesh_{self._layout_now[:12]}"
                self._mesh_name = name
                self._mesh_written = bool(run_on_root(self.comm, lambda: any(
                    g.get("Name") == name for g in parse_xdmf(self.u_path).iter("Grid"))))
        if self.interface_writer is not None:
            self.interface_writer.restore(state["interface"])

    # ------------------------------------------------------------------ CSV
    def _write_csv(self, inc, extra: Optional[dict]) -> None:
        """Append the row and rewrite the file on rank 0; a failure raises on every rank."""
        row = [getattr(inc, attr) for _, attr in _CSV_COLUMNS]
        row += list(np.asarray(inc.applied_force, dtype=float).reshape(3))
        row += list(np.asarray(inc.contact_force, dtype=float).reshape(3))
        row += [(extra or {}).get(k, "") for k in self.extra_columns]

        def act():
            self.rows.append(row)
            self._flush_csv()

        run_on_root(self.comm, act)

    def _flush_csv(self) -> None:
        header = [c for c, _ in _CSV_COLUMNS] + ["applied_fx_N", "applied_fy_N", "applied_fz_N",
                                                 "contact_fx_N", "contact_fy_N", "contact_fz_N"]
        header += list(self.extra_columns)
        text = io.StringIO(newline="")
        w = csv.writer(text)
        w.writerow(header)
        for r in self.rows:
            w.writerow([f"{v:.10g}" if isinstance(v, float) else v for v in r])
        atomic_write(self.csv_path, text.getvalue())

    def write(self, inc, extra: Optional[dict] = None) -> None:
        """Write increment ``inc`` (a :class:`~rough_contact.solver.loading.Increment`).

        Collective.

        Raises:
            OutputWriteError (every rank): the folder's file system has not the room for the
                increment (checked before writing: an HDF5 file that runs out of space cannot
                even be closed), or a write failed; the message names the file and the cause.
        """
        needed = self._bytes_per_step()
        files = ", ".join(os.path.basename(f) for f, on in (
            (self.u_path.replace(".xdmf", ".h5"), self.u is not None),
            (os.path.join(self.outdir, "interface.h5"), self.interface_writer is not None),
            (self.csv_path, True)) if on)
        run_on_root(self.comm, lambda: check_free_space(
            self.outdir, needed, f"increment {inc.step} to {files} in {self.outdir}"))
        self.load_factors.append(float(inc.load_factor))
        t = float(pseudo_time(self.load_factors)[-1])
        if self.u is not None:
            self._write_displacement(t)
        if self.interface_writer is not None:
            self.interface_writer.write(inc.load_factor, t)
        self._write_csv(inc, extra)


@contextlib.contextmanager
def _quiet_hdf5():
    """Silence HDF5's automatic error printing (dozens of lines per failure, on every rank)
    while DOLFINx writes: its failure is reported once, as an :class:`OutputWriteError`. The
    library is the HDF5 loaded in this process (found in /proc/self/maps); where it cannot be
    found, nothing changes."""
    lib = _hdf5_library()
    if lib is None:
        yield
        return
    func, data = ctypes.c_void_p(), ctypes.c_void_p()
    lib.H5Eget_auto2(ctypes.c_int64(0), ctypes.byref(func), ctypes.byref(data))  # H5E_DEFAULT
    lib.H5Eset_auto2(ctypes.c_int64(0), None, None)
    try:
        yield
    finally:
        lib.H5Eset_auto2(ctypes.c_int64(0), func, data)


_HDF5 = []


def _hdf5_library():
    if not _HDF5:
        lib = None
        try:
            with open("/proc/self/maps") as f:
                paths = {ln.split()[-1] for ln in f if "libhdf5" in ln and "_hl" not in ln}
            for path in sorted(paths):
                candidate = ctypes.CDLL(path)
                if hasattr(candidate, "H5Eset_auto2") and hasattr(candidate, "H5Eget_auto2"):
                    lib = candidate
                    break
        except OSError:
            lib = None
        _HDF5.append(lib)
    return _HDF5[0]


_UNCLOSED = []


def _never_destroy(obj) -> None:
    """Keep ``obj`` alive to the end of the process and past it: the C++ destructor of an
    XDMFFile whose close failed tries to close again, throws, and terminates the process
    (``std::terminate``) at exit, after the clear error."""
    _UNCLOSED.append(obj)
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))


class CsvRecorder:
    """Rows of named values, one per increment, kept on every rank and written by rank 0 to
    ``path`` (rewritten atomically per row; ``None``: memory only). Resumable: pass it in
    ``load_path(..., outputs=[recorder])`` and a resumed run continues its rows and file.

    Args:
        path: CSV file, or None.
        columns: column names.
        comm: communicator.
    """

    def __init__(self, path: Optional[str], columns: Sequence[str], comm: MPI.Comm):
        self.path = None if path is None else os.fspath(path)
        self.columns = tuple(columns)
        self.comm = comm
        self.rows: list = []

    def add(self, row: Sequence[float]) -> None:
        """Append one row (the same on every rank) and rewrite the file."""
        if len(row) != len(self.columns):
            raise ValueError(f"a row of {len(row)} values for {len(self.columns)} columns "
                             f"({', '.join(self.columns)})")
        self.rows.append(tuple(float(v) for v in row))
        self._flush()

    def _flush(self) -> None:
        """Rewrite the file on rank 0 (collective: a failure raises on every rank)."""
        if self.path is None:
            return

        def act():
            os.makedirs(os.path.dirname(self.path) or ".", exist_ok=True)
            text = io.StringIO(newline="")
            w = csv.writer(text)
            w.writerow(self.columns)
            w.writerows([[f"{v:.12g}" for v in r] for r in self.rows])
            atomic_write(self.path, text.getvalue())

        run_on_root(self.comm, act)

    def array(self) -> np.ndarray:
        """(n_rows, n_columns) values."""
        return np.array(self.rows, dtype=float).reshape(-1, len(self.columns))

    def checkpoint_state(self) -> list:
        return list(self.rows)

    def restore(self, state: list) -> None:
        self.rows = list(state)
        self._flush()

