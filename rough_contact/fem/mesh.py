"""gmsh model -> one DOLFINx mesh holding every body of a contact scene.

Units: whatever the gmsh model uses; the scenes in ``rough_contact/scenes/meshes/`` are in mm.

The bodies are meshed together in gmsh after an OCC ``fragment``, so that their contact
faces share one conforming surface mesh. Before the mesh reaches DOLFINx, the nodes that
the *split body* (the owner of the first contact surface) shares with the other bodies
are duplicated in numpy, so the bodies become disconnected parts of one mesh whose contact
faces still carry identical facets (same vertex coordinates, different vertices). This is
the "duplicate" route of ``docs/design.md``: robust for any geometry, P1 and P2 alike, and it
needs no periodic node matching (this gmsh build lacks ANN).

The gmsh model lives on one rank only; :func:`scene_from_gmsh` is collective and
distributes the mesh with ``dolfinx.mesh.create_mesh``; tags are distributed with
``distribute_entity_data`` + ``meshtags_from_entities`` (the DOLFINx 0.5.2 API).

Physical groups of the gmsh model carry *names*; they become the keys of
``Scene.labels`` (name -> tag), and their gmsh tags become the DOLFINx tag values. Volume
and surface groups must use distinct tags and distinct names, and surface groups must not
overlap (a facet carries one tag), except across the split interface, where the two
contact groups contain the same gmsh surface and are told apart by their owner body.
"""

from __future__ import annotations

import contextlib
import typing
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

import dolfinx
import dolfinx.cpp
import dolfinx.fem
import dolfinx.mesh
import ufl

from rough_contact.fem import compat

__all__ = [
    "Scene",
    "ConformityReport",
    "scene_from_gmsh",
    "check_conformity",
    "facet_vertex_coordinates",
    "owned_facets",
    "measure_of",
    "write_xdmf",
    "describe",
    "build_scene",
    "build_contact_scene",
    "gmsh_session",
    "entity_centers",
    "set_transfinite_hexahedra",
    "add_groups",
    "validate_positive",
    "validate_order",
    "validate_cell_type",
]

# gmsh element type -> (DOLFINx cell name, degree); gmsh facet type for each cell type.
_GMSH_CELLS = {4: ("tetrahedron", 1), 11: ("tetrahedron", 2),
               5: ("hexahedron", 1), 12: ("hexahedron", 2)}
_GMSH_FACETS = {4: 2, 11: 9, 5: 3, 12: 10}


