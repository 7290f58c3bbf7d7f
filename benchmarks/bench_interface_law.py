"""Throughput of the composed interface law (normal + Mindlin tangential + friction) at points.

Prints a table: points/s of ``InterfaceLaw.evaluate`` for all-stick, all-slip, all-open and
mixed states (single core, best of --repeat), and the cost split between the normal law
(``NormalLaw.evaluate(h, curvature=True)``) and the friction return map.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_interface_law.py [--n 200000]

Normal law: McCool's GW equivalent of the paper's Fig. 18 surface (m00 = 0.625 um^2, m20 = 8e-5,
m02 = 8e-4, m40 = 1.04e-6, m04 = 1.04e-4 um^-2), E* = 1.0667e5 MPa, seated at 1 MPa.
Targets: >= 1e6 points/s all-slip, >= 5e6 points/s all-stick or all-open.

Allocator note: with glibc's default (dynamic) mmap/trim thresholds, the multi-MB temporaries of
each call are returned to the OS and page-faulted again on the next call; about half the CPU
time is then system time. Fixing the thresholds removes it (about 2x on stick/open):

    MALLOC_MMAP_THRESHOLD_=134217728 MALLOC_TRIM_THRESHOLD_=536870912 \
        .venv/bin/python benchmarks/bench_interface_law.py
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rough_contact.interface.friction import (FrictionInput, IsotropicSlipHardening,
                                             OrthotropicSlipHardening)
from rough_contact.interface.law import InterfaceLaw
from rough_contact.interface.normal import NormalLaw
from rough_contact.interface.state import InterfaceState
from rough_contact.interface.tangential import TangentialStiffness
from rough_contact.surface import SpectralMoments


def best_time(fn, repeat):
    """Best CPU time (process_time) of `repeat` calls [s]: per-core cost on a loaded host."""
    fn()  # warm-up
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def jumps(law, n, regime, rng):
    """Jumps (n, 3) and a committed state for one regime."""
    st = InterfaceState(rng.normal(size=(n, 2)) * 1e-4, rng.uniform(0, 1e-4, (n, 2)),
                        rng.uniform(0, 1e-4, n))
    g = rng.uniform(-2e-4, 2e-4, n)  # around the seating separation (contact)
    _, k, _ = law.normal.evaluate(law.h0 + g)
    kt_min = min(law.tangential.kt_over_kn) * k
    # slip needed to reach the friction limit ~ mu p / kT
    p, _, _ = law.normal.evaluate(law.h0 + g)
    s_lim = 0.5 * p / np.maximum(kt_min, 1e-300)
    ang = rng.uniform(0, 2 * np.pi, n)
    d = np.column_stack([np.cos(ang), np.sin(ang)])
    if regime == "stick":
        s = st.plastic_slip + 1e-3 * s_lim[:, None] * d
    elif regime == "slip":
        s = st.plastic_slip + 30.0 * s_lim[:, None] * d
    elif regime == "open":
        g = np.full(n, 2.0 * law.normal.h_max)
        s = st.plastic_slip + 1e-4 * d
    else:  # mixed: one third each
        parts = [jumps(law, n // 3 + 1, r, rng) for r in ("stick", "slip", "open")]
        jj = np.concatenate([p_[0] for p_ in parts])[:n]
        cat = [np.concatenate([getattr(p_[1], a) for p_ in parts])[:n]
               for a in ("plastic_slip", "accumulated_slip", "slip_path")]
        return jj, InterfaceState(*cat)
    return np.column_stack([g, s]), st


def main(n=200_000, repeat=5):
    surf = SpectralMoments(0.625, 8e-5, 8e-4, 1.04e-6, 1.04e-4)  # paper, Fig. 18 (um units)
    normal = NormalLaw.greenwood_williamson(surf, 2.0e5 / (2 * (1 - 0.25**2)))
    frictions = {
        "orthotropic": OrthotropicSlipHardening((0.5, 0.3), (0.5, 0.6), (275.0, 275.0),
                                                potential_axes=(0.125, 0.2)),
        "isotropic": IsotropicSlipHardening(0.5, 0.5, 275.0),
    }
    rng = np.random.default_rng(0)
    # warm-up (imports, first-touch of the normal-law tables)
    law = InterfaceLaw(normal, TangentialStiffness((0.7, 1.0)), frictions["orthotropic"])
    law = law.with_seating(1.0)
    for regime in ("stick", "slip", "open", "mixed"):
        law.evaluate(*jumps(law, n, regime, rng))
    print(f"n = {n} points per call, best CPU time of {repeat}; throughput in 1e6 points per "
          "CPU-second (one core)\n")
    print(f"{'friction':12s} {'kTx/kTy':8s} {'regime':7s} {'law':>8s} {'normal':>8s} "
          f"{'friction':>9s} {'share N/F/rest':>16s} {'slip%':>6s} {'its':>4s}")
    for fname, fr in frictions.items():
        for ts in (TangentialStiffness((0.7, 1.0)), TangentialStiffness((0.7, 0.7))):
            law = InterfaceLaw(normal, ts, fr).with_seating(1.0)
            for regime in ("stick", "slip", "open", "mixed"):
                jump, st = jumps(law, n, regime, rng)
                t_law = best_time(lambda: law.evaluate(jump, st), repeat)
                h = law.h0 + jump[:, 0]
                t_norm = best_time(lambda: normal.evaluate(h, curvature=True), repeat)
                p, k, a, dk = normal.evaluate(h, curvature=True)
                cx, cy = ts.kt_over_kn
                m = np.flatnonzero(p > 0)
                sp, kap = st.plastic_slip[m], st.accumulated_slip[m]
                cols = FrictionInput(jump[m, 1] - sp[:, 0], jump[m, 2] - sp[:, 1], cx * k[m],
                                     cy * k[m], cx * dk[m], cy * dk[m], p[m], k[m],
                                     kap[:, 0].copy(), kap[:, 1].copy(), st.slip_path[m])
                out_t, out_D = np.empty((m.size, 2)), np.empty((m.size, 2, 3))
                if m.size:  # the friction kernel as the law calls it (no value checks)
                    t_fr = best_time(lambda: fr.evaluate(cols, out_t, out_D), repeat)
                    res = fr.evaluate(cols, out_t, out_D)
                    slip = 100.0 * res.slip_index.size / n
                    its = res.iterations
                else:
                    t_fr, slip, its = 0.0, 0.0, 0
                rest = max(t_law - t_norm - t_fr, 0.0)
                share = f"{t_norm / t_law:4.0%}/{t_fr / t_law:4.0%}/{rest / t_law:4.0%}"
                print(f"{fname:12s} {ts.kt_over_kn[0]:.1f}/{ts.kt_over_kn[1]:.1f}  {regime:7s} "
                      f"{n / t_law / 1e6:8.2f} {n / t_norm / 1e6:8.2f} "
                      f"{(n / t_fr / 1e6 if t_fr else np.inf):9.2f} {share:>16s} {slip:6.1f} {its:4d}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, allow_abbrev=False,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=200_000, help="points per call")
    ap.add_argument("--repeat", type=int, default=5, help="timing repeats (best is reported)")
    a = ap.parse_args()
    main(a.n, a.repeat)
