"""Default contact options for touching, lightly loaded wires (issue 14 defect 1).

Runs the three touching wires of ``examples/three_wires.py`` (gap 0 in the
reference state, twisted by a rigid plate, ``mu = 0.3``) with the normal law's
``smoothing`` gap set to ``s (R1 + R2)`` for several ``s``, and prints Newton
iterations, cut-backs, wall time and the final torque (its change measures
what the smoothing costs in accuracy: the smoothed law leaves a touching pair
apart by up to ``smoothing``).  The chosen default is the smallest ``s`` that
converges without cut-backs.

    python benchmarks/touching_defaults.py [--elements 8] [--turns 0.25] [--steps 2] [--length 0.01]

Writes the ``touching_defaults`` section of ``docs/benchmarks.md`` with the full-size default
arguments (``--elements 24 --turns 1 --steps 8 --length 0.03``).

``--start`` measures instead the first state of touching wires with the example's options
(``examples/twisted_pair_extreme.py``: two wires, smoothing ``1e-3 (R1 + R2)``; ``examples/three_wires.py``:
the default), a 5 N pull on from t = 0, for lengths up to 0.2 m: Newton iterations of step 0
(budget ``stepping.STEP_ZERO_ITERATIONS`` x 30), the contact force and the largest gap between
the wires there (the smoothed law pushes touching points apart), then half a turn in 4 steps
(``--no-twist``: step 0 only).  Writes the ``touching_start`` section.

    python benchmarks/touching_defaults.py --start [--no-twist] [--no-write]
"""
import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "examples"))

from _report import single_thread  # noqa: E402

single_thread()

import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
import three_wires  # noqa: E402
import twisted_pair_extreme as twisted_pair  # noqa: E402
from beamsolver.stepping.steps import STEP_ZERO_ITERATIONS  # noqa: E402

R = 0.5e-3
SMOOTHING = (0.0, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2)      # x (R1 + R2)


def run(s, elements, turns, steps, length):
    model, plate, _ = three_wires.build(n_elements=elements, turns=turns, length=length, smoothing=s * 2 * R)
    t0 = time.perf_counter()
    try:
        sol = bs.solve(model, steps=steps)
        outcome = "converged"
    except bs.ConvergenceError as e:
        sol, outcome = e.solution, "stopped"
    wall = time.perf_counter() - t0
    its = sum(st["iterations"] for st in sol.stats)
    cuts = sum(st.get("cutbacks", 0) for st in sol.stats)
    return (f"{s:g}", outcome, f"{turns * sol.times[-1]:.3f}", its, cuts, f"{wall:.1f}",
            f"{sol.reaction(plate)[5]:.6g}")


def main(elements=24, turns=1.0, steps=8, length=0.03, write=True):
    from _report import machine, table, write_section
    rows = []
    for s in SMOOTHING:
        rows.append(run(s, elements, turns, steps, length))
        print(rows[-1], flush=True)
    head = ["smoothing / (R1 + R2)", "outcome", "twist reached [turns]", "Newton it.", "cut-backs", "wall [s]",
            "torque [N m]"]
    md = table(head, rows)
    print(md)
    if write:
        write_section("touching_defaults", f"""## Default smoothing for touching wires (issue 14)

`python benchmarks/touching_defaults.py --elements {elements} --turns {turns:g} --steps {steps} --length {length:g}`
({machine()}).  Three touching steel wires (R = 0.5 mm, `examples/three_wires.py`), `mu = 0.3`,
the normal law smoothed over `smoothing` (line contact; point and orthogonal pairs stay sharp);
the default is `1e-6 (R1 + R2)` (`contact.options.SMOOTHING`): every smoothing tried converges,
and the smallest leaves the answers of lightly loaded strands unchanged (the seven-wire strand's radial
deformation at a strain of 1e-4 is about 3e-8 m, and a smoothing gap of 1e-3 (R1 + R2) changed its
stiffness by 7 %).  The sharp law (`0`) stalls in the first step: touching points cycle between
open and closed.

{md}
""")


