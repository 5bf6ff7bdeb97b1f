"""A tangent pattern held across Newton iterations: the element pattern plus reserved contact node pairs.

``extra_pattern.BlockPattern`` builds the exact union of the element pattern and the active contact
blocks, without the entries that sum to exactly zero: a new pattern whenever a contact point enters or
leaves an element pair, which on a loaded step of a bundle is every Newton iteration, and PARDISO then
redoes its ordering and symbolic analysis (``linsolve._Pardiso``; ~0.5 s at 61 wires).  ``HeldPattern``
stores explicit zeros instead: its pattern is the element pattern plus 6 x 6 node blocks for every
*reserved* node pair, the union of the node pairs the contact blocks have used so far (grown when a
block reaches a pair outside it, rebuilt from the current pairs alone when fewer than ``RESET_SHARE`` of
the reserved pairs are still used then), so consecutive tangents have the same ``indptr``, ``indices``
and PARDISO runs its numerical factorisation only (phase 22).  The values are those of
``BlockPattern`` to round-off (the same entries summed, in another order; zeros kept).

Node-level layout: the reserved node graph ``(nptr, nrow)`` (node column ``b``: sorted row nodes ``a``)
covers the element pattern (every element couples whole nodes) and the reserved pairs; dof column ``j``
of node ``b`` holds the free dofs of its row nodes in order, so the entry (row dof ``6 a + p``, column
dof ``6 b + q``) sits at ``indptr[red[6 b + q]] + eoff[e] + prank[a, p]``, ``e`` the pair's place in the
node graph, ``eoff[e]`` its offset in the node column (the same for the six columns of ``b``) and
``prank[a, p]`` the rank of dof ``p`` among the free dofs of ``a``: memory per node pair, not per entry.
"""
import numpy as np

from .._jit import jit, jit_callee
from . import node_keys
from .csc import canonical_csc

__all__ = ["HeldPattern", "RESET_SHARE", "LINEAR_KEYS"]

RESET_SHARE = 0.8      # growth: keep the old reserve while at least this share of its contact pairs is in use
LINEAR_KEYS = True     # the node-pair keys by ``node_keys`` (linear time), else numpy's unique / union1d / setdiff1d


