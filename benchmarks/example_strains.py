"""Largest strain of every example, as ``beamsolver run examples/NAME.py`` solves it.

Each example's ``build()`` with its defaults and its ``solve_options`` (as the command line
runs it); per example: the material its docstring states, the largest von Mises equivalent
surface strain over all steps and elements (``Solution.equivalent_strain``,
docs/theory_material_range.md), the largest utilisation where a section has a limit, the
wall time.  ``plectoneme`` runs 2.2 turns instead of 5 (``--full``: as given, minutes).

    python benchmarks/example_strains.py [--only twisted_pair,bend45] [--full]
"""
import argparse
import runpy
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))

import beamsolver as bs  # noqa: E402

MATERIAL = {        # what each example's docstring states, in a few words
    "twisted_pair": "steel wire grade 1770, yield 1416 MPa",
    "twisted_pair_extreme": "elastic rod, steel moduli, no limit (benchmark)",
    "plectoneme": "elastic rod, steel moduli, no limit (benchmark)",
    "three_wires": "elastic rod, steel moduli, no limit (contact test)",
    "seven_wire_strand": "steel wire grade 1770, yield 1416 MPa",
    "strand_sweep": "steel wire grade 1770, yield 1416 MPa",
    "bend45": "dimensionless benchmark (E = 1e7), no limit",
    "roll_up": "elastic, steel moduli, no limit (benchmark)",
    "capstan": "rope EA/EI given, post E = 1 GPa, no limit",
    "crossing_beams": "E = 1e7, no limit (benchmark)",
    "rolling": "E = 1 GPa, no limit (benchmark)",
    "limit_points": "dimensionless benchmarks, no limit",
}
QUICK = {"plectoneme": dict(turns=2.2, steps=22)}


def largest(name, full=False):
    """``(largest equivalent strain, largest utilisation or nan, steps, wall)`` of example ``name``."""
    ns = runpy.run_path(str(ROOT / "examples" / f"{name}.py"), run_name="example")
    opts = dict(ns.get("solve_options") or {})
    kw = {} if full else dict(QUICK.get(name, {}))
    steps = kw.pop("steps", None)
    if steps is not None:
        opts["steps"] = steps
    out = ns["build"](**kw)
    model = out[0] if isinstance(out, tuple) else out
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            sol = bs.solve(model, verbose=False, **opts)
        except bs.ConvergenceError as e:
            sol = e.solution
    wall = time.perf_counter() - t0
    eq = max(float(sol.equivalent_strain(k).max()) for k in range(len(sol)))
    limited = np.isfinite(sol.description["beam_yield_stress"]).any() or \
        np.isfinite(sol.description["beam_yield_strain"]).any()
    u = max(float(s.get("utilisation", 0.0)) for s in sol.stats) if limited else np.nan
    return eq, u, len(sol) - 1, wall


def main(names, full=False):
    print("| example | material | largest equivalent strain | utilisation | steps | solve [s] |")
    print("|---|---|---:|---:|---:|---:|")
    for name in names:
        eq, u, steps, wall = largest(name, full)
        us = "-" if np.isnan(u) else f"{u:.2f}"
        print(f"| {name} | {MATERIAL.get(name, '?')} | {eq:.3g} | {us} | {steps} | {wall:.2f} |", flush=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default=",".join(MATERIAL))
    ap.add_argument("--full", action="store_true")
    a = ap.parse_args()
    main(a.only.split(","), a.full)
