"""Banded factorisations of a sparse symmetric matrix: definiteness and shifted solves, cheaply.

A tangent of beams is banded once its unknowns are ordered along the beams: the
reverse Cuthill-McKee ordering (``scipy.sparse.csgraph``) finds such an order,
``P = A[p][:, p]`` with half-bandwidth ``b``.  Up to ``BAND_MAX`` LAPACK's banded
factorisations then cost ``O(n b^2)`` and a solve ``O(n b)``, with none of a
general sparse factorisation's bookkeeping:

- ``positive_definite(band)``: banded Cholesky (``dpbtrf``), which exists exactly
  when ``A`` is positive definite (as the dense Cholesky of ``definiteness``);
- ``sum_positive_definite(...)``: the same question for ``K + K^T`` gathered straight from the
  entries of a CSC ``K`` into row-wise band storage and factorised in one compiled loop
  (``definiteness.Inertia``: twice as fast as the gather, the scatter and ``dpbtrf`` for a beam);
- ``shifted_inverse(A, sigma)``: ``x = (A - sigma I)^-1 y`` as a ``LinearOperator``
  for the shift-invert Lanczos of ``eigsh`` (``OPinv``): banded LU with partial
  pivoting (``dgbtrf``/``dgbtrs``) when banded, else SuperLU as ``eigsh`` itself
  would use; the eigenpairs are those of ``eigsh``'s own shift-invert.

Wider bands (contact between many beams, joins across a structure) return
``None`` from ``band`` and the callers keep their general sparse paths.
"""
import numpy as np
import scipy.sparse as sp

from .._jit import jit

__all__ = ["BAND_MAX", "band", "positive_definite", "sum_positive_definite", "shifted_inverse"]

BAND_MAX = 64            # largest half-bandwidth (after reordering) for the banded factorisations


def band(A):
    """``(perm, b, rows, cols, values)`` of the symmetric ``A`` (n, n) reordered by reverse
    Cuthill-McKee (``P[i, j] = A[perm[i], perm[j]]`` at ``(rows, cols)``, duplicates summed) with
    half-bandwidth ``b``, or ``None`` when ``b > BAND_MAX``."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    A = sp.csr_matrix(A)
    A.sum_duplicates()
    perm = reverse_cuthill_mckee(A, symmetric_mode=True)
    where = np.empty_like(perm)
    where[perm] = np.arange(len(perm))
    C = A.tocoo()
    rows, cols = where[C.row], where[C.col]
    b = int(np.abs(rows - cols).max()) if C.nnz else 0
    return None if b > BAND_MAX else (perm, b, rows, cols, C.data)


def positive_definite(banded):
    """True when the matrix of ``band(A)`` is positive definite (banded Cholesky succeeds)."""
    from scipy.linalg.lapack import dpbtrf
    perm, b, rows, cols, values = banded
    up = rows <= cols
    ab = np.zeros((b + 1, len(perm)))
    ab[b + rows[up] - cols[up], cols[up]] = values[up]
    _, info = dpbtrf(ab, lower=0, overwrite_ab=1)
    return info == 0


@jit
def sum_positive_definite(data, up, partner, rows, offsets, ab):
    """Whether ``S = K + K^T`` is positive definite: its Cholesky factorisation in place in ``ab``
    ``(n, b + 1)``, row ``j`` holding ``S[j, j + k]`` at ``k`` (zeroed first), filled from the CSC
    values ``data`` of ``K``: the entry at position ``up[i]`` (row ``rows[i]``, ``offsets[i]`` to the
    right of the diagonal) plus its transpose at ``partner[i]``.  A pivot that is not positive (or
    NaN) stops it: ``False``."""
    n, w = ab.shape
    ab[:, :] = 0.0
    for i in range(len(up)):
        ab[rows[i], offsets[i]] = data[up[i]] + data[partner[i]]
    for j in range(n):
        d = ab[j, 0]
        if not d > 0.0:
            return False
        s = np.sqrt(d)
        ab[j, 0] = s
        m = min(w - 1, n - 1 - j)
        for k in range(1, m + 1):
            ab[j, k] /= s
        for k in range(1, m + 1):
            v = ab[j, k]
            if v != 0.0:
                row = j + k
                for col in range(k, m + 1):
                    ab[row, col - k] -= v * ab[j, col]
    return True


def shifted_inverse(A, sigma, banded=None):
    """``LinearOperator`` applying ``(A - sigma I)^-1`` (``A`` symmetric sparse (n, n)); ``banded``:
    ``band(A)`` if already computed.  Raises ``RuntimeError`` when ``A - sigma I`` is exactly singular
    (as SuperLU does)."""
    from scipy.sparse.linalg import LinearOperator, splu
    n = A.shape[0]
    banded = band(A) if banded is None else banded
    if banded is None:
        lu = splu(sp.csc_matrix(A - sigma * sp.identity(n, format="csc")))
        return LinearOperator((n, n), matvec=lu.solve, dtype=float)
    from scipy.linalg.lapack import dgbtrf, dgbtrs
    perm, b, rows, cols, values = banded
    ab = np.zeros((3 * b + 1, n))
    ab[2 * b + rows - cols, cols] = values
    ab[2 * b] -= sigma
    lu, ipiv, info = dgbtrf(ab, b, b, overwrite_ab=1)
    if info > 0:
        raise RuntimeError(f"shifted_inverse: A - sigma I is exactly singular (pivot {info})")

    def solve(y):
        z, _ = dgbtrs(lu, b, b, np.asarray(y, dtype=float).reshape(n, -1)[perm], ipiv)
        x = np.empty_like(z)
        x[perm] = z
        return x.reshape(np.shape(y))

    return LinearOperator((n, n), matvec=solve, dtype=float)
