"""Twisting two beams into a two-ply: the main job of beamsolver.

Two straight steel wires (radius ``R``) touch along their length, side by side
at ``x = +-R``; both are clamped at ``z = 0``.  Their upper ends are rigidly
linked to a plate node on the pair's axis, which is turned about ``e_z`` by
``turns`` full turns while a small dead axial pull keeps the pair taut (its
other degrees of freedom held).  The wires wrap around each other into a
two-ply in contact, with Coulomb friction (``mu = 0.3`` by default; the slip
increment is the SE(3) finite difference of the seed paper; sliding starts at
an elastic slip of 0.005 element lengths, Abaqus' default penalty friction).

Stability: the torque of the pair passes Greenhill's limit ``8.99 B / L``
(``B = 2 E I``) at about 1.7 turns; beyond, the straight two-ply followed here
(by symmetry) is an unstable equilibrium, which the script detects from the
eigenvalues of the tangent (``bs.linearize``) and reports: a real pair writhes
into a plectoneme there, which needs an imperfection and path following.

The script prints torque and axial force against the twist angle, writes
ParaView files (``.pvd`` + ``.vtu``, beams and contact points) to ``--output``
and, when the ``[viz]`` extra is installed, renders a picture.

    python examples/twisted_pair.py [--output twisted_pair_output] [--turns 2] [--steps 16] [--mu 0.3]

Contact options: a normal law smoothed over a gap of ``1e-3 (R1 + R2)``
(touching, lightly loaded wires: a sharp penalty makes Newton cycle on points
whose gap hovers at zero) and the default penalty (Young's modulus).
"""
import argparse
import time

import numpy as np

import beamsolver as bs


solve_options = dict(steps=16)      # for `beamsolver run examples/twisted_pair.py`


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


COLUMNS = ("twist [turns]", "torque [N m]", "axial force [N]", "plate z [m]", "contacts", "sticking",
           "min gap [m]", "Newton it.", "wall [s]")


def table(sol, plate, clamps, turns):
    """Rows, one per step: twist [turns], torque on the plate about e_z [N m], axial force
    (the clamps' reaction along e_z) [N], plate height [m], contact points carrying force,
    of which sticking, smallest gap of those [m], Newton iterations, wall time of the step [s]."""
    rows = []
    for k in range(len(sol.times)):
        r = sol.reaction(plate, k)
        axial = -sum(sol.reaction(c, k)[2] for c in clamps)
        c = sol.contact(k) or {}
        gap = np.asarray(c.get("gap", np.zeros(0)))
        active = np.asarray(c.get("normal_force", np.zeros(0))) > 0
        stick = np.asarray(c.get("stick", np.zeros(0, dtype=bool)))
        rows.append((turns * sol.times[k], r[5], axial, sol.position(plate, k)[2], int(active.sum()),
                     int((stick & active).sum()) if len(stick) else 0,
                     float(gap[active].min()) if active.any() else np.nan, sol.stats[k]["iterations"],
                     sol.stats[k].get("wall_time", 0.0)))
    return rows


def stability(model, sol, turns):
    """Twist [turns] from which the tangent (``bs.linearize``) has a negative eigenvalue (None
    if never), and its lowest eigenvalue at the last step.  ``model`` should be the frictionless
    twin of the solved scene: the elastic, load and normal-contact stiffness at the solution's
    poses is symmetric (conservative), so its eigenvalues decide stability; a slipping point's
    tangent is not symmetric, and sticking friction is left out (the estimate is conservative).
    Cheap here (about 200 unknowns, dense)."""
    lowest = []
    for k in range(1, len(sol.times)):
        K = bs.linearize(model, sol, k).K.toarray()
        lowest.append(np.linalg.eigvalsh(0.5 * (K + K.T))[0])
    lowest = np.array(lowest)
    neg = np.flatnonzero(lowest < 0)
    first = None if len(neg) == 0 else turns * sol.times[1 + neg[0]]
    return first, float(lowest[-1]) if len(lowest) else np.nan


def main(output=None, turns=2.0, steps=16, n_elements=16, mu=0.3, length=0.02, verbose=False, swap=False):
    """Solve and print the summary; returns ``(solution, rows, wall time)``."""
    model, plate, (a, b) = build(length=length, n_elements=n_elements, turns=turns, mu=mu, swap=swap)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, output=output, verbose=verbose)
    wall = time.perf_counter() - t0
    rows = table(sol, plate, (a.first, b.first), turns)
    print(f"twisted pair: 2 wires R = 0.5 mm, L = {length * 1e3:g} mm, {n_elements} elements each, "
          f"mu = {mu}, {turns:g} turns in {steps} steps")
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---:|" * len(COLUMNS))
    for tw, tq, ax, z, nc, ns, g, it, w in rows:
        print(f"| {tw:.3f} | {tq:.5g} | {ax + 0.0:.4g} | {z:.6g} | {nc} | {ns} | {g:.3e} | {it} | {w:.2f} |")
    n_it = sum(s["iterations"] for s in sol.stats)
    print(f"converged steps {len(sol.times) - 1}, Newton iterations {n_it}, wall time {wall:.1f} s")
    twin, _, _ = build(length=length, n_elements=n_elements, turns=turns, mu=0.0, swap=swap)
    tw_c, lam = stability(twin, sol, turns)
    if tw_c is None:
        print(f"stability: the frictionless tangent stays positive definite (lowest eigenvalue {lam:.3g} N m "
              f"at the end)")
    else:
        print(f"stability: the frictionless tangent has a negative eigenvalue from {tw_c:.3g} turns on (lowest {lam:.3g} N m "
              f"at the end).\n  The torque has passed the Greenhill limit of the pair (about 9 B / L, B = 2 E I):"
              f"\n  the straight two-ply followed here by symmetry is an unstable equilibrium; a real pair\n"
              f"  writhes into a plectoneme there (more pull delays it only a little: the pair is short).")
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
    ap.add_argument("--mu", type=float, default=0.3, help="friction coefficient (0: frictionless)")
    args = ap.parse_args()
    main(output=args.output, turns=args.turns, steps=args.steps, n_elements=args.elements, mu=args.mu)
