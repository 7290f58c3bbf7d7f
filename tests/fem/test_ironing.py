"""Rigid indenters that move (``rigid_motion``) with gap and normal from the current
configuration (``sliding="large"``): a rigid sphere and a rigid cylinder pressed into an
elastic slab and ironed 5 contact radii along it, with Coulomb friction. Serial and
``mpirun -n 2``; on 2 ranks every figure is compared with the same run on one rank.

References (not from this code's interface):
- the energy balance: the work of the force the indenter exerts on the slab along the
  indenter's path (trapezoidal rule over the increments) equals the slab's elastic energy
  (1/2 int sigma : eps, assembled by DOLFINx) plus the interface's stored energy (normal
  penalty: the closed form k w^2 (-Li2(-exp(-g/w))) of int_g^inf p, checked against numerical
  quadrature here; tangential: |t_T|^2 / (2 k_T)) plus the frictional dissipation;
- the geometry of the rigid surfaces: at the converged state every point's gap is its signed
  distance to the moved sphere/cylinder, computed here from the deformed coordinates.
"""

from __future__ import annotations

import numpy as np
import pytest
import ufl
from mpi4py import MPI
from scipy.integrate import quad
from scipy.special import spence

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.boundary import fix
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material
from rough_contact.fem.rigid import RigidCylinder, RigidSphere
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes.meshes.blocks import block_on_plane
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

E, NU, MU = 1.0e3, 0.3, 0.3
K_N, WIDTH, K_T = 1e6, 1e-5, 1e6
R, X0 = 2.0, 0.3                 # indenter radius, start position [mm]
H, TOL = 0.0625, 1e-7            # element size [mm], sliding tolerance [-]
_SCENES = {}


def _scene(comm, order=1, cell_type="hexahedron", h=H):
    key = (comm.size, order, cell_type, h)
    if key not in _SCENES:
        _SCENES[key] = block_on_plane(lx=1.75, ly=0.25, h=0.25, mesh_size=h, order=order,
                                      cell_type=cell_type, comm=comm)
    return _SCENES[key]


def _ramp(t):
    return min(max(t, 0.0), 1.0)


def _psi_normal(g):
    """int_g^inf p(g') dg' of the softplus penalty [N/mm]."""
    return -K_N * WIDTH**2 * spence(1.0 + np.exp(-g / WIDTH))


def test_normal_energy_closed_form():
    law = SoftplusPenalty(K_N, WIDTH)
    for g in (-2e-4, -1e-5, 0.0, 3e-5):
        ref = quad(lambda x: law.normal(np.array([x]))[0][0], g, 60 * WIDTH, epsabs=0,
                   epsrel=1e-12)[0]
        assert _psi_normal(g) == pytest.approx(ref, rel=1e-9)


