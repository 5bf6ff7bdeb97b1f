"""``extra_pattern.ExtraPattern``: the tangent with contact COO entries on a cached pattern is
scipy's ``K_el + csc_matrix((v, (r, c)))`` bit for bit (values, stored entries, their order)."""
import numpy as np
import pytest
import scipy.sparse as sp

from beamsolver.assembly.extra_pattern import ExtraPattern


def _scipy(el, rows, cols, vals, red):
    rr, rc = red[np.ravel(rows)], red[np.ravel(cols)]
    keep = (rr >= 0) & (rc >= 0)
    return el + sp.csc_matrix((vals[keep], (rr[keep], rc[keep])), shape=el.shape)


def _identical(a, b):
    """The same CSC arrays, and ``a`` is canonical (sorted, unique rows per column) as it says it is."""
    fresh = sp.csc_matrix((a.data, a.indices, a.indptr), shape=a.shape)      # flags computed, not copied
    return (np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.data, b.data) and a.shape == b.shape
            and a.has_canonical_format == fresh.has_canonical_format == b.has_canonical_format)


def _element_matrix(rng, n, density):
    el = sp.random(n, n, density=density, random_state=rng, format="csc")
    el = el + sp.eye(n, format="csc")
    el.sum_duplicates()
    return el


def _blocks(rng, n_full, m, k, dup_nodes):
    """COO of ``m`` dense ``k x k`` blocks over random dofs (many repeats: duplicates to sum)."""
    d = rng.integers(0, dup_nodes, size=(m, k)) % n_full
    rows, cols = np.repeat(d, k, axis=1).ravel(), np.tile(d, (1, k)).ravel()
    return rows, cols


def test_random_patterns_bit_identical():
    rng = np.random.default_rng(3)
    for trial in range(6):
        n_full = 400
        red = np.arange(n_full)
        fixed = rng.choice(n_full, 40, replace=False)
        red[fixed] = -1
        red[red >= 0] = np.arange(n_full - 40)
        el = _element_matrix(rng, n_full - 40, 0.02)
        # long columns (> 16 entries: std::sort is not an insertion sort there) with many duplicates
        rows, cols = _blocks(rng, n_full, 300, 24, 120 + 100 * trial)
        pat = ExtraPattern(rows, cols, red, n_full - 40, el.indptr, el.indices)
        for _ in range(3):
            vals = rng.standard_normal(len(rows)) * 10.0 ** rng.integers(-8, 8, size=len(rows))
            assert _identical(pat.matrix(el.data, vals), _scipy(el, rows, cols, vals, red))


def test_exact_zeros_dropped_like_scipy():
    """Sums that cancel exactly (element + contact, or contact runs) and zero element values are
    not stored, as ``csr_plus_csr`` drops them."""
    rng = np.random.default_rng(5)
    n = 60
    red = np.arange(n)
    el = _element_matrix(rng, n, 0.1)
    el.data[::7] = 0.0
    rows, cols = _blocks(rng, n, 20, 6, n)
    vals = rng.standard_normal(len(rows))
    vals[::5] = 0.0
    # a contact entry cancelling the element value at the same place
    dense = el.toarray()
    r0, c0 = rows[1], cols[1]
    same = np.flatnonzero((rows == r0) & (cols == c0))
    vals[same] = 0.0
    vals[same[0]] = -dense[r0, c0]
    pat = ExtraPattern(rows, cols, red, n, el.indptr, el.indices)
    K = pat.matrix(el.data, vals)
    ref = _scipy(el, rows, cols, vals, red)
    assert _identical(K, ref)
    assert (K.data != 0).all() and K.nnz < len(pat.indices)


