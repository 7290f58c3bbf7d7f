# # Accuracy against cost of the FE rough-contact model: one knob at a time
#
# Two examples: the flat punch (paper section 9.2, friction case (b), elasto-plastic normal law,
# load to 1000 N then unload) and the beam on a rigid base (section 9.1, Table 4 case 1, elastic
# normal law, friction b, 4.9 N -> 1962 N).  For each knob (mesh size, element order, facet
# quadrature degree, load increments, normal-law table accuracy rtol, elastic vs elasto-plastic
# normal law) a sweep is run with every OTHER knob at the demo's default; the error of each level
# is measured against the finest level of the same sweep (the knob's own converged reference),
# and a separate "fine" run with all knobs at their finest level gives the error of the demo
# defaults against an all-fine reference.
#
# Quantities (all in the package units mm, N, MPa):
# * punch: approach = -mean u_z over the loaded patch of the punch top at the peak load [mm];
#   g_centre = area-mean normal interface jump over the central 2 x 2 mm bin at the peak [mm];
#   pressure distribution = 6 x 6 cosine-mode coefficients of the pressure over the quarter
#   patch at the peak; total frictional dissipation D after unloading [N mm];
# * beam: uN at the centre (x = 0, y = 0) at 1962 N relative to the 4.9 N state [mm] (the demo's
#   definition); pressure distribution = 25 cosine modes along the half length at 1962 N.
# The distribution error is the relative L2 norm ||c - c_ref|| / ||c_ref|| of the mode
# coefficients (bin means, 5 x 5 / 25 bins, are also stored: they carry a bin-assignment
# artefact of 1-2 % when the interface points differ, so they are not used for errors).
#
# Seating: the reference separation h0 is held at the demo default (p_seat of 16 increments for
# the punch, the 4.9 N initial pressure for the beam) for every run, so the increment knob
# measures the path discretisation only.
#
# Wall time = mesh generation + normal-law table + set-up + the whole load path (the normal-law
# table is cached in the process and its first build time is charged to every run using it).
#
# Run:
#     python benchmarks/accuracy_vs_cost.py --quick --csv /tmp/q.csv --doc /tmp/q.md \
#         --figure /tmp/q.png                                       # ~3 min, smoke test
#     python benchmarks/accuracy_vs_cost.py                         # full study (serial)
#     mpirun -n 2 python benchmarks/accuracy_vs_cost.py --knobs mesh  # mesh knob on 2 ranks
#     python benchmarks/accuracy_vs_cost.py --report                # table + figure from the CSV
# Rows are appended to the CSV after every run (a crash loses nothing); runs already present
# (same example/knob/level/ranks/mode) are skipped, so an interrupted study can be resumed.

from __future__ import annotations

import argparse
import csv
import gc
import logging
import os
import sys
import time

import petsc4py

if __name__ == "__main__":
    _PARSER = argparse.ArgumentParser(description=__doc__ or "accuracy vs cost",
                                      allow_abbrev=False)
    _PARSER.add_argument("--quick", action="store_true", help="small sweep (smoke test)")
    _PARSER.add_argument("--examples", nargs="+", default=["beam", "punch"],
                         choices=["beam", "punch"])
    _PARSER.add_argument("--knobs", nargs="+", default=None,
                         help="subset of: fine mesh order quadrature steps rtol normal_law")
    _PARSER.add_argument("--csv", default="docs/accuracy_vs_cost.csv")
    _PARSER.add_argument("--doc", default="docs/accuracy_vs_cost.md")
    _PARSER.add_argument("--figure", default="docs/figures/accuracy_vs_cost.png")
    _PARSER.add_argument("--report", action="store_true", help="only write table + figure")
    _PARSER.add_argument("--no-report", action="store_true")
    _PARSER.add_argument("--merge-from", default=None,
                         help="append the rows of this CSV (e.g. an earlier pass) whose "
                         "(mode, example, knob, level, ranks) is not yet in --csv, then report")
    _PARSER.add_argument("--max-minutes", type=float, default=None,
                         help="skip the remaining runs once this much time has passed")
    ARGS, _PETSC = _PARSER.parse_known_args(sys.argv[1:])
    petsc4py.init([sys.argv[0]] + _PETSC)
