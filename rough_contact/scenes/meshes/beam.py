"""Prismatic beam on a rigid base, paper section 9.1 (half model). Units: mm.

The beam, 10 mm x 120 mm in cross-section and 500 mm long, stands on one of its narrow
faces (10 mm wide, 500 mm long) on a flat rigid base; the load is applied at mid-length on
the top face. By symmetry about the mid-length plane y = 0 only half is meshed:

    beam  [-w/2, w/2] x [0, l/2] x [0, hb]     (w = 10, l = 500, hb = 120 by default)

Only the beam is meshed: the base is the rigid half-space z <= 0
(``rigid_plane = ((0, 0, 0), (0, 0, 1))``, ``contact_pair = (contact_beam, None)``).
The paper applies the load "at the prism mid-length" without giving the loaded area;
here it acts on a strip of the top face, |y| <= load_half_length (full width), so that
the half model carries half of the total load on [0, load_half_length]. The mesh is
refined towards the contact face with a gmsh Threshold field on the distance z.

Labels (tags in brackets):
    body: "beam" (1)
    "contact_beam" (11): bottom face z = 0, the contact surface (normal -z);
    "load" (13): top strip y <= load_half_length; "top" (14): the rest of the top;
    "sides" (15): x = -w/2 and x = +w/2; "symmetry_y" (18): mid-length plane y = 0;
    "end" (19): free end y = l/2.

``cell_type="hexahedron"`` meshes two boxes (under and beyond the load strip) with
structured hexahedra (Q1 or 27-node Q2), graded in height.
"""

from __future__ import annotations

import typing

import numpy as np
from mpi4py import MPI

from rough_contact.fem.mesh import (Scene, add_groups, build_scene, entity_centers,
                                    generate, refine_towards, set_transfinite_hexahedra,
                                    validate_cell_type, validate_order, validate_positive)

__all__ = ["beam_on_base"]


def beam_on_base(mesh_size: float = 20.0, contact_size: typing.Optional[float] = None,
                 order: int = 1, width: float = 10.0, height: float = 120.0,
                 length: float = 500.0, load_half_length: float = 5.0,
                 transition: typing.Optional[float] = None, cell_type: str = "tetrahedron",
                 comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Half model of the beam on the rigid base (paper section 9.1). Collective.

    Args:
        mesh_size: element size away from the contact face [mm].
        contact_size: element size on the contact face [mm]; default ``width / 2``
            (capped at ``mesh_size``).
        order: 1 or 2 (P1 or P2 tetrahedra).
        width: w, beam width = width of the contact face [mm].
        height: hb, beam height [mm].
        length: l, full beam length (the half model is l/2 long) [mm].
        load_half_length: half length of the loaded strip on the top [mm], in (0, l/2).
        transition: height over which the size grows from ``contact_size`` to
            ``mesh_size`` [mm]; default ``height / 2`` (tetrahedra only).
        cell_type: ``"tetrahedron"`` (unstructured, Threshold field) or
            ``"hexahedron"`` (structured: ``contact_size`` along the width and the length,
            graded from ``contact_size`` at the base to ``mesh_size`` in height);
            order 2 gives 27-node hexahedra.
        comm: communicator of the mesh (gmsh runs on rank 0).

    Returns:
        The scene; ``contact_pair = (contact_beam, None)``, rigid half-space z <= 0.
    """
    contact_size = min(width / 2, mesh_size) if contact_size is None else contact_size
    transition = height / 2 if transition is None else transition
    validate_positive(mesh_size=mesh_size, contact_size=contact_size, width=width,
                      height=height, length=length, load_half_length=load_half_length,
                      transition=transition)
    validate_order(order)
    validate_cell_type(cell_type)
    if contact_size > mesh_size:
        raise ValueError(f"contact_size = {contact_size} is invalid; valid range: "
                         f"(0, mesh_size = {mesh_size}]")
    if not load_half_length < length / 2:
        raise ValueError(f"load_half_length = {load_half_length} is invalid; valid range: "
                         f"(0, length / 2 = {length / 2})")
    w, hb, half = width, height, length / 2
    tol = 1e-6 * max(length, height)

    def build(model):
        occ = model.occ
        if cell_type == "hexahedron":  # two boxes, split under the load strip edge
            c = load_half_length
            occ.fragment([(3, occ.addBox(-w / 2, 0, 0, w, c, hb))],
                         [(3, occ.addBox(-w / 2, c, 0, w, half - c, hb))])
        else:
            beam = occ.addBox(-w / 2, 0, 0, w, half, hb)
            strip = occ.addRectangle(-w / 2, 0, hb, w, load_half_length)
            occ.fragment([(3, beam)], [(2, strip)])
        occ.synchronize()
        vols, _ = entity_centers(model, 3)
        add_groups(model, 3, {"beam": (1, vols)})
        tags, c = entity_centers(model, 2)
        x, y, z = c.T
        top = np.abs(z - hb) < tol
        in_load = top & (y < load_half_length + tol)
        add_groups(model, 2, {
            "contact_beam": (11, tags[np.abs(z) < tol]),
            "load": (13, tags[in_load]),
            "top": (14, tags[top & ~in_load]),
            "sides": (15, tags[np.abs(np.abs(x) - w / 2) < tol]),
            "symmetry_y": (18, tags[np.abs(y) < tol]),
            "end": (19, tags[np.abs(y - half) < tol]),
        })
        if cell_type == "hexahedron":
            set_transfinite_hexahedra(model, contact_size, mesh_size,
                                      lambda p, axis: abs(p[2]) if axis == 2 else 0.0)
        else:
            refine_towards(model, "Abs(z)", contact_size, mesh_size, transition)
        generate(model, order)

    return build_scene(
        comm, "beam_on_base", build, split_body="beam", contact_pair=("contact_beam", None),
        rigid_plane=(np.zeros(3), np.array([0.0, 0.0, 1.0])),
        dimensions=dict(width=w, height=hb, length=length, half_length=half,
                        load_half_length=load_half_length, mesh_size=mesh_size,
                        contact_size=contact_size, transition=transition))
