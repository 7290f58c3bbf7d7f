"""Patch-test scenes: two stacked blocks, or one block on a rigid plane. Units: mm.

``two_blocks``: lower block [0, lx] x [0, ly] x [-h1, 0], upper block
[0, lx] x [0, ly] x [0, h2], in contact at z = 0 on a conforming interface (the upper
block's nodes on z = 0 are duplicated, see ``rough_contact.fem.mesh``).

Labels (tags in brackets):
    bodies: "upper" (1), "lower" (2)
    surfaces: "contact_upper" (11, first contact surface, upper block bottom),
    "contact_lower" (12, second, lower block top), "top" (13, z = h2),
    "bottom" (14, z = -h1), "x0" (15), "x1" (16), "y0" (17), "y1" (18); the side groups
    hold the sides of both blocks.

``separate_blocks``: the same two blocks meshed independently (the common face is not
fragmented: each block has its own surface mesh on z = 0, with its own element size), the case
of parts meshed separately; same labels as ``two_blocks``.

``sphere_on_block``: a quarter of an elastic sphere segment (radius R, height ``cap_height``)
touching a quarter block at the origin, the two meshed independently with different element
sizes (non-matching); labels "sphere" (1), "block" (2), "sphere_contact" (11: the sphere's
surface within ``contact_radius`` of the axis), "block_contact" (12: the block's top),
"sphere_top" (13), "bottom" (14), "symmetry_x" (17), "symmetry_y" (18).

``cylinder_on_block``: a cylinder (a bolt head, a pin) standing on a block, the two meshed
independently (the cylinder finer); labels "cylinder" (1), "block" (2), "cylinder_contact" (11:
its base, the first contact surface), "block_contact" (12: the block's top), "cylinder_top"
(13), "bottom" (14).

``block_on_plane``: one block [0, lx] x [0, ly] x [0, h] on the rigid plane z = 0
(``contact_pair = (contact, None)``, ``rigid_plane = ((0, 0, 0), (0, 0, 1))``).
Labels: "block" (1), "contact" (11, z = 0), "top" (13), "x0".."y1" (15-18).
"""

from __future__ import annotations

import typing

import numpy as np
from mpi4py import MPI

from rough_contact.fem.mesh import (Scene, add_groups, build_contact_scene, build_scene,
                                    entity_centers, generate, refine_towards,
                                    set_transfinite_hexahedra, validate_cell_type,
                                    validate_order, validate_positive)

__all__ = ["two_blocks", "separate_blocks", "block_on_plane", "indented_block",
           "sphere_on_block", "cylinder_on_block", "slider_on_slab"]


def _side_groups(model, lx, ly, tol):
    tags, c = entity_centers(model, 2)
    return {"x0": (15, tags[np.abs(c[:, 0]) < tol]),
            "x1": (16, tags[np.abs(c[:, 0] - lx) < tol]),
            "y0": (17, tags[np.abs(c[:, 1]) < tol]),
            "y1": (18, tags[np.abs(c[:, 1] - ly) < tol])}


def _stacked_boxes(model, lx, ly, h1, h2):
    """OCC boxes (lower, upper): [0, lx] x [0, ly] x [-h1, 0] and [0, lx] x [0, ly] x [0, h2]."""
    return model.occ.addBox(0, 0, -h1, lx, ly, h1), model.occ.addBox(0, 0, 0, lx, ly, h2)


def _mesh(model, mesh_size, order, cell_type):
    import gmsh

    if cell_type == "hexahedron":
        # structured: each box edge gets ceil(length / mesh_size) elements
        set_transfinite_hexahedra(model, mesh_size, mesh_size)
    else:
        gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.1 * mesh_size)
    generate(model, order)


