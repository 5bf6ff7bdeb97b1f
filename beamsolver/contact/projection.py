"""Compiled section geometry and projections of the contact search (narrow phase).

Pure batched functions over element or pair arrays; node poses are read from the
pose array ``H`` ``(n, 4, 4)`` through node indices (no gathered copies).  Sections
follow the constant-strain interpolation ``H_A exp(xi h)`` with the element twist
``h = log(H_A^-1 H_B)``; the projections are the Newton iterations of
``kernel_jit._project`` (``frames.project`` is their numpy oracle):

- ``spheres``: the broad phase's element bounding spheres and mid-point tangents;
- ``closest_points``: closest points of two centre lines (kind ``POINT``) and the
  reduced-Hessian ratio ``(H11 - H12^2 / H22) / |x1'|^2`` of the search's rule 2;
- ``gauss_projections``: the slave Gauss points of element pairs, their sphere filter and
  their projections onto the master element (``LINE`` or ``ORTHOGONAL``), started from the
  projection on the master chord, each until converged (``STEP_TOL``), in one pass; ``project_points``: the same projections of
  given slave sections.

The Gauss-point projections run in lockstep over blocks of ``LANES`` (SIMD; the same
operations as ``kernel_jit._project_from``, bit for bit: see the comment above ``LANES``).
(Numba's disk cache would key a function on its own source file only; ``jit_cache`` stamps it
with the digest of every package module it imports.)  The sections are inlined
(``kernel_jit._section_inline``, the same operations): what a loop does not use of them
(``x'``, ``x''``, the rotation) is not computed.
"""
import numpy as np

from ..lie import se3_twin
from .._jit import jit, jit_callee
from ..lie.se3_jit import _SERIES_TABLE, _SWITCH, A_, B_, C_, add, add_outer, cross, dot, mat, mm, mv, scale
from .kernel_jit import _pose_of, _project, _section, _section_inline
from .frames import LINE, POINT

__all__ = ["element_twists", "section_points", "element_points", "spheres", "overlap", "closest_points", "project_points", "gauss_projections",
           "segment_bounds"]


def element_twists(H, enodes):
    """Twists ``h = log(H_A^-1 H_B)`` ``(n, 6)`` of the elements ``enodes`` ``(n, 2)``: the bits of the
    batched ``se3.log`` (``se3_twin.log_relative``; the compiled ``se3_jit.log_relative`` differs in
    round-off, which changes the Newton iteration counts of the contact examples: docs/benchmarks.md)."""
    return se3_twin.log_relative(H, enodes[:, 0], enodes[:, 1])


@jit
def _sections(H, A, h, xi, x, e1):
    for k in range(len(A)):
        RA, xA = _pose_of(H, A[k])
        R, xc, _, _ = _section_inline(RA, xA, (h[k, 0], h[k, 1], h[k, 2]), (h[k, 3], h[k, 4], h[k, 5]), xi[k])
        for i in range(3):
            x[k, i], e1[k, i] = xc[i], R[i][0]


def section_points(H, A, h, xi):
    """Centre points ``(n, 3)`` and first axes ``e_1`` ``(n, 3)`` of the sections ``H_A exp(xi h)``;
    ``A``: node index of each element's first node, ``h`` ``(n, 6)``, ``xi`` ``(n,)``."""
    n = len(A)
    x, e1 = np.empty((n, 3)), np.empty((n, 3))
    _sections(H, np.ascontiguousarray(A), np.ascontiguousarray(h, dtype=float),
              np.ascontiguousarray(np.broadcast_to(xi, (n,)), dtype=float), x, e1)
    return x, e1


@jit
def _element_points(H, enodes, h, e, xi, x):
    for k in range(len(e)):
        j = e[k]
        RA, xA = _pose_of(H, enodes[j, 0])
        _, xc, _, _ = _section_inline(RA, xA, (h[j, 0], h[j, 1], h[j, 2]), (h[j, 3], h[j, 4], h[j, 5]), xi[k])
        for i in range(3):
            x[k, i] = xc[i]


def element_points(H, enodes, h, e, xi):
    """Centre points ``(n, 3)`` of the sections ``xi`` ``(n,)`` of the elements ``e`` ``(n,)`` (``enodes``, twists ``h``:
    all elements'): ``section_points``' points, bit for bit, without gathering the elements' nodes and twists."""
    x = np.empty((len(e), 3))
    _element_points(H, enodes, np.ascontiguousarray(h, dtype=float), np.ascontiguousarray(e),
                    np.ascontiguousarray(xi, dtype=float), x)
    return x


