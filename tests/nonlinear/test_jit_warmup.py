"""The first run (issue 29 item 1): compilations announced, a scene's kernels compiled before step 0."""
import io
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numba
import numpy as np
import pytest
from numba.core import event
from numba.core.registry import CPUDispatcher

import beamsolver as bs
from beamsolver.nonlinear import jit_warmup
from beamsolver.contact import kernel_jit

ROOT = Path(__file__).resolve().parents[2]
from twisted_pair import build


def _dispatchers():
    """Every compiled function of the package reachable from its modules: ``{id: (name, dispatcher)}``."""
    out = {}
    for name, mod in list(sys.modules.items()):
        if not name.startswith("beamsolver"):
            continue
        for k, v in list(vars(mod).items()):
            if isinstance(v, CPUDispatcher):
                out[id(v)] = (f"{name}.{k}", v)
    for k, v in kernel_jit._KERNELS.items():
        out[id(v)] = (f"kernel {k}", v)
    return out


def _signatures():
    return {i: (name, len(d.overloads)) for i, (name, d) in _dispatchers().items()}


@pytest.mark.slow
@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_nothing_compiles_after_the_warm_up():
    """After the warm-up of the main job's scene, its whole solve (crossings of the wires from about
    one turn on) calls no compiled function with new argument types: no compilation in the middle
    of a solve.  Fails if the warm-up leaves out a function (``projection._closest``, first called at
    a crossing) or calls one with other types than the solve (``search._pairs_apart`` on the distance
    matrix's non-contiguous pair arrays)."""
    model = build()[0]
    jit_warmup._scene(model, None)
    before = _signatures()
    bs.solve(model, steps=16, verbose=False)
    after = _signatures()
    new = sorted(name for i, (name, n) in after.items() if n > before.get(i, (name, 0))[1])
    assert new == [], f"compiled or loaded during the solve: {new}"


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_kernel_arguments_have_the_types_of_a_solve():
    """``_kernel_args`` (what the second process compiles and ``kernel_cached`` looks up) has the
    types ``kernel_and_tangent`` passes in a solve: fails when one of them changes alone."""
    bs.solve(build(turns=0.125)[0], steps=1, verbose=False)
    sig = tuple(numba.typeof(a) for a in jit_warmup._kernel_args())
    assert sig in kernel_jit.evaluate.overloads
    assert jit_warmup.kernel_cached() is True


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_first_compilation_is_announced_once():
    """The line at the first compilation (a cache miss) of the process, not again at the next one."""
    out = io.StringIO()

    @numba.njit
    def f(x):
        return x + 1

    with event.install_listener("numba:compile", jit_warmup._Announcer(out, package=__name__)):
        f(1)
        said = out.getvalue()
        f(1.5)                                 # another compilation: no second line
    assert said.startswith("beamsolver: compiling the compiled kernels, first run only, ~")
    assert out.getvalue().count("first run only") == 1


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_nothing_is_announced_without_compilation():
    """A call of a compiled function with known types prints nothing."""
    @numba.njit
    def g(x):
        return 2 * x

    g(1.0)
    out = io.StringIO()
    with event.install_listener("numba:compile", jit_warmup._Announcer(out, package=__name__)):
        g(3.0)
    assert out.getvalue() == ""


@pytest.mark.slow
@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_kernel_process_runs(monkeypatch):
    """The second process where there is no fork (``python -m beamsolver.nonlinear.jit_warmup``) compiles or
    loads the kernel and exits 0."""
    jit_warmup._kernel_call()          # this process's cache: the other process loads it
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    monkeypatch.setattr(sys, "platform", "darwin")
    worker = jit_warmup._Worker(jit_warmup._kernel_call)
    assert worker.proc is not None and worker.pid is None
    assert worker.wait() == 0


def test_second_process_only_with_a_free_core(monkeypatch):
    """``BEAMSOLVER_COMPILE_PROCESS`` decides; unset, a second process only when a core is free."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    monkeypatch.setenv("BEAMSOLVER_COMPILE_PROCESS", "0")
    assert not jit_warmup._two_processes()
    monkeypatch.setenv("BEAMSOLVER_COMPILE_PROCESS", "1")
    monkeypatch.setattr(os, "getloadavg", lambda: (9.0, 9.0, 9.0))
    assert jit_warmup._two_processes()
    monkeypatch.delenv("BEAMSOLVER_COMPILE_PROCESS")
    assert not jit_warmup._two_processes()
    monkeypatch.setattr(os, "getloadavg", lambda: (0.3, 0.3, 0.3))
    assert jit_warmup._two_processes()
    monkeypatch.setattr(os, "getloadavg", lambda: (1.4, 2.0, 2.0))       # one core busy part of the minute
    assert jit_warmup._two_processes()
    monkeypatch.setattr(os, "getloadavg", lambda: (1.6, 1.0, 1.0))
    assert not jit_warmup._two_processes()
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    assert not jit_warmup._two_processes()


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_a_users_own_numba_function_is_not_announced():
    out = io.StringIO()

    @numba.njit
    def h(x):
        return x - 1

    with event.install_listener("numba:compile", jit_warmup._Announcer(out)):
        h(1)
    assert out.getvalue() == ""


STAND_IN = """
import sys
sys.path.insert(0, sys.argv[1])
import beamsolver as bs
from beamsolver.nonlinear import jit_warmup
from twisted_pair import build
import test_jit_warmup as t


class Done:                     # a worker that has already compiled the kernel into the cache
    def running(self):
        return False

    def wait(self):
        return 0


