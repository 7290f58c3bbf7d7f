"""Closed-form references: Hertz and Cattaneo–Mindlin / Mindlin–Deresiewicz.

Pure numpy (no DOLFINx, no MPI): the oracles the FE tests, benchmarks and demos compare with,
and the estimates some scenes use to choose their loads. Nothing here depends on a mesh.

Hertz (a sphere of radius R on an elastic half-space, effective modulus E*; normal force P,
approach delta): P = 4/3 E* sqrt(R) delta^(3/2); contact radius a^3 = 3 P R / (4 E*); peak
pressure p0 = 3 P / (2 pi a^2); p(r) = p0 sqrt(1 - r^2 / a^2). For a rigid sphere
E* = E / (1 - nu^2); for two bodies 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
(:func:`effective_modulus`).

Cattaneo–Mindlin and Mindlin–Deresiewicz (the same contact with Coulomb friction mu, shear
modulus G, a tangential force Q rising monotonically from 0, q = Q / (mu P)), valid when the
normal and tangential problems decouple (nu -> 1/2 for a rigid indenter: the coupling
parameter (1 - 2 nu) / (2 (1 - nu)) vanishes):

* stick radius c / a = (1 - q)^(1/3) (the slip annulus c < r < a grows from the edge);
* tangential approach delta(Q) = K [1 - (1 - q)^(2/3)], K = 3 mu P (2 - nu) / (16 G a), whose
  initial slope is the stiffness of a stuck circular contact, 8 G a / (2 - nu);
* energy dissipated per full cycle between +Q* and -Q* (Masing's rule applied to delta(Q)):
  W = 9 mu^2 P^2 (2 - nu) / (10 G a) [1 - (1 - q*)^(5/3) - (5 q* / 6) (1 + (1 - q*)^(2/3))],
  q* = Q* / (mu P); for small q* it tends to (2 - nu) Q*^3 / (36 G a mu P) (cubic in the
  amplitude). ``tests/unit/test_mindlin_closed_forms.py`` checks W against the numerical loop
  area of the Masing branches and the cubic limit against the series.
* fretting under an imposed displacement amplitude delta* (:func:`fretting_cycle`): partial
  slip while delta* < delta_t = K (the sliding approach), with Q* from delta(Q*) = delta* and
  the energy W above; gross slip beyond, Q* = mu P and the loop of the transition stretched by
  sliding plateaus, W = W(mu P) + 4 mu P (delta* - delta_t) = 4 mu P (delta* - 0.8 delta_t).
  The energy ratio A = W / (4 Q* delta*) rises from 0 (A ~ delta* / (12 delta_t) for small
  amplitudes) to 0.2 at the transition (Fouvry's A_t = 0.2 of a sphere on a flat) and to
  1 - 0.8 delta_t / delta* in gross slip.

Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np

from rough_contact.validation import check_scalar

__all__ = ["effective_modulus", "hertz_force", "hertz_radius", "hertz_peak_pressure",
           "hertz_pressure", "stick_ratio", "sliding_approach", "tangential_approach",
           "energy_per_cycle", "energy_per_cycle_small", "fretting_cycle",
           "fretting_energy_ratio"]


# ## Hertz
def effective_modulus(E1, nu1, E2, nu2):
    """E* of two elastic bodies: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 [MPa] (paper eq 42;
    ``E2 = inf`` for a rigid second body)."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def hertz_force(delta, radius: float, E_star: float):
    """Normal force P = 4/3 E* sqrt(R) delta^(3/2) at the approach ``delta`` [N]."""
    return 4.0 / 3.0 * E_star * np.sqrt(radius) * delta**1.5


def hertz_radius(P, radius: float, E_star: float):
    """Contact radius a = (3 P R / (4 E*))^(1/3) [mm]."""
    return (3.0 * P * radius / (4.0 * E_star)) ** (1.0 / 3.0)


def hertz_peak_pressure(P, a):
    """Peak pressure p0 = 3 P / (2 pi a^2) [MPa] of the contact radius ``a``."""
    return 3.0 * P / (2.0 * np.pi * a**2)


def hertz_pressure(r, p0, a):
    """Pressure p(r) = p0 sqrt(1 - r^2 / a^2) inside the contact, 0 outside [MPa]."""
    return p0 * np.sqrt(np.clip(1.0 - (np.asarray(r) / a) ** 2, 0.0, None))


# ## Cattaneo–Mindlin, Mindlin–Deresiewicz
def _q(Q, mu, P) -> np.ndarray:
    P = np.asarray(P, dtype=float)
    if P.ndim == 0:
        check_scalar("P", float(P), lo=0.0, unit="N")
    elif not np.all(np.isfinite(P) & (P > 0.0)):
        raise ValueError(f"P = {P.min():.6g} N is invalid: it must be finite and > 0")
    check_scalar("mu", mu, lo=0.0)
    q = np.abs(np.asarray(Q, dtype=float)) / (mu * P)
    if np.any(~np.isfinite(q)) or np.any(q > 1.0):
        raise ValueError(f"Q / (mu P) = {np.max(q):.6g} is invalid: the closed forms need "
                         "0 <= |Q| <= mu P (beyond it the contact slides)")
    return q


