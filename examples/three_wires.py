"""Three touching steel wires twisted one turn by a rigid plate, with default contact options.

Material: an elastic rod with steel's moduli and no yield limit, on purpose: one turn over
30 mm gives a surface strain of about ``R Phi / L = 0.1`` (printed: largest equivalent
strain 0.074), ten times steel wire's elastic range; a test of the contact defaults on
touching wires, not a rope (``examples/twisted_pair.py`` is the scene in range).

A user's first strand: three straight wires (radius ``R``) touch each other
along their length, their centres on a circle of radius ``2 R / sqrt(3)``;
they are clamped at ``z = 0`` and their upper ends are rigidly joined to a
plate node on the axis, which is turned about ``e_z`` by ``turns`` full turns
while a small dead axial pull keeps the bundle taut.  Each pair of wires is
declared with ``add_contact(a, b, mu=0.3)`` and nothing else: the defaults
must handle exactly touching (gap 0), lightly loaded wires.

    python examples/three_wires.py [--turns 1] [--steps 8] [--elements 24]
"""
import argparse
import time

import numpy as np

import beamsolver as bs

solve_options = dict(steps=8)       # for `beamsolver run examples/three_wires.py`


def build(radius=0.5e-3, length=0.03, n_elements=24, turns=1.0, pull=5.0, mu=0.3, E=200e9, nu=0.3,
          **contact_options):
    """Returns ``(model, plate node, wires)``; ``contact_options`` go to every ``add_contact``."""
    sec = bs.Section.circular(radius=radius, E=E, nu=nu)
    model = bs.Model()
    rc = 2.0 * radius / np.sqrt(3.0)
    wires = []
    for k in range(3):
        a = np.pi / 2 + 2.0 * np.pi * k / 3
        x, y = rc * np.cos(a), rc * np.sin(a)
        wires.append(model.add_beam(bs.geometry.straight((x, y, 0), (x, y, length), n_elements), sec,
                                    name=f"wire {k}"))
    plate = model.add_node((0.0, 0.0, length), name="plate")
    for w in wires:
        model.clamp(w.first)
        model.join(plate, w.last, rigid=True)
    model.fix(plate, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: 2.0 * np.pi * turns * t})
    model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
    for i in range(3):
        for j in range(i + 1, 3):
            model.add_contact(wires[i], wires[j], mu=mu, **contact_options)
    return model, plate, wires


def main(turns=1.0, steps=8, n_elements=24, length=0.03, mu=0.3, verbose=False, **contact_options):
    """Solve and print one row per step; returns ``(solution, wall time)``."""
    model, plate, wires = build(length=length, n_elements=n_elements, turns=turns, mu=mu, **contact_options)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, verbose=verbose)
    wall = time.perf_counter() - t0
    print(f"three wires: R = 0.5 mm, L = {length * 1e3:g} mm, {n_elements} elements each, mu = {mu}, "
          f"{turns:g} turns in {steps} steps")
    print("| twist [turns] | torque [N m] | contacts | min gap [m] | Newton it. | cut-backs |")
    print("|---:|---:|---:|---:|---:|---:|")
    for k in range(len(sol.times)):
        c = sol.contact(k) or {}
        fn = np.asarray(c.get("normal_force", np.zeros(0)))
        gap = np.asarray(c.get("gap", np.zeros(0)))[fn > 0]
        print(f"| {turns * sol.times[k]:.3f} | {sol.reaction(plate, k)[5]:.5g} | {int((fn > 0).sum())} | "
              f"{gap.min() if len(gap) else np.nan:.3e} | {sol.stats[k]['iterations']} | "
              f"{sol.stats[k].get('cutbacks', 0)} |")
    n_it = sum(s["iterations"] for s in sol.stats)
    print(f"Newton iterations {n_it}, wall time {wall:.1f} s")
    print(sol.material_summary())
    return sol, wall


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--turns", type=float, default=1.0)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--elements", type=int, default=24)
    ap.add_argument("--mu", type=float, default=0.3)
    args = ap.parse_args()
    main(turns=args.turns, steps=args.steps, n_elements=args.elements, mu=args.mu)
