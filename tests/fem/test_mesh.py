"""Scenes from gmsh: volumes, areas, conforming contact faces, disconnected bodies.

Run serial and on two ranks:
    .venv/bin/python -m pytest tests/fem/test_mesh.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_mesh.py
The reference values are the exact geometry of each scene (box volumes and face areas).
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem import compat
from rough_contact.scenes.meshes.beam import beam_on_base
from rough_contact.scenes.meshes.blocks import block_on_plane, two_blocks
from rough_contact.scenes.meshes.flat_punch import flat_punch
from rough_contact.fem.mesh import (add_groups, build_scene, check_conformity, entity_centers,
                                    facet_vertex_coordinates, measure_of, owned_facets)

logging.getLogger().setLevel(logging.WARNING)  # silence JIT compilation messages

COMM = MPI.COMM_WORLD


def global_cell_vertices(scene, body):
    """Global indices of the vertices of the cells of ``body``, gathered on every rank."""
    msh = scene.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim, 0)
    c2v = msh.topology.connectivity(tdim, 0)
    cells = scene.cell_tags.find(scene.tag(body))
    local = np.unique(c2v.array.reshape(msh.topology.index_map(tdim).size_local
                                        + msh.topology.index_map(tdim).num_ghosts, -1)[cells])
    glob = msh.topology.index_map(0).local_to_global(local.astype(np.int32))
    return np.unique(np.concatenate(COMM.allgather(np.asarray(glob, dtype=np.int64))))


def counts(scene):
    """Global numbers of cells, vertices, and owned facets per surface tag."""
    msh = scene.mesh
    tdim = msh.topology.dim
    out = {"cells": msh.topology.index_map(tdim).size_global,
           "vertices": msh.topology.index_map(0).size_global}
    for name, tag in scene.labels.items():
        if name not in scene.bodies:
            out[name] = COMM.allreduce(len(owned_facets(scene, tag)))
    return out


def check_disconnected(scene):
    first, second = scene.bodies
    v1 = global_cell_vertices(scene, first)
    v2 = global_cell_vertices(scene, second)
    assert len(np.intersect1d(v1, v2)) == 0
    assert len(v1) + len(v2) == scene.mesh.topology.index_map(0).size_global


@pytest.fixture(scope="module", params=[("tetrahedron", 1), ("tetrahedron", 2),
                                        ("hexahedron", 1), ("hexahedron", 2)],
                ids=["P1", "P2", "Q1", "Q2"])
def blocks(request):
    cell_type, order = request.param
    return two_blocks(lx=2.0, ly=1.0, h1=0.5, h2=1.0, mesh_size=0.35, order=order,
                      cell_type=cell_type)


def test_blocks_labels_and_pair(blocks):
    assert blocks.bodies == ("upper", "lower")
    assert blocks.contact_pair == (blocks.tag("contact_upper"), blocks.tag("contact_lower"))
    assert blocks.rigid_plane is None
    assert blocks.cell_type in ("tetrahedron", "hexahedron")
    with pytest.raises(ValueError, match="no_such_surface"):
        blocks.tag("no_such_surface")


def test_blocks_volumes_and_areas(blocks):
    lx, ly, h1, h2 = 2.0, 1.0, 0.5, 1.0
    expected = {"upper": lx * ly * h2, "lower": lx * ly * h1, "contact_upper": lx * ly,
                "contact_lower": lx * ly, "top": lx * ly, "bottom": lx * ly,
                "x0": ly * (h1 + h2), "x1": ly * (h1 + h2), "y0": lx * (h1 + h2),
                "y1": lx * (h1 + h2)}
    assert set(expected) == set(blocks.labels)
    for name, value in expected.items():
        assert measure_of(blocks, name) == pytest.approx(value, rel=1e-12), name


def test_blocks_conforming_and_disconnected(blocks):
    report = check_conformity(blocks)
    assert report.conforming, report
    assert report.n_first > 0 and report.max_distance == 0.0
    check_disconnected(blocks)
    # contact facets of the upper block lie on z = 0 and belong to upper-block cells
    xyz = facet_vertex_coordinates(blocks, blocks.tag("contact_upper"))
    assert np.all(xyz[:, :, 2] == 0.0)


def test_blocks_structured_hexahedra_counts(blocks):
    """ceil(length / mesh_size) hexahedra along each box edge: 6 x 3 x (2 + 3)."""
    if blocks.cell_type != "hexahedron":
        pytest.skip("structured counts apply to hexahedra")
    assert blocks.mesh.topology.index_map(3).size_global == 6 * 3 * (2 + 3)
    assert COMM.allreduce(len(owned_facets(blocks, blocks.contact_pair[0]))) == 6 * 3


def test_blocks_outward_normal_of_first_surface_points_down(blocks):
    """The first contact surface is the upper block's bottom: its cells lie above it."""
    msh = blocks.mesh
    tdim = msh.topology.dim
    facets = owned_facets(blocks, blocks.contact_pair[0])
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    cells = np.array([f2c.links(f)[0] for f in facets], dtype=np.int32)
    assert np.all(np.isin(cells, blocks.cell_tags.find(blocks.tag("upper"))))
    mid = dolfinx_midpoints(msh, tdim, cells)
    assert np.all(mid[:, 2] > 0)


