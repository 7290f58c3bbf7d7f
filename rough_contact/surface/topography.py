"""Measured surfaces in: height maps, files, detrending, windows, principal axes, validity advice.

A measured (or synthetic) height map becomes the spectral moments the micro-model needs:

    read (npy / text grid / xyz / instrument files) -> HeightMap -> detrend -> window ->
    FFT moments m00 ... m04 incl. the mixed ones in the map axes (MomentTensor) ->
    rotation to the principal (grain) axes -> SpectralMoments + validity advice

Conventions.
* :class:`HeightMap` holds ``heights`` of shape **(ny, nx)**: row j is y = j dy, column i is
  x = i dx (image layout: the first index runs along y). Heights and spacings share one length
  ``unit`` ("nm", "um", "mm" or "m"); readers convert a different height unit on loading.
* Spectral moments follow :mod:`rough_contact.surface`: angular wavenumbers,
  ``m_pq = integral Phi kx^p ky^q``, so ``m20 = <zx^2>``, ``m40 = <zxx^2>`` (Appendix A).
* Grain angle: the direction of the principal x axis (smallest mean-square slope, the paper's
  grinding direction) measured from the map's x axis towards its y axis, in degrees in
  (-90, 90]. Pass the same direction to the FE layer as ``grain_direction``.

Instrument formats (.x3p, .sur, .opd, .di, .nc, ... about 30) are read through the optional
package SurfaceTopography (``pip install 'rough_contact[topography]'``; imported only when such
a file is read, it brings mpi4py along, which this module otherwise never imports).

Pure module: numpy and scipy only (no dolfinx, ufl, petsc4py, basix, mpi4py, gmsh).
Units: lengths in the map's unit; moments returned as :class:`SpectralMoments` /
:class:`MomentTensor`, stored in mm like the rest of the package.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Protocol, Tuple, Union

import numpy as np

from .moments import (ANISOTROPY_WARN_RATIO, WINDOWS, MomentTensor, SpectralMoments,
                      moment_tensor_from_height_map)
from ..validation import check_scalar

__all__ = ["HeightMap", "LENGTH_UNITS", "MIN_PIXELS", "DETRENDS", "detrend",
           "MAX_PLAUSIBLE_RMS_SLOPE", "MIN_PLAUSIBLE_CURVATURE_RADIUS", "check_units_plausible",
           "PowerSpectrum", "AnisotropicGaussianPSD", "synthetic_height_map",
           "ModelAdvice", "SurfaceAnalysis", "analyze", "model_advice",
           "read_height_map", "write_height_map", "read_npy", "write_npy", "read_text_grid",
           "write_text_grid", "read_xyz", "write_xyz", "read_instrument"]

# length unit -> mm
LENGTH_UNITS = {"nm": 1e-6, "um": 1e-3, "mm": 1.0, "m": 1e3}
# Fewer pixels per side than this leave too few wavenumbers for 4th-order moments (and for the
# Hann window's correction, which assumes the spectrum is much wider than one bin).
MIN_PIXELS = 16
DETRENDS = ("none", "mean", "plane", "curvature")
# slope and curvature principal directions further apart than this: not orthotropic
ORTHOTROPY_WARN_DEG = 5.0
# coordinates of an xyz file must lie within this fraction of a step of a uniform grid
XYZ_GRID_TOL = 1e-3
# Plausibility of the stated units (read_* functions; docs/measured_surfaces.md, "Units").
# rms slope (per axis, after removing the mean plane) above which a map is refused: measured
# engineering surfaces have rms slopes of about 0.01-0.3 (ground, turned, milled, blasted) and
# stylus (60-90 deg cone) and optical instruments (numerical aperture <= 0.95) cannot follow
# flanks much steeper than 45 deg, i.e. slope 1; larger values almost always mean mixed units.
MAX_PLAUSIBLE_RMS_SLOPE = 1.0
# rms curvature radius [mm] below which a map is refused: 1 nm, a few atomic spacings and below
# the radius of the sharpest probe tips (AFM 2-10 nm, stylus >= 0.1 um)
MIN_PLAUSIBLE_CURVATURE_RADIUS = 1e-6
# unit spellings of instrument files (SurfaceTopography) -> (our unit, factor)
_UNIT_ALIASES = {"nm": ("nm", 1.0), "um": ("um", 1.0), "µm": ("um", 1.0), "μm": ("um", 1.0),
                 "mm": ("mm", 1.0), "m": ("m", 1.0), "Å": ("nm", 0.1), "A": ("nm", 0.1),
                 "pm": ("nm", 1e-3), "cm": ("mm", 10.0)}

PathLike = Union[str, Path]


def _check_unit(unit, name: str = "unit") -> str:
    if unit not in LENGTH_UNITS:
        raise ValueError(f"{name} = {unit!r} is invalid: valid length units are "
                         f"{sorted(LENGTH_UNITS)}")
    return unit


# ---------------------------------------------------------------------------------------------
# the height map
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class HeightMap:
    """A sampled height map on a uniform grid.

    Args:
        heights: (ny, nx) heights [unit]; row j at y = j dy, column i at x = i dx. Finite;
            at least ``MIN_PIXELS`` pixels along each side. Stored as a read-only float copy.
        dx: pixel spacing along x (columns) [unit], > 0.
        dy: pixel spacing along y (rows) [unit], > 0.
        unit: length unit of heights and spacings: "nm", "um", "mm" or "m".

    Raises:
        ValueError: not 2D, too few pixels, non-finite heights (the error says how many and
            where), non-positive spacings, unknown unit.
    """

    heights: np.ndarray
    dx: float
    dy: float
    unit: str = "um"

    def __post_init__(self):
        _check_unit(self.unit)
        z = np.array(self.heights, dtype=float)          # a copy: the map owns its data
        if z.ndim != 2:
            raise ValueError(f"heights.shape = {z.shape} is invalid: a 2D array (ny, nx) is "
                             "needed")
        if min(z.shape) < MIN_PIXELS:
            raise ValueError(f"heights.shape = {z.shape} (ny, nx) is too small: each side needs "
                             f">= {MIN_PIXELS} pixels for 4th-order spectral moments")
        bad = ~np.isfinite(z)
        if bad.any():
            rows, cols = np.nonzero(bad)
            shown = ", ".join(f"(row {r}, col {c})" for r, c in zip(rows[:5], cols[:5]))
            more = " ..." if rows.size > 5 else ""
            raise ValueError(
                f"heights contain {rows.size} non-finite values (NaN/inf) of {z.size} pixels, at "
                f"{shown}{more} (x = col dx, y = row dy): fill or crop them before analysing "
                "the map")
        dx = check_scalar("dx", self.dx, lo=0.0, unit=self.unit)
        dy = check_scalar("dy", self.dy, lo=0.0, unit=self.unit)
        z.setflags(write=False)
        object.__setattr__(self, "heights", z)
        object.__setattr__(self, "dx", dx)
        object.__setattr__(self, "dy", dy)

    @property
    def shape(self) -> Tuple[int, int]:
        """(ny, nx) pixels."""
        return self.heights.shape

    @property
    def size(self) -> Tuple[float, float]:
        """(Lx, Ly) = (nx dx, ny dy), the period of the map [unit]."""
        ny, nx = self.heights.shape
        return nx * self.dx, ny * self.dy

    @property
    def x(self) -> np.ndarray:
        """(nx,) column coordinates [unit]."""
        return np.arange(self.heights.shape[1]) * self.dx

    @property
    def y(self) -> np.ndarray:
        """(ny,) row coordinates [unit]."""
        return np.arange(self.heights.shape[0]) * self.dy

    @property
    def rms(self) -> float:
        """RMS height about the mean [unit]."""
        return float(np.std(self.heights))

    def to_unit(self, unit: str) -> "HeightMap":
        """The same map in another length unit."""
        f = LENGTH_UNITS[self.unit] / LENGTH_UNITS[_check_unit(unit)]
        return HeightMap(self.heights * f, self.dx * f, self.dy * f, unit)

    def moments(self, window: str = "none") -> MomentTensor:
        """FFT moments of orders 0, 2, 4 in the map axes (mean removed; no detrending).

        Args:
            window: "none" (periodic map) or "hann" (with the moment correction of
                :func:`rough_contact.surface.moment_tensor_from_height_map`).
        """
        su = LENGTH_UNITS[self.unit]
        # SpectralMoments/MomentTensor take um, mm or m: hand over mm
        return moment_tensor_from_height_map(self.heights.T * su, self.dx * su, self.dy * su,
                                             unit="mm", window=window)


# ---------------------------------------------------------------------------------------------
# detrending
# ---------------------------------------------------------------------------------------------
def detrend(hm: HeightMap, mode: str = "plane") -> HeightMap:
    """Remove the least-squares mean, plane or quadratic surface (curvature) from a map.

    Args:
        hm: the map.
        mode: "none", "mean", "plane" (a + b x + c y) or "curvature" (plane + d x^2 + e x y +
            f y^2, e.g. the form of a cylindrical or spherical part).
    Returns:
        A new HeightMap with the residual heights (same grid and unit). A plane is removed
        exactly by "plane", a paraboloid exactly by "curvature" (to round-off).
    """
    if mode not in DETRENDS:
        raise ValueError(f"detrend mode = {mode!r} is invalid: valid modes are {list(DETRENDS)}")
    z = hm.heights
    if mode == "none":
        return hm
    if mode == "mean":
        return HeightMap(z - z.mean(), hm.dx, hm.dy, hm.unit)
    ny, nx = z.shape
    # coordinates scaled to [-1, 1]: a well-conditioned least-squares problem
    u = np.linspace(-1.0, 1.0, nx)[None, :]
    v = np.linspace(-1.0, 1.0, ny)[:, None]
    u, v = np.broadcast_arrays(u, v)
    cols = [np.ones_like(u), u, v]
    if mode == "curvature":
        cols += [u * u, u * v, v * v]
    A = np.stack([c.ravel() for c in cols], axis=1)          # (ny nx, 3 or 6)
    coef, *_ = np.linalg.lstsq(A, z.ravel(), rcond=None)
    return HeightMap(z - (A @ coef).reshape(z.shape), hm.dx, hm.dy, hm.unit)


_detrend = detrend          # analyze() takes a parameter of that name


# ---------------------------------------------------------------------------------------------
# power spectra and synthetic maps
# ---------------------------------------------------------------------------------------------
class PowerSpectrum(Protocol):
    """A 2D power spectral density Phi(kx, ky) over angular wavenumbers.

    Normalised so that ``m00 = integral Phi dkx dky`` [unit^2]; ``kx, ky`` [rad/unit]
    broadcastable arrays; returns Phi >= 0 [unit^4]. A real surface has Phi(k) = Phi(-k).
    """

    def __call__(self, kx: np.ndarray, ky: np.ndarray) -> np.ndarray: ...


@dataclass(frozen=True)
class AnisotropicGaussianPSD:
    """Sum of anisotropic Gaussian spectra sharing one grain direction; closed-form moments.

    ``Phi(k) = m00 sum_i w_i / (2 pi a_i b_i) exp(-(k1^2/a_i^2 + k2^2/b_i^2)/2)``, with
    k1 = kx cos(theta) + ky sin(theta) along the grain and k2 across it. In the grain axes
    ``m20 = m00 sum w a^2``, ``m02 = m00 sum w b^2``, ``m40 = 3 m00 sum w a^4``,
    ``m04 = 3 m00 sum w b^4``, ``m22 = m00 sum w a^2 b^2``, m11 = m31 = m13 = 0 (orthotropic);
    in the map axes they follow by rotation (:meth:`moments`). One component has bandwidths
    alpha = m00 m40/m20^2 = 3; two reach any alpha >= 3 (:meth:`from_moments`).

    Args:
        m00: height variance [unit^2].
        components: ((w, a, b), ...) weights (> 0, summing to 1) and the standard deviations of
            the spectrum along (a) and across (b) the grain [rad/unit].
        angle_deg: grain direction from the map's x axis towards y [deg].
        unit: length unit ("nm", "um", "mm", "m").
    """

    m00: float
    components: Tuple[Tuple[float, float, float], ...]
    angle_deg: float = 0.0
    unit: str = "um"

    def __post_init__(self):
        _check_unit(self.unit)
        check_scalar("m00", self.m00, lo=0.0, unit=f"{self.unit}^2")
        check_scalar("angle_deg", self.angle_deg, unit="deg")
        comps = tuple(tuple(float(v) for v in c) for c in self.components)
        if not comps or any(len(c) != 3 for c in comps):
            raise ValueError(f"components = {self.components!r} is invalid: give one or more "
                             "(weight, a, b) triples")
        for w, a, b in comps:
            check_scalar("component weight", w, lo=0.0, hi=1.0, hi_open=False)
            check_scalar("component a", a, lo=0.0, unit=f"rad/{self.unit}")
            check_scalar("component b", b, lo=0.0, unit=f"rad/{self.unit}")
        total = sum(c[0] for c in comps)
        if abs(total - 1.0) > 1e-12:
            raise ValueError(f"component weights sum to {total!r}: they must sum to 1")
        object.__setattr__(self, "components", comps)

    @classmethod
    def from_moments(cls, m00: float, m20: float, m02: float, m40: float, m04: float,
                     angle_deg: float = 0.0, unit: str = "um") -> "AnisotropicGaussianPSD":
        """Two Gaussian components matching five principal-axis moments exactly.

        With A = m20/m00 and d^2 = m40/(3 m00) - A^2 (>= 0: alpha1 >= 3), weights w and 1 - w,
        a^2 = A (1 + sqrt((alpha1/3 - 1)(1 - w)/w)) and A (1 - sqrt((alpha1/3 - 1) w/(1 - w)))
        reproduce m20 and m40 (likewise b from m02, m04); w = 1.5/max(alpha1, alpha2) keeps
        both squares positive (w < 3/alpha).

        Args: moments in the grain axes in ``unit`` (m00 unit^2, m20, m02 [-], m40, m04
        unit^-2), the grain angle [deg] and unit. Raises ValueError if alpha1 or alpha2 < 3
        (no Gaussian mixture has a bandwidth below that of a single Gaussian).
        """
        m00 = check_scalar("m00", m00, lo=0.0)
        A1, A2 = check_scalar("m20", m20, lo=0.0) / m00, check_scalar("m02", m02, lo=0.0) / m00
        al1 = m00 * check_scalar("m40", m40, lo=0.0) / m20**2
        al2 = m00 * check_scalar("m04", m04, lo=0.0) / m02**2
        for name, al in (("alpha1 = m00 m40/m20^2", al1), ("alpha2 = m00 m04/m02^2", al2)):
            if al < 3.0 * (1.0 - 1e-12):
                raise ValueError(f"{name} = {al:.6g} is invalid for a Gaussian-mixture "
                                 "spectrum: it must be >= 3")
        w = 0.5 if max(al1, al2) <= 3.0 else 1.5 / max(al1, al2)

        def pair(A, al):
            g = max(al / 3.0 - 1.0, 0.0)
            return (math.sqrt(A * (1.0 + math.sqrt(g * (1.0 - w) / w))),
                    math.sqrt(A * (1.0 - math.sqrt(g * w / (1.0 - w)))))

        (a1, a2), (b1, b2) = pair(A1, al1), pair(A2, al2)
        return cls(m00, ((w, a1, b1), (1.0 - w, a2, b2)), angle_deg, unit)

    def __call__(self, kx, ky) -> np.ndarray:
        th = math.radians(self.angle_deg)
        kx, ky = np.asarray(kx, float), np.asarray(ky, float)
        k1 = kx * math.cos(th) + ky * math.sin(th)
        k2 = -kx * math.sin(th) + ky * math.cos(th)
        out = 0.0
        for w, a, b in self.components:
            out = out + w / (2 * math.pi * a * b) * np.exp(-0.5 * ((k1 / a) ** 2 + (k2 / b) ** 2))
        return self.m00 * out

    def principal_moments(self) -> MomentTensor:
        """Closed-form moments in the grain axes (stored in mm)."""
        s = {"m00": 1.0, "m20": 0.0, "m02": 0.0, "m40": 0.0, "m04": 0.0, "m22": 0.0}
        for w, a, b in self.components:
            s["m20"] += w * a**2
            s["m02"] += w * b**2
            s["m40"] += 3 * w * a**4
            s["m04"] += 3 * w * b**4
            s["m22"] += w * a**2 * b**2
        L = LENGTH_UNITS[self.unit]
        m = {k: self.m00 * v for k, v in s.items()}
        # MomentTensor takes um/mm/m: convert to mm here
        return MomentTensor(m["m00"] * L**2, m["m20"], 0.0, m["m02"], m["m40"] / L**2, 0.0,
                            m["m22"] / L**2, 0.0, m["m04"] / L**2, unit="mm")

    def moments(self) -> MomentTensor:
        """Closed-form moments in the map axes (the grain axes turned by -angle)."""
        return self.principal_moments().rotated(-math.radians(self.angle_deg))


def synthetic_height_map(psd: PowerSpectrum, shape: Tuple[int, int], size: Tuple[float, float],
                         seed: Optional[int] = None, unit: str = "um",
                         random_amplitude: bool = False) -> HeightMap:
    """A periodic Gaussian random surface with a given 2D power spectrum (random phases).

    Fourier coefficients ``Z_k = N sqrt(Phi(k) dkx dky) exp(i phi_k)``, N = nx ny, with phases
    phi_k uniform and Hermitian (those of the FFT of white noise), Z_0 = 0, then z = IFFT(Z).
    The discrete spectrum of the map is then exactly ``Phi(k) dkx dky`` at every wavenumber, so
    its FFT moments equal the Riemann sums of the analytic ones (no sampling scatter); heights
    are Gaussian by the central limit theorem over the many modes. ``random_amplitude=True``
    draws Rayleigh amplitudes as well (a Gaussian random field sample, moments scatter).
    Phi is symmetrised, (Phi(k) + Phi(-k))/2, as the heights are real.

    Args:
        psd: Phi(kx, ky) over angular wavenumbers [rad/unit], normalised to m00 = integral Phi.
        shape: (ny, nx) pixels (array order), each >= MIN_PIXELS.
        size: (Ly, Lx) physical size (array order) [unit]; dx = Lx/nx, dy = Ly/ny.
        seed: seed of numpy's default generator (None: fresh entropy).
        unit: length unit of size and of the heights.
        random_amplitude: also randomise the amplitudes (see above).
    Returns:
        HeightMap of the given shape, mean zero.
    """
    _check_unit(unit)
    try:
        ny, nx = (int(v) for v in shape)
        Ly, Lx = (float(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"shape = {shape!r} and size = {size!r} must each be two numbers "
                         "(ny, nx) and (Ly, Lx)") from None
    if min(nx, ny) < MIN_PIXELS:
        raise ValueError(f"shape = {shape!r} is too small: each side needs >= {MIN_PIXELS} pixels")
    Lx = check_scalar("Lx", Lx, lo=0.0, unit=unit)
    Ly = check_scalar("Ly", Ly, lo=0.0, unit=unit)
    dx, dy = Lx / nx, Ly / ny
    kx = 2 * np.pi * np.fft.fftfreq(nx, d=dx)[None, :]
    ky = 2 * np.pi * np.fft.fftfreq(ny, d=dy)[:, None]
    phi = 0.5 * (np.asarray(psd(kx, ky), float) + np.asarray(psd(-kx, -ky), float))
    phi = np.broadcast_to(phi, (ny, nx))
    if not np.all(np.isfinite(phi)) or np.any(phi < 0):
        raise ValueError("psd returned non-finite or negative values: Phi must be finite and >= 0")
    rng = np.random.default_rng(seed)
    W = np.fft.fft2(rng.standard_normal((ny, nx)))
    if random_amplitude:
        amp = W / math.sqrt(nx * ny)          # E|amp|^2 = 1, Hermitian
    else:
        mag = np.abs(W)
        amp = np.divide(W, mag, out=np.ones_like(W), where=mag > 0)
    Z = (nx * ny) * np.sqrt(phi * (2 * np.pi / Lx) * (2 * np.pi / Ly)) * amp
    Z[0, 0] = 0.0
    return HeightMap(np.fft.ifft2(Z).real, dx, dy, unit)


# ---------------------------------------------------------------------------------------------
# analysis: moments, principal axes, validity advice
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ModelAdvice:
    """Which normal law fits a surface (strongly anisotropic model or its GW equivalent).

    Attributes:
        curvature_ratio: m04/m40 in the grain axes [-].
        misalignment_deg: angle between the slope and the curvature principal directions [deg].
        anisotropic_valid: m04/m40 >= ANISOTROPY_WARN_RATIO and the principal directions agree
            within ORTHOTROPY_WARN_DEG.
        recommended: "anisotropic" (NormalLaw.elastic / elasto_plastic) or
            "greenwood_williamson" (NormalLaw.greenwood_williamson, McCool's equivalent).
        message: the advice as a sentence.
    """

    curvature_ratio: float
    misalignment_deg: float
    anisotropic_valid: bool
    recommended: str
    message: str


def model_advice(principal: MomentTensor, misalignment_deg: float = 0.0) -> ModelAdvice:
    """Advice on the model for moments in the grain axes (see :class:`ModelAdvice`)."""
    ratio = principal.m04 / principal.m40
    mis = abs(float(misalignment_deg))
    notes = []
    if ratio < ANISOTROPY_WARN_RATIO:
        notes.append(
            f"m04/m40 = {ratio:.3g} < {ANISOTROPY_WARN_RATIO:g}: the surface is not strongly "
            "anisotropic, outside the validity of the Bush-Gibson-Keogh model (it assumes "
            "m04/m40 >> 1; the paper's surfaces have 100 and 6561)")
    if mis > ORTHOTROPY_WARN_DEG:
        notes.append(
            f"the slope and curvature principal directions differ by {mis:.2g} deg "
            f"(> {ORTHOTROPY_WARN_DEG:g}): the surface is not orthotropic (m11 = m31 = m13 = 0 "
            "in one frame), which the anisotropic model assumes")
    if notes:
        msg = ("; ".join(notes) + ". McCool's equivalent Greenwood-Williamson model "
               "(NormalLaw.greenwood_williamson), built from the geometric means of the moments, "
               "fits such nearly isotropic surfaces better.")
        return ModelAdvice(ratio, mis, False, "greenwood_williamson", msg)
    msg = (f"m04/m40 = {ratio:.3g} >= {ANISOTROPY_WARN_RATIO:g} and the principal directions "
           f"agree within {mis:.2g} deg: the strongly anisotropic model (NormalLaw.elastic / "
           "elasto_plastic) applies with x along the grain.")
    return ModelAdvice(ratio, mis, True, "anisotropic", msg)


@dataclass(frozen=True)
class SurfaceAnalysis:
    """Result of :func:`analyze` (moments stored in mm, like the rest of the package).

    Attributes:
        map_moments: moments of orders 0, 2, 4 in the map axes.
        principal_moments: the same in the grain axes (m11 = 0).
        grain_angle_deg: grain direction (principal x) from the map's x axis towards y [deg],
            in (-90, 90]: the ``grain_direction`` for the FE layer is (cos, sin) of it.
        curvature_grain_angle_deg: direction of the smallest mean-square curvature [deg].
        spectral_moments: the paper's five moments in the grain axes (x along the grain).
        advice: which normal law fits (warned about when the anisotropic model does not).
        detrend, window: the processing applied.
    """

    map_moments: MomentTensor
    principal_moments: MomentTensor
    grain_angle_deg: float
    curvature_grain_angle_deg: float
    spectral_moments: SpectralMoments
    advice: ModelAdvice
    detrend: str
    window: str

    @property
    def grain_direction(self) -> Tuple[float, float]:
        """Unit vector of the grain in the map axes (x, y)."""
        t = math.radians(self.grain_angle_deg)
        return math.cos(t), math.sin(t)


def _angle_difference_deg(a: float, b: float) -> float:
    """Smallest difference of two axis directions [deg] (modulo 180)."""
    d = math.remainder(a - b, 180.0)
    return abs(d)


def analyze(hm: HeightMap, detrend: str = "plane", window: str = "hann") -> SurfaceAnalysis:
    """Spectral moments of a height map in its principal (grain) axes, with validity advice.

    Steps: :func:`detrend` (``detrend``), FFT moments of orders 0, 2, 4 including the mixed
    ones with the window's moment correction (``window``; see
    :func:`rough_contact.surface.moment_tensor_from_height_map`), rotation to the axes in which
    m11 = 0 with x along the smaller slopes (the grain), :class:`SpectralMoments` there. Warns
    (UserWarning) when the strongly anisotropic model does not apply and says which law fits.

    Args:
        hm: the height map.
        detrend: "none", "mean", "plane" (default) or "curvature".
        window: "hann" (default: for measured, non-periodic maps) or "none" (periodic maps,
            e.g. synthetic ones; exact there).
    Returns:
        SurfaceAnalysis.
    Raises:
        ValueError: bad arguments, or moments that do not describe a valid surface (e.g. a
            map too small for the window correction, or mu <= 0 in the grain axes).
    """
    if window not in WINDOWS:
        raise ValueError(f"window = {window!r} is invalid: valid windows are {list(WINDOWS)}")
    flat = _detrend(hm, detrend)
    try:
        mt = flat.moments(window=window)
    except ValueError as e:
        raise ValueError(f"the moments of this {hm.shape} map after detrend = {detrend!r}, "
                         f"window = {window!r} are invalid ({e}): the map resolves too few "
                         "wavelengths; try window='none' or a larger map") from None
    principal, angle = mt.principal()
    grain = math.degrees(angle)
    curv = math.degrees(mt.curvature_grain_angle())
    advice = model_advice(principal, _angle_difference_deg(grain, curv))
    with warnings.catch_warnings():
        # SpectralMoments' own anisotropy warning is replaced by the advice below
        warnings.filterwarnings("ignore", message=r"m04/m40 = ", category=UserWarning)
        sm = principal.spectral_moments()
    if not advice.anisotropic_valid:
        warnings.warn(advice.message, UserWarning, stacklevel=2)
    return SurfaceAnalysis(mt, principal, grain, curv, sm, advice, detrend, window)


# ---------------------------------------------------------------------------------------------
# files: numpy, text grids, xyz point lists, instrument formats
# ---------------------------------------------------------------------------------------------
def _merge(name: str, given, found, path: PathLike):
    """A metadata value from the caller or the file; both given and different is an error."""
    if given is not None and found is not None and given != found:
        raise ValueError(f"{name} = {given!r} given, but {path} says {name} = {found!r}")
    value = given if given is not None else found
    if value is None:
        raise ValueError(f"{name} is not given and {path} does not say it: pass {name}=...")
    return value


def _spacings(dx, dy, file_dx, file_dy, path):
    """dx, dy from the caller and/or the file; dy defaults to dx when neither gives it."""
    dx = _merge("dx", None if dx is None else float(dx), file_dx, path)
    if dy is None and file_dy is None:
        return dx, dx
    return dx, _merge("dy", None if dy is None else float(dy), file_dy, path)


def _finish(z, dx, dy, unit, height_unit, path, allow_steep=False) -> HeightMap:
    unit = _check_unit(unit)
    if height_unit is not None:
        z = np.asarray(z, float) * (LENGTH_UNITS[_check_unit(height_unit, "height_unit")]
                                    / LENGTH_UNITS[unit])
    try:
        hm = HeightMap(z, float(dx), float(dy), unit)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None
    if not allow_steep:
        check_units_plausible(hm, height_unit=height_unit, source=path)
    return hm


def _larger_units(unit: str):
    return [u for u in LENGTH_UNITS if LENGTH_UNITS[u] > LENGTH_UNITS[unit]]


def _smaller_units(unit: str):
    return [u for u in LENGTH_UNITS if LENGTH_UNITS[u] < LENGTH_UNITS[unit]][::-1]


def check_units_plausible(hm: HeightMap, height_unit: Optional[str] = None,
                          source: Optional[PathLike] = None) -> Tuple[float, float, float, float]:
    """Refuse a map whose slopes or curvatures are implausible for its stated units.

    The mean plane is removed; rms slopes and rms curvatures along x and y are taken by central
    differences inside the map. A rms slope above ``MAX_PLAUSIBLE_RMS_SLOPE`` (45 deg) almost
    always means that the lateral unit is larger, or the height unit smaller, than stated
    (x, y in mm read as um multiplies every slope by 1000); a rms curvature radius below
    ``MIN_PLAUSIBLE_CURVATURE_RADIUS`` (1 nm) means every length is in a larger unit than
    stated. A consistent error of all lengths within these bounds cannot be detected. The
    readers call this unless ``allow_steep=True`` (a genuinely steep surface).

    Args:
        hm: the map as read.
        height_unit: the height unit stated to the reader (None: ``hm.unit``), for the message.
        source: file name for the message.
    Returns:
        (rms slope x, rms slope y [-], rms curvature x, rms curvature y [1/unit]).
    Raises:
        ValueError: naming the quantity, its value, the plausible range, the likely unit
            mix-up and the override.
    """
    z = detrend(hm, "plane").heights
    sx = float(np.sqrt(np.mean(((z[1:-1, 2:] - z[1:-1, :-2]) / (2 * hm.dx)) ** 2)))
    sy = float(np.sqrt(np.mean(((z[2:, 1:-1] - z[:-2, 1:-1]) / (2 * hm.dy)) ** 2)))
    cx = float(np.sqrt(np.mean(((z[1:-1, 2:] - 2 * z[1:-1, 1:-1] + z[1:-1, :-2]) / hm.dx**2) ** 2)))
    cy = float(np.sqrt(np.mean(((z[2:, 1:-1] - 2 * z[1:-1, 1:-1] + z[:-2, 1:-1]) / hm.dy**2) ** 2)))
    hu = hm.unit if height_unit is None else height_unit
    where = f"{source}: " if source is not None else ""
    override = ("if the surface really is this steep, pass allow_steep=True to the reader "
                "(see docs/measured_surfaces.md, 'Units')")
    slope = max(sx, sy)
    if slope > MAX_PLAUSIBLE_RMS_SLOPE:
        axis = "x" if sx >= sy else "y"
        guesses = []
        for u in _larger_units(hm.unit):
            f = LENGTH_UNITS[u] / LENGTH_UNITS[hm.unit]
            if slope / f <= MAX_PLAUSIBLE_RMS_SLOPE:
                guesses.append(f"are the lateral units {u} rather than {hm.unit} (slope "
                               f"{slope / f:.3g})")
                break
        for u in _smaller_units(hu):
            f = LENGTH_UNITS[hu] / LENGTH_UNITS[u]
            if slope / f <= MAX_PLAUSIBLE_RMS_SLOPE:
                guesses.append(f"are the heights in {u} rather than {hu} (slope "
                               f"{slope / f:.3g})")
                break
        raise ValueError(
            f"{where}rms slope {slope:.3g} rad ({axis}; x: {sx:.3g}, y: {sy:.3g}) is implausible "
            f"for a machined surface (expected < ~{MAX_PLAUSIBLE_RMS_SLOPE:g}, measured "
            f"engineering surfaces 0.01-0.3): " + ("; or ".join(guesses) + "? "
                                                   if guesses else "check the units. ")
            + f"(read with lateral unit {hm.unit!r}, heights in {hu!r}); {override}")
    curv = max(cx, cy) * 1.0 / LENGTH_UNITS[hm.unit]           # 1/mm
    if curv * MIN_PLAUSIBLE_CURVATURE_RADIUS > 1.0:
        axis = "x" if cx >= cy else "y"
        r_nm = 1e6 / curv
        raise ValueError(
            f"{where}rms curvature {max(cx, cy):.3g} 1/{hm.unit} ({axis}), a radius of "
            f"{r_nm:.3g} nm, is implausible (expected radius > "
            f"{MIN_PLAUSIBLE_CURVATURE_RADIUS * 1e6:g} nm, a few atomic spacings): are all "
            f"lengths (lateral unit {hm.unit!r}, heights {hu!r}) in a larger unit than "
            f"stated? {override}")
    return sx, sy, cx, cy


def _sidecar(path: Path) -> Path:
    return path.with_suffix(".json")


def write_npy(hm: HeightMap, path: PathLike) -> Path:
    """Write heights (ny, nx) to ``path`` (.npy) and dx, dy, unit to the sidecar ``.json``."""
    path = Path(path)
    np.save(path, hm.heights)
    _sidecar(path).write_text(json.dumps({"dx": hm.dx, "dy": hm.dy, "unit": hm.unit,
                                          "layout": "heights[row = y, column = x]"}, indent=1))
    return path


def read_npy(path: PathLike, dx: Optional[float] = None, dy: Optional[float] = None,
             unit: Optional[str] = None, height_unit: Optional[str] = None,
             allow_steep: bool = False) -> HeightMap:
    """Read a numpy ``.npy`` array of heights (ny, nx) with the spacing from the caller or from a
    sidecar ``.json`` next to it (keys dx, dy, unit, as :func:`write_npy` writes).

    Args:
        path: the .npy file.
        dx, dy: spacings [unit] (dy defaults to dx); needed when there is no sidecar.
        unit: length unit of the spacings and of the map.
        height_unit: unit of the stored heights if it differs from ``unit``.
        allow_steep: skip :func:`check_units_plausible` (a genuinely steep surface).
    """
    path = Path(path)
    meta = {}
    if _sidecar(path).exists():
        meta = json.loads(_sidecar(path).read_text())
    dx, dy = _spacings(dx, dy, meta.get("dx"), meta.get("dy"), path)
    unit = _merge("unit", unit, meta.get("unit"), path)
    return _finish(np.load(path, allow_pickle=False), dx, dy, unit, height_unit, path,
                   allow_steep)


def _delimiter(line: str) -> Optional[str]:
    for d in (",", ";", "\t"):
        if d in line:
            return d
    return None                                 # whitespace


def _read_table(path: Path, delimiter: Optional[str]):
    """Header ``# key = value`` pairs and the numeric table of a text file."""
    meta, first = {}, None
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                s = line.strip()
                if not s:
                    continue
                if s.startswith("#"):
                    key, sep, val = s[1:].partition("=")
                    if sep:
                        meta[key.strip().lower()] = val.strip()
                    continue
                first = s
                break
    except UnicodeDecodeError as e:
        raise ValueError(f"{path} is not a text file (byte {e.start} is not UTF-8): a "
                         f"'{path.suffix}' height map must be a text table; an "
                         "instrument's binary file is read by read_instrument (through "
                         "SurfaceTopography) under its own suffix") from None
    if first is None:
        raise ValueError(f"{path} holds no data lines")
    delim = _delimiter(first) if delimiter is None else delimiter
    try:
        data = np.loadtxt(path, comments="#", delimiter=delim, ndmin=2)
    except ValueError as e:
        raise ValueError(f"{path}: could not read a numeric table ({e})") from None
    return meta, data


