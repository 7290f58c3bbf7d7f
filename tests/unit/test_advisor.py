"""The law advisor (rough_contact.advisor): refusals, agreement with the full tables, inputs.

The refusal tests fail if the advisor picks the cheap law where it must not: a high plasticity
index, a load beyond 10 % real area, a nearly isotropic surface with the anisotropic model.
The agreement tests compare the advisor's estimated differences (coarse population sums on a
few separations) with the same differences taken from the tables a run would use
(``NormalLaw``, built independently by adaptive refinement to rtol).
"""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from rough_contact.advisor import (NORMAL_LAWS, Advice, advise, scene_pressure_range,
                                   _N_PRESSURES)
from rough_contact.interface.normal import NormalLaw
from rough_contact.micro import population
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

E_STAR = 1.067e5           # steel on steel [MPa]
TABLE1 = dict(m00=0.625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)   # um convention
TABLE2 = dict(m00=3.0, m20=1.0, m02=81.0, m40=1.0, m04=6561.0)


def table1():
    return SpectralMoments(**TABLE1, unit="um")


def nearly_isotropic():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return SpectralMoments(m00=0.625, m20=8e-4, m02=8.4e-4, m40=1.04e-4, m04=1.092e-4)


def table_difference(simple, full, P):
    """The advisor's measures from two tables: k and A/A0 at equal pressure, the approach
    h(P[0]) - h(P), p at equal separation."""
    hs, hf = simple.separation_for_pressure(P), full.separation_for_pressure(P)
    _, ks, as_ = simple.evaluate(hs)
    _, kf, af = full.evaluate(hf)
    app = np.abs((hs[0] - hs[1:]) / (hf[0] - hf[1:]) - 1.0)
    ps, _, _ = simple.evaluate(hf)
    return dict(pressure=np.max(np.abs(ps / P - 1)), stiffness=np.max(np.abs(ks / kf - 1)),
                area=np.max(np.abs(as_ / af - 1)), approach=app.max())


def population_difference_at(surface, material, p):
    """Largest |k_el/k_ep - 1| and |a_el/a_ep - 1| over the nominal pressures p from the
    converged population sums (default quadrature; Newton on each model's separation with its
    exact stiffness)."""
    p = np.atleast_1d(np.asarray(p, float))

    def at(model):
        grid = np.linspace(-1.0, 6.0, 29) * surface.rq       # start: ln p interpolated
        h = np.interp(-np.log(p), -np.log(model(grid).pressure), grid)
        for _ in range(60):
            r = model(h)
            step = (np.log(r.pressure) - np.log(p)) * r.pressure / r.stiffness
            h = h + step
            if np.all(np.abs(step) < 1e-12 * surface.rq):
                break
        return model(h)
    el = at(lambda h: population.elastic(surface, material.E_star, h))
    ep = at(lambda h: population.elasto_plastic(surface, material, h))
    # the simpler law relative to the fuller one, as the advisor reports it
    return (np.max(np.abs(el.stiffness / ep.stiffness - 1)),
            np.max(np.abs(el.area_fraction / ep.area_fraction - 1)))


# ---------------------------------------------------------------------------------------------
# refusals: the cheap law must not be picked
# ---------------------------------------------------------------------------------------------
def test_refuses_elastic_asperities_at_high_plasticity_index():
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=5.0)
    adv = advise(s, mat, (1.0, 20.0), 0.05)
    # the oracle: the converged population sums at the top of the range differ by > 5 %
    dk, da = population_difference_at(s, mat.resolve(s), 20.0)
    assert max(dk, da) > 0.05
    assert adv.normal not in ("elastic", "greenwood_williamson"), adv.report()
    assert adv.choice("plasticity").picked == "elasto-plastic"
    assert adv.plasticity_index == pytest.approx(5.0, rel=1e-12)


def test_refuses_the_statistical_law_beyond_ten_percent_real_area():
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    adv = advise(s, mat, (10.0, 1000.0), 0.05)
    # independent: the elastic table's own A/A0 at 1000 MPa is beyond 10 %
    law = NormalLaw.elastic(s, E_STAR, 1e-3)
    _, _, a = law.evaluate(law.separation_for_pressure(np.array([1000.0])))
    assert a[0] > 0.10
    assert adv.normal == "bem", adv.report()
    assert not adv.statistical_valid
    assert adv.max_area_fraction > 0.10
    assert "refused" in adv.choice("statistical_vs_bem").reason


