"""The flat punch's edge in plane strain: does the dissipation converge when the edge is resolved?

GetFEM's flat punch (bench_coulomb_punch.py) at mu = 0.5 slips in a strip along the punch's edge
that no 3D mesh here resolves (docs/punch_refinement.md). This benchmark solves the plane-strain
section of the same punch (punch 2a x hp = 20 x 10 mm on a 100 x 50 mm foundation, E = 200 GPa,
nu = 0.25, 2.5 MPa on the punch top, 16 loading and 15 unloading increments to 1/16 of the load,
isotropic Coulomb friction, exact contact and stick: dual-basis nodal multipliers updated inside
Newton), on meshes graded geometrically towards the edge down to ``--edge-size``
(``rough_contact.scenes.meshes.punch_section``: one hexahedron thick, u_y = 0 on both faces).

Per row: sizes, DOFs, interface points per layer (their x positions: the contact vertices for
the exact route), Newton iterations, CPU, the dissipation per
unit length of the edge at the peak and at the end [N mm / mm], the slip zone at the peak (the
largest distance from the edge of a slipping vertex in contact, and how many slip), and the
traction ratio |t_T| / p at the first vertices off the edge (for the stuck bonded edge it tends
to 0.5431, the ratio of Williams' first mode of the 270-degree free-free wedge).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_punch_section.py \\
        [--mu 0.5] [--edge-size 0.1 0.01 0.001] [--contact-size 0.7] [--mesh-size 10]
        [--edge-growth 0.2] [--k K] [--al-tol 1e-4] [--penalty] [--profile] [--csv FILE]

Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import sys
import time
import typing

import petsc4py
from _common import write_csv

petsc4py.init(sys.argv)   # -rc_* options reach PETSc (before dolfinx is imported)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.interface.enforcement import NewtonAugmentedLagrangian, Penalty  # noqa: E402
from rough_contact.interface.penalty import SoftplusPenalty  # noqa: E402
from rough_contact.scenes import flat_punch  # noqa: E402
from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402

A = 10.0            # punch half width [mm]
PRESSURE = 2.5      # on the punch top [MPa]
N_LOAD = 16
E = flat_punch.E    # both bodies [MPa]


def section_model(comm, mu, k, mesh_size, contact_size, edge_size, edge_growth, exact=True,
                  al_tol=1e-4, thickness=1.0):
    """The section's model (flat_punch.PunchModel) with the Coulomb law, exact or penalty."""
    section = flat_punch.punch_section_scene(comm, mesh_size=mesh_size,
                                            contact_size=contact_size, edge_size=edge_size,
                                            edge_growth=edge_growth, thickness=thickness)
    law = SoftplusPenalty(k_normal=k, width=1e-2 * PRESSURE / k, k_tangential=k, friction=mu)
    return flat_punch.build(
        comm, law=law, steps=N_LOAD, punch_scene=section,
        total_force=4 * PRESSURE * A * thickness,     # build() loads a quarter of it
        quadrature="gauss", points="nodal" if exact else "quadrature",
        basis="dual" if exact else "standard",
        enforcement=NewtonAugmentedLagrangian(tolerance=al_tol) if exact else Penalty(),
        solver_options=dict(linear_solver="mumps"))


class SlipZone(typing.NamedTuple):
    """The slip zone at one state (every rank gets the same)."""

    width: float         # largest edge distance of a slipping point in contact [mm]
    positions: int       # distinct edge distances of the slipping points (per layer)
    edge_share: float    # share of D on the points at the edge (nan without dissipation)
    near: list           # (d, |t_T| / p) at the three points nearest to the edge, off it


def slip_zone(interface, comm) -> SlipZone:
    """The slip zone of the interface's current state (collective)."""
    pf, x = interface.point_fields(), interface.point_coordinates()
    ratio = np.linalg.norm(pf.shear, axis=1) / np.maximum(pf.pressure, 1e-300)
    d, slip, Dw, ratio, p = (np.concatenate(comm.allgather(v)) for v in (
        A - x[:, 0], pf.slipping & pf.contact, pf.dissipation * pf.weight, ratio, pf.pressure))
    near = np.unique(np.round(d[(d > 1e-12) & (p > 0)], 12))[:3]
    total = Dw.sum()
    return SlipZone(float(d[slip].max(initial=0.0)), len(np.unique(np.round(d[slip], 12))),
                    float(Dw[d < 1e-12].sum() / total) if total > 0 else float("nan"),
                    [(dd, float(np.mean(ratio[np.abs(d - dd) < 1e-12]))) for dd in near])


def profile(interface, comm):
    """(d, p, |t_T|, slipping) of the points of one layer (the smallest y: the vertices at
    y = 0, or the first row of Gauss points) at the current state, by d. Collective."""
    pf, x = interface.point_fields(), interface.point_coordinates()
    y0 = comm.allreduce(float(x[:, 1].min(initial=np.inf)), op=MPI.MIN)
    keep = x[:, 1] < y0 + 1e-9
    cols = [A - x[keep, 0], pf.pressure[keep], np.linalg.norm(pf.shear[keep], axis=1),
            (pf.slipping & pf.contact)[keep].astype(float)]
    cols = [np.concatenate(comm.allgather(c)) for c in cols]
    order = np.argsort(cols[0])
    return np.array(cols).T[order]


