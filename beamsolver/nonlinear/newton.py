"""The one Newton loop of beamsolver: ``Newton.iterate`` with a pluggable constraint.

One iteration (``iterate``): evaluate the ``problem.Problem`` at the iterate (residual,
tangent; ``evaluate`` checks it is finite and that no element turns past
``MAX_ELEMENT_ROTATION``), scale the residual and ask ``Convergence.decide`` for the
``Verdict``; then the constraint gives the correction of the free unknowns (``direction``:
one factorisation of the tangent, ``linsolve.factorize_tangent``) and, where it moves the
constrained nodes or the pseudo-time, the next iterate (``move``).  Otherwise the correction
is damped on the size of the Newton correction for a smooth problem (``Newton._damped``) or
by a backtracking line search on the scaled residual (``Newton.backtrack``; after ``LS_CRAWL``
backtracked iterations in a row near the solution, a watchdog full step).  Past ``max_iter`` the
iterations go on while a non-smooth problem's converge fast (``Newton.converging``: ``GRACE_RATE``,
at most ``GRACE_ITER`` more; contact's semi-smooth Newton, whose active set may settle late); for a
smooth one it is a hard cap.

Constraints (the ``Constraint`` protocol):

- ``FixedTime`` (load stepping, ``Newton.step``): ``t`` held at the step's end; the first
  iteration carries the prescribed motions and ``fix(values=)`` targets into the free unknowns
  through the tangent (``K_ff dz_f = -r_f - K_fc dz_c``), later ones are Newton ``K dz = -r``;
- ``stepping.arclength.Sphere``: ``t`` an unknown on Crisfield's sphere (or held at the end).

Elements may not turn by more than ``MAX_ELEMENT_ROTATION`` (nor pass pi within a step:
``check_continuity``): such steps fail with a message saying how many elements the beam needs.
Failures are typed (``beamsolver.failures``).
"""
import contextlib
import logging
import time
from typing import NamedTuple, Protocol

import numpy as np

from ..failures import DampingStalled, Diverged, NonFinite, NotConverged, SingularTangent, StepFailed
from ..lie import se3
from . import augmented as augmented_, linsolve
from .convergence import CONTINUE, CONVERGED, MAX_ITER, Convergence, Verdict
from .rotations import MAX_ELEMENT_ROTATION, RotationGuard, angle, largest_element_rotation, relative_rotations

__all__ = ["Newton", "Constraint", "FixedTime", "Convergence", "Verdict", "RotationGuard", "relative_rotations",
           "angle", "largest_element_rotation", "MAX_ELEMENT_ROTATION"]

log = logging.getLogger("beamsolver")

MULT_GROWTH = 1.0 - 1e-4   # semi-smooth Newton with multiplier unknowns: the merit must fall (Armijo) from the full step
LS_GROWTH = 10.0                     # full Newton steps are kept unless the merit grows this much
LS_CRAWL = 3                         # backtracked iterations in a row after which the next full step ...
LS_WATCHDOG = 1e4                    # ... is kept unless the merit grows this much (``Newton.backtrack``) ...
LS_NEAR = 5e-3                       # ... once the scaled residual is below this times the step's largest
GRACE_RATE = 3.0                     # past max_iter, iterations go on while each cuts the residual this much ...
GRACE_ITER = 10                      # ... at most this many more (``Newton.iterate``)
DAMPING_MIN = 1.0 / 64.0             # shortest damped Newton step (smooth problems)
STALL_RATIO = 1.5                    # undamped fallback if the shortest damped step grows the correction less
DROP_BEFORE_SOLVE = True             # exact stick (augmented): the tangent dropped once K' and A are built, before the
#                                      factorisation (issue 30: the groups' blocks freed first, 1.3 GB on the 0.6 m rope)
DROP_FACTOR = True                   # an iteration's factorisation dropped once its direction is taken (``iterate``),
#                                      before the line search's and the next iterate's evaluations: PARDISO's numerical
#                                      factor freed then, where no lagged ``Solver`` keeps it (``linsolve.FREE_DROPPED``;
#                                      docs/benchmarks.md, "Memory of the strand's loaded step, session 12")
FORCES_ONLY_TRIALS = True            # semi-smooth problems: the line search's full-step trial without tangent ...
FULL_AFTER_FULL = True               # ... but with it after a full step was accepted (``backtrack``)
LM_SHIFT = 1e-3                      # exact stick: after LM_AFTER backtracked iterations in a row, away from the
LM_AFTER = 2                         # solution (not ``near``, with LM_FAR), the direction from K + LM_SHIFT |diag K|
LM_FAR = True                        # on the displacement block (Levenberg, ``Newton._levenberg``; 0: off): the
                                     # long-lay strand's cycle 770 -> 582 iterations, 196 -> 148 s; near the solution
                                     # too, the 40 mm rope's loaded step failed (30 iterations, 3.4e-4, against 19)
                                     # (docs/benchmarks.md, session 9)
INNER_SWITCHES = 0                   # exact stick: branch switches of the linearised groups per Newton direction ...
INNER_PREDICTOR = False              # ... also in a load step's first iteration (the prescribed motions' predictor)
RETRY_SWITCHES = 8                   # ... and so many in a step's attempts after a failed one (``Newton.retrying``, set by
#                                      the stepper; 0: off), with at most TAIL_MAX_UNKNOWNS free unknowns: a slip front
#                                      that Newton moves by a few groups an iteration (the 192 el/wire twisted pair: 581
#                                      iterations, 9 failed attempts, steps down to 1/256 -> 295; docs/theory_mortar.md 3c)
TAIL_SWITCHES = 8                    # exact stick: near the solution (scaled residual <= TAIL_RATIO) the sliding groups
TAIL_RATIO = 1e-5                    # ... at a stick / slip corner (slip's share of the trial c |Pi u| < TAIL_CORNER
TAIL_CORNER = 0.1                    # ... times the disk) start on the stick rows, kept where the linearised trial
#                                      stays in the disk, at most TAIL_SWITCHES solves (``_corner_groups``; 0: off);
SWITCH_CONDENSED = True              # ... the switched groups' rows condensed and solved through A as the plain direction
#                                      from augmented.MIN_UNKNOWNS free unknowns, not the full bordered system factorised
#                                      per switch (``Newton._rows_solve``; docs/benchmarks.md, session 18)
TAIL_ROWS = 1e-3                     # ... the evaluations' branch rows asked for once the scaled residual is below this
TAIL_MAX_UNKNOWNS = 10000            # ... with at most so many free unknowns (the bordered system is factorised
#                                      uncondensed there: the 19-wire strand's, 17 898, one corner direction in its last
#                                      iteration, peak RSS 630 -> 730 MB for the same iterations)
NORMAL_SWITCHES = 4                  # exact stick: Newton directions again with the points the full step opens
                                     # linearised open (the normal law's active set, ``_normal_branches``; 0: off.
                                     # The rope pieces' loaded steps 31 -> 14 and failed -> 19 iterations, the contact
                                     # examples and the strand cycle within 1 %: docs/theory_mortar.md 3d)
