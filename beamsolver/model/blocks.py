"""Local force and tangent blocks of a contribution and their generic assembly.

A contribution (elements, contact, a spring, ...) hands the assembler blocks over
``k`` nodes each (block size ``6 k``):

- ``nodes`` ``(m, k)``: node ids of each block;
- ``f`` ``(m, 6 k)``: the block's part of the residual ``r = f_int - f_ext``,
  conjugate to the body increments ``q`` of its nodes (``H <- H exp(hat(q))``,
  translation first);
- ``K`` ``(m, 6 k, 6 k)`` or ``None``: ``d f / d q``.

``transform`` carries blocks from body increments ``q`` to the unknowns ``z`` of
their nodes (``q = M z``, ``assembly.System.node_transforms``): ``T^T f`` and
``T^T K T`` with ``T = diag(M_1, ..., M_k)``; ``dofs`` numbers a block's rows in
the ``6 n`` unknowns of the representative nodes.
"""
from dataclasses import dataclass

import numpy as np

from .._jit import jit
from ..lie.se3_twin import fma
from .buffers import REUSE_BUFFERS     # noqa: F401  (its former home; buffers.BufferPool reuses blocks' memory)

__all__ = ["Blocks", "Contribution", "transform", "transform_rows", "transform_rows_numpy", "dofs", "levels"]


@dataclass
class Blocks:
    """``nodes (m, k)``, ``f (m, 6k)``, ``K (m, 6k, 6k)`` or ``None`` (see the module docstring)."""
    nodes: np.ndarray
    f: np.ndarray
    K: np.ndarray = None
    levels_of: tuple = None     # ``((nodes, f), ...)`` whose largest nodal force and moment are the levels
                                # (blocks that sum the forces of several parts per node: their parts')

    def __post_init__(self):
        m, k = np.shape(self.nodes)
        if np.shape(self.f) != (m, 6 * k) or (self.K is not None and np.shape(self.K) != (m, 6 * k, 6 * k)):
            raise ValueError(f"Blocks: nodes {np.shape(self.nodes)} need f ({m}, {6 * k}) and K ({m}, {6 * k}, "
                             f"{6 * k}), got f {np.shape(self.f)}, K {np.shape(self.K)}")

    @staticmethod
    def empty(k, tangent=True):
        return Blocks(np.zeros((0, k), dtype=int), np.zeros((0, 6 * k)),
                      np.zeros((0, 6 * k, 6 * k)) if tangent else None)


def transform(M, nodes, f, K=None, which=None):
    """``(T^T f, T^T K T)`` for the blocks ``which`` (default all), ``T = diag(M[nodes[i]])``.

    ``M`` ``(n, 6, 6)`` node transforms; ``f``, ``K`` are copied, not changed.  Other blocks are
    returned as they are (their nodes have ``M = I``).
    """
    which = np.arange(len(nodes)) if which is None else which
    f, Kw = transform_rows(M, nodes, f, K, which)
    K = None if K is None else K.copy()
    if K is not None and len(which):
        K[which] = Kw
    return f, K


def transform_rows(M, nodes, f, K, which):
    """``transform`` without the copy of ``K``: ``f`` transformed (a copy) and the transformed blocks
    ``K[which]`` alone ``(len(which), 6 k, 6 k)`` (``None`` without ``K``).  Compiled, the bits of
    ``transform_rows_numpy`` (its sums in numpy's order: ``einsum`` left to right, ``@`` one fused
    multiply-add chain per entry, ``lie.se3_twin``)."""
    f = np.array(f, dtype=float)
    which = np.ascontiguousarray(which, dtype=np.int64)
    n, m = len(which), f.shape[1]
    Kw = np.empty((n, m, m)) if K is not None else None
    if n:
        _transform(np.ascontiguousarray(M, dtype=float), np.ascontiguousarray(nodes), which, f,
                   np.ascontiguousarray(K, dtype=float) if K is not None else np.empty((0, m, m)),
                   Kw if K is not None else np.empty((0, m, m)), K is not None)
    return f, Kw


