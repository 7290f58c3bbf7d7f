"""ContactProblem + SNES + loading on small scenes. Serial and ``mpirun -n 2``.

Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem

from rough_contact.fem import compat
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad, rigid_body_modes
from rough_contact.solver.snes import SNESSolver

E, NU = 2.0e5, 0.25


def roller(V, scene, name, comp):
    facets = scene.facet_tags.find(scene.tag(name))
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, facets)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


@pytest.mark.parametrize("order", [1, 2])
def test_bulk_uniaxial_exact(order):
    """One block on rollers, uniform pressure on top: the linear field is reproduced exactly."""
    scene = block_on_plane(lx=1.0, ly=2.0, h=1.5, mesh_size=0.6, order=order)
    V = compat.vector_space(scene.mesh, order)
    bcs = [roller(V, scene, "x0", 0), roller(V, scene, "y0", 1), roller(V, scene, "contact", 2)]
    p = 50.0
    problem = ContactProblem(V, {scene.tag("block"): Material(E, NU)}, bcs,
                             [SurfaceLoad(scene.tag("top"), force=[0.0, 0.0, -p * 2.0])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags)
    assert np.allclose(problem.applied_force, [0.0, 0.0, -100.0], rtol=1e-12)
    solver = SNESSolver(problem, prefix="test_bulk_")
    problem.set_load_factor(1.0)
    result = solver.solve()
    assert result.converged
    x = V.tabulate_dof_coordinates()
    u = problem.u.x.array.reshape(-1, 3)
    exact = np.column_stack([NU * p / E * x[:, 0], NU * p / E * x[:, 1], -p / E * x[:, 2]])
    err = scene.mesh.comm.allreduce(np.max(np.abs(u - exact)), op=MPI.MAX)
    assert err < 1e-10 * p / E * 1.5
    solver.destroy()


def test_rigid_body_modes_in_kernel():
    """K (without Dirichlet conditions) annihilates the six rigid body modes."""
    scene = block_on_plane(lx=1.0, ly=1.0, h=1.0, mesh_size=0.6, order=1)
    V = compat.vector_space(scene.mesh, 1)
    problem = ContactProblem(V, Material(E, NU))
    ns = rigid_body_modes(V)
    assert ns.test(problem.K)
    y = problem.K.createVecLeft()
    for v in ns.getVecs():
        problem.K.mult(v, y)
        assert y.norm() < 1e-8 * problem.K.norm()


def test_bad_input_raises():
    with pytest.raises(ValueError, match="Poisson"):
        Material(E, 0.5)
    with pytest.raises(ValueError, match="Young"):
        Material(-1.0, 0.3)
    with pytest.raises(ValueError, match="exactly one"):
        SurfaceLoad(1)
    with pytest.raises(ValueError, match=r"SurfaceLoad\(tag=2\)\.force\[1\] = nan N is invalid"):
        SurfaceLoad(2, force=[0.0, np.nan, 1.0])
    with pytest.raises(ValueError, match=r"SurfaceLoad\(tag=2\)\.traction = \[1, 2\] is invalid"):
        SurfaceLoad(2, traction=[1, 2])
    scene = block_on_plane(lx=1.0, ly=1.0, h=1.0, mesh_size=0.6, order=1)
    V = compat.vector_space(scene.mesh, 1)
    with pytest.raises(ValueError, match=r"seating_stiffness = -1.0 MPa/mm is invalid: it must "
                                         r"be finite and >= 0"):
        ContactProblem(V, Material(E, NU), seating_stiffness=-1.0)
    with pytest.raises(TypeError, match="interface must be a ContactInterface or None, got dict"):
        ContactProblem(V, Material(E, NU), interface={})
    problem = ContactProblem(V, Material(E, NU))
    solver = SNESSolver(problem, prefix="test_bad_")
    from rough_contact.solver.loading import load_path, load_unload_factors

    for kwargs, message in (({"min_increment": 0.0}, "min_increment = 0.0 is invalid"),
                            ({"max_growth": 0.5}, "max_growth = 0.5 is invalid"),
                            ({"factors": [0.5, np.inf]}, "load factor 1 of the load path")):
        args = dict(factors=[0.5], verbose=False) | kwargs
        with pytest.raises(ValueError, match=message):
            list(load_path(problem, solver, **args))
    with pytest.raises(ValueError, match="n_load = 2.5 is invalid"):
        load_unload_factors(2.5)
    with pytest.raises(ValueError, match="final_factor = 1.0 is invalid"):
        load_unload_factors(4, final_factor=1.0)
    solver.destroy()


# ----------------------------------------------------------------------------------------------
# two blocks: patch tests and force balance
# ----------------------------------------------------------------------------------------------
from rough_contact.scenes.meshes.blocks import two_blocks  # noqa: E402
from rough_contact.fem.contact import ContactInterface  # noqa: E402
from rough_contact.interface.contract import ConvergenceError  # noqa: E402
from rough_contact.interface.friction import ReturnMappingError  # noqa: E402
from rough_contact.interface.penalty import LinearPenalty  # noqa: E402
from rough_contact.solver.loading import LoadStepError, load_path  # noqa: E402

LX, LY = 1.0, 2.0


def exponential_normal_law(p0=200.0, ell=2e-3, a0=0.5):
    """A rough-like normal law p = p0 exp(-h/ell), k = p/ell, A/A0 = a0 exp(-h/ell), h in mm."""
    from rough_contact.interface.normal import NormalLaw

    def model(h):
        e = np.exp(-h / ell)
        return p0 * e, p0 * e / ell, a0 * e

    return NormalLaw.from_model(model, (0.0, 40 * ell), rtol=1e-8)


def blocks_problem(law, p, order=1, mesh_size=0.5, E_upper=E, E_lower=E, prefix="test_blocks_",
                   comm=MPI.COMM_WORLD, **problem_kw):
    """Two blocks on rollers (x0, y0, bottom), pressure p [MPa] on top, interface law ``law``."""
    scene = two_blocks(lx=LX, ly=LY, h1=1.0, h2=0.5, mesh_size=mesh_size, order=order, comm=comm)
    V = compat.vector_space(scene.mesh, order)
    bcs = [roller(V, scene, "x0", 0), roller(V, scene, "y0", 1), roller(V, scene, "bottom", 2)]
    first, second = scene.contact_pair
    ci = ContactInterface(V, scene.facet_tags, first, second, law=law, bcs=bcs,
                          quadrature_degree=2)
    mats = {scene.tag("upper"): Material(E_upper, NU), scene.tag("lower"): Material(E_lower, NU)}
    problem = ContactProblem(V, mats, bcs, [SurfaceLoad(scene.tag("top"), traction=[0, 0, -p])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci, **problem_kw)
    solver = SNESSolver(problem, prefix=prefix)
    return scene, problem, solver, ci


@pytest.mark.parametrize("order", [1, 2])
def test_patch_linear_penalty(order):
    """Bilateral linear penalty: a uniform pressure crosses the interface exactly."""
    p, kn = 80.0, 1.0e6
    scene, problem, solver, ci = blocks_problem(LinearPenalty(kn), p, order=order,
                                                E_lower=0.5 * E)
    problem.set_load_factor(1.0)
    result = solver.solve()
    assert result.converged and result.iterations <= 2
    ci.evaluate(problem.u)
    pf = ci.point_fields()
    comm = scene.mesh.comm
    err = comm.allreduce(float(np.max(np.abs(pf.pressure - p), initial=0.0)), op=MPI.MAX)
    assert err <= 1e-8 * p
    gerr = comm.allreduce(float(np.max(np.abs(pf.gap + p / kn), initial=0.0)), op=MPI.MAX)
    assert gerr <= 1e-8 * p / kn
    force = ci.contact_force()
    assert np.allclose(force, [0.0, 0.0, p * LX * LY], rtol=0, atol=1e-8 * p * LX * LY)
    solver.destroy()


def paper_surface_law(friction):
    """Normal law of the paper's surface (Figs 18-19 moments, elastic population, E* of two
    steel bodies), with or without the orthotropic slip-hardening friction of case (b)."""
    from rough_contact.interface.friction import OrthotropicSlipHardening
    from rough_contact.interface.law import InterfaceLaw
    from rough_contact.interface.normal import NormalLaw
    from rough_contact.interface.tangential import TangentialStiffness
    from rough_contact.surface import SpectralMoments

    surface = SpectralMoments(0.625, 8e-5, 8e-4, 1.04e-6, 1.04e-4, unit="um")
    normal = NormalLaw.elastic(surface, E / (2.0 * (1.0 - NU**2)))
    if not friction:
        return InterfaceLaw(normal=normal), normal
    fr = OrthotropicSlipHardening(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5),
                                  hardening=(275.0, 275.0), potential_axes=(0.125, 0.125))
    return InterfaceLaw(normal=normal, tangential=TangentialStiffness((0.7, 0.7)),
                        friction=fr), normal


@pytest.mark.parametrize("which", ["exponential", "paper_surface_with_friction"])
def test_patch_rough_normal_law(which):
    """Rough normal law: uniform pressure, and the separation h = h0 + g solves p(h) = p_applied."""
    from rough_contact.interface.law import InterfaceLaw

    if which == "exponential":
        normal = exponential_normal_law()
        law = InterfaceLaw(normal=normal)
        p_seat, p = 2.0, 60.0
    else:
        law, normal = paper_surface_law(friction=True)
        p_seat, p = 0.5, 20.0
    law = law.with_seating(p_seat)
    scene, problem, solver, ci = blocks_problem(law, p, order=1, prefix="test_rough_")
    factors = [0.25, 0.5, 1.0]
    area = LX * LY
    for inc in load_path(problem, solver, factors, verbose=False):
        # force balance at every converged increment
        applied = inc.applied_force
        assert np.allclose(applied, [0, 0, -inc.load_factor * p * area], rtol=1e-12)
        assert np.allclose(inc.contact_force, -applied, rtol=0, atol=1e-8 * abs(applied[2]))
        assert inc.n_active == inc.n_points
    assert inc.load_factor == 1.0
    pf = ci.point_fields()
    comm = scene.mesh.comm
    err = comm.allreduce(float(np.max(np.abs(pf.pressure - p), initial=0.0)), op=MPI.MAX)
    assert err <= 1e-8 * p
    h_exact = float(normal.separation_for_pressure(np.array([p]))[0])
    herr = comm.allreduce(float(np.max(np.abs(law.h0 + pf.gap - h_exact), initial=0.0)),
                          op=MPI.MAX)
    assert herr <= 1e-8 * abs(h_exact) + 1e-12
    # real area from the law's own A/A0 at the uniform separation
    a_exact = float(normal.evaluate(np.array([h_exact]))[2][0])
    assert np.isclose(ci.real_contact_area(), a_exact * area, rtol=1e-7)
    solver.destroy()


# ----------------------------------------------------------------------------------------------
# a block held only by contact: the singular first Jacobian and its remedy
# ----------------------------------------------------------------------------------------------
def test_seating_spring_for_body_held_only_by_contact():
    """A block above a rigid plane (gap delta) is held only by a unilateral penalty: the first
    Jacobian is singular; the Jacobian-only seating spring lets Newton start, and the converged
    answer is the exact one (uniform pressure p, penetration p / k_N)."""
    scene = block_on_plane(lx=LX, ly=LY, h=0.5, mesh_size=0.5, order=1)
    V = compat.vector_space(scene.mesh, 1)
    bcs = [roller(V, scene, "x0", 0), roller(V, scene, "y0", 1)]
    delta, p, kn = 1e-3, 10.0, 1e5
    law = LinearPenalty(kn, unilateral=True)
    contact = scene.tag("contact")
    ci = ContactInterface(V, scene.facet_tags, contact, None, law=law, bcs=bcs,
                          rigid_plane=((0.0, 0.0, -delta), (0.0, 0.0, 1.0)))
    problem = ContactProblem(V, Material(E, NU), bcs,
                             [SurfaceLoad(scene.tag("top"), traction=[0, 0, -p])],
                             facet_tags=scene.facet_tags, interface=ci, seating_tag=contact,
                             seating_stiffness=1e-2 * kn)
    # While the block floats the residual cannot decrease, so a backtracking line search
    # would stall: take full Newton steps.
    solver = SNESSolver(problem, prefix="test_seat_", defaults={"snes_linesearch_type": "basic"})
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    assert incs[-1].load_factor == 1.0
    pf = ci.point_fields()
    comm = scene.mesh.comm
    err = comm.allreduce(float(np.max(np.abs(pf.pressure - p), initial=0.0)), op=MPI.MAX)
    assert err <= 1e-8 * p
    assert np.isclose(incs[-1].contact_force[2], p * LX * LY, rtol=1e-10)
    assert incs[-1].n_active == incs[-1].n_points
    solver.destroy()


# ----------------------------------------------------------------------------------------------
# cutback
# ----------------------------------------------------------------------------------------------
class _GapState:
    """History of StepLimitedPenalty: the committed normal jump (a LawState: no plastic slip)."""

    def __init__(self, g):
        self.g = g
        self.plastic_slip = np.zeros((g.size, 2))

    def copy(self):
        return _GapState(self.g.copy())

    def __len__(self):
        return self.g.size


class StepLimitedPenalty:
    """Bilateral linear penalty that returns NaN when the normal jump changes by more than
    ``limit`` [mm] from the committed state in one increment (forces cutbacks)."""

    def __init__(self, k_normal, limit):
        self.inner, self.limit = LinearPenalty(k_normal), limit

    def initial_state(self, n):
        return _GapState(np.zeros(n))

    def evaluate(self, jump, committed):
        res = self.inner.evaluate(jump, self.inner.initial_state(len(jump)))
        too_far = np.abs(jump[:, 0] - committed.g) > self.limit
        traction = np.where(too_far[:, None], np.nan, res.traction)
        from dataclasses import replace

        return replace(res, traction=traction, state=_GapState(jump[:, 0].copy()))


def test_cutback_reaches_target_and_keeps_history():
    p, kn = 40.0, 1.0e5
    g_final = -p / kn
    law = StepLimitedPenalty(kn, limit=0.3 * abs(g_final))
    scene, problem, solver, ci = blocks_problem(law, p, prefix="test_cut_")
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    assert incs[-1].load_factor == 1.0
    assert sum(i.cutbacks for i in incs) >= 2
    # every committed step respected the increment limit, and the result is exact
    lams = [0.0] + [i.load_factor for i in incs]
    assert max(np.diff(lams)) <= 0.3 + 1e-12
    pf = ci.point_fields()
    err = scene.mesh.comm.allreduce(float(np.max(np.abs(pf.pressure - p), initial=0.0)), op=MPI.MAX)
    assert err <= 1e-8 * p
    for inc in incs:
        assert np.isclose(inc.contact_force[2], inc.load_factor * p * LX * LY, rtol=1e-8)
    solver.destroy()


def test_cutback_exhausted_names_load_factor():
    p, kn = 40.0, 1.0e5
    law = StepLimitedPenalty(kn, limit=1e-4 * p / kn)  # needs increments < 1e-4
    scene, problem, solver, ci = blocks_problem(law, p, prefix="test_cutx_")
    done = []
    with pytest.raises(LoadStepError, match="load factor") as info:
        for inc in load_path(problem, solver, [0.5e-4, 1.0], min_increment=1e-3, verbose=False):
            done.append(inc)
    assert [i.load_factor for i in done] == [0.5e-4]  # the converged increment was kept
    assert info.value.last_converged == 0.5e-4
    assert 0.5e-4 < info.value.load_factor < 1.0
    solver.destroy()


# ----------------------------------------------------------------------------------------------
# errors keep their type: only convergence failures cut back, on every rank together
# ----------------------------------------------------------------------------------------------
class RaisingPenalty:
    """Bilateral linear penalty that raises ``make_error()`` on ``rank`` (None = every rank):
    always once ``armed``, or (``limit`` given) when the normal jump moves by more than ``limit``
    [mm] from the committed state in one increment."""

    def __init__(self, k_normal, make_error, rank=None, limit=None):
        self.inner, self.make_error, self.rank, self.limit = LinearPenalty(k_normal), \
            make_error, rank, limit
        self.armed, self.raised, self.calls = False, [], 0

    def initial_state(self, n):
        return _GapState(np.zeros(n))

    def evaluate(self, jump, committed):
        self.calls += 1
        here = self.rank is None or MPI.COMM_WORLD.rank == self.rank
        too_far = self.limit is not None and np.any(np.abs(jump[:, 0] - committed.g) > self.limit)
        if here and (self.armed or too_far):
            self.raised.append(self.make_error())
            raise self.raised[-1]
        from dataclasses import replace

        res = self.inner.evaluate(jump, self.inner.initial_state(len(jump)))
        return replace(res, state=_GapState(jump[:, 0].copy()))


class LocalNewtonError(ConvergenceError):
    """Stands for a law's local Newton failure (module level: importable on every rank)."""


