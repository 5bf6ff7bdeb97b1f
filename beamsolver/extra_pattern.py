"""The reduced tangent with extra COO entries (contact blocks) on a cached pattern.

``System.matrix`` adds the COO entries of the contributions (``assemble_blocks``: contact
blocks, 576 entries per pair) to the element tangent.  Through scipy that is
``K_el + csc_matrix((v, (r, c)))`` every evaluation: a COO -> CSC conversion with a sort of
every column and a sparse sum, 0.2 s for the 14e3 contact points of the 19-wire bundle,
although the pattern is the same from one Newton iteration to the next while the active
set does not change.

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
"""
import numpy as np
import scipy.sparse as sp

from ._jit import jit

__all__ = ["ExtraPattern"]


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


@jit
def _merge(el_ptr, el_row, c_ptr, c_row, c_start, n_runs, u_ptr, u_row, u_col, el_pos, c_pos):
    """Union of the element pattern and the runs of the extra entries, column by column (both
    sorted by row): its column starts ``u_ptr``, rows ``u_row``, columns ``u_col`` and the union
    position of every element entry (``el_pos``) and run (``c_pos``); returns the union size."""
    n = 0
    r = 0
    u_ptr[0] = 0
    for j in range(len(el_ptr) - 1):
        a, a_end = el_ptr[j], el_ptr[j + 1]
        while True:
            ra = el_row[a] if a < a_end else -1
            in_col = r < n_runs and c_start[r] < c_ptr[j + 1]
            rb = c_row[c_start[r]] if in_col else -1
            if ra < 0 and rb < 0:
                break
            if rb < 0 or (0 <= ra < rb):
                el_pos[a] = n
                u_row[n] = ra
                a += 1
            elif ra < 0 or rb < ra:
                c_pos[r] = n
                u_row[n] = rb
                r += 1
            else:
                el_pos[a] = n
                c_pos[r] = n
                u_row[n] = ra
                a += 1
                r += 1
            u_col[n] = j
            n += 1
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
    per-entry buffers (12 bytes per entry) are reused when large enough: fresh memory costs
    page faults, up to 1 s of system time for the 8e6 entries of the 19-wire bundle.
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
        size = len(el_indices) + n_runs
        u_ptr = np.empty(n_free + 1, dtype=np.int64)
        u_row = np.empty(size, dtype=np.int32)
        u_col = np.empty(size, dtype=np.int32)
        self.el_pos = np.empty(len(el_indices), dtype=np.int64)
        self.c_pos = np.empty(n_runs, dtype=np.int64)
        n = _merge(np.asarray(el_indptr, dtype=np.int64), el_indices, ptr, c_row, self.start, n_runs,
                   u_ptr, u_row, u_col, self.el_pos, self.c_pos)
        self.indices, self.col = u_row[:n].copy(), u_col[:n].copy()
        self.indptr = u_ptr.astype(np.int32)

    def same(self, rows, cols, base=None):
        """Whether ``(rows, cols)`` is this pattern (the same arrays, or equal ones), on the same
        reduction and element pattern ``base = (red, el_indptr, el_indices)`` (the same arrays)."""
        if base is not None and any(a is not b for a, b in zip(base, self.base)):
            return False
        if rows is self.rows and cols is self.cols:
            return True
        return rows.shape == self.rows.shape and np.array_equal(rows, self.rows) and np.array_equal(cols, self.cols)

    def matrix(self, el_data, vals):
        """CSC matrix from the element values ``el_data`` (in the element pattern's order) and the
        extra values ``vals`` (aligned with ``rows``, ``cols``); exact zeros dropped."""
        data = np.empty(len(self.indices))
        zeros = _values(el_data, self.el_pos, vals, self.order, self.start, self.c_pos, data)
        indices, indptr = self.indices, self.indptr
        if zeros:
            nz = data != 0.0
            data, indices = data[nz], indices[nz]
            indptr = np.concatenate([[0], np.cumsum(np.bincount(self.col[nz], minlength=self.n_free))]).astype(np.int32)
        else:
            indices, indptr = indices.copy(), indptr.copy()
        return sp.csc_matrix((data, indices, indptr), shape=(self.n_free, self.n_free))
