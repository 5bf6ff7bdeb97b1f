"""``bs.load`` checks an archive's members before it decompresses them (issue 28 item 14): unknown
members, sizes that disagree with the .npy headers, and archives declaring far more than their size
(a crafted 3.1 MB file cost 3.0 GB of memory) are refused, also through ``restart=`` and
``beamsolver info``."""
import subprocess
import sys
import tracemalloc
import zipfile

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.results import solution_file


def _model():
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 1.0, 0))
    return m


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    return bs.solve(_model(), steps=2, verbose=False).save(tmp_path_factory.mktemp("a") / "s.npz")


def _rewrite(source, path, replace=None, add=None):
    """``source``'s members, ``replace[name](zip_file)`` writing the named member instead, ``add`` extra ones."""
    replace = replace or {}
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as out:
        for info in src.infolist():
            if info.filename in replace:
                replace[info.filename](out)
            else:
                out.writestr(info.filename, src.read(info))
        for name, data in (add or {}).items():
            out.writestr(name, data)
    return path


def _zeros(name, n_bytes):
    """A member ``name`` of ``n_bytes`` float zeros, streamed (never held in memory)."""
    def write(out):
        header = np.lib.format.header_data_from_array_1_0(np.zeros(0))
        header["shape"] = (n_bytes // 8,)
        with out.open(name, "w", force_zip64=True) as f:
            np.lib.format.write_array_header_1_0(f, header)
            chunk = bytes(2**20)
            for _ in range(n_bytes // len(chunk)):
                f.write(chunk)
    return write


def test_bomb_is_refused_before_decompressing(saved, tmp_path, monkeypatch):
    monkeypatch.setattr(solution_file, "MAX_PLAIN", 2**20)          # scaled down: 64 MiB stand for gigabytes
    bomb = _rewrite(saved, tmp_path / "bomb.npz", {"reactions.npy": _zeros("reactions.npy", 64 * 2**20)})
    assert bomb.stat().st_size < 2**20
    tracemalloc.start()
    try:
        with pytest.raises(bs.InputError, match="archive bomb"):
            bs.load(bomb)
        with pytest.raises(bs.InputError, match="archive bomb"):
            bs.solve(_model(), steps=4, restart=bomb, verbose=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 8 * 2**20                                         # was: the 64 MiB member, and more


def test_unknown_member_and_lying_sizes_are_refused(saved, tmp_path):
    extra = _rewrite(saved, tmp_path / "extra.npz", add={"payload.npy": b"x" * 100})
    with pytest.raises(bs.InputError, match="unknown member 'payload.npy'"):
        bs.load(extra)
    text = _rewrite(saved, tmp_path / "text.npz", add={"model/notes.txt": b"x"})
    with pytest.raises(bs.InputError, match="unknown member 'model/notes.txt'"):
        bs.load(text)

    def lying(out):                           # the header promises 1 GiB, the member holds 8 bytes
        header = np.lib.format.header_data_from_array_1_0(np.zeros(0))
        header["shape"] = (2**27,)
        with out.open("reactions.npy", "w") as f:
            np.lib.format.write_array_header_1_0(f, header)
            f.write(bytes(8))
    liar = _rewrite(saved, tmp_path / "liar.npz", {"reactions.npy": lying})
    with pytest.raises(bs.InputError, match="'reactions.npy' declares"):
        bs.load(liar)


@pytest.mark.slow
def test_cli_info_refuses_a_bomb(saved, tmp_path):
    bomb = _rewrite(saved, tmp_path / "bomb.npz", {"poses.npy": _zeros("poses.npy", 300 * 2**20)})
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "info", str(bomb)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 1 and "archive bomb" in out.stderr and "Traceback" not in out.stderr


def test_saved_results_still_load(saved):
    assert bs.load(saved).n_steps == 2
    assert list(solution_file.saved_times(saved)) == [0.0, 0.5, 1.0]