@jit
def spheres(H, enodes, h, radii, margin, el, mid, radius, tangent):
    """Bounding spheres of the elements ``el`` into ``mid`` ``(n, 3)``, ``radius`` ``(n,)``
    (``|u| / 2 + r + margin``, ``|u|`` the arc length) and the mid-point tangents ``(n, 3)``."""
    for k in range(len(el)):
        j = el[k]
        RA, xA = _pose_of(H, enodes[j, 0])
        u = (h[j, 0], h[j, 1], h[j, 2])
        R, xc, _, _ = _section_inline(RA, xA, u, (h[j, 3], h[j, 4], h[j, 5]), 0.5)
        for i in range(3):
            mid[k, i], tangent[k, i] = xc[i], R[i][0]
        radius[k] = 0.5 * np.sqrt((u[0] * u[0] + u[1] * u[1]) + u[2] * u[2]) + radii[j] + margin


@jit
def overlap(c_s, r_s, c_m, r_m, i, j, keep):
    """``keep[k]``: spheres ``i[k]`` (centres ``c_s``, radii ``r_s``) and ``j[k]`` (``c_m``, ``r_m``) overlap
    (``|c_s[i] - c_m[j]| <= r_s[i] + r_m[j]``, the operations of ``np.linalg.norm``)."""
    for k in range(len(i)):
        a, b = i[k], j[k]
        d0, d1, d2 = c_s[a, 0] - c_m[b, 0], c_s[a, 1] - c_m[b, 1], c_s[a, 2] - c_m[b, 2]
        keep[k] = np.sqrt((d0 * d0 + d1 * d1) + d2 * d2) <= r_s[a] + r_m[b]


@jit
def _closest(H, A1, h1, A2, h2, iterations, out1, out2, ratio):
    for k in range(len(A1)):
        RA1, xA1 = _pose_of(H, A1[k])
        RA2, xA2 = _pose_of(H, A2[k])
        u1, w1 = (h1[k, 0], h1[k, 1], h1[k, 2]), (h1[k, 3], h1[k, 4], h1[k, 5])
        u2, w2 = (h2[k, 0], h2[k, 1], h2[k, 2]), (h2[k, 3], h2[k, 4], h2[k, 5])
        xi1, xi2 = _project(POINT, RA1, xA1, u1, w1, 0.5, RA2, xA2, u2, w2, 0.5, iterations)
        _, x1, x1p, x1pp = _section_inline(RA1, xA1, u1, w1, xi1)
        _, x2, x2p, x2pp = _section_inline(RA2, xA2, u2, w2, xi2)
        d = (x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2])
        h11 = dot(x1p, x1p) - dot(d, x1pp)
        h12 = -dot(x1p, x2p)
        h22 = dot(x2p, x2p) + dot(d, x2pp)
        r = (h11 - h12 * h12 / h22) / dot(x1p, x1p)
        out1[k], out2[k], ratio[k] = xi1, xi2, r if np.isfinite(r) else 0.0


def closest_points(H, A1, h1, A2, h2, iterations=8):
    """Closest points ``(xi1, xi2)`` of element pairs' centre lines, from ``(0.5, 0.5)``, and the
    reduced-Hessian ratio (0 where it is not finite); ``A1``, ``A2``: first nodes, ``h1``, ``h2`` twists."""
    n = len(A1)
    out1, out2, ratio = np.empty(n), np.empty(n), np.empty(n)
    _closest(H, np.ascontiguousarray(A1), np.ascontiguousarray(h1, dtype=float), np.ascontiguousarray(A2),
             np.ascontiguousarray(h2, dtype=float), int(iterations), out1, out2, ratio)
    return out1, out2, ratio


