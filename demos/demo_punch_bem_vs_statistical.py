# # Flat punch with the statistical and the boundary-element normal law on the same surface
#
# The flat punch of section 9.2 (rough_contact.scenes.flat_punch: quarter model, E = 200 GPa,
# nu = 0.25, orthotropic slip-hardening friction of case (b)) is run twice on the same rough
# surface, once with the statistical elastic law of the package (asperity sums, eqs 52-55) and
# once with the BEM law of that surface (rough_contact.micro.bem: exact elastic contact of Gaussian
# realisations of the surface's spectrum, averaged at equal separation). Everything else -
# mesh, friction, tangential stiffness kT = c kN, seating, load path - is identical, so the
# differences are the effect of choosing one normal law or the other:
#
# * approach: mean downward displacement of the loaded patch of the punch top [um];
# * interface closure: area-weighted mean normal jump g over the contact face relative to the
#   seated state [um] (the rough layer's compression);
# * interface stiffness: int k(h) dA over the face [N/mm] and the secant dF/d(approach) of the
#   whole punch;
# * real contact area int A/A0 dA [mm^2] and the frictional dissipation D [N mm].
#
# Load: the paper's 1000 N gives nominal pressures (0.16-2.5 MPa) at which the example
# surfaces touch on 0.01-0.1 % of the area, far below what a BEM grid of one roll-off period
# resolves (docs/bem.md). The demo therefore applies a bolted-joint level load, 50 kN by default
# (nominal 125 MPa on the 20 x 20 mm face, seated at the first of 8 increments), so that the
# contact pressures lie inside the BEM table; points outside either table are counted.
#
# Tangential stiffness: the friction case's kT = 0.7 kN by default (the paper's value);
# ``--kt bem`` takes instead the ratios kT/kN the BEM computes for this surface in full stick
# (both runs; about 0.80 along and 0.93 across the grain of the anisotropic surface, Mindlin's
# 2(1 - nu)/(2 - nu) = 0.857 for the isotropic one).
#
# Units: mm, N, MPa; printed displacements in um.
#
# Run: ``mpirun -n 2 python3 demos/demo_punch_bem_vs_statistical.py [--surface anisotropic]
# [--force 50000] [--steps 8] [--realisations 8] [--ppw 8] [--kt case|bem] [--small]
# [PETSc options]``.
# ``--small`` (coarse P1 mesh, 2 increments, 2 realisations on a coarse grid) runs in well under a
# minute for tests. The runs live in the library: rough_contact.scenes.punch_bem.

from __future__ import annotations

import argparse

from _common import parse_known, start


def parse_args(argv):
    ap = argparse.ArgumentParser(description="Flat punch: statistical vs BEM normal law. "
                                 "Unknown options go to PETSc (prefix rc_).", allow_abbrev=False)
    ap.add_argument("--surface", default="anisotropic",
                    choices=["isotropic", "anisotropic", "self-affine", "paper"])
    ap.add_argument("--force", type=float, default=50e3, help="total punch force [N]")
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--case", default="b", choices=["a", "b", "c"])
    ap.add_argument("--mesh-size", type=float, default=20.0)
    ap.add_argument("--contact-size", type=float, default=2.0)
    ap.add_argument("--order", type=int, default=2, choices=[1, 2])
    ap.add_argument("--realisations", type=int, default=8)
    ap.add_argument("--ppw", type=float, default=8.0)
    ap.add_argument("--backend", default=None, choices=["tamaas", "numpy"],
                    help="BEM backend (default: tamaas, rough_contact.micro.bem)")
    ap.add_argument("--kt", default="case", choices=["case", "bem"],
                    help="tangential stiffness ratio kT/kN: the friction case's (paper: 0.7) "
                    "or the BEM's stick ratios of the surface")
    ap.add_argument("--small", action="store_true", help="test size (< 1 min)")
    ap.add_argument("--outdir", default="results/punch_bem_vs_statistical")
    return parse_known(ap, argv)


if __name__ == "__main__":
    a = start(parse_args)      # PETSc's options in before the library imports dolfinx
    from rough_contact.scenes.punch_bem import run

    run(surface=a.surface, force=a.force, steps=a.steps, case=a.case, mesh_size=a.mesh_size,
        contact_size=a.contact_size, order=a.order, realisations=a.realisations, ppw=a.ppw,
        small=a.small, backend=a.backend, outdir=a.outdir, kt=a.kt)
