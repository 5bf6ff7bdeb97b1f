"""The compiled scatters of the mortar groups (contact/mortar_jit.py) against their numpy oracle (``np.add.at``):
the same bits, repeated rows within a point and points of one group included."""
import numpy as np
import pytest

from beamsolver.contact import mortar_jit


def _case(seed, P=60, n=7, r=30, m=24):
    rng = np.random.default_rng(seed)
    g = rng.integers(0, n, P)
    rows = rng.integers(0, r, (P, m))           # repeats within a point and across points of a group
    return rng, g, rows, n, r, m


@pytest.mark.parametrize("seed", range(3))
def test_scatter_rows_gives_the_bits_of_add_at(seed):
    rng, g, rows, n, r, m = _case(seed)
    vals, scale = rng.standard_normal((len(g), m, 3)), rng.standard_normal(len(g))
    start = rng.standard_normal((n, r, 3))
    for s in (None, scale):
        a = mortar_jit.scatter_rows_numpy(start.copy(), g, rows, vals, s)
        b = mortar_jit.scatter_rows(start.copy(), g, rows, vals, s)
        assert np.array_equal(a, b) and not np.array_equal(a, start)
    flat = rng.standard_normal((len(g), m))
    a = mortar_jit.scatter_rows_numpy(np.zeros((n, r)), g, rows, flat)
    b = mortar_jit.scatter_rows(np.zeros((n, r)), g, rows, flat)
    assert np.array_equal(a, b) and np.any(a)


@pytest.mark.parametrize("seed", range(3))
def test_scatter_block_and_columns_give_the_bits_of_add_at(seed):
    rng, g, rows, n, r, m = _case(seed)
    vals = rng.standard_normal((len(g), m, m))
    a = mortar_jit.scatter_block_numpy(np.zeros((n, r, r)), g, rows, vals)
    b = mortar_jit.scatter_block(np.zeros((n, r, r)), g, rows, vals)
    assert np.array_equal(a, b) and np.any(a)
    cv = rng.standard_normal((len(g), 3, m))
    a = mortar_jit.scatter_columns_numpy(np.zeros((n, 3, r)), g, rows, cv)
    b = mortar_jit.scatter_columns(np.zeros((n, 3, r)), g, rows, cv)
    assert np.array_equal(a, b) and np.any(a)


def test_the_mortar_blocks_are_those_of_the_numpy_scatters():
    """``mortar.multiplier_blocks`` on a random group set: the compiled scatters give the oracle's bits, the compiled
    trial rows (``mortar_jit.trial_rows``, products summed in another order) its values to round-off."""
    from beamsolver.contact import mortar
    rng = np.random.default_rng(5)
    P, n_nodes = 40, 12
    slave = np.sort(rng.choice(n_nodes, (P, 2), replace=True), axis=1)
    nodes = np.concatenate([slave, rng.integers(0, n_nodes, (P, 2))], axis=1)
    G = mortar.groups(slave, rng.uniform(0, 1, P), rng.integers(0, 2, P), np.zeros(P, int), nodes, n_nodes, 2)
    k = len(G["key"])
    d = dict(G=rng.standard_normal((P, 24, 3)), dfdq=rng.standard_normal((P, 24, 24)),
             f=rng.standard_normal((P, 24)), dS=rng.standard_normal((P, 3, 24)), dn=rng.standard_normal((P, 3, 24)),
             dlam_n=rng.standard_normal((P, 24)))
    R = np.linalg.qr(rng.standard_normal((k, 3, 3)))[0]
    st = mortar.nodal_state(G, rng.uniform(0.1, 1, P), rng.standard_normal((P, 3)), rng.uniform(0, 1, P),
                            rng.standard_normal((P, 3)), R, rng.standard_normal((k, 3)), np.ones(k), 0.3 * np.ones(k),
                            rng.uniform(1, 2, k))
    args = (G, d, st, R, rng.standard_normal((k, 3)), np.ones(k), 0.3 * np.ones(k))
    try:
        mortar.use_numpy_scatter(True)
        ref = mortar.multiplier_blocks(*args), mortar.blocks(*args)
    finally:
        mortar.use_numpy_scatter(False)
    out = mortar.multiplier_blocks(*args), mortar.blocks(*args)
    exact = {0, 2, 4, 5, 6}             # f, Kql, Kll, C, the updates' f: no trial rows in them
    for i, (a, b) in enumerate(zip(ref[0] + ref[1], out[0] + out[1])):
        if i in exact:
            assert np.array_equal(a, b), i
        else:
            assert np.abs(a - b).max() <= 1e-14 * np.abs(a).max() and np.any(a != 0), i


