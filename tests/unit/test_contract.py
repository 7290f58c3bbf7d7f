"""The interface-law contract: LawResult.check, check_jump, the failure types, every built-in law
returning a conforming LawResult, and the friction laws' public evaluate."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rough_contact.interface.contract import (ConvergenceError, InterfaceLawProtocol,
                                              LawContractError, LawResult, LawState, check_jump)
from rough_contact.interface.friction import (FrictionInput, FrictionOutput,
                                              IsotropicSlipHardening, OrthotropicSlipHardening,
                                              ReturnMappingError)
from rough_contact.interface.law import InterfaceLaw, NormalLawProtocol, SeatableNormalLaw
from rough_contact.interface.normal import NormalLaw
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.interface.state import InterfaceState
from rough_contact.interface.tangential import TangentialStiffness
from rough_contact.surface import SpectralMoments

FIELDS = ("traction", "tangent", "dissipation", "area_fraction", "contact", "slipping")


def good_result(n=4):
    return LawResult(np.zeros((n, 3)), np.zeros((n, 3, 3)), InterfaceState.zeros(n), np.zeros(n),
                     np.zeros(n), np.zeros(n, bool), np.zeros(n, bool))


def test_check_accepts_a_conforming_result():
    good_result(4).check(4)
    good_result(0).check(0)
    assert np.array_equal(good_result(3).pressure, np.zeros(3))


@pytest.mark.parametrize("name", FIELDS)
def test_check_names_a_missing_field(name):
    r = dataclasses.replace(good_result(4), **{name: None})
    with pytest.raises(LawContractError, match=rf"LawResult\.{name} must be a numpy array"):
        r.check(4)


@pytest.mark.parametrize("name", FIELDS)
def test_check_names_a_field_of_wrong_shape(name):
    r = good_result(4)
    bad = np.zeros((5,) + getattr(r, name).shape[1:], dtype=getattr(r, name).dtype)
    with pytest.raises(LawContractError, match=rf"LawResult\.{name} has shape \(5,"):
        dataclasses.replace(r, **{name: bad}).check(4)
    flat = getattr(r, name).reshape(-1)  # right size, wrong rank
    if flat.shape != getattr(r, name).shape:
        with pytest.raises(LawContractError, match=rf"LawResult\.{name} has shape"):
            dataclasses.replace(r, **{name: flat}).check(4)


@pytest.mark.parametrize("name", FIELDS)
def test_check_names_a_field_of_wrong_dtype(name):
    r = good_result(4)
    value = getattr(r, name)
    bad = value.astype(np.int64) if value.dtype == np.float64 else value.astype(np.float64)
    with pytest.raises(LawContractError, match=rf"LawResult\.{name} has dtype"):
        dataclasses.replace(r, **{name: bad}).check(4)


def test_check_names_a_bad_state():
    r = good_result(4)
    with pytest.raises(LawContractError, match=r"LawResult\.state \(dict\)"):
        dataclasses.replace(r, state={"plastic_slip": np.zeros((4, 2))}).check(4)
    with pytest.raises(LawContractError, match=r"LawResult\.state holds 3 points"):
        dataclasses.replace(r, state=InterfaceState.zeros(3)).check(4)
    assert issubclass(LawContractError, TypeError)


def test_check_jump():
    st = InterfaceState.zeros(3)
    j = np.zeros((3, 3))
    assert check_jump(j, st) is j  # no copy of a float array
    assert check_jump([[0, 0, 0]] * 3, st).dtype == np.float64
    with pytest.raises(ValueError, match=r"jump must have shape \(n_pts, 3\), got \(3, 2\)"):
        check_jump(np.zeros((3, 2)), st)
    with pytest.raises(ValueError, match="LawState with 4 points"):
        check_jump(np.zeros((4, 3)), st)
    with pytest.raises(ValueError, match="got dict"):
        check_jump(j, {})
    bad = np.zeros((3, 3))
    bad[1, 2], bad[2, 0] = np.nan, -np.inf
    with pytest.raises(ConvergenceError, match=r"not finite at 2 of 3 points \(first index 1\)"):
        check_jump(bad, st)


def test_failure_types():
    assert issubclass(ConvergenceError, ArithmeticError)
    assert issubclass(ReturnMappingError, ConvergenceError)
    assert not issubclass(ConvergenceError, ValueError)  # a bad input never triggers a cutback


def test_return_map_failure_through_the_law_is_a_convergence_error(monkeypatch):
    import rough_contact.interface.friction as fr

    monkeypatch.setattr(fr, "_MAX_ITER", 1)
    law = InterfaceLaw(NormalLaw.greenwood_williamson(SURF, E_STAR), TangentialStiffness((0.7, 1.0)),
                       OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (200.0, 50.0),
                                                potential_axes=(0.1, 0.2))).with_seating(1.0)
    jump = np.column_stack([np.zeros(10), np.linspace(1e-3, 2e-3, 10), np.linspace(-1e-3, 1e-3, 10)])
    with pytest.raises(ConvergenceError, match=r"did not converge at \d+ of 10 slipping points"):
        law.evaluate(jump, law.initial_state(10))


# ------------------------------------------------------------------ every built-in law conforms
SURF = SpectralMoments(0.625, 8e-5, 8e-4, 1.04e-6, 1.04e-4)  # paper, Fig. 18 (um units)
E_STAR = 2.0e5 / (2 * (1 - 0.25**2))


@pytest.fixture(scope="module")
def gw_normal():
    return NormalLaw.greenwood_williamson(SURF, E_STAR)


def built_in_laws(normal):
    ts = TangentialStiffness((0.7, 1.0))
    return {
        "rough_ortho": InterfaceLaw(normal, ts, OrthotropicSlipHardening(
            (0.5, 0.3), (0.5, 0.6), (275.0, 275.0), potential_axes=(0.125, 0.2))).with_seating(1.0),
        "rough_ortho_k": InterfaceLaw(normal, ts, OrthotropicSlipHardening(
            (0.5, 0.3), (0.5, 0.6), (275.0, 100.0), potential_exponent=0.5)).with_seating(1.0),
        "rough_iso": InterfaceLaw(normal, TangentialStiffness((0.7, 0.7)),
                                  IsotropicSlipHardening(0.4, 0.5, 275.0)).with_seating(1.0),
        "rough_frictionless": InterfaceLaw(normal).with_seating(1.0),
        "linear_penalty": LinearPenalty(1e4, 2e3, unilateral=True),
        "softplus_penalty": SoftplusPenalty(1e4, 1e-3, 5e3, 0.3),
    }


@pytest.mark.parametrize("name", ["rough_ortho", "rough_ortho_k", "rough_iso",
                                  "rough_frictionless", "linear_penalty", "softplus_penalty"])
@pytest.mark.parametrize("n", [0, 1, 500])
def test_built_in_law_returns_a_conforming_result(gw_normal, name, n):
    law = built_in_laws(gw_normal)[name]
    assert isinstance(law, InterfaceLawProtocol)
    rng = np.random.default_rng(5)
    committed = law.initial_state(n)
    assert isinstance(committed, LawState) and len(committed) == n
    committed.plastic_slip[:] = rng.normal(size=(n, 2)) * 1e-4
    # open, stick and slip points: gaps from -2 to +4 um, slips up to ~1e-2 mm
    jump = np.column_stack([rng.uniform(-2e-3, 4e-3, n),
                            committed.plastic_slip + rng.normal(size=(n, 2))
                            * 10.0 ** rng.uniform(-7, -2, (n, 1))])
    before = committed.copy()
    r = law.evaluate(jump, committed)
    r.check(n)
    np.testing.assert_array_equal(committed.plastic_slip, before.plastic_slip)  # pure
    assert np.isfinite(r.traction).all() and np.isfinite(r.tangent).all()
    assert np.all(r.pressure >= 0) and np.all(r.dissipation >= 0)
    assert np.all((r.area_fraction >= 0) & (r.area_fraction <= 1))
    np.testing.assert_array_equal(r.contact, r.pressure > 0)
    assert not np.any(r.slipping & ~r.contact)
    if n == 500 and name not in ("rough_frictionless", "linear_penalty"):
        assert r.slipping.any() and (r.contact & ~r.slipping).any()


def test_normal_law_protocols(gw_normal):
    assert isinstance(gw_normal, SeatableNormalLaw) and isinstance(gw_normal, NormalLawProtocol)
    with pytest.raises(ValueError, match="NormalLawProtocol"):
        InterfaceLaw(object(), h0=0.0)
    with pytest.raises(ValueError, match="InterfaceState"):
        InterfaceLaw(gw_normal, h0=0.0).evaluate(np.zeros((1, 3)), {"plastic_slip": np.zeros((1, 2))})


# ------------------------------------------------------------------ friction: public evaluate
@pytest.mark.parametrize("friction", [
    OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.7), (275.0, 100.0), potential_axes=(0.125, 0.2)),
    IsotropicSlipHardening(0.4, 0.5, 275.0)], ids=["ortho", "iso"])
@pytest.mark.parametrize("kt_y", [1e4, 1.4e4], ids=["kt_iso", "kt_aniso"])
def test_friction_evaluate_matches_return_map_and_writes_in_place(friction, kt_y):
    rng = np.random.default_rng(9)
    m = 300
    e = rng.normal(size=(m, 2)) * 10.0 ** rng.uniform(-6, -3, (m, 1))
    kt = np.column_stack([np.full(m, 1e4), np.full(m, kt_y)])
    dkt = -kt * 1e3
    p, kn = rng.uniform(0.1, 5.0, m), rng.uniform(1e3, 1e5, m)
    kap, path = rng.uniform(0, 1e-3, (m, 2)), rng.uniform(0, 1e-3, m)
    ref = friction.evaluate(FrictionInput.from_pairs(e, kt, dkt, p, kn, kap, path))
    pts = FrictionInput(e[:, 0].copy(), e[:, 1].copy(), kt[:, 0].copy(), kt[:, 1].copy(),
                        dkt[:, 0].copy(), dkt[:, 1].copy(), p, kn, kap[:, 0].copy(),
                        kap[:, 1].copy(), path)
    snapshot = [getattr(pts, f).copy() for f in pts.__dataclass_fields__]
    big_t, big_D = np.zeros((m, 3)), np.zeros((m, 3, 3))  # as in the composed law: views
    out = friction.evaluate(pts, big_t[:, 1:], big_D[:, 1:, :])
    assert isinstance(out, FrictionOutput)
    assert np.shares_memory(out.traction, big_t) and np.shares_memory(out.tangent, big_D)
    np.testing.assert_array_equal(big_t[:, 1:], ref.traction)
    np.testing.assert_array_equal(big_D[:, 1:, :], ref.tangent)
    assert np.all(big_t[:, 0] == 0) and np.all(big_D[:, 0, :] == 0)  # nothing outside the view
    np.testing.assert_array_equal(np.flatnonzero(ref.slipping), out.slip_index)
    np.testing.assert_array_equal(ref.plastic_increment[out.slip_index, 0], out.plastic_increment_x)
    np.testing.assert_array_equal(ref.plastic_increment[out.slip_index, 1], out.plastic_increment_y)
    np.testing.assert_allclose(out.path_increment, np.hypot(out.plastic_increment_x,
                                                            out.plastic_increment_y), rtol=1e-15)
    assert 0 < out.slip_index.size < m
    for f, before in zip(pts.__dataclass_fields__, snapshot):  # inputs untouched
        np.testing.assert_array_equal(getattr(pts, f), before)
    # without output arrays: allocated, same numbers
    out2 = friction.evaluate(pts)
    np.testing.assert_array_equal(out2.traction, ref.traction)
    # nothing slips: an empty slip set, not None
    calm = friction.evaluate(pts.take(np.flatnonzero(~ref.slipping)))
    assert calm.slip_index.size == 0 and calm.iterations == 0


def test_friction_evaluate_bad_input():
    fr = IsotropicSlipHardening(0.4)
    cols = [np.zeros(3)] * 11
    with pytest.raises(ValueError, match=r"FrictionInput\.kt_y must be a 1-D array .* \(3\)"):
        FrictionInput(*cols[:3], np.zeros(4), *cols[4:])
    with pytest.raises(ValueError, match=r"FrictionInput\.elastic_slip_x"):
        FrictionInput(np.zeros((3, 1)), *cols[1:])
    pts = FrictionInput(*cols)
    with pytest.raises(ValueError, match=r"traction must be a float64 array of shape \(3, 2\)"):
        fr.evaluate(pts, np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"tangent must be a float64 array of shape \(3, 2, 3\)"):
        fr.evaluate(pts, None, np.zeros((3, 2, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="FrictionInput"):
        fr.evaluate({"pressure": np.zeros(3)})


# ------------------------------------------------------------------ model validity
def test_beyond_validity_is_optional_and_checked():
    r = good_result(4)
    assert r.beyond_validity is None
    dataclasses.replace(r, beyond_validity=np.zeros(4, bool)).check(4)
    with pytest.raises(LawContractError, match=r"LawResult\.beyond_validity has shape \(3,\)"):
        dataclasses.replace(r, beyond_validity=np.zeros(3, bool)).check(4)
    with pytest.raises(LawContractError, match=r"LawResult\.beyond_validity has dtype float64"):
        dataclasses.replace(r, beyond_validity=np.zeros(4)).check(4)


@pytest.mark.parametrize("name", ["rough_ortho", "rough_frictionless"])
def test_rough_law_reports_points_below_the_table(gw_normal, name):
    """beyond_validity is exactly the normal law's h < h_min (its lowest knot) at h0 + g."""
    law = built_in_laws(gw_normal)[name]
    h_min = gw_normal.knots[0]
    g = np.array([h_min - 1e-4, h_min - 1e-9, h_min + 1e-9, h_min + 1e-3, 1.0]) - law.h0
    jump = np.column_stack([g, np.zeros((5, 2))])
    r = law.evaluate(jump, law.initial_state(5))
    np.testing.assert_array_equal(r.beyond_validity, [True, True, False, False, False])


