"""Contact throughput: search, kernel and exact tangent per slave point, compiled vs the numpy oracle.

Scene: two parallel beams in line contact (5 Gauss points per slave element,
all active, friction on), ``n`` slave points from 1e2 to 1e5.  Per size, in one run:

- search (broad phase, pair rules, compiled projections: ``ContactSystem.pairs``) per Newton iteration;
- kernel + tangent: the compiled kernel (``contact.kernel_jit``, forward-mode exact tangent)
  and the numpy oracle (``contact.reference``, 24 complex-step kernel evaluations; up to 1e4 points);
- search + kernel + tangent (the issue's measure: target 2e5 points/s at 1e4 points);
- a whole ``ContactSystem.evaluate`` (search + kernel + tangent, the local blocks), compiled kernel.

Plus the JIT start-up: the first call in a fresh process with an empty numba cache
(compiles) and in a second process (loads the cache; numba's cache hit/miss counts printed).

``python benchmarks/contact_throughput.py [max_points]``
"""
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import single_thread  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402
from beamsolver.contact import kernel_jit, reference# noqa: E402
from beamsolver.contact.system import use_numpy_kernel  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"


def line_model(package, n_el, gauss_points=5, mu=0.3):
    """The scene's model built with the beamsolver package ``package`` (a reference copy may be
    passed): two nearly parallel beams of ``n_el`` elements each in line contact, both clamped."""
    sec = package.Section.circular(radius=0.005, E=1e9)
    m = package.Model()
    L = 0.05 * n_el
    master = m.add_beam(package.geometry.straight((0, 0, 0), (L, 0, 0), n_el), sec)
    slave = m.add_beam(package.geometry.straight((0.01 * L, 0.001, 0.0099), (0.99 * L, -0.001, 0.0099), n_el), sec)
    m.clamp(master.first)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, gauss_points=gauss_points)
    return m


