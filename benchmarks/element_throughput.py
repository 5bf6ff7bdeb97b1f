"""Element throughput: the batched SE(3) beam kernel and the assembly, in elements per second.

Scene: one clamped helix (curved and twisted elements, so every coefficient of
the kernel is non-trivial) of ``n`` elements with a dead tip load, in a
deformed, non-equilibrium state.  Per size ``n = 1e2 .. 1e5``:

- kernel: the element type ``"se3-2"`` of the element contract
  (``bs.elements.get("se3-2").evaluate(H, nodes, ref, True)``: forces + exact
  tangent by the compiled numba path, poses read through the node table), and
  the same by the numpy kernel kept as its oracle
  (``reference.internal_forces_and_tangent_numpy``), measured in the same run;
- assembly: ``System.evaluate`` (kernel + loads + residual scatter) and
  ``System.matrix`` (tangent values scattered into the CSC pattern built once);
- iteration: assembly plus the sparse factorisation and solve of one Newton
  iteration (scipy ``splu``, as ``solve`` does), to show the per-iteration cost
  growing linearly with ``n``;

plus a plain per-element Python loop of the same maths (the kernel called
with one element at a time) on a subset, measured in the same run, and the
ratio batched / loop.  Single core: the thread counts of the BLAS/OpenMP
libraries are set to 1 before numpy is imported.  Table on stdout, CSV in
``benchmarks/results/element_throughput.csv``.

``python benchmarks/element_throughput.py [max_elements]``
"""
import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
             "NUMEXPR_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import csv  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

import beamsolver as bs  # noqa: E402
from beamsolver.elements import reference  # noqa: E402
from beamsolver.assembly.system import System  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
TARGET = 2e6            # elements per second for the kernel on one core at 1e4 elements (issue 13)
LOOP_SUBSET = 300       # elements timed one at a time


def scene(n_elements, seed=0):
    """System and a deformed state of a clamped helix with ``n_elements`` elements."""
    sec = bs.Section.circular(radius=0.002, E=2e11)
    m = bs.Model()
    pitch = 0.1
    beam = m.add_beam(bs.geometry.helix(radius=0.02, pitch=pitch, length=pitch * n_elements / 20.0,
                                        n_elements=n_elements), sec)
    m.clamp(beam.first)
    m.add_load(beam.last, force=(1.0, -2.0, 3.0))
    system = System(m)
    rng = np.random.default_rng(seed)
    dz = 1e-3 * rng.standard_normal((system.n_nodes, 6))
    dz[:, :3] *= 0.01
    H = system.update(system.poses0, dz, chains=False)
    return system, H


def _best(fn, min_time=0.3, max_repeat=20):
    """Best wall time of ``fn()`` over repeats lasting at least ``min_time`` in total."""
    best, total, k = np.inf, 0.0, 0
    while (total < min_time or k < 3) and k < max_repeat:
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        best, total, k = min(best, dt), total + dt, k + 1
    return best


def measure(n):
    system, H = scene(n)
    HA, HB = H[system.enodes[:, 0]], H[system.enodes[:, 1]]
    args = (HA, HB, system.L, system.eps0, system.C)
    lf = system.load_factors(1.0)
    group = system.groups[0]                               # the element contract: type, node table, reference
    etype, nodes, ref = group.element_type, group.nodes, group.ref
    etype.evaluate(H, nodes, ref, True)                    # compile (or load the cache) before timing
    t_kernel = _best(lambda: etype.evaluate(H, nodes, ref, True), min_time=1.0, max_repeat=200)
    t_numpy = _best(lambda: reference.internal_forces_and_tangent_numpy(*args))
    t_forces = _best(lambda: etype.evaluate(H, nodes, ref, False), min_time=1.0, max_repeat=200)

    def assemble():
        r, kvals, _ = system.evaluate(H, lf, tangent=True)
        return r, system.matrix(kvals)
    t_assembly = _best(assemble)
    r, K = assemble()
    rhs = -r[system.free_dofs]

    def iteration():
        r, K = assemble()
        spla.splu(K, permc_spec="MMD_AT_PLUS_A").solve(rhs)
    t_iteration = _best(iteration)
    return dict(n_elements=n, n_dofs=system.n_free, kernel=n / t_kernel, numpy=n / t_numpy,
                compiled_over_numpy=t_numpy / t_kernel, forces_only=n / t_forces,
                assembly=n / t_assembly, iteration_ms=1e3 * t_iteration, iteration=n / t_iteration)


