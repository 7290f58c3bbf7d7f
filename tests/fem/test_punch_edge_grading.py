"""The flat punch's edge grading (``flat_punch(edge_size=, edge_band=)``): its arguments are
checked, its distance expression is the exact distance to the punch edge, it refines the
edge, and without it the mesh is the one measured before the option existed.

Run serial and on two ranks:
    .venv/bin/python -m pytest tests/fem/test_punch_edge_grading.py
    mpirun -n 2 .venv/bin/python -m mpi4py -m pytest tests/fem/test_punch_edge_grading.py
References: the size field of the mesh before the option (one Threshold on the distance to
the patch) and, with gmsh 4.8, the level-1 mesh's 4 464 DOFs (1 488 vertices) and 284
contact-face vertices recorded in docs/punch_refinement.md before the option was added; the
distance to the two segments computed by clipping the projection onto each segment.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem.mesh import facet_vertex_coordinates, refine_towards
from rough_contact.scenes.meshes import flat_punch as punch_mesh
from rough_contact.scenes.meshes.flat_punch import flat_punch

logging.getLogger().setLevel(logging.WARNING)

COMM = MPI.COMM_WORLD
A = 10.0   # punch half width [mm] (the default)


def contact_face_facets(scene):
    """Corner coordinates of every facet of the punch's contact face, on every rank."""
    xyz = facet_vertex_coordinates(scene, scene.contact_pair[0])
    return np.concatenate(COMM.allgather(xyz))


@pytest.mark.parametrize("kwargs, match", [
    (dict(edge_size=0.8), r"edge_size = 0\.8 is invalid; valid range: \(0, contact_size = 0\.7\]"),
    (dict(edge_size=0.0), r"edge_size = 0\.0 is invalid; valid range"),
    (dict(edge_size=-0.1), r"edge_size = -0\.1 is invalid; valid range"),
    (dict(edge_size=float("nan")), r"edge_size = nan is invalid; valid range"),
    (dict(edge_size=0.35, edge_band=0.0), r"edge_band = 0\.0 is invalid; valid range: "
                                          r"\(0, half_width = 10\.0\]"),
    (dict(edge_size=0.35, edge_band=10.5), r"edge_band = 10\.5 is invalid; valid range"),
    (dict(edge_size=0.35, edge_band=float("inf")), r"edge_band = inf is invalid"),
    (dict(edge_band=1.0), r"edge_band = 1\.0 is invalid without edge_size"),
    (dict(edge_growth=0.3), r"edge_growth = 0\.3 is invalid without edge_size"),
    (dict(edge_size=0.35, edge_growth=1.5), r"edge_growth = 1\.5 is invalid; valid range: "
                                           r"\(0, 1\] mm per mm"),
    (dict(edge_size=0.35, edge_growth=0.0), r"edge_growth = 0\.0 is invalid"),
    (dict(edge_size=0.35, cell_type="hexahedron"), r"edge_size = 0\.35 is invalid with "
                                                   r"cell_type = 'hexahedron'"),
])
def test_bad_edge_grading_is_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        flat_punch(mesh_size=10.0, contact_size=0.7, order=1, comm=COMM, **kwargs)


def test_edge_distance_expression_is_the_distance_to_the_two_segments():
    rng = np.random.default_rng(7)
    p = rng.uniform([0.0, 0.0, -15.0], [25.0, 25.0, 15.0], size=(2000, 3))
    p[:200, :2] = rng.uniform(0.0, A, size=(200, 2))     # above and below the face
    p[200:300, 2] = 0.0                                  # on the plane of the face
    x, y, z = p.T
    expr = punch_mesh._edge_distance(A)
    got = eval(expr.replace("^", "**"), {"Sqrt": np.sqrt, "Abs": np.abs, "x": x, "y": y, "z": z})
    # nearest point of each segment: the projection clipped to the segment
    d1 = np.linalg.norm(p - np.c_[np.full_like(x, A), np.clip(y, 0, A), 0 * z], axis=1)
    d2 = np.linalg.norm(p - np.c_[np.clip(x, 0, A), np.full_like(y, A), 0 * z], axis=1)
    np.testing.assert_allclose(got, np.minimum(d1, d2), rtol=1e-12, atol=1e-12)


