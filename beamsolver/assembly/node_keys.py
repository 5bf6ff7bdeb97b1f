"""Sorted unique node-pair keys ``b n + a`` of ``held_pattern.HeldPattern``, built in linear time (issue 30).

``np.unique``, ``np.union1d``, ``np.setdiff1d`` and ``np.isin`` on the held pattern's keys cost more than linear
time on the large models (hash tables and sorts larger than the caches: the 0.3 m rope piece's new pattern spent
1.05 s in ``np.unique`` of 5.3e6 element entries and 2.6e6 contact slot pairs).  Here the keys are bucketed by
their column node ``b`` (counting sort), deduplicated per column with a stamp array and each column's few rows
sorted in place; unions, differences and counts of common keys are merges of sorted arrays.  The results are the
numpy functions' (the same sorted int64 arrays: ``tests/assembly/test_held_pattern.py``).
"""
import numpy as np

from .._jit import jit

__all__ = ["unique_keys", "element_keys", "block_keys", "union", "difference", "common"]


@jit
def _unique_keys(keys, n):
    """Sorted unique values of ``keys`` ``(m,)`` (each ``b n + a``, ``0 <= a, b < n``)."""
    m = len(keys)
    start = np.zeros(n + 1, dtype=np.int64)
    for i in range(m):
        start[keys[i] // n + 1] += 1
    for b in range(n):
        start[b + 1] += start[b]
    pos = start[:-1].copy()
    rows = np.empty(m, dtype=np.int64)
    for i in range(m):
        b = keys[i] // n
        rows[pos[b]] = keys[i] - b * n
        pos[b] += 1
    mark = np.full(n, -1, dtype=np.int64)
    out = np.empty(m, dtype=np.int64)
    s = 0
    for b in range(n):
        s0 = s
        for t in range(start[b], start[b + 1]):
            a = rows[t]
            if mark[a] != b:
                mark[a] = b
                out[s] = a
                s += 1
        out[s0:s].sort()
        for t in range(s0, s):
            out[t] += b * n
    return out[:s].copy()


@jit
def _element_raw(el_indptr, el_indices, node_of, n):
    """Keys ``node_of[j] n + node_of[i]`` of the entries (row ``i``, column ``j``) of a CSC pattern, a run of
    equal keys within a column given once."""
    out = np.empty(len(el_indices), dtype=np.int64)
    s = 0
    for j in range(len(el_indptr) - 1):
        b = node_of[j] * n
        last = -1
        for t in range(el_indptr[j], el_indptr[j + 1]):
            k = b + node_of[el_indices[t]]
            if k != last:
                out[s] = k
                s += 1
                last = k
    return out[:s]


@jit
def _block_raw(node, vals, nfree, n):
    """Keys ``b n + a`` of the slot pairs ``(s, t)`` of the blocks ``vals`` ``(m, 6 k, 6 k)`` over ``node``
    ``(m, k)`` (``a = node[., s]``, ``b = node[., t]``) whose nodes both have free dofs and whose 6 x 6 block is
    not all zero."""
    m, k = node.shape
    out = np.empty(m * k * k, dtype=np.int64)
    c = 0
    for blk in range(m):
        for s in range(k):
            a = node[blk, s]
            if nfree[a] == 0:
                continue
            for t in range(k):
                b = node[blk, t]
                if nfree[b] == 0:
                    continue
                nonzero = False
                for p in range(6):
                    for q in range(6):
                        if vals[blk, 6 * s + p, 6 * t + q] != 0.0:
                            nonzero = True
                            break
                    if nonzero:
                        break
                if nonzero:
                    out[c] = b * n + a
                    c += 1
    return out[:c]


@jit
def _merge(x, y, keep_x_only, keep_both, keep_y_only):
    """Sorted unique ``x``, ``y``: the values in ``x`` alone, in both, in ``y`` alone as asked, in order."""
    out = np.empty(len(x) + len(y), dtype=np.int64)
    i = j = c = 0
    while i < len(x) or j < len(y):
        if j == len(y) or (i < len(x) and x[i] < y[j]):
            if keep_x_only:
                out[c] = x[i]
                c += 1
            i += 1
        elif i == len(x) or y[j] < x[i]:
            if keep_y_only:
                out[c] = y[j]
                c += 1
            j += 1
        else:
            if keep_both:
                out[c] = x[i]
                c += 1
            i += 1
            j += 1
    return out[:c].copy()


def unique_keys(keys, n):
    """``np.unique(keys)`` for keys ``b n + a`` (int64, ``0 <= a, b < n``) in linear time."""
    return _unique_keys(np.ascontiguousarray(keys, dtype=np.int64), int(n))


def element_keys(el_indptr, el_indices, node_of, n):
    """Sorted unique node-pair keys ``b n + a`` of a CSC pattern ``(el_indptr, el_indices)`` whose unknowns
    belong to the nodes ``node_of``: ``np.unique(node_of[col] * n + node_of[el_indices])``."""
    raw = _element_raw(np.asarray(el_indptr, dtype=np.int64), np.asarray(el_indices),
                       np.ascontiguousarray(node_of, dtype=np.int64), int(n))
    return _unique_keys(raw, int(n))


def block_keys(node, vals, nfree, n):
    """Sorted unique keys ``b n + a`` of the node pairs of the blocks ``vals`` ``(m, 6 k, 6 k)`` over ``node``
    ``(m, k)`` whose both nodes have free dofs (``nfree > 0``) and whose 6 x 6 block is not all zero."""
    raw = _block_raw(np.ascontiguousarray(node, dtype=np.int64), np.ascontiguousarray(vals),
                     np.ascontiguousarray(nfree, dtype=np.int64), int(n))
    return _unique_keys(raw, int(n))


def union(x, y):
    """``np.union1d`` of sorted unique int64 arrays."""
    return _merge(np.asarray(x, dtype=np.int64), np.asarray(y, dtype=np.int64), True, True, True)


def difference(x, y):
    """``np.setdiff1d(x, y)`` of sorted unique int64 arrays."""
    return _merge(np.asarray(x, dtype=np.int64), np.asarray(y, dtype=np.int64), True, False, False)


def common(x, y):
    """How many values of sorted unique ``x`` are in sorted unique ``y``: ``np.isin(x, y).sum()``."""
    return len(_merge(np.asarray(x, dtype=np.int64), np.asarray(y, dtype=np.int64), False, True, False))
