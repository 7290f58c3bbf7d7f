"""Every demo runs, at a small size, as a user would run it (a subprocess, as dolfinx's own
``python/demo/test.py`` does): exit code 0 and the line that reports its check.

The demos' numbers are verified by the library tests (tests/fem, tests/unit); these tests make
sure the scripts themselves — argument parsing, PETSc options, output — keep working.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
DEMOS = ROOT / "demos"
MPIRUN = shutil.which("mpirun")


def run(args, tmp_path, ranks=1, timeout=600):
    env = dict(os.environ, MPLBACKEND="Agg", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    cmd = [sys.executable] + [str(a) for a in args]
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks)] + cmd
    proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=timeout)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc.stdout


PUNCH_SMALL = ["--mesh-size", "20", "--contact-size", "5", "--order", "1", "--steps", "2",
               "--normal-law", "elastic"]


@pytest.mark.parametrize("ranks", [1, 2])
def test_demo_flat_punch(tmp_path, ranks):
    if ranks > 1 and MPIRUN is None:
        pytest.skip("mpirun not found")
    out = run([DEMOS / "demo_flat_punch.py", *PUNCH_SMALL, "--outdir", tmp_path / "punch",
               "-rc_snes_rtol", "1e-9"], tmp_path, ranks)
    assert "Force balance: max |Fz_contact + Fz_applied|" in out
    assert "Total frictional dissipation D" in out
    # issue 24, item 13: the paper's Table 5 value is no longer printed as if it were the target
    assert "not comparable with the paper's Table 5" in out and "docs/punch.md" in out
    assert (tmp_path / "punch" / "history.csv").exists()


@pytest.mark.parametrize("ranks", [1, 2])
def test_demo_flat_punch_law_auto(tmp_path, ranks):
    """--law auto: the advisor's report printed at the start and written beside the results."""
    if ranks > 1 and MPIRUN is None:
        pytest.skip("mpirun not found")
    small = [a for a in PUNCH_SMALL if a not in ("--normal-law", "elastic")]
    out = run([DEMOS / "demo_flat_punch.py", *small, "--law", "auto", "--outdir",
               tmp_path / "punch", "-rc_snes_rtol", "1e-9"], tmp_path, ranks)
    assert out.index("Law advice") < out.index("Flat punch (quarter)")
    assert "advised normal law:" in out and "Force balance" in out
    text = (tmp_path / "punch" / "advice.txt").read_text()
    assert text.startswith("Law advice") and "plasticity" in text
    import json
    data = json.loads((tmp_path / "punch" / "advice.json").read_text())
    # the demo's asperity data (Y = 2070 MPa, K_Y = 1.62, psi = 0.35) make the e-p law differ
    assert data["normal"] == "elasto-plastic"
    assert f"law=rough ({data['normal']}" in out
    # the default --results: all four FE results (the punch reports the dissipation)
    assert data["results"] == ["force", "area", "approach", "dissipation"]


def test_demo_beam_law_auto(tmp_path):
    out = run([DEMOS / "demo_beam_rigid_base.py", "--cases", "1", "--mesh-size", "80",
               "--contact-size", "20", "--order", "1", "--steps", "2", "--no-xdmf",
               "--law", "auto", "--results", "force", "approach", "--outdir",
               tmp_path / "beam"], tmp_path)
    assert out.index("Law advice") < out.index("| 1 | 0.625 |")
    text = (tmp_path / "beam" / "case1" / "advice.txt").read_text()
    assert text.startswith("Law advice (tolerance 0.05 on k (force distribution) and the "
                           "interface approach,"), text
    import json
    data = json.loads((tmp_path / "beam" / "case1" / "advice.json").read_text())
    assert data["results"] == ["force", "approach"]


