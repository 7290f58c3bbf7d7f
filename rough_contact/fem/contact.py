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
    predict(ratio)       per attempt: the multipliers' secant predictor (no-op without them)
    evaluate(u)          the law at a trial displacement -> LawResult; always runs the law
    assemble_residual(b) / assemble_jacobian(A)   from the last evaluation
    accept(u)            a converged iterate: evaluate there, let the enforcement update its
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
from typing import Optional, Sequence, Union

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
from rough_contact.fem.pairing.facets import (FacetGeometry, FacetRule, facet_connectivity,
                                              owned_tagged_facets)
from rough_contact.fem.queries import InterfaceQueries, InterfaceSummary, PointFields
from rough_contact.fem.rigid import RigidSurface
from rough_contact.interface.contract import (ConvergenceError, InterfaceLawProtocol, LawResult,
                                              NewtonTangentLaw, SoftenableLaw)
from rough_contact.interface.enforcement import AugmentedLagrangian, Enforcement, Penalty
from rough_contact.interface.state import InterfaceHistory
from rough_contact.validation import check_scalar

__all__ = ["ContactInterface", "InterfaceSummary", "PointFields", "Acceptance"]


@dataclass(frozen=True)
class Acceptance:
    """What :meth:`ContactInterface.accept` decided about a converged iterate.

    Attributes:
        done: the increment can be committed (False: the multipliers were updated, solve again).
        change: the largest multiplier change relative to the largest traction [-] (0 for a
            penalty enforcement).
    """

    done: bool
    change: float = 0.0


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
        sliding: ``"small"`` (partners found once) or ``"moderate"`` (the projection redone on
            the deformed surfaces at the start of every increment: ``begin_increment``).
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
                 enforcement: Optional[Enforcement] = None):
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
        self._dirichlet = (None, list(bcs))
        self._set_operator(self._point_set(ctx, bcs))
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
        x = u if isinstance(u, PETSc.Vec) else compat.petsc_vector(u)
        return self.operator.apply(self.operator.pair_values(x)) + self._jump0

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
        self.history.law.update(res)
        self._last, self._last_jump = res, jump
        return res

    def _evaluating_law(self) -> InterfaceLawProtocol:
        law = self.law if self._softened is None else self._softened[1]
        return self.enforcement.law_for(law, self.history.multipliers)

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
        """Start an increment (collective): a sliding pairing projects the points again on the
        committed deformed surfaces (after the previous increment was reported and
        checkpointed). Returns True when the matrix pattern must be rebuilt
        (``ContactProblem.begin_increment`` does it)."""
        if not (self._needs_repair and isinstance(self.pairing, SlidingPairing)):
            return False
        self._needs_repair = False
        jump_old = self.jump(u)
        partners, distance = self.pairing.repair(compat.function_values(u).reshape(-1, 3),
                                                 self.paired)
        changed = self._use_partners(partners)
        raw = self.jump(u) - self._jump0
        jump0 = jump_old - raw                     # tangential jump continuous
        jump0[:, 0] = distance - raw[:, 0]         # normal: the geometric gap now
        self._jump0 = jump0
        self.history.pairing = (self.pairing.state(), jump0.copy())
        return changed

    def _use_partners(self, partners) -> bool:
        before = self.paired.partners.facet.reshape(-1)
        moved = self.comm.allreduce(int(np.any(partners.facet.reshape(-1) != before)),
                                    op=MPI.SUM)
        self.paired = replace(self.paired, partners=partners)
        global_dofs, bcs = self._dirichlet
        self._set_operator(JumpOperator(self.V, self.paired, bcs=bcs, global_dofs=global_dofs),
                           jump0=np.zeros((self.n_points, 3)))
        self._last = None
        self.n_repairs += bool(moved)
        # the pattern follows the current blocks exactly (not their history): a resumed run
        # assembles into the same pattern as the uninterrupted one, bit for bit
        changed = {tuple(k) for k in self.keys.tolist()} != self._matrix_keys
        return bool(self.comm.allreduce(changed, op=MPI.LOR))

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
        self._needs_repair = True
        self._newton_memo = None

    def revert(self) -> None:
        """Back to the committed state (failed increment, before a cutback)."""
        self.history.revert()
        self._forget()

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
        self._needs_repair = True      # the next increment re-pairs on the restored state
        if state["pairing"] is None:
            return False
        pairing_state, jump0 = state["pairing"]
        partners = self.pairing.restore(pairing_state)
        if partners is None:
            return False
        self._use_partners(partners)
        self._jump0 = np.array(jump0)
        return True
