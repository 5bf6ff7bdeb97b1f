"""Strand bending hysteresis (examples/strand_bending.py) at several meshes: the answer-quality table
(theory vs model) and the runtime (Newton iterations, cut-backs, CPU time) per mesh.

    python benchmarks/strand_bending.py [--meshes 8 12] [--lays 2] [--amplitude 5] [--steps 4] [--lay 114.6]

The library's default stick (exact); ``--slip-tolerance`` sets the penalty stick's elastic slip, in element
lengths, when the example's ``STICK`` is "penalty".  The first slip: ``sb.first_slip`` (steps of 0.01 kappa_b).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import strand_bending as sb  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", type=int, nargs="+", default=[8, 12], help="elements per lay")
    ap.add_argument("--lays", type=float, default=sb.LAYS)
    ap.add_argument("--amplitude", type=float, default=sb.AMPLITUDE)
    ap.add_argument("--steps", type=int, default=sb.STEPS)
    ap.add_argument("--slip-tolerance", type=float, default=sb.SLIP_TOLERANCE)
    ap.add_argument("--lay", type=float, default=sb.LAY_UJ * 1e3, help="lay length [mm]")
    a = ap.parse_args()
    sb.SLIP_TOLERANCE = a.slip_tolerance
    table, runtime = {}, []
    for n in a.meshes:
        lay = a.lay * 1e-3
        res = sb.run(a.lays, n, amplitude=a.amplitude, steps=a.steps, slip_tolerance=a.slip_tolerance, lay=lay)
        (EI0, F0), (EIt, Ft) = sb.stiffness_checks(a.lays, n, lay=lay)
        th, rows = sb.compare(res, EI0)
        rows += [("EI frictionless contact", th["EI_min"], EI0, EI0 / sb.theory(F0, lay=lay)["EI_min"] - 1),
                 ("EI wires tied to the core", th["EI_max"], EIt, EIt / sb.theory(Ft, lay=lay)["EI_max"] - 1)]
        fs = sb.first_slip(a.lays, n, lay=lay)
        rows.append((f"first slip, ramp in steps of {sb.ONSET[1]:g} kappa_b [1/m]", fs["kappa_b"], fs["kappa"],
                     fs["kappa"] / fs["kappa_b"] - 1))
        for name, t, m, e in rows:
            table.setdefault(name, [t]).append((m, e))
        n_el = sum(w.n_elements for w in res["strand"].all_wires)
        runtime.append((n, n_el, len(res["times"]) - 1, res["iterations"], res["cutbacks"], res["cpu"]))
    print(f"1+6 strand, {a.lays} lays, +-{a.amplitude} kappa_b, {a.steps} steps per unit t, "
          f"slip_tolerance {a.slip_tolerance}")
    head = " | ".join(f"{n} el/lay: model (error)" for n in a.meshes)
    print(f"| quantity | theory | {head} |")
    print("|---|---:|" + "---:|" * len(a.meshes))
    for name, (t, *cols) in table.items():
        cells = " | ".join(f"{m:.4g} ({e:+.3g})" for m, e in cols)
        print(f"| {name} | {t:.4g} | {cells} |")
    print()
    print("| el/lay | elements | steps | Newton iterations | cut-backs | CPU [s] |")
    print("|---:|---:|---:|---:|---:|---:|")
    for row in runtime:
        print("| {} | {} | {} | {} | {} | {:.1f} |".format(*row))


if __name__ == "__main__":
    main()
