"""The one place where the DOLFINx API version shows.

Everything in the package that needs a function space, the PETSc vector of a function, a
mesh/tag from arrays, dofmap arrays or file output on a DOLFINx API that changed between
releases calls the functions here. Supported: DOLFINx 0.5.2 (Debian 12) — and, once ported,
0.9 (Debian 13). Nothing outside ``rough_contact.fem`` (and the mesh builders / output
modules) imports dolfinx; the solver and the scenes ask the problem or these functions.

Units: none (pure plumbing).
"""

from __future__ import annotations

import numpy as np

import dolfinx
import dolfinx.fem

__all__ = ["DOLFINX_VERSION", "vector_space", "petsc_vector", "function_values", "element_degree",
           "geometry_degree", "geometry_dofmap", "cell_dofmap", "create_petsc_vector",
           "form_sparsity", "block_csr_matrix"]

DOLFINX_VERSION: tuple = tuple(int(p) for p in dolfinx.__version__.split(".")[:2])


def vector_space(mesh, degree: int, family: str = "Lagrange"):
    """The vector (3-component) space of ``family`` and ``degree`` on ``mesh``."""
    return dolfinx.fem.VectorFunctionSpace(mesh, (family, int(degree)))


def petsc_vector(u):
    """The PETSc vector holding the owned (and ghost) values of the Function ``u``."""
    return u.vector


def function_values(u) -> np.ndarray:
    """The local values (owned and ghost) of the Function ``u``, a flat array view."""
    return u.x.array


def element_degree(V) -> int:
    """Polynomial degree of the space ``V``."""
    return int(V.ufl_element().degree())


def geometry_degree(mesh) -> int:
    """Degree of the mesh's coordinate map."""
    return int(mesh.geometry.cmap.degree)


def geometry_dofmap(mesh) -> np.ndarray:
    """(n_cells, n_geometry_nodes) geometry node indices of every local cell."""
    dm = mesh.geometry.dofmap
    return dm.array.reshape(dm.num_nodes, -1)


def cell_dofmap(V) -> np.ndarray:
    """(n_cells, n_dofs_per_cell) block (node) indices of every local cell of ``V``."""
    dm = V.dofmap.list
    return dm.array.reshape(dm.num_nodes, -1)


def create_petsc_vector(V):
    """A new (ghosted) PETSc vector of ``V``'s layout, block size of ``V``."""
    import dolfinx.cpp
    return dolfinx.cpp.la.petsc.create_vector(V.dofmap.index_map, V.dofmap.index_map_bs)


def form_sparsity(a, V) -> tuple[np.ndarray, np.ndarray]:
    """The node-level (block) sparsity pattern of the bilinear form ``a`` on ``V`` x ``V`` on
    this rank's owned rows, in global indices: (rows, cols) int64 arrays."""
    sp = dolfinx.fem.create_sparsity_pattern(a)
    sp.assemble()
    imap = V.dofmap.index_map
    n_loc, r0 = imap.size_local, imap.local_range[0]
    graph = sp.graph
    cm = sp.column_index_map()
    col_l2g = np.concatenate(
        [np.arange(*cm.local_range, dtype=np.int64), cm.ghosts.astype(np.int64)])
    off = graph.offsets
    rows = np.repeat(np.arange(n_loc, dtype=np.int64) + r0, np.diff(off[: n_loc + 1]))
    cols = col_l2g[graph.array[: off[n_loc]]]
    return rows, cols


def block_csr_matrix(V, local_rows: np.ndarray, global_cols: np.ndarray):
    """A preallocated PETSc AIJ matrix of ``V``'s layout (block size 3) whose node-level
    pattern is the (sorted, unique) entries (local_rows, global_cols), with dolfinx's
    local-to-global map so dolfinx assembles into it; new nonzeros are an error."""
    from mpi4py import MPI
    from petsc4py import PETSc
    imap = V.dofmap.index_map
    bs = V.dofmap.index_map_bs
    n_loc, n_glob = imap.size_local, imap.size_global
    indptr_n = np.concatenate([[0], np.cumsum(np.bincount(local_rows, minlength=n_loc))])
    # expand the node pattern to scalar rows: row bs*r+i has cols bs*c+j, c in row r
    seg = (bs * global_cols[:, None] + np.arange(bs)).ravel()
    L = bs * np.diff(indptr_n)
    lens = np.repeat(L, bs)
    indptr = np.concatenate([[0], np.cumsum(lens)])
    within = np.arange(indptr[-1]) - np.repeat(indptr[:-1], lens)
    start = np.repeat(np.repeat(bs * indptr_n[:-1], bs), lens)
    indices = seg[start + within]
    A = PETSc.Mat().create(comm=V.mesh.comm)
    A.setSizes(((bs * n_loc, bs * n_glob), (bs * n_loc, bs * n_glob)), bsize=bs)
    A.setType(PETSc.Mat.Type.AIJ)
    A.setPreallocationCSR((indptr.astype(PETSc.IntType), indices.astype(PETSc.IntType)))
    l2g = np.concatenate(
        [np.arange(*imap.local_range, dtype=np.int64), imap.ghosts.astype(np.int64)])
    lgmap = PETSc.LGMap().create(l2g.astype(PETSc.IntType), bsize=bs, comm=MPI.COMM_SELF)
    A.setLGMap(lgmap, lgmap)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    A.zeroEntries()
    return A
