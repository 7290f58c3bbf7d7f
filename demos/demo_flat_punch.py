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
import logging
import os
import sys


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
    parser.add_argument("--law", default="rough", choices=["rough", "penalty"])
    parser.add_argument("--case", default="b", choices=["a", "b", "c", "none"],
                        help="friction case of Fig 18")
    parser.add_argument("--normal-law", default="elasto-plastic",
                        choices=["elastic", "elasto-plastic"],
                        help="asperity population of the normal law (elasto-plastic: Y, psi, ch, "
                        "omega_p/omega_c of Figs 18-19)")
    parser.add_argument("--outdir", default="results/flat_punch")
    parser.add_argument("--dof-threshold", type=int, default=100_000,
                        help="above this many DOFs the default solver is GAMG+GMRES, else MUMPS")
    args, rest = parser.parse_known_args(argv)
    # PETSc options have one dash; a double-dash leftover is a mistyped option of this script.
    bad = [a for a in rest if a.startswith("--")]
    if bad:
        parser.error(f"unrecognized arguments: {' '.join(bad)}")
    return args, rest


import petsc4py  # noqa: E402

# PETSc must see its command-line options before dolfinx is imported.
if __name__ == "__main__":
    ARGS, PETSC_ARGS = parse_args(sys.argv[1:])
    petsc4py.init([sys.argv[0]] + PETSC_ARGS)
else:
    petsc4py.init()

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from dolfinx import fem  # noqa: E402

from meshes.flat_punch import flat_punch  # noqa: E402
from rough_contact.fem.contact import ContactInterface  # noqa: E402
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad  # noqa: E402
from rough_contact.solver.loading import load_path, load_unload_factors  # noqa: E402
from rough_contact.solver.output import ResultWriter, gather_points  # noqa: E402
from rough_contact.solver.snes import SNESSolver  # noqa: E402

# Silence the INFO lines of the JIT compiler (setuptools resets the root logger's level).
logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

# ## Parameters of the paper
E, NU = 2.0e5, 0.25  # both bodies [MPa], [-]
TOTAL_FORCE = 1000.0  # full punch [N]; the quarter model carries a quarter
MOMENTS_UM = dict(m00=0.625, m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)  # paper's um units
# Fig 18 friction cases: (mu_m, mu_o ratio, potential axes nu, kT/kN per axis)
FRICTION_CASES = {
    "a": dict(mu_macro=(0.2, 0.2), mu_initial_ratio=(1.0, 1.0), nu=(0.125, 0.125), kt=(0.7, 0.7)),
    "b": dict(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5), nu=(0.125, 0.125), kt=(0.7, 0.7)),
    "c": dict(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5), nu=(0.125, 0.125), kt=(0.7, 1.0)),
}
HARDENING = (275.0, 275.0)  # n_x, n_y [1/mm]
# Table 5: total frictional dissipation D [N mm] for cases (a), (b), (c)
TABLE5 = {"21-node": {"a": 0.2478, "b": 0.2540, "c": 0.0150},
          "28-node": {"a": 0.2114, "b": 0.1868, "c": 0.0162}}
# Elasto-plastic asperity data of Figs 18-19 (used with --normal-law elasto-plastic)
PLASTIC = dict(Y=2070.0, K_Y=1.62, psi=0.35, ch=0.967, omega_p_ratio=45.0)


