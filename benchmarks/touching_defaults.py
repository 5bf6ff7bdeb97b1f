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

import beamsolver as bs  # noqa: E402
import three_wires  # noqa: E402

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


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=24)
    ap.add_argument("--turns", type=float, default=1.0)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--length", type=float, default=0.03)
    ap.add_argument("--no-write", action="store_true")
    a = ap.parse_args()
    main(a.elements, a.turns, a.steps, a.length, write=not a.no_write)