START = [("pair", 0.06, 24, 0.0), ("pair", 0.06, 24, 0.3), ("pair", 0.1, 24, 0.0), ("pair", 0.1, 24, 0.3),
         ("pair", 0.1, 40, 0.0), ("pair", 0.1, 40, 0.3), ("pair", 0.2, 48, 0.0), ("pair", 0.2, 48, 0.3),
         ("pair", 0.2, 80, 0.0), ("pair", 0.2, 80, 0.3), ("three", 0.1, 24, 0.0), ("three", 0.1, 24, 0.3)]


def widest_gap(sol, wires, k=0):
    """Largest gap [m] between the centre lines of two wires at equal node numbers, step ``k``."""
    x = [sol.poses[k][w.nodes][:, :3, 3] for w in wires]
    return max(float((np.linalg.norm(x[i] - x[j], axis=1) - 2 * R).max())
               for i in range(len(x)) for j in range(i + 1, len(x)))


def start_row(scene, length, elements, mu, twist=True):
    build = twisted_pair.build if scene == "pair" else three_wires.build
    model, plate, wires = build(length=length, n_elements=elements, turns=0.5, mu=mu)
    t0 = time.perf_counter()
    try:
        sol = bs.solve(model, steps=4, t_end=1.0 if twist else 1e-9)
        outcome = "converged"
    except bs.ConvergenceError as e:
        sol, outcome = e.solution, "stopped"
    wall = time.perf_counter() - t0
    if len(sol.times) == 0:
        return (scene, length, elements, mu, "stopped at t = 0", "-", "-", "-", "-", "-", "-", f"{wall:.1f}")
    c = sol.contact(0)
    return (scene, length, elements, mu, outcome, sol.stats[0]["iterations"], f"{c['normal_force'].sum():.3g}",
            f"{widest_gap(sol, wires):.3g}", f"{0.5 * sol.times[-1]:.3f}" if twist else "-",
            sum(st["iterations"] for st in sol.stats), sum(st.get("cutbacks", 0) for st in sol.stats), f"{wall:.1f}")


def start(twist=True, write=True):
    """Table of the first state of touching wires (``START`` scenes) and, with ``twist``, half a turn."""
    from _report import machine, table, write_section
    rows = []
    for scene in START:
        rows.append(start_row(*scene, twist=twist))
        print(rows[-1], flush=True)
    head = ["scene", "length [m]", "elements", "mu", "outcome", "step-0 Newton it.", "step-0 contact force [N]",
            "step-0 widest gap [m]", "twist reached [turns]", "Newton it.", "cut-backs", "wall [s]"]
    md = table(head, rows)
    print(md)
    if write:
        write_section("touching_start", f"""## Touching wires at t_start (issue 14 item 1)

`python benchmarks/touching_defaults.py --start{'' if twist else ' --no-twist'}` ({machine()}).  Straight
steel wires (R = 0.5 mm) touching along their length with the examples' contact options
(`pair`: `examples/twisted_pair_extreme.py`, smoothing `1e-3 (R1 + R2)`; `three`: `examples/three_wires.py`,
the default), clamped below, rigidly joined to a plate under a 5 N pull from t = 0; then half a turn
in 4 steps.  Step 0 has {STEP_ZERO_ITERATIONS} x `max_iter` Newton iterations (no cut-back there).
The smoothed law pushes touching points apart (`eps_N w / 4` per unit length at gap 0), so the first
state is not the reference one: the contact force and the widest gap of step 0 measure that
(docs/theory.md section 17).

{md}
""")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=24)
    ap.add_argument("--turns", type=float, default=1.0)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--length", type=float, default=0.03)
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--start", action="store_true", help="the first state of touching wires (touching_start)")
    ap.add_argument("--no-twist", action="store_true", help="with --start: step 0 only")
    a = ap.parse_args()
    if a.start:
        start(twist=not a.no_twist, write=not a.no_write)
    else:
        main(a.elements, a.turns, a.steps, a.length, write=not a.no_write)
