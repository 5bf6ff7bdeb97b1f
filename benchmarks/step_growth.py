"""Step growth after a cut-back in slip-dominated contact runs (issue 27 item 6).

Runs the contact examples (``examples/twisted_pair.py``: 2 turns in 16 steps;
``examples/three_wires.py``: 1 turn in 8 steps) with their default inputs, once as they
are and once with a cut-back forced at the first step after ``t_start`` (the ``callback``
raises a retryable ``failures.NotConverged`` at the first Newton iteration there), under
two growth rules: ``easy_limit`` alone (``stepping.steady`` switched off, the rule before)
and the default (``easy_limit`` or ``steady``).  Prints states, Newton iterations,
cut-backs, steps shorter than the user's and wall time, and writes the ``step_growth``
section of ``docs/benchmarks.md``.

    python benchmarks/step_growth.py [--no-write]
"""
import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "examples"))

from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()

import beamsolver as bs  # noqa: E402
from beamsolver.stepping import steps as stepping# noqa: E402
from beamsolver.failures import NotConverged  # noqa: E402

EXAMPLES = {"twisted_pair": 16, "three_wires": 8}


def forced_cut_back():
    """A callback failing the first Newton iteration after ``t_start`` once."""
    done = []

    def callback(info):
        if not done and info["t"] > 0.0:
            done.append(info["t"])
            raise NotConverged("cut-back forced by benchmarks/step_growth.py")
    return callback


def run(example, steps, force, steady):
    """``(states, iterations, cut-backs, short steps, wall)`` of one solve; ``steady=False``: the
    rule before (``easy_limit`` alone)."""
    build = __import__(example).build
    rule = stepping.steady
    if not steady:
        stepping.steady = lambda iterations, previous, max_iter: False
    try:
        t0 = time.perf_counter()
        sol = bs.solve(build()[0], steps=steps, callback=forced_cut_back() if force else None, verbose=False)
        wall = time.perf_counter() - t0
    finally:
        stepping.steady = rule
    dt_user = 1.0 / steps
    short = sum(s["dt"] < dt_user * (1 - 1e-9) for s in sol.stats[1:])
    return (len(sol.times), int(sum(sol.iterations)), int(sum(s["cutbacks"] for s in sol.stats)), short,
            f"{wall:.1f}")


def main(write=True):
    rows = []
    for example, steps in EXAMPLES.items():
        for force in (False, True):
            for steady in (False, True):
                rows.append((example, "first step" if force else "none",
                             "easy_limit or steady" if steady else "easy_limit only") + run(example, steps, force, steady))
                print(rows[-1], flush=True)
    head = ["example", "forced cut-back", "growth rule", "states", "Newton it.", "cut-backs", "short steps", "wall [s]"]
    text = "\n".join([
        "## Step growth after a cut-back (issue 27 item 6)\n",
        f"`python benchmarks/step_growth.py` ({machine()})\n",
        "The contact examples with default inputs, as they are and with the first step after t_start forced "
        "to fail once (callback), under the growth rule before (`easy_limit` only) and the default "
        "(`easy_limit` or `stepping.steady`: iterations at most 1.25 x the previous step's + 1 and at most "
        "2/3 of max_iter). Short steps: steps below the user's size.\n",
        table(head, rows)])
    print(text)
    if write:
        write_section("step_growth", text)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true")
    main(write=not ap.parse_args().no_write)
