"""A bending fixture: impose a curvature history on a bundle of beams between two rigid end plates.

The bundle runs along ``e_z`` from ``z_0`` (its beams' first nodes) to ``z_0 + L`` (their last nodes).
Each end is a rigid plate (a node on the bundle axis rigidly linked to every beam end there;
``cables.Strand.plate`` for a strand).  For a curvature ``kappa(t)`` about the bending axis ``e_b``
(``e_y`` or ``e_x``) and a pull ``T(t)`` (force, along ``e_z``):

- the bottom plate turns by ``-kappa L / 2`` about ``e_b`` through its centre (prescribed);
- the top plate turns by ``+kappa L / 2`` about ``e_b``, its lateral translations are held, its
  axial translation is free under the dead pull ``T e_z``;
- the pull's P-delta is cancelled by the lateral line load of a string under tension, ``w = T kappa``
  per unit bundle length pointing away from the centre of curvature (``-T kappa (e_b x e_z)``),
  shared among the beams as their axial forces are (``EA_i c_i^3``, ``c_i = L / L_i`` the cosine of a
  helical wire's lay angle) and given per unit reference length of each beam (``w c_i`` times the
  share; ``c_i`` the mean of ``e1 . e_z`` over its nodes).  The moment is then uniform along an elastic bundle (docs/theory_strand_bending.md).

The plates' curvature turns the bundle into a circular arc (chord shortening ``kappa^2 L^3 / 24``
taken by the free axial translation).
"""
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError
from .model import Beam, _constant
from .motion import rotation
from .validation import CheckedScalar

__all__ = ["BendingFixture", "bending_fixture"]

AXES = {"x": (np.array([1.0, 0.0, 0.0]), "rx"), "y": (np.array([0.0, 1.0, 0.0]), "ry")}
PLANE_TOL = 1e-9         # beam ends within this (relative to the model size) of their end plane


@dataclass
class BendingFixture:
    """The fixture's nodes and functions: plates ``bottom``, ``top``; ``length`` ``L``; ``z0``;
    ``curvature(t)``, ``pull(t)``; bending axis ``axis`` (unit vector); ``beams``; ``line_loads``."""
    model: object
    beams: list
    bottom: int
    top: int
    z0: float
    length: float
    curvature: Callable[[float], float]
    pull: Callable[[float], float]
    axis: np.ndarray
    line_loads: list

    def moment(self, solution, z=None, step=None):
        """Bending moment about the bending axis across the cut at reference height ``z`` (default
        mid-length), every step (``step=None``) or one: ``resultants.cut_resultant``'s ``bending[..., 0]``."""
        z = self.z0 + 0.5 * self.length if z is None else z
        return solution.cut_resultant(self.beams, z, bending_axis=self.axis, step=step).bending[..., 0]

    def plate_moment(self, solution, step=None):
        """Moment about the bending axis on the top plate from the support (its reaction), per step."""
        steps = slice(None) if step is None else step
        return solution.reactions[steps, self.top, 3:] @ self.axis


def _function(value, what):
    return CheckedScalar(value, what) if callable(value) else _constant(value, what)


def bending_fixture(strand_or_beams, curvature, pull, axis="y", model=None):
    """Bend ``strand_or_beams`` (a ``cables.Strand``, or a list of Beams along ``e_z`` of ``model``) to ``curvature(t)``
    [1/length] about the global ``axis`` ('y' or 'x') under the dead ``pull(t)`` [force] (numbers are
    held constant); plates, constraints, pull and P-delta line loads are added to the beams' model.
    Returns a ``BendingFixture`` (module docstring)."""
    if axis not in AXES:
        raise InputError(f"bending_fixture: axis must be 'x' or 'y', got {axis!r}")
    e_b, dof = AXES[axis]
    kappa = _function(curvature, "bending_fixture: curvature")
    T = _function(pull, "bending_fixture: pull")
    strand = strand_or_beams if hasattr(strand_or_beams, "all_wires") else None
    beams = strand.all_wires if strand is not None else list(strand_or_beams)
    if not beams or not all(isinstance(b, Beam) for b in beams):
        raise InputError(f"bending_fixture: expected a Strand or a list of Beams, got {strand_or_beams!r}")
    model = strand.model if strand is not None else model
    if model is None or any(b.id >= len(model.beams) or model.beams[b.id] is not b for b in beams):
        raise InputError("bending_fixture: give a Strand, or Beams with the Model they belong to (model=)")
    P = model.poses0
    zb, zt = P[[b.first for b in beams], 2, 3], P[[b.last for b in beams], 2, 3]
    tol = PLANE_TOL * model.characteristic_length()
    if np.ptp(zb) > tol or np.ptp(zt) > tol or zt.min() <= zb.max():
        raise InputError("bending_fixture: the beams must run along +e_z, their first nodes in one plane "
                         f"z = z0 and their last in z = z0 + L (first at z {zb.min():.6g}..{zb.max():.6g}, "
                         f"last at {zt.min():.6g}..{zt.max():.6g})")
    z0, L = float(zb.mean()), float(zt.mean() - zb.mean())
    if strand is not None:
        bottom, top = strand.plate("bottom"), strand.plate("top")
    else:
        bottom, top = _plate(model, beams, "first"), _plate(model, beams, "last")
    centre = model.poses0[bottom, :3, 3]
    model.prescribe(bottom, rotation(e_b, lambda t: -0.5 * L * kappa(t), centre))
    model.fix(top, ("ux", "uy", "rx", "ry", "rz"), values={dof: lambda t: 0.5 * L * kappa(t)})
    model.add_load(top, force=(0.0, 0.0, 1.0), scale=T)
    # P-delta: w = T kappa per unit length, shared as the beams' axial forces, away from the centre
    c = np.array([np.mean(P[b.nodes, 2, 0]) for b in beams])        # e1 . e_z: cos of the lay angle
    EA = np.array([b.section.C[0, 0] for b in beams])
    share = EA * c**3 / np.sum(EA * c**3)
    outward = -np.cross(e_b, (0.0, 0.0, 1.0))
    loads = [model.add_line_load(b, force_per_length=outward * s * ci, scale=lambda t: T(t) * kappa(t))
             for b, s, ci in zip(beams, share, c)]
    return BendingFixture(model, beams, bottom, top, z0, L, kappa, T, e_b, loads)


def _plate(model, beams, end):
    """A node at the centroid of the beams' ``end`` nodes, rigidly linked to each of them."""
    nodes = [getattr(b, end) for b in beams]
    node = model.add_node(model.poses0[nodes, :3, 3].mean(axis=0), name=f"plate {end}")
    for n in nodes:
        model.join(node, n, rigid=True)
    return node
