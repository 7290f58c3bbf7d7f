"""Input validation shared by every layer: one helper, one message format.

A bad input raises ``ValueError`` naming the quantity, its value, its unit and the valid range,
e.g. ``"Young's modulus E = -1.0 MPa is invalid: it must be finite and > 0"``.
Pure module: numpy only.
"""

from __future__ import annotations

import math
import numbers
from typing import Optional

__all__ = ["check_scalar", "check_integer"]


def check_scalar(name: str, value, *, lo: Optional[float] = None, hi: Optional[float] = None,
                 lo_open: bool = True, hi_open: bool = True, unit: str = "") -> float:
    """Return ``float(value)`` if it is finite and inside the range, else raise ``ValueError``.

    Args:
        name: the quantity as the user knows it (e.g. ``"p_seat"``).
        value: the number given.
        lo, hi: bounds (None = unbounded on that side).
        lo_open, hi_open: whether the bound itself is excluded (``> lo`` rather than ``>= lo``).
        unit: unit shown after the value (e.g. ``"MPa"``).

    Raises:
        ValueError: not a real number (a string such as "2e5" included), not finite, or
            outside the range.
    """
    if isinstance(value, (str, bytes)):
        # float("2e5") would pass the check, but the caller keeps the value it was given
        # (frozen dataclasses) and fails later with a TypeError far from the input
        raise ValueError(f"{name} = {value!r} is invalid: it must be a number, not a "
                         f"{type(value).__name__}" + (f" (unit {unit})" if unit else ""))
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    ok = math.isfinite(v)
    if ok and lo is not None:
        ok = v > lo if lo_open else v >= lo
    if ok and hi is not None:
        ok = v < hi if hi_open else v <= hi
    if ok:
        return v
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    rng = "finite" + (" and " + " and ".join(parts) if parts else "")
    shown = f"{value!r}" + (f" {unit}" if unit else "")
    raise ValueError(f"{name} = {shown} is invalid: it must be {rng}")


def check_integer(name: str, value, *, lo: int, hi: Optional[int] = None, what: str = "") -> int:
    """Return ``int(value)`` if it is an integer in ``[lo, hi]``, else raise ``ValueError``.

    Python and numpy integers pass; ``True``/``False``, floats (even ``10.0``) and strings do
    not: a count given as a float is usually a misplaced argument.

    Args:
        name: the quantity as the user knows it (e.g. ``"max_updates"``).
        value: the number given.
        lo: the smallest valid value.
        hi: the largest valid value (None = unbounded).
        what: what the count counts, shown in parentheses (e.g. ``"Newton iterations"``).
    """
    if (isinstance(value, numbers.Integral) and not isinstance(value, bool) and value >= lo
            and (hi is None or value <= hi)):
        return int(value)
    rng = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
    raise ValueError(f"{name} = {value!r} is invalid: it must be an integer {rng}"
                     + (f" ({what})" if what else ""))
