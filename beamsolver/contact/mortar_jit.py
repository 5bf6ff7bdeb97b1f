"""Compiled passes of exact stick's mortar groups (``mortar.py``): the scatters of the points' rows into their groups,
the nodal state (``nodal_state``), the multiplier basis, the trial rows, the point terms after the mortar kernel
(``point_terms``) and the point data (``point_data``).

The numpy forms (``np.add.at`` over fancy indices, ``*_numpy`` here; ``mortar.nodal_state_numpy`` and the numpy
branches of ``mortar.py`` under ``use_numpy_scatter``) are their oracle: the loops add in the order ``np.add.at`` /
``np.bincount`` do (points, then rows, then columns), so the sums are the same bits.  ``np.add.at`` cost about 0.8 ms
an evaluation on the twisted pair (issue 26, speed: ``docs/benchmarks.md``), the numpy nodal state and point terms
about 0.3 ms (session 6).
"""
import numpy as np

from .._jit import jit
from ..model.buffers import BufferPool

__all__ = ["scatter_rows", "scatter_block", "scatter_columns", "scatter_rows_numpy", "scatter_block_numpy",
           "scatter_columns_numpy", "trial_rows", "subtract_indexed", "point_terms", "point_terms_into",
           "nodal_state", "point_data", "multiplier_basis", "slivers", "sliver_groups", "branch_rows",
           "point_forces", "interpolate", "turn", "products", "rotate"]


@jit
def _rows(out, g, rows, vals, scale):
    for p in range(rows.shape[0]):
        o, s = out[g[p]], scale[p]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for c in range(vals.shape[2]):
                o[r, c] += s * vals[p, i, c]


@jit
def _rows_plain(out, g, rows, vals):
    for p in range(rows.shape[0]):
        o = out[g[p]]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for c in range(vals.shape[2]):
                o[r, c] += vals[p, i, c]


@jit
def _block(out, g, rows, vals):
    for p in range(rows.shape[0]):
        o = out[g[p]]
        for i in range(rows.shape[1]):
            r = rows[p, i]
            for j in range(rows.shape[1]):
                o[r, rows[p, j]] += vals[p, i, j]


@jit
def _columns(out, g, cols, vals):
    for p in range(cols.shape[0]):
        o = out[g[p]]
        for i in range(vals.shape[1]):
            for j in range(cols.shape[1]):
                o[i, cols[p, j]] += vals[p, i, j]


@jit
def _trial_rows(B, g2, slot_rows, wphi, wn, m, eps, mu, Pi, Q, C, c, dS, dn, dlam_n):
    for p in range(g2.shape[0]):
        for a in range(2):
            g, wgn, se, sm = _slot_weights(g2, wphi, wn, m, eps, mu, p, a)
            # the group's matrices in registers (the stores to ``B`` may alias them: reloaded per column otherwise)
            P00, P01, P02, P10, P11, P12, P20, P21, P22 = _entries(Pi, g)
            Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22 = _entries(Q, g)
            C00, C01, C02, C10, C11, C12, C20, C21, C22 = _entries(C, g)
            s0, s1, s2 = sm * c[g, 0], sm * c[g, 1], sm * c[g, 2]
            o, rows = B[g], slot_rows[a, p]
            for k in range(24):
                t0, t1, t2 = _trial_column(se, wgn, P00, P01, P02, P10, P11, P12, P20, P21, P22,
                                           Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22, dS, dn, p, k)
                r, dl = rows[k], dlam_n[p, k]
                o[0, r] += C00 * t0 + C01 * t1 + C02 * t2 + s0 * dl
                o[1, r] += C10 * t0 + C11 * t1 + C12 * t2 + s1 * dl
                o[2, r] += C20 * t0 + C21 * t1 + C22 * t2 + s2 * dl


@jit
def _slot_weights(g2, wphi, wn, m, eps, mu, p, a):
    """Point ``p``'s slot ``a``: its group ``g`` and weights ``w_n / m``, ``eps w / m``, ``mu w / m``."""
    g = g2[p, a]
    wg, wgn = wphi[p, a] / m[g], wn[p, a] / m[g]
    return g, wgn, eps[g] * wg, mu[g] * wg


