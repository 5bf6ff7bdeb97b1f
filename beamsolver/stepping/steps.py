"""Pseudo-time stepping of ``solve``: step sizes, cut-back, recording, and stopping without loss.

``Run`` walks the user's grid ``t_0 < t_1 < ... < t_steps``.  A step is first
shortened where a prescribed rotation would be ambiguous
(``motion_path.limit_step``); a step whose Newton iterations fail with a
retryable ``failures.StepFailed`` is halved down to ``dt_min`` (compared with a
relative tolerance ``STEP_TOLERANCE`` and ``FLOOR_ULPS`` ulps of ``t``, and a grown step cut back below
``dt_min`` tries ``dt_min`` itself); after two easy steps running the next one
grows (``growth``), never past the user's step (easy: no cut-back and at most ``easy_limit``
Newton iterations, the more of ``EASY_ITERATIONS`` and the iterations of the last step taken at
the user's size: a contact step that needs 15 iterations at any size regrows too; or ``steady``:
about as many iterations as the step before, within 2/3 of the Newton budget, as slip steps of 7-12
iterations at any size), and not back to the size of the
last failed step before ``wait`` easy steps running (``next_step``: the wait doubles
each time that size fails again, up to ``WAIT_MAX``; 2, the fixed rule, until then), and
lands on the grid (no sliver shorter than ``LANDING`` steps before a grid point).  A step after a kink of the
loading path (``kinks``: a reversal, or a motion or load that starts or stops) starts at the size that converged
after the last kink.  Every loop is
bounded: each pass of the main loop advances by at least ``dt_min`` or stops.

Whatever ends a run (``ConvergenceError``, Ctrl-C, an exception from a callback
or a motion), ``abort`` records the converged steps in the output folder
(``solution.npz``, atomically) and attaches the ``Solution`` to the exception.
"""
import logging
import time
import warnings

import numpy as np

from . import branching, diagnosis, kinks, stability, stable_branch
from ..model import buffers, motion_path
from ..nonlinear import linsolve
from ..errors import ConvergenceError, InputError, StabilityWarning, StabilizationWarning
from ..failures import AugmentationFailed, LeftStableBranch, MotionTooFast, NonFinite, StepFailed
from .progress import Progress
from .options import RunOptions
from ..model.material_range import RangeCheck
from ..results.solution import Solution, describe_model

__all__ = ["Run", "growth", "easy_limit", "steady", "next_step", "after_failure", "STEP_TOLERANCE", "FLOOR_ULPS", "EASY_ITERATIONS", "WAIT_MAX",
           "STEP_ZERO_ITERATIONS", "STEP_ZERO_STALL", "STEADY_GROWTH", "STEADY_SHARE"]

log = logging.getLogger("beamsolver")

STEP_TOLERANCE = 1e-9      # relative rounding allowed when comparing step sizes
FLOOR_ULPS = 4.0           # ... and ulps of t allowed when comparing a step with the smallest one (``Run._slack``)
LANDING = 0.1              # a step ending within this fraction of a step before a grid point lands on it
EASY_ITERATIONS = 6        # a step converging within these iterations is easy (growth)
EASY_RUN = 2               # easy steps running before the step grows (growth)
STEADY_GROWTH = 1.25       # steady: at most this times the previous step's iterations, plus one (steady)
STEADY_SHARE = 2.0 / 3.0   # steady: at most this share of max_iter (steady)
WAIT_MAX = 32              # most easy steps running before a step regrows to a size that failed again
MAX_OUTER = 100            # outer iterations of a step (Problem.repeat_step) before it fails
UNDAMPED_MARGIN = 2.0      # an undamped residual up to this times the damped one Newton accepted is equilibrium
STEP_ZERO_ITERATIONS = 4   # Newton budget at t_start / max_iter (no cut-back there; docs/theory.md section 17)
STEP_ZERO_STALL = 10       # step 0 with exact stick's friction: given up after this many iterations without progress
STEP_ZERO_CYCLE = 2        # ... or after this many Newton directions running that reverse the one before (a two-state
#                            cycle, ``newton.CYCLE_COS``; 0: off.  The 19-wire strand twin: given up at iteration 5
#                            instead of 13; issue 30, session 11)
STEP_ZERO_UPDATES = 4      # ... or after this many augmented-Lagrangian updates of its multipliers (outer iterations,
#                            ``MAX_OUTER`` elsewhere; 0: no limit): the 37-wire strand twin's converged after 17, each
#                            re-solve's first residual 0.87 times the last one's (46 of the loaded step's 60 s); the
#                            1+6 strand's converges after 2, the contact examples' step 0 needs none


def growth(iterations, easy):
    """Factor for the next step after a converged one: 2 from the second step running that took
    at most ``EASY_ITERATIONS`` Newton iterations without cut-back (``easy`` counts them, this
    one included), else 1."""
    return 2.0 if easy >= EASY_RUN else 1.0


