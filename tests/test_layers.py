"""The layers of the package, read from the source: who may import whom.

Every module under ``src/rigidkit`` is parsed with :mod:`ast`; every ``import`` and
``from ... import`` statement counts, also those inside functions (an import that
runs late is still a dependency, and a cycle through one is still a cycle). The
rules are those of ``docs/architecture.md``:

- no import cycles among the modules;
- ``kernels`` import only ``kernels`` and the engine ``_engine``;
- the engine imports no layer (only itself and ``errors``);
- ``functional`` imports neither ``objects`` nor ``applications``;
- ``objects`` import no ``applications``.

Only explicit imports are edges: importing ``rigidkit.a.b`` also runs the package
``rigidkit.a``'s ``__init__``, but that is the package's own dependency, not one of
the importing module.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import rigidkit

ROOT = Path(rigidkit.__file__).parent
PACKAGE = "rigidkit"


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {_module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _is_package(name: str) -> bool:
    return MODULES.get(name, Path()).name == "__init__.py"


def _resolve(importer: str, level: int, module: str | None) -> str:
    """The absolute name of ``from <level dots><module> import ...`` in ``importer``."""
    if level == 0:
        return module or ""
    base = importer.split(".")
    if not _is_package(importer):
        base = base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([module] if module else []))


def imports_of(name: str, source: str | None = None) -> set[str]:
    """The rigidkit modules that module ``name`` imports, anywhere in its source."""
    if source is None:
        source = MODULES[name].read_text(encoding="utf-8")
    tree = ast.parse(source)
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(name, node.level, node.module)
            # ``from pkg import sub`` imports the submodule ``pkg.sub`` when there is
            # one, else a name defined by ``pkg`` itself.
            targets = [
                f"{base}.{alias.name}" if f"{base}.{alias.name}" in MODULES else base
                for alias in node.names
            ]
        else:
            continue
        for target in targets:
            if target in MODULES and target != name:
                found.add(target)
    return found


GRAPH = {name: imports_of(name) for name in MODULES}


def _layer(name: str) -> str:
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else ""


def _cycles(graph: dict) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
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
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_parser_sees_function_level_and_relative_imports():
    # Known edges of the tree, one per kind of statement: a module-level relative
    # import, ``from . import submodule``, and an absolute one.
    assert "rigidkit._engine.namespace" in GRAPH["rigidkit._validate"]
    assert "rigidkit.functional.conversions" in GRAPH["rigidkit.functional.so3"]
    assert "rigidkit.objects.rotation" in GRAPH["rigidkit"]
    # Imports inside functions and methods count, relative and absolute alike.
    src = (
        "class C:\n    def f(self):\n        from ..objects import rotation\n"
        "def g():\n    import rigidkit.applications.symbolic\n"
    )
    assert imports_of("rigidkit.functional.so3", src) == {
        "rigidkit.objects.rotation",
        "rigidkit.applications.symbolic",
    }
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [["a", "b"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles():
    assert _cycles(GRAPH) == []


@pytest.mark.parametrize(
    ("layer", "allowed"),
    [
        ("kernels", {"kernels", "_engine"}),
        ("_engine", {"_engine", "errors"}),
    ],
)
def test_low_layers_import_only_below_them(layer, allowed):
    bad = {
        (name, target)
        for name, targets in GRAPH.items()
        if _layer(name) == layer
        for target in targets
        if _layer(target) not in allowed
    }
    assert bad == set()


@pytest.mark.parametrize(
    ("layer", "forbidden"),
    [
        ("functional", {"objects", "applications"}),
        ("objects", {"applications"}),
        ("_validate", {"kernels", "functional", "objects", "applications"}),
        ("_tolerances", {"kernels", "_engine", "functional", "objects", "applications"}),
    ],
)
def test_no_layer_imports_one_above_it(layer, forbidden):
    bad = {
        (name, target)
        for name, targets in GRAPH.items()
        if _layer(name) == layer
        for target in targets
        if _layer(target) in forbidden
    }
    assert bad == set()


#: What only the engine may do: run code it wrote (the builtins ``exec``, ``eval``,
#: ``compile``), compile with numba, start threads. The layers above declare what
#: they need against the engine's public surface (``rigidkit._engine.__init__``).
ENGINE_ONLY_CALLS = {"exec", "eval", "compile"}
ENGINE_ONLY_MODULES = {"numba", "threading", "_thread", "concurrent"}


def engine_only_uses(source: str) -> set[str]:
    """The engine-only calls and imports in ``source`` (anywhere, at any depth)."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.id if isinstance(f, ast.Name) else getattr(f, "attr", None)
            if name in ENGINE_ONLY_CALLS and not (
                isinstance(f, ast.Attribute) and name == "compile"  # re.compile
            ):
                found.add(f"{name}()")
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name):
                if (f.value.id, f.attr) in {("builtins", "exec"), ("builtins", "compile")}:
                    found.add(f"builtins.{f.attr}()")
        elif isinstance(node, ast.Import):
            found |= {
                f"import {a.name}"
                for a in node.names
                if a.name.split(".")[0] in ENGINE_ONLY_MODULES
            }
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module.split(".")[0] in ENGINE_ONLY_MODULES:
                found.add(f"from {node.module}")
    return found


def test_the_engine_only_check_sees_what_it_looks_for():
    src = (
        "import re\nimport numba.core\nfrom concurrent.futures import Future\n"
        "def f():\n    import threading\n    exec(compile('1', 'x', 'eval'))\n"
        "    re.compile('a')\n    return eval('1')\n"
    )
    assert engine_only_uses(src) == {
        "import numba.core",
        "from concurrent.futures",
        "import threading",
        "exec()",
        "compile()",
        "eval()",
    }


@pytest.mark.parametrize("layer", ["functional", "objects", "applications"])
def test_only_the_engine_generates_compiles_or_starts_threads(layer):
    bad = {
        (name, use)
        for name, path in MODULES.items()
        if _layer(name) == layer
        for use in engine_only_uses(path.read_text(encoding="utf-8"))
    }
    assert bad == set()
