"""Conforming pairing: the two surfaces carry the same surface mesh, facet to facet.

Every first facet finds its partner among an all-gathered copy of the second surface (a
surface-sized message) by a KD-tree on facet centroids, then the vertex permutation by
distance. The partner point reuses the barycentric (or bilinear) vertex weights of the point
on the first facet, which is the same physical point for affine facets and for quadratic facets
whose shared edges carry the same mid-nodes: node-to-node kinematics, exact. DOLFINx's
bounding-box trees are not used: on 0.5.2 they see only the rank's own part of the mesh.

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI
from scipy.spatial import cKDTree

from rough_contact.fem.pairing.base import (PairedPoints, Partners, SurfaceContext,
                                            first_surface_points, local_frames)
from rough_contact.fem.pairing.facets import FacetGeometry, owned_tagged_facets
from rough_contact.validation import check_scalar

__all__ = ["ConformingPairing"]


@dataclass(frozen=True)
class ConformingPairing:
    """Facet-to-facet pairing of two surfaces meshed alike.

    Args:
        second_tag: facet tag of the second surface.
        match_tolerance: vertex matching tolerance relative to the facet size [-], > 0.
        strict: True: a facet without match is an error; False: :meth:`match` returns None
            (the ``"auto"`` pairing then projects instead).
    """

    second_tag: int
    match_tolerance: float = 1e-6
    strict: bool = True

    def __post_init__(self):
        check_scalar("match_tolerance", self.match_tolerance, lo=0.0)

    def pair(self, ctx: SurfaceContext) -> Optional[PairedPoints]:
        """The points and their conforming partners (collective); None if some facet has no
        match and ``strict`` is False.

        Raises:
            ValueError (every rank): some facet has no match and ``strict`` is True.
        """
        partners = self.match(ctx)
        if partners is None:
            return None
        xq, normal, N1, weights = first_surface_points(ctx)
        R, jump0 = local_frames(ctx.comm, xq, normal, ctx.grain)
        return PairedPoints(facets=ctx.geo1.facets, n_qp=ctx.rule.nq, x=xq.reshape(-1, 3),
                            weights=weights, frames=R, jump0=jump0, N1=N1,
                            nodes1=ctx.geo1.global_nodes, partners=partners, name="conforming")

    def match(self, ctx: SurfaceContext) -> Optional[Partners]:
        """Conforming partner facets on the second surface, from an all-gathered copy of it
        (collective)."""
        comm, geo1, rule = ctx.comm, ctx.geo1, ctx.rule
        n_f, nq, nv = geo1.facets.size, rule.nq, rule.lam.shape[1]
        element = ctx.V.element.basix_element
        n_close = geo1.closure.shape[1]
        geo2 = FacetGeometry(ctx.V, owned_tagged_facets(ctx.facet_tags, self.second_tag,
                                                        ctx.n_owned_facets, comm))
        gathered = comm.allgather((geo2.vertex_x, geo2.local_facet, geo2.global_nodes))
        owner2 = np.concatenate(
            [np.full(g[1].size, r, dtype=np.int64) for r, g in enumerate(gathered)]
        )
        vx2 = np.concatenate([g[0] for g in gathered]).reshape(-1, nv, 3)
        lf2_all = np.concatenate([g[1] for g in gathered]).astype(np.int64)
        nodes2_all = np.concatenate([g[2] for g in gathered]).reshape(-1, n_close)
        vx1 = geo1.vertex_x  # (n_f, nv, 3)
        size = np.linalg.norm(vx1[:, 1] - vx1[:, 0], axis=1) if n_f else np.zeros(0)
        tol = self.match_tolerance * size
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
        if n_bad and not self.strict:
            return None
        if n_bad:
            example = comm.allgather(vx1[~ok].mean(axis=1)[0].tolist() if np.any(~ok) else None)
            example = next(e for e in example if e is not None)
            n_total = comm.allreduce(n_f, op=MPI.SUM)
            raise ValueError(
                f"{n_bad} of {n_total} facets of contact surface {ctx.first_tag} have no "
                f"matching facet on surface {self.second_tag} (vertex tolerance "
                f"{self.match_tolerance} x facet size), e.g. the facet with centroid {example}; "
                "the interface must be conforming (same surface mesh on both sides)"
            )
        lf2 = lf2_all[partner]
        # barycentric reuse: the point with weights lam on the first facet's vertices
        X2 = np.einsum(
            "qi,fid->fqd", rule.lam, rule.vertices[lf2][np.arange(n_f)[:, None], perm]
        )  # (n_f, nq, 3)
        phi2 = (
            element.tabulate(0, X2.reshape(-1, 3))[0].reshape(n_f, nq, element.dim)
            if n_f
            else np.zeros((0, nq, element.dim))
        )
        closure2 = geo1.closure[lf2]  # same element on both sides
        N2 = np.take_along_axis(phi2, closure2[:, None, :], axis=2)
        shape = (n_f, nq)
        return Partners(
            N2=N2, nodes2=np.broadcast_to(nodes2_all[partner][:, None, :], shape + (n_close,)),
            facet=np.broadcast_to(partner[:, None], shape),
            remote=np.broadcast_to((owner2[partner] != comm.rank)[:, None], shape),
            gap0=np.zeros(shape))
