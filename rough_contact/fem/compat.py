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

__all__ = ["DOLFINX_VERSION", "vector_space", "petsc_vector", "element_degree",
           "geometry_degree", "geometry_dofmap", "cell_dofmap"]

DOLFINX_VERSION: tuple = tuple(int(p) for p in dolfinx.__version__.split(".")[:2])


def vector_space(mesh, degree: int, family: str = "Lagrange"):
    """The vector (3-component) space of ``family`` and ``degree`` on ``mesh``."""
    return dolfinx.fem.VectorFunctionSpace(mesh, (family, int(degree)))


def petsc_vector(u):
    """The PETSc vector holding the owned (and ghost) values of the Function ``u``."""
    return u.vector


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
