"""Cattaneo–Mindlin's normal load with exact stick (nu = 0.49, P2, dual vertex weights,
multipliers inside Newton): with ``first_contact="closure"`` no vertex in contact slips at any
increment of the normal load; with the default (a closing vertex sticks where it was at the
increment's start) the coarse scene already has slipping vertices at the contact's edge.

The continuum has none (Spence's slip annulus is about 1e-21 a wide here, docs/mindlin_dual.md),
so every slipping vertex is a discretisation error; the finer meshes of the benchmark
(benchmarks/bench_mindlin.py --first-contact closure) are measured in docs/mindlin_dual.md,
session 20. Serial and ``mpirun -n 2`` (about 20 s per run).
"""

from __future__ import annotations

import numpy as np
import pytest

from rough_contact.interface.enforcement import NewtonAugmentedLagrangian
from rough_contact.references import hertz_force
from rough_contact.scenes import mindlin


def _normal_load(first_contact):
    h = 0.025                                     # a / 8 at the contact
    return mindlin.run(contact_size=h, refined_radius=0.26, shear_steps=4, points="nodal",
                       basis="dual",
                       enforcement=NewtonAugmentedLagrangian(1e-4, 60),
                       k_tangential=mindlin.KT_SCALE * 2e5 / h, width_ratio=1e-4,
                       preload_steps=2, stop_after=2, first_contact=first_contact)


def _slipping(r):
    """Per normal-load increment: (vertices in contact that slip, vertices in contact)."""
    pts = r.points
    return [(int((pts.slipping[i] & pts.contact[i]).sum()), int(pts.contact[i].sum()))
            for i in range(r.t.size)]


@pytest.fixture(scope="module")
def runs():
    return {fc: _normal_load(fc) for fc in ("increment_start", "closure")}


def test_no_vertex_in_contact_slips_under_the_normal_load(runs):
    r = runs["closure"]
    counts = _slipping(r)
    assert len(counts) == 2 and all(c > 20 for _, c in counts)
    assert [s for s, _ in counts] == [0, 0]
    # the force is the default's: only the tangential history differs
    P0 = runs["increment_start"].P
    np.testing.assert_allclose(r.P, P0, rtol=1e-3)
    assert abs(r.P[-1] / hertz_force(4e-3, 10.0, 2e5 / (1 - 0.49**2)) - 1) < 0.08


def test_the_default_leaves_edge_vertices_slipping(runs):
    """The control: the same scene with the closing vertices held where they were at the
    increment's start has slipping vertices at the end of the normal load, at the edge."""
    r = runs["increment_start"]
    slipping, _ = _slipping(r)[-1]
    assert slipping >= 1
    last = r.points.slipping[-1] & r.points.contact[-1]
    assert r.points.r[last].min() > 0.9 * r.a
