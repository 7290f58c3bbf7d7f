"""Simple penalty interface laws (pure numpy), following the same contract as the rough law.

They serve as oracles and stand-ins for the statistical law of ``rough_contact.interface.law``:
the FE layer (``rough_contact.fem.contact.ContactInterface``) treats every law alike. Both follow
the interface-law contract of ``rough_contact.interface.contract`` (local axes (n, x, y), jump
[g, s_x, s_y] with g > 0 opening, t = dpsi/djump so t_N = -p <= 0, D[:, 0, 0] = k = -dp/dg >= 0,
purity, dissipation increments) and keep their history in ``InterfaceState``.

Units: mm, N, MPa. Jumps [mm]; tractions [MPa]; stiffnesses per area [MPa/mm].
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Optional

import numpy as np
from scipy.special import expit

from ..fingerprint import FINGERPRINT_ADDED
from ..validation import check_scalar
from .contract import CoulombLimit, LawResult, check_jump, check_point_factor
from .state import InterfaceState

__all__ = ["LinearPenalty", "SoftplusPenalty", "ShiftedSoftplusPenalty"]


def _check_inputs(jump, committed) -> np.ndarray:
    if not isinstance(committed, InterfaceState):
        raise ValueError(f"committed state must be an InterfaceState, got "
                         f"{type(committed).__name__}")
    return check_jump(jump, committed)


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
        check_scalar("k_normal", self.k_normal, lo=0.0, unit="MPa/mm")
        check_scalar("k_tangential", self.k_tangential, lo=0.0, lo_open=False, unit="MPa/mm")

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history at n_pts points (this law keeps none: the state is carried unchanged)."""
        return InterfaceState.zeros(n_pts)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState) -> LawResult:
        """Traction (n, 3) and tangent (n, 3, 3) at jump (n, 3) [mm]; pure (no mutation).

        Raises:
            ValueError: wrong shapes. ConvergenceError: non-finite jump.
        """
        jump = _check_inputs(jump, committed)
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
        state = committed.copy()
        state.closed = contact
        return LawResult(
            traction=traction,
            tangent=tangent,
            state=state,
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
    A point without pressure (p = 0, where the softplus underflows far from contact) returns
    to t_T = 0 the same way but is reported as open, not slipping (``LawResult.slipping`` is
    False outside contact).
    The tangent is the consistent (non-symmetric) one. ``area_fraction`` = sigmoid(-g / w)
    is a toy measure (0 far open, 1 deep in contact).

    Newton steps (:meth:`newton_tangent`, used by the FE interface for the Jacobian only): the
    consistent tangent of a slipping point, k_T mu p / |tau| (I - m m^T), has no stiffness
    along the slip direction m, so a Newton step can drive the trial traction tau through zero
    and reverse the slip direction of a point (seen on the unloading branch of the flat punch:
    ~100 of 1 500 points per iteration, the backtracking line search then cuts the steps to
    15-25 %). A point that is slipping and whose trial direction reversed (m . m_prev < 0)
    since the previous Jacobian of the same Newton solve gets the secant stiffness
    ``reversal_stiffness`` x k_T mu p / |tau| along m in that Jacobian. The residual is
    unchanged, so is the converged solution; points that stopped reversing get the consistent
    tangent back, so the final iterations stay quadratic (docs/coulomb.md: 173 -> 146 Newton
    iterations at level 1, 237 -> 202 at level 3). ``reversal_stiffness = 0`` gives the
    consistent tangent everywhere.

    Multipliers (:class:`~rough_contact.interface.contract.MultiplierLaw`): ``with_multipliers``
    gives the law with its penalty shifted by multipliers lambda = (lambda_N, lambda_x,
    lambda_y), p = k_N w softplus((lambda_N / k_N - g) / w) and tau = lambda_T + k_T (s - s_p),
    with the same radial return. The augmented-Lagrangian enforcement
    (``rough_contact.interface.enforcement.AugmentedLagrangian``; Uzawa's iteration, for
    friction Simo and Laursen's scheme) re-solves each increment with lambda replaced by the
    converged tractions until they stop moving. At that fixed point k_N g -> 0 in contact (up
    to the softplus smoothing) and s = s_p: a sticking point does not move, a slipping point
    slips only plastically, so the result no longer depends on k_N, k_T (docs/coulomb.md); the
    penalty sets only how fast the multipliers converge.

    Where a point that closes during an increment starts to stick (``first_contact``): the
    predictor's s_p is the committed plastic slip, and a point that was open at the last commit
    followed the other surface freely, so its s_p is where it was at the increment's start.
    With ``"increment_start"`` (the default; the incremental slip of GetFEM's and MOOSE's
    contact) it therefore sticks there, and its stick traction carries the tangential motion of
    the whole increment, the part from before it touched included. Right for a point that
    arrives while the surfaces slide (it slips at once, with mu p). With ``"closure"`` (the
    node-to-segment convention of first contact) a point open at the last commit
    (``InterfaceState.closed`` False: its pressure was below k_N w ln 2, the smoothed law's
    pressure at zero gap) starts to stick where it is at the end of the increment it closes
    in: its predictor has no elastic part in that increment, tau = lambda_T (0 without
    multipliers), and its tangent has no tangential stiffness. Right for points that close by
    approach, as under an indenter: without it, the vertices that close late in an increment,
    those at the contact's edge where mu p is smallest, are held where they were before they
    touched, and on a fine mesh they slip under a normal load alone (docs/mindlin_dual.md,
    session 20). A point that arrives while the surfaces slide carries no friction in the
    increment it arrives in. The virgin state counts as open, so with ``"closure"`` surfaces in
    contact from the start carry no friction in the first increment either.

    Args:
        k_normal: normal stiffness k_N > 0 [MPa/mm].
        width: smoothing length w > 0 [mm].
        k_tangential: tangential stiffness k_T >= 0 [MPa/mm].
        friction: Coulomb coefficient mu >= 0 [-] (needs k_T > 0 to matter).
        reversal_stiffness: factor >= 0 [-] of the secant stiffness added along m at points
            whose slip direction reversed between two Jacobians (Newton steps only, see
            above; 0 = off).
        first_contact: ``"increment_start"`` or ``"closure"``: where a point that closes
            during an increment starts to stick (above).
    """

    k_normal: float
    width: float
    k_tangential: float = 0.0
    friction: float = 0.0
    reversal_stiffness: float = 1.0
    # checkpoints written before first_contact existed still match at its default
    first_contact: str = field(default="increment_start",
                               metadata={FINGERPRINT_ADDED: True})

    FIRST_CONTACT = ("increment_start", "closure")

    def __post_init__(self) -> None:
        check_scalar("k_normal", self.k_normal, lo=0.0, unit="MPa/mm")
        check_scalar("width", self.width, lo=0.0, unit="mm")
        check_scalar("k_tangential", self.k_tangential, lo=0.0, lo_open=False, unit="MPa/mm")
        check_scalar("friction", self.friction, lo=0.0, lo_open=False)
        check_scalar("reversal_stiffness", self.reversal_stiffness, lo=0.0, lo_open=False)
        if self.first_contact not in self.FIRST_CONTACT:
            raise ValueError(f"first_contact = {self.first_contact!r} is invalid: one of "
                             f"{self.FIRST_CONTACT}")

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history (no plastic slip) at n_pts points."""
        return InterfaceState.zeros(n_pts)

    def with_multipliers(self, multipliers: np.ndarray, stiffness_factor: float = 1.0,
                         tangential_factor: Optional[np.ndarray] = None
                         ) -> ShiftedSoftplusPenalty:
        """The law with its penalty shifted by ``multipliers`` (n, 3) [MPa]
        (``rough_contact.interface.contract.MultiplierLaw``); ``stiffness_factor`` != 1: the
        shifted law has k_N and k_T multiplied by it and the width divided by it (p(0) kept),
        as :meth:`softened` with 1 / factor; ``tangential_factor`` (n,): each point's k_T
        multiplied by its own factor besides (the normal law, whose smoothing is part of the
        answer, is not touched)."""
        f = check_scalar("stiffness_factor", stiffness_factor, lo=0.0)
        tf = None if tangential_factor is None else \
            check_point_factor("tangential_factor", tangential_factor, np.shape(multipliers)[0])
        law = self if f == 1.0 else replace(self, k_normal=self.k_normal * f,
                                            width=self.width / f,
                                            k_tangential=self.k_tangential * f)
        return ShiftedSoftplusPenalty(law, multipliers, tf)

    def softened(self, factor: float) -> SoftplusPenalty:
        """The law with k_N and k_T divided by ``factor`` >= 1 and the width multiplied by it
        (p(0) = k_N w ln 2 kept; friction and ``reversal_stiffness`` unchanged): the starting
        law of Newton's penalty continuation
        (``rough_contact.interface.contract.SoftenableLaw``)."""
        f = check_scalar("softening factor", factor, lo=1.0, lo_open=False)
        return replace(self, k_normal=self.k_normal / f, width=self.width * f,
                       k_tangential=self.k_tangential / f)

    def _kt(self, n: int, factor: Optional[np.ndarray]) -> np.ndarray:
        """(n,) k_T at each point: the law's, times ``factor`` (n,) where given."""
        if factor is None:
            return np.broadcast_to(self.k_tangential, (n,))
        return self.k_tangential * factor

    def _shifts(self, multipliers: Optional[np.ndarray]):
        """(gap shift lambda_N / k_N (n,) [mm], tangential multiplier (n, 2) [MPa]); the scalar
        0.0 for both without multipliers."""
        if multipliers is None:
            return 0.0, 0.0
        lam = np.asarray(multipliers)
        return lam[:, 0] / self.k_normal, lam[:, 1:]

    @staticmethod
    def _trial_traction(jump: np.ndarray, plastic_slip: np.ndarray, lam_t, kt) -> np.ndarray:
        """Elastic predictor tau = lambda_T + k_T (s - s_p) (n, 2) [MPa] (k_T (n,))."""
        return lam_t + kt[:, None] * (jump[:, 1:] - plastic_slip)

    def _anchor(self, jump: np.ndarray, committed: InterfaceState
                ) -> tuple[np.ndarray, Optional[np.ndarray]]:
        """(s_p the predictor starts from (n, 2), the points that closed since the commit
        (n,) bool or None): with ``first_contact="closure"`` a point open at the commit starts
        from its current tangential jump, else from the committed plastic slip."""
        if self.first_contact != "closure":
            return committed.plastic_slip, None
        fresh = ~committed.closed
        if not fresh.any():
            return committed.plastic_slip, None
        sp = committed.plastic_slip.copy()
        sp[fresh] = jump[fresh, 1:]
        return sp, fresh

    def closing_pressure(self) -> float:
        """k_N w ln 2 [MPa]: the pressure at zero gap, above which a point counts as closed
        (``InterfaceState.closed``); unchanged by :meth:`softened` and ``stiffness_factor``."""
        return float(self.k_normal * self.width * np.log(2.0))

    def coulomb_limit(self) -> CoulombLimit:
        """Signorini contact with Coulomb's mu (0 without tangential stiffness), this law's
        penalties and its ``first_contact``
        (``rough_contact.interface.contract.CoulombContactLaw``)."""
        mu = float(self.friction) if self.k_tangential > 0.0 else 0.0
        return CoulombLimit(mu, float(self.k_normal), float(self.k_tangential),
                            self.first_contact)

    def max_friction_coefficient(self) -> float:
        """mu (0 without tangential stiffness): |t_T| <= mu p
        (``rough_contact.interface.contract.FrictionBoundedLaw``)."""
        return float(self.friction) if self.k_tangential > 0.0 else 0.0

    def normal(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pressure p(g) [MPa] and stiffness k = -dp/dg [MPa/mm] at gaps g (n,) [mm]."""
        z = -np.asarray(g, dtype=float) / self.width
        return self.k_normal * self.width * np.logaddexp(0.0, z), self.k_normal * expit(z)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState,
                 multipliers: Optional[np.ndarray] = None,
                 tangential_factor: Optional[np.ndarray] = None) -> LawResult:
        """Traction (n, 3) and tangent (n, 3, 3) at jump (n, 3) [mm]; pure (no mutation).
        ``multipliers`` (n, 3) shift the penalty (see the class; None: the plain penalty).
        ``tangential_factor`` (n,) > 0: each point's k_T times it (None: the law's k_T;
        checked by :meth:`with_multipliers`).

        The trial state carries the plastic slip and, for the record, the slip magnitudes
        (``accumulated_slip``, ``slip_path``); Coulomb friction does not harden.

        Raises:
            ValueError: wrong shapes. ConvergenceError: non-finite jump.
        """
        jump = _check_inputs(jump, committed)
        n = jump.shape[0]
        if multipliers is not None and np.shape(multipliers) != (n, 3):
            raise ValueError(f"multipliers of shape {np.shape(multipliers)} for {n} points; "
                             f"expected ({n}, 3)")
        shift, lam_t = self._shifts(multipliers)
        p, k = self.normal(jump[:, 0] - shift)
        traction = np.zeros((n, 3))
        tangent = np.zeros((n, 3, 3))
        traction[:, 0] = -p
        tangent[:, 0, 0] = k
        state = committed.copy()
        state.closed = p >= self.closing_pressure()
        dissipation = np.zeros(n)
        slipping = np.zeros(n, dtype=bool)
        if self.k_tangential > 0.0:
            kt = self._kt(n, tangential_factor)
            sp, fresh = self._anchor(jump, committed)
            if fresh is not None:
                state.plastic_slip[fresh] = sp[fresh]
            tau = self._trial_traction(jump, sp, lam_t, kt)
            norm = np.linalg.norm(tau, axis=1)
            limit = self.friction * p
            # a relative margin keeps points exactly on the cone (e.g. re-evaluated after a
            # commit) elastic instead of slipping by round-off
            ret = norm > limit * (1.0 + 1e-12)      # radial return (also where p = 0)
            stick = ~ret
            traction[stick, 1:] = tau[stick]
            tangent[stick, 1, 1] = kt[stick]
            tangent[stick, 2, 2] = kt[stick]
            if np.any(ret):
                ns = norm[ret]
                m = tau[ret] / ns[:, None]
                ls = limit[ret]
                traction[ret, 1:] = ls[:, None] * m
                ktr = kt[ret]
                ratio = ls * ktr / ns
                tangent[ret, 1:, 1:] = ratio[:, None, None] * (
                    np.eye(2)[None] - m[:, :, None] * m[:, None, :]
                )
                tangent[ret, 1:, 0] = -self.friction * k[ret][:, None] * m
                dslip = ((ns - ls) / ktr)[:, None] * m
                state.plastic_slip[ret] += dslip
                state.accumulated_slip[ret] += np.abs(dslip)
                state.slip_path[ret] += (ns - ls) / ktr
                dissipation[ret] = np.einsum("ij,ij->i", traction[ret, 1:], dslip)
            if fresh is not None:
                # s_p moves with s at a point closing in this increment: no tangential stiffness
                tangent[fresh, 1:, 1:] = 0.0
            # a point out of contact (p = 0: zero limit, zero traction) follows the other
            # surface freely; it is open, not slipping (the counters count slip in contact)
            slipping = ret & (p > 0.0)
        return LawResult(
            traction=traction,
            tangent=tangent,
            state=state,
            dissipation=dissipation,
            area_fraction=expit(-(jump[:, 0] - shift) / self.width),
            contact=p > 0.0,
            slipping=slipping,
        )

    def newton_tangent(self, jump: np.ndarray, committed: InterfaceState, result: LawResult,
                       previous: Optional[np.ndarray],
                       multipliers: Optional[np.ndarray] = None,
                       tangential_factor: Optional[np.ndarray] = None
                       ) -> tuple[np.ndarray, np.ndarray]:
        """Tangent for a Newton step at ``jump`` (pure; the residual is not affected).

        Args:
            jump: (n, 3) jump the law was evaluated at [mm].
            committed: the committed history ``result`` was computed from.
            result: ``evaluate(jump, committed)``.
            previous: what the previous call of the same Newton solve returned as its second
                value (None at the first Jacobian of a solve).

        Returns:
            (tangent (n, 3, 3), memo): the tangent is ``result.tangent`` with the secant
            stiffness ``reversal_stiffness`` k_T |t_T| / |tau| added along m = tau / |tau| at
            slipping points whose trial direction reversed since ``previous`` (see the
            class); memo = (n, 2) trial directions m, to pass as ``previous`` next time.
            ``multipliers``, ``tangential_factor``: those ``result`` was computed with (None:
            plain penalty; the law's own k_T).
        """
        if self.k_tangential <= 0.0:
            return result.tangent, None
        kt = self._kt(jump.shape[0], tangential_factor)
        tau = self._trial_traction(jump, self._anchor(jump, committed)[0],
                                   self._shifts(multipliers)[1], kt)
        norm = np.linalg.norm(tau, axis=1)
        m = np.divide(tau, norm[:, None], out=np.zeros_like(tau), where=norm[:, None] > 0.0)
        tangent = result.tangent
        if (self.reversal_stiffness > 0.0 and previous is not None
                and previous.shape == m.shape):
            flip = result.slipping & (np.einsum("ij,ij->i", m, previous) < 0.0)
            if np.any(flip):
                tangent = tangent.copy()
                mf = m[flip]
                secant = (self.reversal_stiffness * kt[flip]
                          * np.linalg.norm(result.traction[flip, 1:], axis=1) / norm[flip])
                tangent[flip, 1:, 1:] += secant[:, None, None] * mf[:, :, None] * mf[:, None, :]
        return tangent, m


@dataclass(frozen=True)
class ShiftedSoftplusPenalty:
    """A :class:`SoftplusPenalty` with its penalty shifted by multipliers (n, 3) [MPa]: what
    ``SoftplusPenalty.with_multipliers`` returns for one evaluation of n points;
    ``tangential_factor`` (n,): each point's k_T times it (None: the law's)."""

    law: SoftplusPenalty
    multipliers: np.ndarray
    tangential_factor: Optional[np.ndarray] = None

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history at n_pts points (that of the plain law)."""
        return self.law.initial_state(n_pts)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState) -> LawResult:
        """The shifted law at ``jump`` (see :meth:`SoftplusPenalty.evaluate`)."""
        return self.law.evaluate(jump, committed, self.multipliers, self.tangential_factor)

    def newton_tangent(self, jump, committed, result, previous):
        """See :meth:`SoftplusPenalty.newton_tangent`."""
        return self.law.newton_tangent(jump, committed, result, previous, self.multipliers,
                                       self.tangential_factor)

    def max_friction_coefficient(self) -> float:
        """That of the plain law."""
        return self.law.max_friction_coefficient()
