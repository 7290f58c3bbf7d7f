"""The one place where the DOLFINx API version shows.

Supported: DOLFINx 0.5.2 (Debian 12: numpy 1.24, PETSc 3.18, ufl 2022.2, basix 0.5) and 0.9
(Debian 13: numpy 2.2, PETSc 3.22, ufl 2024.2, basix 0.9). Every call whose spelling differs
between the two goes through a function here (function spaces with a value shape, the PETSc
vector of a function, dofmap arrays, degrees, sparsity patterns, vector/matrix/null-space
creation, the mesh domain, entity data and tags from gmsh arrays, lifting and Dirichlet rows,
mesh tags in XDMF); calls that are the same on both are made directly. Nothing outside
``rough_contact.fem`` (and the mesh builders / output modules) imports dolfinx; the solver and
the scenes ask the problem or these functions. docs/dolfinx09_port.md lists every call and
its two spellings, each checked on both versions.

Units: none (pure plumbing).
"""

from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

import dolfinx
import dolfinx.cpp
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.graph
import dolfinx.io
import dolfinx.la
import dolfinx.mesh
from mpi4py import MPI

__all__ = ["DOLFINX_VERSION", "NEW_API", "vector_space", "petsc_vector", "function_values", "interpolate",
           "element_degree", "geometry_degree", "geometry_dofmap", "cell_dofmap",
           "node_input_indices", "node_keys", "geometry_input_indices",
           "create_petsc_vector", "form_sparsity", "block_csr_matrix", "near_nullspace",
           "mesh_domain", "create_mesh", "meshtags_from_arrays", "facet_geometry_nodes",
           "set_bc", "set_bc_array", "apply_lifting", "write_meshtags", "DirichletBC"]

DOLFINX_VERSION: tuple = tuple(int(p) for p in dolfinx.__version__.split(".")[:2])
#: True on DOLFINx >= 0.8 (the API of 0.9); False on 0.5.2.
NEW_API: bool = DOLFINX_VERSION >= (0, 8)
if DOLFINX_VERSION < (0, 5) or (0, 5) < DOLFINX_VERSION < (0, 8) or DOLFINX_VERSION > (0, 9):
    import warnings
    warnings.warn(f"DOLFINx {dolfinx.__version__} is not a tested version (0.5.2 and 0.9 are); "
                  "rough_contact may fail", RuntimeWarning, stacklevel=2)

#: The Dirichlet condition type (for annotations and isinstance).
DirichletBC = dolfinx.fem.DirichletBC if NEW_API else dolfinx.fem.DirichletBCMetaClass


# ------------------------------------------------------------------ spaces and functions
def vector_space(mesh, degree: int, family: str = "Lagrange"):
    """The vector (3-component) space of ``family`` and ``degree`` on ``mesh``."""
    if NEW_API:
        return dolfinx.fem.functionspace(mesh, (family, int(degree), (3,)))
    return dolfinx.fem.VectorFunctionSpace(mesh, (family, int(degree)))


def petsc_vector(u):
    """The PETSc vector holding the owned (and ghost) values of the Function ``u``."""
    return u.x.petsc_vec if NEW_API else u.vector


def function_values(u) -> np.ndarray:
    """The local values (owned and ghost) of the Function ``u``, a flat array view."""
    return u.x.array


def interpolate(u, f, cells=None) -> None:
    """``u.interpolate(f)`` on the given local cells only (all cells if None)."""
    if cells is None:
        u.interpolate(f)
    elif NEW_API:
        u.interpolate(f, cells0=np.asarray(cells, dtype=np.int32))
    else:
        u.interpolate(f, cells=cells)


def element_degree(V) -> int:
    """Polynomial degree of the space ``V``."""
    return int(V.element.basix_element.degree)


def geometry_degree(mesh) -> int:
    """Degree of the mesh's coordinate map."""
    return int(mesh.geometry.cmap.degree)


def geometry_dofmap(mesh) -> np.ndarray:
    """(n_cells, n_geometry_nodes) geometry node indices of every local cell."""
    dm = mesh.geometry.dofmap
    return np.asarray(dm) if NEW_API else dm.array.reshape(dm.num_nodes, -1)