def _count_solves(solver):
    calls = []
    solve = solver.solve

    def counting(*args, **kwargs):
        calls.append(1)
        return solve(*args, **kwargs)

    solver.solve = counting
    return calls


def _prefixed_options(prefix):
    return sorted(k for k in PETSc.Options().getAll() if k.startswith(prefix))


@pytest.mark.parametrize("where", ["every_rank", "rank_0"])
def test_programming_error_in_law_propagates_at_once(where):
    """A TypeError inside the law leaves load_path at once, with its type (no cutback, no
    LoadStepError); on 2 ranks with the failure on rank 0 only, the other rank raises a
    RuntimeError naming it instead of hanging."""
    comm = MPI.COMM_WORLD
    law = RaisingPenalty(1e5, lambda: TypeError("unsupported operand type(s)"),
                         rank=None if where == "every_rank" else 0)
    scene, problem, solver, ci = blocks_problem(law, 40.0, prefix="test_prop_")
    solves = _count_solves(solver)
    path = load_path(problem, solver, [0.5, 1.0], verbose=False)
    first = next(path)
    assert first.load_factor == 0.5 and len(solves) == 1
    law.armed = True
    with pytest.raises(Exception) as info:
        next(path)
    assert not isinstance(info.value, (LoadStepError, ConvergenceError))
    assert len(solves) == 2  # the failing solve only: no retry with a smaller increment
    if law.raised:  # this rank's law raised: the very object, traceback down to the law
        assert info.value is law.raised[0] and len(law.raised) == 1
        assert any(tb.name == "evaluate" for tb in info.traceback)
    else:
        assert type(info.value) is RuntimeError
        assert str(info.value) == "rank 0 raised TypeError: unsupported operand type(s)"
    # the solver's defaults left the options database although the solve raised
    assert _prefixed_options("test_prop_") == []
    assert ci.dissipation() == 0.0 and comm.allreduce(len(law.raised)) >= 1
    solver.destroy()


