"""Per-point history of the interface laws: the state arrays, and committed / trial bookkeeping.

Units: slips in mm, dissipated energy per nominal area in N/mm (= MPa mm).

The trial state is recomputed from the committed one at every law evaluation (laws are pure
functions, ``rough_contact.interface.contract``); ``StatePair.commit`` runs once per converged
load increment and ``StatePair.revert`` after a failed one, before the cutback. Laws report only
the dissipation increment of a step; ``StatePair`` is where it is summed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from .contract import LawResult, LawState

__all__ = ["InterfaceState", "HistoryInterfaceState", "StatePair", "InterfaceHistory",
           "is_pointwise", "take_points", "keep_points"]


@dataclass
class InterfaceState:
    """History at n interface points (arrays batch-first); the state of every built-in law.

    Attributes:
        plastic_slip: (n, 2) irreversible slip s_p in local axes (x, y) [mm].
        accumulated_slip: (n, 2) sums of |Delta s_p,x| and |Delta s_p,y| [mm]; hardening
            variables of the orthotropic law, (89)-(90).
        slip_path: (n,) sum of ||Delta s_p|| [mm]; hardening variable of the isotropic law (119).
        closed: (n,) bool, the point was in contact when this state was reached, as the law
            that wrote the state judged it (``SoftplusPenalty``: pressure at least that of its
            smoothing at zero gap; ``LinearPenalty``: pressure > 0); a law that does not
            record it passes it on unchanged. Keyword only; default (None): all open, the
            virgin state. ``SoftplusPenalty(first_contact="closure")`` reads it to find the
            points that close during an increment.
    """

    plastic_slip: np.ndarray
    accumulated_slip: np.ndarray
    slip_path: np.ndarray
    closed: Optional[np.ndarray] = field(default=None, kw_only=True)

    def __post_init__(self) -> None:
        n = np.shape(self.plastic_slip)[0] if np.ndim(self.plastic_slip) == 2 else -1
        if self.closed is None and n >= 0:
            self.closed = np.zeros(n, dtype=bool)
        for name, shape in (("plastic_slip", (n, 2)), ("accumulated_slip", (n, 2)),
                            ("slip_path", (n,)), ("closed", (n,))):
            arr = getattr(self, name)
            if not isinstance(arr, np.ndarray) or arr.shape != shape or n < 0:
                want = shape if n >= 0 else "(n, 2)"
                raise ValueError(f"InterfaceState.{name} must be an ndarray of shape {want}, "
                                 f"got {np.shape(arr)}")
        if self.closed.dtype != bool:
            raise ValueError(f"InterfaceState.closed must be a bool array, got dtype "
                             f"{self.closed.dtype}")

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
                              self.slip_path.copy(), closed=self.closed.copy())

    def __setstate__(self, state: dict) -> None:
        # a state pickled before ``closed`` existed (an older checkpoint): all open
        self.__dict__.update(state)
        if self.__dict__.get("closed") is None:
            self.closed = np.zeros(len(self.slip_path), dtype=bool)

    def __len__(self) -> int:
        return self.plastic_slip.shape[0]


@dataclass
class HistoryInterfaceState(InterfaceState):
    """``InterfaceState`` plus the normal history of an irreversible normal law
    (``rough_contact.interface.history.HistoryNormalLawProtocol``).

    Attributes:
        h_min: (n,) smallest mean-plane separation reached so far [mm]; +inf for a virgin point.
    """

    h_min: np.ndarray = None

    def __post_init__(self) -> None:
        super().__post_init__()
        n = self.plastic_slip.shape[0]
        if not isinstance(self.h_min, np.ndarray) or self.h_min.shape != (n,):
            raise ValueError(f"HistoryInterfaceState.h_min must be an ndarray of shape ({n},), "
                             f"got {np.shape(self.h_min)}")

    @classmethod
    def zeros(cls, n_pts: int) -> HistoryInterfaceState:
        """Virgin state at n_pts points (no slip, h_min = +inf)."""
        base = InterfaceState.zeros(n_pts)
        return cls(base.plastic_slip, base.accumulated_slip, base.slip_path,
                   np.full(base.slip_path.shape, np.inf))

    def copy(self) -> HistoryInterfaceState:
        """Deep copy."""
        return HistoryInterfaceState(self.plastic_slip.copy(), self.accumulated_slip.copy(),
                                     self.slip_path.copy(), self.h_min.copy(),
                                     closed=self.closed.copy())


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
        normal_dissipated: (n,) normal hysteresis energy per nominal area (irreversible normal
            law, ``LawResult.normal_dissipation``) summed over committed increments [N/mm];
            zeros for a reversible law.
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
        self.normal_dissipated = np.zeros(n)
        self._pending_normal = np.zeros(n)

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
        self._pending_normal = (np.zeros(n) if result.normal_dissipation is None
                                else result.normal_dissipation)

    def commit(self) -> None:
        """Accept the trial state and its dissipation (after the global Newton converged)."""
        self.committed = self.trial.copy()
        self.dissipated = self.dissipated + self._pending
        self._pending = np.zeros_like(self.dissipated)
        self.normal_dissipated = self.normal_dissipated + self._pending_normal
        self._pending_normal = np.zeros_like(self.dissipated)

    def restore(self, committed: LawState, dissipated: np.ndarray,
                normal_dissipated: Optional[np.ndarray] = None) -> None:
        """Set the committed state and the accumulated dissipation, dropping the trial
        (resuming a checkpoint)."""
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
        nd = (np.zeros_like(d) if normal_dissipated is None
              else np.asarray(normal_dissipated, dtype=float))
        if nd.shape != d.shape:
            raise ValueError(f"restored normal dissipation of shape {nd.shape}, expected "
                             f"{d.shape}")
        self.normal_dissipated = nd.copy()
        self._pending_normal = np.zeros_like(self.dissipated)

    def revert(self) -> None:
        """Discard the trial state and its dissipation (the global Newton failed; cutback)."""
        self.trial = self.committed.copy()
        self._pending = np.zeros_like(self.dissipated)
        self._pending_normal = np.zeros_like(self.dissipated)


class InterfaceHistory:
    """Everything an interface remembers between increments, in one object.

    * the law's history (:class:`StatePair`: committed and trial state, dissipation);
    * the multipliers of an enforcement that has them (committed; the trial ones, the tractions
      of the accepted iterate, which the commit makes the next increment's start; those the
      increment started from, to undo its updates on a revert; those the last converged
      increment started from, for the secant predictor);
    * the pairing of a sliding pairing (an opaque, picklable object and the jump offsets it
      set), None for a fixed pairing.

    ``commit`` after a converged increment, ``revert`` after a failed one; ``state()`` is one
    picklable dict a checkpoint stores and ``restore`` reinstates.

    Args:
        law_state: the law's virgin state.
        multipliers: (n, 3) virgin multipliers [MPa], or None.
    """

    def __init__(self, law_state: LawState, multipliers: Optional[np.ndarray] = None):
        self.law = StatePair(law_state)
        self.multipliers = None if multipliers is None else np.asarray(multipliers, float)
        self.multipliers_before: Optional[np.ndarray] = None
        self._multipliers_start: Optional[np.ndarray] = None
        self._multipliers_trial: Optional[np.ndarray] = None
        self.pairing: Optional[object] = None

    # ------------------------------------------------------------------ lifecycle
    def set_multipliers(self, new: np.ndarray) -> None:
        """Replace the committed multipliers within the current increment (an update or the
        predictor); the trial law state is dropped; :meth:`revert` undoes it."""
        if self.multipliers is None or np.shape(new) != self.multipliers.shape:
            raise ValueError(f"multipliers of shape {np.shape(new)}; this history holds "
                             f"{None if self.multipliers is None else self.multipliers.shape}")
        if self._multipliers_start is None:
            self._multipliers_start = self.multipliers
        self.multipliers = new
        self._multipliers_trial = None
        self.law.revert()

    def propose_multipliers(self, trial: np.ndarray) -> None:
        """The multipliers the commit will make the committed ones (the converged tractions:
        within the tolerance of those used, and the next increment starts from them)."""
        if self.multipliers is None or np.shape(trial) != self.multipliers.shape:
            raise ValueError(f"trial multipliers of shape {np.shape(trial)}; this history "
                             f"holds {None if self.multipliers is None else self.multipliers.shape}")
        self._multipliers_trial = trial

    def commit(self) -> None:
        """Accept the trial state (the global Newton converged and the enforcement is done)."""
        if self.multipliers is not None:
            self.multipliers_before = (self._multipliers_start
                                       if self._multipliers_start is not None
                                       else self.multipliers)
            if self._multipliers_trial is not None:
                self.multipliers = self._multipliers_trial
        self._multipliers_start = self._multipliers_trial = None
        self.law.commit()

    def revert(self) -> None:
        """Drop the trial state and the multiplier changes of the current increment."""
        if self._multipliers_start is not None:
            self.multipliers = self._multipliers_start
            self._multipliers_start = None
        self._multipliers_trial = None
        self.law.revert()

    # ------------------------------------------------------------------ checkpoints
    def state(self) -> dict:
        """The committed history as one picklable dict (for checkpoints)."""
        return dict(committed=self.law.committed, dissipated=self.law.dissipated,
                    normal_dissipated=self.law.normal_dissipated, multipliers=self.multipliers,
                    multipliers_before=self.multipliers_before,
                    pairing=self.pairing)

    def restore(self, state: dict) -> None:
        """Reinstate :meth:`state` (the trial state is dropped).

        Raises:
            ValueError: the state belongs to another interface (point count, multipliers).
        """
        self.law.restore(state["committed"], state["dissipated"],
                         state.get("normal_dissipated"))
        lam, before = state["multipliers"], state["multipliers_before"]
        for name, value in (("multipliers", lam), ("multipliers_before", before)):
            if value is not None and (self.multipliers is None
                                      or np.shape(value) != self.multipliers.shape):
                raise ValueError(f"restored {name} of shape {np.shape(value)}; this interface "
                                 f"holds {None if self.multipliers is None else self.multipliers.shape}")
        if (lam is None) != (self.multipliers is None):
            raise ValueError("the restored history and this interface differ in enforcement "
                             "(multipliers present in one only)")
        self.multipliers = None if lam is None else np.array(lam)
        self.multipliers_before = None if before is None else np.array(before)
        self._multipliers_start = self._multipliers_trial = None
        self.pairing = state["pairing"]


# ---------------------------------------------------------------------- per-point redistribution
def is_pointwise(state: LawState) -> bool:
    """Whether ``state`` can be cut and joined point by point: a dataclass (``InterfaceState``,
    or a user law's) whose every field is an ndarray with one row per point (batch-first)."""
    if not dataclasses.is_dataclass(state) or isinstance(state, type):
        return False
    n = len(state)
    return all(isinstance(getattr(state, f.name), np.ndarray)
               and np.ndim(getattr(state, f.name)) >= 1 and np.shape(getattr(state, f.name))[0] == n
               for f in dataclasses.fields(state))


def take_points(states: Sequence[LawState], index: np.ndarray) -> LawState:
    """The points ``index`` of the states ``states`` joined in order (e.g. the states that
    several ranks saved, re-dealt to another partition).

    Raises:
        TypeError: a state is not :func:`is_pointwise`, or the states are of different types.
    """
    first = states[0]
    bad = [type(s).__name__ for s in states
           if type(s) is not type(first) or not is_pointwise(s)]
    if bad:
        raise TypeError(f"law states of type {sorted(set(bad))} cannot be re-dealt point by point "
                        "(a dataclass of batch-first ndarray fields, all of one type, is needed)")
    index = np.asarray(index, dtype=np.int64)
    joined = {f.name: np.concatenate([getattr(s, f.name) for s in states], axis=0)[index]
              for f in dataclasses.fields(first)}
    return dataclasses.replace(first, **joined)


def keep_points(trial: LawState, committed: LawState, keep: np.ndarray) -> LawState:
    """``trial`` with the points ``keep`` (n,) bool taken from ``committed`` instead (their
    history frozen, e.g. interface points that lost their partner).

    Raises:
        TypeError: the states are not :func:`is_pointwise` or not of one type.
    """
    if type(trial) is not type(committed) or not is_pointwise(trial) \
            or not is_pointwise(committed):
        raise TypeError(f"law states of type {type(trial).__name__} / "
                        f"{type(committed).__name__} cannot be frozen point by point (a "
                        "dataclass of batch-first ndarray fields, both of one type, is needed)")
    keep = np.asarray(keep, dtype=bool)
    out = trial.copy()
    for f in dataclasses.fields(out):
        getattr(out, f.name)[keep] = getattr(committed, f.name)[keep]
    return out
