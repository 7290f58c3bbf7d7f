"""DOLFINx 0.9 spellings of every DOLFINx/basix/ufl/petsc4py call rough_contact makes on 0.5.2.

Each check below runs the 0.9 spelling on a small P2 vector problem on a unit cube and asserts
what the library needs from it (shapes, values, parallel consistency). Run inside the Debian 13
chroot, serially and on 2 ranks:

    bash run.sh debian13 python tools/check_dolfinx09_api.py
    bash run.sh debian13 shell <<< 'mpirun -n 2 "$RC_VENV/bin/python" tools/check_dolfinx09_api.py'

(the chroot's shell starts in the repository and sets RC_VENV to its virtual environment).

Prints one markdown row per check (0.5.2 call | 0.9 call | verified) on rank 0; a check is
"yes" only when it passed on every rank. ``--json PATH`` writes the results as well. Exit code
1 if any check failed. Documented in docs/dolfinx09_port.md. Not part of the test suite (the
suite itself runs on 0.9: `bash run.sh test-debian13`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import traceback

import petsc4py

petsc4py.init(sys.argv[:1])
from petsc4py import PETSc  # noqa: E402
from mpi4py import MPI  # noqa: E402

import numpy as np  # noqa: E402
import basix  # noqa: E402
import basix.ufl  # noqa: E402
import ufl  # noqa: E402
import dolfinx  # noqa: E402
import dolfinx.fem.petsc  # noqa: E402
import dolfinx.io  # noqa: E402
from dolfinx import fem, la, mesh as dmesh  # noqa: E402

comm = MPI.COMM_WORLD
CHECKS: list = []


def check(old: str, new: str):
    def deco(fn):
        CHECKS.append((old, new, fn))
        return fn
    return deco


# ---------------------------------------------------------------- fixtures
class Fx:
    """Lazily built shared objects (collective: every rank builds them in the same order)."""
    _cache: dict = {}

    @classmethod
    def get(cls, name):
        if name not in cls._cache:
            cls._cache[name] = getattr(cls, "_" + name)()
        return cls._cache[name]

    @staticmethod
    def _msh1():
        return dmesh.create_unit_cube(comm, 3, 3, 3, dmesh.CellType.tetrahedron)

    @staticmethod
    def _V1():
        return fem.functionspace(Fx.get("msh1"), ("Lagrange", 2, (3,)))

    @staticmethod
    def _gmsh_p2():
        """P2 tetrahedral unit cube from gmsh (rank 0) as arrays; volume 1, bottom 10, top 11."""
        import gmsh
        data = None
        if comm.rank == 0:
            gmsh.initialize(["-v", "0"])
            gmsh.model.add("cube")
            gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
            gmsh.model.occ.synchronize()
            bottom = [s[1] for s in gmsh.model.getEntities(2)
                      if abs(gmsh.model.occ.getCenterOfMass(2, s[1])[2]) < 1e-9]
            top = [s[1] for s in gmsh.model.getEntities(2)
                   if abs(gmsh.model.occ.getCenterOfMass(2, s[1])[2] - 1) < 1e-9]
            gmsh.model.addPhysicalGroup(3, [1], 1)
            gmsh.model.addPhysicalGroup(2, bottom, 10)
            gmsh.model.addPhysicalGroup(2, top, 11)
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
            gmsh.model.mesh.generate(3)
            gmsh.model.mesh.setOrder(2)
            tags, x, _ = gmsh.model.mesh.getNodes()
            index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
            index[tags.astype(np.int64)] = np.arange(tags.size)
            _, ctags = gmsh.model.mesh.getElementsByType(11)          # 10-node tetrahedra
            cells = index[ctags.astype(np.int64)].reshape(-1, 10)
            facets, fvals = [], []
            for tag, ents in ((10, bottom), (11, top)):
                for e in ents:
                    _, ft = gmsh.model.mesh.getElementsByType(9, e)   # 6-node triangles
                    f = index[ft.astype(np.int64)].reshape(-1, 6)
                    facets.append(f)
                    fvals.append(np.full(len(f), tag, dtype=np.int32))
            data = dict(x=x.reshape(-1, 3), cells=cells,
                        cell_values=np.ones(len(cells), dtype=np.int32),
                        facets=np.concatenate(facets), facet_values=np.concatenate(fvals))
            # keep the model for gmshio
        return data

    @staticmethod
    def _scene():
        """The rough_contact.fem.mesh path on 0.9: create_mesh + distributed tags (P2 geometry)."""
        d = Fx.get("gmsh_p2")
        if d is None:
            d = dict(x=np.empty((0, 3)), cells=np.empty((0, 10), dtype=np.int64),
                     cell_values=np.empty(0, dtype=np.int32),
                     facets=np.empty((0, 6), dtype=np.int64),
                     facet_values=np.empty(0, dtype=np.int32))
        element = basix.ufl.element("Lagrange", "tetrahedron", 2, shape=(3,),
                                    lagrange_variant=basix.LagrangeVariant.equispaced)
        domain = ufl.Mesh(element)
        cell = dolfinx.cpp.mesh.to_type("tetrahedron")
        cells = d["cells"][:, dolfinx.cpp.io.perm_gmsh(cell, 10)]
        msh = dmesh.create_mesh(comm, cells, d["x"], domain)
        tdim = msh.topology.dim
        ent, val = dolfinx.io.distribute_entity_data(msh, tdim, cells, d["cell_values"])
        msh.topology.create_connectivity(tdim, 0)
        ct = dmesh.meshtags_from_entities(msh, tdim, dolfinx.graph.adjacencylist(ent),
                                          val.astype(np.int32))
        ct.name = "cell_tags"
        fcell = dolfinx.cpp.mesh.cell_entity_type(cell, tdim - 1, 0)
        facets = d["facets"][:, dolfinx.cpp.io.perm_gmsh(fcell, 6)]
        ent, val = dolfinx.io.distribute_entity_data(msh, tdim - 1, facets, d["facet_values"])
        msh.topology.create_connectivity(tdim - 1, tdim)
        msh.topology.create_connectivity(tdim - 1, 0)
        ft = dmesh.meshtags_from_entities(msh, tdim - 1, dolfinx.graph.adjacencylist(ent),
                                          val.astype(np.int32))
        ft.name = "facet_tags"
        return msh, ct, ft

    @staticmethod
    def _V2():
        msh = Fx.get("scene")[0]
        return fem.functionspace(msh, ("Lagrange", 2, (3,)))

    @staticmethod
    def _elasticity():
        """Forms, bcs of a linear-elastic problem on the P2 scene (bottom clamped, top load)."""
        msh, ct, ft = Fx.get("scene")
        V = Fx.get("V2")
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        mu, lmbda = fem.Constant(msh, 1.0), fem.Constant(msh, 1.5)

        def eps(w):
            return ufl.sym(ufl.grad(w))
        sigma = 2 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(3)
        a_ufl = ufl.inner(sigma, eps(v)) * ufl.dx
        ds = ufl.Measure("ds", domain=msh, subdomain_data=ft, metadata={"quadrature_degree": 2})
        L_ufl = ufl.inner(fem.Constant(msh, np.array([0.0, 0.0, -1.0])), v) * ds(11)
        fdim = msh.topology.dim - 1
        dofs = fem.locate_dofs_topological(V, fdim, ft.find(10))
        bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), dofs, V)
        return dict(a=fem.form(a_ufl), L=fem.form(L_ufl), a_ufl=a_ufl, bcs=[bc], ds=ds)


def allsum(x):
    return comm.allreduce(x, op=MPI.SUM)


# ---------------------------------------------------------------- checks: spaces and functions
@check("fem.VectorFunctionSpace(msh, (\"Lagrange\", 2))",
       "fem.functionspace(msh, (\"Lagrange\", 2, (3,)))")
def _():
    assert not hasattr(fem, "VectorFunctionSpace")
    V = Fx.get("V1")
    assert V.dofmap.index_map_bs == 3 and V.num_sub_spaces == 3
    assert allsum(V.dofmap.index_map.size_local) == 7 ** 3


@check("fem.FunctionSpace(msh, ufl.VectorElement(...))",
       "fem.functionspace(msh, basix.ufl.element(\"Lagrange\", \"tetrahedron\", 2, shape=(3,)))")
def _():
    msh = Fx.get("msh1")
    V = fem.functionspace(msh, basix.ufl.element("Lagrange", "tetrahedron", 2, shape=(3,)))
    assert V.dofmap.index_map_bs == 3


@check("V.ufl_element().degree()",
       "V.ufl_element().embedded_superdegree (or V.element.basix_element.degree)")
def _():
    V = Fx.get("V1")
    assert V.ufl_element().embedded_superdegree == 2
    assert V.element.basix_element.degree == 2
    assert not callable(getattr(V.ufl_element(), "degree", None))   # ufl 2024.2: no degree()


@check("V.element.basix_element (family, degree, dim, tabulate)",
       "V.element.basix_element (the scalar sub-element of a blocked space: dim = 10)")
def _():
    el = Fx.get("V1").element.basix_element
    assert el.family == basix.ElementFamily.P and el.degree == 2 and el.dim == 10
    tab = el.tabulate(1, np.array([[0.2, 0.3, 0.1]]))
    assert tab.shape == (4, 1, 10, 1)


@check("V.element.needs_dof_transformations", "V.element.needs_dof_transformations")
def _():
    assert Fx.get("V1").element.needs_dof_transformations is False


@check("u.vector (PETSc Vec of a Function)", "u.x.petsc_vec")
def _():
    V = Fx.get("V1")
    u = fem.Function(V)
    assert not hasattr(u, "vector")
    u.x.array[:] = 1.0
    x = u.x.petsc_vec
    y = x.copy()
    y.axpy(2.0, x)
    y.copy(x)                                           # writes through to u.x.array
    assert np.allclose(u.x.array[: x.getLocalSize()], 3.0)
    assert np.isclose(x.norm(PETSc.NormType.NORM_INFINITY), 3.0)
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    assert np.allclose(u.x.array, 3.0)


@check("u.x.array / u.x.scatter_forward() / u.interpolate(f)",
       "u.x.array / u.x.scatter_forward() (scatter_reverse(la.InsertMode.add)) / u.interpolate(f)")
def _():
    u = fem.Function(Fx.get("V1"))
    u.interpolate(lambda x: np.vstack([x[0], 2 * x[1], 3 * x[2]]))
    u.x.scatter_forward()
    n = u.function_space.dofmap.index_map.size_local * 3
    before = u.x.array.copy()
    u.x.array[n:] = 0.0                      # ghosts add nothing
    u.x.scatter_reverse(la.InsertMode.add)
    u.x.scatter_forward()
    assert np.allclose(u.x.array, before) and u.x.array.max() <= 3.0 + 1e-12


@check("V.tabulate_dof_coordinates()", "V.tabulate_dof_coordinates()")
def _():
    V = Fx.get("V1")
    x = V.tabulate_dof_coordinates()
    assert x.shape == (V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts, 3)


@check("V.dofmap.list.array.reshape(num_nodes, -1)", "V.dofmap.list  (already (n_cells, 10) int32)")
def _():
    V = Fx.get("V1")
    dm = V.dofmap.list
    assert isinstance(dm, np.ndarray) and dm.ndim == 2 and dm.shape[1] == 10
    assert dm.shape[1] == V.dofmap.dof_layout.num_dofs


@check("V.dofmap.index_map{,_bs}.size_local/size_global/local_range/ghosts/num_ghosts",
       "unchanged")
def _():
    V = Fx.get("V1")
    im = V.dofmap.index_map
    r0, r1 = im.local_range
    assert r1 - r0 == im.size_local and im.ghosts.size == im.num_ghosts
    assert allsum(im.size_local) == im.size_global


@check("index_map.local_to_global(local)", "index_map.local_to_global(np.int32 array)")
def _():
    im = Fx.get("V1").dofmap.index_map
    loc = np.arange(im.size_local + im.num_ghosts, dtype=np.int32)
    g = im.local_to_global(loc)
    assert np.all(g[: im.size_local] == np.arange(*im.local_range))
    assert np.all(g[im.size_local:] == im.ghosts)


@check("V.sub(c).collapse() -> (Vc, map); fem.locate_dofs_topological((V.sub(c), Vc), ...)",
       "unchanged")
def _():
    msh, _, ft = Fx.get("scene")
    V = Fx.get("V2")
    Vc, _ = V.sub(2).collapse()
    dofs = fem.locate_dofs_topological((V.sub(2), Vc), 2, ft.find(11))
    g = fem.Function(Vc)
    g.interpolate(lambda x: 0.1 * x[0])
    bc = fem.dirichletbc(g, dofs, V.sub(2))
    assert isinstance(bc, fem.DirichletBC)


@check("u_sub.interpolate(f.sub(c)) (a component of a vector Function)", "unchanged")
def _():
    V = Fx.get("V1")
    f = fem.Function(V)
    f.interpolate(lambda x: np.vstack([x[0], x[1], x[2]]))
    Vc, _ = V.sub(1).collapse()
    g = fem.Function(Vc)
    g.interpolate(f.sub(1))
    x = Vc.tabulate_dof_coordinates()
    assert np.allclose(g.x.array, x[:, 1])


@check("fem.dirichletbc(value, dofs, V.sub(c)); fem.DirichletBCMetaClass",
       "fem.dirichletbc(...) -> fem.DirichletBC (type for annotations/isinstance)")
def _():
    assert not hasattr(fem, "DirichletBCMetaClass")
    bc = Fx.get("elasticity")["bcs"][0]
    assert isinstance(bc, fem.DirichletBC)
    V = Fx.get("V1")
    msh = Fx.get("msh1")
    dofs = fem.locate_dofs_geometrical(V.sub(0).collapse()[0], lambda x: np.isclose(x[0], 0.0))
    assert dofs.ndim == 1
    bc0 = fem.dirichletbc(PETSc.ScalarType(0.0), fem.locate_dofs_topological(
        V.sub(0), 2, dmesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[0], 0))),
        V.sub(0))
    assert isinstance(bc0, fem.DirichletBC)


@check("fem.set_bc(u.x.array, bcs)", "fem.set_bc(u.x.array, bcs) (or bc.set(u.x.array) per bc)")
def _():
    bcs = Fx.get("elasticity")["bcs"]
    u = fem.Function(Fx.get("V2"))
    u.x.array[:] = 1.0
    fem.set_bc(u.x.array, bcs)
    w = fem.Function(Fx.get("V2"))
    w.x.array[:] = 1.0
    for bc in bcs:
        bc.set(w.x.array)
    assert np.array_equal(u.x.array, w.x.array)
    assert allsum(np.count_nonzero(u.x.array == 0.0)) > 0


@check("fem.Constant(msh, value); ufl.Measure(\"ds\", subdomain_data=ft, metadata=...)",
       "unchanged")
def _():
    msh, _, ft = Fx.get("scene")
    ds = Fx.get("elasticity")["ds"]
    area = allsum(fem.assemble_scalar(fem.form(fem.Constant(msh, PETSc.ScalarType(1.0)) * ds(10))))
    assert abs(area - 1.0) < 1e-12


# ---------------------------------------------------------------- geometry, topology, tags
@check("msh.geometry.cmap.degree", "msh.geometry.cmap.degree")
def _():
    assert Fx.get("scene")[0].geometry.cmap.degree == 2
    assert Fx.get("msh1").geometry.cmap.degree == 1


@check("msh.geometry.dofmap.array.reshape(num_nodes, -1)",
       "msh.geometry.dofmap  ((n_cells, 10) int32)")
def _():
    dm = Fx.get("scene")[0].geometry.dofmap
    assert isinstance(dm, np.ndarray) and dm.shape[1] == 10


@check("msh.geometry.cmap.create_dof_layout()", "unchanged (entity_closure_dofs etc.)")
def _():
    layout = Fx.get("scene")[0].geometry.cmap.create_dof_layout()
    assert len(layout.entity_closure_dofs(2, 0)) == 6


@check("msh.geometry.x / msh.geometry.index_map()", "unchanged; input_global_indices added")
def _():
    g = Fx.get("scene")[0].geometry
    assert g.x.shape[1] == 3 and g.x.shape[0] == g.index_map().size_local + g.index_map().num_ghosts
    assert g.input_global_indices.size == g.x.shape[0]


@check("ufl.Mesh(ufl.VectorElement(ufl.FiniteElement(\"Lagrange\", ufl.Cell(name, "
       "geometric_dimension=3), 2, variant=\"equispaced\")))",
       "ufl.Mesh(basix.ufl.element(\"Lagrange\", name, 2, shape=(3,), "
       "lagrange_variant=basix.LagrangeVariant.equispaced))")
def _():
    assert not hasattr(ufl, "VectorElement") and not hasattr(ufl, "FiniteElement")
    e = basix.ufl.element("Lagrange", "tetrahedron", 2, shape=(3,),
                          lagrange_variant=basix.LagrangeVariant.equispaced)
    assert ufl.Mesh(e).ufl_cell() == ufl.Cell("tetrahedron")


@check("dolfinx.mesh.create_mesh(comm, cells, x, domain)  (gmsh order via perm_gmsh)",
       "dolfinx.mesh.create_mesh(comm, cells (int64), x, ufl.Mesh(basix.ufl element))")
def _():
    msh, _, _ = Fx.get("scene")
    vol = allsum(fem.assemble_scalar(fem.form(fem.Constant(msh, 1.0) * ufl.dx(domain=msh))))
    assert abs(vol - 1.0) < 1e-12


@check("dolfinx.cpp.io.perm_gmsh(cell_type, n) / dolfinx.cpp.mesh.to_type(name) / "
       "dolfinx.cpp.mesh.cell_entity_type(cell, tdim-1, 0)",
       "unchanged (dolfinx.mesh.to_type also exists)")
def _():
    c = dolfinx.cpp.mesh.to_type("tetrahedron")
    assert c == dmesh.CellType.tetrahedron == dmesh.to_type("tetrahedron")
    # the same permutations as on 0.5.2 (printed there)
    assert list(dolfinx.cpp.io.perm_gmsh(c, 10)) == [0, 1, 2, 3, 8, 9, 5, 7, 6, 4]
    assert list(dolfinx.cpp.io.perm_gmsh(dmesh.CellType.triangle, 6)) == [0, 1, 2, 4, 5, 3]
    assert dolfinx.cpp.mesh.cell_entity_type(c, 2, 0) == dmesh.CellType.triangle


@check("dolfinx.cpp.io.distribute_entity_data(msh._mesh, dim, entities, values)",
       "dolfinx.io.distribute_entity_data(msh, dim, entities (int64), values)")
def _():
    _, ct, ft = Fx.get("scene")
    assert allsum(np.count_nonzero(ct.values == 1)) > 0


@check("dolfinx.mesh.meshtags_from_entities(msh, dim, "
       "dolfinx.cpp.graph.AdjacencyList_int32(entities), values)",
       "dolfinx.mesh.meshtags_from_entities(msh, dim, dolfinx.graph.adjacencylist(entities), "
       "values)")
def _():
    msh, ct, ft = Fx.get("scene")
    nown = msh.topology.index_map(2).size_local
    for tag in (10, 11):
        f = ft.find(tag)
        area = allsum(fem.assemble_scalar(fem.form(
            fem.Constant(msh, 1.0) * ufl.Measure("ds", domain=msh, subdomain_data=ft)(tag))))
        assert abs(area - 1.0) < 1e-12, area
        assert allsum(np.count_nonzero(f < nown)) > 0


@check("msh._mesh (the C++ mesh)", "msh._cpp_object")
def _():
    msh = Fx.get("scene")[0]
    assert not hasattr(msh, "_mesh") and msh._cpp_object is not None


@check("dolfinx.cpp.mesh.entities_to_geometry(msh._mesh, fdim, facets, False)",
       "dolfinx.mesh.entities_to_geometry(msh, fdim, facets (int32), False)")
def _():
    msh, _, ft = Fx.get("scene")
    msh.topology.create_connectivity(2, 0)
    nodes = dmesh.entities_to_geometry(msh, 2, ft.find(10).astype(np.int32), False)
    assert nodes.shape[1] == 6
    assert np.allclose(msh.geometry.x[nodes.ravel(), 2], 0.0)


@check("msh.topology.{dim,cell_type,index_map(d),create_connectivity,connectivity(a,b)."
       "{array,offsets}}", "unchanged")
def _():
    msh = Fx.get("scene")[0]
    t = msh.topology
    t.create_connectivity(2, 3)
    c = t.connectivity(2, 3)
    assert t.dim == 3 and t.cell_type == dmesh.CellType.tetrahedron
    assert c.offsets.size == t.index_map(2).size_local + t.index_map(2).num_ghosts + 1
    assert c.array.dtype == np.int32


@check("dolfinx.mesh.{meshtags, compute_midpoints, exterior_facet_indices, "
       "locate_entities_boundary, create_box, create_unit_cube}", "unchanged")
def _():
    msh = dmesh.create_box(comm, [np.zeros(3), np.ones(3)], [2, 2, 2], dmesh.CellType.hexahedron)
    msh.topology.create_connectivity(2, 3)
    ext = dmesh.exterior_facet_indices(msh.topology)
    mid = dmesh.compute_midpoints(msh, 2, ext)
    tags = dmesh.meshtags(msh, 2, ext, np.full(ext.size, 7, dtype=np.int32))
    assert mid.shape == (ext.size, 3) and tags.find(7).size == ext.size
    b = dmesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[2], 1.0))
    assert allsum(np.count_nonzero(b < msh.topology.index_map(2).size_local)) == 4


@check("(gmsh -> own arrays; gmshio not used)",
       "dolfinx.io.gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=3) -> (mesh, cell_tags, "
       "facet_tags)")
def _():
    import gmsh
    Fx.get("gmsh_p2")                      # rank 0 holds the gmsh model
    res = dolfinx.io.gmshio.model_to_mesh(gmsh.model if comm.rank == 0 else None, comm, 0, gdim=3)
    msh, ct, ft = res[0], res[1], res[2]
    assert msh.geometry.cmap.degree == 2
    area = allsum(fem.assemble_scalar(fem.form(
        fem.Constant(msh, 1.0) * ufl.Measure("ds", domain=msh, subdomain_data=ft)(10))))
    assert abs(area - 1.0) < 1e-12


# ---------------------------------------------------------------- assembly, matrices, vectors
@check("fem.form / fem.assemble_scalar", "unchanged")
def _():
    e = Fx.get("elasticity")
    msh = Fx.get("scene")[0]
    u = fem.Function(Fx.get("V2"))
    u.interpolate(lambda x: np.vstack([x[0], 0 * x[0], 0 * x[0]]))
    en = allsum(fem.assemble_scalar(fem.form(ufl.action(ufl.action(e["a_ufl"], u), u))))
    assert abs(en - (2 * 1.0 + 1.5)) < 1e-10, en     # 2 mu + lambda for eps = e_x (x) e_x
    assert msh is not None


@check("fem.petsc.create_matrix(a); fem.petsc.assemble_matrix(A, a, bcs=bcs[, diagonal=0.0])",
       "unchanged (A = assemble_matrix(a, bcs) also creates)")
def _():
    e = Fx.get("elasticity")
    A = dolfinx.fem.petsc.create_matrix(e["a"])
    A.zeroEntries()
    dolfinx.fem.petsc.assemble_matrix(A, e["a"], bcs=e["bcs"])
    A.assemble()
    B = dolfinx.fem.petsc.create_matrix(e["a"])
    dolfinx.fem.petsc.assemble_matrix(B, e["a"], bcs=e["bcs"], diagonal=0.0)
    B.assemble()
    assert A.getBlockSize() == 3 and A.norm() > 0 and abs(A.norm() - B.norm()) > 0


@check("fem.petsc.assemble_vector(L) -> Vec; b.ghostUpdate(ADD, REVERSE)", "unchanged")
def _():
    e = Fx.get("elasticity")
    b = dolfinx.fem.petsc.assemble_vector(e["L"])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    assert abs(b.sum() + 1.0) < 1e-12      # total load -1 on the unit top face (z component)


@check("fem.petsc.apply_lifting(b, [a], bcs=[bcs], x0=[x], scale=-1.0)",
       "fem.petsc.apply_lifting(b, [a], bcs=[bcs], x0=[x], alpha=-1.0)  (scale -> alpha)")
def _():
    e = Fx.get("elasticity")
    b = dolfinx.fem.petsc.create_vector(e["L"])
    with b.localForm() as bl:
        bl.set(0.0)
    u = fem.Function(Fx.get("V2"))
    u.x.array[:] = 0.01
    dolfinx.fem.petsc.apply_lifting(b, [e["a"]], bcs=[e["bcs"]], x0=[u.x.petsc_vec], alpha=-1.0)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    assert np.isfinite(b.norm())


@check("fem.petsc.set_bc(b, bcs, x0, scale)",
       "fem.petsc.set_bc(b, bcs, x0, alpha)  (scale -> alpha)")
def _():
    e = Fx.get("elasticity")
    b = dolfinx.fem.petsc.assemble_vector(e["L"])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    u = fem.Function(Fx.get("V2"))
    u.x.array[:] = 0.5
    dolfinx.fem.petsc.set_bc(b, e["bcs"], u.x.petsc_vec, -1.0)
    dolfinx.fem.petsc.set_bc(b, e["bcs"], alpha=0.0)
    assert np.isfinite(b.norm())


@check("dolfinx.fem.create_sparsity_pattern(a); sp.assemble(); sp.graph (AdjacencyList: "
       ".array/.offsets); sp.column_index_map()",
       "fem.create_sparsity_pattern(a); sp.finalize(); sp.graph -> (array, offsets) tuple; "
       "sp.column_index_map()")
def _():
    e = Fx.get("elasticity")
    V = Fx.get("V2")
    sp = fem.create_sparsity_pattern(e["a"])
    sp.finalize()
    g = sp.graph
    assert isinstance(g, tuple) and len(g) == 2
    array, offsets = g
    cm = sp.column_index_map()
    col_l2g = np.concatenate([np.arange(*cm.local_range, dtype=np.int64),
                              cm.ghosts.astype(np.int64)])
    n_loc = V.dofmap.index_map.size_local
    assert offsets.size >= n_loc + 1 and col_l2g[array[: offsets[n_loc]]].max() < cm.size_global
    assert sp.index_map(0).size_local == n_loc


@check("dolfinx.cpp.la.petsc.create_vector(index_map, bs)",
       "dolfinx.la.create_petsc_vector(index_map, bs)  (cpp.la.petsc.create_vector gone)")
def _():
    assert not hasattr(dolfinx.cpp.la.petsc, "create_vector")
    V = Fx.get("V2")
    v = la.create_petsc_vector(V.dofmap.index_map, 3)
    assert v.getLocalSize() == 3 * V.dofmap.index_map.size_local
    iset = PETSc.IS().createGeneral(np.arange(min(5, v.getLocalSize()), dtype=PETSc.IntType)
                                    + v.getOwnershipRange()[0], comm=MPI.COMM_SELF)
    loc = PETSc.Vec().createSeq(iset.getSize(), comm=MPI.COMM_SELF)
    sc = PETSc.Scatter().create(v, iset, loc, None)
    v.set(2.0)
    sc.scatter(v, loc, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    assert np.allclose(loc.getArray(), 2.0)


@check("la.create_petsc_vector(imap, bs) x6 + la.orthonormalize(petsc_vecs) -> PETSc.NullSpace",
       "la.vector(imap, bs) x6 + la.orthonormalize(la.Vector list) + "
       "PETSc.Vec().createWithArray(v.array[:bs*n_owned], bsize=bs) -> PETSc.NullSpace")
def _():
    V = Fx.get("V2")
    im, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    x = V.tabulate_dof_coordinates()
    basis = [la.vector(im, bs=bs, dtype=PETSc.ScalarType) for _ in range(6)]
    b = [v.array for v in basis]
    for i in range(3):
        b[i][i::3] = 1.0
    b[3][0::3], b[3][1::3] = -x[:, 1], x[:, 0]
    b[4][0::3], b[4][2::3] = x[:, 2], -x[:, 0]
    b[5][2::3], b[5][1::3] = x[:, 1], -x[:, 2]
    la.orthonormalize(basis)
    assert la.is_orthonormal(basis)
    n = bs * im.size_local
    vecs = [PETSc.Vec().createWithArray(v.array[:n], bsize=bs, comm=comm) for v in basis]
    ns = PETSc.NullSpace().create(vectors=vecs, comm=comm)
    assert ns.test(_assembled_A())
    # la.orthonormalize on PETSc vectors (the 0.5.2 call) is not supported any more:
    try:
        la.orthonormalize([la.create_petsc_vector(im, bs)])
        raise AssertionError("orthonormalize accepted a PETSc Vec")
    except (TypeError, AttributeError):
        pass


def _assembled_A():
    A = dolfinx.fem.petsc.assemble_matrix(Fx.get("elasticity")["a"])   # no bcs: singular
    A.assemble()
    return A


@check("PETSc Mat().setSizes/setPreallocationCSR/LGMap/setLGMap + assemble_matrix into it",
       "unchanged (petsc4py 3.22)")
def _():
    V = Fx.get("V2")
    e = Fx.get("elasticity")
    im, bs = V.dofmap.index_map, 3
    R = dolfinx.fem.petsc.assemble_matrix(e["a"], bcs=e["bcs"])
    R.assemble()
    ai, aj, _ = R.getValuesCSR()            # owned scalar rows, global columns
    A = PETSc.Mat().create(comm=comm)
    n_loc, n_glob = im.size_local, im.size_global
    A.setSizes(((bs * n_loc, bs * n_glob), (bs * n_loc, bs * n_glob)), bsize=bs)
    A.setType(PETSc.Mat.Type.AIJ)
    A.setPreallocationCSR((ai.astype(PETSc.IntType), aj.astype(PETSc.IntType)))
    l2g = np.concatenate([np.arange(*im.local_range, dtype=np.int64), im.ghosts.astype(np.int64)])
    lg = PETSc.LGMap().create(l2g.astype(PETSc.IntType), bsize=bs, comm=MPI.COMM_SELF)
    A.setLGMap(lg, lg)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    A.zeroEntries()
    dolfinx.fem.petsc.assemble_matrix(A, e["a"], bcs=e["bcs"])
    A.assemble()
    A.axpy(-1.0, R, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert A.norm() < 1e-12 * R.norm(), (A.norm(), R.norm())


@check("PETSc.SNES with setFunction/setJacobian on dolfinx Vec/Mat; PETSc.Options prefix",
       "unchanged (petsc4py 3.22)")
def _():
    e = Fx.get("elasticity")
    V = Fx.get("V2")
    u = fem.Function(V)
    A = dolfinx.fem.petsc.create_matrix(e["a"])
    b = dolfinx.fem.petsc.create_vector(e["L"])
    f = dolfinx.fem.petsc.assemble_vector(e["L"])
    f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dolfinx.fem.petsc.set_bc(f, e["bcs"], alpha=0.0)

    def F(snes, x, r):
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, e["a"], bcs=e["bcs"])
        A.assemble()
        A.mult(x, r)
        r.axpy(-1.0, f)
        dolfinx.fem.petsc.set_bc(r, e["bcs"], x, -1.0)

    def J(snes, x, Jm, P):
        pass
    opts = PETSc.Options()
    opts["chk_ksp_type"] = "preonly"
    opts["chk_pc_type"] = "lu"
    opts["chk_pc_factor_mat_solver_type"] = "mumps"
    snes = PETSc.SNES().create(comm)
    snes.setOptionsPrefix("chk_")
    snes.setFunction(F, b)
    snes.setJacobian(J, A)
    snes.setFromOptions()
    x = u.x.petsc_vec.copy()
    snes.solve(None, x)
    assert snes.getConvergedReason() > 0
    for k in ("chk_ksp_type", "chk_pc_type", "chk_pc_factor_mat_solver_type"):
        del opts[k]
    snes.destroy()


@check("(not used) dolfinx.fem.Expression(expr, X); expr.eval(msh, cells)",
       "fem.Expression(ufl_expr, X_ref) ; expr.eval(msh, np.int32 cells) -> (n_cells, n_pts*vs)")
def _():
    V = Fx.get("V2")
    msh = V.mesh
    u = fem.Function(V)
    u.interpolate(lambda x: np.vstack([x[0], x[1], x[2]]))
    X, _ = basix.make_quadrature(basix.CellType.tetrahedron, 2)
    expr = fem.Expression(ufl.tr(ufl.grad(u)), X)
    n = msh.topology.index_map(3).size_local
    vals = expr.eval(msh, np.arange(n, dtype=np.int32))
    assert vals.shape == (n, X.shape[0]) and np.allclose(vals, 3.0)


@check("(not used) facet expression: fem.Expression on facet points",
       "fem.Expression(expr, X_facet_ref) ; expr.eval(msh, flat (cell, local_facet) pairs from "
       "fem.compute_integration_domains(exterior_facet, topology, facets, fdim))")
def _():
    V = Fx.get("V2")
    msh, _, ft = Fx.get("scene")
    u = fem.Function(V)
    u.interpolate(lambda x: np.vstack([x[0], 2 * x[1], 3 * x[2]]))
    n = ufl.FacetNormal(msh)
    Xf, _ = basix.make_quadrature(basix.CellType.triangle, 2)
    expr = fem.Expression(ufl.dot(u, n), Xf)
    tdim = 3
    msh.topology.create_connectivity(2, 3)
    msh.topology.create_connectivity(3, 2)
    facets = ft.find(11)
    facets = facets[facets < msh.topology.index_map(2).size_local]
    ent = fem.compute_integration_domains(fem.IntegralType.exterior_facet, msh.topology, facets,
                                          tdim - 1)
    vals = expr.eval(msh, ent)                # flat: cell0, lf0, cell1, lf1, ...
    assert vals.shape[0] == facets.size
    assert facets.size == 0 or np.allclose(vals, 3.0)    # u.n = 3 z = 3 on top, n = +z


# ---------------------------------------------------------------- basix
@check("basix.{make_quadrature, topology, geometry, cell.facet_outward_normals, "
       "create_element(P, cell, deg, LagrangeVariant.equispaced)}", "unchanged (basix 0.9)")
def _():
    pts, wts = basix.make_quadrature(basix.CellType.triangle, 2)
    assert pts.shape == (3, 2) and abs(wts.sum() - 0.5) < 1e-14
    assert len(basix.topology(basix.CellType.tetrahedron)[2]) == 4
    assert basix.geometry(basix.CellType.hexahedron).shape == (8, 3)
    assert basix.cell.facet_outward_normals(basix.CellType.tetrahedron).shape == (4, 3)
    el = basix.create_element(basix.ElementFamily.P, basix.CellType.tetrahedron, 2,
                              basix.LagrangeVariant.equispaced)
    assert el.dim == 10 and el.tabulate(1, np.zeros((0, 3))).shape == (4, 0, 10, 1)


@check("coordinate element: basix.create_element(P, cell, cmap.degree, equispaced)",
       "same (0.9's CoordinateElement has push_forward/pull_back, no tabulate); cmap.variant")
def _():
    msh = Fx.get("scene")[0]
    cm = msh.geometry.cmap
    assert not hasattr(cm, "tabulate")
    X = np.array([[0.1, 0.2, 0.3], [0.25, 0.25, 0.25]])
    el = basix.create_element(basix.ElementFamily.P, basix.CellType.tetrahedron, cm.degree,
                              basix.LagrangeVariant.equispaced)
    if msh.topology.index_map(3).size_local:
        cx = msh.geometry.x[msh.geometry.dofmap[0]]
        assert np.allclose(cm.push_forward(X, cx), el.tabulate(0, X)[0, :, :, 0] @ cx)
    assert cm.variant == int(basix.LagrangeVariant.equispaced)


# ---------------------------------------------------------------- output
def _tmpdir():
    d = tempfile.mkdtemp(prefix="rc09_") if comm.rank == 0 else None
    return comm.bcast(d, root=0)


@check("XDMFFile(comm, f, \"w\").write_mesh(msh); write_meshtags(tags)",
       "XDMFFile.write_mesh(msh); write_meshtags(tags, msh.geometry)  (geometry now required)")
def _():
    msh, ct, ft = Fx.get("scene")
    path = os.path.join(_tmpdir(), "scene.xdmf")
    with dolfinx.io.XDMFFile(comm, path, "w") as xdmf:
        xdmf.write_mesh(msh)
        xdmf.write_meshtags(ct, msh.geometry)
        xdmf.write_meshtags(ft, msh.geometry)
    Fx._cache["scene_xdmf"] = path


@check("XDMFFile(comm, f, \"r\").read_mesh(name=); read_meshtags(msh, name=)", "unchanged")
def _():
    if "scene_xdmf" not in Fx._cache:
        raise AssertionError("needs the write check")
    with dolfinx.io.XDMFFile(MPI.COMM_SELF, Fx._cache["scene_xdmf"], "r") as xdmf:
        msh = xdmf.read_mesh(name="mesh")
        msh.topology.create_connectivity(2, 3)
        ft = xdmf.read_meshtags(msh, name="facet_tags")
    assert msh.geometry.cmap.degree == 2 and ft.find(10).size > 0


@check("XDMFFile(..., \"w\"/\"a\").write_function(u_geometry_degree, t)",
       "unchanged (the function's degree must equal the geometry's; P2 on a P1 mesh: "
       "interpolate into P1 first)")
def _():
    V = Fx.get("V2")
    u = fem.Function(V, name="u")
    u.interpolate(lambda x: np.vstack([x[0], x[1], x[2]]))
    path = os.path.join(_tmpdir(), "u.xdmf")
    with dolfinx.io.XDMFFile(comm, path, "w") as xdmf:
        xdmf.write_mesh(V.mesh)
        xdmf.write_function(u, 0.0)
    with dolfinx.io.XDMFFile(comm, path, "a") as xdmf:
        xdmf.write_function(u, 1.0)
    # P2 displacement on a P1 mesh -> interpolate to P1 for XDMF
    V1 = Fx.get("V1")
    w = fem.Function(V1)
    w.interpolate(lambda x: np.vstack([x[0], x[1], x[2]]))
    W = fem.functionspace(V1.mesh, ("Lagrange", V1.mesh.geometry.cmap.degree, (3,)))
    wo = fem.Function(W, name="u")
    wo.interpolate(w)
    with dolfinx.io.XDMFFile(comm, path.replace("u.xdmf", "w.xdmf"), "w") as xdmf:
        xdmf.write_mesh(V1.mesh)
        xdmf.write_function(wo, 0.0)


@check("(no VTX on 0.5.2 from Debian 12)",
       "dolfinx.io.VTXWriter(comm, \"u.bp\", [u], engine=\"BP4\"); .write(t)  "
       "(ADIOS2 in Debian 13: "
       "P2 on P1 mesh allowed)")
def _():
    assert dolfinx.common.has_adios2
    V = Fx.get("V1")
    u = fem.Function(V, name="u")
    u.interpolate(lambda x: np.vstack([x[0], x[1], x[2]]))
    d = _tmpdir()
    with dolfinx.io.VTXWriter(comm, os.path.join(d, "u.bp"), [u], engine="BP4") as vtx:
        vtx.write(0.0)
        u.x.array[:] *= 2
        vtx.write(1.0)
    comm.barrier()
    # (Debian 13's python3-dolfinx does not pull in ADIOS2's Python module: no read-back here)
    assert os.path.isfile(os.path.join(d, "u.bp", "md.idx"))
    assert os.path.getsize(os.path.join(d, "u.bp", "data.0")) > 0


@check("(none)", "dolfinx.fem.petsc.NonlinearProblem + dolfinx.nls.petsc.NewtonSolver "
       "(a 0.9 user's own Newton loop)")
def _():
    import dolfinx.nls.petsc
    msh, _, ft = Fx.get("scene")
    V = Fx.get("V2")
    u = fem.Function(V)
    v = ufl.TestFunction(V)
    e = Fx.get("elasticity")
    mu, lmbda = 1.0, 1.5
    eps = ufl.sym(ufl.grad(u))
    F = ufl.inner(2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(3), ufl.sym(ufl.grad(v))) \
        * ufl.dx - ufl.inner(fem.Constant(msh, np.array([0.0, 0.0, -1.0])), v) * e["ds"](11)
    problem = dolfinx.fem.petsc.NonlinearProblem(F, u, bcs=e["bcs"])
    solver = dolfinx.nls.petsc.NewtonSolver(comm, problem)
    n, converged = solver.solve(u)
    assert converged and n <= 2


# ---------------------------------------------------------------- runner
def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", help="write the results to this file (rank 0)")
    args = ap.parse_args()
    rows = []
    for old, new, fn in CHECKS:
        err = None
        try:
            fn()
        except Exception as exc:  # noqa: BLE001 - recorded
            err = f"{type(exc).__name__}: {exc}".splitlines()[0][:200]
            if os.environ.get("RC_CHECK_TRACE"):
                traceback.print_exc()
        errs = comm.allgather(err)
        ok = all(e is None for e in errs)
        first = next((e for e in errs if e is not None), "")
        rows.append(dict(old=old, new=new, ok=ok, error=first))
    if comm.rank == 0:
        import gmsh
        import mpi4py
        versions = dict(dolfinx=dolfinx.__version__, basix=basix.__version__,
                        ufl=ufl.__version__, petsc4py=petsc4py.__version__,
                        petsc=".".join(map(str, PETSc.Sys.getVersion())), numpy=np.__version__,
                        mpi4py=mpi4py.__version__, gmsh=gmsh.__version__,
                        python=sys.version.split()[0], has_adios2=dolfinx.common.has_adios2,
                        ranks=comm.size)
        print("versions:", versions)
        print(f"| 0.5.2 call | 0.9 call | verified ({comm.size} rank{'s' * (comm.size > 1)}) |")
        print("|---|---|---|")
        for r in rows:
            ver = "yes" if r["ok"] else f"no: {r['error']}"
            print(f"| `{r['old']}` | `{r['new']}` | {ver} |")
        n_ok = sum(r["ok"] for r in rows)
        print(f"{n_ok} passed, {len(rows) - n_ok} failed")
        if args.json:
            with open(args.json, "w") as f:
                json.dump(dict(versions=versions, rows=rows), f, indent=1)
    return 0 if all(r["ok"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
