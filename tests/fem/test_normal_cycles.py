"""Normal load cycles of the fretting joint with a normal law that remembers asperity plasticity
(issue 23, item 4): shakedown of the normal hysteresis. Serial and ``mpirun -n 2``.

The law is the closed-form stand-in of tests/memory_law.py (exponential loading, Hertz-like
unloading of fixed recovery DELTA from h_min). Its D(h_min) = (LAM - 2 DELTA/5) p_L(h_min) is
linear in the loading pressure, so while every point loads (the ramp to the peak of cycle 1) the
normal hysteresis summed over the interface is (LAM - 2 DELTA/5) times the increase of the normal
interface force: cycle 1 (from low P to P) dissipates (LAM - 2 DELTA/5)(1 - low) P, whatever
the pressure distribution. Later cycles at the same amplitude reload along the branch of the
same h_min: no point goes below it, no normal hysteresis (exactly, up to the Newton tolerance).
Reference for the rank count: a COMM_SELF run in the same process. Units: mm, N, MPa.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.scenes import fretting
from rough_contact.solver.program import cycle_summary, preload_then_normal_cycles

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: the shared stand-in law
from memory_law import DELTA, LAM, MemoryLaw  # noqa: E402

SMALL = dict(cycles=5, steps_per_cycle=4, mesh_size=0.5, order=1, low=0.1, pressure=10.0,
             case="b", progress=False)


def test_normal_cycle_program_and_bad_input():
    p = preload_then_normal_cycles(preload_steps=2, cycles=2, steps_per_cycle=4, low=0.2)
    assert p.cycle_start == 1.0 and len(p.times) == 2 + 8
    np.testing.assert_allclose([p.channels["preload"](t) for t in p.times],
                               [0.1, 0.2, 0.6, 1.0, 0.6, 0.2, 0.6, 1.0, 0.6, 0.2], atol=1e-15)
    np.testing.assert_array_equal([p.channels["cyclic"](t) for t in p.times], 0.0)
    c = preload_then_normal_cycles(1, 1, 4, low=0.5, shape="cosine", tangential=2.0)
    np.testing.assert_allclose([c.channels["preload"](t) for t in c.times],
                               [0.5, 0.75, 1.0, 0.75, 0.5], atol=1e-15)
    np.testing.assert_allclose([c.channels["cyclic"](t) for t in c.times],
                               [0.0, 2.0, 0.0, -2.0, 0.0], atol=1e-15)
    with pytest.raises(ValueError, match="steps_per_cycle = 3 is invalid: it must be even"):
        preload_then_normal_cycles(1, 1, 3)
    with pytest.raises(ValueError, match="low"):
        preload_then_normal_cycles(1, 1, 4, low=1.0)
    with pytest.raises(ValueError, match="low"):
        preload_then_normal_cycles(1, 1, 4, low=0.0)
    with pytest.raises(ValueError, match="shape = 'sine' is invalid"):
        preload_then_normal_cycles(1, 1, 4, shape="sine")
    # the per-cycle normal hysteresis is the cumulative one's increase over the cycle
    t = np.array(p.times)
    dn = np.array([0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0, 3.5, 3.5, 3.5])
    rows = cycle_summary(t, p, np.linspace(0, 1, t.size), np.ones(t.size), np.zeros(t.size),
                         normal_dissipation=dn)
    assert [r["normal_dissipated"] for r in rows] == [2.0, 0.5]   # dn[5] - dn[1], dn[9] - dn[5]
    assert "normal_dissipated" not in cycle_summary(t, p, t, t, t)[0]
    with pytest.raises(ValueError, match="normal_dissipation of shape"):
        cycle_summary(t, p, t, t, t, normal_dissipation=dn[:-1])


def test_normal_hysteresis_shakes_down_after_the_first_cycle():
    comm = MPI.COMM_WORLD
    r = fretting.run_normal_cycles(normal=MemoryLaw(), comm=comm, **SMALL)
    assert len(r.cycles) == 5
    dn = np.array([c["normal_dissipated"] for c in r.cycles])
    expected = (LAM - 0.4 * DELTA) * (1.0 - SMALL["low"]) * r.force
    # the interface force balances the applied load (so the closed form applies)
    np.testing.assert_allclose(r.fz, r.load, rtol=1e-9)
    assert dn[0] > 0.0
    np.testing.assert_allclose(dn[0], expected, rtol=1e-9)
    assert np.all(np.abs(dn[1:]) <= 1e-12 * dn[0]), dn
    # the normal load's work over a shaken-down cycle closes (elastic reloading branch)
    works = np.array([c["loop_energy"] for c in r.cycles])
    assert works[0] > dn[0] * 0.5 and np.all(np.abs(works[1:]) <= 1e-9 * works[0]), works
    # one rank (COMM_SELF, the whole mesh) = this run's rank count
    r1 = fretting.run_normal_cycles(normal=MemoryLaw(), comm=MPI.COMM_SELF, **SMALL)
    for name in ("gap", "approach", "fz", "normal_dissipation"):
        a, b = getattr(r, name), getattr(r1, name)
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(b).max(),
                                   err_msg=name)
    np.testing.assert_allclose(r.dissipation, r1.dissipation, rtol=1e-10,
                               atol=1e-10 * max(np.abs(r1.normal_dissipation).max(), 1e-300))
    np.testing.assert_allclose(dn, [c["normal_dissipated"] for c in r1.cycles], rtol=1e-10,
                               atol=1e-10 * dn[0])


def test_bolt_cycles_bad_mode():
    from rough_contact.scenes import bolt_head
    with pytest.raises(ValueError, match="mode = 'axial' is invalid: it must be 'normal' or "
                       "'tangential'"):
        bolt_head.run_cycles("axial")
    with pytest.raises(ValueError, match="amplitude"):
        bolt_head.run_cycles("tangential", amplitude_um=-1.0)
