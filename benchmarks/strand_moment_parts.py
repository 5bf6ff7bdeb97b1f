"""The bent strand's moment by parts: the wires' axial forces (lever arms), the wires' own section moments and the
core's, with friction and without, averaged over 60 cuts through the middle lay (10 per sixth of a lay, the period of the wires' pattern) (issue 27: where the friction
moment's last percents go; docs/theory_strand_bending.md section 5).

    python benchmarks/strand_moment_parts.py [--lays 4] [--elements 48] [--amplitude 5] [--lay 114.6]

Virgin branch to ``amplitude kappa_b`` (4 steps with friction, 1 without: elastic); parts about the strand's
EA-weighted centroid at each cut (``Solution.cut_resultant``: a wire's own section moment is its cut about its own
centre, its lever part the difference).  The friction part of each is the difference of the two runs.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import strand_bending as sb  # noqa: E402


def parts(res, lay, cuts=60):
    """Mean over ``cuts`` cuts in the middle lay (the pattern repeats every sixth of a lay: several cuts per sixth) of ``(total, lever, wires' sections, core)`` at the last step."""
    sol, st, fx = res["sol"], res["strand"], res["fixture"]
    beams, core = list(st.all_wires), st.wires[0][0]
    out = []
    for f in (np.arange(cuts) + 0.5) / cuts - 0.5:
        z = fx.z0 + 0.5 * fx.length + f * lay
        tot = sol.cut_resultant(beams, z, bending_axis=fx.axis, step=-1)
        row = np.array([tot.bending[0], 0.0, 0.0, 0.0])
        for b in beams:
            own = sol.cut_resultant([b], z, bending_axis=fx.axis, step=-1).bending[0]
            full = sol.cut_resultant([b], z, point=tot.point, bending_axis=fx.axis, step=-1).bending[0]
            row[1] += full - own
            row[3 if b is core else 2] += own
        out.append(row)
    return np.mean(out, axis=0), np.std(out, axis=0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays", type=float, default=4.0)
    ap.add_argument("--elements", type=int, default=48)
    ap.add_argument("--amplitude", type=float, default=5.0)
    ap.add_argument("--lay", type=float, default=sb.LAY_UJ * 1e3, help="lay length [mm]")
    a = ap.parse_args()
    lay = a.lay * 1e-3
    got = {}
    for mu in (sb.MU, 0.0):
        res = sb.run(a.lays, a.elements, mu=mu, amplitude=a.amplitude, steps=4 if mu else 1, t_end=2.0, lay=lay)
        got[mu] = parts(res, lay), res["kappa"][-1], sb.theory(res["F"], lay=lay)
    (m1, s1), kap, th = got[sb.MU]
    (m0, s0), _, _ = got[0.0]
    EIw = th["EI_min"] - sb.E * np.pi * sb.RC**4 / 4
    ref0 = [th["EI_min"] * kap, 0.0, EIw * kap, th["EI_min"] * kap - EIw * kap]
    print(f"{a.lays:g} lays, {a.elements} el/lay, lay {a.lay:g} mm, kappa = {a.amplitude:g} kappa_b = {kap:.5g} 1/m; "
          f"moments [N m] about the bending axis, mean (sd) over 60 cuts of the middle lay")
    print("| part | with friction | frictionless | frictionless theory | friction part | of M_f (theory "
          f"{th['M_f']:.4f}) |")
    print("|---|---:|---:|---:|---:|---:|")
    for i, name in enumerate(("total", "wires' axial forces (lever arms)", "wires' own section moments", "core")):
        d = m1[i] - m0[i]
        print(f"| {name} | {m1[i]:.4f} ({s1[i]:.4f}) | {m0[i]:.4f} ({s0[i]:.4f}) | {ref0[i]:.4f} | {d:.4f} "
              f"| {d / th['M_f']:+.4f} |")


if __name__ == "__main__":
    main()
