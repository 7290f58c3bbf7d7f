"""Spence's frictional Hertz annulus (rough_contact.frictional_hertz) against results it does
not compute itself:

* the ring kernel, integrated over rings, against the Hankel-transform solution of a smooth
  radial shear (q = r exp(-r^2), whose order-1 transform is xi/4 exp(-xi^2/4));
* the pressure term against quadrature of Hertz's pressure;
* Dundurs' beta in the limits everyone knows (rigid on nu = 0.49; identical bodies);
* beta = 0 (Cattaneo–Mindlin's premise): nothing slips under the normal load;
* Spence's self-similarity, which the incremental solver does not impose: c/a the same at
  every load, and the radial displacement of the stuck rings proportional to r^2;
* ring convergence, and bad inputs.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import j1

from rough_contact.frictional_hertz import (coupling_parameter, hertz_radial_term,
                                            ring_influence, slip_annulus)


def test_ring_influence_against_the_hankel_solution():
    edges = np.linspace(0.0, 5.0, 601)
    r = 0.5 * (edges[1:] + edges[:-1])
    u = ring_influence(edges) @ (r * np.exp(-r ** 2))
    for x in (0.3, 1.0, 2.0, 3.5):
        i = int(np.argmin(np.abs(r - x)))
        exact = quad(lambda xi: xi / 4.0 * np.exp(-xi ** 2 / 4.0) * j1(xi * r[i]), 0.0, 40.0,
                     limit=200)[0]
        assert abs(u[i] / exact - 1.0) < 1e-4, (r[i], u[i], exact)


def test_hertz_radial_term_against_quadrature():
    a, p0 = 0.7, 3.0
    for x in (0.1, 0.5, 0.69, 0.9, 2.0):
        direct = quad(lambda s: p0 * np.sqrt(max(1.0 - (s / a) ** 2, 0.0)) * s, 0.0,
                      min(x, a))[0] / x
        assert hertz_radial_term(x, a, p0) == pytest.approx(direct, rel=1e-10)


def test_coupling_parameter_limits():
    nu = 0.49
    assert abs(coupling_parameter(np.inf, 0.3, 2e5, nu)) == pytest.approx(
        (1 - 2 * nu) / (2 * (1 - nu)), rel=1e-14)
    assert coupling_parameter(2e5, 0.3, 2e5, 0.3) == 0.0
    assert coupling_parameter(2e5, 0.3, np.inf, 0.2) == pytest.approx(
        (1 - 2 * 0.3) / (2 * (1 - 0.3)), rel=1e-14)


def test_no_coupling_no_slip():
    res = slip_annulus(0.0, rings=60)
    assert np.all(res.stick_ratio == 1.0) and np.all(res.sticking[res.r < 1.0])
    assert np.max(np.abs(res.shear)) < 1e-12


@pytest.fixture(scope="module")
def strong():
    return slip_annulus(1.5, rings=120)


def test_slip_annulus_is_self_similar(strong):
    """c/a constant while the load rises (Spence): within one ring from a = 0.4 to 1."""
    ratios = strong.stick_ratio[strong.a >= 0.4]
    assert ratios.min() < 1.0                       # an annulus slips at this beta / mu
    assert ratios.max() - ratios.min() <= 1.0 / (0.4 * strong.rings) + 1e-12


def test_slip_zone_is_one_outer_annulus(strong):
    """Spence's structure: a stuck disc inside one slipping annulus. The solver lets every ring
    stick or slip on its own, so an interleaved pattern would show as the innermost slipping
    ring lying inside the outermost stuck one; from a = 0.4 on the two edges coincide."""
    late = strong.a >= 0.4
    np.testing.assert_allclose(strong.inner_slip_ratio[late], strong.stick_ratio[late],
                               atol=1e-12)
    slip = (strong.r < 1.0) & ~strong.sticking
    assert np.all(strong.r[slip] > strong.r[strong.sticking].max())


def test_coulomb_conditions_and_r2_displacement(strong):
    q, p, st = strong.shear, strong.pressure, strong.sticking
    slip = (strong.r < 1.0) & ~st
    assert np.all(np.abs(q[st]) <= p[st] * (1 + 1e-10))
    np.testing.assert_allclose(np.abs(q[slip]), p[slip], rtol=1e-12)
    assert np.all(q[slip] > 0.0)          # the pressure pulls inwards: friction pushes out
    # stuck rings keep the displacement they had when they stuck: self-similarity makes it
    # C r^2 (a consequence the solver does not impose). A ring at r stuck when the contact
    # radius was r / (c/a): taken from those that stuck once the contact held >= 30 rings
    # (the first few stuck while the contact was one or two rings wide, not self-similar)
    # and before the last increments (r < 0.8 c)
    edges = np.linspace(0.0, 1.0, strong.rings + 1)
    u = ring_influence(edges) @ q - 1.5 * hertz_radial_term(strong.r, 1.0, 1.0)
    k = strong.stick_ratio[-1]
    inner = (strong.r > 0.25 * k) & (strong.r < 0.8 * k)
    ratio = u[inner] / strong.r[inner] ** 2
    assert np.ptp(ratio) <= 0.02 * np.abs(ratio).mean()


def test_ring_convergence():
    c = [slip_annulus(1.0, rings=n).stick_ratio[-1] for n in (100, 200)]
    assert 0.5 < c[1] < 1.0 and abs(c[0] - c[1]) < 0.01


@pytest.mark.parametrize("kwargs,match", [
    (dict(beta_over_mu=-0.1), "beta_over_mu = -0.1 is invalid"),
    (dict(beta_over_mu=float("nan")), "beta_over_mu = nan is invalid"),
    (dict(beta_over_mu=0.1, rings=3), "rings = 3 is invalid"),
    (dict(beta_over_mu=0.1, rings=10.0), "rings = 10.0 is invalid"),
])
def test_bad_inputs(kwargs, match):
    with pytest.raises(ValueError, match=match):
        slip_annulus(**kwargs)


def test_bad_material_inputs():
    with pytest.raises(ValueError, match="nu1 = 0.6 is invalid"):
        coupling_parameter(np.inf, 0.6, 2e5, 0.3)
    with pytest.raises(ValueError, match="E2 = -1"):
        coupling_parameter(np.inf, 0.3, -1.0, 0.3)
    with pytest.raises(ValueError, match="at least one body must be elastic"):
        coupling_parameter(np.inf, 0.3, np.inf, 0.3)
    with pytest.raises(ValueError, match="edges"):
        ring_influence(np.array([0.0, 0.5, 0.4]))
