"""The Newton matrix bordered with multiplier unknowns, ``[[K, K_ql], [K_lq, K_ll]]``, straight into CSC.

``Bordered.matrix`` keeps the pattern (indices, indptr and where each block's entries go) while the tangent's
pattern and the multiplier groups' rows hold (a Newton step of exact stick keeps both), so an iteration only
places values: no COO/CSC constructions and no ``sp.bmat`` (about 1.2 ms an iteration on the twisted pair,
issue 26).  Duplicate entries (a group's padded slots, joined nodes) are summed in their COO order.  The pattern
is built and the values placed by compiled passes (``_border_counts``, ``_border_fill``, ``_border_values``: about
0.26 -> 0.05 ms a build on the main job, whose condensed border changes most iterations, issue 30 session 16);
``merged`` is their numpy oracle (the pattern by ``np.unique``, the values by ``np.bincount``: the same bits), ``bmat``
the numpy/scipy oracle (the former ``Problem.bordered``): the same pattern and values to round-off.
"""
import numpy as np
import scipy.sparse as sp

from .._jit import jit
from ..assembly.csc import canonical_csc

__all__ = ["Bordered", "bmat", "merged", "use_bmat", "IDLE"]

IDLE = 1e-12        # a multiplier row with no free coupling and no own entry below this share of the largest


def _coo(rows_red, nf, c=3):
    """COO rows, cols ``(e,)`` of the border blocks in the order ``K_ql`` ``(g, k6, c)``, ``K_lq`` ``(g, c, k6)``,
    ``K_ll`` ``(g, c, c)`` (kept entries: free rows) and the flat indices of the kept entries of the first two."""
    g, k6 = rows_red.shape
    gi = nf + np.arange(c * g).reshape(g, c)
    rq = np.broadcast_to(rows_red[:, :, None], (g, k6, c)).ravel()
    cq = np.broadcast_to(gi[:, None, :], (g, k6, c)).ravel()
    iq = np.flatnonzero(rq >= 0)
    rl = np.broadcast_to(gi[:, :, None], (g, c, k6)).ravel()
    cl = np.broadcast_to(rows_red[:, None, :], (g, c, k6)).ravel()
    il = np.flatnonzero(cl >= 0)
    rll = np.repeat(gi, c, axis=1).ravel()
    cll = np.tile(gi, (1, c)).ravel()
    return (np.concatenate([rq[iq], rl[il], rll]), np.concatenate([cq[iq], cl[il], cll]), iq, il)


_ORACLE = [False]


def use_bmat(flag=True):
    """``Bordered.matrix`` by the oracle ``bmat`` (benchmarks: the cost before the kept pattern)."""
    _ORACLE[0] = bool(flag)


