"""Multi-process runs driven from a serial test.

(1) A rank killed with SIGKILL during a checkpointed run: the run resumed from the checkpoint
directory ends exactly where the uninterrupted run ends (issue 10: "SIGKILL at any moment never
corrupts the last checkpoint").

Two ranks run the checkpoint test's rough-law program (preload, two tangential cycles with
slip hardening) writing a checkpoint at every converged increment; once a given step has been
reported, rank 1 is killed with SIGKILL (so the kill lands wherever that rank is: solving the
next increment or writing its checkpoint; the test is repeated at three steps). A fresh 2-rank run
resumes from the directory; its final dissipation, contact force and displacement norm equal the
uninterrupted run's to 1e-12 relative, and its output files (history.csv, displacement.xdmf,
interface.xdmf, written by the killed run and continued by the resumed one) hold every increment
once with the uninterrupted run's values.

(2) A checkpoint written on 2 ranks resumed on 1, and the reverse (issue 24: restart does not
depend on the partition): the same program stopped after increment 9 (the first tangential
cycle, slipping) and resumed on the other number of ranks ends with the uninterrupted run's
dissipation, contact force and displacement norms on the resuming number of ranks to 1e-10
relative; its history.csv and interface.xdmf equal that run's, and displacement.xdmf holds every
increment once with the same values at every point (read through the mesh grid each step
points to: the node order of an XDMF mesh may follow the partition).

(3) The non-matching pairings' rank-independence test on 3 ranks (issue 9: 1 = 2 = 3 ranks).

Runs the workers with mpirun; skipped without it.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from kill_rank import kill_checkpointed_run, worker_cmd

MPIRUN = shutil.which("mpirun")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OPENBLAS_NUM_THREADS="1")


def _figures(cmd, out, env=ENV, timeout=600):
    """Run a worker command; the figures it wrote as JSON into ``out``."""
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return json.loads(Path(out).read_text())


def _run(mode, directory, out, timeout=600, ranks=2, stop_after=None, degree=1):
    return _figures(worker_cmd(mode, directory, out, ranks, stop_after), out,
                    env=dict(ENV, RC_WORKER_DEGREE=str(degree)), timeout=timeout)


def _same_output(run, ref, n_steps):
    """The killed-and-resumed run's files hold each increment once, as the reference's do."""
    sys.path.insert(0, str(Path(__file__).parents[1] / "fem"))
    from test_checkpoint import _csv, _xdmf_steps

    from rough_contact.io import read_interface_results

    got, want = _csv(run / "history.csv"), _csv(ref / "history.csv")
    assert [r["step"] for r in got] == list(range(1, n_steps + 1))
    for g, w in zip(got, want):
        for key in ("load_factor", "dissipation_Nmm", "contact_fz_N", "contact_fx_N"):
            assert g[key] == pytest.approx(w[key], rel=1e-9, abs=1e-12), key
    t_run, u_run = _xdmf_steps(run / "displacement.xdmf")
    t_ref, u_ref = _xdmf_steps(ref / "displacement.xdmf")
    assert t_run == t_ref and len(t_ref) == n_steps
    scale = max(np.abs(u).max() for u in u_ref.values())
    for t in t_ref:
        np.testing.assert_allclose(u_run[t], u_ref[t], rtol=0, atol=1e-12 * scale)
    a, b = read_interface_results(str(run / "interface.xdmf")), \
        read_interface_results(str(ref / "interface.xdmf"))
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_allclose(a.field("dissipation_N_per_mm"), b.field("dissipation_N_per_mm"),
                               rtol=1e-9, atol=1e-12 * np.abs(b.field("dissipation_N_per_mm")).max())


@pytest.mark.skipif(MPIRUN is None, reason="needs mpirun")
def test_sigkill_then_resume(tmp_path):
    reference = _run("full", tmp_path / "unused", tmp_path / "full.json")
    for kill_after in (3, 7, 12):
        directory = tmp_path / f"ckpt_{kill_after}"
        proc, killed = kill_checkpointed_run(directory, tmp_path / "never.json", ENV, kill_after)
        assert killed and proc.returncode != 0           # the run did die
        resumed = _run("resume", directory, tmp_path / f"resumed_{kill_after}.json")
        assert resumed["step"] == reference["step"]
        # it did resume from the last complete checkpoint: the checkpoint of step k is written
        # after the loop body of step k (its output), so at or after the reported step
        assert kill_after <= resumed["first"] <= reference["step"]
        _same_output(Path(f"{directory}_out"), tmp_path / "full_out", reference["step"])
        for key in ("D", "unorm", "umax"):
            assert resumed[key] == pytest.approx(reference[key], rel=1e-12), key
        np.testing.assert_allclose(resumed["F"], reference["F"], rtol=1e-12,
                                   atol=1e-12 * np.abs(reference["F"]).max())


def _displacement_by_point(path: Path, time: float) -> dict:
    """{rounded node coordinates: (sum of the values, sum of their squares)} of the step at
    ``time`` of a DOLFINx displacement.xdmf, read through the mesh grid the step points to (a
    partition-free view: coincident nodes of two bodies are summed)."""
    import h5py

    from rough_contact.io.files import parse_xdmf

    root = parse_xdmf(str(path))     # the xi namespace: http (0.5.2) or https (0.9)
    domain = root.find("Domain")
    step = next(g for g in root.iter("Grid") if g.find("Time") is not None
                and float(g.find("Time").get("Value")) == time)
    pointer = next(c for c in step if c.tag.endswith("}include")).get("xpointer")
    name = pointer.split("@Name='")[1].split("'")[0] if "@Name=" in pointer else None
    mesh = next(g for g in domain.findall("Grid") if g.get("GridType") == "Uniform"
                and (name is None or g.get("Name") == name))

    def read(item):
        file, _, dataset = item.text.strip().partition(":")
        with h5py.File(path.parent / file, "r") as f:
            return f[dataset][...]

    x = read(mesh.find("Geometry/DataItem"))
    u = read(step.find("Attribute/DataItem"))
    out = {}
    for xk, uk in zip(np.round(x, 9), u):
        key = tuple(xk.tolist())
        s, q = out.get(key, (0.0, 0.0))
        out[key] = (s + uk, q + uk * uk)
    return name, out


@pytest.mark.skipif(MPIRUN is None, reason="needs mpirun")
@pytest.mark.parametrize("written, resumed", [(2, 1), (1, 2)])
def test_resume_on_another_number_of_ranks(tmp_path, written, resumed):
    reference = _run("full", tmp_path / "unused", tmp_path / "full.json", ranks=resumed)
    directory = tmp_path / "ckpt"
    stopped = _run("checkpointed", directory, tmp_path / "stopped.json", ranks=written,
                   stop_after=9)
    assert stopped["step"] == 9 and stopped["D"] > 0.0         # slipping: history matters
    got = _run("resume", directory, tmp_path / "resumed.json", ranks=resumed)
    assert got["first"] == 10 and got["step"] == reference["step"]
    for key in ("D", "unorm", "umax"):
        assert got[key] == pytest.approx(reference[key], rel=1e-10), key
    np.testing.assert_allclose(got["F"], reference["F"], rtol=1e-10,
                               atol=1e-10 * np.abs(reference["F"]).max())
    sys.path.insert(0, str(Path(__file__).parents[1] / "fem"))
    from test_checkpoint import _csv, _xdmf_steps

    from rough_contact.io import read_interface_results

    run, ref = Path(f"{directory}_out"), tmp_path / "full_out"
    rows, want = _csv(run / "history.csv"), _csv(ref / "history.csv")
    assert [r["step"] for r in rows] == list(range(1, reference["step"] + 1))
    for g, w in zip(rows, want):
        for key in ("load_factor", "dissipation_Nmm", "contact_fz_N", "contact_fx_N"):
            assert g[key] == pytest.approx(w[key], rel=1e-9, abs=1e-12), key
    a, b = (read_interface_results(str(d / "interface.xdmf")) for d in (run, ref))
    np.testing.assert_array_equal(a.times, b.times)
    scale = np.abs(b.field("dissipation_N_per_mm")).max()
    np.testing.assert_allclose(a.field("dissipation_N_per_mm"), b.field("dissipation_N_per_mm"),
                               rtol=1e-9, atol=1e-10 * scale)
    times, _ = _xdmf_steps(run / "displacement.xdmf")
    assert times == _xdmf_steps(ref / "displacement.xdmf")[0] and len(times) == reference["step"]
    umax = reference["umax"]
    for t in (times[0], times[-1]):          # written by the stopped run / by the resumed one
        _, mine = _displacement_by_point(run / "displacement.xdmf", t)
        _, theirs = _displacement_by_point(ref / "displacement.xdmf", t)
        assert mine.keys() == theirs.keys()
        for key, (s, q) in theirs.items():
            np.testing.assert_allclose(mine[key][0], s, rtol=0, atol=1e-10 * umax)
            np.testing.assert_allclose(mine[key][1], q, rtol=0, atol=1e-10 * umax ** 2)


@pytest.mark.skipif(MPIRUN is None, reason="needs mpirun")
@pytest.mark.parametrize("written, resumed", [(2, 1), (1, 2)])
def test_p2_on_an_affine_mesh_resumes_on_another_number_of_ranks(tmp_path, written, resumed):
    """P2 on an affine tetrahedral mesh: the midside nodes are not geometry nodes and are keyed
    by their edge's end vertices (``compat.node_keys``); the rough-law program stopped after 9
    increments on one number of ranks and resumed on the other ends with the uninterrupted
    run's dissipation, contact force and displacement norms to 1e-10."""
    reference = _run("full", tmp_path / "unused", tmp_path / "full.json", ranks=resumed,
                     degree=2)
    directory = tmp_path / "ck"
    stopped = _run("checkpointed", directory, tmp_path / "stopped.json", ranks=written,
                   stop_after=9, degree=2)
    assert stopped["step"] == 9 and stopped["D"] > 0.0
    meta = json.loads(next(directory.glob("slot*/meta.json")).read_text())
    assert meta["keyed"] and meta["signature"]["ranks"] == written
    got = _run("resume", directory, tmp_path / "resumed.json", ranks=resumed, degree=2)
    assert got["first"] == 10 and got["step"] == reference["step"]
    for key in ("D", "unorm", "umax"):
        assert got[key] == pytest.approx(reference[key], rel=1e-10), key
    np.testing.assert_allclose(got["F"], reference["F"], rtol=1e-10,
                               atol=1e-10 * np.abs(reference["F"]).max())


