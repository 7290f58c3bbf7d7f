"""Interface results as surface fields on the contact facets, in XDMF that ParaView shows.

Units: mm, N, MPa. Field names carry their unit (``pressure_MPa``, ``slip_mm``, ...).

The interface operator (:class:`~rough_contact.fem.contact.ContactInterface`) holds its results
at facet quadrature points. For viewing they are turned into **one value per facet** of the
first contact surface:

* **quadrature averaging**: f_F = sum_q w_q f_q / sum_q w_q over the points q of facet F, with
  the interface's own quadrature weights w_q (area represented by each point). This *is* the
  L2 projection onto piecewise constants (DG0) on the facets, computed with the quadrature rule
  the interface integrates with: int_F (f - f_F) dA = 0 with that rule. Hence the integral of a
  facet field over the surface equals the interface's own integral of the point values: the
  facet-averaged traction integrated over the facets is the contact force, exactly.
* **vectors in global axes**: slip, plastic slip, traction and its tangential part are rotated
  from the local axes (n, x, y) of every point to global (X, Y, Z) *before* averaging, and are
  written as 3-component vectors (ParaView draws them with Glyph as arrows).
* **status** per facet: 0 = open, 1 = stick, 2 = slip, the state that covers the largest part
  of the facet's area (sum of quadrature weights of its points in that state); a point is open
  where p = 0 (not in contact), slipping where the friction limit is active, else sticking.
  Ties (parts equal to within 1e-9 of the facet area) go to the more active state (slip, then
  stick).
  ``contact_fraction`` and ``slip_fraction`` give the parts of each facet in contact and
  slipping [-], so the status never hides a partly slipping facet.

:class:`InterfaceWriter` writes, under ``outdir``:

* ``interface.xdmf`` + ``interface.h5``: the facet surface (triangles or quadrilaterals through
  the facet vertices; curved P2 facets are drawn flat) written once, and the facet fields of
  every written increment; one XDMF grid per increment in one temporal collection, all fields
  as cell data of that grid. The time value is the load factor (see :func:`pseudo_time` for
  load paths that go back down); the load factor and step number are stored with every step.
* optionally ``interface_points.xdmf`` (same ``interface.h5``): the exact values at the
  quadrature points as a point cloud (XDMF Polyvertex), with the same vector fields, the
  status per point and the quadrature weight ``weight_mm2`` (sum weight * value is the
  interface's own integral).

Everything is gathered to rank 0 and written there (the interface is surface-sized). The
facets and vertices are ordered by coordinates, so the files do not depend on the number of
ranks. Crash safety as in :mod:`rough_contact.io.results`: the HDF5 file is reopened and
closed at every step (flushed), and the XML index, which is the only thing that lists a step,
is rewritten atomically (temporary file + ``os.replace``) after the step's data are closed:
a failure never corrupts earlier steps.

The output folder holds exactly one run (:func:`rough_contact.io.files.prepare_output_dir`).
"""

from __future__ import annotations

import os
import re
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any, Optional, Protocol, Sequence

import numpy as np
from mpi4py import MPI

from rough_contact.fem import compat
from rough_contact.fem.collective import run_on_root
from rough_contact.fem.contact import PointFields
from rough_contact.io.files import (OutputExistsError, atomic_write_text, check_free_space,
                                   parse_xdmf, run_files, writing)
from rough_contact.validation import check_integer

__all__ = [
    "STATUS_OPEN", "STATUS_STICK", "STATUS_SLIP", "STATUS_NAMES", "InterfaceOutputSource",
    "PointOutput", "FacetOutput", "SurfaceMesh", "InterfaceWriter", "InterfaceResults",
    "FACET_FIELD_NAMES", "POINT_FIELD_NAMES", "MEMORY_FIELD_NAMES", "facet_average", "facet_status",
    "point_output", "facet_output", "facet_vertex_coordinates", "gather_surface",
    "pseudo_time", "read_interface_results",
]

STATUS_OPEN, STATUS_STICK, STATUS_SLIP = 0, 1, 2
STATUS_NAMES = ("open", "stick", "slip")
_TIE = 1e-9  # relative area below which two parts of a facet count as equal

FACET_XDMF, POINT_XDMF, H5_FILE = "interface.xdmf", "interface_points.xdmf", "interface.h5"