@dataclass(frozen=True)
class Scene:
    """One DOLFINx mesh holding the bodies of a contact problem, with tags and labels.

    Attributes:
        mesh: the distributed mesh (all bodies, disconnected from each other).
        cell_tags: cell MeshTags, one value per body (volume physical group).
        facet_tags: facet MeshTags for the named boundary surfaces.
        labels: name -> tag for bodies and surfaces (e.g. ``"punch"``,
            ``"contact_punch"``, ``"load"``, ``"symmetry_x"``).
        contact_pair: (tag of the first contact surface, tag of the second one or ``None``
            when the second body is the rigid plane). The first surface's facets carry the
            quadrature points of the interface; its outward normal points towards the
            second body.
        rigid_plane: ``(point, normal)``, arrays of shape (3,), when the second body is a
            rigid half-space: it occupies ``{x : (x - point) . normal <= 0}``, i.e.
            ``normal`` is the unit outward normal of the rigid base (it points into the
            deformable body). ``None`` for two deformable bodies.
        order: polynomial degree of the geometry (1 or 2); use the same degree for the
            displacement space to keep the facets conforming.
        cell_type: ``"tetrahedron"`` or ``"hexahedron"``.
        dimensions: scene geometry (name -> value, mm), for the tests and demos.
        bodies: names of the bodies (volume groups), the split body first.
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: typing.Any
    facet_tags: typing.Any
    labels: dict
    contact_pair: tuple
    rigid_plane: typing.Optional[tuple] = None
    order: int = 1
    cell_type: str = "tetrahedron"
    dimensions: dict = field(default_factory=dict)
    bodies: tuple = ()

    def tag(self, name: str) -> int:
        """Return the tag of the body or surface called ``name``."""
        try:
            return self.labels[name]
        except KeyError:
            raise ValueError(f"label {name!r} is not in this scene; valid labels: "
                             f"{sorted(self.labels)}") from None

    def name(self, tag: int) -> str:
        """Return the name of the body or surface tagged ``tag``."""
        for key, value in self.labels.items():
            if value == tag:
                return key
        raise ValueError(f"tag {tag} is not in this scene; valid tags: "
                         f"{sorted(self.labels.values())}")


@dataclass(frozen=True)
class ConformityReport:
    """Result of :func:`check_conformity` (global figures, identical on every rank).

    Attributes:
        n_first: number of facets of the first surface.
        n_second: number of facets of the second surface.
        n_matched: facets of the first surface whose vertex coordinates equal those of a
            facet of the second surface (within ``tol``).
        max_distance: largest distance between matched vertices [length unit].
        shared_vertices: number of mesh vertices used by both surfaces (0 when the bodies
            are disconnected across the interface).
    """

    n_first: int
    n_second: int
    n_matched: int
    max_distance: float
    shared_vertices: int

    @property
    def conforming(self) -> bool:
        """True when the two surfaces carry the same facets on distinct vertices."""
        return (self.n_first == self.n_second == self.n_matched and self.shared_vertices == 0)


def _on_rank(comm, rank, func):
    """Run ``func()`` on ``rank`` only; re-raise its exception on every rank. Collective.

    Without this, an exception on the gmsh rank would leave the others waiting forever in
    the next collective call.
    """
    result, error = None, None
    if comm.rank == rank:
        try:
            result = func()
        except Exception as exc:  # noqa: BLE001 - re-raised on every rank below
            error = (isinstance(exc, ValueError), f"{type(exc).__name__}: {exc}")
    error = comm.bcast(error, root=rank)
    if error is not None:
        raise (ValueError if error[0] else RuntimeError)(
            f"on rank {rank} while building the gmsh scene: {error[1]}")
    return result


def build_scene(comm: MPI.Comm, name: str, build: typing.Callable, rank: int = 0,
                **scene_kwargs) -> Scene:
    """Run ``build(model)`` on ``rank`` in a gmsh session, then :func:`scene_from_gmsh`.

    Collective. ``build`` creates, tags and meshes the model; its exceptions are raised on
    every rank.

    Args:
        comm: communicator of the mesh.
        name: gmsh model name.
        build: ``build(gmsh.model) -> None``.
        rank: rank running gmsh.
        scene_kwargs: keyword arguments of :func:`scene_from_gmsh`.
    """
    with gmsh_session(comm, rank, name) as model:
        _on_rank(comm, rank, lambda: build(model))
        return scene_from_gmsh(model, comm, rank=rank, **scene_kwargs)


def build_contact_scene(comm: MPI.Comm, name: str, build: typing.Callable, bodies: tuple,
                        contact_pair: tuple, dimensions: dict) -> Scene:
    """:func:`build_scene` for two deformable bodies in contact. Collective.

    ``bodies = (first, second)`` own the surfaces ``contact_pair = (first, second)``; the first
    body (the owner of the first contact surface) is the split body.
    """
    return build_scene(comm, name, build, split_body=bodies[0], contact_pair=contact_pair,
                       surface_owners=dict(zip(contact_pair, bodies)), dimensions=dimensions)


@contextlib.contextmanager
def gmsh_session(comm: MPI.Comm, rank: int = 0, name: str = "scene"):
    """Yield ``gmsh.model`` on ``rank`` (gmsh initialised quietly, one thread) else ``None``.

    gmsh is finalised on exit: builders own the gmsh session (gmsh 4.8 cannot tell whether
    a caller already initialised it).
    """
    if comm.rank != rank:
        yield None
        return
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add(name)
        yield gmsh.model
    finally:
        gmsh.finalize()


def entity_centers(model, dim: int) -> tuple:
    """Tags (n,) and centres of mass (n, 3) of the OCC entities of dimension ``dim``."""
    tags = np.array([t for _, t in model.getEntities(dim)], dtype=np.int32)
    centers = np.array([model.occ.getCenterOfMass(dim, int(t)) for t in tags]).reshape(-1, 3)
    return tags, centers


def add_groups(model, dim: int, groups: dict) -> None:
    """Add named physical groups {name: (tag, [entity tags])}; empty groups raise."""
    for name, (tag, entities) in groups.items():
        if len(entities) == 0:
            raise ValueError(f"physical group {name!r} selects no entity of dimension {dim}")
        model.addPhysicalGroup(dim, [int(e) for e in entities], tag)
        model.setPhysicalName(dim, tag, name)


def _graded(length, h_near, h_far):
    """(elements, ratio) of a geometric progression from h_near to about h_far over length."""
    if h_far <= h_near * (1 + 1e-12) or length <= h_far:
        return max(1, int(np.ceil(length / h_near - 1e-6))), 1.0
    ratio = (length - h_near) / (length - h_far)  # the series h_near r^k sums to length
    n = 1 + int(np.ceil(np.log(h_far / h_near) / np.log(ratio) - 1e-6))
    return max(n, 1), ratio


def set_transfinite_hexahedra(model, size_near: float, size_far: float,
                              distance: typing.Optional[typing.Callable] = None) -> None:
    """Structured (transfinite, recombined) hexahedra on a model made of 6-sided boxes.

    Each curve is split uniformly with ``size_near`` when both its end points are at the
    same distance from the refinement target, otherwise in a geometric progression from
    ``size_near`` at the nearer end towards ``size_far``. Parallel edges of a box must
    get the same split, so ``distance`` must depend only on the coordinate along the
    curve's axis.

    Args:
        model: ``gmsh.model`` with synchronised OCC boxes.
        size_near, size_far: element sizes near / far from the target [length unit].
        distance: ``distance(point (3,), axis) -> float``, distance of a curve end point
            from the target along ``axis``; ``None`` gives uniform ``size_near``.
    """
    for _, curve in model.getEntities(1):
        ends = model.getBoundary([(1, curve)], combined=False, oriented=True)
        p0, p1 = (np.array(model.getValue(0, abs(t), [])) for _, t in ends)
        axis = int(np.argmax(np.abs(p1 - p0)))
        length = abs(p1[axis] - p0[axis])
        d0, d1 = (0.0, 0.0) if distance is None else (distance(p0, axis), distance(p1, axis))
        if d0 == d1:
            n, ratio = _graded(length, size_near, size_near)
        else:
            n, ratio = _graded(length, size_near, size_far)
        model.mesh.setTransfiniteCurve(curve, n + 1, "Progression",
                                       ratio if d0 < d1 else 1.0 / ratio)
    for dim, surface in model.getEntities(2):
        model.mesh.setTransfiniteSurface(surface)
        model.mesh.setRecombine(dim, surface)
    for _, volume in model.getEntities(3):
        model.mesh.setTransfiniteVolume(volume)


def validate_positive(**values) -> None:
    """Raise ``ValueError`` naming the first value that is not a finite positive number."""
    for key, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{key} = {value!r} is invalid; valid range: finite and > 0")


def validate_cell_type(cell_type) -> None:
    """Raise ``ValueError`` unless ``cell_type`` is "tetrahedron" or "hexahedron"."""
    if cell_type not in ("tetrahedron", "hexahedron"):
        raise ValueError(f"cell_type = {cell_type!r} is invalid; valid values: "
                         "'tetrahedron', 'hexahedron'")


def validate_order(order) -> None:
    """Raise ``ValueError`` unless ``order`` is 1 or 2."""
    if order not in (1, 2):
        raise ValueError(f"order = {order!r} is invalid; valid values: 1, 2")


def _gmsh_groups(model, dim):
    """Physical groups of dimension ``dim`` as {name: (tag, [entities])} (rank with gmsh)."""
    groups = {}
    for d, tag in model.getPhysicalGroups(dim):
        name = model.getPhysicalName(d, tag)
        if not name:
            raise ValueError(f"physical group (dim={d}, tag={tag}) has no name; every group "
                             "of a scene must be named")
        if name in groups:
            raise ValueError(f"physical group name {name!r} is used twice in dimension {dim}")
        groups[name] = (tag, list(model.getEntitiesForPhysicalGroup(d, tag)))
    return groups


def _elements(model, dim, entity):
    types, _, nodes = model.mesh.getElements(dim, entity)
    if len(types) != 1:
        raise ValueError(f"gmsh entity (dim={dim}, tag={entity}) holds {len(types)} element "
                         "types; exactly 1 is supported")
    num_nodes = model.mesh.getElementProperties(types[0])[3]
    return types[0], np.asarray(nodes[0], dtype=np.int64).reshape(-1, num_nodes)


def _read_model(model, split_body, surface_owners):
    """Arrays of the gmsh model, with the split body's interface nodes duplicated."""
    volumes = _gmsh_groups(model, 3)
    surfaces = _gmsh_groups(model, 2)
    if split_body not in volumes:
        raise ValueError(f"split_body {split_body!r} is not a volume group; volume groups: "
                         f"{sorted(volumes)}")
    clash = set(volumes) & set(surfaces)
    tags = [t for t, _ in volumes.values()] + [t for t, _ in surfaces.values()]
    if clash or len(set(tags)) != len(tags):
        raise ValueError(f"volume and surface groups must have distinct names and tags; "
                         f"names in both: {sorted(clash)}, tags: {sorted(tags)}")

    node_tags, coords, _ = model.mesh.getNodes()
    order = np.argsort(node_tags)
    node_tags = np.asarray(node_tags, dtype=np.int64)[order]
    x = np.asarray(coords, dtype=np.float64).reshape(-1, 3)[order]

    def index(gmsh_nodes):
        return np.searchsorted(node_tags, gmsh_nodes)

    cells, cell_values, cell_type, body_of_volume = _read_cells(model, volumes, index)
    facets, facet_values, facet_owner, n_facet_nodes = _read_facets(
        model, volumes, surfaces, surface_owners, cell_type, body_of_volume, index)
    x, cells, facets, n_shared = _split_body_nodes(x, cells, cell_values, facets, facet_owner,
                                                   volumes[split_body][0])
    x, cells, facets = _drop_unused_nodes(x, cells, facets, facet_values, surfaces)
    labels = {name: int(tag) for name, (tag, _) in {**volumes, **surfaces}.items()}
    bodies = (split_body,) + tuple(n for n in volumes if n != split_body)
    return dict(x=x, cells=cells, cell_values=cell_values, facets=facets,
                facet_values=facet_values, cell_type=int(cell_type), labels=labels, bodies=bodies,
                n_shared=n_shared, n_facet_nodes=int(n_facet_nodes))


