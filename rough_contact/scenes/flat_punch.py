"""The paper's flat punch (section 9.2): a square punch pressed on an elastic foundation across
a rough, orthotropic-frictional interface — parameters, laws, set-up and the standard run.

Buczkowski & Kleiber (2009), section 9.2: a flat-ended square punch (20 x 20 x 10 mm) on an
elastic foundation (100 x 100 x 50 mm), E = 200 GPa and nu = 0.25 for both, 1000 N in sixteen
increments, then unloaded; the rough surface of Figs 18-19 (m00 = 0.625 um^2, m20 = 8e-5,
m02 = 8e-4, m40 = 1.04e-6 um^-2, m04 = 1.04e-4 um^-2) and the orthotropic slip-hardening friction
of Fig 18, cases (a), (b), (c). A quarter is modelled (symmetry planes x = 0 and y = 0); it
carries 250 N on a central square of the punch top.

The rough surfaces are seated: the reference separation h0 at zero gap carries the nominal
pressure of the first load increment (h = h0 + g). Defaults (P2, 20 mm away from / 2 mm on the
contact) are the 1 % settings of ``docs/accuracy_vs_cost.md``.

Library code: it never initialises petsc4py and never reads ``sys.argv`` (the entry script
``demos/demo_flat_punch.py`` does). Units: mm, N, MPa.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import element_degree, vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.mesh import Scene
from rough_contact.fem.pairing import AutoPairing
from rough_contact.fem.problem import ContactProblem, Material, SurfaceLoad
from rough_contact.interface.contract import InterfaceLawProtocol
from rough_contact.io import ResultWriter, gather_points
from rough_contact.references import effective_modulus
from rough_contact.scenes.defaults import GRAIN_X, SEATING_STIFFNESS
from rough_contact.scenes.defaults import quadrature_degree as default_qdeg
from rough_contact.scenes.meshes.flat_punch import flat_punch
from rough_contact.scenes.meshes.punch_section import punch_section
from rough_contact.scenes.setup import check_mesh_arguments, check_points_basis
from rough_contact.solver.loading import load_path, load_unload_factors
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_integer, check_scalar

__all__ = ["E", "NU", "TOTAL_FORCE", "MOMENTS_UM", "FRICTION_CASES", "HARDENING", "TABLE5",
           "PLASTIC", "NORMAL_LAWS", "effective_modulus", "make_law", "advise_law",
           "write_advice", "PunchScene", "quarter_punch", "punch_section_scene", "PunchModel",
           "build", "point_data", "plot_slip_directions", "PunchResult", "run"]

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
# Normal laws: the paper's reversible ones, and the same populations with memory of the
# smallest separation (irreversible asperity plasticity: unloading and reloading on the
# elastic branch of h_min; issue 23, docs/unloading.md). The elastic population with memory is
# exactly the reversible elastic law.
NORMAL_LAWS = ("elastic", "elasto-plastic", "greenwood_williamson", "elastic-memory",
               "elasto-plastic-memory")
MEMORY_RTOL = 1e-3   # accuracy of the elasto-plastic history table (its build: 6-7 s CPU on the paper surface)


# ## Interface law
#
# The normal law is tabulated once from the population sums (rank 0 builds it, the others get a
# copy); the friction law is the orthotropic slip-hardening model with Mindlin-type tangential
# stiffness kT = c kN.  ``law="penalty"`` gives a smooth unilateral penalty with Coulomb friction
# instead (a stand-in for debugging the FE layer).
def make_law(comm, law="rough", case="b", normal_law="elastic", seating_pressure=None,
             normal=None, kt_over_kn=None):
    """Interface law and its normal law; ``normal`` (a prebuilt NormalLaw) skips the build;
    ``kt_over_kn`` (kTx/kN, kTy/kN) replaces the friction case's tangential ratios (e.g. the
    BEM's, ``rough_contact.micro.bem.BEMLaw.tangential``)."""
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
    if normal is None and normal_law not in NORMAL_LAWS:  # checked on every rank: no hang
        raise ValueError(f"normal_law = {normal_law!r} is invalid; valid values: "
                         f"{', '.join(repr(n) for n in NORMAL_LAWS)} (or 'auto' in run)")
    if normal is None:
        if comm.rank == 0:  # the table is built once and copied to the other ranks
            from rough_contact.micro.asperity import AsperityMaterial
            from rough_contact.interface.normal import NormalLaw
            from rough_contact.surface import SpectralMoments

            surface = SpectralMoments(**MOMENTS_UM, unit="um")
            E_star = effective_modulus(E, NU, E, NU)
            material = AsperityMaterial(E_star=E_star, nu=NU, **PLASTIC)
            if normal_law == "elastic":
                normal = NormalLaw.elastic(surface, E_star)
            elif normal_law == "greenwood_williamson":
                normal = NormalLaw.greenwood_williamson(surface, E_star)
            elif normal_law == "elasto-plastic":
                normal = NormalLaw.elasto_plastic(surface, material)
            else:   # with memory: the normal history h_min (docs/unloading.md)
                from rough_contact.interface.history import HistoryNormalLaw
                if normal_law == "elastic-memory":
                    normal = HistoryNormalLaw.elastic(surface, E_star)
                else:
                    normal = HistoryNormalLaw.elasto_plastic(surface, material,
                                                             rtol=MEMORY_RTOL, strict=False)
        normal = comm.bcast(normal, root=0)
    if case == "none":
        rough = InterfaceLaw(normal=normal)
    else:
        c = FRICTION_CASES[case]
        friction = OrthotropicSlipHardening(mu_macro=c["mu_macro"],
                                            mu_initial_ratio=c["mu_initial_ratio"],
                                            hardening=HARDENING, potential_axes=c["nu"])
        kt = c["kt"] if kt_over_kn is None else tuple(kt_over_kn)
        rough = InterfaceLaw(normal=normal, tangential=TangentialStiffness(kt),
                             friction=friction)
    return rough.with_seating(seating_pressure), normal


