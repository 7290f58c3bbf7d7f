"""The numpy kernels of the pairing and of the matrix rebuild: the projection's 3 x 3 solver
(``rough_contact.fem.pairing.geometry._solve3``, Cramer's rule, vectorised) against LAPACK
with its singular-system flag, and the scalar CSR expansion of a node pattern
(``rough_contact.fem.compat.scalar_csr``) against scipy's Kronecker product."""

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


def test_scalar_csr_is_the_kronecker_expansion_of_the_node_pattern():
    """compat.scalar_csr against scipy: the node pattern (rows sorted, columns sorted within a
    row, empty rows included) Kronecker-multiplied by a bs x bs block of ones."""
    import scipy.sparse as sp

    from rough_contact.fem.compat import scalar_csr
    rng = np.random.default_rng(1)
    n_rows, n_cols, bs = 300, 1000, 3
    dense = rng.random((n_rows, n_cols)) < 0.01
    dense[[5, 17, 299]] = False                      # empty node rows
    rows, cols = np.nonzero(dense)                   # row-major: rows sorted, cols within
    for dtype in (np.int32, np.int64):
        indptr, indices = scalar_csr(rows, cols, n_rows, bs, dtype)
        ref = sp.kron(sp.csr_matrix(dense.astype(float)), np.ones((bs, bs)), format="csr")
        ref.sort_indices()
        assert indptr.dtype == dtype and indices.dtype == dtype
        np.testing.assert_array_equal(indptr, ref.indptr)
        np.testing.assert_array_equal(indices, ref.indices)