def _read_cells(model, volumes, index):
    """Cells (gmsh node order, indices into the sorted nodes), the body tag of each cell, the
    gmsh cell type and the body tag of every volume entity."""
    cell_type, cell_blocks, cell_values, body_of_volume = None, [], [], {}
    for tag, entities in volumes.values():
        for entity in entities:
            etype, nodes = _elements(model, 3, entity)
            if etype not in _GMSH_CELLS:
                raise ValueError(f"gmsh element type {etype} is not supported; valid: "
                                 f"{sorted(_GMSH_CELLS)} (P1/P2 tetrahedra, hexahedra)")
            if cell_type not in (None, etype):
                raise ValueError(f"mixed gmsh cell types {cell_type} and {etype}")
            cell_type = etype
            cell_blocks.append(index(nodes))
            cell_values.append(np.full(len(nodes), tag, dtype=np.int32))
            body_of_volume[entity] = tag
    if cell_type is None:
        raise ValueError("the gmsh model has no volume physical group with elements")
    return np.concatenate(cell_blocks), np.concatenate(cell_values), cell_type, body_of_volume


def _read_facets(model, volumes, surfaces, surface_owners, cell_type, body_of_volume, index):
    """Facets of the surface groups, their tag and the body owning each (from
    ``surface_owners`` or the one adjacent body); a facet of one body carries one tag."""
    owners_given = dict(surface_owners or {})
    facet_type = _GMSH_FACETS[cell_type]
    facet_blocks, facet_values, facet_owner = [], [], []
    for name, (tag, entities) in surfaces.items():
        if name in owners_given:
            if owners_given[name] not in volumes:
                raise ValueError(f"surface_owners[{name!r}] = {owners_given[name]!r} is not a "
                                 f"volume group; volume groups: {sorted(volumes)}")
            owner = volumes[owners_given[name]][0]
        else:
            owner = None
        for entity in entities:
            if owner is None:
                adjacent = {body_of_volume[v] for v in model.getAdjacencies(2, entity)[0]
                            if v in body_of_volume}
                if len(adjacent) != 1:
                    raise ValueError(f"surface {entity} of group {name!r} touches "
                                     f"{len(adjacent)} bodies (must be 1); give the group's "
                                     "owner in surface_owners")
                entity_owner = adjacent.pop()
            else:
                entity_owner = owner
            etype, nodes = _elements(model, 2, entity)
            if etype != facet_type:
                raise ValueError(f"surface {name!r} holds gmsh elements of type {etype}, "
                                 f"expected {facet_type} for cells of type {cell_type}")
            facet_blocks.append(index(nodes))
            facet_values.append(np.full(len(nodes), tag, dtype=np.int32))
            facet_owner.append(np.full(len(nodes), entity_owner, dtype=np.int32))
    n_facet_nodes = model.mesh.getElementProperties(facet_type)[3]
    facets = (np.concatenate(facet_blocks) if facet_blocks
              else np.empty((0, n_facet_nodes), dtype=np.int64))
    facet_values = np.concatenate(facet_values) if facet_values else np.empty(0, np.int32)
    facet_owner = np.concatenate(facet_owner) if facet_owner else np.empty(0, np.int32)
    # Facets of one body must not carry two tags (a MeshTags entity has one value).
    key = np.column_stack([np.sort(facets, axis=1), facet_owner])
    if len(np.unique(key, axis=0)) != len(key):
        raise ValueError("surface physical groups overlap: a facet of one body belongs to two "
                         "groups; make the groups disjoint")
    return facets, facet_values, facet_owner, n_facet_nodes


