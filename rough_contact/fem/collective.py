"""One rank fails, every rank raises: exceptions made collective, so no rank waits forever.

An exception raised on one MPI rank only (an interface law failing at that rank's points) would
leave the other ranks blocked in the next collective operation. :func:`raise_on_all_ranks` is
called by every rank at a point all ranks reach (after the law call, before any further
collective) and turns a local failure into a failure on every rank, keeping its meaning:

* a failure that a smaller load increment may cure (a
  :class:`~rough_contact.interface.contract.ConvergenceError`) stays one on every rank, so all
  ranks cut back together;
* anything else (bad input, a programming error) stays fatal on every rank: the failing rank
  re-raises its own exception object with its traceback, the others raise a ``RuntimeError``
  naming the failing rank, the exception type and its message.

The design and the reasons are in ``docs/design.md`` (section "Errors").

:func:`run_on_root` is the same rule for work only one rank does (file system work of the
output writers): root runs it, every rank returns root's result or raises root's error.
"""

from __future__ import annotations

import sys
from typing import Optional

from mpi4py import MPI

from rough_contact.interface.contract import ConvergenceError

__all__ = ["raise_on_all_ranks", "run_on_root"]


def raise_on_all_ranks(comm: MPI.Comm, error: Optional[BaseException]) -> None:
    """Collective: raise on every rank if ``error`` is not None on any rank.

    Must be called by every rank of ``comm`` (one ``allgather`` of a few strings).

    Args:
        comm: the communicator whose ranks must agree.
        error: this rank's exception, or None if this rank succeeded.

    Raises:
        BaseException: this rank's own ``error`` (same object, same traceback) when it is fatal
            (not a ConvergenceError), or when every failing rank raised a ConvergenceError.
        ConvergenceError: on a rank without error of its own when every failure is a
            ConvergenceError; of the first failing rank's class when that class can be imported
            by name (module-level), else ConvergenceError itself.
        RuntimeError: on a rank without a fatal error of its own when some rank's error is fatal
            (chained from this rank's own ConvergenceError, if any).
    """
    mine = None
    if error is not None:
        cls = type(error)
        mine = (comm.rank, cls.__name__, str(error), isinstance(error, ConvergenceError),
                cls.__module__, cls.__qualname__)
    failures = [f for f in comm.allgather(mine) if f is not None]
    if not failures:
        return
    fatal = [f for f in failures if not f[3]]
    if error is not None and (fatal == [] or not isinstance(error, ConvergenceError)):
        raise error
    if fatal:
        rank, name, message = fatal[0][:3]
        raise RuntimeError(f"rank {rank} raised {name}: {message}") from error
    rank, name, message, _, module, qualname = failures[0]
    raise _convergence_error(module, qualname, f"rank {rank} raised {name}: {message}")


def run_on_root(comm: MPI.Comm, root_action, root: int = 0):
    """Run ``root_action()`` on root; every rank returns its result or raises its error.

    Collective (one ``bcast``): call it on every rank of ``comm``.

    Args:
        comm: communicator.
        root_action: callable without arguments, called on ``root`` only; its result and any
            exception it raises must be picklable.
        root: the rank that runs ``root_action``.

    Returns:
        ``root_action()``'s result, on every rank.
    """
    result, error = None, None
    if comm.rank == root:
        try:
            result = root_action()
        except Exception as exc:  # noqa: BLE001 -- re-raised on every rank below
            error = exc
    result, error = comm.bcast((result, error), root=root)
    if error is not None:
        raise error
    return result


def _convergence_error(module: str, qualname: str, message: str) -> ConvergenceError:
    """An instance of the named ConvergenceError subclass, or of ConvergenceError itself when
    the class cannot be found by name (a class local to a function has no importable name)."""
    cls = sys.modules.get(module)
    for part in qualname.split("."):
        cls = getattr(cls, part, None)  # a name lookup: None ends it (e.g. at "<locals>")
    if not (isinstance(cls, type) and issubclass(cls, ConvergenceError)):
        return ConvergenceError(message)
    try:
        return cls(message)
    except TypeError:  # a subclass whose __init__ takes other arguments: skip __init__
        return cls.__new__(cls, message)