class Bordered:
    """Assembles bordered matrices of one Newton loop, keeping the last pattern (see the module)."""

    def __init__(self):
        self._p = None
        self.builds = 0          # patterns built (tests, benchmarks)

    def _same(self, K, rows_red, nf, c):
        p = self._p
        if p is None or p["nf"] != nf or p["c"] != c or p["rows_red"].shape != rows_red.shape:
            return False
        for a, b in ((p["indptr"], K.indptr), (p["kindices"], K.indices), (p["rows_red"], rows_red)):
            if a is not b and not np.array_equal(a, b):
                return False
        return True

    def _build(self, K, rows_red, nf, c):
        """The pattern of ``matrix`` (compiled: ``_border_counts``, ``_border_fill``): the output's ``indptr``,
        ``indices``, where ``K``'s entries go (``posK``) and where each border entry goes (``bpos``, ``_coo``'s
        order: ``K_ql``'s kept entries, ``K_lq``'s, then ``K_ll``'s), duplicates at one place."""
        g, k6 = rows_red.shape
        N = nf + c * g
        kptr = np.asarray(K.indptr, dtype=np.int64)
        rows_red = rows_red.copy()
        rr = np.ascontiguousarray(rows_red, dtype=np.int64)
        gu, ng, rank = np.empty((g, k6), dtype=np.int64), np.empty(g, dtype=np.int64), np.empty((g, k6), dtype=np.int64)
        indptr = np.zeros(N + 1, dtype=np.int32)
        nnz = _border_counts(kptr, rr, nf, c, gu, ng, rank, indptr)
        indices = np.empty(nnz, dtype=np.int32)
        posK = np.empty(K.nnz, dtype=np.int64)
        bpos = np.empty(2 * c * int((rr >= 0).sum()) + g * c * c, dtype=np.int64)
        _border_fill(kptr, K.indices, rr, nf, c, gu, ng, rank, indptr, indices, posK, bpos)
        self._p = dict(nf=nf, c=c, indptr_out=indptr, indices=indices, nnz=nnz, N=N, posK=posK, bpos=bpos,
                       ll=bpos[len(bpos) - g * c * c:].reshape(g, c, c), kptr=kptr,
                       indptr=K.indptr, kindices=K.indices, rows_red=rows_red, rr=rr)
        self.builds += 1

    def matrix(self, K, rows_red, Kql, Klq, Kll, R, Lam, C):
        """``(A, rc)``: the bordered CSC ``A`` ``(nf + c g,)^2`` and the multipliers' right-hand side ``-C`` with
        the idle rows (``bmat``) set; ``K`` canonical CSC ``(nf, nf)``, ``rows_red`` ``(g, k6)`` the free row of
        each group slot (``-1``: held), ``Kql`` ``(g, k6, c)``, ``Klq`` ``(g, c, k6)``, ``Kll``, ``R`` ``(g, c, c)``,
        ``Lam``, ``C`` ``(g, c)`` (``c`` = 3: every component; 1: the kept ones of ``condense``, one per row)."""
        if _ORACLE[0]:
            return bmat(K, rows_red, Kql, Klq, Kll, R, Lam, C)
        nf = K.shape[0]
        rows_red = np.asarray(rows_red)
        K = K if K.has_canonical_format else K.copy()
        K.sum_duplicates()
        c = Kll.shape[1]
        if not self._same(K, rows_red, nf, c):
            self._build(K, rows_red, nf, c)
        p = self._p
        g = len(rows_red)
        data = np.empty(p["nnz"])
        free_row = np.zeros(c * g)
        Kql, Klq, Kll = (np.ascontiguousarray(x, dtype=float) for x in (Kql, Klq, Kll))
        _border_values(K.data, p["posK"], Kql, Klq, Kll, p["rr"], p["bpos"], p["kptr"], p["indptr_out"], p["indices"],
                       data, free_row)
        return self._finish(data, np.sqrt(free_row), p, Kll, R, Lam, C)

    @staticmethod
    def _finish(data, free_row, p, Kll, R, Lam, C):
        """``(A, rc)`` of ``matrix`` from the placed values ``data`` and the border rows' norms ``free_row``
        ``(c g,)`` on free columns: a multiplier direction no free unknown can slip in takes the traction's
        component itself as its row (``bmat``)."""
        c = Kll.shape[1]
        rc = -np.ravel(C).copy()
        own = np.linalg.norm(Kll, axis=2).ravel()
        idle = (free_row <= IDLE * max(free_row.max(initial=0.0), 1e-300)) & \
            (own <= IDLE * max(own.max(initial=0.0), 1e-300))
        if idle.any():
            gg, ii = np.divmod(np.flatnonzero(idle), c)
            data[p["ll"][gg, ii]] = R[gg, ii]
            rc[idle] = -np.einsum("gj,gj->g", R[gg, ii], Lam[gg])
        return canonical_csc(data, p["indices"], p["indptr_out"], p["N"]), rc