else:
    petsc4py.init()

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from dolfinx import fem  # noqa: E402


from rough_contact.io import gather_points  # noqa: E402
from rough_contact.scenes import beam as beam_demo  # noqa: E402
from rough_contact.scenes import flat_punch as punch_demo  # noqa: E402
from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402

logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

# ## Defaults of the demos and the sweeps
DEFAULTS = {
    "punch": dict(mesh=(10.0, 1.0), order=1, quadrature=None, steps=16, rtol=1e-4,
                  normal_law="elasto-plastic"),
    "beam": dict(mesh=(40.0, 5.0), order=2, quadrature=None, steps=16, rtol=1e-4,
                 normal_law="elastic"),
}
# Levels per knob, coarse -> fine; the last one is the knob's own reference.  normal_law has no
# "finer" level: its "error" is the model difference against the demo's default law.
SWEEPS_FULL = {
    "punch": dict(mesh=[(20.0, 2.0), (10.0, 1.0), (7.0, 0.7), (5.0, 0.5), (3.5, 0.35)],
                  order=[1, 2], quadrature=[1, 2, 4], steps=[4, 8, 16, 32, 64],
                  rtol=[1e-2, 1e-3, 1e-4, 1e-6], normal_law=["elastic", "elasto-plastic"],
                  mesh_p2=[(20.0, 2.0), (14.0, 1.4), (10.0, 1.0)]),
    "beam": dict(mesh=[(80.0, 10.0), (60.0, 7.5), (40.0, 5.0), (20.0, 2.5)],
                 order=[1, 2], quadrature=[2, 4, 6], steps=[4, 8, 16, 32, 64],
                 rtol=[1e-2, 1e-3, 1e-4, 1e-6], normal_law=["elasto-plastic", "elastic"]),
}
SWEEPS_QUICK = {
    "punch": dict(mesh=[(20.0, 2.0), (14.0, 1.4)], order=[1], quadrature=[1, 2], steps=[4, 8],
                  rtol=[1e-2, 1e-4], normal_law=["elastic", "elasto-plastic"],
                  mesh_p2=[(20.0, 2.0)]),
    "beam": dict(mesh=[(80.0, 10.0), (60.0, 7.5)], order=[1, 2], quadrature=[2, 4],
                 steps=[4, 8], rtol=[1e-2, 1e-4], normal_law=["elasto-plastic", "elastic"]),
}
# All-fine reference (every knob at its finest level); quick mode uses its own small one.
FINE_FULL = {"punch": dict(mesh=(5.0, 0.5), order=1, quadrature=4, steps=32, rtol=1e-6),
             "beam": dict(mesh=(20.0, 2.5), order=2, quadrature=6, steps=64, rtol=1e-6)}
FINE_QUICK = {"punch": dict(mesh=(14.0, 1.4), steps=8), "beam": dict(mesh=(60.0, 7.5), steps=8)}
KNOBS = ("fine", "mesh", "order", "quadrature", "steps", "rtol", "normal_law", "mesh_p2")
BASE_QUICK = {"punch": dict(mesh=(20.0, 2.0), steps=4), "beam": dict(mesh=(80.0, 10.0), steps=4)}

PUNCH_BINS = 5  # per axis over the 10 x 10 mm quarter patch
BEAM_BINS = 25  # along the 250 mm half length
PUNCH_MODES = 6  # cosine modes per axis over the quarter patch (6 x 6)
BEAM_MODES = 25  # cosine modes along the half length (uniform across the width)

# ## Normal-law tables (cached; build time charged to every run that uses them)
_LAW_CACHE: dict = {}