def test_sorted_columns_keep_their_order():
    """Columns already sorted (scipy skips its sort): runs summed in the given order."""
    n = 30
    red = np.arange(n)
    el = sp.eye(n, format="csc")
    rows = np.array([0, 0, 0, 1, 5, 5, 2, 2, 2])
    cols = np.array([3, 3, 3, 3, 3, 3, 7, 7, 7])
    vals = np.array([1e16, 1.0, -1e16, 0.5, 2.0, 3.0, 1.0, 1e-16, -1.0])
    pat = ExtraPattern(rows, cols, red, n, el.indptr, el.indices)
    assert _identical(pat.matrix(el.data, vals), _scipy(el, rows, cols, vals, red))


def _twisted_pair_tangent():
    """The twisted pair (8 elements, half a turn) evaluated with its tangent at the reference poses:
    ``(problem, system, evaluation, element part of the tangent as a CSC matrix)``."""
    import twisted_pair_extreme as twisted_pair
    from beamsolver.assembly import compiled as assembly_jit
    from beamsolver.nonlinear.problem import Problem

    model, _, _ = twisted_pair.build(n_elements=8, turns=0.5)
    problem = Problem.from_model(model)
    s = problem.system
    H = s.poses0.copy()
    problem.begin_step(H, 0.0)
    ev = problem.evaluate(H, 0.0, tangent=True)
    data = np.empty(s.nnz + 1)
    assembly_jit.scatter(s.pos, ev.kvals, data)
    el = sp.csc_matrix((data[:s.nnz], s.indices, s.indptr), shape=(s.n_free, s.n_free))
    return problem, s, ev, el


def test_contact_scene_tangent_bit_identical():
    """The twisted pair's tangent with its contact blocks, through ``System.matrix``."""
    problem, s, ev, el = _twisted_pair_tangent()
    assert len(ev.extra[2])
    for _ in range(2):                       # built, then reused
        assert _identical(problem.tangent(ev), _scipy(el, *ev.extra, s.red))


def test_entries_only_on_constrained_unknowns():
    """No entry kept: the element matrix with its exact zeros dropped, as ``K_el + empty``."""
    el = sp.eye(5, format="csc")
    el.data[2] = 0.0
    red = np.array([0, 1, 2, 3, 4, -1, -1])
    rows, cols = np.array([5, 6, 5]), np.array([5, 5, 0])
    vals = np.array([1.0, 2.0, 3.0])
    K = ExtraPattern(rows, cols, red, 5, el.indptr, el.indices).matrix(el.data, vals)
    assert _identical(K, _scipy(el, rows, cols, vals, red)) and K.nnz == 4


@pytest.mark.slow
def test_solve_bit_identical_to_the_scipy_assembly(monkeypatch):
    """A frictional contact solve (the twisted pair, reduced) with the cached pattern gives the
    poses, reactions and contact forces of the same solve assembled by scipy, bit for bit."""
    import twisted_pair_extreme as twisted_pair
    import beamsolver as bs
    from beamsolver.assembly import compiled as assembly_jit
    from beamsolver.assembly.system import System

    def scipy_matrix(self, kvals, extra=None):
        data = np.empty(self.nnz + 1)
        assembly_jit.scatter(self.pos, kvals, data)
        K = sp.csc_matrix((data[:self.nnz], self.indices, self.indptr), shape=(self.n_free, self.n_free))
        if extra is not None and len(extra[2]):
            K = _scipy(K, *extra, self.red)
        return K

    def run():
        model, _, _ = twisted_pair.build(n_elements=8, turns=0.5)
        return bs.solve(model, steps=4)

    cached = run()
    monkeypatch.setattr(System, "matrix", scipy_matrix)
    plain = run()
    assert [s["iterations"] for s in cached.stats] == [s["iterations"] for s in plain.stats]
    np.testing.assert_array_equal(cached.poses, plain.poses)
    np.testing.assert_array_equal(cached.reactions, plain.reactions)
    for k in range(len(plain.times)):
        np.testing.assert_array_equal(cached.contact(k)["normal_force"], plain.contact(k)["normal_force"])


