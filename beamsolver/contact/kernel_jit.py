"""Compiled (numba) contact kernel with its exact tangent, one contact point per call.

The same maths, arguments and results as ``pairs.contact_kernel`` /
``pairs.kernel_and_tangent`` (their complex-step version is the test oracle,
``tests/test_contact_kernel_jit.py``): projection (the same two Newton
iterations), section frames ``{C}``, ``{F}``, axes ``n, t1, t2``, gap, normal
law, friction (material frames, slip ``log(H_LK_prev^-1 H_LK)[1:3]`` as
``kinematics.slip_increment``, transported traction, slip-tolerance penalty,
Coulomb return mapping) and the nodal wrenches ``J^T w``.

The tangent is forward mode done by hand: every quantity carries its gradient
``(k, 24)`` with respect to the body increments of the nodes ``A1, B1, A2, B2``
(column ``6 j + k``).  Section frames vary as ``dq_C = J_A dq_A + J_B dq_B + h dxi``
(``pairs._node_jacobians``), the twist as ``dh = T(h)^-1 (dq_B - Ad(exp(-h)) dq_A)``,
the projection parameters by the implicit-function theorem at the converged
projection, and the node Jacobians themselves through

- ``d(T(h)^-T v)/dh = G(h, v)`` (``element_jit._geometric``),
- ``d(T(s)^T w)/ds = -T(s)^T G(s, T(s)^T w)``,
- ``d(Ad(exp(-s))^T w)/ds = -M(z) T(-s)``, ``z = Ad(exp(-s))^T w``,
  ``M(z) = [[0, hat(z_f)], [hat(z_f), hat(z_m)]]``.

One difference from the numpy kernel, where that one decides on a whole batch:
the ``active`` flag of the normal law is decided per point (the numpy kernel uses
the smoothed rule for every point of a batch in which any point has a smoothing
gap; the two differ only at a trial traction of exactly zero).
The contact law is pluggable: the kernel calls ``_normal_law`` and
``_tangential_law``, which ``make_kernel`` binds to a ``law.ContactLaw``'s compiled
scalar functions (default ``law.PENALTY_COULOMB``, tested equal to the numpy forms
``law.normal_force`` and ``law.coulomb_return_mapping`` the oracle uses).
``NUMBA_DISABLE_JIT=1`` runs this module as plain Python (slowly).
"""
import hashlib
import types

import numpy as np

from .._jit import jit
from ..element_jit import _geometric
from ..se3_jit import (A_, B_, C_, CP_, D_, DP_, Q2P_, Q2_, Q3P_, Q3_, add, add_outer, coefficient, cross, dot,
                       log_relative, mat, mm, mv, q_matrix, scale, ti_matrix, transpose)
from .law import PENALTY_COULOMB
from .pairs import LINE, ORTHOGONAL, PENALTY_T_MIN

# columns of the per-point parameter table ``par``
XI1, XI2, R1_, R2_, WEIGHT, PENALTY, MULT, MU, PEN_T, SMOOTH, ESLIP, XI1P, XI2P = range(13)
N_PAR = 13


# the law, bound per kernel by ``make_kernel`` (the templates below call these names)
_normal_law = _tangential_law = None


# ---------------------------------------------------------------- small algebra (tuples, 6x6 arrays)
@jit
def _exp(u, w):
    """``exp(hat(u, w))`` as rotation and position tuples (``se3.exp``)."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    a, b, c = coefficient(A_, t), coefficient(B_, t), coefficient(C_, t)
    R = add_outer(mat(scale(a, w), 1.0 - b * t2), scale(b, w), w)
    wxu = cross(w, u)
    return R, add(add(u, scale(b, wxu)), scale(c, cross(w, wxu)))


@jit
def _section(RA, xA, u, w, xi):
    """Pose of ``H_A exp(xi h)``, ``x' = R u`` and ``x'' = R (w x u)`` (``pairs._section``)."""
    Rs, xs = _exp(scale(xi, u), scale(xi, w))
    R = mm(RA, Rs)
    return R, add(mv(RA, xs), xA), mv(R, u), mv(R, cross(w, u))


@jit
def _pose_of(X, j):
    R = ((X[j, 0, 0], X[j, 0, 1], X[j, 0, 2]), (X[j, 1, 0], X[j, 1, 1], X[j, 1, 2]),
         (X[j, 2, 0], X[j, 2, 1], X[j, 2, 2]))
    return R, (X[j, 0, 3], X[j, 1, 3], X[j, 2, 3])


@jit
def _put3(A, r0, c0, M):
    for i in range(3):
        for j in range(3):
            A[r0 + i, c0 + j] = M[i][j]


@jit
def _col(R, j):
    return (R[0][j], R[1][j], R[2][j])


