"""Compiled section geometry and projections of the contact search (narrow phase).

Pure batched functions over element or pair arrays; node poses are read from the
pose array ``H`` ``(n, 4, 4)`` through node indices (no gathered copies).  Sections
follow the constant-strain interpolation ``H_A exp(xi h)`` with the element twist
``h = log(H_A^-1 H_B)``; the projections are the Newton iterations of
``kernel_jit._project`` (``pairs._project`` is their numpy oracle):

- ``closest_points``: closest points of two centre lines (kind ``POINT``) and the
  reduced-Hessian ratio ``(H11 - H12^2 / H22) / |x1'|^2`` of the search's rule 2;
- ``project_points``: a slave section ``xi1`` onto a master element (``LINE`` or
  ``ORTHOGONAL``), started from the projection on the master chord.

``_project`` computes a fixed slave section once and stops at an exact fixed point of
the iteration, with the result of all the iterations asked for; ``project_points`` hands
it the slave section it already has (``kernel_jit._project_from``).  (Numba's disk cache
keys a function on its own source file only: after editing ``kernel_jit._project`` or the
functions it calls, delete the ``__pycache__`` numba files of this module too, or it keeps
the old copy.)  The sections are inlined (``kernel_jit._section_inline``, the same operations):
what a loop does not use of them (``x'``, ``x''``, the rotation) is not computed.
"""
import numpy as np

from .. import se3
from .._jit import jit
from ..se3_jit import dot
from .kernel_jit import _pose_of, _project, _project_from, _section_inline
from .pairs import POINT

__all__ = ["element_twists", "section_points", "closest_points", "project_points"]


def element_twists(H, enodes):
    """Twists ``h = log(H_A^-1 H_B)`` ``(n, 6)`` of the elements ``enodes`` ``(n, 2)``: one batched
    ``se3.log`` (the compiled ``se3_jit.log_relative`` differs in round-off, which was measured to
    change the twisted pair's Newton iteration counts: 139 instead of 135)."""
    return se3.log(se3.relative(H[enodes[:, 0]], H[enodes[:, 1]]))


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


@jit
def _project_points(H, kind, A1, h1, xi1, A2, B2, h2, iterations, out2, dist):
    for k in range(len(A1)):
        RA1, xA1 = _pose_of(H, A1[k])
        RA2, xA2 = _pose_of(H, A2[k])
        _, xB2 = _pose_of(H, B2[k])
        u1, w1 = (h1[k, 0], h1[k, 1], h1[k, 2]), (h1[k, 3], h1[k, 4], h1[k, 5])
        u2, w2 = (h2[k, 0], h2[k, 1], h2[k, 2]), (h2[k, 3], h2[k, 4], h2[k, 5])
        sec1 = _section_inline(RA1, xA1, u1, w1, xi1[k])
        xc = sec1[1]
        chord = (xB2[0] - xA2[0], xB2[1] - xA2[1], xB2[2] - xA2[2])
        rel = (xc[0] - xA2[0], xc[1] - xA2[1], xc[2] - xA2[2])
        s = dot(rel, chord) / max(dot(chord, chord), 1e-300)
        s = min(max(s, 0.0), 1.0)
        _, xi2 = _project_from(kind[k], sec1, RA1, xA1, u1, w1, xi1[k], RA2, xA2, u2, w2, s, iterations)
        _, xf, _, _ = _section_inline(RA2, xA2, u2, w2, xi2)
        out2[k] = xi2
        dist[k] = np.sqrt((xf[0] - xc[0]) ** 2 + (xf[1] - xc[1]) ** 2 + (xf[2] - xc[2]) ** 2)


def project_points(H, kind, A1, h1, xi1, A2, B2, h2, iterations=8):
    """Master parameter ``xi2`` and centre distance of slave sections ``xi1`` projected onto master
    elements (nodes ``A2``, ``B2``; ``kind`` ``LINE`` or ``ORTHOGONAL``), started on the master chord."""
    n = len(A1)
    out2, dist = np.empty(n), np.empty(n)
    c = np.ascontiguousarray
    _project_points(H, c(kind, dtype=np.int64), c(A1), c(h1, dtype=float), c(xi1, dtype=float), c(A2), c(B2),
                    c(h2, dtype=float), int(iterations), out2, dist)
    return out2, dist
