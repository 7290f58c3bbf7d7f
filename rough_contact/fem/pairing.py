"""Non-matching pairing: project the first surface's quadrature points onto the second surface.

Used by :class:`rough_contact.fem.contact.ContactInterface` when the two contact surfaces are
meshed independently (``pairing="projection"``, or ``"auto"`` when the surfaces do not match
facet for facet).

Decisions (docs/nonmatching.md):

* **Projection along the first surface's normal.** Every quadrature point x of the first
  surface, with unit normal n (towards the second body), finds the point of the second surface
  on the line x + t n: X2(xi) = x + t n, solved for the facet coordinates xi and the signed
  distance t (> 0: the second surface lies ahead, i.e. the initial gap is open). Mortar codes
  use the same normal projection; it keeps the pairing symmetric in the sense that the jump's
  normal component is measured along the normal the law uses. A closest-point projection
  would coincide on flat interfaces.
* **Exact on curved geometry.** X2 is the second facet's own geometry map (P1 or P2 cells,
  tetrahedra or hexahedra): the point is found by a vectorised Newton iteration in the facet's
  reference coordinates (3 x 3 systems, quadratic convergence; one step on flat P1 facets).
* **Candidates** are the ``n_candidates`` second facets whose centroids are nearest to x
  (KD-tree of an all-gathered copy of the second surface, as for conforming pairs); a candidate
  is accepted if Newton converged, xi lies in the facet (tolerance ``inside_tol``), |t| is
  within the search radius and the two surfaces face each other there (n . n2 < 0, n2 the
  second body's outward normal). Among accepted candidates the smallest |t| wins.
* **Small sliding**: pairing is done once at set-up (the paper's kinematics); the initial
  normal gap t is kept as the jump's offset g0, the initial tangential offset is zero.

All functions are pure numpy (no MPI): the caller gathers the second surface and reduces the
errors over ranks.

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["SecondSurface", "Projection", "project_points"]


@dataclass(frozen=True)
class SecondSurface:
    """An all-gathered copy of the second contact surface (every rank holds all of it).

    Attributes:
        cell_x: (n2, n_gdof, 3) geometry node coordinates of each facet's cell [mm].
        v0: (n2, 3) reference-cell coordinates of each facet's first vertex.
        tangents: (n2, 3, 2) reference-cell edge vectors (v1 - v0, v2 - v0) of each facet.
        ref_normal: (n2, 3) reference outward normal of each facet's local facet.
        triangle: True for triangular facets (tetrahedra), False for quadrilaterals.
        centroid: (n2, 3) physical facet centroids (vertex means) [mm].
    """

    cell_x: np.ndarray
    v0: np.ndarray
    tangents: np.ndarray
    ref_normal: np.ndarray
    triangle: bool
    centroid: np.ndarray

    @property
    def size(self) -> int:
        return self.cell_x.shape[0]


@dataclass(frozen=True)
class Projection:
    """Result of :func:`project_points` for n points.

    Attributes:
        facet: (n,) index of the partner facet in the :class:`SecondSurface` (-1: none).
        X_ref: (n, 3) the partner point in the partner cell's reference coordinates.
        distance: (n,) signed distance t along the first normal [mm] (the initial gap).
        nearest: (n,) for points without partner: |t| of the closest converged candidate
            whose xi lies in its facet, regardless of radius and facing (inf if none) [mm].
        facing_failure: (n,) bool: a candidate within the radius was rejected only because the
            surfaces do not face each other there.
    """

    facet: np.ndarray
    X_ref: np.ndarray
    distance: np.ndarray
    nearest: np.ndarray
    facing_failure: np.ndarray


def project_points(x: np.ndarray, normal: np.ndarray, surface: SecondSurface, cmap,
                   search_radius: float, n_candidates: int = 12, inside_tol: float = 1e-8,
                   max_iter: int = 25, chunk: int = 20000) -> Projection:
    """Project points along their normals onto the second surface (vectorised).

    Args:
        x: (n, 3) points of the first surface [mm].
        normal: (n, 3) unit normals at x, pointing towards the second body.
        surface: the gathered second surface.
        cmap: the basix coordinate element of the mesh (``tabulate(1, X)``).
        search_radius: largest accepted |t| [mm].
        n_candidates: second facets tried per point (nearest centroids).
        inside_tol: tolerance on the facet coordinates for "inside the facet".
        max_iter: Newton iterations.

        chunk: points projected at once (bounds the memory of the candidate arrays).

    Returns:
        The :class:`Projection`.
    """
    if x.shape[0] > chunk:
        parts = [_project(x[i:i + chunk], normal[i:i + chunk], surface, cmap, search_radius,
                          n_candidates, inside_tol, max_iter)
                 for i in range(0, x.shape[0], chunk)]
        return Projection(*(np.concatenate([getattr(p, f) for p in parts])
                            for f in Projection.__dataclass_fields__))
    return _project(x, normal, surface, cmap, search_radius, n_candidates, inside_tol, max_iter)


def _newton_on_facets(xp, nrm, surface, c, cmap, max_iter=25, inside_tol=1e-8):
    """Solve X_c(xi) = xp + t nrm on facets c (vectorised over m = len(c) pairs).

    Returns:
        X_ref (m, 3) reference-cell point, t (m,), converged (m,), inside (m,), facing (m,)
        (the facet's body faces along -nrm there: n2 . nrm < 0).
    """
    m = c.size
    Xn, v0, T = surface.cell_x[c], surface.v0[c], surface.tangents[c]
    centre = np.array([1.0 / 3.0, 1.0 / 3.0]) if surface.triangle else np.array([0.5, 0.5])
    xi = np.broadcast_to(centre, (m, 2)).copy()
    t = np.zeros(m)
    scale = np.linalg.norm(Xn.max(axis=1) - Xn.min(axis=1), axis=1) if m else np.zeros(0)
    converged = np.zeros(m, dtype=bool)
    for _ in range(max_iter):
        X_ref = v0 + np.einsum("pij,pj->pi", T, xi)
        tab = cmap.tabulate(1, X_ref).reshape(4, m, -1)  # (4, m, n_gdof)
        dphi = np.moveaxis(tab[1:], 0, -1)  # (m, n_gdof, 3)
        X = np.einsum("pk,pki->pi", tab[0], Xn)
        dX = np.einsum("pki,pkd,pdj->pij", Xn, dphi, T)  # (m, 3, 2)
        F = X - xp - t[:, None] * nrm
        J = np.concatenate([dX, -nrm[:, :, None]], axis=2)
        ok = np.abs(np.linalg.det(J)) > 1e-300
        step = np.zeros((m, 3))
        step[ok] = np.linalg.solve(J[ok], -F[ok][:, :, None])[..., 0]
        xi = xi + step[:, :2]
        t = t + step[:, 2]
        converged = ok & (np.linalg.norm(step[:, :2], axis=1) <= 1e-13) & (
            np.abs(step[:, 2]) <= 1e-13 * np.maximum(scale, 1e-300))
        if converged.all():
            break
    X_ref = v0 + np.einsum("pij,pj->pi", T, xi)
    if surface.triangle:
        inside = (xi >= -inside_tol).all(axis=1) & (xi.sum(axis=1) <= 1.0 + inside_tol)
    else:
        inside = ((xi >= -inside_tol) & (xi <= 1.0 + inside_tol)).all(axis=1)
    # outward normal of the facet's body at the point: J^-T N_ref
    tab = cmap.tabulate(1, X_ref).reshape(4, m, -1)
    Jc = np.einsum("pki,pkd->pid", Xn, np.moveaxis(tab[1:], 0, -1))
    ok = np.abs(np.linalg.det(Jc)) > 1e-300
    n2 = np.zeros((m, 3))
    n2[ok] = np.linalg.solve(np.swapaxes(Jc[ok], 1, 2),
                             surface.ref_normal[c][ok][:, :, None])[..., 0]
    facing = np.einsum("pi,pi->p", n2, nrm) < 0.0
    return X_ref, t, converged & np.isfinite(t), inside, facing


def _project(x, normal, surface, cmap, search_radius, n_candidates, inside_tol, max_iter):
    n = x.shape[0]
    facet = np.full(n, -1, dtype=np.int64)
    X_best = np.zeros((n, 3))
    if n == 0 or surface.size == 0:
        return Projection(facet, X_best, np.zeros(n), np.full(n, np.inf),
                          np.zeros(n, dtype=bool))
    k = int(min(n_candidates, surface.size))
    _, cand = cKDTree(surface.centroid).query(x, k=k)
    cand = np.asarray(cand).reshape(n, k)
    pts = np.repeat(np.arange(n), k)
    c = cand.ravel()
    X_ref, t, converged, inside, facing = _newton_on_facets(
        x[pts], normal[pts], surface, c, cmap, max_iter, inside_tol)
    geometric = converged & inside
    within = geometric & (np.abs(t) <= search_radius)
    accepted = within & facing
    # best accepted candidate per point (smallest |t|), vectorised over the k candidates
    score = np.where(accepted, np.abs(t), np.inf).reshape(n, k)
    best = np.argmin(score, axis=1)
    has = np.isfinite(score[np.arange(n), best])
    sel = np.arange(n) * k + best
    facet[has] = c[sel[has]]
    X_best[has] = X_ref[sel[has]]
    distance = np.where(has, t[sel], 0.0)
    nearest = np.where(geometric, np.abs(t), np.inf).reshape(n, k).min(axis=1)
    facing_failure = (within & ~facing).reshape(n, k).any(axis=1) & ~has
    return Projection(facet, X_best, distance, nearest, facing_failure)