def test_groups_are_kept_while_the_pairs_nodes_hold():
    """``mortar.Groups``: the groups of ``mortar.groups`` for new ``xi1`` on the same pairs (one build), built
    again when a pair's nodes or its held flags change."""
    from beamsolver.contact import mortar
    rng = np.random.default_rng(2)
    P, n_nodes = 30, 10
    slave = np.sort(rng.choice(n_nodes, (P, 2)), axis=1)
    nodes = np.concatenate([slave, rng.integers(0, n_nodes, (P, 2))], axis=1)
    beam, decl, held = rng.integers(0, 2, P), np.zeros(P, int), rng.random((P, 2)) < 0.2
    keep = mortar.Groups()

    def check(*args):
        ref, out = mortar.groups(*args), keep(*args)
        assert set(ref) == set(out)
        for k in ref:
            assert np.array_equal(ref[k], out[k]), k
    x0 = rng.uniform(0.01, 0.99, P)          # the points move a little within a Newton step: no sliver appears
    for _ in range(3):
        check(slave, x0 + 1e-6 * rng.uniform(-1, 1, P), beam, decl, nodes, n_nodes, 2, held)
    assert keep.builds == 1
    nodes = nodes.copy()
    nodes[0, 3] = (nodes[0, 3] + 1) % n_nodes
    check(slave, rng.uniform(0, 1, P), beam, decl, nodes, n_nodes, 2, held)
    held = held.copy()
    held[1] = ~held[1]
    check(slave, rng.uniform(0, 1, P), beam, decl, nodes, n_nodes, 2, held)
    assert keep.builds == 3
    # a point that moves far enough to make or unmake a sliver group (``mortar.slivers``): built again
    x1 = rng.uniform(0, 1, P)
    fold = mortar.fold_of(slave, x1, beam, decl, n_nodes, 2, held)
    x2 = x1.copy()
    for p in range(P):
        x2[p] = 1.0 - x1[p]
        if not np.array_equal(mortar.fold_of(slave, x2, beam, decl, n_nodes, 2, held), fold):
            break
        x2[p] = x1[p]
    check(slave, x1, beam, decl, nodes, n_nodes, 2, held)
    check(slave, x2, beam, decl, nodes, n_nodes, 2, held)
    assert not np.array_equal(x1, x2) and keep.builds == 5


