"""Normal law with memory: p(h, h_min), k = -dp/dh|_{h_min}, A/A0(h, h_min) (issue 23).

Units: separations [mm], pressure [MPa], stiffness per nominal area [MPa/mm], dissipation per
nominal area [N/mm] (= MPa mm).

One history variable per point: h_min, the smallest mean-plane separation reached so far. At
h <= h_min the point is loading (the loading law, h_min := h); at h > h_min it is on the
elastic unloading/reloading branch of that h_min (``docs/unloading.md``: summits unload
elastically from their flattened shapes). Reloading retraces the branch up to h_min, then the
loading law: the branch is the elastic response of the interface at fixed h_min, with free
energy psi(h, h_min) = int_h^inf p(h', h_min) dh'. The work put in along any path is
psi + D(h_min), where

    D(h_min) = int_{h_min}^inf p_load dh - int_{h_min}^inf p(h, h_min) dh

is the energy dissipated by the summits' plastic flow, a function of h_min alone (0 for an
elastic population): the normal hysteresis of a point over an increment is D(h_min_new) -
D(h_min_old) >= 0, and over a closed cycle it equals the loop integral of p dh.

:class:`HistoryNormalLaw` is the tabulated law of the paper's elasto-plastic population
(:meth:`HistoryNormalLaw.elasto_plastic`) or the exactly reversible elastic one
(:meth:`HistoryNormalLaw.elastic`). Pure numpy (+ the micro layer).

Table (elasto-plastic). Loading branch: a ``NormalLaw.elasto_plastic``. Unloading branch:
rho(h_min, x) = ln p(h, h_min) - ln p_load(h_min), x = (h - h_min)/sigma (sigma the rms height)
and ln(a/a0) likewise, over [h_lo, h_table_end] x [0, X]:

* x: cubic Hermite on graded knots, with the model's own slopes (d rho/dx = -k sigma/p); the
  knots start uniform and every interval whose midpoint fails the check against the direct
  sums (``rough_contact.micro.unloading``) on the first rows is split (rho bends sharply at
  x ~ 0.3-0.5 on the high rows: the knots crowd there); the halves of an interval that
  failed by less than 8x the threshold are not checked again (error / 16 per halving, taken
  as / 8). O(1) look-up by a uniform table of cells no wider than the shortest interval.
* h_min: a uniform cubic B-spline in a row coordinate v, h_min = h_lo + span (v + beta v^2)/
  (1 + beta) (beta = 1: rows 3x denser at h_lo, where rho varies fastest with h_min), through
  rows uniform in v plus one ghost row beyond each end (not-a-knot conditions); the rows are
  doubled until the row midpoints pass the check at every other x knot. The coarse levels
  have no ghost rows (not-a-knot at the table's ends) and are judged at the interior row
  midpoints; a level that passes there gets its ghost rows and is checked at every row
  midpoint. Once two checks have shown an error ratio >= 8 per doubling, the next level's
  error is estimated as the last one / 8 (/ 16 for a cubic spline); if that passes, a check
  at every fourth x knot confirms it. Each half of rtol goes to one direction. Values between
  rows are a convex combination (B-spline weights >= 0) of four control rows, each a cubic
  Hermite curve in x.
* monotone by construction: every control row's Hermite data is projected onto the set of
  non-increasing curves (running minimum of the values, slopes clipped to <= 0 and scaled into
  the Fritsch-Carlson circle), so rho, and with it p, is non-increasing in h at every h_min:
  k >= 0 everywhere (the build also samples it, ``info["k_nonnegative"]``;
  ``info["monotone_projection_changes"]`` counts the data the projection changed).
* k is the exact h-derivative of the interpolant (consistent tangent at fixed h_min); the
  cells are stored as polynomial coefficients in (t_v, t_x), gathered per point with one take.
  Check points where p < tail p_load(h_min) are not checked. Beyond x = X the branch tapers to
  zero as the ``NormalLaw`` does (cubic, C1).
* h_min below the table: the branch shape of the first row, scaled by p_load(h_min);
  h_min >= h_table_end: nothing has yielded to within the table's tail: the loading law
  (reversible).
"""
from __future__ import annotations

import dataclasses
import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Optional, Protocol, Tuple, runtime_checkable

import numpy as np

from ..validation import check_integer, check_scalar
from .normal import NormalLaw

__all__ = ["HistoryNormalLawProtocol", "ReversalStiffnessProtocol", "HistoryNormalLaw",
           "UnloadingAboveLoadingWarning"]


@runtime_checkable
class HistoryNormalLawProtocol(Protocol):
    """A normal law with one history variable per point, h_min (smallest separation so far).

    ``rough_contact.interface.law.InterfaceLaw`` keeps h_min in its state when its normal law
    implements this protocol (the irreversible knob); a plain ``NormalLawProtocol`` stays
    reversible.
    """

    def evaluate_history(self, h: np.ndarray, h_min: np.ndarray, curvature: bool = False
                         ) -> Tuple[np.ndarray, ...]:
        """(p, k, a) or (p, k, a, dk/dh) at separations h (n,) [mm] after the smallest
        separation h_min (n,) [mm]; where h <= h_min the loading branch (the caller commits
        min(h, h_min)). k = -dp/dh at fixed h_min."""
        ...

    def normal_dissipation(self, h_min: np.ndarray) -> np.ndarray:
        """D(h_min) (n,) [N/mm]: energy per nominal area dissipated by loading to h_min, so
        that the work of any path is psi(h, h_min) + D(h_min); 0 where nothing yielded."""
        ...


