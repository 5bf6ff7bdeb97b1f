"""Compiled (numba) contact kernel with its exact tangent, one contact point per call.

The same maths, arguments and results as ``reference.contact_kernel`` /
``reference.kernel_and_tangent`` (their complex-step version is the test oracle,
``tests/contact/test_contact_kernel_jit.py``): projection (the same two Newton
iterations), section frames ``{C}``, ``{F}``, axes ``n, t1, t2``, gap, normal
law, friction (material frames, slip ``log(H_LK_prev^-1 H_LK)[1:3]`` as
``kinematics.slip_increment``, transported traction, slip-tolerance penalty,
Coulomb return mapping) and the nodal wrenches ``J^T w``.

The tangent is forward mode done by hand: every quantity carries its gradient
``(k, 24)`` with respect to the body increments of the nodes ``A1, B1, A2, B2``
(column ``6 j + k``).  Section frames vary as ``dq_C = J_A dq_A + J_B dq_B + h dxi``
(``frames.node_jacobians``), the twist as ``dh = T(h)^-1 (dq_B - Ad(exp(-h)) dq_A)``,
the projection parameters by the implicit-function theorem at the converged
projection, and the node Jacobians themselves through

- ``d(T(s)^T w)/ds = F(s, w)`` in closed form (``_dt_t``; ``d(T(h)^-T v)/dh = -T(h)^-T F(h, T(h)^-T v)``),
- ``d(Ad(exp(-s))^T w)/ds = -M(z) T(-s)``, ``z = Ad(exp(-s))^T w``,
  ``M(z) = [[0, hat(z_f)], [hat(z_f), hat(z_m)]]``.

One difference from the numpy kernel, where that one decides on a whole batch:
the ``active`` flag of the normal law is decided per point (the numpy kernel uses
the smoothed rule for every point of a batch in which any point has a smoothing
gap; the two differ only at a trial traction of exactly zero).
The contact law is pluggable: the kernel calls ``_normal_law`` and
``_tangential_law``, which ``make_kernel`` binds to a ``law.ContactLaw``'s compiled
scalar functions (default ``law.PENALTY_COULOMB``, tested equal to the numpy forms
``law.normal_force`` and ``law.coulomb_return_mapping`` the oracle uses).
``NUMBA_DISABLE_JIT=1`` runs this module as plain Python (slowly).

Nothing is allocated per point: small algebra stays in tuples, and the 6x6 matrices,
6-vectors and ``(k, 24)`` gradients live in scratch arrays made once per batch
(``_scratch``; named slots ``S_*``, ``V_*``; the gradients are rows of one array ``G`` at
the named row offsets ``G_*``) and written in place.  The loops over the 24 columns are
branch-free and read and write ``G`` at constant rows, so the compiler vectorises them
(AVX2, four columns per instruction; nothing proves that two separate arrays do not overlap,
and runtime overlap checks are refused in loops of fewer than 16 iterations): each column's
sum keeps its terms and their order, so vectorising changes no result.
Every sum keeps its terms and their order (the Newton iteration counts of the contact
examples are round-off sensitive); values that are needed twice are computed once only
where the two computations are the same operations on the same inputs.  Terms that are
structural zeros (the zero blocks of ``T``, ``T^-1``, ``Ad``, ``G`` and the node Jacobians)
are skipped: a sum started at ``+0.0`` is unchanged by an exact zero term, so the results
are the same floats (``_mm_ut``; in a tangent row, which also adds the exact zeros of the
twist variation on the other side's columns, up to the sign of a zero entry).
"""
import hashlib
import types

import numpy as np
from numba import config as numba_config, types as nb_types
from numba.core import cgutils
from numba.extending import intrinsic

from .._jit import jit, jit_callee
from ..errors import InputError
from ..model.buffers import BufferPool
from ..elements.element_jit import _dq_du, _dq_dw
from ..lie.se3_jit import madd, mscale
from ..lie.se3_jit import A_, B_, C_, CP_, D_, Q2P_, Q2_, Q3P_, Q3_, add, add_outer, coefficient, cross, dot, log_relative, mat, mm, mv, q_matrix, scale, ti_matrix, transpose
from . import mortar_jit
from .frames import LINE, ORTHOGONAL
from .law import PENALTY_COULOMB, PENALTY_T_MIN

# columns of the per-point parameter table ``par``
XI1, XI2, R1_, R2_, WEIGHT, PENALTY, MULT, MU, PEN_T, SMOOTH, ESLIP, XI1P, XI2P, TOUCH = range(14)
N_PAR = 14


# the law, bound per kernel by ``make_kernel`` (the templates below call these names)
_normal_law = _tangential_law = None


# ---------------------------------------------------------------- borrowed arrays
@intrinsic
def _borrowed_intrinsic(typingctx, a):
    """A view of the array ``a`` without its memory owner (meminfo): numba's reference counting
    (an atomic increment and decrement per array passed to a function or sliced) skips it.
    The caller keeps ``a`` alive while the view is in use."""
    if not isinstance(a, nb_types.Array):
        return None

    def codegen(context, builder, sig, args):
        ary = cgutils.create_struct_proxy(sig.args[0])(context, builder, value=args[0])
        ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
        ary.parent = cgutils.get_null_value(ary.parent.type)
        return ary._getvalue()

    return a(a), codegen


def _borrowed_python(a):
    """``_borrowed`` as plain Python (``NUMBA_DISABLE_JIT=1``): the array itself."""
    return a


_borrowed = _borrowed_python if numba_config.DISABLE_JIT else _borrowed_intrinsic


# ---------------------------------------------------------------- small algebra (tuples; small arrays written in place)
@jit_callee
def _exp_abc(u, w, t2, a, b, c):
    """``exp(hat(u, w))`` as rotation and position tuples (``se3.exp``) from ``t2 = |w|^2`` and the
    coefficients ``a, b, c`` at ``|w|``."""
    R = add_outer(mat(scale(a, w), 1.0 - b * t2), scale(b, w), w)
    wxu = cross(w, u)
    return R, add(add(u, scale(b, wxu)), scale(c, cross(w, wxu)))


@jit_callee
def _exp_inline(u, w):
    """``exp(hat(u, w))`` as rotation and position tuples (``se3.exp``), inlined into its caller."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    return _exp_abc(u, w, t2, coefficient(A_, t), coefficient(B_, t), coefficient(C_, t))


@jit_callee
def _section_inline(RA, xA, u, w, xi):
    """``_section`` inlined into its caller (the same operations; ``_project``'s iterations: the parts a
    projection kind does not use are dropped by the compiler)."""
    Rs, xs = _exp_inline(scale(xi, u), scale(xi, w))
    R = mm(RA, Rs)
    return R, add(mv(RA, xs), xA), mv(R, u), mv(R, cross(w, u))


@jit_callee
def _section(RA, xA, u, w, xi):
    """Pose of ``H_A exp(xi h)``, ``x' = R u`` and ``x'' = R (w x u)`` (``frames.section``)."""
    return _section_inline(RA, xA, u, w, xi)


@jit_callee
def _coefficients(w):
    """``t^2 = |w|^2`` and the coefficients ``a, b, c, q2, q3, cp, q2p, q3p`` at ``t`` (``coefficient``,
    each once): the sections, node Jacobians and their derivatives at one ``xi h`` share them."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    return t2, (coefficient(A_, t), coefficient(B_, t), coefficient(C_, t), coefficient(Q2_, t), coefficient(Q3_, t),
                coefficient(CP_, t), coefficient(Q2P_, t), coefficient(Q3P_, t))


@jit_callee
def _exp_co(u, w, t2, co):
    """``exp(hat(u, w))`` (``_exp_inline``) with the coefficients of ``_coefficients(w)``."""
    return _exp_abc(u, w, t2, co[0], co[1], co[2])


@jit_callee
def _section_co(RA, xA, u, w, xi, t2, co):
    """``_section`` with the coefficients of ``_coefficients(xi w)``."""
    Rs, xs = _exp_co(scale(xi, u), scale(xi, w), t2, co)
    R = mm(RA, Rs)
    return R, add(mv(RA, xs), xA), mv(R, u), mv(R, cross(w, u))


@jit_callee
def _pose_of(X, j):
    R = ((X[j, 0, 0], X[j, 0, 1], X[j, 0, 2]), (X[j, 1, 0], X[j, 1, 1], X[j, 1, 2]),
         (X[j, 2, 0], X[j, 2, 1], X[j, 2, 2]))
    return R, (X[j, 0, 3], X[j, 1, 3], X[j, 2, 3])


@jit_callee
def _put3(A, r0, c0, M):
    for i in range(3):
        for j in range(3):
            A[r0 + i, c0 + j] = M[i][j]


@jit_callee
def _zero3(A, r0, c0):
    for i in range(3):
        for j in range(3):
            A[r0 + i, c0 + j] = 0.0


@jit_callee
def _col(R, j):
    return (R[0][j], R[1][j], R[2][j])


@jit_callee
def _mm_ut(A, B, out):
    """``out = A @ B`` for block upper-triangular ``(6, 6)`` arrays (``A[3:, :3] == B[3:, :3] == 0``, as
    ``T(h)``, ``T(h)^-1``, ``Ad(H)``): ``_mm`` without the terms of the zero blocks.  The same floats:
    a sum started at ``+0.0`` never becomes ``-0.0``, so adding an exact zero changes nothing."""
    for i in range(6):
        for j in range(6):
            acc = 0.0
            for l in range(3 if i >= 3 else 0, 3 if j < 3 else 6):
                acc += A[i, l] * B[l, j]
            out[i, j] = acc


@jit_callee
def _exp(u, w):
    """``_exp_inline`` as a function of its own (one copy of the maths, called where not inlined)."""
    return _exp_inline(u, w)


@jit_callee
def _ut_entry(A, B, i, j):
    """``(A @ B)[i, j]`` of two block upper-triangular 6 x 6 matrices (``_mm_ut``'s sum: its nonzero terms in order)."""
    acc = 0.0
    for l in range(3 if i >= 3 else 0, 3 if j < 3 else 6):
        acc += A[i, l] * B[l, j]
    return acc


@jit_callee
def _mm_ut_scaled(A, B, x, out):
    """``out = (A @ B) x`` (``_mm_ut``'s sums, each times ``x``)."""
    for i in range(6):
        for j in range(6):
            out[i, j] = _ut_entry(A, B, i, j) * x


@jit_callee
def _minus_mm_ut(C, A, B, out):
    """``out = C - A @ B`` (``_mm_ut``'s sums)."""
    for i in range(6):
        for j in range(6):
            out[i, j] = C[i, j] - _ut_entry(A, B, i, j)


@jit_callee
def _tangent(u, w, T):
    """``T = T(h) = [[T3, Q(-u, -w)], [0, T3]]`` (``se3.tangent``), ``(6, 6)``."""
    t2, co = _coefficients_exp_tangent(w)
    _tangent_co(u, w, T, t2, co)


@jit_callee
def _tangent_co(u, w, T, t2, co):
    """``_tangent`` with the coefficients of ``_coefficients(w)`` (or of ``-w``: the same)."""
    b, c = co[1], co[2]
    T3 = add_outer(mat(scale(-b, w), 1.0 - c * t2), scale(c, w), w)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), dot(w, u), cross(w, u), t2, c, co[3], co[4])
    _put3(T, 0, 0, T3)
    _put3(T, 3, 3, T3)
    _put3(T, 0, 3, Q)
    _zero3(T, 3, 0)


