"""Pictures of a ``Solution``: beams as tubes (pyvista) and curves over pseudo-time (matplotlib).

Optional: ``pip install "beamsolver[viz]"`` (pyvista, which brings the vtk
wheel, and matplotlib).  Nothing in beamsolver imports this module; it
imports pyvista/matplotlib only inside the functions.

Headless machines: ``render`` draws off-screen.  The vtk wheel renders
through EGL when the system has ``libEGL`` and Mesa (Debian:
``libegl1 libegl-mesa0 libgl1-mesa-dri``, usually present); we select
``vtkEGLRenderWindow`` when no ``DISPLAY`` is set, which avoids X entirely.
Fallbacks: Debian ``libosmesa6`` (then set ``VTK_DEFAULT_OPENGL_WINDOW=
vtkOSOpenGLRenderWindow``), or run under ``xvfb-run``.
"""
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.lines import FORCE_NAMES, LineLayout

__all__ = ["render", "plot_history", "FIELDS"]

CELL_FIELDS = FORCE_NAMES + ("strain", "equivalent_strain", "utilisation")
FIELDS = ("displacement", "beam_id", "radius") + CELL_FIELDS


def _pyvista():
    if not os.environ.get("DISPLAY") and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ:
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    try:
        import pyvista
    except ImportError as e:
        raise ImportError("beamsolver.viz.render needs pyvista: pip install 'beamsolver[viz]'") from e
    return pyvista


def _folder_for(path, owner):
    """Create the folder of the image file ``path`` (``InputError`` naming it if that fails)."""
    if path is None:
        return None
    parent = Path(path).parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(f"{owner}: cannot create the folder of path {str(path)!r} "
                         f"({e.strerror or e})") from None
    return path


def _lines(pv, solution, step, refine):
    """Poly-lines (one per beam) with point data; cell (element) fields averaged onto points."""
    lay = LineLayout(solution.description, refine)
    rec = solution.step(step)
    pdata, points = lay.point_data(rec.poses)
    cdata = lay.cell_data(rec.section_forces, rec.strains)
    # segment values onto points: mean of the (one or two) segments meeting at a point
    acc, cnt = {}, np.zeros(lay.n_points)
    np.add.at(cnt, lay.segments.ravel(), 1.0)
    for name in CELL_FIELDS:
        v = cdata[name]
        a = np.zeros((lay.n_points,) + v.shape[1:])
        np.add.at(a, lay.segments[:, 0], v)
        np.add.at(a, lay.segments[:, 1], v)
        acc[name] = a / np.maximum(cnt, 1.0).reshape((-1,) + (1,) * (v.ndim - 1))
    # chains of segments -> one poly-line per beam
    beam = pdata["beam_id"]
    cells = []
    for b in np.unique(beam):
        ids = np.flatnonzero(beam == b)
        cells.append(np.concatenate([[len(ids)], ids]))
    poly = pv.PolyData(points, lines=np.concatenate(cells) if cells else None)
    for k, v in {**pdata, **acc}.items():
        poly.point_data[k] = v
    return poly


def _scalars(poly, color_by, component):
    if color_by is None:
        return None, None
    if color_by not in poly.point_data:
        raise ValueError(f"render: unknown color_by {color_by!r}; choose from {FIELDS}")
    v = np.asarray(poly.point_data[color_by])
    title = color_by
    if v.ndim == 2:
        if component is None:
            v = np.linalg.norm(v, axis=1)
            title = f"|{color_by}|"
        else:
            v = v[:, int(component)]
            title = f"{color_by}[{int(component)}]"
    poly.point_data["_color"] = v
    return "_color", title


# the colour bar: vertical, at the right, in viewport coordinates (x0, y0, x1, y1); the drawing is fitted into
# the part of the window left of it (``_fit``), so the bar never covers the beams
BAR_BOX = (0.86, 0.1, 0.98, 0.9)
SCENE_BOX = (0.02, 0.02, 0.84, 0.98)


