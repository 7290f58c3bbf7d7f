"""What a pairing is: the contract between the contact search and the jump operator.

A pairing takes the two surfaces (the first one as a :class:`SurfaceContext`: its owned facets,
the facet rule and the grain direction) and yields :class:`PairedPoints`: the interface points
on the first surface with their area weights, local frames, initial jump offsets, the first
facets' basis values and global DOFs, and for every point the partner on the second surface
(:class:`Partners`: its facet's closure DOFs and their shape values at the partner point), or
no partner for a rigid counter-surface. :class:`rough_contact.fem.jump.JumpOperator` turns that
into the sparse map from displacement to jump.

A pairing that can follow large motions declares :class:`SlidingPairing`: after a converged
increment it is asked for new partners on the deformed surfaces (``repair``) and its state is
saved in checkpoints. Every call is collective (a rank without contact facets takes part with
empty arrays).

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Protocol, runtime_checkable

import numpy as np
from mpi4py import MPI

from rough_contact.fem.pairing.facets import FacetGeometry, FacetRule, cmap_element

__all__ = ["SurfaceContext", "Partners", "PairedPoints", "Pairing", "SlidingPairing",
           "Repaired", "first_surface_points", "local_frames"]


@dataclass(frozen=True)
class SurfaceContext:
    """The first contact surface as every pairing sees it.

    Attributes:
        V: the displacement space; comm: its communicator.
        facet_tags: facet MeshTags of the mesh; first_tag: the first surface's tag.
        n_owned_facets: owned facets of this rank (all tags).
        geo1: geometry of this rank's owned first-surface facets.
        rule: facet quadrature rule (Gauss of ``degree`` or the vertex rule).
        degree: degree of the Gauss rule (the mortar pairing integrates its pieces with it).
        grain: (3,) grain direction, projected on the facets to give the local x axis.
    """

    V: object
    comm: MPI.Comm
    facet_tags: object
    first_tag: int
    n_owned_facets: int
    geo1: FacetGeometry
    rule: FacetRule
    degree: int
    grain: np.ndarray


@dataclass(frozen=True)
class Partners:
    """The second surface seen from every point of the first one (n_f facets x nq points).

    Attributes:
        N2: (n_f, nq, n_close) partner facet's closure basis values at the partner point.
        nodes2: (n_f, nq, n_close) global block indices of the partner facet's closure DOFs.
        facet: (n_f, nq) partner facet id (an index into the gathered second surface).
        remote: (n_f, nq) bool: the partner facet is owned by another rank.
        gap0: (n_f, nq) initial normal gap [mm] (0 for conforming pairs).
        copy_of: (n_f, nq) or None: for slot-filling points (weight 0, see the mortar
            pairing) the index of the point they repeat (-1 for a point of its own).
    """

    N2: np.ndarray
    nodes2: np.ndarray
    facet: np.ndarray
    remote: np.ndarray
    gap0: np.ndarray
    copy_of: Optional[np.ndarray] = None


@dataclass(frozen=True)
class PairedPoints:
    """The interface points of this rank and their partners.

    Attributes:
        facets: (n_f,) local indices of the owned first-surface facets; point i lies on facet
            ``facets[i // n_qp]``.
        n_qp: point slots per facet.
        x: (n_f * n_qp, 3) reference coordinates of the points [mm].
        weights: (n_f * n_qp,) area each point represents [mm^2] (0 for slot-filling copies).
        frames: (n_f * n_qp, 3, 3) local axes, rows n, x, y in global components.
        jump0: (n_f * n_qp, 3) jump at zero displacement (initial gaps) [mm].
        N1: (n_f, n_qp, n_close) first facets' closure basis values at the points.
        nodes1: (n_f, n_close) global block indices of the first facets' closure DOFs.
        partners: the partners, or None for a rigid counter-surface (u_second = 0).
        name: the pairing that made them (``"conforming"``, ``"projection"``, ``"mortar"``,
            ``"rigid"``).
    """

    facets: np.ndarray
    n_qp: int
    x: np.ndarray
    weights: np.ndarray
    frames: np.ndarray
    jump0: np.ndarray
    N1: np.ndarray
    nodes1: np.ndarray
    partners: Optional[Partners]
    name: str

    @property
    def n_points(self) -> int:
        return self.x.shape[0]


@runtime_checkable
class Pairing(Protocol):
    """Finds the interface points and their partners (collective)."""

    def pair(self, ctx: SurfaceContext) -> PairedPoints:
        """The points of ``ctx``'s first surface and their partners."""
        ...


@dataclass(frozen=True)
class Repaired:
    """What a sliding pairing found on the deformed configuration (one re-pairing).

    Attributes:
        partners: the new partners with zero ``gap0`` (None for a rigid counter-surface). A
            point without partner (``active`` False) has partner facet -1, zero shape values
            and its own facet's closure nodes (no new matrix entries).
        gap: (n,) normal gap [mm] at the configuration it was found on (0 where inactive).
        frames: (n, 3, 3) new local frames (rows n, x, y), or None: unchanged.
        active: (n,) bool: the point has a partner (a point that slid off the second surface,
            or separated beyond the search radius, has none: zero traction).
        anchor: (n, 3) where the partner point (or the closest point of a rigid surface) is
            in the current configuration [mm]: the pairing's fixed point is reached when it
            stops moving.
    """

    partners: Optional[Partners]
    gap: np.ndarray
    frames: Optional[np.ndarray]
    active: np.ndarray
    anchor: np.ndarray


@runtime_checkable
class SlidingPairing(Protocol):
    """A pairing that finds new partners on the deformed surfaces (moderate or large sliding).

    Kinematics: every point keeps its place on the first surface and its law state; its current
    position is projected along its normal onto the deformed second surface (or onto a rigid
    surface moved by ``translation``). The interface keeps the tangential jump continuous
    across a change of partner, takes the normal gap from the re-pairing, and makes points
    without partner inactive.
    """

    def repair(self, u_local: np.ndarray, paired: PairedPoints,
               translation: np.ndarray) -> Repaired:
        """The pairing on the configuration deformed by ``u_local`` (this rank's displacement
        values with ghosts, (n_nodes, 3)), a rigid counter-surface translated by
        ``translation`` (3,) [mm] (collective)."""
        ...

    def state(self) -> object:
        """What a checkpoint must store to rebuild the current pairing (picklable)."""
        ...

    def restore(self, state: object) -> Optional[Repaired]:
        """Reinstate :meth:`state`; the pairing it describes (None: the set-up one)."""
        ...


def first_surface_points(ctx: SurfaceContext):
    """Quadrature points, area weights, unit normals and basis values on the first surface.

    Returns:
        xq: (n_f, nq, 3) physical points [mm]; normal: (n_f, nq, 3) outward unit normals;
        N1: (n_f, nq, n_close) values of the facet-closure basis functions at the points;
        weights: (n_f * nq,) area weights [mm^2].
    """
    geo1, rule = ctx.geo1, ctx.rule
    nq = rule.nq
    cmap_el = cmap_element(ctx.V.mesh)
    n_lf = rule.points.shape[0]
    tab_g = cmap_el.tabulate(1, rule.points.reshape(-1, 3)).reshape(4, n_lf, nq, cmap_el.dim)
    lf1 = geo1.local_facet
    phi_g = tab_g[0][lf1]  # (n_f, nq, n_gdof)
    dphi_g = np.moveaxis(tab_g[1:], 0, -1)[lf1]  # (n_f, nq, n_gdof, 3)
    xq = np.einsum("fqk,fki->fqi", phi_g, geo1.cell_nodes_x)
    J = np.einsum("fki,fqkd->fqid", geo1.cell_nodes_x, dphi_g)  # (n_f, nq, 3, 3)
    t12 = np.einsum("fqid,fde->fqie", J, rule.tangents[lf1])  # (n_f, nq, 3, 2)
    nvec = np.cross(t12[..., 0], t12[..., 1])
    dA = np.linalg.norm(nvec, axis=-1)
    # physical outward direction J^-T N_ref fixes the sign of t1 x t2
    n_ref = np.broadcast_to(rule.normals[lf1][:, None, :, None], J.shape[:-1] + (1,))
    outward = np.linalg.solve(np.swapaxes(J, -1, -2), n_ref)[..., 0]
    sign = np.sign(np.einsum("fqi,fqi->fq", nvec, outward))
    normal = sign[..., None] * nvec / dA[..., None]
    weights = (rule.weights[None, :] * dA).reshape(-1)
    element = ctx.V.element.basix_element
    phi = element.tabulate(0, rule.points.reshape(-1, 3))[0].reshape(n_lf, nq, element.dim)
    N1 = np.take_along_axis(phi[lf1], geo1.closure[lf1][:, None, :], axis=2)
    return xq, normal, N1, weights


def local_frames(comm, xq: np.ndarray, normal: np.ndarray, grain: np.ndarray,
                 rigid=None) -> tuple[np.ndarray, np.ndarray]:
    """Local frames (n, x, y) per point and the initial gap to a rigid surface (collective).

    Args:
        xq: (..., 3) points [mm]; normal: (..., 3) unit normals of the first surface.
        grain: (3,) grain direction; rigid: a rigid counter-surface or None.

    Returns:
        R: (n, 3 local, 3 global) rows n, x, y; jump0: (n, 3) with the rigid initial gap [mm].

    Raises:
        ValueError (every rank): the grain direction is (nearly) normal to the surface.
    """
    jump0 = np.zeros(xq.shape)
    if rigid is not None:
        g0, rnormal = rigid.gap_and_normal(xq.reshape(-1, 3))
        normal = -np.asarray(rnormal, dtype=float).reshape(normal.shape)
        jump0[..., 0] = np.asarray(g0, dtype=float).reshape(jump0.shape[:-1])
    gx = grain - np.einsum("...i,i->...", normal, grain)[..., None] * normal
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
    R = np.stack([normal, ex, ey], axis=-2)
    return R.reshape(-1, 3, 3), jump0.reshape(-1, 3)

