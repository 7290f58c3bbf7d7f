"""Measured surfaces in (rough_contact.surface.topography) and the moments in arbitrary axes (surface.py).

References we did not write: closed-form moments of Gaussian spectra checked against direct
quadrature of the spectrum, finite-difference slopes of the map in real space, invariants of
tensor rotation, exact planes/paraboloids, files written by SurfaceTopography itself.
"""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest

from rough_contact.surface import MomentTensor, SpectralMoments
from rough_contact.surface.topography import (AnisotropicGaussianPSD, HeightMap, analyze, detrend,
                                      read_height_map, read_instrument, read_npy, read_text_grid,
                                      read_xyz, synthetic_height_map, write_height_map, write_npy)

TABLE1 = dict(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)   # um convention
NAMES = ("m00", "m20", "m11", "m02", "m40", "m31", "m22", "m13", "m04")
ORDER = {"m00": 0, "m20": 2, "m11": 2, "m02": 2, "m40": 4, "m31": 4, "m22": 4, "m13": 4, "m04": 4}


def _scale(mt: dict, name: str) -> float:
    """Size of a moment's order, for relative errors of mixed moments (which may be ~0)."""
    o = ORDER[name]
    return {0: mt["m00"], 2: math.hypot(mt["m20"], mt["m02"]),
            4: math.hypot(mt["m40"], mt["m04"])}[o]


@pytest.fixture(scope="module")
def table1_psd():
    """The Table 1 surface as a two-Gaussian spectrum, grain at 30 deg from the map's x axis."""
    return AnisotropicGaussianPSD.from_moments(**TABLE1, angle_deg=30.0)


@pytest.fixture(scope="module")
def table1_map(table1_psd):
    # 512^2 pixels of 2 um: the spectrum (k up to ~7 sigma of its widest component) lies well
    # inside the Nyquist wavenumber pi/dx and is resolved by 2 pi/L
    return synthetic_height_map(table1_psd, (512, 512), (1024.0, 1024.0), seed=12)


# ----------------------------------------------------------------------------------------------
# the spectrum and its closed-form moments
# ----------------------------------------------------------------------------------------------
def test_psd_closed_form_moments_against_direct_quadrature(table1_psd):
    # integral Phi kx^p ky^q on a grid (trapezoid: spectrally accurate for Gaussians; they decay
    # to ~1e-20 at the edge)
    k = np.linspace(-2.5, 2.5, 1001)                      # rad/um
    KX, KY = np.meshgrid(k, k, indexing="ij")
    phi = table1_psd(KX, KY)
    ref = table1_psd.moments().as_um()
    for name in NAMES:
        p, q = int(name[1]), int(name[2])
        trapezoid = getattr(np, "trapezoid", None) or np.trapz   # numpy 2 / numpy 1
        val = trapezoid(trapezoid(phi * KX**p * KY**q, k, axis=1), k)
        assert val == pytest.approx(ref[name], abs=1e-9 * _scale(ref, name)), name
    # and the two components reproduce the five moments asked for, in the grain axes
    pr = table1_psd.principal_moments().as_um()
    for name, v in TABLE1.items():
        assert pr[name] == pytest.approx(v, rel=1e-12)


def test_moment_tensor_rotation_invariants_and_quarter_turn():
    mt = MomentTensor(0.07, 1e-4, 3e-5, 6e-4, 2e-6, 4e-7, 5e-6, -3e-6, 9e-5)
    um = mt.as_um()
    for ang in (0.3, -1.1, 2.0):
        r = mt.rotated(ang).as_um()
        assert r["m20"] + r["m02"] == pytest.approx(um["m20"] + um["m02"], rel=1e-13)
        # integral Phi |k|^4 = m40 + 2 m22 + m04 is rotation invariant
        assert r["m40"] + 2 * r["m22"] + r["m04"] == pytest.approx(
            um["m40"] + 2 * um["m22"] + um["m04"], rel=1e-13)
        back = mt.rotated(ang).rotated(-ang).as_um()
        for name in NAMES:
            assert back[name] == pytest.approx(um[name], abs=1e-13 * _scale(um, name))
    q = mt.rotated(math.pi / 2).as_um()              # x' = y, y' = -x
    assert (q["m20"], q["m02"], q["m40"], q["m04"]) == pytest.approx(
        (um["m02"], um["m20"], um["m04"], um["m40"]), rel=1e-12)
    assert q["m11"] == pytest.approx(-um["m11"], rel=1e-12)
    assert q["m31"] == pytest.approx(-um["m13"], rel=1e-12)
    with pytest.raises(ValueError, match="m11"):
        MomentTensor(0.07, 1e-4, 1e-3, 6e-4, 2e-6, 0.0, 5e-6, 0.0, 9e-5)


