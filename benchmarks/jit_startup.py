"""First run (numba compiles the kernels) versus cached runs, for a tiny solve and the main job.

Each job runs in a fresh Python process with ``NUMBA_CACHE_DIR`` pointing at an
empty temporary folder (first run: every kernel is compiled and written to the
cache), then twice more with the same folder (cached: the kernels are loaded,
nothing is compiled).  Jobs:

- ``tiny``: ``import beamsolver`` and a 2-element cantilever solved in one step
  (what compiling costs, and what loading the cache costs);
- ``main``: ``python examples/twisted_pair.py`` (the main job of the README),
  run in a temporary working folder so its output does not land here.

``python benchmarks/jit_startup.py [--skip-main]``; table on stdout and in the
section ``jit_startup`` of ``docs/benchmarks.md`` (unless ``--skip-main``).

``--timeline``: instead, the main job's first run as a user sees it (issue 29): seconds from the
start to its first line of output, to the end of step 1 (the solver's per-step log record,
shown by a ``logging`` handler the job is started with), to the end, the longest silence (no
byte on stdout or stderr; a progress bar's refresh counts), and CPU time of the job and its
child processes; empty cache with the second compiling process (``BEAMSOLVER_COMPILE_PROCESS=1``; by default only
when a core is free), without it (``=0``) and cached; ``--ref DIR`` adds the first run of the checkout
``DIR`` (e.g. ``/work/main``), interleaved.  Section ``jit_first_run`` of ``docs/benchmarks.md``.

``--warm [--ref DIR]``: the main job's solve with every kernel cached (what inlining choices cost at run time):
least CPU seconds of ``bs.solve`` over 3 solves per process, in 4 processes alternating between this tree and
``DIR``; section ``jit_warm_solve``.

``--functions``: the compiled functions of the main job's first run (one process, empty cache) by
the CPU time numba spends compiling each (numba's ``numba:compile`` events: inclusive of the
functions it compiles on the way, and exclusive); then the same run with two processes, each
process's top-level compilations with their wall-clock times (what the job and its fork compile
when); section ``jit_compile_functions``.
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

TINY = """
import beamsolver as bs
m = bs.Model()
b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), bs.Section.circular(radius=0.01, E=1e9))
m.clamp(b.first)
m.add_load(b.last, force=(0, 0, -1.0))
bs.solve(m, steps=1, verbose=False)
"""


def _run(args, cache, cwd):
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    out = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"{args} failed:\n{out.stderr[-2000:]}")
    return wall


def measure(name, args):
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
        first = _run(args, cache, cwd)
        cached = [_run(args, cache, cwd) for _ in range(2)]
    return dict(job=name, first=first, cached=min(cached), compile=first - min(cached))


MAIN_LOGGED = """
import logging, runpy, sys
logging.basicConfig(level=logging.INFO, format="%(message)s")
sys.argv = [sys.argv[1]]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def timeline(root, cache, cwd, env=None):
    """The main job of checkout ``root`` in a fresh process: seconds to the first output, to the end of
    step 1, to the end; longest silence [s]; CPU [s] of the job and its children; Newton iterations."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(root), "PYTHONUNBUFFERED": "1", **(env or {})}
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.Popen([sys.executable, "-c", MAIN_LOGGED, str(Path(root) / "examples" / "twisted_pair.py")],
                         cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    first = step1 = None
    last, silence, text = 0.0, 0.0, b""
    while chunk := p.stdout.read1(1 << 16):
        t = time.perf_counter() - t0
        first = t if first is None else first
        silence, last = max(silence, t - last), t
        text += chunk
        if step1 is None and b"step 1 " in text:
            step1 = t
    p.wait()
    end = time.perf_counter() - t0
    silence = max(silence, end - last)
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime)
    if p.returncode != 0:
        raise RuntimeError(f"the main job failed:\n{text.decode(errors='replace')[-2000:]}")
    out = text.decode(errors="replace")
    iterations = out.split("Newton iterations ")[1].split(",")[0] if "Newton iterations " in out else "?"
    return dict(first=first, step1=step1, end=end, silence=silence, cpu=cpu, iterations=iterations)


COMPILE_PROFILE = """
import atexit, json, os, runpy, sys, time
from numba.core import event
rows, stack, start = [], [], [time.time()]
class Timer(event.Listener):
    def on_start(self, ev):
        stack.append([time.process_time(), 0.0, time.time()])
    def on_end(self, ev):
        t0, inner, w0 = stack.pop()
        dt = time.process_time() - t0
        if stack:
            stack[-1][1] += dt
        f = ev.data["dispatcher"].py_func
        rows.append((f.__module__ + "." + f.__qualname__.split("__")[0], dt, dt - inner, len(stack), w0, time.time()))
