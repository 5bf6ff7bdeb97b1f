"""Exact stick (``stick="exact"``, mortar nodal multipliers, ``contact/mortar.py``).

Tangent against central finite differences perturbing on the group (stick, slip, turned
multipliers); shear lag on a rigid rod (slip zone ``F / (mu q)``, unloaded stick zone) at two
meshes; answers independent of the augmentation penalty; the patch test with friction (stick
everywhere, no slip); option checks.
"""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import se3
from beamsolver.nonlinear.problem import Problem
from helpers import bordered_tangent_error, contact_tangent_error

import contact_patch
import shear_lag

R = 0.05
SEC = bs.Section.circular(radius=R, E=1e7, nu=0.3)


def _parallel(mu, n_slave=4, **options):
    """A slave beam slightly skew above a clamped master (non-matching meshes, 3-D)."""
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 5), SEC)
    slave = m.add_beam(bs.geometry.straight((0.1, 0.002, 2 * R), (0.9, -0.002, 2 * R), n_slave), SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, stick="exact", **options)
    return m, slave, master


def _move(H, nodes, G):
    H = H.copy()
    H[nodes] = se3.compose(np.broadcast_to(G, (len(nodes), 4, 4)), H[nodes])
    return H


def _pressed(problem, slave, depth):
    """Translate the slave down so that its lowest contact point penetrates by ``depth``."""
    H = problem.system.poses0.copy()
    z = H[slave.nodes, 2, 3].min()
    G = np.eye(4)
    G[2, 3] = 2 * R - z - depth
    H = _move(H, slave.nodes, G)
    # bend it a little so the pressure varies along the slave
    H[slave.nodes, 2, 3] -= depth * np.linspace(0.0, 1.0, len(slave.nodes)) ** 2
    return H


def _updates_committed(n_slave=4, **options):
    """``_parallel(0.05, **options)`` pressed ``2e-3 R`` with the multiplier updates (``newton_multipliers`` off) and
    committed at t = 0: ``(problem, slave, H)``."""
    model, slave, _ = _parallel(0.05, n_slave=n_slave, **options)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    c.newton_multipliers = False
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)
    return problem, slave, H


def _committed(model, slave, turned=False):
    """``(problem, H)``: ``model``'s slave pressed into its master (``_pressed``), the contact's step begun and
    committed there (``turned``: the committed multipliers replaced by random ones)."""
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)
    if turned:
        keys, lam = c.history.tmult
        c.history.update_multipliers(tmult=(keys, np.random.default_rng(3).normal(size=lam.shape) * 50.0))
    return problem, H


def _slid_evaluation(mu=0.5):
    """``(problem, H, ev)``: ``_parallel(mu)`` pressed, its step begun and committed through the problem, the slave
    then slid by 1e-7 R and evaluated with the tangent."""
    model, slave, master = _parallel(mu)
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = _pressed(problem, slave, 2e-3 * R)
    problem.begin_step(H, 0.0)
    problem.commit(H)
    H = _move(H, slave.nodes, se3.exp(np.array([1e-7 * R, 1e-7 * R, 0.0, 1e-7 * R, 0.0, 0.0])))
    return problem, H, problem.evaluate(H, 0.0, tangent=True)


def _slid(regime, n_slave=4):
    """``(problem, H, dz_c)``: ``_parallel`` pressed and committed (``_committed``), the slave slid by 1e-7 R (``stick``,
    ``turned``: every group sticking; ``turned``: random committed multipliers) or by 2e-3 R with ``mu = 0.05`` and
    ``penalty_t = 1e7`` (``slip``: every group sliding), and increments ``dz_c`` prescribed on the slave's first node."""
    model, slave, master = _parallel(0.5 if regime != "slip" else 0.05, n_slave=n_slave,
                                     **(dict(penalty_t=1e7) if regime == "slip" else {}))
    problem, H = _committed(model, slave, turned=regime == "turned")
    slide = {"stick": 1e-7, "slip": 2e-3, "turned": 1e-7}[regime] * R
    H = _move(H, slave.nodes, se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide])))
    dz_c = np.zeros((problem.system.n_nodes, 6))
    dz_c[slave.first] = [1e-6 * R, -2e-6 * R, 1e-6 * R, 1e-6, 0.0, -1e-6]
    return problem, H, dz_c


def _mortar_inputs(monkeypatch):
    """``(kernel_jit.mortar_terms, X, pm)``: the compiled mortar terms and the inputs ``_mortar`` gives them on
    pressed, slid pairs (with friction history) of ``_parallel``."""
    from beamsolver.contact import kernel_jit
    captured = {}
    compiled = kernel_jit.mortar_terms

    def spy(X, pm, law=None, **kw):
        captured.update(X=X, pm=pm)
        return compiled(X, pm, law, **kw)

    monkeypatch.setattr(kernel_jit, "mortar_terms", spy)
    model, slave, master = _parallel(0.5)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)
    slide = 1e-4 * R
    H = _move(H, slave.nodes, se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide])))
    c._local_blocks(H, True)
    return compiled, captured["X"], captured["pm"]


def _fd_error(problem, H, eps=1e-7):
    """Largest difference between the assembled tangent and central differences of the residual
    over the free unknowns, relative to the largest contact tangent entry."""
    return contact_tangent_error(problem, H, eps)[0]


@pytest.mark.slow
@pytest.mark.parametrize("integration", ["points", "segments"])
@pytest.mark.parametrize("regime", ["stick", "slip", "turned"])
def test_exact_stick_tangent_matches_finite_differences(regime, integration):
    """The bordered Newton matrix (poses and nodal multipliers) against central differences of the
    residual and the complementarity functions: sticking groups, sliding ones, multipliers turned in
    the nodes' frames; with segments the weights and parameters of the points move with the segment
    ends (``segment_tangent.mortar_end_terms``: without them the sliding case's C rows erred by 2e-5)."""
    model, slave, master = _parallel(0.5 if regime != "slip" else 0.05, integration=integration,
                                     **(dict(penalty_t=1e7) if regime == "slip" else {}))
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)                                 # history and nodal multipliers (zero) at H
    if regime == "turned":                      # multipliers in the nodes' frames, not zero
        keys, lam = c.history.tmult
        c.history.update_multipliers(tmult=(keys, np.random.default_rng(3).normal(size=lam.shape) * 50.0))
    slide = {"stick": 1e-7, "slip": 2e-3, "turned": 1e-7}[regime] * R
    G = se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide]))
    H = _move(H, slave.nodes, G)
    err_q, err_c, ev = bordered_tangent_error(problem, H)
    m = ev.mult
    live = m["C"].any(axis=1) | m["stick"]
    if regime == "slip":
        assert not m["stick"][live].all() and live.any()
    else:
        assert m["stick"][live].all() and live.any()
    assert err_q < 1e-6 and err_c < 1e-6, (err_q, err_c)


