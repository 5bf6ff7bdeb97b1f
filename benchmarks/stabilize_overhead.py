"""Overhead and effect of ``solve(..., stabilize=2e-4)`` on stable problems.

Each scene is solved without and with the viscous stabilisation, alternately,
``REPEATS`` times; the table gives the median wall times, their ratio, the total
Newton iterations of each, the stabilised answer's relative change (a tip or
plate position, or the twisted pair's torque) and the dissipated fraction
reported at the last step.  Prints a Markdown table; nothing is written.

    python benchmarks/stabilize_overhead.py [--quick]
"""
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402

REPEATS = 3
FRACTION = 2e-4


def cantilever(n):
    """Clamped steel cantilever of ``n`` elements under a dead tip force bending it by about 40 degrees."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=2e11)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 2.0 * sec.C[4, 4]))
    return m, lambda sol: sol.position(b.last)


def joined(n):
    """The same cantilever made of two joined beams (plain Newton updates, damped)."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=2e11)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0.5, 0, 0), n // 2), sec)
    b = m.add_beam(bs.geometry.straight((0.5, 0, 0), (1, 0, 0), n // 2), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, 0, 2.0 * sec.C[4, 4]))
    return m, lambda sol: sol.position(b.last)


def pair(n):
    """The 20 mm twisted pair (``examples/twisted_pair_extreme.py``) to 1 turn, below its instability."""
    import twisted_pair_extreme as tp
    m, plate, _ = tp.build(n_elements=n, turns=1.0)
    return m, lambda sol: np.array([sol.reaction(plate)[5]])


def run(build, n, steps, stabilize):
    model, answer = build(n)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, verbose=False, stabilize=stabilize)
    return time.perf_counter() - t0, sol, answer(sol)


def main(quick=False):
    scenes = [("cantilever", cantilever, (16, 256) if quick else (16, 128, 1024), 8),
              ("joined cantilever", joined, (16,) if quick else (16, 128), 8),
              ("twisted pair, 1 turn", pair, (16,), 8)]
    rows = []
    for name, fn, sizes, steps in scenes:
        for n in sizes:
            plain, damped = [], []
            for _ in range(1 if quick else REPEATS):
                t, sp, a = run(fn, n, steps, None)
                plain.append(t)
                t, sd, b = run(fn, n, steps, FRACTION)
                damped.append(t)
            change = np.linalg.norm(b - a) / np.linalg.norm(a)
            frac = sd.stats[-1]["stabilization"]["fraction"]
            rows.append((name, n, np.median(plain), np.median(damped), int(sp.iterations.sum()),
                         int(sd.iterations.sum()), change, frac))
    print(f"stabilize={FRACTION:g}; median of {1 if quick else REPEATS} alternating runs")
    print("| scene | elements | solve [s] | stabilised [s] | ratio | iterations (plain / stab.) "
          "| answer change | dissipated fraction |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, n, a, b, ia, ib, change, frac in rows:
        print(f"| {name} | {n} | {a:.3f} | {b:.3f} | {b / a:.2f} | {ia} / {ib} | {change:.2e} | {frac:.2e} |")
    return rows


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
