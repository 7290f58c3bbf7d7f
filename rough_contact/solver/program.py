"""Load programs: several load channels, each scaled by its own function of a pseudo-time.

A program is a set of channel functions ``scale(t)`` and the pseudo-times of its increments.
Loads and prescribed displacements name their channel (``SurfaceLoad(..., channel=)``,
``PrescribedDisplacement(..., channel=)``); ``ContactProblem(..., programs=program.channels)``
makes ``set_load_factor(t)`` scale each channel by its function, and ``load_path(problem, solver,
program.times)`` steps through the program with the usual cutback (a cutback halves the
pseudo-time increment, so every channel follows its own function between the increments).

Programs built here (t is dimensionless; the nominal loads are those of the channels):

* :func:`proportional`: one channel ``"load"`` = t, loading then unloading (today's default).
* :func:`preload_then_hold`: channel ``preload`` ramps 0 -> 1 over t in [0, 1], then holds.
* :func:`preload_then_cyclic`: ``preload`` ramps to 1 over t in [0, 1] and holds; ``cyclic``
  is 0 during the preload, then ``amplitude x w(t - 1)`` with w a sine (sin 2 pi s) or a
  triangle wave (0 -> 1 -> -1 -> 0 per unit s) for ``cycles`` cycles of unit length, with
  ``steps_per_cycle`` increments each (a multiple of 4, so the extremes are increments).
* :func:`preload_then_normal_cycles`: ``preload`` ramps 0 -> ``low`` over t in [0, 1], then
  cycles between ``low`` and 1 (up, then down: low -> 1 -> low per unit of t, triangle or
  cosine), ``cycles`` times; a second channel ``cyclic`` (a tangential drive) may cycle with
  it, 0 by default: normal load cycles of a joint (the first cycle carries the first loading
  to the peak, so a law with memory dissipates in it and, at a fixed amplitude, not after).

Units: none (scales multiply the channels' nominal values).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Dict, List

import numpy as np

from rough_contact.cycles import energy_ratio, loop_amplitudes, loop_energies
from rough_contact.validation import check_integer, check_scalar

__all__ = ["LoadProgram", "proportional", "preload_then_hold", "preload_then_cyclic",
           "preload_then_normal_cycles", "cycle_index", "cycle_boundaries", "cycle_summary"]


@dataclass(frozen=True)
class LoadProgram:
    """Channel functions and increment pseudo-times.

    Attributes:
        channels: ``{name: scale(t)}``.
        times: pseudo-times of the increments, in order.
        cycle_start: pseudo-time at which cycle 1 starts (``None`` for a program without cycles).
    """

    channels: Dict[str, Callable[[float], float]]
    times: List[float]
    cycle_start: float | None = None


def _count(name: str, value, lo: int) -> int:
    return check_integer(name, value, lo=lo)


def proportional(n_load: int, n_unload: int = 0) -> LoadProgram:
    """Channel ``"load"`` = t; t = 1/n_load ... 1, then down to 0 in ``n_unload`` steps."""
    n_load = _count("n_load", n_load, 1)
    n_unload = _count("n_unload", n_unload, 0)
    times = [(i + 1) / n_load for i in range(n_load)]
    times += [1.0 + (i + 1) / max(n_unload, 1) for i in range(n_unload)]
    return LoadProgram({"load": lambda t: t if t <= 1.0 else 2.0 - t}, times)


def _ramp_hold(t: float) -> float:
    return min(max(t, 0.0), 1.0)


def preload_then_hold(preload_steps: int, hold_steps: int = 1,
                      preload: str = "preload") -> LoadProgram:
    """``preload`` ramps 0 -> 1 in ``preload_steps`` increments, then stays at 1 for
    ``hold_steps`` increments (t = 1 + k / hold_steps)."""
    n = _count("preload_steps", preload_steps, 1)
    m = _count("hold_steps", hold_steps, 0)
    times = [(i + 1) / n for i in range(n)] + [1.0 + (i + 1) / max(m, 1) for i in range(m)]
    return LoadProgram({preload: _ramp_hold}, times)


def preload_then_cyclic(preload_steps: int, cycles: int, steps_per_cycle: int,
                        amplitude: float = 1.0, shape: str = "triangle",
                        preload: str = "preload", cyclic: str = "cyclic") -> LoadProgram:
    """Preload to 1, hold it, and cycle the ``cyclic`` channel ``cycles`` times.

    Args:
        preload_steps: increments of the preload ramp (t in (0, 1]), >= 1.
        cycles: number of cycles (each of unit pseudo-time), >= 1.
        steps_per_cycle: increments per cycle, a multiple of 4 (>= 4).
        amplitude: scale of the cyclic channel's extremes (> 0).
        shape: ``"triangle"`` (0 -> a -> -a -> 0, linear) or ``"sine"``.
        preload, cyclic: channel names.
    """
    n = _count("preload_steps", preload_steps, 1)
    c = _count("cycles", cycles, 1)
    k = _count("steps_per_cycle", steps_per_cycle, 4)
    if k % 4:
        raise ValueError(f"steps_per_cycle = {k} is invalid: it must be a multiple of 4 (the "
                         "extremes and zero crossings are increments)")
    a = check_scalar("amplitude", amplitude, lo=0.0)
    if shape not in ("triangle", "sine"):
        raise ValueError(f"shape = {shape!r} is invalid: it must be 'triangle' or 'sine'")

    def wave(t: float) -> float:
        if t <= 1.0:
            return 0.0
        s = (t - 1.0) % 1.0
        if shape == "sine":
            return a * math.sin(2.0 * math.pi * s)
        return a * (4.0 * s if s <= 0.25 else 2.0 - 4.0 * s if s <= 0.75 else 4.0 * s - 4.0)

    times = [(i + 1) / n for i in range(n)]
    times += [1.0 + (j + 1) / k for j in range(c * k)]
    return LoadProgram({preload: _ramp_hold, cyclic: wave}, times, cycle_start=1.0)


def preload_then_normal_cycles(preload_steps: int, cycles: int, steps_per_cycle: int,
                               low: float = 0.1, shape: str = "triangle",
                               preload: str = "preload", cyclic: str = "cyclic",
                               tangential: float = 0.0) -> LoadProgram:
    """Normal load cycles: ``preload`` ramps 0 -> ``low`` over t in (0, 1], then goes up to 1
    and back to ``low`` in each cycle (unit pseudo-time; the peak at mid-cycle).

    Args:
        preload_steps: increments of the ramp to ``low`` (t in (0, 1]), >= 1.
        cycles: number of cycles, >= 1.
        steps_per_cycle: increments per cycle, an even number >= 2 (the peak is an increment).
        low: the normal load's minimum as a share of its peak, in (0, 1) (> 0: a rough joint
            held only by its interface needs some load to stay seated).
        shape: ``"triangle"`` (linear up and down) or ``"cosine"`` (low + (1 - low)
            (1 - cos 2 pi s)/2).
        preload, cyclic: channel names.
        tangential: amplitude of the ``cyclic`` channel, a sine in phase with the cycles
            (sin 2 pi s); 0 (default) holds it at 0 (e.g. a tangential drive kept still).
    """
    n = _count("preload_steps", preload_steps, 1)
    c = _count("cycles", cycles, 1)
    k = _count("steps_per_cycle", steps_per_cycle, 2)
    if k % 2:
        raise ValueError(f"steps_per_cycle = {k} is invalid: it must be even (the peak of the "
                         "cycle is an increment)")
    lo = check_scalar("low", low, lo=0.0, hi=1.0)
    b = check_scalar("tangential", tangential, lo=0.0, lo_open=False)
    if shape not in ("triangle", "cosine"):
        raise ValueError(f"shape = {shape!r} is invalid: it must be 'triangle' or 'cosine'")

    def normal(t: float) -> float:
        if t <= 1.0:
            return lo * max(t, 0.0)
        s = (t - 1.0) % 1.0
        if shape == "cosine":
            w = 0.5 * (1.0 - math.cos(2.0 * math.pi * s))
        else:
            w = 2.0 * s if s <= 0.5 else 2.0 - 2.0 * s
        return lo + (1.0 - lo) * w

    def drive(t: float) -> float:
        return 0.0 if t <= 1.0 or b == 0.0 else b * math.sin(2.0 * math.pi * ((t - 1.0) % 1.0))

    times = [(i + 1) / n for i in range(n)]
    times += [1.0 + (j + 1) / k for j in range(c * k)]
    return LoadProgram({preload: normal, cyclic: drive}, times, cycle_start=1.0)


def cycle_index(times, program: LoadProgram) -> np.ndarray:
    """Cycle number (1, 2, ...) of each increment time, 0 before the first cycle (an increment
    ending exactly at the end of a cycle belongs to that cycle)."""
    t = np.asarray(times, dtype=float)
    if program.cycle_start is None:
        return np.zeros(t.shape, dtype=int)
    s = t - program.cycle_start
    return np.where(s <= 0.0, 0, np.ceil(s - 1e-9).astype(int))


def cycle_boundaries(times, program: LoadProgram) -> np.ndarray:
    """Where the program's complete cycles start and end among the increments: indices
    ``b`` with cycle ``k`` (1-based) spanning the increments ``b[k - 1] .. b[k]`` (its first
    entry is the last increment before cycle 1, e.g. the end of the preload). A cycle counts
    when its last increment (pseudo-time ``cycle_start + k``) is among ``times``: a run stopped
    inside a cycle ends at the last complete one. Empty (no complete cycle, or a program
    without cycles) when there is nothing to split.

    Args:
        times: (n,) pseudo-times of the converged increments, increasing.
        program: the program.

    Returns:
        (n_complete_cycles + 1,) increasing indices, or an empty integer array.
    """
    t = np.asarray(times, dtype=float)
    if program.cycle_start is None or t.size == 0:
        return np.zeros(0, dtype=int)
    s = t - program.cycle_start
    before = np.flatnonzero(s <= 1e-9)
    if before.size == 0:
        return np.zeros(0, dtype=int)
    ends = np.flatnonzero((s > 0.5) & np.isclose(s, np.round(s), rtol=0.0, atol=1e-9))
    # complete cycles only, in order 1, 2, ... (a cycle's end is its own increment)
    k = np.round(s[ends]).astype(int)
    ends = ends[k == np.arange(1, len(k) + 1)]
    if ends.size == 0:
        return np.zeros(0, dtype=int)
    return np.r_[before[-1], ends].astype(int)


def cycle_summary(times, program: LoadProgram, displacement, force, dissipation,
                  normal_dissipation=None) -> list:
    """Per cycle of a cyclic program: the loop energy, the interface dissipation, the
    amplitudes, the energy ratio and the secant stiffness.

    Args:
        times: (n,) pseudo-times of the converged increments.
        program: the program (``cycle_start`` set).
        displacement: (n,) the driven displacement (e.g. the prescribed u_x) [mm].
        force: (n,) its work-conjugate force on the body (e.g. ``problem.reaction(tag)[0]``) [N].
        dissipation: (n,) cumulative interface dissipation [N mm].
        normal_dissipation: (n,) cumulative normal hysteresis of a normal law with memory
            (``Increment.normal_dissipation``) [N mm], or None.

    Returns:
        One dict per complete cycle (:func:`cycle_boundaries`): ``cycle``, ``loop_energy``
        (trapezoidal path integral of F du over the cycle [N mm]), ``dissipated`` (interface
        dissipation of the cycle [N mm]; equal to the loop energy in a steady cycle),
        ``delta_amplitude`` and ``force_amplitude`` (half the peak-to-peak u and F [mm], [N]),
        ``energy_ratio`` (A = loop_energy / (4 F* delta*) [-]), ``secant_stiffness``
        ((F_max - F_min) / (u_max - u_min) over the cycle [N/mm]), ``start`` and ``end`` (its
        increments' indices); with ``normal_dissipation`` also ``normal_dissipated`` (the
        normal hysteresis of the cycle [N mm]: 0 once h_min stops moving, shakedown).
    """

    t = np.asarray(times, dtype=float)
    u = np.asarray(displacement, dtype=float)
    f = np.asarray(force, dtype=float)
    d = np.asarray(dissipation, dtype=float)
    if not (len(t) == len(u) == len(f) == len(d)):
        raise ValueError(f"times, displacement, force and dissipation must have equal lengths, "
                         f"got {len(t)}, {len(u)}, {len(f)}, {len(d)}")
    dn = None if normal_dissipation is None else np.asarray(normal_dissipation, dtype=float)
    if dn is not None and dn.shape != t.shape:
        raise ValueError(f"normal_dissipation of shape {dn.shape} must be of the times' shape "
                         f"{t.shape}")
    b = cycle_boundaries(t, program)
    if b.size == 0:
        return []
    energy = loop_energies(u, f, b)
    du, df = loop_amplitudes(u, f, b)
    ratio = energy_ratio(energy, df, du)
    out = [dict(cycle=k + 1, loop_energy=float(energy[k]), dissipated=float(d[e] - d[s]),
                delta_amplitude=float(du[k]), force_amplitude=float(df[k]),
                energy_ratio=float(ratio[k]),
                secant_stiffness=float(df[k] / du[k]) if du[k] > 0 else float("nan"),
                start=int(s), end=int(e))
           for k, (s, e) in enumerate(zip(b[:-1], b[1:]))]
    if dn is not None:
        for c in out:
            c["normal_dissipated"] = float(dn[c["end"]] - dn[c["start"]])
    return out
