"""The command line names bad input in one line instead of a traceback or a silent loss (issue 28
item 13, CLI part): a typo in a script's solve_options, ``info`` on a partial study.json,
``--param`` given twice, a misspelled sweep parameter (also through ``bs.sweep``)."""
import json
import subprocess
import sys

import pytest

import beamsolver as bs
from beamsolver.app import study
from beamsolver.app.sweep_engine import sweep

SCENE = """
import beamsolver as bs

def build(load=1.0, n=2):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0))
    return m, b
"""


def _cli(cwd, *args):
    return subprocess.run([sys.executable, "-m", "beamsolver.app.cli", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=120)


@pytest.mark.slow
def test_typo_in_solve_options_is_named(tmp_path):
    (tmp_path / "s.py").write_text(SCENE + "solve_options = dict(stpes=2)\n")
    out = _cli(tmp_path, "run", "s.py", "-q")
    assert out.returncode == 1 and "Traceback" not in out.stderr
    assert "solve_options in s.py has 'stpes', not an argument of beamsolver.solve" in out.stderr
    (tmp_path / "s.py").write_text(SCENE + "solve_options = [2]\n")
    out = _cli(tmp_path, "run", "s.py", "-q")
    assert out.returncode == 1 and "solve_options in s.py must be a dict" in out.stderr
    (tmp_path / "s.py").write_text(SCENE + "solve_options = dict(steps=2)\n")
    assert _cli(tmp_path, "run", "s.py", "-q").returncode == 0


@pytest.mark.parametrize("meta, words", [({"names": ["load"]}, "incomplete: no 'options', 'points'"),
                                         ({"names": ["load"], "options": "{}", "points": [{"id": "a"}]},
                                          "point 0 is not"),
                                         ([1, 2], "incomplete")])
@pytest.mark.slow
def test_info_on_a_partial_study_json_is_named(tmp_path, meta, words):
    (tmp_path / "st").mkdir()
    (tmp_path / "st" / study.STUDY).write_text(json.dumps(meta))
    out = _cli(tmp_path, "info", "st")
    assert out.returncode == 1 and words in out.stderr and "Traceback" not in out.stderr, out.stderr


def test_param_given_twice_is_refused(tmp_path):
    (tmp_path / "s.py").write_text(SCENE)
    out = _cli(tmp_path, "sweep", "s.py", "--param", "load=1", "--param", "load=2", "-q")
    assert out.returncode == 1 and "--param load is given twice" in out.stderr
    assert not (tmp_path / "s_study").exists()


def test_misspelled_sweep_parameter_is_refused_before_any_point_runs(tmp_path):
    (tmp_path / "s.py").write_text(SCENE)
    out = _cli(tmp_path, "sweep", "s.py", "--param", "laod=1,2", "-q")
    assert out.returncode == 1 and "has no parameter 'laod' (it takes load, n)" in out.stderr, out.stderr
    assert not (tmp_path / "s_study").exists()


def scene(load=1.0):
    return bs.Model()


def test_api_sweep_refuses_a_misspelled_parameter(tmp_path):
    with pytest.raises(bs.InputError, match="scene has no parameter 'laod'"):
        sweep(scene, {"laod": [1.0, 2.0]}, output=tmp_path / "st", verbose=False)
    assert not (tmp_path / "st").exists()
