"""The punch and beam demos' ``--law auto`` options (one block, demos/_common.py): the parsed
``--tolerance`` and ``--results`` reach ``rough_contact.advisor.advise`` through the scene's
``run`` (checked by intercepting ``advise``, no FE solve), and a bad ``--results`` is refused.
The full runs with the flag are in test_demos.py (advice.json records the results used)."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

DEMOS = Path(__file__).resolve().parents[2] / "demos"


def _demo(name):
    sys.path.insert(0, str(DEMOS))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(DEMOS))


class _Reached(Exception):
    pass


@pytest.mark.parametrize("demo, scene, extra", [
    ("demo_flat_punch", "flat_punch", {}),
    ("demo_beam_rigid_base", "beam", {"cases": [3]}),
])
def test_results_flag_reaches_advise(demo, scene, extra, monkeypatch, tmp_path):
    pytest.importorskip("dolfinx")
    from mpi4py import MPI

    import rough_contact.advisor as advisor
    mod = _demo(demo)
    scene_mod = importlib.import_module(f"rough_contact.scenes.{scene}")
    args, rest = mod.parse_args(["--law", "auto", "--tolerance", "0.02", "--results", "area",
                                 "force", "-rc_snes_rtol", "1e-9"])
    assert rest == ["-rc_snes_rtol", "1e-9"]
    opts = mod.law_auto_options(args)
    assert opts == {"tolerance": 0.02, "advise_results": ("area", "force")}
    seen = {}

    def advise(surface, material, pressure_range, tolerance, **kw):
        seen.update(tolerance=tolerance, **kw)
        raise _Reached

    monkeypatch.setattr(advisor, "advise", advise)
    # serial communicator: rank 0 raises before any collective call, whatever the rank count
    with pytest.raises(_Reached):
        scene_mod.run(law="auto", outdir=str(tmp_path), comm=MPI.COMM_SELF, **extra, **opts)
    assert seen["tolerance"] == 0.02 and tuple(seen["results"]) == ("area", "force")
    # the default: all four results (the scenes report the dissipation)
    args, _ = mod.parse_args(["--law", "auto"])
    assert mod.law_auto_options(args)["advise_results"] == advisor.RESULTS_ALL


@pytest.mark.parametrize("demo", ["demo_flat_punch", "demo_beam_rigid_base"])
def test_bad_results_flag_is_refused(demo, capsys):
    mod = _demo(demo)
    with pytest.raises(SystemExit):
        mod.parse_args(["--law", "auto", "--results", "stress"])
    err = capsys.readouterr().err
    assert "--results" in err and "'stress'" in err and "dissipation" in err
