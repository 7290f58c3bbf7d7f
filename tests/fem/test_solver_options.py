"""SNESSolver and PETSc's options database: no interference between solvers, defaults that reach
PETSc when it reads them, and the report of options given but never used.

Serial and ``mpirun -n 2``. Units: mm, N, MPa.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.solver.options import unused_options
from rough_contact.solver.snes import (AMG_DEFAULT, DEFAULT_DOF_THRESHOLD, LINEAR_SOLVERS,
                                       SNESSolver, UnusedOptionsWarning)

E, NU = 2.0e5, 0.25


def bulk_problem(p, mesh_size=0.6):
    """One block on rollers with pressure p [MPa] on top (a linear problem)."""
    scene = block_on_plane(lx=1.0, ly=2.0, h=1.5, mesh_size=mesh_size, order=1)
    V = compat.vector_space(scene.mesh, 1)
    bcs = []
    for name, comp in (("x0", 0), ("y0", 1), ("contact", 2)):
        dofs = fem.locate_dofs_topological(V.sub(comp), 2,
                                           scene.facet_tags.find(scene.tag(name)))
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp)))
    return ContactProblem(V, Material(E, NU), bcs,
                          [SurfaceLoad(scene.tag("top"), traction=[0.0, 0.0, -p])],
                          facet_tags=scene.facet_tags)


def prefixed(prefix):
    """Options of the database under ``prefix`` (names without the dash)."""
    return sorted(k for k in PETSc.Options().getAll() if k.startswith(prefix))


def test_two_solvers_same_prefix_keep_their_own_tolerances():
    """Reproduces issue 8: the second solver used to inherit the first one's (auto-scaled)
    absolute tolerance from the global options database."""
    opts = PETSc.Options()
    opts.setValue("twin_snes_max_it", 7)  # a user option: read by both, never removed
    p1, p2 = bulk_problem(10.0), bulk_problem(1000.0)
    assert p2.f_norm > 50 * p1.f_norm
    s1 = SNESSolver(p1, prefix="twin_", defaults={"snes_rtol": 1e-7})
    assert prefixed("twin_") == ["twin_snes_max_it"]  # s1's defaults are gone again
    s2 = SNESSolver(p2, prefix="twin_")
    rtol1, atol1, _, maxit1 = s1.snes.getTolerances()
    rtol2, atol2, _, maxit2 = s2.snes.getTolerances()
    # the documented defaults: rtol 1e-9 and atol 1e-10 |f| (f = nominal load vector)
    assert (rtol1, rtol2) == (1e-7, 1e-9)
    assert atol1 == pytest.approx(1e-10 * p1.f.norm(), rel=1e-14)
    assert atol2 == pytest.approx(1e-10 * p2.f.norm(), rel=1e-14)
    assert maxit1 == maxit2 == 7
    for solver, problem in ((s1, p1), (s2, p2)):
        problem.set_load_factor(1.0)
        assert solver.solve().converged
    assert s2.snes.getTolerances()[1] == atol2  # the solves changed nothing for the other
    assert prefixed("twin_") == ["twin_snes_max_it"]
    for s in (s1, s2):
        s.destroy()
    opts.delValue("twin_snes_max_it")


def test_command_line_value_wins_over_defaults():
    opts = PETSc.Options()
    opts.setValue("cmd_snes_rtol", 1e-5)
    opts.setValue("cmd_snes_atol", 3e-3)
    solver = SNESSolver(bulk_problem(10.0), prefix="cmd_", defaults={"snes_rtol": 1e-7})
    rtol, atol, _, _ = solver.snes.getTolerances()
    assert (rtol, atol) == (1e-5, 3e-3)
    assert prefixed("cmd_") == ["cmd_snes_atol", "cmd_snes_rtol"]  # the user's stay
    solver.destroy()
    opts.delValue("cmd_snes_rtol")
    opts.delValue("cmd_snes_atol")


def test_defaults_reach_options_read_at_the_first_solve():
    """Multigrid level smoothers are read when GAMG builds its hierarchy, inside the first
    solve, not at setFromOptions: the solver's defaults must still be there then.

    The coarse limit keeps two levels (1521 -> ~108 equations). With a limit of 50 a third level
    of 5-6 aggregates appears whose Galerkin operator has zero diagonal entries on some 2-rank
    partitions (aggregates too small for the six rigid-body modes): SOR then stops with
    FACTOR_NUMERIC_ZEROPIVOT (DIVERGED_PC_FAILED), a failure of the smoother chosen here, not of
    the option handling. The project's own GAMG set (Chebyshev/Jacobi) converges on those
    partitions."""
    problem = bulk_problem(10.0, mesh_size=0.25)
    solver = SNESSolver(problem, prefix="lazy_", linear_solver="gamg", defaults={
        "mg_levels_ksp_type": "richardson", "mg_levels_pc_type": "sor",
        "pc_gamg_coarse_eq_limit": 200})
    problem.set_load_factor(1.0)
    assert solver.solve().converged
    pc = solver.snes.getKSP().getPC()
    assert pc.getType() == "gamg" and pc.getMGLevels() >= 2
    smoother = pc.getMGSmoother(1)
    assert (smoother.getType(), smoother.getPC().getType()) == ("richardson", "sor")
    assert prefixed("lazy_") == []
    solver.destroy()


def test_unused_option_is_reported():
    """A mistyped option under the solver's prefix is reported (rank 0 warns); the options the
    solver read, its own defaults and other prefixes are not."""
    opts = PETSc.Options()
    opts.setValue("typo_snes_monitr", "")  # as given by -typo_snes_monitr
    opts.setValue("typo_snes_max_it", 20)  # correct: read by setFromOptions
    opts.setValue("other_ksp_monitr", "")  # another prefix: not this solver's business
    problem = bulk_problem(10.0)
    solver = SNESSolver(problem, prefix="typo_")
    problem.set_load_factor(1.0)
    assert solver.solve().converged
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        names = solver.report_unused_options()
    assert names == ["typo_snes_monitr"]
    assert "other_ksp_monitr" in unused_options()
    mine = [w for w in caught if issubclass(w.category, UnusedOptionsWarning)]
    if problem.comm.rank == 0:
        assert len(mine) == 1 and "-typo_snes_monitr" in str(mine[0].message)
        assert "typo_snes_max_it" not in str(mine[0].message)
        with pytest.warns(UnusedOptionsWarning, match="-typo_snes_monitr"):
            solver.destroy()  # reports too
    else:
        assert mine == []
        solver.destroy()
    for name in ("typo_snes_monitr", "typo_snes_max_it", "other_ksp_monitr"):
        opts.delValue(name)


def test_bad_arguments():
    problem = bulk_problem(10.0)
    with pytest.raises(ValueError, match="prefix"):
        SNESSolver(problem, prefix="nounderscore")
    with pytest.raises(ValueError, match="dof_threshold = -1 is invalid: it must be finite and "
                                         ">= 0"):
        SNESSolver(problem, prefix="bad_", dof_threshold=-1)
    with pytest.raises(ValueError, match="load factor = nan"):
        problem.set_load_factor(np.nan)


def uniaxial_error(problem, p):
    """Max nodal error of the block's exact solution (uniaxial stress sigma_zz = -p)."""
    from mpi4py import MPI

    x = problem.V.tabulate_dof_coordinates()
    u = problem.u.x.array.reshape(-1, 3)
    exact = np.column_stack([NU * p / E * x[:, 0], NU * p / E * x[:, 1], -p / E * x[:, 2]])
    return problem.comm.allreduce(float(np.max(np.abs(u - exact))), op=MPI.MAX)


