"""The ``beamsolver`` command on a small scene, run as a subprocess."""
import subprocess
import sys
import textwrap

import pytest

import beamsolver as bs

SCENE = textwrap.dedent("""
    import numpy as np
    import beamsolver as bs

    solve_options = dict(steps=5)


    def build():
        sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
        m = bs.Model()
        b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), 4), sec)
        m.clamp(b.first)
        m.add_load(b.last, moment=(0, 0, np.pi * 1e2 / 10), follower=True)
        return m, b


    if __name__ == "__main__":
        raise SystemExit("the __main__ block must not run under `beamsolver run`")
""")


def cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "beamsolver.app.cli", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_run_info_export(tmp_path):
    (tmp_path / "scene.py").write_text(SCENE)
    out = cli("run", "scene.py", "--steps", 2, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "2 steps to t = 1" in out.stdout
    folder = tmp_path / "scene_run"                        # default output folder (not the script's own _output)
    assert (folder / "beams.pvd").exists() and (folder / "beams_0002.vtu").exists()
    assert bs.load(folder).n_steps == 2                    # --steps overrides solve_options
    out = cli("info", folder / "solution.npz", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "iterations" in out.stdout and "reactions" in out.stdout and "clamp" in out.stdout
    assert "-31.4" in out.stdout or "-15.7" in out.stdout   # Mz reaction = -M
    out = cli("export", folder, tmp_path / "again", cwd=tmp_path)
    assert out.returncode == 0 and (tmp_path / "again" / "beams_0002.vtu").exists()
    assert "beams.pvd" in out.stdout and "3 .vtu files" in out.stdout


@pytest.mark.slow
def test_run_with_model_global_and_errors(tmp_path):
    (tmp_path / "g.py").write_text(SCENE + "\nmodel = build()[0]\nsolve_options = dict(steps=1)\n")
    out = cli("run", "g.py", "-o", "res", "-q", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout == "" and bs.load(tmp_path / "res").n_steps == 1
    (tmp_path / "empty.py").write_text("x = 1\n")
    out = cli("run", "empty.py", cwd=tmp_path)
    assert out.returncode != 0 and "build()" in out.stderr
    out = cli("info", "nothing.npz", cwd=tmp_path)
    assert out.returncode == 1 and "nothing.npz" in out.stderr


@pytest.mark.slow
def test_render(tmp_path):
    pytest.importorskip("pyvista")
    (tmp_path / "scene.py").write_text(SCENE)
    assert cli("run", "scene.py", "-q", "-o", "res", cwd=tmp_path).returncode == 0
    out = cli("render", "res", "--step", 3, "-o", "pic.png", "--size", 200, 150, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    head = (tmp_path / "pic.png").read_bytes()[:24]
    assert head[:4] == b"\x89PNG" and int.from_bytes(head[16:20], "big") == 200
