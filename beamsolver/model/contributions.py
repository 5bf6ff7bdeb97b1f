"""User contributions (``Model.add_contribution``): checked against the ``blocks.Contribution`` protocol.

A contribution given by a user (or a future feature) needs:

- ``nodes``: the node ids it acts on (integers in ``[0, n_nodes)``); the
  blocks it returns may only use these nodes, and their beams are not
  updated as strain-space chains (``assembly.System``), as for contact;
- ``evaluate(H, tangent)``: ``H`` ``(n_nodes, 4, 4)`` poses -> ``blocks.Blocks``
  (or ``(Blocks, info)``); ``K`` is required when ``tangent`` is True.

Optional, defaults of ``blocks.Contribution``: ``name`` (the class name, made
unique with a suffix ``_2``, ``_3``, ...), ``smooth``, ``conservative``, and the
step life cycle ``begin_step``, ``repeat_step``, ``unmet``, ``commit``,
``results``, ``get_state``, ``set_state``.  ``checked(model)`` runs when a
Problem is built (``solve``) and raises ``InputError`` naming what is missing.
"""
import numpy as np

from .blocks import Blocks, Contribution
from ..errors import InputError

__all__ = ["checked", "declared_nodes", "UserContribution"]

LIFE_CYCLE = ("begin_step", "repeat_step", "unmet", "commit", "results", "get_state", "set_state")


def _what(i, obj):
    return f"add_contribution no. {i} ({type(obj).__name__})"


def _nodes(i, obj, n_nodes):
    """The checked node ids ``(m,)`` of contribution ``obj``."""
    if not hasattr(obj, "nodes"):
        raise InputError(f"{_what(i, obj)}: has no attribute 'nodes' (the node ids it acts on)")
    try:
        nodes = np.asarray(obj.nodes)
    except Exception:
        nodes = np.asarray([None])
    if nodes.size and (nodes.dtype.kind not in "iu"):
        raise InputError(f"{_what(i, obj)}: nodes must be integer node ids, got {obj.nodes!r}")
    nodes = nodes.astype(int).ravel()
    bad = nodes[(nodes < 0) | (nodes >= n_nodes)]
    if len(bad):
        raise InputError(f"{_what(i, obj)}: node {int(bad[0])} is not a node of the model "
                         f"(it has {n_nodes} nodes)")
    return np.unique(nodes)


def declared_nodes(model):
    """Every node some user contribution of ``model`` acts on (sorted, checked)."""
    sets = [_nodes(i, c, model.n_nodes) for i, c in enumerate(getattr(model, "contributions", ()))]
    return np.unique(np.concatenate(sets)) if sets else np.zeros(0, dtype=int)


def checked(model):
    """``model.contributions`` checked and wrapped as ``UserContribution`` (unique names)."""
    out, names = [], set()
    for i, obj in enumerate(getattr(model, "contributions", ())):
        nodes = _nodes(i, obj, model.n_nodes)
        if not callable(getattr(obj, "evaluate", None)):
            raise InputError(f"{_what(i, obj)}: has no method evaluate(H, tangent) returning blocks.Blocks")
        for name in LIFE_CYCLE:
            if hasattr(obj, name) and not callable(getattr(obj, name)):
                raise InputError(f"{_what(i, obj)}: {name} must be a method, got {getattr(obj, name)!r}")
        base = getattr(obj, "name", type(obj).__name__)
        if not isinstance(base, str) or not base:
            raise InputError(f"{_what(i, obj)}: name must be a non-empty string, got {base!r}")
        name, k = base, 1
        while name in names or name == "contact":
            k += 1
            name = f"{base}_{k}"
        names.add(name)
        out.append(UserContribution(obj, nodes, name, _what(i, obj)))
    return out


class UserContribution(Contribution):
    """A checked user contribution: the object's own methods, the protocol's defaults for the
    missing ones; ``evaluate`` checks the blocks it returns (type, tangent, nodes)."""

    def __init__(self, obj, nodes, name, what):
        self.obj, self.nodes, self.name, self.what = obj, nodes, name, what
        self.smooth = bool(getattr(obj, "smooth", True))
        self.conservative = bool(getattr(obj, "conservative", True))
        for method in LIFE_CYCLE:
            if hasattr(obj, method):
                setattr(self, method, getattr(obj, method))

    def evaluate(self, H, tangent=True):
        out = self.obj.evaluate(H, tangent)
        blocks, info = out if isinstance(out, tuple) and len(out) == 2 else (out, {})
        if not isinstance(blocks, Blocks):
            raise InputError(f"{self.what}: evaluate must return blocks.Blocks (or (Blocks, info)), "
                             f"got {type(blocks).__name__}")
        if tangent and blocks.K is None:
            raise InputError(f"{self.what}: evaluate(H, tangent=True) returned blocks without K")
        outside = np.setdiff1d(np.asarray(blocks.nodes).ravel(), self.nodes)
        if len(outside):
            raise InputError(f"{self.what}: its blocks use node {int(outside[0])}, not one of its nodes")
        return blocks, info
