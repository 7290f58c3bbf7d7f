"""Regression figures: the numbers a pure refactoring must leave unchanged (to ~1e-10 relative).

Runs, at the small sizes the test suite uses, and prints as a table (and writes as JSON with
``--json FILE``, floats at full precision) these figures:

1. ``flat_punch``   the flat-punch demo (``scenes.flat_punch.run``, tests/fem/test_punch.py
                    ``test_demo_main_small``): dissipation D at the end, Newton iterations per
                    increment, force balance (contact vs applied force).
   ``flat_punch_coarse`` the same figures for test_punch.py's ``COARSE`` load path (``build`` +
                    ``load_path``, 4 + 1 increments).
2. ``beam``         beam Table 4 values (``scenes.beam.run``, tests/fem/test_beam.py ``TINY``,
                    cases 1 and 3).
3. ``coulomb_punch`` ``benchmarks/bench_coulomb_punch.py`` level 1: mu = 0.2 plain penalty
                    (default k = 1e7) and mu = 0.5 augmented, vertex rule, k = 1e7.
4. ``fretting``     fretting demo cycle energies (``scenes.fretting.run``: amplitudes 0.3 and
                    4 um, 1 triangle cycle of 8 steps, the settings of the earlier demo test).
5. ``mortar_patch`` mortar patch-test errors (tests/fem/test_nonmatching.py ``patch``): these are
                    round-off (~1e-12): compare them against the 1e-8 bound, not relatively.
6. ``hertz``        rigid sphere on a block (``scenes.hertz.run`` as tests/fem/test_hertz.py:
                    force P, contact radius a, peak pressure p0) and the elastic sphere meshed
                    apart (``scenes.hertz.run_elastic``, same test).
7. ``restart_after_kill`` tests/demos/test_multiprocess.py's SIGKILL-and-resume (2 ranks, run as
                    subprocesses with mpirun; only when this script runs on one rank).

Each figure has a ``run_*`` function (calls the library) and an ``extract_*`` function (turns its
result into plain numbers). The extract functions read results through :func:`get`, which
accepts a dict (``r["key"]``) or an object (``r.key``), so a scene returning a dataclass instead
of a dict needs at most a renamed key there.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/regression_figures.py --json before.json
    mpirun -n 2 .venv/bin/python benchmarks/regression_figures.py --json before_np2.json
    ... [--only flat_punch beam ...] [--skip restart_after_kill]

Compare two JSON files with ``--compare A.json B.json [--rtol 1e-10]`` (no run).
Units: mm, N, MPa.
"""

from __future__ import annotations
from rough_contact.fem import compat

import sys

import petsc4py

petsc4py.init(sys.argv[:1])   # our own options do not go to PETSc (before dolfinx is imported)

import argparse  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Mapping  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


# ## Helpers
def get(obj, key):
    """``obj[key]`` for a mapping, else ``obj.key`` (scene results: dicts now, dataclasses
    after the refactor)."""
    if isinstance(obj, Mapping):
        return obj[key]
    return getattr(obj, key)


def num(x):
    """Plain JSON-able Python numbers (lists for arrays, full precision)."""
    if isinstance(x, Mapping):
        return {str(k): num(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [num(v) for v in x]
    if isinstance(x, np.ndarray):
        return num(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x)
    if x is None or isinstance(x, str):
        return x
    raise TypeError(f"not a plain number: {type(x)!r}")


_TMPDIRS = []


def shared_tmpdir(comm, name):
    """A fresh directory, the same path on every rank (removed at the end of the run)."""
    path = tempfile.mkdtemp(prefix=f"rc_regression_{name}_") if comm.rank == 0 else None
    _TMPDIRS.append(path)
    return comm.bcast(path, root=0)


def git_commit():
    try:
        head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain",
                                "--untracked-files=no"], capture_output=True, text=True,
                               check=True).stdout.strip()
        return head, bool(dirty)
    except (OSError, subprocess.CalledProcessError):
        return None, None


