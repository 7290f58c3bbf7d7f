"""The projection's 3 x 3 solver (``rough_contact.fem.pairing.geometry._solve3``, Cramer's rule,
vectorised) against LAPACK, and its singular-system flag."""

from __future__ import annotations

import numpy as np

from rough_contact.fem.pairing.geometry import _solve3


def test_solve3_matches_lapack_and_flags_singular_systems():
    rng = np.random.default_rng(0)
    m = 2000
    J = rng.normal(size=(m, 3, 3))
    # the projection's systems: two tangent columns of facet size, the unit normal
    J[:, :, :2] *= rng.uniform(1e-3, 10.0, (m, 1, 1))
    b = rng.normal(size=(m, 3))
    x, ok = _solve3(J, b)
    ref = np.linalg.solve(J, b[:, :, None])[..., 0]
    assert ok.all()
    cond = np.linalg.cond(J)
    err = np.linalg.norm(x - ref, axis=1) / np.linalg.norm(ref, axis=1)
    assert np.all(err <= 1e-14 * cond), (err / cond).max()
    np.testing.assert_allclose(np.einsum("pij,pj->pi", J, x), b, rtol=0,
                               atol=1e-12 * np.abs(b).max() * cond.max())
    # singular systems (a zero tangent column, a zero matrix) are flagged, their x is 0
    J[:5, :, 1] = 0.0
    J[5] = 0.0
    x, ok = _solve3(J, b)
    assert not ok[:6].any() and ok[6:].all()
    assert np.all(x[:6] == 0.0)
