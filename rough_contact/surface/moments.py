"""Statistics of a strongly anisotropic Gaussian rough surface (paper sections 2 and 5).

The surface is described by five spectral moments (Bush, Gibson & Keogh; eqs 7-18):
``m00`` (height variance), ``m20, m02`` (mean-square slopes along / across the grain, x along
the grain) and ``m40, m04`` (mean-square curvatures). From them follow the bandwidths (10-11),
the summit density (17), the joint summit pdf (18), the mean summit curvature (70), the
summit-height standard deviation (71-72), the summit mean-plane offset (73) and the plasticity
index (69). Misprinted equations are read as stated in ``docs/equations.md`` (see each property).

Units. The whole package works in **mm, N, MPa**. At the API boundary the moments are
accepted in the paper's micrometre convention (``unit="um"``: m00 in um^2, m20/m02
dimensionless, m40/m04 in um^-2) or directly in mm (``unit="mm"``); they are stored in mm
(m00 in mm^2, m40/m04 in mm^-2). Derived quantities are therefore in mm (sigma, delta),
mm^-1 (curvatures) and mm^-2 (summit density). Moduli are in MPa.

Spectral-moment convention (for :func:`moments_from_height_map`). With the PSD
``Phi(kx, ky)`` over *angular* wavenumbers (rad/length), normalised so that
``m00 = <z^2> = integral Phi dkx dky``, the moments are
``m_pq = integral Phi kx^p ky^q dkx dky`` (Appendix A), hence
``m20 = <(dz/dx)^2>``, ``m02 = <(dz/dy)^2>``, ``m40 = <(d2z/dx2)^2>``,
``m04 = <(d2z/dy2)^2>``. If the PSD is written over *cyclic* frequencies f = k/(2 pi)
(cycles/length), the same moments are ``(2 pi)^(p+q) integral Phi_f fx^p fy^q dfx dfy``.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Tuple

import numpy as np

from ..validation import check_scalar

__all__ = ["SpectralMoments", "moments_from_height_map", "psum", "plasticity_index", "MomentTensor",
           "moment_tensor_from_height_map", "MOMENT_ORDERS", "WINDOWS"]

_UNIT_SCALE = {"um": 1.0e-3, "mm": 1.0, "m": 1.0e3}  # length unit -> mm


# m04/m40 below which SpectralMoments warns that the strongly anisotropic model is out of range.
ANISOTROPY_WARN_RATIO = 10.0


@dataclass(frozen=True)
class SpectralMoments:
    """Spectral moments of a strongly anisotropic rough surface, x along the grain.

    Args:
        m00: height variance [unit^2].
        m20: mean-square slope along x (grain) [-].
        m02: mean-square slope along y [-].
        m40: mean-square curvature along x [unit^-2].
        m04: mean-square curvature along y [unit^-2].
        unit: length unit of the given moments: "um" (paper convention, default), "mm" or "m".

    The stored attributes ``m00 ... m04`` are in mm units (m00 mm^2, m40/m04 mm^-2).
    Raises ValueError for non-positive/non-finite moments, an unknown unit, or moments whose
    covariance matrix (8) is not positive definite (mu = 1 - beta1 - beta2 <= 0).
    """

    m00: float
    m20: float
    m02: float
    m40: float
    m04: float
    unit: str = "um"
    # derived, filled in __post_init__
    alpha1: float = field(init=False, repr=False)
    alpha2: float = field(init=False, repr=False)

    def __post_init__(self):
        if self.unit not in _UNIT_SCALE:
            raise ValueError(f"unit = {self.unit!r} is invalid: valid units are {sorted(_UNIT_SCALE)}")
        L = _UNIT_SCALE[self.unit]
        vals = {n: check_scalar(n, getattr(self, n), lo=0.0)
                for n in ("m00", "m20", "m02", "m40", "m04")}
        object.__setattr__(self, "m00", vals["m00"] * L**2)
        object.__setattr__(self, "m20", vals["m20"])
        object.__setattr__(self, "m02", vals["m02"])
        object.__setattr__(self, "m40", vals["m40"] / L**2)
        object.__setattr__(self, "m04", vals["m04"] / L**2)
        object.__setattr__(self, "unit", "mm")
        object.__setattr__(self, "alpha1", self.m00 * self.m40 / self.m20**2)
        object.__setattr__(self, "alpha2", self.m00 * self.m04 / self.m02**2)
        mu = 1.0 - 1.0 / self.alpha1 - 1.0 / self.alpha2
        if not mu > 0.0:
            raise ValueError(
                f"mu = 1 - 1/alpha1 - 1/alpha2 = {mu:.6g} (alpha1 = {self.alpha1:.6g}, "
                f"alpha2 = {self.alpha2:.6g}) is invalid: the covariance (8) requires mu in (0, 1)")
        ratio = self.m04 / self.m40
        if ratio < ANISOTROPY_WARN_RATIO:
            # Principal summit curvatures differ by about sqrt(m04/m40): below ~3 the eccentric
            # elliptic-paraboloid summits of the strongly anisotropic model (x = grain) are no
            # longer a small-error idealisation. The paper's surfaces have 100 and 6561.
            warnings.warn(
                f"m04/m40 = {ratio:.4g} < {ANISOTROPY_WARN_RATIO:g}: the strongly anisotropic "
                "model (Bush, Gibson & Keogh) assumes m04/m40 >> 1 with x along the grain "
                "(paper: 100 and 6561); a nearly isotropic surface, or one with the grain along "
                "y, is outside its validity", UserWarning, stacklevel=3)

    # -- bandwidths (10)-(11) -------------------------------------------------------------
    @property
    def beta1(self) -> float:
        """1/alpha1 = m20^2/(m00 m40) [-], eq (11)."""
        return 1.0 / self.alpha1

    @property
    def beta2(self) -> float:
        """1/alpha2 = m02^2/(m00 m04) [-], eq (11)."""
        return 1.0 / self.alpha2

    @property
    def mu(self) -> float:
        """mu = 1 - beta1 - beta2 in (0, 1), eq (10)."""
        return 1.0 - self.beta1 - self.beta2

    @property
    def rq(self) -> float:
        """RMS height sqrt(m00) [mm]."""
        return math.sqrt(self.m00)

    @property
    def summit_density(self) -> float:
        """Dsum = (1/(2 pi)^2) sqrt(m40 m04/(m20 m02)) [mm^-2], eq (17) (exponent 1/2)."""
        return math.sqrt(self.m40 * self.m04 / (self.m20 * self.m02)) / (2.0 * math.pi) ** 2

    Dsum = summit_density

    @property
    def mean_summit_curvature(self) -> float:
        """kappa_m bar = sqrt(pi/8) (sqrt(m04) + sqrt(m40)) [mm^-1], eq (70)."""
        return math.sqrt(math.pi / 8.0) * (math.sqrt(self.m04) + math.sqrt(self.m40))

    kappa_m = mean_summit_curvature

    @property
    def sigma_c(self) -> float:
        """c = sigma^2/m00 = 1 - (pi/2 - 1)(beta1 + beta2) [-] (corrected reading of (71-72))."""
        return 1.0 - (math.pi / 2.0 - 1.0) * (self.beta1 + self.beta2)

    @property
    def summit_sigma(self) -> float:
        """Standard deviation of summit heights sigma = sqrt(c m00) [mm], eqs (71)-(72)."""
        return math.sqrt(self.sigma_c * self.m00)

    sigma = summit_sigma

    @property
    def delta(self) -> float:
        """Summit mean plane above the surface mean plane, sqrt(pi m00/2)(sqrt b1 + sqrt b2) [mm] (73)."""
        return math.sqrt(math.pi * self.m00 / 2.0) * (math.sqrt(self.beta1) + math.sqrt(self.beta2))

    def separation(self, s):
        """Dimensional separation h = s sqrt(m00) [mm] from s = h/sqrt(m00), eq (23)."""
        return np.asarray(s, dtype=float) * self.rq

    def plasticity_index(self, E_star: float, H: float) -> float:
        """psi = sqrt(sigma kappa_m) E*/H [-], eq (69); E*, H in MPa."""
        return plasticity_index(self, E_star, H)

    def hardness_for_plasticity_index(self, E_star: float, psi: float) -> float:
        """Hardness H [MPa] giving plasticity index psi for this surface and E* (inverse of (69))."""
        E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
        psi = check_scalar("psi", psi, lo=0.0)
        return math.sqrt(self.summit_sigma * self.mean_summit_curvature) * E_star / psi

    def psum(self, w1, w4, w6):
        """Joint summit pdf (18) in the normalised variables (13); see :func:`psum`."""
        return psum(w1, w4, w6, self.beta1, self.beta2)

    def as_um(self) -> dict:
        """The moments in the paper's micrometre convention (dict)."""
        return {"m00": self.m00 * 1e6, "m20": self.m20, "m02": self.m02,
                "m40": self.m40 * 1e-6, "m04": self.m04 * 1e-6}


