"""Alart–Curnier's complementarity function (rough_contact.interface.alart_curnier) and the
SemismoothNewton enforcement's arguments.

Checked against what the function must encode, not against its own output:
* Phi = 0 exactly on states that satisfy Signorini's and Coulomb's conditions (built from
  their definitions: open with zero traction; closed and sticking inside the cone; closed and
  slipping on the cone with the slip along the traction), for any augmentation r;
* Phi != 0 on states that break one condition (penetration, tension, a traction outside the
  cone, a slip against the traction, a sticking point that moved);
* the generalised derivative equals central finite differences away from the branch switches,
  on every branch, with per-point r;
* the committed plastic slip and the dissipation of a slipping solution: s_p = s and
  D = mu p |s - s_p,old|.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rough_contact.interface.alart_curnier import alart_curnier
from rough_contact.interface.enforcement import SemismoothNewton
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.penalty import SoftplusPenalty

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared stand-in laws
from law_test_helpers import QuadraticNormal  # noqa: E402

MU = 0.3


def _solutions(rng, n):
    """n states of each kind that satisfy the Signorini-Coulomb conditions:
    (traction, jump, committed plastic slip)."""
    sp = rng.normal(size=(3 * n, 2)) * 1e-3
    t = np.zeros((3 * n, 3))
    j = np.zeros((3 * n, 3))
    # open: g > 0, t = 0, any slip
    j[:n, 0] = rng.uniform(1e-4, 1e-2, n)
    j[:n, 1:] = rng.normal(size=(n, 2)) * 1e-3
    # closed, sticking: g = 0, p > 0, |t_T| < mu p, s = s_p
    p = rng.uniform(1.0, 100.0, n)
    ang = rng.uniform(0, 2 * np.pi, n)
    rad = rng.uniform(0.0, 0.95, n) * MU * p
    t[n:2 * n, 0] = -p
    t[n:2 * n, 1:] = rad[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    j[n:2 * n, 1:] = sp[n:2 * n]
    # closed, slipping: g = 0, t_T = mu p m, s - s_p = lam m, lam > 0
    p = rng.uniform(1.0, 100.0, n)
    m = rng.normal(size=(n, 2))
    m /= np.linalg.norm(m, axis=1)[:, None]
    lam = rng.uniform(1e-5, 1e-3, n)
    t[2 * n:, 0] = -p
    t[2 * n:, 1:] = MU * p[:, None] * m
    j[2 * n:, 1:] = sp[2 * n:] + lam[:, None] * m
    return t, j, sp


@pytest.mark.parametrize("r", [1e2, 1e5, 1e8])
def test_zero_exactly_on_solutions(r):
    rng = np.random.default_rng(1)
    t, j, sp = _solutions(rng, 20)
    res = alart_curnier(t, j, sp, MU, r, 3.0 * r)
    scale = np.abs(t).max()
    assert np.abs(res.residual).max() <= 1e-12 * scale
    assert res.contact[20:].all() and not res.contact[:20].any()
    assert res.slipping[40:].all() and not res.slipping[:40].any()
    # the committed plastic slip of a slipping solution is the slip itself; sticking: unchanged
    np.testing.assert_allclose(res.plastic_slip[40:], j[40:, 1:], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(res.plastic_slip[20:40], sp[20:40])
    # D = t_T . (s - s_p,old) = mu p |s - s_p,old| when slipping
    D = MU * -t[40:, 0] * np.linalg.norm(j[40:, 1:] - sp[40:], axis=1)
    np.testing.assert_allclose(res.dissipation[40:], D, rtol=1e-12)
    assert np.all(res.dissipation[20:40] == 0.0)


def test_nonzero_when_a_condition_is_broken():
    rng = np.random.default_rng(2)
    t, j, sp = _solutions(rng, 5)
    cases = []
    tt, jj = t.copy(), j.copy(); jj[5, 0] = -1e-4; cases.append((tt, jj))      # penetration
    tt, jj = t.copy(), j.copy(); tt[0, 0] = +1.0; cases.append((tt, jj))       # tension, open
    tt, jj = t.copy(), j.copy(); tt[5, 1:] *= 10.0 * MU / max(
        np.linalg.norm(tt[5, 1:]) / -tt[5, 0], 1e-3); cases.append((tt, jj))  # outside the cone
    tt, jj = t.copy(), j.copy(); jj[10, 1:] = 2 * sp[10] - jj[10, 1:]; cases.append((tt, jj))
    tt, jj = t.copy(), j.copy(); jj[6, 1:] += 1e-4; cases.append((tt, jj))     # stick moved
    tt, jj = t.copy(), j.copy(); tt[1, 1] = 0.5; cases.append((tt, jj))        # shear while open
    for tt, jj in cases:
        res = alart_curnier(tt, jj, sp, MU, 1e4, 1e4)
        assert np.abs(res.residual).max() > 1e-6


def _fd(t, j, sp, rn, rt, h_t=1e-6, h_j=1e-9):
    n = t.shape[0]
    dt = np.zeros((n, 3, 3))
    dj = np.zeros((n, 3, 3))
    for k in range(3):
        e = np.zeros(3); e[k] = 1.0
        dt[:, :, k] = (alart_curnier(t + h_t * e, j, sp, MU, rn, rt).residual
                       - alart_curnier(t - h_t * e, j, sp, MU, rn, rt).residual) / (2 * h_t)
        dj[:, :, k] = (alart_curnier(t, j + h_j * e, sp, MU, rn, rt).residual
                       - alart_curnier(t, j - h_j * e, sp, MU, rn, rt).residual) / (2 * h_j)
    return dt, dj


def test_derivative_against_finite_differences():
    """Random states on every branch (open, stick, slip), per-point r; points within the FD
    step of a branch switch are left out."""
    rng = np.random.default_rng(3)
    n = 600
    t = np.column_stack([rng.uniform(-50, 20, n), rng.normal(size=(n, 2)) * 3])
    j = rng.normal(size=(n, 3)) * 1e-5
    sp = rng.normal(size=(n, 2)) * 1e-5
    rn = rng.uniform(1e5, 1e6, n)
    rt = rng.uniform(1e5, 1e6, n)
    res = alart_curnier(t, j, sp, MU, rn, rt)
    sig_n = t[:, 0] + rn * j[:, 0]
    sig_t = t[:, 1:] + rt[:, None] * (j[:, 1:] - sp)
    margin = np.minimum(np.abs(sig_n), np.abs(np.linalg.norm(sig_t, axis=1)
                                              - MU * np.maximum(-sig_n, 0)))
    far = margin > 1e-2
    for branch in (~res.contact, res.contact & ~res.slipping, res.slipping):
        assert (branch & far).sum() >= 30          # every branch is exercised
    dt, dj = _fd(t[far], j[far], sp[far], rn[far], rt[far])
    np.testing.assert_allclose(res.d_traction[far], dt, rtol=0, atol=1e-6)
    np.testing.assert_allclose(res.d_jump[far], dj, rtol=0, atol=1e-6 * rn.max())


def test_frictionless():
    """mu = 0: Phi_T = t_T on every point (no tangential constraint)."""
    rng = np.random.default_rng(4)
    t = rng.normal(size=(10, 3))
    j = rng.normal(size=(10, 3)) * 1e-3
    res = alart_curnier(t, j, np.zeros((10, 2)), 0.0, 1e3, 1e3)
    np.testing.assert_array_equal(res.residual[:, 1:], t[:, 1:])
    assert not res.slipping.any()


@pytest.mark.parametrize("kwargs,match", [
    (dict(traction=np.zeros((3, 2))), "traction"),
    (dict(jump=np.full((3, 3), np.nan)), "jump is not finite"),
    (dict(friction=-0.1), "friction"),
    (dict(r_normal=0.0), "r_normal"),
    (dict(r_tangential=np.array([1.0, -1.0, 1.0])), "r_tangential"),
    (dict(r_normal=np.ones(2)), "r_normal of shape")])
def test_bad_inputs(kwargs, match):
    args = dict(traction=np.zeros((3, 3)), jump=np.zeros((3, 3)), plastic_slip=np.zeros((3, 2)),
                friction=0.3, r_normal=1.0, r_tangential=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        alart_curnier(**args)


def test_enforcement_arguments_and_laws():
    with pytest.raises(ValueError, match="r_normal"):
        SemismoothNewton(r_normal=-1.0)
    with pytest.raises(ValueError, match="r_tangential"):
        SemismoothNewton(r_tangential=0.0)
    law = SoftplusPenalty(1e6, 1e-7, k_tangential=1e6, friction=0.2)
    SemismoothNewton().check_law(law)
    assert SemismoothNewton().parameters(law) == (0.2, None, None)
    assert SemismoothNewton(r_normal=5.0).parameters(law) == (0.2, 5.0, 5.0)
    assert SemismoothNewton().parameters(SoftplusPenalty(1e6, 1e-7, friction=0.2))[0] == 0.0


def test_rough_law_refused():
    """The rough law's normal compliance is physical: the exact Signorini limit is refused."""
    law = InterfaceLaw(QuadraticNormal(), h0=1e-3)
    with pytest.raises(TypeError, match="CoulombContactLaw"):
        SemismoothNewton().check_law(law)
