"""``beamsolver paraview OUT``: a ParaView script that shows an output folder in one step,
run in real ParaView (``pvbatch``, Debian's ``paraview`` package, installed by .ci/run)."""
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.io.paraview import paraview_script, screenshot


def _two_wires(folder):
    """Two touching wires pressed together: beams.pvd and contact.pvd with active points."""
    m = bs.Model()
    sec = bs.Section.circular(radius=1e-3, E=2e9, nu=0.3)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, 0.05), 8), sec)
    b = m.add_beam(bs.geometry.straight((2e-3, 0, 0), (2e-3, 0, 0.05), 8), sec)
    for beam in (a, b):
        m.clamp(beam.first)
        m.clamp(beam.last)
    m.add_load(a.nodes[4], force=(2.0, 0, 0))
    m.add_contact(a, b, mu=0.3)
    return bs.solve(m, steps=2, output=str(folder), verbose=False)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("pv") / "out"
    sol = _two_wires(out)
    assert sol.converged and len(sol.contact(-1)) > 0
    return out


def test_the_script_is_written_next_to_the_files(folder):
    script = paraview_script(folder)
    assert script == folder / "view.py"
    text = script.read_text()
    compile(text, str(script), "exec")
    for name in ("beams.pvd", "contact.pvd", "Tube", "TriangleStrips", "radius", "stick"):
        assert name in text


def test_bad_arguments_are_named(tmp_path, folder):
    with pytest.raises(bs.InputError, match="beams.pvd"):
        paraview_script(tmp_path)
    with pytest.raises(bs.InputError, match="color_by"):
        paraview_script(folder, color_by="moment")
    with pytest.raises(bs.InputError, match="size"):
        paraview_script(folder, size=(0, 10))


def test_cli_without_pvbatch_says_how_to_get_it(folder, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(bs.InputError, match="apt-get install paraview"):
        screenshot(folder / "view.py", folder / "x.png")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("pvbatch") is None, reason="ParaView's pvbatch not installed (.ci/run installs it)")
def test_real_paraview_draws_tubes_and_contact_points(folder, tmp_path):
    """Also with the vtk wheel's EGL window asked for (``viz`` sets it in-process): Debian's
    ParaView has no EGL and aborted with it."""
    png = tmp_path / "shot.png"         # kept by pytest's tmp_path for a look
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "paraview", str(folder), "--screenshot", str(png),
                          "--color-by", "M2"], capture_output=True, text=True, timeout=600, env=env)
    assert out.returncode == 0, out.stderr
    assert "view.py" in out.stdout and png.is_file()
    import matplotlib.image
    img = matplotlib.image.imread(str(png))[..., :3]
    assert img.shape[:2] == (800, 1200)
    background = img[5, img.shape[1] // 2]
    drawn = np.any(np.abs(img - background) > 0.05, axis=-1)
    assert 0.01 < drawn.mean() < 0.6                    # something drawn, not everything
    # contact spheres are drawn in the stick/slip colours (green, yellow), which the tubes'
    # blue-grey-red map never gives
    green = (img[..., 1] > 0.35) & (img[..., 0] < 0.25) & (img[..., 2] < 0.25)
    yellow = (img[..., 0] > 0.8) & (img[..., 1] > 0.6) & (img[..., 2] < 0.3)
    assert green.sum() + yellow.sum() > 20
