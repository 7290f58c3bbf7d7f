"""Dual-mortar condensation of the contact multipliers: Alart–Curnier's semismooth Newton on
the displacement alone (``rough_contact.interface.enforcement.SemismoothNewton``).

Setting. The nodal point set with the dual basis (``NodalContactInterface(basis="dual")``) on
P1/Q1 displacements weighs the jump of first-surface vertex j with the dual function psi_j, so
its weighted jump involves the first surface's DOFs of j alone (coefficient s_j I in global
components, s_j = -1: the jump is the second surface's displacement minus the first's) and the
second surface's DOFs through the mortar coefficients A_jM:

    g~_j = R_j (s_j u_j + (1/m_j) sum_M A_jM u_M) + g0_j      (vertex frame R_j, weight m_j).

Unknowns. Exact contact and friction add a traction t_j per vertex (frame components) to the
equilibrium F_b(u) + sum_j m_j B_j^T t_j = 0 (F_b: everything but the contact) and the
complementarity equations Phi_j(t_j, g~_j(u)) = 0 (``rough_contact.interface.alart_curnier``).
The first-surface rows of vertex j read F_b,j + s_j m_j R_j^T t_j = 0, so

    t_j = -(s_j/m_j) R_j F_b,j(u)                                            (condensation)

exactly: the tractions are no unknowns. Substituted, the system in u alone is

    rows of j (first surface):   H_j = m_j R_j^T Phi_j(t_j(u), g~_j(u))
    rows of M (second surface):  H_M = F_b,M - sum_j (s_j/m_j) A_jM^T F_b,j
    every other row:             F_b.

Newton on H is Alart–Curnier's semismooth Newton on (u, t) with t eliminated (Wohlmuth's dual
mortar condensation; Popp et al. for friction): the same iterates, a system of the
displacement's size. Its Jacobian is J = L K + L_g G with K the bulk stiffness, G the rows of
the weighted jumps and L, L_g per-vertex 3 x 3 blocks:

    L on the rows of j:   -s_j R_j^T (dPhi/dt) R_j    (columns of j)
    L on the rows of M:   the identity, plus -(s_j/m_j) A_jM^T (columns of j)
    L_g on rows of j:     m_j R_j^T (dPhi/dg~)       (the frame rows of G_j)

computed as one sparse product [L | L_g] [K; G] with patterns fixed at set-up (K and G do not
change under small sliding; only the blocks of L on the vertices' rows change per iteration).

P2/Q2 (``basis="dual_quadratic"``). A point at every first-surface node, weighted by the
quadratic dual basis of Popp's modified functions Ntilde = T N
(``rough_contact.fem.nodal.quadratic_dual``). An edge node's weighted jump then reaches the
edge's end vertices too, and row k of the residual carries sum_j (T^-1)_kj s_j m_j R_j^T t_j.
The rows are therefore first combined by T (F -> T F, a parallel matrix that is the identity
away from the surface and on Dirichlet components). Each combined row j carries
s_j m_j R_j^T t_j alone, and everything above applies to T F_b. The Jacobian becomes
[L | L_g] [T K; G], where T K is formed once. Derivation: docs/exact_contact_newton.md, section 4.

Dirichlet components. A component of vertex j fixed by a Dirichlet condition is a symmetry
plane through it (``rough_contact.fem.nodal``): its row stays the Dirichlet row, its traction
component is zero, and the vertex frame must have an axis along it (true on a flat surface
meeting a symmetry plane at right angles; checked).

Units: mm, N, MPa.
"""

from __future__ import annotations

from typing import Optional, Protocol, runtime_checkable

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.interface.alart_curnier import ComplementarityResult, alart_curnier

__all__ = ["CondensedInterface", "DualCondensation"]


@runtime_checkable
class CondensedInterface(Protocol):
    """An interface whose enforcement replaces rows of the system (``ContactProblem`` asks):
    the residual and the Jacobian are transformed after the bulk assembly, and the Jacobian
    has the pattern of :meth:`condensed_matrix`."""

    def condenses(self) -> bool:
        """Whether this interface's enforcement condenses (else the usual assembly)."""
        ...

    def condensed_matrix(self, K: PETSc.Mat) -> PETSc.Mat:
        """A new Jacobian matrix with the condensed pattern, from the bulk matrix K (collective)."""
        ...

    def condense_residual(self, u, b: PETSc.Vec) -> None:
        """Replace b = F_b(u) (assembled, Dirichlet rows set) by H(u) (collective)."""
        ...

    def condense_jacobian(self, K: PETSc.Mat, A: PETSc.Mat) -> None:
        """A = J at the iterate of the last :meth:`condense_residual` (collective)."""
        ...


