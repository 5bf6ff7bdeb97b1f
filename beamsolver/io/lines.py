"""Beams as refined poly-lines for drawing: points, segments and their data (numpy only).

Every element is cut into ``refine`` segments at ``xi = k / refine``; the
points are the element type's own interpolation (``ElementType.interpolate``;
for two-node elements the constant-strain ``H_A exp(xi h)`` with
``h = log(H_A^-1 H_B)``),
so a beam bent at constant curvature is drawn on its exact circle or helix
however coarse the mesh.  Shared by ``io.vtk`` (ParaView files) and ``viz``
(pictures); works from a ``Solution`` alone (a loaded one too).

Point data: ``displacement`` (3), ``e1``, ``e2``, ``e3`` (section axes,
the columns of ``R``), ``radius`` (contact radius of the section, for tubes),
``beam_id``; with ``solve(modes=k)``, ``mode_j_u`` and ``mode_j_rotation``
(global displacement and rotation vector of mode ``j = 1..k``, unit-free size 1,
``Solution.modes``; ``node_field``: linear between the nodes).  Segment (cell) data: the section forces of the element
``N, Q2, Q3, T, M2, M3`` (section frame) and ``strain`` (6: ``Gamma_1..3,
kappa_1..3`` minus the reference, so ``sigma = C strain`` and a beam at rest
shows 0; ``Solution.strains`` is the strain itself, reference included:
``strain = Solution.strains - eps0``), ``equivalent_strain`` and ``utilisation``
(``Solution.equivalent_strain``, ``Solution.utilisation``: the material range,
``beamsolver.model.material_range``), ``element``.
"""
import numpy as np

from .. import elements
from ..model.material_range import element_properties, utilisation

__all__ = ["LineLayout", "FORCE_NAMES", "STRAIN_NAMES"]

FORCE_NAMES = ("N", "Q2", "Q3", "T", "M2", "M3")
STRAIN_NAMES = ("Gamma1", "Gamma2", "Gamma3", "kappa1", "kappa2", "kappa3")


class LineLayout:
    """Point/segment numbering of the refined poly-lines of a model description.

    ``description``: ``Solution.description`` (dict of arrays, see
    ``results.describe_model``); ``refine``: segments per element (>= 1).
    """

    def __init__(self, description, refine=8):
        refine = int(refine)
        if refine < 1:
            raise ValueError(f"refine must be >= 1, got {refine}")
        d = description
        self.refine = refine
        self.enodes = np.asarray(d["enodes"])
        n_el = len(self.enodes)
        self.n_elements = n_el
        el_beam = np.asarray(d["element_beam"])
        radius = np.asarray(d["beam_radius"], dtype=float)
        # points: per element xi = 0, 1/s, .., (s-1)/s, plus the last node of each beam
        # (elements of a beam are consecutive and chained, model.add_beam)
        last_of_beam = np.r_[el_beam[1:] != el_beam[:-1], True] if n_el else np.zeros(0, dtype=bool)
        self.last_of_beam = np.flatnonzero(last_of_beam)
        per_el = refine + last_of_beam.astype(int)
        start = np.concatenate([[0], np.cumsum(per_el)[:-1]]).astype(np.int64)
        self.n_points = int(per_el.sum())
        k = np.arange(refine)
        self.point_el = np.repeat(np.arange(n_el), refine)                 # interior/first points
        self.point_xi = np.tile(k / refine, n_el)
        self.point_index = (start[:, None] + k).ravel()
        self.end_index = start[self.last_of_beam] + refine                # last node of each beam
        self.end_node = self.enodes[self.last_of_beam, 1]
        seg_a = (start[:, None] + k).ravel()
        self.segments = np.stack([seg_a, seg_a + 1], axis=1)              # (n_el * s, 2)
        self.segment_el = np.repeat(np.arange(n_el), refine)
        pbeam = np.empty(self.n_points, dtype=np.int32)
        pbeam[self.point_index] = el_beam[self.point_el]
        pbeam[self.end_index] = el_beam[self.last_of_beam]
        self.point_beam = pbeam
        self.point_radius = radius[pbeam]
        self.eps0 = np.asarray(d["eps0"], dtype=float)
        self.material = element_properties(d)
        self.groups = self._groups(d)
        self.reference = self.poses(np.asarray(d["poses0"], dtype=float))[:, :3, 3]

    def _groups(self, d):
        """Per element type: the type, node ids ``(m, k)`` of its elements and, for the points on
        them, their rows of ``point_index`` and local element numbers."""
        names = np.asarray(d.get("beam_element", np.full(len(d["beam_radius"]), elements.DEFAULT)))
        el_type = names[np.asarray(d["element_beam"], dtype=int)] if self.n_elements else names[:0]
        local = np.empty(self.n_elements, dtype=np.int64)
        out = []
        for name in dict.fromkeys(el_type.tolist()):
            etype = elements.get(str(name))
            els = np.flatnonzero(el_type == name)
            local[els] = np.arange(len(els))
            nodes = self.enodes[els, :1] + np.arange(etype.n_nodes)   # nodes of an element are consecutive
            rows = np.flatnonzero(el_type[self.point_el] == name)
            out.append((etype, nodes, rows, local[self.point_el[rows]]))
        return out

    def poses(self, H):
        """Poses ``(n_points, 4, 4)`` of the refined points for node poses ``H``."""
        out = np.empty((self.n_points, 4, 4))
        if self.n_elements == 0:
            return out
        for etype, nodes, rows, e in self.groups:
            out[self.point_index[rows]] = etype.interpolate(H[nodes], e, self.point_xi[rows])
        out[self.end_index] = H[self.end_node]
        return out

    def point_data(self, H):
        P = self.poses(H)
        return dict(displacement=P[:, :3, 3] - self.reference, e1=P[:, :3, 0].copy(),
                    e2=P[:, :3, 1].copy(), e3=P[:, :3, 2].copy(), radius=self.point_radius,
                    beam_id=self.point_beam), P[:, :3, 3].copy()

    def node_field(self, values):
        """Node values ``(n_nodes, m)`` at the refined points, linear in ``xi`` between the nodes of each element."""
        values = np.asarray(values, dtype=float)
        out = np.empty((self.n_points,) + values.shape[1:])
        if self.n_elements == 0:
            return out
        for etype, nodes, rows, e in self.groups:      # piecewise linear through the element's k nodes
            k = etype.n_nodes
            x = self.point_xi[rows] * (k - 1)
            seg = np.minimum(np.floor(x).astype(int), k - 2)
            a, b = values[nodes[e, seg]], values[nodes[e, seg + 1]]
            xi = (x - seg).reshape((-1,) + (1,) * (values.ndim - 1))
            out[self.point_index[rows]] = (1.0 - xi) * a + xi * b
        out[self.end_index] = values[self.end_node]
        return out

    def cell_data(self, sigma, strain):
        e = self.segment_el
        out = {name: np.ascontiguousarray(sigma[e, i]) for i, name in enumerate(FORCE_NAMES)}
        out["strain"] = np.ascontiguousarray((strain - self.eps0)[e])
        eq, u = utilisation(strain, self.eps0, self.material)
        out["equivalent_strain"], out["utilisation"] = eq[e], u[e]
        out["element"] = e.astype(np.int32)
        return out
