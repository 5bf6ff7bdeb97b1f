"""The first run: compile a scene's kernels before its first step, say so, and use both cores.

numba compiles a function at its first call with new argument types (then writes it to the disk
cache, ``_jit``); on a fresh install that is about a minute of CPU for a contact scene, most of it
the contact kernel (``contact.kernel_jit``).  ``warm_up(model)``, run by ``solve`` before step 0:

- does nothing when the contact kernel is in the cache (the cached runs: one index lookup) or
  without contact, or under ``NUMBA_DISABLE_JIT``;
- else starts a second process compiling the default law's contact kernel into the cache (a fork of
  this one: nothing to import again, and what this process has compiled so far is not compiled
  twice; ``python -m beamsolver.nonlinear.jit_warmup`` where there is no fork), when a core is free
  or as the environment variable ``BEAMSOLVER_COMPILE_PROCESS`` (``1``/``0``) says, while this process
  compiles the rest: one evaluation of residual and tangent of a throwaway ``Problem`` of the model at
  its initial poses (the signatures step 0 uses) on a plain-Python stand-in of the kernel
  (``_stand_in``: outputs of its types, so the assembly and history code after the kernel compiles
  here too), a pose update, and the two functions that are otherwise compiled in the middle of a
  solve, on the first crossing of two wires (``search._pairs_apart`` for the distance matrix's pair
  arrays, ``projection._closest``); then it waits for the second process and loads the kernel from
  the cache.  With one process, the same evaluation on the compiled kernel.

``listen()`` (run at ``import beamsolver``): the first compilation of the process (a cache
miss, numba's ``numba:compile`` event; loading from the cache is silent) prints one line on
stderr, ``beamsolver: compiling the compiled kernels, first run only, ~N s`` (``estimate``), then
a tqdm bar of the elapsed seconds against that estimate, refreshed four times a second and naming the
function being compiled (or the second process waited for), while compilations go on; past the estimate,
the seconds and that they are past it.  A batch compiled after the warm-up (a larger model's solver path, met
mid-solve) shows a bar of its own seconds, without an estimate.
"""
import atexit
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
from numba.core import event

__all__ = ["estimate", "kernel_cached", "listen", "warm_up", "ESTIMATE"]

# CPU seconds of the first run's compilation of the main job (examples/twisted_pair.py) on the project's
# 2-core x86-64 machines, measured with an empty NUMBA_CACHE_DIR (session 17): elements and assembly ~7.5 s (a
# beam scene's first run, examples/roll_up.py), the other contact and exact-stick functions (search, projections,
# owners, mortar, bordered and augmented systems) ~27.5 s, the contact kernel in the second process ~21 s (one
# process: the bar ends at 51 s; two: at 36 s, this process's share the longer; session 16: 50 / 32 s, before the
# kernel's forces-only passes and the mortar glue's compiled passes).  Session 11's 14 / 6.5 / 5.5 s predate the
# mortar and saddle-point kernels (docs/benchmarks.md, jit_compile_functions)
ESTIMATE = dict(kernel=21.0, contact=27.5, elements=7.5)
log = logging.getLogger("beamsolver")
_REFRESH = 0.25         # seconds between refreshes of the bar
_IDLE = 3.0             # seconds without compilation that close it (imports between two compilations)
_AGAINST = "{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total} s {postfix}"    # the first batch, against ``estimate``
_PAST = "{{desc}}: {{n:.0f}} s (longer than the ~{estimate} s estimate) {{postfix}}"   # ... once past it
_ELAPSED = "{desc}: {n:.0f} s {postfix}"        # a batch after the warm-up (no estimate)
WAIT_MAX = 600.0        # seconds this process waits for the second one at most (then kills it and compiles)


def _disabled():
    from numba import config
    return bool(config.DISABLE_JIT)


