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

from .buffers import REUSE_BUFFERS     # noqa: F401  (its former home; buffers.BufferPool reuses blocks' memory)

__all__ = ["Blocks", "Contribution", "transform", "transform_rows", "dofs", "levels"]


@dataclass
class Blocks:
    """``nodes (m, k)``, ``f (m, 6k)``, ``K (m, 6k, 6k)`` or ``None`` (see the module docstring)."""
    nodes: np.ndarray
    f: np.ndarray
    K: np.ndarray = None

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
    ``K[which]`` alone ``(len(which), 6 k, 6 k)`` (``None`` without ``K``)."""
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
    """Largest nodal force and moment ``(f_level, m_level)`` of blocks ``f`` ``(m, 6k)``."""
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