@jit
def _mm6(A, B):
    """``A @ B`` for small 2-D arrays."""
    n, k, m = A.shape[0], A.shape[1], B.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for l in range(k):
            a = A[i, l]
            for j in range(m):
                out[i, j] += a * B[l, j]
    return out


@jit
def _mtm(A, B):
    """``A^T @ B`` for small 2-D arrays."""
    n, k, m = A.shape[1], A.shape[0], B.shape[1]
    out = np.zeros((n, m))
    for l in range(k):
        for i in range(n):
            a = A[l, i]
            for j in range(m):
                out[i, j] += a * B[l, j]
    return out


@jit
def _mtv(A, v):
    """``A^T v`` for a 2-D array and a 1-D array."""
    out = np.zeros(A.shape[1])
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            out[j] += A[i, j] * v[i]
    return out


@jit
def _tangent(u, w):
    """``T(h) = [[T3, Q(-u, -w)], [0, T3]]`` (``se3.tangent``), ``(6, 6)``."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    b, c = coefficient(B_, t), coefficient(C_, t)
    T3 = add_outer(mat(scale(-b, w), 1.0 - c * t2), scale(c, w), w)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), dot(w, u), cross(w, u), t2, c, coefficient(Q2_, t),
                 coefficient(Q3_, t))
    T = np.zeros((6, 6))
    _put3(T, 0, 0, T3)
    _put3(T, 3, 3, T3)
    _put3(T, 0, 3, Q)
    return T


@jit
def _tangent_inv(u, w):
    """``T(h)^-1 = [[Ti, -Ti Q(-u, -w) Ti], [0, Ti]]`` (``se3.tangent_inv``), ``(6, 6)``."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    c = coefficient(C_, t)
    Ti = ti_matrix(w, coefficient(D_, t), t2)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), dot(w, u), cross(w, u), t2, c, coefficient(Q2_, t),
                 coefficient(Q3_, t))
    X = mm(mm(Ti, Q), Ti)
    T = np.zeros((6, 6))
    _put3(T, 0, 0, Ti)
    _put3(T, 3, 3, Ti)
    _put3(T, 0, 3, ((-X[0][0], -X[0][1], -X[0][2]), (-X[1][0], -X[1][1], -X[1][2]),
                    (-X[2][0], -X[2][1], -X[2][2])))
    return T


@jit
def _adjoint(R, x):
    """``Ad(H) = [[R, hat(x) R], [0, R]]``, ``(6, 6)``."""
    A = np.zeros((6, 6))
    _put3(A, 0, 0, R)
    _put3(A, 3, 3, R)
    _put3(A, 0, 3, mm(mat(x, 0.0), R))
    return A


@jit
def _adjoint_inv(R, x):
    """``Ad(H^-1)`` of the pose ``(R, x)``."""
    Rt = transpose(R)
    return _adjoint(Rt, scale(-1.0, mv(Rt, x)))


