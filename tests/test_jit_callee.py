"""``_jit.jit_callee``: compiled without the CPython wrapper, still callable from Python (issue 29 item 1)."""
import ast
from pathlib import Path

import numba
import numpy as np
import pytest

from beamsolver import _jit
from beamsolver.lie import se3_jit

PACKAGE = Path(_jit.__file__).resolve().parent
TEMPLATES = {"_friction", "_point", "_evaluate", "_evaluate_rows", "_point_mortar", "_evaluate_mortar"}   # kernel_jit's templates, compiled by make_kernel


def _module(p):
    parts = list(p.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _decorated(trees):
    callees, compiled = set(), set()
    for m, t in trees.items():
        for n in ast.walk(t):
            if isinstance(n, ast.FunctionDef):
                decs = {ast.unparse(d) for d in n.decorator_list}
                if "jit_callee" in decs:
                    callees.add((m, n.name))
                if decs & {"jit", "jit_callee"}:
                    compiled.add((m, n.name))
    return callees, compiled


def _imports(m, t, trees):
    """Names bound by ``from ... import`` to ``(module, name)`` and module aliases to module names."""
    names, mods = {}, {}
    here = m.split(".") if (PACKAGE.parent / Path(*m.split("."))).is_dir() else m.split(".")[:-1]
    for n in ast.walk(t):
        if isinstance(n, ast.ImportFrom):
            base = here[:len(here) - (n.level - 1)] if n.level else []
            src = ".".join(base + ([n.module] if n.module else [])) if n.level else n.module
            for a in n.names:
                if f"{src}.{a.name}" in trees:
                    mods[a.asname or a.name] = f"{src}.{a.name}"
                else:
                    names[a.asname or a.name] = (src, a.name)
    for n in t.body:
        if isinstance(n, ast.FunctionDef):
            names[n.name] = (m, n.name)
    return names, mods


def _functions(body):
    for n in body:
        if isinstance(n, ast.FunctionDef):
            yield n
        elif isinstance(n, ast.ClassDef):
            yield from _functions(n.body)


@pytest.mark.slow
def test_callees_are_called_from_compiled_code_only():
    """No plain-Python function of the package calls a ``jit_callee`` (through its name or module): such a
    call would compile the function a second time, with the wrapper (``python_twin``).  Fails when a
    function called from Python is decorated ``jit_callee`` instead of ``jit``."""
    trees = {_module(p): ast.parse(p.read_text()) for p in PACKAGE.rglob("*.py")}
    callees, compiled = _decorated(trees)
    assert len(callees) > 50
    calls = []
    for m, t in trees.items():
        names, mods = _imports(m, t, trees)
        for f in _functions(t.body):
            if (m, f.name) in compiled or (m.endswith("kernel_jit") and f.name in TEMPLATES):
                continue
            for c in ast.walk(f):
                if not isinstance(c, ast.Call):
                    continue
                target = None
                if isinstance(c.func, ast.Name):
                    target = names.get(c.func.id)
                elif isinstance(c.func, ast.Attribute) and isinstance(c.func.value, ast.Name):
                    target = (mods[c.func.value.id], c.func.attr) if c.func.value.id in mods else None
                if target in callees:
                    calls.append(f"{m}.{f.name} calls {target[0]}.{target[1]}")
    assert calls == []


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_a_callee_called_from_python_runs_its_twin():
    """``se3_jit.cross`` has no CPython wrapper (calling that entry would crash the interpreter); from
    Python it runs its twin, compiled with one."""
    assert isinstance(se3_jit.cross, _jit.CalleeDispatcher)
    assert se3_jit.cross.targetoptions["no_cpython_wrapper"]
    assert se3_jit.cross((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)) == (0.0, 0.0, 1.0)
    twin = se3_jit.cross.python_twin
    assert twin.py_func.__qualname__ == "cross__py" and not twin.targetoptions.get("no_cpython_wrapper", False)
    np.testing.assert_array_equal(se3_jit.coefficient(0, 0.5), np.sin(0.5) / 0.5)
