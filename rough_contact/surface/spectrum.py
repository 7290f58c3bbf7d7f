"""Gaussian rough surfaces with a prescribed spectrum, fitted to five spectral moments.

A user who has only the spectral moments m00, m20, m02, m40, m04 of a surface (the statistical
law's input) gets height maps for the boundary-element law (:mod:`rough_contact.micro.bem`) from here.
Five moments do not determine a spectrum; this module **assumes** the following shape and says
so wherever it is used.

Assumed spectrum (a *stretched isotropic self-affine spectrum with roll-off*):

* an isotropic base PSD over angular wavenumbers q = |(qx, qy)| [rad/mm],

      Phi_iso(q) = C                          for q_l <= q < q_r   (roll-off plateau)
                 = C (q / q_r)^(-2(1 + H))    for q_r <= q <= q_s  (self-affine, Hurst H)
                 = 0                          otherwise,

  with ``q_r / q_l = plateau`` (default 2, one octave) and H (default 0.8) chosen by the user
  (:class:`SpectrumShape`), and C, q_r and the bandwidth ``zeta = q_s / q_r`` fitted to the
  base's m00, m2 and m4 (its bandwidth alpha = m00 m4 / m2^2 fixes zeta, alpha(zeta) being
  monotone);
* stretched to anisotropy: z(x, y) = z_iso(gx x, gy y), so
  ``Phi(qx, qy) = Phi_iso(|(qx/gx, qy/gy)|) / (gx gy)`` with gx gy = 1 and gx^2/gy^2 = m20/m02.
  Then m20 = gx^2 m2, m02 = gy^2 m2, m40 = gx^4 m4, m04 = gy^4 m4: a stretched isotropic
  spectrum has **m04/m40 = (m02/m20)^2** exactly. The paper's surfaces satisfy this (100 = 10^2,
  6561 = 81^2); for other moments the best compromise m4 = sqrt(m40 m04) is used and a
  ``UserWarning`` names the moments actually realised.

Moment convention as in :mod:`rough_contact.surface`: PSD over angular wavenumbers normalised so
that m00 = <z^2> = integral Phi dqx dqy, m_pq = integral Phi qx^p qy^q dqx dqy. For the
isotropic base: m00 = 2 pi I1, m2 = pi I3, m4 = (3 pi / 4) I5 with I_n = integral Phi q^n dq.

Realisations are Gaussian random fields (filtered white noise, periodic), sampled with a grid
that holds ``periods`` longest wavelengths 2 pi / q_l per side and ``pixels_per_wavelength``
pixels per shortest wavelength 2 pi / q_s (in the stretched metric: both scale with the
stretch). Units: mm, rad/mm; moments stored in mm as in :class:`SpectralMoments`.
Pure module: numpy and scipy only.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Tuple

import numpy as np
from scipy.optimize import brentq

from .moments import SpectralMoments
from ..validation import check_scalar

__all__ = ["SpectrumShape", "StretchedSpectrum", "fit_spectrum", "example_surfaces"]

# relative mismatch of m04/m40 against (m02/m20)^2 above which fit_spectrum warns
_MOMENT_MISMATCH_WARN = 0.05


@dataclass(frozen=True)
class SpectrumShape:
    """The assumed shape of the spectrum (see the module docstring).

    Args:
        hurst: Hurst exponent H of the self-affine part, in (0, 1] [-].
        plateau: q_r / q_l, width of the roll-off plateau, >= 1 (1: no plateau) [-].
    """

    hurst: float = 0.8
    plateau: float = 2.0

    def __post_init__(self):
        object.__setattr__(self, "hurst", check_scalar("hurst", self.hurst, lo=0.0, hi=1.0,
                                                       hi_open=False))
        object.__setattr__(self, "plateau", check_scalar("plateau", self.plateau, lo=1.0,
                                                         lo_open=False, hi=1e3))


def _power_integral(n: int, hurst: float, zeta: float) -> float:
    """integral_1^zeta q^(n - 2(1+H)) dq (the self-affine part in units q_r = 1)."""
    e = n + 1 - 2.0 * (1.0 + hurst)
    if abs(e) < 1e-12:
        return math.log(zeta)
    return (zeta ** e - 1.0) / e


def _base_integrals(shape: SpectrumShape, zeta: float) -> Tuple[float, float, float]:
    """I1, I3, I5 of the base PSD with C = 1 and q_r = 1."""
    ql = 1.0 / shape.plateau
    out = []
    for n in (1, 3, 5):
        plateau = (1.0 - ql ** (n + 1)) / (n + 1)
        out.append(plateau + _power_integral(n, shape.hurst, zeta))
    return tuple(out)


def _alpha(shape: SpectrumShape, zeta: float) -> float:
    i1, i3, i5 = _base_integrals(shape, zeta)
    return (2 * math.pi * i1) * (0.75 * math.pi * i5) / (math.pi * i3) ** 2


@dataclass(frozen=True)
class StretchedSpectrum:
    """A stretched isotropic self-affine spectrum with roll-off (see the module docstring).

    Attributes:
        C: plateau level of the isotropic base PSD [mm^4].
        q_l, q_r, q_s: lower cut-off, roll-off and upper cut-off of the base [rad/mm].
        hurst: Hurst exponent [-].
        gx, gy: stretch factors (gx gy = 1) [-]; x is the grain direction (gx <= 1 when the
            surface is smoother along x).
    """

    C: float
    q_l: float
    q_r: float
    q_s: float
    hurst: float
    gx: float = 1.0
    gy: float = 1.0

    @property
    def shape(self) -> SpectrumShape:
        return SpectrumShape(hurst=self.hurst, plateau=self.q_r / self.q_l)

    @property
    def zeta(self) -> float:
        """Bandwidth q_s / q_r [-]."""
        return self.q_s / self.q_r

    def psd(self, qx, qy) -> np.ndarray:
        """Phi(qx, qy) [mm^4] at angular wavenumbers qx, qy [rad/mm] (broadcast)."""
        qx = np.asarray(qx, float) / self.gx
        qy = np.asarray(qy, float) / self.gy
        q = np.hypot(qx, qy)
        with np.errstate(divide="ignore"):
            tail = self.C * (np.maximum(q, self.q_r) / self.q_r) ** (-2.0 * (1.0 + self.hurst))
        out = np.where(q < self.q_r, self.C, tail)
        return np.where((q >= self.q_l) & (q <= self.q_s), out, 0.0) / (self.gx * self.gy)

    def moments(self) -> SpectralMoments:
        """The spectral moments of the continuous spectrum (exact integrals), mm units."""
        i1, i3, i5 = _base_integrals(self.shape, self.zeta)
        qr = self.q_r
        m00 = 2 * math.pi * self.C * qr ** 2 * i1
        m2 = math.pi * self.C * qr ** 4 * i3
        m4 = 0.75 * math.pi * self.C * qr ** 6 * i5
        return SpectralMoments(m00, self.gx ** 2 * m2, self.gy ** 2 * m2, self.gx ** 4 * m4,
                               self.gy ** 4 * m4, unit="mm")

    def grid(self, pixels_per_wavelength: float = 8.0, periods: int = 1,
             fft_friendly: bool = True) -> Tuple[Tuple[int, int], Tuple[float, float]]:
        """Grid that resolves the spectrum: ``((nx, ny), (Lx, Ly))``.

        Args:
            pixels_per_wavelength: pixels per shortest wavelength 2 pi/q_s (stretched), >= 2.
            periods: longest wavelengths 2 pi/q_l per side, >= 1.
            fft_friendly: round the pixel count up to a 2^a 3^b 5^c number.

        Returns:
            (nx, ny) pixels, (Lx, Ly) [mm]. nx == ny: the stretch scales spacing and size alike.
        """
        ppw = check_scalar("pixels_per_wavelength", pixels_per_wavelength, lo=2.0,
                           lo_open=False, hi=1e4)
        periods = int(check_scalar("periods", periods, lo=1.0, lo_open=False, hi=1e3))
        n = int(math.ceil(periods * ppw * self.q_s / self.q_l - 1e-9))
        n += n % 2
        if fft_friendly:
            n = _next_smooth(n)
        L = periods * 2 * math.pi / self.q_l
        return (n, n), (L / self.gx, L / self.gy)

    def realisation(self, shape: Tuple[int, int], size: Tuple[float, float],
                    seed: int) -> np.ndarray:
        """A periodic Gaussian random field with this spectrum (filtered white noise).

        Private generator of this module (the topography module has the public one): the mode
        amplitudes are complex Gaussian with variance Phi(q) dqx dqy, so the heights are
        Gaussian and the expected discrete moments are the sums of Phi over the grid's modes.

        Args:
            shape: (nx, ny) pixels, each >= 4.
            size: (Lx, Ly) periods [mm].
            seed: seed of numpy's default generator.

        Returns:
            heights (nx, ny) [mm], zero mean, C-contiguous; axis 0 is x.
        """
        nx, ny = (int(v) for v in shape)
        if min(nx, ny) < 4:
            raise ValueError(f"shape = {shape!r} is invalid: at least 4 x 4 pixels are needed")
        Lx = check_scalar("Lx", size[0], lo=0.0, unit="mm")
        Ly = check_scalar("Ly", size[1], lo=0.0, unit="mm")
        qx = 2 * np.pi * np.fft.fftfreq(nx, Lx / nx)[:, None]
        qy = 2 * np.pi * np.fft.rfftfreq(ny, Ly / ny)[None, :]
        amp = np.sqrt(self.psd(qx, qy) * (2 * np.pi / Lx) * (2 * np.pi / Ly) * nx * ny)
        amp[0, 0] = 0.0
        rng = np.random.default_rng(seed)
        # rfft2 of real white noise has E|W|^2 = nx ny, Hermitian symmetry is kept by irfft2
        W = np.fft.rfft2(rng.standard_normal((nx, ny)))
        z = np.fft.irfft2(W * amp, s=(nx, ny))
        return np.ascontiguousarray(z - z.mean())

    def discrete_moments(self, shape: Tuple[int, int], size: Tuple[float, float]) -> dict:
        """Expected moments of :meth:`realisation` on this grid (sums over its modes), mm units.

        Returns a dict m00, m20, m02, m40, m04 (the Nyquist modes counted like the others).
        """
        nx, ny = (int(v) for v in shape)
        Lx, Ly = float(size[0]), float(size[1])
        qx = 2 * np.pi * np.fft.fftfreq(nx, Lx / nx)[:, None]
        qy = 2 * np.pi * np.fft.fftfreq(ny, Ly / ny)[None, :]
        w = self.psd(qx, qy) * (2 * np.pi / Lx) * (2 * np.pi / Ly)
        w[0, 0] = 0.0
        return {"m00": float(w.sum()), "m20": float((w * qx ** 2).sum()),
                "m02": float((w * qy ** 2).sum()), "m40": float((w * qx ** 4).sum()),
                "m04": float((w * qy ** 4).sum())}


def _next_smooth(n: int) -> int:
    """Smallest even 2^a 3^b 5^c >= n (fast FFT sizes)."""
    m = max(int(n), 2)
    while True:
        k = m
        for f in (2, 3, 5):
            while k % f == 0:
                k //= f
        if k == 1 and m % 2 == 0:
            return m
        m += 1


def fit_spectrum(moments: SpectralMoments,
                 shape: SpectrumShape = SpectrumShape()) -> StretchedSpectrum:
    """Fit the assumed spectrum (module docstring) to five spectral moments.

    Args:
        moments: the surface's :class:`SpectralMoments` (x = grain direction).
        shape: Hurst exponent and plateau width of the assumed shape.

    Returns:
        The fitted :class:`StretchedSpectrum`; its :meth:`~StretchedSpectrum.moments` equal the
        given ones when m04/m40 = (m02/m20)^2, otherwise m00, m20, m02 are matched and
        m40, m04 are replaced by the closest stretched pair (UserWarning).

    Raises:
        ValueError: if the bandwidth of the moments is below the narrowest this shape can
            produce (a smaller ``plateau`` lowers that limit; 1.5 is the absolute minimum).
    """
    m00, m20, m02, m40, m04 = moments.m00, moments.m20, moments.m02, moments.m40, moments.m04
    gx = (m20 / m02) ** 0.25
    gy = 1.0 / gx
    m2 = math.sqrt(m20 * m02)
    m4 = math.sqrt(m40 * m04)
    mismatch = (m04 / m40) / (m02 / m20) ** 2
    if abs(mismatch - 1.0) > _MOMENT_MISMATCH_WARN:
        warnings.warn(
            f"m04/m40 = {m04 / m40:.4g} differs from (m02/m20)^2 = {(m02 / m20) ** 2:.4g}: a "
            "stretched isotropic spectrum cannot match all five moments; m00, m20, m02 are "
            f"matched and m40, m04 become {gx ** 4 * m4:.4g}, {gy ** 4 * m4:.4g} mm^-2 "
            f"(given {m40:.4g}, {m04:.4g})", UserWarning, stacklevel=2)
    alpha = m00 * m4 / m2 ** 2
    lo = _alpha(shape, 1.0 + 1e-9)
    if not alpha > lo * (1 + 1e-9):
        raise ValueError(
            f"bandwidth alpha = m00 sqrt(m40 m04)/(m20 m02) = {alpha:.6g} is below the minimum "
            f"{lo:.6g} of the assumed spectrum (hurst = {shape.hurst}, plateau = "
            f"{shape.plateau}); valid range: alpha > {lo:.6g} (plateau = 1 allows down to 1.5)")
    hi_z = 2.0
    while _alpha(shape, hi_z) < alpha:
        hi_z *= 2.0
        if hi_z > 1e8:
            raise ValueError(f"bandwidth alpha = {alpha:.6g} needs q_s/q_r > 1e8: valid range "
                             f"alpha < {_alpha(shape, 1e8):.6g}")
    zeta = brentq(lambda lz: _alpha(shape, math.exp(lz)) - alpha, 1e-9, math.log(hi_z),
                  xtol=1e-14, rtol=1e-14)
    zeta = math.exp(zeta)
    i1, i3, _ = _base_integrals(shape, zeta)
    # m2/m00 = q_r^2 (pi i3)/(2 pi i1) fixes q_r; then m00 fixes C
    qr = math.sqrt(m2 / m00 * 2.0 * i1 / i3)
    C = m00 / (2 * math.pi * qr ** 2 * i1)
    return StretchedSpectrum(C=C, q_l=qr / shape.plateau, q_r=qr, q_s=zeta * qr,
                             hurst=shape.hurst, gx=gx, gy=gy)


def example_surfaces() -> dict:
    """The surfaces of the studies in docs/bem.md, as (SpectralMoments, SpectrumShape) pairs.

    All have m00 = 0.625 um^2 and the paper's geometric-mean slope variance
    sqrt(m20 m02) = 2.53e-4 (um convention):

    * ``"isotropic"``: isotropic Gaussian, bandwidth alpha = 10 (q_s/q_r = 10.4 with H = 0.8);
    * ``"anisotropic"``: the same, stretched to m02/m20 = 10 (m04/m40 = 100: strongly
      anisotropic, x = grain);
    * ``"self-affine"``: isotropic, broadband self-affine H = 0.8 over q_s/q_r = 32
      (alpha = 42.7);
    * ``"paper"``: the paper's surface of Figs 18-19 (m04/m40 = 100, alpha = 101.6:
      q_s/q_r = 59, the most expensive).
    """
    import warnings as _w

    m00, m2 = 0.625, math.sqrt(8e-5 * 8e-4)
    base = SpectrumShape(hurst=0.8, plateau=2.0)
    with _w.catch_warnings():
        # the isotropic surfaces are outside the strongly anisotropic statistical model's range
        _w.simplefilter("ignore", UserWarning)
        iso = SpectralMoments(m00, m2, m2, 10 * m2 ** 2 / m00, 10 * m2 ** 2 / m00)
        m20, m02 = m2 / math.sqrt(10), m2 * math.sqrt(10)
        aniso = SpectralMoments(m00, m20, m02, 10 * m20 ** 2 / m00, 10 * m02 ** 2 / m00)
        a_sa = _alpha(base, 32.0)
        sa = SpectralMoments(m00, m2, m2, a_sa * m2 ** 2 / m00, a_sa * m2 ** 2 / m00)
        paper = SpectralMoments(m00=0.625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
    return {"isotropic": (iso, base), "anisotropic": (aniso, base), "self-affine": (sa, base),
            "paper": (paper, base)}
