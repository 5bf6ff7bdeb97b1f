"""Stress resultants across a cut through a bundle of beams (strands, cables, any group of beams).

The cut is material: the sections whose reference centre points lie in the plane
``(x - origin) . axis = position`` (``axis`` a unit vector; for a strand built along ``e_z``,
``position`` is the arc length along the strand axis).  Each beam crossing the plane once is cut
inside one element ``e = (A, B)`` at ``xi`` (linear in the reference coordinate: exact for
straight and helical elements).

The force and moment transmitted across the cut, exerted by the part on the ``+axis`` side on
the part before it, come from the element's nodal forces, which are in equilibrium with the
nodes (docs/theory_strand_bending.md section 6): with ``r_A = f_int,A - f_ext,A`` the element's
part of the residual at its node ``A`` (body components; ``f_ext`` its consistent line loads),
the cut just after ``A`` carries ``F_A = -R_A r_A,u`` and ``M_A = -R_A r_A,w`` (about ``x_A``); the
cut at ``xi`` carries that minus the line load on the piece ``[0, xi]`` of the element (force and
moment, Gauss points along ``H_A exp(xi' h)``), so the cut at ``xi = 1`` is that at ``B`` to the
quadrature of the consistent loads.  A beam running against ``axis`` has the opposite sign.  Summed over the beams with
the lever arms of their forces about ``point``::

    F = sum_i F_i,   M = sum_i (M_i + (x_i - point) x F_i).

The deformed bundle axis ``a`` at the cut is the mean of the beams' tangents there (signed);
``point`` defaults to the axial-stiffness-weighted centroid of the cut centre points.  Reported:
``axial = F . a`` (tension positive), ``torque = M . a`` and the bending moments about the given
``bending_axis`` projected normal to ``a`` (``b1``) and about ``b2 = a x b1``.
"""
from dataclasses import dataclass

import numpy as np

from ..elements import element, line_load
from ..lie import se3
from ..errors import InputError

__all__ = ["CutResultant", "cut_resultant"]


@dataclass
class CutResultant:
    """Resultants across a cut, arrays with a leading step axis when several steps were asked:
    ``force``, ``moment`` ``(..., 3)`` global (moment about ``point``), ``point``, ``axis`` ``(..., 3)``,
    ``axial``, ``torque`` ``(...)``, ``bending`` ``(..., 2)`` about ``bending_axes`` ``(..., 2, 3)``."""
    force: np.ndarray
    moment: np.ndarray
    point: np.ndarray
    axis: np.ndarray
    axial: np.ndarray
    torque: np.ndarray
    bending: np.ndarray
    bending_axes: np.ndarray


def _unit(v, name):
    try:
        v = np.asarray(v, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise InputError(f"cut_resultant: {name} must be a 3-vector, got {v!r}") from None
    n = np.linalg.norm(v)
    if not np.isfinite(n) or n == 0.0:
        raise InputError(f"cut_resultant: {name} must be a finite non-zero 3-vector, got {v.tolist()}")
    return v / n


def _crossings(system, beams, origin, axis, position):
    """Per beam crossing the reference plane: its cut element, ``xi`` and direction sign."""
    P0 = system.poses0[:, :3, 3]
    el, xi, sign = [], [], []
    for b in beams:
        z = (P0[b.nodes] - origin) @ axis
        lo, hi = np.minimum(z[:-1], z[1:]), np.maximum(z[:-1], z[1:])
        hit = np.flatnonzero((lo <= position) & (position <= hi) & (hi > lo))
        if len(hit) == 0:
            continue
        i = int(hit[0])
        el.append(b.elements[i])
        xi.append((position - z[i]) / (z[i + 1] - z[i]))
        sign.append(1.0 if z[i + 1] > z[i] else -1.0)
    if not el:
        raise InputError(f"cut_resultant: no beam of {[b.id for b in beams]} crosses the plane at "
                         f"position {position!r} along axis {axis.tolist()}")
    return np.array(el), np.array(xi), np.array(sign)


def cut_resultant(solution, beams, position, axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0), point=None,
                  bending_axis=(0.0, 1.0, 0.0), step=-1):
    """Resultants across the material cut ``(x_ref - origin) . axis = position`` of ``beams`` (a Beam or
    a list) at ``step`` (an index, or ``None`` for every step); returns a ``CutResultant`` (module
    docstring).  ``point``: global point the moments are taken about (default: the EA-weighted
    centroid of the cut centre points at each step)."""
    system = solution.system
    if system is None:
        raise InputError("cut_resultant: the solution has no model (a loaded one); solve the model again")
    beams = [beams] if not isinstance(beams, (list, tuple)) else list(beams)
    axis, origin = _unit(axis, "axis"), np.asarray(origin, dtype=float).reshape(3)
    b_given = _unit(bending_axis, "bending_axis")
    el, xi, sign = _crossings(system, beams, origin, axis, float(position))
    steps = np.arange(len(solution.times))
    if step is not None:
        try:
            steps = steps[[int(step)]]
        except (IndexError, TypeError, ValueError):
            raise InputError(f"cut_resultant: step {step!r} is not a step of the solution "
                             f"({len(steps)} steps)") from None
    H = solution.poses[steps]                                          # (s, n, 4, 4)
    s, k = len(steps), len(el)
    nodes = system.enodes[el]                                          # (k, 2)
    flat = (np.arange(s)[:, None, None] * H.shape[1] + nodes[None]).reshape(-1, 2)
    Hf = H.reshape(-1, 4, 4)
    f = element.evaluate_nodes(Hf, flat, np.tile(system.L[el], s), np.tile(system.eps0[el], (s, 1)),
                               np.tile(system.C[el], (s, 1, 1)), False)[0].reshape(s, k, 12)
    f = f - _line_loads(system, solution.times[steps], Hf, flat, el).reshape(s, k, 12)
    HA, HB = H[:, nodes[:, 0]], H[:, nodes[:, 1]]                      # (s, k, 4, 4)
    RA = HA[..., :3, :3]
    mv = np.einsum
    FA, MA = -mv("skij,skj->ski", RA, f[..., 0:3]), -mv("skij,skj->ski", RA, f[..., 3:6])
    h = se3.log(se3.relative(HA, HB))
    Hc = se3.interpolate(HA, h, np.broadcast_to(xi, (s, k)))
    xc, tangent = Hc[..., :3, 3], Hc[..., :3, 0]
    a = np.sum(sign[:, None] * tangent, axis=1)
    a /= np.linalg.norm(a, axis=-1, keepdims=True)
    if point is None:
        w = system.C[el, 0, 0]
        p = np.einsum("k,skj->sj", w, xc) / w.sum()
    else:
        p = np.broadcast_to(np.asarray(point, dtype=float).reshape(3), (s, 3))
    sg = sign[None, :, None]
    MAp = MA + np.cross(HA[..., :3, 3] - p[:, None], FA)
    dF, dM = _partial_loads(system, solution.times[steps], HA, h, el, xi, p)
    F = np.sum(sg * (FA - dF), axis=1)
    M = np.sum(sg * (MAp - dM), axis=1)
    b1 = b_given - np.sum(b_given * a, axis=-1, keepdims=True) * a
    norm = np.linalg.norm(b1, axis=-1, keepdims=True)
    if np.any(norm < 1e-6):
        raise InputError(f"cut_resultant: bending_axis {bending_axis!r} is parallel to the bundle axis at the cut")
    b1 /= norm
    b2 = np.cross(a, b1)
    out = CutResultant(F, M, p, a, np.sum(F * a, axis=-1), np.sum(M * a, axis=-1),
                       np.stack([np.sum(M * b1, axis=-1), np.sum(M * b2, axis=-1)], axis=-1),
                       np.stack([b1, b2], axis=-2))
    if step is not None:
        out = CutResultant(*(getattr(out, n)[0] for n in out.__dataclass_fields__))
    return out


