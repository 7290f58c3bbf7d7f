"""Prismatic beam on a rigid base (paper section 9.1), half model: gmsh geometry -> .msh file.

    python3 meshes/beam.py                            # writes beam.msh (P2, 40 / 5 mm)
    python3 meshes/beam.py --mesh-size 60 --contact-size 10 --order 1 -o coarse.msh
    python3 meshes/beam.py --show                     # also opens the mesh in the gmsh window

Needs only gmsh's Python API (Debian: python3-gmsh). Units: mm.

The beam, 10 mm wide, 120 mm high and 500 mm long, stands on its narrow face on a flat RIGID
base; by symmetry about the mid-length plane y = 0 half of it is meshed:

    beam  [-w/2, w/2] x [0, l/2] x [0, hb]     w = 10, l = 500, hb = 120

Only the beam is meshed: the base is the rigid half-space z <= 0, given when the file is read
(``rigid_plane=((0, 0, 0), (0, 0, 1))``, see meshes/README.md). The strip y <= c (c = 5) of the
top face is imprinted as the loaded area. The element size grows from ``contact_size`` at the
contact face z = 0 to ``mesh_size`` at ``transition`` (default hb / 2) above it.

Physical groups (name: tag) — the same as the library's scene (rough_contact.scenes.meshes):
    volume    beam: 1
    surfaces  contact_beam: 11 (bottom z = 0, the contact surface), load: 13 (top strip),
              top: 14 (rest of the top), sides: 15 (x = +-w/2), symmetry_y: 18 (y = 0),
              end: 19 (free end y = l/2)
"""

import argparse

import gmsh


def build(mesh_size=40.0, contact_size=5.0, order=2, w=10.0, hb=120.0, length=500.0, c=5.0,
          transition=None):
    """Create and mesh the model in the current gmsh session."""
    transition = hb / 2 if transition is None else transition
    half = length / 2
    tol = 1e-6 * max(length, hb)
    occ = gmsh.model.occ
    beam = occ.addBox(-w / 2, 0, 0, w, half, hb)
    strip = occ.addRectangle(-w / 2, 0, hb, w, c)       # the loaded strip on the top
    occ.fragment([(3, beam)], [(2, strip)])
    occ.synchronize()

    def group(dim, name, tag, entities):
        if not entities:
            raise ValueError(f"physical group {name!r} selects nothing")
        gmsh.model.addPhysicalGroup(dim, entities, tag)
        gmsh.model.setPhysicalName(dim, tag, name)

    group(3, "beam", 1, [t for _, t in gmsh.model.getEntities(3)])
    surfaces = {}
    for _, s in gmsh.model.getEntities(2):
        x, y, z = occ.getCenterOfMass(2, s)
        if abs(z) < tol:
            key = "contact_beam"
        elif abs(z - hb) < tol:
            key = "load" if y < c + tol else "top"
        elif abs(abs(x) - w / 2) < tol:
            key = "sides"
        elif abs(y) < tol:
            key = "symmetry_y"
        else:
            key = "end"
        surfaces.setdefault(key, []).append(s)
    for name, tag in dict(contact_beam=11, load=13, top=14, sides=15, symmetry_y=18,
                          end=19).items():
        group(2, name, tag, surfaces.get(name, []))

    # element size: contact_size at z = 0, growing to mesh_size at z = transition
    field = gmsh.model.mesh.field
    dist = field.add("MathEval")
    field.setString(dist, "F", "Abs(z)")
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

    gmsh.model.mesh.generate(3)
    if order == 2:
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)   # complete 10-node tetrahedra
        gmsh.model.mesh.setOrder(2)


def write(path="beam.msh", show=False, **sizes):
    """Build the mesh in a fresh gmsh session and write it to ``path`` (MSH 4.1)."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("beam_on_base")
        build(**sizes)
        gmsh.write(str(path))
        if show:
            gmsh.fltk.run()
    finally:
        gmsh.finalize()
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh-size", type=float, default=40.0, help="away from the contact [mm]")
    ap.add_argument("--contact-size", type=float, default=5.0, help="on the contact [mm]")
    ap.add_argument("--order", type=int, choices=[1, 2], default=2)
    ap.add_argument("--load-half-length", dest="c", type=float, default=5.0,
                    help="half length of the loaded strip on the top [mm]")
    ap.add_argument("-o", "--output", default="beam.msh")
    ap.add_argument("--show", action="store_true", help="open the result in gmsh's window")
    args = ap.parse_args(argv)
    write(args.output, show=args.show, mesh_size=args.mesh_size,
          contact_size=args.contact_size, order=args.order, c=args.c)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