def test_increments_count_the_work_of_failed_attempts():
    """Every Newton and linear iteration spent is reported, failed attempts included.

    Reference: PETSc's own monitors (a SNES monitor called once per finished Newton iteration)
    and the number of Jacobian evaluations, each followed by one LU solve (1 linear iteration).
    """
    p, kn = 40.0, 1.0e5
    law = StepLimitedPenalty(kn, limit=0.3 * p / kn)
    scene, problem, solver, ci = blocks_problem(law, p, prefix="test_count_")
    newton = []
    solver.snes.setMonitor(lambda snes, its, norm: newton.append(its) if its > 0 else None)
    solves = _count_solves(solver)
    problem.reset_timings()
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    failed = len(solves) - len(incs)
    assert failed >= 2
    assert sum(i.failed_attempts for i in incs) == failed
    assert sum(i.newton_total for i in incs) == len(newton)
    assert sum(i.linear_total for i in incs) == problem.counters["jacobian"]
    # the failed attempts did linear solves that the converged attempts alone do not show
    assert sum(i.linear_iterations for i in incs) < sum(i.linear_total for i in incs)
    assert all(i.linear_iterations == i.iterations for i in incs)  # LU: 1 per Newton iteration
    solver.destroy()


@pytest.mark.parametrize("error", [ReturnMappingError, LocalNewtonError])
def test_convergence_error_on_one_rank_cuts_back_on_every_rank(error):
    """A ConvergenceError raised on ONE rank (the first that owns interface points) makes every
    rank cut back together; the load path still reaches the exact answer."""
    p, kn = 40.0, 1.0e5
    g_final = -p / kn
    law = RaisingPenalty(kn, lambda: error("local Newton did not converge at 1 point"),
                         rank=-1, limit=0.3 * abs(g_final))
    scene, problem, solver, ci = blocks_problem(law, p, prefix="test_cut1_")
    comm = scene.mesh.comm
    law.rank = next(r for r, n in enumerate(comm.allgather(ci.n_points)) if n > 0)
    solves = _count_solves(solver)
    incs = list(load_path(problem, solver, [1.0], verbose=False))
    assert incs[-1].load_factor == 1.0
    assert sum(i.cutbacks for i in incs) >= 2
    # every failed solve is one raise on the failing rank, and a cutback on every rank
    assert comm.allreduce(len(law.raised), op=MPI.SUM) == len(solves) - len(incs) >= 2
    lams = [0.0] + [i.load_factor for i in incs]
    assert max(np.diff(lams)) <= 0.3 + 1e-12
    assert comm.allgather(lams) == [lams] * comm.size  # every rank took the same steps
    pf = ci.point_fields()
    err = comm.allreduce(float(np.max(np.abs(pf.pressure - p), initial=0.0)), op=MPI.MAX)
    assert err <= 1e-8 * p
    solver.destroy()


def test_material_given_a_string_is_refused_at_once():
    """Issue 24, item 3: Material("2e5", 0.3) was accepted and failed later with a TypeError in
    the Lame parameters; it is refused where it is made, naming E."""
    with pytest.raises(ValueError, match=r"Young's modulus E = '2e5' is invalid: it must be a "
                                         r"number, not a str"):
        Material("2e5", 0.3)
    with pytest.raises(ValueError, match=r"Poisson's ratio nu = '0.3' is invalid"):
        Material(2e5, "0.3")
