"""The options of one run of a stepper (``RunOptions``), typed, as ``solve`` resolves them."""
from dataclasses import dataclass, fields
from typing import Any, Callable, Optional

from ..errors import InputError

__all__ = ["RunOptions", "no_advice"]


def no_advice(failure, rotation_limit, H, t):
    """The ``advice`` of a run without any: no message tail."""
    return ""


@dataclass
class RunOptions:
    """What a stepper (``stepping.STEPPERS``) needs besides the problem, the Newton loop and the grid.

    ``advice(failure, rotation_limit, H, t)``: the tail of a ``ConvergenceError`` message;
    ``penalty_hint``: the tail naming a stiff penalty (``Problem.failure_hint``), also at ``t_start``;
    ``allow_unmet_tolerance``: accept a step whose contributions' tolerance is unmet, with a warning;
    ``check_stability``: ``None``/``True``: judge every converged state (``stability.StepCheck``),
    ``False``: not (nor does the stable-branch rule cut steps back: ``stable_branch``);
    ``modes``: lowest eigenpairs recorded per checked step; ``branch_switching``: ``False``, ``True``
    or ``"auto"``; ``stabilizer``: the ``stabilize.Stabilization`` (a contribution of the problem) or
    ``None``; ``path``: the stepper's own options (``arclength.ArcLength`` for ``"arc-length"``)."""
    advice: Callable = no_advice
    penalty_hint: str = ""
    allow_unmet_tolerance: bool = False
    check_stability: Optional[bool] = None
    modes: int = 0
    branch_switching: Any = False
    stabilizer: Optional[Any] = None
    path: Optional[Any] = None

    @classmethod
    def of(cls, value):
        """``RunOptions`` from ``None``, a dict of its fields or a ``RunOptions``."""
        if value is None:
            return cls()
        if isinstance(value, cls):
            return value
        if isinstance(value, dict):
            unknown = sorted(set(value) - {f.name for f in fields(cls)})
            if unknown:
                raise InputError(f"RunOptions: unknown option(s) {unknown}")
            return cls(**value)
        raise InputError(f"RunOptions: expected a RunOptions or a dict, got {type(value).__name__}")
