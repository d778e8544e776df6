"""The package's picture of imports runs one way.

Every import statement of ``tlmpc/`` (function-local and ``TYPE_CHECKING`` ones included) is read
from the source.  The subpackages form layers, lowest first in :data:`LAYERS`; a module may import
its own layer or a lower one, never a higher one, so the package graph has no cycle.  Nothing
below the facade imports ``tlmpc`` itself or ``tlmpc.api``, and the package root holds only the
facade, the command line and ``__main__``.  Inside a package, modules form no new import cycle.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "tlmpc"

#: The layers, lowest first.  A new subpackage goes where its imports put it.
LAYERS = (
    "base",
    "templates",
    "ltl",
    "io",
    "importers",
    "automata",
    "tasks",
    "synth",
    "mission",
    "abstraction",
    "reactive",
    "planning",
    "control",
    "simulate",
    "verify",
    "runtime",
    "render",
    "view",
    "exports",
    "fleet",
    "pipeline",
    "commands",
    "cli",
    "api",
    "",  # the package face, tlmpc/__init__.py
)

ROOT_MODULES = {"__init__.py", "__main__.py", "api.py", "cli.py"}

#: Module cycles inside one package that predate this test; each is a redesign still to make.
#: The test fails on any other cycle, and on an entry here that no longer exists.  (None left.)
KNOWN_MODULE_CYCLES: frozenset[frozenset[str]] = frozenset()


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@functools.cache
def _modules() -> dict[str, Path]:
    return {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _imports(name: str, path: Path) -> set[str]:
    """The tlmpc modules that ``name`` imports (a ``from P import m`` of a submodule names
    ``P.m``, not the package ``P``)."""
    modules = _modules()
    found: set[str] = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join([*base, *([node.module] if node.module else [])])
            else:
                module = node.module or ""
            submodules = {f"{module}.{alias.name}" for alias in node.names} & modules.keys()
            found.update(submodules)
            if len(submodules) < len(node.names):
                found.add(module)
    return {module for module in found if module in modules and module != name}


@functools.cache
def _graph() -> dict[str, frozenset[str]]:
    return {name: frozenset(_imports(name, path)) for name, path in _modules().items()}


def _layer(module: str) -> str:
    parts = module.split(".")
    if len(parts) == 1:
        return ""
    if (PACKAGE / parts[1]).is_dir():
        return parts[1]
    return "cli" if parts[1] == "__main__" else parts[1]


def test_root_holds_only_the_facade_and_the_command_line() -> None:
    loose = {path.name for path in PACKAGE.glob("*.py")}
    assert loose <= ROOT_MODULES, f"move {sorted(loose - ROOT_MODULES)} into a subpackage"


def test_every_subpackage_has_a_layer() -> None:
    packages = {path.name for path in PACKAGE.iterdir() if (path / "__init__.py").is_file()}
    assert packages - set(LAYERS) == set(), "add the new package to LAYERS where it belongs"


def test_imports_run_down_the_layers() -> None:
    rank = {layer: index for index, layer in enumerate(LAYERS)}
    upward = sorted(
        f"{module} -> {target}"
        for module, targets in _graph().items()
        for target in targets
        if rank[_layer(target)] > rank[_layer(module)]
    )
    assert upward == []


def test_nothing_below_the_facade_imports_it() -> None:
    offenders = sorted(
        f"{module} -> {target}"
        for module, targets in _graph().items()
        for target in targets & {"tlmpc", "tlmpc.api"}
        if module not in {"tlmpc", "tlmpc.api"}
    )
    assert offenders == []


def _cycles(graph: dict[str, frozenset[str]]) -> set[frozenset[str]]:
    """The groups of more than one module that reach each other (by plain reachability:
    a few hundred modules need nothing cleverer)."""
    reach: dict[str, set[str]] = {}
    for start in graph:
        seen: set[str] = set()
        todo = list(graph[start])
        while todo:
            node = todo.pop()
            if node not in seen:
                seen.add(node)
                todo.extend(graph[node])
        reach[start] = seen
    return {
        frozenset({node} | {other for other in reach[node] if node in reach[other]})
        for node in graph
        if any(node in reach[other] for other in reach[node] if other != node)
    }


def test_cycle_finder_finds_a_cycle() -> None:
    graph = {
        "a": frozenset({"b"}),
        "b": frozenset({"c"}),
        "c": frozenset({"a"}),
        "d": frozenset({"a"}),
    }
    assert _cycles(graph) == {frozenset({"a", "b", "c"})}
    assert _cycles({"a": frozenset({"b"}), "b": frozenset()}) == set()


def test_no_new_module_cycles() -> None:
    cycles = _cycles(_graph())
    assert cycles - KNOWN_MODULE_CYCLES == set(), "a new import cycle"
    assert KNOWN_MODULE_CYCLES - cycles == set(), "a known cycle is gone: drop it from the list"
