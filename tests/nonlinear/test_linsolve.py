"""Linear-solver back-ends (``beamsolver.nonlinear.linsolve``): same solution as a dense solve, errors."""
import numpy as np
import pytest
import scipy.sparse as sp

import beamsolver as bs
from beamsolver.nonlinear import linsolve
from beamsolver.errors import InputError

HAVE_PARDISO = "pardiso" in linsolve.available()
BACKENDS = ["splu", "splu-rcm", pytest.param("pardiso", marks=pytest.mark.skipif(not HAVE_PARDISO,
                                                                                 reason="pypardiso not installed")),
            "dense", "auto"]


def spd_matrix(n=60, seed=0):
    """Sparse SPD: a 1-D Laplacian plus a random sparse Gram part."""
    rng = np.random.default_rng(seed)
    lap = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    B = sp.random(n, n, density=0.05, random_state=rng)
    return sp.csc_matrix(lap + B.T @ B + 0.1 * sp.eye(n))


def nonsymmetric_matrix(n=80, seed=1):
    """Sparse, non-symmetric, diagonally dominant, with a permuted pattern (pivoting needed elsewhere)."""
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.08, random_state=rng).tolil()
    A.setdiag(np.abs(A).sum(axis=1).A1 + 1.0)
    A = sp.csc_matrix(A)
    assert abs(A - A.T).max() > 0.1
    return A


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("make", [spd_matrix, nonsymmetric_matrix])
@pytest.mark.parametrize("fmt", ["csc", "csr"])
def test_same_solution_as_dense(backend, make, fmt):
    A = make().asformat(fmt)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    x_dense = np.linalg.solve(A.toarray(), b)
    x = linsolve.factorize(A, backend).solve(b)
    np.testing.assert_allclose(x, x_dense, rtol=1e-10, atol=1e-12 * np.abs(x_dense).max())


@pytest.mark.parametrize("backend", BACKENDS)
def test_solver_refactorises_same_pattern(backend):
    """A Solver kept across iterations: new values with the same pattern, and an older factor still solves."""
    A = nonsymmetric_matrix()
    A2 = A.copy()
    A2.data = A2.data * np.linspace(0.5, 2.0, A2.nnz)
    A2 = A2 + sp.diags(np.abs(A2).sum(axis=1).A1)          # same pattern (diagonal present), new values
    b = np.ones(A.shape[0])
    s = linsolve.Solver(backend)
    f1 = s.factorize(A)
    f2 = s.factorize(A2)
    np.testing.assert_allclose(f2.solve(b), np.linalg.solve(A2.toarray(), b), rtol=1e-10)
    np.testing.assert_allclose(f1.solve(b), np.linalg.solve(A.toarray(), b), rtol=1e-10)
    if s.backend_for(A) == "pardiso":
        assert s.stats["analyses"] == 1          # the symbolic analysis was reused
    s.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_singular_matrix_raises(backend):
    A = sp.csc_matrix(np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [1.0, 1.0, 1.0]]))
    with pytest.raises(linsolve.SingularMatrixError):
        linsolve.factorize(A, backend).solve(np.ones(3))


def test_bad_backend_name():
    with pytest.raises(InputError, match="umfpack"):
        linsolve.factorize(spd_matrix(), "umfpack")
    with pytest.raises(InputError, match="linear_solver"):
        linsolve.Solver("Pardiso")


def test_missing_pardiso_is_an_input_error(monkeypatch):
    monkeypatch.setattr(linsolve, "_pypardiso", lambda: None)
    with pytest.raises(InputError, match="pypardiso"):
        linsolve.Solver("pardiso")
    assert linsolve.Solver("auto").backend_for(spd_matrix()) == "splu"
    assert "pardiso" not in linsolve.available()
    assert linsolve.Solver("auto").backend_for(coupled_matrix()) == "splu-rcm"


def coupled_matrix(n=2000, half_band=20):
    """Banded, 41 non-zeros per column: what contact couplings look like to ``auto``."""
    offsets = list(range(-half_band, half_band + 1))
    diags = [np.full(n - abs(k), -0.01) for k in offsets]
    diags[half_band] = np.full(n, 1.0)
    return sp.csc_matrix(sp.diags(diags, offsets))


