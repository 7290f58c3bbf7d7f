"""The composed rough-interface law at quadrature points: (jump, committed) -> LawResult.

Units: mm, N, MPa. Jumps and separations [mm]; tractions and pressures [MPa]; stiffnesses per
nominal area [MPa/mm]; dissipation per nominal area [N/mm].

The law follows the interface-law contract of ``rough_contact.interface.contract`` (local axes
(n, x, y), jump [g, s_x, s_y] with g > 0 opening, t = dpsi/djump, algorithmic tangent, purity,
failures). The mean-plane separation is h = h0 + g; t_N = -p(h) <= 0 and t_T = K_T(h) (s - s_p)
limited by friction, with K_T = diag(c_x, c_y) kN(h); D[:, 0, 0] = kN(h).
``docs/equations.md`` (section "Interface law") states the paper's equations these readings
rest on.

Layers: normal law (p, kN, A/A0, dkN/dh; any ``NormalLawProtocol``) -> tangential stiffness
(kT = c kN) -> friction return map (only at points with p > 0). Open points (p == 0) carry no
traction, have zero tangential tangent rows and keep their history.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Optional, Protocol, Tuple, Union, runtime_checkable

import numpy as np

from ..validation import check_scalar
from .contract import InterfaceLawProtocol, LawResult, check_jump, check_point_factor
from .friction import (FrictionInput, IsotropicSlipHardening, OrthotropicSlipHardening,
                       ShiftedFrictionInput)
from .history import HistoryNormalLawProtocol, ReversalStiffnessProtocol
from .state import HistoryInterfaceState, InterfaceState
from .tangential import TangentialStiffness

__all__ = ["InterfaceLaw", "ShiftedInterfaceLaw", "NormalLawProtocol", "SeatableNormalLaw",
           "ValidityLimitedNormalLaw"]

Friction = Union[OrthotropicSlipHardening, IsotropicSlipHardening]


@runtime_checkable
class NormalLawProtocol(Protocol):
    """What ``InterfaceLaw`` needs from a normal law: p, kN, A/A0 (and dkN/dh) vs separation.

    ``rough_contact.interface.normal.NormalLaw`` (the statistical law) implements it; so can any
    smooth law of the mean-plane separation h with p -> 0 as h grows. ``with_seating`` needs the
    inverse as well (:class:`SeatableNormalLaw`); a law used with an explicit ``h0`` does not.
    """

    def evaluate(self, h: np.ndarray, curvature: bool = False) -> Tuple[np.ndarray, ...]:
        """Normal law at separations h (n,) [mm].

        Returns:
            ``(p, k, a)``, or ``(p, k, a, dk_dh)`` if ``curvature``: pressure p >= 0 [MPa],
            stiffness k = -dp/dh >= 0 [MPa/mm], real-area fraction a = A/A0 in [0, 1] [-] and
            dk/dh [MPa/mm^2], each (n,) float.
        """
        ...


@runtime_checkable
class SeatableNormalLaw(NormalLawProtocol, Protocol):
    """A normal law with the inverse p -> h, which ``InterfaceLaw.with_seating`` needs."""

    def separation_for_pressure(self, p: np.ndarray) -> np.ndarray:
        """Separation h (n,) [mm] at which the pressure is p (n,) > 0 [MPa] (inverse of p(h))."""
        ...


@runtime_checkable
class ValidityLimitedNormalLaw(NormalLawProtocol, Protocol):
    """A normal law whose model holds only above a separation (``NormalLaw``: below its lowest
    knot h_min a stiff continuation stands in for the asperity model). ``InterfaceLaw`` reports
    such points in ``LawResult.beyond_validity``."""

    def below_validity(self, h: np.ndarray) -> np.ndarray:
        """(n,) bool: True where the separation h (n,) [mm] is outside the model's range."""
        ...


