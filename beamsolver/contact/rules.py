"""Pair rules of the contact search: which element pairs and slave points become contact pairs.

Pure functions over arrays (no state: the hysteresis inputs, the owners chosen at the
last evaluation, are arguments).  The stages, in the order ``ContactSystem.pairs`` runs them:

1. ``apart``: elements sharing a node never pair, nor elements meeting at a joint (their
   nodes merged by ``joint_nodes``);
2. ``crossing``: line contact below ``line_angle``, else ``point_or_orthogonal`` by the
   reduced-Hessian ratio (search.py, rules 1-2), and ``extend_wrap`` (rule 3);
3. ``xi_range``: accepted projection parameters on an element;
4. ownership: ``owners`` (one master element per slave Gauss point and master beam) and
   ``dedupe_points`` (one point pair per crossing).
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .frames import ORTHOGONAL, POINT
from .search import XI_TOL

__all__ = ["joint_nodes", "pieces", "apart", "crossing", "may_cross", "point_or_orthogonal", "extend_wrap", "xi_range", "owners", "dedupe_points", "XI_OVERHANG", "OWNER_TIE"]

XI_OVERHANG = 0.05        # accepted projection past an inner node, in element lengths (kinks of the C0 line)
WRAP_END = 0.05          # extend_wrap: a slave closest point this close to an element end counts as at the end
CROSSING_MARGIN = 1e-9    # crossing: far above the round-off of arccos and cos (1e-16)
OWNER_TIE = 1e-9          # distances equal within this fraction of R1 + R2 tie (a point on a shared node)


def joint_nodes(group, x, tol):
    """Node ids ``(n_nodes,)`` for ``apart`` in which the nodes of a joint are one node.

    ``group`` ``(n_nodes,)``: the join group of each node (``assembly.System.rep``, union-find
    over every ``Model.join``); ``x`` ``(n_nodes, 3)``: reference positions.  Nodes of one
    group within ``tol`` of each other are merged, whichever kind of ``join`` tied them: a
    joint (``join(a, b)``, or ``rigid=True`` on coincident nodes, as the halves of a wire in
    ``examples/plectoneme.py``) makes the elements on either side neighbours, as if they
    shared the node.  A rigid link between nodes apart (wire ends on a plate node) does not:
    the elements it ties are apart at the link, and wires touching along their length up to
    a plate are in contact there too.
    """
    n = len(group)
    ij = cKDTree(x).query_pairs(tol, output_type="ndarray")
    ij = ij[group[ij[:, 0]] == group[ij[:, 1]]]
    if len(ij) == 0:
        return np.arange(n)
    tie = coo_matrix((np.ones(len(ij)), (ij[:, 0], ij[:, 1])), shape=(n, n))
    return connected_components(tie, directed=False)[1]


def pieces(joint_enodes, beam, first, last, n_beams):
    """Beams continued by the next beam at a joint (a wire made of pieces, ``join(a.last, b.first)``): the
    key's master beam and the ends of the runs of pieces.

    ``joint_enodes`` ``(n_el, 2)``: end nodes merged by ``joint_nodes``; ``beam``, ``first``, ``last`` ``(n_el,)``:
    each element's beam and whether it is its beam's first / last.  Element ``e``, its beam's last, is continued by
    element ``e + 1``, the next beam's first, where they meet at a joint (the element ids run on through the
    joint, as the friction history's re-expression of a material point on the next element needs).  Returns
    ``(key_beam, first_end, last_end)`` ``(n_el,)``: the first beam of each element's run of pieces (a slave
    Gauss point has one owner over the run, ``ownership.gauss_owners``' key) and whether the element's first /
    last node ends its run (a beam end: ``xi_range`` accepts ``XI_TOL`` there, ``XI_OVERHANG`` at a joint
    inside the run, where the centre line may have a kink as at an inner node).  Without joints: ``beam``,
    ``first``, ``last``."""
    e = np.flatnonzero(last[:-1] & first[1:] & (beam[:-1] != beam[1:])
                       & (joint_enodes[:-1, 1] == joint_enodes[1:, 0]))
    if not len(e):
        return beam, first, last
    root = np.arange(n_beams)
    for k in e:                     # (once, at set-up: one entry per joint; a run's beams in increasing order)
        root[beam[k + 1]] = root[beam[k]]
    first_end, last_end = first.copy(), last.copy()
    first_end[e + 1] = False
    last_end[e] = False
    return root[beam], first_end, last_end


def apart(enodes, e, m):
    """Mask ``(n,)`` of the element pairs ``(e[k], m[k])`` that share no node, each pair compared
    with its own two elements' nodes (``enodes`` ``(n_el, k)``; pass the table mapped by
    ``joint_nodes`` so that elements meeting at a joint never pair: their centre lines meet
    there, a contact pair between them would find no normal or the full overlap
    ``R1 + R2``).  The search runs it inside the broad phase's compiled pass (``search.broad_pairs``,
    tested equal)."""
    A, B = enodes[e], enodes[m]
    shared = np.zeros(len(A), dtype=bool)
    for a in range(A.shape[1]):            # node columns: no (n, k, k) table
        for b in range(B.shape[1]):
            shared |= A[:, a] == B[:, b]
    return ~shared


def point_or_orthogonal(ratio, point_ratio):
    """Kind of crossing element pairs: ``POINT`` where the reduced-Hessian ``ratio`` is at least
    ``point_ratio`` (an isolated crossing), else ``ORTHOGONAL`` (wrapping)."""
    return np.where(ratio >= point_ratio, POINT, ORTHOGONAL)


def crossing(cos, line_angle, least=None):
    """Mask of the element pairs at or above ``line_angle`` (those needing their closest points);
    ``cos`` ``(n,)``: cosines of the angles between their mid-point tangents (``search.broad_pairs``).
    ``least``: the least ``|cos|`` if known; above ``cos(line_angle) + CROSSING_MARGIN`` no pair crosses
    (every angle is below ``line_angle - CROSSING_MARGIN``: ``|d arccos / dc| >= 1``) and no ``arccos``
    is evaluated (nearly parallel wires)."""
    if least is not None and not may_cross(least, line_angle):
        return np.zeros(len(cos), dtype=bool)
    return np.arccos(np.clip(np.abs(cos), 0.0, 1.0)) >= line_angle


def may_cross(least, line_angle):
    """Whether a pair whose least ``|cos|`` is ``least`` may be at or above ``line_angle`` (``crossing``)."""
    return not least > np.cos(line_angle) + CROSSING_MARGIN


def extend_wrap(enodes, master_beam, n_beams, e, m, kind, xi1=None):
    """A straight slave element leaving a wrap tangentially (it shares a node with an
    ``ORTHOGONAL`` element against the same master beam, ``master_beam[k]`` the beam of ``m[k]``)
    is projected orthogonally too: its closest point to the master sits at its end, where a
    point pair would switch on and off as the tangent point moves (search.py, rule 3).
    ``xi1``: the slave's closest points; given, only point pairs whose closest point lies
    outside ``[WRAP_END, 1 - WRAP_END]`` are extended: a crossing inside the slave element is an
    isolated crossing whatever its neighbours are (a neighbour's kind, decided at closest points
    far outside its elements, must not take the point pair from a crossing of the loop's arms)."""
    orth = kind == ORTHOGONAL
    if not orth.any() or orth.all():
        return kind
    pt = np.flatnonzero(kind == POINT)
    if xi1 is not None:
        pt = pt[(xi1[pt] < WRAP_END) | (xi1[pt] > 1.0 - WRAP_END)]
    if not len(pt):               # (no point pair to extend to: the wraps' node keys not needed)
        return kind
    wrap = np.unique((enodes[e[orth]] * n_beams + master_beam[orth, None]).ravel())
    ids = enodes[e[pt]] * n_beams + master_beam[pt, None]
    near = (wrap[np.minimum(np.searchsorted(wrap, ids), len(wrap) - 1)] == ids).any(axis=1)    # np.isin, wrap sorted
    kind = kind.copy()
    kind[pt[near]] = ORTHOGONAL
    return kind


def xi_range(first, last):
    """Accepted projections ``[lo, hi]`` on elements, given whether each is the first / last of
    its beam: ``XI_OVERHANG`` past an inner node (at a kink of the C0 centre line the closest
    point of either element's extension lies just past the shared node: without it the point
    would be lost), ``XI_TOL`` at a beam end."""
    return np.where(first, -XI_TOL, -XI_OVERHANG), np.where(last, 1.0 + XI_TOL, 1.0 + XI_OVERHANG)


def owners(cand, key, xi2, dist, rsum, known):
    """One master element per slave Gauss point and master beam (``key``), among ``cand``.

    Priority: a projection inside its element over one on an extension (overhang);
    then the nearest, where distances within ``OWNER_TIE`` (R1 + R2) count as equal
    (a point projecting on a node shared by two elements, to round-off); among equals
    the owner of the last evaluation (``known``, over all rows: no flip-flop inside
    Newton), then the element on which the point lies at its start (smaller ``xi2``).
    The search runs its compiled twin ``ownership.gauss_owners`` (tested equal).
    """
    if len(cand) == 0:
        return cand
    k, x = key[cand], xi2[cand]
    outside = (x < -XI_TOL) | (x > 1.0 + XI_TOL)
    order = np.lexsort((dist[cand], outside, k))
    c = cand[order]
    head = np.concatenate([[True], (k[order][1:] != k[order][:-1]) | (outside[order][1:] != outside[order][:-1])])
    best = np.maximum.accumulate(np.where(head, np.arange(len(c)), 0))
    tie = dist[c] <= dist[c[best]] + OWNER_TIE * rsum[c]
    order = np.lexsort((xi2[c], ~known[c], ~tie, outside[order], key[c]))
    c = c[order]
    first = np.concatenate([[True], key[c][1:] != key[c][:-1]])
    return c[first]


def dedupe_points(xC, xF, xi1, xi2, rad, group, known):
    """Indices of the point pairs kept, one per crossing: at a node where two elements meet
    (a kink of the C0 centre line) each element has its own closest point; of pairs of the
    same two beams (``group``) lying within ``R1 + R2`` (``rad``) of each other the nearest is
    kept, a pair chosen at the last evaluation (``known``) first, so the choice cannot flip
    between the two elements of a kink inside Newton.  ``xC``, ``xF``: centre points ``(k, 3)``."""
    idx = np.arange(len(xC))
    if len(idx) < 2:
        return idx
    dist = np.linalg.norm(xF - xC, axis=1)
    outside = (xi1 < -XI_TOL) | (xi1 > 1.0 + XI_TOL) | (xi2 < -XI_TOL) | (xi2 > 1.0 + XI_TOL)
    order = np.lexsort((dist, ~known, outside, group))
    rank = np.empty(len(order), dtype=int)
    rank[order] = np.arange(len(order))
    # candidate pairs (a dominates b: higher priority, same beams, both points close)
    ij = cKDTree(xC).query_pairs(float(rad.max()), output_type="ndarray")
    if len(ij) == 0:
        return idx
    a, b = ij[:, 0], ij[:, 1]
    swap = rank[a] > rank[b]
    a, b = np.where(swap, b, a), np.where(swap, a, b)
    close = ((group[a] == group[b]) & (np.linalg.norm(xC[a] - xC[b], axis=1) < rad[b])
             & (np.linalg.norm(xF[a] - xF[b], axis=1) < rad[b]))
    a, b = a[close], b[close]
    # greedy in priority order, as a fixed point: dropped iff a kept pair dominates it
    dropped = np.zeros(len(idx), dtype=bool)
    for _ in range(len(idx)):
        new = np.zeros(len(idx), dtype=bool)
        new[b[~dropped[a]]] = True
        if np.array_equal(new, dropped):
            break
        dropped = new
    return idx[~dropped]
