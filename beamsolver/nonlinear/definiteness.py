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
Lanczos (``eigsh``) give a lower bound of the count instead.  Before all that,
a tangent that is banded once reordered (``bandfactor``: beams) and positive
definite is recognised by a banded Cholesky, and the shifted Lanczos solves
with a banded LU: the same answers, several times cheaper.

``Inertia`` answers the same question for the tangents of one solve, one per
converged step (``stepping.stability``): their sparsity pattern rarely changes,
so the band layout (ordering, the place of every entry and of its transpose in
LAPACK's band storage) is kept for the pattern, and the common case -- positive
definite -- costs a few array operations and a banded Cholesky; any other case
is ``negative_eigenvalues``.
"""
import numpy as np
import scipy.sparse as sp

from .bandfactor import BAND_MAX, band, positive_definite, shifted_inverse, sum_positive_definite

__all__ = ["negative_eigenvalues", "scaled_symmetric", "nearest_zero", "Inertia", "DENSE_MAX", "SHIFT"]

DENSE_MAX = 600          # unknowns up to which the dense factorisations are used
SHIFT = 1e-6             # Lanczos shift (scaled units) below zero: K itself may be singular
ZERO = 1e-13            # scaled eigenvalues above -ZERO count as non-negative (round-off); the
                        # buckling eigenvalue of a slender beam (EA L^2 / EI = 1e8, 32 elements) is -7e-11


def scaled_symmetric(K, dense=False):
    """``(A, d)``: ``A = D (K + K^T) / 2 D``, ``D = diag(d)``, ``d = |diag K|^-1/2`` (1 where the
    diagonal is 0); ``A`` a dense array with ``dense``, else sparse CSR (``K``: (n, n), sparse)."""
    if dense:
        Kd = K.toarray() if sp.issparse(K) else np.asarray(K, dtype=float)
        S = 0.5 * (Kd + Kd.T)
        d = _inverse_root(np.diag(S))
        return S * d[:, None] * d[None, :], d
    S = _symmetric_part(K)
    d = _inverse_root(S.diagonal())
    rows = np.repeat(np.arange(S.shape[0]), np.diff(S.indptr))
    S.data *= d[rows] * d[S.indices]
    return S, d


def _symmetric_part(K):
    """``(K + K^T) / 2`` as CSR.  A structurally symmetric ``K`` (a beam tangent) needs no sparse
    sum: its CSC and CSR forms then have the same index arrays, and the CSR data read as CSC is
    ``K^T``'s."""
    C = sp.csc_matrix(K, copy=True)
    C.sum_duplicates()
    R = C.tocsr()
    if np.array_equal(C.indptr, R.indptr) and np.array_equal(C.indices, R.indices):
        S = sp.csr_matrix((0.5 * (C.data + R.data), R.indices, R.indptr), shape=C.shape)
        S.eliminate_zeros()          # as the sparse sum does: a narrower band for ``bandfactor``
        return S
    S = sp.csr_matrix(0.5 * (R + R.T))
    S.sum_duplicates()
    return S


def _inverse_root(diagonal):
    d = np.abs(diagonal)
    d[d == 0.0] = 1.0
    return 1.0 / np.sqrt(d)


def nearest_zero(A, k, banded=None, vectors=False):
    """The ``k`` eigenvalues (and, with ``vectors``, eigenvectors) of the sparse symmetric ``A``
    nearest ``-SHIFT``: Lanczos in shift-invert mode (``eigsh``), the shifted solves by
    ``bandfactor.shifted_inverse`` (``banded``: ``band(A)`` if known)."""
    from scipy.sparse.linalg import eigsh
    return eigsh(A, k=k, sigma=-SHIFT, which="LM", return_eigenvectors=vectors,
                 OPinv=shifted_inverse(A, -SHIFT, banded))


def _round_off_discounted(A, neg, k):
    """``(count, lowest)`` from an inertia count ``neg`` > 0: the eigenvalues nearest zero that lie
    in ``[-ZERO, 0)`` are round-off (a neutral mode), not instability, and are not counted."""
    n = A.shape[0]
    lam = nearest_zero(A, min(max(k, neg + 1), n - 2))
    return neg - int(np.sum((lam >= -ZERO) & (lam < 0.0))), float(lam.min())


def negative_eigenvalues(K, k=6):
    """``(count, lowest)``: the number of negative eigenvalues of the symmetric part of ``K`` and
    the lowest eigenvalue of the scaled ``D K D`` (``None`` where it was not needed: positive
    definite, or read from a factorisation)."""
    n = K.shape[0]
    if n == 0:
        return 0, None
    if n <= DENSE_MAX:
        Ad, _ = scaled_symmetric(K, dense=True)
        try:
            np.linalg.cholesky(Ad)
            return 0, None
        except np.linalg.LinAlgError:
            lam = np.linalg.eigvalsh(Ad)
            return int(np.sum(lam < -ZERO)), float(lam.min())
    A, _ = scaled_symmetric(K)
    banded = band(A)
    if banded is not None and positive_definite(banded):
        return 0, None
    from scipy.sparse.linalg import splu
    A = A.tocsc()
    try:
        lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        if np.array_equal(lu.perm_r, lu.perm_c):
            neg = int(np.sum(lu.U.diagonal() < 0.0))
            return (0, None) if neg == 0 else _round_off_discounted(A, neg, k)
    except RuntimeError:        # an exactly zero pivot: decide by the eigenvalues
        pass
    lam = nearest_zero(A, min(k, n - 2))
    return int(np.sum(lam < -ZERO)), float(lam.min())


class Inertia:
    """``negative_eigenvalues`` of a sequence of tangents, the positive definite ones decided cheaply.

    ``inertia(K)`` returns what ``negative_eigenvalues(K)`` returns.  For the pattern of ``K``
    (CSC, canonical: sorted unique rows) a layout is built once and kept while the pattern
    stays (also across instances: the last one, as a solve after a solve of the same model meets
    it): the position of each entry's transpose in ``K.data`` and, when the pattern has a
    half-bandwidth up to ``BAND_MAX`` as numbered (beams: nodes along the beam) or after a
    reverse Cuthill-McKee ordering, the place of each entry on or above the diagonal in a
    row-wise band.  ``K + K^T`` is then factorised: banded Cholesky
    (``bandfactor.sum_positive_definite``), or else SuperLU with diagonal pivots
    (``SymmetricMode``, an LDL^T: all pivots positive means positive definite, Sylvester).
    Neither pivots, so neither needs the scaling ``D`` of ``scaled_symmetric``: factorising
    ``D A D`` is factorising ``A`` with its pivots scaled by ``d_i^2``, to round-off.  Positive
    definite: ``(0, None)``.  Anything else (a failed factorisation, a pattern not structurally
    symmetric) is ``negative_eigenvalues(K)``.  ``layouts`` counts the layouts built.
    """

    def __init__(self):
        self._layout = None
        self._work = None         # the band buffer of the banded factorisation
        self.layouts = 0

    def __call__(self, K, k=6):
        K = K if sp.issparse(K) and K.format == "csc" and K.has_canonical_format else _canonical(K)
        layout = self._layout_of(K)
        if layout is not None and self._positive_definite(K, layout):
            return 0, None
        return negative_eigenvalues(K, k)

    def _layout_of(self, K):
        kept = self._layout if self._layout is not None else (_LAST[0] if _LAST else None)
        if kept is None or not _same_pattern(kept[0], K):
            kept = ((K.indptr.copy(), K.indices.copy()), _layout(K))
            self.layouts += 1
            _LAST[:] = [kept]
        self._layout = kept
        return kept[1]

    def _positive_definite(self, K, layout):
        """Whether ``K + K^T`` is positive definite, by the factorisation of ``layout``."""
        if layout[0] == "band":
            _, shape, up, partner, rows, offsets = layout
            if self._work is None or self._work.shape != shape:
                self._work = np.empty(shape)
            return bool(sum_positive_definite(K.data, up, partner, rows, offsets, self._work))
        from scipy.sparse.linalg import splu
        A = sp.csc_matrix((K.data + K.data[layout[1]], K.indices, K.indptr), shape=K.shape)
        try:
            lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        except RuntimeError:        # an exactly zero pivot
            return False
        return bool(np.array_equal(lu.perm_r, lu.perm_c) and np.all(lu.U.diagonal() > 0.0))


_LAST = []      # [((indptr, indices), layout)] of the last pattern an ``Inertia`` met


def _same_pattern(pattern, K):
    return pattern[0] is K.indptr and pattern[1] is K.indices or \
        np.array_equal(pattern[0], K.indptr) and np.array_equal(pattern[1], K.indices)


def _canonical(K):
    K = sp.csc_matrix(K, copy=True)
    K.sum_duplicates()
    return K


def _layout(K):
    """The layout ``Inertia`` keeps for the pattern of the canonical CSC ``K``: ``("band", band
    shape (n, b + 1), upper positions, their partners, their rows and offsets in the band)`` or
    ``("lu", partners)``; ``None`` for a pattern that is not structurally symmetric."""
    n = K.shape[0]
    if n == 0 or K.nnz == 0:
        return None
    # K's CSR arrays are K^T's CSC arrays: equal to K's for a structurally symmetric pattern, and
    # then the CSR form of the positions 0..nnz-1 gives each entry's transpose
    T = sp.csc_matrix((np.arange(K.nnz, dtype=np.float64), K.indices, K.indptr), shape=K.shape).tocsr()
    if not (np.array_equal(T.indptr, K.indptr) and np.array_equal(T.indices, K.indices)):
        return None
    partner = T.data.astype(np.int64)
    rows = K.indices.astype(np.int64)
    cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(K.indptr))
    pr, pc = rows, cols
    if np.abs(rows - cols).max() > BAND_MAX:
        from scipy.sparse.csgraph import reverse_cuthill_mckee
        perm = reverse_cuthill_mckee(sp.csr_matrix(K.T), symmetric_mode=True)
        where = np.empty(n, dtype=np.int64)
        where[perm] = np.arange(n)
        pr, pc = where[rows], where[cols]
    b = int(np.abs(pr - pc).max())
    if b > BAND_MAX:
        return "lu", partner
    up = np.flatnonzero(pr <= pc)
    return "band", (n, b + 1), up, partner[up], pr[up], pc[up] - pr[up]