@pytest.mark.parametrize("integration", ["points", "segments"])
def test_exact_stick_updates_tangent_matches_finite_differences(integration):
    """The augmented-Lagrangian path (multipliers updated between Newton solves, ``mortar.blocks``) with
    sliding groups against central differences of the residual; with segments the moving ends' terms
    of the nodal sums (``segment_tangent.mortar_end_terms``): measured 2.2e-9 (points 2.2e-9; without
    the terms 5.4e-7)."""
    problem, slave, H = _updates_committed(integration=integration, penalty_t=1e7)
    c = problem.contact
    slide = 2e-3 * R
    H = _move(H, slave.nodes, se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide])))
    ev = problem.evaluate(H, 0.0, tangent=True)
    assert "mortar" in c._local_blocks(H, True)[5] and ev.r.any()
    assert _fd_error(problem, H) < 5e-8


def _shear_lag(n_wire, **options):
    sol, wire, a = shear_lag.main(n_wire=n_wire, stick="exact", **options)
    x, N = shear_lag.axial_force(sol, wire)
    return sol, wire, a, x, N


@pytest.mark.slow
@pytest.mark.parametrize("n_wire", [10, 20])
def test_shear_lag_slip_zone_and_force_profile(n_wire):
    """Slip zone ``F / (mu q)`` from the pulled end within one element, the axial force on the
    closed form ``mu q (x - (L - a))`` there and nothing carried in the stick zone (away from the
    free end, where the pressing phase leaves a small self-equilibrated force)."""
    sol, wire, a, x, N = _shear_lag(n_wire)
    le = 1.0 / n_wire
    assert abs(shear_lag.slip_zone(sol, wire) - a) < le
    F = 15.0
    exact = np.maximum(0.3 * 100.0 * (x - (1.0 - a)), 0.0)
    slip = x > 1.0 - a + le
    stick = (x < 1.0 - a - le) & (x > 0.2)
    assert np.abs(N[slip] - exact[slip]).max() < 0.02 * F
    assert np.abs(N[stick]).max() < 0.01 * F


@pytest.mark.slow
def test_shear_lag_does_not_depend_on_the_penalty():
    """The complementarity parameter ``c`` (``penalty_t``) over four decades, 1e6 (the default, 1e-3 of
    the normal penalty) to 1e10: the same axial forces to 1e-3 F (``c`` only decides how an iterate is
    linearised), where the penalty stick (``stick="penalty"``) differs by newtons."""
    N = [_shear_lag(10, penalty_t=pt)[4] for pt in (None, 1e8, 1e10)]
    assert np.abs(N[0] - N[1]).max() < 1e-3 * 15.0
    assert np.abs(N[0] - N[2]).max() < 1e-3 * 15.0
    sol, wire, _ = shear_lag.main(n_wire=10, stick="penalty")
    assert np.abs(shear_lag.axial_force(sol, wire)[1] - N[0]).max() > 1.0


def test_stick_option_is_checked():
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), SEC)
    b = m.add_beam(bs.geometry.straight((0, 0, 2 * R), (1, 0, 2 * R), 2), SEC)
    with pytest.raises(bs.InputError, match="stick must be 'penalty' or 'exact'"):
        m.add_contact(a, b, mu=0.3, stick="mortar")
    with pytest.raises(bs.InputError, match="stick_tolerance"):
        m.add_contact(a, b, mu=0.3, stick="exact", stick_tolerance=-1.0)


def test_nodal_return_mapping_derivatives():
    """``mortar.return_mapping``'s ``C = d lam / d trial`` and ``c = d lam / d cap`` against central
    differences, in stick and slip."""
    from beamsolver.contact.mortar import return_mapping
    rng = np.random.default_rng(26)
    trial = rng.normal(size=(40, 3))
    cap = np.abs(rng.normal(size=40)) * 1.5
    lam, stick, C, c = return_mapping(trial, cap)
    assert 5 < stick.sum() < 35
    h = 1e-6
    for i in range(3):
        d = np.zeros(3)
        d[i] = h
        fd = (return_mapping(trial + d, cap)[0] - return_mapping(trial - d, cap)[0]) / (2 * h)
        np.testing.assert_allclose(C[:, :, i], fd, atol=1e-8)
    fd = (return_mapping(trial, cap + h)[0] - return_mapping(trial, cap - h)[0]) / (2 * h)
    np.testing.assert_allclose(c, fd, atol=1e-8)
    np.testing.assert_allclose(np.linalg.norm(lam[~stick], axis=1), cap[~stick])


def test_return_mapping_without_capacity_gives_no_traction_and_no_stiffness():
    """A group without normal traction (capacity 0) carries nothing whatever its trial, even a zero one, and
    its traction does not move with the trial (it was a zero-width "stick" with the full trial's stiffness:
    the multiplier column of the bordered matrix then failed its finite-difference check by 65 %)."""
    from beamsolver.contact.mortar import return_mapping
    trial = np.array([[0.0, 0.0, 0.0], [1.0, -2.0, 0.5]])
    lam, stick, C, c = return_mapping(trial, np.zeros(2))
    assert not stick.any()
    np.testing.assert_array_equal(lam, 0.0)
    np.testing.assert_array_equal(C, 0.0)
    np.testing.assert_allclose(c[1], trial[1] / np.linalg.norm(trial[1]))     # d lam / d cap: along the trial
    np.testing.assert_array_equal(c[0], 0.0)


def test_groups_move_a_held_node_to_its_neighbour():
    """``mortar.groups``: a held slave node has no group; the points of its element count wholly
    for the neighbour (boundary modification), the others are split by the hats."""
    from beamsolver.contact.mortar import groups
    slave = np.array([[0, 1], [0, 1], [1, 2]])
    nodes = np.array([[0, 1, 5, 6], [0, 1, 5, 6], [1, 2, 6, 7]])
    xi1 = np.array([0.2, 0.8, 0.5])
    G = groups(slave, xi1, np.zeros(3, dtype=int), np.zeros(3, dtype=int), nodes, 8, 2,
               held=np.array([[True, False], [True, False], [False, False]]))
    assert G["node"].tolist() == [1, 2]
    assert (G["g"][:2] == 0).all() and G["g"][2].tolist() == [0, 1]
    np.testing.assert_allclose(G["phi"].sum(axis=1), 1.0)
    # every node of a group's points is among its members, in the slot given by pos
    for p in range(3):
        for a in range(2):
            assert (G["members"][G["g"][p, a], G["pos"][p, a]] == nodes[p]).all()


