"""A rough joint under fretting: normal preload, then tangential displacement cycles.

Two blocks (lx x ly x h each, P1 or P2 tetrahedra) touch on z = 0 through the paper's rough
interface (spectral moments of section 9.2, orthotropic slip-hardening friction of case (b):
mu rising from 0.25 to 0.5 with the accumulated slip, kT = 0.7 kN). The lower block is clamped
at its bottom; the upper block's top carries the preload P (channel ``preload``) and is driven
in x by u_x = delta* w(t) (channel ``cyclic``; w a sine by default, as a fretting rig drives it,
or a triangle wave), u_y, u_z free. delta* is the displacement amplitude of the top, away from
the contact, as a fretting rig measures it (bulk compliance included).

Per amplitude the run records every increment (u_x, the reaction F_x, the dissipation, the
slipping share of the contact area), prints one line per cycle (rank 0, flushed), writes the
interface fields per increment (``interface.xdmf``) and summarises every cycle of the program
(its cycle boundaries, ``rough_contact.solver.program.cycle_boundaries``): the loop energy E_d,
the amplitudes F* and delta*, the energy ratio A = E_d / (4 F* delta*) and the largest slipping
share. The last cycle of each amplitude is what a fretting study reports (:class:`CycleReport`):
the regime is "stick" when no point slips, "partial slip" while a stuck part of the contact
remains at the extremes, "gross slip" when the whole contact area slips.

Expected shape: nothing slips below the micro-slip onset (A = 0, an elastic line); slip spreads
from the edges of the joint (partial slip, A small) until the whole interface slips (gross
slip); beyond it the loop tends to the parallelogram of an elastic joint in series with a
sliding one, A -> 1 - F* / (k delta*) (k the joint's stick stiffness), and to 1 for
delta* >> F* / k. A Hertzian (sphere-on-flat) contact reaches gross slip at A = 0.2
(Mindlin–Deresiewicz, ``rough_contact.references.fretting_cycle``); the flat joint's nearly
uniform shear makes its slip zone sweep the interface over a narrow range of amplitudes, at a
smaller A (docs/loading.md). Slip hardening makes the first cycles dissipate more than the
later ones (shakedown).

Units: mm, N, MPa (amplitudes given in um at the API).
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.boundary import SurfaceMean
from rough_contact.fem.compat import vector_space
from rough_contact.fem.problem import Material
from rough_contact.io import CsvRecorder
from rough_contact.io.files import atomic_write_text
from rough_contact.io.interface_output import InterfaceWriter
from rough_contact.scenes import flat_punch
from rough_contact.scenes.defaults import quadrature_degree
from rough_contact.scenes.setup import clamped_pair, preload_then_drive
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.solver.checkpoint import has_checkpoint
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import (cycle_boundaries, cycle_summary, preload_then_cyclic,
                                         preload_then_normal_cycles)
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_scalar

__all__ = ["FrettingRun", "CycleReport", "PreloadStiffness", "run_amplitude", "run",
           "REPORT_COLUMNS", "NormalCyclesRun", "run_normal_cycles", "NORMAL_COLUMNS"]


_SCENES: dict = {}   # meshes built by run_amplitude, per parameters and communicator

LOOP_COLUMNS = ("pseudo_time", "u_x_mm", "F_x_N", "F_z_contact_N", "dissipation_Nmm",
                "n_slipping", "n_points", "newton_its_spent", "slip_area_fraction")

REPORT_COLUMNS = ("amplitude_um", "cycle", "delta_um", "force_amplitude_N", "energy_Nmm",
                  "interface_dissipation_Nmm", "energy_ratio", "slip_fraction", "regime",
                  "slipping_increments")
"""Columns of ``fretting_map.csv``: one row per amplitude, its last cycle (:class:`CycleReport`)."""

GROSS_SLIP = 1.0 - 1e-9   # slipping share of the contact area from which no stuck part is left


@dataclass(frozen=True)
class CycleReport:
    """What a fretting study reports of one cycle (normally the last, the steadiest).

    Attributes:
        amplitude_um: prescribed displacement amplitude [um].
        cycle: the program's cycle number (1-based).
        delta_um: delta*, half the peak-to-peak u_x of the cycle [um].
        force_amplitude: F*, half the peak-to-peak F_x of the cycle [N].
        energy: E_d, the loop area (trapezoidal integral of F_x du_x over the cycle) [N mm].
        dissipated: the interface's own dissipation over the cycle [N mm] (equal to E_d in a
            steady cycle).
        energy_ratio: A = E_d / (4 F* delta*) [-].
        slip_fraction: largest slipping share of the contact area over the cycle's increments
            (slipping area / area in contact) [-].
        regime: "stick" (nothing slips), "partial slip", "gross slip" (the whole contact area
            slips at some instant of the cycle: ``slip_fraction >= GROSS_SLIP``).
        slipping_increments: increments of the cycle with slipping points (how finely the
            slipping part of the loop is resolved).
    """

    amplitude_um: float
    cycle: int
    delta_um: float
    force_amplitude: float
    energy: float
    dissipated: float
    energy_ratio: float
    slip_fraction: float
    regime: str
    slipping_increments: int

    def row(self) -> tuple:
        """The values in the order of ``REPORT_COLUMNS``."""
        return (self.amplitude_um, self.cycle, self.delta_um, self.force_amplitude, self.energy,
                self.dissipated, self.energy_ratio, self.slip_fraction, self.regime,
                self.slipping_increments)


def regime(slip_fraction: float) -> str:
    """"stick", "partial slip" or "gross slip" from the largest slipping share of the contact
    area over a cycle."""
    f = check_scalar("slip_fraction", slip_fraction, lo=0.0, lo_open=False, hi=1.0 + 1e-12)
    return "stick" if f == 0.0 else "gross slip" if f >= GROSS_SLIP else "partial slip"


@dataclass(frozen=True)
class FrettingRun:
    """Result of :func:`run_amplitude` (identical on every rank). Arrays have one entry per
    increment of this run (the restarted part included when continued from a checkpoint).

    Attributes:
        amplitude_um: tangential amplitude a [um].
        force: preload P [N].
        dofs: global number of DOFs.
        t: pseudo-time of each increment (``preload_then_cyclic``).
        u: prescribed u_x of the top [mm].
        fx: reaction F_x of the top [N].
        fz: normal interface force [N].
        dissipation: cumulative interface dissipation [N mm].
        slipping: slipping interface points (int).
        n_points: interface points (int).
        slip_fraction: slipping area / area in contact [-].
        newton: Newton iterations spent (all increments).
        boundaries: the program's complete cycles among the increments
            (``rough_contact.solver.program.cycle_boundaries``): cycle k spans the increments
            ``boundaries[k - 1] .. boundaries[k]``.
        cycles: per cycle (``rough_contact.solver.program.cycle_summary``): cycle, loop_energy
            [N mm], dissipated [N mm], delta_amplitude [mm], force_amplitude [N],
            energy_ratio [-], secant_stiffness [N/mm], start, end.
        normal: the tabulated normal law (to reuse for other amplitudes).
        solved: increments solved by this call.
        k_normal, k_tangential: interface normal and tangential stiffness at the end of the
            preload, int dp/dg dA and int dt_x/ds_x dA [N/mm] (a restart past the preload
            reports the checkpointed run's values; NaN only when the preload was not reached).
        steps_per_cycle: increments per cycle of the program.
        wall_time: seconds spent in this call.
    """

    amplitude_um: float
    force: float
    dofs: int
    t: np.ndarray
    u: np.ndarray
    fx: np.ndarray
    fz: np.ndarray
    dissipation: np.ndarray
    slipping: np.ndarray
    n_points: np.ndarray
    slip_fraction: np.ndarray
    newton: int
    boundaries: np.ndarray
    cycles: list
    normal: object
    solved: int
    k_normal: float
    k_tangential: float
    steps_per_cycle: int
    wall_time: float

    def report(self, cycle: int = -1) -> CycleReport:
        """The fretting figures of one cycle (default the last complete one)."""
        if not self.cycles:
            raise ValueError(f"the run at {self.amplitude_um:g} um has no complete cycle "
                             f"({len(self.t)} increments)")
        c = self.cycles[cycle]
        span = slice(c["start"] + 1, c["end"] + 1)        # the cycle's own increments
        slip = float(self.slip_fraction[span].max())
        return CycleReport(amplitude_um=self.amplitude_um, cycle=c["cycle"],
                           delta_um=c["delta_amplitude"] * 1e3,
                           force_amplitude=c["force_amplitude"], energy=c["loop_energy"],
                           dissipated=c["dissipated"], energy_ratio=c["energy_ratio"],
                           slip_fraction=slip, regime=regime(min(slip, 1.0)),
                           slipping_increments=int(np.count_nonzero(self.slipping[span])))


def _cycle_line(amplitude_um, c, slip, n_cycles, seconds) -> str:
    return (f"  a = {amplitude_um:g} um  cycle {c['cycle']}/{n_cycles}: F* = "
            f"{c['force_amplitude']:.4g} N, E_d = {c['loop_energy']:.4e} N mm (interface "
            f"{c['dissipated']:.4e}), A = {c['energy_ratio']:.4f}, slipping "
            f"{100 * slip:.1f} % of the contact area  [{seconds:.1f} s]")


class PreloadStiffness:
    """The interface stiffness at the end of the preload, kept with the checkpoints (a
    :class:`~rough_contact.solver.checkpoint.ResumableOutput`): a run restarted past the
    preload reports the value the checkpointed run measured.

    Attributes:
        value: (3,) int dp/dg dA, int dt_x/ds_x dA, int dt_y/ds_y dA [N/mm]; NaN until measured.
    """

    def __init__(self):
        self.value = np.full(3, np.nan)

    def checkpoint_state(self) -> np.ndarray:
        return self.value.copy()

    def restore(self, state) -> None:
        self.value = np.array(state, dtype=float).reshape(3)


def run_amplitude(amplitude_um: float, *, size=2.0, height=1.0, mesh_size=0.5, order=1,
                  pressure=10.0, cycles=2, steps_per_cycle=32, wave="sine", preload_steps=2,
                  normal=None, comm=MPI.COMM_WORLD, verbose=False, progress=True, loop_csv=None,
                  interface_dir=None, overwrite=False, checkpoint=None, restart=None,
                  stop_after=None, prefix="fret_") -> FrettingRun:
    """Preload to ``pressure`` [MPa] nominal, then ``cycles`` tangential cycles of amplitude
    ``amplitude_um`` [um] (``wave``: "sine" or "triangle", ``steps_per_cycle`` increments each,
    a multiple of 4). Collective; returns identical results on every rank.

    ``progress``: print one line per cycle (and the end of the preload) on rank 0; ``verbose``:
    also one per increment (``load_path``). ``loop_csv``: file receiving one row per increment
    (``LOOP_COLUMNS``: the hysteresis loop, the dissipation, the slipping share).
    ``interface_dir``: folder receiving ``interface.xdmf``/``interface.h5`` (the interface
    fields per increment, time = the program's pseudo-time; ``overwrite`` replaces an earlier
    run's). ``checkpoint``: directory receiving a checkpoint per increment (with the rows);
    ``restart``: such a directory to continue from (the rows, ``loop_csv`` and the interface
    series continue); ``stop_after``: stop after this many increments (the result then covers
    them only). ``prefix``: PETSc options prefix of the solver. ``solved`` in the result: the
    increments solved by this call; ``k_normal``, ``k_tangential``: the interface's normal and
    tangential stiffness at the end of the preload (int dp/dg dA, int dt_x/ds_x dA [N/mm]; kept
    with the checkpoints, so a restart past the preload reports the measured values; NaN only
    when the run stopped before the preload's end).
    """
    t0 = MPI.Wtime()
    a = check_scalar("amplitude", amplitude_um, lo=0.0, unit="um") * 1e-3
    check_scalar("pressure", pressure, lo=0.0, unit="MPa")
    key = (size, height, mesh_size, order, comm.py2f())
    if key not in _SCENES:     # one build per process: the amplitudes and a resumed run share
        _SCENES[key] = two_blocks(lx=size, ly=size, h1=height, h2=height,  # its partition
                                  mesh_size=mesh_size, order=order, comm=comm)
    scene = _SCENES[key]
    V = vector_space(scene.mesh, order)
    force = pressure * size * size
    law, normal = flat_punch.make_law(comm, case="b", normal_law="elastic",
                                      seating_pressure=pressure / preload_steps, normal=normal)
    clamp, ci = clamped_pair(scene, V, law, quadrature_degree=quadrature_degree(order))
    top = scene.tag("top")
    prog = preload_then_cyclic(preload_steps, cycles, steps_per_cycle, shape=wave)
    problem = preload_then_drive(scene, V, Material(flat_punch.E, flat_punch.NU), clamp, ci, top,
                                 force, a, "cyclic", prog.channels)
    solver = SNESSolver(problem, prefix=prefix)
    rec = CsvRecorder(loop_csv, LOOP_COLUMNS, comm)
    outputs = [rec]
    writer = None
    if interface_dir is not None:
        writer = InterfaceWriter(interface_dir, ci, overwrite=overwrite,
                                 resume=restart is not None)
        outputs.append(writer)
    solved = 0
    k_interface = PreloadStiffness()          # restored with the checkpoint on a restart
    for inc in load_path(problem, solver, prog.times, verbose=verbose, checkpoint=checkpoint,
                         resume=restart, outputs=outputs + [k_interface],
                         max_steps=stop_after):
        s = ci.summary()
        rec.add((inc.load_factor, problem.scales["cyclic"] * a, problem.reaction(top)[0],
                 inc.contact_force[2], inc.dissipation, inc.n_slipping, inc.n_points,
                 inc.newton_total, s.slipping_area / s.contact_area if s.contact_area > 0
                 else 0.0))
        if writer is not None:
            writer.write(inc.load_factor, time=inc.load_factor)
        solved += 1
        if abs(inc.load_factor - 1.0) < 1e-12:         # end of the preload
            k_interface.value = ci.interface_stiffness()
            if progress:
                PETSc.Sys.Print(f"  a = {amplitude_um:g} um  preloaded: P = {force:g} N, "
                                f"{problem.num_dofs} DOFs; interface stiffness normal "
                                f"{k_interface.value[0]:.4e}, tangential "
                                f"{k_interface.value[1]:.4e} N/mm "
                                f"(before slip); then {cycles} cycles x {steps_per_cycle} "
                                f"increments ({wave})  [{MPI.Wtime() - t0:.1f} s]", comm=comm)
        elif progress and inc.load_factor > prog.cycle_start:
            k = inc.load_factor - prog.cycle_start
            if abs(k - round(k)) < 1e-9:                   # a cycle ends with this increment
                rows = rec.array()
                done = cycle_summary(rows[:, 0], prog, rows[:, 1], rows[:, 2], rows[:, 4])
                if done:
                    c = done[-1]
                    slip = float(rows[c["start"] + 1:c["end"] + 1, 8].max())
                    PETSc.Sys.Print(_cycle_line(amplitude_um, c, slip, cycles,
                                                MPI.Wtime() - t0), comm=comm)
    solver.destroy()
    t, u, fx, fz, d, slip, npts, its, frac = rec.array().T
    return FrettingRun(amplitude_um=amplitude_um, force=force, dofs=problem.num_dofs, t=t, u=u,
                       fx=fx, fz=fz, dissipation=d, slipping=slip.astype(int),
                       n_points=npts.astype(int), slip_fraction=frac, newton=int(its.sum()),
                       boundaries=cycle_boundaries(t, prog),
                       cycles=cycle_summary(t, prog, u, fx, d), normal=normal, solved=solved,
                       k_normal=float(k_interface.value[0]),
                       k_tangential=float(k_interface.value[1]),
                       steps_per_cycle=int(steps_per_cycle), wall_time=MPI.Wtime() - t0)


NORMAL_COLUMNS = ("pseudo_time", "load_share", "F_z_applied_N", "approach_mm", "mean_gap_mm",
                  "F_z_contact_N", "F_x_N", "dissipation_Nmm", "normal_dissipation_Nmm",
                  "slip_area_fraction", "contact_area_fraction", "newton_its_spent")
"""Columns of :func:`run_normal_cycles`'s per-increment CSV."""


@dataclass(frozen=True)
class NormalCyclesRun:
    """Result of :func:`run_normal_cycles` (identical on every rank). Arrays: one entry per
    increment.

    Attributes:
        force: peak normal force P [N] (the load cycles between ``low`` P and P).
        low: the minimum of the cycles as a share of P [-].
        dofs: global number of DOFs.
        t: pseudo-time of each increment (``preload_then_normal_cycles``).
        load: applied normal force (pressing, > 0) [N].
        approach: mean downward displacement of the loaded top face, -mean u_z [mm] (the
            work-conjugate of the uniform normal load: its work is int load d(approach)).
        gap: mean interface gap, int g dA / A_nominal [mm] (h = h0 + g).
        fz: normal interface force on the upper block (up) [N].
        fx: reaction F_x of the top (its u_x is held) [N].
        dissipation: cumulative frictional dissipation [N mm].
        normal_dissipation: cumulative normal hysteresis of a law with memory [N mm] (0 for
            a reversible law).
        slip_fraction: slipping area / nominal area [-].
        contact_fraction: area in contact / nominal area [-].
        boundaries: the complete cycles among the increments (``cycle_boundaries``).
        cycles: per cycle (``cycle_summary`` of approach and load): ``loop_energy`` (the work
            of the normal load over the cycle, trapezoidal [N mm]), ``dissipated`` (frictional),
            ``normal_dissipated`` (normal hysteresis), amplitudes, start, end.
        normal: the normal law used (to reuse).
        newton: Newton iterations spent.
        wall_time: seconds spent in this call.
    """

    force: float
    low: float
    dofs: int
    t: np.ndarray
    load: np.ndarray
    approach: np.ndarray
    gap: np.ndarray
    fz: np.ndarray
    fx: np.ndarray
    dissipation: np.ndarray
    normal_dissipation: np.ndarray
    slip_fraction: np.ndarray
    contact_fraction: np.ndarray
    boundaries: np.ndarray
    cycles: list
    normal: object
    newton: int
    wall_time: float

    def table(self) -> str:
        """One line per cycle: normal hysteresis, frictional dissipation, load work, the
        mean gap at the cycle's end."""
        lines = [f"  {'cycle':>5} {'D_normal [N mm]':>16} {'D_friction [N mm]':>18} "
                 f"{'load work [N mm]':>17} {'gap at end [um]':>16} {'slip [%] max':>12}"]
        for c in self.cycles:
            span = slice(c["start"] + 1, c["end"] + 1)
            lines.append(f"  {c['cycle']:5d} {c['normal_dissipated']:16.6e} "
                         f"{c['dissipated']:18.6e} {c['loop_energy']:17.6e} "
                         f"{1e3 * self.gap[c['end']]:16.6f} "
                         f"{100 * self.slip_fraction[span].max():12.2f}")
        return "\n".join(lines)


def run_normal_cycles(*, pressure=10.0, low=0.1, cycles=5, steps_per_cycle=8, shape="triangle",
                      preload_steps=1, size=2.0, height=1.0, mesh_size=0.5, order=1,
                      case="b", normal_law="elastic", normal=None, comm=MPI.COMM_WORLD,
                      verbose=False, progress=True, csv_path=None,
                      prefix="fretn_") -> NormalCyclesRun:
    """Normal load cycles of the fretting joint: the top's u_x held at 0, its normal load
    ramped to ``low`` x P (P = ``pressure`` x the nominal area), then ``cycles`` cycles
    low P -> P -> low P (``rough_contact.solver.program.preload_then_normal_cycles``).
    Collective; returns identical results on every rank.

    With a normal law with memory (``normal_law`` "elasto-plastic-memory", or a prebuilt
    ``normal`` implementing ``HistoryNormalLawProtocol``) the first cycle, which carries the
    first loading to P, dissipates normal hysteresis; later cycles at the same amplitude
    reload along the unloading branch of the same h_min and dissipate none (shakedown of the
    normal hysteresis); the friction may go on dissipating (the Poisson expansion of the
    blocks makes the interface's edges slip). ``case``: the friction case of the punch
    (``flat_punch.FRICTION_CASES``) or "none". ``csv_path``: one row per increment
    (``NORMAL_COLUMNS``).
    """
    t0 = MPI.Wtime()
    check_scalar("pressure", pressure, lo=0.0, unit="MPa")
    prog = preload_then_normal_cycles(preload_steps, cycles, steps_per_cycle, low, shape)
    key = (size, height, mesh_size, order, comm.py2f())
    if key not in _SCENES:
        _SCENES[key] = two_blocks(lx=size, ly=size, h1=height, h2=height,
                                  mesh_size=mesh_size, order=order, comm=comm)
    scene = _SCENES[key]
    V = vector_space(scene.mesh, order)
    force = pressure * size * size
    law, normal = flat_punch.make_law(comm, case=case, normal_law=normal_law,
                                      seating_pressure=pressure * low / preload_steps,
                                      normal=normal)
    clamp, ci = clamped_pair(scene, V, law, quadrature_degree=quadrature_degree(order))
    top = scene.tag("top")
    problem = preload_then_drive(scene, V, Material(flat_punch.E, flat_punch.NU), clamp, ci, top,
                                 force, 0.0, "cyclic", prog.channels)
    solver = SNESSolver(problem, prefix=prefix)
    top_uz = SurfaceMean(problem.u, scene.facet_tags, top, 2)
    rec = CsvRecorder(csv_path, NORMAL_COLUMNS, comm)
    area = ci.nominal_area()
    for inc in load_path(problem, solver, prog.times, verbose=verbose, outputs=[rec]):
        s = ci.summary()
        pf = ci.point_fields()
        gap = comm.allreduce(float(np.dot(ci.point_weights(), pf.gap)), op=MPI.SUM) / area
        share = problem.scales["preload"]
        rec.add((inc.load_factor, share, force * share, -top_uz(), gap, inc.contact_force[2],
                 problem.reaction(top)[0], inc.dissipation, inc.normal_dissipation,
                 s.slipping_area / s.nominal_area, s.contact_area / s.nominal_area,
                 inc.newton_total))
        k = inc.load_factor - prog.cycle_start
        if progress and k > 0.5 and abs(k - round(k)) < 1e-9:
            PETSc.Sys.Print(f"  normal cycle {int(round(k))}/{cycles}: normal hysteresis "
                            f"{inc.normal_dissipation:.6e} N mm, friction "
                            f"{inc.dissipation:.6e} N mm (cumulative)  "
                            f"[{MPI.Wtime() - t0:.1f} s]", comm=comm)
    solver.destroy()
    t, share, load, w, gap, fz, fx, d, dn, slip, contact, its = rec.array().T
    return NormalCyclesRun(force=force, low=float(low), dofs=problem.num_dofs, t=t, load=load,
                           approach=w, gap=gap, fz=fz, fx=fx, dissipation=d,
                           normal_dissipation=dn, slip_fraction=slip, contact_fraction=contact,
                           boundaries=cycle_boundaries(t, prog),
                           cycles=cycle_summary(t, prog, w, load, d, normal_dissipation=dn),
                           normal=normal, newton=int(its.sum()), wall_time=MPI.Wtime() - t0)


def report_table(reports) -> str:
    """The fretting table (one line per amplitude), as the demo prints it."""
    lines = [f"  {'a [um]':>7} {'delta* [um]':>11} {'F* [N]':>8} {'E_d [N mm]':>11} "
             f"{'A [-]':>7} {'slip [%]':>8} {'incr.':>5}  regime"]
    for r in reports:
        lines.append(f"  {r.amplitude_um:7.4g} {r.delta_um:11.4g} {r.force_amplitude:8.4g} "
                     f"{r.energy:11.4e} {r.energy_ratio:7.4f} {100 * r.slip_fraction:8.1f} "
                     f"{r.slipping_increments:5d}  {r.regime}")
    return "\n".join(lines)


def write_report_csv(path: str, reports) -> None:
    """``fretting_map.csv`` (``REPORT_COLUMNS``), written atomically (rank 0 only)."""
    text = io.StringIO(newline="")
    w = csv.writer(text)
    w.writerow(REPORT_COLUMNS)
    for r in reports:
        w.writerow([f"{v:.10g}" if isinstance(v, float) else v for v in r.row()])
    atomic_write_text(path, text.getvalue())


def run(amplitudes_um=(0.3, 0.5, 0.7, 1.0, 2.0, 4.0), outdir="results/fretting", plot=True,
        comm=MPI.COMM_WORLD, checkpoint=None, restart=None, xdmf=True, overwrite=False,
        **kwargs) -> list:
    """All amplitudes; returns a list of :class:`FrettingRun`. Collective. Writes in ``outdir``:

    * ``fretting_map.csv``: per amplitude its last cycle (``REPORT_COLUMNS``: delta*, F*, E_d,
      A, slipping share, regime), atomically; ``cycles.csv``: every cycle of every amplitude;
    * ``loop_a<amplitude>um.csv``: per increment (``LOOP_COLUMNS``);
    * ``a<amplitude>um/interface.xdmf`` (+ ``.h5``): the interface fields per increment
      (``xdmf``; ``overwrite`` replaces an earlier run's);
    * ``fretting.png`` (last loops, energy per cycle), ``fretting_loops.png`` (the last loop of
      each amplitude in N and um), ``fretting_map.png`` (A and the slipping share against the
      amplitude), ``loop_largest.png`` (every cycle of the largest amplitude).

    ``checkpoint``: directory receiving one checkpoint directory per amplitude; ``restart``: such
    a directory: finished amplitudes are read back from their last checkpoint (no solve), an
    unfinished one continues, the others run (and checkpoint into ``restart``). ``kwargs`` go
    to :func:`run_amplitude`.
    """
    results, normal = [], None
    if restart is not None:
        checkpoint = restart
    amps = [check_scalar("amplitude", a, lo=0.0, unit="um") for a in amplitudes_um]
    if not amps:
        raise ValueError("amplitudes_um is empty: give at least one amplitude [um]")
    for i, amp in enumerate(amps):
        ck = None if checkpoint is None else os.path.join(checkpoint, f"a{amp:g}um")
        again = ck if restart is not None and has_checkpoint(ck, comm) else None
        PETSc.Sys.Print(f"Amplitude {i + 1}/{len(amps)}: a = {amp:g} um"
                        + (" (continued from its checkpoint)" if again else ""), comm=comm)
        r = run_amplitude(amp, normal=normal, comm=comm, checkpoint=ck, restart=again,
                          loop_csv=os.path.join(outdir, f"loop_a{amp:g}um.csv"),
                          interface_dir=os.path.join(outdir, f"a{amp:g}um") if xdmf else None,
                          overwrite=overwrite, **kwargs)
        normal = r.normal
        results.append(r)
    reports = [r.report() for r in results]
    PETSc.Sys.Print(f"Fretting (last cycle of each amplitude; A = E_d / (4 F* delta*), slip = "
                    f"largest slipping share of the contact area, incr. = increments with "
                    f"slip):\n{report_table(reports)}", comm=comm)
    if comm.rank == 0:
        os.makedirs(outdir, exist_ok=True)
        write_report_csv(os.path.join(outdir, "fretting_map.csv"), reports)
        text = io.StringIO(newline="")
        w = csv.writer(text)
        w.writerow(["amplitude_um", "cycle", "loop_energy_Nmm", "dissipated_Nmm",
                    "force_amplitude_N", "energy_ratio", "secant_stiffness_N_per_mm"])
        for r in results:
            for c in r.cycles:
                w.writerow([r.amplitude_um, c["cycle"], c["loop_energy"], c["dissipated"],
                            c["force_amplitude"], c["energy_ratio"], c["secant_stiffness"]])
        atomic_write_text(os.path.join(outdir, "cycles.csv"), text.getvalue())
        if plot:
            _plot(results, reports, outdir)
    return results


def stick_stiffness(results) -> float:
    """The joint's stick stiffness [N/mm]: the secant F_x / u_x of the first increment of a
    cycle in which nothing slipped yet (the smallest such u_x among the runs; NaN if none)."""
    best = (np.inf, float("nan"))
    for r in results:
        if r.boundaries.size < 2:
            continue
        i = r.boundaries[0] + 1
        du = r.u[i] - r.u[i - 1]
        if r.slipping[i] == 0 and du != 0 and abs(du) < best[0]:
            best = (abs(du), (r.fx[i] - r.fx[i - 1]) / du)
    return best[1]


def _plot(results, reports, outdir):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from rough_contact.io import plotting
    from rough_contact.references import fretting_energy_ratio

    fig = Figure(figsize=(11, 4.4))
    FigureCanvasAgg(fig)
    ax0, ax1 = fig.subplots(1, 2)
    for r in results:
        s, e = r.boundaries[-2], r.boundaries[-1]
        ax0.plot(r.u[s:e + 1] * 1e3 / r.amplitude_um, r.fx[s:e + 1] / r.force, lw=1,
                 label=f"a = {r.amplitude_um:g} um")
    ax0.set_xlabel("u_x / a")
    ax0.set_ylabel("F_x / P")
    ax0.set_title(f"hysteresis loops (cycle {reports[0].cycle}, the last)", fontsize=9)
    ax0.legend(fontsize=7)
    amp = np.array([r.amplitude_um for r in results])
    energy = np.array([rep.energy for rep in reports])
    ok = energy > 1e-9 * max(energy.max(initial=0.0), 1e-300)   # round-off loops: no slip
    ax1.loglog(amp[ok], energy[ok], "o-", label="last cycle, loop area")
    if ok.sum() >= 2:
        a_ok, e_ok = amp[ok], energy[ok]
        ax1.loglog(a_ok, e_ok[0] * (a_ok / a_ok[0]) ** 3, ":", color="0.5", label="slope 3")
        ax1.loglog(a_ok, e_ok[-1] * (a_ok / a_ok[-1]), "--", color="0.5", label="slope 1")
    for a_no in amp[~ok]:
        ax1.axvline(a_no, color="0.85", lw=0.8)
    if (~ok).any():
        ax1.text(0.02, 0.95, "grey lines: amplitudes without slip (elastic loop)",
                 transform=ax1.transAxes, fontsize=7, va="top")
    ax1.set_xlabel("amplitude a [um]")
    ax1.set_ylabel("energy per cycle [N mm]")
    ax1.legend(fontsize=7)
    ax1.set_title("energy dissipated per cycle vs amplitude", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "fretting.png"), dpi=120)

    # the last loop of every amplitude in physical units, one panel each
    n = len(results)
    cols = min(n, 4)
    rows = -(-n // cols)
    fig = Figure(figsize=(3.2 * cols, 3.0 * rows))
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    for ax, r, rep in zip(axes, results, reports):
        plotting.plot_hysteresis(r.u * 1e3, r.fx, boundaries=r.boundaries, cycles=[rep.cycle],
                                 ax=ax, energy_unit="N um", xlabel="u_x [um]",
                                 ylabel="F_x [N]")
        ax.get_legend().remove()
        ax.set_title(f"a = {rep.amplitude_um:g} um, cycle {rep.cycle}\nA = "
                     f"{rep.energy_ratio:.3f}, {rep.regime}", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "fretting_loops.png"), dpi=120)

    # fretting map: A and the slipping share against the amplitude
    delta = np.array([rep.delta_um for rep in reports])
    ratio = np.array([rep.energy_ratio for rep in reports])
    slip = np.minimum([rep.slip_fraction for rep in reports], 1.0)
    gross = [rep.delta_um for rep in reports if rep.regime == "gross slip"]
    refs = {}
    k = stick_stiffness(results)
    force = np.array([rep.force_amplitude for rep in reports])
    if np.isfinite(k) and len(gross):
        sliding = delta >= min(gross)
        refs["elastic joint + sliding (parallelogram)\n$A = 1 - F^*/(k\\,\\delta^*)$, "
             f"k = {k:.3g} N/mm (gross slip)"] = (delta[sliding], 1.0 - force[sliding] / (
                 k * delta[sliding] * 1e-3), "x")
    if len(gross):
        x = np.geomspace(delta.min(), delta.max(), 200)
        refs["Mindlin-Deresiewicz (sphere on flat)\nwith $\\delta_t$ = first gross slip"] = (
            x, fretting_energy_ratio(x / min(gross)))
    if n >= 1 and np.all(delta > 0):
        plotting.plot_fretting_map(delta, ratio, slip, references=refs,
                                   transition=min(gross) if gross else None,
                                   path=os.path.join(outdir, "fretting_map.png"),
                                   title="fretting map (last cycle of each amplitude)")
    plotting.plot_hysteresis(results[-1].u * 1e3, results[-1].fx,
                             boundaries=results[-1].boundaries, energy_unit="N um",
                             xlabel="u_x [um]", ylabel="F_x [N]",
                             title=f"a = {results[-1].amplitude_um:g} um: every cycle",
                             path=os.path.join(outdir, "loop_largest.png"))
