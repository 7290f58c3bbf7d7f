"""Cattaneo–Mindlin and Mindlin–Deresiewicz: a rigid sphere on an elastic block with Coulomb
friction, normal load then tangential load, against the closed forms.

The closed forms (stick radius, tangential approach, energy per cycle) are in
:mod:`rough_contact.references`; this module holds the FE scene that is compared with them.

FE scene (``run``): HALF block [-L, L] x [0, L] x [-H, 0] (``indented_block(half=True)``;
symmetry u_y = 0 on y = 0; the tangential load along x keeps that symmetry), a
``RigidSphere`` touching the top at the origin, ``SoftplusPenalty`` with isotropic Coulomb
friction (stiff normal and tangential penalties). The bottom is pushed up by u_z = delta_n
(channel ``normal``, ramped then held) and moved along x by u_x = s (channel ``shear``); the
total forces are twice the bottom reactions. The stick radius of the FE solution is estimated
from areas, c / a = sqrt(1 - A_slip / A_contact) (A = nominal areas of the slipping and of the
contact points, contact meaning p > 1e-3 p_max: the softplus law is positive everywhere): an
area average, less sensitive to the point spacing than the radius of the outermost stuck
point, but it moves by a whole ring of points when the front crosses one. Beside it, the front
estimate c / a_FE (:mod:`rough_contact.stick_front`): the zeros of the squared stick margin
(mu p - |t|)^2 and of p^2, each fitted against r^2 next to its front over the points gathered
from every rank (``MindlinRun.points``), finer than the point spacing (docs/mindlin_dual.md).

Units: mm, N, MPa.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from mpi4py import MPI

from rough_contact.fem.boundary import fix
from rough_contact.fem.compat import vector_space
from rough_contact.fem.contact import ContactInterface
from rough_contact.fem.nodal import NodalContactInterface
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.fem.rigid import RigidSphere
from rough_contact.interface.enforcement import AugmentedLagrangian, Penalty
from rough_contact.interface.penalty import SoftplusPenalty
from rough_contact.references import hertz_force, hertz_radius, sliding_approach
from rough_contact.scenes.defaults import GRAIN_X, INDENTER_PENALTY
from rough_contact.scenes.defaults import quadrature_degree as default_qdeg
from rough_contact.scenes.meshes.blocks import indented_block
from rough_contact.scenes.setup import check_points_basis
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import LoadProgram
from rough_contact.solver.snes import SNESSolver
from rough_contact.stick_front import contact_front, stick_front
from rough_contact.validation import check_integer, check_scalar

__all__ = ["ParaboloidIndenter", "KT_SCALE", "MindlinRun", "PointSnapshot", "run",
           "checkpointed_points", "checkpointed_forces"]


class ParaboloidIndenter:
    """The indenter of Hertz's and Mindlin's theory: the paraboloid z = r^2 / (2 R) over the
    origin with the gap measured vertically and the normal -z everywhere (the half-space,
    small-slope idealisation: tangential slip is horizontal). A
    :class:`rough_contact.fem.rigid.RigidSurface`.

    With the exact sphere (``RigidSphere``), the local frames tilt by r / R and the block's
    vertical motion u_z shows as a tangential jump u_z r / R, which is of the order of
    Mindlin's tangential compliance near the contact edge: the exact-sphere kinematics is not
    the one the closed forms describe.
    """

    def __init__(self, radius: float):
        self.radius = check_scalar("radius", radius, lo=0.0, unit="mm")

    def describe(self) -> dict:
        """Its parameters, for a checkpoint's fingerprint (``rough_contact.fingerprint``)."""
        return {"radius": float(self.radius)}

    def gap_and_normal(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        g = (x[:, 0] ** 2 + x[:, 1] ** 2) / (2.0 * self.radius) - x[:, 2]
        return g, np.broadcast_to(np.array([0.0, 0.0, -1.0]), x.shape).copy()


KT_SCALE = 3.75
"""Default tangential penalty k_T = KT_SCALE E / h at contact element size h (see :func:`run`)."""


def _program(preload_steps: int, shear_steps: int, cycles: int) -> LoadProgram:
    """``normal`` ramps to 1 over t in [0, 1]; ``shear``: monotonic 0 -> 1 over [1, 2]
    (``cycles`` = 0) or triangle cycles 0 -> 1 -> -1 -> 0 of unit length (``shear_steps`` per
    cycle, a multiple of 4)."""
    def ramp(t):
        return min(max(t, 0.0), 1.0)

    def shear(t):
        if t <= 1.0:
            return 0.0
        if cycles == 0:
            return ramp(t - 1.0)
        s = (t - 1.0) % 1.0
        return 4.0 * s if s <= 0.25 else 2.0 - 4.0 * s if s <= 0.75 else 4.0 * s - 4.0

    times = [(i + 1) / preload_steps for i in range(preload_steps)]
    n = shear_steps * max(cycles, 1)
    times += [1.0 + (j + 1) / shear_steps for j in range(n)]
    return LoadProgram({"normal": ramp, "shear": shear}, times,
                       cycle_start=1.0 if cycles else None)


@dataclass(frozen=True)
class PointSnapshot:
    """The interface points near the contact (within ``gather_radius`` of the axis), gathered
    from every rank and sorted by their coordinates (the same arrays whatever the partition);
    per-increment arrays have one row per increment.

    Attributes:
        x: (n, 3) reference coordinates [mm] (the half model: y >= 0).
        weight: (n,) area each point represents [mm^2].
        pressure: (n_inc, n) p [MPa].
        shear: (n_inc, n, 2) (t_x, t_y) [MPa].
        contact: (n_inc, n) bool: p > 1e-3 of the increment's largest p (the scene's contact).
        slipping: (n_inc, n) bool: in contact and slipping.
    """

    x: np.ndarray
    weight: np.ndarray
    pressure: np.ndarray
    shear: np.ndarray
    contact: np.ndarray
    slipping: np.ndarray

    @property
    def r(self) -> np.ndarray:
        """(n,) distance from the axis of the indenter [mm]."""
        return np.hypot(self.x[:, 0], self.x[:, 1])


@dataclass(frozen=True)
class MindlinRun:
    """Result of :func:`run` (identical on every rank); arrays have one entry per increment.

    Attributes:
        t: pseudo-time (normal ramp over [0, 1], then the shear).
        slide: bottom displacement along x [mm].
        P, Q: total normal and tangential force (twice the half model's bottom reactions) [N].
        stick: FE stick ratio sqrt(1 - A_slip / A_contact) [-] (nan without contact): the
            area estimate, which moves by a whole ring of points when the front crosses one.
        stick_front: FE stick ratio c / a_FE from the fronts of the margins and of the
            pressure (:func:`rough_contact.stick_front.stick_front`, :func:`~rough_contact.
            stick_front.contact_front`: zeros of m^2 = (mu p - |t|)^2 and of p^2 fitted
            against r^2 next to the fronts, finer than the point spacing) [-] (nan where a
            front cannot be fitted, 0 when no point sticks).
        stick_front_inside: the same with only the stuck points inside the innermost slipping
            point fitted (``stick_front(inside_slip=True)``: without the stuck islands a
            discrete solution leaves among slipping points) [-].
        stick_radius, contact_radius: c and a_FE of ``stick_front`` [mm].
        front_residual: relative rms residual of the margin fit [-].
        front_misplaced: stuck points beyond c plus slipping points inside c.
        contact_area: nominal area with p > 1e-3 p_max (whole contact) [mm^2].
        dissipation: committed dissipation (whole contact) [N mm].
        newton: Newton iterations spent on each increment.
        a: Hertz's contact radius at the final P [mm].
        G: shear modulus [MPa]; nu: Poisson ratio; mu: friction coefficient.
        dofs: global number of DOFs.
        cycle_start: pseudo-time at which the cycles start (None for a monotonic slide).
        shear_steps: increments per cycle (or of the monotonic slide).
    """

    t: np.ndarray
    slide: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    stick: np.ndarray
    contact_area: np.ndarray
    dissipation: np.ndarray
    newton: np.ndarray
    a: float
    G: float
    nu: float
    mu: float
    dofs: int
    cycle_start: Optional[float]
    shear_steps: int
    stick_front: Optional[np.ndarray] = None
    stick_front_inside: Optional[np.ndarray] = None
    stick_radius: Optional[np.ndarray] = None
    contact_radius: Optional[np.ndarray] = None
    front_residual: Optional[np.ndarray] = None
    front_misplaced: Optional[np.ndarray] = None
    points: Optional[PointSnapshot] = None


def _gather_points(comm, x, arrays):
    """Every rank's rows of ``x`` (n, 3) and of the (n, k) ``arrays`` on every rank, sorted by
    x, y, z (an order independent of the partition)."""
    xs = np.concatenate(comm.allgather(np.asarray(x, dtype=float)))
    data = np.concatenate(comm.allgather(np.asarray(arrays, dtype=float)))
    # the mesh's distribution perturbs coordinates by rounding (1e-16 mm): sort on keys rounded
    # well above it, so that a partition cannot swap two points of the same x
    key = np.round(xs / max(float(np.abs(xs).max(initial=0.0)), 1e-300), 9)
    order = np.lexsort((key[:, 2], key[:, 1], key[:, 0]))
    return xs[order], data[order]


def _snapshot(snaps, x_near) -> PointSnapshot:
    """The :class:`PointSnapshot` of a record's per-increment point arrays (columns: weight,
    p, t_x, t_y, slipping, contact)."""
    S = np.array(snaps)
    on_all = S[:, :, 5] > 0.5
    return PointSnapshot(x=x_near, weight=S[0, :, 0], pressure=S[:, :, 1], shear=S[:, :, 2:4],
                         contact=on_all, slipping=on_all & (S[:, :, 4] > 0.5))


def checkpointed_forces(directory: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, P, Q [N]) of the increments a checkpointed :func:`run` has done, as
    :func:`checkpointed_points` reads them."""
    from rough_contact.solver.checkpoint import saved_outputs
    rows = saved_outputs(directory)[0][0]
    t, _, P, Q = (np.array(c) for c in list(zip(*rows))[:4])
    return t, P, Q


def checkpointed_points(directory: str) -> tuple[np.ndarray, np.ndarray, PointSnapshot]:
    """(t, P [N], points) of the increments a checkpointed :func:`run` has done, read from
    its checkpoint ``directory`` without resuming it (serial, no FE set-up):
    ``rough_contact.solver.checkpoint.saved_outputs``. ``points`` as ``MindlinRun.points``."""
    from rough_contact.solver.checkpoint import saved_outputs
    _, snaps, x_near = saved_outputs(directory)[0]
    t, P, _ = checkpointed_forces(directory)
    return t, P, _snapshot(snaps, x_near)


class _Record:
    """The per-increment rows and gathered points of :func:`run`, kept with the checkpoints
    (``rough_contact.solver.checkpoint.ResumableOutput``; the same on every rank)."""

    def __init__(self):
        self.rows: list = []
        self.snaps: list = []
        self.x_near: Optional[np.ndarray] = None

    def checkpoint_state(self) -> tuple:
        return list(self.rows), list(self.snaps), self.x_near

    def restore(self, state) -> None:
        rows, snaps, x_near = state
        self.rows, self.snaps, self.x_near = list(rows), list(snaps), x_near


def run(contact_size=0.05, order=2, radius=10.0, delta=4e-3, slide=None, E=2.0e5, nu=0.49,
        mu=0.3, penalty=INDENTER_PENALTY, half_width=4.0, height=4.0, mesh_size=1.0, preload_steps=2,
        shear_steps=12, cycles=0, indenter="paraboloid", quadrature_degree=None,
        k_tangential=None, ring_size=None, ring_band=(0.8, 1.05), ring_growth=None,
        width_ratio=1e-3, first_contact="increment_start",
        augmented=False, augmentation_tolerance=1e-3, points="quadrature", transition=1.0,
        refined_radius=0.4, gather_radius=1.5, front_band=0.5,
        max_updates=30, basis="standard", enforcement=None, comm=MPI.COMM_WORLD,
        verbose=False, checkpoint=None, restart=None, stop_after=None) -> MindlinRun:
    """Normal indentation by ``delta`` [mm], then a tangential bottom displacement: monotonic to
    ``slide`` [mm] (``cycles`` = 0) or ``cycles`` triangle cycles of amplitude ``slide``.

    ``indenter``: ``"paraboloid"`` (:class:`ParaboloidIndenter`, the closed forms'
    kinematics) or ``"sphere"`` (the exact rigid sphere).

    ``penalty``: the normal penalty [MPa/mm]. ``k_tangential``: the tangential one; default
    ``KT_SCALE * E / contact_size`` (3.75 E / h: the elastic slip at the peak pressure is
    about 0.14 % of the element size). A tangential penalty that does not scale with the mesh
    spoils the stick zone: too stiff (1e8 MPa/mm at h = a/8) over-constrains the tangential
    jump at the many quadrature points per node and makes edge points with little pressure
    slip under the normal load alone (c/a 3 % small at every level); too soft (1e7 at a/8)
    adds its compliance and delays slip (c/a up to 4 % large). docs/mindlin.md has the study.
    ``quadrature_degree``: of the facet rule (default 2 ``order``).

    ``preload_steps``: increments of the normal load. A vertex that closes during an increment
    sticks where it was at the increment's start, so its stick shear carries the tangential
    motion of the whole increment. At nu = 0.49 the surface moves inwards under the pressure,
    and 2 increments leave the edge annulus (about 0.98-1 a) slipping under the normal load
    alone; about 8 remove that systematic shear (docs/mindlin_dual.md, session 18). It matters
    when the tangential load is small (Q / mu P below about 0.05).

    ``first_contact``: the law's (``SoftplusPenalty(first_contact=)``). ``"closure"`` makes a
    vertex that closes during an increment stick where it is at the end of it, and no vertex
    in contact then slips under the normal load alone on any mesh measured, with 2 or 8
    increments (docs/mindlin_dual.md, session 20). The default keeps the runs of the earlier
    sessions.

    ``ring_size``: element size [mm] in the annulus ``ring_band`` (fractions of Hertz's radius
    sqrt(R delta)) where the slip zone of a small tangential load lies (c/a = 0.95 at
    Q/mu P = 0.15, a ring 0.05 a wide); default: no ring, ``contact_size`` everywhere in the
    contact. The tangential penalty keeps its ``contact_size`` scaling. ``ring_growth``: the
    distance [mm] from the band over which the ring's size grows to ``contact_size``
    (``indented_block(ring_growth=)``; needed on a large block with a coarse far mesh);
    default: towards ``mesh_size`` over the band's width.

    ``half_width``, ``height``, ``mesh_size``, ``transition``, ``refined_radius`` [mm]: the
    block and its mesh (``indented_block``): the element size grows from ``contact_size``
    (within ``refined_radius`` of the origin) to ``mesh_size`` over ``transition``. A larger
    block needs a proportionally longer transition (a gentle grading), else its coarse far
    mesh stiffens the answer (docs/mindlin_dual.md, "A large block").

    ``width_ratio``: the softplus smoothing length as a fraction of ``delta``. The smoothed law
    carries a pressure k w ln 2 at zero gap (w = width_ratio delta; 8 % of Hertz's p0 at the
    default 1e-3 and k = 1e8) and points just outside the contact keep a small pressure
    while they slide by the whole tangential displacement: a dissipation linear in the
    amplitude, beside Mindlin's cubic one (docs/mindlin.md).

    ``augmented``: exact contact and stick by the augmented-Lagrangian (Uzawa) iteration of
    ``SoftplusPenalty`` with ``AugmentedLagrangian(augmentation_tolerance)``; the penalties then
    set only how fast the multipliers converge.

    ``points``: ``"quadrature"`` (the law at the facet rule's points) or ``"nodal"`` (at the
    vertices of the contact surface on mortar-weighted jumps,
    :class:`rough_contact.fem.nodal.NodalContactInterface`: one constraint per surface vertex,
    so exact stick does not lock on P2). ``max_updates``: multiplier updates per increment.
    ``basis`` (``points="nodal"`` only): the weights of the vertex jumps, ``"standard"`` (the
    vertex functions) or ``"dual"`` (their biorthogonal basis;
    ``NodalContactInterface(basis=)``).

    ``enforcement``: an enforcement of :mod:`rough_contact.interface.enforcement` used as
    given (e.g. ``NewtonAugmentedLagrangian(1e-4)``, the multipliers updated inside the
    Newton iteration, nodal points only); default ``None``: chosen by ``augmented``. Giving
    both ``enforcement`` and ``augmented=True`` is an error.

    ``gather_radius``: the points within ``gather_radius`` x sqrt(R delta) (Hertz's radius at
    ``delta``) of the axis are gathered at every increment (``MindlinRun.points``) and give the
    front estimate ``MindlinRun.stick_front``; ``front_band``: its fitted band, a fraction of
    each front's radius (:func:`rough_contact.stick_front.stick_front`).

    ``slide`` defaults to the approach at which Mindlin's Q reaches mu P for Hertz's P at
    ``delta`` plus the block's shear compliance (so the last increments slide).

    ``checkpoint``: a directory receiving a checkpoint after every converged increment
    (``rough_contact.solver.checkpoint``), the rows and gathered points so far included;
    ``restart``: such a directory to continue from (the same arguments; the result then
    covers the whole run, the restored increments included); ``stop_after``: stop after this
    many increments solved by this call (the result covers the increments done). A run of
    hours (a small Mindlin–Deresiewicz amplitude on a ring-refined mesh) can so be split over
    several sessions and loses no converged increment when killed.

    Returns:
        :class:`MindlinRun` (identical on every rank): per increment the bottom slide, P, Q,
        the FE stick ratio, the contact area, the dissipation; and the scene's constants
        (a from Hertz at the final P, G, DOFs).
    """
    check_scalar("delta", delta, lo=0.0, unit="mm")
    check_scalar("mu", mu, lo=0.0)
    if stop_after is not None:
        check_integer("stop_after", stop_after, lo=1, what="increments")
    check_points_basis(points, basis)
    if enforcement is not None and augmented:
        raise ValueError(f"enforcement = {enforcement!r} with augmented = True is invalid: "
                         "give one of them (augmented=True means AugmentedLagrangian)")
    if cycles and shear_steps % 4:
        raise ValueError(f"shear_steps = {shear_steps} is invalid for cycles: it must be a "
                         "multiple of 4")
    G = E / (2.0 * (1.0 + nu))
    E_star = E / (1.0 - nu**2)
    if slide is None:
        P_h = hertz_force(delta, radius, E_star)
        a_h = hertz_radius(P_h, radius, E_star)
        slide = sliding_approach(mu, P_h, a_h, G, nu) + \
            mu * P_h * height / (G * 2.0 * half_width * half_width)
    check_scalar("slide", slide, lo=0.0, unit="mm")
    check_scalar("gather_radius", gather_radius, lo=0.0)
    check_scalar("front_band", front_band, lo=0.0, hi=1.0, hi_open=False)
    r_gather = gather_radius * np.sqrt(radius * delta)
    ring = None
    if ring_size is not None:
        lo, hi = ring_band
        if not 0.0 <= lo < hi:
            raise ValueError(f"ring_band = {ring_band!r} is invalid: 0 <= lo < hi (fractions "
                             "of Hertz's contact radius)")
        a_h = np.sqrt(radius * delta)
        ring = (0.5 * (lo + hi) * a_h, 0.5 * (hi - lo) * a_h, ring_size)
    scene = indented_block(half_width=half_width, height=height, mesh_size=mesh_size,
                           contact_size=contact_size, transition=transition,
                           refined_radius=refined_radius, order=order, half=True,
                           ring=ring, ring_growth=ring_growth, comm=comm)
    V = vector_space(scene.mesh, order)
    sym = fix(V, scene.facet_tags, scene.tag("symmetry_y"), 1)
    if k_tangential is None:
        k_tangential = KT_SCALE * E / contact_size
    check_scalar("k_tangential", k_tangential, lo=0.0, unit="MPa/mm")
    check_scalar("width_ratio", width_ratio, lo=0.0)
    law = SoftplusPenalty(penalty, width_ratio * delta, k_tangential=k_tangential, friction=mu,
                          first_contact=first_contact)
    if enforcement is None:
        enforcement = AugmentedLagrangian(augmentation_tolerance, max_updates) if augmented \
            else Penalty()
    if indenter not in ("paraboloid", "sphere"):
        raise ValueError(f"indenter = {indenter!r} is invalid: 'paraboloid' or 'sphere'")
    rigid = ParaboloidIndenter(radius) if indenter == "paraboloid" else \
        RigidSphere((0.0, 0.0, radius), radius)
    common = dict(law=law, rigid=rigid, bcs=[sym], grain_direction=GRAIN_X,
                  quadrature_degree=default_qdeg(order) if quadrature_degree is None
                  else quadrature_degree, enforcement=enforcement)
    if points == "nodal":
        ci = NodalContactInterface(V, scene.facet_tags, scene.tag("contact"), basis=basis,
                                   **common)
    else:
        ci = ContactInterface(V, scene.facet_tags, scene.tag("contact"), **common)
    bottom = scene.tag("bottom")
    prog = _program(preload_steps, shear_steps, cycles)
    problem = ContactProblem(
        V, Material(E, nu), [sym], facet_tags=scene.facet_tags, interface=ci,
        prescribed=[PrescribedDisplacement(bottom, (0.0, 0.0, delta), (2,), channel="normal"),
                    PrescribedDisplacement(bottom, (slide, 0.0, 0.0), (0,), channel="shear")],
        programs=prog.channels)
    solver = SNESSolver(problem, prefix="mindlin_")
    record = _Record()          # restored from the checkpoint on a restart
    for inc in load_path(problem, solver, prog.times, verbose=verbose, checkpoint=checkpoint,
                         resume=restart, outputs=[record], max_steps=stop_after):
        R = problem.reaction(bottom)
        pf = ci.point_fields()
        x_loc = ci.point_coordinates()
        near = (np.hypot(x_loc[:, 0], x_loc[:, 1]) < r_gather) & (pf.weight > 0.0)
        x_near, cols = _gather_points(comm, x_loc[near], np.column_stack([
            pf.weight[near], pf.pressure[near], pf.shear[near],
            pf.slipping[near].astype(float)]))
        p_max = comm.allreduce(float(pf.pressure.max(initial=0.0)), op=MPI.MAX)
        record.snaps.append(np.column_stack([cols, cols[:, 1] > 1e-3 * p_max]))
        # contact: p above 1e-3 of the peak (the softplus law is positive everywhere; Hertz's
        # p reaches 1e-3 p0 within 5e-7 a of the edge)
        touching = pf.pressure > 1e-3 * p_max
        A_c, A_s = comm.allreduce(np.array([pf.weight[touching].sum(),
                                            pf.weight[touching & pf.slipping].sum()]),
                                  op=MPI.SUM)
        stick = float(np.sqrt(max(1.0 - A_s / A_c, 0.0))) if A_c > 0 else float("nan")
        # the front estimates, on the gathered points (the same arrays on every rank)
        w_g, p_g, t_g, slip_g = cols[:, 0], cols[:, 1], cols[:, 2:4], cols[:, 4] > 0.5
        r_g = np.hypot(x_near[:, 0], x_near[:, 1])
        on = p_g > 1e-3 * p_max
        cf = contact_front(r_g, p_g, w_g, on, band=front_band)
        sf = stick_front(r_g, p_g, np.linalg.norm(t_g, axis=1), mu, w_g, on & ~slip_g,
                         on & slip_g, band=front_band)
        si = stick_front(r_g, p_g, np.linalg.norm(t_g, axis=1), mu, w_g, on & ~slip_g,
                         on & slip_g, band=front_band, inside_slip=True)
        ratio = sf.radius / cf.radius if cf.radius > 0 else float("nan")
        ratio_in = si.radius / cf.radius if cf.radius > 0 else float("nan")
        record.rows.append((inc.load_factor, problem.scales["shear"] * slide, 2.0 * R[2],
                            2.0 * R[0], stick, 2.0 * A_c, 2.0 * inc.dissipation,
                            inc.newton_total, ratio, sf.radius, cf.radius, sf.residual,
                            sf.n_misplaced, ratio_in))
        record.x_near = x_near
    solver.destroy()
    rows, snaps, x_near = record.rows, record.snaps, record.x_near
    t, s, P, Q, stick, area, D, newton, front, c_r, a_r, res, mis, front_in = \
        (np.array(c) for c in zip(*rows))
    points = _snapshot(snaps, x_near)
    return MindlinRun(t=t, slide=s, P=P, Q=Q, stick=stick, contact_area=area, dissipation=D,
                      newton=newton, a=hertz_radius(P[-1], radius, E_star), G=G, nu=nu, mu=mu,
                      dofs=problem.num_dofs, cycle_start=prog.cycle_start,
                      shear_steps=shear_steps, stick_front=front,
                      stick_front_inside=front_in, stick_radius=c_r,
                      contact_radius=a_r, front_residual=res, front_misplaced=mis.astype(int),
                      points=points)