@jit_callee
def _tangent_inv(u, w, T):
    """``T = T(h)^-1 = [[Ti, -Ti Q(-u, -w) Ti], [0, Ti]]`` (``se3.tangent_inv``), ``(6, 6)``."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    _tangent_inv_co(u, w, T, t2, coefficient(C_, t), coefficient(D_, t), coefficient(Q2_, t), coefficient(Q3_, t))


@jit_callee
def _tangent_inv_co(u, w, T, t2, c, d, q2, q3):
    """``_tangent_inv`` given ``t2 = |w|^2`` and the coefficients ``c, d, q2, q3`` at ``|w|``."""
    Ti = ti_matrix(w, d, t2)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), dot(w, u), cross(w, u), t2, c, q2, q3)
    X = mm(mm(Ti, Q), Ti)
    _put3(T, 0, 0, Ti)
    _put3(T, 3, 3, Ti)
    _put3(T, 0, 3, ((-X[0][0], -X[0][1], -X[0][2]), (-X[1][0], -X[1][1], -X[1][2]),
                    (-X[2][0], -X[2][1], -X[2][2])))
    _zero3(T, 3, 0)


@jit_callee
def _adjoint_inv(R, x, A):
    """``A = Ad(H^-1)`` of the pose ``(R, x)``; ``Ad(H) = [[R, hat(x) R], [0, R]]``, ``(6, 6)``."""
    Rt = transpose(R)
    xt = scale(-1.0, mv(Rt, x))
    _put3(A, 0, 0, Rt)
    _put3(A, 3, 3, Rt)
    _put3(A, 0, 3, mm(mat(xt, 0.0), Rt))
    _zero3(A, 3, 0)


# ---------------------------------------------------------------- one side of a pair: scratch slots
# 6x6 slots of a side's scratch ``S`` (N_SIDE, 6, 6)
(S_TI, S_AH, S_TS, S_AS, S_JA, S_JB, S_DA, S_DB, S_TMH, S_TIAH) = range(10)
assert S_JB == S_JA + 1      # (``_nodal_forces``)
N_SIDE = 10
# 6-vector slots of a side's ``v`` (N_VEC, 6)
(V_WR, V_DB, V_DA) = range(3)
N_VEC = 3
# the gradients ``(k, 24)`` of one point: rows of one flat array ``G`` (N_G * W,), row ``r``, column ``k`` at
# ``G[r * W + k]``; a quantity's rows start at its row offset ``G_*``.  One array and constant offsets let the
# compiler see that the accesses of a loop do not overlap, so the loops over the columns vectorise
# without runtime overlap checks (it refuses more than 8 of them per loop, and any in loops of fewer than
# 16 iterations).  Loops over rows go inside the loop over the columns (unrolled there, a tuple's index
# is a constant; a variable index is a branch that stops the vectorisation).
W = 24
_SIZES = dict(VC=6, VF=6, DH1=6, DH2=6, DWC=6, DWF=6, DN=3, DT1=3, DT2=3, DF=3, DMF=3, DSLIP=2, DLP=2, DPREV=2,
              DTR=2, DXI1=1, DXI2=1, DDIST=1, DLAM=1, DPT=1, WQ=2)
_OFFSETS = dict(zip(_SIZES, np.cumsum([0] + list(_SIZES.values()))[:-1].tolist()))
(G_VC, G_VF, G_DH1, G_DH2, G_DWC, G_DWF, G_DN, G_DT1, G_DT2, G_DF, G_DMF, G_DSLIP, G_DLP, G_DPREV, G_DTR, G_DXI1,
 G_DXI2, G_DDIST, G_DLAM, G_DPT, G_WQ) = _OFFSETS.values()
N_G = sum(_SIZES.values())


@jit_callee
def _side(u, w, S, t2, co, d):
    """``T(h)^-1`` and ``Ad(exp(-h))`` of an element twist into ``S[S_TI]``, ``S[S_AH]``; ``t2, co = _coefficients(w)``,
    ``d`` the coefficient ``d`` at ``|w|``."""
    _tangent_inv_co(u, w, S[S_TI], t2, co[2], d, co[3], co[4])
    Rh, xh = _exp_co(u, w, t2, co)
    _adjoint_inv(Rh, xh, S[S_AH])


@jit_callee
def _jacobians(u, w, xi, t2, co, Ti, Ah, Ts, As, JA, JB):
    """``J_A, J_B`` of ``H_C = H_A exp(xi h)`` (``frames.node_jacobians``); ``Ti = T(h)^-1``,
    ``Ah = Ad(exp(-h))``; also ``Ts = T(xi h)`` and ``As = Ad(exp(-xi h))``; ``t2, co = _coefficients(xi w)``."""
    su, sw = scale(xi, u), scale(xi, w)
    _tangent_co(su, sw, Ts, t2, co)
    _mm_ut_scaled(Ts, Ti, xi, JB)
    Rs, xs = _exp_co(su, sw, t2, co)
    _adjoint_inv(Rs, xs, As)
    _minus_mm_ut(As, JB, Ah, JA)


@jit_callee
def _blk(A, r0, c0):
    """The 3x3 block ``A[r0:r0+3, c0:c0+3]`` of a ``(6, 6)`` array as a tuple."""
    return ((A[r0, c0], A[r0, c0 + 1], A[r0, c0 + 2]), (A[r0 + 1, c0], A[r0 + 1, c0 + 1], A[r0 + 1, c0 + 2]),
            (A[r0 + 2, c0], A[r0 + 2, c0 + 1], A[r0 + 2, c0 + 2]))


@jit_callee
def _hat_mm(z, A):
    """``hat(z) A`` of a 3-vector and a 3x3 tuple: rows ``z1 A_2 - z2 A_1, z2 A_0 - z0 A_2, z0 A_1 - z1 A_0``."""
    return (add(scale(z[1], A[2]), scale(-z[2], A[1])), add(scale(z[2], A[0]), scale(-z[0], A[2])),
            add(scale(z[0], A[1]), scale(-z[1], A[0])))


@jit_callee
def _msub(A, s, B):
    """``A - s B`` of 3x3 tuples."""
    return madd(A, mscale(-s, B))


@jit_callee
def _mdiff(A, B):
    """``A - B`` of 3x3 tuples."""
    return (add(A[0], scale(-1.0, B[0])), add(A[1], scale(-1.0, B[1])), add(A[2], scale(-1.0, B[2])))


@jit_callee
def _axmy(s, A, B):
    """``s A - B`` of 3x3 tuples."""
    return (add(scale(s, A[0]), scale(-1.0, B[0])), add(scale(s, A[1]), scale(-1.0, B[1])),
            add(scale(s, A[2]), scale(-1.0, B[2])))


@jit_callee
def _d_t3t(w, v, b, c, bp, cp):
    """``d(T3(w)^T v)/dw`` at fixed ``v``, ``T3(w)^T v = v + b w x v + c w x (w x v)`` (the ``SO(3)`` block of
    ``T(h)^T``): ``-b hat(v) + bp (w x v) w^T + c ((w.v) I + w v^T - 2 v w^T) + cp (w x (w x v)) w^T`` with
    ``bp = b'(t)/t = a c - b^2``, ``cp = c'(t)/t``."""
    wv = cross(w, v)
    M = add_outer(mat(scale(-b, v), c * dot(w, v)),
                  add(add(scale(bp, wv), scale(cp, cross(w, wv))), scale(-2.0 * c, v)), w)
    return add_outer(M, scale(c, w), v)


@jit_callee
def _dt_t(u, w, a, m, t2, ca, b, c1, c2, c3, cp, q2p, q3p):
    """``F = d(T(s)^T wr)/ds`` at fixed ``wr = (a, m)``, ``s = (u, w)``, as the blocks ``F12, F21, F22`` of
    ``[[0, F12], [F21, F22]]``; ``t2 = |w|^2`` and the coefficients ``a, b, c, q2, q3, cp, q2p, q3p`` at ``|w|``.
    ``T(s)^T wr = (T3^T a, Q(u, w) a + T3^T m)`` (``Q(-u, -w)^T = Q(u, w)``): ``F12 = d(T3^T a)/dw``,
    ``F21 = dQ/du a``, ``F22 = dQ/dw a + d(T3^T m)/dw`` (``element_jit._dq_du``, ``_dq_dw``, ``_d_t3t``).
    ``T(s)^T G(s, T(s)^T wr) = -F``."""
    bp = ca * c1 - b * b
    yw = cross(w, a)
    yww = cross(w, yw)
    a_, b_, e_ = cross(u, a), cross(u, yw), cross(u, yww)
    wa_, wb_ = cross(w, a_), cross(w, b_)
    g1 = add(add(wa_, b_), wb_)
    g2 = add(add(cross(w, wa_), e_), scale(-3.0, wb_))
    g3 = add(cross(w, e_), cross(w, wb_))
    gp = add(add(scale(cp, g1), scale(q2p, g2)), scale(q3p, g3))
    wy = dot(w, a)
    F21 = _dq_du(a, yw, yww, w, t2, wy, c1, c2, c3)
    dQw = _dq_dw(u, w, a, yw, a_, b_, e_, wa_, gp, t2, wy, dot(u, a), dot(w, u), cross(u, w), c1, c2, c3)
    return _d_t3t(w, a, b, c1, bp, cp), F21, madd(dQw, _d_t3t(w, m, b, c1, bp, cp))


@jit_callee
def _jacobian_derivatives(u, w, xi, t2, co, S, v, c):
    """``d(J_A^T wr)/dh, d(J_B^T wr)/dh`` into ``S[S_DA], S[S_DB]`` and ``d/dxi`` into ``v[V_DA], v[V_DB]``
    at fixed ``wr = v[V_WR]``; ``S`` holds ``TI, AH, TMH`` of the element and ``TS, AS, JB`` at this ``xi``;
    ``c``: the element's cached coefficients (``_element_side``); ``t2, co = _coefficients(xi w)``.

    With ``s = xi h``, ``y = T(s)^T wr``, ``b = J_B^T wr = xi T(h)^-T y``, ``T(-s) h = h`` and
    ``F(s, x) = d(T(s)^T x)/ds`` at fixed ``x`` (``_dt_t``; ``G(h, v) = d(T(h)^-T v)/dh = -T(h)^-T F(h, T(h)^-T v)``):
    ``dB/dh = T(h)^-T N``, ``N = xi^2 F(s, wr) - F(h, b)``, ``dB/dxi = T(h)^-T (y + xi F(s, wr) h)``,
    ``dA/dh = -xi M(z_s) T(-s) + M(z_h) T(-h) - Ad(exp(-h))^T dB/dh``, ``dA/dxi = -M(z_s) h - Ad(exp(-h))^T dB/dxi``
    (``z_s = Ad(exp(-s))^T wr``, ``z_h = Ad(exp(-h))^T b``).  Done in 3x3 blocks: ``F``, ``M(z) T``, ``dA/dh``,
    ``dB/dh`` have a zero upper-left block; ``J_B``, ``T``, ``T^-1``, ``Ad`` are ``[[X, Y], [0, X]]``;
    ``T(-s) = [[T3^T, Q3^T], [0, T3^T]]`` of ``T(s) = [[T3, Q3], [0, T3]]`` (``Q(u, w)^T = Q(-u, -w)``).
    """
    wr = v[V_WR]
    a, m = (wr[0], wr[1], wr[2]), (wr[3], wr[4], wr[5])
    T3t, Q3t = transpose(_blk(S[S_TS], 0, 0)), transpose(_blk(S[S_TS], 0, 3))     # T(-s) blocks
    yf, ym = mv(T3t, a), add(mv(Q3t, a), mv(T3t, m))                               # y = T(s)^T wr
    F12, F21, F22 = _dt_t(scale(xi, u), scale(xi, w), a, m, t2, co[0], co[1], co[2], co[3], co[4], co[5], co[6],
                          co[7])                                                     # F(s, wr)
    Ti3t, Xt = transpose(_blk(S[S_TI], 0, 0)), transpose(_blk(S[S_TI], 0, 3))
    tyf, tym = mv(Ti3t, yf), add(mv(Xt, yf), mv(Ti3t, ym))                          # T(h)^-T y
    bf, bm = scale(xi, tyf), scale(xi, tym)                                           # b = J_B^T wr
    H12, H21, H22 = _dt_t(u, w, bf, bm, c[C_T2], c[C_A], c[C_B], c[C_CO], c[C_CO + 1], c[C_CO + 2], c[C_CO + 3],
                          c[C_CO + 4], c[C_CO + 5])                                 # F(h, b)
    x2 = xi * xi
    N12, N21, N22 = _axmy(x2, F12, H12), _axmy(x2, F21, H21), _axmy(x2, F22, H22)
    B12, B21, B22 = mm(Ti3t, N12), mm(Ti3t, N21), madd(mm(Xt, N12), mm(Ti3t, N22))   # dB/dh = T(h)^-T N
    ef = add(yf, scale(xi, mv(F12, w)))                                               # y + xi F(s, wr) h
    em = add(ym, scale(xi, add(mv(F21, u), mv(F22, w))))
    dBf, dBm = mv(Ti3t, ef), add(mv(Xt, ef), mv(Ti3t, em))
    Rst, Yst = transpose(_blk(S[S_AS], 0, 0)), transpose(_blk(S[S_AS], 0, 3))
    zsf, zsm = mv(Rst, a), add(mv(Yst, a), mv(Rst, m))
    Rht, Yht = transpose(_blk(S[S_AH], 0, 0)), transpose(_blk(S[S_AH], 0, 3))
    zhf, zhm = mv(Rht, bf), add(mv(Yht, bf), mv(Rht, bm))
    T3h, Q3h = _blk(S[S_TMH], 0, 0), _blk(S[S_TMH], 0, 3)                           # T(-h) blocks
    Cz = _msub(_hat_mm(zhf, T3h), xi, _hat_mm(zsf, T3t))
    A22 = _msub(madd(_hat_mm(zhf, Q3h), _hat_mm(zhm, T3h)), xi, madd(_hat_mm(zsf, Q3t), _hat_mm(zsm, T3t)))
    A22 = _mdiff(_mdiff(A22, mm(Yht, B12)), mm(Rht, B22))
    DA, DB = S[S_DA], S[S_DB]
    _zero3(DA, 0, 0)
    _put3(DA, 0, 3, _mdiff(Cz, mm(Rht, B12)))
    _put3(DA, 3, 0, _mdiff(Cz, mm(Rht, B21)))
    _put3(DA, 3, 3, A22)
    _zero3(DB, 0, 0)
    _put3(DB, 0, 3, B12)
    _put3(DB, 3, 0, B21)
    _put3(DB, 3, 3, B22)
    dAf = add(cross(zsf, w), mv(Rht, dBf))
    dAm = add(add(cross(zsf, u), cross(zsm, w)), add(mv(Yht, dBf), mv(Rht, dBm)))
    dA, dB = v[V_DA], v[V_DB]
    for i in range(3):
        dA[i], dA[3 + i], dB[i], dB[3 + i] = -dAf[i], -dAm[i], dBf[i], dBm[i]


# ---------------------------------------------------------------- projection and its derivative
@jit_callee
def _same(a, b):
    """``a`` and ``b`` are the same float, bit for bit (not nan)."""
    return a == b and np.signbit(a) == np.signbit(b)


@jit_callee
def _project(kind, RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2, iterations=2):
    """Newton iterations of ``frames.project`` (two in the kernel, from the search's converged point).

    The slave section is computed once where ``xi1`` is fixed (line, orthogonal), and the iterations
    stop at an exact fixed point (an iterate equal to the last, bit for bit, fixes all later ones), so
    the result is that of all ``iterations``."""
    return _project_from(kind, _section_inline(RA1, xA1, u1, w1, xi1), RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2,
                         iterations)


@jit_callee
def _project_from(kind, sec1, RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2, iterations):
    """``_project`` given the slave section ``sec1 = _section(RA1, xA1, u1, w1, xi1)`` (a caller that has it)."""
    return _project_kept(kind, sec1, RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2, iterations)[:2]


@jit_callee
def _project_kept(kind, sec1, RA1, xA1, u1, w1, xi1, RA2, xA2, u2, w2, xi2, iterations):
    """``_project_from`` and the last sections it computed: ``(xi1, xi2, sec1, sec2, at1, at2)``; ``at1``, ``at2``:
    ``sec1``, ``sec2`` are the sections at the returned ``xi1``, ``xi2`` (computed at them, bit for bit: the same
    floats as a new ``_section`` there)."""
    moving = kind != LINE and kind != ORTHOGONAL
    R1, x1, x1p, x1pp = sec1
    sec2, at1, at2 = sec1, xi1, np.nan        # (``sec2``: a placeholder until the first iteration)
    for it in range(iterations):
        if moving and it > 0:
            sec1, at1 = _section_inline(RA1, xA1, u1, w1, xi1), xi1
            R1, x1, x1p, x1pp = sec1
        sec2, at2 = _section_inline(RA2, xA2, u2, w2, xi2), xi2
        R2, x2, x2p, x2pp = sec2
        d = add(x2, scale(-1.0, x1))
        e1 = _col(R1, 0)
        xi1_new, xi2_new = xi1, xi2
        if kind == LINE:
            j = dot(x2p, e1)
            xi2_new = xi2 - dot(d, e1) / (j if j != 0.0 else 1.0)
        elif kind == ORTHOGONAL:
            j = dot(x2p, x2p) + dot(d, x2pp)
            xi2_new = xi2 - dot(d, x2p) / (j if j != 0.0 else 1.0)
        else:
            a11 = -dot(x1p, x1p) + dot(d, x1pp)
            a12, a21 = dot(x2p, x1p), -dot(x1p, x2p)
            a22 = dot(x2p, x2p) + dot(d, x2pp)
            det = a11 * a22 - a12 * a21
            det = det if det != 0.0 else 1.0
            g1, g2 = dot(d, x1p), dot(d, x2p)
            xi1_new = xi1 - (a22 * g1 - a12 * g2) / det
            xi2_new = xi2 - (-a21 * g1 + a11 * g2) / det
        if _same(xi1_new, xi1) and _same(xi2_new, xi2):
            return xi1_new, xi2_new, sec1, sec2, _same(at1, xi1_new), _same(at2, xi2_new)
        xi1, xi2 = xi1_new, xi2_new
    return xi1, xi2, sec1, sec2, _same(at1, xi1), _same(at2, xi2)


@jit_callee
def _rot_col(R, G, r0, k):
    """``R @ G[r0:r0+3, k]``, ``R`` a 3x3 tuple."""
    return (R[0][0] * G[r0 * W + k] + R[0][1] * G[(r0 + 1) * W + k] + R[0][2] * G[(r0 + 2) * W + k],
            R[1][0] * G[r0 * W + k] + R[1][1] * G[(r0 + 1) * W + k] + R[1][2] * G[(r0 + 2) * W + k],
            R[2][0] * G[r0 * W + k] + R[2][1] * G[(r0 + 1) * W + k] + R[2][2] * G[(r0 + 2) * W + k])


@jit_callee
def _col_dot(a, G, r0, k):
    """``a . G[r0:r0+3, k]`` (rows of ``G``)."""
    return a[0] * G[r0 * W + k] + a[1] * G[(r0 + 1) * W + k] + a[2] * G[(r0 + 2) * W + k]


@jit_callee
def _projection_gradient(kind, RC, u1, w1, RF, u2, w2, d, G):
    """``dxi1, dxi2`` (rows ``G_DXI1``, ``G_DXI2`` of ``G``) by the implicit-function theorem at the converged
    projection, from the section-frame variations at fixed ``xi`` (rows ``G_VC``, ``G_VF``) and the twist
    variations (``G_DH1``, ``G_DH2``).  The Jacobians (and their zero guards) are those of ``_project``.
    """
    x1p, x2p = mv(RC, u1), mv(RF, u2)
    x1pp, x2pp = mv(RC, cross(w1, u1)), mv(RF, cross(w2, u2))
    dC, dF = mv(transpose(RC), d), mv(transpose(RF), d)
    e1 = _col(RC, 0)
    c1, c2 = cross(u1, dC), cross(u2, dF)
    jl = dot(x2p, e1)
    jl = jl if jl != 0.0 else 1.0
    jo = dot(x2p, x2p) + dot(d, x2pp)
    jo = jo if jo != 0.0 else 1.0
    a11 = -dot(x1p, x1p) + dot(d, x1pp)
    a12, a21 = dot(x2p, x1p), -dot(x1p, x2p)
    a22 = dot(x2p, x2p) + dot(d, x2pp)
    det = a11 * a22 - a12 * a21
    det = det if det != 0.0 else 1.0
    # one loop over the columns per kind (branch-free: vectorised; a kind's loop computes only what it uses)
    if kind == LINE:
        for k in range(24):
            rel = _relative_col(RC, RF, G, k)
            g = dot(e1, rel) - dC[2] * G[(G_VC + 4) * W + k] + dC[1] * G[(G_VC + 5) * W + k]
            G[G_DXI1 * W + k], G[G_DXI2 * W + k] = 0.0, -g / jl
    elif kind == ORTHOGONAL:
        for k in range(24):
            rel = _relative_col(RC, RF, G, k)
            g2 = dot(x2p, rel) + _col_dot(c2, G, G_VF + 3, k) + _col_dot(dF, G, G_DH2, k)
            G[G_DXI1 * W + k], G[G_DXI2 * W + k] = 0.0, -g2 / jo
    else:
        for k in range(24):
            rel = _relative_col(RC, RF, G, k)
            g2 = dot(x2p, rel) + _col_dot(c2, G, G_VF + 3, k) + _col_dot(dF, G, G_DH2, k)
            g1 = dot(x1p, rel) + _col_dot(c1, G, G_VC + 3, k) + _col_dot(dC, G, G_DH1, k)
            G[G_DXI1 * W + k], G[G_DXI2 * W + k] = -(a22 * g1 - a12 * g2) / det, -(-a21 * g1 + a11 * g2) / det


@jit_callee
def _relative_col(RC, RF, G, k):
    """Column ``k`` of the variation of ``d = x_F - x_C`` at fixed ``xi`` (rows ``G_VC``, ``G_VF`` of ``G``)."""
    dxC, dxF = _rot_col(RC, G, G_VC, k), _rot_col(RF, G, G_VF, k)
    return (dxF[0] - dxC[0], dxF[1] - dxC[1], dxF[2] - dxC[2])


# ---------------------------------------------------------------- one side of a pair: element, section, Jacobians
# per-side element cache ``c`` (2, N_CACHE): the node poses (rows 0-2 of nodes j0, j0 + 1), the twist and the
# coefficients ``a, b`` and ``c, q2, q3, cp, q2p, q3p`` of ``F(h, .)`` of the last element seen on that side
C_POSE, C_U, C_W, C_T2, C_A, C_B, C_CO, N_CACHE = 0, 24, 27, 30, 31, 32, 33, 39


@jit_callee
def _element_side(Xp, j0, S, c, need):
    """Twist ``h = log(H_A^-1 H_B)`` of the element of nodes ``j0, j0 + 1`` and the element's quantities:
    ``T(h)^-1``, ``Ad(exp(-h))``, ``T(h)^-1 Ad(exp(-h))``, ``T(-h)`` into ``S[S_TI], S[S_AH], S[S_TIAH],
    S[S_TMH]`` and the coefficients of ``F(h, .)`` into ``c``.  Kept while the node poses are those of the last
    point on this side, bit for bit (the Gauss points of a slave element, consecutive points on one master
    element): the same floats.  ``need`` (one value for a whole batch: the kept quantities are those it asks
    for): 2 all, 1 the node Jacobians' ``T(h)^-1``, ``Ad(exp(-h))`` (forces only), 0 the twist alone (point data)."""
    hit = True
    for a in range(2):
        for i in range(3):
            for k in range(4):
                x = Xp[j0 + a, i, k]
                m = C_POSE + 12 * a + 4 * i + k
                if not _same(x, c[m]):
                    hit = False
                    c[m] = x
    RA, xA = _pose_of(Xp, j0)
    if hit:
        return RA, xA, (c[C_U], c[C_U + 1], c[C_U + 2]), (c[C_W], c[C_W + 1], c[C_W + 2])
    RB, xB = _pose_of(Xp, j0 + 1)
    u, w, _, d = log_relative(RA, xA, RB, xB)        # (``d`` at ``|w|``, as ``T(h)^-1`` takes it)
    for i in range(3):
        c[C_U + i], c[C_W + i] = u[i], w[i]
    if need == 0:
        return RA, xA, u, w
    t2, co = _coefficients(w)       # each coefficient once (``T(h)^-1``, ``exp(h)``, ``T(-h)``, ``F(h, .)`` share them)
    _side(u, w, S, t2, co, d)
    if need == 1:
        return RA, xA, u, w
    _mm_ut(S[S_TI], S[S_AH], S[S_TIAH])
    _tangent_co(scale(-1.0, u), scale(-1.0, w), S[S_TMH], t2, co)     # (|-w|^2 = |w|^2: the same floats)
    c[C_T2] = t2
    c[C_A], c[C_B] = co[0], co[1]
    for i in range(6):
        c[C_CO + i] = co[2 + i]
    return RA, xA, u, w


@jit_callee
def _variations(S, c0, G, DH, V):
    """Twist variation ``dh = T(h)^-1 (dq_B - Ad(exp(-h)) dq_A)`` and section-frame variation at fixed
    ``xi`` ``(J_A dq_A + J_B dq_B)`` into the rows ``DH``, ``V`` of ``G`` (6 each), node A at column ``c0``
    (``c0`` 0 or 12).  The other side's columns of ``DH`` are zero from ``_scratch`` on (never written)."""
    for i in range(6):
        for k in range(12 - c0, 24 - c0):
            G[(V + i) * W + k] = 0.0
    Ti, TiAh, JA, JB = S[S_TI], S[S_TIAH], S[S_JA], S[S_JB]
    for i in range(6):
        for j in range(6):
            G[(DH + i) * W + c0 + j] = -TiAh[i, j]
            G[(DH + i) * W + c0 + 6 + j] = Ti[i, j]
            G[(V + i) * W + c0 + j] = JA[i, j]
            G[(V + i) * W + c0 + 6 + j] = JB[i, j]


# ---------------------------------------------------------------- 3-vectors with gradients (3, 24)
@jit_callee
def _axes_value(RC, xC, RF, xF):
    """``n, t1, t2`` (``frames.axes``), centre distance, ``c = e1 . n`` and ``|e1 - c n|`` (``_axes`` without the
    gradients)."""
    d = add(xF, scale(-1.0, xC))
    dist = np.sqrt(dot(d, d))
    n = scale(1.0 / dist, d)
    e1 = _col(RC, 0)
    c = dot(e1, n)
    t1r = add(e1, scale(-c, n))
    lt = np.sqrt(dot(t1r, t1r))
    t1 = scale(1.0 / lt, t1r)
    return n, t1, cross(n, t1), dist, c, lt


@jit_callee
def _axes(RC, xC, RF, xF, G):
    """``n, t1, t2`` (``frames.axes``), centre distance, and the gradients of ``n, t1, t2, dist``
    into ``G`` (rows ``G_DN``, ``G_DT1``, ``G_DT2``, ``G_DDIST``; one pass over the 24 columns)."""
    n, t1, t2, dist, c, lt = _axes_value(RC, xC, RF, xF)
    e1, e2, e3 = _col(RC, 0), _col(RC, 1), _col(RC, 2)
    for k in range(24):
        dF = mv(RF, (G[G_VF * W + k], G[(G_VF + 1) * W + k], G[(G_VF + 2) * W + k]))
        dC = mv(RC, (G[G_VC * W + k], G[(G_VC + 1) * W + k], G[(G_VC + 2) * W + k]))
        dd = add(dF, scale(-1.0, dC))
        nd = dot(n, dd)
        dn = scale(1.0 / dist, add(dd, scale(-nd, n)))
        de1 = add(scale(G[(G_VC + 5) * W + k], e2), scale(-G[(G_VC + 4) * W + k], e3))
        dc = dot(n, de1) + dot(e1, dn)
        dt1r = add(add(de1, scale(-dc, n)), scale(-c, dn))
        dt1 = scale(1.0 / lt, add(dt1r, scale(-dot(t1, dt1r), t1)))
        dt2 = add(cross(n, dt1), scale(-1.0, cross(t1, dn)))
        for i in range(3):
            G[(G_DN + i) * W + k], G[(G_DT1 + i) * W + k], G[(G_DT2 + i) * W + k] = dn[i], dt1[i], dt2[i]
        G[G_DDIST * W + k] = nd
    return n, t1, t2, dist


# ---------------------------------------------------------------- friction
@jit_callee
def _pose4(H):
    R = ((H[0, 0], H[0, 1], H[0, 2]), (H[1, 0], H[1, 1], H[1, 2]), (H[2, 0], H[2, 1], H[2, 2]))
    return R, (H[0, 3], H[1, 3], H[2, 3])


@jit_callee
def _compose(RA, xA, RB, xB):
    return mm(RA, RB), add(mv(RA, xB), xA)


@jit_callee
def _vm(y, M):
    """The row ``y^T M`` (``M^T y``) of a 3x3 tuple ``M``."""
    return (y[0] * M[0][0] + y[1] * M[1][0] + y[2] * M[2][0], y[0] * M[0][1] + y[1] * M[1][1] + y[2] * M[2][1],
            y[0] * M[0][2] + y[1] * M[1][2] + y[2] * M[2][2])


@jit_callee
def _row_ut(yf, ym, A):
    """The row ``y^T A``, ``y = (yf, ym)``, of a block upper-triangular ``(6, 6)`` array (``A[3:, :3] == 0``),
    as two 3-tuples (written out: nested inlined helpers cost compile time)."""
    return ((yf[0] * A[0, 0] + yf[1] * A[1, 0] + yf[2] * A[2, 0],
             yf[0] * A[0, 1] + yf[1] * A[1, 1] + yf[2] * A[2, 1],
             yf[0] * A[0, 2] + yf[1] * A[1, 2] + yf[2] * A[2, 2]),
            (yf[0] * A[0, 3] + yf[1] * A[1, 3] + yf[2] * A[2, 3] + ym[0] * A[3, 3] + ym[1] * A[4, 3] + ym[2] * A[5, 3],
             yf[0] * A[0, 4] + yf[1] * A[1, 4] + yf[2] * A[2, 4] + ym[0] * A[3, 4] + ym[1] * A[4, 4] + ym[2] * A[5, 4],
             yf[0] * A[0, 5] + yf[1] * A[1, 5] + yf[2] * A[2, 5] + ym[0] * A[3, 5] + ym[1] * A[4, 5] + ym[2] * A[5, 5]))


@jit_callee
def _row_adjoint_inv(yf, ym, R, xt):
    """The row ``y^T Ad(H^-1)`` of the pose ``H = (R, x)``, ``xt = -R^T x``: ``(R yf, R (ym + yf x xt))``."""
    return mv(R, yf), mv(R, add(ym, cross(yf, xt)))


@jit_callee
def _coefficients_exp_tangent(w):
    """``t^2 = |w|^2`` and the coefficients ``a, b, c, q2, q3`` at ``t``: those of ``exp`` and ``T`` (a
    section and its node Jacobians, without their derivatives; ``_coefficients`` has all ten)."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    return t2, (coefficient(A_, t), coefficient(B_, t), coefficient(C_, t), coefficient(Q2_, t), coefficient(Q3_, t))


@jit_callee
def _section_prev(RA, xA, u, w, xi, R, x, xip):
    """The section at ``xip`` and the factors of its node Jacobians ``J_B = xip T(s) T(h)^-1``,
    ``J_A = Ad(exp(-s)) - J_B Ad(exp(-h))``, ``s = xip h``: ``(same, R, x, Rs, xt, T3, Q)`` with the section
    pose ``(R, x)``, ``exp(s) = (Rs, xs)``, ``xt = -Rs^T xs`` and ``T(s) = [[T3, Q], [0, T3]]``.  ``same``:
    ``xip`` is ``xi`` bit for bit, the section ``(R, x)`` at ``xi`` is returned (the rest unused; the
    Jacobians at ``xi`` are in ``S_JA``, ``S_JB``).  The section is ``_section``'s operations."""
    if _same(xip, xi):
        return True, R, x, R, x, R, R
    su, sw = scale(xip, u), scale(xip, w)
    t2, co = _coefficients_exp_tangent(sw)
    Rs, xs = _exp_abc(su, sw, t2, co[0], co[1], co[2])
    T3 = add_outer(mat(scale(-co[1], sw), 1.0 - co[2] * t2), scale(co[2], sw), sw)
    Q = q_matrix(scale(-1.0, su), scale(-1.0, sw), dot(sw, su), cross(sw, su), t2, co[2], co[3], co[4])
    return False, mm(RA, Rs), add(mv(RA, xs), xA), Rs, scale(-1.0, mv(transpose(Rs), xs)), T3, Q


@jit_callee
def _tangent_inv_rows(u, w):
    """Rows 1 and 2 of ``T(h)^-1 = [[Ti, -Ti Q Ti], [0, Ti]]`` (``_tangent_inv``) as ``(yf, ym)`` pairs."""
    t2 = dot(w, w)
    t = np.sqrt(t2)
    Ti = ti_matrix(w, coefficient(D_, t), t2)
    Q = q_matrix(scale(-1.0, u), scale(-1.0, w), dot(w, u), cross(w, u), t2, coefficient(C_, t),
                 coefficient(Q2_, t), coefficient(Q3_, t))
    return (Ti[1], scale(-1.0, _vm(_vm(Ti[1], Q), Ti))), (Ti[2], scale(-1.0, _vm(_vm(Ti[2], Q), Ti)))


@jit_callee
def _put_row(D, a, c0, yf, ym):
    """``D[a, c0:c0+6] = (yf, ym)``."""
    D[a, c0], D[a, c0 + 1], D[a, c0 + 2], D[a, c0 + 3], D[a, c0 + 4], D[a, c0 + 5] = yf[0], yf[1], yf[2], ym[0], \
        ym[1], ym[2]


@jit_callee
def _slip_row(yf, ym, prev, xip, S, D, a, c0):
    """``D[a, c0:c0+12] = y [J_A, J_B]`` at ``xip`` for the row ``y = (yf, ym)``; ``prev``: ``_section_prev``.
    Without forming ``J``: ``y J_B = xip (y T(s)) T(h)^-1``, ``y J_A = y Ad(exp(-s)) - xip (y T(s)) T(h)^-1
    Ad(exp(-h))`` (``S[S_TI]``, ``S[S_TIAH]``); where ``xip`` is ``xi``, from ``S[S_JA]``, ``S[S_JB]``."""
    same, _, _, Rs, xt, T3, Q = prev
    if same:
        af, am = _row_ut(yf, ym, S[S_JA])
        bf, bm = _row_ut(yf, ym, S[S_JB])
    else:
        zf, zm = _vm(yf, T3), add(_vm(yf, Q), _vm(ym, T3))          # y T(s)
        bf, bm = _row_ut(zf, zm, S[S_TI])
        cf, cm = _row_ut(zf, zm, S[S_TIAH])
        af, am = _row_adjoint_inv(yf, ym, Rs, xt)
        af, am = add(af, scale(-xip, cf)), add(am, scale(-xip, cm))
        bf, bm = scale(xip, bf), scale(xip, bm)
    _put_row(D, a, c0, af, am)
    _put_row(D, a, c0 + 6, bf, bm)


@jit_callee
def _slip_rows(row1, row2, R, xt, sign, prev, xip, S, D, c0):
    """``D[:, c0:c0+12] = sign (row Ad(H^-1)) [J_A, J_B]`` at ``xip`` for the rows ``row1``, ``row2`` ``(yf, ym)``
    of ``T(dy)^-1``; ``H = (R, x)``, ``xt = -R^T x``; ``prev``: ``_section_prev``."""
    for a in range(2):
        yf, ym = row1 if a == 0 else row2
        cf, cm = _row_adjoint_inv(yf, ym, R, xt)
        _slip_row(scale(sign, cf), scale(sign, cm), prev, xip, S, D, a, c0)


@jit_callee
def _section_pose_prev(RA, xA, u, w, xi, R, x, xip):
    """``_section_prev``'s section pose ``(R, x)`` at ``xip`` alone (the same operations; ``_slip_value``: no
    Jacobian factors, whose coefficients and ``T(s)`` a call that is not inlined computes all the same)."""
    if _same(xip, xi):
        return R, x
    su, sw = scale(xip, u), scale(xip, w)
    t2 = dot(sw, sw)
    t = np.sqrt(t2)
    Rs, xs = _exp_abc(su, sw, t2, coefficient(A_, t), coefficient(B_, t), coefficient(C_, t))
    return mm(RA, Rs), add(mv(RA, xs), xA)


@jit_callee
def _material_frames(R1, x1, R2, x2, HCL, HFK, HLKp):
    """``H_CL``, ``H_FK``, ``H_LK`` now and ``dy = log(H_LK_prev^-1 H_LK)`` (its ``u``, ``w``) from the sections
    ``(R1, x1)``, ``(R2, x2)`` at ``xi_prev``."""
    RCL, xCL = _pose4(HCL)
    RFK, xFK = _pose4(HFK)
    RL, xL = _compose(R1, x1, RCL, xCL)
    RK, xK = _compose(R2, x2, RFK, xFK)
    RLt = transpose(RL)
    RLK, xLK = mm(RLt, RK), mv(RLt, add(xK, scale(-1.0, xL)))
    RP, xP = _pose4(HLKp)
    dyu, dyw, _, _ = log_relative(RP, xP, RLK, xLK)
    return RCL, xCL, RFK, xFK, RLK, xLK, dyu, dyw


@jit_callee
def _slip_frames(side1, side2, sec1, sec2, xi1p, xi2p, HCL, HFK, HLKp):
    """The material frames of ``_slip``: the sections at ``xi_prev`` (``prev1``, ``prev2``), ``H_CL``, ``H_FK``,
    ``H_LK`` now and ``dy = log(H_LK_prev^-1 H_LK)`` (its ``u``, ``w``)."""
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    xi1, RC, xC = sec1
    xi2, RF, xF = sec2
    prev1 = _section_prev(RA1, xA1, u1, w1, xi1, RC, xC, xi1p)
    prev2 = _section_prev(RA2, xA2, u2, w2, xi2, RF, xF, xi2p)
    return (prev1, prev2) + _material_frames(prev1[1], prev1[2], prev2[1], prev2[2], HCL, HFK, HLKp)


@jit_callee
def _slip(side1, side2, S1, S2, sec1, sec2, xi1p, xi2p, HCL, HFK, HLKp, D):
    """Slip ``log(H_LK_prev^-1 H_LK)[1:3]`` of the material frames (``kinematics.slip_increment``)
    and its gradient into ``D`` ``(2, 24)``; ``sec1``, ``sec2``: ``(xi, R, x)`` of the sections at the
    point.  With ``dy = log(H_LK_prev^-1 H_LK)`` and the section variations ``dq = J_A dq_A + J_B dq_B`` at
    ``xi_prev`` (fixed): ``d(dy) = T(dy)^-1 (-Ad((H_CL H_LK)^-1) dq_C + Ad(H_FK^-1) dq_F)``; only its rows 1, 2
    are formed, as rows times the factors of ``J`` (``_slip_rows``).  Where ``xi_prev`` is ``xi`` (bit for
    bit) the section and the Jacobians at ``xi`` are reused."""
    prev1, prev2, RCL, xCL, RFK, xFK, RLK, xLK, dyu, dyw = _slip_frames(side1, side2, sec1, sec2, xi1p, xi2p,
                                                                        HCL, HFK, HLKp)
    row1, row2 = _tangent_inv_rows(dyu, dyw)
    Rm, xm = _compose(RCL, xCL, RLK, xLK)
    _slip_rows(row1, row2, Rm, scale(-1.0, mv(transpose(Rm), xm)), -1.0, prev1, xi1p, S1, D, 0)
    _slip_rows(row1, row2, RFK, scale(-1.0, mv(transpose(RFK), xFK)), 1.0, prev2, xi2p, S2, D, 12)
    return (dyu[1], dyu[2])


@jit_callee
def _slip_value(side1, side2, sec1, sec2, xi1p, xi2p, HCL, HFK, HLKp):
    """``_slip``'s value alone (the same operations, no gradient)."""
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    xi1, RC, xC = sec1
    xi2, RF, xF = sec2
    R1, x1 = _section_pose_prev(RA1, xA1, u1, w1, xi1, RC, xC, xi1p)
    R2, x2 = _section_pose_prev(RA2, xA2, u2, w2, xi2, RF, xF, xi2p)
    dyu = _material_frames(R1, x1, R2, x2, HCL, HFK, HLKp)[6]
    return (dyu[1], dyu[2])


def _friction(slip, lamp, t1, t2, lam, par, G):
    """Transported stored traction, tangential penalty, trial traction and the law's tangential part
    (``_tangential_law``, bound by ``make_kernel``); ``lam_t``, its gradient ``(2, 24)``, ``stick``.
    Reads the rows ``G_DSLIP``, ``G_DT1``, ``G_DT2``, ``G_DLAM`` of ``G``; writes ``G_DLP``, ``G_DPREV``,
    ``G_DPT``, ``G_DTR``."""
    lp = (dot(lamp, t1), dot(lamp, t2))
    dt1, dt2, dlp = G_DT1 * W, G_DT2 * W, G_DLP * W          # first entries of the rows
    for k in range(24):
        G[dlp + k] = lamp[0] * G[dt1 + k] + lamp[1] * G[dt1 + W + k] + lamp[2] * G[dt1 + 2 * W + k]
        G[dlp + W + k] = lamp[0] * G[dt2 + k] + lamp[1] * G[dt2 + W + k] + lamp[2] * G[dt2 + 2 * W + k]
    npv = np.sqrt(dot(lamp, lamp))
    nl = np.sqrt(lp[0] * lp[0] + lp[1] * lp[1])
    if nl > 1e-300 * (1.0 + npv):
        s = npv / nl
        l0, l1 = lp[0] / nl, lp[1] / nl
        for k in range(24):
            proj = l0 * G[G_DLP * W + k] + l1 * G[(G_DLP + 1) * W + k]
            G[G_DPREV * W + k] = s * (G[G_DLP * W + k] - l0 * proj)
            G[(G_DPREV + 1) * W + k] = s * (G[(G_DLP + 1) * W + k] - l1 * proj)
        lam_prev = (lp[0] * s, lp[1] * s)
    else:
        for k in range(24):
            G[G_DPREV * W + k] = 0.0
            G[(G_DPREV + 1) * W + k] = 0.0
        lam_prev = (0.0, 0.0)
    pen_t, mu = par[PEN_T], par[MU]
    for k in range(24):
        G[G_DPT * W + k] = 0.0
    if np.isnan(pen_t) and not np.isnan(par[ESLIP]):
        lam_min = PENALTY_T_MIN * par[PENALTY] * par[ESLIP]      # reference.stick_penalty
        if lam >= lam_min:
            pen_t = mu * lam / par[ESLIP]
            for k in range(24):
                G[G_DPT * W + k] = (mu / par[ESLIP]) * G[G_DLAM * W + k]
        else:
            pen_t = mu * lam_min / par[ESLIP]
    tr0, tr1 = lam_prev[0] + pen_t * slip[0], lam_prev[1] + pen_t * slip[1]
    for k in range(24):
        for a in range(2):
            G[(G_DTR + a) * W + k] = (G[(G_DPREV + a) * W + k] + slip[a] * G[G_DPT * W + k]
                                      + pen_t * G[(G_DSLIP + a) * W + k])
    Dtr, Dlam = G[G_DTR * W:(G_DTR + 2) * W].reshape((2, W)), G[G_DLAM * W:(G_DLAM + 1) * W]
    lt0, lt1, D, stick = _tangential_law(tr0, tr1, Dtr, mu, lam, Dlam)
    return (lt0, lt1), D, stick


# ---------------------------------------------------------------- one contact point
@jit_callee
def _wrench_value(R, F, m, w):
    """``_wrench``'s value alone: ``w = (R^T F, R^T m)`` (the same operations)."""
    Rt = transpose(R)
    bF, bm = mv(Rt, F), mv(Rt, m)
    for i in range(3):
        w[i], w[3 + i] = bF[i], bm[i]


@jit_callee
def _wrench(R, F, neg, m, sm, G, V, DW, w):
    """Body wrench ``w = (R^T F, R^T m)`` and its gradient (rows ``DW`` of ``G``, 6) from ``dF = -dF_slave``
    if ``neg`` (else ``dF_slave``; rows ``G_DF``) and ``dm = sm d(n x F)`` (rows ``G_DMF``); ``V``: the rows
    of the frame's variation; ``d(R^T F)/dtheta = hat(R^T F)``."""
    Rt = transpose(R)
    bF, bm = mv(Rt, F), mv(Rt, m)
    for i in range(3):
        w[i], w[3 + i] = bF[i], bm[i]
    df, dm, dv = G_DF * W, G_DMF * W, (V + 3) * W        # first entries of the rows
    Rf, Rm = mscale(-1.0 if neg else 1.0, Rt), mscale(sm, Rt)
    for k in range(24):
        th = (G[dv + k], G[dv + W + k], G[dv + 2 * W + k])
        a = add(mv(Rf, (G[df + k], G[df + W + k], G[df + 2 * W + k])), cross(bF, th))
        b = add(mv(Rm, (G[dm + k], G[dm + W + k], G[dm + 2 * W + k])), cross(bm, th))
        for i in range(3):
            G[(DW + i) * W + k], G[(DW + 3 + i) * W + k] = a[i], b[i]


@jit_callee
def _nodal_forces(S, v, f, j0):
    """``f_j = J_j^T wr`` (``wr = v[V_WR]``, ``J`` in ``S[S_JA]``, ``S[S_JB]``) of the two nodes of one side, rows
    ``j0, j0 + 1`` of ``f`` ``(4, 6)``: ``_nodal``'s forces only, small enough to be inlined (no views)."""
    for s in range(2):
        for i in range(6):
            acc = 0.0
            for l in range(6):
                acc += S[S_JA + s, l, i] * v[V_WR, l]
            f[j0 + s, i] = acc


@jit_callee
def _nodal(u, w, xi, t2, co, S, v, c, G, DW, DH, DXI, f, K, j0):
    """``f_j = J_j^T wr`` (``wr = v[V_WR]``) for the two nodes of one side and their rows of the tangent:
    ``J^T dwr + d(J^T wr)/dh dh + d(J^T wr)/dxi dxi`` (rows ``DW``, ``DH``, ``DXI`` of ``G``; ``dh`` is zero
    outside the side's columns); forces only for an empty ``K`` (``contact_kernel``)."""
    if K.shape[1] == 0:
        _nodal_forces(S, v, f, j0)
        return
    wr = v[V_WR]
    _jacobian_derivatives(u, w, xi, t2, co, S, v, c)
    for s in range(2):
        J, D, dd = (S[S_JA], S[S_DA], v[V_DA]) if s == 0 else (S[S_JB], S[S_DB], v[V_DB])
        for i in range(3):                      # force rows: J[3:, :3] == 0 (block upper triangular)
            f[j0 + s, i] = J[0, i] * wr[0] + J[1, i] * wr[1] + J[2, i] * wr[2]
        for i in range(3, 6):                   # moment rows
            acc = 0.0
            for l in range(6):
                acc += J[l, i] * wr[l]
            f[j0 + s, i] = acc
        _node_rows(J, D, dd, G, DXI, DW, DH, K, 6 * (j0 + s))


@jit_callee
def _node_rows(J, D, dd, G, DXI, DW, DH, K, r0):
    """The six rows ``K[r0:r0+6]`` of one node's tangent, ``J``, ``D``, ``dd`` its ``J``, ``d(J^T wr)/dh``,
    ``d(J^T wr)/dxi``: ``K[r0 + i, c] = dd[i] dxi[c] + sum_l (J[l, i] Dw[l, c] + D[i, l] Dh[l, c])``, summed in this
    order (``dxi``, ``Dw``, ``Dh``: the rows ``DXI``, ``DW``, ``DH`` of ``G``; one function for the six rows: a call
    per row cost about as much as its sums).  A force row's ``J[3:, i]`` (``J[3:, :3] == 0``) and ``D[i, :3]`` (the
    zero upper-left block of ``d(J^T wr)/dh``, ``_jacobian_derivatives``) are structural zeros: their terms, exact
    zeros, are skipped.  ``Dh`` is zero outside the side's columns: its terms there, exact zeros, change a sum only
    in the sign of a zero result (``_mm_ut``), and keep the loops branch-free over all 24 columns, which the
    compiler vectorises (with a runtime check that ``K`` and ``G`` do not overlap, refused in loops of fewer than
    16 iterations)."""
    x, w, h = DXI * W, DW * W, DH * W           # first entries of the rows
    for i in range(3):                          # force rows
        di, j0, j1, j2, d3, d4, d5 = dd[i], J[0, i], J[1, i], J[2, i], D[i, 3], D[i, 4], D[i, 5]
        for c in range(24):
            acc = di * G[x + c]
            acc += j0 * G[w + c]
            acc += j1 * G[w + W + c]
            acc += j2 * G[w + 2 * W + c]
            acc += d3 * G[h + 3 * W + c]
            acc += d4 * G[h + 4 * W + c]
            acc += d5 * G[h + 5 * W + c]
            K[r0 + i, c] = acc
    for i in range(3, 6):                       # moment rows
        di, j0, j1, j2, j3, j4, j5 = dd[i], J[0, i], J[1, i], J[2, i], J[3, i], J[4, i], J[5, i]
        d0, d1, d2, d3, d4, d5 = D[i, 0], D[i, 1], D[i, 2], D[i, 3], D[i, 4], D[i, 5]
        for c in range(24):
            acc = di * G[x + c]
            acc += j0 * G[w + c]
            acc += d0 * G[h + c]
            acc += j1 * G[w + W + c]
            acc += d1 * G[h + W + c]
            acc += j2 * G[w + 2 * W + c]
            acc += d2 * G[h + 2 * W + c]
            acc += j3 * G[w + 3 * W + c]
            acc += d3 * G[h + 3 * W + c]
            acc += j4 * G[w + 4 * W + c]
            acc += d4 * G[h + 4 * W + c]
            acc += j5 * G[w + 5 * W + c]
            acc += d5 * G[h + 5 * W + c]
            K[r0 + i, c] = acc


@jit_callee
def _store_frames(frames, n, t1, t2, RC, xC, RF, xF, R1, R2):
    """``HL, HK, HC, HF`` (``frames.contact_frames``); each entry written once."""
    for k in range(4):
        frames[k, 3, 0], frames[k, 3, 1], frames[k, 3, 2], frames[k, 3, 3] = 0.0, 0.0, 0.0, 1.0
    for i in range(3):
        for k in range(2):
            frames[k, i, 0], frames[k, i, 1], frames[k, i, 2] = n[i], t1[i], t2[i]
        frames[0, i, 3] = xC[i] + R1 * n[i]
        frames[1, i, 3] = xF[i] - R2 * n[i]
        for j in range(3):
            frames[2, i, j], frames[3, i, j] = RC[i][j], RF[i][j]
        frames[2, i, 3], frames[3, i, 3] = xC[i], xF[i]


@jit_callee
def _frame_variations(u1, w1, xi1, co1, u2, w2, xi2, co2, kind, RC, RF, d, S1, S2, G):
    """Node Jacobians of both sides, twist variations (rows ``G_DH1``, ``G_DH2`` of ``G``), projection
    gradients (``G_DXI1``, ``G_DXI2``) and the section-frame variations (``G_VC``, ``G_VF``, 6 rows each);
    ``S1``, ``S2`` hold the elements' ``T(h)^-1``, ``Ad(exp(-h))`` (``_element_side``); ``co1``, ``co2``:
    ``_coefficients(xi w)`` of the sides."""
    _jacobians(u1, w1, xi1, co1[0], co1[1], S1[S_TI], S1[S_AH], S1[S_TS], S1[S_AS], S1[S_JA], S1[S_JB])
    _jacobians(u2, w2, xi2, co2[0], co2[1], S2[S_TI], S2[S_AH], S2[S_TS], S2[S_AS], S2[S_JA], S2[S_JB])
    _variations(S1, 0, G, G_DH1, G_VC)
    _variations(S2, 12, G, G_DH2, G_VF)
    _projection_gradient(kind, RC, u1, w1, RF, u2, w2, d, G)
    h1 = (u1[0], u1[1], u1[2], w1[0], w1[1], w1[2])
    h2 = (u2[0], u2[1], u2[2], w2[0], w2[1], w2[2])
    for k in range(24):
        for i in range(6):
            G[(G_VC + i) * W + k] += h1[i] * G[G_DXI1 * W + k]
            G[(G_VF + i) * W + k] += h2[i] * G[G_DXI2 * W + k]


@jit_callee
def _add_friction_force(F, G, wgt, lt, Dlt, t1, t2):
    """``F + wgt (lt0 t1 + lt1 t2)`` and its gradient added to the rows ``G_DF`` of ``G`` (``Dlt`` ``(2, 24)``)."""
    for k in range(24):
        for i in range(3):
            G[(G_DF + i) * W + k] += wgt * (t1[i] * Dlt[0, k] + lt[0] * G[(G_DT1 + i) * W + k] + t2[i] * Dlt[1, k]
                                     + lt[1] * G[(G_DT2 + i) * W + k])
    return add(F, add(scale(wgt * lt[0], t1), scale(wgt * lt[1], t2)))


@jit_callee
def _moment_gradient(n, F, G):
    """``d(n x F)`` into the rows ``G_DMF`` of ``G`` from ``dF`` (``G_DF``) and ``dn`` (``G_DN``)."""
    f0, f1, f2, n0, n1, n2 = G_DF * W, (G_DF + 1) * W, (G_DF + 2) * W, G_DN * W, (G_DN + 1) * W, (G_DN + 2) * W
    m0, m1, m2 = G_DMF * W, (G_DMF + 1) * W, (G_DMF + 2) * W
    for k in range(24):
        G[m0 + k] = (n[1] * G[f2 + k] - n[2] * G[f1 + k]) - (F[1] * G[n2 + k] - F[2] * G[n1 + k])
        G[m1 + k] = (n[2] * G[f0 + k] - n[0] * G[f2 + k]) - (F[2] * G[n0 + k] - F[0] * G[n2 + k])
        G[m2 + k] = (n[0] * G[f1 + k] - n[1] * G[f0 + k]) - (F[0] * G[n1 + k] - F[1] * G[n0 + k])


def _point(Xp, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames, ws):
    """Forces ``f (4, 6)``, tangent ``K (24, 24)`` and point data of one contact point; ``ws``: the
    scratch arrays of ``_scratch``."""
    S, v, G, cache = ws
    need = 2 if friction or K.shape[1] > 0 else 1       # (the slip's gradient rows take ``T(h)^-1 Ad(exp(-h))``)
    side1, side2 = _element_side(Xp, 0, S[0], cache[0], need), _element_side(Xp, 2, S[1], cache[1], need)
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    xi1, xi2 = _project(kind, RA1, xA1, u1, w1, par[XI1], RA2, xA2, u2, w2, par[XI2])
    co1, co2 = _coefficients(scale(xi1, w1)), _coefficients(scale(xi2, w2))
    RC, xC, _, _ = _section_co(RA1, xA1, u1, w1, xi1, co1[0], co1[1])
    RF, xF, _, _ = _section_co(RA2, xA2, u2, w2, xi2, co2[0], co2[1])
    S1, S2 = S[0], S[1]
    if K.shape[1] > 0:
        _frame_variations(u1, w1, xi1, co1, u2, w2, xi2, co2, kind, RC, RF, add(xF, scale(-1.0, xC)), S1, S2, G)
    else:       # forces only (``contact_kernel``: an empty ``K``): the Jacobians, no variations (their rows stay 0)
        _jacobians(u1, w1, xi1, co1[0], co1[1], S1[S_TI], S1[S_AH], S1[S_TS], S1[S_AS], S1[S_JA], S1[S_JB])
        _jacobians(u2, w2, xi2, co2[0], co2[1], S2[S_TI], S2[S_AH], S2[S_TS], S2[S_AS], S2[S_JA], S2[S_JB])
    n, t1, t2, dist = _axes(RC, xC, RF, xF, G)
    R1, R2, wgt = par[R1_], par[R2_], par[WEIGHT]
    gap = dist - R1 - R2
    touching = 0.0 < gap <= par[TOUCH]          # round-off of a touching pair's gap: touching (reference.touching_gap)
    lam, dlam, active = _normal_law(0.0 if touching else gap, par[PENALTY], par[MULT], par[SMOOTH])  # make_kernel
    for k in range(24):
        G[G_DLAM * W + k] = dlam * G[G_DDIST * W + k]
    F = scale(-wgt * lam, n)
    for k in range(24):
        for i in range(3):
            G[(G_DF + i) * W + k] = -wgt * (n[i] * G[G_DLAM * W + k] + lam * G[(G_DN + i) * W + k])
    lt, stick, slip = (0.0, 0.0), True, (0.0, 0.0)
    if friction:
        if has:         # writes all 24 columns of the slip gradient
            slip = _slip(side1, side2, S1, S2, (xi1, RC, xC), (xi2, RF, xF), par[XI1P], par[XI2P], HCL, HFK, HLKp,
                         G[G_DSLIP * W:(G_DSLIP + 2) * W].reshape((2, W)))
        else:
            for a in range(2):
                for k in range(24):
                    G[(G_DSLIP + a) * W + k] = 0.0
        lt, Dlt, stick = _friction(slip, lamp, t1, t2, lam, par, G)
        if active or _EVERYWHERE:
            F = _add_friction_force(F, G, wgt, lt, Dlt, t1, t2)
        else:
            lt = (0.0, 0.0)
        _store_frames(frames, n, t1, t2, RC, xC, RF, xF, R1, R2)
    mF = cross(n, F)
    _moment_gradient(n, F, G)
    _wrench(RC, F, False, scale(R1, mF), R1, G, G_VC, G_DWC, v[0, V_WR])
    _wrench(RF, scale(-1.0, F), True, scale(R2, mF), R2, G, G_VF, G_DWF, v[1, V_WR])
    _nodal(u1, w1, xi1, co1[0], co1[1], S1, v[0], cache[0], G, G_DWC, G_DH1, G_DXI1, f, K, 0)
    _nodal(u2, w2, xi2, co2[0], co2[1], S2, v[1], cache[1], G, G_DWF, G_DH2, G_DXI2, f, K, 2)
    sc[0], sc[1], sc[2], sc[3] = gap, lam, xi1, xi2
    for i in range(3):
        vec[0, i], vec[1, i], vec[2, i], vec[3, i], vec[4, i], vec[5, i] = n[i], t1[i], t2[i], xC[i], xF[i], F[i]
    two[0, 0], two[0, 1], two[1, 0], two[1, 1] = lt[0], lt[1], slip[0], slip[1]
    flags[0], flags[1] = active, stick


@jit
def share_of_the_kernel(G, v, frames):
    """Compiles the last callees the kernel's ``_point`` types (``_store_frames``, ``_moment_gradient``, both
    ``_wrench``), called with the types ``_point`` gives them (``G``, ``v``: ``_scratch``'s, ``frames`` ``(4, 4, 4)``),
    into the cache: ``jit_warmup`` runs it in the job while a second process compiles the kernel, which then
    loads them instead of compiling them last.  Writes only into its arguments."""
    n = (1.0, 0.0, 0.0)
    R = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    F = scale(-1.0, n)
    R1 = v[0, 0, 0] * 0.0 + 1.0                 # a float64 as ``par[R1_]``
    _store_frames(frames, n, n, n, R, n, R, n, R1, R1)
    mF = cross(n, F)
    _moment_gradient(n, F, G)
    _wrench(R, F, False, scale(R1, mF), R1, G, G_VC, G_DWC, v[0, V_WR])
    _wrench(R, scale(-1.0, F), True, scale(R1, mF), R1, G, G_VF, G_DWF, v[1, V_WR])


@jit_callee
def _scratch():
    """Scratch arrays of one evaluation, reused by every point (the kernel allocates nothing per point); the
    gradients ``G`` start at zero (``_variations`` relies on it)."""
    return np.empty((2, N_SIDE, 6, 6)), np.empty((2, N_VEC, 6)), np.zeros(N_G * W), np.full((2, N_CACHE), np.nan)


def _evaluate(X, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames):
    """Batch driver: ``_point`` over all pairs (a plain loop; one core), on borrowed views of the arguments
    and the scratch (no reference counting per point; the arguments are held by the caller).  A template: ``make_kernel``
    compiles it per contact law; the module's ``evaluate`` is the default law's."""
    own = _scratch()
    ws = (_borrowed(own[0]), _borrowed(own[1]), _borrowed(own[2]), _borrowed(own[3]))
    X, par, HCL, HFK, HLKp, lamp = _borrowed(X), _borrowed(par), _borrowed(HCL), _borrowed(HFK), _borrowed(HLKp), \
        _borrowed(lamp)
    kind, has, f, K, sc = _borrowed(kind), _borrowed(has), _borrowed(f), _borrowed(K), _borrowed(sc)
    vec, two, flags, frames = _borrowed(vec), _borrowed(two), _borrowed(flags), _borrowed(frames)
    for p in range(X.shape[0]):
        _point(X[p], kind[p], par[p], has[p], HCL[p], HFK[p], HLKp[p], lamp[p], friction, f[p], K[p], sc[p],
               vec[p], two[p], flags[p], frames[p], ws)
    own[0][0, 0, 0, 0] = 0.0           # the scratch arrays' owners live until here


@jit_callee
def _friction_given(slip, lamp, t1, t2, lam, par, G):
    """The mortar kernel's friction (``make_kernel(law, mortar=True)``): the given global traction
    ``lamp`` (force per length) applied by its components ``(lamp . t1, lamp . t2)``, their gradient
    at fixed ``lamp`` in the rows ``G_DTR``; no law (the nodal return mapping is in ``mortar.py``)."""
    dt1, dt2, dtr = G_DT1 * W, G_DT2 * W, G_DTR * W
    for k in range(24):
        G[dtr + k] = lamp[0] * G[dt1 + k] + lamp[1] * G[dt1 + W + k] + lamp[2] * G[dt1 + 2 * W + k]
        G[dtr + W + k] = lamp[0] * G[dt2 + k] + lamp[1] * G[dt2 + W + k] + lamp[2] * G[dt2 + 2 * W + k]
    return (dot(lamp, t1), dot(lamp, t2)), G[dtr:dtr + 2 * W].reshape((2, W)), True


# the friction of a point acts only where its normal law does; the mortar kernel's traction (a field
# interpolated from the slave nodes) acts at every point of the overlap (``make_kernel``)
_EVERYWHERE = False


# the gradient rows a mortar evaluation exports per point: n, t1, t2 (9), the slip (2), the normal traction (1)
N_ROWS = 12


def _evaluate_rows(X, kind, par, has, HCL, HFK, HLKp, lamp, friction, f, K, sc, vec, two, flags, frames, rows):
    """``_evaluate`` that also copies each point's gradient rows to ``rows`` ``(P, N_ROWS, 24)``:
    ``d n``, ``d t1``, ``d t2`` (rows 0-8), ``d slip`` (9-10), ``d lam_n`` (11).  A template of the mortar
    kernel (``make_kernel(law, mortar=True)``)."""
    own = _scratch()
    ws = (_borrowed(own[0]), _borrowed(own[1]), _borrowed(own[2]), _borrowed(own[3]))
    G = ws[2]
    for p in range(X.shape[0]):
        _point(X[p], kind[p], par[p], has[p], HCL[p], HFK[p], HLKp[p], lamp[p], friction, f[p], K[p], sc[p],
               vec[p], two[p], flags[p], frames[p], ws)
        r = rows[p]
        for k in range(24):
            for i in range(9):
                r[i, k] = G[(G_DN + i) * W + k]
            r[9, k] = G[G_DSLIP * W + k]
            r[10, k] = G[(G_DSLIP + 1) * W + k]
            r[11, k] = G[G_DLAM * W + k]
    own[0][0, 0, 0, 0] = 0.0


@jit_callee
def _copy_rows(G, rows):
    """The gradient rows a mortar evaluation exports (``_evaluate_rows``) from ``G`` into ``rows`` ``(N_ROWS, 24)``,
    row by row (contiguous writes: a column at a time wrote 12 streams of cache lines, 1000 cycles a point)."""
    for i in range(9):
        for k in range(24):
            rows[i, k] = G[(G_DN + i) * W + k]
    for k in range(24):
        rows[9, k] = G[G_DSLIP * W + k]
    for k in range(24):
        rows[10, k] = G[(G_DSLIP + 1) * W + k]
    for k in range(24):
        rows[11, k] = G[G_DLAM * W + k]


@jit_callee
def _forces_four(n, t1, t2, lam, wgt, RC, RF, R1, R2, S1, S2, f, p, G):
    """``f[q, p]`` ``(4, 6)`` at the four tractions ``T = 0, e_x, e_y, e_z`` without tangent, the operations of each
    traction's forces-only pass of ``_point_mortar`` (``_wrench_value``, ``_nodal_forces``) side by side: the four
    wrenches into the rows ``G_WQ`` of ``G`` (``[side, l, q]``, the tractions innermost), then each nodal force's four
    sums at once (vectorised; each lane its traction's sum, in its order), stored as ``mortar_terms``' differences
    ``f[q] - f[0]`` for ``q`` = 1, 2, 3 (the subtraction of ``_point_mortar``'s end, done here).  ``(F, lt)`` of the
    last, ``e_z``."""
    RCt, RFt = transpose(RC), transpose(RF)
    F, lt = (0.0, 0.0, 0.0), (0.0, 0.0)
    for q in range(4):
        lamp = (1.0 if q == 1 else 0.0, 1.0 if q == 2 else 0.0, 1.0 if q == 3 else 0.0)
        lt = (dot(lamp, t1), dot(lamp, t2))
        F = add(scale(-wgt * lam, n), add(scale(wgt * lt[0], t1), scale(wgt * lt[1], t2)))
        mF = cross(n, F)
        for side in range(2):
            Rt, Fs, m = (RCt, F, scale(R1, mF)) if side == 0 else (RFt, scale(-1.0, F), scale(R2, mF))
            bF, bm = mv(Rt, Fs), mv(Rt, m)
            for i in range(3):
                G[G_WQ * W + (6 * side + i) * 4 + q] = bF[i]
                G[G_WQ * W + (6 * side + 3 + i) * 4 + q] = bm[i]
    for side in range(2):
        S = S1 if side == 0 else S2
        for s in range(2):
            for i in range(6):
                a0, a1, a2, a3 = 0.0, 0.0, 0.0, 0.0
                for l in range(6):
                    j, r = S[S_JA + s, l, i], G_WQ * W + (6 * side + l) * 4
                    a0, a1, a2, a3 = a0 + j * G[r], a1 + j * G[r + 1], a2 + j * G[r + 2], a3 + j * G[r + 3]
                f[0, p, 2 * side + s, i], f[1, p, 2 * side + s, i] = a0, a1 - a0
                f[2, p, 2 * side + s, i], f[3, p, 2 * side + s, i] = a2 - a0, a3 - a0
    return F, lt


def _point_mortar(Xp, kind, par, has, HCL, HFK, HLKp, f, K, p, sc, vec, two, flags, frames, ws, rows, Tp, spare):
    """``_point`` of the mortar kernel at the four given tractions ``T = 0, e_x, e_y, e_z`` (``mortar_terms``):
    the geometry, projection, slip and their gradients once, then per traction what depends on it (the
    friction force, wrenches and nodal rows), each the same operations as a ``_point`` call with that
    traction; ``f[q, p]`` ``(4, 6)``, ``K[q, p]`` ``(24, 24)`` (``q``: the traction; ``q`` = 1, 2, 3 less those
    of ``q`` = 0 at the end, ``mortar_terms``' differences); the point data as the last call left them;
    ``rows`` ``(N_ROWS, 24)``: the gradient rows (``_evaluate_rows``).  An empty ``K`` ``(4, P, 0, 0)``: forces only
    (``mortar_forces``; ``rows`` untouched), the same bits as with the tangent.  ``K`` ``(2, P, 24, 24)``: the
    tangents at ``T = 0`` and at the point's traction ``Tp`` less the first (``mortar_terms(T=)``: the tangent at
    fixed traction ``sum_k T_k dK_k`` by linearity, two tangents instead of four); the unit tractions' forces
    then without tangent.  ``K`` ``(1, P, 24, 24)``: the whole tangent at ``Tp`` (``mortar_terms(whole=True)``).
    An empty ``f`` ``(0, P, 4, 6)`` (and ``K``): the point data alone, no traction's pass (``mortar_data``; its
    ``lam_t``, ``stick`` and force ``F`` are zeros and True, not the last pass's).
    ``spare``: an empty ``(0, 0)`` and a ``(4, 6)`` scratch.  A template (``make_kernel``)."""
    S, v, G, cache = ws
    tangent = K.shape[2] > 0
    data = f.shape[0] == 0          # point data only (``mortar_data``: no forces, no tangent)
    need = 2 if tangent else 0 if data else 1
    side1, side2 = _element_side(Xp, 0, S[0], cache[0], need), _element_side(Xp, 2, S[1], cache[1], need)
    RA1, xA1, u1, w1 = side1
    RA2, xA2, u2, w2 = side2
    xi1, xi2, sec1, sec2, at1, at2 = _project_kept(kind, _section_inline(RA1, xA1, u1, w1, par[XI1]), RA1, xA1, u1,
                                                   w1, par[XI1], RA2, xA2, u2, w2, par[XI2], 2)
    co1, co2 = _coefficients(scale(xi1, w1)), _coefficients(scale(xi2, w2))
    # the projection's last sections where they are at the projected point (the same operations as ``_section_co``)
    RC, xC, _, _ = sec1 if at1 else _section_co(RA1, xA1, u1, w1, xi1, co1[0], co1[1])
    RF, xF, _, _ = sec2 if at2 else _section_co(RA2, xA2, u2, w2, xi2, co2[0], co2[1])
    S1, S2 = S[0], S[1]
    if tangent:
        _frame_variations(u1, w1, xi1, co1, u2, w2, xi2, co2, kind, RC, RF, add(xF, scale(-1.0, xC)), S1, S2, G)
    elif not data:       # forces only (``mortar_forces``: an empty ``K``): the Jacobians, no variations, no gradient rows
        # (the five coefficients they take: the others' sums are left out)
        _jacobians(u1, w1, xi1, co1[0], co1[1][:5], S1[S_TI], S1[S_AH], S1[S_TS], S1[S_AS], S1[S_JA], S1[S_JB])
        _jacobians(u2, w2, xi2, co2[0], co2[1][:5], S2[S_TI], S2[S_AH], S2[S_TS], S2[S_AS], S2[S_JA], S2[S_JB])
    # (without the tangent no pass reads the gradient rows: the axes' and the normal law's are not formed)
    n, t1, t2, dist = _axes(RC, xC, RF, xF, G) if tangent else _axes_value(RC, xC, RF, xF)[:4]
    R1, R2, wgt = par[R1_], par[R2_], par[WEIGHT]
    gap = dist - R1 - R2
    touching = 0.0 < gap <= par[TOUCH]          # round-off of a touching pair's gap: touching (reference.touching_gap)
    lam, dlam, active = _normal_law(0.0 if touching else gap, par[PENALTY], par[MULT], par[SMOOTH])  # make_kernel
    if tangent:
        for k in range(24):
            G[G_DLAM * W + k] = dlam * G[G_DDIST * W + k]
    slip = (0.0, 0.0)
    if has and not tangent:
        slip = _slip_value(side1, side2, (xi1, RC, xC), (xi2, RF, xF), par[XI1P], par[XI2P], HCL, HFK, HLKp)
    elif has:         # writes all 24 columns of the slip gradient
        slip = _slip(side1, side2, S1, S2, (xi1, RC, xC), (xi2, RF, xF), par[XI1P], par[XI2P], HCL, HFK, HLKp,
                     G[G_DSLIP * W:(G_DSLIP + 2) * W].reshape((2, W)))
    else:
        for a in range(2):
            for k in range(24):
                G[(G_DSLIP + a) * W + k] = 0.0
    if tangent:
        _copy_rows(G, rows)
    contracted = tangent and K.shape[0] < 4       # 2: at T = 0 and at Tp; 1: at Tp only
    _store_frames(frames, n, t1, t2, RC, xC, RF, xF, R1, R2)     # (the geometry's: once, not per traction)
    F, lt, stick = (0.0, 0.0, 0.0), (0.0, 0.0), True
    four = not data and (not tangent or K.shape[0] == 1)      # the four tractions' forces without tangent
    for step in range(0 if data else 5 if contracted else 4):
        q = step if not contracted else (0, 4, 1, 2, 3)[step]         # the unit tractions last (the point data)
        if four and q < 4:          # (after the loop, side by side)
            continue
        lamp = (1.0 if q == 1 else 0.0, 1.0 if q == 2 else 0.0, 1.0 if q == 3 else 0.0) if q < 4 else \
            (Tp[0], Tp[1], Tp[2])
        fq = f[q, p] if q < 4 else spare[1]
        if not contracted:
            Kq = K[q, p]
        elif q == 4:
            Kq = K[K.shape[0] - 1, p]
        elif q == 0 and K.shape[0] == 2:
            Kq = K[0, p]
        else:
            Kq = spare[0]
        # no normal traction and no given traction, nor their derivatives: the force and its tangent are zeros
        # (up to their signs), which the forces-only lines below give and ``Kq`` is set to; a point of the
        # overlap out of the normal law with zero multipliers at its nodes skips the wrenches' and nodal rows
        zero = Kq.shape[1] > 0 and lam == 0.0 and dlam == 0.0 and lamp[0] == 0.0 and lamp[1] == 0.0 and \
            lamp[2] == 0.0
        if zero:
            for i in range(24):
                for j in range(24):
                    Kq[i, j] = 0.0
            Kq = spare[0]
        if Kq.shape[1] == 0:        # forces only: the values of the lines below, no gradient rows
            lt, stick = (dot(lamp, t1), dot(lamp, t2)), True
            F = add(scale(-wgt * lam, n), add(scale(wgt * lt[0], t1), scale(wgt * lt[1], t2)))
            mF = cross(n, F)
            _wrench_value(RC, F, scale(R1, mF), v[0, V_WR])
            _wrench_value(RF, scale(-1.0, F), scale(R2, mF), v[1, V_WR])
            _nodal_forces(S1, v[0], fq, 0)
            _nodal_forces(S2, v[1], fq, 2)
        else:
            F = scale(-wgt * lam, n)
            for k in range(24):
                for i in range(3):
                    G[(G_DF + i) * W + k] = -wgt * (n[i] * G[G_DLAM * W + k] + lam * G[(G_DN + i) * W + k])
            lt, Dlt, stick = _friction_given(slip, lamp, t1, t2, lam, par, G)
            F = _add_friction_force(F, G, wgt, lt, Dlt, t1, t2)
            mF = cross(n, F)
            _moment_gradient(n, F, G)
            _wrench(RC, F, False, scale(R1, mF), R1, G, G_VC, G_DWC, v[0, V_WR])
            _wrench(RF, scale(-1.0, F), True, scale(R2, mF), R2, G, G_VF, G_DWF, v[1, V_WR])
            _nodal(u1, w1, xi1, co1[0], co1[1], S1, v[0], cache[0], G, G_DWC, G_DH1, G_DXI1, fq, Kq, 0)
            _nodal(u2, w2, xi2, co2[0], co2[1], S2, v[1], cache[1], G, G_DWF, G_DH2, G_DXI2, fq, Kq, 2)
    if four:
        F, lt = _forces_four(n, t1, t2, lam, wgt, RC, RF, R1, R2, S1, S2, f, p, G)
        stick = True
    # the point data as the last traction's pass left them (written once)
    sc[0], sc[1], sc[2], sc[3] = gap, lam, xi1, xi2
    for i in range(3):
        vec[0, i], vec[1, i], vec[2, i], vec[3, i], vec[4, i], vec[5, i] = n[i], t1[i], t2[i], xC[i], xF[i], F[i]
    two[0, 0], two[0, 1], two[1, 0], two[1, 1] = lt[0], lt[1], slip[0], slip[1]
    flags[0], flags[1] = active, stick
    for q in range(1, 1 if data else 4):     # the differences to T = 0: the friction's parts (``mortar_terms``)
        if not four:        # (``_forces_four`` stores them)
            fq, f0 = f[q, p], f[0, p]
            for i in range(4):
                for j in range(6):
                    fq[i, j] -= f0[i, j]
        if tangent and ((q == 1 and K.shape[0] == 2) or not contracted):
            Kq, K0 = K[q, p], K[0, p]
            for i in range(24):
                for j in range(24):
                    Kq[i, j] -= K0[i, j]


def _evaluate_mortar(X, kind, par, has, HCL, HFK, HLKp, f, K, sc, vec, two, flags, frames, rows, T):
    """``_point_mortar`` over all pairs: ``f`` ``(4, P, 4, 6)``, ``K`` ``(4, P, 24, 24)`` at ``T = 0`` and the
    differences to it at the three others (or ``(2, P, 24, 24)``: at ``T = 0`` and at the points' tractions ``T``
    ``(P, 3)`` less it), the point data and the gradient rows ``(P, N_ROWS, 24)``.  A template of the mortar kernel
    (``make_kernel(law, mortar=True)``)."""
    own = _scratch()
    ws = (_borrowed(own[0]), _borrowed(own[1]), _borrowed(own[2]), _borrowed(own[3]))
    own_spare = (np.empty((0, 0)), np.empty((4, 6)))
    spare = (_borrowed(own_spare[0]), _borrowed(own_spare[1]))
    # borrowed views (no reference counting per point and traction; the caller holds the arguments), as ``_evaluate``
    X, par, HCL, HFK, HLKp, T = _borrowed(X), _borrowed(par), _borrowed(HCL), _borrowed(HFK), _borrowed(HLKp), \
        _borrowed(T)
    kind, has, f, K, sc = _borrowed(kind), _borrowed(has), _borrowed(f), _borrowed(K), _borrowed(sc)
    vec, two, flags, frames, rows = _borrowed(vec), _borrowed(two), _borrowed(flags), _borrowed(frames), \
        _borrowed(rows)
    for p in range(X.shape[0]):
        _point_mortar(X[p], kind[p], par[p], has[p], HCL[p], HFK[p], HLKp[p], f, K, p, sc[p], vec[p], two[p],
                      flags[p], frames[p], ws, rows[p], T[p % T.shape[0]], spare)
    own[0][0, 0, 0, 0] = 0.0           # the scratch arrays' owners live until here
    own_spare[1][0, 0] = 0.0


# ---------------------------------------------------------------- the kernel of a contact law
_LAW_PATH = ("_friction", "_point", "_evaluate")      # the templates on the call path to the law, callee first
_MORTAR_PATH = ("_point", "_evaluate_rows")          # the four-call mortar kernel's (``_friction`` is ``_friction_given``)
_MORTAR_ONCE_PATH = ("_point_mortar", "_evaluate_mortar")   # the mortar kernel's: the geometry once per point
_TEMPLATES = {name: globals()[name] for name in _LAW_PATH + _MORTAR_PATH[1:] + _MORTAR_ONCE_PATH}
_KERNELS = {}


def _code_bytes(code):
    """Bytes identifying a code object's instructions, names and constants (stable across processes)."""
    consts = b"".join(_code_bytes(c) if isinstance(c, types.CodeType) else repr(c).encode() for c in code.co_consts)
    return code.co_code + repr(code.co_names).encode() + consts


def _digest(law):
    """Identity of a law's code: a law edited in place gets a new compiled kernel (and cache entry).
    Only the two functions' own code counts: after editing a helper they call, clear the numba
    cache (``__pycache__``) or rename the law."""
    codes = tuple(getattr(f, "py_func", f).__code__ for f in (law.normal, law.tangential))
    if codes not in _DIGESTS:      # (every evaluation asks: the bytes' hash cost 70 us a call on the main job)
        _DIGESTS[codes] = hashlib.sha1(b"".join(_code_bytes(c) for c in codes)).hexdigest()[:10]
    return _DIGESTS[codes]


_DIGESTS = {}    # ``_digest`` by the laws' code objects (equal code objects: equal instructions, names, constants)


def make_kernel(law, mortar=False):
    """The compiled batch driver ``_evaluate`` for ``law`` (a ``law.ContactLaw``), built once per process.

    The templates on the law's call path (``_friction``, ``_point``, ``_evaluate``) are copied
    with ``_normal_law`` and ``_tangential_law`` bound to the law's functions as globals, under
    the name ``<template>__<law name>_<code digest>``: numba's disk cache (``cache=True``) keys
    on that name and the template's source file, so each law's kernel compiles once per machine
    and loads from the cache afterwards (closures or functions passed as arguments are
    recompiled in every process with numba 0.68).  ``mortar``: the mortar kernel (``_evaluate_mortar``, the
    geometry once per point for the four tractions of ``mortar_terms``), ``"four"``: its former form, one
    ``_evaluate_rows`` call per traction (``mortar_terms_four``, the oracle).
    """
    key = f"{'mortar_' if mortar else ''}{law.name}_{_digest(law)}"
    path = _LAW_PATH if not mortar else _MORTAR_PATH if mortar == "four" else _MORTAR_ONCE_PATH
    if (key, path) not in _KERNELS:
        glb = dict(globals(), _normal_law=law.normal, _tangential_law=law.tangential)
        if mortar:
            glb["_friction"] = _friction_given
            glb["_EVERYWHERE"] = True      # the nodal traction field acts over the whole projected overlap
        for name in path:
            t = _TEMPLATES[name]
            f = types.FunctionType(t.__code__, glb, f"{name}__{key}", t.__defaults__)
            f.__qualname__, f.__doc__ = f.__name__, t.__doc__
            glb[name] = jit(f) if name == path[-1] else jit_callee(f)
        _KERNELS[key, path] = glb[path[-1]]
    return _KERNELS[key, path]


evaluate = make_kernel(PENALTY_COULOMB)


@jit
def _project_all(kind, HA1, h1, xi1, HA2, h2, xi2, iterations, out1, out2):
    for p in range(len(kind)):
        RA1, xA1 = _pose_of(HA1, p)
        RA2, xA2 = _pose_of(HA2, p)
        out1[p], out2[p] = _project(kind[p], RA1, xA1, (h1[p, 0], h1[p, 1], h1[p, 2]), (h1[p, 3], h1[p, 4], h1[p, 5]),
                                    xi1[p], RA2, xA2, (h2[p, 0], h2[p, 1], h2[p, 2]),
                                    (h2[p, 3], h2[p, 4], h2[p, 5]), xi2[p], iterations)


def project(kind, HA1, h1, xi1, HA2, h2, xi2, iterations=3):
    """Compiled ``frames.project`` (same arguments, batches ``(P, ...)``): ``xi1, xi2`` after
    ``iterations`` Newton iterations on the projection conditions of each pair's ``kind``."""
    P = len(h1)
    args = [np.ascontiguousarray(np.broadcast_to(a, (P,) + np.shape(a)[-s:] if s else (P,)), dtype=float)
            for a, s in ((HA1, 2), (h1, 1), (xi1, 0), (HA2, 2), (h2, 1), (xi2, 0))]
    kind = np.ascontiguousarray(np.broadcast_to(kind, (P,)), dtype=np.int64)
    out1, out2 = np.empty(P), np.empty(P)
    _project_all(kind, *args, int(iterations), out1, out2)
    return out1, out2


# ---------------------------------------------------------------- the signatures of reference.py
_PAR_COLUMNS = ((XI1, "xi1", np.nan), (XI2, "xi2", np.nan), (R1_, "R1", np.nan), (R2_, "R2", np.nan),
                (WEIGHT, "weight", np.nan), (PENALTY, "penalty", np.nan), (MULT, "multiplier", 0.0),
                (MU, "mu", np.nan), (PEN_T, "penalty_t", np.nan), (SMOOTH, "smoothing", 0.0),
                (ESLIP, "elastic_slip", np.nan), (TOUCH, "touch", 0.0))


def _readonly(v, shape, dtype):
    """``np.ascontiguousarray(np.broadcast_to(v, shape), dtype=dtype)``: for an array ``v`` already of
    that shape, dtype and layout the same read-only view without the broadcasting machinery (the
    kernel's argument types, hence its cached compilation, stay those of that expression)."""
    if isinstance(v, np.ndarray) and v.shape == shape and v.dtype == dtype and v.flags.c_contiguous:
        out = v.view()
        out.flags.writeable = False
        return out
    return np.ascontiguousarray(np.broadcast_to(v, shape), dtype=dtype)


_EYE4, _ZERO3 = np.eye(4), np.zeros(3)     # ``_table``'s defaults (read only)
_EYE4.flags.writeable = _ZERO3.flags.writeable = False


def _table(X, p):
    P = X.shape[0]
    par = np.empty((P, N_PAR))
    for k, name, default in _PAR_COLUMNS:
        v = p.get(name, default)
        par[:, k] = v if isinstance(v, np.ndarray) and v.shape == (P,) else \
            np.broadcast_to(np.asarray(v, dtype=float), (P,))
    par[:, XI1P] = p["xi1_prev"] if "xi1_prev" in p else par[:, XI1]
    par[:, XI2P] = p["xi2_prev"] if "xi2_prev" in p else par[:, XI2]
    frames = [_readonly(p[k] if k in p else _EYE4, (P, 4, 4), np.float64) for k in ("H_CL", "H_FK", "H_LK_prev")]
    lamp = _readonly(p["lam_t_prev"] if "lam_t_prev" in p else _ZERO3, (P, 3), np.float64)
    has = _readonly(p.get("has_history", False), (P,), np.bool_)
    kind = _readonly(p["kind"], (P,), np.int64)
    return kind, par, has, frames, lamp


def kernel_and_tangent(X, p, friction=True, law=None, K=None):
    """Wrenches ``(P, 4, 6)``, exact tangent ``(P, 24, 24)`` and point data (``reference.kernel_and_tangent``).

    ``X``: ``(P, 4, 4, 4)`` node poses ``A1, B1, A2, B2``; ``p``: the per-pair parameters of
    ``reference.contact_kernel``.  Column ``6 j + k`` of the tangent is the body increment ``k``
    of node ``j``.  ``law``: a ``law.ContactLaw`` (default ``PENALTY_COULOMB``, the law of ``reference.py``).
    ``K``: optional C-contiguous float array ``(P, 24, 24)`` the tangent is written to (a buffer the
    caller keeps: no fresh 4.6 kB per point and its page faults).
    """
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), lamp = _table(X, p)
    if K is None:
        K = np.empty((P, 24, 24))
    elif K.shape != (P, 24, 24) or K.dtype != np.float64 or not K.flags.c_contiguous:
        raise InputError(f"kernel_and_tangent: K must be a C-contiguous float array {(P, 24, 24)}, "
                         f"got {K.dtype} {K.shape}")
    f = np.empty((P, 4, 6))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames = np.empty((P, 2), dtype=np.bool_), np.empty((P, 4, 4, 4))
    kern = evaluate if law is None else make_kernel(law)
    kern(X, kind, par, has, HCL, HFK, HLKp, lamp, bool(friction), f, K, sc, vec, two, flags, frames)
    out = dict(gap=sc[:, 0], lam_n=sc[:, 1], active=flags[:, 0], n=vec[:, 0], t1=vec[:, 1], t2=vec[:, 2],
               xC=vec[:, 3], xF=vec[:, 4], xi1=sc[:, 2], xi2=sc[:, 3], lam_t=two[:, 0], stick=flags[:, 1],
               slip=two[:, 1], F_slave=vec[:, 5])
    if friction:
        out.update(HL=frames[:, 0], HK=frames[:, 1], HC=frames[:, 2], HF=frames[:, 3])
    return f, K, out


