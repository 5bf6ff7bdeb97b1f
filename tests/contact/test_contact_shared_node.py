"""Pair rule ``rules.apart`` (issue 14, robustness): elements sharing a node never pair, tested
per pair.  A slave element sharing a node with one candidate master element must still pair with
the other master elements of the batch (was: its nodes were compared with those of every
candidate master element, so it lost all its pairs).  Through ``Model`` every beam has its own
nodes and a beam is never in contact with itself, so no scene reaches the rule with a shared
node today; the rule is pinned on crafted candidate sets.
"""
import numpy as np

from beamsolver.contact import rules


def test_apart_compares_each_pair_with_its_own_elements():
    enodes = np.array([[0, 1], [1, 2], [5, 6], [6, 7]])
    e, m = np.array([0, 0, 2, 3]), np.array([1, 2, 3, 1])
    np.testing.assert_array_equal(rules.apart(enodes, e, m), [False, True, False, True])


def test_apart_equals_a_pairwise_check_on_random_pairs():
    rng = np.random.default_rng(3)
    enodes = rng.integers(0, 12, size=(20, 3))
    e, m = rng.integers(0, 20, 200), rng.integers(0, 20, 200)
    want = [not set(enodes[a]) & set(enodes[b]) for a, b in zip(e, m)]
    got = rules.apart(enodes, e, m)
    assert 0 < got.sum() < len(got)
    np.testing.assert_array_equal(got, want)

