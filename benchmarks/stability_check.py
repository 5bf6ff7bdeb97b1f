"""Overhead of the stability check (on by default since issue 28 item 5) and of ``modes=3``.

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

``--scenes``: the default check (``check_stability=None``) against ``check_stability=False`` on the
project's scenes: the main job (``examples/twisted_pair.py``, friction: nothing is decided, only
the note is recorded) and its frictionless twin, Argyris' frame (``examples/limit_points.py``,
F = 1.5 N, 10 steps), a 256-element cantilever (8 steps) and a 19-wire 1+6+12 strand stretched
in 4 steps (``cables.build_strand``, half a lay, with and without friction).  The solves
alternate, ``REPEATS`` each; the table gives the medians, their ratio, and the time spent in
the check itself (``stability.StepCheck.tangent`` and ``record``, summed over the steps) as a
share of the checked solve: the ratio of two noisy wall times on a shared machine scatters by
several per cent, the share does not.

    python benchmarks/stability_check.py [--quick] [--scenes [--write]]
"""
import os
import sys
import time

from _report import single_thread

single_thread()   # a BLAS pool on a shared 2-core machine makes a 96 x 96 dense eigh 100 times slower

import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
from beamsolver.stepping.stability import StepCheck  # noqa: E402
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


def strand19(mu=0.3, eps=1e-4, lays=0.5, elements_per_lay=24):
    """1+6+12 strand (core 1.03 mm fitted, wires 1 mm, lay angle 10 deg, outer layer left-hand),
    clamped at the bottom, its top plate pulled to the strain ``eps``."""
    from beamsolver import cables
    Rc, Rw, beta = 1.03e-3, 1.0e-3, np.deg2rad(10.0)
    L = lays * 2 * np.pi * (Rc + Rw) / np.tan(beta)
    st = cables.build_strand([cables.Layer(Rc, 1), cables.Layer(Rw, 6, lay_angle=beta),
                              cables.Layer(Rw, 12, lay_angle=beta, direction="left")], L, 2e11, nu=0.3,
                             elements_per_lay=elements_per_lay, mu=mu, touch_tol=-0.5, fit_core=True)
    st.clamp("bottom")
    st.model.prescribe(st.plate("top"), bs.motion.translation((0.0, 0.0, eps * L)))
    return st.model


def _scenes():
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import twisted_pair
    from limit_points import argyris_frame
    return [("main job (twisted pair, mu 0.3)", lambda: twisted_pair.build()[0], 16),
            ("main job frictionless", lambda: twisted_pair.build(mu=0.0)[0], 16),
            ("Argyris frame F = 1.5 N", lambda: argyris_frame(1.5)[0], 10),
            ("cantilever, 256 elements", lambda: cantilever(256), 8),
            ("19-wire strand, mu 0.3", lambda: strand19(0.3), 4),
            ("19-wire strand frictionless", lambda: strand19(0.0), 4)]


class _Clock:
    """CPU seconds spent in ``StepCheck.tangent`` and ``StepCheck.record`` while installed."""

    def __init__(self):
        self.seconds = 0.0
        self.saved = (StepCheck.tangent, StepCheck.record)

    def __enter__(self):
        def timed(f):
            def wrapper(*a, **k):
                t0 = time.process_time()
                try:
                    return f(*a, **k)
                finally:
                    self.seconds += time.process_time() - t0
            return wrapper
        StepCheck.tangent, StepCheck.record = (timed(f) for f in self.saved)
        return self

    def __exit__(self, *exc):
        StepCheck.tangent, StepCheck.record = self.saved


def _run(build, steps, check):
    """``(wall, cpu, solution)`` of one solve (``check_stability=check``)."""
    m = build()
    t0, c0 = time.perf_counter(), time.process_time()
    sol = bs.solve(m, steps=steps, verbose=False, check_stability=check)
    return time.perf_counter() - t0, time.process_time() - c0, sol


def scenes(quick=False, write=False):
    """The default check against none on the project's scenes (module docstring): medians of wall
    and CPU times (CPU: the process's, which a loaded machine's waits do not stretch); ``write``:
    the table into docs/benchmarks.md (section ``stability_default``)."""
    repeats = 1 if quick else REPEATS + 2
    lines = ["| scene | unknowns | steps | stable (last step) | wall off [s] | wall default [s] | ratio "
             "| CPU off [s] | CPU default [s] | ratio | check CPU [ms] | share of CPU |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    print("\n".join(lines))
    for name, build, steps in _scenes():
        bs.solve(build(), steps=steps, verbose=False)                 # compiles, caches
        off, on, inside = [], [], []
        for _ in range(repeats):
            off.append(_run(build, steps, False)[:2])
            with _Clock() as clock:
                *t, sol = _run(build, steps, None)
            on.append(t)
            inside.append(clock.seconds)
        (wa, ca), (wb, cb), c = np.median(off, axis=0), np.median(on, axis=0), np.median(inside)
        n = bs.linearize(build(), sol).K.shape[0]
        last = sol.stats[-1]
        stable = last["stable"] if last["stable"] is not None else \
            "None (" + last["stable_note"].split(":")[1].strip() + ")"
        lines.append(f"| {name} | {n} | {sol.n_steps} | {stable} | {wa:.3f} | {wb:.3f} | {wb / wa:.3f} | {ca:.3f} | "
                     f"{cb:.3f} | {cb / ca:.3f} | {1e3 * c:.1f} | {c / cb:.2%} |")
        print(lines[-1], flush=True)
    if write:
        from _report import machine, write_section
        write_section("stability_default", "## The stability check of every step, on by default (issue 28 item 5)\n\n"
                      f"`python benchmarks/stability_check.py --scenes --write` ({machine()}, load average "
                      f"{os.getloadavg()[0]:.1f}; medians of {repeats} solves each, alternating)\n\n"
                      "Off: `check_stability=False`; default: every converged step's tangent checked "
                      "(`stepping.stability`, `definiteness.Inertia`). Wall times on a shared machine scatter by "
                      "several per cent; the CPU time spent in the check itself (`StepCheck.tangent` and `record`) "
                      "as a share of the solve's CPU time does not. Friction: nothing to decide, only the note.\n\n"
                      + "\n".join(lines))


if __name__ == "__main__":
    if "--scenes" in sys.argv:
        scenes(quick="--quick" in sys.argv, write="--write" in sys.argv)
    else:
        main(quick="--quick" in sys.argv)
