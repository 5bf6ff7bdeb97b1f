"""Files a new user gets: permissions, re-runs into the same folder, readers, contact points, tubes."""
import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs

meshio = pytest.importorskip("meshio")

import crossing_beams
import twisted_pair_extreme as twisted_pair

L, EI = 10.0, 1e2


def roll_up(n_elements=4):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n_elements), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, 2 * np.pi * EI / L), follower=True)
    return m, b


def pair(n_elements=4):
    """The main job at a small size: some contact candidates carry no force after a 16th of a turn."""
    model, plate, beams = twisted_pair.build(n_elements=n_elements, turns=2.0)
    return model


def listed(pvd):
    return re.findall(r'file="([^"]+)"', Path(pvd).read_text())


@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def test_files_follow_the_umask(tmp_path, umask_022):
    sol = bs.solve(pair(), steps=1, t_end=0.0625, output=tmp_path, checkpoint=0)
    sol.save(tmp_path / "copy.npz")
    files = sorted(p for p in tmp_path.iterdir() if p.is_file())
    assert {p.suffix for p in files} == {".vtu", ".pvd", ".npz"}
    for p in files:
        assert stat.S_IMODE(p.stat().st_mode) == 0o644, p.name     # mkstemp alone gives 0600


def test_rerun_removes_the_previous_series_only(tmp_path):
    m, _ = roll_up()
    bs.solve(m, steps=6, output=tmp_path)
    mine = tmp_path / "beams_notes.txt"
    other = tmp_path / "beams_0005.vtu.bak"
    mine.write_text("user file")
    other.write_text("user file")
    bs.solve(m, steps=2, output=tmp_path)
    vtu = sorted(p.name for p in tmp_path.glob("*.vtu"))
    assert vtu == ["beams_0000.vtu", "beams_0001.vtu", "beams_0002.vtu"]
    assert listed(tmp_path / "beams.pvd") == vtu
    assert mine.exists() and other.exists()                        # never anything not ours
    # a contact run then a run without contact: no stale contact series or collection
    bs.solve(pair(), steps=2, t_end=0.125, output=tmp_path / "p")
    assert (tmp_path / "p" / "contact.pvd").exists()
    bs.solve(m, steps=1, output=tmp_path / "p")
    assert sorted(p.name for p in (tmp_path / "p").glob("*.vtu")) == ["beams_0000.vtu", "beams_0001.vtu"]
    assert not (tmp_path / "p" / "contact.pvd").exists()


def test_export_into_a_used_folder_removes_stale_steps(tmp_path):
    m, _ = roll_up()
    sol = bs.solve(m, steps=4, output=tmp_path)
    bs.io.write_vtk(sol, tmp_path, steps=[0, -1])
    assert sorted(p.name for p in tmp_path.glob("*.vtu")) == ["beams_0000.vtu", "beams_0004.vtu"]


def test_every_file_is_read_by_meshio_and_pyvista(tmp_path):
    pv = pytest.importorskip("pyvista")
    model, _, _ = crossing_beams.build(load=50.0, n_elements=4)
    sol = bs.solve(model, steps=2, output=tmp_path)
    assert len(sol.contact(0).get("gap", ())) == 0 and len(sol.contact(2)["gap"]) > 0   # step 0: no contact
    for vtu in sorted(tmp_path.glob("*.vtu")):
        mesh = meshio.read(vtu)
        grid = pv.read(vtu)
        assert grid.n_points == len(mesh.points), vtu.name
        if vtu.name.startswith("contact"):
            assert set(mesh.point_data) >= {"gap", "normal_force", "stick", "tangential_force"}
            assert set(grid.point_data.keys()) >= {"gap", "normal_force", "stick", "tangential_force"}
    empty = meshio.read(tmp_path / "contact_0000.vtu")
    assert empty.points.shape == (0, 3) and empty.point_data["tangential_force"].shape == (0, 3)
    for pvd in ("beams.pvd", "contact.pvd"):
        reader = pv.get_reader(tmp_path / pvd)
        assert [float(t) for t in reader.time_values] == sol.times.tolist()
        reader.set_active_time_value(reader.time_values[-1])
        assert reader.read()[0].n_points > 0
    assert bs.load(tmp_path).n_steps == 2


def test_contact_files_hold_the_active_points_only(tmp_path):
    sol = bs.solve(pair(), steps=1, t_end=0.0625, output=tmp_path)
    c = sol.contact(-1)
    active = c["normal_force"] > 0
    assert 0 < active.sum() < len(active)                 # the scene has open candidates
    mesh = meshio.read(tmp_path / "contact_0001.vtu")
    assert len(mesh.points) == active.sum()
    assert np.all(mesh.point_data["normal_force"] > 0)
    np.testing.assert_allclose(mesh.points, c["position"][active])
    np.testing.assert_allclose(mesh.point_data["gap"], c["gap"][active])
    np.testing.assert_allclose(mesh.point_data["tangential_force"], c["tangential_force"][active])
    np.testing.assert_array_equal(mesh.point_data["stick"], c["stick"][active].astype(int))


def test_vtu_strain_is_the_solution_strain_minus_the_reference(tmp_path):
    m, b = roll_up()
    sol = bs.solve(m, steps=1, output=tmp_path)
    eps0 = sol.description["eps0"]
    assert "reference included" in bs.Solution.__doc__ and "Solution.strains - eps0" in bs.io.vtk.__doc__
    np.testing.assert_allclose(sol.strains[0], eps0)                    # at rest: the reference strain
    mesh = meshio.read(tmp_path / "beams_0001.vtu")
    el = mesh.cell_data["element"][0]
    np.testing.assert_allclose(mesh.cell_data["strain"][0], (sol.strains[1] - eps0)[el])
    C = b.section.C
    np.testing.assert_allclose(sol.section_forces[1], (sol.strains[1] - eps0) @ C.T, rtol=1e-9, atol=1e-9)
