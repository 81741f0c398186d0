"""The package's layers: imports go downwards only and form no cycle.

Every import inside python/bayesgrasp is read from the source (nothing is imported) and resolved
to the importing and the imported *module*: each .py file is a node, a package's ``__init__.py``
is the node named after the package, and the compiled ``_core`` (with its submodules) is the node
``bayesgrasp._core``. On that module graph:

* every top-level module or sub-package has a layer in ``LAYERS``;
* an import from one top-level entry to another goes strictly downwards: never up, and never
  sideways to a peer in the same layer;
* there is no cycle, inside packages included: a package's ``__init__`` importing its own modules
  is an edge like any other, so ``planners/__init__ -> planners.stability -> planners/__init__``
  is a cycle.

Conventions:

* Lazy imports (inside functions) count like module-level ones, for the layers and for the
  cycles: deferring an import defers the dependency, it does not remove it. Cycles that only
  close through a lazy import and that the package keeps on purpose are listed, edge by edge and
  with their reason, in ``KNOWN_CYCLE_EDGES``; nothing else is exempt.
* ``import a.b.c`` and ``from a.b.c import x`` are edges to ``a.b.c`` only, not to the parent
  packages that Python runs first (else every module would be in a cycle with its package's
  ``__init__``).
* ``from pkg import name`` is an edge to ``pkg.name`` if that is a module, else to ``pkg``.
* ``if TYPE_CHECKING:`` imports count too (there is one: experiments.registry -> loop.context).

``check(root)`` runs all of it on any copy of the package; the meta-tests below plant a cycle and
a sideways import in a copy and see it fail.
"""
import ast
import shutil
from pathlib import Path
from typing import Dict, List, Set, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[2] / "python" / "bayesgrasp"
EXTENSIONS = {"_core"}   # compiled from cpp/bindings: no source in the package

# Layer of each top-level module or sub-package, lowest first. "" is the package's own __init__.
# Strictly downwards: members of one layer are peers and may not import each other.
LAYERS = [
    {"", "_core", "_args", "cache", "hand_urdf", "client", "progress"},  # peers: they import nothing of the package
    # the numerical modules, ordered by their imports; peers in a row import none of each other
    {"hand", "gp", "belief", "optim", "quality", "lift_trace", "io", "decomposition"},
    {"sim", "vision"},               # sim -> hand; vision -> belief
    {"physics"},                     # physics -> sim
    {"objects"},
    {"arm"},                         # the arm under the hand: URDF kinematics, batched IK, its collisions
    {"world"},
    {"models"},
    {"planners"},
    {"viz"},
    {"viewer"},                      # viewer -> viz
    {"loop"},                        # the run context, the episodes, the category pipeline
    {"experiments", "service"},      # the thesis's experiments and the HTTP service, both on the loop
    {"cli", "cache_build"},           # cache_build runs the CLI to fill the shipped cache
]
LEVEL = {name: i for i, layer in enumerate(LAYERS) for name in layer}

# (importer, imported) edges allowed to close a cycle, each with its reason. Both are lazy imports.
KNOWN_CYCLE_EDGES = {
    ("bayesgrasp.experiments.driver", "bayesgrasp.experiments"):
        "driver._prepare_object imports the package inside the function so that every experiment is registered",
}

Graph = Dict[str, Set[Tuple[str, int]]]


