"""Model only what the scene requires: the cheapest interface law within a tolerance.

Given a rough surface (spectral moments, or a height map), the asperity material (E*, nu,
hardness or yield strength), the range of nominal pressures a scene puts on the interface and a
tolerance, :func:`advise` evaluates every modelling choice of the package's rough law over that
range with cheap, pure-numpy estimates and returns the cheapest law that stays within the
tolerance of the full model, with the figures behind each choice (:class:`Advice`).

The choices (``docs/advisor.md`` gives the measured figures behind each):

* **plasticity** - elastic asperities (``NormalLaw.elastic``, eqs 52-55) or elasto-plastic ones
  (``NormalLaw.elasto_plastic``, eqs 78-88, about 10-30x the build time). The classical screen is
  the plasticity index psi (69) (Greenwood-Williamson: mostly elastic below 0.6, mostly plastic
  above 1); the decision is the actual difference of the two population sums at the scene's
  pressures.
* **anisotropy** - the strongly anisotropic model (Bush-Gibson-Keogh) or McCool's isotropic
  equivalent (``NormalLaw.greenwood_williamson``, closed form, ~100x cheaper to build). Below
  m04/m40 = 10 (``ANISOTROPY_WARN_RATIO``) the anisotropic model is outside its validity and is
  refused whatever it costs.
* **statistical vs BEM** - the statistical laws neglect the elastic interaction of the
  asperities. Measured against exact FFT boundary elements on narrow-band Gaussian surfaces
  (``docs/bem.md``), the stiffness at a given load and the pressure at a given separation are
  within 10 % up to A/A0 = 3 %, then drift (k -20 ... -25 % at A/A0 = 9 %, -50 % at 25 %). Above
  A/A0 = 10 % the statistical laws are refused and the BEM law is advised. With
  ``bem_check=True`` (and Tamaas) a small BEM computation on realisations of the surface
  overrides the measured figures where it is significant beyond its sampling error.
* **validity limit** - the statistical tables end where A/A0 reaches 0.3 (``area_limit``); a
  scene beyond it runs on the stiff continuation, not on the model.
* **friction** - slip hardening or plain Coulomb (mu = mu_m): assessed when the scene's slip
  amplitude is given (the mean coefficient over the slip path differs by
  (1 - mu_o)(1 - exp(-n s))/(n s)).
* **penalty** - a plain penalty in place of the rough law: only when the scene needs no real
  contact area and the interface compliance is below the tolerance of the total (needs the
  bulk stiffness).

What is compared, for a simpler law against the fuller one, over pressures p in the range:
the stiffness k and the real-area fraction A/A0 at equal pressure, the interface approach
h(p_min) - h(p) (what a seated interface closes between the lightest and the given load), and,
for information, the pressure at equal separation (seating removes a uniform shift of ln p, so
the FE results do not see it). Each is the largest relative difference over the range.
``results`` selects which of them the tolerance holds (force ~ k, area, approach) and may add the
frictional dissipation, estimated as ``DISSIPATION_AMPLIFICATION`` times the k difference (partial
slip amplifies it; measured on the punch, ``docs/advisor.md``).

The estimates: the population sums (``rough_contact.micro.population``) at a handful of
separations spanning the range, with coarse quadrature (elastic n_quad = 16; elasto-plastic
n_quad = 8, n_t = 8: ~0.2 % from the converged sums), interpolated by cubic Hermite curves of
ln p with the models' own stiffness as slope data. ``tests/unit/test_advisor.py`` checks the
estimated differences against those of the full tables.

Cost: the population calls take the cheaper options of :mod:`rough_contact.micro.population`
(a coarse p-window search, the numpy-only Hermite table of the shape factors, which spares the
first call of a process the import of scipy.interpolate and the spline build, and F_3/2, F_1/2
from one parabolic-cylinder call); ``docs/advisor.md`` ("Cost") has the measured figures.

Units: mm, N, MPa. Pure layer: numpy and scipy (no dolfinx).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import asdict, dataclass, field
from typing import Optional, Tuple

import numpy as np

from .micro import population
from .micro.asperity import AsperityMaterial
from .micro.tables import hermite_coeffs, hermite_eval, horner, horner_dt, limited_slopes
from .surface import ANISOTROPY_WARN_RATIO, SpectralMoments
from .validation import check_scalar

__all__ = ["Advice", "Choice", "Difference", "LawCost", "BEMCheck", "BEMCheckResult", "advise",
           "scene_pressure_range",
           "NORMAL_LAWS", "STATISTICAL_VALID_AREA", "STATISTICAL_REFUSE_AREA",
           "LAW_EVALUATION_RATE", "RESULTS_ALL", "RESULTS_DEFAULT",
           "DISSIPATION_AMPLIFICATION"]

# The normal laws the advisor chooses between, cheapest first.
NORMAL_LAWS = ("greenwood_williamson", "elastic", "elasto-plastic", "bem")

# Statistical vs exact BEM (docs/bem.md, narrow-band Gaussian surfaces alpha ~ 10, isotropic and
# m04/m40 = 100): k at equal load within 10 % up to A/A0 = 3 %; above it the asperity sum turns
# too soft. Pairs (A/A0, worst |k_stat/k_BEM - 1| of the two surfaces at equal load).
STATISTICAL_VALID_AREA = 0.03
STATISTICAL_REFUSE_AREA = 0.10
_BEM_DRIFT = ((0.033, 0.06), (0.092, 0.25), (0.25, 0.53), (0.39, 0.69))
# Bandwidth alpha above which the measured agreement need not hold: on a broadband self-affine
# surface (alpha = 43) the statistical laws were outside 10 % at every load (docs/bem.md).
_BROADBAND_ALPHA = 30.0
# Every tabulated NormalLaw (statistical or BEM) evaluates by the same O(1) look-up: measured
# 6-9 million points per second on the project's machine (docs/bem.md, "Evaluation").
LAW_EVALUATION_RATE = 7.0e6

# Quadrature of the estimates (elastic: n_quad = 16, ~1e-3 from the converged sums on the paper's
# surfaces; elasto-plastic and its elastic twin on the same nodes: n_quad = 8, n_t = 8).
_NQ_EL = 16
_NQ_EP, _NT_EP = 8, 8
# Build time of a default table (rtol 1e-4) per second the advisor spends per separation of the
# same model: calibrated on the paper's two surfaces (benchmarks/bench_advisor.py prints the
# estimate beside the measured build; within a factor 2).
_BUILD_PER_ESTIMATE = {"greenwood_williamson": 200.0, "elastic": 120.0, "elasto-plastic": 1000.0}
_N_PRESSURES = 7
# Bracket width of the p-window search in the advisor's population calls (the default search
# runs to the fixed point, ~140 calls of the window function; this one ~20). The window's edge
# lies where the integrand's bound is exp(-50) of its peak; p is a standard-normal variable, so
# an edge moved by 0.05 moves that level by at most ~0.5 in the exponent: the window's content
# is the same, its nodes move by < 0.05 (the estimates change by < 1e-4, measured)
_WINDOW_TOL = 0.05

# The FE results a scene may need within the tolerance (``advise(..., results=...)``):
# "force" - the normal force distribution (seen through k at equal pressure), "area" - the real
# contact area (A/A0 at equal pressure), "approach" - the interface approach, "dissipation" -
# the frictional dissipation.
RESULTS_ALL = ("force", "area", "approach", "dissipation")
RESULTS_DEFAULT = ("force", "area", "approach")
# Frictional dissipation in partial slip is a small difference of large terms (the slip beyond
# the stick limit, with kT = c kN), so a relative difference in kN shows amplified in it.
# Measured (benchmarks/bench_advisor.py, docs/advisor.md): on the coarse quarter punch, Table 1
# surface, psi = 0.35 with K_Y Y = (2/pi) H, McCool's GW against the anisotropic law differs by
# 1.25 % in k at equal pressure (the advisor's estimate over 0.156-5 MPa) and by 9.11 % in the
# punch's total dissipation: 7.3x; on the beam 1.21 % -> 0.31 % (0.26x). The worst measured
# figure, rounded up, is used.
DISSIPATION_AMPLIFICATION = 7.5
_N_EP = 4             # separations of the elasto-plastic estimate


# ----------------------------------------------------------------------------------------------
# typed results
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Difference:
    """Largest relative differences of a simpler law from the fuller one over the range.

    Attributes:
        pressure: |p_s(h)/p_f(h) - 1| at equal separation (information: seating removes it) [-].
        stiffness: |k_s(p)/k_f(p) - 1| at equal pressure [-].
        area: |a_s(p)/a_f(p) - 1| at equal pressure (A/A0) [-].
        approach: |dh_s(p)/dh_f(p) - 1|, dh(p) = h(p_min) - h(p) the interface approach from
            the lightest load [-].
        at_pressure: nominal pressure where the largest of stiffness, area, approach occurs [MPa].
    """

    pressure: float
    stiffness: float
    area: float
    approach: float
    at_pressure: float

    @property
    def largest(self) -> float:
        """The largest of the differences the FE results see (k, A/A0, approach) [-]."""
        return max(self.stiffness, self.area, self.approach)

    @property
    def dissipation(self) -> float:
        """Estimated relative difference of the frictional dissipation in partial slip:
        ``DISSIPATION_AMPLIFICATION`` times the stiffness difference (measured, see there) [-]."""
        return DISSIPATION_AMPLIFICATION * self.stiffness

    def largest_of(self, results) -> float:
        """The largest estimated difference over the given FE results (``RESULTS_ALL``) [-]."""
        by = {"force": self.stiffness, "area": self.area, "approach": self.approach,
              "dissipation": self.dissipation}
        return max(by[r] for r in results)

    def worst_of(self, results) -> Tuple[str, float]:
        """(result, estimated difference) of the worst of the given FE results."""
        by = {"force": self.stiffness, "area": self.area, "approach": self.approach,
              "dissipation": self.dissipation}
        r = max(results, key=lambda q: by[q])
        return r, by[r]


@dataclass(frozen=True)
class LawCost:
    """Cost of one normal law.

    Attributes:
        law: one of ``NORMAL_LAWS``.
        build_seconds: estimated wall time to build its default table (rtol 1e-4) [s]; None for
            the BEM law (minutes; depends on the grid and realisations).
        evaluations_per_second: points per second of the tabulated law at run time [1/s] (the
            same look-up for every table).
    """

    law: str
    build_seconds: Optional[float]
    evaluations_per_second: float = LAW_EVALUATION_RATE


@dataclass(frozen=True)
class Choice:
    """One modelling choice, assessed over the scene's pressure range.

    Attributes:
        name: "plasticity", "anisotropy", "statistical_vs_bem", "validity", "friction",
            "penalty".
        simple, full: the cheaper and the fuller option (e.g. "elastic", "elasto-plastic").
        picked: which of the two the advisor keeps (or "not assessed").
        difference: the estimated differences of simple vs full (None if not computed).
        reason: one sentence a reviewer can read.
    """

    name: str
    simple: str
    full: str
    picked: str
    difference: Optional[Difference]
    reason: str


@dataclass(frozen=True)
class Advice:
    """The advisor's answer (:func:`advise`).

    Attributes:
        normal: the normal law to build, one of ``NORMAL_LAWS``.
        full_normal: the fullest statistical law that applies to this surface (the reference
            the differences are measured against).
        friction: "slip-hardening" or "coulomb" (or "as given" when not assessed).
        interface: "rough" or "penalty".
        tolerance: the tolerance used [-].
        pressure_range: (p_min, p_max) [MPa].
        choices: the assessed choices, in the order above.
        costs: estimated cost of each candidate normal law.
        statistical_valid: whether the statistical model is inside its measured validity over
            the range.
        max_area_fraction: largest A/A0 of the chosen statistical law over the range [-].
        plasticity_index: psi (69) of the surface and material [-].
        advisor_seconds: wall time of :func:`advise` (without the optional BEM check) [s].
        results: the FE results held within the tolerance (of ``RESULTS_ALL``).
        surface: the surface's moments; material: the resolved asperity material.
        bem_check: what the optional small BEM check measured (:class:`BEMCheckResult`; None
            when it was not asked for or could not run).
    """

    normal: str
    full_normal: str
    friction: str
    interface: str
    tolerance: float
    pressure_range: Tuple[float, float]
    choices: Tuple[Choice, ...]
    costs: Tuple[LawCost, ...]
    statistical_valid: bool
    max_area_fraction: float
    plasticity_index: float
    advisor_seconds: float
    results: Tuple[str, ...]
    surface: SpectralMoments = field(repr=False)
    material: AsperityMaterial = field(repr=False)
    bem_check: Optional["BEMCheckResult"] = None

    def choice(self, name: str) -> Choice:
        """The assessed choice of that name (KeyError if not assessed)."""
        for c in self.choices:
            if c.name == name:
                return c
        raise KeyError(f"choice {name!r} was not assessed; assessed: "
                       f"{[c.name for c in self.choices]}")

    def cost(self, law: str) -> LawCost:
        for c in self.costs:
            if c.law == law:
                return c
        raise KeyError(f"no cost for law {law!r}")

    # -- building the advised law ---------------------------------------------------------
    def normal_law(self, law: Optional[str] = None, rtol: float = 1e-4, **kwargs):
        """Build the advised normal law (or ``law``, one of ``NORMAL_LAWS``) as a ``NormalLaw``.

        ``kwargs`` go to the constructor (``NormalLaw.elastic`` ... or, for "bem",
        ``rough_contact.micro.bem.bem_law_from_moments``).
        """
        from .interface.normal import NormalLaw

        law = self.normal if law is None else law
        with warnings.catch_warnings():
            # an anisotropy warning was already weighed by the advisor and is in the report
            warnings.filterwarnings("ignore", message=r"m04/m40 = ", category=UserWarning)
            if law == "greenwood_williamson":
                return NormalLaw.greenwood_williamson(self.surface, self.material.E_star, rtol,
                                                      **kwargs)
            if law == "elastic":
                return NormalLaw.elastic(self.surface, self.material.E_star, rtol, **kwargs)
            if law == "elasto-plastic":
                return NormalLaw.elasto_plastic(self.surface, self.material, rtol, **kwargs)
            if law == "bem":
                from .micro import bem

                kw = dict(E_star=self.material.E_star, nu=self.material.nu)
                kw.update(kwargs)
                return bem.bem_law_from_moments(self.surface, **kw).normal
        raise ValueError(f"law = {law!r} is invalid; valid laws: {NORMAL_LAWS}")

    # -- the report -----------------------------------------------------------------------
    def summary(self) -> str:
        """One line per verdict, as a reviewer reads it."""
        return "; ".join(_short(c) for c in self.choices if c.picked != "not assessed")

    def report(self) -> str:
        """The advice as text (printed at the start of a run, written beside the results)."""
        p0, p1 = self.pressure_range
        lines = [
            f"Law advice (tolerance {self.tolerance:.3g} on {_results_text(self.results)}, "
            f"nominal pressures {p0:.4g}-{p1:.4g} MPa):",
            f"  advised normal law: {self.normal} (full model: {self.full_normal}); "
            f"friction: {self.friction}; interface: {self.interface}",
            f"  {self.summary()}",
            f"  surface: sigma = {math.sqrt(self.surface.m00) * 1e3:.4g} um, m04/m40 = "
            f"{self.surface.m04 / self.surface.m40:.4g}, alpha = {self.surface.alpha1:.4g}; "
            f"E* = {self.material.E_star:.5g} MPa, H = {self.material.H:.5g} MPa, "
            f"psi = {self.plasticity_index:.3g}",
        ]
        for c in self.choices:
            d = c.difference
            figs = "" if d is None else (
                f" [k {d.stiffness:.2%}, A/A0 {d.area:.2%}, approach {d.approach:.2%}, "
                f"p(h) {d.pressure:.2%}"
                + (f", dissipation ~{d.dissipation:.2%} ({DISSIPATION_AMPLIFICATION:g} x k)"
                   if "dissipation" in self.results else "")
                + f"; worst at {d.at_pressure:.4g} MPa]")
            lines.append(f"  - {c.name}: {c.simple} vs {c.full} -> {c.picked}.{figs} {c.reason}")
        costs = ", ".join(
            f"{c.law} {'minutes' if c.build_seconds is None else f'~{c.build_seconds:.2g} s'}"
            for c in self.costs)
        lines.append(f"  table build (estimated): {costs}; every table evaluates "
                     f"~{LAW_EVALUATION_RATE / 1e6:.0f} M points/s")
        lines.append(f"  advisor wall time {self.advisor_seconds * 1e3:.0f} ms")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """Plain data (JSON-ready) of the advice."""
        d = {k: v for k, v in asdict(self).items()
             if k not in ("surface", "material", "bem_check")}
        if self.bem_check is not None:
            d["bem_check"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                              for k, v in asdict(self.bem_check).items()}
        d["surface_um"] = self.surface.as_um()
        d["material"] = {"E_star": self.material.E_star, "nu": self.material.nu,
                         "H": self.material.H, "Y": self.material.Y}
        d["report"] = self.report()
        return d

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, default=float)


def _results_text(results) -> str:
    names = {"force": "k (force distribution)", "area": "A/A0", "approach":
             "the interface approach", "dissipation": "the frictional dissipation"}
    items = [names[r] for r in results]
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _check_results(results) -> Tuple[str, ...]:
    if isinstance(results, str):
        results = (results,)
    try:
        out = tuple(results)
    except TypeError:
        out = None
    if not out or any(r not in RESULTS_ALL for r in out):
        raise ValueError(f"results = {results!r} is invalid: it must be a non-empty selection "
                         f"of {RESULTS_ALL}")
    return tuple(r for r in RESULTS_ALL if r in out)


def _short(c: Choice) -> str:
    d = c.difference
    if c.name == "plasticity":
        if c.picked == c.simple:
            return (f"elastic asperities suffice (e-p differs by <= {d.largest:.1%} up to "
                    f"{_p_max(c):.3g} MPa)")
        return f"plasticity matters (e-p differs by {d.largest:.1%})"
    if c.name == "anisotropy":
        if c.picked == c.simple and "outside its validity" in c.reason:
            return ("isotropic equivalent (anisotropic model outside its validity"
                    + ("" if d is None else f"; they differ by {d.largest:.1%}") + ")")
        if c.picked == c.simple:
            return f"isotropic equivalent suffices (differs by <= {d.largest:.1%})"
        if d is None:
            return "anisotropic model kept (no isotropic elasto-plastic law)"
        if " in dissipation " in c.reason:
            return (f"anisotropy matters for the dissipation (k differs {d.stiffness:.1%}, "
                    f"dissipation ~{d.dissipation:.0%})")
        q = max((("k", d.stiffness), ("A/A0", d.area), ("approach", d.approach)),
                key=lambda t: t[1])
        return f"anisotropy matters ({q[0]} differs {q[1]:.0%})"
    if c.name == "statistical_vs_bem":
        return c.reason.split(":")[0]
    if c.name == "friction":
        return f"friction: {c.picked}"
    if c.name == "penalty":
        return f"interface: {c.picked}"
    return c.reason.split(":")[0]


def _p_max(c: Choice) -> float:
    return float(c.reason.split("up to ")[1].split(" MPa")[0]) if "up to " in c.reason else 0.0


# ----------------------------------------------------------------------------------------------
# curves of one model on a few separations
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Curve:
    """p, k, A/A0 of one model at a few separations, with Hermite interpolation in h."""

    h: np.ndarray
    p: np.ndarray
    k: np.ndarray
    a: np.ndarray
    # at_pressure's results by pressures (the advisor asks a curve for the same pressures
    # several times)
    _memo: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def of(cls, r, h: np.ndarray) -> "_Curve":
        """The curve of a PopulationResult at separations h (points with p = 0 dropped)."""
        p, k, a = (np.asarray(v, float) for v in (r.pressure, r.stiffness, r.area_fraction))
        ok = (p > 0) & (k > 0) & (a > 0) & np.isfinite(p) & np.isfinite(k) & np.isfinite(a)
        return cls(h[ok], p[ok], k[ok], a[ok])

    def merged(self, other: "_Curve") -> "_Curve":
        h = np.concatenate([self.h, other.h])
        o = np.argsort(h)
        return _Curve(h[o], *(np.concatenate([getattr(self, n), getattr(other, n)])[o]
                              for n in ("p", "k", "a")))

    def covers(self, p_lo: float, p_hi: float) -> Tuple[bool, bool]:
        """(reaches p_hi at its smallest h, reaches down to p_lo at its largest h)."""
        return bool(self.p.size and self.p[0] >= p_hi), bool(self.p.size and self.p[-1] <= p_lo)

    def _segments(self, x):
        """Interval index and local coordinate t of separations x (clipped to the knots)."""
        x = np.clip(np.asarray(x, float), self.h[0], self.h[-1])
        dx = np.diff(self.h)
        i = np.clip(np.searchsorted(self.h, x, side="right") - 1, 0, dx.size - 1)
        return i, (x - self.h[i]) / dx[i], dx[i]

    def at_h(self, x):
        """ln p interpolated with slopes -k/p: (p, k) at separations x [mm]."""
        c = hermite_coeffs(np.log(self.p[:-1]), np.log(self.p[1:]), -self.k[:-1] / self.p[:-1],
                           -self.k[1:] / self.p[1:], np.diff(self.h))
        i, t, dx = self._segments(x)
        ci = c[:, i]
        p = np.exp(horner(ci, t))
        return p, -p * horner_dt(ci, t) / dx

    def separation(self, P):
        """h where the interpolated p equals P (bisection on the monotone Hermite curve)."""
        lnp = np.log(self.p)
        c = hermite_coeffs(lnp[:-1], lnp[1:], -self.k[:-1] / self.p[:-1],
                           -self.k[1:] / self.p[1:], np.diff(self.h))
        lnP = np.log(np.asarray(P, float))
        # the interval: ln p decreases along the knots
        i = np.clip(np.searchsorted(-lnp, -lnP, side="left") - 1, 0, self.h.size - 2)
        ci = c[:, i]
        # Newton from the secant's root, kept inside a bracket [lo, hi] that every step
        # narrows (a step leaving it is replaced by bisection): converged to 1e-13 of the
        # interval in ~4 steps where the bisection took 34 to reach 6e-11
        lo, hi = np.zeros_like(lnP), np.ones_like(lnP)
        t = np.clip((ci[0] - lnP) / (lnp[i] - lnp[i + 1]), 0.0, 1.0)
        for _ in range(60):
            f = horner(ci, t) - lnP
            above = f > 0.0                 # ln p decreases in t: the root lies beyond t
            lo = np.where(above, t, lo)
            hi = np.where(above, hi, t)
            with np.errstate(divide="ignore", invalid="ignore"):
                tn = t - f / horner_dt(ci, t)
            tn = np.where((tn > lo) & (tn < hi), tn, 0.5 * (lo + hi))
            done = np.max(np.abs(tn - t)) < 1e-13
            t = tn
            if done:
                break
        return self.h[i] + t * np.diff(self.h)[i]

    def at_pressure(self, P):
        """(h, k, a) at pressures P: k and ln a interpolated in h (limited three-point slopes
        for ln k and ln a: the stiffness data are exact at the knots)."""
        P = np.asarray(P, float)
        key = P.tobytes()
        if key not in self._memo:
            self._memo[key] = self._at_pressure(P)
        return tuple(v.copy() for v in self._memo[key])

    def _at_pressure(self, P):
        x = self.separation(P)
        lk, _ = hermite_eval(self.h, np.log(self.k), limited_slopes(self.h, np.log(self.k)), x)
        la, _ = hermite_eval(self.h, np.log(self.a), limited_slopes(self.h, np.log(self.a)), x)
        return x, np.exp(lk), np.exp(la)


def _difference(simple: _Curve, full: _Curve, P: np.ndarray) -> Difference:
    hs, ks, as_ = simple.at_pressure(P)
    hf, kf, af = full.at_pressure(P)
    dk = np.abs(ks / kf - 1.0)
    da = np.abs(as_ / af - 1.0)
    apps, appf = hs[0] - hs[1:], hf[0] - hf[1:]
    dapp = np.concatenate([[0.0], np.abs(apps / appf - 1.0)])
    # pressure at equal separation: at the full law's separations of the range
    ps, _ = simple.at_h(np.clip(hf, simple.h[0], simple.h[-1]))
    dp = np.abs(ps / P - 1.0)
    worst = np.maximum(np.maximum(dk, da), dapp)
    return Difference(float(dp.max()), float(dk.max()), float(da.max()), float(dapp.max()),
                      float(P[int(np.argmax(worst))]))


def _gw_separations(surface: SpectralMoments, E_star: float, P) -> np.ndarray:
    """h where McCool's GW law (closed form) carries P: a first guess of the range [mm]."""
    s = np.linspace(-4.0, 12.0, 81) * surface.rq
    p = population.greenwood_williamson(surface, E_star, s).pressure
    ok = p > 0
    return np.interp(-np.log(P), -np.log(p[ok]), s[ok])