def test_demo_flat_punch_rejects_bad_options(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    for args, words in ((["--steps", "0"], "steps = 0"), (["--mesh-size", "-1"], "mesh_size"),
                        (["--stpes", "4"], "unrecognized arguments: --stpes")):
        proc = subprocess.run([sys.executable, str(DEMOS / "demo_flat_punch.py"), *args],
                              cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        assert proc.returncode != 0
        assert words in proc.stderr, proc.stderr[-2000:]


def _own_stderr(stderr: str) -> list:
    """The program's lines of stderr: before the launcher's closing note (the dashed box that
    Open MPI's mpirun 4 or prterun 5 adds when a process exits with a non-zero status),
    without blank lines and the launcher's own "PMIX ERROR" lines. Those are dropped first:
    prterun 5 may print one between the box's dashed line and its text (seen on Debian 13)."""
    lines = [ln for ln in stderr.splitlines() if "PMIX ERROR" not in ln]
    for i, line in enumerate(lines[:-1]):
        if set(line) == {"-"} and ("Primary job" in lines[i + 1]
                                   or "exited with non-zero status" in lines[i + 1]):
            lines = lines[:i]
            break
    return [ln for ln in lines if ln.strip()]


@pytest.mark.parametrize("ranks", [1, 2])
def test_demo_error_on_every_rank_ends_with_the_message(tmp_path, ranks):
    """Issue 24, item 7: a bad input that every rank refuses (a negative element size, checked
    by the library) ends the run with status 1, the message as the last line of the demo's
    error output and of its standard output, once, and no MPI_ABORT banner after it."""
    if ranks > 1 and MPIRUN is None:
        pytest.skip("mpirun not found")
    env = dict(os.environ, MPLBACKEND="Agg", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    cmd = [sys.executable, str(DEMOS / "demo_flat_punch.py"), "--mesh-size", "-1",
           "--outdir", str(tmp_path / "out")]
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks)] + cmd
    proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    message = "ValueError: mesh_size = -1.0 mm is invalid: it must be finite and > 0"
    assert proc.returncode != 0
    assert "MPI_ABORT" not in proc.stderr, proc.stderr[-3000:]
    assert proc.stderr.count(message) == 1, proc.stderr[-3000:]
    assert _own_stderr(proc.stderr)[-1] == message, proc.stderr[-3000:]
    if ranks > 1:
        assert proc.stdout.strip().splitlines()[-1] == f"error: {message}"


@pytest.mark.skipif(MPIRUN is None, reason="mpirun not found")
def test_uncaught_exception_on_some_ranks_aborts(tmp_path):
    """The other half of item 7: when only some ranks fail, the others would wait forever in
    their next collective, so the job is still aborted (MPI_ABORT, after the message); when all
    fail, it ends without the abort."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    worker = Path(__file__).with_name("failing_ranks.py")
    runs = {mode: subprocess.run([MPIRUN, "-n", "2", sys.executable, str(worker), mode],
                                 cwd=tmp_path, env=env, capture_output=True, text=True,
                                 timeout=120) for mode in ("one", "all")}
    one, every = runs["one"], runs["all"]
    # rank 0 of "one" waits in a barrier that only an abort ends: the run returning at all
    # (within the timeout) shows the abort. Its banner's text is not checked: Open MPI's help
    # system sometimes fails to print it ("Data unpack would read past end of buffer").
    assert one.returncode != 0, one.stderr[-2000:]
    assert "ValueError: steps = 0 is invalid (rank 1 of 2)" in one.stderr
    assert every.returncode != 0 and "MPI_ABORT" not in every.stderr, every.stderr[-2000:]
    own = _own_stderr(every.stderr)
    assert own[-1] == "ValueError: steps = 0 is invalid (rank 0 of 2)", every.stderr[-2000:]
    assert "rank 1: ValueError: steps = 0 is invalid (rank 1 of 2)" in every.stderr


def _readme_snippet() -> str:
    """The python block under "## What it does" in README.md."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## What it does"):]
    start = section.index("```python\n") + len("```python\n")
    return section[start:section.index("```\n", start)]


