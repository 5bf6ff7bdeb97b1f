"""Whether each converged step is a stable equilibrium: recorded by default, said once a run.

Every converged step of ``solve`` (step 0 included) records in ``stats[k]``:

- ``stable``: ``True`` when the symmetric tangent at the converged state is positive definite
  (a strict minimum of the potential energy), ``False`` when it has negative eigenvalues,
  ``None`` where it is not decided, and then always
- ``stable_note``: why not, or what was checked when it was not the step's own tangent;
- ``negative_eigenvalues`` (``None`` where not decided) and ``lowest_eigenvalue`` (scaled as in
  ``definiteness``; ``None`` where not computed: positive definite).

What is checked (``StepCheck``, built from ``solve(check_stability=, stabilize=)``):

- a conservative problem (``Problem.conservative``): the tangent of the converged state,
  ``definiteness.Inertia`` (a banded Cholesky on a layout kept for the pattern; the count of
  ``negative_eigenvalues`` when it fails).  The tangent is assembled already (Newton's last
  evaluation), so the check costs a matrix build and the Cholesky;
- ``stabilize`` on a conservative model: the model's own tangent, without the viscous damping
  (the stabilisation suspended for one more evaluation): the stability of the state as an
  equilibrium of the model; ``stable_note`` says so (``stats[k]["stabilization"]["equilibrium"]``
  says whether the state is one);
- friction, follower loads or a contribution without a potential: there is no potential and
  the tangent is not symmetric: ``stable=None``, the note names the parts;
- ``check_stability=False``: ``stable=None``, the note says it was switched off;
- step 0 kept as given (nothing acts at ``t_start``) that is no equilibrium (a pre-stressed
  contribution): ``stable=None``, the note gives its residual.

``check_stability=True`` where nothing can be decided warns once (``StabilityWarning``); options
that would do nothing together are refused by ``model.validation.check_stability_options``.

The first unstable state of a run is warned about (``StabilityWarning``, the step, its ``t``
and the count) and added to ``Solution.message``.
"""
import logging
import warnings

from ..errors import StabilityWarning
from ..nonlinear.definiteness import Inertia

__all__ = ["StepCheck", "nonconservative_parts", "unstable_text", "unsolved_note"]

log = logging.getLogger("beamsolver")

OFF_NOTE = "not checked: solve(check_stability=False)"
MODEL_NOTE = ("of the model's tangent without the stabilisation's viscous damping (the damped tangent "
              "is checked by the stabilisation)")


def nonconservative_parts(problem, skip=()):
    """Names of the parts of ``problem`` without a potential (follower loads, friction, ...),
    contributions in ``skip`` left out."""
    s = problem.system
    parts = []
    if len(s.load_nodes) and s.load_follower.any():
        parts.append("follower loads")
    if s.line is not None and len(s.line.follower):
        parts.append("follower line loads")
    for c in problem.contributions:
        if c in skip or c.conservative:
            continue
        parts.append("friction in contact (mu > 0)" if c.name == "contact" else f"contribution {c.name!r}")
    return parts


def unstable_text(step, t, negative, kept=False, advice=True):
    """The warning on the first unstable state of a run (step ``step`` at ``t``, ``negative``
    negative eigenvalues); ``kept``: kept by the stable-branch rule after its cut-backs;
    ``advice``: how load stepping reaches a stable branch."""
    head = (f"step {step} (t = {t:.6g}): the equilibrium is unstable (the tangent has {negative} negative "
            "eigenvalue(s))")
    if kept:
        return (head + ": the steps from a stable equilibrium converged to an unstable one also after cut-backs: "
                "the stable branch ends here (a limit point, or the bifurcation of a perfect structure); the "
                "path goes on unstable")
    head += ": the path has passed a limit point or bifurcation"
    if not advice:
        return head
    return head + ("; branch_switching='auto' moves it onto a stable branch, an imperfection or "
                   "path='arc-length' follows it")


def unsolved_note(ratio):
    """The ``stable_note`` of a step 0 kept as given (nothing acts at ``t_start``) that is no equilibrium
    (scaled residual ``ratio``, e.g. a pre-stressed contribution): stability is not defined there."""
    return (f"not decided: the given state at t_start is kept unsolved (nothing acts there) and is not an "
            f"equilibrium (scaled residual {ratio:.3g})")


class StepCheck:
    """The stability record of the converged steps of one run of ``problem``.

    ``option``: ``solve(check_stability=)`` (``None``/``True``: check, ``False``: not);
    ``stabilizer``: the run's ``stabilize.Stabilization`` or ``None``.  ``checks``: whether a
    tangent is checked at all; ``note``: the ``stable_note`` of every step when not."""

    def __init__(self, problem, option=None, stabilizer=None):
        self.problem, self.stabilizer = problem, stabilizer
        self.inertia = Inertia()
        parts = nonconservative_parts(problem, skip=(stabilizer,))
        if option is False:
            self.note = OFF_NOTE
        elif parts:
            self.note = ("not decided: " + ", ".join(parts) + ": no potential energy, the tangent is not "
                         "symmetric (its symmetric part proves nothing either way)")
        else:
            self.note = None
        self.checks = self.note is None
        if option is True and parts:          # asked for and impossible: said, not a silent no-op
            text = f"solve(check_stability=True): stability is {self.note}; every step records stable=None"
            log.warning(text)
            warnings.warn(text, StabilityWarning, stacklevel=4)

    def tangent(self, H, t, ev):
        """The tangent to check at the converged poses ``H`` (at ``t``; ``ev`` its evaluation, with
        tangent data): the problem's, or the model's without the damping of an active
        stabilisation (one more evaluation).  ``None`` when nothing is checked."""
        if not self.checks:
            return None
        problem, stab = self.problem, self.stabilizer
        if stab is None or not stab.active:
            if ev.kvals is None:
                ev = problem.evaluate(H, t, tangent=True)
            return problem.tangent(ev)
        stab.suspended = True
        try:
            return problem.tangent(problem.evaluate(H, t, tangent=True))
        finally:
            stab.suspended = False

    def record(self, stats, K, known=None, note=None):
        """Fill ``stats`` with ``stable``, ``negative_eigenvalues``, ``lowest_eigenvalue`` (and
        ``stable_note``) for the tangent ``K`` (``tangent``; ``None``: not checked, for the reason
        ``note``, by default ``self.note``).  ``known``: a count of ``K``'s negative eigenvalues
        already computed this step (the stable-branch rule's), used when it is 0.  Returns the
        count (``None``: not decided)."""
        if K is None:
            stats.update(stable=None, negative_eigenvalues=None, lowest_eigenvalue=None,
                         stable_note=note or self.note)
            return None
        neg, lowest = (0, None) if known == 0 else self.inertia(K)
        stats.update(stable=neg == 0, negative_eigenvalues=int(neg), lowest_eigenvalue=lowest)
        if self.stabilizer is not None and self.stabilizer.active:
            stats["stable_note"] = MODEL_NOTE
        return int(neg)
