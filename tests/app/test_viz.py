"""Pictures (optional [viz] extra): skipped cleanly when pyvista / matplotlib are missing."""
import struct

import numpy as np
import pytest

import beamsolver as bs


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


@pytest.fixture(scope="module")
def roll_up():
    L, EI = 10.0, 1e2
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.2)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), 4), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, 2 * np.pi * EI / L), follower=True)
    return bs.solve(m, steps=2), b


@pytest.mark.slow
def test_core_never_imports_pictures():
    import subprocess
    import sys
    code = ("import sys, beamsolver as bs; bs.Model(); "
            "print(any(m.split('.')[0] in ('pyvista', 'vtk', 'matplotlib', 'meshio') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_render_png_of_requested_size(tmp_path, roll_up):
    pytest.importorskip("pyvista")
    from beamsolver import viz
    sol, _ = roll_up
    path = tmp_path / "roll.png"
    img = viz.render(sol, path=path, color_by="M3", window_size=(320, 240))
    assert png_size(path) == (320, 240) and path.stat().st_size > 1000
    assert img.shape == (240, 320, 3)
    assert (img != img[0, 0]).any(axis=-1).mean() > 0.02        # something besides background is drawn
    with pytest.raises(ValueError, match="color_by"):
        viz.render(sol, color_by="nonsense", window_size=(50, 50))


def test_plot_history_png(tmp_path, roll_up):
    pytest.importorskip("matplotlib")
    from beamsolver import viz
    sol, b = roll_up
    fig = viz.plot_history(sol, "reaction", node=b.first, component="mz", path=tmp_path / "h.png")
    w, h = png_size(tmp_path / "h.png")                  # 6 x 4 in at 100 dpi, cropped to the drawing
    assert 300 < w <= 600 and 200 < h <= 400
    line = fig.axes[0].lines[0]
    np.testing.assert_allclose(line.get_xdata(), sol.times)
    np.testing.assert_allclose(line.get_ydata(), [sol.reaction(b.first, k)[5] for k in range(3)])
    fig = viz.plot_history(sol, ["iterations", lambda s, k: s.position(b.last, k)[1]])
    assert [len(a.lines) for a in fig.axes] == [1, 1]           # a count and a length: one axis each


def test_render_by_utilisation_with_a_stretched_axis(roll_up):
    """The material-range field colours the tubes; ``scale`` squeezes the drawing along one axis
    (the roll-up is a circle in the x-y plane: squeezed along y by 10, its drawn height over its
    width drops from about 1 to below 0.3)."""
    pytest.importorskip("pyvista")
    from beamsolver import viz
    sol, _ = roll_up
    img = viz.render(sol, color_by="utilisation", window_size=(160, 160))
    assert (img != 255).any(axis=-1).mean() > 0.02

    def aspect(im):
        drawn = (im != 255).any(axis=-1)
        rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
        return np.ptp(rows) / np.ptp(cols)
    kw = dict(color_by=None, window_size=(200, 200), view="xy", contacts=False)
    assert aspect(viz.render(sol, **kw)) > 0.8
    assert aspect(viz.render(sol, scale=(1, 0.1, 1), **kw)) < 0.3
    with pytest.raises(ValueError, match="scale"):
        viz.render(sol, scale=(1, 0, 1), **kw)


def _bar_and_beams(sol, step, **kw):
    """The colour bar's rectangle and the drawn meshes' bounds, in viewport coordinates, as ``render`` draws."""
    from beamsolver.app import viz
    args = dict(path=None, color_by="displacement", component=None, window_size=(800, 600), refine=8, n_sides=24,
                view="auto", zoom=1.0, contacts=True, cmap="viridis", background="white", show_edges=False,
                scale=None)
    args.update(kw)
    plotter = viz._plotter(sol, step, **args)
    try:
        bars = list(plotter.scalar_bars.values())
        assert len(bars) == 1
        x0, y0 = bars[0].GetPositionCoordinate().GetValue()[:2]
        w, h = bars[0].GetPosition2Coordinate().GetValue()[:2]
        return (x0, y0, x0 + w, y0 + h), viz.viewport_bounds(plotter, viz.drawn_points(plotter))
    finally:
        plotter.close()


def _apart(a, b):
    return a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]


@pytest.mark.parametrize("scene", ["upright pair", "long cantilever"])
def test_colour_bar_leaves_the_beams_free(scene):
    """``render``'s colour bar does not cover the beams (issue 29: a horizontal bar at the bottom covered the
    main job's upright wires at step 0; a bar at the right must not cover a long beam drawn across the window):
    the bar's rectangle and the drawn tubes' screen bounds do not overlap, and the beams stay inside the window."""
    pytest.importorskip("pyvista")
    m = bs.Model()
    if scene == "upright pair":                   # the main job's wires at step 0, without the contact
        sec = bs.Section.circular(radius=0.5e-3, E=200e9, nu=0.3)
        for x in (0.5e-3, -0.5e-3):
            b = m.add_beam(bs.geometry.straight((x, 0, 0), (x, 0, 1.0), 8), sec)
            m.clamp(b.first)
            m.add_load(b.last, force=(0, 0, 100.0))
    else:
        sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.2)
        b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), 4), sec)
        m.clamp(b.first)
        m.add_load(b.last, force=(0, 0, -0.1))
    sol = bs.solve(m, steps=1, verbose=False)
    for step in (0, 1):
        for view in ("auto", "iso", "xz"):
            bar, beams = _bar_and_beams(sol, step, view=view)
            assert _apart(bar, beams), (step, view, bar, beams)
            assert 0.0 <= beams[0] and beams[2] <= 1.0 and 0.0 <= beams[1] and beams[3] <= 1.0, (step, view, beams)
            assert beams[3] - beams[1] > 0.5 or beams[2] - beams[0] > 0.5, "the drawing was shrunk too far"
