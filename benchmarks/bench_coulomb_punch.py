"""GetFEM's flat-punch benchmark with the Coulomb penalty law: Newton iterations, CPU, dissipation.

Quarter model of a 20 x 20 x 10 mm punch on a 100 x 100 x 50 mm foundation (E = 200 GPa,
nu = 0.25 both), foundation bottom clamped, symmetry planes, uniform pressure 2.5 MPa on the
punch top (1000 N on the full punch), 16 loading increments and 16 unloading ones down to 1/16
of the load (a punch held only by a penalty contact has no equilibrium at zero load),
isotropic Coulomb friction (``SoftplusPenalty``). Prints per run: DOFs, interface points,
Newton iterations (all attempts, including failed ones), cutbacks, the largest count in one
increment, CPU time, the dissipation at the peak and at the end, and at the peak the largest
k_N |g| over the points in contact (kg/t) and k_T |s - s_p| over the sticking ones (kTs/t),
relative to the largest traction (about 1 for a penalty, the tolerance for exact enforcement).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_coulomb_punch.py \\
        [--levels 1 2 3] [--mu 0.2 0.5] [--k 1e7] [--predictor none secant]
        [--quadrature gauss vertex nodal] [--reversal-stiffness 0 1] [--augmented 0 1 2 3]
        [--al-tol 1e-3] [--basis standard dual] [--residual-ratio 1e-2] [--ssn-r R]
        [--continuation none 100,10] [--after 10] [--linear-solver auto mumps hypre] [--csv FILE]
        [--mesh-size H] [--contact-size HC] [--edge-size HE] [--edge-band B] [--edge-growth G]
        [--order 1] [--transition T] [--slip-map]

Levels (P1; mesh and contact size in LEVELS): 1 ~4.5 k DOFs, 2 ~26 k, 3 ~73 k, 4 ~99 k (the size
of GetFEM's finest run). ``--mesh-size`` (bulk element size, (0, 50] mm) and ``--contact-size``
(element size on the contact patch, (0, min(mesh size, 10)] mm) replace the level's sizes, for
refining the bulk and the contact separately (docs/punch_refinement.md); every row shows the
sizes used, the DOFs and the vertices of the punch's contact face. ``--edge-size`` (element
size at the punch's free edge, (0, contact size] mm) and ``--edge-band`` (the distance from
the edge within which it applies, (0, 10] mm, default the contact size) grade the mesh towards
the edge (``rough_contact.scenes.meshes.flat_punch``).
Units: mm, N, MPa.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import petsc4py
from _common import write_csv

petsc4py.init(sys.argv)   # -rc_* options reach PETSc (before dolfinx is imported)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from rough_contact.fem.mesh import facet_vertex_coordinates
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.interface.enforcement import (AugmentedLagrangian, NewtonAugmentedLagrangian,
                                                 SemismoothNewton,
                                                 Penalty)
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.scenes import flat_punch
from rough_contact.scenes.meshes.flat_punch import edge_grading
from rough_contact.solver.loading import LoadStepError, load_path, load_unload_factors
from rough_contact.solver.snes import Continuation

# (mesh size, contact size) [mm]
LEVELS = {1: (10.0, 0.7), 2: (5.0, 0.3), 3: (3.3, 0.2), 4: (3.3, 0.165)}
N_LOAD = 16
FOUNDATION_HALF_WIDTH = 50.0   # [mm]: the largest mesh size that means anything
PUNCH_HALF_WIDTH = 10.0        # [mm]: the largest contact size (one element across the face)


def level_sizes(level: int, mesh_size=None, contact_size=None) -> tuple:
    """(mesh size, contact size) [mm] of ``level`` (LEVELS), either replaced when given.
    Raises ValueError naming the option, its value and the valid range."""
    h, hc = LEVELS[level]
    h = h if mesh_size is None else mesh_size
    hc = hc if contact_size is None else contact_size
    if not (math.isfinite(h) and 0.0 < h <= FOUNDATION_HALF_WIDTH):
        raise ValueError(f"--mesh-size = {h!r} mm is invalid: valid range (0, "
                         f"{FOUNDATION_HALF_WIDTH:g}] mm (the foundation's half width)")
    top = min(h, PUNCH_HALF_WIDTH)
    if not (math.isfinite(hc) and 0.0 < hc <= top):
        raise ValueError(f"--contact-size = {hc!r} mm is invalid: valid range (0, {top:g}] mm "
                         f"(at most the mesh size, {h:g} mm"
                         + (f", of level {level}" if mesh_size is None else "")
                         + f", and the punch's half width, {PUNCH_HALF_WIDTH:g} mm)")
    return h, hc


def contact_vertices(scene, comm) -> int:
    """Global number of vertices of the punch's contact face (the first contact surface)."""
    xyz = facet_vertex_coordinates(scene, scene.contact_pair[0]).reshape(-1, 3)
    allxyz = np.concatenate(comm.allgather(xyz))
    return len(np.unique(np.round(allxyz, 9), axis=0))


