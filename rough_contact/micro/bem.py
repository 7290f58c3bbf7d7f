"""Normal (and tangential) interface law of a rough surface computed by boundary elements.

The statistical laws (:mod:`rough_contact.micro.population`) sum independent asperities; this module
solves the *exact* frictionless contact of the measured or synthetic height map against a rigid
flat on a periodic elastic half-space (FFT boundary elements) at a sequence of mean pressures, and
tabulates the result as a :class:`~rough_contact.interface.normal.NormalLaw` (built by
``NormalLaw.from_table``: same contract, same evaluation, same continuation rules), so the FE
layer uses it unchanged. See ``docs/bem.md`` for the derivations and the verification.

Quantities (all per unit nominal area; internal units mm, N, MPa):

* separation ``h = d`` [mm]: the distance from the rigid flat to the mean plane of the
  *undeformed* height map, the same meaning as the statistical laws' h. In the periodic
  half-space the uniform (q = 0) part of the elastic displacement is undetermined; it is set to
  zero (the FE bodies carry the macroscopic deformation), so in elastic contact d equals the mean
  gap between the flat and the deformed surface. With the gap g(x) = d + u(x) - z(x),
  d = mean over the elastic contact points of z - u.
* pressure ``p`` [MPa]: mean contact pressure (the load per nominal area).
* area fraction ``a = A/A0`` [-]: fraction of pixels carrying pressure (pixel counting, biased
  high at first order in the pixel size); with ``area_extrapolation`` also the Richardson
  estimate 2 A(grid) - A(grid/2) from the map sub-sampled by 2, which the table then uses.
* normal stiffness ``k = -dp/dh`` [MPa/mm]: computed from each solution by Barber's relation:
  with the contact set C (elastic contact points) frozen, an approach dh moves every point of C
  by dh, so k = mean(dp) where dp, supported on C, solves (K dp)|_C = 1 (K the half-space
  operator). For elastic contact this is the exact derivative of p(h) (changes of C are of higher
  order because the pressure vanishes continuously at its edge); it is checked against finite
  differences of p(h) in the tests. The table's k is the derivative of its interpolant; the build
  reports the largest difference to the BEM k (``info["table_k_error"]``).
* tangential stiffnesses ``kT_x, kT_y`` [MPa/mm]: the same incremental problem for a uniform
  tangential displacement with every contact point in stick (Mindlin's assumption, no slip
  annulus), with the periodic Cerruti kernel. Valid for two bodies of the same Poisson ratio and
  modulus (Dundurs' beta = 0: no normal-tangential coupling) or a rigid counter-body; the ratio
  kT/kN is compared with Mindlin's 2(1 - nu)/(2 - nu) for a circular contact.

Elastic and saturated variants: ``hardness=None`` solves the elastic problem (0 <= p); a hardness
H caps the pressure, 0 <= p <= H (perfectly plastic, "saturated" contact: points at H may
interpenetrate the flat, which models material flattened away; volume is not conserved). In the
saturated case d = mean over the elastic (0 < p < H) contact points of z - u, and k is the
derivative with the saturated and open sets frozen.

Backends (``backend=``): ``"tamaas"`` uses Tamaas' Polonsky-Keer-Rey solver (the optional extra
``rough_contact[bem]``); ``"numpy"`` is this module's own Polonsky-Keer constrained conjugate
gradient, with an active-set loop for the pressure cap, the reference implementation and the
fallback where Tamaas is absent (pass it explicitly: a missing Tamaas raises
:class:`BackendUnavailableError`, never a silent switch). Default (``None``): "tamaas" for elastic
contact, "numpy" for the saturated variant - Tamaas' KatoSaturated stalled above its tolerance
in our checks (and its tolerance is absolute: mm-sized inputs stop it at once), so it is not used.
Both use the same half-space operator (Tamaas' basic_2d displacement equals
``2 p(q)/(E* |q|)`` to round-off, checked in the tests) and agree to 1e-7 and better; the
post-processing (d, A/A0, k, kT) is this module's for both. The backend that ran is recorded in
every result (``BEMCurves.backend``, ``info["backend"]``).

Pure module: numpy and scipy (tamaas imported lazily); no dolfinx, petsc4py, mpi4py.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Dict, Optional, Protocol, Sequence, Tuple

import numpy as np
from scipy.fft import irfft2 as _irfft2, rfft2 as _rfft2

from ..surface import SpectralMoments
from ..validation import check_scalar
from .tables import hermite_eval

if TYPE_CHECKING:          # annotations only: the law class lives in the layer above
    from ..interface.normal import NormalLaw

__all__ = [
    "BEMCurves", "BEMLaw", "BackendUnavailableError", "HeightMapWarning",
    "available_backends", "bem_curves", "bem_normal_law", "bem_law_from_moments",
    "bem_law_from_spectrum",
    "check_height_map", "spacing_from_coordinates", "mindlin_ratio", "law_ratios",
    "agreement_range", "default_cache_dir", "default_pressures", "law_from_curves",
    "HalfSpace", "NumpySolver", "TamaasSolver", "MapDiagnostics", "resolution_check",
    "MIN_PIXELS_PER_CORRELATION", "WARN_PIXELS_PER_CORRELATION", "WARN_RMS_SLOPE",
    "MAX_RMS_SLOPE",
]

# ----------------------------------------------------------------------------------------------
# limits of the input checks (documented in docs/bem.md)
# ----------------------------------------------------------------------------------------------
#: below this many pixels per correlation length the map resolves no asperity: ValueError
MIN_PIXELS_PER_CORRELATION = 2.0
#: below this many a warning (the grid-convergence study in docs/bem.md)
WARN_PIXELS_PER_CORRELATION = 8.0
#: rms slope above which the small-slope (linear half-space) assumption is strained: warning
WARN_RMS_SLOPE = 0.1
#: rms slope above which the half-space BEM is meaningless here: ValueError
MAX_RMS_SLOPE = 0.5

_CACHE_VERSION = 1
_BACKENDS = ("tamaas", "numpy")


class BackendUnavailableError(ImportError):
    """The requested BEM backend cannot be imported (e.g. Tamaas not installed)."""


class HeightMapWarning(UserWarning):
    """A height map that the BEM can solve but whose result should be doubted."""


def available_backends() -> Tuple[str, ...]:
    """Names of the backends that can run here ("numpy" always; "tamaas" when installed)."""
    out = []
    try:
        _import_tamaas()
        out.append("tamaas")
    except BackendUnavailableError:
        pass
    out.append("numpy")
    return tuple(out)


def _import_tamaas():
    try:
        import tamaas  # noqa: F401  (optional extra rough_contact[bem])
    except ImportError as e:
        raise BackendUnavailableError(
            "the BEM backend 'tamaas' is not installed (it is the optional extra "
            "rough_contact[bem]: `RC_EXTRAS=bem bash run.sh setup`, or `pip install -c "
            ".venv/constraints.txt tamaas==2.8.1`); pass backend='numpy' for this package's "
            f"own, slower reference solver ({e})") from None
    return tamaas


# ----------------------------------------------------------------------------------------------
# input checks
# ----------------------------------------------------------------------------------------------
def spacing_from_coordinates(x, y, rtol: float = 1e-3) -> Tuple[float, float]:
    """Sampling steps (dx, dy) [mm] of a height map from its coordinate vectors.

    Args:
        x: (nx,) coordinates along axis 0 [mm], strictly monotone and uniformly spaced.
        y: (ny,) coordinates along axis 1 [mm], likewise.
        rtol: largest accepted deviation of a step from the mean step (relative).

    Raises:
        ValueError: fewer than 2 coordinates, non-finite values, or non-uniform spacing (the FFT
            half-space operator needs a uniform grid: resample the map first).
    """
    out = []
    for name, c in (("x", x), ("y", y)):
        c = np.asarray(c, dtype=float).ravel()
        if c.size < 2 or not np.isfinite(c).all():
            raise ValueError(f"coordinates {name} must hold >= 2 finite values, got {c.size} "
                             f"({int((~np.isfinite(c)).sum())} non-finite)")
        d = np.diff(c)
        step = float(np.mean(d))
        dev = np.abs(d - step) / abs(step) if step != 0 else np.full(d.shape, np.inf)
        if step <= 0 or dev.max() > rtol:
            j = int(np.argmax(dev))
            raise ValueError(
                f"non-uniform spacing along {name}: step {name}[{j + 1}] - {name}[{j}] = "
                f"{float(d[j])!r} mm deviates by {dev[j]:.3g} (relative) from the mean step {float(step)!r} "
                f"mm; valid: strictly increasing, uniform to rtol = {rtol:g} (resample the map "
                "onto a uniform grid)")
        out.append(step)
    return out[0], out[1]


def _correlation_lengths(z: np.ndarray) -> Tuple[float, float]:
    """Correlation lengths along both axes in pixels: first lag where the ACF falls below 1/e.

    inf where it never does within half the map (a surface constant along that axis).
    """
    Z = _rfft2(z)
    acf = _irfft2(np.abs(Z) ** 2, s=z.shape)
    acf /= acf[0, 0]
    out = []
    for line in (acf[: z.shape[0] // 2 + 1, 0], acf[0, : z.shape[1] // 2 + 1]):
        below = np.flatnonzero(line < math.exp(-1.0))
        if below.size == 0:
            out.append(math.inf)               # no decorrelation along this axis (e.g. a wave)
            continue
        j = int(below[0])
        # linear interpolation between lags j-1 and j
        f0, f1 = line[j - 1], line[j]
        out.append(float(j - 1 + (f0 - math.exp(-1.0)) / (f0 - f1)))
    return out[0], out[1]


@dataclass(frozen=True)
class MapDiagnostics:
    """What :func:`check_height_map` measured (pixels, mm, -)."""

    shape: Tuple[int, int]
    spacing: Tuple[float, float]
    rms_height: float
    rms_slope: float
    correlation_pixels: Tuple[float, float]
    edge_mismatch: float


def check_height_map(z, dx: float, dy: Optional[float] = None, *,
                     boundary: str = "periodic") -> Tuple[np.ndarray, MapDiagnostics]:
    """Validate a height map for the BEM and return it prepared (mean removed, contiguous).

    Args:
        z: (nx, ny) heights [mm], axis 0 = x (grain direction), nx, ny >= 8.
        dx, dy: uniform sampling steps [mm] (dy defaults to dx); use
            :func:`spacing_from_coordinates` for a map given with coordinates.
        boundary: "periodic" (the map is one period), "mirror" (a measured, non-periodic map:
            extended by even reflection to 2nx x 2ny, continuous and periodic, 4x the cost) or
            "window" (the heights are tapered to the mean plane over the outer 1/8 of each side
            by a Tukey window: cheaper, but the edge strips carry less load).

    Returns:
        (heights prepared for the solver [mm], :class:`MapDiagnostics` of the input map).

    Raises:
        ValueError: not 2D or too small, NaN/inf heights (fill or crop unmeasured points
            first), bad steps or boundary, fewer than ``MIN_PIXELS_PER_CORRELATION`` pixels per
            correlation length, an rms slope above ``MAX_RMS_SLOPE``, a flat map.

    Warns:
        HeightMapWarning: fewer than ``WARN_PIXELS_PER_CORRELATION`` pixels per correlation
            length, an rms slope above ``WARN_RMS_SLOPE`` (small-slope assumption strained), or
            a "periodic" map whose opposite edges do not match (use boundary="mirror").
    """
    z = np.asarray(z, dtype=float)
    if z.ndim != 2 or min(z.shape) < 8:
        raise ValueError(f"height map shape {z.shape} is invalid: a 2D map of at least 8 x 8 "
                         "pixels is needed")
    bad = ~np.isfinite(z)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise ValueError(
            f"height map has {int(bad.sum())} NaN/inf values out of {z.size} (first at pixel "
            f"({i}, {j})); valid: all heights finite. Fill unmeasured points (e.g. "
            "interpolation) or crop the map before the BEM")
    dx = check_scalar("dx", dx, lo=0.0, unit="mm")
    dy = dx if dy is None else check_scalar("dy", dy, lo=0.0, unit="mm")
    if boundary not in ("periodic", "mirror", "window"):
        raise ValueError(f"boundary = {boundary!r} is invalid; valid: 'periodic', 'mirror', "
                         "'window'")
    z = z - z.mean()
    rq = float(np.sqrt(np.mean(z ** 2)))
    if not rq > 0:
        raise ValueError("height map is flat (rms height 0 mm): nothing to compute")
    # rms slope by central differences inside the map (no wrap: valid for non-periodic maps)
    gx = (z[2:, 1:-1] - z[:-2, 1:-1]) / (2 * dx)
    gy = (z[1:-1, 2:] - z[1:-1, :-2]) / (2 * dy)
    slope = float(np.sqrt(np.mean(gx ** 2) + np.mean(gy ** 2)))
    cx, cy = _correlation_lengths(z)
    # mismatch of the periodic continuation: rms jump across the opposite edges relative to the
    # rms jump between interior neighbours
    jump = np.sqrt(0.5 * (np.mean((z[0] - z[-1]) ** 2) + np.mean((z[:, 0] - z[:, -1]) ** 2)))
    inner = np.sqrt(0.5 * (np.mean(np.diff(z, axis=0) ** 2) + np.mean(np.diff(z, axis=1) ** 2)))
    mismatch = float(jump / inner) if inner > 0 else 0.0
    diag = MapDiagnostics(z.shape, (dx, dy), rq, slope, (cx, cy), mismatch)
    cmin = min(cx, cy)
    if cmin < MIN_PIXELS_PER_CORRELATION:
        raise ValueError(
            f"correlation length = {cmin:.3g} pixels (x: {cx:.3g}, y: {cy:.3g}) is below "
            f"MIN_PIXELS_PER_CORRELATION = {MIN_PIXELS_PER_CORRELATION:g}: the map does not "
            "resolve its asperities (noise-like heights); measure or resample with a finer step")
    if cmin < WARN_PIXELS_PER_CORRELATION:
        warnings.warn(
            f"correlation length = {cmin:.3g} pixels (x: {cx:.3g}, y: {cy:.3g}) < "
            f"{WARN_PIXELS_PER_CORRELATION:g}: contact spots are under-resolved and the BEM law "
            "is grid-dependent (see the grid-convergence study in docs/bem.md)",
            HeightMapWarning, stacklevel=2)
    if slope > MAX_RMS_SLOPE:
        raise ValueError(
            f"rms slope = {slope:.3g} is above MAX_RMS_SLOPE = {MAX_RMS_SLOPE:g}: the half-space "
            "boundary elements assume small slopes; this surface is too rough for them (check "
            "units and detrending: heights and steps both in mm)")
    if slope > WARN_RMS_SLOPE:
        warnings.warn(
            f"rms slope = {slope:.3g} > {WARN_RMS_SLOPE:g}: the small-slope assumption of the "
            "half-space boundary elements is strained (errors of the order of the slope squared)",
            HeightMapWarning, stacklevel=2)
    if boundary == "periodic" and mismatch > 3.0:
        warnings.warn(
            f"the map is not periodic: the jump across opposite edges is {mismatch:.3g} times "
            "the rms jump between neighbouring pixels, so the periodic BEM sees an artificial "
            "ridge along the edges; use boundary='mirror' (or 'window') for a measured map",
            HeightMapWarning, stacklevel=2)
    if boundary == "mirror":
        z = np.concatenate([z, z[::-1]], axis=0)
        z = np.concatenate([z, z[:, ::-1]], axis=1)
    elif boundary == "window":
        z = z * np.outer(_tukey(z.shape[0]), _tukey(z.shape[1]))
        z = z - z.mean()
    return np.ascontiguousarray(z), diag


def _tukey(n: int, frac: float = 0.25) -> np.ndarray:
    """Tukey window (flat top, cosine tapers over frac/2 of the length at each end)."""
    w = np.ones(n)
    m = max(int(frac * n / 2), 1)
    ramp = 0.5 * (1 - np.cos(np.pi * (np.arange(m) + 0.5) / m))
    w[:m] = ramp
    w[-m:] = ramp[::-1]
    return w


# ----------------------------------------------------------------------------------------------
# the half-space operator and the solvers
# ----------------------------------------------------------------------------------------------
class HalfSpace:
    """Periodic elastic half-space: surface displacement from surface tractions by FFT.

    Normal: u(q) = 2 p(q) / (E* |q|); tangential (Cerruti, both bodies with the same nu, or one
    rigid): u_i(q) = 2 / (E* |q| (1 - nu)) (delta_ij - nu q_i q_j / |q|^2) t_j(q). The q = 0 mode
    (uniform displacement) is set to zero: it is the mean separation's job.

    Args:
        shape: (nx, ny) pixels; size: (Lx, Ly) [mm]; E_star [MPa]; nu [-].
    """

    def __init__(self, shape: Tuple[int, int], size: Tuple[float, float], E_star: float,
                 nu: float):
        self.shape = (int(shape[0]), int(shape[1]))
        self.size = (float(size[0]), float(size[1]))
        nx, ny = self.shape
        qx = 2 * np.pi * np.fft.fftfreq(nx, self.size[0] / nx)[:, None]
        qy = 2 * np.pi * np.fft.rfftfreq(ny, self.size[1] / ny)[None, :]
        q = np.hypot(qx, qy)
        q[0, 0] = 1.0
        self._g = 2.0 / (E_star * q)
        self._g[0, 0] = 0.0
        ct = 1.0 / (1.0 - nu)
        self._gxx = self._g * ct * (1.0 - nu * (qx / q) ** 2)
        self._gyy = self._g * ct * (1.0 - nu * (qy / q) ** 2)
        self._gxy = -self._g * ct * nu * qx * qy / q ** 2

    def normal(self, p: np.ndarray) -> np.ndarray:
        """Zero-mean normal displacement [mm] of the pressure field p (nx, ny) [MPa]."""
        return _irfft2(self._g * _rfft2(p), s=self.shape)

    def tangential(self, tx: np.ndarray, ty: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Zero-mean tangential displacements [mm] of the shear tractions tx, ty [MPa]."""
        X, Y = _rfft2(tx), _rfft2(ty)
        ux = _irfft2(self._gxx * X + self._gxy * Y, s=self.shape)
        uy = _irfft2(self._gxy * X + self._gyy * Y, s=self.shape)
        return ux, uy


