"""Contact interface operator: facet pairing, facet quadrature, jump kinematics, assembly.

DOLFINx 0.5.2 has no external operators and cannot evaluate quadrature coefficients on facets,
so the interface terms are assembled by hand (see ``/work/shared/DESIGN.md``):

* set-up (once): for every owned facet of the FIRST contact surface, its facet quadrature
  points mapped into the reference cell, the area weights and normals from the geometry map,
  the basis values of the facet-closure DOFs and their GLOBAL indices. The partner facet on
  the SECOND surface is found in a small all-gathered copy of that surface (vertex
  coordinates, KD-tree); the partner's reference coordinates reuse the barycentric
  coordinates of the point on the shared facet, which is exact for P1 and P2 geometry.
  The jump operator is stored per point: jump = B u_pair + jump0, B of shape
  (n_pts, 3, n_pair_dofs), in local axes (n, x, y).
* every evaluation: one PETSc VecScatter fetches the displacement DOFs the owned facets touch
  (wherever they are owned), the jump at all points is one batched matmul, the law is called ONCE,
  and the element vectors B^T t w and matrices B^T D B w are added with global indices.

Conventions (contract of ``rough_contact.interface.law``): n is the unit normal of the first
surface pointing towards the second body, x is the grain direction projected on the facet,
y = n x x. jump = [g, s_x, s_y] are the local components of u_second - u_first (g > 0 opens).
The law returns t = dpsi/djump; the residual contribution is R = int B^T t dA and the tangent
int B^T (dt/djump) B dA. The force the interface exerts on the first body is int R_loc^T t dA.

Rigid obstacle (``second_tag=None``): u_second = 0. With ``rigid_plane=(point, normal)``
(``normal`` = unit normal of the plane pointing towards the first body) the local normal is
-normal everywhere and the initial gap is the distance of each point from the plane;
without a plane, the plane is taken tangent to the first surface at every point (n = facet
normal, zero initial gap).

Units: mm, N, MPa. Positions and jumps [mm], tractions [MPa], forces [N], areas [mm^2].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import basix
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc
from scipy.spatial import cKDTree

import dolfinx
import dolfinx.cpp
import dolfinx.fem

__all__ = ["ContactInterface", "PointFields", "SlipStats"]


@dataclass(frozen=True)
class SlipStats:
    """Global (all-rank) counts and extremes at the interface quadrature points.

    Attributes:
        n_points: number of interface quadrature points.
        n_contact: points with p > 0.
        n_slipping: points where the friction limit is active.
        contact_area: nominal area of the points in contact [mm^2].
        slipping_area: nominal area of the slipping points [mm^2].
        max_slip: largest |(s_x, s_y)| [mm].
        max_plastic_slip: largest |plastic slip| [mm] (0 if the law stores none).
    """

    n_points: int
    n_contact: int
    n_slipping: int
    contact_area: float
    slipping_area: float
    max_slip: float
    max_plastic_slip: float


@dataclass(frozen=True)
class PointFields:
    """Local (this rank's) fields at the interface quadrature points, for output.

    Attributes:
        pressure: (n,) p = -t_N [MPa].
        shear: (n, 2) (t_x, t_y) [MPa].
        area_fraction: (n,) A/A0 [-].
        gap: (n,) normal jump g [mm].
        slip: (n, 2) tangential jump (s_x, s_y) [mm].
        plastic_slip: (n, 2) [mm] (zeros if the law's state has no ``plastic_slip``).
        dissipation: (n,) committed accumulated dissipation per area [N/mm].
        contact: (n,) bool.
        slipping: (n,) bool.
        weight: (n,) quadrature weight = area represented by the point [mm^2].
    """

    pressure: np.ndarray
    shear: np.ndarray
    area_fraction: np.ndarray
    gap: np.ndarray
    slip: np.ndarray
    plastic_slip: np.ndarray
    dissipation: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    weight: np.ndarray


def _owned_tagged_facets(facet_tags, tag: int, n_owned: int, comm) -> np.ndarray:
    facets = np.asarray(facet_tags.indices[facet_tags.values == tag], dtype=np.int32)
    facets = np.unique(facets[facets < n_owned])
    if comm.allreduce(facets.size, op=MPI.SUM) == 0:
        gathered = comm.allgather(np.unique(facet_tags.values))
        present = sorted({int(v) for arr in gathered for v in arr})
        raise ValueError(f"contact facet tag {tag} marks no facet; tags present: {present}")
    return facets


class _FacetGeometry:
    """Geometry and basis data of a set of exterior facets, vectorised over facets."""

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
        cell = _basix_cell(msh)
        n_lf = len(basix.topology(cell)[2])
        c_to_f = msh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, n_lf)
        self.local_facet = np.argmax(c_to_f[self.cells] == facets[:, None], axis=1)

        x = msh.geometry.x
        n_gdof = _cmap_element(msh).dim
        gdofs = msh.geometry.dofmap.array.reshape(-1, n_gdof)
        self.cell_nodes_x = x[gdofs[self.cells]]  # (n_f, n_gdof, 3)
        # facet vertices in the reference facet's vertex order (geometry dofs 0..3 = vertices)
        ref_facet_vertices = np.array(basix.topology(cell)[2])
        self.vertex_x = x[gdofs[self.cells[:, None], ref_facet_vertices[self.local_facet]]]

        element = V.element.basix_element
        self.closure = np.array(element.entity_closure_dofs[2])  # (4, n_close)
        dofs = V.dofmap.list.array.reshape(-1, element.dim)
        local_nodes = np.take_along_axis(
            dofs[self.cells], self.closure[self.local_facet], axis=1
        )
        self.global_nodes = V.dofmap.index_map.local_to_global(
            local_nodes.ravel().astype(np.int32)
        ).reshape(local_nodes.shape).astype(np.int64)


class ContactInterface:
    """Interface operator between two tagged surfaces (or one surface and a rigid plane).

    Args:
        V: vector Lagrange space of degree 1 or 2 (P1/P2 tetrahedra, Q1/Q2 hexahedra) on the
            mesh holding both bodies.
        facet_tags: MeshTags on facets.
        first_tag: tag of the first contact surface (its normal defines the local axes).
        second_tag: tag of the conforming second surface, or None for a rigid obstacle.
        law: interface law with ``initial_state(n)`` and ``evaluate(jump, committed)``.
        rigid_plane: for ``second_tag=None``: (point (3,), unit normal (3,) pointing towards the
            first body) [mm], or an object with ``point`` and ``normal`` attributes; None = a
            plane tangent to the first surface at every point.
        grain_direction: (3,) global direction projected on the facet to give the local x axis.
        quadrature_degree: degree of the facet quadrature rule.
        bcs: Dirichlet conditions whose DOFs the interface must not touch (also
            ``set_dirichlet_dofs``).
        match_tolerance: vertex matching tolerance relative to the facet size [-].

    Raises:
        ValueError: unknown/empty tags, unsupported spaces, surfaces that do not match.
    """

    def __init__(
        self,
        V,
        facet_tags,
        first_tag: int,
        second_tag: int | None = None,
        *,
        law: Any,
        rigid_plane: Any = None,
        grain_direction: Sequence[float] = (1.0, 0.0, 0.0),
        quadrature_degree: int = 2,
        bcs: Sequence[Any] = (),
        match_tolerance: float = 1e-6,
    ):
        msh = V.mesh
        comm = msh.comm
        self.comm = comm
        self.V = V
        self.law = law
        tdim = msh.topology.dim
        if tdim != 3 or msh.topology.cell_type not in _CELLS:
            raise ValueError(
                "ContactInterface needs a tetrahedral or hexahedral 3D mesh, got "
                f"{msh.topology.cell_type}"
            )
        bs = V.dofmap.index_map_bs
        element = V.element.basix_element
        if bs != 3 or element.degree not in (1, 2) or element.family != basix.ElementFamily.P:
            raise ValueError(
                f"V must be a vector Lagrange space of degree 1 or 2 with 3 components, got "
                f"block size {bs}, degree {element.degree}"
            )
        if V.element.needs_dof_transformations:
            raise ValueError("V needs DOF transformations on facets (degree >= 3): not supported")
        if msh.geometry.cmap.degree not in (1, 2):
            raise ValueError(f"geometry degree {msh.geometry.cmap.degree} not supported (1 or 2)")
        if second_tag is not None and second_tag == first_tag:
            raise ValueError(f"first_tag and second_tag are both {first_tag}")
        if second_tag is not None and rigid_plane is not None:
            raise ValueError("give either second_tag or rigid_plane, not both")
        if int(quadrature_degree) < 0:
            raise ValueError(f"quadrature_degree = {quadrature_degree} must be >= 0")
        grain = np.asarray(grain_direction, dtype=float)
        if grain.shape != (3,) or not np.all(np.isfinite(grain)) or np.linalg.norm(grain) == 0:
            raise ValueError(f"grain_direction = {grain_direction!r} must be a nonzero 3-vector")
        self.first_tag, self.second_tag = first_tag, second_tag

        msh.topology.create_connectivity(tdim - 1, tdim)
        msh.topology.create_connectivity(tdim, tdim - 1)
        n_owned_facets = msh.topology.index_map(tdim - 1).size_local

        # ---- first surface: quadrature, geometry, basis -----------------------------------
        facets1 = _owned_tagged_facets(facet_tags, first_tag, n_owned_facets, comm)
        self._facets1 = facets1
        geo1 = _FacetGeometry(V, facets1)
        n_f = facets1.size
        cell = _basix_cell(msh)
        facet_cell = _CELLS[msh.topology.cell_type][1]
        ref_x = basix.geometry(cell)
        ref_facets = np.array(basix.topology(cell)[2])  # (n_lf, nv)
        xi, w_ref = basix.make_quadrature(facet_cell, int(quadrature_degree))
        nq = w_ref.size
        self.n_facets, self.n_qp = n_f, nq
        # vertex weights of the facet points: barycentric (triangle) or bilinear (quadrilateral).
        # A point of the shared surface has the same weights on both sides (up to the vertex
        # permutation), so they carry the partner's reference coordinates exactly.
        lam = _vertex_weights(facet_cell, xi)  # (nq, nv)
        nv = lam.shape[1]
        n_lf = ref_facets.shape[0]
        fv_ref = ref_x[ref_facets]  # (n_lf, nv, 3)
        X_lf = np.einsum("qi,fid->fqd", lam, fv_ref)  # (n_lf, nq, 3) points per local facet
        T_lf = np.stack([fv_ref[:, 1] - fv_ref[:, 0], fv_ref[:, 2] - fv_ref[:, 0]], axis=2)
        N_lf = basix.cell.facet_outward_normals(cell)  # (n_lf, 3)

        cmap_el = _cmap_element(msh)
        tab_g = cmap_el.tabulate(1, X_lf.reshape(-1, 3)).reshape(4, n_lf, nq, cmap_el.dim)
        lf1 = geo1.local_facet
        phi_g = tab_g[0][lf1]  # (n_f, nq, n_gdof)
        dphi_g = np.moveaxis(tab_g[1:], 0, -1)[lf1]  # (n_f, nq, n_gdof, 3)
        xq = np.einsum("fqk,fki->fqi", phi_g, geo1.cell_nodes_x)
        J = np.einsum("fki,fqkd->fqid", geo1.cell_nodes_x, dphi_g)  # (n_f, nq, 3, 3)
        t12 = np.einsum("fqid,fde->fqie", J, T_lf[lf1])  # (n_f, nq, 3, 2)
        nvec = np.cross(t12[..., 0], t12[..., 1])
        dA = np.linalg.norm(nvec, axis=-1)
        # physical outward direction J^-T N_ref fixes the sign of t1 x t2
        n_ref = np.broadcast_to(N_lf[lf1][:, None, :, None], J.shape[:-1] + (1,))
        outward = np.linalg.solve(np.swapaxes(J, -1, -2), n_ref)[..., 0]
        sign = np.sign(np.einsum("fqi,fqi->fq", nvec, outward))
        normal = sign[..., None] * nvec / dA[..., None]
        self._weights = (w_ref[None, :] * dA).reshape(-1)
        self._x = xq.reshape(-1, 3)

        # local axes (n, x, y)
        jump0 = np.zeros((n_f, nq, 3))
        if second_tag is None and rigid_plane is not None:
            point, pnormal = _plane(rigid_plane)
            normal = np.broadcast_to(-pnormal, normal.shape).copy()
            jump0[..., 0] = (xq - point) @ pnormal
        gx = grain - np.einsum("fqi,i->fq", normal, grain)[..., None] * normal
        gnorm = np.linalg.norm(gx, axis=-1)
        bad = gnorm < 1e-6 * np.linalg.norm(grain)
        n_bad = comm.allreduce(int(bad.sum()), op=MPI.SUM)
        if n_bad:
            raise ValueError(
                f"grain_direction {grain.tolist()} is (nearly) normal to the contact surface at "
                f"{n_bad} points; choose a direction lying in the surface"
            )
        ex = gx / gnorm[..., None]
        ey = np.cross(normal, ex)
        Rloc = np.stack([normal, ex, ey], axis=-2)  # (n_f, nq, 3 local, 3 global)
        self._R = Rloc.reshape(-1, 3, 3)
        self._jump0 = jump0.reshape(-1, 3)

        phi_u = element.tabulate(0, X_lf.reshape(-1, 3))[0].reshape(n_lf, nq, element.dim)
        N1 = np.take_along_axis(phi_u[lf1], geo1.closure[lf1][:, None, :], axis=2)  # (n_f,nq,nc)
        n_close = N1.shape[-1]
        B1 = -np.einsum("fqac,fqk->fqakc", Rloc, N1).reshape(n_f, nq, 3, 3 * n_close)
        nodes = geo1.global_nodes  # (n_f, n_close)

        # ---- second surface: all-gathered facet data, matching, partner basis -------------
        if second_tag is not None:
            facets2 = _owned_tagged_facets(facet_tags, second_tag, n_owned_facets, comm)
            geo2 = _FacetGeometry(V, facets2)
            gathered = comm.allgather((geo2.vertex_x, geo2.local_facet, geo2.global_nodes))
            owner2 = np.concatenate(
                [np.full(g[1].size, r, dtype=np.int64) for r, g in enumerate(gathered)]
            )
            vx2 = np.concatenate([g[0] for g in gathered]).reshape(-1, nv, 3)
            lf2_all = np.concatenate([g[1] for g in gathered]).astype(np.int64)
            nodes2_all = np.concatenate([g[2] for g in gathered]).reshape(-1, n_close)
            vx1 = geo1.vertex_x  # (n_f, nv, 3)
            size = np.linalg.norm(vx1[:, 1] - vx1[:, 0], axis=1) if n_f else np.zeros(0)
            tol = match_tolerance * size
            partner = np.zeros(n_f, dtype=np.int64)
            ok = np.zeros(n_f, dtype=bool)
            perm = np.zeros((n_f, nv), dtype=np.int64)
            if n_f and vx2.shape[0]:
                tree = cKDTree(vx2.mean(axis=1))
                _, partner = tree.query(vx1.mean(axis=1), k=1)
                d = np.linalg.norm(vx1[:, :, None, :] - vx2[partner][:, None, :, :], axis=-1)
                perm = np.argmin(d, axis=2)  # first vertex i <-> partner vertex perm[i]
                ok = (np.max(np.min(d, axis=2), axis=1) <= tol) & (
                    np.sort(perm, axis=1) == np.arange(nv)
                ).all(axis=1)
            n_bad = comm.allreduce(int(np.sum(~ok)), op=MPI.SUM)
            if n_bad:
                example = comm.allgather(vx1[~ok].mean(axis=1)[0].tolist() if np.any(~ok) else None)
                example = next(e for e in example if e is not None)
                n_total = comm.allreduce(n_f, op=MPI.SUM)
                raise ValueError(
                    f"{n_bad} of {n_total} facets of contact surface {first_tag} have no matching "
                    f"facet on surface {second_tag} (vertex tolerance {match_tolerance} x facet "
                    f"size), e.g. the facet with centroid {example}; the interface must be "
                    "conforming (same surface mesh on both sides)"
                )
            lf2 = lf2_all[partner]
            self.n_remote_partners = int(np.sum(owner2[partner] != comm.rank))
            # barycentric reuse: the point with weights lam on the first facet's vertices
            X2 = np.einsum(
                "qi,fid->fqd", lam, fv_ref[lf2][np.arange(n_f)[:, None], perm]
            )  # (n_f, nq, 3)
            phi2 = (
                element.tabulate(0, X2.reshape(-1, 3))[0].reshape(n_f, nq, element.dim)
                if n_f
                else np.zeros((0, nq, element.dim))
            )
            closure2 = geo1.closure[lf2]  # same element on both sides
            N2 = np.take_along_axis(phi2, closure2[:, None, :], axis=2)
            B2 = np.einsum("fqac,fqk->fqakc", Rloc, N2).reshape(n_f, nq, 3, 3 * n_close)
            B = np.concatenate([B1, B2], axis=3)
            nodes = np.concatenate([nodes, nodes2_all[partner]], axis=1)
        else:
            B = B1
            self.n_remote_partners = 0
        # pair DOFs in ascending global order (PETSc's row insertion is faster with sorted
        # columns); B's columns follow
        pair_dofs = (3 * nodes[:, :, None] + np.arange(3)).reshape(n_f, 3 * nodes.shape[1])
        order = np.argsort(pair_dofs, axis=1)
        pair_dofs = np.take_along_axis(pair_dofs, order, axis=1)
        B = np.take_along_axis(B, order[:, None, None, :], axis=3)
        self._n_pair_dofs = B.shape[3]
        self._B = B.reshape(n_f * nq, 3, self._n_pair_dofs)
        self._Bf = B.reshape(n_f, nq * 3, self._n_pair_dofs)  # per-facet view for matmul
        self._BfT = np.ascontiguousarray(np.swapaxes(self._Bf, 1, 2))
        self._pair_nodes = nodes  # (n_f, n_nodes_pair) global block indices
        self._pair_dofs = pair_dofs  # (n_f, nd) global scalar DOFs
        self.n_points = n_f * nq
        self.n_points_global = comm.allreduce(self.n_points, op=MPI.SUM)

        # ---- communication: one scatter for every DOF the owned facets touch -------------
        self._uniq, inv = np.unique(self._pair_dofs, return_inverse=True)
        self._inv = inv.reshape(self._pair_dofs.shape)
        template = dolfinx.cpp.la.petsc.create_vector(V.dofmap.index_map, 3)
        self._template = template
        self._loc = PETSc.Vec().createSeq(self._uniq.size, comm=MPI.COMM_SELF)
        is_from = PETSc.IS().createGeneral(self._uniq.astype(PETSc.IntType), comm=MPI.COMM_SELF)
        self._scatter = PETSc.Scatter().create(template, is_from, self._loc, None)
        self._rows = self._pair_dofs.astype(PETSc.IntType)
        self.set_dirichlet_dofs(None, bcs)

        # ---- history --------------------------------------------------------------------
        self.committed = law.initial_state(self.n_points)
        self.trial = self.committed.copy()
        self._diss_committed = np.zeros(self.n_points)
        self._last_u = self._last = self._last_jump = None
        self._cache_valid = self._committed_last = False

    # ------------------------------------------------------------------ set-up helpers
    def set_dirichlet_dofs(self, global_dofs: np.ndarray | None = None, bcs: Sequence[Any] = ()):
        """Mark DOFs the interface must not assemble into (collective).

        Args:
            global_dofs: global scalar DOF indices owned by this rank (each rank passes its own).
            bcs: dolfinx DirichletBC objects of V (their owned DOFs are added).
        """
        marker = self._template.duplicate()
        marker.set(0.0)
        r0 = marker.getOwnershipRange()[0]
        arr = marker.getArray()
        n_own = arr.size
        for bc in bcs:
            dofs, n_owned_bc = bc.dof_indices()
            dofs = np.asarray(dofs)[:n_owned_bc]
            arr[dofs[dofs < n_own]] = 1.0
        if global_dofs is not None:
            g = np.asarray(global_dofs, dtype=np.int64) - r0
            if np.any((g < 0) | (g >= n_own)):
                raise ValueError(
                    "set_dirichlet_dofs: global_dofs must be owned by the calling rank, got "
                    f"{int(np.sum((g < 0) | (g >= n_own)))} DOFs outside [{r0}, {r0 + n_own})"
                )
            arr[g] = 1.0
        marker.setArray(arr)
        self._scatter.scatter(marker, self._loc, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        fixed = self._loc.getArray()[self._inv] != 0.0
        self._rows = np.where(fixed, -1, self._pair_dofs).astype(PETSc.IntType)
        marker.destroy()

    def sparsity_blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """Global node-level (block size 3) (rows, cols) of every pair's dense block.

        Returns:
            rows, cols: int64 arrays (n_facets, m, m) of global block indices, m = nodes per pair.
        """
        m = self._pair_nodes.shape[1]
        rows = np.broadcast_to(self._pair_nodes[:, :, None], (self.n_facets, m, m))
        cols = np.broadcast_to(self._pair_nodes[:, None, :], (self.n_facets, m, m))
        return rows, cols

    def create_matrix(self, a) -> PETSc.Mat:
        """A PETSc AIJ matrix with the pattern of the bilinear form ``a`` plus the interface.

        The interface couples DOFs that share no cell (often no rank), so the pattern is
        merged here in global indices; the matrix has dolfinx's layout and local-to-global
        map, so ``dolfinx.fem.petsc.assemble_matrix(A, a, bcs)`` works on it.
        """
        comm = self.comm
        imap = self.V.dofmap.index_map
        bs = 3
        sp = dolfinx.fem.create_sparsity_pattern(a)
        sp.assemble()
        n_loc = imap.size_local
        r0 = imap.local_range[0]
        graph = sp.graph
        cm = sp.column_index_map()
        col_l2g = np.concatenate(
            [np.arange(*cm.local_range, dtype=np.int64), cm.ghosts.astype(np.int64)]
        )
        off = graph.offsets
        bulk_rows = np.repeat(np.arange(n_loc, dtype=np.int64) + r0, np.diff(off[: n_loc + 1]))
        bulk_cols = col_l2g[graph.array[: off[n_loc]]]
        n_glob = imap.size_global
        # interface entries, sent to the rank owning the row
        rows, cols = self.sparsity_blocks()
        key = np.unique(rows.ravel() * n_glob + cols.ravel())
        ranges = np.array(comm.allgather(imap.local_range[0]) + [n_glob])
        dest = np.searchsorted(ranges, key // n_glob, side="right") - 1
        order = np.argsort(dest, kind="stable")
        key = key[order]
        send_counts = np.bincount(dest, minlength=comm.size).astype(np.int64)
        recv_counts = np.array(comm.alltoall(send_counts.tolist()), dtype=np.int64)
        recv = np.empty(recv_counts.sum(), dtype=np.int64)
        comm.Alltoallv([key, send_counts, MPI.INT64_T], [recv, recv_counts, MPI.INT64_T])
        key = np.unique(np.concatenate([bulk_rows * n_glob + bulk_cols, recv]))
        nrow = key // n_glob - r0
        ncol = key % n_glob
        indptr_n = np.concatenate([[0], np.cumsum(np.bincount(nrow, minlength=n_loc))])
        # expand the node pattern to scalar rows: row bs*r+i has cols bs*c+j, c in row r
        seg = (bs * ncol[:, None] + np.arange(bs)).ravel()
        L = bs * np.diff(indptr_n)
        lens = np.repeat(L, bs)
        indptr = np.concatenate([[0], np.cumsum(lens)])
        within = np.arange(indptr[-1]) - np.repeat(indptr[:-1], lens)
        start = np.repeat(np.repeat(bs * indptr_n[:-1], bs), lens)
        indices = seg[start + within]
        A = PETSc.Mat().create(comm=comm)
        A.setSizes(((bs * n_loc, bs * n_glob), (bs * n_loc, bs * n_glob)), bsize=bs)
        A.setType(PETSc.Mat.Type.AIJ)
        A.setPreallocationCSR(
            (indptr.astype(PETSc.IntType), indices.astype(PETSc.IntType))
        )
        l2g = np.concatenate(
            [np.arange(*imap.local_range, dtype=np.int64), imap.ghosts.astype(np.int64)]
        )
        lgmap = PETSc.LGMap().create(l2g.astype(PETSc.IntType), bsize=bs, comm=MPI.COMM_SELF)
        A.setLGMap(lgmap, lgmap)
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        A.zeroEntries()
        return A

    # ------------------------------------------------------------------ evaluation
    def _pair_values(self, u) -> np.ndarray:
        x = u.vector if hasattr(u, "vector") else u
        self._scatter.scatter(x, self._loc, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self._loc.getArray(readonly=True)[self._inv]

    def jump(self, u) -> np.ndarray:
        """Local jump [g, s_x, s_y] (n_pts, 3) [mm] at displacement u (Function or PETSc Vec)."""
        return self._jump_of(self._pair_values(u))

    def _jump_of(self, u_pair: np.ndarray) -> np.ndarray:
        # batched matmul per facet: (n_f, nq*3, nd) @ (n_f, nd, 1)
        return (self._Bf @ u_pair[:, :, None]).reshape(-1, 3) + self._jump0

    def evaluate(self, u):
        """Evaluate the law at u (collective); cached while u's pair values do not change."""
        u_pair = self._pair_values(u)
        hit = self._cache_valid and np.array_equal(u_pair, self._last_u)
        if self.comm.allreduce(hit, op=MPI.LAND):  # ranks must agree: collectives follow
            return self._last
        jump = self._jump_of(u_pair)
        error = None
        try:
            res = self.law.evaluate(jump, self.committed)
            finite = np.isfinite(res.traction).all(axis=1) & np.isfinite(res.tangent).all(
                axis=(1, 2)
            )
        except (ValueError, ArithmeticError, RuntimeError) as exc:  # keep ranks in step: raise
            # everywhere, below (a rank-local ReturnMappingError would otherwise hang the rest)
            error, finite = str(exc), np.zeros(self.n_points, dtype=bool)
        errors = [e for e in self.comm.allgather(error) if e is not None]
        if errors:
            raise ValueError(f"interface law failed: {errors[0]}")
        n_bad = self.comm.allreduce(int(np.sum(~finite)), op=MPI.SUM)
        if n_bad:
            where = self._x[~finite][0].tolist() if np.any(~finite) else None
            where = next(e for e in self.comm.allgather(where) if e is not None)
            raise ValueError(
                f"interface law returned non-finite traction/tangent at {n_bad} of "
                f"{self.n_points_global} points, e.g. at x = {where} mm"
            )
        self.trial = res.state
        self._last_u, self._last, self._last_jump = u_pair.copy(), res, jump
        self._cache_valid, self._committed_last = True, False
        return res

    def assemble_residual(self, u, b: PETSc.Vec) -> None:
        """Add int B^T t dA to b (global PETSc Vec of V's layout) and assemble b (collective)."""
        res = self.evaluate(u)
        tw = (res.traction * self._weights[:, None]).reshape(self.n_facets, 3 * self.n_qp, 1)
        r = self._BfT @ tw  # (n_f, nd, 1)
        rows = self._rows.ravel()
        keep = rows >= 0
        if np.any(keep):
            b.setValues(rows[keep], r.ravel()[keep], addv=PETSc.InsertMode.ADD_VALUES)
        b.assemblyBegin()
        b.assemblyEnd()

    def assemble_jacobian(self, u, A: PETSc.Mat) -> None:
        """Add int B^T D B dA to A (collective). Flushes A first; the caller calls A.assemble()."""
        res = self.evaluate(u)
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        if self.n_facets == 0:  # setValuesRCV with zero rows dies with SIGFPE
            return
        DB = (res.tangent * self._weights[:, None, None]) @ self._B  # (n_pts, 3, nd)
        K = self._BfT @ DB.reshape(self._Bf.shape)  # (n_f, nd, nd), batched BLAS
        rows = self._rows
        A.setValuesRCV(rows, rows, K, addv=PETSc.InsertMode.ADD_VALUES)

    # ------------------------------------------------------------------ history
    def commit(self, u=None) -> None:
        """Accept the trial state of the last evaluation (after a converged increment).

        Args:
            u: if given, the law is first evaluated at u (the converged displacement).
        """
        if u is not None:
            self.evaluate(u)
        if self._last is not None and not self._committed_last:
            self._diss_committed = self._diss_committed + self._last.dissipation
            self.trial = self._last.state
            self._committed_last = True
        self.committed = self.trial.copy()
        self._cache_valid = False  # a new committed state: never reuse the old evaluation

    def revert(self) -> None:
        """Discard the trial state (failed increment, before a cutback)."""
        self.trial = self.committed.copy()
        self._last = None
        self._cache_valid = False

    # ------------------------------------------------------------------ output
    def _result(self):
        if self._last is None:
            raise ValueError("the interface has not been evaluated since the last commit/revert")
        return self._last

    def contact_force(self) -> np.ndarray:
        """(3,) force on the FIRST body's surface in global axes [N] (collective)."""
        res = self._result()
        f = np.einsum("pai,pa,p->i", self._R, res.traction, self._weights)
        return self.comm.allreduce(f, op=MPI.SUM)

    def real_contact_area(self) -> float:
        """int A/A0 dA over the interface [mm^2] (collective)."""
        res = self._result()
        return self.comm.allreduce(float(np.dot(res.area_fraction, self._weights)), op=MPI.SUM)

    def nominal_area(self) -> float:
        """Area of the first contact surface [mm^2] (collective)."""
        return self.comm.allreduce(float(self._weights.sum()), op=MPI.SUM)

    def dissipation(self) -> float:
        """Committed accumulated frictional dissipation int D dA [N mm] (collective)."""
        return self.comm.allreduce(float(np.dot(self._diss_committed, self._weights)), op=MPI.SUM)

    def slip_stats(self) -> SlipStats:
        """Counts and extremes of contact and slip at the last evaluation (collective)."""
        res = self._result()
        c = self.comm
        slip = np.linalg.norm(self._last_jump[:, 1:], axis=1)
        ps = self._plastic_slip()
        return SlipStats(
            n_points=self.n_points_global,
            n_contact=c.allreduce(int(res.contact.sum()), op=MPI.SUM),
            n_slipping=c.allreduce(int(res.slipping.sum()), op=MPI.SUM),
            contact_area=c.allreduce(float(self._weights[res.contact].sum()), op=MPI.SUM),
            slipping_area=c.allreduce(float(self._weights[res.slipping].sum()), op=MPI.SUM),
            max_slip=c.allreduce(float(slip.max(initial=0.0)), op=MPI.MAX),
            max_plastic_slip=c.allreduce(
                float(np.linalg.norm(ps, axis=1).max(initial=0.0)), op=MPI.MAX
            ),
        )

    def _plastic_slip(self) -> np.ndarray:
        ps = getattr(self.trial, "plastic_slip", None)
        if ps is None:
            return np.zeros((self.n_points, 2))
        return np.asarray(ps)[:, :2]

    @property
    def facets(self) -> np.ndarray:
        """(n_facets,) local indices of this rank's owned first-surface facets, in point order:
        point i lies on facet ``facets[i // n_qp]`` (read-only)."""
        return _read_only(self._facets1)

    def local_frames(self) -> np.ndarray:
        """(n_pts, 3, 3) local axes per point: rows n, x, y in global components (read-only)."""
        return _read_only(self._R)

    def point_coordinates(self) -> np.ndarray:
        """(n_pts, 3) reference coordinates of this rank's interface points [mm]."""
        return self._x

    def point_weights(self) -> np.ndarray:
        """(n_pts,) area represented by each of this rank's points [mm^2]."""
        return self._weights

    def point_fields(self) -> PointFields:
        """This rank's point fields at the last evaluation (see PointFields)."""
        res = self._result()
        jump = self._last_jump
        return PointFields(
            pressure=-res.traction[:, 0],
            shear=res.traction[:, 1:].copy(),
            area_fraction=np.asarray(res.area_fraction),
            gap=jump[:, 0],
            slip=jump[:, 1:],
            plastic_slip=self._plastic_slip(),
            dissipation=self._diss_committed + 0.0,
            contact=np.asarray(res.contact),
            slipping=np.asarray(res.slipping),
            weight=self._weights,
        )


_CELLS = {
    dolfinx.mesh.CellType.tetrahedron: (basix.CellType.tetrahedron, basix.CellType.triangle),
    dolfinx.mesh.CellType.hexahedron: (basix.CellType.hexahedron, basix.CellType.quadrilateral),
}


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


def _basix_cell(msh) -> basix.CellType:
    return _CELLS[msh.topology.cell_type][0]


def _cmap_element(msh):
    # dolfinx's coordinate element is the basix Lagrange element of the geometry degree;
    # for degree <= 2 all Lagrange variants have the same nodes.
    return basix.create_element(
        basix.ElementFamily.P, _basix_cell(msh), msh.geometry.cmap.degree,
        basix.LagrangeVariant.equispaced,
    )


def _vertex_weights(facet_cell, xi: np.ndarray) -> np.ndarray:
    """(nq, nv) P1/Q1 vertex shape functions of the reference facet at points xi (nq, 2)."""
    a, b = xi[:, 0], xi[:, 1]
    if facet_cell == basix.CellType.triangle:
        return np.column_stack([1.0 - a - b, a, b])
    return np.column_stack([(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b])


def _plane(rigid_plane) -> tuple[np.ndarray, np.ndarray]:
    if hasattr(rigid_plane, "point") and hasattr(rigid_plane, "normal"):
        point, normal = rigid_plane.point, rigid_plane.normal
    else:
        point, normal = rigid_plane
    point = np.asarray(point, dtype=float)
    normal = np.asarray(normal, dtype=float)
    if point.shape != (3,) or normal.shape != (3,) or not np.all(np.isfinite(normal)):
        raise ValueError(f"rigid_plane = {rigid_plane!r} must be (point (3,), normal (3,))")
    nn = np.linalg.norm(normal)
    if nn == 0:
        raise ValueError("rigid_plane normal must be nonzero")
    return point, normal / nn
