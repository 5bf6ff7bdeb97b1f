"""Known defect found while writing the property tests (reported, not fixed here): two beams
crossing exactly at a node of each, the upper one clamped at both ends and pushed down at that
node, lose their contact point -- the two slave elements meeting at the kink each project the
crossing just past their own end (xi = 1.0001 and -0.0001, outside ``XI_TOL``), so no pair is
kept and the beams pass through each other while the solve reports "converged"."""
import pytest

import beamsolver as bs


@pytest.mark.xfail(strict=True, reason="contact point lost at a kink node (point pair outside both elements)")
def test_crossing_at_a_kink_node_keeps_its_contact_point():
    r, n = 0.05, 8
    sec = bs.Section.circular(radius=r, E=1e7, nu=0.3)
    m = bs.Model()
    lower = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), n), sec)
    upper = m.add_beam(bs.geometry.straight((-1, 0, 2 * r), (1, 0, 2 * r), n), sec)
    for node in (lower.first, lower.last, upper.first, upper.last):
        m.clamp(node)
    m.add_load(upper.nodes[n // 2], force=(0.0, 0.0, -50.0))
    m.add_contact(upper, lower)
    sol = bs.solve(m, steps=2, verbose=False)
    gap = sol.position(upper.nodes[n // 2])[2] - sol.position(lower.nodes[n // 2])[2] - 2 * r
    assert gap > -0.1 * r                                        # today: -0.036, 72 % of a radius
    assert sol.contact()["normal_force"].sum() > 1.0                  # today: no contact point at all
