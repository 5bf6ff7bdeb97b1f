"""Numba's disk cache and edits of the code a cached function depends on (beamsolver.jit_cache).

Each test builds a small package in a temporary folder whose ``_jit`` installs the package's
locators (or not: the hazard), and runs it in fresh processes."""
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from beamsolver import jit_cache

JIT = """from numba import njit
{guard}
jit = njit(cache=True)
"""
GUARD = "from pathlib import Path\nfrom beamsolver.jit_cache import install\ninstall(Path(__file__).parent)"
CALLER = """from ._jit import jit
from .callee import f
from .consts import K


@jit
def g():
    return f() + K
"""


def _write(path, text, tick):
    """Write ``text`` with a distinct modification time (numba's own stamp is mtime and size)."""
    path.write_text(text)
    st = os.stat(path)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9 * tick))


def _package(tmp_path, guard, value=1.0, const=0.0):
    pkg = tmp_path / "pkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "_jit.py").write_text(JIT.format(guard=GUARD if guard else ""))
    (pkg / "caller.py").write_text(CALLER)
    (pkg / "other.py").write_text("X = 1\n")                            # not imported by caller
    _callee(pkg, value)
    _write(pkg / "consts.py", f"K = {const}\n", 1)
    return pkg


def _callee(pkg, value, tick=1):
    _write(pkg / "callee.py", f"from ._jit import jit\n\n\n@jit\ndef f():\n    return {value}\n", tick)


def _run(tmp_path, code="from pkg.caller import g; print(g(), g.stats.cache_hits.get(g.signatures[0], 0) > 0)"):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path)] + sys.path), NUMBA_CACHE_DIR="")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    value, hit = out.stdout.split()
    return float(value), hit == "True"


@pytest.mark.slow                      # each test runs numba in 3-4 fresh processes
@pytest.mark.parametrize("guard", [False, True])
def test_an_edited_callee_is_compiled_again(tmp_path, guard):
    """Without the locators numba reloads ``g`` with the old ``f`` inlined (the hazard); with
    them the edit is seen."""
    pkg = _package(tmp_path, guard)
    assert _run(tmp_path) == (1.0, False)
    assert _run(tmp_path) == (1.0, True)                              # g was cached
    _callee(pkg, 2.0, tick=2)
    assert _run(tmp_path)[0] == (2.0 if guard else 1.0)


@pytest.mark.slow
@pytest.mark.parametrize("guard", [False, True])
def test_a_frozen_constant_of_a_plain_module_is_seen(tmp_path, guard):
    """``consts`` has no compiled code; ``g`` freezes its ``K`` (as the contact kernel freezes
    ``contact.frames``' kinds)."""
    pkg = _package(tmp_path, guard)
    assert _run(tmp_path) == (1.0, False)
    _write(pkg / "consts.py", "K = 10.0\n", 3)
    assert _run(tmp_path)[0] == (11.0 if guard else 1.0)


@pytest.mark.slow
def test_an_unrelated_edit_keeps_the_cache(tmp_path):
    pkg = _package(tmp_path, True)
    assert _run(tmp_path) == (1.0, False)
    _write(pkg / "other.py", "X = 2\n", 4)
    assert _run(tmp_path) == (1.0, True)