def easy_limit(reference):
    """Most Newton iterations of an easy step: ``EASY_ITERATIONS``, or ``reference`` (the iterations
    of the last step converged at the user's size without cut-back, ``None``: none yet) if more.
    After a cut-back, a step that converges as fast as the user's steps did counts as easy."""
    return EASY_ITERATIONS if reference is None else max(EASY_ITERATIONS, int(reference))


def steady(iterations, previous, max_iter):
    """Whether a step converged in a steady number of Newton ``iterations``: at most
    ``STEADY_GROWTH * previous + 1`` (``previous``: the iterations of the step before, ``None``:
    none) and at most ``STEADY_SHARE * max_iter``.  A slip-dominated stretch of contact steps
    takes 7-12 iterations at every size; such steps count as easy (the failed-size memory of
    ``next_step`` still holds back a size that failed)."""
    if previous is None:
        return False
    return iterations <= STEADY_GROWTH * previous + 1 and iterations <= STEADY_SHARE * max_iter


def next_step(dt, iterations, easy, failed=np.inf, wait=EASY_RUN):
    """Size of the next step after one of size ``dt`` converged in ``iterations`` (``easy`` as in
    ``growth``), and the memory ``(failed, wait)``: ``failed`` the size of the last failed step
    (``inf``: none), ``wait`` the easy steps running needed before growing back to it.  A step of
    at least ``failed`` converged: forgotten.  Returns ``(size, failed, wait)``, size before the
    cap at the user's step."""
    if dt >= failed * (1.0 - STEP_TOLERANCE):
        failed, wait = np.inf, EASY_RUN
    size = growth(iterations, easy) * dt
    if size >= failed * (1.0 - STEP_TOLERANCE) and easy < wait:
        size = dt
    return size, failed, wait


def after_failure(size, failed=np.inf, wait=EASY_RUN):
    """Memory ``(failed, wait)`` after a step of ``size`` failed: a size at least the last one that
    failed doubles the wait (at most ``WAIT_MAX``), as the fixed rule would retry it every third step."""
    if size >= failed * (1.0 - STEP_TOLERANCE):
        wait = max(min(2 * wait, WAIT_MAX), EASY_RUN)
    return size, wait