def effective_modulus(E1, nu1, E2, nu2):
    """E* of eq (42): 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 [MPa]."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


# ## Interface law
#
# The normal law is tabulated once from the population sums (rank 0 builds it, the others get a
# copy); the friction law is the orthotropic slip-hardening model with Mindlin-type tangential
# stiffness kT = c kN.  ``law="penalty"`` gives a smooth unilateral penalty with Coulomb friction
# instead (a stand-in for debugging the FE layer).
def make_law(comm, law="rough", case="b", normal_law="elastic", seating_pressure=None,
             normal=None):
    """Interface law and its normal law; ``normal`` (a prebuilt NormalLaw) skips the build."""
    from rough_contact.interface.friction import OrthotropicSlipHardening
    from rough_contact.interface.law import InterfaceLaw
    from rough_contact.interface.penalty import SoftplusPenalty
    from rough_contact.interface.tangential import TangentialStiffness

    if law == "penalty":
        return SoftplusPenalty(k_normal=1e5, width=1e-4, k_tangential=7e4, friction=0.5), None
    if law != "rough":
        raise ValueError(f"law = {law!r} is invalid; valid values: 'rough', 'penalty'")
    if case not in FRICTION_CASES and case != "none":
        raise ValueError(f"friction case = {case!r} is invalid; valid: a, b, c, none")
    if normal_law not in ("elastic", "elasto-plastic"):  # checked on every rank: no hang
        raise ValueError(f"normal_law = {normal_law!r} is invalid; valid values: "
                         "'elastic', 'elasto-plastic'")
    if normal is None:
        if comm.rank == 0:  # the table is built once and copied to the other ranks
            from rough_contact.asperity import AsperityMaterial
            from rough_contact.interface.normal import NormalLaw
            from rough_contact.surface import SpectralMoments

            surface = SpectralMoments(**MOMENTS_UM, unit="um")
            E_star = effective_modulus(E, NU, E, NU)
            if normal_law == "elastic":
                normal = NormalLaw.elastic(surface, E_star)
            else:
                normal = NormalLaw.elasto_plastic(
                    surface, AsperityMaterial(E_star=E_star, nu=NU, **PLASTIC))
        normal = comm.bcast(normal, root=0)
    if case == "none":
        rough = InterfaceLaw(normal=normal)
    else:
        c = FRICTION_CASES[case]
        friction = OrthotropicSlipHardening(mu_macro=c["mu_macro"],
                                            mu_initial_ratio=c["mu_initial_ratio"],
                                            hardening=HARDENING, potential_axes=c["nu"])
        rough = InterfaceLaw(normal=normal, tangential=TangentialStiffness(c["kt"]),
                             friction=friction)
    return rough.with_seating(seating_pressure), normal


# ## Scene, spaces, conditions, problem
def build(comm=MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.0, order=2, load_half_width=2.5,
          law="rough", case="b", normal_law="elasto-plastic", steps=16, prefix="rc_",
          dof_threshold=100_000, quadrature_degree=None, normal=None, seating_steps=None,
          cell_type="tetrahedron"):
    """Mesh, law, interface, problem and solver of the quarter punch. Collective.

    ``normal`` passes a prebuilt NormalLaw (same on every rank); ``seating_steps`` (default
    ``steps``) sets the seating pressure to the nominal pressure of 1/seating_steps of the load.

    Returns:
        dict with keys scene, V, law, normal, interface, problem, solver, quarter_force.
    """
    scene = flat_punch(mesh_size=mesh_size, contact_size=contact_size, order=order,
                       load_half_width=load_half_width, cell_type=cell_type, comm=comm)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", order))
    fdim = scene.mesh.topology.dim - 1

    def dofs(name, comp=None):
        facets = scene.facet_tags.find(scene.tag(name))
        if comp is None:
            return fem.locate_dofs_topological(V, fdim, facets)
        return fem.locate_dofs_topological(V.sub(comp), fdim, facets)

    zero = PETSc.ScalarType(0.0)
    bcs = [fem.dirichletbc(zero, dofs("symmetry_x", 0), V.sub(0)),
           fem.dirichletbc(zero, dofs("symmetry_y", 1), V.sub(1)),
           fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), dofs("fixed"), V)]

    quarter_force = TOTAL_FORCE / 4.0
    contact_area = scene.dimensions["half_width"] ** 2
    # Seat the rough surfaces with the nominal pressure of the first increment.
    p_seat = quarter_force / (seating_steps or steps) / contact_area
    interface_law, normal = make_law(comm, law, case, normal_law, seating_pressure=p_seat,
                                     normal=normal)

    first, second = scene.contact_pair
    qdeg = quadrature_degree if quadrature_degree is not None else 2 * order
    interface = ContactInterface(V, scene.facet_tags, first, second, law=interface_law,
                                 grain_direction=(1.0, 0.0, 0.0), quadrature_degree=qdeg, bcs=bcs)
    materials = {scene.tag("punch"): Material(E, NU), scene.tag("foundation"): Material(E, NU)}
    loads = [SurfaceLoad(scene.tag("load"), force=[0.0, 0.0, -quarter_force])]
    problem = ContactProblem(V, materials, bcs, loads, cell_tags=scene.cell_tags,
                             facet_tags=scene.facet_tags, interface=interface,
                             seating_tag=first, seating_stiffness=1e3)
    problem.body_cells = [scene.cell_tags.find(scene.tag(b)) for b in scene.bodies]
    solver = SNESSolver(problem, prefix=prefix, dof_threshold=dof_threshold)
    return dict(scene=scene, V=V, law=interface_law, normal=normal, interface=interface,
                problem=problem, solver=solver, quarter_force=quarter_force)


# ## Output helpers
def point_data(interface):
    """Interface fields at this rank's points, slips turned into global (x, y) components.

    For the flat punch the first surface is the punch bottom: n = -z, x = grain = +x and
    y = n x x = -y, so a local (s_x, s_y) is the global (s_x, -s_y).
    """
    pf = interface.point_fields()
    flip = np.array([1.0, -1.0])
    return interface.point_coordinates(), {
        "pressure_MPa": pf.pressure,
        "area_fraction": pf.area_fraction,
        "gap_mm": pf.gap,
        "slip_mm": pf.slip * flip,
        "plastic_slip_mm": pf.plastic_slip * flip,
        "dissipation_N_per_mm": pf.dissipation,
        "contact": pf.contact.astype(float),
        "slipping": pf.slipping.astype(float),
    }


def plot_slip_directions(comm, interface, path, title, n_grid=12):
    """Quiver of the plastic slip directions at contact points (Figs 18-19). Collective."""
    pts, fields = gather_points(comm, *point_data(interface))
    if comm.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.spatial import cKDTree

    # Sample a regular n_grid x n_grid set of points over the patch (the paper plots nodes).
    a = float(np.max(pts[:, 0]))
    g = (np.arange(n_grid) + 0.5) * a / n_grid
    gx, gy = np.meshgrid(g, g)
    _, idx = cKDTree(pts[:, :2]).query(np.column_stack([gx.ravel(), gy.ravel()]))
    idx = np.unique(idx)
    sp = fields["plastic_slip_mm"][idx]
    mag = np.linalg.norm(sp, axis=1)
    unit = np.where(mag[:, None] > 0, sp / np.maximum(mag, 1e-300)[:, None], 0.0)
    fig, ax = plt.subplots(figsize=(6, 5.4))
    q = ax.quiver(pts[idx, 0], pts[idx, 1], unit[:, 0], unit[:, 1], mag * 1e3, cmap="viridis",
                  pivot="tail", scale=n_grid * 1.3, scale_units="width")
    fig.colorbar(q, ax=ax, label="|plastic slip| [um]")
    ax.set_xlim(0, a * 1.05)
    ax.set_ylim(0, a * 1.05)
    ax.set_aspect("equal")
    ax.set_xlabel("x (grain direction) [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title + "\n(plastic part of u_foundation - u_punch, local x/y turned to global)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


# ## The run
def main(mesh_size=20.0, contact_size=2.0, order=2, load_half_width=2.5, steps=16,
         unload=True, law="rough", case="b", normal_law="elasto-plastic", outdir="results/flat_punch",
         prefix="rc_", dof_threshold=100_000, comm=MPI.COMM_WORLD, verbose=True, plot=True):
    """Run the punch; return a dict of results (identical on every rank). Collective."""
    t0 = MPI.Wtime()
    m = build(comm, mesh_size, contact_size, order, load_half_width, law, case, normal_law,
              steps, prefix, dof_threshold)
    problem, solver, interface = m["problem"], m["solver"], m["interface"]
    n_points = interface.n_points_global
    PETSc.Sys.Print(f"Flat punch (quarter): {problem.num_dofs} DOFs, {n_points} interface points, "
                    f"P{order}, law={law} ({normal_law}, friction case {case}), "
                    f"h0 = {getattr(m['law'], 'h0', float('nan')) * 1e3:.4f} um, "
                    f"linear solver {solver.linear_solver}, {comm.size} rank(s)", comm=comm)

    factors = load_unload_factors(steps, steps - 1 if unload else 0)
    writer = ResultWriter(outdir, comm, u=problem.u,
                          point_data=lambda: point_data(interface),
                          extra_columns=("force_error_rel",))
    history = []
    peak = None
    for inc in load_path(problem, solver, factors, verbose=verbose):
        # Force balance: the normal interface force on the punch equals the applied load (its
        # tangential resultant is carried by the symmetry planes of the quarter model).
        err = abs(inc.contact_force[2] + inc.applied_force[2]) / abs(inc.applied_force[2])
        writer.write(inc, extra={"force_error_rel": err})
        history.append(inc)
        if inc.load_factor == 1.0 and inc.target == 1.0:
            peak = inc
            if plot:
                plot_slip_directions(comm, interface, os.path.join(outdir, "slip_directions_peak.png"),
                                     f"plastic slip directions at 1000 N (case {case})")
    if plot:
        plot_slip_directions(comm, interface, os.path.join(outdir, "slip_directions.png"),
                             f"plastic slip directions after unloading (case {case})")

    # ## Check and comparison with the paper
    D = interface.dissipation()
    max_force_error = max(abs(i.contact_force[2] + i.applied_force[2]) / abs(i.applied_force[2])
                          for i in history)
    PETSc.Sys.Print(f"\nForce balance: max |Fz_contact + Fz_applied| / |Fz_applied| = "
                    f"{max_force_error:.2e} over {len(history)} increments", comm=comm)
    if case in FRICTION_CASES and law == "rough":
        PETSc.Sys.Print(f"Total frictional dissipation D (quarter model, all contact points): "
                        f"{D:.4g} N mm  [paper Table 5, case ({case}): "
                        f"{TABLE5['21-node'][case]} (21-node), {TABLE5['28-node'][case]} (28-node)]",
                        comm=comm)
    else:
        PETSc.Sys.Print(f"Total frictional dissipation D: {D:.4g} N mm", comm=comm)
    PETSc.Sys.Print(f"Output in {outdir}/ (displacement.xdmf, interface.xdmf, history.csv, "
                    f"slip_directions*.png); wall time {MPI.Wtime() - t0:.1f} s", comm=comm)
    assert max_force_error < 1e-6, f"force balance violated: {max_force_error:.3e}"
    solver.destroy()
    return dict(dissipation=D, history=history, peak=peak, num_dofs=problem.num_dofs,
                n_points=n_points, max_force_error=max_force_error)


if __name__ == "__main__":
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    args = ARGS
    main(mesh_size=args.mesh_size, contact_size=args.contact_size, order=args.order,
         load_half_width=args.load_half_width, steps=args.steps, unload=not args.no_unload,
         law=args.law, case=args.case, normal_law=args.normal_law, outdir=args.outdir,
         dof_threshold=args.dof_threshold)
