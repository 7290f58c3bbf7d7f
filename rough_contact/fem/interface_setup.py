"""Set-up checks of :class:`~rough_contact.fem.contact.ContactInterface`: arguments, the choice
of pairing from the user's options, the law's virgin state, and the warning for exact
constraints that lock.

Units: mm.
"""

from __future__ import annotations

import warnings
from typing import Optional, Sequence, Tuple, Union

import basix
import numpy as np

import dolfinx
from rough_contact.fem import compat
from rough_contact.fem.collective import raise_on_all_ranks
from rough_contact.fem.pairing import (ConformingPairing, MortarPairing, Pairing,
                                       ProjectionPairing, RigidPairing,
                                       SlidingProjectionPairing)
from rough_contact.fem.pairing.auto import AutoPairing
from rough_contact.fem.pairing.rigid import SlidingRigidPairing
from rough_contact.fem.pairing.facets import CELLS
from rough_contact.fem.rigid import RigidPlane as RigidPlaneSurface
from rough_contact.fem.rigid import RigidSurface
from rough_contact.interface.contract import (InterfaceLawProtocol, LawContractError, LawResult,
                                              LawState)
from rough_contact.interface.enforcement import Enforcement
from rough_contact.validation import check_integer, check_scalar

__all__ = ["check_arguments", "select_pairing", "initial_law_state", "check_result",
           "warn_overconstrained", "RigidPlane"]

RigidPlane = Tuple[Sequence[float], Sequence[float]]  # (point (3,), unit normal (3,)) [mm]
PAIRINGS = ("auto", "conforming", "projection", "mortar")
SLIDING = ("small", "moderate", "large")


def check_arguments(V, law, first_tag, second_tag, rigid_plane, quadrature_degree,
                    grain_direction, quadrature="gauss") -> tuple[np.ndarray, int]:
    """Validate ContactInterface's arguments; return the grain direction (3,) and the degree."""
    missing = [m for m in ("initial_state", "evaluate") if not callable(getattr(law, m, None))]
    if missing or not isinstance(law, InterfaceLawProtocol):
        raise TypeError(
            f"law {type(law).__name__} does not satisfy InterfaceLawProtocol "
            f"(rough_contact.interface.contract): missing method(s) {', '.join(missing)}")
    msh = V.mesh
    if msh.topology.dim != 3 or msh.topology.cell_type not in CELLS:
        raise ValueError(
            "ContactInterface needs a tetrahedral or hexahedral 3D mesh, got "
            f"{msh.topology.cell_type}")
    bs = V.dofmap.index_map_bs
    element = V.element.basix_element
    if bs != 3 or element.degree not in (1, 2) or element.family != basix.ElementFamily.P:
        raise ValueError(
            f"V must be a vector Lagrange space of degree 1 or 2 with 3 components, got "
            f"block size {bs}, degree {element.degree}")
    if V.element.needs_dof_transformations:
        raise ValueError("V needs DOF transformations on facets (degree >= 3): not supported")
    if compat.geometry_degree(msh) not in (1, 2):
        raise ValueError(f"geometry degree {compat.geometry_degree(msh)} not supported (1 or 2)")
    if second_tag is not None and second_tag == first_tag:
        raise ValueError(f"first_tag and second_tag are both {first_tag}")
    if second_tag is not None and rigid_plane is not None:
        raise ValueError("give either second_tag or rigid_plane, not both")
    degree = check_integer("quadrature_degree", quadrature_degree, lo=0)
    if quadrature not in ("gauss", "vertex"):
        raise ValueError(f"quadrature = {quadrature!r} is invalid: it must be 'gauss' or 'vertex'")
    if quadrature == "vertex" and element.degree != 1:
        raise ValueError(f"quadrature = 'vertex' needs a degree-1 space (P1/Q1), got degree "
                         f"{element.degree}: use a Gauss rule for P2/Q2")
    grain = np.asarray(grain_direction, dtype=float)
    if grain.shape != (3,) or not np.all(np.isfinite(grain)) or np.linalg.norm(grain) == 0:
        raise ValueError(f"grain_direction = {grain_direction!r} must be a nonzero 3-vector")
    return grain, int(degree)


