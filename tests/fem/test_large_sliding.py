"""Large sliding (``ContactInterface(sliding="large")``): the pairing redone on every converged
iterate until it stops moving. Serial and ``mpirun -n 2``; on 2 ranks every figure is compared
with the same run on one rank (``MPI.COMM_SELF``).

References (not from this code's interface):
- Coulomb's law in gross slip: the plain penalty's radial return gives |t_T| = mu p at every
  slipping point, so the friction force is mu times the normal force to round-off, whatever the
  pressure distribution; a hold (nothing moves) must leave it there.
- A frictionless slider: the load the slab carries sits under the slider's centre (the slab's
  own equilibrium: moment of its bottom reaction over its vertical reaction), and the elastic
  end state does not depend on the number of increments.
- Geometry: a point of the slider is in contact exactly while its current position lies over
  the slab (|x| <= half the slab's length).
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import (ContactProblem, Material, PrescribedDisplacement,
                                       SurfaceLoad)
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import slider_on_slab
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import LoadProgram
from rough_contact.solver.snes import SNESSolver

E, NU, P_TOP, MU = 2.0e5, 0.3, 20.0, 0.3
H_SLAB = 0.125                   # slab element length [mm]

_SCENES = {}


def _scene(comm, **kw):
    key = (comm.size, tuple(sorted(kw.items())))
    if key not in _SCENES:
        _SCENES[key] = slider_on_slab(comm=comm, **{"size_slab": H_SLAB, **kw})
    return _SCENES[key]


def _ramp(t):
    return min(max(t, 0.0), 1.0)


def _slab_load_position(problem, V, scene, comm):
    """x of the load the slab carries: moment of its bottom reaction about the y axis over
    its vertical reaction (the slab's own equilibrium)."""
    u, v = problem.u, ufl.TestFunction(V)
    mu_l, lmbda = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))
    eps = ufl.sym(ufl.grad(u))
    sigma = 2 * mu_l * eps + lmbda * ufl.tr(eps) * ufl.Identity(3)
    r = fem_petsc.assemble_vector(fem.form(ufl.inner(sigma, ufl.sym(ufl.grad(v))) * ufl.dx))
    r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dofs = fem.locate_dofs_topological(V, 2, scene.facet_tags.find(scene.tag("bottom")))
    dofs = dofs[dofs < V.dofmap.index_map.size_local]
    rz = r.getArray().reshape(-1, 3)[dofs, 2]
    x = V.tabulate_dof_coordinates()[dofs, 0]
    fz, mz = comm.allreduce(np.array([rz.sum(), (x * rz).sum()]), op=MPI.SUM)
    return mz / fz


def _run(comm, sliding, path, friction=MU, normal="pressure", scene_kw=None, predictor="secant"):
    """The slider pressed (2 increments), then its top driven along x through ``path``
    [(load factor, x displacement)]. ``normal``: "pressure" (P_TOP on the top) or a prescribed
    z displacement of the top [mm] (a float)."""
    scene_kw = scene_kw or {}
    scene = _scene(comm, **scene_kw)
    V = compat.vector_space(scene.mesh, scene_kw.get("order", 1))   # the geometry's degree

    def roller(name):
        dofs = fem.locate_dofs_topological(V.sub(1), 2, scene.facet_tags.find(scene.tag(name)))
        return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(1))

    bcs = [roller("y0_slider"), roller("y0_slab")]
    law = SoftplusPenalty(1e6, 1e-5, k_tangential=1e6 if friction else 0.0, friction=friction)
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                          sliding=sliding)
    ts = np.array([1.0] + [t for t, _ in path])
    xs = np.array([0.0] + [x for _, x in path])
    prog = LoadProgram({"press": _ramp, "slide": lambda t: float(np.interp(t, ts, xs))},
                       [0.5, 1.0] + [t for t, _ in path])
    bottom, top = scene.tag("bottom"), scene.tag("top")
    loads, prescribed = [], [PrescribedDisplacement(bottom, (0.0, 0.0, 0.0), channel="press")]
    if normal == "pressure":
        loads = [SurfaceLoad(top, traction=(0.0, 0.0, -P_TOP), channel="press")]
        prescribed.append(PrescribedDisplacement(top, (1.0, 0.0, 0.0), (0,), channel="slide"))
    else:
        prescribed += [PrescribedDisplacement(top, (1.0, 0.0, 0.0), (0,), channel="slide"),
                       PrescribedDisplacement(top, (0.0, 0.0, -float(normal)), (2,),
                                              channel="press")]
    problem = ContactProblem(V, Material(E, NU), bcs, loads, facet_tags=scene.facet_tags,
                             interface=ci, prescribed=prescribed, programs=prog.channels)
    solver = SNESSolver(problem, prefix=f"test_large_sliding_{comm.size}_")
    incs, active = [], []
    for inc in load_path(problem, solver, prog.times, verbose=False, friction_check=False,
                         predictor=predictor):
        incs.append(inc)
        active.append(comm.allreduce(int(ci.active.sum()), op=MPI.SUM))
    out = dict(incs=incs, active=active, ci=ci, problem=problem, scene=scene,
               x_load=_slab_load_position(problem, V, scene, comm),
               u_max=comm.allreduce(float(np.abs(problem.u.x.array).max()), op=MPI.MAX))
    solver.destroy()
    return out


