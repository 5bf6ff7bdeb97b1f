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

Exact stick (``mortar.py``, ``mortar_end_terms``): the nodal sums ``u_g``, ``lamN_g``, ``nbar_g`` over
``Phi_j(xi_p) W_p (S_p, lam_n,p, n_p)`` and the point forces ``A_p T_p``, ``T_p = sum_j Phi_j(xi_p) v_j``, move
with ``xi_p`` and ``W_p`` too: their terms go to the rows of the forces and of the complementarity functions.
"""
import numpy as np

from .._jit import jit
from ..lie.se3_jit import add, cross, dot, log_relative, mm, mv, scale, transpose
from .kernel_jit import N_ROWS, _adjoint_inv, _exp, _pose_of, _table, _tangent, _tangent_inv, make_kernel
from .law import PENALTY_COULOMB

__all__ = ["end_gradients", "end_terms", "end_derivatives", "mortar_shifted", "mortar_end_terms", "STEP"]

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


def end_derivatives(X, xi, weight, x_g, w_g, length):
    """The segment points with a moving end among ``(k,)`` points (``end_terms``' arguments): their rows
    ``(r,)``, ``dxi/dq`` and ``dW/dq`` ``(r, 24)``."""
    span = weight / (w_g * length)
    a = xi - span * x_g
    b = a + span
    moving = np.flatnonzero((a > CLIPPED) | (b < 1.0 - CLIPPED))
    if not len(moving):
        return moving, np.zeros((0, 24)), np.zeros((0, 24))
    a, b, x_g = a[moving], b[moving], x_g[moving]
    da, db = end_gradients(X[moving], a, b)
    dxi = (1.0 - x_g)[:, None] * da + x_g[:, None] * db
    dW = (w_g[moving] * length[moving])[:, None] * (db - da)
    return moving, dxi, dW


@jit
def _add_terms(K, at, dfdxi, dxi, per_length, dW):
    """``K[at[r]] += dfdxi[r] (x) dxi[r] + per_length[r] (x) dW[r]`` in place (no ``(r, 24, 24)`` temporaries)."""
    for r in range(len(at)):
        Kr = K[at[r]]
        for i in range(24):
            a, c = dfdxi[r, i], per_length[r, i]
            for j in range(24):
                Kr[i, j] += a * dxi[r, j] + c * dW[r, j]


def end_terms(X, xi, weight, x_g, w_g, length, f, forces, K, at):
    """Add the tangent terms of segment points to their blocks ``K[at]`` ``(k, 24, 24)`` (in place): poses ``X``
    ``(k, 4, 4, 4)``, parameters ``xi`` and weights ``weight`` ``(k,)``, their Gauss point ``x_g`` and weight
    ``w_g`` on ``[0, 1]``, slave element ``length``, the points' forces ``f`` ``(k, 24)`` (residual signs) and
    ``forces(rows, xi)``: the forces ``(r, 24)`` of the points ``rows`` moved to ``xi``.  Returns the rows with
    a moving end.  Points without force (the normal law off: no friction either) have no terms."""
    loaded = np.flatnonzero(f.any(axis=1))
    moving, dxi, dW = end_derivatives(X[loaded], xi[loaded], weight[loaded], x_g[loaded], w_g[loaded],
                                      length[loaded])
    moving = loaded[moving]
    if not len(moving):
        return moving
    dfdxi = (forces(moving, xi[moving] + STEP) - f[moving]) / STEP
    per_length = f[moving] / np.where(weight[moving] == 0.0, 1.0, weight[moving])[:, None]
    _add_terms(K, np.ascontiguousarray(at[moving], dtype=np.int64), dfdxi, dxi, per_length, dW)
    return moving


def mortar_shifted(X, p, T, law=None):
    """The mortar kernel (``kernel_jit.mortar_terms``) at the points ``(r, 4, 4, 4)`` with parameters ``p``
    (``xi1`` moved by the caller), forces only where ``mortar_terms`` needs four evaluations: ``AT``
    ``(r, 24)`` the friction forces of the tractions ``T`` ``(r, 3)``, the slips ``S``, normals ``n`` ``(r, 3)``
    and normal tractions ``lam_n`` ``(r,)``."""
    X = np.ascontiguousarray(X, dtype=float)
    r = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), _ = _table(X, p)
    # one traction per call (the kernel's per-traction form, ``mortar="four"``), forces only
    kern = make_kernel(PENALTY_COULOMB if law is None else law, mortar="four")
    f, K = np.empty((2, r, 4, 6)), np.empty((r, 0, 0))           # an empty K: forces only
    sc, vec, two = np.empty((r, 4)), np.empty((r, 6, 3)), np.empty((r, 2, 2))
    flags, frames, rows = np.empty((r, 2), dtype=np.bool_), np.empty((r, 4, 4, 4)), np.empty((r, N_ROWS, 24))
    for k, lamp in enumerate((np.zeros((r, 3)), np.ascontiguousarray(T, dtype=float))):
        kern(X, kind, par, has, HCL, HFK, HLKp, lamp, True, f[k], K, sc if k == 0 else sc.copy(), vec if k == 0
             else vec.copy(), two if k == 0 else two.copy(), flags, frames, rows)
    s = two[:, 1]
    return dict(AT=(f[1] - f[0]).reshape(r, 24), S=s[:, :1] * vec[:, 1] + s[:, 1:] * vec[:, 2], n=vec[:, 0].copy(),
                lam_n=sc[:, 1].copy())


def mortar_end_terms(G, d, st, vals, eps, mu, rows, dxi, dW, weight, shifted, active=None):
    """The exact-stick terms of the moving segment ends (``mortar.blocks``, ``mortar.multiplier_blocks``).

    ``G``, ``d``, ``st``: as ``mortar.multiplier_blocks``'s (``d["f"]``: the points' friction forces ``A_p T_p``);
    ``vals`` ``(n, 3)``: the nodal tractions ``T_p`` interpolates (``v``, or ``lam`` of the updates);
    ``rows`` ``(r,)``: the points with a moving end, ``dxi``, ``dW`` ``(r, 24)`` (``end_derivatives``);
    ``weight`` ``(P,)``; ``shifted``: ``mortar_shifted`` of ``rows`` at ``xi + STEP`` with their ``T_p``;
    ``active`` ``(P,)``: the points whose slip counts (``mortar.nodal_state``; None: all).
    Returns ``F`` ``(n, 6 k, 6 k)``: d f / d q of the group forces (the forces of the points' node A groups)
    and ``B`` ``(n, 3, 6 k)``: d lam_g / d q (``mortar._trial_rows``' part through ``xi_p`` and ``W_p``)."""
    n, k = G["members"].shape
    F, B = np.zeros((n, 6 * k, 6 * k)), np.zeros((n, 3, 6 * k))
    if not len(rows):
        return F, B
    g2, pos, phi = G["g"][rows], G["pos"][rows], G["phi"][rows]
    slots = [(6 * pos[:, a, :, None] + np.arange(6)).reshape(len(rows), 24) for a in range(2)]
    W = weight[rows]
    fp = d["f"][rows]
    # d(A_p T_p)/dxi = dA/dxi T_p + A_p (v_B - v_A); A_p is proportional to W_p
    dfdxi = (shifted["AT"] - fp) / STEP + np.einsum("pij,pj->pi", d["A"][rows], vals[g2[:, 1]] - vals[g2[:, 0]])
    per_length = fp / np.where(W == 0.0, 1.0, W)[:, None]
    Fp = dfdxi[:, :, None] * dxi[:, None, :] + per_length[:, :, None] * dW[:, None, :]
    np.add.at(F, (g2[:, 0, None, None], slots[0][:, :, None], slots[0][:, None, :]), Fp)
    S_xi = (shifted["S"] - d["S"][rows]) / STEP
    n_xi = (shifted["n"] - d["n"][rows]) / STEP
    l_xi = (shifted["lam_n"] - d["lam_n"][rows]) / STEP
    S, nn, ln = d["S"][rows], d["n"][rows], d["lam_n"][rows]
    act = np.ones(len(rows)) if active is None else active[rows].astype(float)
    for a in range(2):
        g = g2[:, a]
        m = st["m"][g]
        wn, wphi = st["wn"][rows, a], st["wphi"][rows, a]
        dwn = W[:, None] * (2 * a - 1) * dxi + phi[:, a, None] * dW                 # d(Phi_j W_p), Phi_j' = -1, +1
        dwphi = act[:, None] * dwn
        dU = (S[:, :, None] * dwphi[:, None, :] + (wphi[:, None] * S_xi)[:, :, None] * dxi[:, None, :]) / m[:, None, None]
        dN = (nn[:, :, None] * dwn[:, None, :] + (wn[:, None] * n_xi)[:, :, None] * dxi[:, None, :]) / m[:, None, None]
        dL = (ln[:, None] * dwphi + (wphi * l_xi)[:, None] * dxi) / m[:, None]
        dtrial = eps[g, None, None] * np.einsum("pij,pjq->piq", st["Pi"][g], dU) + \
            np.einsum("pij,pjq->piq", st["Q"][g], dN)
        dlam = np.einsum("pij,pjq->piq", st["C"][g], dtrial) + \
            mu[g, None, None] * st["c"][g][:, :, None] * dL[:, None, :]
        np.add.at(B, (g[:, None, None], np.arange(3)[None, :, None], slots[a][:, None, :]), dlam)
    return F, B
