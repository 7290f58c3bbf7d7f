"""Rigid counter-surface pairing: the first surface against a rigid body (u_second = 0).

The rigid surface (:mod:`rough_contact.fem.rigid`: plane, sphere, cylinder, signed distance)
gives the initial gap and the normal at every point once, at set-up; the gap is linearised about
them (small sliding). Without a surface, the plane tangent to the first surface at every point
is taken (n = the facet normal, zero initial gap).

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from rough_contact.fem.pairing.base import (PairedPoints, SurfaceContext, first_surface_points,
                                            local_frames)
from rough_contact.fem.rigid import RigidSurface

__all__ = ["RigidPairing"]


@dataclass(frozen=True)
class RigidPairing:
    """Pairing with a rigid obstacle.

    Args:
        surface: the rigid counter-surface, or None for the tangent plane at every point.
    """

    surface: Optional[RigidSurface] = None

    def __post_init__(self):
        if self.surface is not None and not isinstance(self.surface, RigidSurface):
            raise TypeError(f"rigid ({type(self.surface).__name__}) must implement "
                            "rough_contact.fem.rigid.RigidSurface (gap_and_normal(x))")

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """The first surface's points, frames from the rigid normal and the initial gaps."""
        xq, normal, N1, weights = first_surface_points(ctx)
        R, jump0 = local_frames(ctx.comm, xq, normal, ctx.grain, self.surface)
        return PairedPoints(facets=ctx.geo1.facets, n_qp=ctx.rule.nq, x=xq.reshape(-1, 3),
                            weights=weights, frames=R, jump0=jump0, N1=N1,
                            nodes1=ctx.geo1.global_nodes, partners=None, name="rigid")
