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
* **Candidates** are the 4 (then, for the points left without partner, ``n_candidates``,
  then every facet whose centroid is within the search radius + the largest facet radius)
  second facets whose centroids are nearest to x
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
from functools import cached_property

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["SecondSurface", "Projection", "project_points", "MortarPoints", "clip_convex",
           "mortar_points", "cyclic_order"]


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

    @cached_property
    def extent(self) -> np.ndarray:
        """(n2,) size of each facet's cell: the diagonal of its nodes' bounding box [mm] (the
        scale of the projection's convergence test; computed once)."""
        return np.linalg.norm(self.cell_x.max(axis=1) - self.cell_x.min(axis=1), axis=1)


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
        n_candidates: second facets tried per point (nearest centroids): the 4 nearest
            first, then ``n_candidates`` for the points those leave without partner.
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


def project_points_from(previous: np.ndarray, x: np.ndarray, normal: np.ndarray,
                        surface: SecondSurface, cmap, search_radius: float,
                        inside_tol: float = 1e-8, max_iter: int = 25) -> Projection:
    """:func:`project_points` started from each point's previous partner facet (a re-pairing
    after a small motion): a point whose normal still meets its previous facet, within the
    search radius and facing it, keeps it; only the others (and points without a previous
    facet, ``previous`` -1) are searched for among the nearest facets.

    Args:
        previous: (n,) previous partner facet of every point (-1: none).
        others: as :func:`project_points`.
    """
    n = x.shape[0]
    if n == 0 or surface.size == 0:
        return project_points(x, normal, surface, cmap, search_radius)
    cand = np.where(previous < surface.size, previous, -1).reshape(n, 1).astype(np.int64)
    result = _candidates(x, normal, surface, cand, cmap, search_radius, inside_tol, max_iter)
    # points that left their facet: the facet of the nearest centroid, then a search as at
    # set-up for those it does not hold; points that had no partner (beyond an edge): their 4
    # nearest facets only
    was_off = cand[:, 0] < 0
    tree = None
    for group in ("nearest", "off", "full"):
        missing = result.facet < 0
        retry = np.flatnonzero(missing & (was_off if group == "off" else ~was_off))
        if retry.size == 0:
            continue
        if group == "full":
            again = project_points(x[retry], normal[retry], surface, cmap, search_radius,
                                   inside_tol=inside_tol, max_iter=max_iter)
        else:
            tree = cKDTree(surface.centroid) if tree is None else tree
            again = _candidates(x[retry], normal[retry], surface,
                                _nearest(tree, x[retry], 1 if group == "nearest" else 4), cmap,
                                search_radius, inside_tol, max_iter)
        result = _replaced(result, retry, again)
    return result


def tabulate(element, nderiv: int, X: np.ndarray) -> np.ndarray:
    """``element.tabulate(nderiv, X)`` as (n_derivatives, m, dim); safe for m = 0 (basix
    asserts on an empty point set)."""
    n_der = 1 if nderiv == 0 else 4
    if X.shape[0] == 0:
        return np.zeros((n_der, 0, element.dim))
    return element.tabulate(nderiv, X).reshape(n_der, X.shape[0], element.dim)


def _solve3(J: np.ndarray, b: np.ndarray):
    """Solve the (m, 3, 3) systems J x = b (m, 3) by cofactors (Cramer's rule), vectorised:
    for the small, well-scaled systems of the projection this is several times cheaper than
    batched LAPACK. Returns (x (m, 3), ok (m,)): ok where |det J| > 1e-300 (x = 0 elsewhere)."""
    a, b_, c = J[:, :, 0], J[:, :, 1], J[:, :, 2]      # columns
    bxc = np.cross(b_, c)
    det = np.einsum("pi,pi->p", a, bxc)
    ok = np.abs(det) > 1e-300
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    x = np.empty_like(b)
    x[:, 0] = np.einsum("pi,pi->p", b, bxc) * inv
    x[:, 1] = np.einsum("pi,pi->p", a, np.cross(b, c)) * inv
    x[:, 2] = np.einsum("pi,pi->p", a, np.cross(b_, b)) * inv
    return x, ok


