"""Rigid counter-surfaces: exact distances and normals against closed forms, errors."""

from __future__ import annotations

import numpy as np
import pytest

from rough_contact.fem.rigid import (RigidCylinder, RigidPlane, RigidSphere, RigidSurface,
                                     SignedDistanceSurface)

RNG = np.random.default_rng(4)
X = RNG.uniform(-3, 3, (50, 3))


def test_plane():
    s = RigidPlane((0, 0, 1.0), (0, 0, 2.0))
    g, n = s.gap_and_normal(X)
    np.testing.assert_allclose(g, X[:, 2] - 1.0, atol=1e-15)
    np.testing.assert_allclose(n, np.tile([0, 0, 1.0], (50, 1)))
    assert isinstance(s, RigidSurface)


def test_sphere_and_cylinder_closed_forms():
    c, R = np.array([0.5, -1.0, 2.0]), 1.5
    g, n = RigidSphere(c, R).gap_and_normal(X)
    d = X - c
    np.testing.assert_allclose(g, np.sqrt((d**2).sum(1)) - R, rtol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-14)
    # closest point on the sphere is c + R n, and the point is c + (R + g) n
    np.testing.assert_allclose(c + (R + g)[:, None] * n, X, atol=1e-13)
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    g, n = RigidCylinder((0, 0, 0), (2.0, 2.0, 0.0), 0.7).gap_and_normal(X)
    radial = X - np.outer(X @ axis, axis)
    np.testing.assert_allclose(g, np.linalg.norm(radial, axis=1) - 0.7, rtol=1e-14)
    np.testing.assert_allclose(n @ axis, 0.0, atol=1e-14)


def test_signed_distance_matches_the_sphere_with_and_without_gradient():
    c, R = np.array([0.0, 0.0, 2.0]), 1.0
    phi = lambda x: np.linalg.norm(x - c, axis=1) - R                       # noqa: E731
    grad = lambda x: (x - c) / np.linalg.norm(x - c, axis=1)[:, None]       # noqa: E731
    g0, n0 = RigidSphere(c, R).gap_and_normal(X)
    for s, tol in ((SignedDistanceSurface(phi, grad), 1e-14), (SignedDistanceSurface(phi), 1e-8)):
        g, n = s.gap_and_normal(X)
        np.testing.assert_allclose(g, g0, rtol=1e-14)
        np.testing.assert_allclose(n, n0, atol=tol)


def test_errors():
    with pytest.raises(ValueError, match=r"RigidSphere.radius = -1.0 mm is invalid"):
        RigidSphere((0, 0, 0), -1.0)
    with pytest.raises(ValueError, match="RigidCylinder.axis = .* nonzero"):
        RigidCylinder((0, 0, 0), (0, 0, 0), 1.0)
    with pytest.raises(ValueError, match="RigidPlane.point = .* 3 finite numbers"):
        RigidPlane((0, 0), (0, 0, 1))
    with pytest.raises(ValueError, match="centre of the RigidSphere"):
        RigidSphere((0, 0, 0), 1.0).gap_and_normal(np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"phi returned shape \(2,\)"):
        SignedDistanceSurface(lambda x: np.zeros(2)).gap_and_normal(X)