def contact_kernel(X, p, friction=True, law=None):
    """Wrenches ``(P, 4, 6)`` and point data (``reference.contact_kernel``, for batches ``(P, 4, 4, 4)``):
    the kernel without its tangent (an empty ``K``: no variations, no tangent rows; the segment ends'
    forward difference, ``segment_tangent``)."""
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), lamp = _table(X, p)
    f = np.empty((P, 4, 6))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames = np.empty((P, 2), dtype=np.bool_), np.empty((P, 4, 4, 4))
    kern = evaluate if law is None else make_kernel(law)
    kern(X, kind, par, has, HCL, HFK, HLKp, lamp, bool(friction), f, np.empty((P, 0, 0)), sc, vec, two, flags, frames)
    out = dict(gap=sc[:, 0], lam_n=sc[:, 1], active=flags[:, 0], n=vec[:, 0], t1=vec[:, 1], t2=vec[:, 2],
               xC=vec[:, 3], xF=vec[:, 4], xi1=sc[:, 2], xi2=sc[:, 3], lam_t=two[:, 0], stick=flags[:, 1],
               slip=two[:, 1], F_slave=vec[:, 5])
    if friction:
        out.update(HL=frames[:, 0], HK=frames[:, 1], HC=frames[:, 2], HF=frames[:, 3])
    return f, out