def dolfinx_midpoints(msh, dim, entities):
    import dolfinx.mesh
    return dolfinx.mesh.compute_midpoints(msh, dim, entities)


def test_blocks_independent_of_ranks(blocks):
    serial = two_blocks(lx=2.0, ly=1.0, h1=0.5, h2=1.0, mesh_size=0.35, order=blocks.order,
                        cell_type=blocks.cell_type, comm=MPI.COMM_SELF)
    ref = {"cells": serial.mesh.topology.index_map(3).size_global,
           "vertices": serial.mesh.topology.index_map(0).size_global}
    ref.update({n: len(owned_facets(serial, t)) for n, t in serial.labels.items()
                if n not in serial.bodies})
    assert counts(blocks) == ref


@pytest.mark.parametrize("order", [1, 2])
def test_block_on_plane(order):
    scene = block_on_plane(lx=1.0, ly=2.0, h=0.5, mesh_size=0.4, order=order)
    assert scene.contact_pair == (scene.tag("contact"), None)
    point, normal = scene.rigid_plane
    assert np.allclose(point, 0) and np.allclose(normal, [0, 0, 1])
    assert measure_of(scene, "block") == pytest.approx(1.0, rel=1e-12)
    assert measure_of(scene, "contact") == pytest.approx(2.0, rel=1e-12)
    with pytest.raises(ValueError, match="rigid plane"):
        check_conformity(scene)


def test_bad_input_raises():
    with pytest.raises(ValueError, match="mesh_size"):
        two_blocks(mesh_size=-1.0)
    with pytest.raises(ValueError, match="order"):
        two_blocks(order=3)
    with pytest.raises(ValueError, match="cell_type"):
        two_blocks(cell_type="prism")
    with pytest.raises(ValueError, match="foundation_half_width"):
        flat_punch(foundation_half_width=5.0)
    with pytest.raises(ValueError, match="load_half_length"):
        beam_on_base(load_half_length=300.0)


@pytest.fixture(scope="module", params=[("tetrahedron", 1), ("tetrahedron", 2),
                                        ("hexahedron", 1), ("hexahedron", 2)],
                ids=["P1", "P2", "Q1", "Q2"])
def punch(request):
    cell_type, order = request.param
    return flat_punch(mesh_size=12.5, contact_size=2.5, order=order, load_half_width=5.0,
                      cell_type=cell_type)


def longest_edge(scene, tag):
    """Longest facet edge (corner to corner) among the facets tagged ``tag``, global."""
    xyz = facet_vertex_coordinates(scene, tag)
    # DOLFINx vertex order: triangles (0, 1, 2), quadrilaterals tensor-product (0, 1, 3, 2)
    pairs = [(0, 1), (1, 2), (2, 0)] if xyz.shape[1] == 3 else [(0, 1), (1, 3), (3, 2), (2, 0)]
    local = max((np.linalg.norm(xyz[:, i] - xyz[:, j], axis=1).max() for i, j in pairs),
                default=0.0) if len(xyz) else 0.0
    return COMM.allreduce(local, op=MPI.MAX)


