"""Sweep studies without Dask: grid expansion, point ids, input errors, records, the study report,
and the core import path staying free of dask."""
import json
import subprocess
import sys

import pytest

import beamsolver as bs
from beamsolver.app import study
from beamsolver.app.sweep_cli import SceneScript, parse_param


def test_grid_product_order_and_ids():
    pts = study.points({"mu": [0.1, 0.3], "lay_angle": [8, 12], "ends": ["fixed"]})
    assert pts == [dict(mu=0.1, lay_angle=8, ends="fixed"), dict(mu=0.1, lay_angle=12, ends="fixed"),
                   dict(mu=0.3, lay_angle=8, ends="fixed"), dict(mu=0.3, lay_angle=12, ends="fixed")]
    assert study.point_id(pts[1]) == "mu=0.1_lay_angle=12_ends=fixed"
    assert study.point_id({"eps": 1e-05}) == "eps=1e-05"
    # values that do not make a file name: a stable hash of the parameters
    odd = study.point_id({"path": "/tmp/x y"})
    assert odd.startswith("point-") and odd == study.point_id({"path": "/tmp/x y"})
    assert odd != study.point_id({"path": "/tmp/x z"})
    ids = study.point_ids([{"a": 1}, {"a": "1"}, {"a": 2}])         # 1 and "1" would share a folder
    assert ids[2] == "a=2" and ids[0].startswith("point-") and ids[1].startswith("point-") and ids[0] != ids[1]
    assert study.points([{"a": 1}, {"a": 2, "b": "x"}]) == [{"a": 1}, {"a": 2, "b": "x"}]
    assert study.param_names([{"a": 1}, {"a": 2, "b": "x"}]) == ["a", "b"]


@pytest.mark.parametrize("grid, words", [
    ({}, "grid is empty"),
    ({"mu": 0.3}, "grid['mu']"),
    ({"mu": []}, "grid['mu']"),
    ({"status": [1]}, "reserved"),
    ({"not a name": [1]}, "identifier"),
    ([{"a": 1}, {"a": 1}], "repeats point 0"),
    ([{"a": object()}], "grid point 0"),
    ("mu", "grid must be"),
])
def test_bad_grids_raise_input_error(grid, words):
    with pytest.raises(bs.InputError, match=words.replace("[", r"\[").replace("]", r"\]")):
        study.points(grid)


def test_bad_arguments_raise_before_any_engine_starts(tmp_path):
    def scene(a):
        return bs.Model()
    with pytest.raises(bs.InputError, match="scene must be callable"):
        bs.sweep(42, {"a": [1]})
    with pytest.raises(bs.InputError, match="summary must be callable"):
        bs.sweep(scene, {"a": [1]}, summary="x")
    with pytest.raises(bs.InputError, match="'output'"):
        bs.sweep(scene, {"a": [1]}, solve_options={"output": "x"})
    with pytest.raises(bs.InputError, match="'stepz', not an argument of beamsolver.solve"):
        bs.sweep(scene, {"a": [1]}, solve_options={"stepz": 4})
    with pytest.raises(bs.InputError, match="client must be"):
        bs.sweep(scene, {"a": [1]}, client=42, output=tmp_path / "s")


def test_complete_records_and_report(tmp_path):
    opts = {"steps": 4}
    params = [{"mu": 0.1}, {"mu": 0.2}, {"mu": 0.3}]
    ids = [study.point_id(p) for p in params]
    study.write_json(tmp_path / study.STUDY, dict(names=["mu"], options=study.canonical(opts),
                                                  points=[dict(id=i, params=p) for i, p in zip(ids, params)]))
    rows = [dict(id=ids[0], mu=0.1, status="converged", iterations=3, steps=4, wall=0.5, K=1.25, message=""),
            dict(id=ids[1], mu=0.2, status="ConvergenceError", iterations=9, steps=2, wall=0.7,
                 message="solve: could not advance")]
    for p, r in zip(params, rows):
        (tmp_path / r["id"]).mkdir()
        study.write_json(tmp_path / r["id"] / study.POINT, dict(params=p, options=study.canonical(opts), row=r))
    rec = study.read_point(tmp_path, ids[0])
    assert study.is_complete(rec, params[0], opts)
    assert not study.is_complete(rec, params[0], {"steps": 8})          # other solve options: stale
    assert not study.is_complete(rec, params[1], opts)
    assert not study.is_complete(None, params[2], opts)
    assert not study.is_complete(rec, params[0], opts, paraview=True)      # no ParaView files yet
    assert study.is_complete(dict(rec, paraview=True), params[0], opts, paraview=True)
    lost = dict(rows[1], status="KilledWorker")
    assert not study.is_complete(dict(params=params[1], options=study.canonical(opts), row=lost), params[1], opts)
    meta, loaded = study.load_study(tmp_path)
    assert loaded == rows + [None]
    text = study.report(tmp_path)
    assert "3 points over mu" in text and "1 converged" in text and "1 not run" in text
    assert "1 ConvergenceError" in text and "solve: could not advance" in text and "1.25" in text
    path = study.write_summary(tmp_path, loaded, meta["names"])
    lines = path.read_text().splitlines()
    assert lines[0] == "id,mu,status,iterations,steps,wall,K,message"
    assert lines[1] == "mu=0.1,0.1,converged,3,4,0.5,1.25," and len(lines) == 3