# ---------------------------------------------------------------- Gauss-point projections, lanes in lockstep
# The Newton iterations of a Gauss-point projection are one serial chain of dependent operations
# (~50 ns an iteration, latency-bound); iterated in lockstep over a block of ``LANES`` projections
# stored field by field (``S[f, lane]``), the loop over lanes has no branch and no call and the
# compiler runs it in SIMD registers (measured 3x faster).  The lanes compute the same operations
# as ``kernel_jit._project_from``'s ``LINE`` / ``ORTHOGONAL`` iterations, bit for bit: the
# exponential's coefficients by their series (``se3_jit.coefficient`` below its switch; a lane at or
# above it is redone by the scalar iteration), both kinds' updates computed and one selected.
# A lane stops at the first update ``|xi_k - xi_(k-1)| <= _step_tol`` (its ``xi_k`` kept: the iterate of
# ``_project_from`` after ``k`` iterations, bit for bit), a block when all its lanes stopped.  The lanes
# not converged after ``iterations`` go on (the block, its converged lanes frozen) up to
# ``MAX_ITERATIONS`` where their iterate lies in the owners' window (``gauss_projections(window=)``;
# outside it, as before, no owner would take it); one that does not converge gets a nan distance (the
# owners reject it) instead of its last iterate being accepted.  (Going on lane by lane, the scalar
# ``_step`` in a second loop, made every call ~12 % slower: the code the compiler inlines.)
LANES = 64
MAX_ITERATIONS = 64     # a lane's Newton iterations at most (the slow ones: near-degenerate roots)
# Convergence of a lane: its update ``|d xi| <= STEP_TOL (1 + |x_A| / |u|)`` (``_step_tol``; ``x_A`` the
# master's first node, ``|u| = |x'|`` its arc length).  The section point moves by less than
# ``STEP_TOL (|u| + |x_A|)``: ~4500 ulps of its coordinates (eps = 2.2e-16) and of the element, where
# the update's round-off is a few ulps of ``|x_A| / |u|`` (measured <= 2.7e-14 on the 19-wire strand,
# at least 37x below the tolerance there).  Newton converges quadratically from the chord start
# (the scenes: update ~1e-5 at the 2nd iteration, ~1e-13 at the 3rd), so the kept iterate's error is
# ~ C d xi^2, at the iterate's round-off, far below anything the owners (``XI_TOL = 1e-9``) or the
# kernel (two more Newton iterations from it, ``kernel_jit._project``) can see.
STEP_TOL = 1e-12
_SA, _SB, _SC = (tuple(float(v) for v in _SERIES_TABLE[k]) for k in (A_, B_, C_))
_SWITCH_ABC = float(min(_SWITCH[A_], _SWITCH[B_], _SWITCH[C_]))
# fields of a lane: master node pose RA2 (row-major), xA2, twist u2, w2, slave centre x1, axis e1
_RA, _XA, _U, _W, _X1, _E1, N_FIELDS = 0, 9, 12, 15, 18, 21, 24


@jit_callee
def _series(row, t):
    """``se3_jit.coefficient`` of the series ``row`` below its switch (the same operations)."""
    t2 = t * t
    v = row[8]
    v = v * t2 + row[7]
    v = v * t2 + row[6]
    v = v * t2 + row[5]
    v = v * t2 + row[4]
    v = v * t2 + row[3]
    v = v * t2 + row[2]
    v = v * t2 + row[1]
    return v * t2 + row[0]


@jit_callee
def _vec(S, f, l):
    return (S[f, l], S[f + 1, l], S[f + 2, l])


@jit_callee
def _lane(S, l):
    """Master node pose, twist, slave centre and axis of lane ``l``."""
    RA = (_vec(S, _RA, l), _vec(S, _RA + 3, l), _vec(S, _RA + 6, l))
    return RA, _vec(S, _XA, l), _vec(S, _U, l), _vec(S, _W, l), _vec(S, _X1, l), _vec(S, _E1, l)


@jit_callee
def _update(line, x1, e1, x2, x2p, x2pp, xi2):
    """One Newton update of ``xi2`` (``kernel_jit._project_from``, ``LINE`` or ``ORTHOGONAL``) from the master
    section at ``xi2``; both kinds computed, one selected (no branch)."""
    d = add(x2, scale(-1.0, x1))
    jl = dot(x2p, e1)
    jo = dot(x2p, x2p) + dot(d, x2pp)
    j = jl if line else jo
    g = dot(d, e1) if line else dot(d, x2p)
    return xi2 - g / (j if j != 0.0 else 1.0)


