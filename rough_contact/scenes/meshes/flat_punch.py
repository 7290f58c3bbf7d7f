"""Flat square punch on an elastic foundation, paper section 9.2 (quarter model). Units: mm.

Full problem: punch 20 x 20 x 10 mm on a foundation 100 x 100 x 50 mm, load on the punch
top. By symmetry about x = 0 and y = 0 only a quarter is meshed:

    punch       [0, a] x [0, a] x [0, hp]     (a = 10, hp = 10 by default)
    foundation  [0, L] x [0, L] x [-H, 0]     (L = 50, H = 50 by default)

The bodies are fragmented in gmsh, so the patch [0, a]^2 of the foundation top carries the
same surface mesh as the punch bottom; the punch's interface nodes are then duplicated
(``rough_contact.fem.mesh``). The mesh is refined towards the contact patch with a gmsh
Threshold field on the exact distance to the patch (a MathEval field: the distance to the
rectangle [0, a]^2 x {0} is written in closed form, which is exact and needs no sampling).
With ``edge_size`` (tetrahedra only) a second such field grades the mesh towards the punch's
free edge, the segments x = a, 0 <= y <= a and y = a, 0 <= x <= a at z = 0, where the contact
tractions are singular (docs/punch_refinement.md); the smaller of the two sizes wins.

Labels (tags in brackets):
    bodies: "punch" (1), "foundation" (2)
    "contact_punch" (11): punch bottom, FIRST contact surface (normal -z, towards the
        foundation); "contact_foundation" (12): foundation top under the punch, second.
    "load" (13): punch top (the whole quarter top, or the central square
        [0, load_half_width]^2 when given); "punch_top" (14): the rest of the punch top
        (only when load_half_width < a); "punch_sides" (15): x = a and y = a faces of the
        punch; "foundation_top" (16): free foundation top outside the patch;
    "symmetry_x" (17): x = 0 (both bodies); "symmetry_y" (18): y = 0 (both bodies);
    "fixed" (19): foundation bottom z = -H; "foundation_sides" (20): x = L and y = L.

``cell_type="hexahedron"`` builds the quarter from boxes on the grid of break lines
(0, b, a, L in x and y) and meshes them as graded transfinite hexahedra (Q1 or 27-node
Q2), close to the paper's structured hexahedral meshes.
"""

from __future__ import annotations

import typing

import numpy as np
from mpi4py import MPI

from rough_contact.fem.mesh import (Scene, add_groups, build_contact_scene, entity_centers,
                                    generate, refine_towards, set_transfinite_hexahedra,
                                    validate_cell_type, validate_order, validate_positive)

__all__ = ["flat_punch"]


def check_punch_sizes(half_width, foundation_half_width, mesh_size, contact_size) -> None:
    """Raise ValueError unless the foundation is wider than the punch and the contact size
    is at most the mesh size (both punch meshes)."""
    if not foundation_half_width > half_width:
        raise ValueError(f"foundation_half_width = {foundation_half_width} is invalid; valid "
                         f"range: > half_width = {half_width}")
    if contact_size > mesh_size:
        raise ValueError(f"contact_size = {contact_size} is invalid; valid range: "
                         f"(0, mesh_size = {mesh_size}]")


def _refinement_field(model, a, contact_size, mesh_size, transition, extra=()):
    """Threshold on the exact distance to the patch [0, a]^2 x {0}: contact_size -> mesh_size
    (``extra``: further thresholds of ``refine_towards``, the smallest size winning)."""
    dx, dy = f"(Abs(x-{a})+x-{a})/2", f"(Abs(y-{a})+y-{a})/2"
    refine_towards(model, f"Sqrt(({dx})^2+({dy})^2+z^2)", contact_size, mesh_size, transition,
                   extra=extra)


def _edge_distance(a):
    """MathEval expression of the exact distance to the punch edge: the segments x = a,
    0 <= y <= a and y = a, 0 <= x <= a at z = 0 (the quarter model has x, y >= 0)."""
    d1 = f"Sqrt((x-{a})^2+((Abs(y-{a})+y-{a})/2)^2+z^2)"   # to x = a, 0 <= y <= a
    d2 = f"Sqrt((y-{a})^2+((Abs(x-{a})+x-{a})/2)^2+z^2)"   # to y = a, 0 <= x <= a
    return f"(({d1})+({d2})-Abs(({d1})-({d2})))/2"          # min(d1, d2)


