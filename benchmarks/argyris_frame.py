"""Argyris' right-angle frame past its lateral buckling load: steps, cut-backs, iterations.

The frame (two legs of 240 mm, section 30 x 0.6 mm, E = 71240 N/mm^2,
nu = 0.31, clamped at one end) carries an in-plane tip force ``F`` (along the
clamped leg, either sign) with an out-of-plane imperfection ``1e-4 F``; it
buckles sideways near ``F = 1.09 N``.  Solved by force control to ``F_max`` in
``steps`` user steps (the damped Newton, default options); prints a Markdown
table.  Issue 12 item 8: the damped Newton stalled there on a stable path.

    python benchmarks/argyris_frame.py [--quick]
"""
import sys
import time

import beamsolver as bs


def frame(F, imperfection=1e-4, n=10):
    m = bs.Model()
    sec = bs.Section.rectangular(width=0.6, height=30.0, E=71240.0, nu=0.31)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 240, 0), n, e2=(0, 0, 1)), sec)
    b = m.add_beam(bs.geometry.straight((0, 240, 0), (240, 240, 0), n, e2=(0, 0, 1)), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, F, imperfection * F))
    return m, b


def run(F_max, steps, n):
    m, b = frame(F_max, n=n)
    t0 = time.perf_counter()
    try:
        sol = bs.solve(m, steps=steps, verbose=False)
        outcome = "converged"
    except bs.ConvergenceError as e:
        sol = e.solution
        outcome = f"stopped at F = {sol.times[-1] * F_max:.4f} N ({type(getattr(e, 'failure', None) or e).__name__})"
    wall = time.perf_counter() - t0
    return dict(F_max=F_max, n=n, steps=steps, outcome=outcome, taken=sol.n_steps,
                cutbacks=sum(s["cutbacks"] for s in sol.stats[1:]), iterations=int(sol.iterations.sum()),
                undamped=sum("undamped" in s for s in sol.stats), tip_z=sol.position(b.last)[2], wall=wall)


def main(quick=False):
    cases = [(1.1, 11, 4)] if quick else [(1.5, 30, 10), (-1.5, 30, 10), (1.1, 11, 4)]
    print("| F_max [N] | elements per leg | user steps | outcome | steps | cut-backs | iterations | "
          "undamped fallbacks | tip z [mm] | wall [s] |")
    print("|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for F, steps, n in cases:
        r = run(F, steps, n)
        print(f"| {r['F_max']:g} | {r['n']} | {r['steps']} | {r['outcome']} | {r['taken']} | {r['cutbacks']} | "
              f"{r['iterations']} | {r['undamped']} | {r['tip_z']:.2f} | {r['wall']:.1f} |")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