def test_punch_volumes_and_areas(punch):
    a, hp, L, H, b = 10.0, 10.0, 50.0, 50.0, 5.0
    expected = {"punch": a * a * hp, "foundation": L * L * H, "contact_punch": a * a,
                "contact_foundation": a * a, "load": b * b, "punch_top": a * a - b * b,
                "punch_sides": 2 * a * hp, "foundation_top": L * L - a * a,
                "symmetry_x": a * hp + L * H, "symmetry_y": a * hp + L * H, "fixed": L * L,
                "foundation_sides": 2 * L * H}
    assert set(expected) == set(punch.labels)
    for name, value in expected.items():
        assert measure_of(punch, name) == pytest.approx(value, rel=1e-12), name
    assert punch.bodies == ("punch", "foundation")
    assert punch.contact_pair == (punch.tag("contact_punch"), punch.tag("contact_foundation"))


def test_punch_conforming_and_disconnected(punch):
    report = check_conformity(punch)
    assert report.conforming, report
    check_disconnected(punch)


def facet_cells(scene, tag):
    msh = scene.mesh
    tdim = msh.topology.dim
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    return np.array([f2c.links(f)[0] for f in owned_facets(scene, tag)], dtype=np.int32)


def test_punch_contact_facets_belong_to_their_body(punch):
    for surface, body in [("contact_punch", "punch"), ("contact_foundation", "foundation")]:
        cells = facet_cells(punch, punch.tag(surface))
        assert np.all(np.isin(cells, punch.cell_tags.find(punch.tag(body)))), surface


def test_punch_refined_towards_contact(punch):
    """Contact facets have about contact_size edges; far cells are much larger."""
    longest = longest_edge(punch, punch.contact_pair[0])
    assert 0.5 * 2.5 < longest < 1.6 * 2.5
    assert longest_edge(punch, punch.tag("fixed")) > 3 * longest


def test_punch_graded_away_from_patch(punch):
    """Foundation-top facets touching the patch edge x = a are small, at x = L large."""
    xyz = facet_vertex_coordinates(punch, punch.tag("foundation_top"))
    extent = xyz[:, :, 0].max(axis=1) - xyz[:, :, 0].min(axis=1)
    near = np.isclose(xyz[:, :, 0].min(axis=1), 10.0)
    far = np.isclose(xyz[:, :, 0].max(axis=1), 50.0)
    near_max = COMM.allreduce(extent[near].max() if near.any() else 0.0, op=MPI.MAX)
    far_max = COMM.allreduce(extent[far].max() if far.any() else 0.0, op=MPI.MAX)
    assert 0 < near_max < 1.3 * 2.5
    assert far_max > 3 * 2.5


def test_punch_independent_of_ranks(punch):
    serial = flat_punch(mesh_size=12.5, contact_size=2.5, order=punch.order,
                        load_half_width=5.0, cell_type=punch.cell_type, comm=MPI.COMM_SELF)
    ref = {"cells": serial.mesh.topology.index_map(3).size_global,
           "vertices": serial.mesh.topology.index_map(0).size_global}
    ref.update({n: len(owned_facets(serial, t)) for n, t in serial.labels.items()
                if n not in serial.bodies})
    assert counts(punch) == ref


@pytest.mark.parametrize("cell_type, order", [("tetrahedron", 1), ("tetrahedron", 2),
                                             ("hexahedron", 1), ("hexahedron", 2)])
def test_beam(cell_type, order):
    w, hb, half, c = 10.0, 120.0, 250.0, 5.0
    scene = beam_on_base(mesh_size=40.0, contact_size=10.0, order=order,
                         load_half_length=c, cell_type=cell_type)
    expected = {"beam": w * hb * half, "contact_beam": w * half, "load": w * c,
                "top": w * (half - c), "sides": 2 * hb * half, "symmetry_y": w * hb,
                "end": w * hb}
    assert set(expected) == set(scene.labels)
    for name, value in expected.items():
        assert measure_of(scene, name) == pytest.approx(value, rel=1e-12), name
    assert scene.contact_pair == (scene.tag("contact_beam"), None)
    point, normal = scene.rigid_plane
    assert np.allclose(point, 0) and np.allclose(normal, [0, 0, 1])
    xyz = facet_vertex_coordinates(scene, scene.contact_pair[0])
    assert np.all(xyz[:, :, 2] == 0.0)


