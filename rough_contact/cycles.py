"""Load-displacement cycles: the work of a force over each cycle (pure numpy).

Used by the load programs (``rough_contact.solver.program``: per-cycle loop energy) and the
plots (``rough_contact.io.plotting``: hysteresis loops); a module of its own so that neither
layer reaches into the other.

Units: displacement [mm], force [N], energy [N mm].
"""

from __future__ import annotations

import numpy as np

__all__ = ["loop_energies"]


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
    work = np.r_[0.0, np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(u))]
    return work[b[1:]] - work[b[:-1]]