def _forces(r):
    return np.array([inc.contact_force for inc in r["incs"]])


def _same_on_one_rank(world, serial_run, rtol=1e-10):
    """On 2 ranks: the figures of the run on COMM_WORLD equal those on one rank."""
    if MPI.COMM_WORLD.size == 1:
        return
    serial = serial_run(MPI.COMM_SELF)
    scale = np.abs(_forces(world)).max()
    np.testing.assert_allclose(_forces(world), _forces(serial), rtol=0, atol=rtol * scale)
    assert world["active"] == serial["active"]


# the slab 4 mm long, the slider 1 mm: slid 10 slab elements (1.25 mm) forward in 5
# increments, held, slid back to its start in 5, held
SLIDE = 10 * H_SLAB
FORWARD = [(1.0 + 0.2 * (j + 1), SLIDE * (j + 1) / 5) for j in range(5)]
HOLD1 = [(2.5, SLIDE)]
BACK = [(2.5 + 0.2 * (j + 1), SLIDE * (1 - (j + 1) / 5)) for j in range(5)]
HOLD2 = [(4.0, 0.0)]


# the same slide on P2 and on tetrahedra, on a coarse mesh (slab and slider 0.25 mm high,
# elements of 0.25 mm: the slide is 5 of the slab's elements) so that each case takes seconds
COARSE = dict(size_slab=0.25, size_slider=0.25, h_slab=0.25, h_slider=0.25)
ELEMENTS = {"Q1 hexahedra": {},
            "Q2 hexahedra": dict(order=2, **COARSE),
            "P1 tetrahedra": dict(cell_type="tetrahedron", **COARSE),
            "P2 tetrahedra": dict(order=2, cell_type="tetrahedron", **COARSE)}


def _block_slide(comm, element="Q1 hexahedra"):
    return _run(comm, "large", FORWARD + HOLD1 + BACK + HOLD2,
                scene_kw=dict(slab_length=4.0, **ELEMENTS[element]))