@pytest.mark.parametrize("ranks", [1, 2])
def test_readme_snippet(tmp_path, ranks):
    """The README's script runs as it stands (serial and 2 ranks): one line per increment of
    the load path 0.25 ... 1 ... 0.25, the contact force equal to the applied 250 N times the
    load factor (the interface carries the whole load: force balance, 4 digits printed)."""
    if ranks > 1 and MPIRUN is None:
        pytest.skip("mpirun not found")
    script = tmp_path / "readme_snippet.py"
    script.write_text(_readme_snippet())
    out = run([script], tmp_path, ranks)
    rows = [ln.split() for ln in out.splitlines() if ln.startswith("load ")]
    loads = [float(r[1].rstrip(":")) for r in rows]
    assert loads == [0.25, 0.5, 0.75, 1.0, 0.75, 0.5, 0.25]
    for lam, r in zip(loads, rows):
        assert float(r[4]) == pytest.approx(250.0 * lam, abs=0.006), r


def test_show_scene_mesh(tmp_path):
    out = run([DEMOS / "show_scene_mesh.py", "flat_punch", "--mesh-size", "40",
               "--contact-size", "10", "--xdmf", tmp_path / "punch.xdmf"], tmp_path)
    assert "contact_punch" in out and "area 100" in out
    assert (tmp_path / "punch.xdmf").exists()


def test_demo_beam_rigid_base(tmp_path):
    out = run([DEMOS / "demo_beam_rigid_base.py", "--cases", "1", "--mesh-size", "80",
               "--contact-size", "20", "--order", "1", "--steps", "2", "--no-xdmf",
               "--outdir", tmp_path / "beam"], tmp_path)
    assert "| 1 | 0.625 | elastic |" in out
    assert (tmp_path / "beam" / "table4.md").exists()


def test_study_flat_punch_cases(tmp_path):
    out = run([DEMOS / "study_flat_punch_cases.py", "--cases", "a", "--mesh-size", "25",
               "--contact-size", "5", "--steps", "2", "--normal-law", "elastic",
               "--outdir", tmp_path / "cases", "--figdir", tmp_path / "fig"], tmp_path)
    assert "case (a): D_cum peak" in out
    assert (tmp_path / "fig" / "punch_case_a.png").exists()


def test_demo_micro_model(tmp_path):
    out = run([DEMOS / "demo_micro_model.py", "--quick", "--out", tmp_path / "micro"], tmp_path)
    assert "Table 1" in out


def test_demo_friction_point(tmp_path):
    out = run([DEMOS / "demo_friction_point.py", "--out", tmp_path / "fp"], tmp_path)
    assert out.strip()


def test_demo_measured_surface(tmp_path):
    out = run([DEMOS / "demo_measured_surface.py", "--quick", "--out", tmp_path / "ms"],
              tmp_path)
    assert "grain" in out.lower()


def test_plot_interface_pressure(tmp_path):
    png = tmp_path / "pressure.png"
    run([DEMOS / "plot_interface_pressure.py", "--run", "--results", tmp_path / "res",
         "--out", png, "--mesh-size", "20", "--contact-size", "5", "--order", "1",
         "--steps", "2"], tmp_path)
    assert png.stat().st_size > 0


def test_compare_laws(tmp_path):
    out = run([DEMOS / "compare_laws.py", "--surface", "anisotropic", "--no-plastic",
               "--realisations", "1", "--ppw", "3", "--pressures", "4", "--backend", "numpy",
               "--out", tmp_path / "cmp"], tmp_path)
    assert "BEM" in out


def test_demo_punch_bem_vs_statistical(tmp_path):
    env_cache = tmp_path / "cache"
    os.environ["ROUGH_CONTACT_CACHE"] = str(env_cache)
    try:
        out = run([DEMOS / "demo_punch_bem_vs_statistical.py", "--small", "--backend", "numpy",
                   "--outdir", tmp_path / "pb"], tmp_path)
    finally:
        del os.environ["ROUGH_CONTACT_CACHE"]
    assert "secant punch stiffness" in out


