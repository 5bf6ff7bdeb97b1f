"""The numba decorators of the compiled kernels (``se3_jit``, ``element_jit``, ``assembly_jit``, contact).

``cache=True``: compiled once per machine, later runs load the cache.
``error_model="numpy"``: a division by zero gives inf/nan as in numpy (no
per-division check); no ``fastmath``, so results stay those of the numpy
oracle to round-off.

- ``jit``: a function called from Python (an entry point: numba builds its CPython wrapper).
- ``jit_callee``: a function called from compiled functions only.  Compiled without the CPython
  and C wrappers (numba builds, optimises and machine-codes them for every function, and links
  them into every caller: about a fifth of the first run's compile time, ``benchmarks/jit_startup.py
  --functions``).  Called from Python (a test, an interactive session) it still works: the call goes
  to a twin compiled with the wrapper, cached under the name ``<name>__py``.

No function is inlined by numba (``inline="always"``): numba types and lowers an inlined body again
at every call site, which made the contact kernel's first compile 39 s of CPU instead of 20 s; LLVM
still inlines the small callees when it optimises the caller, and the main job's solve time is the
same (``benchmarks/jit_startup.py --warm``, issue 29).

Numba checks a cached function against its own source file only; ``jit_cache.install`` (run
here, before any function is decorated) stamps the package's cached functions with the digest of
their module and every package module it imports instead.
"""
import types

from numba import config, njit
from numba.core.registry import CPUDispatcher

from .jit_cache import install

install()

_OPTIONS = dict(error_model="numpy")

jit = njit(cache=True, **_OPTIONS)


class CalleeDispatcher(CPUDispatcher):
    """A dispatcher compiled without the CPython wrapper (``jit_callee``); a call from Python goes to
    ``python_twin``, the same function compiled with it."""

    _twin = None

    def __call__(self, *args, **kwargs):
        return self.python_twin(*args, **kwargs)

    @property
    def python_twin(self):
        """The same function compiled with a CPython wrapper, under the name ``<name>__py`` (its own
        cache entry: numba's cache index does not tell the two compilations apart)."""
        if self._twin is None:
            f = self.py_func
            g = types.FunctionType(f.__code__, f.__globals__, f.__name__ + "__py", f.__defaults__, f.__closure__)
            g.__qualname__, g.__doc__, g.__module__ = f.__qualname__ + "__py", f.__doc__, f.__module__
            self._twin = jit(g)
        return self._twin


def jit_callee(func):
    """``jit`` without the CPython wrapper, for a function compiled code calls (see the module)."""
    if config.DISABLE_JIT:
        return func
    disp = CalleeDispatcher(py_func=func, locals={},
                            targetoptions=dict(_OPTIONS, nopython=True, no_cpython_wrapper=True, no_cfunc_wrapper=True))
    disp.enable_caching()
    return disp
