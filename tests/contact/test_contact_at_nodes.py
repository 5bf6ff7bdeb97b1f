"""Contact points on or next to a node shared by two elements (issue 14, defect 2).

- Two beams crossing exactly at a node of each, the upper one clamped at both ends and pushed
  down at that node: the two slave elements meeting at the kink each project the crossing just
  past their own end (xi = 1.0001 and -0.0001); the pair must be kept (on one of them), or the
  beams pass through each other while the solve reports "converged".
- A slave Gauss point lying in the plane of a master node projects on both master elements
  sharing it (xi2 = 1 and 0, distances equal to round-off): exactly one of them owns it, the
  same one at every evaluation, and the force is continuous.
"""
import numpy as np

import beamsolver as bs
from beamsolver.nonlinear.problem import Problem
from helpers import crossing_at_nodes


def test_crossing_at_a_kink_node_keeps_its_contact_point():
    r, n = 0.05, 8
    m, upper, lower, _ = crossing_at_nodes(r, n)
    sol = bs.solve(m, steps=2, verbose=False)
    gap = sol.position(upper.nodes[n // 2])[2] - sol.position(lower.nodes[n // 2])[2] - 2 * r
    assert gap > -0.1 * r                                        # was -0.036, 72 % of a radius
    c = sol.contact()
    # equal beams, equally clamped: the contact carries half of the load (was: no contact point)
    np.testing.assert_allclose(c["normal_force"].sum(), 25.0, rtol=0.02)
    assert len(c["normal_force"]) == 1                           # one point pair, not one per element


def _master_node_under_a_gauss_point(lift):
    """Master along x (nodes every 0.25, the node at x = 0 lifted by ``lift``: a kink), a short
    parallel slave above it whose middle Gauss point lies over that node, touching."""
    r = 0.05
    sec = bs.Section.circular(radius=r, E=1e7, nu=0.3)
    m = bs.Model()
    pts = np.array([[x, 0.0, lift if abs(x) < 1e-12 else 0.0] for x in np.linspace(-1, 1, 9)])
    master = m.add_beam(bs.geometry.polyline(pts), sec)
    slave = m.add_beam(bs.geometry.straight((-0.3, 0, 2 * r + lift - 1e-4 * r), (0.3, 0, 2 * r + lift - 1e-4 * r), 1),
                       sec)
    m.clamp(master.first)
    m.clamp(slave.first)
    m.add_contact(slave, master, integration="points")      # the point path: 5 Gauss points per element
    return Problem.from_model(m, check_rigid_modes=False), slave


def _shift(system, nodes, dx):
    H = system.poses0.copy()
    H[nodes, 0, 3] += dx
    return H


def test_gauss_point_on_a_shared_master_node_has_one_stable_owner():
    problem, slave = _master_node_under_a_gauss_point(lift=1e-4)
    system, cs = problem.system, problem.contact
    owners, forces = [], []
    for dx in (2e-11, -2e-11, 2e-11, -2e-11):
        H = _shift(system, slave.nodes, dx)
        P = cs.pairs(H)
        mid = P.gp == 2                                   # the middle of 5 Gauss points
        assert mid.sum() == 1                                # exactly one master element owns it
        owners.append(int(P.m[mid][0]))
        blocks, _ = cs.evaluate(H, tangent=False)
        forces.append(system.assemble_blocks(H, blocks)[0])     # the contact residual
    assert len(set(owners)) == 1, owners                     # the same at every evaluation
    scale = np.abs(forces[0]).max()
    assert scale > 0
    for f in forces[1:]:                                     # continuous: no jump between owners
        assert np.abs(f - forces[0]).max() <= 1e-6 * scale