def test_bench_solver_runs_every_option_set(tmp_path):
    """benchmarks/bench_solver.py on the small punch, 2 ranks: one summary row per set, each
    carrying the applied 250 N through the interface after the same Newton iterations."""
    out = run([ROOT / "benchmarks" / "bench_solver.py", "--sizes", "small", "--sets", "mumps",
               "mumps_lagged", "gamg", "hypre"], tmp_path, ranks=2 if MPIRUN else 1)
    rows = [line.split() for line in out.splitlines()
            if line.split()[:1] == ["small"] and len(line.split()) >= 12]
    assert [r[2] for r in rows] == ["mumps", "mumps_lagged", "gamg", "hypre"]
    for r in rows:
        assert abs(float(r[10]) - 250.0) < 1e-6, r
        assert all(1 <= int(k) <= 8 for k in r[3].split(",")), r


def run_streaming(args, tmp_path, ranks=1, timeout=600):
    """Run like :func:`run`, without PYTHONUNBUFFERED, reading stdout line by line as it comes:
    returns ``[(line, still_running)]`` (whether the process had not exited when the line was
    read: a progress line that only shows up at exit was not flushed)."""
    env = dict(os.environ, MPLBACKEND="Agg", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    env.pop("PYTHONUNBUFFERED", None)
    cmd = [sys.executable] + [str(a) for a in args]
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks)] + cmd
    lines = []
    with subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True) as proc:
        for line in proc.stdout:
            lines.append((line.rstrip("\n"), proc.poll() is None))
        err = proc.stderr.read()
        proc.wait(timeout=timeout)
    out = "\n".join(ln for ln, _ in lines)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{out[-3000:]}\n{err[-3000:]}"
    return lines


