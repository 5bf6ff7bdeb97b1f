"""Mortar friction: nodal tangential multipliers on the slave beam (docs/theory_mortar.md).

Per slave Gauss point ``p`` (line and orthogonal pairs; point pairs keep the point law) the
seed's slip increment ``s_p = (dy[1], dy[2])``, ``dy = log(H_LK_prev^-1 H_LK)`` (``kernel_jit``), is
carried as the global vector ``S_p = s_p1 t1 + s_p2 t2``.  A group ``g`` is one slave node ``j``
against one master beam; with the linear slave shape functions ``Phi_j`` (``1 - xi1`` at node A,
``xi1`` at node B) and the point weights ``w_p`` (length):

- nodal weight ``m_g = int Phi_j ds`` over the slave elements around the node, weighted slip ``u_g = sum_p Phi_j w_p S_p / m_g``,
  weighted normal traction ``lamN_g = sum_p Phi_j w_p lamN_p / m_g``;
- trial ``lam*_g = R_j Lam_g + eps u_g`` (``Lam_g``: the step's multiplier in the section frame of
  node ``j``, ``R_j`` its current rotation; ``eps``: force / length^2), Coulomb return mapping onto
  the disk ``mu lamN_g``: ``lam_g``;
- traction at a point ``T_p = sum_j Phi_j(p) lam_g`` (global, force per length), applied by its
  tangential part ``T_p - (T_p . n) n`` at the contour points like the point law.

Augmented-Lagrangian updates ``Lam_g <- R_j^T lam_g`` repeat the step until every sticking group's
``|u_g|`` is below the tolerance (``ContactSystem.augment``).  All functions are batched numpy; the
point terms come from the compiled kernel (``kernel_jit.mortar_terms``); the complex-step numpy forms
(``reference.mortar_point_friction``, ``mortar_point_derivatives``) are their oracle.  The points' rows go
to their groups by compiled scatters (``mortar_jit``; ``use_numpy_scatter``: their ``np.add.at`` oracle);
``Groups`` keeps the groups while a Newton step's pairs hold.
"""
import numpy as np

from ..lie import se3
from ..model.buffers import BufferPool, equal
from . import mortar_jit

__all__ = ["groups", "Groups", "return_mapping", "nodal_state", "multiplier_basis", "group_forces", "blocks",
           "multiplier_blocks", "branch_rows"]

# the scatters of the points' rows into their groups: compiled (``mortar_jit``), or their numpy oracle
_COMPILED = dict(rows=mortar_jit.scatter_rows, block=mortar_jit.scatter_block, columns=mortar_jit.scatter_columns)
_NUMPY = dict(rows=mortar_jit.scatter_rows_numpy, block=mortar_jit.scatter_block_numpy,
              columns=mortar_jit.scatter_columns_numpy)
_SCATTER = dict(_COMPILED)


def use_numpy_scatter(flag=True):
    """The numpy oracle of the scatters (``np.add.at``) instead of the compiled ones (tests, benchmarks)."""
    _SCATTER.update(_NUMPY if flag else _COMPILED)


def _held_moved(slave_nodes, held):
    """The points' slave nodes with a held node moved to its neighbour (``groups``)."""
    if held is None:
        return slave_nodes
    slave_nodes = slave_nodes.copy()
    hA, hB = held[:, 0], held[:, 1]
    slave_nodes[hA & ~hB, 0] = slave_nodes[hA & ~hB, 1]
    slave_nodes[hB & ~hA, 1] = slave_nodes[hB & ~hA, 0]
    return slave_nodes


def fold_of(slave_nodes, xi1, master_beam, decl, n_nodes, n_beams, held=None, base=None):
    """``slivers`` of the groups ``groups`` makes from these arguments (``base``: their ``_sliver_base`` if kept)."""
    sn, key, order = _sliver_base(slave_nodes, master_beam, decl, n_nodes, n_beams, held) if base is None else base
    if SLIVER is not None and _SCATTER["rows"] is mortar_jit.scatter_rows:
        if not order:            # compiled, the same flags (``slivers`` its oracle)
            order.append(mortar_jit.sliver_groups(key))
        return mortar_jit.slivers(key, sn, xi1, SLIVER, order[0])
    return slivers(key, sn, xi1)


