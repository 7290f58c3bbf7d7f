"""Dirichlet conditions and surface quantities on tagged facets, for the scenes.

The scenes describe their supports by facet tag and component ("u_x = 0 on symmetry_x",
"clamp the bottom") and never call DOLFINx themselves: these functions build the DOLFINx
objects. Each is a thin wrapper over the 0.5.2 calls that have the same form in later
releases (``locate_dofs_topological``, ``dirichletbc``, ``V.sub``); version-dependent calls go
through :mod:`rough_contact.fem.compat`.

Units: those of the mesh and the values given (mm in the scenes).
"""

from __future__ import annotations

import typing

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import ufl
from dolfinx import fem

__all__ = ["fix", "fix_where", "surface_nodes", "SurfaceMean"]


def _facet_dim(V) -> int:
    return V.mesh.topology.dim - 1


def fix(V, facet_tags, tag: int, component: typing.Optional[int] = None):
    """u = 0 on the facets tagged ``tag``: all components (``component=None``, a clamp) or the
    one ``component`` (0, 1, 2: a symmetry plane or a roller). Returns the DirichletBC."""
    facets = facet_tags.find(tag)
    if component is None:
        dofs = fem.locate_dofs_topological(V, _facet_dim(V), facets)
        return fem.dirichletbc(np.zeros(V.dofmap.index_map_bs, dtype=PETSc.ScalarType), dofs, V)
    sub = V.sub(component)
    dofs = fem.locate_dofs_topological(sub, _facet_dim(V), facets)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, sub)


def fix_where(V, component: int, where: typing.Callable) -> tuple:
    """u_component = 0 at the nodes whose coordinates satisfy ``where(x)`` (x: (3, n) array,
    returns (n,) bool). Returns (DirichletBC, global number of such nodes). Collective."""
    sub = V.sub(component)
    collapsed, _ = sub.collapse()
    dofs = fem.locate_dofs_geometrical((sub, collapsed), where)
    n = V.mesh.comm.allreduce(len(dofs[0]), op=MPI.SUM)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs[0], sub), n


def surface_nodes(V, facet_tags, tag: int) -> tuple:
    """This rank's OWNED nodes on the facets tagged ``tag``: (block indices (n,), coordinates
    (n, 3)). The values of a vector Function ``u`` at them are
    ``u.x.array.reshape(-1, bs)[blocks]``."""
    blocks = fem.locate_dofs_topological(V, _facet_dim(V), facet_tags.find(tag))
    blocks = blocks[blocks < V.dofmap.index_map.size_local]
    return blocks, V.tabulate_dof_coordinates()[blocks]


class SurfaceMean:
    """Mean of one displacement component over the facets tagged ``tag``:
    (integral of u_component dA) / (area), both summed over the ranks. Collective calls."""

    def __init__(self, u, facet_tags, tag: int, component: int):
        mesh = u.function_space.mesh
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)(tag)
        self._comm = mesh.comm
        self._form = fem.form(u[component] * ds)
        self.area = self._comm.allreduce(fem.assemble_scalar(fem.form(
            fem.Constant(mesh, PETSc.ScalarType(1.0)) * ds)), op=MPI.SUM)

    def integral(self) -> float:
        """Integral of the component over the surface (all ranks)."""
        return self._comm.allreduce(float(fem.assemble_scalar(self._form)), op=MPI.SUM)

    def __call__(self) -> float:
        return self.integral() / self.area