def write_text_grid(hm: HeightMap, path: PathLike, delimiter: str = ",") -> Path:
    """Write the map as a text grid: ``# dx/dy/unit = ...`` header lines, then ny rows of nx
    heights (row j at y = j dy), full precision (round-trips exactly)."""
    path = Path(path)
    header = (f"rough_contact height map: rows y (first row y = 0), columns x\n"
              f"dx = {hm.dx!r}\ndy = {hm.dy!r}\nunit = {hm.unit}")
    np.savetxt(path, hm.heights, fmt="%.17g", delimiter=delimiter, header=header, comments="# ")
    return path


def read_text_grid(path: PathLike, dx: Optional[float] = None, dy: Optional[float] = None,
                   unit: Optional[str] = None, height_unit: Optional[str] = None,
                   delimiter: Optional[str] = None, allow_steep: bool = False) -> HeightMap:
    """Read a text/CSV grid of heights: ny rows (y) of nx values (x).

    Lines starting with ``#`` are comments; ``# dx = ...``, ``# dy = ...``, ``# unit = ...``
    there give the metadata (as :func:`write_text_grid` writes), else pass them. The delimiter is
    detected from the first data line (comma, semicolon, tab, else whitespace). Implausible
    slopes or curvatures for the stated units raise (:func:`check_units_plausible`) unless
    ``allow_steep=True``.
    """
    path = Path(path)
    meta, z = _read_table(path, delimiter)
    try:
        mdx, mdy = (float(meta[k]) if k in meta else None for k in ("dx", "dy"))
    except ValueError:
        raise ValueError(f"{path}: the header's dx = {meta.get('dx')!r} or dy = "
                         f"{meta.get('dy')!r} is not a number") from None
    dx, dy = _spacings(dx, dy, mdx, mdy, path)
    unit = _merge("unit", unit, meta.get("unit"), path)
    return _finish(z, dx, dy, unit, height_unit, path, allow_steep)


