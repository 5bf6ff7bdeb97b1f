"""The element contract: what an element type provides to the model, the assembly, the solver and the output.

An element type maps the poses of its ``k`` nodes to body-frame nodal forces
and their tangent, batched over elements (docs/theory.md eqs. 14.1-14.2):

- ``reference(P0, C)``: reference data from reference poses ``(n, k, 4, 4)``
  and section stiffnesses ``(n, 6, 6)`` (``Reference``: length ``L``, the
  reference strain ``eps0`` of the reported state, type-specific arrays);
- ``evaluate(H, nodes, ref, tangent, out)``: node poses ``H[nodes[e]]``
  (``H`` ``(N, 4, 4)``, ``nodes`` ``(n, k)``; or ``H`` ``(n, k, 4, 4)`` and
  ``nodes=None``) to forces ``(n, 6k)`` (node-major, translation first),
  tangent ``(n, 6k, 6k)`` (``d f / d q`` for body increments
  ``H_i <- H_i exp(hat(q_i))``; ``None`` without ``tangent``; written into
  ``out`` if given) and an ``ElementState`` (``h``: the relative twist the
  validity check reads, ``strain`` and ``sigma = C (strain - eps0)``, ``(n, 6)``
  each, for output);
- ``energy(H, nodes, ref)``: strain energy per element ``(n,)``, ``int 1/2 (eps - eps0) C (eps -
  eps0) ds`` (the potential whose gradient ``evaluate`` gives; stabilisation and diagnostics
  read it);
- ``rotation_pairs``: the local node pairs whose relative rotation the
  element represents through a logarithm; ``max_rotation``: the largest
  such rotation it accepts (rad), below pi where the logarithm jumps;
- ``interpolate(H_el, e, xi)``: poses at ``xi`` in [0, 1] along elements ``e``
  for drawing.

Nodes of an element run along the beam (first node at ``xi = 0``, last at
``xi = 1``); consecutive elements of a beam share their end node.
"""
from dataclasses import dataclass, field

import numpy as np

from .element import ElementState, is_diagonal
from ..errors import InputError

__all__ = ["ElementType", "Reference", "ElementState", "MAX_ELEMENT_ROTATION", "is_diagonal"]

# an iterate turning a logarithm pair of an element further is rejected: the logarithm is defined
# up to pi, and this keeps a margin for one Newton correction
MAX_ELEMENT_ROTATION = 0.8 * np.pi


@dataclass
class Reference:
    """Reference data of a batch of elements of one type."""
    L: np.ndarray                 # (n,) reference length
    eps0: np.ndarray              # (n, 6) reference strain of the reported state
    C: np.ndarray                 # (n, 6, 6) section stiffness, C-contiguous
    diagonal: bool                # every C diagonal (a faster kernel branch)
    data: dict = field(default_factory=dict)   # type-specific arrays


class ElementType:
    """Base of the element types (see the module docstring for the contract)."""
    name = ""
    n_nodes = 2
    rotation_pairs = ((0, 1),)
    max_rotation = MAX_ELEMENT_ROTATION

    def __repr__(self):
        return f"<element type {self.name!r}, {self.n_nodes} nodes>"

    def n_elements(self, n_poses, label):
        """Elements of a beam through ``n_poses`` node poses (``InputError`` if they do not fit)."""
        k = self.n_nodes
        if n_poses < k or (n_poses - 1) % (k - 1):
            raise InputError(f"{label}: element {self.name!r} has {k} nodes, so a beam needs "
                             f"{k - 1} m + 1 node poses (m >= 1 elements), got {n_poses}")
        return (n_poses - 1) // (k - 1)

    def connectivity(self, n_elements):
        """Local node indices ``(n_elements, k)`` of a beam's elements."""
        k = self.n_nodes
        return (k - 1) * np.arange(n_elements)[:, None] + np.arange(k)

    def rotation_angles(self, H_el):
        """Rotation angles ``(n, len(rotation_pairs))`` of the pairs at element poses ``(n, k, 4, 4)``."""
        out = []
        for i, j in self.rotation_pairs:
            R = np.swapaxes(H_el[:, i, :3, :3], 1, 2) @ H_el[:, j, :3, :3]
            out.append(np.arccos(np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0)))
        return np.stack(out, axis=1)

    @staticmethod
    def poses(H, nodes):
        """``(H, nodes)`` for the kernels: ``H`` ``(N, 4, 4)`` with ``nodes`` ``(n, k)``, or
        ``H`` ``(n, k, 4, 4)`` with ``nodes=None``, as a contiguous pose array and a node table."""
        H = np.ascontiguousarray(H, dtype=float)
        if nodes is None:
            n, k = H.shape[:2]
            return H.reshape(n * k, 4, 4), np.arange(n * k, dtype=np.int64).reshape(n, k)
        return H, np.ascontiguousarray(nodes, dtype=np.int64)

    def reference(self, P0, C):
        raise NotImplementedError

    def evaluate(self, H, nodes, ref, tangent, out=None):
        raise NotImplementedError

    def energy(self, H, nodes, ref):
        raise NotImplementedError

    def interpolate(self, H_el, e, xi):
        raise NotImplementedError
