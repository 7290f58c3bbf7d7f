"""Files of one run: atomic writes, and the output folder that holds exactly one run.

* :func:`atomic_write` (and :func:`atomic_write_text`): a temporary file, fsync,
  ``os.replace``; every file the writers of :mod:`rough_contact.io` write goes through it, so a
  crash leaves the old file or the new one, never a truncated one.
* a write that fails (a full disk, a quota, permissions) raises :class:`OutputWriteError`, one
  message naming the file and the cause (:func:`write_failure`, :func:`writing`);
  :func:`check_free_space` refuses a write that the free space cannot hold before it starts
  (an HDF5 file that runs out of space half-way cannot even be closed).
* :func:`prepare_output_dir` makes a folder hold exactly one run: it refuses a folder with
  results of an earlier run unless ``overwrite=True``, and then removes those files (only the
  files this project's writers produce, ``RUN_OUTPUT_PATTERNS``).
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
from typing import Iterable, Optional, Sequence, Union

from mpi4py import MPI

from rough_contact.fem.collective import run_on_root

__all__ = ["atomic_write", "atomic_write_text", "OutputExistsError", "OutputWriteError",
           "RUN_OUTPUT_PATTERNS", "prepare_output_dir", "run_files", "free_bytes",
           "check_free_space", "write_failure", "writing"]

# Files the project's writers produce in an output folder (ResultWriter: displacement, history,
# the former point cloud with its per-step .bin files; InterfaceWriter: the surface files), and
# the temporary files of their atomic writes (``<name>.tmp<pid>``).
RUN_OUTPUT_PATTERNS = (
    r"displacement\.xdmf", r"displacement\.h5", r"history\.csv", r"interface\.xdmf",
    r"interface\.h5", r"interface_points\.xdmf", r"interface_\d{4,}\.bin",
)


class OutputExistsError(FileExistsError, ValueError):
    """An output folder holds results of an earlier run and ``overwrite`` was not given."""


class OutputWriteError(OSError):
    """An output file could not be written; the message names the file and the cause (e.g. no
    space left on device, with the free space). ``errno`` and ``filename`` are set when known."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else super().__str__()


_SPACE_ERRORS = {errno.ENOSPC: "no space left on device", errno.EDQUOT: "disk quota exceeded",
                 errno.EFBIG: "file too large"}


def _folder(path: str) -> str:
    """The nearest existing folder at or above ``path``'s folder."""
    folder = os.path.dirname(os.path.abspath(os.fspath(path)))
    while not os.path.isdir(folder) and os.path.dirname(folder) != folder:
        folder = os.path.dirname(folder)
    return folder


def free_bytes(path: str) -> int:
    """Bytes an unprivileged writer can still write on the file system holding ``path``."""
    st = os.statvfs(_folder(path))
    return int(st.f_bavail) * int(st.f_frsize)