# ---- the checker: it takes the package root ------------------------------------------------------
def _module_name(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _node(root: Path, module: str) -> str:
    """The graph node of a module name: itself, or the extension it lies in."""
    parts = module.split(".")
    if len(parts) > 1 and parts[0] == root.name and parts[1] in EXTENSIONS:
        return ".".join(parts[:2])
    return module


def _exists(root: Path, module: str) -> bool:
    parts = module.split(".")
    if parts[0] != root.name:
        return False
    if len(parts) > 1 and parts[1] in EXTENSIONS:
        return True
    p = root.parent.joinpath(*parts)
    return p.with_suffix(".py").exists() or (p / "__init__.py").exists()


def _imports(root: Path, path: Path):
    """(imported module, line) for every import of a module of the package in the file."""
    name = _module_name(root, path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):   # ast.walk: inside functions and ``if`` blocks too
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == root.name:
                    yield _node(root, a.name), node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.split(".")[0] == root.name:
                target = node.module
            else:
                continue
            # "from . import x" / "from .pkg import mod": the names may be modules themselves
            for a in node.names:
                candidate = f"{target}.{a.name}"
                yield _node(root, candidate if _exists(root, candidate) else target), node.lineno


def module_graph(root: Path) -> Graph:
    """importer -> {(imported module, line)} for every module of the package at ``root``."""
    graph: Graph = {f"{root.name}.{e}": set() for e in EXTENSIONS}
    for path in sorted(root.rglob("*.py")):
        src = _module_name(root, path)
        graph.setdefault(src, set())
        for dst, line in _imports(root, path):
            if dst != src:
                graph[src].add((dst, line))
    return graph


def _top(module: str) -> str:
    """The top-level entry a module belongs to ("" for the package's __init__)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def unlayered(graph: Graph) -> List[str]:
    return sorted({_top(m) for m in graph} - set(LEVEL))


def layer_violations(graph: Graph) -> List[str]:
    """Imports between top-level entries that do not go strictly downwards."""
    bad = []
    for src in sorted(graph):
        a = _top(src)
        for dst, line in sorted(graph[src]):
            b = _top(dst)
            if a == b or a not in LEVEL or b not in LEVEL:
                continue
            if LEVEL[b] > LEVEL[a]:
                bad.append(f"{src}:{line} imports {dst} (layer of {b!r} above {a!r})")
            elif LEVEL[b] == LEVEL[a]:
                bad.append(f"{src}:{line} imports {dst} (sideways: {b!r} and {a!r} are peers)")
    return bad


def import_cycles(graph: Graph, allowed=KNOWN_CYCLE_EDGES) -> List[str]:
    """The cycles of the module graph without the ``allowed`` edges, one per back edge found."""
    edges = {m: sorted({d for d, _ in ts if d in graph and (m, d) not in allowed}) for m, ts in graph.items()}
    lines = {(m, d): line for m, ts in graph.items() for d, line in ts}
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for d in edges[m]:
            if state.get(d) == 1:
                c = stack[stack.index(d):] + [d]
                cycles.append(" -> ".join(f"{a} (line {lines[a, b]})" for a, b in zip(c, c[1:])) + f" -> {d}")
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(edges):
        if m not in state:
            visit(m)
    return cycles


def check(root: Path) -> List[str]:
    """Every problem with the package at ``root``: unlayered entries, imports not going down,
    cycles, and exemptions in KNOWN_CYCLE_EDGES that no longer match an import."""
    graph = module_graph(root)
    problems = [f"no layer in this test: {t!r}" for t in unlayered(graph)]
    problems += layer_violations(graph)
    problems += [f"import cycle: {c}" for c in import_cycles(graph)]
    present = {(m, d) for m, ts in graph.items() for d, _ in ts}
    problems += [f"stale exemption: {e}" for e in sorted(set(KNOWN_CYCLE_EDGES) - present)]
    return problems


# ---- the package ---------------------------------------------------------------------------------
_GRAPH = None


def _graph() -> Graph:
    global _GRAPH
    if _GRAPH is None:
        _GRAPH = module_graph(ROOT)
    return _GRAPH


def test_every_module_has_a_layer():
    assert not unlayered(_graph()), f"modules without a layer in this test: {unlayered(_graph())}"


def test_imports_go_downwards_only():
    bad = layer_violations(_graph())
    assert not bad, "\n".join(bad)


def test_no_import_cycle_between_modules():
    cycles = import_cycles(_graph())
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_the_exempt_edges_exist_and_each_closes_a_cycle():
    """An exemption must still be needed: the edge is there, and without it a cycle is missed."""
    graph = _graph()
    for edge in KNOWN_CYCLE_EDGES:
        assert edge[1] in {d for d, _ in graph.get(edge[0], ())}, f"stale exemption: {edge}"
        others = {e: r for e, r in KNOWN_CYCLE_EDGES.items() if e != edge}
        assert import_cycles(graph, others), f"{edge} closes no cycle; drop the exemption"


def test_the_checker_sees_the_modules_inside_packages():
    """Guards the checker against going blind: edges inside packages and to _core are in the graph."""
    graph = _graph()
    edges = {(m, d) for m, ts in graph.items() for d, _ in ts}
    assert ("bayesgrasp.planners", "bayesgrasp.planners.stability") in edges
    assert ("bayesgrasp.planners.stability", "bayesgrasp.planners.base") in edges
    assert ("bayesgrasp.physics", "bayesgrasp.sim") in edges
    assert any(d == "bayesgrasp._core" for d, _ in graph["bayesgrasp.gp"])
    assert len(graph) > 80


@pytest.mark.parametrize("module, forbidden", [
    ("bayesgrasp.world", {"viz", "cli", "experiments", "planners"}),
    ("bayesgrasp.vision", {"viz", "cli", "objects", "experiments"}),
    ("bayesgrasp.planners", {"experiments", "cli", "viz"}),
    ("bayesgrasp.loop", {"experiments", "cli", "viz", "viewer"}),
    ("bayesgrasp.service", {"experiments", "cli", "viz", "viewer", "planners", "models", "world", "objects"}),
])
def test_named_modules_hold_no_plotting_or_command_code(module, forbidden):
    graph = _graph()
    found = {_top(d) for m, ts in graph.items() if m == module or m.startswith(module + ".") for d, _ in ts}
    assert not (found & forbidden), f"{module} imports {sorted(found & forbidden)}"


# ---- meta-tests: the checker fails on a copy of the package with a planted fault ------------------
def _copy(tmp_path: Path) -> Path:
    root = tmp_path / "bayesgrasp"
    shutil.copytree(ROOT, root, ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.pyd"))
    return root


def _plant(root: Path, rel: str, old: str, new: str) -> int:
    """Replaces ``old`` (appends if empty) by ``new`` in the copy's file; returns new's first line."""
    path = root / rel
    text = path.read_text()
    if old:
        assert text.count(old) == 1, f"{rel}: the plant's anchor {old!r} is gone"
        line = text[:text.index(old)].count("\n") + 1
        path.write_text(text.replace(old, new))
    else:
        text = text if text.endswith("\n") else text + "\n"
        line = text.count("\n") + 1
        path.write_text(text + new)
    return line


def test_the_checker_passes_an_untouched_copy(tmp_path):
    """The control for the meta-tests below: what fails there is the plant, not the copying."""
    assert check(_copy(tmp_path)) == []


def test_the_checker_fails_a_package_init_cycle(tmp_path):
    """planners.stability takes its base classes from the package's __init__, which imports
    stability: no layer is crossed, only the module-level cycle check sees it."""
    root = _copy(tmp_path)
    line = _plant(root, "planners/stability.py", "from .base import Planner", "from . import Planner")
    problems = check(root)
    cycles = [p for p in problems if p.startswith("import cycle:")]
    assert cycles and all("bayesgrasp.planners.stability (line %d) -> bayesgrasp.planners" % line in c
                          for c in cycles), problems
    assert not layer_violations(module_graph(root)), "a cycle inside one package crosses no layer"


def test_the_checker_fails_a_low_module_importing_a_high_one(tmp_path):
    """hand (numerical layer) imports planners (which imports hand): upward edge and cycle."""
    root = _copy(tmp_path)
    line = _plant(root, "hand.py", "", "from bayesgrasp.planners import make_planner\n")
    problems = check(root)
    upward = f"bayesgrasp.hand:{line} imports bayesgrasp.planners (layer of 'planners' above 'hand')"
    assert upward in problems, problems
    assert any(p.startswith("import cycle:") and f"bayesgrasp.hand (line {line}) -> bayesgrasp.planners" in p
               for p in problems), problems


def test_the_checker_counts_a_lazy_import(tmp_path):
    """The docstring's convention: an import inside a function is an edge too."""
    root = _copy(tmp_path)
    line = _plant(root, "gp.py", "",
                  "\n\ndef _planted():\n    from bayesgrasp.experiments import run\n    return run\n")
    problems = check(root)
    assert f"bayesgrasp.gp:{line + 3} imports bayesgrasp.experiments (layer of 'experiments' above 'gp')" in problems, \
        problems
    assert any(p.startswith("import cycle:") and f"bayesgrasp.gp (line {line + 3}) -> bayesgrasp.experiments" in p
               for p in problems), problems


def test_the_checker_fails_a_sideways_import_between_peers(tmp_path):
    """gp and optim share a layer; neither may import the other (no cycle involved)."""
    root = _copy(tmp_path)
    line = _plant(root, "gp.py", "", "import bayesgrasp.optim\n")
    assert check(root) == [f"bayesgrasp.gp:{line} imports bayesgrasp.optim (sideways: 'optim' and 'gp' are peers)"]


def test_the_checker_fails_a_stale_exemption(tmp_path):
    """Dropping the exempt lazy import must surface as a stale exemption, not pass silently."""
    root = _copy(tmp_path)
    _plant(root, "experiments/driver.py", "    from . import get_experiment as registered",
           "    from .registry import get_experiment as registered")
    assert check(root) == [f"stale exemption: {e}" for e in sorted(KNOWN_CYCLE_EDGES)]