_MORTAR_POOL = BufferPool()      # ``mortar_terms``' tangent buffers (free again once its results are dropped)
_ROWS_POOL = BufferPool()        # its gradient rows (141 MB on the 19-wire bundle: fresh, their page faults cost)
_FRAMES_POOL = BufferPool(keep=3)   # the contact frames ``mortar_terms`` and ``mortar_forces`` return views of
MORTAR_CHUNK = 2048              # points per pass of ``mortar_terms`` with a ``sink`` (its tangent and rows buffers)
_CHUNK_POOL = BufferPool()       # the passes' tangent and gradient rows (``MORTAR_CHUNK`` points: 14 MB)
_CHUNK_ROWS_POOL = BufferPool()
_CHUNK4_POOL = BufferPool()      # the four tractions' tangents of a pass (``mortar_terms(sink=)`` without ``T``: 38 MB)
COMMIT_CHUNK = 8192              # points per pass of ``mortar_data_of`` (a commit's: their poses and four frames, 8 MB)


def mortar_terms(X, p, law=None, T=None, whole=False, pairs=False, sink=None):
    """Point terms of the mortar friction (``mortar.py``) from the compiled mortar kernel.

    ``T`` ``(P, 3)``: the points' tractions, known before the call (exact stick's multipliers): ``dfdq``
    ``(P, 24, 24)`` = ``sum_k T_k dK_k`` from two tangents (at ``T`` and at 0) instead of ``dK`` (equal to
    round-off; half the kernel's tangent rows and memory).  ``whole``: ``dfdq`` is the whole tangent at ``T``
    (the normal law's too, as the point kernel gives it without friction): one tangent.  ``pairs`` (with ``T``):
    ``d["pairs"]``, the pairs' forces and point data without friction (``_pair_data``).

    A point's friction force is linear in the global traction ``T`` (force per length) it is given:
    ``f = A T`` and, at fixed ``T``, ``df/dq = sum_k T_k dK_k``.  Four tractions (``T = 0, e_x, e_y,
    e_z``; the normal part cancels in the differences; one compiled pass, the geometry once per point) give ``A`` ``(P, 24, 3)`` and ``dK``
    ``(P, 3, 24, 24)``; the first also gives the slip ``S = s1 t1 + s2 t2`` ``(P, 3)`` (global) and
    ``dS`` ``(P, 3, 24)``, ``lam_n`` ``(P,)``, ``dlam_n`` ``(P, 24)``, ``n``, ``t1``, ``t2`` ``(P, 3)``, ``dn``
    ``(P, 3, 24)``, ``slip`` ``(P, 2)``, ``HL``, ``HK`` ``(P, 4, 4)``, ``active`` ``(P,)``.  Columns as in
    ``kernel_and_tangent`` (body increments of the nodes A1, B1, A2, B2).

    ``sink`` (with ``T`` and ``whole``): ``sink(a, b, dfdq)`` takes the whole tangents ``(b - a, 24, 24)`` of the
    points ``a .. b - 1``, in order, and ``d`` has no ``dfdq``: the kernel runs over ``MORTAR_CHUNK`` points at a
    time (``_mortar_chunks``; the same operations per point: the same bits), so neither the ``(P, 24, 24)`` tangents
    nor the ``(P, N_ROWS, 24)`` gradient rows are held at once (7 kB a point: 0.5 GB on the 61-wire bundle).
    ``sink`` without ``T`` (the four tractions): ``sink(a, b, dK)`` takes ``dK`` ``(b - a, 3, 24, 24)`` of those
    points, pass by pass, and ``d`` has no ``dK`` (20 kB a point at once: 0.4 GB at the 61-wire strand's step 0).
    """
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), _ = _table(X, p)
    kern = make_kernel(PENALTY_COULOMB if law is None else law, mortar=True)
    if sink is not None and (T is None or whole):
        return _mortar_chunks(X, (kind, par, has, HCL, HFK, HLKp), kern, T, pairs, sink)
    # the tangents into kept memory (4.6 kB a point and traction; fresh memory's page faults cost about as much
    # as the kernel on the 19-wire bundle), a contiguous (4, P, 24, 24) prefix as ``np.empty`` would give
    nK = 4 if T is None else 1 if whole else 2
    f, K = np.empty((4, P, 4, 6)), _MORTAR_POOL.take((nK * P * 576,)).reshape(nK, P, 24, 24)
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames, rows = np.empty((P, 2), dtype=np.bool_), _FRAMES_POOL.take((P, 4, 4, 4)), \
        _ROWS_POOL.take((P, N_ROWS, 24))
    Tc = np.zeros((1, 3)) if T is None else np.ascontiguousarray(T, dtype=float)
    kern(X, kind, par, has, HCL, HFK, HLKp, f, K, sc, vec, two, flags, frames, rows, Tc)
    if T is None:
        return _mortar_terms(P, f[1:], K[1:], sc, vec, two, flags, frames, rows)
    d = _mortar_terms(P, f[1:], None, sc, vec, two, flags, frames, rows)
    d["dfdq"] = K[-1]
    if pairs:
        d["pairs"] = _pair_data(f, sc, vec, par)
    return d


