"""Exceptions raised by beamsolver."""

__all__ = ["InputError", "ConvergenceError"]


class InputError(ValueError):
    """Bad input: the message names the offending object and value."""


class ConvergenceError(RuntimeError):
    """A solve that could not continue; ``.solution`` holds every converged step."""

    def __init__(self, message, solution=None):
        super().__init__(message)
        self.solution = solution
