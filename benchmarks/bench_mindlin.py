"""Cattaneo–Mindlin and Mindlin–Deresiewicz under mesh refinement (rough_contact.scenes.mindlin).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_mindlin.py [--levels 0.05 0.025]
        [--part stick|energy|all|mesh] [--amplitudes 0.5]
        [--ring 0.25 [--ring-band 0.8 1.05] [--ring-growth 0.1]]
        [--exact [--local-penalty] --points nodal --basis dual] [--steps-per-cycle 16]
        [--half-width 4 --height 4 --mesh-size 1 --transition 1] [--preload-steps 2]

Rigid paraboloid R = 10 mm on a half block 8 x 4 x 4 mm, E = 200 GPa, nu = 0.49, mu = 0.3,
Coulomb penalty 1e8 MPa/mm (normal and tangential), P2, bottom pushed up by 4 um (P ~ 294 N,
a ~ 0.20 mm), then slid along x. "stick": the FE stick ratio sqrt(1 - A_slip / A_contact) against
(1 - Q / mu P)^(1/3) at every increment of a monotonic slide to gross slip (12 increments).
"energy": two triangle cycles of the slide (16 increments each) at amplitude x (the slide that
reaches mu P): the interface dissipation of the second cycle and the loop area of Q against the
bottom slide (trapezoids) against Mindlin–Deresiewicz at the measured amplitude Q* ("error",
"loop e"; "trap": the trapezoids' own error on Masing's closed-form loop sampled at the same
steps, -6.3 % at 8 steps per cycle, -1.6 % at 16), and the second cycle's descending branch
against Masing's (largest |Q - Q_Masing| / Q*). After each energy run: the first loading
branch's stick radius c/a_FE against (1 - Q / mu P)^(1/3) and where points slip under the normal
load alone (--stop-after N stops a run after N increments, e.g. 6: the normal load and that
branch only).
Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace

import numpy as np
from petsc4py import PETSc

from _common import normal_load_profile
from rough_contact import references
from rough_contact.frictional_hertz import coupling_parameter
from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.solver.checkpoint import has_checkpoint
from rough_contact.scenes import mindlin

E, NU, MU, R, DELTA = 2.0e5, 0.49, 0.3, 10.0, 4e-3


def beta_over_mu(mu=MU):
    """Dundurs' beta of the rigid indenter on this block over mu (Spence's parameter; the
    indenter's Poisson ratio does not enter)."""
    return abs(coupling_parameter(np.inf, 0.0, E, NU)) / mu


def gross_slide(half_width=4.0, height=4.0):
    """The bottom slide at which Mindlin's Q reaches mu P (Hertz's P and a at DELTA) plus the
    block's shear compliance H / (G 2 L^2) times mu P."""
    G = E / (2 * (1 + NU))
    Es = E / (1 - NU**2)
    P = references.hertz_force(DELTA, R, Es)
    a = references.hertz_radius(P, R, Es)
    return references.sliding_approach(MU, P, a, G, NU) + \
        MU * P * height / (G * 2 * half_width * half_width)


def _kt(h, kt, kt_scale):
    """The tangential penalty at element size h: fixed, or kt_scale E / h."""
    return kt_scale * E / h if kt_scale else kt


def stick(levels, kt=None, kt_scale=None):
    PETSc.Sys.Print(f"{'h':>6} {'h/a':>5} {'DOFs':>7} {'Q/muP':>6} {'c/a FE':>7} {'c/a MD':>7} "
                    f"{'error':>7} {'Newton':>6} {'time s':>6}")
    for h in levels:
        t0 = time.perf_counter()
        r = mindlin.run(contact_size=h, order=2, nu=NU, mu=MU,
                        k_tangential=_kt(h, kt, kt_scale))
        dt = time.perf_counter() - t0
        q = r.Q / (MU * r.P)
        for i in np.flatnonzero((q > 0.01) & (q < 0.99)):
            ref = float(references.stick_ratio(r.Q[i], MU, r.P[i]))
            PETSc.Sys.Print(f"{h:6.4f} {h / r.a:5.3f} {r.dofs:7d} {q[i]:6.3f} "
                            f"{r.stick[i]:7.3f} {ref:7.3f} {r.stick[i] / ref - 1:+7.3f} "
                            f"{int(r.newton.sum()):6d} {dt:6.0f}")


