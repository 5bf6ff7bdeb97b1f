"""The Problem interface between the solver and the physics.

A ``Problem`` is composed of the elements, loads and constraints of an
``assembly.System`` (DOF map, joins, prescribed motions, the fixed CSC pattern)
and of contributions (``blocks.Contribution``: contact, or any other) that hand
local blocks to the generic assembler ``System.assemble_blocks``.  What the
solver uses, and nothing else of the physics:

- ``evaluate(H, t, tangent=True)`` -> ``Evaluation``: residual ``r`` ``(6 n,)`` in the
  unknowns ``z`` (all contributions in it), force levels ``f_level``/``m_level``
  for the convergence test, element ``state``, tangent data and ``timings``;
- ``tangent(ev)``: the reduced (free x free) CSC tangent with every contribution;
  ``full_tangent(ev)`` over all ``6 n`` unknowns; ``coupling(ev, dz_c)``: ``K_fc dz_c``
  on the free rows for prescribed increments ``dz_c`` ``(n, 6)``;
- ``update(H, dz)``: the poses after increments ``dz`` ``(n, 6)``;
- step life cycle: ``begin_step(H, t)`` (``H`` the converged poses before the step),
  ``repeat_step(H)`` after Newton converged (True: re-solve the step, the outer
  iteration of an augmented Lagrangian), ``unmet(t)`` (why the step may not be
  accepted, or ``None``), ``commit(H)`` when it is accepted (returns the step's
  record of the contributions, e.g. the contact point table, or ``None``);
- ``get_state()``/``set_state(state)``: the committed history (restart), keys
  ``name/key`` per contribution;
- ``smooth``: True when every contribution is smooth (the solver damps Newton on
  its correction), else the solver backtracks on the residual;
  ``conservative``: no follower loads (nodal or line) and every contribution derives from a potential.

``system`` is the DOF map and constraints the solver reads (free unknowns,
prescribed nodes and their targets, reactions).  docs/theory.md section 10
gives the equations and the data flow of one Newton iteration.
"""
import contextlib
import time
from dataclasses import dataclass, field

import numpy as np

from ..model import buffers, contributions
from ..assembly.system import System
from ..errors import InputError
from . import augmented as augmented_, bordered as bordered_, condense as condense_
from .bordered import Bordered

__all__ = ["Problem", "Evaluation"]

ALWAYS_TIMED = ("contact",)      # parts reported in the timings of every step, 0 when absent
SEP = "/"                        # between a contribution's name and its own keys in ``get_state``


@dataclass
class Evaluation:
    """One evaluation at poses ``H``: ``r`` ``(6 n,)``, ``f_level``, ``m_level``, element ``state``;
    ``kvals`` (COO values on the System's fixed pattern, ``None`` without tangent), ``extra``
    (COO ``(rows, cols, vals)`` of the contributions' blocks; ``rows``, ``cols`` may be broadcast views
    ``(m, k, k)``: ``np.ravel`` them), ``timings`` (seconds per
    contribution name, part of the evaluation), ``details`` (info per contribution name)."""
    r: np.ndarray
    f_level: float
    m_level: float
    state: object
    kvals: np.ndarray = None
    extra: tuple = None
    timings: dict = field(default_factory=dict)
    details: dict = field(default_factory=dict)
    mult: dict = None           # multipliers that are Newton unknowns (``Problem.multipliers``), or None

    def drop_tangent(self):
        """Forget the tangent data (``kvals``, ``extra``) once it is factorised: the contributions'
        buffers they hold (``contact.system``'s tangent pool) can then serve the next evaluation.  Exact
        stick: ``K'`` and ``A`` of ``Problem.augmented_system`` too (``A`` lives on in its factor; ``K'`` is
        freed with the ``augmented.Augmented``'s own ``drop_tangent``: 0.3 GB on the 0.6 m rope during the
        line search's trial); ``augmented_system`` of this evaluation is then an error.  A large evaluation
        (``buffers.RELEASE_MIN_VALUES`` tangent values) lets the pools' idle buffers go (``buffers.release_idle``)."""
        large = self.kvals is not None and self.kvals.size >= buffers.RELEASE_MIN_VALUES
        self.kvals = self.extra = None
        if self.mult is not None:
            for k in ("Kp", "A", "K_full"):
                self.mult.pop(k, None)
        if large:
            buffers.release_idle()


