"""Facet geometry shared by the pairings: facet quadrature rules, the geometry and closure DOFs
of a set of exterior facets, an all-gathered copy of a contact surface.

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import basix
import numpy as np
from mpi4py import MPI

import dolfinx
from rough_contact.fem import compat
from rough_contact.fem.pairing.geometry import SecondSurface

__all__ = ["FacetGeometry", "FacetRule", "GatheredSurface", "owned_tagged_facets",
           "facet_connectivity", "facet_set", "basix_cell", "facet_cell", "cmap_element",
           "CELLS"]

CELLS = {
    dolfinx.mesh.CellType.tetrahedron: (basix.CellType.tetrahedron, basix.CellType.triangle),
    dolfinx.mesh.CellType.hexahedron: (basix.CellType.hexahedron, basix.CellType.quadrilateral),
}


def basix_cell(msh) -> basix.CellType:
    """The basix cell type of the mesh's cells."""
    return CELLS[msh.topology.cell_type][0]


def facet_cell(msh) -> basix.CellType:
    """The basix cell type of the mesh's facets (triangle or quadrilateral)."""
    return CELLS[msh.topology.cell_type][1]


def cmap_element(msh):
    """The basix Lagrange element of the geometry (for degree <= 2 all Lagrange variants have
    the same nodes, so the equispaced one stands for dolfinx's coordinate element)."""
    return basix.create_element(basix.ElementFamily.P, basix_cell(msh),
                                compat.geometry_degree(msh), basix.LagrangeVariant.equispaced)


def owned_tagged_facets(facet_tags, tag: int, n_owned: int, comm) -> np.ndarray:
    """Sorted local indices of the owned facets marked ``tag`` (collective).

    Raises:
        ValueError (on every rank): no facet of any rank carries ``tag`` (names the tags there).
    """
    facets = np.asarray(facet_tags.indices[facet_tags.values == tag], dtype=np.int32)
    facets = np.unique(facets[facets < n_owned])
    if comm.allreduce(facets.size, op=MPI.SUM) == 0:
        gathered = comm.allgather(np.unique(facet_tags.values))
        present = sorted({int(v) for arr in gathered for v in arr})
        raise ValueError(f"contact facet tag {tag} marks no facet; tags present: {present}")
    return facets


def facet_connectivity(msh) -> int:
    """Create facet-cell connectivities; return the number of owned facets."""
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    return msh.topology.index_map(tdim - 1).size_local


class FacetGeometry:
    """Geometry and basis data of a set of exterior facets, vectorised over facets.

    Attributes:
        facets: (n_f,) local facet indices; cells: (n_f,) their cells; local_facet: (n_f,)
            local facet index in the cell.
        cell_nodes_x: (n_f, n_gdof, 3) geometry nodes of the cells [mm].
        vertex_x: (n_f, nv, 3) facet vertices in the reference facet's vertex order [mm].
        closure: (n_lf, n_close) closure DOFs of every local facet of the element.
        local_nodes, global_nodes: (n_f, n_close) local / global block indices of the facets'
            closure DOFs.
    """

    def __init__(self, V, facets: np.ndarray):
        msh = V.mesh
        tdim = msh.topology.dim
        self.facets = facets
        f_to_c = msh.topology.connectivity(tdim - 1, tdim)
        counts = f_to_c.offsets[facets + 1] - f_to_c.offsets[facets]
        if np.any(counts != 1):
            raise ValueError(
                f"{int(np.sum(counts != 1))} contact facets are interior facets (shared by two "
                "cells); a contact surface must be an exterior facet of one body"
            )
        self.cells = f_to_c.array[f_to_c.offsets[facets]]
        cell = basix_cell(msh)
        n_lf = len(basix.topology(cell)[2])
        c_to_f = msh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, n_lf)
        self.local_facet = np.argmax(c_to_f[self.cells] == facets[:, None], axis=1)

        x = msh.geometry.x
        gdofs = compat.geometry_dofmap(msh)
        self.cell_nodes_x = x[gdofs[self.cells]]  # (n_f, n_gdof, 3)
        # facet vertices in the reference facet's vertex order (geometry dofs 0..3 = vertices)
        ref_facet_vertices = np.array(basix.topology(cell)[2])
        self.vertex_x = x[gdofs[self.cells[:, None], ref_facet_vertices[self.local_facet]]]

        element = V.element.basix_element
        self.closure = np.array(element.entity_closure_dofs[2])  # (4, n_close)
        dofs = compat.cell_dofmap(V)
        local_nodes = np.take_along_axis(
            dofs[self.cells], self.closure[self.local_facet], axis=1
        )
        self.local_nodes = local_nodes                 # (n_f, n_close) local block indices
        self.global_nodes = V.dofmap.index_map.local_to_global(
            local_nodes.ravel().astype(np.int32)
        ).reshape(local_nodes.shape).astype(np.int64)


