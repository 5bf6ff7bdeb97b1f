"""Contact next to a joint (issue 14): elements meeting at a ``join`` never pair.

Two beams joined end to end (``join``, with or without ``rigid=True``, or both joined to one
node there) with contact declared between them: before the fix ``rules.apart`` compared node
ids only, so the two elements at the joint, whose centre lines meet there, became a contact
pair.  At a kink of 45 to 120 degrees the solve stopped with "the centre lines ... intersect:
no contact normal ... Separate them", at 150 degrees with "no convergence ... the tangent at
t = 0 is already indefinite".  In a straight line (0 degrees) the pair was not formed (the
Gauss points project past the master beam's end), which the straight case pins.  A rigid link
between nodes apart (wire ends on a plate node) does not make the wires' elements neighbours:
touching wires keep their contact up to the plate.
"""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import rules
from beamsolver.nonlinear.problem import Problem


import twisted_pair_extreme as twisted_pair

R, L = 0.5e-3, 0.05


def _joined(angle_deg, via, contact=True, n=4):
    """Beam ``a`` along ``e_x`` clamped at 0, beam ``b`` from its end at ``angle_deg`` to ``e_x``,
    tied there by ``via``: "join", "rigid" (``rigid=True`` on coincident nodes) or "node" (both
    joined to one node at the joint); a small load at ``b``'s end."""
    sec = bs.Section.circular(radius=R, E=200e9, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n), sec, name="a")
    t = np.deg2rad(angle_deg)
    p = np.array([L, 0.0, 0.0])
    b = m.add_beam(bs.geometry.straight(p, p + L * np.array([np.cos(t), np.sin(t), 0.0]), n), sec, name="b")
    if via == "node":
        j = m.add_node(p, name="joint")
        m.join(j, a.last)
        m.join(j, b.first)
    else:
        m.join(a.last, b.first, rigid=via == "rigid")
    m.clamp(a.first)
    m.add_load(b.last, force=(0.0, 0.0, -1e-3))
    if contact:
        m.add_contact(a, b)
    return m, a, b


def test_joint_nodes_merges_the_coincident_nodes_of_a_join_group():
    #            0: alone  1, 2: joined, coincident  3, 4: one group, apart  5, 6: coincident, not joined
    group = np.array([0, 1, 1, 3, 3, 5, 6])
    x = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1e-12], [2, 0, 0], [2, 1, 0], [3, 0, 0], [3, 0, 0]], dtype=float)
    ids = rules.joint_nodes(group, x, 1e-9)
    assert ids[1] == ids[2]
    assert len({ids[0], ids[1], ids[3], ids[4], ids[5], ids[6]}) == 6


def test_joint_nodes_merges_nodes_tied_through_a_rigid_link():
    """Two wire ends at one point, each linked rigidly to a plate node away from them: one joint."""
    group = np.array([7, 7, 7, 4])
    x = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1], [0, 0, 0]], dtype=float)
    ids = rules.joint_nodes(group, x, 1e-9)
    assert ids[0] == ids[1] and len({ids[0], ids[2], ids[3]}) == 3


@pytest.mark.parametrize("via", ["join", "rigid", "node"])
@pytest.mark.parametrize("angle", [0.0, 45.0, 90.0, 150.0])
def test_elements_meeting_at_a_joint_never_pair(angle, via):
    m, a, b = _joined(angle, via)
    problem = Problem.from_model(m)
    P = problem.contact.pairs(problem.system.poses0)
    assert P is None or len(P) == 0


@pytest.mark.parametrize("via", ["join", "rigid", "node"])
@pytest.mark.parametrize("angle", [0.0, 90.0, 150.0])
def test_a_joint_with_contact_declared_solves_to_the_no_contact_answer(angle, via):
    m, a, b = _joined(angle, via)
    sol = bs.solve(m, steps=2)
    ref = bs.solve(_joined(angle, via, contact=False)[0], steps=2)
    assert sol.converged and ref.converged
    assert len(sol.contact(-1)["normal_force"]) == 0
    np.testing.assert_allclose(sol.poses[-1], ref.poses[-1], rtol=0, atol=1e-12)
    assert abs(sol.position(b.last)[2]) > 1e-6        # the load did bend the pair


def test_a_rigid_link_between_nodes_apart_keeps_contact_up_to_the_plate():
    """Touching wires rigidly linked to one plate node: the last elements of the two wires are
    tied through the plate but apart, and remain a contact pair."""
    model, plate, (wa, wb) = twisted_pair.build(length=0.02, n_elements=4, turns=0.1, mu=0.0, pull=5.0)
    problem = Problem.from_model(model)
    P = problem.contact.pairs(problem.system.poses0)
    last = {wa.elements[-1], wb.elements[-1]}
    assert any(int(e) in last and int(k) in last for e, k in zip(P.e, P.m))
