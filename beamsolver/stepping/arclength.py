"""Arc-length path following in pseudo-time: ``solve(..., path="arc-length")``.

The pseudo-time ``t`` (which drives the load scales, the prescribed motions and
the ``fix(values=)`` targets) becomes an unknown next to the free increments
``z``.  Each step from the equilibrium ``(H_0, t_0)`` seeks ``(H, t)`` with

    r_f(H, t) = 0,     |S dz|^2 + psi^2 (t - t_0)^2 = ds^2        (docs/theory.md eq. 16.1)

(Crisfield's spherical constraint), ``dz`` the sum of the step's free increments,
``S`` the unit-free scaling of ``Convergence`` (translations over the model size,
rotations in radians) and ``psi`` the scaled displacement rate ``|S dz/dt|`` of the
first step, so both terms weigh alike at the start (``psi=0``: cylindrical).
Newton's iterations border the tangent: with one factorisation of ``K_ff`` two
solves give ``dz_r = -K^-1 r_f`` and ``dz_t = -K^-1 dr_f/dt`` (``rate``), the
increment is ``dz_r + dt dz_t`` and ``dt`` is the root of the quadratic
constraint closer in angle to the step's increment so far (``sphere_root``); a
negative discriminant takes the linearised constraint for that iteration and
halves the next arc length.  The predictor follows ``dz_t`` in the direction of
the previous step.  The arc length adapts to the iterations (``next_arc_length``),
halves on a failed step down to ``min``, and the run stops on reaching ``t_end``
(hit exactly by a final load-controlled correction, ``t`` fixed) or after
``max_steps`` steps (``Solution.converged`` is then False and a warning says so).
"""
import logging
import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..nonlinear import linsolve
from ..model import motion_path
from ..lie import se3
from ..errors import InputError
from ..failures import NonFinite, SingularTangent, StepFailed
from .steps import STEP_TOLERANCE, Run

__all__ = ["ArcLength", "arc_length_options", "check_arc_length_arguments", "ArcLengthRun", "Sphere", "sphere_root",
           "next_arc_length", "rate", "RATE_STEP", "TURN_BACK"]

log = logging.getLogger("beamsolver")

RATE_STEP = 1e-6       # finite-difference step of dr/dt, relative to t_end - t_start (scale and motion rates)
TURN_BACK = 0.0        # a converged step whose direction makes cos <= this with the previous one turned back


@dataclass(frozen=True)
class ArcLength:
    """Options of ``solve(..., path="arc-length", arc_length=...)`` (a dict with these keys works too).

    Arc lengths are unit-free: ``sqrt(|dz_u / L|^2 + |dz_w|^2 + psi^2 dt^2)`` over a step, ``L``
    the model size, rotations in radians.
    ``initial``: first arc length (``None``: the one whose first step advances ``t`` by
    ``(t_end - t_start) / steps``); ``min``: smallest (``None``: ``initial * min_step_ratio``);
    ``max``: largest (``None``: ``initial``); ``target_iterations``: Newton iterations per step the
    adaptation aims at (``ds <- ds sqrt(target / iterations)``, by 0.5 to 2); ``max_steps``: most
    steps (``None``: ``25 * steps``); ``psi``: weight of the pseudo-time (``None``: the scaled
    displacement rate of the first step; ``0``: cylindrical constraint).
    """
    initial: float = None
    min: float = None
    max: float = None
    target_iterations: int = 5
    max_steps: int = None
    psi: float = None


def _positive(name, v, none=True, zero=False):
    if v is None and none:
        return None
    ok = isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool) and np.isfinite(v) \
        and (v >= 0 if zero else v > 0)
    if not ok:
        raise InputError(f"solve: arc_length {name} must be a finite number {'>= 0' if zero else '> 0'}"
                         f"{' or None' if none else ''}, got {v!r}")
    return float(v)


