"""PETSc SNES driver, incremental loading with cutback, output (imports petsc4py/dolfinx)."""