def test_size_rule_picks_mumps_then_amg():
    problem = bulk_problem(10.0)
    assert problem.num_dofs < DEFAULT_DOF_THRESHOLD
    small = SNESSolver(problem, prefix="size1_")
    assert small.option_set == "mumps" and small.linear_solver == "preonly+lu(mumps)"
    assert small.near_nullspace is None
    big = SNESSolver(bulk_problem(10.0), prefix="size2_", dof_threshold=problem.num_dofs - 1)
    assert big.option_set == AMG_DEFAULT
    assert big.linear_solver == f"gmres+{LINEAR_SOLVERS[AMG_DEFAULT]['pc_type']}"
    for s in (small, big):
        s.destroy()


@pytest.mark.parametrize("option_set", ["gamg", "hypre"])
def test_amg_sets_solve_to_the_exact_answer(option_set):
    """Each AMG set, with the six global rigid-body modes and 3 x 3 blocks, solves the block
    under pressure to its exact (uniaxial stress) solution."""
    p = 10.0
    problem = bulk_problem(p, mesh_size=0.25)
    solver = SNESSolver(problem, prefix=f"amg_{option_set}_", linear_solver=option_set)
    assert solver.linear_solver == f"gmres+{option_set}"
    assert problem.A.getBlockSize() == 3
    assert len(solver.near_nullspace.getVecs()) == 6
    assert problem.A.getNearNullSpace() is not None
    problem.set_load_factor(1.0)
    result = solver.solve()
    assert result.converged and result.linear_iterations > result.iterations
    assert uniaxial_error(problem, p) < 1e-8 * p / E
    assert solver.report_unused_options() == []
    solver.destroy()