def test_groups_fold_a_sliver_into_its_neighbour():
    """``mortar.groups``: a slave node whose support meets a master beam in one Gauss point with a small shape function
    (the plectoneme: the master's pieces join there, ``Phi = 0.047``) has no group of its own against that beam; the
    point counts wholly for the other node of the element.  Points with comparable shares keep both groups."""
    from beamsolver.contact.mortar import groups
    slave = np.array([[0, 1], [0, 1], [1, 2], [1, 2], [1, 2]])
    nodes = np.array([[0, 1, 5, 6], [0, 1, 5, 6], [1, 2, 6, 7], [1, 2, 6, 7], [1, 2, 3, 4]])
    beam = np.array([0, 0, 0, 0, 1])
    for xi, kept in ((0.047, 1), (0.953, 2)):       # the point on beam 1 near node 1 / near node 2
        G = groups(slave, np.array([0.2, 0.8, 0.2, 0.6, xi]), beam, np.zeros(5, dtype=int), nodes, 8, 2)
        on1 = G["key"] % 2 == 1
        assert G["node"][on1].tolist() == [kept]                     # one group against beam 1
        assert G["g"][4, 0] == G["g"][4, 1]                          # its point counts wholly for it
        assert G["node"][~on1].tolist() == [0, 1, 2]                 # beam 0: comparable shares, every node kept
    G = groups(slave, np.array([0.2, 0.8, 0.2, 0.6, 0.4]), beam, np.zeros(5, dtype=int), nodes, 8, 2)
    assert G["node"][G["key"] % 2 == 1].tolist() == [1]              # the same single point, shares 0.6 / 0.4
    G = groups(slave, np.array([0.2, 0.8, 0.2, 0.6, 0.047]), beam, np.zeros(5, dtype=int), nodes, 8, 2,
               fold=np.zeros((5, 2), dtype=bool))
    assert G["node"][G["key"] % 2 == 1].tolist() == [1, 2]           # without the fold: two groups, one point


def test_compiled_mortar_terms_match_the_complex_step_oracle(monkeypatch):
    """``kernel_jit.mortar_terms`` (compiled, four evaluations, the friction linear in the given traction)
    against ``reference.mortar_point_derivatives`` (numpy complex steps) on pressed, slid pairs at a random
    traction: forces, ``df/dT``, the tangent at fixed traction, the slip and its derivative, the normal
    traction and the normal's derivative."""
    from beamsolver.contact import reference
    compiled, X, pm = _mortar_inputs(monkeypatch)
    assert len(X) > 4
    T = np.random.default_rng(0).normal(size=(len(X), 3)) * 100.0
    d = reference.mortar_point_derivatives(X, pm, T)
    m = compiled(X, pm)

    def rel(a, b):
        return np.abs(a - b).max() / np.abs(b).max()
    assert m["active"].all()
    assert rel(m["A"], d["G"]) < 1e-11
    assert rel(np.einsum("pij,pj->pi", m["A"], T), d["f"]) < 1e-11
    assert rel(np.einsum("pk,pkij->pij", T, m["dK"]), d["dfdq"]) < 1e-8
    assert rel(m["S"], d["S"]) < 1e-12 and rel(m["dS"], d["dS"]) < 1e-12
    assert rel(m["lam_n"], d["lam_n"]) < 1e-12 and rel(m["dlam_n"], d["dlam_n"]) < 1e-12
    assert rel(m["dn"], d["dn"]) < 1e-12


@pytest.mark.slow
def test_exact_stick_newton_converges_superlinearly():
    """The multipliers are Newton unknowns: once the sticking and sliding groups settle, every step of
    the shear lag (10 elements) converges superlinearly (``log r_{k+1} / log r_k >= 1.4`` for the scaled
    residuals below 1e-2 and above round-off whose iterate has the same stick / slip branches as the one before,
    ``stats["changes"]`` 0; measured 1.49-2.5), not linearly as the updates did.  A group that switches below 1e-2
    (with the default ``c`` one step has one at 4.5e-3: rate 1.2 there) is what ``stats["changes"]`` reports."""
    sol = _shear_lag(10)[0]
    pairs = 0
    for s in sol.stats[1:]:
        r, changes = np.array(s["residuals"]), s["changes"]
        assert len(changes) == len(r) and changes[0] == 0
        for k in range(1, len(r)):
            if r[k - 1] < 1e-2 and r[k] > 1e-10 and changes[k] == 0:
                assert np.log(r[k]) / np.log(r[k - 1]) >= 1.4, (s["residuals"], changes)
                pairs += 1
    assert pairs >= 4


def test_the_main_job_s_tail_converges_without_crawling():
    """Once the scaled residual of a step of the main job (``examples/twisted_pair.py``, 16 steps; its first three here)
    is below 1e-6, at most two more iterations.  Before ``newton.TAIL_SWITCHES`` two sliding groups at their disk's edge
    with a vanishing slip (a stick / slip corner: ``|Lam| / cap`` 1.02 .. 1.0001, slip 1e-8 .. 1e-10 m, across their
    traction) crawled: the lateral row of the slide branch, ``(1 - cap / |trial|) dv - c du``, is nearly singular
    there, each Newton step turned the traction by 0.1 .. 0.3 rad and the disk's curvature gave back a radial residual
    of the same order (t = 0.0625: 1.1e-7, 6.5e-8, 1.1e-7, 1.4e-8, 3.6e-8, 8e-10; 5 and 4 iterations below 1e-6
    in the first and third steps).  On the stick rows the corner converges in one iteration (1.1e-7, 1.7e-9)."""
    import twisted_pair
    model, *_ = twisted_pair.build()
    sol = bs.solve(model, steps=3, t_end=3 / 16, verbose=False)
    tails = []
    for s in sol.stats[1:]:
        r = np.array(s["residuals"])
        below = np.flatnonzero(r[1:] < 1e-6) + 1     # (iteration 0: the last step's poses, before the step's motion)
        tails.append(len(r) - 1 - below[0])
    assert max(tails) <= 2, (tails, [s["residuals"] for s in sol.stats])


