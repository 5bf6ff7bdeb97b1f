"""The kind of a crossing element pair (point or orthogonal) is decided once per load step.

Inside one step's Newton iterations the kind of an element pair stays the one chosen at its
first evaluation of the step (the last converged poses, for the pairs present there): in the
plectoneme (examples/plectoneme.py, extension control, ``stabilize`` 1e-4 as a factor) the
closest-point search of an element pair next to a loop crossing landed far outside both
elements (xi = 4.2 / 2.4) with a reduced-Hessian ratio flipping between -32 and 1.2 from one
iterate to the next; its kind flipped between orthogonal and point, and through
``rules.extend_wrap`` so did the genuine crossing next to it (ratio 0.84), whose contact went
from a point pair 15 um deep to orthogonal Gauss points 26 um apart: Newton cycled between
the two iterates until the step was refused, at every step size down to 2e-9.
"""
import numpy as np

import beamsolver as bs
from beamsolver.contact.frames import ORTHOGONAL, POINT
from beamsolver.nonlinear.problem import Problem


def _scene(angle_deg):
    """A straight slave crossing a straight master at ``angle_deg`` (reduced-Hessian ratio
    ``sin^2``: point pair above 45 degrees, orthogonal below, with the default ``point_ratio``)."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7)
    m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 3), sec)
    a = np.deg2rad(angle_deg)
    d = np.array([np.cos(a), np.sin(a), 0.0])
    c = np.array([0.1, 0.0, 0.1])
    slave = m.add_beam(bs.geometry.straight(c - 0.7 * d, c + 0.7 * d, 3), sec)
    m.add_contact(slave, m.beams[0])
    return m


def _kinds(contact, H):
    return set(contact.pairs(H).kind.tolist())


def test_kind_kept_within_a_step_and_updated_at_the_next():
    problem = Problem.from_model(_scene(46.0), check_rigid_modes=False)
    contact = problem.contact
    H46 = problem.system.poses0.copy()
    H44 = Problem.from_model(_scene(44.0), check_rigid_modes=False).system.poses0.copy()
    contact.begin_step(H46, 0.1)
    assert _kinds(contact, H46) == {POINT}
    # an iterate of the same step where the ratio fell below point_ratio: still a point pair
    assert _kinds(contact, H44) == {POINT}
    assert _kinds(contact, H46) == {POINT}
    # the next step starts from the 44 degree poses: decided anew there, then kept
    contact.begin_step(H44, 0.2)
    assert _kinds(contact, H44) == {ORTHOGONAL}
    assert _kinds(contact, H46) == {ORTHOGONAL}


def test_kind_decided_anew_after_restore():
    """``set_state`` (restart, cut-back) forgets the kinds: the first evaluation decides."""
    problem = Problem.from_model(_scene(46.0), check_rigid_modes=False)
    contact = problem.contact
    H44 = Problem.from_model(_scene(44.0), check_rigid_modes=False).system.poses0.copy()
    contact.begin_step(problem.system.poses0, 0.1)
    assert _kinds(contact, problem.system.poses0) == {POINT}
    contact.set_state(contact.get_state())
    assert _kinds(contact, H44) == {ORTHOGONAL}


def test_wrap_extends_only_to_point_pairs_at_the_slave_end():
    """``rules.extend_wrap`` (search.py, rule 3) turns a point pair orthogonal when its slave element
    shares a node with an orthogonal pair against the same master beam *and* its closest point
    sits at the slave's end; a crossing inside the slave element stays a point pair.  In the
    plectoneme a neighbour's orthogonal kind, decided at closest points far outside its elements
    (xi = 4.16 / 2.87, ratio -32), took the point pair from the crossing of the loop's arms
    (xi1 = 0.63): at the converged state of a step the point pair held 1000 N, decided afresh at
    the start of the next step the pair was five Gauss points 31 um or more apart, without force."""
    from beamsolver.contact import rules
    enodes = np.array([[0, 1], [1, 2], [2, 3], [10, 11]])
    master_beam = np.array([1, 1, 1])
    e, m = np.array([1, 0, 2]), np.array([3, 3, 3])
    kind = np.array([ORTHOGONAL, POINT, POINT])
    xi1 = np.array([0.5, 0.63, 0.01])
    assert rules.extend_wrap(enodes, master_beam, 2, e, m, kind, xi1).tolist() == [ORTHOGONAL, POINT, ORTHOGONAL]
    assert rules.extend_wrap(enodes, master_beam, 2, e, m, kind, np.array([0.5, 0.97, 1.2])).tolist() == \
        [ORTHOGONAL, ORTHOGONAL, ORTHOGONAL]
    # against another master beam, or without an orthogonal neighbour: unchanged
    assert rules.extend_wrap(enodes, np.array([1, 2, 2]), 3, e, m, kind, xi1).tolist() == [ORTHOGONAL, POINT, POINT]
