"""Mortar (segment-to-segment) pairing: the first facets clipped by the second surface's facets
projected on their planes, a triangle rule on every piece.

Integrating over the pieces makes the interface integrals exact for piecewise-polynomial jumps
across non-matching meshes (the patch test passes at round-off, docs/nonmatching.md), where the
Gauss-point projection integrates a kinked partner field with a rule that does not see the
kinks. The clipping itself is :func:`rough_contact.fem.pairing.geometry.mortar_points`.

Every first facet gets the same number of point slots (the largest count on any rank): a facet
with fewer pieces repeats its first point with weight 0 (``Partners.copy_of``); the jump
operator gives such copies the slot of the point they repeat, so they cost nothing in the
assembly and are not counted as interface points.

Units: mm.
"""

from __future__ import annotations

from typing import Optional

import basix
import numpy as np
from mpi4py import MPI

from rough_contact.fem.pairing.base import PairedPoints, Partners, SurfaceContext, local_frames
from rough_contact.fem.pairing.facets import (GatheredSurface, basix_cell, cmap_element,
                                              facet_cell, facet_set)
from rough_contact.fem.pairing.geometry import (_newton_on_facets, cyclic_order, mortar_points,
                                                tabulate)
from rough_contact.validation import check_scalar

__all__ = ["MortarPairing"]


