"""Imports run one way (maths -> element/contact kernels -> assembly -> problem -> results -> solver -> io/cli/viz)
and form no cycle, counting lazy imports inside functions too.

The walk reads every module of the package with ``ast`` (nothing is imported),
resolves relative imports, and checks each edge against ``LAYER``: a module may
import only modules of its own or a lower layer.  A new module must be given a
layer here, which is the point: its place in the direction is decided once.
"""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "beamsolver"

LAYER = {
    # 0: no physics (errors, argument checks, the numpy file format of saved solutions)
    "errors": 0, "version": 0, "_jit": 0, "jit_cache": 0, "progress": 0, "validation": 0, "solution_file": 0, "files": 0,
    "failures": 0,
    # 1: maths and geometry (Lie groups, sections, node poses, motions)
    "se3": 1, "se3_jit": 1, "section": 1, "geometry": 1, "motion": 1, "motion_path": 1, "definiteness": 1,
    "bandfactor": 1,
    "modes": 1, "material_range": 1,
    # 2: element and contact kernels
    "element": 2, "element_jit": 2, "elements": 2, "elements.base": 2, "elements.se3_2": 2, "elements.se3_3": 2,
    "blocks": 2, "line_load": 2, "contact": 2, "contact.law": 2, "contact.kinematics": 2,
    "contact.pairs": 2, "contact.search": 2, "contact.kernel_jit": 2, "contact.options": 2, "contact.record": 2,
    "contact.projection": 2, "contact.rules": 2, "contact.ownership": 2, "contact.state": 2, "contact.adjust": 2, "contact.mortar": 2,
    # 3: model declarations and their assembly
    "model": 3, "contributions": 3, "cables": 3, "bending": 3, "assembly": 3, "stabilize": 3, "topology": 1, "assembly_jit": 3,
    "extra_pattern": 3,
    "contact.system": 3, "contact.conditioning": 3, "linsolve": 3, "bifurcation": 3,
    # 4: the Problem interface between the solver and the physics
    "problem": 4, "jit_warmup": 4,
    # 5: results
    "results": 5, "resultants": 5, "restart": 5, "study": 5,
    # 6: solver, its stepping and failure diagnosis, linearisation
    "solver": 6, "stepping": 6, "stable_branch": 6, "arclength": 6, "diagnosis": 6, "linear": 6, "branching": 6,
    # 7: output, pictures, command line, the package's public face
    "io": 7, "io.archive": 7, "io.lines": 7, "io.vtk": 7, "io.vtu": 7, "io.paraview": 7, "viz": 7, "cli": 7, "sweep_engine": 7, "sweep_cli": 7, "": 7,
}

# lazy imports against the direction, each with its reason
ALLOWED_UPWARD = {
    ("solver", "io.vtk"): "solve(output=folder) creates the default step writer, imported only then",
    ("solver", "io"): "the package of io.vtk, which Python runs before it (same lazy import)",
}


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
    return modules, edges


def test_every_module_has_a_layer():
    modules, _ = _edges()
    assert sorted(set(modules) - set(LAYER)) == [], "give new modules a layer in LAYER"


def test_imports_run_one_way():
    _, edges = _edges()
    bad = [(a, b, "lazy" if lazy else "module level") for a, b, lazy in edges
           if LAYER[b] > LAYER[a] and ((a, b) not in ALLOWED_UPWARD or not lazy)]
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
    assert {("elements.se3_2", "element"), ("element", "se3"), ("solver", "problem"), ("problem", "assembly"),
            ("results", "solution_file"), ("io.archive", "results"), ("contact.pairs", "se3"),
            ("problem", "contact.system"), ("", "solver"), ("solver", "io")} <= pairs
    assert _cycle([("a", "b", False), ("b", "c", True), ("c", "a", True)]) is not None


def test_importing_a_submodule_counts_its_package():
    """``from .io.files import x`` runs ``io/__init__`` first: the walk sees that edge too, so a
    low module inside a high package (the old ``io.archive``, imported by ``results`` while
    ``io/__init__`` imported ``results``) is a cycle the test catches."""
    assert _parents("io.archive") == ["io"] and _parents("contact.kernel_jit") == ["contact"]
    _, edges = _edges()
    assert ("results", "io") not in {(a, b) for a, b, _ in edges}
    old = [("results", "io.archive", True), ("results", "io", True), ("io", "results", False)]
    assert _cycle(old) is not None