@jit_callee
def _step_series(line, x1, e1, RA, xA, u, w, xi2):
    """``_update`` at the section ``kernel_jit._section_inline(RA, xA, u, w, xi2)`` computed with the
    coefficients' series; also the angle ``t`` (the series hold below ``_SWITCH_ABC``)."""
    us, ws = scale(xi2, u), scale(xi2, w)
    t2 = dot(ws, ws)
    t = np.sqrt(t2)
    a, b, c = _series(_SA, t), _series(_SB, t), _series(_SC, t)
    Rs = add_outer(mat(scale(a, ws), 1.0 - b * t2), scale(b, ws), ws)
    wxu = cross(ws, us)
    xs = add(add(us, scale(b, wxu)), scale(c, cross(ws, wxu)))
    R = mm(RA, Rs)
    return _update(line, x1, e1, add(mv(RA, xs), xA), mv(R, u), mv(R, cross(w, u)), xi2), t


@jit_callee
def _step(line, x1, e1, RA, xA, u, w, xi2):
    """``_update`` at the section ``kernel_jit._section`` (any angle; scalar, a rare lane: not inlined)."""
    _, x2, x2p, x2pp = _section(RA, xA, u, w, xi2)
    return _update(line, x1, e1, x2, x2p, x2pp, xi2)


@jit_callee
def _step_tol(xA, u):
    """A lane's convergence tolerance on its update ``d xi``: ``STEP_TOL (1 + |x_A| / |u|)`` (see ``STEP_TOL``)."""
    lu = np.sqrt(dot(u, u))
    return STEP_TOL * (1.0 + np.sqrt(dot(xA, xA)) / lu) if lu > 0.0 else STEP_TOL


@jit_callee
def _iterate(S, line, xi, nxt, ang, tol, done, ok, n, iterations, window, lo, hi):
    """Newton updates of ``xi[:n]`` for the lanes ``S[:, :n]`` (``line[l]``: kind ``LINE``, else
    ``ORTHOGONAL``) until each lane's update is within ``tol[l]`` (``ok[l]``): ``iterations``, then on for the
    lanes not converged, up to ``MAX_ITERATIONS``, where ``window`` is false or their iterate is within
    ``[lo, hi]`` (the others stop there, ``done[l]`` and not ``ok[l]``); ``nxt``, ``ang`` scratch ``(LANES,)``."""
    for l in range(n):
        done[l] = ok[l] = False
    for it in range(MAX_ITERATIONS):
        if it == iterations:            # the lanes left: on only within the window
            for l in range(n):
                if not done[l] and window and not (xi[l] >= lo and xi[l] <= hi):
                    done[l] = True
        for l in range(n):
            if done[l]:             # (its update is not read)
                continue
            RA, xA, u, w, x1, e1 = _lane(S, l)
            nxt[l], ang[l] = _step_series(line[l], x1, e1, RA, xA, u, w, xi[l])
        left = 0
        for l in range(n):
            if done[l]:
                continue
            if ang[l] >= _SWITCH_ABC:
                RA, xA, u, w, x1, e1 = _lane(S, l)
                nxt[l] = _step(line[l], x1, e1, RA, xA, u, w, xi[l])
            done[l] = ok[l] = abs(nxt[l] - xi[l]) <= tol[l]
            xi[l] = nxt[l]
            left += not done[l]
        if left == 0:
            return


@jit_callee
def _fill(S, l, RA2, xA2, h2, k, xc, e1):
    for i in range(3):
        for j in range(3):
            S[_RA + 3 * i + j, l] = RA2[i][j]
        S[_XA + i, l] = xA2[i]
        S[_U + i, l] = h2[k, i]
        S[_W + i, l] = h2[k, 3 + i]
        S[_X1 + i, l] = xc[i]
        S[_E1 + i, l] = e1[i]


@jit_callee
def _chord_start(xc, xA2, xB2):
    """Projection of ``xc`` on the master chord ``xA2 xB2``, clipped to ``[0, 1]``."""
    chord = (xB2[0] - xA2[0], xB2[1] - xA2[1], xB2[2] - xA2[2])
    rel = (xc[0] - xA2[0], xc[1] - xA2[1], xc[2] - xA2[2])
    s = dot(rel, chord) / max(dot(chord, chord), 1e-300)
    return min(max(s, 0.0), 1.0)


