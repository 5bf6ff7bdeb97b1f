"""Cost of writing ParaView output per converged step, in ms per 1000 elements.

A scene of ``n_beams`` helical wires (no contact) is solved once; then each
step of the solution is written again with ``io.vtk.StepWriter`` (one
``.vtu`` + the ``.pvd``, atomic renames) for several element counts,
``refine`` values and compressions, and the ``solution.npz`` save is timed.
Times are the median over the steps (warm caches, local disk).

Writes ``benchmarks/results/output_overhead.md`` and ``.csv``.
"""
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import beamsolver as bs
from beamsolver.io.vtk import StepWriter

OUT = Path(__file__).resolve().parent / "results"


def scene(n_beams, n_elements):
    m = bs.Model()
    sec = bs.Section.circular(radius=1e-3, E=200e9)
    for i in range(n_beams):
        P = bs.geometry.helix(radius=5e-3, pitch=0.1, length=0.2, n_elements=n_elements,
                              phase=2 * np.pi * i / n_beams)
        P[:, 0, 3] += 0.02 * i
        b = m.add_beam(P, sec)
        m.clamp(b.first)
        m.add_load(b.last, force=(0.0, 0.0, 50.0))
    return m


def measure(sol, refine, compression, repeats):
    times = []
    with tempfile.TemporaryDirectory() as d:
        w = StepWriter(d, sol.system, refine=refine, compression=compression, checkpoint=None)
        for _ in range(repeats):
            for k in range(len(sol.times)):
                t0 = time.perf_counter()
                w.write(sol, k)
                times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main(quick=False):
    rows = []
    sizes = [(10, 100)] if quick else [(10, 100), (20, 250)]
    for n_beams, n_el in sizes:
        m = scene(n_beams, n_el)
        t0 = time.perf_counter()
        sol = bs.solve(m, steps=3)
        solve_step = (time.perf_counter() - t0) / 3
        n = n_beams * n_el
        for refine in (1, 8):
            for comp in ("zlib", None):
                t = measure(sol, refine, comp, 1 if quick else 3)
                rows.append(dict(elements=n, refine=refine, compression=str(comp), ms_per_step=1e3 * t,
                                 ms_per_1000_elements=1e3 * t / (n / 1000), solve_ms_per_step=1e3 * solve_step))
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            sol.save(Path(d) / "s.npz")
            t_save = time.perf_counter() - t0
        rows.append(dict(elements=n, refine="-", compression="npz save (all 4 steps)", ms_per_step=1e3 * t_save,
                         ms_per_1000_elements=1e3 * t_save / (n / 1000), solve_ms_per_step=1e3 * solve_step))
    OUT.mkdir(exist_ok=True)
    keys = list(rows[0])
    with open(OUT / "output_overhead.csv", "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.4g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + "\n")
    with open(OUT / "output_overhead.md", "w") as f:
        f.write("# Output overhead per converged step\n\n"
                "`python benchmarks/output_overhead.py` (2-core x86-64). One VTU + PVD per step with "
                "`StepWriter`; `refine` segments drawn per element; median over steps.\n\n")
        f.write("| " + " | ".join(keys) + " |\n|" + "---|" * len(keys) + "\n")
        for r in rows:
            f.write("| " + " | ".join(f"{r[k]:.3g}" if isinstance(r[k], float) else str(r[k]) for k in keys)
                    + " |\n")
    for r in rows:
        print(r)


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
