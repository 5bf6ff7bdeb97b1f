"""Contact robustness (issue 14 defects 3 and 4): tunnelling and intersecting centre lines."""
import warnings

import numpy as np
import pytest

import beamsolver as bs

R = 0.05
SEC = bs.Section.circular(radius=R, E=1e7, nu=0.3)


def _pushed_crossing(drop, height=2 * R):
    """A clamped-clamped master along y; a short rigidly moved slave along x above it (centre
    lines ``height`` apart) translated down by ``drop`` t: it must press the master down."""
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 7), SEC, name="master")
    slave = m.add_beam(bs.geometry.straight((-0.3, 0, height), (0.3, 0, height), 2), SEC, name="slave")
    m.clamp(master.first)
    m.clamp(master.last)
    def down(t):
        G = np.eye(4)
        G[2, 3] = -drop * t
        return G

    for node in slave.nodes:
        m.prescribe(node, down)
    m.add_contact(slave, master)
    return m, slave, master


def test_a_step_that_tunnels_is_cut_back():
    """One step moves the slave (0.5 R above the master) down by 6.5 R: its first iterate lies
    below the master, where the pair's gap is positive and its force zero -- "converged" with the
    master untouched unless the change of side is detected and the step cut back."""
    m, slave, master = _pushed_crossing(6.5 * R, height=2.5 * R)
    sol = bs.solve(m, steps=1)
    assert sol.position(master.nodes[3])[2] < -5 * R              # pushed down (was: untouched, 0)
    c = sol.contact()
    assert c["normal_force"].sum() > 100.0 and np.all(c["normal"][:, 2] < -0.99)   # slave above
    assert sum(s["cutbacks"] for s in sol.stats) >= 1


def test_intersecting_centre_lines_name_the_pair():
    """Centre lines that intersect (distance 0) have no contact normal: no division by zero
    (no RuntimeWarning), and the error names the pair (beams and elements).  In the given
    poses it is bad input; inside a step it is a step failure (cut back) with that message."""
    m, slave, master = _pushed_crossing(0.0, height=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(bs.InputError) as err:
            bs.solve(m, steps=1)
    msg = str(err.value)
    assert "'slave'" in msg and "'master'" in msg and "element" in msg and "normal" in msg


def test_tunnelling_is_a_typed_step_failure_naming_the_pair():
    from beamsolver.nonlinear.problem import Problem
    from beamsolver.failures import ContactTunnelling
    m, slave, master = _pushed_crossing(6.5 * R, height=2.5 * R)
    problem = Problem.from_model(m)
    system = problem.system
    cs = problem.contact
    H = system.poses0.copy()
    cs.begin_step(H, 1.0)
    H[slave.nodes, 2, 3] -= 6.5 * R                     # the slave's centre line now under the master's
    with pytest.raises(ContactTunnelling, match="'slave' element .* 'master' element .* changed sides"):
        cs.evaluate(H)
    assert ContactTunnelling.retry                     # the step is cut back
