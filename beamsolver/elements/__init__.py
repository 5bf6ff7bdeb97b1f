"""Element types (the contract: ``elements.base``) and their registry.

``get(spec)`` turns what ``Model.add_beam(..., element=)`` accepts (a registered
name or an ``ElementType`` instance) into the type; ``TYPES`` maps names to
types.  A new element is one module defining an ``ElementType`` plus one line
here.
"""
from ..errors import InputError
from .base import MAX_ELEMENT_ROTATION, ElementState, ElementType, Reference
from .se3_2 import SE3Two
from .se3_3 import SE3Three

__all__ = ["get", "TYPES", "DEFAULT", "ElementType", "Reference", "ElementState", "MAX_ELEMENT_ROTATION"]

DEFAULT = "se3-2"
TYPES = {t.name: t for t in (SE3Two(), SE3Three())}


def get(spec=None):
    """The element type named ``spec`` (``None``: ``DEFAULT``), or ``spec`` itself if it is one."""
    if spec is None:
        spec = DEFAULT
    if isinstance(spec, ElementType):
        return spec
    if isinstance(spec, str) and spec in TYPES:
        return TYPES[spec]
    raise InputError(f"element must be one of {sorted(TYPES)} or an ElementType, got {spec!r}")
