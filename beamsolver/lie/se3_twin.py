"""Compiled twins of ``se3``'s batched numpy maps that give the same bits.

The contact search and the start of a pair's friction history go through ``se3.log``, ``se3.exp``,
``se3.compose`` and ``se3.relative`` (numpy).  The compiled scalar kernels of ``se3_jit`` agree with
them to round-off only, and a round-off change moves the Newton iteration counts of the contact
examples (docs/benchmarks.md).  The functions here run the numpy operations in the same order:

- a product of 3x3 blocks (numpy's ``@``, the BLAS ``dgemm`` of numpy's OpenBLAS) is the fused
  multiply-add chain ``fma(a2, b2, fma(a1, b1, a0 b0))`` per entry (``fma``: LLVM's ``llvm.fma``,
  one rounding); matrix-vector products (``einsum``) and dot products are left-to-right sums of
  rounded products;
- the transcendental functions (``arctan2``, ``tan``, ``sin``) are numpy's own, called on whole
  arrays between compiled passes: numpy's SIMD versions differ from the C library's in the last bit.

So a twin is checked against its numpy original bit for bit (``tests/lie/test_se3_twin.py``) on
the machine it runs on; where the BLAS does not fuse (another CPU) the two agree to round-off.
"""
import math
from fractions import Fraction

import numpy as np
from llvmlite import ir
from numba import config, types as nb_types
from numba.extending import intrinsic

from .._jit import jit, jit_callee
from .se3 import ATAN_SERIES_RATIO, COEFFICIENT_NAMES, SERIES, SWITCH, coefficient

__all__ = ["fma", "coefficient_table", "log_relative", "exp_compose", "relative", "relative_into", "compose_into",
           "compose_members", "turn_global"]

_SERIES_TABLE = np.array([SERIES[k] for k in COEFFICIENT_NAMES])

_D_SERIES = np.array(SERIES["d"])
_D_SWITCH = SWITCH["d"]
_ATAN_SERIES = np.array([(-1) ** k / (2 * k + 1) for k in range(9)])   # the terms of ``se3.log_so3``


@intrinsic
def _fma_intrinsic(typingctx, a, b, c):
    """``a b + c`` rounded once (LLVM ``llvm.fma.f64``)."""
    sig = nb_types.float64(nb_types.float64, nb_types.float64, nb_types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        f = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(f, [context.cast(builder, v, t, nb_types.float64) for v, t in zip(args, signature.args)])

    return sig, codegen


def _fma_python(a, b, c):
    """``fma`` as plain Python (``NUMBA_DISABLE_JIT=1``): exact rationals, rounded once."""
    if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c)):
        return a * b + c
    exact = Fraction(a) * Fraction(b) + Fraction(c)
    try:
        return float(exact)
    except OverflowError:
        return math.inf if exact > 0 else -math.inf


fma = _fma_python if config.DISABLE_JIT else _fma_intrinsic


@jit_callee
def _mm_entry(A, i, B, j):
    """Entry ``(i, j)`` of ``A @ B`` for 3x3 blocks (arrays or views), numpy's order."""
    return fma(A[i, 2], B[2, j], fma(A[i, 1], B[1, j], A[i, 0] * B[0, j]))


@jit_callee
def _mtm_entry(A, i, B, j):
    """Entry ``(i, j)`` of ``A^T @ B`` (``se3.relative``'s ``swapaxes(A) @ B``), numpy's order."""
    return fma(A[2, i], B[2, j], fma(A[1, i], B[1, j], A[0, i] * B[0, j]))


@jit
def _series(rows, t, out):
    """``out[i, k]``: the nine-term series of coefficient ``rows[i]`` at ``t[k]`` (``se3.coefficient``'s Horner)."""
    for k in range(len(t)):
        t2 = t[k] * t[k]
        for i in range(len(rows)):
            row = _SERIES_TABLE[rows[i]]
            v = row[8]
            for j in range(7, -1, -1):
                v = v * t2 + row[j]
            out[i, k] = v


