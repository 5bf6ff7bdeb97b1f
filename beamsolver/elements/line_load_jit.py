"""Compiled consistent nodal loads of line loads and their stiffness (``line_load``'s formulas).

One element per pass of a loop, small arrays written in place (no allocation per element).  The
loads in real arithmetic, as products of the operators with vectors; their derivative in the rotation
part of the element twist ``h`` by the same complex steps as the numpy form (every SE(3) function here
takes complex twists; the coefficients switch from series to closed form on the real part of the angle,
as ``se3.coefficient``), in its translation part in closed form (``_u_columns``): both forms agree to
round-off (``tests/elements/test_line_load.py``).  The angle's coefficients are computed once per twist
(``_inverse_tangents``, ``_gauss_operators``).  Conventions: ``line_load`` and docs/theory_line_loads.md;
speed: docs/benchmarks.md, "Strand bending, session 10".
"""
import numpy as np

from .._jit import jit, jit_callee
from ..lie.se3_jit import (A_, B_, C_, D_, Q2_, Q3_, _SERIES_TABLE, _SWITCH, _closed, cross, dot, log_relative,
                           pose, q_matrix)

__all__ = ["line_loads"]


@jit_callee
def _coef(k, t):
    """Coefficient ``k`` of ``se3`` at a complex angle ``t`` (series below the switch point of its real part)."""
    if t.real >= _SWITCH[k]:
        return _closed(k, t)
    row = _SERIES_TABLE[k]
    t2 = t * t
    v = row[8] + 0.0 * t2
    for j in range(7, -1, -1):
        v = v * t2 + row[j]
    return v


@jit_callee
def _skew(w, S):
    S[0, 0], S[0, 1], S[0, 2] = 0.0, -w[2], w[1]
    S[1, 0], S[1, 1], S[1, 2] = w[2], 0.0, -w[0]
    S[2, 0], S[2, 1], S[2, 2] = -w[1], w[0], 0.0


