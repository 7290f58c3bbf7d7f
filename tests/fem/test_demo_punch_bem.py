"""The punch demo with the statistical and the BEM normal law, small size, serial and on 2 ranks.

rough_contact.scenes.punch_bem (demos/demo_punch_bem_vs_statistical.py): both laws load the punch with force balance, from the
seated state, inside both tables."""
from __future__ import annotations

from dataclasses import astuple

import numpy as np
from mpi4py import MPI

from rough_contact.scenes import punch_bem as demo


def test_punch_bem_vs_statistical_small(tmp_path, monkeypatch):
    monkeypatch.setenv("ROUGH_CONTACT_CACHE", str(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)))
    out = demo.run(small=True, backend="numpy", verbose=False)
    assert [name for name, _ in out.items()] == ["statistical", "BEM"]
    assert out.num_dofs > 0
    for _, rows in out.items():
        assert len(rows) == 2
        for r in rows:
            assert r.force_error < 1e-8
            assert r.below == 0 and r.beyond == 0          # inside both tables
            assert all(np.isfinite(v) for v in astuple(r))
        # the first increment is the seated state: the rough layer is not compressed on average
        assert abs(rows[0].closure) < 0.1 * abs(rows[1].closure)
        assert rows[1].approach > rows[0].approach > 0
        assert rows[1].dissipation >= 0
