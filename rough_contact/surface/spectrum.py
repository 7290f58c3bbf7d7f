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

A surface whose spectrum is *known* (a callable Phi or a table, e.g. a Gaussian
autocorrelation) needs no assumed shape: :class:`PSDSurface` integrates its moments and
synthesises its realisations (:class:`TabulatedPSD` for tables).

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
from typing import Optional, Protocol, Tuple

import numpy as np
from scipy.optimize import brentq

from .moments import SpectralMoments
from ..validation import check_scalar

__all__ = ["SpectrumShape", "StretchedSpectrum", "fit_spectrum", "example_surfaces",
           "SurfaceSpectrum", "TabulatedPSD", "PSDSurface", "gaussian_realisation",
           "expected_discrete_moments", "AMPLITUDES"]

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
                    seed: int, amplitudes: str = "random") -> np.ndarray:
        """A periodic Gaussian random field with this spectrum (filtered white noise).

        The mode amplitudes are complex Gaussian with variance Phi(q) dqx dqy (or, with
        ``amplitudes="fixed"``, of exactly that modulus with random phases), so the heights are
        Gaussian and the expected discrete moments are the sums of Phi over the grid's modes
        (:func:`gaussian_realisation`).

        Args:
            shape: (nx, ny) pixels, each >= 4.
            size: (Lx, Ly) periods [mm].
            seed: seed of numpy's default generator.
            amplitudes: "random" or "fixed".

        Returns:
            heights (nx, ny) [mm], zero mean, C-contiguous; axis 0 is x.
        """
        return gaussian_realisation(self.psd, shape, size, seed, amplitudes)

    def discrete_moments(self, shape: Tuple[int, int], size: Tuple[float, float]) -> dict:
        """Expected moments of :meth:`realisation` on this grid (sums over its modes), mm units.

        Returns a dict m00, m20, m02, m40, m04 (the Nyquist modes counted like the others).
        """
        return expected_discrete_moments(self.psd, shape, size)


AMPLITUDES = ("random", "fixed")


def gaussian_realisation(psd, shape: Tuple[int, int], size: Tuple[float, float],
                         seed: int, amplitudes: str = "random") -> np.ndarray:
    """A periodic Gaussian random field with the spectrum ``psd`` (filtered white noise).

    ``amplitudes="random"``: the mode amplitudes are complex Gaussian with variance
    Phi(q) dqx dqy, so the heights are Gaussian and the expected discrete moments are the sums of
    Phi over the grid's modes (:func:`expected_discrete_moments`). ``"fixed"``: every mode has
    exactly that modulus and a random phase (the random-phase surface of Appendix A): the
    moments of every realisation *equal* those sums (no scatter of m00 ... m04 between
    realisations, a variance reduction for averages over realisations; heights Gaussian by the
    central limit theorem over the many modes). Phi is symmetrised, (Phi(q) + Phi(-q))/2.

    Args:
        psd: Phi(qx, qy) [mm^4] at angular wavenumbers [rad/mm] (broadcast).
        shape: (nx, ny) pixels, each >= 4; axis 0 is x.
        size: (Lx, Ly) periods [mm].
        seed: seed of numpy's default generator.
        amplitudes: "random" (Gaussian random field) or "fixed" (random phases only).

    Returns:
        heights (nx, ny) [mm], zero mean, C-contiguous.
    """
    if amplitudes not in AMPLITUDES:
        raise ValueError(f"amplitudes = {amplitudes!r} is invalid; valid: {AMPLITUDES}")
    nx, ny = (int(v) for v in shape)
    if min(nx, ny) < 4:
        raise ValueError(f"shape = {shape!r} is invalid: at least 4 x 4 pixels are needed")
    Lx = check_scalar("Lx", size[0], lo=0.0, unit="mm")
    Ly = check_scalar("Ly", size[1], lo=0.0, unit="mm")
    qx = 2 * np.pi * np.fft.fftfreq(nx, Lx / nx)[:, None]
    qy = 2 * np.pi * np.fft.rfftfreq(ny, Ly / ny)[None, :]
    phi = 0.5 * (np.asarray(psd(qx, qy), float) + np.asarray(psd(-qx, -qy), float))
    if not (np.all(np.isfinite(phi)) and np.all(phi >= 0)):
        raise ValueError("the PSD returned negative or non-finite values on the grid: Phi must "
                         "be finite and >= 0")
    amp = np.sqrt(phi * (2 * np.pi / Lx) * (2 * np.pi / Ly) * nx * ny)
    amp[0, 0] = 0.0
    rng = np.random.default_rng(seed)
    # rfft2 of real white noise has E|W|^2 = nx ny, Hermitian symmetry is kept by irfft2
    W = np.fft.rfft2(rng.standard_normal((nx, ny)))
    if amplitudes == "fixed":
        # unit modulus times sqrt(nx ny), the rms modulus of W: |Z| = sqrt(Phi dq nx ny) exactly.
        # The self-conjugate modes (q = 0, Nyquist) of the half spectrum are real: their sign
        # is kept (a phase of 0 or pi), the rest is Hermitian by construction of irfft2
        mag = np.abs(W)
        W = np.divide(W, mag, out=np.ones_like(W), where=mag > 0) * math.sqrt(nx * ny)
    z = np.fft.irfft2(W * amp, s=(nx, ny))
    return np.ascontiguousarray(z - z.mean())


