"""Issue 23: an outside reference for the rough-surface hysteresis loop - boundary elements.

One Gaussian realisation of the paper's Table 1 surface (the spectrum fitted to its moments by
``rough_contact.surface.spectrum.fit_spectrum``, "fixed" amplitudes) is loaded by a rigid flat to
p_max, unloaded and reloaded, with plastic models of the boundary-element contact:

* saturated (always run): a perfectly plastic pressure cap, the "saturated" contact of
  ``rough_contact.micro.bem.NumpySolver``, with two caps: c_h H (the statistical model's fully
  plastic summit pressure) and K_Y Y = (2/pi) H (the peak Hertz pressure at first yield). The
  cap alone has no memory; the memory is added here by hand: at p_max every capped pixel
  interpenetrates the flat by o = z - u - d > 0; that material is taken as flattened away
  (z_pl = z - o, volume not conserved), and the unloading and reloading up to p_max are the
  ELASTIC contact of z_pl (no cap). Loading is the saturated contact of the original map
  (monotone loading: the capped set only grows, so the cap needs no memory there).
* elastic-plastic (``--ep``, slow): Tamaas' ``EPICSolver`` (Polonsky-Keer-Rey contact +
  ``DFSANECXXSolver`` on a ``volume_2d`` model with von Mises yield Y, no hardening), which
  carries the plastic strain field from step to step (memory built in). Its separation is
  d = mean over the contact pixels of z - u_z(surface) (the uniform q = 0 mode of the
  displacement, plastic part included, is zero in Tamaas' periodic model). Loads below
  0.1 p_max are skipped (contacts of one or two pixels, where Tamaas' PKR error is NaN).

The statistical model is evaluated for the moments of the same map (``moments_from_height_map``)
and the same material (H from psi = 1 of the Table 1 surface; Y from the paper's
K_Y Y = (2/pi) H), with the direct sums of ``rough_contact.micro.unloading``. Printed: the load
share on yielded contacts at p_max (statistical: summits beyond omega_c; elastic BEM: pixels above
K_Y Y), the loop (d, p, A/A0 per step), the residual closure (separation shift at p_max/100 and
p_max/10) and the first unloading over the loading stiffness at p_max (the same three-point
rule on both branches; the model's own k_u where it has one), model by model.
Writes docs/hysteresis_bem.csv and docs/figures/hysteresis_bem.png (``--out``, ``--fig``).

    PYTHONPATH=. python benchmarks/bench_hysteresis_bem.py --ep --ppw 4 --periods 1 --nz 10 \
        --depth 0.02      # the docs/unloading.md run: 90 x 90 x 10, ~12 min on 2 busy cores
    PYTHONPATH=. python benchmarks/bench_hysteresis_bem.py     # without Tamaas: ~2 min
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from _common import write_csv
from bench_hysteresis import E_STAR, S1, Loop, plastic_share

from rough_contact.micro.asperity import AsperityMaterial
from rough_contact.micro.bem import HalfSpace, NumpySolver, _post_process
from rough_contact.surface.moments import moments_from_height_map
from rough_contact.surface.spectrum import SpectrumShape, fit_spectrum

HERE = os.path.dirname(os.path.abspath(__file__))
DOCS = os.path.join(HERE, "..", "docs")
NU = 0.3
LOAD = (0.01, 0.03, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0)                       # loading steps / p_max
UNLOAD = (0.9, 0.75, 0.5, 0.25, 0.1, 0.03, 0.01)              # unloading steps / p_max
RELOAD = (0.25, 0.5, 0.75, 1.0, 1.15, 1.3)               # reloading steps / p_max


def surface_map(ppw, periods, seed):
    spec = fit_spectrum(S1, SpectrumShape(hurst=0.8, plateau=2.0))
    (nx, ny), (Lx, Ly) = spec.grid(ppw, periods)
    z = spec.realisation((nx, ny), (Lx, Ly), seed, "fixed")
    return z, (Lx, Ly)


def fd_stiffness(ds, ps, i):
    """-dp/dd at step i of a loading sequence by the three-point rule on unequal steps."""
    d0, d1, d2 = ds[i - 2], ds[i - 1], ds[i]
    p0, p1, p2 = ps[i - 2], ps[i - 1], ps[i]
    # derivative at d2 of the parabola through the three points
    return -(p0 * (d2 - d1) / ((d0 - d1) * (d0 - d2)) + p1 * (d2 - d0) / ((d1 - d0) * (d1 - d2))
             + p2 * (2 * d2 - d0 - d1) / ((d2 - d0) * (d2 - d1)))


def run_saturated(z, size, H_cap, p_max, tol=1e-9):
    K = HalfSpace(z.shape, size, E_STAR, NU)
    rows = []
    sat = NumpySolver(z, K, H_cap, tol=tol)
    p = None
    for f in LOAD:
        p = sat.solve(f * p_max, p)
        d, a, k, _, _ = _post_process(z, p, K, H_cap, False)
        rows.append(dict(branch="loading", f=f, d=d, p=float(p.mean()), a=a, k=k,
                         sat=float((p >= H_cap * (1 - 1e-12)).mean())))
    d_max = rows[-1]["d"]
    # memory by hand: the saturated pixels' overlap is flattened away
    overlap = np.maximum(z - K.normal(p) - d_max, 0.0)
    z_pl = z - overlap
    # elastic state of the flattened map at p_max: its first unloading stiffness
    d_chk, a_chk, k_un, _, _ = _post_process(z_pl, p, K, None, False)
    el = NumpySolver(z_pl, K, None, tol=tol)
    q = p
    for br, seq in (("unloading", UNLOAD), ("reloading", RELOAD)):
        for f in seq:
            if br == "reloading" and f > 1.0:
                q = sat.solve(f * p_max, q)
                d, a, k, _, _ = _post_process(z, q, K, H_cap, False)
            else:
                q = el.solve(f * p_max, q)
                d, a, k, _, _ = _post_process(z_pl, q, K, None, False)
            rows.append(dict(branch=br, f=f, d=d, p=float(q.mean()), a=a, k=k, sat=np.nan))
    info = {"d_check": d_chk - d_max, "k_unload": k_un, "removed_volume": float(overlap.mean())}
    return rows, info


def run_ep(z, size, Y, p_max, nz, depth, tol):
    import tamaas as tm
    from tamaas.nonlinear_solvers import DFSANECXXSolver

    tm.set_log_level(tm.LogLevel.error)
    um = 1e3                                    # Tamaas in um and MPa (relative tolerances)
    zu = np.ascontiguousarray(z * um)
    model = tm.ModelFactory.createModel(tm.model_type.volume_2d,
                                        [depth * um, size[0] * um, size[1] * um],
                                        [nz, z.shape[0], z.shape[1]])
    model.E = E_STAR * (1 - NU ** 2)            # contact modulus E/(1 - nu^2) = E* (rigid flat)
    model.nu = NU
    residual = tm.ModelFactory.createResidual(model, sigma_y=Y, hardening=0.0)
    epic = tm.EPICSolver(tm.PolonskyKeerRey(model, zu, 1e-12), DFSANECXXSolver(residual),
                         tol, relaxation=0.3)
    rows = []
    seq = [("loading", f) for f in LOAD] + [("unloading", f) for f in UNLOAD] \
        + [("reloading", f) for f in RELOAD]
    for br, f in seq:
        if f < 0.1:    # a contact of one or two pixels: Tamaas' PKR error is NaN there
            continue
        t = time.perf_counter()
        epic.solve(f * p_max)
        u = np.array(model.displacement)[0, :, :, 2]
        p = np.array(model.traction)[..., 2]
        c = p > 0
        r = (zu - u)[c]
        rows.append(dict(branch=br, f=f, d=float(r.mean()) / um, p=float(p.mean()),
                         a=float(c.mean()), k=np.nan, sat=np.nan,
                         spread=float(r.std()) / um, seconds=time.perf_counter() - t))
        print(f"  ep {br:9s} {f:5.2f} p_max: d = {rows[-1]['d'] / S1.rq:7.3f} sigma, "
              f"A/A0 = {rows[-1]['a']:.4f}, {rows[-1]['seconds']:.0f} s", flush=True)
    ep = np.array(model["plastic_strain"])
    dz = depth / (nz - 1)
    # mean plastic strain e_zz integrated over depth: a settlement Tamaas' q = 0 mode drops
    info = {"mean_plastic_ezz_integral_mm": float(np.trapz(ep[..., 2].mean(axis=(1, 2)), dx=dz))}
    return rows, info


def statistical(z, size, mat, p_max):
    nx, ny = z.shape
    m = moments_from_height_map(z, size[0] / nx, size[1] / ny, unit="mm")
    loop = Loop(m, mat)
    rows = []
    h_min = loop.h_load(p_max)
    for br, seq in (("loading", LOAD), ("unloading", UNLOAD), ("reloading", RELOAD)):
        for f in seq:
            if br == "loading" or f > 1.0:
                h = loop.h_load(f * p_max)
                p, k, a = (v[0] for v in loop.load(h))
            else:
                h = loop.h_unload(f * p_max, h_min)
                p, k, a = (v[0] for v in loop.unload(h, h_min))
            rows.append(dict(branch=br, f=f, d=h, p=p, a=a, k=k, sat=np.nan))
    k_un = loop.unload(h_min, h_min)[1][0]
    return rows, {"k_unload": k_un, "moments": m, "psi": m.plasticity_index(E_STAR, mat.H),
                  "yielded_share": plastic_share(loop, h_min)}


def closure(rows, f_ref=0.01):
    """Loading minus unloading separation at the same load f_ref p_max (both solved there)."""
    def pick(br):
        r = [r for r in rows if r["branch"] == br and abs(r["f"] - f_ref) < 1e-12]
        return r[0]["d"] if r else np.nan
    return pick("loading") - pick("unloading")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--psi", type=float, default=1.0, help="H from psi on the Table 1 surface")
    ap.add_argument("--p-max", type=float, default=100.0)
    ap.add_argument("--ppw", type=float, default=4.0, help="pixels per shortest wavelength")
    ap.add_argument("--periods", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ep", action="store_true", help="also run Tamaas' elastic-plastic solver")
    ap.add_argument("--nz", type=int, default=8, help="Tamaas volume layers")
    ap.add_argument("--depth", type=float, default=0.04, help="Tamaas volume depth [mm]")
    ap.add_argument("--ep-tol", type=float, default=1e-6)
    ap.add_argument("--out", default=os.path.join(DOCS, "hysteresis_bem.csv"))
    ap.add_argument("--fig", default=os.path.join(DOCS, "figures", "hysteresis_bem.png"))
    a = ap.parse_args(argv)
    mat = AsperityMaterial(E_star=E_STAR, psi=a.psi).resolve(S1)
    H = mat.H
    mat = AsperityMaterial(E_star=E_STAR, H=H)
    Y = mat.yield_pressure / mat.K_Y
    z, size = surface_map(a.ppw, a.periods, a.seed)
    print(f"map {z.shape[0]} x {z.shape[1]} px, {size[0] * 1e3:.1f} x {size[1] * 1e3:.1f} um, "
          f"sigma = {z.std() * 1e3:.4f} um; H = {H:.0f} MPa (psi = {a.psi:g} on Table 1), "
          f"cap ch H = {mat.ch * H:.0f} MPa, Y = {Y:.0f} MPa; p_max = {a.p_max:g} MPa")
    out = {}
    t = time.perf_counter()
    out["statistical"] = statistical(z, size, mat, a.p_max)
    m = out["statistical"][1]["moments"]
    print(f"statistical ({time.perf_counter() - t:.0f} s): map moments sigma = "
          f"{m.rq * 1e3:.4f} um, alpha = {m.alpha1:.2f}, {m.alpha2:.2f}, "
          f"psi = {out['statistical'][1]['psi']:.3f}")
    # how much load sits on yielded contacts at p_max: summits beyond omega_c (statistical) vs
    # pixels of the ELASTIC BEM solution above the first-yield peak pressure K_Y Y
    K = HalfSpace(z.shape, size, E_STAR, NU)
    pe = NumpySolver(z, K, None, tol=1e-9).solve(a.p_max)
    print(f"load share on yielded contacts at p_max: statistical (summits beyond omega_c) "
          f"{out['statistical'][1]['yielded_share']:.3f}, elastic BEM (pixels above K_Y Y) "
          f"{pe[pe > mat.yield_pressure].sum() / pe.sum():.3f}")
    # the cap: ch H (the fully plastic summit pressure of the statistical model: flow only
    # there) and K_Y Y = (2/pi) H (the peak Hertz pressure at first yield: flow from the
    # onset)
    for cname, cap in (("ch H", mat.ch * H), ("K_Y Y", mat.yield_pressure)):
        t = time.perf_counter()
        name = f"BEM cap {cname} + memory"
        out[name] = run_saturated(z, size, cap, a.p_max)
        print(f"saturated BEM, cap {cname} = {cap:.0f} MPa ({time.perf_counter() - t:.0f} s): "
              f"removed volume {out[name][1]['removed_volume'] * 1e6:.3g} nm (mean), "
              f"restart check d(p_max) {out[name][1]['d_check']:.2g} mm, load share at the cap "
              f"at p_max {out[name][0][len(LOAD) - 1]['sat'] * cap / a.p_max:.3f}")
    if a.ep:
        t = time.perf_counter()
        out["Tamaas elastic-plastic"] = run_ep(z, size, Y, a.p_max, a.nz, a.depth, a.ep_tol)
        print(f"Tamaas EP ({time.perf_counter() - t:.0f} s): "
              f"{json.dumps(out['Tamaas elastic-plastic'][1])}")
    sig = S1.rq
    print(f"\n{'model':24s} {'branch':9s} {'p/p_max':>7s} {'d/sigma':>8s} {'p [MPa]':>8s} "
          f"{'A/A0':>7s}")
    rows = []
    for name, (rs, _) in out.items():
        for r in rs:
            print(f"{name:24s} {r['branch']:9s} {r['f']:7.2f} {r['d'] / sig:8.3f} "
                  f"{r['p']:8.3f} {r['a']:7.4f}")
            rows.append({"model": name, "branch": r["branch"], "p/p_max": r["f"],
                         "d [um]": r["d"] * 1e3, "d/sigma": r["d"] / sig, "p [MPa]": r["p"],
                         "A/A0": r["a"], "k [MPa/mm]": r["k"]})
    print(f"\n{'model':24s} {'closure at p_max/100':>22s} {'closure at p_max/10':>22s} "
          f"{'k_u/k_l at p_max, FD':>21s} {'exact k_u':>10s}")
    summary = {}
    for name, (rs, info) in out.items():
        c, c10 = closure(rs), closure(rs, 0.1)
        ld = [r for r in rs if r["branch"] == "loading" and r["f"] >= 0.75]
        un = [r for r in rs if r["branch"] == "unloading" and r["f"] >= 0.75][::-1]
        # the same three-point rule on both branches: (0.75, 0.9, 1) p_max
        kl = fd_stiffness([r["d"] for r in ld], [r["p"] for r in ld], 2)
        ku = fd_stiffness([r["d"] for r in un + ld[-1:]], [r["p"] for r in un + ld[-1:]], 2)
        ke = info.get("k_unload", np.nan)
        summary[name] = (c if np.isfinite(c) else c10, ku / kl)
        print(f"{name:24s} {c / sig:10.3f} sigma {c * 1e3:7.4f} um {c10 / sig:10.3f} sigma "
              f"{c10 * 1e3:7.4f} um {ku / kl:21.3f} {ke / kl:10.3f}")
    write_csv(a.out, rows)
    figure(out, summary, a.fig, a.p_max)
    print(f"\nwrote {os.path.relpath(a.out)}, {os.path.relpath(a.fig)}")


def figure(out, summary, path, p_max):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, (name, (rs, _)) in enumerate(out.items()):
        for br, st in (("loading", "o-"), ("unloading", "s--"), ("reloading", "^:")):
            r = [q for q in rs if q["branch"] == br]
            d = np.array([q["d"] for q in r]) * 1e3
            p = np.array([q["p"] for q in r])
            c, kr = summary[name]
            lab = f"{name}, {br}" + (f" (closure {c * 1e3:.3f} um, k_u/k_l {kr:.2f})"
                                     if br == "loading" else "")
            for a in ax:
                a.plot(d, p, st, color=f"C{i}", ms=3, label=lab if a is ax[0] else None)
    ax[1].set_yscale("log")
    for a in ax:
        a.set_xlabel("separation d [um]")
        a.set_ylabel("nominal pressure p [MPa]")
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend(fontsize=6)
    ax[0].set_title(f"one Table 1 realisation, load to {p_max:g} MPa, unload, reload")
    ax[1].set_title("same, log p")
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