def increment_figures(inc):
    """Per-increment numbers of a ``load_path`` Increment (dataclass now)."""
    cf, af = np.asarray(get(inc, "contact_force")), np.asarray(get(inc, "applied_force"))
    return dict(step=get(inc, "step"), load_factor=get(inc, "load_factor"),
                iterations=get(inc, "iterations"), newton_total=get(inc, "newton_total"),
                cutbacks=get(inc, "cutbacks"), n_active=get(inc, "n_active"),
                n_slipping=get(inc, "n_slipping"), real_area=get(inc, "real_area"),
                dissipation=get(inc, "dissipation"), contact_force=cf, applied_force=af,
                force_error_rel=abs(cf[2] + af[2]) / abs(af[2]))


# ## 1. Flat punch demo (tests/fem/test_punch.py::test_demo_main_small)
PUNCH_SMALL = dict(mesh_size=20.0, contact_size=5.0, order=1, steps=2, normal_law="elastic")


def run_flat_punch(comm):
    from rough_contact.scenes import flat_punch

    return flat_punch.run(**PUNCH_SMALL, outdir=shared_tmpdir(comm, "punch"), comm=comm,
                          prefix="rf_punch_", verbose=False, plot=False)


def extract_flat_punch(res):
    incs = [increment_figures(i) for i in get(res, "history")]
    return dict(settings=PUNCH_SMALL, num_dofs=get(res, "num_dofs"),
                n_points=get(res, "n_points"), D_end=get(res, "dissipation"),
                newton_per_increment=[i["iterations"] for i in incs],
                newton_total_per_increment=[i["newton_total"] for i in incs],
                load_factors=[i["load_factor"] for i in incs],
                contact_fz=[i["contact_force"][2] for i in incs],
                applied_fz=[i["applied_force"][2] for i in incs],
                force_error_rel=[i["force_error_rel"] for i in incs],
                max_force_error=get(res, "max_force_error"),
                D_per_increment=[i["dissipation"] for i in incs],
                n_active=[i["n_active"] for i in incs],
                n_slipping=[i["n_slipping"] for i in incs],
                real_area=[i["real_area"] for i in incs])


# ## 1b. Flat punch, coarse load path (tests/fem/test_punch.py: COARSE, run_punch)
PUNCH_COARSE = dict(mesh_size=20.0, contact_size=2.5, order=1, normal_law="elastic")
PUNCH_COARSE_STEPS, PUNCH_COARSE_UNLOAD = 4, 1


def run_flat_punch_coarse(comm):
    from rough_contact.scenes import flat_punch
    from rough_contact.solver.loading import load_path, load_unload_factors

    m = flat_punch.build(comm=comm, steps=PUNCH_COARSE_STEPS, prefix="rf_coarse_",
                         **PUNCH_COARSE)
    incs = list(load_path(m.problem, m.solver,
                          load_unload_factors(PUNCH_COARSE_STEPS, PUNCH_COARSE_UNLOAD),
                          verbose=False))
    out = dict(history=incs, dissipation=m.interface.dissipation(),
               num_dofs=m.problem.num_dofs, n_points=m.interface.n_points_global)
    m.solver.destroy()
    return out


def extract_flat_punch_coarse(res):
    incs = [increment_figures(i) for i in get(res, "history")]
    return dict(settings=dict(PUNCH_COARSE, steps=PUNCH_COARSE_STEPS,
                              n_unload=PUNCH_COARSE_UNLOAD),
                num_dofs=get(res, "num_dofs"), n_points=get(res, "n_points"),
                D_end=get(res, "dissipation"),
                newton_per_increment=[i["iterations"] for i in incs],
                load_factors=[i["load_factor"] for i in incs],
                contact_force=[i["contact_force"] for i in incs],
                force_error_rel=[i["force_error_rel"] for i in incs],
                D_per_increment=[i["dissipation"] for i in incs],
                n_active=[i["n_active"] for i in incs],
                n_slipping=[i["n_slipping"] for i in incs],
                real_area=[i["real_area"] for i in incs])


