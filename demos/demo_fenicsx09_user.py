# # A FEniCSx 0.9 script with a rough interface
#
# A DOLFINx 0.9 user's own script — their mesh, `functionspace(mesh, ("Lagrange", 2, (3,)))`,
# their own UFL forms and boundary conditions — that adds a rough contact interface with
# rough_contact and solves it twice:
#
# 1. with the add-on's SNES driver and load stepping (`SNESSolver`, `load_path`);
# 2. with the user's own Newton loop (a plain PETSc KSP), calling the interface's lifecycle
#    (`begin_increment`, the residual/Jacobian callbacks, `accept`, `commit`).
#
# Both must give the same displacement and contact force (to the Newton tolerance); the force
# the rough interface carries must balance the applied load. On DOLFINx 0.9 the displacement is
# also written with ADIOS2 (`VTXWriter`, a `.bp` folder ParaView opens). Units: mm, N, MPa.
#
#     mpirun -n 2 .venv/bin/python demos/demo_fenicsx09_user.py [--out results/fenicsx09]
#
# The 0.9 spellings are used directly (this is a user's script): on DOLFINx 0.5.2 it stops with
# a message (the library itself runs on both, through rough_contact.fem.compat).

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import petsc4py

petsc4py.init(sys.argv[:1])

import dolfinx  # noqa: E402

if tuple(int(p) for p in dolfinx.__version__.split(".")[:2]) < (0, 8):
    print(f"demo_fenicsx09_user.py is written for DOLFINx 0.9 (found {dolfinx.__version__}); "
          "run it on Debian 13: bash run.sh debian13 python demos/demo_fenicsx09_user.py")
    sys.exit(0)

import numpy as np  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem, mesh  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.fem.contact import ContactInterface  # noqa: E402
from rough_contact.fem.problem import ContactProblem  # noqa: E402
from rough_contact.interface.friction import OrthotropicSlipHardening  # noqa: E402
from rough_contact.interface.law import InterfaceLaw  # noqa: E402
from rough_contact.interface.normal import NormalLaw  # noqa: E402
from rough_contact.interface.tangential import TangentialStiffness  # noqa: E402
from rough_contact.solver.loading import load_path  # noqa: E402
from rough_contact.solver.snes import SNESSolver  # noqa: E402
from rough_contact.surface import SpectralMoments  # noqa: E402

E, NU, PRESSURE = 2.0e5, 0.3, 5.0          # MPa
CONTACT, TOP = 1, 2                          # facet tags
FACTORS = [0.25, 0.5, 1.0]


def user_model(comm, n: int):
    """What a FEniCSx 0.9 user has: a mesh, a P2 vector space, forms, boundary conditions."""
    domain = mesh.create_box(comm, [[0.0, 0.0, 0.0], [1.0, 1.0, 0.5]], [n, n, max(n // 2, 1)],
                             mesh.CellType.hexahedron)
    fdim = domain.topology.dim - 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[2], 0.0))
    top = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[2], 0.5))
    facets = np.concatenate([bottom, top])
    values = np.concatenate([np.full_like(bottom, CONTACT), np.full_like(top, TOP)])
    order = np.argsort(facets)
    tags = mesh.meshtags(domain, fdim, facets[order], values[order].astype(np.int32))
    V = fem.functionspace(domain, ("Lagrange", 2, (3,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    mu, lmbda = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))

    def sigma(w):
        eps = ufl.sym(ufl.grad(w))
        return 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(3)

    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    a = ufl.inner(sigma(u), ufl.grad(v)) * ufl.dx
    L = ufl.inner(fem.Constant(domain, np.array([0.0, 0.0, -PRESSURE])), v) * ds(TOP)
    # symmetry planes x = 0 and y = 0 (a quarter of a larger block): no rigid sliding
    bcs = []
    for comp in (0, 1):
        side = mesh.locate_entities_boundary(domain, fdim, lambda x, c=comp: np.isclose(x[c], 0.0))
        dofs = fem.locate_dofs_topological(V.sub(comp), fdim, side)
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp)))
    return V, tags, (a, L), bcs


