"""The user law of docs/writing_a_law.md in the punch scene: it runs through the FE layer
unchanged, and its results do not depend on the number of ranks (1, 2 and 3).

The law is taken from the page itself (its single python block), so the page cannot drift away
from what runs. Run as a script, this module prints the integrated results as JSON (used for the
3-rank run, started as a subprocess from the serial test).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import load_path, load_unload_factors

DOC = Path(__file__).resolve().parents[2] / "docs" / "writing_a_law.md"
SMALL = dict(mesh_size=20.0, contact_size=5.0, order=1)


def user_law():
    """ExponentialCoulombLaw from the page's python block, with p(0) = 16 MPa seating."""
    block, = re.findall(r"^```python\n(.*?)^```", DOC.read_text(encoding="utf-8"),
                        flags=re.S | re.M)
    mod = types.ModuleType("writing_a_law_example_fem")
    sys.modules[mod.__name__] = mod
    exec(compile(block, str(DOC), "exec"), mod.__dict__)
    return mod.ExponentialCoulombLaw(p0=1.0, length=1e-3, mu=0.05, kt_over_kn=0.7, g_open=3e-3)


def run_user_law(comm, prefix):
    """Load the quarter punch to 1000 N in 4 increments and back to 1/4; integrated results."""
    m = flat_punch.build(comm, law=user_law(), steps=4, prefix=prefix, **SMALL)
    rows = []
    for inc in load_path(m.problem, m.solver, load_unload_factors(4, 3), verbose=False):
        s = m.interface.summary()
        rows.append(dict(load=inc.load_factor, iterations=inc.iterations,
                         force=[float(v) for v in inc.contact_force],
                         applied=[float(v) for v in inc.applied_force],
                         area=float(inc.real_area), dissipation=float(inc.dissipation),
                         n_slipping=int(s.n_slipping), n_contact=int(s.n_contact)))
    m.solver.destroy()
    return rows


def compare(a, b, rtol=1e-9):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x["load"] == y["load"]
        assert x["n_contact"] == y["n_contact"] and x["n_slipping"] == y["n_slipping"]
        scale = abs(y["force"][2])
        np.testing.assert_allclose(x["force"], y["force"], rtol=rtol, atol=rtol * scale)
        np.testing.assert_allclose(x["area"], y["area"], rtol=rtol)
        np.testing.assert_allclose(x["dissipation"], y["dissipation"], rtol=rtol,
                                   atol=1e-14 * scale)


def test_user_law_runs_in_the_punch_with_force_balance():
    rows = run_user_law(MPI.COMM_WORLD, "ulaw_world_")
    for r in rows:  # the normal interface force carries the applied load
        assert abs(r["force"][2] + r["applied"][2]) <= 1e-8 * abs(r["applied"][2])
    # identical bodies: a small lateral mismatch, so mu = 0.05 makes most points slip on the way
    # up; on the first unloading step the tractions reverse and every point sticks again
    assert 0 < rows[3]["n_slipping"] <= rows[3]["n_contact"]
    assert rows[4]["n_slipping"] == 0
    assert rows[-1]["dissipation"] > 0.0


def test_user_law_same_on_any_rank_count():
    """COMM_WORLD (1 or 2 ranks under the test command) equals COMM_SELF; the serial run also
    starts 3 ranks as a subprocess and compares."""
    world = run_user_law(MPI.COMM_WORLD, "ulaw_cmp_world_")
    alone = run_user_law(MPI.COMM_SELF, "ulaw_cmp_self_")
    compare(world, alone)
    if MPI.COMM_WORLD.size > 1:
        return
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found: the 3-rank comparison needs it")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([mpirun, "--oversubscribe", "-n", "3", sys.executable,
                           "-m", "mpi4py", __file__], env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    three = json.loads(proc.stdout.strip().splitlines()[-1])
    compare(three, alone)


if __name__ == "__main__":
    rows = run_user_law(MPI.COMM_WORLD, "ulaw_script_")
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(rows))
