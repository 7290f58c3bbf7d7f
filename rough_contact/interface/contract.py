"""The interface-law contract: what every law evaluated at contact points takes and returns.

This module is the hand-off between the pure-numpy laws (``rough_contact.interface``) and the
finite-element layer (``rough_contact.fem.contact.ContactInterface``). A law written by a user
plugs in by satisfying :class:`InterfaceLawProtocol` and returning :class:`LawResult`; nothing
else is looked up on it. ``docs/writing_a_law.md`` states the contract in prose and walks
through a complete user law. Pure module: numpy only.

A law is called once per evaluation with ALL interface points of a rank, as arrays (batch
first); a rank may own no point, so n = 0 must work and give empty arrays.

Units: mm, N, MPa. Jumps and gaps [mm]; tractions and pressures [MPa]; stiffnesses per nominal
area [MPa/mm]; dissipation per nominal area [N/mm] (= MPa mm).

Local axes and the jump
-----------------------
At every interface point the FE layer builds an orthonormal frame (n, x, y):

* n is the unit normal of the FIRST surface, pointing towards the second body;
* x is the user's grain direction projected on the surface (the paper's grinding direction);
* y = n x x.

``jump`` (n_pts, 3) holds ``[g, s_x, s_y]``, the components of u_second - u_first in that frame
(plus the initial gap for a rigid obstacle). g > 0 opens the interface; s is the tangential
slip.

Traction and tangent
--------------------
``traction`` (n_pts, 3) = ``[t_N, t_x, t_y]`` is energy-conjugate to the jump,
``t = dpsi/djump`` for the interface free energy psi per nominal area, so in compression
``t_N = -p <= 0`` and the friction traction points along the elastic slip. The FE residual is
``R = int B^T t dA`` and the Jacobian ``int B^T D B dA`` with ``D = dt/djump`` (n_pts, 3, 3)
(row: traction component, column: jump component; ``D[:, 0, 0] = -dp/dg >= 0``), the
ALGORITHMIC tangent of the discrete update the law computes, including the coupling of the
friction traction to the normal jump; it is non-symmetric for friction. A wrong tangent costs
Newton iterations but never changes a converged answer.

History
-------
``evaluate`` is a pure function of ``(jump, committed)``: it must never mutate ``committed``
(SNES line searches evaluate trial points that are thrown away). It returns the trial state
(a :class:`LawState`, a new object) that the interface stores; the interface commits it once
per converged increment and drops it on a cutback. The law reports the dissipation INCREMENT
of the step, ``t_T . Delta s_p >= 0`` per nominal area; the owner of the history accumulates it
(``ContactInterface``, or ``rough_contact.interface.state.StatePair`` at a material point),
never the law.

Failures
--------
A law raises :class:`ConvergenceError` (or a subclass, e.g. the friction return map's
``ReturnMappingError``) when a smaller load increment may cure the failure: the load stepping
then cuts back. A non-finite jump is such a failure (a diverging global iterate), so
:func:`check_jump` raises ``ConvergenceError`` for it. Any other exception (bad input such as a
wrong shape: ``ValueError``; a programming error) propagates at once with its own type and
traceback.

Built-in laws
-------------
``rough_contact.interface.law.InterfaceLaw`` (rough surface + friction) and
``rough_contact.interface.penalty.LinearPenalty`` / ``SoftplusPenalty`` follow this contract and
keep their history in ``rough_contact.interface.state.InterfaceState``;
``rough_contact.interface.state.StatePair`` is the committed/trial bookkeeping that sums the
dissipation increments.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Protocol, TypeVar, runtime_checkable

import numpy as np

__all__ = ["ConvergenceError", "LawState", "LawResult", "InterfaceLawProtocol",
           "CoulombLimit", "CoulombContactLaw",
           "FrictionBoundedLaw", "NewtonTangentLaw", "MultiplierLaw", "SoftenableLaw",
           "LawContractError", "check_jump", "check_point_factor"]


class ConvergenceError(ArithmeticError):
    """A failure that a smaller load increment may cure (a local Newton that did not converge,
    a non-finite jump from a diverging global iterate). Load stepping cuts back on it."""


class LawContractError(TypeError):
    """A law's result does not follow the contract (missing field, wrong shape or dtype)."""


