"""What a contact system carries from one evaluation or step to the next: ``ContactHistory``.

Keyed by material contact point (``state.KeyLayout``: a Gauss point's key, or a point pair's
``point_offset + (decl n_el + e) n_el + m``), sorted by key and looked up by binary search:

- the friction history, one row per point of the last accepted step: material frames ``H_CL``,
  ``H_FK``, ``H_LK`` ``(k, 4, 4)``, elements ``e``, ``m`` and sections ``xi1``, ``xi2`` ``(k,)``, the
  tangential traction ``lam_t`` ``(k, 3)`` (``frictional`` gives it to the kernel's parameters);
- the augmented-Lagrangian multipliers, normal ``mult`` ``(keys, (k,))`` per point and exact
  stick's tangential ``tmult`` ``(keys, (k, 3))`` per (declaration, slave node, master beam)
  (``mortar.py``), each as a committed copy (the last accepted step) and a trial one (the step being
  solved: ``begin_step`` or ``rollback`` resets it, ``update_multipliers`` sets it, ``commit``
  keeps it);
- the friction coefficients of the last accepted step (``mu_committed``: a declaration whose
  friction switches on starts its history afresh, ``start_friction``);
- the kinds of crossing element pairs decided within the step (``step_kinds``), and the projection kind of each
  Gauss point's owner (``step_point_kinds``);
- the search's memory: ``prev_points`` (``e n_el + m``) and ``prev_owners`` (``key n_el + m``), the
  point pairs and Gauss-point owners of the last evaluation (the hysteresis of the ownership rules).

``state()`` gives the committed part as a flat dict of arrays (saved with a ``Solution``, restart),
``restore(state)`` takes it back, checked first (``state.check_state``).
"""
import numpy as np

from ..errors import InputError
from .frames import LINE
from .state import check_state
from ..model.buffers import equal

__all__ = ["ContactHistory", "lookup", "empty_friction", "SHARED_STATE"]

SHARED_STATE = True     # ``state()`` (``Solution.contact_state``, every step) gives the committed friction history's arrays
#                         themselves, read-only, not copies (the 61-wire strand: 88 MB held twice through a step)


def lookup(keys_sorted, keys):
    """``(index, found)`` of ``keys`` in the sorted ``keys_sorted`` (binary search)."""
    if len(keys_sorted) == 0:
        return np.zeros(len(keys), dtype=int), np.zeros(len(keys), dtype=bool)
    idx = np.minimum(np.searchsorted(keys_sorted, keys), len(keys_sorted) - 1)     # (np.clip: 7 us a call, this 3)
    return idx, keys_sorted[idx] == keys


def empty_friction():
    """A friction history without rows (the fields of the module docstring)."""
    return dict(key=np.zeros(0, dtype=np.int64), H_CL=np.zeros((0, 4, 4)), H_FK=np.zeros((0, 4, 4)),
                H_LK=np.zeros((0, 4, 4)), e=np.zeros(0, dtype=int), m=np.zeros(0, dtype=int),
                xi1=np.zeros(0), xi2=np.zeros(0), lam_t=np.zeros((0, 3)))


_ROWS = ("H_CL", "H_FK", "H_LK_prev", "xi1_prev", "xi2_prev", "lam_t_prev")   # ``frictional``'s parameters


def _no_mult():
    return np.zeros(0, dtype=np.int64), np.zeros(0)


def _no_tmult():
    return np.zeros(0, dtype=np.int64), np.zeros((0, 3))