def test_auto_choice():
    small, coupled = spd_matrix(), coupled_matrix()
    assert linsolve.Solver("auto").backend_for(small) == "splu"
    assert linsolve.Solver("auto").backend_for(coupled) == ("pardiso" if HAVE_PARDISO else "splu-rcm")
    b = np.ones(coupled.shape[0])
    np.testing.assert_allclose(linsolve.factorize(coupled, "auto").solve(b),
                               linsolve.factorize(coupled, "splu").solve(b), rtol=1e-10)


def _cantilever():
    m = bs.Model()
    beam = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 8), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(beam.first)
    m.add_load(beam.last, force=(0.0, 0.0, -100.0))
    return m, beam


@pytest.mark.parametrize("backend", BACKENDS)
def test_solve_keyword(backend):
    m, beam = _cantilever()
    ref = bs.solve(m, steps=2, verbose=False)
    sol = bs.solve(m, steps=2, verbose=False, linear_solver=backend)
    np.testing.assert_allclose(sol.position(beam.last), ref.position(beam.last), rtol=1e-9, atol=1e-12)


def test_solve_keyword_bad_name():
    m, _ = _cantilever()
    with pytest.raises(InputError, match="linear_solver"):
        bs.solve(m, steps=1, verbose=False, linear_solver="mumps")


def _weak_diagonal(n=200, seed=4):
    """Non-symmetric band of 2 x 2 blocks ``[[1e-12, 1], [1, 1e-12]]`` weakly coupled: elimination on
    the diagonal grows entries by 1e12; pivoting must leave the diagonal (below
    ``RCM_PIVOT_THRESHOLD`` of the column's largest entry)."""
    rng = np.random.default_rng(seed)
    A = sp.lil_matrix((n, n))
    for i in range(0, n, 2):
        A[i, i], A[i, i + 1], A[i + 1, i], A[i + 1, i + 1] = 1e-12, 1.0, rng.uniform(1, 2), 1e-12
    for i in range(n - 2):
        A[i, i + 2], A[i + 2, i] = 0.1 * rng.uniform(), 0.05 * rng.uniform()
    return sp.csc_matrix(A)


def test_rcm_threshold_pivoting_solves_weak_diagonals():
    """splu-rcm with threshold pivoting: pivots away from a 1e-12 diagonal (no growth), backward
    error at round-off, as with full partial pivoting."""
    A = _weak_diagonal()
    b = np.random.default_rng(5).standard_normal(A.shape[0])
    f = linsolve.factorize(A, "splu-rcm")
    assert not np.array_equal(f._lu.perm_r, np.arange(A.shape[0]))        # it did pivot
    x = f.solve(b)
    assert linsolve._backward_error(A, x, b) < 1e-14
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-9)


def test_rcm_falls_back_to_full_pivoting(monkeypatch):
    """A factor whose solution has a large backward error (here: no pivoting at all on tiny
    diagonals) is recomputed with full partial pivoting."""
    monkeypatch.setattr(linsolve, "RCM_PIVOT_THRESHOLD", 0.0)
    A = _weak_diagonal()
    b = np.random.default_rng(5).standard_normal(A.shape[0])
    f = linsolve.factorize(A, "splu-rcm")
    x_bad = f._solve(b)
    assert linsolve._backward_error(A, x_bad, b) > linsolve.BACKWARD_ERROR
    x = f.solve(b)
    assert linsolve._backward_error(A, x, b) < 1e-14


def test_rcm_ordering_kept_for_the_same_pattern():
    """The second matrix of the same pattern reuses the ordering and gives the factor of a fresh
    ordering: the same solution bit for bit."""
    A = nonsymmetric_matrix()
    A2 = A.copy()
    A2.data = A2.data * np.linspace(0.5, 2.0, A2.nnz)
    b = np.ones(A.shape[0])
    linsolve.factorize(A, "splu-rcm")
    kept = linsolve._RCM_LAST[0][3]
    x2 = linsolve.factorize(A2, "splu-rcm").solve(b)
    assert linsolve._RCM_LAST[0][3] is kept
    linsolve._RCM_LAST.clear()
    np.testing.assert_array_equal(linsolve.factorize(A2, "splu-rcm").solve(b), x2)
    np.testing.assert_allclose(x2, np.linalg.solve(A2.toarray(), b), rtol=1e-10)