def _iron(comm, shape, depth, n_iron=10, order=1, cell_type="hexahedron", h=H):
    scene = _scene(comm, order, cell_type, h)
    V = compat.vector_space(scene.mesh, order)
    bcs = [fix(V, scene.facet_tags, scene.tag("top")),
           fix(V, scene.facet_tags, scene.tag("y0"), 1)]
    # the indenter below the slab (contact face z = 0), touching it at (X0, 0, 0)
    rigid = (RigidSphere((X0, 0.0, -R), R) if shape == "sphere"
             else RigidCylinder((X0, 0.0, -R), (0.0, 1.0, 0.0), R))
    a = np.sqrt(R * depth)           # contact radius (sphere; the cylinder's is close) [mm]
    travel = 5 * a

    def motion(t):                   # pressed in (t <= 1), then ironed along x
        return (travel * _ramp(t - 1.0), 0.0, depth * _ramp(t))

    law = SoftplusPenalty(K_N, WIDTH, k_tangential=K_T, friction=MU)
    ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law, rigid=rigid,
                          rigid_motion=motion, sliding="large", bcs=bcs,
                          sliding_tolerance=TOL)
    problem = ContactProblem(V, Material(E, NU), bcs, [], facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix=f"test_ironing_{comm.size}_")
    # the first ironing increments short: the friction force rises from 0 to mu N over a
    # few micrometres, which the trapezoidal work must resolve
    times = [0.5, 1.0, 1.0005, 1.002, 1.01, 1.04] + [1.0 + (j + 1) / n_iron
                                                     for j in range(n_iron)]
    u, v = problem.u, ufl.TestFunction(V)
    mu_l, lmbda = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))
    eps = ufl.sym(ufl.grad(u))
    energy_form = fem.form(0.5 * ufl.inner(2 * mu_l * eps + lmbda * ufl.tr(eps)
                                           * ufl.Identity(3), eps) * ufl.dx)
    F, d, stored, dissipated, gap_err, its = [np.zeros(3)], [np.zeros(3)], [], [], [], []
    for inc in load_path(problem, solver, times, verbose=False, friction_check=False):
        F.append(np.array(inc.contact_force))
        d.append(ci.translation)
        its.append(inc.iterations)
        res, jump = ci._result(), ci._last_jump
        w = ci.paired.weights
        e_int = np.sum(w * (_psi_normal(jump[:, 0])
                            + 0.5 * np.sum(res.traction[:, 1:] ** 2, axis=1) / K_T))
        e_bulk = fem.assemble_scalar(energy_form)
        stored.append(comm.allreduce(float(e_int + e_bulk), op=MPI.SUM))
        dissipated.append(ci.dissipation())
        # the converged gap is the distance to the moved indenter in the current configuration
        uu = compat.function_values(problem.u).reshape(-1, 3)
        x = ci.paired.x + np.einsum("fqk,fki->fqi", ci.paired.N1,
                                    uu[ci.pairing._ctx.geo1.local_nodes]).reshape(-1, 3)
        g, _ = rigid.gap_and_normal(x - ci.translation)
        gap_err.append(comm.allreduce(float(np.abs(g - jump[:, 0]).max(initial=0.0)),
                                      op=MPI.MAX))
    F, d = np.array(F), np.array(d)
    work = np.cumsum(0.5 * np.einsum("ni,ni->n", F[1:] + F[:-1], np.diff(d, axis=0)))
    out = dict(F=F[1:], work=work, stored=np.array(stored), dissipated=np.array(dissipated),
               gap_err=np.array(gap_err), its=its, a=a, n_fixed=ci.n_fixed_point,
               repairs=ci.n_repairs)
    solver.destroy()
    return out


# P1 hexahedra. On Q2 hexahedra and on tetrahedra of a size that keeps the test fast the force
# ripple of the patch crossing the elements reaches 1 % (docs/sliding_p2.md, with figures): the
# tetrahedra pass on one gmsh version's mesh and fail on the other's, so they are not here
CASES = [("sphere", 1, "hexahedron", H), ("cylinder", 1, "hexahedron", H)]


@pytest.mark.parametrize("shape, order, cell_type, h", CASES)
def test_ironing_rigid_indenter(shape, order, cell_type, h):
    depth = 0.02
    r = _iron(MPI.COMM_WORLD, shape, depth, order=order, cell_type=cell_type, h=h)
    F = r["F"]
    ironing = F[6:]
    # in contact and dragged: the slab pushed up, the friction force against the motion
    assert np.all(F[:, 2] > 0.0) and np.all(ironing[:, 0] > 0.0)
    # no jumps: from one increment (half a contact radius) to the next the forces change by
    # less than 1 % once the ironing is steady (after the first 2 radii)
    steady = ironing[3:]
    for k in (0, 2):
        assert np.abs(np.diff(steady[:, k])).max() <= 0.01 * np.abs(steady[:, k]).mean()
    # the gap is the current distance to the moved indenter (to the sliding tolerance)
    assert r["gap_err"].max() <= TOL * h
    # energy balance: work in = stored + dissipated, within 1 % of the work
    balance = r["work"] - r["stored"] - r["dissipated"]
    assert np.abs(balance).max() <= 0.01 * r["work"][-1]
    assert r["dissipated"][-1] > 0.2 * r["work"][-1]     # a real ironing: mostly friction
    if MPI.COMM_WORLD.size > 1:
        serial = _iron(MPI.COMM_SELF, shape, depth, order=order, cell_type=cell_type, h=h)
        np.testing.assert_allclose(F, serial["F"], rtol=0, atol=1e-10 * np.abs(F).max())
