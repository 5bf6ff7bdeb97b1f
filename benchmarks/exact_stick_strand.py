"""Exact stick on the bent 1+6 strand (examples/strand_bending.py): first slip, stick stiffness and moment
against the mesh and the complementarity parameter c = ``penalty_t`` (issue 26; table in docs/benchmarks.md, "Compiled point terms,
strand bending").

    python benchmarks/exact_stick_strand.py [--meshes 8 16 32] [--penalties 1 10] [--lays 2] [--upto 1.6]
        [--saddle auto direct]

Virgin ramp ``0 -> upto kappa_b`` in steps of 0.05 kappa_b (``t`` in ``[1, 2]``, after the frictionless pull);
first slip = the first step with a slipping point in the middle half (``status``); the c column is
``penalty_t / E`` (the default: ``EXACT_C EI / L_e^4`` of the slave wire, 24 EI / L_e^4).  ``--saddle``: how the
saddle-point Newton systems are solved (``auto``: the library's rule, ``nonlinear/augmented.py`` from
``MIN_UNKNOWNS`` unknowns; ``direct``: factorised as such), each row with each; CPU by ``time.process_time``.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import strand_bending as sb  # noqa: E402


def row(elements_per_lay, factor, lays, upto, saddle="auto"):
    from beamsolver.nonlinear import augmented
    augmented.ENABLED = saddle != "direct"
    orig = sb._contact_options
    extra = {} if factor is None else dict(penalty_t=factor * sb.E)
    sb._contact_options = lambda stick, tol: orig("exact", tol) | extra
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        res = sb.run(lays, elements_per_lay, amplitude=upto, steps=int(round(upto / 0.05)), t_end=2.0, lay=sb.LAY_UJ)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        sb._contact_options = orig
        augmented.ENABLED = True
    th = sb.theory(res["F"], lay=sb.LAY_UJ)
    up = np.flatnonzero(res["times"] > 1.0)
    hit = up[res["share"][up] > 0]
    first = res["kappa"][hit[0]] / th["kappa_b"] if len(hit) else np.nan
    return dict(el=elements_per_lay, penalty="default (24 EI / L_e^4)" if factor is None else f"{factor:g} E",
                EI0=res["M"][up[0]] / res["kappa"][up[0]], first=first, M=res["M"][up[-1]],
                Mth=float(np.ravel(sb.moment(res["kappa"][up[-1]], th))[0]), share=res["share"][up[-1]],
                iterations=res["iterations"], wall=wall, EI_max=th["EI_max"], EI_min=th["EI_min"], cpu=cpu,
                saddle=saddle)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", type=int, nargs="+", default=[8, 16, 32])
    ap.add_argument("--penalties", type=float, nargs="+", default=[1.0],
                    help="penalty_t / E, the complementarity parameter c of the exact stick (1: the default, 24 EI / L_e^4)")
    ap.add_argument("--lays", type=float, default=2.0)
    ap.add_argument("--upto", type=float, default=1.6)
    ap.add_argument("--saddle", nargs="+", default=["auto"], choices=["auto", "direct"])
    a = ap.parse_args()
    print("| el/lay | c (penalty_t) | EI initial [N m^2] | first slip / kappa_b | first slip / kappa_b of the model "
          "| M(end) [N m] | theory [N m] | slipping share | Newton it. | wall [s] | saddle | CPU [s] |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for n in a.meshes:
        for f, saddle in [(f, s) for f in a.penalties for s in a.saddle]:
            r = row(n, None if f == 1.0 else f, a.lays, a.upto, saddle)
            # the plane-section onset scaled by the model's own stick stiffness: the wires' force gradient at
            # the neutral axis grows like (EI_stick - EI_min) (docs/theory_strand_bending.md, section 5)
            own = r["first"] * (r["EI0"] - r["EI_min"]) / (r["EI_max"] - r["EI_min"])
            print(f"| {r['el']} | {r['penalty']} | {r['EI0']:.2f} | {r['first']:.3f} | {own:.3f} | {r['M']:.4f} | {r['Mth']:.4f} "
                  f"| {r['share']:.3f} | {r['iterations']} | {r['wall']:.1f} | {saddle} | {r['cpu']:.1f} |", flush=True)
    print(f"EI_max (plane sections) {r['EI_max']:.1f} N m^2")


if __name__ == "__main__":
    main()
