"""The two-node SE(3) beam element (Sonneville, Cardona & Bruls 2014), batched.

For an element with nodal poses ``H_A, H_B`` and reference length ``L``
(THEORY.md section 3):

- ``h = log(H_A^-1 H_B)``, strain ``eps = h / L`` (``Gamma`` then ``kappa``,
  section frame), section forces ``sigma = C (eps - eps0)``;
- energy ``V = L/2 (eps - eps0)^T C (eps - eps0)``;
- body-frame nodal forces ``f_A = -T(-h)^-T sigma``, ``f_B = T(h)^-T sigma``;
- tangent ``K = B^T (C/L) B + [G(-h, sigma); G(h, sigma)] B`` with
  ``B = [-T(-h)^-1, T(h)^-1]`` and ``G(h, s) = d(T(h)^-T s)/dh`` in closed
  form (derived below, checked against complex-step and finite differences in
  ``tests/test_element.py``).

All functions take arrays batched over elements: poses ``(n, 4, 4)``, ``L``
``(n,)``, ``eps0`` ``(n, 6)``, ``C`` ``(n, 6, 6)``.
"""
from typing import NamedTuple

import numpy as np

from . import se3
from .se3 import _cross, coefficient, skew

__all__ = ["ElementState", "element_state", "reference_strain", "energy",
           "internal_forces", "internal_forces_and_tangent"]


class ElementState(NamedTuple):
    h: np.ndarray       # (n, 6) relative twist log(H_A^-1 H_B)
    strain: np.ndarray  # (n, 6) h / L
    sigma: np.ndarray   # (n, 6) section forces (N, Q2, Q3, T, M2, M3)


def reference_strain(H_A, H_B):
    """Reference length ``L = |u0|`` and strain ``eps0 = h0 / L`` of reference poses."""
    h0 = se3.log(se3.relative(H_A, H_B))
    L = np.sqrt(np.einsum("...i,...i->...", h0[..., :3], h0[..., :3]))
    return L, h0 / L[..., None]


def element_state(H_A, H_B, L, eps0, C):
    h = se3.log(se3.relative(H_A, H_B))
    strain = h / L[:, None]
    sigma = np.einsum("nij,nj->ni", C, strain - eps0)
    return ElementState(h, strain, sigma)


def energy(H_A, H_B, L, eps0, C):
    """Strain energy per element, ``(n,)``."""
    s = element_state(H_A, H_B, L, eps0, C)
    de = s.strain - eps0
    return 0.5 * L * np.einsum("ni,ni->n", de, s.sigma)


def _tangent_inv_blocks(h):
    """Blocks of ``T(h)^-1 = [[Ti, X], [0, Ti]]`` and the pieces reused by ``G``."""
    u, w = h[..., :3], h[..., 3:]
    t = se3.rotation_angle(w)
    W = skew(w)
    WW = W @ W
    d = coefficient("d", t)
    Ti = np.eye(3) + 0.5 * W + d[..., None, None] * WW
    Qm = se3._q_matrix(-u, -w, t)
    X = -Ti @ Qm @ Ti
    return Ti, X, t, d


def _assemble_tinv(Ti, X, transpose_blocks=False):
    n = Ti.shape[:-2]
    out = np.zeros(n + (6, 6))
    if transpose_blocks:  # T(-h)^-1 is T(h)^-1 with every 3x3 block transposed
        Ti, X = np.swapaxes(Ti, -1, -2), np.swapaxes(X, -1, -2)
    out[..., :3, :3] = Ti
    out[..., 3:, 3:] = Ti
    out[..., :3, 3:] = X
    return out


def internal_forces(H_A, H_B, L, eps0, C):
    """Body-frame nodal forces ``(n, 12)`` (A then B) and the ``ElementState``."""
    s = element_state(H_A, H_B, L, eps0, C)
    Ti, X, _, _ = _tangent_inv_blocks(s.h)
    TiB = _assemble_tinv(Ti, X)
    TiA = _assemble_tinv(Ti, X, transpose_blocks=True)
    f = np.concatenate([-np.einsum("nji,nj->ni", TiA, s.sigma),
                        np.einsum("nji,nj->ni", TiB, s.sigma)], axis=-1)
    return f, s


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


def _m(w, a):
    """``d(w x (w x a))/dw = (w.a) I + w a^T - 2 a w^T``."""
    wa = np.einsum("...i,...i->...", w, a)
    return wa[..., None, None] * np.eye(3) + _outer(w, a) - 2.0 * _outer(a, w)