def _split_body_nodes(x, cells, cell_values, facets, facet_owner, split_tag):
    """Duplicate the nodes the split body shares with the other bodies (vectorised): the
    bodies become disconnected, their contact faces keep the same surface mesh."""
    split = cell_values == split_tag
    in_split = np.zeros(len(x), dtype=bool)
    in_split[cells[split].ravel()] = True
    in_other = np.zeros(len(x), dtype=bool)
    in_other[cells[~split].ravel()] = True
    shared = np.flatnonzero(in_split & in_other)
    renumber = np.arange(len(x), dtype=np.int64)
    renumber[shared] = len(x) + np.arange(len(shared), dtype=np.int64)
    x = np.vstack([x, x[shared]])
    cells[split] = renumber[cells[split]]
    of_split = facet_owner == split_tag
    facets[of_split] = renumber[facets[of_split]]
    return x, cells, facets, len(shared)


def _drop_unused_nodes(x, cells, facets, facet_values, surfaces):
    """Keep only the nodes some cell uses, renumbered in their order (vectorised).

    gmsh lists every node of the model, including those of geometric points and curves no volume
    element touches (construction points, embedded entities, meshed but unused surfaces);
    DOLFINx must not receive them: ``distribute_entity_data`` crashed (segmentation fault) on
    such a node in the flat punch at mesh size 2.5 mm, contact size 0.833 mm, P1.

    Raises:
        ValueError: a tagged surface element uses a node that no cell uses (the surface group
            does not lie on the boundary of a meshed volume).
    """
    used = np.zeros(len(x), dtype=bool)
    used[cells.ravel()] = True
    if used.all():
        return x, cells, facets
    new = np.full(len(x), -1, dtype=np.int64)
    new[used] = np.arange(int(used.sum()), dtype=np.int64)
    stray = ~used[facets].all(axis=1) if len(facets) else np.zeros(0, dtype=bool)
    if stray.any():
        names = {int(t): n for n, (t, _) in surfaces.items()}
        bad = sorted({names.get(int(v), str(v)) for v in facet_values[stray]})
        raise ValueError(f"{int(stray.sum())} surface element(s) of group(s) {bad} use nodes "
                         "that no volume element uses: a surface group must lie on the "
                         "boundary of a meshed volume")
    return x[used], new[cells], new[facets]


def scene_from_gmsh(model, comm: MPI.Comm, *, split_body: str,
                    contact_pair: tuple, surface_owners: typing.Optional[dict] = None,
                    rigid_plane: typing.Optional[tuple] = None, rank: int = 0,
                    dimensions: typing.Optional[dict] = None) -> Scene:
    """Distribute a meshed gmsh model (living on ``rank``) as a :class:`Scene`. Collective.

    Args:
        model: ``gmsh.model`` on ``rank`` (ignored elsewhere), already meshed (and
            ``setOrder``-ed for P2), with named physical groups for every body (dim 3) and
            every boundary surface of interest (dim 2).
        comm: communicator of the mesh.
        split_body: name of the body whose nodes shared with other bodies are duplicated
            (conventionally the owner of the first contact surface).
        contact_pair: (name of the first contact surface, name of the second or ``None``
            for a rigid plane).
        surface_owners: surface name -> body name, required for groups whose gmsh
            surfaces touch two bodies (the shared contact surface, once per side).
        rigid_plane: ``(point, normal)`` of the rigid half-space when the second body is
            rigid (see :class:`Scene`); ``normal`` is normalised here.
        rank: the rank holding the gmsh model.
        dimensions: geometry figures to keep in ``Scene.dimensions``.

    Returns:
        The scene; mesh and tags are distributed over ``comm``.
    """
    rigid_plane = _normalised_plane(rigid_plane)
    data = _on_rank(comm, rank, lambda: _read_model(model, split_body, surface_owners))
    return _scene_from_data(data, comm, contact_pair=contact_pair, rigid_plane=rigid_plane,
                            rank=rank, dimensions=dimensions)


def _normalised_plane(rigid_plane):
    """``(point (3,), unit normal (3,))`` of a rigid plane given as (point, normal); None stays."""
    if rigid_plane is None:
        return None
    point = np.asarray(rigid_plane[0], dtype=np.float64).reshape(3)
    normal = np.asarray(rigid_plane[1], dtype=np.float64).reshape(3)
    norm = np.linalg.norm(normal)
    if not norm > 0:
        raise ValueError(f"rigid_plane normal {normal} has zero length; must be nonzero")
    return point, normal / norm


