"""Cattaneo–Mindlin and Mindlin–Deresiewicz under mesh refinement (rough_contact.scenes.mindlin).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_mindlin.py [--levels 0.05 0.025]
        [--part stick|energy|all] [--amplitudes 0.5] [--ring 0.25 [--ring-band 0.8 1.05]]

Rigid paraboloid R = 10 mm on a half block 8 x 4 x 4 mm, E = 200 GPa, nu = 0.49, mu = 0.3,
Coulomb penalty 1e8 MPa/mm (normal and tangential), P2, bottom pushed up by 4 um (P ~ 294 N,
a ~ 0.20 mm), then slid along x. "stick": the FE stick ratio sqrt(1 - A_slip / A_contact) against
(1 - Q / mu P)^(1/3) at every increment of a monotonic slide to gross slip (12 increments).
"energy": two triangle cycles of the slide (16 increments each) at amplitude x (the slide that
reaches mu P): the interface dissipation of the second cycle and the loop area of Q against the
bottom slide (trapezoids) against Mindlin–Deresiewicz at the measured amplitude Q*.
Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from petsc4py import PETSc

from rough_contact import references
from rough_contact.scenes import mindlin

E, NU, MU, R, DELTA = 2.0e5, 0.49, 0.3, 10.0, 4e-3


def gross_slide():
    G = E / (2 * (1 + NU))
    Es = E / (1 - NU**2)
    P = references.hertz_force(DELTA, R, Es)
    a = references.hertz_radius(P, R, Es)
    return references.sliding_approach(MU, P, a, G, NU) + MU * P * 4.0 / (G * 2 * 16.0)


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


def energy(levels, amplitudes, kt=None, kt_scale=None, ring_size=None, ring_band=(0.8, 1.05),
           width_ratio=1e-3, augmented=False, quadrature_degree=None, verbose=False):
    PETSc.Sys.Print(f"{'h':>6} {'DOFs':>7} {'ampl':>5} {'Q*/muP':>6} {'W FE':>10} {'loop':>10} "
                    f"{'W MD':>10} {'error':>7} {'Newton':>6} {'time s':>6}")
    G = E / (2 * (1 + NU))
    for h in levels:
        for amp in amplitudes:
            t0 = time.perf_counter()
            r = mindlin.run(contact_size=h, order=2, nu=NU, mu=MU, slide=amp * gross_slide(),
                            cycles=2, shear_steps=16, k_tangential=_kt(h, kt, kt_scale),
                            ring_size=None if ring_size is None else h * ring_size,
                            ring_band=tuple(ring_band), width_ratio=width_ratio,
                            augmented=augmented, quadrature_degree=quadrature_degree,
                            verbose=verbose)
            t, s, Q, D = r.t, r.slide, r.Q, r.dissipation
            end1 = int(np.argmin(np.abs(t - 2.0)))
            idx = np.arange(end1, t.size)
            W = D[-1] - D[end1]
            Qs = 0.5 * (Q[idx].max() - Q[idx].min())
            loop = float(np.sum(0.5 * (Q[idx][1:] + Q[idx][:-1]) * np.diff(s[idx])))
            ref = float(references.energy_per_cycle(Qs, MU, r.P[-1], r.a, G, NU))
            PETSc.Sys.Print(f"{h:6.4f} {r.dofs:7d} {amp:5.2f} {Qs / (MU * r.P[-1]):6.3f} "
                            f"{W:10.4e} {loop:10.4e} {ref:10.4e} {W / ref - 1:+7.3f} "
                            f"{int(r.newton.sum()):6d} {time.perf_counter() - t0:6.0f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=float, nargs="+", default=[0.05, 0.025])
    ap.add_argument("--part", choices=["stick", "energy", "all"], default="all")
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
    ap.add_argument("--width-ratio", type=float, default=1e-3,
                    help="energy: softplus smoothing length / indentation (default 1e-3)")
    ap.add_argument("--augmented", action="store_true",
                    help="energy: exact stick and contact (augmented Lagrangian, Uzawa)")
    ap.add_argument("--quadrature-degree", type=int, default=None,
                    help="energy: facet Gauss rule degree (default 2 x order = 4; 1 = one point "
                    "per facet, the rule the augmented Lagrangian converges with on P2)")
    ap.add_argument("--verbose", action="store_true",
                    help="energy: print every increment (Newton iterations, multiplier updates, "
                    "cutbacks)")
    args = ap.parse_args(argv)
    if args.part in ("stick", "all"):
        stick(args.levels, args.k_tangential, args.kt_scale)
    if args.part in ("energy", "all"):
        energy(args.levels, args.amplitudes, args.k_tangential, args.kt_scale, args.ring,
               args.ring_band, args.width_ratio, args.augmented, args.quadrature_degree,
               args.verbose)


if __name__ == "__main__":
    main()