def _nodal_case(seed, P=50, n_nodes=12):
    from beamsolver.contact import mortar
    rng = np.random.default_rng(seed)
    slave = np.sort(rng.choice(n_nodes, (P, 2), replace=True), axis=1)
    nodes = np.concatenate([slave, rng.integers(0, n_nodes, (P, 2))], axis=1)
    G = mortar.groups(slave, rng.uniform(0, 1, P), rng.integers(0, 2, P), np.zeros(P, int), nodes, n_nodes, 2)
    k = len(G["key"])
    lam_n = np.where(rng.random(P) < 0.3, 0.0, rng.uniform(0, 1, P))     # points without pressure
    R = np.linalg.qr(rng.standard_normal((k, 3, 3)))[0]
    # multipliers from small (sticking) to large (sliding), some zero
    Lam = rng.standard_normal((k, 3)) * np.where(rng.random(k) < 0.5, 1e-3, 1.0)[:, None]
    Lam[rng.random(k) < 0.2] = 0.0
    args = (G, rng.uniform(0.1, 1, P), 1e-3 * rng.standard_normal((P, 3)), lam_n, rng.standard_normal((P, 3)), R, Lam,
            rng.uniform(0.5, 2, k), 0.3 * np.ones(k), rng.uniform(1, 2, k))
    return args, rng


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("variant", ["newton", "updates"])
def test_compiled_nodal_state_is_the_numpy_form(seed, variant):
    """``mortar.nodal_state`` (one compiled pass, ``mortar_jit.nodal_state``) against its numpy form: the sums of
    ``np.bincount`` to the bit, the projected and mapped values to round-off (``np.einsum``'s order of a 3-term sum
    depends on the machine's vector width), the stick / weak decisions the same; with the updates' active points
    and with the Newton path's hold stiffness (touching groups without pressure)."""
    from beamsolver.contact import mortar
    args, rng = _nodal_case(seed)
    P, k = len(args[1]), len(args[-1])
    kw = dict(active=rng.random(P) < 0.7) if variant == "updates" else dict(hold=np.where(rng.random(k) < 0.5, 5.0, 0.0))
    ref, out = mortar.nodal_state_numpy(*args, **kw), mortar.nodal_state(*args, **kw)
    assert set(out) == set(ref)
    for key in ("wn", "wphi", "lamN", "stick", "weak", "m"):
        assert np.array_equal(out[key], ref[key]), key
    for key in set(ref) - {"wn", "wphi", "lamN", "stick", "weak", "m"}:
        scale = np.abs(ref[key]).max()
        assert np.abs(out[key] - ref[key]).max() <= 1e-14 * scale, key
    assert ref["stick"].any() and (~ref["stick"]).any()
    if variant == "newton":
        assert ref["weak"].any()


def test_point_terms_and_point_data_are_the_numpy_forms():
    """``mortar_jit.point_terms`` (the mortar kernel's ``A``, ``dS``, ``dn``, ``dlam_n`` in one pass) gives the bits of
    the numpy expressions it replaced; ``mortar_jit.point_data`` the tangential traction and stick flags of
    ``system._point_data``'s numpy form."""
    from beamsolver.contact import mortar_jit
    rng = np.random.default_rng(3)
    P = 37
    df, rows = rng.standard_normal((3, P, 4, 6)), rng.standard_normal((P, 12, 24))
    vec, s = rng.standard_normal((P, 6, 3)), rng.standard_normal((P, 2, 2))[:, 1]
    t1, t2 = vec[:, 1], vec[:, 2]
    A, dS, dn, dlam = mortar_jit.point_terms(df, rows, t1, t2, s)
    assert np.array_equal(A, np.transpose(df, (1, 2, 3, 0)).reshape(P, 24, 3))
    assert np.array_equal(dS, t1[:, :, None] * rows[:, None, 9] + s[:, 0, None, None] * rows[:, 3:6]
                          + t2[:, :, None] * rows[:, None, 10] + s[:, 1, None, None] * rows[:, 6:9])
    assert np.array_equal(dn, rows[:, 0:3]) and np.array_equal(dlam, rows[:, 11])
    T, n = rng.standard_normal((P, 3)), rng.standard_normal((P, 3))
    g2 = rng.integers(0, 9, (P, 2))
    stick, phi = rng.random(9) < 0.5, np.where(rng.random((P, 2)) < 0.2, 0.0, rng.random((P, 2)))
    lam_t, held = mortar_jit.point_data(T, n, t1, t2, stick, g2, phi)
    Tt = T - np.sum(T * n, axis=1)[:, None] * n
    ref = np.stack([np.sum(Tt * t1, axis=1), np.sum(Tt * t2, axis=1)], axis=1)
    assert np.abs(lam_t - ref).max() <= 1e-15 * np.abs(ref).max()
    assert np.array_equal(held, (stick[g2] | (phi == 0.0)).all(axis=1)) and held.any() and not held.all()