def write_xyz(hm: HeightMap, path: PathLike, delimiter: str = " ") -> Path:
    """Write the map as an x y z point list (one pixel per line, x fastest), full precision."""
    path = Path(path)
    ny, nx = hm.shape
    X, Y = np.meshgrid(hm.x, hm.y)
    pts = np.stack([X.ravel(), Y.ravel(), hm.heights.ravel()], axis=1)
    np.savetxt(path, pts, fmt="%.17g", delimiter=delimiter, comments="# ",
               header=f"rough_contact height map: x y z, {nx} x {ny} points\nunit = {hm.unit}")
    return path


def _grid_axis(name: str, c: np.ndarray, path: Path) -> Tuple[np.ndarray, int, float, float]:
    """Indices of coordinates c on a uniform grid, the number of grid lines, start and step."""
    u = np.unique(c)
    if u.size < 2:
        raise ValueError(f"{path}: all {name} coordinates are equal ({float(u[0])!r}): a 2D map needs "
                         f">= {MIN_PIXELS} distinct values along each axis")
    steps = np.diff(u)
    step = float(np.median(steps))
    c0 = float(u[0])
    idx = np.rint((c - c0) / step)
    off = np.abs((c - c0) / step - idx)
    if off.max() > XYZ_GRID_TOL or steps.min() < (1 - XYZ_GRID_TOL) * step:
        j = int(np.argmax(np.abs(steps / step - 1)))
        raise ValueError(
            f"{path}: the {name} coordinates are not uniformly spaced: steps between distinct "
            f"values range from {steps.min():.6g} to {steps.max():.6g} (median {step:.6g}), e.g. "
            f"{float(u[j])!r} -> {float(u[j + 1])!r}; a uniform grid within {XYZ_GRID_TOL:g} of a step is "
            "needed (resample the data first)")
    n = int(idx.max()) + 1
    # the step from the extreme coordinates: least affected by rounding in the file
    return idx.astype(np.intp), n, c0, (float(u[-1]) - c0) / (n - 1)


