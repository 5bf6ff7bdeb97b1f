"""Contact as a pipeline inside the Newton loop: search -> pair rules -> projection -> kernel.

``ContactSystem`` is created by ``assembly.System`` only when the model has
contact declarations.  It orchestrates pure stages kept in their own modules:

1. broad phase (``search.py``: element spheres, ``scipy.spatial.cKDTree``, or a compiled sort
   and sweep where the pairs' order cannot matter) on the element twists computed once per
   evaluation (``projection.element_twists``);
2. pair rules (``rules.py``: no pair between elements sharing a node or meeting at a joint,
   the kind of each element pair, closest points of crossings from ``projection.closest_points``);
3. projection of the slave Gauss points (``projection.gauss_projections``, compiled) and
   ownership (``ownership.gauss_owners``, the compiled ``rules.owners``; ``rules.dedupe_points``:
   one owner per slave point, stable at shared nodes), giving one typed ``record.PairSet``;
4. refusals (``_check_sides``: tunnelling; ``_check_normals``: no normal);
5. kernel parameters and history look-up (``_params``), then the compiled kernel of the
   contact law (``kernel_jit``, ``law.ContactLaw``) on the active pairs (``_local_blocks``,
   kept for the same poses and state);
6. local force and tangent blocks over the pairs' 4 nodes, which the generic assembler
   (``assembly.System.assemble_blocks``) transforms and scatters like any contribution.

``ContactSystem.timings`` accumulates the CPU time (``time.process_time``) of these parts
(``TIMED``: search = twists, spheres and broad phase; rules; projection; params = refusals,
active set and history look-up; kernel; blocks) for benchmarks and profiles.

What it carries between evaluations and steps -- the friction history and augmented-Lagrangian
multipliers keyed by material slave point and master beam, committed only when a step is accepted,
the kinds of crossings within a step, the search's memory, the restart state
(``get_state``/``set_state``) -- is one ``history.ContactHistory`` (``ContactSystem.history``).  A
pair with no history (it just came into contact) starts one from the poses at the start of the step
(``begin_step``): its material frames are those of the pair there, its tangential traction zero, so
friction acts from the first step of contact.

The kernel is the system's own (``ContactSystem(system, kernel=...)``, the attribute ``kernel``):
the compiled ``kernel_jit`` by default, the complex-step oracle ``reference`` for systems made after
``use_numpy_kernel(True)``.

Options per ``Model.add_contact`` declaration: ``options.ContactOptions`` (the
defaults and their meaning live there).  Without ``penalty_t`` the tangential
stiffness of a point is ``mu lam_N / (slip_tolerance L_e)``, so the elastic slip
at the onset of sliding is ``slip_tolerance`` times the slave element length
``L_e`` (Abaqus' default penalty friction; below a floor traction, see
``reference.stick_penalty``).
"""

import time

import numpy as np
from scipy.spatial import cKDTree

from ..lie import se3, se3_twin
from ..model.blocks import Blocks, Contribution
from ..model.buffers import BufferPool, equal
from ..errors import InputError
from ..failures import ContactTunnelling, NoContactNormal
from ..model.model import JOIN_TOL
from .law import PENALTY_T_MIN, default_penalty
from . import kernel_jit, mortar, mortar_jit, segment_tangent
from .chains import beam_chains
from .options import (ADJUST, EXACT_C, EXACT_N, GAUSS_POINTS, SEGMENT_POINTS, SMOOTHING, STICK_TOLERANCE,
                      ContactOptions, declaration_table)
from .frames import LINE, NORMAL_TOL, ORTHOGONAL, POINT, no_normal, touch_tolerance
from .frames_jit import material_frames
from .record import OPEN, SLIP, STICK, Candidates, PairSet
from .ownership import gauss_owners, gauss_record
from .projection import closest_points, element_points, element_twists, gauss_projections, segment_bounds
from .search import broad_pairs, element_spheres
from .history import ContactHistory, lookup as history_lookup
from .state import KeyLayout
from . import adjust, conditioning, rules


MAX_AUGMENT = 30
OVERLAP_REPORT = 1e-4    # penetration / (R1 + R2) in the given poses that step 0 reports (100 x the smoothing)
SWITCH_TOL = 1e-12        # a step ending within this (relative) of active_from / friction_from ends before it
TIMED = ("search", "rules", "projection", "params", "kernel", "blocks")   # parts of ``ContactSystem.timings``
LAZY_MORTAR = True       # exact stick: the multiplier blocks only when the tangent is asked for (False: benchmarks)
HISTORY_FRAMES = ("H_CL", "H_FK", "H_LK_prev")   # the kernel parameters of the friction history's frames (P, 4, 4)
CHUNKED = True           # exact stick: the mortar kernel's tangents into the groups' blocks pass by pass
#                          (``kernel_jit.MORTAR_CHUNK`` points; False: the whole (P, 24, 24) array, then scattered)
SLIP_C = True            # exact stick: a group's c for the next step scaled by its last step's slip over the largest
#                          of its declaration's sliding groups (``_balanced_c``; False: the declaration's c everywhere)
SLIP_C_RULES = 10.0      # ... in a declaration whose c max |u| exceeds SLIP_C_RULES x its median sliding traction
SLIP_C_FLOOR = 1e-3      # ... but not below SLIP_C_FLOOR x the declaration's c (c -> 0 would hide a sticking group's
#                          slip from its equation ``C = -c u``: measured, a stall with the forces met and the slips not)
CHAIN_C = True           # exact stick: c's slave length is its chain's (beams joined end to end, ``beam_chains``)
HOLD_CROSSINGS = True    # exact stick: an element pair's line / crossing decision kept in a step (``step_crossings``)
HOLD_BAND = float(np.radians(5.0))   # ... remembered from pairs this close to line_angle on (cheaper on bundles)
PREV_POINTS_KEPT = True  # the slave centre points at the step's start poses kept for the same elements and sections
#                          (``_check_sides``: the same Gauss points from one iterate to the next)
SEARCH_CENTRES = True    # the centre points of the Gauss-point pairs taken from their projections (``_centres``), not
#                          computed again: the same sections, the same floats
KEPT_KINDS_SKIP = True   # the search computes no closest points for a crossing whose kind the step keeps as orthogonal
#                          (``history.step_kinds`` overwrites it, an orthogonal pair reads no closest point): the same
#                          kinds and points, bit for bit (``_candidates``); False: every crossing's, as before
HOLD_POINT_KINDS = True  # a Gauss point's owner keeps its projection kind (line / orthogonal) within a step while a row
#                          of that kind is accepted (``history.step_point_kinds``; False: decided at each evaluation)
PIECES = True            # a joint continuing a beam by the next (a wire in pieces) is an inner node of the owners and
#                          point pairs: projections accepted past it by XI_OVERHANG, one owner per slave point over the
#                          pieces (``rules.pieces``; False: each piece's ends are beam ends, its points keyed by piece)
CHAIN_GROUPS = True      # exact stick: a mortar group is a slave node against a master chain, not a master beam
LIGHT_COMMIT = True      # exact stick: commit's pass computes the point data and groups' state alone, not the forces
#                          (``ContactSystem._commit_mortar``; False: the evaluation without tangent, as before)
LEAN_COMMIT = True       # commit holds every point's data no longer than it needs it: the last step's (``_last``) goes
#                          before the pass, which runs in chunks (``kernel_jit.mortar_data_of``: a chunk's poses,
#                          ``HL`` and ``HK`` in their own buffer, not the pool's), its frames and ``_cache`` once the
#                          history took them, the section poses once ``results``
#                          read them (the 61-wire strand's second step: ~0.3 GB of the first's commit held through it)
SKIP_OPEN = True         # exact stick: Newton's evaluations leave out the points of certainly open groups (``_open_points``)
SKIP_MARGIN = 1e-2       # ... whose gap exceeds the normal law's band by SKIP_MARGIN (R1 + R2) at least
SKIP_MIN = 64            # ... when at least this many points are that far (fewer: the test costs what it saves; the main
#                          job has 10 a median evaluation, and ~50 us of look-ups per evaluation was 4 % of its trials)
EXTRAPOLATE = True       # exact stick: a step's first multipliers extrapolated from the last two steps' (False: before)
SLID_START = 1.2         # ... and those of the groups that slid in the last step scaled by this, out of their
#                          Coulomb disk: a step starts with them sliding (1.0: on the disk's edge, where round-off
#                          decides; ``_extrapolate``)
FIRST_SLIDE = 1.0        # ... and those of the groups sliding at a step's first iterate end its first Newton step (the
#                          predictor) out of their linearised disk by FIRST_SLIDE times that step's relative change of
#                          their disk (``_first_slide``; 0: before; a fixed 1.2: twisted pair 266 (3 cut-backs) -> 209
#                          (1), but the 4-lay strand cycle 230 -> 278 Newton iterations)
FIRST_SLIDE_MAX = 1.5    # ... at most this many times their linearised traction
FIRST_SLIDE_GROWN = True # ... only groups whose disk grows in that step and whose traction keeps its direction


_default = {"kernel": kernel_jit}       # the kernel of contact systems made without one (``use_numpy_kernel``)


def use_numpy_kernel(flag=True):
    """Make contact systems created from now on without a ``kernel`` evaluate contact with the
    complex-step numpy kernel of ``reference`` (the test oracle, slow, imported only here) instead of
    the compiled ``kernel_jit`` (default); returns the previous setting.  Systems made before keep
    theirs (``ContactSystem.kernel``)."""
    previous = _default["kernel"] is not kernel_jit
    if flag:
        from . import reference
        _default["kernel"] = reference
    else:
        _default["kernel"] = kernel_jit
    return previous


def exact_c(EI, L, n):
    """Default ``c`` of exact stick (force / length^2): ``EXACT_C EI / (L_e L_s^3)`` with ``L_s = n L_e / EXACT_N``
    (the slave's length over ``EXACT_N``): the slave's bending stiffness against a nodal displacement at that
    reference element length (``24 EI / L_s^3``) per unit length ``L_e`` of the node (``EI`` its smaller bending
    stiffness, ``L_e`` the median of its element lengths ``L``, ``n`` its elements per beam).  At ``EXACT_N``
    elements it is ``24 EI / L_e^4`` (the previous default) to the bit.  ``c`` weighs slip against traction in the
    stick/slip decision of an iterate: the scenes' best values follow the slave's stiffness, not the normal penalty,
    and under refinement grow like ``1 / L_e`` (a wire's stiffness against a nodal load is the wire's, not its
    element's; ``24 EI / L_e^4`` grew 4096-fold from 16 to 128 elements and Newton stalled;
    docs/theory_mortar.md 3b).  ``contact.system.EXACT_N = None``: ``L_s = L_e``, the rule before (benchmarks)."""
    Le = float(np.median(L))
    return float(EXACT_C * EI / Le ** 4 * ((n if EXACT_N is None else EXACT_N) / n) ** 3)


def _slave_elements(beams):
    """Median element count of the slave beams ``beams`` (element ids of each, or counts)."""
    return float(np.median([n if np.ndim(n) == 0 else len(n) for n in beams]))


class _Decl:
    """One declaration's element sets and parameters (options from ``ContactOptions``)."""

    def __init__(self, k, decl, model):
        o = ContactOptions.from_dict(decl.options)
        self.index = k
        self.options = o
        self.slave_el = np.concatenate([b.elements for b in decl.slave])
        self.master_el = np.concatenate([b.elements for b in decl.master])
        secs = [b.section for b in decl.slave + decl.master]
        self.penalty = decl.penalty if decl.penalty is not None else min(
            default_penalty(a, b) for a in secs for b in secs)
        self.penalty_t = np.nan if o.penalty_t is None else o.penalty_t     # nan: from the slip tolerance
        self.slip_tolerance = o.slip_tolerance
        self.mu = decl.mu
        self.tolerance = o.tolerance
        self.segments = o.integration == "segments"   # line pairs integrated over segments
        self.n_gp = GAUSS_POINTS if o.gauss_points is None else o.gauss_points        # per whole slave element
        xg, wg = np.polynomial.legendre.leggauss(self.n_gp)
        self.gauss = 0.5 * (xg + 1.0), 0.5 * wg        # Gauss points and weights on [0, 1]
        self.n_seg = SEGMENT_POINTS if o.gauss_points is None else o.gauss_points      # per segment
        xs, ws = np.polynomial.legendre.leggauss(self.n_seg)
        self.seg_gauss = 0.5 * (xs + 1.0), 0.5 * ws
        self.line_angle = o.line_angle
        self.point_ratio = o.point_ratio
        self.margin = 2.0 * max(s.radius for s in secs) if o.margin is None else o.margin
        self.smoothing = o.smoothing          # None: SMOOTHING * (R1 + R2) per pair
        self.law = o.law                      # None: the kernel's default law
        self.exact = o.stick == "exact" and decl.mu > 0
        # exact stick: the complementarity parameter c (force / length^2) and the slip tolerance (length)
        # default: EXACT_C EI / (L_e L_s^3) of the slave (``exact_c``; set by ContactSystem, which knows the lengths)
        self.eps_t = o.penalty_t
        self.slave_bending = min(min(b.section.C[4, 4], b.section.C[5, 5]) for b in decl.slave)
        self.slave_beams = [np.asarray(b.elements) for b in decl.slave]     # element ids of each slave beam
        self.slave_ids = [b.id for b in decl.slave]
        # ... and, where the multipliers are not Newton unknowns (arc length), the Uzawa updates' penalty
        self.aug_t = self.penalty if o.penalty_t is None else o.penalty_t
        self.stick_tolerance = (STICK_TOLERANCE * 2.0 * max(s.radius for s in secs)
                                if o.stick_tolerance is None else o.stick_tolerance)


def _point_data(out, idx, n_sel, G, d, st):
    """Exact stick's point data of the pairs ``idx`` into ``out`` (of ``n_sel`` active pairs): the tangential
    traction ``lam_t`` in the point's ``t1, t2``, ``stick`` (every node of the point sticking), ``slip`` and
    the contact frames ``HL``, ``HK``."""
    every = len(idx) == n_sel           # (``idx`` sorted: every active pair)
    lam_t, stick = mortar_jit.point_data(st["T"], d["n"], d["t1"], d["t2"], st["stick"], G["g"], G["phi"])
    if every:
        out["lam_t"], out["stick"], out["slip"] = lam_t, stick, d["slip"]
    else:
        out["lam_t"][idx], out["stick"][idx], out["slip"][idx] = lam_t, stick, d["slip"]
    for name in ("HL", "HK"):
        if every:
            out[name] = d[name]
            continue
        if name not in out:
            out[name] = np.tile(np.eye(4), (n_sel, 1, 1))
        out[name][idx] = d[name]


