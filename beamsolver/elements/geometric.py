"""Geometric stiffness of a logarithm pair, ``G(h, s) = d(T(h)^-T s)/dh`` in closed form (numpy, batched).

``T(h)^-T s = [A n; A m - A Q(u, w) A n]`` with ``A = T_SO3(w)^-T``, ``h = (u, w)``,
``s = (n, m)`` (docs/theory.md eq. 3.7), differentiated term by term (``_geometric``).
Production for the three-node element (``se3_3``, per logarithm pair); the numpy oracle of
the two-node element (``reference``) shares the algebra.

Layout.  Inside, every quantity is stored with the element axis *last* (vectors ``(3, m)``,
3x3 blocks ``(3, 3, m)``): the small-index algebra is then elementwise operations on long
contiguous arrays.  Products of skew matrices are expanded with
``hat(a) hat(b) = b a^T - (a.b) I`` and ``hat(w)^2 = w w^T - |w|^2 I``, so ``Q``
(docs/theory.md eq. 2.6) and the geometric stiffness become sums of a skew matrix, a few
outer products and a multiple of ``I`` (``_mat``).
"""
from functools import partial

import numpy as np

from ..lie import se3
from ..lie.se3 import coefficient

__all__ = ["geometric", "TANGENT_COEFFICIENTS"]


# ---------------------------------------------------------------- batch-last algebra
_cross = partial(se3.cross, axis=0)   # vectors (3, m), element axis last
_dot = partial(se3.dot, axis=0)


def _crosses(a, *vs):
    """``a x v`` for each ``v`` in one operation."""
    r = _cross(a, np.stack(vs, axis=1))
    return [r[:, i] for i in range(len(vs))]


def _mm(A, B):
    """``A @ B`` for ``A`` (r, 3, m) and ``B`` (3, 3, m)."""
    return np.einsum("ikm,kjm->ijm", A, B)


def _mv(A, v):
    """``A @ v`` for ``A`` (3, 3, m) and ``v`` (3, m)."""
    return np.einsum("ijm,jm->im", A, v)


def _mat(skew=None, outers=(), diag=None):
    """``hat(skew) + sum(l r^T for l, r in outers) + diag I``, a (3, 3, m) matrix."""
    l, r = outers[0]
    M = l[:, None] * r[None, :]
    for l, r in outers[1:]:
        M += l[:, None] * r[None, :]
    if skew is not None:
        M[0, 1] -= skew[2]
        M[0, 2] += skew[1]
        M[1, 0] += skew[2]
        M[1, 2] -= skew[0]
        M[2, 0] -= skew[1]
        M[2, 1] += skew[0]
    if diag is not None:
        M[0, 0] += diag
        M[1, 1] += diag
        M[2, 2] += diag
    return M


def _ti(w, d, v, sign=1.0):
    """``Ti v`` (sign +1) or ``Ti^T v`` (sign -1), ``Ti = I + W/2 + d W^2``."""
    wv = _cross(w, v)
    return v + (0.5 * sign) * wv + d * _cross(w, wv)


def _q_mat(u, w, wu, a, t2, c1, c2, c3):
    """``Q(u, w)`` (3, 3, m), ``wu = w.u``, ``a = w x u``, ``t2 = |w|^2``.

    ``WU + UW + WUW = u w^T + w u^T - 2 (w.u) I - (w.u) W``,
    ``WWU + UWW - 3 WUW = w a^T - a w^T - 2 t^2 U + 3 (w.u) W``,
    ``WUWW + WWUW = -2 (w.u) (w w^T - t^2 I)``.
    """
    return _mat(skew=(0.5 - 2.0 * c2 * t2) * u + ((3.0 * c2 - c1) * wu) * w,
                outers=[(c1 * u - c2 * a - (2.0 * c3 * wu) * w, w), (w, c1 * u + c2 * a)],
                diag=(2.0 * c3 * t2 - 2.0 * c1) * wu)


# ---------------------------------------------------------------- coefficients
FORCE_COEFFICIENTS = ("c", "q2", "q3")
TANGENT_COEFFICIENTS = ("c", "q2", "q3", "dp", "cp", "q2p", "q3p")


# ---------------------------------------------------------------- geometric stiffness
def _d_tinv_t(w, d, dp, v):
    """``d(T_SO3(w)^-T v)/dw`` with ``T^-T v = v - w x v / 2 + d w x (w x v)``:

    ``hat(v)/2 + dp (w x (w x v)) w^T + d ((w.v) I + w v^T - 2 v w^T)``.
    """
    wwv = _cross(w, _cross(w, v))
    return _mat(skew=0.5 * v, outers=[(dp * wwv - 2.0 * d * v, w), (w, d * v)], diag=d * _dot(w, v))


