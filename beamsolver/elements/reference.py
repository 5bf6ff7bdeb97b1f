"""The numpy oracle of the two-node element: imported by tests and benchmarks only.

The same maths, arguments and results (to round-off) as the compiled kernel that
``element.internal_forces``/``internal_forces_and_tangent`` run (``element_jit``), batched in
numpy (docs/theory.md eqs. 3.1-3.7); the tangent of ``internal_forces_and_tangent_numpy`` is
an ``(n, 12, 12)`` view of an element-axis-last array.

Inside, every quantity is stored with the element axis *last* (``geometric``'s layout) and
elements are processed in chunks of ``CHUNK``: the small-index algebra is then elementwise
operations on long contiguous arrays (faster in numpy than stacked ``(m, 3, 3) @ (m, 3, 3)``
products; docs/benchmarks.md).

Both nodes share one code path: with ``T(h)^-1 = [[Ti, X], [0, Ti]]``,
``Ti = T_SO3(w)^-1 = I + W/2 + d W^2`` and ``X = -Ti Q(-u, -w) Ti``, the matrix
``T(-h)^-1`` is ``T(h)^-1`` evaluated at ``-h``, so every side quantity is
computed once on the doubled batch ``[-h | h]`` (node A, then node B):
``f_A = -g(h)``, ``f_B = g(-h)`` with ``g(h) = T(-h)^-T sigma = [Ti n; X n + Ti m]``,
and the columns of ``B`` for node A (B) are ``-T(-h)^-1`` (``T(h)^-1``).
"""
import numpy as np

from ..lie import se3
from ..lie.se3 import coefficient
from .element import ElementState
from .geometric import TANGENT_COEFFICIENTS, _cross, _dot, _geometric, _mat, _mm, _mv, _q_mat

__all__ = ["internal_forces_numpy", "internal_forces_and_tangent_numpy", "CHUNK"]

# elements per chunk (benchmarks/element_throughput.py): larger chunks amortise the
# per-call overhead of numpy, beyond ~8k the temporaries fall out of the cache
CHUNK = 6144
FORCE_COEFFICIENTS = ("c", "q2", "q3")
_OFF_DIAGONAL = ~np.eye(6, dtype=bool)


def _log_relative(HA, HB):
    """``log(H_A^-1 H_B)`` as ``u, w`` (3, m), and ``t = |w|``, ``d`` (coefficient of ``Ti``)."""
    h = se3.log_relative(HA, HB).T
    u, w = h[:3], h[3:]
    t = np.sqrt(_dot(w, w))
    return u, w, t, coefficient("d", t)


def _diagonal(C):
    """Diagonal ``(6, m)`` of ``C`` (m, 6, 6) if every ``C`` is diagonal, else ``None``."""
    if np.any(C[:, _OFF_DIAGONAL]):
        return None
    return np.ascontiguousarray(np.einsum("nii->in", C))


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


def internal_forces_numpy(H_A, H_B, L, eps0, C):
    """``internal_forces`` by the batched numpy kernel (the oracle of the compiled one)."""
    f, _, state = _evaluate(H_A, H_B, L, eps0, C, tangent=False)
    return f, state


def internal_forces_and_tangent_numpy(H_A, H_B, L, eps0, C, out=None):
    """``internal_forces_and_tangent`` by the batched numpy kernel (the oracle of the compiled one)."""
    return _evaluate(H_A, H_B, L, eps0, C, tangent=True, out=out)
