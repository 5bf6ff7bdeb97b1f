"""Numba's disk cache and edits of a module a cached function calls (beamsolver.jit_cache)."""
import os
import subprocess
import sys
import textwrap

import pytest

from beamsolver import jit_cache

JIT = """from numba import njit
{guard}
jit = njit(cache=True)
"""
GUARD = "from pathlib import Path\nfrom beamsolver.jit_cache import drop_stale\ndrop_stale(Path(__file__).parent)"


def _package(tmp_path, guard, value):
    pkg = tmp_path / "pkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "_jit.py").write_text(JIT.format(guard=GUARD if guard else ""))
    (pkg / "caller.py").write_text("from ._jit import jit\nfrom .callee import f\n\n\n@jit\ndef g():\n    return f()\n")
    _callee(pkg, value)
    return pkg


def _callee(pkg, value):
    p = pkg / "callee.py"
    p.write_text(f"from ._jit import jit\n\n\n@jit\ndef f():\n    return {value}\n")
    st = os.stat(p)
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9 * int(value)))     # a distinct stamp


def _run(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path)] + sys.path), NUMBA_CACHE_DIR="")
    out = subprocess.run([sys.executable, "-c", "from pkg.caller import g; print(g())"], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return float(out.stdout)


@pytest.mark.parametrize("guard", [False, True])
def test_an_edited_callee_is_compiled_again(tmp_path, guard):
    """Without the guard numba reloads ``g`` with the old ``f`` inlined (the hazard); with it the
    edit is seen."""
    pkg = _package(tmp_path, guard, 1.0)
    assert _run(tmp_path) == 1.0
    assert list((pkg / "__pycache__").glob("caller.*.nbi"))         # g was cached
    _callee(pkg, 2.0)
    assert _run(tmp_path) == (2.0 if guard else 1.0)


def test_drop_stale_deletes_only_on_a_new_digest(tmp_path):
    pkg = tmp_path / "p"
    (pkg / "__pycache__").mkdir(parents=True)
    (pkg / "a.py").write_text("from ._jit import jit\n")
    (pkg / "b.py").write_text("import numpy\n")                      # not compiled
    cached = [pkg / "__pycache__" / n for n in ("a.f-3.py311.nbi", "a.f-3.py311.nbc")]
    other = pkg / "__pycache__" / "b.cpython-311.pyc"

    def make():
        for f in cached + [other]:
            f.write_bytes(b"x")

    make()
    assert jit_cache.drop_stale(pkg) == 2                             # no stamp yet: stale
    assert not any(f.exists() for f in cached) and other.exists()
    assert (pkg / "__pycache__" / jit_cache.STAMP).read_text() == jit_cache.digest([pkg / "a.py"], pkg)
    make()
    assert jit_cache.drop_stale(pkg) == 0 and all(f.exists() for f in cached)
    (pkg / "b.py").write_text("import scipy\n")                      # a module without compiled code
    assert jit_cache.drop_stale(pkg) == 0
    (pkg / "a.py").write_text("from ._jit import jit\nX = 1\n")
    assert jit_cache.drop_stale(pkg) == 2


def test_the_package_digest_covers_its_compiled_modules():
    names = {p.name for p in jit_cache.compiled_modules(os.path.dirname(jit_cache.__file__))}
    assert {"se3_jit.py", "element_jit.py", "kernel_jit.py", "projection.py"} <= names
    assert "solver.py" not in names