def _geometric(u, w, n, mo, k):
    """Blocks of ``G(h, sigma) = d(T(h)^-T sigma)/dh = [[0, G12], [G21, G22]]`` (3, 3, m) each.

    ``T(h)^-T sigma = [A n; A m - A Q(u, w) A n]`` with ``A = T_SO3(w)^-T`` and
    ``Q(u, w) = Q(-u, -w)^T``, differentiated term by term with c1 = c,
    c2 = q2, c3 = q3 of se3 and their derivatives divided by t (c1p = cp, ...);
    with ``y = A n``, ``z = Q(u, w) y``, ``D(v) = d(A v)/dw``:
    ``G12 = D(n)``, ``G21 = -A dQ/du``, ``G22 = D(m - z) - A (dQ/dw + Q D(n))``,
    where ``dQ/du``, ``dQ/dw`` are the derivatives of ``Q(u, w) y`` at fixed ``y``.
    ``k``: dict of the coefficients and ``t2 = |w|^2``.
    """
    d, dp, t2 = k["d"], k["dp"], k["t2"]
    c1, c2, c3 = k["c"], k["q2"], k["q3"]
    y = _ti(w, d, n, -1.0)                                          # A n
    yw = _cross(w, y)
    yww = _cross(w, yw)
    a_, b_, e_ = _crosses(u, y, yw, yww)
    wa_, wb_, we_ = _crosses(w, a_, b_, e_)
    wwa_, wwb_ = _crosses(w, wa_, wb_)
    g1 = wa_ + b_ + wb_
    g2 = wwa_ + e_ - 3.0 * wb_
    g3 = we_ + wwb_
    z = 0.5 * a_ + c1 * g1 + c2 * g2 + c3 * g3                      # Q(u, w) y
    wy, uy, wu = _dot(w, y), _dot(u, y), _dot(w, u)
    uxw = _cross(u, w)
    # dQ/du = -(Y/2 + c1 (P Y + S1 + P S1) + c2 (PP Y + S2 - 3 P S1) + c3 (P S2 + PP S1)),
    # Y, S1, S2 = hat(y), hat(yw), hat(yww), P = hat(w), expanded (module docstring)
    dQu = _mat(skew=-((0.5 - c2 * t2) * y + (c1 - c3 * t2) * yw + c2 * yww),
               outers=[(-(c1 * y + (c1 - 3.0 * c2) * yw + c3 * yww), w), (w, -(c2 * yw + c3 * yww))],
               diag=c1 * wy)
    # dQ/dw = (c1p g1 + c2p g2 + c3p g3) w^T + c1 (-hat(a) - U Y - hat(b) - P U Y)
    #       + c2 (m(w, a) + U m(w, y) + 3 hat(b) + 3 P U Y) + c3 (-hat(e) + P U m(w, y) + m(w, b) - P P U Y),
    # m(w, v) = (w.v) I + w v^T - 2 v w^T, expanded
    gp = k["cp"] * g1 + k["q2p"] * g2 + k["q3p"] * g3
    dQw = _mat(skew=-c1 * a_ + (3.0 * c2 - c1) * b_ - c3 * e_ + ((c1 - 3.0 * c2) * uy) * w + (c2 * wy) * u,
               outers=[(gp - 4.0 * c2 * a_ + c3 * (wy * u - 2.0 * wa_ - 2.0 * b_ + uy * w), w),
                       ((c3 * t2 - c1) * y + (3.0 * c2 - c1) * yw - (c3 * wy) * w, u),
                       (w, c2 * a_ + c3 * b_),
                       (c2 * uxw + c3 * _cross(w, uxw), y)],
               diag=c1 * uy + c2 * _dot(w, a_) - c3 * wy * wu + c3 * _dot(w, b_) - c3 * t2 * uy)
    DAn = _d_tinv_t(w, d, dp, n)
    A = _mat(skew=-0.5 * w, outers=[(d * w, w)], diag=1.0 - d * t2)
    Q = _q_mat(u, w, wu, -uxw, t2, c1, c2, c3)
    G21 = -_mm(A, dQu)
    G22 = _d_tinv_t(w, d, dp, mo - z) - _mm(A, dQw + _mm(Q, DAn))
    return DAn, G21, G22


def geometric(h, s):
    """``G(h, s) = d(T(h)^-T s)/dh`` ``(n, 6, 6)`` for twists ``h`` and vectors ``s`` ``(n, 6)``.

    The closed form of ``_geometric`` (docs/theory.md eq. 3.7) in element-first layout: the
    geometric stiffness of one logarithm pair with the generalised force ``s`` held fixed.
    """
    h, s = np.asarray(h, dtype=float), np.asarray(s, dtype=float)
    u, w = h[:, :3].T, h[:, 3:].T
    t = np.sqrt(_dot(w, w))
    k = se3.coefficients(TANGENT_COEFFICIENTS, t)
    k.update(d=coefficient("d", t), t2=t * t)
    G12, G21, G22 = _geometric(u, w, s[:, :3].T, s[:, 3:].T, k)
    out = np.zeros((len(h), 6, 6))
    out[:, :3, 3:] = G12.transpose(2, 0, 1)
    out[:, 3:, :3] = G21.transpose(2, 0, 1)
    out[:, 3:, 3:] = G22.transpose(2, 0, 1)
    return out
