"""Issue 23: rough-surface hysteresis loops from the direct population sums (micro/unloading.py).

References we did not write in the unloading module: the reversible elastic population sums
(``population.elastic``: closed-form height integrals, another quadrature), the loading sums
(``population.elasto_plastic``), finite differences of the unloading curve, and the physics
ordering in the plasticity index (more plastic summits -> more residual closure, stiffer
unloading).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from rough_contact.micro import population as pop
from rough_contact.micro import unloading as U
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

E_STAR = 1.14e5
S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)   # Table 1
SIG = S1.rq


def _mat(psi):
    return AsperityMaterial(E_star=E_STAR, psi=psi).resolve(S1)


@pytest.mark.parametrize("s_min", [-1.0, 1.0])
def test_elastic_surface_gives_a_closed_loop(s_min):
    """psi = 0.01: omega_c is ~1e4 sigma, no summit yields. Unloading from h_min and reloading
    (the same curve at fixed h_min) must retrace the loading curve: the reversible elastic
    population sums (closed-form height integrals) at the same separations."""
    mat = _mat(0.01)
    h_min = s_min * SIG
    h = h_min + np.array([0.0, 0.1, 0.5, 1.0, 2.0, 3.0]) * SIG
    p, k, a = U.population_unloading(S1, mat, h, h_min, n_quad=24)
    ref = pop.elastic(S1, E_STAR, h, n_quad=48)
    # measured: 2e-8 at n_quad 24 (1e-5 at the default 16, 4e-10 at 32)
    np.testing.assert_allclose(p, ref.pressure, rtol=1e-7)
    np.testing.assert_allclose(k, ref.stiffness, rtol=1e-7)
    np.testing.assert_allclose(a, ref.area_fraction, rtol=1e-7)


@pytest.mark.parametrize("psi", [1.0, 2.0])
def test_unloading_stiffness_equals_fd_of_the_unloading_curve(psi):
    """k(h, h_min) = -dp/dh at fixed h_min: at the reversal h = h_min (one-sided 4th-order
    differences into the unloading branch) and inside it (central differences)."""
    mat = _mat(psi)
    h_min = 0.9 * SIG
    d = 0.02 * SIG
    u = np.array([0.0, 1.0, 2.0, 3.0, 4.0]) * d
    p, k, _ = U.population_unloading(S1, mat, h_min + u, h_min)
    fd0 = -(-25 * p[0] + 48 * p[1] - 36 * p[2] + 16 * p[3] - 3 * p[4]) / (12 * d)
    assert abs(fd0 / k[0] - 1) < 2e-4
    hc = h_min + SIG + np.array([-2.0, -1.0, 0.0, 1.0, 2.0]) * d
    pc, kc, _ = U.population_unloading(S1, mat, hc, h_min)
    fdc = -(pc[0] - 8 * pc[1] + 8 * pc[3] - pc[4]) / (12 * d)
    assert abs(fdc / kc[2] - 1) < 2e-4
    # and the unloading branch is stiffer than the loading branch at the reversal
    kl = pop.elasto_plastic(S1, mat, np.array([h_min])).stiffness[0]
    assert k[0] > kl * (1 + 1e-3)


def _closure(mat, p_max, p_ref):
    """Loading minus unloading separation at p_ref after loading to p_max [mm]."""
    def h_load(p):
        return brentq(lambda h: np.log(pop.elasto_plastic(S1, mat, np.array([h])).pressure[0]
                                       / p), -1 * SIG, 4 * SIG, xtol=1e-5 * SIG)
    h_min = h_load(p_max)
    h_u = brentq(lambda h: np.log(U.population_unloading(S1, mat, np.array([h]), h_min)[0][0]
                                  / p_ref), h_min, h_min + 3 * SIG, xtol=1e-5 * SIG)
    return h_load(p_ref) - h_u, h_min


def test_residual_closure_and_stiffness_ratio_grow_with_plasticity_index():
    """Load to 100 MPa, unload to 1 MPa: the residual closure is ~0 for a nearly elastic
    surface (psi = 0.1) and grows with psi (more summits beyond omega_c, each flattened more);
    so does the first unloading stiffness over the loading stiffness at the same load."""
    out = []
    for psi in (0.1, 1.0, 2.0):
        mat = _mat(psi)
        c, h_min = _closure(mat, 100.0, 1.0)
        ku = U.population_unloading(S1, mat, np.array([h_min]), h_min)[1][0]
        kl = pop.elasto_plastic(S1, mat, np.array([h_min])).stiffness[0]
        out.append((c, ku / kl))
    c, r = np.array(out).T
    assert abs(c[0]) < 1e-4 * SIG and abs(r[0] - 1) < 1e-4
    assert np.all(np.diff(c) > 0.01 * SIG)
    assert np.all(np.diff(r) > 1e-3)
