"""The memory table on the punch's asperity data, whose unloading branch lies above the loading
one (docs/unloading.md, "Which asperity data"): how many table points the build finds above the
loading branch, and that the law as evaluated stays below it with D >= 0 and k >= 0.

    PYTHONPATH=. python benchmarks/bench_unloading_cap.py [--rtol 1e-3] [--points 4000]

Prints one table. Units: mm, MPa.
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from rough_contact.interface.history import HistoryNormalLaw, UnloadingAboveLoadingWarning
from rough_contact.interface.normal import NormalLaw
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.scenes.flat_punch import E, MOMENTS_UM, NU, PLASTIC, effective_modulus
from rough_contact.surface import SpectralMoments


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--points", type=int, default=4000, help="random (h, h_min) checks")
    args = ap.parse_args(argv)
    surface = SpectralMoments(**MOMENTS_UM, unit="um")
    E_star = effective_modulus(E, NU, E, NU)
    rows = []
    for name, mat in (("punch (Y = 2070, K_Y = 1.62)",
                       AsperityMaterial(E_star=E_star, nu=NU, **PLASTIC)),
                      ("default yield, psi = 0.35", AsperityMaterial(E_star=E_star, nu=NU,
                                                                    psi=0.35))):
        loading = NormalLaw.elasto_plastic(surface, mat.resolve(surface), args.rtol)
        t = time.process_time()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            law = HistoryNormalLaw.elasto_plastic(surface, mat, rtol=args.rtol, loading=loading)
        cpu = time.process_time() - t
        warned = any(issubclass(w.category, UnloadingAboveLoadingWarning) for w in caught)
        rng = np.random.default_rng(0)
        hm = law.h_min + rng.random(args.points) * (law.h_table_end - law.h_min)
        h = hm + rng.random(args.points) * 3 * surface.rq
        pu, ku, _ = law.evaluate_history(h, hm)
        pl = law.loading.evaluate(h)[0]
        ok = pl > 1e-12 * pl.max()
        rows.append((name, cpu, law.info["capped_points"], law.info["model_points"], warned,
                     float(np.max(pu[ok] / pl[ok])), float(law.normal_dissipation(hm).min()),
                     float(ku.min())))
    print(f"{'asperity data':<30} {'build CPU [s]':>13} {'above/points':>13} {'warns':>6} "
          f"{'max p_u/p_load':>15} {'min D':>9} {'min k':>9}")
    for r in rows:
        print(f"{r[0]:<30} {r[1]:13.1f} {f'{r[2]}/{r[3]}':>13} {str(r[4]):>6} {r[5]:15.6f} "
              f"{r[6]:9.2g} {r[7]:9.2g}")


if __name__ == "__main__":
    main()