def facet_set(msh, cell_x: np.ndarray, local_facet: np.ndarray,
              vertex_x: np.ndarray) -> SecondSurface:
    """Facets as a :class:`rough_contact.fem.pairing.geometry.SecondSurface` (geometry for the
    Newton projection)."""
    cell = basix_cell(msh)
    ref_facets = np.array(basix.topology(cell)[2])
    ref_x = np.asarray(basix.geometry(cell), dtype=float)
    fv = ref_x[ref_facets[np.asarray(local_facet, dtype=np.int64)]]  # (n, nv, 3)
    return SecondSurface(
        cell_x=cell_x, v0=fv[:, 0], tangents=np.stack([fv[:, 1] - fv[:, 0],
                                                       fv[:, 2] - fv[:, 0]], axis=2),
        ref_normal=basix.cell.facet_outward_normals(cell)[np.asarray(local_facet, np.int64)],
        triangle=ref_facets.shape[1] == 3, centroid=vertex_x.mean(axis=1))


@dataclass(frozen=True)
class GatheredSurface:
    """A contact surface, all-gathered on every rank (for non-matching pairing).

    Attributes:
        surface: its facet geometry (:class:`rough_contact.fem.pairing.geometry.SecondSurface`).
        owner: (n2,) owning rank of each facet.
        local_facet: (n2,) local facet index in its cell.
        nodes: (n2, n_close) global block indices of each facet's closure DOFs.
        vertex_x: (n2, nv, 3) vertex coordinates.
        closure: (n_lf, n_close) closure DOFs of every local facet of the element.
        own_local_nodes: (n_own, n_close) local block indices of the closure DOFs of this
            rank's facets (they come first-to-last in rank order in the gathered arrays).
    """

    surface: SecondSurface
    owner: np.ndarray
    local_facet: np.ndarray
    nodes: np.ndarray
    vertex_x: np.ndarray
    closure: np.ndarray
    own_local_nodes: np.ndarray

    @classmethod
    def create(cls, V, facet_tags, tag: int, n_owned_facets: int) -> GatheredSurface:
        comm = V.mesh.comm
        geo = FacetGeometry(V, owned_tagged_facets(facet_tags, tag, n_owned_facets, comm))
        n_close = geo.closure.shape[1]
        gathered = comm.allgather((geo.cell_nodes_x, geo.local_facet, geo.global_nodes,
                                   geo.vertex_x))
        owner = np.concatenate(
            [np.full(g[1].size, r, dtype=np.int64) for r, g in enumerate(gathered)])
        lf = np.concatenate([g[1] for g in gathered]).astype(np.int64)
        vx = np.concatenate([g[3] for g in gathered])
        return cls(surface=facet_set(V.mesh, np.concatenate([g[0] for g in gathered]), lf, vx),
                   owner=owner, local_facet=lf,
                   nodes=np.concatenate([g[2] for g in gathered]).reshape(-1, n_close),
                   vertex_x=vx, closure=geo.closure,
                   own_local_nodes=np.asarray(geo.local_nodes, dtype=np.int64))


@dataclass(frozen=True)
class FacetRule:
    """Facet quadrature on every local facet of the reference cell.

    Attributes:
        nq: points per facet.
        weights: (nq,) reference facet weights.
        lam: (nq, nv) vertex weights of the points: barycentric (triangle) or bilinear
            (quadrilateral). A point of the shared surface has the same weights on both sides
            (up to the vertex permutation), so they carry the partner's reference coordinates.
        vertices: (n_lf, nv, 3) reference coordinates of each local facet's vertices.
        points: (n_lf, nq, 3) the points in reference cell coordinates, per local facet.
        tangents: (n_lf, 3, 2) reference tangents of each local facet.
        normals: (n_lf, 3) reference outward normals.
    """

    nq: int
    weights: np.ndarray
    lam: np.ndarray
    vertices: np.ndarray
    points: np.ndarray
    tangents: np.ndarray
    normals: np.ndarray

    @classmethod
    def create(cls, msh, degree: int, vertex: bool = False) -> FacetRule:
        """Gauss rule of ``degree`` on the reference facet, or (``vertex``) its vertices with
        equal weights (exact for linear functions on triangles, bilinear ones on
        quadrilaterals: the P1/Q1 facet fields)."""
        cell = basix_cell(msh)
        fcell = facet_cell(msh)
        ref_facets = np.array(basix.topology(cell)[2])  # (n_lf, nv)
        if vertex:
            xi = np.asarray(basix.geometry(fcell), dtype=float)
            area = 0.5 if fcell == basix.CellType.triangle else 1.0
            w_ref = np.full(len(xi), area / len(xi))
        else:
            xi, w_ref = basix.make_quadrature(fcell, degree)
        lam = _vertex_weights(fcell, xi)  # (nq, nv)
        fv_ref = basix.geometry(cell)[ref_facets]  # (n_lf, nv, 3)
        X_lf = np.einsum("qi,fid->fqd", lam, fv_ref)  # (n_lf, nq, 3) points per local facet
        T_lf = np.stack([fv_ref[:, 1] - fv_ref[:, 0], fv_ref[:, 2] - fv_ref[:, 0]], axis=2)
        N_lf = basix.cell.facet_outward_normals(cell)  # (n_lf, 3)
        return cls(w_ref.size, w_ref, lam, fv_ref, X_lf, T_lf, N_lf)


def _vertex_weights(fcell, xi: np.ndarray) -> np.ndarray:
    """(nq, nv) P1/Q1 vertex shape functions of the reference facet at points xi (nq, 2)."""
    a, b = xi[:, 0], xi[:, 1]
    if fcell == basix.CellType.triangle:
        return np.column_stack([1.0 - a - b, a, b])
    return np.column_stack([(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b])