def _sliver_base(slave_nodes, master_beam, decl, n_nodes, n_beams, held):
    """``(sn, key, order)`` of ``fold_of``, what does not follow ``xi1``: the slave nodes with held ones moved, the
    keys ``(P, 2)`` and ``[mortar_jit.sliver_groups(key)]`` (a list filled at the first compiled ``fold_of``)."""
    sn = np.array(_held_moved(slave_nodes, held))      # (its own: ``Groups`` keeps it)
    key = (np.asarray(decl, dtype=np.int64)[:, None] * n_nodes + sn) * n_beams + master_beam[:, None]
    return sn, key, []


def groups(slave_nodes, xi1, master_beam, decl, nodes, n_nodes, n_beams, held=None, fold=None, full=True):
    """Nodal groups (one slave node against one master beam) of ``P`` points.

    ``held`` ``(P, 2)``: whether the point's slave node A, B has a prescribed slip (every increment
    fixed, or joined to a node of the master element: they move as one body).  Their slip is given, so a multiplier there would be redundant (an element between a held node and a
    sliding one could not stick: Uzawa updates grow without bound); as in the boundary
    modification of mortar multiplier spaces (Wohlmuth 2000), the hat of a held node is added to
    its neighbour's in the element, whose multiplier then spans the whole element.

    ``slave_nodes`` ``(P, 2)``: the slave element's nodes A, B; ``xi1`` ``(P,)``; ``nodes`` ``(P, 4)``:
    the pairs' nodes.  Returns a dict: ``key`` ``(G,)`` (``(decl n_nodes + node) n_beams + beam``,
    sorted), ``node`` ``(G,)``, ``g`` ``(P, 2)`` the groups of each point's nodes A and B, ``phi`` ``(P, 2)``
    the shape functions, ``members`` ``(G, k)`` the nodes of each group (padded with its first node)
    and ``pos`` ``(P, 2, 4)`` the slot of each pair node in the group of its node A and B.  Sliver groups
    (``slivers``; ``fold`` ``(P, 2)`` if already known) are folded into their neighbour as held nodes are.
    ``full`` False: ``key``, ``node``, ``g`` and ``phi`` only (the groups' state, ``nodal_state``; not the members and
    slots the forces and tangents scatter by: a commit's, ``ContactSystem._commit_mortar``).
    """
    P = len(xi1)
    slave_nodes = _held_moved(slave_nodes, held)
    key = (np.asarray(decl, dtype=np.int64)[:, None] * n_nodes + slave_nodes) * n_beams + master_beam[:, None]
    if fold is None:
        fold = slivers(key, slave_nodes, xi1)
    if fold.any():
        slave_nodes = slave_nodes.copy()
        slave_nodes[fold] = slave_nodes[:, ::-1][fold]
        key = (np.asarray(decl, dtype=np.int64)[:, None] * n_nodes + slave_nodes) * n_beams + master_beam[:, None]
    ukey, g = np.unique(key.ravel(), return_inverse=True)
    g = g.reshape(P, 2)
    node = (ukey // n_beams) % n_nodes
    if not full:
        return dict(key=ukey, node=node, g=np.ascontiguousarray(g, dtype=np.int64),
                    phi=_shape_functions(xi1))
    # the nodes of each group: every pair node of every member point
    gn = np.repeat(g[:, :, None], 4, axis=2)                       # (P, 2, 4)
    nn = np.repeat(nodes[:, None, :], 2, axis=1)
    gk = gn.astype(np.int64) * n_nodes + nn
    u, inv = np.unique(gk.ravel(), return_inverse=True)
    ug = u // n_nodes
    first = np.searchsorted(ug, np.arange(len(ukey)))
    slot = np.arange(len(u)) - first[ug]
    k = max(4, int(slot.max(initial=0)) + 1)
    members = np.repeat(node[:, None], k, axis=1)
    members[ug, slot] = u % n_nodes
    pos = slot[inv].reshape(P, 2, 4)
    rows2 = (6 * pos[:, :, :, None] + np.arange(6)).reshape(P, 2, 24)
    g = np.ascontiguousarray(g, dtype=np.int64)
    # kept with the groups (``Groups``): the points' slots and rows (``_slots``, ``_slot_rows``: one copy of the
    # (2, P, 24) rows, 79 MB at the commit pass's 206 000 points of the 61-wire strand) and the columns of each group's
    # own node rotation (``_turn``)
    own = np.argmax(members == node[:, None], axis=1)
    slot_rows = np.ascontiguousarray(rows2.transpose(1, 0, 2))
    return dict(key=ukey, node=node, g=g, phi=_shape_functions(xi1), members=members, pos=pos,
                slot_groups=np.ascontiguousarray(g.T), slot_rows=slot_rows,
                rot=6 * own[:, None] + np.arange(3, 6))


SLIVER = 0.25    # a group on one slave element whose shape functions sum to less than this times its partner's there
                 # is folded into it (``slivers``; None: never, as before session 7)


def slivers(key, slave_nodes, xi1):
    """``(P, 2)`` bool: the points' nodes whose group (``key`` ``(P, 2)``) is a sliver, folded into the other node's
    group of the element (the boundary modification of ``groups``' held nodes).  A sliver has its points on one slave
    element and there sums its shape functions to less than ``SLIVER`` times its partner's (a node whose support
    meets this master beam at the end of the element only: the plectoneme's slave node next to a joint of the master's
    pieces, one Gauss point with ``Phi = 0.047``), or both have the same single point (then the smaller one folds): its
    multiplier acts through the partner's points only, 20 times weaker, and when both stick their weighted slips are
    the same constraint (a singular saddle system: Newton steps of the multiplier of 1e22)."""
    P = len(xi1)
    fold = np.zeros((P, 2), dtype=bool)
    if P == 0 or SLIVER is None:
        return fold
    phi = np.stack([1.0 - xi1, xi1], axis=1)
    own = np.repeat(key[:, 0] != key[:, 1], 2)          # (a point of a held node's element counts wholly)
    k, part = key.ravel(), key[:, ::-1].ravel()
    f, fp = phi.ravel(), phi[:, ::-1].ravel()
    elem = np.repeat(slave_nodes[:, 0] * np.int64(slave_nodes.max() + 1) + slave_nodes[:, 1], 2)
    uk, first, inv = np.unique(k, return_index=True, return_inverse=True)
    n = len(uk)
    one_elem = np.bincount(inv, weights=elem != elem[first][inv], minlength=n) == 0
    whole = np.bincount(inv, weights=~own, minlength=n) > 0
    s_own = np.bincount(inv, weights=f, minlength=n)
    s_part = np.bincount(inv, weights=fp, minlength=n)
    npts = np.bincount(inv, minlength=n)
    pk = np.zeros(n, dtype=np.int64)          # the partner (every point of a one-element group has the same one)
    pk[inv] = part
    j = np.searchsorted(uk, pk)
    p_npts = npts[j]
    b_side = np.zeros(n, dtype=bool)
    b_side[inv] = np.tile([False, True], P)
    single = (npts == 1) & (p_npts == 1) & ((s_own < s_part) | ((s_own == s_part) & b_side))
    sliver = one_elem & ~whole & ((s_own < SLIVER * s_part) | single)
    return sliver[inv].reshape(P, 2) & own.reshape(P, 2)


class Groups:
    """``groups`` kept between evaluations while the points' nodes, master beams, declarations, held flags and
    sliver folds are those of the last call (the pairs of a Newton step): then only the shape functions ``phi`` follow
    ``xi1`` (two ``np.unique`` and a sort less per evaluation).  The arrays returned are shared between
    the calls that reuse them: read them only."""

    def __init__(self):
        self._last = None
        self.builds = 0          # ``groups`` calls (tests)

    def __call__(self, slave_nodes, xi1, master_beam, decl, nodes, n_nodes, n_beams, held=None, full=True):
        """``groups(...)`` (``full``: as there; kept without the members, a call asking for them builds them).
        The sliver folds' keys and their sort are kept with the pairs too (``_sliver_base``)."""
        last = self._last
        args = (slave_nodes, master_beam, decl, nodes, held)
        same = last is not None and last[0] == (n_nodes, n_beams) and _same_args(last[1][:5], args)
        base = last[3] if same else _sliver_base(slave_nodes, master_beam, decl, n_nodes, n_beams, held)
        fold = fold_of(slave_nodes, xi1, master_beam, decl, n_nodes, n_beams, held, base=base)
        if same and ("members" in last[2] or not full) and equal(last[1][5], fold):
            return dict(last[2], phi=_shape_functions(xi1))
        G = groups(slave_nodes, xi1, master_beam, decl, nodes, n_nodes, n_beams, held, fold, full)
        self._last = ((n_nodes, n_beams), tuple(None if a is None else np.array(a) for a in args + (fold,)), G, base)
        self.builds += 1
        return G


def _same_args(kept, args):
    """Whether the arrays (or Nones) ``args`` equal the ``kept`` ones, pair by pair (``Groups``)."""
    for a, b in zip(kept, args):
        if (a is None) != (b is None) or (a is not None and not equal(a, b)):
            return False
    return True


def _shape_functions(xi1):
    """``Phi`` ``(P, 2)``: ``1 - xi1`` and ``xi1`` (``np.stack([1.0 - xi1, xi1], axis=1)``, one array filled)."""
    phi = np.empty((len(xi1), 2))
    phi[:, 0] = 1.0 - xi1
    phi[:, 1] = xi1
    return phi


def return_mapping(trial, cap):
    """Coulomb return mapping of ``(G, 3)`` trial tractions onto the disk ``cap`` ``(G,)``.

    Returns ``lam``, ``stick``, ``C`` ``(G, 3, 3)`` = d lam / d trial and ``c`` ``(G, 3)`` = d lam / d cap.
    """
    norm = np.linalg.norm(trial, axis=1)
    stick = (norm <= cap) & (cap > 0.0)        # no capacity: no traction (not a stick of zero width)
    safe = np.where(stick | (norm == 0.0), 1.0, norm)
    t = trial / safe[:, None]
    C = np.where(stick[:, None, None], np.eye(3),
                 (cap / safe)[:, None, None] * (np.eye(3) - t[:, :, None] * t[:, None, :]))
    lam = np.where(stick[:, None], trial, cap[:, None] * t)
    c = np.where(stick[:, None], 0.0, t)
    return lam, stick, C, c


def nodal_state(G, w, S, lam_n, n, R, Lam, eps, mu, m, active=None, hold=None, RL=None):
    """Nodal weighted slip, normal traction and multipliers of the groups ``G`` (``groups``).

    ``w`` ``(P,)`` point weights, ``S`` ``(P, 3)`` slips, ``lam_n`` ``(P,)``, ``n`` ``(P, 3)`` normals; per group:
    the nodal normal ``nu = nbar / |nbar|``, ``nbar = sum_p Phi_j w_p n_p / m_j``, whose projector ``Pi = I - nu nu^T``
    keeps the trial ``Pi (R Lam + eps u)`` and the slip ``Pi u`` tangential (the points' tangent planes
    differ along a curved contact line: a normal part could not be held by their tractions); ``R`` ``(n, 3, 3)``
    the slave node's rotation, ``Lam`` ``(n, 3)`` the step's multiplier in that frame, ``eps`` and
    ``mu`` ``(n,)``; ``m`` ``(n,)`` the nodal weights ``int Phi_j ds`` over the whole slave elements around the
    node, in or out of contact (constant: a point entering contact with zero slip and traction changes
    nothing, where a weight over the active points would jump); ``active`` ``(P,)``: the points whose
    slip counts (where the traction acts; the mean normal takes every point).  Returns a dict with ``m``, ``u`` (projected), ``lamN``, ``trial``, ``lam``, ``stick``,
    ``C``, ``c``, ``Pi``, ``Q`` (d trial / d nbar) per group and the point tractions ``T`` ``(P, 3)``.
    Compiled (``mortar_jit.nodal_state``: the same sums in the same order); ``use_numpy_scatter``: the numpy form.
    ``RL``: ``np.einsum("gij,gj->gi", R, Lam)`` if the caller has it.
    """
    if _SCATTER["rows"] is mortar_jit.scatter_rows:
        st = mortar_jit.nodal_state(G["g"], G["phi"], w, active, S, lam_n, n,
                                    np.einsum("gij,gj->gi", R, Lam) if RL is None else RL, eps, mu, m, hold)
        st["u"] = st.pop("up")
        st["m"] = m
        return st
    return nodal_state_numpy(G, w, S, lam_n, n, R, Lam, eps, mu, m, active, hold)


def nodal_state_numpy(G, w, S, lam_n, n, R, Lam, eps, mu, m, active=None, hold=None):
    """``nodal_state`` in numpy (its oracle)."""
    k = len(G["key"])
    wn = G["phi"] * w[:, None]
    wphi = wn if active is None else wn * active[:, None]
    u = np.stack([np.bincount(G["g"].ravel(), weights=(wphi[:, :, None] * S[:, None, :])[..., i].ravel(),
                              minlength=k) for i in range(3)], axis=1) / m[:, None]
    lamN = np.bincount(G["g"].ravel(), weights=(wphi * lam_n[:, None]).ravel(), minlength=k) / m
    nbar = np.stack([np.bincount(G["g"].ravel(), weights=(wn[:, :, None] * n[:, None, :])[..., i].ravel(),
                                 minlength=len(m)) for i in range(3)], axis=1) / m[:, None]
    size = np.linalg.norm(nbar, axis=1)
    nu = nbar / size[:, None]
    Pi = np.eye(3) - nu[:, :, None] * nu[:, None, :]
    v = np.einsum("gij,gj->gi", R, Lam) + eps[:, None] * u
    trial = np.einsum("gij,gj->gi", Pi, v)
    # d trial = Pi dv + Q dnbar, Q = -((nu . v) Pi + nu (Pi v)^T) / |nbar|
    Q = -(np.sum(nu * v, axis=1)[:, None, None] * Pi + nu[:, :, None] * trial[:, None, :]) / size[:, None, None]
    lam, stick, C, c = return_mapping(trial, mu * np.maximum(lamN, 0.0))
    if hold is not None:
        # touching without normal traction (``hold`` (n,) > 0 where a point lies in the normal law's band):
        # no traction and any slip solve the law, a mechanism Newton cannot factorise (a wire laid on a rod
        # before its load).  Their tangent holds with the stiffness ``hold``, as the point law's stiffness
        # floor does (``law.PENALTY_T_MIN``); the residual keeps their traction at zero.
        weak = (hold > 0) & (lamN <= 0.0)
        C = np.where(weak[:, None, None], (hold / eps)[:, None, None] * np.eye(3), C)
        c = np.where(weak[:, None], 0.0, c)
    else:
        weak = np.zeros(k, dtype=bool)
    T = np.einsum("pa,pai->pi", G["phi"], lam[G["g"]])
    return dict(m=m, u=np.einsum("gij,gj->gi", Pi, u), lamN=lamN, trial=trial, lam=lam, stick=stick, C=C, c=c,
                T=T, wphi=wphi, wn=wn, Pi=Pi, Q=Q, weak=weak, nu=nu)


def multiplier_basis(st):
    """``(G, 3, 3)`` orthonormal columns ``[nu, e1, e2]`` per group (``st``: ``nodal_state``) in which the
    complementarity function's derivative ``dC/dv = I - M_P Pi`` is diagonal (``nonlinear.condense``):
    ``diag(1, 0, 0)`` sticking, ``diag(1, 1, 1 - mu lamN / |trial|)`` sliding with ``e1`` along the trial,
    ``I`` without pressure.  Otherwise ``e1`` is the global axis least aligned with ``nu`` projected on the
    tangent plane (a scene held in a plane keeps its normal axis as a component, whose row is idle).  Compiled
    (``mortar_jit.multiplier_basis``); ``use_numpy_scatter``: this numpy form."""
    if _SCATTER["rows"] is mortar_jit.scatter_rows:
        return mortar_jit.multiplier_basis(st["nu"], st["trial"], st["stick"], st["weak"])
    nu = st["nu"]
    a = np.argmin(np.abs(nu), axis=1)
    e1 = -nu[np.arange(len(nu)), a][:, None] * nu
    e1[np.arange(len(nu)), a] += 1.0
    trial = st["trial"]
    norm = np.linalg.norm(trial, axis=1)
    slide = ~st["stick"] & ~st["weak"] & (norm > 0.0)
    e1 = np.where(slide[:, None], trial, e1)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    return np.stack([nu, e1, np.cross(nu, e1)], axis=2)


def _slots(G, a):
    """Group of each point's node ``a`` (0: A, 1: B) and the point's 24 rows in that group's block."""
    if "slot_rows" in G:
        return G["slot_groups"][a], G["slot_rows"][a]
    P = len(G["g"])
    return G["g"][:, a], (6 * G["pos"][:, a, :, None] + np.arange(6)).reshape(P, 24)


def group_forces(G, f_points):
    """The points' forces ``(P, 24)`` on the groups of their node A, ``(n, 6 k)`` (rows over the group's slots)."""
    n, k = G["members"].shape
    gA, rowsA = _slots(G, 0)
    return _SCATTER["rows"](np.zeros((n, 6 * k)), gA, rowsA, f_points)


def add_pairs(G, f, K, fp, Kp):
    """Add the points' own blocks (``fp`` ``(P, 24)``, ``Kp`` ``(P, 24, 24)`` or None: the normal law's, residual
    signs) to the groups of their node A (``f`` ``(n, 6 k)``, ``K`` ``(n, 6 k, 6 k)``, in place): one set of blocks
    for both (the 19-wire bundle: the pairs' blocks, padded to the groups' ``6 k`` rows, cost 0.6 s to copy and
    as much to assemble)."""
    gA, rowsA = _slots(G, 0)
    _SCATTER["rows"](f, gA, rowsA, fp)
    if K is not None and Kp is not None:
        _SCATTER["block"](K, gA, rowsA, Kp)


_KPOOL = BufferPool()       # the groups' tangent blocks (fresh (n, 6 k, 6 k) memory's page faults: 0.2 s on 19 wires)


def _zero_blocks(shape):
    K = _KPOOL.take(shape)
    K.fill(0.0)
    return K


def block_sink(G):
    """``(K, sink)``: the groups' tangent blocks ``K`` ``(n, 6 k, 6 k)``, zero, and ``sink(a, b, dfdq)``, which adds
    the points ``a .. b - 1``'s tangents ``(b - a, 24, 24)`` to the groups of their node A as ``_point_parts``
    does (``kernel_jit.mortar_terms(sink=)``: pass by pass, in the points' order, the same sums); ``d["Kqq"] = K``
    then stands for ``d["dfdq"]``."""
    n, k = G["members"].shape
    gA, rowsA = _slots(G, 0)
    K = _zero_blocks((n, 6 * k, 6 * k))

    def sink(a, b, vals):
        _SCATTER["block"](K, gA[a:b], rowsA[a:b], vals)
    return K, sink


def _point_parts(G, d):
    """Point forces and their derivatives at fixed traction on the groups of the points' node A:
    ``f`` ``(n, 6 k)``, ``K`` ``(n, 6 k, 6 k)``; and ``A`` ``(n, 6 k, 3)`` = d f / d lam_g (the forces of
    the interpolated tractions: ``A_g = sum_p Phi_j(p) df_p/dT``, rows over the group's slots).  ``d["Kqq"]``
    (``block_sink``): ``K`` scattered already."""
    n, k = G["members"].shape
    gA, rowsA = _slots(G, 0)
    f = group_forces(G, d["f"])
    K = d.pop("Kqq") if "Kqq" in d else _SCATTER["block"](_zero_blocks((n, 6 * k, 6 * k)), gA, rowsA, d["dfdq"])
    A = np.zeros((n, 6 * k, 3))
    for a in range(2):
        g, rows = _slots(G, a)
        _SCATTER["rows"](A, g, rows, d["G"], G["phi"][:, a])
    return f, K, A


def _trial_rows(G, d, st, eps, mu):
    """``d lam_g / d q`` ``(n, 3, 6 k)`` through the points (slips, normals, normal tractions), without the
    turn of the node's frame: ``C (Pi eps du + Q dnbar) + c mu dlamN`` (compiled: ``mortar_jit.trial_rows``;
    ``use_numpy_scatter``: the numpy form)."""
    n, k = G["members"].shape
    B = np.zeros((n, 3, 6 * k))
    if _SCATTER["rows"] is mortar_jit.scatter_rows:
        return mortar_jit.trial_rows(B, G["g"], _slot_rows(G), st["wphi"], st["wn"], st["m"], eps, mu, st["Pi"],
                                     st["Q"], st["C"], st["c"], d["dS"], d["dn"], d["dlam_n"])
    for a in range(2):
        g, rows = _slots(G, a)
        wg, wgn = st["wphi"][:, a] / st["m"][g], st["wn"][:, a] / st["m"][g]
        dtrial = (eps[g] * wg)[:, None, None] * np.einsum("pij,pjq->piq", st["Pi"][g], d["dS"]) + \
            wgn[:, None, None] * np.einsum("pij,pjq->piq", st["Q"][g], d["dn"])
        dlam = np.einsum("pij,pjq->piq", st["C"][g], dtrial) + \
            (mu[g] * wg)[:, None, None] * st["c"][g][:, :, None] * d["dlam_n"][:, None, :]
        _SCATTER["columns"](B, g, rows, dlam)
    return B


def _slot_rows(G):
    """``(2, P, 24)``: the points' rows in the groups of their node A, B (``_slots``, both at once)."""
    if "slot_rows" in G:
        return G["slot_rows"]
    return (6 * G["pos"].transpose(1, 0, 2)[:, :, :, None] + np.arange(6)).reshape(2, len(G["g"]), 24)


def _turn(G, R, Lam):
    """Columns ``(n, 3)`` of the node's rotation increment in each group's block and ``d(R Lam) / dtheta``
    ``(n, 3, 3)`` = ``-R hat(Lam)`` (body increment of the node)."""
    if "rot" in G:
        cols = G["rot"]
    else:
        own = np.argmax(G["members"] == G["node"][:, None], axis=1)
        cols = 6 * own[:, None] + np.arange(3, 6)
    if _SCATTER["rows"] is mortar_jit.scatter_rows and R.flags.c_contiguous:
        return cols, mortar_jit.turn(R, Lam)      # (compiled: einsum's bits on a contiguous R)
    return cols, -np.einsum("gij,gjk->gik", R, se3.skew(Lam))


def _add_columns(M, cols, V):
    """``M[g][:, cols[g]] += V[g]`` for ``M`` ``(n, r, c)``, ``cols`` ``(n, 3)``, ``V`` ``(n, r, 3)``."""
    _SCATTER["columns"](M, np.arange(len(M)), cols, V)


def blocks(G, d, st, R, Lam, eps, mu):
    """Friction force and tangent blocks over the groups' nodes ``G["members"]`` ``(n, k)``.

    ``d``: ``point_derivatives`` at the point tractions ``st["T"]``; ``st``: ``nodal_state``.
    Returns ``f`` ``(n, 6 k)`` and ``K`` ``(n, 6 k, 6 k)`` (``d f / d q``): the point forces and
    their derivatives at fixed traction go to the group of the point's node A; the traction's
    dependence on the slips, normal tractions and node rotation of a group couples every node of
    it: ``K_g += A_g B_g``, ``A_g = sum_p Phi_j(p) df_p/dT`` (rows over the group's slots, which hold
    every member point's nodes) and ``B_g = d lam_g / d q``.
    """
    f, K, A = _point_parts(G, d)
    # d lam_g / d q = C (Pi (eps du + d(R Lam)) + Q dnbar) + c mu dlamN, rows over the group's slots
    B = _trial_rows(G, d, st, eps, mu)
    rot, dR = _turn(G, R, Lam)
    _add_columns(B, rot, np.einsum("gij,gjk,gkl->gil", st["C"], st["Pi"], dR))
    K += A @ B
    return f, K


def multiplier_blocks(G, d, st, R, Lam, c, mu, turn=None):
    """Semi-smooth Newton blocks of the nodal multipliers ``Lam`` ``(n, 3)`` (section frame of the node; the
    traction is ``v = R Lam``) with the complementarity function ``C = v - P(Pi (v + c u))`` (``P`` the
    return mapping onto the disk ``mu lamN``; ``d``: point terms at the tractions ``T_p = sum Phi_j v_j``,
    ``st``: ``nodal_state`` with ``eps = c``).

    Returns ``f`` ``(n, 6 k)`` (contact forces), ``Kqq`` ``(n, 6 k, 6 k)`` = d f / d q at fixed ``Lam``,
    ``Kql`` ``(n, 6 k, 3)`` = d f / d Lam, ``Klq`` ``(n, 3, 6 k)`` = d C / d q, ``Kll`` ``(n, 3, 3)`` = d C / d Lam
    and ``C`` ``(n, 3)``.  Sticking: ``C = nu nu^T v - c Pi u`` (no slip, no normal part); sliding:
    ``C = v - mu lamN t``.  ``turn``: ``_turn(G, R, Lam)`` if known.
    """
    f, Kqq, A = _point_parts(G, d)
    rot, dv = _turn(G, R, Lam) if turn is None else turn
    _add_columns(Kqq, rot, A @ dv)
    Kql = A @ R
    weak = st["weak"]
    MP = mortar_jit.products(st["C"], st["Pi"])                  # d P / d v (einsum's bits)
    B = _trial_rows(G, d, st, c, mu)
    # a touching group without normal traction: C = v exactly (its traction goes to zero in one step); the
    # hold stiffness acts on its slip in the displacement rows only, a tangent-only term like the point law's
    # floor (putting it in d C / d v made the multiplier overshoot and the residual stall: twisted pair)
    if weak.any():
        Kqq[weak] += A[weak] @ B[weak]
        B[weak] = 0.0
        MP[weak] = 0.0
    Klq = np.negative(B, out=B)         # (in place: B is not used again; a fresh (n, 3, 6 k) array's page faults)
    _add_columns(Klq, rot, dv - MP @ dv)
    Kll = R - MP @ R
    v = mortar_jit.rotate(R, Lam)
    return f, Kqq, Kql, Klq, Kll, v - st["lam"]


def branch_rows(G, d, st, R, Lam, c, mu, turn=None):
    """The linearisation of the groups' trial tractions and disks (the active-set inner loop of Newton's direction,
    ``nonlinear.problem.Problem.branch_rows``): ``Tq`` ``(n, 3, 6 k)`` = d trial / d q (the node's turn of ``R Lam``
    included), ``Vq`` ``(n, 3, 6 k)`` = d (R Lam) / d q (the turn's columns only) and ``capq`` ``(n, 6 k)`` =
    d (mu lamN) / d q, rows over the groups' slots (``st``: ``nodal_state`` with ``eps = c``; ``turn``: ``_turn(G, R,
    Lam)`` if known)."""
    n, k = G["members"].shape
    if _SCATTER["rows"] is mortar_jit.scatter_rows:     # both in one pass (the same sums, no zero products)
        Tq, capq = mortar_jit.branch_rows(np.zeros((n, 3, 6 * k)), np.zeros((n, 6 * k)), G["g"], _slot_rows(G),
                                          st["wphi"], st["wn"], st["m"], c, mu, st["Pi"], st["Q"], d["dS"], d["dn"],
                                          d["dlam_n"])
    else:
        eye = dict(st, C=np.ascontiguousarray(np.broadcast_to(np.eye(3), (n, 3, 3))), c=np.zeros((n, 3)))
        Tq = _trial_rows(G, d, eye, c, mu)
        e = np.zeros((n, 3))
        e[:, 0] = 1.0
        capq = _trial_rows(G, d, dict(st, C=np.zeros((n, 3, 3)), c=e), c, mu)[:, 0, :].copy()
    rot, dv = _turn(G, R, Lam) if turn is None else turn
    Vq = np.zeros((n, 3, 6 * k))
    _add_columns(Vq, rot, dv)
    _add_columns(Tq, rot, mortar_jit.products(st["Pi"], dv))
    return Tq, Vq, capq