@jit
def _border_counts(kptr, rows_red, nf, c, gu, ng, rank, indptr):
    """First pass of ``Bordered._build``: per group ``i`` its distinct free rows ``gu[i, :ng[i]]`` (sorted) and the
    rank of each slot's row among them (``rank`` ``(g, k6)``, ``-1``: held), and the output's column pointers
    ``indptr`` ``(nf + c g + 1,)`` (zeros in): a column ``j < nf`` holds ``K``'s rows, then ``c`` multiplier rows per
    group with a slot on ``j``; a multiplier column its group's free rows, then its ``c`` multiplier rows.  Returns
    the number of entries."""
    g, k6 = rows_red.shape
    for i in range(g):
        n = 0
        for a in range(k6):
            r = rows_red[i, a]
            if r < 0:
                continue
            x = 0
            while x < n and gu[i, x] < r:
                x += 1
            if x < n and gu[i, x] == r:
                continue
            for y in range(n, x, -1):
                gu[i, y] = gu[i, y - 1]
            gu[i, x] = r
            n += 1
        ng[i] = n
        for a in range(k6):
            r = rows_red[i, a]
            rank[i, a] = -1
            if r >= 0:
                x = 0
                while gu[i, x] != r:
                    x += 1
                rank[i, a] = x
        for x in range(n):
            indptr[gu[i, x] + 1] += c
        for jc in range(c):
            indptr[nf + c * i + jc + 1] = n + c
    for j in range(nf):
        indptr[j + 1] += kptr[j + 1] - kptr[j]
    for j in range(len(indptr) - 1):
        indptr[j + 1] += indptr[j]
    return indptr[len(indptr) - 1]


@jit
def _border_fill(kptr, kind, rows_red, nf, c, gu, ng, rank, indptr, indices, posK, bpos):
    """Second pass of ``Bordered._build`` (``_border_counts``'s arrays): the rows ``indices`` of every column (sorted:
    groups and components in order), ``K``'s entries' places ``posK`` and the border entries' ``bpos`` in ``_coo``'s
    order (``K_ql`` ``(g, k6, c)`` and ``K_lq`` ``(g, c, k6)`` on free slots, ``K_ll`` ``(g, c, c)``)."""
    g, k6 = rows_red.shape
    fill = np.empty(nf, dtype=np.int64)
    for j in range(nf):
        s0 = indptr[j]
        for s in range(kptr[j], kptr[j + 1]):
            indices[s0 + s - kptr[j]] = kind[s]
            posK[s] = s0 + s - kptr[j]
        fill[j] = s0 + kptr[j + 1] - kptr[j]
    lq = np.empty((g, k6, c), dtype=np.int64)          # K_lq's place of (group, distinct row, component)
    for i in range(g):
        for x in range(ng[i]):
            j = gu[i, x]
            for jc in range(c):
                indices[fill[j]] = nf + c * i + jc
                lq[i, x, jc] = fill[j]
                fill[j] += 1
        for jc in range(c):
            s0 = indptr[nf + c * i + jc]
            for x in range(ng[i]):
                indices[s0 + x] = gu[i, x]
            for r in range(c):
                indices[s0 + ng[i] + r] = nf + c * i + r
    e = 0
    for i in range(g):
        for a in range(k6):
            if rank[i, a] >= 0:
                for jc in range(c):
                    bpos[e] = indptr[nf + c * i + jc] + rank[i, a]
                    e += 1
    for i in range(g):
        for jc in range(c):
            for a in range(k6):
                if rank[i, a] >= 0:
                    bpos[e] = lq[i, rank[i, a], jc]
                    e += 1
    for i in range(g):
        for r in range(c):
            for jc in range(c):
                bpos[e] = indptr[nf + c * i + jc] + ng[i] + r
                e += 1


@jit
def _border_values(Kdata, posK, Kql, Klq, Kll, rows_red, bpos, kptr, indptr, indices, data, free_row):
    """Values of ``Bordered.matrix``: ``K``'s at ``posK``, each border place the sum of its entries in ``_coo``'s order
    (from zero, as ``np.bincount``), and ``free_row`` ``(c g,)`` (zeros in) the sums of squares of each multiplier row's
    entries on free columns, in the order of their places."""
    data[:] = 0.0
    for s in range(len(posK)):
        data[posK[s]] = Kdata[s]
    g, k6, c = Kql.shape
    e = 0
    for i in range(g):
        for a in range(k6):
            if rows_red[i, a] >= 0:
                for jc in range(c):
                    data[bpos[e]] += Kql[i, a, jc]
                    e += 1
    for i in range(g):
        for jc in range(c):
            for a in range(k6):
                if rows_red[i, a] >= 0:
                    data[bpos[e]] += Klq[i, jc, a]
                    e += 1
    for i in range(g):
        for r in range(c):
            for jc in range(c):
                data[bpos[e]] += Kll[i, r, jc]
                e += 1
    nf = len(kptr) - 1
    for j in range(nf):
        for s in range(indptr[j] + kptr[j + 1] - kptr[j], indptr[j + 1]):
            free_row[indices[s] - nf] += data[s] * data[s]


