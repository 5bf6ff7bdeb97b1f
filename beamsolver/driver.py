"""Newton's method with pseudo-time stepping, line search and automatic cut-back.

Per step ``t -> t + dt``: loads are evaluated at ``t + dt``; the first
iteration carries the prescribed motions into the free unknowns through the
tangent (``K_ff dz_f = -r_f - K_fc dz_c``), later iterations are Newton
``K dz = -r``, damped on the size of the Newton correction for a smooth problem
(``Newton._damped``) and by a backtracking line search on the scaled residual
otherwise (``Newton._line_search``).  The physics is reached only through the
``problem.Problem`` interface (residual, tangent, update, step life cycle).
Elements may not turn by more than ``MAX_ELEMENT_ROTATION`` (nor pass pi
within a step): such steps fail with a message saying how many elements the
beam needs.
Failures are typed (``beamsolver.failures``); ``Convergence.decide`` gives
the verdict on every iterate.  The stepping (cut-back, regrowth, landing on
the user's grid, keeping what converged when a run stops) is ``stepping.Run``.
"""
import logging
import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .stepping import diagnosis
from . import elements
from .nonlinear import linsolve
from .lie import se3
from .stepping.arclength import ArcLengthRun, check_arc_length_arguments
from .errors import InputError
from .failures import DampingStalled, Diverged, NonFinite, NotConverged, RotationLimit, SingularTangent, StepFailed
from .nonlinear.jit_warmup import warm_up
from .nonlinear.problem import Problem
from .stepping.restart import restart_from
from .stepping.stabilize import from_option as stabilize_option
from .stepping.steps import Run
from .model.sanity import check_sizes
from .model.validation import check_solve_arguments, check_stability_options


__all__ = ["solve", "Convergence", "Newton"]

log = logging.getLogger("beamsolver")

MAX_ELEMENT_ROTATION = elements.MAX_ELEMENT_ROTATION   # an iterate turning an element further is rejected
LS_GROWTH = 10.0                     # full Newton steps are kept unless the merit grows this much
DAMPING_MIN = 1.0 / 64.0             # shortest damped Newton step (smooth problems)
STALL_RATIO = 1.5                    # undamped fallback if the shortest damped step grows the correction less
MIN_STEP_RATIO = 1e-15               # smallest min_step_ratio: below, t + dt rounds to t
STEP_ROUNDOFF = 1e3                  # steps below this many ulps of |t| are not taken (round-off in t + dt)
ROUNDOFF = 64.0 * np.finfo(float).eps   # position round-off, relative to the distance from the origin
SQRT3 = np.sqrt(3.0)                 # |w|_2 <= SQRT3 |w|_inf (the rotation check's shortcut)
CONTINUITY_MARGIN = 1e-6             # check_continuity's shortcut: far above the ~1e-8 round-off of arccos at 0

CONVERGED, CONTINUE, MAX_ITER, DIVERGED = "converged", "continue", "max_iter", "diverged"


