"""Where the bending fixture's mid-length moment sits against the theory's ``M_f`` (issue 27, session 7).

Virgin ramps ``0 -> amplitude kappa_b`` (``t`` in ``[1, 2]``, ``steps`` per unit t) of ``examples/strand_bending.py``
for lays x elements per lay; prints, at the ramp's end, ``(M - EI_min kappa) / M_f - 1`` at mid-length, its mean
over the middle lay, the friction part with the model's own frictionless stiffness (``stiffness_checks``) and the
moment along the strand (z / L); with ``--line-load`` the P-delta line load is scaled by that factor (sensitivity).

    python benchmarks/strand_fixture_moment.py [--lays 2 4 6] [--elements 16 48] [--amplitude 5] [--steps 8]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import strand_bending as sb  # noqa: E402

ALONG = (0.05, 0.125, 0.25, 0.375, 0.5)


def ramp(lays, epl, amplitude, steps, line_load=1.0):
    """``(mid error, middle-lay mean error, profile errors at ALONG, kappa, M_mid, theory, CPU s)``."""
    model, st, fx, T, k = sb.build(lays, epl, amplitude=amplitude, lay=sb.LAY_UJ)
    for ld in fx.line_loads:
        ld.q = ld.q * line_load
    c0 = time.process_time()
    sol = bs.solve(model, steps=int(round(2 * steps)), t_end=2.0)
    cpu = time.process_time() - c0
    outer = np.concatenate([w.elements for w in st.wires[1]])
    th = sb.theory(float(np.mean(sol.section_forces[int(np.argmin(np.abs(sol.times - 1.0))), outer, 0])), lay=sb.LAY_UJ)
    j, kap = len(sol.times) - 1, fx.curvature(sol.times[-1])
    err = lambda z: (fx.moment(sol, fx.z0 + z, step=j) - th["EI_min"] * kap) / th["M_f"] - 1   # noqa: E731
    L = fx.length
    lay = np.linspace(L / 2 - sb.LAY / 2, L / 2 + sb.LAY / 2, 33)
    return err(L / 2), float(np.mean([err(z) for z in lay])), [err(f * L) for f in ALONG], kap, \
        fx.moment(sol, step=j), th, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays", type=float, nargs="+", default=[2, 4, 6])
    ap.add_argument("--elements", type=int, nargs="+", default=[16, 48])
    ap.add_argument("--amplitude", type=float, default=5.0)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--line-load", type=float, default=1.0)
    ap.add_argument("--no-checks", action="store_true", help="skip the frictionless stiffness (friction-part column)")
    a = ap.parse_args()
    print(f"virgin ramp to {a.amplitude} kappa_b, {a.steps} steps per unit t, line load x {a.line_load}; "
          "errors (M - EI_min kappa) / M_f - 1; CPU s from time.process_time")
    print("| lays | el/lay | mid-length | middle lay (mean) | friction part M - EI_0 kappa, mid | EI_0 / EI_min - 1 | "
          + " | ".join(f"z = {f:g} L" for f in ALONG) + " | CPU s |")
    print("|---:|---:|---:|---:|---:|---:|" + "---:|" * len(ALONG) + "---:|")
    for epl in a.elements:
        for lays in a.lays:
            mid, mean, prof, kap, M, th, cpu = ramp(lays, epl, a.amplitude, a.steps, a.line_load)
            if a.no_checks:
                fp, de = np.nan, np.nan
            else:
                (EI0, F0), _ = sb.stiffness_checks(lays, epl, lay=sb.LAY_UJ)
                fp, de = (M - EI0 * kap) / th["M_f"] - 1, EI0 / sb.theory(F0, lay=sb.LAY_UJ)["EI_min"] - 1
            print(f"| {lays:g} | {epl} | {mid:+.2%} | {mean:+.2%} | {fp:+.2%} | {de:+.2%} | "
                  + " | ".join(f"{e:+.1%}" for e in prof) + f" | {cpu:.1f} |", flush=True)


if __name__ == "__main__":
    main()
