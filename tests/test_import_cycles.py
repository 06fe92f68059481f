"""No two modules of the package import each other, directly or through
others (at module level or inside functions). A subpackage's ``__init__``
importing its own modules is the package's structure, not a cycle, so
imports of a package (``from fractalgeo_rs.lsystem import X``) count as
imports of that ``__init__`` only when made from outside the subpackage."""
import ast
from pathlib import Path

import fractalgeo_rs

ROOT = Path(fractalgeo_rs.__file__).resolve().parent


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _graph():
    modules = {_module_name(p): p for p in ROOT.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        edges = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                targets = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            for t in targets:
                if t in modules and t != name and t != "fractalgeo_rs":
                    if path.name != "__init__.py" and name.startswith(t + "."):
                        continue  # a module importing names of its own package
                    edges.add(t)
        graph[name] = edges
    return graph


def _cycle(graph):
    state, stack = {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                return stack[stack.index(m):] + [m]
            if m not in state:
                found = visit(m)
                if found:
                    return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(graph):
        if n not in state:
            found = visit(n)
            if found:
                return found
    return None


def test_the_graph_sees_the_lsystem_modules():
    g = _graph()
    assert "fractalgeo_rs.lsystem.mesh" in g["fractalgeo_rs.lsystem.export"]


def test_no_import_cycle():
    cycle = _cycle(_graph())
    assert cycle is None, " -> ".join(cycle)
