# # Contact pressure on the interface facets, ParaView-style, from the written XDMF file
#
# Reads ``interface.xdmf`` + ``interface.h5`` written by
# :class:`rough_contact.io.interface_output.InterfaceWriter` (the facets of the first contact
# surface with one value per facet, the quadrature average of the point values, time = load
# factor) and draws the contact pressure of one increment as flat-shaded facets with their
# edges and a colour bar ("Surface With Edges" and ParaView's default "Cool to Warm" map).
# With ``--status`` it also draws the open/stick/slip map next to the plastic-slip arrows.
#
# The picture is made from the file alone (h5py + the XML index), not from the solver's memory,
# so it shows what a user opening the file in ParaView sees.
#
# With ``--run`` the script first runs the flat punch of section 9.2 (quarter model, paper's
# case (b) friction, elasto-plastic rough law) itself through the writer, loading only (the
# pressure at full load), at the size given by ``--mesh-size``/``--contact-size``/``--order``.
#
# Run::
#
#     bash run.sh python demos/plot_interface_pressure.py --run --overwrite \
#         --results results/flat_punch_interface --out docs/figures/interface_pressure.png
#     bash run.sh python demos/plot_interface_pressure.py --results results/flat_punch
#
# Units: mm, N, MPa.

from __future__ import annotations

import argparse
import os
import sys

from _common import parse_known


def parse_args(argv):
    parser = argparse.ArgumentParser(description="Draw the interface pressure of an "
                                     "InterfaceWriter output (optionally run the punch first).",
                                     allow_abbrev=False)
    parser.add_argument("--results", default="results/flat_punch",
                        help="folder holding interface.xdmf and interface.h5")
    parser.add_argument("--step", type=int, default=None,
                        help="written step to draw (1-based); default the first step at the "
                        "largest load factor")
    parser.add_argument("--out", default="docs/figures/interface_pressure.png")
    parser.add_argument("--status", default=None, metavar="PNG",
                        help="also draw the status map and plastic-slip arrows into PNG")
    parser.add_argument("--run", action="store_true",
                        help="run the flat punch first and write its interface into --results")
    parser.add_argument("--overwrite", action="store_true",
                        help="with --run: replace the results of an earlier run in --results")
    parser.add_argument("--mesh-size", type=float, default=20.0)
    parser.add_argument("--contact-size", type=float, default=1.0)
    parser.add_argument("--order", type=int, default=2, choices=[1, 2])
    parser.add_argument("--steps", type=int, default=8, help="loading increments of --run")
    return parse_known(parser, argv)


# ## Optional: the run that writes the file
def run_punch(args, petsc_args):
    """Flat punch through InterfaceWriter into ``args.results`` (collective)."""
    import petsc4py

    petsc4py.init([sys.argv[0]] + petsc_args)  # before dolfinx: -rc_* options reach PETSc
    from mpi4py import MPI
    from petsc4py import PETSc

    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    from rough_contact.scenes import flat_punch

    from rough_contact.io import InterfaceWriter, prepare_output_dir
    from rough_contact.solver.loading import load_path, load_unload_factors

    comm = MPI.COMM_WORLD
    prepare_output_dir(args.results, comm, overwrite=args.overwrite)
    m = flat_punch.build(comm, mesh_size=args.mesh_size, contact_size=args.contact_size,
                         order=args.order, steps=args.steps)
    interface = m.interface
    writer = InterfaceWriter(args.results, interface, points=True, overwrite=args.overwrite)
    for inc in load_path(m.problem, m.solver, load_unload_factors(args.steps, 0),
                         verbose=False):
        writer.write(inc.load_factor)
        PETSc.Sys.Print(f"  load factor {inc.load_factor:.4f}: Fz = {inc.contact_force[2]:.6g} N, "
                        f"{inc.n_slipping} of {inc.n_points} points slipping", comm=comm)
    m.solver.destroy()
    PETSc.Sys.Print(f"{interface.n_points_global} interface points on "
                    f"{len(writer.surface.cells) if comm.rank == 0 else '?'} facets written to "
                    f"{args.results}/", comm=comm)
    return comm.rank == 0


# ## The picture, from the file
def draw(args):
    import numpy as np

    from rough_contact.io import plotting, read_interface_results

    res = read_interface_results(os.path.join(args.results, "interface.xdmf"))
    if res.cells is None:
        raise ValueError(f"{args.results}/interface.xdmf holds no facets ({res.cell_type})")
    n = len(res.times)
    k = (int(np.argmax(res.load_factors)) if args.step is None else args.step - 1)
    if not 0 <= k < n:
        raise ValueError(f"--step {args.step} is out of range: {n} steps written")
    p = res.field("pressure_MPa", k)
    x = res.points[res.cells]
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if res.cells.shape[1] == 4:
        area += 0.5 * np.linalg.norm(np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]), axis=1)
    force = float(area @ p)  # the facet averages integrate to the interface force exactly
    title = (f"contact pressure, load factor {res.load_factors[k]:.3g} (step {k + 1} of {n})\n"
             f"{len(res.cells)} facets, $\\int p\\,dA$ = {force:.4g} N")
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    plotting.plot_pressure_map(res.points, res.cells, p, title=title, path=args.out,
                               figsize=(6.4, 5.2))
    print(f"{args.out}: pressure {p.min():.4g} ... {p.max():.4g} MPa, int p dA = {force:.6g} N")
    if args.status:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(12.0, 5.0))
        FigureCanvasAgg(fig)
        ax1, ax2 = fig.subplots(1, 2)
        plotting.plot_status_map(res.points, res.cells, res.field("status", k), ax=ax1,
                                 title="status (majority of each facet's area)")
        plotting.plot_slip_quiver(res.points, res.field("plastic_slip_mm", k), cells=res.cells,
                                  ax=ax2, label="|plastic slip| [um]",
                                  title="plastic slip directions (u_foundation - u_punch)")
        fig.tight_layout()
        fig.savefig(args.status, dpi=150)
        print(f"{args.status}: status and plastic slip")


if __name__ == "__main__":
    ARGS, PETSC_ARGS = parse_args(sys.argv[1:])
    draw_here = True
    if ARGS.run:
        draw_here = run_punch(ARGS, PETSC_ARGS)  # under mpirun, rank 0 draws
    elif PETSC_ARGS:
        raise SystemExit(f"unrecognized arguments: {' '.join(PETSC_ARGS)} (PETSc options need "
                         "--run)")
    if draw_here:
        draw(ARGS)
