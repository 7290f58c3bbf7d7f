"""Plane-strain section of the flat punch, graded geometrically towards the punch's edge.

The square punch's free edge, away from its corners, sees locally a plane-strain problem: the
section y = const of a long punch. This mesh is that section, one element thick, so the 3D
contact code solves it unchanged (``u_y = 0`` on both faces makes every hexahedron a
plane-strain quadrilateral; the two layers of nodes carry the same in-plane field by symmetry).
Units: mm.

    punch       [0, a] x [0, t] x [0, hp]
    foundation  [0, L] x [0, t] x [-H, 0]     (x = 0 is a symmetry plane)

The section is meshed in the xz-plane with quadrilaterals and extruded over the thickness t
in one layer of hexahedra. Element size (the smallest of three, a gmsh MathEval field):

    edge_size + edge_growth * d_edge            d_edge: distance to the edge point (a, 0)
    contact_size + (mesh_size - contact_size) * d_patch / transition
                                                d_patch: distance to the segment [0, a] x {0}
    mesh_size

so next to the edge the element size grows linearly with the distance, i.e. the elements form
a geometric progression of ratio about 1 + edge_growth away from the edge (the grading that
resolves a singular edge at a cost logarithmic in the smallest size).

Labels (tags): bodies "punch" (1), "foundation" (2); "contact_punch" (11, first surface, the
punch bottom), "contact_foundation" (12, the foundation under it); "load" (13, punch top);
"punch_sides" (15, x = a); "foundation_top" (16); "symmetry_x" (17, x = 0, both bodies);
"plane" (18, y = 0 and y = t, both bodies); "fixed" (19, z = -H); "foundation_sides"
(20, x = L).
"""

from __future__ import annotations

import typing

import numpy as np
from mpi4py import MPI

from rough_contact.fem.mesh import (Scene, add_groups, build_contact_scene, validate_order,
                                    validate_positive)
from rough_contact.scenes.meshes.flat_punch import check_punch_sizes

__all__ = ["punch_section"]


