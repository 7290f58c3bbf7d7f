"""Cost of the BEM normal law: build time vs grid size and backend, next to the statistical laws,
and the evaluation cost of the resulting tables (what the FE layer pays per quadrature point).

    bash run.sh python benchmarks/bench_bem_cost.py                # ~3 min
    bash run.sh python benchmarks/bench_bem_cost.py --grids 64 128 256 512 1024 --pressures 16

Build: one realisation of the isotropic example surface (rough_contact.surface.spectrum) on n x n pixels
over one roll-off period, solved at ``--pressures`` mean pressures (A/A0 ~ 0.5 % to 30 %), with
and without the tangential stiffness; no disk cache. Evaluation: NormalLaw.evaluate on 1e6
random separations inside the table, best of 5. Units: s, M points/s.
"""
from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

from rough_contact.micro import bem
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.interface.normal import NormalLaw
from rough_contact.surface.spectrum import example_surfaces, fit_spectrum

E_STAR, NU = 1.067e5, 0.25


def build_times(grids, n_p, backends, tangential):
    m, shape = example_surfaces()["isotropic"]
    spec = fit_spectrum(m, shape)
    (_, _), (Lx, Ly) = spec.grid(4.0)
    pressures = bem.default_pressures(E_STAR, math.sqrt(m.m20 + m.m02), n=n_p)
    rows = []
    laws = {}
    for n in grids:
        z = spec.realisation((n, n), (Lx, Ly), seed=7)
        ppw = n / (spec.q_s / spec.q_l)
        for backend in backends:
            for tang in ([False, True] if tangential else [False]):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", bem.HeightMapWarning)
                    t0 = time.perf_counter()
                    law = bem.bem_normal_law(z, Lx / n, Ly / n, E_star=E_STAR, nu=NU,
                                             pressures=pressures, backend=backend,
                                             tangential=tang, cache=False)
                    dt = time.perf_counter() - t0
                laws[n] = law
                rows.append((n, ppw, law.info["backend"], tang, dt, dt / n_p))
                print(f"  n = {n:5d} ({ppw:5.1f} px/wavelength)  {law.info['backend']:30s} "
                      f"tangential={tang!s:5s}  {dt:8.2f} s", flush=True)
    return rows, laws, m


def eval_rate(law, n=1_000_000, repeat=5):
    rng = np.random.default_rng(0)
    h = rng.uniform(law.h_min, law.h_table_end, n)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        law.evaluate(h)
        best = min(best, time.perf_counter() - t0)
    return n / best / 1e6


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--grids", nargs="+", type=int, default=[64, 128, 256, 512])
    ap.add_argument("--pressures", type=int, default=8)
    ap.add_argument("--backends", nargs="+", default=None, choices=["tamaas", "numpy"])
    ap.add_argument("--no-tangential", action="store_true")
    args = ap.parse_args(argv)
    backends = args.backends or list(bem.available_backends())
    rows, laws, m = build_times(args.grids, args.pressures, backends, not args.no_tangential)

    # the statistical laws of the same moments (default rtol 1e-4)
    stat = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for name, make in (
                ("GW (McCool)", lambda: NormalLaw.greenwood_williamson(m, E_STAR)),
                ("statistical elastic", lambda: NormalLaw.elastic(m, E_STAR)),
                ("statistical elasto-plastic", lambda: NormalLaw.elasto_plastic(
                    m, AsperityMaterial.from_plasticity_index(m, 0.35, E_STAR, nu=NU)))):
            t0 = time.perf_counter()
            stat[name] = (make(), time.perf_counter() - t0)

    print(f"\nBEM law build time (isotropic example surface, one realisation, {args.pressures} "
          "pressures, A/A0 ~ 0.5-30 %)\n")
    print(f"{'grid':>6s} {'px/wavel.':>9s} {'backend':30s} {'kT':>5s} {'total s':>9s} "
          f"{'s/pressure':>11s}")
    for n, ppw, be, tang, dt, per in rows:
        print(f"{n:6d} {ppw:9.1f} {be:30s} {'yes' if tang else 'no':>5s} {dt:9.2f} {per:11.3f}")
    print("\nStatistical law build time (same moments, rtol 1e-4)\n")
    for name, (law, dt) in stat.items():
        print(f"  {name:28s} {dt:8.2f} s")
    print("\nEvaluation (NormalLaw.evaluate, 1e6 points inside the table, best of 5)\n")
    big = laws[max(laws)]
    for name, law in [(f"BEM ({max(laws)}^2, {big.normal.n_intervals} intervals)", big.normal)] + \
            [(f"{k} ({v[0].n_intervals} intervals)", v[0]) for k, v in stat.items()]:
        print(f"  {name:46s} {eval_rate(law):7.1f} M points/s")


if __name__ == "__main__":
    main()
