"""Small shared helpers for the foundation tests (random poses, sections, models)."""
import numpy as np
import pytest

from beamsolver import se3


def random_rotation_vector(rng, angle, shape=()):
    """Rotation vectors of norm ``angle`` in uniformly random directions, ``shape + (3,)``."""
    v = rng.standard_normal(shape + (3,))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    return v * np.asarray(angle)[..., None] if np.ndim(angle) else v * angle


def random_pose(rng, angle=1.0, scale=1.0, shape=()):
    """Poses with rotation angle up to ``angle`` and translation of order ``scale``."""
    h = np.concatenate([scale * rng.standard_normal(shape + (3,)),
                        random_rotation_vector(rng, angle * rng.uniform(size=shape))], axis=-1)
    return se3.exp(h)


def spd_matrix(rng, diag=(1e3, 4e2, 5e2, 20.0, 30.0, 40.0), coupling=0.3):
    """A full symmetric positive definite 6x6 matrix with the given diagonal scale."""
    d = np.sqrt(np.asarray(diag, dtype=float))
    A = np.eye(6) + coupling * rng.uniform(-1, 1, (6, 6))
    S = A @ A.T
    s = np.sqrt(np.diag(S))
    return (d / s)[:, None] * S * (d / s)[None, :]


def rel_err(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