def edge_grading(contact_size: float, half_width: float, edge_size=None, edge_band=None,
                 cell_type: str = "tetrahedron", edge_growth=None) -> tuple:
    """The checked (edge_size, edge_band) of the grading towards the punch's free edge [mm]:
    (None, None) without ``edge_size``; the band defaults to ``contact_size``. Raises
    ValueError naming the quantity, its value and the valid range (0 < edge_size <=
    contact_size, 0 < edge_band <= half_width, 0 < edge_growth <= 1 or None, tetrahedra
    only). The benchmarks call it to refuse a bad option before any mesh is built."""
    if edge_size is None:
        for name, value in (("edge_band", edge_band), ("edge_growth", edge_growth)):
            if value is not None:
                raise ValueError(f"{name} = {value!r} is invalid without edge_size; valid: "
                                 "None, or give edge_size too")
        return None, None
    if edge_growth is not None and not (np.isfinite(edge_growth) and 0 < edge_growth <= 1):
        raise ValueError(f"edge_growth = {edge_growth!r} is invalid; valid range: (0, 1] mm "
                         "per mm, or None")
    if cell_type != "tetrahedron":
        raise ValueError(f"edge_size = {edge_size!r} is invalid with cell_type = "
                         f"{cell_type!r}; edge grading is for tetrahedra only (edge_size "
                         "= None for hexahedra)")
    if not (np.isfinite(edge_size) and 0 < edge_size <= contact_size):
        raise ValueError(f"edge_size = {edge_size!r} is invalid; valid range: "
                         f"(0, contact_size = {contact_size}] mm")
    edge_band = contact_size if edge_band is None else edge_band
    if not (np.isfinite(edge_band) and 0 < edge_band <= half_width):
        raise ValueError(f"edge_band = {edge_band!r} is invalid; valid range: "
                         f"(0, half_width = {half_width}] mm")
    return edge_size, edge_band


def _edge_field(a, edge_size, edge_band, contact_size, mesh_size, transition, growth=None):
    """``(distance, size, transition)`` of the edge grading for ``refine_towards(extra=)``:
    ``edge_size`` within ``edge_band`` of the edge, then growing linearly at ``growth`` mm per
    mm (a geometric progression of ratio about 1 + growth), by default at twice the patch
    field's rate, (mesh_size - contact_size) / transition per mm, so that it falls below
    the patch field only near the edge (for mesh_size = contact_size, where that rate is 0,
    the size reaches contact_size at 2 edge_band). The distance is max(d - edge_band, 0)."""
    rate = 2.0 * (mesh_size - contact_size) / transition if growth is None else growth
    if rate <= 0.0:
        rate = (contact_size - edge_size) / edge_band if contact_size > edge_size else 1.0
    d = _edge_distance(a)
    beyond = f"(Abs(({d})-{edge_band})+({d})-{edge_band})/2"
    return beyond, edge_size, (mesh_size - edge_size) / rate


