"""The package's layers, read from its source (no dolfinx needed).

Layers, bottom to top (README, "Layout"; docs/design.md): the pure layers (validation,
rough surfaces and the micro-model, ``interface``) < ``fem`` (the only layer importing dolfinx,
ufl, basix; with the mesh builders) < ``solver`` < ``io`` < ``scenes``.

The module lists are found by walking the package, so modules that move (surface and micro
modules into sub-packages) need no change here.
"""
from __future__ import annotations

import ast
from pathlib import Path

import rough_contact

PACKAGE = "rough_contact"
ROOT = Path(rough_contact.__file__).resolve().parent

# Layers that may depend on the FE stack; every other module of the package is a pure layer.
FE_LAYERS = ("fem", "solver", "io", "scenes")
# The only places that import dolfinx / ufl / basix themselves: the FE layer, the output layer,
# and the mesh builders (today rough_contact/scenes/meshes; a top-level meshes/ folder of
# scripts is outside the package and not checked here).
DOLFINX_ALLOWED = ("rough_contact.fem", "rough_contact.io", "rough_contact.scenes.meshes")
FE_STACK = {"dolfinx", "ufl", "basix"}

# Modules that import dolfinx/ufl/basix directly although their layer must not: none (the
# solver and the scenes ask the problem or rough_contact.fem.compat). A new entry needs a reason;
# the test fails on an entry that no longer imports the FE stack.
_PENDING_DOLFINX: set = set()

# Import cycles (as sorted tuples of the modules of one strongly connected component) that
# are known and not yet broken. Empty: the package has none; keep it so.
_PENDING_CYCLES: set = set()

# Imports of rough_contact.io from a layer below it (importer, imported module): none.
_PENDING_IO_USERS: set = set()


# --------------------------------------------------------------------------------------------
# reading the package
# --------------------------------------------------------------------------------------------
def _module_files() -> dict:
    """{module name: path} of every module of the package (``pkg/__init__.py`` -> ``pkg``)."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        if "__pycache__" in parts:
            continue
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _module_files()


def _is_package(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def _imported_names(name: str) -> set:
    """Absolute names of everything module ``name`` imports, at any depth of its code
    (function-level and ``TYPE_CHECKING`` imports included: they are dependencies too).
    ``from X import Y`` gives ``X.Y`` when that is a module of the package, else ``X``."""
    tree = ast.parse(MODULES[name].read_text(), filename=str(MODULES[name]))
    package = name if _is_package(name) else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                found.add(sub if sub in MODULES else source)
    return found


IMPORTS = {name: _imported_names(name) for name in MODULES}


def _ancestors(name: str) -> list:
    parts = name.split(".")
    return [".".join(parts[:k]) for k in range(1, len(parts))]


def _graph() -> dict:
    """Module -> modules of the package that importing it runs.

    Importing ``a.b.c`` also runs the ``__init__`` of ``a`` and ``a.b`` (with its re-exports),
    except the packages the importer itself lives in, which are already being imported.
    """
    graph = {}
    for name, imported in IMPORTS.items():
        own = set(_ancestors(name)) | {name}
        edges = set()
        for target in imported:
            if target.split(".")[0] != PACKAGE:
                continue
            while target not in MODULES:          # an attribute: its module
                target = target.rpartition(".")[0]
            edges.update(m for m in _ancestors(target) + [target]
                         if m in MODULES and m not in own)  # (namespace packages: no module)
        graph[name] = edges
    return graph


def _cycles(graph: dict) -> set:
    """Strongly connected components with more than one module (Tarjan), as sorted tuples."""
    index, low, stack, on_stack, out = {}, {}, [], set(), set()

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.add(tuple(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _layer(name: str) -> str:
    parts = name.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in FE_LAYERS else "pure"


def _cycle_path(graph: dict, component: tuple) -> str:
    """One closed import path through ``component``, for the failure message."""
    members, start = set(component), component[0]
    path, seen = [start], {start}
    while True:
        nxt = sorted(w for w in graph[path[-1]] if w in members)
        step = next((w for w in nxt if w not in seen), None) or nxt[0]
        path.append(step)
        if step in seen:
            return " -> ".join(path[path.index(step):])
        seen.add(step)


PURE = sorted(name for name in MODULES if _layer(name) == "pure")


# --------------------------------------------------------------------------------------------
# the tests
# --------------------------------------------------------------------------------------------
def test_the_walk_finds_the_layers():
    layers = {_layer(m) for m in MODULES}
    assert {"pure", "fem", "solver", "io"} <= layers, layers
    assert "rough_contact.interface" in PURE and "rough_contact.validation" in PURE


def test_pure_layers_do_not_import_dolfinx(imports_without):
    """Every pure module imports (strictly: any error fails) without the FE/MPI stack."""
    imports_without(PURE)


def test_no_import_cycles():
    graph = _graph()
    found = _cycles(graph)
    new = found - _PENDING_CYCLES
    assert not new, "import cycles:\n" + "\n".join(_cycle_path(graph, c) for c in sorted(new))
    stale = _PENDING_CYCLES - found
    assert not stale, f"cycles broken since: remove them from _PENDING_CYCLES: {sorted(stale)}"


def test_cycle_detection_itself():
    """A cycle through a package's ``__init__`` (its re-exports) is one; a chain is none."""
    graph = {"p": {"p.a"}, "p.a": set(), "q.b": {"p"}}
    assert _cycles(graph) == set()
    graph["p.a"] = {"q.b"}   # e.g. a function-level import in p.a
    assert _cycles(graph) == {("p", "p.a", "q.b")}
    assert _cycle_path(graph, ("p", "p.a", "q.b")) == "p -> p.a -> q.b -> p"


