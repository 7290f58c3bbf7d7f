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

import os
import sys

import gmsh

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # _common.py, next to this file
import _common  # noqa: E402


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

    _common.group(3, "beam", 1, [t for _, t in gmsh.model.getEntities(3)])
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
        _common.group(2, name, tag, surfaces.get(name, []))

    # element size: contact_size at z = 0, growing to mesh_size at z = transition
    _common.refine_towards("Abs(z)", contact_size, mesh_size, transition)
    _common.mesh(order)


def write(path="beam.msh", show=False, **sizes):
    """Build the mesh in a fresh gmsh session and write it to ``path`` (MSH 4.1)."""
    return _common.write(build, "beam_on_base", path, show, **sizes)


def main(argv=None):
    ap = _common.parser(__doc__, "beam.msh", mesh_size=40.0, contact_size=5.0)
    ap.add_argument("--load-half-length", dest="c", type=float, default=5.0,
                    help="half length of the loaded strip on the top [mm]")
    args = ap.parse_args(argv)
    write(args.output, show=args.show, mesh_size=args.mesh_size,
          contact_size=args.contact_size, order=args.order, c=args.c)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