def test_compiled_rcm_is_scipys():
    """``_rcm_csc`` gives ``_rcm_scipy``'s ordering and permuted pattern exactly, on unsymmetric
    patterns, explicit zeros, empty columns and a contact tangent."""
    rng = np.random.default_rng(8)
    mats = [nonsymmetric_matrix()]
    for n, dens in ((50, 0.05), (200, 0.02), (300, 0.005)):
        A = sp.random(n, n, density=dens, random_state=rng, format="csc") + sp.eye(n, format="csc")
        A.sum_duplicates()
        mats.append(A)
    Z = mats[2].copy()
    Z.data[::3] = 0.0                    # stored zeros: part of the pattern
    mats.append(Z)
    E = sp.csc_matrix(sp.random(40, 40, density=0.05, random_state=rng).toarray() * (np.arange(40) % 5 != 0))
    mats.append(E)
    import twisted_pair_extreme as twisted_pair
    from beamsolver.nonlinear.problem import Problem
    model, _, _ = twisted_pair.build(n_elements=8, turns=0.5)
    problem = Problem.from_model(model)
    problem.begin_step(problem.system.poses0, 0.0)
    mats.append(problem.tangent(problem.evaluate(problem.system.poses0, 0.0)))
    for A in mats:
        assert A.format == "csc" and A.has_canonical_format
        ours, ref = linsolve._rcm_csc(A), linsolve._rcm_scipy(A)
        for a, b in zip(ours, ref):
            assert a.dtype == b.dtype and np.array_equal(a, b)


def saddle_point(K, m, seed=6):
    """``[[K, B^T], [B, 0]]``: ``m`` Lagrange multipliers on sparse full-rank constraint rows ``B``
    (a zero diagonal block, as the exact-stick contact tangent), CSC."""
    rng = np.random.default_rng(seed)
    n = K.shape[0]
    B = sp.random(m, n, density=min(1.0, 6.0 / n), random_state=rng, format="lil")
    cols = rng.choice(n, size=m, replace=False)
    for i, j in enumerate(cols):
        B[i, j] = 1.0 + rng.uniform()                # full row rank
    B = sp.csr_matrix(B)
    return sp.csc_matrix(sp.bmat([[K, B.T], [B, None]]))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("make", [spd_matrix, nonsymmetric_matrix])
def test_saddle_point(backend, make):
    """Symmetric-indefinite (SPD block) and unsymmetric saddle-point systems with a zero diagonal
    block: the dense solution; ``splu``'s determinant sign is the dense one's."""
    A = saddle_point(make(), 12)
    assert np.all(A.diagonal()[-12:] == 0.0)
    b = np.random.default_rng(7).standard_normal(A.shape[0])
    x_dense = np.linalg.solve(A.toarray(), b)
    f = linsolve.factorize(A, backend)
    np.testing.assert_allclose(f.solve(b), x_dense, rtol=1e-9, atol=1e-11 * np.abs(x_dense).max())
    if hasattr(f, "det_sign"):
        assert f.det_sign() == np.sign(np.linalg.det(A.toarray()))


def test_auto_factorises_small_saddle_systems_dense(monkeypatch):
    """``auto``: saddle-point systems up to ``DENSE_MAX_UNKNOWNS`` = 256 unknowns (0: none) by LAPACK's dense LU
    (the small contact scenes' condensed systems fill in, SuperLU costs 2.6x); larger ones, and plain matrices of any
    size, by SuperLU.
    The dense factor solves one and several right-hand sides as splu does, to round-off, and its determinant sign is
    the dense determinant's, also with an odd number of row interchanges."""
    n = linsolve.DENSE_MAX_UNKNOWNS
    assert n == 256
    monkeypatch.setattr(linsolve, "DENSE_MAX_UNKNOWNS", 0)
    assert linsolve.Solver("auto").backend_for(saddle_point(nonsymmetric_matrix(40), 12), saddle=True) == "splu"
    monkeypatch.setattr(linsolve, "DENSE_MAX_UNKNOWNS", n)
    for size, saddle, backend in ((n, True, "dense"), (n + 1, True, "splu"), (60, False, "splu")):
        A = saddle_point(nonsymmetric_matrix(size - 12), 12)
        assert linsolve.Solver("auto").backend_for(A, saddle=saddle) == backend
        f = linsolve.Solver("auto").factorize(A, saddle=saddle)
        assert f.backend == backend
        B = np.random.default_rng(3).standard_normal((size, 3))
        np.testing.assert_allclose(f.solve(B), linsolve.factorize(A, "splu").solve(B), rtol=1e-10, atol=1e-12)
    P = sp.csc_matrix(np.eye(5)[[1, 0, 2, 3, 4]] * 2.0 + np.triu(np.ones((5, 5)), 1) * 0.1)
    f = linsolve.factorize(P, "dense")
    assert f.det_sign() == np.sign(np.linalg.det(P.toarray())) == -1
    assert f.factor_nnz == 25


