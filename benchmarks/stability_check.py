"""Overhead of ``solve(..., check_stability=True)`` and of ``modes=3`` on stable problems.

Each scene (a clamped cantilever under a tip force, the same made of two joined
beams, a column at 0.9 times its Euler load) is solved in 8 load steps without
the check, with it, and with it and the three lowest modes per step
(``modes=3``), in turn, ``REPEATS`` times; the table gives the median wall time
of each and its ratio to the plain solve, and, timed alone on the last step's
tangent (``bs.linearize``), the cost of one check (``negative_eigenvalues``) and
of one ``lowest_modes(K, 3)`` in milliseconds.  The number of unknowns decides
the path: dense LAPACK up to ``definiteness.DENSE_MAX``, above it a banded
Cholesky / shift-invert Lanczos with banded LU when the reordered tangent is
banded (``bandfactor``), else SuperLU.  The plain solves take 2-3 Newton
iterations per step, so a fixed per-step cost weighs more at small sizes.
BLAS runs on one thread (``_report.single_thread``).  Prints a Markdown table;
nothing is written.

    python benchmarks/stability_check.py [--quick]
"""
import sys
import time

from _report import single_thread

single_thread()   # a BLAS pool on a shared 2-core machine makes a 96 x 96 dense eigh 100 times slower

import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
from beamsolver.nonlinear.definiteness import negative_eigenvalues  # noqa: E402
from beamsolver.nonlinear.modes import lowest_modes  # noqa: E402

REPEATS = 3


def cantilever(n, force=2e3):
    """Clamped steel cantilever of ``n`` elements, dead tip force (strain-space update)."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, force))
    return m


def joined(n, force=2e3):
    """The same cantilever made of two joined beams (plain Newton updates, damped)."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=2e11)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0.5, 0, 0), n // 2), sec)
    b = m.add_beam(bs.geometry.straight((0.5, 0, 0), (1, 0, 0), n // 2), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, 0, force))
    return m


def column(n):
    """Clamped column under 0.9 times its Euler load (stable, lowest eigenvalue near zero)."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=2e11)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(-0.9 * np.pi**2 * sec.C[4, 4] / 4, 0, 1.0))
    return m


def timed(build, steps, check, modes=0):
    model = build()
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, verbose=False, check_stability=check, modes=modes)
    return time.perf_counter() - t0, sol


def alone(build, sol, repeats=7):
    """Median milliseconds of one check and of one ``lowest_modes(K, 3)`` on the tangent of the last step."""
    K = bs.linearize(build(), sol).K
    out = []
    for f in (lambda: negative_eigenvalues(K), lambda: lowest_modes(K, 3)):
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t0)
        out.append(1e3 * np.median(ts))
    return out


def main(quick=False):
    sizes = (16, 256) if quick else (16, 128, 1024)
    rows = []
    for name, fn in (("cantilever", cantilever), ("joined cantilever", joined), ("column 0.9 P_E", column)):
        for n in sizes:
            plain, checked, moded = [], [], []
            for _ in range(1 if quick else REPEATS):
                plain.append(timed(lambda: fn(n), 8, False)[0])
                checked.append(timed(lambda: fn(n), 8, True)[0])
                t, sol = timed(lambda: fn(n), 8, True, modes=3)
                moded.append(t)
            stable = all(s["stable"] for s in sol.stats[1:])
            one = alone(lambda: fn(n), sol)
            rows.append((name, n, 6 * n, np.median(plain), np.median(checked), np.median(moded), stable, *one))
    print("| scene | elements | unknowns | solve [s] | with check [s] | ratio | with modes=3 [s] | ratio | all stable "
          "| one check [ms] | one modes=3 [ms] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|")
    for name, n, dofs, a, b, c, stable, one, three in rows:
        print(f"| {name} | {n} | {dofs} | {a:.3f} | {b:.3f} | {b / a:.2f} | {c:.3f} | {c / a:.2f} | {stable} "
              f"| {one:.2f} | {three:.2f} |")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
