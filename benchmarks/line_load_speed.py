"""Line loads (``Model.add_line_load``): the compiled kernel (``elements.line_load_jit``, the default) against
the numpy form (``line_load.use_numpy``), CPU time per evaluation of the nodal loads, with and without their
stiffness, on random curved elements (the bending fixture of a 4-lay strand at 48 el/lay has 1344).

    python benchmarks/line_load_speed.py [--sizes 100 1344 10000] [--repeat 5]
"""
import argparse
import time

import numpy as np

from beamsolver import se3
from beamsolver.elements import line_load


def _best(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 1344, 10000])
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    rng = np.random.default_rng(0)
    print("| elements | stiffness | numpy [ms] | compiled [ms] | us per element (compiled) | ratio |")
    print("|---:|---|---:|---:|---:|---:|")
    for n in a.sizes:
        HA = se3.exp(rng.normal(size=(n, 6)))
        HB = HA @ se3.exp(0.05 * rng.normal(size=(n, 6)))
        L, q, m = rng.uniform(0.5, 2.0, n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
        for tangent in (False, True):
            fn = line_load.nodal_loads_and_tangent if tangent else line_load.nodal_loads
            fn(HA, HB, L, q, m)                      # compile / warm
            tc = _best(lambda: fn(HA, HB, L, q, m), a.repeat)
            line_load.use_numpy(True)
            try:
                tn = _best(lambda: fn(HA, HB, L, q, m), max(1, a.repeat // 2))
            finally:
                line_load.use_numpy(False)
            print(f"| {n} | {'yes' if tangent else 'no'} | {1e3 * tn:.2f} | {1e3 * tc:.2f} | {1e6 * tc / n:.1f} | "
                  f"{tn / tc:.1f} |", flush=True)


if __name__ == "__main__":
    main()
