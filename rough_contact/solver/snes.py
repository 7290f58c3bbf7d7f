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
* a direct LU factorisation with MUMPS below ``dof_threshold`` global DOFs;
* above it, GMRES (the frictional tangent is not symmetric) preconditioned by GAMG with the
  rigid-body near-nullspace of every body.

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
from typing import Mapping, Optional

import numpy as np
from petsc4py import PETSc

from rough_contact.fem.problem import ContactProblem, rigid_body_modes
from rough_contact.solver.options import default_options, set_default_options, unused_options
from rough_contact.validation import check_scalar

__all__ = ["SolveResult", "SNESSolver", "UnusedOptionsWarning", "set_default_options"]


class UnusedOptionsWarning(UserWarning):
    """PETSc options were given under a solver's prefix but never read (mistyped?)."""


@dataclass
class SolveResult:
    """Outcome of one nonlinear solve.

    Attributes:
        converged: SNES reported convergence.
        reason: SNES converged reason (int; negative = diverged).
        reason_name: readable name of ``reason``.
        iterations: Newton iterations.
        residuals: residual 2-norms, one per iteration (iteration 0 first) [N].
        linear_iterations: total KSP iterations.
    """

    converged: bool
    reason: int
    reason_name: str
    iterations: int
    residuals: list = field(default_factory=list)
    linear_iterations: int = 0


def _reason_name(reason: int) -> str:
    for name in dir(PETSc.SNES.ConvergedReason):
        if not name.startswith("_") and getattr(PETSc.SNES.ConvergedReason, name) == reason:
            return name
    return str(reason)


class SNESSolver:
    """Newton solver on a :class:`~rough_contact.fem.problem.ContactProblem`.

    Args:
        problem: the problem (its ``F``, ``J``, ``u``, ``A``, ``b``, ``K``, ``f_norm``).
        prefix: PETSc options prefix of the SNES (and its KSP/PC), ending with "_".
        dof_threshold: global DOF count (>= 0) above which the default linear solver is
            GMRES+GAMG instead of MUMPS LU.
        near_nullspace: PETSc near-nullspace set on the Jacobian (for GAMG); ``None`` builds the
            rigid body modes of ``problem.V`` when the iterative default is used.
        defaults: extra default options (without prefix) that override the built-in ones but
            not the command line.
    """

    def __init__(
        self,
        problem: ContactProblem,
        prefix: str = "rc_",
        dof_threshold: int = 100_000,
        near_nullspace: Optional[PETSc.NullSpace] = None,
        defaults: Optional[Mapping[str, object]] = None,
    ):
        if not isinstance(prefix, str) or (prefix and not prefix.endswith("_")):
            raise ValueError(f"options prefix {prefix!r} must be a string ending with '_'")
        check_scalar("dof_threshold", dof_threshold, lo=0, lo_open=False)
        self.problem = problem
        self.prefix = prefix
        comm = problem.comm
        n = problem.num_dofs
        direct = n <= dof_threshold
        opts = {
            "snes_type": "newtonls",
            "snes_linesearch_type": "bt",
            "snes_rtol": 1e-9,
            "snes_atol": max(1e-10 * problem.f_norm, 1e-14),
            "snes_stol": 0.0,
            "snes_max_it": 50,
            "snes_error_if_not_converged": False,
        }
        if direct:
            opts.update({
                "ksp_type": "preonly",
                "pc_type": "lu",
                "pc_factor_mat_solver_type": "mumps",
            })
        else:
            opts.update({
                # the frictional tangent is not symmetric: GMRES, not CG
                "ksp_type": "gmres",
                "ksp_gmres_restart": 100,
                "ksp_rtol": 1e-10,
                "ksp_max_it": 1000,
                "pc_type": "gamg",
                "pc_gamg_type": "agg",
                "pc_gamg_agg_nsmooths": 1,
                "pc_gamg_threshold": 0.02,
                "mg_levels_ksp_type": "chebyshev",
                "mg_levels_pc_type": "jacobi",
                "mg_levels_esteig_ksp_type": "cg",
            })
        opts.update(defaults or {})
        self.defaults = opts  # without prefix; in the database only inside _options()
        # An absolute tolerance given by the user (command line or ``defaults``) is kept as is;
        # otherwise solve() raises it to the residual's round-off floor (tiny loads).
        self._auto_atol = not PETSc.Options().hasName(prefix + "snes_atol") and (
            "snes_atol" not in (defaults or {}))

        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        # Never hand u.vector to SNES: the callbacks copy x into u, and line-search work
        # vectors would overwrite the iterate (docs/design.md, "Stack pitfalls").
        self.x = problem.u.vector.copy()
        self.snes.setFunction(problem.F, problem.b)
        self.snes.setJacobian(problem.J, problem.A)
        with self._options():
            self.snes.setFromOptions()
        self._atol0 = self.snes.getTolerances()[1]
        self._k_norm_inf = problem.K.norm(PETSc.NormType.INFINITY)
        pc_type = self.snes.getKSP().getPC().getType()
        if pc_type == "gamg" or near_nullspace is not None:
            if near_nullspace is None:
                near_nullspace = rigid_body_modes(problem.V, problem.body_cells)
            problem.A.setNearNullSpace(near_nullspace)
            problem.K.setNearNullSpace(near_nullspace)
        self.near_nullspace = near_nullspace
        self._residuals: list = []
        self.snes.setMonitor(self._monitor)

    def _options(self):
        """The solver's defaults in the database (where absent) for the duration of a block."""
        return default_options(self.prefix, self.defaults)

    def _monitor(self, snes, its, norm):
        self._residuals.append(float(norm))

    @property
    def linear_solver(self) -> str:
        ksp = self.snes.getKSP()
        pc = ksp.getPC()
        name = f"{ksp.getType()}+{pc.getType()}"
        if pc.getType() == "lu":
            name += f"({pc.getFactorSolverType()})"
        return name

    def solve(self) -> SolveResult:
        """Solve F(u) = 0 starting from ``problem.u``; on success ``problem.u`` holds the root.

        On failure ``problem.u`` holds the last iterate: the caller reverts it.

        Raises:
            Exception: whatever a callback raised (the same object, e.g. a ConvergenceError
                of the interface), and ``PETSc.Error`` (not a convergence failure: numerical
                failures of the linear solver come back as a negative converged reason).
        """
        self._residuals = []
        self.problem.u.vector.copy(self.x)
        if self._auto_atol:
            # Round-off floor of F = K u - f: about eps |K|_inf |u|_inf. Below it Newton cannot
            # converge (seen at a total load of 1 mN on the punch, tests/fem/test_extremes.py).
            u_inf = max(self.x.norm(PETSc.NormType.INFINITY), 1e-30)
            floor = 10.0 * np.finfo(float).eps * self._k_norm_inf * u_inf
            self.snes.setTolerances(atol=max(self._atol0, floor))
        # Some options are read only when the preconditioner is set up, inside the solve.
        with self._options():
            self.snes.solve(None, self.x)
        reason = self.snes.getConvergedReason()
        self.problem.update_solution(self.x)
        res = list(self._residuals)
        ok = reason > 0 and all(np.isfinite(res))
        return SolveResult(ok, int(reason), _reason_name(reason), self.snes.getIterationNumber(),
                           res, self.snes.getLinearSolveIterations())

    def report_unused_options(self) -> list[str]:
        """Warn (rank 0) about options under this solver's prefix that PETSc never read.

        Call it at the end of a run: some options are read only at the first solve.

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
