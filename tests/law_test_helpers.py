"""Shared by the interface-law tests (``tests/unit/test_law.py``,
``tests/unit/test_rough_multiplier.py``, which put this folder on sys.path): closed-form
stand-ins for the tabulated normal law (what ``InterfaceLaw`` asks of a normal law:
``evaluate(h, curvature)``, ``separation_for_pressure``), a random committed state, the trial
friction ratio of a law at a state, and the
central-difference check of a law's consistent tangent. Units: mm, MPa.
"""
from __future__ import annotations

import numpy as np

from rough_contact.interface.friction import OrthotropicSlipHardening
from rough_contact.interface.state import InterfaceState


def random_state(rng, n, scale=1e-4):
    """A committed state of n points: plastic slip ~ N(0, scale), hardening variables in
    [0, 5 scale)."""
    return InterfaceState(rng.normal(size=(n, 2)) * scale, rng.uniform(0, 5 * scale, (n, 2)),
                          rng.uniform(0, 5 * scale, n))


def fd_check(law, jump, st, keep=None, rel_step=1e-7, tol=1e-6):
    """Assert that the largest |central difference - tangent| over the points ``keep`` (all:
    None), relative to each point's largest tangent entry, is <= ``tol``; return the law's
    result at ``jump``."""
    r = law.evaluate(jump, st)
    scale = np.abs(r.tangent).max(axis=(1, 2))
    worst = 0.0
    for j in range(3):
        h = rel_step * max(np.abs(jump[:, j]).max(), 1e-4)
        jp, jm = jump.copy(), jump.copy()
        jp[:, j] += h
        jm[:, j] -= h
        fd = (law.evaluate(jp, st).traction - law.evaluate(jm, st).traction) / (2 * h)
        err = np.abs(fd - r.tangent[:, :, j]).max(axis=1) / np.where(scale > 0, scale, 1.0)
        if keep is not None:
            err = err[keep]
        worst = max(worst, err.max())
    assert worst <= tol, worst
    return r


class ExponentialNormal:
    """p = p0 exp(-h/l) (never zero): k = p/l, dk/dh = -p/l^2, a = p/(p + 1)."""

    def __init__(self, p0=5.0, l=1e-3):
        self.p0, self.l = p0, l

    def evaluate(self, h, curvature=False):
        p = self.p0 * np.exp(-np.asarray(h, float) / self.l)
        k = p / self.l
        out = (p, k, p / (p + 1.0))
        return out + (-k / self.l,) if curvature else out

    def separation_for_pressure(self, p):
        return -self.l * np.log(np.asarray(p, float) / self.p0)


class QuadraticNormal:
    """p = c (h_max - h)^2 for h < h_max, exactly 0 beyond (C1): opens for real.
    A/A0 = min((h_max - h) / 2e-3, 1)."""

    def __init__(self, c=1e6, h_max=2e-3):
        self.c, self.h_max = c, h_max

    def evaluate(self, h, curvature=False):
        d = np.maximum(self.h_max - np.asarray(h, float), 0.0)
        p = self.c * d * d
        k = 2 * self.c * d
        out = (p, k, np.minimum(d / 2e-3, 1.0))
        return out + (np.where(d > 0, -2 * self.c, 0.0),) if curvature else out

    def separation_for_pressure(self, p):
        return self.h_max - np.sqrt(np.asarray(p, float) / self.c)


def trial_ratio(law, jump, st, lam_t):
    """||t_trial||_mu / p with t_trial = lambda_T + c kN (s - s_p) (committed coefficients),
    computed from the normal law directly."""
    p, k, _ = law.normal.evaluate(law.h0 + jump[:, 0])
    c = np.array(law.tangential.kt_over_kn)
    ttr = lam_t + c * k[:, None] * (jump[:, 1:] - st.plastic_slip)
    if isinstance(law.friction, OrthotropicSlipHardening):
        mu, _ = law.friction.coefficients(st.accumulated_slip)
        ntr = np.hypot(ttr[:, 0] / mu[:, 0], ttr[:, 1] / mu[:, 1])
    else:
        mu, _ = law.friction.coefficient(st.slip_path)
        ntr = np.hypot(*ttr.T) / mu
    with np.errstate(divide="ignore", invalid="ignore"):
        return ntr / p