def test_penalty_laws_have_no_validity_limit():
    for law in (LinearPenalty(1e4, 2e3, unilateral=True), SoftplusPenalty(1e4, 1e-3, 5e3, 0.3)):
        assert law.evaluate(np.full((2, 3), -1.0), law.initial_state(2)).beyond_validity is None


def test_friction_bounded_laws(gw_normal):
    from rough_contact.interface.contract import FrictionBoundedLaw

    laws = built_in_laws(gw_normal)
    assert laws["rough_ortho"].max_friction_coefficient() == 0.5        # saturated, largest axis
    assert laws["rough_iso"].max_friction_coefficient() == 0.4
    assert laws["rough_frictionless"].max_friction_coefficient() == 0.0
    assert laws["softplus_penalty"].max_friction_coefficient() == 0.3
    assert SoftplusPenalty(1e4, 1e-3).max_friction_coefficient() == 0.0  # no tangential stiffness
    assert all(isinstance(laws[k], FrictionBoundedLaw) for k in
               ("rough_ortho", "rough_iso", "rough_frictionless", "softplus_penalty"))
    assert not isinstance(laws["linear_penalty"], FrictionBoundedLaw)   # unbounded spring


def test_newton_tangent_laws(gw_normal):
    """Only the Coulomb penalty declares a Newton-step tangent; it returns the consistent
    tangent at the first Jacobian of a solve (no memo yet) and the memo has one row per point."""
    from rough_contact.interface.contract import NewtonTangentLaw

    laws = built_in_laws(gw_normal)
    assert [k for k, law in laws.items() if isinstance(law, NewtonTangentLaw)] == \
        ["softplus_penalty"]
    law = laws["softplus_penalty"]
    jump = np.array([[-1e-3, 2e-3, 0.0], [-1e-3, 0.0, -5e-3]])
    res = law.evaluate(jump, law.initial_state(2))
    tangent, memo = law.newton_tangent(jump, law.initial_state(2), res, None)
    np.testing.assert_array_equal(tangent, res.tangent)
    assert memo.shape == (2, 2)


def test_multiplier_laws(gw_normal):
    """The Coulomb penalty and the rough law (its friction part, issue 22) declare the
    multiplier capability, the linear penalty does not; the law the penalty returns for given
    multipliers follows the contract (the rough law's: tests/unit/test_rough_multiplier.py)."""
    from rough_contact.interface.contract import MultiplierLaw

    laws = built_in_laws(gw_normal)
    assert [k for k, law in laws.items() if isinstance(law, MultiplierLaw)] == \
        ["rough_ortho", "rough_ortho_k", "rough_iso", "rough_frictionless", "softplus_penalty"]
    plain = laws["softplus_penalty"]
    state = plain.initial_state(3)
    law = plain.with_multipliers(np.full((3, 3), 0.1))
    res = law.evaluate(np.array([[-1e-3, 2e-3, 0.0]] * 3), state)
    res.check(3)
    assert np.all(res.traction != plain.evaluate(np.array([[-1e-3, 2e-3, 0.0]] * 3),
                                                 state).traction)
