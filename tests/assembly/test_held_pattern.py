"""``held_pattern.HeldPattern`` and ``System.hold_pattern``: a tangent pattern kept across Newton iterations
(explicit zeros for reserved contact node pairs), its values those of the exact pattern to round-off, grown
(and PARDISO's analysis redone) when a block reaches a node pair outside it."""
import numpy as np
import pytest
import scipy.sparse as sp

from test_extra_pattern import _coo_of, _element_matrix, _node_blocks, _reduction, _scipy

from beamsolver.assembly.held_pattern import RESET_SHARE, HeldPattern


def _nodes(d):
    return np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64)


def _close(K, ref):
    """The same matrix to round-off, ``K``'s pattern holding all of ``ref``'s entries, canonical CSC."""
    scale = abs(ref).max()
    assert abs(K - ref).max() <= 1e-14 * scale
    assert K.shape == ref.shape and K.has_canonical_format
    fresh = sp.csc_matrix((K.data, K.indices, K.indptr), shape=K.shape)
    assert fresh.has_canonical_format                       # sorted, unique rows per column
    pat = sp.csc_matrix((np.ones(K.nnz), K.indices, K.indptr), shape=K.shape)
    r = ref.tocoo()
    assert (np.asarray(pat[r.row, r.col]).ravel() == 1).all()


def test_values_are_the_exact_patterns_to_round_off():
    """Element values plus blocks (clamped and partly fixed nodes, repeated nodes in a block) plus a tail of
    global-node-like terms: scipy's ``K_el + csc_matrix(COO)`` to round-off, zeros stored."""
    rng = np.random.default_rng(21)
    for trial in range(4):
        n_nodes = 60 + 40 * trial
        red, n = _reduction(rng, n_nodes, 5, 4)
        el = _element_matrix(rng, n, 0.02)
        d = _node_blocks(rng, n_nodes, 150 + 50 * trial, 4)
        g = rng.choice(n_nodes, 4, replace=False)
        t_rows = np.repeat(6 * g, 18) + np.tile(np.repeat(np.arange(6), 3), len(g))
        t_cols = np.repeat(6 * g, 18) + 3 + np.tile(np.arange(3), 6 * len(g))
        ones = np.ones((len(d), 24, 24))
        p = HeldPattern(red, n, el.indptr, el.indices).grown(_nodes(d), ones)
        assert p.covers(_nodes(d), ones)
        for _ in range(2):
            vals = rng.standard_normal(len(d) * 24 * 24) * 10.0 ** rng.integers(-6, 6, size=len(d) * 576)
            vals[::9] = 0.0
            t_vals = rng.standard_normal(len(t_rows))
            K = p.matrix(el.data, _nodes(d), vals.reshape(-1, 24, 24), (t_rows, t_cols, t_vals))
            rows, cols = (np.concatenate([a, b]) for a, b in zip(_coo_of(d), (t_rows, t_cols)))
            ref = _scipy(el, rows, cols, np.concatenate([vals, t_vals]), red)
            _close(K, ref)
            assert K.nnz == p.nnz > ref.nnz             # the exact zeros are kept, not dropped


def test_blocks_outside_grow_the_pattern_and_a_stale_reserve_is_dropped():
    """A block over a node pair outside the pattern is not covered (unless its 6 x 6 part is zero: a contact
    point without stiffness), and grows it; a reserve mostly unused at a growth is rebuilt from the blocks."""
    rng = np.random.default_rng(5)
    n_nodes = 80
    red, n = _reduction(rng, n_nodes, 3, 2)
    el = _element_matrix(rng, n, 0.01)
    a = _nodes(_node_blocks(rng, n_nodes, 40, 4))
    b = _nodes(_node_blocks(rng, n_nodes, 40, 4))

    def ones(x):
        return np.ones((len(x), 24, 24))
    p = HeldPattern(red, n, el.indptr, el.indices).grown(a, ones(a))
    assert p.covers(a, ones(a)) and p.covers(a[::3], ones(a[::3])) and not p.covers(b, ones(b))
    assert p.covers(b, np.zeros((len(b), 24, 24)))          # zero blocks need no place
    with pytest.raises(ValueError, match="outside the pattern"):
        p.matrix(el.data, b, ones(b))
    ab = np.concatenate([a[5:], b])
    q = p.grown(ab, ones(ab))                             # most of the reserve in use: it is kept, b added
    assert q.covers(a, ones(a)) and q.covers(b, ones(b)) and q.nnz > p.nnz
    assert q.matrix(el.data).nnz == q.nnz                 # element values alone on the held pattern
    small = np.concatenate([a[:2], b[:1] + 1])            # few of the reserve's pairs in use: rebuilt from them
    assert np.isin(q.keys, HeldPattern(red, n, el.indptr, el.indices).grown(small, ones(small)).keys).mean() \
        < RESET_SHARE
    r = q.grown(small, ones(small))
    assert r.covers(small, ones(small)) and not r.covers(a, ones(a)) and len(r.keys) < len(q.keys) \
        and r.nnz < q.nnz


