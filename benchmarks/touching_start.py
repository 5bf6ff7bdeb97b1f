"""Step 0 of touching starts (docs/theory/contact_laws.md 17.5): Newton iterations, evaluations with tangent and
factorisations at t_start, and CPU of the whole solve, with the normal law's active set and the smoothing parabola's
secant at t_start (``newton.START_SWITCHES``, ``START_SECANT``) on and off.

    python benchmarks/touching_start.py [--scenes twisted_pair contact_patch shear_lag three_wires pair_unloaded]

``twisted_pair``: the main job (``examples/twisted_pair.py``, 16 steps); ``contact_patch``, ``shear_lag``: the examples
with their ``solve_options``; ``three_wires``: ``examples/three_wires.py``'s model, one step of 1e-9 (its state at
t_start, 0.1 m); ``pair_unloaded``: two touching wires of 0.1 m clamped at both ends, no load, two steps
(``tests/contact/test_contact_touching_unloaded.py``).  CPU by ``time.process_time`` (one warm solve each, the
settings alternating; the machine is shared).  Also reported: the largest difference of the node positions between
the two settings over every recorded step (the answers agree to ``dtol``).
"""
import argparse
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))

import beamsolver as bs  # noqa: E402
from beamsolver.nonlinear import linsolve, newton  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402


def touching_pair(R=0.5e-3, L=0.1, n=24, clamp_both=True, load=None):
    """Two straight steel wires touching along ``L``, clamped at their first (and last) nodes, ``load`` on the
    middle node of ``a``: ``(model, a, b)`` (also tests/contact/test_contact_touching_unloaded.py's scene)."""
    sec = bs.Section.circular(radius=R, E=200e9, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, L), n), sec, name="a")
    b = m.add_beam(bs.geometry.straight((2 * R, 0, 0), (2 * R, 0, L), n), sec, name="b")
    for w in (a, b):
        m.clamp(w.first)
        if clamp_both:
            m.clamp(w.last)
    if load is not None:
        m.add_load(a.nodes[n // 2], force=load)
    m.add_contact(b, a)
    return m, a, b


def _pair_unloaded():
    return bs.solve(touching_pair()[0], steps=2)


def _scene(name):
    if name == "twisted_pair":
        import twisted_pair
        return bs.solve(twisted_pair.build()[0], steps=16)
    if name in ("contact_patch", "shear_lag"):
        mod = __import__(name)
        kw = dict(stick="exact") if name == "contact_patch" else {}
        return bs.solve(mod.build(**kw)[0], **mod.solve_options)
    if name == "three_wires":
        import three_wires
        return bs.solve(three_wires.build(length=0.1, n_elements=24, turns=0.5, mu=0.3, pull=5.0)[0], steps=1,
                        t_end=1e-9)
    if name == "pair_unloaded":
        return _pair_unloaded()
    raise SystemExit(f"unknown scene {name}")


def _counted(name):
    """``(solution, CPU, counts at t_start)``."""
    counts = Counter()
    evaluate, factorize, direction = Problem.evaluate, linsolve.factorize_tangent, newton.Newton.direction
    at_start = [False]

    def ev(self, H, t, tangent=True):
        counts["evaluations with tangent"] += bool(tangent) and t == 0.0      # every scene's t_start
        return evaluate(self, H, t, tangent=tangent)

    def fz(*a, **k):
        counts["factorisations"] += at_start[0]
        return factorize(*a, **k)

    def dr(self, e, dz_c=None):
        at_start[0] = self.start
        return direction(self, e, dz_c)

    Problem.evaluate, newton.linsolve.factorize_tangent, newton.Newton.direction = ev, fz, dr
    try:
        t = time.process_time()
        sol = _scene(name)
        cpu = time.process_time() - t
    finally:
        Problem.evaluate, newton.linsolve.factorize_tangent, newton.Newton.direction = evaluate, factorize, direction
    return sol, cpu, counts


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+",
                    default=["twisted_pair", "contact_patch", "shear_lag", "three_wires", "pair_unloaded"])
    args = ap.parse_args()
    print("| scene | t_start: active set, secant | step 0 iterations | t_start: evaluations with tangent, "
          "factorisations | Newton iterations (all steps) | CPU [s] | largest position difference [m] |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for name in args.scenes:
        _scene(name)                              # warm
        runs = {}
        for on in (False, True):
            newton.START_SWITCHES = newton.START_SECANT = on
            runs[on] = _counted(name)
        newton.START_SWITCHES = newton.START_SECANT = True
        P = [np.array([p[:, :3, 3] for p in runs[on][0].poses]) for on in (False, True)]
        diff = float(np.abs(P[0] - P[1]).max()) if P[0].shape == P[1].shape else float("nan")
        for on in (False, True):
            sol, cpu, c = runs[on]
            print(f"| {name} | {'on' if on else 'off'} | {sol.stats[0]['iterations']} | "
                  f"{c['evaluations with tangent']}, {c['factorisations']} | "
                  f"{sum(s['iterations'] for s in sol.stats)} | {cpu:.3f} | {diff:.2g} |", flush=True)


if __name__ == "__main__":
    main()
