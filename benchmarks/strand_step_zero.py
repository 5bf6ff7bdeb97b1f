"""Step 0 of the strand twins' loaded step (issue 30, session 11): Newton iterations and CPU of ``bs.solve(steps=1)``
by step, with ``steps.STEP_ZERO_CYCLE`` and ``STEP_ZERO_UPDATES`` 0 ("off", before: the attempt with exact stick's
friction given up by the stall rule alone, ``STEP_ZERO_STALL`` iterations without progress, its augmented-Lagrangian
updates up to ``MAX_OUTER``) and at their defaults ("on": also given up after that many Newton directions running that
reverse the one before, or after that many updates), the fallback without that friction after a give-up.

    python benchmarks/strand_step_zero.py [--scenes 19 37 rope-40] [--rounds 2]

``rope-40``: ``rope_loaded_step.py``'s rope piece of 40 mm with exact stick
(``tests/nonlinear/test_rope_loaded_step.py``'s scene, ``min_step_ratio=1``).  The other scenes are
``scaling_scenes.strand_model`` (the overlap-free twins of the scaling bundles: ``build_strand(..., fit_core=True,
touch_tol=-0.5)``, bottom clamped), every top end stretched by ``scaling_scenes.STRAIN`` over one step, as
``benchmarks/scaling.py``'s "loaded step".  CPU by ``time.process_time`` between the Newton callbacks (step 0: up
to the first callback at t = 1, including the fallback's second attempt; step 1: the rest), the settings alternating,
least of the rounds; also printed: the iterations each step counts, the callbacks at t = 0 (the failed attempt's
iterations too), whether step 0 warned, and the largest difference of the poses between the settings.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import beamsolver as bs  # noqa: E402
from beamsolver.stepping import steps  # noqa: E402

clock = time.process_time


RULES = dict(STEP_ZERO_CYCLE=steps.STEP_ZERO_CYCLE, STEP_ZERO_UPDATES=steps.STEP_ZERO_UPDATES)


def loaded_step(name, on):
    """``(solution, row)`` of the scene ``name``'s loaded step with the give-up rules ``RULES`` ``on`` or off."""
    from scaling_scenes import STEP_FLOOR, STRAIN, strand_model
    old = {k: getattr(steps, k) for k in RULES}
    for k, v in RULES.items():
        setattr(steps, k, v if on else 0)
    try:
        if name.startswith("rope-"):            # rope_loaded_step.py's piece (its test's: one step, no cut-back)
            from rope_loaded_step import rope
            m, floor = rope(float(name.split("-")[1]) * 1e-3, "exact"), 1.0
        else:
            m, wires, length = strand_model(name)
            for w in wires:
                m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, STRAIN * length * t)))
            floor = STEP_FLOOR
        stamps = []
        t0 = clock()
        sol = bs.solve(m, steps=1, verbose=False, min_step_ratio=floor,
                       callback=lambda d: stamps.append((d["t"], clock())))
        total = clock() - t0
    finally:
        for k, v in old.items():
            setattr(steps, k, v)
    t1 = next((c for t, c in stamps if t > 0.0), t0 + total)
    row = dict(calls0=sum(1 for t, _ in stamps if t == 0.0), it0=int(sol.stats[0]["iterations"]),
               it1=int(sol.stats[-1]["iterations"]), warned=bool(sol.stats[0].get("warnings")),
               s0=t1 - t0, s1=t0 + total - t1, total=total)
    return sol, row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=["19"])
    ap.add_argument("--rounds", type=int, default=2)
    a = ap.parse_args()
    print("| scene | STEP_ZERO_CYCLE, _UPDATES | step 0: callbacks at t = 0 (counted iterations) | step 0 warned "
          "| step 0 CPU [s] | step 1: iterations | step 1 CPU [s] | loaded step CPU [s] | largest pose difference |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|")
    for name in a.scenes:
        best, sols = {}, {}
        for _ in range(a.rounds):
            for on in (False, True):
                sol, row = loaded_step(name, on)
                sols[on] = sol
                if on not in best or row["total"] < best[on]["total"]:
                    best[on] = row
        a_, b_ = sols[False], sols[True]
        diff = max(float(np.abs(a_.poses[k] - b_.poses[k]).max()) for k in range(min(len(a_), len(b_))))
        for on in (False, True):
            r = best[on]
            print(f"| {name} | {'on' if on else 'off'} | {r['calls0']} ({r['it0']}) | {'yes' if r['warned'] else 'no'} "
                  f"| {r['s0']:.2f} | {r['it1']} | {r['s1']:.2f} | {r['total']:.2f} | {diff:.2g} |", flush=True)


if __name__ == "__main__":
    main()
