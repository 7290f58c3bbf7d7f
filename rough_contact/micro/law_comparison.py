"""Statistical vs boundary-element normal law of one rough surface: laws, tables, ratios, plots.

Library functions: :func:`statistical_laws`, :func:`bem_laws`, the tables and ratios,
:func:`compare` (all of it for one source), and the sources :func:`source_from_example`,
:func:`source_from_moments`, :func:`source_from_height_map`. The command line, and the
description of what is compared, is ``demos/compare_laws.py``.

Units: mm, N, MPa inside; separations printed as h/sigma, sigma = sqrt(m00).
"""
from __future__ import annotations

import csv
import math
import os
import time
import warnings

import numpy as np

from . import bem
from .asperity import AsperityMaterial
from ..surface import SpectralMoments, SpectrumShape, example_surfaces, moments_from_height_map

E_STAR = 1.067e5     # MPa, two steel bodies E = 200 GPa, nu = 0.25 (the paper's punch)
NU = 0.25
STAT = ("statistical elastic", "statistical elasto-plastic", "GW (McCool)")
# what a structural analysis sees after seating (stiffness and area at a given load), and the
# absolute level of the law (pressure at a given separation)
AGREE = ("k_at_p", "a_at_p", "p_at_h")


# ## Building the laws
def statistical_laws(moments: SpectralMoments, E_star: float, material: AsperityMaterial,
                     plastic: bool = True):
    """The package's statistical laws of the surface: dict name -> NormalLaw."""
    # the laws are the interface layer's NormalLaw (the layer above micro/): imported here so
    # that importing rough_contact.micro never loads rough_contact.interface
    from rough_contact.interface.normal import NormalLaw

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # isotropic surfaces: reported in the text
        out = {STAT[0]: NormalLaw.elastic(moments, E_star),
               STAT[2]: NormalLaw.greenwood_williamson(moments, E_star)}
        if plastic:
            out[STAT[1]] = NormalLaw.elasto_plastic(moments, material)
    return out


def bem_laws(source: dict, E_star: float, nu: float, cap: float | None, *, realisations: int,
             ppw: float, periods: int, n_pressures: int, area_range, backend, seed,
             tangential=True, amplitudes="fixed", area_extrapolation=None, workers=1,
             tangential_realisations=4):
    """The BEM laws: dict name -> BEMLaw ("BEM elastic", and "BEM saturated" if cap).

    ``amplitudes``, ``area_extrapolation``, ``workers``, ``tangential_realisations``: see
    :func:`rough_contact.micro.bem.bem_law_from_spectrum` (spectral sources; a height map is
    solved once, with ``area_extrapolation`` False unless given)."""
    out = {}
    for name, H in (("BEM elastic", None), ("BEM saturated", cap)):
        if name == "BEM saturated" and cap is None:
            continue
        kw = dict(E_star=E_star, nu=nu, hardness=H, n_pressures=n_pressures,
                  area_range=area_range, backend=backend if H is None else None,
                  tangential=tangential and H is None)
        if source["kind"] == "map":
            out[name] = bem.bem_normal_law(source["z"], source["dx"], source["dy"],
                                           boundary=source["boundary"],
                                           area_extrapolation=bool(area_extrapolation), **kw)
            continue
        kw.update(n_realisations=realisations, pixels_per_wavelength=ppw, periods=periods,
                  seed=seed, amplitudes=amplitudes, area_extrapolation=area_extrapolation,
                  workers=workers, tangential_realisations=tangential_realisations)
        if source["kind"] == "spectrum":
            out[name] = bem.bem_law_from_spectrum(source["spectrum"], **kw)
        else:
            out[name] = bem.bem_law_from_moments(source["moments"], shape=source["shape"],
                                                 **kw)
    return out


