"""Twist and writhe of a ribbon: Calugareanu-White-Fuller ``Lk = Tw + Wr`` for two wires' centre lines
(docs/theory.md, section "Twist and writhe of a two-ply").

A ribbon is a curve ``x(s)`` (the axis: the midline of two wires) with a unit vector ``u(s)``
normal to the tangent ``t(s)`` (from one wire to the other).  All functions take polygons:
points ``(n, 3)``, batched over nothing (one curve at a time).

- ``twist``: ``Tw = (1 / 2 pi) int (t x u) . u' ds``, discretised exactly for the polygon's
  node frames: ``u_i`` is carried to node ``i + 1`` by the smallest rotation taking ``t_i``
  to ``t_(i+1)`` (parallel transport), and the signed angle from it to ``u_(i+1)`` about
  ``t_(i+1)`` is summed.
- ``writhe_closed``: the Gauss double integral of a closed polygon, exact for polygons
  (Klenin & Langowski 2000: the solid angle ``Omega_ij`` of every pair of segments,
  ``Wr = sum_(i != j) Omega_ij / 4 pi``).
- ``writhe_open``: an open curve whose two ends are clamped along the same axis ``e``
  (tangent ``e`` at both ends, as the twisted pair's clamp and plate), closed by
  straight half-lines along ``e`` from its ends (length ``extension`` times the curve's
  size) joined far away (``CLOSURE_WIDTH`` times that length to the side): the writhe of
  that closed polygon.  As the closure grows it tends to the writhe of the curve closed
  at infinity, for which ``Lk = Tw + Wr`` holds with ``Lk`` the number of turns of one
  end relative to the other (the closure carries no twist).
- ``writhe_fuller``: Fuller's formula relative to the straight curve along ``e``,
  ``Wr = (1 / 2 pi) int (e x t) . t' / (1 + e . t) ds``, valid only while the tangent never
  points along ``-e`` (refused, ``InputError``, when ``1 + e . t`` falls below
  ``FULLER_MIN``: a plectoneme's returning arm violates it).
"""
import numpy as np

from ..errors import InputError

__all__ = ["node_tangents", "ribbon", "twist", "writhe_closed", "linking", "writhe_open", "writhe_fuller",
           "CLOSURE_EXTENSION", "CLOSURE_WIDTH", "FULLER_MIN"]

CLOSURE_EXTENSION = 1e3    # length of the closing half-lines, in units of the curve's size
CLOSURE_WIDTH = 1.0        # distance of the far side of the closure, in units of the half-line length
FULLER_MIN = 1e-2          # smallest 1 + e . t accepted by Fuller's formula


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _polygon(points, name, owner, n=None, minimum=2):
    """``points`` as a finite float array ``(n, 3)`` (``n`` given: that many rows; else at least
    ``minimum``), else ``InputError`` naming ``owner``'s argument ``name``."""
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{owner}: {name} must be an array of numbers of shape (n, 3), got {points!r}") from None
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"{owner}: {name} must have shape (n, 3), got {p.shape}")
    if n is not None and len(p) != n:
        raise InputError(f"{owner}: {name} must have {n} rows (one per point of the polygon), got {len(p)}")
    if len(p) < minimum:
        raise InputError(f"{owner}: {name} needs at least {minimum} points, got {len(p)}")
    bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
    if len(bad):
        raise InputError(f"{owner}: {name} must be finite; row {int(bad[0])} is {p[bad[0]].tolist()}")
    return p


def _axis(axis, owner):
    """``axis`` as a unit 3-vector (finite, non-zero), else ``InputError``."""
    try:
        e = np.asarray(axis, dtype=float)
    except (TypeError, ValueError):
        e = None
    if e is None or e.shape != (3,) or not np.all(np.isfinite(e)) or not np.linalg.norm(e) > 0.0:
        raise InputError(f"{owner}: axis must be a finite, non-zero 3-vector, got {axis!r}")
    return e / np.linalg.norm(e)


