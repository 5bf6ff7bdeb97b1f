"""The previous factorisation as a preconditioner (``nonlinear.lagged``, ``linsolve.Solver(lagged=)``)."""
import numpy as np
import pytest
import scipy.sparse as sp

from beamsolver.errors import InputError
from beamsolver.nonlinear import lagged, linsolve

import rolling

HAVE_PARDISO = "pardiso" in linsolve.available()
BACKENDS = ["splu", "splu-rcm", pytest.param("pardiso", marks=pytest.mark.skipif(not HAVE_PARDISO,
                                                                                 reason="pypardiso not installed")),
            "dense"]


def matrix(n=300, seed=1):
    """Sparse, non-symmetric, diagonally dominant."""
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.03, random_state=rng).tolil()
    A.setdiag(np.abs(A).sum(axis=1).A1 + 1.0)
    return sp.csc_matrix(A)


def perturbed(A, size, seed=3):
    """``A`` with its values changed by a relative ``size`` (same pattern)."""
    B = A.copy()
    B.data = B.data * (1.0 + size * np.random.default_rng(seed).uniform(-1.0, 1.0, B.nnz))
    return B


def assert_close(x, y, rtol):
    """Norm-wise: ``|x - y| <= rtol |y|``."""
    assert np.linalg.norm(x - y) <= rtol * np.linalg.norm(y), np.linalg.norm(x - y) / np.linalg.norm(y)


def test_gmres_solves_with_a_nearby_factor():
    A = matrix()
    B = perturbed(A, 1e-2)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    lu = linsolve.factorize(A, "splu")
    x, its, ok = lagged.gmres(B.__matmul__, lu.solve, b, 1e-12, 30)
    assert ok and 1 <= its <= 8
    assert_close(x, np.linalg.solve(B.toarray(), b), 1e-10)


def test_gmres_reports_no_convergence_within_its_budget():
    A = matrix()
    b = np.ones(A.shape[0])
    x, its, ok = lagged.gmres(A.__matmul__, lambda v: v, b, 1e-12, 3)       # no preconditioner, 3 iterations
    assert not ok and its == 3
    assert np.linalg.norm(A @ x - b) > 1e-12 * np.linalg.norm(b)


def test_gmres_gives_up_on_a_hopeless_preconditioner():
    """A 1-D Laplacian without preconditioner: GMRES needs ~n iterations (condition ~n^2)."""
    n = 300
    A = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csc")
    b = np.random.default_rng(2).standard_normal(n)
    x, its, ok = lagged.gmres(A.__matmul__, lambda v: v, b, 1e-10, 30)
    assert not ok and its == lagged.GIVE_UP_AFTER


@pytest.mark.parametrize("backend", BACKENDS)
def test_lagged_solve_equals_the_direct_one(backend):
    A = matrix()
    B = perturbed(A, 1e-3)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    s = linsolve.Solver(backend, lagged=True)
    s.factorize(A).solve(b)
    f = s.factorize(B)
    x = f.solve(b)
    assert isinstance(f, lagged.LaggedFactor) and f.iterations >= 1
    assert s.stats["factorizations"] == 1 and s.stats["lagged"] == 1 and s.stats["lag_failures"] == 0
    assert np.linalg.norm(B @ x - b) <= lagged.LAG_RTOL * np.linalg.norm(b)
    assert_close(x, linsolve.factorize(B, backend).solve(b), 1e-9)
    s.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_far_matrix_is_factorised_afresh(backend):
    """A tangent far from the preconditioner's: GMRES gives up, the matrix is factorised, the solve is exact,
    and the new factor preconditions the next matrix."""
    A, C = matrix(), matrix(seed=7)
    b = np.ones(A.shape[0])
    s = linsolve.Solver(backend, lagged=True)
    s.factorize(A)
    x = s.factorize(C).solve(b)
    assert s.stats["factorizations"] == 2 and s.stats["lag_failures"] == 1
    assert_close(x, np.linalg.solve(C.toarray(), b), 1e-10)
    f = s.factorize(perturbed(C, 1e-4))
    f.solve(b)
    assert s.stats["factorizations"] == 2 and f.iterations <= 4       # preconditioned by C's factor
    s.close()


def test_failed_lagged_solves_back_off():
    """Lagged solves failing in a row: 0, 1, 2 fresh factorisations before the next try; a success resets."""
    s = linsolve.Solver("splu", lagged=True)
    b = np.ones(300)
    s.factorize(matrix(seed=0))
    kinds = []
    for seed in range(1, 8):                                  # every matrix far from the one before
        f = s.factorize(matrix(seed=seed))
        f.solve(b)
        kinds.append(isinstance(f, lagged.LaggedFactor))
    assert kinds == [True, True, False, True, False, False, True], kinds
    near = perturbed(matrix(seed=7), 1e-6)
    kinds = [isinstance(s.factorize(near), lagged.LaggedFactor) for _ in range(4)]
    assert kinds == [False] * 4                                               # four skipped after 4 failures
    f = s.factorize(perturbed(near, 1e-6))
    f.solve(b)
    assert isinstance(f, lagged.LaggedFactor) and f.direct is None          # a success ...
    f = s.factorize(matrix(seed=8))
    f.solve(b)
    assert f.direct is not None
    assert isinstance(s.factorize(matrix(seed=9)), lagged.LaggedFactor)     # ... and the back-off starts over


def test_slow_lagged_solve_refreshes_the_next_factor():
    """A lagged solve that took more than ``LAG_REFRESH_SHARE`` of its budget: the next tangent is factorised."""
    A = matrix()
    s = linsolve.Solver("splu", lagged=True)
    s.factorize(A)
    b = np.ones(A.shape[0])
    f = s.factorize(perturbed(A, 0.6))
    f.solve(b)
    assert f.iterations > linsolve.LAG_REFRESH_SHARE * linsolve.LAG_MAX_ITERATIONS, f.iterations
    assert not isinstance(s.factorize(perturbed(A, 0.6, seed=4)), lagged.LaggedFactor)
    assert s.stats["factorizations"] == 2


