"""Compiled kernels of the Newton direction's glue against their numpy forms, bit for bit: ``condense._schur`` (the
Schur terms of the eliminated components) and ``augmented._scatter_rows`` (``Kq y`` of the augmented solve)."""
import numpy as np

from beamsolver.nonlinear import augmented, condense


def _schur_plain(vals, off, Kql, Klq, w):
    """The Schur terms component after component over the whole block (the former kernel's order)."""
    g, k6 = Kql.shape[:2]
    blocks = vals[off:off + g * k6 * k6].reshape(g, k6, k6)
    for i in range(g):
        for j in range(3):
            if w[i, j] == 0.0:
                continue
            for a in range(k6):
                c = w[i, j] * Kql[i, a, j]
                if c != 0.0:
                    blocks[i, a] -= c * Klq[i, j]


def test_schur_terms_are_the_component_by_component_sums():
    """One pass per block row, the components in order (none, one, two or three of them; zero products skipped):
    the bits of subtracting them one component after the other."""
    rng = np.random.default_rng(3)
    g, k6 = 40, 24
    Kql, Klq = rng.standard_normal((g, k6, 3)), rng.standard_normal((g, 3, k6))
    w = rng.standard_normal((g, 3))
    w[rng.random((g, 3)) < 0.4] = 0.0
    Kql[rng.random((g, k6, 3)) < 0.1] = 0.0
    vals = rng.standard_normal(7 + g * k6 * k6)
    ref = vals.copy()
    _schur_plain(ref, 7, Kql, Klq, w)
    condense._schur(vals, 7, Kql, Klq, w)
    assert np.array_equal(vals, ref)


def test_scatter_rows_is_numpy_s_bincount():
    """``Kq y`` on the rows of the kept components' slots (repeated rows summed in order): ``np.bincount``'s bits."""
    rng = np.random.default_rng(5)
    u, k6, n = 30, 24, 50
    rows = rng.integers(0, n, (u, k6))
    Kq, y = rng.standard_normal((u, k6)), rng.standard_normal(u)
    out = np.zeros(n)
    augmented._scatter_rows(rows, Kq, y, out)
    assert np.array_equal(out, np.bincount(rows.ravel(), weights=(Kq * y[:, None]).ravel(), minlength=n))


def test_augmented_products_and_preconditioner_are_the_numpy_formulas():
    """``Augmented.matvec`` and ``precondition`` (compiled ``_join``, ``_precondition_rhs``, ``_precondition_out``)
    give the bits of the module's formulas in numpy (``np.bincount`` for ``Kq y``, ``np.where``), plain, augmented
    and idle rows, held slots."""
    import scipy.sparse as sp
    rng = np.random.default_rng(7)
    n, u, k6 = 60, 12, 24
    K = sp.random(n, n, density=0.1, random_state=rng, format="csc") + sp.eye(n, format="csc")
    rows = rng.integers(-1, n, (u, k6))
    Kq, Kl = rng.standard_normal((u, k6)), rng.standard_normal((u, k6))
    idle = np.zeros(u, dtype=bool)
    idle[2] = True
    E, p22 = rng.standard_normal(u), rng.standard_normal(u)
    E[[0, 5]] = 0.0
    D = rng.standard_normal(u)
    a = augmented.Augmented(K, K, None, None, Kq, Kl, rows, D, E, p22, idle, direct=None)
    free = rows >= 0
    r0, Q, L = np.where(free, rows, 0), np.where(free, Kq, 0.0), np.where(free, Kl, 0.0)
    Lp = np.where(idle[:, None], 0.0, L)

    def kq(y):
        return np.bincount(r0.ravel(), weights=(Q * y[:, None]).ravel(), minlength=n)

    def kl(x, M):
        return np.einsum("ua,ua->u", M, x[r0])
    x = rng.standard_normal(n + u)
    ref = np.concatenate([K @ x[:n] + kq(x[n:]), kl(x[:n], L) + D * x[n:]])
    assert np.array_equal(a.matvec(x), ref)
    apply = np.sin                                     # any map of the right-hand side
    plain = E == 0.0
    vf, vg = x[:n], x[n:]
    db0 = np.where(plain, vg / p22, 0.0)
    du = apply(vf + kq(np.where(plain, -db0, E * vg)))
    ref = np.concatenate([du, np.where(plain, db0, E * (kl(du, Lp) - vg))])
    assert np.array_equal(a.precondition(x, apply), ref)


def test_scatter_free_is_numpy_s_masked_bincount():
    """The eliminated components' right-hand side terms on the groups' free rows (held slots ``-1`` skipped, repeated
    rows summed in order): ``np.bincount(rows[free], weights=vals[free])``'s bits."""
    rng = np.random.default_rng(6)
    rows, vals = rng.integers(-1, 40, (25, 24)), rng.standard_normal((25, 24))
    out = np.zeros(40)
    condense.scatter_free(rows, vals, out)
    free = rows >= 0
    assert np.array_equal(out, np.bincount(rows[free], weights=vals[free], minlength=40))


def _weights_numpy(Kq, Kl, free, kdiag, d, idle):
    """``augmented.weights`` in numpy (its former form, the oracle)."""
    use = free & (kdiag > 0.0)
    p = Kq * Kl / np.where(use, kdiag, 1.0)
    p = np.where(use, p, 0.0)
    scale = np.abs(p).max(axis=1, initial=0.0)
    sign = np.sign(p.sum(axis=1))
    coupled = ~idle & (scale > 0.0) & (sign != 0.0)
    E = np.where(coupled, sign * augmented.RATIO / np.where(coupled, scale, 1.0), 0.0)
    inv = np.where(coupled, 1.0 / np.where(coupled, E, 1.0), 0.0)
    p22 = np.where(E * d < 0.0, d - inv, -inv)
    p22 = np.where(coupled, p22, np.where(idle | (d == 0.0), 1.0, d))
    E = np.where(coupled, -1.0 / np.where(coupled, p22, 1.0), 0.0)
    return E, p22


def test_weights_are_the_numpy_formulas():
    """``augmented.weights`` (compiled but for the rows' sums) gives numpy's bits: coupled rows of either sign, with
    ``d`` of either sign or zero, idle rows, rows without free slots or stiffness."""
    rng = np.random.default_rng(9)
    u, k6 = 40, 24
    Kq, Kl = rng.standard_normal((u, k6)), rng.standard_normal((u, k6))
    free = rng.random((u, k6)) < 0.8
    free[3] = False
    kdiag = rng.random((u, k6)) * 10.0 ** rng.integers(-3, 3, (u, k6))
    kdiag[4] = 0.0
    kdiag[rng.random((u, k6)) < 0.05] = -1.0
    d = np.where(rng.random(u) < 0.3, 0.0, rng.standard_normal(u) * 0.05)
    idle = rng.random(u) < 0.1
    E, p22 = augmented.weights(Kq, Kl, free, kdiag, d, idle)
    E0, p220 = _weights_numpy(Kq, Kl, free, kdiag, d, idle)
    assert np.array_equal(E, E0) and np.array_equal(p22, p220)
    assert (E != 0.0).sum() > u // 2 and (E == 0.0).sum() > 3