class _Announcer(event.Listener):
    """numba ``numba:compile`` listener (see the module): the line at the first compilation of a
    function of ``package`` in the process, then a bar while compiling, closed after ``_IDLE`` s
    without compilation."""

    def __init__(self, stream=None, package="beamsolver"):
        self.stream, self.package = stream, package
        self.depth, self.bar, self.name, self.said = 0, None, "", False
        self.waiting = False        # for the second process: the bar stays
        self.t0 = self.t_bar = self.idle = 0.0
        self.total, self.ended = 1, False     # the announced estimate [s]; ``close`` ran
        self.lock = threading.Lock()

    def on_start(self, event):
        f = event.data["dispatcher"].py_func
        if self.depth == 0 and f.__module__.startswith(self.package):     # not a user's own numba function
            self.name = f.__qualname__.split("__")[0]
            with self.lock:
                if self.bar is None:
                    self._open()
        self.depth += 1

    def on_end(self, event):
        self.depth -= 1
        if self.depth == 0:
            self.idle = time.perf_counter()

    def _open(self):
        from tqdm import tqdm
        stream = self.stream or sys.stderr
        if not self.said:
            self.total = max(1, int(round(estimate())))
            print(f"beamsolver: compiling the compiled kernels, first run only, ~{self.total} s", file=stream,
                  flush=True)
            self.said, self.t0 = True, time.perf_counter()
        if self.ended:      # after the warm-up (a larger model's solver path): its own clock, no estimate
            total, fmt, self.t_bar = None, _ELAPSED, time.perf_counter()
        else:               # the warm-up's batches count on against the announced estimate
            total, fmt, self.t_bar = self.total, _AGAINST, self.t0
        self.bar = tqdm(total=total, file=stream, desc="compiling", leave=False, mininterval=0.0, bar_format=fmt)
        threading.Thread(target=self._tick, args=(self.bar,), daemon=True).start()

    def _tick(self, bar):
        while True:
            time.sleep(_REFRESH)
            with self.lock:
                if self.bar is not bar:             # closed by ``close``
                    return
                try:
                    if self.depth == 0 and not self.waiting and time.perf_counter() - self.idle > _IDLE:
                        bar.close()
                        self.bar = None
                        return
                    bar.n = time.perf_counter() - self.t_bar
                    if bar.total is not None and bar.n > bar.total:     # past the estimate: say so, not 99 %
                        bar.bar_format = _PAST.format(estimate=bar.total)
                        bar.total = None
                    bar.set_postfix_str(self.name, refresh=False)
                    bar.refresh()
                except (ValueError, OSError):        # the stream was closed (a test's captured stderr)
                    self.bar = None
                    return

    def close(self):
        """Clear the bar now (the warm-up is done: nothing more compiles before the solve prints)."""
        with self.lock:
            self.ended = self.said
            if self.depth == 0:
                self._clear()

    def at_exit(self):
        """Clear a bar still open when the process ends, not leave its last state behind (a test session whose last
        test compiled: ``compiling: 729 s (longer than ...)`` after pytest's summary, the seconds since the session's
        first compilation)."""
        with self.lock:
            self._clear()

    def _clear(self):
        """Close the bar, if open (``leave=False``: its line erased; a closed stream ignored); under ``lock``."""
        if self.bar is not None:
            try:
                self.bar.close()
            except (ValueError, OSError):
                pass
            self.bar = None


_LISTENER = []


def listen(stream=None):
    """Announce the compilations of this process (idempotent; ``import beamsolver`` runs it)."""
    if not _LISTENER and not _disabled():
        _LISTENER.append(_Announcer(stream))
        event.register("numba:compile", _LISTENER[0])
        atexit.register(_LISTENER[0].at_exit)


def estimate():
    """Seconds the first run of a contact scene compiles (``ESTIMATE``; with two processes the kernel in
    the second while this one compiles the rest), or those of the element kernels when the contact kernel
    is cached."""
    if kernel_cached() is True:
        return ESTIMATE["elements"]
    if not _two_processes():
        return sum(ESTIMATE.values())
    return max(ESTIMATE["elements"] + ESTIMATE["contact"], ESTIMATE["kernel"])      # both start before step 0


