"""The paper's beam on a rigid base (section 9.1, Table 4, Fig 13): parameters, laws, set-up,
the deflection along the contact face and the standard run of the six Table 4 cases.

An elastic prismatic beam, 10 x 120 x 500 mm, lies with a narrow face (10 x 500 mm) on a flat
rigid base across a rough surface; 1962 N compress it at mid-length after an initial 4.9 N.
Half the beam is modelled (symmetry plane y = 0). The deflection uN is the change of the
interface normal gap from the state after the initial 4.9 N (``docs/beam.md``).

Library code: it never initialises petsc4py and never reads ``sys.argv`` (the entry script
``demos/demo_beam_rigid_base.py`` does). Units: mm, N, MPa (deflections reported in um).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.boundary import fix, fix_where, surface_nodes
from rough_contact.fem.compat import element_degree, vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.mesh import Scene
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.law import InterfaceLaw
from rough_contact.io import ResultWriter, atomic_write_text, gather_points
from rough_contact.scenes.defaults import SEATING_STIFFNESS
from rough_contact.scenes.defaults import quadrature_degree as default_qdeg
from rough_contact.scenes.meshes.beam import beam_on_base
from rough_contact.scenes.setup import check_mesh_arguments
from rough_contact.solver.loading import load_path
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_integer

# Silence the INFO lines of the JIT compiler (setuptools resets the root logger's level).
logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)

CASES = {  # Table 4: case -> (m00 [um^2], normal law)
    1: (0.6250, "elastic"), 2: (0.3125, "elastic"), 3: (0.0625, "elastic"),
    4: (0.6250, "elasto-plastic"), 5: (0.3125, "elasto-plastic"), 6: (0.0625, "elasto-plastic"),
}
# Table 4 of the paper: (uN at the centre, uN at the end) [um]
TABLE4 = {1: (-1.261, +0.153), 2: (-1.023, +0.316), 3: (-0.577, +0.556),
          4: (-1.744, -0.212), 5: (-1.162, +0.214), 6: (-0.595, +0.551)}
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
            from rough_contact.micro.asperity import AsperityMaterial

            data = dict(PLASTIC)
            if hardness == "tabor":
                data.pop("psi")
            normal = NormalLaw.elasto_plastic(
                surface, AsperityMaterial(E_star=E_STAR, nu=NU1, **data))
    return comm.bcast(normal, root=0)


def beam_material(hardness="psi", m00=None):
    """Asperity material of the elasto-plastic cases (caption data, hardness as chosen)."""
    from rough_contact.micro.asperity import AsperityMaterial

    data = dict(PLASTIC)
    if hardness == "tabor":
        data.pop("psi")
    return AsperityMaterial(E_star=E_STAR, nu=NU1, **data)


# Peak over mean nominal pressure on the contact face assumed by the law advisor: the load acts on
# a 10 mm strip at mid-length of a 500 mm beam, whose bending concentrates the pressure there.
PRESSURE_CONCENTRATION = 10.0


def advise_normal_law(comm, m00, hardness="psi", tolerance=0.05, surface=None, material=None,
                      results=None):
    """The law advisor's choice for the beam on Table 4's surface with variance m00 [um^2]
    (nominal pressures from the seating pressure to PRESSURE_CONCENTRATION times the mean of
    the full load) and the advised NormalLaw (rank 0 builds it). Collective.
    ``results``: the FE results held within ``tolerance`` (``rough_contact.advisor.RESULTS_ALL``
    by default: the run reports the frictional dissipation too).

    Returns ``(advice, normal)``, the same on every rank."""
    advice = normal = None
    if comm.rank == 0:
        from rough_contact.advisor import RESULTS_ALL, advise, scene_pressure_range
        from rough_contact.surface import SpectralMoments

        surface = surface or SpectralMoments(m00=m00, **MOMENTS_UM, unit="um")
        material = material or beam_material(hardness)
        area = 10.0 * 250.0          # half model's contact face [mm^2] (meshes/beam: 10 x 500)
        p_range = scene_pressure_range(TOTAL_FORCE / 2.0, area, INITIAL_FORCE / 2.0 / area,
                                       PRESSURE_CONCENTRATION)
        advice = advise(surface, material, p_range, tolerance,
                        results=RESULTS_ALL if results is None else results)
        normal = advice.normal_law()
    return comm.bcast(advice, root=0), comm.bcast(normal, root=0)


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
@dataclass(frozen=True)
class BeamScene:
    """The half beam shared by all Table 4 cases (:func:`build_scene`).

    Attributes:
        scene: mesh, tags and labels.
        V: vector Lagrange space of the displacement.
        bcs: the symmetry condition u_y = 0 on y = 0.
        bc_mid: u_x = 0 at the contact-face nodes on the mid-plane x = 0 (frictionless variant).
        n_mid: global number of such nodes.
        contact_nodes: (n,) owned block indices of the contact-face nodes.
        contact_x: (n, 3) their coordinates [mm].
    """

    scene: Scene
    V: Any
    bcs: list
    bc_mid: object
    n_mid: int
    contact_nodes: np.ndarray
    contact_x: np.ndarray


@dataclass(frozen=True)
class BeamCase:
    """Law, interface, problem and solver of one Table 4 case (:func:`build_case`).

    Attributes:
        law: the seated interface law.
        interface: contact interface against the rigid base.
        problem: bulk elasticity + interface.
        solver: SNES solver.
        factors: load factors: the initial 4.9 N, then ``steps`` increments to 1962 N.
        p_seat: seating pressure [MPa].
        half_force: force on the half model at load factor 1 [N].
    """

    law: InterfaceLaw
    interface: ContactInterface
    problem: ContactProblem
    solver: SNESSolver
    factors: list
    p_seat: float
    half_force: float


def build_scene(comm=MPI.COMM_WORLD, mesh_size=40.0, contact_size=5.0, order=2,
                load_half_length=5.0):
    """Half beam mesh, space and the symmetry condition (shared by all cases). Collective."""
    check_mesh_arguments(order, mesh_size=mesh_size, contact_size=contact_size,
                         load_half_length=load_half_length)
    scene = beam_on_base(mesh_size=mesh_size, contact_size=contact_size, order=order,
                         load_half_length=load_half_length, comm=comm)
    V = vector_space(scene.mesh, order)
    bcs = [fix(V, scene.facet_tags, scene.tag("symmetry_y"), 1)]
    # u_x = 0 at the contact-face nodes on the mid-plane x = 0 (used by the frictionless
    # variant only; exact by the symmetry of the problem about x = 0).
    tol = 1e-6 * scene.dimensions["height"]
    bc_mid, n_mid = fix_where(V, 0, lambda x: (np.abs(x[0]) < tol) & (np.abs(x[2]) < tol))
    # Contact-face nodes (owned): coordinates and block indices, for the deflection profile.
    cdofs, cx = surface_nodes(V, scene.facet_tags, scene.tag("contact_beam"))
    return BeamScene(scene=scene, V=V, bcs=bcs, bc_mid=bc_mid, n_mid=n_mid, contact_nodes=cdofs,
                     contact_x=cx)


def build_case(setup, normal, m00, steps=16, tangential="mindlin", friction="b", prefix="rc_",
               dof_threshold=None, beam_modulus=E1, quadrature_degree=None):
    """Interface, problem and solver of one Table 4 case on a built scene. Collective.

    ``quadrature_degree`` of the facet rule defaults to twice the element order
    (:func:`rough_contact.scenes.defaults.quadrature_degree`).
    """
    scene, V, bcs = setup.scene, setup.V, list(setup.bcs)
    if friction == "none":
        if setup.n_mid == 0:
            raise ValueError("no contact-face node lies on the mid-plane x = 0: the frictionless "
                             "variant needs one to fix u_x; use a smaller contact_size")
        bcs.append(setup.bc_mid)
    dims = scene.dimensions
    half_force = TOTAL_FORCE / 2.0
    contact_area = dims["width"] * dims["half_length"]
    # Seat the rough surfaces with the nominal pressure of the initial load.
    p_seat = INITIAL_FORCE / 2.0 / contact_area
    law = make_law(normal, m00, p_seat, tangential, friction)
    first, _ = scene.contact_pair
    order = element_degree(V)
    interface = ContactInterface(V, scene.facet_tags, first, None, law=law,
                                 rigid_plane=scene.rigid_plane, grain_direction=GRAIN,
                                 quadrature_degree=(default_qdeg(order)
                                                    if quadrature_degree is None
                                                    else quadrature_degree), bcs=bcs)
    loads = [SurfaceLoad(scene.tag("load"), force=[0.0, 0.0, -half_force])]
    problem = ContactProblem(V, {scene.tag("beam"): Material(beam_modulus, NU1)}, bcs, loads,
                             cell_tags=scene.cell_tags, facet_tags=scene.facet_tags,
                             interface=interface, seating_tag=first,
                             seating_stiffness=SEATING_STIFFNESS,
                             body_cells=[scene.cell_tags.find(scene.tag("beam"))])
    solver = SNESSolver(problem, prefix=prefix, dof_threshold=dof_threshold)
    lam0 = INITIAL_FORCE / TOTAL_FORCE
    factors = [lam0] + [lam0 + (1.0 - lam0) * (i + 1) / steps for i in range(steps)]
    return BeamCase(law=law, interface=interface, problem=problem, solver=solver, factors=factors,
                    p_seat=p_seat, half_force=half_force)


@dataclass(frozen=True)
class DeflectionProfile:
    """Centre-line deflection of the contact face (:func:`deflection_profile`).

    Attributes:
        y: (n_samples,) distance from mid-length along the centre line x = 0 [mm].
        uN: (n_samples,) deflection there [mm] (< 0: approach).
        centre, end: uN at x = 0 on the edges y = 0 and y = l/2 [mm].
        centre_mean, end_mean: uN averaged over the width on those edges [mm].
    """

    y: np.ndarray
    uN: np.ndarray
    centre: float
    end: float
    centre_mean: float
    end_mean: float


@dataclass(frozen=True)
class BeamCaseResult:
    """Result of one Table 4 case (:func:`run_case`); identical on every rank except the point
    arrays ``points_*``, present on rank 0 only (``None`` elsewhere).

    Attributes:
        case: Table 4 case number (1-6).
        m00: height variance of the surface [um^2].
        normal_law: "elastic" or "elasto-plastic".
        centre, end: deflection uN at the centre / end of the contact face (x = 0) [mm].
        centre_mean, end_mean: the same averaged over the width [mm].
        y, profile: centre-line profile uN(y) [mm] (:class:`DeflectionProfile`).
        rigid: rigid-beam reference h(F / A0) - h0 of the normal law alone [mm].
        max_force_error: max relative force-balance error over the increments [-].
        newton: Newton iterations of all increments.
        steps: increments solved.
        contact_force, applied_force: (3,) interface and applied force at the end, half
            model [N].
        lifted_area_fraction: nominal area that moved apart (uN > 0) / nominal area [-].
        lift_from_y: smallest y of a lifted interface point [mm] (inf if none).
        p_end_min: smallest pressure within 5 mm of the end [MPa].
        p_max: largest interface pressure [MPa].
        n_open: interface points without contact.
        n_below_validity: interface points below the normal law's validity.
        h0: seated reference separation [mm]; p_seat: seating pressure [MPa].
        kt_over_kn: (kTx/kN, kTy/kN), ``None`` without friction.
        friction, hardness: the variant run.
        num_dofs, n_points: global numbers of DOFs and interface points.
        wall_time: [s].
        points_y, points_p, points_uN: interface points sorted by y: y [mm], pressure [MPa],
            uN [mm] (rank 0).
    """

    case: int
    m00: float
    normal_law: str
    centre: float
    end: float
    centre_mean: float
    end_mean: float
    y: np.ndarray
    profile: np.ndarray
    rigid: float
    max_force_error: float
    newton: int
    steps: int
    contact_force: np.ndarray
    applied_force: np.ndarray
    lifted_area_fraction: float
    lift_from_y: float
    p_end_min: float
    p_max: float
    n_open: int
    n_below_validity: int
    h0: float
    p_seat: float
    kt_over_kn: Optional[tuple]
    friction: str
    hardness: str
    num_dofs: int
    n_points: int
    wall_time: float
    points_y: Optional[np.ndarray] = None
    points_p: Optional[np.ndarray] = None
    points_uN: Optional[np.ndarray] = None


# ## Deflection along the beam
def contact_uz(setup, u):
    """Vertical displacement of this rank's owned contact-face nodes (n,) [mm].

    On the contact face the interface normal jump is g = u_z (rigid base, n = -z), so
    uN = uz - uz_init.
    """
    return u.x.array[3 * setup.contact_nodes + 2].copy()


def deflection_profile(comm, setup, uN_nodes, n_samples=251):
    """Centre-line (x = 0) profile of uN along y, and the centre and end values. Collective.

    The owned contact-face nodes are gathered to rank 0 and sorted (so the result does not
    depend on the partition). Centre and end values are interpolated linearly at x = 0 along
    the face edges y = 0 and y = l/2 (nodes lie exactly on them); the profile uses a linear
    interpolant on the nodes.

    Returns:
        :class:`DeflectionProfile` (on every rank).
    """
    pts, fields = gather_points(comm, setup.contact_x, {"uN": uN_nodes})
    out = None
    if comm.rank == 0:
        from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator

        xy = np.round(pts[:, :2], 9)
        order = np.lexsort((xy[:, 0], xy[:, 1]))
        xy, val = xy[order], fields["uN"][order]
        half = setup.scene.dimensions["half_length"]
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
        out = DeflectionProfile(y=y, uN=prof, centre=centre, end=end, centre_mean=centre_mean,
                                end_mean=end_mean)
    return comm.bcast(out, root=0)


# ## One case
def run_case(comm, setup, case, steps=16, tangential="mindlin", friction="b", hardness="psi",
             outdir="results/beam", prefix="rc_", dof_threshold=None, verbose=True, xdmf=True,
             beam_modulus=E1, overwrite=False, law="table4", tolerance=0.05,
             advise_results=None):
    """Load one Table 4 case; return its :class:`BeamCaseResult`. Collective.

    Identical on every rank except the point arrays ``points_y``, ``points_p``, ``points_uN``
    (interface quadrature points, sorted by y), present on rank 0 only. Lengths in mm,
    pressures in MPa, forces in N. ``law="auto"``: the law advisor picks the case surface's
    normal law (cheapest within ``tolerance`` of the full model in ``advise_results``, of
    ``rough_contact.advisor.RESULTS_ALL``, None: all); its report is printed and written to
    the case's folder (advice.txt, advice.json).
    """
    t0 = MPI.Wtime()
    m00, normal_law = CASES[case]
    if law not in ("table4", "auto"):
        raise ValueError(f"law = {law!r} is invalid; valid values: 'table4', 'auto'")
    if law == "auto":
        advice, normal = advise_normal_law(comm, m00, hardness, tolerance,
                                           results=advise_results)
        PETSc.Sys.Print(f"\nCase {case}: " + advice.report(), comm=comm)
        if comm.rank == 0:
            case_dir = os.path.join(outdir, f"case{case}")
            os.makedirs(case_dir, exist_ok=True)
            atomic_write_text(os.path.join(case_dir, "advice.txt"), advice.report() + "\n")
            atomic_write_text(os.path.join(case_dir, "advice.json"), advice.to_json() + "\n")
        normal_law = advice.normal
    else:
        normal = make_normal_law(comm, m00, normal_law, hardness)
    t_law = MPI.Wtime() - t0
    c = build_case(setup, normal, m00, steps, tangential, friction, prefix, dof_threshold,
                   beam_modulus)
    problem, solver, interface = c.problem, c.solver, c.interface
    kt = None if c.law.tangential is None else c.law.tangential.kt_over_kn
    PETSc.Sys.Print(
        f"\nCase {case}: m00 = {m00} um^2, {normal_law}; {problem.num_dofs} DOFs, "
        f"{interface.n_points_global} interface points, h0 = {c.law.h0 * 1e3:.4f} um "
        f"(p_seat = {c.p_seat:.3e} MPa), friction {friction}, kT/kN = {kt}, "
        f"{solver.linear_solver}, {comm.size} rank(s); law table {t_law:.1f} s", comm=comm)
    case_dir = os.path.join(outdir, f"case{case}")
    state = {}
    writer = None
    if xdmf:
        writer = ResultWriter(case_dir, comm, u=problem.u, interface=interface,
                              extra_columns=("force_error_rel",), overwrite=overwrite)
    max_force_error, newton = 0.0, 0
    last = None
    for inc in load_path(problem, solver, c.factors, verbose=verbose):
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
    half = setup.scene.dimensions["half_length"]
    end_zone = y_pts > half - 5.0
    p_end = comm.allreduce(float(pf.pressure[end_zone].min(initial=np.inf)), op=MPI.MIN)
    p_max = comm.allreduce(float(pf.pressure.max(initial=0.0)), op=MPI.MAX)
    n_open = comm.allreduce(int((~pf.contact).sum()), op=MPI.SUM)
    below = int(comm.allreduce(interface.law.normal.count_below_validity(
        interface.law.h0 + pf.gap), op=MPI.SUM))
    # rigid-beam reference: a uniform pressure F / A0 on the whole face (no bending)
    p_mean = c.half_force / nominal
    rigid = float(c.law.normal.separation_for_pressure(np.array([p_mean]))[0]) - c.law.h0
    # pressure along the beam for the figure (gathered to rank 0)
    pts, fields = gather_points(comm, interface.point_coordinates(),
                                {"p": pf.pressure, "uN": uN_pts})
    on_points = {}
    if comm.rank == 0:
        k = np.lexsort((pts[:, 0], pts[:, 1]))
        on_points = dict(points_y=pts[k, 1], points_p=fields["p"][k], points_uN=fields["uN"][k])
    wall_time = MPI.Wtime() - t0
    res = BeamCaseResult(
        case=case, rigid=rigid, m00=m00, normal_law=normal_law, centre=prof.centre,
        end=prof.end, centre_mean=prof.centre_mean, end_mean=prof.end_mean, y=prof.y,
        profile=prof.uN, max_force_error=max_force_error, newton=newton,
        steps=last.step if last else 0, contact_force=last.contact_force,
        applied_force=last.applied_force, lifted_area_fraction=area(lifted) / nominal,
        lift_from_y=y_lift, p_end_min=p_end, p_max=p_max, n_open=n_open,
        n_below_validity=below, h0=c.law.h0, p_seat=c.p_seat, kt_over_kn=kt, friction=friction,
        hardness=hardness, num_dofs=problem.num_dofs, n_points=interface.n_points_global,
        wall_time=wall_time, **on_points)
    paper = TABLE4[case]
    PETSc.Sys.Print(
        f"Case {case}: uN centre = {res.centre * 1e3:+.3f} um (paper {paper[0]:+.3f}), "
        f"end = {res.end * 1e3:+.3f} um (paper {paper[1]:+.3f}); force balance "
        f"{max_force_error:.1e}; lifted area {res.lifted_area_fraction * 100:.1f} % "
        + (f"(from y = {y_lift:.1f} mm)" if np.isfinite(y_lift) else "(none)")
        + f"; min p at the end {p_end:.3e} MPa "
        f"(seating {c.p_seat:.3e}); open points {n_open}; {newton} Newton its, "
        f"{res.wall_time:.1f} s", comm=comm)
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
        ls = "-" if r.normal_law == "elastic" else "--"
        col = colors.get(r.m00, "k")
        ax.plot(r.y, r.profile * 1e3, ls, color=col,
                label=f"m00 = {r.m00} um$^2$, {r.normal_law}")
        pc, pe = TABLE4[r.case]
        ax.plot([0.0, r.y[-1]], [pc, pe], markers.get(r.m00, "o"), color=col,
                mfc="none" if r.normal_law != "elastic" else col, ms=8)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("distance from mid-length y [mm]")
    ax.set_ylabel("interface deflection uN [um]  (< 0: approach)")
    r0 = results[0]
    variant = f"friction {r0.friction}"
    if any(r.normal_law != "elastic" for r in results):
        variant += f", e-p hardness from {r0.hardness}"
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
        ax.semilogy(r.points_y, np.maximum(r.points_p, 1e-12), ".", ms=1.5,
                    label=f"case {r.case}: m00 = {r.m00}, {r.normal_law}")
    ax.axhline(results[0].p_seat, color="0.5", ls=":", label="seating pressure (4.9 N)")
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
        pc, pe = TABLE4[r.case]
        c, e = r.centre * 1e3, r.end * 1e3
        lines.append(f"| {r.case} | {r.m00} | {r.normal_law} | {c:+.3f} | {pc:+.3f} "
                     f"| {e:+.3f} | {pe:+.3f} | {e - c:.3f} | {pe - pc:.3f} "
                     f"| {r.rigid * 1e3:+.3f} "
                     f"| {r.lifted_area_fraction * 100:.1f} % | {r.max_force_error:.1e} |")
    return "\n".join(lines)


# ## The run
def run(cases=tuple(sorted(CASES)), mesh_size=40.0, contact_size=5.0, order=2,
         load_half_length=5.0, steps=16, tangential="mindlin", friction="b", hardness="psi",
         outdir="results/beam", figdir=None, fig_suffix="", prefix="rc_", dof_threshold=None,
         comm=MPI.COMM_WORLD, verbose=True, plot=True, xdmf=True, beam_modulus=E1,
         overwrite=False, law="table4", tolerance=0.05, advise_results=None):
    """Run the chosen Table 4 cases; return a list of :class:`BeamCaseResult` (same on every
    rank but the rank-0 point arrays).

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
        law: "table4" (each case's own normal law) or "auto" (the law advisor's choice
            within ``tolerance`` for each case's surface; the case number then selects m00).
        advise_results: with law "auto", the FE results the tolerance holds (of
            ``rough_contact.advisor.RESULTS_ALL``; None: all of them).

    Returns:
        list of :class:`BeamCaseResult`, one per case (see :func:`run_case`).
    """
    cases = [int(k) for k in cases]
    bad = [k for k in cases if k not in CASES]
    if bad or not cases:
        raise ValueError(f"cases = {cases!r} is invalid; valid values: 1-6 (Table 4)")
    if hardness not in HARDNESS:
        raise ValueError(f"hardness = {hardness!r} is invalid; valid values: {HARDNESS}")
    if friction not in ("a", "b", "none"):
        raise ValueError(f"friction = {friction!r} is invalid; valid values: 'a', 'b', 'none'")
    check_integer("steps", steps, lo=1)
    t0 = MPI.Wtime()
    setup = build_scene(comm, mesh_size, contact_size, order, load_half_length)
    if comm.rank == 0:
        os.makedirs(outdir, exist_ok=True)
    results = []
    for case in cases:
        results.append(run_case(comm, setup, case, steps, tangential, friction, hardness, outdir,
                                prefix, dof_threshold, verbose, xdmf, beam_modulus, overwrite,
                                law, tolerance, advise_results))
    text = table(results)
    PETSc.Sys.Print("\n" + text + f"\n\nTotal wall time {MPI.Wtime() - t0:.1f} s on "
                    f"{comm.size} rank(s)", comm=comm)
    if comm.rank == 0:
        atomic_write_text(os.path.join(outdir, "table4.md"), text + "\n")
        # centre-line profiles uN(y) [um], one column per case
        cols = ["y_mm"] + [f"case{r.case}_uN_um" for r in results]
        rows = np.column_stack([results[0].y] + [r.profile * 1e3 for r in results])
        body = "\n".join(",".join(f"{v:.8g}" for v in row) for row in rows)
        atomic_write_text(os.path.join(outdir, "profiles.csv"), ",".join(cols) + "\n" + body + "\n")
        if plot:
            dirs = [outdir] + ([figdir] if figdir else [])
            for d in dirs:
                os.makedirs(d, exist_ok=True)
                plot_profiles(results, os.path.join(d, f"beam_deflection{fig_suffix}.png"))
                plot_pressure(results, os.path.join(d, f"beam_pressure{fig_suffix}.png"))
    for r in results:
        assert r.max_force_error < 1e-6, f"force balance violated: {r.max_force_error:.3e}"
    return results


