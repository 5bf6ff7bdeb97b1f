"""CPU of one Newton evaluation of the twisted pair, forces only (line-search trials) and with the tangent.

``python benchmarks/evaluation_cpu.py [--elements 16] [--rounds 3] [--ref DIR]``

Each tree (this one, and ``DIR`` if given: another checkout with warm numba caches) runs in its own processes,
``--rounds`` of them alternating.  In a process: ``twisted_pair.build(n_elements=...)`` solved once (warm-up), then
three times with ``Newton.evaluate`` timed by wrapping it (process CPU, one thread); per tree the least over solves
and rounds of the solve's CPU and of the mean CPU of its evaluations without and with the tangent (issue 30 item 3:
the glue around the compiled kernels, docs/benchmarks.md "Contact evaluation glue, session 16").
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import single_thread  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
clock = time.process_time


def child(root, n):
    """One process's least ``(solve s, forces ms, calls, tangent ms, calls)`` (JSON on stdout)."""
    single_thread()
    sys.path.insert(0, str(Path(root) / "examples"))
    import beamsolver as bs
    import twisted_pair as tp
    from beamsolver.nonlinear import newton

    bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
    evaluate, acc = newton.Newton.evaluate, {}

    def timed(self, H, t, tangent=True):
        t0 = clock()
        try:
            return evaluate(self, H, t, tangent)
        finally:
            a = acc.setdefault(bool(tangent), [0.0, 0])
            a[0] += clock() - t0
            a[1] += 1
    newton.Newton.evaluate = timed
    best = None
    for _ in range(3):
        acc.clear()
        t0 = clock()
        bs.solve(tp.build(n_elements=n)[0], steps=16, verbose=False)
        row = [clock() - t0, 1e3 * acc[False][0] / acc[False][1], acc[False][1],
               1e3 * acc[True][0] / acc[True][1], acc[True][1]]
        best = row if best is None else [min(a, b) for a, b in zip(best, row)]
    print(json.dumps(best))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ref", help="another checkout (warm numba caches) measured alternately")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        return child(a.child, a.elements)
    trees = [("this tree", ROOT)] + ([(a.ref, Path(a.ref))] if a.ref else [])
    best = {}
    for _ in range(a.rounds):
        for name, root in trees:
            env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
            res = subprocess.run([sys.executable, __file__, "--child", str(root), "--elements", str(a.elements)],
                                 env=env, capture_output=True, text=True, cwd=str(root), check=True)
            row = json.loads(res.stdout.strip().splitlines()[-1])
            best[name] = row if name not in best else [min(x, y) for x, y in zip(best[name], row)]
    print(f"| tree | solve [s] | forces only [ms] (evaluations) | with tangent [ms] (evaluations) |\n|---|---:|---:|---:|")
    for name, (s, f, nf, k, nk) in best.items():
        print(f"| {name} | {s:.3f} | {f:.3f} ({nf}) | {k:.3f} ({nk}) |")
    return best


if __name__ == "__main__":
    main()
