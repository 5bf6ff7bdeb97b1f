"""Reused work arrays: a pool of buffers handed out again once nothing else holds them.

Fresh memory for each evaluation's large arrays (a contact kernel's ``(m, 24, 24)`` tangent blocks,
the assembler's COO index arrays) costs page faults; a ``BufferPool`` keeps the last few buffers
and hands one out again when ``sys.getrefcount`` shows that no array handed out earlier (a view of
it) is alive.  That count of the caller's own references is an implementation detail (CPython
3.14 borrows references on the stack): buffers are reused only on the CPython versions where it was
checked (``REUSE_BUFFERS``), else made anew.
"""
import ctypes
import platform
import sys
import weakref

import numpy as np

__all__ = ["REUSE_BUFFERS", "BufferPool", "equal", "release_idle", "RELEASE_MIN_VALUES", "RELEASE_AT_COMMIT",
           "MMAP_THRESHOLD"]

REUSE_BUFFERS = sys.implementation.name == "cpython" and sys.version_info < (3, 14)
RELEASE_MIN_VALUES = 4_000_000  # tangent values of an evaluation from which ``Evaluation.drop_tangent`` calls
#                                 ``release_idle`` (~28 000 elements: the rope pieces of 0.3 m and more, not the bundles)
RELEASE_AT_COMMIT = True       # ``Problem.commit`` lets the pools' idle buffers go at every accepted step, before the
#                                 contributions' commit pass, and step 0 when it starts again without exact stick's
#                                 friction (``release_idle(fix_threshold=False)``): a step's buffers (step 0's settling:
#                                 the 61-wire strand's 0.66 GB) are not kept through the next (docs/benchmarks.md,
#                                 "Memory of the strand's loaded step, session 12")
MMAP_THRESHOLD = 4 << 20        # bytes: glibc's mmap threshold fixed there by ``release_idle`` (None: left alone)
_POOLS = weakref.WeakSet()
_MMAP_SET = []


def equal(a, b):
    """``np.array_equal(a, b)`` of two arrays (same shape, equal elements, nan unequal) without its argument
    handling: the test of the caches kept for the same poses or pairs, several per evaluation (2 us less each)."""
    return a.shape == b.shape and bool((a == b).all())


def release_idle(fix_threshold=True):
    """Memory over speed for large models (issue 30, the 0.6 m rope within 8 GB): every pool drops the buffers
    nothing else references (the groups' tangent blocks and the kernel's point terms while a line search's
    residual-only trial runs: 1.3 GB on that rope; the next evaluation with tangent takes fresh memory), and,
    once per process on glibc, its mmap threshold is fixed at ``MMAP_THRESHOLD`` (its default grows up to 32 MB
    as large arrays are freed, and freed arrays below it stay in the heap).  Values do not change: a pool's
    buffer is filled by its caller.  Returns the bytes dropped.  ``fix_threshold=False``: the buffers alone
    (``RELEASE_AT_COMMIT``; glibc's threshold as it is)."""
    if fix_threshold and MMAP_THRESHOLD is not None and not _MMAP_SET:
        _MMAP_SET.append(True)
        if sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc":
            try:
                ctypes.CDLL(None).mallopt(-3, int(MMAP_THRESHOLD))       # M_MMAP_THRESHOLD
            except (OSError, AttributeError):
                pass
    return sum(p.release() for p in list(_POOLS))


class BufferPool:
    """At most ``keep`` buffers of one ``dtype``, grown along ``axis``.

    ``take(shape)`` returns a view ``shape`` of a kept buffer that nothing else references and that
    is long enough along ``axis`` (its other sizes equal), else of a new buffer with room for an
    eighth more along ``axis`` (an active set growing by one pair needs no fresh memory), which
    becomes the first kept one.  The view's values are whatever the buffer held: the caller fills it.
    """

    def __init__(self, dtype=float, axis=0, keep=2):
        self.dtype, self.axis, self.keep = np.dtype(dtype), axis, keep
        self.buffers = []
        _POOLS.add(self)

    def release(self):
        """Drop the kept buffers that nothing else references (``release_idle``); returns their bytes."""
        idle = [sys.getrefcount(b) <= 3 for b in self.buffers]     # (the list, ``b``, the argument)
        freed = sum(b.nbytes for b, i in zip(self.buffers, idle) if i)
        self.buffers = [b for b, i in zip(self.buffers, idle) if not i]
        return freed

    def take(self, shape):
        n = shape[self.axis]
        cut = (slice(None),) * self.axis + (slice(0, n),)
        for b in self.buffers if REUSE_BUFFERS else ():
            if b.shape[self.axis] >= n and sys.getrefcount(b) <= 3 and b[cut].shape == tuple(shape):
                return b[cut]      # (references: the list, ``b`` and ``getrefcount``'s argument)
        full = list(shape)
        full[self.axis] = n + n // 8 if REUSE_BUFFERS else n
        b = np.empty(full, dtype=self.dtype)
        self.buffers = [b] + self.buffers[:self.keep - 1]
        return b[cut]
