"""First run (numba compiles the kernels) versus cached runs, for a tiny solve and the main job.

Each job runs in a fresh Python process with ``NUMBA_CACHE_DIR`` pointing at an
empty temporary folder (first run: every kernel is compiled and written to the
cache), then twice more with the same folder (cached: the kernels are loaded,
nothing is compiled).  Jobs:

- ``tiny``: ``import beamsolver`` and a 2-element cantilever solved in one step
  (what compiling costs, and what loading the cache costs);
- ``main``: ``python examples/twisted_pair.py`` (the main job of the README),
  run in a temporary working folder so its output does not land here.

``python benchmarks/jit_startup.py [--skip-main]``; table on stdout and in the
section ``jit_startup`` of ``docs/benchmarks.md`` (unless ``--skip-main``).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

TINY = """
import beamsolver as bs
m = bs.Model()
b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), bs.Section.circular(radius=0.01, E=1e9))
m.clamp(b.first)
m.add_load(b.last, force=(0, 0, -1.0))
bs.solve(m, steps=1, verbose=False)
"""


def _run(args, cache, cwd):
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    out = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"{args} failed:\n{out.stderr[-2000:]}")
    return wall


def measure(name, args):
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
        first = _run(args, cache, cwd)
        cached = [_run(args, cache, cwd) for _ in range(2)]
    return dict(job=name, first=first, cached=min(cached), compile=first - min(cached))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--skip-main", action="store_true", help="only the tiny job (no docs update)")
    args = ap.parse_args(argv)
    jobs = [("tiny: import + 2-element solve", [sys.executable, "-c", TINY])]
    if not args.skip_main:
        jobs.append(("main: python examples/twisted_pair.py", [sys.executable, str(ROOT / "examples" / "twisted_pair.py")]))
    rows = [measure(*j) for j in jobs]
    from _report import machine, table, write_section
    md = table(["job", "first run [s] (compiles)", "cached run [s]", "first - cached [s]"],
               [(r["job"], f"{r['first']:.2f}", f"{r['cached']:.2f}", f"{r['compile']:.2f}") for r in rows])
    print(md)
    if not args.skip_main:
        write_section("jit_startup", f"""## First run (JIT compilation) vs cached runs

`python benchmarks/jit_startup.py` ({machine()})

Wall time of a fresh process; the first run starts from an empty numba cache (`NUMBA_CACHE_DIR`) and
compiles the kernels (`element_jit`, `assembly_jit`, `se3_jit`) into it, the cached runs (best of two)
load them. `tests/test_kernels_jit.py::test_second_process_loads_the_cache` checks that a cached run
compiles nothing.

{md}
""")
    return rows


if __name__ == "__main__":
    main()
