"""Shear lag with Coulomb friction (examples/shear_lag.py): Newton iterations against the answer's error, exact
stick (the default) and the penalty stick over its ``slip_tolerance`` (issue 26: iterations at equal accuracy).

    python benchmarks/shear_lag_accuracy.py [--meshes 10 20] [--tolerances 0.005 1e-3 1e-4 1e-5 1e-6]

Error: the largest difference of the wire's axial force from the closed form ``N = mu q (x - (L - a))`` (F = 15 N)
and the slip zone read from the stick flags (closed form ``a = F / (mu q)`` = 0.5).  CPU by ``time.process_time``.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import shear_lag as sl  # noqa: E402


def row(n, **options):
    model, wire, rod = sl.build(n_wire=n, **options)
    c0 = time.process_time()
    sol = bs.solve(model, steps=sl.solve_options["steps"])
    cpu = time.process_time() - c0
    x, N = sl.axial_force(sol, wire)
    a = 15.0 / (0.3 * 100.0)
    err = np.abs(N - np.maximum(0.3 * 100.0 * (x - (1.0 - a)), 0.0)).max()
    return int(sol.iterations.sum()), [int(i) for i in sol.iterations], sl.slip_zone(sol, wire), err, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", type=int, nargs="+", default=[10, 20])
    ap.add_argument("--tolerances", type=float, nargs="+", default=[0.005, 1e-3, 1e-4, 1e-5, 1e-6])
    a = ap.parse_args()
    print("| stick | slip_tolerance | wire elements | Newton it. (per step) | slip zone (0.5) | max abs(N - N_exact) [N] of 15 | CPU [s] |")
    print("|---|---:|---:|---|---:|---:|---:|")
    cases = [("exact (default)", None, {})] + [("penalty", t, dict(stick="penalty", slip_tolerance=t)) for t in a.tolerances]
    for name, tol, opts in cases:
        for n in a.meshes:
            its, per, zone, err, cpu = row(n, **opts)
            print(f"| {name} | {'-' if tol is None else f'{tol:g}'} | {n} | {its} ({', '.join(map(str, per))}) "
                  f"| {zone:.4f} | {err:.3g} | {cpu:.2f} |", flush=True)


if __name__ == "__main__":
    main()
