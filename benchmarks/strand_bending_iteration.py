"""The strand bending cycle's cost per Newton iteration by part (issue 27 speed, session 10): CPU time
(``time.process_time``) of a piece of ``examples/strand_bending.py``'s cycle (the pull and the first slip steps:
``--t-end``), exclusive per part (``exact_stick_parts``'s timers, with the line loads, the results' recording and the
stability checks added), per Newton direction (linear solve) and split into tangent evaluations and forces-only
(line-search) trials.

    python benchmarks/strand_bending_iteration.py [--lays 4] [--elements 48] [--lay 229.2] [--t-end 1.5] [--steps 4]
        [--repeat 1] [--line-loads]

Prints ``ms per Newton direction`` by part (``+ x trials``: the part's share inside forces-only evaluations), the
counts of directions, tangent evaluations and trials, and the run's totals.  Run it against two trees (``PYTHONPATH``)
in turns to compare them.  ``--line-loads``: instead, CPU ms of one call of the line loads' kernel on the strand's
elements at the poses the piece ends in (forces only, and with their stiffness; best of 20), and the kernel's
results' digest (``line_load.nodal_loads_and_tangent`` of two trees on the same poses).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[0] / "examples"))

import exact_stick_parts as esp  # noqa: E402
import strand_bending as sb  # noqa: E402
from beamsolver.assembly import system as asm  # noqa: E402
from beamsolver.elements import line_load  # noqa: E402
from beamsolver.nonlinear import newton  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402
from beamsolver.stepping import stable_branch, steps  # noqa: E402

EXTRA = [("line loads", line_load, "nodal_loads"), ("line loads", line_load, "nodal_loads_and_tangent"),
         ("elements", asm.System, "_add_line_loads"),
         ("stability (stable branch)", stable_branch, "verdict"),
         ("recording, results", steps.Run, "_record")] if hasattr(steps, "Run") else []
ORDER = esp.ORDER[:-1] + ["line loads", "stability (stable branch)", "recording, results", "Newton loop"]


def counted():
    """Wrap ``Newton.direction`` and ``Problem.evaluate`` to count directions, tangent evaluations and trials."""
    count = dict(directions=0, tangent=0, trials=0)
    direction, evaluate = newton.Newton.direction, Problem.evaluate

    def d(self, *a, **k):
        count["directions"] += 1
        return direction(self, *a, **k)

    def e(self, H, t, tangent=True):
        count["tangent" if tangent else "trials"] += 1
        return evaluate(self, H, t, tangent=tangent)
    newton.Newton.direction, Problem.evaluate = d, e
    return count, (direction, evaluate)


def run_once(a):
    count, orig = counted()
    esp.TIMES.clear()
    esp.install()
    try:
        t0 = time.process_time()
        res = sb.run(a.lays, a.elements, steps=a.steps, t_end=a.t_end, lay=a.lay * 1e-3)
        total = time.process_time() - t0
    finally:
        esp.uninstall()
        newton.Newton.direction, Problem.evaluate = orig
    return total, count, dict(esp.TIMES), res


def line_loads_only(a):
    """``--line-loads``: the line-load kernel alone on the piece's last poses (module docstring)."""
    import hashlib
    res = sb.run(a.lays, a.elements, steps=a.steps, t_end=a.t_end, lay=a.lay * 1e-3)
    ln = Problem.from_model(sb.build(a.lays, a.elements, lay=a.lay * 1e-3)[0]).system.line
    H, scale = res["sol"].poses[-1], res["T"] * res["kappa"][-1]          # the P-delta load's scale T kappa at t
    rows = ln.dead
    args = (H[ln.nodes[rows, 0]], H[ln.nodes[rows, 1]], ln.L[rows], scale * ln.q[rows], scale * ln.m[rows], False)
    out = {}
    for name, fn in (("forces", line_load.nodal_loads), ("forces and stiffness", line_load.nodal_loads_and_tangent)):
        fn(*args)
        best = np.inf
        for _ in range(20):
            t0 = time.process_time()
            r = fn(*args)
            best = min(best, time.process_time() - t0)
        out[name] = (best, r)
    f, K = out["forces and stiffness"][1]
    print(f"line loads on {len(rows)} elements at t = {a.t_end:g}: forces {out['forces'][0] * 1e3:.2f} ms, with "
          f"stiffness {out['forces and stiffness'][0] * 1e3:.2f} ms CPU (best of 20); |f| {np.abs(f).max():.6e}, "
          f"|K| {np.abs(K).max():.6e}, digest {hashlib.sha1(np.round(K, 6).tobytes()).hexdigest()[:8]}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays", type=float, default=4)
    ap.add_argument("--elements", type=int, default=48)
    ap.add_argument("--lay", type=float, default=229.2, help="lay length [mm]")
    ap.add_argument("--t-end", type=float, default=1.5)
    ap.add_argument("--steps", type=int, default=sb.STEPS)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--line-loads", action="store_true", help="the line loads' kernel alone (module docstring)")
    a = ap.parse_args()
    if a.line_loads:
        return line_loads_only(a)
    for part, owner, name in EXTRA:
        esp.TARGETS.append((part, owner, name))
    sb.run(2, 8, steps=1, t_end=1.2, lay=a.lay * 1e-3)          # warm-up: the kernels' compiled code loaded
    best = None
    for _ in range(a.repeat):
        r = run_once(a)
        if best is None or r[0] < best[0]:
            best = r
    total, count, times, res = best
    n = count["directions"]
    scale = 1e3 / n
    print(f"strand {a.lays:g} lays, {a.elements} el/lay, lay {a.lay:g} mm, t in [0, {a.t_end:g}], {a.steps} steps "
          f"per unit t: {total:.2f} CPU s, {res['iterations']} iterations, {res['cutbacks']} cut-backs, {n} Newton "
          f"directions, {count['tangent']} tangent evaluations, {count['trials']} forces-only trials "
          f"({esp.__name__} timers; M at the last step {res['M'][-1]:.8g} N m)\n")
    print("| part | ms per direction (+ of which in trials) |")
    print("|---|---:|")
    for part in ORDER:
        tg, tr = times.get((part, False), 0.0) * scale, times.get((part, True), 0.0) * scale
        if tg + tr > 0.0:
            print(f"| {part} | {tg + tr:.2f}" + (f" (+ {tr:.2f} trials)" if tr > 0.005 else "") + " |")
    print(f"| other (not timed) | {(total - sum(times.values())) * scale:.2f} |")
    print(f"| **total** | **{total * scale:.2f}** |")


if __name__ == "__main__":
    main()
