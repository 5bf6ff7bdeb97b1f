"""Exact stick on beams made of pieces (``contact.system.beam_chains``): a master chain has one multiplier per slave
node, and ``c`` takes the slave's length from its chain (docs/theory_mortar.md 3b, 3d "Chains")."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import system

import plectoneme
import shear_lag

SEC = bs.Section.circular(radius=0.01, E=1e9, nu=0.3)


def test_beam_chains_follow_end_to_end_joins_only():
    """The plectoneme's wires (two pieces joined rigidly, upper ends linked to a plate node outside beams): one chain per
    wire of 24 elements; the plate does not chain the wires.  Beams sharing an end node chain too; a join to a node
    inside a beam does not."""
    model, _, wires = plectoneme.build(n_elements=24, length=0.06, approach=0.3)
    root, count = system.beam_chains(model)
    assert root.tolist() == [0, 0, 2, 2] and count.tolist() == [24] * 4
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 3), SEC)
    b = m.add_beam(bs.geometry.straight((1, 0, 0), (2, 0, 0), 4), SEC)
    c = m.add_beam(bs.geometry.straight((0, 1, 0), (1, 1, 0), 5), SEC)
    d = m.add_beam(bs.geometry.straight((0, 2, 0), (1, 2, 0), 2), SEC)
    m.join(b.first, a.last)
    m.join(c.nodes[2], d.first, rigid=True)         # not at an end of c
    root, count = system.beam_chains(m)
    assert root.tolist() == [0, 0, 2, 3] and count.tolist() == [7, 7, 5, 2]


def test_default_c_takes_the_slave_length_of_its_chain(monkeypatch):
    """The plectoneme's wire against the other wire: 2 beams of 12 elements are one slave of 24 (``c`` 8 times lower
    than two slaves of 12); with ``CHAIN_C = False`` the count per beam, as before."""
    model, _, _ = plectoneme.build(n_elements=24, length=0.06, approach=0.3, stick="exact")
    EI = model.beams[0].section.C[4, 4]
    L = np.full(24, 0.06 / 24)
    cs = system.ContactSystem(bs.nonlinear.problem.Problem.from_model(model).system)
    assert cs.decls[0].eps_t == pytest.approx(system.exact_c(EI, L, 24), rel=1e-12)
    assert cs.decls[1].eps_t == pytest.approx(system.exact_c(EI, L, 24), rel=1e-12)   # a wire's halves: one chain
    monkeypatch.setattr(system, "CHAIN_C", False)
    cs = system.ContactSystem(bs.nonlinear.problem.Problem.from_model(model).system)
    assert cs.decls[0].eps_t == pytest.approx(8.0 * system.exact_c(EI, L, 24), rel=1e-12)


def _shear_lag(pieces, cut=6, n_rod=13, n_wire=20, L=1.0, r=0.01, q=100.0, F=15.0, mu=0.3):
    """``examples/shear_lag.py``'s scene (exact stick) with its clamped rod in ``pieces`` beams (1 or 2, joined rigidly
    at the end of element ``cut``: the same elements either way)."""
    model = bs.Model()
    x0, x1 = -0.05 * L, 1.05 * L
    if pieces == 1:
        rods = [model.add_beam(bs.geometry.straight((x0, 0, 0), (x1, 0, 0), n_rod), SEC)]
    else:
        xm = x0 + (x1 - x0) * cut / n_rod
        rods = [model.add_beam(bs.geometry.straight((x0, 0, 0), (xm, 0, 0), cut), SEC),
                model.add_beam(bs.geometry.straight((xm, 0, 0), (x1, 0, 0), n_rod - cut), SEC)]
        model.join(rods[0].last, rods[1].first, rigid=True)
    wire = model.add_beam(bs.geometry.straight((0, 0, 2 * r), (L, 0, 2 * r), n_wire), SEC)
    for rod in rods:
        for node in rod.nodes:
            if pieces == 1 or node != rods[1].first:         # (a joint's constraint goes on one of its nodes)
                model.clamp(node)
    for node in wire.nodes:
        model.fix(node, dofs=("uy", "rx", "rz"))
    for k, node in enumerate(wire.nodes):
        share = 0.5 if k in (0, n_wire) else 1.0
        model.add_load(node, force=(0, 0, -q * L / n_wire * share), scale=lambda t: min(2.0 * t, 1.0))
    model.add_load(wire.last, force=(F, 0, 0), scale=lambda t: max(2.0 * t - 1.0, 0.0))
    model.add_contact(wire, rods, mu=mu)
    sol = bs.solve(model, steps=8, verbose=False)
    return sol, wire


def test_a_master_in_two_pieces_gives_the_one_piece_answer():
    """The shear lag on a rod cut in two beams joined rigidly, the cut under the stick zone: the same elements, so the
    same answer as the one-piece rod (axial forces to 1e-9 F, the slip zone, the iterations)."""
    one, wire1 = _shear_lag(1)
    two, wire2 = _shear_lag(2)
    N1, N2 = (s.section_forces[-1][w.elements, 0] for s, w in ((one, wire1), (two, wire2)))
    assert np.abs(N1 - N2).max() <= 1e-9 * 15.0
    assert shear_lag.slip_zone(two, wire2) == pytest.approx(shear_lag.slip_zone(one, wire1), abs=1e-12)
    assert int(two.iterations.sum()) == int(one.iterations.sum())


@pytest.mark.parametrize("hold", [True, False])
def test_groups_per_master_beam_miss_the_one_piece_answer(monkeypatch, hold):
    """The scene above with the rule before (a group per master beam, ``CHAIN_GROUPS = False``): the slave nodes next to
    the cut have a multiplier against each piece, whose weighted slips are one constraint when both stick.  Measured:
    a singular tangent at t = 0 (``HOLD_CROSSINGS = False``), or 96 iterations instead of 59 and axial forces off by
    2e-3 F, the slip zone 0.538 m instead of 0.498 (``F / (mu q)`` = 0.5).  Guards that the test above can fail."""
    monkeypatch.setattr(system, "CHAIN_GROUPS", False)
    monkeypatch.setattr(system, "HOLD_CROSSINGS", hold)
    one, wire1 = _shear_lag(1)
    try:
        two, wire2 = _shear_lag(2)
    except bs.ConvergenceError:
        return
    N1, N2 = (s.section_forces[-1][w.elements, 0] for s, w in ((one, wire1), (two, wire2)))
    assert np.abs(N1 - N2).max() > 1e-4 * 15.0


def _crossing_scene(angle_deg, stick="exact", mu=0.3):
    """A slave beam touching a master beam at ``angle_deg`` in the plane ``z = 2 R`` (6 elements each)."""
    R = 0.01
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((-0.5, 0, 0), (0.5, 0, 0), 6), SEC)
    a = np.radians(angle_deg)
    d = 0.5 * np.array([np.cos(a), np.sin(a), 0.0])
    slave = m.add_beam(bs.geometry.straight(tuple(-d + [0, 0, 2 * R]), tuple(d + [0, 0, 2 * R]), 6), SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, stick=stick)
    return m, slave


def _turned(H, nodes, angle_deg):
    """``H`` with ``nodes`` turned by ``angle_deg`` about ``e_z`` through the origin."""
    from beamsolver import se3
    G = np.eye(4)
    a = np.radians(angle_deg)
    G[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    H = H.copy()
    H[nodes] = se3.compose(np.broadcast_to(G, (len(nodes), 4, 4)), H[nodes])
    return H


@pytest.mark.parametrize("hold", [True, False])
def test_line_or_crossing_is_kept_within_a_step_with_exact_stick(monkeypatch, hold):
    """At 19.8 degrees (below ``line_angle``, 20) the pairs are line pairs; turned to 20.3 within the step they stay line
    pairs (``history.step_crossings``: exact stick's friction is the multipliers' on line pairs and the point law's on
    crossings, a jump of the friction force Newton cannot cross); the next step decides afresh: a crossing.  The
    penalty stick decides at every evaluation, as ``HOLD_CROSSINGS = False`` does."""
    from beamsolver.contact.frames import LINE
    monkeypatch.setattr(system, "HOLD_CROSSINGS", hold)
    for stick in ("exact", "penalty"):
        model, slave = _crossing_scene(19.8, stick=stick)
        cs = system.ContactSystem(bs.nonlinear.problem.Problem.from_model(model).system)
        H0 = model.poses0.copy()
        cs.begin_step(H0, 0.1)
        assert (cs.pairs(H0).kind == LINE).all()
        H1 = _turned(H0, slave.nodes, 0.5)
        kept = (cs.pairs(H1).kind == LINE).all()
        assert kept == (hold and stick == "exact")
        cs.begin_step(H1, 0.2)
        assert not (cs.pairs(H1).kind == LINE).any()


def test_points_forced_open_carry_no_normal_force():
    """``ContactSystem.force_open`` (the normal law's open branch, for ``newton.NORMAL_SWITCHES``): the pressed points
    of the frictionless patch test forced open give no contact force and no tangent; released, the same force as
    before (to the bit)."""
    import contact_patch
    model, slave, master = contact_patch.build(mu=0.0, tau=0.0)
    sol = bs.solve(model, steps=2, t_end=0.5, check_rigid_modes=False, verbose=False)
    problem = bs.nonlinear.problem.Problem.from_model(model, check_rigid_modes=False)
    H = sol.poses[-1]
    contact = problem.contact
    pressed = contact.pressed_points(H)
    assert len(pressed) > 10
    b0, _ = contact.evaluate(H)
    contact.force_open(pressed)
    b1, _ = contact.evaluate(H)
    assert len(contact.pressed_points(H)) == 0
    assert np.abs(b1.f).max() == 0.0 and np.abs(b1.K).max() == 0.0
    contact.force_open(None)
    b2, _ = contact.evaluate(H)
    assert np.array_equal(b2.f, b0.f) and np.abs(b0.f).max() > 0.0
