"""The reduced tangent with extra COO entries (contact blocks) on a cached pattern.

``System.matrix`` adds the COO entries of the contributions (``assemble_blocks``: contact
blocks, 576 entries per pair) to the element tangent.  Through scipy that is
``K_el + csc_matrix((v, (r, c)))`` every evaluation: a COO -> CSC conversion with a sort of
every column and a sparse sum, although the pattern is the same from one Newton iteration to
the next while the active set does not change.

``ExtraPattern`` is built once per pattern of the COO entries and gives the same matrix,
bit for bit (the same values summed in the same order, the same stored entries):

- scipy buckets the entries by column in their order (``coo_tocsr``), sorts each column by
  row (``csr_sort_indices``: ``std::sort`` on the row alone, not stable, skipped when every
  column is already sorted) and sums runs of equal rows left to right
  (``csr_sum_duplicates``); ``K_el + K_c`` (``csr_plus_csr``) then adds ``a + b`` entry by
  entry and drops the sums that are exactly zero;
- here the build runs the same bucketing and the same scipy sort on the entry numbers (the
  sort compares rows only, so the numbers travel as the values would), which gives the
  order of the entries in each run; an evaluation (``matrix``) sums the runs in that order
  and adds them to the element values on the union of both patterns (compiled, no sort),
  then drops the exact zeros as scipy does.

``BlockPattern`` gives the same matrix for the entries of dense blocks over whole nodes (what
``System.assemble_blocks`` makes of contact blocks: ``rows = repeat(d, b)``, ``cols = tile(d, b)``
with ``d[:, 6 s + q] = 6 node + q``), built from ``d`` alone, six times less work: the 6
columns of a node hold the same rows in the same order (one row of ``d`` per block), so
scipy's sort, which compares rows only, moves their entries alike; the build buckets and
sorts one column per node (entry numbers of its ``q = 0`` column) in one scipy sort, and an
evaluation reads column ``q`` at number ``+ q`` (a free node's six columns in one pass).  The
only caveat is scipy's "skip the sort when every column is sorted": the node columns are those
of the kept dof columns, so the test sees the same columns.  Entries after the blocks (a
``tail``: ``assemble_blocks``' terms of global-type nodes) make the dof columns they reach
special: those are bucketed (block entries, then tail entries) and sorted on their own, in
the same scipy sort.  A new active set costs a new pattern (build times of both:
docs/benchmarks.md).
"""
import numpy as np
import scipy.sparse as sp

from .._jit import jit, jit_callee
from .csc import canonical_csc
from ..model.buffers import equal

__all__ = ["ExtraPattern", "BlockPattern"]


@jit
def _count(rows, cols, red, ptr):
    """Entries per column of the reduced matrix (``ptr[j + 1]``) and their number: those whose row
    and column are both free (``red >= 0``)."""
    ptr[:] = 0
    n = 0
    for k in range(len(rows)):
        c = red[cols[k]]
        if c >= 0 and red[rows[k]] >= 0:
            ptr[c + 1] += 1
            n += 1
    for j in range(len(ptr) - 1):
        ptr[j + 1] += ptr[j]
    return n


@jit
def _bucket(rows, cols, red, ptr, number, row):
    """Stable bucketing of the kept entries by column (``coo_tocsr``): their entry numbers
    ``number`` (float: scipy's sort moves them as values) and reduced rows ``row``, column by column."""
    nxt = ptr[:-1].copy()
    for k in range(len(rows)):
        c = red[cols[k]]
        r = red[rows[k]]
        if c >= 0 and r >= 0:
            number[nxt[c]] = k
            row[nxt[c]] = r
            nxt[c] += 1


@jit
def _runs(row, ptr, start):
    """Starts of the runs of equal rows within each column (``row`` sorted per column); returns
    their number, ``start`` filled with one more entry (the end)."""
    n = 0
    for j in range(len(ptr) - 1):
        for s in range(ptr[j], ptr[j + 1]):
            if s == ptr[j] or row[s] != row[s - 1]:
                start[n] = s
                n += 1
    start[n] = ptr[-1]
    return n