def _newton_on_facets(xp, nrm, surface, c, cmap, max_iter=25, inside_tol=1e-8):
    """Solve X_c(xi) = xp + t nrm on facets c (vectorised over m = len(c) pairs).

    Returns:
        X_ref (m, 3) reference-cell point, t (m,), converged (m,), inside (m,), facing (m,)
        (the facet's body faces along -nrm there: n2 . nrm < 0).
    """
    m = c.size
    Xn, v0, T = surface.cell_x[c], surface.v0[c], surface.tangents[c]
    XnT = np.swapaxes(Xn, 1, 2)                     # (m, 3, n_gdof)
    centre = np.array([1.0 / 3.0, 1.0 / 3.0]) if surface.triangle else np.array([0.5, 0.5])
    xi = np.broadcast_to(centre, (m, 2)).copy()
    t = np.zeros(m)
    scale = surface.extent[c]
    converged = np.zeros(m, dtype=bool)
    act = np.arange(m)          # active set: pairs still iterating
    J = np.empty((m, 3, 3))
    for _ in range(max_iter):
        if act.size == 0:
            break
        XaT, Ta, na = XnT[act], T[act], nrm[act]
        xa = xi[act]
        tab = tabulate(cmap, 1, v0[act] + (Ta @ xa[:, :, None])[..., 0])
        X = (XaT @ tab[0][:, :, None])[..., 0]                     # (a, 3)
        dphi = np.moveaxis(tab[1:], 0, -1)                         # (a, n_gdof, 3)
        Ja = J[:act.size]
        Ja[:, :, :2] = (XaT @ dphi) @ Ta                           # dX/dxi (a, 3, 2)
        Ja[:, :, 2] = -na
        ta = t[act]
        F = X - xp[act] - ta[:, None] * na
        step, ok = _solve3(Ja, -F)
        xa = xa + step[:, :2]
        ta = ta + step[:, 2]
        xi[act] = xa
        t[act] = ta
        big = np.maximum(np.abs(xa[:, 0]), np.abs(xa[:, 1]))
        done = ok & (np.maximum(np.abs(step[:, 0]), np.abs(step[:, 1])) <= 1e-12 * (1.0 + big)) \
            & (np.abs(step[:, 2]) <= 1e-12 * (scale[act] + np.abs(ta)))
        converged[act[done]] = True
        hopeless = ~ok | (big > 10.0)   # far outside the facet
        act = act[~done & ~hopeless]
    X_ref = v0 + (T @ xi[:, :, None])[..., 0]
    if surface.triangle:
        inside = (xi >= -inside_tol).all(axis=1) & (xi.sum(axis=1) <= 1.0 + inside_tol)
    else:
        inside = ((xi >= -inside_tol) & (xi <= 1.0 + inside_tol)).all(axis=1)
    # outward normal of the facet's body at the point: J^-T N_ref
    tab = tabulate(cmap, 1, X_ref)
    Jc = XnT @ np.moveaxis(tab[1:], 0, -1)                          # (m, 3, 3)
    n2, _ = _solve3(np.swapaxes(Jc, 1, 2), surface.ref_normal[c])
    facing = np.einsum("pi,pi->p", n2, nrm) < 0.0
    return X_ref, t, converged & np.isfinite(t), inside, facing


