"""Mesh convergence of the two- and three-node SE(3) elements on a large-deflection cantilever.

Scene: a straight clamped cantilever of length 1 (``EA = 1e3``, ``EI = 30, 40``, ``GJ = 20``)
under a dead tip force ``(0, 60, 40)`` and moment ``(2, 0, 0)`` (tip rotation ~1 rad), four
load steps.  The reference tip position is the Richardson extrapolation of the two-node
element at 128 and 256 elements (its error falls as h^2).  Per mesh: unknowns, tip error of
each element type, and the rate fitted on the log-log data (``np.polyfit``).  Also the wall
time of one solve.

``python benchmarks/element_convergence.py``
"""
import time

import numpy as np

import beamsolver as bs

SEC = bs.Section(EA=1e3, GA2=4e2, GA3=5e2, GJ=20.0, EI2=30.0, EI3=40.0, radius=0.05)


def tip(n_elements, element):
    """Tip position, unknowns and wall time of the cantilever with ``n_elements`` elements."""
    k = bs.elements.get(element).n_nodes - 1
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1.0, 0, 0), k * n_elements), SEC, element=element)
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 60.0, 40.0), moment=(2.0, 0.0, 0.0))
    t0 = time.perf_counter()
    sol = bs.solve(m, steps=4, rtol=1e-12)
    return sol.position(b.last), 6 * (m.n_nodes - 1), time.perf_counter() - t0


def main():
    a, b = tip(128, "se3-2")[0], tip(256, "se3-2")[0]
    ref = b + (b - a) / 3.0
    rows = []
    for n in (1, 2, 4, 8, 16, 32):
        row = {"elements": n}
        for element in ("se3-2", "se3-3"):
            x, dofs, wall = tip(n, element)
            row[element] = (dofs, float(np.linalg.norm(x - ref)), wall)
        rows.append(row)
    print("Cantilever tip error |x - x_ref| (reference: Richardson of se3-2 at 128/256 elements)")
    print(f"{'elements':>9} {'dofs 2-node':>12} {'err 2-node':>11} {'dofs 3-node':>12} {'err 3-node':>11} "
          f"{'solve s 3-node':>15}")
    for r in rows:
        d2, e2, _ = r["se3-2"]
        d3, e3, w3 = r["se3-3"]
        print(f"{r['elements']:>9d} {d2:>12d} {e2:>11.3e} {d3:>12d} {e3:>11.3e} {w3:>15.3f}")
    for element in ("se3-2", "se3-3"):
        ns = np.array([r["elements"] for r in rows])
        err = np.array([r[element][1] for r in rows])
        ok = err > 1e-12                                  # below: round-off of the reference
        rate = -np.polyfit(np.log(ns[ok]), np.log(err[ok]), 1)[0]
        print(f"fitted rate {element}: {rate:.2f} (err ~ h^rate over {ns[ok].tolist()} elements)")
    return rows


if __name__ == "__main__":
    main()