def _mindlin(mode, directory, out, ranks):
    worker = Path(__file__).with_name("mindlin_worker.py")
    return _figures([MPIRUN, "-n", str(ranks), sys.executable, str(worker), mode,
                     str(directory), str(out)], out)


@pytest.mark.skipif(MPIRUN is None, reason="needs mpirun")
@pytest.mark.parametrize("written, resumed", [(1, 2), (2, 1)])
def test_mindlin_p2_resume_on_another_number_of_ranks(tmp_path, written, resumed):
    """The Mindlin scene (P2 on its quadratic geometry, nodal dual points, exact stick: the
    multipliers and the predictor's state are in the checkpoint) stopped after 3 increments on
    one number of ranks and continued on the other ends with the uninterrupted run's rows (on
    the resuming number of ranks) and gathered tractions to 1e-9: how a long Mindlin–Deresiewicz
    run moves from one rank to two."""
    directory = tmp_path / "ck"
    full = _mindlin("full", directory, tmp_path / "full.json", resumed)
    _mindlin("stopped", directory, tmp_path / "stopped.json", written)
    meta = json.loads(next(directory.glob("slot*/meta.json")).read_text())
    assert meta["keyed"] and meta["signature"]["ranks"] == written
    got = _mindlin("resume", directory, tmp_path / "resumed.json", resumed)
    assert len(got["t"]) == len(full["t"]) == 6 and full["dissipation"][-1] > 0.0
    for key in ("t", "slide", "P", "Q", "dissipation", "stick", "contact_area"):
        ref = np.asarray(full[key])
        np.testing.assert_allclose(got[key], ref, rtol=0, atol=1e-9 * np.abs(ref).max(),
                                   err_msg=key)
    np.testing.assert_allclose(got["x"], full["x"], rtol=0, atol=1e-14)
    for key in ("pressure", "shear"):
        ref = np.asarray(full[key])
        np.testing.assert_allclose(got[key], ref, rtol=0, atol=1e-9 * np.abs(ref).max(),
                                   err_msg=key)
    assert got["slipping"] == full["slipping"]


@pytest.mark.skipif(MPIRUN is None, reason="needs mpirun")
def test_nonmatching_pairings_on_three_ranks():
    """Issue 9 asks 1 = 2 = 3 ranks: the rank-independence test of the non-matching pairings
    (COMM_WORLD figures against COMM_SELF ones, 1e-10) on 3 ranks (2 cores: oversubscribed)."""
    test = Path(__file__).parents[1] / "fem" / "test_nonmatching.py"
    cmd = [MPIRUN, "-n", "3", "--oversubscribe", sys.executable, "-m", "pytest", "-q",
           "-p", "no:cacheprovider", str(test), "-k", "rank_independent"]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