def test_refuses_the_anisotropic_model_on_a_nearly_isotropic_surface():
    s = nearly_isotropic()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    # even with a tolerance so loose that every law would pass
    adv = advise(s, mat, (0.1, 3.0), 0.9)
    assert adv.normal == "greenwood_williamson", adv.report()
    assert adv.full_normal == "greenwood_williamson"
    assert "outside its validity" in adv.choice("anisotropy").reason


def test_refuses_the_isotropic_equivalent_where_anisotropy_matters():
    # Table 2's surface (m04/m40 = 6561): McCool's GW table differs from the anisotropic one by
    # about 9 % in k over this range (tables below); at 5 % the anisotropic law must stay
    s = SpectralMoments(**TABLE2, unit="um")
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    P = np.geomspace(0.01, 0.8, _N_PRESSURES)
    d = table_difference(NormalLaw.greenwood_williamson(s, E_STAR),
                         NormalLaw.elastic(s, E_STAR), P)
    assert max(d["stiffness"], d["area"], d["approach"]) > 0.05
    adv = advise(s, mat, (0.01, 0.8), 0.05)
    assert adv.normal == "elastic", adv.report()
    assert "anisotropy matters" in adv.summary()


def test_picks_the_cheapest_law_when_everything_agrees():
    # light load, the project's reading K_Y Y = (2/pi) H at psi = 0.35: no asperity yields
    # (the e-p and elastic sums are identical) and a loose tolerance admits McCool's GW
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    dk, da = population_difference_at(s, mat.resolve(s), 5.0)
    assert max(dk, da) < 1e-6
    adv = advise(s, mat, (0.156, 5.0), 0.05)
    assert adv.choice("plasticity").picked == "elastic"
    assert adv.choice("plasticity").difference.largest < 1e-3
    assert adv.normal == "greenwood_williamson", adv.report()   # GW within 2.2 % here
    assert "elastic asperities suffice" in adv.summary()
    assert adv.statistical_valid
    tight = advise(s, mat, (0.156, 5.0), 0.01)
    assert tight.normal == "elastic"


def test_refuses_mccool_when_the_dissipation_is_wanted_within_tolerance():
    # The punch's Table 1 case (K_Y Y = (2/pi) H, psi = 0.35, 0.156-5 MPa): McCool's GW is
    # within 5 % in k, A/A0 and approach, but the punch's frictional dissipation with it
    # differed by 9.1 % from the full model (benchmarks/bench_advisor.py): with the dissipation
    # among the results GW must be refused. Independent check of the k difference from the
    # full tables (not the advisor's estimate).
    from rough_contact.advisor import DISSIPATION_AMPLIFICATION, RESULTS_ALL

    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    P = np.geomspace(0.156, 5.0, _N_PRESSURES)
    d = table_difference(NormalLaw.greenwood_williamson(s, E_STAR),
                         NormalLaw.elastic(s, E_STAR), P)
    assert DISSIPATION_AMPLIFICATION * d["stiffness"] > 0.05
    adv = advise(s, mat, (0.156, 5.0), 0.05, results=RESULTS_ALL)
    assert adv.normal != "greenwood_williamson", adv.report()
    assert adv.normal == "elastic", adv.report()          # = the full model here (no yield)
    assert "dissipation" in adv.choice("anisotropy").reason
    assert "frictional dissipation" in adv.report()
    # without the dissipation GW is accepted (test_picks_the_cheapest_law_when_everything_agrees)
    assert advise(s, mat, (0.156, 5.0), 0.05, results=("force", "area")).normal == \
        "greenwood_williamson"


def test_punch_scene_advises_with_the_dissipation():
    # the punch scene reports the dissipation: its --law auto must weigh it (on the demo's own
    # surface and data the advised law is unchanged; with the Table 1 case above it must not be
    # McCool's GW)
    pytest.importorskip("dolfinx")
    from rough_contact.scenes import flat_punch

    class Serial:
        rank = 0

        def bcast(self, x, root=0):
            return x

    mat = AsperityMaterial(E_star=flat_punch.effective_modulus(
        flat_punch.E, flat_punch.NU, flat_punch.E, flat_punch.NU), nu=flat_punch.NU, psi=0.35)
    advice, _ = flat_punch.advise_law(Serial(), surface=table1(), material=mat)
    assert "dissipation" in advice.results
    assert advice.normal != "greenwood_williamson", advice.report()


