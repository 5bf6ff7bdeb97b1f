"""Strain-free adjustment of initial overclosures (Abaqus' contact ``ADJUST``), as pure functions.

Geometry from CAD, from builders or a polyline round a post overlaps slightly
in the reference state: the chords of a polygon on a cylinder of radius
``R + r`` cut ``(R + r)(1 - cos(dphi / 2))`` into it.  Taken at face value the
penalty law puts forces on the reference state, and step 0 has no load-free
equilibrium to start from.  A contact point whose reference gap ``g0`` lies in
``[-adjust, 0)`` is instead taken as touching: its gap is offset for the whole
run by the overlap ``delta = -g0 > 0``,

    g_adjusted = g + delta,   g_adjusted(reference) = 0,

so the overlap puts no force on the reference state (the sharp law has none at
zero gap; a smoothed law keeps its own push of touching wires, solved at step 0
as for wires built touching, docs/theory.md 19.2).  The offset is carried by the
pair's radii: ``R1 + R2`` reduced by ``delta`` in proportion to ``R1`` and
``R2``, so the contact point keeps its place between the surfaces.
Points are identified by the pair keys of ``PairSet.key``: a slave Gauss point
on a master beam, or a crossing's element pair.  Deeper reference overlaps are
not touched (a modelling error, refused where it makes step 0 fail).
docs/theory_adjust.md.
"""
import numpy as np

__all__ = ["offsets", "apply", "summary", "EMPTY"]

EMPTY = (np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))     # keys, offsets, reference gaps


def offsets(key, gap, adjust):
    """Adjustment table from the pairs at the reference poses: ``key`` (P,) int64, reference
    ``gap`` (P,) and ``adjust`` (P,) tolerances (lengths).  Returns ``(keys, delta, gap0)`` of the
    adjusted points (``-adjust <= gap < 0``), sorted by key (a key seen twice keeps its first row)."""
    sel = np.flatnonzero((gap >= -adjust) & (gap < 0.0))
    k, first = np.unique(key[sel], return_index=True)
    sel = sel[first]
    return k.astype(np.int64), -gap[sel], gap[sel]


def apply(key, R1, R2, table):
    """Radii ``(R1, R2)`` of pairs with keys ``key``, reduced for the adjusted points of ``table``
    (``offsets``) by their offset in proportion to ``R1`` and ``R2``; the arrays as given when
    nothing matches."""
    keys, delta, _ = table
    if not len(keys) or not len(key):
        return R1, R2
    idx = np.clip(np.searchsorted(keys, key), 0, len(keys) - 1)
    hit = keys[idx] == key
    if not hit.any():
        return R1, R2
    d = np.where(hit, delta[idx], 0.0)
    s = R1 + R2
    return R1 - d * R1 / s, R2 - d * R2 / s


def summary(table):
    """``dict(count, largest)``: adjusted points and the largest reference overlap adjusted away."""
    keys, delta, _ = table
    return dict(count=int(len(keys)), largest=float(delta.max(initial=0.0)))
