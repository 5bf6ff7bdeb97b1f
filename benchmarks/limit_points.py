"""Limit points traced by arc length: limit loads against closed forms and published values.

Scenes from ``examples/limit_points.py``: the von Mises truss (closed form), DaDeppo &
Schmidt's clamped-hinged 215-degree arch (published ``P_cr = 8.97 EI / R^2``) on three meshes,
Lee's frame (a snap-back; no published value checked here), the truss under today's load
control for comparison, and the shallow sinusoidal arch against its shallow-arch closed form
(upper and lower limit, and the largest distance of the traced points from the closed-form
curve) under mesh refinement and at two rises.  The limit load is the vertex of the parabola
through the first local maximum of the path and its neighbours (``limit_points.peak``); for the
shallow arch, whose closed form is a cubic in the crown height, the extremum of a cubic fitted to
five points (``limit_points.limits``).  Williams' toggle frame (Williams 1964) is not done: its
published load-deflection data was not at hand to check against.

    python benchmarks/limit_points.py [--quick] [--docs]

Prints a Markdown table (limit computed vs reference, error, steps, Newton iterations, wall time),
also written to the ``limit_points`` section of ``docs/benchmarks.md`` (full run only);
writes load-deflection pictures (computed vs reference) to ``benchmarks/results/limit_*.png``
and, with ``--docs``, the first three side by side to ``docs/limit_points.png`` and the shallow
arch (computed points on the closed-form curve) to ``docs/shallow_arch.png``.
"""
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "examples"))

import beamsolver as bs  # noqa: E402
import limit_points as lp  # noqa: E402

OUT = HERE / "results"


def traced(model, **options):
    """``(solution, wall time)`` of an arc-length solve; a stop on ``max_steps`` is expected."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        sol = bs.solve(model, path="arc-length", verbose=False, **options)
    return sol, time.perf_counter() - t0


def row(scene, n, limit, reference, sol, wall, note=""):
    err = "" if reference is None else f"{100.0 * (limit / reference - 1.0):+.3f}"
    return dict(scene=scene, elements=n, limit=f"{limit:.5g}", reference="" if reference is None else
                f"{reference:.5g}", error_pct=err, steps=sol.n_steps, iterations=int(sol.iterations.sum()),
                wall_s=f"{wall:.2f}", note=note)


def truss_rows(curves):
    P_lim, y_lim = lp.truss_limit()
    m, apex = lp.truss(P_lim)
    sol, wall = traced(m, steps=10, t_end=1.5)
    y = lp.heights(sol, apex)
    curves["truss"] = (lp.RISE - y, sol.times * P_lim)
    rows = [row("von Mises truss", 2, lp.peak(sol.times, y) * P_lim, P_lim, sol, wall,
                f"to t_end = 1.5, lowest t {sol.times.min():.3f}")]
    m, _ = lp.truss(P_lim)
    t0 = time.perf_counter()
    try:
        bs.solve(m, steps=10, t_end=1.5, verbose=False)
        reached = 1.5
    except bs.ConvergenceError as e:
        reached = e.solution.times[-1]
    rows.append(dict(scene="von Mises truss, path='load'", elements=2, limit=f"{reached * P_lim:.5g}",
                     reference=f"{P_lim:.5g}", error_pct="", steps="", iterations="",
                     wall_s=f"{time.perf_counter() - t0:.2f}", note="stops at the limit (ConvergenceError)"))
    return rows


def arch_rows(curves, meshes):
    """The arch on two-node elements (``meshes``: element counts), then on ``meshes[1] / 2``
    three-node elements (the same nodes)."""
    rows = []
    for n, element in [(n, "se3-2") for n in meshes] + [(meshes[1], "se3-3")]:
        m, crown = lp.deep_arch(n, element)
        sol, wall = traced(m, steps=40, arc_length=dict(max_steps=230))
        v = lp.heights(sol, crown)
        if element == "se3-2":
            curves[f"arch {n}"] = (v[0] - v, 1000.0 * sol.times)
        count = n if element == "se3-2" else f"{n // 2} (se3-3)"
        rows.append(row("DaDeppo-Schmidt arch", count, 1000.0 * lp.peak(sol.times, v), lp.P_CR_DADEPPO, sol, wall,
                        "P [EI = 1e6, R = 100]"))
    return rows


def lee_rows(curves, meshes):
    rows = []
    scale = lp.LEE_L**2 / (lp.LEE_E * lp.LEE_I)
    for n in meshes:
        m, node = lp.lee_frame(n)
        sol, wall = traced(m, steps=20, t_end=0.3)
        v = lp.heights(sol, node)
        curves[f"lee {n}"] = (v[0] - v, 20.0 * scale * sol.times)
        rows.append(row("Lee's frame", 2 * n, 20.0 * scale * lp.peak(sol.times, v[0] - v), None, sol, wall,
                        "P L^2 / EI; snap-back traced to t_end (P L^2 / EI = 60)"))
    return rows


def shallow_rows(curves, meshes, rises):
    """The shallow arch (``e / r = 3.5``) for each rise ``e / L`` on each mesh; the load in units of
    the closed-form upper limit."""
    rows = []
    for rise in rises:
        for n in meshes:
            m, mid, r = lp.shallow_arch(n, rise)
            q_max, _, q_min = lp.shallow_arch_limits(rise, r)
            sol, wall = traced(m, steps=10, t_end=1.5)
            a = lp.heights(sol, mid)
            curves[f"shallow {n} {rise}"] = (a / rise, sol.times, r / rise, q_min / q_max)
            upper, lower = lp.limits(sol.times, a)
            off = np.abs(sol.times - lp.shallow_arch_load(a, rise, r) / q_max).max()
            rows.append(row(f"shallow arch, e/L = {rise}", n, upper * q_max, q_max, sol, wall,
                            f"lower limit {100 * (lower * q_max / q_min - 1):+.3f} %, "
                            f"largest distance from q(a) {off:.1e} q_max"))
    return rows


def _shallow_panel(ax, curves):
    shown = [k for k in curves if k.startswith("shallow")]
    if not shown:
        return
    a, _, r, _ = curves[shown[0]]
    s = np.linspace(a.min(), a.max(), 400)
    ax.plot(s, lp.shallow_arch_load(s, 1.0, r) / lp.shallow_arch_limits(1.0, r)[0], "k-", lw=1,
            label="closed form (shallow arch)")
    last = [k for k in shown if k.split()[2] == shown[-1].split()[2]]      # the smallest rise
    for name, marker in zip((last[0], last[-1]), "os"):
        a, t, _, _ = curves[name]
        _, n, rise = name.split()
        ax.plot(a, t, marker, ms=3, mfc="none", label=f"{n} elements, e/L = {rise}")
    ax.set(xlabel="crown height a / e", ylabel="q / q_max", title="shallow sinusoidal arch (e / r = 3.5)")
    ax.invert_xaxis()


def _truss_panel(ax, curves):
    d, P = curves["truss"]
    ds = np.linspace(0.0, d.max(), 400)
    ax.plot(ds, lp.truss_load(lp.RISE - ds), "k-", lw=1, label="closed form")
    ax.plot(d, P, "o", ms=3, label="arc length")
    ax.set(xlabel="apex deflection", ylabel="apex load per bar", title="von Mises truss")


def _arch_panel(ax, curves):
    for name in [k for k in curves if k.startswith("arch")]:
        d, P = curves[name]
        ax.plot(d, P, ".-", ms=2, lw=0.8, label=f"{name.split()[1]} elements")
    ax.axhline(lp.P_CR_DADEPPO, color="k", lw=0.8, ls="--", label="DaDeppo & Schmidt")
    ax.set(xlabel="crown deflection", ylabel="crown load P", title="clamped-hinged 215-degree arch")


def _lee_panel(ax, curves):
    for name in [k for k in curves if k.startswith("lee")]:
        d, P = curves[name]
        ax.plot(d, P, ".-", ms=2, lw=0.8, label=f"{2 * int(name.split()[1])} elements")
    ax.set(xlabel="deflection under the load", ylabel="P L^2 / EI", title="Lee's frame (snap-back)")


PANELS = dict(truss=_truss_panel, arch=_arch_panel, lee=_lee_panel, shallow=_shallow_panel)
DOC_PANELS = ("truss", "arch", "lee")


def pictures(curves, docs=False):
    """One PNG per scene in ``benchmarks/results``; with ``docs`` also the first three side by side in
    ``docs/limit_points.png`` and the shallow arch in ``docs/shallow_arch.png``."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        print("(matplotlib missing: no pictures; pip install 'beamsolver[viz]')")
        return []
    OUT.mkdir(exist_ok=True)
    written = []
    for name, panel in PANELS.items():
        fig = Figure(figsize=(5, 3.6))
        ax = fig.subplots()
        panel(ax, curves)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        written.append(OUT / f"limit_{name}.png")
        fig.savefig(written[-1], dpi=100, bbox_inches="tight")
    if docs:
        fig = Figure(figsize=(12, 3.3))
        for ax, name in zip(fig.subplots(1, 3), DOC_PANELS):
            PANELS[name](ax, curves)
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        written.append(HERE.parent / "docs" / "limit_points.png")
        fig.savefig(written[-1], dpi=72, bbox_inches="tight")
        fig = Figure(figsize=(5.5, 3.8))
        ax = fig.subplots()
        _shallow_panel(ax, curves)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        written.append(HERE.parent / "docs" / "shallow_arch.png")
        fig.savefig(written[-1], dpi=90, bbox_inches="tight")
    return written