S = TypeVar("S", bound="LawState")


@runtime_checkable
class LawState(Protocol):
    """Per-point history of a law at n points (arrays batch-first).

    Attributes:
        plastic_slip: (n, 2) irreversible tangential slip (s_p,x, s_p,y) in local axes [mm]
            (zeros for a law without friction history).
    """

    plastic_slip: np.ndarray

    def copy(self: S) -> S:
        """Deep copy (the committed state must not share memory with a trial state)."""
        ...

    def __len__(self) -> int:
        """Number of points n."""
        ...


@dataclass(frozen=True)
class LawResult:
    """Outcome of one law evaluation at n points; every law returns this type.

    Attributes:
        traction: (n, 3) float [t_N, t_x, t_y] [MPa], t = dpsi/djump, t_N = -p.
        tangent: (n, 3, 3) float consistent tangent D = dt/djump [MPa/mm] (rows: traction
            components, columns: jump components; non-symmetric in general).
        state: trial history after this evaluation (a :class:`LawState` with n points).
        dissipation: (n,) float dissipation increment t_T . Delta s_p >= 0 of this step [N/mm].
        area_fraction: (n,) float real-area fraction A/A0 in [0, 1] [-].
        contact: (n,) bool, p > 0 (the point carries load).
        slipping: (n,) bool, in contact and the friction limit is active (False wherever
            ``contact`` is False: a point out of contact is open, not slipping).
        beyond_validity: (n,) bool, True where the law is evaluated outside the range its model
            is valid for (e.g. a statistical normal law below its lowest tabulated separation,
            where a stiff continuation stands in for the model); ``None`` for a law without
            such a limit. The load stepping reports these points per increment.
        normal_dissipation: (n,) float normal hysteresis energy of this step per nominal area
            [N/mm] (>= 0), for a law with an irreversible normal part
            (``rough_contact.interface.history``); ``None`` for a reversible normal law. The
            owner of the history sums it beside the frictional ``dissipation``.
    """

    traction: np.ndarray
    tangent: np.ndarray
    state: LawState
    dissipation: np.ndarray
    area_fraction: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    beyond_validity: Optional[np.ndarray] = None
    normal_dissipation: Optional[np.ndarray] = None

    @property
    def pressure(self) -> np.ndarray:
        """(n,) contact pressure p = -t_N [MPa]."""
        return -self.traction[:, 0]

    def check(self, n: int) -> None:
        """Raise :class:`LawContractError` naming the first field that breaks the contract.

        Checks types, shapes, dtypes and the state's length; finiteness of traction and tangent
        is checked by the caller on every evaluation (a non-finite value is a convergence
        failure, not a contract breach).
        """
        fields = (("traction", (n, 3), np.floating), ("tangent", (n, 3, 3), np.floating),
                  ("dissipation", (n,), np.floating), ("area_fraction", (n,), np.floating),
                  ("contact", (n,), np.bool_), ("slipping", (n,), np.bool_))
        kind_names = {np.floating: "a floating-point dtype", np.bool_: "bool"}
        if self.beyond_validity is not None:
            fields += (("beyond_validity", (n,), np.bool_),)
        if self.normal_dissipation is not None:
            fields += (("normal_dissipation", (n,), np.floating),)
        for name, shape, kind in fields:
            value = getattr(self, name)
            if not isinstance(value, np.ndarray):
                raise LawContractError(f"LawResult.{name} must be a numpy array of shape {shape}, "
                                       f"got {type(value).__name__}")
            if value.shape != shape:
                raise LawContractError(f"LawResult.{name} has shape {value.shape}, the contract "
                                       f"needs {shape} for {n} points")
            if not np.issubdtype(value.dtype, kind):
                raise LawContractError(f"LawResult.{name} has dtype {value.dtype}, the contract "
                                       f"needs {kind_names[kind]}")
        if not isinstance(self.state, LawState):
            raise LawContractError(
                f"LawResult.state ({type(self.state).__name__}) must have a plastic_slip array, "
                "copy() and __len__ (rough_contact.interface.contract.LawState)")
        if len(self.state) != n or np.shape(self.state.plastic_slip) != (n, 2):
            raise LawContractError(
                f"LawResult.state holds {len(self.state)} points with plastic_slip of shape "
                f"{np.shape(self.state.plastic_slip)}; the contract needs {n} and ({n}, 2)")


