"""``lie.se3_twin``: compiled twins of ``se3``'s numpy maps, the same bits.

Samples as the group suite (identity, near identity ``1e-7 randn``, random, rotations close to
pi) and angles on both sides of every switch point the maps pass (the log's atan series at
0.2 rad, the coefficients' closed forms from 0.75 rad).  Bits are compared where numpy's 3x3
``@`` is the fused chain ``se3_twin`` reproduces (``helpers.numpy_matmul_fuses``); elsewhere round-off.
"""
from fractions import Fraction

import numpy as np
import pytest
from numba import njit

from beamsolver.lie import se3, se3_twin
from helpers import assert_same_bits as _same


@njit
def _fma(a, b, c):
    return se3_twin.fma(a, b, c)


def test_fma_rounds_once():
    e = 2.0 ** -30
    cases = [(1.0 + e, 1.0 - e, -1.0), (0.1, 0.2, -0.02), (1e308, 10.0, -1e308), (3.0, 1.0 / 3.0, -1.0)]
    for a, b, c in cases:
        exact = Fraction(a) * Fraction(b) + Fraction(c)
        want = float(exact) if abs(exact) < 1e308 else np.inf
        assert _fma(a, b, c) == want
    assert _fma(1.0 + e, 1.0 - e, -1.0) != (1.0 + e) * (1.0 - e) - 1.0     # what an unfused chain gives


def _twists(rng, n):
    """Twists over the ranges: zero, 1e-7 randn, random, angles across 0.2 and 0.75, close to pi."""
    h = [np.zeros((2, 6)), 1e-7 * rng.standard_normal((n, 6)), rng.standard_normal((n, 6))]
    for angle in (0.19, 0.21, 0.74, 0.76, 0.8, 1.6, np.pi - 1e-6):
        w = rng.standard_normal((n, 3))
        w *= angle / np.linalg.norm(w, axis=1)[:, None]
        h.append(np.concatenate([rng.standard_normal((n, 3)), w], axis=1))
    return np.concatenate(h)


@pytest.mark.parametrize("seed", [0, 1])
def test_log_relative_gives_the_bits_of_the_numpy_log(seed):
    rng = np.random.default_rng(seed)
    h = _twists(rng, 300)
    HA = se3.exp(rng.standard_normal((len(h), 6)))
    H = np.concatenate([HA, se3.compose(HA, se3.exp(h))])
    a, b = np.arange(len(h)), len(h) + np.arange(len(h))
    out = se3_twin.log_relative(H, a, b)
    assert np.isfinite(out).all()
    _same(out, se3.log(se3.relative(H[a], H[b])))
    # and the pairs in another order, with repeated nodes
    p = rng.permutation(len(h))[:50]
    _same(se3_twin.log_relative(H, np.r_[a[p], a[:3]], np.r_[b[p], a[:3]]),
          se3.log(se3.relative(H[np.r_[a[p], a[:3]]], H[np.r_[b[p], a[:3]]])))


@pytest.mark.parametrize("seed", [0, 1])
def test_exp_compose_gives_the_bits_of_the_numpy_interpolation(seed):
    rng = np.random.default_rng(seed)
    h = _twists(rng, 300)
    H = se3.exp(rng.standard_normal((len(h), 6)))
    xi = rng.uniform(-1.2, 1.2, len(h))
    xi[:5] = (0.0, 1.0, -1.0, 0.5, 1e-9)
    a = rng.permutation(len(h))
    out = se3_twin.exp_compose(H, a, h, xi)
    _same(out, se3.interpolate(H[a], h, xi))


def test_relative_into_gives_the_bits_of_the_numpy_relative():
    rng = np.random.default_rng(3)
    A = se3.exp(rng.standard_normal((200, 6)))
    B = se3.exp(rng.standard_normal((200, 6)))
    out = np.empty_like(A)
    for k in range(len(A)):
        se3_twin.relative_into(A[k], B[k], out[k])
    _same(out, se3.relative(A, B))
    _same(se3_twin.relative(A, B), se3.relative(A, B))


def test_coefficient_table_gives_the_bits_of_each_coefficient():
    rng = np.random.default_rng(4)
    t = np.concatenate([[0.0, 1e-9], rng.uniform(0, 3.5, 500), [0.75, 1.0, 1.5, 2.0]])
    names = ("a", "b", "c", "d", "q2", "q3")
    table = se3_twin.coefficient_table(names, t)
    for name, row in zip(names, table):
        assert np.array_equal(row, se3.coefficient(name, t)), name


def test_compose_members_and_turn_global_give_the_bits_of_numpy():
    """``assembly.System``'s pose updates: members ``H_rep X`` and global increments ``exp(w) R``."""
    rng = np.random.default_rng(5)
    H = se3.exp(rng.standard_normal((40, 6)))
    X = se3.exp(rng.standard_normal((10, 6)))
    members, reps = np.arange(30, 40), rng.integers(0, 30, 10)
    want = H.copy()
    want[members] = se3.compose(H[reps], X)
    got = H.copy()
    se3_twin.compose_members(got, members, reps, X)
    _same(got, want)
    dz = np.concatenate([rng.standard_normal((40, 3)), _twists(rng, 5)[:40, 3:]], axis=1)
    g = np.array([0, 3, 7, 12, 25])
    want = H.copy()
    want[g, :3, 3] += dz[g, :3]
    want[g, :3, :3] = se3.exp_so3(dz[g, 3:]) @ H[g, :3, :3]
    got = H.copy()
    se3_twin.turn_global(got, g, dz)
    _same(got, want)