class MortarPairing:
    """Segment-to-segment pairing (needs the Gauss rule; the first surface must lie within the
    second one: make the smaller surface the first).

    Args:
        second_tag: facet tag of the second surface.
        search_radius: largest accepted normal distance to the partner [mm], > 0; default the
            square root of the largest first-facet area.
    """

    def __init__(self, second_tag: int, search_radius: Optional[float] = None):
        if search_radius is not None:
            check_scalar("search_radius", search_radius, lo=0.0, unit="mm")
        self.second_tag = second_tag
        self.search_radius = search_radius

    def describe(self) -> dict:
        """Its options (``rough_contact.fingerprint.Describable``): what a checkpoint records."""
        return dict(second_tag=int(self.second_tag), search_radius=self.search_radius)

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """Points on the pieces and their partners (collective).

        Raises:
            ValueError (on every rank): a part of the first surface is not covered by the
                second surface (uncovered area, facet count, first centroid), or points without
                a partner along their normal.
        """
        comm, geo1 = ctx.comm, ctx.geo1
        msh = ctx.V.mesh
        second_tag = self.second_tag
        element = ctx.V.element.basix_element
        cmap = cmap_element(msh)
        second = GatheredSurface.create(ctx.V, ctx.facet_tags, second_tag, ctx.n_owned_facets)
        first = facet_set(msh, geo1.cell_nodes_x, geo1.local_facet, geo1.vertex_x)
        pts, wts = basix.make_quadrature(basix.CellType.triangle, ctx.degree)
        mp = mortar_points(first, geo1.vertex_x, second.surface, second.vertex_x, pts, wts)
        n_f = geo1.facets.size
        vx, plane_n, area = self._check_coverage(ctx, geo1, mp, n_f)
        # points on the first facets: reference coordinates, normals, basis values
        plane_n = plane_n / np.maximum(np.linalg.norm(plane_n, axis=1), 1e-300)[:, None]
        X1, _, conv1, _, _ = _newton_on_facets(mp.x, plane_n[mp.facet1], first, mp.facet1, cmap)
        order = np.argsort(mp.facet1, kind="stable")
        counts = np.bincount(mp.facet1, minlength=n_f)
        nq = comm.allreduce(int(counts.max(initial=1)), op=MPI.MAX)
        starts = np.cumsum(counts) - counts
        slot = np.arange(nq)[None, :]
        take = order[np.minimum(starts[:, None] + slot, starts[:, None] + counts[:, None] - 1)]
        real = slot < counts[:, None]                       # (n_f, nq)
        take = take.reshape(-1) if n_f else np.zeros(0, dtype=np.int64)
        X1 = X1[take]
        weights = np.where(real.reshape(-1), mp.weight[take], 0.0)
        lf1 = np.repeat(geo1.local_facet, nq)
        cell_x = np.repeat(geo1.cell_nodes_x, nq, axis=0)
        tab = tabulate(cmap, 1, X1)
        xq = np.einsum("pk,pki->pi", tab[0], cell_x)
        J = np.einsum("pki,pkd->pid", cell_x, np.moveaxis(tab[1:], 0, -1))
        ref_normals = basix.cell.facet_outward_normals(basix_cell(msh))
        outward = np.linalg.solve(np.swapaxes(J, 1, 2), ref_normals[lf1][:, :, None])[..., 0] \
            if X1.shape[0] else np.zeros((0, 3))
        normal = outward / np.maximum(np.linalg.norm(outward, axis=1), 1e-300)[:, None]
        phi = tabulate(element, 0, X1)[0]
        N1 = np.take_along_axis(phi, geo1.closure[lf1], axis=1)
        # partner points on the second facets, along the first normal
        f2 = mp.facet2[take]
        X2, gap0, conv2, _, facing = _newton_on_facets(xq, normal, second.surface, f2, cmap)
        search_radius = self.search_radius
        if search_radius is None:
            search_radius = comm.allreduce(float(np.sqrt(area.max(initial=0.0))), op=MPI.MAX)
        failed = ~(conv1[take] & conv2 & facing)
        far = ~failed & (np.abs(gap0) > search_radius)
        n_failed, n_far = comm.allreduce(np.array([failed.sum(), far.sum()]), op=MPI.SUM)
        if n_failed or n_far:
            dist = comm.allreduce(float(np.abs(gap0[far]).max(initial=0.0)), op=MPI.MAX)
            raise ValueError(
                f"{n_failed + n_far} mortar points of contact surface {ctx.first_tag} have no "
                f"partner on surface {second_tag}: {n_failed} whose partner facet faces the "
                f"same way or cannot be reached along their normal, {n_far} farther than the "
                f"search radius {search_radius:.6g} mm (up to {dist:.6g} mm); the surfaces "
                "must face each other and touch (check the tags and the bodies they belong "
                "to)")
        phi2 = tabulate(element, 0, X2)[0]
        N2 = np.take_along_axis(phi2, second.closure[second.local_facet[f2]], axis=1)
        shape = (n_f, nq)
        n_close = N1.shape[1]
        partners = Partners(N2=N2.reshape(shape + (n_close,)),
                            nodes2=second.nodes[f2].reshape(shape + (n_close,)),
                            facet=f2.reshape(shape),
                            remote=(second.owner[f2] != comm.rank).reshape(shape),
                            gap0=gap0.reshape(shape),
                            copy_of=np.where(real, -1, np.arange(n_f)[:, None] * nq))
        R, jump0 = local_frames(comm, xq.reshape(shape + (3,)), normal.reshape(shape + (3,)),
                                ctx.grain)
        return PairedPoints(facets=geo1.facets, n_qp=nq, x=xq, weights=weights, frames=R,
                            jump0=jump0, N1=N1.reshape(shape + (n_close,)),
                            nodes1=geo1.global_nodes, partners=partners, name="mortar")

    def _check_coverage(self, ctx, geo1, mp, n_f):
        """Every first facet's area must be matched by overlaps (collective)."""
        comm = ctx.comm
        vx = geo1.vertex_x[:, cyclic_order(geo1.vertex_x.shape[1])]
        plane_n = np.cross(vx[:, 1] - vx[:, 0], vx[:, -1] - vx[:, 0]) if n_f else np.zeros((0, 3))
        area = np.linalg.norm(plane_n, axis=1) * (
            0.5 if facet_cell(ctx.V.mesh) == basix.CellType.triangle else 1.0)
        covered = np.bincount(mp.facet1, weights=mp.weight, minlength=n_f)
        gap_area = np.clip(area - covered, 0.0, None)
        bad = gap_area > 1e-8 * area
        n_bad = comm.allreduce(int(bad.sum()), op=MPI.SUM)
        if n_bad:
            lost = comm.allreduce(float(gap_area[bad].sum()), op=MPI.SUM)
            total = comm.allreduce(float(area.sum()), op=MPI.SUM)
            first_c = comm.allgather(vx[bad].mean(axis=1)[0].tolist() if bad.any() else None)
            first_c = next(c for c in first_c if c is not None)
            raise ValueError(
                f"{n_bad} facets of contact surface {ctx.first_tag} are not fully covered by "
                f"surface {self.second_tag}: {lost:.6g} of {total:.6g} mm^2 have no partner "
                f"(first such facet centred at {first_c}); with pairing='mortar' the first "
                "surface must lie within the second one (make the smaller surface the first)")
        return vx, plane_n, area