def plasticity_index(surface: SpectralMoments, E_star: float, H: float) -> float:
    """Plasticity index psi = sqrt(sigma kappa_m) E*/H, eq (69).

    Args:
        surface: the surface statistics.
        E_star: effective modulus (42) [MPa].
        H: hardness [MPa].
    """
    E_star = check_scalar("E_star", E_star, lo=0.0, unit="MPa")
    H = check_scalar("H", H, lo=0.0, unit="MPa")
    return math.sqrt(surface.summit_sigma * surface.mean_summit_curvature) * E_star / H


def psum(w1, w4, w6, beta1: float, beta2: float):
    """Joint pdf of summit height and curvatures, eq (18) as read in ``docs/equations.md``.

    psum = mu^2/sqrt(2 pi) w4 w6 exp(-X/2),
    X = (w1 - sqrt(beta1) w4 - sqrt(beta2) w6)^2 + mu (w4^2 + w6^2),
    on w1 in R, w4 > 0, w6 > 0 (zero elsewhere); it integrates to 1.

    Args:
        w1, w4, w6: normalised height and curvatures (13), broadcastable arrays [-].
        beta1, beta2: inverse bandwidths (11) [-].
    Returns:
        density, broadcast shape [-].
    """
    mu = 1.0 - beta1 - beta2
    if not mu > 0:
        raise ValueError(f"mu = 1 - beta1 - beta2 = {mu!r} is invalid: it must be in (0, 1)")
    w1, w4, w6 = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (w1, w4, w6)))
    X = (w1 - math.sqrt(beta1) * w4 - math.sqrt(beta2) * w6) ** 2 + mu * (w4**2 + w6**2)
    out = mu**2 / math.sqrt(2 * math.pi) * w4 * w6 * np.exp(-0.5 * X)
    return np.where((w4 > 0) & (w6 > 0), out, 0.0)


