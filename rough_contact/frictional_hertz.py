"""Frictional Hertz contact of dissimilar bodies under a rising normal load (Spence's problem):
the slip annulus that the normal load alone opens, by axisymmetric ring boundary elements.

Pure numpy/scipy (no DOLFINx, no MPI): a reference for the Cattaneo–Mindlin scene, whose
closed forms (:mod:`rough_contact.references`) assume that the normal and the tangential
problems decouple. They do not when the bodies are elastically dissimilar: pressing a rigid
sphere on an elastic half-space pulls the surface radially inwards, friction resists that, and
a ring next to the contact edge may slip before any tangential force is applied. How wide that
ring is decides whether "no slipping point under the normal load alone" is the right check of
a discrete solution.

The model (all derivations are ours; the kernels are standard half-space results):

* Coupling parameter (Dundurs' beta), for body 1 pressed on body 2 (:func:`coupling_parameter`)
  beta = [(1 - 2 nu1)/G1 - (1 - 2 nu2)/G2] / [2 ((1 - nu1)/G1 + (1 - nu2)/G2)]; a rigid
  indenter (G1 -> inf) on an elastic body gives |beta| = (1 - 2 nu)/(2 (1 - nu)).
* Surface displacements of a half-space under an axisymmetric pressure p(r) and a radial shear
  q(r) (outward positive), written with Hankel transforms f~_n(xi) = int f(r) J_n(xi r) r dr:
  u_r = (2/E*) [ int q~_1 J_1(xi r) dxi - beta int p~_0 J_1(xi r) dxi ]. The first term is the
  ring kernel u_r(r) (E*/2) = int_0^inf q(s) s I11(r, s) ds with
  I11(r, s) = int_0^inf J_1(xi r) J_1(xi s) dxi = Q_1/2(z) / (pi sqrt(r s)),
  z = (r^2 + s^2) / (2 r s), Q_1/2(z) = z k K(k) - (z + 1) k E(k), k^2 = 2 / (z + 1)
  (K, E complete elliptic integrals; log-singular at s = r). The second term is
  -beta (1/r) int_0^r p(s) s ds (a pressure moves a surface point by the load inside its
  radius only); for Hertz's pressure p0 sqrt(1 - s^2/a^2) that integral is
  p0 a^2 / 3 [1 - (1 - r^2/a^2)^(3/2)].
* Goodman's approximation: the shear does not change the pressure (the neglected coupling
  changes p by a relative O(beta mu)), so p is Hertz's at every load, with p0 proportional to
  the contact radius a.
* Incremental Coulomb friction per ring, the load rising with a: a ring in contact sticks
  (its radial displacement does not change in the increment: the rigid sphere's surface does
  not move radially) while |q| <= mu p, else it slips with q = -mu p sign(du_r). A ring out of
  contact carries no shear and moves freely. An active-set loop settles each increment. The
  unknowns scale so that only beta / mu enters.

Spence's self-similarity makes the stick radius c a fixed fraction of a during the loading;
:func:`slip_annulus` returns c/a at every increment, so the run checks it.

Cost and error (``rings``): rings = 400 takes a few seconds; c/a at beta/mu = 1 is 0.9000,
0.9025, 0.9037 at 200, 400, 800 rings (``benchmarks/bench_spence_annulus.py``). The ring
width 1/rings (of the final contact radius) is the resolution: an annulus thinner than one
ring is reported as c/a = 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ellipe, ellipk

from rough_contact.references import hertz_pressure
from rough_contact.validation import check_integer, check_scalar

__all__ = ["coupling_parameter", "ring_kernel", "ring_influence", "hertz_radial_term",
           "SlipAnnulus", "slip_annulus"]


def coupling_parameter(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """Dundurs' beta of body 1 pressed on body 2 (E1 = inf for a rigid body 1); its sign says
    which surface the pressure pulls inwards more; only |beta| / mu matters for the annulus."""
    for name, E in (("E1", E1), ("E2", E2)):
        if not (isinstance(E, (int, float, np.floating)) and E == np.inf):
            check_scalar(name, E, lo=0.0, unit="MPa (or inf for a rigid body)")
    for name, nu in (("nu1", nu1), ("nu2", nu2)):
        check_scalar(name, nu, lo=-1.0, hi=0.5, hi_open=False)
    c1 = 0.0 if np.isinf(E1) else 2.0 * (1.0 + nu1) / E1       # 1 / G1
    c2 = 0.0 if np.isinf(E2) else 2.0 * (1.0 + nu2) / E2
    if c1 == 0.0 and c2 == 0.0:
        raise ValueError("E1 = E2 = inf is invalid: at least one body must be elastic")
    return ((1 - 2 * nu1) * c1 - (1 - 2 * nu2) * c2) / (2 * ((1 - nu1) * c1 + (1 - nu2) * c2))


def ring_kernel(r, s) -> np.ndarray:
    """I11(r, s) = int_0^inf J_1(xi r) J_1(xi s) dxi (r, s > 0, r != s), by Legendre's Q_1/2."""
    r, s = np.asarray(r, dtype=float), np.asarray(s, dtype=float)
    z = (r * r + s * s) / (2.0 * r * s)
    m = 2.0 / (z + 1.0)
    k = np.sqrt(m)
    return (z * k * ellipk(m) - (z + 1.0) * k * ellipe(m)) / (np.pi * np.sqrt(r * s))