def test_pattern_built_on_the_buffers_of_the_last_one():
    """A new pattern reuses the buffers of the one it replaces when they are large enough (and only
    then) and gives the matrix a fresh build gives; the replaced pattern is not usable any more."""
    rng = np.random.default_rng(9)
    n = 300
    red = np.arange(n)
    el = _element_matrix(rng, n, 0.02)
    big = _blocks(rng, n, 200, 24, 150)
    small = _blocks(rng, n, 150, 24, 150)
    first = ExtraPattern(*big, red, n, el.indptr, el.indices)
    second = ExtraPattern(*small, red, n, el.indptr, el.indices, spare=first)
    assert first.buffers is None and second.buffers[0] is not None
    vals = rng.standard_normal(len(small[0]))
    assert _identical(second.matrix(el.data, vals), _scipy(el, *small, vals, red))
    fresh = ExtraPattern(*small, red, n, el.indptr, el.indices)
    assert _identical(second.matrix(el.data, vals), fresh.matrix(el.data, vals))
    third = ExtraPattern(*big, red, n, el.indptr, el.indices, spare=fresh)    # too small: fresh buffers
    assert fresh.buffers is not None and third.buffers[0] is not fresh.buffers[0]
    assert _identical(fresh.matrix(el.data, vals), _scipy(el, *small, vals, red))
    vals = rng.standard_normal(len(big[0]))
    assert _identical(third.matrix(el.data, vals), _scipy(el, *big, vals, red))


def _node_blocks(rng, n_nodes, m, k):
    """Block dofs ``(m, 6 k)`` over ``k`` random nodes each (whole nodes, some repeated within a
    block, as joined nodes share a representative)."""
    nodes = rng.integers(0, n_nodes, size=(m, k))
    nodes[::7, 1] = nodes[::7, 0]
    return ((6 * nodes)[:, :, None] + np.arange(6)).reshape(m, 6 * k)


def _coo_of(d):
    b = d.shape[1]
    return np.repeat(d, b, axis=1).ravel(), np.tile(d, (1, b)).ravel()


def _reduction(rng, n_nodes, clamped, partial):
    """``red`` over ``6 n_nodes`` unknowns: ``clamped`` nodes fully, ``partial`` nodes on some dofs fixed."""
    free = np.ones(6 * n_nodes, dtype=bool)
    for b in rng.choice(n_nodes, clamped, replace=False):
        free[6 * b:6 * b + 6] = False
    for b in rng.choice(n_nodes, partial, replace=False):
        free[6 * b + rng.choice(6, 3, replace=False)] = False
    red = np.full(6 * n_nodes, -1)
    red[free] = np.arange(free.sum())
    return red, int(free.sum())


def test_block_pattern_is_scipys_matrix_bit_for_bit():
    """``BlockPattern`` (built from the block dofs alone) gives scipy's ``K_el + csc_matrix`` of the
    blocks' COO entries, on long columns (> 16 entries: std::sort's partitions, not an insertion
    sort), clamped and partly fixed nodes, repeated nodes in a block, and for new values."""
    from beamsolver.assembly.extra_pattern import BlockPattern, whole_nodes
    rng = np.random.default_rng(11)
    for trial in range(5):
        n_nodes = 60 + 40 * trial
        red, n = _reduction(rng, n_nodes, 5, 4)
        el = _element_matrix(rng, n, 0.02)
        d = _node_blocks(rng, n_nodes, 150 + 50 * trial, 4)
        assert whole_nodes(d)
        rows, cols = _coo_of(d)
        pat = BlockPattern(d, red, n, el.indptr, el.indices)
        for _ in range(3):
            vals = rng.standard_normal(len(rows)) * 10.0 ** rng.integers(-8, 8, size=len(rows))
            assert _identical(pat.matrix(el.data, vals), _scipy(el, rows, cols, vals, red))
        # scipy sorts no column when all are sorted: nor does the pattern
        one = d[:1]
        vals = rng.standard_normal(24 * 24)
        assert _identical(BlockPattern(one, red, n, el.indptr, el.indices).matrix(el.data, vals),
                          _scipy(el, *_coo_of(one), vals, red))


