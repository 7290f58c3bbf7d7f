"""Surface statistics (paper section 2, eqs 10-18, 69-73) and moments from a height map."""
from __future__ import annotations

import math

import numpy as np
import pytest

from rough_contact.surface import SpectralMoments, moments_from_height_map, plasticity_index, psum

# surfaces of Tables 1 and 2 (micrometre convention)
TABLE1 = dict(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
TABLE2 = dict(m00=3.0, m20=1.0, m02=81.0, m40=1.0, m04=6561.0)


def _summit_quadrature(s: SpectralMoments, n=64):
    """Tensor Gauss-Legendre rule for integrals over (w1, w4, w6) of the pdf (14).

    w4, w6 in (0, 12/sqrt(mu)); w1 in c +- 12 around the conditional mean
    c = sqrt(b1) w4 + sqrt(b2) w6 (an independent numerical route: no closed form in w1).
    """
    x, w = np.polynomial.legendre.leggauss(n)
    W = 12.0 / math.sqrt(s.mu)
    w4 = 0.5 * W * (x + 1)
    ww4 = 0.5 * W * w
    W4, W6 = np.meshgrid(w4, w4, indexing="ij")
    WW = np.outer(ww4, ww4)
    c = math.sqrt(s.beta1) * W4 + math.sqrt(s.beta2) * W6
    w1 = c[..., None] + 12.0 * x
    wt = WW[..., None] * 12.0 * w
    return np.broadcast_to(W4[..., None], w1.shape), np.broadcast_to(W6[..., None], w1.shape), w1, wt


def test_units_are_converted_to_mm():
    a = SpectralMoments(**TABLE1)
    b = SpectralMoments(m00=0.0625e-6, m20=8e-5, m02=8e-4, m40=1.04, m04=104.0, unit="mm")
    for name in ("m00", "m20", "m02", "m40", "m04", "mu", "summit_density", "summit_sigma"):
        assert getattr(a, name) == pytest.approx(getattr(b, name), rel=1e-12)
    assert a.m00 == pytest.approx(0.0625e-6)
    assert a.as_um()["m04"] == pytest.approx(1.04e-4)


def test_bandwidths_of_the_paper_surfaces():
    s2 = SpectralMoments(**TABLE2)  # Table 2: "alpha = 3"
    assert s2.alpha1 == pytest.approx(3.0) and s2.alpha2 == pytest.approx(3.0)
    assert s2.mu == pytest.approx(1.0 / 3.0)
    s1 = SpectralMoments(**TABLE1)  # Table 1: "alpha = 10" (10.156 from the printed moments)
    assert s1.alpha1 == pytest.approx(10.0, rel=0.02)
    assert s1.beta1 + s1.beta2 + s1.mu == pytest.approx(1.0)


@pytest.mark.parametrize("moments", [TABLE1, TABLE2])
def test_summit_pdf_normalised_and_moments_match_closed_forms(moments):
    s = SpectralMoments(**moments)
    W4, W6, W1, wt = _summit_quadrature(s)
    p = psum(W1, W4, W6, s.beta1, s.beta2)
    assert np.sum(p * wt) == pytest.approx(1.0, rel=1e-9)
    smu = math.sqrt(s.m00 * s.mu)
    xi1 = W1 * smu
    mean = np.sum(xi1 * p * wt)
    assert mean == pytest.approx(s.delta, rel=1e-9)                      # (73)
    var = np.sum((xi1 - mean) ** 2 * p * wt)
    assert math.sqrt(var) == pytest.approx(s.summit_sigma, rel=1e-9)     # (71)-(72) corrected
    kap = 0.5 * (W4 * math.sqrt(s.m40 * s.mu) + W6 * math.sqrt(s.m04 * s.mu))
    assert np.sum(kap * p * wt) == pytest.approx(s.mean_summit_curvature, rel=1e-9)  # (70)


@pytest.mark.parametrize("moments", [TABLE1, TABLE2])
def test_summit_density_closed_form_equals_integral_16(moments):
    s = SpectralMoments(**moments)
    W4, W6, W1, wt = _summit_quadrature(s)
    mu, b1, b2 = s.mu, s.beta1, s.beta2
    X = W1**2 + (1 - b2) * W4**2 + (1 - b1) * W6**2 - 2 * math.sqrt(b1) * W1 * W4 \
        - 2 * math.sqrt(b2) * W1 * W6 + 2 * math.sqrt(b1 * b2) * W4 * W6
    # the quadratic form above is X of docs/equations.md written out (x-direction pairs w1 with w4)
    p14 = mu**2 / (2 * math.pi) ** 2.5 * math.sqrt(s.m04 * s.m40 / (s.m02 * s.m20)) \
        * W4 * W6 * np.exp(-X / 2)
    assert np.sum(p14 * wt) == pytest.approx(s.summit_density, rel=1e-9)


def test_plasticity_index_roundtrip():
    s = SpectralMoments(**TABLE1)
    H = s.hardness_for_plasticity_index(1.14e5, 0.35)
    assert plasticity_index(s, 1.14e5, H) == pytest.approx(0.35)
    # (69) by hand: sqrt(sigma kappa_m) E*/H
    assert s.plasticity_index(2e5, 3000.0) == pytest.approx(
        math.sqrt(s.summit_sigma * s.mean_summit_curvature) * 2e5 / 3000.0)


def _cosine_surface(nx=64, ny=48, dx=0.5, dy=0.25):
    rng = np.random.default_rng(3)
    Lx, Ly = nx * dx, ny * dy
    x = (np.arange(nx) * dx)[:, None]
    y = (np.arange(ny) * dy)[None, :]
    comps = [(3, 1, 0.7), (5, -2, 0.4), (1, 4, 0.3), (7, 6, 0.1), (2, 0, 0.5)]
    z = np.zeros((nx, ny))
    ex = {"m00": 0.0, "m20": 0.0, "m02": 0.0, "m40": 0.0, "m04": 0.0}
    fd = dict(ex)
    for ix, iy, C in comps:
        kx, ky = 2 * np.pi * ix / Lx, 2 * np.pi * iy / Ly
        z += C * np.cos(kx * x + ky * y + rng.uniform(0, 2 * np.pi))
        half = 0.5 * C**2
        ex["m00"] += half
        ex["m20"] += half * kx**2
        ex["m02"] += half * ky**2
        ex["m40"] += half * kx**4
        ex["m04"] += half * ky**4
        # discrete symbols of the central differences used by method="fd"
        fd["m00"] += half
        fd["m20"] += half * (np.sin(kx * dx) / dx) ** 2
        fd["m02"] += half * (np.sin(ky * dy) / dy) ** 2
        fd["m40"] += half * ((2 - 2 * np.cos(kx * dx)) / dx**2) ** 2
        fd["m04"] += half * ((2 - 2 * np.cos(ky * dy)) / dy**2) ** 2
    return z, dx, dy, ex, fd


@pytest.mark.parametrize("method", ["fft", "fd"])
def test_moments_from_height_map_sum_of_cosines(method):
    z, dx, dy, exact, fd = _cosine_surface()
    s = moments_from_height_map(z, dx, dy, method=method, unit="mm")
    ref = exact if method == "fft" else fd
    for name, v in ref.items():
        assert getattr(s, name) == pytest.approx(v, rel=1e-10), name


def test_moments_from_height_map_um_convention():
    z, dx, dy, exact, _ = _cosine_surface()
    s = moments_from_height_map(z, dx, dy, unit="um")
    assert s.m00 == pytest.approx(exact["m00"] * 1e-6, rel=1e-10)
    assert s.m40 == pytest.approx(exact["m40"] * 1e6, rel=1e-10)


@pytest.mark.parametrize("kwargs, word", [
    (dict(TABLE1, m00=0.0), "m00"),
    (dict(TABLE1, m20=-1.0), "m20"),
    (dict(TABLE1, m04=float("nan")), "m04"),
    (dict(TABLE1, m40=float("inf")), "m40"),
    (dict(TABLE1, unit="inch"), "unit"),
    (dict(m00=1.0, m20=1.0, m02=1.0, m40=1.5, m04=1.5), "mu"),   # alpha = 1.5 -> mu < 0
])
def test_invalid_moments_raise(kwargs, word):
    with pytest.raises(ValueError, match=word):
        SpectralMoments(**kwargs)


def test_invalid_height_map_raises():
    with pytest.raises(ValueError, match="z"):
        moments_from_height_map(np.ones(10), 1.0)
    z = np.random.default_rng(0).normal(size=(8, 8))
    z[2, 2] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        moments_from_height_map(z, 1.0)
    with pytest.raises(ValueError, match="dx"):
        moments_from_height_map(np.random.default_rng(0).normal(size=(8, 8)), -1.0)
    with pytest.raises(ValueError, match="method"):
        moments_from_height_map(np.random.default_rng(0).normal(size=(8, 8)), 1.0, method="x")
    s = SpectralMoments(**TABLE1)
    with pytest.raises(ValueError, match="E_star"):
        plasticity_index(s, -1.0, 100.0)
    with pytest.raises(ValueError, match="H"):
        plasticity_index(s, 1.0, 0.0)
