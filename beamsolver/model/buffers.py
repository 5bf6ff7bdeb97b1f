"""Reused work arrays: a pool of buffers handed out again once nothing else holds them.

Fresh memory for each evaluation's large arrays (a contact kernel's ``(m, 24, 24)`` tangent blocks,
the assembler's COO index arrays) costs page faults; a ``BufferPool`` keeps the last few buffers
and hands one out again when ``sys.getrefcount`` shows that no array handed out earlier (a view of
it) is alive.  That count of the caller's own references is an implementation detail (CPython
3.14 borrows references on the stack): buffers are reused only on the CPython versions where it was
checked (``REUSE_BUFFERS``), else made anew.
"""
import sys

import numpy as np

__all__ = ["REUSE_BUFFERS", "BufferPool"]

REUSE_BUFFERS = sys.implementation.name == "cpython" and sys.version_info < (3, 14)


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