PRESSED_AT_TRIAL = True              # ... the full step's pressed points evaluated with the line search's multipliers
                                     # (its forces-only evaluation reused by the trial; issue 30, session 9) ...
TANGENT_AT_PRESSED = True            # ... and with the tangent where that trial asks for it (``_trial_tangent``): exact
                                     # stick's mortar kernel once there, not a forces-only pass and the tangent's
                                     # (the 37-wire strand's near iterations, docs/benchmarks.md, session 12)
START_SWITCHES = True                # ... at t_start (step 0, ``Newton.start``) from the first iteration, with or
                                     # without multipliers (a touching start's lift-off front: main job's step 0
                                     # 10 -> 8 iterations, 4 with START_SECANT)
START_SECANT = True                  # ... and there the points on the smoothing parabola whose traction the full step
SECANT_SHARE = 0.3                   # cuts to at most this share linearised on its secant to its zero-force end (the
                                     # parabola's double root, which Newton's tangent only halves its distance to:
                                     # docs/theory/contact_laws.md 17.2; ``_normal_branches``) ...
SECANT_REACH = 1.0 - 2.0 ** -10      # ... aimed at this share of the way: where ten tangent steps end (a beam held by
                                     # contact alone keeps the stiffness the crawl left it: the contact patch's slave)
START_SWITCH_LIMIT = 1               # ... and at t_start one such direction again per iteration (not NORMAL_SWITCHES:
                                     # each is an evaluation and a factorisation; the 19-wire strand twin's step 0
                                     # took 7 iterations either way, 21.1 s with 4 against 11.5 s with 1; 9.3 s and
                                     # 10 iterations without the start's switches; the unloaded touching pair's step 0:
                                     # 26 iterations against 10 with 4 and 44 without)
CYCLE_COS = -0.9                     # with ``Newton.cycle_window`` (step 0 with exact stick's friction): a Newton
                                     # direction whose cosine with the one before is below this reverses it; that many
                                     # reversals running fail the step (a two-state cycle: every sliding group's slip,
                                     # hence its traction, reversing at every iteration, the touching strands' step 0)
NORMAL_NEAR = True                   # ... only near the solution (``near``: the residual cut LS_NEAR-fold)
INNER_UNSETTLED = "last"             # branches still changing after INNER_SWITCHES: "last" solve or "plain" Newton's
                                     # (an option: twisted pair 244 -> 195, shear lag 39 -> 22 iterations with 8, but
                                     # the strand bending cycle 197 -> 244 with 6 cut-backs and 5x the CPU time;
                                     # docs/theory_mortar.md section 3c)


class Constraint(Protocol):
    """What closes the Newton system of one step besides equilibrium (``Newton.iterate``).

    ``final``: whether the iterate may be called converged (the load step's predictor must be
    applied first); ``moves``: whether the next iterate comes from ``move`` (else the loop's
    damping / line search updates the free unknowns); ``damped``: whether the loop may damp
    the correction; ``watch_sign``: whether the first tangent's determinant sign is read
    (``Newton.indefinite_seen``)."""
    final: bool
    moves: bool
    damped: bool
    watch_sign: bool

    def direction(self, newton, ev, H, t):
        """``(lu, dzf)``: the factorised tangent (or ``None``) and the correction ``(n_free,)``."""

    def move(self, newton, H, t, dzf):
        """``(H, t, increment)``: the next iterate and the ``increment_ratio`` of the correction
        (``inf`` where it is no Newton increment)."""

    def accept(self, newton, H):
        """Checks of a converged iterate (raise a ``failures.StepFailed`` to refuse it)."""

    def stats(self):
        """The constraint's entries of the step's statistics."""


class FixedTime:
    """Load stepping: the pseudo-time ``t`` held; the first iteration carries the constrained
    nodes onto their targets at ``t`` (``H_target``: the prescribed poses, ``None`` if none) with
    the coupling ``K_fc dz_c`` (the predictor), later ones are Newton corrections, damped or
    line-searched by the loop.  A converged iterate is refused if an element's relative rotation
    may have passed pi since ``H`` (``Newton.check_continuity``)."""
    damped = True
    watch_sign = True

    def __init__(self, newton, H, t, t_prev, H_target):
        self.H_start, self.H_target = H, H_target
        self.dz_c, self.targets = newton.constrained_increments(H, t, t_prev, H_target)

    @property
    def final(self):
        return self.dz_c is None

    @property
    def moves(self):
        return self.dz_c is not None

    def direction(self, newton, ev, H, t):
        return newton.direction(ev, self.dz_c)

    def move(self, newton, H, t, dzf):
        H = newton.reach_targets(H, newton.full(dzf) + self.dz_c, self.H_target, bool(self.targets), t)
        self.dz_c = None
        return H, t, np.inf

    def accept(self, newton, H):
        newton.check_continuity(self.H_start, H)

    def stats(self):
        return {}


class _Measured(NamedTuple):
    """An evaluation (``problem.Evaluation``) with its residual scales and scaled residual, and,
    once computed, its factorised tangent ``lu``, Newton correction ``dzf`` of the free unknowns
    and that correction's norm."""
    ev: object
    scales: tuple
    ratio: float
    lu: object = None
    dzf: object = None
    norm: float = None