def _curves_over(model, P: np.ndarray, h_guess: Tuple[float, float], rq: float,
                 n: int) -> Tuple[_Curve, ...]:
    """The model's results (a tuple of PopulationResults) on n separations covering the
    pressures P: one call, extended (one more call each time) if it falls short."""
    a, b = h_guess

    def run(h):
        return [_Curve.of(r, h) for r in model(h)]

    cs = run(np.linspace(a, b, n))
    for _ in range(6):
        cover = [c.covers(P[0], P[-1]) for c in cs]
        hi_ok = all(c[0] for c in cover)
        lo_ok = all(c[1] for c in cover)
        if hi_ok and lo_ok:
            return tuple(cs)
        ext = []
        if not hi_ok:
            a -= 0.75 * rq
            ext += [a, a + 0.375 * rq]
        if not lo_ok:
            b += 0.75 * rq
            ext += [b - 0.375 * rq, b]
        cs = [c.merged(e) for c, e in zip(cs, run(np.array(ext)))]
    raise ValueError(f"the population model does not span the pressures {P[0]:.4g}-{P[-1]:.4g} "
                     f"MPa between h = {a:.4g} and {b:.4g} mm")


# ----------------------------------------------------------------------------------------------
# the advisor
# ----------------------------------------------------------------------------------------------
def scene_pressure_range(force: float, area: float, seating_pressure: Optional[float] = None,
                         concentration: float = 2.0) -> Tuple[float, float]:
    """Nominal pressure range of a scene from its load: (p_min, p_max) [MPa].

    Args:
        force: largest normal force on the interface [N], > 0.
        area: nominal contact area [mm^2], > 0.
        seating_pressure: lightest pressure of the run (e.g. the seating pressure) [MPa];
            default F/A0/100.
        concentration: peak local pressure over the mean F/A0 (edges of a punch, the loaded
            span of a beam) [-], >= 1.
    """
    F = check_scalar("force", force, lo=0.0, unit="N")
    A = check_scalar("area", area, lo=0.0, unit="mm^2")
    c = check_scalar("concentration", concentration, lo=1.0, lo_open=False)
    p_mean = F / A
    p_lo = p_mean / 100.0 if seating_pressure is None else check_scalar(
        "seating_pressure", seating_pressure, lo=0.0, hi=c * p_mean, unit="MPa")
    return p_lo, c * p_mean


