"""The compiled passes of the contact search (issue 14, search <= 1 us/point) give the floats and the
choices of the numpy steps they replace, bit for bit: element spheres, Gauss-point sections, sphere
filter and projections (``projection.gauss_projections``, lanes in lockstep), owners
(``ownership.gauss_owners`` against ``rules.owners``) and the broad phase's pair order."""
import sys

import numpy as np
import pytest
from scipy.spatial import cKDTree

from beamsolver import se3
from beamsolver.contact import frames, kernel_jit, projection, rules, search
from beamsolver.contact.ownership import gauss_owners
from beamsolver.contact.search import broad_phase, element_spheres

from helpers import kernel_pairs as _pairs, projection_until_converged

ANGLES = np.tile([1e-3, 0.1, 0.5, 0.7, 1.2, np.pi / 2, 2.5], 11)      # 77 pairs: more than one block of lanes


def _poses(seed, angles=ANGLES):
    """Element pairs of ``_pairs`` as one pose table (nodes ``4 k .. 4 k + 3``: A1, B1, A2, B2), master
    elements bent and twisted by up to 2.5 rad (a section angle past every series switch)."""
    rng = np.random.default_rng(seed)
    X, kinds, _, _ = _pairs(rng, len(angles), angles)
    H = X.reshape(-1, 4, 4).copy()
    A1, A2 = 4 * np.arange(len(angles)), 4 * np.arange(len(angles)) + 2
    bend = se3.exp(np.concatenate([np.zeros((len(angles), 3)), rng.uniform(-1, 1, (len(angles), 3)) * angles[:, None]], 1))
    H[A2 + 1] = se3.compose(H[A2 + 1], bend)
    enodes = np.stack([np.arange(len(H)) // 2 * 2, np.arange(len(H)) // 2 * 2 + 1], 1)[::2]    # element k: nodes 2k, 2k+1
    h = projection.element_twists(H, enodes)
    return rng, H, np.where(kinds == frames.POINT, frames.ORTHOGONAL, kinds), enodes, h


def test_element_points_equal_the_gathered_section_points():
    """``projection.element_points`` (elements' nodes and twists read in place: ``ContactSystem._points``) gives
    ``section_points``' centres of the gathered elements, bit for bit (angles past every series switch)."""
    rng, H, _, enodes, h = _poses(4)
    el = rng.integers(0, len(enodes), 300)
    xi = rng.uniform(-0.3, 1.3, 300)
    x = projection.element_points(H, enodes, h, el, xi)
    ref, _ = projection.section_points(H, enodes[el, 0], h[el], xi)
    assert x.shape == (300, 3) and np.array_equal(x.view(np.int64), ref.view(np.int64))


def test_element_spheres_equal_the_numpy_formula():
    _, H, _, enodes, h = _poses(1)
    radii = np.linspace(0.01, 0.1, len(enodes))
    el = np.arange(len(enodes))[::-1].copy()
    mid, radius, tangent = element_spheres(H, enodes, h, radii, 0.03, el)
    x, e1 = projection.section_points(H, enodes[el, 0], h[el], np.full(len(el), 0.5))
    np.testing.assert_array_equal(mid, x)
    np.testing.assert_array_equal(tangent, e1)
    np.testing.assert_array_equal(radius, 0.5 * np.sqrt(np.sum(h[el, :3] ** 2, axis=1)) + radii[el] + 0.03)


def _gauss_reference(H, A1, h1, xg, kind, A2, B2, h2, c2, reach, cap=8):
    """The numpy steps ``gauss_projections`` replaces: every Gauss point's section, the sphere filter,
    the chord start and the Newton iterations of the kernel (``kernel_jit.project``) until the update is
    within the lanes' tolerance (``projection_until_converged``; the distance nan where not converged);
    also the iterations taken."""
    rep, g = np.repeat(np.arange(len(A1)), len(xg)), np.tile(np.arange(len(xg)), len(A1))
    xc, _ = projection.section_points(H, A1[rep], h1[rep], xg[g])
    near = np.sum((xc - c2[rep]) ** 2, axis=1) <= reach[rep] ** 2
    rep, g, xc = rep[near], g[near], xc[near]
    xa, xb = H[A2[rep], :3, 3], H[B2[rep], :3, 3]
    rel, chord = xc - xa, xb - xa
    start = np.clip((rel[:, 0] * chord[:, 0] + rel[:, 1] * chord[:, 1] + rel[:, 2] * chord[:, 2])
                    / np.maximum(chord[:, 0] * chord[:, 0] + chord[:, 1] * chord[:, 1] + chord[:, 2] * chord[:, 2], 1e-300),
                    0.0, 1.0)
    xi2, its, ok = projection_until_converged(kind[rep], H[A1[rep]], h1[rep], xg[g], H[A2[rep]], h2[rep], start, cap)
    xf, _ = projection.section_points(H, A2[rep], h2[rep], xi2)
    d = xf - xc
    dist = np.where(ok, np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2 + d[:, 2] ** 2), np.nan)
    return rep, g, xi2, dist, start, its


@pytest.mark.slow
def test_gauss_projections_equal_the_kernel_projection_bit_for_bit():
    rng, H, kind, enodes, h = _poses(2)
    A1, A2 = enodes[0::2, 0], enodes[1::2, 0]
    h1, h2 = h[0::2], h[1::2]
    xg = np.polynomial.legendre.leggauss(5)[0] * 0.5 + 0.5
    c2, _ = projection.section_points(H, A2, h2, np.full(len(A2), 0.5))
    reach = rng.uniform(0.05, 0.4, len(A1))              # some Gauss points filtered out, some kept
    ref = _gauss_reference(H, A1, h1, xg, kind, A2, A2 + 1, h2, c2, reach)
    got = projection.gauss_projections(H, enodes, h, A1 // 2, A2 // 2, xg, kind, c2, reach)
    assert 0 < len(got[0]) < len(A1) * len(xg)
    for a, b in zip(got, ref[:4]):
        np.testing.assert_array_equal(a, b)
    assert np.isfinite(got[3]).all()
    # lanes at and above the series switch of the exponential's coefficients were taken (scalar redo)
    angle = np.abs(ref[2]) * np.linalg.norm(h2[ref[0], 3:], axis=1)
    assert (angle >= projection._SWITCH_ABC).sum() >= 3 and (angle < projection._SWITCH_ABC).sum() >= 3
    assert set(kind[ref[0]]) == {frames.LINE, frames.ORTHOGONAL}
    # and project_points (the same lanes) from given slave sections
    y2, ydist = projection.project_points(H, kind[ref[0]], A1[ref[0]], h1[ref[0]], xg[ref[1]], A2[ref[0]],
                                          A2[ref[0]] + 1, h2[ref[0]])
    np.testing.assert_array_equal(y2, ref[2])
    np.testing.assert_array_equal(ydist, ref[3])


@pytest.mark.parametrize("seed", range(4))
def test_gauss_projections_stop_once_converged_and_reject_the_unconverged(seed):
    """Each lane stops at its first Newton update within ``projection._step_tol`` (~1e-12 of the element):
    its ``xi2`` is that iterate of the kernel's projection (bit for bit), within the tolerance of the fixed
    number of iterations done before (8, ``kernel_jit.project``), after far fewer.  A lane not converged
    after the block's ``iterations`` goes on (its block), up to ``MAX_ITERATIONS`` (where its iterate is in the
    window); one that does not converge is not accepted silently: its distance is nan (no owner takes it)."""
    rng = np.random.default_rng(seed)
    angles = rng.uniform(1e-3, 2.5, 70)
    rng, H, kind, enodes, h = _poses(20 + seed, angles)
    A1, A2 = enodes[0::2, 0], enodes[1::2, 0]
    h1, h2 = h[0::2], h[1::2]
    xg = np.polynomial.legendre.leggauss(5)[0] * 0.5 + 0.5
    c2, _ = projection.section_points(H, A2, h2, np.full(len(A2), 0.5))
    reach = np.full(len(A1), 10.0)
    cap = projection.MAX_ITERATIONS
    rep, g, xi2, dist, start, its = _gauss_reference(H, A1, h1, xg, kind, A2, A2 + 1, h2, c2, reach, cap)
    args = (H, enodes, h, A1 // 2, A2 // 2, xg, kind, c2, reach)
    got = projection.gauss_projections(*args)
    np.testing.assert_array_equal(got[0], rep)
    np.testing.assert_array_equal(got[2], xi2)
    np.testing.assert_array_equal(got[3], dist)
    ok = np.isfinite(dist)
    assert ok.mean() > 0.95 and np.median(its) <= 4 and (its[ok] > 8).any() == (seed < 3)
    # not converged: orthogonal projections of points far from a strongly bent master (a few, diverging or
    # cycling), which the fixed 8 iterations accepted with a finite distance
    assert (kind[rep][~ok] == frames.ORTHOGONAL).all() and (~ok).sum() <= 8 and (~ok).any() == (seed < 3)
    full = kernel_jit.project(kind[rep], H[A1[rep]], h1[rep], xg[g], H[A2[rep]], h2[rep], start, 8)[1]
    xA, u = H[A2[rep], :3, 3], h2[rep, :3]
    tol = projection.STEP_TOL * (1 + np.linalg.norm(xA, axis=1) / np.linalg.norm(u, axis=1))
    assert np.all(np.abs(got[2] - full)[its <= 8] <= tol[its <= 8])
    # fewer iterations before the window check: the lanes going on give the same floats
    short = projection.gauss_projections(*args, iterations=3)
    assert (its > 3).sum() > 0
    for x, y in zip(short, got):
        np.testing.assert_array_equal(x, y)
    # with the owners' window: a lane not converged after the lockstep and outside it stops there (nan)
    w = projection.gauss_projections(*args, iterations=3, window=10.0)
    after3 = kernel_jit.project(kind[rep], H[A1[rep]], h1[rep], xg[g], H[A2[rep]], h2[rep], start, 3)[1]
    out = (its > 3) & ((after3 < -10.0 - projection.CULL_PAD) | (after3 > 11.0 + projection.CULL_PAD))
    np.testing.assert_array_equal(w[0], rep)
    assert out.any() == (seed < 3)
    assert np.isnan(w[3][out]).all() and np.array_equal(w[2][~out], xi2[~out]) and np.array_equal(w[3][~out], dist[~out], equal_nan=True)
    # project_points: the same lanes
    y2, ydist = projection.project_points(H, kind[rep], A1[rep], h1[rep], xg[g], A2[rep], A2[rep] + 1, h2[rep],
                                          iterations=3)
    np.testing.assert_array_equal(y2, xi2)
    np.testing.assert_array_equal(ydist, dist)


def _owner_rows(rng, n_el, n_rows, n_beams):
    """Random projected rows with many exact ties: distances and ``xi2`` on coarse grids, rows inside
    and on an extension of their master element, repeated (e, g, beam) keys."""
    e = rng.integers(0, n_el, n_rows)
    m = rng.integers(0, n_el, n_rows)
    g = rng.integers(0, 3, n_rows)
    xi2 = rng.choice([-0.06, -0.04, -1e-10, 0.0, 0.3, 0.5, 1.0, 1.0 + 1e-10, 1.03, 1.2, np.nan], n_rows)
    dist = rng.choice([0.1, 0.1 + 1e-12, 0.1 + 1e-9, 0.2, 0.3, np.inf, np.nan], n_rows)
    first, last = rng.random(n_el) < 0.3, rng.random(n_el) < 0.3
    beam = rng.integers(0, n_beams, n_el)
    radius = rng.choice([0.5, 1.0], n_el)
    return e, m, g, xi2, dist, first, last, beam, radius


@pytest.mark.parametrize("seed", range(6))
def test_gauss_owners_equal_the_numpy_owners(seed):
    rng = np.random.default_rng(seed)
    n_el, n_beams, max_gp, decl = 7, 2, 3, seed % 2
    e, m, g, xi2, dist, first, last, beam, radius = _owner_rows(rng, n_el, 300, n_beams)
    key = ((np.int64(decl) * n_el + e) * max_gp + g) * n_beams + beam[m]
    lo, hi = rules.xi_range(first[m], last[m])
    ok = (xi2 >= lo) & (xi2 <= hi) & np.isfinite(dist)
    ids = key * n_el + m
    prev = np.sort(rng.choice(ids, 60))                    # owners of a last evaluation: some rows known
    known = np.isin(ids, prev)
    want = rules.owners(np.flatnonzero(ok), key, xi2, dist, radius[e] + radius[m], known)
    got, got_key = gauss_owners(decl, n_el, max_gp, n_beams, e, m, g, xi2, dist, first, last, beam, radius, prev)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(got_key, key[want])
    assert len(want) > 20


def test_broad_phase_keeps_the_pairs_and_order_of_the_distance_matrix():
    rng = np.random.default_rng(5)
    cs, cm = rng.uniform(0, 1, (200, 3)), rng.uniform(0, 1, (150, 3))
    rs, rm = rng.uniform(0.01, 0.08, 200), rng.uniform(0.01, 0.08, 150)
    i, j = broad_phase(cs, rs, cm, rm)
    D = cKDTree(cs).sparse_distance_matrix(cKDTree(cm), rs.max() + rm.max(), output_type="coo_matrix")
    keep = np.linalg.norm(cs[D.row] - cm[D.col], axis=1) <= rs[D.row] + rm[D.col]
    np.testing.assert_array_equal(i, D.row[keep])
    np.testing.assert_array_equal(j, D.col[keep])
    d = np.linalg.norm(cs[:, None] - cm[None], axis=2) <= rs[:, None] + rm[None]
    assert set(zip(i.tolist(), j.tolist())) == set(zip(*np.nonzero(d)))


def _extend_wrap_isin(enodes, master_beam, n_beams, e, m, kind, xi1):
    """``rules.extend_wrap`` as written with ``np.isin`` (the reference of its binary search)."""
    orth = kind == frames.ORTHOGONAL
    if not orth.any() or orth.all():
        return kind
    wrap = np.unique((enodes[e[orth]] * n_beams + master_beam[orth, None]).ravel())
    pt = np.flatnonzero(kind == frames.POINT)
    pt = pt[(xi1[pt] < rules.WRAP_END) | (xi1[pt] > 1.0 - rules.WRAP_END)]
    near = np.isin(enodes[e[pt]] * n_beams + master_beam[pt, None], wrap).any(axis=1)
    kind = kind.copy()
    kind[pt[near]] = frames.ORTHOGONAL
    return kind


@pytest.mark.parametrize("seed", range(8))
def test_extend_wrap_equals_its_isin_form(seed):
    rng = np.random.default_rng(seed)
    n_el, n = 12, 40
    enodes = np.stack([np.arange(n_el), np.arange(n_el) + 1], axis=1)
    e, m = rng.integers(0, n_el, n), rng.integers(0, n_el, n)
    kind = rng.choice([frames.LINE, frames.ORTHOGONAL, frames.POINT], n, p=[0.2, 0.2 + 0.1 * (seed % 3), 0.6 - 0.1 * (seed % 3)])
    xi1 = rng.choice([-0.1, 0.02, 0.5, 0.97, 1.1], n)
    master_beam = rng.integers(0, 3, n)
    want = _extend_wrap_isin(enodes, master_beam, 3, e, m, kind, xi1)
    np.testing.assert_array_equal(rules.extend_wrap(enodes, master_beam, 3, e, m, kind, xi1), want)


@pytest.mark.parametrize("seed", range(4))
def test_sweep_phase_finds_the_pairs_of_the_distance_matrix(seed):
    """The sort and sweep (``search.sweep_phase``) finds the set of ``broad_phase``'s pairs, slave-major,
    on scenes spread along one axis (a wire) and in a cube, radii uneven."""
    rng = np.random.default_rng(seed)
    ns, nm = 300, 250
    if seed % 2:
        cs = np.c_[rng.uniform(0, 10, ns), rng.uniform(0, 0.2, (ns, 2))]
        cm = np.c_[rng.uniform(0, 10, nm), rng.uniform(0, 0.2, (nm, 2))] + [0, 0, 0.1]
    else:
        cs, cm = rng.uniform(0, 1, (ns, 3)), rng.uniform(0, 1, (nm, 3))
    cs += 1e3 * seed          # far from the origin: the windows' round-off
    cm += 1e3 * seed
    rs, rm = rng.uniform(0.01, 0.08, ns), rng.uniform(0.01, 0.12, nm)
    i, j = broad_phase(cs, rs, cm, rm)
    # a cube: most masters in every window (past the default budget, which gives up there)
    si, sj, edge = search.sweep_phase(cs, rs, cm, rm, **({} if seed % 2 else dict(budget=nm)))
    assert not edge and len(i) > 50
    assert sorted(zip(si.tolist(), sj.tolist())) == sorted(zip(i.tolist(), j.tolist()))
    assert np.all(np.diff(si) >= 0)


def test_sweep_phase_flags_what_the_distance_matrix_may_see_otherwise():
    cs, cm = np.array([[0.0, 0, 0], [5.0, 0, 0]]), np.array([[0.2, 0, 0], [9.0, 0, 0]])
    rs, rm = np.array([0.1, 0.1]), np.array([0.2, 0.1])
    i, j, edge = search.sweep_phase(cs, rs, cm, rm)
    assert not edge and i.tolist() == [0] and j.tolist() == [0]
    cm[0, 0] = 0.1 + 0.2         # spheres touching at the distance matrix's radius (max r_s + max r_m)
    assert search.sweep_phase(cs, rs, cm, rm)[2]
    cm[0, 0] = 0.2
    cs[1, 2] = np.nan
    assert search.sweep_phase(cs, rs, cm, rm)[2]


def test_crossing_skips_arccos_only_where_no_pair_can_cross():
    rng = np.random.default_rng(3)
    angle = np.radians(20.0)
    near = np.cos(angle) + np.array([-1e-12, 0.0, 1e-12, 1e-10, 1e-9, 2e-9, 1e-6])
    for c in near:
        cos = np.r_[rng.uniform(c, 1.0, 20), c] * rng.choice([-1.0, 1.0], 21)
        least = np.abs(cos).min()
        np.testing.assert_array_equal(rules.crossing(cos, angle, least), rules.crossing(cos, angle))


def test_gauss_owners_report_a_choice_by_the_order_of_the_rows():
    """Two rows of a key equal in ``known``, ``xi2`` and ``dist``: the first is chosen, and ``order=True``
    says so (the search then takes the distance matrix's order); rows differing in ``xi2`` do not."""
    args = dict(first=np.zeros(4, bool), last=np.zeros(4, bool), beam=np.zeros(4, int), radius=np.ones(4),
                prev=np.zeros(0, dtype=np.int64))
    e, m, g = np.array([0, 0]), np.array([2, 3]), np.array([0, 0])
    for xi2, tied in ((np.array([0.5, 0.5]), True), (np.array([0.5, 0.4]), False)):
        s, key, got = gauss_owners(0, 4, 1, 1, e, m, g, xi2, np.array([0.1, 0.1]), order=True, **args)
        assert got is tied
        np.testing.assert_array_equal(s, [0] if tied else [1])


def _line_scene(n_el=40):
    """Two nearly parallel wires in line contact (``benchmarks/contact_throughput.py``' scene)."""
    import beamsolver as bs
    from beamsolver.nonlinear.problem import Problem
    from contact_throughput import line_model
    m = line_model(bs, n_el)
    return lambda: Problem.from_model(m, check_rigid_modes=False).contact


def _same_pairs(P, Q):
    from dataclasses import fields
    for f in fields(P):
        a, b = getattr(P, f.name), getattr(Q, f.name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), f.name


def test_the_swept_search_gives_the_pairs_in_the_distance_matrix_order(monkeypatch):
    """Without crossings the search takes the sweep's pairs (``_candidates``): the pair record and the
    owners remembered are those of the distance matrix's order, bit for bit, over two evaluations (the
    second with the first's owners); with owners depending on the order it takes the distance matrix's."""
    from beamsolver.contact import system
    make = _line_scene()
    swept, tree = make(), make()
    H = swept.sys.poses0.copy()
    H[:, :3, 3] += 2e-4 * np.random.default_rng(0).standard_normal((len(H), 3))
    calls = []
    candidates = system.ContactSystem._candidates

    def spy(self, d, geo, sweep=True):
        c = candidates(self, d, geo, sweep=sweep and self is swept)
        calls.append((self is swept, c.swept))
        return c

    monkeypatch.setattr(system.ContactSystem, "_candidates", spy)
    for poses in (H, swept.sys.poses0):
        _same_pairs(swept.pairs(poses), tree.pairs(poses))
        np.testing.assert_array_equal(swept.history.prev_owners, tree.history.prev_owners)
    assert calls == [(True, True), (False, False)] * 2
    # an order-dependent choice of owners: the search is redone in the distance matrix's order
    owners = system.gauss_owners
    monkeypatch.setattr(system, "gauss_owners", lambda *a, **k: owners(*a, **k)[:2] + (True,))
    calls.clear()
    _same_pairs(swept.pairs(H), tree.pairs(H))
    assert calls == [(True, True), (True, False), (False, False)]


def test_sweep_phase_gives_up_on_a_scene_not_spread_along_an_axis():
    """A ball of spheres: the windows of any axis hold most masters; past the budget the sweep flags
    (the search then takes the tree), below it finds the pairs."""
    rng = np.random.default_rng(7)
    cs, cm = rng.uniform(0, 1, (400, 3)), rng.uniform(0, 1, (400, 3))
    rs, rm = np.full(400, 0.05), np.full(400, 0.05)
    assert search.sweep_phase(cs, rs, cm, rm, budget=8)[2]
    i, j = broad_phase(cs, rs, cm, rm)
    si, sj, edge = search.sweep_phase(cs, rs, cm, rm, budget=400)
    assert not edge and sorted(zip(si.tolist(), sj.tolist())) == sorted(zip(i.tolist(), j.tolist()))


@pytest.mark.parametrize("sweep", [False, True])
def test_broad_pairs_are_the_broad_phase_and_apart_in_one_pass(sweep):
    """``search.broad_pairs``: the pairs of ``broad_phase`` (its order; the sweep's: the same set) that
    ``rules.apart`` keeps, their tangents' cosines, master sphere centres and reach, bit for bit."""
    rng = np.random.default_rng(11)
    n_el = 120
    enodes = np.stack([np.arange(n_el), np.arange(n_el) + 1], 1)
    enodes[rng.choice(n_el, 30), 1] = rng.integers(0, n_el, 30)       # shared nodes across the sets
    slave_el, master_el = rng.permutation(n_el)[:70], rng.permutation(n_el)[:80]
    c = np.c_[np.linspace(0, 3, n_el), rng.uniform(0, 0.05, (n_el, 2))]
    r = rng.uniform(0.02, 0.06, n_el)
    t = rng.standard_normal((n_el, 3))
    t /= np.linalg.norm(t, axis=1)[:, None]
    radius = rng.uniform(0.001, 0.01, n_el)
    cs, rs, ts, cm, rm, tm = c[slave_el], r[slave_el], t[slave_el], c[master_el], r[master_el], t[master_el]
    i, j = broad_phase(cs, rs, cm, rm)
    e, m = slave_el[i], master_el[j]
    keep = rules.apart(enodes, e, m)
    assert 0 < keep.sum() < len(keep)
    i, j, e, m = i[keep], j[keep], e[keep], m[keep]
    cos = ts[i, 0] * tm[j, 0] + ts[i, 1] * tm[j, 1] + ts[i, 2] * tm[j, 2]
    got = search.broad_pairs(cs, rs, ts, cm, rm, tm, slave_el, master_el, enodes, radius, sweep=sweep)
    if sweep:
        assert not got[6]
        order = np.lexsort((m, e))
        i, j, e, m, cos = i[order], j[order], e[order], m[order], cos[order]
        s = np.lexsort((got[1], got[0]))
        got = tuple(a[s] for a in got[:5]) + got[5:]
    for a, b in zip(got[:5], (e, m, cos, cm[j], rm[j] + radius[e])):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()
    assert got[5] == np.abs(cos).min()


@pytest.mark.parametrize("ties", [False, True])
def test_sweep_sort_and_bisection_equal_numpy(ties):
    """The sweep's own sort (``search._argsort``: stable merge sort, instead of numba's ``np.argsort``, whose
    generic quicksort cost about a second of the first run's compilation) and bisection (``_bisect``) give
    ``np.argsort(kind="stable")`` and ``np.searchsorted`` (left and right), ties and ends included."""
    rng = np.random.default_rng(7)
    for n in (0, 1, 2, 3, 5, 64, 1000, 1025):
        key = rng.integers(0, 4, size=n).astype(float) if ties else rng.normal(size=n)
        np.testing.assert_array_equal(search._argsort(key), np.argsort(key, kind="stable"))
        s = np.sort(key)
        for v in list(s[:4]) + list(s[-2:]) + [-9.0, 9.0, 0.25]:
            for side in ("left", "right"):
                assert search._bisect(s, v, side == "right") == np.searchsorted(s, v, side=side), (n, v, side)