def _mortar_chunks(X, table, kern, T, pairs, sink):
    """``mortar_terms(X, p, law, T, whole=True, pairs, sink)``: the kernel ``kern`` and the point terms over
    ``MORTAR_CHUNK`` points at a time, each pass's tangents handed to ``sink`` (``table``: ``_table``'s arrays);
    ``T`` None: the four tractions' (``mortar_terms(X, p, law, sink=)``), ``sink`` given their ``dK``."""
    P = X.shape[0]
    C = max(1, min(P, MORTAR_CHUNK))
    nK = 4 if T is None else 1
    # the forces at T = 0 (the pairs'); those of the unit tractions: ``A`` (without ``T`` kept, ``A`` their view as
    # ``mortar_terms``' whole pass gives it: its products, ``einsum``, take the same loops, the same bits)
    f = np.empty((1 if T is not None else 4, P, 4, 6))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames = np.empty((P, 2), dtype=np.bool_), _FRAMES_POOL.take((P, 4, 4, 4))
    terms = tuple(pool.take(shape) for pool, shape in zip(mortar_jit._TERMS_POOLS, ((P, 24, 3), (P, 3, 24),
                                                                                       (P, 3, 24), (P, 24))))
    Tc = np.zeros((1, 3)) if T is None else np.ascontiguousarray(T, dtype=float)
    fbuf, Kbuf = np.empty(4 * C * 24), (_CHUNK_POOL if nK == 1 else _CHUNK4_POOL).take((nK * C * 576,))
    rbuf = _CHUNK_ROWS_POOL.take((C * N_ROWS * 24,))
    for a in range(0, P, C):
        b = min(a + C, P)
        n = b - a
        fc, Kc = fbuf[:4 * n * 24].reshape(4, n, 4, 6), Kbuf[:nK * n * 576].reshape(nK, n, 24, 24)
        rows = rbuf[:n * N_ROWS * 24].reshape(n, N_ROWS, 24)
        kern(X[a:b], *(t[a:b] for t in table), fc, Kc, sc[a:b], vec[a:b], two[a:b], flags[a:b], frames[a:b], rows,
             Tc if T is None else Tc[a:b])
        f[:, a:b] = fc[:len(f)]
        mortar_jit.point_terms_into(fc[1:], rows, vec[a:b, 1], vec[a:b, 2], two[a:b, 1], *(t[a:b] for t in terms))
        sink(a, b, Kc[0] if T is not None else np.transpose(Kc[1:], (1, 0, 2, 3)))
    d = _mortar_terms(P, None, None, sc, vec, two, flags, frames, None, terms=terms)
    if T is None:
        d["A"] = np.transpose(f[1:], (1, 2, 3, 0)).reshape(P, 24, 3)
    if pairs:
        d["pairs"] = _pair_data(f, sc, vec, table[1])
    return d


