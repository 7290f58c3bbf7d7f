"""Incremental loading with commit / revert and automatic cutback.

Units: load factors are dimensionless (external loads = factor x nominal loads); forces in N,
dissipation in N mm (= mJ).

:func:`load_path` is a generator: it yields an :class:`Increment` after every converged step
(including the intermediate steps of a cutback), after the interface history has been committed,
so a caller can write output and stop at any time with every converged increment kept::

    for inc in load_path(problem, solver, load_unload_factors(16)):
        writer.write(inc)

A step that fails to CONVERGE is reverted (displacement and interface history back to the
last committed state) and retried with half the increment, down to ``min_increment``; then a
:class:`LoadStepError` names the load factor that could not be reached. Convergence failures
are exactly: SNES diverged (negative converged reason, e.g. DIVERGED_LINEAR_SOLVE when the
factorisation fails, DIVERGED_MAX_IT, a line-search failure), a non-finite residual norm, and a
:class:`~rough_contact.interface.contract.ConvergenceError` (a law's local Newton such as the
friction return map, a non-finite jump, traction or tangent), which the interface raises on
every rank together. Any other exception (bad input, a programming error, a ``PETSc.Error``)
propagates at once with its type and traceback: no cutback, no LoadStepError.

A failed step whose applied tangential force exceeds what friction can carry (mu_max of a
``FrictionBoundedLaw`` times the normal force: the applied one, or the one the interface carried
at the last converged increment if larger, as under a prescribed normal displacement) raises
:class:`FrictionCapacityError` (a ``LoadStepError``) at once instead of cutting back: the body
slides (``friction_check``).

Guards before and after each solve:

* the starting displacement must be finite: a NaN/inf initial guess is refused (``ValueError``
  with the count and the first owned DOF) before the first solve instead of ending in a
  cutback spiral; load factors must be finite (and the loads are checked where they are made);
* model validity: after every converged step the interface points where the law is evaluated
  outside its model's range (``LawResult.beyond_validity``: for the statistical normal law, a
  separation below its lowest tabulated one, i.e. a real-area fraction above the model's limit,
  where a stiff continuation stands in for the model) are counted. ``validity="warn"`` (default)
  issues a :class:`ModelValidityWarning` per such increment, ``"error"`` raises
  :class:`ModelValidityError` (the increment is committed but not yielded), ``"ignore"`` only
  records the count in :attr:`Increment.n_beyond_validity`.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Iterable, Iterator, Optional, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.problem import ContactProblem
from rough_contact.interface.contract import ConvergenceError, FrictionBoundedLaw
from rough_contact.solver.checkpoint import (CheckpointState, ResumableOutput, read_checkpoint,
                                             write_checkpoint)
from rough_contact.solver.checkpoint import signature as checkpoint_signature
from rough_contact.solver.snes import SNESSolver, SolveResult
from rough_contact.validation import check_integer, check_scalar

__all__ = ["Increment", "LoadStepError", "FrictionCapacityError", "ModelValidityError",
           "ModelValidityWarning", "load_path", "load_unload_factors"]

VALIDITY_POLICIES = ("warn", "error", "ignore")
PREDICTORS = ("secant", "none")


class ModelValidityWarning(UserWarning):
    """A converged increment has interface points outside the law's range of validity."""


class ModelValidityError(RuntimeError):
    """Raised by ``load_path(..., validity="error")`` when a converged increment has interface
    points outside the law's range of validity (that increment is committed).

    Attributes:
        load_factor: the load factor of the offending (committed) increment.
        n_beyond: number of points outside the validity range; n_points: all points.
    """

    def __init__(self, message: str, load_factor: float, n_beyond: int, n_points: int):
        super().__init__(message)
        self.load_factor = load_factor
        self.n_beyond = n_beyond
        self.n_points = n_points


class LoadStepError(RuntimeError):
    """Raised when a load step cannot converge even with the minimum increment (chained from
    the last ConvergenceError, if that was the cause).

    Attributes:
        load_factor: the load factor that could not be reached.
        last_converged: the last converged load factor (its state is committed).
    """

    def __init__(self, message: str, load_factor: float, last_converged: float):
        super().__init__(message)
        self.load_factor = load_factor
        self.last_converged = last_converged