@jit
def _geo(u, w, v):
    """``G(h, v) = d(T(h)^-T v)/dh``, ``(6, 6)`` (``element_jit._geometric``)."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    co = (coefficient(C_, t), coefficient(Q2_, t), coefficient(Q3_, t), coefficient(DP_, t), coefficient(CP_, t),
          coefficient(Q2P_, t), coefficient(Q3P_, t))
    G12, G21, G22 = _geometric(u, w, (v[0], v[1], v[2]), (v[3], v[4], v[5]), coefficient(D_, t), t2, co)
    G = np.zeros((6, 6))
    _put3(G, 0, 3, G12)
    _put3(G, 3, 0, G21)
    _put3(G, 3, 3, G22)
    return G


@jit
def _m_times(z, A):
    """``M(z) A`` with ``M(z) = [[0, hat(z_f)], [hat(z_f), hat(z_m)]]``, column by column."""
    zf, zm = (z[0], z[1], z[2]), (z[3], z[4], z[5])
    out = np.empty((6, A.shape[1]))
    for k in range(A.shape[1]):
        au, aw = (A[0, k], A[1, k], A[2, k]), (A[3, k], A[4, k], A[5, k])
        top, bot = cross(zf, aw), add(cross(zf, au), cross(zm, aw))
        for i in range(3):
            out[i, k], out[3 + i, k] = top[i], bot[i]
    return out


# ---------------------------------------------------------------- node Jacobians and their derivative
@jit
def _jacobians(u, w, xi, Ti):
    """``J_A, J_B`` of ``H_C = H_A exp(xi h)`` (``pairs._node_jacobians``); ``Ti = T(h)^-1``."""
    JB = _mm6(_tangent(scale(xi, u), scale(xi, w)), Ti)
    JB *= xi
    Rs, xs = _exp(scale(xi, u), scale(xi, w))
    Rh, xh = _exp(u, w)
    JA = _adjoint_inv(Rs, xs) - _mm6(JB, _adjoint_inv(Rh, xh))
    return JA, JB


@jit
def _jacobian_derivatives(u, w, xi, wr, Ti):
    """``d(J_A^T wr)/dh, d(J_B^T wr)/dh`` ``(6, 6)`` and ``d/dxi`` ``(6,)`` at fixed ``wr``.

    With ``s = xi h``, ``y = T(s)^T wr``, ``b = J_B^T wr = xi T(h)^-T y`` and ``T(-s) h = h``:
    ``dB/dh = G(h, xi y) - xi^2 T(h)^-T T(s)^T G(s, y)``, ``dB/dxi = T(h)^-T y - xi T(h)^-T T(s)^T G(s, y) h``,
    ``dA/dh = -xi M(z_s) T(-s) + M(z_h) T(-h) - Ad(exp(-h))^T dB/dh``, ``dA/dxi = -M(z_s) h - Ad(exp(-h))^T dB/dxi``.
    """
    su, sw = scale(xi, u), scale(xi, w)
    Ts = _tangent(su, sw)
    y = _mtv(Ts, wr)
    P = _mtm(Ti, _mtm(Ts, _geo(su, sw, y)))            # T(h)^-T T(s)^T G(s, y)
    DB = _geo(u, w, xi * y)
    dB = _mtv(Ti, y)
    h = (u[0], u[1], u[2], w[0], w[1], w[2])
    for i in range(6):
        acc = 0.0
        for j in range(6):
            DB[i, j] -= xi * xi * P[i, j]
            acc += P[i, j] * h[j]
        dB[i] -= xi * acc
    b = _mtv(Ti, xi * y)
    Rs, xs = _exp(su, sw)
    Rh, xh = _exp(u, w)
    As, Ah = _adjoint_inv(Rs, xs), _adjoint_inv(Rh, xh)
    zs = _mtv(As, wr)
    DA = _m_times(_mtv(Ah, b), _tangent(scale(-1.0, u), scale(-1.0, w)))
    Ms = _m_times(zs, _tangent(scale(-xi, u), scale(-xi, w)))
    AhDB = _mtm(Ah, DB)
    hh = np.array(h).reshape(6, 1)
    dA = _m_times(zs, hh)[:, 0]
    AhdB = _mtv(Ah, dB)
    for i in range(6):
        dA[i] = -dA[i] - AhdB[i]
        for j in range(6):
            DA[i, j] -= xi * Ms[i, j] + AhDB[i, j]
    return DA, DB, dA, dB


# ---------------------------------------------------------------- projection and its derivative
@jit
def _project(kind, RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2, iterations=2):
    """Newton iterations of ``pairs._project`` (two in the kernel, from the search's converged point)."""
    for _ in range(iterations):
        R1, x1, x1p, x1pp = _section(RA1, xA1, u1, w1, xi1)
        R2, x2, x2p, x2pp = _section(RA2, xA2, u2, w2, xi2)
        d = add(x2, scale(-1.0, x1))
        e1 = _col(R1, 0)
        if kind == LINE:
            j = dot(x2p, e1)
            xi2 = xi2 - dot(d, e1) / (j if j != 0.0 else 1.0)
        elif kind == ORTHOGONAL:
            j = dot(x2p, x2p) + dot(d, x2pp)
            xi2 = xi2 - dot(d, x2p) / (j if j != 0.0 else 1.0)
        else:
            a11 = -dot(x1p, x1p) + dot(d, x1pp)
            a12, a21 = dot(x2p, x1p), -dot(x1p, x2p)
            a22 = dot(x2p, x2p) + dot(d, x2pp)
            det = a11 * a22 - a12 * a21
            det = det if det != 0.0 else 1.0
            g1, g2 = dot(d, x1p), dot(d, x2p)
            xi1 = xi1 - (a22 * g1 - a12 * g2) / det
            xi2 = xi2 - (-a21 * g1 + a11 * g2) / det
    return xi1, xi2


@jit
def _rot_rows(R, V, r0):
    """``R @ V[r0:r0+3]`` ``(3, 24)``, ``R`` a 3x3 tuple."""
    out = np.empty((3, V.shape[1]))
    for i in range(3):
        out[i] = R[i][0] * V[r0] + R[i][1] * V[r0 + 1] + R[i][2] * V[r0 + 2]
    return out


@jit
def _row_dot(a, M, r0):
    """``a . M[r0:r0+3]`` over the 24 columns."""
    return a[0] * M[r0] + a[1] * M[r0 + 1] + a[2] * M[r0 + 2]


@jit
def _projection_gradient(kind, RC, u1, w1, RF, u2, w2, d, VC0, VF0, Dh1, Dh2):
    """``dxi1, dxi2`` ``(24,)`` by the implicit-function theorem at the converged projection.

    ``VC0``, ``VF0``: section-frame variations at fixed ``xi`` ``(6, 24)``; ``Dh1``, ``Dh2``:
    twist variations.  The Jacobians (and their zero guards) are those of ``_project``.
    """
    x1p, x2p = mv(RC, u1), mv(RF, u2)
    x1pp, x2pp = mv(RC, cross(w1, u1)), mv(RF, cross(w2, u2))
    dC, dF = mv(transpose(RC), d), mv(transpose(RF), d)
    dxC = _rot_rows(RC, VC0, 0)                           # position variations (3, 24)
    dxF = _rot_rows(RF, VF0, 0)
    rel = dxF - dxC
    # g2 = d . x2' (orthogonal / point), at fixed xi
    g2 = _row_dot(x2p, rel, 0) + _row_dot(cross(u2, dF), VF0, 3) + _row_dot(dF, Dh2, 0)
    z = np.zeros(24)
    if kind == LINE:
        e1 = _col(RC, 0)
        g = _row_dot(e1, rel, 0) - dC[2] * VC0[4] + dC[1] * VC0[5]
        j = dot(x2p, e1)
        return z, -g / (j if j != 0.0 else 1.0)
    if kind == ORTHOGONAL:
        j = dot(x2p, x2p) + dot(d, x2pp)
        return z, -g2 / (j if j != 0.0 else 1.0)
    g1 = _row_dot(x1p, rel, 0) + _row_dot(cross(u1, dC), VC0, 3) + _row_dot(dC, Dh1, 0)
    a11 = -dot(x1p, x1p) + dot(d, x1pp)
    a12, a21 = dot(x2p, x1p), -dot(x1p, x2p)
    a22 = dot(x2p, x2p) + dot(d, x2pp)
    det = a11 * a22 - a12 * a21
    det = det if det != 0.0 else 1.0
    return -(a22 * g1 - a12 * g2) / det, -(-a21 * g1 + a11 * g2) / det


# ---------------------------------------------------------------- one side of a pair: element, section, Jacobians
@jit
def _element_side(Xp, j0, xi):
    """Twist, section pose and Jacobians of the element of nodes ``j0, j0 + 1`` at ``xi``."""
    RA, xA = _pose_of(Xp, j0)
    RB, xB = _pose_of(Xp, j0 + 1)
    u, w, t, d = log_relative(RA, xA, RB, xB)
    return RA, xA, u, w


@jit
def _twist_variation(u, w, c0, Ti):
    """``dh = T(h)^-1 (dq_B - Ad(exp(-h)) dq_A)`` as ``(6, 24)``; node A at column ``c0``."""
    Rh, xh = _exp(u, w)
    D = np.zeros((6, 24))
    D[:, c0:c0 + 6] = -_mm6(Ti, _adjoint_inv(Rh, xh))
    D[:, c0 + 6:c0 + 12] = Ti
    return D


@jit
def _frame_variation(JA, JB, c0):
    V = np.zeros((6, 24))
    V[:, c0:c0 + 6] = JA
    V[:, c0 + 6:c0 + 12] = JB
    return V


# ---------------------------------------------------------------- 3-vectors with gradients (3, 24)
@jit
def _cross_rows(a, D):
    """``a x D[:, k]`` for every column ``k``."""
    out = np.empty((3, D.shape[1]))
    out[0] = a[1] * D[2] - a[2] * D[1]
    out[1] = a[2] * D[0] - a[0] * D[2]
    out[2] = a[0] * D[1] - a[1] * D[0]
    return out


@jit
def _axes(RC, xC, RF, xF, VC, VF):
    """``n, t1, t2`` (``pairs._axes``), centre distance, and the gradients of ``n, t1, t2, dist``
    (one pass over the 24 columns)."""
    d = add(xF, scale(-1.0, xC))
    dist = np.sqrt(dot(d, d))
    n = scale(1.0 / dist, d)
    e1, e2, e3 = _col(RC, 0), _col(RC, 1), _col(RC, 2)
    c = dot(e1, n)
    t1r = add(e1, scale(-c, n))
    lt = np.sqrt(dot(t1r, t1r))
    t1 = scale(1.0 / lt, t1r)
    t2 = cross(n, t1)
    Dn, Dt1, Dt2, Ddist = np.empty((3, 24)), np.empty((3, 24)), np.empty((3, 24)), np.empty(24)
    for k in range(24):
        dF = mv(RF, (VF[0, k], VF[1, k], VF[2, k]))
        dC = mv(RC, (VC[0, k], VC[1, k], VC[2, k]))
        dd = add(dF, scale(-1.0, dC))
        nd = dot(n, dd)
        dn = scale(1.0 / dist, add(dd, scale(-nd, n)))
        de1 = add(scale(VC[5, k], e2), scale(-VC[4, k], e3))
        dc = dot(n, de1) + dot(e1, dn)
        dt1r = add(add(de1, scale(-dc, n)), scale(-c, dn))
        dt1 = scale(1.0 / lt, add(dt1r, scale(-dot(t1, dt1r), t1)))
        dt2 = add(cross(n, dt1), scale(-1.0, cross(t1, dn)))
        for i in range(3):
            Dn[i, k], Dt1[i, k], Dt2[i, k] = dn[i], dt1[i], dt2[i]
        Ddist[k] = nd
    return n, t1, t2, dist, Dn, Dt1, Dt2, Ddist


# ---------------------------------------------------------------- friction
@jit
def _pose4(H):
    R = ((H[0, 0], H[0, 1], H[0, 2]), (H[1, 0], H[1, 1], H[1, 2]), (H[2, 0], H[2, 1], H[2, 2]))
    return R, (H[0, 3], H[1, 3], H[2, 3])


@jit
def _compose(RA, xA, RB, xB):
    return mm(RA, RB), add(mv(RA, xB), xA)


@jit
def _slip(side1, side2, Ti1, Ti2, xi1p, xi2p, HCL, HFK, HLKp):
    """Slip ``log(H_LK_prev^-1 H_LK)[1:3]`` of the material frames (``kinematics.slip_increment``)
    and its gradient ``(2, 24)``."""
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    RCm, xCm, _, _ = _section(RA1, xA1, u1, w1, xi1p)
    RFm, xFm, _, _ = _section(RA2, xA2, u2, w2, xi2p)
    RCL, xCL = _pose4(HCL)
    RFK, xFK = _pose4(HFK)
    RL, xL = _compose(RCm, xCm, RCL, xCL)
    RK, xK = _compose(RFm, xFm, RFK, xFK)
    RLt = transpose(RL)
    RLK, xLK = mm(RLt, RK), mv(RLt, add(xK, scale(-1.0, xL)))
    RP, xP = _pose4(HLKp)
    dyu, dyw, _, _ = log_relative(RP, xP, RLK, xLK)
    Tdy = _tangent_inv(dyu, dyw)[1:3].copy()
    Rs, xs = _compose(RCL, xCL, RLK, xLK)
    As = _mm6(Tdy, _adjoint_inv(Rs, xs))
    Am = _mm6(Tdy, _adjoint_inv(RFK, xFK))
    JA1, JB1 = _jacobians(u1, w1, xi1p, Ti1)
    JA2, JB2 = _jacobians(u2, w2, xi2p, Ti2)
    D = np.empty((2, 24))
    D[:, 0:6] = -_mm6(As, JA1)
    D[:, 6:12] = -_mm6(As, JB1)
    D[:, 12:18] = _mm6(Am, JA2)
    D[:, 18:24] = _mm6(Am, JB2)
    return (dyu[1], dyu[2]), D


def _friction(slip, Dslip, lamp, t1, t2, Dt1, Dt2, lam, Dlam, par):
    """Transported stored traction, tangential penalty, trial traction and the law's tangential part
    (``_tangential_law``, bound by ``make_kernel``); ``lam_t``, its gradient ``(2, 24)``, ``stick``."""
    lp = (dot(lamp, t1), dot(lamp, t2))
    Dlp = np.empty((2, 24))
    Dlp[0] = _row_dot(lamp, Dt1, 0)
    Dlp[1] = _row_dot(lamp, Dt2, 0)
    npv = np.sqrt(dot(lamp, lamp))
    nl = np.sqrt(lp[0] * lp[0] + lp[1] * lp[1])
    if nl > 1e-300 * (1.0 + npv):
        s = npv / nl
        l0, l1 = lp[0] / nl, lp[1] / nl
        proj = l0 * Dlp[0] + l1 * Dlp[1]
        Dprev = s * (Dlp - np.outer(np.array([l0, l1]), proj))
        lam_prev = (lp[0] * s, lp[1] * s)
    else:
        Dprev = np.zeros((2, 24))
        lam_prev = (0.0, 0.0)
    pen_t, mu = par[PEN_T], par[MU]
    Dpt = np.zeros(24)
    if np.isnan(pen_t) and not np.isnan(par[ESLIP]):
        lam_min = PENALTY_T_MIN * par[PENALTY] * par[ESLIP]      # pairs.stick_penalty
        if lam >= lam_min:
            pen_t = mu * lam / par[ESLIP]
            Dpt = (mu / par[ESLIP]) * Dlam
        else:
            pen_t = mu * lam_min / par[ESLIP]
    tr0, tr1 = lam_prev[0] + pen_t * slip[0], lam_prev[1] + pen_t * slip[1]
    Dtr = Dprev + np.outer(np.array(slip), Dpt) + pen_t * Dslip
    lt0, lt1, D, stick = _tangential_law(tr0, tr1, Dtr, mu, lam, Dlam)
    return (lt0, lt1), D, stick


# ---------------------------------------------------------------- one contact point
@jit
def _wrench(R, F, DF, m, Dm, V):
    """Body wrench ``(R^T F, R^T m)`` and its gradient; ``V``: the frame's variation ``(6, 24)``;
    ``d(R^T F)/dtheta = hat(R^T F)``."""
    Rt = transpose(R)
    bF, bm = mv(Rt, F), mv(Rt, m)
    w = np.array([bF[0], bF[1], bF[2], bm[0], bm[1], bm[2]])
    D = np.empty((6, 24))
    for k in range(24):
        th = (V[3, k], V[4, k], V[5, k])
        a = add(mv(Rt, (DF[0, k], DF[1, k], DF[2, k])), cross(bF, th))
        b = add(mv(Rt, (Dm[0, k], Dm[1, k], Dm[2, k])), cross(bm, th))
        for i in range(3):
            D[i, k], D[3 + i, k] = a[i], b[i]
    return w, D


@jit
def _nodal(u, w, xi, Ti, JA, JB, wr, Dw, Dh, dxi, c0, f, K, j0):
    """``f_j = J_j^T wr`` for the two nodes of one side and their rows of the tangent:
    ``J^T dwr + d(J^T wr)/dh dh + d(J^T wr)/dxi dxi`` (``dh`` lives in columns ``c0:c0+12``)."""
    DA, DB, dA, dB = _jacobian_derivatives(u, w, xi, wr, Ti)
    for s in range(2):
        J, D, dd = (JA, DA, dA) if s == 0 else (JB, DB, dB)
        r0 = 6 * (j0 + s)
        for i in range(6):
            acc = 0.0
            for l in range(6):
                acc += J[l, i] * wr[l]
            f[j0 + s, i] = acc
            for c in range(24):
                K[r0 + i, c] = dd[i] * dxi[c]
            for l in range(6):
                a = J[l, i]
                for c in range(24):
                    K[r0 + i, c] += a * Dw[l, c]
                b = D[i, l]
                for c in range(c0, c0 + 12):
                    K[r0 + i, c] += b * Dh[l, c]


@jit
def _store_frames(frames, n, t1, t2, RC, xC, RF, xF, R1, R2):
    """``HL, HK, HC, HF`` (``pairs._contact_frames``)."""
    for k in range(4):
        frames[k, :, :] = 0.0
        frames[k, 3, 3] = 1.0
    for i in range(3):
        for k in range(2):
            frames[k, i, 0], frames[k, i, 1], frames[k, i, 2] = n[i], t1[i], t2[i]
        frames[0, i, 3] = xC[i] + R1 * n[i]
        frames[1, i, 3] = xF[i] - R2 * n[i]
        for j in range(3):
            frames[2, i, j], frames[3, i, j] = RC[i][j], RF[i][j]
        frames[2, i, 3], frames[3, i, 3] = xC[i], xF[i]


def _point(Xp, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames):
    """Forces ``f (4, 6)``, tangent ``K (24, 24)`` and point data of one contact point."""
    side1, side2 = _element_side(Xp, 0, 0.0), _element_side(Xp, 2, 0.0)
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    xi1, xi2 = _project(kind, RA1, xA1, u1, w1, par[XI1], RA2, xA2, u2, w2, par[XI2])
    RC, xC, _, _ = _section(RA1, xA1, u1, w1, xi1)
    RF, xF, _, _ = _section(RA2, xA2, u2, w2, xi2)
    Ti1, Ti2 = _tangent_inv(u1, w1), _tangent_inv(u2, w2)
    JA1, JB1 = _jacobians(u1, w1, xi1, Ti1)
    JA2, JB2 = _jacobians(u2, w2, xi2, Ti2)
    Dh1, Dh2 = _twist_variation(u1, w1, 0, Ti1), _twist_variation(u2, w2, 12, Ti2)
    VC, VF = _frame_variation(JA1, JB1, 0), _frame_variation(JA2, JB2, 12)
    d = add(xF, scale(-1.0, xC))
    dxi1, dxi2 = _projection_gradient(kind, RC, u1, w1, RF, u2, w2, d, VC, VF, Dh1, Dh2)
    h1 = np.array([u1[0], u1[1], u1[2], w1[0], w1[1], w1[2]])
    h2 = np.array([u2[0], u2[1], u2[2], w2[0], w2[1], w2[2]])
    VC += np.outer(h1, dxi1)
    VF += np.outer(h2, dxi2)
    n, t1, t2, dist, Dn, Dt1, Dt2, Ddist = _axes(RC, xC, RF, xF, VC, VF)
    R1, R2, wgt = par[R1_], par[R2_], par[WEIGHT]
    gap = dist - R1 - R2
    lam, dlam, active = _normal_law(gap, par[PENALTY], par[MULT], par[SMOOTH])      # bound by make_kernel
    Dlam = dlam * Ddist
    F = scale(-wgt * lam, n)
    DF = -wgt * (np.outer(np.array(n), Dlam) + lam * Dn)
    lt, stick, slip = (0.0, 0.0), True, (0.0, 0.0)
    if friction:
        Dslip = np.zeros((2, 24))
        if has:
            slip, Dslip = _slip(side1, side2, Ti1, Ti2, par[XI1P], par[XI2P], HCL, HFK, HLKp)
        lt, Dlt, stick = _friction(slip, Dslip, lamp, t1, t2, Dt1, Dt2, lam, Dlam, par)
        if active:
            F = add(F, add(scale(wgt * lt[0], t1), scale(wgt * lt[1], t2)))
            DF += wgt * (np.outer(np.array(t1), Dlt[0]) + lt[0] * Dt1 + np.outer(np.array(t2), Dlt[1]) + lt[1] * Dt2)
        else:
            lt = (0.0, 0.0)
        _store_frames(frames, n, t1, t2, RC, xC, RF, xF, R1, R2)
    mF = cross(n, F)
    DmF = _cross_rows(n, DF) - _cross_rows(F, Dn)
    wC, DwC = _wrench(RC, F, DF, scale(R1, mF), R1 * DmF, VC)
    wF, DwF = _wrench(RF, scale(-1.0, F), -DF, scale(R2, mF), R2 * DmF, VF)
    _nodal(u1, w1, xi1, Ti1, JA1, JB1, wC, DwC, Dh1, dxi1, 0, f, K, 0)
    _nodal(u2, w2, xi2, Ti2, JA2, JB2, wF, DwF, Dh2, dxi2, 12, f, K, 2)
    sc[0], sc[1], sc[2], sc[3] = gap, lam, xi1, xi2
    for i in range(3):
        vec[0, i], vec[1, i], vec[2, i], vec[3, i], vec[4, i], vec[5, i] = n[i], t1[i], t2[i], xC[i], xF[i], F[i]
    two[0, 0], two[0, 1], two[1, 0], two[1, 1] = lt[0], lt[1], slip[0], slip[1]
    flags[0], flags[1] = active, stick


def _evaluate(X, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames):
    """Batch driver: ``_point`` over all pairs (a plain loop; one core).  A template: ``make_kernel``
    compiles it per contact law; the module's ``evaluate`` is the default law's."""
    for p in range(X.shape[0]):
        _point(X[p], kind[p], par[p], has[p], HCL[p], HFK[p], HLKp[p], lamp[p], friction, f[p], K[p], sc[p],
               vec[p], two[p], flags[p], frames[p])


# ---------------------------------------------------------------- the kernel of a contact law
_LAW_PATH = ("_friction", "_point", "_evaluate")      # the templates on the call path to the law, callee first
_TEMPLATES = {name: globals()[name] for name in _LAW_PATH}
_KERNELS = {}


def _code_bytes(code):
    """Bytes identifying a code object's instructions, names and constants (stable across processes)."""
    consts = b"".join(_code_bytes(c) if isinstance(c, types.CodeType) else repr(c).encode() for c in code.co_consts)
    return code.co_code + repr(code.co_names).encode() + consts


def _digest(law):
    """Identity of a law's code: a law edited in place gets a new compiled kernel (and cache entry).
    Only the two functions' own code counts: after editing a helper they call, clear the numba
    cache (``__pycache__``) or rename the law."""
    code = [_code_bytes(getattr(f, "py_func", f).__code__) for f in (law.normal, law.tangential)]
    return hashlib.sha1(b"".join(code)).hexdigest()[:10]


def make_kernel(law):
    """The compiled batch driver ``_evaluate`` for ``law`` (a ``law.ContactLaw``), built once per process.

    The templates on the law's call path (``_friction``, ``_point``, ``_evaluate``) are copied
    with ``_normal_law`` and ``_tangential_law`` bound to the law's functions as globals, under
    the name ``<template>__<law name>_<code digest>``: numba's disk cache (``cache=True``) keys
    on that name and the template's source file, so each law's kernel compiles once per machine
    and loads from the cache afterwards (closures or functions passed as arguments are
    recompiled in every process, measured with numba 0.68).
    """
    key = f"{law.name}_{_digest(law)}"
    if key not in _KERNELS:
        glb = dict(globals(), _normal_law=law.normal, _tangential_law=law.tangential)
        for name in _LAW_PATH:
            t = _TEMPLATES[name]
            f = types.FunctionType(t.__code__, glb, f"{name}__{key}", t.__defaults__)
            f.__qualname__, f.__doc__ = f.__name__, t.__doc__
            glb[name] = jit(f)
        _KERNELS[key] = glb["_evaluate"]
    return _KERNELS[key]


evaluate = make_kernel(PENALTY_COULOMB)


@jit
def _project_all(kind, HA1, h1, xi1, HA2, h2, xi2, iterations, out1, out2):
    for p in range(len(kind)):
        RA1, xA1 = _pose_of(HA1, p)
        RA2, xA2 = _pose_of(HA2, p)
        out1[p], out2[p] = _project(kind[p], RA1, xA1, (h1[p, 0], h1[p, 1], h1[p, 2]), (h1[p, 3], h1[p, 4], h1[p, 5]),
                                    xi1[p], RA2, xA2, (h2[p, 0], h2[p, 1], h2[p, 2]),
                                    (h2[p, 3], h2[p, 4], h2[p, 5]), xi2[p], iterations)


def project(kind, HA1, h1, xi1, HA2, h2, xi2, iterations=3):
    """Compiled ``pairs._project`` (same arguments, batches ``(P, ...)``): ``xi1, xi2`` after
    ``iterations`` Newton iterations on the projection conditions of each pair's ``kind``."""
    P = len(h1)
    args = [np.ascontiguousarray(np.broadcast_to(a, (P,) + np.shape(a)[-s:] if s else (P,)), dtype=float)
            for a, s in ((HA1, 2), (h1, 1), (xi1, 0), (HA2, 2), (h2, 1), (xi2, 0))]
    kind = np.ascontiguousarray(np.broadcast_to(kind, (P,)), dtype=np.int64)
    out1, out2 = np.empty(P), np.empty(P)
    _project_all(kind, *args, int(iterations), out1, out2)
    return out1, out2


# ---------------------------------------------------------------- the signatures of pairs.py
def _table(X, p):
    P = X.shape[0]

    def col(name, default=np.nan):
        return np.broadcast_to(np.asarray(p.get(name, default), dtype=float), (P,))

    par = np.empty((P, N_PAR))
    for k, name in ((XI1, "xi1"), (XI2, "xi2"), (R1_, "R1"), (R2_, "R2"), (WEIGHT, "weight"),
                    (PENALTY, "penalty"), (MULT, "multiplier"), (MU, "mu"), (PEN_T, "penalty_t"),
                    (SMOOTH, "smoothing"), (ESLIP, "elastic_slip")):
        par[:, k] = col(name, 0.0 if name in ("smoothing", "multiplier") else np.nan)
    par[:, XI1P] = col("xi1_prev", 0.0) if "xi1_prev" in p else par[:, XI1]
    par[:, XI2P] = col("xi2_prev", 0.0) if "xi2_prev" in p else par[:, XI2]
    eye = np.broadcast_to(np.eye(4), (P, 4, 4))
    frames = [np.ascontiguousarray(np.broadcast_to(p.get(k, eye), (P, 4, 4)), dtype=float)
              for k in ("H_CL", "H_FK", "H_LK_prev")]
    lamp = np.ascontiguousarray(np.broadcast_to(p.get("lam_t_prev", np.zeros(3)), (P, 3)), dtype=float)
    has = np.ascontiguousarray(np.broadcast_to(p.get("has_history", False), (P,)), dtype=np.bool_)
    kind = np.ascontiguousarray(np.broadcast_to(p["kind"], (P,)), dtype=np.int64)
    return kind, par, has, frames, lamp


def kernel_and_tangent(X, p, friction=True, law=None):
    """Wrenches ``(P, 4, 6)``, exact tangent ``(P, 24, 24)`` and point data (``pairs.kernel_and_tangent``).

    ``X``: ``(P, 4, 4, 4)`` node poses ``A1, B1, A2, B2``; ``p``: the per-pair parameters of
    ``pairs.contact_kernel``.  Column ``6 j + k`` of the tangent is the body increment ``k``
    of node ``j``.  ``law``: a ``law.ContactLaw`` (default ``PENALTY_COULOMB``, the law of ``pairs.py``).
    """
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), lamp = _table(X, p)
    f, K = np.empty((P, 4, 6)), np.empty((P, 24, 24))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames = np.empty((P, 2), dtype=np.bool_), np.empty((P, 4, 4, 4))
    kern = evaluate if law is None else make_kernel(law)
    kern(X, kind, par, has, HCL, HFK, HLKp, lamp, bool(friction), f, K, sc, vec, two, flags, frames)
    out = dict(gap=sc[:, 0], lam_n=sc[:, 1], active=flags[:, 0], n=vec[:, 0], t1=vec[:, 1], t2=vec[:, 2],
               xC=vec[:, 3], xF=vec[:, 4], xi1=sc[:, 2], xi2=sc[:, 3], lam_t=two[:, 0], stick=flags[:, 1],
               slip=two[:, 1], F_slave=vec[:, 5])
    if friction:
        out.update(HL=frames[:, 0], HK=frames[:, 1], HC=frames[:, 2], HF=frames[:, 3])
    return f, K, out


def contact_kernel(X, p, friction=True, law=None):
    """Wrenches ``(P, 4, 6)`` and point data (``pairs.contact_kernel``, for batches ``(P, 4, 4, 4)``)."""
    f, _, out = kernel_and_tangent(X, p, friction, law)
    return f, out
