"""The BEM solvers against closed forms: Westergaard's wavy surface and Hertz/Mindlin for one bump.

    bash run.sh python benchmarks/bench_bem_closed_forms.py        # ~20 s

Westergaard (z = D cos(2 pi x / L), plane strain, docs/bem.md): at p/p* = s,
d = D (1 - s + s ln s), k = p*/(D ln(1/s)), A/A0 = (2/pi) asin(sqrt(s)), p* = pi E* D / L.
Hertz (one paraboloid z = -r^2/(2R), contact radius a << period): a^3 = 3 P R/(4 E*),
p0 = 3 P/(2 pi a^2); Mindlin: kT/kN = 2(1 - nu)/(2 - nu) in full stick.
Prints the relative errors of the solved states (per backend, per resolution) and of the
tabulated NormalLaw between its knots. Units: mm, MPa.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from rough_contact.micro import bem
from rough_contact.micro.bem import HalfSpace, NumpySolver, _post_process

E_STAR, NU, AMP, LAM = 1000.0, 0.3, 0.002, 1.0


def westergaard(s):
    pstar = math.pi * E_STAR * AMP / LAM
    return AMP * (1 - s + s * np.log(s)), pstar / (AMP * np.log(1 / s)), \
        2 / np.pi * np.arcsin(np.sqrt(s)), pstar


def wavy(n):
    x = np.arange(n) / n * LAM
    return np.ascontiguousarray(np.repeat((AMP * np.cos(2 * np.pi * x / LAM))[:, None], 8, 1))


def main():
    s = np.array([0.02, 0.05, 0.1, 0.2, 0.4, 0.7])
    d_ex, k_ex, a_ex, pstar = westergaard(s)
    print("Westergaard wavy surface: relative error of the solved states at p/p* = "
          + ", ".join(f"{v:g}" for v in s))
    print(f"{'px/period':>9s} {'backend':32s} {'d':>9s} {'k':>9s} {'A/A0':>9s} {'time s':>7s}")
    for n in (256, 1024, 4096):
        for backend in bem.available_backends():
            t0 = time.perf_counter()
            c = bem.bem_curves(wavy(n), LAM / n, E_star=E_STAR, nu=NU, pressures=s * pstar,
                               backend=backend, tangential=False, cache=False)
            dt = time.perf_counter() - t0
            err = [np.max(np.abs(v[0] / ref - 1)) for v, ref in
                   ((c.separation, d_ex), (c.stiffness, k_ex), (c.area_fraction, a_ex))]
            print(f"{n:9d} {c.backend:32s} {err[0]:9.1e} {err[1]:9.1e} {err[2]:9.1e} {dt:7.2f}")
    print("\nWestergaard: the tabulated NormalLaw (24 pressures, p/p* = 0.02-0.7, Hermite with the "
          "BEM stiffness) between its knots, max relative error over p/p* in each range")
    law = bem.bem_normal_law(wavy(1024), LAM / 1024, E_star=E_STAR, nu=NU,
                             pressures=np.geomspace(0.02, 0.7, 24) * pstar, backend="numpy",
                             tangential=False, cache=False)
    print(f"{'p/p* range':>12s} {'p(h)':>9s} {'k(h)':>9s} {'A/A0(h)':>9s}")
    for lo, hi in ((0.025, 0.05), (0.05, 0.2), (0.2, 0.5), (0.5, 0.65)):
        ss = np.geomspace(lo, hi, 200)
        d, k, a, _ = westergaard(ss)
        pl, kl, al = law.normal.evaluate(d)
        print(f"{lo:5.3f}-{hi:5.3f} {np.max(np.abs(pl / (ss * pstar) - 1)):9.1e} "
              f"{np.max(np.abs(kl / k - 1)):9.1e} {np.max(np.abs(al / a - 1)):9.1e}")

    print("\nHertz bump (R = 1 mm, period 1 mm) and Mindlin's stick ratio, numpy backend")
    print(f"{'px/period':>9s} {'a/period':>8s} {'a px':>5s} {'p0':>9s} {'a':>9s} {'kTx/kN':>9s} "
          f"{'kTy/kN':>9s}  (relative errors)")
    for n in (128, 256, 512):
        x = (np.arange(n) - n // 2) / n
        X, Y = np.meshgrid(x, x, indexing="ij")
        z = -(X ** 2 + Y ** 2) / 2.0
        z = np.ascontiguousarray(z - z.mean())
        K = HalfSpace((n, n), (1.0, 1.0), E_STAR, NU)
        S = NumpySolver(z, K, None, 1e-10)
        for a_h in (0.04, 0.08):
            P = 4 * E_STAR * a_h ** 3 / 3.0
            p = S.solve(P)
            _, a, k, kx, ky = _post_process(z, p, K, None, True)
            m = bem.mindlin_ratio(NU)
            print(f"{n:9d} {a_h:8.2f} {a_h * n:5.0f} "
                  f"{p.max() / (3 * P / (2 * np.pi * a_h ** 2)) - 1:9.1e} "
                  f"{math.sqrt(a / math.pi) / a_h - 1:9.1e} {kx / k / m - 1:9.1e} "
                  f"{ky / k / m - 1:9.1e}")


if __name__ == "__main__":
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bem.HeightMapWarning)
        main()
