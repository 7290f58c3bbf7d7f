"""PETSc SNES driver, incremental loading with cutback, output (imports petsc4py/dolfinx)."""

from .loading import Increment, LoadStepError, interface_summary, load_path, load_unload_factors
from .output import ResultWriter, atomic_write_text, gather_points
from .snes import SNESSolver, SolveResult, set_default_options

__all__ = ["Increment", "LoadStepError", "interface_summary", "load_path", "load_unload_factors",
           "ResultWriter", "atomic_write_text", "gather_points", "SNESSolver", "SolveResult",
           "set_default_options"]