class FrictionCapacityError(LoadStepError):
    """Raised instead of a cutback when the tangential load demanded by the failing step exceeds
    what friction can carry, mu_max times the normal load: the body slides and no smaller
    increment reaches the target.

    Attributes (besides LoadStepError's): tangential, capacity [N].
    """

    def __init__(self, message, load_factor, last_converged, tangential, capacity):
        super().__init__(message, load_factor, last_converged)
        self.tangential = tangential
        self.capacity = capacity


@dataclass
class Increment:
    """Summary of one converged load step (global figures, identical on every rank).

    Attributes:
        step: 1-based count of converged steps.
        load_factor: load factor reached [-].
        target: the load factor of the load path this step heads for [-].
        iterations: Newton iterations of the attempt that converged.
        residual: final residual norm [N].
        residuals: residual norm history of the Newton iterations [N].
        n_points: interface quadrature points (0 without interface).
        n_active: points in contact (p > 0).
        n_slipping: points in contact that slip (the friction limit active).
        applied_force: total external force vector at this load factor (3,) [N].
        contact_force: total interface force on the FIRST body (3,) [N] (zeros if unknown).
        real_area: real contact area [mm^2] (nan if unknown).
        dissipation: cumulative frictional dissipation [N mm] (nan if unknown).
        normal_dissipation: cumulative normal hysteresis energy of a normal law with memory
            [N mm] (0 for a reversible law, nan if unknown); ``normal_dissipation_step`` is
            this step's part.
        cutbacks: halvings done before this step converged.
        newton_total: Newton iterations spent since the previous converged step: this one's
            plus those of every failed attempt in between (cutbacks).
        linear_iterations: Krylov iterations of the attempt that converged (1 per Newton
            iteration for a direct solver).
        linear_total: Krylov iterations spent since the previous converged step, failed
            attempts included.
        failed_attempts: attempts of the step that failed since the previous converged step.
        augmentations: multiplier updates of an augmented-Lagrangian law in the attempt that
            converged (each followed by a Newton solve; ``iterations`` and
            ``linear_iterations`` sum over all solves of the attempt); 0 for other laws.
        wall_time: seconds spent on this step (including failed attempts).
        linear_solver: KSP+PC used.
        n_beyond_validity: interface points outside the law's range of validity (see the
            module: ``LawResult.beyond_validity``).
    """

    step: int
    load_factor: float
    target: float
    iterations: int
    residual: float
    residuals: list = field(default_factory=list)
    n_points: int = 0
    n_active: int = 0
    n_slipping: int = 0
    applied_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    contact_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    real_area: float = float("nan")
    dissipation: float = float("nan")
    cutbacks: int = 0
    wall_time: float = 0.0
    linear_solver: str = ""
    n_beyond_validity: int = 0
    newton_total: int = 0
    linear_iterations: int = 0
    linear_total: int = 0
    failed_attempts: int = 0
    augmentations: int = 0
    normal_dissipation: float = float("nan")
    normal_dissipation_step: float = float("nan")


def load_unload_factors(n_load: int, n_unload: Optional[int] = None,
                        final_factor: Optional[float] = None) -> list:
    """Load factors 1/n, 2/n, ..., 1 then back down in ``n_unload`` equal steps.

    Args:
        n_load: number of loading increments (>= 1).
        n_unload: number of unloading increments (default ``n_load - 1``; 0 = no unloading).
        final_factor: load factor at the end of unloading (default ``1/n_load``: a body held
            only by contact cannot be unloaded to exactly zero force).

    Returns:
        List of load factors.
    """
    check_integer("n_load", n_load, lo=1)
    up = [(i + 1) / n_load for i in range(n_load)]
    if n_unload is None:
        n_unload = n_load - 1
    check_integer("n_unload", n_unload, lo=0)
    final = 1.0 / n_load if final_factor is None else check_scalar(
        "final_factor", final_factor, lo=0.0, lo_open=False, hi=1.0)
    down = [1.0 - (1.0 - final) * (i + 1) / n_unload for i in range(n_unload)]
    return up + down