# ## The law advisor (``normal_law="auto"``)
#
# The scene's nominal pressures run from the seating pressure (the first increment) to twice the
# mean pressure under the punch (the pressure rises towards the punch's edges); the advisor
# (rough_contact.advisor) picks the cheapest normal law within the tolerance over that range.
def advise_law(comm, tolerance=0.05, steps=16, total_force=TOTAL_FORCE, half_width=10.0,
               concentration=2.0, surface=None, material=None, results=None):
    """The advisor's choice for the punch, and the advised NormalLaw (built on rank 0, copied
    to the others). Collective. Returns ``(advice, normal)``, the same on every rank.

    ``results``: the FE results held within ``tolerance`` (``rough_contact.advisor.RESULTS_ALL``
    by default: the run reports the frictional dissipation too)."""
    advice = normal = None
    if comm.rank == 0:
        from rough_contact.advisor import RESULTS_ALL, advise, scene_pressure_range
        from rough_contact.micro.asperity import AsperityMaterial
        from rough_contact.surface import SpectralMoments

        surface = surface or SpectralMoments(**MOMENTS_UM, unit="um")
        E_star = effective_modulus(E, NU, E, NU)
        material = material or AsperityMaterial(E_star=E_star, nu=NU, **PLASTIC)
        quarter = total_force / 4.0
        area = half_width ** 2
        p_range = scene_pressure_range(quarter, area, quarter / steps / area, concentration)
        advice = advise(surface, material, p_range, tolerance,
                        results=RESULTS_ALL if results is None else results)
        normal = advice.normal_law()
    return comm.bcast(advice, root=0), comm.bcast(normal, root=0)


def write_advice(comm, advice, outdir):
    """advice.txt and advice.json beside the results (rank 0, atomic writes)."""
    if comm.rank == 0:
        from rough_contact.io import atomic_write_text

        os.makedirs(outdir, exist_ok=True)
        atomic_write_text(os.path.join(outdir, "advice.txt"), advice.report() + "\n")
        atomic_write_text(os.path.join(outdir, "advice.json"), advice.to_json() + "\n")
    comm.barrier()