def test_saddle_point_auto_coupled():
    """A coupled saddle-point system large enough for ``auto``'s coupled back-end (PARDISO if installed,
    else splu-rcm): the same solution as splu, also after a re-factorisation with the same pattern."""
    A = saddle_point(coupled_matrix(), 200)
    s = linsolve.Solver("auto")
    assert s.backend_for(A) == ("pardiso" if HAVE_PARDISO else "splu-rcm")
    b = np.random.default_rng(8).standard_normal(A.shape[0])
    ref = linsolve.factorize(A, "splu").solve(b)
    np.testing.assert_allclose(s.factorize(A).solve(b), ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())
    A2 = A.copy()
    A2.data[A2.indices < 2000] *= 1.5                      # new values, same pattern
    ref2 = linsolve.factorize(A2, "splu").solve(b)
    np.testing.assert_allclose(s.factorize(A2).solve(b), ref2, rtol=1e-9, atol=1e-12 * np.abs(ref2).max())
    s.close()


@pytest.mark.skipif(not HAVE_PARDISO, reason="pypardiso not installed")
def test_pardiso_solver_keeps_no_factor_the_caller_dropped():
    """A ``Solver`` remembers which factor PARDISO holds without keeping it (a weak reference): the
    caller's last factor and its matrix are freed as soon as the caller drops them (before the next
    tangent is assembled); a factor still held is re-factorised if another one came since.  (Without
    lagging: a lagged ``Solver`` keeps its last fresh factor as the preconditioner, test_lagged.py.)"""
    import gc
    import weakref
    s = linsolve.Solver("pardiso", lagged=False)
    A, B = nonsymmetric_matrix(seed=1), nonsymmetric_matrix(seed=3)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    f = s.factorize(A.copy())                  # the factor's matrix: held by nobody else
    f.solve(b)
    gone, matrix_gone = weakref.ref(f), weakref.ref(f.K)
    del f
    gc.collect()
    assert gone() is None and matrix_gone() is None
    fa, fb = s.factorize(A), s.factorize(B)
    np.testing.assert_allclose(fa.solve(b), np.linalg.solve(A.toarray(), b), rtol=1e-10)
    np.testing.assert_allclose(fb.solve(b), np.linalg.solve(B.toarray(), b), rtol=1e-10)
    s.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_saddle_point_systems_solve_on_every_backend(backend):
    """``factorize(K, saddle=True)``: a saddle-point matrix ``[[K, B], [B^T, 0]]`` (multiplier unknowns with a
    zero diagonal block, badly scaled against ``K`` as exact stick's) is solved to round-off by every back-end;
    PARDISO's pivot perturbation and refinement steps are those of ``SADDLE_*`` for it and the handle's own
    again for the next plain matrix."""
    rng = np.random.default_rng(3)
    n, m = 60, 15
    A = sp.random(n, n, density=0.1, random_state=rng) * 1e9
    K = sp.csr_matrix(A @ A.T + 1e9 * sp.eye(n))
    B = sp.random(n, m, density=0.2, random_state=rng) * 1e-3 + sp.eye(n, m) * 1e-3
    S = sp.csc_matrix(sp.bmat([[K, B], [B.T, None]]))
    b = rng.standard_normal(n + m)
    solver = linsolve.Solver(backend)
    x = solver.factorize(S, saddle=True).solve(b)

    def backward(M, x, b):
        return np.abs(M @ x - b).max() / (abs(M).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max())
    assert backward(S, x, b) <= 1e-14
    if backend == "pardiso":
        ps = solver._pardiso.ps
        assert (ps.iparm[7], ps.iparm[9]) == (linsolve.SADDLE_REFINE, linsolve.SADDLE_PERTURB)
        y = solver.factorize(sp.csc_matrix(K)).solve(b[:n])
        assert (ps.iparm[7], ps.iparm[9]) != (linsolve.SADDLE_REFINE, linsolve.SADDLE_PERTURB)
        assert backward(K, y, b[:n]) <= 1e-14