def _print_increment(inc: Increment) -> None:
    f = inc.contact_force
    PETSc.Sys.Print(
        f"  step {inc.step:3d}  load {inc.load_factor:8.5f}  Newton {inc.iterations:2d}  "
        + (f"(spent {inc.newton_total}, {inc.failed_attempts} failed) "
           if inc.failed_attempts else "")
        + (f"(AL updates {inc.augmentations}) " if inc.augmentations else "")
        + f"lin {inc.linear_iterations}"
        + (f" (spent {inc.linear_total})" if inc.failed_attempts else "")
        + "  "
        f"|F| {inc.residual:9.3e}  active {inc.n_active:6d}/{inc.n_points:<6d} "
        f"slip {inc.n_slipping:6d}  contact force ({f[0]: .4g}, {f[1]: .4g}, {f[2]: .4g}) N"
        + (f"  cutbacks {inc.cutbacks}" if inc.cutbacks else "")
        + (f"  BEYOND VALIDITY {inc.n_beyond_validity}" if inc.n_beyond_validity else "")
        + f"  [{inc.wall_time:.2f} s]"
    )


def load_path(problem: ContactProblem, solver: SNESSolver, factors: Iterable[float], *,
              min_increment: float = 1e-4, max_growth: float = 2.0,
              verbose: bool = True, validity: str = "warn",
              predictor: str = "secant", friction_check: bool = True,
              checkpoint: Optional[str] = None,
              resume: Optional[str] = None,
              outputs: Sequence[ResumableOutput] = (),
              max_steps: Optional[int] = None) -> Iterator[Increment]:
    """Follow ``factors`` with Newton solves; yield after each converged, committed step.

    Args:
        problem: :class:`~rough_contact.fem.problem.ContactProblem` (its ``u`` and interface
            carry the state; they start from the currently committed state).
        solver: :class:`~rough_contact.solver.snes.SNESSolver` of ``problem``.
        factors: load factors to reach in order (loading and unloading alike), finite.
        min_increment: smallest load-factor increment tried in a cutback (> 0).
        max_growth: after a cutback, a converged sub-step lets the next one grow by this
            factor (>= 1) until the target is reached.
        verbose: print one line per converged step with ``PETSc.Sys.Print``.
        validity: what to do when a converged step has interface points outside the law's
            range of validity: ``"warn"`` (a :class:`ModelValidityWarning`), ``"error"`` (raise
            :class:`ModelValidityError`) or ``"ignore"`` (count only).
        predictor: initial guess of each Newton solve. ``"secant"`` (default) extrapolates
            linearly in the load factor from the last two converged states,
            u0 = u_n + (lam - lam_n) / (lam_n - lam_{n-1}) (u_n - u_{n-1}), while the load keeps
            its direction; for the first step, at a load reversal and on a hold (no channel
            scale and no rigid translation changes) it starts from u_n (retracing the loading
            path would put every slipping point of a frictional interface on the wrong side of
            its cone; extrapolating a hold moved a held slider's friction force by the Newton
            tolerance of a far guess). ``"none"`` always starts from u_n. The
            interface history is the committed one either way: the converged result does not
            depend on the choice (to the Newton tolerance), the iteration count does
            (docs/coulomb.md: -67 % / -52 % on the Coulomb punch at mu = 0.2 / 0.5, -19 % on
            the rough punch). With an augmented-Lagrangian enforcement the multipliers are
            extrapolated the same way (``ContactInterface.predict``; the
            converged result does not depend on it, to the multiplier tolerance; 267 -> 86
            Newton iterations on the mu = 0.5 punch).

        friction_check: when a step fails to converge and the law bounds friction
            (``FrictionBoundedLaw``), compare the tangential part of the applied surface force
            (relative to the first surface's mean normal) with mu_max times the normal force:
            the larger of the applied normal force and the normal force the interface carried
            at the last converged increment (a normal load by prescribed displacement applies
            no force but is carried); if it is larger, raise :class:`FrictionCapacityError`
            instead of cutting back (the body slides). Turn it off for a body that other
            supports hold tangentially.
        checkpoint: directory receiving a checkpoint after every converged increment
            (``rough_contact.solver.checkpoint``: atomic, two alternating slots). The
            checkpoint of an increment is written when the caller asks for the next one (after
            its loop body, e.g. the output of the increment; the last one when the loop ends).
        resume: directory of a checkpoint to continue from: the problem (built afresh, same
            mesh, ranks and law) gets its displacement, interface history and load factor, and
            the stepping continues where the checkpointed run stopped (same ``factors``).
        outputs: writers (:class:`~rough_contact.solver.checkpoint.ResumableOutput`, e.g.
            ``ResultWriter``) whose state every checkpoint saves and a resume restores, so
            their files continue; build them with ``resume=True`` when resuming.
        max_steps: stop after this many converged increments of this call, the last one's
            checkpoint written (a planned stop, e.g. a batch job's time limit; continue with
            ``resume``). A caller that leaves the loop with ``break`` instead skips the
            checkpoint of the increment it broke at.

    Yields:
        :class:`Increment` per converged step.

    Raises:
        LoadStepError: a step failed to converge with an increment below ``min_increment``.
        ValueError: a non-finite starting displacement or load factor, a bad option.
        ModelValidityError: with ``validity="error"``, see above.
        Exception: anything that is not a convergence failure, unchanged (see the module).
    """
    check_scalar("min_increment", min_increment, lo=0.0)
    check_scalar("max_growth", max_growth, lo=1.0, lo_open=False)
    if predictor not in PREDICTORS:
        raise ValueError(f"predictor = {predictor!r} is invalid: it must be one of "
                         f"{', '.join(PREDICTORS)}")
    if validity not in VALIDITY_POLICIES:
        raise ValueError(f"validity = {validity!r} is invalid: it must be one of "
                         f"{', '.join(VALIDITY_POLICIES)}")
    if max_steps is not None:
        check_integer("max_steps", max_steps, lo=1)
    stepper = _Stepper(problem, solver, list(factors), min_increment=min_increment,
                       max_growth=max_growth, verbose=verbose, validity=validity,
                       predictor=predictor, friction_check=friction_check)
    yield from stepper.run(checkpoint=checkpoint, resume=resume, outputs=outputs,
                           max_steps=max_steps)


