"""A cylinder (a bolt head, a pin) standing on a block, meshed separately, under the rough law.

The scene a user copies for parts meshed independently (``cylinder_on_block``: the cylinder's
mesh finer than the block's, no common surface mesh), paired by segment-to-segment (mortar)
integration: the cylinder's base is the first contact surface (it lies within the block's top).
The interface is the paper's rough surface (section 9.2 spectral moments, elastic asperities)
with orthotropic slip-hardening friction (case (b): mu from 0.25 to 0.5 with accumulated slip,
grain along x). The block is clamped at its bottom. The cylinder's top carries the preload P
(channel ``preload``: ramped in ``preload_steps`` increments, then held) and is then moved
tangentially by u_x = s (channel ``shear``: 0 during the preload, then ramped to ``slide``
in ``shear_steps`` increments; u_y, u_z free). The cylinder is held only by the interface
(a seating spring helps the first Newton steps, see ``ContactProblem(seating_tag=)``).

Checked at every converged increment: the interface force on the cylinder balances the
preload in z and the reaction of the prescribed top displacement in x, to 1e-8 of P.

Cycles (:func:`run_cycles`, issue 23: a normal law that remembers asperity plasticity):
``mode="normal"`` cycles the normal load between ``low`` P and P (force control, the top's u_x
held at 0); ``mode="tangential"`` holds the bolt's stretch (the top's u_z prescribed: the value
that carries P under force control, found by a force-controlled preload first) and cycles
u_x = a w(t) (triangle wave); the clamping force is then whatever the interface carries.

Units: mm, N, MPa (the slide given in um at the API).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.boundary import SurfaceMean
from rough_contact.fem.compat import vector_space
from rough_contact.fem.problem import ContactProblem, Material, PrescribedDisplacement
from rough_contact.scenes import flat_punch
from rough_contact.scenes.defaults import GRAIN_X, SEATING_STIFFNESS, quadrature_degree
from rough_contact.scenes.setup import clamped_pair, preload_then_drive
from rough_contact.scenes.meshes.blocks import cylinder_on_block
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import (LoadProgram, cycle_boundaries, cycle_summary,
                                         preload_then_cyclic, preload_then_normal_cycles)
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_integer, check_scalar

__all__ = ["BoltIncrement", "BoltHeadRun", "program", "run", "BoltCyclesRun", "run_cycles"]


@dataclass(frozen=True)
class BoltIncrement:
    """One converged increment of :func:`run`.

    Attributes:
        t: pseudo-time (preload over [0, 1], slide over [1, 2]).
        u_x: prescribed slide of the cylinder's top [mm].
        F_z: normal force of the block on the cylinder (up) [N].
        F_x: friction force resisting the slide [N].
        real_area: real contact area [mm^2].
        dissipation: cumulative interface dissipation [N mm].
        slip_fraction: slipping nominal area / nominal area [-].
        balance: force-balance defect / P [-].
        newton: Newton iterations spent so far.
    """

    t: float
    u_x: float
    F_z: float
    F_x: float
    real_area: float
    dissipation: float
    slip_fraction: float
    balance: float
    newton: int


@dataclass(frozen=True)
class BoltHeadRun:
    """Result of :func:`run` (identical on every rank).

    Attributes:
        P: preload [N].
        dofs: global number of DOFs.
        points: global number of interface points.
        pairing: the pairing used ("mortar", "projection").
        rows: the increments (:class:`BoltIncrement`).
    """

    P: float
    dofs: int
    points: int
    pairing: str
    rows: list


def program(preload_steps: int, shear_steps: int) -> LoadProgram:
    """``preload`` ramps to 1 over t in [0, 1] and holds; ``shear`` ramps 0 -> 1 over [1, 2]."""
    def ramp(t):
        return min(max(t, 0.0), 1.0)

    times = [(i + 1) / preload_steps for i in range(preload_steps)]
    times += [1.0 + (i + 1) / shear_steps for i in range(shear_steps)]
    return LoadProgram({"preload": ramp, "shear": lambda t: ramp(t - 1.0)}, times)


def run(pressure=10.0, slide_um=2.0, radius=5.0, height=5.0, size_cylinder=1.0,
        size_block=1.6, order=1, pairing="mortar", preload_steps=2, shear_steps=4,
        comm=MPI.COMM_WORLD, verbose=True) -> BoltHeadRun:
    """Preload the cylinder to ``pressure`` [MPa] nominal on its base, then slide its top by
    ``slide_um`` [um]. Collective; returns the per-increment table (:class:`BoltHeadRun`,
    identical on every rank).

    Raises:
        ValueError: bad sizes or loads (named with their value and range).
        AssertionError: the force balance is violated by more than 1e-8 of P at an increment.
    """
    check_scalar("pressure", pressure, lo=0.0, unit="MPa")
    slide = check_scalar("slide", slide_um, lo=0.0, lo_open=False, unit="um") * 1e-3
    for name, n in (("preload_steps", preload_steps), ("shear_steps", shear_steps)):
        check_integer(name, n, lo=1)
    scene = cylinder_on_block(radius=radius, height=height, size_cylinder=size_cylinder,
                              size_block=size_block, order=order, comm=comm)
    V = vector_space(scene.mesh, order)
    P = pressure * np.pi * radius**2
    law, _ = flat_punch.make_law(comm, case="b", normal_law="elastic",
                                 seating_pressure=pressure / preload_steps)
    clamp, interface = clamped_pair(scene, V, law, grain_direction=GRAIN_X,
                                    quadrature_degree=quadrature_degree(order), pairing=pairing)
    top = scene.tag("cylinder_top")
    prog = program(preload_steps, shear_steps)
    problem = preload_then_drive(scene, V, Material(flat_punch.E, flat_punch.NU), clamp,
                                 interface, top, P, slide, "shear", prog.channels)
    solver = SNESSolver(problem, prefix="bolt_")
    rows = []
    if verbose:
        PETSc.Sys.Print(f"{scene.mesh.topology.index_map(3).size_global} cells, "
                        f"{problem.num_dofs} DOFs, pairing {interface.pairing_used}, "
                        f"{interface.n_points_global} interface points, P = {P:.1f} N")
        PETSc.Sys.Print("N = normal force of the block on the cylinder, Q = friction force "
                        "resisting the slide")
        PETSc.Sys.Print(f"{'t':>5} {'u_x um':>7} {'N [N]':>9} {'Q [N]':>8} {'Q/N':>7} "
                        f"{'slip %':>6} {'A_r mm2':>8} {'D N mm':>9} {'balance':>8} {'Newton':>6}")
    for inc in load_path(problem, solver, prog.times, verbose=False):
        F = inc.contact_force                                 # on the cylinder
        Rx = problem.reaction(top)[0]                         # on the cylinder's top
        applied_z = -P * problem.scales["preload"]
        balance = max(abs(F[2] + applied_z), abs(F[0] + Rx)) / P
        s = interface.summary()
        # F_z: normal force on the cylinder (up); F_x: friction force resisting the slide
        row = BoltIncrement(t=inc.load_factor, u_x=problem.scales["shear"] * slide, F_z=F[2],
                            F_x=-F[0], real_area=inc.real_area, dissipation=inc.dissipation,
                            slip_fraction=s.slipping_area / s.nominal_area, balance=balance,
                            newton=inc.newton_total)
        rows.append(row)
        if verbose:
            PETSc.Sys.Print(f"{row.t:5.2f} {1e3 * row.u_x:7.3f} {row.F_z:9.2f} "
                            f"{row.F_x:8.2f} {row.F_x / row.F_z:7.3f} "
                            f"{100 * row.slip_fraction:6.1f} {row.real_area:8.4f} "
                            f"{row.dissipation:9.3e} {balance:8.1e} {row.newton:6d}")
        assert balance <= 1e-8, f"force balance violated at t = {inc.load_factor}: {balance:.3e}"
    solver.destroy()
    return BoltHeadRun(P=P, dofs=problem.num_dofs, points=interface.summary().n_points,
                       pairing=interface.pairing_used, rows=rows)


@dataclass(frozen=True)
class BoltCyclesRun:
    """Result of :func:`run_cycles` (identical on every rank). Arrays: one entry per increment.

    Attributes:
        mode: "normal" (normal load cycles) or "tangential" (u_x cycles at a fixed stretch).
        P: preload [N] (the peak of the normal cycles; the force-controlled preload that fixed
            the stretch in tangential mode).
        stretch: the top's prescribed downward u_z in tangential mode [mm] (NaN in normal mode).
        dofs: global number of DOFs.
        t: pseudo-times.
        u_x: the top's u_x [mm].
        approach: -mean u_z of the cylinder's top [mm].
        load: applied normal force (normal mode; the reaction in tangential mode) [N].
        F_z: normal force of the block on the cylinder (up) [N] (the clamping force).
        F_x: friction force resisting the slide, -F_x of the interface on the cylinder [N].
        dissipation: cumulative frictional dissipation [N mm].
        normal_dissipation: cumulative normal hysteresis [N mm] (0 for a reversible law).
        slip_fraction: slipping area / area in contact [-].
        contact_fraction: area in contact / nominal area [-].
        boundaries, cycles: the complete cycles (``cycle_summary`` of (approach, load) in
            normal mode, of (u_x, reaction F_x of the top) in tangential mode; with
            ``normal_dissipated``).
        normal: the normal law used.
        wall_time: seconds.
    """

    mode: str
    P: float
    stretch: float
    dofs: int
    t: np.ndarray
    u_x: np.ndarray
    approach: np.ndarray
    load: np.ndarray
    F_z: np.ndarray
    F_x: np.ndarray
    dissipation: np.ndarray
    normal_dissipation: np.ndarray
    slip_fraction: np.ndarray
    contact_fraction: np.ndarray
    boundaries: np.ndarray
    cycles: list
    normal: object
    wall_time: float

    def table(self) -> str:
        """One line per cycle: normal hysteresis, frictional dissipation, the clamping force
        and the slipping share at the cycle's end."""
        lines = [f"  {'cycle':>5} {'D_normal [N mm]':>16} {'D_friction [N mm]':>18} "
                 f"{'F_z end [N]':>12} {'slip % max':>10}"]
        for c in self.cycles:
            span = slice(c["start"] + 1, c["end"] + 1)
            lines.append(f"  {c['cycle']:5d} {c['normal_dissipated']:16.6e} "
                         f"{c['dissipated']:18.6e} {self.F_z[c['end']]:12.6f} "
                         f"{100 * self.slip_fraction[span].max():10.2f}")
        return "\n".join(lines)


