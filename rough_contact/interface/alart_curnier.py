"""Alart–Curnier's complementarity function for unilateral contact with isotropic Coulomb
friction (pure numpy): the per-point equations the semismooth Newton of
:class:`~rough_contact.interface.enforcement.SemismoothNewton` solves together with the
equilibrium.

Conventions of the interface-law contract (local axes (n, x, y)): jump [g, s_x, s_y] with
g > 0 opening; traction t = (t_N, t_x, t_y) with t_N = -p <= 0 in contact. With the committed
plastic slip s_p and the augmentation parameters r_N, r_T > 0 [MPa/mm]:

    augmented normal traction    sigma_N = t_N + r_N g          (contact where sigma_N <= 0)
    augmented tangential one     sigma_T = t_T + r_T (s - s_p)
    slip bound                   rho = mu max(0, -sigma_N)
    Phi_N = t_N - min(0, sigma_N)
    Phi_T = t_T - P(sigma_T),    P = the projection onto the disc |tau| <= rho.

Phi = 0 holds exactly when g >= 0, p >= 0, p g = 0 (Signorini) and |t_T| <= mu p with
t_T = mu p m and s - s_p = lambda m (lambda >= 0) where the point slips, s = s_p where it sticks
(Coulomb): the constraints of exact contact and stick, whatever r_N and r_T (they scale the
equations and set which branch a Newton iterate is on, not the answer). Phi is piecewise
smooth (semismooth); its generalised derivative on each branch:

    open (sigma_N > 0):        dPhi/dt = I                       dPhi/dg = 0
    contact, normal row:       dPhi_N/dt = 0, dPhi_N/dg_N = -r_N
    stick (|sigma_T| <= rho):  dPhi_T/dt_T = 0, dPhi_T/ds = -r_T I
    slip:                      Q = rho / |sigma_T| (I - m m^T), m = sigma_T / |sigma_T|
                               dPhi_T/dt_T = I - Q,  dPhi_T/ds = -r_T Q,
                               dPhi_T/dt_N = mu m,  dPhi_T/dg_N = mu r_N m.

Units: jumps [mm], tractions and Phi [MPa], r [MPa/mm].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..validation import check_scalar

__all__ = ["ComplementarityResult", "alart_curnier"]


@dataclass(frozen=True)
class ComplementarityResult:
    """Alart–Curnier's function and its generalised derivative at n points.

    Attributes:
        residual: (n, 3) Phi [MPa].
        d_traction: (n, 3, 3) dPhi / dt [-].
        d_jump: (n, 3, 3) dPhi / d[g, s_x, s_y] [MPa/mm].
        contact: (n,) bool, sigma_N <= 0 (the contact branch; a tie, touching without
            traction, is on it: a Newton step from a touching start then finds the traction
            instead of leaving the body free).
        slipping: (n,) bool, in contact and |sigma_T| > rho.
        plastic_slip: (n, 2) the plastic slip the point would commit [mm]: s_p + (sigma_T -
            P(sigma_T)) / r_T (= s at a solution where the point slips; unchanged where it
            sticks; a point out of contact follows the other surface, as the penalty laws).
        dissipation: (n,) P(sigma_T) . (plastic slip increment) [N/mm].
    """

    residual: np.ndarray
    d_traction: np.ndarray
    d_jump: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    plastic_slip: np.ndarray
    dissipation: np.ndarray


def alart_curnier(traction: np.ndarray, jump: np.ndarray, plastic_slip: np.ndarray,
                  friction: float, r_normal: float, r_tangential: float
                  ) -> ComplementarityResult:
    """Alart–Curnier's function at n points (module docstring; pure).

    Args:
        traction: (n, 3) t [MPa]; jump: (n, 3) [g, s_x, s_y] [mm];
        plastic_slip: (n, 2) committed s_p [mm];
        friction: Coulomb's mu >= 0 (0: frictionless, Phi_T = t_T);
        r_normal, r_tangential: augmentation parameters > 0 [MPa/mm], one for all points or
            (n,) per point.

    Raises:
        ValueError: shapes that do not agree, non-finite input, or parameters out of range.
    """
    t = np.asarray(traction, dtype=float)
    j = np.asarray(jump, dtype=float)
    sp = np.asarray(plastic_slip, dtype=float)
    n = t.shape[0] if t.ndim == 2 else -1
    if t.shape != (n, 3) or j.shape != (n, 3) or sp.shape != (n, 2):
        raise ValueError(f"traction {t.shape}, jump {j.shape} and plastic_slip {sp.shape} are "
                         "invalid: expected (n, 3), (n, 3) and (n, 2)")
    for name, a in (("traction", t), ("jump", j), ("plastic_slip", sp)):
        if not np.all(np.isfinite(a)):
            bad = np.flatnonzero(~np.isfinite(a).all(axis=1))
            raise ValueError(f"{name} is not finite at {bad.size} of {n} points (first: "
                             f"{a[bad[0]].tolist()})")
    mu = check_scalar("friction", friction, lo=0.0, lo_open=False)
    rn = _augmentation("r_normal", r_normal, n)
    rt = _augmentation("r_tangential", r_tangential, n)

    res = np.empty((n, 3))
    dt = np.zeros((n, 3, 3))
    dj = np.zeros((n, 3, 3))
    sig_n = t[:, 0] + rn * j[:, 0]
    contact = sig_n <= 0.0      # a tie (touching, no traction) starts closed, not free
    res[:, 0] = t[:, 0] - np.minimum(sig_n, 0.0)
    dt[~contact, 0, 0] = 1.0
    dj[contact, 0, 0] = -rn[contact]

    sig_t = t[:, 1:] + rt[:, None] * (j[:, 1:] - sp)
    rho = mu * np.maximum(-sig_n, 0.0)
    norm = np.linalg.norm(sig_t, axis=1)
    stick = contact & (norm <= rho) & (mu > 0.0)   # frictionless: never stuck
    slip = ~stick             # slipping, or out of contact (rho = 0: P = 0)
    proj = sig_t.copy()
    scale = np.divide(rho, norm, out=np.zeros(n), where=norm > 0.0)
    proj[slip] = scale[slip, None] * sig_t[slip]
    res[:, 1:] = t[:, 1:] - proj
    # stick: dPhi_T/ds = -r_T I
    dj[stick, 1, 1] = dj[stick, 2, 2] = -rt[stick]
    # slip (and open: rho = 0, Q = 0): dPhi_T/dt_T = I - Q, dPhi_T/ds = -r_T Q
    m = np.divide(sig_t, norm[:, None], out=np.zeros_like(sig_t), where=norm[:, None] > 0.0)
    Q = scale[:, None, None] * (np.eye(2)[None] - m[:, :, None] * m[:, None, :])
    Q[stick] = 0.0
    dt[:, 1:, 1:] = np.where(stick[:, None, None], 0.0, np.eye(2)[None] - Q)
    dj[slip, 1:, 1:] = -rt[slip, None, None] * Q[slip]
    # the bound rho = -mu sigma_N in contact: dP/drho = m
    slipping = slip & contact & (mu > 0.0)
    dt[slipping, 1:, 0] = mu * m[slipping]
    dj[slipping, 1:, 0] = mu * rn[slipping, None] * m[slipping]

    new_sp = sp.copy()
    dslip = (sig_t[slip] - proj[slip]) / rt[slip, None]
    new_sp[slip] += dslip
    dissipation = np.zeros(n)
    dissipation[slip] = np.einsum("ij,ij->i", proj[slip], dslip)
    return ComplementarityResult(residual=res, d_traction=dt, d_jump=dj, contact=contact,
                                 slipping=slipping, plastic_slip=new_sp,
                                 dissipation=dissipation)


def _augmentation(name: str, r, n: int) -> np.ndarray:
    """(n,) positive finite augmentation parameters from a scalar or an (n,) array."""
    a = np.asarray(r, dtype=float)
    if a.ndim == 0:
        check_scalar(name, float(a), lo=0.0, unit="MPa/mm")
        return np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"{name} of shape {a.shape} is invalid: a scalar or ({n},)")
    bad = ~(np.isfinite(a) & (a > 0.0))
    if np.any(bad):
        raise ValueError(f"{name} = {a[bad][0]!r} at {int(bad.sum())} of {n} points is invalid: "
                         "it must be finite and > 0 [MPa/mm]")
    return a
