"""The one numba decorator of the compiled kernels (``se3_jit``, ``element_jit``, ``assembly_jit``).

``cache=True``: compiled once per machine, later runs load the cache.
``error_model="numpy"``: a division by zero gives inf/nan as in numpy (no
per-division check); no ``fastmath``, so results stay those of the numpy
oracle to round-off.

Numba checks a cached function against its own source file only; ``jit_cache.install`` (run
here, before any function is decorated) stamps the package's cached functions with the digest of
their module and every package module it imports instead.
"""
from numba import njit

from .jit_cache import install

install()

jit = njit(cache=True, error_model="numpy")
# functions taking arrays are inlined into their caller: a call passing arrays costs a reference
# count increment and decrement per array (measured: ~20 % of the element kernel)
jit_inline = njit(cache=True, error_model="numpy", inline="always")