def stick_ratio(Q, mu: float, P: float) -> np.ndarray:
    """c / a = (1 - Q / (mu P))^(1/3) [-]."""
    return (1.0 - _q(Q, mu, P)) ** (1.0 / 3.0)


def sliding_approach(mu: float, P: float, a: float, G: float, nu: float) -> float:
    """K = 3 mu P (2 - nu) / (16 G a): the tangential approach at which the contact starts to
    slide (Q = mu P) [mm]."""
    return 3.0 * mu * P * (2.0 - nu) / (16.0 * G * a)


def tangential_approach(Q, mu: float, P: float, a: float, G: float, nu: float) -> np.ndarray:
    """delta(Q) = 3 mu P (2 - nu) / (16 G a) [1 - (1 - Q / (mu P))^(2/3)] [mm]."""
    q = _q(Q, mu, P)
    check_scalar("a", a, lo=0.0, unit="mm")
    check_scalar("G", G, lo=0.0, unit="MPa")
    return 3.0 * mu * P * (2.0 - nu) / (16.0 * G * a) * (1.0 - (1.0 - q) ** (2.0 / 3.0))


def energy_per_cycle(Q_amplitude, mu: float, P: float, a: float, G: float,
                     nu: float) -> np.ndarray:
    """Mindlin–Deresiewicz energy per full cycle +-Q* [N mm]."""
    q = _q(Q_amplitude, mu, P)
    check_scalar("a", a, lo=0.0, unit="mm")
    check_scalar("G", G, lo=0.0, unit="MPa")
    return 9.0 * mu**2 * P**2 * (2.0 - nu) / (10.0 * G * a) * (
        1.0 - (1.0 - q) ** (5.0 / 3.0) - 5.0 * q / 6.0 * (1.0 + (1.0 - q) ** (2.0 / 3.0)))


def energy_per_cycle_small(Q_amplitude, mu: float, P: float, a: float, G: float,
                           nu: float) -> np.ndarray:
    """The small-amplitude limit (2 - nu) Q*^3 / (36 G a mu P) [N mm]."""
    _q(Q_amplitude, mu, P)
    return (2.0 - nu) * np.abs(Q_amplitude) ** 3 / (36.0 * G * a * mu * P)


def fretting_cycle(delta_amplitude, mu: float, P: float, a: float, G: float, nu: float):
    """Mindlin–Deresiewicz fretting under an imposed tangential displacement amplitude delta*.

    Partial slip (delta* < delta_t = :func:`sliding_approach`): Q* solves delta(Q*) = delta*,
    Q* = mu P [1 - (1 - delta* / delta_t)^(3/2)], and the energy is :func:`energy_per_cycle`.
    Gross slip (delta* >= delta_t): Q* = mu P and the loop is the transition loop with sliding
    plateaus of length 2 (delta* - delta_t) at +-mu P: W = W(mu P) + 4 mu P (delta* - delta_t).

    Args:
        delta_amplitude: delta* >= 0 [mm] (scalar or array).
        mu, P, a, G, nu: friction coefficient, normal force [N], Hertz contact radius [mm],
            shear modulus [MPa], Poisson's ratio, as in :func:`tangential_approach`.

    Returns:
        ``(Q_amplitude, energy, ratio)``: Q* [N], W [N mm] and A = W / (4 Q* delta*) [-]
        (0 at delta* = 0).
    """
    d = np.asarray(delta_amplitude, dtype=float)
    if not np.all(np.isfinite(d) & (d >= 0.0)):
        raise ValueError(f"delta_amplitude = {np.min(d):.6g} mm is invalid: it must be finite "
                         "and >= 0")
    check_scalar("P", P, lo=0.0, unit="N")
    check_scalar("a", a, lo=0.0, unit="mm")
    check_scalar("G", G, lo=0.0, unit="MPa")
    dt = sliding_approach(mu, P, a, G, nu)
    x = np.minimum(d / dt, 1.0)
    Q = mu * P * (1.0 - (1.0 - x) ** 1.5)
    W = energy_per_cycle(Q, mu, P, a, G, nu) + 4.0 * mu * P * np.maximum(d - dt, 0.0)
    box = 4.0 * Q * d
    A = np.where(box > 0, W / np.where(box > 0, box, 1.0), 0.0)
    return Q, W, A


def fretting_energy_ratio(delta_ratio):
    """Mindlin–Deresiewicz energy ratio A as a function of delta* / delta_t alone (A does not
    depend on mu, P, a, G, nu otherwise): :func:`fretting_cycle` with delta_t = 1 [-]."""
    # unit contact: mu = P = a = 1, nu = 0, G = 3 (2 - 0) / 16 makes sliding_approach = 1
    return fretting_cycle(delta_ratio, 1.0, 1.0, 1.0, 3.0 * 2.0 / 16.0, 0.0)[2]
