"""Compiled (numba) SE(3) kernels over one element: the scalar forms of ``se3``.

Vectors are 3-tuples and 3x3 matrices tuples of three rows, so a kernel keeps
its small algebra in registers and allocates nothing.  Conventions are those of
``se3`` (docs/theory.md section 1): twists ``(u, w)``, translation first, right
tangent operators.  Every singular coefficient switches from its nine-term
series to its closed form at the same point ``se3.SWITCH`` as the numpy
version, so both agree to round-off (``tests/elements/test_compiled_kernels.py``).

``NUMBA_DISABLE_JIT=1`` runs these functions as plain Python (slowly).
"""
import numpy as np
from .._jit import jit, jit_callee

from .se3 import ATAN_SERIES_RATIO, COEFFICIENT_NAMES, SERIES, SWITCH

# coefficient indices (rows of _SERIES_TABLE)
A_, B_, C_, D_, Q2_, Q3_, CP_, DP_, Q2P_, Q3P_ = (COEFFICIENT_NAMES.index(k) for k in
                                                 ("a", "b", "c", "d", "q2", "q3", "cp", "dp", "q2p", "q3p"))
_SERIES_TABLE = np.array([SERIES[k] for k in COEFFICIENT_NAMES])
_SWITCH = np.array([SWITCH[k] for k in COEFFICIENT_NAMES])


# ---------------------------------------------------------------- coefficients
@jit_callee
def _closed(k, t):
    """Closed form of coefficient ``k`` at ``t > 0`` (formulas of ``se3``)."""
    s, c = np.sin(t), np.cos(t)
    if k == A_:
        return s / t
    if k == B_:
        h = np.sin(0.5 * t) / (0.5 * t)
        return 0.5 * h * h
    if k == C_:
        return (t - s) / t**3
    if k == D_:
        return (1.0 - 0.5 * t / np.tan(0.5 * t)) / t**2
    if k == Q2_:
        return (t * t + 2.0 * c - 2.0) / (2.0 * t**4)
    if k == Q3_:
        return (2.0 * t - 3.0 * s + t * c) / (2.0 * t**5)
    if k == CP_:
        return (3.0 * s - t * c - 2.0 * t) / t**5
    if k == DP_:
        h = np.sin(0.5 * t)
        return (t * t / (h * h) + 2.0 * t / np.tan(0.5 * t) - 8.0) / (4.0 * t**4)
    if k == Q2P_:
        return (-t * t - t * s - 4.0 * c + 4.0) / t**6
    return (-8.0 * t + 15.0 * s - 7.0 * t * c - t * t * s) / (2.0 * t**7)


@jit_callee
def coefficient(k, t):
    """Singular coefficient number ``k`` (``se3.COEFFICIENT_NAMES``) at the angle ``t >= 0``."""
    if t >= _SWITCH[k]:
        return _closed(k, t)
    row = _SERIES_TABLE[k]
    t2 = t * t
    v = row[8]
    for j in range(7, -1, -1):
        v = v * t2 + row[j]
    return v