def render(solution, step=-1, path=None, color_by="displacement", component=None,
           window_size=(800, 600), refine=8, n_sides=24, view="auto", zoom=1.0, contacts=True,
           cmap="viridis", background="white", show_edges=False, scale=None):
    """Draw the beams of ``step`` as tubes of their section radii; returns the image ``(h, w, 3)``.

    ``step``: a step index or a list of them (drawn together, one colour
    scale).  ``path``: PNG file to write (optional).  ``color_by``: a point
    field (``displacement``, ``radius``, ``beam_id``), an element field
    averaged onto points (``N, Q2, Q3, T, M2, M3``, ``strain``) or ``None``;
    vectors are drawn by magnitude unless ``component`` is given.  ``view``:
    ``"auto"`` (looks along the normal of a flat scene, else isometric),
    ``"xy"``, ``"xz"``, ``"yz"`` or ``"iso"``; ``zoom`` > 1 magnifies.
    ``contacts``: draw the active contact points as red spheres.  ``scale``: factors
    ``(sx, sy, sz)`` stretching the drawing along x, y, z (e.g. ``(1, 1, 0.04)`` to see the lay of a
    long thin cable; say so in the caption), default none.  The colour bar stands at the right
    (``BAR_BOX``), the beams are drawn left of it (``SCENE_BOX``).
    """
    plotter = _plotter(solution, step, path, color_by, component, window_size, refine, n_sides, view, zoom,
                       contacts, cmap, background, show_edges, scale)
    img = plotter.screenshot(str(path) if path is not None else None, return_img=True)
    plotter.close()
    return img


def _plotter(solution, step, path, color_by, component, window_size, refine, n_sides, view, zoom, contacts,
             cmap, background, show_edges, scale):
    """The off-screen plotter ``render`` takes its picture of (arguments of ``render``)."""
    _folder_for(path, "render")
    if scale is not None:
        scale = np.asarray(scale, dtype=float)
        if scale.shape != (3,) or not np.all(np.isfinite(scale) & (scale > 0)):
            raise ValueError(f"render: scale must be three positive numbers, got {scale.tolist()!r}")
    pv = _pyvista()
    n = len(solution)
    steps = [step] if np.ndim(step) == 0 else list(step)
    for k in steps:
        if int(k) != k or not -n <= k < n:
            raise ValueError(f"render: step {k} out of range (the solution has steps 0..{n - 1})")
    steps = [int(k) % n for k in steps]
    polys = [_lines(pv, solution, k, refine) for k in steps]
    scalars, title = zip(*[_scalars(p, color_by, component) for p in polys])
    scalars, title = scalars[0], title[0]
    w, h = (int(window_size[0]), int(window_size[1]))
    plotter = pv.Plotter(off_screen=True, window_size=(w, h))
    plotter.set_background(background)
    kw = dict(smooth_shading=True, show_edges=show_edges)
    if scalars is not None:
        v = np.concatenate([np.asarray(p.point_data[scalars]) for p in polys])
        lo, hi = float(v.min()), float(v.max())
        if hi - lo <= 1e-9 * max(abs(lo), abs(hi)):       # a constant field: avoid a round-off colour bar
            pad = max(1e-3 * abs(hi), 1e-300)
            lo, hi = lo - pad, hi + pad
        kw.update(scalars=scalars, cmap=cmap, clim=(lo, hi))
    for j, (k, poly) in enumerate(zip(steps, polys)):
        tubes = poly.tube(scalars="radius", absolute=True, n_sides=n_sides, capping=True)
        if scale is not None:
            tubes.points = tubes.points * scale
        if scalars is None:
            plotter.add_mesh(tubes, color="lightsteelblue", **kw)
        else:
            plotter.add_mesh(tubes, show_scalar_bar=j == 0,
                             scalar_bar_args=dict(title=title, color="black", vertical=True, n_labels=3,
                                                  fmt="%.3g", label_font_size=14, title_font_size=16,
                                                  position_x=BAR_BOX[0], position_y=BAR_BOX[1],
                                                  width=BAR_BOX[2] - BAR_BOX[0], height=BAR_BOX[3] - BAR_BOX[1]),
                             **kw)
        table = solution.contacts[k] if contacts else {}
        active = np.asarray(table.get("normal_force", np.zeros(0))) > 0
        if active.any():
            pts = pv.PolyData(np.asarray(table["position"])[active] * (1.0 if scale is None else scale))
            r = float(np.min(solution.description["beam_radius"]))
            plotter.add_mesh(pts.glyph(geom=pv.Sphere(radius=r), scale=False, orient=False), color="red")
    _set_view(plotter, np.concatenate([p.points for p in polys]) * (1.0 if scale is None else scale), view)
    if scalars is not None:
        _fit(plotter, drawn_points(plotter), SCENE_BOX)
    if zoom != 1.0:
        plotter.camera.zoom(zoom)
    return plotter