# ----------------------------------------------------------------------------------------------
# moments from a synthetic map (FFT route), principal angle
# ----------------------------------------------------------------------------------------------
def test_moments_of_a_synthetic_512_map_within_1_percent(table1_psd, table1_map):
    est = table1_map.moments(window="none").as_um()
    ref = table1_psd.moments().as_um()
    for name in NAMES:
        # m00 misses only the power of the k = 0 bin (the mean of a finite map is unknowable):
        # Phi(0) (2 pi/L)^2 = 0.36 % of m00 here
        assert abs(est[name] - ref[name]) <= 0.01 * _scale(ref, name), (name, est[name], ref[name])
    assert est["m00"] == pytest.approx(ref["m00"] - table1_psd(0.0, 0.0) * (2 * np.pi / 1024) ** 2,
                                       rel=1e-6)


@pytest.mark.parametrize("angle", [30.0, -60.0, 75.0])
def test_principal_angle_and_moments_recovered(angle):
    psd = AnisotropicGaussianPSD.from_moments(**TABLE1, angle_deg=angle)
    hm = synthetic_height_map(psd, (512, 512), (1024.0, 1024.0), seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                 # Table 1 is in the model's validity
        a = analyze(hm, detrend="none", window="none")
    assert abs(math.remainder(a.grain_angle_deg - angle, 180.0)) < 0.5
    assert abs(math.remainder(a.curvature_grain_angle_deg - angle, 180.0)) < 0.5
    sm = a.spectral_moments.as_um()
    for name, v in TABLE1.items():
        assert sm[name] == pytest.approx(v, rel=0.01), name
    assert a.advice.recommended == "anisotropic" and a.advice.anisotropic_valid
    # the convention in real space: finite-difference slopes of the heights along the reported
    # grain direction are the small ones, and their mean squares are m20, m02 of the grain axes
    # (sixth-order periodic central differences: wavenumber error ~(k dx)^6/140, < 0.5 % here)
    def d(z, axis, h):
        r = lambda n: np.roll(z, -n, axis)  # noqa: E731
        return (r(3) - 9 * r(2) + 45 * r(1) - 45 * r(-1) + 9 * r(-2) - r(-3)) / (60 * h)

    zx, zy = d(hm.heights, 1, hm.dx), d(hm.heights, 0, hm.dy)
    c, s = a.grain_direction
    along = np.mean((c * zx + s * zy) ** 2)
    across = np.mean((-s * zx + c * zy) ** 2)
    assert along == pytest.approx(TABLE1["m20"], rel=0.02)
    assert across == pytest.approx(TABLE1["m02"], rel=0.02)


def test_hann_window_correction_is_unbiased_and_needed():
    """Mean over 300 Gaussian random fields (random amplitudes) of the window-corrected
    moments equals the discrete spectrum's moments within 4 standard errors; without the
    correction m40 is biased by several standard errors."""
    n, L = 64, 64.0
    psd = AnisotropicGaussianPSD(1.0, ((1.0, 0.25, 0.6),), angle_deg=30.0, unit="mm")
    k = 2 * np.pi * np.fft.fftfreq(n, d=L / n)
    KX, KY = np.meshgrid(k, k, indexing="ij")
    kz = k.copy()
    kz[n // 2] = 0.0                                   # the estimator's Nyquist convention
    KXz, KYz = np.meshgrid(kz, kz, indexing="ij")
    w = psd(KX, KY) * (2 * np.pi / L) ** 2
    w[0, 0] = 0.0                                      # the generator's mean is zero
    ref = {nm: float(np.sum(w * KXz ** int(nm[1]) * KYz ** int(nm[2]))) for nm in NAMES}
    hann, raw = [], []
    for seed in range(300):
        hm = synthetic_height_map(psd, (n, n), (L, L), seed=seed, unit="mm",
                                  random_amplitude=True)
        m = hm.to_unit("mm").moments(window="hann")
        hann.append([getattr(m, nm) for nm in NAMES])
        # uncorrected: the windowed periodogram normalised by <w^2> only
        wv = np.sin(np.pi * np.arange(n) / n) ** 2
        W = np.outer(wv, wv)
        z = hm.heights.T - hm.heights.mean()
        P = np.abs(np.fft.fft2(W * z)) ** 2 / n**4 / np.mean(W**2)
        raw.append([float(np.sum(P * KXz ** int(nm[1]) * KYz ** int(nm[2]))) for nm in NAMES])
    hann, raw = np.array(hann), np.array(raw)
    se = hann.std(axis=0) / np.sqrt(len(hann))
    dev = (hann.mean(axis=0) - np.array([ref[nm] for nm in NAMES])) / se
    assert np.all(np.abs(dev) < 4.0), dict(zip(NAMES, dev.round(2)))
    raw_dev = (raw.mean(axis=0)[4] - ref["m40"]) / se[4]
    assert raw_dev > 4.0


def test_measured_style_map_with_form_is_recovered_after_detrend_and_window(table1_psd,
                                                                            table1_map):
    # tilt + curvature as a measured map would carry: not periodic any more
    X, Y = np.meshgrid(table1_map.x, table1_map.y)
    form = 2e-3 * X - 1e-3 * Y + 1e-6 * (X - 500.0) ** 2 + 5e-7 * (Y - 300.0) ** 2
    hm = HeightMap(table1_map.heights + form, table1_map.dx, table1_map.dy, "um")
    a = analyze(hm, detrend="curvature", window="hann")
    # the form is removed exactly: the same result as without it
    b = analyze(table1_map, detrend="curvature", window="hann")
    assert a.grain_angle_deg == pytest.approx(b.grain_angle_deg, abs=1e-9)
    ma, mb = a.map_moments.as_um(), b.map_moments.as_um()
    for name in NAMES:
        assert ma[name] == pytest.approx(mb[name], rel=1e-8, abs=1e-12 * _scale(mb, name))
    # against the spectrum it is a statistical estimate now (the window widens every line to
    # three bins): measured over seeds on 512^2 maps, rms errors ~3 % for slopes and curvatures
    # and ~10 % for m00 (carried by wavelengths up to 1/20 of the map); 1024^2 halves them
    assert abs(a.grain_angle_deg - 30.0) < 1.0
    sm = a.spectral_moments.as_um()
    for name, v in TABLE1.items():
        assert sm[name] == pytest.approx(v, rel=0.25 if name == "m00" else 0.10), name


def test_nearly_isotropic_surface_gets_the_gw_advice():
    psd = AnisotropicGaussianPSD(0.0625, ((1.0, 0.10, 0.13),), angle_deg=10.0)   # m04/m40 = 2.9
    hm = synthetic_height_map(psd, (128, 128), (512.0, 512.0), seed=1)
    with pytest.warns(UserWarning, match="greenwood_williamson"):
        a = analyze(hm, detrend="none", window="none")
    assert a.advice.recommended == "greenwood_williamson"
    assert not a.advice.anisotropic_valid
    assert a.advice.curvature_ratio == pytest.approx((0.13 / 0.10) ** 4, rel=0.01)
    assert isinstance(a.spectral_moments, SpectralMoments)


# ----------------------------------------------------------------------------------------------
# detrending
# ----------------------------------------------------------------------------------------------
def test_detrend_removes_plane_and_paraboloid_exactly(table1_map):
    X, Y = np.meshgrid(np.arange(40) * 0.5, np.arange(30) * 0.25)
    plane = 3.0 + 0.2 * X - 0.7 * Y
    parab = plane + 0.05 * X**2 - 0.03 * X * Y + 0.08 * Y**2
    assert np.max(np.abs(detrend(HeightMap(plane, 0.5, 0.25), "plane").heights)) < 1e-12
    assert np.max(np.abs(detrend(HeightMap(parab, 0.5, 0.25), "curvature").heights)) < 1e-12
    assert np.max(np.abs(detrend(HeightMap(parab, 0.5, 0.25), "plane").heights)) > 1e-2
    # linear: detrending roughness + plane equals detrending the roughness alone
    rough = table1_map.heights[:30, :40]
    a = detrend(HeightMap(rough + plane, 0.5, 0.25), "plane").heights
    b = detrend(HeightMap(rough, 0.5, 0.25), "plane").heights
    assert np.max(np.abs(a - b)) < 1e-12
    assert detrend(HeightMap(plane, 0.5, 0.25), "mean").heights.mean() == pytest.approx(0, abs=1e-12)


# ----------------------------------------------------------------------------------------------
# files
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["map.npy", "map.csv", "map.txt", "map.dat", "map.xyz"])
def test_each_plain_reader_round_trips_a_written_file(tmp_path, table1_map, name):
    hm = HeightMap(table1_map.heights[:20, :36], 2.0, 3.0, "um")
    path = write_height_map(hm, tmp_path / name)
    back = read_height_map(path)
    assert back.shape == (20, 36)
    assert np.array_equal(back.heights, hm.heights)
    assert (back.dx, back.dy, back.unit) == (2.0, 3.0, "um")


def test_readers_take_metadata_from_the_caller_and_convert_units(tmp_path, table1_map):
    z = table1_map.heights[:16, :24]
    # plain CSV without header: spacing and unit from the caller
    np.savetxt(tmp_path / "plain.csv", z, delimiter=",", fmt="%.17g")
    hm = read_text_grid(tmp_path / "plain.csv", dx=0.5, unit="um")
    assert np.array_equal(hm.heights, z) and hm.dy == 0.5
    # whitespace-separated grid, heights in nm, map in um
    np.savetxt(tmp_path / "nm.txt", z * 1e3, fmt="%.17g")
    hm = read_text_grid(tmp_path / "nm.txt", dx=0.5, dy=0.25, unit="um", height_unit="nm")
    assert np.allclose(hm.heights, z, rtol=1e-14) and hm.dy == 0.25
    # .npy without sidecar
    np.save(tmp_path / "bare.npy", z)
    assert read_npy(tmp_path / "bare.npy", dx=1.0, unit="mm").unit == "mm"
    with pytest.raises(ValueError, match="dx is not given"):
        read_npy(tmp_path / "bare.npy", unit="um")
    write_npy(HeightMap(z, 1.0, 1.0, "um"), tmp_path / "side.npy")
    with pytest.raises(ValueError, match="dx = 2.0 given, but"):
        read_npy(tmp_path / "side.npy", dx=2.0)
    # xyz in any order, x and y in mm, z in um -> map in mm
    X, Y = np.meshgrid(np.arange(24) * 0.002, np.arange(16) * 0.003)
    pts = np.stack([X.ravel(), Y.ravel(), z.ravel()], axis=1)
    pts = pts[np.random.default_rng(0).permutation(len(pts))]
    np.savetxt(tmp_path / "shuffled.xyz", pts, fmt="%.9f")
    hm = read_xyz(tmp_path / "shuffled.xyz", unit="mm", height_unit="um")
    assert hm.shape == (16, 24)
    assert hm.dx == pytest.approx(0.002, rel=1e-9) and hm.dy == pytest.approx(0.003, rel=1e-9)
    assert np.allclose(hm.heights, z * 1e-3, atol=1e-12)


def test_instrument_reader_on_a_file_written_by_surface_topography(tmp_path, table1_map):
    st = pytest.importorskip("SurfaceTopography",
                             reason="optional extra 'topography' (SurfaceTopography) missing")
    hm = HeightMap(table1_map.heights[:32, :48], 2.0, 2.5, "um")
    # SurfaceTopography stores heights (nx, ny) with axis 0 along x
    topo = st.Topography(hm.heights.T.copy(), physical_sizes=hm.size, unit="um")
    topo.to_netcdf(str(tmp_path / "map.nc"))
    back = read_height_map(tmp_path / "map.nc")
    assert back.shape == (32, 48) and back.unit == "um"
    assert np.array_equal(back.heights, hm.heights)
    assert (back.dx, back.dy) == pytest.approx((2.0, 2.5), rel=1e-6)   # sizes stored as float32
    nm = read_instrument(tmp_path / "map.nc", unit="nm")
    assert np.allclose(nm.heights, hm.heights * 1e3, rtol=1e-12) and nm.dx == pytest.approx(2e3)


def test_missing_surface_topography_gives_install_hint(tmp_path, monkeypatch):
    (tmp_path / "scan.sur").write_bytes(b"\0" * 64)
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)      # import fails
    with pytest.raises(ImportError, match=r"rough_contact\[topography\]"):
        read_height_map(tmp_path / "scan.sur")