def node_input_indices(V) -> Optional[np.ndarray]:
    """(n_local_nodes,) int64: for every node of ``V`` on this rank (owned, then ghost), the
    index of its geometry node in the arrays the mesh was built from (``input_global_indices``:
    the same for every partition and number of ranks); None when ``V``'s nodes are not the
    geometry's (another degree or layout: checked on the coordinates)."""
    msh = V.mesh
    if element_degree(V) != geometry_degree(msh):
        return None
    dofs, geo = cell_dofmap(V), geometry_dofmap(msh)
    imap = V.dofmap.index_map
    n = imap.size_local + imap.num_ghosts
    if dofs.shape != geo.shape:
        return None
    out = np.full(n, -1, dtype=np.int64)
    out[dofs.reshape(-1)] = np.asarray(msh.geometry.input_global_indices,
                                       dtype=np.int64)[geo.reshape(-1)]
    x = V.tabulate_dof_coordinates()[dofs.reshape(-1)]
    xg = msh.geometry.x[geo.reshape(-1)]
    scale = max(1.0, float(np.abs(msh.geometry.x).max(initial=0.0)))
    if np.any(out < 0) or not np.allclose(x, xg, rtol=0.0, atol=1e-12 * scale):
        return None
    return out


def node_keys(V) -> Optional[np.ndarray]:
    """(n_local_nodes,) int64 keys of every node of ``V`` on this rank (owned, then ghost) that
    do not depend on the partition or the number of ranks (collective), or None where none are
    available.

    A node that is a geometry node is keyed by that node's input index i
    (:func:`node_input_indices`). Degree 2 on a simplex mesh of affine geometry (P2 on
    triangles and tetrahedra) is also keyed: a vertex node by i, an edge's midside node by
    N + min(i, j) N + max(i, j), with i, j its edge's end vertices and N the global number of
    input nodes, so the keys of the two kinds never meet. Which cell node is which vertex or
    edge is found from the coordinates (a cell's nodes lie at its vertices and at its edges'
    midpoints) on one cell and checked on all to 1e-9 of the mesh's extent; anything else
    (Q2, degree 3, curved cells, N ≥ 3e9) gives None."""
    keys = node_input_indices(V)
    msh = V.mesh
    imap = V.dofmap.index_map
    n = imap.size_local + imap.num_ghosts
    comm = msh.comm
    simplex = msh.topology.cell_type.name in ("triangle", "tetrahedron")
    usable = (keys is None and simplex and element_degree(V) == 2 and geometry_degree(msh) == 1)
    if not comm.allreduce(usable, op=MPI.LAND):
        return keys
    dofs, geo = cell_dofmap(V), geometry_dofmap(msh)
    nv = geo.shape[1]
    edges = np.array([(a, b) for a in range(nv) for b in range(a + 1, nv)], dtype=np.int64)
    inputs = np.asarray(msh.geometry.input_global_indices, dtype=np.int64)
    n_input = int(comm.allreduce(int(inputs.max(initial=-1)) + 1, op=MPI.MAX))
    ok = dofs.shape[1] == nv + len(edges) and n_input < 3_000_000_000
    out = np.full(n, -1, dtype=np.int64)
    if ok and len(dofs):
        xv = msh.geometry.x[geo]                                        # (cells, nv, 3)
        places = np.concatenate([xv, 0.5 * (xv[:, edges[:, 0]] + xv[:, edges[:, 1]])], axis=1)
        x = V.tabulate_dof_coordinates()[dofs]                           # (cells, nodes, 3)
        scale = max(1.0, float(np.ptp(msh.geometry.x, axis=0).max()))
        first = np.linalg.norm(x[0][:, None, :] - places[0][None, :, :], axis=2)
        where = np.argmin(first, axis=1)                                 # node -> place
        ok = (len(np.unique(where)) == len(where)
              and np.abs(x - places[:, where]).max() <= 1e-9 * scale)
        if ok:
            vid = inputs[geo]                                            # (cells, nv)
            lo = np.minimum(vid[:, edges[:, 0]], vid[:, edges[:, 1]])
            hi = np.maximum(vid[:, edges[:, 0]], vid[:, edges[:, 1]])
            place_keys = np.concatenate([vid, n_input + lo * n_input + hi], axis=1)
            out[dofs.reshape(-1)] = place_keys[:, where].reshape(-1)
            ok = not np.any(out < 0)
    if not comm.allreduce(bool(ok), op=MPI.LAND):
        return None
    return out