@jit
def _entries(M, g):
    """The nine entries of ``M[g]`` ``(3, 3)``, row by row."""
    return M[g, 0, 0], M[g, 0, 1], M[g, 0, 2], M[g, 1, 0], M[g, 1, 1], M[g, 1, 2], M[g, 2, 0], M[g, 2, 1], M[g, 2, 2]


@jit
def _trial_column(se, wgn, P00, P01, P02, P10, P11, P12, P20, P21, P22, Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22,
                  dS, dn, p, k):
    """Column ``k`` of ``se Pi dS_p + wgn Q dn_p`` ``(3,)`` (each product summed left to right)."""
    d0, d1, d2 = dS[p, 0, k], dS[p, 1, k], dS[p, 2, k]
    n0, n1, n2 = dn[p, 0, k], dn[p, 1, k], dn[p, 2, k]
    t0 = se * (P00 * d0 + P01 * d1 + P02 * d2) + wgn * (Q00 * n0 + Q01 * n1 + Q02 * n2)
    t1 = se * (P10 * d0 + P11 * d1 + P12 * d2) + wgn * (Q10 * n0 + Q11 * n1 + Q12 * n2)
    t2 = se * (P20 * d0 + P21 * d1 + P22 * d2) + wgn * (Q20 * n0 + Q21 * n1 + Q22 * n2)
    return t0, t1, t2


@jit
def _branch_rows(Tq, capq, g2, slot_rows, wphi, wn, m, eps, mu, Pi, Q, dS, dn, dlam_n):
    for p in range(g2.shape[0]):
        for a in range(2):
            g, wgn, se, sm = _slot_weights(g2, wphi, wn, m, eps, mu, p, a)
            P00, P01, P02, P10, P11, P12, P20, P21, P22 = _entries(Pi, g)
            Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22 = _entries(Q, g)
            o, oc, rows = Tq[g], capq[g], slot_rows[a, p]
            for k in range(24):
                t0, t1, t2 = _trial_column(se, wgn, P00, P01, P02, P10, P11, P12, P20, P21, P22,
                                           Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22, dS, dn, p, k)
                r = rows[k]
                o[0, r] += t0
                o[1, r] += t1
                o[2, r] += t2
                oc[r] += sm * dlam_n[p, k]


# ``point_terms``' outputs in kept memory (fresh memory's page faults cost as much as the pass on the 19-wire bundle)
_TERMS_POOLS = tuple(BufferPool() for _ in range(4))