def test_whole_nodes_recognised():
    from beamsolver.assembly.extra_pattern import whole_nodes
    d = ((6 * np.array([[3, 1], [0, 2]]))[:, :, None] + np.arange(6)).reshape(2, 12)
    assert whole_nodes(d)
    bad = d.copy()
    bad[1, 7] += 1
    assert not whole_nodes(bad) and not whole_nodes(d + 1) and not whole_nodes(d[:, :10])


def _system_matrices(s, nodes, K):
    """``System.matrix`` of element values plus blocks ``K`` over ``nodes`` ``(m, 4)`` handed over by
    ``assemble_blocks`` (as contact's), and scipy's matrix of the same COO data."""
    from beamsolver.assembly import compiled as assembly_jit
    from beamsolver.blocks import Blocks
    kvals = np.random.default_rng(len(nodes)).standard_normal(s.group_kslices[-1] + 36 * len(s.block_nodes))
    _, extra, _, _ = s.assemble_blocks(s.poses0, Blocks(nodes, np.zeros((len(nodes), 24)), K))
    data = np.empty(s.nnz + 1)
    assembly_jit.scatter(s.pos, kvals, data)
    el = sp.csc_matrix((data[:s.nnz], s.indices, s.indptr), shape=(s.n_free, s.n_free))
    return s.matrix(kvals, extra), _scipy(el, *extra, s.red)


def test_system_matrix_as_the_active_set_changes():
    """Through ``System.matrix``: contact-like blocks of a changing active set (pairs added,
    dropped, the same set again, a set seen before) give scipy's matrix of the same COO data each
    time; the pattern is rebuilt only when the set changes, on the buffers of the last one."""
    import twisted_pair_extreme as twisted_pair
    from beamsolver.assembly.system import System
    from beamsolver.assembly.extra_pattern import BlockPattern

    model, _, _ = twisted_pair.build(n_elements=12, turns=0.5)
    s = System(model)
    rng = np.random.default_rng(2)
    n_nodes = s.n_nodes
    pairs = rng.integers(0, n_nodes, size=(400, 4))
    sets = [np.arange(300), np.arange(300), np.arange(20, 330), np.arange(0, 400, 2), np.arange(300),
            np.arange(5)]
    built = []
    for sel in sets:
        K = rng.standard_normal((len(sel), 24, 24))
        K[:, ::5] = 0.0                          # exact zeros on the way
        ours, ref = _system_matrices(s, pairs[sel], K)
        assert _identical(ours, ref)
        assert isinstance(s.extra_pattern, BlockPattern)
        built.append((s.extra_pattern, s.extra_pattern.buffers[0]))
    assert built[0][0] is built[1][0] and built[1][0] is not built[2][0] and built[4][0] is not built[0][0]
    assert all(b[1] is built[0][1] for b in built)       # every set fits the first one's buffers


def test_block_pattern_with_a_tail_of_entries():
    """Blocks followed by other COO entries (``assemble_blocks``' terms of global-type nodes, any
    entries): the columns they reach are sorted on their own, with scipy's result bit for bit."""
    from beamsolver.assembly.extra_pattern import BlockPattern
    rng = np.random.default_rng(17)
    for trial in range(4):
        n_nodes = 80 + 30 * trial
        red, n = _reduction(rng, n_nodes, 4, 6)
        el = _element_matrix(rng, n, 0.03)
        d = _node_blocks(rng, n_nodes, 200, 4)
        g = rng.choice(n_nodes, 5, replace=False)          # global-node-like terms, then random entries
        t_rows = np.concatenate([np.repeat(6 * g, 18) + np.tile(np.repeat(np.arange(6), 3), len(g)),
                                 rng.integers(0, 6 * n_nodes, 40)])
        t_cols = np.concatenate([np.repeat(6 * g, 18) + 3 + np.tile(np.arange(3), 6 * len(g)),
                                 rng.integers(0, 6 * n_nodes, 40)])
        rows, cols = (np.concatenate([a, b]) for a, b in zip(_coo_of(d), (t_rows, t_cols)))
        pat = BlockPattern(d, red, n, el.indptr, el.indices, (t_rows, t_cols))
        for _ in range(2):
            vals = rng.standard_normal(len(rows)) * 10.0 ** rng.integers(-8, 8, size=len(rows))
            assert _identical(pat.matrix(el.data, vals), _scipy(el, rows, cols, vals, red))
        assert not pat.same(d, None) and pat.same(d.copy(), (t_rows.copy(), t_cols.copy()))


