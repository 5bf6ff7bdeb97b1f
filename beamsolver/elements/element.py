"""The two-node SE(3) beam element (Sonneville, Cardona & Bruls 2014), batched.

For an element with nodal poses ``H_A, H_B`` and reference length ``L``
(docs/theory.md eqs. 3.1-3.7):

- ``h = log(H_A^-1 H_B)``, strain ``eps = h / L`` (``Gamma`` then ``kappa``,
  section frame), section forces ``sigma = C (eps - eps0)``;
- energy ``V = L/2 (eps - eps0)^T C (eps - eps0)``;
- body-frame nodal forces ``f_A = -T(-h)^-T sigma``, ``f_B = T(h)^-T sigma``;
- tangent ``K = B^T (C/L) B + [G(-h, sigma); G(h, sigma)] B`` with
  ``B = [-T(-h)^-1, T(h)^-1]`` and ``G(h, s) = d(T(h)^-T s)/dh`` in closed
  form (``geometric``, checked against finite differences in the element tests).

All public functions take arrays batched over elements: poses ``(n, 4, 4)``,
``L`` ``(n,)``, ``eps0`` ``(n, 6)``, ``C`` ``(n, 6, 6)``.  They return forces and
states with the element axis first and the tangent ``(n, 12, 12)``.  They run
the compiled kernels of ``element_jit`` (numba; one element per call, a batch
loop, tangent stored element-major, the order ``assembly.System`` scatters).
The batched numpy version, the test oracle, is ``reference``.
"""
from typing import NamedTuple

import numpy as np

from .geometric import geometric

__all__ = ["ElementState", "element_state", "reference_strain", "energy",
           "internal_forces", "internal_forces_and_tangent", "evaluate", "evaluate_nodes", "is_diagonal", "geometric"]


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


_OFF_DIAGONAL = ~np.eye(6, dtype=bool)


def is_diagonal(C):
    """True if every ``C`` ``(n, 6, 6)`` is diagonal."""
    return not np.any(C[:, _OFF_DIAGONAL])


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
    (``element_jit``); ``reference.internal_forces_and_tangent_numpy`` is the
    numpy version, the test oracle.
    """
    return evaluate(H_A, H_B, L, eps0, C, tangent=True, out=out)