def test_demo_fretting(tmp_path):
    """Two amplitudes on 2 ranks (issue 24 items 17, 18): one progress line per cycle, printed
    (and flushed) while the run goes on; fretting_map.csv with the last cycle of each amplitude:
    at 0.3 um nothing slips (stick, A = 0: an elastic line), at 4 um the whole contact slips
    (gross slip) and A approaches the parallelogram of the elastic joint in series with a
    slider, 1 - F* / (k delta*), with k the stick stiffness measured independently by the 0.3 um
    loop (F* / delta*); E_d is the area of the program's last cycle in the per-increment CSV;
    the interface XDMF of every increment reads back."""
    from rough_contact.io.files import parse_xdmf
    from rough_contact.io.interface_output import read_interface_results

    ranks = 2 if MPIRUN else 1
    lines = run_streaming([DEMOS / "demo_fretting.py", "--amplitudes", "0.3", "4", "--cycles",
                           "2", "--steps-per-cycle", "16", "--mesh-size", "0.5", "--outdir",
                           tmp_path / "fret"], tmp_path, ranks)
    text = [ln for ln, _ in lines]
    cycle_line = re.compile(r"^  a = (\S+) um  cycle (\d/\d): F\* = .* A = .*\[[0-9.]+ s\]$")
    progress = [k for k, ln in enumerate(text) if cycle_line.match(ln)]
    assert [cycle_line.match(text[k]).groups() for k in progress] == [
        ("0.3", "1/2"), ("0.3", "2/2"), ("4", "1/2"), ("4", "2/2")]
    assert lines[progress[0]][1], "the first cycle's line arrived only when the run ended"
    table = text.index(next(ln for ln in text if ln.startswith("Fretting (last cycle")))
    assert table > progress[-1]
    import csv

    with open(tmp_path / "fret" / "fretting_map.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["amplitude_um"], r["cycle"], r["regime"]) for r in rows] == [
        ("0.3", "2", "stick"), ("4", "2", "gross slip")]
    small, large = ({k: float(v) for k, v in r.items() if k != "regime"} for r in rows)
    assert small["slip_fraction"] == 0 and abs(small["energy_ratio"]) < 1e-8
    assert large["slip_fraction"] == 1 and large["delta_um"] == pytest.approx(4.0, rel=1e-12)
    # a loop whose branches are never stiffer than the stick stiffness k and stay within +-F*
    # lies inside the parallelogram of slopes k through its tips: A <= 1 - F* / (k delta*),
    # reached by a sharp stick-slip loop (micro-slip rounds the corners off)
    k_stick = small["force_amplitude_N"] / (small["delta_um"] * 1e-3)      # elastic line
    parallelogram = 1.0 - large["force_amplitude_N"] / (k_stick * large["delta_um"] * 1e-3)
    assert 0.85 * parallelogram < large["energy_ratio"] < parallelogram
    # E_d is the loop area of the program's last cycle (pseudo-time 2 -> 3), not of a piece
    # cut at the minima: the trapezoidal F du over those increments of the per-increment CSV
    with open(tmp_path / "fret" / "loop_a4um.csv") as f:
        loop = np.array([[float(r[c]) for c in ("pseudo_time", "u_x_mm", "F_x_N",
                                                "slip_area_fraction")]
                         for r in csv.DictReader(f)])
    last = (loop[:, 0] >= 2.0 - 1e-9) & (loop[:, 0] <= 3.0 + 1e-9)
    t, u, fx, _ = loop[last].T
    assert t[0] == pytest.approx(2.0) and u[0] == pytest.approx(u[-1], abs=1e-15)
    area = float(np.sum(0.5 * (fx[1:] + fx[:-1]) * np.diff(u)))
    assert large["energy_Nmm"] == pytest.approx(area, rel=1e-8)
    assert large["energy_ratio"] == pytest.approx(
        area / (4 * large["force_amplitude_N"] * large["delta_um"] * 1e-3), rel=1e-8)
    # the interface series: one step per increment, time = the pseudo-time of the loop CSV
    t = loop[:, 0]
    xdmf = tmp_path / "fret" / "a4um" / "interface.xdmf"
    grids = parse_xdmf(xdmf).findall(".//Grid[@GridType='Uniform']")
    assert len(grids) == len(t) == 2 + 2 * 16
    res = read_interface_results(str(xdmf))
    np.testing.assert_allclose(res.times, t, rtol=1e-12)
    # the slipping share from the facet fields (area-weighted) is the CSV's at every step
    p = res.points[res.cells]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    share = [np.dot(res.field("slip_fraction", k), area)
             / np.dot(res.field("contact_fraction", k), area) for k in range(len(t))]
    np.testing.assert_allclose(share, loop[:, 3], rtol=1e-9, atol=1e-12)
    for name in ("fretting.png", "fretting_loops.png", "fretting_map.png", "loop_largest.png",
                 "cycles.csv"):
        assert (tmp_path / "fret" / name).exists(), name


