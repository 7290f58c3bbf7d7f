"""Bolt head with and without asperity-plasticity memory (issue 23, item 4): shakedown of the
normal hysteresis under normal load cycles, and the clamping force under tangential cycles at a
fixed bolt stretch.

Scene: ``rough_contact.scenes.bolt_head`` (a cylinder, radius 5 mm, on a block, meshed
separately, mortar pairing; the punch's rough surface and friction case (b)). Normal laws, both
with the same loading branch (``benchmarks/_common.py``: the punch's surface, asperity data
``--material``):

* reversible: ``NormalLaw.elasto_plastic``;
* memory: ``HistoryNormalLaw.elasto_plastic`` (built once at ``--rtol``, cached in ``--out``).

Part 1 (``--normal``): the normal load ramps to ``low`` P, then ``--cycles`` cycles
low P -> P -> low P (force control, the top's u_x held at 0). Printed per cycle: the normal
hysteresis D_N and the frictional dissipation D.
Part 2 (``--tangential``): a force-controlled preload to P gives the stretch (the top's mean
u_z); a second run holds that stretch (the top's u_z prescribed) and cycles u_x between
+-``--amplitude`` um. Printed per cycle: the clamping force F_z at the cycle's end, D_N, D.

Writes ``bolt_normal.csv``, ``bolt_tangential.csv`` (per increment) and
``bolt_normal_cycles.csv``, ``bolt_tangential_cycles.csv`` (per cycle, both laws side by side:
the clamping force at the cycle's end, its loss against the reversible law, the normal
hysteresis and the frictional dissipation of the cycle) in ``--out`` and the figure
``--figure``. ``--compare DIR`` prints the largest difference of every per-increment column
against the CSVs of another run in DIR (e.g. the same command on another number of ranks).

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/bench_bolt_memory.py \\
        [--cycles 5] [--steps-per-cycle 8] [--pressure 10] [--low 0.1] [--amplitude 1.0] \\
        [--material psi|paper] [--rtol 1e-3] [--out results/bench_bolt_memory] \\
        [--figure docs/figures/bolt_memory.png] [--compare results/other_run]

Units: mm, N, MPa (u_x in um).
"""

from __future__ import annotations

import argparse
import os
import sys

import petsc4py
from _common import MEMORY_MATERIALS, punch_memory_law, write_csv

petsc4py.init(sys.argv[:1])

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.scenes import bolt_head  # noqa: E402

LAWS = ("reversible", "memory")


def rows_of(r, law):
    return [dict(law=law, t=t, u_x_um=1e3 * ux, approach_um=1e3 * w, load_N=ld, F_z_N=fz,
                 F_x_N=fx, dissipation_Nmm=d, normal_dissipation_Nmm=dn, slip_share=s)
            for t, ux, w, ld, fz, fx, d, dn, s in zip(r.t, r.u_x, r.approach, r.load, r.F_z,
                                                      r.F_x, r.dissipation,
                                                      r.normal_dissipation, r.slip_fraction)]


def reversal_check(law, n=41, eps=1e-9):
    """The law's reversal stiffness against its own unloading branch just above h_min: max
    |k(h_min + eps sigma, h_min)/k_rev - 1| and max |FD of p/k_rev - 1| over n h_min spanning
    the table, and the range of k_rev/k_load (what the tangential stiffness is scaled by)."""
    s = law.sigma
    hm = np.linspace(law.h_min - 0.5 * s, law.h_table_end - 0.5 * s, n)
    kl, kr = law.reversal_stiffness(hm)
    k_plus = law.evaluate_history(hm + eps * s, hm)[1]
    p0 = law.evaluate_history(hm, hm)[0]
    p1 = law.evaluate_history(hm + 1e-7 * s, hm)[0]
    fd = (p0 - p1) / (1e-7 * s)
    return (float(np.abs(k_plus / kr - 1).max()), float(np.abs(fd / kr - 1).max()),
            float((kr / kl).min()), float((kr / kl).max()))


def cycle_rows(runs):
    """Per cycle, both laws side by side: F_z at the cycle's end, the memory law's loss against
    the reversible law, the normal hysteresis and the frictional dissipation of the cycle."""
    rev, mem = runs["reversible"], runs["memory"]
    out = [dict(cycle=0, F_z_rev_N=rev.F_z[rev.boundaries[0]],
                F_z_mem_N=mem.F_z[mem.boundaries[0]],
                dF_z_memory_N=mem.F_z[mem.boundaries[0]] - rev.F_z[rev.boundaries[0]],
                D_N_mem_Nmm=float(mem.normal_dissipation[mem.boundaries[0]]),
                D_rev_Nmm=float(rev.dissipation[rev.boundaries[0]]),
                D_mem_Nmm=float(mem.dissipation[mem.boundaries[0]]))]
    for cr, cm in zip(rev.cycles, mem.cycles):
        out.append(dict(cycle=cr["cycle"], F_z_rev_N=rev.F_z[cr["end"]],
                        F_z_mem_N=mem.F_z[cm["end"]],
                        dF_z_memory_N=mem.F_z[cm["end"]] - rev.F_z[cr["end"]],
                        D_N_mem_Nmm=cm["normal_dissipated"], D_rev_Nmm=cr["dissipated"],
                        D_mem_Nmm=cm["dissipated"]))
    return out


