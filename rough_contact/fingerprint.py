"""Canonical descriptions of the objects that define a problem: what a checkpoint records so a
restart into another law, pairing, enforcement or load program is refused, naming what differs.

A description is plain JSON data, identical on every rank and in every process for the same
parameters:

* a float is written as its ``repr`` (a string); ints, bools, strings and None stay as they are;
* an array of at most :data:`SMALL_ARRAY` entries is the list of its values (floats as above);
  a larger one is ``{"array": dtype, "shape": ..., "sha256": ..., "sketch": ...}``: the hash
  of its bytes and, for a finite float array, a sketch -- sum |a| and three projections on fixed
  pseudo-random weights;
* a frozen dataclass (the house style for laws, enforcements, pairings) is
  ``{"type": module.qualname, field: description, ...}`` over its fields; a field declared
  ``field(compare=False)`` is not part of its identity and is left out (e.g. build statistics);
  a field declared with ``metadata={FINGERPRINT_ADDED: True}`` (added to the class after
  checkpoints of it existed) is left out while it holds its default, so those checkpoints,
  which lack it, still match (``SoftplusPenalty.first_contact``);
* an object with a ``describe()`` method (:class:`Describable`) gives its own description;
* a function is its qualified name and the values it closes over;
* anything else cannot be described: it is recorded by its qualified class name and a
  :class:`UndescribedWarning` says that a restart cannot check its parameters.

:func:`differences` compares two descriptions and names every differing entry by its path
(``friction.mu_macro[0]: 0.5 in the checkpoint, 0.2 now``). Floats are compared to a relative
:data:`FLOAT_RTOL`, float arrays by their hash or else by their sketches to :data:`ARRAY_RTOL`
of sum |a|: the same table built in another process can differ in its last bits (measured on
the punch's elastic table: 33 of 248 coefficients by <= 2.2e-15 in a few runs out of 70;
OpenBLAS's matrix-vector kernels, for one, round differently on 8- and 16-byte aligned data),
and a restart must not be refused for that; a table built from other inputs differs by far
more.

Pure Python + numpy (no FE import).
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import warnings
from typing import Any, List, Protocol, runtime_checkable

import numpy as np

__all__ = ["Describable", "UndescribedWarning", "describe", "differences", "SMALL_ARRAY",
           "FINGERPRINT_ADDED",
           "FLOAT_RTOL", "ARRAY_RTOL"]

SMALL_ARRAY = 16   # arrays up to this size are written out value by value
FINGERPRINT_ADDED = "rough_contact.fingerprint.added"
"""Key of a dataclass field's metadata: the field was added after checkpoints of its class
existed, and is described only when it differs from its default (module docstring)."""
FLOAT_RTOL = 1e-12  # two floats closer than this (relative) are the same parameter
ARRAY_RTOL = 1e-10  # two float arrays whose sketches agree to this (of sum |a|) are the same
_SKETCH_SEED = 20090424


class UndescribedWarning(RuntimeWarning):
    """An object whose parameters cannot be described: only its class is recorded."""


@runtime_checkable
class Describable(Protocol):
    """An object that states its own identity (for objects that are not dataclasses)."""

    def describe(self) -> dict:
        """Plain data (dict / list / str / int / float / bool / None / ndarray, nested) that is
        equal for two objects that behave alike; :func:`describe` canonicalises it."""


def _is_default(value, default) -> bool:
    """Whether a field's value is its (scalar or string) default."""
    try:
        return bool(value == default) and type(value) is type(default)
    except (TypeError, ValueError):
        return False


def _qualname(obj) -> str:
    t = obj if isinstance(obj, type) else type(obj)
    return f"{t.__module__}.{t.__qualname__}"


def _float(x: float) -> str:
    return repr(float(x))


def _array(a: np.ndarray, path: str):
    if a.dtype == object:
        return [describe(v, f"{path}[{i}]") for i, v in enumerate(a.reshape(-1))]
    if a.size <= SMALL_ARRAY and a.ndim <= 1:
        return [describe(v.item(), f"{path}[{i}]") for i, v in enumerate(a.reshape(-1))]
    data = np.ascontiguousarray(a)
    out = {"array": str(data.dtype), "shape": list(data.shape),
           "sha256": hashlib.sha256(data.tobytes()).hexdigest()}
    if np.issubdtype(data.dtype, np.floating) and np.isfinite(data).all():
        flat = data.reshape(-1).astype(float)
        w = np.random.default_rng(_SKETCH_SEED).uniform(-1.0, 1.0, (3, flat.size))
        out["sketch"] = [_float(np.abs(flat).sum())] + [_float(v) for v in (w * flat).sum(axis=1)]
    return out


