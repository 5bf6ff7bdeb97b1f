"""The twisted pair twisted on past Greenhill's torque: the two-ply writhes into a plectoneme loop.

The scene is the main job's (``examples/twisted_pair.py``: two steel wires of radius
``R = 0.5 mm``, 20 mm long, clamped below, their upper ends rigidly linked to a plate turned
about ``e_z`` under a 5 N dead pull, Coulomb friction ``mu = 0.3``) with two additions:

- a small imperfection: a dead lateral force of ``imperfection`` times the pull on the
  mid-node of each wire, so that the pair leaves the straight (unstable) two-ply;
- self-contact: each wire is made of two beams joined rigidly at mid-length, and contact is
  declared between every two of the four beams (the wires against each other, and the lower
  half of each wire against its upper half), so the arms of the loop push each other apart
  (a beam cannot be in contact with itself; elements sharing a node never pair).

Past the onset of writhing no quasi-static path is traceable under the dead pull: the pair
snaps into a loop.  The solve is stabilised (``solve(stabilize=...)``: artificial viscous
damping in pseudo-time chosen from a dissipated-energy fraction); the script prints per step
the twist, the torque, the ribbon's twist ``Tw`` and writhe ``Wr`` (``beamsolver.topology``; the
axis closed by half-lines along ``e_z``), the linking number ``Lk`` (the plate's turns: the pair
starts untwisted), ``|Lk - Tw - Wr| / Lk``, the fraction converted to writhe ``Wr / Lk`` and the
fraction of the strain energy dissipated by the stabilisation.  It checks ``Lk = Tw + Wr``
within 2 % and compares the torque at the onset of writhing with Greenhill's.

Measured (16 elements per wire, 40 steps, one run each on a loaded 2-core machine):

- defaults (``mu = 0.3``, imperfection 1e-2, ``stabilize = 2e-2``): writhing from 2.08 turns
  (10.9 N m), a loop at the top; stops at 2.12 of the 5 turns (Newton fails as the loop
  tightens on itself), ``Wr / Lk = 0.41``, ``|Lk - Tw - Wr| / Lk <= 1.5e-3``, dissipated 0.40 of
  the strain energy (warned: polluted), solve 134 s (286 s on a loaded machine);
- ``--stabilize 0.2``: 2.62 turns, ``Wr / Lk = 0.37``, dissipated 0.48; ``--stabilize 2e-3``:
  no writhing, stops at 4.16 turns as the unstabilised run (sticking friction stiffens the pair);
- ``--mu 0 --imperfection 1e-3 --stabilize 2e-3 --steps 80``: writhing from 1.63 turns at
  8.31 N m (``M L / B = 8.47``; the frictionless tangent turns indefinite at 8.36), the wires
  separate into two loops, stops at 1.64 turns with ``Wr / Lk = 0.56``.

The writhing torque with friction lies above Greenhill's ``8.99 B / L`` for ``B = 2 E I``: the
sticking wires bend stiffer than two free ones, and the damping delays the snap.

    python examples/plectoneme.py [--output plectoneme_output] [--turns 5] [--steps 40] [--mu 0.3] [--stabilize 2e-2]
"""
import argparse
import time

import numpy as np

import beamsolver as bs
from beamsolver import topology

R, LENGTH, PULL = 0.5e-3, 0.02, 5.0
GREENHILL = 8.99             # M L / B of a clamped-clamped rod at the onset of buckling
LK_MIN = 0.1                 # Lk = Tw + Wr is checked (relative error) from this many turns on
solve_options = dict(steps=40, stabilize=2e-2)   # for `beamsolver run examples/plectoneme.py`


def build(turns=5.0, n_elements=16, mu=0.3, imperfection=1e-2, pull=PULL, E=200e9, nu=0.3):
    """Returns ``(model, plate node, (wire a, wire b))``, each wire a pair ``(lower, upper)`` of
    beams of ``n_elements // 2`` elements."""
    sec = bs.Section.circular(radius=R, E=E, nu=nu)
    model = bs.Model()
    half = n_elements // 2
    wires = []
    for x, name in ((R, "wire a"), (-R, "wire b")):
        lo = model.add_beam(bs.geometry.straight((x, 0, 0), (x, 0, LENGTH / 2), half), sec, name=name + " lower")
        up = model.add_beam(bs.geometry.straight((x, 0, LENGTH / 2), (x, 0, LENGTH), half), sec,
                            name=name + " upper")
        model.join(lo.last, up.first, rigid=True)
        model.clamp(lo.first)
        model.add_load(lo.last, force=(0.0, imperfection * pull, 0.0), scale=lambda t: 1.0)
        wires.append((lo, up))
    plate = model.add_node((0.0, 0.0, LENGTH), name="plate")
    for lo, up in wires:
        model.join(plate, up.last, rigid=True)
    model.fix(plate, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: 2.0 * np.pi * turns * t})
    model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
    (a_lo, a_up), (b_lo, b_up) = wires
    opts = dict(mu=mu, smoothing=2e-3 * R)
    model.add_contact([a_lo, a_up], [b_lo, b_up], **opts)
    model.add_contact(a_lo, a_up, **opts)
    model.add_contact(b_lo, b_up, **opts)
    return model, plate, tuple(wires)


def wire_nodes(wire):
    """Node numbers along a wire (lower beam, then upper beam without the joined node)."""
    lo, up = wire
    return np.concatenate([lo.nodes, up.nodes[1:]])