def expected_discrete_moments(psd, shape: Tuple[int, int], size: Tuple[float, float]) -> dict:
    """Expected moments of :func:`gaussian_realisation` on this grid (sums over its modes).

    Returns a dict m00, m20, m02, m40, m04 in mm units (the Nyquist modes counted like the
    others, the q = 0 mode excluded).
    """
    nx, ny = (int(v) for v in shape)
    Lx, Ly = float(size[0]), float(size[1])
    qx = 2 * np.pi * np.fft.fftfreq(nx, Lx / nx)[:, None]
    qy = 2 * np.pi * np.fft.fftfreq(ny, Ly / ny)[None, :]
    w = 0.5 * (np.asarray(psd(qx, qy), float) + np.asarray(psd(-qx, -qy), float))
    w = np.broadcast_to(w, (nx, ny)) * (2 * np.pi / Lx) * (2 * np.pi / Ly)
    w = np.array(w)
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


# ---------------------------------------------------------------------------------------------
# a surface given by its own power spectrum
# ---------------------------------------------------------------------------------------------
class SurfaceSpectrum(Protocol):
    """What the BEM tier needs of a spectrum (``rough_contact.micro.bem.bem_law_from_spectrum``):
    its moments, a grid that resolves it and Gaussian realisations on that grid (mm units).
    :class:`StretchedSpectrum` and :class:`PSDSurface` satisfy it."""

    def moments(self) -> SpectralMoments: ...

    def grid(self, pixels_per_wavelength: float = 8.0,
             periods: int = 1) -> Tuple[Tuple[int, int], Tuple[float, float]]: ...

    def realisation(self, shape: Tuple[int, int], size: Tuple[float, float],
                    seed: int, amplitudes: str = "random") -> np.ndarray: ...


@dataclass(frozen=True, eq=False)
class TabulatedPSD:
    """A 2D PSD given as a table on a regular wavenumber grid, bilinear in between, 0 outside.

    Args:
        kx: (nkx,) angular wavenumbers along x, strictly increasing [rad/unit].
        ky: (nky,) angular wavenumbers along y, strictly increasing [rad/unit].
        values: (nkx, nky) Phi(kx_i, ky_j) >= 0 [unit^4], normalised so that
            m00 = integral Phi dkx dky (angular wavenumbers, the package convention).

    Call it as ``psd(kx, ky)`` (broadcast). :meth:`isotropic` builds one from a radial table.
    """

    kx: np.ndarray
    ky: np.ndarray
    values: np.ndarray

    def __post_init__(self):
        kx = np.array(self.kx, float).ravel()
        ky = np.array(self.ky, float).ravel()
        v = np.array(self.values, float)
        for name, k in (("kx", kx), ("ky", ky)):
            if k.size < 2 or not np.all(np.isfinite(k)) or np.any(np.diff(k) <= 0):
                raise ValueError(f"{name} of the PSD table is invalid: >= 2 finite, strictly "
                                 f"increasing wavenumbers are needed (got {k.size})")
        if v.shape != (kx.size, ky.size):
            raise ValueError(f"values.shape = {v.shape} is invalid: (len(kx), len(ky)) = "
                             f"{(kx.size, ky.size)} is needed")
        if not np.all(np.isfinite(v)) or np.any(v < 0):
            raise ValueError("values of the PSD table are invalid: all must be finite and >= 0")
        from scipy.interpolate import RegularGridInterpolator

        object.__setattr__(self, "kx", kx)
        object.__setattr__(self, "ky", ky)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "_interp", RegularGridInterpolator(
            (kx, ky), v, method="linear", bounds_error=False, fill_value=0.0))

    @classmethod
    def isotropic(cls, q, phi, n: int = 513) -> "TabulatedPSD":
        """An isotropic PSD Phi(|k|) from a radial table q (increasing, >= 0) [rad/unit],
        phi [unit^4], resampled on an n x n grid over |kx|, |ky| <= max(q)."""
        q = np.asarray(q, float)
        phi = np.asarray(phi, float)
        if q.ndim != 1 or q.shape != phi.shape or q.size < 2 or np.any(np.diff(q) <= 0):
            raise ValueError("q and phi must be 1D tables of the same length (>= 2), q strictly "
                             "increasing")
        k = np.linspace(-q[-1], q[-1], int(n))
        r = np.hypot(k[:, None], k[None, :])
        return cls(k, k, np.interp(r, q, phi, left=phi[0], right=0.0))

    def __call__(self, kx, ky) -> np.ndarray:
        kx, ky = np.broadcast_arrays(np.asarray(kx, float), np.asarray(ky, float))
        pts = np.stack([kx.ravel(), ky.ravel()], axis=1)
        return self._interp(pts).reshape(kx.shape)

    @property
    def k_max(self) -> Tuple[float, float]:
        """Largest |kx|, |ky| of the table [rad/unit]: the PSD is zero beyond."""
        return (float(max(abs(self.kx[0]), abs(self.kx[-1]))),
                float(max(abs(self.ky[0]), abs(self.ky[-1]))))


