"""Twisting two beams into a two-ply: the main job of beamsolver.

Two straight steel wires (radius ``R``) touch along their length, side by side
at ``x = +-R``; both are clamped at ``z = 0``.  Their upper ends are rigidly
linked to a plate node on the pair's axis, which is turned about ``e_z`` by
``turns`` full turns while a small dead axial pull keeps the pair taut (its
other degrees of freedom held).  The wires wrap around each other into a
two-ply in contact.  The default run is frictionless: with ``--mu 0.3``
(Coulomb, SE(3) slip increment) Newton stalls in the first steps, where the
normal forces are tiny and the stick/slip state of every point is undecided
(open problem, issue 5).

The script prints torque and axial force against the twist angle, writes
ParaView files (``.pvd`` + ``.vtu``, beams and contact points) to ``--output``
and, when the ``[viz]`` extra is installed, renders a picture.

    python examples/twisted_pair.py [--output twisted_pair_output] [--turns 2] [--steps 16]

Contact options: a normal law smoothed over a gap of ``1e-3 (R1 + R2)``
(touching, lightly loaded wires: a sharp penalty makes Newton cycle on points
whose gap hovers at zero) and the default penalty (Young's modulus).
"""
import argparse
import time

import numpy as np

import beamsolver as bs


def build(radius=0.5e-3, length=0.02, n_elements=16, turns=2.0, pull=5.0, mu=0.3, E=200e9, nu=0.3,
          swap=False, smoothing=None):
    """Returns ``(model, plate node, (beam_a, beam_b))``; ``swap`` exchanges slave and master."""
    sec = bs.Section.circular(radius=radius, E=E, nu=nu)
    model = bs.Model()
    a = model.add_beam(bs.geometry.straight((radius, 0, 0), (radius, 0, length), n_elements), sec, name="wire a")
    b = model.add_beam(bs.geometry.straight((-radius, 0, 0), (-radius, 0, length), n_elements), sec, name="wire b")
    model.clamp(a.first)
    model.clamp(b.first)
    plate = model.add_node((0.0, 0.0, length), name="plate")
    model.join(plate, a.last, rigid=True)
    model.join(plate, b.last, rigid=True)
    model.fix(plate, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: 2.0 * np.pi * turns * t})
    model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
    slave, master = (b, a) if swap else (a, b)
    model.add_contact(slave, master, mu=mu, smoothing=2e-3 * radius if smoothing is None else smoothing)
    return model, plate, (a, b)


def table(sol, plate, turns):
    """Rows ``(twist [turns], torque [N m], axial force [N], contact points, min gap [m], iterations)``."""
    rows = []
    for k in range(len(sol.times)):
        r = sol.reaction(plate, k)
        c = sol.contact(k) or {}
        gap = np.asarray(c.get("gap", np.zeros(0)))
        active = np.asarray(c.get("normal_force", np.zeros(0))) > 0
        rows.append((turns * sol.times[k], r[5], sol.position(plate, k)[2], int(active.sum()),
                     float(gap[active].min()) if active.any() else np.nan, sol.stats[k]["iterations"]))
    return rows


def main(output=None, turns=2.0, steps=16, n_elements=16, mu=0.0, length=0.02, verbose=False, swap=False):
    """Solve and print the summary; returns ``(solution, rows, wall time)``."""
    model, plate, _ = build(length=length, n_elements=n_elements, turns=turns, mu=mu, swap=swap)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, output=output, verbose=verbose)
    wall = time.perf_counter() - t0
    rows = table(sol, plate, turns)
    print(f"twisted pair: 2 wires R = 0.5 mm, L = {length * 1e3:g} mm, {n_elements} elements each, "
          f"mu = {mu}, {turns:g} turns in {steps} steps")
    print(f"{'twist [turns]':>13} {'torque [N m]':>13} {'plate z [m]':>12} {'contacts':>9} "
          f"{'min gap [m]':>12} {'Newton it.':>10}")
    for tw, tq, z, nc, g, it in rows:
        print(f"{tw:13.3f} {tq:13.5g} {z:12.6g} {nc:9d} {g:12.3e} {it:10d}")
    n_it = sum(s["iterations"] for s in sol.stats)
    print(f"converged steps {len(sol.times) - 1}, Newton iterations {n_it}, wall time {wall:.1f} s")
    if output is not None:
        print(f"ParaView: open {output}/*.pvd (Extract Surface, then Tube with radius by 'radius')")
        try:
            from beamsolver import viz
            png = f"{output}/twisted_pair.png"
            viz.render(sol, step=-1, path=png, color_by="T")
            print(f"picture: {png}")
        except ImportError:
            print("picture: install the [viz] extra (pyvista) to render one")
        except Exception as exc:          # a picture must never fail the run
            print(f"picture: not rendered ({exc})")
    return sol, rows, wall


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="twisted_pair_output")
    ap.add_argument("--turns", type=float, default=2.0)
    ap.add_argument("--steps", type=int, default=16)
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--mu", type=float, default=0.0,
                    help="friction coefficient (default 0: the frictional run does not converge yet)")
    args = ap.parse_args()
    main(output=args.output, turns=args.turns, steps=args.steps, n_elements=args.elements, mu=args.mu)