def owned_nodes(scene):
    """Coordinates of all the mesh's nodes, gathered on every rank, sorted."""
    x = scene.mesh.geometry.x[:scene.mesh.geometry.index_map().size_local]
    x = np.concatenate(COMM.allgather(x))
    return x[np.lexsort(x.T[::-1])]


def patch_field_before_edge_grading(model, a, contact_size, mesh_size, transition, *_, **__):
    """The size field of the punch mesh as it was before the edge grading: one Threshold on
    the exact distance to the patch, nothing else."""
    dx, dy = f"(Abs(x-{a})+x-{a})/2", f"(Abs(y-{a})+y-{a})/2"
    refine_towards(model, f"Sqrt(({dx})^2+({dy})^2+z^2)", contact_size, mesh_size, transition)


def test_default_mesh_is_unchanged(monkeypatch):
    """(10, 0.7) mm without edge grading is the mesh of the size field before the option
    (node for node, any gmsh), and with the gmsh of the recorded runs (4.8) the level-1 mesh
    of docs/punch_refinement.md (4 464 DOFs, 284 contact-face vertices)."""
    import gmsh

    sizes = dict(mesh_size=10.0, contact_size=0.7, order=1, load_half_width=10.0, comm=COMM)
    scene = flat_punch(**sizes)
    assert "edge_size" not in scene.dimensions
    monkeypatch.setattr(punch_mesh, "_refinement_field", patch_field_before_edge_grading)
    before = flat_punch(**sizes)
    np.testing.assert_array_equal(owned_nodes(scene), owned_nodes(before))
    if gmsh.__version__.startswith("4.8."):
        assert scene.mesh.topology.index_map(0).size_global * 3 == 4464
        corners = contact_face_facets(scene).reshape(-1, 3)
        assert len(np.unique(np.round(corners, 9), axis=0)) == 284


@pytest.mark.parametrize("edge_size", [0.35, 0.25])
def test_edge_grading_refines_the_edge(edge_size):
    band = 0.7
    scene = flat_punch(mesh_size=10.0, contact_size=0.7, order=1, load_half_width=10.0,
                       comm=COMM, edge_size=edge_size, edge_band=band)
    assert scene.dimensions["edge_size"] == edge_size and scene.dimensions["edge_band"] == band
    facets = contact_face_facets(scene)
    v = np.unique(np.round(facets.reshape(-1, 3), 9), axis=0)
    d = np.minimum(A - v[:, 0], A - v[:, 1])
    # the two 10 mm edge segments carry about 2 A / edge_size + 1 vertices (31 without grading)
    n_edge = np.count_nonzero(d < 1e-9)
    assert 0.85 * 2 * A / edge_size < n_edge < 1.2 * 2 * A / edge_size + 1
    # facets inside the band have sides of about edge_size; far from it, of about 0.7
    dist = np.minimum(A - facets[..., 0], A - facets[..., 1])
    sides = np.linalg.norm(facets - np.roll(facets, 1, axis=1), axis=2).max(axis=1)
    inside = dist.max(axis=1) <= band
    far = dist.min(axis=1) >= 3.0
    assert inside.sum() > 0 and far.sum() > 0
    assert np.median(sides[inside]) < 1.5 * edge_size
    assert np.median(sides[far]) > 0.8 * 0.7


def test_edge_growth_sets_the_size_beyond_the_band():
    """With ``edge_growth`` g the size beyond the band is edge_size + g (d - band): at
    d = 1.5-2.5 mm with edge_size = band = 0.35 and g = 0.1 about 0.47-0.57 mm, where the
    default rate (0.93 per mm on level 1) has reached the contact size 0.7."""
    sides_at = {}
    for growth in (None, 0.1):
        scene = flat_punch(mesh_size=10.0, contact_size=0.7, order=1, load_half_width=10.0,
                           comm=COMM, edge_size=0.35, edge_band=0.35, edge_growth=growth)
        assert scene.dimensions.get("edge_growth") == growth
        facets = contact_face_facets(scene)
        dist = np.minimum(A - facets[..., 0], A - facets[..., 1]).mean(axis=1)
        sides = np.linalg.norm(facets - np.roll(facets, 1, axis=1), axis=2).max(axis=1)
        sides_at[growth] = np.median(sides[(dist > 1.5) & (dist < 2.5)])
    assert 0.45 < sides_at[0.1] < 0.62
    assert sides_at[None] > 0.65