@jit_callee
def _merge_column(j, el_row, a, a_end, c_row, c_start, r, r_end, n, p, u_row, u_col, el_pos, c_pos):
    """Column ``j`` of the union: element entries ``a:a_end`` and runs ``r:r_end`` (both sorted by
    row) written from union position ``n``, the runs' positions at ``c_pos[p:]``; returns ``(n, p)``."""
    while a < a_end or r < r_end:
        ra = el_row[a] if a < a_end else -1
        rb = c_row[c_start[r]] if r < r_end else -1
        if rb < 0 or (0 <= ra < rb):
            el_pos[a] = n
            u_row[n] = ra
            a += 1
        elif ra < 0 or rb < ra:
            c_pos[p] = n
            p += 1
            u_row[n] = rb
            r += 1
        else:
            el_pos[a] = n
            c_pos[p] = n
            p += 1
            u_row[n] = ra
            a += 1
            r += 1
        u_col[n] = j
        n += 1
    return n, p


@jit
def _merge(el_ptr, el_row, c_ptr, c_row, c_start, n_runs, u_ptr, u_row, u_col, el_pos, c_pos):
    """Union of the element pattern and the runs of the extra entries, column by column (both
    sorted by row): its column starts ``u_ptr``, rows ``u_row``, columns ``u_col`` and the union
    position of every element entry (``el_pos``) and run (``c_pos``); returns the union size."""
    n = 0
    r = 0
    u_ptr[0] = 0
    for j in range(len(el_ptr) - 1):
        r_end = r
        while r_end < n_runs and c_start[r_end] < c_ptr[j + 1]:
            r_end += 1
        n, r = _merge_column(j, el_row, el_ptr[j], el_ptr[j + 1], c_row, c_start, r, r_end, n, r,
                             u_row, u_col, el_pos, c_pos)
        u_ptr[j + 1] = n
    return n


@jit
def _values(el_data, el_pos, vals, order, start, c_pos, out):
    """Union values: element values, plus each run of extra values summed left to right in
    ``order`` (``0 + x`` where no element entry sits, as ``csr_plus_csr``); returns whether
    some value is exactly zero."""
    out[:] = 0.0
    for k in range(len(el_pos)):
        out[el_pos[k]] = el_data[k]
    for u in range(len(c_pos)):
        x = vals[np.int64(order[start[u]])]
        for s in range(start[u] + 1, start[u + 1]):
            x += vals[np.int64(order[s])]
        out[c_pos[u]] += x
    for k in range(len(out)):
        if out[k] == 0.0:
            return True
    return False