def print_cycles(rows):
    print(f"  {'cycle':>5} {'F_z rev [N]':>12} {'F_z mem [N]':>12} {'mem - rev [N]':>13} "
          f"{'D_N mem [N mm]':>14} {'D rev [N mm]':>12} {'D mem [N mm]':>12}")
    for r in rows:
        print(f"  {r['cycle']:5d} {r['F_z_rev_N']:12.4f} {r['F_z_mem_N']:12.4f} "
              f"{r['dF_z_memory_N']:13.4f} {r['D_N_mem_Nmm']:14.4e} {r['D_rev_Nmm']:12.4e} "
              f"{r['D_mem_Nmm']:12.4e}")
    print("  (cycle 0: the end of the preload, with the cumulative dissipation there)")


def compare(out_dir, other_dir, modes):
    """Largest difference of every per-increment column against another run's CSVs."""
    import csv
    for mode in modes:
        paths = [os.path.join(d, f"bolt_{mode}.csv") for d in (out_dir, other_dir)]
        if not all(os.path.exists(q) for q in paths):
            print(f"compare {mode}: missing {[q for q in paths if not os.path.exists(q)]}")
            continue
        a, b = ([row for row in csv.DictReader(open(q))] for q in paths)
        if len(a) != len(b):
            print(f"compare {mode}: {len(a)} increments here, {len(b)} there")
            continue
        print(f"compare {mode} with {other_dir}: max |a - b| / max |b| per column "
              f"({len(a)} increments)")
        for key in a[0]:
            if key == "law":
                continue
            x = np.array([float(r[key]) for r in a])
            y = np.array([float(r[key]) for r in b])
            scale = max(np.abs(y).max(), 1e-300)
            print(f"  {key:>24}: {np.abs(x - y).max() / scale:.2e}")


