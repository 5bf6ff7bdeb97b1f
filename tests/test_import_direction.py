"""Imports run one way between the layers, which are the sub-packages, and form no cycle,
counting lazy imports inside functions too.

The walk reads every module of the package with ``ast`` (nothing is imported),
resolves relative imports, and checks each edge against ``LAYER``: a module may
import only modules of its own or a lower layer.  The layer of a module is that of its
top-level name (``contact.system`` is in ``contact``); a new sub-package or top-level
module must be given a layer here, which is the point: its place is decided once.
"""
import ast
import functools
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "beamsolver"

LAYER = {
    # no physics: errors, typed solver failures, the version, the numba decorator and its cache stamp
    "errors": 0, "failures": 0, "version": 0, "_jit": 0, "jit_cache": 0,
    "lie": 1,          # SE(3)/SO(3) maps, numpy and compiled
    "elements": 2,     # element contract, kernels (numpy and compiled), registry
    "model": 3,        # what the user declares: Model, sections, geometry, cables, motions, checks
    "contact": 4,      # search, pair rules, projection, laws, kernels, orchestration
    "assembly": 5,     # DOF map, constraints, pattern, scatter
    "nonlinear": 6,    # Problem, linear solvers, definiteness, modes
    "results": 7,      # Solution, its file format, linearisation, topology
    "stepping": 8,     # steppers, cut-backs, stabilisation, branch switching, restart, diagnosis
    "driver": 9,       # solve(): arguments, Problem, stepper, writers
    "io": 10,          # writers and readers
    "app": 11,         # command line, sweeps, studies, pictures
    "": 11,            # the package's public face (the command line imports it)
}

# lazy imports against the direction, each with its reason
ALLOWED_UPWARD = {
    ("driver", "io.vtk"): "solve(output=folder) creates the default step writer, imported only then",
    ("driver", "io"): "the package of io.vtk, which Python runs before it (same lazy import)",
    ("driver", "io.writers"): "solve(output=folder) opens the writers (archive and formats), imported only then",
    ("model.validation", "results.solution_file"): "solve(restart=file) checks the file's last time",
    ("model.validation", "results"): "the package of results.solution_file (same lazy import)",
}


def layer(module):
    return LAYER[module.split(".")[0]]


def _name(path):
    rel = path.relative_to(PACKAGE).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules():
    return {_name(p): p for p in PACKAGE.rglob("*.py")}


def _resolve(module, node, modules):
    """Target module names (relative to the package) of one import statement."""
    is_pkg = modules[module].name == "__init__.py"
    if isinstance(node, ast.Import):
        out = []
        for a in node.names:
            if a.name == "beamsolver" or a.name.startswith("beamsolver."):
                out.append(a.name[len("beamsolver."):] if "." in a.name else "")
        return out
    if node.level == 0:
        if not (node.module == "beamsolver" or (node.module or "").startswith("beamsolver.")):
            return []
        base = node.module[len("beamsolver."):] if "." in node.module else ""
    else:
        parts = module.split(".") if module else []
        if not is_pkg:
            parts = parts[:-1]
        parts = parts[:len(parts) - (node.level - 1)] if node.level > 1 else parts
        base = ".".join(parts + ([node.module] if node.module else []))
    out = []
    for a in node.names:
        sub = f"{base}.{a.name}" if base else a.name
        out.append(sub if sub in modules else base)
    return out


def _parents(target):
    """The packages Python runs before ``target`` (``io.archive`` runs ``io/__init__`` first)."""
    parts = target.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


@functools.lru_cache(maxsize=1)          # one walk of the package for the tests below (read only)
def _edges():
    modules = _modules()
    edges = []
    for mod, path in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        top = {id(n) for n in tree.body}
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in _resolve(mod, node, modules):
                    for t in [target] + [p for p in _parents(target) if not mod.startswith(p + ".")]:
                        if t != mod:
                            edges.append((mod, t, id(node) not in top))
    return modules, tuple(edges)


def test_every_module_has_a_layer():
    modules, _ = _edges()
    assert sorted(m for m in modules if m.split(".")[0] not in LAYER) == [], \
        "give new sub-packages and top-level modules a layer in LAYER"


def test_imports_run_one_way():
    _, edges = _edges()
    bad = [(a, b, "lazy" if lazy else "module level") for a, b, lazy in edges
           if layer(b) > layer(a) and ((a, b) not in ALLOWED_UPWARD or not lazy)]
    assert bad == []


def _cycle(edges):
    graph = {}
    for a, b, _ in edges:
        graph.setdefault(a, set()).add(b)
    state = {}

    def visit(n, stack):
        state[n] = 1
        for m in graph.get(n, ()):
            if state.get(m) == 1:
                return stack + [n, m]
            if m not in state:
                found = visit(m, stack + [n])
                if found:
                    return found
        state[n] = 2
        return None
    for n in list(graph):
        if n not in state:
            found = visit(n, [])
            if found:
                return found
    return None


@pytest.mark.parametrize("lazy", [False, True], ids=["module-level", "with lazy imports"])
def test_no_import_cycles(lazy):
    _, edges = _edges()
    assert _cycle([e for e in edges if lazy or not e[2]]) is None


def test_the_walk_sees_known_edges():
    """The checker itself: it finds the edges it must (so an empty list of violations means something)."""
    _, edges = _edges()
    pairs = {(a, b) for a, b, _ in edges}
    assert {("elements.se3_2", "elements.element"), ("elements.geometric", "lie.se3"), ("driver", "nonlinear.problem"),
            ("nonlinear.problem", "assembly.system"), ("results.solution", "results.solution_file"),
            ("io.archive", "results.solution"), ("contact.frames", "lie.se3"), ("contact.reference", "contact.frames"),
            ("nonlinear.problem", "contact.system"), ("", "driver"), ("driver", "io")} <= pairs
    assert _cycle([("a", "b", False), ("b", "c", True), ("c", "a", True)]) is not None


def test_importing_a_submodule_counts_its_package():
    """``from .io.files import x`` runs ``io/__init__`` first: the walk sees that edge too, so a
    low module inside a high package (the old ``io.archive``, imported by ``results`` while
    ``io/__init__`` imported ``results``) is a cycle the test catches."""
    assert _parents("io.archive") == ["io"] and _parents("contact.kernel_jit") == ["contact"]
    _, edges = _edges()
    assert ("results.solution", "io") not in {(a, b) for a, b, _ in edges}
    old = [("results", "io.archive", True), ("results", "io", True), ("io", "results", False)]
    assert _cycle(old) is not None


# the test oracles: beside their kernels, imported by tests and benchmarks only
ORACLES = ("contact.reference", "elements.reference")
# lazy imports of an oracle, each with its reason
ALLOWED_ORACLE = {
    ("contact.system", "contact.reference"): "use_numpy_kernel(True) makes the oracle the kernel of new contact systems, imported only then",
    ("contact.pairs", "contact.reference"): "old names of the oracle, read through the module's __getattr__ only",
}


def test_production_never_imports_an_oracle():
    modules, edges = _edges()
    assert set(ORACLES) <= set(modules)
    bad = [(a, b, "lazy" if lazy else "module level") for a, b, lazy in edges
           if b in ORACLES and a not in ORACLES and ((a, b) not in ALLOWED_ORACLE or not lazy)]
    assert bad == []


def test_few_modules_at_the_top():
    """The layers are the folders: at most 8 modules beside the sub-packages."""
    top = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(top) <= 8, top