def _gauss_legendre_panels(a: float, b: float, panels: int, order: int = 8):
    """Nodes and weights of the composite Gauss-Legendre rule on [a, b]."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(a, b, panels + 1)
    h = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    return (mid[:, None] + h[:, None] * x[None, :]).ravel(), (h[:, None] * w[None, :]).ravel()


@dataclass(frozen=True, eq=False)
class PSDSurface:
    """A rough surface described by its own 2D power spectrum (a callable or a table).

    The surface is the Gaussian random field with PSD ``Phi(kx, ky)`` band-limited to the
    rectangle |kx| <= k_max[0], |ky| <= k_max[1] (Phi is taken as zero outside). Its moments are
    the integrals of the given Phi (:meth:`moment_tensor`, :meth:`moments`; no assumed shape,
    unlike :func:`fit_spectrum`); its height maps for the BEM tier are periodic realisations on a
    grid whose period is ``periods`` times the longest wavelength 2 pi/k_min (:meth:`grid`,
    :meth:`realisation`).

    Args:
        psd: Phi(kx, ky) over angular wavenumbers [rad/unit], returning [unit^4], normalised so
            that m00 = integral Phi dkx dky (e.g. :class:`TabulatedPSD`, or
            ``rough_contact.surface.topography.AnisotropicGaussianPSD``). Vectorised; >= 0.
        k_max: (kx_max, ky_max) band limit [rad/unit] (a table's own extent if None).
        k_min: (kx_min, ky_min) wavenumbers of the longest wavelength one period of the
            synthesis grid must hold [rad/unit] (modes below it are missing from a
            realisation: for a spectrum flat at low k, such as a Gaussian autocorrelation,
            2 pi/k_min should be several correlation lengths; compare :meth:`moments` with
            :meth:`discrete_moments`).
        unit: length unit of the wavenumbers and of Phi ("um", "mm" or "m"); stored in mm.
        panels: Gauss-Legendre panels per axis of the moment integration (8 nodes each).
    """

    psd: object
    k_max: Optional[Tuple[float, float]]
    k_min: Tuple[float, float]
    unit: str = "mm"
    panels: int = 64

    def __post_init__(self):
        from .moments import _UNIT_SCALE

        if self.unit not in _UNIT_SCALE:
            raise ValueError(f"unit = {self.unit!r} is invalid: valid units are "
                             f"{sorted(_UNIT_SCALE)}")
        if not callable(self.psd):
            raise ValueError(f"psd = {self.psd!r} is invalid: a callable Phi(kx, ky) is needed")
        k_max = self.k_max
        if k_max is None:
            if not isinstance(self.psd, TabulatedPSD):
                raise ValueError("k_max = None is only valid for a TabulatedPSD (its extent): "
                                 "give the band limit (kx_max, ky_max) of a callable PSD")
            k_max = self.psd.k_max
        u = f"rad/{self.unit}"
        kx_max = check_scalar("k_max[0]", k_max[0], lo=0.0, unit=u)
        ky_max = check_scalar("k_max[1]", k_max[1], lo=0.0, unit=u)
        kx_min = check_scalar("k_min[0]", self.k_min[0], lo=0.0, hi=kx_max, unit=u)
        ky_min = check_scalar("k_min[1]", self.k_min[1], lo=0.0, hi=ky_max, unit=u)
        s = _UNIT_SCALE[self.unit]                   # mm per unit
        object.__setattr__(self, "panels", int(check_scalar("panels", self.panels, lo=1.0,
                                                            lo_open=False, hi=4096)))
        # internal: mm units
        object.__setattr__(self, "_s", s)
        object.__setattr__(self, "_kmax", (kx_max / s, ky_max / s))
        object.__setattr__(self, "_kmin", (kx_min / s, ky_min / s))

    def psd_mm(self, kx, ky) -> np.ndarray:
        """Phi [mm^4] at angular wavenumbers [rad/mm], zero outside the band (broadcast)."""
        s = self._s
        kx, ky = np.asarray(kx, float), np.asarray(ky, float)
        inside = (np.abs(kx) <= self._kmax[0]) & (np.abs(ky) <= self._kmax[1])
        return np.where(inside, np.asarray(self.psd(kx * s, ky * s), float) * s ** 4, 0.0)

    def _integrate(self, panels: int):
        from .moments import MOMENT_ORDERS

        kx, wx = _gauss_legendre_panels(-self._kmax[0], self._kmax[0], panels)
        ky, wy = _gauss_legendre_panels(-self._kmax[1], self._kmax[1], panels)
        phi = np.broadcast_to(self.psd_mm(kx[:, None], ky[None, :]), (kx.size, ky.size))
        if not (np.all(np.isfinite(phi)) and np.all(phi >= 0)):
            raise ValueError("psd returned negative or non-finite values inside the band: Phi "
                             "must be finite and >= 0")
        out = {}
        for p, q in MOMENT_ORDERS:
            out[(p, q)] = float((wx * kx ** p) @ phi @ (wy * ky ** q))
        return out

    def moment_tensor(self):
        """Moments of orders 0, 2, 4 (mixed ones included) of the band-limited PSD in its own
        axes (:class:`~rough_contact.surface.moments.MomentTensor`, mm). Composite
        Gauss-Legendre quadrature; a UserWarning if halving the panels changes a moment by more
        than 1e-4 (relative to its order's size)."""
        from .moments import MOMENT_ORDERS, MomentTensor

        m = self._integrate(self.panels)
        if self.panels >= 2:
            c = self._integrate(self.panels // 2)
            scale = {0: m[(0, 0)], 2: m[(2, 0)] + m[(0, 2)], 4: m[(4, 0)] + m[(0, 4)]}
            err = max(abs(m[o] - c[o]) / scale[o[0] + o[1]] for o in MOMENT_ORDERS)
            if err > 1e-4:
                warnings.warn(f"the moments of the PSD change by {err:.2g} (relative) when the "
                              f"quadrature panels are halved: raise panels (now {self.panels}) "
                              "or smooth the PSD", UserWarning, stacklevel=2)
        return MomentTensor(*(m[o] for o in MOMENT_ORDERS), unit="mm")

    def moments(self) -> SpectralMoments:
        """The five moments in the PSD's principal (grain) axes, x along the grain (mm)."""
        principal, _ = self.moment_tensor().principal()
        return principal.spectral_moments()

    @property
    def grain_angle_deg(self) -> float:
        """Grain direction of the PSD from its kx axis towards ky [deg]."""
        return math.degrees(self.moment_tensor().grain_angle())

    def grid(self, pixels_per_wavelength: float = 8.0, periods: int = 1,
             fft_friendly: bool = True) -> Tuple[Tuple[int, int], Tuple[float, float]]:
        """((nx, ny), (Lx, Ly)) [mm]: period ``periods`` 2 pi/k_min per axis, pixels
        ``pixels_per_wavelength`` per shortest wavelength 2 pi/k_max (>= 2)."""
        ppw = check_scalar("pixels_per_wavelength", pixels_per_wavelength, lo=2.0,
                           lo_open=False, hi=1e4)
        periods = int(check_scalar("periods", periods, lo=1.0, lo_open=False, hi=1e3))
        out_n, out_L = [], []
        for kmin, kmax in zip(self._kmin, self._kmax):
            n = int(math.ceil(periods * ppw * kmax / kmin - 1e-9))
            n += n % 2
            out_n.append(_next_smooth(n) if fft_friendly else n)
            out_L.append(periods * 2 * math.pi / kmin)
        return (out_n[0], out_n[1]), (out_L[0], out_L[1])

    def realisation(self, shape: Tuple[int, int], size: Tuple[float, float],
                    seed: int, amplitudes: str = "random") -> np.ndarray:
        """A periodic Gaussian random field with this PSD: heights (nx, ny) [mm], axis 0 = x
        (:func:`gaussian_realisation`; ``amplitudes`` "random" or "fixed")."""
        return gaussian_realisation(self.psd_mm, shape, size, seed, amplitudes)

    def discrete_moments(self, shape: Tuple[int, int], size: Tuple[float, float]) -> dict:
        """Expected moments of :meth:`realisation` on this grid (mm;
        :func:`expected_discrete_moments`)."""
        return expected_discrete_moments(self.psd_mm, shape, size)
