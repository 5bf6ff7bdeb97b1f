"""A mathematical benchmark: two short wires twisted far beyond any material's range.

The main job until issue 32 (now ``examples/twisted_pair.py``, 1 m long).  Material: a
linear-elastic rod with steel's moduli (``E = 200 GPa``, ``nu = 0.3``) and no yield limit,
on purpose: two turns over ``L = 20 mm`` give a surface shear strain ``R Phi / L = 0.31``
(printed: the largest von Mises equivalent strain 0.25), some thirty times the elastic range
of steel wire; the answer is the elastic rod's, kept as a hard test of contact, stability
checks and path following (``tests/examples/test_twisted_pair_extreme.py``, ``examples/plectoneme.py``).

Two straight wires (radius ``R``) touch along their length, side by side
at ``x = +-R``; both are clamped at ``z = 0``.  Their upper ends are rigidly
linked to a plate node on the pair's axis, which is turned about ``e_z`` by
``turns`` full turns while a small dead axial pull keeps the pair taut (its
other degrees of freedom held).  The wires wrap around each other into a
two-ply in contact, with Coulomb friction (``mu = 0.3`` by default; the slip
increment is the SE(3) finite difference of the seed paper; sliding starts at
an elastic slip of 0.005 element lengths, Abaqus' default penalty friction).

Stability: the lowest eigenvalue of the (frictionless) tangent (``bs.linearize``)
turns negative at 1.61 turns, where the torque is 8.21 N m (16 elements, 16
steps, interpolated between steps): beyond, the straight two-ply followed here
(by symmetry) is an unstable equilibrium, which the script reports; a real
pair writhes into a plectoneme there, which needs an imperfection and path
following.  The unstable mode is the pair bending as one rod with ``B = 2 E I``
(the wires slide along each other), Greenhill's mode of a twisted rod, but it
sets in at ``M L / B = 8.36``, 7 % below Greenhill's clamped-clamped 8.99
(8.83 N m), which the same eigenvalue test reproduces to 0.2 % for one wire
alone (``benchmarks/twisted_pair_stability.py``); the 5 N pull raises a
single rod's limit by only 0.3 %.

The script prints torque and axial force against the twist angle, writes
ParaView files (``.pvd`` + ``.vtu``, beams and contact points) to ``--output``
and, when the ``[viz]`` extra is installed, renders a picture.

    python examples/twisted_pair_extreme.py [--output twisted_pair_extreme_output] [--turns 2] [--steps 16] [--mu 0.3]

Contact options: a normal law smoothed over a gap of ``1e-3 (R1 + R2)``
(touching, lightly loaded wires: a sharp penalty makes Newton cycle on points
whose gap hovers at zero) and the default penalty (Young's modulus).
"""
import argparse
import time

import numpy as np

import beamsolver as bs


solve_options = dict(steps=16)      # for `beamsolver run examples/twisted_pair_extreme.py`


def build(radius=0.5e-3, length=0.02, n_elements=16, turns=2.0, pull=5.0, mu=0.3, E=200e9, nu=0.3,
          swap=False, smoothing=None, **contact_options):
    """Returns ``(model, plate node, (beam_a, beam_b))``; ``swap`` exchanges slave and master;
    ``contact_options`` go to ``add_contact``."""
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
    model.add_contact(slave, master, mu=mu, smoothing=2e-3 * radius if smoothing is None else smoothing,
                      **contact_options)
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


def lowest_eigenvalues(model, sol):
    """Lowest eigenvalue of the symmetric part of the tangent (``bs.linearize``) at steps 1..n."""
    lowest = []
    for k in range(1, len(sol.times)):
        K = bs.linearize(model, sol, k).K.toarray()
        lowest.append(np.linalg.eigvalsh(0.5 * (K + K.T))[0])
    return np.array(lowest)


def stability(model, sol, turns):
    """Twist [turns] from which the tangent (``bs.linearize``) has a negative eigenvalue (None
    if never), and its lowest eigenvalue at the last step.  ``model`` should be the frictionless
    twin of the solved scene: the elastic, load and normal-contact stiffness at the solution's
    poses is symmetric (conservative), so its eigenvalues decide stability; a slipping point's
    tangent is not symmetric, and sticking friction is left out (the estimate is conservative).
    Cheap here (about 200 unknowns, dense)."""
    lowest = lowest_eigenvalues(model, sol)
    neg = np.flatnonzero(lowest < 0)
    first = None if len(neg) == 0 else turns * sol.times[1 + neg[0]]
    return first, float(lowest[-1]) if len(lowest) else np.nan


def crossing(model, sol, plate, turns):
    """Twist [turns] and torque [N m] where the lowest eigenvalue of the frictionless twin
    ``model`` first turns negative, interpolated linearly between the two steps around it
    (``None`` if it never does, or already at step 1)."""
    lam = np.r_[np.inf, lowest_eigenvalues(model, sol)]
    neg = np.flatnonzero(lam < 0)
    if len(neg) == 0 or neg[0] < 2:
        return None
    k = neg[0]
    s = lam[k - 1] / (lam[k - 1] - lam[k])
    tw = turns * (sol.times[k - 1] + s * (sol.times[k] - sol.times[k - 1]))
    m0, m1 = sol.reaction(plate, k - 1)[5], sol.reaction(plate, k)[5]
    return float(tw), float(m0 + s * (m1 - m0))


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
    print(f"{sol.material_summary()}: linear elastic, a mathematical benchmark far beyond steel wire's "
          f"range (about 0.007)")
    twin, _, _ = build(length=length, n_elements=n_elements, turns=turns, mu=0.0, swap=swap)
    tw_c, lam = stability(twin, sol, turns)
    if tw_c is None:
        print(f"stability: the frictionless tangent stays positive definite (lowest eigenvalue {lam:.3g} N m "
              f"at the end)")
    else:
        B = 2.0 * model.beams[0].section.C[4, 4]
        cross = crossing(twin, sol, plate, turns)
        where = (f"at about {cross[0]:.3g} turns (torque {cross[1]:.3g} N m, M L / B = {cross[1] * length / B:.2f} "
                 f"with B = 2 E I; interpolated between steps)" if cross else f"from {tw_c:.3g} turns on")
        print(f"stability: the frictionless tangent has a negative eigenvalue {where}; lowest {lam:.3g} N m at "
              f"the end.\n  The straight two-ply followed here by symmetry is then an unstable equilibrium; a real "
              f"pair writhes into a plectoneme.\n  The mode is the pair bending as one rod (its wires sliding along "
              f"each other), as in Greenhill's twisted rod,\n  but a little below Greenhill's M L / B = 8.99 "
              f"({8.99 * B / length:.3g} N m; benchmarks/twisted_pair_stability.py).")
    if output is not None:
        print(f"ParaView: paraview --script={bs.io.paraview.paraview_script(output)} (or open {output}/*.pvd)")
        try:
            from beamsolver import viz
            png = f"{output}/twisted_pair_extreme.png"
            viz.render(sol, step=-1, path=png, color_by="T")
            print(f"picture: {png}")
        except ImportError:
            print("picture: install the [viz] extra (pyvista) to render one")
        except Exception as exc:          # a picture must never fail the run
            print(f"picture: not rendered ({exc})")
    return sol, rows, wall


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="twisted_pair_extreme_output")
    ap.add_argument("--turns", type=float, default=2.0)
    ap.add_argument("--steps", type=int, default=16)
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--mu", type=float, default=0.3, help="friction coefficient (0: frictionless)")
    args = ap.parse_args()
    main(output=args.output, turns=args.turns, steps=args.steps, n_elements=args.elements, mu=args.mu)