# ## Scene, spaces, conditions, problem
@dataclass(frozen=True)
class PunchScene:
    """The quarter-punch mesh, its displacement space and boundary conditions.

    Attributes:
        scene: mesh, cell/facet tags and labels (punch, foundation, load, contact pair, ...).
        V: vector Lagrange space of the displacement.
        bcs: symmetry conditions u_x = 0 on x = 0, u_y = 0 on y = 0, and the clamped base.
    """

    scene: Scene
    V: Any
    bcs: list


def quarter_punch(comm=MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.0, order=2,
                  load_half_width=2.5, cell_type="tetrahedron", *, edge_size=None,
                  edge_band=None, edge_growth=None, transition=None) -> PunchScene:
    """Mesh the quarter punch and set its space and boundary conditions. Collective.

    ``edge_size``, ``edge_band``, ``edge_growth``: grading towards the punch's free edge;
    ``transition``: the distance over which the size grows from the contact size to the mesh
    size (:func:`rough_contact.scenes.meshes.flat_punch.flat_punch`; None: the defaults)."""
    check_mesh_arguments(order, mesh_size=mesh_size, contact_size=contact_size,
                         load_half_width=load_half_width)
    scene = flat_punch(mesh_size=mesh_size, contact_size=contact_size, order=order,
                       load_half_width=load_half_width, cell_type=cell_type, comm=comm,
                       edge_size=edge_size, edge_band=edge_band, edge_growth=edge_growth,
                       transition=transition)
    V = vector_space(scene.mesh, order)
    ft = scene.facet_tags
    bcs = [fix(V, ft, scene.tag("symmetry_x"), 0), fix(V, ft, scene.tag("symmetry_y"), 1),
           fix(V, ft, scene.tag("fixed"))]
    return PunchScene(scene, V, bcs)


def punch_section_scene(comm=MPI.COMM_WORLD, *, mesh_size=10.0, contact_size=0.7,
                        edge_size=0.01, edge_growth=0.2, thickness=1.0) -> PunchScene:
    """The plane-strain section of the punch's edge (Q1, one hexahedron thick; mesh of
    :func:`rough_contact.scenes.meshes.punch_section.punch_section`) with its boundary
    conditions: u_x = 0 on x = 0, u_y = 0 on both faces y = 0 and y = t (plane strain), the
    foundation's base clamped. Collective.

    :func:`build` takes it as ``punch_scene``; its ``total_force`` is then 4 x the section's
    force (``build`` loads a quarter of it): ``4 * pressure * half_width * thickness``."""
    scene = punch_section(mesh_size=mesh_size, contact_size=contact_size, edge_size=edge_size,
                          edge_growth=edge_growth, thickness=thickness, comm=comm)
    V = vector_space(scene.mesh, 1)
    ft = scene.facet_tags
    bcs = [fix(V, ft, scene.tag("symmetry_x"), 0), fix(V, ft, scene.tag("plane"), 1),
           fix(V, ft, scene.tag("fixed"))]
    return PunchScene(scene, V, bcs)


@dataclass(frozen=True)
class PunchModel:
    """Everything :func:`build` sets up for the quarter punch (same objects on every rank).

    Attributes:
        scene: mesh, cell/facet tags and labels of punch and foundation.
        V: vector Lagrange space of the displacement.
        law: the interface law (seated: its ``h0`` carries the first increment's pressure).
        normal: the tabulated normal law (None for the penalty stand-in).
        interface: the contact interface (first surface = punch bottom).
        problem: bulk elasticity + interface.
        solver: the SNES solver (options prefix given to :func:`build`).
        quarter_force: total force on the quarter model at load factor 1 [N].
    """

    scene: Scene
    V: Any
    law: InterfaceLawProtocol
    normal: Optional[object]
    interface: ContactInterface
    problem: ContactProblem
    solver: SNESSolver
    quarter_force: float