def test_touching_group_without_pressure_sheds_its_traction_exactly():
    """Touching without normal traction (a sharp law at zero gap, where the law's band holds the group):
    the group carries nothing, so its complementarity function is ``C = v`` and its rows of the bordered
    matrix are exact, ``dC/dLam = R`` and no slip columns, and one Newton step takes its traction to zero.
    The holding stiffness of such groups acts on the displacement rows only (a tangent-only floor).
    (It was ``dC/dLam = (I - mu Pi) R`` and slip columns: the multiplier overshot and the twisted pair's
    residual stalled.)"""
    model = bs.Model()
    master = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 5), SEC)
    slave = model.add_beam(bs.geometry.straight((0.1, 0, 2 * R), (0.9, 0, 2 * R), 4), SEC)
    for b in (master, slave):
        model.clamp(b.first)
    model.clamp(master.last)
    model.add_contact(slave, master, mu=0.5, stick="exact", smoothing=0.0)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = problem.system.poses0.copy()
    c.begin_step(H, 0.0)
    c.commit(H)
    keys, lam = c.history.tmult
    c.history.update_multipliers(tmult=(keys, np.random.default_rng(5).normal(size=lam.shape) * 50.0))
    ev = problem.evaluate(H, 0.0, tangent=True)
    m = ev.mult
    v = np.einsum("gij,gj->gi", m["R"], m["Lam"])
    assert len(v) and not m["stick"].any() and np.allclose(m["C"], v)      # no capacity: C = v
    np.testing.assert_allclose(m["Kll"], m["R"], atol=1e-12)
    # d C / d q: only the turn of the node's own frame (three columns), no slip
    assert (np.count_nonzero(np.abs(m["Klq"]).max(axis=1), axis=1) <= 3).all()


def test_a_group_the_iterate_lacks_comes_back_without_traction():
    """A Newton step of the multipliers sets those of groups its iterate did not have to zero: they acted
    nowhere there, and a group coming back must not bring a traction Newton never saw."""
    model, slave, master = _parallel(0.5)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    keys = np.array([3, 7, 11], dtype=np.int64)
    c.history.update_multipliers(tmult=(keys, np.ones((3, 3))))
    c.multiplier_step(keys[[0, 2]], np.full((2, 3), 0.5))
    c.multiplier_trial(1.0)
    np.testing.assert_array_equal(c.iterate_multipliers(keys), [[1.5] * 3, [0.0] * 3, [1.5] * 3])


def test_the_one_pass_mortar_kernel_gives_the_bits_of_four_kernel_calls(monkeypatch):
    """``kernel_jit.mortar_terms`` (one compiled pass, the geometry once per point for the four tractions)
    against ``mortar_terms_four`` (one call of the point kernel per traction, its oracle): every term the
    same bits, on pressed and slid pairs with friction history."""
    from beamsolver.contact import kernel_jit
    compiled, X, pm = _mortar_inputs(monkeypatch)
    assert len(X) > 4 and np.any(pm["has_history"])
    one, four = compiled(X, pm), kernel_jit.mortar_terms_four(X, pm)
    assert set(one) == set(four)
    for k in one:
        assert np.array_equal(one[k], four[k]), k
    assert np.abs(one["A"]).max() > 0 and np.abs(one["dK"]).max() > 0 and np.abs(one["dS"]).max() > 0


@pytest.mark.slow
def test_pre_stressed_strand_starts_without_exact_friction_when_it_must():
    """A 1+6+12 strand whose touching layers carry contact forces at t_start: with exact stick's friction
    step 0 finds no equilibrium (the iterates alternate between two states: given up once two Newton directions
    running reverse the one before, ``steps.STEP_ZERO_CYCLE``; by the stall rule after 10 iterations without progress
    in sessions 8-10, after the whole budget of 120 before); the solve then finds it without
    that friction, says so, and the stretched step converges with friction (it raised ConvergenceError)."""
    L = bs.cables.Layer
    r, lay = 1e-3, 0.1
    st = bs.cables.build_strand([L(r)] + [L(r, 6 * k, lay_length=lay) for k in (1, 2)], lay, E=2e11,
                                elements_per_lay=24, mu=0.3, contact_options=dict(stick="exact"), fit_core=True,
                                touch_tol=-0.5)
    st.clamp("bottom")
    for w in st.all_wires:
        st.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, 1e-4 * st.length * t)))
    sol = bs.solve(st.model, steps=1)
    assert sol.converged and sol.times[-1] == pytest.approx(1.0)
    warned = [w for w in sol.stats[0].get("warnings", []) if "exact stick's friction" in w]
    assert warned
    # the attempt with friction gives up once it cycles (steps.STEP_ZERO_CYCLE), not after the whole budget
    assert "cycling" in warned[0]
    assert sol.stats[-1]["iterations"] <= 8
    c = sol.contact()
    assert (c["normal_force"] > 0).sum() > 100 and (c["stick"][c["normal_force"] > 0]).any()


def test_the_forces_only_mortar_kernel_gives_the_bits_of_the_full_one(monkeypatch):
    """``kernel_jit.mortar_forces`` (a line-search trial's: no frame variations, no gradient rows, no tangent)
    against ``mortar_terms``: every term it returns the same bits, on pressed and slid pairs with history."""
    from beamsolver.contact import kernel_jit
    compiled, X, pm = _mortar_inputs(monkeypatch)
    full, forces = compiled(X, pm), kernel_jit.mortar_forces(X, pm)
    assert set(forces) == set(full) - {"dK", "dS", "dlam_n", "dn", "G"}     # ``G``: ``A`` contiguous, for the tangent
    for k in forces:
        assert np.array_equal(forces[k], full[k]), k
    assert np.array_equal(full["G"], full["A"]) and full["G"].flags.c_contiguous
    assert np.abs(forces["A"]).max() > 0 and np.abs(forces["S"]).max() > 0


def test_a_residual_evaluation_computes_no_multiplier_blocks_until_they_are_asked_for(monkeypatch):
    """A line-search trial (``tangent=False``) gets the forces and the complementarity residuals only; the
    tangent asked for later at the same poses (an accepted trial) completes the blocks: residuals and blocks
    equal to those of an evaluation with the tangent from the start."""
    from beamsolver.contact import kernel_jit
    calls = []
    full = kernel_jit.mortar_terms
    monkeypatch.setattr(kernel_jit, "mortar_terms", lambda *a, **k: calls.append(1) or full(*a, **k))
    model, slave, master = _parallel(0.5)
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = _pressed(problem, slave, 2e-3 * R)
    problem.begin_step(H, 0.0)
    problem.commit(H)
    H = _move(H, slave.nodes, se3.exp(np.array([1e-4 * R, 0.0, 0.0, 0.0, 0.0, 0.0])))
    problem.begin_step(problem.system.poses0, 1.0)
    trial = problem.evaluate(H, 1.0, tangent=False)
    assert not calls and "Kql" not in trial.mult and trial.kvals is None
    later = problem.evaluate(H, 1.0, tangent=True)
    assert len(calls) == 1
    problem.contact._blocks = None
    fresh = problem.evaluate(H, 1.0, tangent=True)
    np.testing.assert_array_equal(trial.r, fresh.r)
    np.testing.assert_array_equal(trial.mult["C"], fresh.mult["C"])
    for k in ("Kql", "Klq", "Kll", "C"):
        np.testing.assert_array_equal(later.mult[k], fresh.mult[k])
    np.testing.assert_array_equal(later.extra[2], fresh.extra[2])