def _same(x: Any, y: Any) -> bool:
    """Two flattened description entries are the same parameter (see the module)."""
    if x == y:
        return True
    if isinstance(x, dict) and isinstance(y, dict):       # arrays whose hashes differ
        sx, sy = x.get("sketch"), y.get("sketch")
        if (x.get("array"), x.get("shape")) != (y.get("array"), y.get("shape")) or not sx or not sy:
            return False
        fx, fy = np.array(sx, float), np.array(sy, float)
        scale = max(fx[0], fy[0])
        return bool(np.all(np.abs(fx - fy) <= ARRAY_RTOL * scale))
    if isinstance(x, str) and isinstance(y, str):         # floats written as repr
        try:
            fx, fy = float(x), float(y)
        except ValueError:
            return False
        if not (np.isfinite(fx) and np.isfinite(fy)):
            return False
        return abs(fx - fy) <= FLOAT_RTOL * max(abs(fx), abs(fy))
    return False


def _function(fn, path: str) -> dict:
    out = {"function": f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', '?')}"}
    code, cells = getattr(fn, "__code__", None), getattr(fn, "__closure__", None)
    if code is not None and cells:
        out["closure"] = {name: describe(cell.cell_contents, f"{path}.{name}")
                          for name, cell in zip(code.co_freevars, cells)
                          if cell.cell_contents is not fn}
    if getattr(fn, "__defaults__", None):
        out["defaults"] = describe(list(fn.__defaults__), f"{path}.defaults")
    return out


def describe(obj: Any, path: str = "") -> Any:
    """The canonical description of ``obj`` (see the module); ``path`` names it in warnings."""
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, enum.Enum):
        return f"{_qualname(obj)}.{obj.name}"
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return _float(obj)
    if isinstance(obj, np.ndarray):
        return _array(obj, path)
    if isinstance(obj, (list, tuple)):
        return [describe(v, f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, dict):
        return {str(k): describe(obj[k], f"{path}.{k}") for k in sorted(obj, key=str)}
    if isinstance(obj, Describable) and not isinstance(obj, type):
        own = obj.describe()
        body = describe(own, path)
        return {"type": _qualname(obj), **body} if isinstance(body, dict) else \
            {"type": _qualname(obj), "value": body}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out = {"type": _qualname(obj)}
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if f.metadata.get(FINGERPRINT_ADDED) and f.default is not dataclasses.MISSING \
                    and _is_default(value, f.default):
                continue
            if f.compare:
                out[f.name] = describe(value, f"{path}.{f.name}")
        return out
    if callable(obj) and hasattr(obj, "__code__"):
        return _function(obj, path)
    warnings.warn(f"{path.lstrip('.') or 'an object'} ({_qualname(obj)}) cannot be described "
                  "(not a dataclass, no describe() method): a checkpoint records its class only, "
                  "so a restart cannot check its parameters. Make it a (frozen) dataclass or "
                  "give it describe() (rough_contact.fingerprint.Describable)",
                  UndescribedWarning, stacklevel=2)
    return {"type": _qualname(obj), "undescribed": True}


def _flatten(d: Any, path: str, out: dict) -> None:
    if isinstance(d, dict) and not ("array" in d and "sha256" in d):
        for k, v in d.items():
            _flatten(v, f"{path}.{k}" if path else k, out)
    elif isinstance(d, list):
        if not d:
            out[path] = "[]"
        for i, v in enumerate(d):
            _flatten(v, f"{path}[{i}]", out)
        out[f"{path}#len"] = len(d)
    else:
        out[path] = d


def _show(v: Any) -> str:
    if v is None:
        return "(absent)"
    if isinstance(v, dict):
        return f"array {v['array']}{tuple(v['shape'])} sha256 {v['sha256'][:12]}"
    return str(v)


def differences(saved: Any, now: Any, limit: int = 8) -> List[str]:
    """The entries in which two descriptions differ, as ``path: A in the checkpoint, B now``
    (at most ``limit``, then a count of the others); empty when they are equal."""
    a, b = {}, {}
    _flatten(saved, "", a)
    _flatten(now, "", b)
    keys = [k for k in list(a) + [k for k in b if k not in a] if not _same(a.get(k), b.get(k))]
    lengths = {k[:-4] for k in keys if k.endswith("#len")}
    # a list of another length: say so once instead of listing every shifted entry
    keys = [k for k in keys if k.endswith("#len")
            or not any(k.startswith(p + "[") for p in lengths)]
    out = []
    for k in keys:
        if k.endswith("#len"):
            out.append(f"{k[:-4] or '(top)'}: {a.get(k)} entries in the checkpoint, "
                       f"{b.get(k)} now")
        else:
            out.append(f"{k or '(top)'}: {_show(a.get(k))} in the checkpoint, "
                       f"{_show(b.get(k))} now")
    if len(out) > limit:
        out = out[:limit] + [f"and {len(out) - limit} more"]
    return out
