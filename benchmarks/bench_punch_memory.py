"""The paper's flat punch loaded and unloaded with and without asperity-plasticity memory
(issue 23, item 4): how much the memory changes the frictional dissipation, the residual
settlement and the slip pattern.

The quarter punch of section 9.2 (the default tetrahedral mesh: 20 mm away from / 2 mm on the
contact, P2) is loaded to 1000 N in 16 increments and unloaded in 15 to the seating load
(1/16 of the peak, the paper's Table 5 program; a punch held only by its rough interface has no
equilibrium at zero load), with the elasto-plastic population of Figs 18-19 in two forms that
share the same loading branch:

* reversible: ``NormalLaw.elasto_plastic`` (unloads back along the loading curve, the paper's);
* memory: ``HistoryNormalLaw.elasto_plastic`` (the same loading table; unloading and reloading
  on the elastic branch of the smallest separation h_min, ``docs/unloading.md``), built once at
  ``--rtol`` and cached in the output folder.

Printed per friction case and law: the frictional dissipation D (Table 5's quantity), the normal
hysteresis D_N (0 for the reversible law), the residual settlement (the mean interface gap and
the punch top's displacement at the seating load after unloading minus before loading), the
slipping share of the contact area at the peak, in the first unloading increment and at the
end, the stick ratio at the end, the Newton
iterations and the wall time. Writes ``summary.csv`` and ``increments.csv`` in ``--out`` and the
figure ``--figure`` (force against the interface closure and against the punch's approach, both
laws; the slipping area along the program).

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/bench_punch_memory.py \\
        [--cases a b c] [--rtol 1e-3] [--material psi|paper] [--out results/bench_punch_memory] \\
        [--cache results/bench_punch_memory] [--figure docs/figures/punch_memory.png]

Units: mm, N, MPa (gaps printed in um).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import petsc4py
from _common import MEMORY_MATERIALS, punch_memory_law, write_csv

petsc4py.init(sys.argv[:1])

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.fem.boundary import SurfaceMean  # noqa: E402
from rough_contact.io import gather_points  # noqa: E402
from rough_contact.scenes import flat_punch  # noqa: E402
from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402

STEPS = 16
LAWS = ("reversible", "memory")


def run_one(normal, case, comm, mesh_size=20.0, contact_size=2.0, order=2):
    """One load/unload run; returns (per-increment rows, slip maps at the peak and the end)."""
    t0 = time.perf_counter()
    m = flat_punch.build(comm, mesh_size=mesh_size, contact_size=contact_size, order=order,
                         case=case, steps=STEPS, normal=normal, prefix="pm_")
    ci, problem = m.interface, m.problem
    top = SurfaceMean(problem.u, m.scene.facet_tags, m.scene.tag("load"), 2)
    area = ci.nominal_area()
    rows, maps = [], {}
    factors = load_unload_factors(STEPS, STEPS - 1)
    for inc in load_path(problem, m.solver, factors, verbose=False):
        s = ci.summary()
        pf = ci.point_fields()
        gap = comm.allreduce(float(np.dot(ci.point_weights(), pf.gap)), op=MPI.SUM) / area
        rows.append(dict(step=inc.step, load_factor=inc.load_factor,
                         force_N=m.quarter_force * inc.load_factor,
                         mean_gap_um=1e3 * gap, approach_um=-1e3 * top(),
                         dissipation_Nmm=inc.dissipation,
                         normal_dissipation_Nmm=inc.normal_dissipation,
                         contact_share=s.contact_area / s.nominal_area,
                         slip_share=s.slipping_area / max(s.contact_area, 1e-300),
                         newton=inc.newton_total))
        if inc.step in (STEPS, len(factors)):
            pts, f = gather_points(comm, ci.point_coordinates(),
                                   {"slipping": pf.slipping.astype(float),
                                    "contact": pf.contact.astype(float)})
            maps["peak" if inc.step == STEPS else "end"] = (pts, f)
    m.solver.destroy()
    return rows, maps, time.perf_counter() - t0


def summarise(rows, seconds):
    first, peak, last = rows[0], rows[STEPS - 1], rows[-1]
    assert abs(first["load_factor"] - last["load_factor"]) < 1e-12
    return dict(D_friction_Nmm=last["dissipation_Nmm"],
                D_normal_Nmm=last["normal_dissipation_Nmm"],
                settlement_gap_um=first["mean_gap_um"] - last["mean_gap_um"],
                settlement_top_um=last["approach_um"] - first["approach_um"],
                peak_closure_um=first["mean_gap_um"] - peak["mean_gap_um"],
                slip_share_peak=peak["slip_share"], stick_ratio_peak=1 - peak["slip_share"],
                slip_share_first_unload=rows[STEPS]["slip_share"],
                slip_share_end=last["slip_share"], stick_ratio_end=1 - last["slip_share"],
                contact_share_end=last["contact_share"],
                newton=sum(r["newton"] for r in rows), seconds=seconds)


def plot(results, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(13, 4.2))
    FigureCanvasAgg(fig)
    ax0, ax1, ax2 = fig.subplots(1, 3)
    styles = {"reversible": "-", "memory": "--"}
    for (case, law), (rows, _, _) in results.items():
        g0 = rows[0]["mean_gap_um"]
        F = [4 * r["force_N"] for r in rows]                 # full punch
        lab = f"({case}) {law}"
        ax0.plot([g0 - r["mean_gap_um"] for r in rows], F, styles[law], marker=".", lw=1,
                 label=lab)
        ax1.plot([r["approach_um"] for r in rows], F, styles[law], marker=".", lw=1, label=lab)
        ax2.plot(range(1, len(rows) + 1), [100 * r["slip_share"] for r in rows], styles[law],
                 marker=".", lw=1, label=lab)
    ax0.set_xlabel("interface closure: mean gap at 62.5 N (loading) - mean gap [um]")
    ax0.set_ylabel("punch force (full punch) [N]")
    ax0.set_title("force vs interface closure", fontsize=9)
    ax1.set_xlabel("approach of the loaded top, -mean u_z [um]")
    ax1.set_title("force vs punch approach (bulk included)", fontsize=9)
    ax2.axvline(STEPS, color="0.7", lw=0.8)
    ax2.set_xlabel("increment (peak at 16)")
    ax2.set_ylabel("slipping share of the contact area [%]")
    ax2.set_title("slip pattern along the program", fontsize=9)
    for ax in (ax0, ax1, ax2):
        ax.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=120)


def plot_maps(results, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    keys = list(results)
    fig = Figure(figsize=(3.0 * len(keys), 5.6))
    FigureCanvasAgg(fig)
    axes = np.atleast_2d(fig.subplots(2, len(keys))).reshape(2, len(keys))
    for j, key in enumerate(keys):
        maps = results[key][1]
        for i, when in enumerate(("peak", "end")):
            pts, f = maps[when]
            ax = axes[i, j]
            c = np.where(f["contact"] == 0, 0, np.where(f["slipping"] > 0, 2, 1))
            for v, col, lab in ((1, "tab:blue", "stick"), (2, "tab:red", "slip"),
                                (0, "0.8", "open")):
                sel = c == v
                ax.scatter(pts[sel, 0], pts[sel, 1], s=3, c=col, label=lab)
            ax.set_aspect("equal")
            ax.set_title(f"({key[0]}) {key[1]}, {'1000 N' if when == 'peak' else 'unloaded'}",
                         fontsize=8)
            ax.tick_params(labelsize=6)
    axes[0, 0].legend(fontsize=6, markerscale=3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["a", "b", "c"], choices=["a", "b", "c"])
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--material", default="psi",
                    help="asperity data (benchmarks/_common.py punch_material): 'psi' (psi = "
                         "0.35, K_Y Y = (2/pi) H), 'psi=2' (another psi) or 'paper' (Figs 18-19: Y = 2070 MPa, "
                         "K_Y = 1.62; its unloading branch lies above the loading one)")
    ap.add_argument("--out", default="results/bench_punch_memory")
    ap.add_argument("--cache", default="results/bench_punch_memory",
                    help="folder of the cached memory law (shared with bench_bolt_memory.py)")
    ap.add_argument("--figure", default="docs/figures/punch_memory.png")
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    law, seconds, cached = punch_memory_law(args.cache, args.rtol, comm, args.material)
    PETSc.Sys.Print(f"memory law ({args.material} asperity data): rtol {args.rtol:g}, {law.info['rows']} x {law.info['x_knots']}"
                    f" knots, worst check error {law.info['worst_error']:.2g}, build "
                    f"{seconds:.0f} s{' (cached)' if cached else ''}", comm=comm)
    laws = {"reversible": law.loading, "memory": law}
    results, summary, incs = {}, [], []
    for case in args.cases:
        for name in LAWS:
            rows, maps, sec = run_one(laws[name], case, comm)
            results[(case, name)] = (rows, maps, sec)
            s = dict(case=case, law=name, **summarise(rows, sec))
            summary.append(s)
            incs += [dict(case=case, law=name, **r) for r in rows]
            PETSc.Sys.Print(f"  ({case}) {name}: D = {s['D_friction_Nmm']:.4e} N mm, D_N = "
                            f"{s['D_normal_Nmm']:.4e} N mm  [{sec:.0f} s]", comm=comm)
    if comm.rank == 0:
        write_csv(os.path.join(args.out, "summary.csv"), summary)
        write_csv(os.path.join(args.out, "increments.csv"), incs)
        print("\nQuarter punch, 1000 N and back to 62.5 N (16 + 15 increments); settlement = "
              "value at 62.5 N after unloading minus before loading")
        print(f"{'case':>4} {'law':>10} {'D [N mm]':>10} {'D_N [N mm]':>10} "
              f"{'gap sett. um':>12} {'top sett. um':>12} {'closure@peak':>12} "
              f"{'slip% peak':>10} {'slip% unl.1':>11} {'slip% end':>9} {'stick end':>9} "
              f"{'Newton':>6} {'s':>5}")
        for s in summary:
            print(f"{s['case']:>4} {s['law']:>10} {s['D_friction_Nmm']:10.4e} "
                  f"{s['D_normal_Nmm']:10.4e} {s['settlement_gap_um']:12.4e} "
                  f"{s['settlement_top_um']:12.4e} {s['peak_closure_um']:12.4f} "
                  f"{100 * s['slip_share_peak']:10.1f} {100 * s['slip_share_first_unload']:11.1f} "
                  f"{100 * s['slip_share_end']:9.1f} "
                  f"{s['stick_ratio_end']:9.3f} {s['newton']:6d} {s['seconds']:5.0f}")
        for case in args.cases:
            r, mm = (next(s for s in summary if s["case"] == case and s["law"] == n)
                     for n in LAWS)
            print(f"  ({case}) memory vs reversible: D {mm['D_friction_Nmm'] / r['D_friction_Nmm'] - 1:+.3e}"
                  f" (relative), D_N / D = {mm['D_normal_Nmm'] / mm['D_friction_Nmm']:.3e}, "
                  f"gap settlement {r['settlement_gap_um']:.4e} -> {mm['settlement_gap_um']:.4e} um"
                  f", slipping share at the peak {100 * r['slip_share_peak']:.2f} -> "
                  f"{100 * mm['slip_share_peak']:.2f} %")
        plot(results, args.figure)
        plot_maps(results, os.path.splitext(args.figure)[0] + "_slip.png")
        print(f"figures: {args.figure}, {os.path.splitext(args.figure)[0]}_slip.png")


if __name__ == "__main__":
    main()