def plot(normal, tangential, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    panels = (2 if normal else 0) + (3 if tangential else 0)
    fig = Figure(figsize=(4.2 * panels, 4.0))
    FigureCanvasAgg(fig)
    axes = list(np.atleast_1d(fig.subplots(1, panels)))
    styles = {"reversible": "-", "memory": "--"}
    if normal:
        ax0, ax1 = axes.pop(0), axes.pop(0)
        for law, r in normal.items():
            ax0.plot(1e3 * r.approach, r.load, styles[law], lw=1, marker=".", label=law)
        ax0.set_xlabel("approach of the top, -mean u_z [um]")
        ax0.set_ylabel("normal load [N]")
        ax0.set_title("normal cycles: load vs approach", fontsize=9)
        ax0.legend(fontsize=7)
        r = normal["memory"]
        k = np.array([c["cycle"] for c in r.cycles])
        dn = np.array([c["normal_dissipated"] for c in r.cycles])
        df = {law: np.array([c["dissipated"] for c in rr.cycles]) for law, rr in normal.items()}
        ax1.bar(k - 0.2, dn, 0.4, label="normal hysteresis (memory)")
        ax1.bar(k + 0.2, df["memory"], 0.4, label="friction (memory)")
        ax1.plot(k + 0.2, df["reversible"], "k_", ms=14, label="friction (reversible)")
        ax1.set_yscale("symlog", linthresh=max(1e-9, 1e-6 * max(dn.max(), 1e-300)))
        ax1.set_xlabel("cycle")
        ax1.set_ylabel("energy dissipated in the cycle [N mm]")
        ax1.set_title("normal cycles: per-cycle dissipation", fontsize=9)
        ax1.legend(fontsize=7)
    if tangential:
        ax2, ax3, ax4 = axes.pop(0), axes.pop(0), axes.pop(0)
        for law, r in tangential.items():
            after = r.t >= r.t[r.boundaries[0]]
            ax2.plot(r.t[after], r.F_z[after], styles[law], lw=1, marker=".", ms=3, label=law)
            ends = r.boundaries
            ax3.plot(np.arange(len(ends)), r.F_z[ends] / r.F_z[ends[0]] - 1.0, styles[law],
                     marker="o", label=law)
        if set(tangential) == set(LAWS):
            rows = cycle_rows(tangential)
            c = np.array([q["cycle"] for q in rows])
            ax3.plot(c, [q["dF_z_memory_N"] / rows[0]["F_z_rev_N"] for q in rows], "k:",
                     marker="s", ms=4, label="memory - reversible")
            ax4.semilogy(c[1:], [q["D_N_mem_Nmm"] for q in rows[1:]], "o--",
                         label="normal hysteresis (memory)")
            ax4.semilogy(c[1:], [q["D_mem_Nmm"] for q in rows[1:]], "s--",
                         label="friction (memory)")
            ax4.semilogy(c[1:], [q["D_rev_Nmm"] for q in rows[1:]], "s-", mfc="none",
                         label="friction (reversible)")
        ax2.set_xlabel("pseudo-time (one cycle per unit after the preload)")
        ax2.set_ylabel("clamping force F_z [N]")
        ax2.set_title("fixed stretch, u_x cycles: clamping force", fontsize=9)
        ax2.legend(fontsize=7)
        ax3.set_xlabel("cycles done (values at u_x = 0)")
        ax3.set_ylabel("F_z / F_z(end of preload) - 1")
        ax3.set_title("clamping force lost", fontsize=9)
        ax3.legend(fontsize=7)
        ax4.set_xlabel("cycle")
        ax4.set_ylabel("energy dissipated in the cycle [N mm]")
        ax4.set_title("fixed stretch, u_x cycles: per-cycle dissipation", fontsize=9)
        ax4.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=120)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=5)
    ap.add_argument("--steps-per-cycle", type=int, default=8)
    ap.add_argument("--pressure", type=float, default=10.0, help="peak nominal pressure [MPa]")
    ap.add_argument("--low", type=float, default=0.1, help="normal cycles' minimum / peak")
    ap.add_argument("--amplitude", type=float, default=1.0, help="u_x amplitude [um]")
    ap.add_argument("--size-cylinder", type=float, default=1.0)
    ap.add_argument("--size-block", type=float, default=1.6)
    ap.add_argument("--material", default="psi", help=f"asperity data: {MEMORY_MATERIALS} "
                    "(benchmarks/_common.py punch_material)")
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--out", default="results/bench_bolt_memory")
    ap.add_argument("--cache", default="results/bench_punch_memory",
                    help="folder of the cached memory law (shared with bench_punch_memory.py)")
    ap.add_argument("--figure", default="docs/figures/bolt_memory.png")
    ap.add_argument("--skip", choices=["normal", "tangential"], default=None)
    ap.add_argument("--compare", default=None,
                    help="folder of another run's CSVs: print the largest differences")
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    law, seconds, cached = punch_memory_law(args.cache, args.rtol, comm, args.material)
    laws = {"reversible": law.loading, "memory": law}
    common = dict(pressure=args.pressure, cycles=args.cycles,
                  steps_per_cycle=args.steps_per_cycle, size_cylinder=args.size_cylinder,
                  size_block=args.size_block, comm=comm)
    normal, tangential = {}, {}
    for name in LAWS:
        if args.skip != "normal":
            PETSc.Sys.Print(f"normal cycles, {name} law:", comm=comm)
            normal[name] = bolt_head.run_cycles("normal", low=args.low, normal=laws[name],
                                                **common)
        if args.skip != "tangential":
            PETSc.Sys.Print(f"tangential cycles at a fixed stretch, {name} law:", comm=comm)
            tangential[name] = bolt_head.run_cycles("tangential", amplitude_um=args.amplitude,
                                                    normal=laws[name], **common)
    if comm.rank != 0:
        return
    print(f"\nmemory law ({args.material} asperity data): rtol {args.rtol:g}, build "
          f"{seconds:.0f} s{' (cached)' if cached else ''}")
    e_k, e_fd, q_lo, q_hi = reversal_check(law)
    print(f"reversal stiffness: |k(h_min + 1e-9 sigma)/k_rev - 1| <= {e_k:.1e}, one-sided FD "
          f"of p (1e-7 sigma) / k_rev - 1 <= {e_fd:.1e}; k_rev/k_load in [{q_lo:.4f}, "
          f"{q_hi:.4f}] over the table")
    for title, runs in (("NORMAL CYCLES (force control, low P -> P -> low P)", normal),
                        ("TANGENTIAL CYCLES at a fixed stretch", tangential)):
        if not runs:
            continue
        r0 = next(iter(runs.values()))
        print(f"\n{title}: P = {r0.P:.1f} N, {r0.dofs} DOFs"
              + (f", stretch {1e3 * r0.stretch:.4f} um, amplitude {args.amplitude:g} um"
                 if r0.mode == "tangential" else f", low = {args.low:g}"))
        for name, r in runs.items():
            print(f" {name} law ({r.wall_time:.0f} s); F_z at the end of the preload "
                  f"{r.F_z[r.boundaries[0]]:.6f} N")
            print(r.table())
        write_csv(os.path.join(args.out, f"bolt_{r0.mode}.csv"),
                  [row for name, r in runs.items() for row in rows_of(r, name)])
        if set(runs) == set(LAWS):
            rows = cycle_rows(runs)
            print(" per cycle, both laws (F_z at the cycle's end; D_N, D of the cycle):")
            print_cycles(rows)
            write_csv(os.path.join(args.out, f"bolt_{r0.mode}_cycles.csv"), rows)
    plot(normal, tangential, args.figure)
    print(f"figure: {args.figure}")
    if args.compare:
        compare(args.out, args.compare, [m for m in ("normal", "tangential") if m != args.skip])


if __name__ == "__main__":
    main()