def coefficient_table(names, t):
    """``se3.coefficient(name, t)`` of each of ``names`` ``(len(names), n)``, the same bits: the series
    compiled, the closed forms (numpy's trig) only at angles from the coefficient's switch point."""
    t = np.ascontiguousarray(t, dtype=float)
    out = np.empty((len(names), len(t)))
    _series(np.array([COEFFICIENT_NAMES.index(k) for k in names]), t, out)
    for i, name in enumerate(names):
        big = t >= SWITCH[name]
        if big.any():
            out[i, big] = coefficient(name, t[big])
    return out


@jit_callee
def compose_into(A, B, out):
    """``out = se3.compose(A, B)`` for one pair of poses ``(4, 4)`` (``out`` not ``A`` nor ``B``)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = _mm_entry(A, i, B, j)
        out[i, 3] = ((A[i, 0] * B[0, 3] + A[i, 1] * B[1, 3]) + A[i, 2] * B[2, 3]) + A[i, 3]
        out[3, i] = 0.0
    out[3, 3] = 1.0


@jit
def _compose_members(H, members, reps, X):
    for k in range(len(members)):
        compose_into(H[reps[k]], X[k], H[members[k]])


def compose_members(H, members, reps, X):
    """``H[members] = se3.compose(H[reps], X)`` in place, the same bits (``members`` and ``reps`` disjoint)."""
    _compose_members(H, np.ascontiguousarray(members), np.ascontiguousarray(reps), np.ascontiguousarray(X))


@jit
def _turn(H, g, dz, coef):
    W, E, R = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))
    for k in range(len(g)):
        n = g[k]
        w0, w1, w2 = dz[n, 3], dz[n, 4], dz[n, 5]
        W[0, 0], W[0, 1], W[0, 2] = 0.0, -w2, w1
        W[1, 0], W[1, 1], W[1, 2] = w2, 0.0, -w0
        W[2, 0], W[2, 1], W[2, 2] = -w1, w0, 0.0
        a, b = coef[0, k], coef[1, k]
        for i in range(3):
            for j in range(3):
                E[i, j] = ((1.0 if i == j else 0.0) + a * W[i, j]) + b * _mm_entry(W, i, W, j)
        for i in range(3):
            H[n, i, 3] += dz[n, i]
            for j in range(3):
                R[i, j] = H[n, i, j]
        for i in range(3):
            for j in range(3):
                H[n, i, j] = _mm_entry(E, i, R, j)


def turn_global(H, g, dz):
    """Global increments of the nodes ``g`` in place (``assembly.System.update``'s numpy form, its bits):
    ``x += dz[:3]``, ``R <- se3.exp_so3(dz[3:]) @ R``; ``dz`` ``(n, 6)``."""
    g = np.ascontiguousarray(g)
    w = dz[g, 3:]
    t = np.sqrt(w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1] + w[:, 2] * w[:, 2])
    _turn(H, g, np.ascontiguousarray(dz, dtype=float), coefficient_table(("a", "b"), t))


@jit_callee
def relative_into(A, B, out):
    """``out = se3.relative(A, B)`` for one pair of poses ``(4, 4)``."""
    v0, v1, v2 = B[0, 3] - A[0, 3], B[1, 3] - A[1, 3], B[2, 3] - A[2, 3]
    for i in range(3):
        for j in range(3):
            out[i, j] = _mtm_entry(A, i, B, j)
        out[i, 3] = A[0, i] * v0 + A[1, i] * v1 + A[2, i] * v2
        out[3, i] = 0.0
    out[3, 3] = 1.0


@jit
def _relative(A, B, out):
    for k in range(len(A)):
        relative_into(A[k], B[k], out[k])


def relative(A, B):
    """``se3.relative(A, B)`` ``(n, 4, 4)`` of poses ``(n, 4, 4)``, the same bits."""
    A, B = np.ascontiguousarray(A, dtype=float), np.ascontiguousarray(B, dtype=float)
    out = np.empty(A.shape)
    _relative(A, B, out)
    return out


# ---------------------------------------------------------------- log(A^-1 B) of node pairs
@jit
def _log_quaternion(H, a, b, x, q, s):
    """Pass 1 of ``log_relative``: ``x`` ``(n, 3)`` the relative position, ``q`` ``(n, 4)`` the unit
    quaternion (``se3.quaternion``, ``qw >= 0``) of the relative rotation, ``s = |q_v|``."""
    R = np.empty((3, 3))
    for k in range(len(a)):
        A, B = H[a[k]], H[b[k]]
        for i in range(3):
            for j in range(3):
                R[i, j] = _mtm_entry(A, i, B, j)
        v0, v1, v2 = B[0, 3] - A[0, 3], B[1, 3] - A[1, 3], B[2, 3] - A[2, 3]
        for i in range(3):
            x[k, i] = A[0, i] * v0 + A[1, i] * v1 + A[2, i] * v2
        r00, r11, r22 = R[0, 0], R[1, 1], R[2, 2]
        tr = r00 + r11 + r22
        d21, d02, d10 = R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]
        s01, s02, s12 = R[0, 1] + R[1, 0], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1]
        if tr >= r00 and tr >= r11 and tr >= r22:      # np.argmax: the first of equal largest
            q0, q1, q2, q3 = 1.0 + tr, d21, d02, d10
        elif r00 >= r11 and r00 >= r22:
            q0, q1, q2, q3 = d21, 1.0 + r00 - r11 - r22, s01, s02
        elif r11 >= r22:
            q0, q1, q2, q3 = d02, s01, 1.0 - r00 + r11 - r22, s12
        else:
            q0, q1, q2, q3 = d10, s02, s12, 1.0 - r00 - r11 + r22
        nrm = np.sqrt(((q0 * q0 + q1 * q1) + q2 * q2) + q3 * q3)
        q0, q1, q2, q3 = q0 / nrm, q1 / nrm, q2 / nrm, q3 / nrm
        if q0 < 0.0:
            q0, q1, q2, q3 = -q0, -q1, -q2, -q3
        q[k, 0], q[k, 1], q[k, 2], q[k, 3] = q0, q1, q2, q3
        s[k] = np.sqrt(q1 * q1 + q2 * q2 + q3 * q3)


@jit
def _log_rotation(q, s, atan, out, t):
    """Pass 2: the rotation vectors ``out[:, 3:]`` (``se3.log_so3``; ``atan = arctan2(s, qw)``) and
    their angles ``t``."""
    for k in range(len(s)):
        qw, sk = q[k, 0], s[k]
        if sk < ATAN_SERIES_RATIO * qw:
            x2 = (sk / qw) * (sk / qw)
            series = 0.0
            for j in range(8, -1, -1):
                series = series * x2 + _ATAN_SERIES[j]
            f = 2.0 * series / qw
        else:
            f = 2.0 * atan[k] / sk
        w0, w1, w2 = f * q[k, 1], f * q[k, 2], f * q[k, 3]
        out[k, 3], out[k, 4], out[k, 5] = w0, w1, w2
        t[k] = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)


@jit
def _log_translation(x, t, tan_half, out):
    """Pass 3: ``out[:, :3] = T_SO3(w)^-T x`` (``se3.log``; ``tan_half = tan(t / 2)``)."""
    for k in range(len(t)):
        tk = t[k]
        if tk < _D_SWITCH:
            t2 = tk * tk
            d = _D_SERIES[8]
            for j in range(7, -1, -1):
                d = d * t2 + _D_SERIES[j]
        else:
            d = (1.0 - 0.5 * tk / tan_half[k]) / (tk * tk)
        w0, w1, w2 = out[k, 3], out[k, 4], out[k, 5]
        x0, x1, x2 = x[k, 0], x[k, 1], x[k, 2]
        c0, c1, c2 = w1 * x2 - w2 * x1, w2 * x0 - w0 * x2, w0 * x1 - w1 * x0
        e0, e1, e2 = w1 * c2 - w2 * c1, w2 * c0 - w0 * c2, w0 * c1 - w1 * c0
        out[k, 0] = x0 - 0.5 * c0 + d * e0
        out[k, 1] = x1 - 0.5 * c1 + d * e1
        out[k, 2] = x2 - 0.5 * c2 + d * e2


def log_relative(H, a, b):
    """``se3.log(se3.relative(H[a], H[b]))`` ``(n, 6)`` of the node pairs ``a``, ``b`` ``(n,)`` of the
    poses ``H`` ``(N, 4, 4)``, the same bits (three compiled passes around numpy's ``arctan2`` and
    ``tan``; nothing gathered)."""
    H = np.ascontiguousarray(H, dtype=float)
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    n = len(a)
    x, q, s = np.empty((n, 3)), np.empty((n, 4)), np.empty(n)
    _log_quaternion(H, a, b, x, q, s)
    out, t = np.empty((n, 6)), np.empty(n)
    _log_rotation(q, s, np.arctan2(s, q[:, 0]), out, t)
    big = t >= _D_SWITCH
    tan_half = np.ones(n)
    if big.any():
        tan_half[big] = np.tan(0.5 * t[big])
    _log_translation(x, t, tan_half, out)
    return out


# ---------------------------------------------------------------- H_A exp(xi h)
@jit_callee
def exp_compose_into(A, u0, u1, u2, w0, w1, w2, a, b, c, out):
    """``out = se3.compose(A, se3.exp((u, w)))`` with the coefficients ``a, b, c`` of ``|w|``
    (``se3.coefficient``), numpy's order: ``I + a W + b (W @ W)``, ``u + b w x u + c w x (w x u)``."""
    W = np.empty((3, 3))
    W[0, 0], W[0, 1], W[0, 2] = 0.0, -w2, w1
    W[1, 0], W[1, 1], W[1, 2] = w2, 0.0, -w0
    W[2, 0], W[2, 1], W[2, 2] = -w1, w0, 0.0
    E = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            E[i, j] = ((1.0 if i == j else 0.0) + a * W[i, j]) + b * _mm_entry(W, i, W, j)
    c0, c1, c2 = w1 * u2 - w2 * u1, w2 * u0 - w0 * u2, w0 * u1 - w1 * u0
    x0 = (u0 + b * c0) + c * (w1 * c2 - w2 * c1)
    x1 = (u1 + b * c1) + c * (w2 * c0 - w0 * c2)
    x2 = (u2 + b * c2) + c * (w0 * c1 - w1 * c0)
    for i in range(3):
        for j in range(3):
            out[i, j] = _mm_entry(A, i, E, j)
        out[i, 3] = ((A[i, 0] * x0 + A[i, 1] * x1) + A[i, 2] * x2) + A[i, 3]
        out[3, i] = 0.0
    out[3, 3] = 1.0


@jit
def _exp_compose(H, a, h, xi, coef, out):
    for k in range(len(a)):
        x = xi[k]
        exp_compose_into(H[a[k]], x * h[k, 0], x * h[k, 1], x * h[k, 2], x * h[k, 3], x * h[k, 4], x * h[k, 5],
                         coef[0, k], coef[1, k], coef[2, k], out[k])


def exp_angles(h, xi):
    """The rotation angles ``|xi w|`` ``(n,)`` of ``se3.exp(xi h)`` (as ``se3.rotation_angle``)."""
    w = xi[:, None] * h[:, 3:]
    return np.sqrt(w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1] + w[:, 2] * w[:, 2])


def exp_compose(H, a, h, xi):
    """``se3.compose(H[a], se3.exp(xi[:, None] * h))`` ``(n, 4, 4)`` (``se3.interpolate``), the same bits;
    ``a`` ``(n,)`` node indices into ``H`` ``(N, 4, 4)``, ``h`` ``(n, 6)``, ``xi`` ``(n,)``."""
    h, xi = np.ascontiguousarray(h, dtype=float), np.ascontiguousarray(xi, dtype=float)
    out = np.empty((len(a), 4, 4))
    _exp_compose(np.ascontiguousarray(H, dtype=float), np.ascontiguousarray(a), h, xi,
                 coefficient_table(("a", "b", "c"), exp_angles(h, xi)), out)
    return out