def run(level: int, mu: float, k: float, width: float, predictor: str, quadrature="gauss",
        comm=MPI.COMM_WORLD, verbose=False, reversal_stiffness=1.0, augmented=False,
        al_tol=1e-3, continuation=None, linear_solver="auto", residual_ratio=1e-2,
        basis="standard", mesh_size=None, contact_size=None, edge_size=None,
        edge_band=None, ssn_r=None, edge_growth=None, order=1, transition=None,
        want_slip_map=False) -> dict:
    mesh_size, contact_size = level_sizes(level, mesh_size, contact_size)
    edge_size, edge_band = edge_grading(contact_size, PUNCH_HALF_WIDTH, edge_size, edge_band,
                                        edge_growth=edge_growth)
    law = SoftplusPenalty(k_normal=k, width=width, k_tangential=k, friction=mu,
                          reversal_stiffness=reversal_stiffness)
    if augmented == 3:     # Alart-Curnier's semismooth Newton, tractions condensed (dual P1)
        enforcement = SemismoothNewton(r_normal=ssn_r)
    elif augmented == 2:   # multipliers updated inside the Newton iteration (nodal points)
        enforcement = NewtonAugmentedLagrangian(tolerance=al_tol, residual_ratio=residual_ratio)
    elif augmented:
        enforcement = AugmentedLagrangian(tolerance=al_tol)
    else:
        enforcement = Penalty()
    m = flat_punch.build(comm, mesh_size=mesh_size, contact_size=contact_size, order=order,
                         load_half_width=10.0, law=law, steps=N_LOAD,
                         quadrature="gauss" if quadrature == "nodal" else quadrature,
                         points="nodal" if quadrature == "nodal" else "quadrature",
                         basis=basis, enforcement=enforcement, edge_size=edge_size,
                         edge_band=edge_band, edge_growth=edge_growth, transition=transition,
                         solver_options=dict(continuation=continuation,
                                             linear_solver=linear_solver))
    factors = load_unload_factors(N_LOAD, N_LOAD - 1, final_factor=1.0 / N_LOAD)
    t0 = time.process_time()
    exact = (float("nan"), float("nan"))
    smap = []
    incs = []
    kwargs = {"predictor": predictor}
    failed = ""
    try:
        for inc in load_path(m.problem, m.solver, factors, verbose=verbose, **kwargs):
            incs.append(inc)
            if inc.load_factor == 1.0:
                exact = _exactness(m.interface, law, comm)
                if want_slip_map:
                    smap = slip_map(m.interface, comm)
    except LoadStepError as exc:     # reported as a row: the run did not complete
        failed = f"LoadStepError at load factor {exc.load_factor:.6g}"
        PETSc.Sys.Print(f"  FAILED: {exc}")
    cpu = comm.allreduce(time.process_time() - t0, op=MPI.SUM)
    peak = next((i for i in incs if i.load_factor == 1.0), None)
    cont = m.solver.continuation
    out = dict(level=level, mesh_size=mesh_size, contact_size=contact_size,
               dofs=m.problem.num_dofs, vertices=contact_vertices(m.scene, comm),
               points=m.interface.n_points_global, mu=mu,
               k=k, predictor=predictor, quadrature=quadrature,
               reversal_stiffness=reversal_stiffness, augmented=augmented, al_tol=al_tol,
               continuation=("none" if cont is None else
                             ",".join(f"{f:g}" for f in cont.factors)
                             + ("" if cont.after is None else f"/{cont.after}")),
               linear_solver=m.solver.option_set, basis=basis,
               al_updates=sum(i.augmentations for i in incs),
               newton_updates=(m.interface.newton_updates
                               if isinstance(m.interface, NodalContactInterface) else 0),
               newton=sum(i.newton_total for i in incs),
               solves=len(incs) + sum(i.failed_attempts for i in incs),
               cutbacks=sum(i.cutbacks for i in incs),
               max_its=max((i.iterations for i in incs), default=0), cpu=cpu,
               D_peak=peak.dissipation if peak else float("nan"),
               D_end=float("nan") if failed else incs[-1].dissipation,
               slip_peak=peak.n_slipping / max(peak.n_points, 1) if peak else float("nan"),
               gap_peak=exact[0], stick_peak=exact[1],
               failed=failed,
               edge_size=float("nan") if edge_size is None else edge_size,
               edge_band=float("nan") if edge_band is None else edge_band,
               edge_growth=float("nan") if edge_growth is None else edge_growth, order=order,
               transition=float("nan") if transition is None else transition,
               slip_map=smap)
    m.solver.destroy()
    return out