def _merge_models(parts: list) -> dict:
    """Concatenate the arrays of several gmsh models (separate meshes: nothing shared)."""
    labels, bodies = {}, []
    for part in parts:
        clash = set(labels) & set(part["labels"])
        tags = set(labels.values()) & set(part["labels"].values())
        if clash or tags:
            raise ValueError(f"the mesh files share physical group names {sorted(clash)} or "
                             f"tags {sorted(tags)}: every group of the combined scene must have "
                             "its own name and tag")
        labels.update(part["labels"])
        bodies += list(part["bodies"])
    types = {p["cell_type"] for p in parts}
    if len(types) != 1:
        raise ValueError(f"the mesh files hold different cell types (gmsh types {sorted(types)}): "
                         "all bodies must use the same element")
    offsets = np.cumsum([0] + [len(p["x"]) for p in parts[:-1]])
    return dict(x=np.vstack([p["x"] for p in parts]),
                cells=np.vstack([p["cells"] + o for p, o in zip(parts, offsets)]),
                cell_values=np.concatenate([p["cell_values"] for p in parts]),
                facets=np.vstack([p["facets"] + o for p, o in zip(parts, offsets)]),
                facet_values=np.concatenate([p["facet_values"] for p in parts]),
                cell_type=parts[0]["cell_type"], labels=labels, bodies=tuple(bodies),
                n_shared=sum(p["n_shared"] for p in parts),
                n_facet_nodes=parts[0]["n_facet_nodes"])


def scene_from_msh_files(paths: typing.Sequence, comm: MPI.Comm, *, contact_pair: tuple,
                         split_bodies: typing.Optional[typing.Sequence[str]] = None,
                         rigid_plane: typing.Optional[tuple] = None, rank: int = 0,
                         dimensions: typing.Optional[dict] = None,
                         surface_owners: typing.Optional[dict] = None) -> Scene:
    """One scene from one or several gmsh ``.msh`` files (several: meshed separately, e.g. a
    flange and a gasket, for a non-matching interface). Collective.

    Each file is read in its own gmsh model (so node, element and entity numbers of different
    files never clash) and must name its physical groups (bodies: dimension 3, surfaces:
    dimension 2) with names and tags not used by the other files; the arrays are concatenated
    and distributed as for :func:`scene_from_gmsh`.

    Args:
        paths: the ``.msh`` files.
        contact_pair: (first contact surface name, second name) — typically one from each file.
        split_bodies: per file, the body whose nodes shared with its other bodies are duplicated
            (a file with one body needs none: default, its first body).
        surface_owners: surface name -> body name for the groups whose gmsh surfaces touch two
            bodies of one file (a conforming interface meshed in one file, as
            ``meshes/flat_punch.py`` writes it; see :func:`scene_from_gmsh`).

    Raises:
        ValueError: a missing file, clashing group names/tags, different cell types.
    """
    import os

    paths = [os.fspath(p) for p in paths]

    def read():
        import gmsh

        parts = []
        for i, path in enumerate(paths):
            if not os.path.isfile(path):
                raise ValueError(f"mesh file {path!r} does not exist")
            gmsh.model.add(f"part{i}")
            gmsh.merge(path)
            split = None if split_bodies is None else split_bodies[i]
            if split is None:
                split = next(iter(_gmsh_groups(gmsh.model, 3)), None)
            parts.append(_read_model(gmsh.model, split, surface_owners))
            gmsh.model.remove()
        return _merge_models(parts)

    rigid_plane = _normalised_plane(rigid_plane)
    with gmsh_session(comm, rank, "msh_files"):
        data = _on_rank(comm, rank, read)
    return _scene_from_data(data, comm, contact_pair=contact_pair, rigid_plane=rigid_plane,
                            rank=rank, dimensions=dimensions)


_DOLFINX_TO_GMSH = {("tetrahedron", 1): 4, ("tetrahedron", 2): 11, ("hexahedron", 1): 5,
                    ("hexahedron", 2): 12}


