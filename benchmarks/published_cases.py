"""The published cases of tests/published (issue 31) and the cost of keeping the stable branch.

Part 1 solves each case with the default options and prints its number next to the reference:
the column with a kick (tip, Timoshenko & Gere's elastica), Greenhill's torque by bisection over
short intervals, the capstan over a full wrap on a helix and with a polyline cutting into the post
(Euler-Eytelwein), and the imperfect Argyris frame (steps, Newton iterations, tip, plain Newton
too).  Part 2 times stable solves (cantilever, joined cantilever, column at 0.9 P_E; 8 load steps)
with the stable-branch rule (default: the sign of det K of each step's first factorisation, the
inertia check of the steps it flags) and with it switched off (monkeypatched), alternating.  BLAS on one thread.

    python benchmarks/published_cases.py [--write]

``--write`` replaces the ``published_cases`` section of docs/benchmarks.md.
"""
import sys
import time
from pathlib import Path

from _report import machine, single_thread, table, write_section

single_thread()

import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
from beamsolver.stepping import stable_branch# noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "published"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))      # scenes imports limit_points
import scenes  # noqa: E402
from test_elastica_kick import elastica  # noqa: E402
from test_capstan_published import CHORDS, HELIX  # noqa: E402
from stability_check import cantilever, column, joined  # noqa: E402

REPEATS = 3


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def cases():
    rows = []
    m, b, _ = scenes.column()
    sol, wall = _timed(lambda: bs.solve(m, steps=10, verbose=False))
    x, f = elastica(1.1)
    tip = sol.position(b.last)
    rows.append(("column, kick 0.01 P_cr, 1.1 P_cr, 10 steps", f"tip ({tip[0]:.4f}, {tip[1]:.4f})",
                 f"perfect elastica ({x:.4f}, {f:.4f}); 67217fe (0.8033, 0.5290)", sol.n_steps,
                 int(sol.iterations.sum()), wall))
    m, w, sec = scenes.twisted_wire()

    def bisect():
        s = bs.solve(m, steps=18, verbose=False, check_stability=True)
        k = next(k for k, st in enumerate(s.stats[1:], 1) if not st["stable"])
        lo, hi, H, n = s.times[k - 1], s.times[k], s.poses[k - 1], 0
        while hi - lo > 1e-10:
            t, n = 0.5 * (lo + hi), n + 1
            r = bs.solve(m, steps=1, t_start=lo, t_end=t, initial_poses=H, check_stability=True, verbose=False)
            if r.stats[-1]["stable"]:
                lo, H = t, r.poses[-1]
            else:
                hi = t
        return lo, n
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilityWarning)
        (t_c, n), wall = _timed(bisect)
    ML_B = sec.C[3, 3] * 2.0 * np.pi * 2.25 * t_c / sec.C[4, 4]
    rows.append(("Greenhill, 8 elements, bisection to 1e-10", f"M L / B = {ML_B:.3f} ({n} bisections)",
                 "8.99", "", "", wall))
    for name, kw, exact in (("capstan, helix full wrap, mu 0.1", HELIX, np.exp(0.1 * 2.0 * np.pi)),
                            ("capstan, polyline into the post, mu 0.25", CHORDS, np.exp(0.25 * np.pi / 1.02))):
        m, rope, t_out = scenes.capstan(**kw)
        sol, wall = _timed(lambda: bs.solve(m, steps=8, verbose=False))
        ratio = abs(float(np.dot(sol.reaction(rope.last)[:3], t_out))) / kw.get("T_hold", 1.0)
        adj = sol.stats[0].get("adjusted", dict(count=0, largest=0.0))
        rows.append((name, f"{ratio:.5f} ({100 * (ratio / exact - 1):+.2f} %); adjusted {adj['count']} points, "
                     f"largest {adj['largest']:.2g}", f"{exact:.5f}", sol.n_steps, int(sol.iterations.sum()), wall))
    for ls in (True, False):
        m, b = scenes.argyris_frame(1.15)
        sol, wall = _timed(lambda: bs.solve(m, steps=23, verbose=False, line_search=ls))
        rows.append((f"Argyris frame, 1e-4, 1.15 N, 23 steps{'' if ls else ', line_search=False'}",
                     f"tip z {sol.position(b.last)[2]:.2f} mm", "stable buckled path; 07a7d6e: 246 steps, 1986 it."
                     if ls else "07a7d6e: w = -0.079 mm, unstable", sol.n_steps, int(sol.iterations.sum()), wall))
    return table(("case", "result", "reference", "steps", "Newton it.", "wall [s]"), rows, {5: ".2f"})


def overhead():
    """Wall time with the stable-branch rule (the determinant sign of each step's first factorisation and
    the check of the steps it flags) and with it switched off (``stable_branch.ENABLED = False``)."""
    rows = []
    for name, build in (("cantilever", cantilever), ("joined cantilever", joined), ("column 0.9 P_E", column)):
        for n in (16, 256):
            walls = {}
            for label in ("off", "on", "off", "on"):
                stable_branch.ENABLED = label == "on"
                try:
                    times = [_timed(lambda: bs.solve(build(n), steps=8, verbose=False))[1] for _ in range(REPEATS)]
                finally:
                    stable_branch.ENABLED = True
                walls.setdefault(label, []).extend(times)
            off, on = float(np.median(walls["off"])), float(np.median(walls["on"]))
            rows.append((name, n, off, on, on / off))
    return table(("scene", "elements", "without the rule [s]", "with it [s]", "ratio"), rows,
                 {2: ".4f", 3: ".4f", 4: ".2f"})


def main(write=False):
    text = (f"Published cases of tests/published (issue 31), default options unless named; {machine()}.\n"
            "`python benchmarks/published_cases.py --write`\n\n" + cases() + "\n\n"
            "Cost of the stable-branch rule (the sign of det K of each step's first SuperLU factorisation, "
            "and the inertia check of the steps it flags) on stable 8-step solves, median of "
            f"{2 * REPEATS} runs alternating with and without:\n\n" + overhead())
    print(text)
    if write:
        write_section("published_cases", "## Published cases and the stable branch (issue 31)\n\n" + text)


if __name__ == "__main__":
    main(write="--write" in sys.argv)
