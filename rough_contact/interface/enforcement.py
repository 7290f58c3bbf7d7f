"""Enforcement strategies: how an interface imposes its law's constraints.

Pairing, law and enforcement are independent axes (as in Tribol): the same law — a penalty
law such as ``SoftplusPenalty`` — can be used

* as it is (:class:`Penalty`): the penalty compliance is part of the answer (for the rough law
  it is the physical normal compliance of the asperities), one Newton solve per increment;
* with exact constraints (:class:`AugmentedLagrangian`): Uzawa's iteration on per-point
  multipliers, lambda <- the converged tractions, one Newton solve per update, until the
  multipliers stop moving; the law must be a
  :class:`~rough_contact.interface.contract.MultiplierLaw`;
* with exact constraints and the multipliers updated inside the Newton iteration
  (:class:`NewtonAugmentedLagrangian`): lambda <- the tractions at every Newton iterate, the
  same fixed point as Uzawa's at the cost of about one Newton solve per increment (nodal
  points, ``rough_contact.fem.nodal``);
* with exact constraints by Alart–Curnier's semismooth Newton (:class:`SemismoothNewton`):
  the contact and Coulomb conditions are equations solved with the equilibrium, the tractions
  condensed through the dual basis (``rough_contact.fem.condensation``); the law must be a
  :class:`~rough_contact.interface.contract.CoulombContactLaw`, whose penalty is not used.

A strategy is pure numpy and holds no per-point data: the multipliers live in the interface's
history (:class:`~rough_contact.interface.state.InterfaceHistory`), the global reductions and
the loop over Newton solves belong to the FE interface and the load stepping
(``ContactInterface.accept``, ``rough_contact.solver.loading``).

Units: multipliers and tractions [MPa].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Protocol, Union, runtime_checkable

import numpy as np

from ..validation import check_integer, check_scalar
from .contract import (CoulombContactLaw, CoulombLimit, InterfaceLawProtocol, LawResult,
                       MultiplierLaw)

__all__ = ["Enforcement", "Penalty", "AugmentedLagrangian", "NewtonAugmentedLagrangian",
           "SemismoothNewton", "MultiplierUpdate"]


@dataclass(frozen=True)
class MultiplierUpdate:
    """The multipliers proposed after a converged Newton solve.

    Attributes:
        multipliers: (n, 3) new multipliers [MPa].
        change: (n,) magnitude of each point's change [MPa].
    """

    multipliers: np.ndarray
    change: np.ndarray


@runtime_checkable
class Enforcement(Protocol):
    """What the interface asks of an enforcement strategy."""

    name: str

    def check_law(self, law: InterfaceLawProtocol) -> None:
        """Raise ``TypeError`` if ``law`` cannot be enforced this way."""
        ...

    def initial_multipliers(self, n_points: int) -> Optional[np.ndarray]:
        """(n, 3) virgin multipliers, or None for a strategy without multipliers."""
        ...

    def law_for(self, law: InterfaceLawProtocol, multipliers: Optional[np.ndarray],
                spacing: Optional[np.ndarray] = None) -> InterfaceLawProtocol:
        """The law as this strategy evaluates it with the committed ``multipliers``;
        ``spacing``: (n,) the points' spacing [mm] where the point set knows it (the nodal
        one: :attr:`rough_contact.fem.nodal.NodalPoints.spacing`), else None."""
        ...


@dataclass(frozen=True)
class Penalty:
    """The law as it is: no multipliers, one Newton solve per increment."""

    name: str = "penalty"

    def check_law(self, law: InterfaceLawProtocol) -> None:
        """Any law can be used as a penalty."""

    def initial_multipliers(self, n_points: int) -> None:
        """No multipliers."""
        return None

    def law_for(self, law: InterfaceLawProtocol, multipliers: None,
                spacing: Optional[np.ndarray] = None) -> InterfaceLawProtocol:
        """The law itself."""
        return law


@dataclass(frozen=True)
class AugmentedLagrangian:
    """Exact contact and stick by Uzawa's augmented-Lagrangian iteration.

    Within one Newton solve the multipliers are fixed (at the start of an increment
    extrapolated from the last two converged increments by :meth:`extrapolate` with the secant
    predictor); after the solve the interface proposes lambda <- [p, t_x, t_y] of the converged
    solution (:meth:`update`); if the largest change over all points and ranks exceeds
    ``tolerance`` times the largest traction magnitude, the load stepping solves again with
    them, else it commits. A failed increment restores the multipliers it started from.

    Exact constraints at more points per facet than the surface has nodes per facet lock (the
    iteration stalls where contact or stick ends): on P1/Q1 use the vertex rule; on P2 a rule
    of at most 2 points per triangle (the interface warns).

    Args:
        tolerance: convergence of the multipliers, relative to the largest traction magnitude
            of the interface (0 < tol < 1) [-]. Keep it above about 1e-8: the Newton solves are
            accurate to rtol 1e-9 of the step's first residual, and the changes stall there.
        max_updates: multiplier updates per load increment (>= 1) before the increment counts
            as not converged (cutback).
        stiffness_factor: the law's penalty under the multipliers is multiplied by this (> 0)
            (``MultiplierLaw.with_multipliers``): the fixed point does not depend on it, the
            rate of the updates does (about K_b / (K_b + factor x penalty) per update). 1 (the
            default) for a penalty law whose stiffness the user chose (``SoftplusPenalty``);
            for the rough law, whose tangential stiffness K_T = c k_N is the physical and soft
            one, 10-100 (docs/exact_contact.md).
        reference_spacing: the point spacing [mm] (> 0) the law's tangential penalty was
            chosen for, or None (the default: the same penalty at every point). Given, each
            point's tangential penalty is also multiplied by reference_spacing / h_j, h_j the
            point's own spacing (nodal point set only, ``NodalPoints.spacing``). The stiffness
            K_b a point sees from the bodies grows as E / h_j, so on a mesh graded towards a
            front (a ring of small elements where the slip zone lies) a penalty chosen for the
            coarser spacing is soft there and the stick multipliers crawl; scaled, the rate is
            the same everywhere (docs/mindlin_dual.md measures it). The tangential fixed point
            does not depend on it. The normal penalty is left alone: a smoothed one
            (``SoftplusPenalty``'s width) is part of the answer at the contact's edge.
    """

    tolerance: float = 1e-3
    max_updates: int = 30
    stiffness_factor: float = 1.0
    reference_spacing: Optional[float] = None
    name: str = "augmented_lagrangian"

    def __post_init__(self) -> None:
        check_scalar("augmentation tolerance", self.tolerance, lo=0.0, hi=1.0, hi_open=True)
        check_scalar("stiffness_factor", self.stiffness_factor, lo=0.0)
        check_integer("max_updates", self.max_updates, lo=1)
        if self.reference_spacing is not None:
            check_scalar("reference_spacing", self.reference_spacing, lo=0.0, unit="mm")

    def check_law(self, law: InterfaceLawProtocol) -> None:
        """The law must be a MultiplierLaw (its penalty can be shifted)."""
        if not isinstance(law, MultiplierLaw):
            raise TypeError(
                f"the augmented-Lagrangian enforcement needs a law whose penalty can be shifted "
                f"by multipliers (rough_contact.interface.contract.MultiplierLaw: "
                f"with_multipliers); {type(law).__name__} is not one")

    def initial_multipliers(self, n_points: int) -> np.ndarray:
        """Zero multipliers at n_points points."""
        return np.zeros((int(n_points), 3))

    def law_for(self, law: MultiplierLaw, multipliers: np.ndarray,
                spacing: Optional[np.ndarray] = None) -> InterfaceLawProtocol:
        """The law shifted by ``multipliers``, its penalty times ``stiffness_factor`` and, with
        ``reference_spacing``, its tangential penalty times reference_spacing / h_j at each
        point besides (``spacing``: the h_j, (n,) [mm]).

        Raises:
            ValueError: ``reference_spacing`` set and ``spacing`` None (a point set that does
                not know its spacing) or not (n,).
        """
        if self.reference_spacing is None:
            return law.with_multipliers(multipliers, self.stiffness_factor)
        if spacing is None:
            raise ValueError(f"reference_spacing = {self.reference_spacing!r} mm needs the "
                             "points' spacing, which only the nodal point set knows "
                             "(rough_contact.fem.nodal.NodalContactInterface)")
        return law.with_multipliers(multipliers, self.stiffness_factor,
                                    self.reference_spacing / np.asarray(spacing))

    @staticmethod
    def update(multipliers: np.ndarray, result: LawResult) -> MultiplierUpdate:
        """lambda_new = [p, t_x, t_y] of ``result`` (pure) and each point's change."""
        new = np.empty_like(multipliers)
        new[:, 0] = -result.traction[:, 0]
        new[:, 1:] = result.traction[:, 1:]
        return MultiplierUpdate(new, np.linalg.norm(new - multipliers, axis=1))

    @staticmethod
    def extrapolate(multipliers: np.ndarray, previous: np.ndarray,
                    ratio: Union[float, np.floating]) -> np.ndarray:
        """lambda + ratio (lambda - lambda_previous), lambda_N clipped at 0 (pure)."""
        new = multipliers.copy()
        new += ratio * (multipliers - previous)
        new[:, 0] = np.maximum(new[:, 0], 0.0)
        return new


@dataclass(frozen=True)
class NewtonAugmentedLagrangian(AugmentedLagrangian):
    """Exact contact and stick with the multipliers updated inside the Newton iteration.

    The augmented-Lagrangian (Alart-Curnier) fixed point lambda = P_C(lambda + r g~) of
    :class:`AugmentedLagrangian`, reached without a Newton solve per update: at the start of
    every Newton iteration (the converged tractions of Uzawa's scheme, here taken at the
    current iterate) lambda <- [p, t_x, t_y] of the law at the current iterate with the
    current multipliers, as long as that moves the multipliers by more than ``tolerance``
    times the largest traction; then the residual is evaluated again with the new multipliers
    and the Newton step is taken on the penalty tangent. Once the multipliers move by less,
    they stay fixed and Newton converges quadratically on the penalty law shifted by them.
    After the Newton solve the interface checks the multipliers as :class:`AugmentedLagrangian`
    does (``ContactInterface.accept``): if the converged iterate would still move them by more
    than ``tolerance``, it solves again (counted as an update; rare). The converged answer is
    that of :class:`AugmentedLagrangian` with the same tolerance; only the path differs.

    For a fixed contact and stick set each update is one Uzawa step, whose error ratio is
    1 / (1 + r c) (r: the penalty, c: the compliance a vertex multiplier sees); the Newton
    iteration's own convergence runs alongside.

    Used by the nodal point set (``rough_contact.fem.nodal.NodalContactInterface``), whose
    per-vertex multipliers carry no more constraints than the surface has vertices; the
    interface implements the Newton solver's per-iteration hook
    (``rough_contact.solver.snes.NewtonIterationHook``).

    Args:
        tolerance, max_updates, stiffness_factor: as :class:`AugmentedLagrangian`
            (``max_updates`` bounds the re-solves after a converged Newton solve, not the
            in-Newton updates).
        first_iteration: the first Newton iterate (>= 0) at which the multipliers are updated
            (0: also at the start of a solve, the predicted start or, in a re-solve, the
            iterate ``accept`` has just updated them at).
        residual_ratio: the multipliers are updated only at iterates whose residual is at
            most this fraction (0 <= ratio <= 1) of the solve's first residual [-]: an update
            far from equilibrium (a Newton step that overshot) feeds the overshoot into the
            multipliers.
    """

    first_iteration: int = 1
    residual_ratio: float = 1e-2
    name: str = "newton_augmented_lagrangian"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_scalar("residual_ratio", self.residual_ratio, lo=0.0, hi=1.0, lo_open=False,
                     hi_open=False)
        check_integer("first_iteration", self.first_iteration, lo=0, what="Newton iteration")


@dataclass(frozen=True)
class SemismoothNewton:
    """Exact contact and Coulomb stick by Alart–Curnier's semismooth Newton.

    The complementarity function of ``rough_contact.interface.alart_curnier`` is solved
    together with the equilibrium in one Newton iteration; the tractions are condensed
    vertex by vertex through the dual basis (``rough_contact.fem.condensation``), so the
    Newton system has the displacement's size and no multiplier loop exists: a converged
    Newton solve is exact. As in GetFEM's Alart–Curnier contact, the active contact and stick
    sets are updated at every iterate (a semismooth Newton; the backtracking line search on the
    residual norm globalises it).

    The law is used only for its exact limit (``CoulombContactLaw.coulomb_limit``: mu); its
    penalty and smoothing are not: the answer is Signorini–Coulomb's. Nodal point set with the
    dual basis on P1/Q1 displacements (``NodalContactInterface(basis="dual")``), small sliding.

    Args:
        r_normal, r_tangential: the augmentation parameters r_N, r_T > 0 [MPa/mm]. They do not
            change the answer, only which branch (contact/open, stick/slip) an iterate is on
            and so the iteration count. None (the default): per vertex, the bulk stiffness the
            vertex's node sees per area, the mean diagonal of K over its free components
            divided by its weight m_j (about E / h; docs/exact_contact_newton.md measures the
            choice); r_T None: r_N.
    """

    r_normal: Optional[float] = None
    r_tangential: Optional[float] = None
    name: str = "semismooth_newton"

    def __post_init__(self) -> None:
        for what, r in (("r_normal", self.r_normal), ("r_tangential", self.r_tangential)):
            if r is not None:
                check_scalar(what, r, lo=0.0, unit="MPa/mm")

    def check_law(self, law: InterfaceLawProtocol) -> None:
        """The law must be a CoulombContactLaw (its exact limit is what is solved)."""
        if not isinstance(law, CoulombContactLaw):
            raise TypeError(
                f"the semismooth Newton enforcement solves unilateral contact with Coulomb "
                f"friction exactly and needs a law with that limit (rough_contact.interface."
                f"contract.CoulombContactLaw: coulomb_limit, e.g. SoftplusPenalty); "
                f"{type(law).__name__} is not one (for the rough law use AugmentedLagrangian)")
        first = law.coulomb_limit().first_contact
        if first != "increment_start":
            raise ValueError(
                f"first_contact = {first!r} is not available with the semismooth Newton "
                f"enforcement (its condensed friction anchors a closing point at the "
                f"increment's start): use first_contact='increment_start' or "
                f"NewtonAugmentedLagrangian")

    def initial_multipliers(self, n_points: int) -> None:
        """No multipliers: the tractions are condensed."""
        return None

    def law_for(self, law: InterfaceLawProtocol, multipliers: None,
                spacing: Optional[np.ndarray] = None) -> InterfaceLawProtocol:
        """The law itself (not evaluated for the residual)."""
        return law

    def parameters(self, law: CoulombContactLaw) -> tuple[float, Optional[float], Optional[float]]:
        """(mu, r_N, r_T) for ``law``; None where the interface takes the bulk stiffness."""
        limit: CoulombLimit = law.coulomb_limit()
        rt = self.r_tangential if self.r_tangential is not None else self.r_normal
        return limit.friction, self.r_normal, rt