@dataclass
class Convergence:
    """Stopping rule of the Newton loop.

    Converged when the scaled residual is small,
    ``|r_u|_inf <= rtol F_ref`` and ``|r_w|_inf <= rtol M_ref``, or when the last
    full Newton increment is at round-off level,
    ``|dz_u|_inf <= dtol L_ref`` and ``|dz_w|_inf <= dtol``.  ``F_ref`` and
    ``M_ref`` are the largest element nodal force/moment or applied load of
    the iterate (``F_ref >= M_ref / L_ref`` and ``M_ref >= F_ref L_ref``), ``L_ref``
    the model size: the same scene in any unit system converges in the
    same iterations.  Far from the origin positions carry a round-off of
    ``ROUNDOFF |x|``: ``decide`` takes it as a floor of the increment test, so a
    scene converges alike wherever it is placed.
    """
    rtol: float = 1e-8
    dtol: float = 1e-11
    max_iter: int = 30
    divergence: float = 1e12

    def scales(self, ev, L_ref):
        """``(F_ref, M_ref)`` from the force levels of an evaluation (``problem.Evaluation``, or a
        dict with ``f_level`` and ``m_level``)."""
        f, m = (ev["f_level"], ev["m_level"]) if isinstance(ev, dict) else (ev.f_level, ev.m_level)
        F = max(f, m / L_ref)
        M = max(m, f * L_ref)
        return F, M

    def residual_ratio(self, r_free_u, r_free_w, F, M):
        ru = np.abs(r_free_u).max(initial=0.0)
        rw = np.abs(r_free_w).max(initial=0.0)
        return max(ru / F if F > 0 else (0.0 if ru == 0 else np.inf),
                   rw / M if M > 0 else (0.0 if rw == 0 else np.inf))

    def increment_ratio(self, dz, L_ref):
        return max(np.abs(dz[:, :3]).max(initial=0.0) / L_ref, np.abs(dz[:, 3:]).max(initial=0.0))

    @staticmethod
    def floor(H, L_ref):
        """Round-off floor of ``increment_ratio`` at poses ``H``: ``ROUNDOFF max|x| / L_ref``."""
        return ROUNDOFF * float(np.abs(H[:, :3, 3]).max(initial=0.0)) / L_ref

    def decide(self, ratio, increment, iteration, floor=0.0, final=True):
        """Verdict on an iterate with scaled residual ``ratio`` reached by a full Newton increment
        of ``increment_ratio`` ``increment`` (``inf`` if damped or none) at ``iteration``:
        ``CONVERGED`` (``ratio <= rtol`` or ``increment <= max(dtol, floor)``; only if ``final``,
        i.e. the prescribed motions have been applied), else ``MAX_ITER`` (``iteration >=
        max_iter``), ``DIVERGED`` (``ratio > divergence``) or ``CONTINUE``."""
        if final and (ratio <= self.rtol or increment <= max(self.dtol, floor)):
            return CONVERGED
        if iteration >= self.max_iter:
            return MAX_ITER
        if ratio > self.divergence:
            return DIVERGED
        return CONTINUE


def _factorize(K, solver=None):
    """Factorise the tangent through ``linsolve`` (default back-end ``"auto"``)."""
    try:
        return (solver if solver is not None else linsolve.Solver()).factorize(K)
    except linsolve.SingularMatrixError as e:
        raise SingularTangent(f"singular tangent ({e})") from None


def _solve_linear(lu, rhs):
    try:
        return lu.solve(rhs)
    except linsolve.SingularMatrixError as e:   # pardiso reports singularity at the solve
        raise SingularTangent(f"singular tangent ({e})") from None


def _relative_rotations(system, H):
    """Rotations ``R_i^T R_j`` of the node pairs an element represents by a logarithm
    (``system.rotation_pairs``: one per element for two-node elements), ``(n_pairs, 3, 3)``."""
    en = system.rotation_pairs
    return np.swapaxes(H[en[:, 0], :3, :3], 1, 2) @ H[en[:, 1], :3, :3]


def _angle(R):
    """Rotation angles in ``[0, pi]`` of ``(..., 3, 3)`` rotation matrices."""
    return np.arccos(np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0))


def _largest_element_rotation(system, H):
    """Largest rotation angle between the two nodes of an element at poses ``H``."""
    if system.n_elements == 0:
        return 0.0
    return float(_angle(_relative_rotations(system, H)).max())


