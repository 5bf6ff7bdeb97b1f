"""First slip of the bent 1+6 strand against the plane-section kappa_b: lay angle, mesh and the wires' compliance
(issues 26 and 27; docs/theory_strand_bending.md section 5).

    python benchmarks/strand_onset.py [--lays-mm 114.6 171.9 229.2 343.8] [--meshes 24 48] [--c 0 0.1 10]
        [--compliance]

Rows 1: the example's wires (Utting & Jones 1987) on several lay lengths, default options (exact stick), 2 lays;
first slip from the stick flags of the middle half on a ramp in steps of 0.01 kappa_b (``first_slip``); the stick
branch's slope ``EI0`` and its deficit ``(EI_max - EI0) / S`` (``S`` the Steiner term of plane sections); the
model's own onset ``kappa_b S / (EI0 - EI_min)``.  Rows 2 (``--compliance``): the deficit with the wires' (and
core's) shear, torsion or bending stiffness scaled, 2 lays, 16 el/lay, one step to 0.5 kappa_b.  CPU by
``time.process_time``.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import strand_bending as sb  # noqa: E402

SCALES = {"shear": (1, 2), "torsion": (3,), "bending": (4, 5)}     # rows/columns of the section's C


def _with_c(factor):
    """The example's contact options with ``penalty_t = factor E`` (the exact stick's ``c``; ``None``: the default)."""
    orig = sb._contact_options
    if factor is not None:
        sb._contact_options = lambda stick, tol: orig(stick, tol) | dict(penalty_t=factor * sb.E)
    return orig


def onset_rows(lays_mm, meshes, lays, factors=(None,)):
    print("| lay [mm] | lay angle [deg] | el/lay | c | EI0 [N m^2] | EI_max | deficit / S | first slip / kappa_b "
          "| model's own onset / kappa_b | first slip / own | Newton it. | CPU [s] |")
    print("|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for lay, n, f in [(lay, n, f) for lay in lays_mm for n in meshes for f in factors]:
        c0 = time.process_time()
        orig = _with_c(f)
        try:
            fs = sb.first_slip(lays, n, lay=lay * 1e-3)
        finally:
            sb._contact_options = orig
        th = sb.theory(fs["res"]["F"], lay=lay * 1e-3)
        c = "default" if f is None else f"{f:g} E"
        print(f"| {lay:g} | {np.degrees(th['beta']):.2f} | {n} | {c} | {fs['EI0']:.2f} | {th['EI_max']:.2f} "
              f"| {(th['EI_max'] - fs['EI0']) / th['S']:.4f} | {fs['kappa'] / fs['kappa_b']:.3f} "
              f"| {fs['own'] / fs['kappa_b']:.3f} | {fs['kappa'] / fs['own']:.3f} | {fs['res']['iterations']} "
              f"| {time.process_time() - c0:.1f} |", flush=True)


def compliance_rows(factors=((None, 1.0), ("shear", 100.0), ("shear", 1e4), ("torsion", 100.0),
                             ("shear+torsion", 100.0), ("bending", 0.01))):
    print("| stiffness scaled | factor | EI0 (stick) [N m^2] | EI frictionless | deficit (EI_max - EI0) / S "
          "| (EI0 - EI frictionless) / S |")
    print("|---|---:|---:|---:|---:|---:|")
    for what, f in factors:
        secs = []
        for R in (sb.RC, sb.RW):
            s = bs.Section.circular(radius=R, E=sb.E, nu=sb.NU)
            for i in [i for w in (what or "").split("+") for i in SCALES.get(w, ())]:
                s.C[i, i] *= f
            secs.append(s)
        EI = []
        for mu in (sb.MU, 0.0):
            res = sb.run(2, 16, mu=mu, amplitude=0.5, steps=1, t_end=2.0, sections=tuple(secs), lay=sb.LAY_UJ)
            j = np.flatnonzero(res["times"] > 1.0)[0]
            EI.append(res["M"][j] / res["kappa"][j])
        th = sb.theory(res["F"], lay=sb.LAY_UJ)
        print(f"| {what or '-'} | {f:g} | {EI[0]:.3f} | {EI[1]:.3f} | {(th['EI_max'] - EI[0]) / th['S']:.4f} "
              f"| {(EI[0] - EI[1]) / th['S']:.4f} |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays-mm", type=float, nargs="*", default=[114.6, 171.9, 229.2, 343.8])
    ap.add_argument("--meshes", type=int, nargs="+", default=[24, 48])
    ap.add_argument("--lays", type=float, default=2.0)
    ap.add_argument("--compliance", action="store_true")
    ap.add_argument("--c", type=float, nargs="+", default=[0.0],
                    help="penalty_t / E, the exact stick's c (0: the default, 24 EI / L_e^4 at 16 el/beam)")
    a = ap.parse_args()
    if a.compliance:
        compliance_rows()
    if a.lays_mm:
        onset_rows(a.lays_mm, a.meshes, a.lays, [None if f == 0 else f for f in a.c])


if __name__ == "__main__":
    main()
