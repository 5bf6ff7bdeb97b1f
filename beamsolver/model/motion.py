"""Prescribed rigid motions ``t -> G(t)`` (4x4) for ``Model.prescribe``: ``pose(t) = G(t) @ pose_0``.

Arguments are checked when the motion is made, and the values of user callables when it is
evaluated: bad ones raise ``InputError`` naming the function, the argument and the value.
"""
import numbers

import numpy as np

from ..lie import se3
from ..errors import InputError

__all__ = ["rotation", "translation", "compose", "fixed"]


def _show(value):
    """``value`` for a message: sequences as ``(a, b, c)`` with numbers in ``%g``."""
    if isinstance(value, (str, bytes)) or not np.iterable(value):
        return f"{value:g}" if isinstance(value, numbers.Real) and not isinstance(value, bool) else repr(value)
    return "(" + ", ".join(_show(v) for v in value) + ")"


def _vector(value, what, owner):
    """``value`` as 3 finite floats, else ``InputError`` ``owner: what must be 3 finite numbers``."""
    try:
        v = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        v = None
    if v is None or v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"{owner}: {what} must be 3 finite numbers, got {_show(value)}")
    return v


def _number(value, what, owner):
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and np.isfinite(float(value))
    if not ok:
        raise InputError(f"{owner}: {what} must be a finite number, got {_show(value)}")
    return float(value)


def rotation(axis, angle_of_t, center=(0.0, 0.0, 0.0)):
    """Rotation about the line through ``center`` along ``axis`` by ``angle_of_t(t)``
    (a number means ``angle * t``); ``axis`` and ``center`` are 3-vectors, ``axis`` non-zero."""
    owner = "motion.rotation"
    a = _vector(axis, "axis", owner)
    if not np.linalg.norm(a) > 0.0:
        raise InputError(f"{owner}: axis must be a non-zero vector, got {_show(axis)}")
    a = a / np.linalg.norm(a)
    c = _vector(center, "center", owner)
    if callable(angle_of_t):
        ang = angle_of_t
    elif isinstance(angle_of_t, numbers.Real) and not isinstance(angle_of_t, bool) and np.isfinite(angle_of_t):
        ang = lambda t, w=float(angle_of_t): w * t  # noqa: E731
    else:
        raise InputError(f"{owner}: angle_of_t must be a callable t -> angle or a finite number (angle * t), "
                         f"got {_show(angle_of_t)}")

    def G(t):
        R = se3.exp_so3(a * _number(ang(t), f"angle_of_t({t:g})", owner))
        out = np.eye(4)
        out[:3, :3] = R
        out[:3, 3] = c - R @ c
        return out
    return G


def translation(vector_of_t):
    """Translation by ``vector_of_t(t)`` (3 numbers mean ``vector * t``)."""
    owner = "motion.translation"
    if callable(vector_of_t):
        fn = vector_of_t
    else:
        try:
            v = _vector(vector_of_t, "vector_of_t", owner)
        except InputError:
            raise InputError(f"{owner}: vector_of_t must be a callable t -> vector or 3 finite numbers "
                             f"(vector * t), got {_show(vector_of_t)}") from None
        fn = lambda t: v * t  # noqa: E731

    def G(t):
        out = np.eye(4)
        out[:3, 3] = _vector(fn(t), f"vector_of_t({t:g})", owner)
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