class ContactSolver(Protocol):
    """A backend: mean pressure -> pressure field of the rigid-flat contact of the height map."""

    name: str

    def solve(self, mean_pressure: float, initial: Optional[np.ndarray]) -> np.ndarray:
        """Pressure field (nx, ny) [MPa] with mean ``mean_pressure``; ``initial`` a start guess."""


class NumpySolver:
    """Polonsky & Keer (1999) constrained conjugate gradient, with an optional pressure cap.

    Elastic: the classical algorithm (conjugate gradients on the contact set, overlapping points
    released into it with a conjugacy reset, the load restored by scaling). Saturated (pressure cap
    H): an outer active-set loop around it; points at p = H are held at H (their displacement
    moves into an effective surface), the elastic problem is solved on the remaining points, points
    whose pressure exceeds H join the saturated set and saturated points whose gap opens leave it,
    until the set is stable. Converged when the rms gap on the contact set and the largest
    complementarity violation are below ``tol`` times the rms height.
    """

    def __init__(self, z: np.ndarray, halfspace: HalfSpace, hardness: Optional[float],
                 tol: float = 1e-8, max_iter: int = 20000, max_outer: int = 200):
        self.z = z
        self.K = halfspace
        self.H = None if hardness is None else float(hardness)
        self.tol = tol
        self.max_iter = max_iter
        self.max_outer = max_outer
        self.name = "numpy Polonsky-Keer" + ("" if hardness is None else " (saturated)")
        self.iterations = 0
        self._zr = float(np.sqrt(np.mean(z ** 2)))
        unit = np.zeros(z.shape)
        unit[0, 0] = 1.0
        self._tau_pixel = 1.0 / float(halfspace.normal(unit)[0, 0])

    def _pk(self, z: np.ndarray, load: float, allowed: Optional[np.ndarray],
            p: np.ndarray) -> np.ndarray:
        """Elastic Polonsky-Keer on the allowed points: mean(p) = load, p = 0 elsewhere."""
        zr = self._zr
        t = np.zeros_like(z)
        g_old = 1.0
        delta = 0.0
        res = viol = float("nan")
        for it in range(1, self.max_iter + 1):
            g = self.K.normal(p) - z
            S = p > 0
            g -= g[S].mean()
            G = float(np.dot(g[S], g[S]))
            # convergence of the current iterate: rms gap on the contact set, overlap elsewhere
            res = math.sqrt(G / max(int(S.sum()), 1)) / zr
            free = ~S if allowed is None else ~S & allowed
            viol = float(-g[free].min(initial=0.0)) / zr
            if res < self.tol and viol < 10 * self.tol:
                self.iterations += it
                return p
            beta = delta * G / g_old if g_old > 0 else 0.0
            t = np.where(S, g + beta * t, 0.0)
            g_old = G
            r = self.K.normal(t)
            r -= r[S].mean()
            den = float(np.dot(r[S], t[S]))
            tau = float(np.dot(g[S], t[S])) / den if den > 0 else 0.0
            p = np.where(S, p - tau * t, 0.0)
            np.maximum(p, 0.0, out=p)
            over = (p == 0) & (g < 0)          # open points overlapping the flat
            if allowed is not None:
                over &= allowed
            delta = 0.0 if over.any() else 1.0
            # a single contact point has no conjugate direction (tau = 0): release overlapping
            # points with the stiffness of one pixel (the diagonal of the influence matrix)
            p[over] = -(tau if tau > 0 else self._tau_pixel) * g[over]
            p *= load / p.mean()
        raise RuntimeError(f"numpy BEM solver did not converge in {self.max_iter} iterations "
                           f"(residual {res:.3g}, violation {viol:.3g}, tol {self.tol:g})")

    def solve(self, mean_pressure: float, initial: Optional[np.ndarray] = None) -> np.ndarray:
        self.iterations = 0
        if initial is None or not (initial > 0).any():
            p = np.full(self.z.shape, float(mean_pressure))
        else:
            p = initial * (mean_pressure / initial.mean())
        if self.H is None:
            return self._pk(self.z, mean_pressure, None, p)
        H = self.H
        sat = p >= H
        n = p.size
        seen = set()
        for self.outer in range(1, self.max_outer + 1):
            load = mean_pressure - H * np.count_nonzero(sat) / n
            held = np.where(sat, H, 0.0)
            if load <= 1e-12 * mean_pressure:
                # the saturated pixels carry the whole load (exactly, up to round-off): only
                # possible when mean_pressure N / H is an integer; otherwise a solver failure
                if load >= -1e-12 * mean_pressure:
                    return held
                raise RuntimeError("saturated BEM: the saturated set carries more than the load")
            z_eff = self.z - self.K.normal(held)
            start = np.where(sat, 0.0, np.minimum(p, H))
            if not (start > 0).any():
                start = np.where(sat, 0.0, 1.0)
            start *= load / start.mean()
            pf = self._pk(z_eff, load, ~sat, start)
            p = pf + held
            g = self.K.normal(p) - self.z
            contact = (pf > 0) & (pf <= H)
            g -= g[contact].mean() if contact.any() else 0.0
            add = pf > H
            if add.any():          # additions first: they only ever lower the other pressures
                sat |= add
                continue
            release = sat & (g > 10 * self.tol * self._zr)
            if not release.any():
                return p
            key = hashlib.sha1(np.packbits(sat & ~release).tobytes()).digest()
            if key in seen:        # a cycle: the released gaps are at round-off level
                return p
            seen.add(key)
            sat &= ~release
        raise RuntimeError(f"saturated BEM: the saturated set did not settle in {self.max_outer} "
                           "outer iterations")