class ExtraPattern:
    """The union pattern of the element tangent and extra COO entries ``(rows, cols)`` (full ``z``
    numbering, reduced by ``red``: ``-1`` for constrained unknowns), built once; ``matrix`` gives
    ``K_el + csc_matrix((vals, (red[rows], red[cols])))`` of scipy, bit for bit, for new values.

    ``el_indptr``, ``el_indices``: the element tangent's CSC pattern (canonical: sorted, no
    duplicates), ``n_free`` its size.  ``spare``: the pattern this one replaces, whose two
    per-entry buffers (12 bytes per entry) are reused when large enough (fresh memory costs
    page faults).
    """

    def __init__(self, rows, cols, red, n_free, el_indptr, el_indices, spare=None):
        self.rows, self.cols, self.n_free = rows, cols, n_free
        self.base = (red, el_indptr, el_indices)       # the arrays it was built on (``same``)
        red = np.ascontiguousarray(red, dtype=np.int64)
        ptr = np.empty(n_free + 1, dtype=np.int64)
        n_kept = _count(rows, cols, red, ptr)
        if spare is None or len(spare.buffers[0]) < n_kept:
            spare = None
            extra = n_kept + n_kept // 8           # room for a few more pairs next time
            self.buffers = np.empty(extra), np.empty(extra, dtype=np.int32)
        else:
            self.buffers = spare.buffers
            spare.order = spare.buffers = None     # the old pattern is not used any more
        number, row = self.buffers[0][:n_kept], self.buffers[1][:n_kept]
        _bucket(rows, cols, red, ptr, number, row)
        # scipy's own column sort, on the entry numbers (exact as floats below 2^53)
        tmp = sp.csc_matrix((number, row, ptr.astype(np.int32)), shape=(n_free, n_free), copy=False)
        tmp.sort_indices()
        c_row = tmp.indices
        self.order = tmp.data              # entry of ``vals`` (as a float) of each sorted slot
        start = np.empty(n_kept + 1, dtype=np.int64)
        n_runs = _runs(c_row, ptr, start)
        self.start = start[:n_runs + 1].copy()
        u_ptr, u_row, u_col, self.el_pos, self.c_pos = _union_buffers(n_free, len(el_indices), n_runs)
        n = _merge(np.asarray(el_indptr, dtype=np.int64), el_indices, ptr, c_row, self.start, n_runs,
                   u_ptr, u_row, u_col, self.el_pos, self.c_pos)
        self.indices, self.col, self.indptr = u_row[:n].copy(), u_col[:n].copy(), u_ptr.astype(np.int32)

    def same(self, rows, cols, base=None):
        """Whether ``(rows, cols)`` is this pattern (the same arrays, or equal ones), on the same
        reduction and element pattern ``base = (red, el_indptr, el_indices)`` (the same arrays)."""
        if base is not None and any(a is not b for a, b in zip(base, self.base)):
            return False
        if rows is self.rows and cols is self.cols:
            return True
        return rows.shape == self.rows.shape and equal(rows, self.rows) and equal(cols, self.cols)

    def matrix(self, el_data, vals):
        """CSC matrix from the element values ``el_data`` (in the element pattern's order) and the
        extra values ``vals`` (aligned with ``rows``, ``cols``); exact zeros dropped."""
        data = np.empty(len(self.indices))
        zeros = _values(el_data, self.el_pos, vals, self.order, self.start, self.c_pos, data)
        return _csc(data, zeros, self.indices, self.indptr, self.col, self.n_free)


@jit
def _count_nodes(node, drow, kept, spec_ptr, t_row, t_src, ptr):
    """Entries per source column (``ptr[c + 1]``): node column ``b`` (if ``kept[b]``) and the
    special columns ``spec_ptr[b]:spec_ptr[b + 1]`` of node ``b`` get the kept rows ``drow >= 0`` of
    every block holding ``b`` (once per slot); a special column also its tail entries (``t_src``,
    ``-1``: dropped); returns their number."""
    ptr[:] = 0
    n = 0
    for blk in range(len(node)):
        rows = 0
        for i in range(drow.shape[1]):
            if drow[blk, i] >= 0:
                rows += 1
        for s in range(node.shape[1]):
            b = node[blk, s]
            if kept[b]:
                ptr[b + 1] += rows
                n += rows
            for k in range(spec_ptr[b], spec_ptr[b + 1]):
                ptr[k + 1] += rows
                n += rows
    for t in range(len(t_src)):
        if t_src[t] >= 0 and t_row[t] >= 0:
            ptr[t_src[t] + 1] += 1
            n += 1
    for j in range(len(ptr) - 1):
        ptr[j + 1] += ptr[j]
    return n


@jit
def _bucket_nodes(node, drow, kept, spec_ptr, spec_q, t_row, t_src, ptr, number, row):
    """Stable bucketing by source column in the order of the entries of its dof column
    (``coo_tocsr``): block, then row ``i``, then slot ``s``, entry number ``blk b^2 + i b + 6 s``
    (node columns: that of ``q = 0``; special columns: ``+ q``), then the tail entries
    (number ``m b^2 + t``)."""
    nxt = ptr[:-1].copy()
    nb = drow.shape[1]
    for blk in range(len(node)):
        for i in range(nb):
            r = drow[blk, i]
            if r < 0:
                continue
            for s in range(node.shape[1]):
                b = node[blk, s]
                e = blk * nb * nb + i * nb + 6 * s
                if kept[b]:
                    number[nxt[b]] = e
                    row[nxt[b]] = r
                    nxt[b] += 1
                for k in range(spec_ptr[b], spec_ptr[b + 1]):
                    number[nxt[k]] = e + spec_q[k]
                    row[nxt[k]] = r
                    nxt[k] += 1
    n_b = len(node) * nb * nb
    for t in range(len(t_src)):
        c = t_src[t]
        if c >= 0 and t_row[t] >= 0:
            number[nxt[c]] = n_b + t
            row[nxt[c]] = t_row[t]
            nxt[c] += 1


