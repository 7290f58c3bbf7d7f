"""How smooth the nodal tractions of the exact routes are on a curved contact: the Mindlin
scene's rigid paraboloid on the large block (P2, nu = 0.49, mu = 0.3) at full normal load,
each contact node within 0.8 a compared with Hertz's pressure at its radius.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_nodal_traction_noise.py \
        [--basis dual dual_quadratic] [--contact-size 0.05] [--preload-steps 2]

``dual``: vertex points with the first-order dual weights, multipliers updated inside Newton
(``NewtonAugmentedLagrangian``); ``dual_quadratic``: every P2 node, the quadratic dual basis,
the semismooth Newton (``SemismoothNewton``). Prints per route: nodes within 0.8 a, the rms
and largest |p / p_Hertz - 1|, the rms and largest |t| / p0, the slipping nodes in contact,
P against Hertz's force at the same approach, CPU seconds. Reading: docs/exact_contact_newton.md,
section 4.
"""

from __future__ import annotations

import argparse
import sys
import time

import petsc4py

petsc4py.init(sys.argv[:1])

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact import references  # noqa: E402
from rough_contact.interface.enforcement import (NewtonAugmentedLagrangian,  # noqa: E402
                                                 SemismoothNewton)
from rough_contact.scenes import mindlin  # noqa: E402

E, R, DELTA = 2.0e5, 10.0, 4e-3


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--basis", nargs="+", default=["dual", "dual_quadratic"],
                    choices=["dual", "dual_quadratic"])
    ap.add_argument("--contact-size", type=float, default=0.05, help="a/4 = 0.05 mm")
    ap.add_argument("--preload-steps", type=int, default=2)
    args = ap.parse_args(argv)
    nu, mu = 0.49, 0.3
    E_star = E / (1.0 - nu**2)
    rows = []
    for basis in args.basis:
        enf = SemismoothNewton() if basis == "dual_quadratic" else \
            NewtonAugmentedLagrangian(1e-4, 60, residual_ratio=1e-2)
        c0 = time.process_time()
        r = mindlin.run(contact_size=args.contact_size, order=2, nu=nu, mu=mu,
                        preload_steps=args.preload_steps, shear_steps=0, enforcement=enf,
                        points="nodal", basis=basis, half_width=64, height=64, mesh_size=16,
                        transition=48,
                        refined_radius=0.26 if args.contact_size < 0.05 else 0.4)
        cpu = time.process_time() - c0
        pts = r.points                                  # gathered on every rank
        a = references.hertz_radius(r.P[-1], R, E_star)
        p0 = references.hertz_peak_pressure(r.P[-1], a)
        rr = np.hypot(pts.x[:, 0], pts.x[:, 1]) / a
        c = pts.contact[-1]
        inner = c & (rr < 0.8)
        p, t = pts.pressure[-1][inner], pts.shear[-1][inner]
        dev = p / (p0 * np.sqrt(1.0 - rr[inner] ** 2)) - 1.0
        tn = np.linalg.norm(t, axis=1) / p0
        hertz = references.hertz_force(DELTA, R, E_star)
        rows.append((basis, int(inner.sum()), np.sqrt(np.mean(dev**2)), np.abs(dev).max(),
                     np.sqrt(np.mean(tn**2)), tn.max(), int(pts.slipping[-1][c].sum()),
                     r.P[-1] / hertz - 1.0, cpu))
    PETSc.Sys.Print(f"contact size {args.contact_size} mm, {args.preload_steps} normal "
                    f"increments; nodes within 0.8 a at full load")
    PETSc.Sys.Print(f"{'basis':>15} {'nodes':>6} {'p rms':>7} {'p max':>7} {'|t| rms':>8} "
                    f"{'|t| max':>8} {'slip':>5} {'P/Hertz-1':>9} {'CPU s':>7}")
    for b, n, pr, pm, tr, tm, sl, ph, cpu in rows:
        PETSc.Sys.Print(f"{b:>15} {n:6d} {pr:7.4f} {pm:7.4f} {tr:8.4f} {tm:8.4f} {sl:5d} "
                        f"{ph:+9.4f} {cpu:7.0f}")
    if MPI.COMM_WORLD.rank == 0:
        sys.stdout.flush()


if __name__ == "__main__":
    main()