class TamaasSolver:
    """Tamaas' PolonskyKeerRey (elastic) or KatoSaturated (hardness cap) on the same grid."""

    def __init__(self, z: np.ndarray, size: Tuple[float, float], E_star: float, nu: float,
                 hardness: Optional[float], tol: float = 1e-10):
        tm = _import_tamaas()
        tm.set_log_level(tm.LogLevel.error)
        self._surface = np.ascontiguousarray(z, dtype=float)   # tamaas keeps a reference
        self._model = tm.ModelFactory.createModel(tm.model_type.basic_2d, list(size),
                                                  list(z.shape))
        # basic_2d uses the plane modulus E/(1 - nu^2) = E*: set E so that it equals E_star
        self._model.E = E_star * (1.0 - nu ** 2)
        self._model.nu = nu
        if hardness is None:
            self._solver = tm.PolonskyKeerRey(self._model, self._surface, tol)
            kind = "PolonskyKeerRey"
        else:
            self._solver = tm.KatoSaturated(self._model, self._surface, tol, float(hardness))
            kind = "KatoSaturated"
        self.name = f"tamaas {tm.__version__} {kind}"
        self.iterations = -1

    def solve(self, mean_pressure: float, initial: Optional[np.ndarray] = None) -> np.ndarray:
        # Tamaas manages its own iterate between solves; ``initial`` is not passed on (a warm
        # start from the previous load step saved < 20 % in a check at 180^2 pixels)
        self._solver.solve(float(mean_pressure))
        return np.array(self._model.traction, dtype=float)


def _cg_on_set(apply, mask: np.ndarray, rhs: Sequence[np.ndarray], tol: float = 1e-10,
               max_iter: int = 5000) -> Tuple[np.ndarray, ...]:
    """Conjugate gradients for P A P x = P b with x supported on mask (A symmetric PD there).

    ``apply`` maps a tuple of fields to a tuple of fields (block operator).
    """
    x = tuple(np.zeros_like(b) for b in rhs)
    r = tuple(np.where(mask, b, 0.0) for b in rhs)
    d = r
    rr = sum(float(np.dot(ri.ravel(), ri.ravel())) for ri in r)
    r0 = math.sqrt(rr)
    for _ in range(max_iter):
        if math.sqrt(rr) <= tol * r0:
            return x
        Ad = tuple(np.where(mask, a, 0.0) for a in apply(d))
        alpha = rr / sum(float(np.dot(di.ravel(), ai.ravel())) for di, ai in zip(d, Ad))
        x = tuple(xi + alpha * di for xi, di in zip(x, d))
        r = tuple(ri - alpha * ai for ri, ai in zip(r, Ad))
        rr_new = sum(float(np.dot(ri.ravel(), ri.ravel())) for ri in r)
        d = tuple(ri + (rr_new / rr) * di for ri, di in zip(r, d))
        rr = rr_new
    raise RuntimeError(f"stiffness CG did not converge in {max_iter} iterations "
                       f"(residual {math.sqrt(rr) / r0:.3g})")


