"""Shared FE test helper: a contact interface's force, residual and Jacobian figures at one
state, and the Jacobian checked against central differences of the residual.

Also the two blocks on rollers that the nodal and semismooth tests press together, and the
central difference of a residual that the Jacobian checks use.

Imported by tests/fem/test_nodal.py, test_nonmatching.py, test_nodal_ssn.py and
test_semismooth.py (which put this folder on sys.path). Collective: every rank calls it.
"""
from __future__ import annotations

import numpy as np
import ufl
from petsc4py import PETSc

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.scenes.meshes.blocks import separate_blocks, two_blocks


def roller(V, scene, name, comp):
    """u[comp] = 0 on the facets tagged ``name``."""
    facets = scene.facet_tags.find(scene.tag(name))
    dofs = fem.locate_dofs_topological(V.sub(comp), 2, facets)
    return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))


def blocks_on_rollers(comm, pairing, order, cell_type="tetrahedron"):
    """(scene, V, bcs): two blocks, conforming (one mesh, h = 0.3) or not (``separate_blocks``,
    h = 0.2 and 0.28), on rollers x = 0, y = 0 and the bottom."""
    if pairing == "conforming":
        scene = two_blocks(h1=1.0, h2=0.5, mesh_size=0.3, order=order, comm=comm,
                           cell_type=cell_type)
    else:
        scene = separate_blocks(h1=1.0, h2=0.5, size_lower=0.2, size_upper=0.28, order=order,
                                comm=comm, cell_type=cell_type)
    V = compat.vector_space(scene.mesh, order)
    bcs = [roller(V, scene, "x0", 0), roller(V, scene, "y0", 1), roller(V, scene, "bottom", 2)]
    return scene, V, bcs


def residual_jacobian_figures(ci, u, V, fd: bool = False):
    """Evaluate the interface ``ci`` at ``u`` and return (figures, fd_err).

    figures: the contact force (3), then |residual|, |Jacobian| (Frobenius), real contact area
    and nominal area -- quantities independent of the number of ranks.
    fd_err: with ``fd``, |J d - (R(u + e d) - R(u - e d)) / 2e| / |J d| along a fixed
    pseudo-random direction d (central differences, e = 1e-5); else None.
    """
    b = compat.create_petsc_vector(V)
    b.set(0.0)
    ci.evaluate(u)
    ci.assemble_residual(b)
    mass = fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * ufl.dx)
    A = ci.create_matrix(mass)
    ci.evaluate(u)
    ci.assemble_jacobian(A)
    A.assemble()
    figs = np.concatenate([ci.contact_force(), [b.norm(), A.norm(), ci.real_contact_area(),
                                                ci.nominal_area()]])
    fd_err = None
    if fd:
        rng = np.random.default_rng(3)
        x = compat.petsc_vector(u).copy()
        d = x.duplicate()
        r0, r1 = d.getOwnershipRange()
        d.setArray(rng.uniform(-1, 1, 3 * V.dofmap.index_map.size_global)[r0:r1] * 1e-4)
        Jd = b.duplicate()
        A.mult(d, Jd)

        def residual(xs, bs):
            bs.set(0.0)
            ci.evaluate(xs)
            ci.assemble_residual(bs)

        fd_vec = central_difference(residual, x, d, 1e-5)
        fd_vec.axpy(-1.0, Jd)
        fd_err = fd_vec.norm() / Jd.norm()
    A.destroy()
    return figs, fd_err


def central_difference(residual, x, d, eps, check=None):
    """(R(x + eps d) - R(x - eps d)) / (2 eps) as a new PETSc vector; ``residual(xs, bs)``
    writes R(xs) into ``bs``. ``check()``, if given, runs after each evaluation (e.g. to assert
    that no branch of a non-smooth law changed within eps)."""
    res = []
    for sgn in (1.0, -1.0):
        xs = x.copy()
        xs.axpy(sgn * eps, d)
        bs = x.duplicate()
        residual(xs, bs)
        if check is not None:
            check()
        res.append(bs)
    res[0].axpy(-1.0, res[1])
    res[0].scale(0.5 / eps)
    return res[0]


def interpolate_two_bodies(u, scene):
    """A smooth displacement, different on each body of ``scene`` (cells tagged "lower" and
    "upper"): a non-uniform jump across the interface."""
    for name, s in (("lower", 0.0), ("upper", 1.0)):
        cells = scene.cell_tags.find(scene.tag(name))
        compat.interpolate(u, lambda x: 2e-3 * np.stack([
            np.sin(2 * x[0] + 1) * np.cos(x[1]) + 0.5 * s * np.cos(3 * x[1]),
            np.cos(x[0] - 2 * x[1]) - 0.3 * s * np.sin(x[0]),
            np.sin(x[0] + x[1] + x[2]) - 0.8 * s * (1 + x[0] * x[1])]), cells=cells)
    u.x.scatter_forward()