def _checked_map(z, dx, dy) -> Tuple[np.ndarray, float, float]:
    """A finite 2D height map of at least 3x3 samples and positive steps, or ValueError."""
    z = np.asarray(z, dtype=float)
    if z.ndim != 2 or min(z.shape) < 3:
        raise ValueError(f"z.shape = {z.shape} is invalid: a 2D map of at least 3x3 samples is needed")
    if not np.all(np.isfinite(z)):
        raise ValueError("z contains NaN/inf values: all heights must be finite")
    dx = check_scalar("dx", dx, lo=0.0)
    dy = dx if dy is None else check_scalar("dy", dy, lo=0.0)
    return z, dx, dy


def _wavenumbers(n: int, d: float) -> np.ndarray:
    """Angular wavenumbers of an n-point FFT with step d; the Nyquist bin (n even) is set to 0:
    the derivative of a real signal there is ambiguous."""
    k = 2 * np.pi * np.fft.fftfreq(n, d=d)
    if n % 2 == 0:
        k[n // 2] = 0.0
    return k


def _power_spectrum(z: np.ndarray, dx: float, dy: float):
    """Discrete PSD P (nx, ny), normalised so that sum P = <z^2> (Parseval), and the angular
    wavenumbers kx (nx, 1), ky (1, ny) of a periodic map z (nx, ny), axis 0 along x."""
    nx, ny = z.shape
    P = np.abs(np.fft.fft2(z)) ** 2 / (nx * ny) ** 2
    return P, _wavenumbers(nx, dx)[:, None], _wavenumbers(ny, dy)[None, :]


def moments_from_height_map(z, dx: float, dy: float | None = None, method: str = "fft",
                            unit: str = "um") -> SpectralMoments:
    """Spectral moments m00, m20, m02, m40, m04 of a sampled, periodic height map.

    The map is treated as one period of a statistically homogeneous surface; its mean is
    removed. Convention (see the module docstring): angular wavenumbers, so that
    m20 = <(dz/dx)^2>, m40 = <(d2z/dx2)^2> etc.; with cyclic frequencies each moment would
    carry a factor (2 pi)^(p+q).

    Args:
        z: heights, shape (nx, ny) with axis 0 along x (the grain) [unit].
        dx: sampling step along axis 0 [unit].
        dy: sampling step along axis 1 [unit]; defaults to dx.
        method: "fft" (spectral derivatives: exact for band-limited periodic maps) or
            "fd" (second-order central differences, periodic wrap; biased low for content
            near the Nyquist frequency, like a profilometer's finite sampling interval).
        unit: length unit of z, dx, dy ("um", "mm" or "m").
    Returns:
        SpectralMoments (internally in mm).
    Raises:
        ValueError: for a non-2D or non-finite map, non-positive steps or unknown method.
    """
    if method == "fft":
        # the one FFT moment computation of the package (no window: the map is periodic)
        m = _fft_moments(z, dx, dy, window="none")
        m00, m20, m02, m40, m04 = (m[(0, 0)], m[(2, 0)], m[(0, 2)], m[(4, 0)], m[(0, 4)])
    elif method == "fd":
        z, dx, dy = _checked_map(z, dx, dy)
        z = z - z.mean()
        zx = (np.roll(z, -1, 0) - np.roll(z, 1, 0)) / (2 * dx)
        zy = (np.roll(z, -1, 1) - np.roll(z, 1, 1)) / (2 * dy)
        zxx = (np.roll(z, -1, 0) - 2 * z + np.roll(z, 1, 0)) / dx**2
        zyy = (np.roll(z, -1, 1) - 2 * z + np.roll(z, 1, 1)) / dy**2
        m00 = np.mean(z**2)
        m20, m02 = np.mean(zx**2), np.mean(zy**2)
        m40, m04 = np.mean(zxx**2), np.mean(zyy**2)
    else:
        raise ValueError(f"method = {method!r} is invalid: valid methods are 'fft' and 'fd'")
    return SpectralMoments(m00, m20, m02, m40, m04, unit=unit)


# ---------------------------------------------------------------------------------------------
# Moments in arbitrary axes: the mixed moments, rotation to the principal (grain) axes, windows
# ---------------------------------------------------------------------------------------------
# (p, q) of every moment m_pq = integral Phi kx^p ky^q of orders 0, 2 and 4 (odd orders vanish
# for a real surface: Phi(k) = Phi(-k)).
MOMENT_ORDERS = ((0, 0), (2, 0), (1, 1), (0, 2), (4, 0), (3, 1), (2, 2), (1, 3), (0, 4))
_MOMENT_NAMES = tuple(f"m{p}{q}" for p, q in MOMENT_ORDERS)
WINDOWS = ("none", "hann")


@dataclass(frozen=True)
class MomentTensor:
    """Spectral moments of orders 0, 2 and 4 of a surface in arbitrary in-plane axes (x, y).

    ``m_pq = integral Phi(kx, ky) kx^p ky^q dkx dky`` over angular wavenumbers (the convention of
    the module docstring and Appendix A): ``m20, m11, m02`` form the slope covariance
    (``<zx^2>, <zx zy>, <zy^2>``), ``m40 ... m04`` the curvature moments
    (``m40 = <zxx^2>, m31 = <zxx zxy>, m22 = <zxy^2> = <zxx zyy>, m13 = <zyy zxy>,
    m04 = <zyy^2>``). Unlike :class:`SpectralMoments` (principal axes, x along the grain, the
    paper's five moments) the axes here are any, e.g. the pixel axes of a measured map;
    :meth:`principal` rotates to the grain axes.

    Args:
        m00: height variance [unit^2], > 0.
        m20, m11, m02: slope moments [-]; m20, m02 > 0, m11^2 < m20 m02.
        m40, m31, m22, m13, m04: curvature moments [unit^-2]; m40, m22, m04 > 0.
        unit: length unit of the given moments, "um" (default), "mm" or "m"; stored in mm.
    """

    m00: float
    m20: float
    m11: float
    m02: float
    m40: float
    m31: float
    m22: float
    m13: float
    m04: float
    unit: str = "um"

    def __post_init__(self):
        if self.unit not in _UNIT_SCALE:
            raise ValueError(f"unit = {self.unit!r} is invalid: valid units are {sorted(_UNIT_SCALE)}")
        L = _UNIT_SCALE[self.unit]
        for name, (p, q) in zip(_MOMENT_NAMES, MOMENT_ORDERS):
            v = float(getattr(self, name))
            if not math.isfinite(v):
                raise ValueError(f"{name} = {v!r} is invalid: it must be finite")
            if p % 2 == 0 and q % 2 == 0 and not v > 0.0:
                raise ValueError(f"{name} = {v!r} is invalid: it must be > 0")
            object.__setattr__(self, name, v * L ** (2 - p - q))
        object.__setattr__(self, "unit", "mm")
        if not self.m11 ** 2 < self.m20 * self.m02:
            raise ValueError(f"m11 = {self.m11!r} is invalid: the slope covariance needs "
                             f"m11^2 < m20 m02 = {self.m20 * self.m02!r}")

    def as_um(self) -> dict:
        """The moments in the paper's micrometre convention (dict)."""
        return {n: getattr(self, n) * 1e3 ** (2 - p - q)
                for n, (p, q) in zip(_MOMENT_NAMES, MOMENT_ORDERS)}

    def rotated(self, angle: float) -> "MomentTensor":
        """The moments in axes (x', y') turned by ``angle`` [rad] counter-clockwise from (x, y).

        With kx' = c kx + s ky, ky' = -s kx + c ky (c = cos angle, s = sin angle),
        m'_pq = integral Phi (c kx + s ky)^p (-s kx + c ky)^q: the binomial expansion of the
        form of order p + q, evaluated with numpy polynomials in t = kx/ky.
        """
        c, s_ = math.cos(angle), math.sin(angle)
        P = np.polynomial.polynomial
        new = {}
        for name, (p, q) in zip(_MOMENT_NAMES, MOMENT_ORDERS):
            n = p + q
            # coefficient a of t^a multiplies kx^a ky^(n-a), i.e. the moment m_{a, n-a}
            coef = P.polymul(P.polypow([s_, c], p), P.polypow([c, -s_], q))
            coef = np.pad(coef, (0, n + 1 - coef.size))
            new[name] = sum(float(coef[a]) * getattr(self, f"m{a}{n - a}")
                            for a in range(n + 1) if f"m{a}{n - a}" in _MOMENT_NAMES)
        return MomentTensor(**new, unit="mm")

    def grain_angle(self) -> float:
        """Direction of the smallest mean-square slope [rad], in (-pi/2, pi/2], from x towards y.

        The principal axes of the slope covariance (m11' = 0, Longuet-Higgins): m20'(theta) =
        (m20 + m02)/2 + R cos(2 theta - phi), phi = atan2(2 m11, m20 - m02); its minimum is at
        phi/2 + pi/2. Along the grain (the paper's x, e.g. the grinding direction) slopes and
        curvatures are smallest.
        """
        phi = math.atan2(2.0 * self.m11, self.m20 - self.m02)
        return _wrap_half_turn(0.5 * phi + 0.5 * math.pi)

    def curvature_grain_angle(self) -> float:
        """Direction of the smallest mean-square curvature m40'(theta) [rad], in (-pi/2, pi/2].

        For an orthotropic surface (m11 = m31 = m13 = 0 in its principal axes, the assumption of
        the strongly anisotropic model) it equals :meth:`grain_angle`; the difference measures
        how far the surface is from that assumption.
        """
        # m40'(theta) is a trigonometric polynomial of degree 4: a fine grid, then one parabolic
        # refinement (error ~1e-7 rad)
        th = np.linspace(-0.5 * math.pi, 0.5 * math.pi, 3601)
        c, s_ = np.cos(th), np.sin(th)
        f = (c**4 * self.m40 + 4 * c**3 * s_ * self.m31 + 6 * c**2 * s_**2 * self.m22
             + 4 * c * s_**3 * self.m13 + s_**4 * self.m04)
        i = int(np.argmin(f[:-1]))
        fm, f0, fp = f[i - 1], f[i], f[i + 1]   # i - 1 = -1 wraps to the same angle + pi
        den = fm - 2 * f0 + fp
        shift = 0.5 * (fm - fp) / den if den > 0 else 0.0
        return _wrap_half_turn(float(th[i] + shift * (th[1] - th[0])))

    def principal(self) -> Tuple["MomentTensor", float]:
        """The moments in the grain axes (x' along :meth:`grain_angle`) and that angle [rad]."""
        angle = self.grain_angle()
        return self.rotated(angle), angle

    def spectral_moments(self) -> "SpectralMoments":
        """The paper's five moments in THESE axes (x = grain if this tensor is principal).

        The mixed moments m11, m31, m13 are dropped: the model assumes them zero.
        SpectralMoments warns below m04/m40 = ANISOTROPY_WARN_RATIO.
        """
        return SpectralMoments(self.m00, self.m20, self.m02, self.m40, self.m04, unit="mm")


def _wrap_half_turn(angle: float) -> float:
    """An axis direction [rad] in (-pi/2, pi/2]."""
    a = math.remainder(angle, math.pi)
    return a + math.pi if a <= -0.5 * math.pi else a


def _window_1d(n: int, window: str) -> np.ndarray:
    if window == "none":
        return np.ones(n)
    if window == "hann":
        # periodic Hann, sin^2(pi j/n): three DFT bins only, so the correction below is exact
        return np.sin(np.pi * np.arange(n) / n) ** 2
    raise ValueError(f"window = {window!r} is invalid: valid windows are {list(WINDOWS)}")


def _fft_moments(z, dx: float, dy: float | None, window: str) -> dict:
    """Moments {(p, q): m_pq} of orders 0, 2, 4 of a height map in its own unit (FFT).

    The one spectral computation behind :func:`moment_tensor_from_height_map` and
    :func:`moments_from_height_map` (method "fft"); conventions and the window correction as
    described there. z: (nx, ny), axis 0 along x [unit]; dx, dy [unit].
    """
    z, dx, dy = _checked_map(z, dx, dy)
    nx, ny = z.shape
    w = np.outer(_window_1d(nx, window), _window_1d(ny, window))
    P, kx, ky = _power_spectrum(w * (z - z.mean()), dx, dy)
    Pw, _, _ = _power_spectrum(w, dx, dy)
    norm = Pw.sum()                      # <w^2> (Parseval)
    kxp = [np.ones_like(kx), kx, kx**2, kx**3, kx**4]
    kyp = [np.ones_like(ky), ky, ky**2, ky**3, ky**4]
    raw = {(p, q): float((P * kxp[p] * kyp[q]).sum()) / norm for p, q in MOMENT_ORDERS}
    m = {}
    if window == "none":
        m = raw
    else:
        wmom = {(r, s_): float((Pw * kxp[r] * kyp[s_]).sum()) / norm
                for r in range(5) for s_ in range(5) if r + s_ <= 4}
        for p, q in MOMENT_ORDERS:      # increasing order: lower moments are known
            acc = raw[(p, q)]
            for a, b in MOMENT_ORDERS:
                if a <= p and b <= q and (a, b) != (p, q):
                    acc -= math.comb(p, a) * math.comb(q, b) * m[(a, b)] * wmom[(p - a, q - b)]
            m[(p, q)] = acc / wmom[(0, 0)]
    return m


def moment_tensor_from_height_map(z, dx: float, dy: float | None = None, unit: str = "um",
                                  window: str = "none") -> MomentTensor:
    """All moments of orders 0, 2, 4 (incl. m11, m31, m22, m13) of a sampled height map (FFT).

    Same convention and layout as :func:`moments_from_height_map` (method "fft"): the mean is
    removed, z has axis 0 along x, spectral derivatives with the Nyquist bin set to zero.

    Window correction (``window="hann"``, for maps that are not periodic, e.g. measured ones:
    the periodic extension of a non-periodic map jumps at its edges, which adds spurious
    high-wavenumber power and biases m20 ... m04 upwards). The windowed map w z, with w the
    separable periodic Hann window, has the expected discrete spectrum
    ``E|W*Z|^2 = |W|^2 (*) E|Z|^2`` (circular convolution), so its moments, normalised by
    ``<w^2>`` (the power of the window, 9/64 in 2D), are
    ``M_pq = sum_{a<=p, b<=q} C(p,a) C(q,b) m_ab w_{p-a,q-b}``, with
    ``w_rs = sum |W|^2 kx^r ky^s / sum |W|^2`` the window's own moments (w_00 = 1; for the
    periodic Hann w_20 = (2 pi/Lx)^2/3, w_40 = (2 pi/Lx)^4/3, w_02, w_04 likewise, w_22 =
    w_20 w_02, odd ones 0). This triangular system is solved for m_pq order by order, e.g.
    m20 = M20 - w_20 m00, m40 = M40 - 6 w_20 m20 - w_40 m00, m22 = M22 - w_02 m20 - w_20 m02 -
    w_22 m00, m31 = M31 - 3 w_20 m11. The correction is exact in expectation (wavenumbers
    within one bin of the Nyquist bin excepted); on one map the window widens each spectral
    line over three bins, i.e. fewer independent samples.

    Args:
        z: heights, shape (nx, ny), axis 0 along x [unit].
        dx, dy: sampling steps [unit] (dy defaults to dx).
        unit: length unit of z, dx, dy ("um", "mm" or "m").
        window: "none" (periodic map) or "hann" (with the correction above).
    Returns:
        MomentTensor in the map axes (stored in mm).
    """
    m = _fft_moments(z, dx, dy, window)
    return MomentTensor(*(m[o] for o in MOMENT_ORDERS), unit=unit)