def _read_xdmf_part(path: str, labels: dict, mesh_name: str, cell_tags: str,
                    facet_tags: str) -> dict:
    """The arrays of one XDMF mesh file (serial, on the reading rank), in gmsh node order."""
    from dolfinx.io import XDMFFile

    with XDMFFile(MPI.COMM_SELF, path, "r") as xdmf:
        msh = xdmf.read_mesh(name=mesh_name)
        tdim = msh.topology.dim
        msh.topology.create_connectivity(tdim - 1, tdim)
        try:
            ct = xdmf.read_meshtags(msh, name=cell_tags)
            ft = xdmf.read_meshtags(msh, name=facet_tags)
        except RuntimeError as exc:
            raise ValueError(f"{path!r} must hold mesh tags named {cell_tags!r} and "
                             f"{facet_tags!r} (as rough_contact.fem.mesh.write_xdmf writes "
                             f"them): {exc}") from None
    name = msh.topology.cell_type.name
    degree = msh.geometry.cmap.degree
    key = (name, degree)
    if key not in _DOLFINX_TO_GMSH:
        raise ValueError(f"{path!r}: {name} cells of degree {degree} are not supported; "
                         f"supported: {sorted(_DOLFINX_TO_GMSH)}")
    gmsh_cell = _DOLFINX_TO_GMSH[key]
    n_nodes = {4: 4, 11: 10, 5: 8, 12: 27}[gmsh_cell]
    dolfinx_cell = dolfinx.cpp.mesh.to_type(name)
    x = np.array(msh.geometry.x, dtype=np.float64)
    dofmap = np.asarray(compat.geometry_dofmap(msh), dtype=np.int64).reshape(-1, n_nodes)
    cells = np.empty_like(dofmap)
    cells[:, dolfinx.cpp.io.perm_gmsh(dolfinx_cell, n_nodes)] = dofmap   # back to gmsh order
    n_cells = len(cells)
    cell_values = np.full(n_cells, -1, dtype=np.int32)
    cell_values[ct.indices] = ct.values
    if (cell_values < 0).any():
        raise ValueError(f"{path!r}: {int((cell_values < 0).sum())} of {n_cells} cells carry no "
                         f"cell tag: every cell must belong to a body")
    facet_cell = dolfinx.cpp.mesh.cell_entity_type(dolfinx_cell, tdim - 1, 0)
    # geometry nodes of each tagged facet (all of them for P2: DOLFINx 0.5's
    # entities_to_geometry gives the vertices only), through a cell holding it
    msh.topology.create_connectivity(tdim, tdim - 1)
    f2c, c2f = (msh.topology.connectivity(tdim - 1, tdim), msh.topology.connectivity(tdim, tdim - 1))
    f = np.asarray(ft.indices, dtype=np.int64)
    cell = f2c.array[f2c.offsets[f]]
    local = np.argmax(c2f.array.reshape(n_cells, -1)[cell] == f[:, None], axis=1)
    layout = msh.geometry.cmap.create_dof_layout()
    closure = np.array([layout.entity_closure_dofs(tdim - 1, j)
                        for j in range(c2f.array.size // n_cells)], dtype=np.int64)
    facet_nodes = dofmap[cell[:, None], closure[local]]
    facets = np.empty_like(facet_nodes)
    facets[:, dolfinx.cpp.io.perm_gmsh(facet_cell, facet_nodes.shape[1])] = facet_nodes
    found = set(np.unique(cell_values).tolist()) | set(np.unique(ft.values).tolist())
    named = {int(v) for v in labels.values()}
    if found - named:
        raise ValueError(f"{path!r}: tags {sorted(found - named)} have no name in its labels "
                         f"{labels}")
    bodies = tuple(n for n, t in labels.items() if t in set(np.unique(cell_values).tolist()))
    return dict(x=x, cells=cells, cell_values=cell_values, facets=facets,
                facet_values=np.asarray(ft.values, dtype=np.int32), cell_type=gmsh_cell,
                labels={n: int(t) for n, t in labels.items()}, bodies=bodies, n_shared=0,
                n_facet_nodes=int(facets.shape[1]))


def scene_from_xdmf_files(parts: typing.Sequence, comm: MPI.Comm, *, contact_pair: tuple,
                          rigid_plane: typing.Optional[tuple] = None, rank: int = 0,
                          dimensions: typing.Optional[dict] = None, mesh_name: str = "mesh",
                          cell_tags: str = "cell_tags",
                          facet_tags: str = "facet_tags") -> Scene:
    """One scene from several XDMF mesh files written by DOLFINx (e.g. two parts a user meshed
    and saved separately), for a non-matching interface. Collective.

    Each file holds one mesh with its cell tags (one value per body) and facet tags (the named
    surfaces), as :func:`write_xdmf` writes them (``XDMFFile.write_mesh`` + ``write_meshtags``).
    XDMF stores no names, so every file comes with its labels. The files are read on ``rank``
    (serially), their arrays concatenated (bodies of different files share no node) and
    distributed as for :func:`scene_from_gmsh`; tags keep their values.

    Args:
        parts: ``(path, labels)`` per file, labels = {name: tag} of its bodies and surfaces
            (e.g. ``scene.labels`` of the scene that wrote it).
        contact_pair: (first contact surface name, second name).
        mesh_name, cell_tags, facet_tags: the names of the mesh and tag grids in the files.

    Raises:
        ValueError: a missing file, missing tags, tags without a name, clashing names or tags
            between files, different cell types or degrees.
    """
    import os

    parts = [(os.fspath(path), dict(labels)) for path, labels in parts]

    def read():
        arrays = []
        for path, labels in parts:
            if not os.path.isfile(path):
                raise ValueError(f"mesh file {path!r} does not exist")
            arrays.append(_read_xdmf_part(path, labels, mesh_name, cell_tags, facet_tags))
        degrees = {a["cell_type"] for a in arrays}
        if len(degrees) != 1:
            raise ValueError(f"the XDMF files hold different cell types or degrees (gmsh types "
                             f"{sorted(degrees)}): all bodies must use the same element")
        data = _merge_models(arrays)
        data["x"], data["cells"], data["facets"] = _drop_unused_nodes(
            data["x"], data["cells"], data["facets"], data["facet_values"], {})
        return data

    data = _on_rank(comm, rank, read)
    return _scene_from_data(data, comm, contact_pair=contact_pair, rigid_plane=rigid_plane,
                            rank=rank, dimensions=dimensions)


def _scene_from_data(data, comm, *, contact_pair, rigid_plane, rank, dimensions) -> Scene:
    """Distribute the arrays read by :func:`_read_model` (on ``rank``; None elsewhere)."""
    meta = comm.bcast(None if data is None else
                      {k: data[k] for k in ("cell_type", "labels", "n_facet_nodes", "bodies")},
                      root=rank)
    gmsh_cell = meta["cell_type"]
    labels = meta["labels"]
    name, degree = _GMSH_CELLS[gmsh_cell]
    n_nodes = {4: 4, 11: 10, 5: 8, 12: 27}[gmsh_cell]
    if data is None:
        x = np.empty((0, 3))
        cells = np.empty((0, n_nodes), dtype=np.int64)
        cell_values = np.empty(0, dtype=np.int32)
        facets = np.empty((0, meta["n_facet_nodes"]), dtype=np.int64)
        facet_values = np.empty(0, dtype=np.int32)
    else:
        x, cells, cell_values = data["x"], data["cells"], data["cell_values"]
        facets, facet_values = data["facets"], data["facet_values"]

    for pair_name in contact_pair:
        if pair_name is not None and pair_name not in labels:
            raise ValueError(f"contact surface {pair_name!r} is not a physical group; "
                             f"groups: {sorted(labels)}")
    if contact_pair[1] is None and rigid_plane is None:
        raise ValueError("contact_pair has no second surface: give rigid_plane=(point, normal)")

    dolfinx_cell = dolfinx.cpp.mesh.to_type(name)
    cells = cells[:, dolfinx.cpp.io.perm_gmsh(dolfinx_cell, n_nodes)]
    msh = compat.create_mesh(comm, cells, x, name, degree)
    tdim = msh.topology.dim

    msh.topology.create_connectivity(tdim, 0)
    cell_tags = compat.meshtags_from_arrays(msh, tdim, cells, cell_values)
    cell_tags.name = "cell_tags"

    facet_cell = dolfinx.cpp.mesh.cell_entity_type(dolfinx_cell, tdim - 1, 0)
    facets = facets[:, dolfinx.cpp.io.perm_gmsh(facet_cell, facets.shape[1])]
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim - 1, 0)
    facet_tags = compat.meshtags_from_arrays(msh, tdim - 1, facets, facet_values)
    facet_tags.name = "facet_tags"

    pair = (labels[contact_pair[0]],
            None if contact_pair[1] is None else labels[contact_pair[1]])
    return Scene(mesh=msh, cell_tags=cell_tags, facet_tags=facet_tags, labels=dict(labels),
                 contact_pair=pair, rigid_plane=rigid_plane, order=degree, cell_type=name,
                 dimensions=dict(dimensions or {}), bodies=tuple(meta["bodies"]))


def owned_facets(scene: Scene, tag: int) -> np.ndarray:
    """Local indices of the facets tagged ``tag`` that this rank owns, shape (n,) int32."""
    fdim = scene.mesh.topology.dim - 1
    n_owned = scene.mesh.topology.index_map(fdim).size_local
    facets = scene.facet_tags.find(tag)
    return facets[facets < n_owned].astype(np.int32)


def facet_vertex_coordinates(scene: Scene, tag: int) -> np.ndarray:
    """Corner coordinates of the owned facets tagged ``tag``, local to this rank.

    Returns:
        Array of shape (n_facets, n_corners, 3) (3 corners for triangles, 4 for quads),
        corners in DOLFINx's facet vertex order.
    """
    msh = scene.mesh
    fdim = msh.topology.dim - 1
    facets = owned_facets(scene, tag)
    n_corners = 3 if scene.cell_type == "tetrahedron" else 4
    if len(facets) == 0:
        return np.empty((0, n_corners, 3))
    msh.topology.create_connectivity(fdim, 0)
    # Corner geometry nodes (the first n_corners nodes of a P1/P2 facet are its vertices).
    nodes = compat.facet_geometry_nodes(msh, facets)
    return msh.geometry.x[nodes[:, :n_corners]]


def _facet_vertices_global(scene: Scene, tag: int) -> np.ndarray:
    msh = scene.mesh
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, 0)
    f2v = msh.topology.connectivity(fdim, 0)
    facets = owned_facets(scene, tag)
    n_corners = 3 if scene.cell_type == "tetrahedron" else 4
    local = f2v.array.reshape(-1, n_corners)[facets] if len(facets) else \
        np.empty((0, n_corners), dtype=np.int32)
    return msh.topology.index_map(0).local_to_global(local.ravel()).astype(np.int64)


def check_conformity(scene: Scene, first: typing.Optional[int] = None,
                     second: typing.Optional[int] = None, tol: float = 1e-10) -> ConformityReport:
    """Check that two surfaces carry the same facets on distinct vertices. Collective.

    Every owned facet of ``first`` is looked up, by its sorted corner coordinates, among
    the facets of ``second`` gathered from all ranks (surface-sized data only).

    Args:
        scene: the scene.
        first, second: facet tags; default ``scene.contact_pair``.
        tol: largest coordinate distance accepted as equal [length unit].

    Returns:
        Global figures, identical on every rank.
    """
    from scipy.spatial import cKDTree

    first = scene.contact_pair[0] if first is None else first
    second = scene.contact_pair[1] if second is None else second
    if second is None:
        raise ValueError("check_conformity needs two deformable surfaces; this scene's second "
                         "contact body is a rigid plane")
    comm = scene.mesh.comm

    def signature(tag):
        xyz = facet_vertex_coordinates(scene, tag)
        order = np.lexsort((xyz[:, :, 2], xyz[:, :, 1], xyz[:, :, 0]), axis=-1) \
            if len(xyz) else np.empty(xyz.shape[:2], dtype=int)
        xyz = np.take_along_axis(xyz, order[:, :, None], axis=1)
        return xyz.reshape(len(xyz), 3 * xyz.shape[1])

    sig1 = signature(first)
    sig2 = np.concatenate(comm.allgather(signature(second)))
    n1 = comm.allreduce(len(sig1))
    n2 = len(sig2)
    if len(sig1) and n2:
        dist, _ = cKDTree(sig2).query(sig1)
        matched = dist <= tol * np.sqrt(sig1.shape[1])
        n_matched = int(matched.sum())
        dmax = float(dist[matched].max()) if n_matched else 0.0
    else:
        n_matched, dmax = 0, 0.0
    n_matched = comm.allreduce(n_matched)
    dmax = comm.allreduce(dmax, op=MPI.MAX)

    v1 = np.unique(np.concatenate(comm.allgather(_facet_vertices_global(scene, first))))
    v2 = np.unique(np.concatenate(comm.allgather(_facet_vertices_global(scene, second))))
    shared = len(np.intersect1d(v1, v2))
    return ConformityReport(n_first=n1, n_second=n2, n_matched=n_matched, max_distance=dmax,
                            shared_vertices=shared)


def measure_of(scene: Scene, name: str) -> float:
    """Volume of a body or area of a surface, by assembling 1 over its tag. Collective."""
    tag = scene.tag(name)
    if name in scene.bodies:
        measure = ufl.Measure("dx", domain=scene.mesh, subdomain_data=scene.cell_tags)
    else:
        measure = ufl.Measure("ds", domain=scene.mesh, subdomain_data=scene.facet_tags)
    form = dolfinx.fem.form(dolfinx.fem.Constant(scene.mesh, 1.0) * measure(tag))
    return scene.mesh.comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)


