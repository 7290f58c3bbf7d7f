"""Interface output on the contact facets: XDMF/HDF5 read back with h5py and ElementTree.

The files are read here with h5py and the XML parser directly (not with the module's own
reader) and checked against references the writer does not compute: the number of contact
facets from the facet tags, the patch area from the scene's dimensions, facet areas from the
written vertex coordinates, the contact force of ``ContactInterface.contact_force()``, an
analytic linear-penalty state (global slip and traction known in closed form), and the same
run on one rank. Serial and ``mpirun -n 2``. Units: mm, N, MPa.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import tempfile

import h5py
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.mesh
from dolfinx import fem

from rough_contact.fem import compat
from rough_contact.io.files import parse_xdmf as xdmf_root
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.scenes.meshes.flat_punch import flat_punch
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.penalty import LinearPenalty
from rough_contact.io.files import OutputExistsError, prepare_output_dir
from rough_contact.io.interface_output import (
    FACET_FIELD_NAMES, POINT_FIELD_NAMES, InterfaceWriter, facet_average, facet_status,
    pseudo_time, read_interface_results)
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver
from rough_contact.scenes.defaults import SEATING_STIFFNESS

E, NU = 2.0e5, 0.25
FACTORS = [1.0 / 3.0, 2.0 / 3.0, 1.0]
QUARTER_FORCE = 250.0  # N, the paper's 1000 N on the quarter model
VECTORS = {"slip_mm", "plastic_slip_mm", "traction_MPa", "shear_traction_MPa"}


def shared_tmpdir(comm):
    path = tempfile.mkdtemp(prefix="rc_iface_") if comm.rank == 0 else None
    return comm.bcast(path, root=0)


def remove_tmpdir(comm, path):
    comm.barrier()
    if comm.rank == 0:
        shutil.rmtree(path, ignore_errors=True)


def punch_law(comm):
    """The paper's surface (elastic population, loose table) with friction case (b)."""
    from rough_contact.interface.friction import OrthotropicSlipHardening
    from rough_contact.interface.law import InterfaceLaw
    from rough_contact.interface.normal import NormalLaw
    from rough_contact.interface.tangential import TangentialStiffness
    from rough_contact.surface import SpectralMoments

    normal = None
    if comm.rank == 0:
        surface = SpectralMoments(0.625, 8e-5, 8e-4, 1.04e-6, 1.04e-4, unit="um")
        normal = NormalLaw.elastic(surface, E / (2.0 * (1.0 - NU**2)), rtol=1e-2)
    normal = comm.bcast(normal, root=0)
    friction = OrthotropicSlipHardening(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5),
                                        hardening=(275.0, 275.0), potential_axes=(0.125, 0.125))
    return InterfaceLaw(normal=normal, tangential=TangentialStiffness((0.7, 0.7)),
                        friction=friction)


