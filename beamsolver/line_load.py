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
negative) is taken by complex steps on the group: ``H_A exp(i e e_k)`` with
``h - i e T(-h)^-1 e_k`` for node A, ``h + i e T(h)^-1 e_k`` for node B (exact to first order in
``e``, so the derivative is exact to round-off; ``se3.exp`` and the tangents are analytic).
docs/theory_line_loads.md derives it; tests/test_line_load.py checks it by finite differences.
"""
import numpy as np

from . import se3

__all__ = ["GAUSS_POINTS", "nodal_loads", "nodal_loads_and_tangent"]

GAUSS_POINTS = 4                 # per element; exact for a straight element, error O((|h_w| L)^8) when curved
COMPLEX_STEP = 1e-30             # imaginary step of the complex-step derivative
_XG, _WG = np.polynomial.legendre.leggauss(GAUSS_POINTS)
XI, WEIGHTS = 0.5 * (_XG + 1.0), 0.5 * _WG


def _loads(H_A, h, L, q, m, follower):
    """``f_ext`` ``(..., n, 12)`` from poses ``H_A`` ``(..., n, 4, 4)`` and twists ``h`` ``(..., n, 6)``
    (real or complex); ``q``, ``m`` ``(n, 3)`` per unit length."""
    Tp, Tm = se3.tangent_inv(h), se3.tangent_inv(-h)
    f = np.zeros(h.shape[:-1] + (12,), dtype=np.result_type(H_A, h))
    pb = np.concatenate([q, m], axis=-1)
    for x, w in zip(XI, WEIGHTS):
        E = se3.exp(x * h)
        Tx = x * se3.tangent(x * h)
        if follower:
            p = pb
        else:
            Rt = np.swapaxes(H_A[..., :3, :3] @ E[..., :3, :3], -1, -2)
            p = np.concatenate([np.einsum("...ij,...j->...i", Rt, q), np.einsum("...ij,...j->...i", Rt, m)], axis=-1)
        PhiA = se3.adjoint(se3.inverse(E)) - Tx @ Tm
        PhiB = Tx @ Tp
        f[..., :6] += w * np.einsum("...ji,...j->...i", PhiA, p)
        f[..., 6:] += w * np.einsum("...ji,...j->...i", PhiB, p)
    return f * L[:, None]


def nodal_loads(H_A, H_B, L, q, m, follower=False):
    """Consistent nodal loads ``f_ext`` ``(n, 12)`` (node A then B, body components) of loads per
    unit reference length ``q``, ``m`` ``(n, 3)`` on elements ``H_A, H_B`` ``(n, 4, 4)`` of length ``L``
    ``(n,)``; dead (global ``q, m``) or ``follower`` (section-frame ``q, m``)."""
    return _loads(H_A, se3.log(se3.relative(H_A, H_B)), L, q, m, follower)


def nodal_loads_and_tangent(H_A, H_B, L, q, m, follower=False):
    """``(f_ext (n, 12), K (n, 12, 12))`` with ``K = d f_ext / d(dq_A, dq_B)`` (complex steps on the
    group, see the module docstring); arguments as ``nodal_loads``."""
    h, Tp, Tm = se3.log_and_tangent_inv(se3.relative(H_A, H_B))
    f = _loads(H_A, h, L, q, m, follower)
    n = len(L)
    eye = np.eye(6)
    ie = 1j * COMPLEX_STEP
    HA = np.broadcast_to(H_A, (12, n, 4, 4)).astype(complex)
    hh = np.broadcast_to(h, (12, n, 6)).astype(complex)
    HA[:6] = H_A @ se3.exp(ie * eye)[:, None]
    hh[:6] -= ie * Tm.transpose(2, 0, 1)          # -i e T(-h)^-1 e_k, direction k first
    hh[6:] += ie * Tp.transpose(2, 0, 1)
    fc = _loads(HA, hh, L, q, m, follower)        # (12, n, 12)
    K = np.ascontiguousarray(np.transpose(fc.imag, (1, 2, 0))) / COMPLEX_STEP
    return f, K
