"""The 1+6 strand against thin-rod theory: which term differs, and whether it is an end effect.

``examples/seven_wire_strand.py`` compares the model with ``cables.rod_stiffness``
(geometric changes of the wires' curvature and torsion, as Costello) and with
``measure="material"`` (``rod*``: per unit reference length, the SE(3) beam's
strain measure).  This script measures, at one lay angle,

1. the fixed-end torque ``M / eps`` with the wires' torsion or bending stiffness
   switched off (scaled by 1e-3), against each theory's share of those terms;
2. for strands 0.5 to 4 lay lengths long: ``M / eps`` (fixed ends, ``K_ew``),
   ``M / theta`` (twist, no strain: ``K_ww``) and the free-end stiffness
   ``F / eps`` (plate free to turn), each over both theories.

    python benchmarks/strand_theory.py [--angle 10] [--lays 0.5 1 2 4]
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import seven_wire_strand as sw  # noqa: E402
from beamsolver import cables# noqa: E402

RC, RW, EPS = 1.03e-3, 1.0e-3, 1e-4


def theories(beta):
    args = (RC, RW, 6, RC + RW, np.deg2rad(beta), sw.E)
    return {"rod": cables.rod_stiffness(*args, nu=sw.NU),
            "rod*": cables.rod_stiffness(*args, nu=sw.NU, measure="material")}


def fixed_torque(beta, lays=0.5, scale_GJ=1.0, scale_EI=1.0):
    """``M / eps`` with fixed ends, the outer wires' GJ and EI scaled."""
    model, st, plate = sw.build(beta, False, EPS, RC, RW, True, 24, lays)
    C = bs.Section.circular(radius=RW, E=sw.E, nu=sw.NU).C
    for w in st.wires[1]:
        w.section = bs.Section(EA=C[0, 0], GA2=C[1, 1], GA3=C[2, 2], GJ=scale_GJ * C[3, 3],
                               EI2=scale_EI * C[4, 4], EI3=scale_EI * C[5, 5], radius=RW)
    return st.resultant(bs.solve(model, steps=1), plate)[1] / EPS


def twist_torque(beta, lays):
    """``M / theta`` with the plate turned by ``theta L`` (``r theta = EPS``) and no strain."""
    model, st, plate = sw.build(beta, False, EPS, RC, RW, True, 24, lays)
    theta = EPS / (RC + RW)
    model.constraints.pop(plate)            # replace the stretch by a rotation of the plate
    model.prescribe(plate, bs.motion.rotation((0, 0, 1), theta * st.length))
    return st.resultant(bs.solve(model, steps=1), plate)[1] / theta


def term_table(beta):
    b = np.deg2rad(beta)
    s, c, r = np.sin(b), np.cos(b), RC + RW
    G, Ih = sw.E / (2 * (1 + sw.NU)), np.pi * RW**4 / 4
    k0, t0 = s**2 / r, s * c / r
    share = {   # K_ew terms of the wires' torsion and bending, m / cos b * D * dk/deps * dk/dtheta
        "rod": (-(6 / c) * G * 2 * Ih * c**2 * np.cos(2 * b) * np.cos(2 * b) * s * c / r,
                -(6 / c) * sw.E * Ih * 2 * s * c**3 * 2 * s**2 * c**2 / r),
        "rod*": ((6 / c) * G * 2 * Ih * (c**2 * np.cos(2 * b) + r * s * c * t0) * (c**2 * t0 - np.cos(2 * b) * s * c / r),
                 (6 / c) * sw.E * Ih * (2 * s * c**3 + r * s * c * k0) * (c**2 * k0 - 2 * s**2 * c**2 / r))}
    base = fixed_torque(beta, scale_GJ=1e-3, scale_EI=1e-3)
    gj = fixed_torque(beta, scale_GJ=1.0, scale_EI=1e-3) - base
    ei = fixed_torque(beta, scale_GJ=1e-3, scale_EI=1.0) - base
    print(f"1. K_ew terms at {beta:g} deg, half a lay [N m]: model (switching the term on) and theories")
    print("| term | model | rod | rod* |\n|---|---:|---:|---:|")
    print(f"| wire torsion GJ | {gj:.4g} | {share['rod'][0]:.4g} | {share['rod*'][0]:.4g} |")
    print(f"| wire bending EI | {ei:.4g} | {share['rod'][1]:.4g} | {share['rod*'][1]:.4g} |")


def length_table(beta, lays_list):
    th = theories(beta)
    print(f"\n2. {beta:g} deg, computed / theory against the strand length")
    print("| lays | K_ew / rod | K_ew / rod* | K_ww / rod | K_ww / rod* | free / rod | free / rod* | wall [s] |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for lays in lays_list:
        t0 = time.perf_counter()
        kew = fixed_torque(beta, lays)
        kww = twist_torque(beta, lays)
        free = sw.solve_strand(beta, True, EPS, RC, RW, True, 24, lays)[0]
        cells = []
        for i, v in ((1, kew), (2, kww)):
            cells += [v / th["rod"][i], v / th["rod*"][i]]
        cells += [free / (k[0] - k[1] ** 2 / k[2]) for k in (th["rod"], th["rod*"])]
        print(f"| {lays:g} | " + " | ".join(f"{x:.4f}" for x in cells) + f" | {time.perf_counter() - t0:.1f} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--angle", type=float, default=10.0, help="lay angle [deg]")
    ap.add_argument("--lays", type=float, nargs="+", default=[0.5, 1.0, 2.0, 4.0])
    a = ap.parse_args()
    term_table(a.angle)
    length_table(a.angle, a.lays)
