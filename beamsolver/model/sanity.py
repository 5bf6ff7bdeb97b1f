"""Step-0 sanity of a scene's sizes: radii implausible for its lengths (issue 29 item 4).

A radius given in the wrong unit (millimetres in a metre model) builds and solves until the contact
search finds wires that "changed sides".  ``check_sizes(model)``, run by ``solve`` before step 0,
warns once (``GeometryWarning``, the numbers in the message) when

- a beam's radius is larger than its length (the arc length of its reference centre line), or
- a beam's tube (its centre line and radius) holds the centre line of another beam deep inside:
  their centre lines come closer than ``OVERLAP`` (one half) of the larger of the two radii.
  Touching tubes are ``R1 + R2`` apart; a start overlapping by less than half the larger radius
  (a rope's polyline pulled onto a post, adjusted by ``add_contact(adjust=)``) is not flagged, a radius
  a thousand times too large is.  Beams joined to each other (``Model.join``, directly or through a
  node of ``add_node``) are not compared: they meet at the joint.

The nearest approach of two centre lines is that of their reference polylines (segment to
segment); candidate segments come from a k-d tree of the segments' midpoints, so a scene of
``N`` segments costs about ``N log N`` unless radii are of the scene's size.
"""
import warnings

import numpy as np

from ..errors import GeometryWarning

__all__ = ["check_sizes", "size_problems", "segment_distances"]

MAX_LISTED = 5        # problems named in the warning (the rest counted)
OVERLAP = 0.5         # centre lines closer than this times the larger radius: implausible


def segment_distances(a0, a1, b0, b1):
    """Shortest distances ``(n,)`` between the segments ``a0 a1`` and ``b0 b1`` (``(n, 3)`` each)."""
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a, e = np.einsum("ij,ij->i", d1, d1), np.einsum("ij,ij->i", d2, d2)
    b, c, f = np.einsum("ij,ij->i", d1, d2), np.einsum("ij,ij->i", d1, r), np.einsum("ij,ij->i", d2, r)
    den = a * e - b * b
    tiny = 1e-300
    s = np.where(den > 1e-12 * a * e + tiny, np.clip((b * f - c * e) / np.maximum(den, tiny), 0.0, 1.0), 0.0)
    point = e <= tiny                      # b0 b1 a point: t = 0, s its projection on a0 a1
    t = np.where(point, 0.0, (b * s + f) / np.maximum(e, tiny))
    # t outside [0, 1] (or a point): clamp it and recompute s for the clamped t
    t_c = np.clip(t, 0.0, 1.0)
    s = np.where((t == t_c) & ~point, s, np.clip((b * t_c - c) / np.maximum(a, tiny), 0.0, 1.0))
    p, q = a0 + s[:, None] * d1, b0 + t_c[:, None] * d2
    return np.linalg.norm(p - q, axis=1)


def _joined_pairs(model):
    """Pairs ``(i, j)`` (``i < j``) of beam indices joined directly or through nodes of ``add_node``."""
    owner = {}
    for k, b in enumerate(model.beams):
        for n in b.nodes:
            owner[int(n)] = k
    parent = {}

    def find(x):
        while parent.get(x, x) != x:
            x = parent[x]
        return x

    for a, b in model.joins:                 # union-find over nodes; beams' nodes stay their own
        ra, rb = find(("n", int(a))), find(("n", int(b)))
        parent[ra] = rb
    groups = {}
    for n, k in owner.items():
        groups.setdefault(find(("n", n)), set()).add(k)
    for free in model.free_nodes:
        groups.setdefault(find(("n", int(free))), set())
    pairs = set()
    for ks in groups.values():
        ks = sorted(ks)
        pairs.update((ks[i], ks[j]) for i in range(len(ks)) for j in range(i + 1, len(ks)))
    return pairs


def size_problems(model):
    """The implausible sizes of ``model``: a list of ``(kind, text)``, ``kind`` ``"radius"`` (a radius
    above its beam's length) or ``"overlap"`` (a tube holding another beam's centre line deep inside)."""
    beams = model.beams
    if not beams:
        return []
    X = model.poses0[:, :3, 3]
    out = []
    seg_a, seg_b, seg_beam = [], [], []
    for k, b in enumerate(beams):
        P = X[b.nodes]
        length = float(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=1)))
        R = float(b.section.radius)
        if R > length:
            out.append(("radius", f"{b!r} has radius {R:.4g}, larger than its length {length:.4g}"))
        seg_a.append(P[:-1])
        seg_b.append(P[1:])
        seg_beam.append(np.full(len(P) - 1, k))
    if len(beams) < 2:
        return out
    A, B, owner = np.concatenate(seg_a), np.concatenate(seg_b), np.concatenate(seg_beam)
    radius = np.array([float(b.section.radius) for b in beams])
    mid, half = 0.5 * (A + B), 0.5 * np.linalg.norm(B - A, axis=1)
    joined = _joined_pairs(model)
    from scipy.spatial import cKDTree
    tree = cKDTree(mid)
    found = {}
    h_max = float(half.max())
    for i in range(len(beams)):
        mine = np.flatnonzero(owner == i)
        reach = OVERLAP * max(radius[i], radius.max()) + float(half[mine].max()) + h_max
        cand = tree.query_ball_point(mid[mine], r=reach)
        s = np.repeat(mine, [len(c) for c in cand])
        t = np.fromiter((j for c in cand for j in c), dtype=np.int64, count=len(s))
        keep = owner[t] > i
        s, t = s[keep], t[keep]
        if not len(s):
            continue
        pair = np.array([(i, j) not in joined for j in owner[t]], dtype=bool)
        s, t = s[pair], t[pair]
        if not len(s):
            continue
        d = segment_distances(A[s], B[s], A[t], B[t])
        limit = OVERLAP * np.maximum(radius[i], radius[owner[t]])
        for j in np.unique(owner[t][d < limit]):
            sel = owner[t] == j
            found[(i, int(j))] = float(d[sel].min())
    for (i, j), d in sorted(found.items()):
        bi, bj = beams[i], beams[j]
        out.append(("overlap", f"the centre lines of {bi!r} (radius {bi.section.radius:.4g}) and {bj!r} (radius "
                               f"{bj.section.radius:.4g}) come {d:.4g} apart, less than half the larger radius: one tube "
                               f"holds the other's centre line deep inside (touching tubes are R1 + R2 = "
                               f"{bi.section.radius + bj.section.radius:.4g} apart)"))
    return out


def check_sizes(model):
    """Warn once (``GeometryWarning``) if ``model`` has implausible sizes (``size_problems``); returns them."""
    problems = size_problems(model)
    if problems:
        texts = [t for _, t in problems]
        more = f"; and {len(texts) - MAX_LISTED} more" if len(texts) > MAX_LISTED else ""
        lengths = [float(np.sum(np.linalg.norm(np.diff(model.poses0[b.nodes, :3, 3], axis=0), axis=1)))
                   for b in model.beams]
        warnings.warn("implausible sizes for the scene (a radius in another unit than the lengths?): "
                      + "; ".join(texts[:MAX_LISTED]) + more
                      + f" (beam lengths {min(lengths):.4g} to {max(lengths):.4g}, radii "
                        f"{min(b.section.radius for b in model.beams):.4g} to "
                        f"{max(b.section.radius for b in model.beams):.4g})", GeometryWarning, stacklevel=3)
    return problems
