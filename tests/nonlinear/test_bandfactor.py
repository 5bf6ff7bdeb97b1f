"""Banded factorisations of the scaled tangent (``bandfactor``) and the definiteness and modes
that use them: the same answers as dense LAPACK, on matrices banded once reordered and on wide ones."""
import numpy as np
import pytest
import scipy.sparse as sp

from beamsolver.nonlinear import bandfactor
from beamsolver.nonlinear.definiteness import DENSE_MAX, negative_eigenvalues, scaled_symmetric
from beamsolver.nonlinear.modes import lowest_modes


def shuffled_band(rng, n, b, shift):
    """A symmetric matrix of half-bandwidth ``b`` minus ``shift I``, its unknowns shuffled (so only
    a reordering finds the band again)."""
    A = sp.random(n, n, density=1.0, random_state=rng, format="csr")
    A = sp.triu(sp.tril(A, b), -b)
    A = (A + A.T + sp.diags(np.full(n, 2.0 * b + 1.0))).tocsr()      # diagonally dominant: SPD
    A = A - shift * sp.identity(n)
    p = rng.permutation(n)
    return sp.csr_matrix(A[p][:, p])


@pytest.mark.parametrize("shift", [0.0, 0.9, 1.1, 6.0])
def test_banded_cholesky_decides_definiteness_as_the_eigenvalues_do(rng, shift):
    """A shift moving the lowest eigenvalue of a shuffled band matrix across zero flips the verdict."""
    A = shuffled_band(rng, 300, 4, 0.0)
    lowest = np.linalg.eigvalsh(A.toarray())[0]
    B = A - shift * lowest * sp.identity(300)
    banded = bandfactor.band(B)
    assert banded is not None and banded[1] <= 12         # reordered: the band found again
    assert bandfactor.positive_definite(banded) == (shift < 1.0)


@pytest.mark.parametrize("wide", [False, True])
def test_shifted_inverse_solves_the_shifted_system(rng, wide):
    """Banded LU after the reordering, or SuperLU for a matrix with no narrow band: the residual of
    ``(A - sigma I) x = y`` at round-off, for an indefinite shifted matrix."""
    A = shuffled_band(rng, 400, 3, 4.0)
    if wide:
        A = sp.csr_matrix(A + sp.random(400, 400, density=0.05, random_state=rng) * 1e-3)
        A = sp.csr_matrix(A + A.T)
    assert (bandfactor.band(A) is None) == wide
    sigma = -1e-3
    x = bandfactor.shifted_inverse(A, sigma) @ (y := rng.standard_normal(400))
    residual = (A - sigma * sp.identity(400)) @ x - y
    assert np.abs(residual).max() < 1e-10 * np.abs(y).max()


@pytest.mark.parametrize("pattern", ["unsymmetric", "symmetric"])
def test_scaled_symmetric_dense_and_sparse_agree(rng, pattern):
    """Against ``D (K + K^T) / 2 D``; a structurally symmetric ``K`` (unsymmetric values) takes the
    path without a sparse sum."""
    K = sp.random(50, 50, density=0.2, random_state=rng, format="csc") + sp.diags(rng.uniform(-5, 5, 50))
    if pattern == "symmetric":
        K = sp.csc_matrix(K + 2.0 * K.T)
    Ad, d = scaled_symmetric(K, dense=True)
    As, d2 = scaled_symmetric(K)
    Kd = K.toarray()
    ref = np.diag(d) @ (0.5 * (Kd + Kd.T)) @ np.diag(d)
    np.testing.assert_allclose(Ad, ref, atol=1e-14)
    np.testing.assert_allclose(As.toarray(), ref, atol=1e-14)
    np.testing.assert_allclose(np.abs(np.diag(ref)), 1.0)


@pytest.mark.parametrize("negative", [0, 3])
def test_negative_eigenvalues_above_dense_max_match_the_dense_count(rng, negative):
    """Above ``DENSE_MAX`` (banded Cholesky, then the LDL^T inertia) the count is that of the dense
    spectrum, with diagonal scales over four decades; ``lowest`` is a negative eigenvalue of it (the
    lowest of those nearest zero, not necessarily the lowest of all)."""
    n = DENSE_MAX + 100
    A = shuffled_band(rng, n, 5, 0.0)
    lam = np.linalg.eigvalsh(A.toarray())
    A = A - 0.5 * (lam[negative] + lam[max(negative - 1, 0)]) * sp.identity(n) if negative else A
    S = sp.diags(10.0 ** rng.uniform(0, 4, n))
    count, lowest = negative_eigenvalues((S @ A @ S).tocsc())
    assert count == negative
    if negative:
        Ad, _ = scaled_symmetric((S @ A @ S).tocsc(), dense=True)
        spectrum = np.linalg.eigvalsh(Ad)
        assert lowest < 0 and np.abs(spectrum - lowest).min() < 1e-10
    else:
        assert lowest is None


def test_lowest_modes_above_dense_max_on_a_shuffled_band(rng):
    """The banded shift-invert Lanczos gives the dense eigenpairs of the scaled matrix nearest zero."""
    n = DENSE_MAX + 50
    A = shuffled_band(rng, n, 4, 0.0)
    lam = np.linalg.eigvalsh(A.toarray())
    A = sp.csc_matrix(A - (lam[0] + 1e-3) * sp.identity(n))                # one small negative
    got, phi = lowest_modes(A, 3)
    Ad, d = scaled_symmetric(A, dense=True)
    ref, Y = np.linalg.eigh(Ad)
    np.testing.assert_allclose(got, ref[:3], rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum((phi / d[:, None]) * Y[:, :3], axis=0)), 1.0, atol=1e-8)


@pytest.mark.parametrize("shift", [0.0, 0.9, 1.1, 6.0])
def test_compiled_cholesky_of_the_symmetric_sum_is_the_eigenvalues_verdict(rng, shift):
    """``sum_positive_definite`` on the CSC entries of an unsymmetric band matrix ``K`` (natural
    order, half-bandwidth 5) decides as the eigenvalues of ``K + K^T`` do, and leaves its factor."""
    n, b = 200, 5
    K = sp.random(n, n, density=1.0, random_state=rng, format="csr")
    K = sp.csc_matrix(sp.triu(sp.tril(K, b), -b) + sp.diags(np.full(n, b + 1.0)))
    K.sort_indices()
    S = (K + K.T).toarray()
    K = sp.csc_matrix(K - 0.5 * shift * np.linalg.eigvalsh(S)[0] * sp.identity(n))
    K.sort_indices()
    S = (K + K.T).toarray()
    rows = K.indices.astype(np.int64)
    cols = np.repeat(np.arange(n), np.diff(K.indptr))
    where = {(r, c): p for p, (r, c) in enumerate(zip(rows, cols))}
    up = np.flatnonzero(rows <= cols)
    partner = np.array([where[cols[p], rows[p]] for p in up])
    ab = np.empty((n, b + 1))
    verdict = bandfactor.sum_positive_definite(K.data, up, partner, rows[up], cols[up] - rows[up], ab)
    assert verdict == (np.linalg.eigvalsh(S)[0] > 0) == (shift < 1.0)
    if verdict:
        L = np.zeros((n, n))
        for j in range(n):
            m = min(b, n - 1 - j)
            L[j + np.arange(m + 1), j] = ab[j, :m + 1]
        np.testing.assert_allclose(L @ L.T, S, atol=1e-12 * np.abs(S).max())
