"""The two-node SE(3) beam element (Sonneville, Cardona & Bruls 2014), batched.

For an element with nodal poses ``H_A, H_B`` and reference length ``L``
(docs/theory.md eqs. 3.1-3.7):

- ``h = log(H_A^-1 H_B)``, strain ``eps = h / L`` (``Gamma`` then ``kappa``,
  section frame), section forces ``sigma = C (eps - eps0)``;
- energy ``V = L/2 (eps - eps0)^T C (eps - eps0)``;
- body-frame nodal forces ``f_A = -T(-h)^-T sigma``, ``f_B = T(h)^-T sigma``;
- tangent ``K = B^T (C/L) B + [G(-h, sigma); G(h, sigma)] B`` with
  ``B = [-T(-h)^-1, T(h)^-1]`` and ``G(h, s) = d(T(h)^-T s)/dh`` in closed
  form (derived below, checked against finite differences in
  ``tests/test_element.py``).

All public functions take arrays batched over elements: poses ``(n, 4, 4)``,
``L`` ``(n,)``, ``eps0`` ``(n, 6)``, ``C`` ``(n, 6, 6)``.  They return forces and
states with the element axis first and the tangent ``(n, 12, 12)``.  They run
the compiled kernels of ``element_jit`` (numba; one element per call, a batch
loop, tangent stored element-major, the order ``assembly.System`` scatters).
The ``*_numpy`` functions run the batched numpy kernel below, kept as the
test oracle (its tangent is an ``(n, 12, 12)`` view of an element-axis-last
array).

Numpy implementation.  Inside, every quantity is stored with the element axis
*last* (vectors ``(3, m)``, 3x3 blocks ``(3, 3, m)``) and elements are processed
in chunks of ``CHUNK``: the small-index algebra is then elementwise operations
on long contiguous arrays (an order of magnitude faster in numpy than stacked
``(m, 3, 3) @ (m, 3, 3)`` products).  Products of skew matrices are expanded
with ``hat(a) hat(b) = b a^T - (a.b) I`` and ``hat(w)^2 = w w^T - |w|^2 I``, so
``Q`` (docs/theory.md eq. 2.6) and the geometric stiffness become sums of a skew
matrix, a few outer products and a multiple of ``I`` (``_mat``).

Both nodes share one code path: with ``T(h)^-1 = [[Ti, X], [0, Ti]]``,
``Ti = T_SO3(w)^-1 = I + W/2 + d W^2`` and ``X = -Ti Q(-u, -w) Ti``, the matrix
``T(-h)^-1`` is ``T(h)^-1`` evaluated at ``-h``, so every side quantity is
computed once on the doubled batch ``[-h | h]`` (node A, then node B):
``f_A = -g(h)``, ``f_B = g(-h)`` with ``g(h) = T(-h)^-T sigma = [Ti n; X n + Ti m]``,
and the columns of ``B`` for node A (B) are ``-T(-h)^-1`` (``T(h)^-1``).
"""
from functools import partial
from typing import NamedTuple

import numpy as np

from ..lie import se3
from ..lie.se3 import coefficient

__all__ = ["ElementState", "element_state", "reference_strain", "energy",
           "internal_forces", "internal_forces_and_tangent", "evaluate", "evaluate_nodes", "is_diagonal", "geometric", "internal_forces_numpy",
           "internal_forces_and_tangent_numpy", "CHUNK"]

# elements per chunk, measured (benchmarks/element_throughput.py): larger chunks amortise the
# per-call overhead of numpy, beyond ~8k the temporaries fall out of the cache
CHUNK = 6144


class ElementState(NamedTuple):
    h: np.ndarray       # (n, 6) relative twist log(H_A^-1 H_B)
    strain: np.ndarray  # (n, 6) h / L
    sigma: np.ndarray   # (n, 6) section forces (N, Q2, Q3, T, M2, M3)


def reference_strain(H_A, H_B):
    """Reference length ``L = |u0|`` and strain ``eps0 = h0 / L`` of reference poses ``(n, 4, 4)``."""
    from . import element_jit
    h0 = np.empty((len(H_A), 6))
    element_jit.relative_twists(np.ascontiguousarray(H_A, dtype=float), np.ascontiguousarray(H_B, dtype=float), h0)
    L = np.sqrt(np.einsum("...i,...i->...", h0[..., :3], h0[..., :3]))
    return L, h0 / L[..., None]


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


# ---------------------------------------------------------------- relative pose and log
def _log_relative(HA, HB):
    """``log(H_A^-1 H_B)`` as ``u, w`` (3, m), and ``t = |w|``, ``d`` (coefficient of ``Ti``)."""
    h = se3.log_relative(HA, HB).T
    u, w = h[:3], h[3:]
    t = np.sqrt(_dot(w, w))
    return u, w, t, coefficient("d", t)


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