def arc_length_options(value):
    """``ArcLength`` from ``None``, a dict or an ``ArcLength``; bad keys or values: ``InputError``."""
    if value is None:
        return ArcLength()
    if isinstance(value, ArcLength):
        value = value.__dict__
    if not isinstance(value, dict):
        raise InputError(f"solve: arc_length must be a dict, an ArcLength or None, got {value!r}")
    unknown = sorted(set(value) - set(ArcLength.__dataclass_fields__))
    if unknown:
        raise InputError(f"solve: unknown arc_length option(s) {unknown}; known: "
                         f"{sorted(ArcLength.__dataclass_fields__)}")
    out = ArcLength(**value)
    for name in ("initial", "min", "max"):
        _positive(name, getattr(out, name))
    _positive("psi", out.psi, zero=True)
    for name in ("target_iterations", "max_steps"):
        v = getattr(out, name)
        if v is None and name == "max_steps":
            continue
        if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= 1):
            raise InputError(f"solve: arc_length {name} must be a positive integer, got {v!r}")
    if out.min is not None and out.max is not None and out.min > out.max:
        raise InputError(f"solve: arc_length min {out.min!r} exceeds max {out.max!r}")
    return out


def sphere_root(w, tau, dw_r, dw_t, psi, ds):
    """Pseudo-time correction ``dt`` on the sphere ``|w + dw_r + dt dw_t|^2 + psi^2 (tau + dt)^2 = ds^2``
    (docs/theory.md eq. 16.4).

    ``w``, ``tau``: the step's scaled increment and pseudo-time change so far; ``dw_r``, ``dw_t``:
    the scaled solves ``S dz_r``, ``S dz_t``.  Of the two real roots the one whose new increment
    makes the smaller angle with ``(w, tau)`` (Crisfield's criterion).  Returns ``(dt, linearised)``;
    with no real root, ``dt`` of the constraint linearised in ``dt`` and ``linearised = True``.
    """
    p = w + dw_r
    a = float(dw_t @ dw_t) + psi**2
    b = 2.0 * (float(p @ dw_t) + psi**2 * tau)
    c = float(p @ p) + psi**2 * tau**2 - ds**2
    disc = b * b - 4.0 * a * c
    if a > 0.0 and disc >= 0.0:
        q = -0.5 * (b + np.copysign(np.sqrt(disc), b))       # stable pair q / a, c / q
        roots = [q / a] + ([c / q] if q != 0.0 else [])
        cos = [float(w @ (p + d * dw_t)) + psi**2 * tau * (tau + d) for d in roots]
        return roots[int(np.argmax(cos))], False
    if b == 0.0:
        raise StepFailed("arc-length constraint: no root and no slope in the pseudo-time")
    return -c / b, True


def next_arc_length(ds, iterations, target, cut, linearised):
    """Arc length after a converged step of ``ds`` in ``iterations``: ``ds sqrt(target / iterations)``
    by a factor 0.5 to 2 (at most 1 after a cut-back, at most 0.5 after a linearised iteration),
    before the cap to ``[min, max]`` (docs/theory.md eq. 16.6)."""
    f = float(np.clip(np.sqrt(target / max(iterations, 1)), 0.5, 2.0))
    if cut:
        f = min(f, 1.0)
    if linearised:
        f = min(f, 0.5)
    return ds * f


def rate(problem, H, t, ev, delta, t_start):
    """``dr_f/dt`` ``(n_free,)`` at the state ``H`` (constrained nodes on their targets at ``t``;
    ``ev`` its ``problem.Evaluation`` with the tangent; docs/theory.md eq. 16.3).

    Loads: ``-f_ext(H, dlf/dt) = r(H, dlf/dt) - r(H, 0)`` (the residual is linear in the load factors;
    ``dlf/dt`` by a central difference of the scale functions); prescribed motions and ``fix(values=)``: ``K_fc dz_c/dt``
    with the velocity ``dz_c/dt`` (body increments of the motion, global ones of the fixed values)
    by a central difference of step ``delta`` (forward where ``t - delta < t_start``).
    """
    sys = problem.system
    lo = t - delta if t - delta >= t_start else t
    span = t + delta - lo
    out = np.zeros(sys.n_free)
    if len(sys.load_scales):
        dlf = (sys.load_factors(t + delta) - sys.load_factors(lo)) / span
        if np.any(dlf):
            r = sys.evaluate(H, dlf, tangent=False)[0] - sys.evaluate(H, np.zeros_like(dlf), tangent=False)[0]
            out += r[sys.free_dofs]
    if len(sys.prescribed_nodes) or sys.fix_values:
        v = np.zeros((sys.n_nodes, 6))
        p = sys.prescribed_nodes
        if len(p):
            Hc = H[p]
            up = se3.log(se3.relative(Hc, sys.prescribed_poses(t + delta)))
            down = se3.log(se3.relative(Hc, sys.prescribed_poses(lo))) if lo < t else 0.0
            v[p] = (up - down) / span
        for node, comp, f in sys.fix_values:
            v[node, comp] = (float(f(t + delta)) - float(f(lo))) / span
        if np.any(v):
            out += problem.coupling(ev, v)
    return out


