"""Issue 12 item 13 and issue 17 item 11: file errors are an ``InputError`` naming the path and
what is wrong -- an output folder that is a file, under a file, read-only or on a full disk; a
truncated, bit-flipped, empty or hand-edited archive -- also through the command line, without a
traceback from zipfile/json/pathlib."""
import errno
import json
import os
import re
import struct
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import InputError
from beamsolver.app import cli
from beamsolver.io import archive

ROOT = Path(__file__).resolve().parents[2]


SCENE = """
import beamsolver as bs


def build():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 3), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 10.0))
    return m
"""


def _cantilever():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 3), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 10.0))
    return m


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """A good archive of a 2-step run."""
    path = tmp_path_factory.mktemp("good") / "run.npz"
    bs.solve(_cantilever(), steps=2, verbose=False).save(path)
    return path


def _arrays(path):
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def _member_data_offset(path, name):
    """Byte offset of the compressed data of member ``name`` of a zip file."""
    with zipfile.ZipFile(path) as z:
        info = z.getinfo(name)
    with open(path, "rb") as f:
        f.seek(info.header_offset)
        header = f.read(30)
    n_name, n_extra = struct.unpack("<HH", header[26:30])
    return info.header_offset + 30 + n_name + n_extra, info.compress_size


# ---------------------------------------------------------------- output folders
def test_output_that_is_a_file(tmp_path):
    target = tmp_path / "result.txt"
    target.write_text("not a folder")
    with pytest.raises(InputError, match=r"output .*result.txt.* is a file, not a folder"):
        bs.solve(_cantilever(), steps=1, output=target, verbose=False)
    with pytest.raises(InputError, match=r"output .*result.txt.* is a file, not a folder"):
        bs.solve(_cantilever(), steps=1, output=target / "sub" / "run", verbose=False)
    assert target.read_text() == "not a folder"