def normal_law(comm, example, kind, rtol):
    """NormalLaw of the example's surface; returns (law, build seconds). Collective."""
    key = (example, kind, rtol)
    if key not in _LAW_CACHE:
        comm.Barrier()
        t0 = time.perf_counter()
        law = None
        if comm.rank == 0:
            from rough_contact.micro.asperity import AsperityMaterial
            from rough_contact.interface.normal import NormalLaw
            from rough_contact.surface import SpectralMoments

            if example == "punch":
                surface = SpectralMoments(**punch_demo.MOMENTS_UM, unit="um")
                E_star = punch_demo.effective_modulus(punch_demo.E, punch_demo.NU,
                                                      punch_demo.E, punch_demo.NU)
                nu, plastic = punch_demo.NU, punch_demo.PLASTIC
            else:
                m00 = beam_demo.CASES[1][0]
                surface = SpectralMoments(m00=m00, **beam_demo.MOMENTS_UM, unit="um")
                E_star, nu, plastic = beam_demo.E_STAR, beam_demo.NU1, beam_demo.PLASTIC
            if kind == "elastic":
                law = NormalLaw.elastic(surface, E_star, rtol=rtol)
            else:
                law = NormalLaw.elasto_plastic(
                    surface, AsperityMaterial(E_star=E_star, nu=nu, **plastic), rtol=rtol)
        law = comm.bcast(law, root=0)
        _LAW_CACHE[key] = (law, comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
    return _LAW_CACHE[key]


def _modes(pts, p, w, lx, ly, n_modes):
    """Cosine-mode coefficients of the pressure: c_mn = int p cos(m pi x/lx) cos(n pi y/ly) dA
    / int cos^2 (n_modes[0] x n_modes[1] values, MPa) - the pressure field filtered to smooth
    modes; the quadrature of a smooth weight has no bin-assignment error. Cosines fit the
    symmetry planes x = 0 / y = 0 of the quarter/half models."""
    cx = np.cos(np.outer(np.arange(n_modes[0]), np.pi * pts[:, 0] / lx))
    cy = np.cos(np.outer(np.arange(n_modes[1]), np.pi * pts[:, 1] / ly))
    c = np.einsum("ip,jp,p->ij", cx, cy, p * w)
    norm = np.outer(np.where(np.arange(n_modes[0]) == 0, 1.0, 0.5),
                    np.where(np.arange(n_modes[1]) == 0, 1.0, 0.5)) * lx * ly
    return (c / norm).ravel()


def _bin_pressure(comm, interface, edges_x, edges_y, coord=(0, 1), modes=None):
    """Mean pressure per bin (force in bin / bin area) on rank 0, None elsewhere. Collective.

    Also returns the centre-bin mean gap and (if ``modes = (lx, ly, (nx, ny))``) the cosine-mode
    coefficients of the pressure (see ``_modes``).
    """
    pf = interface.point_fields()
    pts, f = gather_points(comm, interface.point_coordinates(),
                           {"p": pf.pressure, "w": pf.weight, "g": pf.gap})
    if comm.rank != 0:
        return None, None, None
    ix = np.clip(np.searchsorted(edges_x, pts[:, coord[0]], side="right") - 1, 0,
                 len(edges_x) - 2)
    iy = np.clip(np.searchsorted(edges_y, pts[:, coord[1]], side="right") - 1, 0,
                 len(edges_y) - 2)
    nb = (len(edges_x) - 1, len(edges_y) - 1)
    force = np.zeros(nb)
    np.add.at(force, (ix, iy), f["p"] * f["w"])
    area = np.outer(np.diff(edges_x), np.diff(edges_y))
    centre = (ix == 0) & (iy == 0)
    g_centre = float(np.sum(f["g"][centre] * f["w"][centre]) / np.sum(f["w"][centre]))
    coeffs = None
    if modes is not None:
        lx, ly, nm = modes
        coeffs = _modes(pts[:, list(coord)], f["p"], f["w"], lx, ly, nm)
    return (force / area).ravel(), g_centre, coeffs


class _Path:
    """The increments of a load path (iterate over it), counting the Newton iterations and the
    largest relative force-balance error |Fz_contact + Fz_applied| / |Fz_applied|."""

    def __init__(self, problem, solver, factors):
        self.problem, self.solver, self.factors = problem, solver, factors
        self.newton, self.max_force_error = 0, 0.0

    def __iter__(self):
        for inc in load_path(self.problem, self.solver, self.factors, verbose=False):
            self.newton += inc.iterations
            self.max_force_error = max(self.max_force_error,
                                       abs(inc.contact_force[2] + inc.applied_force[2])
                                       / abs(inc.applied_force[2]))
            yield inc

    def result(self, comm, interface, times, **figures):
        """One run's row: ``figures``, sizes, Newton, force error and times (``times`` = (start,
        start of the solve, mesh, law) [s]); destroys the solver. Collective."""
        t0, t1, t_mesh, t_law = times
        res = dict(figures, num_dofs=self.problem.num_dofs, n_points=interface.n_points_global,
                   newton=self.newton, max_force_error=self.max_force_error, t_mesh=t_mesh,
                   t_law=t_law, t_solve=time.perf_counter() - t1)
        self.solver.destroy()
        comm.Barrier()
        res["wall_time"] = time.perf_counter() - t0 + t_law
        return res


# ## The punch
def run_punch(comm, mesh, order, quadrature, steps, rtol, kind):
    """One punch run (quarter model, case b, load to 1000 N, unload). Collective."""
    comm.Barrier()
    t0 = time.perf_counter()
    mesh_size, contact_size = mesh
    normal, t_law = normal_law(comm, "punch", kind, rtol)
    t1 = time.perf_counter()
    # seating held at the demo default (16 increments) for every run
    m = punch_demo.build(comm, mesh_size, contact_size, order, load_half_width=2.5, case="b",
                         steps=steps, quadrature_degree=quadrature, normal=normal,
                         seating_steps=DEFAULTS["punch"]["steps"])
    scene, problem, solver, interface = m.scene, m.problem, m.solver, m.interface
    a = scene.dimensions["half_width"]
    t_mesh = 0.0  # included in t_solve (the demo's build makes mesh and problem together)
    # mean u_z over the load patch (the punch approach)
    ds = __import__("ufl").Measure("ds", domain=scene.mesh, subdomain_data=scene.facet_tags)
    load_ds = ds(scene.tag("load"))
    uz_form = fem.form(problem.u[2] * load_ds)
    area_load = comm.allreduce(fem.assemble_scalar(fem.form(
        fem.Constant(scene.mesh, PETSc.ScalarType(1.0)) * load_ds)), op=MPI.SUM)
    edges = np.linspace(0.0, a, PUNCH_BINS + 1)
    out = {}
    path = _Path(problem, solver, load_unload_factors(steps, steps - 1))
    for inc in path:
        if inc.load_factor == 1.0 and inc.target == 1.0:
            uz = comm.allreduce(fem.assemble_scalar(uz_form), op=MPI.SUM) / area_load
            bins, g_c, modes = _bin_pressure(comm, interface, edges, edges,
                                             modes=(a, a, (PUNCH_MODES, PUNCH_MODES)))
            out.update(approach=-uz, bins=bins, g_centre=g_c, modes=modes)
    D = interface.dissipation()
    return path.result(comm, interface, (t0, t1, t_mesh, t_law), approach=out["approach"],
                       g_centre=comm.bcast(out["g_centre"], root=0), dissipation=D,
                       bins=comm.bcast(out["bins"], root=0),
                       modes=comm.bcast(out["modes"], root=0))


# ## The beam
def run_beam(comm, mesh, order, quadrature, steps, rtol, kind):
    """One beam run (Table 4 case 1 surface, friction b). Collective."""
    comm.Barrier()
    t0 = time.perf_counter()
    setup = beam_demo.build_scene(comm, mesh[0], mesh[1], order, 5.0)
    t_mesh = time.perf_counter() - t0
    normal, t_law = normal_law(comm, "beam", kind, rtol)
    t1 = time.perf_counter()
    scene = setup.scene
    dims = scene.dimensions
    case = beam_demo.build_case(setup, normal, beam_demo.CASES[1][0], steps, "mindlin", "b",
                                prefix="rc_", dof_threshold=200_000, quadrature_degree=quadrature)
    problem, solver, interface, factors = case.problem, case.solver, case.interface, case.factors
    uz0 = None
    path = _Path(problem, solver, factors)
    for inc in path:
        if uz0 is None:
            uz0 = beam_demo.contact_uz(setup, problem.u)
    prof = beam_demo.deflection_profile(comm, setup, beam_demo.contact_uz(setup, problem.u) - uz0)
    edges_y = np.linspace(0.0, dims["half_length"], BEAM_BINS + 1)
    edges_x = np.array([-dims["width"] / 2 - 1.0, dims["width"] / 2 + 1.0])
    bins, _, modes = _bin_pressure(comm, interface, edges_x, edges_y,
                                   modes=(dims["width"], dims["half_length"], (1, BEAM_MODES)))
    return path.result(comm, interface, (t0, t1, t_mesh, t_law), uN_centre=prof.centre,
                       uN_end=prof.end, bins=comm.bcast(bins, root=0),
                       modes=comm.bcast(modes, root=0))


# ## Plan, CSV, report
COLUMNS = ["mode", "example", "knob", "level", "ranks", "mesh_size", "contact_size", "order",
           "quadrature", "steps", "rtol", "normal_law", "num_dofs", "n_points", "newton",
           "max_force_error", "approach_mm", "g_centre_mm", "dissipation_Nmm", "uN_centre_mm",
           "uN_end_mm", "wall_time_s", "t_mesh_s", "t_law_s", "t_solve_s", "bins_MPa",
           "timestamp", "modes_MPa"]


def plan(example, quick, knobs):
    """List of (knob, level label, settings dict) for one example."""
    sweeps = (SWEEPS_QUICK if quick else SWEEPS_FULL)[example]
    base = dict(DEFAULTS[example])
    if quick:
        base.update(BASE_QUICK[example])
    runs = []
    for knob in knobs:
        if knob == "fine":
            s = dict(base)
            s.update((FINE_QUICK if quick else FINE_FULL)[example])
            runs.append(("fine", "all-fine", s))
            continue
        for level in sweeps.get(knob, []):
            s = dict(base)
            if knob == "mesh_p2":  # mesh sweep with P2 elements
                s["order"] = 2
            key = {"mesh": "mesh", "order": "order", "quadrature": "quadrature",
                   "steps": "steps", "rtol": "rtol", "normal_law": "normal_law",
                   "mesh_p2": "mesh"}[knob]
            s[key] = tuple(level) if knob.startswith("mesh") else level
            label = f"{level[0]:g}/{level[1]:g}" if knob.startswith("mesh") else f"{level}"
            runs.append((knob, label, s))
    return runs


def _settings_key(r):
    """Identity of a run's settings (for reusing a run under another knob)."""
    return (r["mode"], r["example"], str(r["ranks"]), float(r["mesh_size"]),
            float(r["contact_size"]), int(r["order"]), int(r["quadrature"]), int(r["steps"]),
            float(r["rtol"]), r["normal_law"])


def read_rows(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def append_row(path, row):
    new = not os.path.exists(path)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        if new:
            w.writeheader()
        w.writerow(row)
        f.flush()
        os.fsync(f.fileno())


def run_study(comm, args):
    mode = "quick" if args.quick else "full"
    knobs = args.knobs or list(KNOBS)
    bad = [k for k in knobs if k not in KNOBS]
    if bad:
        raise ValueError(f"knobs = {bad} are invalid; valid values: {KNOBS}")
    done, same = set(), {}
    if comm.rank == 0:
        for r in read_rows(args.csv):
            done.add((r["mode"], r["example"], r["knob"], r["level"], r["ranks"]))
            same[_settings_key(r)] = r
    done, same = comm.bcast((done, same), root=0)
    t_start = time.perf_counter()
    for example in args.examples:
        for knob, label, s in plan(example, args.quick, knobs):
            key = (mode, example, knob, label, str(comm.size))
            if key in done:
                PETSc.Sys.Print(f"skip (in CSV): {key}", comm=comm)
                continue
            if args.max_minutes and (time.perf_counter() - t_start) / 60 > args.max_minutes:
                PETSc.Sys.Print(f"time budget reached; skipped {key}", comm=comm)
                continue
            if comm.rank == 0:  # other processes may have added rows meanwhile
                same = {_settings_key(r): r for r in read_rows(args.csv)}
            same = comm.bcast(same, root=0)
            qdeg = 2 * s["order"] if s["quadrature"] is None else s["quadrature"]
            skey = _settings_key(dict(mode=mode, example=example, ranks=comm.size,
                                      mesh_size=s["mesh"][0], contact_size=s["mesh"][1],
                                      order=s["order"], quadrature=qdeg, steps=s["steps"],
                                      rtol=s["rtol"], normal_law=s["normal_law"]))
            if skey in same:  # identical settings already run under another knob: reuse
                row = dict(same[skey], knob=knob, level=label)
                if comm.rank == 0:
                    append_row(args.csv, row)
                PETSc.Sys.Print(f"reused identical run for {key}", comm=comm)
                continue
            fn = run_punch if example == "punch" else run_beam
            try:
                r = fn(comm, s["mesh"], s["order"], s["quadrature"], s["steps"], s["rtol"],
                       s["normal_law"])
            except Exception as exc:  # noqa: BLE001 - record and continue with the next run
                PETSc.Sys.Print(f"FAILED {key}: {type(exc).__name__}: {exc}", comm=comm)
                continue
            qdeg = 2 * s["order"] if s["quadrature"] is None else s["quadrature"]
            row = dict(mode=mode, example=example, knob=knob, level=label, ranks=comm.size,
                       mesh_size=s["mesh"][0], contact_size=s["mesh"][1], order=s["order"],
                       quadrature=qdeg, steps=s["steps"], rtol=s["rtol"],
                       normal_law=s["normal_law"], num_dofs=r["num_dofs"],
                       n_points=r["n_points"], newton=r["newton"],
                       max_force_error=f"{r['max_force_error']:.3e}",
                       approach_mm=f"{r.get('approach', np.nan):.10e}",
                       g_centre_mm=f"{r.get('g_centre', np.nan):.10e}",
                       dissipation_Nmm=f"{r.get('dissipation', np.nan):.10e}",
                       uN_centre_mm=f"{r.get('uN_centre', np.nan):.10e}",
                       uN_end_mm=f"{r.get('uN_end', np.nan):.10e}",
                       wall_time_s=f"{r['wall_time']:.2f}", t_mesh_s=f"{r['t_mesh']:.2f}",
                       t_law_s=f"{r['t_law']:.2f}", t_solve_s=f"{r['t_solve']:.2f}",
                       bins_MPa=" ".join(f"{v:.8e}" for v in r["bins"]),
                       modes_MPa=" ".join(f"{v:.8e}" for v in r["modes"]),
                       timestamp=time.strftime("%H:%M:%S", time.gmtime()))
            if comm.rank == 0:
                append_row(args.csv, row)
            PETSc.Sys.Print(f"{example:5s} {knob:10s} {label:14s} ranks {comm.size}: "
                            f"{r['num_dofs']} DOFs, {r['wall_time']:.1f} s "
                            f"(mesh {r['t_mesh']:.1f}, law {r['t_law']:.1f}), "
                            f"newton {r['newton']}, "
                            + (f"approach {r['approach'] * 1e3:.5f} um, "
                               f"D {r['dissipation']:.5g} N mm" if example == "punch" else
                               f"uN centre {r['uN_centre'] * 1e3:.5f} um"), comm=comm)
            gc.collect()


# ## Report: errors, table, figure
QUANTITIES = {"punch": [("approach_mm", "approach"), ("g_centre_mm", "g centre"),
                        ("modes_MPa", "pressure dist."),
                        ("dissipation_Nmm", "dissipation D")],
              "beam": [("uN_centre_mm", "uN centre"), ("modes_MPa", "pressure dist.")]}


def _value(row, col):
    if col.endswith("s_MPa"):
        return np.array([float(v) for v in (row.get(col) or "nan").split()])
    return float(row[col])


def _same_points(a, b):
    """True if two runs have the same interface points (same mesh, order, quadrature)."""
    return all(float(a[k]) == float(b[k])
               for k in ("mesh_size", "contact_size", "order", "quadrature"))


def _error(row, ref, col):
    if col == "modes_MPa" and not (row.get(col) and ref.get(col)):
        # rows of the first pass have no mode coefficients; the bin means are free of the
        # bin-assignment artefact when both runs have the same interface points
        if not _same_points(row, ref):
            return float("nan")
        col = "bins_MPa"
    a, b = _value(row, col), _value(ref, col)
    if np.shape(a) != np.shape(b):
        return float("nan")
    if col.endswith("s_MPa"):
        return float(np.linalg.norm(a - b) / np.linalg.norm(b))
    return abs(a - b) / abs(b)


def _default_row(rows, example):
    """The row of a sweep whose settings equal the demo defaults (serial)."""
    d = DEFAULTS[example]
    for r in rows:
        if (r["example"] == example and r["knob"] == "mesh" and r["ranks"] == "1"
                and float(r["mesh_size"]) == d["mesh"][0]
                and float(r["contact_size"]) == d["mesh"][1]):
            return r
    return None


def analyse(rows, mode):
    """Errors of every row against its sweep's finest level (and of defaults vs all-fine)."""
    out = []
    for example in ("punch", "beam"):
        ex = [r for r in rows if r["mode"] == mode and r["example"] == example]
        for knob in KNOBS[1:]:
            for ranks in ("1", "2"):
                sweep = [r for r in ex if r["knob"] == knob and r["ranks"] == ranks]
                if not sweep:
                    continue
                if knob == "normal_law":
                    ref = next((r for r in sweep
                                if r["normal_law"] == DEFAULTS[example]["normal_law"]), None)
                else:
                    levels = [lv for lv in _levels(example, knob, mode)
                              if any(r["level"] == lv for r in sweep)]
                    ref = next(r for r in sweep if r["level"] == levels[-1]) if levels else None
                if ref is None:
                    continue
                for r in sweep:
                    errs = {col: _error(r, ref, col) for col, _ in QUANTITIES[example]}
                    out.append(dict(example=example, knob=knob, level=r["level"], ranks=ranks,
                                    ref=ref["level"], row=r, errors=errs, is_ref=r is ref))
        fine = [r for r in ex if r["knob"] == "fine"]
        dflt = _default_row([r for r in ex], example)
        if fine and dflt is not None:
            errs = {col: _error(dflt, fine[0], col) for col, _ in QUANTITIES[example]}
            out.append(dict(example=example, knob="defaults vs all-fine", level="default",
                            ranks="1", ref="all-fine", row=dflt, errors=errs, is_ref=False))
    return out


def _levels(example, knob, mode):
    sweeps = (SWEEPS_QUICK if mode == "quick" else SWEEPS_FULL)[example]
    return [f"{lv[0]:g}/{lv[1]:g}" if knob.startswith("mesh") else f"{lv}"
            for lv in sweeps.get(knob, [])]


def write_report(args):
    rows = read_rows(args.csv)
    mode = "quick" if args.quick else "full"
    res = analyse(rows, mode)
    if not res:
        print("no rows to report")
        return
    # figure: one panel per (example, quantity), one curve per knob (serial; mesh also 2 ranks)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [(ex, col, name) for ex in ("punch", "beam") for col, name in QUANTITIES[ex]]
    ncol = 3
    nrow = -(-len(panels) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.0 * ncol, 4.2 * nrow), squeeze=False)
    axes = axes.ravel()
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    colors = dict(mesh="tab:blue", order="tab:orange", quadrature="tab:green",
                  steps="tab:red", rtol="tab:purple", normal_law="tab:brown",
                  mesh_p2="tab:cyan")
    for ax, (ex, col, name) in zip(axes, panels):
        for knob in KNOBS[1:]:
            for ranks, ls in (("1", "-o"), ("2", "--s")):
                order = _levels(ex, knob, mode)
                sel = sorted([e for e in res if e["example"] == ex and e["knob"] == knob
                              and e["ranks"] == ranks and not e["is_ref"]],
                             key=lambda e: order.index(e["level"]))  # coarse -> fine
                pts = [(float(e["row"]["wall_time_s"]), e["errors"][col], e["level"])
                       for e in sel]
                if not pts:
                    continue
                t, err, lab = zip(*pts)
                ax.loglog(t, np.maximum(err, 1e-8), ls, color=colors[knob], ms=4,
                          label=f"{knob}" + (" (2 ranks)" if ranks == "2" else ""))
                for ti, ei, li in pts:
                    ax.annotate(li, (ti, max(ei, 1e-8)), fontsize=6, alpha=0.7)
        for lvl in (1e-2, 1e-3):
            ax.axhline(lvl, color="0.6", ls=":", lw=0.8)
        ax.set_title(f"{ex}: {name}", fontsize=9)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error vs sweep reference")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Accuracy vs cost ({mode} mode; errors below 1e-8 drawn at 1e-8; each "
                 "sweep's finest level is its reference and is not drawn)", fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.figure)), exist_ok=True)
    fig.savefig(args.figure, dpi=120)
    plt.close(fig)
    # table
    lines = []
    for ex in ("punch", "beam"):
        cols = QUANTITIES[ex]
        lines.append(f"\n### {ex} ({mode} mode)\n")
        lines.append("| knob | level | ranks | reference | DOFs | Newton | wall [s] | "
                     + " | ".join(f"err {n}" for _, n in cols) + " | "
                     + " | ".join(n for c, n in cols if not c.endswith("s_MPa")) + " |")
        lines.append("|" + "---|" * (7 + len(cols) + len(cols) - 1))
        for e in res:
            if e["example"] != ex:
                continue
            r = e["row"]
            vals = []
            for col, _ in cols:
                if col.endswith("s_MPa"):
                    continue
                scale = 1e3 if col.endswith("_mm") else 1.0
                unit = " um" if col.endswith("_mm") else ""
                vals.append(f"{float(r[col]) * scale:.6g}{unit}")
            errs = ["(ref)" if e["is_ref"] else f"{e['errors'][c]:.2e}" for c, _ in cols]
            lines.append(f"| {e['knob']} | {e['level']} | {e['ranks']} | {e['ref']} | "
                         f"{r['num_dofs']} | {r['newton']} | {float(r['wall_time_s']):.1f} | "
                         + " | ".join(errs) + " | " + " | ".join(vals) + " |")
    # cheapest level of each knob that reaches 1 % / 0.1 % (serial, against the sweep reference)
    lines.append(f"\n### Cheapest level per knob reaching 1 % / 0.1 % ({mode} mode, serial, "
                 "error against the sweep's own finest level; levels ranked by their nominal "
                 "cost (coarse to fine), not by the noisy measured time; the reference level "
                 "itself is excluded, so 'none' means only the reference reaches it)\n")
    lines.append("| example | quantity | knob | 1 % | 0.1 % |")
    lines.append("|---|---|---|---|---|")
    for ex in ("punch", "beam"):
        for col, name in QUANTITIES[ex]:
            for knob in KNOBS[1:]:
                if knob == "normal_law":
                    continue
                order = _levels(ex, knob, mode)  # coarse (cheap) -> fine (expensive)
                cand = sorted([e for e in res if e["example"] == ex and e["knob"] == knob
                               and e["ranks"] == "1" and not e["is_ref"]],
                              key=lambda e: order.index(e["level"]))
                if not cand:
                    continue
                cells = []
                for tol in (1e-2, 1e-3):
                    ok = [e for e in cand if e["errors"][col] <= tol]
                    if all(not np.isfinite(e["errors"][col]) for e in cand):
                        cells.append("n/a")
                        continue
                    cells.append(f"{ok[0]['level']} ({float(ok[0]['row']['wall_time_s']):.0f} s)"
                                 if ok else "none")
                lines.append(f"| {ex} | {name} | {knob} | {cells[0]} | {cells[1]} |")
    table = "\n".join(lines) + "\n"
    # The table goes into the doc between markers (the prose around it is kept).
    start, end = f"<!-- table {mode} start -->", f"<!-- table {mode} end -->"
    text = open(args.doc).read() if os.path.exists(args.doc) else ""
    block = f"{start}\n{table}{end}"
    if start in text and end in text:
        text = text[:text.index(start)] + block + text[text.index(end) + len(end):]
    else:
        text = text + ("\n" if text else "") + block + "\n"
    with open(args.doc, "w") as f:
        f.write(text)
    print(table)
    print(f"wrote the table into {args.doc} and the figure {args.figure}")


if __name__ == "__main__":
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    comm = MPI.COMM_WORLD
    if ARGS.merge_from and comm.rank == 0:
        have = {(r["mode"], r["example"], r["knob"], r["level"], r["ranks"])
                for r in read_rows(ARGS.csv)}
        for r in read_rows(ARGS.merge_from):
            if (r["mode"], r["example"], r["knob"], r["level"], r["ranks"]) not in have:
                append_row(ARGS.csv, {k: r.get(k, "") for k in COLUMNS})
        ARGS.report = True
    if not ARGS.report:
        run_study(comm, ARGS)
    if comm.rank == 0 and not ARGS.no_report:
        write_report(ARGS)
