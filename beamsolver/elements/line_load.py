"""Distributed loads on two-node SE(3) elements: consistent nodal loads and their stiffness.

An element with node poses ``H_A, H_B`` and reference length ``L`` is the curve
``H(xi) = H_A exp(xi h)``, ``h = log(H_A^-1 H_B)``, ``xi`` in ``[0, 1]`` (docs/theory.md
section 3).  A load per unit reference length, force ``q`` and moment ``m``, does the
virtual work ``dW = L int_0^1 p(xi) . dq(xi) dxi`` with the body increment of the section

    dq(xi) = Phi_A(xi) dq_A + Phi_B(xi) dq_B,
    Phi_A = Ad(exp(-xi h)) - xi T(xi h) T(-h)^-1,   Phi_B = xi T(xi h) T(h)^-1,

(``T`` the right tangent of SE(3), ``dh = -T(-h)^-1 dq_A + T(h)^-1 dq_B``) and the load's body
components ``p = (R(xi)^T q, R(xi)^T m)`` for a dead load (global ``q, m``), ``p = (q, m)`` for a
follower load (given in the section frame).  The consistent nodal loads are
``f_ext,X = L sum_g w_g Phi_X(xi_g)^T p(xi_g)`` (Gauss-Legendre, ``GAUSS_POINTS``), body
components at each node (translation first), conjugate to ``H <- H exp(hat(dq))``.

Their derivative ``d f_ext / d(dq_A, dq_B)`` (the load stiffness; the residual's is its
negative): with ``D = d f_ext / d h`` by complex steps in the six directions of ``h`` (exact to
round-off; ``se3.exp`` and the tangents are analytic), ``K_B = D T(h)^-1`` and
``K_A = -D T(-h)^-1 + d f_ext / d w_A|_h``, the last the rigid turn of a dead load's element
(closed form, ``_loads``; zero for a follower load).
docs/theory_line_loads.md derives it; tests/elements/test_line_load.py checks it by finite differences.
"""
import numpy as np

from ..lie import se3

__all__ = ["GAUSS_POINTS", "nodal_loads", "nodal_loads_and_tangent", "use_numpy"]

GAUSS_POINTS = 3                 # per element; exact for a straight element, error O(|h_w|^6) when curved
COMPLEX_STEP = 1e-30             # imaginary step of the complex-step derivative
_XG, _WG = np.polynomial.legendre.leggauss(GAUSS_POINTS)
XI, WEIGHTS = 0.5 * (_XG + 1.0), 0.5 * _WG
_NUMPY = [False]


def use_numpy(flag=True):
    """Evaluate with the numpy form below (the oracle of ``line_load_jit``) instead of the compiled kernel."""
    _NUMPY[0] = bool(flag)


def _compiled(H_A, H_B, L, q, m, follower, tangent):
    from .line_load_jit import line_loads
    n = len(L)
    f = np.empty((n, 12))
    K = np.empty((n, 12, 12)) if tangent else np.empty((0, 12, 12))
    c = np.ascontiguousarray
    line_loads(c(H_A, dtype=float), c(H_B, dtype=float), c(L, dtype=float), c(q, dtype=float),
               c(m, dtype=float), bool(follower), bool(tangent), f, K, XI, WEIGHTS, COMPLEX_STEP)
    return (f, K) if tangent else f