@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_multiplier_basis_is_the_numpy_form(seed):
    """``mortar.multiplier_basis`` compiled (``mortar_jit.multiplier_basis``) against its numpy form on sticking,
    sliding and weak groups: the same bits (the condensation's basis: the Newton step depends on it), orthonormal."""
    from beamsolver.contact import mortar
    args, rng = _nodal_case(seed)
    k = len(args[-1])
    st = mortar.nodal_state(*args, hold=np.where(rng.random(k) < 0.5, 5.0, 0.0))
    out = mortar.multiplier_basis(st)
    try:
        mortar.use_numpy_scatter(True)
        ref = mortar.multiplier_basis(st)
    finally:
        mortar.use_numpy_scatter(False)
    assert np.array_equal(out, ref)
    assert np.abs(np.einsum("gji,gjk->gik", out, out) - np.eye(3)).max() < 1e-14
    slide = ~st["stick"] & ~st["weak"]
    assert slide.any() and st["stick"].any() and st["weak"].any()


def _sliver_inputs(rng, P):
    """Keys ``(P, 2)`` of points on slave elements ``(j, j + 1)`` against 3 master beams, some with a held node (both
    keys equal), shape functions near 0 and 1 (slivers) and some single points with equal shares (the ties)."""
    el = rng.integers(0, 6, P)
    slave = np.stack([el, el + 1], axis=1)
    held = rng.uniform(size=P) < 0.15
    slave[held, 1] = slave[held, 0]
    beam = rng.integers(0, 3, P)
    xi1 = rng.choice([0.047, 0.5, 0.953, 0.2, 0.8], P) if rng.uniform() < 0.5 else rng.uniform(0.0, 1.0, P)
    key = (slave.astype(np.int64)) * 3 + beam[:, None]
    return key, slave, xi1


@pytest.mark.parametrize("seed", range(40))
def test_compiled_slivers_are_the_numpy_ones(seed):
    """``mortar_jit.slivers`` gives ``mortar.slivers``' flags (groups by a stable sort, shares summed in the points'
    order) on random groups with slivers, held nodes and single points of equal shares, at two ratios."""
    from beamsolver.contact import mortar
    rng = np.random.default_rng(seed)
    key, slave, xi1 = _sliver_inputs(rng, int(rng.integers(1, 40)))
    for ratio in (mortar.SLIVER, 0.6):
        old = mortar.SLIVER
        mortar.SLIVER = ratio
        try:
            ref = mortar.slivers(key, slave, xi1)
        finally:
            mortar.SLIVER = old
        assert np.array_equal(mortar_jit.slivers(key, slave, xi1, ratio), ref)


def test_compiled_slivers_see_every_kind_of_fold():
    """The random groups of ``test_compiled_slivers_are_the_numpy_ones`` hold slivers by ratio and single points
    folded by the tie rule (the test is not passed by empty flags), and no points give no flags."""
    from beamsolver.contact import mortar
    folds = ties = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        key, slave, xi1 = _sliver_inputs(rng, int(rng.integers(1, 40)))
        folds += int(mortar.slivers(key, slave, xi1).sum())
        one = np.array([[key[0, 0], key[0, 0] + 3]]), np.array([[0, 1]]), np.array([0.5])
        ties += int(mortar_jit.slivers(*one, mortar.SLIVER).sum())
    assert folds > 20 and ties == 40
    assert mortar_jit.slivers(np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2), dtype=np.int64), np.zeros(0),
                              mortar.SLIVER).shape == (0, 2)


