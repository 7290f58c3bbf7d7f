"""How a normal law is tabulated: cubic Hermite interpolation and adaptive tables of p, k, A/A0.

The statistical population integrals (:mod:`rough_contact.micro.population`) and the BEM
(:mod:`rough_contact.micro.bem`) give pressure p(h), stiffness k(h) = -dp/dh and area fraction
A/A0(h) at separations h; this module turns them into the knot data of a table:

* the **one cubic Hermite interpolant** of the package (coefficients in the local coordinate
  t in [0, 1] of every interval, Horner evaluation, the exact Fritsch-Carlson monotonicity region,
  three-point slopes with the Fritsch-Carlson limiter, :func:`hermite_eval` at points), used by
  ``rough_contact.interface.normal.NormalLaw`` and by the BEM's realisation averaging;
* :func:`tabulate_model`: knots refined adaptively until the log-Hermite interpolant meets rtol
  (or :class:`TableAccuracyError` says why not);
* :func:`tabulate_data`: measured or computed data (PCHIP or Hermite with given k);
* :func:`tabulate_population`: the validity range of a population model, then
  :func:`tabulate_model`.

Each returns a :class:`Table`; ``NormalLaw`` (interface layer) evaluates it at points (look-up,
below-validity continuation, taper). The accuracy contract and the stopping rules are described
in the docstring of ``rough_contact.interface.normal``.

Units: h [mm], p [MPa], k [MPa/mm], A/A0 [-]; ln p and ln a are tabulated.
Pure layer: numpy and scipy only.
"""

from __future__ import annotations

import inspect
import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Tuple

import numpy as np

from ..validation import check_scalar

__all__ = ["Table", "TableAccuracyError", "tabulate_model", "tabulate_data",
           "tabulate_population", "hermite_coeffs", "hermite_eval", "horner", "horner_dt",
           "monotone_hermite", "limited_slopes", "RTOL_RANGE"]

Model = Callable[[np.ndarray], Tuple[np.ndarray, np.ndarray, np.ndarray]]

# Check points inside every interval (fractions of its width): t = 1/2 is where the value error of
# a cubic Hermite interpolant peaks, t = 1/4 and 3/4 are next to where the slope error peaks
# (t = 1/2 -/+ 1/sqrt(12)).
_CHECK_T = np.array([0.25, 0.5, 0.75])
_RTOL_MIN, _RTOL_MAX = 1e-12, 0.1
RTOL_RANGE = (_RTOL_MIN, _RTOL_MAX)


@dataclass(frozen=True, eq=False)
class Table:
    """Knot data of a tabulated normal law (what ``NormalLaw`` assembles and evaluates).

    Attributes:
        h: (N+1,) knots [mm], strictly increasing.
        q, dq: (N+1,) ln p and d ln p/dh [1/mm] at the knots (Hermite data of ln p).
        la, dla: (N+1,) ln a and d ln a/dh [1/mm] (None when ``has_area`` is False).
        has_area: whether area fractions were tabulated.
        rtol: the accuracy reached against the model (None for data tables).
        info: build statistics (model evaluations, knots, wall time, ...).
    """

    h: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    la: Optional[np.ndarray]
    dla: Optional[np.ndarray]
    has_area: bool
    rtol: Optional[float]
    info: dict = field(default_factory=dict)


# ----------------------------------------------------------------------------------------------
# validation helpers
# ----------------------------------------------------------------------------------------------
def _check_budget(max_knots, max_seconds, n_initial: int) -> Tuple[int, float]:
    try:
        mk = int(max_knots)
    except (TypeError, ValueError, OverflowError):
        mk = -1
    if mk != max_knots or mk < n_initial + 1:
        raise ValueError(f"max_knots = {max_knots!r} is outside the valid range: an integer "
                         f">= n_initial + 1 = {n_initial + 1}")
    ms = float(max_seconds) if max_seconds == np.inf else check_scalar(
        "max_seconds", max_seconds, lo=0.0, unit="s")
    return mk, ms


def _check_rtol(rtol) -> float:
    return check_scalar("rtol", rtol, lo=_RTOL_MIN, hi=_RTOL_MAX, lo_open=False, hi_open=False)