def ribbon_measures(sol, wires, step):
    """``(Tw, Wr)`` of the ribbon of the two wires' centre lines at ``step``."""
    na, nb = wire_nodes(wires[0]), wire_nodes(wires[1])
    P = np.array([sol.pose(int(i), step) for i in np.concatenate([na, nb])])
    pa, pb = P[:len(na)], P[len(na):]
    axis, u = topology.ribbon(pa[:, :3, 3], pb[:, :3, 3])
    tw = topology.twist(axis, u, tangents=pa[:, :3, 0] + pb[:, :3, 0])
    return tw, topology.writhe_open(axis)


COLUMNS = ("turns = Lk", "torque [N m]", "plate z [mm]", "Tw", "Wr", "|Lk-Tw-Wr|/Lk", "Wr/Lk",
           "dissipated / strain energy", "contacts", "Newton it.")


def table(sol, plate, wires, turns):
    rows = []
    for k in range(len(sol.times)):
        lk = turns * sol.times[k]
        tw, wr = ribbon_measures(sol, wires, k)
        st = sol.stats[k].get("stabilization", {})
        c = sol.contact(k) or {}
        active = int((np.asarray(c.get("normal_force", np.zeros(0))) > 0).sum())
        err = abs(lk - tw - wr) / lk if lk > 0 else abs(tw + wr)
        rows.append((lk, sol.reaction(plate, k)[5], 1e3 * sol.position(plate, k)[2], tw, wr, err,
                     wr / lk if lk > 0 else 0.0, st.get("fraction", 0.0), active, sol.stats[k]["iterations"]))
    return rows


def onset(rows):
    """Twist [turns] and torque [N m] at the onset of writhing: the largest torque before the
    writhe exceeds 5 % of the linking number."""
    lk, torque, frac = (np.array([r[i] for r in rows]) for i in (0, 1, 6))
    before = frac < 0.05
    k = int(np.argmax(np.where(before, torque, -np.inf)))
    return lk[k], torque[k]


def main(output=None, turns=5.0, steps=40, n_elements=16, mu=0.3, stabilize=2e-2, imperfection=1e-2,
         verbose=False):
    """Solve, print the table and the checks; returns ``(solution, rows, wall time, checks)``."""
    model, plate, wires = build(turns=turns, n_elements=n_elements, mu=mu, imperfection=imperfection)
    t0 = time.perf_counter()
    try:
        sol = bs.solve(model, steps=steps, output=output, verbose=verbose, stabilize=stabilize)
    except bs.ConvergenceError as e:
        print(f"stopped: {e}")
        sol = e.solution
    wall = time.perf_counter() - t0
    rows = table(sol, plate, wires, turns)
    print(f"plectoneme: 2 wires R = {R * 1e3:g} mm, L = {LENGTH * 1e3:g} mm, {n_elements} elements each, mu = {mu}, "
          f"{turns:g} turns in {steps} steps, stabilize = {stabilize}, imperfection {imperfection:g} x pull")
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---:|" * len(COLUMNS))
    for lk, tq, z, tw, wr, err, fw, fd, nc, it in rows:
        print(f"| {lk:.4f} | {tq:.4g} | {z:.3f} | {tw:.4f} | {wr:.4f} | {err:.2e} | {fw:.3f} | {fd:.2e} | {nc} "
              f"| {it} |")
    B = 2.0 * model.beams[0].section.C[4, 4]
    worst = max((r[5] for r in rows if r[0] >= LK_MIN), default=np.nan)     # relative error: Lk not near 0
    tw_c, m_c = onset(rows)
    checks = dict(reached=turns * sol.times[-1], lk_error=worst, onset_turns=tw_c, onset_torque=m_c,
                  onset_ratio=m_c * LENGTH / B, wall=wall, writhe=rows[-1][6])
    print(f"reached {checks['reached']:.3f} of {turns:g} turns in {wall:.1f} s; Newton iterations "
          f"{int(sol.iterations.sum())}; writhe at the end {rows[-1][6]:.1%} of Lk")
    print(f"Lk = Tw + Wr: largest |Lk - Tw - Wr| / Lk {worst:.2e} ({'within' if worst <= 0.02 else 'NOT within'} 2 %)")
    print(f"onset of writhing at {tw_c:.3f} turns, torque {m_c:.4g} N m: M L / B = {checks['onset_ratio']:.2f} "
          f"(B = 2 E I; Greenhill clamped-clamped {GREENHILL}, the pair's frictionless tangent 8.36)")
    if output is not None:
        print(f"ParaView: open {output}/*.pvd (README: Tube filter with radius 'radius')")
        try:
            from beamsolver import viz
            png = f"{output}/plectoneme.png"
            viz.render(sol, step=-1, path=png, color_by="T", view="yz", window_size=(640, 640), zoom=1.3)
            print(f"picture: {png}")
        except ImportError:
            print("picture: install the [viz] extra (pyvista) to render one")
        except Exception as exc:          # a picture must never fail the run
            print(f"picture: not rendered ({exc})")
    return sol, rows, wall, checks


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="plectoneme_output")
    ap.add_argument("--turns", type=float, default=5.0)
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--mu", type=float, default=0.3)
    ap.add_argument("--stabilize", type=float, default=2e-2)
    ap.add_argument("--imperfection", type=float, default=1e-2)
    a = ap.parse_args()
    main(output=a.output, turns=a.turns, steps=a.steps, n_elements=a.elements, mu=a.mu, stabilize=a.stabilize,
         imperfection=a.imperfection, verbose=True)