# ---------------------------------------------------------------- 3-vectors and 3x3 matrices
@jit_callee
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit_callee
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@jit_callee
def axpy(s, a, b):
    """``s a + b``."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


@jit_callee
def scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


@jit_callee
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@jit_callee
def mat(skew, diag):
    """``hat(skew) + diag I``."""
    return ((diag, -skew[2], skew[1]), (skew[2], diag, -skew[0]), (-skew[1], skew[0], diag))


@jit_callee
def add_outer(M, l, r):
    """``M + l r^T``."""
    return ((M[0][0] + l[0] * r[0], M[0][1] + l[0] * r[1], M[0][2] + l[0] * r[2]),
            (M[1][0] + l[1] * r[0], M[1][1] + l[1] * r[1], M[1][2] + l[1] * r[2]),
            (M[2][0] + l[2] * r[0], M[2][1] + l[2] * r[1], M[2][2] + l[2] * r[2]))


@jit_callee
def madd(A, B):
    return (add(A[0], B[0]), add(A[1], B[1]), add(A[2], B[2]))


@jit_callee
def mscale(s, A):
    return (scale(s, A[0]), scale(s, A[1]), scale(s, A[2]))


@jit_callee
def transpose(A):
    return ((A[0][0], A[1][0], A[2][0]), (A[0][1], A[1][1], A[2][1]), (A[0][2], A[1][2], A[2][2]))


@jit_callee
def mv(A, v):
    return (dot(A[0], v), dot(A[1], v), dot(A[2], v))


@jit_callee
def _row(a, B):
    return (a[0] * B[0][0] + a[1] * B[1][0] + a[2] * B[2][0],
            a[0] * B[0][1] + a[1] * B[1][1] + a[2] * B[2][1],
            a[0] * B[0][2] + a[1] * B[1][2] + a[2] * B[2][2])


@jit_callee
def mm(A, B):
    return (_row(A[0], B), _row(A[1], B), _row(A[2], B))


@jit_callee
def ti(w, d, v, sign):
    """``Ti v`` (sign +1) or ``Ti^T v`` (sign -1), ``Ti = T_SO3(w)^-1 = I + W/2 + d W^2``."""
    wv = cross(w, v)
    return add(add(v, scale(0.5 * sign, wv)), scale(d, cross(w, wv)))


@jit_callee
def ti_matrix(w, d, t2):
    """``T_SO3(w)^-1 = hat(w)/2 + d w w^T + (1 - d t^2) I``."""
    return add_outer(mat(scale(0.5, w), 1.0 - d * t2), scale(d, w), w)


@jit_callee
def q_matrix(u, w, wu, a, t2, c1, c2, c3):
    """``Q(u, w)`` (docs/theory.md eq. 2.6), ``wu = w.u``, ``a = w x u``, ``t2 = |w|^2`` (as ``elements.geometric._q_mat``)."""
    M = mat(add(scale(0.5 - 2.0 * c2 * t2, u), scale((3.0 * c2 - c1) * wu, w)), (2.0 * c3 * t2 - 2.0 * c1) * wu)
    M = add_outer(M, add(scale(c1, u), add(scale(-c2, a), scale(-2.0 * c3 * wu, w))), w)
    return add_outer(M, w, add(scale(c1, u), scale(c2, a)))


# ---------------------------------------------------------------- poses
@jit_callee
def mtm(A, B):
    """``A^T B`` of 3x3 tuples."""
    return mm(transpose(A), B)


@jit_callee
def pose(H, e):
    """Rotation (3x3 tuple) and position (3-tuple) of the pose ``H[e]`` of an array ``(n, 4, 4)``."""
    return (((H[e, 0, 0], H[e, 0, 1], H[e, 0, 2]), (H[e, 1, 0], H[e, 1, 1], H[e, 1, 2]),
             (H[e, 2, 0], H[e, 2, 1], H[e, 2, 2])), (H[e, 0, 3], H[e, 1, 3], H[e, 2, 3]))


@jit_callee
def log_relative(RA, xA, RB, xB):
    """``log(H_A^-1 H_B)`` as ``u, w`` tuples, ``t = |w|`` and ``d``; rotations 3x3 tuples, positions 3-tuples.

    Rotation vector through the unit quaternion (Shepperd's choice of the
    largest component, as ``se3.log_so3``: nothing divides by ``sin t``).
    """
    R = mtm(RA, RB)
    x = mv(transpose(RA), add(xB, scale(-1.0, xA)))
    tr = R[0][0] + R[1][1] + R[2][2]
    if tr >= R[0][0] and tr >= R[1][1] and tr >= R[2][2]:
        q = (1.0 + tr, R[2][1] - R[1][2], R[0][2] - R[2][0], R[1][0] - R[0][1])
    elif R[0][0] >= R[1][1] and R[0][0] >= R[2][2]:
        q = (R[2][1] - R[1][2], 1.0 + R[0][0] - R[1][1] - R[2][2], R[0][1] + R[1][0], R[0][2] + R[2][0])
    elif R[1][1] >= R[2][2]:
        q = (R[0][2] - R[2][0], R[0][1] + R[1][0], 1.0 - R[0][0] + R[1][1] - R[2][2], R[1][2] + R[2][1])
    else:
        q = (R[1][0] - R[0][1], R[0][2] + R[2][0], R[1][2] + R[2][1], 1.0 - R[0][0] - R[1][1] + R[2][2])
    inv = 1.0 / np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if q[0] < 0.0:
        inv = -inv
    qw, qv = q[0] * inv, (q[1] * inv, q[2] * inv, q[3] * inv)
    s = np.sqrt(dot(qv, qv))
    if s < ATAN_SERIES_RATIO * qw:        # 2 atan(x)/x / qw, x = s / qw: series
        x2 = (s / qw) ** 2
        series = 1.0 / 17.0
        for k in range(7, -1, -1):
            series = series * x2 + (-1.0) ** k / (2 * k + 1)
        factor = 2.0 * series / qw
    else:
        factor = 2.0 * np.arctan2(s, qw) / s
    w = scale(factor, qv)
    t = np.sqrt(dot(w, w))
    d = coefficient(D_, t)
    return ti(w, d, x, -1.0), w, t, d


@jit_callee
def exp_pose(u, w, out):
    """``exp(hat(u, w))`` into the pose ``out`` (4, 4)."""
    t = np.sqrt(dot(w, w))
    a, b, c = coefficient(A_, t), coefficient(B_, t), coefficient(C_, t)
    M = add_outer(mat(scale(a, w), 1.0 - b * dot(w, w)), scale(b, w), w)   # I + a W + b W^2
    wxu = cross(w, u)
    x = add(add(u, scale(b, wxu)), scale(c, cross(w, wxu)))
    for i in range(3):
        for j in range(3):
            out[i, j] = M[i][j]
        out[i, 3] = x[i]
        out[3, i] = 0.0
    out[3, 3] = 1.0


@jit_callee
def compose_into(A, B, out):
    """``out = A @ B`` for poses (4, 4); ``out`` may be ``A`` or ``B``."""
    r0 = (A[0, 0] * B[0, 0] + A[0, 1] * B[1, 0] + A[0, 2] * B[2, 0],
          A[0, 0] * B[0, 1] + A[0, 1] * B[1, 1] + A[0, 2] * B[2, 1],
          A[0, 0] * B[0, 2] + A[0, 1] * B[1, 2] + A[0, 2] * B[2, 2],
          A[0, 0] * B[0, 3] + A[0, 1] * B[1, 3] + A[0, 2] * B[2, 3] + A[0, 3])
    r1 = (A[1, 0] * B[0, 0] + A[1, 1] * B[1, 0] + A[1, 2] * B[2, 0],
          A[1, 0] * B[0, 1] + A[1, 1] * B[1, 1] + A[1, 2] * B[2, 1],
          A[1, 0] * B[0, 2] + A[1, 1] * B[1, 2] + A[1, 2] * B[2, 2],
          A[1, 0] * B[0, 3] + A[1, 1] * B[1, 3] + A[1, 2] * B[2, 3] + A[1, 3])
    r2 = (A[2, 0] * B[0, 0] + A[2, 1] * B[1, 0] + A[2, 2] * B[2, 0],
          A[2, 0] * B[0, 1] + A[2, 1] * B[1, 1] + A[2, 2] * B[2, 1],
          A[2, 0] * B[0, 2] + A[2, 1] * B[1, 2] + A[2, 2] * B[2, 2],
          A[2, 0] * B[0, 3] + A[2, 1] * B[1, 3] + A[2, 2] * B[2, 3] + A[2, 3])
    for j in range(4):
        out[0, j], out[1, j], out[2, j], out[3, j] = r0[j], r1[j], r2[j], 0.0
    out[3, 3] = 1.0