@pytest.mark.parametrize("element", list(ELEMENTS))
def test_block_slid_and_back_transmits_mu_n_and_keeps_it_on_a_hold(element):
    r = _block_slide(MPI.COMM_WORLD, element)
    incs, F = r["incs"], _forces(r)
    n_pts = incs[0].n_points
    gross = [i for i, inc in enumerate(incs) if inc.n_slipping == n_pts]
    # gross slip in the forward and the backward slide (the first increment back may reverse)
    assert len(gross) >= 8
    for i in gross:
        assert abs(abs(F[i, 0]) - MU * abs(F[i, 2])) <= 1e-8 * MU * abs(F[i, 2])
        assert F[i, 2] == pytest.approx(P_TOP * 0.5, rel=1e-7)    # vertical balance (Newton)
    assert F[6, 0] * F[12, 0] < 0.0                # the friction force reversed going back
    # the holds: nothing moves, the friction force stays mu N (no point falls back into
    # stick with less traction)
    for hold in (7, 13):
        assert np.abs(F[hold] - F[hold - 1]).max() <= 1e-8 * MU * abs(F[hold - 1, 2])
        assert abs(abs(F[hold, 0]) - MU * abs(F[hold, 2])) <= 1e-8 * MU * abs(F[hold, 2])
    assert r["ci"].n_repairs >= 10                  # the partners changed along the way
    # the matrices were rebuilt for new partners; the bulk values copied into the last
    # pattern are those a fresh assembly into it gives, to the bit
    problem = r["problem"]
    assert problem.counters["rebuild"] >= 1
    fresh = r["ci"].create_matrix(problem.a)
    fresh.zeroEntries()
    fem_petsc.assemble_matrix(fresh, problem.a, bcs=problem.bcs)
    fresh.assemble()
    fresh.axpy(-1.0, problem.K, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
    assert fresh.norm() == 0.0
    fresh.destroy()
    _same_on_one_rank(r, lambda comm: _block_slide(comm, element))


def test_moderate_sliding_drops_on_a_hold():
    """What large sliding fixes: moderate sliding pairs once per increment, on the start
    configuration, so the slab's load lags one increment behind the slider; the hold's
    re-pairing moves it under the slider, and points unload into stick."""
    r = _run(MPI.COMM_WORLD, "moderate", FORWARD + HOLD1, scene_kw=dict(slab_length=4.0))
    F = _forces(r)
    assert abs(F[7, 0]) < (1.0 - 5e-3) * MU * abs(F[7, 2])


def _frictionless(comm, sliding, n):
    path = [(1.0 + (j + 1) / n, 5 * H_SLAB * (j + 1) / n) for j in range(n)]
    return _run(comm, sliding, path, friction=0.0, scene_kw=dict(slab_length=4.0))


def test_large_sliding_does_not_lag():
    """A frictionless slider moved 5 slab elements in 1 increment ends where it ends in 8
    increments (the end state is elastic: path-independent), and the slab carries its load
    under the slider's centre; moderate sliding in 1 increment leaves the load behind."""
    one = _frictionless(MPI.COMM_WORLD, "large", 1)
    many = _frictionless(MPI.COMM_WORLD, "large", 8)
    du = np.abs(one["problem"].u.x.array - many["problem"].u.x.array).max()
    du = MPI.COMM_WORLD.allreduce(float(du), op=MPI.MAX)
    assert du <= 1e-8 * many["u_max"]
    assert one["x_load"] == pytest.approx(5 * H_SLAB, abs=1e-3 * H_SLAB)
    lagging = _frictionless(MPI.COMM_WORLD, "moderate", 1)
    assert abs(lagging["x_load"] - 5 * H_SLAB) > 0.5 * 5 * H_SLAB


# off the edge: on Q2 the coarse mesh's normal force depends on where the slider's edges sit
# on the slab's elements by more than the slide changes it while the slider is still fully on
# the slab (+0.14 % at 0.4 mm, docs/sliding_p2.md), so Q2 slides on 0.125 mm elements (a
# narrower scene, 0.25 mm wide, to stay fast)
EDGE_ELEMENTS = {"Q1 hexahedra": {},
                 "Q2 hexahedra": dict(order=2, size_slab=0.125, size_slider=0.125,
                                      h_slab=0.25, h_slider=0.25, width=0.25),
                 "P1 tetrahedra": ELEMENTS["P1 tetrahedra"],
                 "P2 tetrahedra": ELEMENTS["P2 tetrahedra"]}


def _slide_off(comm, element="Q1 hexahedra"):
    # slab 2 mm long (|x| <= 1), slider 1 mm: fully off the slab at 1.5 mm
    path = [(1.0 + 0.1 * (j + 1), 0.2 * (j + 1)) for j in range(8)]
    return _run(comm, "large", path, normal=2e-3,
                scene_kw=dict(slab_length=2.0, **EDGE_ELEMENTS[element]))


@pytest.mark.parametrize("element", list(EDGE_ELEMENTS))
def test_body_sliding_off_the_edge_loses_contact_smoothly(element):
    r = _slide_off(MPI.COMM_WORLD, element)
    ci, incs = r["ci"], r["incs"]
    assert len(incs) == 10 and all(inc.cutbacks == 0 for inc in incs)
    fz = _forces(r)[:, 2]
    assert fz[1] > 0.0 and np.all(np.diff(fz[1:]) <= 1e-12 * fz[1])   # never grows back
    assert fz[-1] == 0.0 and r["active"][-1] == 0                     # all off: no contact
    # in between, the active points are exactly those over the slab
    assert 0 < r["active"][5] < r["active"][1] == incs[0].n_points
    _same_on_one_rank(r, lambda comm: _slide_off(comm, element))


def test_points_off_the_slab_are_inactive_by_geometry():
    """Half-way off (slid 1 mm): a point is active iff its current x lies within the slab."""
    r = _run(MPI.COMM_WORLD, "large", [(1.0 + 0.1 * (j + 1), 0.2 * (j + 1)) for j in range(5)],
             normal=2e-3, scene_kw=dict(slab_length=2.0))
    ci, problem = r["ci"], r["problem"]
    u = compat.function_values(problem.u).reshape(-1, 3)
    x = ci.paired.x + np.einsum("fqk,fki->fqi", ci.paired.N1,
                                u[ci.pairing._ctx.geo1.local_nodes]).reshape(-1, 3)
    over = x[:, 0] <= 1.0
    assert np.array_equal(ci.active, over)
    n_over = MPI.COMM_WORLD.allreduce(int(over.sum()), op=MPI.SUM)
    assert 0 < n_over < ci.n_points_global
    res = ci._result()
    assert np.all(res.traction[~ci.active] == 0.0) and not res.contact[~ci.active].any()


def test_sliding_options_refuse_bad_input():
    from rough_contact.fem.rigid import RigidSphere
    scene = _scene(MPI.COMM_WORLD, slab_length=4.0)
    V = compat.vector_space(scene.mesh, 1)
    law = SoftplusPenalty(1e6, 1e-5)
    first, second = scene.contact_pair
    sphere = RigidSphere((0.0, 0.0, -10.0), 10.0)
    with pytest.raises(ValueError, match="cell_type = 'prism' is invalid; valid values"):
        slider_on_slab(cell_type="prism", comm=MPI.COMM_WORLD)
    with pytest.raises(ValueError, match="sliding_tolerance = 0.0 is invalid: it must be finite and > 0"):
        ContactInterface(V, scene.facet_tags, first, second, law=law, sliding="large",
                         sliding_tolerance=0.0)
    with pytest.raises(ValueError, match="max_repairs = 0 is invalid: it must be an integer"):
        ContactInterface(V, scene.facet_tags, first, second, law=law, sliding="large",
                         max_repairs=0)
    with pytest.raises(TypeError, match="rigid_motion .* must be a callable"):
        ContactInterface(V, scene.facet_tags, first, law=law, rigid=sphere,
                         rigid_motion=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="rigid_motion moves a rigid counter-surface"):
        ContactInterface(V, scene.facet_tags, first, second, law=law,
                         rigid_motion=lambda t: (t, 0.0, 0.0))
    with pytest.raises(ValueError, match="sliding = 'large' needs a deformable second surface"):
        ContactInterface(V, scene.facet_tags, first, law=law, sliding="large")
    with pytest.raises(ValueError, match=r"rigid_motion\(0.0\) = \[0.0, 0.0\] is invalid: it "
                       "must be 3 finite numbers"):
        ContactInterface(V, scene.facet_tags, first, law=law, rigid=sphere, sliding="large",
                         rigid_motion=lambda t: (t, 0.0))
    ci = ContactInterface(V, scene.facet_tags, first, law=law, rigid=sphere, sliding="large",
                          rigid_motion=lambda t: (t, 0.0, 1.0 if t < 1.0 else np.inf))
    assert ci.translation.tolist() == [0.0, 0.0, 1.0]      # where the motion starts
    with pytest.raises(ValueError, match=r"rigid_motion\(1.0\) = \[1.0, 0.0, inf\] is invalid"):
        ci.set_load_factor(1.0)


def test_points_that_left_arrive_again():
    """Frictionless slider driven half off the slab's edge and back: the points that left
    arrive again and the end state is the pressed state (elastic: path-independent)."""
    out = [(1.0 + 0.1 * (j + 1), 0.2 * (j + 1)) for j in range(5)]
    back = [(1.5 + 0.1 * (j + 1), 1.0 - 0.2 * (j + 1)) for j in range(5)]
    r = _run(MPI.COMM_WORLD, "large", out + back, friction=0.0, normal=2e-3,
             scene_kw=dict(slab_length=2.0))
    F, n_pts = _forces(r), r["incs"][0].n_points
    assert min(r["active"]) < n_pts // 2 + n_pts // 10 and r["active"][-1] == n_pts
    np.testing.assert_allclose(F[-1], F[1], rtol=0, atol=1e-8 * abs(F[1, 2]))
