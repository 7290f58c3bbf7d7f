"""Nodal (vertex) interface points obtained through the mortar integrals: exact contact and
stick with no more constraints than the surface can carry, on any element order and pairing.

An exact enforcement (``AugmentedLagrangian``) imposes its constraint at every point the law
is evaluated at. At the quadrature points of a P2 facet (6 Gauss points of degree 4 for 6
nodes, shared with the neighbours: about 4 times as many points as surface nodes) the
constraints lock. This module evaluates the law at the VERTICES of the first surface instead,
on jumps weighted by first-order vertex shape functions N_j (P1 on triangles, Q1 on
quadrilaterals, also for P2/Q2 displacements):

    m_j = sum_q w_q N_j(x_q),        g~_j = R_j (1/m_j) sum_q w_q N_j(x_q) R_q^T g_q,

where q runs over the pairing's points (Gauss points of the conforming or rigid pairing, the
pieces' points of the mortar pairing), w_q their area weights, R_q their frames, g_q = B_q u
+ g0_q their jumps, and R_j the vertex frame (normal: the normalised weighted normal
sum_q w_q N_j n_q; x: the grain direction projected). The law gives t_j at g~_j, and the force
m_j t_j goes back through the same rows: R_c = sum_j m_j B_j^T t_j with
B_j = R_j (1/m_j) sum_q w_q N_j R_q^T B_q. A first-order multiplier space is stable for P2/Q2
displacements and avoids the P2 triangle's corner functions of zero integral (which break a
dual basis). Because the N_j are a partition of unity, a uniform traction gives exactly the
quadrature route's residual: the patch test passes wherever the pairing passes it.

``basis="dual_quadratic"`` (P2/Q2) instead puts a point at every first-surface node, weighted
by Popp's modified quadratic functions and their dual basis (:func:`quadratic_dual`). This is
what lets the semismooth Newton condense the tractions on P2/Q2
(``rough_contact.fem.condensation``). Its nodal tractions are noisier than the vertex set's
on a curved contact (docs/exact_contact_newton.md, section 4).

Each vertex row combines the rows of all the vertex's facets (and their partners): one
"group" per vertex with a variable number of DOFs, padded to the rank's largest count with
zero columns whose matrix rows are skipped (-1). A vertex shared by facets on several ranks is
assembled on the rank that owns its DOF (its global index): every rank sends its partial sums
there once at set-up; a rank without contact facets is normal. A displacement component of
the vertex fixed by a Dirichlet condition (a symmetry plane through it) is a mirror: the
weighted jump and normal of its half patch get no component along that axis, as the full
symmetric patch would have none. The penalty, the
augmented-Lagrangian enforcement and the friction history then work unchanged on the vertex
points.

Units: mm, N, MPa.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import basix
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.jump import JumpOperator
from rough_contact.fem.pairing.base import PairedPoints, SurfaceContext, local_frames
from rough_contact.fem.pairing.facets import basix_cell
from rough_contact.fem.condensation import DualCondensation
from rough_contact.interface.contract import LawResult
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian, SemismoothNewton
from rough_contact.interface.state import InterfaceState

__all__ = ["NodalContactInterface", "NodalPoints", "VertexJumpOperator", "nodal_points",
           "quadratic_dual", "vertex_shape_matrix"]


@dataclass(frozen=True)
class NodalPoints:
    """The vertex points of this rank (the vertices whose DOF it owns).

    Attributes:
        vertex: (n_v,) global block index of each vertex's DOF (ascending).
        x: (n_v, 3) vertex coordinates [mm].
        weights: (n_v,) m_j = int N_j dA over the first surface [mm^2].
        frames: (n_v, 3, 3) local axes, rows n, x, y in global components.
        jump0: (n_v, 3) jump at zero displacement [mm].
        B: (n_v, 3, 3 m) rows of the weighted jump on the vertex's DOFs.
        nodes: (n_v, m) global block indices of those DOFs (padded with the first node).
        pad: (n_v, m) True for padding columns (B = 0 there).
        combination: the rows of T with ``basis="dual_quadratic"``, else None.
        spacing: (n_v,) h_j = sqrt(m_j / s) [mm], s = sqrt(3)/2 on a triangulated surface
            and 1 on a quadrilateral one: the edge of the uniform mesh of equilateral
            triangles (squares) whose vertices carry the weight m_j, i.e. the local point
            spacing (with ``basis="dual_quadratic"`` the node spacing, about half the element
            size). A point on a mirror plane or on the surface's edge carries a smaller
            weight, so a smaller h_j. What ``AugmentedLagrangian(reference_spacing=)``
            scales the penalty with.
    """

    vertex: np.ndarray
    x: np.ndarray
    weights: np.ndarray
    frames: np.ndarray
    jump0: np.ndarray
    B: np.ndarray
    nodes: np.ndarray
    pad: np.ndarray
    combination: Optional["RowCombination"] = None
    spacing: Optional[np.ndarray] = None


@dataclass(frozen=True)
class RowCombination:
    """The rows of T (Ntilde = T N, :func:`quadratic_dual`) owned by this rank, for the
    quadratic dual basis's condensation (docs/exact_contact_newton.md, section 4): entry
    (row node, column node, value) in global block indices; ``col_fixed`` (n, 3): the column
    node's components fixed by a Dirichlet condition."""

    row: np.ndarray
    col: np.ndarray
    value: np.ndarray
    col_fixed: np.ndarray