@jit_callee
def _finish(H, a2, h2, k, S, l, xi2, ok, out2, dist, r, xF):
    """Master parameter and centre distance of lane ``l`` (master first node ``a2``, twist ``h2[k]``)
    into row ``r``; ``ok``: the lane converged, else the distance is nan (no projection).  The master's
    centre point into ``xF[r]`` (if ``xF`` has rows)."""
    RA2, xA2 = _pose_of(H, a2)
    _, xf, _, _ = _section_inline(RA2, xA2, (h2[k, 0], h2[k, 1], h2[k, 2]), (h2[k, 3], h2[k, 4], h2[k, 5]), xi2)
    out2[r] = xi2
    if xF.shape[0] > 0:
        for i in range(3):
            xF[r, i] = xf[i]
    dist[r] = np.sqrt((xf[0] - S[_X1, l]) ** 2 + (xf[1] - S[_X1 + 1, l]) ** 2 + (xf[2] - S[_X1 + 2, l]) ** 2) if ok else np.nan


# ``gauss_projections(window=)``: the cull's window is widened by ``CULL_PAD`` element lengths and its
# bound by ``CULL_SLACK`` of the chord (far above the round-off of the Newton iterates and of
# ``exp(log(H_A^-1 H_B)) = H_A^-1 H_B``, far below the ~1 element between a kept and a culled row)
CULL_PAD = 0.01
CULL_SLACK = 1e-9


@jit_callee
def _misses(xc, e1, xA2, xB2, lo, hi, bow):
    """``LINE`` cull: the slave section plane (centre ``xc``, normal ``e1``) cannot meet the master centre
    line on ``[lo, hi]``.  The line is within ``bow`` of its chord ``xA2 + xi (xB2 - xA2)`` there, so the
    plane's signed distance differs from the chord's, linear in ``xi``, by at most ``bow``: no root where
    the chord's stays beyond ``bow`` on one side at both ends.  Not finite: not culled."""
    chord = (xB2[0] - xA2[0], xB2[1] - xA2[1], xB2[2] - xA2[2])
    rel = (xA2[0] - xc[0], xA2[1] - xc[1], xA2[2] - xc[2])
    g0, g1 = dot(rel, e1), dot(chord, e1)
    f_lo, f_hi = g0 + lo * g1, g0 + hi * g1
    b = bow + CULL_SLACK * np.sqrt(dot(chord, chord))
    return (f_lo > b and f_hi > b) or (f_lo < -b and f_hi < -b)


