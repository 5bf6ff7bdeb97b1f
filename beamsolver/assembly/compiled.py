"""Compiled (numba) scatter and pose updates of ``assembly.System``.

- ``scatter``: COO values summed into the CSC data array of the pattern built
  once (``data[pos[i]] += kvals[i]``; what ``np.bincount(pos, kvals)`` does).
- ``compose_exp``: body increments ``H_i <- H_i exp(hat(dz_i))`` of listed nodes.
- ``rechain``: the strain-space update of cantilever chains
  (docs/theory.md eq. 4.6): ``h_e <- h_e + T(h_e)^-1 dq_b - T(-h_e)^-1 dq_a``,
  poses re-chained from the anchored node, ``H_b = H_a exp(h_e)``.

The numpy versions (``np.bincount``, ``se3.compose``/``se3.exp``,
``System.rechain_numpy``) are the test oracles (``tests/elements/test_compiled_kernels.py``).
"""
import numpy as np

from .._jit import jit, jit_callee
from ..elements.element_jit import _side
from ..lie.se3_jit import C_, Q2_, Q3_, add, coefficient, compose_into, cross, dot, exp_pose, log_relative, mv, pose, scale


@jit
def scatter(pos, kvals, data):
    """``data[:] = 0; data[pos[i]] += kvals[i]`` (``pos`` may point at a dummy last slot)."""
    data[:] = 0.0
    for i in range(len(pos)):
        data[pos[i]] += kvals[i]


@jit
def compose_exp(H, dz, nodes):
    """``H[i] <- H[i] exp(hat(dz[i]))`` for ``i`` in ``nodes`` with a non-zero ``dz[i]`` (in place)."""
    E = np.empty((4, 4))
    for i in nodes:
        if dz[i, 0] == 0.0 and dz[i, 1] == 0.0 and dz[i, 2] == 0.0 and dz[i, 3] == 0.0 and dz[i, 4] == 0.0 \
                and dz[i, 5] == 0.0:
            continue
        exp_pose((dz[i, 0], dz[i, 1], dz[i, 2]), (dz[i, 3], dz[i, 4], dz[i, 5]), E)
        compose_into(H[i], E, H[i])


@jit_callee
def _tinv_apply(u, w, t, d, vu, vw):
    """``T(h)^-1 (vu, vw)`` at ``h = (u, w)``: ``(Ti vu + X vw, Ti vw)``."""
    c1, c2, c3 = coefficient(C_, t), coefficient(Q2_, t), coefficient(Q3_, t)
    Ti, X = _side(u, w, d, t * t, dot(w, u), cross(w, u), c1, c2, c3)
    return add(mv(Ti, vu), mv(X, vw)), mv(Ti, vw)


@jit
def rechain(H_old, H, dz, nodes, ptr):
    """Strain-space update of the chains ``nodes[ptr[k]:ptr[k + 1]]`` (anchor first).

    ``H[anchor]`` must already hold the anchor's new pose; the other nodes' poses are overwritten.
    """
    E = np.empty((4, 4))
    for k in range(len(ptr) - 1):
        for j in range(ptr[k], ptr[k + 1] - 1):
            a, b = nodes[j], nodes[j + 1]
            RA, xA = pose(H_old, a)
            RB, xB = pose(H_old, b)
            u, w, t, d = log_relative(RA, xA, RB, xB)
            qa = ((dz[a, 0], dz[a, 1], dz[a, 2]), (dz[a, 3], dz[a, 4], dz[a, 5]))
            qb = ((dz[b, 0], dz[b, 1], dz[b, 2]), (dz[b, 3], dz[b, 4], dz[b, 5]))
            pu, pw = _tinv_apply(u, w, t, d, qb[0], qb[1])
            mu_, mw_ = _tinv_apply(scale(-1.0, u), scale(-1.0, w), t, d, qa[0], qa[1])
            exp_pose(add(u, add(pu, scale(-1.0, mu_))), add(w, add(pw, scale(-1.0, mw_))), E)
            compose_into(H[a], E, H[b])


@jit
def dead_loads(H, nodes, F, M, fb, kb):
    """Dead loads (docs/theory.md eq. 4.2): body components ``fb[k] = (R^T F_k, R^T M_k)`` at ``nodes[k]``
    and the load stiffness ``kb[k] = -[[0, hat(R^T F_k)], [0, hat(R^T M_k)]]`` (``kb`` may have length 0)."""
    for k in range(len(nodes)):
        i = nodes[k]
        for a in range(3):
            fb[k, a] = H[i, 0, a] * F[k, 0] + H[i, 1, a] * F[k, 1] + H[i, 2, a] * F[k, 2]
            fb[k, 3 + a] = H[i, 0, a] * M[k, 0] + H[i, 1, a] * M[k, 1] + H[i, 2, a] * M[k, 2]
        if len(kb):
            kb[k] = 0.0
            for r0, v0 in ((0, 0), (3, 3)):
                x, y, z = fb[k, v0], fb[k, v0 + 1], fb[k, v0 + 2]
                kb[k, r0, 4], kb[k, r0, 5] = z, -y
                kb[k, r0 + 1, 3], kb[k, r0 + 1, 5] = -z, x
                kb[k, r0 + 2, 3], kb[k, r0 + 2, 4] = y, -x


@jit
def scaled_dead_loads(H, nodes, F, M, lf, fb, kb):
    """``dead_loads`` of the loads ``F * lf``, ``M * lf`` (``(k, 3)``, scales ``lf`` ``(k,)``);
    returns the largest ``|component|`` of the scaled forces and of the moments (NaN if any is)."""
    Fs, Ms = np.empty_like(F), np.empty_like(M)
    f_level, m_level = 0.0, 0.0
    for k in range(len(lf)):
        for a in range(3):
            Fs[k, a], Ms[k, a] = F[k, a] * lf[k], M[k, a] * lf[k]
            f, m = abs(Fs[k, a]), abs(Ms[k, a])
            if f > f_level or f != f:
                f_level = f if f_level == f_level else f_level
            if m > m_level or m != m:
                m_level = m if m_level == m_level else m_level
    dead_loads(H, nodes, Fs, Ms, fb, kb)
    return f_level, m_level


@jit
def global_node_values(r, g, out):
    """``out[i] = -[hat(r_u), hat(r_w)]`` ``(k, 6, 3)`` (stacked on the rows) of the residual ``r`` ``(6 n,)`` at the
    nodes ``g`` (``System._global_node_terms``; its numpy form's values, the negated zeros of ``hat`` included)."""
    for i in range(len(g)):
        for h in range(2):
            x, y, w = r[6 * g[i] + 3 * h], r[6 * g[i] + 3 * h + 1], r[6 * g[i] + 3 * h + 2]
            z = -0.0
            o = out[i]
            a = 3 * h
            o[a, 0], o[a, 1], o[a, 2] = z, w, -y
            o[a + 1, 0], o[a + 1, 1], o[a + 1, 2] = -w, z, x
            o[a + 2, 0], o[a + 2, 1], o[a + 2, 2] = y, -x, z

