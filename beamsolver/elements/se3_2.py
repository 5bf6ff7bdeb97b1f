"""The two-node SE(3) element (``element`` over the compiled ``element_jit``) as an element type, ``"se3-2"``.

Constant strain ``h / L``, ``h = log(H_A^-1 H_B)`` (docs/theory.md section 3);
its interpolation ``H_A exp(xi h)`` is the element's own kinematics.
"""
import numpy as np

from . import element
from ..lie import se3
from .base import ElementType, Reference, is_diagonal

__all__ = ["SE3Two"]


class SE3Two(ElementType):
    """Two nodes, 12 unknowns, exact tangent, compiled kernel."""
    name = "se3-2"
    n_nodes = 2
    rotation_pairs = ((0, 1),)

    def reference(self, P0, C):
        L, eps0 = element.reference_strain(P0[:, 0], P0[:, 1])
        C = np.ascontiguousarray(C, dtype=float)
        return Reference(L, eps0, C, is_diagonal(C))

    def evaluate(self, H, nodes, ref, tangent, out=None):
        if nodes is None:
            H, nodes = self.poses(H, nodes)
        return element.evaluate_nodes(H, nodes, ref.L, ref.eps0, ref.C, tangent, out, ref.diagonal)

    def energy(self, H, nodes, ref):
        """Strain energy per element ``(n,)`` (``element.energy``)."""
        H, nodes = self.poses(H, nodes)
        return element.energy(H[nodes[:, 0]], H[nodes[:, 1]], ref.L, ref.eps0, ref.C)

    def interpolate(self, H_el, e, xi):
        HA, HB = H_el[:, 0], H_el[:, 1]
        h = se3.log(se3.relative(HA, HB))
        return se3.interpolate(HA[e], h[e], xi)
