"""The package's layers (DESIGN.md): imports go downwards only and form no cycle.

Every import inside python/bayesgrasp is read from the source (module level and inside functions
alike), resolved to the importing and the imported module, and checked."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "python" / "bayesgrasp"

# Layer of each top-level module or sub-package, lowest first (DESIGN.md's picture, upside down).
LAYERS = [
    {"_core", "_args", "cache", "data"},
    {"hand", "sim", "quality", "physics", "gp", "belief", "optim", "vision", "lift_trace", "io"},
    {"objects"},
    {"world"},
    {"models"},
    {"planners"},
    {"viz", "viewer"},
    {"experiments"},
    {"cli"},
]
LEVEL = {name: i for i, layer in enumerate(LAYERS) for name in layer}


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: Path):
    """(imported module, line) for every import of a bayesgrasp module in the file."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "bayesgrasp":
                    yield a.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.split(".")[0] == "bayesgrasp":
                target = node.module
            else:
                continue
            # "from . import x" / "from .pkg import mod": the names may be modules themselves
            for a in node.names:
                candidate = f"{target}.{a.name}"
                yield (candidate if _exists(candidate) else target), node.lineno


def _exists(module: str) -> bool:
    p = ROOT.parent.joinpath(*module.split("."))
    return p.with_suffix(".py").exists() or (p / "__init__.py").exists()


def _top(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _graph():
    graph = {}
    for path in ROOT.rglob("*.py"):
        src = _module_name(path)
        graph.setdefault(src, set())
        for dst, line in _imports(path):
            if dst != src and dst.startswith("bayesgrasp."):
                graph[src].add((dst, line))
    return graph


def test_every_module_has_a_layer():
    tops = {_top(m) for m in _graph()} - {""}
    assert tops <= set(LEVEL), f"modules without a layer in this test: {sorted(tops - set(LEVEL))}"


def test_imports_go_downwards_only():
    bad = []
    for src, targets in _graph().items():
        a = _top(src)
        for dst, line in targets:
            b = _top(dst)
            if a and b and a != b and LEVEL[b] > LEVEL[a]:
                bad.append(f"{src}:{line} imports {dst} (layer {b} above {a})")
    assert not bad, "\n".join(bad)


def test_no_import_cycle_between_modules():
    graph = {m: {d for d, _ in ts if d in _graph_nodes()} for m, ts in _graph().items()}
    # a package's __init__ re-exporting its own modules is not a cycle of concern: drop edges
    # from a package to the modules inside it
    graph = {m: {d for d in ds if not d.startswith(m + ".")} for m, ds in graph.items()}
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for d in sorted(graph.get(m, ())):
            if state.get(d) == 1:
                cycles.append(stack[stack.index(d):] + [d])
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


_NODES = None


def _graph_nodes():
    global _NODES
    if _NODES is None:
        _NODES = set(_graph())
    return _NODES


@pytest.mark.parametrize("module, forbidden", [
    ("bayesgrasp.world", {"viz", "cli", "experiments", "planners"}),
    ("bayesgrasp.vision", {"viz", "cli", "objects", "experiments"}),
    ("bayesgrasp.planners", {"experiments", "cli", "viz"}),
])
def test_named_modules_hold_no_plotting_or_command_code(module, forbidden):
    graph = _graph()
    found = {_top(d) for m, ts in graph.items() if m == module or m.startswith(module + ".") for d, _ in ts}
    assert not (found & forbidden), f"{module} imports {sorted(found & forbidden)}"