class DualCondensation:
    """The condensation's constant data and its per-iteration products (module docstring).

    Args:
        V: the displacement space (P1/Q1, or P2/Q2 with the quadratic dual basis); nodal:
            the vertex points (``rough_contact.fem.nodal.NodalPoints``, basis ``"dual"``, or
            ``"dual_quadratic"``: a point at every first-surface node, whose rows are combined
            by T, docs/exact_contact_newton.md section 4); rows: (n_v, nd) global
            rows of each vertex's DOFs, -1 for Dirichlet and padding columns (the vertex jump
            operator's); friction: Coulomb's mu; r_normal, r_tangential: the augmentation
            parameters [MPa/mm] (None: per vertex, the mean diagonal of the bulk matrix K over
            the node's free components divided by m_j; r_tangential None: r_normal's).

    Raises:
        ValueError (every rank): the first surface's coupling of a vertex is not the identity
            on its own DOFs (not P1/Q1 with the dual basis), or a Dirichlet component of a
            vertex is not along an axis of its frame.
    """

    def __init__(self, V, nodal, rows: np.ndarray, friction: float,
                 r_normal: Optional[float], r_tangential: Optional[float], K: PETSc.Mat):
        self.comm = comm = V.mesh.comm
        self.friction = friction
        imap = V.dofmap.index_map
        self.n_local = nl = 3 * imap.size_local
        self.start = s0 = 3 * imap.local_range[0]
        n_glob = 3 * imap.size_global
        n_v, _, nd = nodal.B.shape
        width = nd // 3
        self.n_v = n_v
        self.m = nodal.weights
        self.R = nodal.frames
        rows = np.asarray(rows, dtype=np.int64).reshape(n_v, width, 3)
        own = (nodal.nodes == nodal.vertex[:, None]) & ~nodal.pad
        bad = int(np.sum(own.sum(axis=1) != 1))
        # the first surface's coefficients (global components): A_own = m R^T B_own
        Bb = nodal.B.reshape(n_v, 3, width, 3)
        A = np.einsum("vai,vakc->vkic", self.R, Bb) * self.m[:, None, None, None]  # (v,k,i,c)
        own_col = np.argmax(own, axis=1)
        A_own = A[np.arange(n_v), own_col] / self.m[:, None, None]               # (v, i, c)
        S_rows = 3 * nodal.vertex[:, None] + np.arange(3)                         # (v, 3)
        fixed = rows[np.arange(n_v), own_col] < 0                                 # (v, 3)
        # the jump is second minus first surface: the own coefficient is -I (or +I)
        sign = np.where(np.einsum("vii->v", A_own) < 0.0, -1.0, 1.0)
        want = np.where(fixed[:, :, None], 0.0, sign[:, None, None] * np.eye(3)[None])
        comb = nodal.combination
        first = own.copy()           # the first surface's columns of each vertex's jump
        if comb is not None:
            # quadratic dual basis: an edge node's jump also reaches its end vertices, and
            # the combined rows T F carry one traction each (docs/exact_contact_newton.md,
            # section 4); checked: isotropic blocks, sum over the first surface's columns =
            # sign (rigid translation), own coefficient x T_jj = sign
            first = _owned_flag_at(comm, imap.size_local, imap.local_range[0], nodal.vertex,
                                   nodal.nodes) & ~nodal.pad
            t_jj = np.ones(n_v)
            diag = comb.row == comb.col
            t_jj[np.searchsorted(nodal.vertex, comb.row[diag])] = comb.value[diag]
            A1 = np.where(first[:, :, None, None], A, 0.0) / self.m[:, None, None, None]
            free = ~fixed
            iso = np.abs(A1 - np.einsum("vkii->vki", A1)[..., None] * np.eye(3)).max(
                axis=(1, 3)) if n_v else np.zeros((0, 3))
            total = np.einsum("vkii->vi", A1)
            own_d = np.einsum("vii->vi", A_own) * t_jj[:, None]
            if n_v and bad == 0:
                bad = int(np.sum(np.any(free & ((iso > 1e-9) | (np.abs(total - sign[:, None])
                                                                 > 1e-9)
                                                | (np.abs(own_d - sign[:, None]) > 1e-9)),
                                        axis=1)))
        elif n_v and bad == 0:
            bad = int(np.sum(np.abs(A_own - want).max(axis=(1, 2)) > 1e-9))
        # a fixed component must be along a frame axis: |R[k, i]| = 1 for some k
        if n_v and np.any(fixed):
            along = np.abs(self.R).max(axis=1)                                   # (v, i)
            bad += int(np.sum(fixed & (np.abs(along - 1.0) > 1e-10)))
        n_bad = comm.allreduce(bad, op=MPI.SUM)
        if n_bad:
            raise ValueError(
                f"{n_bad} contact vertices cannot be condensed: the semismooth Newton needs "
                "the first surface's weighted jump to be the identity on the vertex's own DOFs "
                "(P1 displacements, or Q1 on parallelogram facets, with basis='dual'; P2, or Q2 "
                "on parallelogram facets, with basis='dual_quadratic': the dual bases are "
                "biorthogonal there) and every Dirichlet component of a "
                "contact vertex along an axis of its frame (a symmetry plane at right angles)")
        self.fixed = fixed
        self.sign = sign
        self.S_rows = S_rows
        self.S_local = (S_rows - s0).astype(np.int64)
        # second surface: the columns other than the first surface's, their global rows
        partner = ~first & ~nodal.pad                                             # (v, w)
        self.partner = partner
        A_M = np.where(partner[:, :, None, None], A, 0.0)                         # (v,w,i,c)
        A_M = np.where(fixed[:, None, :, None], 0.0, A_M)    # a fixed jump component: zero
        self.A_M = A_M
        self.rows = rows
        # --- G: the frame rows of every vertex's weighted jump, on K's columns
        G_rows = np.repeat(S_rows, width * 3, axis=1).reshape(n_v, 3, width * 3)
        G_cols = np.broadcast_to(rows.reshape(n_v, 1, nd), (n_v, 3, nd))
        keep = (G_cols >= 0) & (nodal.B != 0.0)
        self._G = (G_rows[keep], G_cols[keep], nodal.B[keep])
        self._kg = S_rows + s0                               # K-part rows of Kg for S (own)
        self._gg = S_rows + s0 + nl                          # G-part rows of Kg for S (own)
        self.n_glob = n_glob
        self._L = self._Kg = None
        # augmentation: given, or the bulk stiffness per area at the vertex's node
        diag = K.getDiagonal()             # collective: also on a rank without contact vertices
        d = diag.array[self.S_local] if n_v else np.zeros((0, 3))
        diag.destroy()
        free = np.maximum((~fixed).sum(axis=1), 1)
        stiffness = np.where(fixed, 0.0, d).sum(axis=1) / free / self.m
        self.r_normal = stiffness if r_normal is None else np.full(n_v, float(r_normal))
        self.r_tangential = self.r_normal if r_tangential is None else \
            np.full(n_v, float(r_tangential))
        self._T = self._tmp = None
        if comb is not None:
            self._T = self._combination(comb, nodal.vertex, fixed)

    def _combination(self, comb, vertex: np.ndarray, fixed: np.ndarray) -> PETSc.Mat:
        """T as a parallel matrix on the displacement's rows: the identity but on the first
        surface's free components, whose rows combine those of their facets' nodes (the
        owner of a row builds it; collective). Raises ValueError on every rank if a free
        component would take a fixed one's row."""
        nl, s0 = self.n_local, self.start
        node_fixed = fixed[np.searchsorted(vertex, comb.row)]                     # (n, 3)
        r = (3 * comb.row[:, None] + np.arange(3)).reshape(-1)
        c = (3 * comb.col[:, None] + np.arange(3)).reshape(-1)
        v = np.repeat(comb.value, 3)
        row_fixed = node_fixed.reshape(-1)
        col_fixed = comb.col_fixed.reshape(-1)
        same = r == c
        n_bad = self.comm.allreduce(int(np.sum(~row_fixed & col_fixed & ~same)), op=MPI.SUM)
        if n_bad:
            raise ValueError(f"{n_bad} free components of contact nodes would combine with a "
                             "Dirichlet row (the quadratic dual condensation supports "
                             "symmetry planes through whole facet edges only)")
        keep = ~row_fixed & ~col_fixed
        r, c, v = r[keep], c[keep], v[keep]
        # identity rows: every local row not combined (fixed components included)
        combined = np.zeros(nl, dtype=bool)
        combined[r - s0] = True
        ident = np.flatnonzero(~combined) + s0
        r = np.concatenate([r, ident])
        c = np.concatenate([c, ident])
        v = np.concatenate([v, np.ones(ident.size)])
        order = np.lexsort((c, r))
        r, c, v = r[order] - s0, c[order], v[order]
        indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=nl))])
        T = PETSc.Mat().createAIJ(size=((nl, self.n_glob), (nl, self.n_glob)),
                                  csr=(indptr.astype(PETSc.IntType), c.astype(PETSc.IntType),
                                       v), comm=self.comm)
        T.assemble()
        return T

    # ------------------------------------------------------------------ the residual
    def tractions(self, F_S: np.ndarray) -> np.ndarray:
        """t_j = -(s_j/m_j) R_j F_b,j (frame components) from the rows F_S (n_v, 3) [MPa]."""
        F = np.where(self.fixed, 0.0, F_S)
        return -np.einsum("vai,vi->va", self.R, F) * (self.sign / self.m)[:, None]

    def residual(self, b: PETSc.Vec, jump: np.ndarray, plastic_slip: np.ndarray
                 ) -> tuple[np.ndarray, ComplementarityResult]:
        """Replace b = F_b by H (no assembly of the second surface's rows; see
        :meth:`add_partner_rows`); returns (t, the complementarity result)."""
        if self._T is not None:          # the combined rows T F_b (collective)
            if self._tmp is None:
                self._tmp = b.duplicate()
            self._T.mult(b, self._tmp)
            self._tmp.copy(b)
        arr = b.array
        F_S = arr[self.S_local] if self.n_v else np.zeros((0, 3))
        t = self.tractions(F_S)
        ac = alart_curnier(t, jump, plastic_slip, self.friction, self.r_normal,
                           self.r_tangential)
        H = np.einsum("vai,va->vi", self.R, ac.residual) * self.m[:, None]
        if self.n_v:
            arr[self.S_local] = np.where(self.fixed, F_S, H)
        self._F_S = np.where(self.fixed, 0.0, F_S)
        return t, ac

    def add_partner_rows(self, b: PETSc.Vec) -> None:
        """b_M -= sum_j (s_j/m_j) A_jM^T F_b,j (the second surface's rows; ADD, no
        assembly)."""
        if not self.n_v:
            return
        v = -np.einsum("vwic,vi->vwc", self.A_M, self._F_S) * (self.sign / self.m)[:, None, None]
        r = np.where(self.partner[:, :, None], self.rows, -1).reshape(-1)
        keep = r >= 0
        b.setValues(r[keep].astype(PETSc.IntType), v.reshape(-1)[keep],
                    addv=PETSc.InsertMode.ADD_VALUES)

    # ------------------------------------------------------------------ the Jacobian
    def _build(self, K: PETSc.Mat) -> None:
        """[K; G] and the pattern of [L | L_g] (once; collective)."""
        comm, nl, s0 = self.comm, self.n_local, self.start
        if self._T is not None:         # [T K; G]: K is constant (linear bulk)
            TK = self._T.matMult(K)
            ai, aj, av = TK.getValuesCSR()
            TK.destroy()
        else:
            ai, aj, av = K.getValuesCSR()
        gr, gc, gv = self._G
        order = np.argsort(gr, kind="stable")
        gr, gc, gv = gr[order] - s0, gc[order], gv[order]
        g_ptr = np.concatenate([[0], np.cumsum(np.bincount(gr, minlength=nl))])
        indptr = np.concatenate([ai, ai[-1] + g_ptr[1:]]).astype(PETSc.IntType)
        indices = np.concatenate([aj, gc]).astype(PETSc.IntType)
        values = np.concatenate([av, gv])
        self._Kg = PETSc.Mat().createAIJ(size=((2 * nl, 2 * self.n_glob), (nl, self.n_glob)),
                                         csr=(indptr, indices, values), comm=comm)
        self._Kg.assemble()
        L = PETSc.Mat().createAIJ(size=((nl, self.n_glob), (2 * nl, 2 * self.n_glob)),
                                  nnz=(8, 8), comm=comm)
        L.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        own = np.arange(s0, s0 + nl, dtype=PETSc.IntType)
        L.setValuesRCV(own.reshape(-1, 1), (own + s0).reshape(-1, 1),
                       np.ones((nl, 1, 1)), addv=PETSc.InsertMode.INSERT_VALUES)
        if self.n_v:
            L.setValuesRCV(*self._s_blocks(np.zeros((self.n_v, 3, 3)) + 1.0,
                                           np.zeros((self.n_v, 3, 3)) + 1.0),
                           addv=PETSc.InsertMode.INSERT_VALUES)
            # the second surface's rows: -(1/m_j) A_jM^T on the columns of j (constant)
            v = -np.einsum("vwic->vwci", self.A_M) * (self.sign / self.m)[:, None, None, None]
            rows = np.where(self.partner[:, :, None], self.rows, -1)
            rows = rows.reshape(self.n_v, -1).astype(PETSc.IntType)
            cols = np.ascontiguousarray(self._kg).astype(PETSc.IntType)
            L.setValuesRCV(rows, cols, np.ascontiguousarray(v.reshape(self.n_v, -1, 3)),
                           addv=PETSc.InsertMode.INSERT_VALUES)
        L.assemble()
        L.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        self._L = L

    def _s_blocks(self, Ls: np.ndarray, Lg: np.ndarray):
        """(rows, cols, values) of the vertices' rows of [L | L_g] (global components; a
        fixed component's row is the identity)."""
        f = self.fixed
        Ls = np.where(f[:, None, :], 0.0, Ls)                  # a fixed column: F_S masked
        Ls = np.where(f[:, :, None], np.eye(3)[None], Ls)      # a fixed row: the identity
        Lg = np.where(f[:, :, None], 0.0, Lg)
        cols = np.concatenate([self._kg, self._gg], axis=1).astype(PETSc.IntType)
        return (self.S_rows.astype(PETSc.IntType), cols,
                np.ascontiguousarray(np.concatenate([Ls, Lg], axis=2)))

    def matrix(self, K: PETSc.Mat) -> PETSc.Mat:
        """A new matrix with the pattern of J (collective)."""
        if self._L is None:
            self._build(K)
        return self._L.matMult(self._Kg)

    def jacobian(self, ac: ComplementarityResult, A: PETSc.Mat) -> None:
        """A = [L | L_g] [K; G] with the blocks of ``ac`` (collective)."""
        Ls = -np.einsum("vai,vab,vbk->vik", self.R, ac.d_traction, self.R) * \
            self.sign[:, None, None]
        Lg = np.einsum("vai,vab->vib", self.R, ac.d_jump) * self.m[:, None, None]
        if self.n_v:
            self._L.setValuesRCV(*self._s_blocks(Ls, Lg), addv=PETSc.InsertMode.INSERT_VALUES)
        self._L.assemble()
        self._L.matMult(self._Kg, result=A)