event.register("numba:compile", Timer())
path = sys.argv[2]
def dump(suffix=""):
    with open(path + suffix, "w") as fh:
        fh.write(json.dumps(dict(rows=rows, cpu=time.process_time(), start=start[0], end=time.time())))
atexit.register(dump)
os.register_at_fork(after_in_child=lambda: (rows.clear(), start.__setitem__(0, time.time())))
_exit = os._exit
def traced_exit(code):                  # the forked compiling process leaves by os._exit
    try:
        dump(".fork")
    finally:
        _exit(code)
os._exit = traced_exit
sys.argv = [sys.argv[1]]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def compile_trace(processes, root=ROOT):
    """The main job's first run with ``processes`` (1 or 2) compiling processes, from an empty cache: per
    process, ``dict(rows=[(function, inclusive CPU, exclusive CPU, depth, wall start, wall end)], cpu, start,
    end)``, wall times in seconds from the job's start."""
    import json
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
        out = Path(cwd) / "profile.json"
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(root),
               "BEAMSOLVER_COMPILE_PROCESS": str(processes - 1)}
        t0 = time.time()
        subprocess.run([sys.executable, "-c", COMPILE_PROFILE, str(Path(root) / "examples" / "twisted_pair.py"),
                        str(out)], cwd=cwd, env=env, check=True, capture_output=True)
        procs = [json.loads(f.read_text()) for f in (out, Path(str(out) + ".fork")) if f.exists()]
    for d in procs:
        d["rows"] = [r[:4] + [r[4] - t0, r[5] - t0] for r in d["rows"]]
        d["start"], d["end"] = d["start"] - t0, d["end"] - t0
    return procs


def trace_table(procs):
    """Markdown table of the top-level compilations of each process (what it compiles when), and a summary line."""
    from _report import table
    rows = []
    for k, d in enumerate(procs):
        who = "job" if k == 0 else "fork"
        for name, inc, exc, depth, w0, w1 in d["rows"]:
            if depth == 0:
                rows.append((who, name.replace("beamsolver.", ""), f"{w0:.1f}", f"{w1:.1f}", f"{inc:.2f}"))
    head = "; ".join(f"{'job' if k == 0 else 'fork'}: {d['start']:.1f}-{d['end']:.1f} s, CPU {d['cpu']:.1f} s of which "
                     f"compiling {sum(r[2] for r in d['rows']):.1f} s" for k, d in enumerate(procs))
    return head, table(["process", "compiled function (top level)", "from [s]", "to [s]", "CPU, inclusive [s]"], rows)