def _post_process(z: np.ndarray, p: np.ndarray, K: HalfSpace, hardness: Optional[float],
                  tangential: bool) -> Tuple[float, float, float, float, float]:
    """d [mm], A/A0, k [MPa/mm], kT_x, kT_y [MPa/mm] of one solved pressure field."""
    H = np.inf if hardness is None else hardness
    r = z - K.normal(p)                   # gap = d - r
    contact = p > 0
    elastic = contact & (p < H * (1 - 1e-12))
    if elastic.any():
        d = float(r[elastic].mean())
    else:   # all contact points saturated: d between the open and the saturated bounds
        lo = float(r[~contact].max(initial=-np.inf))
        hi = float(r[contact].min(initial=np.inf))
        d = 0.5 * (lo + hi) if np.isfinite(lo + hi) else (lo if np.isfinite(lo) else hi)
    a = float(contact.mean())
    if a >= 1.0:
        raise ValueError("full contact (A/A0 = 1): the mean pressure is above the range of the "
                         "rough-contact law; lower the largest pressure")
    if elastic.any():
        (dp,) = _cg_on_set(lambda f: (K.normal(f[0]),), elastic, (np.ones_like(z),))
        k = float(dp.mean())
    else:
        k = 0.0
    kx = ky = float("nan")
    if tangential:
        one, zero = np.ones_like(z), np.zeros_like(z)
        tx, _ = _cg_on_set(lambda f: K.tangential(f[0], f[1]), contact, (one, zero))
        _, ty = _cg_on_set(lambda f: K.tangential(f[0], f[1]), contact, (zero, one))
        kx, ky = float(tx.mean()), float(ty.mean())
    return d, a, k, kx, ky


# ----------------------------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BEMCurves:
    """BEM results of one or more height maps (realisations) at the same mean pressures.

    Attributes:
        pressure: (n_p,) mean pressures solved [MPa], increasing.
        separation: (n_r, n_p) separation d of the mean plane [mm].
        area_fraction: (n_r, n_p) A/A0 [-].
        stiffness: (n_r, n_p) normal stiffness k = -dp/dh [MPa/mm] (Barber).
        tangential_stiffness: (n_r, n_p, 2) kT_x, kT_y in full stick [MPa/mm] (NaN if skipped).
        backend: name of the solver that ran (e.g. "tamaas 2.8.1 PolonskyKeerRey").
        grid: (nx, ny) pixels solved (after mirroring), size: (Lx, Ly) [mm].
        E_star [MPa], nu [-], hardness [MPa] or None (elastic).
        rms_height: (n_r,) rms height of each map [mm]; build_time: (n_r,) wall time [s].
        cached: (n_r,) True where the result came from the disk cache.
        refinement_error: with ``rtol``, the largest midpoint error of the last refinement
            round (p, and k for elastic contact); None without refinement.
        area_fraction_extrapolated: (n_r, n_p) Richardson estimate of A/A0,
            2 A(grid) - A(grid/2), at the same pressures (``area_extrapolation=True``), or None.
            ``area_fraction`` stays the raw pixel count.
    """

    pressure: np.ndarray
    separation: np.ndarray
    area_fraction: np.ndarray
    stiffness: np.ndarray
    tangential_stiffness: np.ndarray
    backend: str
    grid: Tuple[int, int]
    size: Tuple[float, float]
    E_star: float
    nu: float
    hardness: Optional[float]
    rms_height: np.ndarray
    build_time: np.ndarray
    cached: np.ndarray
    refinement_error: Optional[float] = None
    area_fraction_extrapolated: Optional[np.ndarray] = None

    @property
    def n_realisations(self) -> int:
        return int(self.separation.shape[0])

    @staticmethod
    def stack(curves: Sequence["BEMCurves"]) -> "BEMCurves":
        """Join single-map results computed at the same pressures into one."""
        c0 = curves[0]
        for c in curves[1:]:
            if not np.array_equal(c.pressure, c0.pressure):
                raise ValueError("curves were computed at different pressures")
        cat = lambda name: np.concatenate([getattr(c, name) for c in curves])  # noqa: E731
        ext = [c.area_fraction_extrapolated is not None for c in curves]
        if any(ext) and not all(ext):
            raise ValueError("some curves have an extrapolated area and some have not")
        return replace(c0, separation=cat("separation"), area_fraction=cat("area_fraction"),
                       area_fraction_extrapolated=cat("area_fraction_extrapolated")
                       if all(ext) else None,
                       stiffness=cat("stiffness"),
                       tangential_stiffness=cat("tangential_stiffness"),
                       rms_height=cat("rms_height"), build_time=cat("build_time"),
                       cached=cat("cached"))


def default_cache_dir() -> Path:
    """``$ROUGH_CONTACT_CACHE`` or ``~/.cache/rough_contact/bem``."""
    env = os.environ.get("ROUGH_CONTACT_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "rough_contact" / "bem"


def _cache_key(z: np.ndarray, size, E_star, nu, hardness, pressures, backend, tol,
               tangential, rtol=None, area_extrapolation=False) -> str:
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(z, dtype=np.float64).tobytes())
    meta = dict(v=_CACHE_VERSION, shape=list(z.shape), size=[float(s) for s in size],
                E_star=float(E_star), nu=float(nu),
                hardness=None if hardness is None else float(hardness),
                pressures=[float(p) for p in pressures], backend=backend, tol=float(tol),
                tangential=bool(tangential))
    if rtol is not None:            # (absent key: results cached before refinement existed)
        meta["rtol"] = float(rtol)
    if area_extrapolation:          # likewise
        meta["area_extrapolation"] = True
    h.update(json.dumps(meta, sort_keys=True).encode())
    return h.hexdigest()[:32]


def _check_pressures(pressures, hardness) -> np.ndarray:
    p = np.array(pressures, dtype=float).ravel()
    if p.size < 3:
        raise ValueError(f"pressures must hold >= 3 values, got {p.size}")
    if not np.isfinite(p).all() or (p <= 0).any():
        raise ValueError(f"pressures = {p!r} MPa are invalid: all must be finite and > 0")
    if np.any(np.diff(p) <= 0):
        raise ValueError("pressures must be strictly increasing")
    if hardness is not None and p[-1] >= hardness:
        raise ValueError(f"largest pressure = {float(p[-1])!r} MPa is invalid: it must be below the "
                         f"hardness H = {hardness!r} MPa (p = H is full plastic contact)")
    return p


def _solver(backend: str, z, size, E_star, nu, hardness, tol) -> ContactSolver:
    if backend == "tamaas":
        return TamaasSolver(z, size, E_star, nu, hardness, tol)
    if backend == "numpy":
        return NumpySolver(z, HalfSpace(z.shape, size, E_star, nu), hardness, tol)
    raise ValueError(f"backend = {backend!r} is invalid; valid: {_BACKENDS}")