def test_demo_fretting_help():
    """--help says how to run on several ranks, the PETSc prefix and the linear-solver default
    (issue 24 item 17)."""
    proc = subprocess.run([sys.executable, str(DEMOS / "demo_fretting.py"), "--help"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    for words in ("mpirun -n 2", "-fret_", "mumps_lagged", "--steps-per-cycle"):
        assert words in proc.stdout, words


def _bolt_rows(out):
    rows = [ln.split() for ln in out.splitlines()
            if len(ln.split()) == 10 and ln.split()[0].replace(".", "").isdigit()]
    return np.array([[float(v) for v in r] for r in rows])


def test_demo_bolt_head(tmp_path):
    """A cylinder meshed separately from its block (mortar pairing), rough law with friction,
    on 1 and 2 ranks: the run checks the force balance (<= 1e-8 of P) at every increment
    itself; the preload is carried (N = P), the friction force grows with the slide, stays
    below the largest friction coefficient (0.5) x N, and both runs print the same table."""
    args = [DEMOS / "demo_bolt_head.py", "--size-cylinder", "1.5", "--size-block", "2.5",
            "--shear-steps", "2"]
    tables = [_bolt_rows(run(args, tmp_path, ranks)) for ranks in ((1, 2) if MPIRUN else (1,))]
    t = tables[0]
    assert t.shape == (4, 10)
    P = 10.0 * np.pi * 25.0
    assert np.allclose(t[1:, 2], P, rtol=1e-4)        # N = P once preloaded (printed digits)
    assert np.all(np.diff(t[1:, 3]) > 0) and np.all(t[:, 4] <= 0.5)
    assert np.all(t[:, 8] <= 1e-8)                     # printed balance
    for other in tables[1:]:
        np.testing.assert_allclose(other[:, :8], t[:, :8], rtol=1e-3, atol=1e-9)


def test_demo_flat_punch_restart(tmp_path):
    """A run stopped after its first increment (``--stop-after 1``, its checkpoint written) and
    continued with ``--restart`` into the same folder ends with the dissipation of the
    uninterrupted run, and its history.csv and displacement.xdmf hold every increment once with
    the uninterrupted run's values; restarting from the checkpoint of a finished run has nothing
    left to do."""
    import re

    sys.path.insert(0, str(Path(__file__).parents[1] / "fem"))
    from test_checkpoint import _csv, _xdmf_steps

    full = run([DEMOS / "demo_flat_punch.py", *PUNCH_SMALL, "--outdir", tmp_path / "full"],
               tmp_path)
    stopped = run([DEMOS / "demo_flat_punch.py", *PUNCH_SMALL, "--outdir", tmp_path / "rest",
                   "--checkpoint", tmp_path / "ckpt", "--stop-after", "1"], tmp_path)
    assert "Stopped after 1 increments" in stopped
    resumed = run([DEMOS / "demo_flat_punch.py", *PUNCH_SMALL, "--outdir", tmp_path / "rest",
                   "--restart", tmp_path / "ckpt", "--checkpoint", tmp_path / "ckpt"], tmp_path)
    pattern = r"Total frictional dissipation D .*?: ([0-9.eE+-]+) N mm"
    assert re.search(pattern, resumed).group(1) == re.search(pattern, full).group(1)
    got, want = _csv(tmp_path / "rest" / "history.csv"), _csv(tmp_path / "full" / "history.csv")
    assert [r["step"] for r in got] == [r["step"] for r in want] == [1, 2, 3]
    for g, w in zip(got, want):
        assert g["dissipation_Nmm"] == pytest.approx(w["dissipation_Nmm"], rel=1e-9, abs=1e-12)
    t_got, u_got = _xdmf_steps(tmp_path / "rest" / "displacement.xdmf")
    t_want, u_want = _xdmf_steps(tmp_path / "full" / "displacement.xdmf")
    assert t_got == t_want
    for t in t_want:
        np.testing.assert_allclose(u_got[t], u_want[t], rtol=0,
                                   atol=1e-10 * np.abs(u_want[t_want[1]]).max())
    again = run([DEMOS / "demo_flat_punch.py", *PUNCH_SMALL, "--outdir", tmp_path / "again",
                 "--restart", tmp_path / "ckpt"], tmp_path)   # the checkpoint is now the end
    assert "Nothing left to do" in again
    assert re.search(r"dissipation D: ([0-9.eE+-]+) N mm", again).group(1) == \
        re.search(pattern, full).group(1)


@pytest.mark.parametrize("ranks", [1, 2])
def test_demo_fenicsx09_user(tmp_path, ranks):
    """The FEniCSx 0.9 user's script (its own mesh, space, forms and boundary conditions, a
    rough interface added, solved by the add-on's SNES driver and by the user's own Newton
    loop): the two solves agree and the contact force balances the load (the demo asserts it).
    Written in DOLFINx 0.9's spelling: on 0.5.2 it only says so."""
    import dolfinx
    if tuple(int(p) for p in dolfinx.__version__.split(".")[:2]) < (0, 8):
        pytest.skip("demo_fenicsx09_user.py is written for DOLFINx 0.9 (Debian 13)")
    if ranks > 1 and MPIRUN is None:
        pytest.skip("mpirun not found")
    out = run([DEMOS / "demo_fenicsx09_user.py", "--n", "3", "--out", tmp_path / "out"],
              tmp_path, ranks)
    assert "force balance" in out and "add-on vs own Newton" in out
    assert (tmp_path / "out" / "displacement.bp").is_dir()