class _Stepper:
    """The state of one load path: the committed and previous converged states, the counters
    of the current step; :meth:`run` is the generator behind :func:`load_path`.

    Each attempt follows the interface lifecycle (``ContactInterface``): begin_increment,
    predict, Newton solve(s) with ``accept`` after each converged one, then commit or revert.
    """

    def __init__(self, problem, solver, factors, *, min_increment, max_growth, verbose,
                 validity, predictor, friction_check):
        self.problem, self.solver, self.factors = problem, solver, factors
        self.comm, self.interface = problem.comm, problem.interface
        self.min_increment, self.max_growth = min_increment, max_growth
        self.verbose, self.validity = verbose, validity
        self.predictor, self.friction_check = predictor, friction_check
        self.u_committed = self.lam_committed = None     # set by run (after a resume)
        self.u_previous, self.lam_previous = None, None  # the converged state before u_committed
        self.step = 0
        self.spent = [0, 0, 0]  # Newton its, linear its, failed attempts since the last step
        self.carried = None     # (3,) interface force of the last converged increment [N]
        self.normal_dissipated = 0.0   # committed normal hysteresis [N mm] at the last step

    def run(self, *, checkpoint, resume, outputs, max_steps) -> Iterator[Increment]:
        problem = self.problem
        restored = None
        if resume is not None:
            restored = read_checkpoint(resume, problem, self.factors, outputs)
        sig = None if checkpoint is None else checkpoint_signature(problem, self.factors)
        _check_initial_guess(problem)
        self.u_committed = problem.solution_vector().copy()
        self.lam_committed = problem.load_factor
        start_index = 0
        if restored is not None:
            self.step, start_index = restored.step, restored.index
            self.lam_previous = restored.lam_previous
            if restored.u_previous is not None:
                self.u_previous = self.u_committed.duplicate()
                self.u_previous.setArray(restored.u_previous)
        if self.interface is not None:   # the baseline of Increment.normal_dissipation_step
            self.normal_dissipated = self.interface.normal_dissipation()
        done = 0
        for i, target in enumerate(self.factors):
            if i < start_index:
                continue
            target = check_scalar(f"load factor {i} of the load path", target)
            delta, cutbacks = target - self.lam_committed, 0
            if restored is not None and i == restored.index:
                delta, cutbacks = restored.delta, restored.cutbacks
            t_start = time.perf_counter()
            while abs(target - self.lam_committed) > 1e-14 * max(1.0, abs(target)):
                if abs(delta) > abs(target - self.lam_committed):
                    delta = target - self.lam_committed
                lam = self.lam_committed + delta
                ok, result, failure, updates = self._attempt(lam)
                if not ok:
                    delta, cutbacks = self._failed(lam, target, result, failure, delta,
                                                   cutbacks)
                    continue
                inc, saved = self._converged(lam, target, i, result, updates, delta, cutbacks,
                                             time.perf_counter() - t_start, checkpoint)
                yield inc
                if checkpoint is not None:
                    write_checkpoint(checkpoint, problem, saved, sig, outputs)
                done += 1
                if max_steps is not None and done >= max_steps:
                    return
                t_start = time.perf_counter()
                if cutbacks:
                    delta *= self.max_growth

    def _attempt(self, lam: float):
        """One attempt at load factor ``lam``: start the increment, predict, solve."""
        problem, interface = self.problem, self.interface
        problem.begin_increment()       # a sliding pairing re-pairs on the committed state
        held = _loads(problem)
        problem.set_load_factor(lam)
        lam_n, lam_p = self.lam_committed, self.lam_previous
        reference = None
        # a hold (no channel and no rigid motion changes) starts from the committed state
        if (self.predictor == "secant" and self.u_previous is not None
                and (lam - lam_n) * (lam_n - lam_p) > 0.0 and _loads(problem) != held):
            # the Newton tolerance refers at most to the residual at u_n under the new load, so
            # the predictor changes the iteration count, not the accuracy of the result
            reference = self.u_committed
            # u0 = u_n + r (u_n - u_{n-1}), r = (lam - lam_n) / (lam_n - lam_{n-1})
            r = (lam - lam_n) / (lam_n - lam_p)
            u = problem.solution_vector()
            self.u_committed.copy(u)
            u.axpy(r, self.u_committed)
            u.axpy(-r, self.u_previous)
            problem.scatter_solution()
            if interface is not None:      # the multipliers of an augmented enforcement too
                interface.predict(r)
        ok, result, failure, updates = _solve_step(problem, self.solver, self.comm, reference)
        self.spent[0] += result.iterations
        self.spent[1] += result.linear_iterations
        return ok, result, failure, updates

    def _converged(self, lam, target, index, result, updates, delta, cutbacks, wall, checkpoint):
        """Commit the converged attempt; the Increment and the checkpoint state to write."""
        problem, interface = self.problem, self.interface
        if interface is not None:
            interface.commit()
        if self.predictor == "secant":
            if self.u_previous is None:
                self.u_previous = self.u_committed.duplicate()
            self.u_committed.copy(self.u_previous)
            self.lam_previous = self.lam_committed
        problem.solution_vector().copy(self.u_committed)
        self.lam_committed = lam
        self.step += 1
        inc = Increment(
            step=self.step, load_factor=lam, target=target, iterations=result.iterations,
            residual=result.residuals[-1] if result.residuals else float("nan"),
            residuals=list(result.residuals), applied_force=problem.current_applied_force(),
            cutbacks=cutbacks, wall_time=wall, linear_solver=self.solver.linear_solver,
            newton_total=self.spent[0], linear_iterations=result.linear_iterations,
            linear_total=self.spent[1], failed_attempts=self.spent[2], augmentations=updates)
        self.spent = [0, 0, 0]
        if interface is not None:
            s = interface.summary()
            inc.n_points, inc.n_active, inc.n_slipping = s.n_points, s.n_contact, s.n_slipping
            inc.contact_force, inc.real_area = s.contact_force, s.real_area
            inc.dissipation = s.dissipation
            inc.n_beyond_validity = s.n_beyond_validity
            self.carried = np.array(s.contact_force, dtype=float)
            inc.normal_dissipation = s.normal_dissipation
            inc.normal_dissipation_step = s.normal_dissipation - self.normal_dissipated
            self.normal_dissipated = s.normal_dissipation
        saved = None
        if checkpoint is not None:   # written after the caller's loop body
            saved = CheckpointState(
                step=self.step, index=index,
                delta=delta * self.max_growth if cutbacks else delta, cutbacks=cutbacks,
                load_factor=lam, lam_previous=self.lam_previous,
                u_previous=None if self.u_previous is None else self.u_previous.getArray().copy(),
                factors=self.factors)
        if self.verbose:
            _print_increment(inc)
        if inc.n_beyond_validity and self.validity != "ignore":
            _validity_guard(inc, self.validity)
        return inc, saved

    def _failed(self, lam, target, result, failure, delta, cutbacks):
        """Revert a failed attempt and halve the increment (or give up with a LoadStepError)."""
        problem, interface = self.problem, self.interface
        f_failed = problem.current_applied_force()     # the load the failed step asked for
        self.spent[2] += 1
        self.u_committed.copy(problem.solution_vector())
        problem.scatter_solution()
        problem.set_load_factor(self.lam_committed)
        if interface is not None:
            interface.revert()
        if failure is not None:
            why = f"{type(failure).__name__}: {failure}"
        else:
            why = f"{result.reason_name} after {result.iterations} its"
        if self.friction_check and interface is not None and isinstance(interface.law,
                                                                        FrictionBoundedLaw):
            _check_friction_capacity(interface, f_failed, self.carried, lam, target,
                                     self.lam_committed, why)
        delta *= 0.5
        cutbacks += 1
        if abs(delta) < self.min_increment:
            raise LoadStepError(
                f"load step to load factor {lam:.6g} (target {target:.6g}) failed ({why}); "
                f"cutback below the minimum increment {self.min_increment:g}; last converged "
                f"load factor {self.lam_committed:.6g} is committed", lam,
                self.lam_committed) from failure
        if self.verbose:
            PETSc.Sys.Print(f"  load {lam:.6g} failed ({why}): cutback to increment "
                            f"{delta:.4g}")
        return delta, cutbacks


