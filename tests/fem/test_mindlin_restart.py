"""Restart of the Mindlin scene (``mindlin.run(checkpoint=, restart=, stop_after=)``), serial
and on 2 ranks: the Mindlin–Deresiewicz runs at small amplitudes take hours, and a killed run
must lose no converged increment.

Reference: the same run without interruption. A run stopped after 3 increments (past the
normal load, its checkpoint written) and continued from the checkpoint gives the
uninterrupted run's rows (slide, P, Q, dissipation, Newton iterations, stick estimates) and
gathered point tractions to round-off: the multipliers of the exact enforcement and the
predictor's state are part of the checkpoint. Units: mm, N, MPa.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.scenes import mindlin
from rough_contact.solver.checkpoint import CheckpointError

SMALL = dict(contact_size=0.1, shear_steps=4, cycles=1, points="nodal", basis="dual",
             k_tangential=7.5e6)


def _run(**kwargs):
    return mindlin.run(enforcement=NewtonAugmentedLagrangian(1e-4, 60), **SMALL, **kwargs)


def test_stopped_run_continues(tmp_path):
    ck = MPI.COMM_WORLD.bcast(str(tmp_path / "ck"), root=0)
    full = _run()
    part = _run(checkpoint=ck, stop_after=3)
    assert part.t.size == 3 and full.t.size == 2 + 4
    rest = _run(checkpoint=ck, restart=ck)
    assert rest.t.size == full.t.size
    assert full.dissipation[-1] > 0.0                 # it slipped: the history matters
    for key in ("t", "slide", "P", "Q", "dissipation", "stick", "contact_area",
                "stick_front", "stick_radius"):
        ref = getattr(full, key)
        np.testing.assert_allclose(getattr(rest, key), ref, rtol=0,
                                   atol=1e-9 * max(np.nanmax(np.abs(ref)), 1e-300), err_msg=key)
    np.testing.assert_array_equal(rest.newton, full.newton)
    np.testing.assert_allclose(rest.points.x, full.points.x, rtol=0, atol=1e-14)
    for key in ("pressure", "shear"):
        ref = getattr(full.points, key)
        np.testing.assert_allclose(getattr(rest.points, key), ref, rtol=0,
                                   atol=1e-9 * np.abs(ref).max(), err_msg=key)
    np.testing.assert_array_equal(rest.points.slipping, full.points.slipping)


def test_a_finished_run_is_read_back_and_bad_stop_refused(tmp_path):
    """Continuing a run whose checkpoint is its last increment solves nothing and returns the
    whole run; ``stop_after`` < 1 is refused naming it."""
    ck = MPI.COMM_WORLD.bcast(str(tmp_path / "ck"), root=0)
    full = _run(checkpoint=ck)
    again = _run(checkpoint=ck, restart=ck)
    np.testing.assert_array_equal(again.Q, full.Q)
    np.testing.assert_array_equal(again.newton, full.newton)
    # the record read from the checkpoint without resuming (benchmarks/bench_normal_load_slip.py)
    t, P, pts = mindlin.checkpointed_points(ck)
    np.testing.assert_array_equal(t, full.t)
    np.testing.assert_array_equal(P, full.P)
    for key in ("x", "pressure", "shear", "contact", "slipping", "weight"):
        np.testing.assert_array_equal(getattr(pts, key), getattr(full.points, key), err_msg=key)
    with pytest.raises(CheckpointError, match="holds no complete checkpoint"):
        mindlin.checkpointed_points(str(tmp_path / "nothing"))
    with pytest.raises(ValueError, match="stop_after = 0 is invalid"):
        _run(stop_after=0)
