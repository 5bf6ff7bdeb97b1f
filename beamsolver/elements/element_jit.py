"""Compiled (numba) path of the two-node SE(3) beam element: one element per call, a batch driver.

The maths and names are those of ``geometric`` and of the numpy test oracle ``reference``
(both agree to round-off, ``tests/elements/test_compiled_kernels.py``): for the side
``s`` of node A (argument ``-h``, sign -1) and of node B (argument ``h``, sign
+1), ``T(h_s)^-1 = [[Ti, X], [0, Ti]]``, the force block ``g_s = [Ti n; X n + Ti m]``
and the geometric blocks ``G12, G21, G22`` of ``geometric._geometric``
(docs/theory.md eqs. 3.4-3.7).  The tangent goes to an array ``(n, 12, 12)``,
element-major (each element's 144 entries contiguous, so an element touches one or two
pages; docs/benchmarks.md), the order ``assembly.System`` scatters.  Node poses are read through a node table
``(n, 2)`` from the model's pose array (``elements.se3_2``), not gathered first.
"""
from .._jit import jit, jit_callee

from ..lie.se3_jit import CP_, C_, DP_, Q2P_, Q2_, Q3P_, Q3_, add, add_outer, axpy, coefficient, cross, dot, log_relative, madd, mat, mm, mscale, mv, pose, q_matrix, scale, ti, ti_matrix, transpose


@jit_callee
def _side(u, w, d, t2, wu, axu, c1, c2, c3):
    """``Ti``, ``X = -Ti Q(-u, -w) Ti`` of ``T(h)^-1`` at ``h = (u, w)``."""
    Ti = ti_matrix(w, d, t2)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), wu, axu, t2, c1, c2, c3)
    return Ti, mscale(-1.0, mm(mm(Ti, Q), Ti))


@jit_callee
def _d_tinv_t(w, d, dp, v):
    """``d(T_SO3(w)^-T v)/dw`` (``geometric._d_tinv_t``)."""
    wwv = cross(w, cross(w, v))
    M = add_outer(mat(scale(0.5, v), d * dot(w, v)), axpy(dp, wwv, scale(-2.0 * d, v)), w)
    return add_outer(M, w, scale(d, v))


@jit_callee
def _dq_du(y, yw, yww, w, t2, wy, c1, c2, c3):
    """``dQ/du`` of ``Q(u, w) y`` at fixed ``y`` (``geometric._geometric``)."""
    M = mat(scale(-1.0, add(add(scale(0.5 - c2 * t2, y), scale(c1 - c3 * t2, yw)), scale(c2, yww))), c1 * wy)
    M = add_outer(M, scale(-1.0, add(add(scale(c1, y), scale(c1 - 3.0 * c2, yw)), scale(c3, yww))), w)
    return add_outer(M, w, scale(-1.0, add(scale(c2, yw), scale(c3, yww))))


@jit_callee
def _dq_dw(u, w, y, yw, a_, b_, e_, wa_, gp, t2, wy, uy, wu, uxw, c1, c2, c3):
    """``dQ/dw`` of ``Q(u, w) y`` at fixed ``y`` (``geometric._geometric``)."""
    sk = add(add(add(scale(-c1, a_), scale(3.0 * c2 - c1, b_)), scale(-c3, e_)),
             add(scale((c1 - 3.0 * c2) * uy, w), scale(c2 * wy, u)))
    diag = c1 * uy + c2 * dot(w, a_) - c3 * wy * wu + c3 * dot(w, b_) - c3 * t2 * uy
    M = mat(sk, diag)
    l0 = add(add(gp, scale(-4.0 * c2, a_)),
             scale(c3, add(add(scale(wy, u), scale(-2.0, wa_)), add(scale(-2.0, b_), scale(uy, w)))))
    M = add_outer(M, l0, w)
    M = add_outer(M, add(add(scale(c3 * t2 - c1, y), scale(3.0 * c2 - c1, yw)), scale(-c3 * wy, w)), u)
    M = add_outer(M, w, add(scale(c2, a_), scale(c3, b_)))
    return add_outer(M, add(scale(c2, uxw), scale(c3, cross(w, uxw))), y)


