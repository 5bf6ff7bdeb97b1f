"""Contact search: broad phase over element bounding spheres, narrow phase by projection.

Broad phase: every element is bounded by a sphere around its mid-point of
radius ``|u|/2 + r + margin`` (``|u|`` is the element's arc length, ``r`` its
section radius); ``scipy.spatial.cKDTree`` finds the slave/master element pairs
whose spheres overlap (cost ~ n log n, trees rebuilt as the beams move).  Their order
(the distance matrix's) is the order of the point pairs and, between rows equal in every
criterion, of the owners; where neither can depend on it (no pair steeper than
``line_angle``, no such equal rows: ``ContactSystem._candidates``) the same pairs come from a
compiled sort and sweep along the axis of the largest spread (``sweep_phase``, ~4x cheaper).

Narrow phase, the choice rule per slave/master element pair (documented in
docs/guide/contact.md, tested on both sides of each switch):

1. angle between the mid-point tangents below ``line_angle`` (default 20 deg):
   **line contact**, the seed's slave-section-plane projection of each slave
   Gauss point (``(x_F - x_C) . e_C1 = 0``);
2. otherwise, solve for the closest points of the two centre lines; if the
   reduced Hessian of the distance, ``(H11 - H12^2 / H22) / |x1'|^2`` (equal to
   ``sin^2`` of the crossing angle for straight beams, and near 0 when the slave
   wraps around the master), is at least ``point_ratio`` (default
   ``sin^2 45 deg = 0.5``): one **point-to-point** pair at the closest points
   (isolated crossing);
3. else **orthogonal projection** of each slave Gauss point onto the master
   centre line (wrapping).  A slave element that would be a point pair but
   shares a node with an orthogonal one against the same master beam (a
   straight rope leaving a wrap tangentially) is projected orthogonally too:
   its closest point sits at its end, and a point pair there would switch on
   and off as the tangent point moves (``rules.extend_wrap``; only point pairs
   whose slave closest point lies within ``rules.WRAP_END`` of an end or past it:
   a crossing inside the slave element stays a point pair).

Projections are accepted on ``[0, 1]`` of the master element (so they continue
across element boundaries along the whole master beam); per slave Gauss point
and master beam the closest accepted projection is kept.  A line row whose slave
section plane cannot meet the master centre line there is not projected
(``projection.gauss_projections(window=)``): about 1.4 projections per slave point
whatever the element length (``benchmarks/search_scaling.py``).
"""
import numpy as np
from scipy.spatial import cKDTree

from .._jit import jit, jit_callee
from .projection import overlap, spheres

XI_TOL = 1e-9


def element_spheres(H, enodes, h, radii, margin, el):
    """Mid-points ``(n, 3)``, bounding radii ``(n,)`` and mid-point tangents ``(n, 3)`` of the elements
    ``el`` ``(n,)`` at poses ``H`` (``enodes``, twists ``h`` ``(n_el, 6)``, section ``radii``: all elements'),
    compiled (``projection.sphere_points``)."""
    mid, radius, tangent = np.empty((len(el), 3)), np.empty(len(el)), np.empty((len(el), 3))
    spheres(H, enodes, np.ascontiguousarray(h, dtype=float), radii, float(margin), np.ascontiguousarray(el), mid,
            radius, tangent)
    return mid, radius, tangent


def broad_phase(c_s, r_s, c_m, r_m):
    """Slave/master element index pairs whose bounding spheres overlap, in the distance matrix's order
    (the search runs it fused with the pair rule ``rules.apart``: ``broad_pairs``)."""
    if len(c_s) == 0 or len(c_m) == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    ts, tm = cKDTree(c_s), cKDTree(c_m)
    # "ndarray": the pairs of the "coo_matrix" output, in the same order, without building a matrix
    # (half the broad phase's time on small scenes)
    D = ts.sparse_distance_matrix(tm, float(r_s.max() + r_m.max()), output_type="ndarray")
    i, j = D["i"], D["j"]
    keep = np.empty(len(i), dtype=bool)
    overlap(c_s, r_s, c_m, r_m, i, j, keep)
    return i[keep], j[keep]


