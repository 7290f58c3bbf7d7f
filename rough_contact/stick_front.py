"""Radius of a circular stick–slip front from discrete contact tractions, finer than the
spacing of the points.

Pure numpy (no DOLFINx, no MPI): the caller gathers the points (every rank the same arrays,
in an order that does not depend on the partition) and calls :func:`stick_front`.

Why the squared margin. In the stick zone of a frictional contact the margin
m = mu p - |t| >= 0 vanishes at a stick–slip front like the square root of the distance to
it: the tangential traction near the edge of a stuck zone bordered by slip behaves like the
stress ahead of a crack tip (the slip zone carries |t| = mu p, the stick zone the elastic
field with a square-root correction). In the Cattaneo–Mindlin solution this is exact over the
whole stick zone: with Hertz's p = (p0/a) sqrt(a^2 - r^2) and the stick-zone traction
t = mu (p0/a) [sqrt(a^2 - r^2) - sqrt(c^2 - r^2)],

    m^2 = (mu p0 / a)^2 (c^2 - r^2),                  r <= c,

a straight line in r^2 whose zero is c^2. Under a normal load alone (no slip, c = a) the same
holds with m = mu p. So m^2 against r^2 is the variable in which to interpolate the front:
a weighted least-squares line m^2 = A - B r^2 through the STUCK points in a band next to the
front, pooled over all azimuths, put to zero: c = sqrt(A / B). The slipping points carry
m = 0 by construction (exact stick) and only say on which side of the front they lie; they
are not fitted.

Which band. Near the front the square-root law is a local (leading-order) statement; in
Mindlin's solution it holds everywhere, in a general problem only close to the front. The
band is the stuck points with r >= (1 - band) c, found by a fixed point (start from all stuck
points, fit, take the band of that c, fit again, until the band stops changing); the default,
half of the stick radius, holds two or more rings of points at spacings of a/8 and finer
down to c = a/2 (one ring or less at a/4 and small c). Where the margin is not Mindlin's,
m^2 = (c^2 - r^2) g(r^2) with g varying, the line is a secant and c moves by about
k band^2 / (3 (1 + k)) for g = 1 + k r^2 / c^2 (second order in the band; the unit tests derive
and check it), so the spread of c over bands is the warning sign. A discrete solution's
margins are least accurate at the point nearest to the front; the fit pools all of the band,
so one such point moves c by a fraction of a ring, not by a ring. ``inside_slip`` fits only
the stuck points inside the innermost slipping one (a ragged discrete front leaves stuck
islands among slipping points, which pull the line outwards).

The estimator uses no constant of Mindlin's (p0, a, mu P): only the points' radii from the
centre of the contact, their pressure, shear magnitude, the friction coefficient, their
area weights and stick/slip flags.

Quality figures returned with c (:class:`StickFront`): the weighted rms residual of the line
relative to the weighted rms of m^2 in the band (0 for an exact square-root margin), the number
of points fitted, and the number of MISPLACED points: stuck points beyond c and slipping ones
inside it (0 when the flags and the front agree).

Units: those of the inputs (radii in mm, tractions in MPa in this project).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rough_contact.validation import check_integer, check_scalar

__all__ = ["StickFront", "stick_front", "contact_front", "mindlin_tractions"]


@dataclass(frozen=True)
class StickFront:
    """Result of :func:`stick_front`.

    Attributes:
        radius: stick radius c (0 when no point sticks; nan when too few stuck points to fit
            a line (fewer than 2 at distinct radii) or when the fitted m^2 does not fall
            outwards, in the band nor over all stuck points) [mm].
        residual: weighted rms residual of the line m^2 = A - B r^2 over the band, divided by
            the weighted rms of m^2 there [-] (nan without a fit).
        n_band: number of stuck points fitted.
        n_misplaced: stuck points at r > c plus slipping points at r < c (0 without a fit).
        iterations: fixed-point iterations of the band (1 = the band of the first fit was
            already consistent).
    """

    radius: float
    residual: float
    n_band: int
    n_misplaced: int
    iterations: int


def _fit(r2: np.ndarray, m2: np.ndarray, w: np.ndarray):
    """Weighted least-squares line m2 = A - B r2; returns (c^2 or nan, relative rms)."""
    W = w.sum()
    xm, ym = np.dot(w, r2) / W, np.dot(w, m2) / W
    sxx = np.dot(w, (r2 - xm) ** 2)
    if not sxx > 0.0:
        return np.nan, np.nan
    slope = np.dot(w, (r2 - xm) * (m2 - ym)) / sxx       # = -B
    if not slope < 0.0:
        return np.nan, np.nan
    A = ym - slope * xm
    res = m2 - (A + slope * r2)
    scale = np.sqrt(np.dot(w, m2**2) / W)
    rel = float(np.sqrt(np.dot(w, res**2) / W) / scale) if scale > 0 else np.nan
    return A / (-slope), rel


def _array(name: str, value, n=None, dtype=float) -> np.ndarray:
    a = np.asarray(value, dtype=dtype)
    if a.ndim != 1:
        raise ValueError(f"{name} has shape {a.shape}: it must be one-dimensional (one entry "
                         "per point)")
    if n is not None and a.size != n:
        raise ValueError(f"{name} has {a.size} entries: it must have one per point ({n})")
    return a


def stick_front(r, pressure, shear, mu: float, weights, sticking, slipping, band: float = 0.5,
                max_iterations: int = 20, inside_slip: bool = False) -> StickFront:
    """Stick radius c of a circular stick zone about r = 0 from the points' margins
    m = mu p - |t| (module docstring): the zero of the weighted least-squares line
    m^2 = A - B r^2 through the stuck points with r >= (1 - band) c.

    Args:
        r: (n,) distance of each point from the centre of the contact [mm], >= 0.
        pressure: (n,) contact pressure p [MPa].
        shear: (n,) magnitude of the tangential traction |t| [MPa], >= 0.
        mu: friction coefficient, > 0.
        weights: (n,) area represented by each point [mm^2], > 0 (the points' share in the fit).
        sticking: (n,) bool, in contact and stuck.
        slipping: (n,) bool, in contact and slipping (disjoint from ``sticking``; points in
            neither are out of contact and ignored).
        band: width of the fitted band as a fraction of c, in (0, 1] (1: all stuck points).
        max_iterations: bound on the band's fixed-point iterations, >= 1.
        inside_slip: fit only the stuck points closer to the centre than the innermost
            slipping point: the stick zone proper, without stuck "islands" left among
            slipping points (a discrete solution's ragged front; in the continuum, monotonic
            loading keeps the stick zone a disc). Off by default: it assumes the front is
            nearly circular, since the innermost slipping point bounds it at every azimuth.

    Returns:
        :class:`StickFront`.

    Raises:
        ValueError: arrays of different lengths or not one-dimensional, a radius negative or
            not finite, a pressure or shear of a stuck point not finite, a shear negative,
            a weight of a stuck point not > 0, a point both stuck and slipping, ``mu``,
            ``band`` or ``max_iterations`` out of range.
    """
    r = _array("r", r)
    n = r.size
    p = _array("pressure", pressure, n)
    t = _array("shear", shear, n)
    w = _array("weights", weights, n)
    stuck = _array("sticking", sticking, n, dtype=bool)
    slip = _array("slipping", slipping, n, dtype=bool)
    mu = check_scalar("mu", mu, lo=0.0)
    band = check_scalar("band", band, lo=0.0, hi=1.0, hi_open=False)
    check_integer("max_iterations", max_iterations, lo=1)
    bad = ~np.isfinite(r) | (r < 0.0)
    if bad.any():
        raise ValueError(f"r = {float(r[bad][0])!r} mm is invalid: radii must be finite and >= 0")
    both = stuck & slip
    if both.any():
        raise ValueError(f"point {int(np.flatnonzero(both)[0])} is both sticking and slipping: "
                         "the flags must be disjoint")
    for name, a in (("pressure", p), ("shear", t)):
        nonfinite = stuck & ~np.isfinite(a)
        if nonfinite.any():
            raise ValueError(f"{name} = {float(a[nonfinite][0])!r} MPa at a stuck point is "
                             "invalid: it must be finite")
    if np.any(t[np.isfinite(t)] < 0.0):
        raise ValueError(f"shear = {float(t[np.isfinite(t)].min())!r} MPa is invalid: it is the "
                         "magnitude |t| >= 0")
    wbad = stuck & ~(np.isfinite(w) & (w > 0.0))
    if wbad.any():
        raise ValueError(f"weights = {float(w[wbad][0])!r} mm^2 at a stuck point is invalid: "
                         "it must be finite and > 0")
    fit = stuck & (r < r[slip].min()) if inside_slip and slip.any() else stuck
    if not fit.any():
        return StickFront(0.0, np.nan, 0, 0, 0)
    rs = r[fit]
    m2 = np.maximum(mu * p[fit] - t[fit], 0.0) ** 2
    ws = w[fit]
    r2 = rs**2
    chosen = np.ones(rs.size, dtype=bool)             # first fit: every stuck point
    c2, rel = np.nan, np.nan
    iterations = 0
    for iterations in range(1, int(max_iterations) + 1):
        if np.unique(rs[chosen]).size < 2:
            c2, rel = np.nan, np.nan
            break
        c2, rel = _fit(r2[chosen], m2[chosen], ws[chosen])
        if (not np.isfinite(c2) or c2 <= 0.0) and not chosen.all():
            # a band too narrow for the points' scatter (e.g. one ring): all stuck points
            chosen = np.ones(rs.size, dtype=bool)
            c2, rel = _fit(r2, m2, ws)
            if np.isfinite(c2) and c2 > 0.0:
                break
        if not np.isfinite(c2) or c2 <= 0.0:
            c2 = np.nan
            break
        nxt = rs >= (1.0 - band) * np.sqrt(c2)
        if np.unique(rs[nxt]).size < 2:
            nxt = np.ones(rs.size, dtype=bool)       # too few in the band: all stuck points
        if np.array_equal(nxt, chosen):
            break
        chosen = nxt
    if not np.isfinite(c2):
        return StickFront(np.nan, np.nan, int(chosen.sum()), 0, iterations)
    c = float(np.sqrt(c2))
    misplaced = int(np.count_nonzero(stuck & (r > c)) + np.count_nonzero(slip & (r < c)))
    return StickFront(c, float(rel), int(chosen.sum()), misplaced, iterations)


def contact_front(r, pressure, weights, contact, band: float = 0.5,
                  max_iterations: int = 20) -> StickFront:
    """Contact radius a from the pressures by the same fit: p^2 = A - B r^2 (exact for
    Hertz's p = p0 sqrt(1 - r^2/a^2); near any smooth contact edge p vanishes like the square
    root of the distance) through the points in contact with r >= (1 - band) a. This is
    :func:`stick_front` with m = p (mu = 1, no shear, every contact point "stuck"), so that c/a
    of two fronts of the same discrete solution compares like with like.

    Args:
        r, pressure, weights: as in :func:`stick_front`.
        contact: (n,) bool, in contact.
        band, max_iterations: as in :func:`stick_front`.
    """
    contact = _array("contact", contact, dtype=bool)
    p = _array("pressure", pressure, contact.size)
    return stick_front(r, p, np.zeros(contact.size), 1.0, weights, contact,
                       np.zeros(contact.size, dtype=bool), band, max_iterations)


def mindlin_tractions(r, c: float, a: float, p0: float, mu: float):
    """Cattaneo–Mindlin's tractions at radii ``r`` (the synthetic data the estimator is checked
    on): p = p0 sqrt(1 - r^2/a^2), |t| = mu (p0/a) [sqrt(a^2 - r^2) - sqrt(c^2 - r^2)] for
    r < c and mu p for c <= r < a; 0 beyond a.

    Returns:
        ``(p, |t|, sticking, slipping)``: (n,) arrays; sticking = r < c, slipping =
        c <= r < a.
    """
    r = np.asarray(r, dtype=float)
    a = check_scalar("a", a, lo=0.0, unit="mm")
    c = check_scalar("c", c, lo=0.0, hi=a, lo_open=False, hi_open=False, unit="mm")
    p0 = check_scalar("p0", p0, lo=0.0, unit="MPa")
    mu = check_scalar("mu", mu, lo=0.0)
    ra = np.sqrt(np.clip(a**2 - r**2, 0.0, None))
    rc = np.sqrt(np.clip(c**2 - r**2, 0.0, None))
    p = p0 / a * ra
    t = mu * p0 / a * (ra - rc)
    sticking = r < c
    slipping = (r >= c) & (r < a)
    return p, t, sticking, slipping