def test_cli_params_and_scene_script_pickle(tmp_path):
    import pickle
    assert parse_param("mu=0.1,0.2") == ("mu", [0.1, 0.2])
    assert parse_param("n=8, 12") == ("n", [8, 12])
    assert parse_param("ends=fixed,'free'") == ("ends", ["fixed", "free"])
    with pytest.raises(bs.InputError, match="NAME=VALUE"):
        parse_param("mu")
    path = tmp_path / "s.py"
    path.write_text("solve_options = dict(steps=3)\ncalls = []\n"
                    "def build(a):\n    calls.append(a)\n    return a\n")
    s = SceneScript(path)
    assert s.solve_options == {"steps": 3} and not s.has_summary and s.build(a=5) == 5
    t = pickle.loads(pickle.dumps(s))                     # the source travels, not the namespace
    assert t.source == s.source and t._ns is None and t.build(a=7) == 7
    assert t.namespace()["calls"] == [7] and s.namespace()["calls"] == [5]


def test_core_import_path_is_free_of_dask():
    code = ("import sys, beamsolver as bs, beamsolver.app.cli, beamsolver.app.study, beamsolver.app.sweep_cli, "
            "beamsolver.app.sweep_engine; assert callable(bs.sweep); "
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'dask', 'distributed', 'cloudpickle'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.replace("'", '"')) == []


def test_progress_bar_over_points(monkeypatch, capsys):
    from beamsolver.app.sweep_engine import _Progress

    class Client:
        def nthreads(self):
            return {"a": 1, "b": 1}

        def scheduler_info(self):
            return {"services": {"dashboard": 8787}}
        dashboard_link = "http://127.0.0.1:8787/status"
    monkeypatch.setattr("sys.stderr.isatty", lambda: True)
    rows = [dict(status="converged"), dict(status="InputError"), None, None, None]
    p = _Progress(None, rows, Client())                    # two points finished in an earlier run
    assert p.bar.n == 2 and "done 1, failed 1, running 2" in p.bar.postfix
    p.update(True, 2)
    assert p.bar.n == 3 and "done 2, failed 1, running 2" in p.bar.postfix
    p.update(False, 0)
    assert "done 2, failed 2, running 0" in p.bar.postfix
    p.close()
    assert "Dask dashboard at http://127.0.0.1:8787/status" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_sweep_refuses_a_script_without_build(tmp_path):
    (tmp_path / "s.py").write_text("model = None\n")
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "sweep", "s.py", "--param", "a=1,2"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 1 and "defines no function build(**params)" in out.stderr
    (tmp_path / "s.py").write_text("def build(a):\n    return None\n")
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "sweep", "s.py", "--param", "a"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 1 and "NAME=VALUE" in out.stderr


def small_scene(load=1.0, kind="beam"):
    if kind == "nothing":
        return "not a model"
    if kind == "crash":
        return 1 / 0
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0))
    return m, b


def bad_summary(sol, model, beam):
    return {"tip": sol.position(beam.last)[1], "status": "mine"}


def tip_summary(sol, model, beam):
    return {"tip": sol.position(beam.last)[1]}


def test_run_point_records_every_kind_of_failure(tmp_path):
    """``run_point`` (what a worker runs) without Dask: pickled scene and summary in, row and record out."""
    import pickle
    from beamsolver.app.sweep_engine import run_point
    code = pickle.dumps((small_scene, tip_summary))
    row = run_point(code, {"load": 1.0}, "p", str(tmp_path), {"steps": 2})
    model, beam = small_scene()
    assert row["status"] == "converged" and row["steps"] == 2 and row["message"] == ""
    assert row["tip"] == bs.solve(model, steps=2, verbose=False).position(beam.last)[1]
    assert bs.load(tmp_path / "p").n_steps == 2
    assert study.read_point(tmp_path, "p")["row"] == row
    cases = [(pickle.dumps((small_scene, bad_summary)), {}, "TypeError", "summary: entry 'status'"),
             (code, {"kind": "nothing"}, "InputError", "returned str, not a Model"),
             (code, {"kind": "crash"}, "ZeroDivisionError", "division by zero"),
             (b"not a pickle", {}, "SceneLoadError", "cannot load the scene")]
    for k, (c, params, status, words) in enumerate(cases):
        row = run_point(c, params, f"q{k}", str(tmp_path), {"steps": 2})
        rec = study.read_point(tmp_path, f"q{k}")
        assert row["status"] == status and words in row["message"], row
        assert ("traceback" in rec) == (status != "InputError") and "tip" not in row
    assert run_point(code, {"load": 1.0}, "p", None, {"steps": 2})["status"] == "converged"   # no output
