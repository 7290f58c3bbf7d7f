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
import logging
import os
import sys

CASES = {  # Table 4: case -> (m00 [um^2], normal law)
    1: (0.6250, "elastic"), 2: (0.3125, "elastic"), 3: (0.0625, "elastic"),
    4: (0.6250, "elasto-plastic"), 5: (0.3125, "elasto-plastic"), 6: (0.0625, "elasto-plastic"),
}
# Table 4 of the paper: (uN at the centre, uN at the end) [um]
TABLE4 = {1: (-1.261, +0.153), 2: (-1.023, +0.316), 3: (-0.577, +0.556),
          4: (-1.744, -0.212), 5: (-1.162, +0.214), 6: (-0.595, +0.551)}


def parse_args(argv):
    """Scene knobs; everything argparse does not know goes to PETSc (prefix rc_)."""
    parser = argparse.ArgumentParser(
        description="Beam on a rigid base across a rough interface (Buczkowski & Kleiber 2009, "
                    "section 9.1, Table 4). Unknown options go to PETSc (prefix rc_).",
        allow_abbrev=False)
    parser.add_argument("--cases", type=int, nargs="+", default=sorted(CASES),
                        choices=sorted(CASES), help="Table 4 cases to run (1-3 elastic, 4-6 "
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
    parser.add_argument("--outdir", default="results/beam")
    parser.add_argument("--figdir", default=None, help="also copy the figures here "
                        "(e.g. docs/figures)")
    parser.add_argument("--fig-suffix", default="", help="appended to the figure file names")
    parser.add_argument("--dof-threshold", type=int, default=200_000,
                        help="above this many DOFs the default solver is GAMG+CG, else MUMPS")
    parser.add_argument("--no-xdmf", action="store_true", help="write no XDMF/point clouds")
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

from meshes.beam import beam_on_base  # noqa: E402
from rough_contact.fem.contact import ContactInterface  # noqa: E402
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad  # noqa: E402
from rough_contact.solver.loading import load_path  # noqa: E402
from rough_contact.solver.output import ResultWriter, atomic_write_text, gather_points  # noqa: E402
from rough_contact.solver.snes import SNESSolver  # noqa: E402

# Silence the INFO lines of the JIT compiler (setuptools resets the root logger's level).
logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

# ## Parameters of the paper
E1, NU1 = 1.057e5, 0.25  # beam [MPa], [-]
E_STAR = E1 / (1.0 - NU1**2)  # rigid base: E* = plane-strain modulus of the beam, 1.127e5 MPa
TOTAL_FORCE = 1962.0  # full beam [N]; the half model carries half
INITIAL_FORCE = 4.9  # full beam [N]
MOMENTS_UM = dict(m20=8e-5, m02=8e-4, m40=1.04e-6, m04=1.04e-4)  # paper's um units
PLASTIC = dict(Y=2070.0, K_Y=1.62, psi=0.35, ch=0.967, omega_p_ratio=45.0)
# Hardness of the elasto-plastic asperities: "psi" (default) = the paper's plasticity index
# psi = 0.35, H = sqrt(sigma kappa_m) E*/psi (about 24 GPa for m00 = 0.625 um^2, far above the
# first-yield pressure K_Y Y = 3.35 GPa); "tabor" = H = Y/0.354 = 5.85 GPa from Y (psi derived).
HARDNESS = ("psi", "tabor")
# Friction: the paper's slip-hardening model with the data of its section 9.2 (same surface):
# "b" (default): mu from 0.25 to 0.5 with slip hardening; "a": constant mu = 0.2;
# "none": frictionless (no tangential traction; the rigid motion along x is then removed by
# u_x = 0 at the contact-face nodes on the mid-plane x = 0, exact by symmetry).
FRICTION = {
    "b": dict(mu_macro=(0.5, 0.5), mu_initial_ratio=(0.5, 0.5), hardening=(275.0, 275.0),
              potential_axes=(0.125, 0.125)),
    "a": dict(mu_macro=(0.2, 0.2), mu_initial_ratio=(1.0, 1.0), hardening=(275.0, 275.0),
              potential_axes=(0.125, 0.125)),
}
GRAIN = (0.0, 1.0, 0.0)  # grinding direction (local x of the law) along the beam axis


# ## Interface law
#
# The normal law is tabulated once from the population sums on rank 0 and broadcast; the
# elasto-plastic table takes ~15 s, the elastic one ~1 s.
def make_normal_law(comm, m00, normal_law, hardness="psi"):
    """NormalLaw of Table 4's surface with variance m00 [um^2]. Collective."""
    normal = None
    if hardness not in HARDNESS:
        raise ValueError(f"hardness = {hardness!r} is invalid; valid values: {HARDNESS}")
    if normal_law not in ("elastic", "elasto-plastic"):
        raise ValueError(f"normal_law = {normal_law!r} is invalid; valid values: 'elastic', "
                         "'elasto-plastic'")
    if comm.rank == 0:
        from rough_contact.interface.normal import NormalLaw
        from rough_contact.surface import SpectralMoments

        surface = SpectralMoments(m00=m00, **MOMENTS_UM, unit="um")
        if normal_law == "elastic":
            normal = NormalLaw.elastic(surface, E_STAR)
        else:
            from rough_contact.asperity import AsperityMaterial

            data = dict(PLASTIC)
            if hardness == "tabor":
                data.pop("psi")
            normal = NormalLaw.elasto_plastic(
                surface, AsperityMaterial(E_star=E_STAR, nu=NU1, **data))
    return comm.bcast(normal, root=0)


def make_law(normal, m00, seating_pressure, tangential="mindlin", friction="b"):
    """Interface law: normal law + tangential stiffness (96) + slip-hardening friction."""
    from rough_contact.interface.friction import OrthotropicSlipHardening
    from rough_contact.interface.law import InterfaceLaw
    from rough_contact.interface.tangential import TangentialStiffness
    from rough_contact.surface import SpectralMoments

    if friction == "none":
        return InterfaceLaw(normal=normal).with_seating(seating_pressure)
    if friction not in FRICTION:
        raise ValueError(f"friction = {friction!r} is invalid; valid values: 'a', 'b', 'none'")
    if tangential == "mindlin":
        kt = TangentialStiffness.from_surface(SpectralMoments(m00=m00, **MOMENTS_UM, unit="um"),
                                              NU1)
    elif tangential == "0.7":
        kt = TangentialStiffness((0.7, 0.7))
    else:
        raise ValueError(f"tangential = {tangential!r} is invalid; valid values: 'mindlin', '0.7'")
    law = InterfaceLaw(normal=normal, tangential=kt,
                       friction=OrthotropicSlipHardening(**FRICTION[friction]))
    return law.with_seating(seating_pressure)


# ## Scene, spaces, conditions
def build_scene(comm=MPI.COMM_WORLD, mesh_size=40.0, contact_size=5.0, order=2,
                load_half_length=5.0):
    """Half beam mesh, space and the symmetry condition (shared by all cases). Collective."""
    scene = beam_on_base(mesh_size=mesh_size, contact_size=contact_size, order=order,
                         load_half_length=load_half_length, comm=comm)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", order))
    fdim = scene.mesh.topology.dim - 1
    sym = fem.locate_dofs_topological(V.sub(1), fdim,
                                      scene.facet_tags.find(scene.tag("symmetry_y")))
    bcs = [fem.dirichletbc(PETSc.ScalarType(0.0), sym, V.sub(1))]
    # u_x = 0 at the contact-face nodes on the mid-plane x = 0 (used by the frictionless
    # variant only; exact by the symmetry of the problem about x = 0).
    tol = 1e-6 * scene.dimensions["height"]
    V0, _ = V.sub(0).collapse()
    mid = fem.locate_dofs_geometrical(
        (V.sub(0), V0), lambda x: (np.abs(x[0]) < tol) & (np.abs(x[2]) < tol))
    n_mid = comm.allreduce(len(mid[0]), op=MPI.SUM)
    bc_mid = fem.dirichletbc(PETSc.ScalarType(0.0), mid[0], V.sub(0))
    # Contact-face nodes (owned): coordinates and z-DOF indices, for the deflection profile.
    imap = V.dofmap.index_map
    cdofs = fem.locate_dofs_topological(V, fdim, scene.facet_tags.find(scene.tag("contact_beam")))
    cdofs = cdofs[cdofs < imap.size_local]
    return dict(scene=scene, V=V, bcs=bcs, bc_mid=bc_mid, n_mid=n_mid, contact_nodes=cdofs,
                contact_x=V.tabulate_dof_coordinates()[cdofs])


def build_case(setup, normal, m00, steps=16, tangential="mindlin", friction="b", prefix="rc_",
               dof_threshold=200_000, beam_modulus=E1):
    """Interface, problem and solver of one Table 4 case on a built scene. Collective."""
    scene, V, bcs = setup["scene"], setup["V"], list(setup["bcs"])
    if friction == "none":
        if setup["n_mid"] == 0:
            raise ValueError("no contact-face node lies on the mid-plane x = 0: the frictionless "
                             "variant needs one to fix u_x; use a smaller contact_size")
        bcs.append(setup["bc_mid"])
    dims = scene.dimensions
    half_force = TOTAL_FORCE / 2.0
    contact_area = dims["width"] * dims["half_length"]
    # Seat the rough surfaces with the nominal pressure of the initial load.
    p_seat = INITIAL_FORCE / 2.0 / contact_area
    law = make_law(normal, m00, p_seat, tangential, friction)
    first, _ = scene.contact_pair
    order = V.ufl_element().degree()
    interface = ContactInterface(V, scene.facet_tags, first, None, law=law,
                                 rigid_plane=scene.rigid_plane, grain_direction=GRAIN,
                                 quadrature_degree=2 * order, bcs=bcs)
    loads = [SurfaceLoad(scene.tag("load"), force=[0.0, 0.0, -half_force])]
    problem = ContactProblem(V, {scene.tag("beam"): Material(beam_modulus, NU1)}, bcs, loads,
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=interface, seating_tag=first, seating_stiffness=1e3)
    problem.body_cells = [scene.cell_tags.find(scene.tag("beam"))]
    solver = SNESSolver(problem, prefix=prefix, dof_threshold=dof_threshold)
    lam0 = INITIAL_FORCE / TOTAL_FORCE
    factors = [lam0] + [lam0 + (1.0 - lam0) * (i + 1) / steps for i in range(steps)]
    return dict(law=law, interface=interface, problem=problem, solver=solver, factors=factors,
                p_seat=p_seat, half_force=half_force)


# ## Deflection along the beam
def contact_uz(setup, u):
    """Vertical displacement of this rank's owned contact-face nodes (n,) [mm].

    On the contact face the interface normal jump is g = u_z (rigid base, n = -z), so
    uN = uz - uz_init.
    """
    return u.x.array[3 * setup["contact_nodes"] + 2].copy()


def deflection_profile(comm, setup, uN_nodes, n_samples=251):
    """Centre-line (x = 0) profile of uN along y, and the centre and end values. Collective.

    The owned contact-face nodes are gathered to rank 0 and sorted (so the result does not
    depend on the partition). Centre and end values are interpolated linearly at x = 0 along
    the face edges y = 0 and y = l/2 (nodes lie exactly on them); the profile uses a linear
    interpolant on the nodes.

    Returns:
        dict (on every rank) with y (n_samples,) [mm], uN (n_samples,) [mm], centre, end [mm],
        centre_mean, end_mean (averages over the width) [mm].
    """
    pts, fields = gather_points(comm, setup["contact_x"], {"uN": uN_nodes})
    out = None
    if comm.rank == 0:
        from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator

        xy = np.round(pts[:, :2], 9)
        order = np.lexsort((xy[:, 0], xy[:, 1]))
        xy, val = xy[order], fields["uN"][order]
        half = setup["scene"].dimensions["half_length"]
        tol = 1e-6 * half

        def edge(y0):
            on = np.abs(xy[:, 1] - y0) < tol
            x, v = xy[on, 0], val[on]
            k = np.argsort(x, kind="stable")
            x, v = x[k], v[k]
            mean = float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(x)) / (x[-1] - x[0]))
            return float(np.interp(0.0, x, v)), mean

        centre, centre_mean = edge(0.0)
        end, end_mean = edge(half)
        y = np.linspace(0.0, half, n_samples)
        q = np.column_stack([np.zeros_like(y), y])
        prof = LinearNDInterpolator(xy, val)(q)
        bad = ~np.isfinite(prof)
        if bad.any():
            prof[bad] = NearestNDInterpolator(xy, val)(q[bad])
        prof[0], prof[-1] = centre, end
        out = dict(y=y, uN=prof, centre=centre, end=end, centre_mean=centre_mean,
                   end_mean=end_mean)
    return comm.bcast(out, root=0)


