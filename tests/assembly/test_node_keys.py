"""``node_keys``: the held pattern's node-pair keys in linear time are numpy's unique / union1d / setdiff1d /
isin, and ``HeldPattern`` built with them is the one built with numpy, array for array."""
import numpy as np
import pytest

from test_extra_pattern import _element_matrix, _node_blocks, _reduction

from beamsolver.assembly import held_pattern, node_keys
from beamsolver.assembly.held_pattern import HeldPattern


def _sorted_unique(rng, n, size):
    return np.unique(rng.integers(0, n * n, size=size)).astype(np.int64)


def test_keys_are_numpys():
    rng = np.random.default_rng(3)
    for n in (1, 2, 7, 300):
        for size in (0, 1, 5, 4000):
            raw = rng.integers(0, n * n, size=size)
            u = node_keys.unique_keys(raw, n)
            assert u.dtype == np.int64 and np.array_equal(u, np.unique(raw))
            x, y = _sorted_unique(rng, n, size), _sorted_unique(rng, n, size // 2 + 1)
            assert np.array_equal(node_keys.union(x, y), np.union1d(x, y))
            assert np.array_equal(node_keys.difference(x, y), np.setdiff1d(x, y))
            assert np.array_equal(node_keys.difference(y, x), np.setdiff1d(y, x))
            assert node_keys.common(x, y) == np.isin(x, y).sum()


def test_element_and_block_keys_are_numpys():
    """A CSC element pattern and node blocks (zero 6 x 6 parts, clamped nodes, repeated nodes in a block)."""
    rng = np.random.default_rng(8)
    n_nodes = 70
    red, n = _reduction(rng, n_nodes, 4, 3)
    el = _element_matrix(rng, n, 0.03)
    node_of = np.flatnonzero(red >= 0) // 6
    col = np.repeat(np.arange(n), np.diff(el.indptr))
    ref = np.unique(node_of[col] * n_nodes + node_of[el.indices])
    assert np.array_equal(node_keys.element_keys(el.indptr, el.indices, node_of, n_nodes), ref)
    d = _node_blocks(rng, n_nodes, 120, 4)
    nodes = np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64)
    vals = rng.standard_normal((len(d), 24, 24))
    vals[rng.random(len(d)) < 0.3, :6, 6:12] = 0.0
    vals[:5] = 0.0
    nfree = np.bincount(node_of, minlength=n_nodes)
    assert np.array_equal(node_keys.block_keys(nodes, vals, nfree, n_nodes),
                          held_pattern._pair_keys(nodes, vals, nfree, n_nodes))


@pytest.mark.parametrize("reset", [False, True])
def test_held_pattern_is_the_numpy_built_one(monkeypatch, reset):
    """The same node graph, dof pattern, positions and values, growth by growth (kept or reset reserve)."""
    rng = np.random.default_rng(13)
    n_nodes = 90
    red, n = _reduction(rng, n_nodes, 5, 4)
    el = _element_matrix(rng, n, 0.02)
    blocks = [_node_blocks(rng, n_nodes, m, 4) for m in (60, 40 if reset else 80, 70)]
    built = {}
    for linear in (True, False):
        monkeypatch.setattr(held_pattern, "LINEAR_KEYS", linear)
        p = HeldPattern(red, n, el.indptr, el.indices)
        out = [p]
        for d in blocks:
            nodes = np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64)
            vals = np.ones((len(d), 24, 24))
            vals[::3, 6:12, :6] = 0.0
            p = p.grown(nodes, vals)
            out.append((p, p.matrix(el.data, nodes, vals)))
        built[linear] = out
    for a, b in zip(built[True][1:], built[False][1:]):
        for name in ("el_keys", "keys", "nptr", "nrow", "eoff", "indptr", "indices", "el_pos"):
            x, y = getattr(a[0], name), getattr(b[0], name)
            assert x.dtype == y.dtype and np.array_equal(x, y), name
        assert np.array_equal(a[1].data, b[1].data)


def test_of_blocks_is_the_element_pattern_grown():
    """``HeldPattern.of_blocks`` (a new pattern built on the blocks at once) is ``HeldPattern(...).grown``, and the
    element pattern alone where the blocks stay inside it."""
    rng = np.random.default_rng(17)
    n_nodes = 60
    red, n = _reduction(rng, n_nodes, 3, 3)
    el = _element_matrix(rng, n, 0.02)
    d = _node_blocks(rng, n_nodes, 50, 4)
    nodes = np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64)
    vals = rng.standard_normal((len(d), 24, 24))
    vals[::4, :6, 18:] = 0.0
    inside = np.zeros_like(vals)
    inside[:, :6, :6] = 1.0                                  # a node with itself: in the element pattern
    for v, grown in ((vals, True), (inside, False)):
        a = HeldPattern.of_blocks(red, n, el.indptr, el.indices, nodes, v)
        p = HeldPattern(red, n, el.indptr, el.indices)
        assert p.covers(nodes, v) != grown
        b = p.grown(nodes, v) if grown else p
        for name in ("el_keys", "keys", "nptr", "nrow", "eoff", "indptr", "indices", "el_pos"):
            x, y = getattr(a, name), getattr(b, name)
            assert x.dtype == y.dtype and np.array_equal(x, y), name
        assert np.array_equal(a.matrix(el.data, nodes, v).data, b.matrix(el.data, nodes, v).data)


@pytest.mark.slow
def test_newton_run_is_the_same_with_numpys_keys(monkeypatch):
    """The twisted pair at 26 elements a wire (exact stick, the augmented Newton system on the held pattern,
    grows as contact points enter) solved with the keys of ``node_keys`` and with numpy's: the same iterations
    and the same poses, bit for bit."""
    import twisted_pair
    import beamsolver as bs
    from beamsolver.assembly import system as system_mod
    monkeypatch.setattr(system_mod, "HOLD_PATTERN", True)
    grown = [0]
    orig = HeldPattern.grown

    def counted(self, *a):
        grown[0] += 1
        return orig(self, *a)
    monkeypatch.setattr(HeldPattern, "grown", counted)
    sols = {}
    for linear in (True, False):
        monkeypatch.setattr(held_pattern, "LINEAR_KEYS", linear)
        model, _, _ = twisted_pair.build(n_elements=26)
        sols[linear] = bs.solve(model, steps=4, verbose=False)
    assert grown[0] >= 1                       # (the numpy run grows its first pattern; node_keys: ``of_blocks``)
    assert [s["iterations"] for s in sols[True].stats] == [s["iterations"] for s in sols[False].stats]
    assert np.array_equal(sols[True].poses, sols[False].poses)
