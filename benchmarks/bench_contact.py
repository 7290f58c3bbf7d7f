"""Time the contact interface operator on the flat-punch scene (~10-20k interface points).

    .venv/bin/python benchmarks/bench_contact.py --contact-size 0.35 --order 2
    mpirun -n 2 .venv/bin/python -m mpi4py benchmarks/bench_contact.py --contact-size 0.35

Prints set-up, matrix-creation and per-call residual / Jacobian times of ContactInterface
(max over ranks), with the rough-surface-like smooth penalty law with friction.
"""

from __future__ import annotations
from rough_contact.fem import compat

import argparse
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


def main(argv=None):
    parser = argparse.ArgumentParser(allow_abbrev=False)
    parser.add_argument("--contact-size", type=float, default=0.35)
    parser.add_argument("--mesh-size", type=float, default=10.0)
    parser.add_argument("--order", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args(argv)

    import ufl
    from dolfinx import fem

    from rough_contact.scenes.meshes.flat_punch import flat_punch
    from rough_contact.fem.contact import ContactInterface
    from rough_contact.interface.penalty import SoftplusPenalty

    comm = MPI.COMM_WORLD
    sc = flat_punch(mesh_size=args.mesh_size, contact_size=args.contact_size, order=args.order)
    V = compat.vector_space(sc.mesh, args.order)
    law = SoftplusPenalty(1e4, 1e-3, k_tangential=5e3, friction=0.3)

    def tmax(t0):
        return comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)

    comm.Barrier()
    t0 = time.perf_counter()
    ci = ContactInterface(V, sc.facet_tags, *sc.contact_pair, law=law,
                          quadrature_degree=2 * args.order)
    t_setup = tmax(t0)
    u_, v_ = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(ufl.inner(ufl.grad(u_), ufl.grad(v_)) * ufl.dx)
    comm.Barrier()
    t0 = time.perf_counter()
    A = ci.create_matrix(a)
    t_mat = tmax(t0)
    from dolfinx.fem.petsc import create_matrix as dolfinx_create_matrix
    comm.Barrier()
    t0 = time.perf_counter()
    dolfinx_create_matrix(a)
    t_mat_dolfinx = tmax(t0)
    u = fem.Function(V)
    rng = np.random.default_rng(comm.rank)
    u.x.array[:] = rng.uniform(-1e-3, 1e-3, u.x.array.size)
    u.x.scatter_forward()
    b = compat.petsc_vector(u).duplicate()
    t_res, t_jac, t_kernel = [], [], []
    for i in range(args.repeat):
        u.x.array[:] *= 1.0 + 1e-3  # a new iterate each time (no cached evaluation)
        comm.Barrier()
        t0 = time.perf_counter()
        ci.evaluate(u)
        ci.assemble_residual(b)
        t_res.append(tmax(t0))
        u.x.array[:] *= 1.0 + 1e-3
        comm.Barrier()
        t0 = time.perf_counter()
        ci.evaluate(u)
        ci.assemble_jacobian(A)
        t_kernel.append(tmax(t0))
        A.assemble()
        t_jac.append(tmax(t0))
    PETSc.Sys.Print(
        f"ranks {comm.size}, P{args.order}, {V.dofmap.index_map.size_global * 3} DOFs, "
        f"{ci.n_points_global} interface points ({comm.allreduce(ci.n_facets)} facets, "
        f"{ci.n_qp} per facet)\n"
        f"set-up {t_setup * 1e3:.0f} ms, create_matrix {t_mat * 1e3:.0f} ms "
        f"(dolfinx's bulk-only create_matrix {t_mat_dolfinx * 1e3:.0f} ms)\n"
        f"residual {np.median(t_res) * 1e3:.1f} ms, Jacobian {np.median(t_kernel) * 1e3:.1f} ms "
        f"(+ A.assemble: {np.median(t_jac) * 1e3:.1f} ms) (medians of {args.repeat})"
    )


if __name__ == "__main__":
    main()