# ---------------------------------------------------------------- the kernel
_OFF_DIAGONAL = ~np.eye(6, dtype=bool)


def _diagonal(C):
    """Diagonal ``(6, m)`` of ``C`` (m, 6, 6) if every ``C`` is diagonal, else ``None``."""
    if np.any(C[:, _OFF_DIAGONAL]):
        return None
    return np.ascontiguousarray(np.einsum("nii->in", C))


def is_diagonal(C):
    """True if every ``C`` ``(n, 6, 6)`` is diagonal."""
    return not np.any(C[:, _OFF_DIAGONAL])


def _twice(x):
    return np.concatenate([x, x], axis=-1)


def _chunk(HA, HB, L, eps0, C, tangent, K_out):
    """Forces (12, m), h, strain, sigma (6, m) of one chunk; the tangent goes to ``K_out`` (12, 12, m)."""
    m = len(L)
    u, w, t, d = _log_relative(HA, HB)
    h = np.concatenate([u, w])
    strain = h / L
    de = strain - eps0.T
    Cd = _diagonal(C)
    if Cd is not None:
        sigma = Cd * de
    else:
        sigma = np.einsum("ijm,jm->im", C.transpose(1, 2, 0), de)
    k = {name: _twice(v) for name, v in
         se3.coefficients(TANGENT_COEFFICIENTS if tangent else FORCE_COEFFICIENTS, t).items()}
    c1, c2, c3 = k["c"], k["q2"], k["q3"]
    # doubled batch [-h | h]: node A quantities first, node B second
    u2, w2, d2 = np.concatenate([-u, u], axis=1), np.concatenate([-w, w], axis=1), _twice(d)
    n2, m2 = _twice(sigma[:3]), _twice(sigma[3:])
    t2 = _twice(t * t)
    wu = _twice(_dot(w, u))
    axu = np.concatenate([_cross(w, u)] * 2, axis=1)            # (-w) x (-u) = w x u
    Ti = _mat(skew=0.5 * w2, outers=[(d2 * w2, w2)], diag=1.0 - d2 * t2)
    X = -_mm(_mm(Ti, _q_mat(-u2, -w2, wu, axu, t2, c1, c2, c3)), Ti)
    Tin = _mv(Ti, n2)
    g = np.concatenate([Tin, _mv(X, n2) + _mv(Ti, m2)])    # g(h) = T(-h)^-T sigma = [Ti n; X n + Ti m]
    f = np.concatenate([-g[:, m:], g[:, :m]])             # f_A = -g(h), f_B = g(-h)
    if not tangent:
        return f, h, strain, sigma
    k.update(d=d2, t2=t2)
    G12, G21, G22 = _geometric(u2, w2, n2, m2, k)
    # rows of node s (A: sign -1, B: +1): Z_s = sign [[Ti^T, 0], [X^T, Ti^T]] (C/L) + [[0, G12], [G21, G22]]
    sign = np.repeat([-1.0, 1.0], m)
    TiT, XT = sign * Ti.transpose(1, 0, 2), sign * X.transpose(1, 0, 2)
    if Cd is not None:
        kd = _twice(Cd / L)
        Z0 = np.concatenate([TiT * kd[:3], XT * kd[:3] + G21])            # (6, 3, 2m)
        Z1 = np.concatenate([G12, TiT * kd[3:] + G22])
    else:
        CL = _twice(C.transpose(1, 2, 0) / L)
        Bt = np.concatenate([np.concatenate([TiT, np.zeros_like(TiT)], axis=1),
                             np.concatenate([XT, TiT], axis=1)])          # (6, 6, 2m)
        Z = np.einsum("ikm,kjm->ijm", Bt, CL)
        Z0 = Z[:, :3] + np.concatenate([np.zeros_like(G21), G21])
        Z1 = Z[:, 3:] + np.concatenate([G12, G22])
    Z0 = np.concatenate([Z0[..., :m], Z0[..., m:]])                       # (12, 3, m)
    Z1 = np.concatenate([Z1[..., :m], Z1[..., m:]])
    # columns of node s: sign [[Ti, X], [0, Ti]] of its side
    for s, cols in ((0, slice(0, 6)), (1, slice(6, 12))):
        part = slice(s * m, (s + 1) * m)
        Tis, Xs = sign[part] * Ti[..., part], sign[part] * X[..., part]
        K_out[:, cols.start:cols.start + 3] = _mm(Z0, Tis)
        K_out[:, cols.start + 3:cols.stop] = _mm(Z0, Xs) + _mm(Z1, Tis)
    return f, h, strain, sigma


