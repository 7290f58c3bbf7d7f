"""The stick-front estimator (rough_contact.stick_front) on data not produced by the FE:
Cattaneo–Mindlin's closed-form tractions sampled at the vertices of jittered triangular
lattices (unstructured-mesh-like point sets of spacing a/4 ... a/16 on the half disc of the
half model), exact and perturbed; a generic square-root margin that is not Mindlin's; bad
inputs.

The synthetic tractions themselves are checked against Mindlin's force balance: the shear
integrates to Q = mu P (1 - (c/a)^3) (numerical quadrature).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from rough_contact.stick_front import contact_front, mindlin_tractions, stick_front

A, P0, MU = 0.2, 3500.0, 0.3


def lattice(h, radius, seed, jitter=0.25):
    """Radii and weights of a triangular lattice of spacing h, rotated and shifted at random
    and jittered by ``jitter`` h (Gaussian), kept on the half disc y >= 0, r < radius; each
    vertex carries the lattice's area per vertex sqrt(3)/2 h^2."""
    rng = np.random.default_rng(seed)
    n = int(radius / h) + 3
    i, j = np.meshgrid(np.arange(-2 * n, 2 * n), np.arange(-2 * n, 2 * n))
    x, y = h * (i + 0.5 * j), h * np.sqrt(3.0) / 2.0 * j
    th = rng.uniform(0.0, np.pi)
    ox, oy = rng.uniform(0.0, h, 2)
    X = np.cos(th) * x - np.sin(th) * y + ox + rng.normal(0.0, jitter * h, x.shape)
    Y = np.sin(th) * x + np.cos(th) * y + oy + rng.normal(0.0, jitter * h, x.shape)
    keep = (np.hypot(X, Y) < radius) & (Y >= 0.0)
    r = np.hypot(X[keep], Y[keep])
    return r, np.full(r.size, np.sqrt(3.0) / 2.0 * h * h)


def area_estimate(r, w, sticking, slipping):
    """The scene's former estimate sqrt(1 - A_slip / A_contact) times the contact radius."""
    return np.sqrt(1.0 - w[slipping].sum() / w[sticking | slipping].sum())


def test_synthetic_tractions_balance_mindlins_force():
    """int t dA = mu P (1 - (c/a)^3), P = 2 pi a^2 p0 / 3: the data below are Mindlin's."""
    P = 2.0 * np.pi * A**2 * P0 / 3.0
    for ca in (0.3, 0.7, 1.0):
        Q = quad(lambda r: 2 * np.pi * r * mindlin_tractions([r], ca * A, A, P0, MU)[1][0],
                 0.0, A, points=[ca * A], epsabs=0, epsrel=1e-11)[0]
        assert Q == pytest.approx(MU * P * (1.0 - ca**3), rel=1e-8, abs=1e-9 * MU * P)


@pytest.mark.parametrize("ratio", [4, 8, 16])
@pytest.mark.parametrize("ca", [1.0, 0.9, 0.75, 0.6, 0.46])
def test_mindlin_front_recovered_exactly(ratio, ca):
    """m^2 = (mu p0 / a)^2 (c^2 - r^2) is linear in r^2: the fit returns c to rounding on any
    point set, where the area estimate is off by the rings' share."""
    r, w = lattice(A / ratio, 1.5 * A, seed=ratio)
    c = ca * A
    p, t, st, sl = mindlin_tractions(r, c, A, P0, MU)
    f = stick_front(r, p, t, MU, w, st, sl)
    assert f.radius == pytest.approx(c, rel=1e-10)
    assert f.residual < 1e-8 and f.n_misplaced == 0 and f.n_band >= 2
    assert contact_front(r, p, w, p > 0).radius == pytest.approx(A, rel=1e-10)


def test_area_estimate_is_quantised_where_the_front_is_not():
    """On the same a/4 lattices the area estimate errs by percents (a ring of vertices is a
    large share of the area), the front fit by rounding only."""
    worst_area, worst_front = 0.0, 0.0
    for seed in range(10):
        r, w = lattice(A / 4, 1.5 * A, seed=seed)
        for ca in (0.9, 0.8, 0.7):
            p, t, st, sl = mindlin_tractions(r, ca * A, A, P0, MU)
            worst_area = max(worst_area, abs(area_estimate(r, w, st, sl) / ca - 1.0))
            worst_front = max(worst_front,
                              abs(stick_front(r, p, t, MU, w, st, sl).radius / (ca * A) - 1))
    assert worst_area > 0.02
    assert worst_front < 1e-10