def vertex_shape_matrix(V) -> tuple[np.ndarray, np.ndarray]:
    """First-order vertex functions in terms of the facet-closure basis of V.

    Returns:
        M: (n_lf, n_close, nv): M[lf, k, i] = value of the P1/Q1 function of the facet's vertex
            i at the node of closure DOF k, so that N_i = sum_k M[lf, k, i] phi_k exactly (the
            first-order space lies in V's space; for P1/Q1, M is a selection).
        vertex_closure: (n_lf, nv) closure index of each facet vertex's DOF.
    """
    element = V.element.basix_element
    cell = basix_cell(V.mesh)
    p1 = basix.create_element(basix.ElementFamily.P, cell, 1)
    closure = np.array(element.entity_closure_dofs[2])        # (n_lf, n_close)
    facet_vertices = np.array(basix.topology(cell)[2])        # (n_lf, nv)
    n_lf, n_close = closure.shape
    X = np.asarray(element.points)[closure].reshape(-1, 3)
    tab = np.asarray(p1.tabulate(0, X)[0]).reshape(n_lf, n_close, p1.dim)
    M = np.take_along_axis(tab, facet_vertices[:, None, :], axis=2)
    M[np.abs(M) < 1e-12] = 0.0
    vertex_closure = np.argmax(M, axis=1)
    if not np.allclose(np.take_along_axis(M, vertex_closure[:, None, :], axis=1), 1.0):
        raise ValueError("the displacement element has no DOF at every facet vertex; the "
                         "nodal point set needs a Lagrange space of degree 1 or 2")
    return M, vertex_closure


def dual_matrix(nv: int) -> np.ndarray:
    """(nv, nv) D with psi_i = sum_j N_j D[j, i] the dual (biorthogonal) basis of the
    first-order vertex functions N_j of a facet: int psi_i N_k dA = delta_ik int N_k dA on
    a flat triangle (nv = 3: psi_i = 4 N_i - 1) or a parallelogram (nv = 4: the tensor product
    of the segment's 2 N_1 - N_2, in basix's vertex order (0,0), (1,0), (0,1), (1,1)); the
    psi_i sum to 1 (a partition of unity, as the N_i)."""
    if nv == 3:
        return 4.0 * np.eye(3) - 1.0
    if nv == 4:
        a = np.array([[2.0, -1.0], [-1.0, 2.0]])
        return np.kron(a, a)          # vertex v = x + 2 y: kron over (y, x) is symmetric here
    raise ValueError(f"a facet with {nv} vertices has no dual basis here (3 or 4)")


BASES = ("standard", "dual", "dual_quadratic")
"""The nodal point set's bases: first-order vertex functions N_j, their dual basis, or a
multiplier at every first-surface node of P2/Q2 with the quadratic dual basis."""

MODIFIED_P2_ALPHA = 0.2
"""Popp et al.'s modification of the 6-node triangle's basis for a quadratic dual basis."""