def punch_section(mesh_size: float = 10.0, contact_size: float = 0.7,
                  edge_size: float = 0.01, edge_growth: float = 0.2, half_width: float = 10.0,
                  punch_height: float = 10.0, foundation_half_width: float = 50.0,
                  foundation_height: float = 50.0, thickness: float = 1.0,
                  transition: typing.Optional[float] = None, order: int = 1,
                  comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Plane-strain section of the punch on the foundation, one hexahedron thick. Collective.

    Args:
        mesh_size: element size away from the contact patch [mm].
        contact_size: element size on the contact patch away from the edge [mm],
            <= mesh_size.
        edge_size: element size at the punch's edge (x = a, z = 0) [mm], <= contact_size.
        edge_growth: growth of the element size per unit distance from the edge, in
            (0, 1]: the ratio of neighbouring elements is about 1 + edge_growth.
        half_width: a [mm]; punch_height: hp [mm]; foundation_half_width: L > a [mm];
        foundation_height: H [mm].
        thickness: t, the section's thickness (one element) [mm].
        transition: distance from the patch over which the size grows from contact_size to
            mesh_size [mm]; default 2 a.
        order: 1 or 2 (Q1 or 27-node Q2 hexahedra).
        comm: communicator of the mesh (gmsh runs on rank 0).

    Returns:
        The scene; ``contact_pair = (contact_punch, contact_foundation)``.
    """
    a, hp, L, H, t = half_width, punch_height, foundation_half_width, foundation_height, thickness
    transition = 2 * a if transition is None else transition
    validate_positive(mesh_size=mesh_size, contact_size=contact_size, edge_size=edge_size,
                      edge_growth=edge_growth, half_width=a, punch_height=hp,
                      foundation_half_width=L, foundation_height=H, thickness=t,
                      transition=transition)
    validate_order(order)
    check_punch_sizes(a, L, mesh_size, contact_size)
    if edge_size > contact_size:
        raise ValueError(f"edge_size = {edge_size} is invalid; valid range: "
                         f"(0, contact_size = {contact_size}]")
    if edge_growth > 1.0:
        raise ValueError(f"edge_growth = {edge_growth} is invalid; valid range: (0, 1]")
    tol = 1e-6 * max(L, H)

    def make(model, algorithm, recombination):
        """Geometry, groups, size field and mesh of one attempt; whether it is all
        hexahedra (and quadrilaterals on every surface)."""
        import gmsh

        # gmsh's default tolerance (relative to the model's size, 100 mm) merges the 1D mesh
        # nodes of sub-micrometre edge elements and leaves triangles on the extruded sides
        gmsh.option.setNumber("Geometry.Tolerance", 1e-14)
        geo = model.geo
        pts = {k: geo.addPoint(x, 0.0, z) for k, (x, z) in dict(
            A=(0, -H), B=(L, -H), C=(L, 0), D=(a, 0), O=(0, 0), E=(a, hp), F=(0, hp)).items()}

        def line(p, q):
            return geo.addLine(pts[p], pts[q])

        ab, bc, cd, do, oa = line("A", "B"), line("B", "C"), line("C", "D"), line("D", "O"), \
            line("O", "A")
        de, ef, fo = line("D", "E"), line("E", "F"), line("F", "O")
        foundation = geo.addPlaneSurface([geo.addCurveLoop([ab, bc, cd, do, oa])])
        punch = geo.addPlaneSurface([geo.addCurveLoop([-do, de, ef, fo])])
        for s in (foundation, punch):
            geo.mesh.setRecombine(2, s)
        geo.extrude([(2, foundation), (2, punch)], 0.0, t, 0.0, numElements=[1], recombine=True)
        geo.synchronize()

        def centers(dim):
            ents = [tag for _, tag in model.getEntities(dim)]
            box = np.array([model.getBoundingBox(dim, e) for e in ents]).reshape(-1, 6)
            return np.array(ents), 0.5 * (box[:, :3] + box[:, 3:])

        vols, vc = centers(3)
        add_groups(model, 3, {"punch": (1, vols[vc[:, 2] > 0]),
                              "foundation": (2, vols[vc[:, 2] < 0])})
        tags, c = centers(2)
        x, y, z = c.T
        on_patch = (np.abs(z) < tol) & (x < a - tol) & (np.abs(y - t / 2) < tol)
        add_groups(model, 2, {
            "contact_punch": (11, tags[on_patch]), "contact_foundation": (12, tags[on_patch]),
            "load": (13, tags[np.abs(z - hp) < tol]),
            "punch_sides": (15, tags[(np.abs(x - a) < tol) & (z > tol)]),
            "foundation_top": (16, tags[(np.abs(z) < tol) & (x > a + tol)]),
            "symmetry_x": (17, tags[np.abs(x) < tol]),
            "plane": (18, tags[(np.abs(y) < tol) | (np.abs(y - t) < tol)]),
            "fixed": (19, tags[np.abs(z + H) < tol]),
            "foundation_sides": (20, tags[np.abs(x - L) < tol])})

        d_edge = f"Sqrt((x-{a})^2+z^2)"
        d_patch = f"Sqrt(((Abs(x-{a})+x-{a})/2)^2+z^2)"
        rate = (mesh_size - contact_size) / transition
        size = (f"Min({edge_size}+{edge_growth}*{d_edge},"
                f"Min({contact_size}+{rate}*{d_patch},{mesh_size}))")
        field = model.mesh.field
        f = field.add("MathEval")
        field.setString(f, "F", size)
        field.setAsBackgroundMesh(f)
        for name, value in (("MeshSizeExtendFromBoundary", 0), ("MeshSizeFromPoints", 0),
                            ("MeshSizeFromCurvature", 0), ("MeshSizeMax", mesh_size)):
            gmsh.option.setNumber(f"Mesh.{name}", value)
        gmsh.option.setNumber("Mesh.Algorithm", algorithm)
        gmsh.option.setNumber("Mesh.RecombinationAlgorithm", recombination)
        model.mesh.generate(3)
        return (sorted(int(e) for e in model.mesh.getElementTypes(3)) == [5]
                and all(list(model.mesh.getElementTypes(2, tag)) == [3]
                        for _, tag in model.getEntities(2)))

    def build(model):
        import gmsh

        # gmsh's quadrilateral recombination can leave a triangle (a prism once extruded),
        # and a cleared extruded mesh keeps stale triangles: each attempt is a fresh model,
        # with the 2D algorithm Frontal-Delaunay or Delaunay and Blossom full-quad or Blossom
        # (gmsh 4.8's Frontal-Delaunay for quads, algorithm 8, crashed on this geometry)
        attempts = ((6, 3), (5, 3), (6, 1), (5, 1), (1, 3))
        for i, (algorithm, recombination) in enumerate(attempts):
            if i:
                gmsh.model.remove()
                gmsh.model.add("punch_section")
            if make(model, algorithm, recombination):
                break
        else:
            raise RuntimeError("punch_section: gmsh left elements other than hexahedra "
                               f"(triangles in the recombination) with every (2D algorithm, "
                               f"recombination algorithm) tried: {attempts}")
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
            model.mesh.setOrder(2)

    return build_contact_scene(
        comm, "punch_section", build, ("punch", "foundation"),
        ("contact_punch", "contact_foundation"),
        dimensions=dict(half_width=a, punch_height=hp, foundation_half_width=L,
                        foundation_height=H, thickness=t, mesh_size=mesh_size,
                        contact_size=contact_size, edge_size=edge_size,
                        edge_growth=edge_growth, transition=transition))
