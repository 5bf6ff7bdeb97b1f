"""Cost of running a parameter study on Dask (``beamsolver.sweep``): per-point overhead and speed-up.

``python benchmarks/sweep_overhead.py [--quick]``

Eight points (a clamped helical cable under eight tip loads, 8 load steps,
no contact) of two sizes: *small* (80 elements, ~0.1 s: the engine's cost
dominates) and *large* (about 5 s per point).  Each set is timed

- serially: a plain loop ``scene -> solve -> Solution.save`` in this process
  (one BLAS thread), the same work a sweep point does, timed before any
  cluster starts (the scheduler of a local cluster runs in this process);
- with ``bs.sweep`` on a local cluster (``sweep_engine.local_client``) of 1
  and of 2 single-threaded worker processes, results saved to a study folder.
  The cluster's start (and the workers' import of beamsolver) is timed apart.

Per-point overhead = (sweep on 1 worker - serial loop) / 8, and the engine's
own = (sweep on 1 worker - sum of the points' times inside the worker) / 8,
which other jobs on the machine do not bias; speed-up = sweep on 1 worker /
sweep on 2 workers.  Targets: overhead < 0.5 s per point, speed-up
>= 1.7 for ~5 s points on 2 cores (a machine shared with other jobs lowers it:
the load average is printed with the table).

Writes the ``sweep_overhead`` section of ``docs/benchmarks.md`` (not with ``--quick``).
"""
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()

import beamsolver as bs  # noqa: E402
from beamsolver.app.sweep_engine import local_client  # noqa: E402

LOADS = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]
SIZES = {"small": 80, "large": 4000}
STEPS = 8


def scene(load, n_elements):
    """A clamped helical steel cable (0.5 m, 10 turns) under an axial tip force of ``20 load`` N."""
    sec = bs.Section.circular(radius=1e-3, E=200e9)
    m = bs.Model()
    b = m.add_beam(bs.geometry.helix(radius=5e-3, pitch=0.05, length=0.5, n_elements=n_elements), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 0.0, 20.0 * load))
    return m, b


def serial(points, folder):
    """Wall time of the plain loop over ``points`` (build, solve, save) in this process."""
    t0 = time.perf_counter()
    for p in points:
        model, _ = scene(**p)
        bs.solve(model, steps=STEPS, verbose=False).save(Path(folder) / f"{len(os.listdir(folder))}.npz")
    return time.perf_counter() - t0


def swept(client, points, folder):
    """Wall time of ``bs.sweep`` over ``points`` on ``client`` and the sum of the points' own times."""
    t0 = time.perf_counter()
    rows = bs.sweep(scene, points, client=client, output=folder, solve_options={"steps": STEPS}, verbose=False)
    wall = time.perf_counter() - t0
    assert all(r["status"] == "converged" for r in rows), rows
    return wall, sum(r["wall"] for r in rows)


def started(n_workers):
    """A local client of ``n_workers`` with beamsolver imported in every worker; and the time it took."""
    t0 = time.perf_counter()
    client = local_client(n_workers)
    client.run(lambda: __import__("beamsolver.driver") and __import__("scipy.sparse.linalg"))
    return client, time.perf_counter() - t0


def main(quick=False):
    sizes = {"small": SIZES["small"]} if quick else SIZES
    sets = {name: [dict(load=x, n_elements=n) for x in LOADS] for name, n in sizes.items()}
    t_all = time.perf_counter()
    t_serial = {}
    with tempfile.TemporaryDirectory() as d:    # before any cluster: its scheduler runs in this process
        serial(sets["small"][:1], d)            # warm imports
        for name, pts in sets.items():
            (Path(d) / name).mkdir()
            t_serial[name] = serial(pts, Path(d) / name)
    clients, start, t_sweep = {}, {}, {}
    try:
        for w in (1, 2):
            clients[w], start[w] = started(w)
        with tempfile.TemporaryDirectory() as d:
            for name, pts in sets.items():
                for w, c in clients.items():
                    t_sweep[name, w] = swept(c, pts, Path(d) / f"{name}{w}")
    finally:
        for c in clients.values():
            c.close()
            c._beamsolver_cluster.close()
    rows = []
    for name, pts in sets.items():
        n, ts, (t1, in1), (t2, in2) = len(pts), t_serial[name], t_sweep[name, 1], t_sweep[name, 2]
        rows.append([name, sizes[name], ts / n, t1, t2, t1 / t2, (t1 - ts) / n, (t1 - in1) / n, in1 / n, in2 / n,
                     in2 / t2])
    load = os.getloadavg()
    text = table(["points", "elements", "serial loop, s per point", "sweep, 1 worker [s]", "sweep, 2 workers [s]",
                  "speed-up 2 vs 1", "overhead vs serial, s per point", "engine overhead, s per point",
                  "in-worker s per point, 1 worker", "in-worker s per point, 2 workers", "points in flight, 2 workers"],
                 rows, fmt={2: ".3f", 3: ".2f", 4: ".2f", 5: ".2f", 6: ".3f", 7: ".3f", 8: ".3f", 9: ".3f", 10: ".2f"})
    cores = os.cpu_count() or 1
    busy = "" if load[1] < 0.5 * cores else (
        f" This run shared the machine with other jobs (5-min load average {load[1]:.1f} on {cores} cores; "
        "in-worker times above the serial loop's): the second worker found no free core, so the speed-up "
        "measures that contention, not the engine; the engine overhead is unaffected.")
    section = f"""## Parameter sweeps on Dask: engine overhead and speed-up

`python benchmarks/sweep_overhead.py` ({machine()}; whole run {time.perf_counter() - t_all:.0f} s; load average
at the end {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} over 1 / 5 / 15 min). Eight points, a clamped helical
cable under eight tip loads, {STEPS} load steps. *Serial loop*: build, solve and save each point in one
process; *sweep*: `bs.sweep` on a local cluster of 1 or 2 single-threaded worker processes, writing the study
folder (per-point archive, point record, summary CSV after every point). Cluster start including the workers'
imports, not in the table: {start[1]:.1f} s (1 worker), {start[2]:.1f} s (2 workers).
Speed-up = sweep on 1 worker / sweep on 2 workers; overhead vs serial = (sweep on 1 worker - serial loop) / 8;
engine overhead = (sweep on 1 worker - the sum of the points' own times in the worker) / 8, both measured in the
same run, so other jobs slowing the machine cancel out (they do not in the comparison with the serial loop, timed
earlier). In-worker time per point next to the serial loop's shows how loaded the machine was during the sweeps;
points in flight = sum of the in-worker times / sweep wall time on 2 workers (2: both workers busy all along).

{text}

Targets: overhead < 0.5 s per point; speed-up >= 1.7 for points of ~5 s on this 2-core machine.{busy}"""
    print(section)
    if not quick:
        write_section("sweep_overhead", section)
    return rows


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