class Run:
    """One call of ``solve`` under load control, the stepper ``"load"`` (``stepping.steppers``):
    ``start``, then ``loop``, then ``finish``; ``abort(exc)`` on any exception."""
    name = "load"
    switch_advice = True          # the warning on an unstable state says how to reach a stable one
    multipliers_in_newton = True  # exact stick's multipliers are Newton unknowns (arc length: Uzawa updates)

    @staticmethod
    def path_options(value, restart, branch_switching=False, stabilize=None):
        """The stepper's own options from ``solve(arc_length=)``: none under load control."""
        if value is not None:
            raise InputError("solve: arc_length options need path='arc-length'")
        return None

    def __init__(self, problem, newton, writer, grid, dt_min, verbose, options):
        self.problem, self.sys = problem, problem.system
        self.newton, self.writer, self.grid = newton, writer, grid
        self.dt_user = grid[1] - grid[0]
        self.dt_min = dt_min
        self.verbose = verbose
        self.opt = options = RunOptions.of(options)
        self.sol = None
        self.progress = None
        self.warned_unstable = False
        self.range = None             # material_range.RangeCheck: sections with a yield limit only
        self.negative = None          # negative eigenvalues of the last converged state's tangent, if known
        self.step_negative = None     # the same of the step being tried, if the stable-branch rule counted them
        self.stability = stability.StepCheck(problem, options.check_stability, options.stabilizer)
        self.branch_tries = 0         # LeftStableBranch failures since a step converged at its first try
        self.outer_limit = None       # outer iterations a step may take (step 0 with friction: STEP_ZERO_UPDATES)
        newton.watch_sign = self._watches_branch(problem, options)

    @staticmethod
    def _watches_branch(problem, options):
        """Whether the stable-branch rule (``stable_branch``) watches the steps: a conservative problem, not with
        ``branch_switching`` (its switch moves onto a stable branch itself) nor ``check_stability=False`` (nothing is
        decided about stability then: no cut-back, no warning)."""
        return (problem.conservative and not options.branch_switching and options.check_stability is not False
                and stable_branch.ENABLED)

    # ------------------------------------------------------------------ start
    def start(self, restart_solution, initial_poses):
        sys, grid = self.sys, self.grid
        t_start, steps = grid[0], len(grid) - 1
        self.dt, self.t, self.k, self.easy = self.dt_user, t_start, 1, 0
        self.failed, self.wait, self.reference, self.previous = np.inf, EASY_RUN, None, None
        self.t_before, self.kink_size = None, None     # the converged step before the last one; ``kinks``
        if restart_solution is None:
            self.sol = Solution(sys.model, sys)
            self.range = RangeCheck.of(self.sol.description)
            H0 = sys.poses0.copy() if initial_poses is None else np.array(initial_poses, dtype=float)
            self._step_zero(H0, t_start)
        else:
            self.sol = sol = restart_solution
            self.range = RangeCheck.of(describe_model(sys.model, sys))
            self.H = sol.poses[-1].copy()
            self.t = float(sol.times[-1])
            self.k = int(np.searchsorted(grid, self.t + 1e-12 * self.dt_user, side="right"))
            rs = sol.resume
            if rs.get("t0") == t_start and rs.get("t_end") == grid[-1] and rs.get("steps") == steps:
                dt = float(rs["dt"])
                if np.isfinite(dt) and dt >= self.dt_min * (1.0 - STEP_TOLERANCE):   # else: a bad file
                    self.dt, self.easy = min(dt, self.dt_user), int(rs["easy"])
                    self.failed, self.wait = _memory(rs)
                    self.reference = _reference(rs)
                    self.previous = _reference(rs, "previous")
                    self.kink_size = _size(rs.get("kink_size"))
            self.t_before = float(sol.times[-2]) if len(sol) >= 2 else None
            if self.writer is not None:
                for j in range(len(sol)):
                    self.writer.write(sol, j)
        # the stepping state before the first step: a checkpoint of a run stopped at once says how far it went
        self.sol.resume = dict(t0=float(grid[0]), t_end=float(grid[-1]), steps=int(steps), dt=float(self.dt),
                               easy=int(self.easy), **self._memory_state())
        self.progress = Progress(self.verbose, t_start, grid[-1], self.t)
        if self.opt.stabilizer is not None:
            self.opt.stabilizer.t_last = self.t      # the converged state the first step starts from

    def _step_zero(self, H0, t_start):
        """Step 0: the state ``H0`` at ``t_start`` (prescribed nodes on their motion) or, when loads,
        motions or ``fix`` values act there or contact pushes ``H0`` off balance
        (``Newton.at_rest``), the equilibrium solved there from ``H0`` with
        ``STEP_ZERO_ITERATIONS`` times the Newton budget ``max_iter``: no step can be cut back
        there, and the first state of touching wires converges only linearly (docs/theory.md
        section 17, touching wires at t_start)."""
        sys, problem = self.sys, self.problem
        H = H0.copy()
        if len(sys.prescribed_nodes):
            H[sys.prescribed_nodes] = sys.prescribed_poses(t_start)
            sys.sync_members(H)
        stats, record = dict(iterations=0, residuals=[], wall_time=0.0, dt=0.0, cutbacks=0), None
        acts = _acts_at(sys, H0, t_start)
        pushed, overlap = False, None
        if not acts:
            ev0 = problem.evaluate(H, t_start, tangent=False)
            # contact alone may push the given poses (touching wires under the smoothed law,
            # docs/theory.md 19.2); round-off contact forces ask for a correction at round-off
            pushed = problem.solves_start and not self.newton.at_rest(ev0, H, t_start)
            overlap = problem.initial_overlap(H) if pushed else None
            if overlap:                  # e.g. a strand's wires built overlapping (cables.build_strand)
                self.sol.message = overlap
                log.warning(overlap)
                warnings.warn(overlap, RuntimeWarning, stacklevel=4)
        if acts or pushed:
            t0 = time.perf_counter()
            self.H, self.t = H0, None
            conv = self.newton.conv
            max_iter, conv.max_iter = conv.max_iter, STEP_ZERO_ITERATIONS * conv.max_iter
            # no slip before t_start: friction's multipliers stay out of the Newton unknowns at step 0
            problem.multipliers_in_newton(False)
            try:
                H, ev0, stats = self._solve_start(t_start)
            except StepFailed as e:
                raise self._start_failure(e, pushed, H, t_start) from None
            finally:
                self.t, conv.max_iter = t_start, max_iter
                problem.multipliers_in_newton(self.multipliers_in_newton)
                problem.exact_friction(True)
            stats.update(wall_time=time.perf_counter() - t0, dt=0.0, cutbacks=0)
            if overlap:
                stats.setdefault("warnings", []).append(overlap)
            record = problem.commit(H)
            if problem.contributions:
                self.sol.contact_state = problem.get_state()
        self._check_finite(H, ev0.r, ev0.state, t_start)
        if self.range is not None:
            self.range.check(ev0.state.strain, stats, 0)
        self._record_stability(stats, 0, t_start, H, ev0, solved=acts or pushed)
        adjusted = problem.adjusted
        if adjusted and adjusted["count"]:
            stats["adjusted"] = dict(adjusted)
            log.info("t = %.6g: %d point(s) of reference overlap adjusted to touching, strain-free (largest "
                     "overlap %.3g)", t_start, adjusted["count"], adjusted["largest"])
        self.sol.append(t_start, H, sys.reactions(H, ev0.r), ev0.state.sigma, ev0.state.strain, stats, record,
                        problem.extras or None)
        self.H = H
        if self.writer is not None:
            self.writer.write(self.sol, 0)

    def _solve_start(self, t_start):
        """Newton at ``t_start`` (step 0): ``(H, ev, stats)``.  Exact stick's friction has no history at
        ``t_start``: if the equilibrium is not found with it, it is found without it and friction starts from zero
        traction there, with a warning in the stats (the touching wires of a 1+6+12 strand under their contact
        pre-stress: docs/theory_mortar.md 3b)."""
        newton = self.newton
        # with exact stick's friction, an attempt that stalls (the multipliers' updates alternating between two
        # states, a rope piece: 0.30 / 0.34 for 80 iterations) gives up early: the fallback below solves it
        newton.stall_window = STEP_ZERO_STALL if self.problem.exact_friction(True) else None
        newton.cycle_window = (STEP_ZERO_CYCLE or None) if newton.stall_window else None
        self.outer_limit = (STEP_ZERO_UPDATES or None) if newton.stall_window else None
        newton.start = True                 # the normal law's active set and secant from the first iteration
        self.problem.hold_point_kinds(False)   # each evaluation decides: step 0 moves far and cannot be cut back
        try:
            try:
                return self.newton_step(t_start)
            except StepFailed as e:
                if not self.problem.exact_friction(False):
                    raise
                failed = e
            finally:
                newton.stall_window = newton.cycle_window = self.outer_limit = None
            if buffers.RELEASE_AT_COMMIT:      # the failed attempt's work arrays (exact stick's point terms) go
                buffers.release_idle(fix_threshold=False)
            H, ev0, stats = self.newton_step(t_start)
        finally:
            newton.start = False
            self.problem.hold_point_kinds(True)
        note = (f"step 0 (t = {t_start:.6g}): no equilibrium with exact stick's friction ({failed}); found "
                "without it, friction starts from zero traction at that state")
        log.warning(note)
        stats.setdefault("warnings", []).append(note)
        return H, ev0, stats

    def _start_failure(self, e, pushed, H, t_start):
        """The ``ConvergenceError`` of a step 0 that failed with ``e`` (``pushed``: contact pushes the given
        poses ``H``, nothing else acts)."""
        self.sol.converged, self.sol.message = False, str(e)
        if pushed:
            why = (f"contact forces already act ({diagnosis.pushing_point(self.problem, H)}): {e}; "
                   "separate the beams by a small gap, let add_contact(adjust=) cover the overlap "
                   "(strain-free adjustment) or raise max_iter")
        else:
            why = f"loads or motions already act: {e}; start the loads from zero or use more steps"
        why += self.opt.penalty_hint
        err = ConvergenceError(f"solve: no equilibrium at t_start = {t_start:.6g}, where {why}", self.sol)
        err.failure = e
        return err

    def _name_nonfinite(self, t):
        """A non-finite residual from the user's input (a load scale or motion at ``t``): InputError."""
        found = diagnosis.nonfinite_source(self.problem, self.H, t)
        if found is not None and found[0]:
            raise InputError(f"solve: at t = {t:.6g} {found[1]}")

    def _check_finite(self, H, r, state, t):
        """Never record a non-finite state: name the input behind it (``InputError``) or fail."""
        if np.all(np.isfinite(r)) and np.all(np.isfinite(H)) and np.all(np.isfinite(state.sigma)):
            return
        found = diagnosis.nonfinite_source(self.problem, H, t)
        if found is not None and found[0]:
            raise InputError(f"solve: at t = {t:.6g} {found[1]}")
        raise NonFinite(f"non-finite state at t = {t:.6g}" + (f": {found[1]}" if found else ""))

    # ------------------------------------------------------------------ steps
    def loop(self):
        grid = self.grid
        steps = len(grid) - 1
        while self.k <= steps:
            t_next = min(self.t + self.dt, grid[self.k])
            if grid[self.k] - t_next < max(1e-9 * self.dt_user, LANDING * self.dt):
                t_next = grid[self.k]           # no sliver before the grid point
            kink = self.t_before is not None and kinks.kink(self.sys, self.t_before, self.t, t_next)
            if kink:                             # the size that converged after the last kink, or a share of the step
                size = self.kink_size if self.kink_size is not None else \
                    (kinks.FIRST if kink == "start" else 1.0) * (t_next - self.t)
                if t_next - self.t > size * (1.0 + STEP_TOLERANCE):
                    t_next = self.t + max(size, self.dt_min)
            t0 = time.perf_counter()
            t_start = self.t
            try:
                t_next, H, ev, stats = self._attempt(t_next)
            finally:
                self.newton.retrying = False
            stats.update(wall_time=time.perf_counter() - t0, dt=t_next - t_start)
            if kink:
                self.kink_size = t_next - t_start
                stats["kink"] = True
            self._record(t_next, H, ev, stats)

    def _attempt(self, t_next):
        """Converge the step ``t -> t_next``, halving it on failure; returns the step reached."""
        t, cutbacks, rotation_limit, failed_sizes, branch_here = self.t, 0, None, [], 0
        before = self._negative_before()
        while True:
            self.step_negative = None
            t_try, rot = motion_path.limit_step(self.sys, t, t_next)
            if t_try < t_next and t_try - t < self.dt_min - self._slack(t_try):
                self._stop(MotionTooFast(f"a prescribed rotation turns by {rot:.3g} rad over a step of "
                                      f"{t_try - t:.3g}, more than MAX_MOTION_ROTATION = "
                                      f"{motion_path.MAX_MOTION_ROTATION:.3g} rad, even at the smallest step"),
                           rotation_limit)
            self.newton.reset_timings()
            self.newton.retrying = cutbacks > 0    # (exact stick's active-set directions, ``newton.RETRY_SWITCHES``)
            try:
                H, ev, stats = self.newton_step(t_try)
                self._check_finite(H, ev.r, ev.state, t_try)
                stats.update(cutbacks=cutbacks, timings=dict(self.newton.timings))
                if failed_sizes:
                    stats["failed_dt"] = list(failed_sizes)
                if t_try < t_next:
                    stats["motion_rotation"] = rot
                self._keep_branch(t_try, H, ev, stats, before)
                if not cutbacks:
                    self.branch_tries = 0
                return t_try, H, ev, stats
            except StepFailed as e:
                if isinstance(e, NonFinite):
                    self._name_nonfinite(t_try)
                h = 0.5 * (t_try - t)
                # the smallest step failed: ``t + dt_min - t`` is ``dt_min`` only up to the round-off of ``t``
                # (1e7 ulps of t = 0.94 in a 2e-9 step: 5e-8 of it, above STEP_TOLERANCE), so the test has that slack
                at_floor = t_try - t <= self.dt_min + self._slack(t_try)
                if not at_floor and h < self.dt_min:
                    h = self.dt_min             # a grown step cut back: the smallest step is still tried
                if isinstance(e, LeftStableBranch):
                    branch_here, self.branch_tries = branch_here + 1, self.branch_tries + 1
                    if branch_here > stable_branch.RETRIES or self.branch_tries > stable_branch.RETRIES_RUN or \
                            at_floor:
                        return self._keep_unstable(e)
                cutbacks += 1
                failed_sizes.append(t_try - t)
                self.failed, self.wait = after_failure(t_try - t, self.failed, self.wait)
                if e.rotation:
                    rotation_limit = str(e)
                log.info("t = %.6g: step %.3g failed (%s); cutting back to %.3g", t_try, t_try - t, e, h)
                if not e.retry or at_floor:
                    self._stop(e, rotation_limit)
                t_next = t + h
                self.easy = 0

    def _slack(self, t):
        """Absolute slack of a comparison with the smallest step ending at ``t``: ``STEP_TOLERANCE`` of it and
        ``FLOOR_ULPS`` ulps of ``t`` (a step's length ``t_try - t`` carries the rounding of ``t + dt``)."""
        return STEP_TOLERANCE * self.dt_min + FLOOR_ULPS * np.spacing(abs(t))

    def _negative_before(self):
        """``before()`` of ``stable_branch.verdict`` for a step from the current state: its
        negative-eigenvalue count, known from the last step's check or computed once when asked
        (``None`` where the problem is not conservative)."""
        known, ev = self.negative, getattr(self.newton, "last_evaluation", None)
        cache = []

        def before():
            if known is not None:
                return known
            if not cache:
                e = ev if ev is not None else self.problem.evaluate(self.H, self.t, tangent=True)
                cache.append(stable_branch.negative_count(self.problem, e))
            return cache[0]
        return before

    def _keep_branch(self, t, H, ev, stats, before):
        """``stable_branch.verdict`` on the step converged at ``t``: raises ``LeftStableBranch``
        carrying the step, for ``_keep_unstable`` (not with ``branch_switching``, whose switch
        moves the path onto a stable branch itself).  Only a step whose first tangent had ``det < 0``
        (``Newton.indefinite_seen``) or that took undamped Newton iterations (the fallback, or
        ``line_search=False``) is checked."""
        if not self._watches_branch(self.problem, self.opt):
            return
        if not (self.newton.indefinite_seen or stats.get("undamped") is not None or not self.newton.line_search):
            self.negative = None        # every tangent of the step had det > 0: not checked (stable_branch)
            return
        try:
            self.negative = self.step_negative = stable_branch.verdict(self.problem, self.newton.last_evaluation,
                                                                       before, t)
        except LeftStableBranch as e:
            e.t, e.result = t, (t, H, ev, stats)
            raise

    def _keep_unstable(self, failure):
        """Keep the unstable state of ``failure`` (``LeftStableBranch``) after ``stable_branch.RETRIES``
        such failures of a step, or ``RETRIES_RUN`` since a step converged at its first try, or at
        the smallest step, and say so once (``StabilityWarning``; where steps are checked
        (``stability.StepCheck.checks``) the check's warning reports it)."""
        t, H, ev, stats = failure.result
        self.negative = self.step_negative = failure.negative
        self.branch_tries = 0
        stats.update(left_stable_branch=True)
        text = stable_branch.kept(failure)
        if not self.warned_unstable and not self.stability.checks:
            self.warned_unstable = True
            log.warning(text)
            warnings.warn(text, StabilityWarning, stacklevel=5)
            self.sol.message = text if not self.sol.message else self.sol.message + "; " + text
        return failure.result

    def newton_step(self, t_next, start=None):
        """Newton at ``t_next`` (from the last converged state, or from ``start`` at ``t_next``),
        repeated while the problem asks to re-solve the step (outer iterations, e.g.
        augmented-Lagrangian updates); refused or warned if ``Problem.unmet``."""
        sys, newton, problem = self.sys, self.newton, self.problem
        H_target = sys.prescribed_poses(t_next) if len(sys.prescribed_nodes) else None
        problem.begin_step(self.H, t_next)
        H0, t_prev = (self.H, self.t) if start is None else (start, t_next)
        H, ev, stats = newton.step(H0, t_next, H_target, t_prev)

        def again(state):
            H, ev, more = newton.step(state[0], t_next, H_target, self.t)
            return (H, ev), more
        H, ev = self.outer_iterations((H, ev), stats, t_next, again)
        if self.opt.stabilizer is not None:
            self.opt.stabilizer.check(problem.tangent(newton.last_evaluation), t_next)
        self.check_unmet(t_next, stats)
        return H, ev, stats

    def outer_iterations(self, state, stats, t, again):
        """Re-solve the step converged at ``t`` while the problem asks (``Problem.repeat_step``, e.g.
        augmented-Lagrangian updates), at most ``MAX_OUTER`` times: ``state`` a tuple whose first
        item is the converged poses, ``again(state)`` -> ``(state, more stats)``; the iterations and
        residuals are added to ``stats``.  Returns the last state.  ``AugmentationFailed`` after ``outer_limit``
        of them if set (step 0's attempt with exact stick's friction), else after ``MAX_OUTER``."""
        while self.problem.repeat_step(state[0]):
            if self.outer_limit and stats.get("augmentations", 0) >= self.outer_limit:
                raise AugmentationFailed(f"{self.outer_limit} augmented-Lagrangian updates did not meet the "
                                         "tolerances")
            if stats.get("augmentations", 0) >= MAX_OUTER:
                raise AugmentationFailed(f"the outer iterations (augmented-Lagrangian updates) still ask to re-solve "
                                         f"the step at t = {t:.6g} after MAX_OUTER = {MAX_OUTER}")
            state, more = again(state)
            stats["iterations"] += more["iterations"]
            stats["residuals"] += more["residuals"]
            stats["augmentations"] = stats.get("augmentations", 0) + 1
        return state

    def check_unmet(self, t, stats):
        """Refuse (``AugmentationFailed``) or, with ``allow_unmet_tolerance``, warn about a step whose
        contributions' tolerance is unmet (``Problem.unmet``)."""
        text = self.problem.unmet(t)
        if text:
            if not self.opt.allow_unmet_tolerance:
                raise AugmentationFailed(text + " (solve(..., allow_unmet_tolerance=True) accepts it "
                                         "with a warning)")
            stats.setdefault("warnings", []).append(text)
            log.warning(text)
            warnings.warn(text, RuntimeWarning, stacklevel=5)

    def _record(self, t_next, H, ev, stats):
        sys, sol, problem = self.sys, self.sol, self.problem
        stab = self.opt.stabilizer
        damped = H
        if stab is not None:
            balance = self._undamped(stab, H, ev)
            if stab.settle and not balance["equilibrium"] and t_next >= self.grid[-1] - 1e-12 * self.dt_user:
                H, ev, balance = self._settle(stab, t_next, H, ev, stats, balance)
        t_next, H, ev = self._stability(stats, t_next, H, ev)
        solver = getattr(self.newton, "linsolver", None)
        if linsolve.DROP_BASE_AT_COMMIT and solver is not None:
            solver.drop_base()
        record = problem.commit(H)
        if stab is not None:
            stats["stabilization"] = dict(stab.record(damped, t_next), **balance)
        for w in stats.get("warnings", ()):
            sol.message = w if not sol.message else sol.message + "; " + w
        # the stepping state after this step, set together with the step (restart reads both)
        dt = t_next - self.t
        t, k = t_next, self.k
        if t >= self.grid[k] - 1e-12 * self.dt_user:
            t, k = self.grid[k], k + 1
        if stats["cutbacks"] == 0 and dt >= self.dt_user * (1.0 - STEP_TOLERANCE):
            self.reference = stats["iterations"]
        its, previous, self.previous = stats["iterations"], self.previous, stats["iterations"]
        calm = its <= easy_limit(self.reference) or steady(its, previous, self.newton.conv.max_iter)
        easy = self.easy + 1 if calm and stats["cutbacks"] == 0 else 0
        dt, self.failed, self.wait = next_step(dt, stats["iterations"], easy, self.failed, self.wait)
        dt = min(dt, self.dt_user)
        if problem.contributions:
            sol.contact_state = problem.get_state()
        if self.range is not None:
            self.range.check(ev.state.strain, stats, len(sol))
        sol.append(t_next, H, sys.reactions(H, ev.r), ev.state.sigma, ev.state.strain, stats, record,
                   problem.extras or None)
        sol.resume = dict(t0=float(self.grid[0]), t_end=float(self.grid[-1]), steps=len(self.grid) - 1,
                          dt=float(dt), easy=int(easy), **self._memory_state())
        self.t_before = self.t
        self.H, self.t, self.k, self.dt, self.easy = H, t, k, dt, easy
        if self.writer is not None:
            self.writer.write(sol, sol.n_steps)
        self.progress.step(sol.n_steps, t_next, stats["dt"], stats)

    def _undamped(self, stab, H, ev):
        """The balance of the converged state ``H`` (evaluation ``ev``) without the viscous forces of
        the stabilisation ``stab``: ``undamped_residual`` (scaled as Newton's residual) and
        ``equilibrium``: at most the solve's ``rtol``, or twice the damped residual Newton accepted
        (a step converged on its increment), i.e. an equilibrium of the model itself."""
        full = self.newton.residual_ratio(ev)
        if not stab.active:
            return dict(undamped_residual=full, equilibrium=True)
        blocks, _ = stab.evaluate(H, tangent=False)
        ratio = self.newton.residual_ratio(ev, ev.r - self.sys.assemble_blocks(H, blocks)[0])
        return dict(undamped_residual=ratio,
                    equilibrium=bool(ratio <= max(self.newton.conv.rtol, UNDAMPED_MARGIN * full)))

    def _settle(self, stab, t, H, ev, stats, balance):
        """The last step's damped state ``H`` (evaluation ``ev``, ``balance`` of ``_undamped``) solved once
        more at ``t`` without the viscous forces, from ``H``: ``(H, ev, balance)`` of the equilibrium
        reached, or the damped ones if Newton fails there; ``stats["settle"]`` records which."""
        stab.suspended = True
        try:
            H1, ev1, more = self.newton_step(t, start=H)
            self._check_finite(H1, ev1.r, ev1.state, t)
        except StepFailed as e:
            stats["settle"] = dict(failed=str(e), from_residual=balance["undamped_residual"])
            log.warning("t = %.6g: the undamped solve of the last step failed (%s); its damped state is kept", t, e)
            return H, ev, balance
        finally:
            stab.suspended = False
        stats["settle"] = dict(iterations=more["iterations"], residuals=more["residuals"],
                               from_residual=balance["undamped_residual"])
        return H1, ev1, dict(undamped_residual=self.newton.residual_ratio(ev1), equilibrium=True)

    def _off_equilibrium(self):
        """A stabilised run whose final state is not an equilibrium of the model (``_undamped``):
        ``Solution.mark_off_equilibrium`` with the reason, and a ``StabilizationWarning``."""
        sol = self.sol
        rec = sol.stats[-1].get("stabilization", {}) if len(sol) else {}
        if rec.get("equilibrium", True):
            return
        text = (f"t = {sol.times[-1]:.6g}: the final state is not an equilibrium of the model: without the "
                f"stabilisation's viscous forces the scaled residual is {rec['undamped_residual']:.3g} (rtol "
                f"{self.newton.conv.rtol:g}): the damping still carries that share of the largest force; "
                "stabilize=dict(..., settle=True) solves the last step once more without damping, or use a "
                "smaller stabilize fraction or factor")
        log.warning(text)
        warnings.warn(text, StabilizationWarning, stacklevel=4)
        sol.mark_off_equilibrium(text)

    def _memory_state(self):
        """The failed-size memory of ``next_step``, the ``easy_limit`` reference and the ``steady``
        previous iterations for ``resume`` (JSON: no inf)."""
        return dict(failed=None if not np.isfinite(self.failed) else float(self.failed), wait=int(self.wait),
                    reference=self.reference, previous=self.previous,
                    kink_size=None if self.kink_size is None else float(self.kink_size))

    def _stability(self, stats, t, H, ev):
        """Record whether the converged state ``H`` (evaluation ``ev``) is a stable equilibrium
        (``stability.StepCheck``), its lowest modes (``modes``) and, with ``branch_switching``, move
        onto a stable branch (``branching.switch``, which may record the step at an earlier ``t``,
        past a crossing); warn once.  Returns the step to record ``(t, H, ev)``."""
        check = self.stability
        K = check.tangent(H, t, self.newton.last_evaluation)
        neg = check.record(stats, K, self.step_negative)
        if K is not None:
            if branching.wanted(self.opt.branch_switching, self.sol.stats, neg):
                t, H, ev, K = branching.switch(self, stats, t, H, ev, K)
            if self.opt.modes:
                branching.record_modes(self.sys, stats, H, K, self.opt.modes)
            neg = stats["negative_eigenvalues"]
        self.negative = neg if self.problem.conservative else None
        self._warn_unstable(stats, len(self.sol), t)
        return t, H, ev

    def _record_stability(self, stats, step, t, H, ev, solved=True):
        """``stability.StepCheck`` on a state recorded without ``_stability`` (step 0); one kept as
        given (not ``solved``) is checked only if it is an equilibrium (``Newton.at_rest``)."""
        check = self.stability
        if check.checks and not solved and not self.newton.at_rest(ev, H, t):
            neg = check.record(stats, None, note=stability.unsolved_note(self.newton.residual_ratio(ev)))
        else:
            neg = check.record(stats, check.tangent(H, t, ev))
        self.negative = neg if self.problem.conservative else None
        self._warn_unstable(stats, step, t)

    def _warn_unstable(self, stats, step, t):
        """The first unstable state of the run, recorded as step ``step`` at ``t``: ``StabilityWarning``
        and ``Solution.message`` (``stability.unstable_text``)."""
        if stats.get("stable") is not False or self.warned_unstable:
            return
        self.warned_unstable = True
        text = stability.unstable_text(step, t, stats["negative_eigenvalues"], stats.get("left_stable_branch", False),
                                       self.switch_advice)
        log.warning(text)
        warnings.warn(text, StabilityWarning, stacklevel=6)
        self.sol.message = text if not self.sol.message else self.sol.message + "; " + text

    # ------------------------------------------------------------------ end
    def _stop(self, failure, rotation_limit, why=None):
        """Raise ``ConvergenceError`` for ``failure`` at the current step; ``why``: what could not
        advance (default: the step fell below its floor)."""
        sol = self.sol
        hint = self.opt.advice(failure, rotation_limit, self.H, self.t)
        sol.converged = False
        sol.message = str(failure)
        why = why or f"could not advance from t = {self.t:.6g} (step fell below {self.dt_min:.3g})"
        err = ConvergenceError(f"solve: {why}: {failure}{hint}", sol)
        err.failure = failure
        raise err from None

    def abort(self, exc):
        """Keep what converged: save it, close the output, attach ``.solution`` to ``exc``."""
        if self.progress is not None:
            self.progress.close()
        sol = self.sol
        if sol is not None:
            if not isinstance(exc, ConvergenceError):   # interrupted: what converged stands (restartable)
                sol.message = f"stopped by {type(exc).__name__}: {exc}" if str(exc) else \
                    f"stopped by {type(exc).__name__}"
            if getattr(exc, "solution", None) is None:
                try:
                    exc.solution = sol
                except AttributeError:
                    pass
        if self.writer is not None:
            try:
                entries = getattr(self.writer, "entries", None)
                if sol is not None and len(sol) and entries is not None and sol.n_steps not in entries:
                    self.writer.write(sol, sol.n_steps)
            except Exception as e:      # never hide the exception that ended the run
                log.error("could not save the solution after %s: %s", type(exc).__name__, e)
            finally:
                try:
                    self.writer.close()
                except Exception as e:
                    log.error("could not close the output after %s: %s", type(exc).__name__, e)

    def finish(self):
        self.progress.close()
        if self.opt.stabilizer is not None:
            self._off_equilibrium()
        if self.writer is not None:
            self.writer.close()
        return self.sol