def write_xdmf(scene: Scene, filename: str) -> None:
    """Write the mesh, cell tags and facet tags to one XDMF file (for ParaView). Collective."""
    from dolfinx.io import XDMFFile

    msh = scene.mesh
    msh.topology.create_connectivity(msh.topology.dim - 1, msh.topology.dim)
    with XDMFFile(msh.comm, filename, "w") as xdmf:
        xdmf.write_mesh(msh)
        compat.write_meshtags(xdmf, scene.cell_tags, msh)
        compat.write_meshtags(xdmf, scene.facet_tags, msh)


def describe(scene: Scene) -> str:
    """One line per label with its tag and global measure; cell and DOF counts. Collective."""
    msh = scene.mesh
    n_cells = msh.topology.index_map(msh.topology.dim).size_global
    n_nodes = msh.geometry.index_map().size_global
    lines = [f"{scene.cell_type} P{scene.order}: {n_cells} cells, {n_nodes} nodes "
             f"({3 * n_nodes} displacement DOFs at degree {scene.order}), "
             f"{msh.comm.size} rank(s); contact_pair={scene.contact_pair}, "
             f"rigid_plane={scene.rigid_plane}"]
    for name, tag in scene.labels.items():
        kind = "volume" if name in scene.bodies else "area"
        if kind == "volume":
            owned = scene.cell_tags.indices < msh.topology.index_map(msh.topology.dim).size_local
            n = msh.comm.allreduce(int(np.sum(scene.cell_tags.values[owned] == tag)))
        else:
            n = msh.comm.allreduce(len(owned_facets(scene, tag)))
        lines.append(f"  {name:20s} tag {tag:3d}  {kind} {measure_of(scene, name):.6g}  "
                     f"({n} {'cells' if kind == 'volume' else 'facets'})")
    return "\n".join(lines)


