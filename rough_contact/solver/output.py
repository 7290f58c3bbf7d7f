"""Results on disk: displacement XDMF, interface point clouds, one CSV row per increment.

Units: mm, N, MPa (columns and fields carry their unit in the name).

Everything is written so that a crash never leaves a corrupt file and every converged increment
that was written stays readable:

* ``displacement.xdmf/.h5``: DOLFINx ``XDMFFile``, reopened in append mode and closed at every
  step (so the HDF5 file is flushed and the XML index rewritten per step).
* ``interface.xdmf/.h5``: the contact surface as facets with the interface fields per increment
  (``rough_contact.fem.interface_output.InterfaceWriter``; ``interface_points.xdmf`` holds the
  exact quadrature-point values), ParaView shows it by default (``docs/output.md``).
* Time values are the load factor while the load rises from 0, then the load path's length
  (``pseudo_time``): ParaView's time axis follows the load, never the step number.
* The folder holds exactly one run: earlier results make the writer refuse, or with
  ``overwrite=True`` they are removed first (``prepare_output_dir``).
* ``history.csv``: one row per converged increment, rewritten atomically.
"""

from __future__ import annotations

import csv
import io
import os
from typing import Iterable, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI

__all__ = ["ResultWriter", "gather_points", "atomic_write", "atomic_write_text"]


def atomic_write(path: str, content: Union[str, bytes, Iterable[bytes]]) -> None:
    """Write ``content`` to ``path`` atomically: a temporary file, fsync, ``os.replace``.

    A crash leaves either the old file or the new one, never a truncated one. Every file this
    module writes goes through here.

    Args:
        path: destination.
        content: text (written as UTF-8, newlines unchanged), bytes, or an iterable of bytes
            chunks (written one after the other).
    """
    if isinstance(content, str):
        chunks: Iterable[bytes] = [content.encode("utf-8")]
    elif isinstance(content, (bytes, bytearray)):
        chunks = [bytes(content)]
    else:
        chunks = content
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "wb") as fh:
        for chunk in chunks:
            fh.write(chunk)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def atomic_write_text(path: str, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`atomic_write`)."""
    atomic_write(path, text)


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


_CSV_COLUMNS = [
    ("step", "step"), ("load_factor", "load_factor"), ("target", "target"),
    ("newton_its", "iterations"), ("residual_N", "residual"), ("n_points", "n_points"),
    ("n_active", "n_active"), ("n_slipping", "n_slipping"), ("real_area_mm2", "real_area"),
    ("dissipation_Nmm", "dissipation"), ("cutbacks", "cutbacks"), ("wall_time_s", "wall_time"),
    ("n_beyond_validity", "n_beyond_validity"),
    ("newton_its_spent", "newton_total"), ("linear_its", "linear_iterations"),
    ("linear_its_spent", "linear_total"), ("failed_attempts", "failed_attempts"),
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
                 extra_patterns: Sequence[str] = ()):
        from rough_contact.fem.interface_output import InterfaceWriter, prepare_output_dir

        self.outdir = os.fspath(outdir)
        self.comm = comm
        self.removed = prepare_output_dir(self.outdir, comm, overwrite=overwrite,
                                          extra_patterns=extra_patterns)
        self.u = u
        self.interface_writer = (None if interface is None
                                 else InterfaceWriter(self.outdir, interface, points=points))
        self.extra_columns = tuple(extra_columns)
        self.rows: list = []
        self.load_factors: list = []
        self._u_out = None
        self._xdmf_started = False
        if u is not None:
            from dolfinx import fem

            msh = u.function_space.mesh
            degree = msh.geometry.cmap.degree
            V = u.function_space
            if V.ufl_element().degree() == degree:
                self._u_out = u
            else:  # XDMF needs the geometry's degree
                self._u_out = fem.Function(
                    fem.VectorFunctionSpace(msh, ("Lagrange", degree)), name=u.name)
        self.csv_path = os.path.join(self.outdir, "history.csv")
        self.u_path = os.path.join(self.outdir, "displacement.xdmf")

    # ------------------------------------------------------------------ displacement
    def _write_displacement(self, t: float) -> None:
        from dolfinx.io import XDMFFile

        if self._u_out is not self.u:
            self._u_out.interpolate(self.u)
        mode = "a" if self._xdmf_started else "w"
        with XDMFFile(self.comm, self.u_path, mode) as xdmf:
            if not self._xdmf_started:
                xdmf.write_mesh(self.u.function_space.mesh)
            xdmf.write_function(self._u_out, t)
        self._xdmf_started = True

    # ------------------------------------------------------------------ CSV
    def _write_csv(self, inc, extra: Optional[dict]) -> None:
        if self.comm.rank != 0:
            return
        row = [getattr(inc, attr) for _, attr in _CSV_COLUMNS]
        row += list(np.asarray(inc.applied_force, dtype=float).reshape(3))
        row += list(np.asarray(inc.contact_force, dtype=float).reshape(3))
        row += [(extra or {}).get(k, "") for k in self.extra_columns]
        self.rows.append(row)
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
        """
        from rough_contact.fem.interface_output import pseudo_time

        self.load_factors.append(float(inc.load_factor))
        t = float(pseudo_time(self.load_factors)[-1])
        if self.u is not None:
            self._write_displacement(t)
        if self.interface_writer is not None:
            self.interface_writer.write(inc.load_factor, t)
        self._write_csv(inc, extra)