class InterfaceOutputSource(Protocol):
    """What the output layer reads from the interface operator (``ContactInterface``).

    Points are facet-major: point i lies on the owned facet ``facets[i // n_qp]``.
    """

    comm: MPI.Comm
    V: Any  # dolfinx vector function space; only its mesh is used
    n_qp: int

    @property
    def facets(self) -> np.ndarray:
        """(n_facets,) local indices of the owned first-surface facets, in point order."""

    def local_frames(self) -> np.ndarray:
        """(n_pts, 3, 3) rows n, x, y of the local axes in global components."""

    def point_coordinates(self) -> np.ndarray:
        """(n_pts, 3) point coordinates [mm]."""

    def point_fields(self) -> PointFields:
        """Fields at the points at the last evaluation."""


# --------------------------------------------------------------------------------------------
# point and facet fields (pure numpy)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _InterfaceFields:
    """The fields of the points and of the facets (``_FIELDS``, in that order); what they are at
    each: :class:`PointOutput`, :class:`FacetOutput`."""

    pressure: np.ndarray
    area_fraction: np.ndarray
    gap: np.ndarray
    slip: np.ndarray
    plastic_slip: np.ndarray
    traction: np.ndarray
    shear_traction: np.ndarray
    dissipation: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class PointOutput(_InterfaceFields):
    """Interface fields at this rank's quadrature points, vectors in global axes.

    Attributes:
        pressure: (n,) contact pressure p = -t_N [MPa].
        area_fraction: (n,) real-area fraction A/A0 [-].
        gap: (n,) normal jump g = (u_second - u_first) . n [mm] (> 0 opens).
        slip: (n, 3) tangential part of u_second - u_first [mm].
        plastic_slip: (n, 3) plastic (irreversible) part of the slip [mm].
        traction: (n, 3) traction on the first body's surface [MPa]; int traction dA is
            ``ContactInterface.contact_force()``.
        shear_traction: (n, 3) tangential part of ``traction`` [MPa].
        dissipation: (n,) accumulated frictional dissipation per area [N/mm] (= mJ/mm^2).
        status: (n,) int32, 0 open, 1 stick, 2 slip.
        weight: (n,) area represented by the point [mm^2].
        h_min, max_closure, normal_dissipation: (n,) only for a normal law with memory
            (else None): smallest separation reached [mm] (NaN where virgin), the largest
            closure reached h0 - h_min [mm], accumulated normal hysteresis energy per area
            [N/mm]; written as ``MEMORY_FIELD_NAMES``.
    """

    weight: np.ndarray
    h_min: Optional[np.ndarray] = None
    max_closure: Optional[np.ndarray] = None
    normal_dissipation: Optional[np.ndarray] = None


@dataclass(frozen=True)
class FacetOutput(_InterfaceFields):
    """Interface fields per owned facet of the first surface (DG0, quadrature averages).

    Attributes:
        pressure, area_fraction, gap, dissipation: (n_f,) averages, units as in PointOutput.
        slip, plastic_slip, traction, shear_traction: (n_f, 3) averages in global axes.
        status: (n_f,) int32, the state covering the largest part of the facet.
        contact_fraction: (n_f,) part of the facet's area in contact [-].
        slip_fraction: (n_f,) part of the facet's area slipping [-].
        area: (n_f,) facet area, sum of its quadrature weights [mm^2].
        max_closure, normal_dissipation: (n_f,) averages (normal law with memory only,
            else None).
    """

    contact_fraction: np.ndarray
    slip_fraction: np.ndarray
    area: np.ndarray
    max_closure: Optional[np.ndarray] = None
    normal_dissipation: Optional[np.ndarray] = None


# (attribute, name in the file); the order is the order of the arrays in ParaView's lists
_FIELDS = (
    ("pressure", "pressure_MPa"), ("area_fraction", "area_fraction"), ("gap", "gap_mm"),
    ("slip", "slip_mm"), ("plastic_slip", "plastic_slip_mm"), ("traction", "traction_MPa"),
    ("shear_traction", "shear_traction_MPa"), ("dissipation", "dissipation_N_per_mm"),
    ("status", "status"),
)
FACET_FIELD_NAMES = tuple(n for _, n in _FIELDS) + ("contact_fraction", "slip_fraction")
POINT_FIELD_NAMES = tuple(n for _, n in _FIELDS) + ("weight_mm2",)
# written besides, only when the normal law has memory (h_min at the points only)
_MEMORY = (("max_closure", "max_closure_mm"),
           ("normal_dissipation", "normal_dissipation_N_per_mm"), ("h_min", "h_min_mm"))
MEMORY_FIELD_NAMES = tuple(n for _, n in _MEMORY)


