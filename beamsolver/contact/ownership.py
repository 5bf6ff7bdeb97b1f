"""Compiled ownership of the slave Gauss points: ``rules.owners`` in one pass (no sorts of all rows).

``gauss_owners`` takes the projected rows of ``projection.gauss_projections`` and returns the
rows ``rules.owners`` chooses among the accepted ones (``rules.xi_range``, finite distance), in
the same order (by key).  The rows are bucketed by slave element (a counting sort, stable), each
bucket's few rows sorted by key in place; per key the owner is the least of ``(not tie, not known,
xi2, dist, row)`` among the rows inside their element, else among those on an extension, where
``tie`` compares the distance with the least of that level (``rules.OWNER_TIE``) and ``known``
(the owner of the last evaluation, a binary search) is looked up only where two rows tie.
"""
import numpy as np

from .._jit import jit, jit_callee
from .rules import OWNER_TIE, XI_OVERHANG
from .search import XI_TOL

__all__ = ["gauss_owners", "gauss_record"]


@jit_callee
def _known(sorted_ids, x):
    """``x`` in the sorted array ``sorted_ids`` (binary search)."""
    lo, hi = 0, len(sorted_ids)
    while lo < hi:
        mid = (lo + hi) // 2
        if sorted_ids[mid] < x:
            lo = mid + 1
        else:
            hi = mid
    return lo < len(sorted_ids) and sorted_ids[lo] == x


@jit
def _owners(base, n_el, max_gp, n_beams, pair, e_pair, m_pair, g, xi2, dist, first, last, beam, radius, prev, out,
            out_key, tied):
    n = len(g)
    key = np.empty(n, dtype=np.int64)
    start = np.zeros(n_el + 1, dtype=np.int64)
    e, m = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    for r in range(n):
        e[r], m[r] = e_pair[pair[r]], m_pair[pair[r]]
    n_ok = 0
    for r in range(n):
        lo = -XI_TOL if first[m[r]] else -XI_OVERHANG
        hi = 1.0 + XI_TOL if last[m[r]] else 1.0 + XI_OVERHANG
        if xi2[r] >= lo and xi2[r] <= hi and np.isfinite(dist[r]):
            key[r] = ((base + e[r]) * max_gp + g[r]) * n_beams + beam[m[r]]
            start[e[r] + 1] += 1
            n_ok += 1
        else:
            key[r] = -1
    for j in range(n_el):
        start[j + 1] += start[j]
    rows = np.empty(n_ok, dtype=np.int64)
    fill = start[:-1].copy()
    for r in range(n):
        if key[r] >= 0:
            rows[fill[e[r]]] = r
            fill[e[r]] += 1
    n_out = 0
    for j in range(n_el):
        a, b = start[j], start[j + 1]
        for i in range(a + 1, b):          # insertion sort by key, stable
            r = rows[i]
            p = i
            while p > a and key[rows[p - 1]] > key[r]:
                rows[p] = rows[p - 1]
                p -= 1
            rows[p] = r
        i = a
        while i < b:
            q = i
            inside = False
            while q < b and key[rows[q]] == key[rows[i]]:
                x = xi2[rows[q]]
                inside = inside or not (x < -XI_TOL or x > 1.0 + XI_TOL)
                q += 1
            # the level chosen (inside over an extension), its least distance and ties
            least = np.inf
            for p in range(i, q):
                r = rows[p]
                if (not (xi2[r] < -XI_TOL or xi2[r] > 1.0 + XI_TOL)) == inside:
                    least = min(least, dist[r])
            n_tie = 0
            best = -1
            for p in range(i, q):
                r = rows[p]
                if (not (xi2[r] < -XI_TOL or xi2[r] > 1.0 + XI_TOL)) == inside:
                    if dist[r] <= least + OWNER_TIE * (radius[e[r]] + radius[m[r]]):
                        n_tie += 1
                        if best < 0:
                            best = r
            if n_tie > 1:
                best = -1
                best_known = False
                for p in range(i, q):
                    r = rows[p]
                    if (not (xi2[r] < -XI_TOL or xi2[r] > 1.0 + XI_TOL)) != inside:
                        continue
                    if not dist[r] <= least + OWNER_TIE * (radius[e[r]] + radius[m[r]]):
                        continue
                    kn = _known(prev, key[r] * n_el + m[r])
                    if best >= 0 and kn == best_known and xi2[r] == xi2[best] and dist[r] == dist[best]:
                        tied[0] = True          # equal rows: the first one is chosen
                    if best < 0 or (kn and not best_known) or (kn == best_known and (
                            xi2[r] < xi2[best] or (xi2[r] == xi2[best] and dist[r] < dist[best]))):
                        best, best_known = r, kn
            out[n_out] = best
            out_key[n_out] = key[best]
            n_out += 1
            i = q
    return n_out


