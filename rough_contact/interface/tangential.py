"""Tangential (shear) contact stiffness: Mindlin's ratio kN/kT, eqs (96)-(97), Table 3.

Units: stiffnesses per area in MPa/mm; ratios are dimensionless.

Mindlin (1949) gives, for two bodies with the same elastic constants and an elliptic contact
with semi-axis B along the tangential force and A across it,

    B < A:  e^2 = 1 - B^2/A^2,
            kN/kT = pi(2-nu)/(4(1-nu)) / K(e) [2K(e)/pi - nu N(e)/(2 pi^2 (2-nu) e)]
    B > A:  k1^2 = 1 - A^2/B^2, the same with K(k1) and N1(k1) = -N(k1),
    (97)    N(e) = 4 pi [(2/e - e) K(e) - (2/e) E(e)].

Writing N(e)/e = 4 pi [2 D(m) - K(m)] with m = e^2 and D(m) = (K - E)/m = R_D(0, 1-m, 1)/3
(Carlson's symmetric integral) removes the 0/0 at B = A and keeps full accuracy for
B/A -> 0 or infinity (K through ``ellipkm1``):

    kN/kT = (2-nu)/(2(1-nu)) [1 - s nu (2D - K) / ((2-nu) K)],  s = +1 (B < A), -1 (B > A).

Limits: nu = 0 -> 1; B/A -> 0 -> 1; B/A -> infinity -> 1/(1-nu); B = A -> (2-nu)/(2(1-nu)),
and ratio(r) + ratio(1/r) = (2-nu)/(1-nu) exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import elliprd, ellipkm1

from ..validation import check_scalar

__all__ = ["normal_to_tangential_ratio", "TangentialStiffness"]


def normal_to_tangential_ratio(b2_over_a2, nu):
    """Mindlin's ratio kN/kT of normal to tangential contact stiffness, eq (96).

    Args:
        b2_over_a2: squared axis ratio B^2/A^2 of the contact ellipse (scalar or array), B the
            semi-axis along the tangential force [-], > 0 and finite.
        nu: Poisson's ratio of both bodies (scalar or array broadcastable), in (-1, 0.5] [-].

    Returns:
        kN/kT (float or ndarray, broadcast shape), between 1 and 1/(1-nu) for nu >= 0.

    Raises:
        ValueError: if an axis ratio is not positive and finite or nu is outside (-1, 0.5].
    """
    r = np.asarray(b2_over_a2, dtype=float)
    nu_arr = np.asarray(nu, dtype=float)
    if not np.all(np.isfinite(r) & (r > 0.0)):
        raise ValueError(f"b2_over_a2 = {b2_over_a2!r} must be finite and > 0")
    if not np.all(np.isfinite(nu_arr) & (nu_arr > -1.0) & (nu_arr <= 0.5)):
        raise ValueError(f"nu = {nu!r} must lie in (-1, 0.5]")
    r, nu_arr = np.broadcast_arrays(r, nu_arr)
    sign = np.where(r <= 1.0, 1.0, -1.0)
    m1 = np.where(r <= 1.0, r, 1.0 / r)  # complementary parameter 1 - m, in (0, 1]
    kk = ellipkm1(m1)  # K(m), accurate as m -> 1
    dd = elliprd(0.0, m1, 1.0) / 3.0  # D(m) = (K - E)/m, no cancellation as m -> 0
    out = (2.0 - nu_arr) / (2.0 * (1.0 - nu_arr)) * (
        1.0 - sign * nu_arr * (2.0 * dd - kk) / ((2.0 - nu_arr) * kk)
    )
    return out[()] if out.ndim == 0 else out


@dataclass(frozen=True)
class TangentialStiffness:
    """Tangential stiffnesses per axis as multiples of the normal stiffness: kT_i = c_i kN(h).

    The paper's examples give c directly (kTx = kTy = 0.7 kN; kTx = 0.7 kN, kTy = kN); Mindlin's
    ratio gives it from the contact-ellipse shape (``from_mindlin``). Because kT follows kN(h),
    the tangential stiffness vanishes when the contact opens.

    Args:
        kt_over_kn: (c_x, c_y) = (kTx/kN, kTy/kN) along the local x (grain) and y axes [-],
            each > 0 and finite.
    """

    kt_over_kn: tuple[float, float] = (1.0, 1.0)

    def __post_init__(self) -> None:
        c = np.asarray(self.kt_over_kn, dtype=float)
        if c.shape != (2,):
            raise ValueError(f"kt_over_kn must be a pair (c_x, c_y), got {self.kt_over_kn!r}")
        object.__setattr__(self, "kt_over_kn", tuple(
            check_scalar(name, v, lo=0.0)
            for name, v in zip(("kt_over_kn[0] (kTx/kN)", "kt_over_kn[1] (kTy/kN)"), c)))

    @classmethod
    def from_mindlin(cls, axis_ratio_sq: float, nu: float) -> TangentialStiffness:
        """Mindlin stiffnesses for a contact ellipse with (a_x/a_y)^2 = axis_ratio_sq.

        Args:
            axis_ratio_sq: (semi-axis along x / semi-axis along y)^2 of the contact ellipse [-].
            nu: Poisson's ratio of both bodies, in (-1, 0.5] [-].

        Returns:
            TangentialStiffness with c_x = 1/ratio(a_x^2/a_y^2), c_y = 1/ratio(a_y^2/a_x^2).
        """
        r = check_scalar("axis_ratio_sq", axis_ratio_sq, lo=0.0)
        rx = normal_to_tangential_ratio(r, nu)
        ry = normal_to_tangential_ratio(1.0 / r, nu)
        return cls((1.0 / float(rx), 1.0 / float(ry)))

    @classmethod
    def from_surface(cls, surface, nu: float) -> TangentialStiffness:
        """Mindlin stiffnesses for the typical asperity contact of an anisotropic surface.

        The contact ellipse of a summit has b^2/a^2 = (w4/w6) sqrt(m40/m04), eq (27) (a along x,
        b along y); for the typical summit (w4 = w6) the squared axis ratio along x is
        (a/b)^2 = sqrt(m04/m40). A grain along x (m40 < m04) gives long contacts along x, hence
        a softer kTx.

        Args:
            surface: object with spectral moments ``m40``, ``m04`` (e.g. ``SpectralMoments``; the
                ratio does not depend on the length unit).
            nu: Poisson's ratio of both bodies, in (-1, 0.5] [-].
        """
        m40 = check_scalar("surface.m40", surface.m40, lo=0.0)
        m04 = check_scalar("surface.m04", surface.m04, lo=0.0)
        return cls.from_mindlin(np.sqrt(m04 / m40), nu)

    @property
    def isotropic(self) -> bool:
        """True when kTx == kTy."""
        return self.kt_over_kn[0] == self.kt_over_kn[1]

    def evaluate(self, kn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tangential stiffnesses (kTx, kTy), each (n,) [MPa/mm], at normal stiffness kn (n,)."""
        kn = np.asarray(kn, dtype=float)
        return self.kt_over_kn[0] * kn, self.kt_over_kn[1] * kn