@jit
def _point_terms(df, rows, t1, t2, s, A, dS, dn, dlam):
    for p in range(rows.shape[0]):
        for r in range(24):
            for q in range(3):
                A[p, r, q] = df[q, p, r // 6, r % 6]
        for i in range(3):
            for k in range(24):
                dS[p, i, k] = ((t1[p, i] * rows[p, 9, k] + s[p, 0] * rows[p, 3 + i, k]) + t2[p, i] * rows[p, 10, k]) \
                    + s[p, 1] * rows[p, 6 + i, k]
                dn[p, i, k] = rows[p, i, k]
        for k in range(24):
            dlam[p, k] = rows[p, 11, k]


def point_terms(df, rows, t1, t2, s):
    """The mortar kernel's point terms as contiguous arrays in one pass (``kernel_jit._mortar_terms``): ``A``
    ``(P, 24, 3)`` from the force differences ``df`` ``(3, P, 4, 6)``, the global slip's gradient ``dS`` ``(P, 3, 24)``
    = ``t1 ds1 + s1 dt1 + t2 ds2 + s2 dt2`` (summed in this order, as the numpy form), ``dn`` ``(P, 3, 24)`` and
    ``dlam_n`` ``(P, 24)`` from the gradient rows ``rows`` ``(P, N_ROWS, 24)``; ``t1``, ``t2`` ``(P, 3)``, ``s``
    ``(P, 2)`` (no ``(P, 3, 24)`` temporaries, no strided copies downstream)."""
    P = rows.shape[0]
    A, dS, dn, dlam = (pool.take(shape) for pool, shape in zip(_TERMS_POOLS, ((P, 24, 3), (P, 3, 24), (P, 3, 24),
                                                                              (P, 24))))
    _point_terms(df, rows, _c(t1), _c(t2), _c(s), A, dS, dn, dlam)
    return A, dS, dn, dlam


def point_terms_into(df, rows, t1, t2, s, A, dS, dn, dlam):
    """``point_terms`` into the given C-contiguous outputs ``A`` ``(P, 24, 3)``, ``dS``, ``dn`` ``(P, 3, 24)``,
    ``dlam`` ``(P, 24)`` (``kernel_jit._mortar_chunks``: one pass's points)."""
    _point_terms(_c(df), rows, _c(t1), _c(t2), _c(s), A, dS, dn, dlam)


@jit
def _point_forces(A, T, swap, out):
    for p in range(A.shape[0]):
        t0, t1, t2 = T[p, 0], T[p, 1], T[p, 2]
        for i in range(A.shape[1]):
            x0, x1, x2 = A[p, i, 0] * t0, A[p, i, 1] * t1, A[p, i, 2] * t2
            # (+ 0.0: einsum sums into zeros, so products all -0 give +0)
            out[p, i] = ((x0 + x2) + x1 if swap else (x0 + x1) + x2) + 0.0


def point_forces(A, T):
    """``np.einsum("pij,pj->pi", A, T)`` ``(P, 24)`` of ``A`` ``(P, 24, 3)``, ``T`` ``(P, 3)`` (the points' forces at
    their tractions, ``ContactSystem._mortar``) in one compiled pass, in einsum's order of the layouts it meets: ``A``
    C-contiguous ``(x0 + x2) + x1`` (its two-lane sum), ``A`` the kernel's ``(P, 24)`` rows by force (the view
    ``kernel_jit.mortar_forces`` gives, the last axis outermost) ``(x0 + x1) + x2``; numpy itself for any other."""
    P = A.shape[0]
    ok = A.dtype == np.float64 and A.ndim == 3 and A.shape[2] == 3 and T.dtype == np.float64 and \
        T.flags.c_contiguous and P > 1          # (one point: numba would see the view as another layout)
    s = A.strides
    if ok and A.flags.c_contiguous:
        swap = True
    elif ok and s[1] == 8 and s[0] == 8 * A.shape[1] and s[2] >= s[0] * P:
        swap = False
    else:
        return np.einsum("pij,pj->pi", A, T)
    out = np.empty(A.shape[:2])
    _point_forces(A, T, swap, out)
    return out


@jit
def _turn(R, Lam, out):
    for g in range(R.shape[0]):
        l0, l1, l2 = Lam[g, 0], Lam[g, 1], Lam[g, 2]
        for k in range(3):          # column k of ``se3.skew(Lam[g])``
            s0 = 0.0 if k == 0 else -l2 if k == 1 else l1
            s1 = l2 if k == 0 else 0.0 if k == 1 else -l0
            s2 = -l1 if k == 0 else l0 if k == 1 else 0.0
            for i in range(3):
                out[g, i, k] = -(((R[g, i, 0] * s0 + R[g, i, 1] * s1) + R[g, i, 2] * s2) + 0.0)


def turn(R, Lam):
    """``-np.einsum("gij,gjk->gik", R, se3.skew(Lam))`` ``(G, 3, 3)`` (``mortar._turn``: ``d(R Lam) / dtheta``) in one
    pass: einsum's sums on contiguous arrays, ``(x0 + x1) + x2`` into zeros (+ 0.0: -0 products give +0)."""
    out = np.empty((len(R), 3, 3))
    _turn(_c(R), _c(Lam), out)
    return out


@jit
def _products(A, B, out):
    for g in range(A.shape[0]):
        for i in range(3):
            for k in range(3):
                out[g, i, k] = ((A[g, i, 0] * B[g, 0, k] + A[g, i, 1] * B[g, 1, k]) + A[g, i, 2] * B[g, 2, k]) + 0.0


def products(A, B):
    """``np.einsum("gij,gjk->gik", A, B)`` ``(G, 3, 3)``: einsum's ``(x0 + x1) + x2`` into zeros on C-contiguous
    arrays (compiled), numpy itself on others."""
    if not (A.flags.c_contiguous and B.flags.c_contiguous and A.dtype == B.dtype == np.float64):
        return np.einsum("gij,gjk->gik", A, B)
    out = np.empty((len(A), 3, 3))
    _products(A, B, out)
    return out


@jit
def _rotate(R, v, out):
    for g in range(R.shape[0]):
        for i in range(3):
            out[g, i] = ((R[g, i, 0] * v[g, 0] + R[g, i, 2] * v[g, 2]) + R[g, i, 1] * v[g, 1]) + 0.0


def rotate(R, v):
    """``np.einsum("gij,gj->gi", R, v)`` ``(G, 3)``: einsum's two-lane ``(x0 + x2) + x1`` into zeros on C-contiguous
    arrays (compiled, as ``nodal_state``'s), numpy itself on others."""
    if not (R.flags.c_contiguous and v.flags.c_contiguous and R.dtype == v.dtype == np.float64):
        return np.einsum("gij,gj->gi", R, v)
    out = np.empty((len(R), 3))
    _rotate(R, v, out)
    return out


@jit
def _interpolate(phi, V, g2, out):
    for p in range(g2.shape[0]):
        a, b = g2[p, 0], g2[p, 1]
        for i in range(V.shape[1]):
            out[p, i] = (phi[p, 0] * V[a, i] + phi[p, 1] * V[b, i]) + 0.0    # (einsum's +0 from -0 products)


def interpolate(phi, V, g2):
    """``np.einsum("pa,pai->pi", phi, V[g2])`` ``(P, 3)``: the groups' vectors ``V`` ``(G, 3)`` at the points by their
    shape functions ``phi`` ``(P, 2)`` over their groups ``g2`` ``(P, 2)``, without the ``(P, 2, 3)`` gather (a sum of
    two products: the same bits in either order, signed zeros as einsum's)."""
    out = np.empty((len(g2), V.shape[1]))
    _interpolate(_c(phi), _c(V), _c(g2, np.int64), out)
    return out


@jit
def _nodal_state(g2, phi, w, active, S, lam_n, n, Rl, eps, mu, m, hold, u, lamN, trial, lam, stick, C, c, T, wphi, wn,
                 Pi, Q, weak, nu, up):
    G = len(m)
    nbar = np.zeros((G, 3))
    for p in range(g2.shape[0]):               # the sums in ``np.bincount``'s order (points, then nodes A, B)
        for a in range(2):
            g = g2[p, a]
            x = phi[p, a] * w[p]
            wn[p, a] = x
            y = x * (1.0 if active[p] else 0.0) if active.shape[0] > 0 else x
            wphi[p, a] = y
            for i in range(3):
                u[g, i] += y * S[p, i]
            lamN[g] += y * lam_n[p]
            for i in range(3):
                nbar[g, i] += x * n[p, i]
    for g in range(G):
        for i in range(3):
            u[g, i] /= m[g]
            nbar[g, i] /= m[g]
        lamN[g] /= m[g]
        size = np.sqrt((nbar[g, 0] * nbar[g, 0] + nbar[g, 1] * nbar[g, 1]) + nbar[g, 2] * nbar[g, 2])
        for i in range(3):
            nu[g, i] = nbar[g, i] / size
        for i in range(3):
            for j in range(3):
                Pi[g, i, j] = (1.0 if i == j else 0.0) - nu[g, i] * nu[g, j]
        v0, v1, v2 = Rl[g, 0] + eps[g] * u[g, 0], Rl[g, 1] + eps[g] * u[g, 1], Rl[g, 2] + eps[g] * u[g, 2]
        for i in range(3):          # ``np.einsum("gij,gj->gi")`` on contiguous arrays: (x0 + x2) + x1
            trial[g, i] = (Pi[g, i, 0] * v0 + Pi[g, i, 2] * v2) + Pi[g, i, 1] * v1
            up[g, i] = (Pi[g, i, 0] * u[g, 0] + Pi[g, i, 2] * u[g, 2]) + Pi[g, i, 1] * u[g, 1]
        nv = (nu[g, 0] * v0 + nu[g, 1] * v1) + nu[g, 2] * v2
        for i in range(3):
            for j in range(3):
                Q[g, i, j] = -(nv * Pi[g, i, j] + nu[g, i] * trial[g, j]) / size
        # ``mortar.return_mapping`` onto the disk ``mu max(lamN, 0)``
        cap = mu[g] * max(lamN[g], 0.0) if not np.isnan(lamN[g]) else mu[g] * lamN[g]
        norm = np.sqrt((trial[g, 0] * trial[g, 0] + trial[g, 1] * trial[g, 1]) + trial[g, 2] * trial[g, 2])
        st = norm <= cap and cap > 0.0
        stick[g] = st
        safe = 1.0 if (st or norm == 0.0) else norm
        t0, t1, t2 = trial[g, 0] / safe, trial[g, 1] / safe, trial[g, 2] / safe
        k = cap / safe
        for i in range(3):
            ti = t0 if i == 0 else t1 if i == 1 else t2
            for j in range(3):
                tj = t0 if j == 0 else t1 if j == 1 else t2
                C[g, i, j] = (1.0 if i == j else 0.0) if st else k * ((1.0 if i == j else 0.0) - ti * tj)
            lam[g, i] = trial[g, i] if st else cap * ti
            c[g, i] = 0.0 if st else ti
        wk = hold.shape[0] > 0 and hold[g] > 0 and lamN[g] <= 0.0
        weak[g] = wk
        if wk:
            h = hold[g] / eps[g]
            for i in range(3):
                for j in range(3):
                    C[g, i, j] = h * (1.0 if i == j else 0.0)
                c[g, i] = 0.0
    for p in range(g2.shape[0]):
        ga, gb = g2[p, 0], g2[p, 1]
        for i in range(3):
            T[p, i] = phi[p, 0] * lam[ga, i] + phi[p, 1] * lam[gb, i]


def nodal_state(g2, phi, w, active, S, lam_n, n, Rl, eps, mu, m, hold):
    """``mortar.nodal_state``'s arrays in one compiled pass (``g2`` ``(P, 2)`` the points' groups, ``Rl`` ``(n, 3)``
    the multipliers' tractions ``R Lam``, ``active`` and ``hold`` None or arrays): ``u`` (projected), ``lamN``,
    ``trial``, ``lam``, ``stick``, ``C``, ``c``, ``T``, ``wphi``, ``wn``, ``Pi``, ``Q``, ``weak``, ``nu`` as a dict.
    The sums keep numpy's order (``np.bincount``'s, ``np.einsum``'s on contiguous arrays), so the results are the
    numpy form's to the bit on this machine (``tests/contact/test_contact_mortar_jit.py``: to round-off anywhere)."""
    P, G = len(g2), len(m)
    out = dict(u=np.zeros((G, 3)), lamN=np.zeros(G), trial=np.empty((G, 3)), lam=np.empty((G, 3)),
               stick=np.empty(G, dtype=np.bool_), C=np.empty((G, 3, 3)), c=np.empty((G, 3)), T=np.empty((P, 3)),
               wphi=np.empty((P, 2)), wn=np.empty((P, 2)), Pi=np.empty((G, 3, 3)), Q=np.empty((G, 3, 3)),
               weak=np.empty(G, dtype=np.bool_), nu=np.empty((G, 3)), up=np.empty((G, 3)))
    _nodal_state(_c(g2, np.int64), _c(phi), _c(w), np.zeros(0, dtype=np.bool_) if active is None else _c(active, np.bool_),
                 _c(S), _c(lam_n), _c(n), _c(Rl), _c(eps), _c(mu), _c(m), np.zeros(0) if hold is None else _c(hold),
                 *out.values())
    return out


@jit
def _point_data(T, n, t1, t2, stick, g2, phi, lam_t, held):
    for p in range(T.shape[0]):
        tn = (T[p, 0] * n[p, 0] + T[p, 1] * n[p, 1]) + T[p, 2] * n[p, 2]
        a0, a1, a2 = T[p, 0] - tn * n[p, 0], T[p, 1] - tn * n[p, 1], T[p, 2] - tn * n[p, 2]
        lam_t[p, 0] = (a0 * t1[p, 0] + a1 * t1[p, 1]) + a2 * t1[p, 2]
        lam_t[p, 1] = (a0 * t2[p, 0] + a1 * t2[p, 1]) + a2 * t2[p, 2]
        held[p] = (stick[g2[p, 0]] or phi[p, 0] == 0.0) and (stick[g2[p, 1]] or phi[p, 1] == 0.0)


def point_data(T, n, t1, t2, stick, g2, phi):
    """Exact stick's point data (``system._point_data``): the tangential part of the traction ``T`` ``(P, 3)`` in the
    point's ``t1, t2`` ``(P, 2)`` (``T - (T . n) n``, the numpy form's sums) and whether every node of the point sticks
    (``stick`` ``(n,)`` of the groups ``g2`` ``(P, 2)``, a node of zero weight ``phi`` counting as sticking)."""
    P = len(T)
    lam_t, held = np.empty((P, 2)), np.empty(P, dtype=np.bool_)
    _point_data(_c(T), _c(n), _c(t1), _c(t2), _c(stick, np.bool_), _c(g2, np.int64), _c(phi), lam_t, held)
    return lam_t, held


@jit
def _multiplier_basis(nu, trial, stick, weak, B):
    for g in range(nu.shape[0]):
        a = 0                           # ``np.argmin(np.abs(nu))``: the first of equal magnitudes
        for i in range(1, 3):
            if abs(nu[g, i]) < abs(nu[g, a]):
                a = i
        e0, e1, e2 = -nu[g, a] * nu[g, 0], -nu[g, a] * nu[g, 1], -nu[g, a] * nu[g, 2]
        if a == 0:
            e0 += 1.0
        elif a == 1:
            e1 += 1.0
        else:
            e2 += 1.0
        t0, t1, t2 = trial[g, 0], trial[g, 1], trial[g, 2]
        norm = np.sqrt((t0 * t0 + t1 * t1) + t2 * t2)
        if not stick[g] and not weak[g] and norm > 0.0:
            e0, e1, e2 = t0, t1, t2
        n = np.sqrt((e0 * e0 + e1 * e1) + e2 * e2)
        e0, e1, e2 = e0 / n, e1 / n, e2 / n
        n0, n1, n2 = nu[g, 0], nu[g, 1], nu[g, 2]
        B[g, 0, 0], B[g, 1, 0], B[g, 2, 0] = n0, n1, n2
        B[g, 0, 1], B[g, 1, 1], B[g, 2, 1] = e0, e1, e2
        B[g, 0, 2], B[g, 1, 2], B[g, 2, 2] = n1 * e2 - n2 * e1, n2 * e0 - n0 * e2, n0 * e1 - n1 * e0


def multiplier_basis(nu, trial, stick, weak):
    """``mortar.multiplier_basis`` compiled (the numpy form's operations per group): ``(n, 3, 3)``."""
    B = np.empty((len(nu), 3, 3))
    _multiplier_basis(_c(nu), _c(trial), _c(stick, np.bool_), _c(weak, np.bool_), B)
    return B


@jit
def _sub_indexed(out, vals, idx):
    for p in range(out.shape[0]):
        o, v = out[p], vals[idx[p]]
        for i in range(o.shape[0]):
            for j in range(o.shape[1]):
                o[i, j] -= v[i, j]


def trial_rows(B, g2, slot_rows, wphi, wn, m, eps, mu, Pi, Q, C, c, dS, dn, dlam_n):
    """``mortar._trial_rows`` compiled: ``B[g] (3, 6 k) += C (Pi eps w du + Q w dnbar) + c mu w dlamN`` over the
    points' groups ``g2`` ``(P, 2)`` (of their nodes A, B) and slot rows ``slot_rows`` ``(2, P, 24)`` (node A's, node
    B's), in place; the per-point products summed in registers (no ``(P, 3, 24)`` temporaries), equal to the numpy
    form to round-off."""
    _trial_rows(B, _c(g2, np.int64), _c(slot_rows, np.int64), _c(wphi), _c(wn), _c(m), _c(eps), _c(mu), _c(Pi),
                _c(Q), _c(C), _c(c), _c(dS), _c(dn), _c(dlam_n))
    return B


def branch_rows(Tq, capq, g2, slot_rows, wphi, wn, m, eps, mu, Pi, Q, dS, dn, dlam_n):
    """``trial_rows`` at ``C = I, c = 0`` into ``Tq`` ``(n, 3, 6 k)`` and at ``C = 0, c = e_1`` (its first row) into
    ``capq`` ``(n, 6 k)``, in place, in one pass: the same sums without the zero products (``1 t0 + 0 t1 + 0 t2 +
    0 dl`` is ``t0``; the rows start at +0, which a zero of either sign leaves +0), the bits for finite terms."""
    _branch_rows(Tq, capq, _c(g2, np.int64), _c(slot_rows, np.int64), _c(wphi), _c(wn), _c(m), _c(eps), _c(mu),
                 _c(Pi), _c(Q), _c(dS), _c(dn), _c(dlam_n))
    return Tq, capq


def subtract_indexed(out, vals, idx):
    """``out[p] -= vals[idx[p]]`` in place (``out`` ``(P, r, c)``; no copy of ``vals[idx]``)."""
    _sub_indexed(out, _c(vals), _c(idx, np.int64))
    return out


def _c(a, dtype=np.float64):
    return np.ascontiguousarray(a, dtype=dtype)


def scatter_rows(out, g, rows, vals, scale=None):
    """``out[g[p], rows[p, i], :] += scale[p] vals[p, i, :]`` in place (``np.add.at`` order): ``out`` ``(n, r, c)``,
    ``g`` ``(P,)``, ``rows`` ``(P, m)``, ``vals`` ``(P, m, c)``, ``scale`` ``(P,)`` or None (no product).
    A 2-d ``out`` ``(n, r)`` and ``vals`` ``(P, m)`` add single entries."""
    flat = out.ndim == 2
    o = out[:, :, None] if flat else out
    v = _c(vals)[:, :, None] if flat else _c(vals)
    if scale is None:
        _rows_plain(o, _c(g, np.int64), _c(rows, np.int64), v)
    else:
        _rows(o, _c(g, np.int64), _c(rows, np.int64), v, _c(scale))
    return out


def scatter_block(out, g, rows, vals):
    """``out[g[p], rows[p, i], rows[p, j]] += vals[p, i, j]`` in place (``np.add.at`` order); ``out`` ``(n, r, r)``,
    ``rows`` ``(P, m)``, ``vals`` ``(P, m, m)``."""
    _block(out, _c(g, np.int64), _c(rows, np.int64), _c(vals))
    return out


def scatter_columns(out, g, cols, vals):
    """``out[g[p], i, cols[p, j]] += vals[p, i, j]`` in place (``np.add.at`` order); ``out`` ``(n, r, c)``,
    ``cols`` ``(P, m)``, ``vals`` ``(P, r, m)``."""
    _columns(out, _c(g, np.int64), _c(cols, np.int64), _c(vals))
    return out


def slivers(key, slave_nodes, xi1, sliver, groups=None):
    """``mortar.slivers`` compiled (its numpy form the oracle): ``(P, 2)`` bool, the points' nodes whose group
    (``key`` ``(P, 2)``) is a sliver at the ratio ``sliver`` (``mortar.SLIVER``).  The groups from a stable sort of
    the keys, each group's shape functions summed in the order of the points as ``np.bincount`` does (the same
    bits); 70 us of numpy a call on the main job's 80 points (two ``np.unique``, six ``np.bincount``).  ``groups``:
    ``sliver_groups(key)`` if kept (the same keys: ``mortar.Groups``)."""
    P = len(xi1)
    fold = np.zeros((P, 2), dtype=np.bool_)
    if P:
        key = _c(key, np.int64)
        order, start = sliver_groups(key) if groups is None else groups
        _sliver_fold(key, _c(slave_nodes, np.int64), _c(xi1), float(sliver), order, start, fold)
    return fold


def sliver_groups(key):
    """``(order, start)``: the stable sort of the keys ``(P, 2)`` raveled and where each group starts in it,
    ``(n + 1,)`` (``slivers``: they depend on the keys alone)."""
    k = _c(key, np.int64).ravel()
    order = np.argsort(k, kind="mergesort")          # stable: a group's entries in the points' order
    start = np.empty(len(k) + 1, dtype=np.int64)
    n = _group_starts(k, order, start)
    return order, start[:n + 1]


@jit
def _group_starts(k, order, start):
    n = 0
    for i in range(len(k)):
        if i == 0 or k[order[i]] != k[order[i - 1]]:
            start[n] = i
            n += 1
    start[n] = len(k)
    return n


@jit
def _sliver_fold(key, sn, xi1, sliver, order, start, fold):
    k = key.ravel()
    n = len(start) - 1
    uk = np.empty(n, dtype=np.int64)
    npts = np.empty(n, dtype=np.int64)
    pk = np.empty(n, dtype=np.int64)
    s_own, s_part = np.zeros(n), np.zeros(n)
    one_elem = np.ones(n, dtype=np.bool_)
    whole = np.zeros(n, dtype=np.bool_)
    b_side = np.zeros(n, dtype=np.bool_)
    for g in range(n):
        first = order[start[g]]
        e0, e1 = sn[first // 2, 0], sn[first // 2, 1]
        uk[g] = k[first]
        npts[g] = start[g + 1] - start[g]
        for j in range(start[g], start[g + 1]):
            i = order[j]
            p, a = i // 2, i % 2
            phi_a = xi1[p] if a == 1 else 1.0 - xi1[p]
            phi_b = 1.0 - xi1[p] if a == 1 else xi1[p]
            s_own[g] += phi_a
            s_part[g] += phi_b
            if sn[p, 0] != e0 or sn[p, 1] != e1:
                one_elem[g] = False
            if key[p, 0] == key[p, 1]:
                whole[g] = True
            pk[g] = key[p, 1 - a]                        # the last point's partner, as ``pk[inv] = part``
            b_side[g] = a == 1
    is_sliver = np.zeros(n, dtype=np.bool_)
    for g in range(n):
        j = np.searchsorted(uk, pk[g])
        single = npts[g] == 1 and npts[j] == 1 and (s_own[g] < s_part[g] or (s_own[g] == s_part[g] and b_side[g]))
        is_sliver[g] = one_elem[g] and not whole[g] and (s_own[g] < sliver * s_part[g] or single)
    for g in range(n):
        if is_sliver[g]:
            for j in range(start[g], start[g + 1]):
                i = order[j]
                p = i // 2
                fold[p, i % 2] = key[p, 0] != key[p, 1]


# ---------------------------------------------------------------- the numpy oracle
def scatter_rows_numpy(out, g, rows, vals, scale=None):
    """``scatter_rows`` by ``np.add.at``."""
    v = vals if scale is None else scale.reshape((-1,) + (1,) * (vals.ndim - 1)) * vals
    np.add.at(out, (g[:, None], rows), v)
    return out


def scatter_block_numpy(out, g, rows, vals):
    """``scatter_block`` by ``np.add.at``."""
    np.add.at(out, (g[:, None, None], rows[:, :, None], rows[:, None, :]), vals)
    return out


def scatter_columns_numpy(out, g, cols, vals):
    """``scatter_columns`` by ``np.add.at``."""
    np.add.at(out, (g[:, None, None], np.arange(out.shape[1])[None, :, None], cols[:, None, :]), vals)
    return out