# ---------------------------------------------------------------------------------------------
# the estimates against the full tables
# ---------------------------------------------------------------------------------------------
def _close(estimate, exact):
    # within 10 % of the difference, or 0.3 percentage points where it is small
    return abs(estimate - exact) <= max(0.1 * exact, 3e-3)


@pytest.mark.parametrize("moments, p_range", [(TABLE1, (0.156, 5.0)), (TABLE2, (0.01, 0.8))])
def test_anisotropy_estimate_agrees_with_the_full_tables(moments, p_range):
    s = SpectralMoments(**moments, unit="um")
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    adv = advise(s, mat, p_range, 0.01)
    est = adv.choice("anisotropy").difference
    P = np.geomspace(*p_range, _N_PRESSURES)
    exact = table_difference(NormalLaw.greenwood_williamson(s, E_STAR),
                             NormalLaw.elastic(s, E_STAR), P)
    for q in ("pressure", "stiffness", "area", "approach"):
        assert _close(getattr(est, q), exact[q]), (q, getattr(est, q), exact[q])


def test_plasticity_estimate_agrees_with_the_converged_sums():
    # the demos' caption data (Y = 2070 MPa, K_Y = 1.62, psi = 0.35), over the advisor's
    # pressures, from the converged population sums
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.25, Y=2070.0, K_Y=1.62, psi=0.35)
    est = advise(s, mat, (0.156, 5.0), 0.05).choice("plasticity").difference
    dk, da = population_difference_at(s, mat.resolve(s), np.geomspace(0.156, 5.0, _N_PRESSURES))
    assert _close(est.stiffness, dk) and _close(est.area, da), (est, dk, da)


@pytest.mark.slow
def test_plasticity_estimate_agrees_with_the_full_tables():
    # the demos' caption data (Y = 2070 MPa, K_Y = 1.62, psi = 0.35): the elasto-plastic law
    # differs strongly; tables at rtol 1e-3 (~1e-3 from the model, far below the differences)
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.25, Y=2070.0, K_Y=1.62, psi=0.35)
    p_range = (0.156, 5.0)
    adv = advise(s, mat, p_range, 0.05)
    est = adv.choice("plasticity").difference
    P = np.geomspace(*p_range, _N_PRESSURES)
    exact = table_difference(NormalLaw.elastic(s, E_STAR, 1e-3),
                             NormalLaw.elasto_plastic(s, mat, 1e-3), P)
    for q in ("pressure", "stiffness", "area", "approach"):
        assert _close(getattr(est, q), exact[q]), (q, getattr(est, q), exact[q])
    assert adv.normal == "elasto-plastic"


# ---------------------------------------------------------------------------------------------
# result, report, inputs
# ---------------------------------------------------------------------------------------------
def test_advice_report_json_and_law():
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    adv = advise(s, mat, (0.156, 5.0), 0.01)
    assert isinstance(adv, Advice) and adv.normal in NORMAL_LAWS
    text = adv.report()
    for word in ("advised normal law: elastic", "plasticity", "anisotropy",
                 "statistical_vs_bem", "validity", "advisor wall time"):
        assert word in text
    data = json.loads(adv.to_json())
    assert data["normal"] == "elastic" and data["pressure_range"] == [0.156, 5.0]
    law = adv.normal_law(rtol=1e-3)
    assert law.info["model"] == "elastic"
    # the advisor's own cost is small; its ratio to a table build is measured in
    # benchmarks/bench_advisor.py, not asserted here
    assert adv.advisor_seconds > 0


def test_friction_and_penalty_choices():
    from rough_contact.interface.friction import OrthotropicSlipHardening
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    fr = OrthotropicSlipHardening(mu_macro=0.5, mu_initial_ratio=0.5, hardening=275.0)
    # mean coefficient over a slip s: mu_m (1 - (1 - r)(1 - exp(-n s))/(n s))
    short = advise(s, mat, (0.156, 5.0), 0.05, friction=fr, slip=1e-3)     # n s = 0.275
    assert short.friction == "slip-hardening"
    long = advise(s, mat, (0.156, 5.0), 0.05, friction=fr, slip=1.0)       # n s = 275
    assert long.friction == "coulomb"           # (1 - 0.5)/275 = 0.18 % < 5 %
    stiff_bulk = advise(s, mat, (0.156, 5.0), 0.05, need_real_area=False, bulk_stiffness=1.0)
    assert stiff_bulk.interface == "penalty"
    assert advise(s, mat, (0.156, 5.0), 0.05).interface == "rough"


