"""Node-pose generators: frames, tangents, the documented e2 rule, exact curves."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry
from beamsolver.elements import element
from beamsolver.assembly.system import System


def _check_frames(P, tol=1e-14):
    R = P[:, :3, :3]
    assert np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max() < tol
    assert np.abs(np.linalg.det(R) - 1.0).max() < tol
    assert np.all(P[:, 3] == [0, 0, 0, 1])


def _chord_tangents(P):
    """Central chords ``x[i+1] - x[i-1]``, normalised (exact tangent for a circle)."""
    d = P[2:, :3, 3] - P[:-2, :3, 3]
    return d / np.linalg.norm(d, axis=1, keepdims=True)


GENERATORS = {
    "straight": lambda: geometry.straight((1, -2, 0.5), (3, 1, 2), 7),
    "arc": lambda: geometry.arc(2.5, 2.0, 9, origin=(1, 2, 3)),
    "helix": lambda: geometry.helix(0.3, 1.1, 2.5, 40, phase=0.4, z0=-1.0),
    "polyline": lambda: geometry.polyline([[0, 0, 0], [1, 0.2, 0], [2, 1, 0.3], [2.5, 2, 1], [2.6, 3, 2]]),
}


@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_orthonormal_frames(name):
    P = GENERATORS[name]()
    assert P.ndim == 3 and P.shape[1:] == (4, 4)
    _check_frames(P)


@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_reference_state_has_zero_residual(name):
    P = GENERATORS[name]()
    m = bs.Model()
    m.add_beam(P, bs.Section(EA=1e6, GA2=4e5, GA3=4e5, GJ=1e2, EI2=2e2, EI3=3e2, radius=0.01))
    s = System(m, check_rigid_modes=False)
    r, _, info = s.evaluate(s.poses0, np.zeros(0))
    assert np.abs(r).max() <= 1e-16 * 1e6 * 10, np.abs(r).max()
    assert np.abs(info["state"].sigma).max() <= 1e-16 * 1e6 * 10


def test_straight_tangent_and_e2_rule():
    P = geometry.straight((0, 0, 0), (2, 0, 0), 4)
    assert np.array_equal(P[:, :3, 0], np.tile([1.0, 0, 0], (5, 1)))
    assert np.array_equal(P[:, :3, 1], np.tile([0, 1.0, 0], (5, 1)))
    assert np.array_equal(P[:, :3, 2], np.tile([0, 0, 1.0], (5, 1)))
    assert np.allclose(P[:, 0, 3], np.linspace(0, 2, 5), rtol=0, atol=1e-15)
    # along e_z: e2 = e_y
    P = geometry.straight((0, 0, 0), (0, 0, -3), 2)
    assert np.allclose(P[:, :3, 1], [0, 1, 0], rtol=0, atol=1e-15)
    assert np.allclose(P[:, :3, 0], [0, 0, -1], rtol=0, atol=1e-15)
    # general direction: e2 = unit(e_z x e1), e3 = e1 x e2
    a, b = np.array([1.0, -2, 0.5]), np.array([3.0, 1, 2])
    P = geometry.straight(a, b, 3)
    e1 = (b - a) / np.linalg.norm(b - a)
    e2 = np.cross([0, 0, 1], e1)
    e2 /= np.linalg.norm(e2)
    assert np.allclose(P[:, :3, 0], e1, rtol=0, atol=1e-15)
    assert np.allclose(P[:, :3, 1], e2, rtol=0, atol=1e-15)
    assert np.allclose(P[:, :3, 2], np.cross(e1, e2), rtol=0, atol=1e-15)
    d = P[1:, :3, 3] - P[:-1, :3, 3]
    assert np.allclose(d / np.linalg.norm(d, axis=1, keepdims=True), e1, rtol=0, atol=1e-15)
    # an explicit e2 is projected normal to the axis
    P = geometry.straight((0, 0, 0), (1, 0, 0), 2, e2=(0.3, 0, 1))
    assert np.allclose(P[:, :3, 1], [0, 0, 1], rtol=0, atol=1e-15)
    assert np.allclose(P[:, :3, 2], [0, -1, 0], rtol=0, atol=1e-15)


def test_arc_exact_circle_and_frames():
    R, angle, n, o = 2.5, 2.0, 9, np.array([1.0, 2.0, 3.0])
    P = geometry.arc(R, angle, n, origin=o)
    x = P[:, :3, 3]
    centre = o + [0, R, 0]
    assert np.abs(np.linalg.norm(x - centre, axis=1) - R).max() < 1e-15 * R * 4
    assert np.allclose(x[:, 2], o[2], rtol=0, atol=0)
    assert np.allclose(x[0], o, rtol=0, atol=0)
    assert np.allclose(P[0, :3, 0], [1, 0, 0], atol=0)
    # node i at angle i * angle / n
    phi = np.arctan2(x[:, 0] - centre[0], centre[1] - x[:, 1])
    assert np.abs(phi - np.linspace(0, angle, n + 1)).max() < 1e-15 * 8
    # e1 = tangent (central chords of a circle are exactly parallel to it)
    assert np.abs(P[1:-1, :3, 0] - _chord_tangents(P)).max() < 1e-14
    # e2 to the centre, e3 = +z
    to_c = (centre - x) / R
    assert np.abs(P[:, :3, 1] - to_c).max() < 1e-15 * 4
    assert np.abs(P[:, :3, 2] - [0, 0, 1]).max() < 1e-15

def test_arc_negative_angle_turns_towards_minus_y():
    """e1 runs along the node order (axial reference strain +1), centre at -radius e_y."""
    R = 2.0
    Pn = geometry.arc(R, -1.0, 4)
    _check_frames(Pn)
    Pp = geometry.arc(R, 1.0, 4)
    mirror = np.diag([1.0, -1.0, 1.0])
    assert np.abs(Pn[:, :3, 3] - Pp[:, :3, 3] @ mirror).max() < 1e-15 * 4
    assert np.all(Pn[1:, 1, 3] < 0)
    x = Pn[:, :3, 3]
    assert np.abs(np.linalg.norm(x - [0, -R, 0], axis=1) - R).max() < 1e-15 * 4
    assert np.abs(Pn[1:-1, :3, 0] - _chord_tangents(Pn)).max() < 1e-14
    assert np.abs(Pn[:, :3, 1] - ([0, -R, 0] - x) / R).max() < 1e-15 * 4
    L, eps0 = element.reference_strain(Pn[:-1], Pn[1:])
    assert np.allclose(eps0, [1, 0, 0, 0, 0, 1 / R], rtol=0, atol=1e-14)


def test_helix_positions_lay_angle_pitch():
    r, p, length, n, phase, z0 = 0.3, 1.1, 2.5, 40, 0.4, -1.0
    P = geometry.helix(r, p, length, n, phase=phase, z0=z0)
    x = P[:, :3, 3]
    z = z0 + np.linspace(0, length, n + 1)
    th = 2 * np.pi * (z - z0) / p + phase
    assert np.abs(x - np.stack([r * np.cos(th), r * np.sin(th), z], axis=1)).max() < 1e-15 * 8
    # lay angle: angle between e1 and the axis, tan(alpha) = 2 pi r / pitch
    alpha = np.arctan(2 * np.pi * r / p)
    assert np.abs(np.arccos(P[:, 2, 0]) - alpha).max() < 1e-14
    # pitch: one turn later the point is straight above
    Pq = geometry.helix(r, p, p, 4, phase=phase, z0=z0)
    assert np.abs(Pq[-1, :2, 3] - Pq[0, :2, 3]).max() < 1e-15 * 8
    assert abs(Pq[-1, 2, 3] - Pq[0, 2, 3] - p) < 1e-15 * 4
    # e2: principal normal towards the axis
    assert np.abs(P[:, :3, 1] - np.stack([-np.cos(th), -np.sin(th), 0 * th], axis=1)).max() < 1e-15 * 4
    # handedness: positive pitch turns counterclockwise about +z while rising (right-handed)
    def turn(y):
        return y[:-1, 0] * y[1:, 1] - y[:-1, 1] * y[1:, 0]
    assert np.all(turn(x) > 0)
    Pl = geometry.helix(r, -p, length, n)
    assert np.all(turn(Pl[:, :3, 3]) < 0)


@pytest.mark.parametrize("z", [0.0, 0.37, 1.9])
def test_helix_e1_is_derivative_of_position(z):
    r, p, d = 0.3, 1.1, 1e-5
    P = geometry.helix(r, p, 2 * d, 2, phase=0.4, z0=z - d)
    fd = (P[2, :3, 3] - P[0, :3, 3]) / np.linalg.norm(P[2, :3, 3] - P[0, :3, 3])
    # central difference error ~ (k d)^2 / 6
    assert np.abs(P[1, :3, 0] - fd).max() < 1e-9


def test_polyline_of_arc_points_reproduces_arc():
    R, angle, n = 2.5, 2.0, 9
    A = geometry.arc(R, angle, n)
    P = geometry.polyline(A[:, :3, 3])
    _check_frames(P)
    assert np.abs(P - A).max() < 1e-13, np.abs(P - A).max()
    # resampling: 2n segments resampled to n lands on every other point
    A2 = geometry.arc(R, angle, 2 * n)
    Pr = geometry.polyline(A2[:, :3, 3], n_elements=n)
    assert Pr.shape == (n + 1, 4, 4)
    assert np.abs(Pr - A).max() < 1e-13, np.abs(Pr - A).max()


def test_polyline_resampling_uniform_and_straight():
    pts = np.array([[0, 0, 0], [0.1, 0, 0], [1.5, 0, 0], [2.0, 0, 0]])
    P = geometry.polyline(pts, n_elements=5)
    assert np.allclose(P[:, 0, 3], np.linspace(0, 2, 6), rtol=0, atol=1e-15)
    S = geometry.straight((0, 0, 0), (2, 0, 0), 5)
    assert np.abs(P - S).max() < 1e-15 * 4
    # two points: a straight element with the default e2 rule
    P2 = geometry.polyline([[0, 0, 0], [0, 0, 1]])
    assert np.allclose(P2[:, :3, 1], [0, 1, 0], atol=1e-15)
    # e2 parallel-transported along a planar bend stays in the bending plane's normal
    Pb = geometry.polyline([[0, 0, 0], [1, 0, 0], [2, 1, 0], [2, 2, 0]])
    assert np.allclose(Pb[:, :3, 2], [0, 0, 1], atol=1e-15)


def test_polyline_e1_tangent_of_circle_through_neighbours():
    rng = np.random.default_rng(0)
    pts = np.cumsum(rng.uniform(0.5, 1.0, (7, 3)), axis=0)
    P = geometry.polyline(pts)
    _check_frames(P, tol=1e-13)
    for i in range(1, 6):
        a, b, c = pts[i - 1], pts[i], pts[i + 1]
        # circle through a, b, c: centre o solves |o-a| = |o-b| = |o-c| in their plane
        nrm = np.cross(b - a, c - b)
        M = np.array([b - a, c - b, nrm])
        rhs = np.array([(b @ b - a @ a) / 2, (c @ c - b @ b) / 2, nrm @ a])
        o = np.linalg.solve(M, rhs)
        t = np.cross(nrm, b - o)
        t /= np.linalg.norm(t)
        assert np.abs(P[i, :3, 0] - t).max() < 1e-12
        assert np.dot(P[i, :3, 0], c - a) > 0