def select_pairing(V, pairing: Union[str, Pairing], second_tag: Optional[int],
                   rigid: Optional[RigidSurface], rigid_plane: Optional[RigidPlane],
                   search_radius: Optional[float], sliding: str, match_tolerance: float,
                   quadrature: str) -> Union[Pairing, str]:
    """The pairing object for ContactInterface's options (``"auto"`` is returned as is: it
    tries the conforming pairing and falls back to the projection)."""
    check_scalar("match_tolerance", match_tolerance, lo=0.0)
    if search_radius is not None:
        check_scalar("search_radius", search_radius, lo=0.0, unit="mm")
    if sliding not in SLIDING:
        raise ValueError(f"sliding = {sliding!r} is invalid: it must be 'small', 'moderate' or "
                         "'large'")
    if not isinstance(pairing, str):
        if not isinstance(pairing, Pairing):
            raise TypeError(f"pairing ({type(pairing).__name__}) must be one of {PAIRINGS} or "
                            "a rough_contact.fem.pairing.Pairing (pair(ctx))")
        return pairing
    if pairing not in PAIRINGS:
        raise ValueError(f"pairing = {pairing!r} is invalid: it must be 'auto', "
                         "'conforming', 'projection' or 'mortar'")
    if rigid is not None or rigid_plane is not None or second_tag is None:
        if rigid is not None and rigid_plane is not None:
            raise ValueError("give either rigid or rigid_plane, not both")
        if rigid is not None and second_tag is not None:
            raise ValueError("give either second_tag or rigid, not both")
        if rigid_plane is not None:
            _plane(rigid_plane)                         # validates with its own message
            rigid = RigidPlaneSurface(*rigid_plane)     # normalises once
        if pairing == "mortar":
            raise ValueError("pairing = 'mortar' needs a second surface (second_tag) and "
                             "the Gauss rule (quadrature='gauss')")
        if sliding != "small":
            if rigid is None:
                raise ValueError(
                    f"sliding = {sliding!r} needs a deformable second surface (second_tag) "
                    "and the projection pairing, or a rigid surface (rigid or rigid_plane); "
                    "the tangent plane of a rigid obstacle given by neither cannot slide")
            _same_degree(V, sliding)
            return SlidingRigidPairing(rigid)
        return RigidPairing(rigid)
    if sliding != "small":
        if pairing not in ("auto", "projection"):
            raise ValueError(
                f"sliding = {sliding!r} needs a deformable second surface (second_tag) and "
                f"the projection pairing (pairing 'auto' or 'projection', got {pairing!r}, "
                f"second_tag {second_tag!r})")
        _same_degree(V, sliding)
        return SlidingProjectionPairing(second_tag, search_radius)
    if pairing == "mortar":
        if quadrature != "gauss":
            raise ValueError("pairing = 'mortar' needs a second surface (second_tag) and "
                             "the Gauss rule (quadrature='gauss')")
        return MortarPairing(second_tag, search_radius)
    if pairing == "projection":
        return ProjectionPairing(second_tag, search_radius)
    if pairing == "conforming":
        return ConformingPairing(second_tag, match_tolerance)
    return "auto"


def _same_degree(V, sliding: str) -> None:
    if compat.element_degree(V) != compat.geometry_degree(V.mesh):
        raise ValueError(
            f"sliding = {sliding!r} needs a displacement space of the geometry's degree "
            f"({compat.geometry_degree(V.mesh)}), got {compat.element_degree(V)}")


def pair_auto(ctx, second_tag, match_tolerance, search_radius):
    """``"auto"``: the conforming pairing if every facet finds its match, else the projection
    (collective). Returns (pairing object, paired points)."""
    auto = AutoPairing(second_tag, "projection", match_tolerance, search_radius)
    paired = auto.pair(ctx)
    return auto.chosen, paired