class Sphere:
    """The arc-length constraint of one step for ``Newton.iterate`` (``nonlinear.newton.Constraint``):
    every correction is ``dz_r + dt dz_t`` (``ArcLengthRun.solve2``) with ``dt`` the root of the
    sphere of radius ``ds`` (``sphere_root``), or ``dt = t_fixed - t`` with ``t_fixed`` given;
    the iterate then moves with its constrained nodes onto their targets at ``t + dt``
    (``ArcLengthRun.move``).  ``w``, ``tau``: the step's scaled increment and pseudo-time change so
    far (updated); ``linearised``: the iterations that took the linearised constraint."""
    final = True
    moves = True
    damped = False
    watch_sign = False

    def __init__(self, run, w, tau, ds, t_fixed=None):
        self.run, self.w, self.tau, self.ds, self.t_fixed = run, w, tau, ds, t_fixed
        self.linearised = 0
        self.dt = None

    def direction(self, newton, ev, H, t):
        run = self.run
        dz_r, dz_t = run.solve2(ev, H, t)
        if self.t_fixed is None:
            dt, lin = sphere_root(self.w, self.tau, run.S * dz_r, run.S * dz_t, run.psi, self.ds)
            self.linearised += lin
        else:
            dt = self.t_fixed - t
        dzf = dz_r + dt * dz_t
        self.w, self.tau, self.dt = self.w + run.S * dzf, self.tau + dt, dt
        return None, dzf

    def move(self, newton, H, t, dzf):
        inc = newton.conv.increment_ratio(newton.full(dzf), newton.L_ref)
        return self.run.move(H, t, dzf, t + self.dt), t + self.dt, inc

    def accept(self, newton, H):
        pass

    def stats(self):
        return dict(linearised=self.linearised)


