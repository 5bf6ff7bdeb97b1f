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
