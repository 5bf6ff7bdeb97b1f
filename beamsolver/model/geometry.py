"""Node-pose generators: ``(n_elements + 1, 4, 4)`` arrays with ``e1`` along the tangent.

Choice of ``e2`` (documented once, used by every generator unless an ``e2``
is given): ``e2 = unit(e_z x e1)``, or ``e_y`` when ``e1`` is parallel to
``e_z``; ``e3 = e1 x e2``.  So a beam along ``+x`` has ``e2 = +y``, ``e3 = +z``.
Arcs and helices carry their principal normal (towards the centre / axis) as
``e2``; polylines parallel-transport ``e2`` from the first node.

No generator makes an element turning by more than ``MAX_REFERENCE_ELEMENT_ROTATION``
(0.75 pi, the model's limit): past it the relative rotation of the end frames
would describe a shorter turn the other way (a helix with one element per turn
would be straight).  Arcs and helices name the ``n_elements`` needed; a polyline
whose centre line folds back or turns that sharply at a point is refused.
"""
import numpy as np

from ..errors import InputError
from .validation import MAX_REFERENCE_ELEMENT_ROTATION, count, real, vector

__all__ = ["straight", "arc", "helix", "double_helix", "polyline", "frames_from_tangents"]

_PARALLEL_TOL = 1e-9


def _unit(v, what="vector"):
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    if np.any(n <= 0.0) or not np.all(np.isfinite(v)):
        raise InputError(f"geometry: {what} must be finite and non-zero, got {v.tolist()}")
    return v / n


def _finite_points(points, what):
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"geometry.{what}: points must be numbers of shape (n, 3), got {points!r}") from None
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"geometry.{what}: points must have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        bad = np.argwhere(~np.isfinite(p))[0]
        raise InputError(f"geometry.{what}: point {bad[0]} is not finite: {p[bad[0]].tolist()}")
    return p


def _check_n(n_elements, what):
    return count(n_elements, "n_elements", f"geometry.{what}")


def _check_turn(angle_per_element, n, what):
    """Refuse elements turning by more than ``MAX_REFERENCE_ELEMENT_ROTATION`` (the relative rotation of
    their end frames would alias to a shorter rotation): name the element count needed."""
    if angle_per_element > MAX_REFERENCE_ELEMENT_ROTATION * (1.0 + 1e-12):
        need = int(np.ceil(n * angle_per_element / MAX_REFERENCE_ELEMENT_ROTATION * (1.0 - 1e-12)))
        raise InputError(f"geometry.{what}: {n} element(s) turn by {angle_per_element:.3f} rad per element, "
                         f"more than an element can represent (limit 0.75 pi = {MAX_REFERENCE_ELEMENT_ROTATION:.3f} "
                         f"rad; its end frames would describe a shorter turn); use n_elements >= {need}")


def _default_e2(e1):
    e1 = np.asarray(e1, dtype=float)
    c = np.cross([0.0, 0.0, 1.0], e1)
    nc = np.linalg.norm(c)
    if nc < 1e-6:
        return np.array([0.0, 1.0, 0.0])
    return c / nc


def _poses(x, e1, e2):
    e1 = _unit(e1, "tangent")
    e2 = e2 - np.sum(e2 * e1, axis=-1, keepdims=True) * e1
    e2 = _unit(e2, "e2 (parallel to the tangent?)")
    e3 = np.cross(e1, e2)
    H = np.zeros(x.shape[:-1] + (4, 4))
    H[..., :3, 0], H[..., :3, 1], H[..., :3, 2] = e1, e2, e3
    H[..., :3, 3] = x
    H[..., 3, 3] = 1.0
    return H