@jit
def _pairs_apart(i, j, c_s, r_s, c_m, r_m, t_s, t_m, slave_el, master_el, enodes, radius, e, m, cos, c2, reach):
    n = 0
    least = np.inf
    for k in range(len(i)):
        a, b = i[k], j[k]
        d0, d1, d2 = c_s[a, 0] - c_m[b, 0], c_s[a, 1] - c_m[b, 1], c_s[a, 2] - c_m[b, 2]
        if not np.sqrt((d0 * d0 + d1 * d1) + d2 * d2) <= r_s[a] + r_m[b]:       # ``overlap``
            continue
        ea, mb = slave_el[a], master_el[b]
        shared = False
        for x in range(enodes.shape[1]):                                       # ``rules.apart``
            for y in range(enodes.shape[1]):
                shared = shared or enodes[ea, x] == enodes[mb, y]
        if shared:
            continue
        e[n], m[n] = ea, mb
        cos[n] = t_s[a, 0] * t_m[b, 0] + t_s[a, 1] * t_m[b, 1] + t_s[a, 2] * t_m[b, 2]
        least = min(least, abs(cos[n])) if not np.isnan(cos[n]) else least
        for x in range(3):
            c2[n, x] = c_m[b, x]
        reach[n] = r_m[b] + radius[ea]
        n += 1
    return n, least


@jit_callee
def _argsort(key):
    """``np.argsort(key, kind="stable")`` of a 1-d float array without NaN: a bottom-up merge sort (numba's
    ``np.argsort`` compiles its generic quicksort, about a second of the first run)."""
    n = len(key)
    a, b = np.arange(n), np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            i, j = lo, mid
            for k in range(lo, hi):
                if i < mid and (j >= hi or key[a[i]] <= key[a[j]]):
                    b[k] = a[i]
                    i += 1
                else:
                    b[k] = a[j]
                    j += 1
        a, b = b, a
        width *= 2
    return a


@jit_callee
def _bisect(key, v, right):
    """``np.searchsorted(key, v, side="right" if right else "left")`` in a sorted float array."""
    lo, hi = 0, len(key)
    while lo < hi:
        mid = (lo + hi) // 2
        if key[mid] < v or (right and key[mid] == v):
            lo = mid + 1
        else:
            hi = mid
    return lo


SWEEP_MARGIN = 1e-9     # sweep: relative widening of its windows and of the distance-matrix radius checked
SWEEP_BUDGET = 32       # sweep: masters in the windows per slave element, at most (else the tree)


@jit
def _sweep(c_s, r_s, c_m, r_m, R, budget, i, j):
    """Pairs ``(a, b)`` of overlapping spheres (``overlap``'s test), slave-major, masters by their centre's
    coordinate along the axis of the largest spread; written to ``i``, ``j`` if they are long enough.
    Returns their number and whether the distance matrix of ``broad_phase`` could differ: a centre or
    radius not finite, or an overlapping pair within ``SWEEP_MARGIN`` of its radius ``R``; or whether
    the windows held more than ``budget`` masters in all (a scene not spread along one axis: a sheet,
    a ball, where the tree is cheaper; the pairs are then incomplete)."""
    edge = False
    for a in range(len(r_s)):
        edge = edge or not (np.isfinite(r_s[a]) and np.isfinite(c_s[a, 0]) and np.isfinite(c_s[a, 1])
                            and np.isfinite(c_s[a, 2]))
    for b in range(len(r_m)):
        edge = edge or not (np.isfinite(r_m[b]) and np.isfinite(c_m[b, 0]) and np.isfinite(c_m[b, 1])
                            and np.isfinite(c_m[b, 2]))
    if edge:
        return 0, True
    ax, spread = 0, -1.0
    for x in range(3):
        lo, hi = np.inf, -np.inf
        for b in range(len(r_m)):
            lo, hi = min(lo, c_m[b, x]), max(hi, c_m[b, x])
        if hi - lo > spread:
            ax, spread = x, hi - lo
    order = _argsort(c_m[:, ax])
    key = np.empty(len(order))
    for q in range(len(order)):
        key[q] = c_m[order[q], ax]
    r_max = 0.0
    for b in range(len(r_m)):
        r_max = max(r_max, r_m[b])
    n = 0
    seen = 0
    for a in range(len(r_s)):
        # |x_a - x_b| <= |c_a - c_b| <= r_a + r_b: the masters in a window of the sorted coordinate
        w = (r_s[a] + r_max) * (1.0 + SWEEP_MARGIN) + 1e-12 * abs(c_s[a, ax])     # round-off of x_a -+ w
        lo = _bisect(key, c_s[a, ax] - w, False)
        hi = _bisect(key, c_s[a, ax] + w, True)
        seen += hi - lo
        if seen > budget:
            return n, True
        for q in range(lo, hi):
            b = order[q]
            d0, d1, d2 = c_s[a, 0] - c_m[b, 0], c_s[a, 1] - c_m[b, 1], c_s[a, 2] - c_m[b, 2]
            d = np.sqrt((d0 * d0 + d1 * d1) + d2 * d2)
            if d <= r_s[a] + r_m[b]:
                edge = edge or d >= R * (1.0 - SWEEP_MARGIN)
                if n < len(i):
                    i[n], j[n] = a, b
                n += 1
    return n, edge