def _size_boxes(model, faces: dict, sizes, cell_type: str) -> None:
    """Each box meshed with its own element size: structured hexahedra per box, or tetrahedra
    with the box's size on its boundary. ``sizes``: ((volume tag, size), ...)."""
    if cell_type == "hexahedron":
        _separate_hexahedra(model, faces, sizes)
        return
    import gmsh

    for vol, size in sizes:
        model.mesh.setSize(model.getBoundary([(3, vol)], recursive=True), size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", max(size for _, size in sizes))


def _separate_hexahedra(model, faces: dict, sizes) -> None:
    """Structured hexahedra on boxes meshed independently: ``sizes = ((volume, size), ...)``,
    every curve of a volume's faces (``faces[volume]``) split into ``ceil(length / size)``
    elements, then every surface and volume transfinite (recombined surfaces)."""
    for vol, size in sizes:
        edges = model.getBoundary([(2, f) for f in faces[vol]], combined=False, oriented=False)
        for curve in sorted({abs(t) for _, t in edges}):
            a, b = model.getBoundary([(1, curve)], combined=False, oriented=False)
            length = np.linalg.norm(np.subtract(model.getValue(0, a[1], []),
                                                model.getValue(0, b[1], [])))
            model.mesh.setTransfiniteCurve(curve, 1 + max(1, int(np.ceil(length / size - 1e-9))))
    for dim, surface in model.getEntities(2):
        model.mesh.setTransfiniteSurface(surface)
        model.mesh.setRecombine(dim, surface)
    for _, volume in model.getEntities(3):
        model.mesh.setTransfiniteVolume(volume)


def two_blocks(lx: float = 1.0, ly: float = 1.0, h1: float = 1.0, h2: float = 1.0,
               mesh_size: float = 0.25, order: int = 1, cell_type: str = "tetrahedron",
               comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Two stacked boxes touching on z = 0, conforming interface. Collective.

    Args:
        lx, ly: plan size of both blocks [mm].
        h1, h2: heights of the lower and upper block [mm].
        mesh_size: largest tetrahedron edge, or hexahedron edge target [mm].
        order: 1 or 2 (P1/P2 tetrahedra, Q1/Q2 27-node hexahedra).
        cell_type: ``"tetrahedron"`` (unstructured) or ``"hexahedron"`` (structured,
            each box edge split into ``ceil(length / mesh_size)`` elements).
        comm: communicator of the mesh (gmsh runs on rank 0).

    Returns:
        The scene; ``contact_pair = (contact_upper, contact_lower)``.
    """
    validate_positive(lx=lx, ly=ly, h1=h1, h2=h2, mesh_size=mesh_size)
    validate_order(order)
    validate_cell_type(cell_type)
    tol = 1e-6 * max(lx, ly, h1, h2)
    def build(model):
        lower, upper = _stacked_boxes(model, lx, ly, h1, h2)
        model.occ.fragment([(3, lower)], [(3, upper)])
        model.occ.synchronize()
        vols, vc = entity_centers(model, 3)
        add_groups(model, 3, {"upper": (1, vols[vc[:, 2] > 0]),
                              "lower": (2, vols[vc[:, 2] < 0])})
        tags, c = entity_centers(model, 2)
        z = c[:, 2]
        add_groups(model, 2, {"contact_upper": (11, tags[np.abs(z) < tol]),
                              "contact_lower": (12, tags[np.abs(z) < tol]),
                              "top": (13, tags[np.abs(z - h2) < tol]),
                              "bottom": (14, tags[np.abs(z + h1) < tol]),
                              **_side_groups(model, lx, ly, tol)})
        _mesh(model, mesh_size, order, cell_type)

    return build_contact_scene(
        comm, "two_blocks", build, ("upper", "lower"), ("contact_upper", "contact_lower"),
        dimensions=dict(lx=lx, ly=ly, h1=h1, h2=h2, mesh_size=mesh_size))


def separate_blocks(lx: float = 1.0, ly: float = 1.0, h1: float = 1.0, h2: float = 1.0,
                    size_lower: float = 0.25, size_upper: float = 0.35, order: int = 1,
                    cell_type: str = "tetrahedron",
                    comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Two stacked boxes meshed independently: non-matching surface meshes on z = 0.
    Collective.

    Args:
        lx, ly: plan size of both blocks [mm].
        h1, h2: heights of the lower and upper block [mm].
        size_lower, size_upper: element size in each block [mm] (tetrahedra: target size;
            hexahedra: each box edge split into ``ceil(length / size)`` elements, so that
            e.g. sizes 1/3 and 1/9 give nested faces and 1/5 and 1/7 non-nested ones).
        order: 1 or 2 (P1/P2 tetrahedra, Q1/Q2 27-node hexahedra).
        cell_type: ``"tetrahedron"`` or ``"hexahedron"``.
        comm: communicator of the mesh (gmsh runs on rank 0).

    Returns:
        The scene; ``contact_pair = (contact_upper, contact_lower)``.
    """
    validate_positive(lx=lx, ly=ly, h1=h1, h2=h2, size_lower=size_lower,
                      size_upper=size_upper)
    validate_order(order)
    validate_cell_type(cell_type)
    tol = 1e-6 * max(lx, ly, h1, h2)

    def build(model):
        lower, upper = _stacked_boxes(model, lx, ly, h1, h2)
        model.occ.synchronize()   # no fragment: two independent surface meshes on z = 0
        add_groups(model, 3, {"upper": (1, [upper]), "lower": (2, [lower])})
        faces = {v: [t for _, t in model.getBoundary([(3, v)], oriented=False)]
                 for v in (lower, upper)}
        tags, c = entity_centers(model, 2)
        z = c[:, 2]
        on_z0 = set(tags[np.abs(z) < tol].tolist())
        add_groups(model, 2, {
            "contact_upper": (11, [t for t in faces[upper] if t in on_z0]),
            "contact_lower": (12, [t for t in faces[lower] if t in on_z0]),
            "top": (13, tags[np.abs(z - h2) < tol]),
            "bottom": (14, tags[np.abs(z + h1) < tol]),
            **_side_groups(model, lx, ly, tol)})
        _size_boxes(model, faces, ((lower, size_lower), (upper, size_upper)), cell_type)
        generate(model, order)

    return build_contact_scene(
        comm, "separate_blocks", build, ("upper", "lower"), ("contact_upper", "contact_lower"),
        dimensions=dict(lx=lx, ly=ly, h1=h1, h2=h2, size_lower=size_lower,
                        size_upper=size_upper))


def slider_on_slab(slab_length: float = 3.0, slider_length: float = 1.0, width: float = 0.5,
                   h_slab: float = 0.5, h_slider: float = 0.5, size_slab: float = 0.125,
                   size_slider: float = 0.1, order: int = 1,
                   cell_type: str = "hexahedron",
                   comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """A short block (the slider) on a long one (the slab), meshed independently (structured
    hexahedra, or unstructured tetrahedra of the given target sizes), both centred on x = 0,
    y in [0, width]: the scene of a body sliding over several elements of the other.
    Collective. ``order``: 1 or 2; ``cell_type``: ``"hexahedron"`` or ``"tetrahedron"``.

    Groups: bodies ``slider`` (1), ``slab`` (2); ``contact_slider`` (11, first),
    ``contact_slab`` (12), ``top`` (13, slider top), ``bottom`` (14, slab bottom),
    ``y0_slider`` (15), ``y0_slab`` (16).
    """
    validate_positive(slab_length=slab_length, slider_length=slider_length, width=width,
                      h_slab=h_slab, h_slider=h_slider, size_slab=size_slab,
                      size_slider=size_slider)
    validate_order(order)
    validate_cell_type(cell_type)
    if slider_length >= slab_length:
        raise ValueError(f"slider_length = {slider_length} must be < slab_length = "
                         f"{slab_length}")
    tol = 1e-6 * max(slab_length, h_slab, h_slider)

    def build(model):
        slab = model.occ.addBox(-slab_length / 2, 0, -h_slab, slab_length, width, h_slab)
        slider = model.occ.addBox(-slider_length / 2, 0, 0, slider_length, width, h_slider)
        model.occ.synchronize()   # no fragment: two independent surface meshes on z = 0
        add_groups(model, 3, {"slider": (1, [slider]), "slab": (2, [slab])})
        faces = {v: [t for _, t in model.getBoundary([(3, v)], oriented=False)]
                 for v in (slab, slider)}
        tags, c = entity_centers(model, 2)
        z, y = c[:, 2], c[:, 1]

        def pick(vol, mask):
            return [t for t in faces[vol] if t in set(tags[mask].tolist())]

        add_groups(model, 2, {
            "contact_slider": (11, pick(slider, np.abs(z) < tol)),
            "contact_slab": (12, pick(slab, np.abs(z) < tol)),
            "top": (13, pick(slider, np.abs(z - h_slider) < tol)),
            "bottom": (14, pick(slab, np.abs(z + h_slab) < tol)),
            "y0_slider": (15, pick(slider, np.abs(y) < tol)),
            "y0_slab": (16, pick(slab, np.abs(y) < tol))})
        _size_boxes(model, faces, ((slab, size_slab), (slider, size_slider)), cell_type)
        generate(model, order)

    return build_contact_scene(
        comm, "slider_on_slab", build, ("slider", "slab"), ("contact_slider", "contact_slab"),
        dimensions=dict(slab_length=slab_length, slider_length=slider_length, width=width,
                        h_slab=h_slab, h_slider=h_slider))


def sphere_on_block(radius: float = 10.0, cap_height: float = 1.0, half_width: float = 4.0,
                    height: float = 4.0, contact_radius: float = 1.0,
                    contact_size: float = 0.05, size_ratio: float = 0.7,
                    mesh_size: float = 1.0, transition: float = 1.0,
                    refined_radius: float = 0.4, order: int = 1,
                    comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Quarter sphere segment on a quarter block, meshed independently. Collective.

    The sphere (centre (0, 0, R)) is cut by the plane z = ``cap_height``; its surface within
    ``contact_radius`` of the z axis is the first contact surface (a separate face, so that the
    surface can be paired with the block's top by the mortar pairing, which needs the first
    surface inside the second). The block is [0, L]^2 x [-H, 0].

    Args:
        radius, cap_height: sphere radius and segment height [mm].
        half_width, height: block size L, H [mm].
        contact_radius: radius of the sphere's contact face [mm] (< the segment's radius).
        contact_size: element size in the block within ``refined_radius`` of the origin [mm];
            the sphere gets ``size_ratio`` x that (non-matching surface meshes).
        mesh_size, transition: far element size and the distance over which sizes grow [mm].
        order: 1 or 2.

    Returns:
        The scene; ``contact_pair = (sphere_contact, block_contact)``.
    """
    validate_positive(radius=radius, cap_height=cap_height, half_width=half_width,
                      height=height, contact_radius=contact_radius, contact_size=contact_size,
                      size_ratio=size_ratio, mesh_size=mesh_size, transition=transition,
                      refined_radius=refined_radius)
    validate_order(order)
    base = float(np.sqrt(radius**2 - (radius - cap_height) ** 2))
    if cap_height >= radius or contact_radius >= base:
        raise ValueError(f"sphere_on_block: need cap_height ({cap_height}) < radius ({radius}) "
                         f"and contact_radius ({contact_radius}) < the segment's base radius "
                         f"({base:.6g}) [mm]")
    tol = 1e-6 * max(radius, half_width, height)

    def build(model):
        occ = model.occ
        ball = occ.addSphere(0, 0, radius, radius)
        box = occ.addBox(0, 0, 0, base * 1.1, base * 1.1, cap_height)
        seg, _ = occ.intersect([(3, ball)], [(3, box)])
        cyl = occ.addCylinder(0, 0, -1.0, 0, 0, cap_height + 2.0, contact_radius)
        inner, _ = occ.intersect([(3, seg[0][1])], [(3, cyl)], removeObject=False,
                                 removeTool=False)
        outer, _ = occ.cut([(3, seg[0][1])], [(3, cyl)])
        pieces, _ = occ.fragment(inner, outer)
        block = occ.addBox(0, 0, -height, half_width, half_width, height)
        occ.synchronize()
        sphere_vols = [t for d, t in pieces if d == 3]
        add_groups(model, 3, {"sphere": (1, sphere_vols), "block": (2, [block])})
        sphere_faces = {t for _, t in model.getBoundary([(3, v) for v in sphere_vols],
                                                        combined=False, oriented=False)}
        block_faces = {t for _, t in model.getBoundary([(3, block)], oriented=False)}
        tags, c = entity_centers(model, 2)
        r = np.hypot(c[:, 0], c[:, 1])
        curved = [t for t in tags if t in sphere_faces and model.getType(2, t) == "Sphere"]
        contact = [t for t, ri in zip(tags, r) if t in curved and ri < contact_radius]
        add_groups(model, 2, {
            "sphere_contact": (11, contact),
            "block_contact": (12, [t for t, ci in zip(tags, c)
                                   if t in block_faces and abs(ci[2]) < tol]),
            "sphere_top": (13, [t for t, ci in zip(tags, c)
                                if t in sphere_faces and abs(ci[2] - cap_height) < tol]),
            "bottom": (14, tags[np.abs(c[:, 2] + height) < tol]),
            "symmetry_x": (17, tags[np.abs(c[:, 0]) < tol]),
            "symmetry_y": (18, tags[np.abs(c[:, 1]) < tol])})
        # one size field per body (restricted to its volumes), the smaller one wins
        dist = "Sqrt(x^2+y^2+z^2)"
        refine_towards(model, f"(Abs({dist}-{refined_radius})+{dist}-{refined_radius})/2",
                       contact_size, mesh_size, transition,
                       regions=[(sphere_vols, size_ratio * contact_size),
                                ([block], contact_size)])
        generate(model, order)

    return build_contact_scene(
        comm, "sphere_on_block", build, ("sphere", "block"), ("sphere_contact", "block_contact"),
        dimensions=dict(radius=radius, cap_height=cap_height, half_width=half_width,
                        height=height, contact_radius=contact_radius,
                        contact_size=contact_size, size_ratio=size_ratio))


def cylinder_on_block(radius: float = 5.0, height: float = 5.0, half_width: float = 10.0,
                      block_height: float = 10.0, size_cylinder: float = 1.0,
                      size_block: float = 1.6, order: int = 1,
                      comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """A cylinder of ``radius`` x ``height`` on the block [-L, L]^2 x [-Hb, 0], its base centred
    on the block's top, meshed independently (non-matching interface). Collective.

    Args:
        radius, height: cylinder size [mm].
        half_width, block_height: block size L, Hb [mm] (L > radius).
        size_cylinder, size_block: element sizes of the two bodies [mm].
        order: 1 or 2.

    Returns:
        The scene; ``contact_pair = (cylinder_contact, block_contact)`` (the base lies within the
        block's top, as the mortar pairing needs of the first surface).
    """
    validate_positive(radius=radius, height=height, half_width=half_width,
                      block_height=block_height, size_cylinder=size_cylinder,
                      size_block=size_block)
    validate_order(order)
    if half_width <= radius:
        raise ValueError(f"cylinder_on_block: half_width = {half_width} mm must exceed radius "
                         f"= {radius} mm (the base must lie on the block's top)")
    tol = 1e-6 * max(radius, height, half_width, block_height)

    def build(model):
        import gmsh

        cyl = model.occ.addCylinder(0, 0, 0, 0, 0, height, radius)
        block = model.occ.addBox(-half_width, -half_width, -block_height, 2 * half_width,
                                 2 * half_width, block_height)
        model.occ.synchronize()           # not fragmented: two independent meshes
        add_groups(model, 3, {"cylinder": (1, [cyl]), "block": (2, [block])})
        cyl_faces = {t for _, t in model.getBoundary([(3, cyl)], oriented=False)}
        tags, c = entity_centers(model, 2)
        z = c[:, 2]
        add_groups(model, 2, {
            "cylinder_contact": (11, [t for t, zi in zip(tags, z)
                                      if t in cyl_faces and abs(zi) < tol]),
            "block_contact": (12, [t for t, zi in zip(tags, z)
                                   if t not in cyl_faces and abs(zi) < tol]),
            "cylinder_top": (13, tags[np.abs(z - height) < tol]),
            "bottom": (14, tags[np.abs(z + block_height) < tol])})
        for vol, size in ((cyl, size_cylinder), (block, size_block)):
            points = model.getBoundary([(3, vol)], recursive=True)
            model.mesh.setSize(points, size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", max(size_cylinder, size_block))
        generate(model, order)

    return build_contact_scene(
        comm, "cylinder_on_block", build, ("cylinder", "block"),
        ("cylinder_contact", "block_contact"),
        dimensions=dict(radius=radius, height=height, half_width=half_width,
                        block_height=block_height, size_cylinder=size_cylinder,
                        size_block=size_block))


def block_on_plane(lx: float = 1.0, ly: float = 1.0, h: float = 1.0,
                   mesh_size: float = 0.25, order: int = 1, cell_type: str = "tetrahedron",
                   comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """One box [0, lx] x [0, ly] x [0, h] resting on the rigid plane z = 0. Collective.

    Args:
        lx, ly, h: block size [mm].
        mesh_size: largest tetrahedron edge, or hexahedron edge target [mm].
        order: 1 or 2.
        cell_type: ``"tetrahedron"`` or ``"hexahedron"`` (structured).
        comm: communicator of the mesh.

    Returns:
        The scene; ``contact_pair = (contact, None)``, rigid half-space z <= 0.
    """
    validate_positive(lx=lx, ly=ly, h=h, mesh_size=mesh_size)
    validate_order(order)
    validate_cell_type(cell_type)
    tol = 1e-6 * max(lx, ly, h)
    def build(model):
        block = model.occ.addBox(0, 0, 0, lx, ly, h)
        model.occ.synchronize()
        add_groups(model, 3, {"block": (1, [block])})
        tags, c = entity_centers(model, 2)
        add_groups(model, 2, {"contact": (11, tags[np.abs(c[:, 2]) < tol]),
                              "top": (13, tags[np.abs(c[:, 2] - h) < tol]),
                              **_side_groups(model, lx, ly, tol)})
        _mesh(model, mesh_size, order, cell_type)

    return build_scene(
        comm, "block_on_plane", build, split_body="block", contact_pair=("contact", None),
        rigid_plane=(np.zeros(3), np.array([0.0, 0.0, 1.0])),
        dimensions=dict(lx=lx, ly=ly, h=h, mesh_size=mesh_size))


def indented_block(half_width: float = 4.0, height: float = 4.0, mesh_size: float = 1.0,
                   contact_size: float = 0.05, transition: float = 1.0,
                   refined_radius: float = 0.4, order: int = 1, half: bool = False,
                   ring: typing.Optional[tuple[float, float, float]] = None,
                   ring_growth: typing.Optional[float] = None,
                   comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Quarter of a block [0, L] x [0, L] x [-H, 0] for an indenter touching its top at the
    origin (or, with ``half``, the half [-L, L] x [0, L] x [-H, 0], for loads along x):
    element size ``contact_size`` within ``refined_radius`` of the origin, growing to
    ``mesh_size`` over a further ``transition`` [mm]. ``ring = (radius, half_band, size)``
    refines further around a contact edge: element size ``size`` within ``half_band`` of the
    circle of ``radius`` about the z axis on the top face (the band's distance is measured in r
    and depth), growing to the surrounding sizes over 2 ``half_band``. Collective.

    ``ring_growth`` [mm]: the ring's size instead grows linearly to ``contact_size`` over
    this distance from the band (and on at the same rate beyond). The default growth towards
    ``mesh_size`` over 2 ``half_band`` is a cliff when ``mesh_size`` is coarse (16 mm on a
    large block: the size passes ``contact_size`` within a micrometre of the band) and gmsh
    then leaves a narrow band under-refined (docs/mindlin_dual.md, "ring-refined P2").

    Labels: "block" (1); "contact" (11): top z = 0; "bottom" (14): z = -H;
    "symmetry_x" (17): x = 0 (empty for ``half``); "symmetry_y" (18): y = 0.
    The scene's rigid plane (metadata only) is z = 0 with normal -z; pass the real indenter
    to ``ContactInterface(rigid=...)``.
    """
    validate_positive(half_width=half_width, height=height, mesh_size=mesh_size,
                      contact_size=contact_size, transition=transition,
                      refined_radius=refined_radius)
    validate_order(order)
    if ring is not None:
        ring_radius, half_band, ring_size = ring
        validate_positive(ring_radius=ring_radius, ring_half_band=half_band,
                          ring_size=ring_size)
    if ring_growth is not None:
        if ring is None:
            raise ValueError(f"ring_growth = {ring_growth!r} is invalid without a ring")
        validate_positive(ring_growth=ring_growth)
        if not ring[2] < contact_size:
            raise ValueError(f"ring size = {ring[2]!r} mm is invalid with ring_growth: it must "
                             f"be below contact_size = {contact_size!r} mm")
    tol = 1e-6 * max(half_width, height)

    def build(model):
        x0 = -half_width if half else 0.0
        box = model.occ.addBox(x0, 0, -height, half_width - x0, half_width, height)
        model.occ.synchronize()
        add_groups(model, 3, {"block": (1, [box])})
        tags, c = entity_centers(model, 2)
        groups = {"contact": (11, tags[np.abs(c[:, 2]) < tol]),
                  "bottom": (14, tags[np.abs(c[:, 2] + height) < tol]),
                  "symmetry_x": (17, tags[np.abs(c[:, 0]) < tol]),
                  "symmetry_y": (18, tags[np.abs(c[:, 1]) < tol])}
        if half:
            del groups["symmetry_x"]
        add_groups(model, 2, groups)
        r = "Sqrt(x^2+y^2+z^2)"
        extra = ()
        if ring is not None:
            # distance to the band |rho - R| <= b of the top face: (rho - R, z) outside the band
            d_rho = f"Abs(Sqrt(x^2+y^2)-{ring_radius})-{half_band}"
            d_band = f"Sqrt((({d_rho})+Abs({d_rho}))^2/4+z^2)"
            width = 2.0 * half_band if ring_growth is None else \
                ring_growth * (mesh_size - ring_size) / (contact_size - ring_size)
            extra = ((d_band, ring_size, width),)
        refine_towards(model, f"(Abs({r}-{refined_radius})+{r}-{refined_radius})/2",
                       contact_size, mesh_size, transition, extra=extra)
        generate(model, order)

    return build_scene(
        comm, "indented_block", build, split_body="block", contact_pair=("contact", None),
        rigid_plane=(np.zeros(3), np.array([0.0, 0.0, -1.0])),
        dimensions=dict(half_width=half_width, height=height, mesh_size=mesh_size,
                        contact_size=contact_size))