class Problem:
    """Elements, loads and constraints of ``system`` plus ``contributions`` (``Problem.from_model``
    builds them from the model: contact, then the user's); see the module docstring for the protocol."""

    def __init__(self, system, contributions=()):
        self.system = system
        self.contributions = list(contributions)
        self._lf = (None, np.zeros(0))
        self._bordered = Bordered()      # the bordered matrix's pattern, kept across Newton iterations
        self.extras = {}                 # the last ``commit``'s per-step values besides the record
        self.shift = 0.0                 # Levenberg shift of the augmented path's displacement block (``levenberg``)

    @classmethod
    def from_model(cls, model, check_rigid_modes=True):
        """The Problem of ``model``: its System, its contact (if declared) and its user contributions
        (``Model.add_contribution``, checked: ``contributions.checked``)."""
        user = contributions.checked(model)
        system = System(model, check_rigid_modes=check_rigid_modes)
        return cls(system, _contact(system) + user)

    @property
    def contact(self):
        """The contact contribution (``contact.system.ContactSystem``), ``None`` without contact."""
        return next((c for c in self.contributions if c.name == "contact"), None)

    def initial_overlap(self, H):
        """A sentence naming the pre-stress that overlaps at the given poses ``H`` put into the model
        (the contributions' optional ``overlap(H)``), ``None`` if none."""
        texts = [t for t in (c.overlap(H) for c in self.contributions if hasattr(c, "overlap")) if t]
        return "; ".join(texts) or None

    def failure_hint(self):
        """What the contributions would add to a ``ConvergenceError`` (their optional ``failure_hint()``,
        e.g. a contact penalty far stiffer than its default), ``""`` if nothing."""
        return "".join(c.failure_hint() for c in self.contributions if hasattr(c, "failure_hint"))

    # ------------------------------------------------------------ properties
    @property
    def adjusted(self):
        """The strain-free adjustment of the reference overlaps (``contact.adjust``): ``dict(count,
        largest)``, ``None`` without contact."""
        return self.contact.adjusted if self.contact is not None else None

    @property
    def solves_start(self):
        """Whether forces of the contributions on the load-free given poses make step 0 an
        equilibrium to solve (``Newton.at_rest`` decides): contact, whose smoothed law pushes
        touching wires apart (docs/theory.md 19.2); user contributions keep the given state."""
        return self.contact is not None

    @property
    def smooth(self):
        return all(c.smooth for c in self.contributions)

    @property
    def conservative(self):
        s = self.system
        if len(s.load_nodes) and np.any(s.load_follower):
            return False
        if s.line is not None and len(s.line.follower):
            return False
        return all(c.conservative for c in self.contributions)

    @property
    def timing_names(self):
        """Names of the parts timed in ``Evaluation.timings``: ``contact`` always (0 without
        contact: ``Solution.stats[k]["timings"]`` has the same keys in every scene), then those of
        the other contributions."""
        return ALWAYS_TIMED + tuple(c.name for c in self.contributions if c.name not in ALWAYS_TIMED)

    # ------------------------------------------------------------ evaluation
    def load_factors(self, t):
        """Load scales at ``t`` (the last ``t`` is cached: a step evaluates many iterates)."""
        if self._lf[0] != t:
            s = self.system
            self._lf = (t, s.load_factors(t) if len(s.load_scales) else np.zeros(0))
        return self._lf[1]

    def evaluate(self, H, t, tangent=True):
        """Residual, force levels and tangent data of every part at poses ``H``, time ``t``."""
        s = self.system
        r, kvals, info = s.evaluate(H, self.load_factors(t), tangent=tangent)
        ev = Evaluation(r, info["f_level"], info["m_level"], info["state"], kvals)
        coo = []
        for c in self.contributions:
            t0 = time.perf_counter()
            blocks, cinfo = c.evaluate(H, tangent)
            rc, cc, fl, ml = s.assemble_blocks(H, blocks)
            if "multipliers" in cinfo:
                ev.mult = self._multipliers(H, c, blocks, cinfo.pop("multipliers"))
                if blocks.K is not None:     # where the groups' blocks (the last ones) sit in ``ev.extra``'s values
                    k6 = blocks.K.shape[1]
                    ev.mult["offset"] = sum(len(x[2]) for x in coo) + (len(blocks.K) - len(ev.mult["C"])) * k6 * k6
            ev.timings[c.name] = time.perf_counter() - t0
            ev.details[c.name] = cinfo
            ev.r = ev.r + rc
            ev.f_level, ev.m_level = max(ev.f_level, fl), max(ev.m_level, ml)
            if len(cc[2]):
                coo.append(cc)
        if len(coo) == 1:
            ev.extra = coo[0]
        elif coo:
            ev.extra = tuple(np.concatenate([np.ravel(x) for x in a]) for a in zip(*coo))
        return ev

    def tangent(self, ev):
        """Reduced tangent (free x free) as CSC, every contribution in it."""
        return self.system.matrix(ev.kvals, ev.extra)

    # ------------------------------------------------------------ multipliers as Newton unknowns
    def _multipliers(self, H, owner, blocks, m):
        """The multiplier unknowns of contribution ``owner`` (``m``: its complementarity residual ``C``
        ``(g, 3)``, weights ``m`` ``(g,)``, group ``key``, ``members`` ``(g, k)``, ``stick``, slips ``u``, slip
        tolerances ``tol`` and, with the tangent, ``Kql`` ``(g, 6 k, 3)``, ``Klq`` ``(g, 3, 6 k)``, ``Kll``
        ``(g, 3, 3)``) with their blocks carried to the unknowns ``z`` (``blocks.transform``) and numbered
        (``dofs``: full ``z`` numbering)."""
        s = self.system
        nodes = m["members"]
        out = dict(owner=owner, C=m["C"], m=m["m"], key=m["key"], stick=m["stick"], u=m["u"], tol=m["tol"],
                   cap=m.get("cap"))
        if "Kql" not in m:
            return out
        Kql, Klq = m["Kql"], m["Klq"]
        rows = {k: m[k] for k in ("Tq", "Vq", "capq") if k in m}
        if s.transformed.any() and len(nodes):
            which = np.flatnonzero(s.transformed[nodes].any(axis=1))
            if len(which):
                M = s.node_transforms(H)
                k = nodes.shape[1]
                T = np.zeros((len(which), 6 * k, 6 * k))
                for j in range(k):
                    T[:, 6 * j:6 * j + 6, 6 * j:6 * j + 6] = M[nodes[which, j]]
                Kql, Klq = Kql.copy(), Klq.copy()
                Kql[which] = np.swapaxes(T, 1, 2) @ Kql[which]
                Klq[which] = Klq[which] @ T
                for k in ("Tq", "Vq"):
                    if k in rows:
                        rows[k] = rows[k].copy()
                        rows[k][which] = rows[k][which] @ T
                if "capq" in rows:
                    rows["capq"] = rows["capq"].copy()
                    rows["capq"][which] = np.einsum("ga,gab->gb", rows["capq"][which], T)
        from ..model import blocks as _blocks
        out.update(Kql=Kql, Klq=Klq, Kll=m["Kll"], R=m["R"], Lam=m["Lam"], B=m.get("B"),
                   dofs=_blocks.dofs(s.rep, nodes))
        if rows:
            out.update(rows, trial=m["trial"], cap=m["cap"], Pi=m["Pi"], weak=m["weak"])
        return out

    def predicted_branches(self, ev, x, dz_c=None):
        """The groups' branches at the Newton step ``x`` ``(n_free + 3 g,)`` (free increments, then the multipliers'
        step: ``linear_system(condense=False)``'s solution) by their linearised trial tractions and disks (the rows of
        ``mortar.branch_rows``, ``want_branch_rows``): ``(stick (g,), trial (g, 3), cap (g,))``."""
        mu = ev.mult
        n = self.system.n_free
        dz = self._group_increments(mu, x, dz_c)
        dLam = x[n:].reshape(-1, 3)
        trial = mu["trial"] + np.einsum("gij,gj->gi", mu["Tq"], dz) + \
            np.einsum("gij,gjk,gk->gi", mu["Pi"], mu["R"], dLam)
        cap = mu["cap"] + np.einsum("ga,ga->g", mu["capq"], dz)
        return (np.linalg.norm(trial, axis=1) <= cap) & (cap > 0.0), trial, cap

    def _group_increments(self, mu, x, dz_c=None):
        """``(g, k6)``: the increments of the groups' slots (free ones from ``x``, prescribed ones from ``dz_c``)."""
        rows_red = self._rows_red(mu)
        dz = np.where(rows_red >= 0, x[:self.system.n_free][np.maximum(rows_red, 0)], 0.0)
        return dz if dz_c is None else dz + self._prescribed_slots(mu, dz_c)

    def branch_rows(self, ev, stick, trial):
        """``(Klq, Kll, C)`` of the multipliers of ``ev`` with the groups whose branch ``stick`` ``(g,)`` differs from
        their iterate's (not those without pressure) linearised on that branch at the iterate: sticking ``C = v -
        trial`` (derivatives ``Vq - Tq``, ``R - Pi R``), sliding along the direction ``t`` of the predicted ``trial``
        ``(g, 3)`` (``predicted_branches``) ``C = v - cap t`` (``Vq - t capq^T``, ``R``); the others' rows as
        evaluated."""
        mu = ev.mult
        norm = np.linalg.norm(trial, axis=1)
        t = trial / np.where(norm > 0.0, norm, 1.0)[:, None]
        Klq, Kll, C = mu["Klq"].copy(), mu["Kll"].copy(), mu["C"].copy()
        sw = (stick != mu["stick"]) & ~mu["weak"]
        v = np.einsum("gij,gj->gi", mu["R"], mu["Lam"])
        on, off = sw & stick, sw & ~stick
        Klq[on] = mu["Vq"][on] - mu["Tq"][on]
        Kll[on] = mu["R"][on] - mu["Pi"][on] @ mu["R"][on]
        C[on] = v[on] - mu["trial"][on]
        Klq[off] = mu["Vq"][off] - t[off][:, :, None] * mu["capq"][off][:, None, :]
        Kll[off] = mu["R"][off]
        C[off] = v[off] - mu["cap"][off][:, None] * t[off]
        return Klq, Kll, C

    @contextlib.contextmanager
    def rows_of(self, ev, rows):
        """Inside: ``ev``'s multipliers' rows ``(Klq, Kll, C)`` are ``rows`` (``branch_rows``), so that
        ``linear_system`` / ``augmented_system`` condense and solve the Newton system of those branches; after: the
        evaluation's rows again (its tangent values without either's Schur terms, ``uncondense``).  A switched
        group's rows are diagonal in the evaluation's basis ``B`` (``[nu, t1, t2]``: sticking ``D = diag(1, 0, 0)``,
        sliding along a fixed direction ``D = I``), so its condensation is exact (``condense``)."""
        mu = ev.mult
        saved = mu["Klq"], mu["Kll"], mu["C"]
        self.uncondense(ev)
        mu["Klq"], mu["Kll"], mu["C"] = rows
        try:
            yield
        finally:
            self.uncondense(ev)
            mu["Klq"], mu["Kll"], mu["C"] = saved

    def bordered(self, ev, K, rhs, dz_c=None, rows=None):
        """The Newton system with the multiplier unknowns of ``ev`` appended: ``[[K, K_ql], [K_lq, K_ll]]``
        (CSC, ``bordered.Bordered``: its pattern kept while the tangent's and the groups' hold) and
        ``[rhs; -C - K_lc dz_c]``.  A multiplier direction no free unknown can slip in (supports hold it, e.g.
        a scene kept in a plane) has an empty row and column: its traction acts on held unknowns only, so it
        is set to zero there (row: the traction's component itself).  ``rows``: ``(Klq, Kll, C)`` in place of the
        evaluation's (``branch_rows``)."""
        mu = ev.mult
        rows_red = self._rows_red(mu)
        Klq, Kll, C = (mu["Klq"], mu["Kll"], mu["C"]) if rows is None else rows
        A, rc = self._bordered.matrix(K, rows_red, mu["Kql"], Klq, Kll, mu["R"], mu["Lam"], C)
        if dz_c is not None:
            dzf = np.ravel(dz_c)[mu["dofs"]]                       # (g, 6 k): constrained increments only
            dzf = np.where(rows_red < 0, dzf, 0.0)
            rc = rc - np.einsum("gij,gj->gi", Klq, dzf).ravel()
        return A, np.concatenate([rhs, rc])

    def _split(self, ev, condense=True):
        """The ``condense.Split`` of ``ev``'s multipliers with its Schur terms in ``ev``'s tangent values (added
        in place, once), ``None`` where the full bordered system is solved."""
        mu = ev.mult
        if mu is None or not (condense and condense_.ENABLED and mu.get("B") is not None and "offset" in mu):
            return None
        if "split" not in mu:
            mu.pop("K_full", None)
            mu["split"] = condense_.split(mu["Kql"], mu["Klq"], mu["Kll"], mu["R"], mu["Lam"], mu["C"], mu["B"])
            condense_.add_schur(ev.extra[2], mu["offset"], mu["split"])
        return mu["split"]

    def _force_rhs(self, ev, dz_c, sp):
        """The free rows' right-hand side ``(n_free,)``: ``-r``, the prescribed coupling and the eliminated
        components' terms (``condense.rhs_terms``)."""
        s = self.system
        rhs = -ev.r[s.free_dofs]
        if dz_c is not None:
            rhs -= self.coupling(ev, dz_c)
        if sp is not None:
            add = np.zeros(len(rhs))
            condense_.scatter_free(self._rows_red(ev.mult), condense_.rhs_terms(sp), add)
            rhs += add
        return rhs

    def _kept(self, ev):
        """The kept components of ``ev``'s split: ``(g, j, Kq, Kl, d, rows_red)``, their groups and components
        ``(u,)``, couplings ``(u, k6)``, ``D``'s entries ``(u,)`` (round-off set to zero) and free rows ``(u, k6)``."""
        mu, sp = ev.mult, ev.mult["split"]
        g, j = sp.kept[:, 0], sp.kept[:, 1]
        d = sp.d[g, j]
        d = np.where(np.abs(d) < bordered_.IDLE, 0.0, d)       # a sticking group's tangential components: zero
        return g, j, sp.Kql[g, :, j], sp.Klq[g, j], d, self._rows_red(mu)[g]

    def linear_system(self, ev, dz_c=None, condense=True, rows=None):
        """``(A, rhs)``: the Newton system of ``ev`` (CSC, free unknowns first; ``dz_c`` ``(n, 6)`` prescribed
        increments).  With multipliers, those components their owner's basis makes eliminable are eliminated
        exactly (``condense``: their Schur terms go into ``ev``'s tangent values, in place, once) and the others
        border the tangent (``Bordered``, one row each); ``condense=False``: the full ``bordered`` system.
        Once ``augmented_system`` has put its augmentation into the tangent values, the same system from the
        tangent it kept.  ``split_solution`` gives the increments and the multipliers' step from its solution."""
        mu = ev.mult
        sp = self._split(ev, condense)
        if mu is not None and sp is not None and "E" in mu:
            return self.augmented_system(ev, dz_c).direct()
        rhs = self._force_rhs(ev, dz_c, sp)
        if mu is not None and sp is None:
            return self.bordered(ev, self._full_tangent(ev), rhs, dz_c, rows)
        K = self.tangent(ev)
        if mu is None:
            return K, rhs
        return self._condensed(ev, K, rhs, dz_c)

    def _full_tangent(self, ev):
        """``tangent(ev)`` of an evaluation whose values hold no Schur terms (the full bordered system), kept in
        ``ev.mult`` until they change (``_split``, ``uncondense``) or are dropped: the active-set inner loop
        (``Newton._active_set_direction``) solves several bordered systems on one tangent."""
        mu = ev.mult
        if "K_full" not in mu:
            mu["K_full"] = self.tangent(ev)
        return mu["K_full"]

    def _condensed(self, ev, K, rhs, dz_c):
        """The condensed bordered system on the tangent ``K`` (``linear_system``)."""
        sp = ev.mult["split"]
        g, j, Kq, Kl, d, rows = self._kept(ev)
        A, rc = self._bordered.matrix(K, rows, Kq[:, :, None], Kl[:, None, :], d[:, None, None],
                                      np.ones((len(g), 1, 1)), sp.b[g, j][:, None], sp.C[g, j][:, None])
        if dz_c is not None:
            rc = rc - np.einsum("ua,ua->u", Kl, self._prescribed_slots(ev.mult, dz_c)[g])
        return A, np.concatenate([rhs, rc])

    def augments(self, ev):
        """Whether ``ev``'s Newton system is solved through ``augmented_system``: ``augmented.ENABLED``, the
        condensed multiplier path, at least ``augmented.MIN_UNKNOWNS`` free unknowns (smaller saddle systems are
        factorised directly: as fast per solve, docs/benchmarks.md)."""
        mu = ev.mult
        return (augmented_.ENABLED and mu is not None and condense_.ENABLED and mu.get("B") is not None
                and "offset" in mu and "Kql" in mu and self.system.n_free >= augmented_.MIN_UNKNOWNS)

    def augmented_system(self, ev, dz_c=None):
        """The condensed Newton system of ``ev`` (``linear_system``) as an ``augmented.Augmented``: the tangent
        ``K'`` (kept, for products) and ``A = K' + Kq E Kl`` (``E``: ``augmented.weights``; added to ``K'``'s values
        on the held pattern, ``System.add_products``, else into ``ev``'s values, in place, and assembled again), the
        kept rows' couplings and right-hand sides; its ``solve(solver)`` gives ``linear_system``'s solution.  Needs
        the condensed path (``augments``); built once per evaluation, the right-hand sides per ``dz_c``."""
        mu = ev.mult
        sp = self._split(ev)
        if sp is None:
            raise ValueError("Problem.augmented_system: no condensed multiplier system in this evaluation")
        g, j, Kq, Kl, d, rows = self._kept(ev)
        free = rows >= 0
        free_row = np.linalg.norm(np.where(free, Kl, 0.0), axis=1)
        own = np.abs(d)
        IDLE = bordered_.IDLE
        idle = (free_row <= IDLE * max(free_row.max(initial=0.0), 1e-300)) & \
            (own <= IDLE * max(own.max(initial=0.0), 1e-300))
        first = "E" not in mu
        if not first and "Kp" not in mu:
            raise ValueError("Problem.augmented_system: the evaluation's tangent was dropped (Evaluation.drop_tangent)")
        f = self._force_rhs(ev, dz_c, sp)        # (before an augmentation in the values, which the coupling reads)
        if first:
            Kp = mu["Kp"] = self.levenberg(self.tangent(ev))
            E, p22 = augmented_.weights(Kq, Kl, free, self._element_diagonal(ev)[mu["dofs"][g]], d, idle)
            mu["E"], mu["p22"] = E, p22
            A = self.system.add_products(Kp, mu["dofs"][g], Kq, Kl, E)     # on the held pattern: no assembly
            if A is None:
                w = np.zeros(sp.d.shape)
                w[g, j] = -E
                condense_.add_products(ev.extra[2], mu["offset"], sp, w)
                mu["in_values"] = True
                A = self.tangent(ev)
            mu["A"] = A
        E, p22 = mu["E"], mu["p22"]
        gv = -sp.C[g, j]
        gv[idle] = -sp.b[g, j][idle]
        if dz_c is not None:
            pc = np.einsum("ua,ua->u", Kl, self._prescribed_slots(mu, dz_c)[g])
            gv = gv - pc
            if not first and mu.get("in_values"):       # the coupling read from the values holds Kq E Kl_c dz_c
                f = f + np.bincount(rows[free], weights=(Kq * (E * pc)[:, None])[free], minlength=len(f))
        Kp = mu["Kp"]
        return augmented_.Augmented(Kp, mu["A"], f, gv, Kq, Kl, rows, np.where(idle, 1.0, d), E, p22, idle,
                                    direct=lambda: self._condensed(ev, Kp, f, dz_c))

    def levenberg(self, K):
        """``K`` with ``shift`` times its diagonal's magnitudes added to its diagonal (``Newton``'s Levenberg shift of
        exact stick's displacement block, ``newton.LM_SHIFT``; the pattern kept), ``K`` itself without a shift."""
        if not self.shift > 0.0:
            return K
        K = K.copy()
        d = K.diagonal()
        K.setdiag(d + self.shift * np.abs(d))
        return K

    def _element_diagonal(self, ev):
        """The elements' diagonal stiffness ``(6 n,)`` (z numbering) of ``ev``'s tangent values."""
        s = self.system
        if getattr(self, "_diag_entries", None) is None:
            self._diag_entries = np.flatnonzero(s.coo_rows == s.coo_cols)
        i = self._diag_entries
        return np.bincount(s.coo_rows[i], weights=ev.kvals[i], minlength=6 * s.n_nodes)

    def uncondense(self, ev):
        """The tangent values of ``ev`` without the Schur terms ``linear_system`` put into them (``condense.
        remove_schur``), so that ``linear_system(ev, condense=False)`` is the full bordered system again."""
        mu = ev.mult
        sp = None if mu is None else mu.pop("split", None)
        if sp is not None:
            if mu.pop("in_values", False):          # ``augmented_system``'s augmentation in the values: out too
                g, j = sp.kept[:, 0], sp.kept[:, 1]
                w = np.zeros(sp.d.shape)
                w[g, j] = mu["E"]
                condense_.add_products(ev.extra[2], mu["offset"], sp, w)
            for k in ("E", "p22", "A", "Kp", "K_full"):
                mu.pop(k, None)
            condense_.remove_schur(ev.extra[2], mu["offset"], sp)

    def _prescribed_slots(self, mu, dz_c):
        """``(g, k6)``: the prescribed increments ``dz_c`` on the groups' held slots (zero on free ones)."""
        dz = np.ravel(dz_c)[mu["dofs"]]
        return np.where(self._rows_red(mu) < 0, dz, 0.0)

    def _rows_red(self, mu):
        """``(g, k6)``: the free (reduced) row of each group slot of the multipliers ``mu`` (``-1``: held), once per
        evaluation (kept in ``mu``)."""
        if "rows_red" not in mu:
            mu["rows_red"] = self.system.red[mu["dofs"]]
        return mu["rows_red"]

    def split_solution(self, ev, x, dz_c=None):
        """``(dzf, dLam)``: the free increments ``(n_free,)`` and the multipliers' Newton step ``(g, 3)`` (``None``
        without multipliers) from the solution ``x`` of ``linear_system``."""
        n = self.system.n_free
        mu = ev.mult
        if mu is None:
            return x, None
        sp = mu.get("split")
        if sp is None:
            return x[:n], x[n:].reshape(-1, 3)
        rows_red = self._rows_red(mu)
        dz = np.where(rows_red >= 0, x[:n][rows_red], 0.0)
        if dz_c is not None:
            dz = dz + self._prescribed_slots(mu, dz_c)
        return x[:n], condense_.recover(sp, x[n:], dz)

    def want_branch_rows(self, flag):
        """Whether the multipliers' owners compute the rows of Newton's active-set inner loop (``predicted_branches``,
        ``branch_rows``; ``newton.INNER_SWITCHES``)."""
        for c in self.contributions:
            if hasattr(c, "branch_rows"):
                c.branch_rows = bool(flag)

    def multipliers_in_newton(self, flag):
        """Whether multipliers may be Newton unknowns (exact stick); otherwise their owners update them
        between Newton solves (augmented-Lagrangian outer iterations)."""
        for c in self.contributions:
            if hasattr(c, "newton_multipliers"):
                c.newton_multipliers = bool(flag)

    def hold_point_kinds(self, flag):
        """Whether a Gauss point's owner keeps its projection kind within a step (``contact.system.HOLD_POINT_KINDS``);
        ``Run``'s step 0 turns it off: each evaluation decides there (a touching start moves the wires apart over many
        iterations and cannot be cut back)."""
        for c in self.contributions:
            if hasattr(c, "hold_point_kinds"):
                c.hold_point_kinds = bool(flag)

    def exact_friction(self, flag):
        """Whether exact stick's friction acts (``Run``'s step 0 turns it off when the equilibrium at ``t_start``
        is not found with it: friction then starts from zero traction at the state found).  Returns whether a
        contribution has such friction."""
        found = False
        for c in self.contributions:
            if hasattr(c, "exact_friction"):
                c.exact_friction = bool(flag)
                found = found or bool(np.any(c.has_exact_friction()))
        return found

    def multiplier_step(self, ev, x):
        """Hand the Newton step ``x`` ``(3 g,)`` of the multipliers of ``ev`` to their owner (trial length 0)."""
        ev.mult["owner"].multiplier_step(ev.mult["key"], x, ev.mult.get("stick"), ev.mult.get("cap"))

    def multiplier_trial(self, s):
        """The iterate's multipliers: the accepted ones plus ``s`` times the last Newton step."""
        for c in self.contributions:
            f = getattr(c, "multiplier_trial", None)
            if f is not None:
                f(s)

    def accept_multipliers(self):
        """The trial multipliers become the accepted ones (a new Newton iterate)."""
        for c in self.contributions:
            f = getattr(c, "accept_multipliers", None)
            if f is not None:
                f()

    def pressed_points(self, H, law=False, tangent=False):
        """Per contribution, the sorted keys of its points whose normal law presses at poses ``H`` (None where it has
        no such points): for ``Newton``'s active set of the normal law (``newton.NORMAL_SWITCHES``); with ``law``,
        ``(keys, lam_n, gap, parabola)`` (``ContactSystem.pressed_points``); with ``tangent``, the evaluation behind
        them (kept for an evaluation of the same poses) computes the contact's tangent too."""
        return [c.pressed_points(H, law, tangent) if hasattr(c, "pressed_points") else None
                for c in self.contributions]

    def force_secant(self, keys, gaps=None, reach=1.0):
        """Evaluate the points ``keys`` (per contribution, as ``pressed_points``; None: none) at the gaps ``gaps`` on
        the secant of the normal law's smoothing parabola to the share ``reach`` of the way to its zero-force end until
        called again (``ContactSystem.force_secant``)."""
        for k, c in enumerate(self.contributions):
            if hasattr(c, "force_secant"):
                c.force_secant(None if keys is None else keys[k], None if keys is None else gaps[k], reach)

    def force_open(self, keys):
        """Evaluate the points ``keys`` (per contribution, as ``pressed_points``; None: none) on the normal law's open
        branch (no normal force, no stiffness) until called again."""
        for k, c in enumerate(self.contributions):
            if hasattr(c, "force_open"):
                c.force_open(None if keys is None else keys[k])

    def multiplier_ratio(self, ev, F):
        """How far the multipliers of ``ev`` are from their equations, on the scale of the residual ratio:
        ``max |C_g| m_g / F`` and, for sticking groups, ``rtol``-free ``max |u_g| / tol_g`` (returned apart):
        ``(ratio, stick_ratio)``; ``(0, 0)`` without multipliers."""
        mu = ev.mult
        if mu is None or not len(mu["m"]):
            return 0.0, 0.0
        r = float(np.max(np.linalg.norm(mu["C"], axis=1) * mu["m"])) / F if F > 0 else 0.0
        st = mu["stick"]
        s = float(np.max(np.linalg.norm(mu["u"][st], axis=1) / mu["tol"][st])) if st.any() else 0.0
        return r, s

    def full_tangent(self, ev):
        """Tangent over all ``6 n`` unknowns as CSR."""
        return self.system.full_matrix(ev.kvals, ev.extra)

    def coupling(self, ev, dz_c):
        """``K_fc dz_c`` on the free rows for prescribed increments ``dz_c`` ``(n, 6)``."""
        return self.system.prescribed_coupling(ev.kvals, np.ravel(dz_c), ev.extra)

    def update(self, H, dz):
        return self.system.update(H, dz)

    # ------------------------------------------------------------ step life cycle
    def begin_step(self, H, t):
        for c in self.contributions:
            c.begin_step(H, t)

    def repeat_step(self, H):
        """True when a contribution asks to re-solve the step (every one is asked)."""
        return any([c.repeat_step(H) for c in self.contributions])

    def unmet(self, t):
        texts = [u for u in (c.unmet(t) for c in self.contributions) if u]
        return "; ".join(texts) if texts else None

    def commit(self, H):
        """Accept the step at ``H``; returns the contributions' record of it (or ``None``).  Their per-step
        values of other shapes (exact stick's nodal table) are in ``extras`` then."""
        record, self.extras = None, {}
        if buffers.RELEASE_AT_COMMIT:        # the step's work arrays: not kept through the commit pass and the next step
            buffers.release_idle(fix_threshold=False)
        for c in self.contributions:
            c.commit(H)
            res = c.results(H)
            if res is not None:
                record = res if record is None else {**record, **res}
            nodal = getattr(c, "nodal_results", None)
            self.extras.update((nodal() if nodal is not None else None) or {})
        return record

    def get_state(self):
        """Committed history of the contributions as one flat dict of arrays, keys ``name/key``
        (``name`` the contribution's, ``key`` its own: equal keys of two contributions are kept apart)."""
        return {f"{c.name}{SEP}{k}": v for c in self.contributions for k, v in c.get_state().items()}

    def set_state(self, state):
        """Give every contribution its part of ``state`` (``get_state``), its own keys.  Keys without
        ``/`` come from archives written before the keys were namespaced, which held only the contact
        history: they go to the contribution named ``contact``."""
        legacy = {k: v for k, v in state.items() if SEP not in k}
        names = {c.name for c in self.contributions}
        foreign = sorted({k.split(SEP, 1)[0] for k in state if SEP in k} - names)
        if foreign or (legacy and "contact" not in names):
            raise InputError(f"contact state: entries of {foreign or ['contact']}, which this model does not have "
                             f"(its contributions: {sorted(names) or 'none'}): the state of another model")
        for c in self.contributions:
            prefix = c.name + SEP
            part = {k[len(prefix):]: v for k, v in state.items() if k.startswith(prefix)}
            c.set_state({**legacy, **part} if c.name == "contact" else part)


def _contact(system):
    """``[ContactSystem]`` for a model with contact declarations, else ``[]``."""
    if not system.model.contacts:    # scenes without contact never import or run contact code
        return []
    from ..contact.system import ContactSystem
    return [ContactSystem(system)]