# ## 2. Beam on a rigid base, Table 4 (tests/fem/test_beam.py, TINY, cases 1 and 3)
BEAM_TINY = dict(mesh_size=60.0, contact_size=10.0, order=1, steps=4)
BEAM_CASES = (1, 3)


def run_beam(comm):
    from rough_contact.scenes import beam

    return beam.run(cases=BEAM_CASES, **BEAM_TINY, plot=False, xdmf=False, verbose=False,
                    outdir=shared_tmpdir(comm, "beam"), comm=comm, prefix="rf_beam_")


def extract_beam(results):
    out = dict(settings=dict(BEAM_TINY, cases=list(BEAM_CASES)))
    for r in results:
        out[f"case{get(r, 'case')}"] = dict(
            m00=get(r, "m00"), normal_law=get(r, "normal_law"),
            uN_centre_um=get(r, "centre") * 1e3, uN_end_um=get(r, "end") * 1e3,
            uN_centre_mean_um=get(r, "centre_mean") * 1e3,
            uN_end_mean_um=get(r, "end_mean") * 1e3, rigid_um=get(r, "rigid") * 1e3,
            lifted_area_fraction=get(r, "lifted_area_fraction"),
            max_force_error=get(r, "max_force_error"), newton=get(r, "newton"),
            contact_force=get(r, "contact_force"), applied_force=get(r, "applied_force"),
            p_max=get(r, "p_max"), p_end_min=get(r, "p_end_min"), n_open=get(r, "n_open"),
            h0=get(r, "h0"), num_dofs=get(r, "num_dofs"), n_points=get(r, "n_points"))
    return out


# ## 3. Coulomb punch benchmark, level 1 (benchmarks/bench_coulomb_punch.py)
# (name, keyword arguments of bench_coulomb_punch.run); width: the script's default 1e-2 * 2.5 / k
COULOMB_RUNS = (
    ("mu0.2_penalty", dict(level=1, mu=0.2, k=1e7, predictor="secant", quadrature="gauss",
                           augmented=False)),
    ("mu0.5_augmented_vertex", dict(level=1, mu=0.5, k=1e7, predictor="secant",
                                    quadrature="vertex", augmented=True)),
)


def run_coulomb_punch(comm):
    import bench_coulomb_punch as bench

    return {name: bench.run(width=1e-2 * 2.5 / kw["k"], comm=comm, **kw)
            for name, kw in COULOMB_RUNS}


def extract_coulomb_punch(rows):
    keys = ("dofs", "points", "newton", "solves", "cutbacks", "max_its", "al_updates",
            "D_peak", "D_end", "slip_peak")        # not "cpu"
    return {name: {k: get(r, k) for k in keys} for name, r in rows.items()}


# ## 4. Fretting demo (the earlier tests/demos/test_demos.py::test_demo_fretting settings; the
# triangle wave pinned so that figures stored before the sine default stay comparable)
FRETTING_AMPLITUDES = (0.3, 4.0)
FRETTING_SMALL = dict(cycles=1, steps_per_cycle=8, mesh_size=0.5, wave="triangle")


def run_fretting(comm):
    from rough_contact.scenes import fretting

    return fretting.run(FRETTING_AMPLITUDES, outdir=shared_tmpdir(comm, "fretting"), plot=False,
                        comm=comm, xdmf=False, progress=False, **FRETTING_SMALL)