def _twisted_pair_system(hold):
    import twisted_pair_extreme as twisted_pair
    from beamsolver.nonlinear.problem import Problem
    model, _, _ = twisted_pair.build(n_elements=12, turns=0.5)
    problem = Problem.from_model(model)
    problem.system.hold_pattern = hold
    return problem


def test_system_holds_the_pattern_while_the_active_set_stays_inside():
    """Through ``System.matrix`` (contact-like blocks handed over by ``assemble_blocks``, the twisted pair's
    element pattern and its global-type nodes): fewer pairs, the same pairs: the same pattern (the very
    ``HeldPattern``); a pair outside: the pattern grows; values those of the exact pattern each time."""
    from beamsolver.model.blocks import Blocks
    held, exact = _twisted_pair_system(True).system, _twisted_pair_system(False).system
    rng = np.random.default_rng(2)
    pairs = rng.integers(0, held.n_nodes, size=(300, 4))
    kvals = rng.standard_normal(held.group_kslices[-1] + 36 * len(held.block_nodes))
    sets = [np.arange(200), np.arange(0, 200, 3), np.arange(200), np.arange(150, 300), np.arange(100)]
    patterns, mats = [], []
    for sel in sets:
        K = rng.standard_normal((len(sel), 24, 24))
        K[:, ::5] = 0.0
        out = []
        for s in (held, exact):
            _, extra, _, _ = s.assemble_blocks(s.poses0, Blocks(pairs[sel], np.zeros((len(sel), 24)), K))
            out.append(s.matrix(kvals, extra))
        _close(*out)
        patterns.append(held.held_pattern)
        mats.append(out[0])
        assert exact.held_pattern is None
    assert patterns[0] is patterns[1] is patterns[2] and patterns[3] is not patterns[2] and patterns[4] is patterns[3]
    for i, j in ((0, 1), (1, 2), (3, 4)):
        assert np.array_equal(mats[i].indptr, mats[j].indptr) and np.array_equal(mats[i].indices, mats[j].indices)
    assert mats[3].nnz > mats[2].nnz


def test_hold_rule_and_its_input():
    import beamsolver as bs
    from beamsolver.assembly import system as system_mod
    s = _twisted_pair_system("auto").system
    assert s.n_free < system_mod.HOLD_MIN_UNKNOWNS and not s.holds_pattern()
    s.hold_pattern = True
    assert s.holds_pattern()
    s.hold_pattern = "always"
    with pytest.raises(bs.InputError, match="hold_pattern.*'always'"):
        s.holds_pattern()


@pytest.mark.slow
def test_newton_steps_keep_one_pattern_and_the_same_results(monkeypatch):
    """The main job (two wires twisted, 16 steps) solved with the held pattern and with the exact one: the
    same Newton iterations in every step and the same poses; the held tangents keep one pattern over the
    whole run (the wires touch along their length from the start), the exact ones change 60 times in 159
    tangents as contact points enter and leave.  (The penalty stick: exact stick's iteration counts move with
    round-off, which another pivot order gives.)"""
    import twisted_pair
    import beamsolver as bs
    from beamsolver.assembly import system as system_mod
    from beamsolver.nonlinear import linsolve

    patterns = []
    orig = linsolve.Solver.factorize

    def factorize(self, K, saddle=False):
        patterns.append((K.indptr.tobytes(), K.indices.tobytes()))
        return orig(self, K, saddle)
    monkeypatch.setattr(linsolve.Solver, "factorize", factorize)
    sols, changes = {}, {}
    for hold in (False, True):
        monkeypatch.setattr(system_mod, "HOLD_PATTERN", hold)
        patterns.clear()
        model, _, _ = twisted_pair.build(n_elements=16, turns=2.0, stick="penalty")
        sols[hold] = bs.solve(model, steps=16, verbose=False)
        changes[hold] = sum(a != b for a, b in zip(patterns, patterns[1:]))
    assert [s["iterations"] for s in sols[True].stats] == [s["iterations"] for s in sols[False].stats]
    # converged poses agree to the Newton tolerance's level: another pivot order (SuperLU's ordering sees the
    # stored zeros) moves them by 3e-11 here (splu-rcm instead of splu: 5e-12); a wrong tangent value would
    # change the iterations above
    np.testing.assert_allclose(sols[True].poses, sols[False].poses, rtol=0, atol=1e-9)
    assert changes[True] == 0 and changes[False] > 10, changes