def ring_influence(edges: np.ndarray, gauss_points: int = 24) -> np.ndarray:
    """A[i, j] = int over ring j of s I11(r_i, s) ds, r_i the centre of ring i, for rings
    between consecutive ``edges`` (increasing, edges[0] >= 0): (E*/2) u_r(r_i) = A @ q for a
    shear q constant on each ring. Each ring is integrated by Gauss–Legendre in u with
    s = anchor +- L u^2 (anchor: the ring's end nearest r_i; the own ring split at r_i), which
    removes the logarithmic singularity. One row per Python iteration (a table built once)."""
    edges = np.asarray(edges, dtype=float)
    if edges.ndim != 1 or edges.size < 2 or edges[0] < 0 or np.any(np.diff(edges) <= 0):
        raise ValueError(f"edges = {edges!r} is invalid: need an increasing 1-D array of at "
                         "least 2 radii >= 0")
    check_integer("gauss_points", gauss_points, lo=2)
    r = 0.5 * (edges[1:] + edges[:-1])
    u, w = np.polynomial.legendre.leggauss(int(gauss_points))
    u, w = 0.5 * (u + 1.0), 0.5 * w
    lo, hi = edges[:-1], edges[1:]
    A = np.empty((r.size, r.size))
    for i, ri in enumerate(r):
        row = np.zeros(r.size)
        for a_, b_ in ((lo, np.minimum(hi, ri)), (np.maximum(lo, ri), hi)):
            length = b_ - a_
            keep = length > 0.0
            if not keep.any():
                continue
            a_, b_, length = a_[keep], b_[keep], length[keep]
            from_a = np.abs(a_ - ri) <= np.abs(b_ - ri)
            anchor = np.where(from_a, a_, b_)
            sign = np.where(from_a, 1.0, -1.0)
            s = anchor[:, None] + sign[:, None] * length[:, None] * u[None, :] ** 2
            with np.errstate(divide="ignore", invalid="ignore"):
                f = s * ring_kernel(ri, s)
            f[~np.isfinite(f)] = 0.0              # s = r_i or s = 0: weight 0 there (u = 0)
            row[keep] += (f * (2.0 * length[:, None] * u[None, :]) * w[None, :]).sum(axis=1)
        A[i] = row
    return A