def straight(start=(0.0, 0.0, 0.0), end=(1.0, 0.0, 0.0), n_elements=10, e2=None):
    """Straight beam from ``start`` to ``end``; ``e2`` optional (projected normal to the axis)."""
    n = _check_n(n_elements, "straight")
    a, b = _finite_points([start, end], "straight")
    if np.linalg.norm(b - a) == 0.0:
        raise InputError(f"geometry.straight: start and end coincide at {a.tolist()}")
    e1 = (b - a) / np.linalg.norm(b - a)
    e2v = _default_e2(e1) if e2 is None else vector(e2, "e2", "geometry.straight")
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    x = a + s * (b - a)
    return _poses(x, np.broadcast_to(e1, x.shape), np.broadcast_to(e2v, x.shape).copy())


def arc(radius, angle, n_elements, origin=(0.0, 0.0, 0.0)):
    """Circular arc from ``origin`` with tangent ``+x``, turning towards ``+y`` about ``+z``.

    Centre ``origin + (0, radius, 0)``; ``e2`` points to the centre, ``e3 = +z``.
    A negative ``angle`` turns towards ``-y`` (centre ``origin - (0, radius, 0)``,
    ``e3 = -z``), so ``e1`` always runs along the node order.
    """
    n = _check_n(n_elements, "arc")
    radius = real(radius, "radius", "geometry.arc", above=0.0)
    angle = real(angle, "angle", "geometry.arc")
    if angle == 0:
        raise InputError(f"geometry.arc: angle must be finite and non-zero, got {angle!r}")
    _check_turn(abs(angle) / n, n, "arc")
    origin = _finite_points([origin], "arc")[0]
    sg = np.sign(angle)
    phi = np.linspace(0.0, abs(angle), n + 1)
    c, s = np.cos(phi), np.sin(phi)
    x = np.stack([radius * s, sg * radius * (1.0 - c), np.zeros_like(phi)], axis=-1) + origin
    e1 = np.stack([c, sg * s, np.zeros_like(phi)], axis=-1)
    e2 = np.stack([-s, sg * c, np.zeros_like(phi)], axis=-1)
    return _poses(x, e1, e2)


def helix(radius, pitch, length, n_elements, phase=0.0, z0=0.0):
    """Helix about ``e_z``: ``x = (r cos(th + phase), r sin(th + phase), z)``, ``th = 2 pi z / pitch``.

    ``pitch > 0`` is right-handed, ``pitch < 0`` left-handed; ``z`` runs from
    ``z0`` to ``z0 + length``.  ``e2`` is the principal normal (towards the
    axis), so every element has the same constant reference strain.
    """
    n = _check_n(n_elements, "helix")
    radius = real(radius, "radius", "geometry.helix", above=0.0)
    length = real(length, "length", "geometry.helix", above=0.0)
    pitch = real(pitch, "pitch", "geometry.helix")
    phase = real(phase, "phase", "geometry.helix")
    z0 = real(z0, "z0", "geometry.helix")
    if pitch == 0:
        raise InputError(f"geometry.helix: pitch must be finite and non-zero, got {pitch!r}")
    # the frames turn about the Darboux vector by 2 pi per turn of the helix
    _check_turn(2.0 * np.pi * length / abs(pitch) / n, n, "helix")
    z = z0 + np.linspace(0.0, length, n + 1)
    k = 2.0 * np.pi / pitch
    th = k * (z - z0) + phase
    c, s = np.cos(th), np.sin(th)
    x = np.stack([radius * c, radius * s, z], axis=-1)
    e1 = np.stack([-radius * k * s, radius * k * c, np.ones_like(z)], axis=-1)
    e2 = np.stack([-c, -s, np.zeros_like(z)], axis=-1)
    return _poses(x, e1, e2)


