# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # Slip-hardening friction at one interface point
#
# Material-point drivers for the interface law of Buczkowski & Kleiber (2009), section 8:
# the statistical normal law p(h) (McCool's GW equivalent of the paper's Fig. 18 surface),
# tangential stiffness kT = c kN(h) and orthotropic / isotropic slip-hardening friction
#
#     mu_i = mu_mi [1 - (1 - mu_oi) exp(-n_i kappa_i)]                     (89)-(90)
#     f = sqrt((t_x/mu_x)^2 + (t_y/mu_y)^2) - p <= 0                       (91)
#     slip direction from the potential ellipse (nu_x, nu_y)                (98)/(101)
#
# Units: mm, N, MPa. The point is seated at p_seat (h = h0, g = 0) and then driven by the
# tangential slip s = (s_x, s_y) at fixed normal jump g. Each driver checks a known result:
# the hardening curves (89)-(90), the slip/traction angle relation (118), f = 0 after every
# return, non-negative dissipation, and the symmetry / asymmetry of the paper's cases (b), (c).
#
#     .venv/bin/python demos/demo_friction_point.py [--docs] [--out results/friction_point]

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rough_contact.interface.friction import (  # noqa: E402
    IsotropicSlipHardening,
    OrthotropicSlipHardening,
)
from rough_contact.interface.law import InterfaceLaw  # noqa: E402
from rough_contact.interface.normal import NormalLaw  # noqa: E402
from rough_contact.interface.state import StatePair  # noqa: E402
from rough_contact.interface.tangential import TangentialStiffness  # noqa: E402
from rough_contact.surface import SpectralMoments  # noqa: E402


def drive(law: InterfaceLaw, slips: np.ndarray, g: float = 0.0) -> dict:
    """Drive one point through the slip path slips (steps, 2) [mm] at normal jump g [mm]."""
    pair = StatePair(law.initial_state(1))
    out = {k: [] for k in ("t", "p", "sp", "kappa", "path", "slip", "dw", "dsp")}
    for s in slips:
        r = law.evaluate(np.array([[g, s[0], s[1]]]), pair.committed)
        out["dsp"].append(r.state.plastic_slip[0] - pair.committed.plastic_slip[0])
        pair.update(r)
        pair.commit()
        out["t"].append(r.traction[0, 1:])
        out["p"].append(r.pressure[0])
        out["sp"].append(pair.committed.plastic_slip[0].copy())
        out["kappa"].append(pair.committed.accumulated_slip[0].copy())
        out["path"].append(pair.committed.slip_path[0])
        out["slip"].append(r.slipping[0])
        out["dw"].append(r.dissipation[0])
    return {k: np.array(v) for k, v in out.items()}


def mu_curve(fr: OrthotropicSlipHardening, axis: int, kappa):
    return fr.mu_macro[axis] * (1 - (1 - fr.mu_initial_ratio[axis]) * np.exp(-fr.hardening[axis] * kappa))