def run_punch(comm, outdir, prefix):
    """Coarse quarter punch (P1), three load steps, surface and point files written per step.

    Returns a dict of what the test compares the files with (global figures on every rank).
    """
    scene = flat_punch(mesh_size=20.0, contact_size=2.5, order=1, load_half_width=2.5, comm=comm)
    V = compat.vector_space(scene.mesh, 1)

    def dofs(name, comp=None):
        facets = scene.facet_tags.find(scene.tag(name))
        if comp is None:
            return fem.locate_dofs_topological(V, 2, facets)
        return fem.locate_dofs_topological(V.sub(comp), 2, facets)

    zero = PETSc.ScalarType(0.0)
    bcs = [fem.dirichletbc(zero, dofs("symmetry_x", 0), V.sub(0)),
           fem.dirichletbc(zero, dofs("symmetry_y", 1), V.sub(1)),
           fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), dofs("fixed"), V)]
    area = scene.dimensions["half_width"] ** 2
    law = punch_law(comm).with_seating(QUARTER_FORCE * FACTORS[0] / area)
    first, second = scene.contact_pair
    ci = ContactInterface(V, scene.facet_tags, first, second, law=law, bcs=bcs,
                          grain_direction=(1.0, 0.0, 0.0), quadrature_degree=2)
    problem = ContactProblem(
        V, {scene.tag("punch"): Material(E, NU), scene.tag("foundation"): Material(E, NU)}, bcs,
        [SurfaceLoad(scene.tag("load"), force=[0.0, 0.0, -QUARTER_FORCE])],
        cell_tags=scene.cell_tags, facet_tags=scene.facet_tags, interface=ci,
        seating_tag=first, seating_stiffness=SEATING_STIFFNESS)
    solver = SNESSolver(problem, prefix=prefix)
    prepare_output_dir(outdir, comm)
    writer = InterfaceWriter(outdir, ci, points=True)
    forces, n_slipping, n_contact = [], [], []
    for inc in load_path(problem, solver, FACTORS, verbose=False):
        writer.write(inc.load_factor)
        forces.append(ci.contact_force())
        n_slipping.append(inc.n_slipping)
        n_contact.append(inc.n_active)
    pf = ci.point_fields()
    w = ci.point_weights()
    # the local tangential axes of the punch bottom: n = -z, x = +x, y = n x x = -y
    local_slip_integral = comm.allreduce(np.einsum("p,pa->a", w, pf.slip), op=MPI.SUM)
    n_tagged = comm.allreduce(int(np.sum(
        (scene.facet_tags.values == first)
        & (scene.facet_tags.indices < scene.mesh.topology.index_map(2).size_local))), op=MPI.SUM)
    solver.destroy()
    return dict(forces=np.array(forces), n_slipping=n_slipping, n_contact=n_contact,
                local_slip_integral=local_slip_integral, n_facets=n_tagged, area=area,
                n_points=ci.n_points_global, n_qp=ci.n_qp)


@pytest.fixture(scope="module")
def punch():
    comm = MPI.COMM_WORLD
    outdir = shared_tmpdir(comm)
    ref = run_punch(comm, outdir, "test_iface_out_")
    yield outdir, ref
    remove_tmpdir(comm, outdir)


def parse_xdmf(path):
    """(grids, h5 folder) of an XDMF temporal collection, read with ElementTree."""
    root = xdmf_root(path)
    collection = root.find("./Domain/Grid")
    assert collection.get("GridType") == "Collection"
    assert collection.get("CollectionType") == "Temporal"
    return collection.findall("Grid"), os.path.dirname(path)


def dataset(item, folder):
    """Read the HDF5 data item with h5py and check its declared dimensions."""
    file_name, path = item.text.strip().split(":")
    with h5py.File(os.path.join(folder, file_name), "r") as h5:
        data = h5[path][...]
    assert tuple(int(d) for d in item.get("Dimensions").split()) == data.shape
    return data


def step_fields(grid, folder):
    return {a.get("Name"): dataset(a.find("DataItem"), folder)
            for a in grid.findall("Attribute") if a.get("Center") != "Grid"}


def grid_scalar(grid, name):
    att = next(a for a in grid.findall("Attribute") if a.get("Name") == name)
    assert att.get("Center") == "Grid"
    return float(att.find("DataItem").text)


def triangle_areas(points, cells):
    x = points[cells]
    return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)


def test_surface_file_has_cells_fields_and_load_factor_times(punch):
    outdir, ref = punch
    grids, folder = parse_xdmf(os.path.join(outdir, "interface.xdmf"))
    assert len(grids) == len(FACTORS)
    for grid, lam in zip(grids, FACTORS):
        assert float(grid.find("Time").get("Value")) == lam
        assert grid_scalar(grid, "load_factor") == lam
        topo = grid.find("Topology")
        assert topo.get("TopologyType") == "Triangle"
        assert int(topo.get("NumberOfElements")) == ref["n_facets"]
        cells = dataset(topo.find("DataItem"), folder)
        points = dataset(grid.find("Geometry/DataItem"), folder)
        assert cells.shape == (ref["n_facets"], 3) and points.shape[1] == 3
        assert cells.min() == 0 and cells.max() == len(points) - 1  # every vertex used
        assert np.all(np.diff(np.sort(cells, axis=1), axis=1) > 0)  # no repeated vertex
        # the facets tile the contact patch [0, a]^2 x {0}
        assert np.isclose(triangle_areas(points, cells).sum(), ref["area"], rtol=1e-12)
        assert np.allclose(points[:, 2], 0.0, atol=1e-12)
        fields = step_fields(grid, folder)
        assert set(fields) == set(FACET_FIELD_NAMES)
        for name, data in fields.items():
            assert data.shape == ((ref["n_facets"], 3) if name in VECTORS else (ref["n_facets"],))
            assert np.all(np.isfinite(data))
        centre = [a for a in grid.findall("Attribute") if a.get("Name") == "slip_mm"][0]
        assert centre.get("Center") == "Cell" and centre.get("AttributeType") == "Vector"