def _loads(problem) -> tuple:
    """What the load factor sets: every channel's scale and a rigid counter-surface's
    translation (equal tuples: the same loads)."""
    scales = tuple(sorted(problem.scales.items()))
    interface = problem.interface
    return scales + (() if interface is None else tuple(interface.translation.tolist()))


def _check_friction_capacity(interface, f, carried, lam, target, lam_committed, why) -> None:
    """Raise FrictionCapacityError if the tangential part of the applied force ``f`` (3,) [N]
    of the failed step exceeds mu_max times the normal force: the larger of the applied one
    (the normal part of ``f``) and the one the interface carried at the last converged increment
    (``carried`` (3,) [N], None before the first one), so that a normal load applied by a
    prescribed displacement (no applied normal force) counts too."""
    mu = float(interface.law.max_friction_coefficient())
    n = interface.mean_normal()
    applied_normal = abs(float(f @ n))
    carried_normal = 0.0 if carried is None else abs(float(carried @ n))
    normal = max(applied_normal, carried_normal)
    tangential = float(np.linalg.norm(f - (f @ n) * n))
    capacity = mu * normal
    if tangential > capacity * (1.0 + 1e-9) + 1e-12 * max(tangential, normal):
        excess = tangential - capacity
        raise FrictionCapacityError(
            f"load step to load factor {lam:.6g} (target {target:.6g}) failed ({why}) and the "
            f"applied tangential force {tangential:.6g} N exceeds what friction can carry, "
            f"mu_max x normal force = {mu:.4g} x {normal:.6g} N = {capacity:.6g} N, by "
            f"{excess:.6g} N ({100 * excess / max(capacity, 1e-300):.3g} %): the body slides, no "
            "smaller increment reaches it. Lower the tangential load, raise the normal load, or "
            "drive the motion by a prescribed displacement; if other supports hold the body "
            f"tangentially, pass friction_check=False. The normal force is the larger of the "
            f"applied one ({applied_normal:.6g} N) and the one the interface carried at the last "
            f"converged increment ({carried_normal:.6g} N). Last converged load factor "
            f"{lam_committed:.6g} is committed", lam, lam_committed, tangential, capacity)