def test_pardiso_analysis_only_when_the_held_pattern_grows():
    """PARDISO (``linsolve.Solver``) on tangents of a held pattern: one analysis while it holds, another one
    when a block outside it makes it grow; the solutions are right."""
    from beamsolver.model.blocks import Blocks
    from beamsolver.nonlinear import linsolve
    if "pardiso" not in linsolve.available():
        pytest.skip("pypardiso is not installed")
    s = _twisted_pair_system(True).system
    rng = np.random.default_rng(8)
    free = np.flatnonzero(s.is_rep & (s.kind == 0))
    pairs = rng.choice(free, size=(60, 4))
    kvals = rng.standard_normal(s.group_kslices[-1] + 36 * len(s.block_nodes))
    solver = linsolve.Solver("pardiso", lagged=False)
    counts = []
    for sel in (np.arange(40), np.arange(0, 40, 2), np.arange(60), np.arange(30)):
        K = rng.standard_normal((len(sel), 24, 24))
        _, extra, _, _ = s.assemble_blocks(s.poses0, Blocks(pairs[sel], np.zeros((len(sel), 24)), K))
        A = s.matrix(kvals, extra)
        col = np.repeat(np.arange(s.n_free), np.diff(A.indptr))
        A.data[:] = np.where(A.indices == col, 10.0, 1e-3 * rng.standard_normal(A.nnz))    # diagonally dominant
        b = rng.standard_normal(s.n_free)
        x = solver.factorize(A).solve(b)
        assert np.abs(A @ x - b).max() <= 1e-10 * np.abs(b).max()
        counts.append(solver.stats["analyses"])
    assert counts == [1, 1, 2, 2]


def test_tangents_share_the_patterns_index_arrays():
    """The held tangents (and exact stick's ``A = K' + Kq E Kl``, ``System.add_products``) hold the pattern's own
    ``indices`` / ``indptr``, not copies (issue 30: one index array less on the 0.6 m rope); a factorisation and
    solve with PARDISO leaves them as they were, and the values are those of a tangent on copied arrays."""
    from beamsolver.model.blocks import Blocks
    from beamsolver.nonlinear import linsolve
    s = _twisted_pair_system(True).system
    rng = np.random.default_rng(5)
    free = np.flatnonzero(s.is_rep & (s.kind == 0))
    pairs = rng.choice(free, size=(40, 4))
    kvals = rng.standard_normal(s.group_kslices[-1] + 36 * len(s.block_nodes))
    K = rng.standard_normal((40, 24, 24))
    _, extra, _, _ = s.assemble_blocks(s.poses0, Blocks(pairs, np.zeros((40, 24)), K))
    T = s.matrix(kvals, extra)
    p = s.held_pattern
    assert T.indices is p.indices and T.indptr is p.indptr
    kept = p.indices.copy(), p.indptr.copy()
    dofs = 6 * np.repeat(pairs[:, :2], 6, axis=1) + np.tile(np.arange(6), 2)
    A = s.add_products(T, dofs, rng.standard_normal((40, 12)), rng.standard_normal((40, 12)), rng.random(40))
    assert A is not None and A.indices is p.indices and A.indptr is p.indptr
    again = s.matrix(kvals, extra)
    assert s.held_pattern is p and again.indices is p.indices and np.array_equal(again.data, T.data)
    if "pardiso" in linsolve.available():
        col = np.repeat(np.arange(s.n_free), np.diff(A.indptr))
        A.data[:] = np.where(A.indices == col, 10.0, 1e-3 * rng.standard_normal(A.nnz))
        b = rng.standard_normal(s.n_free)
        solver = linsolve.Solver("pardiso", lagged=False)
        x = solver.factorize(A).solve(b)
        assert np.abs(A @ x - b).max() <= 1e-10 * np.abs(b).max()
        solver.close()
    assert np.array_equal(p.indices, kept[0]) and np.array_equal(p.indptr, kept[1])


