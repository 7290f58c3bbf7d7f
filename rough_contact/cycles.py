"""Load-displacement cycles: the work of a force over each cycle (pure numpy).

Used by the load programs (``rough_contact.solver.program``: per-cycle loop energy) and the
plots (``rough_contact.io.plotting``: hysteresis loops); a module of its own so that neither
layer reaches into the other.

What a fretting study reports per cycle (Fouvry, Kapsa & Vincent's fretting-map quantities):
the displacement amplitude delta* and force amplitude F* (half the peak-to-peak ranges over the
cycle), the energy dissipated E_d (the loop area) and the energy ratio A = E_d / (4 F* delta*),
the loop area over that of the rectangle the loop fits in: 0 for an elastic (closed-line) loop,
1 - delta_s / delta* for the parallelogram of an elastic-perfectly-sliding joint (stiffness k,
sliding force F_s, delta_s = F_s / k), 1 for a rigid-plastic (rectangular) loop.

Units: displacement [mm], force [N], energy [N mm].
"""

from __future__ import annotations

import numpy as np

__all__ = ["loop_energies", "loop_amplitudes", "energy_ratio"]


def loop_energies(displacement, force, boundaries) -> np.ndarray:
    """Work of the force on each cycle, the path integral of F du (trapezoidal rule).

    On a closed loop this is the area enclosed, the energy dissipated per cycle when F is the
    force applied to the body and u its work-conjugate displacement (elastic energy is
    returned over a closed cycle). The trapezoidal rule is exact for a path that is linear
    between the recorded increments.

    Args:
        displacement: (n,) [mm].
        force: (n,) [N].
        boundaries: increasing indices, cycle k spans ``[b[k], b[k + 1]]``.

    Returns:
        (len(boundaries) - 1,) energies [N mm].
    """
    u, f, b = _checked(displacement, force, boundaries)
    work = np.r_[0.0, np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(u))]
    return work[b[1:]] - work[b[:-1]]


def loop_amplitudes(displacement, force, boundaries) -> tuple[np.ndarray, np.ndarray]:
    """Displacement and force amplitudes of each cycle: half their peak-to-peak ranges over the
    cycle's increments (boundaries included).

    Args:
        displacement: (n,) [mm].
        force: (n,) [N].
        boundaries: increasing indices, cycle k spans ``[b[k], b[k + 1]]``.

    Returns:
        ``(delta_amplitude, force_amplitude)``, each (len(boundaries) - 1,) [mm], [N].
    """
    u, f, b = _checked(displacement, force, boundaries)
    du = np.array([np.ptp(u[s:e + 1]) for s, e in zip(b[:-1], b[1:])])
    df = np.array([np.ptp(f[s:e + 1]) for s, e in zip(b[:-1], b[1:])])
    return 0.5 * du, 0.5 * df


def energy_ratio(energy, force_amplitude, displacement_amplitude) -> np.ndarray:
    """Energy ratio A = E_d / (4 F* delta*) [-] (the loop's area over that of its bounding
    rectangle; 0 where F* delta* = 0: a loop without extent dissipates nothing).

    Args:
        energy: E_d, energy dissipated per cycle [N mm].
        force_amplitude: F* >= 0 [N].
        displacement_amplitude: delta* >= 0 [mm].
    """
    e = np.asarray(energy, dtype=float)
    f = np.asarray(force_amplitude, dtype=float)
    d = np.asarray(displacement_amplitude, dtype=float)
    for name, v in (("energy", e), ("force_amplitude", f), ("displacement_amplitude", d)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} holds non-finite values ({v.tolist()!r})")
    if np.any(f < 0) or np.any(d < 0):
        raise ValueError(f"force_amplitude {f.min():.6g} N and displacement_amplitude "
                         f"{d.min():.6g} mm must be >= 0 (half peak-to-peak ranges)")
    box = 4.0 * f * d
    return np.where(box > 0, e / np.where(box > 0, box, 1.0), 0.0)


def _checked(displacement, force, boundaries):
    u = np.asarray(displacement, dtype=float)
    f = np.asarray(force, dtype=float)
    if f.shape != u.shape or u.ndim != 1:
        raise ValueError(f"force of shape {f.shape} must be of the displacement's shape "
                         f"{u.shape} (n,)")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(u))):
        raise ValueError(f"force and displacement hold {int(np.sum(~np.isfinite(f)))} and "
                         f"{int(np.sum(~np.isfinite(u)))} non-finite values")
    b = np.asarray(boundaries)
    if (b.ndim != 1 or len(b) < 2 or not np.issubdtype(b.dtype, np.integer)
            or np.any(np.diff(b) <= 0) or b[0] < 0 or b[-1] >= len(u)):
        raise ValueError(f"boundaries {b.tolist()} must be increasing indices in [0, {len(u) - 1}]")
    return u, f, b
