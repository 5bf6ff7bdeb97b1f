"""A new user's smaller frictions (issue 29 item 5), each fixed: the command line and the files left behind."""
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.app import cli

ROOT = Path(__file__).resolve().parents[2]

SCENE = textwrap.dedent("""
    import numpy as np
    import beamsolver as bs

    solve_options = dict(steps=2)


    def build():
        sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
        m = bs.Model()
        b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), 2), sec)
        m.clamp(b.first)
        m.add_load(b.last, force=(0, 0, -1.0))
        return m
""")


@pytest.fixture
def saved(tmp_path, monkeypatch):
    """A scene script and ``beamsolver run`` of it (default output folder) in ``tmp_path``."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.py").write_text(SCENE)
    assert cli.main(["run", "scene.py", "-q"]) == 0
    return tmp_path


def test_version(capsys):
    """``beamsolver --version`` (there was none)."""
    with pytest.raises(SystemExit) as exit_:
        cli.main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out.strip() == f"beamsolver {bs.__version__}"


def test_run_writes_its_own_default_folder(saved):
    """``beamsolver run scene.py`` writes ``scene_run/``, not the ``scene_output/`` a script's own ``__main__``
    writes (the main job and ``beamsolver run`` on it wrote the same folder)."""
    assert (saved / "scene_run" / "beams.pvd").is_file() and not (saved / "scene_output").exists()


def test_export_names_every_file_it_writes(saved, capsys, monkeypatch):
    """``beamsolver export`` names ``contact.pvd`` too when it writes one (it reported only ``beams.pvd``)."""
    assert cli.main(["export", "scene_run", "again"]) == 0
    out = capsys.readouterr().out
    assert "again/beams.pvd" in out and "3 .vtu files" in out and "contact.pvd" not in out
    from beamsolver import io

    def with_contact(sol, folder):                 # a contact scene's files, without compiling its kernel
        folder = Path(folder)
        folder.mkdir()
        for name in ("beams.pvd", "contact.pvd", "beams_0000.vtu", "contact_0000.vtu"):
            (folder / name).write_text("")
        return folder / "beams.pvd"

    monkeypatch.setattr(io, "write_vtk", with_contact)
    assert cli.main(["export", "scene_run", "third"]) == 0
    out = capsys.readouterr().out
    assert "third/beams.pvd, third/contact.pvd (2 .vtu files" in out


def test_render_without_pyvista_says_one_line(saved, capsys, monkeypatch):
    """Without pyvista, ``beamsolver render`` prints one line and exits 1, as ``sweep`` without dask (it printed
    a 20-line chained traceback)."""
    monkeypatch.setitem(sys.modules, "pyvista", None)          # import pyvista raises ImportError
    assert cli.main(["render", "scene_run", "-o", "pic.png"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["beamsolver render: beamsolver.viz.render needs pyvista: pip install 'beamsolver[viz]'"]


def test_render_has_view_zoom_and_scale(saved, monkeypatch):
    """``beamsolver render --view --zoom --scale`` reach ``viz.render`` (a strand rendered as a thin stick)."""
    from beamsolver.app import viz
    seen = {}
    monkeypatch.setattr(viz, "render", lambda sol, **kw: seen.update(kw))
    assert cli.main(["render", "scene_run", "-o", "pic.png", "--view", "xz", "--zoom", "2.5",
                     "--scale", "1", "1", "0.02"]) == 0
    assert seen["view"] == "xz" and seen["zoom"] == 2.5 and seen["scale"] == [1.0, 1.0, 0.02]
    assert cli.main(["render", "scene_run", "-o", "pic.png"]) == 0
    assert seen["view"] == "auto" and seen["zoom"] == 1.0 and seen["scale"] is None


def test_summary_counts_the_iterations_of_step_0(saved):
    """``Solution.summary`` (``beamsolver info``'s line) counts step 0's Newton iterations, as the main job's
    ``sum(s["iterations"] for s in sol.stats)`` does (141 there against 130 here before)."""
    sol = bs.load(saved / "scene_run")
    it = [s["iterations"] for s in sol.stats]
    sol.stats[0]["iterations"] = 3                            # step 0 with iterations (a contact scene's)
    text = sol.summary()
    assert f"Newton iterations total {sum(it[1:]) + 3} (3 at step 0), max {max(it[1:] + [3])}" in text
    sol.stats[0]["iterations"] = 0
    assert f"Newton iterations total {sum(it[1:])}, max" in sol.summary()


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="needs the git checkout")
def test_what_runs_leave_behind_is_ignored():
    """The folders the examples, ``beamsolver run`` and ``sweep`` write where they are started, and the strand
    sweep's picture, are ignored by git (they showed as untracked files); the docs' pictures are not."""
    paths = ["twisted_pair_output/view.py", "twisted_pair_output/twisted_pair.png", "scene_run/solution.npz",
             "strand_study/summary.json", "strand_sweep.png", "plectoneme_output/plectoneme.png"]
    out = subprocess.run(["git", "check-ignore", *paths, "docs/twisted_pair.png", "examples/twisted_pair.py"],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.stdout.split() == paths


def _script(tmp_path, text):
    (tmp_path / "s.py").write_text(textwrap.dedent(text))
    return subprocess.run([sys.executable, "s.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_sweep_without_the_main_guard_says_so_at_once(tmp_path):
    """A sweep script without ``if __name__ == "__main__":`` fails before the local cluster starts, with the
    script's line in the message (it printed ~500 lines of Dask tracebacks first: each spawned worker
    imported the script and started a sweep of its own)."""
    out = _script(tmp_path, SCENE + "\nrows = bs.sweep(lambda load: build(), dict(load=[1.0, 2.0]), solve_options=dict(steps=1))\n")
    assert out.returncode == 1
    assert 's.py, line 16, calls sweep outside `if __name__ == "__main__":`' in out.stderr
    assert len(out.stderr.splitlines()) < 25 and "Nanny" not in out.stderr and "distributed" not in out.stderr


def test_main_guard_detection(tmp_path):
    """Guarded calls (directly or through a function) pass; an unguarded call through a function is caught."""
    out = _script(tmp_path, """
        from beamsolver.app.sweep_engine import unguarded_main_call


        def main():
            return unguarded_main_call()


        print(repr(main()))
        if __name__ == "__main__":
            print(repr(unguarded_main_call()))
            print(repr(main()))
    """)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:3] == ["'s.py, line 9,'", "''", "''"]
