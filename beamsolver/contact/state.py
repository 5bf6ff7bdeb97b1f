"""Checks of a committed contact state given back to a contact system (restart, ``linearize``).

A state comes from ``ContactSystem.get_state`` through a saved file, so it may be damaged or
belong to another model.  Everything the contact system will index or look up is checked
before it is used, and a state that is wrong raises ``InputError`` naming the entry:

- ``history.*``: one row per point, ``key`` strictly increasing (looked up by binary
  search), ``e``, ``m`` element ids, ``H_CL``, ``H_FK``, ``H_LK`` ``(k, 4, 4)``, ``xi1``,
  ``xi2`` ``(k,)``, ``lam_t`` ``(k, 3)``, all finite;
- every key names the point it was made for (``ContactSystem._point_pairs`` and
  ``ownership.gauss_owners``): a point pair's key ``point_offset + (decl n_el + e) n_el + m``,
  a Gauss point's ``((decl n_el + e) max_gp + g) n_beams + beam[m]``; the stored ``e`` and
  ``m`` must be those the key encodes (element ids shifted against their keys would carry
  the friction history to other material points: a wrong force, no error);
- ``mult_keys`` / ``mult_values``: equal lengths, keys strictly increasing and in the key range,
  values finite;
- ``prev_points`` (``e n_el + m``) and ``prev_owners`` (``key n_el + m``): integers in range.
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["KeyLayout", "check_state"]

WHERE = "contact state"
HISTORY_SHAPES = dict(key=(), e=(), m=(), H_CL=(4, 4), H_FK=(4, 4), H_LK=(4, 4), xi1=(), xi2=(), lam_t=(3,))
INTEGER = ("key", "e", "m")


@dataclass(frozen=True)
class KeyLayout:
    """The key space of a contact system: ``n_el`` elements, ``max_gp`` Gauss points per element,
    ``n_decls`` declarations, ``el_beam`` ``(n_el,)`` beam of each element, ``n_beams`` beams."""
    n_el: int
    max_gp: int
    n_decls: int
    el_beam: np.ndarray
    n_beams: int
    key_beam: np.ndarray = None     # the master beam a Gauss point's key names per element (``rules.pieces``: a wire
    #                                 in pieces is keyed by its first piece); None: ``el_beam``

    @property
    def point_offset(self):
        return np.int64(self.n_el) * self.max_gp * self.n_beams * self.n_decls

    @property
    def key_end(self):
        """One past the largest key (point keys come after the Gauss-point keys)."""
        return self.point_offset + np.int64(self.n_decls) * self.n_el * self.n_el

    def decode(self, key):
        """``(e, m_or_beam, is_point)`` encoded in ``key`` ``(k,)``: the slave element, then the master
        element of a point pair or the master beam of a Gauss point."""
        point = key >= self.point_offset
        rest = np.where(point, key - self.point_offset, key)
        n_el = np.int64(self.n_el)
        m_point = rest % n_el
        e_point = (rest // n_el) % n_el
        beam = rest % self.n_beams
        e_gauss = (rest // self.n_beams // self.max_gp) % n_el
        return np.where(point, e_point, e_gauss), np.where(point, m_point, beam), point


def _bad(name, what):
    return InputError(f"{WHERE}: {name!r} {what} (a damaged restart file, or the state of another model)")


def _array(state, name, shape, integer, n=None):
    try:
        a = np.asarray(state[name])
    except Exception as e:
        raise _bad(name, f"is not an array ({type(e).__name__})") from None
    if a.dtype.kind not in ("iu" if integer else "iuf"):
        raise _bad(name, f"must hold {'integers' if integer else 'numbers'}, got dtype {a.dtype}")
    if a.ndim != 1 + len(shape) or a.shape[1:] != shape or (n is not None and len(a) != n):
        want = ("k",) + shape if n is None else (n,) + shape
        raise _bad(name, f"has shape {a.shape}, expected {want}")
    if not integer and not np.all(np.isfinite(a)):
        raise _bad(name, "is not finite")
    return a.astype(np.int64) if integer else a.astype(float)


def _keys(name, key, layout):
    if len(key) and (key.min() < 0 or key.max() >= layout.key_end):
        raise _bad(name, f"has keys outside 0..{layout.key_end - 1}")
    if np.any(np.diff(key) <= 0):
        raise _bad(name, "is not strictly increasing")


def _ids(name, a, upper):
    if len(a) and (a.min() < 0 or a.max() >= upper):
        raise _bad(name, f"has ids outside 0..{upper - 1}")


def check_state(state, layout):
    """The parts of ``state`` (dict of arrays, ``ContactSystem.get_state``'s keys; missing parts
    stay missing) checked against the key space ``layout`` (``KeyLayout``); ``InputError`` names
    the first entry that is wrong.  Returns ``(history, mult, prev)``: the history dict (``None``
    if absent), ``(mult_keys, mult_values)`` (``None``) and ``{"prev_points": ..., "prev_owners": ...}``."""
    history = None
    present = [k for k in HISTORY_SHAPES if f"history.{k}" in state]
    if present:
        n = len(np.asarray(state[f"history.{present[0]}"]))
        history = {k: _array(state, f"history.{k}", HISTORY_SHAPES[k], k in INTEGER, n) for k in present}
    if history is not None and "key" in history:
        key = history["key"]
        _keys("history.key", key, layout)
        for k in ("e", "m"):
            if k in history:
                _ids(f"history.{k}", history[k], layout.n_el)
        if "e" in history and "m" in history:
            e, mb, point = layout.decode(key)
            stored = np.where(point, history["m"], layout.el_beam[history["m"]])
            keyed = stored if layout.key_beam is None else np.where(point, history["m"], layout.key_beam[history["m"]])
            # (keyed by the piece before ``rules.pieces``: an older archive's rows are valid, their keys not looked up)
            wrong = np.flatnonzero((e != history["e"]) | ((mb != stored) & (mb != keyed)))
            if len(wrong):
                i = int(wrong[0])
                raise _bad("history.e", f"and 'history.m' disagree with 'history.key' at {len(wrong)} of {len(key)} "
                           f"points (first: row {i}, key {int(key[i])} is of slave element {int(e[i])}, stored "
                           f"e = {int(history['e'][i])}, m = {int(history['m'][i])})")
    mult = None
    if "mult_keys" in state or "mult_values" in state:
        if "mult_keys" not in state or "mult_values" not in state:
            raise _bad("mult_keys", "and 'mult_values' come together; one is missing")
        mk = _array(state, "mult_keys", (), True)
        mv = _array(state, "mult_values", (), False, len(mk))
        _keys("mult_keys", mk, layout)
        mult = (mk, mv)
    prev = {}
    for name, upper in (("prev_points", np.int64(layout.n_el) * layout.n_el),
                        ("prev_owners", layout.point_offset * layout.n_el)):
        if name in state:
            a = _array(state, name, (), True)
            _ids(name, a, upper)
            prev[name] = a
    return history, mult, prev