def test_height_map_input():
    from rough_contact.surface import synthetic_height_map  # noqa: F401  (a map is an array)
    rng = np.random.default_rng(0)
    n = 64
    x = np.arange(n) * 1.0
    z = (np.sin(2 * np.pi * x / 16)[:, None] * 0.1 + np.sin(2 * np.pi * x / 4)[None, :] * 0.3
         + 0.05 * rng.standard_normal((n, n)))
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, H=6000.0)
    adv = advise(z, mat, (0.1, 3.0), 0.05, dx=1.0, unit="um")
    assert adv.normal in NORMAL_LAWS
    with pytest.raises(ValueError, match="dx"):
        advise(z, mat, (0.1, 3.0))


@pytest.mark.parametrize("kwargs, words", [
    (dict(tolerance=0.0), "tolerance = 0.0"),
    (dict(tolerance=1.5), "tolerance = 1.5"),
    (dict(pressure_range=(5.0, 1.0)), "p_max"),
    (dict(pressure_range=(-1.0, 1.0)), "p_min"),
    (dict(pressure_range=3.0), "pressure_range = 3.0"),
    (dict(material="steel"), "material = 'steel'"),
    (dict(slip=-1.0), "slip = -1.0 mm"),
])
def test_bad_inputs(kwargs, words):
    args = dict(surface=table1(), material=AsperityMaterial(E_star=E_STAR, psi=0.35),
                pressure_range=(0.1, 1.0), tolerance=0.05)
    args.update(kwargs)
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(".", r"\.")):
        advise(**args)


def test_scene_pressure_range():
    assert scene_pressure_range(1000.0, 400.0, 0.156, 2.0) == (0.156, 5.0)
    assert scene_pressure_range(100.0, 10.0) == (0.1, 20.0)
    with pytest.raises(ValueError, match="concentration = 0.5"):
        scene_pressure_range(1.0, 1.0, concentration=0.5)
    with pytest.raises(ValueError, match="area = 0"):
        scene_pressure_range(1.0, 0)


def test_elasto_plastic_and_elastic_share_nodes_and_match_the_separate_sums():
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.25, Y=2070.0, K_Y=1.62, psi=0.35).resolve(s)
    h = np.linspace(0.5, 3.0, 4) * s.rq
    ep, el = population.elasto_plastic_and_elastic(s, mat, h)
    ref_ep = population.elasto_plastic(s, mat, h)
    for q in ("pressure", "stiffness", "area_fraction"):
        assert np.array_equal(getattr(ep, q), getattr(ref_ep, q))
    # the elastic twin at the default quadrature equals the closed-form inner integrals of
    # population.elastic (an independent rule) to the quadrature's accuracy
    ref_el = population.elastic(s, E_STAR, h)
    for q in ("pressure", "stiffness", "area_fraction"):
        np.testing.assert_allclose(getattr(el, q), getattr(ref_el, q), rtol=2e-4)


# ---------------------------------------------------------------------------------------------
# the optional small BEM check (bem_check=True)
# ---------------------------------------------------------------------------------------------
def _example(name):
    from rough_contact.surface import example_surfaces
    return example_surfaces()[name][0]


def _needs_tamaas():
    from rough_contact.micro import bem
    if "tamaas" not in bem.available_backends():
        pytest.skip("the BEM check needs Tamaas (the extra rough_contact[bem]), not installed")


def test_bem_check_refuses_the_statistical_law_the_measured_figures_would_keep(monkeypatch):
    # Anisotropic example surface (m04/m40 = 100, alpha = 10) at 120-350 MPa: measured against
    # 12-realisation BEM (docs/bem.md, an independent study) the statistical k at equal load is
    # 0.75 of BEM at 119 MPa and 0.47 at 350 MPa. With the measured figures neutralised (they
    # would call the law valid at any area), the refusal must come from the check itself.
    _needs_tamaas()
    import rough_contact.advisor as advisor
    from rough_contact.advisor import BEMCheck

    s = _example("anisotropic")
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    monkeypatch.setattr(advisor, "STATISTICAL_VALID_AREA", 1.0)
    ignored = advise(s, mat, (120.0, 350.0), 0.05)
    assert ignored.statistical_valid and ignored.normal != "bem"       # without the check
    adv = advise(s, mat, (120.0, 350.0), 0.05,
                 bem_check=BEMCheck(n_realisations=6, n_pressures=3, cache=False))
    c = adv.bem_check
    assert c is not None and c.verdict == "refused", adv.report()
    assert adv.normal == "bem" and not adv.statistical_valid
    assert "small BEM check" in adv.choice("statistical_vs_bem").reason
    # the check's figures against the independent measurement (docs/bem.md), within the
    # sampling error of 6 realisations plus the coarse grid (k within ~7 %)
    np.testing.assert_allclose(c.pressures[[0, -1]], [120.0, 350.0])
    assert abs(c.stiffness_ratio[0] - 0.75) < 0.1 and abs(c.stiffness_ratio[-1] - 0.47) < 0.1
    assert c.stiffness_ratio[-1] + 2 * c.stiffness_se[-1] < 0.9
    # the check's time is not the advisor's own cost
    assert adv.advisor_seconds < c.seconds