def build(comm=MPI.COMM_WORLD, mesh_size=20.0, contact_size=2.0, order=2, load_half_width=2.5,
          law="rough", case="b", normal_law="elasto-plastic", steps=16, prefix="rc_",
          dof_threshold=None, quadrature_degree=None, normal=None, seating_steps=None,
          cell_type="tetrahedron", *, punch_scene=None, total_force=TOTAL_FORCE,
          solver_defaults=None, quadrature="gauss", solver_options=None, enforcement=None,
          kt_over_kn=None, pairing="auto", points="quadrature", basis="standard",
          edge_size=None, edge_band=None, edge_growth=None, transition=None):
    """Mesh, law, interface, problem and solver of the quarter punch. Collective.

    ``pairing`` pairs the punch bottom with the foundation (``ContactInterface(pairing=)``):
    ``"auto"`` (default) is the conforming pairing when the two surfaces match facet to facet
    (the scene of :func:`quarter_punch`), else the mortar, the non-matching pairing that
    passes the patch test (docs/nonmatching.md); with ``quadrature="vertex"``, which the mortar
    cannot use, surfaces that do not match are an error naming the choices. ``"conforming"``,
    ``"projection"``, ``"mortar"`` or a :class:`~rough_contact.fem.pairing.Pairing` are used as
    given (the projection fails the patch test on non-nested meshes).

    ``quadrature`` is the interface rule (``"gauss"`` of ``quadrature_degree``, default 2 x
    order, or ``"vertex"``: nodal, P1 only; see ``ContactInterface``).

    ``points``: ``"quadrature"`` (the law at the rule's points) or ``"nodal"`` (at the
    first surface's vertices on mortar-weighted jumps, any order:
    :class:`rough_contact.fem.nodal.NodalContactInterface`).

    ``basis`` (``points="nodal"`` only): the weights of the nodal set's vertex jumps,
    ``"standard"`` (the vertex functions N_j, the default) or ``"dual"`` (their biorthogonal
    basis: a vertex's jump uses its own DOFs, node to node on a conforming pairing;
    ``NodalContactInterface(basis=)``, docs/exact_contact_newton.md).

    ``edge_size``, ``edge_band``, ``edge_growth`` grade the mesh towards the punch's free
    edge, ``transition`` sets the patch field's growth distance (passed to
    :func:`quarter_punch`; None: no edge grading, the default distance 2 a).

    ``punch_scene`` reuses a :class:`PunchScene` of :func:`quarter_punch` (mesh sizes, order,
    cell type and edge grading are then taken from it); ``total_force`` is the full punch's
    force at load factor 1 [N] (the quarter carries a quarter); ``solver_defaults`` are extra
    SNES/KSP/PC defaults (without prefix) that the command line can override; ``solver_options`` are
    extra keyword arguments of :class:`~rough_contact.solver.snes.SNESSolver` (e.g.
    ``linear_solver="hypre"``); ``dof_threshold=None`` is the solver's measured default.

    ``kt_over_kn`` (kTx/kN, kTy/kN) replaces the friction case's tangential stiffness ratios.

    ``normal`` passes a prebuilt NormalLaw (same on every rank); ``seating_steps`` (default
    ``steps``) sets the seating pressure to the nominal pressure of 1/seating_steps of the load.

    ``law`` is "rough", "penalty" or any object satisfying the interface-law contract
    (``rough_contact.interface.contract.InterfaceLawProtocol``), used as given;
    ``enforcement`` (``rough_contact.interface.enforcement``: ``Penalty()``, the default, or
    ``AugmentedLagrangian(...)``) is how the interface imposes it.

    Returns:
        :class:`PunchModel`.
    """
    check_integer("steps", steps, lo=1)
    if seating_steps is not None:
        check_integer("seating_steps", seating_steps, lo=1)
    check_points_basis(points, basis)
    if punch_scene is None:
        punch_scene = quarter_punch(comm, mesh_size, contact_size, order, load_half_width,
                                    cell_type, edge_size=edge_size, edge_band=edge_band,
                                    edge_growth=edge_growth, transition=transition)
    scene, V, bcs = punch_scene.scene, punch_scene.V, punch_scene.bcs
    order = element_degree(V)

    check_scalar("total_force", total_force, lo=0.0, unit="N")
    quarter_force = total_force / 4.0
    contact_area = scene.dimensions["half_width"] ** 2
    # Seat the rough surfaces with the nominal pressure of the first increment.
    p_seat = quarter_force / (seating_steps or steps) / contact_area
    if isinstance(law, str):
        interface_law, normal = make_law(comm, law, case, normal_law, seating_pressure=p_seat,
                                         normal=normal, kt_over_kn=kt_over_kn)
    else:
        interface_law = law

    first, second = scene.contact_pair
    qdeg = quadrature_degree if quadrature_degree is not None else default_qdeg(order)
    if isinstance(pairing, str) and pairing == "auto":   # non-matching: the patch-exact mortar
        pairing = AutoPairing(second, "mortar" if quadrature == "gauss" else None)
    common = dict(law=interface_law, grain_direction=GRAIN_X, quadrature_degree=qdeg,
                  quadrature=quadrature, bcs=bcs, enforcement=enforcement, pairing=pairing)
    if points == "nodal":
        interface = NodalContactInterface(V, scene.facet_tags, first, second, basis=basis,
                                          **common)
    else:
        interface = ContactInterface(V, scene.facet_tags, first, second, **common)
    materials = {scene.tag("punch"): Material(E, NU), scene.tag("foundation"): Material(E, NU)}
    loads = [SurfaceLoad(scene.tag("load"), force=[0.0, 0.0, -quarter_force])]
    problem = ContactProblem(V, materials, bcs, loads, cell_tags=scene.cell_tags,
                             facet_tags=scene.facet_tags, interface=interface,
                             seating_tag=first, seating_stiffness=SEATING_STIFFNESS,
                             body_cells=[scene.cell_tags.find(scene.tag(b)) for b in scene.bodies])
    solver = SNESSolver(problem, prefix=prefix, dof_threshold=dof_threshold,
                        defaults=solver_defaults, **(solver_options or {}))
    return PunchModel(scene=scene, V=V, law=interface_law, normal=normal, interface=interface,
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
    """Quiver of the plastic slip directions at contact points (Figs 18-19), about n_grid^2
    arrows, drawn by :func:`rough_contact.io.plotting.plot_slip_quiver`. Collective."""
    from rough_contact.io import plotting

    pts, fields = gather_points(comm, *point_data(interface))
    if comm.rank != 0:
        return
    plotting.plot_slip_quiver(
        pts[:, :2], fields["plastic_slip_mm"], max_arrows=n_grid * n_grid, scale=1e3,
        label="|plastic slip| [um]", axes="xy", path=path, figsize=(6.0, 5.4), dpi=130,
        title=title + "\n(plastic part of u_foundation - u_punch; x = grain)")


# ## The run
@dataclass(frozen=True)
class PunchResult:
    """Result of :func:`run` (identical on every rank).

    Attributes:
        dissipation: total frictional dissipation D of the quarter model at the end [N mm].
        history: the converged increments of this call
            (:class:`rough_contact.solver.loading.Increment`, in order).
        peak: the increment at the full load (load factor 1), ``None`` if not reached.
        num_dofs: global number of displacement DOFs.
        n_points: global number of interface points.
        max_force_error: max over the increments of |Fz_contact + Fz_applied| / |Fz_applied|.
    """

    dissipation: float
    history: list
    peak: Optional[object]
    num_dofs: int
    n_points: int
    max_force_error: float


def run(mesh_size=20.0, contact_size=2.0, order=2, load_half_width=2.5, steps=16,
         unload=True, law="rough", case="b", normal_law="elasto-plastic", outdir="results/flat_punch",
         prefix="rc_", dof_threshold=None, comm=MPI.COMM_WORLD, verbose=True, plot=True,
         overwrite=False, validity="warn", checkpoint=None, restart=None, stop_after=None,
         tolerance=0.05, advise_results=None):
    """Run the punch; return a :class:`PunchResult` (identical on every rank). Collective.

    ``outdir`` receives one run: earlier results there make it refuse unless ``overwrite``.
    ``validity``: what a converged increment with interface points beyond the normal law's
    validity does (``"warn"``, ``"error"``, ``"ignore"``; ``rough_contact.solver.loading``).
    ``checkpoint``: directory receiving a checkpoint after every converged increment;
    ``restart``: a checkpoint directory of the same run (same options and ranks) to continue
    from (``rough_contact.solver.checkpoint``); the output files in ``outdir`` (the stopped
    run's) are cut back to the checkpoint and continued. ``stop_after``: stop after this many
    increments (checkpoint written), to continue later with ``restart``.
    ``normal_law="auto"`` (or ``law="auto"``): the law advisor picks the cheapest normal law
    within ``tolerance`` of the full model over the run's pressures; its report is printed and
    written beside the results (advice.txt, advice.json). ``advise_results``: the FE results
    the tolerance holds (of ``rough_contact.advisor.RESULTS_ALL``; None: all of them).
    """
    t0 = MPI.Wtime()
    normal = None
    if law == "auto":
        law, normal_law = "rough", "auto"
    if normal_law == "auto" and law == "rough":
        advice, normal = advise_law(comm, tolerance, steps, results=advise_results)
        PETSc.Sys.Print(advice.report(), comm=comm)
        write_advice(comm, advice, outdir)
        normal_law = advice.normal
    m = build(comm, mesh_size, contact_size, order, load_half_width, law, case, normal_law,
              steps, prefix, dof_threshold, normal=normal)
    problem, solver, interface = m.problem, m.solver, m.interface
    n_points = interface.n_points_global
    PETSc.Sys.Print(f"Flat punch (quarter): {problem.num_dofs} DOFs, {n_points} interface points, "
                    f"P{order}, law={law} ({normal_law}, friction case {case}), "
                    f"h0 = {getattr(m.law, 'h0', float('nan')) * 1e3:.4f} um, "
                    f"linear solver {solver.linear_solver}, {comm.size} rank(s)", comm=comm)

    factors = load_unload_factors(steps, steps - 1 if unload else 0)
    writer = ResultWriter(outdir, comm, u=problem.u, interface=interface,
                          extra_columns=("force_error_rel",), overwrite=overwrite,
                          extra_patterns=(r"slip_directions.*\.png",),
                          resume=restart is not None)
    if writer.removed:
        PETSc.Sys.Print(f"Replaced {len(writer.removed)} files of an earlier run in {outdir}/",
                        comm=comm)
    history = []
    peak = None
    for inc in load_path(problem, solver, factors, verbose=verbose, validity=validity,
                         checkpoint=checkpoint, resume=restart, outputs=[writer],
                         max_steps=stop_after):
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
    if not history:                      # restarted from the checkpoint of a completed run
        D = interface.dissipation()
        PETSc.Sys.Print(f"Nothing left to do: the checkpoint in {restart} is the end of the run; "
                        f"total frictional dissipation D: {D:.4g} N mm", comm=comm)
        solver.destroy()
        return PunchResult(dissipation=D, history=history, peak=None,
                           num_dofs=problem.num_dofs, n_points=n_points, max_force_error=0.0)
    if stop_after is not None and history[-1].step < len(factors):
        PETSc.Sys.Print(f"Stopped after {len(history)} increments (stop_after); continue with "
                        f"restart={checkpoint!r} (--restart)", comm=comm)
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
                        f"{D:.4g} N mm", comm=comm)
        PETSc.Sys.Print(f"  (not comparable with the paper's Table 5, case ({case}): "
                        f"{TABLE5['21-node'][case]} / {TABLE5['28-node'][case]} N mm with its "
                        "21/28-node elements; no reading of the paper's data reproduces those "
                        "values, ours are 2-3 orders of magnitude smaller for reasons analysed "
                        "in docs/punch.md: this is expected, not a failed run)", comm=comm)
    else:
        PETSc.Sys.Print(f"Total frictional dissipation D: {D:.4g} N mm", comm=comm)
    if normal_law.endswith("-memory"):
        PETSc.Sys.Print(f"Normal hysteresis (asperity plasticity, law with memory): "
                        f"{interface.normal_dissipation():.4g} N mm", comm=comm)
    PETSc.Sys.Print(f"Output in {outdir}/ (displacement.xdmf, interface.xdmf, history.csv, "
                    f"slip_directions*.png); wall time {MPI.Wtime() - t0:.1f} s", comm=comm)
    assert max_force_error < 1e-6, f"force balance violated: {max_force_error:.3e}"
    solver.destroy()
    return PunchResult(dissipation=D, history=history, peak=peak, num_dofs=problem.num_dofs,
                       n_points=n_points, max_force_error=max_force_error)