def loop_rate(n=LOOP_SUBSET):
    """Elements per second of the same kernel called once per element (plain Python loop)."""
    system, H = scene(n)
    group = system.groups[0]
    etype, nodes, ref = group.element_type, group.nodes, group.ref
    refs = [bs.elements.Reference(ref.L[e:e + 1], ref.eps0[e:e + 1], ref.C[e:e + 1], ref.diagonal)
            for e in range(n)]

    def loop():
        for e in range(n):
            etype.evaluate(H, nodes[e:e + 1], refs[e], True)
    return n / _best(loop, min_time=0.5, max_repeat=5)


def main(max_elements=100_000):
    sizes = [n for n in (100, 1_000, 10_000, 100_000) if n <= max_elements]
    loop = loop_rate()
    rows = []
    for n in sizes:
        row = measure(n)
        row["ratio_to_loop"] = row["kernel"] / loop
        rows.append(row)
    header = (f"{'elements':>9} {'dofs':>8} {'kernel el/s':>12} {'numpy el/s':>11} {'numba/numpy':>12} "
              f"{'forces el/s':>12} {'assembly el/s':>14} {'iteration ms':>13} {'iteration el/s':>15} "
              f"{'kernel/loop':>12}")
    lines = ["Element throughput (one core; kernel = forces + exact tangent, compiled; numpy = the same by "
             "the numpy oracle; assembly = kernel + loads + scatter into CSC; iteration = assembly + splu "
             "factor/solve)", header]
    for r in rows:
        lines.append(f"{r['n_elements']:>9d} {r['n_dofs']:>8d} {r['kernel']:>12.3g} {r['numpy']:>11.3g} "
                     f"{r['compiled_over_numpy']:>12.1f} {r['forces_only']:>12.3g} "
                     f"{r['assembly']:>14.3g} {r['iteration_ms']:>13.2f} {r['iteration']:>15.3g} "
                     f"{r['ratio_to_loop']:>12.0f}")
    lines.append(f"per-element Python loop over the same kernel ({LOOP_SUBSET} elements): {loop:.3g} el/s")
    at = [r["kernel"] for r in rows if r["n_elements"] == 10_000] or [max(r["kernel"] for r in rows)]
    lines.append(f"target {TARGET:.0e} el/s for the kernel at 1e4 elements: "
                 f"{'met' if at[0] >= TARGET else 'NOT met'} ({at[0]:.3g} el/s)")
    print("\n".join(lines))
    if max_elements >= 100_000:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from _report import machine, table, write_section
        md = table(["elements", "kernel el/s (numba)", "numpy kernel el/s", "numba / numpy", "forces only el/s",
                    "assembly el/s", "iteration ms", "batched / loop"],
                   [(r["n_elements"], r["kernel"], r["numpy"], f"{r['compiled_over_numpy']:.1f}", r["forces_only"],
                     r["assembly"], r["iteration_ms"], f"{r['ratio_to_loop']:.0f}") for r in rows])
        write_section("element_throughput", f"""## Element throughput

`python benchmarks/element_throughput.py` ({machine()}; one thread)

Kernel = internal forces + exact tangent of the SE(3) element, compiled with numba (`element_jit`, one
element per call, a batch loop); numpy = the batched numpy kernel kept as its test oracle, same run;
assembly = kernel + loads + scatter into the CSC pattern built once; iteration = assembly + sparse
factorisation and solve. The public kernel called element by element from a Python loop runs at
{loop:.3g} el/s (per-call overhead). Target (issue 13): {TARGET:.0e} el/s for the kernel on one core at
1e4 elements: {lines[-1].split(": ", 1)[1]}.

{md}
""")
    OUT.mkdir(exist_ok=True)
    with open(OUT / "element_throughput.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]) + ["loop"])
        w.writeheader()
        for r in rows:
            w.writerow({**r, "loop": loop})
    return rows, loop


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 100_000)
