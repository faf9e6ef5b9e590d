"""The import graph of python/manakov has no cycle (imports inside functions count).

The graph is read from the source with ``ast``, not from ``sys.modules``: an
import inside a function body runs only when the function is called, yet it
still ties the two modules together (and forms a circle the day someone moves
it to the top). The checker is tested on synthetic graphs, so that it can fail.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = "manakov"
PACKAGE_DIR = Path(__file__).resolve().parents[1] / "python" / PACKAGE


def _module_name(path: Path) -> str:
    return path.stem  # "top", "__init__", "_checks", ...


def _target(node: ast.ImportFrom | ast.Import, alias: ast.alias, modules: set[str]) -> list[str]:
    """The package modules an import statement names (possibly none)."""
    found = []
    if isinstance(node, ast.Import):
        parts = alias.name.split(".")
        if parts[0] == PACKAGE and len(parts) >= 2 and parts[1] in modules:
            found.append(parts[1])
        return found
    # ast.ImportFrom
    if node.level == 0:
        parts = (node.module or "").split(".")
        if parts[0] != PACKAGE:
            return found
        rest = parts[1:]
    elif node.level == 1:
        rest = (node.module or "").split(".") if node.module else []
    else:  # beyond the package: not ours
        return found
    if rest and rest[0] in modules:
        found.append(rest[0])
    elif not rest and alias.name in modules:
        # "from . import theta" / "from manakov import theta"
        found.append(alias.name)
    elif not rest:
        # "from manakov import kotter": names re-exported by __init__ depend on it
        found.append("__init__")
    return found


def import_graph(source: dict[str, str]) -> dict[str, set[str]]:
    """Module -> the package modules it imports, anywhere in its body.

    ``source`` maps module names (file stems, ``__init__`` for the package) to
    their code. Imports of the package itself (``from . import x`` of a
    non-module name) count as imports of ``__init__``.
    """
    modules = set(source)
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, code in source.items():
        for node in ast.walk(ast.parse(code)):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for alias in node.names:
                    for t in _target(node, alias, modules):
                        if t != name:
                            graph[name].add(t)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a closed path ``[m0, m1, ..., m0]``, or None."""
    white, grey, black = 0, 1, 2
    colour = dict.fromkeys(graph, white)
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        colour[m] = grey
        stack.append(m)
        for n in sorted(graph.get(m, ())):
            if colour.get(n, black) == grey:
                return stack[stack.index(n) :] + [n]
            if colour.get(n) == white:
                found = visit(n)
                if found:
                    return found
        stack.pop()
        colour[m] = black
        return None

    for m in sorted(graph):
        if colour[m] == white:
            found = visit(m)
            if found:
                return found
    return None


def package_source() -> dict[str, str]:
    """Every module of the package; the compiled ``_core`` through its stub."""
    src = {_module_name(p): p.read_text() for p in sorted(PACKAGE_DIR.glob("*.py"))}
    for stub in sorted(PACKAGE_DIR.glob("*.pyi")):
        src.setdefault(_module_name(stub), stub.read_text())
    return src


def test_the_package_import_graph_has_no_cycle():
    src = package_source()
    assert {"top", "theta", "_checks", "_core", "__init__"} <= set(src)
    graph = import_graph(src)
    # __init__ imports every public module and nothing imports __init__ back
    # (a module importing "from . import name" of a re-export would close a circle).
    cycle = find_cycle(graph)
    assert cycle is None, f"import cycle in python/manakov: {' -> '.join(cycle or [])}"


def test_the_graph_sees_the_known_edges():
    """The parser finds real edges of the package (so an empty graph cannot pass)."""
    graph = import_graph(package_source())
    assert "theta" in graph["__init__"]
    assert "top" in graph["cli"]
    assert "_checks" in graph["top"]


def test_the_shared_checks_are_the_bottom_and_theta_is_a_leaf():
    graph = import_graph(package_source())
    assert graph["_checks"] <= {"_core"}
    assert graph["theta"] <= {"_core"}
    assert graph["_core"] == set()


FUNCTION_LEVEL_CYCLE = {
    "a": "from . import b\n",
    "b": "def f():\n    from .c import g\n    return g\n",
    "c": "import numpy\n\ndef g():\n    import manakov.a\n    return manakov.a\n",
}


def test_checker_finds_a_cycle_through_imports_inside_functions():
    graph = import_graph(FUNCTION_LEVEL_CYCLE)
    assert graph == {"a": {"b"}, "b": {"c"}, "c": {"a"}}
    cycle = find_cycle(graph)
    assert cycle is not None and cycle[0] == cycle[-1] and set(cycle) == {"a", "b", "c"}


@pytest.mark.parametrize(
    "source, edge",
    [
        ({"x": "from .y import z\n", "y": ""}, ("x", "y")),
        ({"x": "from manakov.y import z\n", "y": ""}, ("x", "y")),
        ({"x": "import manakov.y as yy\n", "y": ""}, ("x", "y")),
        ({"x": "from manakov import y\n", "y": ""}, ("x", "y")),
        ({"x": "from . import kotter\n", "__init__": ""}, ("x", "__init__")),
        ({"x": "class C:\n    def m(self):\n        from .y import q\n", "y": ""}, ("x", "y")),
    ],
)
def test_checker_reads_every_import_form(source, edge):
    graph = import_graph(source)
    assert edge[1] in graph[edge[0]]


def test_checker_ignores_other_packages_and_accepts_a_dag():
    src = {
        "a": "import numpy\nfrom os import path\nfrom .b import x\n",
        "b": "from .c import y\n",
        "c": "from ..other import z\nimport manakovx\n",
    }
    graph = import_graph(src)
    assert graph == {"a": {"b"}, "b": {"c"}, "c": set()}
    assert find_cycle(graph) is None
    graph["c"].add("a")
    assert find_cycle(graph) == ["a", "b", "c", "a"]
