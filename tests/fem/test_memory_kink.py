"""Repeated normal load cycles with a normal law whose unloading is stiffer than its loading
(issue 23, item 4: the bolt-head normal cycles that stopped at the peak of cycle 5). Serial and
``mpirun -n 2``.

At the peak of a repeated cycle every loaded point comes back to its h_min, where the normal
tangent jumps from the first unloading stiffness k_rev to the loading tangent k_load. The
normal residual is continuous there (p is), and semismooth Newton copes with the kink; but the
tangential stiffness k_T = c k_N jumped with it, so the tangential traction c k_N (s - s_p) of
every point in stick was discontinuous at the solution, and Newton stalled (backtracking to 10 %
steps) until the load step failed. ``InterfaceLaw`` now scales k_N by k_load(h_min)/k_rev(h_min)
in k_T on the unloading branch of a law that states its reversal stiffness
(``ReversalStiffnessProtocol``).

The stand-in law: p_L = C exp(-h/LAM) on loading; from h_min, p = p_L(h_min) x^1.5,
x = 1 - (h - h_min)/delta, so k_rev/k_load = 1.5 LAM/delta = 3 at delta = LAM/2 (the
tests/memory_law.py law has delta = 1.5 LAM: k continuous, which is why it never showed this).
D(h_min) = p_L(h_min) (LAM - 2 delta/5). Units: mm, N, MPa.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rough_contact.interface.history import ReversalStiffnessProtocol
from rough_contact.interface.state import HistoryInterfaceState
from rough_contact.scenes import bolt_head, flat_punch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # tests/: the shared stand-in law
from memory_law import C, LAM, MemoryLaw  # noqa: E402

DELTA_STIFF = 0.5 * LAM          # k_rev/k_load = 3 at the reversal
COARSE = dict(cycles=5, steps_per_cycle=8, size_cylinder=1.5, size_block=2.5, low=0.1,
              pressure=10.0, case="b", progress=False)


class StiffUnloadingLaw(MemoryLaw):
    """The shared closed-form law with memory whose unloading branch starts 1.5 LAM/delta times
    stiffer than the loading branch (``HistoryNormalLawProtocol``)."""

    def __init__(self, delta=DELTA_STIFF):
        self.delta = delta


class StiffUnloadingLawWithReversal(StiffUnloadingLaw):
    """The same law, stating k_load and k_rev at h_min (``ReversalStiffnessProtocol``)."""

    def reversal_stiffness(self, h_min):
        p = C * np.exp(-np.asarray(h_min, float) / LAM)
        return p / LAM, 1.5 * p / self.delta


def _tangential_traction(normal, h, h_min, slip):
    law, _ = flat_punch.make_law(MPI.COMM_SELF, case="b", normal=normal, seating_pressure=1.0)
    n = h.size
    state = HistoryInterfaceState.zeros(n)
    state.h_min[:] = h_min
    jump = np.column_stack([h - law.h0, np.full(n, slip), np.zeros(n)])
    return law.evaluate(jump, state).traction


def test_tangential_traction_is_continuous_at_the_reversal():
    assert isinstance(StiffUnloadingLawWithReversal(), ReversalStiffnessProtocol)
    assert not isinstance(StiffUnloadingLaw(), ReversalStiffnessProtocol)
    h_min = 1.6e-3                                  # p_L = 10 MPa
    eps = 1e-12 * LAM
    h = np.array([h_min - eps, h_min + eps])
    slip = 1e-7                                     # stick: |t_T| << mu p
    t = _tangential_traction(StiffUnloadingLawWithReversal(), h, h_min, slip)
    # p and t_T continuous to O(eps k / p) = O(1e-12)
    np.testing.assert_allclose(t[1, 0], t[0, 0], rtol=1e-9)
    np.testing.assert_allclose(t[1, 1], t[0, 1], rtol=1e-9)
    assert abs(t[0, 1]) < 0.1 * abs(t[0, 0])         # in stick
    # the cause of the stall: with k_T = c k_N the tangential traction jumps by k_rev/k_load
    t_old = _tangential_traction(StiffUnloadingLaw(), h, h_min, slip)
    np.testing.assert_allclose(t_old[1, 0], t_old[0, 0], rtol=1e-9)
    np.testing.assert_allclose(t_old[1, 1] / t_old[0, 1], 1.5 * LAM / DELTA_STIFF, rtol=1e-9)
    # k_T on the unloading branch: the unloading stiffness scaled by k_load/k_rev (= 1/3 here)
    hu = np.array([h_min + 0.3 * DELTA_STIFF])
    t_new = _tangential_traction(StiffUnloadingLawWithReversal(), hu, h_min, slip)
    t_raw = _tangential_traction(StiffUnloadingLaw(), hu, h_min, slip)
    np.testing.assert_allclose(t_new[0, 1] / t_raw[0, 1], DELTA_STIFF / (1.5 * LAM), rtol=1e-12)
    np.testing.assert_allclose(t_new[0, 0], t_raw[0, 0], rtol=0, atol=0)


def test_bolt_normal_cycles_shake_down_with_a_stiffer_unloading_branch():
    """Failed before the fix with LoadStepError at the peak of cycle 5 (t = 5.4941 -> 5.5,
    DIVERGED_MAX_IT at every cutback; the peaks of cycles 2-4 took 29, 34, 45 Newton
    iterations)."""
    comm = MPI.COMM_WORLD
    r = bolt_head.run_cycles("normal", normal=StiffUnloadingLawWithReversal(), comm=comm,
                             **COARSE)
    assert len(r.cycles) == 5
    np.testing.assert_allclose(r.F_z, r.load, rtol=1e-9)
    dn = np.array([c["normal_dissipated"] for c in r.cycles])
    # every point loads on the way to the first peak: D_N = (LAM - 2 delta/5) (1 - low) P
    expected = (LAM - 0.4 * DELTA_STIFF) * (1.0 - COARSE["low"]) * r.P
    np.testing.assert_allclose(dn[0], expected, rtol=1e-9)
    assert np.all(np.abs(dn[1:]) <= 1e-12 * dn[0]), dn
    works = np.array([c["loop_energy"] for c in r.cycles])
    assert works[0] > 0.5 * dn[0] and np.all(np.abs(works[1:]) <= 1e-9 * works[0]), works
    if comm.size > 1:       # the same run on one rank (COMM_SELF: the whole mesh)
        r1 = bolt_head.run_cycles("normal", normal=StiffUnloadingLawWithReversal(),
                                  comm=MPI.COMM_SELF, **COARSE)
        for name in ("approach", "F_z", "F_x", "normal_dissipation"):
            a, b = getattr(r, name), getattr(r1, name)
            np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(b).max(),
                                       err_msg=name)
        np.testing.assert_allclose(r.dissipation, r1.dissipation, rtol=1e-10,
                                   atol=1e-10 * dn[0])


def test_tangent_on_the_unloading_branch_matches_finite_differences():
    """The scaled k_T keeps the interface tangent consistent (k_load/k_rev is fixed by the
    committed h_min): central differences of the traction in the jump, in stick and in slip."""
    law, _ = flat_punch.make_law(MPI.COMM_SELF, case="b", normal=StiffUnloadingLawWithReversal(),
                                 seating_pressure=1.0)
    h_min = 1.6e-3
    h = h_min + np.array([0.3, 0.3, 0.6, 0.1]) * DELTA_STIFF
    slip = np.array([[1e-7, 0.0], [2e-4, 1e-4], [-3e-4, 2e-4], [5e-5, -5e-5]])
    n = h.size
    state = HistoryInterfaceState.zeros(n)
    state.h_min[:] = h_min
    jump = np.column_stack([h - law.h0, slip])
    res = law.evaluate(jump, state)
    assert not res.slipping[0] and res.slipping[1:].any()
    step = 1e-10
    for j in range(3):
        dj = np.zeros((n, 3))
        dj[:, j] = step
        fd = (law.evaluate(jump + dj, state).traction
              - law.evaluate(jump - dj, state).traction) / (2 * step)
        np.testing.assert_allclose(res.tangent[:, :, j], fd, rtol=1e-5,
                                   atol=1e-5 * np.abs(res.tangent).max(), err_msg=f"column {j}")