def geometry_input_indices(msh) -> np.ndarray:
    """(n_owned_geometry_nodes,) int64 input indices of this rank's owned geometry nodes, in
    the order an XDMF file writes them."""
    n = msh.geometry.index_map().size_local
    return np.asarray(msh.geometry.input_global_indices, dtype=np.int64)[:n]


def cell_dofmap(V) -> np.ndarray:
    """(n_cells, n_dofs_per_cell) block (node) indices of every local cell of ``V``."""
    dm = V.dofmap.list
    return np.asarray(dm) if NEW_API else dm.array.reshape(dm.num_nodes, -1)


# ------------------------------------------------------------------ PETSc objects
def create_petsc_vector(V):
    """A new (ghosted) PETSc vector of ``V``'s layout, block size of ``V``."""
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    if NEW_API:
        return dolfinx.la.create_petsc_vector(imap, bs)
    return dolfinx.cpp.la.petsc.create_vector(imap, bs)


def form_sparsity(a, V) -> tuple[np.ndarray, np.ndarray]:
    """The node-level (block) sparsity pattern of the bilinear form ``a`` on ``V`` x ``V`` on
    this rank's owned rows, in global indices: (rows, cols) int64 arrays."""
    sp = dolfinx.fem.create_sparsity_pattern(a)
    if NEW_API:
        sp.finalize()
        array, offsets = sp.graph
    else:
        sp.assemble()
        array, offsets = sp.graph.array, sp.graph.offsets
    imap = V.dofmap.index_map
    n_loc, r0 = imap.size_local, imap.local_range[0]
    cm = sp.column_index_map()
    col_l2g = np.concatenate(
        [np.arange(*cm.local_range, dtype=np.int64), np.asarray(cm.ghosts, dtype=np.int64)])
    rows = np.repeat(np.arange(n_loc, dtype=np.int64) + r0, np.diff(offsets[: n_loc + 1]))
    cols = col_l2g[np.asarray(array[: offsets[n_loc]])]
    return rows, cols


def scalar_csr(local_rows: np.ndarray, global_cols: np.ndarray, n_rows: int, bs: int,
               dtype=np.int64) -> tuple[np.ndarray, np.ndarray]:
    """The scalar CSR (indptr, indices) of a node-level pattern with block size ``bs``: node
    entry (r, c) becomes the bs x bs block of scalar rows bs r + i and columns bs c + j.

    ``local_rows`` (sorted), ``global_cols``: the node pattern's entries (rows 0..n_rows-1).
    Every scalar row of node row r repeats the same bs k_r columns (k_r: the node row's
    entries), so the indices are one gather of the expanded columns (one pass over the
    output, in ``dtype``; PETSc's integer type when it is 32-bit)."""
    counts = np.bincount(local_rows, minlength=n_rows)
    starts_n = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(dtype)
    seg = (bs * global_cols.astype(dtype)[:, None] + np.arange(bs, dtype=dtype)).ravel()
    lens = np.repeat((bs * counts).astype(dtype), bs)          # per scalar row
    indptr = np.zeros(lens.size + 1, dtype=dtype)
    np.cumsum(lens, out=indptr[1:])
    # output position q of scalar row (r, i) reads seg[bs starts_n[r] + q - indptr[bs r + i]]
    shift = np.repeat(bs * np.repeat(starts_n, bs) - indptr[:-1], lens)
    shift += np.arange(indptr[-1], dtype=dtype)
    return indptr, seg[shift]