@jit
def _gauss_project(H, enodes, h, e, m, xg, line, c2, reach, iterations, overhang, seg, lo_seg, hi_seg, xs, row, gp,
                   out2, dist, xC, xF):
    """Slave Gauss points ``xg`` of element pairs ``k`` (slave ``e[k]``, master ``m[k]``) within ``reach[k]``
    of ``c2[k]``, projected on the master; rows in the order ``(k, g)``, returns their number.  A slave
    element's sections are computed once.  ``overhang >= 0``: ``LINE`` rows whose plane misses the master
    on ``[-overhang, 1 + overhang]`` (``_misses``) are culled.  ``seg[k]``: the points of pair ``k`` are
    ``lo_seg[k] + (hi_seg[k] - lo_seg[k]) xs`` (its segment; none if empty), their sections its own.  ``xC``,
    ``xF`` ``(rows, 3)`` (or ``(0, 3)``: not written): the slave and master centre points of each row."""
    cull = overhang >= 0.0
    lo, hi = -overhang - CULL_PAD, 1.0 + overhang + CULL_PAD
    # |x(xi) - chord(xi)| <= |x''| |xi (xi - 1)| / 2 for xi in and beyond [0, 1]; |x''| = |w x u|
    quad = 0.5 * max(0.25, -lo * hi)
    S = np.empty((N_FIELDS, LANES))
    xi, nxt, ang, tol = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES)
    ln, done, ok = np.empty(LANES, dtype=np.bool_), np.empty(LANES, dtype=np.bool_), np.empty(LANES, dtype=np.bool_)
    lane_row = np.empty(LANES, dtype=np.int64)
    slot = np.full(len(enodes), -1, dtype=np.int64)
    sec = np.empty((len(e) + 1, max(len(xg), len(xs)), 6))   # per slave element: centre and axis of each point
    n_sec = 0                                  # (the last row: a segment's points)
    n, l = 0, 0
    for k in range(len(e)):
        s = slot[e[k]]
        ng = len(xg)
        if seg[k]:
            if not hi_seg[k] > lo_seg[k]:
                continue
            s, ng = len(e), len(xs)
            RA1, xA1 = _pose_of(H, enodes[e[k], 0])
            u1, w1 = (h[e[k], 0], h[e[k], 1], h[e[k], 2]), (h[e[k], 3], h[e[k], 4], h[e[k], 5])
            for g in range(ng):
                R1, xc, _, _ = _section_inline(RA1, xA1, u1, w1, lo_seg[k] + (hi_seg[k] - lo_seg[k]) * xs[g])
                for i in range(3):
                    sec[s, g, i], sec[s, g, 3 + i] = xc[i], R1[i][0]
        elif s < 0:
            s = slot[e[k]] = n_sec
            n_sec += 1
            RA1, xA1 = _pose_of(H, enodes[e[k], 0])
            u1, w1 = (h[e[k], 0], h[e[k], 1], h[e[k], 2]), (h[e[k], 3], h[e[k], 4], h[e[k], 5])
            for g in range(len(xg)):
                R1, xc, _, _ = _section_inline(RA1, xA1, u1, w1, xg[g])
                for i in range(3):
                    sec[s, g, i], sec[s, g, 3 + i] = xc[i], R1[i][0]
        RA2, xA2 = _pose_of(H, enodes[m[k], 0])
        _, xB2 = _pose_of(H, enodes[m[k], 1])
        r2 = reach[k] * reach[k]
        bow = 0.0
        if cull and line[k]:
            wxu = cross((h[m[k], 3], h[m[k], 4], h[m[k], 5]), (h[m[k], 0], h[m[k], 1], h[m[k], 2]))
            bow = quad * np.sqrt(dot(wxu, wxu))
        for g in range(ng):
            xc = (sec[s, g, 0], sec[s, g, 1], sec[s, g, 2])
            d0, d1, d2 = xc[0] - c2[k, 0], xc[1] - c2[k, 1], xc[2] - c2[k, 2]
            if not (d0 * d0 + d1 * d1) + d2 * d2 <= r2:
                continue
            if cull and line[k] and _misses(xc, (sec[s, g, 3], sec[s, g, 4], sec[s, g, 5]), xA2, xB2, lo, hi, bow):
                continue
            _fill(S, l, RA2, xA2, h, m[k], xc, (sec[s, g, 3], sec[s, g, 4], sec[s, g, 5]))
            xi[l] = _chord_start(xc, xA2, xB2)
            tol[l] = _step_tol(xA2, (h[m[k], 0], h[m[k], 1], h[m[k], 2]))
            ln[l] = line[k]
            row[n], gp[n], lane_row[l] = k, g, n
            if xC.shape[0] > 0:
                for i in range(3):
                    xC[n, i] = xc[i]
            n += 1
            l += 1
            if l == LANES:
                _iterate(S, ln, xi, nxt, ang, tol, done, ok, l, iterations, cull, lo, hi)
                for j in range(l):
                    mj = m[row[lane_row[j]]]
                    _finish(H, enodes[mj, 0], h, mj, S, j, xi[j], ok[j], out2, dist, lane_row[j], xF)
                l = 0
    _iterate(S, ln, xi, nxt, ang, tol, done, ok, l, iterations, cull, lo, hi)
    for j in range(l):
        mj = m[row[lane_row[j]]]
        _finish(H, enodes[mj, 0], h, mj, S, j, xi[j], ok[j], out2, dist, lane_row[j], xF)
    return n