def _two_boxes(model):
    model.occ.addBox(0, 0, -1, 1, 1, 1)
    model.occ.addBox(0, 0, 0, 1, 1, 1)
    model.occ.fragment([(3, 1)], [(3, 2)])
    model.occ.synchronize()
    vols, vc = entity_centers(model, 3)
    add_groups(model, 3, {"up": (1, vols[vc[:, 2] > 0]), "down": (2, vols[vc[:, 2] < 0])})
    tags, c = entity_centers(model, 2)
    interface = tags[np.abs(c[:, 2]) < 1e-9]
    add_groups(model, 2, {"c_up": (11, interface), "c_down": (12, interface)})
    model.mesh.generate(3)


def test_errors_on_the_gmsh_rank_raise_on_every_rank():
    def build(model):
        raise ValueError("broken geometry")

    with pytest.raises(ValueError, match="broken geometry"):
        build_scene(COMM, "broken", build, split_body="up", contact_pair=("c_up", "c_down"))
    with pytest.raises(ValueError, match="split_body"):
        build_scene(COMM, "two_boxes", _two_boxes, split_body="nope",
                    contact_pair=("c_up", "c_down"))


def test_shared_surface_needs_an_owner():
    with pytest.raises(ValueError, match="touches 2 bodies"):
        build_scene(COMM, "two_boxes", _two_boxes, split_body="up",
                    contact_pair=("c_up", "c_down"))
    scene = build_scene(COMM, "two_boxes", _two_boxes, split_body="up",
                        contact_pair=("c_up", "c_down"),
                        surface_owners={"c_up": "up", "c_down": "down"})
    assert check_conformity(scene).conforming
    check_disconnected(scene)


# ------------------------------------------------------------------ nodes no cell uses
def _global_node_count(scene) -> int:
    im = scene.mesh.geometry.index_map()
    return im.size_global


def _used_nodes_global(scene) -> int:
    """Distinct geometry nodes referenced by the cells, counted over all ranks."""
    g = scene.mesh.geometry
    local = np.unique(compat.geometry_dofmap(scene.mesh))
    owned = local[local < g.index_map().size_local]
    return COMM.allreduce(int(owned.size))


def _two_boxes_and_stray_point(model):
    model.occ.addPoint(5.0, 5.0, 5.0)            # meshed (a node), used by no element
    _two_boxes(model)


def test_nodes_no_cell_uses_are_dropped():
    scene = build_scene(COMM, "stray", _two_boxes_and_stray_point, split_body="up",
                        contact_pair=("c_up", "c_down"),
                        surface_owners={"c_up": "up", "c_down": "down"})
    assert _global_node_count(scene) == _used_nodes_global(scene)
    assert np.isclose(COMM.allreduce(
        float(np.max(np.abs(scene.mesh.geometry.x[:, 0]), initial=0.0)), op=MPI.MAX), 1.0)
    assert check_conformity(scene).conforming


def test_surface_group_off_the_volumes_is_refused():
    def build(model):
        model.occ.addRectangle(3.0, 3.0, 5.0, 1.0, 1.0)   # a meshed surface outside the boxes
        _two_boxes(model)
        tags, c = entity_centers(model, 2)
        add_groups(model, 2, {"loose": (13, tags[c[:, 0] > 2.5])})
        model.mesh.generate(3)

    with pytest.raises(ValueError, match=r"surface element\(s\) of group\(s\) \['loose'\] use "
                       "nodes that no volume element uses"):
        build_scene(COMM, "loose", build, split_body="up", contact_pair=("c_up", "c_down"),
                    surface_owners={"c_up": "up", "c_down": "down", "loose": "up"})