def masing_error(r, G, block_compliance):
    """Largest |Q_FE - Q_Masing| / Q* over the second cycle's descending branch (t in
    [2.25, 2.75]): Masing's branch from the amplitude (s*, Q*) of the FE loop, Q(s) = Q* -
    2 Q_v((s* - s) / 2), with the virgin curve Q_v(s) of Mindlin's closed form plus the block's
    linear shear compliance s = delta(Q) + c_b Q (inverted by bisection)."""
    P, a, mu = r.P[-1], r.a, r.mu
    idx = np.flatnonzero((r.t > 2.25 + 1e-9) & (r.t < 2.75 - 1e-9))
    top = int(np.argmin(np.abs(r.t - 2.25)))
    s_top, Q_top = r.slide[top], r.Q[top]

    def virgin(x):                      # Q at slide x >= 0 (bisection on [0, mu P])
        lo, hi = np.zeros_like(x), np.full_like(x, mu * P)
        for _ in range(60):
            m = 0.5 * (lo + hi)
            f = references.tangential_approach(m, mu, P, a, G, NU) + block_compliance * m
            lo, hi = np.where(f < x, m, lo), np.where(f < x, hi, m)
        return 0.5 * (lo + hi)

    Q_ref = Q_top - 2.0 * virgin(0.5 * (s_top - r.slide[idx]))
    return float(np.max(np.abs(r.Q[idx] - Q_ref)) / abs(Q_top)) if idx.size else float("nan")


