"""Expansion of saved results: bytes the members of ``solution.npz`` declare uncompressed over the
file's size (what ``solution_file.MAX_EXPANSION`` bounds against archive bombs), and the time
``check_members`` adds to ``beamsolver.load``.

Scenes: a cantilever at rest over many steps (zeros compress best: the worst legitimate case),
a loaded cantilever, the rolling contact scene and the capstan (line contact, friction), and a
crafted bomb (a valid file whose ``reactions`` member declares 1 GiB of zeros).  Run:
``python benchmarks/archive_expansion.py [--write]``; prints a table (``--write``: also the
``archive_expansion`` section of docs/benchmarks.md).
"""
import sys
import tempfile
import time
import warnings
import zipfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
from beamsolver.results import solution_file# noqa: E402

from _report import machine, table, write_section  # noqa: E402


def cantilever(load, n=20):
    sec = bs.Section.circular(radius=1e-2, E=200e9, nu=0.3)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0))
    return m


def scenes():
    import capstan
    import rolling
    yield "cantilever at rest, 20 el., 400 steps", cantilever(0.0), dict(steps=400)
    yield "cantilever loaded, 20 el., 50 steps", cantilever(1e3), dict(steps=50)
    yield "rolling (contact, mu 0.5), 8 steps", rolling.build(mu=0.5, n_elements=3)[0], dict(steps=8)
    yield "capstan (line contact), 8 steps", capstan.build(n_arc=12)[0], dict(steps=8)


def bomb(path, source, gib=1.0):
    """``source``'s members, ``reactions`` replaced by a member declaring ``gib`` GiB of zeros."""
    n = int(gib * 2**30 // 8)
    header = np.lib.format.header_data_from_array_1_0(np.zeros(0))
    header["shape"] = (n,)
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as out:
        for info in src.infolist():
            if info.filename != "reactions.npy":
                out.writestr(info.filename, src.read(info))
                continue
            with out.open("reactions.npy", "w", force_zip64=True) as f:
                np.lib.format.write_array_header_1_0(f, header)
                chunk = bytes(2**24)
                for _ in range(n * 8 // len(chunk)):
                    f.write(chunk)


def measure(path):
    declared = sum(i.file_size for i in zipfile.ZipFile(path).infolist())
    size = path.stat().st_size
    t0 = time.perf_counter()
    with open(path, "rb") as f:
        try:
            solution_file.check_members(f, str(path))
            verdict = "loads"
        except bs.InputError:
            verdict = "refused"
    t_check = time.perf_counter() - t0
    t_load = np.nan
    if verdict == "loads":
        t0 = time.perf_counter()
        bs.load(path)
        t_load = time.perf_counter() - t0
    return declared, size, t_check, t_load, verdict


def main(write=False):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, model, kw in scenes():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = bs.solve(model, verbose=False, **kw)
            path = sol.save(tmp / "s.npz")
            d, s, tc, tl, verdict = measure(path)
            rows.append([name, d / 2**20, s / 2**20, d / s, 1e3 * tc, 1e3 * tl, verdict])
        bomb(tmp / "bomb.npz", path)
        d, s, tc, tl, verdict = measure(tmp / "bomb.npz")
        rows.append(["crafted: reactions declares 1 GiB of zeros", d / 2**20, s / 2**20, d / s, 1e3 * tc, tl,
                     verdict])
    text = table(["archive", "declared [MiB]", "file [MiB]", "expansion", "check [ms]", "load [ms]", "verdict"],
                 rows, {1: ".3f", 2: ".3f", 3: ".1f", 4: ".2f", 5: ".1f"})
    print(text)
    if write:
        write_section("archive_expansion", f"""## Archive expansion (`python benchmarks/archive_expansion.py`)

{machine()}. Bytes the members of a saved result declare uncompressed over the file's size; `bs.load`
refuses an archive declaring more than `MAX_PLAIN` = {solution_file.MAX_PLAIN // 2**20} MiB and more than
`MAX_EXPANSION` = {solution_file.MAX_EXPANSION:g} times its size, reading headers only (check column).

{text}""")


if __name__ == "__main__":
    main(write="--write" in sys.argv)