@pytest.mark.parametrize("ratio", [8, 16])
def test_noise_on_the_shear(ratio):
    """Random error of 1 % of mu p0 on every shear value (20 lattices per c): the requirement
    is c within 1 %, the estimator must stay well inside it (mean bias < 0.2 %, each draw < 1 %)
    for c/a >= 0.5."""
    rng = np.random.default_rng(7)
    for ca in (1.0, 0.8, 0.6, 0.5):
        errs = []
        for seed in range(20):
            r, w = lattice(A / ratio, 1.5 * A, seed=100 * ratio + seed)
            p, t, st, sl = mindlin_tractions(r, ca * A, A, P0, MU)
            t = np.abs(t + rng.normal(0.0, 0.01 * MU * P0, t.size) * (r < A))
            errs.append(stick_front(r, p, t, MU, w, st, sl).radius / (ca * A) - 1.0)
        errs = np.array(errs)
        assert abs(errs.mean()) < 2e-3, (ca, errs.mean())
        assert np.abs(errs).max() < 1e-2, (ca, np.abs(errs).max())


def test_generic_square_root_margin_bias_shrinks_with_the_band():
    """A margin that vanishes like sqrt(c - r) but is not Mindlin's,
    m^2 = (c^2 - r^2)(1 + k r^2 / c^2) (k = +-0.5: the prefactor varies by 50 % over the stick
    zone): the line through the band is then a secant, and its zero moves off c. With
    u = c^2 - r^2, m^2 = (1 + k) u - k u^2 / c^2; the least-squares line of u^2 over
    u in [0, U] is U u - U^2 / 6, so the zero moves by k U^2 / (6 (1 + k)) in u, i.e.
    c by about k b^2 / (3 (1 + k)) c for a band b (U = 2 b c^2 to first order): second order
    in the band (the square-root law is local), of the sign of k."""
    c = 0.5 * A
    r, w = lattice(A / 16, 1.5 * A, seed=3)
    st, sl = r < c, (r >= c) & (r < A)
    p = np.full(r.size, 1000.0)
    for k in (0.5, -0.5):
        m = np.sqrt(np.clip(c * c - r * r, 0.0, None) * (1.0 + k * (r / c) ** 2))
        errs = [stick_front(r, p, MU * p - m, MU, w, st, sl, band=b).radius / c - 1.0
                for b in (1.0, 0.5, 0.25, 0.1)]
        assert np.all(np.diff(np.abs(errs)) < 0), errs
        assert np.all(np.sign(errs) == np.sign(k)), errs
        for b, e in zip((0.5, 0.25, 0.1), errs[1:]):
            assert abs(e) < abs(k) * b * b / (3.0 * (1.0 - abs(k))), (k, b, e)


def test_stuck_islands_among_slipping_points():
    """Stuck points left in the slip annulus (a ragged discrete front) with a small margin pull
    the plain fit outwards; ``inside_slip`` fits the stick zone proper and returns c again."""
    r, w = lattice(A / 8, 1.5 * A, seed=5)
    c = 0.6 * A
    p, t, st, sl = mindlin_tractions(r, c, A, P0, MU)
    islands = np.flatnonzero(sl & (r < c + 0.3 * A))[::3]       # every third annulus point
    st, sl = st.copy(), sl.copy()
    st[islands], sl[islands] = True, False
    t = t.copy()
    t[islands] = MU * p[islands] * (1.0 - 0.05)                  # a margin of 5 % of mu p
    plain = stick_front(r, p, t, MU, w, st, sl)
    inner = stick_front(r, p, t, MU, w, st, sl, inside_slip=True)
    assert plain.radius > 1.01 * c
    assert plain.n_misplaced >= islands.size
    assert inner.radius == pytest.approx(c, rel=1e-10)
    # without slipping points the option changes nothing
    none = np.zeros(r.size, dtype=bool)
    p, t, st, _ = mindlin_tractions(r, A, A, P0, MU)
    assert stick_front(r, p, t, MU, w, st, none, inside_slip=True).radius == \
        pytest.approx(A, rel=1e-10)


def test_order_of_the_points_does_not_matter():
    r, w = lattice(A / 8, 1.5 * A, seed=11)
    p, t, st, sl = mindlin_tractions(r, 0.7 * A, A, P0, MU)
    t = t * (1.0 + 0.02 * np.sin(37.0 * r / A))               # not exactly Mindlin's
    f = stick_front(r, p, t, MU, w, st, sl)
    perm = np.random.default_rng(0).permutation(r.size)
    g = stick_front(r[perm], p[perm], t[perm], MU, w[perm], st[perm], sl[perm])
    assert g.radius == pytest.approx(f.radius, rel=1e-12)
    assert g.n_band == f.n_band