def _check_points(weights: np.ndarray, n_qp: int) -> np.ndarray:
    w = np.asarray(weights, dtype=float)
    check_integer("n_qp", n_qp, lo=1)
    if w.ndim != 1 or w.size % n_qp:
        raise ValueError(f"weights of shape {w.shape} must be (n_facets * n_qp,), n_qp = {n_qp}")
    if np.any(~np.isfinite(w)) or np.any(w < 0.0):
        raise ValueError(f"quadrature weights must be finite and >= 0, min = {w.min(initial=0)}")
    w = w.reshape(-1, n_qp)
    if np.any(w.sum(axis=1) <= 0.0):   # weight-0 points fill the mortar pairing's slots
        raise ValueError("every facet needs a positive total quadrature weight; "
                         f"{int(np.sum(w.sum(axis=1) <= 0.0))} facets have none")
    return w


def facet_average(values: np.ndarray, weights: np.ndarray, n_qp: int) -> np.ndarray:
    """Area-weighted average per facet of facet-major point values (the L2 projection on DG0).

    Args:
        values: (n_f * n_qp, ...) point values; points of facet f are f*n_qp ... f*n_qp+n_qp-1.
        weights: (n_f * n_qp,) quadrature weights [mm^2], >= 0 with a positive sum per facet
            (the mortar pairing fills its slots with weight-0 copies).
        n_qp: points per facet.

    Returns:
        (n_f, ...) sum_q w_q v_q / sum_q w_q.
    """
    w = _check_points(weights, n_qp)
    v = np.asarray(values, dtype=float)
    if v.shape[:1] != (w.size,):
        raise ValueError(f"values of shape {v.shape} do not match {w.size} weights")
    v = v.reshape(w.shape + v.shape[1:])
    area = w.sum(axis=1)
    return np.einsum("fq,fq...->f...", w, v) / area.reshape((-1,) + (1,) * (v.ndim - 2))