def point_data(interface, gap_init):
    """Interface fields at this rank's points (for the XDMF point cloud)."""
    pf = interface.point_fields()
    return interface.point_coordinates(), {
        "pressure_MPa": pf.pressure, "area_fraction": pf.area_fraction, "gap_mm": pf.gap,
        "uN_mm": pf.gap - gap_init, "slip_mm": pf.slip, "contact": pf.contact.astype(float),
        "slipping": pf.slipping.astype(float)}


# ## One case
def run_case(comm, setup, case, steps=16, tangential="mindlin", friction="b", hardness="psi",
             outdir="results/beam", prefix="rc_", dof_threshold=200_000, verbose=True, xdmf=True,
             beam_modulus=E1):
    """Load one Table 4 case; return its results. Collective.

    The result dict is identical on every rank except the point arrays ``points_y``,
    ``points_p``, ``points_uN`` (interface quadrature points, sorted by y), present on rank 0
    only. Lengths in mm, pressures in MPa, forces in N.
    """
    t0 = MPI.Wtime()
    m00, normal_law = CASES[case]
    normal = make_normal_law(comm, m00, normal_law, hardness)
    t_law = MPI.Wtime() - t0
    c = build_case(setup, normal, m00, steps, tangential, friction, prefix, dof_threshold,
                   beam_modulus)
    problem, solver, interface = c["problem"], c["solver"], c["interface"]
    kt = None if c["law"].tangential is None else c["law"].tangential.kt_over_kn
    PETSc.Sys.Print(
        f"\nCase {case}: m00 = {m00} um^2, {normal_law}; {problem.num_dofs} DOFs, "
        f"{interface.n_points_global} interface points, h0 = {c['law'].h0 * 1e3:.4f} um "
        f"(p_seat = {c['p_seat']:.3e} MPa), friction {friction}, kT/kN = {kt}, "
        f"{solver.linear_solver}, {comm.size} rank(s); law table {t_law:.1f} s", comm=comm)
    case_dir = os.path.join(outdir, f"case{case}")
    state = {}
    writer = None
    if xdmf:
        writer = ResultWriter(case_dir, comm, u=problem.u,
                              point_data=lambda: point_data(interface, state["gap0"]),
                              extra_columns=("force_error_rel",))
    max_force_error, newton = 0.0, 0
    last = None
    for inc in load_path(problem, solver, c["factors"], verbose=verbose):
        err = abs(inc.contact_force[2] + inc.applied_force[2]) / abs(inc.applied_force[2])
        max_force_error = max(max_force_error, err)
        newton += inc.iterations
        if "uz0" not in state:  # the initial 4.9 N state is the reference of the deflection
            state["uz0"] = contact_uz(setup, problem.u)
            state["gap0"] = interface.point_fields().gap.copy()
        if writer is not None:
            writer.write(inc, extra={"force_error_rel": err})
        last = inc
    uN_nodes = contact_uz(setup, problem.u) - state["uz0"]
    prof = deflection_profile(comm, setup, uN_nodes)

    # separation: interface points that moved apart (uN > 0), unloaded below the seating
    # pressure, or fully open (p == 0, beyond the law's last separation)
    pf = interface.point_fields()
    uN_pts = pf.gap - state["gap0"]
    w = pf.weight

    def area(mask):
        return comm.allreduce(float(w[mask].sum()), op=MPI.SUM)

    nominal = interface.nominal_area()
    y_pts = interface.point_coordinates()[:, 1]
    lifted = uN_pts > 0.0
    y_lift = comm.allreduce(float(y_pts[lifted].min(initial=np.inf)), op=MPI.MIN)
    half = setup["scene"].dimensions["half_length"]
    end_zone = y_pts > half - 5.0
    p_end = comm.allreduce(float(pf.pressure[end_zone].min(initial=np.inf)), op=MPI.MIN)
    p_max = comm.allreduce(float(pf.pressure.max(initial=0.0)), op=MPI.MAX)
    n_open = comm.allreduce(int((~pf.contact).sum()), op=MPI.SUM)
    below = int(comm.allreduce(interface.law.normal.count_below_validity(
        interface.law.h0 + pf.gap), op=MPI.SUM))
    # rigid-beam reference: a uniform pressure F / A0 on the whole face (no bending)
    p_mean = c["half_force"] / nominal
    rigid = float(c["law"].normal.separation_for_pressure(np.array([p_mean]))[0]) - c["law"].h0
    res = dict(case=case, rigid=rigid, m00=m00, normal_law=normal_law, centre=prof["centre"],
               end=prof["end"],
               centre_mean=prof["centre_mean"], end_mean=prof["end_mean"], y=prof["y"],
               profile=prof["uN"], max_force_error=max_force_error, newton=newton,
               steps=last.step if last else 0, contact_force=last.contact_force,
               applied_force=last.applied_force, lifted_area_fraction=area(lifted) / nominal,
               lift_from_y=y_lift, p_end_min=p_end, p_max=p_max, n_open=n_open,
               n_below_validity=below, h0=c["law"].h0, p_seat=c["p_seat"],
               kt_over_kn=kt, friction=friction, hardness=hardness, num_dofs=problem.num_dofs,
               n_points=interface.n_points_global, wall_time=MPI.Wtime() - t0)
    # pressure along the beam for the figure (gathered to rank 0)
    pts, fields = gather_points(comm, interface.point_coordinates(),
                                {"p": pf.pressure, "uN": uN_pts})
    if comm.rank == 0:
        k = np.lexsort((pts[:, 0], pts[:, 1]))
        res["points_y"], res["points_p"], res["points_uN"] = (pts[k, 1], fields["p"][k],
                                                             fields["uN"][k])
    paper = TABLE4[case]
    PETSc.Sys.Print(
        f"Case {case}: uN centre = {res['centre'] * 1e3:+.3f} um (paper {paper[0]:+.3f}), "
        f"end = {res['end'] * 1e3:+.3f} um (paper {paper[1]:+.3f}); force balance "
        f"{max_force_error:.1e}; lifted area {res['lifted_area_fraction'] * 100:.1f} % "
        + (f"(from y = {y_lift:.1f} mm)" if np.isfinite(y_lift) else "(none)")
        + f"; min p at the end {p_end:.3e} MPa "
        f"(seating {c['p_seat']:.3e}); open points {n_open}; {newton} Newton its, "
        f"{res['wall_time']:.1f} s", comm=comm)
    solver.destroy()
    return res


