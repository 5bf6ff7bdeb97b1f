"""Group axioms of SE(3), one suite run against both implementations (as jaxlie's tests).

``impl`` is the numpy module ``lie.se3`` (batched) or the compiled scalar kernels of
``lie.se3_jit`` (one pose per call, looped here), behind the same five functions:
``exp``, ``log``, ``compose``, ``log_relative`` and ``coefficient``.  Samples: the identity,
near-identity elements (``exp(1e-7 randn)``), random elements and rotations close to pi.
"""
import numpy as np
import pytest

from beamsolver.lie import se3, se3_jit
from beamsolver.lie.se3 import COEFFICIENT_NAMES

TOL = 1e-12


class _Numpy:
    exp, log, compose, log_relative = se3.exp, se3.log, se3.compose, se3.log_relative

    @staticmethod
    def coefficient(name, t):
        return se3.coefficient(name, t)


class _Compiled:
    @staticmethod
    def exp(h):
        out = np.empty(h.shape[:-1] + (4, 4))
        for i in range(len(h)):
            se3_jit.exp_pose(tuple(h[i, :3]), tuple(h[i, 3:]), out[i])
        return out

    @staticmethod
    def compose(A, B):
        out = np.empty(np.broadcast_shapes(A.shape, B.shape))
        A, B = np.broadcast_to(A, out.shape), np.broadcast_to(B, out.shape)
        for i in range(len(out)):
            se3_jit.compose_into(np.ascontiguousarray(A[i]), np.ascontiguousarray(B[i]), out[i])
        return out

    @staticmethod
    def log_relative(A, B):
        out = np.empty(A.shape[:-2] + (6,))
        for i in range(len(out)):
            RA, xA = se3_jit.pose(np.ascontiguousarray(A), i)
            RB, xB = se3_jit.pose(np.ascontiguousarray(B), i)
            u, w, _, _ = se3_jit.log_relative(RA, xA, RB, xB)
            out[i] = u + w
        return out

    @classmethod
    def log(cls, H):
        return cls.log_relative(np.broadcast_to(np.eye(4), H.shape).copy(), H)

    @staticmethod
    def coefficient(name, t):
        k = COEFFICIENT_NAMES.index(name)
        return np.array([se3_jit.coefficient(k, float(x)) for x in np.ravel(t)]).reshape(np.shape(t))


@pytest.fixture(params=["numpy", "compiled"])
def impl(request):
    return {"numpy": _Numpy, "compiled": _Compiled}[request.param]


def _twists(kind, n=16, seed=0):
    rng = np.random.default_rng(seed)
    h = rng.standard_normal((n, 6))
    if kind == "identity":
        return np.zeros((n, 6))
    if kind == "near-identity":
        return 1e-7 * h
    if kind == "near-pi":
        w = h[:, 3:] / np.linalg.norm(h[:, 3:], axis=1, keepdims=True)
        return np.concatenate([h[:, :3], (np.pi - 1e-6 * rng.uniform(size=(n, 1))) * w], axis=1)
    w = h[:, 3:] / np.linalg.norm(h[:, 3:], axis=1, keepdims=True) * rng.uniform(0, 3.0, (n, 1))
    return np.concatenate([h[:, :3], w], axis=1)


KINDS = ["identity", "near-identity", "random", "near-pi"]


def _close(a, b, tol=TOL):
    assert np.isfinite(a).all()
    np.testing.assert_allclose(a, b, rtol=0.0, atol=tol * max(1.0, np.abs(b).max()))


@pytest.mark.parametrize("kind", KINDS)
def test_log_inverts_exp(impl, kind):
    h = _twists(kind)
    tol = 1e-8 if kind == "near-pi" else TOL        # d log / dH grows like 1/(pi - t) there
    _close(impl.log(impl.exp(h)), h, tol)


@pytest.mark.parametrize("kind", KINDS)
def test_exp_inverts_log(impl, kind):
    H = se3.exp(_twists(kind, seed=1))
    _close(impl.exp(impl.log(H)), H)


@pytest.mark.parametrize("kind", KINDS)
def test_identity_is_neutral(impl, kind):
    H = impl.exp(_twists(kind, seed=2))
    I = np.broadcast_to(np.eye(4), H.shape).copy()
    _close(impl.compose(H, I), H)
    _close(impl.compose(I, H), H)
    _close(impl.exp(np.zeros((1, 6))), np.eye(4)[None])
    _close(impl.log(np.eye(4)[None]), np.zeros((1, 6)))


@pytest.mark.parametrize("kind", KINDS)
def test_composition_is_associative(impl, kind):
    A, B, C = (impl.exp(_twists(kind, seed=s)) for s in (3, 4, 5))
    _close(impl.compose(impl.compose(A, B), C), impl.compose(A, impl.compose(B, C)))


@pytest.mark.parametrize("kind", KINDS)
def test_relative_log_is_log_of_the_relative_pose(impl, kind):
    """``log_relative(A, B) = log(A^-1 B)``; ``B = A exp(h)`` gives back ``h``."""
    A = impl.exp(_twists("random", seed=6))
    h = _twists(kind, seed=7)
    tol = 1e-8 if kind == "near-pi" else 1e-11
    _close(impl.log_relative(A, impl.compose(A, impl.exp(h))), h, tol)


@pytest.mark.parametrize("kind", KINDS)
def test_one_parameter_subgroup(impl, kind):
    """``exp(s h) exp(r h) = exp((s + r) h)``."""
    h = 0.5 * _twists(kind, seed=8)
    _close(impl.compose(impl.exp(0.3 * h), impl.exp(0.7 * h)), impl.exp(h))


@pytest.mark.parametrize("name", COEFFICIENT_NAMES)
def test_coefficients_are_finite_and_agree_across_the_switch(impl, name):
    """Every singular coefficient at 0, across its series/closed-form switch and up to pi: finite,
    and equal to the numpy table to round-off."""
    t = np.concatenate([[0.0, 1e-300, 1e-8], np.geomspace(1e-4, 1.0, 40), np.linspace(1.0, np.pi - 1e-3, 20)])
    c = impl.coefficient(name, t)
    assert np.isfinite(c).all()
    np.testing.assert_allclose(c, se3.coefficient(name, t), rtol=1e-13, atol=0.0)