class ArcLengthRun(Run):
    """``stepping.Run`` with ``loop`` following the path by arc length (see the module docstring);
    ``options.path``: its ``ArcLength`` (``None``: the defaults)."""
    name = "arc-length"
    switch_advice = False      # it follows unstable branches: the warning on one gives no advice
    multipliers_in_newton = False  # the bordered solves keep t fixed: exact stick by Uzawa updates

    def __init__(self, problem, newton, writer, grid, dt_min, verbose, options):
        super().__init__(problem, newton, writer, grid, dt_min, verbose, options)
        problem.multipliers_in_newton(False)     # the bordered solves keep t fixed: Uzawa updates instead
        self.arc = self.opt.path if self.opt.path is not None else ArcLength()
        self.t_end = float(grid[-1])
        self.span = float(grid[-1] - grid[0])
        sys = self.sys
        scale = np.ones(6 * sys.n_nodes)
        scale.reshape(-1, 6)[:, :3] = 1.0 / newton.L_ref
        self.S = scale[sys.free_dofs]           # unit-free weights of the free increments
        self.prev = None                        # (w, tau) of the last converged step
        self._converged = None                  # (H, t, evaluation) of the last converged iterate

    @staticmethod
    def path_options(arc_length, restart, branch_switching=False, stabilize=None):
        """``ArcLength`` options of ``path="arc-length"``; ``InputError`` on bad input.

        ``restart``, ``branch_switching`` and ``stabilize`` are refused with ``"arc-length"``: the switch
        bisects the load and re-solves under load control, and the viscous forces need the step ``dt``
        known before the step, which a path past a limit point does not give (``modes=`` and
        ``check_stability`` work)."""
        if restart is not None:
            raise InputError("solve: restart is not supported with path='arc-length' (start the run again)")
        if branch_switching is not False and branch_switching is not None:
            raise InputError(f"solve: branch_switching={branch_switching!r} is not supported with path='arc-length' "
                             "(the switch re-solves under load control); use path='load' for it, or modes= to see "
                             "the critical modes along the arc-length path")
        if stabilize is not None and stabilize is not False:
            raise InputError(f"solve: stabilize={stabilize!r} is not supported with path='arc-length' (the viscous "
                             "forces divide by a pseudo-time step known in advance); arc length passes limit points "
                             "without it, use stabilize with path='load'")
        return arc_length_options(arc_length)

    @property
    def t_iter(self):
        """Pseudo-time of the last evaluated iterate (failure messages)."""
        t = self.newton.t_evaluated
        return float(self.grid[0]) if t is None else t

    # ------------------------------------------------------------ linear algebra
    def solve2(self, ev, H, t):
        """``(dz_r, dz_t)`` at the iterate ``(H, t)`` (evaluation ``ev``): one factorisation of
        ``K_ff``, two solves (``-r_f`` and ``-dr_f/dt``)."""
        newton, sys = self.newton, self.sys
        t0 = time.perf_counter()
        K = self.problem.tangent(ev)
        drdt = rate(self.problem, H, t, ev, RATE_STEP * self.span, float(self.grid[0]))
        if not np.all(np.isfinite(drdt)):
            raise NonFinite(f"the pseudo-time rate dr/dt is not finite at t = {t:.6g}")
        t1 = time.perf_counter()
        try:
            lu = linsolve.factorize_tangent(K, newton.linsolver)
            dz_r = lu.solve(-ev.r[sys.free_dofs])
            dz_t = lu.solve(-drdt)
        finally:
            newton.timings["assembly"] += t1 - t0
            newton.timings["linear_solve"] += time.perf_counter() - t1
        if not (np.all(np.isfinite(dz_r)) and np.all(np.isfinite(dz_t))):
            raise SingularTangent("the linear solve returned non-finite values")
        return dz_r, dz_t

    def move(self, H, t, dzf, t_new):
        """Free nodes by ``dzf``, constrained ones onto their targets at ``t_new`` (``Newton.move``:
        prescribed poses exactly, ``fix(values=)`` components by their increments)."""
        return self.newton.move(H, t, t_new, self.newton.full(dzf))

    def _tangent_at(self, H, t):
        """``dz/dt`` ``(n_free,)`` along the path at the equilibrium ``(H, t)``; without contributions
        (contact) the evaluation of the converged iterate is reused (committing a contribution's
        history may change the tangent)."""
        last = self._converged
        if last is not None and last[0] is H and last[1] == t and not self.problem.contributions:
            ev = last[2]
        else:
            ev = self.newton.evaluate(H, t)
        return self.solve2(ev, H, t)[1]

    # ------------------------------------------------------------ one step
    def _correct(self, H, t, w, tau, ds, t_fixed=None):
        """Newton iterations (``Newton.iterate`` under the ``Sphere`` constraint) from the iterate
        ``(H, t)`` of a step (scaled increment ``w``, pseudo-time change ``tau`` so far) onto the
        sphere of radius ``ds``, or at ``t = t_fixed`` if given.  Returns ``(H, t, w, tau, ev,
        stats)``; raises a ``failures.StepFailed``."""
        sphere = Sphere(self, w, tau, ds, t_fixed)
        H, t, ev, stats = self.newton.iterate(H, t, sphere)
        self._converged = (H, t, ev)
        return H, t, sphere.w, sphere.tau, ev, stats

    def _predict(self, v, ds):
        """Pseudo-time change of the predictor along ``v = dz/dt`` with arc length ``ds``, in the
        direction of the previous step (forward at the first)."""
        sv = self.S * v
        tau = ds / np.sqrt(float(sv @ sv) + self.psi**2)
        if self.prev is not None:
            w0, tau0 = self.prev
            if float(sv @ w0) + self.psi**2 * tau0 < 0.0:
                tau = -tau
        return tau

    def _arc_step(self, ds):
        """One converged step of arc length ``ds`` from ``(self.H, self.t)``."""
        H0, t0, sys = self.H, self.t, self.sys
        self.problem.begin_step(H0, t0)
        v = self._tangent_at(H0, t0)
        tau = self._predict(v, ds)
        t_try, _ = motion_path.limit_step(sys, t0, t0 + tau)
        if t_try != t0 + tau:                     # a prescribed rotation would be ambiguous: shorter arc
            ds, tau = ds * (t_try - t0) / tau, t_try - t0
        self.ds_used = ds
        crossing = t0 < self.t_end <= t0 + tau * (1.0 + STEP_TOLERANCE)
        if crossing:                              # the last step: load control onto t_end
            tau = self.t_end - t0
        H = self.move(H0, t0, tau * v, t0 + tau)
        out = self._correct(H, t0 + tau, self.S * tau * v, tau, ds, self.t_end if crossing else None)
        H, t, w, tau, ev, stats = self._augment(out)
        if not crossing and t0 < self.t_end <= t:    # passed t_end on the sphere: redo by load control
            return self._arc_step_to_end(H0, t0, v, ds)
        self._check_turn(w, tau)
        rot = motion_path.path_rotation(sys, t0, t)
        if rot > motion_path.MAX_MOTION_ROTATION:
            raise StepFailed(f"a prescribed rotation turns by {rot:.3g} rad over the step (more than "
                             f"MAX_MOTION_ROTATION = {motion_path.MAX_MOTION_ROTATION:.3g} rad)")
        self.newton.check_continuity(H0, H)
        return H, t, w, tau, ev, stats

    def _arc_step_to_end(self, H0, t0, v, ds):
        """The step from ``(H0, t0)`` with ``t = t_end`` held (predictor along ``v``)."""
        self.problem.begin_step(H0, t0)              # forget the first attempt's outer iterations
        tau = self.t_end - t0
        H = self.move(H0, t0, tau * v, self.t_end)
        out = self._augment(self._correct(H, self.t_end, self.S * tau * v, tau, ds, self.t_end))
        self.newton.check_continuity(H0, out[0])
        return out

    def _augment(self, out):
        """Outer iterations at the converged ``t`` (``Problem.repeat_step``, e.g. augmented-Lagrangian
        updates) with ``t`` held; refused or warned if ``Problem.unmet``."""
        H, t, w, tau, ev, stats = out

        def again(state):
            H, t, w, tau, ev, more = self._correct(*state[:4], 0.0, t_fixed=state[1])
            return (H, t, w, tau, ev), more
        H, t, w, tau, ev = self.outer_iterations((H, t, w, tau, ev), stats, t, again)
        self.check_unmet(t, stats)
        return H, t, w, tau, ev, stats

    def _check_turn(self, w, tau):
        """Refuse a step that turned back along the path (``cos <= TURN_BACK`` with the previous one)."""
        if self.prev is None:
            return
        w0, tau0 = self.prev
        dot = float(w @ w0) + self.psi**2 * tau * tau0
        norm = np.sqrt((float(w @ w) + (self.psi * tau)**2) * (float(w0 @ w0) + (self.psi * tau0)**2))
        if norm > 0.0 and dot <= TURN_BACK * norm:
            raise StepFailed(f"the step turned back along the path (cos = {dot / norm:.3g} with the previous step)")

    # ------------------------------------------------------------ the run
    def _setup(self):
        """``psi``, the arc lengths ``(initial, min, max)`` and ``max_steps`` from the first tangent."""
        arc, steps = self.arc, len(self.grid) - 1
        v = self._tangent_at(self.H, self.t)
        sv = float(np.linalg.norm(self.S * v))
        psi = arc.psi if arc.psi is not None else (sv if sv > 0.0 else 1.0 / self.span)
        if psi == 0.0 and sv == 0.0:
            raise InputError("solve: arc_length psi = 0 (cylindrical) but nothing moves with t at the start")
        self.psi = psi
        ds0 = arc.initial if arc.initial is not None else \
            (self.span / steps) * np.sqrt(sv**2 + psi**2)
        ratio = self.dt_min / self.dt_user
        lo = arc.min if arc.min is not None else ds0 * ratio
        hi = arc.max if arc.max is not None else ds0
        if lo > hi or not lo <= ds0 <= hi:
            raise InputError(f"solve: arc_length needs min <= initial <= max, got {lo:.3g}, {ds0:.3g}, {hi:.3g}")
        self.ds, self.ds_min, self.ds_max = ds0, lo, hi
        self.max_steps = arc.max_steps if arc.max_steps is not None else 25 * steps
        self.sol.resume = self._resume()      # before any step: its "path" lets times go back (Solution)

    def _resume(self):
        """``Solution.resume`` of an arc-length run: ``path`` (times need not increase), ``t0``, ``t_end``."""
        return dict(path="arc-length", t0=float(self.grid[0]), t_end=self.t_end)

    def loop(self):
        self._setup()
        while self.t < self.t_end:
            if self.sol.n_steps >= self.max_steps:
                self._not_reached()
                return
            t0 = time.perf_counter()
            H, t, w, tau, ev, stats = self._attempt_arc()
            stats.update(wall_time=time.perf_counter() - t0, dt=t - self.t)
            self._record_arc(H, t, w, tau, ev, stats)

    def _attempt_arc(self):
        """Converge one step, halving the arc length on a retryable failure down to ``min``."""
        ds, failed = self.ds, []
        while True:
            self.newton.reset_timings()
            try:
                out = self._arc_step(ds)
                self._check_finite(out[0], out[4].r, out[4].state, out[1])
                out[5].update(cutbacks=len(failed), arc_length=self.ds_used, psi=self.psi,
                              timings=dict(self.newton.timings))
                if failed:
                    out[5]["failed_arc_length"] = failed
                self.ds = self.ds_used
                return out
            except StepFailed as e:
                if isinstance(e, NonFinite):
                    self._name_nonfinite(self.t_iter)      # InputError when a scale or motion gave it
                failed.append(ds)
                ds *= 0.5
                log.info("t = %.6g: arc-length step %.3g failed (%s); cutting back to %.3g", self.t, 2 * ds, e, ds)
                if not e.retry or ds < self.ds_min * (1.0 - STEP_TOLERANCE):
                    self._stop_arc(e, 2.0 * ds)

    def _record_arc(self, H, t, w, tau, ev, stats):
        sys, sol, problem = self.sys, self.sol, self.problem
        t, H, ev = self._stability(stats, t, H, ev)     # no branch switching here: the same (t, H, ev)
        record = problem.commit(H)
        if problem.contributions:
            sol.contact_state = problem.get_state()
        for text in stats.get("warnings", ()):
            sol.message = text if not sol.message else sol.message + "; " + text
        stats["t"] = t
        if self.range is not None:
            self.range.check(ev.state.strain, stats, len(sol))
        sol.append(t, H, sys.reactions(H, ev.r), ev.state.sigma, ev.state.strain, stats, record,
                   problem.extras or None)
        sol.resume = self._resume()
        ds = next_arc_length(self.ds, stats["iterations"], self.arc.target_iterations, stats["cutbacks"] > 0,
                             stats["linearised"] > 0)
        self.ds = float(np.clip(ds, self.ds_min, self.ds_max))
        self.H, self.t, self.prev = H, t, (w, tau)
        if self.writer is not None:
            self.writer.write(sol, sol.n_steps)
        self.progress.step(sol.n_steps, t, stats["dt"], stats)

    def _not_reached(self):
        text = (f"arc-length: t_end = {self.t_end:.6g} not reached after {self.sol.n_steps} steps "
                f"(max_steps; t = {self.t:.6g}): raise arc_length max_steps or max")
        self.sol.converged = False
        self.sol.message = text if not self.sol.message else self.sol.message + "; " + text
        log.warning(text)
        warnings.warn(text, RuntimeWarning, stacklevel=4)

    def _stop_arc(self, failure, ds):
        self._stop(failure, None, f"arc-length could not advance from t = {self.t:.6g} (arc length "
                                  f"{ds:.3g}, min {self.ds_min:.3g})")


def check_arc_length_arguments(path, arc_length, restart, branch_switching=False, stabilize=None):
    """``ArcLength`` options for ``path="arc-length"`` (``None`` for ``"load"``); ``InputError`` on bad
    input (``Run.path_options``, ``ArcLengthRun.path_options``; ``stepping.steppers`` has every stepper)."""
    if not isinstance(path, str) or path not in ("load", "arc-length"):
        raise InputError(f"solve: path must be 'load' or 'arc-length', got {path!r}")
    runner = Run if path == "load" else ArcLengthRun
    return runner.path_options(arc_length, restart, branch_switching, stabilize)