def double_helix(strand_radius, strand_pitch, radius, pitch, length, n_elements, phase=0.0, strand_phase=0.0):
    """A wire of a strand laid in a rope: a helix of ``radius`` about a helical strand centre line.

    The strand's centre line ``C(th) = R (cos(th + strand_phase), sin(th + strand_phase), 0) + (0, 0, c th)``,
    ``R = strand_radius``, ``c = strand_pitch / (2 pi)``; the wire
    ``x = C + radius (cos(phi) N + sin(phi) B)``, ``phi = phase + 2 pi s / pitch`` with ``N`` the
    principal normal of ``C`` (towards the axis), ``B = T x N`` and ``s`` the arc length along ``C``
    (Costello 1997, ch. 4).  Pitches are signed (> 0: right hand).  Nodes at uniform heights ``z``
    of the wire itself from 0 to ``length``, exact tangents as ``e1``, ``e2`` parallel-transported.
    """
    n = _check_n(n_elements, "double_helix")
    for name, v in (("strand_radius", strand_radius), ("radius", radius), ("length", length)):
        real(v, name, "geometry.double_helix", above=0.0)
    for name, v in (("strand_pitch", strand_pitch), ("pitch", pitch)):
        if real(v, name, "geometry.double_helix") == 0.0:
            raise InputError(f"geometry.double_helix: {name} must be finite and non-zero, got {v!r}")
    L = np.hypot(strand_radius, strand_pitch / (2.0 * np.pi))
    _check_turn(2.0 * np.pi * (length / abs(strand_pitch) + length * L / abs(strand_pitch * pitch) * 2.0 * np.pi) / n,
                n, "double_helix")
    z = np.linspace(0.0, length, n + 1)
    x, t = double_helix_points(strand_radius, strand_pitch / (2.0 * np.pi), radius, phase,
                               2.0 * np.pi / pitch, z)
    c, s = np.cos(strand_phase), np.sin(strand_phase)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return frames_from_tangents(x @ rot.T, t @ rot.T)


def double_helix_points(R, c, r, phase, s_rate, z, iterations=8):
    """Points ``(len(z), 3)`` and unit tangents of ``double_helix`` (strand radius ``R``, axial advance
    ``c`` per radian, signed; wire radius ``r``; ``phi = phase + s_rate s``; strand phase 0) at the
    points whose own height is ``z``: the strand parameter ``th`` solved from ``x_z(th) = z`` by Newton
    from ``th = z / c`` (``|dx_z / dth| >= |c| - r |s_rate| L R / L``, > 0 for any strand whose wires
    advance along it)."""
    z = np.asarray(z, dtype=float)
    th = z / c
    for _ in range(iterations):
        x, dx = _double_helix(R, c, r, phase, s_rate, th)
        th = th - (x[:, 2] - z) / dx[:, 2]
    x, dx = _double_helix(R, c, r, phase, s_rate, th)
    x[:, 2] = z                                      # converged to round-off: the exact heights
    return x, dx / np.linalg.norm(dx, axis=1, keepdims=True)


def _double_helix(R, c, r, phase, s_rate, th):
    """Points of the double helix and their ``d / dth`` at strand parameters ``th``."""
    L = np.hypot(R, c)
    ct, st = np.cos(th), np.sin(th)
    zero = np.zeros_like(th)
    C = np.stack([R * ct, R * st, c * th], axis=-1)
    N = np.stack([-ct, -st, zero], axis=-1)
    B = np.stack([c * st, -c * ct, np.full_like(th, R)], axis=-1) / L
    phi = phase + s_rate * L * th                       # s = L th
    cp, sp = np.cos(phi)[:, None], np.sin(phi)[:, None]
    x = C + r * (cp * N + sp * B)
    dC = np.stack([-R * st, R * ct, np.full_like(th, c)], axis=-1)
    dN = np.stack([st, -ct, zero], axis=-1)
    dB = np.stack([c * ct, c * st, zero], axis=-1) / L
    return x, dC + r * (s_rate * L * (-sp * N + cp * B) + cp * dN + sp * dB)