def gauss_owners(decl, n_el, max_gp, n_beams, e, m, g, xi2, dist, first, last, beam, radius, prev, pair=None,
                 order=False):
    """Owners (``rules.owners``) among the projected Gauss-point rows ``e``, ``m``, ``g``, ``xi2``, ``dist``
    ``(n,)`` of declaration ``decl``: accepted rows only (``rules.xi_range`` of the master: ``first``,
    ``last`` per element; finite distance), key ``((decl n_el + e) max_gp + g) n_beams + beam[m]``,
    section ``radius`` per element, ``prev``: sorted ``key * n_el + m`` of the last owners.  ``pair``
    ``(n,)``: if given, row ``r``'s elements are ``e[pair[r]]``, ``m[pair[r]]`` (of element pairs).
    Returns the rows chosen, in key order, and their keys."""
    n = len(g)
    pair = np.arange(n) if pair is None else pair
    out, out_key = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    tied = np.zeros(1, dtype=bool)
    k = _owners(np.int64(decl) * n_el, int(n_el), int(max_gp), int(n_beams), pair, e, m, g, xi2, dist, first, last,
                beam, radius, prev, out, out_key, tied)
    return (out[:k], out_key[:k], bool(tied[0])) if order else (out[:k], out_key[:k])


@jit
def _fill(s, r, g, xi2, e, m, kind, xg, wg, length, enodes, radius, key, n_el, seg, lo, hi, xs, ws, o_kind, o_e, o_m,
          o_xi1, o_xi2, o_weight, o_gp, o_nodes, o_R1, o_R2, o_ids):
    for k in range(len(s)):
        row = s[k]
        c = r[row]
        ek, mk, gk = e[c], m[c], g[row]
        o_kind[k], o_e[k], o_m[k], o_gp[k] = kind[c], ek, mk, gk
        if seg is None:
            o_xi1[k], o_xi2[k] = xg[gk], xi2[row]
            o_weight[k] = wg[gk] * length[ek]
        elif seg[c]:        # a segment's points (``projection.segment_bounds``)
            o_xi1[k], o_xi2[k] = lo[c] + (hi[c] - lo[c]) * xs[gk], xi2[row]
            o_weight[k] = ((hi[c] - lo[c]) * ws[gk]) * length[ek]
        else:
            o_xi1[k], o_xi2[k] = xg[gk], xi2[row]
            o_weight[k] = wg[gk] * length[ek]
        o_nodes[k, 0], o_nodes[k, 1], o_nodes[k, 2], o_nodes[k, 3] = enodes[ek, 0], enodes[ek, 1], enodes[mk, 0], enodes[mk, 1]
        o_R1[k], o_R2[k] = radius[ek], radius[mk]
        o_ids[k] = key[k] * n_el + mk


def gauss_record(s, key, r, g, xi2, e, m, kind, xg, wg, length, enodes, radius, segments=None):
    """The fields of ``record.PairSet`` (but ``decl``) of the owners ``s`` (keys ``key``) among the projected
    rows ``r`` (element pair of each row), ``g``, ``xi2``, in one compiled pass, and the owner ids
    ``key * n_el + m``; element pairs' slave and master elements ``e``, ``m`` and ``kind``, Gauss points and
    weights ``xg``, ``wg`` on ``[0, 1]``, element ``length``, end nodes ``enodes``, section ``radius``.
    ``xi1 = xg[g]``, ``weight = wg[g] * length[e]``, ``nodes`` ``(P, 4)``: A1, B1, A2, B2.  ``segments``:
    ``(seg, lo, hi, xs, ws)``: per element pair (``projection.segment_bounds``) and the segments' Gauss points
    and weights: where ``seg``, ``xi1 = lo + (hi - lo) xs[g]``, ``weight = (hi - lo) ws[g] length[e]``."""
    n = len(s)
    f = dict(kind=np.empty(n, dtype=kind.dtype), e=np.empty(n, dtype=e.dtype), m=np.empty(n, dtype=m.dtype),
             xi1=np.empty(n), xi2=np.empty(n), weight=np.empty(n), gp=np.empty(n, dtype=g.dtype),
             nodes=np.empty((n, 4), dtype=enodes.dtype), R1=np.empty(n), R2=np.empty(n))
    ids = np.empty(n, dtype=np.int64)
    seg = lo = hi = xs = ws = None
    if segments is not None:
        seg, lo, hi, xs, ws = (np.ascontiguousarray(a) for a in segments)
    _fill(s, r, g, xi2, e, m, kind, xg, wg, length, enodes, radius, key, np.int64(len(enodes)), seg, lo, hi, xs, ws,
          f["kind"], f["e"], f["m"], f["xi1"], f["xi2"], f["weight"], f["gp"], f["nodes"], f["R1"], f["R2"], ids)
    return f, ids