def test_bem_check_keeps_the_statistical_law_where_it_is_valid():
    # Light load on the same surface (A/A0 <= 2.6 %): the 12-realisation study puts the
    # statistical k at equal load within 10 % of BEM (1.04 at 8 MPa, 0.94 at 41 MPa), so the
    # check must not refuse it. (The old check solved one random-amplitude realisation and
    # compared p at equal separation: 1.3-1.8 from realisation scatter alone, refused.)
    _needs_tamaas()
    from rough_contact.advisor import BEMCheck

    s = _example("anisotropic")
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    adv = advise(s, mat, (8.0, 40.0), 0.05,
                 bem_check=BEMCheck(n_realisations=6, n_pressures=3, cache=False))
    assert adv.bem_check is not None and adv.bem_check.verdict != "refused", adv.report()
    assert adv.statistical_valid and adv.normal == "elastic", adv.report()
    assert "small BEM check" in adv.choice("statistical_vs_bem").reason
    data = json.loads(adv.to_json())
    assert data["bem_check"]["verdict"] == adv.bem_check.verdict


def test_bem_check_without_tamaas_is_skipped_with_a_note(monkeypatch):
    from rough_contact.micro import bem

    monkeypatch.setattr(bem, "available_backends", lambda: ("numpy",))
    s = table1()
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    adv = advise(s, mat, (0.156, 5.0), 0.05, bem_check=True)
    plain = advise(s, mat, (0.156, 5.0), 0.05)
    assert adv.normal == plain.normal and adv.bem_check is None
    assert "Tamaas" in adv.choice("statistical_vs_bem").reason


def test_bem_check_options_are_checked():
    from rough_contact.advisor import BEMCheck
    with pytest.raises(ValueError, match="n_realisations = 1"):
        BEMCheck(n_realisations=1)
    with pytest.raises(ValueError, match="pixels_per_wavelength = 1"):
        BEMCheck(pixels_per_wavelength=1)


@pytest.mark.slow
def test_bem_check_refuses_the_statistical_law_on_a_broadband_surface():
    # The paper's surface taken as self-affine (alpha = 102) at 10-50 MPa: the statistical
    # A/A0 stays below 3 %, where the measured figures (narrow-band surfaces) call the law
    # valid; on the broadband self-affine example (alpha = 43) the 12-realisation study found
    # k at equal load 16-23 % high at light load. The check (8 realisations) must refuse it.
    _needs_tamaas()
    from rough_contact.advisor import BEMCheck

    s = _example("paper")
    mat = AsperityMaterial(E_star=E_STAR, nu=0.3, psi=0.35)
    plain = advise(s, mat, (5.0, 50.0), 0.05)
    assert plain.statistical_valid and plain.max_area_fraction < 0.03
    adv = advise(s, mat, (5.0, 50.0), 0.05, bem_check=BEMCheck(pixels_per_wavelength=2,
                                                                cache=False))
    assert adv.bem_check.verdict == "refused" and adv.normal == "bem", adv.report()


def test_curve_separation_inverts_the_interpolated_pressure():
    # _Curve.separation (Newton inside a shrinking bracket) against the forward evaluation
    # at_h of the same Hermite curve: p(h(P)) = P; and at_pressure's memo returns copies
    from rough_contact.advisor import _Curve

    s = table1()
    h = np.linspace(0.0, 3.5, 8) * s.rq
    c = _Curve.of(population.elastic(s, E_STAR, h, n_quad=16), h)
    P = np.geomspace(c.p[-1] * 1.0001, c.p[0] * 0.9999, 57)
    x = c.separation(P)
    assert np.all(np.diff(x) < 0)
    p, _ = c.at_h(x)
    assert np.max(np.abs(p / P - 1.0)) < 1e-11
    a = c.at_pressure(P)
    a[0][:] = 0.0
    assert np.array_equal(c.at_pressure(P)[0], x)