def facet_status(contact: np.ndarray, slipping: np.ndarray, weights: np.ndarray,
                 n_qp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Status per facet from the point states (module docstring: the majority of the area).

    Args:
        contact: (n_f * n_qp,) bool, p > 0.
        slipping: (n_f * n_qp,) bool, friction limit active (counts only where in contact).
        weights: (n_f * n_qp,) quadrature weights [mm^2].
        n_qp: points per facet.

    Returns:
        status (n_f,) int32 (0 open, 1 stick, 2 slip), contact_fraction (n_f,),
        slip_fraction (n_f,).
    """
    contact = np.asarray(contact, dtype=bool)
    slip = contact & np.asarray(slipping, dtype=bool)
    stick = contact & ~slip
    parts = facet_average(np.column_stack([~contact, stick, slip]).astype(float), weights, n_qp)
    # ties go to the more active state: bias by less than any real difference of parts
    status = np.argmax(parts + _TIE * np.arange(3), axis=1).astype(np.int32)
    return status, parts[:, 1] + parts[:, 2], parts[:, 2]


def _point_status(contact: np.ndarray, slipping: np.ndarray) -> np.ndarray:
    contact = np.asarray(contact, dtype=bool)
    return np.where(contact, np.where(slipping, STATUS_SLIP, STATUS_STICK),
                    STATUS_OPEN).astype(np.int32)


def point_output(interface: InterfaceOutputSource) -> PointOutput:
    """This rank's interface fields at the points, vectors rotated to global axes."""
    pf = interface.point_fields()
    R = interface.local_frames()  # (n, 3 local, 3 global)
    tangential = R[:, 1:, :]
    shear = np.einsum("pai,pa->pi", tangential, pf.shear)
    normal_traction = -np.asarray(pf.pressure)[:, None] * R[:, 0, :]
    return PointOutput(
        pressure=np.asarray(pf.pressure, dtype=float),
        area_fraction=np.asarray(pf.area_fraction, dtype=float),
        gap=np.asarray(pf.gap, dtype=float),
        slip=np.einsum("pai,pa->pi", tangential, pf.slip),
        plastic_slip=np.einsum("pai,pa->pi", tangential, pf.plastic_slip),
        traction=normal_traction + shear,
        shear_traction=shear,
        dissipation=np.asarray(pf.dissipation, dtype=float),
        status=_point_status(pf.contact, pf.slipping),
        weight=np.asarray(pf.weight, dtype=float),
        **({} if pf.normal_dissipation is None else {
            "h_min": np.where(np.isfinite(pf.h_min), pf.h_min, np.nan).astype(float),
            "max_closure": np.asarray(pf.max_closure, dtype=float),
            "normal_dissipation": np.asarray(pf.normal_dissipation, dtype=float)}),
    )


def facet_output(interface: InterfaceOutputSource,
                 points: Optional[PointOutput] = None) -> FacetOutput:
    """This rank's facet fields (quadrature averages of :func:`point_output`)."""
    po = point_output(interface) if points is None else points
    n_qp, w = interface.n_qp, po.weight
    status, contact_fraction, slip_fraction = facet_status(po.status != STATUS_OPEN,
                                                           po.status == STATUS_SLIP, w, n_qp)
    avg = {attr: facet_average(getattr(po, attr), w, n_qp)
           for attr, _ in _FIELDS if attr != "status"}
    if po.normal_dissipation is not None:
        avg.update({a: facet_average(getattr(po, a), w, n_qp)
                    for a in ("max_closure", "normal_dissipation")})
    return FacetOutput(status=status, contact_fraction=contact_fraction,
                       slip_fraction=slip_fraction, area=w.reshape(-1, n_qp).sum(axis=1), **avg)


# --------------------------------------------------------------------------------------------
# the facet surface
# --------------------------------------------------------------------------------------------
def facet_vertex_coordinates(interface: InterfaceOutputSource) -> np.ndarray:
    """(n_f, nv, 3) vertex coordinates of this rank's facets, in cyclic order (XDMF/VTK
    triangle or quadrilateral), oriented so that the facet normal is the interface normal n
    (from the first body towards the second) [mm]."""
    import basix
    import dolfinx.mesh

    msh = interface.V.mesh
    tdim = msh.topology.dim
    facets = np.asarray(interface.facets, dtype=np.int32)
    cell_type = {dolfinx.mesh.CellType.tetrahedron: basix.CellType.tetrahedron,
                 dolfinx.mesh.CellType.hexahedron: basix.CellType.hexahedron}.get(
                     msh.topology.cell_type)
    if cell_type is None:
        raise ValueError(f"cell type {msh.topology.cell_type} is not supported "
                         "(tetrahedron or hexahedron)")
    ref_facets = np.array(basix.topology(cell_type)[2])  # (n_lf, nv) reference vertex order
    nv = ref_facets.shape[1]
    if facets.size == 0:
        return np.zeros((0, nv, 3))
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    cells = f_to_c.array[f_to_c.offsets[facets]]
    c_to_f = msh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, ref_facets.shape[0])
    local_facet = np.argmax(c_to_f[cells] == facets[:, None], axis=1)
    gdofs = compat.geometry_dofmap(msh)
    # the first geometry nodes of a cell are its vertices, in the reference cell's order
    vx = msh.geometry.x[gdofs[cells[:, None], ref_facets[local_facet]]]
    if nv == 4:  # basix quadrilateral vertices are in tensor order; XDMF wants them cyclic
        vx = vx[:, [0, 1, 3, 2]]
    n_mean = interface.local_frames()[:, 0, :].reshape(facets.size, -1, 3).mean(axis=1)
    if nv == 3:
        geometric = np.cross(vx[:, 1] - vx[:, 0], vx[:, 2] - vx[:, 0])
    else:  # cross product of the diagonals: the quadrilateral's area-weighted normal
        geometric = np.cross(vx[:, 2] - vx[:, 0], vx[:, 3] - vx[:, 1])
    flip = np.einsum("fi,fi->f", geometric, n_mean) < 0.0
    reverse = np.r_[0, np.arange(nv - 1, 0, -1)]
    vx[flip] = vx[flip][:, reverse]
    return vx


@dataclass(frozen=True)
class SurfaceMesh:
    """The gathered facet surface (rank 0).

    Attributes:
        points: (n_v, 3) vertex coordinates [mm], sorted lexicographically.
        cells: (n_c, nv) int64 vertex indices per facet, cyclic, oriented along n.
        cell_type: ``"Triangle"`` or ``"Quadrilateral"`` (XDMF topology type).
        order: (n_c,) position of each written facet in the rank-by-rank concatenation.
    """

    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    order: np.ndarray