def bem_curves(z, dx: float, dy: Optional[float] = None, *, E_star: float, nu: float,
               pressures, hardness: Optional[float] = None, backend: Optional[str] = None,
               boundary: str = "periodic", tol: Optional[float] = None,
               tangential: bool = True, rtol: Optional[float] = None, max_pressures: int = 64,
               area_extrapolation: bool = False, cache: bool = True,
               cache_dir: Optional[os.PathLike] = None) -> BEMCurves:
    """Solve the rough contact of one height map at the given mean pressures.

    Args:
        z: (nx, ny) heights [mm], axis 0 = x; see :func:`check_height_map` for the checks.
        dx, dy: sampling steps [mm].
        E_star: effective modulus E* [MPa]; nu: Poisson ratio of the bodies [-] (tangential
            kernel only).
        pressures: (n_p,) mean pressures [MPa], increasing, >= 3 values.
        hardness: None (elastic) or the pressure cap H [MPa] (saturated contact).
        backend: None (default: "tamaas" for elastic, "numpy" for saturated), "tamaas"
            (needs the extra rough_contact[bem]) or "numpy".
        boundary: "periodic", "mirror" or "window" (:func:`check_height_map`).
        tol: solver tolerance (default 1e-10 for tamaas, 1e-8 for numpy, both relative).
        tangential: also compute the stick tangential stiffnesses (about doubles the cost).
        rtol: None, or the accuracy the table must reach between its knots - the check of
            ``NormalLaw.from_model``: every interval is solved at its geometric-mean pressure
            and, where the table built from the other points misses p (and, elastic, k) there
            by more than rtol, both halves are split again (the midpoints always become knots);
            until all pass or ``max_pressures`` is reached (the worst remaining error is then in
            ``BEMCurves.refinement_error``).
        max_pressures: limit of the refinement.
        area_extrapolation: also solve the map sub-sampled by 2 (every other pixel, a quarter
            of the pixels) at the same pressures and report the Richardson estimate
            2 A(grid) - A(grid/2) of the real-area fraction beside the raw pixel count
            (``BEMCurves.area_fraction_extrapolated``): pixel counting overestimates A/A0 at
            first order in the pixel size (docs/bem.md, "Real area"). Exact sub-sampling of
            the same surface needs a map without content at wavelengths below 4 pixels
            (synthetic realisations at >= 4 pixels per shortest wavelength); otherwise a
            HeightMapWarning says how much slope variance the coarse grid loses. Needs an even
            number of pixels per side (after mirroring).
        cache: read/write the result in the disk cache (keyed by the prepared heights, the grid,
            E*, nu, H, the pressures, the backend, tol, rtol and the code version).
        cache_dir: cache directory (default :func:`default_cache_dir`).

    Returns:
        :class:`BEMCurves` with one realisation.

    Raises:
        ValueError: bad map (see :func:`check_height_map`) or parameters, full contact.
        BackendUnavailableError: the backend cannot be imported.
    """
    E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
    nu = check_scalar("nu", nu, lo=-1.0, hi=0.5, hi_open=False)
    if hardness is not None:
        hardness = check_scalar("hardness", hardness, lo=0.0, unit="MPa")
    pressures = _check_pressures(pressures, hardness)
    backend = _default_backend(backend, hardness)
    if backend == "tamaas":
        _import_tamaas()
    tol = (1e-10 if backend == "tamaas" else 1e-8) if tol is None else \
        check_scalar("tol", tol, lo=0.0, hi=1e-2)
    zp, diag = check_height_map(z, dx, dy, boundary=boundary)
    dx, dy = diag.spacing
    size = (zp.shape[0] * dx, zp.shape[1] * dy)
    if rtol is not None:
        rtol = check_scalar("rtol", rtol, lo=1e-6, lo_open=False, hi=0.1)
    area_extrapolation = bool(area_extrapolation)
    if area_extrapolation:
        _check_subsampling(zp, dx, dy)
    key = _cache_key(zp, size, E_star, nu, hardness, pressures, backend, tol, tangential,
                     rtol, area_extrapolation)
    path = Path(cache_dir or default_cache_dir()) / f"bem_{key}.npz"
    if cache and path.exists():
        with np.load(path, allow_pickle=False) as f:
            meta = json.loads(str(f["meta"]))
            return BEMCurves(pressure=f["pressure"] if "pressure" in f else pressures,
                             separation=f["separation"][None],
                             area_fraction=f["area_fraction"][None],
                             stiffness=f["stiffness"][None],
                             tangential_stiffness=f["tangential_stiffness"][None],
                             backend=meta["backend"], grid=tuple(zp.shape), size=size,
                             E_star=E_star, nu=nu, hardness=hardness,
                             rms_height=np.array([diag.rms_height]),
                             build_time=np.array([meta["build_time"]]),
                             cached=np.array([True]),
                             refinement_error=meta.get("refinement_error"),
                             area_fraction_extrapolated=f["area_fraction_extrapolated"][None]
                             if "area_fraction_extrapolated" in f else None)
    t0 = time.perf_counter()
    solver = _solver(backend, zp, size, E_star, nu, hardness, tol)
    K = HalfSpace(zp.shape, size, E_star, nu)

    def solve_all(pr):
        n = pr.size
        d, a, k = np.empty(n), np.empty(n), np.empty(n)
        kt = np.full((n, 2), np.nan)
        p_field = None
        for j, pm in enumerate(pr):      # one BEM solve per pressure, warm-started in order
            p_field = solver.solve(pm, p_field)
            d[j], a[j], k[j], kt[j, 0], kt[j, 1] = _post_process(zp, p_field, K, hardness,
                                                                 tangential)
        return d, a, k, kt

    d, a, k, kt = solve_all(pressures)
    worst = None
    if rtol is not None:
        pressures, d, a, k, kt, worst = _refine(solve_all, pressures, d, a, k, kt, rtol,
                                                hardness is None, int(max_pressures))
    a_ext = None
    if area_extrapolation:
        a_ext = 2.0 * a - _coarse_areas(zp, size, E_star, nu, hardness, backend, tol, pressures)
    elapsed = time.perf_counter() - t0
    out = BEMCurves(pressure=pressures, separation=d[None], area_fraction=a[None],
                    area_fraction_extrapolated=None if a_ext is None else a_ext[None],
                    stiffness=k[None], tangential_stiffness=kt[None], backend=solver.name,
                    grid=tuple(zp.shape), size=size, E_star=E_star, nu=nu, hardness=hardness,
                    rms_height=np.array([diag.rms_height]), build_time=np.array([elapsed]),
                    cached=np.array([False]), refinement_error=worst)
    if cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + f".{os.getpid()}.tmp.npz")
        extra = {} if a_ext is None else {"area_fraction_extrapolated": a_ext}
        np.savez(tmp, pressure=pressures, separation=d, area_fraction=a, stiffness=k,
                 tangential_stiffness=kt, **extra,
                 meta=json.dumps({"backend": solver.name, "build_time": elapsed,
                                  "refinement_error": worst}))
        os.replace(tmp, path)   # atomic: a concurrent reader never sees half a file
    return out


def _check_subsampling(zp: np.ndarray, dx: float, dy: float) -> float:
    """Fraction of the slope variance of zp at wavelengths below 4 pixels (lost by the grid/2
    of the area extrapolation); ValueError for an odd side, HeightMapWarning above 1 %."""
    if zp.shape[0] % 2 or zp.shape[1] % 2:
        raise ValueError(f"area_extrapolation needs an even number of pixels per side, got "
                         f"{zp.shape} (crop one row/column, or use boundary='mirror')")
    P = np.abs(_rfft2(zp)) ** 2
    kx = np.abs(np.fft.fftfreq(zp.shape[0]))[:, None]        # cycles per pixel
    ky = np.abs(np.fft.rfftfreq(zp.shape[1]))[None, :]
    w = P * ((kx / dx) ** 2 + (ky / dy) ** 2)
    lost = float(w[(kx > 0.25) | (ky > 0.25)].sum() / w.sum())
    if lost > 0.01:
        warnings.warn(
            f"{lost:.1%} of the map's slope variance lies at wavelengths below 4 pixels, which "
            "the half-resolution grid of the area extrapolation does not carry: the "
            "extrapolated A/A0 mixes that loss of roughness into the discretisation error",
            HeightMapWarning, stacklevel=3)
    return lost


def _coarse_areas(zp, size, E_star, nu, hardness, backend, tol, pressures) -> np.ndarray:
    """Pixel-counted A/A0 of the map sub-sampled by 2 at the given pressures."""
    zc = np.ascontiguousarray(zp[::2, ::2])
    zc = zc - zc.mean()
    solver = _solver(backend, zc, size, E_star, nu, hardness, tol)
    out = np.empty(pressures.size)
    p = None
    for j, pm in enumerate(pressures):
        p = solver.solve(pm, p)
        out[j] = float((p > 0).mean())
    return out


def _refine(solve_all, p, d, a, k, kt, rtol, use_k, max_pressures):
    """Midpoint checks and bisection of the pressure list (see :func:`bem_curves`, rtol)."""
    todo = np.ones(p.size - 1, bool)          # intervals still to check
    worst = 0.0
    while todo.any():
        if p.size + int(todo.sum()) > max_pressures:
            break
        i = np.flatnonzero(todo)
        pm = np.sqrt(p[i] * p[i + 1])
        dm, am, km, ktm = solve_all(pm)
        o = np.argsort(d)                      # the table wants increasing h
        law, _ = _law_from_data(d[o], p[o], k[o], a[o], use_k)
        pl, kl, _ = law.evaluate(dm)
        err = np.abs(pl / pm - 1)
        if use_k:
            err = np.maximum(err, np.abs(kl / km - 1))
        worst = float(err.max())
        fail = err > rtol
        # insert the midpoints (solved anyway); the halves of failing intervals are checked next
        pos = i + 1
        p, d, a, k = (np.insert(v, pos, w) for v, w in ((p, pm), (d, dm), (a, am), (k, km)))
        kt = np.insert(kt, pos, ktm, axis=0)
        new_todo = np.zeros(p.size - 1, bool)
        shifted = i + np.arange(i.size)        # index of interval i's left half after insertion
        new_todo[shifted[fail]] = True
        new_todo[shifted[fail] + 1] = True
        todo = new_todo
    return p, d, a, k, kt, worst


# ----------------------------------------------------------------------------------------------
# the law
# ----------------------------------------------------------------------------------------------
def mindlin_ratio(nu: float) -> float:
    """kT/kN = 2(1 - nu)/(2 - nu) of a circular contact in full stick (Mindlin 1949) [-]."""
    nu = check_scalar("nu", nu, lo=-1.0, hi=0.5, hi_open=False)
    return 2.0 * (1.0 - nu) / (2.0 - nu)