def extract_fretting(results):
    out = dict(settings=dict(FRETTING_SMALL, amplitudes_um=list(FRETTING_AMPLITUDES)))
    for r in results:
        cycles = [{k: get(c, k) for k in ("cycle", "loop_energy", "dissipated",
                                          "secant_stiffness")} for c in get(r, "cycles")]
        fx = np.asarray(get(r, "fx"))
        out[f"a{get(r, 'amplitude_um'):g}um"] = dict(
            cycles=cycles, newton=get(r, "newton"), dofs=get(r, "dofs"),
            k_normal=get(r, "k_normal"), k_tangential=get(r, "k_tangential"),
            D_end=float(np.asarray(get(r, "dissipation"))[-1]),
            max_abs_fx_over_P=float(np.abs(fx).max() / get(r, "force")),
            n_increments=len(fx))
    return out


# ## 5. Mortar patch test (tests/fem/test_nonmatching.py::patch, same set-up)
# (name, cell type, order, lower size, upper size, first surface, law, E_lower / E)
# The test's CASES, frictionless (LinearPenalty, E_lower = E / 2) and, for three of them, with
# Coulomb friction (SoftplusPenalty, same material both sides).
_PATCH_GEOMETRIES = (
    ("tet_P1_5:7_upper", "tetrahedron", 1, 0.2, 0.28, "upper"),
    ("tet_P2_5:7_lower", "tetrahedron", 2, 0.2, 0.28, "lower"),
    ("tet_P1_1:3_lower", "tetrahedron", 1, 0.1, 0.3, "lower"),
    ("tet_P1_3:1_lower", "tetrahedron", 1, 0.3, 0.1, "lower"),
    ("hex_Q1_5:7_upper", "hexahedron", 1, 1 / 5, 1 / 7, "upper"),
    ("hex_Q2_5:7_lower", "hexahedron", 2, 1 / 5, 1 / 7, "lower"),
    ("hex_Q1_3:9_lower", "hexahedron", 1, 1 / 3, 1 / 9, "lower"),
)
PATCH_CASES = tuple((g[0] + "_frictionless",) + g[1:] + ("linear", 0.5)
                    for g in _PATCH_GEOMETRIES) + \
    tuple((g[0] + "_friction",) + g[1:] + ("coulomb", 1.0)
          for g in (_PATCH_GEOMETRIES[1], _PATCH_GEOMETRIES[3], _PATCH_GEOMETRIES[5]))
PATCH_E, PATCH_NU, PATCH_P = 2.0e5, 0.25, 80.0


def _patch(comm, cell_type, order, size_lower, size_upper, first, law_name, e_ratio):
    from dolfinx import fem
    from petsc4py import PETSc

    from rough_contact.fem.contact import ContactInterface
    from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
    from rough_contact.interface.penalty import LinearPenalty, SoftplusPenalty
    from rough_contact.scenes.meshes.blocks import separate_blocks
    from rough_contact.solver.snes import SNESSolver

    law = LinearPenalty(1e6) if law_name == "linear" else \
        SoftplusPenalty(1e6, 1e-7, k_tangential=1e6, friction=0.3)
    scene = separate_blocks(h1=1.0, h2=0.5, size_lower=size_lower, size_upper=size_upper,
                            order=order, cell_type=cell_type, comm=comm)
    V = compat.vector_space(scene.mesh, order)

    def roller(name, comp):
        dofs = fem.locate_dofs_topological(V.sub(comp), 2, scene.facet_tags.find(scene.tag(name)))
        return fem.dirichletbc(PETSc.ScalarType(0.0), dofs, V.sub(comp))

    bcs = [roller("x0", 0), roller("y0", 1), roller("bottom", 2)]
    a, b = scene.contact_pair
    if first == "lower":
        a, b = b, a
    ci = ContactInterface(V, scene.facet_tags, a, b, law=law, bcs=bcs,
                          quadrature_degree=2 * order, pairing="mortar")
    mats = {scene.tag("upper"): Material(PATCH_E, PATCH_NU),
            scene.tag("lower"): Material(e_ratio * PATCH_E, PATCH_NU)}
    problem = ContactProblem(V, mats, bcs,
                             [SurfaceLoad(scene.tag("top"), traction=[0, 0, -PATCH_P])],
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=ci)
    solver = SNESSolver(problem, prefix="rf_patch_")
    problem.set_load_factor(1.0)
    result = solver.solve()
    ci.evaluate(problem.u)
    pf = ci.point_fields()
    real = pf.weight > 0
    p_err = comm.allreduce(float(np.max(np.abs(pf.pressure[real] - PATCH_P), initial=0.0)),
                           op=MPI.MAX)
    s_err = comm.allreduce(float(np.max(np.abs(pf.shear[real]), initial=0.0)), op=MPI.MAX)
    slipping = comm.allreduce(int(pf.slipping[real].sum()), op=MPI.SUM)
    out = dict(converged=bool(result.converged), pressure_error_rel=p_err / PATCH_P,
               shear_error_rel=s_err / PATCH_P, slipping=slipping,
               contact_force=np.asarray(ci.contact_force()),
               nominal_area=ci.summary().nominal_area, num_dofs=problem.num_dofs,
               n_points=ci.n_points_global)
    solver.destroy()
    return out


