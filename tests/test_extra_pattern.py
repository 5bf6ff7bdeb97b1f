"""``extra_pattern.ExtraPattern``: the tangent with contact COO entries on a cached pattern is
scipy's ``K_el + csc_matrix((v, (r, c)))`` bit for bit (values, stored entries, their order)."""
import numpy as np
import scipy.sparse as sp

from beamsolver.extra_pattern import ExtraPattern


def _scipy(el, rows, cols, vals, red):
    rr, rc = red[rows], red[cols]
    keep = (rr >= 0) & (rc >= 0)
    return el + sp.csc_matrix((vals[keep], (rr[keep], rc[keep])), shape=el.shape)


def _identical(a, b):
    return (np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.data, b.data) and a.shape == b.shape)


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


def test_contact_scene_tangent_bit_identical():
    """The twisted pair's tangent with its contact blocks, through ``System.matrix``."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import twisted_pair
    from beamsolver.problem import Problem

    model, _, _ = twisted_pair.build(n_elements=8, turns=0.5)
    problem = Problem.from_model(model)
    s = problem.system
    H = s.poses0.copy()
    problem.begin_step(H, 0.0)
    ev = problem.evaluate(H, 0.0, tangent=True)
    assert len(ev.extra[2])
    data = np.empty(s.nnz + 1)
    from beamsolver import assembly_jit
    assembly_jit.scatter(s.pos, ev.kvals, data)
    el = sp.csc_matrix((data[:s.nnz], s.indices, s.indptr), shape=(s.n_free, s.n_free))
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


def test_solve_bit_identical_to_the_scipy_assembly(monkeypatch):
    """A frictional contact solve (the twisted pair, reduced) with the cached pattern gives the
    poses, reactions and contact forces of the same solve assembled by scipy, bit for bit."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import twisted_pair
    import beamsolver as bs
    from beamsolver import assembly_jit
    from beamsolver.assembly import System

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
