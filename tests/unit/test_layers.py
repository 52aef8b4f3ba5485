"""The package's layers (docs/architecture.md): no import cycle among covcontact's modules (imports inside
functions count), and the rules of who may import whom."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src" / "covcontact"


def _module(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports() -> dict[str, set[str]]:
    """module -> the covcontact modules it imports (at the top or inside functions)."""
    modules = {_module(p): p for p in SRC.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        out = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                candidates = [target] + [f"{target}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                candidates = [a.name for a in node.names]
            else:
                continue
            for c in candidates:
                if c in modules and c != name:
                    out.add(c)
        graph[name] = out
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def _reaches(graph: dict[str, set[str]], start: str) -> set[str]:
    seen, todo = set(), [start]
    while todo:
        for w in graph[todo.pop()]:
            if w not in seen:
                seen.add(w)
                todo.append(w)
    return seen


def test_no_import_cycle():
    graph = _imports()
    assert len(graph) > 50  # the whole package was read
    assert _cycles(graph) == []


def test_the_serial_run_knows_nothing_of_mpi():
    """The run, Newton and the serial model reach no module of covcontact.parallel but the launcher's
    environment queries (the distributed run is the PETSc backend's strategy, parallel/run.py)."""
    graph = _imports()
    for start in ("covcontact.solvers.run", "covcontact.solvers.newton", "covcontact.solvers.model",
                  "covcontact.solvers.procedure"):
        reached = {m for m in _reaches(graph, start) if m.startswith("covcontact.parallel")}
        assert reached <= {"covcontact.parallel", "covcontact.parallel.launcher"}, (start, reached)


def test_lower_layers_do_not_reach_up():
    graph = _imports()
    rules = {
        "covcontact.contact": ("covcontact.io", "covcontact.solvers", "covcontact.problem"),
        "covcontact.assembly": ("covcontact.problem", "covcontact.solvers", "covcontact.io"),
        "covcontact.elements": ("covcontact.problem", "covcontact.solvers", "covcontact.io", "covcontact.contact"),
        "covcontact.materials": ("covcontact.problem", "covcontact.solvers", "covcontact.io",
                                 "covcontact.elements"),
        "covcontact.description": ("covcontact.solvers", "covcontact.io", "covcontact.problem"),
        "covcontact.loads": ("covcontact.solvers", "covcontact.io", "covcontact.problem"),
    }
    for low, above in rules.items():
        for name, targets in graph.items():
            if name == low or name.startswith(low + "."):
                bad = {t for t in targets if t.startswith(above)}
                assert not bad, f"{name} imports {sorted(bad)}"