def test_contact_scene_with_global_nodes_takes_the_block_path():
    """The twisted pair's contact reaches global-type nodes (partly fixed ends): its tangent is
    built by ``BlockPattern`` with the global-node terms as a tail, equal to scipy's."""
    from beamsolver.assembly.extra_pattern import BlockPattern

    problem, s, ev, el = _twisted_pair_tangent()
    assert _identical(problem.tangent(ev), _scipy(el, *ev.extra, s.red))
    assert isinstance(s.extra_pattern, BlockPattern) and s.extra_pattern.tail is not None


def test_block_index_arrays_are_views_of_the_block_dofs():
    """The COO index arrays of blocks are broadcast views of the block dofs (no ``m k^2`` memory of
    their own): raveled they are ``repeat(d, k)`` and ``tile(d, k)``; read-only; the same arrays
    while the dofs stay the same, new ones (over new dofs) when they change, the old ones untouched."""
    import twisted_pair_extreme as twisted_pair
    from beamsolver.assembly.system import System
    from beamsolver.model.blocks import Blocks

    model, _, _ = twisted_pair.build(n_elements=12, turns=0.5)
    s = System(model)
    rng = np.random.default_rng(4)
    plain = np.flatnonzero(~s.transformed & s.is_rep)     # no transform, no global-node terms
    sets = [rng.choice(plain, size=(m, 4)) for m in (50, 40)]

    def index(nodes):
        d = ((6 * s.rep[nodes])[:, :, None] + np.arange(6)).reshape(len(nodes), 24)
        blocks = Blocks(nodes, np.zeros((len(nodes), 24)), np.zeros((len(nodes), 24, 24)))
        return d, s.assemble_blocks(s.poses0, blocks)[1][:2]

    d0, (rows0, cols0) = index(sets[0])
    for d, (rows, cols) in ((d0, (rows0, cols0)), index(sets[1])):
        assert np.array_equal(np.ravel(rows), np.repeat(d, 24, axis=1).ravel())
        assert np.array_equal(np.ravel(cols), np.tile(d, (1, 24)).ravel())
        assert not rows.flags.writeable and not cols.flags.writeable
        assert rows.strides[2] == 0 and cols.strides[1] == 0 and rows.base.size == d.size
    assert index(sets[1])[1][0] is index(sets[1])[1][0]            # the same dofs: the same arrays
    assert np.array_equal(np.ravel(rows0), np.repeat(d0, 24, axis=1).ravel())


def test_prescribed_coupling_of_blocks_equals_the_entrywise_sum():
    """``System.prescribed_coupling`` reads the contact blocks through their dofs (``_block_coupling``,
    no per-entry temporaries): equal to the sum over the COO entries (copies of the index arrays,
    which take the entry-wise path) to round-off, on the twisted pair (blocks and a tail of
    global-node terms) with every constrained unknown moved."""
    problem, s, ev, el = _twisted_pair_tangent()
    rng = np.random.default_rng(8)
    dz = np.where(s.red < 0, rng.standard_normal(len(s.red)), 0.0)
    rows, cols, vals = ev.extra
    no_elements = np.zeros_like(ev.kvals)           # the contact's part alone
    ours = s.prescribed_coupling(no_elements, dz, ev.extra)
    ref = s.prescribed_coupling(no_elements, dz, (rows.copy(), cols.copy(), vals))
    scale = np.abs(ref).max()
    assert scale > 0 and np.abs(ours - ref).max() <= 1e-13 * scale
