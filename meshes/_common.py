"""What the gmsh scripts of this folder share: physical groups, the element-size field, meshing,
writing the .msh file and the command line. gmsh's Python API only (no DOLFINx, no
``rough_contact``), like the scripts. Units: mm.
"""

import argparse

import gmsh


def group(dim, name, tag, entities):
    """Physical group ``name`` (``tag``) of the ``entities`` of dimension ``dim``; empty raises."""
    if not entities:
        raise ValueError(f"physical group {name!r} selects nothing")
    gmsh.model.addPhysicalGroup(dim, entities, tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def refine_towards(distance, contact_size, mesh_size, transition):
    """Element size ``contact_size`` where the MathEval expression ``distance`` (in x, y, z) is
    0, growing to ``mesh_size`` where it reaches ``transition`` [mm] (a Threshold field)."""
    field = gmsh.model.mesh.field
    dist = field.add("MathEval")
    field.setString(dist, "F", distance)
    thr = field.add("Threshold")
    field.setNumber(thr, "InField", dist)
    field.setNumber(thr, "SizeMin", contact_size)
    field.setNumber(thr, "SizeMax", mesh_size)
    field.setNumber(thr, "DistMin", 0.0)
    field.setNumber(thr, "DistMax", transition)
    field.setAsBackgroundMesh(thr)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)


def mesh(order):
    """Tetrahedra of ``order`` 1 or 2 (complete 10-node tetrahedra)."""
    gmsh.model.mesh.generate(3)
    if order == 2:
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.model.mesh.setOrder(2)


def write(build, model_name, path, show=False, **sizes):
    """Run ``build(**sizes)`` in a fresh gmsh session and write the mesh to ``path`` (MSH 4.1);
    ``show`` also opens it in gmsh's window. Returns ``path``."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add(model_name)
        build(**sizes)
        gmsh.write(str(path))
        if show:
            gmsh.fltk.run()
    finally:
        gmsh.finalize()
    return path


def parser(doc, output, mesh_size, contact_size):
    """The options of every script (element sizes, order, output, --show); a script adds its
    own (the loaded patch)."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--mesh-size", type=float, default=mesh_size, help="away from the contact [mm]")
    ap.add_argument("--contact-size", type=float, default=contact_size, help="on the contact [mm]")
    ap.add_argument("--order", type=int, choices=[1, 2], default=2)
    ap.add_argument("-o", "--output", default=output)
    ap.add_argument("--show", action="store_true", help="open the result in gmsh's window")
    return ap
