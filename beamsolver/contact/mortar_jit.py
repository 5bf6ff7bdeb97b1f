"""Compiled scatters of the mortar groups' blocks (``mortar.py``): the points' rows added to their groups.

The numpy forms (``np.add.at`` over fancy indices, ``*_numpy`` here) are their oracle: the loops add
in the order ``np.add.at`` does (points, then rows, then columns), so the sums are the same bits.  ``np.add.at``
cost about 0.8 ms an evaluation on the twisted pair (issue 26, speed: ``docs/benchmarks.md``).
"""
import numpy as np

from .._jit import jit

__all__ = ["scatter_rows", "scatter_block", "scatter_columns", "scatter_rows_numpy", "scatter_block_numpy",
           "scatter_columns_numpy"]


@jit
def _rows(out, g, rows, vals, scale):
    for p in range(rows.shape[0]):
        o, s = out[g[p]], scale[p]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for c in range(vals.shape[2]):
                o[r, c] += s * vals[p, i, c]


@jit
def _rows_plain(out, g, rows, vals):
    for p in range(rows.shape[0]):
        o = out[g[p]]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for c in range(vals.shape[2]):
                o[r, c] += vals[p, i, c]


@jit
def _block(out, g, rows, vals):
    for p in range(rows.shape[0]):
        o = out[g[p]]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for j in range(rows.shape[1]):
                o[r, rows[p, j]] += vals[p, i, j]


@jit
def _columns(out, g, cols, vals):
    for p in range(cols.shape[0]):
        o = out[g[p]]
        for i in range(vals.shape[1]):
            for j in range(cols.shape[1]):
                o[i, cols[p, j]] += vals[p, i, j]


def _c(a, dtype=np.float64):
    return np.ascontiguousarray(a, dtype=dtype)


def scatter_rows(out, g, rows, vals, scale=None):
    """``out[g[p], rows[p, i], :] += scale[p] vals[p, i, :]`` in place (``np.add.at`` order): ``out`` ``(n, r, c)``,
    ``g`` ``(P,)``, ``rows`` ``(P, m)``, ``vals`` ``(P, m, c)``, ``scale`` ``(P,)`` or None (no product).
    A 2-d ``out`` ``(n, r)`` and ``vals`` ``(P, m)`` add single entries."""
    flat = out.ndim == 2
    o = out[:, :, None] if flat else out
    v = _c(vals)[:, :, None] if flat else _c(vals)
    if scale is None:
        _rows_plain(o, _c(g, np.int64), _c(rows, np.int64), v)
    else:
        _rows(o, _c(g, np.int64), _c(rows, np.int64), v, _c(scale))
    return out


def scatter_block(out, g, rows, vals):
    """``out[g[p], rows[p, i], rows[p, j]] += vals[p, i, j]`` in place (``np.add.at`` order); ``out`` ``(n, r, r)``,
    ``rows`` ``(P, m)``, ``vals`` ``(P, m, m)``."""
    _block(out, _c(g, np.int64), _c(rows, np.int64), _c(vals))
    return out


def scatter_columns(out, g, cols, vals):
    """``out[g[p], i, cols[p, j]] += vals[p, i, j]`` in place (``np.add.at`` order); ``out`` ``(n, r, c)``,
    ``cols`` ``(P, m)``, ``vals`` ``(P, r, m)``."""
    _columns(out, _c(g, np.int64), _c(cols, np.int64), _c(vals))
    return out


# ---------------------------------------------------------------- the numpy oracle
def scatter_rows_numpy(out, g, rows, vals, scale=None):
    """``scatter_rows`` by ``np.add.at``."""
    v = vals if scale is None else scale.reshape((-1,) + (1,) * (vals.ndim - 1)) * vals
    np.add.at(out, (g[:, None], rows), v)
    return out


def scatter_block_numpy(out, g, rows, vals):
    """``scatter_block`` by ``np.add.at``."""
    np.add.at(out, (g[:, None, None], rows[:, :, None], rows[:, None, :]), vals)
    return out


def scatter_columns_numpy(out, g, cols, vals):
    """``scatter_columns`` by ``np.add.at``."""
    np.add.at(out, (g[:, None, None], np.arange(out.shape[1])[None, :, None], cols[:, None, :]), vals)
    return out