def _trial_rows_plain(B, g2, rows2, wphi, wn, m, eps, mu, Pi, Q, C, c, dS, dn, dlam_n):
    """The former compiled ``_trial_rows`` in Python: every entry read where it is used (its order of operations)."""
    for p in range(g2.shape[0]):
        for a in range(2):
            g = g2[p, a]
            wg, wgn = wphi[p, a] / m[g], wn[p, a] / m[g]
            se, sm = eps[g] * wg, mu[g] * wg
            o = B[g]
            for k in range(24):
                t = [se * (Pi[g, i, 0] * dS[p, 0, k] + Pi[g, i, 1] * dS[p, 1, k] + Pi[g, i, 2] * dS[p, 2, k]) +
                     wgn * (Q[g, i, 0] * dn[p, 0, k] + Q[g, i, 1] * dn[p, 1, k] + Q[g, i, 2] * dn[p, 2, k])
                     for i in range(3)]
                r = rows2[p, a, k]
                for i in range(3):
                    o[i, r] += C[g, i, 0] * t[0] + C[g, i, 1] * t[1] + C[g, i, 2] * t[2] + sm * c[g, i] * dlam_n[p, k]


def _trial_case(seed, P=30, n=7, k6=36):
    rng = np.random.default_rng(seed)
    g2 = rng.integers(0, n, (P, 2))
    rows2 = rng.integers(0, k6, (P, 2, 24))
    f = rng.standard_normal
    args = dict(wphi=f((P, 2)), wn=f((P, 2)), m=rng.uniform(0.5, 2, n), eps=f(n), mu=f(n), Pi=f((n, 3, 3)),
                Q=f((n, 3, 3)), C=f((n, 3, 3)), c=f((n, 3)), dS=f((P, 3, 24)), dn=f((P, 3, 24)), dlam_n=f((P, 24)))
    for a in ("dS", "dn", "dlam_n"):                # zeros of both signs among the terms
        args[a][rng.random(args[a].shape) < 0.1] = 0.0
        args[a][rng.random(args[a].shape) < 0.05] = -0.0
    return g2, rows2, args, n, k6


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_trial_rows_are_the_former_loops(seed):
    """``mortar_jit.trial_rows`` (the group's matrices held in registers, the rows ``(2, P, 24)``): the bits of the
    loops that read every entry where it is used."""
    from beamsolver.contact import mortar_jit
    g2, rows2, a, n, k6 = _trial_case(seed)
    ref = np.zeros((n, 3, k6))
    _trial_rows_plain(ref, g2, rows2, *a.values())
    out = mortar_jit.trial_rows(np.zeros((n, 3, k6)), g2, rows2.transpose(1, 0, 2), *a.values())
    assert _bits(out, ref) and np.any(ref)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_branch_rows_are_the_trial_rows_at_the_identity_and_the_cap(seed):
    """``mortar_jit.branch_rows``: the bits of the trial rows at ``C = I, c = 0`` (``Tq``) and the first row at
    ``C = 0, c = e_1`` (``capq``), zero products and signed zeros among the terms included."""
    from beamsolver.contact import mortar_jit
    g2, rows2, a, n, k6 = _trial_case(seed)
    Tq, cap = np.zeros((n, 3, k6)), np.zeros((n, 3, k6))
    _trial_rows_plain(Tq, g2, rows2, *dict(a, C=np.broadcast_to(np.eye(3), (n, 3, 3)), c=np.zeros((n, 3))).values())
    e = np.zeros((n, 3))
    e[:, 0] = 1.0
    _trial_rows_plain(cap, g2, rows2, *dict(a, C=np.zeros((n, 3, 3)), c=e).values())
    b = {k: v for k, v in a.items() if k not in ("C", "c")}
    out = mortar_jit.branch_rows(np.zeros((n, 3, k6)), np.zeros((n, k6)), g2, rows2.transpose(1, 0, 2), *b.values())
    assert _bits(out[0], Tq) and _bits(out[1], np.ascontiguousarray(cap[:, 0])) and np.any(Tq) and np.any(cap)
    assert not np.signbit(out[0][out[0] == 0]).any() and not np.signbit(cap[cap == 0]).any()