def node_tangents(points):
    """Unit tangents at the nodes of a polygon ``(n, 3)``: the mean of the adjacent segments'
    directions (the end segments' at the ends)."""
    points = _polygon(points, "points", "node_tangents")
    seg = _unit(np.diff(points, axis=0))
    t = np.empty_like(points)
    t[0], t[-1] = seg[0], seg[-1]
    t[1:-1] = _unit(seg[:-1] + seg[1:])
    return t


def ribbon(x_a, x_b):
    """Axis (the midline) and ribbon vectors (from wire a to wire b) of two wires' centre lines
    sampled at the same arc lengths, ``(n, 3)`` each."""
    x_a = _polygon(x_a, "x_a", "ribbon", minimum=1)
    x_b = _polygon(x_b, "x_b", "ribbon", n=len(x_a))
    return 0.5 * (x_a + x_b), x_b - x_a


def _transport(u, t0, t1):
    """``u`` carried by the smallest rotation taking unit ``t0`` to unit ``t1`` (rows)."""
    c = np.einsum("ij,ij->i", t0, t1)
    k = np.cross(t0, t1)
    # Rodrigues with the axis k / |k| and angle acos(c): R u = c u + k x u + (k . u) k / (1 + c)
    return c[:, None] * u + np.cross(k, u) + (np.einsum("ij,ij->i", k, u) / (1.0 + c))[:, None] * k


def twist(axis, ribbon_vectors, tangents=None):
    """Twist ``Tw`` (turns) of the ribbon ``ribbon_vectors`` ``(n, 3)`` about the polygon ``axis``
    ``(n, 3)`` (node tangents ``tangents``, default ``node_tangents(axis)``)."""
    axis = _polygon(axis, "axis", "twist")
    ribbon_vectors = _polygon(ribbon_vectors, "ribbon_vectors", "twist", n=len(axis))
    t = node_tangents(axis) if tangents is None else _unit(_polygon(tangents, "tangents", "twist", n=len(axis)))
    u = ribbon_vectors - np.einsum("ij,ij->i", ribbon_vectors, t)[:, None] * t
    u = _unit(u)
    if np.any(np.einsum("ij,ij->i", t[:-1], t[1:]) <= -1.0 + 1e-12):
        raise InputError("twist: the axis tangent reverses between two nodes; refine the polygon")
    carried = _transport(u[:-1], t[:-1], t[1:])
    angle = np.arctan2(np.einsum("ij,ij->i", np.cross(carried, u[1:]), t[1:]),
                       np.einsum("ij,ij->i", carried, u[1:]))
    return float(angle.sum() / (2.0 * np.pi))


def _solid_angles(p1, p2, p3, p4):
    """Signed solid angles ``Omega`` ``(m,)`` of segment pairs ``p1 -> p2``, ``p3 -> p4`` (rows),
    Klenin & Langowski (2000) eq. 15; zero for coplanar pairs."""
    r13, r14, r23, r24 = p3 - p1, p4 - p1, p3 - p2, p4 - p2
    nrm = [np.cross(r13, r14), np.cross(r14, r24), np.cross(r24, r23), np.cross(r23, r13)]
    lens = [np.linalg.norm(v, axis=1) for v in nrm]
    ok = np.all([ln > 1e-300 for ln in lens], axis=0)
    nn = [v[ok] / ln[ok, None] for v, ln in zip(nrm, lens)]
    dot = lambda x, y: np.clip(np.einsum("ij,ij->i", x, y), -1.0, 1.0)   # noqa: E731
    omega = np.zeros(len(p1))
    omega[ok] = (np.arcsin(dot(nn[0], nn[1])) + np.arcsin(dot(nn[1], nn[2])) + np.arcsin(dot(nn[2], nn[3]))
                 + np.arcsin(dot(nn[3], nn[0])))
    omega[ok] *= np.sign(np.einsum("ij,ij->i", np.cross(p4[ok] - p3[ok], p2[ok] - p1[ok]), r13[ok]))
    return omega


def writhe_closed(points):
    """Writhe of the closed polygon through ``points`` ``(n, 3)`` (the last joined to the first)."""
    p = _polygon(points, "points", "writhe_closed", minimum=3)
    a, b = p, np.roll(p, -1, axis=0)          # segment i: a[i] -> b[i]
    n = len(p)
    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))         # the last and first segments are adjacent
    i, j = i[keep], j[keep]
    return float(2.0 * np.sum(_solid_angles(a[i], b[i], a[j], b[j])) / (4.0 * np.pi))