def _owned_flag_at(comm, n_owned: int, first_owned: int, flagged: np.ndarray,
                   wanted: np.ndarray) -> np.ndarray:
    """Whether each of ``wanted`` (global node indices, any shape, any rank's nodes) is among
    the ``flagged`` nodes of some rank (each rank flags nodes it owns: global indices in
    [first_owned, first_owned + n_owned)). Collective; one PETSc scatter of the wanted entries
    from a distributed flag vector, so memory is O(owned + wanted) per rank, whatever the
    number of ranks (an allgather of every rank's list would be O(all flagged))."""
    flags = PETSc.Vec().createMPI((n_owned, PETSc.DECIDE), comm=comm)
    r0, r1 = flags.getOwnershipRange()
    if r0 != first_owned or r1 != first_owned + n_owned:
        raise RuntimeError(f"node ownership [{r0}, {r1}) of the flag vector differs from the "
                           f"index map's [{first_owned}, {first_owned + n_owned})")
    flags.set(0.0)
    flags.array[np.asarray(flagged, dtype=np.int64) - first_owned] = 1.0
    uniq, inv = np.unique(np.asarray(wanted, dtype=np.int64), return_inverse=True)
    got = PETSc.Vec().createSeq(uniq.size, comm=PETSc.COMM_SELF)
    is_from = PETSc.IS().createGeneral(uniq.astype(PETSc.IntType), comm=PETSc.COMM_SELF)
    scatter = PETSc.Scatter().create(flags, is_from, got, None)
    try:
        scatter.scatter(flags, got, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        out = got.getArray().copy() > 0.5
    finally:
        for obj in (scatter, is_from, got, flags):
            obj.destroy()
    return out[inv.reshape(np.shape(wanted))]
