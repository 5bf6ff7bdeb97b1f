"""The stepping's hook for critical modes and branch switching (``solve(modes=, branch_switching=)``).

``wanted`` decides from the counts of negative eigenvalues whether to switch
at a converged step; ``switch`` moves the state onto a stable branch at the
same load (``bifurcation.descend``, then the solver's Newton) and records
what it did in the step's ``stats["branch_switch"]``; ``record_modes`` stores
the lowest modes of the recorded state (``stats["mode_eigenvalues"]``,
``stats["modes"]``).
"""
import logging
import time
import warnings

import numpy as np

from . import bifurcation
from ..nonlinear import linsolve
from ..nonlinear.definiteness import negative_eigenvalues
from ..errors import StabilityWarning
from ..failures import StepFailed
from ..nonlinear.modes import lowest_modes

__all__ = ["wanted", "switch", "locate", "record_modes", "OPTIONS", "BISECTION"]

log = logging.getLogger("beamsolver")

OPTIONS = (False, True, "auto")
BISECTION = 1e-3     # the crossing is located to this fraction of the step from the last stable state
BISECTION_MAX = 40   # most bisections
CLUSTER = 0.05       # crossings closer than this fraction of the step to the first are one crossing


def wanted(option, recorded, negative):
    """Switch at a step with ``negative`` negative eigenvalues?  ``True``: whenever there are some;
    ``"auto"``: when the count went up since the last recorded step (``recorded``: its stats)."""
    if not option or not negative:
        return False
    if option == "auto":
        return bifurcation.crossing(recorded[-1].get("negative_eigenvalues") if recorded else None, negative)
    return True


def record_modes(system, stats, H, K, k):
    """``stats["mode_eigenvalues"]`` ``(k,)`` and ``stats["modes"]`` ``(k, n, 6)``: the lowest eigenpairs
    of ``K`` at ``H`` as global node displacements and rotations, each of unit size."""
    lam, phi = lowest_modes(K, k)
    full = [bifurcation.full_increments(system, p) for p in phi.T]
    twists = [bifurcation.normalise(system, bifurcation.node_twists(system, H, dz)) for dz in full]
    stats.update(mode_eigenvalues=[float(x) for x in lam], modes=twists)


def _factorize(K):
    return linsolve.factorize_tangent(K, what="branch switching: singular bordered tangent")


def _weights(system, phi):
    """The metric of the amplitude (``bifurcation.descend``) on the free unknowns: the rotations of
    ``phi`` (in body frames, their projection stays meaningful at large rotations, unlike that
    of translations, which mixes axial and lateral motion as the frames turn), or its
    translations scaled by ``1 / L_ref^2`` if it has no rotation."""
    rot = np.zeros((system.n_nodes, 6), dtype=bool)
    rot[:, 3:] = True
    rot = rot.ravel()[system.free_dofs]
    if np.any(phi[rot] != 0.0):
        return rot.astype(float)
    return (~rot) / system.length_scale**2


def _descend(run, t, H, K):
    """``bifurcation.descend`` from ``H`` along the lowest mode of ``K``; ``(H, steps, lam)``."""
    sys, newton, problem = run.sys, run.newton, run.problem
    lam, phi = lowest_modes(K, 1)
    direction = bifurcation.normalise(sys, bifurcation.full_increments(sys, phi[:, 0])).ravel()[sys.free_dofs]

    def evaluate(H):
        ev = newton.evaluate(H, t)
        return ev.r[sys.free_dofs], problem.tangent(ev)

    def update(H, dzf):
        return problem.update(H, bifurcation.full_increments(sys, dzf))

    H1, steps = bifurcation.descend(evaluate, _factorize, update,
                                    lambda dzf: bifurcation.size(sys, bifurcation.full_increments(sys, dzf)),
                                    H, direction, _weights(sys, direction))
    return H1, steps, float(lam[0])


def _bisect(run, t_a, t_b, at_b, above):
    """The first load in ``(t_a, t_b]`` (to ``BISECTION`` of the step from ``run.t``) whose count of
    negative eigenvalues exceeds ``above``, and its state ``(H, ev, K, count, lowest)``
    (``at_b``: that of ``t_b``).  Each trial is a Newton step from the last recorded state."""
    for _ in range(BISECTION_MAX):
        if t_b - t_a <= BISECTION * (t_b - run.t):
            break
        t_m = 0.5 * (t_a + t_b)
        try:
            at_m = _state(run, t_m)
        except StepFailed:
            break
        if at_m[3] > above:
            t_b, at_b = t_m, at_m
        else:
            t_a = t_m
    return t_b, at_b