@jit
def _merge_nodes(el_ptr, el_row, col_src, run_ptr, c_row, c_start, u_ptr, u_row, u_col, el_pos, c_pos):
    """``_merge`` with the runs of the source column ``col_src[j]`` (``run_ptr``) in dof column ``j``;
    ``c_pos`` in the order column, run."""
    n = 0
    p = 0
    u_ptr[0] = 0
    for j in range(len(el_ptr) - 1):
        b = col_src[j]
        n, p = _merge_column(j, el_row, el_ptr[j], el_ptr[j + 1], c_row, c_start, run_ptr[b], run_ptr[b + 1],
                             n, p, u_row, u_col, el_pos, c_pos)
        u_ptr[j + 1] = n
    return n


@jit
def _values_nodes(el_data, el_pos, vals, order, start, col_src, col_off, run_ptr, c_pos, out):
    """``_values`` of ``BlockPattern``: dof column ``j`` sums the runs of its source column at the
    entry numbers ``order + col_off[j]``, left to right; returns whether some value is exactly zero."""
    out[:] = 0.0
    for k in range(len(el_pos)):
        out[el_pos[k]] = el_data[k]
    # the consecutive columns of one source column together (a node's: one pass over its entries,
    # whose values sit side by side); each column's sums in its own order
    x = np.empty(6)
    p = 0
    j = 0
    while j < len(col_src):
        b = col_src[j]
        nq = 1
        while nq < 6 and j + nq < len(col_src) and col_src[j + nq] == b:
            nq += 1
        r0, r1 = run_ptr[b], run_ptr[b + 1]
        nr = r1 - r0
        if nq == 6:                          # a free node: its six columns, offsets 0..5
            for u in range(r0, r1):
                o = order[start[u]]
                x0, x1, x2, x3, x4, x5 = vals[o], vals[o + 1], vals[o + 2], vals[o + 3], vals[o + 4], vals[o + 5]
                for s in range(start[u] + 1, start[u + 1]):
                    o = order[s]
                    x0 += vals[o]
                    x1 += vals[o + 1]
                    x2 += vals[o + 2]
                    x3 += vals[o + 3]
                    x4 += vals[o + 4]
                    x5 += vals[o + 5]
                k = p + u - r0
                out[c_pos[k]] += x0
                out[c_pos[k + nr]] += x1
                out[c_pos[k + 2 * nr]] += x2
                out[c_pos[k + 3 * nr]] += x3
                out[c_pos[k + 4 * nr]] += x4
                out[c_pos[k + 5 * nr]] += x5
            p += 6 * nr
            j += 6
            continue
        for u in range(r0, r1):
            o = order[start[u]]
            for g in range(nq):
                x[g] = vals[o + col_off[j + g]]
            for s in range(start[u] + 1, start[u + 1]):
                o = order[s]
                for g in range(nq):
                    x[g] += vals[o + col_off[j + g]]
            for g in range(nq):
                out[c_pos[p + g * (r1 - r0) + u - r0]] += x[g]
        p += nq * (r1 - r0)
        j += nq
    for k in range(len(out)):
        if out[k] == 0.0:
            return True
    return False


@jit
def _node_runs(row, ptr, start, run_ptr):
    """``_runs`` per source column, with the first run of each column ``run_ptr[c]``."""
    n = 0
    for j in range(len(ptr) - 1):
        run_ptr[j] = n
        for s in range(ptr[j], ptr[j + 1]):
            if s == ptr[j] or row[s] != row[s - 1]:
                start[n] = s
                n += 1
    run_ptr[len(ptr) - 1] = n
    start[n] = ptr[-1]
    return n


