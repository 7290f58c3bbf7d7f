# # Flat punch on an elastic foundation across a rough, orthotropic-frictional interface
#
# This demo reproduces section 9.2 of Buczkowski & Kleiber (2009): a flat-ended square punch
# (20 x 20 x 10 mm) pressed into an elastic foundation (100 x 100 x 50 mm), E = 200 GPa and
# nu = 0.25 for both, loaded with a total force of 1000 N in sixteen increments, then unloaded.
# The interface is a rough surface with the spectral moments of the paper (Figs 18-19):
#
#     m00 = 0.625 um^2, m20 = 8e-5, m02 = 8e-4, m40 = 1.04e-6 um^-2, m04 = 1.04e-4 um^-2,
#
# whose statistical asperity model gives the normal pressure p(h) as a function of the
# separation h of the mean planes, and the orthotropic slip-hardening friction of the paper,
# case (b) of Fig 18 by default:
#
#     mu_mx = mu_my = 0.5, mu_ox = mu_oy = 0.5, nu_x = nu_y = 0.125, kTx = kTy = 0.7 kN,
#     n_x = n_y = 275 /mm.
#
# Units: mm, N, MPa.  Only a quarter is modelled (symmetry planes x = 0 and y = 0); the quarter
# carries 250 N.  The load acts on a central square of the punch top (half-width 2.5 mm in the
# quarter, the paper's "one element in the middle of the punch").
#
# What is solved, at every load factor lam:
#
#     find u:  int_Omega sigma(u) : eps(v) dx + int_Gamma t(B u) . B v dA = lam int_load f . v ds
#
# with t the interface traction from the law (energy-conjugate to the jump [g, s_x, s_y] of the
# displacement across the interface, in local axes n, x, y), solved by Newton (PETSc SNES) with
# the consistent tangent.  The rough surfaces are first *seated*: the reference separation h0 at
# zero gap carries the nominal pressure of the first load increment, h = h0 + g.
#
# Discretisation defaults (benchmarks/accuracy_vs_cost.py, docs/accuracy_vs_cost.md): P2
# tetrahedra, 20 mm element size away from the contact and 2 mm on it: the normal displacement
# across the rough layer within 0.03 % and the pressure distribution within 0.34 % of P2 at
# 10/1 mm. The dissipation carries a first-order load-path error of about 3 % at the paper's 16
# increments (1.5 % at 32, 0.8 % at 64: ``--steps 64`` for 1 %), and is mesh-sensitive.
#
# Run: ``mpirun -n 2 python3 demos/demo_flat_punch.py [--mesh-size ...] [PETSc options]``;
# every SNES/KSP/PC option takes the prefix ``rc_``, e.g. ``-rc_snes_monitor``.
#
# The quantity checked against the paper is the total frictional dissipation D = sum t_T . du_p
# over the contact points (Table 5); the plot shows the directions of the tangential plastic
# displacements at the contact points (Figs 18-19).

from __future__ import annotations

import argparse

from _common import (DOF_THRESHOLD_HELP, add_law_auto_arguments, law_auto_options,
                     parse_known, start)


def parse_args(argv):
    """Scene knobs; everything argparse does not know goes to PETSc (prefix rc_)."""
    parser = argparse.ArgumentParser(description="Flat punch on a foundation, rough interface "
                                     "(Buczkowski & Kleiber 2009, section 9.2). Unknown options "
                                     "go to PETSc (prefix rc_).", allow_abbrev=False)
    parser.add_argument("--mesh-size", type=float, default=20.0, help="element size away from "
                        "the contact [mm]")
    parser.add_argument("--contact-size", type=float, default=2.0, help="element size on the "
                        "contact patch [mm]")
    parser.add_argument("--order", type=int, default=2, choices=[1, 2])
    parser.add_argument("--load-half-width", type=float, default=2.5,
                        help="half-width of the central load patch on the punch top [mm]")
    parser.add_argument("--steps", type=int, default=16, help="loading increments")
    parser.add_argument("--no-unload", action="store_true")
    add_law_auto_arguments(parser, ["rough", "penalty"], "rough", "rough (the --normal-law "
                           "given), a penalty stand-in", "OUTDIR/advice.txt, advice.json")
    parser.add_argument("--case", default="b", choices=["a", "b", "c", "none"],
                        help="friction case of Fig 18")
    parser.add_argument("--normal-law", default="elasto-plastic",
                        choices=["elastic", "elasto-plastic", "elastic-memory",
                                 "elasto-plastic-memory"],
                        help="asperity population of the normal law (elasto-plastic: Y, psi, ch, "
                        "omega_p/omega_c of Figs 18-19); '-memory': the irreversible law that "
                        "remembers the smallest separation (docs/unloading.md)")
    parser.add_argument("--outdir", default="results/flat_punch")
    parser.add_argument("--checkpoint", default=None, metavar="DIR",
                        help="write a checkpoint after every converged increment into DIR")
    parser.add_argument("--restart", default=None, metavar="DIR",
                        help="continue a stopped run from its checkpoint DIR (same options and "
                             "number of ranks)")
    parser.add_argument("--stop-after", type=int, default=None, metavar="N",
                        help="stop after N increments (their checkpoint written: use with "
                             "--checkpoint, continue with --restart)")
    parser.add_argument("--validity", default="warn", choices=["warn", "error", "ignore"],
                        help="interface points beyond the normal law's validity in a converged "
                             "increment: warn (default), stop with an error, or only count them")
    parser.add_argument("--dof-threshold", type=int, default=None, help=DOF_THRESHOLD_HELP)
    return parse_known(parser, argv)


if __name__ == "__main__":
    # PETSc must see its command-line options before dolfinx is imported (the library imports it)
    args = start(parse_args)
    # The scene, its laws, the set-up and the load stepping live in the library
    # (rough_contact/scenes/flat_punch.py reads top to bottom as what is solved):
    #   build(...) -> PunchModel(scene, V, law, normal, interface, problem, solver)
    #   run(...)   -> load path 1000 N in `steps` increments and back, output, force-balance check
    from rough_contact.scenes.flat_punch import run

    run(mesh_size=args.mesh_size, contact_size=args.contact_size, order=args.order,
        load_half_width=args.load_half_width, steps=args.steps, unload=not args.no_unload,
        law=args.law, case=args.case, normal_law=args.normal_law, outdir=args.outdir,
        dof_threshold=args.dof_threshold, overwrite=True, validity=args.validity,
        checkpoint=args.checkpoint, restart=args.restart, stop_after=args.stop_after,
        **law_auto_options(args))

