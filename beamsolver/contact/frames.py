"""Pair kinds, tolerances and the numpy geometry of one contact pair (complex-step safe).

A pair is a slave section ``{C}`` at ``xi1`` of element ``A1 B1`` and a master section ``{F}``
at ``xi2`` of element ``A2 B2`` (seed paper; docs/theory.md sections 6-7):

- sections ``H_A exp(xi h)``, ``h = log(H_A^-1 H_B)`` (``section``);
- projection by kind (``project``): ``LINE``: ``(x_F - x_C) . e_C1 = 0``; ``ORTHOGONAL``:
  ``(x_C - x_F) . e_F1 = 0``; ``POINT``: closest points of both centre lines, ``xi1`` solved too;
- axes ``n = (x_F - x_C)/|x_F - x_C|``, ``t1 = e_C1`` made orthogonal to ``n``, ``t2 = n x t1``
  (``axes``); contact frames ``{L}`` at ``x_C + R1 n`` and ``{K}`` at ``x_F - R2 n`` (``contact_frames``);
- node Jacobians of a section (``node_jacobians``) and body wrenches (``body_wrench``).

Production uses these where the compiled kernel (``kernel_jit``) does not apply: the start of a
pair's friction history (``material_frames``, ``system``) and exact stick (``mortar``).  The
complex-step oracle (``reference.py``) is built from them.  Complex inputs give complex-step
derivatives: branches are fixed on the real part, and the non-analytic SE(3) logarithm is
linearised exactly around its real part (``log_c``).
"""
import numpy as np

from ..lie import se3
from ..lie.se3 import cross as _cross, dot as _dot

__all__ = ["LINE", "ORTHOGONAL", "POINT", "NORMAL_TOL", "TOUCH_ROUNDOFF", "touch_tolerance", "no_normal",
           "log_c", "section", "project", "node_jacobians", "body_wrench", "axes", "contact_frames",
           "material_frames", "pose"]

LINE, ORTHOGONAL, POINT = 0, 1, 2
NORMAL_TOL = 1e-9        # centre distance / (R1 + R2) below which a pair has no contact normal
TOUCH_ROUNDOFF = 32.0    # touching tolerance / (eps (scene extent + R1 + R2)): the gap's round-off is ~1 such unit


def touch_tolerance(extent, R1, R2):
    """Gap below which a pair touches (the kernels' touching rule, ``reference.touching_gap``): ``TOUCH_ROUNDOFF eps (extent + R1 + R2)``,
    ``extent`` the largest node coordinate of the scene (its round-off in the centre-line distance),
    ``R1 + R2`` that of the distance itself (docs/theory_contact_tolerances.md)."""
    return TOUCH_ROUNDOFF * np.finfo(float).eps * (extent + R1 + R2)


def log_c(H):
    """SE(3) log that is exact under complex-step: ``log(H_r) + i T^-1 vee(Im(H_r^-1 H))``."""
    if not np.iscomplexobj(H):
        return se3.log(H)
    Hr = H.real
    h = se3.log(Hr)
    d = se3.vee(se3.relative(Hr, H).imag)
    return h + 1j * np.einsum("...ij,...j->...i", se3.tangent_inv(h), d)


def section(HA, h, xi):
    """Pose, position derivative ``dx/dxi`` and second derivative at ``xi``."""
    H = se3.compose(HA, se3.exp(xi[..., None] * h))
    R = H[..., :3, :3]
    u, w = h[..., :3], h[..., 3:]
    xp = np.einsum("...ij,...j->...i", R, u)
    xpp = np.einsum("...ij,...j->...i", R, _cross(w, u))
    return H, xp, xpp


def project(kind, HA1, h1, xi1, HA2, h2, xi2, iterations=3):
    """Newton on the projection conditions, starting from the search's real solution.

    Each kind's step is computed for every pair and selected with ``where``; a denominator is
    replaced by 1 where its kind is not the pair's (or where it is 0), so the branches a pair
    does not take never divide by a tiny number (an overflow warning for a value thrown away).
    """
    line, point = np.asarray(kind) == LINE, np.asarray(kind) == POINT
    for _ in range(iterations):
        H1, x1p, x1pp = section(HA1, h1, xi1)
        H2, x2p, x2pp = section(HA2, h2, xi2)
        d = H2[..., :3, 3] - H1[..., :3, 3]
        e1 = H1[..., :3, 0]
        # LINE: f = d . e_C1, df/dxi2 = x2' . e_C1
        f_line = _dot(d, e1)
        j_line = _dot(x2p, e1)
        # ORTHOGONAL: f = d . x2', df/dxi2 = x2'.x2' + d . x2''
        f_orth = _dot(d, x2p)
        j_orth = _dot(x2p, x2p) + _dot(d, x2pp)
        step2 = np.where(line, -f_line / np.where(line & (j_line != 0), j_line, 1.0),
                         -f_orth / np.where(np.logical_not(line) & (j_orth != 0), j_orth, 1.0))
        # POINT: F = (d . x1', d . x2') = 0, 2x2 Newton
        a11 = -_dot(x1p, x1p) + _dot(d, x1pp)
        a12 = _dot(x2p, x1p)
        a21 = -_dot(x1p, x2p)
        a22 = _dot(x2p, x2p) + _dot(d, x2pp)
        det = a11 * a22 - a12 * a21
        det = np.where(point & (det != 0), det, 1.0)
        g1, g2 = _dot(d, x1p), f_orth
        p1 = -(a22 * g1 - a12 * g2) / det
        p2 = -(-a21 * g1 + a11 * g2) / det
        xi1 = xi1 + np.where(point, p1, 0.0)
        xi2 = xi2 + np.where(point, p2, step2)
    return xi1, xi2


