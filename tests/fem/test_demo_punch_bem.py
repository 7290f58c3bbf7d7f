"""The punch demo with the statistical and the BEM normal law, small size, serial and on 2 ranks.

rough_contact.scenes.punch_bem (demos/demo_punch_bem_vs_statistical.py): both laws load the punch with force balance, from the
seated state, inside both tables."""
from __future__ import annotations

from dataclasses import astuple

import numpy as np
import pytest
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


def test_punch_takes_the_tangential_stiffness_from_the_bem(tmp_path, monkeypatch):
    """Issue 24, item 22: ``kt="bem"`` hands the BEM's stick ratios kT/kN to the interface law
    (before: always the friction case's 0.7). Independent check: on the isotropic surface they
    equal Mindlin's circular-contact ratio 2(1 - nu)/(2 - nu) within the BEM's discretisation
    error at this coarse grid (3 px per shortest wavelength; 0.05 % for one Hertz contact at
    5 px radius, tests/unit/test_bem.py::test_hertz_and_mindlin)."""
    from rough_contact.micro.bem import mindlin_ratio
    from rough_contact.scenes import flat_punch

    monkeypatch.setenv("ROUGH_CONTACT_CACHE", str(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)))
    out = demo.run(surface="isotropic", small=True, backend="numpy", verbose=False, kt="bem")
    assert out.kt_source == "bem"
    c = np.asarray(out.kt_over_kn)
    assert np.all(np.abs(c / mindlin_ratio(flat_punch.NU) - 1) < 0.03)
    assert not np.allclose(c, flat_punch.FRICTION_CASES["b"]["kt"], rtol=0.05)
    for _, rows in out.items():
        assert all(r.force_error < 1e-8 for r in rows) and rows[1].dissipation >= 0
    # the interface law the punch builds carries these ratios
    laws, _ = demo.build_laws(MPI.COMM_WORLD, "isotropic", 2, 3.0, True, "numpy")
    law, _ = flat_punch.make_law(MPI.COMM_WORLD, case="b", seating_pressure=1.0,
                                 normal=laws["BEM"], kt_over_kn=out.kt_over_kn)
    assert law.tangential.kt_over_kn == pytest.approx(tuple(c))
