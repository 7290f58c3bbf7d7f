"""Issue 23: load-separation hysteresis loops of a rough surface with asperity-plasticity memory.

The paper's Table 1 surface (m00 = 0.0625 um^2, ..., E* = 1.14e5 MPa) at plasticity indices
psi = 0.5, 1, 2 (the hardness H set from psi, eq (69)), computed with the DIRECT population sums
of ``rough_contact.micro.unloading`` (not the tabulated ``HistoryNormalLaw``):

* loading (virgin, h_min := h): ``population.elasto_plastic`` (the paper's loading law);
* unloading and reloading at fixed h_min (the smallest separation reached):
  ``unloading.population_unloading``; beyond h_min the loading branch again.

The cycle: load to p_max, unload to p_max/1000, reload to 1.3 p_max. Printed tables:

1. per psi: h_min, residual closure (loading minus unloading separation at the same small
   reference pressure p_ref = p_max/100 and p_max/1000, in sigma and um), the hysteresis energy of
   the cycle per nominal area D = int (p_load - p_unload) dh [N/mm = mJ/mm^2] and its share of
   the loading work, and the share of the load at p_max carried by summits beyond omega_c;
2. the unloading stiffness at h_min = h_load(p) against the loading stiffness at the same load p
   (k_unload/k_load at p = 1 ... 300 MPa).

Writes docs/hysteresis_loops.csv (the loop curves), docs/hysteresis_stiffness.csv (table 2) and
docs/figures/hysteresis_loops.png. Run (~8 min on 2 loaded cores, mostly root finding on the
loading sums):

    PYTHONPATH=. python benchmarks/bench_hysteresis.py
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from scipy.optimize import brentq

from _common import write_csv

from rough_contact.micro import population as pop
from rough_contact.micro import unloading as U
from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.surface import SpectralMoments

E_STAR = 1.14e5                                                                  # MPa, Table 1
S1 = SpectralMoments(m00=0.0625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)  # Table 1
HERE = os.path.dirname(os.path.abspath(__file__))
DOCS = os.path.join(HERE, "..", "docs")


class Loop:
    """Loading / unloading sums of one surface and material (direct population sums)."""

    def __init__(self, surface, material, n_quad=16, n_t=24):
        self.s = surface
        self.mat = material.resolve(surface)
        self.nq, self.nt = n_quad, n_t
        self.sig = surface.rq

    def load(self, h):
        r = pop.elasto_plastic(self.s, self.mat, np.atleast_1d(np.asarray(h, float)))
        return r.pressure, r.stiffness, r.area_fraction

    def unload(self, h, h_min):
        h = np.atleast_1d(np.asarray(h, float))
        if np.any(h < h_min):
            raise ValueError(f"h = {h.min():g} mm < h_min = {h_min:g} mm: not on the unloading "
                             "branch (valid range [h_min, inf))")
        return U.population_unloading(self.s, self.mat, h, h_min, self.nq, self.nt)

    def h_load(self, p):
        """Separation [mm] at which the loading branch carries p [MPa]."""
        f = lambda h: np.log(self.load(h)[0][0] / p)           # noqa: E731
        return brentq(f, -6 * self.sig, 12 * self.sig, xtol=1e-7 * self.sig)

    def h_unload(self, p, h_min):
        """Separation [mm] >= h_min at which the unloading branch from h_min carries p [MPa]."""
        def f(h):
            with np.errstate(divide="ignore"):      # p = 0 far out: log -> -inf, still a sign
                return np.log(self.unload(h, h_min)[0][0] / p)
        if f(h_min) <= 0.0:        # p = p(h_min) to the sums' accuracy (1e-6): the reversal
            return h_min
        return brentq(f, h_min, h_min + 12 * self.sig, xtol=1e-7 * self.sig)

    def dissipation(self, h_min, u_end, n=48):
        """D = int_{h_min}^{h_min+u_end} (p_load - p_unload) dh [MPa mm = N/mm] (Gauss-Legendre
        on 4 panels graded towards h_min; beyond u_end both branches are below p_max/1e3)."""
        edges = h_min + u_end * np.array([0.0, 0.05, 0.2, 0.5, 1.0])
        x, w = np.polynomial.legendre.leggauss(n)
        tot = 0.0
        for a, b in zip(edges[:-1], edges[1:]):
            h = 0.5 * (a + b) + 0.5 * (b - a) * x
            tot += 0.5 * (b - a) * np.dot(w, self.load(h)[0] - self.unload(h, h_min)[0])
        return tot


def plastic_share(loop, h):
    """Share of the loading pressure at h carried by summits beyond omega_c (ZMC + plastic)."""
    r = pop.elasto_plastic(loop.s, loop.mat, np.atleast_1d(h))
    return float((r.pressure_transition[0] + r.pressure_plastic[0]) / r.pressure[0])


def run_case(psi, p_max, n_curve=40):
    loop = Loop(S1, AsperityMaterial(E_star=E_STAR, psi=psi))
    sig = loop.sig
    t0 = time.perf_counter()
    h_min = loop.h_load(p_max)
    h_end = loop.h_unload(1e-3 * p_max, h_min)
    h_top = loop.h_load(1.3 * p_max)
    h_lstart = loop.h_load(1e-3 * p_max)
    # curves (graded towards the low-h end where the pressure changes fastest)
    s = np.linspace(0.0, 1.0, n_curve) ** 1.5
    hl = h_min + (h_lstart - h_min) * s
    hu = h_min + (h_end - h_min) * s
    hr = h_top + (h_min - h_top) * s[::-1]
    L, Uu, R = loop.load(hl), loop.unload(hu, h_min), loop.load(hr)
    rows = []
    for br, hh, vals in (("loading", hl[::-1], [v[::-1] for v in L]),
                         ("unloading", hu, Uu), ("reloading", hu[::-1], [v[::-1] for v in Uu]),
                         ("reloading beyond h_min", hr[::-1], [v[::-1] for v in R])):
        for h, p, k, a in zip(hh, *vals):
            rows.append({"psi": psi, "branch": br, "h/sigma": h / sig, "h [um]": h * 1e3,
                         "p [MPa]": p, "k [MPa/mm]": k, "A/A0": a})
    out = {"psi": psi, "H": loop.mat.H, "h_min": h_min, "rows": rows,
           "plastic_share": plastic_share(loop, h_min)}
    for f in (1e-2, 1e-3):
        pr = f * p_max
        out[f"closure_{f:g}"] = loop.h_load(pr) - loop.h_unload(pr, h_min)
    out["D"] = loop.dissipation(h_min, h_end - h_min)
    out["W_load"] = _work(loop.load, h_min, h_lstart)          # loading work to h_min
    out["seconds"] = time.perf_counter() - t0
    return loop, out


def _work(fn, a, b, n=64):
    x, w = np.polynomial.legendre.leggauss(n)
    edges = a + (b - a) * np.array([0.0, 0.05, 0.2, 0.5, 1.0])
    return sum(0.5 * (hi - lo) * np.dot(w, fn(0.5 * (lo + hi) + 0.5 * (hi - lo) * x)[0])
               for lo, hi in zip(edges[:-1], edges[1:]))


def stiffness_ratios(loop, pressures):
    rows = []
    for p in pressures:
        h = loop.h_load(p)
        _, kl, _ = loop.load(h)
        _, ku, _ = loop.unload(h, h)           # unloading branch from h_min = h, at h
        rows.append({"psi": loop.mat.psi if loop.mat.psi else np.nan, "p [MPa]": p,
                     "h/sigma": h / loop.sig, "k_load [MPa/mm]": kl[0],
                     "k_unload [MPa/mm]": ku[0], "ratio": ku[0] / kl[0]})
    return rows


def figure(cases, ratios, path, p_max):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.4))
    for i, c in enumerate(cases):
        col = f"C{i}"
        for br, st in (("loading", "-"), ("unloading", "--"), ("reloading beyond h_min", "-")):
            r = [q for q in c["rows"] if q["branch"] == br]
            h = np.array([q["h [um]"] for q in r])
            p = np.array([q["p [MPa]"] for q in r])
            lab = f"psi = {c['psi']:g}, {br}" if br != "reloading beyond h_min" else None
            ax[0].plot(h, p, st, color=col, label=lab)
            ax[1].semilogy(h, p, st, color=col, label=lab)
        ax[0].plot(c["h_min"] * 1e3, p_max, "o", color=col, ms=4)
    ax[0].set_xlim(None, None)
    for a in ax[:2]:
        a.set_xlabel("separation h [um] (mean plane of the rough surface to the flat)")
        a.set_ylabel("nominal pressure p [MPa]")
        a.grid(True, which="both", alpha=0.3)
    ax[0].set_title(f"load to {p_max:g} MPa, unload, reload to {1.3 * p_max:g} MPa")
    ax[1].set_title("same, log p: the residual closure is the horizontal gap")
    ax[0].legend(fontsize=7)
    for i, (psi, rows) in enumerate(ratios.items()):
        ax[2].semilogx([r["p [MPa]"] for r in rows], [r["ratio"] for r in rows], "o-",
                       color=f"C{i}", label=f"psi = {psi:g}")
    ax[2].axhline(1.0, color="k", lw=0.8)
    ax[2].set_xlabel("nominal pressure p [MPa]")
    ax[2].set_ylabel("k_unload(h_min = h_load(p)) / k_load(p)")
    ax[2].set_title("first unloading stiffness / loading stiffness")
    ax[2].grid(True, which="both", alpha=0.3)
    ax[2].legend(fontsize=8)
    fig.suptitle("Table 1 surface (sigma = %.3g um, E* = %.3g MPa): statistical model with "
                 "asperity-plasticity memory (direct sums)" % (S1.rq * 1e3, E_STAR), fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--psi", type=float, nargs="+", default=[0.5, 1.0, 2.0])
    ap.add_argument("--p-max", type=float, default=100.0, help="largest load of the cycle [MPa]")
    ap.add_argument("--pressures", type=float, nargs="+",
                    default=[1.0, 3.0, 10.0, 30.0, 100.0, 300.0],
                    help="loads of the stiffness-ratio table [MPa]")
    ap.add_argument("--no-write", action="store_true", help="print only (no csv, no figure)")
    a = ap.parse_args(argv)
    sig_um = S1.rq * 1e3
    print(f"Table 1 surface, sigma = {sig_um:.4g} um, E* = {E_STAR:g} MPa; cycle 0 -> "
          f"{a.p_max:g} -> {a.p_max / 1e3:g} -> {1.3 * a.p_max:g} MPa (direct sums)\n")
    cases, ratios = [], {}
    for psi in a.psi:
        loop, c = run_case(psi, a.p_max)
        cases.append(c)
        ratios[psi] = stiffness_ratios(loop, a.pressures)
    print("1. residual closure after unloading from p_max (loading minus unloading separation "
          "at the same p_ref)")
    print(f"{'psi':>5s} {'H [MPa]':>8s} {'h_min/sig':>9s} {'beyond w_c':>10s} "
          f"{'p_ref=p_max/100':>22s} {'p_ref=p_max/1000':>22s} {'D [N/mm]':>9s} {'D/W_load':>8s}"
          f" {'s':>5s}")
    print(f"{'':>5s} {'':>8s} {'':>9s} {'(load %)':>10s} {'[sigma]':>10s} {'[um]':>11s} "
          f"{'[sigma]':>10s} {'[um]':>11s}")
    for c in cases:
        print(f"{c['psi']:5.2f} {c['H']:8.0f} {c['h_min'] / S1.rq:9.3f} "
              f"{100 * c['plastic_share']:10.1f} "
              f"{c['closure_0.01'] / S1.rq:10.4f} {c['closure_0.01'] * 1e3:11.5f} "
              f"{c['closure_0.001'] / S1.rq:10.4f} {c['closure_0.001'] * 1e3:11.5f} "
              f"{c['D']:9.3g} {c['D'] / c['W_load']:8.3f} {c['seconds']:5.1f}")
    print("\n2. unloading stiffness at h_min = h_load(p) / loading stiffness at p")
    print(f"{'p [MPa]':>8s} " + " ".join(f"{'psi=%g' % psi:>9s}" for psi in a.psi))
    for i, p in enumerate(a.pressures):
        print(f"{p:8g} " + " ".join(f"{ratios[psi][i]['ratio']:9.4f}" for psi in a.psi))
    if a.no_write:
        return
    write_csv(os.path.join(DOCS, "hysteresis_loops.csv"), [r for c in cases for r in c["rows"]])
    write_csv(os.path.join(DOCS, "hysteresis_stiffness.csv"),
              [dict(r, psi=psi) for psi, rows in ratios.items() for r in rows])
    figure(cases, ratios, os.path.join(DOCS, "figures", "hysteresis_loops.png"), a.p_max)
    print("\nwrote docs/hysteresis_loops.csv, docs/hysteresis_stiffness.csv, "
          "docs/figures/hysteresis_loops.png")


if __name__ == "__main__":
    main()