def drawn_points(plotter):
    """World coordinates ``(n, 3)`` of the points of every mesh drawn (tubes, contact glyphs)."""
    meshes = [getattr(a, "mapper", None) for a in plotter.renderer.actors.values()]
    return np.concatenate([np.asarray(m.dataset.points) for m in meshes if m is not None and m.dataset is not None])


def viewport_bounds(plotter, points):
    """``(x0, y0, x1, y1)``: the bounds of world ``points`` ``(n, 3)`` as the plotter's camera projects
    them, in viewport coordinates (0..1 across the window)."""
    w, h = plotter.window_size
    M = np.array([[plotter.camera.GetCompositeProjectionTransformMatrix(w / h, -1, 1).GetElement(i, j)
                   for j in range(4)] for i in range(4)])
    q = np.c_[points, np.ones(len(points))] @ M.T
    ndc = q[:, :2] / q[:, 3:]
    (x0, y0), (x1, y1) = ndc.min(axis=0), ndc.max(axis=0)
    return 0.5 * (x0 + 1), 0.5 * (y0 + 1), 0.5 * (x1 + 1), 0.5 * (y1 + 1)


def _fit(plotter, points, box):
    """Zoom the camera out (never in) and shift the picture so that ``points`` fall into ``box``
    ``(x0, y0, x1, y1)`` of the viewport."""
    x0, y0, x1, y1 = viewport_bounds(plotter, points)
    s = min(1.0, (box[2] - box[0]) / max(x1 - x0, 1e-12), (box[3] - box[1]) / max(y1 - y0, 1e-12))
    plotter.camera.zoom(s)
    x0, y0, x1, y1 = viewport_bounds(plotter, points)
    cx, cy = plotter.camera.GetWindowCenter()
    # the window centre is in -1..1 coordinates; the picture moves opposite to it
    plotter.camera.SetWindowCenter(cx + (x0 + x1) - (box[0] + box[2]), cy + (y0 + y1) - (box[1] + box[3]))


def _set_view(plotter, points, view):
    if view == "auto":
        ext = np.ptp(points, axis=0) if len(points) else np.ones(3)
        flat = np.flatnonzero(ext <= 1e-3 * ext.max())
        view = {2: "xy", 1: "xz", 0: "yz"}.get(int(flat[0]), "iso") if len(flat) == 1 else "iso"
    if view == "xy":
        plotter.view_xy()
    elif view == "xz":
        plotter.view_xz()
    elif view == "yz":
        plotter.view_yz()
    elif view == "iso":
        plotter.view_isometric()
    else:
        raise ValueError(f"render: view must be 'auto', 'xy', 'xz', 'yz' or 'iso', got {view!r}")
    plotter.reset_camera()


_COMPONENTS = {"x": 0, "y": 1, "z": 2, "fx": 0, "fy": 1, "fz": 2, "mx": 3, "my": 4, "mz": 5}


