"""Cost of the material-range check per converged step (``material_range.RangeCheck.check``).

For ``n_el`` elements (random strains around the reference, one beam with a yield stress)
the time of one check, the step's largest utilisation and warning test, best of ``--repeat`` runs; a
section without a limit skips it (``RangeCheck.of`` is ``None``).  Compare with the
main job's step: about 0.05 s for 64 elements (``python examples/twisted_pair.py``).

    python benchmarks/material_range_cost.py [--elements 64,1000,10000,100000] [--repeat 20]
"""
import argparse
import time
import warnings

import numpy as np

import beamsolver as bs
from beamsolver.model.material_range import RangeCheck


def description(n_el, yield_stress):
    model = bs.Model()
    sec = bs.Section.circular(radius=0.5e-3, E=200e9, yield_stress=yield_stress)
    model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n_el), sec, name="wire")
    return bs.Solution(model).description


def main(elements=(64, 1000, 10000, 100000), repeat=20):
    rng = np.random.default_rng(0)
    print("| elements | check per step [ms] | per element [ns] | without a limit |")
    print("|---:|---:|---:|---|")
    for n in elements:
        check = RangeCheck.of(description(n, 1416e6))
        check.warned = True                       # time the check, not the warning
        none = RangeCheck.of(description(n, None))
        d = description(n, 1416e6)
        strains = d["eps0"] + 1e-3 * rng.standard_normal((n, 6)) * [1, 1, 1, 1e3, 1e3, 1e3]   # curvatures ~1/m
        best = np.inf
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for _ in range(repeat):
                t0 = time.perf_counter()
                check.check(strains, {}, 1)
                best = min(best, time.perf_counter() - t0)
        print(f"| {n} | {best * 1e3:.3f} | {best / n * 1e9:.0f} | {'skipped (None)' if none is None else 'checked'} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", default="64,1000,10000,100000")
    ap.add_argument("--repeat", type=int, default=20)
    a = ap.parse_args()
    main(tuple(int(x) for x in a.elements.split(",")), a.repeat)