@pytest.mark.parametrize("regime", ["stick", "slip", "turned"])
def test_condensed_step_is_the_bordered_one(regime):
    """The Newton step with the multiplier components eliminated per group (``nonlinear.condense``: sliding and
    unloaded groups entirely, a sticking group's normal component) equals the full bordered solve's to round-off,
    poses and multipliers, also with prescribed increments on held nodes (the Schur terms' coupling)."""
    import scipy.sparse.linalg as spla
    problem, H, dz_c = _slid(regime)
    system = problem.system
    nf = system.n_free
    for prescribed in (None, dz_c):
        ev = problem.evaluate(H, 0.0, tangent=True)
        rhs = -ev.r[system.free_dofs] - (0.0 if prescribed is None else problem.coupling(ev, prescribed))
        A, b = problem.bordered(ev, problem.tangent(ev), rhs, prescribed)
        full = spla.spsolve(A.tocsc(), b)
        A2, b2 = problem.linear_system(ev, prescribed)
        dq, dlam = problem.split_solution(ev, spla.spsolve(A2.tocsc(), b2), prescribed)
        sp = ev.mult["split"]
        assert A2.shape[0] - nf == len(sp.kept) < 3 * len(ev.mult["C"])
        if regime == "slip":
            assert sp.elim.all(axis=1).any() and not ev.mult["stick"].all()
        else:
            assert (sp.elim.sum(axis=1) == 1).any()
        assert np.abs(dq - full[:nf]).max() <= 1e-11 * np.abs(full[:nf]).max()   # measured 2e-14 .. 5e-13
        assert np.abs(dlam.ravel() - full[nf:]).max() <= 1e-11 * np.abs(full[nf:]).max()


@pytest.mark.parametrize("regime", ["stick", "slip"])
def test_switched_rows_condensed_step_is_the_bordered_one(regime):
    """Newton's active-set directions (``Newton._rows_solve``): the groups' rows switched to the other branch
    (``Problem.branch_rows``: sticking ones sliding along their trial, sliding ones sticking) and condensed in the
    evaluation's basis (``Problem.rows_of``) give the full bordered system's step to round-off, directly and through
    ``A = K' + Kq E Kl`` (GMRES), with prescribed increments too; after the context the evaluation's rows and tangent
    are back (its residual of the multipliers' equations, which the line search reads, unchanged)."""
    import scipy.sparse.linalg as spla
    from beamsolver.nonlinear import linsolve
    problem, H, dz_c = _slid(regime, n_slave=6)         # every group sticking / sliding: half switched to the other
    problem.want_branch_rows(True)
    nf = problem.system.n_free
    for prescribed in (None, dz_c):
        ev = problem.evaluate(H, 0.0, tangent=True)
        mu = ev.mult
        raw, C0 = problem.tangent(ev).toarray(), mu["C"].copy()
        stick = mu["stick"].copy()
        stick[::2] = ~stick[::2]                      # every other group switched
        stick = np.where(mu["weak"], mu["stick"], stick)
        assert (stick != mu["stick"]).sum() >= 3 and stick.any() and not stick.all()
        rows = problem.branch_rows(ev, stick, mu["trial"])
        A, b = problem.linear_system(ev, prescribed, condense=False, rows=rows)
        full = spla.spsolve(A.tocsc(), b)
        with problem.rows_of(ev, rows):
            A2, b2 = problem.linear_system(ev, prescribed)
            assert A2.shape[0] - nf == len(mu["split"].kept) < 3 * len(mu["C"])
            direct = problem.split_solution(ev, spla.spsolve(A2.tocsc(), b2), prescribed)
        with problem.rows_of(ev, rows):
            aug = problem.augmented_system(ev, prescribed)
            augmented = problem.split_solution(ev, aug.solve(linsolve.Solver()), prescribed)
        for dq, dlam in (direct, augmented):                       # measured <= 2.1e-12 and 7.3e-14
            assert np.abs(dq - full[:nf]).max() <= 1e-10 * np.abs(full[:nf]).max()
            assert np.abs(dlam.ravel() - full[nf:]).max() <= 1e-10 * np.abs(full[nf:]).max()
        assert "split" not in mu and np.array_equal(mu["C"], C0)
        assert np.abs(problem.tangent(ev).toarray() - raw).max() <= 1e-9 * np.abs(raw).max()


def test_the_tangent_at_the_points_tractions_is_the_contraction_of_the_four(monkeypatch):
    """``mortar_terms(T=)`` (exact stick: the tractions are the multipliers, known before the call) computes the
    tangent at fixed traction from two tangents (at ``T`` and at 0): ``sum_k T_k dK_k`` of the four-traction form
    to round-off, and the other terms the same bits."""
    from beamsolver.contact import reference
    compiled, X, pm = _mortar_inputs(monkeypatch)
    T = np.random.default_rng(0).normal(size=(len(X), 3)) * 100.0
    four, two = compiled(X, pm), compiled(X, pm, T=T)
    exact = reference.mortar_point_derivatives(X, pm, T)["dfdq"]
    err_two, err_four = (np.abs(a - exact).max() / np.abs(exact).max()
                         for a in (two["dfdq"], np.einsum("pk,pkij->pij", T, four["dK"])))
    assert err_two < 1e-10 and err_two <= err_four       # measured 1.8e-12 and 2.4e-10 (the four's differences)
    for k in set(four) - {"dK"}:
        assert np.array_equal(two[k], four[k]), k