def run_mortar_patch(comm):
    return {c[0]: _patch(comm, *c[1:]) for c in PATCH_CASES}


def extract_mortar_patch(results):
    return {name: {k: get(r, k) for k in ("converged", "pressure_error_rel", "shear_error_rel",
                                          "slipping", "contact_force", "nominal_area",
                                          "num_dofs", "n_points")}
            for name, r in results.items()}


# ## 6. Hertz, rigid sphere (tests/fem/test_hertz.py::test_sphere_on_block_against_hertz)
HERTZ_SETTINGS = dict(contact_size=0.04, order=1, quadrature="vertex", penalty=1e8)


# and the elastic sphere, meshed apart (test_elastic_sphere_on_separately_meshed_block)
HERTZ_ELASTIC_SETTINGS = dict(contact_size=0.08, order=2, pairing="mortar")
HERTZ_KEYS = ("P", "a_fe", "a_hertz", "a_error", "p0_fe", "p0_hertz", "p0_error", "force_from_p",
              "band_error", "points", "dofs")


def run_hertz(comm):
    from rough_contact.scenes import hertz

    return dict(rigid=hertz.run(**HERTZ_SETTINGS, comm=comm),
                elastic=hertz.run_elastic(**HERTZ_ELASTIC_SETTINGS, comm=comm))


def extract_hertz(r):
    rigid, elastic = get(r, "rigid"), get(r, "elastic")
    return dict(rigid=dict(settings=HERTZ_SETTINGS, **{k: get(rigid, k) for k in HERTZ_KEYS}),
                elastic=dict(settings=HERTZ_ELASTIC_SETTINGS, balance=get(elastic, "balance"),
                             **{k: get(elastic, k) for k in HERTZ_KEYS}))


# ## 7. Restart after SIGKILL (tests/demos/test_multiprocess.py::test_sigkill_then_resume)
KILL_AFTER = 7          # one of the test's three kill points (3, 7, 12)


def _kill_rank():
    """tests/demos/kill_rank.py: the worker's command and the run killed at a step."""
    sys.path.insert(0, str(ROOT / "tests" / "demos"))
    import kill_rank

    return kill_rank


def _worker_env():
    # a clean environment for a nested mpirun (drop what our own MPI start-up exported)
    drop = ("OMPI_MCA", "OMPI_COMM_", "OMPI_FIRST", "OMPI_APP", "OMPI_UNIVERSE", "OMPI_FILE",
            "OMPI_NUM", "OMPI_ARGV", "OMPI_COMMAND", "PMIX_", "PMI_")
    env = {k: v for k, v in os.environ.items() if not k.startswith(drop)}
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg")
    return env


