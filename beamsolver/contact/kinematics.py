"""Contact kinematics on SE(3) (Bruls & Bosten, seed eqs. 4, 7, 8).

Frames ``{L}`` (slave contour point) and ``{K}`` (master contour point) have
axes ``(n, t1, t2)``; ``H_LK = H_L^-1 H_K``; the normal gap is ``[H_LK]_{1,4}``
(1-based) and the relative motion increment over a step is
``dy = log(H_LK(t - dt)^-1 H_LK(t))`` with components in ``{K}``.
"""
import numpy as np

from ..lie import se3

__all__ = ["relative_motion", "slip_increment", "normal_gap"]


def relative_motion(H_LK_prev, H_LK):
    """``dy = log(H_LK_prev^-1 H_LK)``, ``(..., 6)`` (seed eq. 7)."""
    return se3.log(se3.relative(H_LK_prev, H_LK))


def slip_increment(H_LK_prev, H_LK):
    """Tangential slip increment ``dg_T = (dy[1], dy[2])`` (0-based), ``(..., 2)`` (seed eq. 8)."""
    return relative_motion(H_LK_prev, H_LK)[..., 1:3]


def normal_gap(H_LK):
    """``g_N = [H_LK]_11``: first translation component of ``H_LK`` (seed eq. 4)."""
    return np.asarray(H_LK)[..., 0, 3]