def _rotation_between(a, b):
    """Minimal rotation taking unit ``a`` to unit ``b``."""
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if c <= -1.0 + _PARALLEL_TOL:
        raise InputError("geometry.polyline: the centre line reverses direction between two points")
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def frames_from_tangents(x, t, e2=None):
    """Poses at points ``x`` with tangents ``t``; ``e2`` parallel-transported from the first."""
    t = _unit(t, "tangent")
    e2_0 = _default_e2(t[0]) if e2 is None else vector(e2, "e2", "geometry")
    e2_0 = e2_0 - np.dot(e2_0, t[0]) * t[0]
    e2s = np.zeros_like(t)
    e2s[0] = _unit(e2_0, "e2 (parallel to the first tangent?)")
    for i in range(1, len(t)):
        e2s[i] = _rotation_between(t[i - 1], t[i]) @ e2s[i - 1]
    return _poses(x, t, e2s)


def polyline(points, n_elements=None, e2=None):
    """Beam through ``points`` (n, 3).

    With ``n_elements`` the polyline is first resampled uniformly along its
    length.  Node tangents are those of the circle through each point and its
    two neighbours (exact for points on an arc); ``e2`` is parallel-transported.
    """
    p = _finite_points(points, "polyline")
    if len(p) < 2:
        raise InputError(f"geometry.polyline: need at least 2 points, got {len(p)}")
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if np.any(seg <= 0.0):
        i = int(np.argmin(seg))
        raise InputError(f"geometry.polyline: points {i} and {i + 1} coincide at {p[i].tolist()}")
    if n_elements is not None:
        n = _check_n(n_elements, "polyline")
        s = np.concatenate([[0.0], np.cumsum(seg)])
        snew = np.linspace(0.0, s[-1], n + 1)
        p = np.stack([np.interp(snew, s, p[:, k]) for k in range(3)], axis=-1)
    if len(p) == 2:
        t = np.repeat((p[1:] - p[:1]), 2, axis=0)
        return frames_from_tangents(p, t, e2)
    a = p[1:-1] - p[:-2]
    b = p[2:] - p[1:-1]
    ia, ib = 1.0 / np.sum(a * a, axis=1, keepdims=True), 1.0 / np.sum(b * b, axis=1, keepdims=True)
    tm = a * ia + b * ib
    nt = np.linalg.norm(tm, axis=1)
    rev = np.flatnonzero(nt <= 1e-12 * np.sqrt(np.maximum(ia, ib))[:, 0])
    if len(rev):
        i = int(rev[0]) + 1
        raise InputError(f"geometry.polyline: element {i - 1} (points {i - 1} to {i}) turns by {np.pi:.3f} rad "
                         f"(limit 0.75 pi = {MAX_REFERENCE_ELEMENT_ROTATION:.3f} rad): the centre line reverses at point {i}")
    tm = tm / nt[:, None]
    c0 = _unit(p[1] - p[0])
    t0 = 2.0 * np.dot(tm[0], c0) * c0 - tm[0]
    c1 = _unit(p[-1] - p[-2])
    t1 = 2.0 * np.dot(tm[-1], c1) * c1 - tm[-1]
    t = np.concatenate([t0[None], tm, t1[None]])
    _check_fold(p, t)
    return frames_from_tangents(p, t, e2)


def _check_fold(p, t):
    """Refuse a polyline whose node tangent leaves a chord by more than half the element limit:
    the element between them would turn by more than ``MAX_REFERENCE_ELEMENT_ROTATION`` (or fold back,
    ``e1`` against the chord)."""
    c = np.diff(p, axis=0)
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    ang = np.arccos(np.clip(np.stack([np.sum(t[:-1] * c, axis=1), np.sum(t[1:] * c, axis=1)]), -1.0, 1.0))
    turn = 2.0 * ang.max(axis=0)
    bad = np.flatnonzero(turn > MAX_REFERENCE_ELEMENT_ROTATION)
    if len(bad):
        i = int(bad[0])
        raise InputError(f"geometry.polyline: element {i} (points {i} to {i + 1}) turns by {turn[i]:.3f} rad "
                         f"(limit 0.75 pi = {MAX_REFERENCE_ELEMENT_ROTATION:.3f} rad): the centre line folds back or "
                         "turns too sharply there; round the corner with more points")