def _pair_data(f, sc, vec, par):
    """The pairs' kernel without friction (``contact_kernel(X, p, friction=False)``) from the mortar kernel's pass
    at ``T = 0``: forces ``f[0]`` ``(P, 4, 6)`` and its point data (the same bits up to the signs of zeros: the
    unit tractions' terms of that pass are zeros; ``f`` None: no forces, ``mortar_data``'s)."""
    n, lam = vec[:, 0], sc[:, 1]
    data = dict(gap=sc[:, 0], lam_n=lam, n=n, t1=vec[:, 1], t2=vec[:, 2], xC=vec[:, 3], xF=vec[:, 4], xi1=sc[:, 2],
                xi2=sc[:, 3], F_slave=(-par[:, WEIGHT] * lam)[:, None] * n)
    return (None if f is None else f[0]), data


def _mortar_pass(X, p, law, n_forces):
    """The mortar kernel without tangent over the points ``X`` (``mortar_forces``, ``mortar_data``): ``n_forces``
    (4: the four tractions' forces; 0: none) -> ``(f, par, sc, vec, d)``, ``d`` the point data ``S``, ``lam_n``,
    ``n``, ``t1``, ``t2``, ``slip``, ``HL``, ``HK``, ``active``, ``xi1``, ``xi2``."""
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), _ = _table(X, p)
    kern = make_kernel(PENALTY_COULOMB if law is None else law, mortar=True)
    f, K = np.empty((n_forces, P, 4, 6)), np.empty((4, P, 0, 0))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames, rows = np.empty((P, 2), dtype=np.bool_), _FRAMES_POOL.take((P, 4, 4, 4)), np.empty((P, 0, 0))
    kern(X, kind, par, has, HCL, HFK, HLKp, f, K, sc, vec, two, flags, frames, rows, np.zeros((1, 3)))
    return f, par, sc, vec, _point_dict(sc, vec, two, flags, frames[:, 0], frames[:, 1])


