# # Flat punch, the three friction cases of section 9.2 (Table 5, Figs 18-19)
#
# Runs the quarter punch of ``demo_flat_punch`` (its ``build``) for the friction cases of the
# paper,
#
#   (a) mu_mx = mu_my = 0.2, mu_ox = mu_oy = 1,   nu_x = nu_y = 0.125, kTx = kTy = 0.7 kN
#   (b) mu_mx = mu_my = 0.5, mu_ox = mu_oy = 0.5, nu_x = nu_y = 0.125, kTx = kTy = 0.7 kN
#   (c) as (b) but kTx = 0.7 kN, kTy = kN,
#
# with n_x = n_y = 275 /mm, the rough surface of Figs 18-19 (m00 = 0.625 um^2 ...), E = 200 GPa,
# nu = 0.25, 1000 N on the whole punch (250 N on the quarter) in 16 increments, then unloading in
# 15 increments to 1/16 of the load (the rough interface has no stiffness at zero load).
#
# Post-processing, per case:
#   * total frictional dissipation: D_cum = sum over points of int t_T . d u^p_T (our definition,
#     the energy really dissipated) at peak and after unloading, and the paper's literal
#     D_lit = sum t_T . u^p_T (tractions times total plastic slips) at peak, both for the
#     modelled quarter (the paper's Table 5 sums "all contact points" of its quarter model);
#   * quiver plots of the plastic slip directions at peak and after unloading (Figs 18-19) with
#     the stick/slip map at peak;
#   * the reversal of the tangential tractions on unloading: fraction of the contact area whose
#     traction points against its peak-load direction, per unloading increment;
#   * the mirror x <-> y asymmetry of the results (zero for (a), (b) on a mirror-symmetric mesh).
#
# Units: mm, N, MPa; dissipation N mm. Run (serial or ``mpirun -n 2``):
#
#   python demos/study_flat_punch_cases.py [--cases a b c] [--cell-type hexahedron]
#          [--contact-size 1.0] [--mesh-size 10] [--outdir results/punch_cases]
#          [--figdir docs/figures]
#
# The results table is written to ``<outdir>/punch_cases.json`` and printed.


from __future__ import annotations

import argparse
import json
import os
import time
from dataclasses import asdict, replace

from mpi4py import MPI

from rough_contact.scenes import flat_punch as punch
from rough_contact.scenes.punch_cases import plot_case, plot_unloading, run_case, summary_table


def main(argv=None, comm=MPI.COMM_WORLD):
    parser = argparse.ArgumentParser(description="Flat punch, friction cases (a)-(c) of "
                                     "section 9.2", allow_abbrev=False)
    parser.add_argument("--cases", nargs="+", default=["a", "b", "c"], choices=["a", "b", "c"])
    parser.add_argument("--cell-type", default="hexahedron",
                        choices=["tetrahedron", "hexahedron"])
    parser.add_argument("--mesh-size", type=float, default=10.0)
    parser.add_argument("--contact-size", type=float, default=1.0)
    parser.add_argument("--order", type=int, default=1, choices=[1, 2])
    parser.add_argument("--steps", type=int, default=16)
    parser.add_argument("--normal-law", default="elasto-plastic",
                        choices=["elastic", "elasto-plastic"])
    parser.add_argument("--outdir", default="results/punch_cases")
    parser.add_argument("--figdir", default="docs/figures")
    parser.add_argument("--verbose", action="store_true")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    results = []
    for case in args.cases:
        res = run_case(case, comm, mesh_size=args.mesh_size, contact_size=args.contact_size,
                       order=args.order, cell_type=args.cell_type, steps=args.steps,
                       normal_law=args.normal_law, verbose=args.verbose)
        results.append(res)
        if comm.rank == 0:
            print(f"case ({case}): D_cum peak {res.D_peak:.4e}, end {res.D_end:.4e}, "
                  f"D_lit peak {res.D_literal_peak:.4e} N mm (quarter); Table 5: "
                  f"{punch.TABLE5['21-node'][case]} / {punch.TABLE5['28-node'][case]}; "
                  f"{res.num_dofs} DOFs, {res.n_points} points, "
                  f"{res.wall_time:.1f} s", flush=True)
    if comm.rank == 0:
        os.makedirs(args.outdir, exist_ok=True)
        os.makedirs(args.figdir, exist_ok=True)
        for res in results:
            plot_case(res, os.path.join(args.figdir, f"punch_case_{res.case}.png"))
        plot_unloading(results, os.path.join(args.figdir, "punch_unloading.png"))
        table = summary_table(results)
        print(table)
        keep = [{k: v for k, v in asdict(replace(r, peak=None, end=None)).items()
                 if k not in ("peak", "end")} for r in results]
        with open(os.path.join(args.outdir, "punch_cases.json"), "w") as fh:
            json.dump(dict(args=vars(args), ranks=comm.size, results=keep), fh, indent=1)
        print(f"total wall time {time.perf_counter() - t0:.1f} s on {comm.size} rank(s)")
    return results


if __name__ == "__main__":
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    main()