def test_surface_oriented_along_interface_normal(punch):
    """Facet normals of the written cells point from the punch into the foundation (-z)."""
    outdir, _ = punch
    grids, folder = parse_xdmf(os.path.join(outdir, "interface.xdmf"))
    points = dataset(grids[0].find("Geometry/DataItem"), folder)
    cells = dataset(grids[0].find("Topology/DataItem"), folder)
    x = points[cells]
    nz = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])[:, 2]
    assert np.all(nz < 0.0)


def test_integrals_of_facet_and_point_fields_equal_contact_force(punch):
    """Facet averages x facet areas (from the written vertices), and point values x weights,
    integrate to ContactInterface.contact_force() at every step."""
    outdir, ref = punch
    grids, folder = parse_xdmf(os.path.join(outdir, "interface.xdmf"))
    pgrids, _ = parse_xdmf(os.path.join(outdir, "interface_points.xdmf"))
    points = dataset(grids[0].find("Geometry/DataItem"), folder)
    cells = dataset(grids[0].find("Topology/DataItem"), folder)
    area = triangle_areas(points, cells)
    for k, force in enumerate(ref["forces"]):
        scale = abs(force[2])
        assert np.isclose(scale, FACTORS[k] * QUARTER_FORCE, rtol=1e-8)  # force balance
        f = step_fields(grids[k], folder)
        assert np.allclose(area @ f["traction_MPa"], force, rtol=0, atol=1e-10 * scale)
        assert np.isclose(area @ f["pressure_MPa"], force[2], rtol=1e-10)
        p = step_fields(pgrids[k], folder)
        assert set(p) == set(POINT_FIELD_NAMES)
        assert len(p["weight_mm2"]) == ref["n_points"]
        assert np.isclose(p["weight_mm2"].sum(), ref["area"], rtol=1e-12)
        assert np.allclose(p["weight_mm2"] @ p["traction_MPa"], force, rtol=0, atol=1e-10 * scale)
        assert np.isclose(p["weight_mm2"] @ p["pressure_MPa"], force[2], rtol=1e-10)


def test_vectors_in_global_axes(punch):
    """On the plane z = 0 the tangential vectors have no z component, the traction's z
    component is the pressure, and the global slip is (s_x, -s_y) of the local axes
    (n = -z, x = grain = +x, y = n x x = -y)."""
    outdir, ref = punch
    for name in ("interface.xdmf", "interface_points.xdmf"):
        grids, folder = parse_xdmf(os.path.join(outdir, name))
        for grid in grids:
            f = step_fields(grid, folder)
            scale = np.abs(f["traction_MPa"]).max()
            for v in ("slip_mm", "plastic_slip_mm", "shear_traction_MPa"):
                assert np.abs(f[v][:, 2]).max() <= 1e-14 * max(np.abs(f[v]).max(), 1e-300)
            assert np.allclose(f["traction_MPa"][:, 2], f["pressure_MPa"], atol=1e-12 * scale)
            assert np.allclose(f["traction_MPa"][:, :2], f["shear_traction_MPa"][:, :2],
                               atol=1e-12 * scale)
    grids, folder = parse_xdmf(os.path.join(outdir, "interface_points.xdmf"))
    p = step_fields(grids[-1], folder)
    sx, sy = ref["local_slip_integral"]
    integral = p["weight_mm2"] @ p["slip_mm"]
    assert abs(sx) > 0 and abs(sy) > 0
    assert np.allclose(integral, [sx, -sy, 0.0], rtol=1e-10, atol=1e-14 * abs(sx))


