# # Elastic beam on a rigid base across a rough interface (paper section 9.1, Table 4, Fig 13)
#
# Buczkowski & Kleiber (2009), section 9.1: an elastic prismatic beam, 10 x 120 mm in
# cross-section and 500 mm long, lies with one of its narrow faces (10 x 500 mm) on a flat rigid
# base. A total force of 1962 N compresses it at mid-length, applied in sixteen increments from
# an initial load of 4.9 N. E1 = 1.057e5 MPa, nu1 = 0.25, so E* = E1/(1 - nu1^2) = 1.127e5 MPa.
# The interface is a rough anisotropic surface with
#
#     m20 = 8e-5, m02 = 8e-4, m40 = 1.04e-6 um^-2, m04 = 1.04e-4 um^-2,
#     m00 in {0.625, 0.3125, 0.0625} um^2,
#
# and the elastic (eqs 52-55) or elasto-plastic (eqs 78-88; Y = 2070 MPa, K_Y = 1.62,
# psi = 0.35, ch = 0.967, omega_p/omega_c = 45) normal law: the six cases of Table 4.
#
# Units: mm, N, MPa (deflections are printed in um).  Half model (symmetry plane y = 0, the
# mid-length section); the half carries 981 N.  The load acts on a strip of the top face,
# |y| <= 5 mm (the paper says only "at the prism mid-length").
#
# What is solved at every load factor lam (applied force = lam * 981 N):
#
#     find u:  int_Omega sigma(u) : eps(v) dx + int_Gamma t(B u) . B v dA = lam int_load f . v ds
#
# with Gamma the beam's bottom face and the rigid base z <= 0 as the second body (u = 0 there).
# t is the rough-interface traction: t_N = -p(h0 + g) from the statistical normal law and a
# tangential traction with the Mindlin tangential stiffness kT = c kN (eq 96) limited by the
# paper's slip-hardening friction.
#
# Modelling choices the paper does not state (documented in docs/beam.md):
# * reference of the deflection: uN(x, y) = g - g_init, the change of the interface normal jump
#   g (g > 0 opens) between the state after the initial 4.9 N and the final 1962 N;
#   uN < 0 = the surfaces approach, uN > 0 = they move apart (lift-off at the ends);
# * seating: zero gap carries the nominal pressure of the initial load, p(h0) = 4.9 N / 5000 mm^2
#   (then the initial state is an almost uniform pressure, as for a beam laid on the base);
# * tangential stiffness: Mindlin's ratio (96) for the typical asperity contact ellipse of this
#   surface (``TangentialStiffness.from_surface``; ``--tangential 0.7`` for kT = 0.7 kN);
#   friction (not given in section 9.1): the paper's slip-hardening model with the data of its
#   other example on the same surface (section 9.2, case (b); ``--friction a`` or ``none`` for
#   the alternatives).  The beam's rigid motion along x (its sides are free) is restrained by
#   that tangential stiffness; the frictionless variant fixes u_x = 0 at the contact-face nodes
#   on the mid-plane x = 0 instead (exact by symmetry);
# * elasto-plastic asperities: hardness from the paper's psi = 0.35 (``--hardness tabor`` for
#   H = Y/0.354);
# * gravity is not included (the paper does not mention it; 1-3 % of the load for a metal beam).
#
# Run: ``mpirun -n 2 python3 demos/demo_beam_rigid_base.py [--cases 1 4] [PETSc options]``;
# every SNES/KSP/PC option takes the prefix ``rc_``.

from __future__ import annotations

import argparse

from _common import (DOF_THRESHOLD_HELP, add_law_auto_arguments, law_auto_options,
                     parse_known, start)

TABLE4_CASES = [1, 2, 3, 4, 5, 6]  # m00 = 0.625, 0.3125, 0.0625 um^2; elastic, elasto-plastic


def parse_args(argv):
    """Scene knobs; everything argparse does not know goes to PETSc (prefix rc_)."""
    parser = argparse.ArgumentParser(
        description="Beam on a rigid base across a rough interface (Buczkowski & Kleiber 2009, "
                    "section 9.1, Table 4). Unknown options go to PETSc (prefix rc_).",
        allow_abbrev=False)
    parser.add_argument("--cases", type=int, nargs="+", default=TABLE4_CASES,
                        choices=TABLE4_CASES, help="Table 4 cases to run (1-3 elastic, 4-6 "
                        "elasto-plastic; m00 = 0.625, 0.3125, 0.0625 um^2)")
    parser.add_argument("--mesh-size", type=float, default=40.0,
                        help="element size away from the contact [mm]")
    parser.add_argument("--contact-size", type=float, default=5.0,
                        help="element size on the contact face [mm]")
    parser.add_argument("--order", type=int, default=2, choices=[1, 2])
    parser.add_argument("--load-half-length", type=float, default=5.0,
                        help="half length of the loaded strip on the top face [mm]")
    parser.add_argument("--steps", type=int, default=16, help="load increments after the "
                        "initial load")
    parser.add_argument("--tangential", default="mindlin", choices=["mindlin", "0.7"],
                        help="kT/kN: Mindlin's ratio (96) for this surface, or 0.7 on both axes")
    parser.add_argument("--friction", default="b", choices=["b", "a", "none"],
                        help="friction data: section 9.2 case (b) (default) or (a), or "
                        "frictionless")
    parser.add_argument("--hardness", default="psi", choices=["psi", "tabor"],
                        help="elasto-plastic asperity hardness: from psi = 0.35 (default) or "
                        "H = Y/0.354")
    add_law_auto_arguments(parser, ["table4"], "table4", "normal law: each case's own "
                           "(Table 4)", "OUTDIR/caseN/advice.txt, advice.json")
    parser.add_argument("--outdir", default="results/beam")
    parser.add_argument("--figdir", default=None, help="also copy the figures here "
                        "(e.g. docs/figures)")
    parser.add_argument("--fig-suffix", default="", help="appended to the figure file names")
    parser.add_argument("--dof-threshold", type=int, default=None, help=DOF_THRESHOLD_HELP)
    parser.add_argument("--no-xdmf", action="store_true", help="write no XDMF/point clouds")
    return parse_known(parser, argv)


if __name__ == "__main__":
    # PETSc must see its command-line options before dolfinx is imported (the library imports it)
    args = start(parse_args)
    # The scene, laws, set-up, deflection extraction and figures live in the library
    # (rough_contact/scenes/beam.py): build_scene -> BeamScene, build_case -> BeamCase,
    # run_case (one Table 4 case), run (the chosen cases, the table and the figures).
    from rough_contact.scenes.beam import run

    run(cases=args.cases, mesh_size=args.mesh_size, contact_size=args.contact_size,
        order=args.order, load_half_length=args.load_half_length, steps=args.steps,
        tangential=args.tangential, friction=args.friction, hardness=args.hardness,
        outdir=args.outdir, figdir=args.figdir, fig_suffix=args.fig_suffix,
        dof_threshold=args.dof_threshold, xdmf=not args.no_xdmf, overwrite=True, law=args.law,
        **law_auto_options(args))