SLIP_MAP_BINS = (0.0, 5.0, 8.0, 9.0, 9.5, 9.9, 9.99, PUNCH_HALF_WIDTH)


def slip_map(interface, comm, bins=SLIP_MAP_BINS) -> list:
    """Where along the punch's free edges the dissipation lies, at the current state
    (collective). Each interface point is assigned to its nearer free edge (x = a or y = a of
    the quarter): d = a - max(x, y) is its distance to that edge and s = min(x, y) its
    position along it (s = a is the corner). Per bin [s0, s1) of ``bins``: (s0, s1, share of
    the accumulated dissipation, number of slipping points, the largest d of a slipping point
    [mm]); the last bin includes s = a."""
    pf, x = interface.point_fields(), interface.point_coordinates()
    d, s, slip, Dw = (np.concatenate(comm.allgather(v)) for v in (
        PUNCH_HALF_WIDTH - np.maximum(x[:, 0], x[:, 1]), np.minimum(x[:, 0], x[:, 1]),
        pf.slipping & pf.contact, pf.dissipation * pf.weight))
    total = Dw.sum()
    which = np.clip(np.searchsorted(bins, s, side="right") - 1, 0, len(bins) - 2)
    rows = []
    for b in range(len(bins) - 1):
        inb = which == b
        rows.append((bins[b], bins[b + 1],
                     float(Dw[inb].sum() / total) if total > 0 else float("nan"),
                     int(np.count_nonzero(slip & inb)),
                     float(d[slip & inb].max(initial=0.0))))
    return rows