def read_xyz(path: PathLike, unit: Optional[str] = None, height_unit: Optional[str] = None,
             delimiter: Optional[str] = None, allow_steep: bool = False) -> HeightMap:
    """Read an x y z point list of a map sampled on a uniform grid (any point order).

    The points must form a complete uniform grid: distinct x (and y) values equally spaced to
    within ``XYZ_GRID_TOL`` of a step, every grid node present exactly once. ``# unit = ...``
    in a comment line gives the unit (as :func:`write_xyz` writes), else pass ``unit``;
    ``height_unit`` converts a z column in another unit (e.g. x, y in mm and z in um).
    Implausible slopes or curvatures for the stated units raise
    (:func:`check_units_plausible`) unless ``allow_steep=True``.
    """
    path = Path(path)
    meta, data = _read_table(path, delimiter)
    if data.shape[1] != 3:
        raise ValueError(f"{path}: {data.shape[1]} columns per line; an xyz file has 3 (x y z)")
    x, y, z = data.T
    ix, nx, x0, dx = _grid_axis("x", x, path)
    iy, ny, y0, dy = _grid_axis("y", y, path)
    counts = np.bincount(iy * nx + ix, minlength=nx * ny)
    if np.any(counts != 1):
        missing, dup = int(np.sum(counts == 0)), int(np.sum(counts > 1))
        j = int(np.flatnonzero(counts != 1)[0])
        raise ValueError(f"{path}: the points do not form a complete {nx} x {ny} grid: "
                         f"{missing} nodes missing, {dup} repeated (first at x = "
                         f"{x0 + (j % nx) * dx:.6g}, y = {y0 + (j // nx) * dy:.6g})")
    heights = np.empty((ny, nx))
    heights[iy, ix] = z
    unit = _merge("unit", unit, meta.get("unit"), path)
    return _finish(heights, dx, dy, unit, height_unit, path, allow_steep)