def _loads(H_A, h, L, q, m, follower, rotation=False):
    """``f_ext`` ``(..., n, 12)`` from poses ``H_A`` ``(..., n, 4, 4)`` and twists ``h`` ``(..., n, 6)``
    (real or complex); ``q``, ``m`` ``(n, 3)`` per unit length.  With ``rotation`` (real arguments,
    dead loads) also ``d f_ext / d w_A`` at fixed ``h`` ``(n, 12, 3)``: turning ``H_A`` by ``dw`` turns
    the whole element, ``dp = (E^T hat(R_A^T q), E^T hat(R_A^T m)) dw`` with ``E`` the rotation of
    ``exp(xi h)``."""
    Tp, Tm = se3.tangent_inv(h), se3.tangent_inv(-h)
    f = np.zeros(h.shape[:-1] + (12,), dtype=np.result_type(H_A, h))
    G = np.zeros(h.shape[:-1] + (12, 3)) if rotation else None
    pb = np.concatenate([q, m], axis=-1)
    RAt = np.swapaxes(H_A[..., :3, :3], -1, -2)
    vq, vm = np.einsum("...ij,...j->...i", RAt, q), np.einsum("...ij,...j->...i", RAt, m)
    for x, w in zip(XI, WEIGHTS):
        E = se3.exp(x * h)
        Tx = x * se3.tangent(x * h)
        Et = np.swapaxes(E[..., :3, :3], -1, -2)
        p = pb if follower else np.concatenate([np.einsum("...ij,...j->...i", Et, vq),
                                                np.einsum("...ij,...j->...i", Et, vm)], axis=-1)
        PhiA = se3.adjoint(se3.inverse(E)) - Tx @ Tm
        PhiB = Tx @ Tp
        f[..., :6] += w * np.einsum("...ji,...j->...i", PhiA, p)
        f[..., 6:] += w * np.einsum("...ji,...j->...i", PhiB, p)
        if rotation:
            dp = np.concatenate([Et @ se3.skew(vq), Et @ se3.skew(vm)], axis=-2)        # (n, 6, 3)
            G[..., :6, :] += w * np.swapaxes(PhiA, -1, -2) @ dp
            G[..., 6:, :] += w * np.swapaxes(PhiB, -1, -2) @ dp
    f *= L[:, None]
    return (f, G * L[:, None, None]) if rotation else f


def nodal_loads(H_A, H_B, L, q, m, follower=False):
    """Consistent nodal loads ``f_ext`` ``(n, 12)`` (node A then B, body components) of loads per
    unit reference length ``q``, ``m`` ``(n, 3)`` on elements ``H_A, H_B`` ``(n, 4, 4)`` of length ``L``
    ``(n,)``; dead (global ``q, m``) or ``follower`` (section-frame ``q, m``)."""
    if not _NUMPY[0]:
        return _compiled(H_A, H_B, L, q, m, follower, False)
    return _loads(H_A, se3.log(se3.relative(H_A, H_B)), L, q, m, follower)


def nodal_loads_and_tangent(H_A, H_B, L, q, m, follower=False):
    """``(f_ext (n, 12), K (n, 12, 12))`` with ``K = d f_ext / d(dq_A, dq_B)``; arguments as
    ``nodal_loads``.  ``D = d f_ext / d h`` by complex steps in ``h`` (6 directions), then
    ``K_B = D T(h)^-1``, ``K_A = -D T(-h)^-1`` plus, for dead loads, the rigid turn of the element
    by ``dw_A`` at fixed ``h`` (``_loads(..., rotation=True)``).  Compiled (``line_load_jit``, the same
    formulas and complex steps) unless ``use_numpy``."""
    if not _NUMPY[0]:
        return _compiled(H_A, H_B, L, q, m, follower, True)
    h = se3.log(se3.relative(H_A, H_B))
    if follower:
        f, G = _loads(H_A, h, L, q, m, True), None
    else:
        f, G = _loads(H_A, h, L, q, m, False, rotation=True)
    hh = h + 1j * COMPLEX_STEP * np.eye(6)[:, None, :]                        # (6, n, 6), direction first
    D = np.transpose(_loads(H_A, hh, L, q, m, follower).imag, (1, 2, 0)) / COMPLEX_STEP   # (n, 12, 6)
    K = np.empty(f.shape + (12,))
    K[:, :, :6] = -D @ se3.tangent_inv(-h)
    K[:, :, 6:] = D @ se3.tangent_inv(h)
    if G is not None:
        K[:, :, 3:6] += G
    return f, K