def run(mu, k, mesh_size, contact_size, edge_size, edge_growth, exact=True, al_tol=1e-4,
        comm=MPI.COMM_WORLD, verbose=False, want_profile=False):
    t_wall = time.perf_counter()
    m = section_model(comm, mu, k, mesh_size, contact_size, edge_size, edge_growth, exact, al_tol)
    thickness = m.scene.dimensions["thickness"]
    factors = load_unload_factors(N_LOAD, N_LOAD - 1, final_factor=1.0 / N_LOAD)
    t0 = time.process_time()
    incs, peak_zone, prof = [], None, None
    for inc in load_path(m.problem, m.solver, factors, verbose=verbose):
        incs.append(inc)
        if inc.load_factor == 1.0:
            peak_zone = slip_zone(m.interface, comm)
            if want_profile:
                prof = profile(m.interface, comm)
    end_zone = slip_zone(m.interface, comm)
    cpu = comm.allreduce(time.process_time() - t0, op=MPI.SUM)
    peak = next(i for i in incs if i.load_factor == 1.0)
    d = np.concatenate(comm.allgather(A - m.interface.point_coordinates()[:, 0]))
    verts = len(np.unique(np.round(d, 12)))     # points per layer (x positions)
    out = dict(mu=mu, k=k, exact=exact, mesh_size=mesh_size, contact_size=contact_size,
               edge_size=edge_size, edge_growth=edge_growth, dofs=m.problem.num_dofs,
               vertices=verts, newton=sum(i.newton_total for i in incs),
               cutbacks=sum(i.cutbacks for i in incs), cpu=cpu,
               wall=time.perf_counter() - t_wall,
               D_peak=peak.dissipation / thickness, D_end=incs[-1].dissipation / thickness,
               zone_peak=peak_zone.width, slipping_peak=peak_zone.positions,
               edge_share_peak=peak_zone.edge_share, zone_end=end_zone.width,
               slipping_end=end_zone.positions, ratio_near=peak_zone.near)
    m.solver.destroy()
    return out, prof


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, nargs="+", default=[0.5])
    ap.add_argument("--edge-size", type=float, nargs="+", default=[0.1, 0.01, 0.001],
                    help="element size at the edge [mm], (0, contact size]")
    ap.add_argument("--contact-size", type=float, nargs="+", default=[0.7],
                    help="element size on the contact away from the edge [mm]")
    ap.add_argument("--mesh-size", type=float, nargs="+", default=[10.0],
                    help="element size away from the contact [mm]")
    ap.add_argument("--edge-growth", type=float, default=0.2,
                    help="element size growth per mm from the edge, (0, 1]")
    ap.add_argument("--k", type=float, default=None,
                    help="k_N = k_T [MPa/mm]; default per row max(1e9, E / (20 edge size)): "
                    "the exact route's multiplier updates converge at a rate set by k against "
                    "the stiffness E / h of the smallest elements (k = 1e7 fails at 3e-4 mm)")
    ap.add_argument("--al-tol", type=float, default=1e-4)
    ap.add_argument("--penalty", action="store_true",
                    help="the plain Gauss penalty instead of exact enforcement")
    ap.add_argument("--profile", action="store_true",
                    help="print p, |t_T| and slip against the edge distance at the peak")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--verbose", action="store_true")
    args, _petsc = ap.parse_known_args(argv)
    comm = MPI.COMM_WORLD
    head = (f"{'mu':>4} {'h':>5} {'h_c':>5} {'h_e':>8} {'k':>7} {'DOFs':>6} {'verts':>5} {'Newton':>6} "
            f"{'cutb':>4} {'CPU s':>7} {'D peak/len':>11} {'D end/len':>11} {'zone pk':>9} "
            f"{'slip pk':>7} {'edge shr':>8} {'zone end':>9} {'slip end':>8}  ratio near edge")
    PETSc.Sys.Print(head)
    rows = []
    for mu in args.mu:
        for h in args.mesh_size:
            for hc in args.contact_size:
                for he in args.edge_size:
                    k = args.k if args.k is not None else max(1e9, E / (20.0 * he))
                    r, prof = run(mu, k, h, hc, he, args.edge_growth, not args.penalty,
                                  args.al_tol, comm, args.verbose, args.profile)
                    near = " ".join(f"{d:.2e}:{q:.4f}" for d, q in r.pop("ratio_near"))
                    PETSc.Sys.Print(
                        f"{mu:4.2f} {h:5.2f} {hc:5.2f} {he:8.1e} {k:7.1e} {r['dofs']:6d} "
                        f"{r['vertices']:5d} {r['newton']:6d} {r['cutbacks']:4d} "
                        f"{r['cpu']:7.1f} {r['D_peak']:11.5e} {r['D_end']:11.5e} "
                        f"{r['zone_peak']:9.3e} {r['slipping_peak']:7d} "
                        f"{r['edge_share_peak']:8.3f} {r['zone_end']:9.3e} "
                        f"{r['slipping_end']:8d}  {near}")
                    r["ratio_near"] = near
                    rows.append(r)
                    if prof is not None:
                        PETSc.Sys.Print(f"  {'d [mm]':>10} {'p [MPa]':>10} {'|t_T|/p':>8} slip")
                        for d, p, t, s in prof[prof[:, 0] < 5 * hc]:
                            PETSc.Sys.Print(f"  {d:10.3e} {p:10.4e} "
                                            f"{t / p if p > 0 else 0.0:8.4f} {int(s)}")
    if args.csv and comm.rank == 0:
        write_csv(args.csv, rows)


if __name__ == "__main__":
    main()
