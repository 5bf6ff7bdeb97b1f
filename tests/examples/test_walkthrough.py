"""A new user's walk-through (issue 17): the main job's script, every example under `beamsolver run`,
`info`, `export`, `render`, and every file written opened with meshio, pyvista and `bs.load`."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

import beamsolver as bs

meshio = pytest.importorskip("meshio")
pv = pytest.importorskip("pyvista")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
REDUCED = ("--steps", "2", "--t-end", "0.25")       # a quarter of each example's pseudo-time, two steps


def run(*args, cwd):
    return subprocess.run([sys.executable, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=300)


def check_folder(folder):
    """Every file in ``folder`` opens: VTU with meshio and pyvista, PVD with pyvista, NPZ with bs.load."""
    files = sorted(p for p in Path(folder).iterdir() if p.is_file())
    assert files, folder
    for p in files:
        if p.suffix == ".vtu":
            assert pv.read(p).n_points == len(meshio.read(p).points), p
        elif p.suffix == ".pvd":
            reader = pv.get_reader(p)
            listed = re.findall(r'file="([^"]+)"', p.read_text())
            assert len(reader.time_values) == len(listed) and all((p.parent / f).is_file() for f in listed)
            reader.set_active_time_value(reader.time_values[-1])
            reader.read()
        elif p.suffix == ".npz":
            assert bs.load(p).n_steps >= 1
        elif p.suffix == ".png":
            assert p.read_bytes()[:4] == b"\x89PNG"
        elif p.name == "view.py":                     # the ParaView script (bs.io.paraview)
            text = p.read_text()
            compile(text, str(p), "exec")
            assert "beams.pvd" in text
        else:
            raise AssertionError(f"unexpected file {p.name}")
    return {p.name for p in files}


@pytest.mark.slow
@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.py")))
def test_every_example_runs_under_beamsolver_run(example, tmp_path):
    out = run("-m", "beamsolver.app.cli", "run", EXAMPLES / example, "-o", "out", *REDUCED, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    names = check_folder(tmp_path / "out")
    written = out.stdout.splitlines()[-1]
    assert written.startswith("written:") and "beams.pvd" in written and "solution.npz" in written
    assert ("contact.pvd" in written) == ("contact.pvd" in names)
    info = run("-m", "beamsolver.app.cli", "info", "out", cwd=tmp_path)
    assert info.returncode == 0 and "; converged" in info.stdout, info.stderr


@pytest.mark.slow
def test_main_job_script_export_and_render(tmp_path):
    out = run(EXAMPLES / "twisted_pair.py", "--output", "out", "--turns", "0.25", "--steps", "2",
              "--elements", "8", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "| 0.000 | 0 | 0 | 500 | 0 |" in out.stdout     # step 0 carries the constant 500 N pull, no twist
    assert "within the elastic range" in out.stdout and "stays positive definite" in out.stdout
    names = check_folder(tmp_path / "out")
    assert {"beams.pvd", "contact.pvd", "solution.npz", "twisted_pair.png", "view.py"} <= names
    assert "paraview --script=out/view.py" in out.stdout
    exp = run("-m", "beamsolver.app.cli", "export", "out", "again", cwd=tmp_path)
    assert exp.returncode == 0, exp.stderr
    assert {n for n in names if n.endswith((".vtu", ".pvd"))} == {n for n in check_folder(tmp_path / "again")}
    pic = run("-m", "beamsolver.app.cli", "render", "out", "-o", "pic.png", "--size", "160", "120", cwd=tmp_path)
    assert pic.returncode == 0 and (tmp_path / "pic.png").read_bytes()[:4] == b"\x89PNG", pic.stderr
