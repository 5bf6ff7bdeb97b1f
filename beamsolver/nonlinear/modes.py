"""The lowest eigenpairs of a tangent: critical modes of an equilibrium.

The tangent ``K`` (free x free) mixes forces and moments; as in
``definiteness``, its symmetric part is scaled, ``A = D (K + K^T)/2 D`` with
``D = |diag K|^-1/2``.  An eigenpair ``A y = lam y`` is a pair of the pencil

    K_s phi = lam |diag K_s| phi,     phi = D y,

with a dimensionless ``lam`` (the same number ``solve(check_stability=True)``
records as ``lowest_eigenvalue``) and ``phi`` a direction of the solver's
unknowns; ``lam`` crosses zero exactly where ``K`` becomes singular, and
``phi`` is then the null vector (the buckling mode).  Up to
``definiteness.DENSE_MAX`` unknowns LAPACK gives the exact lowest pairs;
above, a shifted Lanczos (``eigsh``, shift ``-definiteness.SHIFT``) gives the
pairs *nearest zero*, which are the lowest ones when the negative eigenvalues
are few and small (near a crossing, where modes are wanted); its shifted
solves use a banded LU where the tangent is banded (``bandfactor``).
"""
import numpy as np

from .definiteness import DENSE_MAX, nearest_zero, scaled_symmetric

__all__ = ["lowest_modes"]


def lowest_modes(K, k):
    """``(lam, phi)``: the ``k`` lowest eigenvalues ``(k,)`` (ascending, dimensionless) of the scaled
    pencil above and their directions ``phi`` ``(n, k)`` in the unknowns of ``K`` (columns
    D-orthonormal: ``y = phi / D`` has unit norm).  ``k`` is cut to the size of ``K``."""
    n = K.shape[0]
    k = int(min(k, n))
    if k <= 0:
        return np.zeros(0), np.zeros((n, 0))
    if n <= DENSE_MAX or k >= n - 1:
        from scipy.linalg import eigh
        A, d = scaled_symmetric(K, dense=True)
        lam, Y = eigh(A, subset_by_index=(0, k - 1), driver="evr")
    else:
        A, d = scaled_symmetric(K)
        lam, Y = nearest_zero(A, k, vectors=True)
        order = np.argsort(lam)
        lam, Y = lam[order], Y[:, order]
    return lam, d[:, None] * Y