def run_restart_after_kill(comm):
    if comm.size != 1:
        return dict(skipped="only run on one rank (the workers are started with their own "
                            "mpirun -n 2; nested in an MPI job they would oversubscribe)")
    if shutil.which("mpirun") is None:
        return dict(skipped="mpirun not found")
    tmp = Path(tempfile.mkdtemp(prefix="rc_regression_kill_"))
    env = _worker_env()
    kill_rank = _kill_rank()

    def run(mode, directory, out):
        proc = subprocess.run(kill_rank.worker_cmd(mode, directory, out), env=env,
                              capture_output=True, text=True, timeout=600)
        if proc.returncode != 0:
            raise RuntimeError(f"checkpoint_worker {mode} failed:\n{proc.stdout[-2000:]}\n"
                               f"{proc.stderr[-2000:]}")
        return json.loads(Path(out).read_text())

    reference = run("full", tmp / "unused", tmp / "full.json")
    directory = tmp / f"ckpt_{KILL_AFTER}"
    proc, killed = kill_rank.kill_checkpointed_run(directory, tmp / "never.json", env, KILL_AFTER)
    resumed = run("resume", directory, tmp / "resumed.json")
    shutil.rmtree(tmp, ignore_errors=True)
    return dict(reference=reference, resumed=resumed, killed=killed,
                killed_returncode=proc.returncode)


def extract_restart_after_kill(r):
    if "skipped" in r:
        return r
    ref, res = get(r, "reference"), get(r, "resumed")

    def rel(a, b):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))

    return dict(kill_after_step=KILL_AFTER, killed=get(r, "killed"),
                resumed_from_step=res["first"], final_step=res["step"],
                reference_final_step=ref["step"],
                rel_diff_D=rel(res["D"], ref["D"]), rel_diff_F=rel(res["F"], ref["F"]),
                rel_diff_unorm=rel(res["unorm"], ref["unorm"]),
                rel_diff_umax=rel(res["umax"], ref["umax"]),
                reference_D=ref["D"], reference_F=ref["F"], reference_unorm=ref["unorm"],
                reference_umax=ref["umax"])


# ## Driver
FIGURES = {
    "flat_punch": (run_flat_punch, extract_flat_punch),
    "flat_punch_coarse": (run_flat_punch_coarse, extract_flat_punch_coarse),
    "beam": (run_beam, extract_beam),
    "coulomb_punch": (run_coulomb_punch, extract_coulomb_punch),
    "fretting": (run_fretting, extract_fretting),
    "mortar_patch": (run_mortar_patch, extract_mortar_patch),
    "hertz": (run_hertz, extract_hertz),
    "restart_after_kill": (run_restart_after_kill, extract_restart_after_kill),
}


def flatten(d, prefix=""):
    """(dotted key, value) rows of a nested dict; lists of numbers stay one row."""
    rows = []
    for k, v in d.items():
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict):
            rows += flatten(v, key)
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for i, item in enumerate(v):
                rows += flatten(item, f"{key}[{i}]")
        else:
            rows.append((key, v))
    return rows


def table(figures) -> str:
    rows = flatten(figures)
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v!r}" for k, v in rows)


# Round-off figures (errors of exact results, differences of equal runs): a refactoring may move
# them anywhere below the tests' bounds, so they are checked against an absolute bound, not
# relatively.
ROUNDOFF_KEYS = ("*force_error*", "*.pressure_error_rel", "*.shear_error_rel",
                 "restart_after_kill.rel_diff_*", "hertz.elastic.balance",
                 "fretting.a0.3um.cycles[[]*[]].loop_energy")
ROUNDOFF_BOUND = 1e-8
SKIP_KEYS = ("restart_after_kill.skipped",)