def _check_initial_guess(problem: ContactProblem) -> None:
    """Refuse a non-finite starting displacement on every rank (collective)."""
    x = problem.owned_solution_values()
    bad = np.flatnonzero(~np.isfinite(x))
    n_bad = problem.comm.allreduce(int(bad.size), op=MPI.SUM)
    if n_bad:
        first = problem.comm.allgather(
            None if bad.size == 0 else (problem.comm.rank, int(bad[0]), float(x[bad[0]])))
        rank, dof, value = next(f for f in first if f is not None)
        raise ValueError(
            f"the initial guess (displacement u) has {n_bad} non-finite value(s) (first: {value} "
            f"at local DOF {dof} of rank {rank}); it must be finite: set u before solving "
            "(u.x.array[:] = 0.0 for an unloaded start)")


def _validity_guard(inc: Increment, policy: str) -> None:
    frac = inc.n_beyond_validity / max(inc.n_points, 1)
    msg = (f"load factor {inc.load_factor:.6g}: {inc.n_beyond_validity} of {inc.n_points} "
           f"interface points ({100 * frac:.3g} %) are beyond the interface law's range of "
           "validity (for the statistical normal law: separation below its lowest tabulated "
           "value, i.e. real-area fraction above the model's limit, where a stiff continuation "
           "replaces the rough-surface model); pressures and stiffnesses there are not the "
           "model's. Lower the load, or use a law valid at higher load (e.g. the BEM-calibrated "
           "law, rough_contact.micro.bem)")
    if policy == "error":
        raise ModelValidityError(msg + "; this increment is committed", inc.load_factor,
                                 inc.n_beyond_validity, inc.n_points)
    warnings.warn(msg, ModelValidityWarning, stacklevel=3)