def flat_punch(mesh_size: float = 10.0, contact_size: typing.Optional[float] = None,
               order: int = 1, half_width: float = 10.0, punch_height: float = 10.0,
               foundation_half_width: float = 50.0, foundation_height: float = 50.0,
               load_half_width: typing.Optional[float] = None,
               transition: typing.Optional[float] = None, cell_type: str = "tetrahedron",
               comm: MPI.Comm = MPI.COMM_WORLD, edge_size: typing.Optional[float] = None,
               edge_band: typing.Optional[float] = None,
               edge_growth: typing.Optional[float] = None) -> Scene:
    """Quarter model of the flat punch on the foundation (paper section 9.2). Collective.

    Args:
        mesh_size: element size away from the contact patch [mm].
        contact_size: element size on the contact patch [mm]; default ``mesh_size / 4``
            (capped at ``mesh_size``).
        order: 1 or 2 (P1 or P2 tetrahedra).
        half_width: a, half the punch width (quarter-model punch is a x a) [mm].
        punch_height: hp [mm].
        foundation_half_width: L, half the foundation width [mm]; must exceed a.
        foundation_height: H [mm].
        load_half_width: b, half width of a central square load patch on the punch top
            [mm], 0 < b <= a; ``None`` loads the whole top.
        transition: distance from the patch over which the size grows from
            ``contact_size`` to ``mesh_size`` [mm]; default ``2 a`` (tetrahedra only).
        cell_type: ``"tetrahedron"`` (unstructured, Threshold field) or
            ``"hexahedron"`` (structured boxes: uniform ``contact_size`` over the patch
            columns, geometric grading from ``contact_size`` to ``mesh_size`` away
            from the patch); order 2 gives 27-node hexahedra.
        comm: communicator of the mesh (gmsh runs on rank 0).
        edge_size: element size at the punch's free edge [mm], 0 < edge_size <=
            contact_size (tetrahedra only); ``None`` (default) adds no edge grading and
            leaves the mesh as without the option.
        edge_band: distance from the edge within which the size is ``edge_size`` [mm],
            0 < edge_band <= half_width; beyond it the size grows linearly at twice the
            patch field's rate until the patch field is the smaller. Default
            ``contact_size``; only with ``edge_size``.
        edge_growth: growth of the element size per mm beyond ``edge_band``, (0, 1]: the
            elements then form a geometric progression of ratio about 1 + edge_growth away
            from the edge. Default ``None``: twice the patch field's rate (see above); only
            with ``edge_size``.

    Returns:
        The scene; ``contact_pair = (contact_punch, contact_foundation)``.
    """
    a, hp, L, H = half_width, punch_height, foundation_half_width, foundation_height
    contact_size = min(mesh_size / 4, mesh_size) if contact_size is None else contact_size
    transition = 2 * a if transition is None else transition
    validate_positive(mesh_size=mesh_size, contact_size=contact_size, half_width=a,
                      punch_height=hp, foundation_half_width=L, foundation_height=H,
                      transition=transition)
    validate_order(order)
    validate_cell_type(cell_type)
    check_punch_sizes(a, L, mesh_size, contact_size)
    if load_half_width is not None and not 0 < load_half_width <= a:
        raise ValueError(f"load_half_width = {load_half_width} is invalid; valid range: "
                         f"(0, half_width = {a}] or None")
    edge_size, edge_band = edge_grading(contact_size, a, edge_size, edge_band, cell_type,
                                        edge_growth)
    b = a if load_half_width is None else load_half_width
    tol = 1e-6 * max(L, H)

    def build(model):
        occ = model.occ
        if cell_type == "hexahedron":
            # boxes on the grid of break lines, so every volume is a 6-sided box
            xb = [0.0, b, a, L] if b < a else [0.0, a, L]
            boxes = [(3, occ.addBox(x0, y0, -H, x1 - x0, y1 - y0, H))
                     for x0, x1 in zip(xb[:-1], xb[1:]) for y0, y1 in zip(xb[:-1], xb[1:])]
            boxes += [(3, occ.addBox(x0, y0, 0, x1 - x0, y1 - y0, hp))
                      for x0, x1 in zip(xb[:-1], xb[1:]) if x1 <= a
                      for y0, y1 in zip(xb[:-1], xb[1:]) if y1 <= a]
            occ.fragment(boxes[:1], boxes[1:])
        else:
            punch = occ.addBox(0, 0, 0, a, a, hp)
            foundation = occ.addBox(0, 0, -H, L, L, H)
            tools = [(3, foundation)]
            if b < a:  # imprint the load patch on the punch top
                tools.append((2, occ.addRectangle(0, 0, hp, b, b)))
            occ.fragment([(3, punch)], tools)
        occ.synchronize()
        vols, vc = entity_centers(model, 3)
        add_groups(model, 3, {"punch": (1, vols[vc[:, 2] > 0]),
                              "foundation": (2, vols[vc[:, 2] < 0])})
        tags, c = entity_centers(model, 2)
        x, y, z = c.T
        inside = (x < a - tol) & (y < a - tol)
        on_patch = (np.abs(z) < tol) & inside
        top = np.abs(z - hp) < tol
        in_load = top & (x < b + tol) & (y < b + tol)
        punch_side = (z > tol) & ((np.abs(x - a) < tol) | (np.abs(y - a) < tol))
        groups = {"contact_punch": (11, tags[on_patch]),
                  "contact_foundation": (12, tags[on_patch]),
                  "load": (13, tags[in_load])}
        if b < a:
            groups["punch_top"] = (14, tags[top & ~in_load])
        groups.update({
            "punch_sides": (15, tags[punch_side]),
            "foundation_top": (16, tags[(np.abs(z) < tol) & ~inside]),
            "symmetry_x": (17, tags[np.abs(x) < tol]),
            "symmetry_y": (18, tags[np.abs(y) < tol]),
            "fixed": (19, tags[np.abs(z + H) < tol]),
            "foundation_sides": (20, tags[(np.abs(x - L) < tol) | (np.abs(y - L) < tol)]),
        })
        add_groups(model, 2, groups)

        if cell_type == "hexahedron":
            def distance(p, axis):  # from the patch [0, a]^2 x {0}, along one axis
                return abs(p[2]) if axis == 2 else max(p[axis] - a, 0.0)

            set_transfinite_hexahedra(model, contact_size, mesh_size, distance)
        else:
            extra = (() if edge_size is None else
                     [_edge_field(a, edge_size, edge_band, contact_size, mesh_size, transition,
                                  edge_growth)])
            _refinement_field(model, a, contact_size, mesh_size, transition, extra)
        generate(model, order)

    return build_contact_scene(
        comm, "flat_punch", build, ("punch", "foundation"), ("contact_punch", "contact_foundation"),
        dimensions=dict(half_width=a, punch_height=hp, foundation_half_width=L,
                        foundation_height=H, load_half_width=b, mesh_size=mesh_size,
                        contact_size=contact_size, transition=transition,
                        **({} if edge_size is None else
                           dict(edge_size=edge_size, edge_band=edge_band)),
                        **({} if edge_growth is None else dict(edge_growth=edge_growth))))
