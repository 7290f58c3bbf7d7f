"""Elastic vs elasto-plastic normal stiffness at given nominal pressures (issue 12, README claim).

For the beam's three surfaces (Table 1 moments with m00 = 0.625, 0.3125, 0.0625 um^2), the
plasticity indices psi = 0.35 and 0.5 of Figs 7-8, and nominal pressures p = W/A0, prints the
separation h where each population model carries p (Newton on the model's own exact stiffness,
k = -dp/dh), A/A0 there, both stiffnesses and their relative difference
``k_ep/k_el - 1`` — directly from the population integrals (rough_contact.micro.population), no table.

Material readings (``--reading``):
  project (default): the project's reading behind eq (74), as in demos/demo_micro_model.py
      (Figs 7-8): E* = 1.14e5 MPa, nu = 0.3, H from psi by (69), K_Y Y = (2/pi) H
      (``AsperityMaterial.from_plasticity_index``);
  caption: the beam demo's literal caption data (demos/demo_beam_rigid_base.py): E* = 1.127e5
      MPa, nu = 0.25, H from psi by (69), Y = 2070 MPa, K_Y = 1.62.
h/rq and A/A0 are those of the elasto-plastic model. Rows where either model's A/A0 exceeds 0.3
lie below the normal law's validity limit h_min (marked "*"): there the FE layer uses the stiff
continuation, not these values.

Usage:
    .venv/bin/python benchmarks/bench_ep_vs_elastic_stiffness.py
    .venv/bin/python benchmarks/bench_ep_vs_elastic_stiffness.py --reading caption
    .venv/bin/python benchmarks/bench_ep_vs_elastic_stiffness.py --pressures 1,10,100,300,1000
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from rough_contact.micro import population
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

MOMENTS = dict(m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)       # Table 1, um convention
READINGS = {
    "project": dict(E_star=1.14e5, material=lambda s, psi, E: AsperityMaterial.from_plasticity_index(
        s, psi, E)),
    "caption": dict(E_star=1.057e5 / (1 - 0.25**2), material=lambda s, psi, E: AsperityMaterial(
        E_star=E, nu=0.25, psi=psi, Y=2070.0, K_Y=1.62, ch=0.967, omega_p_ratio=45.0)),
}


def separation_at(model, p_target, sigma, n_grid=61, iters=30):
    """h [mm] with model(h).pressure == p_target (vectorised Newton with the exact k)."""
    grid = np.linspace(-3.0, 6.0, n_grid) * sigma
    r = model(grid)
    lp = np.log(r.pressure)
    # start: interpolation of ln p on the grid (p decreases with h)
    h = np.interp(-np.log(p_target), -lp, grid)
    for _ in range(iters):
        r = model(h)
        # Newton on ln p: d ln p/dh = -k/p
        step = (np.log(r.pressure) - np.log(p_target)) * r.pressure / r.stiffness
        h = h + step
        if np.all(np.abs(step) <= 1e-12 * sigma):
            break
    r = model(h)
    if not np.allclose(r.pressure, p_target, rtol=1e-9):
        raise RuntimeError(f"Newton did not converge: p = {r.pressure} vs {p_target}")
    return h, r


def main(argv=None):
    ap = argparse.ArgumentParser(allow_abbrev=False, description=__doc__.splitlines()[0])
    ap.add_argument("--reading", default="project", choices=sorted(READINGS))
    ap.add_argument("--m00", default="0.625,0.3125,0.0625", help="comma list [um^2]")
    ap.add_argument("--psi", default="0.35,0.5", help="comma list of plasticity indices")
    ap.add_argument("--pressures", default="1,10,100,1000", help="comma list [MPa]")
    ap.add_argument("--n-quad", type=int, default=None, help="population quadrature (default: "
                    "the population functions' own defaults)")
    args = ap.parse_args(argv)
    reading = READINGS[args.reading]
    E = reading["E_star"]
    p = np.array([float(v) for v in args.pressures.split(",")])
    kw = {} if args.n_quad is None else {"n_quad": args.n_quad}
    print(f"reading: {args.reading}, E* = {E:.6g} MPa; population quadrature: "
          f"{kw.get('n_quad', 'default')}")
    print(f"{'m00 um^2':>9s} {'psi':>5s} {'H MPa':>8s} {'KY*Y MPa':>9s} {'p MPa':>7s} "
          f"{'h/rq':>7s} {'A/A0 ep':>8s}{'k_el MPa/mm':>12s} {'k_ep MPa/mm':>12s} {'k_ep/k_el-1':>12s}")
    t0 = time.perf_counter()
    worst = {}
    for m00 in (float(v) for v in args.m00.split(",")):
        s = SpectralMoments(m00=m00, **MOMENTS, unit="um")
        h_el, r_el = separation_at(lambda h: population.elastic(s, E, h, **kw), p, s.rq)
        for psi in (float(v) for v in args.psi.split(",")):
            mat = reading["material"](s, psi, E).resolve(s)
            h_ep, r_ep = separation_at(lambda h: population.elasto_plastic(s, mat, h, **kw), p,
                                       s.rq)
            diff = r_ep.stiffness / r_el.stiffness - 1
            for i, pi in enumerate(p):
                flag = "*" if max(r_el.area_fraction[i], r_ep.area_fraction[i]) > 0.3 else " "
                print(f"{m00:9.4g} {psi:5.2f} {mat.H:8.0f} {mat.yield_pressure:9.0f} {pi:7g} "
                      f"{h_ep[i] / s.rq:7.3f} {r_ep.area_fraction[i]:7.4f}{flag}"
                      f"{r_el.stiffness[i]:12.5g} {r_ep.stiffness[i]:12.5g} {diff[i]:+12.3%}")
                worst[(m00, psi, pi)] = diff[i]
    print(f"\n{time.perf_counter() - t0:.1f} s. Largest |k_ep/k_el - 1| per pressure:")
    for pi in p:
        d = {k: v for k, v in worst.items() if k[2] == pi}
        k = max(d, key=lambda key: abs(d[key]))
        print(f"  p = {pi:g} MPa: {d[k]:+.3%} (m00 = {k[0]:g} um^2, psi = {k[1]:g})")


if __name__ == "__main__":
    main()