@jit
def _transform(M, nodes, which, f, K, Kw, tangent):
    """``f[w] <- T^T f[w]`` (in place) and ``Kw[i] = (T^T K[w]) T``, ``w = which[i]``, ``T`` the block
    diagonal of ``M[nodes[w]]``: each sum in numpy's order over the six terms of ``T``'s node block (the other
    ``6 (k - 1)`` are products with ``T``'s zeros, which leave a finite sum as it is: the same bits)."""
    m = f.shape[1]
    T, A, fw = np.zeros((m, m)), np.empty((m, m)), np.empty(m)
    for i in range(len(which)):
        w = which[i]
        for j in range(nodes.shape[1]):
            Mj = M[nodes[w, j]]
            for a in range(6):
                for b in range(6):
                    T[6 * j + a, 6 * j + b] = Mj[a, b]
        for r in range(m):
            fw[r] = f[w, r]
        for r in range(m):                  # einsum("ij,j->i", T^T, f)
            q0 = r - r % 6
            acc = T[q0, r] * fw[q0]
            for c in range(q0 + 1, q0 + 6):
                acc = acc + T[c, r] * fw[c]
            f[w, r] = acc
        if not tangent:
            continue
        for r in range(m):                  # A = T^T @ K[w]
            q0 = r - r % 6
            for c in range(m):
                acc = T[q0, r] * K[w, q0, c]
                for q in range(q0 + 1, q0 + 6):
                    acc = fma(T[q, r], K[w, q, c], acc)
                A[r, c] = acc
        for r in range(m):                  # Kw[i] = A @ T
            for c in range(m):
                q0 = c - c % 6
                acc = A[r, q0] * T[q0, c]
                for q in range(q0 + 1, q0 + 6):
                    acc = fma(A[r, q], T[q, c], acc)
                Kw[i, r, c] = acc


def transform_rows_numpy(M, nodes, f, K, which):
    """``transform_rows`` in numpy (its test oracle)."""
    f = f.copy()
    if len(which) == 0:
        return f, (None if K is None else K[:0].copy())
    k = nodes.shape[1]
    T = np.zeros((len(which), 6 * k, 6 * k))
    for j in range(k):
        T[:, 6 * j:6 * j + 6, 6 * j:6 * j + 6] = M[nodes[which, j]]
    Tt = np.swapaxes(T, 1, 2)
    f[which] = np.einsum("nij,nj->ni", Tt, f[which])
    return f, (None if K is None else Tt @ K[which] @ T)


def dofs(rep, nodes):
    """Row numbers ``(m, 6 k)`` of blocks over ``nodes`` in the unknowns ``6 rep[node] + c``."""
    m, k = nodes.shape
    return ((6 * rep[nodes])[:, :, None] + np.arange(6)).reshape(m, 6 * k)


def levels(f):
    """Largest nodal force and moment ``(f_level, m_level)`` of blocks ``f`` ``(m, 6k)``: ``levels_numpy``'s maxima,
    compiled (exact: a maximum rounds nothing; nan if there is one), several calls an evaluation."""
    return _levels(np.ascontiguousarray(f, dtype=float).reshape(-1, 6))


@jit
def _levels(x):
    fl, ml = 0.0, 0.0
    for i in range(x.shape[0]):
        for c in range(3):
            v, w = abs(x[i, c]), abs(x[i, c + 3])
            if v > fl or v != v:
                fl = v
            if w > ml or w != w:
                ml = w
    return fl, ml


def levels_numpy(f):
    """``levels`` in numpy (its test oracle)."""
    fb = np.abs(f.reshape(len(f), f.shape[1] // 6, 2, 3))
    return fb[:, :, 0].max(initial=0.0), fb[:, :, 1].max(initial=0.0)


class Contribution:
    """A part of the physics that hands blocks to the generic assembler (``problem.Problem``).

    ``evaluate(H, tangent)`` returns ``(Blocks, info)``; the step life cycle defaults to
    nothing: ``begin_step(H, t)`` before a step's Newton iterations, ``repeat_step(H)`` after
    them (True: re-solve the step, e.g. an augmented-Lagrangian update), ``unmet(t)`` why the
    step may not be accepted (``None``: it may), ``commit(H)`` when the step is accepted,
    ``results(H)`` its per-step record, ``get_state()``/``set_state(state)`` the committed
    history (restart).  ``smooth``: whether the residual is smooth (else the solver backtracks
    on the residual); ``conservative``: whether it derives from a potential.
    """
    name = "contribution"
    smooth = True
    conservative = True

    def evaluate(self, H, tangent=True):
        raise NotImplementedError

    def begin_step(self, H, t):
        pass

    def repeat_step(self, H):
        return False

    def unmet(self, t):
        return None

    def commit(self, H):
        pass

    def results(self, H):
        return None

    def get_state(self):
        return {}

    def set_state(self, state):
        pass
