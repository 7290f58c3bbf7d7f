"""Restart of the fretting scene (issue 10: "--restart DIR resumes a killed run ... its output
files continue seamlessly"), serial and on 2 ranks.

Reference: the same amplitude run without interruption. A run stopped after 5 increments
(its checkpoint written) and continued from the checkpoint directory gives the uninterrupted
run's hysteresis loop (u_x, F_x) and dissipation to 1e-12; its per-increment CSV and its
interface XDMF hold every increment once (the XDMF fields those of the uninterrupted run to
1e-10 of their size). The all-amplitudes driver restarted from a checkpoint directory reads back a
finished amplitude without solving it again (same loop, 0 Newton iterations spent on it) and runs
the missing one. The joint's interface stiffness measured at the end of the preload is kept
with the checkpoint: a run continued past the preload reports the uninterrupted run's value
(issue 24: it printed NaN). Units: mm, N, MPa.
"""

from __future__ import annotations

import csv
import os

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem import compat
from rough_contact.io.interface_output import read_interface_results
from rough_contact.scenes import fretting

SMALL = dict(cycles=1, steps_per_cycle=8, mesh_size=0.5, order=1)


def _tmp(tmp_path, name):
    return MPI.COMM_WORLD.bcast(str(tmp_path / name), root=0)


def test_stopped_amplitude_continues(tmp_path):
    xfull, xpart = _tmp(tmp_path, "xdmf_full"), _tmp(tmp_path, "xdmf_part")
    full = fretting.run_amplitude(2.0, interface_dir=xfull, **SMALL)
    ck, loop = _tmp(tmp_path, "ck"), _tmp(tmp_path, "loop.csv")
    part = fretting.run_amplitude(2.0, checkpoint=ck, loop_csv=loop, stop_after=5,
                                  interface_dir=xpart, **SMALL)
    assert len(part.t) == 5
    rest = fretting.run_amplitude(2.0, checkpoint=ck, restart=ck, loop_csv=loop,
                                  interface_dir=xpart, **SMALL)
    assert len(rest.t) == len(full.t) and rest.solved == len(full.t) - 5
    for key in ("t", "u", "fx", "fz", "dissipation"):
        scale = np.abs(getattr(full, key)).max()
        np.testing.assert_allclose(getattr(rest, key), getattr(full, key), rtol=0,
                                   atol=1e-12 * scale, err_msg=key)
    assert full.dissipation[-1] > 0.0                         # it slipped: history matters
    # issue 24: the continued run started past the preload (step 2) and reported the joint's
    # stiffness as NaN; it is kept with the checkpoint and equals the uninterrupted run's
    assert np.isfinite(full.k_normal) and full.k_normal > 0.0
    assert rest.k_normal == pytest.approx(full.k_normal, rel=1e-12)
    assert rest.k_tangential == pytest.approx(full.k_tangential, rel=1e-12)
    if MPI.COMM_WORLD.rank == 0:
        with open(loop) as f:
            rows = list(csv.DictReader(f))
        assert len(rows) == len(full.t)
        np.testing.assert_allclose([float(r["F_x_N"]) for r in rows], full.fx, rtol=1e-11,
                                   atol=1e-11 * np.abs(full.fx).max())
    # the interface series continues: every increment once, the uninterrupted run's fields
    a = read_interface_results(os.path.join(xfull, "interface.xdmf"))
    b = read_interface_results(os.path.join(xpart, "interface.xdmf"))
    np.testing.assert_allclose(b.times, full.t, rtol=1e-14)
    np.testing.assert_allclose(a.times, full.t, rtol=1e-14)
    for step in (4, 5, len(full.t) - 1):
        for name in ("pressure_MPa", "shear_traction_MPa", "slip_fraction"):
            fa, fb = a.field(name, step), b.field(name, step)
            np.testing.assert_allclose(fb, fa, rtol=0, atol=1e-10 * max(np.abs(fa).max(), 1),
                                       err_msg=f"{name} at step {step}")


def test_driver_restart_reads_finished_amplitudes(tmp_path):
    ck, out = _tmp(tmp_path, "ck"), _tmp(tmp_path, "out")
    first = fretting.run([0.5], outdir=out, plot=False, checkpoint=ck, **SMALL)
    again = fretting.run([0.5, 2.0], outdir=out, plot=False, restart=ck, **SMALL)
    assert again[0].solved == 0 and first[0].solved == len(first[0].t)  # read back
    assert again[0].report() == first[0].report()          # the same last-cycle figures
    for r in again:                                        # one interface step per increment
        res = read_interface_results(os.path.join(out, f"a{r.amplitude_um:g}um",
                                                  "interface.xdmf"))
        np.testing.assert_allclose(res.times, r.t, rtol=1e-14)
    np.testing.assert_allclose(again[0].fx, first[0].fx, rtol=0,
                               atol=1e-12 * np.abs(first[0].fx).max())
    assert again[1].solved == len(again[1].t) == len(first[0].t)
    # the amplitude read back reports the stiffness its run measured (was NaN: issue 24); it is
    # what the driver prints as "preloaded joint: interface normal stiffness ..."
    assert again[0].k_normal == pytest.approx(first[0].k_normal, rel=1e-12)
    assert np.isfinite(again[0].k_tangential) and again[0].k_tangential > 0.0
    assert again[1].dissipation[-1] > again[0].dissipation[-1]
    with pytest.raises(ValueError, match="max_steps = 0 is invalid"):
        fretting.run_amplitude(0.5, stop_after=0, **SMALL)


def test_interface_stiffness_of_a_linear_penalty():
    """The joint's interface stiffness the fretting scene reports (ContactInterface.
    interface_stiffness) is int dt/djump dA: for a bilateral linear penalty k_N, k_T on a flat
    2 x 2 mm interface it is (k_N, k_T, k_T) x 4 mm^2 (non-matching meshes, mortar pairing)."""
    from dolfinx import fem

    from rough_contact.fem.contact import ContactInterface
    from rough_contact.interface.penalty import LinearPenalty
    from rough_contact.scenes.meshes.blocks import separate_blocks

    scene = separate_blocks(lx=2.0, ly=2.0, size_lower=0.5, size_upper=0.7)
    V = compat.vector_space(scene.mesh, 1)
    ci = ContactInterface(V, scene.facet_tags, *scene.contact_pair,
                          law=LinearPenalty(3e4, k_tangential=1e4), pairing="mortar")
    ci.evaluate(fem.Function(V))
    np.testing.assert_allclose(ci.interface_stiffness(), [1.2e5, 4e4, 4e4], rtol=1e-12)