def _project(x, normal, surface, cmap, search_radius, n_candidates, inside_tol, max_iter):
    n = x.shape[0]
    facet = np.full(n, -1, dtype=np.int64)
    X_best = np.zeros((n, 3))
    if n == 0 or surface.size == 0:
        return Projection(facet, X_best, np.zeros(n), np.full(n, np.inf),
                          np.zeros(n, dtype=bool))
    tree = cKDTree(surface.centroid)
    # pass 1: the 4 nearest facets find almost every partner; pass 2: n_candidates nearest for
    # the points pass 1 left without partner; pass 3: every facet whose centroid lies within
    # the search radius + the largest facet radius (elongated facets, steep normals)
    result = _candidates(x, normal, surface, _nearest(tree, x, min(4, n_candidates)), cmap,
                         search_radius, inside_tol, max_iter)
    radius = search_radius + float(np.max(np.linalg.norm(
        surface.cell_x - surface.centroid[:, None, :], axis=2)))
    for finder in (lambda xs: _nearest(tree, xs, n_candidates),
                   lambda xs: _within(tree, xs, radius)):
        retry = np.flatnonzero(result.facet < 0)
        if retry.size == 0:
            break
        again = _candidates(x[retry], normal[retry], surface, finder(x[retry]), cmap,
                            search_radius, inside_tol, max_iter)
        result = _replaced(result, retry, again)
    return result


def _replaced(result: "Projection", rows: np.ndarray, again: "Projection") -> "Projection":
    """``result`` with the points ``rows`` replaced by ``again`` (a projection of those points)."""
    merged = [getattr(result, f).copy() for f in Projection.__dataclass_fields__]
    for arr, new in zip(merged, (getattr(again, f) for f in Projection.__dataclass_fields__)):
        arr[rows] = new
    return Projection(*merged)


def _nearest(tree, x, k):
    """(n, k) indices of the k nearest centroids."""
    k = int(min(k, tree.n))
    return np.asarray(tree.query(x, k=k)[1]).reshape(x.shape[0], k)


def _within(tree, x, radius):
    """(n, k) indices of all centroids within radius (-1 padding)."""
    counts = tree.query_ball_point(x, radius, return_length=True)
    k = int(min(max(int(np.max(counts, initial=1)), 1), tree.n))
    d, cand = tree.query(x, k=k, distance_upper_bound=radius)
    cand = np.asarray(cand).reshape(x.shape[0], k)
    return np.where(cand < tree.n, cand, -1)


def _candidates(x, normal, surface, cand, cmap, search_radius, inside_tol, max_iter):
    n, k = cand.shape
    facet = np.full(n, -1, dtype=np.int64)
    X_best = np.zeros((n, 3))
    valid = (cand >= 0).ravel()
    pts = np.repeat(np.arange(n), k)[valid]
    c = cand.ravel()[valid]
    m = valid.size
    X_ref = np.zeros((m, 3))
    t = np.zeros(m)
    converged = np.zeros(m, dtype=bool)
    inside = np.zeros(m, dtype=bool)
    facing = np.zeros(m, dtype=bool)
    X_ref[valid], t[valid], converged[valid], inside[valid], facing[valid] = _newton_on_facets(
        x[pts], normal[pts], surface, c, cmap, max_iter, inside_tol)
    c = np.where(valid, cand.ravel(), -1)
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


# --------------------------------------------------------------------------------------------
# segment-to-segment (mortar-style) integration
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MortarPoints:
    """Quadrature points on the intersections of first facets with projected second facets.

    Attributes:
        facet1: (m,) local index of the first facet (into the caller's first-facet arrays).
        facet2: (m,) partner facet in the :class:`SecondSurface`.
        x: (m, 3) points on the first facet's plane [mm].
        weight: (m,) area weights [mm^2] (sum over a first facet = its area, for flat facets
            entirely covered by the second surface).
    """

    facet1: np.ndarray
    facet2: np.ndarray
    x: np.ndarray
    weight: np.ndarray


def cyclic_order(n_vertices: int) -> np.ndarray:
    """Reference vertex order -> cyclic order (quadrilaterals are numbered tensor-wise)."""
    return np.array([0, 1, 2]) if n_vertices == 3 else np.array([0, 1, 3, 2])


