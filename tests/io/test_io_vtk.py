"""ParaView output: VTU/PVD read back, refined poly-lines on the exact circle, interrupted runs."""
import re
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs

meshio = pytest.importorskip("meshio")

import crossing_beams

L, EI = 10.0, 1e2


def roll_up(n_elements=4, turns=1.0):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n_elements), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, 2 * np.pi * turns * EI / L), follower=True)
    return m, b


def pvd_entries(path):
    text = Path(path).read_text()
    return [(float(t), f) for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)]


def test_roll_up_files_arrays_and_exact_circle(tmp_path):
    m, b = roll_up(4)
    sol = bs.solve(m, steps=4, output=tmp_path)
    entries = pvd_entries(tmp_path / "beams.pvd")
    assert [t for t, _ in entries] == sol.times.tolist()
    assert not list(tmp_path.glob(".*")), "temporary files left behind"
    assert not (tmp_path / "contact.pvd").exists()          # no contact declared: no contact files
    refine = 8
    n_pts, n_seg = 4 * refine + 1, 4 * refine
    for k, (t, name) in enumerate(entries):
        mesh = meshio.read(tmp_path / name)
        assert mesh.points.shape == (n_pts, 3)
        assert [c.type for c in mesh.cells] == ["line"] and mesh.cells[0].data.shape == (n_seg, 2)
        pd, cd = mesh.point_data, {key: v[0] for key, v in mesh.cell_data.items()}
        for key, shape in dict(displacement=(n_pts, 3), e1=(n_pts, 3), e2=(n_pts, 3), e3=(n_pts, 3),
                               radius=(n_pts,), beam_id=(n_pts,)).items():
            assert pd[key].shape == shape, key
        for key in ("N", "Q2", "Q3", "T", "M2", "M3", "element"):
            assert cd[key].shape == (n_seg,), key
        assert cd["strain"].shape == (n_seg, 6)
        np.testing.assert_allclose(pd["radius"], 0.1)
        # nodes are every refine-th point; displacement is position minus reference
        np.testing.assert_allclose(mesh.points[::refine], sol.poses[k][:, :3, 3], atol=1e-12 * L)
        np.testing.assert_allclose(pd["displacement"][::refine], sol.displacement(k), atol=1e-12 * L)
        E = np.stack([pd["e1"], pd["e2"], pd["e3"]], axis=-1)
        np.testing.assert_allclose(E @ np.swapaxes(E, 1, 2), np.broadcast_to(np.eye(3), E.shape), atol=1e-12)
        np.testing.assert_allclose(cd["M3"], 2 * np.pi * EI / L * t, rtol=1e-8, atol=1e-9)
    # the last step is a full circle of radius L / (2 pi): every refined point on it
    pts = meshio.read(tmp_path / entries[-1][1]).points
    R = L / (2 * np.pi)
    assert np.abs(np.linalg.norm(pts - [0, R, 0], axis=1) - R).max() < 1e-9 * L
    # the refined points are not just the nodes: the mid-element point is on the circle too
    assert np.abs(np.linalg.norm(pts[refine // 2] - [0, R, 0]) - R) < 1e-9 * L


def test_contact_point_set_per_step(tmp_path):
    model, slave, master = crossing_beams.build(load=50.0, n_elements=4)
    sol = bs.solve(model, steps=2, output=tmp_path)
    entries = pvd_entries(tmp_path / "contact.pvd")
    assert [t for t, _ in entries] == sol.times.tolist()
    # step 0: no contact yet -> a valid file with no points (meshio cannot read meshes without cells)
    empty = (tmp_path / entries[0][1]).read_text()
    assert 'NumberOfPoints="0"' in empty and 'Name="gap"' in empty and 'Name="stick"' in empty
    mesh = meshio.read(tmp_path / entries[-1][1])
    c = sol.contact(-1)
    k = len(c["gap"])
    assert k >= 1 and mesh.points.shape == (k, 3)
    assert [cb.type for cb in mesh.cells] == ["vertex"]
    np.testing.assert_allclose(mesh.points, c["position"])
    np.testing.assert_allclose(mesh.point_data["gap"], c["gap"])
    np.testing.assert_allclose(mesh.point_data["normal_force"], c["normal_force"])
    assert mesh.point_data["tangential_force"].shape == (k, 3)
    assert mesh.point_data["slip_increment"].shape == (k, 2)
    assert mesh.point_data["stick"].shape == (k,)
    np.testing.assert_allclose(mesh.point_data["normal_force"].sum(), 50.0, rtol=1e-4)


def test_interrupted_run_leaves_valid_pvd_of_converged_steps(tmp_path):
    # two elements cannot roll up two turns (an element may turn at most 0.8 pi): fails mid-way
    m, b = roll_up(2, turns=2.0)
    with pytest.raises(bs.ConvergenceError) as err:
        bs.solve(m, steps=8, min_step_ratio=0.25, output=tmp_path)
    part = err.value.solution
    assert 1 < part.n_steps < 8 and not part.converged
    entries = pvd_entries(tmp_path / "beams.pvd")
    assert [t for t, _ in entries] == part.times.tolist()
    for _, name in entries:
        assert meshio.read(tmp_path / name).points.shape == (2 * 8 + 1, 3)
    assert not list(tmp_path.glob(".*"))
    saved = bs.load(tmp_path)                      # solution.npz is saved when the run stops
    assert not saved.converged and saved.times.tolist() == part.times.tolist()


def test_write_vtk_from_saved_solution_and_pyvista(tmp_path):
    m, b = roll_up(4)
    sol = bs.solve(m, steps=2)
    sol.save(tmp_path / "run.npz")
    pvd = bs.io.write_vtk(bs.load(tmp_path / "run.npz"), tmp_path / "vtk", refine=3)
    entries = pvd_entries(pvd)
    assert len(entries) == 3 and not (tmp_path / "vtk" / "solution.npz").exists()
    assert meshio.read(pvd.parent / entries[-1][1]).points.shape == (4 * 3 + 1, 3)
    pv = pytest.importorskip("pyvista")
    reader = pv.get_reader(str(pvd))
    np.testing.assert_allclose(reader.time_values, sol.times)
    reader.set_active_time_value(sol.times[-1])
    grid = reader.read()[0]
    assert grid.n_points == 13 and "radius" in grid.point_data and "M3" in grid.cell_data


def test_custom_writer_object(tmp_path):
    from beamsolver.io.vtk import StepWriter
    m, b = roll_up(4)
    sol = bs.solve(m, steps=1, output=StepWriter(tmp_path, refine=2, compression=None, checkpoint=None))
    entries = pvd_entries(tmp_path / "beams.pvd")
    assert len(entries) == 2 and not (tmp_path / "solution.npz").exists()
    mesh = meshio.read(tmp_path / entries[-1][1])
    assert mesh.points.shape == (4 * 2 + 1, 3)
    np.testing.assert_allclose(mesh.points[::2], sol.poses[-1][:, :3, 3], atol=1e-12 * L)


@pytest.mark.parametrize("compression", ["zlib", "lzma", None])
def test_write_vtu_arrays_read_back_exactly_by_meshio_and_pyvista(tmp_path, compression):
    from beamsolver.io.vtu import BLOCK, write_vtu
    rng = np.random.default_rng(1)
    n = BLOCK // 8 + 5                     # the points span two compressed blocks
    pts = rng.standard_normal((n, 3))
    seg = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    pdata = dict(u=rng.standard_normal((n, 3)), r=rng.random(n), id=np.arange(n, dtype=np.int32))
    cdata = dict(N=rng.standard_normal(n - 1), strain=rng.standard_normal((n - 1, 6)),
                 element=np.arange(n - 1, dtype=np.int32))
    path = tmp_path / "a.vtu"
    write_vtu(path, pts, "line", seg, pdata, cdata, compression)
    mesh = meshio.read(path)
    assert mesh.points.dtype == np.float64 and np.array_equal(mesh.points, pts)
    assert mesh.cells[0].type == "line" and np.array_equal(mesh.cells[0].data, seg)
    for k, v in pdata.items():
        assert mesh.point_data[k].dtype == v.dtype and np.array_equal(mesh.point_data[k], v), k
    for k, v in cdata.items():
        assert mesh.cell_data[k][0].dtype == v.dtype and np.array_equal(mesh.cell_data[k][0], v), k
    write_vtu(tmp_path / "v.vtu", pts[:3], "vertex", np.arange(3).reshape(-1, 1), dict(g=np.ones(3)))
    v = meshio.read(tmp_path / "v.vtu")
    assert v.cells[0].type == "vertex" and np.array_equal(v.point_data["g"], np.ones(3))
    pv = pytest.importorskip("pyvista")
    grid = pv.read(path)
    np.testing.assert_array_equal(grid.points, pts)
    np.testing.assert_array_equal(grid.cell_data["strain"], cdata["strain"])
    with pytest.raises(ValueError, match="compression"):
        write_vtu(path, pts, "line", seg, compression="gzip")