class ContactSystem(Contribution):
    """The contact of ``system`` (an ``assembly.System`` whose model has contact declarations) as a
    contribution: the pipeline of the module docstring.  ``kernel``: the module evaluating the contact
    points, ``contact_kernel(X, p, friction, law=)`` and ``kernel_and_tangent(X, p, friction, law=,
    K=)`` (default the compiled ``kernel_jit``, or the oracle ``reference`` after
    ``use_numpy_kernel(True)``); ``history``: what it carries between evaluations and steps
    (``history.ContactHistory``)."""

    def __init__(self, system, kernel=None):
        self.sys = system
        self.kernel = _default["kernel"] if kernel is None else kernel
        model = system.model
        n_el = system.n_elements
        self.el_beam, self.el_radius, self.el_first, self.el_last = self._element_tables(model, n_el)
        self.n_beams = len(model.beams)
        self._joint_tables(system)
        self.decls = [_Decl(k, d, model) for k, d in enumerate(model.contacts)]
        # per-declaration parameters as arrays, indexed by a pair's ``decl`` (no loop over pairs)
        self._decl_penalty = np.array([d.penalty for d in self.decls])
        self._decl_penalty_t = np.array([d.penalty_t for d in self.decls])
        self._mu = np.array([d.mu for d in self.decls])
        self._switch = [(d.active_from, d.friction_from) for d in model.contacts]
        self._decl_on = np.ones(len(self.decls), dtype=bool)
        self.max_gp = max(max(d.n_gp, d.n_seg if d.segments else 0) for d in self.decls)
        # segments: a slave point's key names its segment, ``max_gp * slot + g``, slot ``m mod n_slots`` for a
        # line segment against master element ``m`` (the masters overlapping one slave element are consecutive
        # and fewer than ``n_slots``), ``n_slots`` for the points of whole elements (other kinds)
        self.n_slots = self._segment_slots(system) if any(d.segments for d in self.decls) else 0
        self.key_gp = self.max_gp * (self.n_slots + 1)
        layout = KeyLayout(n_el, self.key_gp, len(self.decls), self.el_beam, self.n_beams, self.el_key_beam)
        self.point_offset = layout.point_offset
        self.history = ContactHistory(layout)
        self.exact_friction = True       # exact stick's friction acts (off at step 0: ``Problem.exact_friction``)
        self.hold_point_kinds = True     # owners keep their projection kind in a step (off at step 0: ``Problem.hold_point_kinds``)
        self._switch_to(-np.inf)
        self.history.mu_committed = self._decl_mu       # friction of the last committed step
        table = declaration_table([d.options for d in self.decls])    # None as each option's kernel_none
        self._decl_slip_tol = np.array([d.slip_tolerance for d in self.decls])
        self._decl_smoothing, self._decl_tolerance = table["smoothing"], table["tolerance"]
        self._decl_adjust = table["adjust"]
        self._decl_exact = np.array([d.exact for d in self.decls])
        chain_root, chain = beam_chains(model)
        # the mortar groups' master: its chain (a slave node against a wire in pieces has one multiplier)
        self.el_master = chain_root[self.el_beam] if CHAIN_GROUPS else self.el_beam
        for d in self.decls:
            if d.eps_t is None:
                n = chain[d.slave_ids] if CHAIN_C else d.slave_beams
                d.eps_t = exact_c(d.slave_bending, system.L[d.slave_el], _slave_elements(n))
        self._decl_eps_t = np.array([d.eps_t for d in self.decls])
        self._decl_aug_t = np.array([d.aug_t for d in self.decls])
        self._decl_stick_tol = np.array([d.stick_tolerance for d in self.decls])
        # slave nodes whose every increment is fixed (``mortar.groups``' boundary modification)
        self._held = ~system.free.reshape(-1, 6)[system.rep].any(axis=1)
        self._node_len = np.bincount(system.enodes.ravel(), weights=np.repeat(0.5 * system.L, 2),
                                     minlength=len(system.poses0))
        self._augments = 0
        self.newton_multipliers = True   # exact stick: multipliers are Newton unknowns (else Uzawa updates)
        self.branch_rows = False         # exact stick: the rows of Newton's active-set inner loop (``mortar.branch_rows``)
        self._groups = mortar.Groups()   # the mortar groups, kept while the pairs' nodes hold
        self._kept_weights = None         # their nodal weights (``_nodal_weights``)
        self._first = False       # the step's first Newton step of the multipliers is still to come (``_first_slide``)
        self._mstep, self._ms = None, 0.0     # the Newton step of the multipliers (keys, dLam) and its trial length
        self._t_step = None        # t of the step begun (``begin_step``)
        self._slide_c = None       # (keys, factor) of the groups' c for the next step (``_balanced_c``)
        self._commits = []         # (t, (keys, Lam)) of the last two converged steps' multipliers (``_extrapolate``)
        self._slid = None          # keys (sorted) of the groups that slid in the last converged step (``_extrapolate``)
        self._evaluation_memory()
        self.timings = dict.fromkeys(TIMED, 0.0)
        self._clock = time.process_time()
        self._penalties = conditioning.penalty_ratios(model, system)
        conditioning.warn_ill_conditioned(self._penalties)
        self._adjusted = adjust.EMPTY
        self._adjusted = self._reference_adjustment(system.poses0)
        self.adjusted = adjust.summary(self._adjusted)    # count and largest overlap adjusted away

    def _evaluation_memory(self):
        """What the evaluations keep from one call to the next (``__init__``): the search's and projections'
        results at the same poses, the pose-free terms of the same pairs, the kernels' buffers."""
        self._sweepable = {}       # per declaration: whether the last search found no crossing (``_candidates``)
        self._H_prev = None        # last converged poses (start of the step)
        self._geo = self._geo_prev = None    # (poses, element twists) of the last evaluation / of H_prev
        self._prev_points = None             # ``_points(prev=True, keep=True)``'s last sections (``PREV_POINTS_KEPT``)
        self._part_centres = {}              # ``pairs``: centre points of its Gauss-point records (``SEARCH_CENTRES``)
        self._pair_centres = None            # (P, twists, x_C, x_F) of the last ``pairs`` (``_centres``)
        self._blocks = None        # (poses, local blocks) of the last evaluation, for the same state
        self._forced = None        # keys of points linearised on the normal law's open branch (``force_open``)
        self._secant = None        # (keys, gaps, reach): points linearised on the parabola's secant (``force_secant``)
        self._skipped = 0          # points of open groups the last evaluation left out (``_open_points``)
        self._full = False         # evaluate every point (``_state``: commit, updates, results)
        self._far = None           # (pairs, far beyond the normal law's band) of the last ``_active``
        self._band = None          # (pairs, smoothing gaps, extent, normal multipliers) of the last ``_active``
        self._held_of = None       # (nodes, held slave nodes) of the last ``_held_slip``
        self._kept_lam = None      # (keys, history multipliers, theirs, Newton step, its rows): ``iterate_multipliers``
        self._kept_terms = None    # (multipliers, mu, keys, masters, kinds, declarations, terms) of ``_point_terms``
        self._kept_params = None   # (``_kept_terms``, sel, (parameters, keys, elements)) of ``_params``
        self._tangent_pool = BufferPool()     # tangent buffers of the compiled kernel (``_tangent_out``)
        self._mortar_pool = BufferPool()      # tangent blocks of pairs and mortar groups (``_with_mortar``)

    def _joint_tables(self, system):
        """``_joint_enodes`` ``(n_el, 2)``: element end nodes with the nodes of a joint merged (elements meeting there
        never pair); ``el_key_beam``, ``el_first_end``, ``el_last_end`` ``(n_el,)``: a wire in pieces has one owner per
        slave point over its pieces (the key's master beam), and a projection past a joint between pieces is accepted
        as past an inner node (``rules.pieces``; ``PIECES``)."""
        self._joint_enodes = rules.joint_nodes(system.rep, system.poses0[:, :3, 3],
                                               JOIN_TOL * system.length_scale)[system.enodes]
        self.el_key_beam, self.el_first_end, self.el_last_end = (
            rules.pieces(self._joint_enodes, self.el_beam, self.el_first, self.el_last, self.n_beams) if PIECES
            else (self.el_beam, self.el_first, self.el_last))

    @staticmethod
    def _element_tables(model, n_el):
        """Per element ``(n_el,)``: its beam's id, section radius, and whether it is its beam's first / last."""
        beam, radius = np.empty(n_el, dtype=int), np.empty(n_el)
        first, last = np.zeros(n_el, dtype=bool), np.zeros(n_el, dtype=bool)
        for b in model.beams:
            beam[b.elements] = b.id
            radius[b.elements] = b.section.radius
            first[b.elements[0]] = True
            last[b.elements[-1]] = True
        return beam, radius, first, last

    def _segment_slots(self, system):
        """Key slots of line segments per slave element: more than the master elements one slave element
        of a segmenting declaration can overlap (its length over the shortest master's, plus 2, and a
        stretch of 2 between them)."""
        n = 1
        for d in self.decls:
            if d.segments:
                n = max(n, int(np.ceil(2.0 * system.L[d.slave_el].max() / system.L[d.master_el].min())) + 2)
        return n

    def _reference_adjustment(self, H0):
        """``adjust.offsets`` of the pairs at the reference poses ``H0``; the search's memory
        (owners, point pairs, kinds) is left as it was."""
        saved = self.history.memory()
        P = self.pairs(H0)
        self.history.recall(saved)
        self.timings = dict.fromkeys(TIMED, 0.0)
        if P is None:
            return adjust.EMPTY
        xC, xF = self._centres(H0, P)
        gap = np.linalg.norm(xF - xC, axis=1) - P.R1 - P.R2
        tol = self._decl_adjust[P.decl]
        tol = np.where(np.isnan(tol), ADJUST * (P.R1 + P.R2), tol)
        return adjust.offsets(P.key, gap, tol)

    def failure_hint(self):
        """The tail of a ``ConvergenceError`` naming a penalty far stiffer than its default
        (``conditioning.stiff_penalty_hint``), else ``""``."""
        return conditioning.stiff_penalty_hint(self._penalties)

    def has_exact_friction(self):
        """Whether a declaration has exact stick with friction (``Problem.exact_friction``)."""
        return bool(self._decl_exact.any())

    def _switch_to(self, t):
        """Declarations and friction acting in a step ending at ``t`` (``add_contact``'s
        ``active_from``, ``friction_from``: on for ``t`` after them); before any step, off."""
        def on(t0):
            return t0 is None or t > t0 + SWITCH_TOL * max(1.0, abs(t0))
        self._decl_on = np.array([on(a) for a, _ in self._switch], dtype=bool)
        self._decl_mu = np.where([on(f) for _, f in self._switch], self._mu, 0.0)
        if not self.exact_friction:
            self._decl_mu = np.where(self._decl_exact, 0.0, self._decl_mu)
        self.history.start_friction(self._decl_mu)    # friction starting this step: as at first contact

    # ------------------------------------------------------------ history
    def get_state(self):
        """Committed contact state as a flat dict of arrays (``ContactHistory.state``: saved with a
        ``Solution``, restart), with exact stick's extrapolation data (``_extrapolate``): ``tmult_steps`` the times
        of the last two steps' multipliers, ``tmult_prev_keys`` / ``tmult_prev_values`` the older ones (the last
        are the history's ``tmult_*``), and the groups' ``c`` factors ``slide_c_keys`` / ``slide_c_factors``
        (``_balanced_c``); ``set_state`` restores it, so a restart takes the same steps."""
        out = self.history.state()
        c = self._commits
        if c and all(t is not None for t, _ in c):
            out["tmult_steps"] = np.array([t for t, _ in c], dtype=float)
            if len(c) == 2:
                out["tmult_prev_keys"], out["tmult_prev_values"] = (np.array(a) for a in c[0][1])
        if self._slide_c is not None:
            out["slide_c_keys"], out["slide_c_factors"] = (np.array(a) for a in self._slide_c)
        if self._slid is not None:
            out["slid_keys"] = np.array(self._slid)
        return out

    def set_state(self, state):
        """Restore a state from ``get_state`` (``ContactHistory.restore``: missing parts empty, checked
        first, ``InputError`` naming a damaged or foreign entry)."""
        self.history.restore(state)
        self._blocks = None
        self._commits = []
        times = np.asarray(state.get("tmult_steps", ()), dtype=float).ravel()
        if len(times) and "tmult_keys" in state:
            last = (times[-1], self.history.tmult_committed)
            if len(times) == 2 and "tmult_prev_keys" in state:
                prev = (np.asarray(state["tmult_prev_keys"], dtype=np.int64),
                        np.asarray(state["tmult_prev_values"], dtype=float).reshape(-1, 3))
                self._commits = [(times[0], prev), last]
            else:
                self._commits = [last]
        self._slide_c = None
        self._slid = np.asarray(state["slid_keys"], dtype=np.int64) if "slid_keys" in state else None
        if "slide_c_keys" in state:
            self._slide_c = (np.asarray(state["slide_c_keys"], dtype=np.int64),
                             np.asarray(state["slide_c_factors"], dtype=float))

    def _lap(self, part=None):
        """Add the CPU time since the last lap to ``timings[part]`` (``None``: start a lap)."""
        t = time.process_time()
        if part is not None:
            self.timings[part] += t - self._clock
        self._clock = t

    # ------------------------------------------------------------ geometry
    def _twists(self, H):
        """Twists ``(n_elements, 6)`` of all elements at ``H`` (compiled; kept for the same poses)."""
        g = self._geo
        if g is None or g[0].shape != H.shape or not equal(g[0], H):
            g = self._geo = (np.array(H, dtype=float), element_twists(H, self.sys.enodes))
        return g

    def _centres(self, H, P, prev=False):
        """Centre points ``x_C``, ``x_F`` ``(P, 3)`` of the pairs ``P`` at ``H`` (``prev``: at the last
        converged poses), compiled, reading the elements' nodes and twists in place; those ``pairs(H)`` found
        with ``P`` (``SEARCH_CENTRES``: the same floats) where ``P`` is its record."""
        c = self._pair_centres
        if not prev and c is not None and c[0] is P and self._twists(H) is c[1]:
            self._pair_centres = None       # (handed out once: not held through the kernels)
            return c[2], c[3]
        # (at the step's start poses the slave points are kept: the same Gauss points from one iterate to the next)
        return self._points(H, P.e, P.xi1, prev, keep=prev), self._points(H, P.m, P.xi2, prev)

    def _prev_twists(self):
        """Twists ``(n_elements, 6)`` of all elements at the last converged poses (once per step)."""
        if self._geo_prev is None:
            g = self._geo       # a step starts at the last iterate's poses, whose twists are kept
            if g is not None and g[0].shape == self._H_prev.shape and equal(g[0], self._H_prev):
                self._geo_prev = (self._H_prev, g[1])
            else:
                self._geo_prev = (self._H_prev, element_twists(self._H_prev, self.sys.enodes))
        return self._geo_prev[1]

    def _pose_at(self, H, e, xi):
        """Section poses ``(k, 4, 4)`` ``H_A exp(xi h)`` of elements ``e`` at ``H`` (compiled, the twists kept
        for these poses)."""
        Hc, h = self._twists(H)
        return se3_twin.exp_compose(Hc, self.sys.enodes[e, 0], h[e], xi)       # se3.interpolate's bits

    def _points(self, H, e, xi, prev=False, keep=False):
        """Centre points ``(k, 3)`` of the sections ``xi`` of elements ``e`` at ``H`` (``prev``: at the
        last converged poses, whose twists are kept for the step)."""
        if prev:
            Hc, h = self._H_prev, self._prev_twists()
            c = self._prev_points     # (the step's twists, e, xi, points) of the last call with ``keep``
            if keep and c is not None and c[0] is self._geo_prev and equal(c[1], e) and _same_bits(c[2], xi):
                return c[3]
        else:
            Hc, h = self._twists(H)
        x = element_points(Hc, self.sys.enodes, h, e, xi)
        if prev and keep and PREV_POINTS_KEPT:
            x.flags.writeable = False
            self._prev_points = (self._geo_prev, np.array(e), np.array(xi), x)
        return x

    # ------------------------------------------------------------ search
    def pairs(self, H):
        """All potential contact pairs at poses ``H`` (a ``PairSet``, None if there are none).

        Per declaration: broad phase and pair rules (``_candidates``), then point pairs
        (``_point_pairs``) and Gauss-point projections (``_gauss_pairs``), each keeping one
        owner per slave point; the owners are remembered for the next evaluation.
        """
        out, chosen, owners = [], [], []
        self._lap()
        geo = self._twists(H)
        self._part_centres, self._pair_centres = {}, None
        for d in self.decls:
            if not self._decl_on[d.index]:
                continue
            c = self._candidates(d, geo)
            part, ids = self._point_pairs(d, H, c)
            rec, own, tied = self._gauss_pairs(d, geo, c)
            if tied and c.swept:      # owners depending on the pairs' order: the distance matrix's order
                c = self._candidates(d, geo, sweep=False)
                part, ids = self._point_pairs(d, H, c)
                rec, own, _ = self._gauss_pairs(d, geo, c)
            out += [part, rec]
            chosen.append(ids)
            owners.append(own)
        hist = self.history
        hist.prev_points = np.sort(np.concatenate(chosen)) if chosen else np.zeros(0, dtype=np.int64)
        # sorted as made: a declaration's owner ids are ascending (``gauss_owners``' key order, one
        # owner per key, ``key * n_el + m``, ``m < n_el``) and above the last declaration's (``key``
        # grows with ``decl``)
        hist.prev_owners = np.concatenate(owners) if owners else np.zeros(0, dtype=np.int64)
        out = [p for p in out if p is not None and len(p)]
        P = (out[0] if len(out) == 1 else PairSet.concatenate(out)) if out else None
        if SEARCH_CENTRES and P is not None:
            # the centre points of the Gauss-point rows as their projections computed them (``_centres``)
            xy = [self._part_centres.get(id(p)) for p in out]
            xy = [c[1:] if c is not None and c[0] is p else (self._points(H, p.e, p.xi1), self._points(H, p.m, p.xi2))
                  for p, c in zip(out, xy)]
            self._pair_centres = (P, geo) + ((xy[0][0], xy[0][1]) if len(xy) == 1 else
                                             (np.concatenate([c[0] for c in xy]), np.concatenate([c[1] for c in xy])))
        self._part_centres = {}
        if P is not None and len(self._adjusted[0]):
            P.R1, P.R2 = adjust.apply(P.key, P.R1, P.R2, self._adjusted)
        return P

    def _candidates(self, d, geo, sweep=True):
        """Broad phase and pair rules of declaration ``d``: element pairs not sharing a node,
        their kind (line below ``line_angle``, else point or orthogonal by the reduced-Hessian
        ratio; search.py) and the closest points of non-line pairs; ``geo``: poses and element
        twists (``_twists``).

        The pairs are those of the distance matrix (``search.broad_phase``), in its order: the
        order of the point pairs and of equal owners.  With ``sweep``, first the same pairs from a
        sort and sweep (``search.sweep_phase``, cheaper): kept, in their order, when no pair is a
        crossing (so no point pairs; ``pairs`` falls back when the owners depend on the order)."""
        en = self.sys.enodes
        H, h = geo
        cs, rs, ts = element_spheres(H, en, h, self.el_radius, d.margin, d.slave_el)
        cm, rm, tm = element_spheres(H, en, h, self.el_radius, d.margin, d.master_el)
        args = (cs, rs, ts, cm, rm, tm, d.slave_el, d.master_el, self._joint_enodes, self.el_radius)
        # the sweep is tried unless the last search of the declaration had crossings or the sweep's flag
        tried = swept = sweep and self._sweepable.get(d.index, True)
        edge = False
        if tried:
            e, m, cos, c2, reach, least, edge = broad_pairs(*args, sweep=True)
            swept = not edge and not rules.may_cross(least, d.line_angle)
        if not swept:
            e, m, cos, c2, reach, least = broad_pairs(*args)
        if sweep:
            self._sweepable[d.index] = not edge and not rules.may_cross(least, d.line_angle)
        self._lap("search")
        cross = rules.crossing(cos, d.line_angle, least)
        if HOLD_CROSSINGS and d.exact and (rules.may_cross(least, d.line_angle - HOLD_BAND)
                                           or self.history.cross_values.any()):
            # exact stick: line or crossing kept within the step (``step_crossings``; nothing to keep where every pair
            # is ``HOLD_BAND`` below ``line_angle`` and none was held)
            held = self.history.step_crossings(d.index, e, m, cross)
            if swept and np.any(held & ~cross):    # (a crossing held: the pairs in the distance matrix's order)
                e, m, cos, c2, reach, least = broad_pairs(*args)
                swept = False
                if sweep:
                    self._sweepable[d.index] = False
                held = self.history.step_crossings(d.index, e, m, rules.crossing(cos, d.line_angle, least))
            cross = held
        kinds = np.full(len(e), LINE)
        xi1, xi2 = np.zeros(len(e)), np.zeros(len(e))
        b = np.flatnonzero(cross)
        if len(b):
            self._lap("rules")
            kept = self.history.kept_kinds(d.index, e[b], m[b]) if KEPT_KINDS_SKIP else None
            run = b if kept is None else b[kept != ORTHOGONAL]
            x1, x2, ratio = closest_points(H, en[e[run], 0], h[e[run]], en[m[run], 0], h[m[run]])
            kinds[b] = ORTHOGONAL       # (those left out: their kept kind, ``step_kinds`` below sets it anyway)
            kinds[run] = rules.point_or_orthogonal(ratio, d.point_ratio)
            xi1[run], xi2[run] = x1, x2
            if len(run) < len(b) and self._wrap_may_change(kinds, xi1, run, kept[kept != ORTHOGONAL]):
                rest = b[kept == ORTHOGONAL]       # ``extend_wrap`` reads every crossing's fresh kind: compute them all
                x1, x2, ratio = closest_points(H, en[e[rest], 0], h[e[rest]], en[m[rest], 0], h[m[rest]])
                kinds[rest] = rules.point_or_orthogonal(ratio, d.point_ratio)
                xi1[rest], xi2[rest] = x1, x2
            self._lap("projection")
            kinds = rules.extend_wrap(en, self.el_beam[m], self.n_beams, e, m, kinds, xi1)
            kinds = self.history.step_kinds(d.index, e, m, kinds, kept)
        self._lap("rules")
        return Candidates(e=e, m=m, kind=kinds, xi1=xi1, xi2=xi2, c2=c2, reach=reach, swept=swept)

    @staticmethod
    def _wrap_may_change(kinds, xi1, run, kept):
        """Whether ``rules.extend_wrap`` could turn a crossing of ``run`` that the step does not keep yet (``kept``
        ``-1``) into an orthogonal pair: a point pair with its slave closest point at an element end (``WRAP_END``).
        Where none is, the crossings left out of ``_candidates``' closest points (their kind kept as orthogonal) change
        nothing through ``extend_wrap``: it turns point pairs only, and every kept kind is set by ``step_kinds``."""
        new = run[kept < 0]
        x = xi1[new]
        return bool(np.any((kinds[new] == POINT) & ((x < rules.WRAP_END) | (x > 1.0 - rules.WRAP_END))))

    def _record(self, d, kind, e, m, xi1, xi2, weight, key, gp):
        en = self.sys.enodes
        nodes = np.concatenate([en[e], en[m]], axis=1)
        return PairSet(kind=kind, e=e, m=m, xi1=xi1, xi2=xi2, weight=weight, key=key, gp=gp,
                       decl=np.full(len(e), d.index), nodes=nodes, R1=self.el_radius[e], R2=self.el_radius[m])

    def _point_pairs(self, d, H, c):
        """Point-to-point pairs: one per crossing (``rules.dedupe_points``), on both elements up to
        ``rules.XI_OVERHANG`` past an inner node.  Returns the record and the chosen element pairs."""
        n_el = len(self.sys.enodes)
        pt = np.flatnonzero(c.kind == POINT)
        if not len(pt):             # no point pairs: no record
            self._lap("rules")
            return None, np.zeros(0, dtype=np.int64)
        e, m, x1, x2 = c.e[pt], c.m[pt], c.xi1[pt], c.xi2[pt]
        lo1, hi1 = self._xi_range(e)
        lo2, hi2 = self._xi_range(m)
        pt = pt[(x1 >= lo1) & (x1 <= hi1) & (x2 >= lo2) & (x2 <= hi2)]
        e, m, x1, x2 = c.e[pt], c.m[pt], c.xi1[pt], c.xi2[pt]
        keep = np.arange(len(pt))       # rules.dedupe_points of fewer than two pairs
        if len(pt) > 1:
            keep = rules.dedupe_points(self._points(H, e, x1), self._points(H, m, x2), x1, x2,
                                       self.el_radius[e] + self.el_radius[m],
                                       self.el_key_beam[e] * self.n_beams + self.el_key_beam[m],
                                       _member(e * n_el + m, self.history.prev_points))
        pt, e, m = pt[keep], e[keep], m[keep]
        key = self.point_offset + (np.int64(d.index) * n_el + e) * n_el + m
        rec = self._record(d, np.full(len(pt), POINT), e, m, c.xi1[pt], c.xi2[pt], self.sys.L[e], key,
                           np.zeros(len(pt), int))
        self._lap("rules")
        return rec, e * n_el + m

    def _gauss_pairs(self, d, geo, c):
        """Line and orthogonal projections of the slave Gauss points; one owner per slave
        point and master beam (``ownership.gauss_owners``, the compiled ``rules.owners``).  Returns
        the record, the owner ids and whether the owners depend on the order of the pairs; ``geo``:
        poses and element twists (``_twists``)."""
        en = self.sys.enodes
        xg, wg = d.gauss
        e, m, kind, c2, reach = c.e, c.m, c.kind, c.c2, c.reach
        if (kind == POINT).any():
            gp = np.flatnonzero(kind != POINT)
            e, m, kind, c2, reach = e[gp], m[gp], kind[gp], c2[gp], reach[gp]
        H, h = geo
        # a slave Gauss point outside the master element's sphere (grown by R1) cannot touch that
        # element: no projection for it, nor for a line row whose section plane misses the master on
        # the overhang the owners accept (``window``: projections per slave point bounded as elements
        # get finer); the others from the projection on the master chord, Newton iterations until
        # converged (compiled, projection.py: ``STEP_TOL``; 8, then on in the window up to
        # ``MAX_ITERATIONS``; not converged: nan distance, no owner; the kernel polishes the point with
        # 2 more and needs it converged for an exact tangent)
        segments = slot = None
        if d.segments:
            seg, slot = self._segments(e, m, kind)
            # n_seg points on every segment (a count depending on its length would make the forces jump)
            segments = (seg,) + segment_bounds(H, en, h, e, m, seg) + d.seg_gauss
        r, g, xi2, dist, *xCF = gauss_projections(H, en, h, e, m, xg, kind, c2, reach, iterations=8,
                                                  window=rules.XI_OVERHANG,
                                                  segments=None if segments is None else segments[:4],
                                                  centres=SEARCH_CENTRES)
        self._lap("projection")
        gk = g if slot is None else g + self.max_gp * slot[r]
        hold = HOLD_POINT_KINDS and self.hold_point_kinds
        if hold and len(r) and len(self.history.point_keys):
            dist = self._held_point_kinds(d, e, m, kind, r, gk, xi2, dist)
        s, key, tied = gauss_owners(d.index, len(en), self.key_gp, self.n_beams, e, m, gk, xi2, dist, self.el_first_end,
                                    self.el_last_end, self.el_key_beam, self.el_radius, self.history.prev_owners, pair=r,
                                    order=True)
        if hold:
            self.history.step_point_kinds(key, kind[r[s]])
        f, ids = gauss_record(s, key, r, g, xi2, e, m, kind, xg, wg, self.sys.L, en, self.el_radius,
                              segments)
        rec = PairSet(key=key, decl=np.full(len(s), d.index), **f)
        if SEARCH_CENTRES:
            self._part_centres[id(rec)] = (rec, xCF[0][s], xCF[1][s])     # (the record held: its id not reused)
        self._lap("rules")
        return rec, ids, tied

    def _held_point_kinds(self, d, e, m, kind, r, gk, xi2, dist):
        """The distances ``dist`` of the projected rows (element pair ``r``, key Gauss point ``gk``) with the rows of a
        key whose owner kind the step keeps (``history.step_point_kinds``) set to nan where they are of another kind and
        the key has an accepted row of the kept kind (in ``rules.xi_range``, finite distance): no owner among them.  A
        key without such a row takes its owner from all (its point does not vanish)."""
        kept = self.history.point_kinds
        if len(kind) and (kind == kind[0]).all() and (kept == kind[0]).all():
            return dist              # (one kind of projection, as on line contact alone: nothing to hold)
        n_el = np.int64(len(self.sys.enodes))
        er, mr, kr = e[r], m[r], kind[r]
        key = ((np.int64(d.index) * n_el + er) * self.key_gp + gk) * self.n_beams + self.el_key_beam[mr]
        held = self.history.held_point_kinds(key)
        lo, hi = rules.xi_range(self.el_first_end[mr], self.el_last_end[mr])
        ok = (xi2 >= lo) & (xi2 <= hi) & np.isfinite(dist) & (kr == held)
        other = (held >= 0) & (kr != held)
        if not other.any() or not ok.any():
            return dist
        covered = _member(key, np.unique(key[ok]))
        drop = other & covered
        if not drop.any():
            return dist
        dist = dist.copy()
        dist[drop] = np.nan
        return dist

    def _segments(self, e, m, kind):
        """Which element pairs are integrated over segments and the key slot of each pair
        (``__init__``): the line pairs, unless their slave element meets the same master beam in an
        orthogonal pair too (a wrap's end: the points of the whole element, one owner each, as without
        segments, so nothing is counted twice)."""
        line = kind == LINE
        group = e.astype(np.int64) * self.n_beams + self.el_beam[m]
        mixed = _member(group, np.unique(group[~line])) if not line.all() else np.zeros(len(e), dtype=bool)
        seg = line & ~mixed
        return seg, np.where(seg, m % self.n_slots, self.n_slots)

    def _xi_range(self, el):
        """Accepted projections ``[lo, hi]`` on elements ``el`` (``rules.xi_range``; a joint between pieces is an
        inner node: ``rules.pieces``)."""
        return rules.xi_range(self.el_first_end[el], self.el_last_end[el])

    def _params(self, P, sel, H):
        """Kernel parameters for the pairs ``sel`` (history and multipliers looked up)."""
        b, self._band = self._band, None
        same = b is not None and b[0] is P      # ``_active``'s of these pairs (element by element: the same floats)
        c = self._kept_params
        if same and c is not None and c[0] is self._kept_terms and equal(c[1], sel):
            fixed, key, e, m = c[2]         # (the same pairs and state as the last call: its arrays, read only)
        else:
            dec, key, e, m = P.decl[sel], P.key[sel], P.e[sel], P.m[sel]
            fixed = dict(kind=P.kind[sel], R1=P.R1[sel], R2=P.R2[sel], penalty=self._decl_penalty[dec],
                         penalty_t=self._decl_penalty_t[dec], mu=self._decl_mu[dec],
                         # elastic slip at the onset of sliding (used where no penalty_t is given)
                         elastic_slip=self._decl_slip_tol[dec] * self.sys.L[e])
            if same:
                fixed.update(smoothing=b[1][sel], multiplier=b[3][sel])
            else:
                fixed.update(smoothing=self._smoothing(P, sel), multiplier=self.history.normal_multipliers(key))
            self._kept_params = None
            if same:
                for v in (*fixed.values(), key, e, m):
                    v.flags.writeable = False
                self._kept_params = (self._kept_terms, np.array(sel), (fixed, key, e, m))
        p = dict(kind=fixed["kind"], xi1=P.xi1[sel], xi2=P.xi2[sel], R1=fixed["R1"], R2=fixed["R2"],
                 weight=P.weight[sel], penalty=fixed["penalty"], penalty_t=fixed["penalty_t"], mu=fixed["mu"],
                 elastic_slip=fixed["elastic_slip"], smoothing=fixed["smoothing"], multiplier=fixed["multiplier"])
        extent = b[2] if same else _extent(H)
        # round-off gaps touch (reference.touching_gap, the kernels' rule) where the law's smoothing gap does not cover them already
        touch = touch_tolerance(extent, p["R1"], p["R2"])
        p["touch"] = np.where(p["smoothing"] >= touch, 0.0, touch)
        if self._forced is not None and len(self._forced):     # the normal law's open branch (``force_open``)
            off = _member(key, self._forced)
            p["penalty"] = np.where(off, 0.0, p["penalty"])
            p["multiplier"] = np.where(off, 0.0, p["multiplier"])
        if self._secant is not None:     # the smoothing parabola's secant to its zero-force end (``force_secant``)
            self._secant_law(key, p)
        hf = self.history.frictional(p, key, e, m)
        hist = self.history.friction
        # a point pair whose crossing moved to a neighbouring element pair keeps the
        # history of the committed point pair of the same two beams next to it
        cand = np.flatnonzero(~hf & (p["kind"] == POINT) & (p["mu"] > 0))
        hp = np.flatnonzero(hist["key"] >= self.point_offset) if len(cand) else cand
        if len(cand) and len(hp):
            hf = self._inherit_points(P, sel, H, p, hf, cand, hp)
        # a pair without history starts it from the last converged poses: its
        # material frames are those of the pair there (same xi), its traction zero
        new = np.flatnonzero(~hf & (p["mu"] > 0))
        if len(new) and self._H_prev is not None:
            h = self._prev_twists()           # the element twists at the last converged poses
            H_CL, H_FK, H_LK = material_frames(self._H_prev, P.nodes[sel][new], p["xi1"][new], p["xi2"][new],
                                               p["R1"][new], p["R2"][new], h[P.e[sel][new]], h[P.m[sel][new]])
            ok = np.isfinite(H_LK).all(axis=(1, 2))
            new = new[ok]
            p["H_CL"][new], p["H_FK"][new], p["H_LK_prev"][new] = H_CL[ok], H_FK[ok], H_LK[ok]
            p["xi1_prev"][new], p["xi2_prev"][new] = p["xi1"][new], p["xi2"][new]
            hf = hf.copy()
            hf[new] = True
        p["has_history"] = hf
        return p

    def _inherit_points(self, P, sel, H, p, hf, cand, hp):
        """Give the point pairs ``cand`` (no history of their own) the history of the nearest
        committed point pair ``hp`` of the same declaration and beams within ``R1 + R2``;
        material points are re-expressed on the new elements (same beam, consecutive ids)."""
        hist = self.history.friction
        en, nb = self.sys.enodes, self.n_beams
        e, m = P.e[sel][cand], P.m[sel][cand]
        x = self._points(H, e, p["xi1"][cand])
        he, hm = hist["e"][hp], hist["m"][hp]
        hx = self._points(H, he, hist["xi1"][hp])       # the stored material points, now
        hdecl = (hist["key"][hp] - self.point_offset) // (np.int64(len(en)) * len(en))
        kb = self.el_key_beam           # (a wire in pieces: one beam, ``rules.pieces``)
        g_new = (P.decl[sel][cand] * nb + kb[e]) * nb + kb[m]
        g_old = (hdecl * nb + kb[he]) * nb + kb[hm]
        k = min(4, len(hp))
        dist, j = cKDTree(hx).query(x, k=k)
        dist, j = dist.reshape(len(cand), k), j.reshape(len(cand), k)
        jc = np.minimum(j, len(hp) - 1)
        good = (j < len(hp)) & (g_old[jc] == g_new[:, None]) & \
            (dist < (p["R1"][cand] + p["R2"][cand])[:, None])
        ok = good.any(axis=1)
        if not ok.any():
            return hf
        jh = hp[jc[ok, np.argmax(good[ok], axis=1)]]
        ii = cand[ok]
        for name, src in (("H_CL", "H_CL"), ("H_FK", "H_FK"), ("H_LK_prev", "H_LK"), ("lam_t_prev", "lam_t")):
            p[name][ii] = hist[src][jh]
        p["xi1_prev"][ii] = hist["xi1"][jh] + hist["e"][jh] - P.e[sel][ii]
        p["xi2_prev"][ii] = hist["xi2"][jh] + hist["m"][jh] - P.m[sel][ii]
        hf = hf.copy()
        hf[ii] = True
        return hf

    def _smoothing(self, P, sel):
        """Smoothing gap per pair: the declaration's, else ``SMOOTHING (R1 + R2)`` for line
        contact (touching, nearly parallel wires, whose many Gauss points hover at gap zero)
        and 0 (sharp) for point and orthogonal pairs (crossings and wraps keep the exact
        penalty law).  ``R1 + R2`` of the sections: a pair's radii reduced by an adjustment
        (``contact.adjust``) leave it as it was."""
        rsum = self.el_radius[P.e[sel]] + self.el_radius[P.m[sel]]
        given = self._decl_smoothing[P.decl[sel]]
        return np.where(np.isnan(given), np.where(P.kind[sel] == LINE, SMOOTHING * rsum, 0.0), given)

    def _active(self, P, H, centres=None, dist=None):
        """Pairs whose trial normal traction is positive (``centres``: ``_centres(H, P)`` if known; ``dist``: their
        distances ``|x_F - x_C|``, if known)."""
        if dist is None:
            xC, xF = self._centres(H, P) if centres is None else centres
            dist = np.linalg.norm(xF - xC, axis=1)
        gap = dist - P.R1 - P.R2
        pen, mult, smoothing, base, margin, exact = self._point_terms(P)
        extent = _extent(H)
        self._band = (P, smoothing, extent, mult)     # (``_params`` of these pairs: the same values, taken)
        # the smoothing zone plus a small band keeps the projection-updated gap consistent
        band = base + touch_tolerance(extent, P.R1, P.R2)
        trial = mult - pen * gap
        on = trial > -pen * band
        # (``_open_points``: the pairs far beyond that band, from the same gaps)
        self._far = (P, trial <= -pen * (band + margin)) if SKIP_OPEN else None
        if self.newton_multipliers and self._decl_exact.any():
            # exact stick: the nodal traction field acts over the whole overlap the search found (a point
            # that left the normal law keeps its share of the field: no jump in the residual)
            on |= exact
        return np.flatnonzero(on)

    def _point_terms(self, P):
        """``_active``'s terms of the pairs ``P`` that do not depend on the poses, ``(P,)`` each: penalty, normal
        multiplier, smoothing gap, ``smoothing + 1e-3 (R1 + R2)``, ``SKIP_MARGIN (R1 + R2)`` and the exact-stick line
        pairs with friction; kept (read only) while the pairs' keys, masters and kinds, the multipliers and the
        friction coefficients are the same (a Newton step's evaluations)."""
        c = self._kept_terms
        if c is not None and c[0] is self.history.mult and c[1] is self._decl_mu and equal(c[2], P.key) and \
                equal(c[3], P.m) and equal(c[4], P.kind) and equal(c[5], P.decl):
            return c[6]
        rsum = P.R1 + P.R2
        smoothing = self._smoothing(P, slice(None))
        terms = (self._decl_penalty[P.decl], self.history.normal_multipliers(P.key), smoothing,
                 smoothing + 1e-3 * rsum, SKIP_MARGIN * rsum,
                 self._decl_exact[P.decl] & (P.kind == LINE) & (self._decl_mu[P.decl] > 0))
        for v in terms:
            v.flags.writeable = False
        self._kept_terms = (self.history.mult, self._decl_mu, np.array(P.key), np.array(P.m), np.array(P.kind),
                            np.array(P.decl), terms)
        return terms

    def _open_points(self, P, H, sel):
        """``sel`` without the exact-stick points that certainly act on nothing at ``H`` (``SKIP_OPEN``): a point whose
        gap from the centre points exceeds the normal law's band (``_active``'s) by ``SKIP_MARGIN (R1 + R2)`` and whose
        two candidate groups (its slave nodes A, B against its master beam, ``mortar.groups``' keys before the boundary
        modification, which moves a point to the other node's group only) have zero multipliers and no point within
        that band.  Such a group's disk is empty and its traction zero: its complementarity function ``C = v = 0``,
        its rows and its Schur terms vanish whatever its slip and normal, so its points' forces, tangents and slips
        change nothing Newton uses (a point kept for its other group adds nothing to this one: no normal traction, zero
        traction).  The evaluations of ``commit`` and the updates take every point (``_state``): the points' history
        and the groups' slips are those of the whole overlap.  Counted in ``_skipped``.  Not tried below ``SKIP_MIN``
        far points."""
        far = self._far[1][sel] if self._far is not None and self._far[0] is P else None
        if far is None or np.count_nonzero(far) < max(SKIP_MIN, 1):
            return sel
        nb, nn = self.n_beams, len(H)
        dec = P.decl[sel]
        mort = self._decl_exact[dec] & (P.kind[sel] == LINE) & (self._decl_mu[dec] > 0)
        far &= mort
        if np.count_nonzero(far) < max(SKIP_MIN, 1):
            return sel
        keys = (dec.astype(np.int64)[:, None] * nn + P.nodes[sel, :2]) * nb + self.el_master[P.m[sel]][:, None]
        ukeys = np.unique(keys[mort])
        hot = np.zeros(len(ukeys), dtype=bool)
        hot[np.searchsorted(ukeys, keys[mort & ~far].ravel())] = True
        hot |= np.any(self.iterate_multipliers(ukeys) != 0.0, axis=1)
        skip = far.copy()
        skip[far] = ~hot[np.searchsorted(ukeys, keys[far])].any(axis=1)
        self._skipped = int(skip.sum())
        return sel[~skip] if self._skipped else sel

    # ------------------------------------------------------------ refusals
    def element_label(self, e):
        """``Beam b 'name' element j`` for the global element id ``e``."""
        b = self.sys.model.beams[self.el_beam[e]]
        return f"Beam {b.id}" + (f" {b.name!r}" if b.name else "") + f" element {e - b.elements[0]}"

    def _pair_label(self, e, m):
        return f"{self.element_label(e)} (global {e}) against {self.element_label(m)} (global {m})"

    def _check_normals(self, P, sel, H, centres, dist=None):
        """Refuse (a step failure: cut back) pairs whose centre lines intersect: no normal
        (``centres``: ``_centres(H, P)``; ``dist``: all pairs' ``|x_F - x_C|``, if known)."""
        if dist is None:
            dist = np.linalg.norm(centres[1][sel] - centres[0][sel], axis=1)
        else:
            dist = dist[sel]      # (the same floats: a row's norm is its own)
        bad = np.flatnonzero(no_normal(dist, P.R1[sel], P.R2[sel]))
        if len(bad):
            k = sel[bad[0]]
            msg = (f"add_contact no. {int(P.decl[k])}: the centre lines of {self._pair_label(P.e[k], P.m[k])} "
                   f"intersect (distance below {NORMAL_TOL:g} (R1 + R2)): no contact normal ({len(bad)} such pairs)")
            if self._H_prev is None:          # the given (reference or initial) poses: bad input
                raise InputError(msg + " in the given poses: do two beams share a centre line? Separate them")
            raise NoContactNormal(msg)

    def _check_sides(self, P, H, centres, d=None):
        """Tunnelling: refuse (cut back) a step over which a pair changed sides.

        The centre-line distance vector ``d = x_F - x_C`` of each candidate pair (same
        elements and ``xi``) at the last converged poses and now: ``d_prev . d < 0`` means
        one beam passed through the other within the step, where the penalty, seeing
        the other side, would push them further apart and report a converged state.
        """
        if self._H_prev is None or self._H_prev.shape != H.shape or equal(self._H_prev, H):
            return              # (at the step's start, the first iterate: d_prev = d, no pair changed sides)
        d = centres[1] - centres[0] if d is None else d
        x0C, x0F = self._centres(H, P, prev=True)
        d0 = x0F - x0C
        rsum = P.R1 + P.R2
        back = np.sum(d * d0, axis=1) < -(NORMAL_TOL * rsum) ** 2
        if not back.any():
            return              # (no pair turned: the test below finds none)
        seen = ~no_normal(np.linalg.norm(d0, axis=1), P.R1, P.R2)
        flip = np.flatnonzero(seen & back)
        if len(flip):
            k = flip[0]
            raise ContactTunnelling(f"contact: {self._pair_label(P.e[k], P.m[k])} changed sides within the "
                                f"step (one beam passed through the other; {len(flip)} such pairs)")

    # ------------------------------------------------------------ evaluation
    name = "contact"         # of the contribution, in timings and evaluation details (problem.Problem)
    smooth = False           # a piecewise smooth residual: the solver backtracks on the residual

    @property
    def conservative(self):
        """Frictionless contact has a potential (symmetric tangent at equilibrium)."""
        return not any(d.mu > 0 for d in self.decls)

    def _local_blocks(self, H, tangent):
        """``(P, sel, p, f, K, out)`` at poses ``H``: pairs, active ones, kernel parameters, the contact's
        part of the residual ``f`` ``(m, 4, 6)`` (minus the kernel's wrenches, negated in place: no copy
        of the blocks), its tangent blocks ``K`` ``(m, 24, 24)`` and point data; None without active pairs.

        Kept for the same poses and contact state (``_blocks``, cleared when the state changes):
        the tangent evaluation at an accepted line-search trial reuses the trial's (the compiled
        kernel computes the tangent with the forces; the numpy oracle only when asked).
        """
        c = self._blocks
        if c is not None and equal(c[0], H) and (c[1] is None or c[1][4] is not None or not tangent):
            return c[1]
        c = None                   # (its tangent buffer may serve this evaluation: ``_tangent_out``)
        asked, tangent = tangent, tangent or self.kernel is kernel_jit
        chosen = self._chosen(H)
        if chosen is None:
            return None
        return self._kernel_blocks(H, *chosen, asked, tangent)

    def _chosen(self, H):
        """``_local_blocks``' pairs ``P`` at ``H``, the active ones ``sel`` it evaluates and their kernel parameters ``p``:
        ``(P, sel, p)``, or None without active pairs (``_blocks`` then says so for ``H``)."""
        P = self.pairs(H)
        self._lap()
        sel = np.zeros(0, dtype=int)
        if P is not None:
            centres = self._centres(H, P)
            d = centres[1] - centres[0]
            dist = np.linalg.norm(d, axis=1)
            self._check_sides(P, H, centres, d)
            sel = self._active(P, H, centres, dist)
        if len(sel) == 0:
            self._blocks = (np.array(H), None)
            return None
        self._check_normals(P, sel, H, centres, dist)
        self._skipped = 0
        if SKIP_OPEN and not self._full and self.newton_multipliers and not self.n_slots and self._decl_exact.any():
            sel = self._open_points(P, H, sel)
            if len(sel) == 0:
                self._blocks = (np.array(H), None)
                return None
        p = self._params(P, sel, H)
        self._lap("params")
        self._blocks = None        # its tangent buffer may be reused (``_tangent_out``)
        return P, sel, p

    def _kernel_blocks(self, H, P, sel, p, asked, tangent):
        """``_local_blocks``' kernels on the pairs ``_chosen`` gave (``asked``: the tangent asked for, ``tangent``:
        computed)."""
        fric = p["mu"] > 0
        mort = self._decl_exact[P.decl[sel]] & (p["kind"] == LINE) & fric
        # every pair a mortar pair whose whole tangent the mortar kernel gives (``_mortar``: points integration,
        # multipliers as unknowns): the pairs' kernel without tangent (its forces: the same bits)
        whole = tangent and self.kernel is kernel_jit and self.newton_multipliers and not self.n_slots and mort.all()
        if whole:
            # the pairs' forces (the normal law's) and point data: the mortar kernel's at zero traction (``_mortar``,
            # ``kernel_jit.mortar_terms``: the same bits as the pairs' kernel without friction; one pass, not two)
            f, K, out = None, np.empty((0, 24, 24)), {}   # (``_with_mortar``: every pair's blocks in its group's)
        else:
            f, K, out = self._kernels(np.take(H, P.nodes[sel], axis=0), p, P.decl[sel], tangent,
                                      friction=fric & ~mort if mort.any() else None)
            np.negative(f, out=f)
        if K is not None:
            np.negative(K, out=K)
        if K is not None and self.n_slots:
            # the segment ends' tangent terms: now if the tangent is asked for, else when it is (``evaluate``)
            out["segment_ends"] = fric & ~mort
            if asked:
                self._segment_ends(H, P, sel, p, f, K, out.pop("segment_ends"))
        if mort.any():
            # exact stick's terms: forces and complementarity residuals only unless the tangent is asked for (a
            # line-search trial); its blocks when it is (``evaluate``: ``mortar_pending``)
            lazy = LAZY_MORTAR and not asked
            out["mortar"] = self._mortar(H, P, sel, p, np.flatnonzero(mort), out, not lazy, f, K)
            if f is None:
                f = out["mortar"].pop("pair_f")
            if lazy:
                out["mortar_pending"] = np.flatnonzero(mort)
        self._lap("kernel")
        # kept for commit/augment at the same poses (the converged iterate): no second pass
        Hc = np.array(H)           # (read by both: never written)
        if fric.all() or not fric.any() or mort.any():
            self._cache = (Hc, P, sel, p, out)
        self._blocks = (Hc, (P, sel, p, f, K, out))
        return self._blocks[1]

    def _segment_ends(self, H, P, sel, p, f, K, friction):
        """Add the tangent terms of the moving segment ends (``segment_tangent``) to the blocks ``K`` of the
        segment points among the active pairs ``sel`` (``f``: their forces, residual signs; ``friction``: the
        kernel's friction flags).  The exact-stick multipliers' terms: ``_mortar_ends``."""
        key = P.key[sel]
        gk = (key // self.n_beams) % self.key_gp
        seg = (key < self.point_offset) & (p["kind"] == LINE) & (gk // self.max_gp < self.n_slots)
        for d in self.decls:
            idx = np.flatnonzero(seg & (P.decl[sel] == d.index))
            if not d.segments or not len(idx):
                continue
            g = gk[idx] % self.max_gp
            X = np.take(H, P.nodes[sel[idx]], axis=0)

            def forces(rows, xi):
                at = idx[rows]
                q = {k: (v[at] if np.ndim(v) else v) for k, v in p.items()}
                q["xi1"] = xi
                fk = self._kernels(X[rows], q, P.decl[sel[at]], False, friction=friction[at])[0]
                return -fk.reshape(len(rows), 24)

            segment_tangent.end_terms(X, p["xi1"][idx], p["weight"][idx], d.seg_gauss[0][g], d.seg_gauss[1][g],
                                      self.sys.L[P.e[sel[idx]]], f[idx].reshape(len(idx), 24), forces, K, idx)

    def overlap(self, H):
        """Initial overlaps at poses ``H``: ``None`` when no pair penetrates by more than
        ``OVERLAP_REPORT (R1 + R2)``, else a sentence naming the deepest pair, its penetration and
        the normal force of the overlapping points (the pre-stress they put into an unloaded model)."""
        blocks = self._local_blocks(H, False)
        if blocks is None:
            return None
        P, sel, p, f, K, out = blocks
        depth = -out["gap"] / (p["R1"] + p["R2"])
        over = depth > OVERLAP_REPORT
        if not over.any():
            return None
        k = int(np.argmax(depth))
        force = float(np.sum(p["weight"][over] * out["lam_n"][over]))
        return (f"{int(over.sum())} contact points overlap in the given poses, the deepest by "
                f"{-out['gap'][k]:.3g} ({depth[k]:.2g} (R1 + R2); {self.element_label(P.e[sel][k])} against "
                f"{self.element_label(P.m[sel][k])}): their normal force, {force:.4g} in all, pre-stresses "
                "the model at t_start")

    def _mortar(self, H, P, sel, p, idx, out, tangent=True, f_pairs=None, K_pairs=None):
        """Exact stick (``mortar.py``) on the pairs ``sel[idx]``: nodal groups, multipliers and blocks
        (residual signs: minus the forces); the point data ``lam_t``, ``stick``, ``slip``, ``HL``,
        ``HK`` of ``out`` are overwritten for these pairs.  ``f_pairs`` ``(m, 4, 6)``, ``K_pairs`` ``(m, 24, 24)``:
        the active pairs' blocks (residual signs), which these pairs' go to (``mortar.add_pairs``: the group of the
        point's node A holds all of its nodes), so that ``_with_mortar`` leaves them out (``folded``).  ``f_pairs``
        None (``_local_blocks``: every active pair a mortar pair): the pairs' forces and point data are the mortar
        kernel's at zero traction (``kernel_jit.mortar_terms(pairs=True)``), written to ``out``, the forces returned
        as ``pair_f``."""
        X = np.take(H, P.nodes[sel[idx]], axis=0)      # (``H[nodes]``'s copy: 44 -> 16 us at 640 points)
        pm = p if len(idx) == len(sel) else {k: (v[idx] if np.ndim(v) else v) for k, v in p.items()}
        ssn = self.newton_multipliers
        G, gdecl, R, Lam, eps, mu, law, RL, T_pts = self._group_state(H, P, sel[idx], pm, ssn)
        # with the updates, the four tractions' tangents pass by pass once the points' tractions are known
        # (``_mortar_passes``): not ``(4, P, 24, 24)`` at once
        defer = tangent and not ssn and CHUNKED and f_pairs is not None and not self.n_slots and \
            (K_pairs is None or len(K_pairs) == len(sel))
        d, K_pairs = self._mortar_kernel(X, pm, law, T_pts, tangent, f_pairs is None, K_pairs, G, defer)
        if not tangent:     # forces only (a trial, the commit's pass over every point): the poses not needed past the
            X = None        # kernel, nor ``A`` past the forces (below): 0.2 GB at the 61-wire strand's commit
        if f_pairs is None and "pairs" in d:    # the pairs' own kernel (``_local_blocks``: every pair a mortar pair)
            f_pairs, pair_out = d.pop("pairs")
            if not tangent:                     # (a view of the kernel's (4, P, 4, 6) forces, as ``A``)
                f_pairs = f_pairs.copy()
            np.negative(f_pairs, out=f_pairs)
            # (every active pair: ``_point_data`` below gives them their own arrays)
            blank = {} if len(idx) == len(sel) else dict(
                lam_t=np.zeros((len(idx), 2)), stick=np.ones(len(idx), dtype=bool), slip=np.zeros((len(idx), 2)))
            out.update(pair_out, active=d["active"], **blank)
        m = self._nodal_weights(G, P.e[sel[idx]])
        hold = v = None
        if ssn:
            hold, v = self._hold(G, d, m, mu, gdecl), RL
        # with the updates, the slip is integrated where the normal law acts (the kernel applies the traction
        # there); as Newton unknowns the traction field acts on every point of the overlap
        st = mortar.nodal_state(G, pm["weight"], d["S"], d["lam_n"], d["n"], R, Lam, eps, mu, m,
                                None if ssn else d["active"], hold=hold, RL=RL)
        mult = None
        if ssn:       # the multiplier itself is the traction (its complementarity function is an equation)
            st["T"] = T_pts
        if defer:
            K_pairs = self._mortar_passes(X, pm, law, d, st["T"], G, K_pairs, idx)
        d["f"] = mortar_jit.point_forces(d["A"], st["T"])
        if not tangent:
            del d["A"]
        if tangent:
            f, K, mult = self._mortar_tangent(P, sel, idx, X, pm, G, d, st, R, Lam, eps, mu, law, v, K_pairs)
        else:
            f, K = mortar.group_forces(G, d["f"]), None
        _point_data(out, idx, len(sel), G, d, st)
        if ssn:
            if tangent:
                mult["B"] = mortar.multiplier_basis(st)
            mult = dict(mult or {}, **self._multiplier_state(G, st, v, m, R, Lam, mu, gdecl))
        np.negative(f, out=f)
        if K is not None:
            np.negative(K, out=K)
        folded, own = None, f
        if f_pairs is not None:
            own = f.copy()           # the groups' own forces (the force levels: ``_with_mortar``)
            mortar.add_pairs(G, f, None, f_pairs.reshape(-1, 24)[idx], None)
            folded = idx
        return dict(members=G["members"], f=f, K=K, key=G["key"], decl=gdecl,
                    lam=v if ssn else st["lam"], u=st["u"], stick=st["stick"], R=R, m=m, lamN=st["lamN"],
                    mult=mult, folded=folded, f_own=own, pair_f=f_pairs.reshape(-1, 4, 6) if f_pairs is not None else None)

    def _commit_mortar(self, H, P, sel, p, out):
        """``_mortar``'s point data and groups' state (multipliers as Newton unknowns) on the active pairs ``sel``, every
        one a mortar pair, as the evaluation without tangent computes them (``_kernel_blocks``' whole path), without
        their forces: the mortar kernel's point data alone (``kernel_jit.mortar_data``, the same bits as
        ``mortar_forces``'), the groups, ``mortar.nodal_state`` and ``_point_data`` into ``out`` as there.  What
        ``commit`` stores (frames, slips, tractions, the groups' slips, multipliers and status) and ``results``
        reports; the dict of ``_mortar`` without ``f``, ``K`` and the multiplier blocks (and without ``members`` unless
        the groups were kept with them).  The history's frames ``HISTORY_FRAMES`` are taken out of ``p`` after the
        kernel (``commit``, ``augment`` and ``results`` read none of them)."""
        n = len(sel)
        idx = np.arange(n)
        # the groups without their members and slots (kept so: the next evaluation of these pairs builds those)
        G, gdecl, R, Lam, eps, mu, law, RL, T_pts = self._group_state(H, P, sel, p, True, full=False)
        if LEAN_COMMIT:       # a pass's poses, two frames of a point kept (0.1 GB each at the 61-wire strand's commit)
            d = kernel_jit.mortar_data_of(H, P.nodes[sel], p, law)
        else:
            d = kernel_jit.mortar_data(H[P.nodes[sel]], p, law)   # (its poses not held past it: 0.1 GB at the
        #                                                          61-wire strand's commit)
        for k in HISTORY_FRAMES:    # the kernel's alone: not kept with ``p`` (``_cache``, ``_last``; 79 MB there)
            p.pop(k, None)
        self.history.forget_rows()  # (nor with ``frictional``'s kept rows)
        out.update(d.pop("pairs")[1], active=d["active"], lam_t=np.zeros((n, 2)), stick=np.ones(n, dtype=bool),
                   slip=np.zeros((n, 2)))
        m = self._nodal_weights(G, P.e[sel]) if "members" in G else self._nodal_weights_of(G, P.e[sel])
        hold = self._hold(G, d, m, mu, gdecl)
        st = mortar.nodal_state(G, p["weight"], d["S"], d["lam_n"], d["n"], R, Lam, eps, mu, m, None, hold=hold, RL=RL)
        st["T"] = T_pts
        _point_data(out, idx, n, G, d, st)
        mult = self._multiplier_state(G, st, RL, m, R, Lam, mu, gdecl)
        return dict(members=G.get("members"), f=None, K=None, key=G["key"], decl=gdecl, lam=RL, u=st["u"],
                    stick=st["stick"], R=R, m=m, lamN=st["lamN"], mult=mult, folded=None, f_own=None, pair_f=None)

    def _group_state(self, H, P, rows, p, ssn, full=True):
        """The nodal groups of the pairs ``rows`` of ``P`` (point data ``p``; ``full``: with members and slots) and
        their state: ``(G, gdecl, R, Lam, eps, mu, law, RL, T_pts)``: declarations, node rotations, multipliers (the
        iterate's as Newton unknowns (``ssn``), else the updates' history), ``c``, ``mu``, the law, the multipliers'
        global tractions ``R Lam`` and, with ``ssn``, the points' tractions (the multipliers interpolated)."""
        n_nodes = len(H)
        nodes = P.nodes[rows]
        G = self._groups(nodes[:, :2], p["xi1"], self.el_master[P.m[rows]], P.decl[rows], nodes, n_nodes,
                         self.n_beams, self._held_slip(nodes), full=full)
        gdecl = G["key"] // (np.int64(n_nodes) * self.n_beams)
        R = H[G["node"], :3, :3]
        Lam = self.iterate_multipliers(G["key"]) if ssn else self.history.tangential_multipliers(G["key"])
        eps, mu = (self._decl_eps_t if ssn else self._decl_aug_t)[gdecl], self._decl_mu[gdecl]
        if ssn:
            eps = self._balanced_c(G["key"], eps)
        law = self._mortar_law(gdecl)
        RL = mortar_jit.rotate(R, Lam)        # the multipliers' tractions (global; einsum's bits)
        T_pts = mortar_jit.interpolate(G["phi"], RL, G["g"]) if ssn else None
        return G, gdecl, R, Lam, eps, mu, law, RL, T_pts

    def _hold(self, G, d, m, mu, gdecl):
        """Groups with a point in the normal law's band (kernel data ``d``): the point law's stiffness floor
        (mortar.py); 0 elsewhere."""
        touch = np.bincount(G["g"].ravel(), weights=np.repeat(d["active"].astype(float), 2), minlength=len(m))
        return np.where(touch > 0, mu * PENALTY_T_MIN * self._decl_penalty[gdecl], 0.0)

    def _multiplier_state(self, G, st, RL, m, R, Lam, mu, gdecl):
        """What Newton keeps of the groups with multipliers as unknowns: complementarity residual ``C``, weights,
        members, frames, multipliers, keys, status, slips, tolerances and Coulomb caps."""
        return dict(C=RL - st["lam"], m=m, members=G.get("members"), R=R, Lam=Lam, key=G["key"], stick=st["stick"],
                    u=st["u"], tol=self._decl_stick_tol[gdecl], cap=mu * np.maximum(st["lamN"], 0.0))

    def _mortar_law(self, gdecl):
        """The one contact law of the declarations ``gdecl`` of the mortar groups (``InputError`` if they differ)."""
        laws = {id(self.decls[0].law): self.decls[0].law} if len(self.decls) == 1 else \
            {id(self.decls[k].law): self.decls[k].law for k in np.unique(gdecl)}
        if len(laws) > 1:
            raise InputError("contact: exact stick needs one contact law over the declarations of a scene, "
                             f"got {len(laws)}")
        return next(iter(laws.values()))

    def _mortar_kernel(self, X, pm, law, T_pts, tangent, pairs, K_pairs, G=None, defer=False):
        """``(d, K_pairs)``: the mortar kernel's point terms of ``_mortar`` (forces only without ``tangent``; with the
        multipliers as Newton unknowns, ``T_pts`` given, the tangent at the points' tractions) and the pairs' own
        blocks still to fold in (None where the kernel's ``dfdq`` holds them); ``pairs``: the pairs' own forces
        and point data too (``kernel_jit.mortar_terms(pairs=True)``).  With the whole tangent at ``T_pts`` and the
        groups ``G`` (``CHUNKED``), the points' tangents go to the groups' blocks pass by pass (``mortar.block_sink``,
        ``d["Kqq"]``) instead of ``d["dfdq"]`` ``(P, 24, 24)``.  ``defer`` (the updates, ``T_pts`` None): the point
        data alone (``kernel_jit.mortar_data``, the same bits); ``_mortar_passes`` adds the tangent's terms."""
        if not tangent:
            return kernel_jit.mortar_forces(X, pm, law, pairs=pairs), K_pairs
        if T_pts is None and defer:
            d = kernel_jit.mortar_data(X, pm, law)
            del d["pairs"]
            return d, K_pairs
        if T_pts is None:
            return kernel_jit.mortar_terms(X, pm, law), K_pairs
        # the points' tractions are known (the multipliers): the tangent at them, two not four (one, the normal
        # law's included, where the pairs' own tangent has no segment ends' terms to keep)
        whole = K_pairs is not None and not self.n_slots
        Kqq, sink = mortar.block_sink(G) if whole and CHUNKED and G is not None else (None, None)
        d = kernel_jit.mortar_terms(X, pm, law, T=T_pts, whole=whole, pairs=pairs, sink=sink)
        if sink is not None:
            d["Kqq"] = Kqq
        return d, (None if whole and (d.get("dfdq") is not None or "Kqq" in d) else K_pairs)

    def _mortar_passes(self, X, pm, law, d, T, G, K_pairs, idx):
        """The tangent's terms of ``_mortar`` with the updates (``defer``: ``d`` the point data of
        ``kernel_jit.mortar_data``, ``T`` ``(P, 3)`` the points' tractions of ``mortar.nodal_state``): the mortar
        kernel at the four tractions ``kernel_jit.MORTAR_CHUNK`` points at a time (``mortar_terms(sink=)``), each
        pass's ``dfdq = sum_k T_k dK_k`` less the pairs' own blocks ``K_pairs`` (rows ``idx``) into the groups'
        blocks (``mortar.block_sink``: ``d["Kqq"]``), and ``A``, ``G``, ``dS``, ``dn``, ``dlam_n`` into ``d``: the
        same operations per point as ``mortar_terms`` and ``_mortar_tangent`` on the whole arrays, the same bits,
        without the ``(4, P, 24, 24)`` tangents (0.4 GB at the 61-wire strand's step 0) nor ``dfdq``.  Returns None
        (the pairs' blocks folded in)."""
        Kqq, sink = mortar.block_sink(G)

        def passed(a, b, dK):
            dfdq = np.einsum("pk,pkij->pij", T[a:b], dK)
            if K_pairs is not None:
                mortar_jit.subtract_indexed(dfdq, K_pairs, idx[a:b])
            sink(a, b, dfdq)
        terms = kernel_jit.mortar_terms(X, pm, law, sink=passed)
        d.update({k: terms[k] for k in ("A", "G", "dS", "dn", "dlam_n")}, Kqq=Kqq)
        return None

    def _nodal_weights(self, G, e):
        """``m`` ``(n,)`` of the groups ``G`` (``mortar.nodal_state``), their points on the slave elements ``e``:
        half of each element at the node, the whole element beside a held node."""
        c = self._kept_weights              # (kept while the groups, ``mortar.Groups``, and the elements hold)
        if c is not None and c[0] is G["members"] and equal(c[1], e):
            return c[2]
        m = self._nodal_weights_of(G, e)
        self._kept_weights = (G["members"], np.array(e), m)
        return m

    def _nodal_weights_of(self, G, e):
        L = self.sys.L
        one = G["g"][:, 0] == G["g"][:, 1]
        merged = np.unique(G["g"][:, 0][one] * np.int64(len(L)) + e[one])
        return self._node_len[G["node"]] + np.bincount(merged // len(L), weights=0.5 * L[merged % len(L)],
                                                       minlength=len(G["key"]))

    def _mortar_tangent(self, P, sel, idx, X, pm, G, d, st, R, Lam, eps, mu, law, v, K_pairs):
        """``_mortar``'s blocks with the tangent: ``(f, K, mult)`` (forces and tangent blocks of the groups, the
        multiplier blocks with exact stick's multipliers as Newton unknowns, else None); ``v`` the multipliers'
        tractions (None with the updates), ``K_pairs`` the pairs' own blocks to fold in (or None)."""
        ssn = v is not None
        if "G" not in d:        # (``kernel_jit.mortar_terms`` gives it contiguous)
            d["G"] = d["A"]
        if d.get("dfdq") is None and "Kqq" not in d:
            d["dfdq"] = np.einsum("pk,pkij->pij", st["T"], d["dK"])
        if K_pairs is not None:      # the points' own (normal) blocks go to their groups with the friction's
            rows = idx
            if len(K_pairs) < len(sel):     # left out by ``_local_blocks`` (a kernel without ``whole``: oracles)
                K_pairs = -self._kernels(X, pm, P.decl[sel[idx]], True, friction=False)[1]
                rows = np.arange(len(idx))
            mortar_jit.subtract_indexed(d["dfdq"], K_pairs, rows)
        mult = None
        if ssn:
            turn = mortar._turn(G, R, Lam)      # (the node's turn: one product for both)
            f, K, Kql, Klq, Kll, C = mortar.multiplier_blocks(G, d, st, R, Lam, eps, mu, turn=turn)
            mult = dict(Kql=-Kql, Klq=Klq, Kll=Kll)
            if self.branch_rows and not self.n_slots:   # the active-set inner loop's rows (not with segments' ends)
                Tq, Vq, capq = mortar.branch_rows(G, d, st, R, Lam, eps, mu, turn=turn)
                mult.update(Tq=Tq, Vq=Vq, capq=capq, trial=st["trial"], cap=mu * np.maximum(st["lamN"], 0.0),
                            Pi=st["Pi"], weak=st["weak"] | (st["lamN"] <= 0.0))
        else:
            f, K = mortar.blocks(G, d, st, R, Lam, eps, mu)
        if self.n_slots:
            ends = self._mortar_ends(P, sel, idx, X, pm, G, d, st, v if ssn else st["lam"], eps, mu, law,
                                     None if ssn else d["active"])
            if ends is not None:
                F, B = ends
                weak = st["weak"] if ssn else np.ones(len(st["m"]), dtype=bool)
                A = np.einsum("gij,gkj->gik", Kql, R) if ssn else mortar._point_parts(G, d)[2]
                K += F
                K[weak] += A[weak] @ B[weak]
                if ssn:
                    B[weak] = 0.0
                    Klq -= B
        return f, K, mult

    def _mortar_ends(self, P, sel, idx, X, pm, G, d, st, vals, eps, mu, law, active):
        """The exact-stick terms of the moving segment ends (``segment_tangent.mortar_end_terms``) of the
        mortar points ``sel[idx]`` (``_mortar``'s data): ``(F, B)``, or None without such points."""
        key = P.key[sel[idx]]
        gk = (key // self.n_beams) % self.key_gp
        seg = (key < self.point_offset) & (pm["kind"] == LINE) & (gk // self.max_gp < self.n_slots)
        x_g, w_g = np.full(len(idx), 0.5), np.ones(len(idx))
        on = np.zeros(len(idx), dtype=bool)
        for dc in self.decls:
            k = seg & (P.decl[sel[idx]] == dc.index)
            if dc.segments and k.any():
                g = gk[k] % self.max_gp
                x_g[k], w_g[k], on[k] = dc.seg_gauss[0][g], dc.seg_gauss[1][g], True
        pts = np.flatnonzero(on)
        if not len(pts):
            return None
        rows, dxi, dW = segment_tangent.end_derivatives(X[pts], pm["xi1"][pts], pm["weight"][pts], x_g[pts],
                                                        w_g[pts], self.sys.L[P.e[sel[idx[pts]]]])
        if not len(rows):
            return None
        rows = pts[rows]
        q = {k: (v[rows] if np.ndim(v) else v) for k, v in pm.items()}
        q["xi1"] = pm["xi1"][rows] + segment_tangent.STEP
        shifted = segment_tangent.mortar_shifted(X[rows], q, st["T"][rows], law)
        return segment_tangent.mortar_end_terms(G, d, st, vals, eps, mu, rows, dxi, dW, pm["weight"], shifted, active)

    def _held_slip(self, nodes):
        """``(P, 2)``: slave nodes A, B of the pairs over ``nodes`` ``(P, 4)`` whose slip is prescribed:
        every increment fixed, or joined to a node of the master element (``mortar.groups``); kept (read only) while
        ``nodes`` are the same (a Newton step's evaluations)."""
        c = self._held_of
        if c is not None and equal(c[0], nodes):
            return c[1]
        r = self.sys.rep[nodes]
        joined = (r[:, :2, None] == r[:, None, 2:]).any(axis=2)
        held = self._held[nodes[:, :2]] | joined
        held.flags.writeable = False
        self._held_of = (np.array(nodes), held)
        return held

    def kernel_inputs(self, H):
        """Node poses ``(m, 4, 4, 4)`` and kernel parameters (dict of arrays) of the pairs active at
        ``H``, as the kernel receives them (benchmarks, tests); ``None`` without active pairs."""
        P = self.pairs(H)
        if P is None:
            return None
        sel = self._active(P, H)
        if len(sel) == 0:
            return None
        return H[P.nodes[sel]], self._params(P, sel, H)

    def _kernels(self, X, p, decl, tangent, friction=None):
        """The kernel of each declaration's law on the pairs with friction and on those without
        (``friction``: the friction branch for all): ``f``, ``K`` (or None), ``out``."""
        laws = [d.law for d in self.decls]
        compiled = self.kernel is kernel_jit
        if any(law is not None for law in laws) and not compiled:
            raise InputError("contact: the numpy oracle kernel (use_numpy_kernel) has only the default law; "
                             f"add_contact declared law={next(law for law in laws if law is not None)!r}")
        fric = p["mu"] > 0 if friction is None else np.broadcast_to(friction, (len(X),))
        if len(laws) == 1:          # one declaration: the friction flag is the group
            group = fric.astype(np.int64)
            kinds = np.flatnonzero([not fric.all(), fric.any()])
        else:
            group = np.unique([id(law) for law in laws], return_inverse=True)[1][decl] * 2 + fric
            kinds = np.unique(group)
        if len(kinds) == 1:                     # one kind: no masked copies of the (m, 24, 24) blocks
            out = self._tangent_out(len(X)) if tangent and compiled else None
            return _kernel(self.kernel, X, p, bool(kinds[0] % 2), laws[decl[0]], tangent, out)
        f = np.zeros((len(X), 4, 6))
        K = np.zeros((len(X), 24, 24)) if tangent else None
        out = {}
        for g in kinds:
            mask = group == g
            pm = {k: (v[mask] if np.ndim(v) else v) for k, v in p.items()}
            fm, Km, om = _kernel(self.kernel, X[mask], pm, bool(g % 2), laws[decl[np.argmax(mask)]], tangent)
            if tangent:
                K[mask] = Km
            f[mask] = fm
            for k, v in om.items():
                if k not in out:
                    out[k] = np.zeros((len(X),) + np.shape(v)[1:], dtype=np.asarray(v).dtype)
                out[k][mask] = v
        return f, K, out

    def _tangent_out(self, m):
        """An ``(m, 24, 24)`` array for the compiled kernel's tangent (``buffers.BufferPool``): a view of
        a kept buffer that nothing else references (blocks of an earlier evaluation may still be in
        use, e.g. the solver's last evaluation during a line search), else of a new buffer; at most
        two kept.  Reusing memory avoids the page faults of a fresh array per evaluation."""
        return self._tangent_pool.take((m, 24, 24))

    def evaluate(self, H, tangent=True):
        """Local blocks of the active pairs and point data: ``(blocks.Blocks, info)``.

        Blocks over the pair's 4 nodes (slave A, B, master A, B): ``f`` ``(m, 24)`` is the
        contact's part of the residual (minus the contact forces on the nodes) and ``K``
        ``(m, 24, 24)`` its derivative in the nodes' body increments; the generic assembler
        (``assembly.System.assemble_blocks``) transforms and scatters them.  The kernel's results
        are kept for the same poses and state (``_local_blocks``).
        """
        blocks = self._local_blocks(H, tangent)
        self._lap()
        if blocks is None:
            return Blocks.empty(4, tangent), dict(n_active=0)
        P, sel, p, f, K, out = blocks
        if tangent and K is not None and "segment_ends" in out:
            self._segment_ends(H, P, sel, p, f, K, out.pop("segment_ends"))
        if tangent and K is not None and "mortar_pending" in out:
            out["mortar"] = self._mortar(H, P, sel, p, out.pop("mortar_pending"), out, True, f, K)
        info = dict(n_active=len(sel))
        if "mortar" in out:
            b = _with_mortar(P.nodes[sel], f.reshape(-1, 24), K if tangent else None, out["mortar"],
                             self._mortar_pool)
            if b.K is not None and b.K is out["mortar"]["K"]:
                # handed over (the Newton system adds to them in place, ``Problem.linear_system``): a second
                # evaluation of these poses computes them again
                out["mortar"]["K"] = None
                out["mortar_pending"] = out["mortar"]["folded"]
            if out["mortar"]["mult"] is not None:
                info["multipliers"] = out["mortar"]["mult"]
        else:
            b = Blocks(P.nodes[sel], f.reshape(-1, 24), K if tangent else None)
        self._lap("blocks")
        return b, info

    # ------------------------------------------------------------ the normal law's branches (an option)
    def pressed_points(self, H, law=False, tangent=False):
        """Sorted keys of the points whose normal law presses at poses ``H`` (``lam_n > 0``); with ``law``,
        ``(keys, lam_n, gap, parabola)`` in that order, ``parabola`` where the traction is on the smoothing parabola
        (``0 < lam_n < penalty smoothing``, docs/theory/contact_laws.md 7.2).  ``tangent``: the blocks behind them
        (``_local_blocks``, kept for an ``evaluate`` of the same poses) with the tangent, as ``evaluate(H, True)``
        asks for it (``newton.TANGENT_AT_PRESSED``: the line search's trial then needs no second pass)."""
        blocks = self._local_blocks(H, tangent)
        if blocks is None:
            e = np.zeros(0, dtype=np.int64)
            return (e, np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool)) if law else e
        P, sel, p, _, _, out = blocks
        on = out["lam_n"] > 0
        key = P.key[sel][on]
        order = np.argsort(key)
        if not law:
            return key[order]
        lam = out["lam_n"][on][order]
        return key[order], lam, out["gap"][on][order], lam < (p["penalty"] * p["smoothing"])[on][order]

    def force_open(self, keys):
        """Evaluate the points ``keys`` (sorted; None: none) on the normal law's open branch (no normal force, no
        stiffness): Newton's active-set step for the normal law (``nonlinear.newton.NORMAL_SWITCHES``)."""
        forced = None if keys is None else np.asarray(keys, dtype=np.int64)
        if forced is None and self._forced is None:
            return                 # nothing forced before nor now: the kept blocks stay valid (``_local_blocks``)
        self._forced = forced
        self._blocks = None

    def force_secant(self, keys, gaps=None, reach=1.0):
        """Evaluate the points ``keys`` (sorted; None: none) on the secant of the normal law's smoothing parabola from
        their traction at the gaps ``gaps`` to the share ``reach`` of the way to its zero-force end (the gap ``w``),
        until called again: the same traction there, ``1 / (2 reach)`` times the stiffness.  Newton's step then takes
        a point whose traction falls to zero that far in one iteration where the parabola's tangent halves its distance
        to the end (a double root: ``newton.START_SECANT``)."""
        if keys is None and self._secant is None:
            return
        self._secant = None if keys is None else (np.asarray(keys, dtype=np.int64), np.asarray(gaps, dtype=float),
                                                  float(reach))
        self._blocks = None

    def _secant_law(self, key, p):
        """``force_secant``'s law in the kernel parameters ``p`` of the points ``key``: the parabola
        ``(x + W)^2 / (4 W)``, ``x = m - eps g``, ``W = eps w``, through the point's traction at its gap ``g0`` with
        ``k = 1 / (2 reach)`` times its slope is the parabola of ``W' = W / k^2`` with ``x' + W' = (x + W) / k``:
        smoothing ``w / k^2`` and multiplier ``(x0 + W) / k - W / k^2 + eps g0``, ``x0 = m - eps g0``."""
        keys, gaps, reach = self._secant
        if not len(keys):
            return
        i = np.minimum(np.searchsorted(keys, key), len(keys) - 1)
        on = keys[i] == key
        if not on.any():
            return
        pen, w, m = p["penalty"], p["smoothing"], p["multiplier"]
        k = 0.5 / reach
        W, pg = pen * w, pen * gaps[i]
        p["multiplier"] = np.where(on, (m - pg + W) / k - W / k**2 + pg, m)
        p["smoothing"] = np.where(on, w / k**2, w)

    # ------------------------------------------------------------ multipliers as Newton unknowns
    def _sliding_c(self, m):
        """``(keys, f)`` (sorted keys): the factor ``clip(|u_g| / max |u|, SLIP_C_FLOOR, 1)`` of ``c`` of the groups
        of a converged state's mortar data ``m`` (sticking ones included: their slip is below the tolerance), ``max |u|``
        over their declaration's sliding groups; 1 in a declaration where none slid or where ``c max |u|`` is below
        ``SLIP_C_RULES`` times the median traction of its sliding groups (the slip does not rule their trials: the twisted
        pair's and the shear lag's sliding groups, ``c |u| / |lam|`` 0.01 .. 2, got slower with a lower ``c``; ``_balanced_c``);
        None when ``SLIP_C`` is off or no group slid."""
        if not SLIP_C:
            return None
        lam, u = np.linalg.norm(m["lam"], axis=1), np.linalg.norm(m["u"], axis=1)
        slid = ~m["stick"] & (lam > 0.0) & (u > 0.0)
        if not slid.any():
            return None
        eps = self._decl_eps_t
        umax, lmed = np.zeros(len(eps)), np.zeros(len(eps))
        np.maximum.at(umax, m["decl"][slid], u[slid])
        for k in np.unique(m["decl"][slid]):
            lmed[k] = np.median(lam[slid & (m["decl"] == k)])
        umax[eps * umax <= SLIP_C_RULES * lmed] = 0.0      # the slip does not rule the trials: c stays
        top = umax[m["decl"]]
        keys = np.asarray(m["key"])
        f = np.where(top > 0.0, np.clip(u / np.where(top > 0.0, top, 1.0), SLIP_C_FLOOR, 1.0), 1.0)
        order = np.argsort(keys)
        return keys[order], f[order]

    def _balanced_c(self, keys, eps):
        """``c`` ``(k,)`` of exact stick's complementarity function for the groups ``keys`` (declarations' ``eps``):
        lowered for a group of the last converged step in proportion to its slip against the largest sliding one of
        its declaration (``_sliding_c``; docs/theory_mortar.md section 3d).

        ``c`` weighs a slip against a traction in the trial ``v + c u``, and is not in the equations a solution
        meets.  A group whose slip is a small fraction of its neighbours' (a nearly sticking one) with the
        declaration's ``c`` has a stick band ``|u| < (mu lamN - |v|) / c`` of picometres and a sliding direction
        that is its slip's: Newton's corrections reversed that slip from one iterate to the next (measured on
        the extreme twisted pair: the slip direction of the sliding groups turned by 180 degrees while the force
        residual fell a thousandfold, the Armijo test refused the full steps and the line search crawled)."""
        sc = self._slide_c
        if sc is None or not len(keys):
            return eps
        i = np.minimum(np.searchsorted(sc[0], keys), len(sc[0]) - 1)
        found = sc[0][i] == keys
        return np.where(found, eps * sc[1][i], eps)

    def iterate_multipliers(self, keys):
        """Nodal multipliers ``(k, 3)`` of the groups ``keys`` at the current iterate: the trial ones of the
        step (``history``) plus the trial length times the last Newton step of the multipliers."""
        c = self._kept_lam         # (the same groups and multipliers as the last call: the same look-ups)
        tmult, step = self.history.tmult, self._mstep
        if c is None or c[1] is not tmult or not equal(c[0], keys):
            c = self._kept_lam = (np.array(keys), tmult, self.history.tangential_multipliers(keys), None, None)
        Lam = c[2].copy()
        if step is not None and self._ms != 0.0:
            if c[3] is not step:
                i = np.minimum(np.searchsorted(step[0], keys), max(len(step[0]) - 1, 0))
                found = (step[0][i] == keys) if len(step[0]) else np.zeros(len(keys), dtype=bool)
                c = self._kept_lam = c[:3] + (step, (found, i[found]))
            found, rows = c[4]
            Lam[found] += self._ms * step[1][rows]
        return Lam

    def multiplier_step(self, keys, dLam, stick=None, cap=None):
        """The Newton step ``dLam`` ``(k, 3)`` of the multipliers of the groups ``keys`` (sorted); trial length 0.
        The multipliers of groups the step's iterate did not have (no contact point: they acted nowhere there)
        are set to zero: a group coming back starts without traction, not with a value Newton never saw (on the
        twisted pair such stale tractions at the contact zone's ends kept the multipliers' residual at 1e-6)."""
        keys = np.asarray(keys)
        old_keys, old = self.history.tmult
        gone = ~np.isin(old_keys, keys)
        if gone.any() and np.any(old[gone]):
            self.history.update_multipliers(None, (old_keys, np.where(gone[:, None], 0.0, old)))
        dLam = np.asarray(dLam).reshape(-1, 3)
        if self._first and stick is not None and cap is not None:
            dLam = self._first_slide(keys, dLam, np.asarray(stick), np.asarray(cap))
        self._first = False
        self._mstep, self._ms = (keys, dLam), 0.0

    def _first_slide(self, keys, dLam, stick, cap):
        """The step's first Newton step ``dLam`` ``(k, 3)`` of the groups ``keys``, with the groups not sticking at its
        iterate (``stick`` ``(k,)``, ``cap`` ``(k,)`` their disks' radii ``mu lamN`` there) ending out of their
        linearised disk: ``f (Lam + dLam) - Lam``, ``f = 1 + FIRST_SLIDE | |Lam + dLam| / cap - 1 |`` (at most
        ``FIRST_SLIDE_MAX``).  That step (the predictor's, which carries the prescribed motions) puts a sliding
        group's traction on its linearised disk (``|Lam + dLam|``), and at the next iterate the disk's
        nonlinearity decided whether it sticks: the twisted pair at t = 0.4375, where the disks of its four sliding
        groups grew by 31 % linearised and 45 % in fact, three of them stuck with slips of 1e5-1e6 times their
        tolerance (``c |u|`` 0.2-2.4 % of the disk), and Newton, reversing those slips, threw every group out of its
        disk (stick counts 11, 14, 3, 1): a failed attempt.  The margin follows the disk's change, so a step whose
        disks hardly change (a strand bent in full slip) is hardly touched.  Like ``SLID_START`` an initial guess:
        the equations are unchanged."""
        s = ~stick & (cap > 0.0)
        if FIRST_SLIDE == 0.0 or not s.any():
            return dLam
        Lam = self.iterate_multipliers(keys)
        if FIRST_SLIDE_GROWN:
            # only where the disk grows and the traction keeps its direction
            n = np.linalg.norm(Lam + dLam, axis=1)
            s &= (n > cap) & (np.sum(Lam * (Lam + dLam), axis=1) > 0.0)
            if not s.any():
                return dLam
        new = Lam[s] + dLam[s]
        f = np.minimum(1.0 + FIRST_SLIDE * np.abs(np.linalg.norm(new, axis=1) / cap[s] - 1.0), FIRST_SLIDE_MAX)
        out = dLam.copy()
        out[s] = f[:, None] * new - Lam[s]
        return out

    def multiplier_trial(self, s):
        """The iterate's multipliers are the step's plus ``s`` times the last Newton step."""
        if s != self._ms and self._mstep is not None:
            self._ms = s
            self._blocks = None

    def accept_multipliers(self):
        """The trial multipliers become the step's (``history``): the next Newton step starts from them."""
        if self._mstep is None or self._ms == 0.0:
            self._mstep, self._ms = None, 0.0
            return
        old = self.history.tmult
        keys = np.union1d(old[0], self._mstep[0])
        vals = self.iterate_multipliers(keys)
        self.history.update_multipliers(None, (keys, vals))
        self._mstep, self._ms = None, 0.0

    # ------------------------------------------------------------ per step
    def begin_step(self, H, t):
        """A step from the converged poses ``H`` to time ``t`` starts (or starts again after a failure):
        the declarations acting at ``t``, the trial history reset to the committed one."""
        self._switch_to(t)
        self._blocks = None
        self.history.begin_step()
        self._H_prev = np.array(H, dtype=float)
        self._geo_prev = None
        self._prev_points = None
        self._augments = 0
        self._mstep, self._ms = None, 0.0
        self._first = True
        self._t_step = t
        if EXTRAPOLATE and self._decl_exact.any() and self.newton_multipliers:
            self._extrapolate(t)

    def _extrapolate(self, t):
        """Exact stick's first multipliers of the step to ``t``: linear in ``t`` through the last two converged
        steps' (``_commits``; docs/theory_mortar.md, section 3c), for the groups both have (the others start from
        the last step's, as before).  Only forwards (``t`` beyond the last step) and with two distinct times."""
        c = self._commits
        if len(c) < 2 or None in (c[-1][0], c[-2][0]) or c[-1][0] <= c[-2][0]:
            return
        (t0, (k0, L0)), (t1, (k1, L1)) = c[-2], c[-1]
        if t <= t1 or not len(k1):
            return
        i, found = history_lookup(k0, k1)
        vals = L1.copy()
        s = (t - t1) / (t1 - t0)
        vals[found] += s * (L1[found] - L0[i[found]])
        if self._slid is not None and SLID_START != 1.0:
            # a group that slid in the last step has its traction on the disk's edge: unscaled, round-off decides
            # whether a step's first iterate (no slip yet) sticks, and half of them did (the strand bent in full
            # slip: 560 of 1146 groups sticking at the first iterate, 54 at the end, ~8 Newton iterations to get there)
            vals[np.isin(k1, self._slid)] *= SLID_START
        self.history.update_multipliers(None, (k1, vals))

    def _state(self, H, commit=False):
        """``(P, sel, (p, out))`` at ``H``: the pairs, the active ones (every one: the points ``_open_points`` leaves out
        of Newton's evaluations too) and their kernel parameters and point data (exact stick's: ``out["mortar"]``),
        for ``commit`` and ``augment``; ``(None, None, None)`` without pairs.  ``commit`` (``LIGHT_COMMIT``): where
        every active pair is a mortar pair of the compiled kernel (``_kernel_blocks``' whole path), their point data
        and the groups' state without the forces (``_commit_mortar``), the same bits as the evaluation's; no blocks
        are kept for ``H`` then (the next step's ``begin_step`` clears them; the stepping drivers evaluate nothing
        between).  ``augment`` takes the evaluation: its blocks at ``H`` serve the evaluations that may follow there
        before the commit (a stability check)."""
        if self._decl_exact.any():      # the mortar pass: through the evaluation (kept for these poses)
            if self._skipped:           # an evaluation that left points out (``_open_points``): every point
                self._blocks, self._cache = None, None
            self._full = True
            try:
                if commit and LIGHT_COMMIT and self._blocks is None and self.kernel is kernel_jit and \
                        self.newton_multipliers and not self.n_slots:
                    chosen = self._chosen(H)
                    if chosen is not None:
                        P, sel, p = chosen
                        if (self._decl_exact[P.decl[sel]] & (p["kind"] == LINE) & (p["mu"] > 0)).all():
                            out = {}
                            out["mortar"] = self._commit_mortar(H, P, sel, p, out)
                            self._lap("kernel")
                            self._cache = (H.copy(), P, sel, p, out)
                            return P, sel, (p, out)
                        self._kernel_blocks(H, P, sel, p, False, True)
                else:
                    self._local_blocks(H, False)
            finally:
                self._full = False
        cache = getattr(self, "_cache", None)
        if cache is not None and cache[0].shape == H.shape and equal(cache[0], H):
            _, P, sel, p, out = cache
            if p["mu"].any() or "HL" not in out:
                return P, sel, (p, out)
        P = self.pairs(H)
        if P is None:
            return None, None, None
        sel = self._active(P, H)
        p = self._params(P, sel, H)
        out = {}
        if len(sel):
            fric = p["mu"] > 0
            # the full kernel (with friction frames) for every active pair
            _, _, out = self._kernels(H[P.nodes[sel]], p, P.decl[sel], False, friction=bool(fric.any()))
            if not fric.any():
                out["slip"] = np.zeros((len(sel), 2))
        return P, sel, (p, out)

    def repeat_step(self, H):
        """The outer iteration of ``problem.Problem``: an augmented-Lagrangian update (``augment``)."""
        return self.augment(H)

    def unmet(self, t):
        """Why the last step may not be accepted (penetration above the tolerance after
        ``MAX_AUGMENT`` updates), or ``None``."""
        if not getattr(self, "unmet_tolerance", None):
            return None
        return (f"augmented Lagrangian: after {self._augments} updates the penetration (or, with "
                f"stick='exact', a sticking node's slip) is {self.unmet_tolerance:.3g} times the requested "
                f"tolerance at t = {t:.6g}")

    def augment(self, H):
        """Augmented-Lagrangian update; True when the step must be re-solved.

        Normal multipliers where the penetration exceeds ``tolerance``; with exact stick, the nodal
        tangential multipliers (``mortar.py``) where a sticking node's weighted slip exceeds
        ``stick_tolerance``.  After ``MAX_AUGMENT`` updates without meeting the tolerances it returns
        False with ``unmet_tolerance`` set to the largest ratio penetration or slip / tolerance
        (else ``None``)."""
        self.unmet_tolerance = None
        tol = [d.tolerance for d in self.decls]
        if all(t is None for t in tol) and not (self._decl_exact.any() and not self.newton_multipliers):
            return False
        P, sel, po = self._state(H)
        if P is None or len(sel) == 0:
            return False
        p, out = po
        gap = out["gap"]
        tols = self._decl_tolerance[P.decl[sel]]
        ratio, mult, tmult = 0.0, None, None
        if np.any(-gap > tols):
            ratio = float(np.max(-gap / tols))
            keys = P.key[sel]
            lam = np.where(np.isfinite(tols), out["lam_n"], 0.0)
            order = np.argsort(keys)
            mult = (keys[order], lam[order])
        m = out.get("mortar")
        if m is not None and not self.newton_multipliers:
            slip, stol = np.linalg.norm(m["u"], axis=1), self._decl_stick_tol[m["decl"]]
            bad = m["stick"] & (slip > stol)
            if bad.any():
                ratio = max(ratio, float(np.max(slip[bad] / stol[bad])))
                tmult = (m["key"], np.einsum("gji,gj->gi", m["R"], m["lam"]))
        if ratio == 0.0:
            return False
        if self._augments >= MAX_AUGMENT:      # not met: the caller decides (error or warning)
            self.unmet_tolerance = ratio
            return False
        self.history.update_multipliers(mult, tmult)
        self._augments += 1
        self._blocks = None
        return True

    def commit(self, H):
        """Store friction history and multipliers of the converged state (``ContactHistory.commit``)."""
        self._blocks = None
        if LEAN_COMMIT:       # the last step's point data (its table is the Solution's): not held through this pass
            self._last = None
        P, sel, po = self._state(H, commit=True)
        if P is None or len(sel) == 0:
            self.history.commit(self._decl_mu)
            self._last = self._last_mortar = None
            self._commits = []
            self._slide_c = self._slid = None
            return
        p, out = po
        m = out.get("mortar")
        self._last_mortar = m
        tmult = None if m is None else (m["key"], np.einsum("gji,gj->gi", m["R"], m["lam"]))
        keys = P.key[sel]
        order = np.argsort(keys)
        HL, HK = _frames(out)
        HC, HF = self._pose_at(H, P.e[sel], out["xi1"]), self._pose_at(H, P.m[sel], out["xi2"])
        lam_t = out["lam_t"]
        lam_vec = lam_t[:, :1] * out["t1"] + lam_t[:, 1:] * out["t2"]
        friction = dict(key=keys[order], H_CL=se3_twin.relative(HC, HL)[order],
                        H_FK=se3_twin.relative(HF, HK)[order], H_LK=se3_twin.relative(HL, HK)[order],
                        e=P.e[sel][order], m=P.m[sel][order], xi1=out["xi1"][order],
                        xi2=out["xi2"][order], lam_t=lam_vec[order])
        self.history.commit(self._decl_mu, friction, tmult)
        if LEAN_COMMIT:       # the frames are the history's now (``results`` reads none); nothing evaluates at ``H``
            out.pop("HL", None)       # before the next ``begin_step``, whose evaluations make their own ``_cache``
            out.pop("HK", None)
            self._cache = None
            p = {k: p[k] for k in _RESULTS_PARAMS}    # of every point's kernel parameters ``results`` reads five
        self._last = (P, sel, p, out, (np.array(H), HC, HF))
        self._commits = [] if tmult is None else (self._commits + [(self._t_step, tmult)])[-2:]
        self._slide_c = None if m is None else self._sliding_c(m)
        self._slid = None if m is None else np.sort(np.asarray(m["key"])[~m["stick"] & (m["lamN"] > 0.0)])

    def nodal_results(self):
        """Exact stick's nodal table of the committed state (``Solution.extra``, one entry per step), or None
        without mortar groups: per group (a slave node against a master beam, or the chain of beams joined end to
        end it belongs to: ``beam_chains``) ``mortar_node`` and ``mortar_master_beam`` (ids; of a chain its first
        beam), ``mortar_normal_force`` ``m lamN`` and ``mortar_tangential_force`` (g, 3)
        ``m lam`` (global; forces on the slave: the nodal weight ``m`` times the weighted tractions, the quantities
        whose Coulomb cone the law enforces, ``|m lam| <= mu m lamN``), ``mortar_status`` (``OPEN``,
        ``STICK``, ``SLIP``) and ``mortar_slip`` ``|u|``, the weighted slip of the step (a length)."""
        m = getattr(self, "_last_mortar", None)
        if m is None:
            return None
        n_nodes = len(self.sys.poses0)
        key = np.asarray(m["key"], dtype=np.int64)
        lamN = np.maximum(m["lamN"], 0.0)
        mu = self._decl_mu[m["decl"]]
        stick = m["stick"] & (lamN > 0) & (mu > 0)
        return dict(mortar_node=(key // self.n_beams) % n_nodes, mortar_master_beam=key % self.n_beams,
                    mortar_normal_force=m["m"] * lamN, mortar_tangential_force=m["m"][:, None] * m["lam"],
                    mortar_status=np.where(lamN > 0, np.where(stick, STICK, SLIP), OPEN).astype(np.int8),
                    mortar_slip=np.linalg.norm(m["u"], axis=1))

    def results(self, H):
        """Contact point table of the committed state (dict of arrays).

        ``position`` (k, 3) midway between the contour points, ``gap``, ``normal_force``
        and ``tangential_force`` (k, 3) (forces on the slave, integrated over the point's
        weight), ``stick`` (False for frictionless or open points), ``status`` (``record.OPEN``
        no normal force, ``STICK``, ``SLIP`` sliding or frictionless), ``slip_increment``
        (k, 2) of the step, ``kind`` (0 line, 1 orthogonal, 2 point), ``angle`` between
        the tangents (degrees), element ids, ``xi1``, ``xi2``, ``weight``, ``normal``.
        """
        last = getattr(self, "_last", None)
        if last is None:
            return dict(position=np.zeros((0, 3)), gap=np.zeros(0), normal_force=np.zeros(0),
                        tangential_force=np.zeros((0, 3)), stick=np.zeros(0, dtype=bool),
                        status=np.zeros(0, dtype=np.int8),
                        slip_increment=np.zeros((0, 2)), kind=np.zeros(0, dtype=int),
                        angle=np.zeros(0), slave_element=np.zeros(0, dtype=int),
                        master_element=np.zeros(0, dtype=int), xi1=np.zeros(0), xi2=np.zeros(0),
                        weight=np.zeros(0))
        P, sel, p, out, (H_c, HC, HF) = last
        w = p["weight"]
        lam_t = out["lam_t"]
        ft = (w * lam_t[:, 0])[:, None] * out["t1"] + (w * lam_t[:, 1])[:, None] * out["t2"]
        if HC is None or not equal(H_c, H):   # the section poses of commit are those at its poses
            HC, HF = self._pose_at(H, P.e[sel], out["xi1"]), self._pose_at(H, P.m[sel], out["xi2"])
        elif LEAN_COMMIT:                     # read once (``Problem.commit``): not held through the next step
            self._last = (P, sel, p, out, (H_c, None, None))
        e1s, e1m = HC[:, :3, 0], HF[:, :3, 0]
        ang = np.degrees(np.arccos(np.clip(np.abs(np.sum(e1s * e1m, axis=1)), 0.0, 1.0)))
        active = out["lam_n"] > 0
        stick = out["stick"] & active & (p["mu"] > 0)
        status = np.where(active, np.where(stick, STICK, SLIP), OPEN).astype(np.int8)
        return dict(position=0.5 * (out["xC"] + out["xF"]) + 0.5 * (p["R1"] - p["R2"])[:, None] * out["n"],
                    gap=out["gap"], normal_force=w * out["lam_n"], tangential_force=ft,
                    stick=stick, status=status, slip_increment=out["slip"], kind=p["kind"],
                    angle=ang, slave_element=P.e[sel], master_element=P.m[sel],
                    xi1=out["xi1"], xi2=out["xi2"], weight=w, normal=np.array(out["n"]))   # (a copy: the Solution
        #                                                           keeps it, not the kernel's (P, 6, 3) vectors)


_RESULTS_PARAMS = ("weight", "R1", "R2", "mu", "kind")     # the kernel parameters ``ContactSystem.results`` reads


def _frames(out):
    if "HL" in out:         # (before the frames below: 65 MB at the 61-wire strand's commit)
        return out["HL"], out["HK"]
    frame = np.stack([out["n"], out["t1"], out["t2"]], axis=-1)
    HL = np.zeros(frame.shape[:-2] + (4, 4))
    HK = np.zeros_like(HL)
    HL[:, :3, :3] = HK[:, :3, :3] = frame
    HL[:, 3, 3] = HK[:, 3, 3] = 1.0
    HL[:, :3, 3] = out["xC"]
    HK[:, :3, 3] = out["xF"]
    return HL, HK


def _extent(H):
    """Largest node coordinate of the poses ``H`` (``frames.touch_tolerance``)."""
    return float(np.abs(H[..., :3, 3]).max(initial=0.0))

def _with_mortar(nodes, f, K, m, pool=None):
    """The pairs' 4-node blocks and the mortar groups' blocks (``ContactSystem._mortar``) as one
    ``Blocks`` over the groups' ``k`` nodes: the pair blocks padded with their first node (zero rows); the
    mortar pairs' own blocks are in their groups' (``m["folded"]``) and left out, the force levels those of the
    parts (``Blocks.levels_of``).
    ``pool``: a ``BufferPool`` the tangent blocks go to (kept memory: on the 19-wire bundle the fresh
    ``(m, 6 k, 6 k)`` array's page faults cost 2.5 s an evaluation), else a new array."""
    k = m["members"].shape[1]
    levels = None
    if m.get("folded") is not None:          # the mortar pairs' blocks are in their groups' (``_mortar``)
        levels = ((nodes, f), (m["members"], m["f_own"]))      # the force levels of the parts, as unfolded
        if len(m["folded"]) < len(nodes):       # (``folded`` sorted, distinct: else every pair is folded)
            keep = np.ones(len(nodes), dtype=bool)
            keep[m["folded"]] = False
            # (an empty ``K``: every pair folded, its tangent never computed, ``_local_blocks``)
            nodes, f, K = nodes[keep], f[keep], (None if K is None else K[keep] if len(K) else K)
        else:
            nodes = nodes[:0]
    n = len(nodes)
    if n == 0:           # every pair in its group: the groups' blocks themselves (no copy; ``evaluate``)
        return Blocks(m["members"], m["f"], K if K is None else m["K"], levels_of=levels)
    nodes = np.concatenate([np.concatenate([nodes, np.repeat(nodes[:, :1], k - 4, axis=1)], axis=1), m["members"]])
    fa = np.zeros((n, 6 * k))
    fa[:, :24] = f
    if K is None:
        return Blocks(nodes, np.concatenate([fa, m["f"]]), levels_of=levels)
    shape = (n + len(m["K"]), 6 * k, 6 * k)
    Ka = np.empty(shape) if pool is None else pool.take(shape)
    Ka[:n] = 0.0
    Ka[:n, :24, :24] = K
    Ka[n:] = m["K"]
    return Blocks(nodes, np.concatenate([fa, m["f"]]), Ka, levels_of=levels)


def _kernel(kernel, X, p, friction, law, tangent, K=None):
    """``f``, ``K`` (None without ``tangent`` on the numpy path) and point data of one call of
    ``kernel`` (``ContactSystem.kernel``); ``K``: the compiled kernel's output array for the tangent
    (None: a new one)."""
    if tangent:
        kw = ({} if law is None else dict(law=law)) | ({} if K is None else dict(K=K))
        return kernel.kernel_and_tangent(X, p, friction=friction, **kw)
    f, out = kernel.contact_kernel(X, p, friction=friction, **({} if law is None else dict(law=law)))
    return f, None, out


def _same_bits(a, b):
    """Float arrays ``a``, ``b`` equal bit for bit (signed zeros and nans told apart)."""
    a, b = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
    return a.shape == b.shape and equal(a.view(np.int64), b.view(np.int64))


def _member(a, b_sorted):
    """``np.isin(a, b_sorted)`` for a sorted ``b_sorted`` (binary search)."""
    if len(b_sorted) == 0:
        return np.zeros(len(a), dtype=bool)
    i = np.minimum(np.searchsorted(b_sorted, a), len(b_sorted) - 1)
    return b_sorted[i] == a


def _interp_pose(H, enodes, e, xi):
    HA, HB = H[enodes[e, 0]], H[enodes[e, 1]]
    h = se3.log(se3.relative(HA, HB))
    return se3.interpolate(HA, h, xi)


def _interp_pos(H, enodes, e, xi):
    return _interp_pose(H, enodes, e, xi)[:, :3, 3]