@dataclass(frozen=True)
class BEMLaw:
    """A normal law computed by boundary elements, with its data and its realisation scatter.

    Attributes:
        normal: the :class:`NormalLaw` (``NormalLaw.from_table`` of the data below): use it
            wherever a statistical NormalLaw is used.
        curves: the raw :class:`BEMCurves` (every realisation).
        separation: (n,) table separations h [mm], increasing.
        pressure, stiffness, area_fraction: (n,) realisation means at equal separation
            [MPa, MPa/mm, -].
        pressure_std, stiffness_std, area_std: (n,) standard deviations over the realisations at
            equal separation (zeros for one map): the error band of a single realisation; the
            mean's standard error is std / sqrt(n_realisations).
        tangential_ratio: (n, 2) kT_x/kN, kT_y/kN in full stick (NaN if not computed) [-].
        info: backend, grid, timings, interpolation-error estimates, k source, area source...
        area_fraction_pixel: (n,) the raw pixel-counted A/A0 at the same separations (equal to
            ``area_fraction`` unless that is the Richardson estimate, ``info["area_source"]``).
    """

    normal: NormalLaw
    curves: BEMCurves
    separation: np.ndarray
    pressure: np.ndarray
    stiffness: np.ndarray
    area_fraction: np.ndarray
    pressure_std: np.ndarray
    stiffness_std: np.ndarray
    area_std: np.ndarray
    tangential_ratio: np.ndarray
    info: dict = field(default_factory=dict)
    area_fraction_pixel: Optional[np.ndarray] = None

    def tangential(self):
        """:class:`TangentialStiffness` with the BEM ratios kT/kN averaged over the table.

        The interface law takes a constant ratio; ``info["tangential_ratio_range"]`` says how
        much the BEM ratio varies over the load range.
        """
        from rough_contact.interface.tangential import TangentialStiffness

        r = np.nanmean(self.tangential_ratio, axis=0)
        if not np.isfinite(r).all():
            raise ValueError("the tangential stiffness was not computed (tangential=False)")
        return TangentialStiffness((float(r[0]), float(r[1])))


def _realisation_table(c: BEMCurves, r: int, area: Optional[np.ndarray] = None):
    """(h, p, k, a) of realisation r, ordered by increasing h; a from ``area`` (n_r, n_p) if
    given, else the pixel count."""
    o = np.argsort(c.separation[r])
    a = c.area_fraction if area is None else area
    return c.separation[r][o], c.pressure[o], c.stiffness[r][o], a[r][o]


def _hermite_eval(h, p, k, a, x):
    """p, k, a of one realisation at separations x (inside its range), consistent with its k."""
    from scipy.interpolate import PchipInterpolator

    q, dq = hermite_eval(h, np.log(p), -k / p, x)
    pv = np.exp(q)
    kv = -pv * dq
    av = np.exp(PchipInterpolator(h, np.log(a))(x))
    return pv, kv, av


def _law_from_data(h, p, k, a, use_k: bool):
    """NormalLaw from table data; Hermite with k when consistent, else PCHIP. -> (law, source)."""
    # The BEM result is handed over as the interface layer's NormalLaw (BEMLaw.normal), the one
    # reference of micro/ to the layer above: imported here, so that importing rough_contact.micro
    # never loads rough_contact.interface. The table itself is built by tables.tabulate_data.
    from ..interface.normal import NormalLaw

    if use_k:
        try:
            return NormalLaw.from_table(h, p, a, k=k), "BEM stiffness (Hermite)"
        except ValueError:
            pass
    return NormalLaw.from_table(h, p, a), "derivative of the PCHIP interpolant of ln p"


def _interpolation_error(h, p, k, a, use_k):
    """Leave-every-other-knot-out estimate of the table's interpolation error (max relative)."""
    if h.size < 5:
        return {"p": float("nan"), "k": float("nan"), "a": float("nan")}
    keep = np.zeros(h.size, bool)
    keep[::2] = True
    keep[-1] = True
    law, _ = _law_from_data(h[keep], p[keep], k[keep], a[keep], use_k)
    x = ~keep
    pv, kv, av = law.evaluate(h[x])
    return {"p": float(np.max(np.abs(pv / p[x] - 1))), "k": float(np.max(np.abs(kv / k[x] - 1))),
            "a": float(np.max(np.abs(av / a[x] - 1)))}


def law_from_curves(curves: BEMCurves) -> BEMLaw:
    """Tabulate :class:`BEMCurves` (one or more realisations) as a :class:`BEMLaw`.

    One realisation: the knots are its solved points. Several: every realisation's ln p(h) is
    interpolated (cubic Hermite with its own stiffness) onto common separations inside the range
    all realisations cover, and p, k, A/A0 are averaged *at equal separation* (the mean pressure
    of many interface patches at the same separation); the standard deviations are the band.
    The table uses the BEM stiffness as Hermite slope data when the elastic law is tabulated
    and the data are consistent (monotone), else the PCHIP derivative (always for a hardness:
    there the frozen-set stiffness misses the first-order growth of the saturated set).

    A/A0: the Richardson estimate when the curves carry one (``area_extrapolation=True``) and
    it is positive everywhere, else the pixel count; the pixel count at the table's
    separations is kept beside it (``BEMLaw.area_fraction_pixel``, ``info["area_source"]``).
    """
    nr = curves.n_realisations
    use_k = curves.hardness is None
    ext = curves.area_fraction_extrapolated
    area_source = "pixel count"
    if ext is not None:
        if np.all(ext > 0) and np.all(ext <= curves.area_fraction):
            area_source = "Richardson 2 A(grid) - A(grid/2)"
        else:
            warnings.warn("the Richardson estimate of A/A0 is outside (0, pixel count] at some "
                          "pressure (coarse grid outside its asymptotic range): the table keeps "
                          "the pixel count", HeightMapWarning, stacklevel=2)
            ext = None
    tabs = [_realisation_table(curves, r, ext) for r in range(nr)]
    pix = [_realisation_table(curves, r) for r in range(nr)]
    if nr == 1:
        h, p, k, a = tabs[0]
        a_pix = pix[0][3]
        ps = ks = as_ = np.zeros_like(h)
        kt = curves.tangential_stiffness[0][np.argsort(curves.separation[0])]
        ratio = kt / k[:, None]
    else:
        lo = max(t[0][0] for t in tabs)
        hi = min(t[0][-1] for t in tabs)
        if not hi > lo:
            raise ValueError("the realisations share no separation range: widen the pressures")
        hm = np.sort(np.mean([t[0] for t in tabs], axis=0))
        h = np.unique(np.clip(hm, lo, hi))
        vals = np.array([_hermite_eval(*t, h) for t in tabs])        # (nr, 3, n)
        p, k, a = vals.mean(axis=0)
        ps, ks, as_ = vals.std(axis=0, ddof=1)
        a_pix = np.mean([_hermite_eval(*t, h)[2] for t in pix], axis=0)
        ratio = np.full((h.size, 2), np.nan)
        with_kt = [r for r in range(nr) if np.isfinite(curves.tangential_stiffness[r]).all()]
        if with_kt:
            # the ratio kT/kN varies slowly (and little between realisations): average the
            # ratio of each realisation that has it, at equal h
            rr = []
            for r in with_kt:
                t = tabs[r]
                o = np.argsort(curves.separation[r])
                kt = curves.tangential_stiffness[r][o] / t[2][:, None]
                rr.append([np.interp(h, t[0], kt[:, j]) for j in range(2)])
            ratio = np.mean(rr, axis=0).T
    law, source = _law_from_data(h, p, k, a, use_k)
    info = {
        "source": "bem", "backend": curves.backend, "grid": list(curves.grid),
        "size_mm": list(curves.size), "realisations": nr, "hardness": curves.hardness,
        "E_star": curves.E_star, "nu": curves.nu, "k_source": source,
        "area_source": area_source,
        "area_pixel_range": [float(a_pix.min()), float(a_pix.max())],
        "build_time_s": float(np.sum(curves.build_time)),
        "cached": int(np.count_nonzero(curves.cached)),
        "pressure_range": [float(p.min()), float(p.max())],
        "area_range": [float(a.min()), float(a.max())],
        "interpolation_error": _interpolation_error(h, p, k, a, use_k and "Hermite" in source),
        "refinement_error": curves.refinement_error,
    }
    pk, kk, ak = law.evaluate(h)
    info["table_k_error"] = float(np.max(np.abs(kk / k - 1)))
    if np.isfinite(ratio).all():
        info["tangential_ratio_range"] = [[float(ratio[:, j].min()), float(ratio[:, j].max())]
                                          for j in range(2)]
    law.info.update(info)
    return BEMLaw(normal=law, curves=curves, separation=h, pressure=p, stiffness=k,
                  area_fraction=a, pressure_std=ps, stiffness_std=ks, area_std=as_,
                  tangential_ratio=ratio, info=info, area_fraction_pixel=a_pix)