def compile_profile(top=15):
    """Table of the functions compiled by the main job's first run, by exclusive CPU seconds (section
    ``jit_compile_functions`` of ``docs/benchmarks.md``)."""
    from _report import table
    data = compile_trace(1)[0]
    by = {}
    for name, inc, exc, depth, _, _ in data["rows"]:
        b = by.setdefault(name, [0, 0.0, 0.0])
        b[0] += 1
        b[1] = max(b[1], inc) if depth else b[1] + inc
        b[2] += exc
    total = sum(r[2] for r in data["rows"])
    rows = sorted(by.items(), key=lambda kv: -kv[1][2])[:top]
    md = table(["function", "compilations", "exclusive CPU [s]", "share"],
               [(n.replace("beamsolver.", ""), c, f"{e:.2f}", f"{e / total:.0%}") for n, (c, _, e) in rows])
    head = f"compilation CPU {total:.1f} s of the process's {data['cpu']:.1f} s; the {top} costliest functions:"
    print(head)
    print(md)
    two_head, two = trace_table(compile_trace(2))
    print(two_head)
    print(two)
    from _report import machine, write_section
    write_section("jit_compile_functions", f"""## What the first run compiles (issue 29)

`python benchmarks/jit_startup.py --functions` ({machine()}): the main job in one process
(`BEAMSOLVER_COMPILE_PROCESS=0`) from an empty numba cache; CPU seconds numba spends compiling each function,
exclusive of the functions it compiles on the way (a function compiled for two argument types, e.g. a literal
integer argument, counts twice).

{head}

{md}

The same job with two compiling processes (`BEAMSOLVER_COMPILE_PROCESS=1`: the job and the fork compiling the
contact kernel, `nonlinear/jit_warmup.py`): each process's top-level compilations (a function with the ones it
compiles on the way), wall seconds from the job's start and CPU seconds; the job waits for the fork before it
loads the kernel, then solves.  {two_head}.

{two}
""")
    return by


def _auto_two():
    sys.path.insert(0, str(ROOT))
    from beamsolver.nonlinear.jit_warmup import _two_processes
    return _two_processes()


def first_run(ref=None, skip=()):
    """Rows of the ``--timeline`` table (see the module docstring)."""
    variants = [("this tree, first run (default)", ROOT, {}),
                ("this tree, first run (2 processes)", ROOT, {"BEAMSOLVER_COMPILE_PROCESS": "1"}),
                ("this tree, first run (1 process)", ROOT, {"BEAMSOLVER_COMPILE_PROCESS": "0"})]
    if ref:
        variants.append((f"{ref}, first run", Path(ref), {"PYTHONDONTWRITEBYTECODE": "1"}))   # writes nothing there
    rows = []
    for name, root, env in variants:
        if any(k in name for k in skip):
            continue
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
            if not env:
                name += f" (load {os.getloadavg()[0]:.1f}: {'2 processes' if _auto_two() else '1 process'})"
            rows.append((name, timeline(root, cache, cwd, env)))
            if root == ROOT and not env:
                rows.append(("this tree, cached run", timeline(root, cache, cwd)))
    for name, r in rows:
        print(f"{name}: {r}", file=sys.stderr, flush=True)
    return rows


WARM = """
import sys, time
sys.path.insert(0, sys.argv[1] + "/examples")
import beamsolver as bs
import twisted_pair as tp
best = []
for _ in range(3):
    model = tp.build()[0]
    t0 = time.process_time()
    sol = bs.solve(model, steps=16, verbose=False)
    best.append(time.process_time() - t0)
print(min(best), sum(s["iterations"] for s in sol.stats))
"""