@jit_callee
def _geometric(u, w, n, mo, d, t2, co):
    """``G12, G21, G22`` of ``G(h, sigma) = d(T(h)^-T sigma)/dh`` at ``h = (u, w)``; ``co``: coefficients."""
    c1, c2, c3, dp, cp, q2p, q3p = co
    y = ti(w, d, n, -1.0)
    yw = cross(w, y)
    yww = cross(w, yw)
    a_, b_, e_ = cross(u, y), cross(u, yw), cross(u, yww)
    wa_, wb_, we_ = cross(w, a_), cross(w, b_), cross(w, e_)
    wwa_, wwb_ = cross(w, wa_), cross(w, wb_)
    g1 = add(add(wa_, b_), wb_)
    g2 = add(add(wwa_, e_), scale(-3.0, wb_))
    g3 = add(we_, wwb_)
    z = add(add(scale(0.5, a_), scale(c1, g1)), add(scale(c2, g2), scale(c3, g3)))
    wy, uy, wu = dot(w, y), dot(u, y), dot(w, u)
    uxw = cross(u, w)
    gp = add(add(scale(cp, g1), scale(q2p, g2)), scale(q3p, g3))
    dQu = _dq_du(y, yw, yww, w, t2, wy, c1, c2, c3)
    dQw = _dq_dw(u, w, y, yw, a_, b_, e_, wa_, gp, t2, wy, uy, wu, uxw, c1, c2, c3)
    DAn = _d_tinv_t(w, d, dp, n)
    A = add_outer(mat(scale(-0.5, w), 1.0 - d * t2), scale(d, w), w)
    Q = q_matrix(u, w, wu, scale(-1.0, uxw), t2, c1, c2, c3)
    G21 = mscale(-1.0, mm(A, dQu))
    G22 = madd(_d_tinv_t(w, d, dp, add(mo, scale(-1.0, z))), mscale(-1.0, mm(A, madd(dQw, mm(Q, DAn)))))
    return DAn, G21, G22


@jit_callee
def _put(K, e, r0, c0, M):
    for i in range(3):
        for j in range(3):
            K[e, r0 + i, c0 + j] = M[i][j]


@jit_callee
def _scale_cols(M, k0, k1, k2):
    return ((M[0][0] * k0, M[0][1] * k1, M[0][2] * k2), (M[1][0] * k0, M[1][1] * k1, M[1][2] * k2),
            (M[2][0] * k0, M[2][1] * k1, M[2][2] * k2))


@jit_callee
def _block(C, i0, j0, e, invL):
    """``C[i0:i0+3, j0:j0+3] / L`` of element ``e`` as a 3x3 tuple."""
    return ((C[e, i0, j0] * invL, C[e, i0, j0 + 1] * invL, C[e, i0, j0 + 2] * invL),
            (C[e, i0 + 1, j0] * invL, C[e, i0 + 1, j0 + 1] * invL, C[e, i0 + 1, j0 + 2] * invL),
            (C[e, i0 + 2, j0] * invL, C[e, i0 + 2, j0 + 1] * invL, C[e, i0 + 2, j0 + 2] * invL))


@jit_callee
def _z_rows(TiT, XT, G12, G21, G22, C, e, invL, diagonal):
    """Rows of one node: ``Z = sign B_s^T (C/L) + [[0, G12], [G21, G22]]`` as four 3x3 blocks."""
    if diagonal:
        Z00 = _scale_cols(TiT, C[e, 0, 0] * invL, C[e, 1, 1] * invL, C[e, 2, 2] * invL)
        Z10 = madd(_scale_cols(XT, C[e, 0, 0] * invL, C[e, 1, 1] * invL, C[e, 2, 2] * invL), G21)
        Z11 = madd(_scale_cols(TiT, C[e, 3, 3] * invL, C[e, 4, 4] * invL, C[e, 5, 5] * invL), G22)
        return Z00, G12, Z10, Z11
    C00, C01 = _block(C, 0, 0, e, invL), _block(C, 0, 3, e, invL)
    C10, C11 = _block(C, 3, 0, e, invL), _block(C, 3, 3, e, invL)
    Z00, Z01 = mm(TiT, C00), madd(mm(TiT, C01), G12)
    Z10 = madd(madd(mm(XT, C00), mm(TiT, C10)), G21)
    Z11 = madd(madd(mm(XT, C01), mm(TiT, C11)), G22)
    return Z00, Z01, Z10, Z11