def test_only_fem_io_and_mesh_builders_import_dolfinx():
    importers = {name for name, imported in IMPORTS.items()
                 if {n.split(".")[0] for n in imported} & FE_STACK}
    allowed = {m for m in importers
               if any(m == p or m.startswith(p + ".") for p in DOLFINX_ALLOWED)}
    offenders = importers - allowed
    new = offenders - _PENDING_DOLFINX
    assert not new, (f"{sorted(new)} import dolfinx/ufl/basix: only {DOLFINX_ALLOWED} may; "
                     "use the problem or rough_contact.fem.compat")
    stale = _PENDING_DOLFINX - offenders
    assert not stale, f"fixed or moved: remove them from _PENDING_DOLFINX: {sorted(stale)}"


def test_io_is_not_imported_from_below():
    """rough_contact.io sits above fem, solver and the pure layers: none of them imports it."""
    uses = {(name, target) for name, imported in IMPORTS.items()
            if _layer(name) in ("pure", "fem", "solver")
            for target in imported if target.startswith("rough_contact.io")}
    new = uses - _PENDING_IO_USERS
    assert not new, f"imports of rough_contact.io from a lower layer: {sorted(new)}"
    stale = _PENDING_IO_USERS - uses
    assert not stale, f"removed since: drop them from _PENDING_IO_USERS: {sorted(stale)}"


def test_io_lazy_exports_are_spelled_as_imports():
    """rough_contact.io loads its public names on first use (``_SOURCES``); its
    ``TYPE_CHECKING`` imports name the same objects of the same modules, so the cycle test,
    which reads imports, sees every re-export."""
    tree = ast.parse(MODULES["rough_contact.io"].read_text())
    spelled = {(alias.name, node.module) for node in ast.walk(tree)
               if isinstance(node, ast.ImportFrom) and node.level == 1 for alias in node.names}
    sources = next(ast.literal_eval(node.value) for node in tree.body
                   if isinstance(node, ast.Assign) and node.targets[0].id == "_SOURCES")
    assert spelled == set(sources.items())
