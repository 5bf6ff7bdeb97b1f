"""User-facing scene declaration: beams, constraints, loads, contact pairs.

A ``Model`` only records and validates what the user declares; the numerics
live in ``element``, ``assembly`` and ``solver``.  Node ids are global
integers (``beam.nodes``); every ``add_beam`` creates new nodes, and beams are
connected with ``join``.
"""
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from .. import elements
from ..errors import InputError
from .section import Section
from .contact_options import check_contact_options, describe as describe_contact_options
from .validation import (MAX_REFERENCE_ELEMENT_ROTATION, ORTHONORMAL_TOL, CheckedScalar, as_array, check_node_id,
                         check_pose, real)

__all__ = ["Model", "Beam", "Load", "LineLoad", "ContactDeclaration", "ElementGroup", "DOF_NAMES"]

DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
JOIN_TOL = 1e-9                       # coincidence tolerance relative to the model size
ZERO_LENGTH_TOL = 1e-12               # an element shorter than this times the model size has zero length
LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])   # of every pose


@dataclass
class Beam:
    """A beam: its global node ids, element ids, section and index in the model."""
    id: int
    nodes: np.ndarray
    elements: np.ndarray
    section: Section
    name: Optional[str] = None
    element_type: elements.ElementType = elements.get()

    @property
    def connectivity(self):
        """Global node ids of every element ``(n_elements, k)`` (``k`` nodes of its element type)."""
        return self.nodes[self.element_type.connectivity(self.n_elements)]

    @property
    def first(self):
        return int(self.nodes[0])

    @property
    def last(self):
        return int(self.nodes[-1])

    @property
    def n_elements(self):
        return len(self.elements)

    def __repr__(self):
        label = f" {self.name!r}" if self.name else ""
        return f"Beam {self.id}{label} (nodes {self.first}..{self.last}, {self.n_elements} elements)"


@dataclass
class ElementGroup:
    """The elements of one element type: global element ids, node ids ``(n, k)``, reference data."""
    element_type: elements.ElementType
    elements: np.ndarray
    nodes: np.ndarray
    ref: elements.Reference


@dataclass
class Load:
    node: int
    force: np.ndarray
    moment: np.ndarray
    follower: bool
    scale: Callable[[float], float]


@dataclass
class LineLoad:
    """A load per unit reference length on every element of ``beam``: force ``q``, moment ``m``
    (global components, or section-frame ones if ``follower``), ramped by ``scale(t)``."""
    beam: Beam
    q: np.ndarray
    m: np.ndarray
    follower: bool
    scale: Callable[[float], float]


@dataclass
class ContactDeclaration:
    """``active_from``: the declaration acts only in steps ending after this time (None: always);
    ``friction_from``: frictionless in steps ending at or before it, Coulomb friction with
    ``mu`` after it, from zero tangential traction at the state it starts from."""
    slave: list
    master: list
    mu: float = 0.0
    penalty: Optional[float] = None
    options: dict = field(default_factory=dict)
    active_from: Optional[float] = None
    friction_from: Optional[float] = None


def _ramp(t):
    return t


def _distinct_pairs(slave, master):
    """Unordered pairs ``(a, b)`` of distinct beams, ``a`` (slave) in ``slave`` and ``b`` in ``master``,
    each once, in the order of the lists: ``[a, b, c]`` twice gives ``(a, b), (a, c), (b, c)``."""
    seen, out = set(), []
    for a in slave:
        for b in master:
            key = frozenset((a.id, b.id))
            if a.id != b.id and key not in seen:
                seen.add(key)
                out.append((a, b))
    return out


def _constant(value, what):
    """A function of ``t`` returning the finite number ``value`` (for values given as constants)."""
    try:
        c = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number or a function t -> float, got {value!r}") from None
    if not np.isfinite(c):
        raise InputError(f"{what} must be finite, got {value!r}")
    return lambda t: c


