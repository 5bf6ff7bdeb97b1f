"""The Newton direction's glue (issue 30 item 3): CPU of ``Newton.direction`` per call on the twisted pair, and what
of it is not the linear solver's factorisations and factor solves.

``python benchmarks/direction_glue.py [--ref DIR] [--rounds 3] [--sizes 16,128] [--solves 3]``

Each tree (this one, and ``DIR`` if given: another checkout with warm numba caches) runs in its own processes,
``--rounds`` of them alternating between the trees.  A process solves ``twisted_pair.build(n_elements=n)`` (16
steps) once to warm up, then ``--solves`` times, timing every ``Newton.direction`` call and, inside it, every call
of ``linsolve.factorize_tangent`` and of a factor's ``solve`` / ``apply`` (the outermost only: a factor calling
another is counted once); the glue is the difference.  Per size: the solve with the least glue, then the least over
the rounds.  Single thread, CPU time (``time.process_time``); Markdown on stdout (no section of docs/benchmarks.md).
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
FACTORS = ("_DenseFactor", "_SpluFactor", "_SpluRcmFactor", "_Pardiso", "_PardisoFactor")


def child(root, sizes, solves):
    """One process's ``{size: (direction ms, linear solver ms, glue ms, calls)}`` per direction (JSON on stdout)."""
    single_thread()
    import beamsolver as bs
    from beamsolver.nonlinear import augmented, linsolve, newton
    sys.path.insert(0, str(Path(root) / "examples"))
    import twisted_pair as tp
    acc = dict(direction=0.0, linear=0.0, calls=0)
    depth = [0]

    def timed(f, key):
        def g(*a, **k):
            if depth[0]:
                return f(*a, **k)
            depth[0] += 1
            t = clock()
            try:
                return f(*a, **k)
            finally:
                acc[key] += clock() - t
                depth[0] -= 1
        return g
    linsolve.factorize_tangent = augmented.factorize_tangent = timed(linsolve.factorize_tangent, "linear")
    for name in FACTORS:
        cls = getattr(linsolve, name, None)
        for m in ("solve", "apply"):
            if cls is not None and m in cls.__dict__:
                setattr(cls, m, timed(cls.__dict__[m], "linear"))
    direction = newton.Newton.direction

    def timed_direction(self, *a, **k):
        t = clock()
        try:
            return direction(self, *a, **k)
        finally:
            acc["direction"] += clock() - t
            acc["calls"] += 1
    newton.Newton.direction = timed_direction
    out = {}
    for n in sizes:
        bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
        best = None
        for _ in range(solves):
            acc.update(direction=0.0, linear=0.0, calls=0)
            bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
            c = acc["calls"]
            row = (1e3 * acc["direction"] / c, 1e3 * acc["linear"] / c, 1e3 * (acc["direction"] - acc["linear"]) / c, c)
            best = row if best is None or row[2] < best[2] else best
        out[str(n)] = best
    print(json.dumps(out))


def run(root, sizes, solves):
    env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
    res = subprocess.run([sys.executable, __file__, "--child", str(root), "--sizes", ",".join(map(str, sizes)),
                          "--solves", str(solves)], env=env, capture_output=True, text=True, cwd=str(root))
    if res.returncode:
        raise RuntimeError(f"{root}: {res.stderr[-2000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", help="another checkout (warm numba caches) measured alternately")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", default="16,128")
    ap.add_argument("--solves", type=int, default=3)
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",") if s]
    if a.child:
        return child(a.child, sizes, a.solves)
    trees = [("this tree", ROOT)] + ([(a.ref, Path(a.ref))] if a.ref else [])
    best = {name: {} for name, _ in trees}
    for r in range(a.rounds):
        for name, root in trees:
            for n, row in run(root, sizes, a.solves).items():
                if n not in best[name] or row[2] < best[name][n][2]:
                    best[name][n] = row
            print(f"round {r}: {name}: {best[name]}", file=sys.stderr, flush=True)
    rows = [(name, f"{n} el/wire", *best[name][str(n)]) for n in sizes for name, _ in trees]
    print(table(["tree", "size", "direction [ms]", "linear solver [ms]", "glue [ms]", "calls"], rows,
                fmt={2: ".3f", 3: ".3f", 4: ".3f"}))
    return best


if __name__ == "__main__":
    main()