# ## Figures and table
def plot_profiles(results, path):
    """Fig 13 equivalent: uN along the beam for every case run (rank 0 only)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    colors = {0.625: "tab:blue", 0.3125: "tab:orange", 0.0625: "tab:green"}
    markers = {0.625: "s", 0.3125: "x", 0.0625: "^"}  # the paper's symbols
    for r in results:
        ls = "-" if r["normal_law"] == "elastic" else "--"
        col = colors.get(r["m00"], "k")
        ax.plot(r["y"], r["profile"] * 1e3, ls, color=col,
                label=f"m00 = {r['m00']} um$^2$, {r['normal_law']}")
        pc, pe = TABLE4[r["case"]]
        ax.plot([0.0, r["y"][-1]], [pc, pe], markers.get(r["m00"], "o"), color=col,
                mfc="none" if r["normal_law"] != "elastic" else col, ms=8)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("distance from mid-length y [mm]")
    ax.set_ylabel("interface deflection uN [um]  (< 0: approach)")
    r0 = results[0]
    variant = f"friction {r0['friction']}"
    if any(r["normal_law"] != "elastic" for r in results):
        variant += f", e-p hardness from {r0['hardness']}"
    ax.set_title(f"Beam on rigid base: uN at 1962 N relative to the 4.9 N state ({variant})\n"
                 "lines: this code; markers: paper Table 4 (filled elastic, open elasto-plastic)",
                 fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_pressure(results, path):
    """Interface pressure along the beam at 1962 N (rank 0 only)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    for r in results:
        ax.semilogy(r["points_y"], np.maximum(r["points_p"], 1e-12), ".", ms=1.5,
                    label=f"case {r['case']}: m00 = {r['m00']}, {r['normal_law']}")
    ax.axhline(results[0]["p_seat"], color="0.5", ls=":", label="seating pressure (4.9 N)")
    ax.set_xlabel("distance from mid-length y [mm]")
    ax.set_ylabel("contact pressure p [MPa]")
    ax.set_title("Interface pressure at 1962 N (all quadrature points)", fontsize=9)
    ax.legend(fontsize=7, markerscale=6)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def table(results) -> str:
    """Markdown table of the results beside the paper's Table 4."""
    lines = ["| case | m00 [um^2] | normal law | uN centre [um] | paper | uN end [um] | paper "
             "| end - centre [um] | paper | rigid beam [um] | lifted area | force balance |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        pc, pe = TABLE4[r["case"]]
        c, e = r["centre"] * 1e3, r["end"] * 1e3
        lines.append(f"| {r['case']} | {r['m00']} | {r['normal_law']} | {c:+.3f} | {pc:+.3f} "
                     f"| {e:+.3f} | {pe:+.3f} | {e - c:.3f} | {pe - pc:.3f} "
                     f"| {r['rigid'] * 1e3:+.3f} "
                     f"| {r['lifted_area_fraction'] * 100:.1f} % | {r['max_force_error']:.1e} |")
    return "\n".join(lines)


# ## The run
def main(cases=tuple(sorted(CASES)), mesh_size=40.0, contact_size=5.0, order=2,
         load_half_length=5.0, steps=16, tangential="mindlin", friction="b", hardness="psi",
         outdir="results/beam", figdir=None, fig_suffix="", prefix="rc_", dof_threshold=200_000,
         comm=MPI.COMM_WORLD, verbose=True, plot=True, xdmf=True, beam_modulus=E1):
    """Run the chosen Table 4 cases; return a list of result dicts (same on every rank).

    Args:
        cases: Table 4 case numbers (1-6).
        mesh_size, contact_size: element sizes away from / on the contact face [mm].
        order: 1 or 2 (P1 or P2 tetrahedra).
        load_half_length: half length of the loaded strip on the top face [mm].
        steps: load increments after the initial 4.9 N.
        tangential: "mindlin" (eq 96 for this surface) or "0.7" (kT = 0.7 kN).
        friction: "b" (default; mu 0.25 -> 0.5, slip hardening), "a" (mu = 0.2) or "none"
            (frictionless; u_x = 0 on the mid-plane nodes of the contact face).
        hardness: asperity hardness of the elasto-plastic cases: "psi" (from the paper's
            psi = 0.35) or "tabor" (H = Y/0.354).
        outdir: output directory (per-case XDMF/CSV, summary, figures).
        figdir: if given, the figures are also written there.
        fig_suffix: appended to the figure names (beam_deflection<suffix>.png, ...).
        comm: communicator.
        plot, xdmf: write figures / XDMF output.
        beam_modulus: Young's modulus of the beam's bulk [MPa] (the paper's E1 by default; the
            interface law keeps E* of the paper). A very large value gives the rigid-beam
            limit, a check of the whole chain against the normal law alone.

    Returns:
        list of dicts with keys case, m00, normal_law, centre, end [mm], y, profile [mm],
        max_force_error, lifted_area_fraction, ... (see ``run_case``).
    """
    cases = [int(k) for k in cases]
    bad = [k for k in cases if k not in CASES]
    if bad or not cases:
        raise ValueError(f"cases = {cases!r} is invalid; valid values: 1-6 (Table 4)")
    if hardness not in HARDNESS:
        raise ValueError(f"hardness = {hardness!r} is invalid; valid values: {HARDNESS}")
    if friction not in ("a", "b", "none"):
        raise ValueError(f"friction = {friction!r} is invalid; valid values: 'a', 'b', 'none'")
    if int(steps) != steps or steps < 1:
        raise ValueError(f"steps = {steps!r} must be an integer >= 1")
    t0 = MPI.Wtime()
    setup = build_scene(comm, mesh_size, contact_size, order, load_half_length)
    if comm.rank == 0:
        os.makedirs(outdir, exist_ok=True)
    results = []
    for case in cases:
        results.append(run_case(comm, setup, case, steps, tangential, friction, hardness, outdir,
                                prefix, dof_threshold, verbose, xdmf, beam_modulus))
    text = table(results)
    PETSc.Sys.Print("\n" + text + f"\n\nTotal wall time {MPI.Wtime() - t0:.1f} s on "
                    f"{comm.size} rank(s)", comm=comm)
    if comm.rank == 0:
        atomic_write_text(os.path.join(outdir, "table4.md"), text + "\n")
        # centre-line profiles uN(y) [um], one column per case
        cols = ["y_mm"] + [f"case{r['case']}_uN_um" for r in results]
        rows = np.column_stack([results[0]["y"]] + [r["profile"] * 1e3 for r in results])
        body = "\n".join(",".join(f"{v:.8g}" for v in row) for row in rows)
        atomic_write_text(os.path.join(outdir, "profiles.csv"), ",".join(cols) + "\n" + body + "\n")
        if plot:
            dirs = [outdir] + ([figdir] if figdir else [])
            for d in dirs:
                os.makedirs(d, exist_ok=True)
                plot_profiles(results, os.path.join(d, f"beam_deflection{fig_suffix}.png"))
                plot_pressure(results, os.path.join(d, f"beam_pressure{fig_suffix}.png"))
    for r in results:
        assert r["max_force_error"] < 1e-6, f"force balance violated: {r['max_force_error']:.3e}"
    return results


if __name__ == "__main__":
    from rough_contact.solver.parallel import abort_on_uncaught_exception

    abort_on_uncaught_exception()  # one failing rank must not leave the others waiting
    args = ARGS
    main(cases=args.cases, mesh_size=args.mesh_size, contact_size=args.contact_size,
         order=args.order, load_half_length=args.load_half_length, steps=args.steps,
         tangential=args.tangential, friction=args.friction, hardness=args.hardness,
         outdir=args.outdir, figdir=args.figdir, fig_suffix=args.fig_suffix,
         dof_threshold=args.dof_threshold, xdmf=not args.no_xdmf)