def quadratic_dual(facet: str) -> tuple[np.ndarray, np.ndarray]:
    """The dual (biorthogonal) basis of a quadratic facet's nodal functions, in basix's DOF
    order: the reference-element piece of a quadratic dual-mortar condensation (design and
    status: docs/exact_contact_newton.md, section 4; used by ``basis="dual_quadratic"``).

    On the 6-node triangle the vertex functions integrate to zero, so no dual basis of the
    plain functions has positive weights. Popp et al.'s modified functions
    Ntilde_v = N_v + alpha (N_e + N_e') (the two edges at v), Ntilde_e = (1 - 2 alpha) N_e,
    alpha = 1/5, still sum to 1 and integrate to 2/15 and 1/5 of the area. The 9-node
    quadrilateral needs no modification (the functions integrate to 1/36, 1/9, 4/9 of the area):
    the dual basis is the tensor product of the segment's.

    Args:
        facet: ``"triangle6"`` (P2 tetrahedra) or ``"quadrilateral9"`` (Q2 hexahedra).

    Returns:
        T: (n, n) Ntilde_i = sum_k T[i, k] N_k (the identity for ``"quadrilateral9"``); the
            displacement's coefficients change as u = T^T utilde.
        A: (n, n) psi_i = sum_k A[i, k] Ntilde_k with int psi_i Ntilde_k dA =
            delta_ik int Ntilde_k dA on an affine facet; the psi_i sum to 1.
    """
    if facet == "triangle6":
        # basix: vertices 0, 1, 2; DOF 3 + e on edge e, the edge opposite vertex e
        a = MODIFIED_P2_ALPHA
        T = np.diag([1.0, 1.0, 1.0, 1.0 - 2 * a, 1.0 - 2 * a, 1.0 - 2 * a])
        for v in range(3):
            for e in range(3):
                if e != v:
                    T[v, 3 + e] = a
        # mass matrix of the plain P2 functions on the unit-area triangle, in 1/180: vertex
        # 6 (itself), -1 (other vertex), -4 (opposite edge), 0 (adjacent edge); edge 32, 16
        M = np.zeros((6, 6))
        M[:3, :3] = 7.0 * np.eye(3) - 1.0
        M[3:, 3:] = 16.0 * np.eye(3) + 16.0
        M[:3, 3:] = M[3:, :3] = -4.0 * np.eye(3)
        M /= 180.0
        Mt = T @ M @ T.T
    elif facet == "quadrilateral9":
        # segment [0, 1]: nodes 0, 1, midpoint; mass of the quadratic functions
        m1 = np.array([[4.0, -1.0, 2.0], [-1.0, 4.0, 2.0], [2.0, 2.0, 16.0]]) / 30.0
        # basix's 9-node quadrilateral: (x, y) node index per DOF (0, 1: ends, 2: midpoint)
        xy = [(0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (0, 2), (1, 2), (2, 1), (2, 2)]
        T = np.eye(9)
        Mt = np.array([[m1[i[0], j[0]] * m1[i[1], j[1]] for j in xy] for i in xy])
    else:
        raise ValueError(f"facet = {facet!r} is invalid: 'triangle6' or 'quadrilateral9'")
    D = np.diag(Mt.sum(axis=1))            # int Ntilde_k dA (the functions sum to 1)
    return T, D @ np.linalg.inv(Mt)


def quadratic_shape_matrix(V) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The modified quadratic functions and their dual basis in V's facet-closure order.

    Returns:
        M: (n_lf, n_close, n_close): M[lf, k, i] = T[i, k], Ntilde_i = sum_k M[lf, k, i] phi_k
            (T of :func:`quadratic_dual`, permuted to the closure's order of facet lf).
        closure_index: (n_lf, n_close): the multiplier of closure DOF k sits at node k.
        D: (n_lf, n_close, n_close): psi_i = sum_k Ntilde_k D[lf, k, i].

    Raises:
        ValueError: V is not a degree-2 Lagrange space on tetrahedra or hexahedra.
    """
    element = V.element.basix_element
    cell = basix_cell(V.mesh)
    if element.degree != 2 or cell not in (basix.CellType.tetrahedron,
                                           basix.CellType.hexahedron):
        raise ValueError(f"basis = 'dual_quadratic' needs P2 or Q2 displacements (degree 2 on "
                         f"tetrahedra or hexahedra); got degree {element.degree} on "
                         f"{cell.name}")
    facet = "triangle6" if cell == basix.CellType.tetrahedron else "quadrilateral9"
    T_ref, A_ref = quadratic_dual(facet)
    closure = np.array(element.entity_closure_dofs[2])          # (n_lf, n_close)
    facet_vertices = np.array(basix.topology(cell)[2])          # (n_lf, nv)
    corners = np.asarray(basix.geometry(cell))
    X = np.asarray(element.points)
    n_lf, n_close = closure.shape
    nv = facet_vertices.shape[1]
    # reference-facet nodes in quadratic_dual's order, as pairs of facet vertices whose
    # midpoint the node is (a vertex: the pair (i, i)); the centre of a quadrilateral last
    pairs = ([(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)] if nv == 3 else
             [(0, 0), (1, 1), (2, 2), (3, 3), (0, 1), (0, 2), (1, 3), (2, 3), (0, 3)])
    M = np.zeros((n_lf, n_close, n_close))
    D = np.zeros((n_lf, n_close, n_close))
    for lf in range(n_lf):              # set-up, over the cell's 4 or 6 reference facets
        c = corners[facet_vertices[lf]]
        ref_x = np.array([0.5 * (c[a] + c[b]) for a, b in pairs])
        dist = np.linalg.norm(X[closure[lf]][:, None, :] - ref_x[None, :, :], axis=2)
        perm = np.argmin(dist, axis=1)                          # closure k -> reference node
        if not np.allclose(dist[np.arange(n_close), perm], 0.0) or \
                np.unique(perm).size != n_close:
            raise ValueError("the P2/Q2 element's facet nodes are not at the facet's vertices, "
                             "edge midpoints and centre: no quadratic dual basis")
        M[lf] = T_ref[np.ix_(perm, perm)].T
        D[lf] = A_ref[np.ix_(perm, perm)].T
    return M, np.tile(np.arange(n_close), (n_lf, 1)), D


def nodal_points(ctx: SurfaceContext, paired: PairedPoints, op: JumpOperator,
                 basis: str = "standard") -> NodalPoints:
    """The vertex points of the first surface from the pairing's points (collective).

    Args:
        ctx: the first surface; paired: the pairing's points; op: their jump operator (its
            per-point rows and the DOFs of its groups; Dirichlet rows are not used).
        basis: the weight of the vertex jumps: ``"standard"`` (N_j) or ``"dual"`` (the
            biorthogonal psi_j of :func:`dual_matrix`; the weights m_j and normals stay those
            of N_j, int psi_j = int N_j); or ``"dual_quadratic"`` (P2/Q2 only): a point at
            every node of the first surface, the weights m_j and normals those of Popp's
            modified functions Ntilde_j, the jumps weighted by their dual basis
            (:func:`quadratic_shape_matrix`); ``combination`` then holds the rows of T. With P1 displacements the dual weighted jump of
            vertex j involves the first surface's DOFs of j alone (and, on a conforming
            pairing, the second's of its partner alone): entries below 1e-12 m_j are dropped,
            a sparser Jacobian.

    Raises:
        ValueError (every rank): a vertex with zero weight.
    """
    V, comm = ctx.V, ctx.comm
    if basis not in BASES:
        raise ValueError(f"basis = {basis!r} is invalid: one of {', '.join(BASES)}")
    if basis == "dual_quadratic":
        M, vclose, Dq = quadratic_shape_matrix(V)
    else:
        M, vclose = vertex_shape_matrix(V)
    lf = ctx.geo1.local_facet
    n_f, nq = paired.facets.size, paired.n_qp
    nv = M.shape[2]
    Nv = np.einsum("fqk,fkv->fqv", paired.N1, M[lf])                  # (n_f, nq, nv)
    vid = np.take_along_axis(paired.nodes1, vclose[lf], axis=1)       # (n_f, nv)
    c = paired.weights.reshape(n_f, nq, 1) * Nv                       # w_q N_j(x_q)
    if basis == "standard":                                           # the jump's weights
        cj = c
    elif basis == "dual":
        cj = c @ dual_matrix(nv)
    else:
        cj = np.einsum("fqk,fki->fqi", c, Dq[lf])
    R = paired.frames.reshape(n_f, nq, 3, 3)
    jump0 = paired.jump0.copy()
    jump0[:, 0] += op.gap0
    # per (facet, vertex): weight, weighted normal, weighted initial jump (global components)
    m_fv = c.sum(axis=1)
    n_fv = np.einsum("fqv,fqi->fvi", c, R[:, :, 0, :])
    j0_fv = np.einsum("fqv,fqai,fqa->fvi", cj, R, jump0.reshape(n_f, nq, 3))
    # per (group, vertex): the weighted rows sum_q c R_q^T B_q on the group's DOFs
    n_g, nqs, nd = op.n_groups, op.nqs, op._B.shape[2]
    own = np.flatnonzero(op.own_slot)
    slot = op._point_slot[own]
    cs = np.zeros((n_g * nqs, nv))
    cs[slot] = cj.reshape(-1, nv)[own]
    Rs = np.zeros((n_g * nqs, 3, 3))
    Rs[slot] = paired.frames[own]
    Bg = np.einsum("sai,sad->sid", Rs, op._B).reshape(n_g, nqs, 3, nd)
    G = np.einsum("gsv,gsid->gvid", cs.reshape(n_g, nqs, nv), Bg)     # (n_g, nv, 3, nd)
    group_facet = np.zeros(n_g, dtype=np.int64)
    group_facet[slot // nqs] = own // nq
    nn = nd // 3
    group_nodes = op._pair_dofs[:, ::3] // 3                           # (n_g, nn), ascending
    t_vid = np.repeat(vid[group_facet], nn, axis=1).reshape(-1)       # (n_g * nv * nn,)
    t_node = np.broadcast_to(group_nodes[:, None, :], (n_g, nv, nn)).reshape(-1)
    t_val = G.reshape(n_g, nv, 3, nn, 3).transpose(0, 1, 3, 2, 4).reshape(-1, 3, 3)
    # components of the vertex's own displacement fixed by a Dirichlet condition (rows -1 of
    # the quadrature operator): a symmetry plane through the vertex, mirrored below
    m_keys = 3 * V.dofmap.index_map.size_global
    flat = (np.arange(n_g)[:, None] * m_keys + op._pair_dofs).reshape(-1)
    own_dofs = (np.arange(n_g)[:, None, None] * m_keys + 3 * vid[group_facet][:, :, None]
                + np.arange(3))
    pos = np.minimum(np.searchsorted(flat, own_dofs), max(flat.size - 1, 0))
    f_fixed = (op._rows.reshape(-1)[pos] < 0) if flat.size else np.zeros((0, nv, 3), bool)
    if basis == "dual_quadratic":
        # the row combinations T (Ntilde = T N) per facet: (row node, column node, T, the
        # column node's fixed components), sent with the rest to the row node's owner
        gi, gk, gl = np.nonzero(np.swapaxes(M[lf[group_facet]], 1, 2))   # (g, row i, col k)
        q_row = vid[group_facet[gi], gk].astype(np.int64)
        q_col = vid[group_facet[gi], gl].astype(np.int64)
        q_val = M[lf[group_facet[gi]], gl, gk]
        q_fix = f_fixed.reshape(n_g, nv, 3)[gi, gl]
    else:
        q_row = q_col = np.zeros(0, dtype=np.int64)
        q_val, q_fix = np.zeros(0), np.zeros((0, 3), dtype=bool)
    f_vid = vid[group_facet].reshape(-1)
    f_fixed = f_fixed.reshape(-1, 3)
    keep = np.any(t_val != 0.0, axis=(1, 2))
    t_vid, t_node, t_val = t_vid[keep], t_node[keep], t_val[keep]
    # send everything to the rank owning the vertex's DOF
    imap = V.dofmap.index_map
    r0 = imap.local_range[0]
    ranges = np.array(comm.allgather(r0) + [imap.size_global])
    dest_v = np.searchsorted(ranges, vid.reshape(-1), side="right") - 1
    dest_t = np.searchsorted(ranges, t_vid, side="right") - 1
    a_vals = np.concatenate([vid.reshape(-1, 1).astype(float), m_fv.reshape(-1, 1),
                             n_fv.reshape(-1, 3), j0_fv.reshape(-1, 3)], axis=1)
    dest_f = np.searchsorted(ranges, f_vid, side="right") - 1
    dest_q = np.searchsorted(ranges, q_row, side="right") - 1
    send = [(a_vals[dest_v == r], t_vid[dest_t == r], t_node[dest_t == r], t_val[dest_t == r],
             f_vid[dest_f == r], f_fixed[dest_f == r], q_row[dest_q == r], q_col[dest_q == r],
             q_val[dest_q == r], q_fix[dest_q == r]) for r in range(comm.size)]
    recv = comm.alltoall(send)
    q_row = np.concatenate([r[6] for r in recv]).astype(np.int64)
    q_col = np.concatenate([r[7] for r in recv]).astype(np.int64)
    q_val = np.concatenate([r[8] for r in recv]).astype(float)
    q_fix = np.concatenate([r[9] for r in recv]).reshape(-1, 3).astype(bool)
    _, first = np.unique(np.stack([q_row, q_col]), axis=1, return_index=True)
    combination = RowCombination(q_row[first], q_col[first], q_val[first], q_fix[first]) \
        if basis == "dual_quadratic" else None
    a_vals = np.concatenate([r[0] for r in recv])
    a_vid = a_vals[:, 0].astype(np.int64)
    t_vid = np.concatenate([r[1] for r in recv]).astype(np.int64)
    t_node = np.concatenate([r[2] for r in recv]).astype(np.int64)
    t_val = np.concatenate([r[3] for r in recv]).reshape(-1, 3, 3)
    f_vid = np.concatenate([r[4] for r in recv]).astype(np.int64)
    f_fixed = np.concatenate([r[5] for r in recv]).reshape(-1, 3)
    verts, iv = np.unique(a_vid, return_inverse=True)
    n_v = verts.size
    m = np.bincount(iv, weights=a_vals[:, 1], minlength=n_v)
    sums = np.stack([np.bincount(iv, weights=a_vals[:, k], minlength=n_v)
                     for k in range(2, 8)], axis=1) if n_v else np.zeros((0, 6))
    n_bad = comm.allreduce(int(np.sum(m <= 0.0)), op=MPI.SUM)
    if n_bad:
        raise ValueError(f"{n_bad} vertices of contact surface {ctx.first_tag} have weight "
                         "int N_j dA <= 0; the nodal point set needs positive vertex weights")
    n_glob = imap.size_global
    key = np.searchsorted(verts, t_vid) * n_glob + t_node
    ukey, inv = np.unique(key, return_inverse=True)
    vals = np.stack([np.bincount(inv, weights=t_val.reshape(-1, 9)[:, k], minlength=ukey.size)
                     for k in range(9)], axis=1).reshape(-1, 3, 3) if ukey.size else \
        np.zeros((0, 3, 3))
    kv, kn = ukey // n_glob, ukey % n_glob
    if basis != "standard":  # biorthogonality: the other first-surface DOFs vanish (round-off)
        big = np.abs(vals).reshape(-1, 9).max(axis=1, initial=0.0) > 1e-12 * m[kv]
        ukey, vals, kv, kn = ukey[big], vals[big], kv[big], kn[big]
    counts = np.bincount(kv, minlength=n_v)
    width = int(counts.max(initial=1))
    starts = np.cumsum(counts) - counts
    col = np.arange(ukey.size) - starts[kv]
    A = np.zeros((n_v, 3, width, 3))
    A[kv, :, col, :] = vals
    nodes = np.empty((n_v, width), dtype=np.int64)
    nodes[:] = kn[starts][:, None] if n_v else 0
    nodes[kv, col] = kn
    pad = np.ones((n_v, width), dtype=bool)
    pad[kv, col] = False
    # a component fixed at the vertex is a mirror plane: the vertex's patch is half of a
    # symmetric one whose weighted jump and normal have no component along it
    hits = np.zeros((n_v, 3))
    np.add.at(hits, np.searchsorted(verts, f_vid), f_fixed.astype(float))
    fixed = hits > 0.0
    A[fixed] = 0.0
    sums[:, :3][fixed] = 0.0
    sums[:, 3:][fixed] = 0.0
    # vertex frames and coordinates
    normal = sums[:, :3] / np.maximum(np.linalg.norm(sums[:, :3], axis=1), 1e-300)[:, None]
    x = V.tabulate_dof_coordinates()[(verts - r0).astype(np.int64)].reshape(n_v, 3)
    frames, _ = local_frames(comm, x, normal, ctx.grain)
    B = np.einsum("vai,vikc->vakc", frames, A).reshape(n_v, 3, 3 * width) / m[:, None, None]
    j0 = np.einsum("vai,vi->va", frames, sums[:, 3:]) / m[:, None]
    shape = 1.0 if basix_cell(V.mesh) == basix.CellType.hexahedron else np.sqrt(3.0) / 2.0
    return NodalPoints(vertex=verts, x=x, weights=m, frames=frames, jump0=j0, B=B,
                       nodes=nodes, pad=pad, combination=combination,
                       spacing=np.sqrt(m / shape))


class VertexJumpOperator(JumpOperator):
    """The jump operator at the vertex points: one group per vertex (one point slot), its DOFs
    the union of those of its facets and their partners, padded with zero columns.

    Args:
        V: the displacement space; nodal: the vertex points; bcs, global_dofs: Dirichlet DOFs
            (``JumpOperator.set_dirichlet_dofs``).
    """

    def __init__(self, V, nodal: NodalPoints, bcs: Sequence = (), global_dofs=None):
        self.V = V
        self.comm = V.mesh.comm
        n_v, _, nd = nodal.B.shape
        self.gap0 = np.zeros(n_v)
        self.keys = None
        self.n_remote_partners = 0
        self.n_groups, self.nqs = n_v, 1
        self._B = np.ascontiguousarray(nodal.B)
        self._Bf = self._B
        self._BfT = np.ascontiguousarray(np.swapaxes(self._B, 1, 2))
        self._point_slot = np.arange(n_v, dtype=np.int64)
        self.own_slot = np.ones(n_v, dtype=bool)
        self._identity_slots = True
        self.pair_nodes = nodal.nodes
        self._pair_dofs = (3 * nodal.nodes[:, :, None] + np.arange(3)).reshape(n_v, nd)
        self._pad = np.repeat(nodal.pad, 3, axis=1)
        self.n_points = n_v
        self._communication()
        self.set_dirichlet_dofs(global_dofs, bcs)

    def set_dirichlet_dofs(self, global_dofs=None, bcs: Sequence = ()) -> None:
        """As ``JumpOperator.set_dirichlet_dofs``; padding columns are never assembled."""
        super().set_dirichlet_dofs(global_dofs, bcs)
        rows = np.array(self._rows)
        rows[self._pad] = -1
        self._rows = rows.astype(PETSc.IntType)


class NodalContactInterface(ContactInterface):
    """:class:`~rough_contact.fem.contact.ContactInterface` whose law is evaluated at the
    vertices of the first surface on mortar-weighted jumps (module docstring): one point, one
    constraint per surface vertex, so ``AugmentedLagrangian`` gives exact contact and stick
    without locking on P1, P2, Q1 and Q2, with the conforming, mortar, projection and rigid
    pairings. Same arguments as ``ContactInterface``; ``quadrature_degree`` sets the rule the
    vertex integrals are computed with (the pairing's points). Small sliding only.

    Per-point queries (``point_fields``, ``weights``, ``frames``, ``points``) are per vertex
    (weights m_j, which sum to the nominal area); the per-facet output
    (``rough_contact.io.interface_output``) is not available on vertex points.

    Attributes (besides ``ContactInterface``'s):
        quadrature_points: the pairing's points the vertex integrals were computed from.
        nodal: the :class:`NodalPoints` of this rank.

    Raises:
        ValueError: ``sliding`` other than ``"small"`` (the vertex rows are built once).
    """

    _constraints_per_point = False

    def __init__(self, V, facet_tags, first_tag, second_tag=None, basis: str = "standard",
                 **kwargs):
        if basis not in BASES:
            raise ValueError(f"basis = {basis!r} is invalid: 'standard' (the vertex functions "
                             "N_j), 'dual' (their biorthogonal basis) or 'dual_quadratic' (a "
                             "point at every node of P2/Q2, the quadratic dual basis)")
        self.basis = basis
        sliding = kwargs.get("sliding", "small")
        if sliding != "small":
            raise ValueError(f"sliding = {sliding!r} is invalid for the nodal point set: only "
                             "'small' (the vertex rows are built once at set-up)")
        enforcement = kwargs.get("enforcement")
        if isinstance(enforcement, SemismoothNewton):
            degree = V.element.basix_element.degree
            if (basis, degree) not in (("dual", 1), ("dual_quadratic", 2)):
                raise ValueError(
                    f"the semismooth Newton enforcement condenses the tractions through a "
                    f"dual basis: basis = {basis!r} with displacement degree {degree}; it "
                    "needs basis = 'dual' on P1/Q1 or basis = 'dual_quadratic' on P2/Q2")
        super().__init__(V, facet_tags, first_tag, second_tag, **kwargs)
        self.newton_updates = 0      # multiplier updates inside Newton iterations (all solves)
        self._condensation = None    # built at the first condensed_matrix (Dirichlet rows final)
        self._condensed_iterate = None

    def _point_set(self, ctx: SurfaceContext, bcs: Sequence) -> JumpOperator:
        quad = JumpOperator(ctx.V, self.paired, bcs=bcs)
        self.quadrature_points = self.paired
        self.nodal = nodal_points(ctx, self.paired, quad, self.basis)
        nodal = self.nodal
        n_v = nodal.vertex.size
        self.paired = PairedPoints(
            facets=np.zeros(0, dtype=np.int32), n_qp=1, x=nodal.x, weights=nodal.weights,
            frames=nodal.frames, jump0=nodal.jump0, N1=np.zeros((n_v, 1, 0)),
            nodes1=nodal.vertex[:, None], partners=None, name="nodal")
        return VertexJumpOperator(ctx.V, nodal, bcs=bcs)

    @property
    def point_spacing(self) -> np.ndarray:
        """(n_v,) the vertex spacing h_j of :attr:`NodalPoints.spacing` [mm]."""
        return self.nodal.spacing

    def updates_in_newton(self) -> bool:
        """Whether the enforcement updates the multipliers inside the Newton iteration
        (``NewtonAugmentedLagrangian``; the solver's ``NewtonIterationHook``)."""
        return isinstance(self.enforcement, NewtonAugmentedLagrangian)

    def newton_iteration(self, iteration: int, residual: float, first: float) -> bool:
        """The Newton solver's per-iteration hook (``rough_contact.solver.snes.
        NewtonIterationHook``; collective): with ``NewtonAugmentedLagrangian``, from Newton
        iteration ``first_iteration`` on and at iterates whose residual norm ``residual`` is at
        most ``residual_ratio`` x the solve's first one (``first``), lambda <- the tractions
        of the last evaluation (the current iterate: the solver evaluates the residual at an
        iterate before starting the iteration from it) if that moves the multipliers by more
        than the tolerance (largest change over all vertices and ranks / largest traction
        magnitude). Not during a penalty continuation's softened solves. Returns whether the multipliers changed (the
        residual must be evaluated again); counts the updates in ``newton_updates``."""
        enf = self.enforcement
        if (not isinstance(enf, NewtonAugmentedLagrangian) or self._softened is not None
                or iteration < enf.first_iteration or self._last is None
                or residual > enf.residual_ratio * first):
            return False
        res = self._last
        update = enf.update(self.history.multipliers, res)
        top = np.zeros(2)
        if update.change.size:
            top[:] = update.change.max(), np.linalg.norm(res.traction, axis=1).max()
        self.comm.Allreduce(MPI.IN_PLACE, top, op=MPI.MAX)
        rel = top[0] / top[1] if top[1] > 0.0 else 0.0
        if rel <= enf.tolerance:
            return False
        self.history.set_multipliers(update.multipliers)
        self._last = None      # the solver evaluates again; the Newton-step memo is kept
        self.newton_updates += 1
        return True

    # ------------------------------------------------------------ semismooth Newton
    def condenses(self) -> bool:
        """Whether the tractions are condensed (``SemismoothNewton``;
        ``rough_contact.fem.condensation.CondensedInterface``)."""
        return isinstance(self.enforcement, SemismoothNewton)

    def condensed_matrix(self, K: PETSc.Mat) -> PETSc.Mat:
        """A Jacobian matrix with the condensed pattern (collective; builds the condensation
        with the Dirichlet rows known now)."""
        mu, rn, rt = self.enforcement.parameters(self.law)
        self._condensation = DualCondensation(self.V, self.nodal, self.operator._rows, mu, rn,
                                              rt, K)
        return self._condensation.matrix(K)

    def condense_residual(self, u, b: PETSc.Vec) -> None:
        """b = F_b(u) (assembled, Dirichlet rows set) -> H(u) (collective; module
        ``rough_contact.fem.condensation``). The tractions, contact, slip, plastic slip and
        dissipation at u become the interface's last evaluation (its trial state)."""
        cond = self._condensation
        jump = self.jump(u)
        committed = self.history.law.committed
        t, ac = cond.residual(b, jump, committed.plastic_slip)
        cond.add_partner_rows(b)
        b.assemblyBegin()
        b.assemblyEnd()
        dslip = np.abs(ac.plastic_slip - committed.plastic_slip)
        contact = ac.contact & (t[:, 0] < 0.0)
        state = InterfaceState(ac.plastic_slip, committed.accumulated_slip + dslip,
                               committed.slip_path + np.linalg.norm(
                                   ac.plastic_slip - committed.plastic_slip, axis=1),
                               closed=contact)
        res = LawResult(traction=t, tangent=np.zeros((t.shape[0], 3, 3)), state=state,
                        dissipation=ac.dissipation, area_fraction=contact.astype(float),
                        contact=contact, slipping=ac.slipping & contact)
        self.history.law.update(res)
        self._last, self._last_jump = res, jump
        self._condensed_iterate = ac

    def condense_jacobian(self, K: PETSc.Mat, A: PETSc.Mat) -> None:
        """A = the condensed Jacobian at the iterate of the last :meth:`condense_residual`
        (collective)."""
        if self._condensed_iterate is None:
            raise RuntimeError("condense_jacobian before condense_residual: the semismooth "
                               "Newton's Jacobian is taken at the last residual's iterate")
        self._condensation.jacobian(self._condensed_iterate, A)

    def evaluate(self, u) -> LawResult:
        """``ContactInterface.evaluate``; with the semismooth Newton the last residual's
        result, which must be at u (the tractions come from the residual, not from the law)."""
        if not self.condenses():
            return super().evaluate(u)
        if self._last is None or not np.array_equal(self.jump(u), self._last_jump):
            raise RuntimeError("the semismooth Newton's tractions are those of the last "
                               "residual evaluation, which was not at this displacement")
        return self._last

    def _forget(self) -> None:
        super()._forget()
        self._condensed_iterate = None

    @property
    def softenable(self) -> bool:
        """``ContactInterface.softenable``; False with the semismooth Newton, which does not
        use the law's penalty (a penalty continuation would repeat the same solve)."""
        return not self.condenses() and super().softenable

    def describe(self) -> dict:
        """``ContactInterface.describe`` plus the point set (a checkpoint of the quadrature
        route is not resumed on vertex points, nor the other way round)."""
        out = dict(super().describe(), points="nodal")
        if self.basis != "standard":       # the standard basis keeps its old fingerprint
            out["basis"] = self.basis
        return out