def _evaluate(H_A, H_B, L, eps0, C, tangent, out=None):
    n = len(L)
    f = np.empty((n, 12))
    K = None
    if tangent:
        K = np.empty((12, 12, n)) if out is None else out
        if K.shape != (12, 12, n):
            raise ValueError(f"out must have shape (12, 12, {n}), got {K.shape}")
    h, strain, sigma = np.empty((n, 6)), np.empty((n, 6)), np.empty((n, 6))
    for a in range(0, n, CHUNK):
        b = min(a + CHUNK, n)
        out = _chunk(H_A[a:b], H_B[a:b], L[a:b], eps0[a:b], C[a:b], tangent,
                     K[..., a:b] if tangent else None)
        f[a:b], h[a:b], strain[a:b], sigma[a:b] = (x.T for x in out)
    return f, (K.transpose(2, 0, 1) if tangent else None), ElementState(h, strain, sigma)


def evaluate(H_A, H_B, L, eps0, C, tangent, out=None, diagonal=None):
    """Forces, tangent (``tangent``: else ``None``) and state by the compiled kernels (``element_jit``).

    The tangent is a C-contiguous ``(n, 12, 12)`` array (``out`` if given, of that shape).
    ``diagonal``: whether every ``C`` is diagonal, if known (else checked).
    """
    n = len(L)
    H = np.concatenate([np.asarray(H_A, dtype=float).reshape(n, 4, 4), np.asarray(H_B, dtype=float).reshape(n, 4, 4)])
    nodes = np.stack([np.arange(n), np.arange(n, 2 * n)], axis=1)
    return evaluate_nodes(H, nodes, L, eps0, C, tangent, out, diagonal)


def evaluate_nodes(H, nodes, L, eps0, C, tangent, out=None, diagonal=None):
    """``evaluate`` for elements whose node poses are ``H[nodes[e, 0]], H[nodes[e, 1]]``.

    ``H``: poses ``(N, 4, 4)``; ``nodes``: ``(n, 2)`` integer rows of ``H``.  The kernel reads
    the poses in place (no gathered copies); this is the path ``elements.se3_2`` runs.
    """
    from . import element_jit   # numba compiles (or loads its cache) on first use
    n = len(L)
    H, L, eps0, C = (np.ascontiguousarray(x, dtype=float) for x in (H, L, eps0, C))
    nodes = np.ascontiguousarray(nodes, dtype=np.int64)
    if diagonal is None:
        diagonal = is_diagonal(C)
    f = np.empty((n, 12))
    h, strain, sigma = np.empty((n, 6)), np.empty((n, 6)), np.empty((n, 6))
    K = np.empty((0, 12, 12))
    if tangent:
        K = np.empty((n, 12, 12)) if out is None else out
        if K.shape != (n, 12, 12):
            raise ValueError(f"out must have shape ({n}, 12, 12), got {K.shape}")
    element_jit.evaluate(H, nodes, L, eps0, C, diagonal, tangent, f, h, strain, sigma, K)
    return f, (K if tangent else None), ElementState(h, strain, sigma)


def element_state(H_A, H_B, L, eps0, C):
    """``ElementState`` (relative twist, strain, section forces) per element."""
    return evaluate(H_A, H_B, L, eps0, C, tangent=False)[2]


def energy(H_A, H_B, L, eps0, C):
    """Strain energy per element, ``(n,)``."""
    s = element_state(H_A, H_B, L, eps0, C)
    de = s.strain - eps0
    return 0.5 * L * np.einsum("ni,ni->n", de, s.sigma)


def internal_forces(H_A, H_B, L, eps0, C):
    """Body-frame nodal forces ``(n, 12)`` (A then B) and the ``ElementState``."""
    f, _, state = evaluate(H_A, H_B, L, eps0, C, tangent=False)
    return f, state


def internal_forces_and_tangent(H_A, H_B, L, eps0, C, out=None):
    """Nodal forces ``(n, 12)``, tangent ``(n, 12, 12)`` and the ``ElementState``.

    The tangent is ``d f / d q`` for body increments ``q = (q_A, q_B)``
    (``H <- H exp(hat(q))``), material and geometric parts, exact; ``out``,
    if given, a C-contiguous array ``(n, 12, 12)`` to write it into.  Compiled
    (``element_jit``); ``internal_forces_and_tangent_numpy`` is the numpy
    version, kept as the test oracle (its ``out`` is element-axis-last,
    ``(12, 12, n)``, see the module docstring).
    """
    return evaluate(H_A, H_B, L, eps0, C, tangent=True, out=out)


def internal_forces_numpy(H_A, H_B, L, eps0, C):
    """``internal_forces`` by the batched numpy kernel (the oracle of the compiled one)."""
    f, _, state = _evaluate(H_A, H_B, L, eps0, C, tangent=False)
    return f, state


def internal_forces_and_tangent_numpy(H_A, H_B, L, eps0, C, out=None):
    """``internal_forces_and_tangent`` by the batched numpy kernel (the oracle of the compiled one)."""
    return _evaluate(H_A, H_B, L, eps0, C, tangent=True, out=out)