def test_status_and_fractions(punch):
    outdir, ref = punch
    grids, folder = parse_xdmf(os.path.join(outdir, "interface.xdmf"))
    pgrids, _ = parse_xdmf(os.path.join(outdir, "interface_points.xdmf"))
    for k, grid in enumerate(grids):
        f = step_fields(grid, folder)
        status, cf, sf = f["status"], f["contact_fraction"], f["slip_fraction"]
        assert status.dtype.kind == "i" and set(np.unique(status)) <= {0, 1, 2}
        assert np.all((0 <= sf) & (sf <= cf + 1e-15) & (cf <= 1 + 1e-15))
        parts = np.column_stack([1 - cf, cf - sf, sf])
        largest = parts.max(axis=1, keepdims=True)
        # the status is a state covering the largest part (the more active one on ties)
        chosen = parts[np.arange(len(status)), status]
        assert np.all(chosen >= largest[:, 0] - 1e-9)
        # the point cloud counts the same slipping/contact points as the load path
        ps = step_fields(pgrids[k], folder)["status"]
        assert np.sum(ps == 2) == ref["n_slipping"][k]
        assert np.sum(ps > 0) == ref["n_contact"][k]
    # at full load the coarse punch sticks in the centre and slips at its edge
    last = step_fields(grids[-1], folder)["status"]
    assert np.any(last == 1) and np.any(last == 2)


def test_files_do_not_depend_on_rank_count(punch):
    """The files written on all ranks equal those of a run on one rank (COMM_SELF)."""
    outdir, _ = punch
    comm = MPI.COMM_WORLD
    serial_dir = tempfile.mkdtemp(prefix="rc_iface_self_")
    try:
        run_punch(MPI.COMM_SELF, serial_dir, "test_iface_self_")
        for name in ("interface.xdmf", "interface_points.xdmf"):
            grids, folder = parse_xdmf(os.path.join(outdir, name))
            sgrids, sfolder = parse_xdmf(os.path.join(serial_dir, name))
            assert len(grids) == len(sgrids)
            g = dataset(grids[0].find("Geometry/DataItem"), folder)
            assert np.array_equal(g, dataset(sgrids[0].find("Geometry/DataItem"), sfolder))
            if name == "interface.xdmf":
                assert np.array_equal(dataset(grids[0].find("Topology/DataItem"), folder),
                                      dataset(sgrids[0].find("Topology/DataItem"), sfolder))
            for grid, sgrid in zip(grids, sgrids):
                a, b = step_fields(grid, folder), step_fields(sgrid, sfolder)
                for key in a:
                    scale = max(np.abs(b[key]).max(), 1e-300)
                    assert np.allclose(a[key], b[key], rtol=1e-8, atol=1e-10 * scale), key
    finally:
        shutil.rmtree(serial_dir, ignore_errors=True)
    comm.barrier()


@pytest.mark.parametrize("cell_type,order,grain,empty_ranks", [
    ("tetrahedron", 2, (1.0, 0.0, 0.0), False), ("hexahedron", 1, (1.0, 2.0, 0.0), False),
    ("tetrahedron", 1, (0.0, 1.0, 0.0), True)])
