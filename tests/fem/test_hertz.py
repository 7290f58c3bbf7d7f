"""A rigid sphere indenting an elastic block against Hertz (serial and 2 ranks), and the rigid
plane given as a RigidSurface reproducing ``rigid_plane=`` exactly.

Hertz: a^3 = 3 P R / (4 E*), p0 = 3 P / (2 pi a^2), P from the reaction of the pushed bottom.
Measured convergence (benchmarks/bench_hertz.py, docs/indenters.md): P1 with the nodal rule,
contact size 0.04 mm (a / 5): a +0.9 %, p0 +2.1 %; 0.02 mm: a +1.1 %, p0 +0.04 %; P2 Gauss at 0.04:
a +0.8 %, p0 -1.3 %. The test uses the 0.04 mm P1 level with 3 % / 4 % bounds.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem
from rough_contact.fem import compat
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.rigid import RigidPlane
from rough_contact.interface.penalty import LinearPenalty
from rough_contact.scenes import hertz

from test_contact import LOWER_TOP, smooth_field, two_blocks  # noqa: E402


def test_sphere_on_block_against_hertz():
    r = hertz.run(contact_size=0.04, order=1, quadrature="vertex", penalty=1e8)
    assert abs(r.a_error) <= 0.03
    assert abs(r.p0_error) <= 0.04
    # force balance: the integrated contact pressure carries the bottom reaction
    assert r.force_from_p == pytest.approx(r.P, rel=2e-4)
    assert r.band_error["0-0.5 a"] <= 0.15


def test_rigid_plane_surface_equals_rigid_plane_argument():
    msh, tags = two_blocks(MPI.COMM_WORLD, single=True)
    V = compat.vector_space(msh, 2)
    plane = ((0.1, -0.2, 0.3), (0.2, 0.1, 1.0))
    law = LinearPenalty(1e3, 2e2)
    a = ContactInterface(V, tags, LOWER_TOP, law=law, rigid_plane=plane)
    b = ContactInterface(V, tags, LOWER_TOP, law=law, rigid=RigidPlane(*plane))
    u = fem.Function(V)
    u.interpolate(lambda x: smooth_field(x, 0.0, 1e-3))
    np.testing.assert_array_equal(a.jump(u), b.jump(u))
    np.testing.assert_array_equal(a.local_frames(), b.local_frames())
    with pytest.raises(ValueError, match="give either rigid or rigid_plane, not both"):
        ContactInterface(V, tags, LOWER_TOP, law=law, rigid_plane=plane, rigid=RigidPlane(*plane))
    with pytest.raises(TypeError, match="must implement rough_contact.fem.rigid.RigidSurface"):
        ContactInterface(V, tags, LOWER_TOP, law=law, rigid=object())


def test_elastic_sphere_on_separately_meshed_block():
    """An elastic sphere meshed independently of the block (mortar pairing), coarse P2 mesh
    (block elements a/3 at the contact): Hertz's contact radius within 2 %, peak pressure within
    4 % (the finer levels of benchmarks/bench_hertz.py --elastic converge to -0.07 % / -0.6 %),
    top and bottom reactions balance to the Newton tolerance."""
    r = hertz.run_elastic(contact_size=0.08, order=2, pairing="mortar")
    assert abs(r.a_error) < 0.02
    assert abs(r.p0_error) < 0.04
    assert r.balance < 1e-8
    # int p dA exceeds the axial force P by the tilt of the sphere's normals (cos 1.4 deg at r = a)
    assert 0.0 <= r.force_from_p / r.P - 1.0 < 1e-3