class Newton:
    """Newton iterations of one step (``iterate`` under a ``Constraint``; ``step``: load stepping) on a
    ``problem.Problem`` with the ``Convergence`` ``conv``; ``evaluate`` is the checked, timed
    evaluation it uses (also for branch switching), ``last_evaluation`` that of the last converged
    state.  ``timings`` accumulates the wall time
    of ``assembly`` (residual, tangent, sparse matrix), of each of the problem's contributions
    (``Problem.timing_names``, part of assembly) and ``linear_solve`` (factorisation and solves)
    until ``reset_timings``."""

    def __init__(self, problem, conv, line_search=True, callback=None):
        self.problem = problem
        self.sys = system = problem.system
        self.conv = conv
        self.line_search = line_search
        self.callback = callback
        n = system.n_nodes
        dof_u = np.zeros((n, 6), dtype=bool)
        dof_u[:, :3] = True
        fu = dof_u.ravel()[system.free_dofs]
        self.fu, self.fw = np.flatnonzero(fu), np.flatnonzero(~fu)
        self._dofs_u, self._dofs_w = system.free_dofs[self.fu], system.free_dofs[self.fw]   # in all 6 n unknowns
        self.L_ref = system.length_scale
        self.rotations = RotationGuard(system)
        self.linsolver = linsolve.Solver()    # solve(linear_solver=...) replaces it
        problem.want_branch_rows(INNER_SWITCHES > 0)
        self.ratio_now = np.inf               # the scaled residual of the iterate whose direction is computed
        self.retrying = False                 # the stepper's attempt after a failed one (``RETRY_SWITCHES``)
        self.stall_ratio = np.inf             # correction growth of the shortest damped trial
        self.indefinite_seen = False          # the step's first tangent had det < 0 (or a back-end that cannot tell)
        self.crawl = 0                        # backtracked line searches in a row (``backtrack``)
        self.full_taken = False               # the last line search of the step kept the full step (``backtrack``)
        self.near = False                     # the iterate's residual below LS_NEAR x the step's largest
        self.watch_sign = False               # whether to look (stepping.Run: conservative problems)
        self.t_evaluated = None               # t of the last evaluation (failure messages)
        self.stall_window = None              # a step fails after this many iterations without a new lowest residual
        self.least_inc = (np.inf, 0)          # ... or a new shortest full Newton increment (``_verdict``)
        self.cycle_window = None              # ... or after this many Newton directions running reverse the one
        #                                       before (``CYCLE_COS``, ``_cycling``)
        self.reversals = (None, 0)            # the last direction (scaled) and the reversals running up to it
        self.status = None                    # exact stick: (keys, stick flags) of the groups at the last iterate
        self.last_evaluation = None           # of the last converged state
        self.start = False                    # solving at t_start (step 0: ``START_SWITCHES``, ``START_SECANT``)
        self.secant_done = None               # per contribution, keys of the points the step put on the secant once
        self.reset_timings()

    def reset_timings(self):
        self.timings = dict(assembly=0.0, linear_solve=0.0, **dict.fromkeys(self.problem.timing_names, 0.0))

    def _ratio(self, r, scales):
        return self.conv.residual_ratio(r[self._dofs_u], r[self._dofs_w], *scales)

    def residual_ratio(self, ev, r=None):
        """Scaled residual (``Convergence.residual_ratio``) of the residual ``r`` ``(6 n,)`` (default
        ``ev.r``) with the force scales of the evaluation ``ev``, and the multipliers' equations
        (``_with_multipliers``)."""
        scales = self.conv.scales(ev, self.L_ref)
        return self._with_multipliers(ev, self._ratio(ev.r if r is None else r, scales), scales)

    def _with_multipliers(self, ev, ratio, scales):
        """The scaled residual ``ratio`` with the multipliers that are Newton unknowns (exact stick): their
        complementarity residuals (``Problem.multiplier_ratio``, on the force scale) and a sticking group's
        slip against its tolerance (a ratio of 1 counts as ``rtol``)."""
        if ev.mult is None:
            return ratio
        r, stick = self.problem.multiplier_ratio(ev, scales[0])
        if log.isEnabledFor(logging.DEBUG):
            log.debug("   forces %.3e, multipliers' equations %.3e, %d of %d groups sticking, largest sticking "
                      "slip / tolerance %.3g", ratio, r, ev.mult["stick"].sum(), len(ev.mult["stick"]), stick)
        return max(ratio, r, self.conv.rtol * stick)

    def _measured(self, ev):
        """``ev`` with its residual scales and scaled residual (``_Measured``; no direction yet)."""
        scales = self.conv.scales(ev, self.L_ref)
        return _Measured(ev, scales, self._with_multipliers(ev, self._ratio(ev.r, scales), scales))

    def at_rest(self, ev, H, t):
        """Whether the given poses ``H`` (evaluated in ``ev`` at ``t``) are an equilibrium by
        Newton's tests (``Convergence.decide``): the scaled residual, else the Newton correction
        one iteration would make, against its round-off floor.  A state Newton could not start
        from (a singular tangent, a refused contact) counts as at rest: it is kept as given."""
        if not np.all(np.isfinite(ev.r)) or self._ratio(ev.r, self.conv.scales(ev, self.L_ref)) <= self.conv.rtol:
            return True
        try:
            _, dzf = self.direction(self.problem.evaluate(H, t, tangent=True))
        except StepFailed:
            return True
        return self._inc(dzf) <= max(self.conv.dtol, self.conv.floor(H, self.L_ref))

    def _merit(self, ev, scales):
        rf = ev.r[self.sys.free_dofs]
        F, M = scales
        phi = float(np.sum((rf[self.fu] / F) ** 2) + np.sum((rf[self.fw] / M) ** 2))
        if ev.mult is not None:
            phi += float(np.sum((np.linalg.norm(ev.mult["C"], axis=1) * ev.mult["m"] / F) ** 2))
        return phi

    def check_continuity(self, H0, H1):
        """``RotationGuard.check_continuity``: refuse a step over which an element's relative rotation
        may have passed through pi (``failures.RotationLimit``)."""
        self.rotations.check_continuity(H0, H1)

    def _norm(self, dzf):
        """Norm of free increments, translations in units of the model size (unit-independent)."""
        return float(np.sqrt(np.sum((dzf[self.fu] / self.L_ref) ** 2) + np.sum(dzf[self.fw] ** 2)))

    def _inc(self, dzf):
        """``Convergence.increment_ratio`` of free increments."""
        return max(np.abs(dzf[self.fu]).max(initial=0.0) / self.L_ref, np.abs(dzf[self.fw]).max(initial=0.0))

    def direction(self, ev, dz_c=None):
        """``(lu, dzf)``: the factorised tangent of ``ev`` and the Newton increment of the free
        unknowns ``(n_free,)`` (with the prescribed-motion coupling of ``dz_c`` ``(n, 6)``)."""
        problem = self.problem
        if ev.mult is not None and "Tq" in ev.mult and (dz_c is None or INNER_PREDICTOR):
            if INNER_SWITCHES or self._retry_switches():
                return self._active_set_direction(ev, dz_c, INNER_SWITCHES or RETRY_SWITCHES)
            if TAIL_SWITCHES and self.ratio_now <= TAIL_RATIO and self.sys.n_free <= TAIL_MAX_UNKNOWNS:
                corner = self._corner_groups(ev)
                if corner.any():
                    return self._active_set_direction(ev, dz_c, TAIL_SWITCHES, corner)
        t0 = time.perf_counter()
        aug = problem.augmented_system(ev, dz_c) if problem.augments(ev) else None
        if aug is None:
            K, rhs = problem.linear_system(ev, dz_c)     # with multipliers: condensed and bordered
        elif DROP_BEFORE_SOLVE:
            ev.drop_tangent()      # the tangent's values are in K' and A now (the direct fallback needs K' alone)
        t1 = time.perf_counter()
        if aug is not None:                              # the saddle system through A = K' + Kq E Kl
            lu, dzf = self._timed(lambda: (aug, aug.solve(self.linsolver)), t0, t1)
        else:
            lu, dzf = self._timed(lambda: self._factored(K, rhs, ev.mult is not None), t0, t1)
        if ev.mult is not None:
            dzf, dlam = problem.split_solution(ev, dzf, dz_c)
            problem.multiplier_step(ev, dlam)
        return lu, dzf

    def _direction(self, ev, H, t, constraint):
        """The constraint's Newton direction ``(lu, dzf)`` at the iterate ``ev``; with exact stick near the solution,
        with the normal law's active set (``_normal_branches``)."""
        lu, dzf = constraint.direction(self, ev, H, t)
        if NORMAL_SWITCHES and constraint.final and not constraint.moves and \
                ((ev.mult is not None and (self.near or not NORMAL_NEAR)) or (self.start and START_SWITCHES)):
            held = [lu]
            lu = None                 # (held by ``held`` alone: ``_normal_branches`` may let it go)
            lu, dzf = self._normal_branches(ev, H, t, held, dzf)
        return lu, dzf

    def _levenberg(self, ev, H, t, constraint):
        """``_direction`` at the iterate ``ev``; with exact stick's multipliers after ``LM_AFTER`` backtracked line
        searches in a row (``crawl``) and, with ``LM_FAR``, not ``near`` the solution, from the tangent shifted by
        ``LM_SHIFT`` times its diagonal's magnitudes (``Problem.levenberg``: the augmented path's displacement block).
        A frictional strand whose wires have soft torsion-bending modes (a long lay) took steps along them that the
        residual's curvature cut to 1/8 .. 1/128 of their length, iteration after iteration, with no contact status
        changing (docs/benchmarks.md, session 9); the shift shortens them.  The residual and the convergence test are
        unchanged."""
        shift = LM_SHIFT if LM_SHIFT > 0.0 and ev.mult is not None and self.crawl >= LM_AFTER and \
            not (LM_FAR and self.near) else 0.0
        self.problem.shift = shift
        try:
            return self._direction(ev, H, t, constraint)
        finally:
            self.problem.shift = 0.0

    @staticmethod
    def release(ev, lu):
        """The tangent of ``ev`` is factorised in ``lu``: its values (the contact's (m, 24, 24) blocks) are not needed
        any more, and freeing them lets the next evaluation reuse their memory (exact stick's K' too: only the factor
        of A is kept)."""
        ev.drop_tangent()
        if isinstance(lu, augmented_.Augmented):
            lu.drop_tangent()

    def _normal_branches(self, ev, H, t, held, dzf):
        """The Newton direction ``(lu, dzf)`` at ``(H, t)`` with the points that press at ``H`` but not at the full
        step linearised on the normal law's open branch (``Problem.force_open``), again until no more open (at most
        ``NORMAL_SWITCHES`` times): a lift-off front moves by several nodes in one Newton iteration.  At t_start
        (``START_SECANT``) the points on the smoothing parabola that press at both but whose traction the full step
        cuts to ``SECANT_SHARE`` or less are linearised, once in the step, on the parabola's secant to ``SECANT_REACH``
        of the way to its zero-force end (``Problem.force_secant``): the parabola's tangent only halves their distance
        to that double root per iteration.  The residual, line search and convergence test are the exact law's.
        ``held``: ``[lu]``, the factorised tangent's only reference (``_direction``), dropped before the full step's
        contact tangent is computed (``TANGENT_AT_PRESSED``; ``DROP_FACTOR``, as ``iterate`` drops it before the line
        search: the factor of ``A`` freed then where no lagged ``Solver`` keeps it) unless the first tangent's sign
        is read (``watch_sign``); the returned ``lu`` is then None."""
        problem = self.problem
        lu = held.pop()
        secant = self.start and START_SECANT
        now = problem.pressed_points(H, law=secant)
        keys = [(k[0] if secant else k) if k is not None else None for k in now]
        if not any(k is not None and len(k) for k in keys):
            return lu, dzf
        forced = [np.zeros(0, dtype=np.int64) for _ in now]
        on_secant = [np.zeros(0, dtype=np.int64) for _ in now]
        # a point goes on the secant once in a step: then it is where ten tangent steps would have taken it, and
        # Newton's own steps finish (a beam held by contact alone keeps the stiffness that leaves it)
        done = self.secant_done if self.secant_done is not None else on_secant
        try:
            for switch in range(min(NORMAL_SWITCHES, START_SWITCH_LIMIT) if self.start else NORMAL_SWITCHES):
                # the multipliers of the line search's full step: the normal law does not depend on them, and the
                # full step's evaluation (forces only) then serves the line search's first trial when nothing opens;
                # the first one (no point forced yet) with the tangent if that trial asks for it (``TANGENT_AT_PRESSED``;
                # ``ev``'s tangent, solved, is released first, as ``iterate`` does before the line search)
                problem.multiplier_trial(1.0 if PRESSED_AT_TRIAL else 0.0)
                tangent = PRESSED_AT_TRIAL and TANGENT_AT_PRESSED and switch == 0 and self._trial_tangent(ev)
                if tangent:
                    self.release(ev, lu)
                    if DROP_FACTOR and not self.watch_sign:
                        lu = None
                then = problem.pressed_points(problem.update(H, self.full(dzf)), law=secant, tangent=tangent)
                then_keys = [(b[0] if secant else b) if b is not None else None for b in then]
                opened = [np.setdiff1d(np.setdiff1d(np.setdiff1d(a, b), f), s) if a is not None else f[:0]
                          for a, b, f, s in zip(keys, then_keys, forced, on_secant)]
                crawl = [self._crawling(a, b, np.union1d(f, d), s) if secant and a is not None else s
                         for a, b, f, s, d in zip(now, then, forced, on_secant, done)]
                grew = [len(c) > len(s) for c, s in zip(crawl, on_secant)]
                if not any(len(o) for o in opened) and not any(grew):
                    break
                forced = [np.union1d(f, o) for f, o in zip(forced, opened)]
                on_secant = crawl
                problem.force_open(forced)
                if secant:
                    problem.force_secant(on_secant, [a[2][np.searchsorted(a[0], c)] if a is not None else None
                                                     for a, c in zip(now, on_secant)], SECANT_REACH)
                ev2 = self.evaluate(H, t)
                lu, dzf = self.direction(ev2)
                ev2.drop_tangent()
        finally:
            problem.force_open(None)
            if secant:
                problem.force_secant(None)
                self.secant_done = [np.union1d(d, s) for d, s in zip(done, on_secant)]
        return lu, dzf

    @staticmethod
    def _crawling(now, then, forced, on_secant):
        """Sorted keys of ``on_secant`` and of the points of ``now`` (``(keys, lam_n, gap, parabola)`` at the
        iterate) on the parabola whose traction at the full step (``then``, the same form) is at most
        ``SECANT_SHARE`` of theirs, not ``forced`` open (``_normal_branches``)."""
        ka, la, _, pa = now
        kb, lb = then[0], then[1]
        i = np.minimum(np.searchsorted(kb, ka), max(len(kb) - 1, 0))
        both = kb[i] == ka if len(kb) else np.zeros(len(ka), dtype=bool)
        lam1 = np.where(both, lb[i] if len(kb) else 0.0, 0.0)
        c = both & pa & (lam1 <= SECANT_SHARE * la)
        return np.union1d(on_secant, np.setdiff1d(ka[c], forced))

    def _retry_switches(self):
        """Whether Newton's directions predict the groups' branches (a failed step's retry, ``RETRY_SWITCHES``)."""
        return bool(RETRY_SWITCHES) and self.retrying and self.sys.n_free <= TAIL_MAX_UNKNOWNS

    @staticmethod
    def _corner_groups(ev):
        """``(g,)``: the sliding groups of ``ev`` (pressed, not weak) at a stick / slip corner: their slip's share of
        the trial, ``c |Pi u| = |trial - Pi R Lam|``, below ``TAIL_CORNER`` times their disk ``mu lamN``.  There the
        slide branch's row across the trial, ``(1 - cap / |trial|) dv - c (cap / |trial|) du``, is nearly singular
        (``|trial| -> cap``, and ``du`` hardly follows ``dv`` where ``c`` is small against the wires' stiffness): each
        Newton step turned such a traction by 0.1 .. 0.3 rad and the disk's curvature gave back a radial residual of
        that order squared; the main job's tails crawled (docs/benchmarks.md, session 14, branch bE)."""
        mu = ev.mult
        v = np.einsum("gij,gj->gi", mu["R"], mu["Lam"])
        cu = np.linalg.norm(mu["trial"] - np.einsum("gij,gj->gi", mu["Pi"], v), axis=1)
        return ~mu["stick"] & ~mu["weak"] & (mu["cap"] > 0.0) & (cu < TAIL_CORNER * mu["cap"])

    def _active_set_direction(self, ev, dz_c=None, switches=None, corner=None):
        """``direction`` with the groups' stick / slip branches decided on the linearised problem (exact stick): the
        Newton system is solved (condensed, as ``direction``), each group's branch predicted at the step's end by its
        linearised trial traction and disk (``Problem.predicted_branches``); groups predicted on the other branch get
        that branch's rows (``Problem.branch_rows``) and the full bordered system (``Problem.uncondense``) is solved
        again, at most ``INNER_SWITCHES`` times, until no group changes (a slip front then moves by several nodes in
        one Newton iteration).  Not in the iteration that carries the prescribed motions (``INNER_PREDICTOR``):
        predicted that far, the branches of a 1+6+12 strand's first step from zero tractions settled with 276 groups
        switched and Newton crawled (residual 5 after 30 iterations).  ``switches``: at most so many (default
        ``INNER_SWITCHES``); ``corner`` ``(g,)`` (``_corner_groups``, Newton's tail): those sliding groups start on the
        stick rows and only their branches are predicted."""
        problem, mu = self.problem, ev.mult
        n = self.sys.n_free
        used, rows = mu["stick"], None
        switches = INNER_SWITCHES if switches is None else switches
        start = 0
        condensed = SWITCH_CONDENSED and problem.augments(ev)
        if corner is not None:      # the corner groups start on the stick rows
            if not condensed:
                problem.uncondense(ev)
            used = mu["stick"] | corner
            rows = problem.branch_rows(ev, used, mu["trial"])
            start = 1
        for inner in range(start, switches + 1):
            if condensed:
                lu, x = self._rows_solve(ev, dz_c, rows)
            else:
                lu, x = self._bordered_solve(ev, dz_c, inner, rows)
            if inner == start:
                first = (lu, x)
            stick, trial, _ = problem.predicted_branches(ev, x, dz_c)
            stick = np.where(mu["weak"], mu["stick"], stick)
            if corner is not None:
                # only the corner groups' branches are predicted (the others': as evaluated; all predicted from the
                # tail on, the main job's step to t = 0.4375 cycled two directions for 10 iterations): one stays on
                # the stick rows while its linearised trial stays in its disk
                stick = np.where(corner, stick, mu["stick"])
            if np.array_equal(stick, used):
                break
            if inner == switches:
                if INNER_UNSETTLED == "plain":
                    lu, x = first
                break
            if rows is None and not condensed:
                problem.uncondense(ev)
            used = stick
            rows = problem.branch_rows(ev, used, trial)
        problem.multiplier_step(ev, x[n:].reshape(-1, 3))
        return lu, x[:n]

    def _rows_solve(self, ev, dz_c, rows):
        """``(lu, x)``: the Newton system of ``ev`` with its multipliers' rows ``rows`` (``Problem.branch_rows``;
        ``None``: the evaluation's) condensed and solved as ``direction`` solves it (through ``A = K' + Kq E Kl``
        from ``augmented.MIN_UNKNOWNS`` free unknowns), ``x`` ``(n_free + 3 g,)`` the free increments and the
        multipliers' step."""
        problem = self.problem
        with problem.rows_of(ev, rows) if rows is not None else contextlib.nullcontext():
            t0 = time.perf_counter()
            if problem.augments(ev):
                aug = problem.augmented_system(ev, dz_c)
                lu, x = self._timed(lambda: (aug, aug.solve(self.linsolver)), t0, time.perf_counter())
            else:
                K, rhs = problem.linear_system(ev, dz_c)
                lu, x = self._timed(lambda: self._factored(K, rhs, True), t0, time.perf_counter())
            dzf, dlam = problem.split_solution(ev, x, dz_c)
        return lu, np.concatenate([dzf, np.ravel(dlam)])

    def _factored(self, K, rhs, saddle):
        """``(lu, x)``: ``K`` factorised by the Newton's solver and ``K x = rhs`` solved."""
        lu = linsolve.factorize_tangent(K, self.linsolver, saddle=saddle)
        return lu, lu.solve(rhs)

    def _timed(self, solve, t0, t1):
        """``solve()`` ``-> (lu, x)``, timed as the linear solve (``t0 .. t1``: its system's assembly); a non-finite
        ``x`` is refused (``SingularTangent``)."""
        try:
            lu, x = solve()
        finally:
            t2 = time.perf_counter()
            self.timings["assembly"] += t1 - t0
            self.timings["linear_solve"] += t2 - t1
        if not np.all(np.isfinite(x)):
            raise SingularTangent("the linear solve returned non-finite values")
        return lu, x

    def _bordered_solve(self, ev, dz_c, inner, rows):
        """``_rows_solve`` by the full bordered system (``SWITCH_CONDENSED = False``: a factorisation of it per switch;
        the evaluation's rows condensed at ``inner == 0``)."""
        problem = self.problem
        t0 = time.perf_counter()
        K, rhs = problem.linear_system(ev, dz_c, condense=inner == 0, rows=rows)
        lu, x = self._timed(lambda: self._factored(K, rhs, True), t0, time.perf_counter())
        if inner == 0 and rows is None:
            dzf, dlam = problem.split_solution(ev, x, dz_c)
            x = np.concatenate([dzf, np.ravel(dlam)])
        return lu, x

    def evaluate(self, H, t, tangent=True):
        """``Problem.evaluate`` timed into ``timings`` and checked (finite residual, element rotations
        below ``MAX_ELEMENT_ROTATION``: ``NonFinite`` / ``RotationLimit``); ``t_evaluated``: its ``t``."""
        self.t_evaluated = t
        t0 = time.perf_counter()
        ev = self.problem.evaluate(H, t, tangent=tangent)
        self.timings["assembly"] += time.perf_counter() - t0
        for name, seconds in ev.timings.items():
            self.timings[name] = self.timings.get(name, 0.0) + seconds
        if not np.isfinite(ev.r).all():
            raise NonFinite("the residual is not finite")
        self.rotations.check(ev.state)
        return ev

    def _write_targets(self, dz, H, t, t_prev, H_target):
        """Write into ``dz`` ``(n, 6)`` the increments carrying the constrained nodes from ``H`` (at
        ``t_prev``) to their targets at ``t`` (prescribed poses ``H_target``; ``fix(values=)``
        components); returns the ``fix(values=)`` targets."""
        sys = self.sys
        targets = sys.fixed_value_increments(H, t, t_prev) if sys.fix_values else []
        if len(sys.prescribed_nodes):
            p = sys.prescribed_nodes
            dz[p] = se3.log(se3.relative(H[p], H_target))
        for node, comp, dx in targets:
            dz[node, comp] = dx
        return targets

    def constrained_increments(self, H, t, t_prev, H_target):
        """Increments ``dz_c`` ``(n, 6)`` carrying the constrained nodes to their targets at ``t``
        (``None`` if there is nothing to move) and the ``fix(values=)`` targets."""
        sys = self.sys
        if not (len(sys.prescribed_nodes) or sys.fix_values):
            return None, []
        dz_c = np.zeros((sys.n_nodes, 6))
        targets = self._write_targets(dz_c, H, t, t_prev, H_target)
        if not (len(sys.prescribed_nodes) or targets):
            return None, targets
        return (dz_c if np.any(dz_c) else None), targets

    def move(self, H, t_prev, t, dz):
        """The iterate at ``t`` from ``H`` at ``t_prev``: free nodes by ``dz`` ``(n, 6)`` (its
        constrained entries are overwritten), constrained ones onto their targets at ``t`` (the
        arc-length iterations, whose ``t`` moves with every correction)."""
        sys = self.sys
        H_target = sys.prescribed_poses(t) if len(sys.prescribed_nodes) else None
        targets = self._write_targets(dz, H, t, t_prev, H_target)
        return self.reach_targets(H, dz, H_target, bool(targets), t)

    def reach_targets(self, H, dz, H_target, fix_values, t):
        """The predictor update: free nodes by ``dz`` ``(n, 6)``, constrained ones exactly onto their
        targets at ``t`` (``H_target`` the prescribed poses; ``fix_values``: whether ``fix(values=)``
        components are enforced)."""
        sys = self.sys
        H = self.problem.update(H, dz)
        if len(sys.prescribed_nodes):
            H[sys.prescribed_nodes] = H_target
        if fix_values:
            sys.enforce_fixed_values(H, t)
        sys.sync_members(H)
        return H

    def step(self, H, t, H_target, t_prev=None):
        """Solve for equilibrium at ``t`` (from the equilibrium ``H`` at ``t_prev``) by ``iterate``
        with the ``FixedTime`` constraint; returns ``(H, ev, stats)`` (``ev`` the
        ``problem.Evaluation`` of the converged state) or raises a ``failures.StepFailed``."""
        H, _, ev, stats = self.iterate(H, t, FixedTime(self, H, t, t_prev, H_target))
        return H, ev, stats

    def iterate(self, H, t, constraint):
        """Newton iterations from the iterate ``(H, t)`` under ``constraint`` (``Constraint``) until
        ``Convergence.decide`` says converged; returns ``(H, t, ev, stats)`` (``ev`` the
        ``problem.Evaluation`` of the converged state, ``stats`` its ``iterations``, ``residuals``
        and the constraint's entries) or raises a ``failures.StepFailed``.

        With ``line_search``, the Newton step of a smooth problem (``Problem.smooth``) is damped
        on the Newton correction (``_damped``); otherwise the residual line search
        ``backtrack`` is used (only where the constraint lets the loop update the iterate).
        """
        conv, problem = self.conv, self.problem
        residuals = []
        self.crawl, self.full_taken = 0, False
        self.ratio_now = np.inf              # (``_record``'s; ``direction``'s tail test)
        self.least_inc = (np.inf, 0)         # the shortest full Newton increment of the step and its iteration
        self.reversals = (None, 0)
        self.secant_done = None
        if constraint.watch_sign:
            self.indefinite_seen = False
        damped_its = 0
        floor = conv.floor(H, self.L_ref)
        damping = self.line_search and problem.smooth and constraint.damped
        plain = False                # undamped Newton after the damped iteration stalled
        last_inc = np.inf
        ahead = None                 # the ``_Measured`` evaluation of an accepted trial (line search, damping)
        lam = 1.0
        rotation_streak = 0
        stats_extra = {}
        for it in range(conv.max_iter + GRACE_ITER + 1):
            ev, scales, ratio, lu, dzf, nrm = self._measured(self.evaluate(H, t)) if ahead is None else ahead
            ahead = None
            problem.accept_multipliers()        # those the iterate was evaluated with
            self._record(ev, ratio, residuals, stats_extra, it, t, H)
            verdict = self._verdict(residuals, last_inc, it, floor, constraint)
            if verdict is CONVERGED:
                if damped_its:
                    stats_extra["damped"] = damped_its
                return self._converged(H, t, ev, constraint, dict(iterations=it, residuals=residuals, **stats_extra))
            if dzf is None:
                lu, dzf = self._levenberg(ev, H, t, constraint)
            if it == 0 and self.watch_sign and constraint.watch_sign:
                self._watch_first_tangent(lu)
            self.release(ev, lu)
            if DROP_FACTOR:
                lu = None
            if ev.mult is not None:
                problem.multiplier_trial(1.0)
            if constraint.moves:
                H, t, last_inc = constraint.move(self, H, t, dzf)
                continue
            if self.cycle_window:
                self._cycling(dzf, ratio, residuals)
            dz = self.full(dzf)
            if not damping:
                H, ahead, last_inc = self._undamped(H, dz, ev, scales, ratio, t, plain)
                continue
            lam0 = min(1.0, 2.0 * lam)          # after a damped iteration, try twice its length
            inc = conv.increment_ratio(dz, self.L_ref)
            try:
                H, lam, ahead, rotation = self._damped(H, dz, dzf, t, lam0, nrm, inc)
            except DampingStalled:
                if not self.stall_ratio <= STALL_RATIO:
                    raise
                # the shortest damped step leaves the Newton correction about as it is (a flat
                # direction, not a poor linearisation): plain Newton from here on, as on smooth
                # stable paths past which the damping test stalls; max_iter bounds it
                log.debug("t = %.6g: damped Newton stalled (correction ratio %.3g); undamped Newton steps", t,
                          self.stall_ratio)
                damping, plain = False, True
                stats_extra["undamped"] = it
                last_inc = inc
                H = problem.update(H, dz)
                continue
            damped_its += lam < 1.0
            # the full step turned an element past the limit in two iterations running: the
            # equilibrium itself needs it (refine) rather than an overshooting iterate
            rotation_streak = rotation_streak + 1 if rotation is not None else 0
            if rotation_streak >= 2:
                raise rotation
            last_inc = inc if lam == 1.0 else np.inf
        raise AssertionError("unreachable: decide() returns MAX_ITER from max_iter on, converging is False "
                             "after GRACE_ITER more")

    def _record(self, ev, ratio, residuals, stats, it, t, H):
        """Book an iterate (``ev`` at ``(H, t)``, scaled residual ``ratio``, iteration ``it``): its residual (``ratio_now``,
        and the tail's branch rows asked for below ``TAIL_ROWS``), exact stick's status changes (``_count_changes``), ``near`` for the line search, the log and the callback."""
        residuals.append(ratio)
        self.ratio_now = ratio
        if (TAIL_SWITCHES or RETRY_SWITCHES) and not INNER_SWITCHES and ev.mult is not None:
            # the branch rows of exact stick's tail and retries (their cost: only where they may be needed)
            self.problem.want_branch_rows(self._retry_switches() or (
                TAIL_SWITCHES and ratio <= TAIL_ROWS and self.sys.n_free <= TAIL_MAX_UNKNOWNS))
        self._count_changes(ev, stats, it)
        self.near = ratio <= LS_NEAR * max(residuals)
        log.debug("t = %.6g  iteration %d  scaled residual %.3e", t, it, ratio)
        if self.callback is not None:
            self.callback(dict(t=t, iteration=it, residual=ratio, poses=H))

    def _count_changes(self, ev, stats, it):
        """Exact stick: append to ``stats["changes"]`` how many groups of ``ev`` are on the other branch (stick /
        slip) than at the iterate before (groups that appeared or vanished count; 0 at the first iterate), the
        contact status changes a semi-smooth Newton converges superlinearly without."""
        mu = ev.mult
        if mu is None:
            return
        prev, self.status = (None if it == 0 else self.status), (mu["key"], mu["stick"])
        changes = stats.setdefault("changes", [])
        if prev is None:
            changes.append(0)
            return
        common, i0, i1 = np.intersect1d(prev[0], mu["key"], assume_unique=True, return_indices=True)
        changes.append(int(len(prev[0]) + len(mu["key"]) - 2 * len(common)
                           + np.count_nonzero(prev[1][i0] != mu["stick"][i1])))

    def _verdict(self, residuals, last_inc, it, floor, constraint):
        """``Convergence.decide`` on the iterate whose scaled residual is ``residuals[-1]``: ``CONVERGED`` or
        ``CONTINUE`` (past ``max_iter`` while ``converging``), else the ``failures.StepFailed`` raised, also after
        ``stall_window`` iterations without a new lowest residual or full-step increment."""
        ratio = residuals[-1]
        verdict = self.conv.decide(ratio, last_inc, it, floor, final=constraint.final)
        if verdict is MAX_ITER and not self.problem.smooth and self.converging(residuals, it - self.conv.max_iter):
            verdict = CONTINUE
        if verdict is not CONTINUE and verdict is not CONVERGED:
            raise self._failure(verdict, ratio)
        if np.isfinite(last_inc) and last_inc < self.least_inc[0]:
            self.least_inc = (last_inc, it)
        # progress: a new lowest residual, or a new shortest full Newton increment (a crawl to a double root of the
        # normal law, the touching start of docs/theory/contact_laws.md 17.2, keeps its residual and halves its steps)
        if verdict is CONTINUE and self.stall_window and \
                it - max(int(np.argmin(residuals)), self.least_inc[1]) >= self.stall_window:
            raise NotConverged(f"no progress in {self.stall_window} iterations (scaled residual {ratio:.3g}, "
                               f"lowest {min(residuals):.3g})", ratio)
        return verdict

    def _cycling(self, dzf, ratio, residuals):
        """Count the Newton direction ``dzf`` of the iterate (scaled residual ``ratio``) as a reversal of the one
        before (cosine below ``CYCLE_COS``, translations in units of the model size); ``cycle_window`` of them running
        fail the step (``NotConverged``): the iterates alternate between two states, as the touching strands' step 0
        with exact stick's friction did (docs/benchmarks.md, "Step 0 of touching strands, session 11")."""
        v = dzf.copy()
        v[self.fu] /= self.L_ref
        last, running = self.reversals
        nv = float(np.linalg.norm(v))
        if last is not None and len(last) == len(v) and nv > 0.0:
            cos = float(last @ v) / (float(np.linalg.norm(last)) * nv)
            running = running + 1 if cos < CYCLE_COS else 0
        self.reversals = (v, running)
        if running >= self.cycle_window:
            raise NotConverged(f"cycling: {running} Newton directions running reverse the one before (scaled residual "
                               f"{ratio:.3g}, lowest {min(residuals):.3g})", ratio)

    @staticmethod
    def converging(residuals, extra):
        """Whether an iteration past ``max_iter`` (the ``extra``-th) of a problem that is not smooth
        (``Problem.smooth``; a smooth one stops at ``max_iter``) may go on: at most ``GRACE_ITER`` of them,
        each after iterations that cut the scaled residual by ``GRACE_RATE`` at least, twice running
        (a semi-smooth Newton whose contact active set has just settled, e.g. the 40 mm rope's loaded step:
        6.7e-4, 1.8e-4 at iteration 30, then 1.5e-5, 1.9e-7, 3.5e-10), not one stalled or oscillating."""
        if extra >= GRACE_ITER or len(residuals) < 3:
            return False
        r0, r1, r2 = residuals[-3:]
        return r1 * GRACE_RATE <= r0 and r2 * GRACE_RATE <= r1

    def _converged(self, H, t, ev, constraint, stats):
        """The return of ``iterate`` at the converged iterate ``(H, t)`` evaluated in ``ev``."""
        constraint.accept(self, H)
        self.last_evaluation = ev     # of the converged state (its tangent: stability check)
        return H, t, ev, dict(stats, **constraint.stats())

    def _watch_first_tangent(self, lu):
        """``indefinite_seen`` from the factorised first tangent ``K(H_n, t_n+1)``: indefinite where a step
        may jump (a back-end that cannot tell counts as indefinite)."""
        sign = getattr(lu, "det_sign", None)
        self.indefinite_seen = sign is None or sign() < 0

    def _undamped(self, H, dz, ev, scales, ratio, t, plain):
        """A Newton update without damping: the full step (``plain``, or no line search) or the residual line
        search's.  Returns ``(H, ahead, increment ratio)`` (``ahead``: the trial's ``_Measured`` evaluation
        or ``None``; the ratio is ``inf`` while multipliers that are unknowns move, ``ratio > rtol``)."""
        conv = self.conv
        inc = conv.increment_ratio(dz, self.L_ref)
        if ev.mult is not None and ratio > conv.rtol:
            inc = np.inf                 # the multipliers move too: no convergence on a small dz alone
        if not self.line_search or plain:
            return self.problem.update(H, dz), None, inc
        H, ahead = self.backtrack(H, dz, ev, scales, t)
        return H, ahead, inc

    def _failure(self, verdict, ratio):
        """The typed failure of a ``Convergence.decide`` verdict other than converged / continue."""
        if verdict is MAX_ITER:
            return NotConverged(f"no convergence in {self.conv.max_iter} iterations (scaled residual {ratio:.3g})",
                                ratio)
        return Diverged(f"diverging (scaled residual {ratio:.3g})")

    def full(self, dzf):
        """Increments ``(n, 6)`` of all nodes from those of the free unknowns (zero elsewhere)."""
        dz = np.zeros(6 * self.sys.n_nodes)
        dz[self.sys.free_dofs] = dzf
        return dz.reshape(-1, 6)

    def _damped(self, H, dz, dzf, t, lam, nrm=None, inc=None):
        """Damped Newton update ``H exp(lam dz)`` (smooth problems).

        A trial length is accepted when the Newton correction at the trial point is smaller than
        the current one (``|dz(trial)| < |dz|``, translations scaled by the model size): an
        affine-invariant test, blind to the huge but harmless axial-force residuals a slender
        beam shows after a large rotation increment (the next iteration removes them), which
        made the residual line search crawl.  The trial's tangent, factorisation and
        correction are those of the next iteration, so an accepted full step costs nothing
        extra: where plain Newton converges, this is plain Newton.  Otherwise the length is
        halved (a trial that is not finite, is singular or turns an element past the limit is
        rejected too) down to ``DAMPING_MIN``.

        ``nrm``, ``inc``: ``_norm(dzf)`` and ``_inc(dzf)`` if known.  Returns ``(H, lam, ahead,
        rotation)``: ``ahead`` the trial's ``_Measured`` evaluation (its ``lu``, ``dzf``,
        ``norm`` ``None`` if it converged), ``rotation`` the rotation-limit failure of the full first
        trial, if that is what rejected it.
        """
        problem, conv = self.problem, self.conv
        inc = self._inc(dzf) if inc is None else inc
        if inc <= 1e3 * conv.dtol:     # round-off level: nothing to damp
            return problem.update(H, dz), 1.0, None, None
        if nrm is None:
            nrm = self._norm(dzf)
        rotation = None
        failure = None
        first = True
        while True:
            self.stall_ratio = np.inf
            H1 = problem.update(H, dz if lam == 1.0 else lam * dz)
            try:
                m = self._measured(self.evaluate(H1, t))
                if m.ratio <= conv.rtol:
                    return H1, lam, m, None
                lu1, d1 = self.direction(m.ev)
                nrm1 = self._norm(d1)
                self.stall_ratio = nrm1 / nrm
                if nrm1 < nrm or self._inc(d1) <= conv.dtol:
                    return H1, lam, m._replace(lu=lu1, dzf=d1, norm=nrm1), rotation
            except StepFailed as e:
                failure = e
                if first and e.rotation:
                    rotation = e
            first = False
            lam *= 0.5
            if lam < DAMPING_MIN:
                if failure is not None and failure.rotation:
                    raise failure
                raise DampingStalled(f"damped Newton stalled: no step length down to {DAMPING_MIN:g} of the "
                                     "Newton increment reduces the Newton correction")

    def _trial_tangent(self, ev0):
        """Whether the line search's full-step trial from the iterate ``ev0`` is evaluated with the tangent
        (``backtrack``: not for semi-smooth problems with multipliers, ``FORCES_ONLY_TRIALS``, unless the step's last
        line search kept the full step, ``FULL_AFTER_FULL``)."""
        return ev0.mult is None or not FORCES_ONLY_TRIALS or (FULL_AFTER_FULL and self.full_taken)

    def backtrack(self, H, dz, ev0, scales, t):
        """Backtracking on the scaled residual (problems that are not smooth; the others use the
        damped Newton of ``_damped``: a piecewise smooth residual made its natural-monotonicity
        test accept steps that later stalled, e.g. in the twisted pair).

        Returns ``(H1, ahead)``: the accepted poses and, when the full step is accepted, its
        ``_Measured`` evaluation (with tangent: the next iteration's, computed once; ``None`` otherwise).
        The residual does not depend on whether the tangent is computed: semi-smooth problems evaluate the full
        step's trial with it only after the step's last line search kept the full step (``FULL_AFTER_FULL``, then
        kept 79 times in 105 on the main job, against 27 in 67 otherwise), else forces only."""
        problem = self.problem
        phi0 = self._merit(ev0, scales)
        H1 = problem.update(H, dz)
        if phi0 <= (10.0 * self.conv.rtol) ** 2 * len(self.sys.free_dofs):
            return H1, None
        alpha = 1.0
        best = (np.inf, H1, alpha)
        # Newton may raise the residual for a while: only a blow-up (factor LS_GROWTH) triggers
        # backtracking, which then asks for a decrease; after LS_CRAWL backtracked iterations in a
        # row near the solution (``near``: the residual cut LS_NEAR-fold from the step's largest), a
        # growth up to LS_WATCHDOG (a non-monotone watchdog step: thousands of contact points crossing
        # the kinks of the normal and friction laws at once, the 40 mm rope's loaded step, where
        # backtracked steps of 0.1 .. 0.01 crawled for 25 iterations; far from it, at the start of a
        # step, the backtracking guards the contact examples' iterations)
        watchdog = self.crawl >= LS_CRAWL and self.near
        growth = (LS_WATCHDOG if watchdog else LS_GROWTH) if ev0.mult is None \
            else MULT_GROWTH     # semi-smooth with multipliers: Armijo from the full step
        for _ in range(8):
            ev1 = None
            try:
                # the full step is nearly always accepted: evaluated with the tangent the next
                # iteration needs; the backtracked trials need the residual only.  Semi-smooth (bordered)
                # problems reject many full steps (Armijo): residuals only there too, unless the last one was kept
                ev1 = self.evaluate(H1, t, tangent=alpha == 1.0 and self._trial_tangent(ev0))
                phi = self._merit(ev1, scales)
            except StepFailed:
                phi = np.inf
            if phi < best[0]:
                best = (phi, H1, alpha)
            if np.isfinite(phi) and phi <= (growth * phi0 if alpha == 1.0 else (1.0 - 1e-4 * alpha) * phi0):
                self.crawl = 0 if alpha == 1.0 else self.crawl + 1
                self.full_taken = alpha == 1.0
                return H1, (self._measured(ev1) if alpha == 1.0 and ev1.kvals is not None else None)
            # minimiser of the quadratic through phi(0), phi'(0) = -2 phi0, phi(alpha)
            if np.isfinite(phi):
                a_new = phi0 * alpha**2 / (phi - phi0 + 2.0 * alpha * phi0)
            else:
                a_new = 0.1 * alpha
            # semi-smooth (bordered) systems: halving (the merit is only piecewise smooth), a tenth after a failure
            alpha = float(np.clip(a_new, 0.1 * alpha, 0.5 * alpha)) if ev0.mult is None or not np.isfinite(phi) \
                else 0.5 * alpha
            problem.multiplier_trial(alpha)
            H1 = problem.update(H, alpha * dz)
        if not np.isfinite(best[0]):
            raise NonFinite("line search found no finite residual along the Newton direction")
        self.crawl += 1
        self.full_taken = False
        problem.multiplier_trial(best[2])
        return best[1], None


