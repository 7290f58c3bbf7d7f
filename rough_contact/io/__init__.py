"""Results on disk and pictures: interface XDMF, displacement XDMF, CSV histories, atomic
writes, plots (imports dolfinx through ``rough_contact.fem``; nothing below imports this).

Modules:
    files               atomic writes, the output folder that holds exactly one run
    interface_output    interface fields on the contact facets (XDMF + HDF5), reading back
    results             ResultWriter (displacement XDMF, interface, history.csv), CsvRecorder
    plotting            matplotlib pictures from plain arrays (needs numpy alone to import)

The names below are loaded on first use (PEP 562): ``import rough_contact.io.plotting`` stays
free of MPI and DOLFINx, while ``from rough_contact.io import ResultWriter`` works as usual.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the same names as _SOURCES, spelled as imports for readers and checkers
    from .files import (RUN_OUTPUT_PATTERNS, OutputExistsError, OutputWriteError,  # noqa: F401
                        atomic_write, atomic_write_text, prepare_output_dir)
    from .interface_output import (InterfaceResults, InterfaceWriter,  # noqa: F401
                                   pseudo_time, read_interface_results)
    from .results import CsvRecorder, ResultWriter, gather_points  # noqa: F401

# public name -> module of this package that defines it
_SOURCES = {
    "RUN_OUTPUT_PATTERNS": "files", "OutputExistsError": "files", "OutputWriteError": "files",
    "atomic_write": "files",
    "atomic_write_text": "files", "prepare_output_dir": "files",
    "InterfaceResults": "interface_output", "InterfaceWriter": "interface_output",
    "pseudo_time": "interface_output", "read_interface_results": "interface_output",
    "CsvRecorder": "results", "ResultWriter": "results", "gather_points": "results",
}

__all__ = sorted(_SOURCES)


def __getattr__(name: str):
    if name not in _SOURCES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_SOURCES[name]}"), name)
    globals()[name] = value  # the next look-up is a plain attribute
    return value


def __dir__():
    return sorted(set(globals()) | set(_SOURCES))