def generate(model, order: int) -> None:
    """Mesh the model in 3D and, for ``order`` 2, make it second order (complete 10-node
    tetrahedra / 27-node hexahedra)."""
    import gmsh

    model.mesh.generate(3)
    if order == 2:
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        model.mesh.setOrder(2)


def refine_towards(model, distance: str, contact_size: float, mesh_size: float,
                   transition: float, regions: typing.Optional[typing.Sequence] = None,
                   extra: typing.Sequence = ()) -> None:
    """Element size from ``contact_size`` at distance 0 to ``mesh_size`` beyond ``transition``.

    Args:
        model: ``gmsh.model``.
        distance: gmsh MathEval expression in x, y, z of the exact distance to the contact
            region [mm] (exact, unlike gmsh's sampled Distance field).
        regions: optional ``[(volume tags, contact size), ...]``: a size field per group of
            volumes (restricted to them, their faces and curves), the smallest size winning —
            bodies meshed separately with their own sizes at the contact.
        extra: further ``[(distance, size, transition), ...]``: element size ``size`` at
            distance 0 from another region (e.g. a ring around a contact edge), growing to
            ``mesh_size`` over ``transition``; the smallest size wins everywhere.
    """
    import gmsh

    field = model.mesh.field

    def threshold(size, dist_expr=distance, width=transition):
        dist = field.add("MathEval")
        field.setString(dist, "F", dist_expr)
        thr = field.add("Threshold")
        field.setNumber(thr, "InField", dist)
        field.setNumber(thr, "SizeMin", size)
        field.setNumber(thr, "SizeMax", mesh_size)
        field.setNumber(thr, "DistMin", 0.0)
        field.setNumber(thr, "DistMax", width)
        return thr

    more = [threshold(size, expr, width) for expr, size, width in extra]
    if regions is None:
        main = threshold(contact_size)
        if more:
            smallest = field.add("Min")
            field.setNumbers(smallest, "FieldsList", [main] + more)
            main = smallest
        field.setAsBackgroundMesh(main)
    else:
        restricted = []
        for vols, size in regions:
            res = field.add("Restrict")
            field.setNumber(res, "InField", threshold(size))
            faces = model.getBoundary([(3, v) for v in vols], combined=False, oriented=False)
            curves = model.getBoundary(faces, combined=False, oriented=False)
            field.setNumbers(res, "VolumesList", list(vols))
            field.setNumbers(res, "SurfacesList", sorted({abs(t) for _, t in faces}))
            field.setNumbers(res, "CurvesList", sorted({abs(t) for _, t in curves}))
            restricted.append(res)
        smallest = field.add("Min")
        field.setNumbers(smallest, "FieldsList", restricted + more)
        field.setAsBackgroundMesh(smallest)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
