"""The tangent terms of segment points whose segment ends move (``integration="segments"``).

A segment's point ``p`` sits at ``xi_p = a + (b - a) x_g`` with the weight ``W_p = (b - a) w_g L_e``,
and its ends ``a``, ``b`` move with the poses (``projection.segment_bounds``: the slave section plane
through a master node, ``g(s) = (x_N - x_C(s)) . e_C1(s) = 0``).  The kernel's tangent holds ``xi_p``
and ``W_p`` fixed; this module adds, over the pair's 4 nodes (slave A, B, master A, B),

    K_p += df_p/dxi (x) dxi_p/dq + (f_p / W_p) (x) dW_p/dq,

``ds/dq = -(dg/dq) / (dg/ds)`` for an end ``s`` not clipped to the slave element's ends (0 there):
``dg/dq`` through the section's body increment ``eps = J_A dq_A + J_B dq_B`` (``frames.node_jacobians``),
``dg/deps = (-E1, E1 x R_C^T d)``, ``d = x_N - x_C``, and the master node's translation ``R_N^T e_C1``;
``dg/ds = d . e_C1' - x_C' . e_C1`` (compiled, ``_end_gradient``).  ``df_p/dxi`` (configuration fixed) is a
forward difference of the kernel's forces in ``xi`` (``STEP``: one more kernel call), for the points of
segments with a moving end only.  docs/theory_mortar.md section 7.
"""
import numpy as np

from .._jit import jit
from ..lie.se3_jit import add, cross, dot, log_relative, mm, mv, scale, transpose
from .kernel_jit import _adjoint_inv, _exp, _pose_of, _tangent, _tangent_inv

__all__ = ["end_gradients", "end_terms", "STEP"]

STEP = 1e-7       # forward difference of the forces in xi (truncation ~STEP, round-off ~1e-16 / STEP)
CLIPPED = 1e-12   # an end this close to the slave element's end is taken as clipped there (it does not move)


@jit
def _end_gradient(X, s, clipped, out):
    """``ds/dq`` into ``out`` ``(k, 24)`` for segment ends ``s`` ``(k,)`` over the 4 node poses ``X`` ``(k, 4, 4, 4)``
    (0 where ``clipped``); the master node whose section plane defines ``s`` is the one nearer to it.
    ``J_B = s T(s h) T(h)^-1``, ``J_A = Ad(exp(-s h)) - J_B Ad(exp(-h))`` (``frames.node_jacobians``) as rows."""
    T, Ti, As, Ah = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6))
    rT, rB, rA = np.empty(6), np.empty(6), np.empty(6)
    for k in range(len(s)):
        for c in range(24):
            out[k, c] = 0.0
        if clipped[k]:
            continue
        RA, xA = _pose_of(X[k], 0)
        RB, xB = _pose_of(X[k], 1)
        u, w, _, _ = log_relative(RA, xA, RB, xB)
        sk = s[k]
        su, sw = scale(sk, u), scale(sk, w)
        Rs, ps = _exp(su, sw)
        RC = mm(RA, Rs)
        xC = add(mv(RA, ps), xA)
        e1 = (RC[0][0], RC[1][0], RC[2][0])
        _, x2 = _pose_of(X[k], 2)
        _, x3 = _pose_of(X[k], 3)
        node = 2 if abs(dot(add(x2, scale(-1.0, xC)), e1)) <= abs(dot(add(x3, scale(-1.0, xC)), e1)) else 3
        RN, xN = _pose_of(X[k], node)
        d = add(xN, scale(-1.0, xC))
        D = mv(transpose(RC), d)
        row = (-1.0, 0.0, 0.0, 0.0, -D[2], D[1])                       # dg/deps: (-E1, E1 x D)
        gs = dot(d, mv(RC, (0.0, w[2], -w[1]))) - dot(mv(RC, u), e1)    # dg/ds
        inv = -1.0 / (gs if gs != 0.0 else 1.0)
        _tangent(su, sw, T)
        _tangent_inv(u, w, Ti)
        _adjoint_inv(Rs, ps, As)
        Rh, ph = _exp(u, w)
        _adjoint_inv(Rh, ph, Ah)
        for j in range(6):
            acc = 0.0
            for i in range(6):
                acc += row[i] * T[i, j]
            rT[j] = acc
        for j in range(6):
            acc = 0.0
            for i in range(6):
                acc += rT[i] * Ti[i, j]
            rB[j] = sk * acc
        for j in range(6):
            acc = 0.0
            for i in range(6):
                acc += row[i] * As[i, j] - rB[i] * Ah[i, j]
            rA[j] = acc
        for j in range(6):
            out[k, j] = inv * rA[j]
            out[k, 6 + j] = inv * rB[j]
        eN = mv(transpose(RN), e1)
        for j in range(3):
            out[k, 6 * node + j] = inv * eN[j]


def end_gradients(X, a, b):
    """``da/dq``, ``db/dq`` ``(k, 24)`` of segments ``[a, b]`` over the pairs' 4 node poses ``X``; an end at
    the slave element's end (clipped) does not move."""
    X = np.ascontiguousarray(X, dtype=float)
    da, db = np.empty((len(a), 24)), np.empty((len(b), 24))
    _end_gradient(X, np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(a <= CLIPPED), da)
    _end_gradient(X, np.ascontiguousarray(b, dtype=float), np.ascontiguousarray(b >= 1.0 - CLIPPED), db)
    return da, db


def end_terms(X, xi, weight, x_g, w_g, length, f, forces):
    """The tangent terms ``(k, 24, 24)`` of segment points: poses ``X`` ``(k, 4, 4, 4)``, parameters ``xi`` and
    weights ``weight`` ``(k,)``, their Gauss point ``x_g`` and weight ``w_g`` on ``[0, 1]``, slave element
    ``length``, the points' forces ``f`` ``(k, 24)`` (residual signs) and ``forces(rows, xi)``: the forces
    ``(r, 24)`` of the points ``rows`` moved to ``xi``.  Returns the rows with a moving end and their terms
    ``(r, 24, 24)``."""
    span = weight / (w_g * length)
    a = xi - span * x_g
    b = a + span
    moving = np.flatnonzero((a > CLIPPED) | (b < 1.0 - CLIPPED))
    out = np.zeros((len(xi), 24, 24))
    if not len(moving):
        return moving, out[:0]
    a, b, x_g, xi = a[moving], b[moving], x_g[moving], xi[moving]
    da, db = end_gradients(X[moving], a, b)
    dxi = (1.0 - x_g)[:, None] * da + x_g[:, None] * db
    dW = (w_g[moving] * length[moving])[:, None] * (db - da)
    dfdxi = (forces(moving, xi + STEP) - f[moving]) / STEP
    per_length = f[moving] / np.where(weight[moving] == 0.0, 1.0, weight[moving])[:, None]
    return moving, dfdxi[:, :, None] * dxi[:, None, :] + per_length[:, :, None] * dW[:, None, :]
