"""PETSc SNES driver, incremental loading with cutback, output (imports petsc4py/dolfinx)."""

from .loading import Increment, LoadStepError, load_path, load_unload_factors
from .options import default_options, unused_options
from .output import ResultWriter, atomic_write, atomic_write_text, gather_points
from .snes import SNESSolver, SolveResult, UnusedOptionsWarning, set_default_options

__all__ = ["Increment", "LoadStepError", "load_path", "load_unload_factors", "default_options",
           "unused_options", "ResultWriter", "atomic_write", "atomic_write_text",
           "gather_points", "SNESSolver", "SolveResult", "UnusedOptionsWarning",
           "set_default_options"]
