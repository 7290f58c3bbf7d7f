"""Non-matching interfaces: two blocks meshed independently (``separate_blocks``).

* Patch test (the reference: a uniform pressure must cross any interface exactly, since the
  exact solution — uniform stress, linear displacements — lies in every body's FE space):
  segment-to-segment integration (``pairing="mortar"``) transmits it to 1e-8 on element-size
  ratios 5:7 and 1:3, either side first, P1/P2 tetrahedra and Q1/Q2 hexahedra, frictionless
  and with Coulomb friction (no slip: the blocks have the same lateral strain). The Gauss-point
  projection (``pairing="projection"``) is exact only when each first facet lies inside one
  second facet (nested meshes, fine side first), checked too.
* Rank independence (serial = 2 ranks to 1e-10) of residual, Jacobian, force and area at a
  smooth non-uniform displacement, both non-matching pairings; finite-difference Jacobian.
* Errors: surfaces that face the same way, surfaces far apart, invalid knobs.

Run serial and in parallel:
    .venv/bin/python -m pytest tests/fem/test_nonmatching.py
    mpirun -n 2 .venv/bin/python -m pytest tests/fem/test_nonmatching.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
from rough_contact.io.interface_output import facet_output
from rough_contact.scenes.meshes.blocks import separate_blocks
from rough_contact.solver.snes import SNESSolver

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: shared checks
from interface_checks import interpolate_two_bodies, residual_jacobian_figures  # noqa: E402

E, NU = 2.0e5, 0.25


def roller(V, scene, name, comp):
    facets = scene.facet_tags.find(scene.tag(name))
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, facets)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


def patch(cell_type, order, size_lower, size_upper, first, pairing, law, E_lower,
          p=80.0, comm=MPI.COMM_WORLD):
    """Uniform pressure p on the top of two separately meshed blocks on rollers; returns the
    largest pressure and shear errors (relative to p), the contact force and the interface."""
    scene = separate_blocks(h1=1.0, h2=0.5, size_lower=size_lower, size_upper=size_upper,
                            order=order, cell_type=cell_type, comm=comm)
    V = compat.vector_space(scene.mesh, order)
    bcs = [roller(V, scene, "x0", 0), roller(V, scene, "y0", 1), roller(V, scene, "bottom", 2)]
    a, b = scene.contact_pair
    if first == "lower":
        a, b = b, a
    ci = ContactInterface(V, scene.facet_tags, a, b, law=law, bcs=bcs,
                          quadrature_degree=2 * order, pairing=pairing)
    assert ci.pairing_used == pairing
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(E_lower, NU)}
    problem = ContactProblem(V, mats, bcs, [SurfaceLoad(scene.tag("top"), traction=[0, 0, -p])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="test_nonmatching_")
    problem.set_load_factor(1.0)
    result = solver.solve()
    assert result.converged
    ci.evaluate(problem.u)
    pf = ci.point_fields()
    real = pf.weight > 0          # mortar facets repeat a point with weight 0 to fill slots
    c = scene.mesh.comm
    p_err = c.allreduce(float(np.max(np.abs(pf.pressure[real] - p), initial=0.0)), op=MPI.MAX)
    s_err = c.allreduce(float(np.max(np.abs(pf.shear[real]), initial=0.0)), op=MPI.MAX)
    slipping = c.allreduce(int(pf.slipping[real].sum()), op=MPI.SUM)
    force = ci.contact_force()
    summary = ci.summary()
    # issue 24, item 11: the header's count (n_points_global) is the increments' count, the
    # points with weight; the mortar's slot-filling copies are counted apart (n_slots_global)
    n_real = c.allreduce(int(real.sum()), op=MPI.SUM)
    assert ci.n_points_global == summary.n_points == n_real
    assert ci.n_slots_global == c.allreduce(ci.n_points, op=MPI.SUM) >= n_real
    facets = facet_output(ci)          # what the XDMF writer writes per facet
    f_err = c.allreduce(float(np.max(np.abs(facets.pressure - p), initial=0.0)), op=MPI.MAX)
    assert f_err <= 1e-8 * p
    assert abs(c.allreduce(float(facets.area.sum()), op=MPI.SUM) - 1.0) <= 1e-10
    solver.destroy()
    return p_err / p, s_err / p, force, summary, slipping


CASES = [  # cell type, order, lower size, upper size, first surface
    ("tetrahedron", 1, 0.2, 0.28, "upper"),        # 5:7
    ("tetrahedron", 2, 0.2, 0.28, "lower"),
    ("tetrahedron", 1, 0.1, 0.3, "lower"),         # 1:3, fine side first
    ("tetrahedron", 1, 0.3, 0.1, "lower"),         # 3:1, coarse side first
    ("hexahedron", 1, 1 / 5, 1 / 7, "upper"),
    ("hexahedron", 2, 1 / 5, 1 / 7, "lower"),
    ("hexahedron", 1, 1 / 3, 1 / 9, "lower"),      # coarse first, nested
]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0][:3]}-P{c[1]}-"
                         f"{c[2]:.3g}:{c[3]:.3g}-{c[4]}")
def test_mortar_patch_frictionless(case):
    """Uniform pressure crosses a non-matching interface exactly (different block stiffness:
    the blocks slide laterally against each other, the law carries no shear); the facet
    output (quadrature averages, weight-0 slot copies included) shows it too."""
    p_err, s_err, force, summary, _ = patch(*case, "mortar", LinearPenalty(1e6), 0.5 * E)
    assert p_err <= 1e-8
    assert abs(force[2] / 80.0 - (1.0 if case[4] == "upper" else -1.0)) <= 1e-10
    assert abs(summary.nominal_area - 1.0) <= 1e-10


@pytest.mark.parametrize("case", [CASES[1], CASES[3], CASES[5]],
                         ids=lambda c: f"{c[0][:3]}-P{c[1]}-{c[2]:.3g}:{c[3]:.3g}-{c[4]}")
def test_mortar_patch_with_friction(case):
    """Coulomb friction, same material both sides: uniform pressure, no shear, no slip."""
    law = SoftplusPenalty(1e6, 1e-7, k_tangential=1e6, friction=0.3)
    p_err, s_err, force, summary, slipping = patch(*case, "mortar", law, E)
    assert p_err <= 1e-8
    assert s_err <= 1e-8
    assert slipping == 0


def test_projection_patch_nested_is_exact():
    """Gauss points of the fine side, each fine facet inside one coarse facet: exact."""
    for order in (1, 2):
        p_err, *_ = patch("hexahedron", order, 1 / 3, 1 / 9, "upper", "projection",
                          LinearPenalty(1e6), 0.5 * E)
        assert p_err <= 1e-8


def _figures(comm, pairing, order=2, fd=False):
    scene = separate_blocks(h1=1.0, h2=0.5, size_lower=0.2, size_upper=0.28, order=order,
                            comm=comm)
    V = compat.vector_space(scene.mesh, order)
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.2)
    moderate = pairing == "moderate"
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=law,
                          quadrature_degree=2 * order,
                          pairing="projection" if moderate else pairing,
                          sliding="moderate" if moderate else "small")
    u = fem.Function(V)
    interpolate_two_bodies(u, scene)
    if moderate:    # the upper face slid by up to 0.07 mm (a quarter element), 0 at its
        upper = scene.cell_tags.find(scene.tag("upper"))   # edges: it stays over the lower one
        shift = fem.Function(V)
        compat.interpolate(shift, lambda x: np.stack([0.07 * np.sin(np.pi * x[0]), 0 * x[0],
                                                       0 * x[0]]), cells=upper)
        u.x.array[:] += shift.x.array
        u.x.scatter_forward()
        ci.commit()          # a converged increment: the next one re-pairs
        ci.begin_increment(u)
        assert ci.comm.allreduce(ci.n_repairs, op=MPI.MAX) == 1
    return residual_jacobian_figures(ci, u, V, fd)


@pytest.mark.parametrize("pairing", ["projection", "mortar", "moderate"])
def test_rank_independent_and_jacobian(pairing):
    """Non-uniform state with friction: the same figures on all ranks and on one; the assembled
    Jacobian is the derivative of the assembled residual."""
    world, fd_err = _figures(MPI.COMM_WORLD, pairing, fd=True)
    serial, _ = _figures(MPI.COMM_SELF, pairing)
    np.testing.assert_allclose(world, serial, rtol=1e-10)
    assert abs(world[-1] - 1.0) <= 1e-10        # nominal area: the whole 1 x 1 face
    assert fd_err < 1e-6


def test_errors():
    comm = MPI.COMM_WORLD
    scene = separate_blocks(h1=1.0, h2=0.5, size_lower=0.5, size_upper=0.4, comm=comm)
    V = compat.vector_space(scene.mesh, 1)
    law = LinearPenalty(1.0)
    top, lower = scene.tag("top"), scene.tag("contact_lower")
    # the upper block's top faces up like the lower block's top: a wrong tag
    with pytest.raises(ValueError, match=r"have no partner on surface .* within the search "
                       r"radius"):
        ContactInterface(V, scene.facet_tags, top, lower, law=law, pairing="projection")
    with pytest.raises(ValueError, match=r"not fully covered by surface"):
        ContactInterface(V, scene.facet_tags, top, lower, law=law, pairing="mortar")
    # the bottom of the lower block, 1 mm below its top, faces down: wrong way + far
    bottom = scene.tag("bottom")
    upper = scene.tag("contact_upper")
    with pytest.raises(ValueError, match=r"no partner"):
        ContactInterface(V, scene.facet_tags, upper, bottom, law=law, pairing="projection",
                         search_radius=0.1)
    with pytest.raises(ValueError, match="pairing = 'mortar' needs a second surface"):
        ContactInterface(V, scene.facet_tags, upper, law=law, pairing="mortar",
                         rigid_plane=((0, 0, 0), (0, 0, 1)))
    with pytest.raises(ValueError, match="pairing = 'nts' is invalid"):
        ContactInterface(V, scene.facet_tags, upper, lower, law=law, pairing="nts")
    # a conforming pairing is refused on these meshes, with the conforming message
    with pytest.raises(ValueError, match="must be conforming"):
        ContactInterface(V, scene.facet_tags, upper, lower, law=law, pairing="conforming")
    # auto falls back to the projection
    ci = ContactInterface(V, scene.facet_tags, upper, lower, law=law)
    assert ci.pairing_used == "projection"


def _write_block_msh(path, z0, height, size, prefix, body_tag, tag0, order=1):
    """A block [0, 1]^2 x [z0, z0 + height] as its own .msh file (gmsh, rank 0 only)."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(prefix)
        box = gmsh.model.occ.addBox(0, 0, z0, 1, 1, height)
        gmsh.model.occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [box], body_tag)
        gmsh.model.setPhysicalName(3, body_tag, prefix)
        names = {"bottom": lambda c: abs(c[2] - z0) < 1e-9,
                 "top": lambda c: abs(c[2] - z0 - height) < 1e-9,
                 "x0": lambda c: abs(c[0]) < 1e-9, "y0": lambda c: abs(c[1]) < 1e-9}
        for k, (name, sel) in enumerate(names.items()):
            faces = [t for _, t in gmsh.model.getEntities(2)
                     if sel(gmsh.model.occ.getCenterOfMass(2, t))]
            gmsh.model.addPhysicalGroup(2, faces, tag0 + k)
            gmsh.model.setPhysicalName(2, tag0 + k, f"{prefix}_{name}")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def _assert_parts_transmit_pressure(scene, order, prefix, p=80.0):
    """The blocks of :func:`_write_block_msh` read as one scene, the upper one pressed by ``p``
    on its top, both on rollers: the mortar pairing transmits ``p`` exactly (patch test)."""
    V = compat.vector_space(scene.mesh, order)
    bcs = [roller(V, scene, f"{b}_{s}", c) for b in ("lower", "upper")
           for s, c in (("x0", 0), ("y0", 1))] + [roller(V, scene, "lower_bottom", 2)]
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair, law=LinearPenalty(1e6),
                          bcs=bcs, pairing="mortar", quadrature_degree=2 * order)
    mats = {scene.tag("upper"): Material(E, NU), scene.tag("lower"): Material(0.5 * E, NU)}
    problem = ContactProblem(V, mats, bcs, [SurfaceLoad(scene.tag("upper_top"),
                                                        traction=[0, 0, -p])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix=prefix)
    problem.set_load_factor(1.0)
    assert solver.solve().converged
    ci.evaluate(problem.u)
    pf = ci.point_fields()
    real = pf.weight > 0
    err = scene.mesh.comm.allreduce(float(np.abs(pf.pressure[real] - p).max(initial=0.0)),
                                    op=MPI.MAX)
    assert err <= 1e-8 * p
    solver.destroy()


def test_two_msh_files_make_one_scene(tmp_path):
    """Two blocks meshed in two .msh files (sizes 0.2 and 0.28) make one scene; the mortar
    pairing between them transmits a uniform pressure exactly (patch test)."""
    from rough_contact.fem.mesh import scene_from_msh_files

    comm = MPI.COMM_WORLD
    folder = comm.bcast(str(tmp_path), root=0)
    lower, upper = f"{folder}/lower.msh", f"{folder}/upper.msh"
    if comm.rank == 0:
        _write_block_msh(lower, -1.0, 1.0, 0.2, "lower", 2, 20)
        _write_block_msh(upper, 0.0, 0.5, 0.28, "upper", 1, 10)
    comm.Barrier()
    scene = scene_from_msh_files([lower, upper], comm,
                                 contact_pair=("upper_bottom", "lower_top"))
    _assert_parts_transmit_pressure(scene, 1, "test_msh_files_")
    with pytest.raises(ValueError, match="share physical group names"):
        scene_from_msh_files([lower, lower], comm, contact_pair=("lower_top", "lower_top"))
    with pytest.raises(ValueError, match="does not exist"):
        scene_from_msh_files([lower, f"{folder}/nothing.msh"], comm,
                             contact_pair=("lower_top", "x"))


@pytest.mark.parametrize("order", [1, 2])
def test_two_xdmf_files_make_one_scene(tmp_path, order):
    """Two parts meshed and saved separately as DOLFINx XDMF files (mesh, cell tags, facet
    tags; sizes 0.2 and 0.28, P1 and P2) make one scene with their tags; the mortar pairing
    between them transmits a uniform pressure exactly (patch test)."""
    from rough_contact.fem.mesh import measure_of, scene_from_msh_files, scene_from_xdmf_files
    from rough_contact.fem.mesh import write_xdmf

    comm = MPI.COMM_WORLD
    folder = comm.bcast(str(tmp_path), root=0)
    labels = {}
    for name, z0, h, size, body, tag0 in (("lower", -1.0, 1.0, 0.2, 2, 20),
                                          ("upper", 0.0, 0.5, 0.28, 1, 10)):
        if comm.rank == 0:
            _write_block_msh(f"{folder}/{name}.msh", z0, h, size, name, body, tag0, order)
        comm.Barrier()
        part = scene_from_msh_files([f"{folder}/{name}.msh"], comm,
                                    contact_pair=(f"{name}_top", f"{name}_bottom"))
        write_xdmf(part, f"{folder}/{name}.xdmf")      # what a user's own script would write
        labels[name] = part.labels
    scene = scene_from_xdmf_files([(f"{folder}/lower.xdmf", labels["lower"]),
                                   (f"{folder}/upper.xdmf", labels["upper"])], comm,
                                  contact_pair=("upper_bottom", "lower_top"))
    assert scene.order == order and set(scene.bodies) == {"lower", "upper"}
    for name, value in (("lower", 1.0), ("upper", 0.5), ("upper_bottom", 1.0), ("lower_x0", 1.0)):
        assert measure_of(scene, name) == pytest.approx(value, rel=1e-10), name
    _assert_parts_transmit_pressure(scene, order, "test_xdmf_files_")
    with pytest.raises(ValueError, match=r"tags \[1\d\] have no name|tags \[.*\] have no name"):
        scene_from_xdmf_files([(f"{folder}/upper.xdmf", {"upper": 1})], comm,
                              contact_pair=("upper", "upper"))
    with pytest.raises(ValueError, match="does not exist"):
        scene_from_xdmf_files([(f"{folder}/none.xdmf", {})], comm, contact_pair=("a", "b"))



@pytest.mark.parametrize("pairing", ["projection", "auto"])
def test_larger_first_surface_says_swap(pairing):
    """Issue 24, item 12: a slab 3 mm long given as the first surface and a slider 1 mm long
    as the second: the slab's points beyond the slider's edge have no partner and no search
    radius gives them one. The error says which surface is larger and to swap them, as the
    mortar's does, instead of "raise search_radius"; with the surfaces swapped it pairs."""
    from rough_contact.scenes.meshes.blocks import slider_on_slab

    scene = slider_on_slab(size_slab=0.25, size_slider=0.2)
    V = compat.vector_space(scene.mesh, 1)
    slider, slab = scene.contact_pair
    with pytest.raises(ValueError) as err:
        ContactInterface(V, scene.facet_tags, slab, slider, law=LinearPenalty(1.0),
                         pairing=pairing, search_radius=10.0)
    msg = str(err.value)
    assert f"Surface {slab} (1.5 mm^2) is larger than surface {slider} (0.5 mm^2)" in msg
    assert "swap first_tag and second_tag" in msg and "raise search_radius" not in msg
    assert ("pairing = 'auto'" in msg) == (pairing == "auto")
    ci = ContactInterface(V, scene.facet_tags, slider, slab, law=LinearPenalty(1.0),
                          pairing=pairing)
    assert ci.pairing_used == "projection"
    assert abs(ci.nominal_area() - 0.5) <= 1e-12