def whole_nodes(d):
    """Whether the block dofs ``d`` ``(m, 6 k)`` come in whole nodes: ``d[:, 6 s + q] = 6 node + q``."""
    d = np.asarray(d)
    if d.ndim != 2 or d.shape[1] % 6 or not np.issubdtype(d.dtype, np.integer):
        return False
    first = d[:, 0::6]
    return bool((first % 6 == 0).all() and (d.reshape(len(d), -1, 6) == first[:, :, None] + np.arange(6)).all())


class BlockPattern:
    """``ExtraPattern`` of the COO entries of dense blocks over the dofs ``d`` ``(m, 6 k)`` (whole
    nodes: ``whole_nodes(d)``), ``rows = repeat(d, 6 k)``, ``cols = tile(d, 6 k)``, followed by the
    entries ``tail = (t_rows, t_cols)`` (or ``None``): ``matrix`` gives
    ``K_el + csc_matrix((vals, (red[rows], red[cols])))`` of scipy bit for bit, ``vals`` the blocks
    ``(m, 6 k, 6 k)`` raveled, then the tail's values.  A dof column with tail entries (special)
    is sorted on its own; the others read their node's column.  ``spare``: the ``BlockPattern`` it
    replaces, whose buffers (8 bytes per entry of a node column while its numbers fit in int32, else 12)
    are reused when large enough.
    """

    def __init__(self, d, red, n_free, el_indptr, el_indices, tail=None, spare=None):
        self.d, self.n_free = d, n_free
        self.tail = None if tail is None else (np.array(tail[0]), np.array(tail[1]))
        self.base = (red, el_indptr, el_indices)
        red = np.ascontiguousarray(red, dtype=np.int64)
        n_nodes = len(red) // 6
        node = np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64)
        drow = red[d]
        free_dofs = np.flatnonzero(red >= 0)
        # source column of every dof column: its node's, or a special column (tail entries) at
        # n_nodes + k, numbered node by node
        t_rows, t_cols = self.tail if tail is not None else (np.zeros(0, dtype=np.int64),) * 2
        t_row = red[t_rows]
        special = np.zeros(len(red), dtype=bool)
        special[t_cols[(t_row >= 0) & (red[t_cols] >= 0)]] = True
        spec_dofs = np.flatnonzero(special)
        src = free_dofs // 6
        off = free_dofs % 6
        is_spec = special[free_dofs]
        src[is_spec] = n_nodes + np.arange(len(spec_dofs))
        off[is_spec] = 0
        self.col_src, self.col_off = src, off
        spec_ptr = n_nodes + np.searchsorted(spec_dofs // 6, np.arange(n_nodes + 1))
        spec_q = np.zeros(n_nodes + len(spec_dofs), dtype=np.int64)
        spec_q[n_nodes:] = spec_dofs % 6
        t_src = np.full(len(t_cols), -1, dtype=np.int64)
        t_src[special[t_cols]] = n_nodes + np.searchsorted(spec_dofs, t_cols[special[t_cols]])
        kept = np.zeros(n_nodes, dtype=bool)
        kept[free_dofs[~is_spec] // 6] = True
        n_src = n_nodes + len(spec_dofs)
        ptr = np.empty(n_src + 1, dtype=np.int64)
        n_kept = _count_nodes(node, drow, kept, spec_ptr, t_row, t_src, ptr)
        # entry numbers and their runs in int32 while they fit (half the memory of int64)
        idx = np.int32 if len(node) * drow.shape[1] ** 2 + len(t_src) < np.iinfo(np.int32).max else np.int64
        if (spare is None or spare.buffers is None or len(spare.buffers[0]) < n_kept
                or spare.buffers[0].dtype != idx):
            extra = n_kept + n_kept // 8           # room for a few more pairs next time
            self.buffers = np.empty(extra, dtype=idx), np.empty(extra, dtype=np.int32)
        else:
            self.buffers = spare.buffers
            spare.order = spare.buffers = None     # the old pattern is not used any more
        number, row = self.buffers[0][:n_kept], self.buffers[1][:n_kept]
        _bucket_nodes(node, drow, kept, spec_ptr, spec_q, t_row, t_src, ptr, number, row)
        # scipy's own column sort (the one of ``coo.tocsc``), on the entry numbers
        tmp = sp.csc_matrix((number, row, ptr.astype(np.int32)), shape=(max(n_free, 1), n_src), copy=False)
        tmp.sort_indices()
        c_row = tmp.indices
        self.order = tmp.data
        start = np.empty(n_kept + 1, dtype=idx)
        self.run_ptr = np.empty(n_src + 1, dtype=np.int64)
        n_runs = _node_runs(c_row, ptr, start, self.run_ptr)
        self.start = start[:n_runs + 1].copy()
        n_c = int((self.run_ptr[src + 1] - self.run_ptr[src]).sum())
        pos = np.int32 if len(el_indices) + n_c < np.iinfo(np.int32).max else np.int64
        u_ptr, u_row, u_col, self.el_pos, self.c_pos = _union_buffers(n_free, len(el_indices), n_c, pos)
        n = _merge_nodes(np.asarray(el_indptr, dtype=np.int64), el_indices, src, self.run_ptr, c_row,
                         self.start, u_ptr, u_row, u_col, self.el_pos, self.c_pos)
        self.indices, self.col, self.indptr = u_row[:n].copy(), u_col[:n].copy(), u_ptr.astype(np.int32)

    def same(self, d, tail=None, base=None):
        """Whether ``d`` and ``tail`` are this pattern's (the same ``d`` array, or equal ones), on the
        same ``base = (red, el_indptr, el_indices)`` (the same arrays)."""
        if base is not None and any(a is not b for a, b in zip(base, self.base)):
            return False
        if (tail is None) != (self.tail is None) or (tail is not None and not (
                equal(tail[0], self.tail[0]) and equal(tail[1], self.tail[1]))):
            return False
        return d is self.d or (d.shape == self.d.shape and equal(d, self.d))

    def matrix(self, el_data, vals):
        """CSC matrix from the element values ``el_data`` and the block values ``vals`` (the blocks
        raveled, ``(m (6 k)^2,)``, then the tail's); exact zeros dropped."""
        data = np.empty(len(self.indices))
        zeros = _values_nodes(el_data, self.el_pos, vals, self.order, self.start, self.col_src, self.col_off,
                              self.run_ptr, self.c_pos, data)
        return _csc(data, zeros, self.indices, self.indptr, self.col, self.n_free)


def _csc(data, zeros, indices, indptr, col, n_free):
    """The union-pattern CSC matrix of ``data``, without its exact zeros (``zeros``: some are).  The
    pattern is canonical (sorted, unique rows per column, as scipy's sum makes it): ``csc.canonical_csc``."""
    if zeros:
        d, i, p = np.empty(len(data)), np.empty(len(data), dtype=np.int32), np.empty(n_free + 1, dtype=np.int32)
        k = _drop_zeros(data, indices, col, d, i, p)
        data, indices, indptr = d[:k], i[:k], p
    else:
        indices, indptr = indices.copy(), indptr.copy()
    return canonical_csc(data, indices, indptr, n_free)


@jit
def _drop_zeros(data, indices, col, d, i, ptr):
    """Entries of ``data`` that are not exactly zero into ``d``, their rows into ``i`` (order kept) and
    the column pointers into ``ptr``; returns their number (``data != 0``, ``bincount`` of ``col``)."""
    ptr[:] = 0
    k = 0
    for s in range(len(data)):
        if data[s] != 0.0:
            d[k], i[k] = data[s], indices[s]
            ptr[col[s] + 1] += 1
            k += 1
    for j in range(len(ptr) - 1):
        ptr[j + 1] += ptr[j]
    return k


def _union_buffers(n_free, n_el, n_c, pos=np.int64):
    """Output buffers of a union-pattern merge (``_merge``, ``_merge_nodes``): column pointers
    ``(n_free + 1,)``, rows and columns ``(n_el + n_c,)`` (room for no overlap) and the union
    positions (dtype ``pos``) of the ``n_el`` element entries and of the ``n_c`` contact runs."""
    size = n_el + n_c
    return (np.empty(n_free + 1, dtype=np.int64), np.empty(size, dtype=np.int32), np.empty(size, dtype=np.int32),
            np.empty(n_el, dtype=pos), np.empty(n_c, dtype=pos))