def initial_law_state(law, n: int, comm) -> LawState:
    """The law's virgin state, checked against the LawState contract (collective)."""
    state, error = None, None
    try:
        state = law.initial_state(n)
        if not isinstance(state, LawState):
            raise LawContractError(
                f"{type(law).__name__}.initial_state returned "
                f"{type(state).__name__}, which lacks plastic_slip, copy() or __len__ "
                "(rough_contact.interface.contract.LawState)")
        if len(state) != n or np.shape(state.plastic_slip) != (n, 2):
            raise LawContractError(
                f"{type(law).__name__}.initial_state({n}) holds {len(state)} points "
                f"with plastic_slip of shape {np.shape(state.plastic_slip)}; the contract "
                f"needs {n} and ({n}, 2)")
    except Exception as exc:  # noqa: BLE001 - re-raised on every rank just below
        error = exc
    raise_on_all_ranks(comm, error)
    return state


def check_result(law, res, n: int) -> None:
    """The full contract check of a law's result (done on the first evaluation)."""
    if not isinstance(res, LawResult):
        raise LawContractError(
            f"{type(law).__name__}.evaluate returned {type(res).__name__}; the contract needs "
            "rough_contact.interface.contract.LawResult")
    res.check(n)


# surface nodes per surface facet of a large surface mesh (triangles: V ~ F / 2, E ~ 3F / 2;
# quadrilaterals: V ~ F, E ~ 2F), by (cell type, element degree)
_NODES_PER_FACET = {
    (dolfinx.mesh.CellType.tetrahedron, 1): 0.5, (dolfinx.mesh.CellType.tetrahedron, 2): 2.0,
    (dolfinx.mesh.CellType.hexahedron, 1): 1.0, (dolfinx.mesh.CellType.hexahedron, 2): 4.0,
}


def warn_overconstrained(enforcement: Enforcement, n_points: int, cell_type,
                         element_degree: int, rule_degree: int) -> None:
    """Warn when an enforcement with multipliers would impose its constraints exactly at more
    points per facet than there are surface nodes per facet (they lock: the multiplier
    iteration stalls, docs/coulomb.md)."""
    if enforcement.initial_multipliers(0) is None:
        return
    nodes = _NODES_PER_FACET.get((cell_type, element_degree))
    if nodes is None or n_points <= nodes:
        return
    fix = ("use quadrature='vertex'" if element_degree == 1 else
           f"use a facet rule of at most {int(nodes)} point(s) per facet (quadrature_degree=1 "
           "on triangles), or a P1/Q1 mesh with the vertex rule")
    warnings.warn(
        f"an augmented-Lagrangian enforcement imposes its constraints exactly at every point: "
        f"the Gauss rule of degree {int(rule_degree)} puts {n_points} points on each facet, "
        f"about {n_points / nodes:g} times the surface nodes of a degree-{element_degree} mesh; "
        "the constraints lock and the multiplier iteration may not converge where contact or "
        f"stick ends (docs/coulomb.md); {fix}", UserWarning, stacklevel=3)


def _plane(rigid_plane: RigidPlane) -> tuple[np.ndarray, np.ndarray]:
    try:
        point, normal = rigid_plane
    except (TypeError, ValueError):
        raise ValueError(f"rigid_plane = {rigid_plane!r} must be (point (3,), normal (3,))")
    point = np.asarray(point, dtype=float)
    normal = np.asarray(normal, dtype=float)
    if point.shape != (3,) or normal.shape != (3,) or not np.all(np.isfinite(normal)):
        raise ValueError(f"rigid_plane = {rigid_plane!r} must be (point (3,), normal (3,))")
    nn = np.linalg.norm(normal)
    if nn == 0:
        raise ValueError("rigid_plane normal must be nonzero")
    return point, normal / nn
