"""``blocks.transform_rows`` (compiled): the bits of its numpy form ``transform_rows_numpy``."""
import numpy as np
import pytest

from beamsolver.lie import se3
from beamsolver.model import blocks

from helpers import assert_same_bits


@pytest.mark.parametrize("k", [2, 4])
def test_transform_rows_gives_the_bits_of_numpy(k):
    rng = np.random.default_rng(k)
    n_nodes, m = 12, 9
    M = np.broadcast_to(np.eye(6), (n_nodes, 6, 6)).copy()
    for i in (1, 4, 7):                                   # transformed nodes: rotations and joins
        M[i] = se3.adjoint(se3.exp(rng.standard_normal(6)))
    nodes = rng.integers(0, n_nodes, (m, k))
    f, K = rng.standard_normal((m, 6 * k)), rng.standard_normal((m, 6 * k, 6 * k))
    which = np.flatnonzero(np.isin(nodes, (1, 4, 7)).any(axis=1))
    assert len(which)
    got, want = blocks.transform_rows(M, nodes, f, K, which), blocks.transform_rows_numpy(M, nodes, f, K, which)
    assert_same_bits(got[0], want[0])
    assert_same_bits(got[1], want[1])
    f_only = blocks.transform_rows(M, nodes, f, None, which)
    assert f_only[1] is None
    assert_same_bits(f_only[0], want[0])
    # transform: the others unchanged, the inputs not changed
    f0, K0 = f.copy(), K.copy()
    ft, Kt = blocks.transform(M, nodes, f, K, which)
    assert np.array_equal(f, f0) and np.array_equal(K, K0)
    rest = np.setdiff1d(np.arange(m), which)
    assert np.array_equal(ft[rest], f[rest]) and np.array_equal(Kt[rest], K[rest])
    assert_same_bits(Kt[which], want[1])


@pytest.mark.parametrize("k", [1, 2, 4])
def test_levels_gives_the_maxima_of_numpy(k):
    rng = np.random.default_rng(10 + k)
    f = rng.standard_normal((7, 6 * k)) * np.repeat([1.0, 1e3], 3 * k).reshape(1, -1)[:, :6 * k]
    assert blocks.levels(f) == blocks.levels_numpy(f)
    assert blocks.levels(f[:0]) == blocks.levels_numpy(f[:0]) == (0.0, 0.0)
    f[3, 6 * (k - 1) + 4] = np.nan                        # a nan moment: nan, as numpy's maximum
    got, want = blocks.levels(f), blocks.levels_numpy(f)
    assert got[0] == want[0] and np.isnan(got[1]) and np.isnan(want[1])
