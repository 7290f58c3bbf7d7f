"""The jump operator: displacement -> jump at the interface points, its transpose for the
residual and the Jacobian, and its sparsity pattern.

Built from a pairing's :class:`~rough_contact.fem.pairing.base.PairedPoints`:

    jump = B u_pair + jump0            (local axes n, x, y at every point)

B holds, per point, minus the first facet's closure basis and plus the partner facet's, rotated
into the point's frame. Points are grouped into element blocks ("groups"): one per (first facet,
partner facet) pair, holding the first facet's points whose partner lies on that facet (all the
facet's points for conforming pairs and rigid obstacles: a group is a facet). A group's columns
are the closure DOFs of both facets in ascending global order (PETSc inserts sorted columns
faster); it has ``nqs`` point slots, unused ones have B = 0. A slot-filling copy of the mortar
pairing (``Partners.copy_of``, weight 0) shares the slot of the point it repeats.

Communication: one PETSc ``VecScatter`` from the global displacement vector to a sequential
vector of every DOF the rank's groups touch, wherever they are owned. Rows of Dirichlet DOFs are
-1 (PETSc skips negative rows and columns in matrices; for vectors they are filtered out).

Units: mm (B is dimensionless; weights in mm^2).
"""

from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem import compat
from rough_contact.fem.pairing.base import PairedPoints, Partners

__all__ = ["JumpOperator"]


