"""Steppers by name (``solve(path=...)``): a registry of classes following the ``Stepper`` protocol.

A stepper walks the pseudo-time of one ``solve`` over the one Newton loop
(``nonlinear.newton.Newton``; ``Newton.step`` for a fixed ``t``, ``Newton.iterate`` with a
constraint of its own otherwise).  A new strategy is a class registered here, not an edit of
``solve``'s signature: ``register(MyStepper)`` makes ``solve(..., path=MyStepper.name)`` use it.
"""
from typing import Protocol

from ..errors import InputError
from .arclength import ArcLengthRun
from .steps import Run

__all__ = ["Stepper", "STEPPERS", "register", "stepper"]


class Stepper(Protocol):
    """``name``: its ``solve(path=)``; ``path_options(value, restart, branch_switching, stabilize)``:
    its own options checked (``solve(arc_length=)``; refusing what it cannot do); built as
    ``cls(problem, newton, writer, grid, dt_min, verbose, options)`` (``options`` a
    ``stepping.options.RunOptions``, ``writer`` an ``io.writers`` writer or ``None``), then
    ``start(restart_solution, initial_poses)``, ``loop()``, ``finish()`` (the ``Solution``);
    ``abort(exc)`` on any exception (keeps and saves what converged, attaches ``exc.solution``)."""
    name: str

    @staticmethod
    def path_options(value, restart, branch_switching=False, stabilize=None): ...

    def start(self, restart_solution, initial_poses): ...

    def loop(self): ...

    def finish(self): ...

    def abort(self, exc): ...


STEPPERS = {}


def register(cls):
    """Add the stepper class ``cls`` under ``cls.name``; returns ``cls`` (a decorator)."""
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name:
        raise InputError(f"register: a stepper needs a name (str), got {name!r}")
    missing = [m for m in ("path_options", "start", "loop", "finish", "abort") if not callable(getattr(cls, m, None))]
    if missing:
        raise InputError(f"register: stepper {name!r} lacks {missing} (stepping.steppers.Stepper)")
    STEPPERS[name] = cls
    return cls


def stepper(path):
    """The stepper class of ``solve(path=path)``; ``InputError`` naming the known ones."""
    if not isinstance(path, str) or path not in STEPPERS:
        raise InputError(f"solve: path must be {' or '.join(repr(k) for k in STEPPERS)}, got {path!r}")
    return STEPPERS[path]


register(Run)
register(ArcLengthRun)