def sweep_phase(c_s, r_s, c_m, r_m, budget=SWEEP_BUDGET):
    """``broad_phase``'s pairs by a sort and sweep (compiled), in another order (slave-major); and whether
    they could differ from ``broad_phase``'s set (``_sweep``: not finite, a pair at its radius, or more
    than ``budget`` masters per slave element in the windows)."""
    i, j = np.empty(4 * len(c_s), dtype=np.intp), np.empty(4 * len(c_s), dtype=np.intp)
    if len(c_s) == 0 or len(c_m) == 0:
        return i[:0], j[:0], False
    R = float(r_s.max() + r_m.max())
    cap = int(budget * len(c_s))
    n, edge = _sweep(c_s, r_s, c_m, r_m, R, cap, i, j)
    if n > len(i) and not edge:
        i, j = np.empty(n, dtype=np.intp), np.empty(n, dtype=np.intp)
        n, edge = _sweep(c_s, r_s, c_m, r_m, R, cap, i, j)
    return i[:n], j[:n], edge


def broad_pairs(c_s, r_s, t_s, c_m, r_m, t_m, slave_el, master_el, enodes, radius, sweep=False):
    """``broad_phase`` and the pair rule ``rules.apart`` in one compiled pass over the distance
    matrix's pairs (in its order), with the data the later stages read of each pair kept.

    Spheres ``c_s``, ``r_s``, mid-point tangents ``t_s`` of the slave elements ``slave_el`` (``c_m``,
    ``r_m``, ``t_m``, ``master_el``: the masters'); ``enodes``: the end nodes ``rules.apart`` compares
    (joints merged), ``radius``: section radii, both ``(n_el, ...)``.  Returns, per element pair kept:
    slave and master elements ``e``, ``m``, the cosine of their mid-point tangents (``rules.crossing``),
    the master's sphere centre ``c2`` ``(n, 3)`` and ``reach``: its radius plus the slave's section
    radius (``projection.gauss_projections``' filter); and the least ``|cos|`` (inf without pairs; nan
    cosines left out), for ``rules.crossing``.

    ``sweep``: the pairs of ``sweep_phase`` (the same set, another order) instead of the distance
    matrix's; returns also whether that set could differ (then use the distance matrix)."""
    if sweep:
        i, j, edge = sweep_phase(c_s, r_s, c_m, r_m)
        return _apart(i, j, c_s, r_s, t_s, c_m, r_m, t_m, slave_el, master_el, enodes, radius) + (edge,)
    if len(c_s) == 0 or len(c_m) == 0:
        i = j = np.zeros(0, dtype=np.intp)
    else:
        D = cKDTree(c_s).sparse_distance_matrix(cKDTree(c_m), float(r_s.max() + r_m.max()), output_type="ndarray")
        i, j = D["i"], D["j"]
    return _apart(i, j, c_s, r_s, t_s, c_m, r_m, t_m, slave_el, master_el, enodes, radius)


def _apart(i, j, c_s, r_s, t_s, c_m, r_m, t_m, slave_el, master_el, enodes, radius):
    n = len(i)
    e, m, cos, c2, reach = (np.empty(n, dtype=slave_el.dtype), np.empty(n, dtype=master_el.dtype), np.empty(n),
                            np.empty((n, 3)), np.empty(n))
    k, least = _pairs_apart(i, j, c_s, r_s, c_m, r_m, t_s, t_m, slave_el, master_el, enodes, radius, e, m, cos, c2,
                            reach)
    return e[:k], m[:k], cos[:k], c2[:k], reach[:k], least
