"""SE(3) slip increment (seed eqs. 4, 7, 8; docs/theory.md eqs. 6.4-6.5)."""
import numpy as np
import pytest

from beamsolver import se3
from beamsolver.contact import relative_motion, slip_increment
from beamsolver.contact.kinematics import normal_gap


def _pose(R, x):
    H = np.zeros(np.shape(R)[:-2] + (4, 4))
    H[..., :3, :3] = R
    H[..., :3, 3] = x
    H[..., 3, 3] = 1.0
    return H


def _rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _random_poses(rng, shape):
    return se3.exp(rng.normal(size=shape + (6,)))


# contact frame at the touching point: n = -e_z (towards the master below),
# t1 = e_y (both axes), t2 = n x t1 = e_x
FRAME0 = _pose(np.stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], axis=1), np.zeros(3))


def _rolling(R1, R2, beta):
    """Material frame ``{L}`` after the slave (radius ``R1``) rolled by ``beta`` without slipping
    on a fixed cylinder of radius ``R2`` (``R2 = inf``: a plane); axes parallel to ``e_y``.
    Returns ``H_L`` and the slave centre's displacement."""
    c0 = np.array([0.0, 0.0, R1])
    if np.isinf(R2):
        c1 = c0 + np.array([R1 * beta, 0.0, 0.0])
    else:
        D = R1 + R2
        alpha = beta * R1 / D                           # arc lengths R2 alpha = R1 (beta - alpha)
        c0 = np.array([0.0, 0.0, R1])                   # master axis at (0, 0, -R2)
        c1 = np.array([D * np.sin(alpha), 0.0, D * np.cos(alpha) - R2])
    Q = _rot_y(beta)
    G = _pose(Q, c1 - Q @ c0)                           # x -> Q (x - c0) + c1
    return G @ FRAME0, c1 - c0


def _rolling_constant(R1, R2):
    """``|dg_T| = c beta^3 + O(beta^5)`` for rolling (pole of the finite planar motion)."""
    if np.isinf(R2):
        return R1 / 12.0
    D = R1 + R2
    k = D / R1
    return (D * (-1.0 / 8.0 + 1.0 / (24.0 * k) + k / 12.0) - R2 / 8.0) / k**2


@pytest.mark.parametrize("shape", [(), (5,), (2, 3)])
def test_pure_sliding_gives_the_sliding_distance(shape):
    rng = np.random.default_rng(1)
    G = _random_poses(rng, shape)                      # both frames start together anywhere
    d = rng.uniform(0.01, 2.0, size=shape)
    phi = rng.uniform(0.0, 2 * np.pi, size=shape)
    # the slave slides by d along the tangent plane direction (cos phi t1 + sin phi t2)
    u = np.zeros(shape + (6,))
    u[..., 1], u[..., 2] = d * np.cos(phi), d * np.sin(phi)
    H_K = G
    H_L = se3.compose(G, se3.exp(u))
    H_LK_prev = se3.relative(G, G)
    dg = slip_increment(H_LK_prev, se3.relative(H_L, H_K))
    assert dg.shape == shape + (2,)
    np.testing.assert_allclose(np.linalg.norm(dg, axis=-1), d, rtol=1e-12)
    np.testing.assert_allclose(dg[..., 0], -d * np.cos(phi), atol=1e-12)   # K moves back relative to L
    np.testing.assert_allclose(dg[..., 1], -d * np.sin(phi), atol=1e-12)


def test_sliding_along_a_curved_master_gives_the_arc_length():
    """A slave frame carried by an angle ``a`` around a master axis at distance ``R``
    (the master frame fixed): slip = arc length ``R a``, no normal motion."""
    R = 1.0
    for a in (1e-3, 0.1, 0.7):
        H_K = FRAME0.copy()                             # master material frame (fixed)
        G = _pose(_rot_y(a), np.zeros(3))
        shift = _pose(np.eye(3), np.array([0.0, 0.0, R]))
        H_L0 = FRAME0.copy()
        H_L = shift @ G @ np.linalg.inv(shift) @ H_L0  # the slave slid around the master axis
        dy = relative_motion(np.eye(4), se3.relative(H_L, H_K))
        np.testing.assert_allclose(np.linalg.norm(dy[[1, 2]]), R * a, rtol=1e-12)
        assert abs(dy[0]) < 1e-12