@pytest.mark.parametrize("mesh_size, contact_size, order, cell_type", [
    (2.5, 0.833, 1, "tetrahedron"),      # segfaulted in distribute_entity_data before the fix
    (20.0, 2.5, 2, "tetrahedron"),
    (12.0, 1.7, 1, "tetrahedron"),
    (20.0, 2.5, 1, "hexahedron"),
    (20.0, 3.0, 2, "hexahedron"),
])
def test_punch_builder_sweep(mesh_size, contact_size, order, cell_type):
    scene = flat_punch(mesh_size=mesh_size, contact_size=contact_size, order=order,
                       cell_type=cell_type)
    assert _global_node_count(scene) == _used_nodes_global(scene)
    assert np.isclose(measure_of(scene, "contact_punch"), 100.0, rtol=1e-10)
    assert check_conformity(scene).conforming


def test_indented_block_ring_refines_the_band_only():
    """``ring=(radius, half_band, size)``: top facets inside the band have edges near ``size``,
    those well inside it keep the contact size (the distance field is exact)."""
    from rough_contact.scenes.meshes.blocks import indented_block

    h, ring = 0.1, (0.5, 0.1, 0.025)
    scene = indented_block(half_width=2.0, height=1.5, mesh_size=0.6, contact_size=h,
                           transition=0.5, refined_radius=1.0, half=True, ring=ring)
    xyz = facet_vertex_coordinates(scene, scene.tag("contact"))
    rho = np.linalg.norm(xyz.mean(axis=1)[:, :2], axis=1)
    edge = np.linalg.norm(xyz - np.roll(xyz, 1, axis=1), axis=2).max(axis=1)

    def count(sel):
        return COMM.allreduce(int(sel.sum()), op=MPI.SUM)

    def mean(sel):
        return COMM.allreduce(float(edge[sel].sum()), op=MPI.SUM) / count(sel)

    band = np.abs(rho - ring[0]) < 0.8 * ring[1]
    inner = rho < 0.15
    assert count(band) > 100 and count(inner) > 5
    assert mean(band) < 1.3 * ring[2]
    assert mean(inner) > 0.7 * h
    with pytest.raises(ValueError, match="ring_size"):
        indented_block(ring=(0.5, 0.1, 0.0))


def test_indented_block_ring_growth_refines_a_narrow_band_under_a_coarse_far_mesh():
    """A narrow ring on a large block with a coarse far mesh (the Mindlin energy scene's: band
    0.744-1.03 of a = 0.2 mm, 64 mm block, 16 mm far size): growing towards ``mesh_size`` over
    the band's width, the size passes the contact size within 2e-4 mm of the band and gmsh
    leaves the band under-refined (123 top facets in it, longest edges 3.1 x the ring size on
    average); with
    ``ring_growth`` (to the contact size over 2 half bands) the band's facets have the ring's
    size and the centre keeps the contact size."""
    from rough_contact.scenes.meshes.blocks import indented_block

    h, ring = 0.05, (0.1774, 0.0286, 0.008)
    scene = indented_block(half_width=64.0, height=64.0, mesh_size=16.0, contact_size=h,
                           transition=48.0, refined_radius=0.4, half=True, ring=ring,
                           ring_growth=2.0 * ring[1])
    xyz = facet_vertex_coordinates(scene, scene.tag("contact"))
    rho = np.linalg.norm(xyz.mean(axis=1)[:, :2], axis=1)
    edge = np.linalg.norm(xyz - np.roll(xyz, 1, axis=1), axis=2).max(axis=1)

    def mean(sel):
        n = COMM.allreduce(int(sel.sum()), op=MPI.SUM)
        return COMM.allreduce(float(edge[sel].sum()), op=MPI.SUM) / n, n

    band, n_band = mean(np.abs(rho - ring[0]) < 0.8 * ring[1])
    inner, n_inner = mean(rho < 0.05)
    assert n_band > 300 and n_inner > 2
    assert band < 1.3 * ring[2]
    assert inner > 0.7 * h
    with pytest.raises(ValueError, match="ring_growth"):
        indented_block(ring=(0.5, 0.1, 0.05), ring_growth=0.0)
    with pytest.raises(ValueError, match="ring size"):
        indented_block(contact_size=0.05, ring=(0.5, 0.1, 0.06), ring_growth=0.1)
    with pytest.raises(ValueError, match="without a ring"):
        indented_block(ring_growth=0.1)
