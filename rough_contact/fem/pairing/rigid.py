"""Rigid counter-surface pairing: the first surface against a rigid body (u_second = its
prescribed translation, zero by default).

The rigid surface (:mod:`rough_contact.fem.rigid`: plane, sphere, cylinder, signed distance)
gives the initial gap and the normal at every point at set-up; :class:`RigidPairing` linearises
the gap about them (small sliding). Without a surface, the plane tangent to the first surface at
every point is taken (n = the facet normal, zero initial gap). :class:`SlidingRigidPairing`
evaluates gap and normal again on the current configuration (moderate and large sliding).

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.fem.pairing.base import (PairedPoints, Repaired, SurfaceContext,
                                            first_surface_points, local_frames)
from rough_contact.fem.rigid import RigidSurface

__all__ = ["RigidPairing", "SlidingRigidPairing"]


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


class SlidingRigidPairing:
    """A rigid counter-surface seen from the current configuration (a
    :class:`~rough_contact.fem.pairing.base.SlidingPairing`): at every re-pairing the signed
    distance g of x + u to the rigid surface moved by its translation, and the rigid normal at
    the closest point, give the gap and the frame (n = -rigid normal, x = grain projected,
    y = n x x). The interface linearises the gap about the configuration of the last
    re-pairing; with ``sliding="large"`` it re-pairs until the gap and normal stop changing,
    so the converged gap is the distance in the current configuration.

    Args:
        surface: the rigid counter-surface (:class:`rough_contact.fem.rigid.RigidSurface`).
    """

    def __init__(self, surface: RigidSurface):
        if not isinstance(surface, RigidSurface):
            raise TypeError(f"rigid ({type(surface).__name__}) must implement "
                            "rough_contact.fem.rigid.RigidSurface (gap_and_normal(x))")
        self.surface = surface
        self._ctx: Optional[SurfaceContext] = None
        self._frames: Optional[np.ndarray] = None     # the last re-pairing's (None: set-up)

    def describe(self) -> dict:
        """Its options (``rough_contact.fingerprint.Describable``)."""
        return dict(surface=self.surface)

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """The set-up pairing (that of :class:`RigidPairing`)."""
        self._ctx = ctx
        paired = RigidPairing(self.surface).pair(ctx)
        return paired

    def repair(self, u_local: np.ndarray, paired: PairedPoints,
               translation: np.ndarray) -> Repaired:
        """Gap, frames and closest points on the current configuration (no communication
        beyond a check of the grain direction)."""
        ctx = self._ctx
        x1 = paired.x + np.einsum("fqk,fki->fqi", paired.N1,
                                  u_local[ctx.geo1.local_nodes]).reshape(-1, 3)
        gap, nu = self.surface.gap_and_normal(x1 - np.asarray(translation, dtype=float))
        gap, nu = np.asarray(gap, dtype=float), np.asarray(nu, dtype=float)
        n = -nu
        grain = ctx.grain
        gx = grain - (n @ grain)[:, None] * n
        gnorm = np.linalg.norm(gx, axis=1)
        n_bad = ctx.comm.allreduce(int(np.sum(gnorm < 1e-6 * np.linalg.norm(grain))),
                                   op=MPI.SUM)
        if n_bad:
            raise ValueError(f"grain_direction {grain.tolist()} is (nearly) normal to the rigid "
                             f"surface at {n_bad} points; choose a direction lying in it")
        ex = gx / gnorm[:, None]
        frames = np.stack([n, ex, np.cross(n, ex)], axis=1)
        self._frames = frames
        return Repaired(partners=None, gap=gap, frames=frames,
                        active=np.ones(gap.shape, dtype=bool), anchor=x1 - gap[:, None] * nu)

    def state(self) -> object:
        """The last re-pairing's frames (None: the set-up pairing)."""
        return self._frames

    def restore(self, state: object) -> Optional[Repaired]:
        """Reinstate :meth:`state`: its frames (gap and anchor not restored)."""
        self._frames = state
        if state is None:
            return None
        n = state.shape[0]
        return Repaired(partners=None, gap=np.zeros(n), frames=np.array(state),
                        active=np.ones(n, dtype=bool), anchor=np.zeros((n, 3)))
