"""PARDISO's start-up per process: loading pypardiso and making the first handle (issue 30 item 3).

pypardiso finds MKL's ``mkl_rt`` with ``find_library`` and, failing that (pip installs), a recursive glob of
``sys.prefix/lib*/**`` (site-packages included), once at its import (a module-level solver) and once more for
``linsolve``'s first handle.  ``linsolve._mkl_rt`` looks in ``lib`` alone and hands the path over
(``PYPARDISO_MKL_RT``).  Fresh processes, interleaved: ``linsolve`` as it is, and with ``_mkl_rt`` disabled
(pypardiso's own search); wall and CPU seconds, median of ``--repeat``.

    python benchmarks/pardiso_startup.py [--repeat 5]
"""
import argparse
import json
import subprocess
import sys

import numpy as np

CODE = """
import json, os, sys, time
os.environ.pop("PYPARDISO_MKL_RT", None)
from beamsolver.nonlinear import linsolve
if sys.argv[1] == "search":
    linsolve._mkl_rt = lambda: None
t, c = time.perf_counter(), time.process_time()
linsolve._pardiso_handle(linsolve._pypardiso())
print(json.dumps([time.perf_counter() - t, time.process_time() - c]))
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    runs = {"lib look-up (linsolve._mkl_rt)": [], "pypardiso's recursive search": []}
    for _ in range(a.repeat):
        for mode, key in (("lookup", "lib look-up (linsolve._mkl_rt)"), ("search", "pypardiso's recursive search")):
            out = subprocess.run([sys.executable, "-c", CODE, mode], capture_output=True, text=True, check=True)
            runs[key].append(json.loads(out.stdout.strip().splitlines()[-1]))
    print("| MKL found by | wall [s] | CPU [s] |")
    print("|---|---:|---:|")
    for key, r in runs.items():
        w, c = np.median(np.array(r), axis=0)
        print(f"| {key} | {w:.3f} | {c:.3f} |")


if __name__ == "__main__":
    main()
