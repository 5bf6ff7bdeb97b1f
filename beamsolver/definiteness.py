"""Is a tangent positive definite?  Negative eigenvalues of the symmetric part, counted cheaply.

The tangent ``K`` (free x free, sparse) mixes forces and moments, so it is
first scaled symmetrically, ``A = D K D`` with ``D = |diag K|^-1/2`` (a
congruence: the signs of the eigenvalues -- Sylvester's inertia -- are
unchanged, and the spectrum becomes dimensionless).  Up to ``DENSE_MAX``
unknowns a Cholesky factorisation of ``A`` decides (it exists exactly when
``A`` is positive definite); only when it fails are the eigenvalues computed
(LAPACK).  Above, the inertia is read from a sparse LDL^T: SuperLU with
diagonal pivots only (``SymmetricMode``), whose pivots are ``D``; when some
are negative, the eigenvalues nearest zero are computed and those within
round-off of zero (``-ZERO <= lam < 0``, a neutral mode such as the turn of a
buckled round column about its axis) are not counted; should it
pivot off the diagonal, the ``k`` eigenvalues nearest zero by a shifted
Lanczos (``eigsh``) give a lower bound of the count instead.
"""
import numpy as np
import scipy.sparse as sp

__all__ = ["negative_eigenvalues", "DENSE_MAX", "SHIFT"]

DENSE_MAX = 600          # unknowns up to which the dense factorisations are used
SHIFT = 1e-6             # Lanczos shift (scaled units) below zero: K itself may be singular
ZERO = 1e-13            # scaled eigenvalues above -ZERO count as non-negative (round-off); the
                        # buckling eigenvalue of a slender beam (EA L^2 / EI = 1e8, 32 elements) is -7e-11


def _scaled_symmetric(K):
    K = sp.csr_matrix(K)
    K = 0.5 * (K + K.T)
    d = np.abs(K.diagonal())
    d[d == 0.0] = 1.0
    D = sp.diags(1.0 / np.sqrt(d))
    return (D @ K @ D).tocsc()


def _round_off_discounted(A, neg, k):
    """``(count, lowest)`` from an inertia count ``neg`` > 0: the eigenvalues nearest zero that lie
    in ``[-ZERO, 0)`` are round-off (a neutral mode), not instability, and are not counted."""
    from scipy.sparse.linalg import eigsh
    n = A.shape[0]
    lam = eigsh(A, k=min(max(k, neg + 1), n - 2), sigma=-SHIFT, which="LM", return_eigenvectors=False)
    return neg - int(np.sum((lam >= -ZERO) & (lam < 0.0))), float(lam.min())


def negative_eigenvalues(K, k=6):
    """``(count, lowest)``: the number of negative eigenvalues of the symmetric part of ``K`` and
    the lowest eigenvalue of the scaled ``D K D`` (``None`` where it was not needed: positive
    definite, or read from a factorisation)."""
    n = K.shape[0]
    if n == 0:
        return 0, None
    A = _scaled_symmetric(K)
    if n <= DENSE_MAX:
        Ad = A.toarray()
        try:
            np.linalg.cholesky(Ad)
            return 0, None
        except np.linalg.LinAlgError:
            lam = np.linalg.eigvalsh(Ad)
            return int(np.sum(lam < -ZERO)), float(lam.min())
    from scipy.sparse.linalg import eigsh, splu
    try:
        lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        if np.array_equal(lu.perm_r, lu.perm_c):
            neg = int(np.sum(lu.U.diagonal() < 0.0))
            return (0, None) if neg == 0 else _round_off_discounted(A, neg, k)
    except RuntimeError:        # an exactly zero pivot: decide by the eigenvalues
        pass
    lam = eigsh(A, k=min(k, n - 2), sigma=-SHIFT, which="LM", return_eigenvectors=False)
    return int(np.sum(lam < -ZERO)), float(lam.min())