@pytest.mark.parametrize("R2", [np.inf, 3.0, 0.5])
def test_rolling_slip_is_cubic_while_centre_line_slip_is_R_dtheta(R2):
    R1 = 1.0
    betas = np.geomspace(1e-3, 1e-1, 7)
    se3_slip, centre_slip = [], []
    for b in betas:
        H_L, dc = _rolling(R1, R2, b)
        H_LK = se3.relative(H_L, FRAME0)
        se3_slip.append(np.linalg.norm(slip_increment(np.eye(4), H_LK)))
        # centre-line measure: tangential displacement of the slave centre (master fixed)
        centre_slip.append(abs(dc @ FRAME0[:3, 2]))
        assert abs(normal_gap(H_LK)) < 1e-12 + b**2        # still touching (to second order)
    se3_slip, centre_slip = np.array(se3_slip), np.array(centre_slip)
    rate, logc = np.polyfit(np.log(betas), np.log(se3_slip), 1)
    assert abs(rate - 3.0) < 0.02, rate
    c = abs(_rolling_constant(R1, R2))
    np.testing.assert_allclose(se3_slip / betas**3, c, rtol=2e-3 if np.isinf(R2) else 5e-3)
    # the centre-line measure sees the rolling as slip: R dtheta (R1 beta R2/(R1+R2) on a cylinder)
    expected = R1 * betas if np.isinf(R2) else (R1 + R2) * np.sin(betas * R1 / (R1 + R2))
    np.testing.assert_allclose(centre_slip, expected, rtol=1e-12)
    assert np.all(centre_slip > 1e2 * se3_slip)


def test_rolling_on_a_plane_constant_is_R_over_12():
    for R1 in (0.3, 1.0, 2.5):
        b = 2e-3
        H_L, _ = _rolling(R1, np.inf, b)
        dg = slip_increment(np.eye(4), se3.relative(H_L, FRAME0))
        np.testing.assert_allclose(np.linalg.norm(dg), R1 * b**3 / 12.0, rtol=1e-5)


@pytest.mark.parametrize("shape", [(), (4,), (3, 2)])
def test_superposed_rigid_motion_leaves_slip_and_gap_unchanged(shape):
    rng = np.random.default_rng(7)
    HL0, HK0 = _random_poses(rng, shape), _random_poses(rng, shape)
    HL1, HK1 = _random_poses(rng, shape), _random_poses(rng, shape)
    G0, G1 = _random_poses(rng, shape), _random_poses(rng, shape)
    a_prev, a = se3.relative(HL0, HK0), se3.relative(HL1, HK1)
    b_prev = se3.relative(se3.compose(G0, HL0), se3.compose(G0, HK0))
    b = se3.relative(se3.compose(G1, HL1), se3.compose(G1, HK1))
    np.testing.assert_allclose(slip_increment(b_prev, b), slip_increment(a_prev, a), atol=1e-10)
    np.testing.assert_allclose(relative_motion(b_prev, b)[..., 0], relative_motion(a_prev, a)[..., 0],
                               atol=1e-10)
    np.testing.assert_allclose(normal_gap(b) - normal_gap(b_prev), normal_gap(a) - normal_gap(a_prev),
                               atol=1e-10)


def test_identity_and_near_identity_are_finite():
    I = np.broadcast_to(np.eye(4), (3, 4, 4))
    assert np.all(slip_increment(I, I) == 0.0)
    rng = np.random.default_rng(3)
    h = 1e-9 * rng.normal(size=(3, 6))
    dg = slip_increment(I, se3.exp(h))
    assert np.all(np.isfinite(dg))
    np.testing.assert_allclose(dg, h[:, 1:3], rtol=1e-6, atol=1e-24)