def default_pressures(E_star: float, rms_slope: float, hardness: Optional[float] = None,
                      area_range: Tuple[float, float] = (0.005, 0.3),
                      n: int = 16) -> np.ndarray:
    """Mean pressures [MPa] expected to span ``area_range`` of A/A0 (n, log-spaced).

    Uses the proportionality A/A0 ~ 2 p / (E* rms_slope) of exact elastic rough contact at light
    load (Persson; Hyun et al. find a factor 1.6-2.5) only to *place* the pressures; the areas
    actually reached are in the result. With a hardness, A/A0 >= p/H caps the largest pressure.
    """
    E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
    rms_slope = check_scalar("rms_slope", rms_slope, lo=0.0)
    a0 = check_scalar("area_range[0]", area_range[0], lo=0.0, hi=1.0)
    a1 = check_scalar("area_range[1]", area_range[1], lo=a0, hi=1.0)
    n = int(check_scalar("n", n, lo=3.0, lo_open=False, hi=1e4))
    lo, hi = 0.5 * a0 * E_star * rms_slope, 0.5 * a1 * E_star * rms_slope
    if hardness is not None:
        H = check_scalar("hardness", hardness, lo=0.0, unit="MPa")
        hi = min(hi, 0.9 * a1 * H)
        lo = min(lo, hi / 20.0)
    return np.geomspace(lo, hi, n)


def _default_backend(backend: Optional[str], hardness) -> str:
    if backend is None:
        return "tamaas" if hardness is None else "numpy"
    if backend not in _BACKENDS:
        raise ValueError(f"backend = {backend!r} is invalid; valid: {_BACKENDS} or None")
    if backend == "tamaas" and hardness is not None:
        raise ValueError(
            "backend = 'tamaas' with a hardness is not supported: Tamaas' KatoSaturated stalled "
            "above its tolerance and needs dimensionless inputs in our checks (docs/bem.md); "
            "the saturated variant uses backend='numpy' (the default when hardness is given)")
    return backend


def bem_normal_law(z, dx: float, dy: Optional[float] = None, *, E_star: float, nu: float = 0.3,
                   pressures=None, area_range: Tuple[float, float] = (0.005, 0.3),
                   n_pressures: int = 16, hardness: Optional[float] = None,
                   backend: Optional[str] = None, boundary: str = "periodic",
                   tol: Optional[float] = None, tangential: bool = True,
                   rtol: Optional[float] = None, area_extrapolation: bool = False,
                   cache: bool = True,
                   cache_dir: Optional[os.PathLike] = None) -> BEMLaw:
    """The BEM normal law of one height map (measured or synthetic).

    Args:
        z: (nx, ny) heights [mm], axis 0 = x (grain direction).
        dx, dy: sampling steps [mm] (dy defaults to dx).
        E_star: effective modulus E* [MPa]; nu: Poisson ratio [-] (tangential stiffness).
        pressures: mean pressures to solve [MPa] (increasing, >= 3); default
            :func:`default_pressures` over ``area_range`` with ``n_pressures`` values.
        hardness: None (elastic) or the pressure cap H [MPa] (saturated, elasto-plastic).
        backend: None (default: "tamaas" for elastic, "numpy" for saturated), "tamaas", "numpy".
        boundary, tol, tangential, area_extrapolation, cache, cache_dir: see
            :func:`bem_curves`.
        rtol: None, or refine the pressures until the table meets rtol at the interval
            midpoints (:func:`bem_curves`; k carries pixel-level noise of about 0.5-1 % at
            8 pixels per shortest wavelength, so rtol below that is not reachable).

    Returns:
        :class:`BEMLaw`; ``.normal`` is the NormalLaw for the FE layer. Its table spans the
        solved pressures: below the smallest separation the stiff continuation, beyond the
        largest the cubic taper of :class:`NormalLaw` apply (the BEM resolves no lighter load).
    """
    backend = _default_backend(backend, hardness)
    if pressures is None:
        zc, diag = check_height_map(z, dx, dy, boundary=boundary)
        pressures = default_pressures(E_star, diag.rms_slope, hardness, area_range, n_pressures)
    c = bem_curves(z, dx, dy, E_star=E_star, nu=nu, pressures=pressures, hardness=hardness,
                   backend=backend, boundary=boundary, tol=tol, tangential=tangential,
                   rtol=rtol, area_extrapolation=area_extrapolation, cache=cache,
                   cache_dir=cache_dir)
    return law_from_curves(c)


def bem_law_from_moments(moments: SpectralMoments, *, E_star: float, nu: float = 0.3,
                         n_realisations: int = 4, pixels_per_wavelength: float = 4.0,
                         periods: int = 1, shape=None, seed: int = 0, pressures=None,
                         area_range: Tuple[float, float] = (0.005, 0.3), n_pressures: int = 16,
                         hardness: Optional[float] = None, backend: Optional[str] = None,
                         tol: Optional[float] = None, tangential: bool = True,
                         rtol: Optional[float] = None, area_extrapolation: Optional[bool] = None,
                         amplitudes: str = "random",
                         tangential_realisations: Optional[int] = None, workers: int = 1,
                         cache: bool = True,
                         cache_dir: Optional[os.PathLike] = None) -> BEMLaw:
    """The BEM law of a surface known only by its spectral moments, with realisation scatter.

    Gaussian realisations of the spectrum fitted by :func:`rough_contact.surface.spectrum.fit_spectrum`
    (the assumed shape is documented there: stretched isotropic self-affine with roll-off) are
    solved at the same pressures and averaged at equal separation (:func:`law_from_curves`);
    :func:`bem_law_from_spectrum` does the work.

    Args:
        moments: :class:`SpectralMoments` (x = grain direction).
        shape: :class:`rough_contact.surface.spectrum.SpectrumShape` (default H = 0.8, plateau 2).
        the others: as in :func:`bem_law_from_spectrum`.

    Returns:
        :class:`BEMLaw` whose ``*_std`` give the scatter between realisations.
    """
    from rough_contact.surface.spectrum import SpectrumShape, fit_spectrum

    spec = fit_spectrum(moments, SpectrumShape() if shape is None else shape)
    out = bem_law_from_spectrum(
        spec, E_star=E_star, nu=nu, n_realisations=n_realisations,
        pixels_per_wavelength=pixels_per_wavelength, periods=periods, seed=seed,
        pressures=pressures, area_range=area_range, n_pressures=n_pressures, hardness=hardness,
        backend=backend, tol=tol, tangential=tangential, rtol=rtol,
        area_extrapolation=area_extrapolation, amplitudes=amplitudes,
        tangential_realisations=tangential_realisations, workers=workers, cache=cache,
        cache_dir=cache_dir, rms_slope=math.sqrt(moments.m20 + moments.m02))
    out.info["spectrum"] = {"C_mm4": spec.C, "q_l": spec.q_l, "q_r": spec.q_r,
                            "q_s": spec.q_s, "hurst": spec.hurst, "gx": spec.gx,
                            "gy": spec.gy}
    out.normal.info.update(out.info)
    return out


def _bem_curves_job(kw: dict) -> BEMCurves:
    """One realisation's :func:`bem_curves` (a picklable job for a process pool)."""
    kw = dict(kw)
    z, dx, dy = kw.pop("z"), kw.pop("dx"), kw.pop("dy")
    return bem_curves(z, dx, dy, **kw)


