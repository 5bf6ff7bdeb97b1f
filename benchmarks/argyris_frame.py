"""Argyris' right-angle frame past its lateral buckling load: steps, cut-backs, iterations.

The frame (two legs of 240 mm, section 30 x 0.6 mm, E = 71240 N/mm^2,
nu = 0.31, clamped at one end) carries an in-plane tip force ``F`` (along the
clamped leg, either sign) with an out-of-plane imperfection ``1e-4 F``; it
buckles sideways near ``F = 1.09 N``.  Solved by force control to ``F_max`` in
``steps`` user steps (the damped Newton, default options); prints a Markdown
table.  Issue 12 item 8: the damped Newton stalled there on a stable path, and
after a cut-back the step regrew to the size that had just failed, every third
step.  Each case runs with the step growth of ``solve`` (``rule`` "memory": a size
that failed again waits twice as many easy steps, ``bs.stepping.steps.WAIT_MAX``) and
with the fixed rule (``WAIT_MAX = 2``: back to the failed size after two easy
steps); "all iterations" counts the failed attempts' too (``callback``).

    python benchmarks/argyris_frame.py [--quick]
"""
import sys
import time
from pathlib import Path

import beamsolver as bs

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from limit_points import argyris_frame as frame  # noqa: E402


def run(F_max, steps, n, imperfection=1e-4, wait_max=None):
    m, b = frame(F_max, imperfection=imperfection, n=n)
    count = [0]

    def callback(info):
        count[0] += info["iteration"] > 0
    saved = bs.stepping.steps.WAIT_MAX
    if wait_max is not None:
        bs.stepping.steps.WAIT_MAX = wait_max
    t0 = time.perf_counter()
    try:
        sol = bs.solve(m, steps=steps, verbose=False, callback=callback)
        outcome = "converged"
    except bs.ConvergenceError as e:
        sol = e.solution
        outcome = f"stopped at F = {sol.times[-1] * F_max:.4f} N ({type(getattr(e, 'failure', None) or e).__name__})"
    finally:
        bs.stepping.steps.WAIT_MAX = saved
    wall = time.perf_counter() - t0
    return dict(F_max=F_max, n=n, steps=steps, imperfection=imperfection, outcome=outcome, taken=sol.n_steps,
                cutbacks=sum(s["cutbacks"] for s in sol.stats[1:]), iterations=int(sol.iterations.sum()),
                all_iterations=count[0],
                undamped=sum("undamped" in s for s in sol.stats), tip_z=sol.position(b.last)[2], wall=wall)


def main(quick=False):
    cases = [(1.1, 11, 4, 1e-4)] if quick else [(1.5, 30, 10, 1e-4), (-1.5, 30, 10, 1e-4), (1.1, 11, 4, 1e-4),
                                              (1.5, 30, 10, 1e-3)]
    print("| F_max [N] | imperfection | elements per leg | user steps | rule | outcome | steps | cut-backs | "
          "iterations | all iterations | undamped fallbacks | tip z [mm] | wall [s] |")
    print("|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for F, steps, n, imperfection in cases:
        for rule, wait_max in (("fixed", 2), ("memory", None)):
            r = run(F, steps, n, imperfection, wait_max)
            print(f"| {r['F_max']:g} | {r['imperfection']:g} | {r['n']} | {r['steps']} | {rule} | {r['outcome']} | "
                  f"{r['taken']} | {r['cutbacks']} | {r['iterations']} | {r['all_iterations']} | {r['undamped']} | "
                  f"{r['tip_z']:.2f} | {r['wall']:.1f} |", flush=True)


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