# ----------------------------------------------------------------------------------------------
# bad inputs
# ----------------------------------------------------------------------------------------------
def test_bad_inputs_give_clear_errors(tmp_path, table1_map):
    z = np.array(table1_map.heights[:20, :20])
    z[3, 7] = np.nan
    z[12, 0] = np.inf
    with pytest.raises(ValueError, match=r"2 non-finite values .* \(row 3, col 7\), \(row 12, col 0\)"):
        HeightMap(z, 1.0, 1.0)
    with pytest.raises(ValueError, match=r"too small: each side needs >= 16"):
        HeightMap(np.zeros((8, 100)), 1.0, 1.0)
    with pytest.raises(ValueError, match=r"dx = -1.0 um is invalid"):
        HeightMap(np.zeros((16, 16)), -1.0, 1.0)
    with pytest.raises(ValueError, match="unit = 'inch' is invalid"):
        HeightMap(np.zeros((16, 16)), 1.0, 1.0, "inch")
    hm = HeightMap(np.zeros((16, 16)), 1.0, 1.0)
    with pytest.raises(ValueError, match="detrend mode"):
        detrend(hm, "cubic")
    with pytest.raises(ValueError, match="window"):
        analyze(hm, window="blackman")
    # xyz: a non-uniform x spacing, and a missing node
    X, Y = np.meshgrid(np.arange(20.0), np.arange(18.0))
    X[:, 10:] += 0.3
    np.savetxt(tmp_path / "nonuni.xyz", np.stack([X.ravel(), Y.ravel(), 0 * X.ravel()], 1))
    with pytest.raises(ValueError, match="x coordinates are not uniformly spaced"):
        read_xyz(tmp_path / "nonuni.xyz", unit="um")
    X, Y = np.meshgrid(np.arange(20.0), np.arange(18.0))
    pts = np.stack([X.ravel(), Y.ravel(), 0 * X.ravel()], 1)[1:]
    np.savetxt(tmp_path / "hole.xyz", pts)
    with pytest.raises(ValueError, match="1 nodes missing"):
        read_xyz(tmp_path / "hole.xyz", unit="um")
    # NaN in a file is named with the file
    np.savetxt(tmp_path / "nan.csv", z, delimiter=",")
    with pytest.raises(ValueError, match=r"nan.csv: heights contain 2 non-finite"):
        read_text_grid(tmp_path / "nan.csv", dx=1.0, unit="um")
    with pytest.raises(ValueError, match="suffix"):
        write_height_map(hm, tmp_path / "map.sur")
    with pytest.raises(ValueError, match="alpha1"):
        AnisotropicGaussianPSD.from_moments(0.0625, 8e-5, 8e-4, 1e-8, 1.04e-4)
    with pytest.raises(ValueError, match="weights sum"):
        AnisotropicGaussianPSD(1.0, ((0.5, 1.0, 2.0),))