def sampled_loop_bias(slide, steps, block_compliance):
    """The loop-area measure's own error at ``steps`` increments per cycle: trapezoids over
    Masing's closed-form loop (Mindlin's virgin curve plus the block's compliance) sampled at
    the bench's uniform slide steps, against Mindlin–Deresiewicz's energy at the same Q*
    (tends to 0 as ``steps`` grows: 1024 steps give < 1e-4)."""
    G = E / (2 * (1 + NU))
    Es = E / (1 - NU**2)
    P = references.hertz_force(DELTA, R, Es)
    a = references.hertz_radius(P, R, Es)

    def virgin(x):
        lo, hi = np.zeros_like(x), np.full_like(x, MU * P)
        for _ in range(80):
            m = 0.5 * (lo + hi)
            f = references.tangential_approach(m, MU, P, a, G, NU) + block_compliance * m
            lo, hi = np.where(f < x, m, lo), np.where(f < x, hi, m)
        return 0.5 * (lo + hi)

    Qs = float(virgin(np.array([slide]))[0])
    down = np.linspace(slide, -slide, steps // 2 + 1)
    up = np.linspace(-slide, slide, steps // 2 + 1)
    s = np.concatenate([down, up[1:]])
    Q = np.concatenate([Qs - 2 * virgin(0.5 * (slide - down)),
                        -Qs + 2 * virgin(0.5 * (up[1:] + slide))])
    loop = float(np.sum(0.5 * (Q[1:] + Q[:-1]) * np.diff(s)))
    return loop / float(references.energy_per_cycle(Qs, MU, P, a, G, NU)) - 1.0


def mesh_only(levels, ring_size=None, ring_band=(0.8, 1.05), ring_growth=None, scene=None):
    """The scene's mesh alone (seconds, no solve): DOFs and, with a ring, the top-surface
    vertices in the band against the count its area needs at the ring size (coverage ~1 when
    gmsh has refined the whole band), and the vertex spacing there (median nearest neighbour).
    For sizing runs before paying for them."""
    import dolfinx
    from scipy.spatial import cKDTree

    from rough_contact.fem.compat import vector_space
    from rough_contact.scenes.meshes.blocks import indented_block

    scene = dict(scene or {})
    a_h = np.sqrt(R * DELTA)
    lo, hi = ring_band
    PETSc.Sys.Print(f"{'h':>6} {'ring':>7} {'DOFs':>8} {'band verts':>10} {'coverage':>8} "
                    f"{'spacing':>8}")
    for h in levels:
        size = None if ring_size is None else h * ring_size
        ring = None if size is None else (0.5 * (lo + hi) * a_h, 0.5 * (hi - lo) * a_h, size)
        sc = indented_block(half_width=scene.get("half_width", 4.0),
                            height=scene.get("height", 4.0),
                            mesh_size=scene.get("mesh_size", 1.0), contact_size=h,
                            transition=scene.get("transition", 1.0), order=2, half=True,
                            ring=ring, ring_growth=None if ring_growth is None
                            else ring_growth * a_h)
        dofs = 3 * vector_space(sc.mesh, 2).dofmap.index_map.size_global
        msh = sc.mesh
        msh.topology.create_connectivity(2, 0)
        top = dolfinx.mesh.compute_incident_entities(
            msh, sc.facet_tags.find(sc.tag("contact")), 2, 0)
        nloc = msh.topology.index_map(0).size_local
        xv = dolfinx.mesh.compute_midpoints(msh, 0, np.unique(top[top < nloc]))[:, :2]
        xv = np.concatenate(msh.comm.allgather(xv))
        rho = np.hypot(xv[:, 0], xv[:, 1]) / a_h
        band = (rho > lo) & (rho < min(hi, 1.0))
        if size is None or not band.any():
            PETSc.Sys.Print(f"{h:6.4f} {'-':>7} {dofs:8d}")
            continue
        need = 0.5 * np.pi * a_h**2 * (min(hi, 1.0)**2 - lo**2) / (0.866 * size**2)
        d, _ = cKDTree(xv).query(xv[band], k=2)
        PETSc.Sys.Print(f"{h:6.4f} {size:7.5f} {dofs:8d} {int(band.sum()):10d} "
                        f"{band.sum() / need:8.2f} {np.median(d[:, 1]):8.5f}")


def energy(levels, amplitudes, kt=None, kt_scale=None, ring_size=None, ring_band=(0.8, 1.05),
           ring_growth=None, width_ratio=1e-3, augmented=False, quadrature_degree=None,
           verbose=False, steps_per_cycle=16, scene=None):
    """``scene``: further arguments of ``mindlin.run`` (block, mesh, points, enforcement).
    ``ring_growth``: the ring's growth to the contact size, a fraction of Hertz's radius.
    ``scene["local_penalty"]``: the enforcement's tangential penalty scaled with the vertex
    spacing (``reference_spacing`` = the level's size)."""
    scene = dict(scene or {})
    local = scene.pop("local_penalty", False)
    ckpt_root = scene.pop("checkpoint", None)
    PETSc.Sys.Print(f"{'h':>6} {'DOFs':>7} {'ampl':>5} {'Q*/muP':>6} {'W FE':>10} {'loop':>10} "
                    f"{'W MD':>10} {'error':>7} {'loop e':>7} {'trap':>7} {'Masing':>7} "
                    f"{'Newton':>6} {'time s':>6} "
                    f"{'CPU s':>6}")
    G = E / (2 * (1 + NU))
    L, H = scene.get("half_width", 4.0), scene.get("height", 4.0)
    c_b = H / (G * 2.0 * L * L)         # the block's shear compliance [mm/N]
    for h in levels:
        if local:
            scene["enforcement"] = replace(scene["enforcement"], reference_spacing=h)
        for amp in amplitudes:
            t0, c0 = time.perf_counter(), time.process_time()
            if ckpt_root is not None:
                # one directory per run; an existing checkpoint there is continued (the time
                # columns are then this call's only)
                pre = scene.get("preload_steps", 2)
                closure = scene.get("first_contact", "increment_start") == "closure"
                ckpt = os.path.join(ckpt_root, f"h{h:g}_amp{amp:g}"
                                    + (f"_p{pre}" if pre != 2 else "")
                                    + ("_closure" if closure else ""))
                scene["checkpoint"] = ckpt
                scene["restart"] = ckpt if has_checkpoint(ckpt) else None
                if scene["restart"] is not None:
                    PETSc.Sys.Print(f"continuing from the checkpoint in {ckpt}")
            r = mindlin.run(contact_size=h, order=2, nu=NU, mu=MU,
                            slide=amp * gross_slide(L, H), cycles=2,
                            shear_steps=steps_per_cycle, k_tangential=_kt(h, kt, kt_scale),
                            ring_size=None if ring_size is None else h * ring_size,
                            ring_band=tuple(ring_band), width_ratio=width_ratio,
                            ring_growth=None if ring_growth is None
                            else ring_growth * np.sqrt(R * DELTA),
                            augmented=augmented, quadrature_degree=quadrature_degree,
                            verbose=verbose, **scene)
            t, s, Q, D = r.t, r.slide, r.Q, r.dissipation
            if t[-1] < r.cycle_start + 2.0 - 1e-9:
                # stopped early (--stop-after): no cycle to measure yet
                PETSc.Sys.Print(f"{h:6.4f} {r.dofs:7d} {amp:5.2f} stopped at t = {t[-1]:.4f} "
                                f"after {t.size} increments ({int(r.newton.sum())} Newton)")
                if t[-1] >= r.cycle_start - 1e-9:
                    first_loading(r)
                continue
            end1 = int(np.argmin(np.abs(t - 2.0)))
            idx = np.arange(end1, t.size)
            W = D[-1] - D[end1]
            Qs = 0.5 * (Q[idx].max() - Q[idx].min())
            loop = float(np.sum(0.5 * (Q[idx][1:] + Q[idx][:-1]) * np.diff(s[idx])))
            ref = float(references.energy_per_cycle(Qs, MU, r.P[-1], r.a, G, NU))
            trap = sampled_loop_bias(amp * gross_slide(L, H), steps_per_cycle, c_b)
            PETSc.Sys.Print(f"{h:6.4f} {r.dofs:7d} {amp:5.2f} {Qs / (MU * r.P[-1]):6.3f} "
                            f"{W:10.4e} {loop:10.4e} {ref:10.4e} {W / ref - 1:+7.3f} "
                            f"{loop / ref - 1:+7.3f} "
                            f"{trap:+7.4f} "
                            f"{masing_error(r, G, c_b):7.4f} {int(r.newton.sum()):6d} "
                            f"{time.perf_counter() - t0:6.0f} {time.process_time() - c0:6.0f}")
            first_loading(r)


def first_loading(r):
    """The stick radius on the first loading branch (from the end of the normal load to the
    first peak) against Cattaneo–Mindlin's c / a = (1 - Q / mu P)^(1/3), and the slip under the
    normal load alone: the points in contact that slip at the end of the normal load, the
    innermost one's radius over Hertz's radius (the continuum has none: Spence's annulus is
    ~1e-21 a at nu = 0.49, mu = 0.3, docs/mindlin_dual.md)."""
    i0 = int(np.argmin(np.abs(r.t - r.cycle_start)))
    i1 = int(np.argmin(np.abs(r.t - min(r.cycle_start + 0.25, r.t[-1]))))
    slip0 = r.points.slipping[i0]
    inner = float(r.points.r[slip0].min()) / r.a if slip0.any() else float("nan")
    PETSc.Sys.Print(f"  normal load alone: {int(slip0.sum())} of "
                    f"{int(r.points.contact[i0].sum())} points in contact slip, the innermost "
                    f"at r / a_Hertz = {inner:.4f}")
    # where they are: per band of r / a_Hertz, the slipping points, the mean radial shear
    # (outwards on the block positive) / mu p0 and the largest |t| / mu p, against the
    # continuum's (Spence's problem at this beta / mu)
    PETSc.Sys.Print("\n".join(normal_load_profile(r.points, i0, r.a, r.mu,
                                                   beta_over_mu(r.mu))))
    PETSc.Sys.Print(f"  {'Q/muP':>7} {'c/a FE':>7} {'inside':>7} {'c/a CM':>7} {'error':>7} "
                    f"{'in err':>7}")
    for i in range(i0, i1 + 1):
        q = abs(r.Q[i]) / (r.mu * r.P[i])
        cm = float(references.stick_ratio(abs(r.Q[i]), r.mu, r.P[i]))
        PETSc.Sys.Print(f"  {q:7.4f} {r.stick_front[i]:7.4f} {r.stick_front_inside[i]:7.4f} "
                        f"{cm:7.4f} {r.stick_front[i] / cm - 1:+7.4f} "
                        f"{r.stick_front_inside[i] / cm - 1:+7.4f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=float, nargs="+", default=[0.05, 0.025])
    ap.add_argument("--part", choices=["stick", "energy", "all", "mesh"], default="all",
                    help="mesh: the energy scene's mesh only (DOFs, ring coverage)")
    ap.add_argument("--amplitudes", type=float, nargs="+", default=[0.5])
    ap.add_argument("--k-tangential", type=float, default=None,
                    help="tangential penalty [MPa/mm] (default: the normal one, 1e8)")
    ap.add_argument("--kt-scale", type=float, default=None,
                    help="tangential penalty k_T = KT_SCALE * E / h at element size h "
                    "(overrides --k-tangential)")
    ap.add_argument("--ring", type=float, default=None,
                    help="energy: element size in the ring (--ring-band) as a fraction of the "
                    "level's contact size (e.g. 0.25: four times finer at the contact edge)")
    ap.add_argument("--ring-band", type=float, nargs=2, default=[0.8, 1.05],
                    help="the ring's radii as fractions of Hertz's radius sqrt(R delta)")
    ap.add_argument("--ring-growth", type=float, default=None,
                    help="energy: distance from the ring's band over which its size grows to the "
                    "contact size, a fraction of Hertz's radius (default: towards --mesh-size "
                    "over the band's width, too steep for a coarse far mesh)")
    ap.add_argument("--width-ratio", type=float, default=1e-3,
                    help="energy: softplus smoothing length / indentation (default 1e-3)")
    ap.add_argument("--augmented", action="store_true",
                    help="energy: exact stick and contact (augmented Lagrangian, Uzawa)")
    ap.add_argument("--quadrature-degree", type=int, default=None,
                    help="energy: facet Gauss rule degree (default 2 x order = 4; 1 = one point "
                    "per facet, the rule the augmented Lagrangian converges with on P2)")
    ap.add_argument("--steps-per-cycle", type=int, default=16,
                    help="energy: increments per cycle (a multiple of 4)")
    ap.add_argument("--preload-steps", type=int, default=2,
                    help="energy: increments of the normal load (a vertex that closes during "
                    "an increment sticks where it was at the increment's start, so the shear "
                    "of the edge vertices under the normal load alone grows with the "
                    "increment: at nu = 0.49 2 increments leave an edge annulus slipping, "
                    "docs/mindlin_dual.md)")
    ap.add_argument("--first-contact", default="increment_start",
                    choices=["increment_start", "closure"],
                    help="energy: where a vertex that closes during an increment starts to "
                    "stick (SoftplusPenalty(first_contact=)): at the increment's start (the "
                    "default, the runs of sessions 12-19) or where it is at its end; with "
                    "'closure' no vertex in contact slips under the normal load alone "
                    "(docs/mindlin_dual.md, session 20)")
    ap.add_argument("--points", default="quadrature", choices=["quadrature", "nodal"])
    ap.add_argument("--basis", default="standard", choices=["standard", "dual"])
    ap.add_argument("--exact", action="store_true",
                    help="energy: exact contact and stick by multipliers updated inside "
                    "Newton (NewtonAugmentedLagrangian(--al-tol); needs --points nodal)")
    ap.add_argument("--al-tol", type=float, default=1e-4)
    ap.add_argument("--local-penalty", action="store_true",
                    help="energy, with --exact: the tangential penalty chosen for the level's "
                    "size h scaled at each vertex by h / h_j (NewtonAugmentedLagrangian("
                    "reference_spacing=h)): the ring's vertices get a stiffer one, fewer "
                    "Newton iterations, the same fixed point")
    ap.add_argument("--checkpoint", default=None, metavar="DIR",
                    help="energy: a checkpoint per increment in DIR/h<h>_amp<amplitude> "
                    "(_p<N> appended for --preload-steps N other than 2, _closure for "
                    "--first-contact closure); a run "
                    "whose directory holds one continues from it (a killed run loses no "
                    "converged increment; CPU and time columns then cover this call only)")
    ap.add_argument("--stop-after", type=int, default=None, metavar="N",
                    help="energy: stop each run after N increments solved by this call (e.g. "
                    "the normal load and the first loading branch only, whose stick radius is "
                    "printed; with --checkpoint a later call continues)")
    ap.add_argument("--half-width", type=float, default=4.0, help="block half width L [mm]")
    ap.add_argument("--height", type=float, default=4.0, help="block height H [mm]")
    ap.add_argument("--mesh-size", type=float, default=1.0, help="far element size [mm]")
    ap.add_argument("--transition", type=float, default=1.0,
                    help="distance over which the element size grows to --mesh-size [mm]")
    ap.add_argument("--verbose", action="store_true",
                    help="energy: print every increment (Newton iterations, multiplier updates, "
                    "cutbacks)")
    args = ap.parse_args(argv)
    if args.part == "mesh":
        mesh_only(args.levels, args.ring, args.ring_band, args.ring_growth,
                  dict(half_width=args.half_width, height=args.height,
                       mesh_size=args.mesh_size, transition=args.transition))
        return
    if args.part in ("stick", "all"):
        stick(args.levels, args.k_tangential, args.kt_scale)
    if args.part in ("energy", "all"):
        scene = dict(half_width=args.half_width, height=args.height,
                     mesh_size=args.mesh_size, transition=args.transition,
                     points=args.points, basis=args.basis, preload_steps=args.preload_steps,
                     first_contact=args.first_contact)
        if args.exact:
            scene["enforcement"] = NewtonAugmentedLagrangian(args.al_tol, 60)
        elif args.local_penalty:
            ap.error("--local-penalty needs --exact")
        scene["local_penalty"] = args.local_penalty
        scene["checkpoint"] = args.checkpoint
        scene["stop_after"] = args.stop_after
        energy(args.levels, args.amplitudes, args.k_tangential, args.kt_scale, args.ring,
               args.ring_band, args.ring_growth, args.width_ratio, args.augmented,
               args.quadrature_degree, args.verbose, args.steps_per_cycle, scene)


if __name__ == "__main__":
    main()
