"""Per-point history of the interface laws: the state arrays, and committed / trial bookkeeping.

Units: slips in mm, dissipated energy per nominal area in N/mm (= MPa mm).

The trial state is recomputed from the committed one at every law evaluation (laws are pure
functions, ``rough_contact.interface.contract``); ``StatePair.commit`` runs once per converged
load increment and ``StatePair.revert`` after a failed one, before the cutback. Laws report only
the dissipation increment of a step; ``StatePair`` is where it is summed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contract import LawResult, LawState

__all__ = ["InterfaceState", "AugmentedState", "StatePair"]


@dataclass
class InterfaceState:
    """History at n interface points (arrays batch-first); the state of every built-in law.

    Attributes:
        plastic_slip: (n, 2) irreversible slip s_p in local axes (x, y) [mm].
        accumulated_slip: (n, 2) sums of |Delta s_p,x| and |Delta s_p,y| [mm]; hardening
            variables of the orthotropic law, (89)-(90).
        slip_path: (n,) sum of ||Delta s_p|| [mm]; hardening variable of the isotropic law (119).
    """

    plastic_slip: np.ndarray
    accumulated_slip: np.ndarray
    slip_path: np.ndarray

    def __post_init__(self) -> None:
        n = np.shape(self.plastic_slip)[0] if np.ndim(self.plastic_slip) == 2 else -1
        for name, shape in (("plastic_slip", (n, 2)), ("accumulated_slip", (n, 2)),
                            ("slip_path", (n,))):
            arr = getattr(self, name)
            if not isinstance(arr, np.ndarray) or arr.shape != shape or n < 0:
                want = shape if n >= 0 else "(n, 2)"
                raise ValueError(f"InterfaceState.{name} must be an ndarray of shape {want}, "
                                 f"got {np.shape(arr)}")

    @classmethod
    def zeros(cls, n_pts: int) -> InterfaceState:
        """Virgin state (no slip, no hardening) at n_pts points."""
        n = int(n_pts)
        if n < 0:
            raise ValueError(f"n_pts = {n_pts!r} is invalid: it must be >= 0")
        return cls(np.zeros((n, 2)), np.zeros((n, 2)), np.zeros(n))

    def copy(self) -> InterfaceState:
        """Deep copy."""
        return InterfaceState(self.plastic_slip.copy(), self.accumulated_slip.copy(),
                              self.slip_path.copy())

    def __len__(self) -> int:
        return self.plastic_slip.shape[0]


@dataclass
class AugmentedState(InterfaceState):
    """History of an augmented-Lagrangian penalty law: :class:`InterfaceState` plus multipliers.

    Attributes:
        multiplier: (n, 3) [lambda_N, lambda_x, lambda_y]: the contact pressure lambda_N >= 0
            and the tangential traction (lambda_x, lambda_y) the penalty is shifted by [MPa].
            In a law evaluation they are the tractions of the trial point; in the committed
            state, those of the last multiplier update (within an increment) or of the last
            converged increment.
    """

    multiplier: np.ndarray = None

    def __post_init__(self) -> None:
        super().__post_init__()
        n = len(self)
        if not isinstance(self.multiplier, np.ndarray) or self.multiplier.shape != (n, 3):
            raise ValueError(f"AugmentedState.multiplier must be an ndarray of shape ({n}, 3), "
                             f"got {np.shape(self.multiplier)}")

    @classmethod
    def zeros(cls, n_pts: int) -> AugmentedState:
        """Virgin state (no slip, no hardening, zero multipliers) at n_pts points."""
        base = InterfaceState.zeros(n_pts)
        return cls(base.plastic_slip, base.accumulated_slip, base.slip_path,
                   np.zeros((len(base), 3)))

    def copy(self) -> AugmentedState:
        """Deep copy."""
        return AugmentedState(self.plastic_slip.copy(), self.accumulated_slip.copy(),
                              self.slip_path.copy(), self.multiplier.copy())


class StatePair:
    """Committed and trial history of one interface, and the dissipation accumulated over it.

    The one place where history is committed or dropped and where the dissipation increments
    that laws report (``LawResult.dissipation``) are summed.

    Args:
        committed: the converged state (any ``LawState``); ``trial`` starts as a copy of it.

    Attributes:
        committed: state at the last converged increment.
        trial: state of the latest law evaluation.
        dissipated: (n,) dissipation per nominal area summed over committed increments [N/mm].
    """

    def __init__(self, committed: LawState):
        if not isinstance(committed, LawState):
            raise ValueError(f"committed ({type(committed).__name__}) must be a LawState "
                             "(plastic_slip, copy(), __len__)")
        self.committed = committed
        self.trial = committed.copy()
        n = len(committed)
        self.dissipated = np.zeros(n)
        self._pending = np.zeros(n)

    def update(self, result: LawResult) -> None:
        """Keep the trial state and dissipation increment of a law evaluation.

        The latest call wins: a line search evaluates several trial points, and only the one the
        global Newton accepted is committed.

        Raises:
            ValueError: ``result`` is not a ``LawResult`` or holds another number of points.
        """
        if not isinstance(result, LawResult):
            raise ValueError(f"update expects a LawResult, got {type(result).__name__}")
        n = len(self.committed)
        if len(result.state) != n or np.shape(result.dissipation) != (n,):
            raise ValueError(f"trial state has {len(result.state)} points and dissipation shape "
                             f"{np.shape(result.dissipation)}; committed has {n} points")
        self.trial = result.state
        self._pending = result.dissipation

    def commit(self) -> None:
        """Accept the trial state and its dissipation (after the global Newton converged)."""
        self.committed = self.trial.copy()
        self.dissipated = self.dissipated + self._pending
        self._pending = np.zeros_like(self.dissipated)

    def restore(self, committed: LawState, dissipated: np.ndarray) -> None:
        """Set the committed state and the accumulated dissipation, dropping the trial (resuming a
        checkpoint; an augmented-Lagrangian multiplier update, or undoing one)."""
        if not isinstance(committed, LawState) or len(committed) != len(self.committed):
            raise ValueError(f"restored state ({type(committed).__name__}, "
                             f"{len(committed) if isinstance(committed, LawState) else '?'} "
                             f"points) must be a LawState of {len(self.committed)} points")
        d = np.asarray(dissipated, dtype=float)
        if d.shape != self.dissipated.shape:
            raise ValueError(f"restored dissipation of shape {d.shape}, expected "
                             f"{self.dissipated.shape}")
        self.committed = committed.copy()
        self.trial = committed.copy()
        self.dissipated = d.copy()
        self._pending = np.zeros_like(self.dissipated)

    def revert(self) -> None:
        """Discard the trial state and its dissipation (the global Newton failed; cutback)."""
        self.trial = self.committed.copy()
        self._pending = np.zeros_like(self.dissipated)
