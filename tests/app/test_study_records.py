"""Study records without Dask (``run_point``, ``study``): summary keys that would overwrite a grid
parameter, a point failing at ``t_start`` (no step at all), file modes following the umask."""
import os
import pickle
import stat

import pytest

import beamsolver as bs
from beamsolver.app import study
from beamsolver.app.sweep_engine import run_point


def scene(load=1.0, at_start=False):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0), scale=(lambda t: 1.0) if at_start else (lambda t: t))
    return m, b


def load_summary(sol, model, beam):
    return {"load": 123.0, "tip": sol.position(beam.last)[1]}


def test_summary_key_named_like_a_parameter_is_refused_not_overwriting_it(tmp_path):
    code = pickle.dumps((scene, load_summary))
    rows = [run_point(code, {"load": v}, f"p{v}", str(tmp_path), {"steps": 2}) for v in (1.0, 2.0)]
    for v, row in zip((1.0, 2.0), rows):
        assert row["load"] == v                      # the grid's value stands
        assert row["status"] == "TypeError" and "'load'" in row["message"] and "parameter" in row["message"]
        assert "tip" not in row


def test_point_failing_at_t_start_records_no_step_and_no_unreadable_file(tmp_path):
    """Nothing converged: ``steps`` is 0 (not -1) and no solution.npz that ``bs.load`` refuses."""
    code = pickle.dumps((scene, None))
    row = run_point(code, {"load": 1e6, "at_start": True}, "p", str(tmp_path), {"steps": 2, "max_iter": 1})
    assert row["status"] == "ConvergenceError" and "t_start" in row["message"]
    assert row["steps"] == 0 and row["iterations"] == 0
    assert not (tmp_path / "p" / "solution.npz").exists()
    assert study.read_point(tmp_path, "p")["row"] == row


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_study_files_follow_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        code = pickle.dumps((scene, None))
        row = run_point(code, {"load": 1.0}, "p", str(tmp_path), {"steps": 1})
        study.write_json(tmp_path / study.STUDY, {"names": ["load"], "points": []})
        study.write_summary(tmp_path, [row], ["load"])
    finally:
        os.umask(old)
    for path in (tmp_path / study.STUDY, tmp_path / study.SUMMARY, tmp_path / "p" / study.POINT):
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask, path