def test_det_sign_of_a_lagged_factor_is_its_own_matrix():
    A = matrix()
    s = linsolve.Solver("splu", lagged=True)
    s.factorize(A)
    B = A.copy()
    B[0, 0] = -B[0, 0] * 3.0                                   # one row turned: the determinant changes sign
    assert linsolve.factorize(A, "splu").det_sign() == -linsolve.factorize(B, "splu").det_sign()
    f = s.factorize(sp.csc_matrix(B))
    assert f.det_sign() == linsolve.factorize(B, "splu").det_sign()


def test_auto_lags_only_expensive_factorisations():
    """``lagged="auto"``: no lagging for a cheap factorisation (a small matrix, splu without flops);
    a budget from PARDISO's flops and fill, ``LAG_COST_SHARE`` of a re-factorisation."""
    A = matrix()
    s = linsolve.Solver("splu")
    s.factorize(A)
    assert not isinstance(s.factorize(perturbed(A, 1e-6)), lagged.LaggedFactor)

    class F:
        flops, factor_nnz = 48.2e9, 48.5e6          # the 61-wire bundle's tangent (docs/benchmarks.md)
    assert s.lag_budget(F) == 24 and s.lag_budget(F, analysis=True) == 30
    F.flops, F.factor_nnz = 0.816e9, 5.89e6         # the 61-wire strand's: a cheap re-factorisation
    assert s.lag_budget(F) == 0 and s.lag_budget(F, analysis=True) == 11
    assert linsolve.Solver("splu", lagged=False).lag_budget(F, analysis=True) == 0
    F.flops, F.factor_nnz = 0.5 * linsolve.LAG_MIN_FLOPS, 1e4     # expensive per entry, cheap in all
    assert s.lag_budget(F, analysis=True) == 0


def test_bad_lagged_option():
    with pytest.raises(InputError, match="lagged"):
        linsolve.Solver(lagged="yes")


@pytest.fixture(scope="module")
def rolled_lagged():
    """The frictional rolling scene with every tangent after the first lagged (budget 30), and plain."""
    counts = []
    orig = linsolve.Solver.lagged_done

    def spy(self, iterations, budget, converged):
        counts.append((iterations, converged))
        return orig(self, iterations, budget, converged)
    mp = pytest.MonkeyPatch()
    mp.setattr(linsolve, "LAGGED", True)
    mp.setattr(linsolve.Solver, "lagged_done", spy)
    try:
        lag = rolling.main(mu=0.5, theta=1.0, steps=11)
    finally:
        mp.undo()
    return lag, rolling.main(mu=0.5, theta=1.0, steps=11), counts


def test_lagged_newton_stays_quadratic_with_friction(rolled_lagged):
    (_, _, _, sol), _, counts = rolled_lagged
    assert sum(ok for _, ok in counts) >= 10                  # lagged solves did happen
    r = [np.log(b) / np.log(a) for s in sol.stats[2:] for a, b in zip(s["residuals"][:-1], s["residuals"][1:])
         if a < 1e-2 and 1e-10 < b < a]
    assert len(r) >= 5 and min(r) > 1.8, r
    assert max(sol.iterations[2:]) <= 5


def test_lagged_newton_reaches_the_direct_solution(rolled_lagged):
    (d, exact, ft, sol), (d0, _, ft0, sol0), _ = rolled_lagged
    np.testing.assert_array_equal(sol.iterations, sol0.iterations)
    np.testing.assert_allclose(d, d0, rtol=1e-9)
    np.testing.assert_allclose(ft, ft0, rtol=1e-7)


def test_a_factor_of_another_kind_does_not_precondition():
    """``factorize(kind=)``: the augmented matrix of exact stick (``augmented``) and a plain tangent of the same
    shape do not precondition each other (each switch factorises afresh); within one kind the factor lags."""
    A = matrix()
    s = linsolve.Solver("splu", lagged=True)
    s.factorize(A)
    assert not isinstance(s.factorize(perturbed(A, 1e-4), kind="augmented"), lagged.LaggedFactor)
    assert isinstance(s.factorize(perturbed(A, 2e-4), kind="augmented"), lagged.LaggedFactor)
    assert not isinstance(s.factorize(perturbed(A, 3e-4)), lagged.LaggedFactor)
    assert s.stats["factorizations"] == 3 and s.stats["lagged"] == 1
    s.close()


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_dropped_base_is_let_go_and_the_next_matrix_factorised_afresh(backend):
    """``Solver.drop_base`` (the stepping's, at every accepted step: ``DROP_BASE_AT_COMMIT``): the base is no longer
    referenced (PARDISO frees its numerical factor), the next matrix, near the old base's, is factorised afresh
    (its solve exact), and that factor preconditions the one after."""
    import gc
    import weakref
    A = matrix()
    b = np.ones(A.shape[0])
    s = linsolve.Solver(backend, lagged=True)
    s.factorize(A).solve(b)
    base = weakref.ref(s._base)
    s.drop_base()
    gc.collect()
    assert base() is None
    B = perturbed(A, 1e-4)
    f = s.factorize(B)
    assert not isinstance(f, lagged.LaggedFactor) and s.stats["factorizations"] == 2
    assert_close(f.solve(b), np.linalg.solve(B.toarray(), b), 1e-10)
    g = s.factorize(perturbed(B, 1e-4))
    g.solve(b)
    assert isinstance(g, lagged.LaggedFactor) and g.direct is None and s.stats["factorizations"] == 2
    s.close()
