"""The Mindlin scene's front estimate (``MindlinRun.stick_front``, ``rough_contact.stick_front``)
on a tiny exact-stick run: contact elements a/2, P2, dual vertex weights, multipliers inside
Newton, one shear increment to partial slip and one to gross slip (about 10 s).

The gathered points near the contact are the same arrays on every rank, in coordinate order,
each vertex once; they hold the whole contact (their contact area is the scene's, summed over
all points of all ranks); ``stick_front`` is the estimator applied to them. The estimator
itself is verified in tests/unit/test_stick_front.py; docs/mindlin_dual.md has the
measurements. Serial and ``mpirun -n 2``.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.scenes import mindlin
from rough_contact.stick_front import contact_front, stick_front


@pytest.fixture(scope="module")
def run():
    return mindlin.run(contact_size=0.1, shear_steps=2, points="nodal", basis="dual",
                       enforcement=NewtonAugmentedLagrangian(1e-4, 60), k_tangential=7.5e6)


def test_gathered_points_do_not_depend_on_the_partition(run):
    pts = run.points
    comm = MPI.COMM_WORLD
    for a in (pts.x, pts.weight, pts.pressure, pts.shear, pts.contact, pts.slipping):
        copies = comm.allgather(a)
        assert all(np.array_equal(copies[0], b) for b in copies)
    key = np.round(pts.x / np.abs(pts.x).max(), 9)
    assert np.array_equal(np.lexsort((key[:, 2], key[:, 1], key[:, 0])), np.arange(len(key)))
    x = pts.x
    assert np.unique(x, axis=0).shape[0] == x.shape[0]
    # the gather radius holds the whole contact: twice the half model's contact area
    area = 2.0 * np.array([pts.weight[c].sum() for c in pts.contact])
    np.testing.assert_allclose(area, run.contact_area, rtol=1e-12)


def test_stick_front_is_the_estimator_on_the_gathered_points(run):
    pts = run.points
    r = pts.r
    for i in range(run.t.size):
        on, sl = pts.contact[i], pts.slipping[i]
        t = np.linalg.norm(pts.shear[i], axis=1)
        a = contact_front(r, pts.pressure[i], pts.weight, on).radius
        c = stick_front(r, pts.pressure[i], t, run.mu, pts.weight, on & ~sl, sl).radius
        np.testing.assert_equal([run.contact_radius[i], run.stick_radius[i]], [a, c])
        np.testing.assert_allclose(run.stick_front[i], c / a, rtol=1e-15)
    # gross slip at the end: no stuck point, c = 0; partial slip before it
    assert run.stick_front[-1] == 0.0 and not (pts.contact[-1] & ~pts.slipping[-1]).any()
    assert 0.0 < run.stick_front[-2] < 1.0
