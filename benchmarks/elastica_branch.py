"""Post-buckling of columns from the straight state by branch switching, against the elastica.

Two columns (L = 1, EI = 1, EA = GA = 1e6), no imperfection, loaded in equal steps
with ``solve(..., branch_switching="auto")``:

* clamped-free, axial tip load up to ``P_MAX`` times ``P_cr = pi^2 EI / (4 L^2)``;
  elastica (Timoshenko & Gere, sec. 2.7): ``sqrt(P / P_cr) = 2 K(k) / pi``,
  ``k = sin(alpha / 2)``, tip deflection ``f / L = 2 k / K``, tip shortening
  ``1 - x / L = 2 - 2 E(k) / K``;
* pinned-pinned under prescribed end shortening ``delta`` up to ``DELTA_MAX``:
  ``delta / L = 2 - 2 E / K`` and ``P / P_cr = (2 K / pi)^2`` with ``P_cr = pi^2 EI / L^2``.

Prints a Markdown table of the largest deviation from the elastica per mesh and
writes ``benchmarks/results/elastica_branch.png`` (P / P_cr against the tip
deflections: computed markers, elliptic-integral lines).

    python benchmarks/elastica_branch.py [--quick]
"""
import sys
import time
import warnings
from pathlib import Path

from _report import single_thread

single_thread()   # dense eigensolvers with a BLAS pool on the shared machine: 10-100 times slower

import numpy as np  # noqa: E402
from scipy.optimize import brentq  # noqa: E402
from scipy.special import ellipe, ellipk  # noqa: E402

import beamsolver as bs  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"
P_MAX = 4.0
DELTA_MAX = 0.5


def section():
    return bs.Section(EA=1e6, GA2=1e6, GA3=1e6, GJ=1.0, EI2=1.0, EI3=1.3, radius=0.01)


def elastica(k):
    """``(P / P_cr, f / L, 1 - x / L)`` of the clamped-free elastica of modulus ``k`` (arrays)."""
    K, E = ellipk(k * k), ellipe(k * k)
    return (2.0 * K / np.pi) ** 2, 2.0 * k / K, 2.0 - 2.0 * E / K


def cantilever(n, steps):
    """Clamped-free column: ``(P / P_cr, f, shortening)`` per step and the wall time."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), section())
    m.clamp(b.first)
    m.add_load(b.last, force=(-P_MAX * np.pi**2 / 4.0, 0.0, 0.0))
    t0 = time.perf_counter()
    sol = bs.solve(m, steps=steps, verbose=False, branch_switching="auto")
    wall = time.perf_counter() - t0
    x = sol.poses[:, b.last, :3, 3]
    return P_MAX * sol.times, np.hypot(x[:, 1], x[:, 2]), 1.0 - x[:, 0], wall


def pinned(n, steps):
    """Pinned column under end shortening: ``(delta, P / P_cr)`` per step and the wall time."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), section())
    m.fix(b.first, dofs=("ux", "uy", "uz", "rx"))
    m.fix(b.last, dofs=("ux", "uy", "uz"), values={"ux": lambda t: -DELTA_MAX * t})
    t0 = time.perf_counter()
    sol = bs.solve(m, steps=steps, verbose=False, branch_switching="auto")
    wall = time.perf_counter() - t0
    return DELTA_MAX * sol.times, -sol.reactions[:, b.last, 0] / np.pi**2, wall


def cantilever_error(P, f, short):
    """Largest deviation of ``f`` and the shortening from the elastica at the loads ``P > 1``."""
    past = P > 1.0 + 1e-9
    k = np.array([brentq(lambda k: elastica(k)[0] - p, 1e-12, 1.0 - 1e-15) for p in P[past]])
    _, f_ref, s_ref = elastica(k)
    return max(np.abs(f[past] - f_ref).max(), np.abs(short[past] - s_ref).max())


def pinned_error(delta, P):
    past = delta > 1e-3
    k = np.array([brentq(lambda k: elastica(k)[2] - d, 1e-9, 1.0 - 1e-12) for d in delta[past]])
    return np.abs(P[past] - elastica(k)[0]).max()


def picture(cant, pin, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    k = np.linspace(1e-4, np.sin(0.5 * np.radians(179.0)), 400)
    P, f, s = elastica(k)
    keep = P <= P_MAX * 1.02
    fig, (a, b) = plt.subplots(1, 2, figsize=(9.5, 4.0))
    a.plot(f[keep], P[keep], "k-", lw=1, label="elastica: deflection f/L")
    a.plot(s[keep], P[keep], "k--", lw=1, label="elastica: shortening 1 - x/L")
    a.plot([0, 0], [0, 1], "k-", lw=1)
    Pc, fc, sc = cant
    a.plot(fc, Pc, "o", ms=4, label="beamsolver: f/L")
    a.plot(sc, Pc, "s", ms=4, mfc="none", label="beamsolver: 1 - x/L")
    a.set(xlabel="tip displacement / L", ylabel="P / P_cr", title="clamped-free column, tip load")
    a.legend(fontsize=8, loc="lower right")
    kd = k[s <= DELTA_MAX * 1.02]
    Pd, _, sd = elastica(kd)
    b.plot(np.r_[0.0, 0.0, sd], np.r_[0.0, 1.0, Pd], "k-", lw=1, label="elastica")
    b.plot(*pin, "o", ms=4, label="beamsolver (branch switching)")
    b.set(xlabel="end shortening delta / L", ylabel="P / P_cr", title="pinned column, prescribed shortening",
          ylim=(0, None))
    b.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def main(quick=False):
    meshes = (8, 16) if quick else (8, 16, 32)
    steps = 12 if quick else 24
    rows, cant, pin = [], None, None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilityWarning)
        for n in meshes:
            P, f, s, wall_c = cantilever(n, steps)
            d, Pd, wall_p = pinned(2 * n, steps)
            rows.append((n, cantilever_error(P, f, s), wall_c, pinned_error(d, Pd), wall_p))
            cant, pin = (P, f, s), (d, Pd)
    print(f"| elements (clamped-free / pinned) | clamped-free: max error f, shortening [L] | wall [s] | "
          f"pinned: max error P/P_cr | wall [s] |")
    print("|---|---:|---:|---:|---:|")
    for n, ec, wc, ep, wp in rows:
        print(f"| {n} / {2 * n} | {ec:.2e} | {wc:.2f} | {ep:.2e} | {wp:.2f} |")
    print(f"written: {picture(cant, pin, RESULTS / 'elastica_branch.png')}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
