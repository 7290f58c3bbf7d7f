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
on a uniform tensor grid in (h_min, x) over [h_lo, h_table_end] x [0, X], as a bicubic Hermite
surface: x-slopes are the model's own stiffness (d rho/dx = -k sigma/p), h_min-slopes and the
cross slopes are three-point differences. rho is smooth in both variables (nearly quadratic in
x, slowly drifting with h_min), so the grid is coarse. The grid is refined by doubling, per
direction, until the interpolant matches the direct population sums
(``rough_contact.micro.unloading``) at the midpoints of both directions to rtol (p, k and A/A0,
relative; check points where p < tail p_load(h_min) are not checked). k is the exact
h-derivative of the interpolant (consistent tangent at fixed h_min); the build verifies k >= 0
on a dense sample and records it in ``info``. Beyond x = X the branch tapers to zero as the
``NormalLaw`` does (cubic, C1). h_min below the table: the branch shape of the first row,
scaled by p_load(h_min); h_min >= h_table_end: nothing has yielded to within the table's tail:
the loading law (reversible).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Optional, Protocol, Tuple, runtime_checkable

import numpy as np

from ..validation import check_scalar
from .normal import NormalLaw

__all__ = ["HistoryNormalLawProtocol", "HistoryNormalLaw"]

# bicubic Hermite: f(tm, tx) = [1 tm tm^2 tm^3] M F M^T [1 tx tx^2 tx^3]^T
_M = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0],
               [2.0, -2.0, 1.0, 1.0]])


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


def _fd(v, d, axis):
    """Derivative along ``axis`` on a uniform grid of step d: central, one-sided 3-point ends."""
    v = np.moveaxis(v, axis, 0)
    out = np.empty_like(v)
    if v.shape[0] >= 3:
        out[1:-1] = (v[2:] - v[:-2]) / (2 * d)
        out[0] = (-3 * v[0] + 4 * v[1] - v[2]) / (2 * d)
        out[-1] = (3 * v[-1] - 4 * v[-2] + v[-3]) / (2 * d)
    else:
        out[:] = (v[-1] - v[0]) / d
    return np.moveaxis(out, 0, axis)


def _bicubic(f, fx, dm, dx):
    """Cell coefficients (n_m-1, n_x-1, 4, 4) from grid values f and exact x-slopes fx."""
    fm = _fd(f, dm, 0)
    fmx = _fd(fx, dm, 0)
    n_m, n_x = f.shape[0] - 1, f.shape[1] - 1
    F = np.empty((n_m, n_x, 4, 4))
    for a, (ia, sa) in enumerate(((0, 0), (1, 0), (0, 1), (1, 1))):
        # rows of F: f(i), f(i+1), dm f(i), dm f(i+1); columns the same in x
        for b, (jb, sb) in enumerate(((0, 0), (1, 0), (0, 1), (1, 1))):
            src = (f, fx, fm, fmx)[sb + 2 * sa]
            scale = (dx if sb else 1.0) * (dm if sa else 1.0)
            F[:, :, a, b] = src[ia:ia + n_m, jb:jb + n_x] * scale
    return np.einsum("ab,mnbc,dc->mnad", _M, F, _M)