def test_mkl_library_is_found_without_pypardisos_recursive_search():
    """``linsolve._mkl_rt`` finds the MKL library pypardiso loads (a look-up in ``lib`` instead of pypardiso's
    recursive glob of the whole prefix, 1.0-1.3 s wall of start-up per process), in a subprocess so the import
    is the first; the solve works with it (the time: ``python benchmarks/jit_startup.py``)."""
    pytest.importorskip("pypardiso")
    import subprocess
    import sys
    code = ("import os, time, numpy as np, scipy.sparse as sp\n"
            "os.environ.pop('PYPARDISO_MKL_RT', None)\n"
            "from beamsolver.nonlinear import linsolve\n"
            "t = time.perf_counter(); m = linsolve._pypardiso(); dt = time.perf_counter() - t\n"
            "f = linsolve.Solver('pardiso').factorize(sp.csc_matrix(np.diag([2.0, 4.0])))\n"
            "print(os.environ.get('PYPARDISO_MKL_RT'), f.solve(np.array([2.0, 4.0])).tolist(), dt)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    path, x = out[0], out[1:3]
    assert "mkl_rt" in path and path == linsolve._mkl_rt()
    assert x == ["[1.0,", "1.0]"]


def test_splu_orders_saddle_point_systems_by_their_own_ordering(monkeypatch):
    """``splu`` factorises a saddle-point system (``saddle=True``) with ``SADDLE_SPLU_ORDERING`` (default
    MMD_AT_PLUS_A; COLAMD, faster on the main job's bordered tangents, 0.40 ms against 0.63, is the option) and a
    plain one with MMD_AT_PLUS_A, each solved to round-off with the dense determinant's sign."""
    import scipy.sparse.linalg as spla
    A = saddle_point(nonsymmetric_matrix(), 12)
    b = np.random.default_rng(9).standard_normal(A.shape[0])
    dense = A.toarray()
    assert linsolve.SADDLE_SPLU_ORDERING == "MMD_AT_PLUS_A"
    for option in ("MMD_AT_PLUS_A", "COLAMD"):
        monkeypatch.setattr(linsolve, "SADDLE_SPLU_ORDERING", option)
        for saddle, ordering in ((True, option), (False, "MMD_AT_PLUS_A")):
            f = linsolve.Solver("splu").factorize(A, saddle=saddle)
            assert np.array_equal(f._lu.perm_c, spla.splu(A, permc_spec=ordering).perm_c)
            x = f.solve(b)
            assert np.abs(A @ x - b).max() <= 1e-13 * (np.abs(dense).sum(axis=1).max() * np.abs(x).max())
            assert f.det_sign() == np.sign(np.linalg.det(dense))
    assert not np.array_equal(spla.splu(A, permc_spec="COLAMD").perm_c, spla.splu(A, permc_spec="MMD_AT_PLUS_A").perm_c)


@pytest.mark.skipif(not HAVE_PARDISO, reason="pypardiso not installed")
def test_pardiso_keeps_its_one_based_indices_per_pattern(monkeypatch):
    """``_Pardiso._call`` (``ONE_BASED``): PARDISO gets the analysed pattern's 1-based index arrays, made once per
    pattern (pypardiso's own call copies them twice at every phase): the same bits as pypardiso's call, and no
    copy at a re-factorisation or a solve on the same pattern; a new pattern is analysed with its own arrays."""
    made = []
    one_based = linsolve._one_based

    def counted(a):
        made.append(len(a))
        return one_based(a)
    A = nonsymmetric_matrix()
    A2 = A.copy()
    A2.data = A2.data * np.linspace(0.5, 2.0, A2.nnz)
    b = np.random.default_rng(3).standard_normal(A.shape[0])
    out = {}
    for flag in (False, True):
        monkeypatch.setattr(linsolve, "ONE_BASED", flag)
        monkeypatch.setattr(linsolve, "_one_based", counted)
        made.clear()
        s = linsolve.Solver("pardiso", lagged=False)
        x1 = s.factorize(A).solve(b)
        f2 = s.factorize(A2)
        x2, x3 = f2.solve(b), f2.solve(2.0 * b)
        assert len(made) == 2 and s.stats["analyses"] == 1       # indptr and indices, once
        B = A2 + sp.eye(A.shape[0], k=5, format="csc")             # a new pattern
        x4 = s.factorize(B).solve(b)
        assert len(made) == 4 and s.stats["analyses"] == 2
        assert s._pardiso._direct is flag
        out[flag] = (x1, x2, x3, x4)
        s.close()
    for x, y in zip(out[False], out[True]):
        assert np.array_equal(x, y)
    np.testing.assert_allclose(out[True][3], np.linalg.solve(B.toarray(), b), rtol=1e-10)


@pytest.mark.slow
def test_pardiso_frees_a_dropped_factor_and_keeps_the_bits():
    """``FREE_DROPPED``: once the caller drops a PARDISO factorisation (a ``Solver(lagged=False)``: nothing else
    keeps it), PARDISO's numerical factor is freed (phase 0) and its analysis kept: three matrices of one pattern,
    each factorised after the previous factor was dropped, give the solutions of a handle that keeps its factor,
    bit for bit, with one analysis; the handle holds no factorisation in between (issue 30: 1 GB on the 0.6 m
    rope).  In a child process with one MKL thread (PARDISO's results vary run to run with two)."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    if "pardiso" not in linsolve.available():
        pytest.skip("pypardiso is not installed")
    root = Path(linsolve.__file__).resolve().parents[2]
    env = dict(os.environ, MKL_NUM_THREADS="1", OMP_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run([sys.executable, "-c", _FREE_DROPPED_RUNS], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.split()[-1] == "same", r.stdout


_FREE_DROPPED_RUNS = """
import numpy as np, scipy.sparse as sp
from beamsolver.nonlinear import linsolve
n = 2000
A = (sp.random(n, n, 5e-3, format="csc", random_state=4) + 10.0 * sp.eye(n, format="csc")).tocsc()
A.sort_indices()
b = np.random.default_rng(3).standard_normal(n)
out = {}
for free in (False, True):
    linsolve.FREE_DROPPED = free
    s = linsolve.Solver("pardiso", lagged=False)
    xs = []
    for k in range(3):
        B = A.copy()
        B.data = B.data * (1.0 + 0.1 * k) + 0.01 * k
        f = s.factorize(B)
        xs += [f.solve(b), f.apply(b)]
        handle = f._owner
        del f
        assert handle.current() is None and (handle.current is linsolve._NONE) == free
    assert s.stats["analyses"] == 1, s.stats
    out[free] = xs
    s.close()
print("same" if all(np.array_equal(x, y) for x, y in zip(out[False], out[True])) else "different")
"""


@pytest.mark.skipif(not HAVE_PARDISO, reason="pypardiso not installed")
def test_pardiso_matching_off_from_a_size(monkeypatch):
    """``MATCHING_OFF_MIN``: PARDISO analyses a non-saddle matrix of at least that many unknowns without its weighted
    matching (from a fresh handle: MKL's defaults written first), a saddle-point one or a smaller one with it; the
    solutions are right either way; None keeps MKL's matching."""
    rng = np.random.default_rng(6)

    def matrix(n):
        A = sp.random(n, n, density=0.02, random_state=rng, format="csc") + sp.diags(4.0 + rng.random(n))
        return sp.csc_matrix(A)
    cases = [(matrix(120), False), (matrix(60), False), (matrix(120), True), (matrix(120), False)]
    for off, expect in ((100, (0, 1, 1, 0)), (None, (1, 1, 1, 1))):
        monkeypatch.setattr(linsolve, "MATCHING_OFF_MIN", off)
        s = linsolve.Solver("pardiso", lagged=False)
        got = []
        for A, saddle in cases:
            b = rng.standard_normal(A.shape[0])
            f = s.factorize(A, saddle=saddle)
            got.append(int(s._pardiso.ps.iparm[12]))
            x = f.solve(b)
            assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)
        assert tuple(got) == expect
        s.close()
