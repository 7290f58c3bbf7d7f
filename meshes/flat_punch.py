"""Flat punch on a foundation (paper section 9.2), quarter model: gmsh geometry -> .msh file.

    python3 meshes/flat_punch.py                      # writes flat_punch.msh (P2, 20 / 2 mm)
    python3 meshes/flat_punch.py --mesh-size 40 --contact-size 10 --order 1 -o coarse.msh
    python3 meshes/flat_punch.py --show               # also opens the mesh in the gmsh window

Needs only gmsh's Python API (Debian: python3-gmsh). Units: mm. Edit the numbers below (or pass
them as options) to change the geometry; keep the physical-group names, they are what the
scene reads (see meshes/README.md for reading the file with ``scene_from_msh_files``).

Geometry (symmetry about x = 0 and y = 0, so only a quarter is meshed):

    punch       [0, a] x [0, a] x [0, hp]     a = 10 (half of the 20 mm punch), hp = 10
    foundation  [0, L] x [0, L] x [-H, 0]     L = 50, H = 50

The two boxes are fragmented, so the punch bottom and the foundation top under it share one
surface mesh (a conforming interface). The central square [0, b]^2 of the punch top (b = 2.5)
is imprinted as the loaded patch. The element size grows from ``contact_size`` on the contact
square to ``mesh_size`` at ``transition`` (default 2 a) from it: a Threshold field on the exact
distance to the square [0, a]^2 x {0}, written in closed form.

Physical groups (name: tag) — the same as the library's scene (rough_contact.scenes.meshes):
    volumes   punch: 1, foundation: 2
    surfaces  contact_punch: 11 (punch bottom, the first contact surface),
              contact_foundation: 12 (the same surface, owned by the foundation),
              load: 13, punch_top: 14 (rest of the top), punch_sides: 15, foundation_top: 16,
              symmetry_x: 17 (x = 0), symmetry_y: 18 (y = 0), fixed: 19 (z = -H),
              foundation_sides: 20 (x = L and y = L)
"""

import os
import sys

import gmsh

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # _common.py, next to this file
import _common  # noqa: E402


def build(mesh_size=20.0, contact_size=2.0, order=2, a=10.0, hp=10.0, L=50.0, H=50.0, b=2.5,
          transition=None):
    """Create and mesh the model in the current gmsh session."""
    transition = 2 * a if transition is None else transition
    tol = 1e-6 * max(L, H)
    occ = gmsh.model.occ
    punch = occ.addBox(0, 0, 0, a, a, hp)
    foundation = occ.addBox(0, 0, -H, L, L, H)
    tools = [(3, foundation)]
    if b < a:                                   # imprint the load patch on the punch top
        tools.append((2, occ.addRectangle(0, 0, hp, b, b)))
    occ.fragment([(3, punch)], tools)
    occ.synchronize()

    def centre(dim, tag):
        return occ.getCenterOfMass(dim, tag)

    vols = [t for _, t in gmsh.model.getEntities(3)]
    _common.group(3, "punch", 1, [v for v in vols if centre(3, v)[2] > 0])
    _common.group(3, "foundation", 2, [v for v in vols if centre(3, v)[2] < 0])

    surfaces = {}
    for _, s in gmsh.model.getEntities(2):
        x, y, z = centre(2, s)
        inside = x < a - tol and y < a - tol
        top = abs(z - hp) < tol
        in_load = top and x < b + tol and y < b + tol
        if abs(z) < tol and inside:
            keys = ["contact_punch", "contact_foundation"]
        elif in_load:
            keys = ["load"]
        elif top:
            keys = ["punch_top"]
        elif z > tol and (abs(x - a) < tol or abs(y - a) < tol):
            keys = ["punch_sides"]
        elif abs(z) < tol:
            keys = ["foundation_top"]
        elif abs(x) < tol:
            keys = ["symmetry_x"]
        elif abs(y) < tol:
            keys = ["symmetry_y"]
        elif abs(z + H) < tol:
            keys = ["fixed"]
        else:
            keys = ["foundation_sides"]
        for k in keys:
            surfaces.setdefault(k, []).append(s)
    tags = dict(contact_punch=11, contact_foundation=12, load=13, punch_top=14, punch_sides=15,
                foundation_top=16, symmetry_x=17, symmetry_y=18, fixed=19, foundation_sides=20)
    for name, tag in tags.items():
        if name in surfaces:                    # punch_top is empty when b = a
            _common.group(2, name, tag, surfaces[name])

    # element size: contact_size at distance 0 from the contact square, mesh_size beyond
    dx, dy = f"(Abs(x-{a})+x-{a})/2", f"(Abs(y-{a})+y-{a})/2"
    _common.refine_towards(f"Sqrt(({dx})^2+({dy})^2+z^2)", contact_size, mesh_size, transition)
    _common.mesh(order)


def write(path="flat_punch.msh", show=False, **sizes):
    """Build the mesh in a fresh gmsh session and write it to ``path`` (MSH 4.1)."""
    return _common.write(build, "flat_punch", path, show, **sizes)


def main(argv=None):
    ap = _common.parser(__doc__, "flat_punch.msh", mesh_size=20.0, contact_size=2.0)
    ap.add_argument("--load-half-width", dest="b", type=float, default=2.5,
                    help="half width of the loaded square on the punch top [mm]")
    args = ap.parse_args(argv)
    write(args.output, show=args.show, mesh_size=args.mesh_size,
          contact_size=args.contact_size, order=args.order, b=args.b)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
