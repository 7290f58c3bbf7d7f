"""Simple penalty interface laws (pure numpy), with the same contract as the rough-surface law.

They serve as oracles and stand-ins for the statistical law of ``rough_contact.interface.law``:
the FE layer (``rough_contact.fem.contact.ContactInterface``) treats every law alike.

Units: mm, N, MPa. Jumps [mm]; tractions [MPa]; stiffnesses per area [MPa/mm].

Contract (see ``/work/notes/common.md``): at each point the local axes are (n, x, y), with n the
unit normal of the FIRST surface pointing towards the second body. ``jump`` (n_pts, 3) holds
[g, s_x, s_y], the local components of u_second - u_first (g > 0 opens the gap). The traction is
energy-conjugate to the jump, t = dpsi/djump, so t_N = -p <= 0 in compression, and the tangent
D = dt/djump has D[:, 0, 0] = k = -dp/dg >= 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import expit

__all__ = ["LinearPenalty", "SoftplusPenalty", "PenaltyState", "PenaltyResult"]


@dataclass
class PenaltyState:
    """History at interface points.

    Attributes:
        plastic_slip: (n_pts, 2) accumulated irreversible slip in local axes (x, y) [mm].
    """

    plastic_slip: np.ndarray

    def copy(self) -> PenaltyState:
        return PenaltyState(self.plastic_slip.copy())

    def __len__(self) -> int:
        return self.plastic_slip.shape[0]


@dataclass(frozen=True)
class PenaltyResult:
    """Outcome of one law evaluation at n points.

    Attributes:
        traction: (n, 3) [t_N, t_x, t_y] [MPa], energy-conjugate to the jump.
        tangent: (n, 3, 3) consistent tangent dt/djump [MPa/mm].
        state: trial state (not committed).
        dissipation: (n,) increment t_T . delta(plastic slip) [N/mm].
        area_fraction: (n,) real-area fraction A/A0 [-] (a toy measure for penalty laws).
        contact: (n,) bool, p > 0.
        slipping: (n,) bool, the friction limit is active.
    """

    traction: np.ndarray
    tangent: np.ndarray
    state: PenaltyState
    dissipation: np.ndarray
    area_fraction: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray

    @property
    def pressure(self) -> np.ndarray:
        """(n,) contact pressure p = -t_N [MPa]."""
        return -self.traction[:, 0]


def _check_jump(jump: np.ndarray, committed: PenaltyState) -> np.ndarray:
    jump = np.asarray(jump, dtype=float)
    if jump.ndim != 2 or jump.shape[1] != 3:
        raise ValueError(f"jump must have shape (n_pts, 3), got {jump.shape}")
    if not np.all(np.isfinite(jump)):
        bad = np.flatnonzero(~np.all(np.isfinite(jump), axis=1))
        raise ValueError(
            f"jump is not finite at {bad.size} of {jump.shape[0]} points (first index {bad[0]})"
        )
    if committed.plastic_slip.shape != (jump.shape[0], 2):
        raise ValueError(
            f"committed state has {committed.plastic_slip.shape[0]} points, "
            f"jump has {jump.shape[0]}"
        )
    return jump


def _positive(name: str, value: float, allow_zero: bool = False) -> None:
    ok = value >= 0.0 if allow_zero else value > 0.0
    if not (np.isfinite(value) and ok):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} = {value!r} must be finite and {bound}")


@dataclass(frozen=True)
class LinearPenalty:
    """Linear penalty: t_N = k_N g (bilateral) or k_N min(g, 0) (unilateral); t_T = k_T s.

    Args:
        k_normal: normal penalty stiffness k_N > 0 [MPa/mm].
        k_tangential: tangential penalty stiffness k_T >= 0 [MPa/mm] (elastic, no friction).
        unilateral: if True the interface carries no tension and no shear while open (g > 0).
    """

    k_normal: float
    k_tangential: float = 0.0
    unilateral: bool = False

    def __post_init__(self) -> None:
        _positive("k_normal", self.k_normal)
        _positive("k_tangential", self.k_tangential, allow_zero=True)

    def initial_state(self, n_pts: int) -> PenaltyState:
        return PenaltyState(np.zeros((int(n_pts), 2)))

    def evaluate(self, jump: np.ndarray, committed: PenaltyState) -> PenaltyResult:
        """Traction (n, 3) and tangent (n, 3, 3) at jump (n, 3) [mm]; pure (no mutation)."""
        jump = _check_jump(jump, committed)
        n = jump.shape[0]
        g = jump[:, 0]
        active = (g <= 0.0) if self.unilateral else np.ones(n, dtype=bool)
        kn = np.where(active, self.k_normal, 0.0)
        kt = np.where(active, self.k_tangential, 0.0)
        traction = np.empty((n, 3))
        traction[:, 0] = kn * g
        traction[:, 1:] = kt[:, None] * jump[:, 1:]
        tangent = np.zeros((n, 3, 3))
        tangent[:, 0, 0] = kn
        tangent[:, 1, 1] = kt
        tangent[:, 2, 2] = kt
        contact = -traction[:, 0] > 0.0
        return PenaltyResult(
            traction=traction,
            tangent=tangent,
            state=committed.copy(),
            dissipation=np.zeros(n),
            area_fraction=contact.astype(float),
            contact=contact,
            slipping=np.zeros(n, dtype=bool),
        )


@dataclass(frozen=True)
class SoftplusPenalty:
    """Smooth unilateral penalty with optional isotropic Coulomb friction.

    Normal: p(g) = k_N w softplus(-g / w) = k_N w ln(1 + exp(-g / w)), so p -> k_N (-g) for
    g << -w, p -> 0 for g >> w, and k = -dp/dg = k_N sigmoid(-g / w) (C-infinity).
    Tangential: elastic predictor tau = k_T (s - s_p); if |tau| > mu p the point slips
    (radial return): t_T = mu p tau / |tau|, s_p += (|tau| - mu p) / k_T * tau / |tau|.
    The tangent is the consistent (non-symmetric) one. ``area_fraction`` = sigmoid(-g / w)
    is a toy measure (0 far open, 1 deep in contact).

    Args:
        k_normal: normal stiffness k_N > 0 [MPa/mm].
        width: smoothing length w > 0 [mm].
        k_tangential: tangential stiffness k_T >= 0 [MPa/mm].
        friction: Coulomb coefficient mu >= 0 [-] (needs k_T > 0 to matter).
    """

    k_normal: float
    width: float
    k_tangential: float = 0.0
    friction: float = 0.0

    def __post_init__(self) -> None:
        _positive("k_normal", self.k_normal)
        _positive("width", self.width)
        _positive("k_tangential", self.k_tangential, allow_zero=True)
        _positive("friction", self.friction, allow_zero=True)

    def initial_state(self, n_pts: int) -> PenaltyState:
        return PenaltyState(np.zeros((int(n_pts), 2)))

    def normal(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pressure p(g) [MPa] and stiffness k = -dp/dg [MPa/mm] at gaps g (n,) [mm]."""
        z = -np.asarray(g, dtype=float) / self.width
        return self.k_normal * self.width * np.logaddexp(0.0, z), self.k_normal * expit(z)

    def evaluate(self, jump: np.ndarray, committed: PenaltyState) -> PenaltyResult:
        """Traction (n, 3) and tangent (n, 3, 3) at jump (n, 3) [mm]; pure (no mutation)."""
        jump = _check_jump(jump, committed)
        n = jump.shape[0]
        p, k = self.normal(jump[:, 0])
        traction = np.zeros((n, 3))
        tangent = np.zeros((n, 3, 3))
        traction[:, 0] = -p
        tangent[:, 0, 0] = k
        state = committed.copy()
        dissipation = np.zeros(n)
        slipping = np.zeros(n, dtype=bool)
        if self.k_tangential > 0.0:
            kt = self.k_tangential
            tau = kt * (jump[:, 1:] - committed.plastic_slip)
            norm = np.linalg.norm(tau, axis=1)
            limit = self.friction * p
            # a relative margin keeps points exactly on the cone (e.g. re-evaluated after a
            # commit) elastic instead of slipping by round-off
            slipping = norm > limit * (1.0 + 1e-12)
            stick = ~slipping
            traction[stick, 1:] = tau[stick]
            tangent[stick, 1, 1] = kt
            tangent[stick, 2, 2] = kt
            if np.any(slipping):
                ns = norm[slipping]
                m = tau[slipping] / ns[:, None]
                ls = limit[slipping]
                traction[slipping, 1:] = ls[:, None] * m
                ratio = ls * kt / ns
                tangent[slipping, 1:, 1:] = ratio[:, None, None] * (
                    np.eye(2)[None] - m[:, :, None] * m[:, None, :]
                )
                tangent[slipping, 1:, 0] = -self.friction * k[slipping][:, None] * m
                dslip = ((ns - ls) / kt)[:, None] * m
                state.plastic_slip[slipping] += dslip
                dissipation[slipping] = np.einsum("ij,ij->i", traction[slipping, 1:], dslip)
        return PenaltyResult(
            traction=traction,
            tangent=tangent,
            state=state,
            dissipation=dissipation,
            area_fraction=expit(-jump[:, 0] / self.width),
            contact=p > 0.0,
            slipping=slipping,
        )