@pytest.mark.parametrize("P", [0, 1, 2, 7, 640])
def test_compiled_point_forces_are_numpy_s_einsum(P):
    """``mortar_jit.point_forces``: ``np.einsum("pij,pj->pi", A, T)``'s bits for ``A`` C-contiguous (the mortar terms')
    and for the view of the kernel's ``(4, P, 4, 6)`` forces ``mortar_forces`` gives, and numpy's own elsewhere."""
    rng = np.random.default_rng(P)
    f, T = rng.standard_normal((4, P, 4, 6)), rng.standard_normal((P, 3))
    T[rng.random(T.shape) < 0.3] = -0.0             # signed zeros: products all -0 sum to +0 as einsum's
    T[rng.random(T.shape) < 0.2] = 0.0
    for A in (rng.standard_normal((P, 24, 3)), np.transpose(f[1:], (1, 2, 3, 0)).reshape(P, 24, 3),
              rng.standard_normal((P, 3, 24)).transpose(0, 2, 1)):
        A[rng.random(A.shape) < 0.05] = 0.0
        assert _bits(mortar_jit.point_forces(A, T), np.einsum("pij,pj->pi", A, T))


@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_interpolation_is_numpy_s_einsum(seed):
    """``mortar_jit.interpolate``: ``np.einsum("pa,pai->pi", phi, V[g2])``'s bits."""
    rng = np.random.default_rng(seed)
    P, G = 300, 40
    phi, V, g2 = rng.uniform(-1, 1, (P, 2)), rng.standard_normal((G, 3)), rng.integers(0, G, (P, 2))
    V[rng.random(V.shape) < 0.3] = 0.0
    phi[rng.random(phi.shape) < 0.3] = -0.0
    assert _bits(mortar_jit.interpolate(phi, V, g2), np.einsum("pa,pai->pi", phi, V[g2]))


def _bits(a, b):
    """Equal to the bit (signed zeros told apart)."""
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_turn_is_numpy_s_einsum(seed):
    """``mortar_jit.turn``: ``-np.einsum("gij,gjk->gik", R, se3.skew(Lam))``'s bits, zero multipliers (a step's
    start) and signed zeros included."""
    from beamsolver.lie import se3
    rng = np.random.default_rng(seed)
    G = 50
    R, Lam = rng.standard_normal((G, 3, 3)), rng.standard_normal((G, 3))
    Lam[:10] = 0.0
    Lam[10:20] = -0.0
    Lam[rng.random(Lam.shape) < 0.2] = -0.0
    R[rng.random(R.shape) < 0.1] = 0.0
    assert _bits(mortar_jit.turn(R, Lam), -np.einsum("gij,gjk->gik", R, se3.skew(Lam)))


@pytest.mark.parametrize("G", [0, 1, 2, 127])
def test_compiled_products_and_rotations_are_numpy_s_einsum(G):
    """``mortar_jit.products`` and ``rotate``: ``np.einsum("gij,gjk->gik")``'s and ``np.einsum("gij,gj->gi")``'s
    bits on contiguous arrays (signed zeros included), numpy's own on others."""
    rng = np.random.default_rng(G)
    A, B, v = rng.standard_normal((G, 3, 3)), rng.standard_normal((G, 3, 3)), rng.standard_normal((G, 3))
    for a in (A, B, v):
        a[rng.random(a.shape) < 0.2] = -0.0
        a[rng.random(a.shape) < 0.1] = 0.0
    for X in (A, np.swapaxes(A, 1, 2)):
        assert _bits(mortar_jit.products(X, B), np.einsum("gij,gjk->gik", X, B))
        assert _bits(mortar_jit.rotate(X, v), np.einsum("gij,gj->gi", X, v))
