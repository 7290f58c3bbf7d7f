"""Projection pairing: every point of the first surface projected along its normal onto the
second surface (non-matching meshes), optionally again on the deformed surfaces after every
converged increment (moderate sliding).

The projection kernels are :func:`rough_contact.fem.pairing.geometry.project_points`
(vectorised Newton on the partner facets' own geometry map, exact on P2 faces); this module
gathers the second surface, checks that every point found a partner and turns the projection
into :class:`~rough_contact.fem.pairing.base.Partners`.

Units: mm.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.fem.pairing.base import (PairedPoints, Partners, Repaired, SurfaceContext,
                                            first_surface_points, local_frames)
from rough_contact.fem.pairing.facets import GatheredSurface, cmap_element, facet_set
from rough_contact.fem.pairing.geometry import project_points, project_points_from, tabulate
from rough_contact.validation import check_scalar

__all__ = ["ProjectionPairing", "SlidingProjectionPairing", "facet_areas"]


def facet_areas(vertex_x: np.ndarray) -> np.ndarray:
    """(n,) areas of the flat facets spanned by their vertices (n, 3 or 4, 3) in reference
    order (quadrilaterals numbered tensor-wise: 0, 1, 3, 2 around) [mm^2]: half the norm of the
    cross product of the two diagonals (of two edges for a triangle)."""
    if vertex_x.shape[0] == 0:
        return np.zeros(0)
    if vertex_x.shape[1] == 3:
        d1, d2 = vertex_x[:, 1] - vertex_x[:, 0], vertex_x[:, 2] - vertex_x[:, 0]
    else:
        d1, d2 = vertex_x[:, 3] - vertex_x[:, 0], vertex_x[:, 2] - vertex_x[:, 1]
    return 0.5 * np.linalg.norm(np.cross(d1, d2), axis=1)


class ProjectionPairing:
    """Non-matching pairing by normal projection, once at set-up (small sliding).

    Args:
        second_tag: facet tag of the second surface.
        search_radius: the largest accepted distance between a first-surface point and its
            partner along the normal [mm], > 0; default: the largest facet diameter of the first
            surface. Points without partner within it are an error.
    """

    def __init__(self, second_tag: int, search_radius: Optional[float] = None):
        if search_radius is not None:
            check_scalar("search_radius", search_radius, lo=0.0, unit="mm")
        self.second_tag = second_tag
        self.search_radius = search_radius
        self._ctx: Optional[SurfaceContext] = None
        self._second: Optional[GatheredSurface] = None

    def describe(self) -> dict:
        """Its options (``rough_contact.fingerprint.Describable``): what a checkpoint records."""
        return dict(second_tag=int(self.second_tag), search_radius=self.search_radius)

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """Set-up projection of the undeformed surfaces (collective).

        Raises:
            ValueError (on every rank): points without partner within the search radius, or
                whose only candidates face the wrong way (count, first coordinates, the
                nearest distance found).
        """
        xq, normal, N1, weights = first_surface_points(ctx)
        R, jump0 = local_frames(ctx.comm, xq, normal, ctx.grain)
        comm = ctx.comm
        n_f, nq = xq.shape[:2]
        self._ctx = ctx
        self._second = GatheredSurface.create(ctx.V, ctx.facet_tags, self.second_tag,
                                              ctx.n_owned_facets)
        if self.search_radius is None:
            vx1 = ctx.geo1.vertex_x
            diam = (np.linalg.norm(vx1[:, :, None] - vx1[:, None], axis=-1).max(initial=0.0)
                    if n_f else 0.0)
            self.search_radius = comm.allreduce(float(diam), op=MPI.MAX)
        x = xq.reshape(-1, 3)
        proj = project_points(x, R[:, 0, :], self._second.surface, cmap_element(ctx.V.mesh),
                              self.search_radius)
        self._check(proj, x)
        return PairedPoints(facets=ctx.geo1.facets, n_qp=nq, x=x, weights=weights, frames=R,
                            jump0=jump0, N1=N1, nodes1=ctx.geo1.global_nodes,
                            partners=self._partners(proj, (n_f, nq)), name="projection")

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _zero_gap(p: Partners) -> Partners:
        return Partners(N2=p.N2, nodes2=p.nodes2, facet=p.facet, remote=p.remote,
                        gap0=np.zeros(p.facet.shape), copy_of=p.copy_of)

    def _partners(self, proj, shape) -> Partners:
        """Partner data of a complete projection onto the gathered second surface."""
        comm = self._ctx.comm
        second = self._second
        owner2, lf2_all, nodes2_all = second.owner, second.local_facet, second.nodes
        n_close, closure = nodes2_all.shape[1], second.closure
        lf2 = lf2_all[proj.facet]
        phi2 = tabulate(self._ctx.V.element.basix_element, 0, proj.X_ref)[0]
        N2 = np.take_along_axis(phi2, closure[lf2], axis=1)
        return Partners(N2=N2.reshape(shape + (n_close,)),
                        nodes2=nodes2_all[proj.facet].reshape(shape + (n_close,)),
                        facet=proj.facet.reshape(shape),
                        remote=(owner2[proj.facet] != comm.rank).reshape(shape),
                        gap0=proj.distance.reshape(shape))

    def _check(self, proj, x, after=""):
        comm = self._ctx.comm
        first_tag, second_tag, search_radius = self._ctx.first_tag, self.second_tag, \
            self.search_radius
        missing = proj.facet < 0
        n_missing = comm.allreduce(int(missing.sum()), op=MPI.SUM)
        if n_missing:
            n_facing = comm.allreduce(int(proj.facing_failure.sum()), op=MPI.SUM)
            first = comm.allgather(x[missing][:3].tolist() if missing.any() else [])
            first = [p for r in first for p in r][:3]
            nearest = comm.allreduce(float(proj.nearest[missing].min(initial=np.inf)),
                                     op=MPI.MIN)
            n_total = comm.allreduce(x.shape[0], op=MPI.SUM)
            why = (f"{n_facing} of them only found facets of surface {second_tag} that face the "
                   "same way (the surfaces must face each other: check the tags and the "
                   "bodies they belong to); " if n_facing else "")
            found = (f"the nearest partner found along the normal of such a point is "
                     f"{nearest:.6g} mm away" if np.isfinite(nearest) else
                     "no facet of the second surface lies on their normals")
            # points whose normal meets no facet at all: beyond the second surface's edge,
            # where no search radius helps (a larger first surface)
            n_off = comm.allreduce(int((missing & ~np.isfinite(proj.nearest)).sum()),
                                   op=MPI.SUM)
            area1 = comm.allreduce(float(facet_areas(self._ctx.geo1.vertex_x).sum()),
                                   op=MPI.SUM)
            area2 = float(facet_areas(self._second.vertex_x).sum())   # gathered: global
            if n_off and area1 > area2 * (1.0 + 1e-9):
                advice = (
                    f"Surface {first_tag} ({area1:.6g} mm^2) is larger than surface "
                    f"{second_tag} ({area2:.6g} mm^2): {n_off} of these points lie beyond the "
                    f"edge of surface {second_tag}, where no search radius finds a partner. "
                    "Make the smaller surface the first contact surface (swap first_tag and "
                    "second_tag): every point of the first surface needs a partner")
            else:
                advice = ("Check that the surfaces overlap and face each other, or raise "
                          "search_radius")
            raise ValueError(
                f"{after}{n_missing} of {n_total} quadrature points of contact surface "
                f"{first_tag} have no partner on surface {second_tag} within the search "
                f"radius {search_radius:.6g} mm along their normal; {why}{found}; first "
                f"points: {first}. {advice}")


class SlidingProjectionPairing(ProjectionPairing):
    """The projection pairing redone on the deformed surfaces (a
    :class:`~rough_contact.fem.pairing.base.SlidingPairing`): at the start of every increment
    (moderate sliding) or until it stops changing within the increment (large sliding; the
    interface drives it). A point whose normal no longer meets the second surface within the
    search radius (it slid off its edge, or separated) is inactive until it finds one again.
    Needs a displacement space of the geometry's degree (the surfaces move exactly with u).
    """

    def __init__(self, second_tag: int, search_radius: Optional[float] = None):
        super().__init__(second_tag, search_radius)
        self._projection = None          # the last re-pairing's projection (None: set-up)

    # ------------------------------------------------------------------ sliding capability
    def repair(self, u_local: np.ndarray, paired: PairedPoints,
               translation: Optional[np.ndarray] = None) -> Repaired:
        """The pairing on the surfaces deformed by ``u_local`` (n_nodes, 3) (collective; see
        :class:`~rough_contact.fem.pairing.base.SlidingPairing`; ``translation`` is unused:
        the second surface moves with its own displacements)."""
        ctx, sec = self._ctx, self._second
        n_f, nq, n_close = paired.N1.shape
        x1 = paired.x + np.einsum("fqk,fki->fqi", paired.N1,
                                  u_local[ctx.geo1.local_nodes]).reshape(-1, 3)
        u2 = ctx.comm.allgather(u_local[sec.own_local_nodes])
        u2 = np.concatenate(u2).reshape(-1, n_close, 3) if u2 else np.zeros((0, n_close, 3))
        cell_x = sec.surface.cell_x.copy()
        rows = np.arange(cell_x.shape[0])[:, None]
        cell_x[rows, sec.closure[sec.local_facet]] += u2   # Lagrange: facet = its closure
        nv = sec.vertex_x.shape[1]
        surface = facet_set(ctx.V.mesh, cell_x, sec.local_facet, sec.vertex_x + u2[:, :nv])
        previous = (self._projection.facet if self._projection is not None
                    else paired.partners.facet.reshape(-1))
        proj = project_points_from(previous, x1, paired.frames[:, 0, :], surface,
                                   cmap_element(ctx.V.mesh), self.search_radius)
        self._projection = proj
        return self._repaired(proj, x1, paired.frames[:, 0, :])

    def _repaired(self, proj, x1: Optional[np.ndarray], normal: np.ndarray) -> Repaired:
        """The :class:`Repaired` of a projection (points without partner inactive)."""
        n_f, nq = self._ctx.geo1.facets.size, self._ctx.rule.nq
        active = proj.facet >= 0
        facet = np.where(active, proj.facet, 0)
        p = self._partners(replace(proj, facet=facet), (n_f, nq))
        shape = (n_f, nq)
        act = active.reshape(shape)
        own_nodes = np.broadcast_to(self._ctx.geo1.global_nodes[:, None, :], p.nodes2.shape)
        partners = Partners(N2=np.where(act[..., None], p.N2, 0.0),
                            nodes2=np.where(act[..., None], p.nodes2, own_nodes),
                            facet=np.where(act, p.facet, -1), remote=p.remote & act,
                            gap0=np.zeros(shape), copy_of=p.copy_of)
        gap = np.where(active, proj.distance, 0.0)
        anchor = None if x1 is None else x1 + gap[:, None] * normal
        return Repaired(partners=partners, gap=gap, frames=None, active=active, anchor=anchor)

    def state(self) -> object:
        """The last re-pairing's projection (None: the set-up pairing)."""
        return self._projection

    def restore(self, state: object) -> Optional[Repaired]:
        """Reinstate :meth:`state`; its pairing (``gap`` and ``anchor`` are not restored: the
        interface restores its jump offsets), or None for the set-up pairing."""
        self._projection = state
        if state is None:
            return None
        n = self._ctx.geo1.facets.size * self._ctx.rule.nq
        return self._repaired(state, None, np.zeros((n, 3)))