class JumpOperator:
    """B and its transpose at the points of one pairing (collective construction).

    Args:
        V: the displacement space (block size 3).
        paired: the pairing's points.
        partners: partners to use instead of ``paired.partners`` (a re-pairing).
        bcs, global_dofs: Dirichlet DOFs the operator must not assemble into
            (:meth:`set_dirichlet_dofs`).

    Attributes:
        n_points: points of this rank (slot-filling copies included); n_groups: element blocks;
        n_remote_partners: blocks whose partner facet another rank owns; keys: (n_groups, 2)
        (first facet, partner facet) of every block (None for a rigid pairing).
    """

    def __init__(self, V, paired: PairedPoints, partners: Optional[Partners] = None, bcs=(),
                 global_dofs=None):
        self.V = V
        self.comm = V.mesh.comm
        self._build(paired.frames, paired.N1, paired.nodes1,
                    paired.partners if partners is None else partners)
        self._communication()
        self.set_dirichlet_dofs(global_dofs, bcs)

    # ------------------------------------------------------------------ construction
    def _build(self, R: np.ndarray, N1: np.ndarray, nodes1: np.ndarray,
               partners: Optional[Partners]) -> None:
        n_f, nq, n_close = N1.shape
        R = R.reshape(n_f, nq, 3, 3)
        B1 = -np.einsum("fqac,fqk->fqakc", R, N1).reshape(n_f, nq, 3, 3 * n_close)
        self.gap0 = np.zeros(n_f * nq)
        self.keys = None
        self.n_remote_partners = 0
        if partners is None:
            group_facet = np.arange(n_f)
            slot = np.tile(np.arange(nq), n_f)
            nqs, n_g = nq, n_f
            B = B1
            nodes = nodes1
            point_slot = np.repeat(group_facet, nq) * nqs + slot
            own_slot = np.ones(n_f * nq, dtype=bool)
        else:
            if partners.facet.size:
                # partner facet -1: a point without partner (sliding), a group of its own
                key = (np.arange(n_f)[:, None] * (int(partners.facet.max()) + 2)
                       + partners.facet + 1)
            else:
                key = np.zeros((0, nq), dtype=np.int64)
            copy_of = (np.full(n_f * nq, -1, dtype=np.int64) if partners.copy_of is None
                       else partners.copy_of.reshape(-1).astype(np.int64))
            own = np.flatnonzero(copy_of < 0)          # points with a slot of their own
            uniq, group = np.unique(key.ravel()[own], return_inverse=True)
            n_g = uniq.size
            order = np.argsort(group, kind="stable")
            counts = np.bincount(group, minlength=n_g)
            starts = (np.cumsum(counts) - counts).astype(np.int64)
            slot = np.empty(group.size, dtype=np.int64)
            slot[order] = np.arange(group.size) - np.repeat(starts, counts)
            nqs = int(counts.max(initial=0))
            first_point = own[order[starts]] if n_g else np.zeros(0, dtype=np.int64)
            group_facet = first_point // nq
            B2 = np.einsum("fqac,fqk->fqakc", R, partners.N2).reshape(n_f * nq, 3, 3 * n_close)
            B = np.zeros((n_g, nqs, 3, 6 * n_close))
            B[group, slot] = np.concatenate([B1.reshape(n_f * nq, 3, 3 * n_close)[own],
                                             B2[own]], axis=2)
            nodes = np.concatenate([nodes1[group_facet],
                                    partners.nodes2.reshape(n_f * nq, n_close)[first_point]],
                                   axis=1)
            self.gap0 = partners.gap0.reshape(-1)
            self.n_remote_partners = int(np.sum(partners.remote.reshape(-1)[first_point]))
            self.keys = np.stack([group_facet, partners.facet.reshape(-1)[first_point]], axis=1)
            point_slot = np.empty(n_f * nq, dtype=np.int64)
            point_slot[own] = group * nqs + slot
            copies = np.flatnonzero(copy_of >= 0)
            point_slot[copies] = point_slot[copy_of[copies]]
            own_slot = copy_of < 0
        pair_dofs = (3 * nodes[:, :, None] + np.arange(3)).reshape(n_g, 3 * nodes.shape[1])
        order = np.argsort(pair_dofs, axis=1)
        pair_dofs = np.take_along_axis(pair_dofs, order, axis=1)
        B = np.take_along_axis(B, order[:, None, None, :], axis=3)
        nd = B.shape[3]
        self.n_groups, self.nqs = n_g, nqs
        self._B = B.reshape(n_g * nqs, 3, nd)
        self._Bf = B.reshape(n_g, nqs * 3, nd)  # per-group view for matmul
        self._BfT = np.ascontiguousarray(np.swapaxes(self._Bf, 1, 2))
        self._point_slot = point_slot.astype(np.int64)
        self.own_slot = own_slot
        self._identity_slots = bool(n_g * nqs == n_f * nq and
                                    np.array_equal(point_slot, np.arange(n_f * nq)))
        self.pair_nodes = nodes  # (n_g, n_nodes_pair) global block indices
        self._pair_dofs = pair_dofs  # (n_g, nd) global scalar DOFs
        self.n_points = n_f * nq

    def _communication(self) -> None:
        """One scatter for every DOF the groups touch (collective)."""
        self._uniq, inv = np.unique(self._pair_dofs, return_inverse=True)
        self._inv = inv.reshape(self._pair_dofs.shape)
        self._template = compat.create_petsc_vector(self.V)
        self._loc = PETSc.Vec().createSeq(self._uniq.size, comm=MPI.COMM_SELF)
        is_from = PETSc.IS().createGeneral(self._uniq.astype(PETSc.IntType), comm=MPI.COMM_SELF)
        self._scatter = PETSc.Scatter().create(self._template, is_from, self._loc, None)
        self._rows = self._pair_dofs.astype(PETSc.IntType)

    def set_dirichlet_dofs(self, global_dofs: Optional[np.ndarray] = None,
                           bcs: Sequence = ()) -> None:
        """Mark DOFs the operator must not assemble into (collective).

        Args:
            global_dofs: global scalar DOF indices owned by this rank (each rank its own).
            bcs: dolfinx DirichletBC objects of V (their owned DOFs are added).

        Raises:
            ValueError: ``global_dofs`` not owned by the calling rank.
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
        self._scatter.scatter(marker, self._loc, PETSc.InsertMode.INSERT,
                              PETSc.ScatterMode.FORWARD)
        fixed = self._loc.getArray()[self._inv] != 0.0
        self._rows = np.where(fixed, -1, self._pair_dofs).astype(PETSc.IntType)
        marker.destroy()

    # ------------------------------------------------------------------ application
    def pair_values(self, x: PETSc.Vec) -> np.ndarray:
        """(n_groups, nd) displacement values of every group's DOFs (collective scatter)."""
        self._scatter.scatter(x, self._loc, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self._loc.getArray(readonly=True)[self._inv]

    def apply(self, u_pair: np.ndarray) -> np.ndarray:
        """(n_points, 3) B u_pair (without the offset jump0) [mm]."""
        # batched matmul per group: (n_g, nqs*3, nd) @ (n_g, nd, 1)
        jump = (self._Bf @ u_pair[:, :, None]).reshape(-1, 3)
        if not self._identity_slots:
            jump = jump[self._point_slot]
        return jump

    def to_slots(self, values: np.ndarray) -> np.ndarray:
        """Per-point values (n_pts, ...) laid out in group slots (n_g * nqs, ...), zero in
        unused slots."""
        if self._identity_slots:
            return values
        out = np.zeros((self.n_groups * self.nqs,) + values.shape[1:])
        own = self.own_slot
        out[self._point_slot[own]] = values[own]   # slot-filling copies carry weight 0
        return out

    def add_transpose(self, tw: np.ndarray, b: PETSc.Vec) -> None:
        """b += B^T tw for per-point weighted tractions tw (n_pts, 3) (no assembly call)."""
        tw = self.to_slots(tw)
        r = self._BfT @ tw.reshape(self.n_groups, 3 * self.nqs, 1)  # (n_g, nd, 1)
        rows = self._rows.ravel()
        keep = rows >= 0
        if np.any(keep):
            b.setValues(rows[keep], r.ravel()[keep], addv=PETSc.InsertMode.ADD_VALUES)

    def add_congruence(self, Dw: np.ndarray, A: PETSc.Mat) -> None:
        """A += B^T Dw B for per-point weighted tangents Dw (n_pts, 3, 3). Flushes A first (a
        dolfinx assembly ends with INSERT); the caller calls ``A.assemble()``."""
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        if self.n_groups == 0:  # setValuesRCV with zero rows dies with SIGFPE
            return
        D = self.to_slots(Dw)
        DB = D @ self._B  # (n_g * nqs, 3, nd)
        K = self._BfT @ DB.reshape(self._Bf.shape)  # (n_g, nd, nd), batched BLAS
        A.setValuesRCV(self._rows, self._rows, K, addv=PETSc.InsertMode.ADD_VALUES)

    # ------------------------------------------------------------------ sparsity
    def sparsity_blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """Global node-level (block size 3) (rows, cols) of every group's dense block, int64
        arrays (n_groups, m, m), m = nodes per group."""
        m = self.pair_nodes.shape[1]
        rows = np.broadcast_to(self.pair_nodes[:, :, None], (self.n_groups, m, m))
        cols = np.broadcast_to(self.pair_nodes[:, None, :], (self.n_groups, m, m))
        return rows, cols

    def create_matrix(self, a) -> PETSc.Mat:
        """A PETSc AIJ matrix with the pattern of the bilinear form ``a`` plus every group's
        block (collective): the blocks couple DOFs that share no cell (often no rank), so the
        pattern is merged in global indices, each entry sent to the rank owning its row. The
        matrix has dolfinx's layout and local-to-global map, so dolfinx assembles into it."""
        comm = self.comm
        imap = self.V.dofmap.index_map
        r0, n_glob = imap.local_range[0], imap.size_global
        bulk_rows, bulk_cols = compat.form_sparsity(a, self.V)
        rows, cols = self.sparsity_blocks()
        key = np.unique(rows.ravel() * n_glob + cols.ravel())
        ranges = np.array(comm.allgather(r0) + [n_glob])
        dest = np.searchsorted(ranges, key // n_glob, side="right") - 1
        order = np.argsort(dest, kind="stable")
        key = key[order]
        send_counts = np.bincount(dest, minlength=comm.size).astype(np.int64)
        recv_counts = np.array(comm.alltoall(send_counts.tolist()), dtype=np.int64)
        recv = np.empty(recv_counts.sum(), dtype=np.int64)
        comm.Alltoallv([key, send_counts, MPI.INT64_T], [recv, recv_counts, MPI.INT64_T])
        key = np.unique(np.concatenate([bulk_rows * n_glob + bulk_cols, recv]))
        return compat.block_csr_matrix(self.V, key // n_glob - r0, key % n_glob)
