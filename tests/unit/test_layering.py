"""The pure layers must import without dolfinx, ufl, petsc4py, basix or mpi4py."""
from __future__ import annotations

import pkgutil
import subprocess
import sys

import rough_contact
import rough_contact.interface

PURE = ["rough_contact.surface", "rough_contact.surface.moments", "rough_contact.surface.spectrum",
        "rough_contact.surface.topography", "rough_contact.micro.asperity",
        "rough_contact.micro.population", "rough_contact.micro.tables", "rough_contact.micro.bem",
        "rough_contact.micro.law_comparison", "rough_contact.validation"] + [
    f"rough_contact.interface.{m.name}" for m in pkgutil.iter_modules(rough_contact.interface.__path__)
]


def test_pure_layers_do_not_import_dolfinx():
    code = (
        "import importlib, sys\n"
        f"for name in {PURE!r}:\n"
        "    try:\n"
        "        importlib.import_module(name)\n"
        "    except ModuleNotFoundError as e:\n"
        "        if e.name != name: raise\n"
        "bad = {'dolfinx', 'ufl', 'petsc4py', 'basix', 'mpi4py', 'gmsh'} & set(sys.modules)\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
