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

Writes ``bolt_normal.csv``, ``bolt_tangential.csv`` (per increment) in ``--out`` and the figure
``--figure``.

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/bench_bolt_memory.py \\
        [--cycles 5] [--steps-per-cycle 8] [--pressure 10] [--low 0.1] [--amplitude 1.0] \\
        [--material psi|paper] [--rtol 1e-3] [--out results/bench_bolt_memory] \\
        [--figure docs/figures/bolt_memory.png]

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


def plot(normal, tangential, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    panels = (2 if normal else 0) + (2 if tangential else 0)
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
        ax2, ax3 = axes.pop(0), axes.pop(0)
        for law, r in tangential.items():
            ax2.plot(r.t, r.F_z, styles[law], lw=1, marker=".", ms=3, label=law)
            ends = r.boundaries
            ax3.plot(np.arange(len(ends)), r.F_z[ends] / r.F_z[ends[0]] - 1.0, styles[law],
                     marker="o", label=law)
        ax2.set_xlabel("pseudo-time (preload to 1, then one cycle per unit)")
        ax2.set_ylabel("clamping force F_z [N]")
        ax2.set_title("fixed stretch, u_x cycles: clamping force", fontsize=9)
        ax2.legend(fontsize=7)
        ax3.set_xlabel("cycles done (values at u_x = 0)")
        ax3.set_ylabel("F_z / F_z(end of preload) - 1")
        ax3.set_title("clamping force lost per cycle", fontsize=9)
        ax3.legend(fontsize=7)
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
    plot(normal, tangential, args.figure)
    print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
