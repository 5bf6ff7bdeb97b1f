"""Where the twisted pair becomes unstable, against Greenhill's limit of a twisted rod.

The 20 mm pair (``examples/twisted_pair_extreme.py``, the main job until issue 32) reports the twist from which the
frictionless tangent (``bs.linearize``) has a negative eigenvalue.  This script
locates that crossing (the lowest eigenvalue interpolated linearly between
steps) for

1. one wire alone (``B = E I``), twisted with the pair's end conditions (bottom
   clamped, top: rotation prescribed, lateral motion and tilt held, axial motion
   free under a dead pull), without and with the 5 N pull: checks the method
   against Greenhill's clamped-clamped value ``M L / B = 8.99`` (2 pi x 1.4303);
2. the pair (two touching wires, contact smoothed as in the example), with the
   example's friction (mu = 0.3; eigenvalues of the frictionless twin) and
   frictionless (mu = 0),

and prints the twist, the torque at the crossing and ``M L / B`` with
``B = 2 E I`` for the pair.

    python benchmarks/twisted_pair_stability.py [--elements 16] [--resolution 16]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import twisted_pair_extreme as twisted_pair  # noqa: E402

R, L, E, NU = 0.5e-3, 0.02, 200e9, 0.3
GREENHILL = 8.99          # M L / B of a clamped-clamped rod at the onset of buckling, no axial force


def single_wire(n_elements, turns, pull):
    """One wire with the pair's end conditions; returns ``(model, top node, bottom node)``."""
    sec = bs.Section.circular(radius=R, E=E, nu=NU)
    model = bs.Model()
    w = model.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, L), n_elements), sec)
    model.clamp(w.first)
    model.fix(w.last, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: 2.0 * np.pi * turns * t})
    if pull:
        model.add_load(w.last, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
    return model, w.last


def lowest_eigenvalues(model, sol):
    """Lowest eigenvalue of the symmetric part of the tangent at every step (dense)."""
    out = []
    for k in range(len(sol.times)):
        K = bs.linearize(model, sol, k).K.toarray()
        out.append(np.linalg.eigvalsh(0.5 * (K + K.T))[0])
    return np.array(out)


def crossing(lam, twist, torque):
    """Twist and torque where ``lam`` first turns negative (linear interpolation), or ``None``."""
    neg = np.flatnonzero(lam < 0)
    if len(neg) == 0 or neg[0] == 0:
        return None
    k = neg[0]
    s = lam[k - 1] / (lam[k - 1] - lam[k])
    return twist[k - 1] + s * (twist[k] - twist[k - 1]), torque[k - 1] + s * (torque[k] - torque[k - 1])


def run_wire(n_elements, resolution, pull, turns=2.25):
    model, top = single_wire(n_elements, turns, pull)
    steps = int(round(turns * resolution))
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps)
    lam = lowest_eigenvalues(model, sol)
    torque = np.array([sol.reaction(top, k)[5] for k in range(len(sol.times))])
    return crossing(lam, turns * sol.times, torque), time.perf_counter() - t0


def run_pair(n_elements, resolution, mu, turns=1.75):
    model, plate, _ = twisted_pair.build(n_elements=n_elements, turns=turns, mu=mu)
    twin = twisted_pair.build(n_elements=n_elements, turns=turns, mu=0.0)[0]
    steps = int(round(turns * resolution))
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps)
    lam = lowest_eigenvalues(twin, sol)
    torque = np.array([sol.reaction(plate, k)[5] for k in range(len(sol.times))])
    return crossing(lam, turns * sol.times, torque), time.perf_counter() - t0


def main(n_elements=16, resolution=16):
    EI = bs.Section.circular(radius=R, E=E, nu=NU).C[4, 4]
    rows = []
    for pull in (0.0, 5.0):
        c, wall = run_wire(n_elements, resolution, pull)
        rows.append((f"one wire, pull {pull:g} N", EI, c, wall))
    for mu in (0.3, 0.0):
        c, wall = run_pair(n_elements, resolution, mu)
        rows.append((f"pair, mu = {mu:g} (frictionless tangent), pull 5 N", 2 * EI, c, wall))
    print(f"twisted pair stability: R = {R * 1e3} mm, L = {L * 1e3} mm, E = {E:.3g} Pa, nu = {NU}, "
          f"{n_elements} elements per wire, steps of 1/{resolution} turn; Greenhill M L / B = {GREENHILL}")
    print("| case | B [N m^2] | twist at crossing [turns] | torque [N m] | M L / B | 8.99 B / L [N m] | wall [s] |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, B, c, wall in rows:
        tw, M = c if c is not None else (np.nan, np.nan)
        print(f"| {name} | {B:.4g} | {tw:.3f} | {M:.4g} | {M * L / B:.3f} | {GREENHILL * B / L:.4g} | {wall:.1f} |")
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--resolution", type=int, default=16, help="load steps per turn")
    a = ap.parse_args()
    main(a.elements, a.resolution)