def _size(n: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{int(n)} bytes"


def _errno_of(exc: BaseException) -> Optional[int]:
    """The errno of an OSError, or the one HDF5 puts in its messages ('errno = 28'), following
    the chain of causes."""
    while exc is not None:
        if isinstance(exc, OSError) and exc.errno:
            return int(exc.errno)
        found = re.search(r"errno = (\d+)", str(exc))
        if found:
            return int(found.group(1))
        if "No space left on device" in str(exc):
            return errno.ENOSPC
        exc = exc.__cause__ or exc.__context__
    return None


def write_failure(path: str, exc: BaseException, min_free: int = 64 * 1024) -> OutputWriteError:
    """The clear error for a failed write of ``path`` (``exc``: what the writer raised). The
    cause is the errno of ``exc`` when it has one (also in HDF5's messages), else a file system
    with less than ``min_free`` bytes free is taken for a full disk."""
    path = os.fspath(path)
    code = _errno_of(exc)
    try:
        free = free_bytes(path)
    except OSError:
        free = None
    if code is None and free is not None and free < min_free:
        code = errno.ENOSPC
    if code in _SPACE_ERRORS:
        where = "" if free is None else f" ({_size(free)} free on the file system of " \
            f"{_folder(path)})"
        message = (f"cannot write {path}: {_SPACE_ERRORS[code]}{where}; free some space or "
                   "write the results to another folder")
    else:
        message = f"cannot write {path}: {type(exc).__name__}: {exc}"
    err = OutputWriteError(message)
    err.errno, err.filename = code, path
    return err


@contextlib.contextmanager
def writing(path: str):
    """Turn an OSError or RuntimeError (HDF5's failures) raised inside into
    :func:`write_failure` of ``path``."""
    try:
        yield
    except OutputWriteError:
        raise
    except (OSError, RuntimeError) as exc:
        raise write_failure(path, exc) from exc


def check_free_space(path: str, needed: int, what: str) -> None:
    """Raise :class:`OutputWriteError` before writing when the file system of ``path`` has less
    than ``needed`` bytes free (``what``: the files about to be written, for the message)."""
    free = free_bytes(path)
    if free < needed:
        err = OutputWriteError(
            f"cannot write {what}: no space left on device ({_size(free)} free on the file "
            f"system of {_folder(path)}, the step needs about {_size(needed)}); free some space "
            "or write the results to another folder")
        err.errno, err.filename = errno.ENOSPC, os.fspath(path)
        raise err


def atomic_write(path: str, content: Union[str, bytes, Iterable[bytes]]) -> None:
    """Write ``content`` to ``path`` atomically: a temporary file, fsync, ``os.replace``.

    A crash leaves either the old file or the new one, never a truncated one. Every file the
    output writers write goes through here. A failed write (e.g. a full disk) removes the
    temporary file and raises :class:`OutputWriteError` naming ``path`` and the cause.

    Args:
        path: destination.
        content: text (written as UTF-8, newlines unchanged), bytes, or an iterable of bytes
            chunks (written one after the other).
    """
    if isinstance(content, str):
        chunks: Iterable[bytes] = [content.encode("utf-8")]
    elif isinstance(content, (bytes, bytearray)):
        chunks = [bytes(content)]
    else:
        chunks = content
    tmp = f"{path}.tmp{os.getpid()}"
    try:
        with open(tmp, "wb") as fh:
            for chunk in chunks:
                fh.write(chunk)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise write_failure(path, exc) from exc


def atomic_write_text(path: str, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`atomic_write`)."""
    atomic_write(path, text)


def run_files(outdir: str, patterns: Sequence[str]) -> list:
    """Sorted names of the files in ``outdir`` whose name fully matches one of ``patterns``
    (regular expressions), or the temporary file of an atomic write of such a name."""
    if not os.path.isdir(outdir):
        return []
    regex = re.compile("|".join(f"(?:{p})(?:\\.tmp\\d+)?" for p in patterns))
    return sorted(f for f in os.listdir(outdir)
                  if regex.fullmatch(f) and os.path.isfile(os.path.join(outdir, f)))


def prepare_output_dir(outdir: str, comm: MPI.Comm = MPI.COMM_WORLD, overwrite: bool = False,
                       extra_patterns: Sequence[str] = ()) -> list:
    """Make ``outdir`` ready for exactly one run (collective).

    Creates the folder. If it holds files a writer of this project produces
    (``RUN_OUTPUT_PATTERNS``: displacement.xdmf/.h5, history.csv, interface.xdmf/.h5,
    interface_points.xdmf, interface_NNNN.bin, their temporaries) it raises
    :class:`OutputExistsError`, or with ``overwrite=True`` removes exactly those files. Other
    files are never touched.

    Args:
        outdir: output folder.
        comm: communicator (rank 0 does the file system work).
        overwrite: remove the results of an earlier run instead of refusing.
        extra_patterns: further file-name regular expressions (full match) of the caller's own
            outputs, e.g. ``r"slip_directions.*\\.png"``.

    Returns:
        Names of the removed files.

    Raises:
        OutputExistsError: earlier results present and ``overwrite`` is False.
    """
    outdir = os.fspath(outdir)
    patterns = tuple(RUN_OUTPUT_PATTERNS) + tuple(extra_patterns)

    def act():
        if os.path.exists(outdir) and not os.path.isdir(outdir):
            raise ValueError(f"output directory {outdir!r} exists and is not a directory")
        os.makedirs(outdir, exist_ok=True)
        found = run_files(outdir, patterns)
        if found and not overwrite:
            shown = ", ".join(found[:6]) + (", ..." if len(found) > 6 else "")
            raise OutputExistsError(
                f"output directory {outdir!r} holds results of an earlier run ({len(found)} "
                f"files: {shown}); pass overwrite=True (--overwrite) to replace them, or choose "
                "another directory")
        for f in found:
            os.remove(os.path.join(outdir, f))
        return found

    return run_on_root(comm, act)


_XI = "http://www.w3.org/2001/XInclude"


def parse_xdmf(path: str):
    """The root element of an XDMF file. DOLFINx 0.5.2 declares the ``xi`` prefix of its
    ``<xi:include>`` elements as http://www.w3.org/2001/XInclude, 0.9 as https://...; an
    undeclared prefix gets the former. The prefix is registered for the URI the file uses, so
    that a file written back (e.g. cut to a restart's step) keeps ``xi:`` — the prefix the
    writer uses for the steps it appends later."""
    import re
    import xml.etree.ElementTree as ET
    with open(path, encoding="utf-8") as f:
        xml = f.read()
    declared = re.search(r'xmlns:xi="([^"]+)"', xml)
    if declared is None and "xi:" in xml:
        xml = xml.replace("<Xdmf ", f'<Xdmf xmlns:xi="{_XI}" ', 1)
    ET.register_namespace("xi", declared.group(1) if declared else _XI)
    return ET.fromstring(xml)