def warm_solve(ref=None, rounds=4):
    """Rows ``(tree, least solve CPU [s], Newton iterations)`` of the ``--warm`` table."""
    trees = [("this tree", ROOT)] + ([(str(ref), Path(ref))] if ref else [])
    caches = {name: tempfile.mkdtemp(prefix="warm_") for name, _ in trees}
    best, its = {}, {}
    for r in range(rounds + 1):                       # round 0 fills the caches (compiles)
        for name, root in trees:
            env = {**os.environ, "NUMBA_CACHE_DIR": caches[name], "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
            out = subprocess.run([sys.executable, "-c", WARM, str(root)], env=env, capture_output=True, text=True,
                                 check=True).stdout.split()
            if r:
                best[name] = min(best.get(name, float("inf")), float(out[0]))
                its[name] = out[1]
    return [(name, best[name], its[name]) for name, _ in trees]


def main_warm(ref):
    from _report import machine, table, write_section
    rows = warm_solve(ref)
    base = rows[-1][1]
    md = table(["tree", "main job's solve, least CPU [s]", "ratio", "Newton it."],
               [(n, f"{t:.3f}", f"{t / base:.3f}", it) for n, t, it in rows])
    print(md)
    load = os.getloadavg()
    write_section("jit_warm_solve", f"""## The main job's solve with the kernels cached (issue 29)

`python benchmarks/jit_startup.py --warm{' --ref ' + ref if ref else ''}` ({machine()}; load average at the end
{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}): `bs.solve` of `examples/twisted_pair.py`'s model, least CPU
time of 3 solves per process, 4 processes per tree alternating, every kernel loaded from a warm cache.

{md}
""")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--skip-main", action="store_true", help="only the tiny job (no docs update)")
    ap.add_argument("--timeline", action="store_true", help="the main job's first run as a user sees it")
    ap.add_argument("--ref", help="with --timeline / --warm: also this checkout")
    ap.add_argument("--skip", nargs="*", default=(), help="with --timeline: leave out the variants naming these")
    ap.add_argument("--functions", action="store_true", help="compile CPU time per function of the main job")
    ap.add_argument("--warm", action="store_true", help="the main job's solve, kernels cached, against --ref")
    args = ap.parse_args(argv)
    if args.warm:
        return main_warm(args.ref)
    if args.functions:
        return compile_profile()
    if args.timeline:
        return main_timeline(args.ref, args.skip)
    jobs = [("tiny: import + 2-element solve", [sys.executable, "-c", TINY])]
    if not args.skip_main:
        jobs.append(("main: python examples/twisted_pair.py", [sys.executable, str(ROOT / "examples" / "twisted_pair.py")]))
    rows = [measure(*j) for j in jobs]
    from _report import machine, table, write_section
    md = table(["job", "first run [s] (compiles)", "cached run [s]", "first - cached [s]"],
               [(r["job"], f"{r['first']:.2f}", f"{r['cached']:.2f}", f"{r['compile']:.2f}") for r in rows])
    print(md)
    if not args.skip_main:
        write_section("jit_startup", f"""## First run (JIT compilation) vs cached runs

`python benchmarks/jit_startup.py` ({machine()})

Wall time of a fresh process; the first run starts from an empty numba cache (`NUMBA_CACHE_DIR`) and
compiles the kernels (`element_jit`, `assembly_jit`, `se3_jit`) into it, the cached runs (best of two)
load them. `tests/elements/test_compiled_kernels.py::test_second_process_loads_the_cache` checks that a cached run
compiles nothing.

{md}
""")
    return rows


def main_timeline(ref, skip=()):
    from _report import machine, table, write_section
    rows = first_run(ref, skip)
    load = os.getloadavg()
    md = table(["run of `python examples/twisted_pair.py`", "first output [s]", "step 1 done [s]", "end [s]",
                "longest silence [s]", "CPU, job + children [s]", "Newton it."],
               [(n, f"{r['first']:.1f}", "-" if r["step1"] is None else f"{r['step1']:.1f}", f"{r['end']:.1f}",
                 f"{r['silence']:.1f}", f"{r['cpu']:.1f}", r["iterations"]) for n, r in rows])
    print(md)
    write_section("jit_first_run", f"""## The main job's first run: compilation announced, before step 0, in two processes (issue 29)

`python benchmarks/jit_startup.py --timeline{' --ref ' + ref if ref else ''}{' --skip ' + ' '.join(skip) if skip else ''}` ({machine()}; load average at the end
{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} over 1 / 5 / 15 min)

Each run is a fresh process started from an empty numba cache (`NUMBA_CACHE_DIR`; the cached run reuses the
first run's); the job runs with a `logging` handler so the end of step 1 is seen. Seconds from the start to its first
byte of output (the line `beamsolver: compiling the compiled kernels, first run only, ~N s`), to the end of step 1
and to the end; longest silence: the longest time without a byte on stdout or stderr (the compile bar refreshes
four times a second); CPU: user + system time of the job and its child processes (the second compiling process
included). On a loaded machine wall times stretch with the load; the CPU column does not.

{md}
""")
    return rows


if __name__ == "__main__":
    main()