def gather_surface(comm: MPI.Comm, vertex_x: np.ndarray, root: int = 0) -> Optional[SurfaceMesh]:
    """Gather every rank's facets (n_f, nv, 3) into one surface on ``root`` (None elsewhere).

    Vertices shared by facets (on any rank) are merged: copies of one geometry node carry
    bit-identical coordinates. Vertices, then facets, are sorted by coordinates, so the result
    does not depend on the partition.
    """
    parts = comm.gather(np.ascontiguousarray(vertex_x, dtype=float), root=root)
    if comm.rank != root:
        return None
    nv = next((p.shape[1] for p in parts if p.size), parts[0].shape[1])
    allx = np.concatenate([p.reshape(-1, nv, 3) for p in parts], axis=0)
    points, inverse = np.unique(allx.reshape(-1, 3), axis=0, return_inverse=True)
    cells = inverse.reshape(-1, nv).astype(np.int64)
    # canonical form: smallest vertex first (a cyclic shift keeps the orientation), facets in
    # lexicographic order of their vertex lists
    shift = np.argmin(cells, axis=1)
    cells = np.take_along_axis(cells, (shift[:, None] + np.arange(nv)) % nv, axis=1)
    order = np.lexsort(cells.T[::-1])
    return SurfaceMesh(points=points, cells=cells[order], order=order,
                       cell_type="Triangle" if nv == 3 else "Quadrilateral")


def _gather_rows(comm: MPI.Comm, arrays: dict, root: int = 0) -> Optional[dict]:
    gathered = comm.gather(arrays, root=root)
    if comm.rank != root:
        return None
    return {k: np.concatenate([g[k] for g in gathered], axis=0) for k in arrays}


# --------------------------------------------------------------------------------------------
# time values
# --------------------------------------------------------------------------------------------
def pseudo_time(load_factors: Sequence[float]) -> np.ndarray:
    """Time values of a load path: the load factor while it increases from 0, then the length
    of the load path sum |d lambda| (strictly increasing, so ParaView plays the unloading after
    the loading instead of merging equal load factors).

    Args:
        load_factors: (n,) load factors of the written increments, in order.

    Returns:
        (n,) time values; equal to the load factors for a monotonic loading from 0.

    Raises:
        ValueError: two consecutive equal load factors (the time would not increase).
    """
    lam = np.asarray(load_factors, dtype=float)
    if lam.ndim != 1 or not np.all(np.isfinite(lam)):
        raise ValueError(f"load factors must be a finite 1D sequence, got {load_factors!r}")
    steps = np.abs(np.diff(np.r_[0.0, lam]))
    if np.any(steps == 0.0):
        i = int(np.argmin(steps))
        raise ValueError(f"load factor {float(lam[i])!r} repeats at written step {i + 1}: the time "
                         "value must increase; pass time= explicitly")
    t = np.cumsum(steps)
    monotone = np.cumprod(np.r_[0.0, lam][1:] > np.r_[0.0, lam][:-1]).astype(bool)
    return np.where(monotone, lam, t)


# --------------------------------------------------------------------------------------------
# the writer
# --------------------------------------------------------------------------------------------
def _data_item(h5name: str, path: str, shape: tuple, dtype: np.dtype) -> str:
    dtype = np.dtype(dtype)
    kind = "Int" if np.issubdtype(dtype, np.integer) else "Float"
    dims = " ".join(str(d) for d in shape)
    return (f'<DataItem Dimensions="{dims}" NumberType="{kind}" Precision="{dtype.itemsize}" '
            f'Format="HDF">{h5name}:{path}</DataItem>')


