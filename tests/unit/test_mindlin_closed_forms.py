"""Cattaneo–Mindlin / Mindlin–Deresiewicz closed forms (rough_contact.references) against
things derived independently here: the loop area of Masing's branches built from the
monotonic compliance curve (numerical quadrature), the series of the energy at small amplitude,
and the stiffness of a stuck circular contact."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from rough_contact import references as ref
from rough_contact.scenes import mindlin

MU, P, G, NU, A = 0.3, 120.0, 7.0e4, 0.3, 0.2


@pytest.mark.parametrize("q", [0.05, 0.3, 0.6, 0.9, 1.0])
def test_energy_is_the_masing_loop_area(q):
    """Unloading from Q* follows delta* - 2 delta((Q* - Q) / 2), reloading the mirror image:
    the enclosed area is the energy per cycle."""
    Qs = q * MU * P

    def delta(Q):
        return ref.tangential_approach(Q, MU, P, A, G, NU)

    ds = delta(Qs)
    area = quad(lambda Q: (ds - 2 * delta((Qs - Q) / 2)) - (-ds + 2 * delta((Qs + Q) / 2)),
                -Qs, Qs, epsabs=0, epsrel=1e-12)[0]
    assert ref.energy_per_cycle(Qs, MU, P, A, G, NU) == pytest.approx(area, rel=1e-9)


def test_small_amplitude_limit_is_cubic():
    for q in (1e-3, 1e-2):
        Qs = q * MU * P
        exact = ref.energy_per_cycle(Qs, MU, P, A, G, NU)
        small = ref.energy_per_cycle_small(Qs, MU, P, A, G, NU)
        assert exact == pytest.approx(small, rel=2 * q)      # next term is O(q^4)
    # the cubic coefficient from the series of the bracket: 5/162 q^3
    Qs = 1e-3 * MU * P
    bracket = ref.energy_per_cycle(Qs, MU, P, A, G, NU) / (
        9 * MU**2 * P**2 * (2 - NU) / (10 * G * A))
    assert bracket / 1e-9 == pytest.approx(5 / 162, rel=1e-2)


def test_stick_ratio_and_stiffness_limits():
    assert ref.stick_ratio(0.0, MU, P) == 1.0
    assert ref.stick_ratio(MU * P, MU, P) == 0.0
    assert ref.stick_ratio(0.875 * MU * P, MU, P) == pytest.approx(0.5)
    dQ = 1e-6 * MU * P
    k0 = dQ / ref.tangential_approach(dQ, MU, P, A, G, NU)
    assert k0 == pytest.approx(8 * G * A / (2 - NU), rel=1e-5)   # stuck circular contact


def test_paraboloid_indenter_gap():
    ind = mindlin.ParaboloidIndenter(10.0)
    g, n = ind.gap_and_normal(np.array([[0.3, 0.4, 0.0], [0.0, 0.0, -0.01]]))
    np.testing.assert_allclose(g, [0.25 / 20.0, 0.01])
    np.testing.assert_allclose(n, [[0, 0, -1], [0, 0, -1]])


def test_bad_input():
    with pytest.raises(ValueError, match=r"Q / \(mu P\) = 1.5 is invalid"):
        ref.stick_ratio(1.5 * MU * P, MU, P)
    with pytest.raises(ValueError, match="P = -1"):
        ref.energy_per_cycle(1.0, MU, -1.0, A, G, NU)
    with pytest.raises(ValueError, match="a = 0"):
        ref.tangential_approach(1.0, MU, P, 0.0, G, NU)
    with pytest.raises(ValueError, match="radius"):
        mindlin.ParaboloidIndenter(0.0)


def test_hertz_closed_forms_are_consistent():
    """a^2 = R delta (the geometry of the contact) and the pressure integrates to P."""
    R, E_star, delta = 10.0, 2.2e5, 4e-3
    P = ref.hertz_force(delta, R, E_star)
    a = ref.hertz_radius(P, R, E_star)
    assert a == pytest.approx(np.sqrt(R * delta), rel=1e-12)
    p0 = ref.hertz_peak_pressure(P, a)
    total = quad(lambda r: 2 * np.pi * r * ref.hertz_pressure(r, p0, a), 0.0, a,
                 epsabs=0, epsrel=1e-12)[0]
    assert total == pytest.approx(P, rel=1e-9)
    assert ref.hertz_pressure(1.5 * a, p0, a) == 0.0
    # two identical elastic bodies: half the modulus of one on a rigid body
    assert ref.effective_modulus(2e5, 0.3, 2e5, 0.3) == pytest.approx(
        0.5 * ref.effective_modulus(2e5, 0.3, np.inf, 0.0), rel=1e-14)


def test_references_import_no_fe_stack(imports_without):
    """The oracles are pure numpy: importing them pulls in no DOLFINx, MPI or PETSc."""
    imports_without(["rough_contact.references"])


def _masing_fretting_loop(delta_s):
    """Q* and the loop area under an imposed displacement amplitude delta*, built numerically:
    the virgin curve Q(delta) by root-finding on Mindlin's delta(Q) (saturating at mu P beyond
    the sliding approach), Masing's branches U(d) = -Q* + 2 Q((d + delta*) / 2) and
    L(d) = -U(-d), the area by quadrature."""
    from scipy.optimize import brentq

    K = ref.sliding_approach(MU, P, A, G, NU)

    def virgin(d):
        if d >= K:
            return MU * P
        return brentq(lambda Q: ref.tangential_approach(Q, MU, P, A, G, NU) - d, 0.0, MU * P,
                      xtol=1e-14 * MU * P, rtol=1e-15)

    Qs = virgin(delta_s)

    def upper(d):
        return -Qs + 2.0 * virgin(0.5 * (d + delta_s))

    kinks = [k for k in (2 * K - delta_s,) if -delta_s < k < delta_s]
    area = quad(lambda d: upper(d) + upper(-d), -delta_s, delta_s, points=kinks or None,
                epsabs=0, epsrel=1e-10, limit=200)[0]
    return Qs, area


@pytest.mark.parametrize("x", [0.1, 0.5, 0.9, 1.0, 1.3, 2.0, 5.0])
def test_fretting_cycle_is_the_masing_loop_under_imposed_displacement(x):
    """Energy, force amplitude and energy ratio A = W / (4 Q* delta*) of fretting_cycle against
    the loop built numerically from the monotonic curve (partial and gross slip)."""
    K = ref.sliding_approach(MU, P, A, G, NU)
    Qs, area = _masing_fretting_loop(x * K)
    Q, W, ratio = ref.fretting_cycle(x * K, MU, P, A, G, NU)
    assert Q == pytest.approx(Qs, rel=1e-9)
    assert W == pytest.approx(area, rel=1e-7)
    assert ratio == pytest.approx(area / (4 * Qs * x * K), rel=1e-7)


def test_fretting_energy_ratio_limits():
    """Closed forms derived by hand: A -> delta* / (12 delta_t) for small amplitudes
    (W ~ 5/162 q^3 x 4.8 mu P delta_t, delta* ~ 2/3 q delta_t), A = 0.2 at the transition
    delta* = delta_t (Fouvry's A_t of a sphere on a flat), A = 1 - 0.8 delta_t / delta* in
    gross slip (-> 1: the rectangle of rigid-plastic sliding), and no energy without motion."""
    K = ref.sliding_approach(MU, P, A, G, NU)
    d = np.array([1e-4, 1e-3]) * K
    ratio = ref.fretting_cycle(d, MU, P, A, G, NU)[2]
    np.testing.assert_allclose(ratio, d / (12 * K), rtol=2e-3)
    assert ref.fretting_cycle(K, MU, P, A, G, NU)[2] == pytest.approx(0.2, rel=1e-12)
    x = np.array([1.0, 1.5, 3.0, 100.0])
    np.testing.assert_allclose(ref.fretting_cycle(x * K, MU, P, A, G, NU)[2], 1 - 0.8 / x,
                               rtol=1e-12)
    Q, W, ratio = ref.fretting_cycle(0.0, MU, P, A, G, NU)
    assert Q == W == ratio == 0.0
    # A rises monotonically through the transition
    a_of_x = ref.fretting_cycle(np.linspace(0.01, 4, 400) * K, MU, P, A, G, NU)[2]
    assert np.all(np.diff(a_of_x) > 0)
    with pytest.raises(ValueError, match="delta_amplitude = -1"):
        ref.fretting_cycle(-1.0, MU, P, A, G, NU)
    # the dimensionless form used by the fretting map
    x = np.array([0.2, 1.0, 2.5])
    np.testing.assert_allclose(ref.fretting_energy_ratio(x),
                               ref.fretting_cycle(x * K, MU, P, A, G, NU)[2], rtol=1e-12)
