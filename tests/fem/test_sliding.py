"""Moderate sliding (``ContactInterface(sliding="moderate")``): a slider pressed on a long slab
(meshed independently, hexahedra 0.1 / 0.125 mm) and pushed 0.6 mm along it — six slab elements —
then held. Serial and ``mpirun -n 2``.

References (not from this code's interface): the slab's equilibrium — the moment of its bottom
reaction about the y axis over its vertical reaction is the x position of the load it carries,
which must be the slider's centre (the slider is symmetric and, frictionless, carries no
tangential force); the vertical force balance; Coulomb's bound in gross slip (|F_x| = mu P).
With small sliding (pairing kept from set-up) the load stays where the slider started — the
test shows the difference.
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

E, NU, P_TOP, SLIDE = 2.0e5, 0.3, 20.0, 0.6


def _program(n_slide=6):
    def ramp(t):
        return min(max(t, 0.0), 1.0)

    times = [0.5, 1.0] + [1.0 + (j + 1) / n_slide for j in range(n_slide)] + [3.0]
    return LoadProgram({"press": ramp, "slide": lambda t: ramp(t - 1.0)}, times)


_SCENE = {}


def _scene():
    """Built once: a second build of the same mesh may be partitioned differently on 2 ranks,
    and a checkpoint only resumes into the partition it was written from."""
    if "s" not in _SCENE:
        _SCENE["s"] = slider_on_slab(comm=MPI.COMM_WORLD)
    return _SCENE["s"]


def _run(sliding, friction=0.0, **path):
    comm = MPI.COMM_WORLD
    scene = _scene()
    V = compat.vector_space(scene.mesh, 1)

    def roller(name):
        dofs = fem.locate_dofs_topological(V.sub(1), 2, scene.facet_tags.find(scene.tag(name)))
        return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(1))

    bcs = [roller("y0_slider"), roller("y0_slab")]
    law = SoftplusPenalty(1e6, 1e-5, k_tangential=1e6 if friction else 0.0, friction=friction)
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, bcs=bcs,
                          sliding=sliding)
    prog = _program()
    bottom, top = scene.tag("bottom"), scene.tag("top")
    problem = ContactProblem(
        V, Material(E, NU), bcs, [SurfaceLoad(top, traction=(0.0, 0.0, -P_TOP),
                                              channel="press")],
        facet_tags=scene.facet_tags, interface=ci,
        prescribed=[PrescribedDisplacement(bottom, (0.0, 0.0, 0.0), channel="press"),
                    PrescribedDisplacement(top, (SLIDE, 0.0, 0.0), (0,), channel="slide")],
        programs=prog.channels)
    solver = SNESSolver(problem, prefix="test_sliding_")
    incs = list(load_path(problem, solver, prog.times, verbose=False, friction_check=False,
                          **path))
    # the slab's bottom reaction: force and moment about the y axis, from its own equilibrium
    u, v = problem.u, ufl.TestFunction(V)
    mu_l, lmbda = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))

    def sigma(w):
        eps = ufl.sym(ufl.grad(w))
        return 2 * mu_l * eps + lmbda * ufl.tr(eps) * ufl.Identity(3)

    r = fem_petsc.assemble_vector(fem.form(ufl.inner(sigma(u), ufl.sym(ufl.grad(v))) * ufl.dx))
    r.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dofs = fem.locate_dofs_topological(V, 2, scene.facet_tags.find(bottom))
    dofs = dofs[dofs < V.dofmap.index_map.size_local]
    rz = r.getArray().reshape(-1, 3)[dofs, 2]
    x = V.tabulate_dof_coordinates()[dofs, 0]
    fz, mz = comm.allreduce(np.array([rz.sum(), (x * rz).sum()]), op=MPI.SUM)
    out = dict(incs=incs, x_load=mz / fz, u=problem.u.x.array.copy(), fz=fz, P=P_TOP * 1.0 * 0.5, ci=ci,
               F=incs[-1].contact_force, n_repairs=ci.n_repairs)
    solver.destroy()
    return out


def test_frictionless_slider_carries_its_load_along():
    moved = _run("moderate")
    assert moved["n_repairs"] >= 5                       # the partners changed as it slid
    assert moved["fz"] == pytest.approx(moved["P"], rel=1e-6)
    for inc in moved["incs"]:                            # vertical balance at every increment
        assert abs(inc.contact_force[2] + inc.applied_force[2]) <= 1e-6 * moved["P"]
    assert abs(moved["F"][0]) <= 1e-6 * moved["P"]        # frictionless: no tangential force
    # the load the slab carries sits under the slider's centre, which is now at x = SLIDE
    assert moved["x_load"] == pytest.approx(SLIDE, abs=0.01 * SLIDE)
    kept = _run("small")                                 # pairs kept from set-up
    assert abs(kept["x_load"]) < 0.1 * SLIDE              # the load stayed behind


def test_slider_in_gross_slip_transmits_mu_p():
    mu = 0.3
    r = _run("moderate", friction=mu)
    assert r["n_repairs"] >= 5
    # gross slip at the end of the slide and at the hold: |F_x| = mu P (softplus + return map)
    assert abs(r["incs"][-2].contact_force[0]) == pytest.approx(mu * r["P"], rel=1e-3)
    assert r["fz"] == pytest.approx(r["P"], rel=1e-6)


def test_moderate_sliding_refuses_what_it_cannot_do():
    scene = slider_on_slab(comm=MPI.COMM_WORLD)
    V = compat.vector_space(scene.mesh, 1)
    law = SoftplusPenalty(1e6, 1e-5)
    with pytest.raises(ValueError, match="sliding = 'moderate' needs a deformable second"):
        ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, sliding="moderate",
                         pairing="mortar")
    with pytest.raises(ValueError, match="sliding = 'huge' is invalid: it must be 'small', "
                       "'moderate' or 'large'"):
        ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law, sliding="huge")


@pytest.mark.parametrize("sliding", ["moderate", "large"])
def test_sliding_resumes_exactly(tmp_path, sliding):
    """A checkpoint holds the pairing its increment used: stopped after 5 increments (mid-slide,
    partners already changed) and resumed, the run ends as the uninterrupted one (displacements
    to 1e-12 of their maximum)."""
    directory = MPI.COMM_WORLD.bcast(str(tmp_path / "ck"), root=0)
    full = _run(sliding, friction=0.3)
    part = _run(sliding, friction=0.3, checkpoint=directory, max_steps=5)
    assert len(part["incs"]) == 5 and part["n_repairs"] >= 2
    rest = _run(sliding, friction=0.3, checkpoint=directory, resume=directory)
    assert [i.step for i in rest["incs"]] == [i.step for i in full["incs"]][5:]
    scale = MPI.COMM_WORLD.allreduce(float(np.abs(full["u"]).max()), op=MPI.MAX)
    np.testing.assert_allclose(rest["u"], full["u"], rtol=0, atol=1e-12 * scale)
    # forces: sums of k x jump over the points; on 2 ranks the resumed run is not bitwise the
    # uninterrupted one (measured 2e-12 of P), so the bound is 1e-10 of P
    np.testing.assert_allclose(rest["F"], full["F"], rtol=0, atol=1e-10 * full["P"])