# ---------------------------------------------------------------- the contact kernel
def _kernel_args():
    """Arguments of the default law's compiled kernel as ``kernel_jit.kernel_and_tangent`` passes them
    (the same types), for no contact point."""
    from ..contact import kernel_jit
    X = np.zeros((0, 4, 4, 4))
    kind, par, has, frames, lamp = kernel_jit._table(X, dict(kind=np.zeros(0, dtype=np.int64)))
    out = (np.empty((0, 4, 6)), np.empty((0, 24, 24)), np.empty((0, 4)), np.empty((0, 6, 3)), np.empty((0, 2, 2)),
           np.empty((0, 2), dtype=np.bool_), np.empty((0, 4, 4, 4)))
    return (X, kind, par, has, *frames, lamp, True) + out


def _kernel_call():
    """Compile (or load) the default law's contact kernel."""
    from ..contact import kernel_jit
    kernel_jit.evaluate(*_kernel_args())


def kernel_cached():
    """Whether the default law's contact kernel is loaded or in numba's disk cache for this code
    (numba's own index lookup: its key and the digest stamp of ``jit_cache``); ``None`` if that
    cannot be told."""
    try:
        import numba
        from ..contact import kernel_jit
        disp = kernel_jit.evaluate
        sig = tuple(numba.typeof(a) for a in _kernel_args())
        if sig in disp.overloads:
            return True
        cache = disp._cache
        return cache._index_key(sig, disp.targetctx.codegen()) in cache._cache_file._load_index()
    except Exception:           # a numba without these internals: not known
        return None


def _two_processes():
    """Whether the kernel compiles in a second process: ``BEAMSOLVER_COMPILE_PROCESS`` ``1`` yes, ``0`` no,
    unset: when a core is free (two or more cores, 1-minute load average below their number less a half;
    on a machine kept busy by other jobs a second process gains no core and only adds the callees both
    processes compile).  Main job on 2 cores: at load 1.2-1.5 two processes 17.9 s against 30.4 s for one, at
    load 3-4 54-72 s against 43-64 s (docs/benchmarks.md, jit_first_run_tradeoffs)."""
    flag = os.environ.get("BEAMSOLVER_COMPILE_PROCESS", "")
    if flag in ("0", "1"):
        return flag == "1"
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    return cores >= 2 and load < cores - 0.5


