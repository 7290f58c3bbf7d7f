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
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.solver.options import unused_options
from rough_contact.solver.snes import SNESSolver, UnusedOptionsWarning

E, NU = 2.0e5, 0.25


def bulk_problem(p, mesh_size=0.6):
    """One block on rollers with pressure p [MPa] on top (a linear problem)."""
    scene = block_on_plane(lx=1.0, ly=2.0, h=1.5, mesh_size=mesh_size, order=1)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
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
    solve, not at setFromOptions: the solver's defaults must still be there then."""
    problem = bulk_problem(10.0, mesh_size=0.25)
    solver = SNESSolver(problem, prefix="lazy_", dof_threshold=0, defaults={
        "mg_levels_ksp_type": "richardson", "mg_levels_pc_type": "sor",
        "pc_gamg_coarse_eq_limit": 50})
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
