"""The Newton matrix bordered with multiplier unknowns, ``[[K, K_ql], [K_lq, K_ll]]``, straight into CSC.

``Bordered.matrix`` keeps the pattern (indices, indptr and where each block's entries go) while the tangent's
pattern and the multiplier groups' rows hold (a Newton step of exact stick keeps both), so an iteration only
places values: no COO/CSC constructions and no ``sp.bmat`` (about 1.2 ms an iteration on the twisted pair,
issue 26).  Duplicate entries (a group's padded slots, joined nodes) are summed in their COO order.  ``bmat``
is its numpy/scipy oracle (the former ``Problem.bordered``): the same pattern and values to round-off.
"""
import numpy as np
import scipy.sparse as sp

from .._jit import jit
from ..assembly.csc import canonical_csc

__all__ = ["Bordered", "bmat", "use_bmat", "IDLE"]

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
        """The pattern of ``matrix``.  ``K``'s entries (canonical: sorted, no duplicates) and the border's (a row or a
        column of a multiplier: never at one of ``K``'s) are merged by their sorted keys; only the border's are
        sorted and made unique (``_build_unique``: the same pattern by one ``np.unique`` over all the entries)."""
        g = rows_red.shape[0]
        N = nf + c * g
        rb, cb, iq, il = _coo(rows_red, nf, c)
        kc = np.repeat(np.arange(nf, dtype=np.int64), np.diff(K.indptr))
        kkeys = kc * N + K.indices.astype(np.int64)
        ubk, inv = np.unique(cb * N + rb, return_inverse=True)
        inv = inv.ravel()
        posK, ub = np.empty(len(kkeys), dtype=np.int64), np.empty(len(ubk), dtype=np.int64)
        u = np.empty(len(kkeys) + len(ubk), dtype=np.int64)
        _merge(kkeys, ubk, posK, ub, u)
        self._store(K, rows_red, nf, c, g, N, u, posK, ub, inv, iq, il)

    def _build_unique(self, K, rows_red, nf, c):
        """``_build`` by one ``np.unique`` over every entry (its oracle: the same pattern)."""
        g = rows_red.shape[0]
        N = nf + c * g
        rb, cb, iq, il = _coo(rows_red, nf, c)
        kc = np.repeat(np.arange(nf, dtype=np.int64), np.diff(K.indptr))
        rows = np.concatenate([K.indices.astype(np.int64), rb])
        cols = np.concatenate([kc, cb])
        u, pos = np.unique(cols * N + rows, return_inverse=True)
        pos = pos.ravel()
        nk = K.nnz
        ub, inv = np.unique(pos[nk:], return_inverse=True)      # the border's entries (apart from K's)
        self._store(K, rows_red, nf, c, g, N, u, pos[:nk], ub, inv.ravel(), iq, il)

    def _store(self, K, rows_red, nf, c, g, N, u, posK, ub, inv, iq, il):
        """Keep the pattern: ``u`` the sorted keys ``col N + row`` of the entries, ``posK`` where ``K``'s go, ``ub``
        where the border's distinct ones go and ``inv`` which of them each border entry (``_coo``'s order) is."""
        indptr, indices = np.zeros(N + 1, dtype=np.int32), np.empty(len(u), dtype=np.int32)
        _split_keys(u, N, indptr, indices)
        nlq = len(iq) + len(il)
        lq = inv[len(iq):nlq]
        ulq, lq_inv = np.unique(lq, return_inverse=True)
        self._p = dict(nf=nf, c=c, indptr_out=indptr, indices=indices, nnz=len(u), N=N,
                       posK=posK, border=ub, inv=inv, iq=iq, il=il,
                       lq_rows=indices[ub[ulq]].astype(np.int64) - nf, lq_entries=ub[ulq],
                       ll=ub[inv[nlq:]].reshape(g, c, c), n_border=len(inv),
                       indptr=K.indptr, kindices=K.indices, rows_red=rows_red.copy())
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
        data = np.empty(p["nnz"])
        data[p["posK"]] = K.data
        vals = np.concatenate([np.ravel(Kql)[p["iq"]], np.ravel(Klq)[p["il"]], np.ravel(Kll)])
        data[p["border"]] = np.bincount(p["inv"], weights=vals, minlength=len(p["border"]))
        rc = -np.ravel(C).copy()
        # a multiplier direction no free unknown can slip in: its row is the traction's component itself (bmat)
        g = len(rows_red)
        free_row = np.sqrt(np.bincount(p["lq_rows"], weights=data[p["lq_entries"]] ** 2, minlength=c * g))
        own = np.linalg.norm(Kll, axis=2).ravel()
        idle = (free_row <= IDLE * max(free_row.max(initial=0.0), 1e-300)) & \
            (own <= IDLE * max(own.max(initial=0.0), 1e-300))
        if idle.any():
            gg, ii = np.divmod(np.flatnonzero(idle), c)
            data[p["ll"][gg, ii]] = R[gg, ii]
            rc[idle] = -np.einsum("gj,gj->g", R[gg, ii], Lam[gg])
        return canonical_csc(data, p["indices"], p["indptr_out"], p["N"]), rc


@jit
def _merge(a, b, pa, pb, u):
    """Merge the sorted, disjoint keys ``a`` and ``b`` into ``u``; ``pa``, ``pb``: where each of them goes (the
    positions ``np.arange(len(a)) + np.searchsorted(b, a)`` and alike, in one linear pass: the two searches took 0.12 ms
    of a build's 0.26 on the main job's bordered tangents)."""
    i = j = 0
    n, m = len(a), len(b)
    for k in range(n + m):
        if j >= m or (i < n and a[i] < b[j]):
            pa[i] = k
            u[k] = a[i]
            i += 1
        else:
            pb[j] = k
            u[k] = b[j]
            j += 1


@jit
def _split_keys(u, N, indptr, indices):
    """The CSC pattern of the sorted keys ``u`` (``col N + row``): ``indices`` the rows ``u % N`` and ``indptr``
    ``(N + 1,)`` (zeros in) the columns' starts, in one pass (``np.bincount(u // N)`` and ``u % N``: 0.08 ms of a
    build's 0.22 on the main job's bordered tangents, issue 30 session 9)."""
    for k in range(len(u)):
        col = u[k] // N
        indices[k] = u[k] - col * N
        indptr[col + 1] += 1
    for j in range(N):
        indptr[j + 1] += indptr[j]


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