def _point_dict(sc, vec, two, flags, HL, HK):
    """The point data of a mortar kernel pass without tangent (its ``sc``, ``vec``, ``two``, ``flags`` and frames
    ``HL``, ``HK``): ``S``, ``lam_n``, ``n``, ``t1``, ``t2``, ``slip``, ``HL``, ``HK``, ``active``, ``xi1``, ``xi2``."""
    n, t1, t2, s = vec[:, 0], vec[:, 1], vec[:, 2], two[:, 1]
    return dict(S=s[:, :1] * t1 + s[:, 1:] * t2, lam_n=sc[:, 1].copy(), n=n, t1=t1, t2=t2, slip=s.copy(),
                HL=HL, HK=HK, active=flags[:, 0].copy(), xi1=sc[:, 2].copy(), xi2=sc[:, 3].copy())


def mortar_forces(X, p, law=None, pairs=False):
    """``mortar_terms`` without the tangent's parts (a line-search trial needs the residuals only): ``A``, ``S``,
    ``lam_n``, ``n``, ``t1``, ``t2``, ``slip``, ``HL``, ``HK``, ``active``, ``xi1``, ``xi2``, the same bits as
    ``mortar_terms``' (the mortar kernel with an empty tangent: no frame variations, no gradient rows); ``pairs``:
    as ``mortar_terms``'."""
    P = len(X)
    f, par, sc, vec, d = _mortar_pass(X, p, law, 4)
    d["A"] = np.transpose(f[1:], (1, 2, 3, 0)).reshape(P, 24, 3)
    if pairs:
        d["pairs"] = _pair_data(f, sc, vec, par)
    return d