def hertz_radial_term(r, a: float, p0: float) -> np.ndarray:
    """(1/r) int_0^r p(s) s ds for Hertz's pressure p0 sqrt(1 - s^2/a^2) on s < a."""
    r = np.asarray(r, dtype=float)
    inside = np.clip(1.0 - (np.minimum(r, a) / a) ** 2, 0.0, None)
    return p0 * a * a / 3.0 * (1.0 - inside ** 1.5) / r


@dataclass(frozen=True)
class SlipAnnulus:
    """Result of :func:`slip_annulus`, the final contact radius being 1.

    a: contact radius of each increment; stick_ratio: c/a per increment (c: the outer edge of
    the outermost sticking ring; 1 when no ring slips); inner_slip_ratio: the inner edge of the
    innermost slipping ring over a (1 when none slips); r: ring centres; shear: q / mu at the
    end (in units of the final peak pressure); pressure: p at the end; sticking: the rings
    that stick at the end; rings: the ring count."""
    a: np.ndarray
    stick_ratio: np.ndarray
    inner_slip_ratio: np.ndarray
    r: np.ndarray
    shear: np.ndarray
    pressure: np.ndarray
    sticking: np.ndarray
    rings: int


def slip_annulus(beta_over_mu: float, rings: int = 400, max_sweeps: int = 200) -> SlipAnnulus:
    """The slip annulus of a rigid sphere pressed monotonically on an elastic half-space with
    Coulomb friction mu and coupling parameter beta (or two dissimilar elastic bodies, with
    Dundurs' beta), under Goodman's approximation (module docstring). ``rings`` uniform rings
    cover the final contact radius; the contact grows by one ring per increment. Raises
    ValueError for a bad input and RuntimeError if an increment's active set does not settle
    within ``max_sweeps``."""
    check_scalar("beta_over_mu", beta_over_mu, lo=0.0, lo_open=False)
    check_integer("rings", rings, lo=4)
    check_integer("max_sweeps", max_sweeps, lo=1)
    n = int(rings)
    edges = np.linspace(0.0, 1.0, n + 1)
    r = 0.5 * (edges[1:] + edges[:-1])
    A = ring_influence(edges)
    u_prev = np.zeros(n)                   # (E*/2) u_r / mu
    ratios, inner = np.ones(n), np.ones(n)
    half = 0.5 / n
    for m in range(1, n + 1):
        a = edges[m]
        contact = r < a
        p = hertz_pressure(r, a, a)          # p0 proportional to a (Hertz); 0 beyond a
        phi = beta_over_mu * hertz_radial_term(r, a, a)
        stick = contact.copy()
        sign = np.zeros(n)
        for _ in range(int(max_sweeps)):
            slip = contact & ~stick
            q = np.zeros(n)
            q[slip] = -sign[slip] * p[slip]
            S = np.flatnonzero(stick)
            if S.size:
                rhs = u_prev[S] + phi[S] - A[np.ix_(S, np.flatnonzero(slip))] @ q[slip]
                q[S] = np.linalg.solve(A[np.ix_(S, S)], rhs)
            u = A @ q - phi
            du = u - u_prev
            over = stick & (np.abs(q) > p * (1.0 + 1e-12))
            wrong = slip & (np.sign(du) != sign) & (np.abs(du) > 1e-14 * max(a * a, 1e-300))
            if not over.any() and not wrong.any():
                break
            stick[over], sign[over] = False, -np.sign(q[over])
            stick[wrong] = True
        else:
            raise RuntimeError(f"slip_annulus: the stick/slip set of increment {m} (a = {a:g}) "
                               f"did not settle in max_sweeps = {max_sweeps} sweeps")
        u_prev = u
        st, sl = contact & stick, contact & ~stick
        if sl.any():
            ratios[m - 1] = (r[st].max() + half) / a if st.any() else 0.0
            inner[m - 1] = (r[sl].min() - half) / a
    return SlipAnnulus(a=edges[1:].copy(), stick_ratio=ratios, inner_slip_ratio=inner, r=r,
                       shear=q, pressure=p, sticking=stick & (r < 1.0), rings=n)