def _partial_loads(system, times, HA, h, el, xi, p):
    """Force and moment about ``p`` ``(s, k, 3)`` of the line loads on the pieces ``[0, xi]`` of the cut
    elements ``el`` at each step (poses ``HA``, twists ``h`` ``(s, k, ...)``; global components)."""
    s, k = HA.shape[:2]
    dF, dM = np.zeros((s, k, 3)), np.zeros((s, k, 3))
    ln = system.line
    if ln is None:
        return dF, dM
    j, rows = np.nonzero(el[:, None] == ln.element[None, :])
    if not len(j):
        return dF, dM
    lf = np.array([system.load_factors(t)[system.n_point_loads:] for t in times])[:, ln.load[rows]]   # (s, m)
    fol = np.isin(rows, ln.follower)
    for x, w in zip(line_load.XI, line_load.WEIGHTS):
        Hx = se3.interpolate(HA[:, j], h[:, j], x * xi[j])                   # (s, m, 4, 4)
        R = Hx[..., :3, :3]
        q = np.where(fol[:, None], np.einsum("smij,mj->smi", R, ln.q[rows]), ln.q[rows])
        m = np.where(fol[:, None], np.einsum("smij,mj->smi", R, ln.m[rows]), ln.m[rows])
        wl = (w * xi[j] * ln.L[rows])[None, :, None] * lf[..., None]
        np.add.at(dF, (slice(None), j), wl * q)
        np.add.at(dM, (slice(None), j), wl * (np.cross(Hx[..., :3, 3] - p[:, None], q) + m))
    return dF, dM


def _line_loads(system, times, Hf, flat, el):
    """Consistent nodal loads ``(s k, 12)`` of the line loads on the cut elements at each step."""
    out = np.zeros((len(flat), 12))
    ln = system.line
    if ln is None:
        return out
    j, rows = np.nonzero(el[:, None] == ln.element[None, :])        # cut element j carries line-table row
    if not len(j):
        return out
    s, k = len(times), len(el)
    lf = np.array([system.load_factors(t)[system.n_point_loads:] for t in times])      # (s, n_line_loads)
    idx = (np.arange(s)[:, None] * k + j[None]).ravel()
    rr = np.tile(rows, s)
    fac = lf[np.repeat(np.arange(s), len(rows)), ln.load[rr]][:, None]
    follower = np.isin(rr, ln.follower)
    for fol in (False, True):
        sel = follower == fol
        if sel.any():
            i, r = idx[sel], rr[sel]
            np.add.at(out, i, line_load.nodal_loads(Hf[flat[i, 0]], Hf[flat[i, 1]], ln.L[r], fac[sel] * ln.q[r],
                                                    fac[sel] * ln.m[r], fol))
    return out
