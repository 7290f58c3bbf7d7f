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