def read_instrument(path: PathLike, unit: Optional[str] = None, channel: Optional[int] = None,
                    allow_steep: bool = False, **surface_topography_kwargs) -> HeightMap:
    """Read an instrument file through SurfaceTopography (optional extra ``topography``).

    About 30 formats (.x3p, .sur, .opd, .opdx, .di, .ibw, .plu, .datx, .nc, ...), detected
    from the file. The map is returned in the file's unit, or converted to ``unit`` if given.

    Args:
        path: the file.
        unit: length unit of the returned map (None: the file's).
        channel: data channel index (None: the format's default).
        allow_steep: skip :func:`check_units_plausible` (a genuinely steep surface).
        **surface_topography_kwargs: passed to ``SurfaceTopography.read_topography`` for files
            lacking metadata, e.g. ``physical_sizes=(Lx, Ly)``, ``unit="um"``,
            ``height_scale_factor``.
    Raises:
        ImportError: SurfaceTopography is not installed (says how to install it).
        ValueError: a line scan (1D), undefined pixels, an unknown unit.
    """
    try:
        from SurfaceTopography import read_topography
    except ImportError:
        raise ImportError(
            f"reading {Path(path).suffix or 'this'} files needs the optional package "
            "SurfaceTopography: pip install 'rough_contact[topography]' (in this repository: "
            "RC_EXTRAS=topography bash run.sh setup); numpy arrays, text grids and xyz lists "
            "are read without it (read_npy, read_text_grid, read_xyz)") from None
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"height map file {path} not found")
    if channel is not None:
        surface_topography_kwargs["channel_index"] = int(channel)
    topo = read_topography(str(path), **surface_topography_kwargs)
    if topo.dim != 2:
        raise ValueError(f"{path} holds a {topo.dim}D scan: a 2D map is needed for the "
                         "anisotropic moments")
    if not getattr(topo, "is_uniform", True):
        raise ValueError(f"{path} holds non-uniformly sampled data: resample it to a uniform "
                         "grid first")
    file_unit = topo.unit
    if file_unit not in _UNIT_ALIASES:
        raise ValueError(f"{path}: length unit {file_unit!r} is not supported; known units are "
                         f"{sorted(_UNIT_ALIASES)} (pass unit=... to SurfaceTopography through "
                         "the keyword arguments if the file has none)")
    ours, factor = _UNIT_ALIASES[file_unit]
    h = topo.heights()
    h = np.ma.filled(h.astype(float), np.nan) if np.ma.isMaskedArray(h) else np.asarray(h, float)
    dx, dy = (float(v) for v in topo.pixel_size)
    # SurfaceTopography stores heights (nx, ny), axis 0 along x: transpose to (ny, nx)
    hm = _finish(h.T * factor, dx * factor, dy * factor, ours, None, path, allow_steep)
    return hm if unit is None else hm.to_unit(unit)


