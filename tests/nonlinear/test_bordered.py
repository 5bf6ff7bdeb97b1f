"""``nonlinear.bordered.Bordered`` (the bordered Newton matrix of exact stick straight into CSC, its pattern kept)
against its scipy oracle ``bordered.bmat`` (COO/CSC constructors and ``sp.bmat``)."""
import numpy as np
import scipy.sparse as sp

from beamsolver.nonlinear import bordered


def _case(rng, nf=40, g=6, k6=24, idle_group=None):
    K = sp.random(nf, nf, density=0.15, random_state=rng, format="csc") + sp.eye(nf, format="csc")
    K = sp.csc_matrix(K)
    K.sort_indices()
    rows = rng.integers(-1, nf, (g, k6))          # held slots (-1) and repeated rows (padded members, joins)
    rows[:, 1] = rows[:, 0]
    Kql, Klq = rng.standard_normal((g, k6, 3)), rng.standard_normal((g, 3, k6))
    Kll = rng.standard_normal((g, 3, 3))
    if idle_group is not None:                    # a group whose first direction no free unknown moves
        rows[idle_group] = -1
        Kll[idle_group, 0] = 0.0
    R = np.linalg.qr(rng.standard_normal((g, 3, 3)))[0]
    return K, rows, Kql, Klq, Kll, R, rng.standard_normal((g, 3)), rng.standard_normal((g, 3))


def _same(A, rc, B, rc0):
    assert A.shape == B.shape and np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices)
    np.testing.assert_allclose(A.data, B.data, rtol=1e-14, atol=1e-14 * np.abs(B.data).max())
    np.testing.assert_allclose(rc, rc0, rtol=1e-14, atol=0)


def test_the_bordered_matrix_is_the_bmat_of_its_blocks():
    rng = np.random.default_rng(0)
    for idle in (None, 2):
        args = _case(rng, idle_group=idle)
        A, rc = bordered.Bordered().matrix(*args)
        B, rc0 = bordered.bmat(*args)
        _same(A, rc, B, rc0)
        if idle is not None:             # the idle row holds the traction's component: R[g, 0] . Lam[g]
            assert rc[3 * idle] == -args[5][idle, 0] @ args[6][idle] and rc0[3 * idle] == rc[3 * idle]


def test_the_pattern_is_kept_while_the_blocks_pattern_holds_and_rebuilt_when_it_changes():
    rng = np.random.default_rng(1)
    K, rows, *rest = _case(rng)
    b = bordered.Bordered()
    for k in range(3):                   # new values, same patterns
        vals = [rng.standard_normal(np.shape(a)) for a in rest]
        K = sp.csc_matrix((rng.standard_normal(K.nnz), K.indices, K.indptr), shape=K.shape)
        _same(*b.matrix(K, rows, *vals), *bordered.bmat(K, rows, *vals))
    assert b.builds == 1
    rows = rows.copy()
    rows[0, 5] = -1 if rows[0, 5] >= 0 else 3          # a slot held or freed: a new pattern
    _same(*b.matrix(K, rows, *vals), *bordered.bmat(K, rows, *vals))
    K2 = sp.csc_matrix(K + sp.eye(K.shape[0], k=5, format="csc"))
    _same(*b.matrix(K2, rows, *vals), *bordered.bmat(K2, rows, *vals))
    assert b.builds == 3


def test_one_component_groups_are_the_bmat_of_their_blocks():
    """The kept components of ``condense`` border the tangent one row each (``c`` = 1), idle rows included."""
    rng = np.random.default_rng(2)
    K, rows, Kql, Klq, Kll, R, Lam, C = _case(rng, g=7)
    rows[3] = -1                                  # no free unknown moves unit 3, and its diagonal is zero
    args = (K, rows, Kql[:, :, :1], Klq[:, :1], np.abs(Kll[:, :1, :1]), np.ones((7, 1, 1)), Lam[:, :1], C[:, :1])
    args[4][3] = 0.0
    A, rc = bordered.Bordered().matrix(*args)
    B, rc0 = bordered.bmat(*args)
    _same(A, rc, B, rc0)
    assert A.shape[0] == K.shape[0] + 7 and rc[3] == -Lam[3, 0]


def test_the_compiled_passes_are_numpy_s_bit_for_bit():
    """``Bordered.matrix`` (pattern and values by the compiled passes ``_border_counts``, ``_border_fill``,
    ``_border_values``) gives the bits of its numpy oracle ``merged`` (``np.unique``, ``np.bincount``): every
    component or one (``c`` = 1), an idle group, held slots and repeated rows, columns without border entries, a
    group without free slots, and again on the kept pattern with new values."""
    rng = np.random.default_rng(4)
    for c, idle, g in ((3, None, 6), (3, 1, 6), (1, None, 7), (3, None, 1), (1, None, 40)):
        K, rows, Kql, Klq, Kll, R, Lam, C = _case(rng, g=g, idle_group=idle)
        if c == 1:
            Kql, Klq, Kll, R, Lam, C = Kql[:, :, :1], Klq[:, :1], Kll[:, :1, :1], R[:, :1, :1], Lam[:, :1], C[:, :1]
        b = bordered.Bordered()
        for _ in range(2):
            A, rc = b.matrix(K, rows, Kql, Klq, Kll, R, Lam, C)
            B, rc0 = bordered.merged(K, rows, Kql, Klq, Kll, R, Lam, C)
            assert np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices)
            assert A.indices.dtype == A.indptr.dtype == np.int32
            assert np.array_equal(A.data, B.data) and np.array_equal(rc, rc0)
            _same(A, rc, *bordered.bmat(K, rows, Kql, Klq, Kll, R, Lam, C))
            Kql, Klq, Kll = (rng.standard_normal(np.shape(x)) for x in (Kql, Klq, Kll))
            K = sp.csc_matrix((rng.standard_normal(K.nnz), K.indices, K.indptr), shape=K.shape)
        assert b.builds == 1