def test_output_in_a_folder_that_cannot_be_written(tmp_path, monkeypatch):
    def refuse(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")
    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(InputError, match=r"output folder .*out.*: cannot write .*Permission denied"):
        bs.solve(_cantilever(), steps=1, output=tmp_path / "out", verbose=False)


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root writes to read-only folders")
def test_output_in_a_read_only_folder(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(InputError, match=r"output folder .*ro.*: cannot write"):
            bs.solve(_cantilever(), steps=1, output=ro, verbose=False)
    finally:
        ro.chmod(0o755)


def test_output_on_a_full_disk_at_start_and_during_the_run(tmp_path, monkeypatch):
    real_replace = os.replace
    calls = []

    def full(src, dst):
        calls.append(dst)
        if len(calls) > limit:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_replace(src, dst)
    monkeypatch.setattr(os, "replace", full)
    limit = 0
    with pytest.raises(InputError, match=r"output folder .*full0.*: cannot write .*No space left on device"):
        bs.solve(_cantilever(), steps=3, output=tmp_path / "full0", verbose=False)
    limit, calls[:] = 4, []         # the disk fills up after the first files
    with pytest.raises(InputError, match=r"output folder .*full1.*: cannot write \S+ \(No space left on device\)"):
        bs.solve(_cantilever(), steps=3, output=tmp_path / "full1", verbose=False)
    assert not [p for p in (tmp_path / "full1").iterdir() if p.name.endswith(".tmp")]   # no temp files left


def test_a_step_file_that_fails_stops_the_output_and_no_collection_lists_a_missing_file(tmp_path, monkeypatch):
    # the files are written by a background thread (io.vtk.StepWriter): its failure reaches solve,
    # which keeps the converged steps (.solution), and no later step's files or collections follow
    real_replace = os.replace

    def full(src, dst):
        if Path(dst).name == "beams_0002.vtu":
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_replace(src, dst)
    monkeypatch.setattr(os, "replace", full)
    folder = tmp_path / "out"
    with pytest.raises(InputError, match=r"cannot write beams_0002\.vtu \(No space left on device\)") as err:
        bs.solve(_cantilever(), steps=6, output=folder, verbose=False)
    assert err.value.solution is not None and err.value.solution.n_steps >= 2
    listed = re.findall(r'file="([^"]+)"', (folder / "beams.pvd").read_text())
    assert listed == ["beams_0000.vtu", "beams_0001.vtu"]
    assert sorted(p.name for p in folder.glob("*.vtu")) == listed
    assert not [p for p in folder.iterdir() if p.name.endswith(".tmp")]


def test_save_into_a_file_path(tmp_path, saved):
    (tmp_path / "f").write_text("x")
    with pytest.raises(InputError, match=r"save\(.*f.*\): cannot write"):
        bs.load(saved).save(tmp_path / "f" / "again.npz")


# ---------------------------------------------------------------- damaged archives
def _truncated(path, tmp):
    data = path.read_bytes()
    out = tmp / "truncated.npz"
    out.write_bytes(data[:len(data) // 2])
    return out


def _bit_flipped(path, tmp):
    data = bytearray(path.read_bytes())
    start, size = _member_data_offset(path, "poses.npy")
    data[start + size // 2] ^= 0x10
    out = tmp / "flipped.npz"
    out.write_bytes(bytes(data))
    return out


def _empty(path, tmp):
    out = tmp / "empty.npz"
    out.write_bytes(b"")
    return out


def _edited(change):
    def make(path, tmp):
        arrays = _arrays(path)
        change(arrays)
        out = tmp / "edited.npz"
        np.savez(out, **arrays)
        return out
    return make


def _drop(key):
    return lambda a: a.pop(key)


def _set(key, value):
    return lambda a: a.__setitem__(key, value)


DAMAGE = {
    "truncated": (_truncated, r"damaged|not a beamsolver result"),
    "bit-flipped": (_bit_flipped, r"damaged"),
    "empty": (_empty, r"the file is empty"),
    "missing poses": (_edited(_drop("poses")), r"missing 'poses'"),
    "missing model": (_edited(_drop("model/enodes")), r"missing 'model/enodes'"),
    "bad stats JSON": (_edited(_set("stats", np.array("[{not json"))), r"'stats' is not valid JSON"),
    "bad resume JSON": (_edited(_set("resume", np.array("{"))), r"'resume' is not valid JSON"),
    "stats not a list": (_edited(_set("stats", np.array("3"))), r"'stats' must hold a JSON list, got int"),
    "stats too short": (_edited(_set("stats", np.array("[{}]"))), r"'stats' must be a list of 3 dicts"),
    "times vs poses": (_edited(lambda a: a.__setitem__("times", np.arange(4.0))),
                       r"inconsistent: 4 times but 3 steps of poses"),
    "poses shape": (_edited(lambda a: a.__setitem__("poses", a["poses"][:, :, :3])),
                    r"'poses' has shape \(3, 4, 3, 4\), expected \(3, 4, 4, 4\)"),
    "reactions shape": (_edited(lambda a: a.__setitem__("reactions", a["reactions"][:2])),
                        r"'reactions' has shape \(2, 4, 6\), expected \(3, 4, 6\)"),
    "non-finite poses": (_edited(lambda a: a["poses"].__setitem__((1, 2, 0, 3), np.nan)),
                         r"'poses' is not finite at step 1"),
    "no steps": (_edited(lambda a: a.update({k: a[k][:0] for k in ("times", "poses", "reactions",
                                                                     "section_forces", "strains")})),
                 r"no steps"),
    "format string": (_edited(_set("format", np.array("something-else"))), r"not a beamsolver result"),
    "contact counts": (_edited(lambda a: a.update({"contact/gap": np.zeros(2),
                                                    "contact_count/gap": np.array([1, 1])})),
                       r"'contact_count/gap' has 2 entries for 3 steps"),
}


@pytest.mark.parametrize("name", list(DAMAGE))
def test_load_of_a_damaged_archive(name, saved, tmp_path):
    make, pattern = DAMAGE[name]
    path = make(saved, tmp_path)
    with pytest.raises(InputError, match=rf"load\('{tmp_path}.*'\): .*({pattern})"):
        bs.load(path)


def test_load_of_other_files(tmp_path):
    with pytest.raises(InputError, match=r"load\('.*README.md'\): not a beamsolver result \(not a .npz"):
        bs.load(ROOT / "README.md")
    np.save(tmp_path / "a.npy", np.zeros(3))
    with pytest.raises(InputError, match=r"a.npy'\): not a beamsolver result"):
        bs.load(tmp_path / "a.npy")
    with pytest.raises(InputError, match=r"no such file"):
        bs.load(tmp_path / "missing.npz")
    with pytest.raises(InputError, match=r"no solution.npz in the folder"):
        bs.load(tmp_path)


def test_restart_from_a_damaged_archive(saved, tmp_path):
    path = _truncated(saved, tmp_path)
    with pytest.raises(InputError, match=r"load\(.*truncated.npz'\)"):
        bs.solve(_cantilever(), steps=4, restart=path, verbose=False)


# ---------------------------------------------------------------- the command line
@pytest.mark.parametrize("command", ["info", "export", "render", "run"])
def test_cli_reports_a_damaged_archive_in_one_line(command, saved, tmp_path, capsys):
    bad = _bit_flipped(saved, tmp_path)
    scene = tmp_path / "scene.py"
    scene.write_text(SCENE)
    args = {"info": ["info", bad], "export": ["export", bad, tmp_path / "vtk"],
            "render": ["render", bad, "-o", tmp_path / "x.png"],
            "run": ["run", scene, "-o", tmp_path / "o", "-q", "--restart", bad]}[command]
    code = cli.main([str(a) for a in args])
    err = capsys.readouterr().err
    assert code == 1
    assert f"beamsolver {command}: load('{bad}'): damaged" in err
    assert len(err.strip().splitlines()) == 1


def test_cli_info_of_a_non_archive_says_so():
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "info", "README.md"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 1
    assert "README.md'): not a beamsolver result" in out.stderr
    assert "pickle" not in out.stderr and "Traceback" not in out.stderr


def test_cli_export_into_a_file(saved, tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    assert cli.main(["export", str(saved), str(tmp_path / "f")]) == 1
    assert "is a file, not a folder" in capsys.readouterr().err


def test_a_good_archive_still_loads(saved):
    sol = bs.load(saved)
    assert sol.n_steps == 2 and json.loads(json.dumps(sol.stats)) == sol.stats
    np.testing.assert_array_equal(archive.saved_times(saved), sol.times)
