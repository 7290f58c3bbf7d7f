"""Slip counters count only points in contact (issue 24, item 8; serial and 2 ranks).

The Mindlin scene in small (``rough_contact.scenes.mindlin``: a rigid paraboloid on a half
block, ``SoftplusPenalty`` with Coulomb friction mu = 0.3, coarse P1 mesh): the bottom is pushed
up by delta (normal load alone, no tangential load), then pulled down by delta (lift-off). The
points outside the contact move radially under the indentation; they carry no pressure (the
softplus is exactly 0 beyond 745 smoothing lengths of gap), so Coulomb's cone is the point
t_T = 0 there and they are open, not slipping. What must hold whatever the law's internals:

* no increment reports more slipping points than points in contact, and the slipping area is
  part of the contact area;
* after lift-off no point is in contact, so none slips (the report had "active 0, slip 1284");
* ``history.csv`` (``ResultWriter``) carries the same counts as the increments.
"""

from __future__ import annotations

import csv

from mpi4py import MPI

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.io import ResultWriter
from rough_contact.scenes.meshes.blocks import indented_block
from rough_contact.scenes.mindlin import ParaboloidIndenter
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver

DELTA = 4e-3          # indentation [mm]: Hertz's a = sqrt(R delta) = 0.2 mm for R = 10 mm


def test_slip_counted_only_in_contact(tmp_path_factory):
    comm = MPI.COMM_WORLD
    scene = indented_block(half_width=2.0, height=2.0, mesh_size=0.8, contact_size=0.1,
                           transition=0.8, refined_radius=0.3, order=1, half=True, comm=comm)
    V = vector_space(scene.mesh, 1)
    sym = fix(V, scene.facet_tags, scene.tag("symmetry_y"), 1)
    law = SoftplusPenalty(1e8, 1e-3 * DELTA, k_tangential=2e7, friction=0.3)
    ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), law=law,
                          rigid=ParaboloidIndenter(10.0), bcs=[sym], quadrature="vertex")
    bottom = scene.tag("bottom")
    problem = ContactProblem(
        V, Material(2e5, 0.3), [sym], facet_tags=scene.facet_tags, interface=ci,
        prescribed=[PrescribedDisplacement(bottom, (0.0, 0.0, DELTA), (2,))])
    solver = SNESSolver(problem, prefix="slipcount_")
    outdir = comm.bcast(str(tmp_path_factory.mktemp("slipcount")) if comm.rank == 0 else None)
    writer = ResultWriter(outdir, comm, interface=ci, points=False)
    incs = []
    for inc in load_path(problem, solver, [0.5, 1.0, 0.0, -1.0], verbose=False):
        writer.write(inc)
        s = ci.summary()
        assert s.slipping_area <= s.contact_area * (1.0 + 1e-12)
        incs.append(inc)
    solver.destroy()
    loaded, lifted = incs[1], incs[-1]
    assert 0 < loaded.n_active < loaded.n_points          # a contact patch, open points around
    # the open points did move tangentially (what the old count took for slip)
    for inc in incs:
        assert inc.n_slipping <= inc.n_active, (inc.load_factor, inc.n_active, inc.n_slipping)
    assert lifted.n_active == 0 and lifted.n_slipping == 0
    if comm.rank == 0:
        with open(f"{outdir}/history.csv") as f:
            rows = list(csv.DictReader(f))
        assert [int(r["n_slipping"]) for r in rows] == [i.n_slipping for i in incs]
        assert [int(r["n_active"]) for r in rows] == [i.n_active for i in incs]