def test_a_second_evaluation_of_the_same_poses_has_the_tangent_without_the_schur_terms():
    """The groups' blocks go to the evaluation without a copy and the condensed Newton system adds its Schur terms
    to them in place: evaluated again at the same poses (a step's start after ``at_rest``), the contact computes
    them again; the tangent and the Newton system are those of a fresh evaluation."""
    problem, H, first = _slid_evaluation()
    A1, b1 = problem.linear_system(first)
    assert len(first.mult["split"].kept) < 3 * len(first.mult["C"])
    again = problem.evaluate(H, 0.0, tangent=True)
    problem.contact._blocks = None
    fresh = problem.evaluate(H, 0.0, tangent=True)
    np.testing.assert_array_equal(again.extra[2], fresh.extra[2])
    A2, b2 = problem.linear_system(again)
    assert np.array_equal(A1.toarray(), A2.toarray()) and np.array_equal(b1, b2)


def test_the_mortar_kernel_gives_the_pairs_kernel_without_friction(monkeypatch):
    """Every active pair a mortar pair: ``_local_blocks`` takes the pairs' forces and point data from the mortar
    kernel's pass at zero traction (``mortar_terms(pairs=True)``, ``mortar_forces(pairs=True)``) instead of a second
    pass of the point kernel without friction: the same bits.  At zero traction the whole tangent is the point
    kernel's without friction, the points out of the normal law (their forces' pass only, zeros) included."""
    from beamsolver.contact import kernel_jit
    compiled, X, pm = _mortar_inputs(monkeypatch)
    X = X.copy()
    X[::3, 2:, 2, 3] -= 4.0 * R          # every third pair's master moved away: out of the normal law
    zero = np.zeros((len(X), 3))
    f, K, ref = kernel_jit.kernel_and_tangent(X, pm, friction=False)
    assert (ref["lam_n"] == 0).any() and (ref["lam_n"] > 0).any()      # points in and out of the normal law
    for d in (compiled(X, pm, T=zero, whole=True, pairs=True), kernel_jit.mortar_forces(X, pm, pairs=True)):
        fp, out = d["pairs"]
        assert np.array_equal(fp, f)
        for k in out:
            assert np.array_equal(out[k], ref[k]), k
    assert np.array_equal(compiled(X, pm, T=zero, whole=True)["dfdq"], K)


def test_nodal_table_of_exact_stick_is_in_the_solution_and_its_file(tmp_path):
    """``Solution.extra["mortar_*"]``: per slave node and master beam the nodal forces whose cone the law
    holds; on the shear lag (10 elements) the slipping nodes are those of the pulled end, on the cone to
    Newton's tolerance (``|C_g| m_g <= rtol F``, ``F`` the force scale), the sticking ones inside it with a weighted slip below ``stick_tolerance``; the
    forces sum to the pull; saved and loaded as they are.  The penalty stick has no such table."""
    sol, wire, a, x, N = _shear_lag(10)
    ex = sol.extra
    node, fn, ft = ex["mortar_node"][-1], ex["mortar_normal_force"][-1], ex["mortar_tangential_force"][-1]
    st, slip = ex["mortar_status"][-1], ex["mortar_slip"][-1]
    assert len(node) == len(fn) == len(ft) == len(st) == len(slip) > 0
    assert set(node) <= set(wire.nodes)
    mag = np.linalg.norm(ft, axis=1)
    xs = sol.poses[0][node, 0, 3]
    assert (st == 2).any() and (st == 1).any()
    assert xs[st == 2].min() > xs[st == 1].max()                      # the slip zone at the pulled end
    tol = 1e-8 * 100.0                               # Newton's rtol on the force scale (at least q L)
    np.testing.assert_allclose(mag[st == 2], 0.3 * fn[st == 2], rtol=0, atol=tol)
    assert np.all(mag[st == 1] < 0.3 * fn[st == 1])
    assert slip[st == 1].max() <= 1e-8 * (0.01 + 0.01)                 # STICK_TOLERANCE (R1 + R2)
    assert abs(ft[:, 0].sum()) == pytest.approx(15.0, rel=1e-3)     # the pull, carried by friction
    sol.save(tmp_path / "s.npz")
    back = bs.load(tmp_path / "s.npz")
    for k in ("mortar_node", "mortar_status", "mortar_tangential_force"):
        np.testing.assert_array_equal(back.extra[k][-1], ex[k][-1])
    pen = shear_lag.main(n_wire=10, stick="penalty")[0]
    assert not any(k.startswith("mortar_") for k in pen.extra)


def _two_committed_steps():
    """A parallel pair's contact with two committed steps of nodal multipliers (t = 0.2: groups 3, 7; t = 0.4:
    groups 3, 7, 11): ``(problem, slave, contact, poses, keys at 0.4, multipliers at 0.4)``."""
    model, slave, master = _parallel(0.5)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = problem.system.poses0.copy()
    k0, k1 = np.array([3, 7], dtype=np.int64), np.array([3, 7, 11], dtype=np.int64)
    L0 = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    L1 = np.array([[2.0, 0.0, 1.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]])
    c.history.commit(c._decl_mu, None, (k1, L1))
    c._commits = [(0.2, (k0, L0)), (0.4, (k1, L1))]
    return problem, slave, c, H, k1, L1


def test_a_step_starts_from_the_multipliers_extrapolated_from_the_last_two_steps():
    """``begin_step`` (exact stick, multipliers as Newton unknowns) starts the step to ``t`` from the nodal multipliers
    linear in ``t`` through the last two converged steps', for the groups both have; a group only the last step has
    keeps its value; a step not beyond the last one (a repeat, or only one step known) starts from the last step's."""
    from beamsolver.contact import system as contact_system
    assert contact_system.EXTRAPOLATE
    _, _, c, H, k1, L1 = _two_committed_steps()
    c.begin_step(H, 0.5)                       # half a step ahead
    keys, lam = c.history.tmult
    np.testing.assert_array_equal(keys, k1)
    np.testing.assert_allclose(lam, [[2.5, 0.0, 1.5], [0.0, 0.5, 0.0], [5.0, 5.0, 5.0]], rtol=1e-15)
    for t in (0.4, 0.3):                       # not beyond the last step: the last step's
        c.begin_step(H, t)
        np.testing.assert_array_equal(c.history.tmult[1], L1)
    c._commits = c._commits[-1:]               # one step known
    c.begin_step(H, 0.5)
    np.testing.assert_array_equal(c.history.tmult[1], L1)