class InterfaceWriter:
    """Write the interface's facet fields (and optionally its point cloud) per increment.

    Args:
        outdir: output folder (created).
        interface: the interface operator (:class:`InterfaceOutputSource`).
        points: also write ``interface_points.xdmf``, the exact values at the quadrature points.
        overwrite: replace this writer's files from an earlier run; without it, existing
            ``interface.xdmf``/``interface.h5``/``interface_points.xdmf`` raise
            :class:`~rough_contact.io.files.OutputExistsError` (see also
            :func:`~rough_contact.io.files.prepare_output_dir`).

    Collective: construct and call :meth:`write` on every rank.
    """

    def __init__(self, outdir: str, interface: InterfaceOutputSource, *, points: bool = False,
                 overwrite: bool = False, resume: bool = False):
        self.outdir = os.fspath(outdir)
        self.interface = interface
        self.comm = interface.comm
        self.points = bool(points)
        self.facet_path = os.path.join(self.outdir, FACET_XDMF)
        self.point_path = os.path.join(self.outdir, POINT_XDMF)
        self.h5_path = os.path.join(self.outdir, H5_FILE)
        self.load_factors: list = []
        self.times: list = []
        n_qp = interface.n_qp
        surface = gather_surface(self.comm, facet_vertex_coordinates(interface))
        xq = _gather_rows(self.comm, {"x": np.asarray(interface.point_coordinates())})
        self.surface = surface

        def create():
            with writing(self.outdir):
                os.makedirs(self.outdir, exist_ok=True)
            # points: facet by facet in the surface's facet order, by coordinates within a facet
            x = xq["x"].reshape(-1, n_qp, 3)[surface.order]
            fid = np.repeat(np.arange(x.shape[0]), n_qp)
            x = x.reshape(-1, 3)
            within = np.lexsort((x[:, 2], x[:, 1], x[:, 0], fid))
            self._point_order = (surface.order[:, None] * n_qp + np.arange(n_qp)).ravel()[within]
            if resume:                # the resumed run's files: restore() trims them
                return
            mine = run_files(self.outdir, (re.escape(FACET_XDMF), re.escape(H5_FILE),
                                            re.escape(POINT_XDMF)))
            if mine and not overwrite:
                raise OutputExistsError(
                    f"{', '.join(mine)} already in {self.outdir!r} (an earlier run); pass "
                    "overwrite=True or use prepare_output_dir")
            for f in mine:
                os.remove(os.path.join(self.outdir, f))
            self._new_h5()
            self._write_xml()

        self._point_geometry = None if xq is None else xq["x"]   # rank 0 only
        self._point_order = None  # rank 0 only, like every gathered array
        self._specs: dict = {}
        run_on_root(self.comm, create)

    def _new_h5(self) -> None:
        import h5py

        with writing(self.h5_path), h5py.File(self.h5_path, "w") as h5:
            h5["Mesh/geometry"] = self.surface.points
            h5["Mesh/topology"] = self.surface.cells
            if self.points:
                h5["Points/geometry"] = self._point_geometry[self._point_order]

    # ------------------------------------------------------------------ restart
    def checkpoint_state(self) -> dict:
        """What :meth:`restore` needs to continue the files (picklable)."""
        return dict(times=list(self.times), load_factors=list(self.load_factors),
                    specs=dict(self._specs))

    def restore(self, state: dict) -> None:
        """Continue from :meth:`checkpoint_state` (collective): steps written after it are
        deleted from the HDF5 file and the XML indexes rewritten; an unreadable HDF5 file (a
        kill in the middle of its write) is moved aside as ``*.damaged`` and the series
        restarts at the resumed step."""
        def act():
            import h5py

            self.times = list(state["times"])
            self.load_factors = list(state["load_factors"])
            self._specs = dict(state["specs"])
            n = len(self.times)
            if not os.path.exists(self.h5_path):
                warnings.warn(f"no earlier interface output in {self.outdir!r}: its series "
                              "starts at the resumed step", RuntimeWarning, stacklevel=2)
                self.times, self.load_factors = [], []
                self._new_h5()
                self._write_xml()
                return self.times, self.load_factors
            try:
                with h5py.File(self.h5_path, "a") as h5:
                    for group in [g for g in h5 if g.startswith("Step_")]:
                        if int(group[5:]) > n:
                            del h5[group]
                    for k in range(n):
                        h5[f"Step_{k + 1:04d}"].attrs["time"]   # raises if lost
            except (OSError, KeyError) as exc:
                for f in (self.h5_path, self.facet_path, self.point_path):
                    if os.path.exists(f):
                        os.replace(f, f + ".damaged")
                warnings.warn(f"{self.h5_path} could not be continued ({type(exc).__name__}: "
                              f"{exc}); moved aside as *.damaged, the interface series restarts "
                              "at the resumed step", RuntimeWarning, stacklevel=2)
                self.times, self.load_factors = [], []
                self._new_h5()
            self._write_xml()
            return self.times, self.load_factors

        self.times, self.load_factors = run_on_root(self.comm, act)
        self.times, self.load_factors = list(self.times), list(self.load_factors)

    # ------------------------------------------------------------------ XML
    def _grid(self, k: int, mesh_items: list, items: list, center: str) -> list:
        lines = [f'      <Grid Name="step_{k + 1}" GridType="Uniform">',
                 f'        <Time Value="{float(self.times[k])!r}"/>'] + mesh_items
        for name, path, (shape, dtype) in items:
            kind = "Scalar" if len(shape) == 1 else "Vector"
            lines.append(f'        <Attribute Name="{name}" AttributeType="{kind}" '
                         f'Center="{center}">{_data_item(H5_FILE, path, shape, dtype)}'
                         '</Attribute>')
        for name, value in (("load_factor", self.load_factors[k]), ("step", float(k + 1))):
            lines.append(f'        <Attribute Name="{name}" AttributeType="Scalar" Center="Grid">'
                         f'<DataItem Dimensions="1" NumberType="Float" Precision="8" '
                         f'Format="XML">{value!r}</DataItem></Attribute>')
        lines.append("      </Grid>")
        return lines

    def _document(self, name: str, mesh_items: list, steps: list, center: str) -> str:
        lines = ['<?xml version="1.0" ?>', '<Xdmf Version="3.0">', "  <Domain>",
                 f'    <Grid Name="{name}" GridType="Collection" CollectionType="Temporal">']
        for k, items in enumerate(steps):
            lines += self._grid(k, mesh_items, items, center)
        lines += ["    </Grid>", "  </Domain>", "</Xdmf>", ""]
        return "\n".join(lines)

    def _write_xml(self) -> None:
        s = self.surface
        facet_mesh = [
            f'        <Topology TopologyType="{s.cell_type}" NumberOfElements="{len(s.cells)}">'
            f'{_data_item(H5_FILE, "/Mesh/topology", s.cells.shape, s.cells.dtype)}</Topology>',
            f'        <Geometry GeometryType="XYZ">'
            f'{_data_item(H5_FILE, "/Mesh/geometry", s.points.shape, s.points.dtype)}'
            '</Geometry>']
        steps = [self._items(k, "facets", FACET_FIELD_NAMES) for k in range(len(self.times))]
        atomic_write_text(self.facet_path, self._document("interface", facet_mesh, steps, "Cell"))
        if self.points:
            n = len(self._point_order)
            point_mesh = [
                f'        <Topology TopologyType="Polyvertex" NumberOfElements="{n}" '
                'NodesPerElement="1"/>',
                f'        <Geometry GeometryType="XYZ">'
                f'{_data_item(H5_FILE, "/Points/geometry", (n, 3), np.float64)}</Geometry>']
            steps = [self._items(k, "points", POINT_FIELD_NAMES) for k in range(len(self.times))]
            atomic_write_text(self.point_path,
                              self._document("interface_points", point_mesh, steps, "Node"))

    def _items(self, k: int, group: str, names: Sequence[str]) -> list:
        specs = self._specs[group]
        names = list(names) + [n for n in MEMORY_FIELD_NAMES if n in specs]
        return [(n, f"/Step_{k + 1:04d}/{group}/{n}", specs[n]) for n in names]

    # ------------------------------------------------------------------ steps
    def write(self, load_factor: float, time: Optional[float] = None) -> None:
        """Write the interface fields of the last evaluation as one step (collective).

        Args:
            load_factor: load factor of the increment [-], stored with the step.
            time: time value of the step; default :func:`pseudo_time` of the load factors
                (= the load factor while the load increases from 0). Must increase.
        """
        lam = float(load_factor)
        if time is None:
            t = float(pseudo_time(self.load_factors + [lam])[-1])
        else:
            t = float(time)
        if not np.isfinite(t) or (self.times and t <= self.times[-1]):
            raise ValueError(f"time value {t!r} of step {len(self.times) + 1} must be finite and "
                             f"> the previous one ({self.times[-1] if self.times else None!r})")
        po = point_output(self.interface)
        fo = facet_output(self.interface, po)
        facet_arrays = {name: getattr(fo, attr) for attr, name in _FIELDS}
        facet_arrays["contact_fraction"] = fo.contact_fraction
        facet_arrays["slip_fraction"] = fo.slip_fraction
        memory = po.normal_dissipation is not None
        if memory:
            facet_arrays.update({n: getattr(fo, a) for a, n in _MEMORY if a != "h_min"})
        facet_arrays = _gather_rows(self.comm, facet_arrays)
        point_arrays = None
        if self.points:
            point_arrays = {name: getattr(po, attr) for attr, name in _FIELDS}
            point_arrays["weight_mm2"] = po.weight
            if memory:
                point_arrays.update({n: getattr(po, a) for a, n in _MEMORY})
            point_arrays = _gather_rows(self.comm, point_arrays)
        k = len(self.times)

        def act():
            import h5py

            order = self.surface.order
            data = {"facets": {n: a[order] for n, a in facet_arrays.items()}}
            if self.points:
                data["points"] = {n: a[self._point_order] for n, a in point_arrays.items()}
            # shape and type of every field: the same at every step
            self._specs = {g: {n: (a.shape, a.dtype) for n, a in d.items()}
                           for g, d in data.items()}
            group = f"Step_{k + 1:04d}"
            # refused before HDF5 starts: a file that runs out of space half-way cannot be
            # closed cleanly (h5py then fails in its destructors)
            needed = sum(a.nbytes for d in data.values() for a in d.values())
            check_free_space(self.h5_path, int(1.25 * needed) + 64 * 1024,
                             f"step {k + 1} to {self.h5_path}")
            with writing(self.h5_path), h5py.File(self.h5_path, "a") as h5:
                if group in h5:  # left by a failed earlier attempt at this step: not listed
                    del h5[group]
                for g, d in data.items():
                    for n, a in d.items():
                        h5[f"{group}/{g}/{n}"] = a
                h5[group].attrs["load_factor"] = lam
                h5[group].attrs["time"] = t
            self.times.append(t)
            self.load_factors.append(lam)
            try:
                self._write_xml()
            except Exception:
                self.times.pop()
                self.load_factors.pop()
                raise

        run_on_root(self.comm, act)
        if self.comm.rank != 0:
            self.times.append(t)
            self.load_factors.append(lam)