def main(quick=False, docs=False):
    from _report import machine, table, write_section
    curves = {}
    rows = truss_rows(curves)
    rows += arch_rows(curves, (20, 40) if quick else (20, 40, 80))
    rows += lee_rows(curves, (10,) if quick else (10, 20))
    rows += shallow_rows(curves, (32, 64) if quick else (16, 32, 64, 128), (0.005,) if quick else (0.01, 0.005))
    keys = list(rows[0])
    text = table(keys, [[r[k] for k in keys] for r in rows])
    print(text)
    for p in pictures(curves, docs):
        print(f"written: {p}")
    if not quick:
        write_section("limit_points", f"""## Limit points by arc length (issue 15)

`python benchmarks/limit_points.py` ({machine()}). `solve(..., path="arc-length")`
on the scenes of `examples/limit_points.py`; the limit is the vertex of the parabola through
the first local maximum of the path and its neighbours; error against the closed form (truss)
or DaDeppo & Schmidt's `8.97 EI / R^2` (arch; second order in the mesh of two-node elements,
and on three-node elements over the same nodes). Lee's frame: no
published value is checked (its limit `P L^2 / EI` converges towards about 18.5).
Shallow sinusoidal arch (`e / r = 3.5`, load in units of the closed-form upper limit): limits from
a cubic fit through five points, against the shallow-arch closed form (docs/theory.md); the
difference is the mesh error (second order, larger for the slenderer arch) plus the shallow-arch
theory's own, of order `(pi e / L)^2`, negative. Williams' toggle frame is not done (its published
data was not at hand).

{text}

![load-deflection paths](limit_points.png)

![shallow arch: computed points on the closed-form curve](shallow_arch.png)
""")
    return rows


if __name__ == "__main__":
    main(quick="--quick" in sys.argv, docs="--docs" in sys.argv)
