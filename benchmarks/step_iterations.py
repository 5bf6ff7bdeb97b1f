"""Newton iterations of the main job against its load step (issue 30 item 3: where a small scene's iterations go).

``python benchmarks/step_iterations.py [--steps 8,16,32,64] [--elements 16] [--no-write]``

The main job (``examples/twisted_pair.py``: two wires of 16 elements twisted by two turns under a pull, exact
stick, ``mu = 0.3``) solved with ``bs.solve(model, steps=n)`` for each ``n``, each in its own process, one thread.
Per run: Newton iterations (all steps, step 0 included) and cut-backs, iterations per load step, CPU seconds
(``time.process_time``, the first solve of the process: numba caches loaded, so compare rows with each other),
the iterations at which exact stick's groups changed branch (stick <-> slip against the iterate before,
``stats["changes"]``: the active-set search) and those at which the scaled residual rose, and the plate's
torque at ``t = 1``.  If the iterations of a step were those of a smooth Newton method once the stick / slip
set is known, they would not grow with the step; they do: the set is searched.

Markdown on stdout and in the section ``step_iterations`` of ``docs/benchmarks.md``.
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def child(steps, elements):
    """One solve of the main job with ``steps`` load steps: a JSON line on stdout."""
    single_thread()
    import time

    import numpy as np
    sys.path.insert(0, str(ROOT / "examples"))
    import beamsolver as bs
    import twisted_pair

    model, plate, _ = twisted_pair.build(n_elements=elements)
    t0 = time.process_time()
    sol = bs.solve(model, steps=steps)
    cpu = time.process_time() - t0
    its = [s["iterations"] for s in sol.stats]
    changed = sum(int(np.count_nonzero(s.get("changes", [])[1:])) for s in sol.stats)
    rose = sum(int(np.count_nonzero(np.diff(np.asarray(s["residuals"], dtype=float)) > 0.0))
               for s in sol.stats)
    torque = float(sol.reaction(plate, -1)[5])
    print(json.dumps(dict(steps=steps, iterations=int(sum(its)), step0=int(its[0]),
                          cutbacks=int(sum(s.get("cutbacks", 0) for s in sol.stats)),
                          cpu=cpu, changed=changed, rose=rose, torque=torque)))


def run(steps, elements):
    out = subprocess.run([sys.executable, __file__, "--child", str(steps), "--elements", str(elements)],
                         capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="8,16,32,64")
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child is not None:
        return child(a.child, a.elements)
    rows = []
    for n in [int(s) for s in a.steps.split(",")]:
        r = run(n, a.elements)
        loaded = r["iterations"] - r["step0"]
        rows.append([n, r["iterations"], r["cutbacks"], loaded / n, r["changed"], r["rose"], r["cpu"],
                     r["torque"]])
        print(f"  steps {n}: {r['iterations']} iterations", file=sys.stderr)
    text = (f"`python benchmarks/step_iterations.py --steps {a.steps} --elements {a.elements}` ({machine()}; one "
            f"thread, each row its own process).  The main job (`examples/twisted_pair.py`, {a.elements} el/wire, "
            "exact stick) with `bs.solve(model, steps=n)`: Newton iterations (step 0's included) and cut-backs, "
            "iterations per load step (step 0's left out), iterations at which a group changed branch (stick <-> "
            "slip) or the scaled residual rose, CPU of the solve (the process's first: caches loaded), the "
            "plate's torque at t = 1.\n\n")
    text += table(["load steps", "iterations", "cut-backs", "per load step", "branch changed", "residual rose",
                   "CPU [s]", "torque [N m]"], rows, fmt={3: ".3g", 6: ".3g", 7: ".6g"})
    print(text)
    if not a.no_write:
        write_section("step_iterations", "## Newton iterations of the main job against its load step (issue 30)\n\n"
                      + text)


if __name__ == "__main__":
    main()