def main(out: Path, docs: bool = False, p_seat: float = 5.0) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    surf = SpectralMoments(0.625, 8e-5, 8e-4, 1.04e-6, 1.04e-4)  # Fig. 18 (um units)
    normal = NormalLaw.greenwood_williamson(surf, 2.0e5 / (2 * (1 - 0.25**2)))
    ortho = OrthotropicSlipHardening((0.3, 0.5), (0.5, 0.6), (275.0, 275.0), potential_axes=(0.1, 0.2))
    ts = TangentialStiffness((0.7, 0.7))
    law = InterfaceLaw(normal, ts, ortho).with_seating(p_seat)
    p0, kn0, _ = normal.evaluate(np.array([law.h0]))
    kt = 0.7 * kn0[0]
    print(f"seated at p = {p0[0]:.4g} MPa, kN = {kn0[0]:.4g} MPa/mm, kT = {kt:.4g} MPa/mm, "
          f"h0 = {law.h0 * 1e3:.4f} um")
    checks = {}
    figs = []

    # 1. hardening curves: monotonic sliding along x and along y
    s_max = 0.02
    s = np.linspace(0, s_max, 401)[1:]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    err = 0.0
    for axis, name in ((0, "x"), (1, "y")):
        path = np.zeros((s.size, 2))
        path[:, axis] = s
        d = drive(law, path)
        ratio = d["t"][:, axis] / d["p"]
        ax[0].plot(s * 1e3, ratio, label=f"sliding along {name}")
        kap = d["kappa"][:, axis]
        ax[1].plot(kap * 1e3, ratio, lw=3, alpha=0.5, label=f"law, {name}")
        ax[1].plot(kap * 1e3, mu_curve(ortho, axis, kap), "k--", lw=1,
                   label=f"eq ({89 + axis})" if axis == 0 else f"eq ({89 + axis})")
        sl = d["slip"]
        err = max(err, np.abs(ratio[sl] - mu_curve(ortho, axis, kap[sl])).max() / ortho.mu_macro[axis])
    ax[0].set(xlabel="total slip s [um]", ylabel="t_T / p [-]", title="monotonic sliding")
    ax[1].set(xlabel="accumulated plastic slip kappa [um]", ylabel="mu = t_T / p [-]",
              title="hardening curves vs (89)-(90)")
    for a in ax:
        a.legend()
        a.grid(alpha=0.3)
    checks["hardening curve max rel error"] = err
    figs.append(("friction_hardening", fig))

    # 2. sliding at several angles: slip angle alpha vs traction angle beta, eq (118)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4.5))
    nux, nuy = ortho.potential_axes
    worst_118, worst_f = 0.0, 0.0
    th_all = np.radians([0, 15, 30, 45, 60, 75, 90])
    for th in th_all:
        d = drive(law, np.outer(np.linspace(0, 0.01, 201)[1:], [np.cos(th), np.sin(th)]))
        sl = d["slip"]
        dsp = d["dsp"][sl]
        alpha = np.arctan2(dsp[:, 1], dsp[:, 0])
        beta = np.arctan2(d["t"][sl, 1], d["t"][sl, 0])
        pred = np.arctan2(np.sin(alpha) * nuy**2, np.cos(alpha) * nux**2)
        worst_118 = max(worst_118, np.abs(beta - pred).max())
        mu = np.column_stack([mu_curve(ortho, 0, d["kappa"][sl, 0]), mu_curve(ortho, 1, d["kappa"][sl, 1])])
        f = np.hypot(d["t"][sl, 0] / mu[:, 0], d["t"][sl, 1] / mu[:, 1]) - d["p"][sl]
        worst_f = max(worst_f, np.abs(f / d["p"][sl]).max())
        ax[0].plot(d["t"][:, 0], d["t"][:, 1], label=f"{np.degrees(th):.0f} deg")
        ax[1].plot(np.degrees(alpha), np.degrees(beta), "o", ms=3)
        # final yield ellipse
        phi = np.linspace(0, 2 * np.pi, 200)
        ax[0].plot(d["p"][-1] * mu[-1, 0] * np.cos(phi), d["p"][-1] * mu[-1, 1] * np.sin(phi), "k:", lw=0.5)
    a = np.linspace(0, np.pi / 2, 100)
    ax[1].plot(np.degrees(a), np.degrees(np.arctan2(np.sin(a) * nuy**2, np.cos(a) * nux**2)), "k-",
               lw=1, label="(118): tan b = tan a (nu_y/nu_x)^2")
    ax[0].set(xlabel="t_x [MPa]", ylabel="t_y [MPa]", title="traction paths, final slip ellipses",
              aspect="equal")
    ax[0].legend(fontsize=7, loc="lower left")
    ax[1].set(xlabel="slip increment angle alpha [deg]", ylabel="traction angle beta [deg]",
              title=f"non-associated slip, nu_y/nu_x = {nuy / nux:g}")
    ax[1].legend()
    for a_ in ax:
        a_.grid(alpha=0.3)
    checks["eq (118) max angle error [rad]"] = worst_118
    checks["max |f|/p after return"] = worst_f
    figs.append(("friction_angles", fig))

    # 3. loading, unloading, reversal: orthotropic and isotropic
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    cyc = np.concatenate([np.linspace(0, 0.01, 201), np.linspace(0.01, -0.01, 801)[1:],
                          np.linspace(-0.01, 0.01, 801)[1:]])
    iso = IsotropicSlipHardening(0.4, 0.5, 275.0)
    min_dw = np.inf
    for fr, name in ((ortho, "orthotropic (x)"), (iso, "isotropic")):
        lw = InterfaceLaw(normal, ts, fr, h0=law.h0)
        d = drive(lw, np.column_stack([cyc, np.zeros_like(cyc)]))
        ax[0].plot(cyc * 1e3, d["t"][:, 0], label=name)
        ax[1].plot(np.arange(cyc.size), (d["kappa"][:, 0] if fr is ortho else d["path"]) * 1e3, label=name)
        assert np.all(np.diff(d["kappa"][:, 0]) >= 0) and np.all(np.diff(d["path"]) >= 0)
        min_dw = min(min_dw, d["dw"].min())
    ax[0].set(xlabel="s_x [um]", ylabel="t_x [MPa]", title="load, unload, reverse")
    ax[1].set(xlabel="step", ylabel="hardening variable [um]", title="hardening never decreases")
    for a_ in ax:
        a_.legend()
        a_.grid(alpha=0.3)
    checks["min dissipation increment [N/mm]"] = min_dw
    figs.append(("friction_cycle", fig))

    # 4. the paper's cases (b) kTx = kTy = 0.7 kN and (c) kTx = 0.7 kN, kTy = kN
    fr_b = OrthotropicSlipHardening((0.5, 0.5), (0.5, 0.5), (275.0, 275.0), potential_axes=(0.125, 0.125))
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    sym = {}
    for c, case in (((0.7, 0.7), "(b)"), ((0.7, 1.0), "(c)")):
        lw = InterfaceLaw(normal, TangentialStiffness(c), fr_b, h0=law.h0)
        ss = np.linspace(0, 2e-3, 201)[1:]
        dx = drive(lw, np.column_stack([ss, 0 * ss]))
        dy = drive(lw, np.column_stack([0 * ss, ss]))
        ax[0].plot(ss * 1e3, dx["t"][:, 0], label=f"{case} along x")
        ax[0].plot(ss * 1e3, dy["t"][:, 1], "--", label=f"{case} along y")
        ax[1].plot(ss * 1e3, dx["sp"][:, 0] * 1e3, label=f"{case} along x")
        ax[1].plot(ss * 1e3, dy["sp"][:, 1] * 1e3, "--", label=f"{case} along y")
        sym[case] = np.abs(dx["t"][:, 0] - dy["t"][:, 1]).max()
    ax[0].set(xlabel="total slip [um]", ylabel="traction [MPa]", title="paper cases (b), (c)")
    ax[1].set(xlabel="total slip [um]", ylabel="plastic slip [um]",
              title="stiffer axis: more plastic slip")
    for a_ in ax:
        a_.legend(fontsize=8)
        a_.grid(alpha=0.3)
    checks["case (b) x/y asymmetry [MPa]"] = sym["(b)"]
    checks["case (c) x/y asymmetry [MPa]"] = sym["(c)"]
    figs.append(("friction_cases_bc", fig))

    for name, fig in figs:
        fig.tight_layout()
        path = out / f"{name}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        if docs:
            dest = Path(__file__).resolve().parents[1] / "docs" / "figures"
            dest.mkdir(parents=True, exist_ok=True)
            shutil.copy(path, dest / path.name)
        print(f"wrote {path}")
    for k, v in checks.items():
        print(f"check: {k} = {v:.3e}")
    assert checks["hardening curve max rel error"] < 1e-10
    assert checks["eq (118) max angle error [rad]"] < 1e-10
    assert checks["max |f|/p after return"] < 1e-10
    assert checks["min dissipation increment [N/mm]"] >= 0.0
    assert checks["case (b) x/y asymmetry [MPa]"] < 1e-12 * p_seat
    assert checks["case (c) x/y asymmetry [MPa]"] > 1e-3 * p_seat
    return checks


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description="friction material-point drivers", allow_abbrev=False)
    ap.add_argument("--out", type=Path, default=Path("results/friction_point"))
    ap.add_argument("--docs", action="store_true", help="copy PNGs to docs/figures/")
    ap.add_argument("--p-seat", type=float, default=5.0, help="seating pressure [MPa]")
    a = ap.parse_args()
    main(a.out, a.docs, a.p_seat)