@jit_callee
def _find(nptr, nrow, a, b):
    """Place of the node pair (row ``a``, column ``b``) in the node graph, ``-1`` if absent."""
    lo, hi = nptr[b], nptr[b + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if nrow[mid] < a:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < nptr[b + 1] and nrow[lo] == a else -1


@jit
def _expand(nptr, nrow, nfree, first, indptr, indices, eoff):
    """The dof pattern of the node graph: column pointers ``indptr`` (``(n_free + 1,)``), rows
    ``indices`` and each node pair's offset ``eoff`` within its node column; ``first[a]`` is the first
    free (reduced) dof of node ``a``."""
    indptr[0] = 0
    j = 0
    for b in range(len(nptr) - 1):
        off = 0
        for e in range(nptr[b], nptr[b + 1]):
            eoff[e] = off
            off += nfree[nrow[e]]
        for q in range(nfree[b]):
            s = indptr[j]
            for e in range(nptr[b], nptr[b + 1]):
                a = nrow[e]
                for p in range(nfree[a]):
                    indices[s] = first[a] + p
                    s += 1
            indptr[j + 1] = s
            j += 1


@jit
def _element_positions(el_indptr, el_indices, node_of, first, nptr, nrow, eoff, indptr, out):
    """Position of every element-pattern entry in the held pattern; returns how many are not in it."""
    missing = 0
    for j in range(len(el_indptr) - 1):
        b = node_of[j]
        for s in range(el_indptr[j], el_indptr[j + 1]):
            i = el_indices[s]
            a = node_of[i]
            e = _find(nptr, nrow, a, b)
            if e < 0:
                missing += 1
                out[s] = 0
            else:
                out[s] = indptr[j] + eoff[e] + (i - first[a])
    return missing


@jit_callee
def _zero_block(vals, blk, s, t):
    """Whether the 6 x 6 block of slots ``(s, t)`` of block ``blk`` of ``vals`` ``(m, 6 k, 6 k)`` is all zero."""
    for p in range(6):
        for q in range(6):
            if vals[blk, 6 * s + p, 6 * t + q] != 0.0:
                return False
    return True


@jit
def _uncovered(node, vals, nfree, nptr, nrow):
    """Number of slot pairs of the blocks ``vals`` over ``node`` ``(m, k)`` whose node pair (both with free
    dofs, a 6 x 6 block not all zero) is not in the node graph."""
    n = 0
    for blk in range(node.shape[0]):
        for t in range(node.shape[1]):
            b = node[blk, t]
            if nfree[b] == 0:
                continue
            for s in range(node.shape[1]):
                a = node[blk, s]
                if nfree[a] > 0 and _find(nptr, nrow, a, b) < 0 and not _zero_block(vals, blk, s, t):
                    n += 1
    return n


@jit
def _values(el_data, el_pos, node, vals, red, nfree, indptr, eoff, nptr, nrow, t_rows, t_cols, t_vals, out):
    """Held-pattern values: element values, plus the blocks ``vals`` ``(m, 6 k, 6 k)`` over ``node``
    ``(m, k)``, plus the tail entries (full numbering, dropped where held); explicit zeros kept.  Returns
    False if an entry with a free row and column has no place in the pattern.  Each entry sums its terms in
    block, then slot-pair order; a pair of whole free nodes is the 6 x 6 block at ``indptr[j0] + eoff[e]``
    with column stride ``L`` (``_node_block``)."""
    out[:] = 0.0
    for s in range(len(el_pos)):
        out[el_pos[s]] += el_data[s]
    k = node.shape[1]
    for blk in range(node.shape[0]):
        for t in range(k):
            b = node[blk, t]
            if nfree[b] == 0:
                continue
            for s in range(k):
                a = node[blk, s]
                if nfree[a] == 0:
                    continue
                e = _find(nptr, nrow, a, b)
                if e < 0:
                    if not _zero_block(vals, blk, s, t):
                        return False
                    continue                     # a zero block
                if nfree[a] == 6 and nfree[b] == 6:
                    base, L = _node_block(red, indptr, eoff, b, e)
                    for q in range(6):
                        col = base + q * L
                        for p in range(6):
                            out[col + p] += vals[blk, 6 * s + p, 6 * t + q]
                    continue
                for q in range(6):
                    j = red[6 * b + q]
                    if j < 0:
                        continue
                    base = indptr[j] + eoff[e]
                    r = 0
                    for p in range(6):
                        if red[6 * a + p] >= 0:
                            out[base + r] += vals[blk, 6 * s + p, 6 * t + q]
                            r += 1
    for u in range(len(t_rows)):
        j, i = red[t_cols[u]], red[t_rows[u]]
        if i < 0 or j < 0:
            continue
        e = _find(nptr, nrow, t_rows[u] // 6, t_cols[u] // 6)
        if e < 0:
            return False
        r = 0
        for p in range(t_rows[u] % 6):
            if red[t_rows[u] - t_rows[u] % 6 + p] >= 0:
                r += 1
        out[indptr[j] + eoff[e] + r] += t_vals[u]
    return True


@jit_callee
def _node_block(red, indptr, eoff, b, e):
    """``(base, L)``: the entry of (row dof 0 of the pair's row node, column dof 0 of node ``b``) for the node
    pair ``e`` and the stride between ``b``'s six columns (they hold the same rows: ``_expand``), ``b`` free."""
    j0 = red[6 * b]
    return indptr[j0] + eoff[e], indptr[j0 + 1] - indptr[j0]


@jit
def _add_products(node, Kq, Kl, w, red, nfree, indptr, eoff, nptr, nrow, out):
    """``out += sum_u w_u Kq_u Kl_u^T`` on the held pattern, ``Kq``, ``Kl`` ``(m, 6 k)`` over the nodes ``node``
    ``(m, k)`` (rank-one blocks; held rows and columns dropped), each entry's terms added row after row.  A
    group's consecutive rows (the same nodes) share one pass over its blocks (its node pairs found once); a
    group with a repeated node, row by row (``_row_products``).  Returns False (``out`` partly changed) if a
    node pair with an entry has no place in the pattern."""
    k, m = node.shape[1], node.shape[0]
    place = np.empty((k, k), dtype=np.int64)
    u = 0
    while u < m:
        end = u + 1
        while end < m and _same_nodes(node, u, end):
            end += 1
        for t in range(k):
            for s in range(k):
                place[s, t] = _find(nptr, nrow, node[u, s], node[u, t])
        if _repeated(node, u):
            for v in range(u, end):
                if not _row_products(node, Kq, Kl, w, red, indptr, eoff, place, v, out):
                    return False
            u = end
            continue
        for t in range(k):
            b = node[u, t]
            if nfree[b] == 0:
                continue
            for s in range(k):
                a = node[u, s]
                e = place[s, t]
                if nfree[a] == 0:
                    continue
                if e >= 0 and nfree[a] == 6 and nfree[b] == 6:
                    base, L = _node_block(red, indptr, eoff, b, e)
                    for q in range(6):
                        col = base + q * L
                        for v in range(u, end):
                            c = w[v] * Kl[v, 6 * t + q]
                            if w[v] == 0.0 or c == 0.0:
                                continue
                            for p in range(6):
                                out[col + p] += Kq[v, 6 * s + p] * c
                    continue
                for q in range(6):
                    j = red[6 * b + q]
                    if j < 0:
                        continue
                    for v in range(u, end):
                        c = w[v] * Kl[v, 6 * t + q]
                        if w[v] == 0.0 or c == 0.0:
                            continue
                        if not _column_terms(Kq, v, s, a, c, red, indptr, eoff, j, e, out):
                            return False
        u = end
    return True


@jit_callee
def _column_terms(Kq, v, s, a, c, red, indptr, eoff, j, e, out):
    """``out`` += ``Kq[v, 6 s + p] c`` over the free dofs ``p`` of node ``a`` (the ``s``-th of row ``v``), in column
    ``j`` at the node pair ``e``'s entries; ``e < 0`` (no place): False if a term is not zero."""
    r = 0
    for p in range(6):
        if red[6 * a + p] >= 0:
            x = Kq[v, 6 * s + p] * c
            if e < 0:
                if x != 0.0:
                    return False
            else:
                out[indptr[j] + eoff[e] + r] += x
            r += 1
    return True


@jit_callee
def _same_nodes(node, u, v):
    """Whether rows ``u`` and ``v`` of ``node`` ``(m, k)`` are over the same nodes."""
    for t in range(node.shape[1]):
        if node[u, t] != node[v, t]:
            return False
    return True


@jit_callee
def _repeated(node, u):
    """Whether row ``u`` of ``node`` ``(m, k)`` names a node twice."""
    for t in range(node.shape[1]):
        for s in range(t):
            if node[u, s] == node[u, t]:
                return True
    return False


@jit_callee
def _row_products(node, Kq, Kl, w, red, indptr, eoff, place, u, out):
    """``out += w_u Kq_u Kl_u^T`` of the one row ``u`` (``_add_products``; ``place`` its node pairs' places)."""
    if w[u] == 0.0:
        return True
    k = node.shape[1]
    for t in range(k):
        b = node[u, t]
        for s in range(k):
            a = node[u, s]
            e = place[s, t]
            for q in range(6):
                j = red[6 * b + q]
                c = w[u] * Kl[u, 6 * t + q]
                if j < 0 or c == 0.0:
                    continue
                if not _column_terms(Kq, u, s, a, c, red, indptr, eoff, j, e, out):
                    return False
    return True


def _pair_keys(node, vals, nfree, n):
    """Sorted unique keys ``b n + a`` of the node pairs of the blocks ``vals`` ``(m, 6 k, 6 k)`` over ``node``
    ``(m, k)`` whose both nodes have free dofs and whose 6 x 6 block is not all zero."""
    m, k = node.shape
    a = np.repeat(node, k, axis=1).ravel()
    b = np.tile(node, (1, k)).ravel()
    nonzero = (vals.reshape(m, k, 6, k, 6) != 0.0).any(axis=(2, 4)).ravel()
    keep = (nfree[a] > 0) & (nfree[b] > 0) & nonzero
    return np.unique(b[keep].astype(np.int64) * n + a[keep])


class HeldPattern:
    """The element pattern ``(el_indptr, el_indices)`` (reduced, ``n_free``; ``red`` ``(6 n,)`` the
    reduction, ``-1`` for held unknowns) plus 6 x 6 blocks over the reserved node pairs ``keys``
    (``b n + a``, sorted) as one CSC pattern kept while the contact blocks stay inside it (see the
    module).  ``matrix`` gives the tangent with explicit zeros; ``covers`` tells whether blocks fit."""

    def __init__(self, red, n_free, el_indptr, el_indices, keys=None, el_keys=None):
        self.base = (red, el_indptr, el_indices)
        red = np.ascontiguousarray(red, dtype=np.int64)
        n = len(red) // 6
        self.n_nodes, self.n_free, self.red = n, n_free, red
        free_dofs = np.flatnonzero(red >= 0)
        node_of = free_dofs // 6
        self.nfree = np.bincount(node_of, minlength=n).astype(np.int64)
        first = np.zeros(n, dtype=np.int64)
        first[node_of[::-1]] = np.arange(n_free)[::-1]          # the first free dof of each node
        if el_keys is None:            # the element pattern's node pairs (kept: ``grown`` passes them on)
            if LINEAR_KEYS:
                el_keys = node_keys.element_keys(el_indptr, el_indices, node_of, n)
            else:
                el_col = np.repeat(np.arange(n_free), np.diff(el_indptr))
                el_keys = np.unique(node_of[el_col] * n + node_of[el_indices])
        self.el_keys = el_keys
        if keys is None:
            self.keys = np.zeros(0, dtype=np.int64)
        else:
            self.keys = node_keys.difference(keys, el_keys) if LINEAR_KEYS else np.setdiff1d(keys, el_keys)
        allk = node_keys.union(el_keys, self.keys) if LINEAR_KEYS else np.union1d(el_keys, self.keys)
        self.nptr = np.searchsorted(allk // n, np.arange(n + 1)).astype(np.int64)
        self.nrow = (allk % n).astype(np.int64)
        self.eoff = np.empty(len(allk), dtype=np.int64)
        col_len = np.bincount(allk // n, weights=self.nfree[self.nrow], minlength=n).astype(np.int64)
        size = int((col_len * self.nfree).sum())
        small = size < np.iinfo(np.int32).max      # int32 while they fit (half the memory), written as such
        self.indptr = np.empty(n_free + 1, dtype=np.int32 if small else np.int64)
        self.indices = np.empty(size, dtype=np.int32)
        _expand(self.nptr, self.nrow, self.nfree, first, self.indptr, self.indices, self.eoff)
        self.el_pos = np.empty(len(el_indices), dtype=np.int32 if small else np.int64)
        missing = _element_positions(np.asarray(el_indptr, dtype=np.int64), el_indices, node_of, first, self.nptr,
                                     self.nrow, self.eoff, self.indptr, self.el_pos)
        if missing:
            raise ValueError(f"HeldPattern: {missing} element entries outside whole node blocks")

    @property
    def nnz(self):
        return len(self.indices)

    def same_base(self, base):
        """Whether it was built on these arrays ``(red, el_indptr, el_indices)`` (the same objects)."""
        return all(a is b for a, b in zip(base, self.base))

    def covers(self, node, vals):
        """Whether the pattern holds the blocks ``vals`` ``(m, 6 k, 6 k)`` over ``node`` ``(m, k)``: every node
        pair of theirs, except those whose 6 x 6 block is all zero (a contact point without stiffness)."""
        return _uncovered(node, vals, self.nfree, self.nptr, self.nrow) == 0

    def add_products(self, data, node, Kq, Kl, w):
        """Add the rank-one blocks ``w_u Kq_u Kl_u^T`` (``Kq``, ``Kl`` ``(m, 6 k)`` over the nodes ``node`` ``(m, k)``,
        full numbering; ``w`` ``(m,)``) to the values ``data`` of a matrix on this pattern, in place: no second
        assembly of a tangent that only changes there (``nonlinear.augmented``).  False where a block leaves the
        pattern (``data`` is then partly changed)."""
        return bool(_add_products(np.ascontiguousarray(node, dtype=np.int64), np.ascontiguousarray(Kq),
                                  np.ascontiguousarray(Kl), np.ascontiguousarray(w, dtype=float), self.red,
                                  self.nfree, self.indptr, self.eoff, self.nptr, self.nrow, data))

    def grown(self, node, vals):
        """The pattern holding the node pairs of the blocks ``vals`` over ``node`` too (``covers``): this reserve
        plus theirs, or theirs alone when fewer than ``RESET_SHARE`` of the reserve's pairs are among them (a
        stale reserve is dropped)."""
        if LINEAR_KEYS:
            new = node_keys.block_keys(node, vals, self.nfree, self.n_nodes)
            used = node_keys.common(self.keys, new)
            keys = node_keys.union(self.keys, new) if used >= RESET_SHARE * len(self.keys) else new
        else:
            new = _pair_keys(node, vals, self.nfree, self.n_nodes)
            used = np.isin(self.keys, new, assume_unique=True).sum() if len(self.keys) else 0
            keys = np.union1d(self.keys, new) if used >= RESET_SHARE * len(self.keys) else new
        return HeldPattern(self.base[0], self.n_free, self.base[1], self.base[2], keys=keys, el_keys=self.el_keys)

    @classmethod
    def of_blocks(cls, red, n_free, el_indptr, el_indices, node, vals):
        """``HeldPattern(red, n_free, el_indptr, el_indices).grown(node, vals)`` where the blocks leave the element
        pattern, else the element pattern alone: the same arrays, without building the element pattern's own
        held pattern first (a new contact pattern's cost, ``System.matrix``)."""
        nfree = np.bincount(np.flatnonzero(np.asarray(red) >= 0) // 6, minlength=len(red) // 6)
        keys = node_keys.block_keys(node, vals, nfree, len(red) // 6)
        return cls(red, n_free, el_indptr, el_indices, keys=keys)

    def matrix(self, el_data, node=None, vals=None, tail=None):
        """CSC ``(n_free, n_free)`` of the element values ``el_data`` (element pattern order) plus the blocks
        ``vals`` ``(m, 6 k, 6 k)`` over ``node`` ``(m, k)`` (``covers``) and the ``tail`` COO
        ``(rows, cols, vals)`` (full numbering; node pairs in the pattern), explicit zeros kept.  Its ``indices``
        and ``indptr`` are the pattern's own arrays, not copies (one copy less of the largest index array: 0.15 GB
        on the 0.6 m rope); nothing changes them in place (canonical: scipy does not sort or sum them again)."""
        if node is None:
            node, vals = np.zeros((0, 1), dtype=np.int64), np.zeros((0, 6, 6))
        t = tail if tail is not None else (np.zeros(0, dtype=np.int64),) * 2 + (np.zeros(0),)
        data = np.empty(self.nnz)
        ok = _values(el_data, self.el_pos, node, vals, self.red, self.nfree, self.indptr, self.eoff, self.nptr,
                     self.nrow, np.asarray(t[0], dtype=np.int64), np.asarray(t[1], dtype=np.int64),
                     np.asarray(t[2], dtype=float), data)
        if not ok:
            raise ValueError("HeldPattern: a block or tail entry outside the pattern (see covers)")
        return canonical_csc(data, self.indices, self.indptr, self.n_free)
