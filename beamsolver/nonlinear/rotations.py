"""Element rotations a step may not take: past the element type's limit within an element
(``MAX_ELEMENT_ROTATION`` for se3-2), or through pi within a step (the logarithm would see the short
way round).  ``RotationGuard`` checks every iterate and every converged step of ``nonlinear.newton``."""
import numpy as np

from .. import elements
from ..failures import RotationLimit
from ..lie import se3

__all__ = ["RotationGuard", "relative_rotations", "angle", "largest_element_rotation", "MAX_ELEMENT_ROTATION",
           "CONTINUITY_MARGIN"]

MAX_ELEMENT_ROTATION = elements.MAX_ELEMENT_ROTATION   # an iterate turning an element further is rejected
SQRT3 = np.sqrt(3.0)                 # |w|_2 <= SQRT3 |w|_inf (the rotation check's shortcut)
CONTINUITY_MARGIN = 1e-6             # check_continuity's shortcut: far above the ~1e-8 round-off of arccos at 0


def relative_rotations(system, H):
    """Rotations ``R_i^T R_j`` of the node pairs an element represents by a logarithm
    (``system.rotation_pairs``: one per element for two-node elements), ``(n_pairs, 3, 3)``."""
    en = system.rotation_pairs
    return np.swapaxes(H[en[:, 0], :3, :3], 1, 2) @ H[en[:, 1], :3, :3]


def angle(R):
    """Rotation angles in ``[0, pi]`` of ``(..., 3, 3)`` rotation matrices."""
    return np.arccos(np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0))


def largest_element_rotation(system, H):
    """Largest rotation angle between the two nodes of an element at poses ``H``."""
    if system.n_elements == 0:
        return 0.0
    return float(angle(relative_rotations(system, H)).max())


class RotationGuard:
    """The rotation checks of one ``assembly.System`` (``check``: an iterate; ``check_continuity``:
    a step), failing with ``failures.RotationLimit`` naming the element and its beam."""

    def __init__(self, system):
        self.sys = system
        # the rotation check's shortcut bound, a margin far above the round-off of |w|
        self._smallest_limit = (1.0 - 1e-9) * float(system.rotation_limit.min(initial=np.inf))

    def _element_label(self, e):
        """``element e (element j of Beam b)`` for a global element id."""
        for b in self.sys.model.beams:
            if b.elements[0] <= e <= b.elements[-1]:
                return f"element {e} (no. {e - b.elements[0]} of the {b.n_elements} of Beam {b.id})"
        return f"element {e}"

    def check(self, state):
        """Refuse an iterate whose element state ``state`` turns an element past its type's limit."""
        w = state.h[:, 3:]
        # |w| <= sqrt(3) max|w_i|: far below every limit, nothing to measure
        if len(w) and np.abs(w).max() * SQRT3 < self._smallest_limit:
            return
        ang = se3.rotation_angle(w)
        limit = self.sys.rotation_limit          # of each element's type, MAX_ELEMENT_ROTATION for se3-2
        worst = int(np.argmax(ang - limit)) if len(ang) else 0
        if len(ang) and ang[worst] > limit[worst]:
            raise RotationLimit(f"{self._element_label(worst)} turns by {ang[worst]:.4f} rad within one element "
                                f"(limit MAX_ELEMENT_ROTATION = {limit[worst] / np.pi:.2g} pi = "
                                f"{limit[worst]:.4f} rad; an element cannot turn by pi): refine the mesh")

    def check_continuity(self, H0, H1):
        """Refuse a step over which an element's relative rotation may have passed through pi.

        The element only sees ``log(H_A^-1 H_B)``, whose angle lies in ``[0, pi]``: an element
        turned past pi within one load step would look like one turned the short way round (a
        silent wrong answer).  Passing pi and coming back to the angle ``t1`` from ``t0`` takes a
        rotation of at least ``(pi - t0) + (pi - t1)``, so a step whose relative rotations change
        by less than that (the geodesic angle between old and new) cannot have passed it.
        """
        if self.sys.n_elements == 0:
            return
        R0, R1 = relative_rotations(self.sys, H0), relative_rotations(self.sys, H1)
        a0, a1 = angle(R0), angle(R1)
        # the change is at most a0 + a1: below pi (a margin above the arccos round-off) nothing can pass
        if (a0 + a1).max() < np.pi - CONTINUITY_MARGIN:
            return
        change = angle(np.swapaxes(R0, 1, 2) @ R1)
        bad = np.flatnonzero(change >= (np.pi - a0) + (np.pi - a1) - 1e-9)
        if len(bad):
            e = int(bad[np.argmax(change[bad])])
            raise RotationLimit(f"{self._element_label(self.sys.pair_element[e])} turns by {change[e]:.3f} rad "
                                "within one element in "
                                "one load step and may have passed pi, which an element cannot represent: "
                                "use smaller steps or refine the mesh")