def block_csr_matrix(V, local_rows: np.ndarray, global_cols: np.ndarray):
    """A preallocated PETSc AIJ matrix of ``V``'s layout (block size 3) whose node-level
    pattern is the (sorted, unique) entries (local_rows, global_cols), with dolfinx's
    local-to-global map so dolfinx assembles into it; new nonzeros are an error."""
    from mpi4py import MPI
    from petsc4py import PETSc
    imap = V.dofmap.index_map
    bs = V.dofmap.index_map_bs
    n_loc, n_glob = imap.size_local, imap.size_global
    indptr, indices = scalar_csr(local_rows, global_cols, n_loc, bs, PETSc.IntType)
    A = PETSc.Mat().create(comm=V.mesh.comm)
    A.setSizes(((bs * n_loc, bs * n_glob), (bs * n_loc, bs * n_glob)), bsize=bs)
    A.setType(PETSc.Mat.Type.AIJ)
    A.setPreallocationCSR((indptr, indices))
    l2g = np.concatenate(
        [np.arange(*imap.local_range, dtype=np.int64), np.asarray(imap.ghosts, dtype=np.int64)])
    lgmap = PETSc.LGMap().create(l2g.astype(PETSc.IntType), bsize=bs, comm=MPI.COMM_SELF)
    A.setLGMap(lgmap, lgmap)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    A.zeroEntries()
    return A


def near_nullspace(V, n_vectors: int, fill):
    """An orthonormalised PETSc near-nullspace of ``n_vectors`` vectors of ``V``'s layout;
    ``fill(k, local_array)`` writes vector k's local values (owned and ghost)."""
    from petsc4py import PETSc
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    if NEW_API:
        vecs = [dolfinx.la.vector(imap, bs) for _ in range(n_vectors)]
        for k, v in enumerate(vecs):
            fill(k, v.array)
        dolfinx.la.orthonormalize(vecs)
        n_own = bs * imap.size_local
        petsc = [PETSc.Vec().createWithArray(v.array[:n_own].copy(), bsize=bs,
                                             comm=V.mesh.comm) for v in vecs]
        return PETSc.NullSpace().create(vectors=petsc, comm=V.mesh.comm)
    vecs = [dolfinx.la.create_petsc_vector(imap, bs) for _ in range(n_vectors)]
    for k, v in enumerate(vecs):
        with v.localForm() as loc:
            fill(k, np.asarray(loc))
    dolfinx.la.orthonormalize(vecs)
    return PETSc.NullSpace().create(vectors=vecs, comm=V.mesh.comm)


# ------------------------------------------------------------------ meshes and tags
def mesh_domain(cell_name: str, degree: int):
    """The ufl domain of a 3D mesh of ``cell_name`` cells ("tetrahedron", "hexahedron") with
    an equispaced Lagrange geometry of ``degree``."""
    import ufl
    if NEW_API:
        import basix
        import basix.ufl
        return ufl.Mesh(basix.ufl.element("Lagrange", cell_name, int(degree), shape=(3,),
                                          lagrange_variant=basix.LagrangeVariant.equispaced))
    cell = ufl.Cell(cell_name, geometric_dimension=3)
    return ufl.Mesh(ufl.VectorElement(
        ufl.FiniteElement("Lagrange", cell, int(degree), variant="equispaced")))