def _eval_cells(C, i, j, tm, tx, second=False):
    """Value, d/dtx (and d2/dtx2) of the bicubic cells C[i, j] at (tm, tx)."""
    c = C[i, j]                                           # (n, 4, 4)
    Tm = np.stack([np.ones_like(tm), tm, tm * tm, tm * tm * tm], axis=-1)
    g = np.einsum("na,nab->nb", Tm, c)                    # polynomial in tx
    v = g[:, 0] + tx * (g[:, 1] + tx * (g[:, 2] + tx * g[:, 3]))
    dv = g[:, 1] + tx * (2.0 * g[:, 2] + tx * 3.0 * g[:, 3])
    if second:
        return v, dv, 2.0 * g[:, 2] + 6.0 * tx * g[:, 3]
    return v, dv


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
    _dm: float = 1.0                    # row spacing [mm]
    _dx: float = 1.0                    # x spacing [-]
    _X: float = 0.0                     # end of the x table [-]
    _C: Optional[np.ndarray] = None     # (n_m, n_x, 4, 4) bicubic cells of rho
    _CA: Optional[np.ndarray] = None    # same for ln(a/a0)
    _D: Optional[np.ndarray] = None     # (n_m + 1,) D(h_min) at the rows [N/mm]
    _dD: Optional[np.ndarray] = None    # (n_m + 1,) dD/dh_min at the rows (monotone slopes)
    _IL: float = 0.0                    # int exp(rho(row 0, x)) dx incl. taper [-]
    info: dict = field(default_factory=dict, compare=False)   # build statistics, not identity

    # ------------------------------------------------------------ NormalLaw interface
    @property
    def reversible(self) -> bool:
        return self._C is None

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
                       n_quad: int = 16, n_t: int = 16, n_rows: int = 8, n_x: int = 8,
                       tail: float = 1e-12, max_points: int = 20000,
                       max_seconds: float = 600.0, strict: bool = True) -> "HistoryNormalLaw":
        """Table of the elasto-plastic population with memory (reading "consistent").

        Args:
            surface: SpectralMoments; material: AsperityMaterial (resolved on surface here).
            rtol: relative accuracy of p, k and A/A0 on the unloading branch against the direct
                sums (``micro.unloading._row_sums`` with the same n_quad, n_t) at the midpoints
                of the grid in both directions, in [1e-8, 0.1].
            loading: a prebuilt ``NormalLaw.elasto_plastic`` of the same surface and material
                (its build time is then not counted); None builds one at rtol.
            n_quad, n_t: quadrature of the direct sums (shape rule, height nodes per panel).
            n_rows, n_x: initial numbers of h_min and x intervals (doubled as needed).
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
        for name, v in (("n_rows", n_rows), ("n_x", n_x)):
            if int(v) != v or v < 2:
                raise ValueError(f"{name} = {v!r} is invalid: it must be an integer >= 2")
        mat = material.resolve(surface)
        if loading is None:
            loading = NormalLaw.elasto_plastic(surface, mat, rtol)
        t_load = time.perf_counter() - t0
        t1 = time.perf_counter()
        sig = surface.rq
        hL, hE = loading.h_min, loading.h_table_end
        cache: dict = {}
        n_pts = [0]

        def model(hms, xs):
            """(rho, d rho/dx, ln a - ln a0, d ln a/dx) on rows hms x xs, cached per point."""
            out = np.empty((4, len(hms), len(xs)))
            for i, hm in enumerate(hms):
                row = cache.setdefault(round(float((hm - hL) / (hE - hL)), 12), {})
                need = [x for x in xs if round(float(x), 12) not in row]
                if need:
                    if time.perf_counter() - t1 > max_seconds or n_pts[0] > max_points:
                        raise _Budget()
                    uu = np.concatenate([[0.0], np.asarray(need) * sig])
                    p, k, a, da = U._row_sums(surface, mat, float(hm), uu, n_quad, n_t)
                    n_pts[0] += uu.size
                    p = np.maximum(p, 1e-300)
                    a = np.maximum(a, 1e-300)
                    for x, pv, kv, av, dav in zip(need, p[1:], k[1:], a[1:], da[1:]):
                        row[round(float(x), 12)] = (math.log(pv / p[0]), -kv / pv * sig,
                                                    math.log(av / a[0]), -dav / av * sig)
                for j, x in enumerate(xs):
                    out[:, i, j] = row[round(float(x), 12)]
            return out

        # x range: first row (slowest decay) down to tail
        X = 2.0
        try:
            while model([hL], [X])[0, 0, 0] > math.log(tail) and X < 64:
                X *= 1.5
        except _Budget:
            raise RuntimeError("HistoryNormalLaw: budget exhausted while scanning the x range")
        nm, nx = int(n_rows), int(n_x)
        worst = np.inf
        table = None
        while True:
            try:
                hm = np.linspace(hL, hE, nm + 1)
                xs = np.linspace(0.0, X, nx + 1)
                m = model(hm, xs)
                table = (hm, xs, m)
                # checks: x midpoints on the rows, row midpoints at the x knots
                xmid = 0.5 * (xs[:-1] + xs[1:])
                hmid = 0.5 * (hm[:-1] + hm[1:])
                ex = cls._check(m, hm, xs, model(hm, xmid), hm, xmid, tail)
                em = cls._check(m, hm, xs, model(hmid, xs), hmid, xs, tail)
            except _Budget:
                if strict or table is None:
                    raise RuntimeError(
                        f"HistoryNormalLaw: budget (max_points = {max_points}, max_seconds = "
                        f"{max_seconds}) exhausted at rtol = {rtol}; reached {worst:.2g} with "
                        f"{nm} x {nx} intervals: loosen rtol or raise the budget") from None
                break
            worst = max(ex, em)
            if worst <= rtol:
                break
            if ex > rtol:
                nx *= 2
            if em > rtol:
                nm *= 2
        hm, xs, m = table
        law = cls._assemble(loading, rtol, sig, hm, xs, m, surface)
        ok = law._check_monotone()
        law.info.update({"build_seconds": time.perf_counter() - t0, "loading_seconds": t_load,
                         "history_seconds": time.perf_counter() - t1, "rows": hm.size,
                         "x_knots": xs.size, "X": X, "model_points": n_pts[0],
                         "worst_error": float(worst), "n_quad": n_quad, "n_t": n_t,
                         "k_nonnegative": ok, "reversible": False})
        return law

    @classmethod
    def _check(cls, m, hm, xs, ref, hq, xq, tail):
        """Worst relative error of p, k, a of the grid table (m on hm x xs) at hq x xq."""
        dm, dx = hm[1] - hm[0], xs[1] - xs[0]
        C = _bicubic(m[0], m[1], dm, dx)
        CA = _bicubic(m[2], m[3], dm, dx)
        H, Xq = np.meshgrid(hq, xq, indexing="ij")
        H, Xq = H.ravel(), Xq.ravel()
        i, j, tm, tx = cls._locate(H, Xq, hm[0], dm, dx, hm.size - 1, xs.size - 1)
        r, dr = _eval_cells(C, i, j, tm, tx)
        la, _ = _eval_cells(CA, i, j, tm, tx)
        rr, drr, lar = (ref[q].ravel() for q in range(3))
        use = rr > math.log(tail)
        if not use.any():
            return 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            ek = np.where(drr < 0, np.abs(np.exp(r - rr) * (dr / dx) / drr - 1.0), np.inf)
        e = np.maximum.reduce([np.abs(np.expm1(r - rr)), ek, np.abs(np.expm1(la - lar))])
        return float(e[use].max())

    @staticmethod
    def _locate(hm, x, h0, dm, dx, n_m, n_x):
        um = np.clip((hm - h0) / dm, 0.0, n_m)
        i = np.minimum(um.astype(np.intp), n_m - 1)
        ux = np.clip(x / dx, 0.0, n_x)
        j = np.minimum(ux.astype(np.intp), n_x - 1)
        return i, j, um - i, ux - j

    @classmethod
    def _assemble(cls, loading, rtol, sig, hm, xs, m, surface):
        dm, dx = float(hm[1] - hm[0]), float(xs[1] - xs[0])
        C = _bicubic(m[0], m[1], dm, dx)
        CA = _bicubic(m[2], m[3], dm, dx)
        n_m = hm.size - 1
        # recoverable energy per row: sigma p0 int exp(rho) dx (Gauss-Legendre per x cell, on
        # the interpolant itself) + the taper's p_X L/4
        g, w = np.polynomial.legendre.leggauss(8)
        g, w = 0.5 * (g + 1.0), 0.5 * w
        n_x = xs.size - 1
        I = np.zeros(n_m + 1)
        for r in range(n_m + 1):
            i = np.full(n_x * g.size, min(r, n_m - 1))
            tm = np.full(i.size, 1.0 if r == n_m else 0.0)
            j = np.repeat(np.arange(n_x), g.size)
            tx = np.tile(g, n_x)
            v, _ = _eval_cells(C, i, j, tm, tx)
            I[r] = dx * np.sum(np.tile(w, n_x) * np.exp(v))
            vX, dvX = _eval_cells(C, i[-1:], j[-1:], tm[-1:], np.ones(1))
            pX, kX = math.exp(vX[0]), -math.exp(vX[0]) * dvX[0] / dx      # per unit x
            if kX > 0:
                I[r] += pX * (3.0 * pX / kX) / 4.0
        p0 = loading.evaluate(hm)[0]
        E_rec = sig * p0 * I
        W = _work_to(loading, hm)
        D = np.maximum(W - E_rec, 0.0)
        D[-1] = 0.0
        dD = _pchip_slopes(hm, D)
        law = cls(loading=loading, rtol=rtol, sigma=sig, _hm0=float(hm[0]), _dm=dm, _dx=dx,
                  _X=float(xs[-1]), _C=C, _CA=CA, _D=D, _dD=dD, _IL=float(I[0]),
                  info={"recoverable_energy_rows": E_rec, "work_rows": W})
        return law

    def _check_monotone(self, n: int = 200_000) -> bool:
        rng = np.random.default_rng(1)
        hm = rng.uniform(self.h_min, self.h_table_end, n)
        h = hm + rng.uniform(0.0, 1.2 * self._X * self.sigma, n)
        _, k, _ = self.evaluate_history(h, hm)
        return bool(np.all(k >= 0.0))

    # ------------------------------------------------------------ evaluation
    def evaluate_history(self, h, h_min, curvature: bool = False):
        """(p [MPa], k = -dp/dh|_{h_min} [MPa/mm], A/A0 [-][, dk/dh [MPa/mm^2]]) at
        separations h after the smallest separation h_min (broadcast; h <= h_min: loading)."""
        h = np.asarray(h, dtype=float)
        hmn = np.asarray(h_min, dtype=float)
        if np.isnan(h).any() or np.isnan(hmn).any():
            raise ValueError("h or h_min contains NaN: valid range (-inf, inf] mm")
        h, hmn = np.broadcast_arrays(h, hmn)
        shape = h.shape
        h, hmn = h.ravel(), hmn.ravel()
        if self._C is None:                       # reversible: h_min has no effect
            return tuple(v.reshape(shape) for v in self.loading.evaluate(h, curvature))
        # one loading evaluation: at h on the loading branch, at h_min (the branch's p0) else
        out = self.loading.evaluate(np.minimum(h, hmn), curvature)
        out = [np.array(v, dtype=float).ravel() for v in out]
        un = np.flatnonzero((h > hmn) & (hmn < self.h_table_end))
        if un.size:
            self._unload(h.take(un), hmn.take(un), [v.take(un) for v in out], out, un,
                         curvature)
        return tuple(v.reshape(shape) for v in out)

    def _unload(self, h, hm, base, out, idx, curvature):
        p0, a0 = base[0], base[2]
        sig, dx = self.sigma, self._dx
        n_m, n_x = self._C.shape[0], self._C.shape[1]
        x = (h - hm) / sig
        xc = np.minimum(x, self._X)
        i, j, tm, tx = self._locate(hm, xc, self._hm0, self._dm, dx, n_m, n_x)
        r = _eval_cells(self._C, i, j, tm, tx, second=curvature)
        la, _ = _eval_cells(self._CA, i, j, tm, tx)
        p = p0 * np.exp(r[0])
        k = -p * r[1] / (dx * sig)
        a = a0 * np.exp(la)
        if curvature:
            d1 = r[1] / (dx * sig)
            dk = -p * (r[2] / (dx * sig) ** 2 + d1 * d1)
        tp = x > self._X
        if tp.any():
            pe, ke, ae = p[tp], k[tp], a[tp]
            L = 3.0 * pe / np.maximum(ke, 1e-300)
            t = np.clip((x[tp] - self._X) * sig / L, 0.0, 1.0)
            p[tp] = pe * (1 - t) ** 3
            k[tp] = 3.0 * pe / L * (1 - t) ** 2
            a[tp] = ae * (1 - t) ** 3
            if curvature:
                dk[tp] = -6.0 * pe / (L * L) * (1 - t)
        out[0][idx], out[1][idx], out[2][idx] = p, k, a
        if curvature:
            out[3][idx] = dk

    def normal_dissipation(self, h_min) -> np.ndarray:
        """D(h_min) [N/mm] (module doc): cubic Hermite with monotone slopes through the rows'
        values; below the table the first row's branch shape scaled by p_load(h_min)."""
        hm = np.asarray(h_min, dtype=float)
        if self._C is None:
            return np.zeros(hm.shape)
        flat = hm.ravel()
        out = np.zeros(flat.size)
        n_m = self._D.size - 1
        inside = (flat >= self._hm0) & (flat < self.h_table_end)
        if inside.any():
            u = (flat[inside] - self._hm0) / self._dm
            i = np.minimum(u.astype(np.intp), n_m - 1)
            t = u - i
            y0, y1 = self._D[i], self._D[i + 1]
            m0, m1 = self._dD[i] * self._dm, self._dD[i + 1] * self._dm
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