def clip_convex(subject: np.ndarray, n_subject: np.ndarray, clip: np.ndarray) -> tuple:
    """Sutherland–Hodgman clipping of polygons by convex counter-clockwise polygons, 2D,
    vectorised over m pairs.

    Args:
        subject: (m, V, 2) polygon vertices (cyclic; rows beyond ``n_subject`` ignored).
        n_subject: (m,) vertex counts.
        clip: (m, c, 2) convex clip polygons, counter-clockwise.

    Returns:
        (vertices (m, V', 2), counts (m,)) of the intersections (count < 3: empty).
    """
    poly, n = subject, n_subject.astype(np.int64)
    m = poly.shape[0]
    rows = np.arange(m)[:, None]
    for e in range(clip.shape[1]):
        a = clip[:, e]
        b = clip[:, (e + 1) % clip.shape[1]]
        V = poly.shape[1]
        idx = np.arange(V)[None, :]
        valid = idx < n[:, None]
        nxt = np.where(idx + 1 < n[:, None], idx + 1, 0)
        p, q = poly, poly[rows, nxt]
        edge = (b - a)[:, None, :]

        def side(z):
            return edge[..., 0] * (z[..., 1] - a[:, None, 1]) - edge[..., 1] * (
                z[..., 0] - a[:, None, 0])

        sp, sq = side(p), side(q)
        inp, inq = sp >= 0.0, sq >= 0.0
        denom = np.where(sp - sq == 0.0, 1.0, sp - sq)
        cross = p + (sp / denom)[..., None] * (q - p)
        out = np.stack([cross, q], axis=2).reshape(m, 2 * V, 2)
        keep = np.stack([valid & (inp != inq), valid & inq], axis=2).reshape(m, 2 * V)
        order = np.argsort(~keep, axis=1, kind="stable")
        n = keep.sum(axis=1)
        width = max(int(n.max(initial=0)), 1)
        poly = np.take_along_axis(out, order[:, :width, None], axis=1)
    return poly, n


