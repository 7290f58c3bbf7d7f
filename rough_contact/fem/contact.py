"""The contact interface: a pairing, a jump operator, a law, an enforcement and one history,
driven by an explicit increment lifecycle.

DOLFINx 0.5.2 has no external operators and cannot evaluate quadrature coefficients on facets,
so the interface terms R_c = int B^T t dA and dR_c/du = int B^T D B dA are assembled by hand
(``docs/design.md``). The pieces, each replaceable on its own:

* **pairing** (:mod:`rough_contact.fem.pairing`): the interface points on the first surface,
  their weights, local frames and partners (conforming, projection, mortar, rigid);
* **jump operator** (:class:`~rough_contact.fem.jump.JumpOperator`): u -> jump, its transpose,
  the sparsity pattern;
* **law** (:class:`~rough_contact.interface.contract.InterfaceLawProtocol`): traction, tangent
  and trial state at all points of a rank in one call;
* **enforcement** (:mod:`rough_contact.interface.enforcement`): the law as it is (penalty) or
  with exact constraints by multipliers (augmented Lagrangian);
* **history** (:class:`~rough_contact.interface.state.InterfaceHistory`): law state,
  multipliers and pairing in one object.

Lifecycle (every call collective; ``docs/design.md`` draws it)::

    begin_increment(u)   once per increment: a sliding pairing re-pairs on the committed state
                         (moderate sliding; large sliding after a revert or a restart)
    predict(ratio)       per attempt: the multipliers' secant predictor (no-op without them)
    evaluate(u)          the law at a trial displacement -> LawResult; always runs the law
    assemble_residual(b) / assemble_jacobian(A)   from the last evaluation
    accept(u)            a converged iterate: evaluate there; large sliding pairs again there
                         and, if the pairing moved, installs it -> Acceptance(done=False,
                         repaired=True, rebuild=...); else the enforcement may update its
                         multipliers -> Acceptance(done=...): solve again unless done
    commit()             the increment is converged: trial -> committed
    revert()             the increment failed: back to the committed state

Conventions (``rough_contact.interface.contract``): n is the unit normal of the first surface
pointing towards the second body, x the grain direction projected on the facet, y = n x x;
jump = [g, s_x, s_y] of u_second - u_first (g > 0 opens). Rigid obstacle (``second_tag=None``):
u_second = 0, the gap and normal from ``rigid`` / ``rigid_plane`` (or the tangent plane).

Failures: a non-finite jump, traction or tangent and a law's ConvergenceError raise
``ConvergenceError`` on every rank (the load stepping cuts back); any other exception of the
law propagates with its type on the failing rank and as a ``RuntimeError`` naming it on the
others (:func:`rough_contact.fem.collective.raise_on_all_ranks`).

Units: mm, N, MPa.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem import compat
from rough_contact.fem.collective import raise_on_all_ranks
from rough_contact.fem.interface_setup import (RigidPlane, check_arguments, check_result,
                                               initial_law_state, pair_auto, select_pairing,
                                               warn_overconstrained)
from rough_contact.fem.jump import JumpOperator
from rough_contact.fingerprint import describe
from rough_contact.fem.pairing import Pairing, SlidingPairing, SurfaceContext
from rough_contact.fem.pairing.base import Repaired
from rough_contact.fem.pairing.facets import (FacetGeometry, FacetRule, facet_connectivity,
                                              owned_tagged_facets)
from rough_contact.fem.queries import InterfaceQueries, InterfaceSummary, PointFields
from rough_contact.fem.rigid import RigidSurface
from rough_contact.interface.contract import (ConvergenceError, InterfaceLawProtocol, LawResult,
                                              NewtonTangentLaw, SoftenableLaw)
from rough_contact.interface.enforcement import AugmentedLagrangian, Enforcement, Penalty
from rough_contact.interface.state import InterfaceHistory, keep_points
from rough_contact.validation import check_integer, check_scalar

__all__ = ["ContactInterface", "InterfaceSummary", "PointFields", "Acceptance"]


@dataclass(frozen=True)
class Acceptance:
    """What :meth:`ContactInterface.accept` decided about a converged iterate.

    Attributes:
        done: the increment can be committed (False: the multipliers were updated, or the
            pairing moved (large sliding): solve again).
        change: the largest multiplier change relative to the largest traction [-] (0 for a
            penalty enforcement); after a re-pairing, how far the pairing moved relative to the
            largest facet diameter of the first surface [-].
        repaired: the pairing was updated on the converged iterate (large sliding).
        rebuild: the new pairing needs matrix entries the current pattern lacks (the problem
            rebuilds its matrices before solving again).
    """

    done: bool
    change: float = 0.0
    repaired: bool = False
    rebuild: bool = False


class ContactInterface(InterfaceQueries):
    """Interface operator between two tagged surfaces (or one surface and a rigid body).

    Args:
        V: vector Lagrange space of degree 1 or 2 (P1/P2 tetrahedra, Q1/Q2 hexahedra) on the
            mesh holding both bodies.
        facet_tags: MeshTags on facets.
        first_tag: tag of the first contact surface (its normal defines the local axes).
        second_tag: tag of the second surface, or None for a rigid obstacle.
        law: the interface law (``initial_state(n)``, ``evaluate(jump, committed)``).
        rigid_plane: for ``second_tag=None``: (point (3,), unit normal (3,) pointing towards the
            first body) [mm]; None = a plane tangent to the first surface at every point.
        rigid: for ``second_tag=None``: any rigid counter-surface
            (:class:`rough_contact.fem.rigid.RigidSurface`), gap and normal linearised at set-up.
        grain_direction: (3,) global direction projected on the facet to give the local x axis.
        quadrature_degree: degree (integer >= 0) of the facet Gauss rule.
        quadrature: ``"gauss"`` or ``"vertex"`` (the facet's vertices with equal weights, P1/Q1
            only: one point, one constraint per surface node; docs/solver.md).
        bcs: Dirichlet conditions whose DOFs the interface must not touch.
        match_tolerance: conforming vertex matching tolerance relative to the facet size, > 0.
        pairing: ``"auto"`` (conforming if every facet finds its match, else projection),
            ``"conforming"``, ``"projection"`` (Gauss points projected along the normal: cheap,
            fails the patch test on non-nested meshes), ``"mortar"`` (segment-to-segment:
            passes the patch test on non-matching meshes; Gauss rule only), or any
            :class:`~rough_contact.fem.pairing.Pairing` object, e.g.
            ``AutoPairing(second_tag, "mortar")`` (conforming, else mortar).
        search_radius: projection/mortar: largest accepted normal distance to a partner [mm].
        sliding: ``"small"`` (partners found once, a rigid gap linearised at set-up),
            ``"moderate"`` (the pairing redone on the deformed configuration at the start of
            every increment: ``begin_increment``) or ``"large"`` (moreover redone on every
            converged iterate until it stops moving: a fixed point per increment, see
            ``docs/sliding.md``). Moderate and large: the projection pairing, or a rigid
            surface (gap and normal of x + u); a point without partner is inactive.
        rigid_motion: for a rigid counter-surface: its translation [mm] (3,) as a function of
            the load factor (``ContactProblem.set_load_factor`` passes it on; the surface given
            is where the translation is zero); None: fixed.
        sliding_tolerance: large sliding: the pairing has converged when no partner point (or
            closest point) moved, and no gap changed, by more than this fraction of the
            largest facet diameter of the first surface, > 0.
        max_repairs: large sliding: re-pairings per increment (>= 1) before the increment
            counts as failed (cutback).
        enforcement: :class:`~rough_contact.interface.enforcement.Penalty` (default: the law
            as it is) or :class:`~rough_contact.interface.enforcement.AugmentedLagrangian`.

    Attributes:
        history: law state, multipliers and pairing (``InterfaceHistory``).
        paired: the pairing's points; operator: the jump operator.
        pairing_used: ``"conforming"``, ``"projection"``, ``"mortar"`` or ``"rigid"``.
        n_points: this rank's point slots (the length of every per-point array; the mortar
            pairing's weight-0 slot-filling copies included).
        n_points_global: global number of interface points, without those copies (what
            ``summary().n_points`` and the increments count).
        n_slots_global: global number of point slots, copies included (the law is evaluated
            at every slot; equal to n_points_global except for the mortar pairing).
        n_facets, n_qp, n_groups, n_remote_partners, n_repairs.

    Raises:
        TypeError: ``law`` does not satisfy the protocol, or the enforcement cannot use it.
        LawContractError: ``law.initial_state`` returns no valid ``LawState``.
        ValueError: unknown/empty tags, unsupported spaces, surfaces that do not match.
    """

    def __init__(self, V, facet_tags, first_tag: int, second_tag: Optional[int] = None, *,
                 law: InterfaceLawProtocol, rigid_plane: Optional[RigidPlane] = None,
                 rigid: Optional[RigidSurface] = None,
                 grain_direction: Sequence[float] = (1.0, 0.0, 0.0),
                 quadrature_degree: int = 2, quadrature: str = "gauss", bcs: Sequence = (),
                 match_tolerance: float = 1e-6, pairing: Union[str, Pairing] = "auto",
                 search_radius: Optional[float] = None, sliding: str = "small",
                 enforcement: Optional[Enforcement] = None,
                 rigid_motion: Optional[Callable[[float], Sequence[float]]] = None,
                 sliding_tolerance: float = 1e-10, max_repairs: int = 20):
        self.comm, self.V, self.law = V.mesh.comm, V, law
        self.enforcement = Penalty() if enforcement is None else enforcement
        if not isinstance(self.enforcement, Enforcement):
            raise TypeError(f"enforcement ({type(enforcement).__name__}) must be a "
                            "rough_contact.interface.enforcement.Enforcement (Penalty or "
                            "AugmentedLagrangian)")
        chosen = select_pairing(V, pairing, second_tag, rigid, rigid_plane, search_radius,
                                sliding, match_tolerance, quadrature)
        grain, degree = check_arguments(V, law, first_tag, second_tag, rigid_plane,
                                        quadrature_degree, grain_direction, quadrature)
        self.enforcement.check_law(law)
        self.first_tag, self.second_tag, self.sliding = first_tag, second_tag, sliding
        self.sliding_tolerance = check_scalar("sliding_tolerance", sliding_tolerance, lo=0.0)
        self.max_repairs = check_integer("max_repairs", max_repairs, lo=1)
        if rigid_motion is not None and not callable(rigid_motion):
            raise TypeError(f"rigid_motion ({type(rigid_motion).__name__}) must be a callable "
                            "load factor -> translation (3,) [mm]")
        if rigid_motion is not None and second_tag is not None:
            raise ValueError("rigid_motion moves a rigid counter-surface: give it with rigid "
                             f"or rigid_plane, not with second_tag = {second_tag!r}")
        self.rigid_motion = rigid_motion
        self._translation = np.zeros(3)
        self.set_load_factor(0.0)             # the surface where the motion starts it
        self.grain_direction = tuple(float(g) for g in grain)
        self.quadrature, self.quadrature_degree = quadrature, degree
        n_owned = facet_connectivity(V.mesh)
        rule = FacetRule.create(V.mesh, degree, vertex=quadrature == "vertex")
        if quadrature == "gauss" and self._constraints_per_point:
            warn_overconstrained(self.enforcement, rule.nq, V.mesh.topology.cell_type,
                                 compat.element_degree(V), degree)
        geo1 = FacetGeometry(V, owned_tagged_facets(facet_tags, first_tag, n_owned, self.comm))
        ctx = SurfaceContext(V, self.comm, facet_tags, first_tag, n_owned, geo1, rule, degree,
                             grain)
        if chosen == "auto":
            self.pairing, self.paired = pair_auto(ctx, second_tag, match_tolerance,
                                                  search_radius)
        else:
            self.pairing, self.paired = chosen, chosen.pair(ctx)
        self.pairing_used = self.paired.name
        self.n_repairs, self._needs_repair, self._matrix_keys = 0, False, set()
        self.n_fixed_point = 0       # large sliding: re-pairings on converged iterates, in all
        vx1 = ctx.geo1.vertex_x
        diam = (np.linalg.norm(vx1[:, :, None] - vx1[:, None], axis=-1).max(initial=0.0)
                if vx1.shape[0] else 0.0)
        self._length = self.comm.allreduce(float(diam), op=MPI.MAX)
        self._active = np.ones(self.paired.n_points, dtype=bool)
        self._anchor = self._start = None
        self._dirichlet = (None, list(bcs))
        self._set_operator(self._point_set(ctx, bcs))
        if (isinstance(self.enforcement, AugmentedLagrangian)
                and self.enforcement.reference_spacing is not None
                and self.point_spacing is None):
            raise ValueError(
                f"enforcement {self.enforcement.name} with reference_spacing = "
                f"{self.enforcement.reference_spacing!r} mm scales the penalty with each "
                "point's spacing, which only the nodal point set knows: use "
                "rough_contact.fem.nodal.NodalContactInterface, or reference_spacing=None")
        n = self.n_points
        self.history = InterfaceHistory(initial_law_state(law, n, self.comm),
                                        self.enforcement.initial_multipliers(n))
        self._last = self._last_jump = self._newton_memo = None
        self._result_checked = False  # the first evaluation's result is checked in full
        self._softened = None         # (factor, law.softened(factor)) during a continuation

    # the law is evaluated at the pairing's points (a subclass may aggregate them: the nodal
    # point set of rough_contact.fem.nodal, whose constraints are not per quadrature point)
    _constraints_per_point = True

    def _point_set(self, ctx: SurfaceContext, bcs: Sequence) -> JumpOperator:
        """The jump operator at the points the law is evaluated at (collective); here the
        pairing's points themselves (``self.paired``)."""
        return JumpOperator(ctx.V, self.paired, bcs=bcs)

    @property
    def point_spacing(self) -> Optional[np.ndarray]:
        """(n_pts,) each point's spacing [mm] where the point set defines one (the nodal
        set's ``NodalPoints.spacing``), else None (quadrature points: a rule's points are not
        spaced as the mesh is). Passed to the enforcement (``Enforcement.law_for``)."""
        return None

    def _set_operator(self, operator: JumpOperator, jump0: Optional[np.ndarray] = None):
        self.operator = operator
        if jump0 is None:
            jump0 = self.paired.jump0.copy()
            jump0[:, 0] += operator.gap0
        self._jump0 = jump0
        self.n_points = operator.n_points
        self.n_points_global, self.n_slots_global = self.comm.allreduce(
            np.array([int(operator.own_slot.sum()), self.n_points]), op=MPI.SUM).tolist()
        self.n_facets, self.n_qp = self.paired.facets.size, self.paired.n_qp
        self.n_groups, self.n_remote_partners = operator.n_groups, operator.n_remote_partners

    # ------------------------------------------------------------------ matrices, DOFs
    def create_matrix(self, a) -> PETSc.Mat:
        """A PETSc matrix with the pattern of the bilinear form ``a`` plus the interface blocks
        (collective); dolfinx assembles ``a`` into it unchanged."""
        if self.keys is not None:     # the (first facet, partner facet) blocks it holds
            self._matrix_keys = {tuple(k) for k in self.keys.tolist()}
        return self.operator.create_matrix(a)

    @property
    def keys(self) -> Optional[np.ndarray]:
        return self.operator.keys if isinstance(self.pairing, SlidingPairing) else None

    def set_dirichlet_dofs(self, global_dofs=None, bcs: Sequence = ()) -> None:
        """Mark DOFs the interface must not assemble into (collective; see JumpOperator)."""
        self._dirichlet = (global_dofs, list(bcs))   # re-applied after a re-pairing
        self.operator.set_dirichlet_dofs(global_dofs, bcs)

    def jump(self, u) -> np.ndarray:
        """Local jump [g, s_x, s_y] (n_pts, 3) [mm] at displacement u (Function or PETSc Vec)."""
        return self._raw(u, self._translation) + self._jump0

    def _raw(self, u, translation: np.ndarray) -> np.ndarray:
        """B u, plus the rigid counter-surface's translation seen in the local frames (it is
        the second surface's displacement) [mm]."""
        x = u if isinstance(u, PETSc.Vec) else compat.petsc_vector(u)
        raw = self.operator.apply(self.operator.pair_values(x))
        if self.paired.partners is None and np.any(translation != 0.0):
            raw = raw + np.einsum("pai,i->pa", self.paired.frames, translation)
        return raw

    def set_load_factor(self, lam: float) -> None:
        """Move a rigid counter-surface to ``rigid_motion(lam)`` (no communication; no-op
        without a motion). ``ContactProblem.set_load_factor`` calls it."""
        if self.rigid_motion is None:
            return
        d = np.asarray(self.rigid_motion(float(lam)), dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)):
            raise ValueError(f"rigid_motion({float(lam)!r}) = {d.tolist()!r} is invalid: it "
                             "must be 3 finite numbers (a translation in mm)")
        self._translation = d

    @property
    def translation(self) -> np.ndarray:
        """(3,) current translation of a rigid counter-surface [mm] (zero without motion)."""
        return self._translation.copy()

    # ------------------------------------------------------------------ lifecycle
    def evaluate(self, u) -> LawResult:
        """The law at displacement u (Function or PETSc Vec), on all points (collective). The
        trial state and dissipation increment go to the history; the result is what the
        assembly and the queries use until the next evaluation, commit or revert.

        Raises:
            ConvergenceError: on every rank, if any rank met a non-finite jump, traction or
                tangent, or a ConvergenceError of the law.
            LawContractError: the first result breaks the contract (naming the field).
        """
        jump = self.jump(u)
        law = self._evaluating_law()
        res, error = None, None
        try:
            self._check_finite("jump", jump, np.isfinite(jump).all(axis=1))
            res = law.evaluate(jump, self.history.law.committed)
            if not self._result_checked:
                check_result(self.law, res, self.n_points)
            finite = (np.isfinite(res.traction).all(axis=1)
                      & np.isfinite(res.tangent).all(axis=(1, 2)))
            self._check_finite("traction/tangent returned by the law", jump, finite)
        except Exception as exc:  # noqa: BLE001 - re-raised on every rank just below
            error = exc
        raise_on_all_ranks(self.comm, error)
        self._result_checked = True
        if not self._active.all():
            res = self._without_inactive(res)
        self.history.law.update(res)
        self._last, self._last_jump = res, jump
        return res

    def _without_inactive(self, res: LawResult) -> LawResult:
        """``res`` with the points without partner made inactive: zero traction, tangent and
        dissipation, not in contact, their history frozen at the committed state."""
        off = ~self._active
        traction, tangent = res.traction.copy(), res.tangent.copy()
        traction[off], tangent[off] = 0.0, 0.0

        def zero(a, value):
            if a is None:
                return None
            a = a.copy()
            a[off] = value
            return a

        return replace(res, traction=traction, tangent=tangent,
                       state=keep_points(res.state, self.history.law.committed, off),
                       dissipation=zero(res.dissipation, 0.0),
                       area_fraction=zero(res.area_fraction, 0.0),
                       contact=zero(res.contact, False), slipping=zero(res.slipping, False),
                       beyond_validity=zero(res.beyond_validity, False),
                       normal_dissipation=zero(res.normal_dissipation, 0.0))

    @property
    def active(self) -> np.ndarray:
        """(n_pts,) bool: the point has a partner (False: it slid off the second surface or
        separated beyond the search radius; zero traction) (read-only)."""
        a = self._active.view()
        a.flags.writeable = False
        return a

    def _evaluating_law(self) -> InterfaceLawProtocol:
        law = self.law if self._softened is None else self._softened[1]
        return self.enforcement.law_for(law, self.history.multipliers, self.point_spacing)

    @property
    def softenable(self) -> bool:
        """Whether the law can be softened (``SoftenableLaw``: Newton's penalty continuation)."""
        return isinstance(self.law, SoftenableLaw)

    @property
    def softening(self) -> float:
        """The factor the law's penalty is divided by in the evaluations (1: the law itself)."""
        return 1.0 if self._softened is None else self._softened[0]

    def set_softening(self, factor: float) -> None:
        """Evaluate ``law.softened(factor)`` instead of the law until set back to 1 (no
        communication; the committed history is shared, the trial state is the last
        evaluation's). ``SNESSolver`` does this for a penalty continuation.

        Raises:
            TypeError: factor > 1 for a law that is not a ``SoftenableLaw``.
            ValueError: factor < 1 or not finite.
        """
        factor = check_scalar("softening factor", factor, lo=1.0, lo_open=False)
        if factor == 1.0:
            self._softened = None
        else:
            if not self.softenable:
                raise TypeError(f"the law {type(self.law).__name__} cannot be softened for a "
                                "penalty continuation (it is no rough_contact.interface."
                                "contract.SoftenableLaw: softened(factor))")
            if self._softened is None or self._softened[0] != factor:
                self._softened = (factor, self.law.softened(factor))
        self._forget()

    def _check_finite(self, what: str, jump: np.ndarray, finite: np.ndarray) -> None:
        if finite.all():
            return
        bad = np.flatnonzero(~finite)
        raise ConvergenceError(
            f"non-finite {what} at {bad.size} of {self.n_points} interface points of rank "
            f"{self.comm.rank}, e.g. at x = {self.paired.x[bad[0]].tolist()} mm "
            f"(jump {jump[bad[0]].tolist()} mm)")

    def assemble_residual(self, b: PETSc.Vec) -> None:
        """Add int B^T t dA of the last evaluation to b and assemble b (collective)."""
        res = self._result()
        self.operator.add_transpose(res.traction * self.paired.weights[:, None], b)
        b.assemblyBegin()
        b.assemblyEnd()

    def assemble_jacobian(self, A: PETSc.Mat) -> None:
        """Add int B^T D B dA of the last evaluation to A (collective; flushes A first, the
        caller calls ``A.assemble()``). A law with a Newton-step tangent
        (``NewtonTangentLaw``) gives it here."""
        res = self._result()
        tangent, law = res.tangent, self._evaluating_law()
        if isinstance(law, NewtonTangentLaw) and self.operator.n_groups:
            tangent, self._newton_memo = law.newton_tangent(
                self._last_jump, self.history.law.committed, res, self._newton_memo)
        self.operator.add_congruence(tangent * self.paired.weights[:, None, None], A)

    def begin_solve(self) -> None:
        """Forget the previous Newton solve's tangent memo (the SNES wrapper calls it)."""
        self._newton_memo = None

    def begin_increment(self, u) -> bool:
        """Start an increment at the committed displacement u (collective): a sliding pairing
        pairs again on the committed configuration (after the previous increment was reported
        and checkpointed). Returns True when the matrix pattern must be rebuilt
        (``ContactProblem.begin_increment`` does it)."""
        if not isinstance(self.pairing, SlidingPairing):
            return False
        x = compat.petsc_vector(u)
        # what the re-pairings of this increment start from (the committed configuration)
        self._start = (self.jump(u), x.copy(), self._translation.copy(), self._active.copy(),
                       np.array(self.history.law.committed.plastic_slip))
        if not self._needs_repair:
            return False
        self._needs_repair = False
        return self._install(self._repair(u), u)

    def _repair(self, u) -> Repaired:
        return self.pairing.repair(compat.function_values(u).reshape(-1, 3), self.paired,
                                   self._translation)

    def _install(self, rep: Repaired, u) -> bool:
        """Use the pairing ``rep`` found at displacement u (collective). The jump offsets: the
        tangential jump is continuous at the committed configuration (the elastic slip carried
        over; a point that arrives starts with none: s = s_p there), the normal gap is the
        re-pairing's (exact at u); a point without partner keeps its committed jump, unused.
        Returns True when the matrix pattern must be rebuilt."""
        jump_c, x_c, d_c, active_c, slip_c = self._start
        changed = self._use(rep)
        raw_c = self._raw(x_c, d_c)
        raw_k = self._raw(u, self._translation)
        jump0 = np.empty_like(raw_c)
        jump0[:, 1:] = jump_c[:, 1:] - raw_c[:, 1:]
        arriving = rep.active & ~active_c
        jump0[arriving, 1:] = slip_c[arriving] - raw_c[arriving, 1:]
        jump0[:, 0] = rep.gap - raw_k[:, 0]
        jump0[~rep.active] = jump_c[~rep.active]
        self._jump0 = jump0
        self._anchor = rep.anchor
        self.history.pairing = (self.pairing.state(), jump0.copy(), rep.active.copy(),
                                None if rep.anchor is None else rep.anchor.copy())
        return changed

    def _use(self, rep: Repaired) -> bool:
        """Rebuild the jump operator on the pairing ``rep`` (zero offsets; collective).
        Returns True when the matrix pattern must be rebuilt."""
        partners = rep.partners
        if partners is not None:
            before = self.paired.partners.facet.reshape(-1)
            moved = int(np.any(partners.facet.reshape(-1) != before))
        else:
            moved = int(rep.frames is not None and not np.array_equal(rep.frames,
                                                                       self.paired.frames))
        moved = self.comm.allreduce(moved, op=MPI.SUM)
        frames = self.paired.frames if rep.frames is None else rep.frames
        self.paired = replace(self.paired, partners=partners, frames=frames)
        self._active = np.asarray(rep.active, dtype=bool).copy()
        on_operator = self.paired
        if not self._active.all():           # points without partner: B = 0
            n_f, nq = self.paired.N1.shape[:2]
            N1 = self.paired.N1 * self._active.reshape(n_f, nq)[..., None]
            on_operator = replace(self.paired, N1=N1)
        global_dofs, bcs = self._dirichlet
        self._set_operator(JumpOperator(self.V, on_operator, bcs=bcs, global_dofs=global_dofs),
                           jump0=np.zeros((self.n_points, 3)))
        self._last = None
        self.n_repairs += bool(moved)
        if self.keys is None:                # a rigid surface: blocks are the facets
            return False
        # the pattern follows the current blocks exactly (not their history): a resumed run
        # assembles into the same pattern as the uninterrupted one, bit for bit
        changed = {tuple(k) for k in self.keys.tolist()} != self._matrix_keys
        return bool(self.comm.allreduce(changed, op=MPI.LOR))

    def _follow(self, u) -> Optional[Acceptance]:
        """Large sliding: pair again at the converged iterate u (collective). None if the
        pairing did not move (the same points active, no partner point and no gap moved by
        more than ``sliding_tolerance`` x the largest facet diameter); else the new pairing is
        installed and the increment must be solved again."""
        rep = self._repair(u)
        act = rep.active
        moved = np.zeros(2)
        moved[0] = float(np.any(act != self._active))
        if act.any():
            gap_now = self._last_jump[act, 0]
            shift = np.abs(rep.gap[act] - gap_now).max()
            if self._anchor is not None:
                shift = max(shift, np.linalg.norm(rep.anchor[act] - self._anchor[act],
                                                  axis=1).max())
            else:
                shift = np.inf
            moved[1] = shift
        self.comm.Allreduce(MPI.IN_PLACE, moved, op=MPI.MAX)
        rel = moved[1] / self._length if self._length > 0 else moved[1]
        if moved[0] == 0.0 and rel <= self.sliding_tolerance:
            return None
        rebuild = self._install(rep, u)
        self.n_fixed_point += 1
        self._forget()
        return Acceptance(False, float(rel), repaired=True, rebuild=rebuild)

    def predict(self, ratio: float) -> bool:
        """Secant predictor of the multipliers, lambda_n + ratio (lambda_n - lambda_{n-1})
        (no communication; :meth:`revert` undoes it). Returns whether anything was done."""
        h = self.history
        if not isinstance(self.enforcement, AugmentedLagrangian) or h.multipliers_before is None:
            return False
        h.set_multipliers(self.enforcement.extrapolate(h.multipliers, h.multipliers_before,
                                                       float(ratio)))
        self._forget()
        return True

    def accept(self, u) -> Acceptance:
        """A converged iterate (collective): the law is evaluated at u, then an enforcement
        with multipliers proposes new ones; if they moved by more than its tolerance (largest
        change over all points and ranks / largest traction magnitude), they replace the
        committed ones and the increment must be solved again (``done`` False)."""
        res = self.evaluate(u)
        if self.sliding == "large":
            moved = self._follow(u)
            if moved is not None:
                return moved
        if not isinstance(self.enforcement, AugmentedLagrangian):
            return Acceptance(True)
        update = self.enforcement.update(self.history.multipliers, res)
        top = np.zeros(2)
        if update.change.size:
            top[:] = update.change.max(), np.linalg.norm(res.traction, axis=1).max()
        self.comm.Allreduce(MPI.IN_PLACE, top, op=MPI.MAX)
        rel = top[0] / top[1] if top[1] > 0.0 else 0.0
        if rel <= self.enforcement.tolerance:      # the commit starts the next increment
            self.history.propose_multipliers(update.multipliers)   # from the tractions
            return Acceptance(True, rel)
        self.history.set_multipliers(update.multipliers)
        self._forget()
        return Acceptance(False, rel)

    def commit(self) -> None:
        """Accept the trial state of the last evaluation (after :meth:`accept` said done)."""
        self.history.commit()
        # moderate sliding pairs again at the next increment's start; large sliding ends every
        # increment on a converged pairing, which the next one starts from
        self._needs_repair = self.sliding != "large"
        self._newton_memo = None

    def revert(self) -> None:
        """Back to the committed state (failed increment, before a cutback)."""
        self.history.revert()
        self._forget()
        if self.sliding == "large":         # the next attempt pairs on the committed state
            self._needs_repair = True

    def _forget(self) -> None:
        self._last = None
        self._newton_memo = None

    # ------------------------------------------------------------------ checkpoints
    def describe(self) -> dict:
        """What defines this interface, as canonical plain data (``rough_contact.fingerprint``):
        the law's parameters, the pairing (its options, the surfaces, the grain direction), the
        quadrature rule and the enforcement; equal on every rank and for every rank count."""
        return dict(
            law=describe(self.law, "law"),
            pairing=dict(describe(self.pairing, "pairing"), used=self.pairing_used,
                         first_tag=int(self.first_tag), sliding=self.sliding,
                         second_tag=None if self.second_tag is None else int(self.second_tag),
                         grain_direction=describe(self.grain_direction)),
            quadrature=dict(rule=self.quadrature, degree=int(self.quadrature_degree),
                            points_per_facet=int(self.n_qp)),
            enforcement=describe(self.enforcement, "enforcement"))

    def state(self) -> dict:
        """The interface's committed history (one picklable object for checkpoints)."""
        return self.history.state()

    def restore(self, state: dict) -> bool:
        """Reinstate :meth:`state` (collective). Returns True when the matrices must be rebuilt
        (a sliding pairing's partners changed)."""
        self.history.restore(state)
        self._forget()
        if not isinstance(self.pairing, SlidingPairing):
            return False
        # moderate: the next increment re-pairs on the restored state; large: the restored
        # pairing is the converged one the interrupted run went on with
        self._needs_repair = self.sliding != "large"
        if state["pairing"] is None:
            return False
        pairing_state, jump0 = state["pairing"][:2]
        rep = self.pairing.restore(pairing_state)
        if rep is None:
            return False
        if len(state["pairing"]) > 2:          # (..., active points, anchor points)
            rep = replace(rep, active=np.array(state["pairing"][2], dtype=bool))
        self._use(rep)
        self._jump0 = np.array(jump0)
        self._anchor = None if len(state["pairing"]) < 4 else np.array(state["pairing"][3])
        return True