def test_analytic_penalty_state_global_vectors(cell_type, order, grain, empty_ranks):
    """Block on a rigid plane, uniform displacement u = (a, b, -d): with a linear penalty the
    global slip is -(a, b, 0), the traction on the block (-kT a, -kT b, kN d), whatever the
    local axes (grain direction); quadrilateral facets for hexahedra, P2 tetrahedra; with
    ``empty_ranks`` only rank 0's facets are tagged, so the other ranks own no contact facet."""
    comm = MPI.COMM_WORLD
    lx, ly = 1.0, 2.0
    scene = block_on_plane(lx=lx, ly=ly, h=0.5, mesh_size=0.5, order=order, cell_type=cell_type,
                           comm=comm)
    V = compat.vector_space(scene.mesh, order)
    kn, kt = 1.0e5, 3.0e4
    a, b, d = 2e-4, -1e-4, 5e-4
    contact = scene.tag("contact")
    tags = scene.facet_tags
    if empty_ranks and comm.rank > 0:
        tags = dolfinx.mesh.meshtags(scene.mesh, 2, tags.indices,
                                     np.where(tags.values == contact, 99, tags.values))
    ci = ContactInterface(V, tags, contact, None, law=LinearPenalty(kn, kt),
                          rigid_plane=((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), grain_direction=grain)
    u = fem.Function(V)
    u.interpolate(lambda x: np.vstack([np.full(x.shape[1], a), np.full(x.shape[1], b),
                                       np.full(x.shape[1], -d)]))
    ci.evaluate(u)
    outdir = shared_tmpdir(comm)
    try:
        writer = InterfaceWriter(outdir, ci, points=True)
        writer.write(1.0)
        grids, folder = parse_xdmf(os.path.join(outdir, "interface.xdmf"))
        topo = grids[0].find("Topology")
        nv = 4 if cell_type == "hexahedron" else 3
        assert topo.get("TopologyType") == ("Quadrilateral" if nv == 4 else "Triangle")
        points = dataset(grids[0].find("Geometry/DataItem"), folder)
        cells = dataset(topo.find("DataItem"), folder)
        assert cells.shape[1] == nv
        x = points[cells]
        if nv == 4:  # planar quads: area and normal from the diagonals
            normal = 0.5 * np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
        else:
            normal = 0.5 * np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        assert np.isclose(np.linalg.norm(normal, axis=1).sum(),
                          ci.nominal_area() if empty_ranks else lx * ly, rtol=1e-12)
        assert len(cells) == comm.allreduce(ci.n_facets, op=MPI.SUM)
        if empty_ranks and comm.size > 1:
            assert ci.n_facets == 0 or comm.rank == 0
        assert np.all(normal[:, 2] < 0)  # n points from the block into the plane
        for name, n_rows in (("interface.xdmf", len(cells)),
                             ("interface_points.xdmf", ci.n_points_global)):
            grids, folder = parse_xdmf(os.path.join(outdir, name))
            f = step_fields(grids[0], folder)
            assert len(f["pressure_MPa"]) == n_rows
            assert np.allclose(f["slip_mm"], [-a, -b, 0.0], rtol=0, atol=1e-12 * d)
            assert np.allclose(f["traction_MPa"], [-kt * a, -kt * b, kn * d], rtol=0,
                               atol=1e-10 * kn * d)
            assert np.allclose(f["pressure_MPa"], kn * d, rtol=1e-12)
            assert np.allclose(f["gap_mm"], -d, rtol=1e-12)
            assert np.all(f["status"] == 1)  # in contact, no friction limit
    finally:
        remove_tmpdir(comm, outdir)


def test_overwrite_guard():
    """A folder with results of an earlier run is refused, or cleaned of exactly those files."""
    comm = MPI.COMM_WORLD
    outdir = shared_tmpdir(comm)
    try:
        earlier = ["history.csv", "interface.xdmf", "interface_0012.bin", "displacement.h5",
                   "interface.h5.tmp4711"]
        keep = ["notes.txt", "interface_final.png", "history.csv.bak"]
        if comm.rank == 0:
            for f in earlier + keep:
                open(os.path.join(outdir, f), "w").close()
        comm.barrier()
        with pytest.raises(OutputExistsError, match="interface_0012.bin") as info:
            prepare_output_dir(outdir, comm)
        assert isinstance(info.value, ValueError) and outdir in str(info.value)
        removed = prepare_output_dir(outdir, comm, overwrite=True)
        assert sorted(removed) == sorted(earlier)
        assert sorted(os.listdir(outdir)) == sorted(keep)
        comm.barrier()
        assert prepare_output_dir(outdir, comm) == []  # now clean: no error
        removed = prepare_output_dir(outdir, comm, overwrite=True, extra_patterns=[r".*\.png"])
        assert removed == ["interface_final.png"]
        comm.barrier()  # every rank has looked at the folder before it changes again
        if comm.rank == 0:
            open(os.path.join(outdir, "file"), "w").close()
        comm.barrier()
        with pytest.raises(ValueError, match="not a directory"):
            prepare_output_dir(os.path.join(outdir, "file"), comm)
    finally:
        remove_tmpdir(comm, outdir)


def test_writer_refuses_earlier_files_and_bad_times():
    comm = MPI.COMM_WORLD
    scene = block_on_plane(lx=1.0, ly=1.0, h=0.5, mesh_size=0.6, comm=comm)
    V = compat.vector_space(scene.mesh, 1)
    ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), None,
                          law=LinearPenalty(1e5), rigid_plane=((0, 0, 0), (0, 0, 1)))
    ci.evaluate(fem.Function(V))
    outdir = shared_tmpdir(comm)
    try:
        w = InterfaceWriter(outdir, ci)
        w.write(0.5)
        with pytest.raises(ValueError, match="repeats"):
            w.write(0.5)
        with pytest.raises(ValueError, match="time value"):
            w.write(0.7, time=0.25)
        w.write(0.25)  # unloading: the time goes on as the load-path length
        assert w.times == [0.5, 0.75] and w.load_factors == [0.5, 0.25]
        with pytest.raises(OutputExistsError, match="interface.xdmf"):
            InterfaceWriter(outdir, ci)
        InterfaceWriter(outdir, ci, overwrite=True).write(1.0)
        if comm.rank == 0:
            res = read_interface_results(os.path.join(outdir, "interface.xdmf"))
            assert list(res.times) == [1.0] and list(res.load_factors) == [1.0]
            assert res.field("pressure_MPa").shape == (len(res.cells),)
            with pytest.raises(ValueError, match="out of range"):
                res.field("pressure_MPa", 3)
            with pytest.raises(ValueError, match="not in the file"):
                res.field("pressure")
    finally:
        remove_tmpdir(comm, outdir)


