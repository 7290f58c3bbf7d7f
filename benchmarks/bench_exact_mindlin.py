"""Cattaneo–Mindlin with exact stick (rough_contact.scenes.mindlin, P2): one monotonic run, a
table row per increment: P against Hertz at the same approach, Q/muP, the FE stick ratio
against (1 - Q/muP)^(1/3), the dissipation, Newton iterations.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_exact_mindlin.py \\
        [--points nodal|quadrature] [--basis standard|dual] [--plain]
        [--enforcement uzawa|newton] [--residual-ratio 1e-2] [--contact-size 0.05]
        [--preload-steps 2] [--shear-steps 6] [--k-tangential 1e9] [--al-tol 1e-4] [--nu 0.49]
        [--half-width 4] [--height 4] [--mesh-size 1] [--transition 1]
        [--refined-radius 0.4] [--front-band 0.5] [--save run.npz]

Two stick ratios per increment: "c/a area", the scene's area estimate sqrt(1 - A_slip /
A_contact), and "c/a front", the fronts of the margin and of the pressure fitted next to them
(``rough_contact.stick_front``, finer than the vertex rings). After the table, the estimator is
checked on Cattaneo–Mindlin's closed-form tractions sampled at this mesh's gathered point radii
(c/a = 0.3 ... 1): its error there is that of the estimator alone. ``--save`` writes the
gathered points (``MindlinRun.points``) and the per-increment figures to an ``.npz``.

``--shear-steps 0`` runs the normal load alone. ``--enforcement newton`` updates the
multipliers inside the Newton iteration (``NewtonAugmentedLagrangian``, nodal points only);
``uzawa`` (default) is ``AugmentedLagrangian``, one Newton solve per update.

Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from _common import edge_bands
from rough_contact import references
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian, SemismoothNewton
from rough_contact.scenes import mindlin
from rough_contact.stick_front import mindlin_tractions, stick_front

E, R, DELTA = 2.0e5, 10.0, 4e-3


def _fronts(r, E_star, bands):
    """Per increment: the stick front at other bands (c / a_FE), c / a_Hertz(P), and the
    slipping points in contact: count, smallest r / a_Hertz, largest p / p0 among them."""
    pts = r.points
    rad = pts.r
    PETSc.Sys.Print("\nfronts: c/a_FE at the bands " + ", ".join(f"{b:g}" for b in bands)
                    + "; c/a_Hertz; slipping points in contact: n, min r/a_H, max p/p0")
    for i in range(r.t.size):
        a_h = references.hertz_radius(r.P[i], R, E_star)
        p0 = references.hertz_peak_pressure(r.P[i], a_h)
        on, sl = pts.contact[i], pts.slipping[i]
        t = np.linalg.norm(pts.shear[i], axis=1)
        cs = [stick_front(rad, pts.pressure[i], t, r.mu, pts.weight, on & ~sl, sl, band=b).radius
              / r.contact_radius[i] for b in bands]
        s = f"{r.t[i]:6.3f} " + " ".join(f"{c:7.4f}" for c in cs)
        s += f" {r.stick_radius[i] / a_h:7.4f} {int(sl.sum()):4d}"
        if sl.any():
            s += f" {rad[sl].min() / a_h:7.4f} {pts.pressure[i][sl].max() / p0:7.4f}"
        PETSc.Sys.Print(s)


def _edge_profile(r, E_star, i):
    """The margin near the edge at increment ``i`` (the full normal load): per radial bin of
    the points in contact, the mean radial shear, the rms hoop shear, the smallest margin
    m = mu p - |t| (all / mu p0) and the slipping points."""
    pts = r.points
    a_h = references.hertz_radius(r.P[i], R, E_star)
    p0 = references.hertz_peak_pressure(r.P[i], a_h)
    sl, sh = pts.slipping[i], pts.shear[i]
    m = r.mu * pts.pressure[i] - np.linalg.norm(sh, axis=1)
    s0 = r.mu * p0
    PETSc.Sys.Print(f"\nmargin at t = {r.t[i]:.3f} (a_H = {a_h:.5f} mm, p0 = {p0:.1f} MPa): "
                    "r/a_H bin, points in contact, mean t_r, rms t_theta, min m (/ mu p0), "
                    "slipping")
    edges = (0.0, 0.5, 0.7, 0.8, 0.85, 0.9, 0.925, 0.95, 0.975, 1.0, 1.025, 1.05, 1.1)
    bands, t_r, t_h = edge_bands(pts, i, a_h, edges)
    for lo, hi, b in bands:
        PETSc.Sys.Print(f"{lo:5.3f}-{hi:5.3f} {int(b.sum()):4d} {t_r[b].mean() / s0:+8.4f} "
                        f"{np.sqrt(np.mean(t_h[b] ** 2)) / s0:8.4f} {m[b].min() / s0:8.4f} "
                        f"{int((b & sl).sum()):4d}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", default="nodal", choices=["nodal", "quadrature"])
    ap.add_argument("--plain", action="store_true", help="plain penalty (no augmentation)")
    ap.add_argument("--basis", default="standard",
                    choices=["standard", "dual", "dual_quadratic"])
    ap.add_argument("--enforcement", default="uzawa", choices=["uzawa", "newton", "ssn"],
                    help="uzawa: AugmentedLagrangian; newton: NewtonAugmentedLagrangian; "
                         "ssn: SemismoothNewton (needs --basis dual_quadratic on P2)")
    ap.add_argument("--residual-ratio", type=float, default=1e-2,
                    help="NewtonAugmentedLagrangian.residual_ratio (--enforcement newton)")
    ap.add_argument("--contact-size", type=float, default=0.05)
    ap.add_argument("--preload-steps", type=int, default=2)
    ap.add_argument("--first-contact", default="increment_start",
                    choices=["increment_start", "closure"],
                    help="where a vertex that closes during an increment starts to stick "
                    "(SoftplusPenalty(first_contact=); docs/mindlin_dual.md, session 20)")
    ap.add_argument("--shear-steps", type=int, default=6)
    ap.add_argument("--k-tangential", type=float, default=1e9,
                    help="tangential penalty [MPa/mm]; with exact stick it sets only how fast "
                    "the multipliers converge")
    ap.add_argument("--al-tol", type=float, default=1e-4)
    ap.add_argument("--nu", type=float, default=0.49)
    ap.add_argument("--width-ratio", type=float, default=1e-3,
                    help="the softplus smoothing length w / delta (mindlin.run(width_ratio=)); "
                    "its pressure tail beyond the contact's edge scales as w^(2/3)")
    ap.add_argument("--half-width", type=float, default=4.0,
                    help="block half width L [mm] (the half model is [-L, L] x [0, L] x [-H, 0])")
    ap.add_argument("--height", type=float, default=4.0, help="block height H [mm]")
    ap.add_argument("--mesh-size", type=float, default=1.0,
                    help="element size away from the contact [mm]")
    ap.add_argument("--refined-radius", type=float, default=0.4,
                    help="radius about the origin meshed at --contact-size [mm]")
    ap.add_argument("--transition", type=float, default=1.0,
                    help="distance over which the element size grows to --mesh-size [mm]")
    ap.add_argument("--front-band", type=float, default=0.5,
                    help="band of the front fits, a fraction of the front's radius")
    ap.add_argument("--bands", type=float, nargs="*", default=[0.25, 1.0],
                    help="further bands of the front fit, printed beside --front-band's")
    ap.add_argument("--save", default=None, help="write the gathered points to this .npz")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    newton = args.enforcement in ("newton", "ssn") and not args.plain
    if args.enforcement == "ssn" and not args.plain:
        enforcement = SemismoothNewton()
    elif newton:
        enforcement = NewtonAugmentedLagrangian(args.al_tol, 60,
                                                residual_ratio=args.residual_ratio)
    else:
        enforcement = None
    t0, c0 = time.perf_counter(), time.process_time()
    r = mindlin.run(contact_size=args.contact_size, order=2, nu=args.nu,
                    preload_steps=args.preload_steps, shear_steps=args.shear_steps,
                    augmented=not (args.plain or newton), enforcement=enforcement,
                    points=args.points, basis=args.basis,
                    augmentation_tolerance=args.al_tol, max_updates=60,
                    k_tangential=args.k_tangential, half_width=args.half_width,
                    height=args.height, mesh_size=args.mesh_size,
                    transition=args.transition, refined_radius=args.refined_radius,
                    front_band=args.front_band, width_ratio=args.width_ratio,
                    first_contact=args.first_contact, verbose=args.verbose)
    E_star = E / (1.0 - args.nu**2)
    q = r.Q / (r.mu * r.P)
    PETSc.Sys.Print(f"{'t':>6} {'P [N]':>8} {'P/Hertz-1':>9} {'Q/muP':>7} {'c/a MD':>7} "
                    f"{'area':>7} {'error':>7} {'front':>7} {'error':>7} {'inside':>7} "
                    f"{'error':>7} {'a_FE/a_H':>8} "
                    f"{'resid':>6} {'misp':>4} {'D [N mm]':>10} {'Newton':>6}")
    for i in range(r.t.size):
        delta = DELTA * min(r.t[i], 1.0)
        hertz = references.hertz_force(delta, R, E_star)
        ref = float(references.stick_ratio(min(abs(r.Q[i]), r.mu * r.P[i]), r.mu, r.P[i]))
        a_h = references.hertz_radius(r.P[i], R, E_star)
        PETSc.Sys.Print(f"{r.t[i]:6.3f} {r.P[i]:8.3f} {r.P[i] / hertz - 1:+9.4f} {q[i]:7.4f} "
                        f"{ref:7.4f} {r.stick[i]:7.4f} {r.stick[i] / ref - 1:+7.4f} "
                        f"{r.stick_front[i]:7.4f} {r.stick_front[i] / ref - 1:+7.4f} "
                        f"{r.stick_front_inside[i]:7.4f} "
                        f"{r.stick_front_inside[i] / ref - 1:+7.4f} "
                        f"{r.contact_radius[i] / a_h:8.4f} {r.front_residual[i]:6.3f} "
                        f"{int(r.front_misplaced[i]):4d} "
                        f"{r.dissipation[i]:10.3e} {int(r.newton[i]):6d}")
    _fronts(r, E_star, args.bands)
    _edge_profile(r, E_star, int(np.searchsorted(r.t, 1.0 - 1e-12)))
    # the estimator alone: Mindlin's tractions at this mesh's point radii (a = Hertz's radius)
    a_h = references.hertz_radius(r.P[-1], R, E_star)
    p0 = references.hertz_peak_pressure(r.P[-1], a_h)
    rad, w = r.points.r, r.points.weight
    errs = []
    for ca in (1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3):
        p, t, st, sl = mindlin_tractions(rad, ca * a_h, a_h, p0, r.mu)
        f = stick_front(rad, p, t, r.mu, w, st, sl, band=args.front_band)
        errs.append(f"{ca:.1f}: {f.radius / (ca * a_h) - 1:+.1e}")
    PETSc.Sys.Print("estimator on Mindlin's tractions at these point radii, c/a: error  "
                    + ", ".join(errs))
    if args.save and MPI.COMM_WORLD.rank == 0:
        pts = r.points
        np.savez(args.save, x=pts.x, weight=pts.weight, pressure=pts.pressure, shear=pts.shear,
                 contact=pts.contact, slipping=pts.slipping, t=r.t, P=r.P, Q=r.Q,
                 stick=r.stick, stick_front=r.stick_front,
                 stick_front_inside=r.stick_front_inside, stick_radius=r.stick_radius,
                 contact_radius=r.contact_radius, mu=r.mu, nu=r.nu, G=r.G)
    PETSc.Sys.Print(f"DOFs {r.dofs}, wall {time.perf_counter() - t0:.0f} s, "
                    f"CPU (rank 0) {time.process_time() - c0:.0f} s")
    return r


if __name__ == "__main__":
    main()