def test_a_step_starts_with_the_groups_that_slid_out_of_their_disk():
    """``begin_step`` scales the extrapolated multipliers of the groups that slid in the last converged step
    (``_slid``) by ``SLID_START``: their traction was on the disk's edge, where round-off decided whether the step's
    first iterate (no slip yet) sticks; the others are extrapolated as before.  ``commit`` records the groups that
    slid (pressed, not sticking) and ``get_state`` / ``set_state`` carry them (restart)."""
    from beamsolver.contact import system as contact_system
    assert contact_system.SLID_START > 1.0
    problem, slave, c, H, k1, L1 = _two_committed_steps()
    c._slid = np.array([7, 11], dtype=np.int64)
    c.begin_step(H, 0.5)
    s = contact_system.SLID_START
    np.testing.assert_allclose(c.history.tmult[1], [[2.5, 0.0, 1.5], [0.0, 0.5 * s, 0.0], [5.0 * s, 5.0 * s, 5.0 * s]],
                               rtol=1e-15)
    state = c.get_state()
    np.testing.assert_array_equal(state["slid_keys"], [7, 11])
    c._slid = None
    c.set_state(state)
    np.testing.assert_array_equal(c._slid, [7, 11])
    c.commit(_pressed(problem, slave, 2e-3 * R))       # pressed, nothing slid in this step
    assert c._slid is not None and len(c._slid) == 0


@pytest.mark.slow
def test_three_wires_exact_stick_iterations_with_extrapolated_multipliers(monkeypatch):
    """Three wires twisted half a turn in four steps (12 elements) with exact stick: at most 150 Newton iterations
    (measured 102 and one cut-back in session 6, 141 and one with the session 7 ``c``; 219 and two cut-backs when
    each step started from the last step's multipliers, its Newton then switching most groups from stick to slip
    and back in the first iterations).  The extrapolation alone: ``SLID_START`` 1 (with its default 1.2, which the
    strand cycle needs, 245 iterations against 492 without, this scene takes 152 and two cut-backs)."""
    from beamsolver.contact import system as contact_system
    monkeypatch.setattr(contact_system, "SLID_START", 1.0)
    import contextlib
    import io
    import three_wires
    with contextlib.redirect_stdout(io.StringIO()):
        sol = three_wires.main(stick="exact", n_elements=12, turns=0.5, steps=4)[0]
    assert sol.converged and sol.times[-1] == pytest.approx(1.0)
    assert sum(s["iterations"] for s in sol.stats) <= 150


@pytest.mark.parametrize("regime", ["stick", "slip"])
def test_predicted_branches_linearise_the_trial_and_the_disk(regime):
    """``Problem.predicted_branches`` (the active-set inner loop of Newton's direction, ``mortar.branch_rows``): the
    groups' trial tractions and disks at a step ``x`` of poses and multipliers, linearised, against central
    differences of the evaluated ones along ``x`` (multipliers turned in the nodes' frames, so the turn's columns
    count); and ``Problem.branch_rows`` gives the evaluated rows where no branch changes."""
    model, slave, master = _parallel(0.5 if regime == "stick" else 0.05,
                                     **(dict(penalty_t=1e7) if regime == "slip" else {}))
    problem = Problem.from_model(model, check_rigid_modes=False)
    problem.want_branch_rows(True)
    c, system = problem.contact, problem.system
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)
    keys, lam = c.history.tmult
    c.history.update_multipliers(tmult=(keys, np.random.default_rng(3).normal(size=lam.shape) * 5.0))
    slide = {"stick": 1e-7, "slip": 2e-3}[regime] * R
    H = _move(H, slave.nodes, se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide])))
    ev = problem.evaluate(H, 0.0, tangent=True)
    mu = ev.mult
    assert "Tq" in mu and mu["stick"].any() == (regime == "stick")
    rng = np.random.default_rng(7)
    nf, g = system.n_free, len(mu["key"])
    x = np.concatenate([rng.normal(size=nf) * 1e-3 * R, rng.normal(size=3 * g)])
    stick, trial, cap = problem.predicted_branches(ev, x)
    h = 1e-5
    dz = np.zeros(6 * system.n_nodes)
    dz[system.free_dofs] = x[:nf]
    ends = []
    for s in (h, -h):
        c.multiplier_step(mu["key"], x[nf:].reshape(-1, 3))
        c.multiplier_trial(s)
        e = problem.evaluate(problem.update(H, s * dz.reshape(-1, 6)), 0.0, tangent=True)
        assert np.array_equal(e.mult["key"], mu["key"])
        ends.append((e.mult["trial"], e.mult["cap"]))
    c.multiplier_step(mu["key"], np.zeros((g, 3)))
    fd_trial, fd_cap = ((a - b) / (2 * h) for a, b in zip(*ends))
    lin_trial, lin_cap = trial - mu["trial"], cap - mu["cap"]
    assert np.abs(fd_trial).max() > 0 and np.abs(fd_cap).max() > 0
    assert np.abs(lin_trial - fd_trial).max() < 1e-6 * np.abs(fd_trial).max()
    assert np.abs(lin_cap - fd_cap).max() < 1e-6 * np.abs(fd_cap).max()
    for a, b in zip(problem.branch_rows(ev, mu["stick"], trial), (mu["Klq"], mu["Kll"], mu["C"])):
        np.testing.assert_array_equal(a, b)


def test_shear_lag_slip_front_moves_several_nodes_per_newton_iteration(monkeypatch):
    """Shear lag (10 elements), exact stick: the pull's two steps take at most 4 Newton iterations each (measured 3
    and 2; the penalty stick 2 and 2).  Each sticking node is rigid, so a Newton step on the iterate's branches loads
    only the first sticking node and the slip front moved by one node per iteration (6 and 8); the active-set inner
    loop of Newton's direction (``newton.INNER_SWITCHES``) switches the nodes the linearised step pushes out of their
    disks and solves again (an option: ``INNER_SWITCHES = 8``).  The answer is the one the tests above check (slip
    zone within an element)."""
    from beamsolver.nonlinear import newton
    monkeypatch.setattr(newton, "INNER_SWITCHES", 8)
    sol, wire, a, x, N = _shear_lag(10)
    pull = [s["iterations"] for s in sol.stats[-2:]]
    assert max(pull) <= 4, pull
    assert abs(shear_lag.slip_zone(sol, wire) - a) < 0.1


def test_a_failed_step_s_retry_predicts_the_slip_front(monkeypatch):
    """Shear lag on 100 elements (100 groups), exact stick, ``max_iter = 12``: the pull's first step fails (the slip
    front moves a node or two an iteration) and is retried at half length; there every Newton direction predicts the
    groups' branches (``newton.RETRY_SWITCHES``): the retry converges in at most 4
    iterations (measured 3; 9 without), and the answer is the same (slip zone)."""
    from beamsolver.nonlinear import newton
    model, wire, _ = shear_lag.build(n_wire=100, stick="exact")
    sol = bs.solve(model, steps=4, max_iter=12)
    retried = [s for s in sol.stats if s.get("cutbacks")]
    assert retried and retried[0]["iterations"] <= 4, [(s["iterations"], s.get("cutbacks")) for s in sol.stats]
    zone = shear_lag.slip_zone(sol, wire)
    monkeypatch.setattr(newton, "RETRY_SWITCHES", 0)
    model, wire, _ = shear_lag.build(n_wire=100, stick="exact")
    before = bs.solve(model, steps=4, max_iter=12)
    assert [s for s in before.stats if s.get("cutbacks")][0]["iterations"] > 4
    assert abs(shear_lag.slip_zone(before, wire) - zone) < 1e-9