@runtime_checkable
class InterfaceLawProtocol(Protocol):
    """An interface law evaluated at all points of an interface in one vectorised call."""

    def initial_state(self, n_points: int) -> LawState:
        """Virgin history at ``n_points`` points."""
        ...

    def evaluate(self, jump: np.ndarray, committed: LawState) -> LawResult:
        """Traction, tangent and trial state at ``jump`` (n, 3) [mm]; never mutates input.

        Raises:
            ConvergenceError: a failure a smaller load increment may cure.
            ValueError: bad input (wrong shapes, unset parameters).
        """
        ...


@runtime_checkable
class FrictionBoundedLaw(Protocol):
    """A law whose tangential traction is bounded by a friction coefficient times the pressure:
    |t_T| <= mu_max p at every point and state. The load stepping uses the bound to recognise a
    tangential load that no friction can carry (a sliding body) instead of cutting back."""

    def max_friction_coefficient(self) -> float:
        """The largest friction coefficient the law can reach (saturated, over all directions);
        0 for a frictionless law."""
        ...


@runtime_checkable
class NewtonTangentLaw(Protocol):
    """A law that proposes, for the Newton step only, a tangent other than the consistent one
    (the residual and so the converged solution are unchanged). The FE interface calls it at
    every Jacobian assembly with what the previous call of the same Newton solve returned
    (``None`` at the first Jacobian of a solve: the interface forgets it at every new solve,
    commit and revert)."""

    def newton_tangent(self, jump: np.ndarray, committed: LawState, result: LawResult,
                       previous: Optional[np.ndarray]
                       ) -> tuple[np.ndarray, Optional[np.ndarray]]:
        """(tangent (n, 3, 3) for the Newton step at ``jump``, memo for the next call)."""
        ...


@runtime_checkable
class MultiplierLaw(Protocol):
    """A penalty law that can be shifted by Lagrange multipliers, so that an enforcement
    strategy (``rough_contact.interface.enforcement.AugmentedLagrangian``) imposes its contact
    and stick constraints exactly.

    The multipliers are (n, 3) ``[lambda_N, lambda_x, lambda_y]``: the contact pressure
    lambda_N >= 0 and the tangential traction the penalty is shifted by [MPa]. At the fixed
    point of the multiplier updates (lambda <- the converged tractions [p, t_x, t_y]) the
    constraints the law makes exact hold: for a Coulomb penalty (``SoftplusPenalty``) the
    elastic gap and the elastic slip vanish; for the rough law (``InterfaceLaw``) only the
    elastic slip does -- its normal pressure p(h) is the physical asperity compliance and is
    not shifted (lambda_N unused). The multipliers are kept by the interface's
    history, not by the law state: a law with this capability is still an ordinary law (its
    ``evaluate`` is the unshifted penalty)."""

    def with_multipliers(self, multipliers: np.ndarray, stiffness_factor: float = 1.0,
                         tangential_factor: Optional[np.ndarray] = None
                         ) -> InterfaceLawProtocol:
        """The law with its penalty shifted by ``multipliers`` (n, 3) [MPa], and the penalty the
        multipliers are augmented with multiplied by ``stiffness_factor`` (> 0; 1: the law's
        own; the fixed point does not depend on it, the rate of the updates does: about
        K_b / (K_b + factor x penalty) per update, K_b the stiffness a point sees from the
        bodies). ``tangential_factor`` (n,) > 0 (:func:`check_point_factor`), or None: each
        point's tangential penalty multiplied by its own factor besides: K_b grows as the
        points get closer, so a mesh graded towards a front needs a tangential penalty that
        grows with it. It only scales the tangential penalty, whose fixed point (s = s_p where
        a point sticks, |t| = mu p where it slips) does not depend on it; a smoothed normal
        penalty's fixed point does depend on its own stiffness. Returns an object with the
        same ``initial_state``/``evaluate`` (and ``newton_tangent``, if the law has one) for
        those n points; cheap to create (no copy of the arrays)."""
        ...