def create_mesh(comm, cells: np.ndarray, x: np.ndarray, cell_name: str, degree: int,
                destinations=None):
    """A distributed mesh from input arrays (cells in DOLFINx node order, int64).

    ``destinations(n_cells, n_ranks) -> (n_cells,) int32``, if given, chooses the rank of every
    input cell of the calling rank (instead of the graph partitioner)."""
    cells = np.asarray(cells, dtype=np.int64)
    domain = mesh_domain(cell_name, degree)
    if destinations is None and NEW_API and comm.size > 1:
        # DOLFINx 0.9's graph partitioners (the default, and SCOTCH with a fixed seed) hand the
        # parts to the ranks in a different order from one process to the next (seen: 2 of 6
        # runs), which scrambles the layout of a restarted run's output: a deterministic
        # geometric partition instead (slabs of equal cell count along the longest extent)
        destinations = _slabs(cells, x)
    if destinations is None:
        return dolfinx.mesh.create_mesh(comm, cells, x, domain)
    if NEW_API:
        # 0.9 hands the partitioner the cells' vertices only (the topology), not all nodes
        n_vertices = 4 if cell_name == "tetrahedron" else 8

        def partitioner(comm_, nparts, cell_types, local_cells):
            n = int(np.asarray(local_cells[0]).size // n_vertices)
            return dolfinx.graph.adjacencylist(
                np.asarray(destinations(n, nparts), dtype=np.int32).reshape(-1, 1))
    else:
        def partitioner(comm_, nparts, tdim, local_cells, ghost_mode):
            dest = np.asarray(destinations(local_cells.num_nodes, nparts), dtype=np.int32)
            return dolfinx.cpp.graph.AdjacencyList_int32(dest.reshape(-1, 1))
    return dolfinx.mesh.create_mesh(comm, cells, x, domain, partitioner=partitioner)


def _slabs(cells: np.ndarray, x: np.ndarray):
    """destinations(n, n_ranks): the input cells of this rank (all of them on the rank that
    holds the input arrays) cut into n_ranks slabs of equal cell count along the longest extent
    of their centroids; deterministic."""
    def destinations(n_cells, n_ranks):
        if n_cells == 0:
            return np.zeros(0, dtype=np.int32)
        n_vertices = 4 if cells.shape[1] in (4, 10) else 8     # tetrahedra / hexahedra
        centroids = np.asarray(x)[cells[:n_cells, :n_vertices]].mean(axis=1)
        axis = int(np.argmax(np.ptp(centroids, axis=0)))
        order = np.lexsort((np.arange(n_cells), centroids[:, axis]))
        dest = np.empty(n_cells, dtype=np.int32)
        dest[order] = (np.arange(n_cells) * n_ranks) // n_cells
        return dest
    return destinations


def meshtags_from_arrays(msh, dim: int, entities: np.ndarray, values: np.ndarray):
    """MeshTags of dimension ``dim`` from rank-0 entity arrays (vertices in DOLFINx order,
    original input node numbers) and their values (collective)."""
    if NEW_API:
        ents, vals = dolfinx.io.distribute_entity_data(msh, dim, entities,
                                                       np.asarray(values, dtype=np.int32))
        adjacency = dolfinx.graph.adjacencylist(ents)
    else:
        ents, vals = dolfinx.cpp.io.distribute_entity_data(msh._mesh, dim, entities, values)
        adjacency = dolfinx.cpp.graph.AdjacencyList_int32(ents)
    return dolfinx.mesh.meshtags_from_entities(msh, dim, adjacency, np.asarray(vals, np.int32))


def facet_geometry_nodes(msh, facets: np.ndarray) -> np.ndarray:
    """(n, n_nodes) geometry node indices of the given local facets."""
    fdim = msh.topology.dim - 1
    if NEW_API:
        return dolfinx.mesh.entities_to_geometry(msh, fdim, np.asarray(facets, np.int32), False)
    return dolfinx.cpp.mesh.entities_to_geometry(msh._mesh, fdim, facets, False)


def write_meshtags(xdmf, tags, msh) -> None:
    """Write MeshTags to an open XDMFFile."""
    if NEW_API:
        xdmf.write_meshtags(tags, msh.geometry)
    else:
        xdmf.write_meshtags(tags)


# ------------------------------------------------------------------ Dirichlet rows, lifting
def set_bc(b, bcs: Sequence, x0=None, scale: float = 1.0) -> None:
    """Dirichlet rows of the PETSc vector b: b = scale (g - x0) (x0 None: scale g)."""
    if NEW_API:
        dolfinx.fem.petsc.set_bc(b, bcs, x0, alpha=scale)
    else:
        dolfinx.fem.petsc.set_bc(b, bcs, x0, scale=scale)


def set_bc_array(x: np.ndarray, bcs: Sequence) -> None:
    """Dirichlet values into the array x (owned and ghost entries); 0.9 deprecates
    ``fem.set_bc`` for ``DirichletBC.set``."""
    if NEW_API:
        for bc in bcs:
            bc.set(x)
    else:
        dolfinx.fem.set_bc(x, bcs)


def apply_lifting(b, a: Sequence, bcs: Sequence, scale: float = 1.0) -> None:
    """b -= scale A g for the Dirichlet values g (dolfinx's lifting), per form of ``a``."""
    if NEW_API:
        dolfinx.fem.petsc.apply_lifting(b, a, bcs=bcs, alpha=scale)
    else:
        dolfinx.fem.petsc.apply_lifting(b, a, bcs=bcs, scale=scale)
