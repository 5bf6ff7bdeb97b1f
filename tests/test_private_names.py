"""No module reaches the private names of the solver, its stepping, the Problem or the assembly.

A private name of one of ``OWNERS`` is one starting with a single underscore that
the module defines: a top-level function, class or variable, a method or class
attribute, or an attribute it sets on ``self``.  Every other file of the package
and every test, benchmark and example is read with ``ast`` (nothing is
imported); it may neither import such a name nor read it as an attribute of
anything but ``self``/``cls`` -- a name that two owners or an outside class also
define is still caught, which errs on the safe side.  What must stay is in
``ALLOWED`` with its reason.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "beamsolver"
OWNERS = ("driver", "nonlinear.newton", "stepping.steps", "nonlinear.problem", "assembly.system")
SCANNED = ("beamsolver", "tests", "benchmarks", "examples")

# (file relative to the repository, private name): reason
ALLOWED = {}


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def private_names(path):
    """Private names ``path`` defines (see the module docstring)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) \
                and isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            names.add(node.attr)
    return {n for n in names if _private(n)}


def _module_of(import_from, path):
    """Dotted module of an ``ImportFrom`` relative to the package (``None`` outside it)."""
    mod = import_from.module or ""
    if import_from.level:
        parent = path.relative_to(PACKAGE).parent.parts if PACKAGE in path.parents else ()
        base = parent[:len(parent) - (import_from.level - 1)]
        return ".".join(base + tuple(p for p in mod.split(".") if p))
    return mod[len("beamsolver."):] if mod.startswith("beamsolver.") else None


def violations(path, owned):
    """``(private name, line)`` reached by ``path`` in the modules of ``owned`` {module: names}."""
    tree = ast.parse(path.read_text())
    rel = path.relative_to(PACKAGE).with_suffix("").as_posix().replace("/", ".") \
        if PACKAGE in path.parents else None
    foreign = set().union(*(names for mod, names in owned.items() if mod != rel))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and _module_of(node, path) in owned \
                and _module_of(node, path) != rel:
            found += [(a.name, node.lineno) for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Attribute) and node.attr in foreign \
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")):
            found.append((node.attr, node.lineno))
    return found


def _files():
    for folder in SCANNED:
        yield from sorted((ROOT / folder).rglob("*.py"))


@pytest.mark.slow
def test_no_private_cross_module_access():
    owned = {m: private_names(PACKAGE / (m.replace(".", "/") + ".py")) for m in OWNERS}
    bad = []
    for path in _files():
        rel = path.relative_to(ROOT).as_posix()
        bad += [f"{rel}:{line} {name}" for name, line in violations(path, owned) if (rel, name) not in ALLOWED]
    assert not bad, "private names of " + ", ".join(OWNERS) + " reached from outside:\n" + "\n".join(bad)


@pytest.mark.parametrize("source, caught", [
    ("from beamsolver.driver import _advice\n", "_advice"),
    ("from beamsolver.nonlinear.newton import _Measured\n", "_Measured"),
    ("from .stepping.steps import _memory\n", "_memory"),
    ("def f(run, t):\n    return run._attempt(t)\n", "_attempt"),
    ("def f(newton):\n    return newton._merit\n", "_merit"),
    ("class A:\n    def f(self):\n        return self._attempt\n", None),
    ("from beamsolver.nonlinear.newton import Newton\n", None),
])
def test_the_check_can_fail(tmp_path, source, caught):
    path = tmp_path / "probe.py"
    path.write_text(source)
    owned = {m: private_names(PACKAGE / (m.replace(".", "/") + ".py")) for m in OWNERS}
    names = [n for n, _ in violations(path, owned)]
    assert names == ([caught] if caught else [])