@dataclass(frozen=True)
class CoulombLimit:
    """The exact limit of a Coulomb penalty law: unilateral contact (Signorini) with isotropic
    Coulomb friction, and the law's penalties (a natural scale for an augmentation).

    Attributes:
        friction: Coulomb's mu >= 0 (0: frictionless) [-].
        k_normal, k_tangential: the law's penalties [MPa/mm] (k_tangential 0: frictionless).
        first_contact: where a point that closes during an increment starts to stick
            (``SoftplusPenalty``: ``"increment_start"`` or ``"closure"``).
    """

    friction: float
    k_normal: float
    k_tangential: float
    first_contact: str = "increment_start"


@runtime_checkable
class CoulombContactLaw(Protocol):
    """A penalty law whose penalty-to-infinity limit is unilateral contact with isotropic
    Coulomb friction and whose state is ``InterfaceState`` (``SoftplusPenalty``): the
    semismooth Newton enforcement (``rough_contact.interface.enforcement.SemismoothNewton``)
    solves that limit exactly instead of the penalty. The rough law is no such law: its
    normal compliance is physical."""

    def coulomb_limit(self) -> CoulombLimit:
        """The law's exact limit and penalties."""
        ...


@runtime_checkable
class SoftenableLaw(Protocol):
    """A penalty law that can give the same law at a softer penalty, for Newton's penalty
    continuation (``rough_contact.solver.snes.Continuation``): a stiff penalty's stick/slip and
    contact switches happen within a jump of order traction / penalty, far below a Newton step,
    and a Newton solve from a far start stalls; the solver first solves with the softened law
    and starts the law itself from that solution. The softened law takes and returns the same
    states as the law (the committed history is shared); the converged answer is the law's
    own, the softened law only supplies a starting point."""

    def softened(self, factor: float) -> InterfaceLawProtocol:
        """The law with its penalty stiffnesses divided by ``factor`` (>= 1) [-] (and any
        smoothing length of the penalty multiplied by it, so the pressure at zero gap is
        kept)."""
        ...


def check_jump(jump, committed: LawState) -> np.ndarray:
    """Validate the arguments of ``evaluate`` as the contract requires; return the jump.

    Args:
        jump: (n, 3) [g, s_x, s_y] [mm].
        committed: the committed state; must hold n points.

    Returns:
        ``jump`` as a float array (n, 3) (no copy if it already is one).

    Raises:
        ValueError: ``jump`` is not (n, 3), or ``committed`` is not a ``LawState`` of n points.
        ConvergenceError: ``jump`` is not finite somewhere (names the count and the first index).
    """
    jump = np.asarray(jump, dtype=float)
    if jump.ndim != 2 or jump.shape[1] != 3:
        raise ValueError(f"jump must have shape (n_pts, 3), got {jump.shape}")
    n = jump.shape[0]
    if not isinstance(committed, LawState) or len(committed) != n:
        got = (f"{len(committed)} points" if isinstance(committed, LawState)
               else type(committed).__name__)
        raise ValueError(f"committed state must be a LawState with {n} points (as jump), "
                         f"got {got}")
    if not np.isfinite(jump).all():
        bad = np.flatnonzero(~np.isfinite(jump).all(axis=1))
        raise ConvergenceError(f"jump is not finite at {bad.size} of {n} points (first index "
                               f"{bad[0]}): a diverging global iterate")
    return jump


def check_point_factor(name: str, factor, n: int) -> np.ndarray:
    """A per-point factor (e.g. ``with_multipliers``' ``tangential_factor``): a finite (n,)
    array > 0, returned as a float array.

    Raises:
        ValueError: naming ``name``, the shape or the first bad value, and the valid range.
    """
    try:
        f = np.asarray(factor, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} ({type(factor).__name__}) is invalid: it must be an ({n},) "
                         "array of numbers > 0") from None
    if f.shape != (n,):
        raise ValueError(f"{name} of shape {f.shape} for {n} points is invalid: one factor "
                         f"per point, ({n},)")
    bad = ~(np.isfinite(f) & (f > 0.0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{i}] = {float(f[i])!r} is invalid ({int(bad.sum())} of {n} "
                         f"points): it must be finite and > 0")
    return f