@runtime_checkable
class ReversalStiffnessProtocol(Protocol):
    """A normal law with memory that states the stiffness at the reversal h = h_min.

    At h = h_min the normal tangent jumps from the loading tangent k_load(h_min) (h <= h_min)
    to the first unloading stiffness k_rev(h_min) = -dp/dh at h -> h_min+ (usually stiffer).
    p is continuous there, the normal tangent need not be: Newton copes with that kink. But a
    tangential stiffness k_T = c k_N would jump with it and make the interface traction itself
    discontinuous at h = h_min, exactly where every loaded point sits at the peak of a repeated
    load cycle. ``rough_contact.interface.law.InterfaceLaw`` therefore scales k_N by
    k_load(h_min)/k_rev(h_min) in the tangential stiffness on the unloading branch when the
    normal law implements this protocol (k_T continuous at the reversal; docs/unloading.md).
    """

    def reversal_stiffness(self, h_min: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """(k_load(h_min), k_rev(h_min)) (n,) [MPa/mm]: the loading tangent at h_min and the
        unloading branch's stiffness at h -> h_min+ (k_rev = k_load for a reversible law)."""
        ...


# Uniform cubic B-spline blending in h_min: on row cell i, f(tm) = sum_a b_a(tm) c[i + a] with
# b_a(tm) = sum_p _B[a, p] tm^p >= 0 and sum_a b_a = 1 (a convex combination of 4 control rows).
_B = np.array([[1.0, -3.0, 3.0, -1.0], [4.0, 0.0, -6.0, 3.0], [1.0, 3.0, 3.0, -3.0],
               [0.0, 0.0, 0.0, 1.0]]) / 6.0
_GRADING = 1.0       # row grading beta: row spacing grows 1 + 2 beta = 3x from h_lo to h_end
_HALF_X = 1.0 / 8.0  # estimated error ratio of a halved x cell (1/16 for cubic Hermite)
_HALF_ROWS = 1.0 / 8.0       # estimated error ratio of doubled rows (1/16 for the cubic spline)
_HALF_ROWS_RATE = 8.0        # ... used once two checks have shown at least this ratio
_BLOCK = 32768       # points per evaluation block: fewer numpy calls per point (8192: 10-15 % slower)


def _row_h(v, h0, span, beta):
    """h_min [mm] of the row coordinate v (rows uniform in v; v = 0: h0, v = 1: h0 + span):
    h_min = h0 + span (v + beta v^2)/(1 + beta), denser rows at small h_min."""
    v = np.asarray(v, float)
    return h0 + span * (v + beta * v * v) / (1.0 + beta)


def _row_v(h, h0, span, beta):
    """Inverse of ``_row_h`` on [h0, h0 + span] (h clipped to it)."""
    s = np.array(np.clip((np.asarray(h, float) - h0) * (1.0 / span), 0.0, 1.0), ndmin=1)
    if beta == 0.0:
        return s
    s *= 4.0 * beta * (1.0 + beta)
    s += 1.0
    np.sqrt(s, out=s)
    s -= 1.0
    s *= 1.0 / (2.0 * beta)
    return s


def _spline_controls(V):
    """Control rows (n+3, ...) of the uniform cubic B-spline through the row data V (n+1, ...)
    at uniform rows, with the not-a-knot end conditions (third derivative continuous at the
    second and the last-but-one row). n >= 3."""
    n = V.shape[0] - 1
    M = np.zeros((n + 3, n + 3))
    for i in range(n + 1):
        M[i, i:i + 3] = (1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0)
    M[n + 1, 0:5] = (-1.0, 4.0, -6.0, 4.0, -1.0)
    M[n + 2, n - 2:n + 3] = (-1.0, 4.0, -6.0, 4.0, -1.0)
    rhs = np.zeros((n + 3,) + V.shape[1:])
    rhs[:n + 1] = V
    return np.linalg.solve(M, rhs.reshape(n + 3, -1)).reshape(rhs.shape)


def _monotone_controls(v, d, xk):
    """Project Hermite data (values v, x-slopes d; (n_c, n_k)) of every control row into the
    set of non-increasing cubic Hermite curves: values made non-increasing along x (running
    minimum), slopes clipped to <= 0 (0 next to a flat secant) and scaled into the
    Fritsch-Carlson circle alpha^2 + beta^2 <= 9. Returns (v, d, number of data changed)."""
    v2 = np.minimum.accumulate(v, axis=1)
    sec = np.diff(v2, axis=1) / np.diff(xk)
    d2 = np.minimum(d, 0.0)
    flat = sec >= 0.0
    d2[:, :-1] = np.where(flat, 0.0, d2[:, :-1])
    d2[:, 1:] = np.where(flat, 0.0, d2[:, 1:])
    with np.errstate(divide="ignore", invalid="ignore"):
        al = np.where(flat, 0.0, d2[:, :-1] / sec)
        be = np.where(flat, 0.0, d2[:, 1:] / sec)
        r = np.hypot(al, be)
        tau = np.where(r > 3.0, 3.0 / r, 1.0)
    fac = np.ones_like(d2)
    fac[:, :-1] = tau
    fac[:, 1:] = np.minimum(fac[:, 1:], tau)
    d2 = d2 * fac
    changed = int(np.count_nonzero(v2 != v) + np.count_nonzero(d2 != d))
    return v2, d2, changed


def _cells(v, d, xk):
    """Per-cell polynomial coefficients (n_m, n_x, 16), index 4 p + q of tm^p tx^q, of the
    B-spline (h_min) x cubic Hermite (x) surface with control rows v, d (n_m + 3, n_x + 1)."""
    dx = np.diff(xk)
    y0, y1 = v[:, :-1], v[:, 1:]
    m0, m1 = d[:, :-1] * dx, d[:, 1:] * dx
    dy = y1 - y0
    H = np.stack([y0, m0, 3.0 * dy - 2.0 * m0 - m1, -2.0 * dy + m0 + m1], axis=-1)
    n_m = v.shape[0] - 3
    Hw = np.stack([H[a:a + n_m] for a in range(4)], axis=0)        # (4, n_m, n_x, 4)
    C = np.einsum("ap,amjq->mjpq", _B, Hw)
    return C.reshape(n_m, dx.size, 16)


def _poly(cc, tm, tx, second=False):
    """rho, d rho/dtx (and d2 rho/dtx2) and ln(a/a0) of the gathered cell coefficients cc
    (32, n) at (tm, tx) (Horner in tm for both tables at once, then in tx); ln(a/a0) is None
    if cc holds rho's 16 coefficients only."""
    return _tx_horner(_tm_horner(cc, tm), tx, second)


def _tm_horner(cc, tm):
    """The cells' polynomials in tx (k, 4, n) at the row coordinates tm (n,): Horner in tm of
    the gathered coefficients cc (16 k, n), k = 2 (rho, ln a/a0) or 1 (rho)."""
    c4 = cc.reshape(-1, 4, 4, tm.size)                    # [k, p, q, point]
    g = c4[:, 3] * tm
    g += c4[:, 2]
    g *= tm
    g += c4[:, 1]
    g *= tm
    g += c4[:, 0]
    return g


def _tx_horner(g, tx, second=False):
    """rho, d rho/dtx (and d2 rho/dtx2) and ln(a/a0) (None if k = 1) of the polynomials in tx
    g (k, 4, n) at tx (n,)."""
    v = g[:, 3] * tx
    v += g[:, 2]
    v *= tx
    v += g[:, 1]
    v *= tx
    v += g[:, 0]
    dv = g[0, 3] * (3.0 * tx)
    dv += 2.0 * g[0, 2]
    dv *= tx
    dv += g[0, 1]
    la = v[1] if v.shape[0] == 2 else None
    if second:
        d2 = g[0, 3] * (6.0 * tx)
        d2 += 2.0 * g[0, 2]
        return v[0], dv, la, d2
    return v[0], dv, la


def _hermite_mid(v, d, xk):
    """Value and x-slope of the cubic Hermite curves (rows of v, d) at the cell midpoints."""
    dx = np.diff(xk)
    y0, y1, m0, m1 = v[:, :-1], v[:, 1:], d[:, :-1], d[:, 1:]
    val = 0.5 * (y0 + y1) + 0.125 * dx * (m0 - m1)
    der = 1.5 * (y1 - y0) / dx - 0.25 * (m0 + m1)
    return val, der


def _rel_errors(r, dr, la, ref, tail):
    """Worst relative error of p, k, A/A0 (table rho, d rho/dx, ln a/a0 against the model's
    (rho, d rho/dx, ln a/a0)), over the points where the model's rho >= ln(tail)."""
    rr, drr, lar = ref
    use = rr >= math.log(tail)
    if not use.any():
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ek = np.where(drr < 0, np.abs(np.exp(r - rr) * dr / drr - 1.0), np.inf)
    e = np.maximum.reduce([np.abs(np.expm1(r - rr)), ek, np.abs(np.expm1(la - lar))])
    return float(e[use].max())


@dataclass(frozen=True, eq=False)
class HistoryNormalLaw:
    """Irreversible normal law of a rough interface (module doc); implements
    :class:`HistoryNormalLawProtocol` and, for the loading branch and seating, the
    ``NormalLaw`` interface (``evaluate(h)`` is the loading law, ``separation_for_pressure``
    its inverse).

    Build it with :meth:`elastic` (exactly reversible: h_min has no effect) or
    :meth:`elasto_plastic` (the tabulated population with memory).
    """

    loading: NormalLaw
    rtol: Optional[float]
    sigma: float = 1.0
    _hm0: float = 0.0                   # first row h_min [mm]
    _span: float = 1.0                  # last row - first row [mm]
    _beta: float = 0.0                  # row grading (rows uniform in v, module doc)
    _X: float = 0.0                     # end of the x table [-]
    _xk: Optional[np.ndarray] = None    # (n_x + 1,) x knots (graded) [-]
    _xinv: Optional[np.ndarray] = None  # (n_x,) 1/knot spacing
    _xinv_h: Optional[np.ndarray] = None  # (n_x,) 1/(knot spacing sigma) [1/mm]
    _xnext: Optional[np.ndarray] = None  # (n_x,) right end of each x cell (inf for the last)
    _lut: Optional[np.ndarray] = None   # O(1) x look-up: cell index per LUT cell
    _lut_inv: float = 1.0               # LUT cells per unit x
    _CF: Optional[np.ndarray] = None    # (32, n_m n_x) cell coefficients, row 16 k + 4 p + q:
    #                                     k = 0 rho, 1 ln(a/a0); of tm^p tx^q
    _n_m: int = 0                       # row cells
    _D: Optional[np.ndarray] = None     # (n_m + 1,) D(h_min) at the rows [N/mm]
    _dD: Optional[np.ndarray] = None    # (n_m + 1,) dD/dh_min at the rows (monotone slopes)
    _IL: float = 0.0                    # int exp(rho(row 0, x)) dx incl. taper [-]
    _capped: bool = False               # the sums went above the loading branch: cap by it
    info: dict = field(default_factory=dict, compare=False)   # build statistics, not identity
    _memo: dict = field(default_factory=dict, compare=False, repr=False)  # h_min data, not identity

    def __getstate__(self):
        """Pickle without the remembered h_min data."""
        state = dict(self.__dict__)
        state.pop("_memo", None)
        return state

    def __setstate__(self, state):
        """Unpickle; a table pickled by the session-3 code (uniform bicubic grid, keys _C, _dm)
        is refused: its cells would be read as a reversible law."""
        if "_C" in state or "_dm" in state:
            raise ValueError("HistoryNormalLaw: this pickle holds a table in the older format "
                             "(uniform bicubic grid, before the graded B-spline table): it "
                             "cannot be read; delete the cached file and rebuild the law")
        for key, value in state.items():
            object.__setattr__(self, key, value)
        object.__setattr__(self, "_memo", {})

    # ------------------------------------------------------------ NormalLaw interface
    @property
    def reversible(self) -> bool:
        return self._CF is None

    @property
    def h_min(self) -> float:
        return self.loading.h_min

    @property
    def h_table_end(self) -> float:
        return self.loading.h_table_end

    @property
    def h_max(self) -> float:
        return self.loading.h_max

    def evaluate(self, h, curvature: bool = False):
        """The loading law (``NormalLaw.evaluate``): the response of a virgin interface."""
        return self.loading.evaluate(h, curvature)

    def separation_for_pressure(self, p):
        """Inverse of the loading law (seating a virgin interface)."""
        return self.loading.separation_for_pressure(p)

    def below_validity(self, h):
        return self.loading.below_validity(h)

    # ------------------------------------------------------------ constructors
    @classmethod
    def elastic(cls, surface, E_star: float, rtol: float = 1e-4, **kwargs) -> "HistoryNormalLaw":
        """Elastic population: the reversible ``NormalLaw.elastic`` (h_min has no effect,
        D = 0): loading, unloading and reloading coincide exactly."""
        t0 = time.perf_counter()
        law = NormalLaw.elastic(surface, E_star, rtol, **kwargs)
        return cls(loading=law, rtol=rtol, sigma=surface.rq,
                   info={"build_seconds": time.perf_counter() - t0, "reversible": True})

    @classmethod
    def elasto_plastic(cls, surface, material, rtol: float = 1e-4, *, loading=None,
                       n_quad: int = 16, n_t: int = 16, n_zeta: int = 24,
                       n_rows: int = 4, n_x: int = 8,
                       tail: float = 1e-12, max_points: int = 20000,
                       max_seconds: float = 600.0, strict: bool = True) -> "HistoryNormalLaw":
        """Table of the elasto-plastic population with memory (reading "consistent").

        Args:
            surface: SpectralMoments; material: AsperityMaterial (resolved on surface here).
            rtol: relative accuracy of p, k and A/A0 on the unloading branch against the direct
                sums (``micro.unloading._row_sums`` with the same n_quad, n_t, n_zeta), in
                [1e-8, 0.1];
                half of it is given to the x direction (cell midpoints on the first rows), half
                to the h_min direction (row midpoints at every other x knot).
            loading: a prebuilt ``NormalLaw.elasto_plastic`` of the same surface and material
                (its build time is then not counted); None builds one at rtol.
            n_quad, n_t, n_zeta: quadrature of the direct sums (K nodes per panel, height
                nodes per half-panel, zeta nodes per half; ``micro.unloading._row_sums``). With
                n_zeta = n_quad = 16 the sums are off by up to 9e-4 high above the mean plane
                (h_min ~ 7 sigma, psi = 2); 24 zeta nodes bring them to <= 4e-6.
            n_rows: initial number of h_min intervals (>= 3; doubled as needed); these rows
                also decide the graded x knots.
            n_x: initial number of uniform x intervals (>= 2; a failing interval is split).
            tail: the x table ends where the first row's p/p_load(h_min) < tail; check points
                below tail are not checked.
            max_points, max_seconds: budget (direct-sum points; wall time [s]).
            strict: False returns the last table when rtol or the budget is not met
                (``info["worst_error"]`` says what was reached).
        Raises:
            ValueError: bad arguments; RuntimeError: rtol not reached within the budget.
        """
        from ..micro import unloading as U
        t0 = time.perf_counter()
        rtol = check_scalar("rtol", rtol, lo=1e-8, hi=0.1, lo_open=False, hi_open=False)
        tail = check_scalar("tail", tail, lo=0.0, hi=1e-2)
        for name, v, lo in (("n_rows", n_rows, 3), ("n_x", n_x, 2), ("n_quad", n_quad, 2),
                            ("n_t", n_t, 2), ("n_zeta", n_zeta, 2)):
            check_integer(name, v, lo=lo)
        mat = material.resolve(surface)
        if loading is None:
            loading = NormalLaw.elasto_plastic(surface, mat, rtol)
        t_load = time.perf_counter() - t0
        t1 = time.perf_counter()
        sig = surface.rq
        hL, hE = loading.h_min, loading.h_table_end
        cache: dict = {}
        n_pts = [0]
        n_capped = [0]
        cap_worst = [0.0]               # largest ln(p_unload / p_load(h)) met (the warning)

        def model(hms, xs):
            """(rho, d rho/dx, ln a - ln a0, d ln a/dx) (4, len(hms), len(xs)), cached per
            point; one direct-sum call per row for the points not yet known (the sums at a
            point do not depend on the other points of the call), the row's start (u = 0:
            p0, a0) in its first call only."""
            out = np.empty((4, len(hms), len(xs)))
            for i, hm in enumerate(hms):
                row = cache.setdefault(round(float((hm - hL) / (hE - hL)), 12), {})
                need = [x for x in xs if round(float(x), 12) not in row]
                if need:
                    if time.perf_counter() - t1 > max_seconds or n_pts[0] > max_points:
                        raise _Budget()
                    start = row.get("start")
                    uu = np.asarray(need) * sig
                    if start is None:
                        uu = np.concatenate([[0.0], uu])
                    p, k, a, da = U._row_sums(surface, mat, float(hm), uu, n_quad, n_t, n_zeta)
                    n_pts[0] += uu.size
                    p = np.maximum(p, 1e-300)
                    a = np.maximum(a, 1e-300)
                    if start is None:
                        start = row["start"] = (p[0], a[0])
                        p, k, a, da = p[1:], k[1:], a[1:], da[1:]
                        uu = uu[1:]
                    vals = np.stack([np.log(p / start[0]), -k / p * sig,
                                     np.log(a / start[1]), -da / a * sig])
                    n_capped[0] += _count_above_loading(vals[0], loading, float(hm), uu,
                                                        rtol, tail, worst=cap_worst)
                    for x, col in zip(need, vals.T):
                        row[round(float(x), 12)] = tuple(float(c) for c in col)
                for j, x in enumerate(xs):
                    out[:, i, j] = row[round(float(x), 12)]
            return out

        # x range: the first row (slowest decay) down to tail, one direct-sum call
        Xs = 2.0 * 1.5 ** np.arange(9)
        try:
            r0 = model([hL], Xs)[0, 0]
        except _Budget:
            raise RuntimeError("HistoryNormalLaw: budget exhausted while scanning the x range")
        below = np.flatnonzero(r0 <= math.log(tail))
        X = float(Xs[below[0]] if below.size else Xs[-1])
        nm = int(n_rows)
        xk = np.linspace(0.0, X, int(n_x) + 1)
        worst_x = worst_m = np.inf
        table = None
        levels: list = []               # (row intervals or "x", check error, points so far)
        stage = "x"
        try:
            # 1. graded x knots: split every x cell whose midpoint fails on any of the first rows
            span, beta = hE - hL, _GRADING
            rows0 = _row_h(np.linspace(0.0, 1.0, nm + 1), hL, span, beta)
            passed: set = set()
            worst_pass = 0.0                       # worst error of the cells that passed
            while True:
                m = model(rows0, xk)
                xm = 0.5 * (xk[:-1] + xk[1:])
                todo = [j for j in range(xm.size) if round(float(xm[j]), 12) not in passed]
                worst_x = worst_pass
                split = []
                if todo:
                    ref = model(rows0, xm[todo])
                    v, dv = _hermite_mid(m[0], m[1], xk)
                    va, _ = _hermite_mid(m[2], m[3], xk)
                    for c, j in enumerate(todo):
                        e = _rel_errors(v[:, j], dv[:, j], va[:, j], ref[:3, :, c], tail)
                        worst_x = max(worst_x, e)
                        if e > 0.5 * rtol:
                            split.append(xm[j])
                            # the halves of a cubic Hermite cell with exact slopes: error
                            # / 16; taken as / 8: halves of a cell within 8x of the
                            # threshold are not checked
                            if e * _HALF_X <= 0.5 * rtol:
                                for mid in (0.5 * (xk[j] + xm[j]), 0.5 * (xm[j] + xk[j + 1])):
                                    passed.add(round(float(mid), 12))
                                worst_pass = max(worst_pass, e * _HALF_X)
                        else:
                            passed.add(round(float(xm[j]), 12))
                            worst_pass = max(worst_pass, e)
                if not split:
                    break
                xk = np.sort(np.concatenate([xk, split]))
            # 2. rows: doubled until the row midpoints pass at every other x knot (and the
            #    last); the checked points become knots of the next rows if they fail
            stage = "rows"
            levels.append(("x", worst_x, n_pts[0]))
            xc = xk[np.unique(np.r_[np.arange(0, xk.size, 2), xk.size - 1])]
            xs = xk[np.unique(np.r_[np.arange(0, xk.size, 4), xk.size - 1])]    # sparse
            checks: list = []               # full checks (nm, error)
            while True:
                # rows uniform in v; the coarse levels without ghost rows (not-a-knot at the
                # table's ends) and checked at the interior row midpoints; a candidate for
                # the table gets one ghost row beyond each end (interior spline conditions at
                # the ends: the end intervals' error was 3x the interior's without them) and
                # is checked at every row midpoint
                v = np.arange(nm + 1) / nm
                rows = _row_h(v, hL, span, beta)
                hmid = _row_h((np.arange(nm) + 0.5) / nm, hL, span, beta)

                def check(law, xq, mids):
                    hq = hmid[mids]
                    r, dr, la = law._rho(np.repeat(hq, xq.size), np.tile(xq, hq.size))
                    ref = model(hq, xq)
                    return _rel_errors(r, dr, la, [q.ravel() for q in ref[:3]], tail)

                def ghosted():
                    hm = _row_h(np.arange(-1, nm + 2) / nm, hL, span, beta)
                    m = model(hm, xk)
                    law = cls._assemble(loading, rtol, sig, hm, xk, m, beta, energy=False)
                    return (hm, m, True), law

                every = np.arange(nm)
                # embedded estimate: the error of the last level / 16 (rows doubled, cubic),
                # taken as / 8, once the last two checks have shown that rate (>= 8); if it
                # passes, the table's check at every fourth x knot only confirms it
                est = None
                if len(checks) >= 2 and checks[-2][1] >= _HALF_ROWS_RATE * checks[-1][1]:
                    est = checks[-1][1] * _HALF_ROWS
                if est is not None and est <= 0.5 * rtol:
                    table, law = ghosted()
                    worst_m = check(law, xs, every)
                    levels.append((nm, worst_m, n_pts[0], "sparse", est))
                    if worst_m <= 0.5 * rtol:
                        worst_m = max(worst_m, est)
                        break
                    worst_m = check(law, xc, every)
                    levels.append((nm, worst_m, n_pts[0]))
                    if worst_m <= 0.5 * rtol:
                        break
                    checks.append((nm, worst_m))
                    nm *= 2
                    continue
                m = model(rows, xk)
                law = cls._assemble(loading, rtol, sig, rows, xk, m, beta, energy=False,
                                    ghosts=False)
                table = (rows, m, False)
                inner = every[1:-1] if nm > 2 else every
                worst_m = check(law, xc, inner)
                checks.append((nm, worst_m))
                levels.append((nm, worst_m, n_pts[0], "interior"))
                if worst_m <= 0.5 * rtol:
                    table, law = ghosted()
                    worst_m = check(law, xc, every)
                    levels.append((nm, worst_m, n_pts[0]))
                    if worst_m <= 0.5 * rtol:
                        break
                nm *= 2
        except _Budget:
            if strict or table is None:
                raise RuntimeError(
                    f"HistoryNormalLaw: budget (max_points = {max_points}, max_seconds = "
                    f"{max_seconds}) exhausted at rtol = {rtol} while refining {stage} "
                    f"({nm} rows intervals x {xk.size - 1} x intervals; x check error "
                    f"{worst_x:.2g}): loosen rtol or raise the budget") from None
        hm, m, gh = table
        law = cls._assemble(loading, rtol, sig, hm, xk, m, beta, capped=n_capped[0] > 0,
                            ghosts=gh)
        ok = law._check_monotone()
        worst = worst_x + worst_m
        if n_capped[0]:
            warnings.warn(
                f"HistoryNormalLaw: the summits' unloading sums exceed the loading law at "
                f"{n_capped[0]} of {n_pts[0]} table points (up to a factor "
                f"{math.exp(cap_worst[0]):.4g}): with these yield data one summit's load jumps "
                f"up where it starts to yield (Zhao-Maietta-Chang at omega_c above the Hertz "
                f"load), and its elastic unloading from the jump would return more work than "
                f"the loading took. The unloading branch is capped by the loading branch "
                f"there (no memory, less normal dissipation); docs/unloading.md",
                UnloadingAboveLoadingWarning, stacklevel=2)
        law.info.update({"capped_points": int(n_capped[0])})
        law.info.update({"build_seconds": time.perf_counter() - t0, "loading_seconds": t_load,
                         "history_seconds": time.perf_counter() - t1, "rows": law._n_m + 1,
                         "x_knots": xk.size, "X": X, "model_points": n_pts[0],
                         "worst_error": float(worst), "worst_error_x": float(worst_x),
                         "worst_error_h_min": float(worst_m), "n_quad": n_quad, "n_t": n_t,
                         "levels": levels,
                         "n_zeta": n_zeta,
                         "k_nonnegative": ok, "reversible": False,
                         "converged": bool(worst_x <= 0.5 * rtol and worst_m <= 0.5 * rtol)})
        return law

    @classmethod
    def _assemble(cls, loading, rtol, sig, hm, xk, m, beta, energy=True, capped=False,
                  ghosts=True):
        """The law from row data m (4, n_m + 3, n_knots) on the rows hm (uniform in v, the
        first and the last a ghost row beyond the table) and the x knots xk; ghosts=False:
        m (4, n_m + 1, n_knots) on the table's rows only (not-a-knot at the table's ends:
        the coarse levels of the build)."""
        g = 1 if ghosts else 0
        n_m, n_x = hm.size - 1 - 2 * g, xk.size - 1
        cv, cd, ch1 = _monotone_controls(*_spline_controls(np.stack([m[0], m[1]], 1)
                                                             ).transpose(1, 0, 2), xk)
        av, ad, ch2 = _monotone_controls(*_spline_controls(np.stack([m[2], m[3]], 1)
                                                             ).transpose(1, 0, 2), xk)
        # the spline through all rows; cells of the table's rows only (ghost cells dropped)
        sl = slice(g, cv.shape[0] - g)
        CF = np.concatenate([_cells(cv[sl], cd[sl], xk), _cells(av[sl], ad[sl], xk)], axis=2)
        CF = np.ascontiguousarray(CF.reshape(n_m * n_x, 32).T)
        dxk = np.diff(xk)
        w = float(dxk.min())
        n_lut = int(round(float(xk[-1]) / w))
        lut = np.clip(np.searchsorted(xk, (np.arange(n_lut + 1) + 0.5) * w, side="right") - 1,
                      0, n_x - 1).astype(np.intp)
        nxt = np.concatenate([xk[1:-1], [np.inf]])
        hm = hm[g:hm.size - g]
        law = cls(loading=loading, rtol=rtol, sigma=sig, _hm0=float(hm[0]),
                  _span=float(hm[-1] - hm[0]), _beta=float(beta),
                  _X=float(xk[-1]), _xk=xk, _xinv=1.0 / dxk, _xinv_h=1.0 / (dxk * sig),
                  _xnext=nxt, _lut=lut,
                  _lut_inv=1.0 / w, _CF=CF, _n_m=n_m, _capped=bool(capped),
                  info={"monotone_projection_changes": ch1 + ch2})
        if not energy:
            return law
        # recoverable energy per row: sigma p0 int exp(rho) dx (Gauss-Legendre per x cell, on
        # the interpolant itself) + the taper's p_X L/4
        g, wg = np.polynomial.legendre.leggauss(8)
        g, wg = 0.5 * (g + 1.0), 0.5 * wg
        xq = (xk[:-1, None] + dxk[:, None] * g).ravel()
        wq = (dxk[:, None] * wg).ravel()
        I = np.zeros(n_m + 1)
        if capped:      # the capped branch has a kink inside a cell: 8 Gauss panels per cell
            sub = (np.arange(8)[:, None] + g) / 8.0
            xq8 = (xk[:-1, None, None] + dxk[:, None, None] * sub).ravel()
            wq8 = np.broadcast_to((dxk[:, None, None] * wg / 8.0), (dxk.size, 8, g.size)).ravel()
        for r in range(n_m + 1):
            vX, dvX, _ = law._rho(np.full(1, hm[r]), np.full(1, xk[-1]))
            pX, kX = math.exp(vX[0]), -math.exp(vX[0]) * dvX[0]      # per unit x
            if capped:
                # the branch as evaluated (never above the loading branch), taper included,
                # by quadrature of evaluate_history itself
                L = 3.0 * pX / kX if kX > 0 else 1.0
                xs = np.concatenate([xq8, xk[-1] + L * sub.ravel()])
                ws = np.concatenate([wq8, np.tile(L * wg / 8.0, 8)])
                pu = law.evaluate_history(hm[r] + sig * xs, np.full(xs.size, hm[r]))[0]
                I[r] = np.sum(ws * pu) / max(loading.evaluate(hm[r:r + 1])[0][0], 1e-300)
                continue
            v, _, _ = law._rho(np.full(xq.size, hm[r]), xq)
            I[r] = np.sum(wq * np.exp(v))
            if kX > 0:
                I[r] += pX * (3.0 * pX / kX) / 4.0
        p0 = loading.evaluate(hm)[0]
        E_rec = sig * p0 * I
        W = _work_to(loading, hm)
        D = np.maximum(W - E_rec, 0.0)
        D[-1] = 0.0
        dD = _pchip_slopes(np.linspace(0.0, 1.0, n_m + 1), D)      # dD/dv
        object.__setattr__(law, "_D", D)
        object.__setattr__(law, "_dD", dD)
        object.__setattr__(law, "_IL", float(I[0]))
        law.info.update({"recoverable_energy_rows": E_rec, "work_rows": W})
        return law

    def _cell(self, hm, x):
        """Cell index and local coordinates (tm, tx) of the points (h_min, x), x in [0, X]."""
        um = _row_v(hm, self._hm0, self._span, self._beta)
        um *= self._n_m
        i = np.minimum(um.astype(np.intp), self._n_m - 1)
        um -= i
        j = self._lut.take((x * self._lut_inv).astype(np.intp))
        j += x >= self._xnext.take(j)
        tx = x - self._xk.take(j)
        tx *= self._xinv.take(j)
        i *= self._xinv.size
        i += j
        return i, j, um, tx

    def _rho(self, hm, x):
        """(rho, d rho/dx, ln a/a0) of the table at (h_min, x), x clipped to [0, X]."""
        x = np.clip(x, 0.0, self._X)
        c, j, tm, tx = self._cell(np.asarray(hm, float), x)
        r, dr, la = _poly(self._CF.take(c, axis=1), tm, tx)
        return r, dr * self._xinv.take(j), la

    def _check_monotone(self, n: int = 200_000) -> bool:
        rng = np.random.default_rng(1)
        hm = rng.uniform(self.h_min, self.h_table_end, n)
        h = hm + rng.uniform(0.0, 1.2 * self._X * self.sigma, n)
        _, k, _ = self.evaluate_history(h, hm)
        return bool(np.all(k >= 0.0))

    # ------------------------------------------------------------ evaluation
    def evaluate_history(self, h, h_min, curvature: bool = False, area: bool = True):
        """(p [MPa], k = -dp/dh|_{h_min} [MPa/mm], A/A0 [-][, dk/dh [MPa/mm^2]]) at
        separations h after the smallest separation h_min (broadcast; h <= h_min: loading;
        h_min >= h_table_end: the loading law at h). ``area=False`` skips A/A0 (returned as
        None; p, k, dk/dh unchanged): a Newton iteration needs p and k only.

        What an unloading point needs of its h_min alone (p_load(h_min), A0, the row cell and
        its local coordinate), and its cell polynomials in x while it stays in its x cell, are
        remembered for the last h_min array seen (a Newton loop calls with the same committed
        h_min every iteration): the values are those of a first call, bit for bit, only not
        recomputed."""
        h = np.asarray(h, dtype=float)
        hmn = np.asarray(h_min, dtype=float)
        if np.isnan(h).any() or np.isnan(hmn).any():
            raise ValueError("h or h_min contains NaN: valid range (-inf, inf] mm")
        h, hmn = np.broadcast_arrays(h, hmn)
        shape = h.shape
        h, hmn = h.ravel(), hmn.ravel()
        if self._CF is None:                      # reversible: h_min has no effect
            res = [v.reshape(shape) for v in self.loading.evaluate(h, curvature)]
            if not area:
                res[2] = None
            return tuple(res)
        n = h.size
        out = [np.empty(n) for _ in range(4 if curvature else 3)]
        memo = self._memo_of(hmn)
        h_end = self.h_table_end
        load_block = (self.loading if area else self._loading_without_area())._eval_block

        def ob4(o):                               # p, k, a, dk (None without curvature)
            return (o[0], o[1], o[2], o[3] if curvature else None)

        for s in range(0, n, _BLOCK):             # blocks that stay in cache
            e = min(s + _BLOCK, n)
            hb, mb = h[s:e], hmn[s:e]
            ob = [o[s:e] for o in out]
            unm = hb > mb
            unm &= mb < h_end
            un = np.flatnonzero(unm)
            if not un.size:
                load_block(hb, *ob4(ob))
                continue
            if memo.p0 is not None:
                # h_min data remembered: the loading law only at the loading points
                ld = np.flatnonzero(~unm)
                if ld.size:
                    tmp = [np.empty(ld.size) for _ in ob]
                    load_block(hb.take(ld), *ob4(tmp))
                    for o, t in zip(ob, tmp):
                        o[ld] = t
                ug = un + s
                p0, a0 = memo.p0.take(ug), memo.a0.take(ug)
                base, tm = memo.base.take(ug), memo.tm.take(ug)
                kept = (memo, ug)
            else:
                # one loading evaluation per point: at h, or at h_min where unloading (p0, a0)
                load_block(np.where(unm, mb, hb), *ob4(ob))
                p0, a0 = ob[0].take(un), ob[2].take(un)
                base, tm = self._row_cell(mb.take(un))
                kept = None
            self._unload(hb.take(un), mb.take(un), p0, a0, base, tm, ob, un, curvature, area,
                         kept)
        res = [v.reshape(shape) for v in out]
        if not area:
            res[2] = None
        return tuple(res)

    def _loading_without_area(self) -> NormalLaw:
        """The loading law that skips A/A0 (a = 0): the same p, k, dk/dh."""
        law = self._memo.get("loading_without_area")
        if law is None:
            law = dataclasses.replace(self.loading, has_area=False)
            self._memo["loading_without_area"] = law
        return law

    def _memo_of(self, hmn) -> "_HminMemo":
        """The remembered h_min data of this h_min array: a new record (h_min only) if it is
        not the array of the last call; at the second call with it, its data at every point
        (from then on an unloading point skips the loading law at h_min and the row look-up)."""
        memo = self._memo.get("h_min")
        if memo is None or memo.h_min.shape != hmn.shape or not np.array_equal(memo.h_min, hmn):
            memo = _HminMemo(hmn)
            self._memo["h_min"] = memo
        elif memo.p0 is None:
            hm = np.minimum(memo.h_min, self.h_table_end)       # only h_min < h_end is used
            p0, a0 = np.empty(hm.size), np.empty(hm.size)
            for s in range(0, hm.size, _BLOCK):
                e = min(s + _BLOCK, hm.size)
                self.loading._eval_block(hm[s:e], p0[s:e], np.empty(e - s), a0[s:e], None)
            memo.base, memo.tm = self._row_cell(hm)
            memo.cell = np.full(hm.size, -1, dtype=np.intp)
            memo.G = np.empty((2, 4, hm.size))
            memo.p0, memo.a0 = p0, a0
        return memo

    def _row_cell(self, hm):
        """First cell index (row cell i times the x cells) and local row coordinate tm of h_min."""
        um = _row_v(hm, self._hm0, self._span, self._beta)
        um *= self._n_m
        i = np.minimum(um.astype(np.intp), self._n_m - 1)
        um -= i
        i *= self._xinv.size
        return i, um

    def _unload(self, h, hm, p0, a0, base, tm, out, idx, curvature, area=True, kept=None):
        """The unloading branch at the points idx (h > h_min, h_min < h_table_end) of out;
        p0, a0: the loading law at h_min; base, tm: ``_row_cell(h_min)``; ``area=False``:
        out[2] is left as it is (rho's cells only); kept = (memo, point indices): the
        points' polynomials in tx are taken from the memo where the point is in the same
        cell as at its last evaluation (the same values: the same cell and tm), else made
        and kept there."""
        sig = self.sigma
        x = h - hm
        x *= 1.0 / sig
        xc = np.minimum(x, self._X)
        j = self._lut.take((xc * self._lut_inv).astype(np.intp))
        j += xc >= self._xnext.take(j)
        tx = xc - self._xk.take(j)
        tx *= self._xinv.take(j)
        c = base + j
        if kept is None:
            g = _tm_horner((self._CF if area else self._CF[:16]).take(c, axis=1), tm)
        else:
            memo, ug = kept
            miss = np.flatnonzero(memo.cell.take(ug) != c)
            if miss.size:
                um, cm = ug.take(miss), c.take(miss)
                memo.G[:, :, um] = _tm_horner(self._CF.take(cm, axis=1), tm.take(miss))
                memo.cell[um] = cm
            g = memo.G.take(ug, axis=2) if area else memo.G[0].take(ug, axis=1)[None]
        r = _tx_horner(g, tx, second=curvature)
        p = np.exp(r[0])
        p *= p0
        s = self._xinv_h.take(j)
        d1 = r[1]
        d1 *= s                                   # d rho/dh = d rho/dtx dtx/dh
        k = p * d1
        np.negative(k, out=k)
        if area:
            a = np.exp(r[2])
            a *= a0
        else:
            a = np.zeros(h.size)
        if curvature:
            dk = r[3] * s
            dk *= s
            dk += d1 * d1
            dk *= p
            np.negative(dk, out=dk)
        if x.max() > self._X:
            tp = np.flatnonzero(x > self._X)
            pe, ke, ae = p[tp], k[tp], a[tp]
            # taper length 3 p/k at X (C1); sigma where k(X) = 0 (a flat tail: p(X), far
            # below the tail ratio, may have underflowed to 0)
            with np.errstate(divide="ignore", invalid="ignore"):
                L = np.where(ke > 0.0, 3.0 * pe / ke, sig)
            t = np.clip((x[tp] - self._X) * sig / L, 0.0, 1.0)
            p[tp] = pe * (1 - t) ** 3
            k[tp] = 3.0 * pe / L * (1 - t) ** 2
            a[tp] = ae * (1 - t) ** 3
            if curvature:
                dk[tp] = -6.0 * pe / (L * L) * (1 - t)
        if self._capped:
            # never above the loading branch at the same separation (build warning): there
            # the point follows the loading branch (values and tangent) without memory
            lp, lk, la = np.empty(h.size), np.empty(h.size), np.empty(h.size)
            ld = np.empty(h.size) if curvature else None
            self.loading._eval_block(h, lp, lk, la, ld)
            up = np.flatnonzero(p > lp)
            if up.size:
                p[up], k[up], a[up] = lp[up], lk[up], la[up]
                if curvature:
                    dk[up] = ld[up]
        out[0][idx], out[1][idx] = p, k
        if area:
            out[2][idx] = a
        if curvature:
            out[3][idx] = dk

    def reversal_stiffness(self, h_min) -> Tuple[np.ndarray, np.ndarray]:
        """(k_load(h_min), k_rev(h_min)) [MPa/mm] (``ReversalStiffnessProtocol``): the loading
        tangent and the stiffness of the unloading branch of h_min at its start, the limit of
        ``evaluate_history(h, h_min)[1]`` as h -> h_min+ (the table's d rho/dx at x = 0; with
        a capped table the larger of the two, as the cap then takes the loading branch). Equal
        for the reversible law and where h_min >= h_table_end."""
        hm = np.asarray(h_min, dtype=float)
        flat = hm.ravel()
        p0, kl, _ = self.loading.evaluate(flat)
        kr = np.array(kl, dtype=float, copy=True)
        if self._CF is not None:
            inside = np.flatnonzero(flat < self.h_table_end)
            if inside.size:
                # row cell and tm of h_min; x = 0 is the first x cell (tx = 0): only the four
                # coefficients of tm^p tx^1 (p = 0..3) of rho are gathered
                tm = _row_v(flat.take(inside), self._hm0, self._span, self._beta)
                tm *= self._n_m
                i = np.minimum(tm.astype(np.intp), self._n_m - 1)
                tm -= i
                i *= self._xinv.size
                cc = self._CF[1:16:4].take(i, axis=1)
                d = ((cc[3] * tm + cc[2]) * tm + cc[1]) * tm + cc[0]   # d rho/dtx at tx = 0
                k = -p0.take(inside) * d * self._xinv_h[0]
                kr[inside] = np.maximum(k, kl.take(inside)) if self._capped else k
        return kl.reshape(hm.shape), kr.reshape(hm.shape)

    def normal_dissipation(self, h_min) -> np.ndarray:
        """D(h_min) [N/mm] (module doc): cubic Hermite with monotone slopes through the rows'
        values; below the table the first row's branch shape scaled by p_load(h_min)."""
        hm = np.asarray(h_min, dtype=float)
        if self._CF is None:
            return np.zeros(hm.shape)
        flat = hm.ravel()
        out = np.zeros(flat.size)
        n_m = self._D.size - 1
        inside = (flat >= self._hm0) & (flat < self.h_table_end)
        if inside.any():
            u = _row_v(flat[inside], self._hm0, self._span, self._beta) * n_m
            i = np.minimum(u.astype(np.intp), n_m - 1)
            t = u - i
            y0, y1 = self._D[i], self._D[i + 1]
            m0, m1 = self._dD[i] / n_m, self._dD[i + 1] / n_m
            t2, t3 = t * t, t * t * t
            out[inside] = ((2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * m0
                           + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * m1)
        below = flat < self._hm0
        if below.any():
            hb = flat[below]
            W = _work_to(self.loading, hb)
            p0 = self.loading.evaluate(hb)[0]
            out[below] = np.maximum(W - self.sigma * p0 * self._IL, 0.0)
        return out.reshape(hm.shape)


class _HminMemo:
    """What the unloading points of one h_min array need of h_min alone: p_load(h_min), A0,
    first cell index and row coordinate (``HistoryNormalLaw._row_cell``); None until filled."""

    __slots__ = ("h_min", "p0", "a0", "base", "tm", "cell", "G")

    def __init__(self, h_min):
        self.h_min = h_min.copy()
        self.p0 = self.a0 = self.base = self.tm = None
        self.cell = None    # (n,) the cell whose polynomials in tx G holds (-1: none)
        self.G = None       # (2, 4, n) rho's and ln(a/a0)'s polynomials in tx of that cell


class UnloadingAboveLoadingWarning(UserWarning):
    """The direct sums put an unloading branch above the loading one (capped by it)."""




def _count_above_loading(rho, loading, h_min, u, rtol, tail=1e-12, worst=None) -> int:
    """Number of one row's points (rho at u = h - h_min [mm]) where the direct sums put the
    unloading branch above the loading branch, ln p_u/p_load(h) > rtol (below rtol the sums
    and the loading table agree to their accuracy, e.g. on rows where nothing has yielded),
    among the points where both branches are above ``tail`` p_load(h_min) and h is inside the
    loading table (beyond it the loading law's taper ends at its h_max while the sums go on).
    The largest excess goes into ``worst[0]`` (a one-element list of the build) if given."""
    pl = loading.evaluate(np.concatenate([[h_min], h_min + np.asarray(u, float)]))[0]
    r_load = np.log(np.maximum(pl[1:], 1e-300) / max(pl[0], 1e-300))
    use = ((r_load >= math.log(tail)) & (np.asarray(rho) >= math.log(tail))
           & (h_min + np.asarray(u, float) < loading.h_table_end))
    excess = (np.asarray(rho) - r_load)[use]
    if excess.size and worst is not None:
        worst[0] = max(worst[0], float(excess.max()))
    return int(np.count_nonzero(excess > rtol))


class _Budget(Exception):
    pass


def _work_to(loading: NormalLaw, h) -> np.ndarray:
    """int_h^inf p_load dh' [N/mm] for an array h (Gauss-Legendre on the loading knots, the
    taper in closed form, the penalty continuation below the table in closed form)."""
    h = np.atleast_1d(np.asarray(h, dtype=float))
    knots = loading.knots
    g, w = np.polynomial.legendre.leggauss(8)
    g, w = 0.5 * (g + 1.0), 0.5 * w
    dx = np.diff(knots)
    pts = knots[:-1, None] + dx[:, None] * g
    cell = (loading.evaluate(pts)[0] * w).sum(axis=1) * dx          # per interval
    tail = loading._pe * loading._taper / 4.0                        # int of P (1 - t)^3
    cum = np.concatenate([np.cumsum(cell[::-1])[::-1], [0.0]]) + tail  # int_{knot_i}^inf
    out = np.empty(h.size)
    inside = (h >= knots[0]) & (h < knots[-1])
    if inside.any():
        hi = h[inside]
        i = np.clip(np.searchsorted(knots, hi, side="right") - 1, 0, knots.size - 2)
        # int_{h}^{knot_{i+1}} p: Gauss on [h, knot_{i+1}]
        a, b = hi, knots[i + 1]
        q = a[:, None] + (b - a)[:, None] * g
        part = (loading.evaluate(q)[0] * w).sum(axis=1) * (b - a)
        out[inside] = part + cum[i + 1]
    above = h >= knots[-1]
    if above.any():
        s = np.clip((h[above] - knots[-1]) / loading._taper, 0.0, 1.0)
        out[above] = loading._pe * loading._taper / 4.0 * (1.0 - s) ** 4
    below = h < knots[0]
    if below.any():
        d = knots[0] - h[below]
        out[below] = cum[0] + d * (loading._p0 + d * (loading._k0 / 2.0 + d * loading._c0 / 6.0))
    return out


def _pchip_slopes(x, y):
    """Fritsch-Carlson monotone slopes of the data (x uniform or not)."""
    h = np.diff(x)
    dlt = np.diff(y) / h
    m = np.zeros_like(y)
    a, b = dlt[:-1], dlt[1:]
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    same = a * b > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        m[1:-1] = np.where(same, (w1 + w2) / (w1 / a + w2 / b), 0.0)
    m[0], m[-1] = dlt[0], dlt[-1]
    return m
