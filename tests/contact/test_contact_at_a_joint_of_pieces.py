"""A slave point over the joint of a master wire made of pieces (``join(a.last, b.first, rigid=True)``).

The plectoneme's wires are each two beams joined end to end.  A slave Gauss point projected
orthogonally on the master at the joint lands past the end of both pieces where the centre line
has a convex kink (``xi2 = 1.0000055`` on one, ``-0.0069`` on the other): both were rejected
(a beam end accepts only ``XI_TOL``, an inner node ``rules.XI_OVERHANG``), so a point
penetrating by 6.9 um had no owner at some Newton iterates and one at others, and the five-turn
run's Newton cycled at every step size at t = 0.939 (docs/benchmarks.md, session 15, branch bK).
The joint of a chain of pieces is an inner node of the chain: the projection is accepted on the
overhang there, and the two pieces share one owner per slave point (one key, not one per piece).
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact.frames import ORTHOGONAL
from beamsolver.nonlinear.problem import Problem

R = 0.05


def _kinked_pieces(lift=0.01, angle=60.0, pieces=True):
    """Master along ``e_x`` from -1 to 1, 8 elements, its middle node lifted by ``lift`` with the frame there
    along ``e_x`` and the others along the chords (the elements next to it curved, the centre line kinked
    there), one beam or two beams joined rigidly at the middle node (``pieces``: the same node poses); a
    one-element slave crossing over the middle at ``angle`` degrees, its middle Gauss point ``R / 100`` into
    the master there.  ``point_ratio = 1``: the crossing (ratio ``sin^2 angle < 1``) is projected
    orthogonally."""
    sec = bs.Section.circular(radius=R, E=1e7, nu=0.3)
    m = bs.Model()
    x = np.linspace(-1.0, 1.0, 9)
    pts = np.stack([x, 0.0 * x, lift * (1.0 - np.abs(x))], axis=1)
    t = np.where(x[:, None] < 0, [1.0, 0.0, lift], [1.0, 0.0, -lift])
    t[4] = (1.0, 0.0, 0.0)
    poses = bs.geometry.frames_from_tangents(pts, t)
    if pieces:
        a = m.add_beam(poses[:5], sec, name="a")
        b = m.add_beam(poses[4:], sec, name="b")
        m.join(a.last, b.first, rigid=True)
        master = [a, b]
    else:
        master = [m.add_beam(poses, sec, name="master")]
    t = np.deg2rad(angle)
    d = 0.3 * np.array([np.cos(t), np.sin(t), 0.0])
    top = pts[4] + np.array([0.0, 0.0, 2.0 * R - 1e-2 * R])
    slave = m.add_beam(bs.geometry.straight(top - d, top + d, 1), sec, name="slave")
    for beam in master + [slave]:
        m.clamp(beam.first)
    m.clamp(master[-1].last)
    m.add_contact(slave, master, integration="points", point_ratio=1.0)
    return Problem.from_model(m, check_rigid_modes=False), slave


def _gaps(pieces):
    """Gap of the slave's middle Gauss point as the slave moves along the master across the joint (one owner
    asserted at each position)."""
    problem, slave = _kinked_pieces(pieces=pieces)
    system, cs = problem.system, problem.contact
    gaps = []
    for dx in np.linspace(-0.02, 0.02, 9):
        H = system.poses0.copy()
        H[slave.nodes, 0, 3] += dx
        P = cs.pairs(H)
        mid = (P.e == slave.elements[0]) & (P.gp == 2)      # the middle of 5 Gauss points
        assert (P.kind[mid] == ORTHOGONAL).all()
        assert mid.sum() == 1, (pieces, dx, P.m[mid])        # one owner over both pieces (was: none near the joint)
        xC, xF = cs._points(H, P.e[mid], P.xi1[mid]), cs._points(H, P.m[mid], P.xi2[mid])
        gaps.append(float(np.linalg.norm(xF - xC) - 2 * R))
    return np.array(gaps)


def test_a_slave_point_over_the_joint_of_two_pieces_has_one_owner():
    one = _gaps(pieces=False)         # the same centre line as one beam: the joint an inner node
    assert one.max() < 0.0            # penetrating all along (the apex is the master's top)
    two = _gaps(pieces=True)
    np.testing.assert_allclose(two, one, rtol=0, atol=1e-12 * R)