# ---------------------------------------------------------------------------------------------
# the pure helpers, on hand-made data
# ---------------------------------------------------------------------------------------------
def test_facet_average_is_weighted_mean():
    w = np.array([1.0, 3.0, 2.0, 2.0])
    v = np.array([[4.0, 1.0], [0.0, 1.0], [1.0, 0.0], [3.0, 2.0]])
    assert np.allclose(facet_average(v, w, 2), [[1.0, 1.0], [2.0, 1.0]])
    assert np.allclose(facet_average(v[:, 0], w, 2), [1.0, 2.0])
    # a weight-0 point (the mortar pairing's slot copies) does not count
    assert np.allclose(facet_average(v, np.array([1.0, 0.0, 1.0, 1.0]), 2),
                       [[4.0, 1.0], [2.0, 1.0]])
    with pytest.raises(ValueError, match="weights"):
        facet_average(v, np.array([1.0, -1.0, 1.0, 1.0]), 2)
    with pytest.raises(ValueError, match="positive total quadrature weight"):
        facet_average(v, np.array([0.0, 0.0, 1.0, 1.0]), 2)
    with pytest.raises(ValueError, match="n_qp"):
        facet_average(v, w, 3)


def test_facet_status_majority_and_ties():
    # 4 facets x 3 points, equal weights except facet 3
    contact = np.array([0, 0, 1, 1, 1, 0, 1, 1, 1, 1, 1, 0], dtype=bool)
    slipping = np.array([0, 1, 0, 1, 0, 0, 1, 1, 0, 1, 0, 0], dtype=bool)
    w = np.array([1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2], dtype=float)
    status, cf, sf = facet_status(contact, slipping, w, 3)
    # facet 0: open 2/3 (a slipping flag without contact counts as open) -> open
    # facet 1: slip 1/3, stick 1/3, open 1/3 -> tie, the most active state: slip
    # facet 2: slip 2/3 -> slip; facet 3: slip 1/4, stick 1/4, open 1/2 -> open
    assert status.tolist() == [0, 2, 2, 0]
    assert np.allclose(cf, [1 / 3, 2 / 3, 1, 0.5])
    assert np.allclose(sf, [0, 1 / 3, 2 / 3, 0.25])


def test_pseudo_time():
    assert pseudo_time([0.25, 0.5, 1.0]).tolist() == [0.25, 0.5, 1.0]
    assert np.allclose(pseudo_time([0.5, 1.0, 0.5, 0.25, 0.75]), [0.5, 1.0, 1.5, 1.75, 2.25])
    with pytest.raises(ValueError, match="repeats"):
        pseudo_time([0.5, 0.5])


@pytest.mark.skipif(shutil.which("pvpython") is None or MPI.COMM_WORLD.size > 1,
                    reason="ParaView's pvpython not installed (optional check, serial)")
