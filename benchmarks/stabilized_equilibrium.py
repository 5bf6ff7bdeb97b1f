"""The final verdict of stabilised runs (docs/theory_stabilized_equilibrium.md): the shallow
sinusoidal arch of ``examples/limit_points.shallow_arch`` (32 elements, total load 10 N, 10 load
steps) solved plainly and with ``stabilize=`` variants; per run the status, the midspan node's
displacement and the undamped scaled residual of the final state.  Run:
``python benchmarks/stabilized_equilibrium.py``; prints a table.
"""
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
from limit_points import shallow_arch  # noqa: E402

from _report import machine, table  # noqa: E402

LOAD = 10.0                     # N: the total of q sin(pi x / L) over the span, 2 q L / pi
VARIANTS = (None, dict(factor=1e3), dict(factor=1e3, settle=True), True, dict(settle=True))


def run(stabilize):
    model, mid, _ = shallow_arch(32, load=LOAD * np.pi / 2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = bs.solve(model, steps=10, stabilize=stabilize, verbose=False)
    rec = sol.stats[-1].get("stabilization", {})
    return [str(stabilize), sol.status, float(np.linalg.norm(sol.position(mid) - sol.position(mid, 0))),
            rec.get("undamped_residual", "-"), sol.stats[-1].get("settle", {}).get("iterations", "-")]


def main():
    rows = [run(v) for v in VARIANTS]
    print(machine())
    print(table(["stabilize", "status", "midspan displacement [m]", "undamped residual", "settle iterations"],
                rows, {2: ".4g", 3: ".3g"}))


if __name__ == "__main__":
    main()
