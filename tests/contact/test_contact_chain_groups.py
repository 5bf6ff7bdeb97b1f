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
    same answer as the one-piece rod (axial forces to 1e-9 F, the slip zone, the iterations).  With a group per master
    beam (``CHAIN_GROUPS = False``) the slave nodes next to the cut had a multiplier against each piece, whose weighted
    slips were one constraint when both stuck: the first step failed (a singular tangent at t = 0)."""
    one, wire1 = _shear_lag(1)
    two, wire2 = _shear_lag(2)
    N1, N2 = (s.section_forces[-1][w.elements, 0] for s, w in ((one, wire1), (two, wire2)))
    assert np.abs(N1 - N2).max() <= 1e-9 * 15.0
    assert shear_lag.slip_zone(two, wire2) == pytest.approx(shear_lag.slip_zone(one, wire1), abs=1e-12)
    assert int(two.iterations.sum()) == int(one.iterations.sum())


def test_groups_per_master_beam_fail_where_the_master_is_cut(monkeypatch):
    """The scene above with the rule before (a group per master beam): guards that the test above can fail."""
    monkeypatch.setattr(system, "CHAIN_GROUPS", False)
    with pytest.raises(bs.ConvergenceError):
        _shear_lag(2)
