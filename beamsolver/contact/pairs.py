"""Former home of the pair geometry and the contact oracle, kept so that old imports work.

The pair kinds, tolerances and numpy geometry are in ``frames`` (production), ``PENALTY_T_MIN``
in ``law``; the complex-step oracle (``contact_kernel``, ``kernel_and_tangent``,
``touching_gap``, ``stick_penalty``) is ``reference`` and is loaded only when one of its names is
read here (production never imports it).
"""
from .frames import (LINE, NORMAL_TOL, ORTHOGONAL, POINT, TOUCH_ROUNDOFF, material_frames, no_normal,
                     touch_tolerance)
from .frames import (axes as _axes, body_wrench as _body_wrench, contact_frames as _contact_frames,  # noqa: F401
                     log_c as _log_c, node_jacobians as _node_jacobians, pose as _pose, project as _project,
                     section as _section)
from .law import PENALTY_T_MIN

__all__ = ["LINE", "ORTHOGONAL", "POINT", "NORMAL_TOL", "TOUCH_ROUNDOFF", "PENALTY_T_MIN", "touch_tolerance",
           "no_normal", "material_frames"]

_ORACLE = ("contact_kernel", "kernel_and_tangent", "touching_gap", "stick_penalty", "CHUNK")


def __getattr__(name):
    if name in _ORACLE:
        from . import reference
        return getattr(reference, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
