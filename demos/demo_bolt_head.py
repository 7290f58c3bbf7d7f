"""A cylinder (bolt head) on a block, meshed separately, rough interface with orthotropic
slip-hardening friction: preload, then a tangential slide of the top.

    bash run.sh python demos/demo_bolt_head.py [--pressure 10] [--slide 2] [--order 1]
        [--size-cylinder 1.0] [--size-block 1.6] [--pairing mortar|projection]
    mpirun -n 2 .venv/bin/python demos/demo_bolt_head.py

Prints one line per increment: the slide, the normal and tangential interface forces, the
slipping fraction of the base, the real contact area, the dissipation and the force balance
(interface force vs applied preload and top reaction, <= 1e-8 of P or the run stops). The
library function is rough_contact.scenes.bolt_head.run; copy it for your own pair of parts.
"""

import argparse

from rough_contact.scenes import bolt_head


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pressure", type=float, default=10.0, help="nominal preload [MPa]")
    ap.add_argument("--slide", type=float, default=2.0, help="tangential slide of the top [um]")
    ap.add_argument("--order", type=int, default=1, choices=[1, 2])
    ap.add_argument("--size-cylinder", type=float, default=1.0, help="element size [mm]")
    ap.add_argument("--size-block", type=float, default=1.6, help="element size [mm]")
    ap.add_argument("--pairing", default="mortar", choices=["mortar", "projection"])
    ap.add_argument("--shear-steps", type=int, default=4)
    args = ap.parse_args(argv)
    return bolt_head.run(pressure=args.pressure, slide_um=args.slide, order=args.order,
                         size_cylinder=args.size_cylinder, size_block=args.size_block,
                         pairing=args.pairing, shear_steps=args.shear_steps)


if __name__ == "__main__":
    main()
