"""Contact search: broad phase over element bounding spheres, narrow phase by projection.

Broad phase: every element is bounded by a sphere around its mid-point of
radius ``|u|/2 + r + margin`` (``|u|`` is the element's arc length, ``r`` its
section radius); ``scipy.spatial.cKDTree`` finds the slave/master element pairs
whose spheres overlap (cost ~ n log n, trees rebuilt as the beams move).

Narrow phase, the choice rule per slave/master element pair (documented in
the README, tested on both sides of each switch):

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
and master beam the closest accepted projection is kept.
"""
import numpy as np
from scipy.spatial import cKDTree

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
    """Slave/master element index pairs whose bounding spheres overlap."""
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