def compare(a_path, b_path, rtol):
    """Print the rows of two JSON files of this script that differ: numbers by more than rtol
    relative to the largest magnitude in the row (a list row, e.g. a force vector or a history,
    is one row), round-off rows (``ROUNDOFF_KEYS``) beyond ``ROUNDOFF_BOUND`` absolute, other
    values (counts are numbers too) when not equal. Returns the number of differing rows."""
    from fnmatch import fnmatchcase

    a, b = (json.loads(Path(p).read_text())["figures"] for p in (a_path, b_path))
    ra, rb = dict(flatten(a)), dict(flatten(b))
    bad = worst_all = 0.0
    only = sorted(set(ra) ^ set(rb))
    for key in only:
        print(f"ONLY IN {'A' if key in ra else 'B'}: {key}")
    for key in sorted(set(ra) & set(rb)):
        if any(fnmatchcase(key, p) for p in SKIP_KEYS):
            continue
        va, vb = ra[key], rb[key]
        try:
            fa = np.asarray(va, dtype=float).ravel()
            fb = np.asarray(vb, dtype=float).ravel()
            if fa.shape != fb.shape or isinstance(va, str) or isinstance(vb, str):
                raise ValueError
        except (TypeError, ValueError):
            if va != vb:
                bad += 1
                print(f"DIFF {key}: {va!r} vs {vb!r}")
            continue
        diff = np.where(np.isnan(fa) & np.isnan(fb), 0.0, np.abs(fa - fb))
        if any(fnmatchcase(key, p) for p in ROUNDOFF_KEYS):
            ok = bool(np.all(np.abs(fa) <= ROUNDOFF_BOUND) and np.all(np.abs(fb) <= ROUNDOFF_BOUND))
            what = f"round-off row, bound {ROUNDOFF_BOUND:g}"
        else:
            scale = max(np.nanmax(np.abs(fa), initial=0.0), np.nanmax(np.abs(fb), initial=0.0))
            rel = float(np.max(diff, initial=0.0) / scale) if scale > 0 else 0.0
            worst_all = max(worst_all, rel)
            ok = rel <= rtol
            what = f"rel {rel:.3e}"
        if not ok:
            bad += 1
            print(f"DIFF {key}: {va!r} vs {vb!r} ({what})")
    print(f"{int(bad)} of {len(set(ra) & set(rb))} common rows differ beyond rtol = {rtol:g} "
          f"(largest relative difference of the compared rows {worst_all:.3e}); "
          f"{len(only)} rows in one file only")
    return int(bad) + len(only)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=None, help="write the figures to this JSON file (rank 0)")
    ap.add_argument("--only", nargs="+", choices=sorted(FIGURES), default=None)
    ap.add_argument("--skip", nargs="+", choices=sorted(FIGURES), default=[])
    ap.add_argument("--compare", nargs=2, metavar=("A.json", "B.json"), default=None,
                    help="compare two JSON files of this script and exit (no run)")
    ap.add_argument("--rtol", type=float, default=1e-10)
    args = ap.parse_args(argv)
    if args.compare:
        return 1 if compare(*args.compare, args.rtol) else 0

    comm = MPI.COMM_WORLD
    names = [n for n in (args.only or FIGURES) if n not in args.skip]
    figures, timings = {}, {}
    t_all = time.perf_counter()
    for name in names:
        run, extract = FIGURES[name]
        t0 = time.perf_counter()
        figures[name] = num(extract(run(comm)))
        timings[name] = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
        if comm.rank == 0:
            print(f"[regression_figures] {name}: {timings[name]:.1f} s", flush=True)
    comm.Barrier()
    for path in _TMPDIRS:
        if path is not None:
            shutil.rmtree(path, ignore_errors=True)
    commit, dirty = git_commit()
    doc = dict(commit=commit, dirty=dirty, ranks=comm.size, figures=figures,
               wall_time_s=timings, total_wall_time_s=time.perf_counter() - t_all)
    if comm.rank == 0:
        print(f"\nRegression figures, commit {commit}{' (dirty)' if dirty else ''}, "
              f"{comm.size} rank(s)\n")
        print(table(figures))
        print(f"\ntotal wall time {doc['total_wall_time_s']:.1f} s")
        if args.json:
            Path(args.json).parent.mkdir(parents=True, exist_ok=True)
            Path(args.json).write_text(json.dumps(doc, indent=1) + "\n")
            print(f"written {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
