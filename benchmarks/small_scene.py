"""Small scenes at the compute floor (issue 30 item 3): the main job's warm solve, the twisted pair's
CPU per Newton iteration at 16 -> 128 el/wire against its compiled kernels + sparse LU, and start-up.

``python benchmarks/small_scene.py [--ref DIR] [--rounds 3] [--sizes 16,32,64,128] [--no-write]``

Each tree (this one, and ``DIR`` if given: another checkout with warm numba caches) runs in its own
processes, ``--rounds`` of them alternating between the trees; every number is the least over the
rounds (the machine is shared: ratios within one run, not across runs).  In a process:

- **start-up**: CPU of ``import beamsolver``; the first solve of the main job against the later ones
  (what loading the numba caches and first calls cost);
- **main job warm**: ``bs.solve`` of ``examples/twisted_pair.py``'s model (2 x 16 elements, 16 steps),
  least CPU of 3 solves after the first;
- per el/wire: the same scene (``twisted_pair.build(n_elements=n)``) solved twice warm: CPU per
  Newton iteration (all), and its **compute floor**: the compiled element and contact kernels
  (``element_jit.evaluate``, ``kernel_jit.evaluate``; exact stick's mortar kernel ``kernel_jit.mortar_terms``,
  ``mortar_forces``, with their thin wrappers) + the linear solver's factorisations and solves,
  timed by wrapping them.  The default solver (PARDISO from 1500 unknowns: 128 el/wire; loaded before
  the first such size is timed, after the smaller ones: a process that has loaded MKL runs the small
  scenes ~0.03 s slower).

Single thread, CPU time (``time.process_time``); Markdown on stdout and in the section ``small_scene``
of ``docs/benchmarks.md``.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
clock = time.process_time


def child(root, sizes):
    """One process's measurements (JSON on stdout), the package and examples of ``root``."""
    single_thread()
    t0 = clock()
    import beamsolver as bs
    t_import = clock() - t0
    sys.path.insert(0, str(Path(root) / "examples"))
    import twisted_pair as tp
    from beamsolver.contact import kernel_jit
    from beamsolver.elements import element_jit
    from beamsolver.nonlinear import linsolve

    floor = [0.0]

    def timed(owner, name):
        f = getattr(owner, name)

        def g(*a, **k):
            t = clock()
            try:
                return f(*a, **k)
            finally:
                floor[0] += clock() - t
        setattr(owner, name, g)

    solves = []
    for _ in range(4):
        model = tp.build()[0]
        t = clock()
        sol = bs.solve(model, steps=16, verbose=False)
        solves.append(clock() - t)
    out = dict(import_s=t_import, first_solve_s=solves[0], warm_s=min(solves[1:]),
               its=sum(s["iterations"] for s in sol.stats), sizes={})
    timed(element_jit, "evaluate")
    timed(kernel_jit, "evaluate")
    for name in ("mortar_terms", "mortar_forces"):      # exact stick's kernel (the default since session 6)
        if hasattr(kernel_jit, name):
            timed(kernel_jit, name)
    factorize = linsolve.Solver.factorize

    def factorized(solver, K, *a, **k):
        t = clock()
        lu = factorize(solver, K, *a, **k)
        floor[0] += clock() - t
        solve = lu.solve

        def timed_solve(*a, **k):
            t1 = clock()
            try:
                return solve(*a, **k)
            finally:
                floor[0] += clock() - t1
        lu.solve = timed_solve
        return lu
    linsolve.Solver.factorize = factorized
    loaded = False
    for n in sizes:
        if 12 * n >= linsolve.AUTO_MIN_UNKNOWNS and "pardiso" in linsolve.available() and not loaded:
            # the default solver's choice at this size: loaded once before timing (~0.6 s per process)
            bs.solve(tp.build(n_elements=16, turns=0.25)[0], steps=2, linear_solver="pardiso", verbose=False)
            loaded = True
        best = None
        for _ in range(2):
            model = tp.build(n_elements=n)[0]
            floor[0] = 0.0
            t = clock()
            sol = bs.solve(model, steps=16, verbose=False)
            cpu, its = clock() - t, sum(s["iterations"] for s in sol.stats)
            row = (1e3 * cpu / its, 1e3 * floor[0] / its, its)
            best = row if best is None or row[0] < best[0] else best
        out["sizes"][str(n)] = best
    print(json.dumps(out))


def run(root, sizes):
    env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
    res = subprocess.run([sys.executable, __file__, "--child", str(root), "--sizes", ",".join(map(str, sizes))],
                         env=env, capture_output=True, text=True, cwd=str(root))
    if res.returncode:
        raise RuntimeError(f"{root}: {res.stderr[-2000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def merge(a, b):
    """The least of each number of two runs' results (per size: the row of the least CPU per iteration)."""
    if a is None:
        return b
    out = {k: min(a[k], b[k]) for k in ("import_s", "first_solve_s", "warm_s")}
    out["its"] = b["its"]
    out["sizes"] = {n: min(a["sizes"][n], b["sizes"][n]) for n in b["sizes"]}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", help="another checkout (warm numba caches) measured alternately")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", default="16,32,64,128")
    ap.add_argument("--no-write", action="store_true", help="do not write docs/benchmarks.md")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",") if s]
    if a.child:
        return child(a.child, sizes)
    trees = [("this tree", ROOT)] + ([(a.ref, Path(a.ref))] if a.ref else [])
    best = {name: None for name, _ in trees}
    for r in range(a.rounds):
        for name, root in trees:
            best[name] = merge(best[name], run(root, sizes))
            print(f"round {r}: {name}: {best[name]}", file=sys.stderr, flush=True)
    base = best[trees[-1][0]]
    rows = []
    for name, _ in trees:
        b = best[name]
        rows.append((name, "main job solve, warm [s]", b["warm_s"], b["warm_s"] / base["warm_s"], ""))
        rows.append((name, "  its first solve in a process [s]", b["first_solve_s"],
                     b["first_solve_s"] / base["first_solve_s"], ""))
        rows.append((name, "import beamsolver [s]", b["import_s"], b["import_s"] / base["import_s"], ""))
        for n in map(str, sizes):
            ms, fl, its = b["sizes"][n]
            rows.append((name, f"{n} el/wire: ms / iteration ({its} it.)", ms, ms / base["sizes"][n][0],
                         f"floor {fl:.3f} ms ({ms / fl:.1f}x)"))
    md = table(["tree", "measure", "value", "ratio", "compute floor (kernels + LU) / it."], rows,
               fmt={2: ".4g", 3: ".3f"})
    print(md)
    load = os.getloadavg()
    text = (f"`python benchmarks/small_scene.py{' --ref ' + a.ref if a.ref else ''} --rounds {a.rounds} --sizes "
            f"{a.sizes}` ({machine()}; load average at the end {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}): "
            "single thread, CPU time, least over the rounds (one process per tree and round, alternating). "
            "Main job: `examples/twisted_pair.py`'s solve, 16 steps; per el/wire the same scene; compute "
            "floor: the compiled element and contact kernels + the linear solver's factorisations and solves "
            "per Newton iteration, and the iteration's CPU over it.\n\n" + md)
    if not a.no_write:
        write_section("small_scene", "## Small scenes at the compute floor (issue 30 item 3)\n\n" + text)
    return best


if __name__ == "__main__":
    main()
