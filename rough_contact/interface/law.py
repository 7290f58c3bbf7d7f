"""The composed interface law at quadrature points: (jump, committed state) -> traction, tangent.

Units: mm, N, MPa. Jumps and separations [mm]; tractions and pressures [MPa]; stiffnesses per
nominal area [MPa/mm]; dissipation per nominal area [N/mm].

Contract (``/work/notes/common.md``): local axes (n, x, y) per point, n the unit normal of the
FIRST surface pointing towards the second body, x the grain direction, y = n x x.
``jump`` (n_pts, 3) = [g, s_x, s_y] = local components of u_second - u_first (g > 0 opens).
The mean-plane separation is h = h0 + g. The traction is energy-conjugate to the jump,
t = dpsi/djump: t_N = -p(h) <= 0 and t_T = K_T(h) (s - s_p) limited by friction, with
K_T = diag(c_x, c_y) kN(h). The tangent is D = dt/djump (n_pts, 3, 3), D[:, 0, 0] = kN(h).

Layers: normal law (p, kN, A/A0, dkN/dh) -> tangential stiffness (kT = c kN) -> friction return
map (only at points with p > 0). Open points (p == 0) carry no traction, have zero tangential
tangent rows and keep their history.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Optional, Union

import numpy as np

from .friction import IsotropicSlipHardening, OrthotropicSlipHardening, _Columns, _norm
from .state import InterfaceState
from .tangential import TangentialStiffness

__all__ = ["InterfaceLaw", "LawResult"]

Friction = Union[OrthotropicSlipHardening, IsotropicSlipHardening]


@dataclass(frozen=True)
class LawResult:
    """Outcome of one law evaluation at n points.

    Attributes:
        traction: (n, 3) [t_N, t_x, t_y] [MPa], t_N = -p.
        tangent: (n, 3, 3) consistent (algorithmic) tangent dt/djump [MPa/mm], non-symmetric.
        state: trial InterfaceState (commit it after the global Newton converged).
        dissipation: (n,) increment t_T . Delta s_p >= 0 [N/mm].
        area_fraction: (n,) real-area fraction A/A0 [-].
        contact: (n,) bool, p > 0.
        slipping: (n,) bool, the friction limit is active.
        pressure: (n,) contact pressure p [MPa].
    """

    traction: np.ndarray
    tangent: np.ndarray
    state: InterfaceState
    dissipation: np.ndarray
    area_fraction: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    pressure: np.ndarray


@dataclass(frozen=True)
class InterfaceLaw:
    """Rough-interface law: statistical normal law + Mindlin tangential stiffness + friction.

    Args:
        normal: normal law with ``evaluate(h, curvature=False) -> (p, k, a)`` and
            ``evaluate(h, curvature=True) -> (p, k, a, dk_dh)``, and (for ``with_seating``)
            ``separation_for_pressure(p) -> h`` (``rough_contact.interface.normal.NormalLaw``).
        tangential: tangential stiffness ratios kT/kN (needed when ``friction`` is given).
        friction: ``OrthotropicSlipHardening`` or ``IsotropicSlipHardening``; None means
            frictionless (t_T = 0, no history).
        h0: reference mean-plane separation [mm] at zero gap (h = h0 + g); set it directly or
            with ``with_seating``.
    """

    normal: Any
    tangential: Optional[TangentialStiffness] = None
    friction: Optional[Friction] = None
    h0: Optional[float] = None

    def __post_init__(self) -> None:
        if not callable(getattr(self.normal, "evaluate", None)):
            raise ValueError(f"normal = {self.normal!r} must have an evaluate(h, curvature) method")
        if self.friction is not None:
            if not isinstance(self.friction, (OrthotropicSlipHardening, IsotropicSlipHardening)):
                raise ValueError(f"friction = {self.friction!r} must be an "
                                 "OrthotropicSlipHardening or IsotropicSlipHardening (or None "
                                 "for frictionless)")
            if not isinstance(self.tangential, TangentialStiffness):
                raise ValueError("tangential (a TangentialStiffness) is required when friction is "
                                 f"given, got {self.tangential!r}")
        if self.h0 is not None:
            h0 = float(self.h0)
            if not np.isfinite(h0):
                raise ValueError(f"h0 = {self.h0!r} must be finite [mm]")
            object.__setattr__(self, "h0", h0)

    def with_seating(self, p_seat: float) -> InterfaceLaw:
        """Copy whose h0 solves p(h0) = p_seat [MPa] (zero gap carries the seating pressure)."""
        p = float(p_seat)
        if not (np.isfinite(p) and p > 0.0):
            raise ValueError(f"p_seat = {p_seat!r} must be finite and > 0 [MPa]")
        h0 = float(np.asarray(self.normal.separation_for_pressure(np.array([p]))).reshape(-1)[0])
        return dataclasses.replace(self, h0=h0)

    def initial_state(self, n_pts: int) -> InterfaceState:
        """Virgin history at n_pts points."""
        return InterfaceState.zeros(n_pts)

    def evaluate(self, jump: np.ndarray, committed: InterfaceState) -> LawResult:
        """Traction, consistent tangent and trial state at jump (n, 3) [mm]; never mutates input.

        Raises:
            ValueError: bad shapes, non-finite jumps or h0 not set.
            rough_contact.interface.friction.ReturnMappingError: local Newton failure.
        """
        if self.h0 is None:
            raise ValueError("h0 (reference separation [mm]) is not set: pass h0= or use "
                             "with_seating(p_seat)")
        jump = np.asarray(jump, dtype=float)
        if jump.ndim != 2 or jump.shape[1] != 3:
            raise ValueError(f"jump must have shape (n_pts, 3), got {jump.shape}")
        n = jump.shape[0]
        if not isinstance(committed, InterfaceState) or len(committed) != n:
            got = len(committed) if isinstance(committed, InterfaceState) else type(committed)
            raise ValueError(f"committed state must be an InterfaceState with {n} points, "
                             f"got {got}")
        if not np.isfinite(jump).all():
            bad = np.flatnonzero(~np.isfinite(jump).all(axis=1))
            raise ValueError(f"jump is not finite at {bad.size} of {n} points (first {bad[0]})")

        h = self.h0 + jump[:, 0]
        traction = np.zeros((n, 3))
        tangent = np.zeros((n, 3, 3))  # zero rows 1-2 at open points; row 0 = [k, 0, 0]
        if self.friction is None:
            p, k, a = self.normal.evaluate(h, curvature=False)
        else:
            p, k, a, dk = self.normal.evaluate(h, curvature=True)
        traction[:, 0] = -p
        tangent[:, 0, 0] = k
        contact = p > 0.0
        slipping = np.zeros(n, dtype=bool)
        dissipation = np.zeros(n)
        if self.friction is None or not contact.any():
            return LawResult(traction, tangent, committed.copy(), dissipation, a, contact,
                             slipping, p)

        cx, cy = self.tangential.kt_over_kn
        sp = committed.plastic_slip
        kap = committed.accumulated_slip
        if contact.all():  # work on views: no gather/scatter
            cols = _Columns(jump[:, 1] - sp[:, 0], jump[:, 2] - sp[:, 1], cx * k, cy * k,
                            cx * dk, cy * dk, p, k, kap[:, 0], kap[:, 1], committed.slip_path)
            slip = self.friction._map(cols, traction[:, 1:], tangent[:, 1:, :])
            pts = None if slip is None else slip.idx
        else:
            ic = np.flatnonzero(contact)
            kc, dkc = k.take(ic), dk.take(ic)
            cols = _Columns(jump[ic, 1] - sp[ic, 0], jump[ic, 2] - sp[ic, 1], cx * kc, cy * kc,
                            cx * dkc, cy * dkc, p.take(ic), kc, kap[ic, 0], kap[ic, 1],
                            committed.slip_path.take(ic))
            out_t = np.empty((ic.size, 2))
            out_D = np.empty((ic.size, 2, 3))
            slip = self.friction._map(cols, out_t, out_D)
            traction[ic, 1:] = out_t
            tangent[ic, 1:, :] = out_D
            pts = None if slip is None else ic.take(slip.idx)

        state = committed.copy()
        if slip is not None:
            dspx, dspy = slip.dspx, slip.dspy
            dw = traction[pts, 1] * dspx + traction[pts, 2] * dspy
            state.plastic_slip[pts, 0] += dspx
            state.plastic_slip[pts, 1] += dspy
            state.accumulated_slip[pts, 0] += np.abs(dspx)
            state.accumulated_slip[pts, 1] += np.abs(dspy)
            state.slip_path[pts] += _norm(dspx, dspy)
            state.dissipated[pts] += dw
            dissipation[pts] = dw
            slipping[pts] = True
        return LawResult(traction, tangent, state, dissipation, a, contact, slipping, p)
