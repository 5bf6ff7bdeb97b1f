"""``frames.material_frames`` compiled, the same bits (``lie.se3_twin``: numpy's order of operations).

The start of a pair's friction history (``system.ContactSystem._params``) takes the pair's frames at
the last converged poses for every pair without history, at every evaluation of a step that has
new pairs; the numpy version spent most of its time in Python calls.
"""
import numpy as np

from .._jit import jit
from ..lie.se3_twin import coefficient_table, exp_angles, exp_compose_into, relative_into
from .frames import NORMAL_TOL

__all__ = ["material_frames"]


@jit
def _frames(H, nodes, xi1, xi2, R1, R2, h1, h2, coef, H_CL, H_FK, H_LK):
    m = len(xi1)
    HC, HF, HL, HK = np.empty((4, 4)), np.empty((4, 4)), np.zeros((4, 4)), np.zeros((4, 4))
    for k in range(m):
        x, y = xi1[k], xi2[k]
        exp_compose_into(H[nodes[k, 0]], x * h1[k, 0], x * h1[k, 1], x * h1[k, 2], x * h1[k, 3], x * h1[k, 4],
                         x * h1[k, 5], coef[0, k], coef[1, k], coef[2, k], HC)
        exp_compose_into(H[nodes[k, 2]], y * h2[k, 0], y * h2[k, 1], y * h2[k, 2], y * h2[k, 3], y * h2[k, 4],
                         y * h2[k, 5], coef[0, m + k], coef[1, m + k], coef[2, m + k], HF)
        # frames.axes
        d0, d1, d2 = HF[0, 3] - HC[0, 3], HF[1, 3] - HC[1, 3], HF[2, 3] - HC[2, 3]
        dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if dist < NORMAL_TOL * (R1[k] + R2[k]) or dist == 0.0:
            n0 = n1 = n2 = np.nan
        else:
            n0, n1, n2 = d0 / dist, d1 / dist, d2 / dist
        e0, e1, e2 = HC[0, 0], HC[1, 0], HC[2, 0]
        en = e0 * n0 + e1 * n1 + e2 * n2
        a0, a1, a2 = e0 - en * n0, e1 - en * n1, e2 - en * n2
        na = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        a0, a1, a2 = a0 / na, a1 / na, a2 / na
        b0, b1, b2 = n1 * a2 - n2 * a1, n2 * a0 - n0 * a2, n0 * a1 - n1 * a0
        # frames.contact_frames: axes (n, t1, t2) as columns, at x_C + R1 n and x_F - R2 n
        for P in (HL, HK):
            P[0, 0], P[0, 1], P[0, 2] = n0, a0, b0
            P[1, 0], P[1, 1], P[1, 2] = n1, a1, b1
            P[2, 0], P[2, 1], P[2, 2] = n2, a2, b2
            P[3, 3] = 1.0
        HL[0, 3], HL[1, 3], HL[2, 3] = HC[0, 3] + R1[k] * n0, HC[1, 3] + R1[k] * n1, HC[2, 3] + R1[k] * n2
        HK[0, 3], HK[1, 3], HK[2, 3] = HF[0, 3] - R2[k] * n0, HF[1, 3] - R2[k] * n1, HF[2, 3] - R2[k] * n2
        relative_into(HC, HL, H_CL[k])
        relative_into(HF, HK, H_FK[k])
        relative_into(HL, HK, H_LK[k])


def material_frames(H, nodes, xi1, xi2, R1, R2, h1, h2):
    """``frames.material_frames(H[nodes], kind, xi1, xi2, R1, R2, h1, h2)`` (its bits): ``H_CL``, ``H_FK``,
    ``H_LK`` ``(m, 4, 4)`` of the pairs over the nodes ``(m, 4)`` (slave A, B, master A, B) of the poses
    ``H``; ``h1``, ``h2`` ``(m, 6)`` the elements' twists."""
    m = len(nodes)
    f = lambda v: np.ascontiguousarray(v, dtype=float)      # noqa: E731
    xi1, xi2, R1, R2, h1, h2 = f(xi1), f(xi2), f(R1), f(R2), f(h1), f(h2)
    c = coefficient_table(("a", "b", "c"), np.concatenate([exp_angles(h1, xi1), exp_angles(h2, xi2)]))
    out = np.empty((3, m, 4, 4))
    _frames(np.ascontiguousarray(H, dtype=float), np.ascontiguousarray(nodes), xi1, xi2, R1, R2, h1, h2, c,
            out[0], out[1], out[2])
    return out[0], out[1], out[2]