def scene(n_points, gauss_points=5, mu=0.3):
    """The contact system of ``line_model`` with ``n_points`` slave points and its reference poses,
    friction history committed for every point."""
    m = line_model(bs, max(1, n_points // gauss_points), gauss_points, mu)
    contact = Problem.from_model(m, check_rigid_modes=False).contact
    H = contact.sys.poses0.copy()
    contact.commit(H)          # friction history for every point
    return contact, H


def _best(fn, repeat):
    """Least CPU time of the process over ``repeat`` calls (the machine is shared: wall time
    counts other jobs' time slices; everything measured here runs on one thread)."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def _projection_time(c, H, repeat):
    """Least CPU time of the search's projection part (``ContactSystem.timings['projection']``: the
    Gauss points' sections, sphere filter and projections, ``projection.gauss_projections``, one
    compiled pass) over ``repeat`` searches."""
    best = np.inf
    for _ in range(repeat):
        c.timings = dict.fromkeys(c.timings, 0.0)
        c.pairs(H)
        best = min(best, c.timings["projection"])
    return best


def measure(n_points, oracle_max=10_000):
    c, H = scene(n_points)
    repeat = 3 if n_points <= 10_000 else 1
    t_search = _best(lambda: c.pairs(H), repeat)
    t_proj = _projection_time(c, H, repeat)
    X, p = c.kernel_inputs(H)
    kernel_jit.kernel_and_tangent(X[:2], {k: (v[:2] if np.ndim(v) else v) for k, v in p.items()})   # compiled
    K = np.empty((len(X), 24, 24))      # the tangent buffer a caller keeps (ContactSystem does)
    t_jit = _best(lambda: kernel_jit.kernel_and_tangent(X, p, friction=True, K=K), repeat)
    t_np = _best(lambda: reference.kernel_and_tangent(X, p, friction=True), 1) if n_points <= oracle_max else np.nan
    use_numpy_kernel(False)
    # a new step before each evaluation: the contact system keeps its last evaluation for the same poses
    t_eval = _best(lambda: (c.begin_step(H, 0.0), c.evaluate(H, tangent=True)), repeat)
    n = len(X)
    return dict(points=n, search_s=t_search, projection_s=t_proj, kernel_jit_s=t_jit, kernel_numpy_s=t_np, evaluate_s=t_eval,
                search_pts_per_s=n / t_search, kernel_jit_pts_per_s=n / t_jit, kernel_numpy_pts_per_s=n / t_np,
                search_kernel_pts_per_s=n / (t_search + t_jit), evaluate_pts_per_s=n / t_eval)


STARTUP = """
import time
t0 = time.perf_counter()
import numpy as np
from beamsolver.contact import kernel_jit
t1 = time.perf_counter()
X = np.tile(np.eye(4), (1, 4, 1, 1)); X[0, 2:, 2, 3] = 0.15; X[0, 1, 0, 3] = X[0, 3, 0, 3] = 1.0
p = dict(kind=np.array([0]), xi1=np.array([0.5]), xi2=np.array([0.5]), R1=np.array([0.1]), R2=np.array([0.1]),
         weight=np.array([1.0]), penalty=np.array([1.0]), multiplier=np.array([0.0]), mu=np.array([0.3]),
         penalty_t=np.array([np.nan]), elastic_slip=np.array([0.005]), has_history=np.array([True]))
kernel_jit.kernel_and_tangent(X, p)
t2 = time.perf_counter()
s = kernel_jit.evaluate.stats
print(t1 - t0, t2 - t1, sum(s.cache_hits.values()), sum(s.cache_misses.values()))
"""


def startup():
    """First call in a process with an empty numba cache, then in a second process sharing that cache."""
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for run in ("first process (empty cache: compiles)", "second process (cached)"):
            out = subprocess.run([sys.executable, "-c", STARTUP], env=env, capture_output=True, text=True,
                                 check=True).stdout.split()
            rows.append((run, float(out[0]), float(out[1]), int(out[2]), int(out[3])))
    return rows


def main(sizes=(100, 1_000, 10_000, 100_000), out=OUT):
    rows = [measure(n) for n in sizes]
    keys = list(rows[0])
    md = ["| slave points | search / iteration (s) | of which projection (s) | kernel + tangent, compiled (s) | numpy oracle (s) | "
          "speed-up | search pts/s | kernel+tangent pts/s (compiled) | (numpy) | search + kernel + tangent pts/s | "
          "evaluate pts/s | rest of evaluate (us/point) |",
          "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        md.append(f"| {r['points']} | {r['search_s']:.4f} | {r['projection_s']:.4f} | {r['kernel_jit_s']:.4f} | {r['kernel_numpy_s']:.4f} | "
                  f"{r['kernel_numpy_s'] / r['kernel_jit_s']:.0f}x | {r['search_pts_per_s']:.3g} | "
                  f"{r['kernel_jit_pts_per_s']:.3g} | {r['kernel_numpy_pts_per_s']:.3g} | "
                  f"{r['search_kernel_pts_per_s']:.3g} | {r['evaluate_pts_per_s']:.3g} | "
                  f"{1e6 * (r['evaluate_s'] - r['search_s'] - r['kernel_jit_s']) / r['points']:.1f} |")
    md.append("")
    at = [r for r in rows if r["points"] >= 10_000][:1]
    verdict = (f" {'Met' if at[0]['search_kernel_pts_per_s'] >= 2e5 else 'Not met'}: "
               f"{at[0]['search_kernel_pts_per_s']:.3g} points/s at {at[0]['points']} points.") if at else ""
    md.append("Target (issue 14): 2e5 slave points/s for search + kernel + tangent at 1e4 points." + verdict)
    st = startup()
    md += ["", "| JIT start-up | import (s) | first call (s) | numba cache hits | cache misses |",
           "|---|---:|---:|---:|---:|"]
    md += [f"| {r[0]} | {r[1]:.2f} | {r[2]:.2f} | {r[3]} | {r[4]} |" for r in st]
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "contact_throughput.md").write_text("\n".join(md) + "\n")
        with open(out / "contact_throughput.csv", "w") as f:
            f.write(",".join(keys) + "\n")
            for r in rows:
                f.write(",".join(f"{r[k]:.6g}" for k in keys) + "\n")
    return rows, "\n".join(md)


if __name__ == "__main__":
    top = int(float(sys.argv[1])) if len(sys.argv) > 1 else 100_000
    sizes = [n for n in (100, 1_000, 10_000, 100_000) if n <= top]
    load0 = os.getloadavg()[0]
    rows, md = main(sizes)
    load = (f"machine load (1-minute load average) {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end, "
            f"on {os.cpu_count()} cores")
    md += "\n\n" + load.capitalize() + "."
    print(md)
    if top >= 10_000:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from _report import machine, write_section
        write_section("contact_throughput", f"""## Contact throughput

`python benchmarks/contact_throughput.py` ({machine()})

Two parallel beams in line contact, 5 Gauss points per slave element, all points active, friction
on.  Search = broad phase (bounding spheres, scipy cKDTree) + pair rules + SE(3) projections
(compiled, `contact/projection.py`; `ContactSystem.pairs`; its projection part: the Gauss points'
sections, sphere filter and projections in one compiled pass); kernel + tangent compiled = `contact.kernel_jit.kernel_and_tangent`
(numba, forward-mode exact tangent: gradients with respect to the 24 node increments carried
through the projection, the frames, the laws and the node Jacobians; an element's twist and
operators computed once for consecutive points on it; the tangent written to a
buffer kept between calls, as `ContactSystem` does); numpy oracle =
`contact.reference.kernel_and_tangent` (24 complex-step kernel evaluations per point, measured up
to 1e4 points); evaluate = `ContactSystem.evaluate` (search + compiled kernel + tangent, the
local blocks handed to the assembler; after `begin_step`: the contact system keeps its last
evaluation for the same poses); the rest of evaluate is the refusals, the active set, the
parameter look-up and the blocks.  Times are CPU
times of the process (least of 3; the machine is shared with other jobs).  The start-up rows run
a one-point kernel call in fresh processes sharing one numba cache directory.

{md}
""")