def run_cycles(mode="normal", *, pressure=10.0, low=0.1, amplitude_um=1.0, cycles=5,
               steps_per_cycle=8, preload_steps=2, radius=5.0, height=5.0, size_cylinder=1.0,
               size_block=1.6, order=1, pairing="mortar", case="b", normal_law="elastic",
               normal=None, comm=MPI.COMM_WORLD, progress=True,
               prefix="boltc_") -> BoltCyclesRun:
    """Normal or tangential load cycles of the bolt head (module doc). Collective.

    ``mode="normal"``: the preload ramps to ``low`` P (``preload_steps``), then ``cycles``
    cycles low P -> P -> low P (``preload_then_normal_cycles``), u_x of the top held at 0.
    ``mode="tangential"``: a force-controlled preload to P finds the stretch (the top's mean
    u_z); then a second run prescribes that u_z uniformly on the top (ramped in
    ``preload_steps``) and cycles u_x between +-``amplitude_um`` (``preload_then_cyclic``,
    triangle). ``normal_law`` / ``normal``: as ``flat_punch.make_law`` (e.g. a prebuilt
    ``HistoryNormalLaw``); ``case``: friction case or "none".
    """
    t0 = MPI.Wtime()
    if mode not in ("normal", "tangential"):
        raise ValueError(f"mode = {mode!r} is invalid: it must be 'normal' or 'tangential'")
    check_scalar("pressure", pressure, lo=0.0, unit="MPa")
    a = check_scalar("amplitude", amplitude_um, lo=0.0, unit="um") * 1e-3
    scene = cylinder_on_block(radius=radius, height=height, size_cylinder=size_cylinder,
                              size_block=size_block, order=order, comm=comm)
    P = pressure * np.pi * radius**2
    seat = pressure * (low if mode == "normal" else 1.0) / preload_steps
    law, normal = flat_punch.make_law(comm, case=case, normal_law=normal_law,
                                      seating_pressure=seat, normal=normal)
    top = scene.tag("cylinder_top")
    material = Material(flat_punch.E, flat_punch.NU)

    def interface_and_clamp(V):
        return clamped_pair(scene, V, law, grain_direction=GRAIN_X,
                            quadrature_degree=quadrature_degree(order), pairing=pairing)

    stretch = float("nan")
    if mode == "normal":
        prog = preload_then_normal_cycles(preload_steps, cycles, steps_per_cycle, low)
        V = vector_space(scene.mesh, order)
        clamp, ci = interface_and_clamp(V)
        problem = preload_then_drive(scene, V, material, clamp, ci, top, P, 0.0, "cyclic",
                                     prog.channels)
    else:
        # the stretch that carries P: a force-controlled preload (same law, a problem of its own)
        V = vector_space(scene.mesh, order)
        clamp, ci = interface_and_clamp(V)
        pre = program(preload_steps, 1)
        problem = preload_then_drive(scene, V, material, clamp, ci, top, P, 0.0, "shear",
                                     pre.channels)
        solver = SNESSolver(problem, prefix=prefix + "pre_")
        for _ in load_path(problem, solver, pre.times[:preload_steps], verbose=False):
            pass
        stretch = -SurfaceMean(problem.u, scene.facet_tags, top, 2)()
        solver.destroy()
        prog = preload_then_cyclic(preload_steps, cycles, steps_per_cycle, shape="triangle")
        V = vector_space(scene.mesh, order)
        clamp, ci = interface_and_clamp(V)
        problem = ContactProblem(
            V, material, [clamp], [], facet_tags=scene.facet_tags, interface=ci,
            seating_tag=ci.first_tag, seating_stiffness=SEATING_STIFFNESS,
            prescribed=[PrescribedDisplacement(top, (0.0, 0.0, -stretch), (2,), "preload"),
                        PrescribedDisplacement(top, (a, 0.0, 0.0), (0,), "cyclic")],
            programs=prog.channels)
    solver = SNESSolver(problem, prefix=prefix)
    top_uz = SurfaceMean(problem.u, scene.facet_tags, top, 2)
    rows = []
    for inc in load_path(problem, solver, prog.times, verbose=False):
        F = inc.contact_force                                 # on the cylinder
        R = problem.reaction(top)
        s = ci.summary()
        load = P * problem.scales["preload"] if mode == "normal" else -R[2]
        rows.append((inc.load_factor, problem.scales["cyclic"] * a, -top_uz(), load, F[2],
                     -F[0], R[0], inc.dissipation, inc.normal_dissipation,
                     s.slipping_area / s.contact_area if s.contact_area > 0 else 0.0,
                     s.contact_area / s.nominal_area))
        k = inc.load_factor - prog.cycle_start
        if progress and k > 0.5 and abs(k - round(k)) < 1e-9:
            PETSc.Sys.Print(f"  {mode} cycle {int(round(k))}/{cycles}: F_z = {F[2]:.6g} N, "
                            f"normal hysteresis {inc.normal_dissipation:.6e} N mm, friction "
                            f"{inc.dissipation:.6e} N mm (cumulative)  "
                            f"[{MPI.Wtime() - t0:.1f} s]", comm=comm)
    solver.destroy()
    t, ux, w, load, fz, fx, rx, d, dn, slip, contact = np.array(rows).T
    if mode == "normal":
        summary = cycle_summary(t, prog, w, load, d, normal_dissipation=dn)
    else:
        summary = cycle_summary(t, prog, ux, rx, d, normal_dissipation=dn)
    return BoltCyclesRun(mode=mode, P=P, stretch=stretch, dofs=problem.num_dofs, t=t, u_x=ux,
                         approach=w, load=load, F_z=fz, F_x=fx, dissipation=d,
                         normal_dissipation=dn, slip_fraction=slip, contact_fraction=contact,
                         boundaries=cycle_boundaries(t, prog), cycles=summary, normal=normal,
                         wall_time=MPI.Wtime() - t0)