def test_uncondense_gives_back_the_tangent_without_the_schur_terms():
    """``Problem.uncondense`` (the inner loop's bordered solves after a condensed one) takes the eliminated components'
    Schur terms out of the evaluation's tangent values again: the tangent of a fresh evaluation to round-off, and the
    full bordered system is built from it."""
    problem, H, ev = _slid_evaluation()
    raw = problem.tangent(ev).toarray()
    problem.linear_system(ev)
    schur = np.abs(problem.tangent(ev).toarray() - raw).max()
    assert "split" in ev.mult and schur > 0.0
    problem.uncondense(ev)
    assert "split" not in ev.mult
    assert np.abs(problem.tangent(ev).toarray() - raw).max() <= 1e-6 * schur
    A, _ = problem.linear_system(ev, condense=False)
    assert A.shape[0] == problem.system.n_free + 3 * len(ev.mult["C"])
    assert np.abs(problem.tangent(ev).toarray() - raw).max() <= 1e-6 * schur


def test_a_step_s_first_newton_step_leaves_the_sliding_groups_out_of_their_disk(monkeypatch):
    """The step's first Newton step of the multipliers (the predictor's, ``multiplier_step`` with the iterate's stick
    flags and disks) ends a group not sticking at ``f (Lam + dLam)``, ``f = 1 + FIRST_SLIDE | |Lam + dLam| / cap - 1 |``
    (at most ``FIRST_SLIDE_MAX``): out of its linearised disk by that step's relative change of the disk, where the
    disk's nonlinearity decided the next iterate's branch (the twisted pair at t = 0.4375: three of its four sliding
    groups stuck there with slips of 1e5-1e6 times the tolerance).  Sticking groups, groups without a disk, groups
    whose disk shrinks or whose traction turns back (``FIRST_SLIDE_GROWN``) and later Newton steps are not scaled."""
    from beamsolver.contact import system as contact_system
    monkeypatch.setattr(contact_system, "FIRST_SLIDE", 1.0)
    top = contact_system.FIRST_SLIDE_MAX
    model, slave, master = _parallel(0.5)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = problem.system.poses0.copy()
    assert contact_system.FIRST_SLIDE_GROWN
    keys = np.array([3, 7, 11, 12, 13, 14], dtype=np.int64)
    Lam = np.array([[2.0, 0.0, 1.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0],
                    [0.0, 0.0, 2.0]])
    dLam = np.array([[1.0, 1.0, 1.0], [0.5, 0.0, 0.0], [-1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-2.0, 0.0, 0.0],
                     [0.0, 0.0, -1.0]])
    stick = np.array([True, False, False, False, False, False])
    cap = np.array([9.0, 1.0, 4.0, 0.0, 0.5, 1.5])
    c.begin_step(H, 0.5)
    c.history.update_multipliers(None, (keys, Lam))
    c.multiplier_step(keys, dLam, stick, cap)
    c.multiplier_trial(1.0)
    f = np.sqrt(1.25)                                   # 1 + (|(0.5, 1, 0)| / 1 - 1)
    np.testing.assert_allclose(c.iterate_multipliers(keys),
                               [[3.0, 1.0, 2.0], [0.5 * f, f, 0.0], [4.0 * top, 5.0 * top, 6.0 * top], [0.0, 2.0, 0.0],
                                [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], rtol=1e-15)
    c.accept_multipliers()
    c.multiplier_step(keys, dLam, stick, cap)      # the step's second Newton step: as computed
    c.multiplier_trial(1.0)
    np.testing.assert_allclose(c.iterate_multipliers(keys) - c.history.tangential_multipliers(keys), dLam, rtol=1e-15)


def test_a_touching_start_crawling_to_the_normal_law_s_double_root_is_progress_not_a_stall(monkeypatch):
    """Step 0 of the contact patch (touching beams, exact stick's friction) without the parabola's secant
    (``newton.START_SECANT``, which takes it there in 2: ``test_contact_touching_secant.py``): Newton crawls to the
    smoothed normal law's zero-force end (docs/theory/contact_laws.md 17.2), its scaled residual constant to 10 digits
    while its increments halve, 11 iterations. The stall window (``steps.STEP_ZERO_STALL`` = 10 iterations) counts a
    new shortest increment as progress: without it step 0 fell back to a start without friction, whose tangent is
    singular here (the slave is held along the beams by friction alone)."""
    from beamsolver.nonlinear import newton
    from beamsolver.stepping import steps
    monkeypatch.setattr(newton, "START_SECANT", False)
    model, slave, master = contact_patch.build(stick="exact")
    sol = bs.solve(model, **contact_patch.solve_options)
    st = sol.stats[0]
    assert sol.converged and st["iterations"] > steps.STEP_ZERO_STALL
    assert np.ptp(np.log10(st["residuals"])) < 1e-6                       # no new lowest residual on the way
    assert not [w for w in st.get("warnings", []) if "exact stick's friction" in w]


def test_the_full_bordered_systems_of_one_evaluation_share_its_tangent():
    """``linear_system(condense=False)`` keeps the tangent of the values without Schur terms (``Problem._full_tangent``:
    the active-set inner loop's bordered solves on one evaluation): the same bits as a fresh ``tangent``, built once,
    dropped when the condensed system puts its Schur terms into the values (and with the evaluation's tangent)."""
    problem, H, ev = _slid_evaluation()
    A, rhs = problem.linear_system(ev, condense=False)
    K = ev.mult["K_full"]
    assert np.array_equal(K.data, problem.tangent(ev).data)
    B, rhs2 = problem.linear_system(ev, condense=False)
    assert ev.mult["K_full"] is K and np.array_equal(A.data, B.data) and np.array_equal(rhs, rhs2)
    problem.linear_system(ev)
    assert "K_full" not in ev.mult
    problem.uncondense(ev)
    problem.linear_system(ev, condense=False)
    assert np.array_equal(ev.mult["K_full"].data, problem.tangent(ev).data)
    ev.drop_tangent()
    assert "K_full" not in ev.mult