def mortar_data_of(H, nodes, p, law=None, chunk=None):
    """``mortar_data(H[nodes], p, law)``, the same bits, over ``COMMIT_CHUNK`` (``chunk``) points at a time: a pass's
    points' poses gathered for it alone, and of the kernel's four frames of a point ``HL`` and ``HK`` kept ``(P, 2, 4,
    4)`` (a commit's every point: 206 304 on the 61-wire strand, whose ``H[nodes]`` and four frames are 0.1 GB each)."""
    P = len(nodes)
    C = max(1, min(P, COMMIT_CHUNK if chunk is None else chunk))
    kind, par, has, (HCL, HFK, HLKp), _ = _table(nodes, p)
    kern = make_kernel(PENALTY_COULOMB if law is None else law, mortar=True)
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, HLK, frames = np.empty((P, 2), dtype=np.bool_), np.empty((P, 2, 4, 4)), np.empty((C, 4, 4, 4))
    for a in range(0, P, C):
        b = min(a + C, P)
        n = b - a
        X = np.ascontiguousarray(H[nodes[a:b]], dtype=float)
        kern(X, kind[a:b], par[a:b], has[a:b], HCL[a:b], HFK[a:b], HLKp[a:b], np.empty((0, n, 4, 6)),
             np.empty((4, n, 0, 0)), sc[a:b], vec[a:b], two[a:b], flags[a:b], frames[:n], np.empty((n, 0, 0)),
             np.zeros((1, 3)))
        HLK[a:b] = frames[:n, :2]
    d = _point_dict(sc, vec, two, flags, HLK[:, 0], HLK[:, 1])
    d["pairs"] = _pair_data(None, sc, vec, par)
    return d


def mortar_data(X, p, law=None):
    """``mortar_forces``' point data without its forces (a commit's: ``ContactSystem.commit`` stores frames, slips and
    the groups' state, no force): ``S``, ``lam_n``, ``n``, ``t1``, ``t2``, ``slip``, ``HL``, ``HK``, ``active``,
    ``xi1``, ``xi2`` and ``d["pairs"]``' point data (``gap``, ``lam_n``, ``n``, ``t1``, ``t2``, ``xC``, ``xF``, ``xi1``,
    ``xi2``, ``F_slave``), the same bits as ``mortar_forces(pairs=True)``'s: the mortar kernel with an empty ``f``
    (the geometry, projection, normal law, slip and frames of each point; not the four tractions' wrenches and nodal
    forces, nor the Jacobians they take)."""
    _, par, sc, vec, d = _mortar_pass(X, p, law, 0)
    d["pairs"] = _pair_data(None, sc, vec, par)
    return d


def mortar_terms_four(X, p, law=None):
    """``mortar_terms`` by four calls of the point kernel (``make_kernel(law, mortar="four")``): its oracle.

    A point's friction force is linear in the global traction ``T`` (force per length) it is given:
    ``f = A T`` and, at fixed ``T``, ``df/dq = sum_k T_k dK_k``.  Four evaluations (``T = 0, e_x, e_y,
    e_z``; the normal part cancels in the differences) give ``A`` ``(P, 24, 3)`` and ``dK``
    ``(P, 3, 24, 24)``; the first also gives the slip ``S = s1 t1 + s2 t2`` ``(P, 3)`` (global) and
    ``dS`` ``(P, 3, 24)``, ``lam_n`` ``(P,)``, ``dlam_n`` ``(P, 24)``, ``n``, ``t1``, ``t2`` ``(P, 3)``, ``dn``
    ``(P, 3, 24)``, ``slip`` ``(P, 2)``, ``HL``, ``HK`` ``(P, 4, 4)``, ``active`` ``(P,)``.  Columns as in
    ``kernel_and_tangent`` (body increments of the nodes A1, B1, A2, B2).
    """
    X = np.ascontiguousarray(X, dtype=float)
    P = X.shape[0]
    kind, par, has, (HCL, HFK, HLKp), _ = _table(X, p)
    kern = make_kernel(PENALTY_COULOMB if law is None else law, mortar="four")
    f, K = np.empty((4, P, 4, 6)), np.empty((4, P, 24, 24))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames, rows = np.empty((P, 2), dtype=np.bool_), np.empty((P, 4, 4, 4)), np.empty((P, N_ROWS, 24))
    junk = np.empty((P, N_ROWS, 24))
    for k in range(4):
        lamp = np.zeros((P, 3))
        if k:
            lamp[:, k - 1] = 1.0
        kern(X, kind, par, has, HCL, HFK, HLKp, lamp, True, f[k], K[k], sc, vec, two, flags, frames,
             rows if k == 0 else junk)
    return _mortar_terms(P, f[1:] - f[0], K[1:] - K[0], sc, vec, two, flags, frames, rows)


def _mortar_terms(P, df, dK, sc, vec, two, flags, frames, rows, terms=None):
    """``mortar_terms``' dict from the differences of the forces ``df`` ``(3, P, 4, 6)`` and tangents ``dK``
    ``(3, P, 24, 24)`` at ``T = e_x, e_y, e_z`` to those at ``T = 0`` and the kernel's point data (``terms``:
    ``mortar_jit.point_terms``' results, if computed already; then ``rows`` is not read, and ``df`` may be None:
    ``A`` is then their contiguous ``A``, the same values)."""
    A = terms[0] if df is None else np.transpose(df, (1, 2, 3, 0)).reshape(P, 24, 3)
    dK = None if dK is None else np.transpose(dK, (1, 0, 2, 3))
    n, t1, t2, s = vec[:, 0], vec[:, 1], vec[:, 2], two[:, 1]
    S = s[:, :1] * t1 + s[:, 1:] * t2
    # ``G``: ``A`` contiguous (the scatters' input; ``A`` itself, a view, for the forces' products); the slip's
    # gradient ``dS = t1 ds1 + s1 dt1 + t2 ds2 + s2 dt2`` and the rows in one compiled pass (``mortar_jit.point_terms``)
    Ac, dS, dn, dlam_n = mortar_jit.point_terms(df, rows, t1, t2, s) if terms is None else terms
    return dict(A=A, G=Ac, dK=dK, S=S, dS=dS, lam_n=sc[:, 1].copy(), dlam_n=dlam_n, n=n, t1=t1, t2=t2, dn=dn,
                slip=s.copy(), HL=frames[:, 0], HK=frames[:, 1], active=flags[:, 0].copy(),
                xi1=sc[:, 2].copy(), xi2=sc[:, 3].copy())