@jit_callee
def _mm(A, B, C):
    """``C = A B`` (square blocks of equal size)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            s = 0.0 * A[0, 0]
            for k in range(n):
                s += A[i, k] * B[k, j]
            C[i, j] = s


@jit_callee
def _inverse_tangents(h, Dp, Op, Dm, Om, s):
    """The inverse right tangents of SE(3) at ``h`` and ``-h`` (``se3.tangent_inv``): ``[[Dp, Op], [0, Dp]]`` and
    ``[[Dm, Om], [0, Dm]]``, written into the 3x3 blocks; the angle, its coefficients and ``hat(w)^2`` once
    (``hat(-w) = -hat(w)``).  ``h`` (6,) real or complex."""
    u, w = h[:3], h[3:]
    W, WW = s[0], s[1]
    t = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    c1, c2 = 1.0 * (0.5 + 0.0 * t), _coef(D_, t)
    _skew(w, W)
    _mm(W, W, WW)
    for i in range(3):
        for j in range(3):
            Dp[i, j] = c1 * W[i, j] + c2 * WW[i, j] + (1.0 if i == j else 0.0)
            Dm[i, j] = c1 * -W[i, j] + c2 * WW[i, j] + (1.0 if i == j else 0.0)
    c3, q2, q3 = _coef(C_, t), _coef(Q2_, t), _coef(Q3_, t)
    nu, nw = (-u[0], -u[1], -u[2]), (-w[0], -w[1], -w[2])
    for D, O, a, b in ((Dp, Op, nu, nw), (Dm, Om, (u[0], u[1], u[2]), (w[0], w[1], w[2]))):
        Q = q_matrix(a, b, dot(b, a), cross(b, a), t * t, c3, q2, q3)
        for i in range(3):
            for j in range(3):
                s[8][i, j] = Q[i][j]
        _mm(D, s[8], s[0])
        _mm(s[0], D, O)
        for i in range(3):
            for j in range(3):
                O[i, j] = -O[i, j]


@jit_callee
def _gauss_operators(h, Da, Oa, Dx, Ox, s):
    """At the twist ``h`` (6,): ``Ad(exp(h)^-1) = [[Da, Oa], [0, Da]]`` (``Da`` the transposed rotation of
    ``exp(h)``) and the right tangent ``T(h) = [[Dx, Ox], [0, Dx]]`` (``se3.tangent``), written into the 3x3
    blocks; the angle, its coefficients and ``hat(w)^2`` once."""
    u, w = h[:3], h[3:]
    W, WW, R = s[0], s[1], s[7]
    t = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    ca, cb, cc = 1.0 * _coef(A_, t), _coef(B_, t), _coef(C_, t)
    cx = -1.0 * cb
    _skew(w, W)
    _mm(W, W, WW)
    for i in range(3):
        for j in range(3):
            R[i, j] = ca * W[i, j] + cb * WW[i, j] + (1.0 if i == j else 0.0)
            Dx[i, j] = cx * W[i, j] + cc * WW[i, j] + (1.0 if i == j else 0.0)
    nu, nw = (-u[0], -u[1], -u[2]), (-w[0], -w[1], -w[2])
    Q = q_matrix(nu, nw, dot(nw, nu), cross(nw, nu), t * t, cc, _coef(Q2_, t), _coef(Q3_, t))
    for i in range(3):
        for j in range(3):
            Ox[i, j] = Q[i][j]
    wxu = s[9][0]
    wxu[0], wxu[1], wxu[2] = w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0]
    x = s[9][1]
    x[0] = u[0] + cb * wxu[0] + cc * (w[1] * wxu[2] - w[2] * wxu[1])
    x[1] = u[1] + cb * wxu[1] + cc * (w[2] * wxu[0] - w[0] * wxu[2])
    x[2] = u[2] + cb * wxu[2] + cc * (w[0] * wxu[1] - w[1] * wxu[0])
    p = s[9][2]
    for i in range(3):
        p[i] = 0.0
        for j in range(3):
            Da[i, j] = R[j, i]
            p[i] -= R[j, i] * x[j]
    _skew(p, s[0])
    _mm(s[0], Da, Oa)


@jit_callee
def _product(D1, O1, D2, O2, D, O, tmp):
    """``[[D, O], [0, D]] = [[D1, O1], [0, D1]] [[D2, O2], [0, D2]]``."""
    _mm(D1, D2, D)
    _mm(D1, O2, O)
    _mm(O1, D2, tmp)
    for i in range(3):
        for j in range(3):
            O[i, j] += tmp[i, j]


@jit_callee
def _tv(D, O, pu, pw, ou, ow):
    """``(ou, ow) = [[D, O], [0, D]]^T (pu, pw)``."""
    for i in range(3):
        a, b = 0.0 * pu[0], 0.0 * pu[0]
        for j in range(3):
            a += D[j, i] * pu[j]
            b += O[j, i] * pu[j] + D[j, i] * pw[j]
        ou[i], ow[i] = a, b


@jit_callee
def _point_load(Da, vq, vm, q, m, follower, pu, pw):
    """The load per unit length at a Gauss point in its section frame, ``pu``, ``pw`` (3,): the follower's own
    ``q``, ``m``, or the dead load's ``vq``, ``vm`` turned by the point's ``Da``."""
    for i in range(3):
        if follower:
            pu[i], pw[i] = q[i], m[i]
        else:
            pu[i] = Da[i, 0] * vq[0] + Da[i, 1] * vq[1] + Da[i, 2] * vq[2]
            pw[i] = Da[i, 0] * vm[0] + Da[i, 1] * vm[1] + Da[i, 2] * vm[2]


@jit_callee
def _element(vq, vm, h, L, q, m, follower, rotation, f, G, w6, XI, WEIGHTS):
    """``f`` (12,) = ``line_load._loads`` of one element (twist ``h``, real or complex; ``vq, vm`` the load in node
    A's frame, ``q, m`` as given); with ``rotation`` also ``G`` (12, 3), d f / d w_A at fixed ``h`` (real ``h``).
    Every 6x6 operator here is block upper triangular with equal diagonal blocks, kept as two 3x3 blocks.  The loads
    as products of the operators with vectors, ``Phi_B^T p = T(h)^-T y``, ``Phi_A^T p = Ad(E^-1)^T p - T(-h)^-T y``,
    ``y = x T(x h)^T p``; the operators themselves only for ``G``."""
    b, s, hx, pu, pw = w6
    Dp, Op, Dm, Om, Dx, Ox, Da, Oa, DA, OA, DB, OB, X = b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], \
        b[9], b[10], b[11], b[12]
    yu, yw, zu, zw = s[10][0], s[10][1], s[10][2], s[11][0]
    _inverse_tangents(h, Dp, Op, Dm, Om, s)
    f[:] = 0.0
    if rotation:
        G[:, :] = 0.0
    for g in range(XI.shape[0]):
        x, wg = XI[g], WEIGHTS[g]
        for i in range(6):
            hx[i] = x * h[i]
        _gauss_operators(hx, Da, Oa, Dx, Ox, s)
        _point_load(Da, vq, vm, q, m, follower, pu, pw)
        _tv(Dx, Ox, pu, pw, yu, yw)
        for i in range(3):
            yu[i] *= x
            yw[i] *= x
        _tv(Da, Oa, pu, pw, zu, zw)                      # Ad(E^-1)^T p
        for i in range(3):
            f[i] += wg * zu[i]
            f[3 + i] += wg * zw[i]
        _tv(Dm, Om, yu, yw, zu, zw)                      # Phi_A^T p = Ad(E^-1)^T p - T(-h)^-T y
        for i in range(3):
            f[i] -= wg * zu[i]
            f[3 + i] -= wg * zw[i]
        _tv(Dp, Op, yu, yw, zu, zw)                      # Phi_B^T p = T(h)^-T y
        for i in range(3):
            f[6 + i] += wg * zu[i]
            f[9 + i] += wg * zw[i]
        if rotation:
            for i in range(3):
                for j in range(3):
                    Dx[i, j] *= x
                    Ox[i, j] *= x
            _product(Dx, Ox, Dm, Om, DA, OA, X)          # Phi_A = Ad(E^-1) - x T(x h) T(-h)^-1
            for i in range(3):
                for j in range(3):
                    DA[i, j] = Da[i, j] - DA[i, j]
                    OA[i, j] = Oa[i, j] - OA[i, j]
            _product(Dx, Ox, Dp, Op, DB, OB, X)          # Phi_B = x T(x h) T(h)^-1
            # dp = (E^T hat(vq), E^T hat(vm)) (6, 3): the rigid turn of the element by dw_A
            Xq, Xm = s[0], s[1]
            _skew(vq, X)
            _mm(Da, X, Xq)
            _skew(vm, X)
            _mm(Da, X, Xm)
            for j in range(3):
                for i in range(3):
                    a0, a1, b0, b1 = 0.0, 0.0, 0.0, 0.0
                    for k in range(3):
                        a0 += (DA[k, i] * Xq[k, j]).real
                        a1 += (OA[k, i] * Xq[k, j] + DA[k, i] * Xm[k, j]).real
                        b0 += (DB[k, i] * Xq[k, j]).real
                        b1 += (OB[k, i] * Xq[k, j] + DB[k, i] * Xm[k, j]).real
                    G[i, j] += wg * a0
                    G[3 + i, j] += wg * a1
                    G[6 + i, j] += wg * b0
                    G[9 + i, j] += wg * b1
    for i in range(12):
        f[i] *= L
    if rotation:
        for i in range(12):
            for j in range(3):
                G[i, j] *= L


@jit_callee
def _u_columns(vq, vm, h, L, q, m, follower, D, w6, XI, WEIGHTS):
    """The columns ``D[:, :3]`` of ``d f / d h`` (the translation part ``u`` of ``h``), real: ``f`` is linear in
    ``u`` through the off-diagonal blocks ``O`` of the operators alone, each linear in ``u`` (``Q(u, w)``, the
    position in ``Ad``), so ``dO / du e`` is ``O`` at the twist ``(e, w)``; the diagonal blocks and ``p`` do not
    depend on ``u``, and with ``y = x T(x h)^T p``: ``d f_A = (0, dOa^T p_u - dOm^T y_u - Dm^T dy_w)``,
    ``d f_B = (0, dOp^T y_u + Dp^T dy_w)``, ``dy_w = x dOx^T p_u`` (the translation rows are zero)."""
    b, s, hx, pu, pw = w6
    Dp, Op, Dm, Om, Dx, Ox, Da, Oa = b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]
    yu, yw, zu, zw, dyw, z2 = s[10][0], s[10][1], s[10][2], s[11][0], s[11][1], s[11][2]
    he = b[12][0]
    for i in range(12):
        for k in range(3):
            D[i, k] = 0.0
    for k in range(3):
        for i in range(3):
            hx[i], hx[3 + i] = (1.0 if i == k else 0.0), h[3 + i]
        _inverse_tangents(hx, Dp, Op, Dm, Om, s)         # Op, Om: dOp e_k, dOm e_k (u of -h moves by -e_k)
        for g in range(XI.shape[0]):
            x, wg = XI[g], WEIGHTS[g]
            for i in range(3):
                hx[i], hx[3 + i] = (x if i == k else 0.0), x * h[3 + i]
            _gauss_operators(hx, Da, Oa, Dx, Ox, s)
            _point_load(Da, vq, vm, q, m, follower, pu, pw)
            for i in range(3):
                a, c = 0.0, 0.0
                for j in range(3):
                    a += Dx[j, i] * pu[j]
                    c += Ox[j, i] * pu[j]
                yu[i], dyw[i] = x * a, x * c
            for i in range(3):
                a, c, d = 0.0, 0.0, 0.0
                for j in range(3):
                    a += Oa[j, i] * pu[j] - Om[j, i] * yu[j] - Dm[j, i] * dyw[j]
                    c += Op[j, i] * yu[j] + Dp[j, i] * dyw[j]
                D[3 + i, k] += wg * a
                D[9 + i, k] += wg * c
    for i in range(12):
        for k in range(3):
            D[i, k] *= L


@jit
def line_loads(HA, HB, L, q, m, follower, tangent, f, K, XI, WEIGHTS, COMPLEX_STEP):
    """Consistent nodal loads ``f`` (n, 12) and, with ``tangent``, their derivative ``K`` (n, 12, 12) in the
    nodes' body increments (``line_load.nodal_loads_and_tangent``); poses ``HA, HB`` (n, 4, 4), lengths
    ``L`` (n,), loads per unit reference length ``q, m`` (n, 3), dead or ``follower``; Gauss points ``XI``,
    weights ``WEIGHTS`` on ``[0, 1]`` and the imaginary step ``COMPLEX_STEP`` (``line_load``'s).  The loads in
    real arithmetic (the complex form's real part, to round-off), their derivative in the rotation part of ``h`` by
    complex steps, in the translation part in closed form (``_u_columns``)."""
    c = np.complex128
    w6 = (np.zeros((13, 3, 3), c), np.zeros((12, 3, 3), c), np.zeros(6, c), np.zeros(3, c), np.zeros(3, c))
    w6r = (np.zeros((13, 3, 3)), np.zeros((12, 3, 3)), np.zeros(6), np.zeros(3), np.zeros(3))     # real scratch
    hh, fk = np.zeros(6, c), np.zeros(12, c)
    h, fe = np.zeros(6), np.zeros(12)
    vq, vm = np.zeros(3), np.zeros(3)
    G, D = np.zeros((12, 3)), np.zeros((12, 6))
    Tp, Tm = np.zeros((6, 6)), np.zeros((6, 6))
    b, s, hx = w6r[0], w6r[1], w6r[2]
    for e in range(HA.shape[0]):
        RA, xA = pose(HA, e)
        RB, xB = pose(HB, e)
        u, w, t, d = log_relative(RA, xA, RB, xB)
        for i in range(3):
            h[i], h[3 + i] = u[i], w[i]
            vq[i] = RA[0][i] * q[e, 0] + RA[1][i] * q[e, 1] + RA[2][i] * q[e, 2]
            vm[i] = RA[0][i] * m[e, 0] + RA[1][i] * m[e, 1] + RA[2][i] * m[e, 2]
        rotation = tangent and not follower
        _element(vq, vm, h, L[e], q[e], m[e], follower, rotation, fe, G, w6r, XI, WEIGHTS)
        for i in range(12):
            f[e, i] = fe[i]
        if not tangent:
            continue
        _u_columns(vq, vm, h, L[e], q[e], m[e], follower, D, w6r, XI, WEIGHTS)
        for k in range(3, 6):                            # the rotation part: complex steps
            for i in range(6):
                hh[i] = h[i]
            hh[k] += 1j * COMPLEX_STEP
            _element(vq, vm, hh, L[e], q[e], m[e], follower, False, fk, G, w6, XI, WEIGHTS)
            for i in range(12):
                D[i, k] = fk[i].imag / COMPLEX_STEP
        # K_A = -D T(-h)^-1 (+ the rigid turn G), K_B = D T(h)^-1
        _inverse_tangents(h, b[0], b[1], b[2], b[3], s)
        for i in range(3):
            for j in range(3):
                Tp[i, j] = Tp[3 + i, 3 + j] = b[0][i, j]
                Tp[i, 3 + j] = b[1][i, j]
                Tm[i, j] = Tm[3 + i, 3 + j] = b[2][i, j]
                Tm[i, 3 + j] = b[3][i, j]
        for i in range(12):
            for j in range(6):
                a, bb = 0.0, 0.0
                for k in range(6):
                    a += D[i, k] * Tm[k, j]
                    bb += D[i, k] * Tp[k, j]
                K[e, i, j] = -a
                K[e, i, 6 + j] = bb
            if rotation:
                for j in range(3):
                    K[e, i, 3 + j] += G[i, j]
