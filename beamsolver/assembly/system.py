"""DOF map, CSR/CSC pattern built once, vectorised scatter of element arrays.

Unknowns (``z``) are six per *representative* node (``6 * node + k``):

- free and prescribed nodes: body increments, ``H <- H exp(hat(z))``;
- nodes with a partial ``fix``: global increments ``(dx, dtheta)``,
  ``x <- x + dx``, ``R <- exp(dtheta) R``, so that fixed global directions are
  single unknowns; their body increments are ``q = M z`` with
  ``M = diag(R^T, R^T)``;
- a node joined to a representative has no unknowns of its own:
  ``H_i = H_rep X_i`` with a constant ``X_i``, so ``q_i = Ad(X_i^-1) M_rep z_rep``.

Residual and tangent in ``z`` are ``M^T r`` and ``M^T K M``, plus for the
global-type nodes the term ``[[0, -hat(r_u)], [0, -hat(r_w)]]`` from the
dependence of ``M`` on ``R`` (``r`` in global components), which keeps Newton
quadratic.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from . import compiled as assembly_jit
from ..model import contributions
from ..elements import line_load
from ..lie import se3, se3_twin
from ..model import blocks as _blocks
from ..model.buffers import equal
from ..errors import InputError
from .csc import canonical_csc
from .extra_pattern import BlockPattern, ExtraPattern, whole_nodes
from . import held_pattern as held_pattern_
from .held_pattern import HeldPattern
from ..lie.se3 import skew
from ..model.validation import check_pose

__all__ = ["System", "FREE", "GLOBAL", "CLAMPED", "PRESCRIBED"]

FREE, GLOBAL, CLAMPED, PRESCRIBED = 0, 1, 2, 3
HOLD_PATTERN = "auto"        # System.hold_pattern's default: True, False or "auto" (``HOLD_MIN_UNKNOWNS``)
HOLD_MIN_UNKNOWNS = 1_500    # "auto": a held pattern from this size (linsolve's PARDISO size: its analysis reused)
# rank tolerance of the rigid-mode check: the constraint rows mix unit rotations with lever arms
# in units of the group's size (``_rigid_mode_rank``), so entries are O(1)
RIGID_MODE_TOL = 1e-9


def _rigid_mode_rank(x, fixed):
    """Number of independent rigid-body modes of a group of nodes that ``fixed`` constrains.

    ``x``: ``(k, 3)`` node positions, ``fixed``: ``(k, 6)`` fixed global increments.  A rigid
    mode is ``u = a + theta x (x - c)``, ``w = theta``; positions are taken about the group's
    centroid ``c`` and in units of its size, so the rank is the same in any
    unit system and anywhere in space (tolerance ``RIGID_MODE_TOL``).
    """
    if not fixed.any():
        return 0
    c = x.mean(axis=0)
    size = float(np.ptp(x, axis=0).max()) if len(x) > 1 else 0.0
    d = (x - c) / (size if size > 0.0 else 1.0)
    G = np.zeros((len(x), 6, 6))
    G[:, :3, :3] = np.eye(3)
    G[:, :3, 3:] = -skew(d)
    G[:, 3:, 3:] = np.eye(3)
    return int(np.linalg.matrix_rank(G[fixed], tol=RIGID_MODE_TOL))


def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


DENSE_KEYS = 1 << 16        # unique_inverse marks keys in a dense table up to this bound (or 16 per key)


def unique_inverse(key, bound):
    """``np.unique(key, return_inverse=True)`` for integer keys in ``[0, bound)``; for a small
    ``bound`` by a dense table of the keys present (no sort)."""
    if bound > max(DENSE_KEYS, 16 * len(key)):
        return np.unique(key, return_inverse=True)
    present = np.zeros(bound, dtype=bool)
    present[key] = True
    return np.flatnonzero(present), (np.cumsum(present) - 1)[key]


def beams_anchored(model, kind):
    """The rigid-mode check's exact shortcut: without joins, contact or nodes outside beams the
    connected groups are the beams (a beam's elements chain all its nodes), and a beam with a
    clamped or prescribed node has no free rigid-body mode."""
    if model.joins or model.contacts or model.free_nodes:
        return False
    anchored = (kind == CLAMPED) | (kind == PRESCRIBED)
    return all(anchored[b.nodes].any() for b in model.beams)


def _representatives(n, joins, cons, group_constraint):
    """Representative node of every node ``(n,)``: joined groups merged by union-find, the
    constrained node of a group (``group_constraint``) chosen as its representative."""
    if not joins:
        return np.arange(n)
    parent = list(range(n))
    for a, b in joins:
        ra, rb = _find(parent, a), _find(parent, b)
        if ra == rb:
            continue
        # the constrained node of a group becomes its representative
        ca, cb = group_constraint(parent, ra, cons), group_constraint(parent, rb, cons)
        if ca is not None and cb is not None:
            raise InputError(f"join({a}, {b}): both joined groups carry constraints "
                             f"(nodes {ca} and {cb}); constrain only one node of a joint")
        if cb is not None:
            parent[ra] = rb
        else:
            parent[rb] = ra
    return np.array([_find(parent, i) for i in range(n)])




class System:
    """Compiled, validated model: DOF map, element table, load arrays, sparse pattern."""

    def __init__(self, model, check_rigid_modes=True):
        if not model.beams:
            raise InputError("Model: no beams were added")
        self.model = model
        self.hold_pattern = HOLD_PATTERN
        n = model.n_nodes
        self.n_nodes = n
        self.groups = model.element_groups()          # one per element type (model.ElementGroup)
        self.enodes, self.L, self.eps0, self.C = model.element_table(self.groups)   # end nodes (n_el, 2)
        self.C = np.ascontiguousarray(self.C, dtype=float)
        self.C_diagonal = bool(not np.any(self.C[:, ~np.eye(6, dtype=bool)]))
        self.n_elements = len(self.L)
        self._build_rotation_pairs()
        self.poses0 = model.poses0
        self.length_scale = model.characteristic_length()
        self._build_reps(model)
        self._build_loads(model)
        self._build_pattern()
        self._place_line_loads()
        self._build_chains(model)
        if check_rigid_modes:
            self._check_rigid_modes(model)

    # ------------------------------------------------------------ chains
    def _build_chains(self, model):
        """Cantilever beams: one end clamped/prescribed, nothing else attached.

        Their Newton updates are applied in strain space (``h_e <- h_e + B_e dq``,
        poses re-chained from the anchored end), a retraction that agrees with
        ``H exp(dq)`` to first order (so Newton stays quadratic) but carries no
        axial overshoot: a constant-curvature increment stays exact.
        """
        busy = set(self.members.tolist()) | set(self.rep[self.members].tolist())
        in_contact = {b.id for d in model.contacts for b in d.slave + d.master}
        busy |= set(contributions.declared_nodes(model).tolist())   # user contributions: as contact
        chains = []
        for b in model.beams:
            if b.id in in_contact or any(int(i) in busy for i in b.nodes):
                continue
            k = self.kind[b.nodes]
            anchored = np.flatnonzero(k != FREE)
            if len(anchored) != 1 or k[anchored[0]] == GLOBAL:
                continue
            if anchored[0] == 0:
                chains.append((b.nodes, b.elements, False))
            elif anchored[0] == len(b.nodes) - 1:
                chains.append((b.nodes[::-1], b.elements[::-1], True))
        self.chains = chains
        self.chain_nodes = (np.concatenate([c[0][1:] for c in chains]) if chains
                            else np.zeros(0, dtype=int))
        # flat chain table for assembly_jit.rechain: nodes in chain order, chain k in ptr[k]:ptr[k+1]
        self.chain_index = np.concatenate([c[0] for c in chains]).astype(np.int64) if chains \
            else np.zeros(0, dtype=np.int64)
        self.chain_ptr = np.cumsum([0] + [len(c[0]) for c in chains]).astype(np.int64)

    def _build_rotation_pairs(self):
        """Node pairs ``(n_p, 2)`` whose relative rotation an element represents by a logarithm, their
        element ids and per element the largest rotation its type accepts (``rotation_limit``)."""
        pairs, owner = [], []
        self.rotation_limit = np.empty(self.n_elements)
        for g in self.groups:
            for i, j in g.element_type.rotation_pairs:
                pairs.append(g.nodes[:, [i, j]])
                owner.append(g.elements)
            self.rotation_limit[g.elements] = g.element_type.max_rotation
        self.rotation_pairs = np.concatenate(pairs) if len(self.groups) > 1 or len(pairs) > 1 else self.enodes
        self.pair_element = np.concatenate(owner)

    # ------------------------------------------------------------ dof map
    def _build_reps(self, model):
        n = self.n_nodes
        cons = model.constraints
        rep = _representatives(n, model.joins, cons, self._group_constraint)
        self._set_constraints(model, rep)

    def _set_constraints(self, model, rep):
        """Node kinds, fixed unknowns, joined members and the free/fixed DOF numbering from the
        representatives ``rep`` ``(n,)``."""
        n = self.n_nodes
        cons = model.constraints
        # a constrained member hands its constraint to the representative
        kind = np.full(n, FREE)
        fixed = np.zeros((n, 6), dtype=bool)
        self.motions = {}
        for node, c in cons.items():
            r = rep[node]
            if r != node:
                raise InputError(f"node {node}: constrain the representative node {r} of its joint instead")
            if c[0] == "clamp":
                kind[r] = CLAMPED
                fixed[r] = True
            elif c[0] == "prescribe":
                kind[r] = PRESCRIBED
                fixed[r] = True
                self.motions[r] = c[1]
            else:
                kind[r] = GLOBAL
                fixed[r, sorted(c[1])] = True
        self.rep = rep
        self.kind = kind
        is_rep = rep == np.arange(n)
        self.is_rep = is_rep
        P = self.poses0
        self.members = np.flatnonzero(~is_rep)
        if len(self.members):
            self._member_reps = rep[self.members]
            self.X = se3.relative(P[rep[self.members]], P[self.members])   # H_i = H_rep X_i
            self.Ad_Xinv = se3.adjoint(se3.inverse(self.X))
        else:
            self.X, self.Ad_Xinv = np.zeros((0, 4, 4)), np.zeros((0, 6, 6))
            self._member_reps = np.zeros(0, dtype=np.intp)
        self.global_nodes = np.flatnonzero(kind == GLOBAL)
        # prescribed global translations of fixed components: (node, component, f)
        self.fix_values = []
        for node, vals in model.fix_values.items():
            for comp, f in vals.items():
                self.fix_values.append((int(node), int(comp), f))
        self.prescribed_nodes = np.array(sorted(self.motions), dtype=int)
        free = np.repeat(is_rep, 6).reshape(n, 6) & ~fixed
        self.free = free.ravel()
        self.fixed_dofs = (np.repeat(is_rep, 6).reshape(n, 6) & fixed).ravel()
        self.free_dofs = np.flatnonzero(self.free)
        self.n_free = len(self.free_dofs)
        self.red = np.full(6 * n, -1)
        self.red[self.free_dofs] = np.arange(self.n_free)
        # nodes whose increments are transformed (q = M z)
        transformed = np.zeros(n, dtype=bool)
        transformed[self.members] = True
        transformed[self.global_nodes] = True
        if len(self.global_nodes):
            transformed |= np.isin(rep, self.global_nodes)
        self.transformed = transformed
        self.any_transformed = bool(transformed.any())
        self.group_transformed = [np.flatnonzero(transformed[g.nodes].any(axis=1)) for g in self.groups]
        self.body_nodes = np.flatnonzero(is_rep & ((kind == FREE) | (kind == PRESCRIBED)))

    @staticmethod
    def _group_constraint(parent, root, cons):
        for node in cons:
            if _find(parent, node) == root:
                return node
        return None

    def _check_rigid_modes(self, model):
        """Every connected group (joints, contact) needs 6 independent constraints."""
        if beams_anchored(model, self.kind):
            return
        n = self.n_nodes
        parent = list(range(n))

        def union(a, b):
            ra, rb = _find(parent, a), _find(parent, b)
            if ra != rb:
                parent[ra] = rb
        for g in self.groups:
            for nodes in g.nodes.tolist():
                for b in nodes[1:]:
                    union(nodes[0], b)
        for i in range(n):
            union(i, int(self.rep[i]))
        for decl in model.contacts:
            beams = decl.slave + decl.master
            for b in beams[1:]:
                union(beams[0].first, b.first)
        groups = {}
        for i in range(n):
            groups.setdefault(_find(parent, i), []).append(i)
        P = self.poses0
        fixed = self.fixed_dofs.reshape(n, 6) & (self.is_rep & (self.kind != FREE))[:, None]
        for root, nodes in groups.items():
            if np.any(np.isin(self.kind[nodes], (CLAMPED, PRESCRIBED)) & self.is_rep[nodes]):
                continue       # a clamped or prescribed node alone fixes all six rigid-body modes
            rank = _rigid_mode_rank(P[nodes, :3, 3], fixed[nodes])
            if rank < 6:
                owners = [model.beam_of_node(i) for i in nodes]   # Beam (a dataclass) is unhashable
                beams = sorted({b.id for b in owners if b is not None})
                what = f"beam(s) {beams}" if beams else f"node(s) {nodes}"
                raise InputError(f"{what}: {6 - rank} rigid-body mode(s) are not constrained; "
                                 "clamp, fix or prescribe nodes (or pass check_rigid_modes=False "
                                 "if contact holds them)")

    # ------------------------------------------------------------ loads
    def _build_loads(self, model):
        loads = model.loads
        self.load_nodes = np.array([ld.node for ld in loads], dtype=int)
        self.load_F = np.array([ld.force for ld in loads]).reshape(-1, 3)
        self.load_M = np.array([ld.moment for ld in loads]).reshape(-1, 3)
        self.load_follower = np.array([ld.follower for ld in loads], dtype=bool)
        self.load_scales = [ld.scale for ld in loads]
        self.dead = np.flatnonzero(~self.load_follower)
        self.dead_nodes = self.load_nodes[self.dead]
        self.n_point_loads = len(loads)
        self.line = _line_table(model, self.enodes, self.L)
        self.load_scales = self.load_scales + [ld.scale for ld in model.line_loads]

    def load_factors(self, t):
        """Scales at ``t`` of the nodal loads, then of the line loads (``model.line_loads``)."""
        return np.array([float(s(t)) for s in self.load_scales])

    def loads_act(self, lf):
        """Whether any load is non-zero with the load factors ``lf`` (``load_factors``)."""
        n = self.n_point_loads
        point = np.abs(self.load_F).sum(axis=1) + np.abs(self.load_M).sum(axis=1)
        line = [np.abs(ld.q).sum() + np.abs(ld.m).sum() for ld in self.model.line_loads]
        return bool(np.any(lf[:n] * point != 0) or np.any(lf[n:] * np.array(line) != 0))

    # ------------------------------------------------------------ pattern
    def _build_pattern(self):
        n = self.n_nodes
        k6 = np.arange(6)
        # per element group: dofs (n_g, 6k) of its elements, k from the connectivity
        self.group_edofs = [_blocks.dofs(self.rep, g.nodes) for g in self.groups]
        self.edofs_flat = np.concatenate([ed.ravel() for ed in self.group_edofs])
        # node blocks: dead-loaded nodes and global-type representatives
        bn = sorted(set(self.dead_nodes.tolist()) | set(self.global_nodes.tolist()))
        self.block_nodes = np.array(bn, dtype=int)
        self.load_dofs = ((6 * self.rep[self.load_nodes])[:, None] + k6).ravel()
        self.dead_where = np.searchsorted(self.block_nodes, self.load_nodes[self.dead])
        self.dead_unique = len(set(self.dead_where.tolist())) == len(self.dead_where)
        self.dead_blocks_in_order = len(self.dead_where) == len(bn) and \
            bool((self.dead_where == np.arange(len(bn))).all())
        ndofs = (6 * self.rep[self.block_nodes])[:, None] + k6
        # element entries group by group in the order of the kernels' tangent storage, (n_g, 6k, 6k),
        # then the node blocks (n_b, 6, 6)
        shapes = [(len(ed), ed.shape[1], ed.shape[1]) for ed in self.group_edofs]
        self.group_kslices = np.cumsum([0] + [a * b * c for a, b, c in shapes])
        blocks = list(zip(self.group_edofs, shapes)) + [(ndofs, (len(ndofs), 6, 6))]
        rows = np.concatenate([np.broadcast_to(ed[:, :, None], sh).ravel() for ed, sh in blocks])
        cols = np.concatenate([np.broadcast_to(ed[:, None, :], sh).ravel() for ed, sh in blocks])
        # int32 while 6 n and the entry count fit (half the memory: 3 x 5 MB at 61 wires, 9638 elements)
        small = 6 * n < np.iinfo(np.int32).max and len(rows) < np.iinfo(np.int32).max
        idx = np.int32 if small else np.int64
        self.coo_rows, self.coo_cols = rows, cols = rows.astype(idx), cols.astype(idx)
        rr, rc = self.red[rows], self.red[cols]
        keep = (rr >= 0) & (rc >= 0)
        nf = self.n_free
        key = rc[keep].astype(np.int64) * max(nf, 1) + rr[keep]
        ukey, inv = unique_inverse(key, max(nf, 1) ** 2)
        self.nnz = len(ukey)
        pos = np.full(len(rows), self.nnz, dtype=idx)     # dropped entries go to a dummy slot
        pos[keep] = inv
        self.pos = pos
        self.indices = (ukey % max(nf, 1)).astype(np.int32)
        counts = np.bincount((ukey // max(nf, 1)).astype(np.int64), minlength=nf)
        self.indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
        # entries (free row, prescribed column) for the predictor
        if not (len(self.prescribed_nodes) or self.fix_values):
            self.fc = np.zeros(0, dtype=np.intp)
            return
        presc = np.zeros(6 * n, dtype=bool)
        for r in self.prescribed_nodes:
            presc[6 * r:6 * r + 6] = True
        for node, comp, _ in self.fix_values:
            presc[6 * node + comp] = True
        self.fc = np.flatnonzero((rr >= 0) & presc[cols])

    def _place_line_loads(self):
        """Dofs of the line-loaded elements and the positions of their 12 x 12 blocks in the COO values
        (those of the elements, ``group_kslices``): the load stiffness shares the element pattern."""
        ln = self.line
        if ln is None:
            return
        start = np.full(self.n_elements, -1)
        for j, g in enumerate(self.groups):
            if g.element_type.n_nodes == 2:
                start[g.elements] = self.group_kslices[j] + 144 * np.arange(len(g.elements))
        ln.dofs = _blocks.dofs(self.rep, ln.nodes)
        ln.kpos = (start[ln.element][:, None] + np.arange(144)).ravel()

    # ------------------------------------------------------------ transforms
    def node_transforms(self, H):
        """``M_i`` ``(n, 6, 6)`` for the transformed nodes (identity elsewhere), read-only, kept while the
        global-type nodes' rotations stay."""
        if not self.any_transformed:
            return None
        g = self.global_nodes
        key = H[g, :3, :3]          # M depends on the poses of the global-type nodes only
        c = getattr(self, "_transforms", None)
        if c is not None and equal(c[0], key):
            return c[1]             # read-only: shared by the evaluations at these poses
        M = np.broadcast_to(np.eye(6), (self.n_nodes, 6, 6)).copy()
        if len(g):
            Rt = np.swapaxes(H[g, :3, :3], 1, 2)
            M[g] = 0.0
            M[g, :3, :3] = Rt
            M[g, 3:, 3:] = Rt
        if len(self.members):
            M[self.members] = self.Ad_Xinv @ M[self.rep[self.members]]
        M.flags.writeable = False
        self._transforms = (key, M)
        return M

    def assemble_blocks(self, H, blocks):
        """Generic assembly of local blocks (``blocks.Blocks``, any ``k`` nodes per block;
        docs/theory.md eqs. 10.2-10.3).

        Node transforms (joins, global-type nodes) are applied to the blocks touching a
        transformed node.  Returns ``(r, coo, f_level, m_level)``: the residual ``(6 n,)``,
        the tangent as COO ``(rows, cols, vals)`` in full ``z`` numbering (empty without
        ``blocks.K``; ``rows``, ``cols`` of the blocks are ``(m, k, k)`` views, ``_block_coo``:
        ``np.ravel`` them for flat arrays) and the largest transformed nodal force and moment.
        """
        nodes, f, K = blocks.nodes, blocks.f, blocks.K
        which, Kw, M = (), None, None
        transformed = self.any_transformed
        if transformed and len(nodes):
            which = np.flatnonzero(self.transformed[nodes].any(axis=1))
            if len(which):
                M = self.node_transforms(H)
                f, Kw = _blocks.transform_rows(M, nodes, f, K, which)
        d = _blocks.dofs(self.rep, nodes)
        r = np.bincount(d.ravel(), weights=f.ravel(), minlength=6 * self.n_nodes)
        coo = (np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0))
        if K is not None and len(nodes):
            rows, cols = self._block_coo(d)
            g = self._global_among(self.rep[nodes])
            tail = self._global_node_terms(r, g) if len(g) else None
            if tail is not None:
                rows, cols = self._concat_index(rows, cols, tail[0], tail[1])
            if Kw is None and tail is None:
                vals = K.ravel()                   # the blocks themselves: no copy
            else:                                  # one copy: the blocks, the transformed ones, the tail
                vals = np.empty(K.size + (0 if tail is None else len(tail[2])))
                vals[:K.size] = K.ravel()
                if Kw is not None:
                    vals[:K.size].reshape(K.shape)[which] = Kw
                if tail is not None:
                    vals[K.size:] = tail[2]
            coo = (rows, cols, vals)
        if blocks.levels_of is None:
            return (r, coo) + _blocks.levels(f)
        fl, ml = 0.0, 0.0
        for ln, lf in blocks.levels_of:
            # (the blocks' own nodes: their transformed rows ``which``, as above)
            w = which if ln is nodes else \
                np.flatnonzero(self.transformed[ln].any(axis=1)) if transformed and len(ln) else ()
            if len(w):
                M = self.node_transforms(H) if M is None else M
                lf = _blocks.transform_rows(M, ln, lf, None, w)[0]
            a, b = _blocks.levels(lf)
            fl, ml = max(fl, a), max(ml, b)
        return (r, coo, fl, ml)

    def _global_among(self, nodes):
        """The global-type nodes among ``nodes`` (any shape), sorted (``np.intersect1d``'s result without
        its sort of ``nodes``)."""
        g = self.global_nodes
        if not len(g):
            return g
        present = np.zeros(self.n_nodes, dtype=bool)
        present[nodes.ravel()] = True
        return g[present[g]]

    def _block_coo(self, d):
        """Rows and columns of the COO entries of blocks over the dofs ``d`` ``(m, k)``: read-only
        ``(m, k, k)`` broadcast views of (a copy of) ``d``, without memory of their own (``np.ravel``
        gives the ``(m k^2,)`` arrays ``repeat(d, k)``, ``tile(d, k)``; the CSC path never needs them:
        ``BlockPattern`` reads ``d``); the same arrays while ``d`` stays the same, which ``matrix``
        recognises at once."""
        c = getattr(self, "_coo_index", None)
        if c is None or c[0].shape != d.shape or not equal(c[0], d):
            m, k = d.shape
            small = 6 * self.n_nodes <= np.iinfo(np.int32).max
            dk = np.array(d, dtype=np.int32 if small else np.int64)      # int32: half the memory when raveled
            rows = np.broadcast_to(dk[:, :, None], (m, k, k))
            cols = np.broadcast_to(dk[:, None, :], (m, k, k))
            c = self._coo_index = (dk, rows, cols, whole_nodes(d))
        return c[1], c[2]

    def _concat_index(self, a_rows, a_cols, b_rows, b_cols):
        """The COO index arrays ``a`` (``_block_coo``'s views, raveled) followed by ``b``, kept (the same
        read-only arrays) while ``a``'s are the same arrays and ``b``'s equal."""
        c = getattr(self, "_coo_concat", None)
        if c is None or c[0] is not a_rows or c[1] is not a_cols or not (
                (c[6] is b_rows and c[7] is b_cols) or (equal(c[2], b_rows) and equal(c[3], b_cols))):
            rows, cols = _ravel_concat(a_rows, b_rows), _ravel_concat(a_cols, b_cols)
            rows.flags.writeable = cols.flags.writeable = False
            c = self._coo_concat = (a_rows, a_cols, np.array(b_rows), np.array(b_cols), rows, cols, b_rows, b_cols)
        return c[4], c[5]

    def _global_node_terms(self, r, g):
        """COO of ``[[0, -hat(r_u)], [0, -hat(r_w)]]`` at global-type nodes ``g`` (the dependence of
        ``M`` on ``R``, see the module docstring) for the residual ``r`` of one contribution; the
        index arrays are the same (read-only) arrays while ``g`` is."""
        vals = np.empty((len(g), 6, 3))           # -[hat(r_u), hat(r_w)] per node (compiled: one call, no stacks)
        assembly_jit.global_node_values(r, np.ascontiguousarray(g, dtype=np.int64), vals)
        c = getattr(self, "_global_index", None)
        if c is None or not equal(c[0], g):
            rows = np.broadcast_to((6 * g)[:, None, None] + np.arange(6)[:, None], vals.shape).ravel()
            cols = np.broadcast_to((6 * g)[:, None, None] + 3 + np.arange(3), vals.shape).ravel()
            rows.flags.writeable = cols.flags.writeable = False
            c = self._global_index = (np.array(g), rows, cols)
        return c[1], c[2], vals.ravel()

    # ------------------------------------------------------------ evaluation
    def evaluate(self, H, load_factors, tangent=True):
        """Residual ``r = f_int - f_ext`` in ``z`` (``(6 n,)``) and, with ``tangent``, K values.

        Returns ``(r, kvals, info)``: ``kvals`` are COO values aligned with the
        pattern (``None`` without tangent); ``info`` holds the element state
        and force levels for the convergence test.
        """
        kvals = blocks = None
        n_k = self.group_kslices[-1]
        if tangent:
            # the kernels write their tangents straight into the COO value array (no copy), the node
            # blocks follow them
            kvals = np.empty(n_k + 36 * len(self.block_nodes))
            blocks = kvals[n_k:].reshape(-1, 6, 6)
            blocks[...] = 0.0
        f, state, f_level, m_level, M = self._element_forces(H, kvals)
        ndof = 6 * self.n_nodes
        r = np.bincount(self.edofs_flat, weights=f, minlength=ndof)
        # external loads (body components at their node, then transformed)
        if len(self.load_nodes):
            r, f_level, m_level = self._add_loads(H, load_factors[:self.n_point_loads], M, r, blocks,
                                                  f_level, m_level)
        if self.line is not None:
            r, f_level, m_level = self._add_line_loads(H, load_factors[self.n_point_loads:], M, r, kvals,
                                                       f_level, m_level)
        if tangent and len(self.global_nodes):
            g = self.global_nodes
            rg = r.reshape(-1, 6)[g]
            where = np.searchsorted(self.block_nodes, g)
            blocks[where, :3, 3:] -= _hat(rg[:, :3])
            blocks[where, 3:, 3:] -= _hat(rg[:, 3:])
        info = dict(state=state, f_level=f_level, m_level=m_level)
        return r, kvals, info

    def _element_forces(self, H, kvals):
        """Element forces of all groups (flat, in ``edofs_flat`` order, transformed to ``z``), tangent
        blocks into ``kvals`` (if given), the ``ElementState`` per element, force levels and ``M``."""
        fs, states, f_level, m_level = [], [], 0.0, 0.0
        M = self.node_transforms(H)
        for j, g in enumerate(self.groups):
            m, et = 6 * g.element_type.n_nodes, self.group_transformed[j]
            out = None if kvals is None else \
                kvals[self.group_kslices[j]:self.group_kslices[j + 1]].reshape(len(g.nodes), m, m)
            f, K, state = g.element_type.evaluate(H, g.nodes, g.ref, kvals is not None, out)
            levels = _blocks.levels(f)
            f_level, m_level = max(f_level, levels[0]), max(m_level, levels[1])
            if M is not None and len(et):
                # the generic block transform on the blocks touching a transformed node; the
                # tangent goes back into kvals
                if K is None:       # (the rows ``et`` of a copy of ``f``: the same per-row transform)
                    f = _blocks.transform_rows(M, g.nodes, f, None, et)[0]
                else:
                    ft, Kt = _blocks.transform(M, g.nodes[et], f[et], K[et])
                    f = f.copy()
                    f[et] = ft
                    K[et] = Kt
            if len(self.groups) == 1:
                return f.ravel(), state, f_level, m_level, M
            fs.append(f.ravel())
            states.append(state)
        n = self.n_elements
        merged = [np.empty((n, 6)) for _ in range(3)]
        for g, state in zip(self.groups, states):
            for out, x in zip(merged, state):
                out[g.elements] = x
        return np.concatenate(fs), type(states[0])(*merged), f_level, m_level, M

    def _add_loads(self, H, lf, M, r, blocks, f_level, m_level):
        """``r - f_ext`` and the dead-load stiffness added to ``blocks`` (if given); updated force levels.

        Dead loads: body components ``R^T F`` with the stiffness ``-[[0, hat(R^T F)], [0, hat(R^T M)]]``
        (docs/theory.md eq. 4.2); follower loads are constant in the body frame.
        """
        d = self.dead
        kb = np.empty((len(d) if blocks is not None else 0, 6, 6))
        if len(d) == len(self.load_F):                  # dead loads only: one compiled call
            fext = np.empty((len(d), 6))
            fl, ml = assembly_jit.scaled_dead_loads(H, self.dead_nodes, self.load_F, self.load_M, lf, fext, kb)
            f_level, m_level = max(f_level, fl), max(m_level, ml)
        else:
            Fs, Ms = self.load_F * lf[:, None], self.load_M * lf[:, None]
            f_level = max(f_level, np.abs(Fs).max(initial=0.0))
            m_level = max(m_level, np.abs(Ms).max(initial=0.0))
            fext = np.concatenate([Fs, Ms], axis=1)
            if len(d):
                fd = np.empty((len(d), 6))
                assembly_jit.dead_loads(H, self.dead_nodes, Fs[d], Ms[d], fd, kb)
                fext[d] = fd
        if M is not None:
            fext = np.einsum("nji,nj->ni", M[self.load_nodes], fext)
        r = r - np.bincount(self.load_dofs, weights=fext.ravel(), minlength=len(r))
        if blocks is not None and len(d):
            if M is not None:
                Md = M[self.load_nodes[d]]
                kb = np.swapaxes(Md, 1, 2) @ kb @ Md
            if self.dead_blocks_in_order:      # the node blocks are the dead loads' blocks, in order
                blocks += kb
            elif self.dead_unique:
                blocks[self.dead_where] += kb
            else:
                np.add.at(blocks, self.dead_where, kb)
        return r, f_level, m_level

    def _add_line_loads(self, H, lf, M, r, kvals, f_level, m_level):
        """``r - f_ext`` of the line loads and their stiffness added to the element blocks of
        ``kvals`` (if given; ``line_load``, dead and follower); updated force levels."""
        ln = self.line
        f = np.zeros((len(ln.element), 12))
        K = np.zeros((len(ln.element), 12, 12)) if kvals is not None else None
        for rows, follower in ((ln.dead, False), (ln.follower, True)):
            rows = rows[lf[ln.load[rows]] != 0.0]      # a load scaled to zero: no loads, no stiffness (zero rows)
            if not len(rows):
                continue
            HA, HB = H[ln.nodes[rows, 0]], H[ln.nodes[rows, 1]]
            fac = lf[ln.load[rows]][:, None]
            args = (HA, HB, ln.L[rows], fac * ln.q[rows], fac * ln.m[rows], follower)
            if K is None:
                f[rows] = line_load.nodal_loads(*args)
            else:
                f[rows], K[rows] = line_load.nodal_loads_and_tangent(*args)
        fl, ml = _blocks.levels(f)
        if M is not None:
            f, K = _blocks.transform(M, ln.nodes, f, K)
        r = r - np.bincount(ln.dofs.ravel(), weights=f.ravel(), minlength=len(r))
        if K is not None:
            np.add.at(kvals, ln.kpos, -K.ravel())
        return r, max(f_level, fl), max(m_level, ml)

    def matrix(self, kvals, extra=None):
        """Reduced tangent (free x free) as CSC from the COO values.

        ``extra``: optional ``(rows, cols, vals)`` COO entries in full ``z``
        numbering (``assemble_blocks``), whose pattern may change between iterations.  Where
        ``holds_pattern()`` (large models), whole-node blocks go on the held pattern
        (``held_pattern.HeldPattern``: explicit zeros for reserved contact node pairs, the same
        ``indptr``/``indices`` from one Newton iteration to the next while the blocks stay inside it),
        else on the exact one (``extra_pattern``: exact zeros dropped, as scipy's sum).
        """
        data = np.empty(self.nnz + 1)
        assembly_jit.scatter(self.pos, kvals, data)
        has_extra = extra is not None and len(extra[2])
        held = self._held(data[:self.nnz], extra if has_extra else None)
        if held is not None:
            return held
        if has_extra:
            return self._extra_pattern(extra).matrix(data[:self.nnz], extra[2])
        return canonical_csc(data[:self.nnz], self.indices, self.indptr, self.n_free)

    def holds_pattern(self):
        """Whether ``matrix`` keeps a held pattern (``held_pattern.HeldPattern``): ``hold_pattern`` True, or
        ``"auto"`` with at least ``HOLD_MIN_UNKNOWNS`` free unknowns (where PARDISO is the back-end and
        reuses its analysis while the pattern holds; small scenes keep the exact pattern)."""
        h = self.hold_pattern
        if h not in (True, False, "auto"):
            raise InputError(f"System.hold_pattern must be True, False or 'auto', got {h!r}")
        return h is True or (h == "auto" and self.n_free >= HOLD_MIN_UNKNOWNS)

    @property
    def held_pattern(self):
        """The ``held_pattern.HeldPattern`` of the last ``matrix`` call (``None`` if none): a new object
        whenever the reserve grew (a contact block outside it)."""
        return getattr(self, "_held_cache", None)

    def _held(self, el_data, extra):
        """The tangent on the held pattern (``matrix``) for the element values ``el_data`` and the
        contributions' COO ``extra`` (``None``: none), or ``None`` where no pattern is held: not
        ``holds_pattern``, or entries that are not whole-node blocks (``_block_coo``'s, maybe with
        ``_concat_index``'s tail)."""
        if not self.holds_pattern():
            self._held_cache = None
            return None
        node = tail = None
        if extra is not None:
            c, cc = getattr(self, "_coo_index", None), getattr(self, "_coo_concat", None)
            if c is None or not c[3]:
                return None
            n_b = c[1].size
            if extra[0] is c[1] and extra[1] is c[2]:
                pass
            elif cc is not None and extra[0] is cc[4] and extra[1] is cc[5] and cc[0] is c[1] and cc[1] is c[2]:
                tail = (cc[2], cc[3], extra[2][n_b:])
            else:
                return None
            node = self._block_nodes(c[0])
        p = getattr(self, "_held_cache", None)
        base = (self.red, self.indptr, self.indices)
        k = 1 if node is None else node.shape[1]
        vals = None if node is None else extra[2][:n_b].reshape(-1, 6 * k, 6 * k)
        if p is None or not p.same_base(base):
            if node is not None and held_pattern_.LINEAR_KEYS:      # a new pattern: built on the blocks at once
                p = self._held_cache = HeldPattern.of_blocks(self.red, self.n_free, self.indptr, self.indices, node,
                                                             vals)
                return p.matrix(el_data, node, vals, tail)
            p = HeldPattern(self.red, self.n_free, self.indptr, self.indices)
        if node is None:
            self._held_cache = p
            return p.matrix(el_data)
        if not p.covers(node, vals):
            p = p.grown(node, vals)
        self._held_cache = p
        return p.matrix(el_data, node, vals, tail)

    def add_products(self, K, dofs, Kq, Kl, w):
        """``K + sum_u w_u Kq_u Kl_u^T`` (CSC, a new ``data``) for a tangent ``K`` of ``matrix`` on the held pattern,
        ``Kq``, ``Kl`` ``(m, 6 k)`` over whole-node dofs ``dofs`` ``(m, 6 k)`` (full numbering), ``w`` ``(m,)``;
        ``None`` where no pattern is held for ``K`` or a block leaves it (then assemble the changed values)."""
        p = self.held_pattern
        if p is None or K.nnz != p.nnz or not equal(K.indptr, p.indptr):
            return None
        data = K.data.copy()
        if not p.add_products(data, np.asarray(dofs)[:, 0::6] // 6, Kq, Kl, w):
            return None
        return canonical_csc(data, K.indices, K.indptr, K.shape[0])

    def forget_held_pattern(self):
        """Drop the held pattern: the next ``matrix`` call builds a new one (what a new contact pattern costs)."""
        self._held_cache = None

    def contact_blocks(self, extra):
        """The whole-node blocks of the contributions' COO ``extra``: nodes ``(m, k)`` and values ``(m, 6 k, 6 k)``
        (views), or ``None`` where they are not whole-node blocks."""
        c = getattr(self, "_coo_index", None)
        if c is None or not c[3]:
            return None
        node = self._block_nodes(c[0])
        k = node.shape[1]
        return node, extra[2][:c[1].size].reshape(-1, 6 * k, 6 * k)

    def _block_nodes(self, d):
        """The nodes ``(m, k)`` of whole-node block dofs ``d`` ``(m, 6 k)`` (kept while ``d`` is the same array)."""
        c = getattr(self, "_block_nodes_cache", None)
        if c is None or c[0] is not d:
            c = self._block_nodes_cache = (d, np.ascontiguousarray(d[:, 0::6] // 6, dtype=np.int64))
        return c[1]

    @property
    def extra_pattern(self):
        """The cached pattern of the contributions' COO entries of the last ``matrix`` call
        (``extra_pattern.BlockPattern`` or ``ExtraPattern``; ``None`` before): a new object
        whenever the entries' pattern changed (a new active contact set)."""
        return getattr(self, "_extra_cache", None)

    def _extra_pattern(self, extra):
        """The pattern of the COO entries ``extra`` (kept while it stays: the same active contact
        pairs): ``extra_pattern.BlockPattern`` of the block dofs when they are the index arrays of
        ``_block_coo`` over whole nodes (possibly followed by ``_concat_index``'s), else
        ``extra_pattern.ExtraPattern``."""
        p = getattr(self, "_extra_cache", None)
        base = (self.red, self.indptr, self.indices)
        c, cc = getattr(self, "_coo_index", None), getattr(self, "_coo_concat", None)
        blocks = c is not None and c[3]
        if blocks and extra[0] is c[1] and extra[1] is c[2]:
            tail = None
        elif blocks and cc is not None and extra[0] is cc[4] and extra[1] is cc[5] and cc[0] is c[1] and cc[1] is c[2]:
            tail = cc[2], cc[3]
        else:
            blocks = False
        if blocks:
            if not isinstance(p, BlockPattern) or not p.same(c[0], tail, base):
                p = self._extra_cache = BlockPattern(c[0], self.red, self.n_free, self.indptr, self.indices, tail,
                                                     spare=p if isinstance(p, BlockPattern) else None)
        elif not isinstance(p, ExtraPattern) or not p.same(np.ravel(extra[0]), np.ravel(extra[1]), base):
            p = self._extra_cache = ExtraPattern(np.ravel(extra[0]), np.ravel(extra[1]), self.red, self.n_free,
                                                 self.indptr, self.indices,
                                                 spare=p if isinstance(p, ExtraPattern) else None)
        return p

    def full_matrix(self, kvals, extra=None):
        """The tangent over all ``6 n`` unknowns (constrained ones included) as CSR."""
        ndof = 6 * self.n_nodes
        rows, cols = self.coo_rows, self.coo_cols
        if extra is not None and len(extra[2]):
            rows = np.concatenate([rows, np.ravel(extra[0])])
            cols = np.concatenate([cols, np.ravel(extra[1])])
            kvals = np.concatenate([kvals, extra[2]])
        return sp.coo_matrix((kvals, (rows, cols)), shape=(ndof, ndof)).tocsr()

    def prescribed_coupling(self, kvals, dz_full, extra=None):
        """``K_fc dz_c`` on the free rows (reduced numbering)."""
        e = self.fc
        out = np.bincount(self.red[self.coo_rows[e]], weights=kvals[e] * dz_full[self.coo_cols[e]],
                          minlength=self.n_free).astype(float)   # int when no element couples (empty)
        if extra is not None and len(extra[2]):
            rows, cols, vals = extra
            n_b = self._block_entries(extra)
            if n_b:                              # dense blocks first: only those reaching a moved node
                d = self._coo_index[0]
                out += self._block_coupling(d, vals[:n_b].reshape(len(d), d.shape[1], d.shape[1]), dz_full)
                if n_b == len(vals):
                    return out
                rows, cols, vals = rows[n_b:], cols[n_b:], vals[n_b:]
            rows, cols = np.ravel(rows), np.ravel(cols)
            rr = self.red[rows]
            keep = (rr >= 0) & (self.red[cols] < 0)
            out += np.bincount(rr[keep], weights=vals[keep] * dz_full[cols[keep]], minlength=self.n_free)
        return out

    def _block_entries(self, extra):
        """How many leading entries of the COO ``extra`` are ``_block_coo``'s blocks (its very index
        arrays, maybe followed by ``_concat_index``'s tail): 0 if they are not."""
        c, cc = getattr(self, "_coo_index", None), getattr(self, "_coo_concat", None)
        if c is None:
            return 0
        if extra[0] is c[1] and extra[1] is c[2]:
            return c[1].size
        if cc is not None and extra[0] is cc[4] and extra[1] is cc[5] and cc[0] is c[1] and cc[1] is c[2]:
            return c[1].size
        return 0

    def _block_coupling(self, d, K, dz_full):
        """``K_fc dz_c`` of dense blocks ``K`` ``(m, k, k)`` over the dofs ``d`` ``(m, k)``: only the
        blocks with a constrained, moved column, no ``(m k^2,)`` temporaries."""
        rd = self.red[d]
        w = np.where(rd < 0, dz_full[d], 0.0)
        hit = np.flatnonzero(w.any(axis=1))
        y = np.einsum("bij,bj->bi", K[hit], w[hit])
        keep = rd[hit] >= 0
        return np.bincount(rd[hit][keep], weights=y[keep], minlength=self.n_free)

    # ------------------------------------------------------------ poses
    def update(self, H, dz, chains=True):
        """Apply unknown increments ``dz`` ``(n, 6)`` to the poses (a new array).

        With ``chains``, cantilever beams are updated in strain space (see
        ``_build_chains``); the anchored node must already hold its new pose
        when ``H_anchor`` is given through ``dz`` (prescribed targets are set by
        the caller before re-chaining).
        """
        H0 = H
        H = H.copy()
        dz = np.ascontiguousarray(dz, dtype=float)
        assembly_jit.compose_exp(H, dz, self.body_nodes)       # nodes with a zero increment are skipped
        if chains and self.chains:
            assembly_jit.rechain(H0, H, dz, self.chain_index, self.chain_ptr)
        g = self.global_nodes
        if len(g):        # x += dz_u, R <- exp(dz_w) R (compiled, numpy's bits)
            se3_twin.turn_global(H, g, dz)
        self.sync_members(H)
        return H

    def rechain_numpy(self, H_old, H, dz):
        """The numpy form of ``assembly_jit.rechain`` (its test oracle)."""
        for nodes, elements, reverse in self.chains:
            a, b = nodes[:-1], nodes[1:]              # chain order: anchor first
            h, Tp, Tm = se3.log_and_tangent_inv(se3.relative(H_old[a], H_old[b]))
            # strain-space increment: dh = -T(-h)^-1 dq_a + T(h)^-1 dq_b
            dh = np.einsum("nij,nj->ni", Tp, dz[b]) - np.einsum("nij,nj->ni", Tm, dz[a])
            E = se3.exp(h + dh)
            P = E.copy()                              # prefix products by doubling
            d = 1
            while d < len(P):
                P[d:] = se3.compose(P[:-d].copy(), P[d:])
                d *= 2
            H[b] = se3.compose(H[nodes[0]], P)

    def sync_members(self, H):
        """``H[members] = H[rep] X`` in place (compiled, the bits of ``se3.compose``)."""
        if len(self.members):
            se3_twin.compose_members(H, self.members, self._member_reps, self.X)

    def prescribed_poses(self, t):
        """Target poses ``G(t) H_0`` of the prescribed representatives ``(k, 4, 4)``; every
        ``G(t)`` is checked to be a rigid motion (``validation.check_pose``)."""
        out = np.zeros((len(self.prescribed_nodes), 4, 4))
        for j, node in enumerate(self.prescribed_nodes):
            G = check_pose(self.motions[node](t), f"prescribe({node})", f"motion(t = {t:.6g})")
            out[j] = G @ self.poses0[node]
        return out

    def fixed_value_increments(self, H, t, t_prev=None):
        """``[(node, component, increment)]`` reaching ``fix(..., values=)`` targets at ``t``.

        A rotation is an angle, not wrapped: from the poses ``H`` at ``t_prev`` (angle
        ``g(t_prev)`` up to round-off) the increment is ``g(t) - g(t_prev)`` plus that round-off.
        """
        out = []
        for n, c, f in self.fix_values:
            v = float(f(t))
            if c < 3:
                out.append((n, c, self.poses0[n, c, 3] + v - H[n, c, 3]))
            else:
                Rr = H[n, :3, :3] @ self.poses0[n, :3, :3].T      # rotation about e_k only
                k = c - 3
                a, b = (k + 1) % 3, (k + 2) % 3
                cur = np.arctan2(Rr[b, a], Rr[a, a])
                ref = cur if t_prev is None else float(f(t_prev))
                out.append((n, c, v - ref - ((cur - ref + np.pi) % (2.0 * np.pi) - np.pi)))
        return out

    def enforce_fixed_values(self, H, t):
        """Set the prescribed components of ``fix(..., values=)`` exactly (in place)."""
        for n, c, f in self.fix_values:
            v = float(f(t))
            if c < 3:
                H[n, c, 3] = self.poses0[n, c, 3] + v
            else:
                w = np.zeros(3)
                w[c - 3] = v
                H[n, :3, :3] = se3.exp_so3(w) @ self.poses0[n, :3, :3]

    def reactions(self, H, r):
        """Global force and moment ``(n, 6)`` on each node (the residual, group-summed at joints)."""
        rn = r.reshape(-1, 6)
        out = np.zeros((self.n_nodes, 6))
        rr = rn[self.rep]
        body = self.kind[self.rep] != GLOBAL
        R = H[self.rep, :3, :3]
        out[body, :3] = np.einsum("nij,nj->ni", R[body], rr[body, :3])
        out[body, 3:] = np.einsum("nij,nj->ni", R[body], rr[body, 3:])
        out[~body] = rr[~body]
        return out


@dataclass
class _LineTable:
    """Line loads element by element: ``element`` ids, end ``nodes`` ``(k, 2)``, ``L``, ``q``, ``m``
    ``(k, 3)``, index ``load`` of the ``LineLoad`` (its scale), ``dead``/``follower`` rows, ``dofs``
    ``(k, 12)`` and the positions ``kpos`` ``(k 144,)`` of the element blocks in the COO values."""
    element: np.ndarray
    nodes: np.ndarray
    L: np.ndarray
    q: np.ndarray
    m: np.ndarray
    load: np.ndarray
    dead: np.ndarray
    follower: np.ndarray
    dofs: np.ndarray = None
    kpos: np.ndarray = None


def _line_table(model, enodes, L):
    """The ``_LineTable`` of ``model.line_loads`` (``None`` without line loads)."""
    lls = model.line_loads
    if not lls:
        return None
    el = np.concatenate([ld.beam.elements for ld in lls])
    which = np.concatenate([np.full(ld.beam.n_elements, k) for k, ld in enumerate(lls)])
    fol = np.array([ld.follower for ld in lls])[which]
    return _LineTable(el, enodes[el], L[el], np.array([ld.q for ld in lls])[which],
                      np.array([ld.m for ld in lls])[which], which, np.flatnonzero(~fol), np.flatnonzero(fol))


def _ravel_concat(a, b):
    """``np.concatenate([np.ravel(a), b])`` written in one pass (``a`` a broadcast view: no raveled copy first)."""
    out = np.empty(a.size + len(b), dtype=np.result_type(a, b))
    out[:a.size].reshape(a.shape)[...] = a
    out[a.size:] = b
    return out


def _hat(v):
    """``se3.skew(v)`` ``(k, 3, 3)`` of real 3-vectors ``(k, 3)``: the same values, one stack."""
    z = np.zeros(len(v))
    x, y, w = v[:, 0], v[:, 1], v[:, 2]
    return np.stack([z, -w, y, w, z, -x, -y, x, z], axis=1).reshape(-1, 3, 3)


def _concat(a, b):
    """Two COO triplets ``(rows, cols, vals)`` as one."""
    return tuple(np.concatenate([x, y]) for x, y in zip(a, b))