def gauss_projections(H, enodes, h, e, m, xg, kind, c2, reach, iterations=8, window=None, segments=None, centres=False):
    """Slave Gauss points ``xg`` ``(g,)`` of element pairs ``(n,)`` projected on their master elements.

    Pair ``k``: slave element ``e[k]`` (its sections are computed once), master element ``m[k]``,
    ``kind[k]`` (``LINE`` or ``ORTHOGONAL``); ``enodes``, twists ``h`` ``(n_el, 6)``: all elements'.
    A Gauss point whose centre lies farther than ``reach[k]`` from
    ``c2[k]`` ``(n, 3)`` (the master's bounding sphere grown by the slave radius) cannot touch the
    master and is skipped.  The others are projected as ``project_points`` does (from the master
    chord, Newton iterations until the update is within ``_step_tol``: ``iterations``, then on for the lanes
    left, up to ``MAX_ITERATIONS``, where their iterate is in the window).  Returns, over the rows kept in
    the order ``(k, g)``: pair ``row``, Gauss point ``gp``, ``xi2`` and centre distance (nan where the
    projection did not converge: no owner takes the row).

    ``window``: the overhang past the master's nodes of the projections the ownership accepts
    (``rules.XI_OVERHANG``); given, a ``LINE`` row whose slave section plane cannot meet the master
    centre line on ``[-window, 1 + window]`` (widened by ``CULL_PAD``; ``_misses``: the chord's
    signed distance and the bound of the line's bow) is not projected: its converged projection
    would be rejected.  Without it the rows within ``reach`` grow like ``1 + 7 R / L`` per slave
    point as the elements get shorter than the radii; with it about one or two.

    ``segments``: ``(seg, lo, hi)`` ``(n,)`` (``segment_bounds``) and ``xs`` ``(s,)``: the points of a pair
    with ``seg`` are ``lo + (hi - lo) xs`` (none where ``hi <= lo``); the others' are ``xg``.

    ``centres``: also the rows' slave and master centre points ``(rows, 3)`` (the sections at the slave point and at
    ``xi2``: ``element_points``' floats, bit for bit).
    """
    c = np.ascontiguousarray
    n = len(e) * (len(xg) if segments is None else max(len(xg), len(segments[3])))
    row, gp = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    out2, dist = np.empty(n), np.empty(n)
    if segments is None:
        seg, lo, hi, xs = np.zeros(len(e), dtype=np.bool_), np.zeros(len(e)), np.ones(len(e)), c(xg, dtype=float)
    else:
        seg, lo, hi, xs = (c(a) for a in segments)
    xC, xF = (np.empty((n, 3)), np.empty((n, 3))) if centres else (np.empty((0, 3)), np.empty((0, 3)))
    k = _gauss_project(H, enodes, c(h, dtype=float), c(e), c(m), c(xg, dtype=float), c(np.asarray(kind) == LINE),
                       c(c2, dtype=float), c(reach, dtype=float), int(iterations),
                       -1.0 if window is None else float(window), seg, lo, hi, xs, row, gp, out2, dist, xC, xF)
    if centres:
        return row[:k], gp[:k], out2[:k], dist[:k], xC[:k], xF[:k]
    return row[:k], gp[:k], out2[:k], dist[:k]


SEGMENT_SNAP = 1e-4 # segment ends this close to the slave element's ends are snapped to them
PLANE_TOL = 1e-14   # segment ends: Newton stops when its step is this small (parameter units)


@jit_callee
def _plane_through(RA, xA, u, w, xB, xN, iterations):
    """Slave parameter ``xi`` whose section plane passes through the point ``xN`` (``(xN - x(xi)) . e1(xi) = 0``),
    Newton from the projection of ``xN`` on the chord ``xA xB`` (kept within ``[-1, 2]``); ``u``, ``w``: the
    element's twist.  ``d/dxi (x, e1) = (R u, R (w x E1))``."""
    xi = _chord_start(xN, xA, xB)
    for _ in range(iterations):
        R, x, xp, _ = _section_inline(RA, xA, u, w, xi)
        d = (xN[0] - x[0], xN[1] - x[1], xN[2] - x[2])
        e1 = (R[0][0], R[1][0], R[2][0])
        e1p = mv(R, (0.0, w[2], -w[1]))
        f = dot(d, e1)
        j = dot(d, e1p) - dot(xp, e1)
        nxt = min(max(xi - f / (j if j != 0.0 else 1.0), -1.0), 2.0)
        done = abs(nxt - xi) <= PLANE_TOL
        xi = nxt
        if done:                # converged (quadratically: 2-4 iterations from the chord on the scenes)
            break
    return xi


@jit_callee
def _snap(s, snap):
    """``s`` within ``snap`` of the slave element's ends taken as the end itself."""
    if s < snap:
        return 0.0
    if s > 1.0 - snap:
        return 1.0
    return s