def test_topography_is_a_pure_layer(imports_without):
    imports_without(["rough_contact.surface.topography"], also={"SurfaceTopography"})


@pytest.mark.parametrize("suffix", [".csv", ".xyz"])
def test_binary_file_with_a_text_suffix_names_the_file(tmp_path, suffix):
    """Issue 24, item 4: a binary file named .csv raised a raw UnicodeDecodeError without the
    file name; now a ValueError names the file and the cause."""
    from rough_contact.surface.topography import read_height_map
    path = tmp_path / f"scan{suffix}"
    path.write_bytes(bytes(range(128, 256)) * 8)
    with pytest.raises(ValueError, match=rf"scan\{suffix} is not a text file"):
        read_height_map(path, dx=1e-3, dy=1e-3) if suffix == ".csv" else read_height_map(path)


# ----------------------------------------------------------------------------------------------
# issue 24, item 5: implausible slopes for the stated units
# ----------------------------------------------------------------------------------------------
def test_lateral_units_mixed_up_are_refused_with_the_likely_cause(tmp_path, table1_map,
                                                                  table1_psd):
    """x, y in mm read as um multiply every slope by 1000: refused, naming the mix-up and the
    override (before the fix the map was accepted with rms slopes of tens of rad)."""
    hm = HeightMap(table1_map.heights[:64, :64], 2.0, 2.0, "um")
    # the reference slope, by a route that shares nothing with the check: the spectrum's own
    # moments (rms slope sqrt(m20), sqrt(m02) of Table 1 in the map axes, 0.01-0.03)
    assert math.sqrt(max(TABLE1["m20"], TABLE1["m02"])) < 0.03
    X, Y = np.meshgrid(hm.x * 1e-3, hm.y * 1e-3)                       # x, y in mm, z in um
    np.savetxt(tmp_path / "surface.xyz", np.stack([X.ravel(), Y.ravel(),
                                                   hm.heights.ravel()], 1), fmt="%.12g")
    ok = read_height_map(tmp_path / "surface.xyz", unit="mm", height_unit="um")
    assert ok.unit == "mm"
    with pytest.raises(ValueError, match=r"rms slope .* rad .* implausible for a machined surface "
                       r"\(expected < ~1.*lateral units mm rather than um.*allow_steep=True"):
        read_height_map(tmp_path / "surface.xyz", unit="um", height_unit="um")
    # the slopes the user would have got are ~1000x the true ones: tens of rad
    steep = read_height_map(tmp_path / "surface.xyz", unit="um", height_unit="um",
                            allow_steep=True)
    from rough_contact.surface.topography import check_units_plausible
    # the slopes and curvatures the check measures are the spectrum's (map axes, closed form;
    # central differences at 2 um pixels read them 2-7 % low)
    m = table1_psd.moments()
    got = check_units_plausible(table1_map)
    want = [math.sqrt(m.m20), math.sqrt(m.m02), math.sqrt(m.m40) * 1e-3, math.sqrt(m.m04) * 1e-3]
    np.testing.assert_allclose(got, want, rtol=0.1)
    with pytest.raises(ValueError, match="rms slope"):
        check_units_plausible(steep)
    assert steep.dx == pytest.approx(ok.dx, rel=1e-9)                    # same numbers, unit um
    # heights in um stated as mm: the other mix-up is named
    np.savetxt(tmp_path / "h.csv", hm.heights, delimiter=",")
    with pytest.raises(ValueError, match="heights in um rather than mm"):
        read_text_grid(tmp_path / "h.csv", dx=2.0, unit="um", height_unit="mm")
    assert read_text_grid(tmp_path / "h.csv", dx=2.0, unit="um").unit == "um"
    # every length in nm although the map is in mm: curvature radii far below an atom
    np.save(tmp_path / "all.npy", hm.heights * 1e-3)
    with pytest.raises(ValueError, match=r"rms curvature .* radius of .* nm, is implausible"):
        read_npy(tmp_path / "all.npy", dx=2e-3, unit="nm")
    assert read_npy(tmp_path / "all.npy", dx=2e-3, unit="mm").unit == "mm"