def test_no_stuck_point_and_too_few():
    r = np.array([0.1, 0.2, 0.3])
    p = np.ones(3)
    t = 0.3 * p
    none = np.zeros(3, dtype=bool)
    assert stick_front(r, p, t, MU, np.ones(3), none, ~none).radius == 0.0
    one = np.array([True, False, False])
    f = stick_front(r, p, 0.1 * p, MU, np.ones(3), one, ~one)
    assert np.isnan(f.radius) and f.n_band == 1
    # a margin that grows outwards has no front to extrapolate to
    rising = stick_front(r, p, 0.3 - r, MU, np.ones(3), ~none, none)
    assert np.isnan(rising.radius)


def test_bad_inputs_refused():
    r = np.array([0.0, 0.1, 0.2, 0.3])
    p = np.array([4.0, 3.0, 2.0, 1.0])
    t = np.zeros(4)
    w = np.ones(4)
    st = np.array([True, True, True, False])
    sl = ~st
    with pytest.raises(ValueError, match="pressure has 3 entries"):
        stick_front(r, p[:3], t, MU, w, st, sl)
    with pytest.raises(ValueError, match="r has shape"):
        stick_front(r[:, None], p, t, MU, w, st, sl)
    with pytest.raises(ValueError, match="r = -0.1 mm is invalid"):
        stick_front(np.array([0.0, -0.1, 0.2, 0.3]), p, t, MU, w, st, sl)
    with pytest.raises(ValueError, match="both sticking and slipping"):
        stick_front(r, p, t, MU, w, st, np.ones(4, dtype=bool))
    with pytest.raises(ValueError, match="mu = 0"):
        stick_front(r, p, t, 0.0, w, st, sl)
    with pytest.raises(ValueError, match="band = 1.5"):
        stick_front(r, p, t, MU, w, st, sl, band=1.5)
    with pytest.raises(ValueError, match="band = 0"):
        stick_front(r, p, t, MU, w, st, sl, band=0.0)
    with pytest.raises(ValueError, match="max_iterations = 0"):
        stick_front(r, p, t, MU, w, st, sl, max_iterations=0)
    with pytest.raises(ValueError, match="weights = -1.0 mm"):
        stick_front(r, p, t, MU, np.array([1.0, -1.0, 1.0, 1.0]), st, sl)
    with pytest.raises(ValueError, match="pressure = nan MPa at a stuck point"):
        stick_front(r, np.array([4.0, np.nan, 2.0, 1.0]), t, MU, w, st, sl)
    with pytest.raises(ValueError, match="shear = -1.0 MPa"):
        stick_front(r, p, np.array([0.0, -1.0, 0.0, 0.0]), MU, w, st, sl)
    with pytest.raises(ValueError, match="c = 0.3 mm is invalid"):
        mindlin_tractions(r, 0.3, 0.2, P0, MU)


def test_scene_refuses_bad_front_arguments():
    """mindlin.run checks the front's arguments before it builds a mesh."""
    from rough_contact.scenes import mindlin
    with pytest.raises(ValueError, match="front_band = 0"):
        mindlin.run(front_band=0.0)
    with pytest.raises(ValueError, match="gather_radius = -1"):
        mindlin.run(gather_radius=-1.0)


def test_band_of_one_ring_falls_back_to_all_stuck_points():
    """A coarse stick zone: the centre point and one ring whose margins scatter more than they
    fall across the ring's small spread of radii (the state of a tiny P2 run, contact elements
    a/2, at Q/mu P = 0.67, rounded). The band of the first fit holds only the ring, where the
    line rises; the estimate then uses every stuck point instead of giving up."""
    r = np.array([0.0, 0.097550, 0.097550, 0.097972, 0.098600, 0.1696, 0.1951])
    p = np.array([3258.1, 2841.1, 2855.3, 2863.8, 2818.9, 1711.1, 1073.0])
    t = np.array([239.37, 443.05, 419.48, 309.25, 396.07, 513.33, 321.89])
    w = np.array([0.00416, 0.00414, 0.00416, 0.00840, 0.00834, 0.00826, 0.00412])
    st = np.array([True] * 5 + [False] * 2)
    ring = stick_front(r[1:], p[1:], t[1:], MU, w[1:], st[1:], ~st[1:], band=1.0)
    assert np.isnan(ring.radius)                     # the ring alone: m^2 does not fall
    f = stick_front(r, p, t, MU, w, st, ~st)
    assert np.isfinite(f.radius) and r[4] < f.radius < r[5]
    assert f.n_band == 5