class _Worker:
    """The second compiling process: a fork of this one (no imports to repeat, and the compiled functions
    this process already holds, e.g. the element twists of the model's set-up, are not compiled again),
    or ``python -m beamsolver.nonlinear.jit_warmup`` where there is no ``fork``."""

    def __init__(self, target):
        self.proc = self.pid = None
        if sys.platform.startswith("linux"):         # fork without exec: Linux only (as multiprocessing's default)
            from numba.core.compiler_lock import global_compiler_lock
            with global_compiler_lock:      # no other thread of this process is inside numba or LLVM at the fork
                self.pid = os.fork()
                if self.pid == 0:
                    _child(target)          # never returns
        else:
            root = str(Path(__file__).resolve().parent.parent)
            env = dict(os.environ, PYTHONPATH=os.pathsep.join([root] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
            self.proc = subprocess.Popen([sys.executable, "-m", "beamsolver.nonlinear.jit_warmup"], env=env,
                                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def running(self):
        if self.proc is not None:
            return self.proc.poll() is None
        if self.pid is None:
            return False
        done, _ = os.waitpid(self.pid, os.WNOHANG)
        if done:
            self.pid = None
        return not done

    def wait(self, timeout=None):
        """Wait for the process; its exit status (0: compiled; None: already reaped).  After ``timeout``
        seconds (default ``WAIT_MAX``) it is killed: this process compiles what it did not."""
        timeout = WAIT_MAX if timeout is None else timeout
        if self.proc is not None:
            try:
                return self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                return self.proc.wait()
        if self.pid is None:
            return None
        end = time.monotonic() + timeout
        while True:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.pid = None
                return os.waitstatus_to_exitcode(status)
            if time.monotonic() > end:
                os.kill(self.pid, signal.SIGKILL)
                end = float("inf")
            time.sleep(0.02)


def _child(target):
    """The forked process: compile ``target()`` into the cache and leave, silently (the parent's progress
    bar thread may have held a lock of the streams or of the bar at the fork: nothing here touches them)."""
    code = 1
    try:
        for a in _LISTENER:
            event.unregister("numba:compile", a)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        sys.stdout = sys.stderr = open(devnull, "w", closefd=False)       # new objects: no lock held
        target()
        code = 0
    except BaseException:           # the parent compiles what is missing
        pass
    finally:
        os._exit(code)


def _start_kernel_process():
    """A process compiling the contact kernel into the cache (None unless ``_two_processes()``)."""
    if not _two_processes():
        return None
    return _Worker(_kernel_call)


# ---------------------------------------------------------------- a scene's kernels
def warm_up(model):
    """Compile what solving ``model`` needs before its first step, on a first run (see the module)."""
    if _disabled() or not model.contacts or kernel_cached() is not False:
        return
    worker = _start_kernel_process()
    try:
        _scene(model, worker)
    except Exception as exc:          # the solve compiles what is left, as it goes
        log.info("compilation before step 0 stopped early: %r", exc)
    finally:
        if worker is not None and worker.running():
            _wait(worker)
        for a in _LISTENER:
            a.close()


def _scene(model, worker):
    """The warm-up of ``model`` in this process; ``worker``: the process compiling the kernel (or None:
    compiled here).  With a worker, the throwaway evaluation runs on a stand-in of the kernel (``_stand_in``)
    so that what comes after the kernel (assembly of the contact blocks, history updates) compiles here
    while the worker compiles the kernel, which is loaded from the cache after."""
    from ..contact import kernel_jit
    from ..contact.projection import closest_points
    from .problem import Problem
    if worker is not None:          # the kernel's last callees, here: the worker loads them when it gets there
        kernel_jit.share_of_the_kernel(np.zeros(kernel_jit.N_G * kernel_jit.W), np.zeros((2, kernel_jit.N_VEC, 6)),
                                       np.zeros((4, 4, 4)))
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = problem.system.poses0.copy()
    compiled = kernel_jit.evaluate
    if worker is not None:
        kernel_jit.evaluate = _stand_in
    try:
        problem.begin_step(H, 0.0)
        ev = problem.evaluate(H, 0.0)
        problem.tangent(ev)
        problem.update(H, np.full((problem.system.n_nodes, 6), 1e-12))    # the compiled pose updates
        problem.commit(H)                 # the friction history's frames (contact.frames_jit, lie.se3_twin)
    finally:
        kernel_jit.evaluate = compiled
    _exact_stick_callees()
    c = problem.contact
    geo = c._twists(H)
    for d in c.decls:
        c._candidates(d, geo, sweep=False)
    c._points(H, np.zeros(0, dtype=np.int64), np.zeros(0))     # ``projection.element_points``: a later iterate's centres
    en = problem.system.enodes
    closest_points(H, en[:0, 0], np.zeros((0, 6)), en[:0, 0], np.zeros((0, 6)))
    if worker is not None and worker.running():
        _wait(worker)
    _kernel_call()


def _exact_stick_callees():
    """The exact stick path's compiled helpers that the stand-in's data do not reach (they run where some pairs are
    not folded into their groups, where a group's components are eliminated and in the Newton system), on empty
    arrays of the solve's types (``contact.mortar_jit.subtract_indexed``, ``branch_rows`` and ``point_forces``, ``nonlinear.condense._schur`` and
    ``scatter_free``, the bordered pattern's passes ``nonlinear.bordered._border_counts``, ``_border_fill``,
    ``_border_values``, the augmented solve's ``nonlinear.augmented._join``, ``_precondition_rhs``,
    ``_precondition_out``, ``_couplings``, ``_weights_of``)."""
    from ..contact import mortar_jit
    from . import augmented, bordered, condense
    mortar_jit.subtract_indexed(np.zeros((0, 24, 24)), np.zeros((0, 24, 24)), np.zeros(0, dtype=np.int64))
    v, m3 = np.zeros((0, 3, 24)), np.zeros((0, 3, 3))
    mortar_jit.branch_rows(np.zeros((0, 3, 24)), np.zeros((0, 24)), np.zeros((0, 2), dtype=np.int64),
                           np.zeros((2, 0, 24), dtype=np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0),
                           np.zeros(0), np.zeros(0), m3, m3, v, v, np.zeros((0, 24)))
    for A in (np.zeros((2, 24, 3)), np.transpose(np.zeros((3, 2, 4, 6)), (1, 2, 3, 0)).reshape(2, 24, 3)):
        mortar_jit.point_forces(A, np.zeros((2, 3)))        # (the tangent's terms, a trial's forces: two layouts)
    condense._schur(np.zeros(0), 0, np.zeros((0, 24, 3)), np.zeros((0, 3, 24)), np.zeros((0, 3)))
    condense.scatter_free(np.zeros((0, 24), dtype=np.int64), np.zeros((0, 24)), np.zeros(0))
    none, rows, i32 = np.zeros(0, dtype=np.int64), np.zeros((0, 24), dtype=np.int64), np.zeros(0, dtype=np.int32)
    kptr, ptr = np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int32)
    bordered._border_counts(kptr, rows, 0, 3, rows, none, rows, ptr)
    bordered._border_fill(kptr, i32, rows, 0, 3, rows, none, rows, ptr, i32, none, none)
    bordered._border_values(np.zeros(0), none, np.zeros((0, 24, 3)), np.zeros((0, 3, 24)), np.zeros((0, 3, 3)), rows,
                            none, kptr, ptr, i32, np.zeros(0), np.zeros(0))
    f, f2, b = np.zeros(0), np.zeros((0, 24)), np.zeros(0, dtype=bool)
    augmented._join(f, rows, f2, f, f, f, f)
    augmented._precondition_rhs(f, f, b, f, f, rows, f2, f, f)
    augmented._precondition_out(f, f, f, b, f, f, f)
    augmented._couplings(f2, f2, np.zeros((0, 24), dtype=bool), f2, f2, f)
    augmented._weights_of(f, f, b, f, 1.0, f, f)


def _stand_in(X, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames):
    """Plain-Python stand-in of the compiled kernel ``kernel_jit.evaluate`` (its arguments; nothing compiled):
    outputs of the kernel's types and shapes, every point touching, the even ones sticking, the odd ones
    sliding, so the code after the kernel takes the paths of a solve."""
    from ..contact.kernel_jit import XI1, XI2
    f[:], K[:], two[:], vec[:] = 0.0, 0.0, 0.0, 0.0
    sc[:, 0], sc[:, 1], sc[:, 2], sc[:, 3] = -1e-9, 1.0, par[:, XI1], par[:, XI2]
    vec[:, 0, 0] = vec[:, 1, 1] = vec[:, 2, 2] = 1.0
    vec[:, 3], vec[:, 4] = X[:, 0, :3, 3], X[:, 2, :3, 3]
    flags[:, 0], flags[:, 1] = True, np.arange(len(flags)) % 2 == 0
    frames[:] = np.eye(4)


def _wait(worker):
    a = _LISTENER[0] if _LISTENER else None
    if a is not None:
        a.waiting, a.name = True, "the contact kernel, in a second process"
    try:
        worker.wait()
    finally:
        if a is not None:
            a.waiting, a.idle = False, time.perf_counter()


if __name__ == "__main__":
    _kernel_call()