class Model:
    """A scene: ``add_beam``, ``clamp``, ``fix``, ``prescribe``, ``join``, ``add_load``, ``add_contact``,
    ``add_contribution``."""

    def __init__(self):
        self.beams = []
        self._poses = []          # list of (n_i + 1, 4, 4)
        self._refs = {}           # beam id -> (section, its C, element type, Reference) when added
        self._n_nodes = 0
        self._n_elements = 0
        self.constraints = {}     # node -> ("clamp",) | ("fix", frozenset) | ("prescribe", motion)
        self.joins = []           # (node_a, node_b)
        self.loads = []
        self.line_loads = []
        self.contacts = []
        self.contributions = []   # user contributions (blocks.Contribution protocol), checked at solve
        self.free_nodes = []      # nodes created by add_node (no elements)
        self.fix_values = {}      # node -> {component: callable} prescribed global translations

    # ------------------------------------------------------------ geometry
    @property
    def n_nodes(self):
        return self._n_nodes

    @property
    def n_elements(self):
        return self._n_elements

    @property
    def poses0(self):
        """Reference node poses ``(n_nodes, 4, 4)``."""
        if not self._poses:
            return np.zeros((0, 4, 4))
        return np.concatenate(self._poses)

    def add_beam(self, poses, section, name=None, element=None):
        """Add a beam through node poses ``(m (k - 1) + 1, 4, 4)`` with ``section``; returns the ``Beam``.

        ``element``: the element type, a name of ``beamsolver.elements.TYPES`` or an
        ``ElementType`` (default ``"se3-2"``, the two-node SE(3) element; ``"se3-3"``:
        three-node quadratic elements, so ``2 m + 1`` poses with every second one a mid node).
        """
        bid = len(self.beams)
        label = f"Beam {bid}" + (f" {name!r}" if name else "")
        etype = elements.get(element)
        if not isinstance(section, Section):
            raise InputError(f"{label}: section must be a beamsolver.Section, got {type(section).__name__}")
        P = as_array(poses, "poses", label)
        if P.ndim != 3 or P.shape[1:] != (4, 4) or P.shape[0] < 2:
            raise InputError(f"{label}: poses must have shape (n + 1, 4, 4) with n >= 1, got {P.shape}")
        if not np.isfinite(P).all():
            i = int(np.argwhere(~np.all(np.isfinite(P), axis=(1, 2)))[0, 0])
            raise InputError(f"{label}: node {i} has non-finite coordinates {P[i, :3, 3].tolist()}")
        R = P[:, :3, :3]
        err = np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max(axis=(1, 2))
        det = np.linalg.det(R)
        if err.max() > ORTHONORMAL_TOL or det.min() <= 0.0:
            i = int(np.flatnonzero((err > ORTHONORMAL_TOL) | (det <= 0.0))[0])
            raise InputError(f"{label}: pose of node {i} is not a rotation (|R^T R - I| = {err[i]:.3g}, "
                             f"det = {det[i]:.6g}); use beamsolver.geometry or orthonormalise it")
        if (P[:, 3] != LAST_ROW).any():
            raise InputError(f"{label}: the last row of every pose must be (0, 0, 0, 1)")
        n_el = etype.n_elements(len(P), label)
        conn = etype.connectivity(n_el)
        ref = etype.reference(P[conn], np.broadcast_to(section.C, (n_el, 6, 6)))
        L = ref.L
        size = max(np.ptp(P[:, :3, 3], axis=0).max(), L.sum())
        short = np.flatnonzero(L <= ZERO_LENGTH_TOL * size)
        if len(short):
            i = int(short[0])
            a, b = conn[i, 0], conn[i, -1]
            raise InputError(f"{label}: element {i} has zero length (nodes {a} and {b} coincide at "
                             f"{P[a, :3, 3].tolist()})")
        ang = etype.rotation_angles(P[conn]).max(axis=1)
        big = np.flatnonzero(ang > MAX_REFERENCE_ELEMENT_ROTATION)
        if len(big):
            i = int(big[0])
            raise InputError(f"{label}: element {i} turns by {ang[i]:.3f} rad in the reference pose "
                             f"(limit {MAX_REFERENCE_ELEMENT_ROTATION:.3f} rad, MAX_REFERENCE_ELEMENT_ROTATION); "
                             "use more elements")
        nodes = np.arange(self._n_nodes, self._n_nodes + len(P))
        element_ids = np.arange(self._n_elements, self._n_elements + n_el)
        beam = Beam(bid, nodes, element_ids, section, name, etype)
        self._refs[bid] = (section, section.C.copy(), etype, ref)
        self.beams.append(beam)
        self._poses.append(P)
        self._n_nodes += len(P)
        self._n_elements += n_el
        return beam

    def add_node(self, pose, name=None):
        """A node without elements (e.g. the reference of a rigid plate); returns its id.

        It carries stiffness only through ``join(..., rigid=True)`` links.
        """
        label = f"add_node({name or ''})"
        try:
            H = np.array(pose, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{label}: pose must be a finite 4x4 matrix or a 3-vector, got {pose!r}") from None
        if H.shape == (3,):
            x = H
            H = np.eye(4)
            H[:3, 3] = x
        if H.shape != (4, 4) or not np.all(np.isfinite(H)):
            raise InputError(f"{label}: pose must be a finite 4x4 matrix or a 3-vector, got shape {H.shape}")
        H = check_pose(H, label)
        i = self._n_nodes
        self._poses.append(H[None])
        self._n_nodes += 1
        self.free_nodes.append(i)
        return i

    # ------------------------------------------------------------ helpers
    def _node(self, node, what):
        if isinstance(node, Beam):
            raise InputError(f"{what}: expected a node id, got {node!r}; use beam.first / beam.last / beam.nodes[i]")
        return check_node_id(node, self._n_nodes, what)

    def beam_of_node(self, node):
        """The Beam owning ``node`` (None for nodes made by ``add_node``)."""
        for b in self.beams:
            if b.nodes[0] <= node <= b.nodes[-1]:
                return b
        if node in self.free_nodes:
            return None
        raise InputError(f"unknown node id {node!r}")

    def _set_constraint(self, node, value, what):
        old = self.constraints.get(node)
        if old is not None and old[0] != value[0]:
            raise InputError(f"{what}: node {node} already has a '{old[0]}' constraint")
        if old is not None and value[0] == "fix":
            value = ("fix", old[1] | value[1])
        self.constraints[node] = value

    # ------------------------------------------------------------ constraints
    def clamp(self, node):
        """Fix all six increments of ``node``."""
        i = self._node(node, "clamp")
        self._set_constraint(i, ("clamp",), f"clamp({node})")

    def fix(self, node, dofs=DOF_NAMES, values=None):
        """Fix the named increments of ``node`` in GLOBAL directions ('ux', 'uy', 'uz', 'rx', 'ry', 'rz').

        ``values``: optional ``{'uz': f, 'rz': g, ...}`` giving prescribed global
        displacements ``f(t)`` of fixed components, and at most one rotation
        angle ``g(t)`` about a global axis (then rx, ry, rz must all be fixed);
        a number instead of a function is held constant (``solve`` then starts
        from the equilibrium with it at ``t_start``).
        """
        i = self._node(node, "fix")
        if isinstance(dofs, str):
            dofs = (dofs,)
        if not isinstance(dofs, (tuple, list, set, frozenset, np.ndarray)):
            raise InputError(f"fix({node}): dofs must be names from {DOF_NAMES}, got {dofs!r}")
        bad = [d for d in dofs if d not in DOF_NAMES]
        if bad or not dofs:
            raise InputError(f"fix({node}): unknown dofs {bad or dofs!r}; choose from {DOF_NAMES}")
        idx = frozenset(DOF_NAMES.index(d) for d in dofs)
        if values is not None and not isinstance(values, Mapping):
            raise InputError(f"fix({node}): values must be a dict {{dof: t -> float}}, got {values!r}")
        if values:
            rot = {"rx", "ry", "rz"}
            for k, f in values.items():
                if k not in dofs:
                    raise InputError(f"fix({node}): values[{k!r}] needs {k!r} among the fixed dofs {tuple(dofs)}")
                if k in rot and not rot <= set(dofs):
                    raise InputError(f"fix({node}): a prescribed rotation {k!r} needs all of rx, ry, rz fixed")
                if not callable(f):
                    values = {**values, k: _constant(f, f"fix({node}): values[{k!r}]")}
            if len([k for k in values if k in rot]) > 1:
                raise InputError(f"fix({node}): at most one rotation can be prescribed; use prescribe()")
            if len(idx) == 6:
                raise InputError(f"fix({node}): with all six dofs fixed use prescribe() for motions")
            self.fix_values.setdefault(i, {}).update(
                {DOF_NAMES.index(k): CheckedScalar(f, f"fix({node}): values[{k!r}]") for k, f in values.items()})
        if len(idx) == 6:
            self._set_constraint(i, ("clamp",), f"fix({node})")
        else:
            self._set_constraint(i, ("fix", idx), f"fix({node})")

    def prescribe(self, node, motion):
        """Prescribe ``pose(t) = motion(t) @ pose_0`` for ``node``; ``motion(t)`` returns a 4x4 pose."""
        i = self._node(node, "prescribe")
        if not callable(motion):
            raise InputError(f"prescribe({node}): motion must be callable t -> 4x4 pose, got {motion!r}")
        check_pose(motion(0.0), f"prescribe({node})", "motion(t = 0)")
        self._set_constraint(i, ("prescribe", motion), f"prescribe({node})")

    def join(self, node_a, node_b, rigid=False):
        """Rigidly join two coincident nodes (their relative pose stays the reference one).

        With ``rigid=True`` the nodes may be apart: a rigid link (e.g. wire
        ends on a plate made with ``add_node``).
        """
        a = self._node(node_a, "join")
        b = self._node(node_b, "join")
        if a == b:
            raise InputError(f"join({node_a}, {node_b}): a node cannot be joined to itself")
        P = self.poses0
        size = self.characteristic_length()          # relative: the same decision in any unit
        gap = np.linalg.norm(P[a, :3, 3] - P[b, :3, 3])
        if gap > JOIN_TOL * size and not rigid:
            raise InputError(f"join({node_a}, {node_b}): nodes are {gap:.3g} apart; a joint needs coincident "
                             "nodes (pass rigid=True for a rigid link)")
        self.joins.append((a, b))

    # ------------------------------------------------------------ loads
    def add_load(self, node, force=None, moment=None, follower=False, scale=_ramp):
        """Nodal force/moment, ramped by ``scale(t)`` (default ``t``).

        Dead loads (default) are given in global components; a ``follower``
        load is given in the node's body frame and turns with it.
        """
        i = self._node(node, "add_load")
        F = np.zeros(3) if force is None else as_array(force, "force", f"add_load({node})").reshape(-1)
        M = np.zeros(3) if moment is None else as_array(moment, "moment", f"add_load({node})").reshape(-1)
        for name, v in (("force", F), ("moment", M)):
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise InputError(f"add_load({node}): {name} must be 3 finite numbers, got {v.tolist()}")
        if not callable(scale):
            raise InputError(f"add_load({node}): scale must be callable t -> float, got {scale!r}")
        self.loads.append(Load(i, F, M, bool(follower), CheckedScalar(scale, f"add_load({node}): scale")))

    def add_line_load(self, beam, force_per_length=None, moment_per_length=None, follower=False, scale=_ramp):
        """A distributed load on every element of ``beam``, per unit reference length: force
        ``force_per_length`` (force / length) and moment ``moment_per_length`` (force), ramped by
        ``scale(t)`` (default ``t``); returns the ``LineLoad``.

        Dead loads (default) are given in global components; a ``follower`` load in the section
        frame (``e1`` the tangent) and turns with it.  The element integrates it consistently
        over its length along ``H_A exp(xi h)`` (``line_load``; two-node elements only).
        """
        what = f"add_line_load({beam!r})"
        if not isinstance(beam, Beam) or beam.id >= len(self.beams) or self.beams[beam.id] is not beam:
            raise InputError(f"{what}: expected a Beam of this model")
        if beam.element_type.n_nodes != 2:
            raise InputError(f"{what}: line loads need two-node elements, the beam has "
                             f"{beam.element_type.name!r} elements")
        q = np.zeros(3) if force_per_length is None else as_array(force_per_length, "force_per_length", what).reshape(-1)
        m = np.zeros(3) if moment_per_length is None else as_array(moment_per_length, "moment_per_length",
                                                                   what).reshape(-1)
        for name, v in (("force_per_length", q), ("moment_per_length", m)):
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise InputError(f"{what}: {name} must be 3 finite numbers, got {v.tolist()}")
        if not callable(scale):
            raise InputError(f"{what}: scale must be callable t -> float, got {scale!r}")
        load = LineLoad(beam, q, m, bool(follower), CheckedScalar(scale, f"{what}: scale"))
        self.line_loads.append(load)
        return load

    # ------------------------------------------------------------ contact
    def add_contact(self, slave, master, mu=0.0, penalty=None, active_from=None, friction_from=None, **options):
        """Declare contact between ``slave`` and ``master`` (a Beam or a list of Beams each).

        ``mu``: Coulomb friction coefficient (default 0: frictionless).
        ``penalty``: normal penalty, force / length^2 (contact force per unit length
        per unit penetration; default: the Young's modulus ``EA / (pi r^2)`` of the
        softer section, ``contact.law.default_penalty``; ``solve`` warns when
        ``penalty L_e^2 / EA`` passes 1e6, ``contact.conditioning``).  Options, lengths in the
        model's unit:

{contact_options}

        Switched in pseudo-time (default None: from the start): ``active_from``: the
        declaration acts only in steps ending after this time; ``friction_from``: frictionless
        in the steps ending at or before it, then friction from zero tangential traction at the
        state the first frictional step starts from (a pretension applied frictionless).

        Unknown options are refused.  The same beams on both
        sides (``add_contact(group, group)``, as for the wires of a cable) declare every
        unordered pair of distinct beams once, as one declaration per pair (the same as
        declaring the pairs one by one); no beam is in contact with itself, nor elements
        sharing a node.  Lists that only partly overlap are refused.  Returns the
        ``ContactDeclaration`` (a list of them for a group).
        """
        for side, v in (("slave", slave), ("master", master)):
            if not isinstance(v, (Beam, list, tuple)):
                raise InputError(f"add_contact: {side} must be a Beam or a list of Beams, got {v!r}")
        s = [slave] if isinstance(slave, Beam) else list(slave)
        m = [master] if isinstance(master, Beam) else list(master)
        for b in s + m:
            if not isinstance(b, Beam) or b.id >= len(self.beams) or self.beams[b.id] is not b:
                raise InputError(f"add_contact: {b!r} is not a beam of this model")
            if b.element_type.n_nodes != 2:
                raise InputError(f"add_contact: {b!r} has {b.element_type.name!r} elements; contact works on "
                                 "two-node elements only")
        mu = real(mu, "mu", "add_contact", minimum=0.0)
        penalty = real(penalty, "penalty", "add_contact", above=0.0, none=True)
        options = check_contact_options(options)
        active_from = real(active_from, "active_from", "add_contact", none=True)
        friction_from = real(friction_from, "friction_from", "add_contact", none=True)
        switch = dict(active_from=active_from, friction_from=friction_from)
        same = {b.id for b in s} & {b.id for b in m}
        if not same:
            self._refuse_declared(_distinct_pairs(s, m))
            decl = ContactDeclaration(s, m, mu, penalty, options, **switch)
            self.contacts.append(decl)
            return decl
        pairs = _distinct_pairs(s, m) if {b.id for b in s} == {b.id for b in m} else []
        if not pairs:
            raise InputError(f"add_contact: beam {sorted(same)[0]} is declared in contact with itself"
                             + ("" if len(same) == 1 and len(s) == len(m) == 1 else
                                " (a group in contact within itself is declared with the same beams on "
                                "both sides)"))
        self._refuse_declared(pairs)
        decls = [ContactDeclaration([a], [b], mu, penalty, dict(options), **switch) for a, b in pairs]
        self.contacts.extend(decls)
        return decls

    def _refuse_declared(self, pairs):
        """``InputError`` if a beam pair of ``pairs`` (``(Beam, Beam)``) already has a contact declaration:
        a second one would add its forces again (twice the penalty)."""
        for i, d in enumerate(self.contacts):
            declared = {frozenset((a.id, b.id)) for a, b in _distinct_pairs(d.slave, d.master)}
            for a, b in pairs:
                if frozenset((a.id, b.id)) in declared:
                    lo, hi = sorted((a.id, b.id))
                    raise InputError(f"add_contact: beams {lo} and {hi} are already in contact by declaration "
                                     f"{i}; a second declaration would add its contact forces again (twice the "
                                     "penalty)")

    def add_contribution(self, contribution):
        """Add a physics contribution: an object with ``nodes`` (the node ids it acts on) and
        ``evaluate(H, tangent)`` -> ``blocks.Blocks`` of local forces and tangents, optionally
        ``name``, ``smooth``, ``conservative`` and the step life cycle of ``blocks.Contribution``.
        It is checked when a problem is built (``solve``: ``contributions.checked``); returns it."""
        self.contributions.append(contribution)
        return contribution

    # ------------------------------------------------------------ summary
    def element_groups(self):
        """``ElementGroup`` per element type, in the order the types first appear among the beams."""
        by_type = {}
        for b in self.beams:
            by_type.setdefault(b.element_type.name, []).append(b)
        P = None
        groups = []
        for beams in by_type.values():
            etype = beams[0].element_type
            ref = self._reference_when_added(beams[0]) if len(beams) == 1 else None
            if ref is not None:
                b = beams[0]
                groups.append(ElementGroup(etype, b.elements.copy(), b.connectivity, ref))
                continue
            P = self.poses0 if P is None else P
            nodes = np.concatenate([b.connectivity for b in beams])
            C = np.concatenate([np.broadcast_to(b.section.C, (b.n_elements, 6, 6)) for b in beams])
            groups.append(ElementGroup(etype, np.concatenate([b.elements for b in beams]), nodes,
                                       etype.reference(P[nodes], C)))
        return groups

    def _reference_when_added(self, beam):
        """The ``Reference`` ``add_beam`` computed for ``beam`` (the same numbers ``element_groups``
        computes), if its section, stiffness and element type are still those it was added with."""
        section, C, etype, ref = self._refs.get(beam.id, (None,) * 4)
        if section is beam.section and etype is beam.element_type and np.array_equal(C, section.C):
            return ref
        return None

    def element_table(self, groups=None):
        """Per element: end node ids ``(n_el, 2)`` (first and last node), reference length, reference
        strain, C (from ``element_groups``, or ``groups`` if given)."""
        groups = self.element_groups() if groups is None else groups
        if len(groups) == 1:
            g = groups[0]
            return np.ascontiguousarray(g.nodes[:, [0, -1]]), g.ref.L, g.ref.eps0, g.ref.C
        n = self.n_elements
        nodes, L, eps0, C = np.zeros((n, 2), dtype=int), np.zeros(n), np.zeros((n, 6)), np.zeros((n, 6, 6))
        for g in groups:
            nodes[g.elements] = g.nodes[:, [0, -1]]
            L[g.elements], eps0[g.elements], C[g.elements] = g.ref.L, g.ref.eps0, g.ref.C
        return nodes, L, eps0, C

    def characteristic_length(self):
        P = self.poses0
        return float(max(np.ptp(P[:, :3, 3], axis=0).max(), 1e-300))

    def __repr__(self):
        return (f"Model({len(self.beams)} beams, {self.n_nodes} nodes, {self.n_elements} elements, "
                f"{len(self.constraints)} constrained nodes, {len(self.loads)} loads, "
                f"{len(self.line_loads)} line loads, "
                f"{len(self.contacts)} contact declarations)")


# the options' meanings are written once, with their defaults and checks (model.contact_options)
Model.add_contact.__doc__ = Model.add_contact.__doc__.replace("{contact_options}", describe_contact_options(" " * 8))
