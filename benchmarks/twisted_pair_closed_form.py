"""The main job (``examples/twisted_pair.py``) against its closed forms as the mesh is refined.

For 8..128 elements a wire (``--elements``), frictionless and with ``mu = 0.3``, the
torque, the ply angle in the middle half of the wires and the plate's shortening at two
turns, each relative to the uniform-helix closed form (docs/theory_twoply.md), and the
largest von Mises surface stress relative to the helix's.  The last rows extrapolate the
three finest meshes (Richardson, observed order): what remains is the model's continuum
answer minus the closed form, the clamped ends (bending length ``sqrt(B / T_w)`` = 6.3 mm
of the 1 m wires) and the contact penetration, which the closed form leaves out.

    python benchmarks/twisted_pair_closed_form.py [--elements 8,16,32,64,128] [--mu 0,0.3] [--c 1e4,1e5]
        [--exact-n none]

``--c``: exact stick's ``c`` (``penalty_t``, N/m^2) given explicitly, one row per value (default: the library's);
``--exact-n none``: the default ``c`` as before session 7, ``24 EI / L_e^4`` (``contact.system.EXACT_N = None``).
Newton iterations with the cut-backs in brackets; CPU seconds (``time.process_time``; the machine may be shared).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import twisted_pair as tp  # noqa: E402

QUANTITIES = ("torque", "ply angle", "shortening", "von Mises")


def run(n_elements, mu, turns=2.0, steps=16, c=None):
    """``(torque, ply angle, shortening, von Mises stress, Newton iterations, cut-backs, CPU s)`` at the last step
    (``c``: exact stick's ``penalty_t``, None: the default)."""
    model, plate, beams = tp.build(n_elements=n_elements, turns=turns, mu=mu,
                                   **({} if c is None else dict(penalty_t=c)))
    t0 = time.process_time()
    sol = bs.solve(model, steps=steps, verbose=False)
    cpu = time.process_time() - t0
    dz = sol.position(plate, 0)[2] - sol.position(plate, -1)[2]
    theta = np.mean([tp.ply_angle(sol, b) for b in beams])
    vm = sol.equivalent_strain(-1).max() * beams[0].section.E
    cuts = int(sum(s.get("cutbacks", 0) for s in sol.stats))
    return (sol.reaction(plate, -1)[5], theta, dz, vm, int(sol.iterations.sum()), cuts, cpu)


def richardson(v):
    """Extrapolated value and observed order from the three finest values ``v`` (element size halving)."""
    d1, d2 = v[-2] - v[-3], v[-1] - v[-2]
    if d1 == 0 or d2 == 0 or d1 / d2 <= 1:
        return v[-1], np.nan
    p = np.log2(d1 / d2)
    return v[-1] + d2 / (2**p - 1), p


def main(elements=(8, 16, 32, 64, 128), mus=(0.0, 0.3), cs=(None,)):
    cf = tp.closed_form(4 * np.pi)
    ref = (cf["torque"], cf["ply_angle"], cf["shortening"], cf["von_mises"])
    print(f"closed form at 2 turns: torque {ref[0]:.6g} N m, ply angle {np.degrees(ref[1]):.5f} deg, "
          f"shortening {ref[2] * 1e6:.5g} um, von Mises {ref[3] / 1e6:.4g} MPa")
    print("| mu | c | elements | torque / cf - 1 | ply angle / cf - 1 | shortening / cf - 1 | von Mises / cf - 1 "
          "| Newton it. (cut-backs) | CPU [s] |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for mu in mus:
        for c in cs:
            vals = []
            label = "default" if c is None else f"{c:g}"
            for n in elements:
                try:
                    *v, it, cuts, cpu = run(n, mu, c=c)
                except bs.ConvergenceError as e:
                    print(f"| {mu:g} | {label} | {n} | failed: {str(e)[:80]} | | | | | |", flush=True)
                    continue
                vals.append(v)
                rel = [x / r - 1 for x, r in zip(v, ref)]
                print(f"| {mu:g} | {label} | {n} | " + " | ".join(f"{e:+.2e}" for e in rel) + f" | {it} ({cuts}) "
                      f"| {cpu:.1f} |", flush=True)
            if len(vals) >= 3 and len(vals) == len(elements):
                ext = [richardson(np.array(vals)[:, j]) for j in range(len(QUANTITIES))]
                cells = [f"{x / r - 1:+.2e} (p {p:.1f})" for (x, p), r in zip(ext, ref)]
                print(f"| {mu:g} | {label} | extrapolated | " + " | ".join(cells) + " | | |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", default="8,16,32,64,128")
    ap.add_argument("--mu", default="0,0.3")
    ap.add_argument("--c", default=None, help="exact stick's c (penalty_t) values, comma-separated")
    ap.add_argument("--exact-n", default=None, help="contact.system.EXACT_N ('none': the rule before session 7)")
    a = ap.parse_args()
    if a.exact_n is not None:
        from beamsolver.contact import system
        system.EXACT_N = None if a.exact_n.lower() == "none" else float(a.exact_n)
    main(tuple(int(x) for x in a.elements.split(",")), tuple(float(x) for x in a.mu.split(",")),
         (None,) if a.c is None else tuple(float(x) for x in a.c.split(",")))