@dataclass(frozen=True)
class InterfaceLaw:
    """Rough-interface law: statistical normal law + Mindlin tangential stiffness + friction.

    Implements ``rough_contact.interface.contract.InterfaceLawProtocol`` with
    ``InterfaceState`` as history.

    Args:
        normal: the normal law (``NormalLawProtocol``, e.g.
            ``rough_contact.interface.normal.NormalLaw``; ``with_seating`` needs a
            ``SeatableNormalLaw``).
        tangential: tangential stiffness ratios kT/kN (needed when ``friction`` is given).
        friction: ``OrthotropicSlipHardening`` or ``IsotropicSlipHardening``; None means
            frictionless (t_T = 0, no history).
        h0: reference mean-plane separation [mm] at zero gap (h = h0 + g); set it directly or
            with ``with_seating``.

    Normal memory (the irreversible knob): a normal law that implements
    ``rough_contact.interface.history.HistoryNormalLawProtocol`` (e.g. ``HistoryNormalLaw``)
    makes the state a ``HistoryInterfaceState`` whose h_min (the smallest separation reached)
    is committed and reverted with the slip history; p, kN, A/A0 then follow the loading branch
    where h <= h_min and the elastic unloading/reloading branch of h_min elsewhere, and
    ``LawResult.normal_dissipation`` is the normal hysteresis energy of the step. A plain
    ``NormalLaw`` (e.g. the elasto-plastic one, the default) stays reversible.

    Tangential stiffness with memory: k_T = c k_N on the loading branch (the paper's rule);
    on the unloading branch of h_min, if the normal law implements
    ``ReversalStiffnessProtocol``, k_T = c k_N k_load(h_min)/k_rev(h_min): the unloading
    stiffness scaled so that k_T is continuous at h = h_min (where k_N jumps from the loading
    tangent to the stiffer first unloading stiffness). Without the scale the tangential
    traction c k_N (s - s_p) jumps at h = h_min, and the residual is discontinuous at the
    peak of every repeated load cycle (Newton stalls; docs/unloading_scenes.md).

    Multipliers (``rough_contact.interface.contract.MultiplierLaw``, exact stick): with an
    augmented-Lagrangian enforcement (``AugmentedLagrangian``, ``NewtonAugmentedLagrangian``)
    the law is evaluated as ``with_multipliers(lambda)``, lambda = (lambda_N, lambda_x,
    lambda_y) per point. Only the FRICTION part is shifted: the trial traction of the return
    map becomes t_trial = lambda_T + K_T(h) (s - s_p) (same return map otherwise: slip
    hardening, orthotropic criterion, non-associated potential, algorithmic tangent). The
    normal pressure p(h), its stiffness kN(h), the area fraction and the normal memory are the
    unshifted law's, bit for bit: the asperity model's normal compliance is physical and stays
    in the answer. lambda_N is not used (the enforcement's update sets it to the converged
    pressure p, which the shifted law reproduces anyway); it must still be finite and >= 0.
    At the enforcement's fixed point (lambda_T = the converged tangential traction) a sticking
    point has s = s_p (no elastic slip) and a slipping point slips only plastically: the
    option replaces the tangential micro-compliance K_T = c kN (the Mindlin stiffness of the
    asperity contacts) by rigid stick. With ``Penalty()`` (the default) the law keeps the
    paper's tangential compliance. A frictionless law's ``with_multipliers`` is the law itself.
    """

    normal: NormalLawProtocol
    tangential: Optional[TangentialStiffness] = None
    friction: Optional[Friction] = None
    h0: Optional[float] = None

    def __post_init__(self) -> None:
        if not isinstance(self.normal, NormalLawProtocol):
            raise ValueError(f"normal = {self.normal!r} must implement NormalLawProtocol "
                             "(evaluate(h, curvature))")
        if self.friction is not None:
            if not isinstance(self.friction, (OrthotropicSlipHardening, IsotropicSlipHardening)):
                raise ValueError(f"friction = {self.friction!r} must be an "
                                 "OrthotropicSlipHardening or IsotropicSlipHardening (or None "
                                 "for frictionless)")
            if not isinstance(self.tangential, TangentialStiffness):
                raise ValueError("tangential (a TangentialStiffness) is required when friction is "
                                 f"given, got {self.tangential!r}")
        if self.h0 is not None:
            object.__setattr__(self, "h0", check_scalar("h0", self.h0, unit="mm"))

    def max_friction_coefficient(self) -> float:
        """Largest friction coefficient reachable (the saturated mu_macro, largest axis); 0
        without friction (``rough_contact.interface.contract.FrictionBoundedLaw``)."""
        if self.friction is None:
            return 0.0
        return float(np.max(self.friction.mu_macro))

    def with_seating(self, p_seat: float) -> InterfaceLaw:
        """Copy whose h0 solves p(h0) = p_seat [MPa] (zero gap carries the seating pressure).

        Raises:
            ValueError: p_seat not finite and > 0, or a normal law without the inverse
                (``SeatableNormalLaw``).
        """
        p = check_scalar("p_seat", p_seat, lo=0.0, unit="MPa")
        if not isinstance(self.normal, SeatableNormalLaw):
            raise ValueError(f"with_seating needs a normal law with separation_for_pressure(p) "
                             f"(SeatableNormalLaw); {type(self.normal).__name__} has none: give "
                             "h0 directly")
        h0 = float(np.asarray(self.normal.separation_for_pressure(np.array([p]))).reshape(-1)[0])
        return dataclasses.replace(self, h0=h0)

    @property
    def has_normal_memory(self) -> bool:
        """True when the normal law keeps a history (``HistoryNormalLawProtocol``)."""
        return isinstance(self.normal, HistoryNormalLawProtocol)

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history at n_pts points (a ``HistoryInterfaceState`` with h_min = +inf when
        the normal law has memory)."""
        if self.has_normal_memory:
            return HistoryInterfaceState.zeros(n_pts)
        return InterfaceState.zeros(n_pts)

    def normal_dissipated(self, state: InterfaceState) -> np.ndarray:
        """(n,) normal hysteresis energy per nominal area dissipated since the virgin state
        [N/mm]: D(h_min) of the state's h_min (zeros for a reversible normal law)."""
        if not self.has_normal_memory:
            return np.zeros(len(state))
        return np.asarray(self.normal.normal_dissipation(state.h_min), dtype=float)

    def with_multipliers(self, multipliers: np.ndarray, stiffness_factor: float = 1.0,
                         tangential_factor: Optional[np.ndarray] = None
                         ) -> InterfaceLawProtocol:
        """The law with its friction trial traction shifted by the tangential multipliers
        (``rough_contact.interface.contract.MultiplierLaw``; see the class).

        Args:
            multipliers: (n, 3) [lambda_N, lambda_x, lambda_y] [MPa], finite, lambda_N >= 0
                (lambda_N is not used: the normal law stays the unshifted p(h)).
            stiffness_factor: (> 0) the shifted law's tangential stiffness is factor x K_T:
                t_trial = lambda_T + factor K_T(h) (s - s_p). The fixed point (s = s_p at
                sticking points) does not depend on it; the updates converge by about
                K_b / (K_b + factor K_T) each (K_b: the stiffness a point sees from the
                bodies), and the rough law's K_T is soft: 10-100 is the useful range
                (docs/exact_contact.md). The normal law is never scaled.
            tangential_factor: (n,) > 0 or None: each point's K_T multiplied by its own
                factor besides (``MultiplierLaw.with_multipliers``).

        Returns:
            A :class:`ShiftedInterfaceLaw` for those n points; the law itself when it is
            frictionless (nothing to shift).

        Raises:
            ValueError: ``multipliers`` not (n, 3), not finite, or lambda_N < 0.
        """
        lam = _check_multipliers(multipliers)
        f = check_scalar("stiffness_factor", stiffness_factor, lo=0.0)
        tf = None if tangential_factor is None else \
            check_point_factor("tangential_factor", tangential_factor, lam.shape[0])
        if self.friction is None:
            return self
        return ShiftedInterfaceLaw(self, lam, f, tf)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState) -> LawResult:
        """Traction, consistent tangent and trial state at jump (n, 3) [mm]; never mutates input.

        Args:
            jump: (n, 3) [g, s_x, s_y] [mm].
            committed: history at the last converged increment (n points).

        Returns:
            ``LawResult`` with an ``InterfaceState`` trial state and the dissipation increment.

        Raises:
            ValueError: bad shapes, a committed state that is not an InterfaceState, h0 not set.
            rough_contact.interface.contract.ConvergenceError: non-finite jump, or
                ``ReturnMappingError`` (a subclass) when the local Newton fails.
        """
        return self._evaluate(jump, committed, None)

    def _evaluate(self, jump: np.ndarray, committed: InterfaceState,
                  shift: Optional[np.ndarray], stiffness_factor: float = 1.0,
                  tangential_factor: Optional[np.ndarray] = None) -> LawResult:
        """``evaluate`` with the friction trial traction shifted by ``shift`` (n, 2) [MPa]
        (None: the plain law) and the tangential stiffness multiplied by ``stiffness_factor``
        and by ``tangential_factor`` (n,) (only with a shift)."""
        if self.h0 is None:
            raise ValueError("h0 (reference separation [mm]) is not set: pass h0= or use "
                             "with_seating(p_seat)")
        if not isinstance(committed, InterfaceState):
            raise ValueError(f"committed state must be an InterfaceState, got "
                             f"{type(committed).__name__}")
        jump = check_jump(jump, committed)
        n = jump.shape[0]
        if shift is not None and shift.shape != (n, 2):
            raise ValueError(f"multipliers hold {shift.shape[0]} points; the jump has {n}: "
                             f"with_multipliers needs an (n, 3) array for the n = {n} points "
                             "evaluated")

        h = self.h0 + jump[:, 0]
        traction = np.zeros((n, 3))
        tangent = np.zeros((n, 3, 3))  # zero rows 1-2 at open points; row 0 = [k, 0, 0]
        curv = self.friction is not None
        normal_dissipation = None
        if self.has_normal_memory:
            if not isinstance(committed, HistoryInterfaceState):
                raise ValueError("committed state must be a HistoryInterfaceState (h_min) for a "
                                 f"normal law with memory, got {type(committed).__name__}: use "
                                 "initial_state()")
            out = self.normal.evaluate_history(h, committed.h_min, curvature=curv)
            h_min_new = np.minimum(committed.h_min, h)
            normal_dissipation = np.zeros(n)
            moved = np.flatnonzero(h_min_new < committed.h_min)
            if moved.size:
                D = self.normal.normal_dissipation
                normal_dissipation[moved] = np.maximum(
                    D(h_min_new[moved]) - D(committed.h_min[moved]), 0.0)
        else:
            out = self.normal.evaluate(h, curvature=curv)
        if curv:
            p, k, a, dk = out
        else:
            p, k, a = out
        traction[:, 0] = -p
        tangent[:, 0, 0] = k
        contact = p > 0.0
        beyond = (np.asarray(self.normal.below_validity(h), dtype=bool)
                  if isinstance(self.normal, ValidityLimitedNormalLaw) else None)
        slipping = np.zeros(n, dtype=bool)
        dissipation = np.zeros(n)
        if self.friction is None or not contact.any():
            state = committed.copy()
            if normal_dissipation is not None:
                state.h_min = h_min_new
            return LawResult(traction, tangent, state, dissipation, a, contact,
                             slipping, beyond, normal_dissipation)

        cx, cy = self.tangential.kt_over_kn
        if shift is not None and stiffness_factor != 1.0:
            cx, cy = cx * stiffness_factor, cy * stiffness_factor
        sp = committed.plastic_slip
        kap = committed.accumulated_slip
        kt, dkt = k, dk         # k_T / c and its h-derivative
        if normal_dissipation is not None and isinstance(self.normal, ReversalStiffnessProtocol):
            un = np.flatnonzero(h > committed.h_min)      # on the unloading branch of h_min
            if un.size:
                kl, kr = self.normal.reversal_stiffness(committed.h_min.take(un))
                ok = kr > 0.0
                scale = np.where(ok, kl / np.where(ok, kr, 1.0), 1.0)
                kt, dkt = k.copy(), dk.copy()
                kt[un] *= scale
                dkt[un] *= scale
        if shift is not None and tangential_factor is not None:     # one factor per point
            kt, dkt = kt * tangential_factor, dkt * tangential_factor   # new arrays
        if contact.all():  # work on views: no gather/scatter
            cols = (jump[:, 1] - sp[:, 0], jump[:, 2] - sp[:, 1], cx * kt, cy * kt, cx * dkt,
                    cy * dkt, p, k, kap[:, 0], kap[:, 1], committed.slip_path)
            pts_in = (FrictionInput(*cols) if shift is None
                      else ShiftedFrictionInput(*cols, shift[:, 0], shift[:, 1]))
            slip = self.friction.evaluate(pts_in, traction[:, 1:], tangent[:, 1:, :])
            pts = slip.slip_index
        else:
            ic = np.flatnonzero(contact)
            kc, dkc = kt.take(ic), dkt.take(ic)
            cols = (jump[ic, 1] - sp[ic, 0], jump[ic, 2] - sp[ic, 1], cx * kc, cy * kc,
                    cx * dkc, cy * dkc, p.take(ic), k.take(ic), kap[ic, 0], kap[ic, 1],
                    committed.slip_path.take(ic))
            pts_in = (FrictionInput(*cols) if shift is None
                      else ShiftedFrictionInput(*cols, shift[ic, 0], shift[ic, 1]))
            slip = self.friction.evaluate(pts_in)
            traction[ic, 1:] = slip.traction
            tangent[ic, 1:, :] = slip.tangent
            pts = ic.take(slip.slip_index)

        state = committed.copy()
        if pts.size:
            dspx, dspy = slip.plastic_increment_x, slip.plastic_increment_y
            dw = traction[pts, 1] * dspx + traction[pts, 2] * dspy
            state.plastic_slip[pts, 0] += dspx
            state.plastic_slip[pts, 1] += dspy
            state.accumulated_slip[pts, 0] += np.abs(dspx)
            state.accumulated_slip[pts, 1] += np.abs(dspy)
            state.slip_path[pts] += slip.path_increment
            dissipation[pts] = dw
            slipping[pts] = True
        if normal_dissipation is not None:
            state.h_min = h_min_new
        return LawResult(traction, tangent, state, dissipation, a, contact, slipping, beyond,
                         normal_dissipation)