# ## Tables
def table_vs_separation(laws: dict, sigma: float, s_grid):
    """Rows h/sigma, then p, A/A0, k of every law at h = s sigma."""
    rows = []
    for s in s_grid:
        row = {"h/sigma": s}
        for name, law in laws.items():
            p, k, a = law.evaluate(np.array([s * sigma]))
            row[f"{name}: p [MPa]"] = float(p[0])
            row[f"{name}: A/A0"] = float(a[0])
            row[f"{name}: k [MPa/mm]"] = float(k[0])
        rows.append(row)
    return rows


def table_vs_load(laws: dict, sigma: float, pressures):
    """Rows p, then h/sigma, A/A0, k of every law at that load."""
    rows = []
    for pm in pressures:
        row = {"p [MPa]": float(pm)}
        for name, law in laws.items():
            h = law.separation_for_pressure(np.array([pm]))
            _, k, a = law.evaluate(h)
            row[f"{name}: h/sigma"] = float(h[0] / sigma)
            row[f"{name}: A/A0"] = float(a[0])
            row[f"{name}: k [MPa/mm]"] = float(k[0])
        rows.append(row)
    return rows


def ratio_rows(stat: dict, reference: "bem.BEMLaw", pressures, sigma):
    """Ratios statistical/BEM over the load range (rough_contact.micro.bem.law_ratios).

    ``se p/A/k``: relative standard errors of the BEM mean (realisation std / sqrt(n)) at the
    BEM separation of each load - the uncertainty of every ratio from the finite sample.
    """
    rows = []
    n = reference.curves.n_realisations
    for name, law in stat.items():
        r = bem.law_ratios(law, reference.normal, pressures)
        below = law.below_validity(law.separation_for_pressure(pressures))
        se = [np.interp(r["h"], reference.separation, std / val) / math.sqrt(n)
              for std, val in ((reference.pressure_std, reference.pressure),
                               (reference.area_std, reference.area_fraction),
                               (reference.stiffness_std, reference.stiffness))]
        for i, pm in enumerate(pressures):
            rows.append({"law": name, "p [MPa]": float(pm), "h/sigma (BEM)": r["h"][i] / sigma,
                         "stat valid": "no" if below[i] else "yes",
                         "se p": float(se[0][i]), "se A": float(se[1][i]),
                         "se k": float(se[2][i]),
                         "p ratio at equal h": r["p_at_h"][i], "A ratio at equal h": r["a_at_h"][i],
                         "k ratio at equal h": r["k_at_h"][i], "A ratio at equal p": r["a_at_p"][i],
                         "k ratio at equal p": r["k_at_p"][i],
                         "dh/sigma at equal p": r["dh_at_p"][i] / sigma})
    return rows


def print_rows(rows, title, keys=None, fmt="{:10.4g}"):
    print(f"\n{title}")
    keys = keys or list(rows[0])
    short = [k.replace("statistical ", "stat ").replace(" [MPa/mm]", "") for k in keys]
    print(" | ".join(f"{k:>12.12s}" for k in short))
    for r in rows:
        print(" | ".join(f"{r[k]:12.4g}" if isinstance(r[k], float) else f"{str(r[k]):>12.12s}"
                         for k in keys))