model = build()[0]
jit_warmup._scene(model, Done())
before = t._signatures()
bs.solve(model, steps=16, verbose=False)
after = t._signatures()
print(sorted(name for i, (name, n) in after.items() if n > before.get(i, (name, 0))[1]))
"""


@pytest.mark.slow
@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_the_kernels_stand_in_leaves_nothing_to_compile():
    """With a second process compiling the kernel, this one evaluates the scene on a stand-in of the kernel
    (``_stand_in``: plain Python, outputs of the kernel's types) and compiles what comes after it; then loads the
    kernel.  In a fresh process (nothing held yet, the disk cache warm), the main job's solve after that loads
    or compiles nothing: fails if the stand-in's outputs take other paths or types than the kernel's."""
    jit_warmup._kernel_call()                          # the kernel in the cache, as the worker leaves it
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), str(ROOT / "examples"), str(Path(__file__).parent)]))
    out = subprocess.run([sys.executable, "-c", STAND_IN, str(ROOT / "examples")], env=env, capture_output=True,
                         text=True, cwd=Path(__file__).parent)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork on Linux only")
def test_forked_worker_runs_its_target_silently(tmp_path, capfd):
    """The second process is a fork running one function: its exit status says whether it ran (0) or raised
    (1), and it writes nothing on this process's streams (not even the traceback of a failure); one that
    does not finish in time is killed (this process then compiles what it would have)."""
    flag = tmp_path / "ran"

    def ok():
        flag.write_text("yes")
        print("noise")

    def fails():
        raise RuntimeError("no")

    assert jit_warmup._Worker(ok).wait() == 0 and flag.read_text() == "yes"
    assert jit_warmup._Worker(fails).wait() == 1
    assert jit_warmup._Worker(lambda: time.sleep(60)).wait(timeout=0.3) == -9
    assert capfd.readouterr() == ("", "")


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_the_bar_is_cleared_when_the_warm_up_ends():
    """``close`` (run at the end of the warm-up) clears the bar at once, instead of ``_IDLE`` seconds after the last
    compilation: the solve's first printed lines do not land behind a stale bar."""
    out = io.StringIO()

    @numba.njit
    def f(x):
        return x + 1

    a = jit_warmup._Announcer(out, package=__name__)
    with event.install_listener("numba:compile", a):
        f(1)
    assert a.bar is not None
    a.close()
    assert a.bar is None
    n = len(out.getvalue())
    time.sleep(3 * jit_warmup._REFRESH)
    assert len(out.getvalue()) == n            # the refresh thread has stopped


def _fresh():
    """A new compiled function of this module (its first call is a compilation the announcer sees)."""
    @numba.njit
    def f(x):
        return x + 1
    return f


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_the_bar_says_when_it_is_past_the_estimate(monkeypatch):
    """Past the announced estimate the bar shows the seconds and says so (it used to stop at 99 % of it)."""
    monkeypatch.setattr(jit_warmup, "estimate", lambda: 0.1)        # announced as ~1 s
    out = io.StringIO()
    a = jit_warmup._Announcer(out, package=__name__)
    with event.install_listener("numba:compile", a):
        _fresh()(1)
        a.t_bar -= 2.0                                 # as if compiling had begun 2 s ago
    time.sleep(3 * jit_warmup._REFRESH)                # the bar stays _IDLE s after the last compilation
    a.close()
    assert "s (longer than the ~1 s estimate)" in out.getvalue()


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_a_compilation_after_the_warm_up_counts_its_own_seconds():
    """A batch compiled after the warm-up (a larger model's solver path, mid-solve) gets a bar of its own seconds, not
    the warm-up's estimate with the seconds since the first announcement (which sat at 99 % from its start)."""
    out = io.StringIO()
    a = jit_warmup._Announcer(out, package=__name__)
    with event.install_listener("numba:compile", a):
        _fresh()(1)
        a.close()                                      # the warm-up's end
        n = len(out.getvalue())
        _fresh()(1)
    later = out.getvalue()[n:]
    a.close()
    assert "compiling: 0 s" in later and "%|" not in later
    assert out.getvalue().count("first run only") == 1


SHARE = """
import numpy as np
from beamsolver.contact import kernel_jit as kj
from beamsolver.nonlinear import jit_warmup
kj.share_of_the_kernel(np.zeros(kj.N_G * kj.W), np.zeros((2, kj.N_VEC, 6)), np.zeros((4, 4, 4)))
names = ("_store_frames", "_moment_gradient", "_wrench")
before = [len(getattr(kj, n).overloads) for n in names]
jit_warmup._kernel_call()
print(before, [len(getattr(kj, n).overloads) for n in names])
"""


@pytest.mark.slow
@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_the_jobs_share_of_the_kernel_has_the_kernels_signatures(tmp_path):
    """``kernel_jit.share_of_the_kernel`` (compiled by the job while the second process compiles the kernel) calls
    ``_store_frames``, ``_moment_gradient`` and both ``_wrench`` with the types ``_point`` calls them with: in a
    process with an empty cache, compiling the kernel after it adds no signature to them.  Fails when ``_point``
    calls one of them with other types (the share would compile for nothing, the kernel compile them again)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", SHARE], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "[1, 1, 2] [1, 1, 2]"


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiled kernels only")
def test_a_bar_open_at_exit_is_cleared(tmp_path):
    """A process that ends while its bar is open (it compiled in its last seconds: a test session's last test)
    erases the bar's line (``_Announcer.at_exit``), not leaves ``compiling: ...`` after its own last output."""
    code = ("import beamsolver\nfrom beamsolver.lie import se3_jit\n"
            "se3_jit.cross((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))\nprint('done', flush=True)\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout == "done\n", out.stderr[-2000:]
    assert "compiling:" in out.stderr                       # the bar was shown ...
    last = [line for line in re.split(r"[\r\n]", out.stderr) if line][-1]
    assert last.strip() == "", repr(out.stderr[-200:])      # ... and its line cleared at exit (blanks over it)