def _solve_step(problem: ContactProblem, solver: SNESSolver, comm: MPI.Comm,
                reference: Optional[PETSc.Vec] = None):
    """Solve one load step: a Newton solve, then ``interface.accept`` at the converged iterate;
    while an enforcement with multipliers updates them (``Acceptance.done`` False), another
    Newton solve from the current iterate. ``reference``: see ``SNESSolver.solve``.

    A large-sliding interface may re-pair at the converged iterate instead (``Acceptance.
    repaired``; the matrices are rebuilt when it asks): another Newton solve, at most
    ``interface.max_repairs`` times.

    Returns:
        (converged, SolveResult with iterations summed over the solves, the failure or None,
        number of multiplier updates). More updates than the enforcement's ``max_updates``
        (or re-pairings than ``max_repairs``) is a failure (a ConvergenceError: the caller
        reverts, which also restores the multipliers, and cuts back).
    """
    interface = problem.interface
    ok, total, failure = _attempt(solver, comm, reference=reference)
    updates = repairs = 0
    while ok and interface is not None:
        acceptance = interface.accept(problem.u)
        if acceptance.done:
            break
        enforcement = interface.enforcement
        if acceptance.rebuild:           # large sliding: the new pairing needs new blocks
            problem.rebuild_matrices()
        if acceptance.repaired:
            repairs += 1
            if repairs > interface.max_repairs:
                failure = ConvergenceError(
                    f"large sliding: the pairing still moved by {acceptance.change:.3g} of the "
                    f"largest facet diameter after {interface.max_repairs} re-pairings "
                    f"(sliding_tolerance {interface.sliding_tolerance:g}); a smaller increment "
                    "moves it less")
                return False, total, failure, updates
        elif updates >= enforcement.max_updates:
            failure = ConvergenceError(
                f"augmented Lagrangian: the multipliers still moved by {acceptance.change:.3g} "
                f"of the largest traction after {updates} updates (augmentation tolerance "
                f"{enforcement.tolerance:g}, max_updates {enforcement.max_updates}); a stiffer "
                "penalty needs fewer updates")
            return False, total, failure, updates
        updates += not acceptance.repaired
        first = total.residuals[0] if total.residuals else 0.0
        if total.reference_norm is not None:
            first = min(first, total.reference_norm)
        ok, result, failure = _attempt(solver, comm, atol=solver.snes.getTolerances()[0] * first)
        total = SolveResult(result.converged, result.reason, result.reason_name,
                            total.iterations + result.iterations,
                            total.residuals + result.residuals,
                            total.linear_iterations + result.linear_iterations,
                            reference_norm=total.reference_norm)
    return ok, total, failure, updates


def _attempt(solver: SNESSolver, comm: MPI.Comm, atol: Optional[float] = None,
             reference: Optional[PETSc.Vec] = None):
    """One Newton solve (``atol``, ``reference``: see ``SNESSolver.solve``). Returns
    ``(converged on every rank, SolveResult or None, the ConvergenceError or None)``; every
    other exception propagates."""
    failure = None
    try:
        kw = {k: v for k, v in (("atol", atol), ("reference", reference)) if v is not None}
        result = solver.solve(**kw)
        ok = result.converged
    except ConvergenceError as exc:
        # raised on every rank together by the interface (rough_contact.fem.collective)
        result, ok, failure = None, False, exc
    ok_all = comm.allreduce(bool(ok), op=MPI.LAND)
    if result is None:  # the work done up to the exception still counts
        result = SolveResult(False, 0, "CONVERGENCE_ERROR", solver.snes.getIterationNumber(),
                             [], solver.snes.getLinearSolveIterations())
    return ok_all, result, failure