def bem_law_from_spectrum(spectrum, *, E_star: float, nu: float = 0.3,
                          n_realisations: int = 4, pixels_per_wavelength: float = 4.0,
                          periods: int = 1, seed: int = 0, pressures=None,
                          area_range: Tuple[float, float] = (0.005, 0.3), n_pressures: int = 16,
                          hardness: Optional[float] = None, backend: Optional[str] = None,
                          tol: Optional[float] = None, tangential: bool = True,
                          rtol: Optional[float] = None,
                          area_extrapolation: Optional[bool] = None,
                          amplitudes: str = "random",
                          tangential_realisations: Optional[int] = None,
                          workers: int = 1, cache: bool = True,
                          cache_dir: Optional[os.PathLike] = None,
                          rms_slope: Optional[float] = None) -> BEMLaw:
    """The BEM law of a surface given by its spectrum: Gaussian realisations, averaged.

    Args:
        spectrum: a :class:`rough_contact.surface.spectrum.SurfaceSpectrum` - a
            :class:`~rough_contact.surface.spectrum.PSDSurface` (the user's own PSD, a callable
            or a :class:`~rough_contact.surface.spectrum.TabulatedPSD`) or a
            :class:`~rough_contact.surface.spectrum.StretchedSpectrum`.
        E_star, nu, hardness, backend, tol, tangential, rtol, cache, cache_dir: as in
            :func:`bem_normal_law` (with rtol the first realisation chooses the pressures, the
            others are solved at the same ones).
        n_realisations: number of realisations (seeds seed, seed + 1, ...), >= 1.
        pixels_per_wavelength: pixels per shortest wavelength of the spectrum (grid study in
            docs/bem.md).
        periods: longest wavelengths per side of every realisation.
        pressures: mean pressures [MPa]; default from the rms slope over area_range.
        area_extrapolation: report the Richardson estimate of A/A0 (:func:`bem_curves`) and
            tabulate it; None (default): when pixels_per_wavelength >= 6 (the half-resolution
            grid then still has >= 3 pixels per shortest wavelength: same surface, asymptotic
            range of the pixel-count error).
        amplitudes: "random" (Gaussian random fields: independent samples of the surface) or
            "fixed" (random phases, every mode at its expected modulus: the realisations share
            the spectrum's discrete moments exactly, which removes most of the scatter of p at
            equal separation between realisations; docs/bem.md, "Realisation scatter").
        tangential_realisations: with ``tangential``, compute the stick stiffness for the first
            this many realisations only (None: all); the ratio kT/kN scatters little between
            realisations (docs/bem.md), and it is the costliest part of a solve.
        workers: realisations solved in parallel processes (>= 1; each is single-threaded).
        rms_slope: rms slope of the surface (default: from the spectrum's moments), for the
            default pressures.

    Returns:
        :class:`BEMLaw` whose ``*_std`` give the scatter between realisations.
    """
    nr = int(check_scalar("n_realisations", n_realisations, lo=1.0, lo_open=False, hi=1e4))
    backend = _default_backend(backend, hardness)
    (nx, ny), (Lx, Ly) = spectrum.grid(pixels_per_wavelength, periods)
    if area_extrapolation is None:
        area_extrapolation = pixels_per_wavelength >= 6.0
    if pressures is None:
        if rms_slope is None:
            m = spectrum.moments()
            rms_slope = math.sqrt(m.m20 + m.m02)
        pressures = default_pressures(E_star, rms_slope, hardness, area_range, n_pressures)
    workers = int(check_scalar("workers", workers, lo=1.0, lo_open=False, hi=256))
    n_kt = nr if tangential_realisations is None else int(tangential_realisations)

    def job(r, pr, refine):
        return dict(z=spectrum.realisation((nx, ny), (Lx, Ly), seed + r, amplitudes),
                    dx=Lx / nx, dy=Ly / ny, E_star=E_star, nu=nu, pressures=pr,
                    hardness=hardness, backend=backend, tol=tol,
                    tangential=tangential and r < n_kt, rtol=rtol if refine else None,
                    area_extrapolation=area_extrapolation, cache=cache, cache_dir=cache_dir)

    # the first realisation fixes the pressures (with rtol it refines them)
    curves = [_bem_curves_job(job(0, pressures, True))]
    pressures = curves[0].pressure
    rest = [job(r, pressures, False) for r in range(1, nr)]
    if workers > 1 and rest:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        # spawn, not fork: the caller may hold threads (FFT, BLAS, MPI) that fork would copy
        # in an undefined state
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as ex:
            curves += list(ex.map(_bem_curves_job, rest))
    else:
        curves += [_bem_curves_job(j) for j in rest]
    out = law_from_curves(BEMCurves.stack(curves))
    out.info.update({"spectrum_type": type(spectrum).__name__, "amplitudes": amplitudes,
                     "pixels_per_wavelength": float(pixels_per_wavelength),
                     "periods": int(periods), "seeds": [seed + r for r in range(nr)]})
    out.normal.info.update(out.info)
    return out


# ----------------------------------------------------------------------------------------------
# comparison of laws
# ----------------------------------------------------------------------------------------------
def law_ratios(law: NormalLaw, reference: NormalLaw, pressures) -> Dict[str, np.ndarray]:
    """Ratios law/reference over a load range, at equal separation and at equal load.

    Args:
        law, reference: the two laws (e.g. statistical and BEM).
        pressures: (n,) mean pressures [MPa] > 0 (the load range).

    Returns:
        dict of (n,) arrays: ``h`` (reference separation at each load [mm]), ``p_at_h``,
        ``k_at_h``, ``a_at_h`` (ratios at the reference's separation), ``k_at_p``, ``a_at_p``
        (ratios at equal load), ``dh_at_p`` (law's minus reference's separation at equal
        load [mm]).
    """
    pr = np.asarray(pressures, float)
    if not np.all(np.isfinite(pr) & (pr > 0)):
        raise ValueError("pressures must be finite and > 0 MPa")
    h = reference.separation_for_pressure(pr)
    pr_r, kr_r, ar_r = reference.evaluate(h)
    pl, kl, al = law.evaluate(h)
    hl = law.separation_for_pressure(pr)
    _, kl2, al2 = law.evaluate(hl)
    with np.errstate(divide="ignore", invalid="ignore"):
        return {"h": h, "p_at_h": pl / pr_r, "k_at_h": kl / kr_r, "a_at_h": al / ar_r,
                "k_at_p": kl2 / kr_r, "a_at_p": al2 / ar_r, "dh_at_p": hl - h}


def agreement_range(law: NormalLaw, reference: NormalLaw, pressures, tol: float = 0.1,
                    quantities: Sequence[str] = ("p_at_h", "k_at_p", "a_at_p")):
    """Load range over which ``law`` agrees with ``reference`` within ``tol``.

    Args:
        law, reference, pressures: as in :func:`law_ratios`.
        tol: largest accepted relative deviation of every ratio in ``quantities`` [-].
        quantities: keys of :func:`law_ratios` (ratios) that must agree.

    Returns:
        (p_lo, p_hi) [MPa], the widest contiguous run of the given pressures where all ratios
        are within 1 +- tol, or None if there is none.
    """
    tol = check_scalar("tol", tol, lo=0.0)
    pr = np.sort(np.asarray(pressures, float).ravel())
    r = law_ratios(law, reference, pr)
    ok = np.ones(pr.size, bool)
    for q in quantities:
        if q not in r or q in ("h", "dh_at_p"):
            raise ValueError(f"quantity {q!r} is invalid; valid: p_at_h, k_at_h, a_at_h, "
                             "k_at_p, a_at_p")
        ok &= np.abs(r[q] - 1.0) <= tol
    if not ok.any():
        return None
    # widest contiguous run of True: starts and ends from the edges of the padded mask
    edges = np.diff(np.concatenate([[0], ok.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    j = int(np.argmax(ends - starts))
    return float(pr[starts[j]]), float(pr[ends[j] - 1])


def resolution_check(z, dx: float, dy: Optional[float] = None, *, E_star: float,
                     nu: float = 0.3, pressures=None, factor: int = 2, **kwargs) -> dict:
    """How much the BEM law of a measured map depends on its sampling step.

    A profilometer map carries roughness down to its sampling step, so its BEM law cannot be
    refined; it can be *coarsened*. This solves the map and the map sub-sampled by ``factor``
    (every factor-th pixel) at the same pressures and compares the laws at equal separation.
    By the grid study of docs/bem.md the error of the full map is roughly the difference found
    here divided by 2-4 (first-order area, faster p and k).

    Args:
        z, dx, dy, E_star, nu, pressures: as in :func:`bem_normal_law`.
        factor: sub-sampling factor, >= 2.
        **kwargs: passed on to :func:`bem_curves` (hardness, backend, boundary, tol, cache...).

    Returns:
        dict with the max relative differences ``p``, ``k``, ``a`` (equal separation) over the
        load range, and both laws (``"fine"``, ``"coarse"``: :class:`BEMLaw`).
    """
    factor = int(check_scalar("factor", factor, lo=2.0, lo_open=False, hi=64.0))
    z = np.asarray(z, dtype=float)
    dy = dx if dy is None else dy
    if pressures is None:
        _, diag = check_height_map(z, dx, dy, boundary=kwargs.get("boundary", "periodic"))
        pressures = default_pressures(E_star, diag.rms_slope, kwargs.get("hardness"))
    kwargs.setdefault("tangential", False)
    fine = law_from_curves(bem_curves(z, dx, dy, E_star=E_star, nu=nu, pressures=pressures,
                                      **kwargs))
    coarse = law_from_curves(bem_curves(np.ascontiguousarray(z[::factor, ::factor]),
                                        dx * factor, dy * factor, E_star=E_star, nu=nu,
                                        pressures=pressures, **kwargs))
    h = fine.separation
    inside = (h >= coarse.normal.h_min) & (h <= coarse.normal.h_table_end)
    p, k, a = coarse.normal.evaluate(h[inside])
    return {"p": float(np.max(np.abs(p / fine.pressure[inside] - 1))),
            "k": float(np.max(np.abs(k / fine.stiffness[inside] - 1))),
            "a": float(np.max(np.abs(a / fine.area_fraction[inside] - 1))),
            "fine": fine, "coarse": coarse, "factor": factor}
