"""The command line as a new user meets it (issue 17 items 7, 8, 10)."""
import subprocess
import sys

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.app import cli


def cantilever():
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), 4), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, np.pi * 1e2 / 10), follower=True)
    return m


def test_info_of_an_interrupted_run_says_stopped(tmp_path, capsys):
    def stop(info):
        if info["t"] > 0.5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        bs.solve(cantilever(), steps=4, output=tmp_path, checkpoint=0, callback=stop)
    assert cli.main(["info", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "stopped at t = 0.5 of 1" in text and "converged" not in text
    bs.solve(cantilever(), steps=4, output=tmp_path)
    assert cli.main(["info", str(tmp_path)]) == 0
    assert "; converged" in capsys.readouterr().out


def test_build_with_required_arguments_gets_one_line(tmp_path):
    (tmp_path / "s.py").write_text("def build(n_elements, load):\n    raise AssertionError('not called')\n")
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "run", "s.py"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 1
    assert out.stderr.strip().splitlines() == [
        "beamsolver run: build() in s.py needs arguments (n_elements, load); give them defaults, "
        "or define a Model named 'model'"]


def test_checkpoint_option_reaches_solve(tmp_path, monkeypatch, capsys):
    (tmp_path / "s.py").write_text("import beamsolver as bs\n")
    seen, real_solve = {}, bs.solve

    def fake_solve(model, **opts):
        seen.update(opts)
        return real_solve(model, steps=1)

    monkeypatch.setattr(cli, "_scene", lambda script: (cantilever(), {}))
    monkeypatch.setattr(bs, "solve", fake_solve)
    assert cli.main(["run", str(tmp_path / "s.py"), "-o", str(tmp_path / "o"), "--checkpoint", "0", "-q"]) == 0
    assert seen["checkpoint"] == 0.0