def linking(points_a, points_b):
    """Gauss linking number of two closed polygons ``(n, 3)``, ``(m, 3)`` (exact for polygons)."""
    a = _polygon(points_a, "points_a", "linking", minimum=3)
    b = _polygon(points_b, "points_b", "linking", minimum=3)
    i, j = np.meshgrid(np.arange(len(a)), np.arange(len(b)), indexing="ij")
    i, j = i.ravel(), j.ravel()
    return float(np.sum(_solid_angles(a[i], np.roll(a, -1, 0)[i], b[j], np.roll(b, -1, 0)[j])) / (4.0 * np.pi))


def _closure(points, e, extension):
    """The polygon ``points`` closed by half-lines along ``e`` from its ends, joined far away."""
    size = max(np.ptp(points, axis=0).max(), np.linalg.norm(points[-1] - points[0]))
    Z = extension * size
    side = np.cross(e, [1.0, 0.0, 0.0])
    if np.linalg.norm(side) < 0.5:
        side = np.cross(e, [0.0, 1.0, 0.0])
    side = _unit(side) * CLOSURE_WIDTH * Z
    top, bottom = points[-1] + Z * e, points[0] - Z * e
    return np.vstack([points, top, top + side, bottom + side, bottom])


def writhe_open(points, axis=(0.0, 0.0, 1.0), extension=CLOSURE_EXTENSION):
    """Writhe of an open polygon ``(n, 3)`` clamped along ``axis`` at both ends (start below,
    end above), closed by half-lines along ``axis`` (module docstring)."""
    e = _axis(axis, "writhe_open")
    p = _polygon(points, "points", "writhe_open")
    return writhe_closed(_closure(p, e, extension))


def writhe_fuller(points, axis=(0.0, 0.0, 1.0), tangents=None):
    """Fuller's writhe of an open polygon ``(n, 3)`` relative to the straight curve along ``axis``
    (tangent increments integrated segment by segment between node tangents)."""
    e = _axis(axis, "writhe_fuller")
    points = _polygon(points, "points", "writhe_fuller")
    t = node_tangents(points) if tangents is None else \
        _unit(_polygon(tangents, "tangents", "writhe_fuller", n=len(points)))
    low = 1.0 + t @ e
    if low.min() < FULLER_MIN:
        k = int(np.argmin(low))
        raise InputError(f"writhe_fuller: the tangent at node {k} points against the axis (1 + e.t = "
                         f"{low[k]:.3g} < {FULLER_MIN:g}): Fuller's formula does not hold; use writhe_open")
    # on each segment the tangent turns along the great circle from t_i to t_(i+1): integrate there
    g = np.linspace(0.0, 1.0, 9)[:, None, None]
    t0, t1 = t[:-1], t[1:]
    ang = np.arccos(np.clip(np.einsum("ij,ij->i", t0, t1), -1.0, 1.0))
    s = np.sin(ang)
    small = s < 1e-12
    s = np.where(small, 1.0, s)
    w0 = np.where(small, 1.0 - g[..., 0], np.sin((1.0 - g[..., 0]) * ang) / s)
    w1 = np.where(small, g[..., 0], np.sin(g[..., 0] * ang) / s)
    tg = w0[..., None] * t0 + w1[..., None] * t1                       # (9, m, 3) along the arc
    k = np.cross(t0, t1) / s[:, None]                                  # rotation axis of each arc
    dt = np.where(small[None, :, None], 0.0, np.cross(np.broadcast_to(k, tg.shape), tg) * ang[None, :, None])
    f = np.einsum("gij,gij->gi", np.cross(np.broadcast_to(e, tg.shape), tg), dt) / (1.0 + tg @ e)
    integral = (f[0] + f[-1]) / 16.0 + f[1:-1].sum(axis=0) / 8.0       # trapezoid rule over the arc
    return float(integral.sum() / (2.0 * np.pi))