def _d_tinv_t(w, t, d, vec):
    """``d(T_SO3(w)^-T vec)/dw`` with ``T^-T vec = vec - w x vec / 2 + d w x (w x vec)``."""
    dp = coefficient("dp", t)
    wwv = _cross(w, _cross(w, vec))
    return 0.5 * skew(vec) + dp[..., None, None] * _outer(wwv, w) + d[..., None, None] * _m(w, vec)


def _geometric(h, sigma):
    """``G(h, sigma) = d(T(h)^-T sigma)/dh``, ``(n, 6, 6)``.

    ``T(h)^-T sigma = [A n; A m - A Q(u, w) A n]`` with ``A = T_SO3(w)^-T`` and
    ``Q(u, w) = Q(-u, -w)^T``; differentiated term by term (c1 = c, c2 = q2,
    c3 = q3 of se3, and their derivatives divided by t).
    """
    u, w = h[..., :3], h[..., 3:]
    n, m = sigma[..., :3], sigma[..., 3:]
    t = se3.rotation_angle(w)
    P, U = skew(w), skew(u)
    PP = P @ P
    d = coefficient("d", t)
    c1, c2, c3 = coefficient("c", t), coefficient("q2", t), coefficient("q3", t)
    c1p, c2p, c3p = coefficient("cp", t), coefficient("q2p", t), coefficient("q3p", t)
    A = np.eye(3) - 0.5 * P + d[..., None, None] * PP

    y = np.einsum("...ij,...j->...i", A, n)
    yw = _cross(w, y)
    yww = _cross(w, yw)
    a_ = _cross(u, y)
    b_ = _cross(u, yw)
    e_ = _cross(u, yww)
    g1 = _cross(w, a_) + _cross(u, yw) + _cross(w, b_)
    g2 = _cross(w, _cross(w, a_)) + e_ - 3.0 * _cross(w, b_)
    g3 = _cross(w, e_) + _cross(w, _cross(w, b_))
    z = 0.5 * a_ + c1[..., None] * g1 + c2[..., None] * g2 + c3[..., None] * g3  # Q(u,w) y

    C1, C2, C3 = c1[..., None, None], c2[..., None, None], c3[..., None, None]
    Y, S1, S2 = skew(y), skew(yw), skew(yww)
    dQu = -(0.5 * Y + C1 * (P @ Y + S1 + P @ S1) + C2 * (PP @ Y + S2 - 3.0 * P @ S1)
            + C3 * (P @ S2 + PP @ S1))
    UY = U @ Y
    PUY = P @ UY
    Mwy = _m(w, y)
    dQw = (_outer(c1p[..., None] * g1 + c2p[..., None] * g2 + c3p[..., None] * g3, w)
           + C1 * (-skew(a_) - UY - skew(b_) - PUY)
           + C2 * (_m(w, a_) + U @ Mwy + 3.0 * skew(b_) + 3.0 * PUY)
           + C3 * (-skew(e_) + P @ U @ Mwy + _m(w, b_) - PP @ UY))
    DAn = _d_tinv_t(w, t, d, n)

    G = np.zeros(h.shape[:-1] + (6, 6))
    G[..., :3, 3:] = DAn
    G[..., 3:, :3] = -A @ dQu
    G[..., 3:, 3:] = _d_tinv_t(w, t, d, m) - _d_tinv_t(w, t, d, z) - A @ (dQw + _q_times(u, w, t, DAn))
    return G


def _q_times(u, w, t, M):
    return se3._q_matrix(u, w, t) @ M


def internal_forces_and_tangent(H_A, H_B, L, eps0, C):
    """Nodal forces ``(n, 12)``, tangent ``(n, 12, 12)`` and the ``ElementState``.

    The tangent is ``d f / d q`` for body increments ``q = (q_A, q_B)``
    (``H <- H exp(hat(q))``), material and geometric parts, exact.
    """
    s = element_state(H_A, H_B, L, eps0, C)
    h, sigma = s.h, s.sigma
    Ti, X, t, d = _tangent_inv_blocks(h)
    TiB = _assemble_tinv(Ti, X)
    TiA = _assemble_tinv(Ti, X, transpose_blocks=True)
    f = np.concatenate([-np.einsum("nji,nj->ni", TiA, sigma),
                        np.einsum("nji,nj->ni", TiB, sigma)], axis=-1)
    B = np.concatenate([-TiA, TiB], axis=-1)                     # (n, 6, 12)
    CB = (C / L[:, None, None]) @ B
    G = _geometric(np.concatenate([-h, h]), np.concatenate([sigma, sigma]))
    nel = h.shape[0]
    Gs = np.concatenate([G[:nel], G[nel:]], axis=-2)            # (n, 12, 6)
    K = np.swapaxes(B, -1, -2) @ CB + Gs @ B
    return f, K, s