# --------------------------------------------------------------------------------------------
# reading back (no dolfinx needed: xml + h5py)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class InterfaceResults:
    """An interface XDMF file read back (``interface.xdmf`` or ``interface_points.xdmf``).

    Attributes:
        points: (n_v, 3) vertex (or quadrature point) coordinates [mm].
        cells: (n_c, nv) facet vertex indices, or None for the point cloud.
        cell_type: XDMF topology type (``"Triangle"``, ``"Quadrilateral"``, ``"Polyvertex"``).
        times: (n_steps,) time values.
        load_factors: (n_steps,) load factors.
        field_names: names of the fields of every step.
        h5_path: the HDF5 file holding the data.
        datasets: per step, {field name: dataset path in ``h5_path``}.
    """

    points: np.ndarray
    cells: Optional[np.ndarray]
    cell_type: str
    times: np.ndarray
    load_factors: np.ndarray
    field_names: tuple
    h5_path: str
    datasets: tuple

    def field(self, name: str, step: int = -1) -> np.ndarray:
        """Values of field ``name`` at ``step`` (0-based; negative counts from the end)."""
        import h5py

        n = len(self.datasets)
        if not -n <= step < n:
            raise ValueError(f"step = {step} is out of range for {n} written steps")
        if name not in self.datasets[step]:
            raise ValueError(f"field {name!r} not in the file; fields: {sorted(self.field_names)}")
        with h5py.File(self.h5_path, "r") as h5:
            return h5[self.datasets[step][name]][...]