@jit
def _segment_bounds(H, enodes, h, e, m, seg, iterations, lo, hi, snap):
    for k in range(len(e)):
        lo[k], hi[k] = 0.0, 1.0
        if not seg[k]:
            continue
        RA1, xA1 = _pose_of(H, enodes[e[k], 0])
        _, xB1 = _pose_of(H, enodes[e[k], 1])
        u1, w1 = (h[e[k], 0], h[e[k], 1], h[e[k], 2]), (h[e[k], 3], h[e[k], 4], h[e[k], 5])
        _, xA2 = _pose_of(H, enodes[m[k], 0])
        _, xB2 = _pose_of(H, enodes[m[k], 1])
        a = _plane_through(RA1, xA1, u1, w1, xB1, xA2, iterations)
        b = _plane_through(RA1, xA1, u1, w1, xB1, xB2, iterations)
        lo[k] = _snap(min(max(min(a, b), 0.0), 1.0), snap)
        hi[k] = _snap(min(max(max(a, b), 0.0), 1.0), snap)


def segment_bounds(H, enodes, h, e, m, seg, iterations=8):
    """Segments ``[lo, hi]`` ``(n,)`` of the slave elements ``e`` against the master elements ``m`` (pairs ``seg``;
    the others ``[0, 1]``): the slave parameters whose section planes pass through the master's end nodes
    (``LINE`` projection inverted, ``_plane_through``), sorted and clipped to ``[0, 1]``; ``hi <= lo``: no
    overlap.  Slave points of ``[lo, hi]`` project into the master element (``[0, 1]``); the segments of
    one slave element against consecutive master elements meet where the plane passes through their
    shared node, so they tile the slave element's overlap with the master beam."""
    c = np.ascontiguousarray
    n = len(e)
    lo, hi = np.empty(n), np.empty(n)
    _segment_bounds(H, enodes, c(h, dtype=float), c(e), c(m), c(seg, dtype=np.bool_), int(iterations), lo, hi,
                    float(SEGMENT_SNAP))
    return lo, hi


@jit
def _project_points(H, line, A1, h1, xi1, A2, B2, h2, iterations, out2, dist):
    S = np.empty((N_FIELDS, LANES))
    xi, nxt, ang, tol = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES)
    ln, done, ok = np.empty(LANES, dtype=np.bool_), np.empty(LANES, dtype=np.bool_), np.empty(LANES, dtype=np.bool_)
    no_points = np.empty((0, 3))
    n = len(A1)
    for lo in range(0, n, LANES):
        m = min(LANES, n - lo)
        for l in range(m):
            k = lo + l
            RA1, xA1 = _pose_of(H, A1[k])
            RA2, xA2 = _pose_of(H, A2[k])
            _, xB2 = _pose_of(H, B2[k])
            R1, xc, _, _ = _section_inline(RA1, xA1, (h1[k, 0], h1[k, 1], h1[k, 2]), (h1[k, 3], h1[k, 4], h1[k, 5]),
                                           xi1[k])
            _fill(S, l, RA2, xA2, h2, k, xc, (R1[0][0], R1[1][0], R1[2][0]))
            xi[l] = _chord_start(xc, xA2, xB2)
            tol[l] = _step_tol(xA2, (h2[k, 0], h2[k, 1], h2[k, 2]))
            ln[l] = line[k]
        _iterate(S, ln, xi, nxt, ang, tol, done, ok, m, iterations, False, 0.0, 1.0)
        for l in range(m):
            _finish(H, A2[lo + l], h2, lo + l, S, l, xi[l], ok[l], out2, dist, lo + l, no_points)


def project_points(H, kind, A1, h1, xi1, A2, B2, h2, iterations=8):
    """Master parameter ``xi2`` and centre distance of slave sections ``xi1`` projected onto master
    elements (nodes ``A2``, ``B2``; ``kind`` ``LINE`` or ``ORTHOGONAL``), started on the master chord
    (the iterations of ``kernel_jit._project_from``, lanes in lockstep, each until its update is within
    ``_step_tol``: ``iterations``, then on for the lanes left up to ``MAX_ITERATIONS``; the distance is nan
    where it did not converge)."""
    n = len(A1)
    out2, dist = np.empty(n), np.empty(n)
    c = np.ascontiguousarray
    _project_points(H, c(np.asarray(kind) == LINE), c(A1), c(h1, dtype=float), c(np.broadcast_to(xi1, (n,)), dtype=float),
                    c(A2), c(B2), c(h2, dtype=float), int(iterations), out2, dist)
    return out2, dist