class ContactHistory:
    """The contact state of the module docstring over the key space ``layout`` (``state.KeyLayout``)."""

    def __init__(self, layout):
        self.layout = layout
        self.friction = empty_friction()
        self.mult_committed = self.mult = _no_mult()
        self.tmult_committed = self.tmult = _no_tmult()
        self.mu_committed = None        # friction per declaration of the last accepted step (None: unknown)
        self.prev_points = np.zeros(0, dtype=np.int64)
        self.prev_owners = np.zeros(0, dtype=np.int64)
        self._kept_rows = None      # ``frictional``'s last rows where every point had history (its arrays, keys)
        self.forget_kinds()

    # ------------------------------------------------------------ steps
    def begin_step(self):
        """A step starts (or starts again): the trial multipliers are the committed ones, the kinds
        of the crossings are decided afresh."""
        self.mult = self.mult_committed
        self.tmult = self.tmult_committed
        self.forget_kinds()

    rollback = begin_step

    def update_multipliers(self, mult=None, tmult=None):
        """New trial multipliers (an augmented-Lagrangian update; ``None``: kept)."""
        self.mult = self.mult if mult is None else mult
        self.tmult = self.tmult if tmult is None else tmult

    def commit(self, mu, friction=None, tmult=None):
        """The step is accepted: its trial normal multipliers, friction coefficients ``mu`` per
        declaration, friction history ``friction`` (dict of the module docstring's fields, sorted by
        key; ``None``: no rows) and tangential multipliers ``tmult`` (``None``: none) are kept."""
        self.forget_rows()
        self.mult_committed = self.mult
        self.mu_committed = mu
        self.friction = empty_friction() if friction is None else friction
        if SHARED_STATE:          # replaced at the next commit, never written: ``state`` hands them out as they are
            for v in self.friction.values():
                v.setflags(write=False)
        self.tmult_committed = self.tmult = _no_tmult() if tmult is None else tmult

    def start_friction(self, mu):
        """Friction coefficients ``mu`` per declaration for the coming step: where friction starts
        (``mu > 0``, none in the last accepted step) the history rows are dropped, so friction acts as
        at first contact, from the step's start.  Not after a restart (``mu_committed`` unknown)."""
        if self.mu_committed is None:
            return
        starts = (mu > 0) & (self.mu_committed == 0)
        if starts.any():
            self.friction = {k: v[~starts[self.friction_decl()]] for k, v in self.friction.items()}

    def friction_decl(self):
        """Declaration of every row of the friction history (decoded from the point keys)."""
        lay = self.layout
        key, n_el = self.friction["key"], np.int64(lay.n_el)
        gauss = key < lay.point_offset
        return np.where(gauss, key // np.maximum(n_el * lay.max_gp * lay.n_beams, 1),
                        (key - lay.point_offset) // (n_el * n_el)).astype(int)

    def forget_rows(self):
        """Let ``frictional``'s kept rows go (a commit's pass drops the points' frames: not held through it)."""
        self._kept_rows = None

    # ------------------------------------------------------------ look-ups
    def normal_multipliers(self, keys):
        """Trial normal multiplier ``(k,)`` of the points ``keys`` (0 where there is none)."""
        mi, mf = lookup(self.mult[0], keys)
        return np.where(mf, self.mult[1][mi] if len(self.mult[1]) else 0.0, 0.0)

    def tangential_multipliers(self, keys):
        """Trial tangential multiplier ``(k, 3)`` of the nodal groups ``keys`` (0 where there is none)."""
        mi, mf = lookup(self.tmult[0], keys)
        lam = np.zeros((len(keys), 3))
        lam[mf] = self.tmult[1][mi[mf]]
        return lam

    def frictional(self, p, keys, e, m):
        """Put the friction history of the points ``keys`` on elements ``e``, ``m`` into the kernel
        parameters ``p`` (``H_CL``, ``H_FK``, ``H_LK_prev``, ``xi1_prev``, ``xi2_prev``, ``lam_t_prev``;
        points without history: identities, their own ``xi1``, ``xi2``, zero traction); returns
        ``found`` ``(k,)``, the points with history."""
        hist = self.friction
        c = self._kept_rows
        if c is not None and c[0] is hist and equal(c[1], keys) and equal(c[2], e) and equal(c[3], m):
            p.update(c[4])          # every point found again: the same rows (read only)
            return c[5]
        hi, hf = lookup(hist["key"], keys)
        n = len(keys)
        if len(hist["key"]):
            every = hf.all()        # (every pair with history, as in a step's later iterates: no masking)
            for name, src in (("H_CL", "H_CL"), ("H_FK", "H_FK"), ("H_LK_prev", "H_LK")):
                p[name] = hist[src][hi] if every else np.where(hf[:, None, None], hist[src][hi], np.eye(4))
            # material points, re-expressed on the current elements (same beam, consecutive ids)
            p["xi1_prev"] = np.where(hf, hist["xi1"][hi] + hist["e"][hi] - e, p["xi1"])
            p["xi2_prev"] = np.where(hf, hist["xi2"][hi] + hist["m"][hi] - m, p["xi2"])
            p["lam_t_prev"] = np.where(hf[:, None], hist["lam_t"][hi], 0.0)
            if every:             # kept for the next look-up of these points (a line search's trials): no gathers
                rows = {k: p[k] for k in _ROWS}
                for v in rows.values():
                    v.flags.writeable = False
                hf.flags.writeable = False
                self._kept_rows = (hist, np.array(keys), np.array(e), np.array(m), rows, hf)
        else:
            p.update(H_CL=np.tile(np.eye(4), (n, 1, 1)), H_FK=np.tile(np.eye(4), (n, 1, 1)),
                     H_LK_prev=np.tile(np.eye(4), (n, 1, 1)), xi1_prev=p["xi1"].copy(),
                     xi2_prev=p["xi2"].copy(), lam_t_prev=np.zeros((n, 3)))
        return hf

    # ------------------------------------------------------------ kinds of crossings
    def forget_kinds(self):
        """Empty the kinds of the step (``step_kinds``, ``step_crossings``, ``point_kinds``): the next evaluation decides
        them."""
        self.kind_keys, self.kind_values = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=int)
        self.cross_keys, self.cross_values = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool)
        self.point_keys, self.point_kinds = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=int)

    def step_crossings(self, decl, e, m, cross):
        """Line or crossing of element pairs kept within a step (exact stick's declarations): a pair (declaration
        ``decl``, slave ``e``, master ``m``) seen at an earlier evaluation of the step keeps that decision (``cross``
        ``(n,)`` bool, crossing at ``line_angle`` and above); the others are remembered as decided now.

        With exact stick a line pair's friction is the mortar multipliers' and a crossing's the point law's: a pair
        whose angle passes ``line_angle`` within a Newton step changes its friction force by the difference of the two
        (the plectoneme at t = 0.858: 8 N on a node; the line search's trials landed on the other side at any length
        above 1/32 of the step, and Newton crawled).  Held for the step, the residual has no such jump; a new step
        decides afresh."""
        n_el = np.int64(self.layout.n_el)
        keys = (np.int64(decl) * n_el + e) * n_el + m
        idx, found = lookup(self.cross_keys, keys)
        if found.any():
            cross = np.where(found, self.cross_values[idx], cross)
        if not found.all():
            k = np.concatenate([self.cross_keys, keys[~found]])
            v = np.concatenate([self.cross_values, cross[~found]])
            order = np.argsort(k, kind="stable")
            self.cross_keys, self.cross_values = k[order], v[order]
        return cross

    def kept_kinds(self, decl, e, m):
        """The kinds ``step_kinds`` keeps for the element pairs (declaration ``decl``, slave ``e``, master ``m``) of
        this step: ``(n,)``, ``-1`` where none is kept yet."""
        n_el = np.int64(self.layout.n_el)
        idx, found = lookup(self.kind_keys, (np.int64(decl) * n_el + e) * n_el + m)
        return np.where(found, self.kind_values[idx] if len(self.kind_values) else -1, -1)

    def step_kinds(self, decl, e, m, kinds, kept=None):
        """Kinds of crossing element pairs kept within a step: a pair (declaration ``decl``, slave
        ``e``, master ``m``) that was a point or orthogonal pair at an earlier evaluation of the
        step keeps that kind while it is a crossing; the others are remembered as decided now.

        The choice (the reduced-Hessian ratio of the closest points, ``rules.extend_wrap``) is
        not continuous: decided afresh at every iterate it may flip between two iterates, and
        the contact force with it (a point pair at the crossing against Gauss points around
        it), so that Newton cycles (docs/theory.md, kind of a crossing within a step).  ``kept``: ``kept_kinds`` of
        the pairs ``kinds != LINE`` if known (no second look-up)."""
        n_el = np.int64(self.layout.n_el)
        cross = np.flatnonzero(kinds != LINE)
        if not len(cross):
            return kinds
        keys = (np.int64(decl) * n_el + e[cross]) * n_el + m[cross]
        if kept is None:
            kept = self.kept_kinds(decl, e[cross], m[cross])
        found = kept >= 0
        kinds = kinds.copy()
        kinds[cross[found]] = kept[found]
        if not found.all():
            k = np.concatenate([self.kind_keys, keys[~found]])
            v = np.concatenate([self.kind_values, kinds[cross[~found]]])
            order = np.argsort(k, kind="stable")
            self.kind_keys, self.kind_values = k[order], v[order]
        return kinds

    def held_point_kinds(self, keys):
        """The projection kinds ``step_point_kinds`` keeps for the Gauss-point ``keys`` in this step: ``(n,)``, ``-1``
        where none is kept yet."""
        idx, found = lookup(self.point_keys, keys)
        return np.where(found, self.point_kinds[idx] if len(self.point_kinds) else -1, -1)

    def step_point_kinds(self, keys, kinds):
        """Remember the projection kind (``LINE``, ``ORTHOGONAL``) of the owners of Gauss-point ``keys`` not yet kept in
        the step: the owners of a later evaluation of the step are of that kind while one of its rows is accepted
        (``ContactSystem._gauss_pairs``).  The two kinds measure a point differently (the section plane's master point
        against the orthogonal foot) and act with different laws (line contact's smoothing, exact stick's mortar
        friction against the point law): a point handed from one kind to the other between Newton iterates changes
        its force (the plectoneme: 0.5 N at t = 0.566, 96 N at t = 0.797) and Newton cycles at any step size."""
        idx, found = lookup(self.point_keys, keys)
        if found.all():
            return
        k = np.concatenate([self.point_keys, keys[~found]])
        v = np.concatenate([self.point_kinds, kinds[~found]])
        order = np.argsort(k, kind="stable")
        self.point_keys, self.point_kinds = k[order], v[order]

    # ------------------------------------------------------------ the search's memory
    def memory(self):
        """The search's memory (point pairs, owners, kinds and crossings of the step), for ``recall``."""
        return (self.prev_points, self.prev_owners, self.kind_keys, self.kind_values, self.cross_keys,
                self.cross_values, self.point_keys, self.point_kinds)

    def recall(self, memory):
        """Put back the search's memory saved by ``memory``."""
        (self.prev_points, self.prev_owners, self.kind_keys, self.kind_values, self.cross_keys,
         self.cross_values, self.point_keys, self.point_kinds) = memory

    # ------------------------------------------------------------ restart
    def state(self):
        """Committed contact state as a flat dict of arrays (saved with a ``Solution``, restart).

        ``history.<field>``: friction history per point key (material frames, ``xi``,
        traction); ``mult_keys``/``mult_values``: augmented-Lagrangian multipliers;
        ``tmult_keys``/``tmult_values``: exact stick's nodal tangential multipliers (``mortar.py``);
        ``prev_points``/``prev_owners``: the point pairs and Gauss-point owners of the last
        evaluation (the hysteresis of the ownership rules).  ``restore`` takes it back.
        """
        out = {f"history.{k}": v if SHARED_STATE and not v.flags.writeable else np.array(v)
               for k, v in self.friction.items()}
        out["mult_keys"], out["mult_values"] = (np.array(a) for a in self.mult_committed)
        out["tmult_keys"], out["tmult_values"] = (np.array(a) for a in self.tmult_committed)
        out["prev_points"] = np.array(self.prev_points)
        out["prev_owners"] = np.array(self.prev_owners)
        return out

    def restore(self, state):
        """Restore a state from ``state()`` (missing parts: empty; older archives lack some), checked
        first (``state.check_state``: ``InputError`` naming a damaged or foreign entry).  The trial
        multipliers are the restored ones, the kinds of crossings forgotten."""
        history, mult, prev = check_state(state, self.layout)
        hist = empty_friction()
        for k, v in (history or {}).items():
            hist[k] = v.astype(hist[k].dtype)
        n = {len(v) for v in hist.values()}
        if len(n) > 1:
            raise InputError(f"contact state: the history has {sorted(n)} rows in different entries "
                             f"(given: {sorted(history or {})}; all of {sorted(hist)} are needed)")
        self.friction = hist
        self.mu_committed = None          # a restart keeps its history also at a friction switch
        if mult is not None:
            self.mult_committed = mult
        self.mult = self.mult_committed
        if "tmult_keys" in state:
            self.tmult_committed = (np.asarray(state["tmult_keys"], dtype=np.int64),
                                    np.asarray(state["tmult_values"], dtype=float).reshape(-1, 3))
        self.tmult = self.tmult_committed
        for name, v in prev.items():
            setattr(self, name, np.sort(v))
        self.forget_kinds()