def rough_law():
    """The paper's ground surface (moments in um) against steel, with slip-hardening friction."""
    surface = SpectralMoments(m00=0.625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)
    normal = NormalLaw.elastic(surface, E_star=E / (2 * (1 - NU ** 2)), rtol=1e-4)
    friction = OrthotropicSlipHardening(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5),
                                        hardening=(275.0, 275.0), potential_axes=(0.125, 0.125))
    return InterfaceLaw(normal, TangentialStiffness((0.7, 0.7)), friction).with_seating(
        p_seat=0.1 * PRESSURE)


def build(comm, n):
    V, tags, forms, bcs = user_model(comm, n)
    interface = ContactInterface(V, tags, CONTACT, law=rough_law(),
                                 rigid_plane=((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), bcs=bcs)
    problem = ContactProblem(V, None, bcs, forms=forms, facet_tags=tags, interface=interface,
                             seating_tag=CONTACT, seating_stiffness=1e3)
    return problem, interface


def solve_with_the_addon(comm, n):
    problem, interface = build(comm, n)
    solver = SNESSolver(problem, prefix="u09_")
    for inc in load_path(problem, solver, FACTORS, verbose=False):
        pass
    solver.destroy()
    return problem, interface


def solve_with_own_newton(comm, n, rtol=1e-10, max_it=30):
    """The user's Newton loop: residual and Jacobian from the problem's callbacks, a direct
    solve, and the interface's lifecycle around each increment."""
    problem, interface = build(comm, n)
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    for lam in FACTORS:
        problem.begin_increment()
        problem.set_load_factor(lam)
        x = problem.solution_vector().copy()
        dx = x.duplicate()
        norm0 = None
        for it in range(max_it):
            problem.F(None, x, problem.b)         # evaluates the interface at x
            norm = problem.b.norm()
            norm0 = norm if norm0 is None else norm0
            if norm <= rtol * norm0:
                break
            problem.J(None, x, problem.A, problem.A)
            ksp.setOperators(problem.A)
            ksp.solve(problem.b, dx)
            x.axpy(-1.0, dx)
        else:
            raise RuntimeError(f"load factor {lam}: Newton did not converge in {max_it} its")
        problem.update_solution(x)
        if not interface.accept(problem.u).done:   # penalty enforcement: always done
            raise RuntimeError("the interface asked for another solve")
        interface.commit()
        PETSc.Sys.Print(f"  own Newton: load {lam:.2f}, {it} iterations, |F| {norm:.3e} N")
    ksp.destroy()
    return problem, interface


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--n", type=int, default=4, help="elements per side of the block")
    ap.add_argument("--out", default="results/fenicsx09", help="output folder (VTX .bp)")
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    addon, ci_a = solve_with_the_addon(comm, args.n)
    own, ci_o = solve_with_own_newton(comm, args.n)
    f_a, f_o = ci_a.contact_force(), ci_o.contact_force()
    applied = -PRESSURE * 1.0 * 1.0
    norms = [p.solution_vector().norm() for p in (addon, own)]
    PETSc.Sys.Print(f"contact force (add-on's SNES) {f_a} N, (own Newton) {f_o} N, applied "
                    f"{applied} N; |u| {norms[0]:.10e} / {norms[1]:.10e} mm; real contact area "
                    f"{ci_a.real_contact_area():.4e} mm^2 of {ci_a.nominal_area():.4g}")
    balance = abs(f_a[2] + applied) / abs(applied)
    same = abs(norms[0] - norms[1]) / norms[0]
    assert balance < 1e-8, f"force balance {balance:.3e}"
    assert same < 1e-7, f"the two solves differ by {same:.3e}"
    out = Path(args.out)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.Barrier()
    from dolfinx.io import VTXWriter
    with VTXWriter(comm, str(out / "displacement.bp"), [addon.u], engine="BP4") as vtx:
        vtx.write(1.0)
    PETSc.Sys.Print(f"force balance {balance:.2e}, add-on vs own Newton {same:.2e}; "
                    f"displacement written to {out / 'displacement.bp'} (ADIOS2/VTX)")


if __name__ == "__main__":
    main()
