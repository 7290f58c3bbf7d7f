"""A rough joint under fretting: normal preload, then tangential displacement cycles.

Two blocks (lx x ly x h each, P1 or P2 tetrahedra) touch on z = 0 through the paper's rough
interface (spectral moments of section 9.2, orthotropic slip-hardening friction of case (b):
mu rising from 0.25 to 0.5 with the accumulated slip, kT = 0.7 kN). The lower block is clamped
at its bottom; the upper block's top carries the preload P (channel ``preload``) and is driven
in x by u_x = a w(t) (channel ``cyclic``, triangle wave), u_y, u_z free. Per amplitude a, the
run reports every increment (u_x, the reaction F_x, the dissipation) and per cycle the loop
energy, the interface dissipation and the secant stiffness (``rough_contact.solver.program``).

Expected shape (Mindlin–Deresiewicz for a smooth contact; here the rough interface): at small
amplitude only the edges micro-slip and the energy per cycle grows like a^3 (slope 3 on log-log);
at large amplitude the joint slides and the energy grows like a (slope 1); slip hardening makes
the first cycles dissipate more than the later ones (shakedown).

Units: mm, N, MPa (amplitudes given in um at the API).
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from rough_contact.fem.compat import vector_space
from rough_contact.fem.problem import Material
from rough_contact.io import CsvRecorder
from rough_contact.scenes import flat_punch
from rough_contact.scenes.defaults import quadrature_degree
from rough_contact.scenes.setup import clamped_pair, preload_then_drive
from rough_contact.scenes.meshes.blocks import two_blocks
from rough_contact.solver.checkpoint import has_checkpoint
from rough_contact.solver.loading import load_path
from rough_contact.solver.program import cycle_summary, preload_then_cyclic
from rough_contact.solver.snes import SNESSolver
from rough_contact.validation import check_scalar

__all__ = ["FrettingRun", "PreloadStiffness", "run_amplitude", "run"]


_SCENES: dict = {}   # meshes built by run_amplitude, per parameters and communicator

LOOP_COLUMNS = ("pseudo_time", "u_x_mm", "F_x_N", "F_z_contact_N", "dissipation_Nmm",
                "n_slipping", "n_points", "newton_its_spent")


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
        newton: Newton iterations spent (all increments).
        cycles: per cycle (``rough_contact.solver.program.cycle_summary``): cycle, loop_energy
            [N mm], dissipated [N mm], secant_stiffness [N/mm].
        normal: the tabulated normal law (to reuse for other amplitudes).
        solved: increments solved by this call.
        k_normal, k_tangential: interface normal and tangential stiffness at the end of the
            preload, int dp/dg dA and int dt_x/ds_x dA [N/mm] (a restart past the preload
            reports the checkpointed run's values; NaN only when the preload was not reached).
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
    newton: int
    cycles: list
    normal: object
    solved: int
    k_normal: float
    k_tangential: float


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
                  pressure=10.0, cycles=2, steps_per_cycle=16, preload_steps=2, normal=None,
                  comm=MPI.COMM_WORLD, verbose=False, loop_csv=None, checkpoint=None,
                  restart=None, stop_after=None) -> FrettingRun:
    """Preload to ``pressure`` [MPa] nominal, then ``cycles`` tangential cycles of amplitude
    ``amplitude_um`` [um]. Collective; returns identical results on every rank.

    ``loop_csv``: file receiving one row per increment (``LOOP_COLUMNS``: the hysteresis loop
    and the dissipation). ``checkpoint``: directory receiving a checkpoint per increment (with
    the rows); ``restart``: such a directory to continue from (the rows and ``loop_csv``
    continue); ``stop_after``: stop after this many increments (the result then covers them
    only). ``solved`` in the result: the increments solved by this call; ``k_normal``,
    ``k_tangential``: the interface's normal and tangential stiffness at the end of the preload
    (int dp/dg dA, int dt_x/ds_x dA [N/mm]; kept with the checkpoints, so a restart past the
    preload reports the measured values; NaN only when the run stopped before the preload's end).
    """
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
    prog = preload_then_cyclic(preload_steps, cycles, steps_per_cycle)
    problem = preload_then_drive(scene, V, Material(flat_punch.E, flat_punch.NU), clamp, ci, top,
                                 force, a, "cyclic", prog.channels)
    solver = SNESSolver(problem, prefix="fret_")
    rec = CsvRecorder(loop_csv, LOOP_COLUMNS, comm)
    solved = 0
    k_interface = PreloadStiffness()          # restored with the checkpoint on a restart
    for inc in load_path(problem, solver, prog.times, verbose=verbose, checkpoint=checkpoint,
                         resume=restart, outputs=[rec, k_interface], max_steps=stop_after):
        rec.add((inc.load_factor, problem.scales["cyclic"] * a, problem.reaction(top)[0],
                 inc.contact_force[2], inc.dissipation, inc.n_slipping, inc.n_points,
                 inc.newton_total))
        solved += 1
        if abs(inc.load_factor - 1.0) < 1e-12:         # end of the preload
            k_interface.value = ci.interface_stiffness()
    solver.destroy()
    t, u, fx, fz, d, slip, npts, its = rec.array().T
    return FrettingRun(amplitude_um=amplitude_um, force=force, dofs=problem.num_dofs, t=t, u=u,
                       fx=fx, fz=fz, dissipation=d, slipping=slip.astype(int),
                       n_points=npts.astype(int), newton=int(its.sum()),
                       cycles=cycle_summary(t, prog, u, fx, d), normal=normal, solved=solved,
                       k_normal=float(k_interface.value[0]),
                       k_tangential=float(k_interface.value[1]))


def run(amplitudes_um=(0.3, 0.5, 0.7, 1.0, 2.0, 4.0), outdir="results/fretting", plot=True,
        comm=MPI.COMM_WORLD, checkpoint=None, restart=None, **kwargs) -> list:
    """All amplitudes; returns a list of :class:`FrettingRun`; writes ``cycles.csv``,
    ``loop_a<amplitude>um.csv`` (per increment) and PNGs in ``outdir``. Collective.

    ``checkpoint``: directory receiving one checkpoint directory per amplitude; ``restart``: such
    a directory: finished amplitudes are read back from their last checkpoint (no solve), an
    unfinished one continues, the others run (and checkpoint into ``restart``).
    """
    results, normal = [], None
    if restart is not None:
        checkpoint = restart
    for amp in amplitudes_um:
        ck = None if checkpoint is None else os.path.join(checkpoint, f"a{amp:g}um")
        again = ck if restart is not None and has_checkpoint(ck, comm) else None
        r = run_amplitude(amp, normal=normal, comm=comm, checkpoint=ck, restart=again,
                          loop_csv=os.path.join(outdir, f"loop_a{amp:g}um.csv"), **kwargs)
        normal = r.normal
        last = r.cycles[-1]
        if not results:
            PETSc.Sys.Print(f"  preloaded joint: interface normal stiffness {r.k_normal:.4e} "
                            f"N/mm, tangential {r.k_tangential:.4e} N/mm (before slip)",
                            comm=comm)
        PETSc.Sys.Print(f"  a = {amp:8.4g} um: {r.dofs} DOFs, Newton {r.newton}, energy per "
                        f"cycle {last['loop_energy']:.4e} N mm (interface {last['dissipated']:.4e}), "
                        f"secant stiffness {last['secant_stiffness']:.4e} N/mm, max |Fx|/P "
                        f"{np.abs(r.fx).max() / r.force:.3f}", comm=comm)
        results.append(r)
    if comm.rank == 0:
        os.makedirs(outdir, exist_ok=True)
        path = os.path.join(outdir, "cycles.csv")
        with open(path + ".tmp", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["amplitude_um", "cycle", "loop_energy_Nmm", "dissipated_Nmm",
                        "secant_stiffness_N_per_mm"])
            for r in results:
                for c in r.cycles:
                    w.writerow([r.amplitude_um, c["cycle"], c["loop_energy"], c["dissipated"],
                                c["secant_stiffness"]])
        os.replace(path + ".tmp", path)
        if plot:
            _plot(results, outdir)
    return results


def _plot(results, outdir):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from rough_contact.io import plotting

    fig = Figure(figsize=(11, 4.4))
    FigureCanvasAgg(fig)
    ax0, ax1 = fig.subplots(1, 2)
    for r in results:
        ax0.plot(r.u * 1e3 / r.amplitude_um, r.fx / r.force, lw=1,
                 label=f"a = {r.amplitude_um:g} um")
    ax0.set_xlabel("u_x / a")
    ax0.set_ylabel("F_x / P")
    ax0.set_title("hysteresis loops (all cycles)", fontsize=9)
    ax0.legend(fontsize=7)
    amp = np.array([r.amplitude_um for r in results])
    energy = np.array([r.cycles[-1]["loop_energy"] for r in results])
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
    plotting.plot_hysteresis(results[-1].u, results[-1].fx,
                             path=os.path.join(outdir, "loop_largest.png"))
