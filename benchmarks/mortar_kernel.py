"""CPU of exact stick's compiled mortar kernel per call, in the twisted pair's solve (issue 30).

``python benchmarks/mortar_kernel.py [--sizes 16,128] [--rounds 3] [--ref DIR]``

Each tree (this one, and ``DIR`` if given: another checkout with warm numba caches) runs in its own processes,
``--rounds`` of them alternating between the trees.  In a process, per size: ``twisted_pair.build(n_elements=n)``
solved once (warm-up), then once more with ``kernel_jit.mortar_terms`` (with the tangent) and
``kernel_jit.mortar_forces`` (forces only: the line-search trials) timed by wrapping them, and the compiled kernel
alone (the function ``kernel_jit.make_kernel`` returns for the mortar kernel) split by the tangent it computes.
Per tree the least over the rounds of: the solve's CPU, ms per ``mortar_terms`` and ``mortar_forces`` call, and
ms per kernel call with and without the tangent.  One thread, CPU time (``time.process_time``); Markdown on stdout.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import single_thread, table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
clock = time.process_time
COLUMNS = ("solve_s", "terms_ms", "forces_ms", "kernel_tangent_ms", "kernel_forces_ms")


def _timer(acc, key, f):
    """``f`` timed into ``acc[key] = [seconds, calls]``."""
    def g(*a, **k):
        t = clock()
        try:
            return f(*a, **k)
        finally:
            s = acc.setdefault(key, [0.0, 0])
            s[0] += clock() - t
            s[1] += 1
    return g


def child(root, sizes):
    """One process's measurements per size (JSON on stdout), the package and examples of ``root``."""
    single_thread()
    for var in ("NUMBA_NUM_THREADS",):
        os.environ[var] = "1"
    sys.path.insert(0, str(Path(root) / "examples"))
    import beamsolver as bs
    import twisted_pair as tp
    from beamsolver.contact import kernel_jit

    terms, forces, make = kernel_jit.mortar_terms, kernel_jit.mortar_forces, kernel_jit.make_kernel
    out = {}
    for n in sizes:
        bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
        acc = {}

        def made(law, mortar=False):
            kern = make(law, mortar)
            if mortar is not True:
                return kern

            def timed(*a):      # ``a[7]``, ``a[8]``: the forces (empty: point data only), the tangents (empty: none)
                key = "kernel_tangent" if a[8].shape[-1] else "kernel_forces" if a[7].shape[0] else "kernel_data"
                return _timer(acc, key, kern)(*a)
            return timed
        kernel_jit.mortar_terms = _timer(acc, "terms", terms)
        kernel_jit.mortar_forces = _timer(acc, "forces", forces)
        kernel_jit.make_kernel = made
        try:
            t = clock()
            sol = bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
            solve = clock() - t
        finally:
            kernel_jit.mortar_terms, kernel_jit.mortar_forces, kernel_jit.make_kernel = terms, forces, make
        row = dict(solve_s=solve, its=sum(s["iterations"] for s in sol.stats))
        for key in ("terms", "forces", "kernel_tangent", "kernel_forces"):
            s, c = acc.get(key, [0.0, 0])
            row[key + "_ms"], row[key + "_calls"] = 1e3 * s / max(c, 1), c
        out[n] = row
    print(json.dumps(out))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,128")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ref", help="another checkout (warm numba caches) measured alternately")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",")]
    if a.child:
        return child(a.child, sizes)
    trees = [("this tree", ROOT)] + ([(a.ref, Path(a.ref))] if a.ref else [])
    best = {}
    for _ in range(a.rounds):
        for name, root in trees:
            env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1", "NUMBA_NUM_THREADS": "1"}
            res = subprocess.run([sys.executable, __file__, "--child", str(root), "--sizes", a.sizes], env=env,
                                 capture_output=True, text=True, cwd=str(root), check=True)
            for n, row in json.loads(res.stdout.strip().splitlines()[-1]).items():
                b = best.setdefault((name, int(n)), row)
                for k in COLUMNS:
                    b[k] = min(b[k], row[k])
    def cell(r, key):
        return f"{r[key + '_ms']:.3f} ({r[key + '_calls']})"
    rows = [(f"{n}", name, r["its"], r["solve_s"], cell(r, "terms"), cell(r, "forces"), cell(r, "kernel_tangent"),
             cell(r, "kernel_forces"))
            for (name, n), r in sorted(best.items(), key=lambda x: (x[0][1], x[0][0] != "this tree"))]
    print(table(("el/wire", "tree", "iterations", "solve [s]", "mortar_terms [ms] (calls)",
                 "mortar_forces [ms] (calls)", "kernel, tangent [ms] (calls)", "kernel, forces only [ms] (calls)"),
                rows, fmt={3: ".3f"}))
    return best


if __name__ == "__main__":
    main()
