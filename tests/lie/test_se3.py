"""Property tests of the Lie-group kernels (docs/theory.md sections 1-2)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from beamsolver import se3

SHAPES = [(), (5,), (2, 3)]
# angle families: identity, tiny, moderate, near pi (below pi for log(exp(h)) = h)
TINY = [0.0, 1e-12, 1e-8, 1e-4]
NEAR_PI = [np.pi - 1e-6, np.pi - 1e-9]
ANGLES = st.one_of(st.sampled_from(TINY + NEAR_PI), st.floats(1e-3, np.pi - 1e-3))
SEEDS = st.integers(0, 2**32 - 1)
SHAPE = st.sampled_from(SHAPES)
FAST = settings(max_examples=80, deadline=None)


def _unit(rng, shape):
    v = rng.standard_normal(shape + (3,))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _twist(rng, shape, angle, tscale=1.0):
    return np.concatenate([tscale * rng.standard_normal(shape + (3,)), angle * _unit(rng, shape)], axis=-1)


def _is_pose(H, tol=1e-13):
    R = H[..., :3, :3]
    orth = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max()
    return orth < tol and np.all(np.linalg.det(R) > 0) and np.all(H[..., 3, :] == [0, 0, 0, 1])


# ---------------------------------------------------------------- round trips
@FAST
@given(seed=SEEDS, shape=SHAPE, angle=ANGLES, tscale=st.sampled_from([0.0, 1e-9, 1.0, 100.0]))
def test_log_exp_round_trip(seed, shape, angle, tscale):
    rng = np.random.default_rng(seed)
    h = _twist(rng, shape, angle, tscale)
    H = se3.exp(h)
    assert H.shape == shape + (4, 4)
    assert _is_pose(H)
    h2 = se3.log(H)
    assert h2.shape == shape + (6,)
    assert np.all(np.isfinite(h2))
    # translations grow like |u| / (pi - t) near pi in log coordinates; compare
    # on the scale of the data
    scale = max(1.0, np.abs(h).max())
    assert np.abs(h2 - h).max() <= 2e-14 * scale


@FAST
@given(seed=SEEDS, shape=SHAPE,
       angle=st.one_of(st.sampled_from(TINY + NEAR_PI + [np.pi]), st.floats(1e-3, np.pi)),
       tscale=st.sampled_from([0.0, 1e-9, 1.0, 100.0]))
def test_exp_log_round_trip_any_pose(seed, shape, angle, tscale):
    rng = np.random.default_rng(seed)
    R = se3.exp_so3(angle * _unit(rng, shape))
    H = np.zeros(shape + (4, 4))
    H[..., :3, :3] = R
    H[..., :3, 3] = tscale * rng.standard_normal(shape + (3,))
    H[..., 3, 3] = 1.0
    h = se3.log(H)
    assert np.all(np.isfinite(h))
    assert np.all(se3.rotation_angle(h[..., 3:]) <= np.pi + 1e-15)
    H2 = se3.exp(h)
    assert np.abs(H2 - H).max() <= 5e-15 * max(1.0, tscale)


def test_exp_log_at_exactly_pi_about_axes():
    """Rotations by exactly pi about axes (R symmetric, the axis from the symmetric part)."""
    for axis in np.eye(3).tolist() + [[1, 1, 0], [1, 1, 1], [0, -1, 2]]:
        a = np.array(axis, float) / np.linalg.norm(axis)
        R = 2.0 * np.outer(a, a) - np.eye(3)
        w = se3.log_so3(R)
        assert abs(np.linalg.norm(w) - np.pi) < 1e-15 * np.pi
        assert min(np.abs(w - np.pi * a).max(), np.abs(w + np.pi * a).max()) < 4e-15
        assert np.abs(se3.exp_so3(w) - R).max() < 4e-15


def test_identity_and_zero():
    for shape in SHAPES:
        h = np.zeros(shape + (6,))
        assert np.array_equal(se3.exp(h), np.broadcast_to(np.eye(4), shape + (4, 4)))
        assert np.array_equal(se3.log(se3.exp(h)), h)
        assert np.array_equal(se3.tangent(h), np.broadcast_to(np.eye(6), shape + (6, 6)))
        assert np.array_equal(se3.tangent_inv(h), np.broadcast_to(np.eye(6), shape + (6, 6)))


@pytest.mark.parametrize("delta", [1e-9, 1e-6])
def test_log_so3_near_pi_without_loss(delta):
    """|w| = pi - delta: measured max error 8.9e-16 over 2000 random axes."""
    rng = np.random.default_rng(1)
    w = (np.pi - delta) * _unit(rng, (500,))
    err = np.abs(se3.log_so3(se3.exp_so3(w)) - w).max()
    assert err < 4e-15


def test_log_so3_exactly_pi_random_axes():
    rng = np.random.default_rng(2)
    a = _unit(rng, (500,))
    w2 = se3.log_so3(se3.exp_so3(np.pi * a))
    err = np.minimum(np.abs(w2 - np.pi * a).max(axis=-1), np.abs(w2 + np.pi * a).max(axis=-1))
    assert err.max() < 4e-15


# ---------------------------------------------------------------- tangents
def _group_fd(expf, logf, x, dx, eps):
    """Central difference on the group of ``log(exp(x)^-1 exp(x + e dx)) / e``."""
    E0inv = np.linalg.inv(expf(x))
    plus = logf(E0inv @ expf(x + eps * dx))
    minus = logf(E0inv @ expf(x - eps * dx))
    return (plus - minus) / (2.0 * eps)


@FAST
@given(seed=SEEDS, shape=SHAPE,
       angle=st.one_of(st.sampled_from([0.0, 1e-12, 1e-8, 1e-4, 1e-2, 3.0, np.pi - 1e-6]),
                       st.floats(1e-3, 3.0)))
def test_tangent_se3_against_group_finite_differences(seed, shape, angle):
    rng = np.random.default_rng(seed)
    h = _twist(rng, shape, angle)
    dh = rng.standard_normal(shape + (6,))
    fd = _group_fd(se3.exp, se3.log, h, dh, 1e-5)
    an = np.einsum("...ij,...j->...i", se3.tangent(h), dh)
    # central differences: truncation ~ eps^2 |h''| ~ 1e-10, round-off ~ 1e-16 / eps
    assert np.abs(fd - an).max() <= 1e-8 * max(1.0, np.abs(an).max())


@FAST
@given(seed=SEEDS, shape=SHAPE,
       angle=st.one_of(st.sampled_from([0.0, 1e-12, 1e-8, 1e-4, 1e-2, 3.0]), st.floats(1e-3, 3.0)))
def test_tangent_so3_against_group_finite_differences(seed, shape, angle):
    rng = np.random.default_rng(seed)
    w = angle * _unit(rng, shape)
    dw = rng.standard_normal(shape + (3,))
    fd = _group_fd(se3.exp_so3, se3.log_so3, w, dw, 1e-5)
    an = np.einsum("...ij,...j->...i", se3.tangent_so3(w), dw)
    assert np.abs(fd - an).max() <= 1e-8 * max(1.0, np.abs(an).max())


def test_tangent_first_order_agreement():
    """The defect of exp(h + e dh) vs exp(h) exp(e T dh) is O(e^2): halves twice per halving of e."""
    rng = np.random.default_rng(3)
    h = _twist(rng, (), 2.0)
    dh = rng.standard_normal(6)
    errs = []
    for eps in (1e-3, 5e-4, 2.5e-4):
        lhs = se3.exp(h + eps * dh)
        rhs = se3.exp(h) @ se3.exp(eps * se3.tangent(h) @ dh)
        errs.append(np.abs(lhs - rhs).max())
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(rates - 2.0) < 0.1), rates


@FAST
@given(seed=SEEDS, shape=SHAPE,
       angle=st.one_of(st.sampled_from([0.0, 1e-12, 1e-8, 1e-4, 1e-2, np.pi - 1e-9, np.pi]),
                       st.floats(1e-3, np.pi)))
def test_tangent_inv_times_tangent_is_identity(seed, shape, angle):
    """Measured worst 3.2e-16 (relative to max(1, |h|)) over angles in [0, pi]."""
    rng = np.random.default_rng(seed)
    h = _twist(rng, shape, angle)
    tol = 2e-15 * max(1.0, np.abs(h).max())
    assert np.abs(se3.tangent_inv(h) @ se3.tangent(h) - np.eye(6)).max() <= tol
    w = h[..., 3:]
    assert np.abs(se3.tangent_inv_so3(w) @ se3.tangent_so3(w) - np.eye(3)).max() <= tol


# ---------------------------------------------------------------- identities
@FAST
@given(seed=SEEDS, shape=SHAPE, angle=ANGLES)
def test_adjoint_identity(seed, shape, angle):
    """``H exp(h) H^-1 = exp(Ad(H) h)``."""
    rng = np.random.default_rng(seed)
    H = se3.exp(_twist(rng, shape, rng.uniform(0, np.pi)))
    h = _twist(rng, shape, angle)
    lhs = H @ se3.exp(h) @ se3.inverse(H)
    rhs = se3.exp(np.einsum("...ij,...j->...i", se3.adjoint(H), h))
    assert np.abs(lhs - rhs).max() <= 5e-14 * max(1.0, np.abs(lhs).max())
    assert np.abs(se3.inverse(H) @ H - np.eye(4)).max() < 1e-14
    assert np.abs(se3.compose(H, H) - H @ H).max() < 1e-14 * max(1.0, np.abs(H @ H).max())


@FAST
@given(seed=SEEDS, shape=SHAPE,
       angle=st.one_of(st.sampled_from([0.0, 1e-12, 1e-8, 1e-4, 1e-2]), st.floats(1e-3, 3.0)))
def test_tangent_inverse_adjoint_identity(seed, shape, angle):
    """``T(h)^-1 Ad(exp(-h)) = T(-h)^-1`` (docs/theory.md eq. 2.8)."""
    rng = np.random.default_rng(seed)
    h = _twist(rng, shape, angle)
    lhs = se3.tangent_inv(h) @ se3.adjoint(se3.exp(-h))
    rhs = se3.tangent_inv(-h)
    assert np.abs(lhs - rhs).max() <= 1e-13 * max(1.0, np.abs(rhs).max())


@FAST
@given(seed=SEEDS, shape=SHAPE, angle=ANGLES)
def test_interpolate_end_points(seed, shape, angle):
    rng = np.random.default_rng(seed)
    HA = se3.exp(_twist(rng, shape, rng.uniform(0, np.pi)))
    HB = HA @ se3.exp(_twist(rng, shape, angle))
    h = se3.log(se3.relative(HA, HB))
    assert np.array_equal(se3.interpolate(HA, h, np.zeros(shape)), se3.compose(HA, np.eye(4)))
    assert np.abs(se3.interpolate(HA, h, np.zeros(shape)) - HA).max() < 1e-15 * 4
    assert np.abs(se3.interpolate(HA, h, np.ones(shape)) - HB).max() < 2e-14 * max(1.0, np.abs(HB).max())
    # midpoint: half way in the twist, relative pose exp(h / 2) both sides
    Hm = se3.interpolate(HA, h, np.full(shape, 0.5))
    assert np.abs(se3.log(se3.relative(HA, Hm)) - se3.log(se3.relative(Hm, HB))).max() < 1e-13 * max(1.0, np.abs(h).max())


@FAST
@given(seed=SEEDS, shape=SHAPE)
def test_hat_vee_skew_unskew(seed, shape):
    rng = np.random.default_rng(seed)
    h = rng.standard_normal(shape + (6,))
    w, v = h[..., 3:], rng.standard_normal(shape + (3,))
    W = se3.skew(w)
    assert np.array_equal(se3.unskew(W), w)
    assert np.array_equal(W, -np.swapaxes(W, -1, -2))
    assert np.allclose(np.einsum("...ij,...j->...i", W, v), np.cross(w, v), rtol=0, atol=1e-14)
    X = se3.hat(h)
    assert np.array_equal(se3.vee(X), h)
    assert np.all(X[..., 3, :] == 0)
    assert np.array_equal(X[..., :3, :3], W)


def test_no_nan_anywhere_at_special_angles():
    rng = np.random.default_rng(4)
    for angle in [0.0, 1e-300, 1e-12, 1e-8, 1e-4, np.pi - 1e-9, np.pi]:
        h = _twist(rng, (2, 3), angle)
        for f in (se3.exp, se3.tangent, se3.tangent_inv, lambda x: se3.log(se3.exp(x))):
            assert np.all(np.isfinite(f(h)))
        for f in (se3.exp_so3, se3.tangent_so3, se3.tangent_inv_so3):
            assert np.all(np.isfinite(f(h[..., 3:])))