def _check_multipliers(multipliers) -> np.ndarray:
    """The multipliers as a float (n, 3) array; ValueError naming what is wrong."""
    try:
        lam = np.asarray(multipliers, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"multipliers ({type(multipliers).__name__}) must be an (n, 3) array "
                         "[lambda_N, lambda_x, lambda_y] [MPa]") from None
    if lam.ndim != 2 or lam.shape[1] != 3:
        raise ValueError(f"multipliers must have shape (n, 3) [lambda_N, lambda_x, lambda_y] "
                         f"[MPa], got {lam.shape}")
    finite = np.isfinite(lam)
    if not finite.all():
        bad = np.flatnonzero(~finite.all(axis=1))
        raise ValueError(f"multipliers are not finite at {bad.size} of {lam.shape[0]} points "
                         f"(first index {bad[0]}: {lam[bad[0]].tolist()} MPa); valid: finite")
    if lam.shape[0] and lam[:, 0].min() < 0.0:
        i = int(np.argmin(lam[:, 0]))
        raise ValueError(f"multipliers[:, 0] (lambda_N, a contact pressure) = "
                         f"{float(lam[i, 0])!r} MPa at point {i} is invalid: it must be >= 0")
    return lam


@dataclass(frozen=True)
class ShiftedInterfaceLaw:
    """An :class:`InterfaceLaw` with its friction trial traction shifted by the tangential
    multipliers of n points: what ``InterfaceLaw.with_multipliers`` returns (the normal law is
    the unshifted one; lambda_N is not used).

    Attributes:
        law: the plain law (with friction).
        multipliers: (n, 3) [lambda_N, lambda_x, lambda_y] [MPa], checked by
            ``with_multipliers``.
        stiffness_factor: the shifted law's K_T is this times the law's (> 0).
        tangential_factor: (n,) each point's K_T times it besides, or None.
    """

    law: InterfaceLaw
    multipliers: np.ndarray
    stiffness_factor: float = 1.0
    tangential_factor: Optional[np.ndarray] = None

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history at n_pts points (that of the plain law)."""
        return self.law.initial_state(n_pts)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState) -> LawResult:
        """The law at ``jump`` (n, 3) with t_trial = lambda_T + K_T (s - s_p) (see
        :meth:`InterfaceLaw.evaluate`; ValueError if the multipliers are not for n points)."""
        return self.law._evaluate(jump, committed, self.multipliers[:, 1:],
                                  self.stiffness_factor, self.tangential_factor)

    def max_friction_coefficient(self) -> float:
        """That of the plain law."""
        return self.law.max_friction_coefficient()

    @property
    def has_normal_memory(self) -> bool:
        """That of the plain law."""
        return self.law.has_normal_memory

    def normal_dissipated(self, state: InterfaceState) -> np.ndarray:
        """That of the plain law."""
        return self.law.normal_dissipated(state)
