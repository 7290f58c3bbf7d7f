"""Build one of the library's scene meshes, print its labels and measures, optionally write XDMF.

    bash run.sh python demos/show_scene_mesh.py flat_punch [--mesh-size 20 --contact-size 2
        --order 2 --cell-type hexahedron] [--xdmf punch.xdmf]
    bash run.sh python demos/show_scene_mesh.py beam [--mesh-size 40 --contact-size 5]
    mpirun -n 2 .venv/bin/python demos/show_scene_mesh.py two_blocks --mesh-size 0.5

The scenes' geometries as gmsh scripts a user can edit are in the top-level ``meshes/`` folder;
this script shows the builders the library scenes use (``rough_contact/scenes/meshes/``).
Units: mm.
"""

import argparse
import logging

from mpi4py import MPI

from rough_contact.fem.mesh import describe, write_xdmf
from rough_contact.scenes.meshes.beam import beam_on_base
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.scenes.meshes.flat_punch import flat_punch

# builder and its float keywords exposed as --options
SCENES = {
    "flat_punch": (flat_punch, ["mesh_size", "contact_size", "load_half_width", "transition"]),
    "beam": (beam_on_base, ["mesh_size", "contact_size", "load_half_length", "transition"]),
    "two_blocks": (two_blocks, ["mesh_size", "lx", "ly", "h1", "h2"]),
}


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    sub = ap.add_subparsers(dest="scene", required=True)
    for name, (builder, floats) in SCENES.items():
        p = sub.add_parser(name, help=(builder.__doc__ or name).splitlines()[0],
                           allow_abbrev=False)
        for key in floats:
            p.add_argument("--" + key.replace("_", "-"), dest=key, type=float, default=None)
        p.add_argument("--order", type=int, default=1)
        p.add_argument("--cell-type", default=None, choices=["tetrahedron", "hexahedron"])
        p.add_argument("--xdmf", default=None, help="write mesh and tags to this file")
    return ap


def main(argv=None):
    logging.getLogger().setLevel(logging.WARNING)
    opts = parser().parse_args(argv)
    builder, _ = SCENES[opts.scene]
    kwargs = {k: v for k, v in vars(opts).items()
              if k not in ("scene", "xdmf") and v is not None}
    scene = builder(comm=MPI.COMM_WORLD, **kwargs)
    text = describe(scene)
    if scene.mesh.comm.rank == 0:
        print(text)
    if opts.xdmf:
        write_xdmf(scene, opts.xdmf)
    return scene


if __name__ == "__main__":
    main()