def _memory(resume):
    """``(failed, wait)`` from a ``resume`` dict; a missing or damaged entry: no memory."""
    try:
        failed = float(resume.get("failed"))
        wait = int(resume.get("wait"))
    except (TypeError, ValueError, OverflowError):
        return np.inf, EASY_RUN
    if not (np.isfinite(failed) and failed > 0):
        return np.inf, EASY_RUN
    return failed, min(max(wait, EASY_RUN), WAIT_MAX)


def _size(value):
    """A step size from a ``resume`` entry; missing or damaged: ``None``."""
    try:
        size = float(value)
    except (TypeError, ValueError, OverflowError):
        return None
    return size if np.isfinite(size) and size > 0 else None


def _reference(resume, key="reference"):
    """The ``easy_limit`` reference (or ``key``: another iteration count) of a ``resume`` dict;
    missing or damaged: ``None``."""
    try:
        ref = int(resume.get(key))
    except (TypeError, ValueError, OverflowError):
        return None
    return ref if ref >= 0 else None


def _acts_at(system, H, t):
    """Whether loads, prescribed motions or ``fix`` values act at ``t`` on the state ``H``."""
    if len(system.load_scales) and system.loads_act(system.load_factors(t)):
        return True
    if len(system.prescribed_nodes) and np.any(system.prescribed_poses(t) != H[system.prescribed_nodes]):
        return True
    return any(dx != 0 for _, _, dx in system.fixed_value_increments(H, t)) if system.fix_values else False


