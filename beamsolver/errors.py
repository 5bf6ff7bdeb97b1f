"""Exceptions raised by beamsolver."""

__all__ = ["InputError", "ConvergenceError", "StabilityWarning", "StabilizationWarning", "MaterialRangeWarning",
           "ConditioningWarning", "GeometryWarning"]


class InputError(ValueError):
    """Bad input: the message names the offending object and value."""


class ConvergenceError(RuntimeError):
    """A solve that could not continue; ``.solution`` holds every converged step, ``.failure``
    the typed reason (a ``beamsolver.failures.StepFailed``) when a step failed."""

    def __init__(self, message, solution=None):
        super().__init__(message)
        self.solution = solution
        self.failure = None


class StabilityWarning(RuntimeWarning):
    """A converged equilibrium is unstable (its tangent is indefinite), said once a run, or a
    stability check asked for where none can be made: see ``solve(check_stability=)``."""


class StabilizationWarning(RuntimeWarning):
    """The viscous stabilisation has dissipated a large part of the strain energy: see ``solve(stabilize=)``."""


class MaterialRangeWarning(UserWarning):
    """A section is used beyond the yield stress or strain it was given (``Section(yield_stress=)``):
    the linear-elastic answer is no longer the material's (``beamsolver.model.material_range``)."""


class ConditioningWarning(RuntimeWarning):
    """A contact penalty far stiffer than the beams it couples leaves the tangent ill-conditioned:
    see ``beamsolver.contact.conditioning``."""


class GeometryWarning(UserWarning):
    """Sizes implausible for the scene at step 0 (a radius larger than its beam, a tube reaching another
    beam's centre line: often a radius in another unit than the lengths): see ``beamsolver.model.sanity``."""
