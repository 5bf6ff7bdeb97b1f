"""Contact options of one ``Model.add_contact`` declaration as one validated, typed object.

``ContactOptions`` (defined with the user's declarations, ``model.contact_options``: each field's
default, check and meaning written once) is read here by the contact system;
``declaration_table`` builds the kernel's per-declaration parameters from it.
"""
import numpy as np

from ..model.contact_options import (ADJUST, EXACT_C, EXACT_N, GAUSS_POINTS, LINE_ANGLE, SEGMENT_POINTS,
                                     SLIP_TOLERANCE, SMOOTHING, STICK_TOLERANCE, ContactOptions, describe)

__all__ = ["ContactOptions", "declaration_table", "describe", "SMOOTHING", "SLIP_TOLERANCE", "STICK_TOLERANCE",
           "LINE_ANGLE", "ADJUST", "EXACT_C", "EXACT_N", "GAUSS_POINTS", "SEGMENT_POINTS"]


def declaration_table(options):
    """The per-declaration parameters ``{name: (n_decl,) float array}`` of the ``ContactOptions``
    fields that have a ``kernel_none`` (the number standing for ``None``: derived per pair, or off),
    one entry per declaration of ``options``, indexed by a pair's ``decl``."""
    from dataclasses import fields
    out = {}
    for f in fields(ContactOptions):
        none = f.metadata["kernel_none"]
        if none is not None:
            out[f.name] = np.array([none if getattr(o, f.name) is None else getattr(o, f.name) for o in options],
                                   dtype=float)
    return out