def _check_range(pressure_range) -> Tuple[float, float]:
    try:
        lo, hi = (float(v) for v in pressure_range)
    except (TypeError, ValueError):
        raise ValueError(f"pressure_range = {pressure_range!r} is invalid: it must be two "
                         "pressures (p_min, p_max) in MPa") from None
    lo = check_scalar("pressure_range[0] (p_min)", lo, lo=0.0, unit="MPa")
    hi = check_scalar("pressure_range[1] (p_max)", hi, lo=lo, unit="MPa")
    return lo, hi


def _drift(a: float) -> float:
    """Measured |k_stat/k_BEM - 1| at equal load at real-area fraction a (interpolated in ln a;
    below 3.3 % the 10 % band, within the sampling error of the measurement)."""
    aa = np.log([x for x, _ in _BEM_DRIFT])
    ee = np.array([e for _, e in _BEM_DRIFT])
    if a <= _BEM_DRIFT[0][0]:
        return 0.1
    return float(np.interp(math.log(a), aa, ee))


def advise(surface, material: AsperityMaterial, pressure_range, tolerance: float = 0.05, *,
           slip: Optional[float] = None, friction=None, need_real_area: bool = True,
           bulk_stiffness: Optional[float] = None, bem_check=False,
           dx: Optional[float] = None, dy: Optional[float] = None,
           unit: str = "um", results=RESULTS_DEFAULT) -> Advice:
    """The cheapest normal law that stays within ``tolerance`` of the full model, and why.

    Args:
        surface: :class:`~rough_contact.surface.SpectralMoments` (x = grain), or a height map
            (2-D array ``z[i, j]`` at ``x = i dx``; give ``dx``, ``dy`` and ``unit``; its moments
            are taken by central differences).
        material: :class:`~rough_contact.micro.asperity.AsperityMaterial` (E* of the two bodies,
            nu, hardness H or yield strength Y or plasticity index psi).
        pressure_range: (p_min, p_max), nominal pressures of the scene [MPa]
            (:func:`scene_pressure_range` estimates it from a load and an area).
        tolerance: largest accepted relative difference of the advised law from the full model
            in each of ``results``, in (0, 1) [-].
        slip: slip amplitude of the scene [mm] (for the friction choice; None: not assessed).
        friction: the scene's friction law (``OrthotropicSlipHardening`` or
            ``IsotropicSlipHardening``) for the friction choice.
        need_real_area: the scene reports the real contact area (a penalty cannot).
        bulk_stiffness: stiffness of the bodies per unit area near the interface, about E*/L
            for a contact of size L [MPa/mm] (for the penalty choice; None: not assessed).
        bem_check: False, True or a :class:`BEMCheck` (its options): check the statistical
            law against exact BEM on Gaussian realisations of this surface's fitted spectrum
            (default 8 realisations of one roll-off period, 4 px per shortest wavelength;
            seconds on narrow-band surfaces, a minute on broadband ones; needs Tamaas, the
            extra ``rough_contact[bem]``, else skipped with a note). Judged: k at equal load
            (and the approach when among ``results``) against max(tolerance, 10 %) with the
            sampling error of the realisations' mean: significantly outside -> the BEM law is
            advised; significantly inside -> the statistical law is kept whatever the
            measured figures say; within the sampling error -> the measured verdict stands.
        results: the FE results that must stay within ``tolerance``, a selection of
            ``RESULTS_ALL``: "force" (k at equal pressure), "area" (A/A0 at equal pressure),
            "approach" (h(p_min) - h(p)), "dissipation" (frictional dissipation, estimated as
            ``DISSIPATION_AMPLIFICATION`` times the k difference: partial slip amplifies it).
            Default ``RESULTS_DEFAULT`` (all but the dissipation); the punch and beam demos
            pass all four, as they report the dissipation.

    Returns:
        :class:`Advice`.

    Raises:
        ValueError: a bad input, naming it, its value and the valid range.
    """
    t0 = time.perf_counter()
    tol = check_scalar("tolerance", tolerance, lo=0.0, hi=1.0)
    results = _check_results(results)
    if not isinstance(surface, SpectralMoments):
        from .surface import moments_from_height_map

        if dx is None:
            raise ValueError("surface is a height map but dx = None: give the sampling step dx")
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r"m04/m40 = ", category=UserWarning)
            surface = moments_from_height_map(surface, dx, dy, method="fd", unit=unit)
    if not isinstance(material, AsperityMaterial):
        raise ValueError(f"material = {material!r} is invalid: it must be an AsperityMaterial")
    mat = material.resolve(surface)
    p_lo, p_hi = _check_range(pressure_range)
    if slip is not None:
        slip = check_scalar("slip", slip, lo=0.0, unit="mm")
    if bulk_stiffness is not None:
        bulk_stiffness = check_scalar("bulk_stiffness", bulk_stiffness, lo=0.0, unit="MPa/mm")
    E = mat.E_star
    rq = surface.rq
    P = np.geomspace(p_lo, p_hi, _N_PRESSURES)
    psi = surface.plasticity_index(E, mat.H)
    ratio = surface.m04 / surface.m40
    anisotropic_valid = ratio >= ANISOTROPY_WARN_RATIO

    # -- the curves: GW in closed form, the population sums on a few separations --------------
    timing = {}
    hg = _gw_separations(surface, E, np.array([4.0 * p_hi, p_lo / 4.0]))
    t = time.perf_counter()
    gw, = _curves_over(lambda h: [population.greenwood_williamson(surface, E, h)], P,
                       (hg[0], hg[1]), rq, 9)
    timing["greenwood_williamson"] = (time.perf_counter() - t) / max(gw.h.size, 1)
    t = time.perf_counter()
    el, = _curves_over(lambda h: [population.elastic(surface, E, h, n_quad=_NQ_EL,
                                                     window_tol=_WINDOW_TOL,
                                                     shape_table="hermite",
                                                     inner="recurrence")], P,
                       (hg[0] - 0.5 * rq, hg[1] + 0.5 * rq), rq, 8)
    timing["elastic"] = (time.perf_counter() - t) / el.h.size
    he = el.separation(np.array([p_hi, p_lo]))
    t = time.perf_counter()
    # elasto-plastic and elastic sums on the same (coarse) nodes: their quadrature errors
    # cancel in the ratio
    ep, el_same = _curves_over(
        lambda h: population.elasto_plastic_and_elastic(surface, mat, h, n_quad=_NQ_EP,
                                                        n_t=_NT_EP, window_tol=_WINDOW_TOL,
                                                        shape_table="hermite"),
        P, (he[0] - 0.5 * rq, he[1] + 0.25 * rq), rq, _N_EP)
    timing["elasto-plastic"] = (time.perf_counter() - t) / ep.h.size

    choices = []
    # -- plasticity ---------------------------------------------------------------------------
    d_pl = _difference(el_same, ep, P)
    psi_text = ("mostly elastic by the classical screen psi < 0.6" if psi < 0.6 else
                "mostly plastic by the classical screen psi > 1" if psi > 1.0 else
                "in the transition 0.6 < psi < 1 of the classical screen")
    q_pl, e_pl = d_pl.worst_of(results)
    elastic_ok = e_pl <= tol
    choices.append(Choice(
        "plasticity", "elastic", "elasto-plastic", "elastic" if elastic_ok else "elasto-plastic",
        d_pl, f"psi = {psi:.3g} ({psi_text}); at the scene's pressures the elasto-plastic law "
              f"differs from the elastic one by {e_pl:.2%} in {q_pl} "
              f"({'<=' if elastic_ok else '>'} tolerance {tol:.3g}) up to {p_hi:.4g} MPa"))
    full_normal = "elasto-plastic"

    # -- anisotropy ---------------------------------------------------------------------------
    if not anisotropic_valid:
        full_normal = "greenwood_williamson"
        d_an = _difference(gw, el, P)
        normal = "greenwood_williamson"
        why = (f"m04/m40 = {ratio:.3g} < {ANISOTROPY_WARN_RATIO:g}: the strongly anisotropic "
               "model is outside its validity, refused whatever it costs; McCool's isotropic "
               "equivalent is the law for this surface")
        if not elastic_ok:
            why += (f" (its asperities are elastic: plasticity, {d_pl.largest:.1%} here, is not "
                    "in the isotropic law; the saturated BEM law models it)")
        choices.append(Choice("anisotropy", "greenwood_williamson", "elastic", normal, d_an, why))
    elif elastic_ok:
        d_an = _difference(gw, el, P)
        q_an, e_an = d_an.worst_of(results)
        iso_ok = e_an <= tol
        normal = "greenwood_williamson" if iso_ok else "elastic"
        extra = ""
        if q_an == "dissipation":
            extra = (f": k differs {d_an.stiffness:.2%}, which partial slip amplifies about "
                     f"{DISSIPATION_AMPLIFICATION:g} times in the frictional dissipation "
                     "(measured on the punch)")
        choices.append(Choice(
            "anisotropy", "greenwood_williamson", "elastic", normal, d_an,
            f"m04/m40 = {ratio:.4g}: McCool's isotropic equivalent differs from the anisotropic "
            f"elastic law by {e_an:.2%} in {q_an} ({'<=' if iso_ok else '>'} tolerance "
            f"{tol:.3g}){extra}"))
    else:
        normal = "elasto-plastic"
        choices.append(Choice(
            "anisotropy", "greenwood_williamson", "elasto-plastic", "elasto-plastic", None,
            f"m04/m40 = {ratio:.4g}; plasticity matters and the package's elasto-plastic law "
            "is the anisotropic one (McCool's equivalent is elastic only)"))

    # -- statistical vs BEM, validity limit ----------------------------------------------------
    curve = {"greenwood_williamson": gw, "elastic": el, "elasto-plastic": ep}[normal]
    _, _, a_chosen = curve.at_pressure(P)
    a_full = ep.at_pressure(P)[2] if anisotropic_valid else a_chosen
    a_max = float(max(a_chosen.max(), a_full.max()))
    drift = _drift(a_max)
    broadband = surface.alpha1 > _BROADBAND_ALPHA or surface.alpha2 > _BROADBAND_ALPHA
    note = (f" The bandwidth alpha = {max(surface.alpha1, surface.alpha2):.3g} > "
            f"{_BROADBAND_ALPHA:g}: on a broadband self-affine surface (alpha = 43) the "
            "statistical laws were outside 10 % of BEM at every load; if this surface is "
            "self-affine, check with bem_check=True or demos/compare_laws.py."
            if broadband else "")
    if a_max <= STATISTICAL_VALID_AREA:
        statistical_valid = True
        why = (f"statistical law valid (A/A0 <= {a_max:.2%}): inside the measured range "
               f"A/A0 <= {STATISTICAL_VALID_AREA:.0%} where its k at a given load and p at a "
               "given separation are within 10 % of exact BEM")
    elif a_max <= STATISTICAL_REFUSE_AREA:
        statistical_valid = drift <= max(tol, 0.1)
        why = (f"statistical law {'valid' if statistical_valid else 'drifting'} "
               f"(A/A0 up to {a_max:.2%}): beyond {STATISTICAL_VALID_AREA:.0%} the asperity sum "
               f"turns too soft, k at equal load about {drift:.0%} below exact BEM at this area "
               "(measured)")
    else:
        statistical_valid = False
        why = (f"statistical law refused (A/A0 up to {a_max:.1%} > "
               f"{STATISTICAL_REFUSE_AREA:.0%}): measured against exact BEM its k at equal load "
               f"is about {drift:.0%} low there (the asperities interact through the half-space); "
               "the BEM law (rough_contact.micro.bem) is advised")
    check = None
    bem_seconds = 0.0
    if bem_check:
        t = time.perf_counter()
        options = bem_check if isinstance(bem_check, BEMCheck) else BEMCheck()
        # the check judges the statistical model's neglect of the asperities' interaction:
        # the elastic statistical law (GW on an isotropic surface) against elastic BEM
        check, skipped = _bem_check(surface, mat, gw if normal == "greenwood_williamson" else el,
                                    P, max(tol, 0.1), results, options)
        bem_seconds = time.perf_counter() - t
        if check is None:
            why += f". {skipped}"
        elif check.verdict == "refused":
            statistical_valid = False
            why = f"statistical law refused: {check.text()}; the BEM law is advised"
        elif check.verdict == "confirmed":
            statistical_valid = True
            why = f"statistical law valid: {check.text()} (A/A0 <= {a_max:.2%})"
        else:
            why += f". {check.text()}: the measured verdict stands"
    choices.append(Choice("statistical_vs_bem", normal, "bem",
                          normal if statistical_valid else "bem", None, why + note))
    if not statistical_valid:
        normal = "bem"
    # model-validity limit of the tables (area_limit 0.3)
    if a_max >= 0.3:
        choices.append(Choice(
            "validity", "table", "continuation", "continuation", None,
            f"beyond the tables' validity: A/A0 reaches {a_max:.2g} >= 0.3 (area_limit), points "
            "would run on the stiff continuation below h_min, not on the model"))
    else:
        h_top = curve.separation(np.array([p_hi]))[0]
        choices.append(Choice(
            "validity", "table", "continuation", "table", None,
            f"inside the tables' validity: A/A0 <= {a_max:.2g} < 0.3 (area_limit), separation "
            f">= {h_top / rq:.3g} sigma at {p_hi:.4g} MPa"))

    # -- friction: slip hardening or plain Coulomb ---------------------------------------------
    fric = "as given"
    if friction is not None and slip is not None:
        mu_o = np.asarray(friction.mu_initial_ratio, float)
        n = np.asarray(friction.hardening, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = n * slip
            mean_gap = np.where(x > 0, (1.0 - mu_o) * -np.expm1(-x) / np.where(x > 0, x, 1.0),
                                1.0 - mu_o)
        d = float(np.max(mean_gap))
        fric = "coulomb" if d <= tol else "slip-hardening"
        choices.append(Choice(
            "friction", "coulomb", "slip-hardening", fric, None,
            f"over a slip of {slip * 1e3:.3g} um the mean friction coefficient of the "
            f"slip-hardening law is {d:.1%} below mu_m (1/n = {1e3 / max(n.max(), 1e-300):.3g} "
            f"um); plain Coulomb with mu = mu_m {'suffices' if d <= tol else 'would not'}"))
    else:
        choices.append(Choice("friction", "coulomb", "slip-hardening", "not assessed", None,
                              "slip amplitude or friction law not given: the friction law is "
                              "kept as given"))

    # -- penalty ------------------------------------------------------------------------------
    interface = "rough"
    if need_real_area:
        choices.append(Choice("penalty", "penalty", "rough", "rough", None,
                              "the scene reports the real contact area: a penalty has none"))
    elif bulk_stiffness is None:
        choices.append(Choice("penalty", "penalty", "rough", "not assessed", None,
                              "bulk stiffness not given: the rough law is kept"))
    else:
        _, k_lo, _ = curve.at_pressure(np.array([p_lo]))
        share = float(bulk_stiffness / (bulk_stiffness + k_lo[0]))
        interface = "penalty" if share <= tol else "rough"
        choices.append(Choice(
            "penalty", "penalty", "rough", interface, None,
            f"the interface carries {share:.1%} of the compliance at {p_lo:.4g} MPa "
            f"(k = {k_lo[0]:.4g} MPa/mm against the bulk's {bulk_stiffness:.4g} MPa/mm)"))

    # -- costs ----------------------------------------------------------------------------------
    costs = tuple(LawCost(k, timing[k] * f) for k, f in _BUILD_PER_ESTIMATE.items()) + \
        (LawCost("bem", None),)
    return Advice(normal=normal, full_normal=full_normal, friction=fric, interface=interface,
                  tolerance=tol, pressure_range=(p_lo, p_hi), choices=tuple(choices),
                  costs=costs, statistical_valid=statistical_valid, max_area_fraction=a_max,
                  plasticity_index=psi,
                  advisor_seconds=time.perf_counter() - t0 - bem_seconds,
                  results=results, surface=surface, material=mat, bem_check=check)


@dataclass(frozen=True)
class BEMCheck:
    """The optional small BEM check of the statistical law (``advise(..., bem_check=True)``).

    Gaussian realisations of the surface's fitted spectrum
    (:func:`rough_contact.surface.spectrum.fit_spectrum`, the assumed shape H = 0.8, plateau 2),
    each solved by exact elastic boundary elements (Tamaas) at the scene's pressures. The
    statistical law's k at equal load and its interface approach are compared with the mean of
    the realisations, with the standard error of that mean from their scatter: one roll-off
    period holds ~10 modes, so a single realisation scatters by ~20 % in k at equal load at
    A/A0 = 1-3 % (docs/bem.md, "Realisation scatter"), and one realisation alone decides
    nothing at the 10 % level.

    Attributes:
        n_realisations: realisations (fixed amplitudes, random phases, seeds 0, 1, ...), >= 2.
        pixels_per_wavelength: pixels per shortest wavelength (4: k within ~3-7 % of the
            converged grid on the narrow-band example surfaces, docs/bem.md), >= 2.
        min_area_fraction: the check runs from the load where the statistical A/A0 reaches this
            (a grid of one roll-off period resolves A/A0 down to ~0.5 %) [-].
        significance: a difference counts when it exceeds the limit by this many standard
            errors (refusal) or stays below it by as many (confirmation) [-].
        n_pressures: pressures solved between the lightest checked load and p_max, >= 3.
        cache: use the BEM disk cache (``rough_contact.micro.bem.default_cache_dir``).
    """

    n_realisations: int = 8
    pixels_per_wavelength: float = 4.0
    min_area_fraction: float = 0.005
    significance: float = 2.0
    n_pressures: int = 5
    cache: bool = True

    def __post_init__(self):
        check_scalar("BEMCheck.n_realisations", self.n_realisations, lo=2.0, lo_open=False,
                     hi=1e4)
        check_scalar("BEMCheck.pixels_per_wavelength", self.pixels_per_wavelength, lo=2.0,
                     lo_open=False, hi=64.0)
        check_scalar("BEMCheck.min_area_fraction", self.min_area_fraction, lo=0.0, hi=0.3)
        check_scalar("BEMCheck.significance", self.significance, lo=0.0, lo_open=False, hi=10.0)
        check_scalar("BEMCheck.n_pressures", self.n_pressures, lo=3.0, lo_open=False, hi=100.0)


@dataclass(frozen=True)
class BEMCheckResult:
    """What the small BEM check measured (statistical law / mean of the BEM realisations).

    Attributes:
        pressures: the loads checked [MPa].
        stiffness_ratio, stiffness_se: k_stat/k_BEM at equal load and the relative standard
            error of the BEM mean [-].
        approach_ratio, approach_se: the interface approach h(p_0) - h(p) from the lightest
            checked load, statistical / BEM, and its relative standard error (first entry
            NaN: no approach at p_0) [-].
        pressure_ratio: p_stat/p_BEM at the BEM's separation (information: seating removes a
            uniform shift) [-].
        area_ratio: A/A0 at equal load (information: pixel-counted on a coarse grid, which
            overestimates the BEM area; docs/bem.md) [-].
        verdict: "refused" (significantly outside the limit), "confirmed" (significantly
            inside) or "inconclusive" (within the sampling error of the limit).
        limit: the limit the judged differences are held to [-].
        judged: the differences judged ("k at equal load", "approach").
        n_realisations, grid: realisations and pixels of each; backend: the BEM solver.
        seconds: wall time of the check [s].
    """

    pressures: np.ndarray
    stiffness_ratio: np.ndarray
    stiffness_se: np.ndarray
    approach_ratio: np.ndarray
    approach_se: np.ndarray
    pressure_ratio: np.ndarray
    area_ratio: np.ndarray
    verdict: str
    limit: float
    judged: Tuple[str, ...]
    n_realisations: int
    grid: Tuple[int, int]
    backend: str
    seconds: float

    def text(self) -> str:
        """One sentence: the verdict and the figures behind it."""
        dk = np.abs(self.stiffness_ratio - 1.0)
        j = int(np.argmax(dk))
        parts = [f"k at equal load {self.stiffness_ratio[j]:.3g} of BEM "
                 f"(+-{self.stiffness_se[j]:.1%} s.e.) at {self.pressures[j]:.4g} MPa"]
        if "approach" in self.judged and self.approach_ratio.size > 1:
            da = np.abs(self.approach_ratio[1:] - 1.0)
            i = int(np.argmax(da)) + 1
            parts.append(f"approach {self.approach_ratio[i]:.3g} (+-{self.approach_se[i]:.1%})")
        return (f"a small BEM check ({self.n_realisations} realisations of "
                f"{self.grid[0]}x{self.grid[1]} px, {self.pressures[0]:.4g}-"
                f"{self.pressures[-1]:.4g} MPa, {self.seconds:.1f} s) gives "
                + ", ".join(parts) + f" (p(h) {np.min(self.pressure_ratio):.3g}-"
                f"{np.max(self.pressure_ratio):.3g}, A/A0 {np.min(self.area_ratio):.3g}-"
                f"{np.max(self.area_ratio):.3g}, information): {self.verdict} against the "
                f"limit {self.limit:.0%}")


def _bem_check(surface, material, curve: "_Curve", P, limit: float, results,
               options: BEMCheck) -> Tuple[Optional[BEMCheckResult], str]:
    """The small BEM check of the statistical ``curve`` over the loads P: (result, note);
    result None (with the reason in note) when it cannot run."""
    from .micro import bem
    from .surface.spectrum import SpectrumShape, fit_spectrum

    if "tamaas" not in bem.available_backends():
        return None, ("BEM check skipped: its solver Tamaas (the extra rough_contact[bem]) is not "
                      "installed; the measured figures decide")
    t0 = time.perf_counter()
    # the loads a coarse grid of one roll-off period resolves (statistical A/A0 >= min area)
    _, _, a = curve.at_pressure(P)
    ok = a >= options.min_area_fraction
    if not ok.any():
        return None, (f"BEM check skipped: the scene's loads stay below A/A0 = "
                      f"{options.min_area_fraction:.1%}, which a small BEM grid does not resolve; "
                      "the measured figures decide")
    i = int(np.argmax(ok))
    if i == 0:
        p0 = float(P[0])
    else:   # where A/A0 reaches the limit, interpolated in ln a, ln p
        p0 = float(np.exp(np.interp(math.log(options.min_area_fraction),
                                    np.log(a[i - 1:i + 1]), np.log(P[i - 1:i + 1]))))
    p1 = float(P[-1])
    if p1 <= p0 * 1.01:
        p0 = p1 / 1.5
    Pc = np.geomspace(p0, p1, int(options.n_pressures))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        spec = fit_spectrum(surface, SpectrumShape())
        (nx, ny), (Lx, Ly) = spec.grid(options.pixels_per_wavelength, 1)
        d, k, ar = [], [], []
        backend = ""
        for r in range(int(options.n_realisations)):
            z = spec.realisation((nx, ny), (Lx, Ly), r, "fixed")
            c = bem.bem_curves(z, Lx / nx, Ly / ny, E_star=material.E_star, nu=material.nu,
                               pressures=Pc, backend="tamaas", tangential=False,
                               cache=options.cache)
            d.append(c.separation[0])
            k.append(c.stiffness[0])
            ar.append(c.area_fraction[0])
            backend = c.backend
    d, k, ar = np.array(d), np.array(k), np.array(ar)
    n = d.shape[0]
    hs, ks, as_ = curve.at_pressure(Pc)
    kb = k.mean(axis=0)
    k_ratio = ks / kb
    k_se = k.std(axis=0, ddof=1) / math.sqrt(n) / kb
    app_b = d[:, :1] - d                       # each realisation's approach from Pc[0]
    ab = app_b.mean(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        app_ratio = (hs[0] - hs) / ab
        app_se = app_b.std(axis=0, ddof=1) / math.sqrt(n) / ab
    app_ratio[0], app_se[0] = np.nan, np.nan
    ps, _ = curve.at_h(np.clip(d.mean(axis=0), curve.h[0], curve.h[-1]))
    p_ratio = ps / Pc
    a_ratio = as_ / ar.mean(axis=0)
    judged = ("k at equal load",) + (("approach",) if "approach" in results else ())
    dev = [np.abs(k_ratio - 1.0)]
    se = [np.abs(k_ratio) * k_se]
    if "approach" in results:
        dev.append(np.abs(app_ratio[1:] - 1.0))
        se.append(np.abs(app_ratio[1:]) * app_se[1:])
    z_ = options.significance
    if any(np.any(x - z_ * e > limit) for x, e in zip(dev, se)):
        verdict = "refused"
    elif all(np.all(x + z_ * e <= limit) for x, e in zip(dev, se)):
        verdict = "confirmed"
    else:
        verdict = "inconclusive"
    return BEMCheckResult(pressures=Pc, stiffness_ratio=k_ratio, stiffness_se=k_se,
                          approach_ratio=app_ratio, approach_se=app_se, pressure_ratio=p_ratio,
                          area_ratio=a_ratio, verdict=verdict, limit=limit, judged=judged,
                          n_realisations=n, grid=(nx, ny), backend=backend,
                          seconds=time.perf_counter() - t0), ""
