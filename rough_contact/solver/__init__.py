"""PETSc SNES driver, incremental loading with cutback (imports petsc4py/dolfinx).

Output (ResultWriter, CsvRecorder, atomic writes) is in :mod:`rough_contact.io`.
"""

from .loading import Increment, LoadStepError, load_path, load_unload_factors
from .options import default_options, unused_options
from .snes import SNESSolver, SolveResult, UnusedOptionsWarning, set_default_options

__all__ = ["Increment", "LoadStepError", "load_path", "load_unload_factors", "default_options",
           "unused_options", "SNESSolver", "SolveResult", "UnusedOptionsWarning",
           "set_default_options"]