def _model_values(model: Model, h: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Call the model and validate its output (finite, p > 0, k >= 0, 0 < a <= 1)."""
    out = model(h)
    try:
        p, k, a = (np.asarray(v, dtype=float).reshape(h.shape) for v in out)
    except (TypeError, ValueError):
        raise ValueError(
            "the model must return three arrays (pressure, stiffness, area_fraction) "
            f"shaped like h {h.shape}") from None
    for name, v in (("pressure", p), ("stiffness", k), ("area_fraction", a)):
        bad = ~np.isfinite(v)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            raise ValueError(f"model {name} is not finite at {int(bad.sum())} separations, "
                             f"e.g. {name}({h.flat[j]!r} mm) = {v.flat[j]!r}")
    for name, v, lo_ok, rng in (("pressure", p, p > 0, "(0, inf) MPa"),
                                ("stiffness", k, k >= 0, "[0, inf) MPa/mm"),
                                ("area_fraction", a, (a > 0) & (a <= 1), "(0, 1]")):
        if not lo_ok.all():
            j = int(np.flatnonzero(~lo_ok)[0])
            raise ValueError(f"model {name}({h.flat[j]!r} mm) = {v.flat[j]!r} is outside the valid "
                             f"range {rng} inside the table range")
    return p, k, a


# ----------------------------------------------------------------------------------------------
# cubic Hermite helpers (coefficients in the local coordinate t in [0, 1])
# ----------------------------------------------------------------------------------------------
def hermite_coeffs(y0, y1, d0, d1, dx) -> np.ndarray:
    """Coefficients (4, n) of y(t) = c0 + c1 t + c2 t^2 + c3 t^3 with slopes d0, d1 per unit h."""
    m0 = d0 * dx
    m1 = d1 * dx
    dy = y1 - y0
    return np.stack([y0, m0, 3.0 * dy - 2.0 * m0 - m1, -2.0 * dy + m0 + m1])


def horner(c, t):
    return c[0] + t * (c[1] + t * (c[2] + t * c[3]))


def horner_dt(c, t):
    return c[1] + t * (2.0 * c[2] + t * (3.0 * c[3]))


def monotone_hermite(dy, m0, m1) -> np.ndarray:
    """True where the cubic Hermite segment (secant dy, end slopes m0, m1 in t) is monotone.

    Exact Fritsch-Carlson (1980) region for alpha = m0/dy, beta = m1/dy.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        al = m0 / dy
        be = m1 / dy
        s = al + be - 2.0
        phi = al - (2.0 * al + be - 3.0) ** 2 / (3.0 * s)
    zero = dy == 0.0
    ok = (al >= 0) & (be >= 0) & ((s <= 0) | (2 * al + be - 3 <= 0) | (al + 2 * be - 3 <= 0)
                                  | (phi >= 0))
    return np.where(zero, (m0 == 0) & (m1 == 0), ok)


def limited_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Second-order three-point slopes of y(x) at the knots, limited to keep y monotone.

    Interior knots: the derivative of the parabola through three neighbours; end knots: the
    one-sided three-point formula. Then the Fritsch-Carlson limiter: a slope of the wrong sign (or
    next to a flat secant) is set to zero, and slopes are scaled into the circle
    alpha^2 + beta^2 <= 9, which keeps every segment monotone.
    """
    dx = np.diff(x)
    sec = np.diff(y) / dx
    d = np.empty_like(y)
    if len(x) == 2:
        d[:] = sec[0]
        return d
    hl, hr = dx[:-1], dx[1:]
    d[1:-1] = (hr * sec[:-1] + hl * sec[1:]) / (hl + hr)
    d[0] = ((2 * dx[0] + dx[1]) * sec[0] - dx[0] * sec[1]) / (dx[0] + dx[1])
    d[-1] = ((2 * dx[-1] + dx[-2]) * sec[-1] - dx[-1] * sec[-2]) / (dx[-1] + dx[-2])
    # sign limiter: the slope must have the sign of both adjacent secants
    left = np.concatenate([sec[:1], sec])
    right = np.concatenate([sec, sec[-1:]])
    same = (np.sign(d) == np.sign(left)) & (np.sign(d) == np.sign(right))
    d = np.where(same, d, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        al = np.where(sec != 0, d[:-1] / sec, 0.0)
        be = np.where(sec != 0, d[1:] / sec, 0.0)
        r = np.hypot(al, be)
        tau = np.where(r > 3.0, 3.0 / r, 1.0)
    fac = np.ones_like(d)
    fac[:-1] = tau
    fac[1:] = np.minimum(fac[1:], tau)
    return d * fac


def hermite_eval(x_knots, y, dy, x):
    """Cubic Hermite interpolant of knot values y and slopes dy, and its derivative, at x.

    Args:
        x_knots: (n,) strictly increasing knots; y, dy: (n,) values and slopes (per unit x).
        x: points inside [x_knots[0], x_knots[-1]] (any shape).
    Returns:
        (value, derivative) at x, shaped like x.
    """
    xk = np.asarray(x_knots, float)
    y = np.asarray(y, float)
    dy = np.asarray(dy, float)
    x = np.asarray(x, float)
    dxs = np.diff(xk)
    c = hermite_coeffs(y[:-1], y[1:], dy[:-1], dy[1:], dxs)
    i = np.clip(np.searchsorted(xk, x, side="right") - 1, 0, dxs.size - 1)
    t = (x - xk[i]) / dxs[i]
    ci = c[:, i]
    return horner(ci, t), horner_dt(ci, t) / dxs[i]


# ----------------------------------------------------------------------------------------------
# adaptive table
# ----------------------------------------------------------------------------------------------
# An interval whose check error has not at least halved over this many successive bisections is
# taken to be limited by the model, not by the table (see _adaptive_table).
_STALL_GENERATIONS = 2
_STALL_RATIO = 0.5


class TableAccuracyError(ValueError):
    """The normal-law table could not reach the requested accuracy (see :meth:`NormalLaw.from_model`).

    A ``ValueError`` (bad combination of model and rtol), raised with what was reached and where.

    Attributes:
        reason: ``"model-limited"`` (refining no longer reduces the error: the model is less
            accurate, or less self-consistent, than rtol there), ``"max_knots"`` or
            ``"max_seconds"`` (the build budget ran out first).
        rtol: the requested relative accuracy.
        reached: worst relative error vs the model at the check points of the failing
            intervals, per quantity: ``{"pressure": .., "stiffness": .., "area_fraction": ..}``.
        h_range: ``(h_a, h_b)`` [mm], the span of the failing intervals.
        model_consistency: largest ``|k_model - (-dp_model/dh)| / k_model`` measured on the
            failing intervals (the model's mid-interval stiffness against the central
            difference of its own pressure over the interval): how far the model's stiffness is
            from the derivative of its pressure.
        knots: number of knots when the build stopped.
        seconds: wall time of the build when it stopped [s].
        advice: what to change, as a sentence.
        length_scale: ``(name, value in mm)`` in which the message also shows h (e.g.
            ``("sqrt(m00)", rq)``), or None.
    """

    def __init__(self, reason: str, rtol: float, reached: dict, h_range: Tuple[float, float],
                 model_consistency: Optional[float], knots: int, seconds: float,
                 advice: str, length_scale: Optional[Tuple[str, float]] = None):
        self.reason = reason
        self.rtol = rtol
        self.reached = dict(reached)
        self.h_range = (float(h_range[0]), float(h_range[1]))
        self.model_consistency = model_consistency
        self.knots = int(knots)
        self.seconds = float(seconds)
        self.advice = advice
        self.length_scale = length_scale
        super().__init__(self._message())

    def _fields(self) -> tuple:
        return (self.reason, self.rtol, self.reached, self.h_range, self.model_consistency,
                self.knots, self.seconds, self.advice, self.length_scale)

    def __reduce__(self):
        # picklable (e.g. sent between processes): rebuilt from its fields, not the message
        return (type(self), self._fields())

    def with_advice(self, advice: str, length_scale: Optional[Tuple[str, float]] = None,
                    seconds: Optional[float] = None) -> "TableAccuracyError":
        """The same error with other advice, optionally h also shown in units of a length
        ``(name, value in mm)`` and another wall time (e.g. including the caller's set-up)."""
        return TableAccuracyError(self.reason, self.rtol, self.reached, self.h_range,
                                  self.model_consistency, self.knots,
                                  self.seconds if seconds is None else seconds, advice,
                                  length_scale if length_scale is not None else self.length_scale)

    def _message(self) -> str:
        why = {
            "model-limited": (
                f"halving the failing intervals {_STALL_GENERATIONS} times did not reduce their "
                "error (a cubic Hermite table's error falls 8-16x per halving when the model is "
                "smooth and its stiffness is the derivative of its pressure): the model itself is "
                "less accurate than rtol there"),
            "max_knots": "the knot budget max_knots ran out",
            "max_seconds": "the time budget max_seconds ran out (or the next refinement round "
                           "would have exceeded it)",
        }[self.reason]
        r = self.reached
        where = f"h in [{self.h_range[0]:.6g}, {self.h_range[1]:.6g}] mm"
        if self.length_scale is not None:
            name, scale = self.length_scale
            where += (f" (h/{name} in [{self.h_range[0] / scale:.4g}, "
                      f"{self.h_range[1] / scale:.4g}])")
        msg = (f"normal-law table: rtol = {self.rtol:g} not reached ({why}). Reached "
               f"{max(r.values()):.3g} (pressure {r['pressure']:.2g}, stiffness "
               f"{r['stiffness']:.2g}, A/A0 {r['area_fraction']:.2g}, relative to the model at "
               f"the check points) on {where}; rtol/2 elsewhere; {self.knots} knots, "
               f"{self.seconds:.1f} s.")
        if self.model_consistency is not None:
            msg += (f" There the model's stiffness differs from the derivative of its own "
                    f"pressure by up to {self.model_consistency:.2g} (relative).")
        return msg + " " + self.advice


def _rtol_advice(reached: float) -> float:
    """A looser rtol that the reached accuracy supports: 2x (the check tolerance is rtol/2), one
    significant digit, rounded up."""
    r = 2.0 * reached * (1.0 + 1e-9)
    e = np.floor(np.log10(r))
    return float(np.ceil(r / 10.0 ** e) * 10.0 ** e)


def _rtol_text(reached: float) -> str:
    r = _rtol_advice(reached)
    if r > _RTOL_MAX:
        return (f"no rtol in the valid range (<= {_RTOL_MAX:g}) covers the {reached:.2g} reached: "
                "the model's stiffness is too far from the derivative of its pressure")
    return f"a looser rtol (>= {r:.2g}, what the model supports here)"


def _adaptive_table(model: Model, h_lo: float, h_hi: float, rtol: float, n_initial: int,
                    max_knots: int, floors: Tuple[float, float, float], check: str = "quarter",
                    max_seconds: float = np.inf, t_start: Optional[float] = None):
    """Refine knots on [h_lo, h_hi] until the log-Hermite interpolant meets rtol/2 at check points.

    Stops with :class:`TableAccuracyError` when refining no longer helps or the budget runs out:

    * **model-limited**: the check error of a cubic Hermite interpolant of a smooth model falls
      16x (values) or 8x (slopes) per bisection once the interval resolves the model. An
      interval still failing after :data:`_STALL_GENERATIONS` successive bisections that each
      reduced its error less than 2x is limited by the model (quadrature noise, or a stiffness
      that is not the derivative of the pressure): it is split no further, and once nothing else
      needs refinement the build stops with the accuracy reached.
    * **max_knots** / **max_seconds**: a round that would exceed either budget is not started
      (its cost is predicted from the measured cost per model evaluation so far).

    Returns knots h (N+1,), the model's p, k, a there, the number of model evaluations and the
    worst check-point error.
    """
    t_start = time.perf_counter() if t_start is None else t_start
    tol = 0.5 * rtol
    fp, fk, fa = floors
    if check == "quarter":
        check_t, mid = _CHECK_T, 1
    elif check == "midpoint":
        check_t, mid = np.array([0.5]), 0
    else:
        raise ValueError(f"check = {check!r} is invalid: valid values are 'quarter', 'midpoint'")
    nt = check_t.size
    h = np.linspace(h_lo, h_hi, n_initial + 1)
    t_eval = time.perf_counter()
    p, k, a = _model_values(model, h)
    n_eval = h.size
    sec_eval = time.perf_counter() - t_eval      # wall time spent in the model
    # check-point data of every interval, (n_int, nt); NaN where not evaluated yet
    cp = np.full((n_initial, nt), np.nan)
    ck = cp.copy()
    ca = cp.copy()
    # per interval: check error of its parent (inf: none) and the number of successive
    # bisections that reduced the error less than 2x
    parent_err = np.full(n_initial, np.inf)
    stall = np.zeros(n_initial, dtype=np.intp)

    def stop(reason, bad):
        """TableAccuracyError for the intervals flagged in bad (or the worst one)."""
        idx = np.flatnonzero(bad) if bad.any() else np.array([int(np.argmax(err))])
        reached = {name: float(e[idx].max()) for name, e in zip(
            ("pressure", "stiffness", "area_fraction"), errs)}
        # the model's own consistency over the interval: its mid-interval stiffness against the
        # central difference of its pressure (truncation error O(dx^2), negligible on the small
        # intervals where refinement stalls)
        dxs = np.diff(h)[idx]
        fd = (p[idx] - p[idx + 1]) / dxs
        kc = ck[idx, mid]
        cons = float(np.max(np.abs(kc - fd) / np.maximum(kc, fk)))
        advice = ("To change: " + _rtol_text(max(reached.values()))
                  + "; or make the model more accurate there"
                  + ("; or raise max_knots" if reason == "max_knots" else "")
                  + ("; or raise max_seconds" if reason == "max_seconds" else "") + ".")
        return TableAccuracyError(reason, rtol, reached, (h[idx].min(), h[idx + 1].max()),
                                  cons, h.size, time.perf_counter() - t_start, advice)

    for _ in range(200):
        need = np.isnan(cp[:, 0])
        if need.any():
            idx = np.flatnonzero(need)
            hx = h[idx, None] + (h[idx + 1] - h[idx])[:, None] * check_t[None, :]
            t_eval = time.perf_counter()
            pv, kv, av = _model_values(model, hx)
            sec_eval += time.perf_counter() - t_eval
            n_eval += hx.size
            cp[idx], ck[idx], ca[idx] = pv, kv, av
        dxs = np.diff(h)
        q = np.log(p)
        dq = -k / p
        la = np.log(a)
        if np.any(np.diff(q) > 0):
            j = int(np.flatnonzero(np.diff(q) > 0)[0])
            raise ValueError(
                f"model pressure is not non-increasing: p({float(h[j])!r} mm) = {float(p[j])!r} MPa < "
                f"p({float(h[j + 1])!r} mm) = {float(p[j + 1])!r} MPa")
        dla = limited_slopes(h, la)
        cq = hermite_coeffs(q[:-1], q[1:], dq[:-1], dq[1:], dxs)
        ca_ = hermite_coeffs(la[:-1], la[1:], dla[:-1], dla[1:], dxs)
        t = check_t[None, :]
        pi = np.exp(horner(cq[:, :, None], t))
        ki = -pi * horner_dt(cq[:, :, None], t) / dxs[:, None]
        ai = np.exp(horner(ca_[:, :, None], t))
        errs = [(np.abs(pi - cp) / np.maximum(cp, fp)).max(axis=1),
                (np.abs(ki - ck) / np.maximum(ck, fk)).max(axis=1),
                (np.abs(ai - ca) / np.maximum(ca, fa)).max(axis=1)]
        if check == "midpoint":
            # The slope error of a cubic Hermite interpolant is (asymptotically) largest at
            # t = 1/2 -/+ 1/sqrt(12), where it is 3.08/dx times the value error at t = 1/2; the
            # relative stiffness error is that of d(ln p)/dh.
            eq = np.abs(horner(cq, 0.5) - np.log(cp[:, 0]))
            qmin = np.minimum(np.abs(dq[:-1]), np.abs(dq[1:]))
            with np.errstate(divide="ignore", invalid="ignore"):
                est = np.where(qmin > 0, 3.08 * eq / (dxs * qmin), 0.0)
            # ln a uses three-point slopes: its error is not symmetric about t = 1/2 and peaks
            # up to ~3x higher elsewhere in the interval (measured), hence the factor 4
            ea = 4.0 * np.abs(ai[:, 0] - ca[:, 0]) / np.maximum(ca[:, 0], fa)
            errs[1] = np.maximum(errs[1], est)
            errs[2] = np.maximum(errs[2], ea)
        err = np.maximum.reduce(errs)
        mono = monotone_hermite(np.diff(q), dq[:-1] * dxs, dq[1:] * dxs)
        bad = (err > tol) | ~mono
        # stagnation: freshly checked intervals whose error fell less than 2x since their parent
        fresh = need
        slow = fresh & bad & (err > _STALL_RATIO * parent_err)
        stall = np.where(fresh, np.where(slow, stall + 1, 0), stall)
        limited = bad & (stall >= _STALL_GENERATIONS)
        fail = bad & ~limited
        # 2:1 grading (an interval is at most twice as wide as its neighbours): keeps the
        # three-point slopes of ln a accurate and makes refinement fronts advance in one round
        nb = np.minimum(np.concatenate([[np.inf], dxs[:-1]]), np.concatenate([dxs[1:], [np.inf]]))
        fail |= dxs > 2.0 * nb * (1.0 + 1e-9)
        if not fail.any():
            if limited.any():
                raise stop("model-limited", limited)
            return h, p, k, a, n_eval, float(err.max())
        if h.size + fail.sum() > max_knots:
            raise stop("max_knots", bad)
        # time budget: do not start a round that the measured cost says would overrun it
        n_next = 2 * int(fail.sum()) * nt
        if time.perf_counter() - t_start + sec_eval / n_eval * n_next > max_seconds:
            raise stop("max_seconds", bad)
        fi = np.flatnonzero(fail)
        # split failing intervals at their midpoints (check point t = 1/2 becomes a knot)
        hm = 0.5 * (h[fi] + h[fi + 1])
        pos = fi + 1
        h = np.insert(h, pos, hm)
        p = np.insert(p, pos, cp[fi, mid])
        k = np.insert(k, pos, ck[fi, mid])
        a = np.insert(a, pos, ca[fi, mid])
        # interval fi becomes two: both need fresh check points and inherit its error history
        keep = ~fail
        new_n = h.size - 1
        ncp = np.full((new_n, nt), np.nan)
        nck = ncp.copy()
        nca = ncp.copy()
        # index of old interval j in the new list: j + (number of failing intervals before j)
        shift = np.cumsum(fail) - fail
        newpos = np.arange(fail.size) + shift
        ncp[newpos[keep]] = cp[keep]
        nck[newpos[keep]] = ck[keep]
        nca[newpos[keep]] = ca[keep]
        npe = np.repeat(np.where(fail, err, parent_err), np.where(fail, 2, 1))
        nst = np.repeat(stall, np.where(fail, 2, 1))
        cp, ck, ca, parent_err, stall = ncp, nck, nca, npe, nst
    raise ValueError(f"rtol = {rtol!r}: table refinement did not converge in 200 rounds")


def _population_advice(fn, name: str, kwargs: dict, e: TableAccuracyError) -> str:
    """What to change when a population law's table stops short of rtol (for the error)."""
    todo = [_rtol_text(max(e.reached.values()))]
    params = inspect.signature(fn).parameters
    if "n_quad" in params:
        nq = int(kwargs["n_quad"]) if "n_quad" in kwargs else int(params["n_quad"].default)
        todo.append(f"more population quadrature (n_quad = {nq} now; the population integral's "
                    "error falls quickly with n_quad, its cost grows about as n_quad^3)")
    if name == "elasto_plastic":
        todo.append("the elastic law NormalLaw.elastic (no asperity plasticity), if plasticity "
                    "is negligible at the loads of interest")
    if e.reason == "max_knots":
        todo.append("a larger max_knots")
    if e.reason == "max_seconds":
        todo.append("a larger max_seconds")
    return "To change: " + "; or ".join(todo) + "."


# ----------------------------------------------------------------------------------------------
# tables from a model, from data, from a population model
# ----------------------------------------------------------------------------------------------
def tabulate_model(model: Model, h_range: Tuple[float, float], rtol: float = 1e-5, *,
               n_initial: int = 16, max_knots: int = 20000,
               max_seconds: float = 300.0, floor: float = 1e-15,
               check: str = "quarter") -> Table:
    """Tabulate any model ``h -> (p, k, a)`` on ``h_range = (h_min, h_table_end)``.

    Args:
        model: vectorised callable; given h (any shape, mm) returns pressure [MPa] > 0,
            stiffness -dp/dh [MPa/mm] >= 0 and area fraction in (0, 1], each shaped like h,
            with p non-increasing. Its k must be the derivative of its p to within rtol.
        h_range: (h_min, h_table_end) [mm], h_min < h_table_end. p must be > 0 on it. Below
            h_min the stiff continuation applies; beyond h_table_end the taper to zero.
        rtol: relative accuracy of p, k and a at every point of the table, in [1e-12, 0.1].
        n_initial: number of uniform intervals to start refining from.
        max_knots: knot budget; a refinement round that would exceed it is not started
            and :class:`TableAccuracyError` is raised instead.
        max_seconds: wall-time budget of the build [s] (np.inf: none); a refinement round
            that the measured cost per model evaluation says would exceed it is not started
            and :class:`TableAccuracyError` is raised instead.
        floor: errors are relative to max(|value|, floor * value at h_min) (guards zeros).
        check: "quarter" compares p, k, a with the model at t = 1/4, 1/2, 3/4 of every
            interval (3 model evaluations per interval, robust); "midpoint" only at t = 1/2
            and bounds the stiffness error by the asymptotic Hermite error ratio (about 3x
            fewer model evaluations, for expensive models).

    Raises:
        ValueError: bad arguments, a model returning non-finite / out-of-range values or a
            non-monotone pressure.
        TableAccuracyError: (a ValueError) rtol not reached: the model is less accurate or
            less self-consistent than rtol somewhere (refinement stalls there), or the
            budget ran out. The error states the accuracy reached, where, and what to change.
    """
    t_start = time.perf_counter()
    rtol = _check_rtol(rtol)
    try:
        h_lo, h_hi = (float(v) for v in h_range)
    except (TypeError, ValueError):
        raise ValueError(f"h_range must be two numbers (h_min, h_table_end) in mm, got "
                         f"{h_range!r}") from None
    if not (np.isfinite(h_lo) and np.isfinite(h_hi) and h_lo < h_hi):
        raise ValueError(f"h_range = {h_range!r} mm must be finite with h_min < h_table_end")
    n_initial = int(n_initial)
    if n_initial < 2:
        raise ValueError(f"n_initial = {n_initial} is outside the valid range [2, inf)")
    max_knots, max_seconds = _check_budget(max_knots, max_seconds, n_initial)
    p_ref, k_ref, a_ref = (float(v[0]) for v in _model_values(model, np.array([h_lo])))
    floors = (floor * p_ref, floor * k_ref, floor * a_ref)
    h, p, k, a, n_eval, worst = _adaptive_table(model, h_lo, h_hi, rtol, n_initial,
                                                max_knots, floors, check, max_seconds,
                                                t_start)
    q, la = np.log(p), np.log(a)
    info = {"model_evaluations": n_eval + 1, "worst_checkpoint_error": worst,
            "knots": h.size, "build_seconds": time.perf_counter() - t_start}
    return Table(h, q, -k / p, la, limited_slopes(h, la), True, rtol, info)


def tabulate_data(h, p, a=None, k=None) -> Table:
    """Table of tabulated data (e.g. measured), interpolated monotonically.

    ``ln p`` is interpolated by monotone PCHIP (Fritsch-Butland slopes, as
    :class:`scipy.interpolate.PchipInterpolator`), so p is non-increasing and C1 and k is the
    exact derivative of the interpolant; ``ln a`` likewise when a is given. When the data
    include the stiffness k (e.g. from boundary elements), ``ln p`` is instead the cubic
    Hermite interpolant with slopes ``-k/p`` (fourth-order accurate instead of PCHIP's
    first-order slopes); every interval must then be monotone (Fritsch-Carlson region).

    Args:
        h: (n,) separations [mm], finite, strictly increasing, n >= 3.
        p: (n,) pressures [MPa], finite, > 0, strictly decreasing.
        a: optional (n,) area fractions A/A0 in (0, 1], non-increasing. Without it,
            ``evaluate`` returns a == 0 and ``has_area`` is False.
        k: optional (n,) stiffnesses -dp/dh [MPa/mm], finite, > 0, used as Hermite slope
            data (the table's k then equals them at the knots).

    Below ``h[0]`` the stiff continuation applies, beyond ``h[-1]`` the cubic taper to zero
    over L = 3 p_end/k_end (so p == 0 from ``h_max = h[-1] + L``): end the data where the
    pressure is negligible if the taper matters.
    """
    from scipy.interpolate import PchipInterpolator

    h = np.array(h, dtype=float).ravel()
    p = np.array(p, dtype=float).ravel()
    if h.size < 3 or p.size != h.size:
        raise ValueError(f"from_table needs h and p of equal length >= 3, got {h.size} and "
                         f"{p.size}")
    for name, v in (("h", h), ("p", p)):
        if not np.isfinite(v).all():
            raise ValueError(f"table {name} has {int((~np.isfinite(v)).sum())} non-finite "
                             "entries; valid: finite numbers")
    if np.any(np.diff(h) <= 0):
        j = int(np.flatnonzero(np.diff(h) <= 0)[0])
        raise ValueError(f"table h must be strictly increasing: h[{j}] = {float(h[j])!r}, "
                         f"h[{j + 1}] = {float(h[j + 1])!r} mm")
    if np.any(p <= 0):
        j = int(np.flatnonzero(p <= 0)[0])
        raise ValueError(f"table p[{j}] = {float(p[j])!r} MPa is outside the valid range (0, inf)")
    if np.any(np.diff(p) >= 0):
        j = int(np.flatnonzero(np.diff(p) >= 0)[0])
        raise ValueError(f"table p must be strictly decreasing in h: p[{j}] = {float(p[j])!r}, "
                         f"p[{j + 1}] = {float(p[j + 1])!r} MPa")
    q = np.log(p)
    if k is not None:
        k = np.array(k, dtype=float).ravel()
        if k.size != h.size or not np.isfinite(k).all() or np.any(k <= 0):
            raise ValueError(f"table k must have {h.size} finite entries > 0 MPa/mm, got "
                             f"{k.size} entries (min {np.min(k) if k.size else None!r})")
        dq = -k / p
        dxs = np.diff(h)
        mono = monotone_hermite(np.diff(q), dq[:-1] * dxs, dq[1:] * dxs)
        if not mono.all():
            j = int(np.flatnonzero(~mono)[0])
            raise ValueError(
                f"table k is inconsistent with p on [h[{j}], h[{j + 1}]] = [{float(h[j])!r}, "
                f"{float(h[j + 1])!r}] mm: the Hermite interpolant of ln p would not be monotone "
                f"(k = {float(k[j])!r}, {float(k[j + 1])!r} MPa/mm, secant "
                f"{-(p[j + 1] - p[j]) / dxs[j]!r} MPa/mm); tabulate more densely or omit k")
    else:
        dq = np.minimum(PchipInterpolator(h, q).derivative()(h), 0.0)
    if dq[-1] == 0.0:
        # PCHIP zeroes a one-sided end slope of the wrong sign; the taper needs k > 0 at the
        # table end: half the last secant keeps the segment monotone (Fritsch-Carlson region
        # for any alpha in [0, 3])
        dq[-1] = 0.5 * (q[-1] - q[-2]) / (h[-1] - h[-2])
    dxs = np.diff(h)
    if not np.all(monotone_hermite(np.diff(q), dq[:-1] * dxs, dq[1:] * dxs)):
        raise ValueError("internal error: PCHIP slopes of ln p are not monotone")
    has_area = a is not None
    la = dla = None
    if has_area:
        a = np.array(a, dtype=float).ravel()
        if a.size != h.size or not np.isfinite(a).all():
            raise ValueError(f"table a must have {h.size} finite entries, got {a.size}")
        if np.any((a <= 0) | (a > 1)):
            j = int(np.flatnonzero((a <= 0) | (a > 1))[0])
            raise ValueError(f"table a[{j}] = {float(a[j])!r} is outside the valid range (0, 1]")
        if np.any(np.diff(a) > 0):
            j = int(np.flatnonzero(np.diff(a) > 0)[0])
            raise ValueError(f"table a must be non-increasing in h: a[{j}] = {float(a[j])!r}, "
                             f"a[{j + 1}] = {float(a[j + 1])!r}")
        la = np.log(a)
        dla = np.minimum(PchipInterpolator(h, la).derivative()(h), 0.0)
    info = {"knots": h.size, "source": "table"}
    return Table(h, q, dq, la, dla, has_area, None, info)


def tabulate_population(fn, surface, param, rtol, area_limit, depth, tail, kwargs, name,
                     check, max_knots: int = 20000, max_seconds: float = 300.0):
    t_start = time.perf_counter()
    rtol = _check_rtol(rtol)
    max_knots, max_seconds = _check_budget(max_knots, max_seconds, 16)
    area_limit = check_scalar("area_limit", area_limit, lo=0.0, hi=1.0)
    depth = check_scalar("depth", depth, lo=0.0, lo_open=False)
    tail = check_scalar("tail", tail, lo=0.0, hi=1e-2)

    calls = [0]

    def model(h):
        calls[0] += np.size(h)
        r = fn(surface, param, h, **kwargs)
        return r.pressure, r.stiffness, r.area_fraction

    sigma = float(np.sqrt(surface.m00))   # rms height [mm] (m00 stored in mm^2)
    # coarse scan in steps of sigma/2, from `depth` sigma below the mean plane upwards
    grid = np.arange(-depth, 12.0 + 1e-9, 0.5) * sigma
    p_g, k_g, a_g = (np.asarray(v, float) for v in model(grid))
    if not (np.all(np.isfinite(a_g)) and np.all(np.isfinite(p_g))):
        raise ValueError(f"{name} model returned non-finite values on the range "
                         f"[{float(grid[0])!r}, {float(grid[-1])!r}] mm")
    # --- h_min: where A/A0 falls to area_limit, but not below -depth sigma
    above = a_g > area_limit
    if not above[0]:
        h_lo = float(grid[0])
    else:
        if above[-1]:
            raise ValueError(f"{name} model A/A0 stays above area_limit = {area_limit!r} up "
                             f"to h = {float(grid[-1])!r} mm (12 sigma)")
        j = int(np.flatnonzero(above)[-1])   # last grid point above the limit
        lo, hi = float(grid[j]), float(grid[j + 1])
        for _ in range(2):                    # bracket shrinks 8x per round
            sub = np.linspace(lo, hi, 9)[1:-1]
            a_s = np.asarray(model(sub)[2], float)
            up = np.flatnonzero(a_s > area_limit)
            i = int(up[-1]) + 1 if up.size else 0
            edges = np.concatenate([[lo], sub, [hi]])
            lo, hi = float(edges[i]), float(edges[i + 1])
        h_lo = hi                             # A/A0(h_min) <= area_limit, within sigma/128
    # --- h_table_end: first scan point with p <= tail * p(max(h_min, 0)) (and p > 0)
    p_ref = float(np.asarray(model(np.array([max(h_lo, 0.0)]))[0], float)[0])
    for _ in range(2):
        cand = np.flatnonzero((grid > h_lo) & (p_g <= tail * p_ref) & (p_g > 0))
        if cand.size or grid[-1] > 30 * sigma:
            break
        grid = np.arange(12.5, 40.0 + 1e-9, 0.5) * sigma     # extend the scan to 40 sigma
        p_g = np.asarray(model(grid)[0], float)
    if cand.size:
        h_hi = float(grid[cand[0]])
    else:
        pos = np.flatnonzero((grid > h_lo) & (p_g > 0))
        # the model underflowed to p == 0 before reaching the tail ratio: accept its last
        # positive value if it is already small
        if pos.size == 0 or p_g[pos[-1]] > 1e-6 * p_ref:
            raise ValueError(f"{name} model pressure does not fall to tail = {tail!r} times "
                             f"p_ref = {p_ref!r} MPa up to h = {float(grid[-1])!r} mm (40 sigma)")
        h_hi = float(grid[pos[-1]])
    n_scan = calls[0]
    remaining = max_seconds - (time.perf_counter() - t_start)
    if not remaining > 0.0:
        raise ValueError(f"max_seconds = {max_seconds!r} s is too small: the {name} model's "
                         f"range scan alone took {time.perf_counter() - t_start:.3g} s")
    try:
        table = tabulate_model(model, (h_lo, h_hi), rtol, check=check, max_knots=max_knots,
                               max_seconds=remaining)
    except TableAccuracyError as e:
        raise e.with_advice(_population_advice(fn, name, kwargs, e), ("sqrt(m00)", sigma),
                            time.perf_counter() - t_start) from None
    table.info.update({"model": name, "sigma_mm": sigma, "area_limit": area_limit,
                     "build_seconds": time.perf_counter() - t_start,
                     "depth": depth, "tail": tail, "p_ref": p_ref,
                     "range_scan_evaluations": n_scan,
                     "model_evaluations": calls[0]})
    return table
