"""Prescribed rigid motions ``t -> G(t)`` (4x4) for ``Model.prescribe``: ``pose(t) = G(t) @ pose_0``."""
import numpy as np

from . import se3

__all__ = ["rotation", "translation", "compose", "fixed"]


def _as_fn(v):
    return v if callable(v) else (lambda t, v=v: v * t)


def rotation(axis, angle_of_t, center=(0.0, 0.0, 0.0)):
    """Rotation about the line through ``center`` along ``axis`` by ``angle_of_t(t)``
    (a number means ``angle * t``)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    c = np.asarray(center, dtype=float)
    ang = _as_fn(angle_of_t)

    def G(t):
        R = se3.exp_so3(a * float(ang(t)))
        out = np.eye(4)
        out[:3, :3] = R
        out[:3, 3] = c - R @ c
        return out
    return G


def translation(vector_of_t):
    """Translation by ``vector_of_t(t)`` (a 3-vector means ``vector * t``)."""
    if callable(vector_of_t):
        fn = vector_of_t
    else:
        v = np.asarray(vector_of_t, dtype=float)
        fn = lambda t: v * t  # noqa: E731

    def G(t):
        out = np.eye(4)
        out[:3, 3] = np.asarray(fn(t), dtype=float)
        return out
    return G


def compose(*motions):
    """``G(t) = G_1(t) @ G_2(t) @ ...`` (the last is applied first)."""
    def G(t):
        out = np.eye(4)
        for m in motions:
            out = out @ m(t)
        return out
    return G


def fixed():
    return lambda t: np.eye(4)
