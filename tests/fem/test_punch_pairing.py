"""``flat_punch.build(pairing=)`` (issue 24, item 15; serial and 2 ranks).

The quarter punch meshed as one conforming model pairs conformingly. A punch meshed separately
from its foundation (two gmsh volumes not fragmented: the punch bottom's surface mesh differs
from the foundation top's) used to fall back silently to the Gauss-point projection, which fails
the patch test on such meshes (docs/nonmatching.md); ``pairing="auto"`` (the default) now takes
the mortar there, and with the vertex rule (which the mortar cannot use) refuses with a message
naming the choices. The mortar run carries the applied load through the interface.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import vector_space
from rough_contact.fem.mesh import add_groups, build_contact_scene, entity_centers, generate
from rough_contact.scenes import flat_punch
from rough_contact.solver.loading import load_path

A, HP, L, H = 10.0, 10.0, 30.0, 20.0      # punch half width and height, foundation [mm]


def _separate_punch(comm, order=1):
    """The quarter punch on its foundation as two volumes meshed independently (element sizes
    3 and 5 mm on the contact: non-matching), the labels of ``flat_punch.quarter_punch``."""
    def build(model):
        import gmsh

        punch = model.occ.addBox(0, 0, 0, A, A, HP)
        foundation = model.occ.addBox(0, 0, -H, L, L, H)
        model.occ.synchronize()                 # no fragment: two surface meshes on z = 0
        add_groups(model, 3, {"punch": (1, [punch]), "foundation": (2, [foundation])})
        faces = {v: [t for _, t in model.getBoundary([(3, v)], oriented=False)]
                 for v in (punch, foundation)}
        tags, c = entity_centers(model, 2)
        x, y, z = c.T
        tol = 1e-6 * L

        def pick(vol, mask):
            return [t for t in faces[vol] if t in set(tags[mask].tolist())]

        add_groups(model, 2, {
            "contact_punch": (11, pick(punch, np.abs(z) < tol)),
            "contact_foundation": (12, pick(foundation, np.abs(z) < tol)),
            "load": (13, pick(punch, np.abs(z - HP) < tol)),
            "symmetry_x": (17, tags[np.abs(x) < tol]),
            "symmetry_y": (18, tags[np.abs(y) < tol]),
            "fixed": (19, tags[np.abs(z + H) < tol])})
        model.mesh.setSize(model.getBoundary([(3, punch)], recursive=True), 3.0)
        model.mesh.setSize(model.getBoundary([(3, foundation)], recursive=True), 5.0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 10.0)
        generate(model, order)

    scene = build_contact_scene(comm, "separate_punch", build, ("punch", "foundation"),
                                ("contact_punch", "contact_foundation"),
                                dimensions=dict(half_width=A))
    V = vector_space(scene.mesh, order)
    ft = scene.facet_tags
    bcs = [fix(V, ft, scene.tag("symmetry_x"), 0), fix(V, ft, scene.tag("symmetry_y"), 1),
           fix(V, ft, scene.tag("fixed"))]
    return flat_punch.PunchScene(scene, V, bcs)


def test_nonmatching_punch_pairs_by_mortar():
    ps = _separate_punch(MPI.COMM_WORLD)
    m = flat_punch.build(punch_scene=ps, law="penalty", steps=2, prefix="pp_")
    assert m.interface.pairing_used == "mortar"
    incs = list(load_path(m.problem, m.solver, [0.5, 1.0], verbose=False))
    fz = incs[-1].contact_force[2]
    assert abs(fz + incs[-1].applied_force[2]) <= 1e-8 * abs(incs[-1].applied_force[2])
    m.solver.destroy()
    # what the projection would have been is still there when asked for
    m = flat_punch.build(punch_scene=ps, law="penalty", steps=2, prefix="pp_",
                         pairing="projection")
    assert m.interface.pairing_used == "projection"
    m.solver.destroy()


def test_nonmatching_punch_with_vertex_rule_refuses():
    ps = _separate_punch(MPI.COMM_WORLD)
    with pytest.raises(ValueError, match=r"do not match facet to facet; choose a non-matching "
                       r"pairing: pairing='mortar' .* or pairing='projection'"):
        flat_punch.build(punch_scene=ps, law="penalty", steps=2, quadrature="vertex")


def test_conforming_punch_pairs_conformingly():
    ps = flat_punch.quarter_punch(MPI.COMM_WORLD, mesh_size=20.0, contact_size=5.0, order=1)
    for quadrature in ("gauss", "vertex"):
        m = flat_punch.build(punch_scene=ps, law="penalty", steps=2, quadrature=quadrature)
        assert m.interface.pairing_used == "conforming"
        m.solver.destroy()
