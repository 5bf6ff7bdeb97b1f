"""The stopping rule of the Newton loop (``Convergence``) and its verdict (``Verdict``).

``Convergence.decide`` gives the verdict on every iterate of ``nonlinear.newton.Newton``;
``solve(..., convergence=Convergence(...))`` or ``rtol=``, ``dtol=``, ``max_iter=`` set it.
"""
import enum
from dataclasses import dataclass

import numpy as np

__all__ = ["Convergence", "Verdict", "CONVERGED", "CONTINUE", "MAX_ITER", "DIVERGED", "ROUNDOFF"]

ROUNDOFF = 64.0 * np.finfo(float).eps   # position round-off, relative to the distance from the origin


class Verdict(enum.Enum):
    """What ``Convergence.decide`` says of an iterate."""
    CONVERGED = "converged"
    CONTINUE = "continue"
    MAX_ITER = "max_iter"
    DIVERGED = "diverged"


CONVERGED, CONTINUE, MAX_ITER, DIVERGED = Verdict.CONVERGED, Verdict.CONTINUE, Verdict.MAX_ITER, Verdict.DIVERGED


@dataclass
class Convergence:
    """Stopping rule of the Newton loop.

    Converged when the scaled residual is small,
    ``|r_u|_inf <= rtol F_ref`` and ``|r_w|_inf <= rtol M_ref``, or when the last
    full Newton increment is at round-off level,
    ``|dz_u|_inf <= dtol L_ref`` and ``|dz_w|_inf <= dtol``.  ``F_ref`` and
    ``M_ref`` are the largest element nodal force/moment or applied load of
    the iterate (``F_ref >= M_ref / L_ref`` and ``M_ref >= F_ref L_ref``), ``L_ref``
    the model size: the same scene in any unit system converges in the
    same iterations.  Far from the origin positions carry a round-off of
    ``ROUNDOFF |x|``: ``decide`` takes it as a floor of the increment test, so a
    scene converges alike wherever it is placed.
    """
    rtol: float = 1e-8
    dtol: float = 1e-11
    max_iter: int = 30
    divergence: float = 1e12

    def scales(self, ev, L_ref):
        """``(F_ref, M_ref)`` from the force levels of an evaluation (``problem.Evaluation``, or a
        dict with ``f_level`` and ``m_level``)."""
        f, m = (ev["f_level"], ev["m_level"]) if isinstance(ev, dict) else (ev.f_level, ev.m_level)
        F = max(f, m / L_ref)
        M = max(m, f * L_ref)
        return F, M

    def residual_ratio(self, r_free_u, r_free_w, F, M):
        ru = np.abs(r_free_u).max(initial=0.0)
        rw = np.abs(r_free_w).max(initial=0.0)
        return max(ru / F if F > 0 else (0.0 if ru == 0 else np.inf),
                   rw / M if M > 0 else (0.0 if rw == 0 else np.inf))

    def increment_ratio(self, dz, L_ref):
        return max(np.abs(dz[:, :3]).max(initial=0.0) / L_ref, np.abs(dz[:, 3:]).max(initial=0.0))

    @staticmethod
    def floor(H, L_ref):
        """Round-off floor of ``increment_ratio`` at poses ``H``: ``ROUNDOFF max|x| / L_ref``."""
        return ROUNDOFF * float(np.abs(H[:, :3, 3]).max(initial=0.0)) / L_ref

    def decide(self, ratio, increment, iteration, floor=0.0, final=True):
        """Verdict on an iterate with scaled residual ``ratio`` reached by a full Newton increment
        of ``increment_ratio`` ``increment`` (``inf`` if damped or none) at ``iteration``:
        ``Verdict.CONVERGED`` (``ratio <= rtol`` or ``increment <= max(dtol, floor)``; only if
        ``final``, i.e. the prescribed motions have been applied), else ``MAX_ITER`` (``iteration
        >= max_iter``), ``DIVERGED`` (``ratio > divergence``) or ``CONTINUE``."""
        if final and (ratio <= self.rtol or increment <= max(self.dtol, floor)):
            return CONVERGED
        if iteration >= self.max_iter:
            return MAX_ITER
        if ratio > self.divergence:
            return DIVERGED
        return CONTINUE