@pytest.mark.slow
def test_a_process_running_old_code_cannot_stamp_it_new(tmp_path):
    """A process imports the old code, the files change, another process caches the new code,
    then the old process compiles and saves: the next process must run the new code."""
    pkg = _package(tmp_path, True)
    go = tmp_path / "go"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path)] + sys.path), NUMBA_CACHE_DIR="")
    old = subprocess.Popen([sys.executable, "-c",
                            "import os, time\nfrom pkg.caller import g\nopen('ready', 'w').close()\n"
                            "while not os.path.exists('go'): time.sleep(0.05)\nprint(g())"],
                           cwd=tmp_path, env=env, stdout=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while not (tmp_path / "ready").exists():
            assert time.monotonic() - t0 < 120 and old.poll() is None
            time.sleep(0.05)
        _callee(pkg, 2.0, tick=2)
        assert _run(tmp_path) == (2.0, False)                         # new code compiled and saved
        go.write_text("")
        assert float(old.communicate(timeout=300)[0]) == 1.0           # old code saved last
    finally:
        old.kill()
    assert _run(tmp_path)[0] == 2.0


def test_dependencies_follow_imports_transitively(tmp_path):
    pkg = _package(tmp_path, True)
    deps = {(rel, line) for rel, line in jit_cache.dependencies(pkg / "caller.py", "g", pkg)}
    assert {rel for rel, _ in deps} == {"caller.py", "callee.py", "consts.py", "_jit.py"}
    line = next(n for rel, n in deps if rel == "_jit.py")
    assert (pkg / "_jit.py").read_text().splitlines()[line - 1].startswith("jit = njit(")   # the decorator's options


def _stamp(pkg, module, name):
    """The stamp ``jit_cache`` gives the function ``name`` of ``pkg.module`` (read, not imported)."""
    src = (pkg / f"{module}.py").read_text()
    code = compile(src, str(pkg / f"{module}.py"), "exec")
    func = next(c for c in code.co_consts if getattr(c, "co_name", None) == name)
    jit_cache.forget()                   # as a new process: sources read again
    return jit_cache.function_digest(type("F", (), {"__code__": func})(), pkg / f"{module}.py", pkg)


def test_the_stamp_covers_exactly_what_the_function_names(tmp_path):
    """Editing a plain function of the same module, a plain module it imports, a comment or a
    docstring keeps ``g``'s stamp (and its rank, the cache file's name); editing the jitted helper
    it calls, the constant it freezes or the decorator's options changes it."""
    pkg = _package(tmp_path, True)
    before = _stamp(pkg, "caller", "g")
    assert before[1] == 0
    (pkg / "caller.py").write_text("import os\n\n\ndef plain(x):\n    return os.sep * x\n\n\n" + CALLER
                                   + "\n\ndef later():\n    return 2\n")
    assert _stamp(pkg, "caller", "g") == before                   # lines moved, plain functions added
    (pkg / "caller.py").write_text(CALLER.replace("    return f() + K", '    """Doc."""\n    return f() + K  # sum'))
    assert _stamp(pkg, "caller", "g") == before
    (pkg / "consts.py").write_text("K = 0.0\n\n\ndef unrelated():\n    return 3\n")
    assert _stamp(pkg, "caller", "g") == before
    (pkg / "caller.py").write_text(CALLER)
    for path, text in (("callee.py", "from ._jit import jit\n\n\n@jit\ndef f():\n    return 2.0\n"),
                       ("consts.py", "K = 1.0\n"),
                       ("_jit.py", JIT.format(guard=GUARD).replace("cache=True", "cache=True, fastmath=True"))):
        old = (pkg / path).read_text()
        (pkg / path).write_text(text)
        assert _stamp(pkg, "caller", "g")[0] != before[0], path
        (pkg / path).write_text(old)
    assert _stamp(pkg, "caller", "g") == before


@pytest.mark.slow
def test_an_edit_moving_a_kernel_keeps_its_cache(tmp_path):
    """numba names a cache entry by the function's first line: a plain function added above ``g``
    would compile it again; the locators name it by its rank instead."""
    pkg = _package(tmp_path, True)
    assert _run(tmp_path) == (1.0, False)
    _write(pkg / "caller.py", "def plain():\n    return 1\n\n\n" + CALLER, 5)
    assert _run(tmp_path) == (1.0, True)


def test_the_contact_kernel_depends_on_the_constants_it_freezes():
    root = Path(jit_cache.__file__).resolve().parent
    deps = jit_cache.dependencies(root / "contact" / "kernel_jit.py", "_evaluate", root)
    rel = {r for r, _ in deps}
    assert {"contact/frames.py", "contact/law.py", "lie/se3_jit.py", "_jit.py"} <= rel
    assert not rel & {"driver.py", "nonlinear/linsolve.py", "contact/system.py", "contact/reference.py"}
    frames = (root / "contact" / "frames.py").read_text().splitlines()
    used = {frames[line - 1].split(" = ")[0] for r, line in deps if r == "contact/frames.py"}
    assert used == {"LINE, ORTHOGONAL, POINT"}                    # not the numpy geometry beside them


def test_digests_are_kept_between_processes_for_the_same_sources(tmp_path, monkeypatch):
    """A new process reads the digests of unchanged sources from the store (no syntax trees walked);
    any edit of the package's sources makes it compute them again."""
    pkg = _package(tmp_path, True)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    before = _stamp(pkg, "caller", "g")
    jit_cache._store(pkg.resolve()).save()
    assert (tmp_path / "cache" / "jit_digests.pkg.json").is_file()
    real = jit_cache._function_digest

    def walked(*a):
        raise AssertionError("computed again")
    monkeypatch.setattr(jit_cache, "_function_digest", walked)
    assert _stamp(pkg, "caller", "g") == before                    # read from the store
    (pkg / "consts.py").write_text("K = 1.0\n")
    with pytest.raises(AssertionError, match="computed again"):
        _stamp(pkg, "caller", "g")
    monkeypatch.setattr(jit_cache, "_function_digest", real)
    assert _stamp(pkg, "caller", "g")[0] != before[0]
