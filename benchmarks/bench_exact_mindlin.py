"""Cattaneo–Mindlin with exact stick (rough_contact.scenes.mindlin, P2): one monotonic run, a
table row per increment: P against Hertz at the same approach, Q/muP, the FE stick ratio
against (1 - Q/muP)^(1/3), the dissipation, Newton iterations.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_exact_mindlin.py \\
        [--points nodal|quadrature] [--basis standard|dual] [--plain]
        [--enforcement uzawa|newton] [--residual-ratio 1e-2] [--contact-size 0.05]
        [--preload-steps 2] [--shear-steps 6] [--k-tangential 1e9] [--al-tol 1e-4] [--nu 0.49]
        [--half-width 4] [--height 4] [--mesh-size 1] [--transition 1]
        [--refined-radius 0.4]

``--shear-steps 0`` runs the normal load alone. ``--enforcement newton`` updates the
multipliers inside the Newton iteration (``NewtonAugmentedLagrangian``, nodal points only);
``uzawa`` (default) is ``AugmentedLagrangian``, one Newton solve per update.

Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import time

from petsc4py import PETSc

from rough_contact import references
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.scenes import mindlin

E, R, DELTA = 2.0e5, 10.0, 4e-3


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", default="nodal", choices=["nodal", "quadrature"])
    ap.add_argument("--plain", action="store_true", help="plain penalty (no augmentation)")
    ap.add_argument("--basis", default="standard", choices=["standard", "dual"])
    ap.add_argument("--enforcement", default="uzawa", choices=["uzawa", "newton"])
    ap.add_argument("--residual-ratio", type=float, default=1e-2,
                    help="NewtonAugmentedLagrangian.residual_ratio (--enforcement newton)")
    ap.add_argument("--contact-size", type=float, default=0.05)
    ap.add_argument("--preload-steps", type=int, default=2)
    ap.add_argument("--shear-steps", type=int, default=6)
    ap.add_argument("--k-tangential", type=float, default=1e9,
                    help="tangential penalty [MPa/mm]; with exact stick it sets only how fast "
                    "the multipliers converge")
    ap.add_argument("--al-tol", type=float, default=1e-4)
    ap.add_argument("--nu", type=float, default=0.49)
    ap.add_argument("--half-width", type=float, default=4.0,
                    help="block half width L [mm] (the half model is [-L, L] x [0, L] x [-H, 0])")
    ap.add_argument("--height", type=float, default=4.0, help="block height H [mm]")
    ap.add_argument("--mesh-size", type=float, default=1.0,
                    help="element size away from the contact [mm]")
    ap.add_argument("--refined-radius", type=float, default=0.4,
                    help="radius about the origin meshed at --contact-size [mm]")
    ap.add_argument("--transition", type=float, default=1.0,
                    help="distance over which the element size grows to --mesh-size [mm]")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    newton = args.enforcement == "newton" and not args.plain
    enforcement = NewtonAugmentedLagrangian(args.al_tol, 60, residual_ratio=args.residual_ratio) \
        if newton else None
    t0, c0 = time.perf_counter(), time.process_time()
    r = mindlin.run(contact_size=args.contact_size, order=2, nu=args.nu,
                    preload_steps=args.preload_steps, shear_steps=args.shear_steps,
                    augmented=not (args.plain or newton), enforcement=enforcement,
                    points=args.points, basis=args.basis,
                    augmentation_tolerance=args.al_tol, max_updates=60,
                    k_tangential=args.k_tangential, half_width=args.half_width,
                    height=args.height, mesh_size=args.mesh_size,
                    transition=args.transition, refined_radius=args.refined_radius,
                    verbose=args.verbose)
    E_star = E / (1.0 - args.nu**2)
    q = r.Q / (r.mu * r.P)
    PETSc.Sys.Print(f"{'t':>6} {'P [N]':>8} {'P/Hertz-1':>9} {'Q/muP':>7} {'c/a FE':>7} "
                    f"{'c/a MD':>7} {'error':>7} {'D [N mm]':>10} {'Newton':>6}")
    for i in range(r.t.size):
        delta = DELTA * min(r.t[i], 1.0)
        hertz = references.hertz_force(delta, R, E_star)
        ref = float(references.stick_ratio(min(abs(r.Q[i]), r.mu * r.P[i]), r.mu, r.P[i]))
        PETSc.Sys.Print(f"{r.t[i]:6.3f} {r.P[i]:8.3f} {r.P[i] / hertz - 1:+9.4f} {q[i]:7.4f} "
                        f"{r.stick[i]:7.4f} {ref:7.4f} {r.stick[i] / ref - 1:+7.4f} "
                        f"{r.dissipation[i]:10.3e} {int(r.newton[i]):6d}")
    PETSc.Sys.Print(f"DOFs {r.dofs}, wall {time.perf_counter() - t0:.0f} s, "
                    f"CPU (rank 0) {time.process_time() - c0:.0f} s")
    return r


if __name__ == "__main__":
    main()