def test_command_line_picks_the_set_and_overrides_single_options():
    opts = PETSc.Options()
    # -pc_type alone picks the whole GAMG set (GMRES + its tolerances), not just the PC
    opts.setValue("pick1_pc_type", "gamg")
    s1 = SNESSolver(bulk_problem(10.0), prefix="pick1_")
    assert s1.option_set == "gamg" and s1.linear_solver == "gmres+gamg"
    assert s1.snes.getKSP().getTolerances()[0] == LINEAR_SOLVERS["gamg"]["ksp_rtol"]
    # -linear_solver wins over the size rule; a single option changes only itself
    opts.setValue("pick2_linear_solver", "hypre")
    opts.setValue("pick2_ksp_rtol", 1e-9)
    opts.setValue("pick2_near_nullspace", "per_body")
    problem = bulk_problem(10.0)
    s2 = SNESSolver(problem, prefix="pick2_", linear_solver="mumps")
    assert s2.option_set == "hypre" and s2.linear_solver == "gmres+hypre"
    ksp = s2.snes.getKSP()
    assert ksp.getTolerances()[0] == 1e-9
    assert ksp.getTolerances()[3] == LINEAR_SOLVERS["hypre"]["ksp_max_it"]
    problem.set_load_factor(1.0)
    assert s2.solve().converged
    assert s2.report_unused_options() == []  # linear_solver and near_nullspace were read
    for s in (s1, s2):
        s.destroy()
    for name in ("pick1_pc_type", "pick2_linear_solver", "pick2_ksp_rtol",
                 "pick2_near_nullspace"):
        opts.delValue(name)


def test_command_line_threshold():
    opts = PETSc.Options()
    problem = bulk_problem(10.0)
    opts.setValue("thr_dof_threshold", problem.num_dofs - 1)
    solver = SNESSolver(problem, prefix="thr_", dof_threshold=10**9)
    assert solver.dof_threshold == problem.num_dofs - 1 and solver.option_set == AMG_DEFAULT
    assert solver.report_unused_options() == []
    solver.destroy()
    opts.delValue("thr_dof_threshold")


def test_bad_solver_choices():
    problem = bulk_problem(10.0)
    with pytest.raises(ValueError, match="linear solver = 'superlu' is invalid; valid values: "
                                         "'auto', 'mumps'"):
        SNESSolver(problem, prefix="bad1_", linear_solver="superlu")
    with pytest.raises(ValueError, match="near_nullspace = 'local' is invalid"):
        SNESSolver(problem, prefix="bad2_", linear_solver="gamg", near_nullspace="local")



def test_unused_option_is_reported_after_the_first_solve():
    """Issue 24, item 14: a mistyped option was reported only when the solver was destroyed at
    the end of a (long) run; it is reported right after the first solve (rank 0)."""
    PETSc.Options().setValue("early_snes_monitr", "")
    problem = bulk_problem(10.0)
    solver = SNESSolver(problem, prefix="early_")
    problem.set_load_factor(1.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert solver.solve().converged
    mine = [w for w in caught if issubclass(w.category, UnusedOptionsWarning)]
    if problem.comm.rank == 0:
        assert len(mine) == 1 and "-early_snes_monitr" in str(mine[0].message)
    else:
        assert mine == []
    with warnings.catch_warnings(record=True) as caught:   # the second solve stays quiet
        warnings.simplefilter("always")
        assert solver.solve().converged
    assert not [w for w in caught if issubclass(w.category, UnusedOptionsWarning)]
    PETSc.Options().delValue("early_snes_monitr")
    solver.destroy()