def test_add_products_sums_row_by_row_in_order():
    """``HeldPattern.add_products`` (a group's node pairs found once for its consecutive rows) adds
    ``w_u Kq_u Kl_u^T`` row after row, in order: the same bits as those sums done one by one here."""
    rng = np.random.default_rng(4)
    n_nodes = 50
    red, n = _reduction(rng, n_nodes, 3, 3)
    el = _element_matrix(rng, n, 0.03)
    groups = _nodes(_node_blocks(rng, n_nodes, 30, 3))
    node = np.repeat(groups, rng.integers(1, 4, size=len(groups)), axis=0)   # 1-3 consecutive rows a group
    node = np.concatenate([node, groups[:4]])                               # a group again, later
    u = len(node)
    Kq, Kl = rng.standard_normal((u, 18)), rng.standard_normal((u, 18))
    w = rng.standard_normal(u)
    w[::5] = 0.0
    p = HeldPattern(red, n, el.indptr, el.indices).grown(groups, np.ones((len(groups), 18, 18)))
    K = p.matrix(el.data)
    data = K.data.copy()
    assert p.add_products(data, node, Kq, Kl, w)
    ref = K.data.copy()
    where = {}
    for j in range(n):
        for s in range(K.indptr[j], K.indptr[j + 1]):
            where[K.indices[s], j] = s
    for r in range(u):
        if w[r] == 0.0:
            continue
        for t in range(3):
            for s in range(3):
                for q in range(6):
                    j = red[6 * node[r, t] + q]
                    c = w[r] * Kl[r, 6 * t + q]
                    if j < 0 or c == 0.0:
                        continue
                    for pp in range(6):
                        i = red[6 * node[r, s] + pp]
                        if i >= 0:
                            ref[where[i, j]] += Kq[r, 6 * s + pp] * c
    assert np.array_equal(data, ref)


def test_values_sum_block_after_block_in_order():
    """``HeldPattern.matrix`` (a pair of whole free nodes placed as one 6 x 6 block) sums each entry's terms as the
    plain loop does: element value first, then the blocks in order, slot pair by slot pair (clamped, partly fixed and
    repeated nodes), then the tail: the same bits as those sums done one by one here."""
    rng = np.random.default_rng(8)
    n_nodes = 50
    red, n = _reduction(rng, n_nodes, 3, 3)
    el = _element_matrix(rng, n, 0.03)
    d = _node_blocks(rng, n_nodes, 40, 3)
    node = _nodes(d)
    vals = rng.standard_normal((len(d), 18, 18))
    vals[3] = 0.0
    g = rng.choice(n_nodes, 2, replace=False)
    t_rows, t_cols = np.repeat(6 * g, 6) + np.tile(np.arange(6), 2), np.repeat(6 * g + 3, 6)
    t_vals = rng.standard_normal(len(t_rows))
    p = HeldPattern(red, n, el.indptr, el.indices).grown(node, np.ones_like(vals))
    K = p.matrix(el.data, node, vals, (t_rows, t_cols, t_vals))
    ref = p.matrix(el.data).data                      # element values alone (zeros elsewhere)
    where = {}
    for j in range(n):
        for s in range(K.indptr[j], K.indptr[j + 1]):
            where[K.indices[s], j] = s
    for blk in range(len(node)):
        for t in range(3):
            for s in range(3):
                for q in range(6):
                    j = red[6 * node[blk, t] + q]
                    for pp in range(6):
                        i = red[6 * node[blk, s] + pp]
                        if i >= 0 and j >= 0:
                            ref[where[i, j]] += vals[blk, 6 * s + pp, 6 * t + q]
    for r, c, v in zip(t_rows, t_cols, t_vals):
        if red[r] >= 0 and red[c] >= 0:
            ref[where[red[r], red[c]]] += v
    assert np.array_equal(K.data, ref)