@jit_callee
def element_kernel(H, nodes, L, eps0, C, e, diagonal, tangent, f, h, strain, sigma, K):
    """Forces (and with ``tangent`` the tangent) of element ``e`` with node poses ``H[nodes[e]]``,
    written to row/column ``e``."""
    RA, xA = pose(H, nodes[e, 0])
    RB, xB = pose(H, nodes[e, 1])
    u, w, t, d = log_relative(RA, xA, RB, xB)
    invL = 1.0 / L[e]
    for i in range(3):
        h[e, i], h[e, 3 + i] = u[i], w[i]
    for i in range(6):
        strain[e, i] = h[e, i] * invL
    for i in range(6):
        s = 0.0
        if diagonal:
            s = C[e, i, i] * (strain[e, i] - eps0[e, i])
        else:
            for j in range(6):
                s += C[e, i, j] * (strain[e, j] - eps0[e, j])
        sigma[e, i] = s
    n = (sigma[e, 0], sigma[e, 1], sigma[e, 2])
    m = (sigma[e, 3], sigma[e, 4], sigma[e, 5])
    c1, c2, c3 = coefficient(C_, t), coefficient(Q2_, t), coefficient(Q3_, t)
    t2, wu, axu = t * t, dot(w, u), cross(w, u)
    mu, mw = scale(-1.0, u), scale(-1.0, w)
    TiB, XB = _side(u, w, d, t2, wu, axu, c1, c2, c3)       # node B: argument h
    TiA, XA = transpose(TiB), transpose(XB)                 # node A: argument -h (eq. 2.7: T(-h)^-1 blocks)
    gA0, gA1 = mv(TiA, n), add(mv(XA, n), mv(TiA, m))
    gB0, gB1 = mv(TiB, n), add(mv(XB, n), mv(TiB, m))
    for i in range(3):                                      # f_A = -g(h), f_B = g(-h)
        f[e, i], f[e, 3 + i] = -gB0[i], -gB1[i]
        f[e, 6 + i], f[e, 9 + i] = gA0[i], gA1[i]
    if not tangent:
        return
    co = (c1, c2, c3, coefficient(DP_, t), coefficient(CP_, t), coefficient(Q2P_, t), coefficient(Q3P_, t))
    for s in range(2):
        if s == 0:
            us, ws, Ti, X, sg = mu, mw, TiA, XA, -1.0
        else:
            us, ws, Ti, X, sg = u, w, TiB, XB, 1.0
        G12, G21, G22 = _geometric(us, ws, n, m, d, t2, co)
        Z00, Z01, Z10, Z11 = _z_rows(mscale(sg, transpose(Ti)), mscale(sg, transpose(X)), G12, G21, G22,
                                     C, e, invL, diagonal)
        for c in range(2):                                  # columns of node c: sign [[Ti, X], [0, Ti]]
            Tc, Xc = (mscale(-1.0, TiA), mscale(-1.0, XA)) if c == 0 else (TiB, XB)
            r0, c0 = 6 * s, 6 * c
            _put(K, e, r0, c0, mm(Z00, Tc))
            _put(K, e, r0 + 3, c0, mm(Z10, Tc))
            _put(K, e, r0, c0 + 3, madd(mm(Z00, Xc), mm(Z01, Tc)))
            _put(K, e, r0 + 3, c0 + 3, madd(mm(Z10, Xc), mm(Z11, Tc)))


@jit
def evaluate(H, nodes, L, eps0, C, diagonal, tangent, f, h, strain, sigma, K):
    """Batch driver: ``element_kernel`` over all elements (a plain loop; one core).

    ``H``: node poses ``(N, 4, 4)``, ``nodes``: ``(n, 2)`` rows of ``H`` of each element (A, B);
    reading the poses through the node table saves gathering them into copies.
    """
    for e in range(len(L)):
        element_kernel(H, nodes, L, eps0, C, e, diagonal, tangent, f, h, strain, sigma, K)


@jit
def relative_twists(HA, HB, h):
    """``h[e] = log(HA[e]^-1 HB[e])`` for poses ``(n, 4, 4)``, into ``h`` ``(n, 6)``."""
    for e in range(len(h)):
        RA, xA = pose(HA, e)
        RB, xB = pose(HB, e)
        u, w, t, d = log_relative(RA, xA, RB, xB)
        for i in range(3):
            h[e, i], h[e, 3 + i] = u[i], w[i]
