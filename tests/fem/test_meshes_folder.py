"""The gmsh scripts of the top-level ``meshes/`` folder write .msh files that
``scene_from_msh_files`` reads into the same scene as the library's builders (serial and
``mpirun -n 2``).

Checked against the library's in-memory builders (rough_contact/scenes/meshes/), which the
scenes and their tests use: the same labels and bodies, the same global numbers of cells and
tagged facets, the same measure of every group (exact geometry: e.g. the 100 mm^2 contact
square), and a conforming contact pair. Units: mm.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from mpi4py import MPI

from rough_contact.fem.mesh import (check_conformity, measure_of, owned_facets,
                                    scene_from_msh_files)
from rough_contact.scenes.meshes.beam import beam_on_base
from rough_contact.scenes.meshes.flat_punch import flat_punch

MESHES = Path(__file__).resolve().parents[2] / "meshes"


def _script(name):
    """The meshes/ script as a module. Its ``import _common`` must find meshes/_common.py, not
    another folder's ``_common`` a test imported before (benchmarks/ and demos/ have one)."""
    import sys
    saved = sys.modules.pop("_common", None)
    try:
        spec = importlib.util.spec_from_file_location(f"meshes_{name}", MESHES / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        if saved is not None:
            sys.modules["_common"] = saved
    return module


def _write(comm, tmp_path, name, **sizes):
    """Run the script's ``write`` on rank 0; the path on every rank."""
    path = None
    if comm.rank == 0:
        path = str(_script(name).write(tmp_path / f"{name}.msh", **sizes))
    return comm.bcast(path, root=0)


def _same_scene(a, b):
    comm = a.mesh.comm
    assert a.labels == b.labels
    assert a.bodies == b.bodies
    assert a.contact_pair == b.contact_pair
    cells = [s.mesh.topology.index_map(3).size_global for s in (a, b)]
    assert cells[0] == cells[1] > 0
    for name, tag in a.labels.items():
        assert measure_of(a, name) == pytest.approx(measure_of(b, name), rel=1e-12), name
        if name not in a.bodies:                  # surface groups: same number of facets
            n = [comm.allreduce(len(owned_facets(s, tag))) for s in (a, b)]
            assert n[0] == n[1] > 0, name


@pytest.mark.parametrize("order", [1, 2])
def test_flat_punch_script(tmp_path, order):
    comm = MPI.COMM_WORLD
    sizes = dict(mesh_size=40.0, contact_size=10.0, order=order)
    path = _write(comm, tmp_path, "flat_punch", **sizes)
    scene = scene_from_msh_files(
        [path], comm, contact_pair=("contact_punch", "contact_foundation"),
        split_bodies=["punch"],
        surface_owners={"contact_punch": "punch", "contact_foundation": "foundation"})
    library = flat_punch(load_half_width=2.5, comm=comm, **sizes)
    _same_scene(scene, library)
    assert measure_of(scene, "contact_punch") == pytest.approx(100.0, rel=1e-12)
    assert measure_of(scene, "load") == pytest.approx(6.25, rel=1e-12)
    assert check_conformity(scene).conforming


def test_beam_script(tmp_path):
    comm = MPI.COMM_WORLD
    sizes = dict(mesh_size=60.0, contact_size=10.0, order=1)
    path = _write(comm, tmp_path, "beam", **sizes)
    scene = scene_from_msh_files([path], comm, contact_pair=("contact_beam", None),
                                 rigid_plane=((0.0, 0.0, 0.0), (0.0, 0.0, 2.0)))
    library = beam_on_base(comm=comm, **sizes)
    _same_scene(scene, library)
    assert measure_of(scene, "contact_beam") == pytest.approx(10.0 * 250.0, rel=1e-12)
    point, normal = scene.rigid_plane
    assert list(normal) == [0.0, 0.0, 1.0]               # normalised on reading
