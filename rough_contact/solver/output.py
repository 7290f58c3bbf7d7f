"""Results on disk: displacement XDMF, interface point clouds, one CSV row per increment.

Units: mm, N, MPa (columns and fields carry their unit in the name).

Everything is written so that a crash never leaves a corrupt file and every converged increment
that was written stays readable:

* ``displacement.xdmf/.h5``: DOLFINx ``XDMFFile``, reopened in append mode and closed at every
  step (so the HDF5 file is flushed and the XML index rewritten per step).
* ``interface.xdmf``: the interface quadrature points as an XDMF ``Polyvertex`` point cloud with
  one grid per step; the data of step k go to ``interface_<k>.bin`` (raw little-endian float64,
  written to a temporary file then renamed), and the small XML index is rewritten atomically
  (temporary file + ``os.replace``). ParaView reads it with the "XDMF Reader".
* ``history.csv``: one row per converged increment, rewritten atomically.

Point fields come gathered to rank 0 in global point order (rank by rank).
"""

from __future__ import annotations

import csv
import io
import os
from typing import Iterable, Optional, Union

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
]


class ResultWriter:
    """Write displacement, interface point fields and a CSV history for each increment.

    Args:
        outdir: output directory (created).
        comm: communicator.
        u: displacement function (written to ``displacement.xdmf``), or ``None``.
        point_data: callable returning ``(points (n, 3), {name: (n,) or (n, k) array})`` for the
            locally owned interface points, or ``None``.
        extra_columns: names of extra CSV columns filled from ``write(..., extra=)``.
    """

    def __init__(self, outdir: str, comm: MPI.Comm, u=None, point_data=None,
                 extra_columns: tuple = ()):
        self.outdir = os.fspath(outdir)
        self.comm = comm
        if comm.rank == 0:
            os.makedirs(self.outdir, exist_ok=True)
        comm.barrier()
        self.u = u
        self.point_data = point_data
        self.extra_columns = tuple(extra_columns)
        self.rows: list = []
        self.grids: list = []
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
        self.pc_path = os.path.join(self.outdir, "interface.xdmf")

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

    # ------------------------------------------------------------------ point cloud
    def _write_points(self, step: int, t: float) -> None:
        pts, fields = self.point_data()
        pts, fields = gather_points(self.comm, pts, fields)
        if self.comm.rank != 0:
            return
        name = f"interface_{step:04d}.bin"
        chunks, items, offset = [], [], 0
        n = len(pts)
        for key, arr in [("__geometry__", pts)] + list(fields.items()):
            arr = np.ascontiguousarray(arr, dtype="<f8")
            chunks.append(arr.tobytes())
            items.append((key, arr.shape, offset))
            offset += arr.nbytes
        atomic_write(os.path.join(self.outdir, name), chunks)
        self.grids.append((step, t, n, name, items))
        atomic_write(self.pc_path, self._point_cloud_xml())

    def _point_cloud_xml(self) -> str:
        lines = ['<?xml version="1.0" ?>', '<Xdmf Version="3.0">', "  <Domain>",
                 '    <Grid Name="interface" GridType="Collection" CollectionType="Temporal">']
        for step, t, n, name, items in self.grids:
            lines.append(f'      <Grid Name="step_{step}" GridType="Uniform">')
            lines.append(f'        <Time Value="{t!r}"/>')
            lines.append(f'        <Topology TopologyType="Polyvertex" NumberOfElements="{n}" '
                         'NodesPerElement="1"/>')
            for key, shape, off in items:
                dims = " ".join(str(d) for d in shape)
                item = (f'<DataItem Format="Binary" NumberType="Float" Precision="8" '
                        f'Endian="Little" Seek="{off}" Dimensions="{dims}">{name}</DataItem>')
                if key == "__geometry__":
                    lines.append(f'        <Geometry GeometryType="XYZ">{item}</Geometry>')
                else:
                    # (n,) scalar, (n, 3) vector, anything else (e.g. (n, 2)) a matrix
                    kind = "Scalar" if len(shape) == 1 else (
                        "Vector" if shape[1] == 3 else "Matrix")
                    lines.append(f'        <Attribute Name="{key}" AttributeType="{kind}" '
                                 f'Center="Node">{item}</Attribute>')
            lines.append("      </Grid>")
        lines += ["    </Grid>", "  </Domain>", "</Xdmf>", ""]
        return "\n".join(lines)

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
        t = float(inc.step)
        if self.u is not None:
            self._write_displacement(t)
        if self.point_data is not None:
            self._write_points(inc.step, t)
        self._write_csv(inc, extra)
