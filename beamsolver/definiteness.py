"""Is a tangent positive definite?  Negative eigenvalues of the symmetric part, counted cheaply.

The tangent ``K`` (free x free, sparse) mixes forces and moments, so it is
first scaled symmetrically, ``D K D`` with ``D = |diag K|^-1/2`` (a congruence:
the signs of the eigenvalues -- Sylvester's inertia -- are unchanged, and the
spectrum becomes dimensionless).  Up to ``DENSE_MAX`` unknowns all eigenvalues
are computed (LAPACK); above, the ``k`` eigenvalues nearest zero by a shifted
Lanczos (``scipy.sparse.linalg.eigsh``, shift-invert about ``-SHIFT``): a lower
bound of the count, exact while fewer than ``k`` eigenvalues have crossed zero,
which is what a path following test needs.
"""
import numpy as np
import scipy.sparse as sp

__all__ = ["negative_eigenvalues", "DENSE_MAX", "SHIFT"]

DENSE_MAX = 600          # unknowns up to which all eigenvalues are computed
SHIFT = 1e-6             # Lanczos shift (scaled units) below zero: K itself may be singular
ZERO = 1e-10             # scaled eigenvalues above -ZERO count as non-negative (round-off)


def _scaled_symmetric(K):
    K = sp.csr_matrix(K)
    K = 0.5 * (K + K.T)
    d = np.abs(K.diagonal())
    d[d == 0.0] = 1.0
    D = sp.diags(1.0 / np.sqrt(d))
    return (D @ K @ D).tocsc()


def negative_eigenvalues(K, k=6):
    """``(count, lowest)``: number of negative eigenvalues of the symmetric part of ``K`` (all of
    them up to ``DENSE_MAX`` unknowns, else among the ``k`` nearest zero) and the lowest one
    found, both of the Jacobi-scaled matrix ``D K D``."""
    n = K.shape[0]
    if n == 0:
        return 0, np.inf
    A = _scaled_symmetric(K)
    if n <= DENSE_MAX:
        lam = np.linalg.eigvalsh(A.toarray())
    else:
        from scipy.sparse.linalg import eigsh
        lam = eigsh(A, k=min(k, n - 2), sigma=-SHIFT, which="LM", return_eigenvectors=False)
    return int(np.sum(lam < -ZERO)), float(lam.min())
