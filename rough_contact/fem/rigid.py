"""Rigid counter-surfaces: plane, sphere, cylinder and any signed-distance function.

A rigid surface gives, at points x (n, 3) [mm] of the first (deformable) contact surface, the
signed distance g (n,) [mm] to the surface (positive outside the rigid body, i.e. open) and the
unit outward normal of the rigid body at the closest point (n, 3) (pointing from the rigid body
towards the point). ``ContactInterface(..., rigid=...)`` evaluates both ONCE at set-up, at the
undeformed positions, and linearises the gap about them: g(u) = g0 + n0 . u (small sliding, as
for the paper's interface; exact for the plane). This is accurate while the displacements are
small against the indenter's radius (the neglected term is of order |u_T|^2 / (2 R)).

Units: mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional, Protocol, runtime_checkable

import numpy as np

from rough_contact.validation import check_scalar

__all__ = ["RigidSurface", "RigidPlane", "RigidSphere", "RigidCylinder",
           "SignedDistanceSurface"]


@runtime_checkable
class RigidSurface(Protocol):
    """What ``ContactInterface`` needs from a rigid counter-surface."""

    def gap_and_normal(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance g (n,) [mm] (> 0 outside the rigid body) and unit outward normal of
        the rigid body (n, 3) at points x (n, 3) [mm]; vectorised."""
        ...


def _vector(name: str, v, unit_length: bool = False) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} = {v!r} is invalid: it must be 3 finite numbers")
    if unit_length:
        n = np.linalg.norm(a)
        if n == 0.0:
            raise ValueError(f"{name} = {v!r} is invalid: it must be a nonzero vector")
        a = a / n
    return a


def _points(x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"points of shape {x.shape} must be (n, 3)")
    return x


def _radius(name: str, value) -> float:
    return check_scalar(name, value, lo=0.0, unit="mm")


def _radial(d: np.ndarray, radius: float, where: str):
    """Gap |d| - radius and outward normal d / |d| of a round rigid body (sphere, cylinder) at
    points whose vectors from its centre (or axis) are ``d`` (n, 3) [mm]."""
    r = np.linalg.norm(d, axis=1)
    if np.any(r == 0.0):
        raise ValueError(f"a contact point lies {where}: its normal is undefined")
    return r - radius, d / r[:, None]


@dataclass(frozen=True)
class RigidPlane:
    """Half-space behind the plane through ``point`` with outward unit ``normal`` (towards the
    deformable body)."""

    point: tuple
    normal: tuple

    def __post_init__(self):
        object.__setattr__(self, "point", _vector("RigidPlane.point", self.point))
        object.__setattr__(self, "normal", _vector("RigidPlane.normal", self.normal, True))

    def gap_and_normal(self, x):
        x = _points(x)
        n = np.broadcast_to(self.normal, x.shape).copy()
        return (x - self.point) @ self.normal, n


@dataclass(frozen=True)
class RigidSphere:
    """Rigid ball of ``radius`` [mm] centred at ``center`` [mm]."""

    center: tuple
    radius: float

    def __post_init__(self):
        object.__setattr__(self, "center", _vector("RigidSphere.center", self.center))
        object.__setattr__(self, "radius", _radius("RigidSphere.radius", self.radius))

    def gap_and_normal(self, x):
        return _radial(_points(x) - self.center, self.radius, "at the centre of the RigidSphere")


@dataclass(frozen=True)
class RigidCylinder:
    """Rigid infinite cylinder of ``radius`` [mm] about the axis through ``point`` along
    ``axis``."""

    point: tuple
    axis: tuple
    radius: float

    def __post_init__(self):
        object.__setattr__(self, "point", _vector("RigidCylinder.point", self.point))
        object.__setattr__(self, "axis", _vector("RigidCylinder.axis", self.axis, True))
        object.__setattr__(self, "radius", _radius("RigidCylinder.radius", self.radius))

    def gap_and_normal(self, x):
        d = _points(x) - self.point
        return _radial(d - np.outer(d @ self.axis, self.axis), self.radius,
                       "on the axis of the RigidCylinder")


@dataclass(frozen=True)
class SignedDistanceSurface:
    """Any rigid body given by a vectorised signed distance ``phi(x (n, 3)) -> (n,)`` [mm]
    (> 0 outside). The normal is ``gradient(x) -> (n, 3)`` normalised, or, without it, central
    finite differences of phi with step ``step`` [mm]."""

    phi: Callable[[np.ndarray], np.ndarray]
    gradient: Optional[Callable[[np.ndarray], np.ndarray]] = None
    step: float = 1e-6

    def __post_init__(self):
        if not callable(self.phi):
            raise TypeError("SignedDistanceSurface.phi must be a callable x (n, 3) -> (n,)")
        check_scalar("SignedDistanceSurface.step", self.step, lo=0.0, unit="mm")

    def gap_and_normal(self, x):
        x = _points(x)
        g = np.asarray(self.phi(x), dtype=float)
        if g.shape != (len(x),) or not np.all(np.isfinite(g)):
            raise ValueError(f"SignedDistanceSurface.phi returned shape {g.shape} or non-finite "
                             f"values for {len(x)} points; it must return ({len(x)},) finite")
        if self.gradient is not None:
            grad = np.asarray(self.gradient(x), dtype=float)
        else:
            h = self.step
            grad = np.stack([(np.asarray(self.phi(x + h * e)) - np.asarray(self.phi(x - h * e)))
                             / (2 * h) for e in np.eye(3)], axis=1)
        if grad.shape != x.shape or not np.all(np.isfinite(grad)):
            raise ValueError("SignedDistanceSurface: the gradient is not finite (n, 3)")
        norm = np.linalg.norm(grad, axis=1)
        if np.any(norm == 0.0):
            raise ValueError("SignedDistanceSurface: zero gradient at a contact point")
        return g, grad / norm[:, None]