def _exactness(interface, law, comm) -> tuple:
    """At the current (converged) state: the largest k_N |g| over the points in contact and
    the largest k_T |s - s_p| (the elastic slip) over the sticking ones, both relative to the
    largest traction magnitude [-]. About 1 for a penalty (its compliance), about the
    augmentation tolerance for exact enforcement."""
    pf = interface.point_fields()
    stick = pf.contact & ~pf.slipping
    t = np.hypot(pf.pressure, np.linalg.norm(pf.shear, axis=1))
    vals = np.array([np.max(law.k_normal * np.abs(pf.gap[pf.contact]), initial=0.0),
                     np.max(law.k_tangential * np.linalg.norm(
                         (pf.slip - pf.plastic_slip)[stick], axis=1), initial=0.0),
                     np.max(t, initial=0.0)])
    comm.Allreduce(MPI.IN_PLACE, vals, op=MPI.MAX)
    return vals[0] / vals[2], vals[1] / vals[2]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[1], choices=sorted(LEVELS))
    ap.add_argument("--mu", type=float, nargs="+", default=[0.2])
    ap.add_argument("--k", type=float, nargs="+", default=[1e7], help="penalty k_N = k_T [MPa/mm]")
    ap.add_argument("--width", type=float, default=None,
                    help="softplus width [mm] (default 1e-2 * 2.5 MPa / k: p(0) ~ 0.7 %% of p)")
    ap.add_argument("--predictor", nargs="+", default=["secant"], choices=["secant", "none"])
    ap.add_argument("--quadrature", nargs="+", default=["gauss"], choices=["gauss", "vertex", "nodal"],
                    help="interface points: the Gauss rule's, the vertex rule's (P1), or the "
                    "nodal point set through the Gauss rule (rough_contact.fem.nodal)")
    ap.add_argument("--reversal-stiffness", type=float, nargs="+", default=[1.0],
                    help="SoftplusPenalty.reversal_stiffness (0 = consistent tangent everywhere)")
    ap.add_argument("--augmented", type=int, nargs="+", default=[0], choices=[0, 1, 2, 3],
                    help="1 = augmented Lagrangian (Uzawa) on top of the penalty; 3 = "
                    "Alart-Curnier's semismooth Newton with the tractions condensed "
                    "(SemismoothNewton: --quadrature nodal --basis dual, P1; augmentation: "
                    "--ssn-r); 2 = the "
                    "multipliers updated inside the Newton iteration (NewtonAugmentedLagrangian, "
                    "--quadrature nodal only)")
    ap.add_argument("--al-tol", type=float, default=1e-3,
                    help="AugmentedLagrangian.tolerance")
    ap.add_argument("--basis", nargs="+", default=["standard"], choices=["standard", "dual"],
                    help="the nodal set's vertex weights (NodalContactInterface basis): the "
                    "vertex functions or their dual (biorthogonal) basis")
    ap.add_argument("--ssn-r", type=float, default=None,
                    help="SemismoothNewton.r_normal (--augmented 3) [MPa/mm]; default: per vertex, "
                    "the bulk stiffness per area")
    ap.add_argument("--residual-ratio", type=float, default=1e-2,
                    help="NewtonAugmentedLagrangian.residual_ratio (--augmented 2)")
    ap.add_argument("--continuation", nargs="+", default=["100,10"],
                    help="penalty continuation: softening factors (default 100,10, the "
                         "solver's) or none (rough_contact.solver.snes.Continuation)")
    ap.add_argument("--after", default="none",
                    help="Newton iterations with the law itself before the continuation "
                         "(none: after a failed solve, the default of Continuation)")
    ap.add_argument("--linear-solver", nargs="+", default=["auto"],
                    help="SNESSolver linear_solver: auto (MUMPS up to the DOF threshold), "
                         "mumps, hypre, ...")
    ap.add_argument("--mesh-size", type=float, default=None,
                    help="bulk element size [mm], replacing the level's (LEVELS); (0, 50]")
    ap.add_argument("--contact-size", type=float, default=None,
                    help="element size on the contact patch [mm], replacing the level's; "
                    "(0, min(mesh size, 10)]")
    ap.add_argument("--edge-size", type=float, default=None,
                    help="element size at the punch's free edge [mm] (edge grading; default "
                    "none); (0, contact size]")
    ap.add_argument("--edge-band", type=float, default=None,
                    help="distance from the edge within which --edge-size applies [mm]; "
                    "(0, 10], default the contact size")
    ap.add_argument("--edge-growth", type=float, default=None,
                    help="growth of the element size per mm beyond the edge band, (0, 1] "
                    "(a geometric grading of ratio about 1 + growth); default twice the patch "
                    "field's rate")
    ap.add_argument("--transition", type=float, default=None,
                    help="distance over which the element size grows from the contact size to "
                    "the mesh size [mm], > 0; default 2 x the punch half width (20 mm)")
    ap.add_argument("--order", type=int, default=1, choices=[1, 2],
                    help="element order (P1 is GetFEM's; P2 for the bulk's own error)")
    ap.add_argument("--slip-map", action="store_true",
                    help="print, after each row, where along the free edges the dissipation "
                    "and the slip zone lie at the peak (slip_map)")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--verbose", action="store_true")
    args, _petsc = ap.parse_known_args(argv)   # the rest goes to PETSc
    if args.mesh_size is not None and args.contact_size is not None and len(args.levels) > 1:
        ap.error(f"--mesh-size and --contact-size together replace both sizes of every level: "
                 f"give one level, not --levels {' '.join(map(str, args.levels))}")
    if args.transition is not None and not (math.isfinite(args.transition)
                                            and args.transition > 0):
        ap.error(f"--transition = {args.transition} is invalid; valid range: > 0 mm")
    for level in args.levels:     # refused before any mesh is built
        try:
            edge_grading(level_sizes(level, args.mesh_size, args.contact_size)[1],
                         PUNCH_HALF_WIDTH, args.edge_size, args.edge_band,
                         edge_growth=args.edge_growth)
        except ValueError as exc:
            ap.error(str(exc))
    rows = []
    head = (f"{'level':>5} {'h':>5} {'h_c':>5} {'h_e/band':>10} {'DOFs':>7} {'verts':>6} {'points':>6} "
            f"{'mu':>4} {'k':>7} {'rev':>4} "
            f"{'predictor':>9} {'AL':>2} {'upd':>4} {'Nupd':>5} {'cont':>10} {'linear':>6} "
            f"{'Newton':>6} {'solves':>6} {'cutb':>4} {'max/inc':>7} {'CPU s':>7} "
            f"{'D peak':>10} {'D end':>10} {'slip':>5} {'kg/t':>8} {'kTs/t':>8}")
    PETSc.Sys.Print(head)
    for level in args.levels:
        for mu in args.mu:
            for k in args.k:
                for pred, quad, rs, al, co, ls, basis in [
                        (a, b, c, d, e, f, g) for a in args.predictor for b in args.quadrature
                        for c in args.reversal_stiffness for d in args.augmented
                        for e in args.continuation for f in args.linear_solver
                        for g in args.basis]:
                    if basis == "dual" and quad != "nodal":
                        continue
                    w = args.width if args.width is not None else 1e-2 * 2.5 / k
                    cont = (None if co == "none" else Continuation(
                        tuple(float(x) for x in co.split(",")),
                        None if args.after == "none" else int(args.after)))
                    if al >= 2 and quad != "nodal":
                        continue       # the in-Newton update is the nodal point set's
                    r = run(level, mu, k, w, pred, quad, verbose=args.verbose,
                            reversal_stiffness=rs, augmented=al, al_tol=args.al_tol,
                            continuation=cont, linear_solver=ls,
                            residual_ratio=args.residual_ratio, basis=basis,
                            mesh_size=args.mesh_size, contact_size=args.contact_size,
                            edge_size=args.edge_size, edge_band=args.edge_band,
                            ssn_r=args.ssn_r, edge_growth=args.edge_growth,
                            order=args.order, transition=args.transition,
                            want_slip_map=args.slip_map)
                    rows.append(r)
                    label = pred + "/" + quad[0] + ("*" if basis == "dual" else "")
                    PETSc.Sys.Print(
                        f"{r['level']:5d} {r['mesh_size']:5.3g} {r['contact_size']:5.3g} "
                        + ("         -" if args.edge_size is None else
                           f"{r['edge_size']:5.3g}/{r['edge_band']:4.3g}")
                        + " "
                        f"{r['dofs']:7d} {r['vertices']:6d} {r['points']:6d} {mu:4.2f} {k:7.1e} "
                        f"{rs:4.2g} {label:>9} {al:2d} {r['al_updates']:4d} "
                        f"{r['newton_updates']:5d} "
                        f"{r['continuation']:>10} {r['linear_solver']:>6} "
                        f"{r['newton']:6d} "
                        f"{r['solves']:6d} {r['cutbacks']:4d} "
                        f"{r['max_its']:7d} {r['cpu']:7.1f} {r['D_peak']:10.4e} "
                        f"{r['D_end']:10.4e} {r['slip_peak']:5.2f} {r['gap_peak']:8.1e} "
                        f"{r['stick_peak']:8.1e}"
                        + (f"  FAILED ({r['failed']})" if r["failed"] else ""))
                    if r["slip_map"]:
                        PETSc.Sys.Print("      s along the edge [mm]   D share   slipping   "
                                        "slip zone width [mm]")
                        for s0, s1, share, n, w in r["slip_map"]:
                            PETSc.Sys.Print(f"      [{s0:5.2f}, {s1:5.2f})   {share:9.4f} "
                                            f"{n:9d}   {w:11.4g}")
    if args.csv and MPI.COMM_WORLD.rank == 0:
        write_csv(args.csv, [{k: v for k, v in r.items() if k != "slip_map"} for r in rows])
    return rows


if __name__ == "__main__":
    main()
