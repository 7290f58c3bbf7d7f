"""The machinery of the history table (issue 23): rows graded in h_min with ghost rows, a
uniform cubic B-spline in the row coordinate v, cubic Hermite in x on graded knots, the
monotone projection of the control rows, the O(1) look-up, the taper, the consistent tangent
and the normal dissipation.

Checked on synthetic row data of closed form (no population sums, so the tests take about a
second): a surface cubic in v and quadratic in x must be reproduced to round-off (the spline
and the Hermite pieces are exact for it); k must be the derivative of p (central finite
differences), dk/dh that of k; data chosen so that the spline's control rows oscillate must
still give k >= 0 everywhere (and do give k < 0 without the projection, which shows the check
can fail); D(h_min) must equal the loading work minus the recoverable energy, both integrated
here by the trapezoid rule over ``evaluate``/``evaluate_history``. The direct population sums
are exercised by the coarse real table at the end. Units: mm, MPa.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy.integrate import trapezoid
import pytest

from rough_contact.interface import history as H
from rough_contact.interface.history import HistoryNormalLaw
from rough_contact.interface.normal import NormalLaw

SIG = 1e-3            # mm: the x unit of the synthetic tables
C0, LAM = 50.0, 1e-3  # MPa, mm: loading p = C0 exp(-h/LAM)
XK = np.array([0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0])   # graded x knots [-]


def _loading():
    def model(h):
        p = C0 * np.exp(-h / LAM)
        return p, p / LAM, 0.3 * np.exp(-(h + 1e-3) / (2 * LAM))
    return NormalLaw.from_model(model, (-1e-3, 5e-3), rtol=1e-8)


def _synthetic(rho, drho, la, dla, n=6, xk=XK, loading=None, capped=False):
    """HistoryNormalLaw from closed-form row data rho(v, x), d rho/dx, ln a/a0, d/dx."""
    loading = loading or _loading()
    hL, hE = loading.h_min, loading.h_table_end
    v = np.arange(-1, n + 2) / n
    hm = H._row_h(v, hL, hE - hL, H._GRADING)
    V, X = np.meshgrid(v, xk, indexing="ij")
    m = np.array([rho(V, X), drho(V, X), la(V, X), dla(V, X)])
    return HistoryNormalLaw._assemble(loading, 1e-3, SIG, hm, xk, m, H._GRADING, capped=capped)


# a surface cubic in v and quadratic in x (exact for the table), decreasing in x
def _alpha(v):
    return 1.0 + 2.0 * v - 0.5 * v * v + 0.3 * v ** 3


def _rho(v, x):
    return -(_alpha(v) * x + 0.2 * x * x)


def _drho(v, x):
    return -(_alpha(v) + 0.4 * x)


def _la(v, x):
    return -((0.8 + v) * x + 0.1 * x * x)


def _dla(v, x):
    return -((0.8 + v) + 0.2 * x)


def test_row_map_is_inverted():
    h = np.linspace(-2.0, 7.0, 1001)
    for beta in (0.0, 0.5, H._GRADING):
        v = H._row_v(h, -1.0, 5.0, beta)
        inside = (h >= -1.0) & (h <= 4.0)
        np.testing.assert_allclose(H._row_h(v[inside], -1.0, 5.0, beta), h[inside], atol=1e-13)
        assert np.all(v[h < -1.0] == 0.0) and np.all(v[h > 4.0] == 1.0)


def test_table_reproduces_cubic_quadratic_surface_to_round_off():
    law = _synthetic(_rho, _drho, _la, _dla)
    assert law.info["monotone_projection_changes"] == 0
    rng = np.random.default_rng(0)
    n = 20000
    hm = rng.uniform(law._hm0, law._hm0 + law._span, n)
    x = rng.uniform(0.0, XK[-1], n)
    h = hm + x * SIG
    p, k, a = law.evaluate_history(h, hm)
    p0, _, a0 = law.loading.evaluate(hm)
    v = H._row_v(hm, law._hm0, law._span, law._beta)
    np.testing.assert_allclose(p, p0 * np.exp(_rho(v, x)), rtol=1e-11)
    np.testing.assert_allclose(k, -p0 * np.exp(_rho(v, x)) * _drho(v, x) / SIG, rtol=1e-10)
    np.testing.assert_allclose(a, a0 * np.exp(_la(v, x)), rtol=1e-11)


def test_tangent_and_curvature_are_derivatives_and_branch_is_continuous():
    law = _synthetic(_rho, _drho, _la, _dla)
    rng = np.random.default_rng(1)
    n = 2000
    hm = rng.uniform(law.h_min - 0.3 * law._span, law.h_table_end, n)   # also below the table
    h = hm + rng.uniform(0.01, 1.3 * XK[-1], n) * SIG                    # also in the taper
    p, k, a, dk = law.evaluate_history(h, hm, curvature=True)
    d = 1e-7 * SIG
    pp, kp, _ = law.evaluate_history(h + d, hm)
    pm, km, _ = law.evaluate_history(h - d, hm)
    ok = p > 1e-12 * C0
    np.testing.assert_allclose(k[ok], ((pm - pp) / (2 * d))[ok], rtol=1e-6)
    np.testing.assert_allclose(dk[ok], ((kp - km) / (2 * d))[ok], rtol=2e-5,
                               atol=1e-7 * np.abs(dk[ok]).max())
    # the branch starts at the loading law's value exactly (p and A/A0 continuous)
    hms = np.linspace(law.h_min, law.h_table_end, 50)[:-1]
    pl, kl, al = law.loading.evaluate(hms)
    pu, ku, au = law.evaluate_history(hms + 1e-12 * SIG, hms)
    np.testing.assert_allclose(pu, pl, rtol=1e-11)
    np.testing.assert_allclose(au, al, rtol=1e-11)
    assert np.all(ku > 0)
    np.testing.assert_array_equal(law.evaluate_history(hms, hms)[0], pl)   # h = h_min: loading


def test_k_nonnegative_by_construction_on_oscillating_rows():
    """Rows alternating between a steep and a nearly flat shape: the not-a-knot spline's
    control rows overshoot and some of them increase in x. The projection onto monotone
    Hermite data keeps k >= 0 at every point; without it the same data gives k < 0."""
    def steep(v):
        n = 6
        return np.where(np.round(v * n).astype(int) % 2 == 0, 4.0, 0.02)

    rho = lambda v, x: -steep(v) * x * (1.0 + 0.1 * x)                  # noqa: E731
    drho = lambda v, x: -steep(v) * (1.0 + 0.2 * x)                      # noqa: E731
    la = lambda v, x: -0.5 * x                                           # noqa: E731
    dla = lambda v, x: -0.5 + 0.0 * x                                    # noqa: E731
    rng = np.random.default_rng(2)
    hm = rng.uniform(-1e-3, 5e-3, 200_000)
    h = hm + rng.uniform(0.0, 1.2 * XK[-1], hm.size) * SIG
    law = _synthetic(rho, drho, la, dla)
    assert law.info["monotone_projection_changes"] > 0
    _, k, _ = law.evaluate_history(h, hm)
    assert np.all(k >= 0.0)
    plain = pytest.MonkeyPatch()
    plain.setattr(H, "_monotone_controls", lambda v, d, xk: (v, d, 0))
    try:
        law_plain = _synthetic(rho, drho, la, dla)
    finally:
        plain.undo()
    _, k_plain, _ = law_plain.evaluate_history(h, hm)
    assert np.any(k_plain < 0.0)


def test_dissipation_is_loading_work_minus_recoverable_energy():
    law = _synthetic(_rho, _drho, _la, _dla)
    n_m = law._n_m
    rows = H._row_h(np.arange(n_m + 1) / n_m, law._hm0, law._span, law._beta)
    for hm in rows[:-1:2]:
        hh = np.linspace(hm, law.h_max + 2 * SIG, 400001)
        W = trapezoid(law.loading.evaluate(hh)[0], hh)
        E = trapezoid(law.evaluate_history(hh, np.full_like(hh, hm))[0], hh)
        assert float(law.normal_dissipation(np.array([hm]))[0]) == pytest.approx(W - E, rel=1e-5)
    D = law.normal_dissipation(np.linspace(law.h_min - 2 * SIG, law.h_max, 500))
    assert np.all(D >= 0) and np.all(np.diff(D) <= 1e-12 * D.max())


def test_bad_build_arguments_are_named():
    from rough_contact.micro.asperity import AsperityMaterial
    from rough_contact.surface import SpectralMoments
    s = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0)
    for kw, match in (({"n_rows": 2}, "n_rows = 2"), ({"n_x": 1}, "n_x = 1"),
                      ({"n_zeta": 1.5}, "n_zeta = 1.5"), ({"rtol": 0.5}, "rtol")):
        with pytest.raises(ValueError, match=match):
            HistoryNormalLaw.elasto_plastic(s, mat, **{"rtol": 1e-3, **kw})


@functools.lru_cache(maxsize=None)
def _coarse_loading():
    """Table 1 surface, psi = 1, and its coarse loading law (rtol 1e-2, n_quad 8)."""
    from rough_contact.micro.asperity import AsperityMaterial
    from rough_contact.surface import SpectralMoments
    s = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
    mat = AsperityMaterial(E_star=1.14e5, psi=1.0).resolve(s)
    return s, mat, NormalLaw.elasto_plastic(s, mat, rtol=1e-2, n_quad=8)


def test_coarse_population_table_against_direct_sums_at_random_points():
    """A coarse table of the paper's Table 1 surface (rtol 1e-2, cheap sums n_quad 8): its
    error against the direct sums at random points -- not the build's own check points -- is
    within rtol, k >= 0 on the build's dense sample, and the build's bookkeeping is sane."""
    from rough_contact.micro import unloading as U
    s, mat, loading = _coarse_loading()
    rtol = 1e-2
    law = HistoryNormalLaw.elasto_plastic(s, mat, rtol, loading=loading, n_quad=8, n_t=16,
                                          n_zeta=8, n_rows=3, n_x=2)
    info = law.info
    assert info["converged"] and info["worst_error"] <= rtol and info["k_nonnegative"]
    assert info["rows"] >= 4 and info["x_knots"] > 3
    sig = s.rq
    rng = np.random.default_rng(5)
    errs = []
    for hm in rng.uniform(loading.h_min, loading.h_table_end, 6):
        x = rng.uniform(0.0, 4.0, 5)
        p, k, a, _ = U._row_sums(s, mat, hm, np.concatenate([[0.0], x * sig]), 8, 16, 8)
        pt, kt, at = law.evaluate_history(hm + x * sig, np.full(5, hm))
        use = p[1:] >= 1e-12 * p[0]
        e = np.max([np.abs(pt / p[1:] - 1), np.abs(kt / k[1:] - 1), np.abs(at / a[1:] - 1)],
                   axis=0)
        errs.extend(e[use])
    assert len(errs) > 20 and max(errs) <= rtol


def test_taper_beyond_the_table_is_finite_when_p_underflows_at_its_end():
    """Far beyond the tail p(X) underflows to 0 on steep rows (the population's high rows
    reach rho ~ -2000 at X): the taper past X must give zeros, not 0/0 (it gave NaN k)."""
    steep = lambda v, x: -(1.0 + v) * x - 60.0 * x * x                  # noqa: E731
    dsteep = lambda v, x: -(1.0 + v) - 120.0 * x                         # noqa: E731
    law = _synthetic(steep, dsteep, _la, _dla)
    hm = np.linspace(law.h_min, law.h_table_end, 40)[:-1]
    for x in (XK[-1] - 1e-9, XK[-1] + 0.5, XK[-1] + 3.0):
        p, k, a, dk = law.evaluate_history(hm + x * SIG, hm, curvature=True)
        for v in (p, k, a, dk):
            assert np.all(np.isfinite(v))
        assert np.all(p >= 0) and np.all(k >= 0) and np.all(p < 1e-300)


def test_pickle_roundtrip_and_old_format_refused():
    import pickle
    law = _synthetic(_rho, _drho, _la, _dla)
    back = pickle.loads(pickle.dumps(law))
    hm = np.linspace(law.h_min, law.h_table_end, 30)
    h = hm + 0.7 * SIG
    for x, y in zip(law.evaluate_history(h, hm), back.evaluate_history(h, hm)):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(law.normal_dissipation(hm), back.normal_dissipation(hm))
    old = object.__new__(HistoryNormalLaw)
    with pytest.raises(ValueError, match="older format"):
        old.__setstate__({"loading": law.loading, "_C": np.zeros((1, 1, 4, 4)), "_dm": 1.0})



def test_unloading_above_loading_is_capped_by_the_loading_branch():
    """A population cannot give back more force on unloading than it took on loading at the
    same separation (its normal dissipation would be negative: the paper's yield data make one
    summit's load jump up at first yield, and the elastic unloading from the jump lies above
    the loading curve). A table flagged as crossing the loading branch is evaluated as
    min(unloading, loading) with the tangent of the branch taken; its D(h_min) is the loading
    work minus the recoverable energy of that capped branch (trapezoid rule here); the build's
    detector counts the points above the loading branch by more than rtol only."""
    # loading ln p = -h/LAM, so rho_load(x) = -x (SIG = LAM); this branch crosses it at x = 5
    rho = lambda v, x: -(1.5 + 0.2 * v) * x + 0.1 * x * x
    drho = lambda v, x: -(1.5 + 0.2 * v) + 0.2 * x
    free = _synthetic(rho, drho, _la, _dla)
    law = _synthetic(rho, drho, _la, _dla, capped=True)
    rng = np.random.default_rng(3)
    hm = law.h_min + rng.random(20000) * (law.h_table_end - law.h_min)
    h = hm + rng.random(20000) * 8 * SIG
    p, k, a = law.evaluate_history(h, hm)
    pf, kf, af = free.evaluate_history(h, hm)
    pl, kl, al = law.loading.evaluate(h)
    assert np.all(p <= pl * (1 + 1e-14))
    above = pf > pl
    assert above.mean() > 0.05                     # the uncapped table does cross
    np.testing.assert_array_equal(p[~above], pf[~above])
    np.testing.assert_array_equal(k[above], kl[above])
    np.testing.assert_array_equal(a[above], al[above])
    # dissipation of the capped branch: work minus the energy it gives back
    n_m = law._n_m
    rows = H._row_h(np.arange(n_m + 1) / n_m, law._hm0, law._span, law._beta)
    for r in rows[:-1:2]:
        hh = np.linspace(r, law.h_max + 2 * SIG, 400001)
        W = trapezoid(law.loading.evaluate(hh)[0], hh)
        E = trapezoid(law.evaluate_history(hh, np.full_like(hh, r))[0], hh)
        assert float(law.normal_dissipation(np.array([r]))[0]) == pytest.approx(W - E, rel=1e-5)
    # the detector: one point above by 0.3, one below, one above by rtol/2 (not counted)
    u = np.array([0.25, 0.5, 1.0]) * SIG
    r_load = -u / LAM
    assert H._count_above_loading(r_load + [0.3, -0.2, 0.5e-4], law.loading, 1e-3, u, 1e-4) == 1


def test_h_min_beyond_the_table_end_gives_the_loading_law_at_h():
    """h_min >= h_table_end: nothing has yielded, the loading law at h (reversible). The law
    returned the loading law at h_min there (p frozen at p_load(h_min) while k = k_load(h_min)
    > 0: a tangent that is not the derivative of p)."""
    law = _synthetic(_rho, _drho, _la, _dla)
    L = law.loading
    hm = np.linspace(L.h_table_end, L.h_max, 41)[:-1]
    h = hm + 0.3 * (L.h_max - hm)
    for got, want in zip(law.evaluate_history(h, hm, curvature=True), L.evaluate(h, True)):
        np.testing.assert_array_equal(got, want)
    d = 1e-4 * (L.h_max - L.h_table_end)
    k_fd = (law.evaluate_history(h - d, hm)[0] - law.evaluate_history(h + d, hm)[0]) / (2 * d)
    np.testing.assert_allclose(law.evaluate_history(h, hm)[1], k_fd, rtol=1e-4)


def _mixed_points(law, n, seed):
    """Loading, unloading, taper, below-table, beyond-the-table-end and virgin points."""
    rng = np.random.default_rng(seed)
    lo, hi = law.h_min - 0.2 * law._span, law.h_max
    hm = rng.uniform(lo, hi, n)
    hm[::9] = np.inf
    h = hm + rng.uniform(-0.5, 1.5, n) * XK[-1] * SIG
    h[::9] = rng.uniform(lo, hi, h[::9].size)
    return h, hm


@pytest.mark.parametrize("curvature", [False, True])
def test_repeated_h_min_is_remembered_bit_for_bit(curvature):
    """A Newton loop calls with the same committed h_min every iteration: from the second
    call on, what unloading points need of h_min alone is remembered, and a point's cell
    polynomial in x while it stays in its x cell. Every call must give
    exactly what a law that never saw this h_min gives (a fresh copy), for changing h, with
    and without A/A0, over several evaluation blocks; and an h_min array changed in place
    must not be mistaken for the remembered one."""
    import pickle
    law = _synthetic(_rho, _drho, _la, _dla)
    n = 2 * H._BLOCK + 777
    h, hm = _mixed_points(law, n, 7)
    rng = np.random.default_rng(8)
    kept = []
    for it, area in enumerate([False, False, True, True, False, True, True]):
        hh = h + rng.normal(0.0, 0.05, n) * SIG * (it > 0)
        memo = law._memo.get("h_min")
        before = None if memo is None or memo.cell is None else memo.cell.copy()
        got = law.evaluate_history(hh, hm, curvature, area=area)
        if before is not None:          # points whose x cell was kept, and points that moved
            after = law._memo["h_min"].cell
            kept.append((np.count_nonzero((after == before) & (before >= 0)),
                          np.count_nonzero((after != before) & (before >= 0))))
        fresh = pickle.loads(pickle.dumps(law)).evaluate_history(hh, hm, curvature, area=area)
        assert (got[2] is None) == (not area) and (fresh[2] is None) == (not area)
        for x, y in zip(got, fresh):
            if y is not None:
                np.testing.assert_array_equal(x, y)
    assert law._memo["h_min"].p0 is not None           # the hot path was taken
    assert all(k > n / 6 and c > 0 for k, c in kept[1:])   # cells kept and cells changed
    # what is remembered is not part of the law's identity (checkpoint fingerprints)
    from rough_contact.fingerprint import describe
    assert describe(law) == describe(_synthetic(_rho, _drho, _la, _dla))
    hm[::3] -= 0.3 * SIG                               # changed in place: not the same h_min
    got = law.evaluate_history(h, hm, curvature)
    fresh = pickle.loads(pickle.dumps(law)).evaluate_history(h, hm, curvature)
    for x, y in zip(got, fresh):
        np.testing.assert_array_equal(x, y)


def test_without_area_same_p_k_dk():
    law = _synthetic(_rho, _drho, _la, _dla)
    h, hm = _mixed_points(law, 5000, 9)
    full = law.evaluate_history(h, hm, curvature=True)
    part = law.evaluate_history(h, hm, curvature=True, area=False)
    assert part[2] is None
    for i in (0, 1, 3):
        np.testing.assert_array_equal(part[i], full[i])
    rev = HistoryNormalLaw(loading=law.loading, rtol=1e-3)      # reversible: h_min ignored
    p, k, a = rev.evaluate_history(h, hm, area=False)
    assert a is None
    np.testing.assert_array_equal(p, law.loading.evaluate(h)[0])


def test_budget_exhausted_on_a_coarse_level_returns_that_table_or_raises():
    """The coarse row levels of the build have no ghost rows (not-a-knot at the table's
    ends): with strict=False a budget that runs out there returns that table -- a usable law
    (finite, k >= 0, the branch starting on the loading law) flagged as not converged;
    strict=True raises and names the budget."""
    s, mat, loading = _coarse_loading()
    kw = dict(loading=loading, n_quad=8, n_t=16, n_zeta=8, n_rows=3, n_x=2)
    law = HistoryNormalLaw.elasto_plastic(s, mat, 1e-3, strict=False, max_points=150, **kw)
    info = law.info
    assert not info["converged"] and info["levels"][-1][-1] == "interior"
    assert info["worst_error_h_min"] > 0.5e-3 and info["k_nonnegative"]
    rng = np.random.default_rng(2)
    hm = rng.uniform(loading.h_min, loading.h_table_end, 4000)
    h = hm + rng.uniform(0.0, 8.0, 4000) * s.rq
    p, k, a, dk = law.evaluate_history(h, hm, curvature=True)
    assert all(np.all(np.isfinite(v)) for v in (p, k, a, dk)) and np.all(k >= 0)
    np.testing.assert_allclose(law.evaluate_history(hm + 1e-9 * s.rq, hm)[0],
                               loading.evaluate(hm)[0], rtol=1e-6)
    with pytest.raises(RuntimeError, match="max_points = 60"):
        HistoryNormalLaw.elasto_plastic(s, mat, 1e-3, strict=True, max_points=60, **kw)
