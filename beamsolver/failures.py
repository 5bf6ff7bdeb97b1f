"""Typed failures of a Newton step (solver-private), so the solver decides on the kind, not on text.

A step raises one of these; ``solve`` cuts the step back when ``retry`` is
true, otherwise it stops at once with ``ConvergenceError`` whose ``failure``
attribute is the instance (``isinstance(error.failure, RotationLimit)``).
"""

__all__ = ["StepFailed", "RotationLimit", "NotConverged", "Diverged", "DampingStalled",
           "SingularTangent", "NonFinite", "AugmentationFailed", "MotionTooFast",
           "ContactTunnelling", "NoContactNormal", "LeftStableBranch"]


class StepFailed(Exception):
    """A Newton step that failed; ``retry``: a smaller step may succeed."""
    retry = True
    rotation = False          # failed on the element-rotation limit


class RotationLimit(StepFailed):
    """An element turned past ``MAX_ELEMENT_ROTATION`` or may have passed pi within a step."""
    rotation = True


class NotConverged(StepFailed):
    """``max_iter`` iterations without meeting the tolerance; ``ratio``: last scaled residual."""

    def __init__(self, message, ratio=float("nan")):
        super().__init__(message)
        self.ratio = ratio


class Diverged(StepFailed):
    """The scaled residual grew past ``Convergence.divergence``."""


class DampingStalled(StepFailed):
    """Neither a damped nor the full Newton step reduces the Newton correction."""


class SingularTangent(StepFailed):
    """The tangent could not be factorised or solved; ``condition``: estimate if known."""

    def __init__(self, message, condition=None):
        super().__init__(message)
        self.condition = condition


class NonFinite(StepFailed):
    """A non-finite residual or increment; ``source`` names the input that produced it, if known."""

    def __init__(self, message, source=None):
        super().__init__(message)
        self.source = source


class AugmentationFailed(StepFailed):
    """Augmented-Lagrangian updates did not meet the requested penetration tolerance."""
    retry = False


class MotionTooFast(StepFailed):
    """A prescribed motion turns by more than ``MAX_MOTION_ROTATION`` even over the smallest step."""
    retry = False


class ContactTunnelling(StepFailed):
    """A contact pair changed sides within the step (one beam passed through the other)."""


class NoContactNormal(StepFailed):
    """The centre lines of a contact pair intersect: the pair has no normal."""


class LeftStableBranch(StepFailed):
    """A step from a stable equilibrium converged to an unstable one (``stable_branch``): a
    shorter step is tried; ``negative``: negative eigenvalues of the end state's tangent, ``t``
    its time, ``result``: the converged step ``(t, H, ev, stats)`` (kept if no shorter step helps)."""

    def __init__(self, message, negative, t=float("nan"), result=None):
        super().__init__(message)
        self.negative, self.t, self.result = negative, t, result