def write_csv(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


# ## Figure
def plot(laws: dict, bands: dict, sigma: float, pressures, path, title):
    """p, A/A0, k vs h/sigma (top) and A/A0, k, h/sigma vs load (bottom)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    styles = {STAT[0]: "C0-", STAT[1]: "C1--", STAT[2]: "C2:", "BEM elastic": "k-",
              "BEM saturated": "C3-."}
    fig, ax = plt.subplots(2, 3, figsize=(13, 7.5))
    ref = laws["BEM elastic"]
    h = np.linspace(ref.h_min, ref.h_table_end, 300)     # where the BEM law is data
    for name, law in laws.items():
        p, k, a = law.evaluate(h)
        off = law.below_validity(h)      # a statistical law's stiff continuation: not shown
        p, k, a = (np.where(off, np.nan, v) for v in (p, k, a))
        st = styles.get(name, "-")
        ax[0, 0].semilogy(h / sigma, p, st, label=name)
        ax[0, 1].semilogy(h / sigma, a, st)
        ax[0, 2].semilogy(h / sigma, k, st)
        hp = law.separation_for_pressure(pressures)
        _, kp, ap = law.evaluate(hp)
        ax[1, 0].loglog(pressures, ap, st, label=name)
        ax[1, 1].loglog(pressures, kp, st)
        ax[1, 2].semilogx(pressures, hp / sigma, st)
    for name, b in bands.items():   # realisation scatter of the BEM law (+- 1 std)
        s = b.separation / sigma
        ax[0, 0].fill_between(s, b.pressure - b.pressure_std, b.pressure + b.pressure_std,
                              color="0.7", alpha=0.5, lw=0)
        ax[0, 1].fill_between(s, b.area_fraction - b.area_std, b.area_fraction + b.area_std,
                              color="0.7", alpha=0.5, lw=0)
        ax[0, 2].fill_between(s, b.stiffness - b.stiffness_std, b.stiffness + b.stiffness_std,
                              color="0.7", alpha=0.5, lw=0)
    for a_, lab in zip(ax[0], ("p [MPa]", "A/A0", "k [MPa/mm]")):
        a_.set_xlabel("h / sigma")
        a_.set_ylabel(lab)
        a_.grid(True, which="both", alpha=0.3)
    for a_, lab in zip(ax[1], ("A/A0", "k [MPa/mm]", "h / sigma")):
        a_.set_xlabel("mean pressure p [MPa]")
        a_.set_ylabel(lab)
        a_.grid(True, which="both", alpha=0.3)
    ax[0, 0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ## The run
def confidence_rows(law: "bem.BEMLaw", sigma: float, pressures, level: float = 0.95):
    """The BEM mean at each load with its confidence interval over the realisations.

    Student t with n - 1 degrees of freedom on the realisations' standard deviation at equal
    separation (``BEMLaw.*_std``): half-width t s / sqrt(n), relative to the mean. NaN for a
    single map (no realisations)."""
    from scipy.stats import t as student_t

    n = law.curves.n_realisations
    tq = float(student_t.ppf(0.5 + level / 2, n - 1)) if n > 1 else float("nan")
    h = law.normal.separation_for_pressure(np.asarray(pressures, float))
    rows = []
    for pm, hh in zip(pressures, h):
        _, k, a = law.normal.evaluate(np.array([hh]))
        rel = [float(np.interp(hh, law.separation, std / val)) * tq / math.sqrt(n)
               for std, val in ((law.pressure_std, law.pressure),
                                (law.area_std, law.area_fraction),
                                (law.stiffness_std, law.stiffness))]
        rows.append({"p [MPa]": float(pm), "h/sigma": float(hh / sigma),
                     "A/A0": float(a[0]), "k [MPa/mm]": float(k[0]),
                     f"ci{level * 100:.0f} p(h)": rel[0], f"ci{level * 100:.0f} A": rel[1],
                     f"ci{level * 100:.0f} k": rel[2]})
    return rows


def _load_points(ref: "bem.BEMLaw", n: int = 9, area_point: float = 0.01):
    """n log-spaced loads over the BEM table, plus the load where its A/A0 = area_point."""
    pressures = np.geomspace(ref.pressure.min(), ref.pressure.max(), n)
    a = ref.area_fraction
    if a.min() < area_point < a.max():
        lp = np.interp(math.log(area_point), np.log(a), np.log(ref.pressure))
        pressures = np.unique(np.append(pressures, math.exp(lp)))
    return pressures


def compare(source: dict, *, E_star=E_STAR, nu=NU, psi=0.35, tol=0.1, realisations=64, ppw=8.0,
            periods=1, n_pressures=12, area_range=(0.003, 0.3), backend=None, seed=0,
            plastic=True, tangential=True, out=None, verbose=True, label="",
            amplitudes="fixed", area_extrapolation=None, workers=2, tangential_realisations=4):
    """Build every law, print the tables, write CSV/PNG into ``out``; return a dict of results.

    Defaults (docs/bem.md, "Realisation scatter"): 64 fixed-amplitude realisations of one
    roll-off period at 8 px per shortest wavelength, solved 2 at a time, put the standard error
    of the BEM mean at or below 5 % for p(h), A/A0 and k at every load down to A/A0 = 1 %
    (4.4, 1.7, 2.6 % there for the anisotropic example surface,
    ``benchmarks/bench_bem_scatter.py``); the table reaches A/A0 ~ 0.3-1 % and that 1 % load
    is one of the comparison loads. The 95 % confidence intervals are printed."""
    t0 = time.perf_counter()
    moments = source["moments"]
    sigma = math.sqrt(moments.m00)
    material = AsperityMaterial.from_plasticity_index(moments, psi, E_star, nu=nu)
    cap = material.ch * material.H            # flow pressure of a fully plastic asperity (66)
    t_stat = time.perf_counter()
    stat = statistical_laws(moments, E_star, material, plastic)
    t_stat = time.perf_counter() - t_stat
    t_bem = time.perf_counter()
    bl = bem_laws(source, E_star, nu, cap if plastic else None, realisations=realisations,
                  ppw=ppw, periods=periods, n_pressures=n_pressures, area_range=area_range,
                  backend=backend, seed=seed, tangential=tangential, amplitudes=amplitudes,
                  area_extrapolation=area_extrapolation, workers=workers,
                  tangential_realisations=tangential_realisations)
    t_bem = time.perf_counter() - t_bem
    ref = bl["BEM elastic"]
    laws = dict(stat)
    laws.update({k: v.normal for k, v in bl.items()})
    # the load range: what the elastic BEM table covers, with its 1 % real-area point
    pressures = _load_points(ref)
    ci = confidence_rows(ref, sigma, pressures)
    s_grid = np.linspace(ref.separation.min(), ref.separation.max(), 7) / sigma
    by_h = table_vs_separation(laws, sigma, s_grid)
    by_p = table_vs_load(laws, sigma, pressures)
    ratios = ratio_rows({k: stat[k] for k in (STAT[0], STAT[2]) if k in stat}, ref,
                        pressures, sigma)
    p_sat = pressures
    if plastic:
        sat = bl["BEM saturated"]
        # the saturated table covers a different load range: compare inside both tables
        lo = max(sat.pressure.min(), ref.pressure.min())
        hi = min(sat.pressure.max(), ref.pressure.max())
        p_sat = np.geomspace(lo, hi, 9)
        ratios += ratio_rows({STAT[1]: stat[STAT[1]]}, sat, p_sat, sigma)
    agree = {}
    for name in stat:
        reference, pr = (bl["BEM saturated"].normal, p_sat) if name == STAT[1] else \
            (ref.normal, pressures)
        agree[name] = {q: bem.agreement_range(stat[name], reference, pr, tol, (q,))
                       for q in AGREE}
        agree[name]["all"] = bem.agreement_range(stat[name], reference, pr, tol, AGREE)
    info = ref.info
    nr = ref.curves.n_realisations
    if verbose:
        print(f"Surface {label}: m00 = {moments.m00 * 1e6:.4g} um^2, m20 = {moments.m20:.4g}, "
              f"m02 = {moments.m02:.4g}, m40 = {moments.m40 * 1e-6:.4g} um^-2, "
              f"m04 = {moments.m04 * 1e-6:.4g} um^-2 (sigma = {sigma * 1e3:.4g} um), "
              f"E* = {E_star:g} MPa, nu = {nu}")
        print(f"BEM: backend {info['backend']}, grid {info['grid']} px over "
              f"{info['size_mm'][0]:.4g} x {info['size_mm'][1]:.4g} mm, "
              f"{info['realisations']} realisation(s), k from {info['k_source']}; "
              f"saturated cap c_h H = {cap:.4g} MPa (psi = {psi}, H = {material.H:.4g} MPa)")
        print(f"build time: statistical laws {t_stat:.1f} s, BEM laws {t_bem:.1f} s "
              f"({sum(v.info['cached'] for v in bl.values())} cached realisations)")
        if moments.m04 / moments.m40 < 10:
            print("note: m04/m40 < 10 - the statistical 'elastic' and 'elasto-plastic' laws (the "
                  "strongly anisotropic model) are outside their validity; GW is the relevant one")
        keys = ["h/sigma"] + [f"{n}: p [MPa]" for n in laws]
        print_rows(by_h, "Pressure p [MPa] vs separation", keys)
        print_rows(by_h, "Real-area fraction A/A0 vs separation",
                   ["h/sigma"] + [f"{n}: A/A0" for n in laws])
        print_rows(by_h, "Stiffness k [MPa/mm] vs separation",
                   ["h/sigma"] + [f"{n}: k [MPa/mm]" for n in laws])
        print_rows(by_p, "Separation h/sigma vs load",
                   ["p [MPa]"] + [f"{n}: h/sigma" for n in laws])
        print_rows(by_p, "A/A0 vs load", ["p [MPa]"] + [f"{n}: A/A0" for n in laws])
        print_rows(by_p, "k [MPa/mm] vs load", ["p [MPa]"] + [f"{n}: k [MPa/mm]" for n in laws])
        print_rows(ratios, "Statistical / BEM (elasto-plastic vs saturated BEM)")
        b = bl["BEM elastic"]
        print(f"\nBEM realisation scatter (1 std / mean, one realisation) over the table: "
              f"p {np.max(b.pressure_std / b.pressure):.2g}, "
              f"A/A0 {np.max(b.area_std / b.area_fraction):.2g}, "
              f"k {np.max(b.stiffness_std / b.stiffness):.2g}; standard error of the mean of "
              f"{info['realisations']}: p {np.max(b.pressure_std / b.pressure) / math.sqrt(nr):.2g}"
              f", A/A0 {np.max(b.area_std / b.area_fraction) / math.sqrt(nr):.2g}, "
              f"k {np.max(b.stiffness_std / b.stiffness) / math.sqrt(nr):.2g}")
        print(f"A/A0: {info['area_source']} (raw pixel count "
              f"{info['area_pixel_range'][0]:.3g}-{info['area_pixel_range'][1]:.3g} over the "
              f"table, extrapolated {info['area_range'][0]:.3g}-{info['area_range'][1]:.3g})")
        if nr > 1:
            print_rows(ci, f"BEM elastic mean and its 95 % confidence interval (relative "
                       f"half-width, Student t over {nr} realisations, at equal separation)")
        if np.isfinite(b.tangential_ratio).all():
            r = np.nanmean(b.tangential_ratio, axis=0)
            print(f"BEM tangential stiffness in stick: kTx/kN = {r[0]:.3f}, kTy/kN = {r[1]:.3f} "
                  f"(range {info.get('tangential_ratio_range')}); Mindlin (circle) "
                  f"{bem.mindlin_ratio(nu):.3f}")
        print(f"\nLoad range [MPa] over which the statistical law agrees with the BEM law within "
              f"{tol:.0%} (tested {pressures[0]:.4g} - {pressures[-1]:.4g} MPa):")
        print(f"  {'law':28s} {'k at equal load':>18s} {'A/A0 at equal load':>20s} "
              f"{'p at equal h':>18s} {'all three':>18s}")
        for name, rng in agree.items():
            txt = ["-" if r is None else f"{r[0]:.4g}-{r[1]:.4g}"
                   for r in (rng["k_at_p"], rng["a_at_p"], rng["p_at_h"], rng["all"])]
            print(f"  {name:28s} {txt[0]:>18s} {txt[1]:>20s} {txt[2]:>18s} {txt[3]:>18s}")
        print("  (elasto-plastic compared with the saturated BEM law, the others with the elastic "
              "one; '-': nowhere)")
        print(f"wall time {time.perf_counter() - t0:.1f} s")
    if out:
        os.makedirs(out, exist_ok=True)
        write_csv(by_h, os.path.join(out, "laws_vs_separation.csv"))
        write_csv(by_p, os.path.join(out, "laws_vs_load.csv"))
        write_csv(ratios, os.path.join(out, "ratios.csv"))
        write_csv(ci, os.path.join(out, "bem_confidence.csv"))
        plot(laws, {"BEM elastic": bl["BEM elastic"]}, sigma, pressures,
             os.path.join(out, "compare_laws.png"), f"{label}: statistical vs BEM laws "
             f"(band: +-1 std over {info['realisations']} realisation(s))")
        if verbose:
            print(f"output: {out}/ (laws_vs_separation.csv, laws_vs_load.csv, ratios.csv, "
                  "bem_confidence.csv, compare_laws.png)")
    return dict(stat=stat, bem=bl, pressures=pressures, ratios=ratios, agree=agree, ci=ci,
                sigma=sigma, time_stat=t_stat, time_bem=t_bem, material=material, cap=cap)


def source_from_height_map(z, dx: float, dy: float | None = None, *, unit: str = "um",
                           boundary: str = "mirror"):
    """The surface as a measured height map -> dict(kind="map", z, dx, dy, boundary, moments).

    Args:
        z: (nx, ny) heights, axis 0 along x (the grain) [unit].
        dx, dy: sampling steps along axes 0 and 1 [unit] (dy defaults to dx).
        unit: length unit of z, dx, dy: "um", "mm" or "m".
        boundary: "periodic", "mirror" or "window" (see :func:`bem.check_height_map`).
    Returns:
        the source for :func:`compare` (lengths in mm); the statistical laws use the map's
        moments (central differences), the BEM law the map itself.
    """
    scales = {"um": 1e-3, "mm": 1.0, "m": 1e3}
    if unit not in scales:
        raise ValueError(f"unit = {unit!r} is invalid: valid units are {sorted(scales)}")
    scale = scales[unit]
    if dx is None:
        raise ValueError("dx = None is invalid: the height map needs its sampling step dx > 0 "
                         f"[{unit}]")
    dy = dx if dy is None else dy
    z_mm = np.asarray(z, float) * scale
    # moments of the map as the BEM sees it (mirrored if not periodic), by central
    # differences: an FFT of a non-periodic map counts the edge jump as roughness
    zp, _ = bem.check_height_map(z_mm, dx * scale, dy * scale, boundary=boundary)
    moments = moments_from_height_map(zp, dx * scale, dy * scale, method="fd", unit="mm")
    return dict(kind="map", z=z_mm, dx=dx * scale, dy=dy * scale, boundary=boundary,
                moments=moments)


def source_from_spectrum(spectrum):
    """The surface as its own power spectrum
    (:class:`rough_contact.surface.spectrum.PSDSurface`) -> source for :func:`compare`; the
    statistical laws use the PSD's moments (integrated), the BEM law its realisations."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        m = spectrum.moments()
    return dict(kind="spectrum", spectrum=spectrum, moments=m)


def source_from_moments(moments_um, hurst: float = 0.8, plateau: float = 2.0):
    """The surface as five spectral moments (um convention: m00 um^2, m20, m02 [-], m40, m04
    um^-2) with the assumed spectrum shape (Hurst exponent [-], roll-off plateau q_r/q_l [-])
    -> dict(kind="moments", moments, shape) for :func:`compare`."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        m = SpectralMoments(*moments_um, unit="um")
    return dict(kind="moments", moments=m, shape=SpectrumShape(hurst, plateau))


def source_from_example(name: str):
    """One of :func:`rough_contact.surface.spectrum.example_surfaces` -> source for
    :func:`compare`."""
    surfaces = example_surfaces()
    if name not in surfaces:
        raise ValueError(f"surface = {name!r} is invalid: valid surfaces are {sorted(surfaces)}")
    m, shape = surfaces[name]
    return dict(kind="moments", moments=m, shape=shape)