def node_jacobians(h, xi, E_h, E_xi):
    """``J_A, J_B`` with ``dq_C = J_A dq_A + J_B dq_B`` for ``H_C = H_A exp(xi h)``.

    ``J_B = xi T(xi h) T(h)^-1`` and ``J_A = Ad(exp(-xi h)) - xi T(xi h) T(-h)^-1``,
    with ``T(-h)^-1 = T(h)^-1 Ad(exp(-h))`` (from ``T(-h) = Ad(exp(h)) T(h)``), so one
    inverse tangent serves both.  ``E_h = exp(h) = H_A^-1 H_B``, ``E_xi = exp(xi h) = H_A^-1 H_C``.
    """
    JB = (se3.tangent(xi[..., None] * h) * xi[..., None, None]) @ se3.tangent_inv(h)
    JA = se3.adjoint(se3.inverse(E_xi)) - JB @ se3.adjoint(se3.inverse(E_h))
    return JA, JB


def body_wrench(H, F, m):
    R = H[..., :3, :3]
    return np.concatenate([np.einsum("...ji,...j->...i", R, F), np.einsum("...ji,...j->...i", R, m)], axis=-1)


def no_normal(dist, R1, R2):
    """Pairs whose centre lines (nearly) intersect: ``dist < NORMAL_TOL (R1 + R2)``, no normal."""
    return np.real(dist) < NORMAL_TOL * np.real(R1 + R2)


def axes(HC, HF, R1, R2):
    """Centre points, contact axes ``n, t1, t2`` and centre distance (docs/theory.md eqs. 6.2-6.3).

    Where the centre lines intersect (``no_normal``) there is no normal: ``n`` is then
    ``(nan, nan, nan)`` without a division by zero, and the caller must refuse the pair.
    """
    xC, xF = HC[..., :3, 3], HF[..., :3, 3]
    d = xF - xC
    dist = np.sqrt(_dot(d, d))
    bad = no_normal(dist, R1, R2) | (np.real(dist) == 0.0)
    n = np.where(bad[..., None], np.nan, d) / np.where(bad, 1.0, dist)[..., None]
    e1 = HC[..., :3, 0]
    t1 = e1 - _dot(e1, n)[..., None] * n
    t1 = t1 / np.sqrt(_dot(t1, t1))[..., None]
    return xC, xF, n, t1, _cross(n, t1), dist


def contact_frames(n, t1, t2, xC, xF, R1, R2):
    """``{L}`` at ``x_C + R1 n`` and ``{K}`` at ``x_F - R2 n``, axes ``(n, t1, t2)``."""
    frame = np.stack([n, t1, t2], axis=-1)
    return pose(frame, xC + R1[..., None] * n), pose(frame, xF - R2[..., None] * n)


def material_frames(X, kind, xi1, xi2, R1, R2, h1=None, h2=None):
    """Frames of a pair at fixed ``xi1, xi2`` (no projection): ``H_CL``, ``H_FK``, ``H_LK``.

    Used to start the friction history of a pair that has none: its material
    frames are those of the pair at the last converged poses ``X``.  ``h1``, ``h2``: the
    elements' twists ``log(H_A^-1 H_B)`` there if known (else computed).
    """
    HA1, HB1, HA2, HB2 = X[..., 0, :, :], X[..., 1, :, :], X[..., 2, :, :], X[..., 3, :, :]
    h1 = se3.log(se3.relative(HA1, HB1)) if h1 is None else h1
    h2 = se3.log(se3.relative(HA2, HB2)) if h2 is None else h2
    HC, _, _ = section(HA1, h1, xi1)
    HF, _, _ = section(HA2, h2, xi2)
    xC, xF, n, t1, t2, _ = axes(HC, HF, R1, R2)
    HL, HK = contact_frames(n, t1, t2, xC, xF, R1, R2)
    return se3.relative(HC, HL), se3.relative(HF, HK), se3.relative(HL, HK)


def pose(R, x):
    """Poses ``(..., 4, 4)`` of rotations ``R`` ``(..., 3, 3)`` and positions ``x`` ``(..., 3)``."""
    H = np.zeros(R.shape[:-2] + (4, 4), dtype=R.dtype)
    H[..., :3, :3] = R
    H[..., :3, 3] = x
    H[..., 3, 3] = 1.0
    return H
