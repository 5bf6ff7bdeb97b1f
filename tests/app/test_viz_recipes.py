"""Pictures a new user makes (issue 17): smooth tubes from the VTU files, one y axis per unit."""
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs

import crossing_beams
import twisted_pair_extreme as twisted_pair

SIDES = 12


@pytest.fixture(scope="module")
def pair_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("pair")
    model, plate, beams = twisted_pair.build(n_elements=4, turns=2.0)
    return bs.solve(model, steps=2, t_end=0.125, output=out), out


def test_guide_pyvista_recipe_runs_as_written_without_warnings(pair_run):
    """The one-line pyvista recipe of docs/guide/output.md, taken from the page: no warning (pyvista 0.49
    raised a PyVistaFutureWarning on ``extract_surface()`` without ``algorithm``), one tube per beam."""
    pv = pytest.importorskip("pyvista")
    import re
    import warnings
    page = (Path(__file__).resolve().parents[2] / "docs" / "guide" / "output.md").read_text()
    recipe = re.search(r"\(pyvista: `(grid\.[^`]*)`", page).group(1)
    recipe = re.sub(r"\s*\n\s*", "", recipe)
    grid = pv.read(pair_run[1] / "beams_0002.vtu")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tube = eval(recipe, {"grid": grid})
    assert tube.n_cells == 2 * (20 + 2)          # one capped tube per beam (pyvista's default 20 sides)


def _pieces(tube):
    """Separate capped tubes in a Tube filter output: each is SIDES side strips and 2 caps."""
    assert tube.n_cells % (SIDES + 2) == 0
    return tube.n_cells // (SIDES + 2)


def test_readme_tube_recipe_gives_one_capped_tube_per_beam(pair_run):
    """The user guide's ParaView chain (docs/guide/output.md), with pyvista's wrappers of the same VTK filters: Cell Data to
    Point Data, Extract Surface, Triangle Strips (vtkStripper: segments -> poly-lines), Tube."""
    pv = pytest.importorskip("pyvista")
    sol, out = pair_run
    grid = pv.read(out / "beams_0002.vtu")
    n_beams, n_segments = 2, grid.n_cells
    surface = grid.cell_data_to_point_data(pass_cell_data=True).extract_surface(algorithm="dataset_surface")
    plain = surface.tube(scalars="radius", absolute=True, n_sides=SIDES, capping=True)
    assert _pieces(plain) == n_segments          # the old recipe: a capped tube per segment (ribs)
    chains = surface.strip(max_length=100000)
    assert chains.n_lines == n_beams
    assert set(chains.point_data.keys()) >= {"radius", "displacement", "N", "T", "M3"}
    tube = chains.tube(scalars="radius", absolute=True, n_sides=SIDES, capping=True)
    assert _pieces(tube) == n_beams
    # the tube surrounds the centre line at the wire radius
    R = float(grid.point_data["radius"][0])
    d = np.min(np.linalg.norm(tube.points[:, None, :] - grid.points[None, :, :], axis=2), axis=1)
    assert np.all(d <= 1.01 * R) and np.median(d) > 0.9 * R
    img = pv.Plotter(off_screen=True, window_size=(160, 120))
    img.add_mesh(tube, scalars="T")
    shot = img.screenshot(return_img=True)
    img.close()
    assert (shot != shot[0, 0]).any(axis=-1).mean() > 0.01


def test_plot_history_one_axis_per_unit():
    pytest.importorskip("matplotlib")
    from beamsolver import viz
    model, slave, master = crossing_beams.build(load=50.0, n_elements=4)
    sol = bs.solve(model, steps=2)
    fig = viz.plot_history(sol, ["contact_force", "penetration"])
    force_ax, length_ax = fig.axes
    np.testing.assert_allclose(force_ax.lines[0].get_ydata(),
                               [np.sum(c.get("normal_force", 0.0)) for c in sol.contacts])
    pen = length_ax.lines[0].get_ydata()
    assert pen.max() > 0
    lo, hi = length_ax.get_ylim()
    assert hi - lo < 10 * pen.max()                      # on its own scale, not flat at 0 next to forces
    fig = viz.plot_history(sol, ["reaction", "contact_force"], node=0, component="fz")
    assert len(fig.axes) == 1 and len(fig.axes[0].lines) == 2     # two forces share one axis
    fig = viz.plot_history(sol, ["reaction", "iterations", "penetration"], node=0, component="mz")
    assert len(fig.axes) == 3
    assert len(fig.axes[0].get_legend().get_texts()) == 3