def mortar_points(first: SecondSurface, first_vertices: np.ndarray, second: SecondSurface,
                  second_vertices: np.ndarray, rule_points: np.ndarray,
                  rule_weights: np.ndarray, min_fraction: float = 1e-10) -> MortarPoints:
    """Quadrature points on the overlaps of first facets with the second surface's facets
    projected on the first facets' planes (flat-facet mortar integration).

    Each first facet's vertex plane gets an orthonormal frame; the candidate second facets
    (centroid closer than the two facets' radii) are projected on it along its normal, clipped
    by the first facet (convex), fan-triangulated, and each triangle gets ``rule_points``.

    Args:
        first, second: the two surfaces (``first`` only for its centroids).
        first_vertices: (n1, nv, 3) vertex coordinates of the first facets (reference order).
        second_vertices: (n2, nv, 3) same for the second facets.
        rule_points, rule_weights: a triangle quadrature rule on the reference triangle
            (weights summing to 1/2).
        min_fraction: overlaps smaller than this fraction of the first facet's area are
            dropped (facets touching along an edge or a corner).

    Returns:
        The :class:`MortarPoints`.
    """
    n1, nv = first_vertices.shape[:2]
    empty = MortarPoints(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)),
                         np.zeros(0))
    if n1 == 0 or second.size == 0:
        return empty
    cyc = cyclic_order(nv)
    P1 = first_vertices[:, cyc]
    P2 = second_vertices[:, cyc]
    i1, i2 = _overlap_candidates(P1, P2)
    # frames on the first facets' planes
    e1 = P1[:, 1] - P1[:, 0]
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    nrm = np.cross(P1[:, 1] - P1[:, 0], P1[:, -1] - P1[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    e2 = np.cross(nrm, e1)
    origin = P1[:, 0]

    def to2d(X, f):
        d = X - origin[f][:, None, :]
        return np.stack([np.einsum("pvi,pi->pv", d, e1[f]), np.einsum("pvi,pi->pv", d, e2[f])],
                        axis=-1)

    clip = to2d(P1[i1], i1)      # counter-clockwise by construction of e2 = n x e1
    subj = to2d(P2[i2], i1)
    # the projected second facet may be clockwise: reverse it (orientation does not matter
    # for clipping a polygon by a convex one, but the fan areas below are signed)
    area2 = 0.5 * np.sum(subj[:, :, 0] * np.roll(subj[:, :, 1], -1, axis=1)
                         - np.roll(subj[:, :, 0], -1, axis=1) * subj[:, :, 1], axis=1)
    subj = np.where((area2 < 0)[:, None, None], subj[:, ::-1], subj)
    poly, n = clip_convex(subj, np.full(i1.size, nv), clip)
    # facet areas (triangles; parallelograms for the flat quadrilaterals this rule assumes)
    area1 = np.linalg.norm(np.cross(P1[:, 1] - P1[:, 0], P1[:, -1] - P1[:, 0]), axis=1)
    if nv == 3:
        area1 *= 0.5
    return _fan_points(poly, n, i1, i2, (origin, e1, e2), area1, rule_points, rule_weights,
                       min_fraction, empty)


def _overlap_candidates(P1: np.ndarray, P2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(i1, i2): pairs of first and second facets (cyclic vertices P1, P2) whose centroids are
    closer than the sum of their radii: the only ones that can overlap."""
    n1, n2 = P1.shape[0], P2.shape[0]
    c1 = P1.mean(axis=1)
    c2 = P2.mean(axis=1)
    r1 = np.linalg.norm(P1 - c1[:, None], axis=2).max(axis=1)
    r2 = np.linalg.norm(P2 - c2[:, None], axis=2).max(axis=1)
    # candidate pairs: centroid distance <= r1 + max r2 (then filtered by r1 + r2)
    tree = cKDTree(c2)
    counts = tree.query_ball_point(c1, r1 + r2.max(), return_length=True)
    k = int(min(max(int(np.max(counts)), 1), n2))
    dist, cand = tree.query(c1, k=k)
    dist, cand = np.asarray(dist).reshape(n1, k), np.asarray(cand).reshape(n1, k)
    ok = (cand < n2)
    ok[ok] &= dist[ok] <= (r1[:, None] + r2[np.where(ok, cand, 0)])[ok] * (1 + 1e-12)
    i1, j = np.nonzero(ok)
    return i1, cand[i1, j]


def _fan_points(poly, n, i1, i2, frame, area1, rule_points, rule_weights, min_fraction,
                empty) -> MortarPoints:
    """Fan triangulation of the clipped polygons (2D, in the first facets' frames) from vertex
    0, the triangle rule on every triangle, mapped back to 3D."""
    origin, e1, e2 = frame
    V = poly.shape[1]
    xs, ws, f1s, f2s = [], [], [], []
    for t in range(1, V - 1):       # at most 6 triangles: a loop over fan positions only
        has = n > t + 1
        if not has.any():
            break
        a, b, c = poly[has, 0], poly[has, t], poly[has, t + 1]
        ab, ac = b - a, c - a
        det = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]
        pts2 = a[:, None] + rule_points[None, :, 0, None] * ab[:, None] + \
            rule_points[None, :, 1, None] * ac[:, None]      # (h, nq, 2)
        f = i1[has]
        x3 = origin[f][:, None] + pts2[..., 0, None] * e1[f][:, None] + \
            pts2[..., 1, None] * e2[f][:, None]
        w = np.abs(det)[:, None] * rule_weights[None, :]
        keep = np.abs(det) > 2.0 * min_fraction * area1[f]
        xs.append(x3[keep].reshape(-1, 3))
        ws.append(w[keep].ravel())
        f1s.append(np.repeat(f[keep], rule_points.shape[0]))
        f2s.append(np.repeat(i2[has][keep], rule_points.shape[0]))
    if not xs:
        return empty
    return MortarPoints(np.concatenate(f1s).astype(np.int64), np.concatenate(f2s).astype(
        np.int64), np.concatenate(xs), np.concatenate(ws))
