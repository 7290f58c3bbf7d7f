"""Slip-hardening friction at interface points: return mapping and consistent tangent.

Units: tractions and pressures in MPa, slips in mm, stiffnesses per area in MPa/mm,
hardening rates in 1/mm.

Orthotropic model, paper section 8.1
------------------------------------
Friction coefficients harden with the accumulated slip along each axis, (89)-(90):

    mu_i = mu_mi [1 - (1 - mu_oi) exp(-n_i kappa_i)],   i = x, y,

slip criterion (91), an ellipse scaled by the contact pressure p = -t_N:

    f = sqrt((t_x/mu_x)^2 + (t_y/mu_y)^2) - p <= 0,

non-associated slip potential (98)/(101) with axes (nu_x, nu_y); only the ratio nu_y/nu_x
matters (the size is absorbed by the slip multiplier), either fixed or from the k-form of (98),
nu_y/nu_x = (mu_y/mu_x)^k. The potential's t_N term only produces dilatancy, which the paper
removes (Delta u^p_N = 0), so (98) and the Huber-von Mises cylinder (101) give the same law here.
Slip rule (99): Delta s_p = Delta gamma dg/dt_T, dg/dt_i = t_i / (nu_i^2 ||t||_nu).

Isotropic model, paper section 8.2
----------------------------------
(119) mu_F = mu_m [1 - (1 - beta) exp(-n kappa)], kappa = effective plastic slip (path length),
(120) f = ||t_T|| - mu_F p,  (121) circular potential (slip coaxial with the traction).

Decisions (documented in ``docs/equations.md``):
    * Elastic part in TOTAL form: t_T = K_T(h) (s - s_p), K_T = diag(kTx, kTy), kT_i = c_i kN(h)
      (``tangential.TangentialStiffness``). On opening (kN -> 0) the elastic slip is released and
      the plastic slip s_p is kept. The tangent therefore contains dK_T/dg = c_i dkN/dh.
    * Hardening variables accumulate slip MAGNITUDE: kappa_i += |Delta s_p,i| (orthotropic) and
      kappa += ||Delta s_p|| (isotropic), so hardening never reverses on unloading. For monotonic
      slip along +x this is the paper's u^p_Tx.
    * With the k-form of the potential, the axis ratio uses the committed (start-of-increment)
      friction coefficients, so each step solves one scalar equation (exact when mu_o = 1 or
      n = 0; otherwise lagged by one increment).
    * Backward Euler (closest-point type) return map. Writing lambda = Delta gamma/||t||_nu and
      w_i = 1/nu_i^2, the corrected traction is diagonal in lambda,
          t_i = t_trial,i / (1 + lambda kT_i w_i),
      so each slipping point solves ONE scalar equation for lambda >= 0 (monotone, unique root),
      by safeguarded Newton on H(lambda) = p/N(lambda) - 1 (N = ||t||_mu, linear in lambda for
      isotropic perfect friction, so Newton is exact in one step there).
    * Isotropic law with kTx == kTy: radial return, tau = p mu_F(kappa_n + (T_trial - tau)/kT),
      closed form without hardening, else a monotone scalar Newton on tau.
    * p below 1e-16 of the trial norm (including p = 0 and denormals): closed-form limit (all
      elastic slip becomes plastic, t = p times the slip direction on the ellipse), no overflow.
    * After the Newton reaches |H| <= 1e-10 one more Newton step is taken, so the map is smooth
      to round-off (f = 0 to ~1e-16 p) and finite differences reproduce the tangent.
    * The tangent returned is the ALGORITHMIC one (derivative of the discrete map), including the
      coupling to the normal jump through p(h) and kT(h); ``continuum_tangent`` gives the paper's
      (107)-(110) for comparison.
    * Multipliers (exact stick by an augmented-Lagrangian enforcement): the elastic predictor
      may be shifted, t_trial = lambda_T + K_T e (``FrictionInput.trial_shift_x/_y``); everything
      after the predictor is the same map with that t_trial (the plastic increment is
      Delta s_p = e - (t - lambda_T) / K_T, the hardening follows it).

Sign convention (the interface-law contract, ``rough_contact.interface.contract``):
t = dpsi/djump, jump = (g, s_x, s_y), t_N = -p, so the friction traction t_T points along the
elastic slip s - s_p (it resists the motion of the second body). ``docs/equations.md`` lists
the readings of (89)-(131) used here.

Entry point: ``evaluate(FrictionInput, traction=, tangent=) -> FrictionOutput``, what the
composed law (``rough_contact.interface.law.InterfaceLaw``) calls at every evaluation (shapes
checked, values trusted, results written into the caller's arrays). Other callers build the
input with ``FrictionInput.from_pairs`` ((m, 2) pairs, every value validated);
``FrictionOutput.slipping`` and ``.plastic_increment`` give the dense (m,) / (m, 2) views.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ..validation import check_scalar
from .contract import ConvergenceError

__all__ = [
    "OrthotropicSlipHardening",
    "IsotropicSlipHardening",
    "FrictionInput",
    "ShiftedFrictionInput",
    "FrictionOutput",
    "ReturnMappingError",
    "continuum_tangent",
    "directional_coefficient",
    "traction_angle",
    "limit_coefficient",
]

_TOL_LOOSE = 1e-10  # |H| = |p/N - 1| (or |R|/(p mu)) before the final polishing Newton step
_MAX_ITER = 80
_RELEASE = 1e-16  # p < 1e-16 N_trial min(a)/max(a): closed-form release limit (no overflow)


class ReturnMappingError(ConvergenceError):
    """The local Newton of the return map did not converge at some points.

    A ``ConvergenceError``: a smaller load increment (a smaller slip increment) usually cures it.
    """


@dataclass(frozen=True)
class FrictionInput:
    """What a friction law's return map needs at m contact points, as 1-D columns (m,).

    The composed law (``rough_contact.interface.law.InterfaceLaw``) fills it from the normal
    law, the tangential stiffness and the committed history; ``evaluate`` reads it and never
    writes to it. Columns rather than (m, 2) pairs so that the caller can hand over views and
    the return map can gather the slipping subset with one ``take`` per column.

    Attributes:
        elastic_slip_x, elastic_slip_y: trial elastic slip e = s - s_p(committed) [mm].
        kt_x, kt_y: tangential stiffnesses kT_i = c_i kN(h) > 0 [MPa/mm] (with a memory law,
            on the unloading branch c_i kN(h) kN_load(h_min)/kN_rev(h_min): InterfaceLaw).
        dkt_x, dkt_y: their derivatives d kT_i / d g [MPa/mm^2].
        pressure: contact pressure p >= 0 [MPa].
        kn: normal stiffness kN = -dp/dg >= 0 [MPa/mm].
        kappa_x, kappa_y: committed accumulated slip magnitudes, hardening variables of the
            orthotropic law (89)-(90) [mm].
        slip_path: committed effective plastic slip (path length), hardening variable of the
            isotropic law (119) [mm].

    The elastic predictor is t_trial = K_T e; :class:`ShiftedFrictionInput` adds tangential
    multipliers to it.

    Raises:
        ValueError: a column that is not a 1-D array, or columns of different lengths. Values
            are not checked here (``evaluate`` is the hot path; ``from_pairs`` checks them).
    """

    elastic_slip_x: np.ndarray
    elastic_slip_y: np.ndarray
    kt_x: np.ndarray
    kt_y: np.ndarray
    dkt_x: np.ndarray
    dkt_y: np.ndarray
    pressure: np.ndarray
    kn: np.ndarray
    kappa_x: np.ndarray
    kappa_y: np.ndarray
    slip_path: np.ndarray

    def __post_init__(self) -> None:
        m = np.shape(self.elastic_slip_x)[0] if np.ndim(self.elastic_slip_x) == 1 else -1
        for name in self.__dataclass_fields__:
            v = getattr(self, name)
            if not isinstance(v, np.ndarray) or v.ndim != 1 or v.shape[0] != m:
                raise ValueError(f"FrictionInput.{name} must be a 1-D array of the same length "
                                 f"as elastic_slip_x ({m}), got shape {np.shape(v)}")

    def __len__(self) -> int:
        return self.elastic_slip_x.shape[0]

    shifted = False    # the elastic predictor is K_T e (ShiftedFrictionInput: + lambda_T)

    @classmethod
    def from_pairs(cls, elastic_slip, kt, dkt, pressure, kn, accumulated_slip,
                   slip_path, trial_shift=None) -> FrictionInput:
        """The validated input from (m, 2) pairs and (m,) arrays (every value checked).

        Args:
            elastic_slip: (m, 2) trial elastic slip s - s_p(committed) [mm].
            kt: (m, 2) tangential stiffnesses (kTx, kTy) > 0 [MPa/mm].
            dkt: (m, 2) their derivatives d kT / d g [MPa/mm^2].
            pressure: (m,) contact pressure p >= 0 [MPa].
            kn: (m,) normal stiffness -dp/dg >= 0 [MPa/mm].
            accumulated_slip: (m, 2) committed hardening variables kappa_x, kappa_y [mm]
                (orthotropic law).
            slip_path: (m,) committed effective plastic slip [mm] (isotropic law).
            trial_shift: optional (m, 2) tangential multipliers lambda_T [MPa] shifting the
                elastic predictor (a :class:`ShiftedFrictionInput`; None: the plain input).

        Raises:
            ValueError: a wrong shape, a non-finite value, p < 0, kT <= 0 or kN < 0.
        """
        e = np.asarray(elastic_slip, dtype=float)
        if e.ndim != 2 or e.shape[1] != 2:
            raise ValueError(f"elastic_slip must have shape (m, 2), got {e.shape}")
        m = e.shape[0]
        arrs = {}
        for name, arr, shape in (("kt", kt, (m, 2)), ("dkt", dkt, (m, 2)),
                                 ("pressure", pressure, (m,)), ("kn", kn, (m,)),
                                 ("accumulated_slip", accumulated_slip, (m, 2)),
                                 ("slip_path", slip_path, (m,)),
                                 ("trial_shift", trial_shift, (m, 2))):
            if arr is None:     # no trial_shift
                continue
            a = np.asarray(arr, dtype=float)
            if a.shape != shape:
                raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
            arrs[name] = a
        for name in arrs:
            if not np.isfinite(arrs[name]).all():
                raise ValueError(f"{name} must be finite at every point")
        if not np.isfinite(e).all():
            raise ValueError("elastic_slip must be finite at every point")
        if np.any(arrs["pressure"] < 0):
            raise ValueError("pressure must be >= 0 at every point [MPa]")
        if np.any(arrs["kt"] <= 0):
            raise ValueError("kt (tangential stiffness) must be > 0 at every contact point "
                             "[MPa/mm]")
        if np.any(arrs["kn"] < 0):
            raise ValueError("kn (normal stiffness) must be >= 0 at every point [MPa/mm]")
        kt, dkt, kap = arrs["kt"], arrs["dkt"], arrs["accumulated_slip"]
        cols = (e[:, 0].copy(), e[:, 1].copy(), kt[:, 0].copy(), kt[:, 1].copy(),
                dkt[:, 0].copy(), dkt[:, 1].copy(), arrs["pressure"], arrs["kn"],
                kap[:, 0].copy(), kap[:, 1].copy(), arrs["slip_path"])
        shift = arrs.get("trial_shift")
        if shift is None:
            return cls(*cols)
        return ShiftedFrictionInput(*cols, shift[:, 0].copy(), shift[:, 1].copy())

    def take(self, idx) -> FrictionInput:
        """The columns at points ``idx`` (a gathered copy, of the same type)."""
        return type(self)(*(getattr(self, f).take(idx) for f in self.__dataclass_fields__))

    def trial_slip(self) -> Tuple[np.ndarray, np.ndarray]:
        """(e_x, e_y) with t_trial = K_T (e_x, e_y) [mm]: here the elastic slip."""
        return self.elastic_slip_x, self.elastic_slip_y


@dataclass(frozen=True)
class ShiftedFrictionInput(FrictionInput):
    """A :class:`FrictionInput` whose elastic predictor is shifted by tangential multipliers:
    t_trial = lambda_T + K_T e (the rough law under an augmented-Lagrangian enforcement,
    ``InterfaceLaw.with_multipliers``). The return map is otherwise the same: the corrected
    traction, the plastic slip increment Delta s_p = e - (t - lambda_T) / K_T and the hardening
    follow from t_trial; the g-column of the tangent keeps d t_trial / dg = dK_T/dg e (the
    shift does not depend on the jump).

    Attributes (besides :class:`FrictionInput`'s):
        trial_shift_x, trial_shift_y: (m,) tangential multipliers lambda_x, lambda_y [MPa].
    """

    trial_shift_x: np.ndarray
    trial_shift_y: np.ndarray

    shifted = True

    def trial_slip(self) -> Tuple[np.ndarray, np.ndarray]:
        """(e_x, e_y) with t_trial = K_T (e_x, e_y): e + lambda_T / K_T [mm] (K_T > 0, as the
        return map needs)."""
        return (self.elastic_slip_x + self.trial_shift_x / self.kt_x,
                self.elastic_slip_y + self.trial_shift_y / self.kt_y)


@dataclass(frozen=True)
class FrictionOutput:
    """Outcome of ``evaluate`` at m contact points; slip data only where the limit is active.

    Attributes:
        traction: (m, 2) tangential traction (t_x, t_y) [MPa] (the array given as ``traction=``
            to ``evaluate``, if any).
        tangent: (m, 2, 3) algorithmic tangent d t_T / d(g, s_x, s_y) [MPa/mm] (likewise).
        slip_index: (k,) int, ascending indices in [0, m) of the points that slip.
        plastic_increment_x, plastic_increment_y: (k,) Delta s_p at those points [mm].
        path_increment: (k,) ||Delta s_p|| [mm] (increment of the isotropic law's kappa, (119)).
        iterations: local Newton iterations used (0 if nothing slipped).
    """

    traction: np.ndarray
    tangent: np.ndarray
    slip_index: np.ndarray
    plastic_increment_x: np.ndarray
    plastic_increment_y: np.ndarray
    path_increment: np.ndarray
    iterations: int

    @property
    def slipping(self) -> np.ndarray:
        """(m,) bool, True where the friction limit is active."""
        out = np.zeros(self.traction.shape[0], dtype=bool)
        out[self.slip_index] = True
        return out

    @property
    def plastic_increment(self) -> np.ndarray:
        """(m, 2) Delta s_p at all points [mm] (zero where sticking)."""
        out = np.zeros((self.traction.shape[0], 2))
        out[self.slip_index, 0] = self.plastic_increment_x
        out[self.slip_index, 1] = self.plastic_increment_y
        return out


_NO_SLIP = np.zeros(0, dtype=np.intp)
_NO_SLIP.flags.writeable = False
_NO_INCREMENT = np.zeros(0)
_NO_INCREMENT.flags.writeable = False


def _no_slip(traction, tangent) -> FrictionOutput:
    return FrictionOutput(traction, tangent, _NO_SLIP, _NO_INCREMENT, _NO_INCREMENT,
                          _NO_INCREMENT, 0)


def _outputs(points: FrictionInput, traction, tangent):
    """Check (or allocate) the arrays ``evaluate`` writes into."""
    if not isinstance(points, FrictionInput):
        raise ValueError(f"points must be a FrictionInput, got {type(points).__name__}")
    m = len(points)
    if traction is None:
        traction = np.empty((m, 2))
    elif not (isinstance(traction, np.ndarray) and traction.shape == (m, 2)
              and traction.dtype == np.float64):
        raise ValueError(f"traction must be a float64 array of shape ({m}, 2), got "
                         f"{getattr(traction, 'dtype', type(traction).__name__)} "
                         f"{np.shape(traction)}")
    if tangent is None:
        tangent = np.empty((m, 2, 3))
    elif not (isinstance(tangent, np.ndarray) and tangent.shape == (m, 2, 3)
              and tangent.dtype == np.float64):
        raise ValueError(f"tangent must be a float64 array of shape ({m}, 2, 3), got "
                         f"{getattr(tangent, 'dtype', type(tangent).__name__)} "
                         f"{np.shape(tangent)}")
    return traction, tangent


# ----------------------------------------------------------------------------- validation
def _pair(name: str, value, **bounds) -> Tuple[float, float]:
    """(x, y) pair of parameters, each checked by ``check_scalar`` (a scalar applies to both)."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.full(3, np.nan)  # not numeric: reported as not a pair below
    if arr.ndim == 0:
        arr = np.array([arr, arr], dtype=float)
    if arr.shape != (2,):
        raise ValueError(f"{name} must be a scalar or a pair (x, y), got {value!r}")
    return tuple(check_scalar(f"{name}[{axis}]", float(v), **bounds) for axis, v in zip("xy", arr))


def _norm(x, y):
    """sqrt(x^2 + y^2) of arrays; np.hypot (30x slower) only where squares could over/underflow."""
    r = np.sqrt(x * x + y * y)
    bad = ~((r < 1e150) & (r > 1e-150))
    if bad.any():
        r[bad] = np.hypot(x[bad], y[bad])
    return r


# ----------------------------------------------------------------------------- hardening
def _hardening(mu_m: float, mu_o: float, n: float, kappa):
    """mu(kappa) and dmu/dkappa of (89)/(90)/(119); kappa >= 0 [mm].

    n = 0 keeps the initial value mu_o mu_m; mu_o = 1 gives the constant mu_m. Constant laws
    return Python floats (broadcast for free).
    """
    if n == 0.0 or mu_o == 1.0:
        return (mu_m * mu_o if n == 0.0 else mu_m), 0.0
    soft = np.exp(-n * kappa)
    soft *= 1.0 - mu_o
    return mu_m * (1.0 - soft), (mu_m * n) * soft


# ----------------------------------------------------------------------------- Newton driver
def _solve_lambda(model, lam0, lo, hi, what: str):
    """Safeguarded Newton for H(lambda) = 0 on all points at once (H increasing, H(lo)<0<=H(hi)).

    ``model(lam) -> (H, dH)``. Iterates until |H| <= 1e-10 everywhere, then takes one more
    Newton step: with quadratic convergence that leaves lambda at round-off, so the result is a
    smooth function of the inputs to ~1e-16 (finite differences of the traction see the
    tangent, not the solver tolerance). Returns (lam, iterations).
    """
    lam = lam0
    for it in range(1, _MAX_ITER + 1):
        H, dH = model(lam)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            step = lam - H / dH
        aH = np.abs(H)
        if aH.max() <= _TOL_LOOSE:
            ok = np.isfinite(step) & (step >= 0.0)
            return (step if ok.all() else np.where(ok, step, lam)), it
        below = H < 0.0
        lo = np.where(below, lam, lo)
        hi = np.where(below, hi, lam)
        ok = (step > lo) & (step < hi)
        if ok.all():
            lam = step
            continue
        with np.errstate(invalid="ignore", over="ignore"):
            geometric = (lo > 0.0) & (hi > 16.0 * lo)
            mid = np.where(geometric, np.sqrt(lo * hi), 0.5 * (lo + hi))
        new = np.where(ok, step, mid)
        done = (aH <= _TOL_LOOSE) | ((hi - lo) <= 4e-16 * hi)
        lam = np.where(done, lam, new)
        if done.all():
            return lam, it
    nbad = int(np.count_nonzero(aH > _TOL_LOOSE))
    raise ReturnMappingError(
        f"{what}: local Newton did not converge at {nbad} of {lam.size} slipping points after "
        f"{_MAX_ITER} iterations (max |p/N - 1| = {aH.max():.3e}; non-finite input or extreme "
        "parameters)"
    )


def _initial_bracket(excess_num, p, ax, ay, qx2, qy2, n_lo):
    """Bracket and first guess for lambda: N(lam) is squeezed by 1/(1 + lam a) bounds."""
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        excess = np.minimum(excess_num / p, 1e300) - 1.0
        amin = np.minimum(ax, ay)
        amax = np.maximum(ax, ay)
        hi = np.minimum(excess / amin, 1e300)
        lo = np.maximum((np.minimum(n_lo / p, 1e300) - 1.0) / amax, 0.0)
        aeff = (qx2 * ax + qy2 * ay) / (qx2 + qy2)
        lam0 = np.clip(excess / aeff, lo, hi)
    return lam0, lo, hi


def _write_stick(c: FrictionInput, out_t, out_D):
    """Elastic (stick) values at every point: t = K_T e (+ lambda_T when shifted),
    dt/d(g, s) = [dK_T e, K_T]."""
    tx = c.kt_x * c.elastic_slip_x
    ty = c.kt_y * c.elastic_slip_y
    if c.shifted:
        tx += c.trial_shift_x
        ty += c.trial_shift_y
    out_t[:, 0] = tx
    out_t[:, 1] = ty
    out_D[:, 0, 0] = c.dkt_x * c.elastic_slip_x
    out_D[:, 0, 1] = c.kt_x
    out_D[:, 0, 2] = 0.0
    out_D[:, 1, 0] = c.dkt_y * c.elastic_slip_y
    out_D[:, 1, 1] = 0.0
    out_D[:, 1, 2] = c.kt_y
    return tx, ty


def _write_slip(idx, out_t, out_D, tx, ty, D):
    out_t[idx, 0] = tx
    out_t[idx, 1] = ty
    for (i, j), v in D.items():
        out_D[idx, i, j] = v


def _tangent(c: FrictionInput, tx, ty, lam, wx, wy, Dx, Dy, bx, by, c0):
    """Algorithmic tangent rows d t_T / d(g, s_x, s_y) at slipping points.

    t_i = t_trial,i / D_i with D_i = 1 + lam kT_i w_i and the scalar equation F = N - p = 0;
    dt_i = r_i - v_i dlam,  r_i = [dt_trial,i - t_i w_i lam dkT_i]/D_i,  v_i = t_i w_i kT_i/D_i,
    dlam = (sum_i b_i r_i - dp)/den,  den = sum_i b_i v_i - c0 = -dN/dlam > 0,  dp/dg = -kN.
    """
    rsx = c.kt_x / Dx
    rsy = c.kt_y / Dy
    lwx = lam * wx
    lwy = lam * wy
    rgx = c.dkt_x * (c.elastic_slip_x - lwx * tx) / Dx
    rgy = c.dkt_y * (c.elastic_slip_y - lwy * ty) / Dy
    vx = tx * wx * rsx  # = t_x w_x kTx / D_x
    vy = ty * wy * rsy
    inv = 1.0 / (bx * vx + by * vy - c0)
    dl_g = (bx * rgx + by * rgy + c.kn) * inv
    dl_sx = bx * rsx * inv
    dl_sy = by * rsy * inv
    return {(0, 0): rgx - vx * dl_g, (0, 1): rsx - vx * dl_sx, (0, 2): -vx * dl_sy,
            (1, 0): rgy - vy * dl_g, (1, 1): -vy * dl_sx, (1, 2): rsy - vy * dl_sy}


def _spread(ax, ay):
    """min(a)/max(a): the release limit needs lam a_i >> 1 along BOTH axes."""
    return np.minimum(ax, ay) / np.maximum(ax, ay)


def _released(c: FrictionInput, ex, ey, ux, uy, mux, muy):
    """Limit p << |t_trial| (p/N_trial < 1e-16 min(a)/max(a)): all elastic slip turns plastic.

    (ex, ey) = t_trial / K_T (``FrictionInput.trial_slip``: the elastic slip e, plus
    lambda_T / K_T when the predictor is shifted), (ux, uy) the slip direction of the potential.

    The exact map gives t = t_trial/(1 + lam a) with lam a_i ~ N_trial/p; to double precision
    t = p u/||u/mu|| with u the slip direction of the potential, Delta s_p = e - t/kT, and the
    only surviving tangent term is through p: dt/dg = -kN u/||u/mu|| (the others are O(p/N)).
    The closed form avoids overflow at denormal pressures.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        nrm = np.hypot(ux / mux, uy / muy)
        pos = nrm > 0
        dx = np.where(pos, ux / nrm, 0.0)
        dy = np.where(pos, uy / nrm, 0.0)
    tx = c.pressure * dx
    ty = c.pressure * dy
    D = {(0, 0): -c.kn * dx, (0, 1): 0.0, (0, 2): 0.0, (1, 0): -c.kn * dy, (1, 1): 0.0,
         (1, 2): 0.0}
    return tx, ty, ex - tx / c.kt_x, ey - ty / c.kt_y, D


def _pick(v, idx):
    """``v`` at the points ``idx``: a per-point array gathered, a scalar (a constant law's
    coefficient, a fixed weight) as it is."""
    return v if np.isscalar(v) else v[idx]


# ----------------------------------------------------------------------------- return map
class _SlipHardening:
    """The return map of both slip-hardening laws, around each law's own corrector.

    The elastic (stick) predictor at every point; at the points whose trial traction lies outside
    the slip criterion, the closed-form release where the pressure vanishes against the trial
    traction (``_release``) and the law's scalar return map elsewhere (``_return_map``). A law
    gives ``_committed_mu(points)`` (the coefficients (mu_x, mu_y) of the criterion at the
    start of the increment) and ``_corrector(s, mu_x, mu_y, t_trial_x, t_trial_y)`` at the
    slipping points: the release mask and the per-point values its two correctors take.
    """

    def evaluate(self, points: FrictionInput, traction: Optional[np.ndarray] = None,
                 tangent: Optional[np.ndarray] = None) -> FrictionOutput:
        """Backward-Euler return map and algorithmic tangent at m contact points (hot path).

        Pure: ``points`` is read, never written. The results are written into ``traction`` and
        ``tangent`` when given (e.g. views into the composed law's (n, 3) and (n, 3, 3) arrays,
        which saves a copy), else into new arrays. Only shapes are checked here; the values are
        trusted (finite, p >= 0, kT > 0: what the composed law produces from a finite jump);
        callers with unchecked data build ``points`` with ``FrictionInput.from_pairs``.

        Args:
            points: the inputs at m points (``FrictionInput``).
            traction: optional (m, 2) float64 output for (t_x, t_y) [MPa].
            tangent: optional (m, 2, 3) float64 output for d t_T / d(g, s_x, s_y) [MPa/mm].

        Returns:
            ``FrictionOutput``: traction and tangent at all m points, and the plastic slip
            increments at the k slipping points.

        Raises:
            ValueError: wrong types or shapes. ReturnMappingError (a ``ConvergenceError``): the
                local Newton did not converge.
        """
        out_t, out_D = _outputs(points, traction, tangent)
        mux, muy = self._committed_mu(points)
        tx, ty = _write_stick(points, out_t, out_D)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            qx = tx / (mux * points.pressure)
            qy = ty / (muy * points.pressure)
            slipping = qx * qx + qy * qy > 1.0
        if not slipping.any():
            return _no_slip(out_t, out_D)
        idx = np.flatnonzero(slipping)
        s = points.take(idx)
        released, values = self._corrector(s, _pick(mux, idx), _pick(muy, idx), tx.take(idx),
                                           ty.take(idx))
        dspx = np.empty(idx.size)
        dspy = np.empty(idx.size)
        its = 0
        if released.any():
            r = np.flatnonzero(released)
            rtx, rty, dspx[r], dspy[r], D = self._release(s.take(r), *(_pick(v, r)
                                                                       for v in values))
            _write_slip(idx[r], out_t, out_D, rtx, rty, D)
        if not released.all():
            g = np.flatnonzero(~released) if released.any() else slice(None)
            sg = s.take(g) if released.any() else s
            gtx, gty, dspx[g], dspy[g], D, its = self._return_map(sg, *(_pick(v, g)
                                                                        for v in values))
            _write_slip(idx[g], out_t, out_D, gtx, gty, D)
        return FrictionOutput(out_t, out_D, idx, dspx, dspy, _norm(dspx, dspy), its)


# ----------------------------------------------------------------------------- orthotropic
@dataclass(frozen=True)
class OrthotropicSlipHardening(_SlipHardening):
    """Orthotropic slip-hardening friction, eqs (89)-(118).

    Args:
        mu_macro: (mu_mx, mu_my), macroscopic (saturated) friction coefficients, > 0 [-].
        mu_initial_ratio: (mu_ox, mu_oy), initial coefficient as a fraction of mu_macro, in
            (0, 1] [-] (1 = no hardening).
        hardening: (n_x, n_y), slip-hardening rates, >= 0 [1/mm] (0 = constant mu = mu_o mu_m).
        potential_axes: (nu_x, nu_y) of the slip potential (98)/(101), > 0 [-]; only the ratio
            matters. None (and no exponent) means a circle: slip coaxial with the traction.
        potential_exponent: k of (98), nu_y/nu_x = (mu_y/mu_x)^k (k = 1 associated, k = 0
            circle); evaluated with the committed coefficients. Exclusive with potential_axes.

    A scalar given for a pair applies to both axes.
    """

    mu_macro: Tuple[float, float]
    mu_initial_ratio: Tuple[float, float] = (1.0, 1.0)
    hardening: Tuple[float, float] = (0.0, 0.0)
    potential_axes: Optional[Tuple[float, float]] = None
    potential_exponent: Optional[float] = None

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "mu_macro", _pair("mu_macro", self.mu_macro, lo=0.0))
        s(self, "mu_initial_ratio",
          _pair("mu_initial_ratio", self.mu_initial_ratio, lo=0.0, hi=1.0, hi_open=False))
        s(self, "hardening", _pair("hardening", self.hardening, lo=0.0, lo_open=False, unit="1/mm"))
        if self.potential_axes is not None and self.potential_exponent is not None:
            raise ValueError("give either potential_axes or potential_exponent, not both")
        if self.potential_axes is not None:
            s(self, "potential_axes",
              _pair("potential_axes", self.potential_axes, lo=0.0))
        if self.potential_exponent is not None:
            s(self, "potential_exponent",
              check_scalar("potential_exponent", self.potential_exponent))

    # -- coefficients ---------------------------------------------------------------------
    def _mu(self, kapx, kapy):
        mux, dmux = _hardening(self.mu_macro[0], self.mu_initial_ratio[0], self.hardening[0], kapx)
        muy, dmuy = _hardening(self.mu_macro[1], self.mu_initial_ratio[1], self.hardening[1], kapy)
        return mux, dmux, muy, dmuy

    def coefficients(self, accumulated_slip: np.ndarray):
        """Friction coefficients and slopes at accumulated slip kappa (m, 2) [mm].

        Returns:
            mu (m, 2) [-] and dmu/dkappa (m, 2) [1/mm], eqs (89)-(90), (111)-(112).
        """
        k = np.asarray(accumulated_slip, dtype=float)
        mux, dmux, muy, dmuy = self._mu(k[..., 0], k[..., 1])
        b = np.broadcast_arrays(mux, dmux, muy, dmuy, k[..., 0])
        return np.stack([b[0], b[2]], axis=-1), np.stack([b[1], b[3]], axis=-1)

    def _weights(self, mux, muy):
        """(w_x, w_y) = (1, (nu_x/nu_y)^2) of the slip potential, floats or arrays [-]."""
        if self.potential_exponent is not None:
            return 1.0, (mux / muy) ** (2.0 * self.potential_exponent)
        if self.potential_axes is not None:
            return 1.0, (self.potential_axes[0] / self.potential_axes[1]) ** 2
        return 1.0, 1.0

    def slip_function(self, traction_t, pressure, accumulated_slip):
        """f of (91) [MPa] at traction (m, 2), pressure (m,), accumulated slip (m, 2)."""
        mu, _ = self.coefficients(accumulated_slip)
        t = np.asarray(traction_t, dtype=float)
        return np.hypot(t[:, 0] / mu[:, 0], t[:, 1] / mu[:, 1]) - np.asarray(pressure, dtype=float)

    # -- return map ----------------------------------------------------------------------
    def _committed_mu(self, c: FrictionInput):
        mux, _, muy, _ = self._mu(c.kappa_x, c.kappa_y)
        return mux, muy

    def _corrector(self, s: FrictionInput, mux, muy, cx, cy):
        wx, wy = self._weights(mux, muy)
        ax = s.kt_x * wx
        ay = s.kt_y * wy
        ntr = _norm(cx / mux, cy / muy)
        released = ntr * (_RELEASE * _spread(ax, ay)) > s.pressure
        return released, (mux, muy, wy, cx, cy, ntr, ax, ay)

    def _release(self, s: FrictionInput, _mux, _muy, wy, *_):
        ex, ey = s.trial_slip()
        ux, uy = ex, ey / wy       # w_x = 1
        mx, _, my, _ = self._mu(s.kappa_x + np.abs(ex), s.kappa_y + np.abs(ey))
        return _released(s, ex, ey, ux, uy, mx, my)

    def _return_map(self, s: FrictionInput, mux_n, muy_n, wy, cx, cy, ntr, ax, ay):
        mmx, mmy = self.mu_macro
        wx = 1.0
        acx, acy = np.abs(cx), np.abs(cy)
        qx2 = (cx / mux_n) ** 2
        qy2 = (cy / muy_n) ** 2
        n_lo = _norm(cx / mmx, cy / mmy)  # trial norm with saturated mu (lower bound of N)
        lam0, lo, hi = _initial_bracket(ntr, s.pressure, ax, ay, qx2, qy2, n_lo)
        p = s.pressure

        def state(lam):
            Dx = 1.0 + lam * ax
            Dy = 1.0 + lam * ay
            tx = cx / Dx
            ty = cy / Dy
            mux, dmux, muy, dmuy = self._mu(s.kappa_x + lam * wx * acx / Dx,
                                            s.kappa_y + lam * wy * acy / Dy)
            return Dx, Dy, tx, ty, mux, dmux, muy, dmuy

        def model(lam):
            Dx, Dy, tx, ty, mux, dmux, muy, dmuy = state(lam)
            qx = tx / mux
            qy = ty / muy
            N2 = qx * qx + qy * qy
            # d/dlam: dt_i = -a_i t_i / D_i, dkappa_i = w_i |t_i| / D_i
            dqx = (-ax * tx - qx * dmux * wx * np.abs(tx)) / (Dx * mux)
            dqy = (-ay * ty - qy * dmuy * wy * np.abs(ty)) / (Dy * muy)
            N = np.sqrt(N2)
            # H = p/N - 1, dH = -p dN/N^2 with dN = (q . dq)/N
            return p / N - 1.0, -p * (qx * dqx + qy * dqy) / (N2 * N)

        lam, its = _solve_lambda(model, lam0, lo, hi, "orthotropic friction return map")
        Dx, Dy, tx, ty, mux, dmux, muy, dmuy = state(lam)
        # linearisation of F = N(t, mu(kappa)) - p
        qx = tx / mux
        qy = ty / muy
        N = _norm(qx, qy)
        ntx = qx / (N * mux)
        nty = qy / (N * muy)
        nmx = -qx * ntx
        nmy = -qy * nty
        bx = ntx + nmx * dmux * lam * wx * np.sign(tx)
        by = nty + nmy * dmuy * lam * wy * np.sign(ty)
        c0 = nmx * dmux * wx * np.abs(tx) + nmy * dmuy * wy * np.abs(ty)
        D = _tangent(s, tx, ty, lam, wx, wy, Dx, Dy, bx, by, c0)
        return tx, ty, lam * wx * tx, lam * wy * ty, D, its


# ----------------------------------------------------------------------------- isotropic
@dataclass(frozen=True)
class IsotropicSlipHardening(_SlipHardening):
    """Isotropic slip-hardening friction (Fredriksson), eqs (119)-(131).

    Args:
        mu_macro: macroscopic friction coefficient mu_m > 0 [-].
        mu_initial_ratio: beta of (119), initial coefficient as a fraction of mu_m, in (0, 1] [-].
        hardening: slip-hardening rate n >= 0 [1/mm].

    The hardening variable is the effective plastic slip (path length sum ||Delta s_p||).
    With kTx == kTy the return map is radial and is solved in closed form (no hardening) or by a
    scalar monotone Newton on the traction magnitude; with kTx != kTy the general scalar return
    map (as in the orthotropic law) is used.
    """

    mu_macro: float
    mu_initial_ratio: float = 1.0
    hardening: float = 0.0

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "mu_macro", check_scalar("mu_macro", self.mu_macro, lo=0.0))
        s(self, "mu_initial_ratio",
          check_scalar("mu_initial_ratio", self.mu_initial_ratio, lo=0.0, hi=1.0, hi_open=False))
        s(self, "hardening",
          check_scalar("hardening", self.hardening, lo=0.0, lo_open=False, unit="1/mm"))

    def _mu(self, kap):
        return _hardening(self.mu_macro, self.mu_initial_ratio, self.hardening, kap)

    def coefficient(self, slip_path):
        """mu_F (119) and d mu_F / d kappa (129) at effective plastic slip kappa [mm], arrays."""
        kap = np.asarray(slip_path, dtype=float)
        mu, dmu = self._mu(kap)
        return np.broadcast_to(mu, kap.shape).copy(), np.broadcast_to(dmu, kap.shape).copy()

    def slip_function(self, traction_t, pressure, slip_path):
        """f of (120) [MPa]."""
        mu, _ = self.coefficient(slip_path)
        t = np.asarray(traction_t, dtype=float)
        return np.hypot(t[:, 0], t[:, 1]) - mu * np.asarray(pressure, dtype=float)

    # -- return map ----------------------------------------------------------------------
    def _committed_mu(self, c: FrictionInput):
        mu, _ = self._mu(c.slip_path)
        return mu, mu

    def _corrector(self, s: FrictionInput, mu, _, cx, cy):
        T = _norm(cx, cy)
        released = T * (_RELEASE * _spread(s.kt_x, s.kt_y)) > mu * s.pressure
        return released, (mu, cx, cy, T)

    def _release(self, s: FrictionInput, *_):
        ex, ey = s.trial_slip()
        mu, _ = self._mu(s.slip_path + np.hypot(ex, ey))
        return _released(s, ex, ey, ex, ey, mu, mu)

    def _return_map(self, s: FrictionInput, mu_n, cx, cy, T):
        """Radial when kTx == kTy (and dkTx == dkTy), else the general scalar return map."""
        radial = np.array_equal(s.kt_x, s.kt_y) and np.array_equal(s.dkt_x, s.dkt_y)
        return (self._radial if radial else self._general)(s, mu_n, cx, cy, T)

    def _radial(self, s: FrictionInput, mu_n, cx, cy, T):
        """kTx == kTy: t = tau m, m = t_trial/|t_trial|, tau = p mu(kappa_n + (T - tau)/k)."""
        k, dk, p, kap = s.kt_x, s.dkt_x, s.pressure, s.slip_path
        its = 1
        if self.mu_initial_ratio == 1.0 or self.hardening == 0.0:
            mu, dmu = mu_n, 0.0
            tau = p * mu  # closed form
        else:
            # R(tau) = tau - p mu(kappa_n + (T - tau)/k) is convex and increasing: Newton from
            # the right end tau = T (R > 0 there) converges monotonically; one polishing step.
            tau = T
            for its in range(1, _MAX_ITER + 1):
                mu, dmu = self._mu(kap + (T - tau) / k)
                R = tau - p * mu
                tau_new = tau - R / (1.0 + p * dmu / k)
                if np.all(R <= _TOL_LOOSE * p * mu):
                    tau = tau_new
                    break
                tau = tau_new
            else:
                raise ReturnMappingError(
                    f"isotropic friction return map: local Newton did not converge at "
                    f"{int(np.count_nonzero(R > _TOL_LOOSE * p * mu))} of {tau.size} slipping "
                    "points")
            mu, dmu = self._mu(kap + (T - tau) / k)
        mx = cx / T
        my = cy / T
        dgam = (T - tau) / k
        # d tau = [mu dp + c dT - c dgam dk] / (1 + c),  c = p mu'/k,  dp/dg = -kN
        # d t_trial = k ds + dk e dg;  dT = m . d t_trial;  dm = (I - m m) d t_trial / T
        cc = p * dmu / k
        inv = 1.0 / (1.0 + cc)
        dT_g = dk * (mx * s.elastic_slip_x + my * s.elastic_slip_y)
        dtau_g = (cc * (dT_g - dgam * dk) - mu * s.kn) * inv
        ck = cc * k * inv
        r = tau / T
        rk = r * k
        px = dk * s.elastic_slip_x - mx * dT_g
        py = dk * s.elastic_slip_y - my * dT_g
        mxy = mx * my
        D = {(0, 0): dtau_g * mx + r * px, (1, 0): dtau_g * my + r * py,
             (0, 1): ck * mx * mx + rk * (1.0 - mx * mx), (0, 2): (ck - rk) * mxy,
             (1, 1): (ck - rk) * mxy, (1, 2): ck * my * my + rk * (1.0 - my * my)}
        return tau * mx, tau * my, dgam * mx, dgam * my, D, its

    def _general(self, s: FrictionInput, mu_n, cx, cy, T):
        """kTx != kTy: t_i = t_trial,i / (1 + lam kT_i), kappa = kappa_n + lam ||t||."""
        ax, ay, p, kap = s.kt_x, s.kt_y, s.pressure, s.slip_path
        lam0, lo, hi = _initial_bracket(T / mu_n, p, ax, ay, cx * cx, cy * cy,
                                        T / self.mu_macro)

        def state(lam):
            Dx = 1.0 + lam * ax
            Dy = 1.0 + lam * ay
            tx = cx / Dx
            ty = cy / Dy
            Tn = _norm(tx, ty)
            mu, dmu = self._mu(kap + lam * Tn)
            return Dx, Dy, tx, ty, Tn, mu, dmu

        def model(lam):
            Dx, Dy, tx, ty, Tn, mu, dmu = state(lam)
            dT = -(tx * tx * ax / Dx + ty * ty * ay / Dy) / Tn
            N = Tn / mu
            dN = dT / mu - Tn * dmu * (Tn + lam * dT) / (mu * mu)
            return p / N - 1.0, -p * dN / (N * N)

        lam, its = _solve_lambda(model, lam0, lo, hi, "isotropic friction return map")
        Dx, Dy, tx, ty, Tn, mu, dmu = state(lam)
        fac = 1.0 / Tn - lam * dmu / mu
        bx = tx / mu * fac
        by = ty / mu * fac
        c0 = -Tn * Tn * dmu / (mu * mu)
        D = _tangent(s, tx, ty, lam, 1.0, 1.0, Dx, Dy, bx, by, c0)
        return tx, ty, lam * tx, lam * ty, D, its


# ----------------------------------------------------------------------------- paper's formulas
def continuum_tangent(traction_t, pressure, kn, kt, mu, dmu, potential_axes=(1.0, 1.0)):
    """The paper's continuum elasto-plastic tangent (105)-(110), in this package's convention.

    The paper writes (107) for (t_x, t_y, t_N = p) against (u_x, u_y, u_N = approach) with
    constant stiffnesses; here it is returned as d(t_N = -p, t_x, t_y)/d(g, s_x, s_y), with
    g = -u_N. The hardening modulus uses |dg/dt_i| (hardening by slip magnitude).

    Args:
        traction_t: (m, 2) tangential traction on the slip surface [MPa].
        pressure: (m,) contact pressure [MPa] (unused by (107) except through f = 0).
        kn: (m,) normal stiffness [MPa/mm].
        kt: (m, 2) tangential stiffnesses [MPa/mm].
        mu: (m, 2) current (mu_x, mu_y) [-]; dmu: (m, 2) d mu_i / d kappa_i [1/mm].
        potential_axes: (nu_x, nu_y) [-].

    Returns:
        (m, 3, 3) tangent [MPa/mm].
    """
    t = np.asarray(traction_t, dtype=float)
    tx, ty = t[:, 0], t[:, 1]
    mux, muy = mu[:, 0], mu[:, 1]
    nux, nuy = potential_axes
    fmu = np.hypot(tx / mux, ty / muy)
    fnu = np.hypot(tx / nux, ty / nuy)
    cx = tx / (mux**2 * fmu)
    cy = ty / (muy**2 * fmu)
    cz = -1.0
    dx = tx / (nux**2 * fnu)
    dy = ty / (nuy**2 * fnu)
    dz = 0.0
    ktx, kty = kt[:, 0], kt[:, 1]
    A = ktx * cx * dx + kty * cy * dy + kn * cz * dz  # (108)
    H = -(tx**2 * dmu[:, 0] * np.abs(dx) / (mux**3 * fmu)
          + ty**2 * dmu[:, 1] * np.abs(dy) / (muy**3 * fmu))  # (110)
    s = 1.0 / (A - H)
    # (107), rows/cols ordered (x, y, N) in the paper's variables
    P = np.empty((t.shape[0], 3, 3))
    P[:, 0, 0] = ktx * (kn * cz * dz + kty * cy * dy - H)
    P[:, 0, 1] = -ktx * kty * cy * dx
    P[:, 0, 2] = -ktx * kn * cz * dx
    P[:, 1, 0] = -ktx * kty * cx * dy
    P[:, 1, 1] = kty * (ktx * cx * dx + kn * cz * dz - H)
    P[:, 1, 2] = -kty * kn * cz * dy
    P[:, 2, 0] = -ktx * kn * cx * dz
    P[:, 2, 1] = -kty * kn * cy * dz
    P[:, 2, 2] = kn * (ktx * cx * dx + kty * cy * dy - H)
    P *= s[:, None, None]
    D = np.empty_like(P)
    D[:, 0, 0] = P[:, 2, 2]
    D[:, 0, 1:] = -P[:, 2, :2]
    D[:, 1:, 0] = -P[:, :2, 2]
    D[:, 1:, 1:] = P[:, :2, :2]
    return D


def directional_coefficient(mu_x, mu_y, alpha):
    """Directional friction coefficient mu_alpha of (115) for slip inclination alpha [rad].

    (115) is the traction magnitude / p for slip at angle alpha under the ASSOCIATED rule
    (nu ~ mu); for a general potential use ``limit_coefficient(mu_x, mu_y, traction_angle(...))``.
    """
    c2 = np.cos(alpha) ** 2
    s2 = np.sin(alpha) ** 2
    return np.sqrt((mu_x**4 * c2 + mu_y**4 * s2) / (mu_x**2 * c2 + mu_y**2 * s2))


def traction_angle(alpha, nu_x, nu_y):
    """Traction inclination beta from slip inclination alpha, (118): tan b = tan a (nu_y/nu_x)^2.

    Quadrant-correct (atan2); angles in rad.
    """
    return np.arctan2(np.sin(alpha) * nu_y**2, np.cos(alpha) * nu_x**2)


def limit_coefficient(mu_x, mu_y, beta):
    """|t_T| / p on the slip ellipse (91) for a traction at inclination beta [rad]."""
    return 1.0 / np.hypot(np.cos(beta) / mu_x, np.sin(beta) / mu_y)