_FORMATS = {".npy": "npy", ".csv": "text", ".txt": "text", ".dat": "text", ".xyz": "xyz"}


def read_height_map(path: PathLike, **kwargs) -> HeightMap:
    """Read a height map, choosing the reader by the file suffix.

    ``.npy`` -> :func:`read_npy`; ``.csv``, ``.txt``, ``.dat`` -> :func:`read_text_grid`;
    ``.xyz`` -> :func:`read_xyz`; anything else -> :func:`read_instrument` (SurfaceTopography).
    Keyword arguments go to that reader. Every reader refuses a map whose rms slope or
    curvature is implausible for the stated units (:func:`check_units_plausible`, e.g. x, y in
    mm read as um); ``allow_steep=True`` accepts a genuinely steep surface.
    """
    kind = _FORMATS.get(Path(path).suffix.lower(), "instrument")
    reader = {"npy": read_npy, "text": read_text_grid, "xyz": read_xyz,
              "instrument": read_instrument}[kind]
    return reader(path, **kwargs)


def write_height_map(hm: HeightMap, path: PathLike) -> Path:
    """Write a height map in the plain format given by the suffix (.npy, .csv/.txt/.dat, .xyz)."""
    kind = _FORMATS.get(Path(path).suffix.lower())
    if kind is None:
        raise ValueError(f"suffix {Path(path).suffix!r} is invalid for writing: valid suffixes are "
                         f"{sorted(_FORMATS)}")
    writer = {"npy": write_npy, "text": write_text_grid, "xyz": write_xyz}[kind]
    return writer(hm, path)