def _refine_advice(system, H, t, t_start, t_end):
    """How many elements the beams whose elements turn most would need (rotations taken to grow
    in proportion to the pseudo-time), as a message tail."""
    ang = np.zeros(system.n_elements)
    np.maximum.at(ang, system.pair_element, _angle(_relative_rotations(system, H)))   # per element
    grow = (t_end - t_start) / (t - t_start) if t > t_start else 1.0
    parts = []
    for b in system.model.beams:
        a = float(ang[b.elements].max())
        if a < 0.5 * MAX_ELEMENT_ROTATION:
            continue
        # strictly below pi/2 (floor + 1, with a margin for round-off: a turn of exactly pi/2 per element
        # is not below it)
        need = int(np.floor(b.n_elements * max(a * grow, MAX_ELEMENT_ROTATION) / (0.5 * np.pi) + 1e-6)) + 1
        parts.append(f"Beam {b.id} ({b.n_elements} elements) turns by {a:.3f} rad per element at "
                     f"t = {t:.6g}: about {need} elements keep it below pi/2 at t = {t_end:.6g}")
    return "".join("; " + p for p in parts)


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
    """Newton iterations of one step (``step``) on a ``problem.Problem`` with the ``Convergence``
    ``conv``; ``evaluate`` is the checked, timed evaluation it uses (also for branch switching),
    ``last_evaluation`` that of the last converged state.  ``timings`` accumulates the wall time
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
        # the rotation check's shortcut bound, a margin far above the round-off of |w|
        self._smallest_limit = (1.0 - 1e-9) * float(system.rotation_limit.min(initial=np.inf))
        self.linsolver = linsolve.Solver()    # solve(linear_solver=...) replaces it
        self.stall_ratio = np.inf             # correction growth of the shortest damped trial
        self.indefinite_seen = False          # the step's first tangent had det < 0 (or a back-end that cannot tell)
        self.watch_sign = False               # whether to look (stepping.Run: conservative problems)
        self.reset_timings()

    def reset_timings(self):
        self.timings = dict(assembly=0.0, linear_solve=0.0, **dict.fromkeys(self.problem.timing_names, 0.0))

    def _ratio(self, r, scales):
        return self.conv.residual_ratio(r[self._dofs_u], r[self._dofs_w], *scales)

    def residual_ratio(self, ev, r=None):
        """Scaled residual (``Convergence.residual_ratio``) of the residual ``r`` ``(6 n,)`` (default
        ``ev.r``) with the force scales of the evaluation ``ev``."""
        return self._ratio(ev.r if r is None else r, self.conv.scales(ev, self.L_ref))

    def _measured(self, ev):
        """``ev`` with its residual scales and scaled residual (``_Measured``; no direction yet)."""
        scales = self.conv.scales(ev, self.L_ref)
        return _Measured(ev, scales, self._ratio(ev.r, scales))

    def at_rest(self, ev, H, t):
        """Whether the given poses ``H`` (evaluated in ``ev`` at ``t``) are an equilibrium by
        Newton's tests (``Convergence.decide``): the scaled residual, else the Newton correction
        one iteration would make, against its round-off floor.  A state Newton could not start
        from (a singular tangent, a refused contact) counts as at rest: it is kept as given."""
        if not np.all(np.isfinite(ev.r)) or self._ratio(ev.r, self.conv.scales(ev, self.L_ref)) <= self.conv.rtol:
            return True
        try:
            _, dzf = self._direction(self.problem.evaluate(H, t, tangent=True))
        except StepFailed:
            return True
        return self._inc(dzf) <= max(self.conv.dtol, self.conv.floor(H, self.L_ref))

    def _merit(self, r, scales):
        rf = r[self.sys.free_dofs]
        F, M = scales
        return float(np.sum((rf[self.fu] / F) ** 2) + np.sum((rf[self.fw] / M) ** 2))

    def _element_label(self, e):
        """``element e (element j of Beam b)`` for a global element id."""
        for b in self.sys.model.beams:
            if b.elements[0] <= e <= b.elements[-1]:
                return f"element {e} (no. {e - b.elements[0]} of the {b.n_elements} of Beam {b.id})"
        return f"element {e}"

    def _check_rotation(self, state):
        w = state.h[:, 3:]
        # |w| <= sqrt(3) max|w_i|: far below every limit, nothing to measure
        if len(w) and np.abs(w).max() * SQRT3 < self._smallest_limit:
            return
        ang = se3.rotation_angle(w)
        limit = self.sys.rotation_limit          # of each element's type, MAX_ELEMENT_ROTATION for se3-2
        worst = int(np.argmax(ang - limit)) if len(ang) else 0
        if len(ang) and ang[worst] > limit[worst]:
            raise RotationLimit(f"{self._element_label(worst)} turns by {ang[worst]:.4f} rad within one element "
                                f"(limit MAX_ELEMENT_ROTATION = {limit[worst] / np.pi:.2g} pi = "
                                f"{limit[worst]:.4f} rad; an element cannot turn by pi): refine the mesh")

    def check_continuity(self, H0, H1):
        """Refuse a step over which an element's relative rotation may have passed through pi.

        The element only sees ``log(H_A^-1 H_B)``, whose angle lies in ``[0, pi]``: an element
        turned past pi within one load step would look like one turned the short way round (a
        silent wrong answer).  Passing pi and coming back to the angle ``t1`` from ``t0`` takes a
        rotation of at least ``(pi - t0) + (pi - t1)``, so a step whose relative rotations change
        by less than that (the geodesic angle between old and new) cannot have passed it.
        """
        if self.sys.n_elements == 0:
            return
        R0, R1 = _relative_rotations(self.sys, H0), _relative_rotations(self.sys, H1)
        a0, a1 = _angle(R0), _angle(R1)
        # the change is at most a0 + a1: below pi (a margin above the arccos round-off) nothing can pass
        if (a0 + a1).max() < np.pi - CONTINUITY_MARGIN:
            return
        change = _angle(np.swapaxes(R0, 1, 2) @ R1)
        bad = np.flatnonzero(change >= (np.pi - a0) + (np.pi - a1) - 1e-9)
        if len(bad):
            e = int(bad[np.argmax(change[bad])])
            raise RotationLimit(f"{self._element_label(self.sys.pair_element[e])} turns by {change[e]:.3f} rad "
                                "within one element in "
                                "one load step and may have passed pi, which an element cannot represent: "
                                "use smaller steps or refine the mesh")

    def _norm(self, dzf):
        """Norm of free increments, translations in units of the model size (unit-independent)."""
        return float(np.sqrt(np.sum((dzf[self.fu] / self.L_ref) ** 2) + np.sum(dzf[self.fw] ** 2)))

    def _inc(self, dzf):
        """``Convergence.increment_ratio`` of free increments."""
        return max(np.abs(dzf[self.fu]).max(initial=0.0) / self.L_ref, np.abs(dzf[self.fw]).max(initial=0.0))

    def _direction(self, ev, dz_c=None):
        """Newton increment on the free unknowns (with the prescribed-motion coupling ``dz_c``)."""
        problem = self.problem
        t0 = time.perf_counter()
        rhs = -ev.r[self.sys.free_dofs]
        if dz_c is not None:
            rhs -= problem.coupling(ev, dz_c)
        K = problem.tangent(ev)
        t1 = time.perf_counter()
        try:
            lu = _factorize(K, self.linsolver)
            dzf = _solve_linear(lu, rhs)
        finally:
            t2 = time.perf_counter()
            self.timings["assembly"] += t1 - t0
            self.timings["linear_solve"] += t2 - t1
        if not np.all(np.isfinite(dzf)):
            raise SingularTangent("the linear solve returned non-finite values")
        return lu, dzf

    def evaluate(self, H, t, tangent=True):
        """``Problem.evaluate`` timed into ``timings`` and checked (finite residual, element rotations
        below ``MAX_ELEMENT_ROTATION``: ``NonFinite`` / ``RotationLimit``)."""
        t0 = time.perf_counter()
        ev = self.problem.evaluate(H, t, tangent=tangent)
        self.timings["assembly"] += time.perf_counter() - t0
        for name, seconds in ev.timings.items():
            self.timings[name] = self.timings.get(name, 0.0) + seconds
        if not np.isfinite(ev.r).all():
            raise NonFinite("the residual is not finite")
        self._check_rotation(ev.state)
        return ev

    def _predictor(self, H, t, t_prev, H_target):
        """Increments ``dz_c`` ``(n, 6)`` carrying the constrained nodes to their targets at ``t``
        (``None`` if there is nothing to move) and the ``fix(values=)`` targets."""
        sys = self.sys
        targets = sys.fixed_value_increments(H, t, t_prev) if sys.fix_values else []
        if not (len(sys.prescribed_nodes) or targets):
            return None, targets
        dz_c = np.zeros((sys.n_nodes, 6))
        if len(sys.prescribed_nodes):
            p = sys.prescribed_nodes
            dz_c[p] = se3.log(se3.relative(H[p], H_target))
        for node, comp, dx in targets:
            dz_c[node, comp] = dx
        return (dz_c if np.any(dz_c) else None), targets

    def _reach_targets(self, H, dz, H_target, fix_values, t):
        """The predictor update: free nodes by ``dz``, constrained ones exactly onto their targets."""
        sys = self.sys
        H = self.problem.update(H, dz)
        if len(sys.prescribed_nodes):
            H[sys.prescribed_nodes] = H_target
        if fix_values:
            sys.enforce_fixed_values(H, t)
        sys.sync_members(H)
        return H

    def step(self, H, t, H_target, t_prev=None):
        """Solve for equilibrium at ``t`` (from the equilibrium ``H`` at ``t_prev``); returns
        ``(H, ev, stats)`` (``ev`` the ``problem.Evaluation`` of the converged state) or raises a
        ``failures.StepFailed``.

        With ``line_search``, the Newton step of a smooth problem (``Problem.smooth``) is damped
        on the Newton correction (``_damped``); otherwise the residual line search
        ``_line_search`` is used.
        """
        conv, problem = self.conv, self.problem
        H_start = H
        residuals = []
        self.indefinite_seen = False
        damped_its = 0
        dz_c, targets = self._predictor(H, t, t_prev, H_target)
        floor = conv.floor(H, self.L_ref)
        damping = self.line_search and problem.smooth
        plain = False                # undamped Newton after the damped iteration stalled
        last_inc = np.inf
        ahead = None                 # the ``_Measured`` evaluation of an accepted trial (line search, damping)
        lam = 1.0
        rotation_streak = 0
        stats_extra = {}
        for it in range(conv.max_iter + 1):
            ev, scales, ratio, lu, dzf, nrm = self._measured(self.evaluate(H, t)) if ahead is None else ahead
            ahead = None
            residuals.append(ratio)
            log.debug("t = %.6g  iteration %d  scaled residual %.3e", t, it, ratio)
            if self.callback is not None:
                self.callback(dict(t=t, iteration=it, residual=ratio, poses=H))
            verdict = conv.decide(ratio, last_inc, it, floor, final=dz_c is None)
            if verdict == CONVERGED:
                self.check_continuity(H_start, H)
                if damped_its:
                    stats_extra["damped"] = damped_its
                self.last_evaluation = ev     # of the converged state (its tangent: stability check)
                return H, ev, dict(iterations=it, residuals=residuals, **stats_extra)
            if verdict != CONTINUE:
                raise self._failure(verdict, ratio)
            if dzf is None:
                lu, dzf = self._direction(ev, dz_c)
            if it == 0 and self.watch_sign:     # the first tangent K(H_n, t_n+1): indefinite where a step may jump
                sign = getattr(lu, "det_sign", None)
                self.indefinite_seen = sign is None or sign() < 0
            dz = self._full(dzf)
            if dz_c is not None:
                H = self._reach_targets(H, dz + dz_c, H_target, bool(targets), t)
                dz_c = None
                last_inc = np.inf
                continue
            if not damping:
                last_inc = conv.increment_ratio(dz, self.L_ref)
                if not self.line_search or plain:
                    H = problem.update(H, dz)
                    continue
                H, ahead = self._line_search(H, dz, ev.r, scales, t)
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
        raise AssertionError("unreachable: decide() returns MAX_ITER at iteration max_iter")

    def _failure(self, verdict, ratio):
        """The typed failure of a ``Convergence.decide`` verdict other than converged / continue."""
        if verdict == MAX_ITER:
            return NotConverged(f"no convergence in {self.conv.max_iter} iterations (scaled residual {ratio:.3g})",
                                ratio)
        return Diverged(f"diverging (scaled residual {ratio:.3g})")

    def _full(self, dzf):
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
                lu1, d1 = self._direction(m.ev)
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

    def _line_search(self, H, dz, r0, scales, t):
        """Backtracking on the scaled residual (problems that are not smooth; the others use the
        damped Newton of ``_damped``: a piecewise smooth residual made its natural-monotonicity
        test accept steps that later stalled, e.g. in the twisted pair).

        Returns ``(H1, ahead)``: the accepted poses and, when the full step is accepted, its
        ``_Measured`` evaluation (with tangent: the next iteration's, computed once; ``None`` otherwise).
        The residual does not depend on whether the tangent is computed."""
        problem = self.problem
        phi0 = self._merit(r0, scales)
        H1 = problem.update(H, dz)
        if phi0 <= (10.0 * self.conv.rtol) ** 2 * len(self.sys.free_dofs):
            return H1, None
        alpha = 1.0
        best = (np.inf, H1)
        for _ in range(8):
            ev1 = None
            try:
                # the full step is nearly always accepted: evaluated with the tangent the next
                # iteration needs; the backtracked trials need the residual only
                ev1 = self.evaluate(H1, t, tangent=alpha == 1.0)
                phi = self._merit(ev1.r, scales)
            except StepFailed:
                phi = np.inf
            if phi < best[0]:
                best = (phi, H1)
            # Newton may raise the residual for a while: only a blow-up (factor
            # LS_GROWTH) triggers backtracking, which then asks for a decrease
            if phi <= (LS_GROWTH * phi0 if alpha == 1.0 else (1.0 - 1e-4 * alpha) * phi0):
                return H1, (self._measured(ev1) if alpha == 1.0 else None)
            # minimiser of the quadratic through phi(0), phi'(0) = -2 phi0, phi(alpha)
            if np.isfinite(phi):
                a_new = phi0 * alpha**2 / (phi - phi0 + 2.0 * alpha * phi0)
            else:
                a_new = 0.1 * alpha
            alpha = float(np.clip(a_new, 0.1 * alpha, 0.5 * alpha))
            H1 = problem.update(H, alpha * dz)
        if not np.isfinite(best[0]):
            raise NonFinite("line search found no finite residual along the Newton direction")
        return best[1], None


def _starting_point(restart, model, problem, t_start, t_end):
    """``(solution to continue or None, t_start)``: a restart starts at its first saved time."""
    sol = None
    if restart is not None:
        sol = restart_from(restart, model, problem)
        t_start = float(sol.times[0])
    if not (np.isfinite(t_end) and np.isfinite(t_start) and t_end > t_start):
        raise InputError(f"solve: need t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    return sol, t_start


def solve(model, steps=20, t_end=1.0, output=None, *, t_start=0.0, rtol=1e-8, dtol=1e-11,
          max_iter=30, line_search=True, min_step_ratio=2.0**-12, callback=None,
          check_rigid_modes=True, verbose=None, initial_poses=None, restart=None, checkpoint=60.0,
          linear_solver=None, allow_unmet_tolerance=False, check_stability=False, modes=0,
          branch_switching=False, stabilize=None, path="load", arc_length=None):
    """Quasi-static solve of ``model`` from ``t_start`` to ``t_end`` in ``steps`` equal steps.

    Every converged (sub)step is recorded in the returned ``Solution``.  Step 0 is
    the state at ``t_start``: the reference (or ``initial_poses``) when no load,
    prescribed motion or ``fix`` value acts there, else the equilibrium solved
    there (its Newton statistics in ``stats[0]``).  A step
    that fails is halved down to ``min_step_ratio`` times the user's step, then
    ``ConvergenceError`` is raised with the last converged ``Solution``
    (``.solution``) and the typed reason (``.failure``).  A step over which a
    prescribed rotation turns by more than ``motion_path.MAX_MOTION_ROTATION``
    is shortened first, so motions are followed as continuous paths.

    ``output``: folder for ParaView files and ``solution.npz`` (``None``: no
    output; see ``beamsolver.io.vtk``), the latter saved at the end, whenever
    the run stops (also by Ctrl-C or an exception) and every ``checkpoint``
    seconds (0: every step; ``None``: only at the end or stop); or a writer
    object with ``write(solution, step)`` and ``close()`` such as ``io.vtk.StepWriter``.
    Any exception leaving ``solve`` carries the converged steps as ``.solution``.
    ``callback(info)`` is called at every Newton iteration with ``t``,
    ``iteration``, ``residual`` (scaled) and ``poses``.
    ``verbose``: progress bar / lines (see ``progress.Progress``); ``None`` shows a bar on a terminal.
    ``restart``: a ``Solution`` (or the path of a saved one) of this model; the
    run continues from its last step on the grid ``linspace(restart.times[0],
    t_end, steps + 1)`` with its stepping state and contact history, so the
    same arguments give the same final state as a run never interrupted.
    ``linear_solver``: sparse direct solver of the Newton systems, ``"auto"``
    (default: scipy ``"splu"`` for beams and small scenes; for large bundles
    of wires in contact ``"pardiso"`` if pypardiso is installed, ``pip install
    "beamsolver[fast]"``, else ``"splu-rcm"``, scipy after an RCM ordering),
    or one of those by name (see ``beamsolver.nonlinear.linsolve``).
    ``allow_unmet_tolerance``: accept a step whose contact penetration still
    exceeds ``add_contact(tolerance=)`` after the augmented-Lagrangian updates,
    with a warning in ``stats[k]["warnings"]`` and ``Solution.message``
    (default: a ``ConvergenceError``).
    ``check_stability``: after every converged step count the negative
    eigenvalues of the tangent (``definiteness.negative_eigenvalues``) where the
    problem is conservative (no follower loads, no friction), record
    ``stable``, ``negative_eigenvalues`` and ``lowest_eigenvalue`` (scaled;
    ``None`` where not computed) in ``stats`` and warn once
    (``StabilityWarning``) on an unstable equilibrium; opt-in: on stable 8-step
    solves of 96-6144 unknowns (2-3 Newton iterations a step) it added 6-27 % to
    the wall time, ``modes=3`` 22-112 % (``benchmarks/stability_check.py``, one
    run on a shared 2-core machine).  "Stable" means the
    symmetric tangent is positive definite: the converged state is a strict
    minimum of the potential energy.  With friction or follower loads the
    tangent is unsymmetric and depends on the history, there is no potential,
    and the definiteness of its symmetric part would prove nothing either way:
    such steps record ``stable=None`` and are not switched.
    ``modes``: with it (a count ``k``), the ``k`` lowest eigenpairs of the
    scaled tangent (``modes.lowest_modes``) of every checked step, in
    ``stats[k]["mode_eigenvalues"]`` and ``stats[k]["modes"]`` ``(k, n_nodes, 6)``
    (global displacement and rotation vector per node, unit-free size 1:
    ``bifurcation``); ``Solution.modes(step)``; VTU point fields ``mode_1_u``,
    ``mode_1_rotation``, ...  ``branch_switching``: ``"auto"`` at a step where
    the count of negative eigenvalues went up (a bifurcation or limit point
    crossed; where one step passed several critical loads, the switch is made
    between the first two and recorded as its own step: ``branching.locate``),
    ``True`` at every step with negative eigenvalues, the amplitude along the
    lowest mode is raised from ``bifurcation.AMPLITUDE`` at the same load, the
    other unknowns relaxed, down the energy onto a stable branch
    (``bifurcation.descend``); ``stats[k]["branch_switch"]`` records the mode,
    the crossing, the descent and the counts before and after, and a state
    still unstable after it is warned about.  Either implies ``check_stability``.

    ``stabilize``: artificial viscous damping in pseudo-time (Abaqus ``*STATIC, STABILIZE``) to pass
    instabilities under load control: ``True`` (dissipated-energy fraction 2e-4), a fraction, or
    ``dict(fraction=, factor=, warn=)``; the energy it dissipates is recorded per step in
    ``stats[k]["stabilization"]`` and warned about above ``warn`` (``beamsolver.stabilize``).

    ``path``: ``"load"`` (default) steps the pseudo-time on the grid above;
    ``"arc-length"`` follows the equilibrium path by arc length through limit
    points and snap-backs, ``t`` going down as well as up
    (``beamsolver.stepping.arclength``; options ``arc_length``, a dict or
    ``arclength.ArcLength``: ``initial``, ``min``, ``max``,
    ``target_iterations``, ``max_steps``, ``psi``).  Its ``times`` are not
    monotonic; ``stats[k]`` adds ``arc_length``, ``t`` and ``linearised``;
    ``restart``, ``branch_switching`` and ``stabilize`` are refused with it.

    ``Solution.stats[k]["timings"]``: wall time of the step's ``assembly``
    (residuals, tangents, sparse matrices), of each contribution to it (``contact``
    for scenes with contact, part of assembly) and ``linear_solve``
    (factorisations and solves), in seconds.
    """
    check_solve_arguments(model, steps=steps, t_end=t_end, t_start=t_start, rtol=rtol, dtol=dtol, max_iter=max_iter,
                          min_step_ratio=min_step_ratio, checkpoint=checkpoint, initial_poses=initial_poses,
                          restart=restart, callback=callback, output=output)
    arc = check_arc_length_arguments(path, arc_length, restart, branch_switching, stabilize)
    if restart is None:
        check_sizes(model)      # implausible radii or lengths: a GeometryWarning before anything is compiled
    warm_up(model)          # a first run: compile before step 0, in two processes (jit_warmup)
    problem = Problem.from_model(model, check_rigid_modes=check_rigid_modes)
    system = problem.system
    sol, t_start = _starting_point(restart, model, problem, t_start, t_end)
    grid = np.linspace(t_start, t_end, int(steps) + 1)
    dt_min = _step_floor(min_step_ratio, grid)
    newton = Newton(problem, Convergence(rtol=rtol, dtol=dtol, max_iter=max_iter), line_search, callback)
    newton.linsolver = linsolve.Solver(linear_solver)
    options = _run_options(problem, t_start, t_end, allow_unmet_tolerance, check_stability, modes,
                           branch_switching, stabilize, problem.failure_hint())
    if sol is not None and options["stabilizer"] is not None:
        options["stabilizer"].resume(sol)
    run = None
    try:
        args = (problem, newton, _writer(output, system, checkpoint), grid, dt_min, verbose, options)
        run = Run(*args) if arc is None else ArcLengthRun(*args, arc)
        run.start(sol, initial_poses)
        run.loop()
        return run.finish()         # inside: a failure of the output's last files carries .solution too
    except BaseException as e:
        if run is not None:
            run.abort(e)
        raise


def _run_options(problem, t_start, t_end, allow_unmet_tolerance, check_stability, modes, branch_switching,
                 stabilize, penalty_hint=""):
    """The options of ``stepping.Run``; a stabilisation joins ``problem``'s contributions;
    ``penalty_hint``: the tail of a ``ConvergenceError`` the contributions give
    (``Problem.failure_hint``: a stiff penalty named), in place of the generic advice."""
    modes, branch_switching = check_stability_options(modes, branch_switching)
    stabilizer = stabilize_option(problem.system, stabilize, check=problem.conservative)
    if stabilizer is not None:
        problem.contributions.append(stabilizer)
    return dict(allow_unmet_tolerance=allow_unmet_tolerance, advice=_advice(problem, t_start, t_end, penalty_hint),
                penalty_hint=penalty_hint,
                check_stability=bool(check_stability or modes or branch_switching), modes=modes,
                branch_switching=branch_switching, stabilizer=stabilizer)


def _step_floor(min_step_ratio, grid):
    """Smallest step: ``min_step_ratio`` times the user's, raised to ``STEP_ROUNDOFF`` ulps of the
    largest ``|t|`` (shorter steps vanish in round-off).  Only a user's step that is itself not
    representable is refused: a short interval (e.g. bisecting for a critical load) is attempted,
    only its cut-backs are limited."""
    dt_user = grid[1] - grid[0]
    try:
        ratio = float(min_step_ratio)
    except (TypeError, ValueError):
        raise InputError(f"solve: min_step_ratio must be a number in [{MIN_STEP_RATIO:g}, 1], "
                         f"got {min_step_ratio!r}") from None
    if not MIN_STEP_RATIO <= ratio <= 1.0:
        raise InputError(f"solve: min_step_ratio must lie in [{MIN_STEP_RATIO:g}, 1] (smaller steps vanish "
                         f"in round-off), got {min_step_ratio!r}")
    t_max = float(np.abs(grid).max())
    floor = STEP_ROUNDOFF * np.finfo(float).eps * t_max
    if dt_user <= floor:
        raise InputError(f"solve: the step {dt_user:.3g} ((t_end - t_start) / steps) vanishes in round-off at "
                         f"t = {t_max:.6g} (it must exceed {floor:.3g}): use fewer steps or a longer interval")
    return max(dt_user * ratio, floor)


def _writer(output, system, checkpoint):
    if output is None:
        return None
    if hasattr(output, "write"):
        return output                     # e.g. io.vtk.StepWriter(folder, refine=4, compression=None)
    if checkpoint is None:
        checkpoint = np.inf               # saved at the end and when the run stops, not periodically
    elif not (isinstance(checkpoint, (int, float)) and checkpoint >= 0):
        raise InputError(f"solve: checkpoint must be a number of seconds >= 0 or None, got {checkpoint!r}")
    from .io.vtk import StepWriter
    return StepWriter(output, system, checkpoint=checkpoint)


def _advice(problem, t_start, t_end, penalty_hint=""):
    """``advice(failure, rotation_limit, H, t)``: the tail of a ``ConvergenceError`` message
    (``penalty_hint``, if any, in place of the tangent's diagnosis)."""
    system = problem.system

    def advice(failure, rotation_limit, H, t):
        msg = str(failure)
        hint = "" if rotation_limit is None or rotation_limit == msg else \
            f"; a larger step had failed because {rotation_limit}"
        turned = _largest_element_rotation(system, H)
        if not hint and turned > 0.75 * MAX_ELEMENT_ROTATION and not failure.rotation:
            hint = (f"; elements already turn by up to {turned:.2f} rad within one element "
                    f"(limit {MAX_ELEMENT_ROTATION:.2f}): refine the mesh")
        if failure.rotation or rotation_limit is not None or turned > 0.75 * MAX_ELEMENT_ROTATION:
            hint += _refine_advice(system, H, t, t_start, t_end)
        if penalty_hint:
            return hint + penalty_hint
        if not hint:
            hint = diagnosis.advice(failure, problem, H, t)
        return hint
    return advice
