"""Flat punch with a normal law that remembers asperity plasticity (issue 23): load, unload.

Serial and ``mpirun -n 2`` (rank-agnostic: the serial reference is a COMM_SELF run in the same
process). The irreversible law here is a closed-form stand-in of an elasto-plastic population
(exponential loading, Hertz-like elastic unloading of fixed recovery DELTA from the smallest
separation h_min), so that the test takes seconds; the tabulated population law
(``HistoryNormalLaw.elasto_plastic``) implements the same protocol. Units: mm, N, MPa.
"""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np
from mpi4py import MPI

from rough_contact.io.files import prepare_output_dir
from rough_contact.io.interface_output import (InterfaceWriter, MEMORY_FIELD_NAMES,
                                               POINT_FIELD_NAMES)
from rough_contact.scenes import flat_punch as punch
from rough_contact.solver.loading import load_path, load_unload_factors

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: the shared stand-in law
from memory_law import DELTA, MemoryLaw  # noqa: E402

COARSE = dict(mesh_size=20.0, contact_size=2.5, order=1)
STEPS = 4
FACTORS = load_unload_factors(STEPS, STEPS - 1)      # up to 1, back to 1/4 (the seating load)


def _run(comm, normal, normal_law="elastic", outdir=None):
    m = punch.build(comm=comm, steps=STEPS, prefix="mem_", normal=normal, normal_law=normal_law,
                    **COARSE)
    ci = m.interface
    writer = None
    if outdir is not None:
        prepare_output_dir(outdir, comm)
        writer = InterfaceWriter(outdir, ci, points=True)
    incs, gaps = [], []
    for inc in load_path(m.problem, m.solver, FACTORS, verbose=False):
        incs.append(inc)
        pf = ci.point_fields()
        w = ci.point_weights()
        gaps.append(comm.allreduce(float(np.dot(w, pf.gap)), op=MPI.SUM)
                    / ci.nominal_area())
        if writer is not None:
            writer.write(inc.load_factor)
    return m, incs, np.array(gaps)


def test_memory_punch_settles_dissipates_and_does_not_depend_on_rank_count(tmp_path):
    comm = MPI.COMM_WORLD
    outdir = comm.bcast(str(tmp_path / "out"), root=0)
    m, incs, gaps = _run(comm, MemoryLaw(), outdir=outdir)
    ci = m.interface
    # residual settlement: back at the first load, the interface stays more closed
    settlement = gaps[0] - gaps[-1]
    assert incs[0].load_factor == incs[-1].load_factor == 1.0 / STEPS
    assert settlement > 0.1 * DELTA, settlement
    # normal hysteresis: > 0, accumulated only while loading, equal per step and in total to
    # D(h_min) of the committed state summed over the points (the law evaluated directly)
    Dn = ci.normal_dissipation()
    assert Dn > 0.0
    steps = np.array([i.normal_dissipation_step for i in incs])
    assert np.all(steps[STEPS:] == 0.0) and np.all(steps[:STEPS] > 0.0)
    np.testing.assert_allclose(steps.sum(), Dn, rtol=1e-12)
    assert incs[-1].normal_dissipation == Dn
    h_min = ci.history.law.committed.h_min
    direct = comm.allreduce(float(np.dot(ci.point_weights(),
                                         MemoryLaw().normal_dissipation(h_min))), op=MPI.SUM)
    np.testing.assert_allclose(Dn, direct, rtol=1e-12)
    assert ci.summary().normal_dissipation == Dn
    # point fields and the interface XDMF output carry the memory
    pf = ci.point_fields()
    np.testing.assert_array_equal(pf.h_min, h_min)
    assert np.all(pf.max_closure >= 0.0) and np.all(pf.normal_dissipation >= 0.0)
    if comm.rank == 0:
        with h5py.File(f"{outdir}/interface.h5", "r") as f:
            last = sorted(k for k in f if k.startswith("Step_"))[-1]
            assert set(MEMORY_FIELD_NAMES) <= set(f[last]["points"])
            assert set(f[last]["points"]) == set(POINT_FIELD_NAMES) | set(MEMORY_FIELD_NAMES)
            assert np.nanmax(f[last]["points"]["max_closure_mm"][...]) > 0.0
    # one rank (COMM_SELF, the whole mesh) = this run's rank count
    m1, incs1, gaps1 = _run(MPI.COMM_SELF, MemoryLaw())
    np.testing.assert_allclose(m1.interface.normal_dissipation(), Dn, rtol=1e-10)
    np.testing.assert_allclose(gaps1, gaps, rtol=1e-10)
    for a, b in zip(incs, incs1):
        assert a.n_active == b.n_active and a.n_slipping == b.n_slipping
        np.testing.assert_allclose(a.contact_force, b.contact_force, rtol=0,
                                   atol=1e-10 * abs(b.contact_force[2]))
        np.testing.assert_allclose(a.dissipation, b.dissipation, rtol=1e-10, atol=1e-14)
    m.solver.destroy()
    m1.solver.destroy()


def test_elastic_population_with_memory_is_the_reversible_law():
    comm = MPI.COMM_WORLD
    m0, incs0, gaps0 = _run(comm, None, "elastic")
    m1, incs1, gaps1 = _run(comm, None, "elastic-memory")
    assert m1.interface.point_fields().h_min is not None
    assert m0.interface.point_fields().h_min is None
    np.testing.assert_allclose(gaps1, gaps0, rtol=0, atol=1e-12 * np.abs(gaps0).max())
    for a, b in zip(incs0, incs1):
        np.testing.assert_allclose(b.contact_force, a.contact_force, rtol=0,
                                   atol=1e-12 * abs(a.contact_force[2]))
        np.testing.assert_allclose(b.dissipation, a.dissipation, rtol=1e-12, atol=1e-18)
        assert b.normal_dissipation == 0.0
    m0.solver.destroy()
    m1.solver.destroy()


def test_checkpoint_resume_keeps_h_min_and_normal_dissipation(tmp_path):
    """A run stopped at step 3 (before its checkpoint) and resumed from its checkpoint ends with the uninterrupted
    run's normal hysteresis, per step and in total (h_min and the sum travel in the
    checkpoint's interface state)."""
    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path / "ckpt"), root=0)
    _, ref, _ = _run(comm, MemoryLaw())
    m = punch.build(comm=comm, steps=STEPS, prefix="mem_", normal=MemoryLaw(), **COARSE)
    for inc in load_path(m.problem, m.solver, FACTORS, verbose=False, checkpoint=directory):
        if inc.step == 3:
            break
    m.solver.destroy()
    m = punch.build(comm=comm, steps=STEPS, prefix="mem_", normal=MemoryLaw(), **COARSE)
    resumed = list(load_path(m.problem, m.solver, FACTORS, verbose=False, resume=directory))
    assert [i.step for i in resumed] == [i.step for i in ref[2:]]
    for a, b in zip(resumed, ref[2:]):
        np.testing.assert_allclose(a.normal_dissipation_step, b.normal_dissipation_step,
                                   rtol=1e-10, atol=1e-15)
        np.testing.assert_allclose(a.normal_dissipation, b.normal_dissipation, rtol=1e-10)
    assert resumed[-1].normal_dissipation > 0.0
    m.solver.destroy()
