"""Worker for tests/demos/test_multiprocess.py (run under mpirun): the Mindlin scene on P2 of
tests/fem/test_mindlin_restart.py (nodal dual points, exact stick), uninterrupted ("full"),
stopped after N increments with its checkpoint written into DIR ("stopped"), or continued from
DIR ("resume"). Writes the run's rows and gathered point tractions as JSON (rank 0).
Usage: mindlin_worker.py MODE DIR OUT.json [N]"""

import json
import sys
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).parents[1] / "fem"))
from test_mindlin_restart import _run  # noqa: E402  (the restart test's scene and enforcement)

ROWS = ("t", "slide", "P", "Q", "dissipation", "stick", "contact_area", "newton")


def main(mode, directory, out, stop_after=None):
    kwargs = {"full": {}, "stopped": dict(checkpoint=directory, stop_after=int(stop_after or 3)),
              "resume": dict(checkpoint=directory, restart=directory)}[mode]
    run = _run(**kwargs)
    if MPI.COMM_WORLD.rank == 0:
        result = {key: [float(v) for v in getattr(run, key)] for key in ROWS}
        result.update(x=run.points.x.tolist(), pressure=run.points.pressure.tolist(),
                      shear=run.points.shear.tolist(),
                      slipping=run.points.slipping.astype(bool).tolist())
        with open(out, "w") as f:
            json.dump(result, f)


if __name__ == "__main__":
    main(*sys.argv[1:])