def _state(run, t):
    """The equilibrium at ``t`` reached from the last recorded state: ``(H, ev, K, count, lowest)``."""
    H, ev, _ = run.newton_step(t)
    K = run.problem.tangent(run.newton.last_evaluation)
    return (H, ev, K) + tuple(negative_eigenvalues(K))


def locate(run, t, at_t, before):
    """Where to switch over the step ``run.t -> t`` whose count of negative eigenvalues went up
    from ``before``: ``(t_s, state, t_c)``.  ``t_c`` is the first load past the crossing; if the
    step also passed a further critical load ``t_2`` (the count grew again more than ``CLUSTER``
    of the step to ``t_c`` later: closer ones are one crossing, a double eigenvalue split by
    round-off), ``t_s`` is halfway to it, where only the first mode is unstable (the other
    unknowns can then be relaxed about it), else the step's end."""
    t_c, at_c = _bisect(run, run.t, t, at_t, before)
    t_lo, at_lo = t_c, at_c
    while at_t[3] > at_lo[3]:
        t_2, at_2 = _bisect(run, t_lo, t, at_t, at_lo[3])
        if t_2 - t_c > CLUSTER * (t_c - run.t):
            t_s = 0.5 * (t_lo + t_2)
            return t_s, _state(run, t_s), t_c
        t_lo, at_lo = t_2, at_2
    return t, at_t, t_c


def switch(run, stats, t, H, ev, K):
    """Move the unstable state ``H`` (evaluation ``ev``, tangent ``K``) at ``t`` onto a stable branch
    along the lowest mode; returns ``(t, H, ev, K)`` of the step to record: the old one if
    switching failed (with a warning), or, where the count of negative eigenvalues went up over
    the step, the switched state at the load ``locate`` chose, which may lie before ``t`` (the
    stepping goes on from it)."""
    sys, start = run.sys, time.perf_counter()
    before = (run.sol.stats[-1].get("negative_eigenvalues") or 0) if run.sol.stats else 0
    record = dict(mode=1, amplitude=bifurcation.AMPLITUDE)
    at, t_c = (H, ev, K, stats["negative_eigenvalues"], stats["lowest_eigenvalue"]), t
    try:
        if stats["negative_eigenvalues"] > before:
            t, at, t_c = locate(run, t, at, before)
        record.update(critical_t=t_c, negative_before=at[3])
        stats.update(negative_eigenvalues=at[3], lowest_eigenvalue=at[4], stable=at[3] == 0, dt=t - run.t)
        H1, steps, lam = _descend(run, t, at[0], at[2])
        H1, ev1, more = run.newton_step(t, start=H1)
        K1 = run.problem.tangent(run.newton.last_evaluation)
        neg, lowest = negative_eigenvalues(K1)
    except StepFailed as e:
        record.update(failed=str(e), wall_time=time.perf_counter() - start)
        _warn(run, f"t = {t:.6g}: branch switching failed ({e}); the state stays on the unstable branch")
        stats["branch_switch"] = record
        return (t,) + at[:3]
    record.update(eigenvalue=lam, descent_steps=steps, iterations=more["iterations"], negative_after=neg,
                  distance=float(bifurcation.size(sys, _distance(sys, at[0], H1))),
                  wall_time=time.perf_counter() - start)
    stats.update(branch_switch=record, stable=neg == 0, negative_eigenvalues=neg, lowest_eigenvalue=lowest)
    log.info("t = %.6g: switched branch along mode 1 (eigenvalue %.3g; crossing at t = %.6g) in %d descent "
             "steps; %d negative eigenvalue(s) left", t, lam, t_c, steps, neg)
    if neg:
        _warn(run, f"t = {t:.6g}: after branch switching the tangent still has {neg} negative eigenvalue(s): "
                   "the state is not stable")
    return t, H1, ev1, K1


def _distance(system, H0, H1):
    """Translations ``(n, 6)`` (rotation part 0) between two states, for the unit-free size of the move."""
    d = np.zeros((system.n_nodes, 6))
    d[:, :3] = H1[:, :3, 3] - H0[:, :3, 3]
    return d


def _warn(run, text):
    log.warning(text)
    warnings.warn(text, StabilityWarning, stacklevel=6)
    run.sol.message = text if not run.sol.message else run.sol.message + "; " + text
