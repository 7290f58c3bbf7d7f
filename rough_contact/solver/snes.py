"""PETSc SNES (Newton with line search) for a :class:`rough_contact.fem.problem.ContactProblem`.

Units follow the problem (residuals are nodal forces in N).

All SNES / KSP / PC options live under ONE options prefix (default ``"rc_"``), so anything can
be changed from the command line, e.g. ``-rc_snes_monitor -rc_pc_type gamg -rc_ksp_type cg``.
The solver's defaults are written into PETSc's options database only where the user gave
nothing, and only while PETSc reads them (``setFromOptions`` and the solves); afterwards they
are removed again, so two solvers never see each other's settings
(:mod:`rough_contact.solver.options`, ``docs/design.md`` "PETSc options"):

* Newton with a line search (``newtonls`` + ``bt``), relative tolerance 1e-9, absolute
  tolerance 1e-10 times the norm of the nominal load vector, at most 50 iterations;
* a linear solver from the option sets of :data:`LINEAR_SOLVERS` ("mumps": direct LU;
  "gamg", "hypre": GMRES preconditioned by algebraic multigrid with the six rigid-body modes
  as near-nullspace and 3 x 3 nodal blocks, inexact Newton: linear tolerance 1e-6 of the
  current residual for GAMG, Eisenstat-Walker for hypre),
  chosen by :class:`SNESSolver` from ``-rc_linear_solver``, else ``-rc_pc_type``, else the
  problem size (MUMPS up to :data:`DEFAULT_DOF_THRESHOLD` DOFs, :data:`AMG_DEFAULT` above);
  single options of the set are overridden by the command line one by one. The measurements
  behind these choices are in ``docs/solver.md``.

Penalty continuation (:class:`Continuation`, on by default; ``-rc_continuation none`` turns it
off): a Newton solve of a penalty law that can be softened (``SoftenableLaw``) that has failed
starts again from the same point with the penalty divided by 100, then by 10, and finally
solves the law itself from the last solution (docs/coulomb.md, "Penalty continuation").

Options given but never used (a mistyped ``-rc_snes_monitr``) are reported as a warning by
:meth:`SNESSolver.report_unused_options`, which :meth:`SNESSolver.destroy` calls.

Errors: a diverged Newton (negative converged reason) is returned in :class:`SolveResult`; an
exception raised inside the residual or Jacobian callback (e.g. a
:class:`~rough_contact.interface.contract.ConvergenceError` of the interface) leaves
``snes.solve`` as the very same exception object (petsc4py 3.18 re-raises it) and propagates;
so does a ``PETSc.Error`` (see ``docs/design.md`` "Errors").
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Mapping, Optional, Protocol, Union, runtime_checkable

import numpy as np
from petsc4py import PETSc

from rough_contact.fem.problem import ContactProblem, rigid_body_modes
from rough_contact.interface.contract import ConvergenceError
from rough_contact.solver.options import default_options, set_default_options, unused_options
from rough_contact.validation import check_integer, check_scalar

__all__ = ["SolveResult", "SNESSolver", "UnusedOptionsWarning", "set_default_options",
           "NewtonIterationHook",
           "LINEAR_SOLVERS", "AMG_DEFAULT", "DEFAULT_DOF_THRESHOLD", "Continuation"]


# The option sets (PETSc option names without prefix) and the size rule; the figures behind
# the choices are in docs/solver.md (benchmarks/bench_solver.py).
_KRYLOV = {
    # The frictional tangent is not symmetric: GMRES, not CG. The linear tolerance is a fixed
    # ratio (inexact Newton): 1e-6 of the current residual costs no extra Newton iteration
    # on the punch and 35-40 % fewer Krylov iterations than 1e-10 (docs/solver.md).
    "ksp_type": "gmres",
    "ksp_gmres_restart": 100,
    "ksp_rtol": 1e-6,
    "ksp_max_it": 1000,
    "ksp_norm_type": "unpreconditioned",
    "ksp_pc_side": "right",
}
LINEAR_SOLVERS: dict = {
    # direct LU; this MUMPS build has PORD ordering only
    "mumps": {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"},
    # smoothed-aggregation AMG with the rigid-body near-nullspace, Chebyshev/Jacobi smoothing
    "gamg": {**_KRYLOV,
             "pc_type": "gamg",
             "pc_gamg_type": "agg",
             "pc_gamg_agg_nsmooths": 1,
             "pc_gamg_threshold": 0.01,
             "pc_gamg_square_graph": 1,
             "pc_gamg_coarse_eq_limit": 1000,
             "mg_levels_ksp_type": "chebyshev",
             "mg_levels_pc_type": "jacobi",
             "mg_levels_esteig_ksp_type": "cg"},
    # BoomerAMG for 3D elasticity: strong threshold 0.7, HMIS coarsening with one aggressive
    # level, ext+i interpolation truncated to 4 entries. Nodal coarsening and rigid-body
    # vector interpolation (-rc_pc_hypre_boomeramg_nodal_coarsen 6
    # -rc_pc_hypre_boomeramg_vec_interp_variant 2) cost more than they save here.
    "hypre": {**_KRYLOV,
              "pc_type": "hypre",
              "pc_hypre_type": "boomeramg",
              "pc_hypre_boomeramg_strong_threshold": 0.7,
              "pc_hypre_boomeramg_coarsen_type": "HMIS",
              "pc_hypre_boomeramg_interp_type": "ext+i",
              "pc_hypre_boomeramg_P_max": 4,
              "pc_hypre_boomeramg_agg_nl": 1,
              # Eisenstat-Walker linear tolerances: the solve dominates here, and loose early
              # solves cost 1-2 more Newton iterations per increment but halve the Krylov work
              # (-40 % CPU on the punch); -rc_snes_ksp_ew false: the fixed ratio ksp_rtol
              "snes_ksp_ew": True},
    # the LU factors of one Jacobian kept for 3 Newton iterations, across load steps, with
    # GMRES correcting for the change: half the CPU time of "mumps" at 88 k DOFs, same memory
    "mumps_lagged": {**_KRYLOV, "pc_type": "lu", "pc_factor_mat_solver_type": "mumps",
                     "snes_lag_preconditioner": 3, "snes_lag_preconditioner_persists": True},
    # GMRES with the tolerances above; the preconditioner is whatever -rc_pc_type says
    "krylov": dict(_KRYLOV),
}
#: The AMG set the size rule picks above the threshold (measured, docs/solver.md).
AMG_DEFAULT = "hypre"
#: Global DOF count up to which the size rule keeps MUMPS (measured, docs/solver.md).
DEFAULT_DOF_THRESHOLD = 30_000


@dataclass(frozen=True)
class Continuation:
    """Newton's penalty continuation for stiff penalty laws.

    A stiff penalty k switches a point between stick and slip (or contact and separation)
    within a jump of order traction / k; at k = 1e9 MPa/mm on the Coulomb punch that is 1e-9 mm,
    a tenth of a Newton step, and the line search crawls (docs/coulomb.md). The softened law
    (``SoftenableLaw.softened``: k / factor) has its switches spread over a range wider by the
    factor, its Newton solve converges from the same start, and its solution is a start for the
    next, stiffer one from which Newton converges.

    A solve first runs Newton with the law itself (at most ``after`` iterations; None: the
    solver's ``snes_max_it``); if it has not converged (or the law raised a
    ``ConvergenceError``), it starts again from the same initial iterate with the law softened
    by ``factors[0]``, then ``factors[1]``, ..., each solve starting from the previous one's
    solution, and ends with the law itself; if that fails too, the load stepping cuts back as
    before. Solves that converge within ``after`` iterations are untouched (the same iterates
    as without continuation): with ``after=None`` (the default) every solve that converges
    without the continuation is unchanged, and only the solves that would fail (and cut back)
    are retried. The converged answer is the law's own; only the path of the Newton iterates
    changes.

    Args:
        factors: softening factors (each > 1, strictly decreasing) [-].
        after: Newton iterations (>= 0) with the law itself before the continuation; 0 runs the
            continuation at every solve; None: after a failed solve (``snes_max_it``).
    """

    factors: tuple = (100.0, 10.0)
    after: Optional[int] = None

    def __post_init__(self) -> None:
        f = tuple(float(check_scalar(f"continuation factor {i}", x, lo=1.0))
                  for i, x in enumerate(self.factors))
        if not f or any(b >= a for a, b in zip(f, f[1:])):
            raise ValueError(f"continuation factors = {self.factors!r} are invalid: give at "
                             "least one factor > 1, strictly decreasing (e.g. (100, 10))")
        object.__setattr__(self, "factors", f)
        if self.after is not None:
            check_integer("continuation after", self.after, lo=0,
                          what="Newton iterations with the law itself")


def _parse_continuation(text: str) -> Optional[Continuation]:
    """``-PREFIXcontinuation``: "none" or comma-separated factors ("100,10")."""
    if text.strip().lower() in ("none", "off", "false", "0", ""):
        return None
    try:
        factors = tuple(float(t) for t in text.split(","))
    except ValueError:
        raise ValueError(f"continuation = {text!r} is invalid: give 'none' or comma-separated "
                         "softening factors > 1, decreasing (e.g. 100,10)") from None
    return Continuation(factors)


@runtime_checkable
class NewtonIterationHook(Protocol):
    """An interface that may change its law between Newton iterations (e.g. multipliers
    updated inside the Newton iteration, ``rough_contact.interface.enforcement.
    NewtonAugmentedLagrangian``). :class:`SNESSolver` calls :meth:`newton_iteration` in its
    convergence test, after the residual at Newton iterate ``iteration`` was evaluated; if it
    returns True, the residual is evaluated again at the same iterate with the changed law and
    the solve does not stop there."""

    def updates_in_newton(self) -> bool:
        """Whether :meth:`newton_iteration` may change the law (else the solver ignores the
        hook: its Newton iteration is PETSc's own)."""
        ...

    def newton_iteration(self, iteration: int, residual: float, first: float) -> bool:
        """At Newton iterate ``iteration`` with residual norm ``residual`` [N], ``first`` that
        of the solve's start (collective): True if the law changed."""
        ...


class UnusedOptionsWarning(UserWarning):
    """PETSc options were given under a solver's prefix but never read (mistyped?)."""


@dataclass
class SolveResult:
    """Outcome of one nonlinear solve.

    Attributes:
        converged: SNES reported convergence.
        reason: SNES converged reason (int; negative = diverged).
        reason_name: readable name of ``reason``.
        iterations: Newton iterations (all solves of a continuation).
        residuals: residual 2-norms, one per iteration (iteration 0 first) [N]; with a
            continuation those of every solve, one after the other.
        linear_iterations: total KSP iterations.
        stages: with a continuation, (softening factor, Newton iterations, converged) of each
            solve in order (factor 1: the law itself); empty without.
        reference_norm: |F(reference)| of ``SNESSolver.solve(reference=)`` [N], or None.
    """

    converged: bool
    reason: int
    reason_name: str
    iterations: int
    residuals: list = field(default_factory=list)
    linear_iterations: int = 0
    stages: list = field(default_factory=list)
    reference_norm: Optional[float] = None


def _reason_name(reason: int) -> str:
    for name in dir(PETSc.SNES.ConvergedReason):
        if not name.startswith("_") and getattr(PETSc.SNES.ConvergedReason, name) == reason:
            return name
    return str(reason)


def _choose_linear_solver(cmd, prefix: str, n: int, dof_threshold: Optional[int],
                          linear_solver: str, condensed: bool = False) -> tuple[int, str]:
    """(the DOF threshold, the option set's name): the command line's ``-PREFIXdof_threshold``
    and ``-PREFIXlinear_solver`` override the arguments; ``"auto"`` takes the set of a given
    ``-PREFIXpc_type``, else MUMPS up to the threshold and algebraic multigrid above it.

    ``condensed`` (the semismooth Newton's system, ``ContactProblem.condensed``): its
    constraint rows have no elastic diagonal, which the AMG preconditioners cannot handle
    (measured: hypre's GMRES diverges at the first solve of the punch); ``"auto"`` is MUMPS at
    any size, and an AMG set is refused."""
    if cmd.hasName(prefix + "dof_threshold"):
        dof_threshold = cmd.getInt(prefix + "dof_threshold")
    if dof_threshold is None:
        dof_threshold = DEFAULT_DOF_THRESHOLD
    check_scalar("dof_threshold", dof_threshold, lo=0, lo_open=False)
    if cmd.hasName(prefix + "linear_solver"):
        linear_solver = cmd.getString(prefix + "linear_solver")
    if linear_solver != "auto" and linear_solver not in LINEAR_SOLVERS:
        raise ValueError(f"linear solver = {linear_solver!r} is invalid; valid values: "
                         f"'auto', {', '.join(repr(k) for k in LINEAR_SOLVERS)}")
    if linear_solver == "auto":
        pc_user = (cmd.getString(prefix + "pc_type") if cmd.hasName(prefix + "pc_type")
                   else None)
        if pc_user is not None:
            linear_solver = {"lu": "mumps", "cholesky": "mumps", "gamg": "gamg",
                             "hypre": "hypre"}.get(pc_user, "krylov")
        elif condensed:
            linear_solver = "mumps"
        else:
            linear_solver = "mumps" if n <= int(dof_threshold) else AMG_DEFAULT
    if condensed and linear_solver in ("gamg", "hypre"):
        raise ValueError(f"linear solver = {linear_solver!r} is invalid for the semismooth "
                         "Newton's condensed system (rows of contact constraints without an "
                         "elastic diagonal defeat algebraic multigrid); valid: 'mumps', "
                         "'mumps_lagged', 'krylov' with an LU preconditioner, or 'auto'")
    return int(dof_threshold), linear_solver


class SNESSolver:
    """Newton solver on a :class:`~rough_contact.fem.problem.ContactProblem`.

    The linear solver is one of the option sets of :data:`LINEAR_SOLVERS`, chosen as follows
    (``docs/solver.md``):

    1. ``-<prefix>linear_solver NAME`` on the command line, else the ``linear_solver``
       argument, if it is not ``"auto"``;
    2. else ``-<prefix>pc_type`` on the command line: ``lu``/``cholesky`` pick ``"mumps"``,
       ``gamg`` and ``hypre`` pick their own set, anything else ``"krylov"`` (GMRES with the
       set's tolerances and no preconditioner options);
    3. else by size: ``"mumps"`` up to ``dof_threshold`` global DOFs, :data:`AMG_DEFAULT`
       above.

    Single options of the set are then overridden one by one by the ``defaults`` argument and,
    above it, by the command line (``-rc_ksp_rtol 1e-8`` changes the linear tolerance only).

    Args:
        problem: the problem (its ``F``, ``J``, ``u``, ``A``, ``b``, ``K``, ``f_norm``).
        prefix: PETSc options prefix of the SNES (and its KSP/PC), ending with "_".
        dof_threshold: global DOF count (>= 0) above which the size rule picks the AMG set;
            ``None`` = :data:`DEFAULT_DOF_THRESHOLD` (measured); ``-<prefix>dof_threshold``
            overrides it.
        linear_solver: "auto" or a name of :data:`LINEAR_SOLVERS`.
        near_nullspace: for the AMG sets: "global" (the six rigid-body modes of the whole
            mesh: bodies coupled through the interface share one coarse space), "per_body"
            (six modes per body of ``problem.body_cells``: only for bodies that can float
            free), or a PETSc near-nullspace; ``-<prefix>near_nullspace global|per_body``
            overrides a name.
        defaults: extra default options (without prefix) that override the option set but
            not the command line.
        continuation: :class:`Continuation` for penalty laws that can be softened
            (``SoftenableLaw``; other laws ignore it), or None. The default,
            ``Continuation()``, retries only the solves that failed, so every solve that
            converges without it is unchanged (docs/coulomb.md, "Penalty continuation");
            ``-<prefix>continuation 100,10`` (or ``none``) and
            ``-<prefix>continuation_after N`` override it.
    """

    def __init__(
        self,
        problem: ContactProblem,
        prefix: str = "rc_",
        dof_threshold: Optional[int] = None,
        linear_solver: str = "auto",
        near_nullspace: Union[str, PETSc.NullSpace] = "global",
        defaults: Optional[Mapping[str, object]] = None,
        continuation: Optional[Continuation] = Continuation(),
    ):
        if not isinstance(prefix, str) or (prefix and not prefix.endswith("_")):
            raise ValueError(f"options prefix {prefix!r} must be a string ending with '_'")
        self.problem = problem
        self.prefix = prefix
        comm = problem.comm
        cmd = PETSc.Options()
        self.dof_threshold, linear_solver = _choose_linear_solver(
            cmd, prefix, problem.num_dofs, dof_threshold, linear_solver, problem.condensed)
        self.option_set = linear_solver
        if cmd.hasName(prefix + "continuation"):
            continuation = _parse_continuation(cmd.getString(prefix + "continuation"))
        if continuation is not None and not isinstance(continuation, Continuation):
            raise TypeError(f"continuation must be a Continuation or None, got "
                            f"{type(continuation).__name__}")
        if cmd.hasName(prefix + "continuation_after"):
            after = cmd.getInt(prefix + "continuation_after")
            continuation = Continuation(continuation.factors if continuation else
                                        Continuation().factors, after)
        self.continuation = continuation
        if cmd.hasName(prefix + "near_nullspace"):
            near_nullspace = cmd.getString(prefix + "near_nullspace")
        if isinstance(near_nullspace, str) and near_nullspace not in ("global", "per_body"):
            raise ValueError(f"near_nullspace = {near_nullspace!r} is invalid; valid values: "
                             "'global', 'per_body' or a PETSc.NullSpace")
        opts = {
            "snes_type": "newtonls",
            "snes_linesearch_type": "bt",
            "snes_rtol": 1e-9,
            "snes_atol": max(1e-10 * problem.f_norm, 1e-14),
            "snes_stol": 0.0,
            "snes_max_it": 50,
            "snes_error_if_not_converged": False,
        }
        opts.update(LINEAR_SOLVERS[linear_solver])
        hook = (isinstance(problem.interface, NewtonIterationHook)
                and problem.interface.updates_in_newton())
        if hook:
            # a law changed between iterations (_converged_with_hook) changes the residual the
            # next step starts from; PETSc 3.18's backtracking compares the step with the norm
            # before the change and fails: PETSc takes the full step, the convergence test
            # backtracks with the current norms
            opts["snes_linesearch_type"] = "basic"
        opts.update(defaults or {})
        self.defaults = opts  # without prefix; in the database only inside _options()
        # An absolute tolerance given by the user (command line or ``defaults``) is kept as is;
        # otherwise solve() raises it to the residual's round-off floor (tiny loads).
        self._auto_atol = not cmd.hasName(prefix + "snes_atol") and (
            "snes_atol" not in (defaults or {}))

        if problem.A.getBlockSize() != 3:
            raise ValueError(f"Jacobian block size = {problem.A.getBlockSize()} is invalid: the "
                             "AMG preconditioners need the 3 displacement components per node "
                             "as one block (3)")
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        # Never hand u.vector to SNES: the callbacks copy x into u, and line-search work
        # vectors would overwrite the iterate (docs/design.md, "Stack pitfalls").
        self.x = problem.solution_vector().copy()
        self.snes.setFunction(problem.F, problem.b)
        self.snes.setJacobian(problem.J, problem.A)
        self._A = problem.A        # a re-pairing may replace it (problem.rebuild_matrices)
        with self._options():
            self.snes.setFromOptions()
        self._atol0 = self.snes.getTolerances()[1]
        self._k_norm_inf = problem.K.norm(PETSc.NormType.INFINITY)
        self._set_near_nullspace(near_nullspace)
        self._residuals: list = []
        self._tighten = None
        self._reported_after_first_solve = False
        self.snes.setMonitor(self._monitor)
        if hook:
            self._ttol = self._fnorm0 = self._f_prev = 0.0
            self._x_prev = None
            self.snes.setConvergenceTest(self._converged_with_hook)

    def _converged_with_hook(self, snes, iteration, norms):
        """PETSc's default convergence test (absolute, relative to the first residual, step
        length) for an interface with a :class:`NewtonIterationHook`, with the line search
        done here (PETSc's is ``basic``: a full step, evaluated): the residual norm at the
        full step is compared with the one at the previous iterate as the interface's law then
        was, and the step is halved until |F| <= (1 - 1e-4 theta) |F_previous| (at most
        ``_MAX_BACKTRACKS`` times, else DIVERGED_LINE_SEARCH); the iterate and residual are
        replaced in place. Then the interface may change its law (:meth:`NewtonIterationHook.
        newton_iteration`): the residual is evaluated again at the same iterate and the solve
        does not stop there. The monitor has already printed the full step's norm."""
        xnorm, ynorm, fnorm = (float(v) for v in norms)
        rtol, atol, stol, _ = snes.getTolerances()
        reasons = PETSc.SNES.ConvergedReason
        x, f = snes.getSolution(), snes.getFunction()[0]
        try:
            if iteration == 0:
                self._ttol, self._fnorm0 = fnorm * rtol, fnorm
                self._x_prev = x.copy()
            elif np.isfinite(fnorm) and fnorm > self._f_prev:
                fnorm = self._backtrack(snes, x, f, fnorm)
            if not np.isfinite(fnorm):
                return reasons.DIVERGED_FNORM_NAN
            if iteration > 0 and fnorm > self._f_prev * (1.0 - 1e-12):   # no decrease
                if fnorm < atol:
                    return reasons.CONVERGED_FNORM_ABS
                return (reasons.CONVERGED_FNORM_RELATIVE if fnorm <= self._ttol
                        else reasons.DIVERGED_LINE_SEARCH)
            changed = self.problem.interface.newton_iteration(int(iteration), fnorm,
                                                              self._fnorm0)
            if changed:
                self.problem.F(snes, x, f)
                fnorm = f.norm()
            self._f_prev = fnorm
            x.copy(self._x_prev)
        except Exception as exc:
            self.problem.callback_error = exc
            raise
        if changed:
            return reasons.ITERATING
        if fnorm < atol:
            return reasons.CONVERGED_FNORM_ABS
        if iteration > 0 and fnorm <= self._ttol:
            return reasons.CONVERGED_FNORM_RELATIVE
        if iteration > 0 and ynorm < stol * xnorm:
            return reasons.CONVERGED_SNORM_RELATIVE
        return reasons.ITERATING

    _MAX_BACKTRACKS = 12

    def _backtrack(self, snes, x, f, fnorm: float) -> float:
        """Armijo backtracking on |F| along the full step x - x_prev (in place); the norm
        reached (its first value that decreases enough, or the last tried)."""
        step = x.copy()
        step.axpy(-1.0, self._x_prev)
        theta = 1.0
        try:
            for _ in range(self._MAX_BACKTRACKS):
                if np.isfinite(fnorm) and fnorm <= (1.0 - 1e-4 * theta) * self._f_prev:
                    break
                theta *= 0.5
                self._x_prev.copy(x)
                x.axpy(theta, step)
                self.problem.F(snes, x, f)
                fnorm = f.norm()
        finally:
            step.destroy()
        return fnorm

    def _set_near_nullspace(self, near_nullspace) -> None:
        """Rigid-body modes for the algebraic multigrid preconditioners (else none)."""
        problem = self.problem
        pc_type = self.snes.getKSP().getPC().getType()
        if pc_type in ("gamg", "hypre", "ml") or not isinstance(near_nullspace, str):
            if near_nullspace == "global":
                near_nullspace = rigid_body_modes(problem.V)
            elif near_nullspace == "per_body":
                near_nullspace = rigid_body_modes(problem.V, problem.body_cells)
            problem.A.setNearNullSpace(near_nullspace)
            problem.K.setNearNullSpace(near_nullspace)
            self.near_nullspace = near_nullspace
        else:
            self.near_nullspace = None

    def _options(self):
        """The solver's defaults in the database (where absent) for the duration of a block."""
        return default_options(self.prefix, self.defaults)

    def _monitor(self, snes, its, norm):
        self._residuals.append(float(norm))
        if its == 0 and self._tighten is not None:
            rtol, atol, ref = self._tighten
            if norm < ref:      # the start is better than the reference: today's target
                snes.setTolerances(atol=max(atol, rtol * norm))

    @property
    def linear_solver(self) -> str:
        ksp = self.snes.getKSP()
        pc = ksp.getPC()
        name = f"{ksp.getType()}+{pc.getType()}"
        if pc.getType() == "lu":
            name += f"({pc.getFactorSolverType()})"
        return name

    def solve(self, atol: Optional[float] = None,
              reference: Optional[PETSc.Vec] = None) -> SolveResult:
        """Solve F(u) = 0 starting from ``problem.u``; on success ``problem.u`` holds the root.

        With a :class:`Continuation` and a law that can be softened, a solve that has not
        converged after ``continuation.after`` iterations is done again from the same start
        through the softened laws (see :class:`Continuation`); the result sums the solves.

        On failure ``problem.u`` holds the last iterate: the caller reverts it.

        Args:
            atol: if given, the absolute residual tolerance of this solve is at least this [N]
                (the augmented-Lagrangian re-solves of a load step use the first solve's
                rtol x initial residual: a re-solve starts from a small residual, and its
                own rtol would ask for more accuracy than the step's first solve reached).
            reference: if given, a state (solution vector) whose residual the relative
                tolerance refers to at most: the (full-law) solve stops at
                rtol x min(|F(start)|, |F(reference)|). The load stepping passes the last
                converged state (evaluated under the new load), so that a predicted start with a
                larger residual (a secant extrapolation far beyond the last increment, e.g. 400x
                from the seating step into an exponential law) changes the iteration count, not
                the accuracy. The norm is in ``SolveResult.reference_norm``.

        Raises:
            Exception: whatever a callback raised (the same object, e.g. a ConvergenceError
                of the interface), and ``PETSc.Error`` (not a convergence failure: numerical
                failures of the linear solver come back as a negative converged reason).
        """
        interface = self.problem.interface
        cont = self.continuation
        if cont is None or interface is None or not interface.softenable:
            return self._solve(atol, reference)
        stages, parts = [], []
        if cont.after is None or cont.after > 0:
            u0 = self.problem.solution_vector().copy()
            max_it = self.snes.getTolerances()[3]
            self.snes.setTolerances(max_it=max_it if cont.after is None
                                    else min(cont.after, max_it))
            try:
                first = self._solve(atol, reference)
            except ConvergenceError:
                first = SolveResult(False, 0, "CONVERGENCE_ERROR",
                                    self.snes.getIterationNumber(), [],
                                    self.snes.getLinearSolveIterations())
            finally:
                self.snes.setTolerances(max_it=max_it)
            if first.converged:
                return first
            stages.append((1.0, first.iterations, False))
            parts.append(first)
            u0.copy(self.problem.solution_vector())    # start again from the same point
            self.problem.scatter_solution()
            u0.destroy()
        try:
            for factor in cont.factors:
                interface.set_softening(factor)
                r = self._solve(atol)
                stages.append((factor, r.iterations, r.converged))
                parts.append(r)
                if not r.converged:
                    break
        finally:
            interface.set_softening(1.0)
        if parts[-1].converged:
            r = self._solve(atol, reference)
            stages.append((1.0, r.iterations, r.converged))
            parts.append(r)
        last = parts[-1]
        return SolveResult(last.converged, last.reason, last.reason_name,
                           sum(p.iterations for p in parts),
                           [x for p in parts for x in p.residuals],
                           sum(p.linear_iterations for p in parts), stages,
                           reference_norm=last.reference_norm)

    def _residual_norm(self, x: PETSc.Vec) -> float:
        """|F(x)| under the current load [N] (one residual evaluation; collective). Leaves
        ``problem.u`` at x."""
        b = self.problem.b.duplicate()
        try:
            self.problem.F(self.snes, x, b)
            return float(b.norm())
        finally:
            b.destroy()

    def _solve(self, atol: Optional[float], reference: Optional[PETSc.Vec] = None) -> SolveResult:
        """One Newton solve of the current law (see :meth:`solve`)."""
        self._residuals = []
        if self.problem.A is not self._A:          # new pattern after a re-pairing
            self.snes.setJacobian(self.problem.J, self.problem.A)
            self._A = self.problem.A
        self.problem.solution_vector().copy(self.x)
        ref_norm = None
        if reference is not None:
            ref_norm = self._residual_norm(reference)
            self.problem.update_solution(self.x)   # back at the start
        if self.problem.interface is not None:
            self.problem.interface.begin_solve()   # no Newton-step memory from the last solve
        if self._auto_atol:
            # Round-off floor of F = K u - f: about eps |K|_inf |u|_inf. Below it Newton cannot
            # converge (seen at a total load of 1 mN on the punch, tests/fem/test_extremes.py).
            u_inf = max(self.x.norm(PETSc.NormType.INFINITY), 1e-30)
            floor = 10.0 * np.finfo(float).eps * self._k_norm_inf * u_inf
            self.snes.setTolerances(atol=max(self._atol0, floor))
        atol_before = None
        if atol is not None:
            atol_now = self.snes.getTolerances()[1]
            if atol > atol_now:
                atol_before = atol_now
                self.snes.setTolerances(atol=atol)
        # SNES measures rtol against the residual at the start, which a predicted start may have
        # inflated. With a reference the target is absolute, rtol x |F(reference)|; the monitor
        # tightens it to rtol x |F(start)| at iteration 0 when the start is the smaller (so the
        # target is rtol x min of the two; without evaluating the start twice). PETSc >= 3.19
        # tests iteration 0 before the monitor: a start already within rtol x |F(reference)|
        # is accepted there, as accurate as a solve from the reference would end.
        rtol_before, atol_set = self.snes.getTolerances()[:2]
        self._tighten = None
        if ref_norm is not None and np.isfinite(ref_norm) and ref_norm > 0.0:
            self.snes.setTolerances(rtol=0.0, atol=max(atol_set, rtol_before * ref_norm))
            self._tighten = (rtol_before, atol_set, ref_norm)
        # Some options are read only when the preconditioner is set up, inside the solve.
        self.problem.callback_error = None
        try:
            with self._options():
                self.snes.solve(None, self.x)
        except PETSc.Error:
            # petsc4py >= 3.20 wraps an exception of our callbacks in a PETSc.Error: give the
            # caller the original (a ConvergenceError to cut back on, a user's TypeError, ...)
            if self.problem.callback_error is not None:
                self._fresh_vectors()
                raise self.problem.callback_error from None
            raise
        finally:
            if self._tighten is not None:
                self.snes.setTolerances(rtol=rtol_before, atol=atol_set)
                self._tighten = None
            if atol_before is not None:
                self.snes.setTolerances(atol=atol_before)
        reason = self.snes.getConvergedReason()
        self.problem.update_solution(self.x)
        if not self._reported_after_first_solve:   # a typo shows now, not at the end of a run
            self._reported_after_first_solve = True
            self.report_unused_options()
        res = list(self._residuals)
        ok = reason > 0 and all(np.isfinite(res))
        return SolveResult(ok, int(reason), _reason_name(reason), self.snes.getIterationNumber(),
                           res, self.snes.getLinearSolveIterations(), reference_norm=ref_norm)

    def _fresh_vectors(self) -> None:
        """After a callback's exception petsc4py >= 3.20 leaves the vectors the line search had
        locked read-only locked (petsc4py has no call to unlock them): the SNES drops its work
        vectors and gets a new solution and residual vector."""
        self.snes.reset()
        self.x = self.x.duplicate()
        self.problem.b = self.problem.b.duplicate()
        self.snes.setFunction(self.problem.F, self.problem.b)
        self.snes.setJacobian(self.problem.J, self.problem.A)
        self._A = self.problem.A

    def report_unused_options(self) -> list[str]:
        """Warn (rank 0) about options under this solver's prefix that PETSc never read.

        Called after the first solve (some options are read only then) and by :meth:`destroy`.

        Returns:
            The unused option names (without the dash) on this rank.
        """
        names = unused_options(self.prefix)
        if names and self.problem.comm.rank == 0:
            warnings.warn(
                f"PETSc options given but never used (mistyped, or not applicable to the "
                f"solver {self.linear_solver}): {' '.join('-' + n for n in names)}",
                UnusedOptionsWarning, stacklevel=2)
        return names

    def destroy(self) -> None:
        """Report unused options (see :meth:`report_unused_options`), free the PETSc objects."""
        self.report_unused_options()
        self.snes.destroy()
        self.x.destroy()
