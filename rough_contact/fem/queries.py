"""Read-only queries of an interface's last evaluation: forces, areas, counts, point fields.

:class:`InterfaceQueries` is the query half of
:class:`~rough_contact.fem.contact.ContactInterface` (the lifecycle half lives there). It reads
only what the lifecycle keeps: the points (``paired``: reference coordinates, weights, frames),
the jump operator's slot layout (``operator.own_slot``: the mortar pairing's weight-0 slot
copies are not counted), the last evaluation (``_result()``, ``_last_jump``) and the history.
Every method that returns a global figure is collective.

Units: mm, N, MPa.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.interface.contract import LawResult
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.state import HistoryInterfaceState

__all__ = ["InterfaceQueries", "InterfaceSummary", "PointFields"]


@dataclass(frozen=True)
class InterfaceSummary:
    """Global (all-rank) figures of the interface, identical on every rank.

    Contact, slip, force and areas are those of the last evaluation; the dissipation is the
    committed one (summed over converged increments).

    Attributes:
        n_points: number of interface quadrature points (without the weight-0 copies that
            fill the slots of the mortar pairing).
        n_contact: points with p > 0.
        n_slipping: points in contact where the friction limit is active (a point out of
            contact is open, never counted as slipping, whatever the law reports).
        contact_force: (3,) force on the FIRST body's surface in global axes [N].
        real_area: real contact area int A/A0 dA [mm^2].
        nominal_area: area of the first contact surface [mm^2].
        contact_area: nominal area of the points in contact [mm^2].
        slipping_area: nominal area of the slipping points (in contact) [mm^2].
        max_slip: largest |(s_x, s_y)| [mm].
        max_plastic_slip: largest |plastic slip| of the trial state [mm].
        dissipation: committed accumulated frictional dissipation int D dA [N mm].
        n_beyond_validity: points where the law reports evaluation outside its model's range
            (``LawResult.beyond_validity``; 0 for a law without such a limit).
        normal_dissipation: committed accumulated normal hysteresis energy int D_N dA [N mm]
            of a normal law with memory (``LawResult.normal_dissipation``; 0 for a
            reversible law).
    """

    n_points: int
    n_contact: int
    n_slipping: int
    contact_force: np.ndarray
    real_area: float
    nominal_area: float
    contact_area: float
    slipping_area: float
    max_slip: float
    max_plastic_slip: float
    dissipation: float
    n_beyond_validity: int = 0
    normal_dissipation: float = 0.0


@dataclass(frozen=True)
class PointFields:
    """Local (this rank's) fields at the interface quadrature points, for output.

    Attributes:
        pressure: (n,) p = -t_N [MPa].
        shear: (n, 2) (t_x, t_y) [MPa].
        area_fraction: (n,) A/A0 [-].
        gap: (n,) normal jump g [mm].
        slip: (n, 2) tangential jump (s_x, s_y) [mm].
        plastic_slip: (n, 2) plastic slip of the trial state [mm].
        dissipation: (n,) committed accumulated dissipation per area [N/mm].
        contact: (n,) bool.
        slipping: (n,) bool, in contact and slipping.
        weight: (n,) quadrature weight = area represented by the point [mm^2].
        h_min, max_closure, normal_dissipation: only for a normal law with memory
            (state ``HistoryInterfaceState``), else None: (n,) smallest mean-plane separation
            reached (committed; +inf where virgin) [mm]; h0 - h_min, the largest closure
            reached, which the unloading branch remembers (0 where virgin) [mm]; committed
            accumulated normal hysteresis energy per area [N/mm].
    """

    pressure: np.ndarray
    shear: np.ndarray
    area_fraction: np.ndarray
    gap: np.ndarray
    slip: np.ndarray
    plastic_slip: np.ndarray
    dissipation: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray
    weight: np.ndarray
    h_min: Optional[np.ndarray] = None
    max_closure: Optional[np.ndarray] = None
    normal_dissipation: Optional[np.ndarray] = None


class InterfaceQueries:
    """Queries of the last evaluation (mixed into ContactInterface)."""

    def _result(self) -> LawResult:
        if self._last is None:
            raise ValueError("the interface has not been evaluated since the last commit/revert")
        return self._last

    def contact_force(self) -> np.ndarray:
        """(3,) force on the FIRST body's surface in global axes [N] (collective)."""
        res = self._result()
        f = np.einsum("pai,pa,p->i", self.paired.frames, res.traction, self.paired.weights)
        return self.comm.allreduce(f, op=MPI.SUM)

    def interface_stiffness(self) -> np.ndarray:
        """(3,) the interface's tangent stiffness summed over its area, in local axes
        (normal, x, y): int dt_i/djump_i dA [N/mm] at the last evaluation (collective). For a
        flat joint these are its normal and tangential interface stiffnesses (the bodies'
        compliance not included)."""
        res = self._result()
        k = np.einsum("pii,p->i", res.tangent, self.paired.weights)
        return self.comm.allreduce(k, op=MPI.SUM)

    def real_contact_area(self) -> float:
        """int A/A0 dA over the interface [mm^2] (collective)."""
        res = self._result()
        return self.comm.allreduce(float(np.dot(res.area_fraction, self.paired.weights)),
                                   op=MPI.SUM)

    def nominal_area(self) -> float:
        """Area of the first contact surface [mm^2] (collective)."""
        return self.comm.allreduce(float(self.paired.weights.sum()), op=MPI.SUM)

    def dissipation(self) -> float:
        """Committed accumulated frictional dissipation int D dA [N mm] (collective)."""
        return self.comm.allreduce(float(np.dot(self.history.law.dissipated,
                                                self.paired.weights)), op=MPI.SUM)

    def mean_normal(self) -> np.ndarray:
        """(3,) area-weighted mean unit normal of the first surface (towards the second body),
        global axes (collective)."""
        n = self.comm.allreduce(np.einsum("pi,p->i", self.paired.frames[:, 0, :],
                                          self.paired.weights), op=MPI.SUM)
        norm = np.linalg.norm(n)
        return n / norm if norm > 0 else n

    def n_contact(self) -> int:
        """Global number of points in contact (p > 0) at the last evaluation (collective, one
        allreduce: cheap enough for every Jacobian)."""
        return self.comm.allreduce(int((self._result().contact & self.operator.own_slot).sum()),
                                   op=MPI.SUM)

    def summary(self) -> InterfaceSummary:
        """Global figures after the last evaluation (collective: two allreduces)."""
        res = self._result()
        w = self.paired.weights
        own = self.operator.own_slot  # counts skip the mortar pairing's slot-filling copies
        force = np.einsum("pai,pa,p->i", self.paired.frames, res.traction, w)
        slipping = res.slipping & res.contact   # a point out of contact is open (any law)
        sums = np.concatenate([force, [
            float(np.dot(res.area_fraction, w)), float(w.sum()), float(w[res.contact].sum()),
            float(w[slipping].sum()), float(np.dot(self.history.law.dissipated, w)),
            float((res.contact & own).sum()), float((slipping & own).sum()),
            0.0 if res.beyond_validity is None else float((res.beyond_validity & own).sum()),
            float(own.sum()), float(np.dot(self.history.law.normal_dissipated, w))]])
        sums = self.comm.allreduce(sums, op=MPI.SUM)
        slip = np.linalg.norm(self._last_jump[:, 1:], axis=1)
        plastic = np.linalg.norm(self.history.law.trial.plastic_slip, axis=1)
        maxima = np.array([slip.max(initial=0.0), plastic.max(initial=0.0)])
        self.comm.Allreduce(MPI.IN_PLACE, maxima, op=MPI.MAX)
        return InterfaceSummary(
            n_points=int(sums[11]), n_contact=int(sums[8]), n_slipping=int(sums[9]),
            contact_force=sums[:3], real_area=float(sums[3]), nominal_area=float(sums[4]),
            contact_area=float(sums[5]), slipping_area=float(sums[6]),
            max_slip=float(maxima[0]), max_plastic_slip=float(maxima[1]),
            dissipation=float(sums[7]), n_beyond_validity=int(sums[10]),
            normal_dissipation=float(sums[12]))

    @property
    def facets(self) -> np.ndarray:
        """(n_facets,) local indices of this rank's owned first-surface facets, in point order:
        point i lies on facet ``facets[i // n_qp]`` (read-only)."""
        return _read_only(self.paired.facets)

    def local_frames(self) -> np.ndarray:
        """(n_pts, 3, 3) local axes per point: rows n, x, y in global components (read-only)."""
        return _read_only(self.paired.frames)

    def point_coordinates(self) -> np.ndarray:
        """(n_pts, 3) reference coordinates of this rank's interface points [mm]."""
        return self.paired.x

    def point_weights(self) -> np.ndarray:
        """(n_pts,) area represented by each of this rank's points [mm^2]."""
        return self.paired.weights

    def point_fields(self) -> PointFields:
        """This rank's point fields at the last evaluation (see PointFields)."""
        res = self._result()
        jump = self._last_jump
        return PointFields(
            pressure=-res.traction[:, 0],
            shear=res.traction[:, 1:].copy(),
            area_fraction=np.asarray(res.area_fraction),
            gap=jump[:, 0],
            slip=jump[:, 1:],
            plastic_slip=np.array(self.history.law.trial.plastic_slip, dtype=float),
            dissipation=self.history.law.dissipated.copy(),
            contact=np.asarray(res.contact),
            slipping=np.asarray(res.slipping) & np.asarray(res.contact),
            weight=self.paired.weights,
            **self._memory_fields(),
        )

    def normal_dissipation(self) -> float:
        """Committed accumulated normal hysteresis energy int D_N dA [N mm] (collective; 0 for
        a reversible normal law)."""
        return self.comm.allreduce(float(np.dot(self.history.law.normal_dissipated,
                                                self.paired.weights)), op=MPI.SUM)

    def _memory_fields(self) -> dict:
        """h_min, largest closure and normal dissipation per point (PointFields), empty for a
        law without normal memory."""
        committed = self.history.law.committed
        if not isinstance(committed, HistoryInterfaceState):
            return {}
        h_min = np.array(committed.h_min, dtype=float)
        h0 = self.law.h0 if isinstance(self.law, InterfaceLaw) else None
        closure = (np.zeros_like(h_min) if h0 is None
                   else np.where(np.isfinite(h_min), np.maximum(float(h0) - h_min, 0.0), 0.0))
        return {"h_min": h_min, "max_closure": closure,
                "normal_dissipation": self.history.law.normal_dissipated.copy()}


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view