def test_paraview_reads_surface(punch):
    """ParaView's own reader (chosen by OpenDataFile) finds cells, fields and load times."""
    outdir, ref = punch
    script = (
        "from paraview.simple import *\n"
        f"r = OpenDataFile({os.path.join(outdir, 'interface.xdmf')!r})\n"
        "t = list(r.TimestepValues)\n"
        "r.UpdatePipeline(t[-1])\n"
        "i = r.GetDataInformation()\n"
        "a = sorted((a.GetName(), a.GetNumberOfComponents()) for a in r.CellData)\n"
        "print('RESULT|' + '|'.join(map(repr, [i.GetNumberOfCells(), t, a])))\n")
    out = subprocess.run(["pvpython", "-c", script], capture_output=True, text=True, timeout=300,
                         env={k: v for k, v in os.environ.items()
                              if not k.startswith(("OMPI_", "PMIX_"))})
    line = next(ln for ln in out.stdout.splitlines() if ln.startswith("RESULT"))
    n_cells, times, arrays = line.split("|")[1:]
    assert int(n_cells) == ref["n_facets"]
    assert ast.literal_eval(times) == FACTORS
    arrays = dict(ast.literal_eval(arrays))
    assert set(arrays) == set(FACET_FIELD_NAMES)
    assert all(arrays[n] == 3 for n in VECTORS)


def _series(comm, path, times):
    from dolfinx.io import XDMFFile

    msh = dolfinx.mesh.create_unit_cube(comm, 2, 2, 2)
    u = fem.Function(compat.vector_space(msh, 1), name="u")
    for k, t in enumerate(times):
        u.x.array[:] = t
        with XDMFFile(comm, path, "w" if k == 0 else "a") as f:
            if k == 0:
                f.write_mesh(msh)
            f.write_function(u, t)
    return u


def test_time_series_cut_back_and_continued():
    """A restart's trimming (io.results.truncate_time_series): a DOLFINx XDMF series of 4 steps cut
    back to 2 keeps those 2 (XML and data), drops the others' datasets, and DOLFINx can then
    append the same time values again (it refuses a dataset that exists)."""
    from dolfinx.io import XDMFFile

    from rough_contact.io.results import truncate_time_series

    comm = MPI.COMM_WORLD
    folder = comm.bcast(tempfile.mkdtemp() if comm.rank == 0 else None, root=0)
    path = os.path.join(folder, "displacement.xdmf")
    u = _series(comm, path, [0.25, 0.5, 0.75, 1.0])
    if comm.rank == 0:
        assert truncate_time_series(path, 2)
        root = xdmf_root(path)
        times = [float(t.get("Value")) for t in root.iter("Time")]
        assert times == [0.25, 0.5]
        with h5py.File(os.path.join(folder, "displacement.h5"), "r") as h5:
            assert sorted(h5["Function/u"]) == ["0_25", "0_5"]
            np.testing.assert_allclose(h5["Function/u/0_5"][...], 0.5, rtol=1e-14)
    comm.Barrier()
    for t in (0.75, 1.0):                               # the resumed run writes them again
        u.x.array[:] = 10 * t
        with XDMFFile(comm, path, "a") as f:
            f.write_function(u, t)
    if comm.rank == 0:
        root = xdmf_root(path)
        assert [float(t.get("Value")) for t in root.iter("Time")] == [0.25, 0.5, 0.75, 1.0]
        with h5py.File(os.path.join(folder, "displacement.h5"), "r") as h5:
            np.testing.assert_allclose(h5["Function/u/1"][...], 10.0, rtol=1e-14)
        shutil.rmtree(folder)


def test_damaged_time_series_moved_aside():
    """An HDF5 file a kill damaged in the middle of its write cannot be continued: it is moved
    aside with a warning and the caller is told to start the series afresh."""
    from rough_contact.io.results import truncate_time_series

    if MPI.COMM_WORLD.rank != 0:
        return
    folder = tempfile.mkdtemp()
    path = os.path.join(folder, "displacement.xdmf")
    _series(MPI.COMM_SELF, path, [0.5, 1.0])
    h5 = os.path.join(folder, "displacement.h5")
    with open(h5, "r+b") as f:                          # a torn write: the superblock is gone
        f.write(b"\0" * 64)
    with pytest.warns(RuntimeWarning, match="could not be continued .* moved aside"):
        assert not truncate_time_series(path, 1)
    assert sorted(os.listdir(folder)) == ["displacement.h5.damaged", "displacement.xdmf.damaged"]
    assert not truncate_time_series(path, 1)            # nothing left: start afresh
    shutil.rmtree(folder)
