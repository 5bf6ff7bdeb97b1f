"""Keep load stepping on the stable branch the load path and the imperfection select.

From a stable equilibrium (a minimum of the potential energy), Newton
iterations towards the next load level may converge to an equilibrium on the
other side of a bifurcation, a saddle of the energy: the clamped-free column
past ``P_cr`` under a small lateral force, the imperfect Argyris frame.  The
full Newton step taken from a state whose tangent at the new load is already
indefinite, or the undamped fallback of ``solver.Newton.step``, lands there and
the step "converges".  Short steps, where the tangent at the new load is still
positive definite, follow the stable branch (docs/theory_stable_branch.md).

``verdict`` decides after a converged step of a conservative problem
(``Problem.conservative``: a symmetric tangent, a potential) that started from
a stable state and is flagged by the stepping (``stepping.Run._keep_branch``: the
step's first tangent had ``det < 0``, ``Newton.indefinite_seen``, or the step
took undamped Newton iterations): the end state's tangent is checked
(``definiteness.negative_eigenvalues``: a Cholesky factorisation of the scaled
tangent when it is positive definite).  Stable: kept.  Unstable: the step left
the stable branch, ``LeftStableBranch`` is raised and the step is cut back, at
most ``RETRIES`` times for one step and ``RETRIES_RUN`` times since a step last
converged at its first try; past that
(the stable branch itself ends there: a limit point, or the bifurcation of a
perfect structure) the unstable state is kept, and said so.  Steps from an
unstable state and non-conservative problems (friction, follower loads,
stabilisation) are not checked, nor is any step of ``solve(check_stability=False)``
(nothing is decided about stability there: ``stepping.steps.Run._watches_branch``).
"""
from ..nonlinear.definiteness import negative_eigenvalues
from ..failures import LeftStableBranch

__all__ = ["negative_count", "verdict", "kept", "RETRIES", "RETRIES_RUN", "ENABLED"]

ENABLED = True     # False: no step is checked (the determinant sign is not read either); benchmarks measure
                   # the rule's cost with it, and a user can follow an unstable branch on purpose

RETRIES = 3        # cut-backs of one step for leaving the stable branch before its unstable end state is kept
RETRIES_RUN = 8    # the same since a step last converged at its first try (no homing in on a critical load)


def negative_count(problem, ev):
    """Negative eigenvalues of the tangent of the evaluation ``ev`` (``problem.Evaluation``)."""
    return negative_eigenvalues(problem.tangent(ev))[0]


def verdict(problem, ev, before, t):
    """Check the step converged at ``t`` (evaluation ``ev``).  ``before()``: negative-eigenvalue
    count of the state the step started from (computed only when needed).  Returns the end
    state's count (``None``: not counted); raises ``LeftStableBranch`` (with ``negative``) for an
    unstable state reached from a stable one."""
    if not problem.conservative or before() != 0:
        return None
    neg = negative_count(problem, ev)
    if neg:
        raise LeftStableBranch(f"t = {t:.6g}: the step from a stable equilibrium converged to an unstable one "
                               f"(the tangent has {neg} negative eigenvalue(s)): the stable branch was left", neg)
    return 0


def kept(failure):
    """The text saying an unstable state was kept after ``RETRIES`` cut-backs (or at the smallest step)."""
    return (f"t = {failure.t:.6g}: the steps from a stable equilibrium converged to an unstable one (the tangent "
            f"has {failure.negative} negative eigenvalue(s)) also after cut-backs: the stable branch ends here (a "
            "limit point, or the bifurcation of a perfect structure); the path goes on unstable")