def _series(solution, what, node, component):
    """Values over the steps, a label and the kind of unit (curves of one kind share an axis)."""
    n = len(solution)
    if callable(what):
        name = getattr(what, "__name__", "value")
        return np.array([float(what(solution, k)) for k in range(n)]), name, getattr(what, "unit", name)
    c = _COMPONENTS.get(component, component)
    if what in ("reaction", "position", "displacement"):
        if node is None:
            raise ValueError(f"plot_history: {what!r} needs node=")
        nn = solution.poses.shape[1]
        if isinstance(node, (bool, np.bool_)) or not isinstance(node, (int, np.integer)) or not 0 <= node < nn:
            raise InputError(f"plot_history: unknown node id {node!r} (nodes 0..{nn - 1})")
        if what == "reaction":
            v = np.array(solution.reactions[:, node])
            unit = "moment" if c is not None and int(c) >= 3 else "force"
        else:
            v = np.array(solution.poses[:, node, :3, 3])
            if what == "displacement":
                v = v - v[0]
            unit = "length"
        label = f"{what} {component if component is not None else '|.|'} at node {node}"
        return (np.linalg.norm(v[:, :3], axis=1) if c is None else v[:, int(c)]), label, unit
    if what == "iterations":
        return (np.array([s.get("iterations", 0) for s in solution.stats], dtype=float), "Newton iterations",
                "count")
    if what == "contact_force":
        force = [np.sum(t.get("normal_force", 0.0)) for t in solution.contacts]
        return np.array(force), "total normal contact force", "force"
    if what == "penetration":
        return np.array([max(-np.min(t["gap"], initial=0.0), 0.0) if "gap" in t else 0.0
                         for t in solution.contacts]), "largest penetration", "length"
    raise ValueError(f"plot_history: unknown quantity {what!r}; use 'reaction', 'position', 'displacement', "
                     "'iterations', 'contact_force', 'penetration' or a callable f(solution, step)")


def _unit_axes(ax, units):
    """One y axis per kind of unit: ``ax`` for the first, twin axes on the right for the others."""
    axes = {}
    for i, u in enumerate(dict.fromkeys(units)):
        if i == 0:
            axes[u] = ax
            continue
        twin = ax.twinx()
        if i > 1:
            twin.spines["right"].set_position(("axes", 1.0 + 0.18 * (i - 1)))
        axes[u] = twin
    return axes


def plot_history(solution, what="reaction", node=None, component=None, path=None, ax=None,
                 marker="o", label=None, **plot_kw):
    """Plot a quantity against pseudo-time; returns the matplotlib ``Figure``.

    ``what``: ``"reaction"`` (``component`` ``fx fy fz mx my mz`` or 0..5),
    ``"position"``/``"displacement"`` (``x y z``), ``"iterations"``,
    ``"contact_force"``, ``"penetration"``, a callable ``f(solution, step)``,
    or a list of these (one curve each, same ``node``/``component``; curves of
    one kind of unit -- force, moment, length, count, or each callable (its
    ``unit`` attribute, else its name) -- share a y axis, the others get twin
    axes on the right: ``fig.axes``).
    ``path``: image file to write.  Without ``ax`` a new ``Figure`` is made
    on matplotlib's Agg canvas (no pyplot, no display needed).
    """
    try:
        from matplotlib.figure import Figure
    except ImportError as e:
        raise ImportError("beamsolver.viz.plot_history needs matplotlib: pip install 'beamsolver[viz]'") from e
    if ax is None:
        fig = Figure(figsize=(6, 4))      # Agg canvas, no pyplot state, no display needed
        ax = fig.subplots()
    else:
        fig = ax.figure
    t = np.array(solution.times)
    whats = what if isinstance(what, (list, tuple)) else [what]
    curves = [_series(solution, w, node, component) for w in whats]
    axes = _unit_axes(ax, [u for _, _, u in curves])
    lines = []
    for i, (y, lab, unit) in enumerate(curves):
        kw = dict(plot_kw) if "color" in plot_kw else dict(plot_kw, color=f"C{i}")
        lines += axes[unit].plot(t, y, marker=marker, label=label or lab, **kw)
    ax.set_xlabel("pseudo-time t")
    for unit, a in axes.items():
        labs = [lab for _, lab, u in curves if u == unit]
        a.set_ylabel(label or (labs[0] if len(labs) == 1 else f"{unit}: " + ", ".join(labs)))
    if len(whats) > 1:
        ax.legend(lines, [ln.get_label() for ln in lines])
    ax.grid(True, alpha=0.3)
    if _folder_for(path, "plot_history") is not None:
        fig.savefig(path, dpi=100, bbox_inches="tight")
    return fig