def _split_item(item: ET.Element, folder: str) -> tuple[str, str]:
    if item.get("Format") != "HDF" or ":" not in item.text:
        raise ValueError(f"data item {item.text.strip()!r} (format {item.get('Format')!r}) is "
                         "not HDF5 data of InterfaceWriter: the file was written by another "
                         "writer (e.g. the binary point cloud of ResultWriter)")
    file_name, path = item.text.strip().split(":", 1)
    return os.path.join(folder, file_name), path


def read_interface_results(path: str) -> InterfaceResults:
    """Read an interface XDMF file written by :class:`InterfaceWriter` (any rank, no MPI).

    Args:
        path: ``.../interface.xdmf`` or ``.../interface_points.xdmf``.
    """
    import h5py

    folder = os.path.dirname(os.path.abspath(path))
    root = parse_xdmf(path)
    grids = root.findall("./Domain/Grid/Grid")
    if not grids:
        raise ValueError(f"{path!r} holds no written step")
    topo = grids[0].find("Topology")
    cell_type = topo.get("TopologyType")
    h5_path, geo_path = _split_item(grids[0].find("Geometry/DataItem"), folder)
    with h5py.File(h5_path, "r") as h5:
        points = h5[geo_path][...]
        cells = None
        if topo.find("DataItem") is not None:
            cells = h5[_split_item(topo.find("DataItem"), folder)[1]][...]
    times, load_factors, datasets = [], [], []
    for grid in grids:
        times.append(float(grid.find("Time").get("Value")))
        fields = {}
        for att in grid.findall("Attribute"):
            item = att.find("DataItem")
            if att.get("Center") == "Grid":
                if att.get("Name") == "load_factor":
                    load_factors.append(float(item.text))
                continue
            fields[att.get("Name")] = _split_item(item, folder)[1]
        datasets.append(fields)
    return InterfaceResults(points=points, cells=cells, cell_type=cell_type,
                            times=np.array(times), load_factors=np.array(load_factors),
                            field_names=tuple(datasets[0]), h5_path=h5_path,
                            datasets=tuple(datasets))
