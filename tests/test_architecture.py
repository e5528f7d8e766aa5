"""The package's shape: layers that import only downward, no import circles,
imports at the top of each file.

Each top-level module or subpackage of ``lenscompare`` sits on a layer; a unit
may import only units on lower layers (and its own files). A new module must
be given a layer here, which is the moment to decide where it belongs.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "lenscompare"

# Lowest first. Units on one layer do not import each other.
LAYERS = [
    {"__init__", "errors", "units", "progress", "_native", "reference_scenes", "interrupts"},
    {"limits"},
    {"atomic", "_schema", "cluster"},
    {"optics", "metrics", "lenses", "meshes", "spectral"},
    {"scene", "adaptive"},
    {"motion"},
    {"cameras", "native_scene"},
    {"image", "flat_geometry", "diffraction", "postfilter", "render_spectral", "motion_path"},
    {"render", "povray", "mitsuba", "pbrt"},
    {"plan", "measure", "figures"},
    {"experiment"},
    {"verdict"},
    {"cost", "checks", "sweep"},
    {"report"},
    {"commands"},
    {"cli"},
    {"__main__", "console"},
]
LAYER_OF = {unit: i for i, layer in enumerate(LAYERS) for unit in layer}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_module(name: str) -> bool:
    relative = Path(*name.split(".")[1:]) if "." in name else Path()
    return (PACKAGE.parent / "lenscompare" / relative).with_suffix(".py").is_file() or (
        PACKAGE / relative / "__init__.py").is_file()


def _imports(path: Path, text: str | None = None):
    """(imported module, ast node, inside a function?) for every import in a
    file (or in ``text``, read as if it were that file)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text(encoding="utf-8") if text is None else text)
    functions = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
                 for n in ast.walk(f) if n is not f}
    for node in ast.walk(tree):
        nested = id(node) in functions
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("lenscompare"):
                yield target, node, nested
                continue
            for alias in node.names:  # "from . import render" imports the module render
                candidate = f"{target}.{alias.name}"
                yield (candidate if _is_module(candidate) else target), node, nested
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node, nested


def _unit(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _files():
    return sorted(PACKAGE.rglob("*.py"))


def _internal_graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {}
    for path in _files():
        name = _module_name(path)
        graph.setdefault(name, set())
        for target, _, _ in _imports(path):
            if target.startswith("lenscompare") and target != name:
                graph[name].add(target)
    return graph


def test_every_unit_has_a_layer():
    units = {_unit(_module_name(p)) for p in _files()} | {"_native"}
    assert units - set(LAYER_OF) == set(), "give the new module a layer in LAYERS"


def _upward_arrows(path: Path, text: str | None = None) -> list[str]:
    source = _unit(_module_name(path))
    arrows = []
    for target, node, _ in _imports(path, text):
        if not target.startswith("lenscompare"):
            continue
        unit = _unit(target)
        if unit != source and LAYER_OF[unit] >= LAYER_OF[source]:
            arrows.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {source} -> {unit}")
    return arrows


def _hidden_imports(path: Path, text: str | None = None) -> list[str]:
    """Imports inside functions: only a third-party one, with a comment saying why."""
    lines = (path.read_text(encoding="utf-8") if text is None else text).splitlines()
    return [f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {target}"
            for target, node, nested in _imports(path, text)
            if nested and (target.startswith("lenscompare") or "#" not in lines[node.lineno - 1])]


def test_imports_go_only_downward():
    assert [arrow for path in _files() for arrow in _upward_arrows(path)] == []


def test_no_import_circle_between_modules():
    graph = _internal_graph()
    state: dict[str, int] = {}  # 1 visiting, 2 done
    circles = []

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                circles.append(" -> ".join(trail[trail.index(nxt):] + [nxt]) if nxt in trail else f"{node} -> {nxt}")
            elif nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert circles == []


def test_the_checks_see_what_they_look_for():
    """The walkers themselves: render.py importing report inside a function is
    both an upward arrow and a hidden import; numpy at the top is neither."""
    snippet = "import numpy\n\ndef f():\n    from .report import build_report\n    import colour\n"
    render = PACKAGE / "render.py"
    assert _upward_arrows(render, snippet) == ["lenscompare/render.py:4 render -> report"]
    assert _hidden_imports(render, snippet) == ["lenscompare/render.py:4 lenscompare.report",
                                                "lenscompare/render.py:5 colour"]
    assert _hidden_imports(render, "def f():\n    import colour  # slow to import\n") == []


def test_imports_are_at_the_top_unless_a_comment_says_why():
    assert [hidden for path in _files() for hidden in _hidden_imports(path)] == []


@pytest.mark.parametrize("module", ["lenscompare.cli", "lenscompare.report", "lenscompare.experiment"])
def test_modules_import_cleanly_on_their_own(module):
    import importlib

    importlib.import_module(module)
