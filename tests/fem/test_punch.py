"""Flat punch (paper section 9.2) on coarse meshes: Newton convergence, rank independence, demo.

Serial and ``mpirun -n 2``. Units: mm, N, MPa.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.scenes import flat_punch as demo  # noqa: E402

from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402

# the elastic population builds its normal-law table in ~1 s (elasto-plastic: ~15 s)
COARSE = dict(mesh_size=20.0, contact_size=2.5, order=1, normal_law="elastic")


def run_punch(comm, steps=4, n_unload=1, prefix="test_punch_"):
    m = demo.build(comm=comm, steps=steps, prefix=prefix, **COARSE)
    incs = list(load_path(m.problem, m.solver, load_unload_factors(steps, n_unload),
                          verbose=False))
    return m, incs


def test_newton_quadratic_rough_orthotropic_friction():
    """Rough normal law + orthotropic slip-hardening friction: Newton converges quadratically."""
    m, incs = run_punch(MPI.COMM_WORLD)
    assert [i.load_factor for i in incs] == load_unload_factors(4, 1)
    assert all(i.cutbacks == 0 for i in incs)
    slipping = [i for i in incs if i.n_slipping > 0]
    assert slipping, "the coarse punch should slip near its edge at full load"
    for inc in incs:
        r = np.asarray(inc.residuals) / inc.residuals[0]
        assert inc.iterations <= 7
        assert r[-1] < 1e-9
        # once in the asymptotic range, e_{k+1} <= C e_k^2
        for k in range(len(r) - 1):
            if r[k] < 1e-1:
                assert r[k + 1] <= 10.0 * r[k] ** 2, (inc.step, r.tolist())
        # normal force balance at every converged increment
        assert np.isclose(inc.contact_force[2], -inc.applied_force[2], rtol=1e-8)
    m.solver.destroy()


def test_punch_results_do_not_depend_on_rank_count():
    """Integrated quantities on all ranks equal the serial (COMM_SELF) run to 1e-8."""
    comm = MPI.COMM_WORLD
    m_par, par = run_punch(comm, prefix="test_par_")
    D_par = m_par.interface.dissipation()
    m_ser, ser = run_punch(MPI.COMM_SELF, prefix="test_ser_")
    D_ser = m_ser.interface.dissipation()
    for a, b in zip(par, ser):
        assert a.n_active == b.n_active and a.n_slipping == b.n_slipping
        assert np.allclose(a.contact_force, b.contact_force, rtol=1e-8,
                           atol=1e-8 * abs(b.contact_force[2]))
        assert np.isclose(a.real_area, b.real_area, rtol=1e-8)
    assert D_ser > 0.0
    assert np.isclose(D_par, D_ser, rtol=1e-8)
    m_par.solver.destroy()
    m_ser.solver.destroy()


def test_demo_main_small(tmp_path):
    comm = MPI.COMM_WORLD
    outdir = comm.bcast(str(tmp_path), root=0)
    res = demo.run(mesh_size=20.0, contact_size=5.0, order=1, steps=2, outdir=outdir, comm=comm,
                    normal_law="elastic",
                    prefix="test_demo_", verbose=False)
    assert res.max_force_error < 1e-8
    assert len(res.history) == 3
    if comm.rank == 0:
        for name in ("history.csv", "displacement.xdmf", "displacement.h5", "interface.xdmf",
                     "slip_directions.png", "slip_directions_peak.png"):
            assert os.path.getsize(os.path.join(outdir, name)) > 0, name
        rows = open(os.path.join(outdir, "history.csv")).read().strip().splitlines()
        assert len(rows) == 1 + 3
        assert not any(f.endswith(".tmp" + str(os.getpid())) for f in os.listdir(outdir))


def test_demo_rejects_bad_case():
    with pytest.raises(ValueError, match="friction case"):
        demo.make_law(MPI.COMM_WORLD, case="z", seating_pressure=1.0)