def merged(K, rows_red, Kql, Klq, Kll, R, Lam, C):
    """``Bordered.matrix`` by numpy (the oracle of its compiled passes): the pattern by ``np.unique`` over every
    entry, the border's values by ``np.bincount`` in ``_coo``'s order, the border rows' norms by ``np.bincount`` over
    their places in order.  The same bits."""
    nf = K.shape[0]
    rows_red = np.asarray(rows_red)
    K = sp.csc_matrix(K)
    K.sum_duplicates()
    g = rows_red.shape[0]
    c = Kll.shape[1]
    N = nf + c * g
    rb, cb, iq, il = _coo(rows_red, nf, c)
    kc = np.repeat(np.arange(nf, dtype=np.int64), np.diff(K.indptr))
    u, pos = np.unique(np.concatenate([kc, cb]) * N + np.concatenate([K.indices.astype(np.int64), rb]),
                       return_inverse=True)
    pos = pos.ravel()
    border, inv = np.unique(pos[K.nnz:], return_inverse=True)
    inv = inv.ravel()
    indptr = np.zeros(N + 1, dtype=np.int32)
    np.cumsum(np.bincount(u // N, minlength=N), out=indptr[1:])
    indices = (u % N).astype(np.int32)
    nlq = len(iq) + len(il)
    lq = np.unique(inv[len(iq):nlq])
    data = np.empty(len(u))
    data[pos[:K.nnz]] = K.data
    vals = np.concatenate([np.ravel(Kql)[iq], np.ravel(Klq)[il], np.ravel(Kll)])
    data[border] = np.bincount(inv, weights=vals, minlength=len(border))
    free_row = np.sqrt(np.bincount(indices[border[lq]].astype(np.int64) - nf, weights=data[border[lq]] ** 2,
                                   minlength=c * g))
    p = dict(indices=indices, indptr_out=indptr, N=N, ll=border[inv[nlq:]].reshape(g, c, c))
    return Bordered._finish(data, free_row, p, Kll, R, Lam, C)


def bmat(K, rows_red, Kql, Klq, Kll, R, Lam, C):
    """``Bordered.matrix`` by scipy's COO/CSC constructors and ``sp.bmat`` (the oracle)."""
    nf = K.shape[0]
    g, k6 = rows_red.shape
    c = Kll.shape[1]
    gi = np.arange(c * g).reshape(g, c)
    rows = np.broadcast_to(rows_red[:, :, None], (g, k6, c))
    cols = np.broadcast_to(gi[:, None, :], (g, k6, c))
    keep = rows >= 0
    Bql = sp.csc_matrix((Kql[keep], (rows[keep], cols[keep])), shape=(nf, c * g))
    rl = np.broadcast_to(gi[:, :, None], (g, c, k6))
    cl = np.broadcast_to(rows_red[:, None, :], (g, c, k6))
    keep = cl >= 0
    Blq = sp.csc_matrix((Klq[keep], (rl[keep], cl[keep])), shape=(c * g, nf))
    rc = -C.ravel()
    free_row = np.sqrt(np.asarray(Blq.multiply(Blq).sum(axis=1)).ravel())
    own = np.linalg.norm(Kll, axis=2).ravel()
    idle = (free_row <= IDLE * max(free_row.max(initial=0.0), 1e-300)) & \
        (own <= IDLE * max(own.max(initial=0.0), 1e-300))
    if idle.any():
        gg, ii = np.divmod(np.flatnonzero(idle), c)
        Kll = Kll.copy()
        Kll[gg, ii] = R[gg, ii]
        rc[idle] = -np.einsum("gj,gj->g", R[gg, ii], Lam[gg])
    Bll = sp.csc_matrix((Kll.ravel(), (np.repeat(gi, c, axis=1).ravel(), np.tile(gi, (1, c)).ravel())),
                        shape=(c * g, c * g))
    return sp.bmat([[K, Bql], [Blq, Bll]], format="csc"), rc
