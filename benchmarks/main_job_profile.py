"""The main job's warm solve by kind of work (issue 30 item 3: "the main job's before/after profile").

``python benchmarks/main_job_profile.py [--solves 3] [--steps 16] [--no-write]``

``examples/twisted_pair.py``'s model (2 x 16 elements, exact stick) solved once to load the compiled code, then
``--solves`` times unprofiled (least CPU: the solve as the user meets it) and ``--solves`` times under cProfile,
whose own time per function is sorted into:

- **compiled kernels**: the numba-compiled functions of ``beamsolver`` (element, contact, mortar, SE(3) kernels),
  called from Python (a compiled function's callees are inside it);
- **linear solver**: ``nonlinear/linsolve.py`` and ``bandfactor.py`` and the scipy / pypardiso factorisations
  they call (SuperLU, LAPACK, PARDISO: calls cProfile cannot see are counted in their caller's own time);
- **numpy / scipy calls**: numpy's and scipy's functions and C methods (ufuncs, reductions, einsum, array
  creation, sparse matrices) other than the above;
- **Python glue**: every other function of ``beamsolver`` (bookkeeping, caches, transforms, Newton's loop) and
  the Python built-ins they call (``len``, ``isinstance``, list and dict methods);
- **other**: the standard library's and other packages' Python functions (logging, numba's dispatch).

cProfile adds a cost per Python call, so the glue's share is larger under it than in the plain solve: read the
shares against each other, the plain CPU for the time.  Single thread, CPU time (``time.process_time``);
Markdown on stdout and in the section ``main_job_profile`` of ``docs/benchmarks.md``.
"""
import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()
ROOT = Path(__file__).resolve().parents[1]
clock = time.process_time
KINDS = ("compiled kernels", "linear solver", "numpy / scipy calls", "Python glue", "other")
SOLVER_FILES = ("linsolve.py", "bandfactor.py")
SOLVER_NAMES = ("superlu", "gstrf", "gstrs", "lapack", "pardiso", "getrf", "getrs")


def compiled_functions():
    """``{(file, first line, name)}`` of the numba-compiled functions alive in the process (the package makes some
    of its dispatchers on first use, not as module attributes: they are found among the live objects)."""
    import gc

    from numba.core.dispatcher import Dispatcher
    out = set()
    for obj in gc.get_objects():
        if isinstance(obj, Dispatcher):
            code = obj.py_func.__code__
            out.add((code.co_filename, code.co_firstlineno, code.co_name))
    return out


def kind(key, compiled):
    """The kind of work of a cProfile entry ``(file, line, name)``."""
    file, _, name = key
    if key in compiled:
        return "compiled kernels"
    low = name.lower()
    if file == "~":                                  # a C function or method
        if any(s in low for s in SOLVER_NAMES):
            return "linear solver"
        return "numpy / scipy calls" if ("numpy" in low or "scipy" in low) else "Python glue"   # builtins: glue
    if file.endswith(SOLVER_FILES) or "pypardiso" in file or "_dsolve" in file or "_decomp_lu" in file:
        return "linear solver"
    if "/numpy/" in file or "/scipy/" in file:
        return "numpy / scipy calls"
    if "/beamsolver/" in file:
        return "Python glue"
    return "other"


def measure(solves, steps):
    import beamsolver as bs
    sys.path.insert(0, str(ROOT / "examples"))
    import twisted_pair as tp

    def solve():
        return bs.solve(tp.build()[0], steps=steps, verbose=False)

    sol = solve()                                    # compiled code loaded, first calls made
    its = int(sum(s["iterations"] for s in sol.stats))
    plain = []
    for _ in range(solves):
        t0 = clock()
        solve()
        plain.append(clock() - t0)
    prof = cProfile.Profile()
    t0 = clock()
    prof.enable()
    for _ in range(solves):
        solve()
    prof.disable()
    profiled = (clock() - t0) / solves
    compiled = compiled_functions()
    share = dict.fromkeys(KINDS, 0.0)
    calls = dict.fromkeys(KINDS, 0)
    for key, (_, ncalls, tottime, _, _) in pstats.Stats(prof).stats.items():
        k = kind(key, compiled)
        share[k] += tottime / solves
        calls[k] += ncalls // solves
    return dict(its=its, plain=min(plain), profiled=profiled, seconds=share, calls=calls)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--solves", type=int, default=3)
    ap.add_argument("--steps", type=int, default=16)
    ap.add_argument("--no-write", action="store_true")
    a = ap.parse_args(argv)
    r = measure(a.solves, a.steps)
    total = sum(r["seconds"].values())
    rows = [[k, f"{r['seconds'][k]:.3f}", f"{100 * r['seconds'][k] / total:.0f} %", r["calls"][k],
             f"{1e3 * r['seconds'][k] / r['its']:.2f}"] for k in KINDS]
    rows.append(["all (under cProfile)", f"{total:.3f}", "100 %", sum(r["calls"].values()),
                 f"{1e3 * total / r['its']:.2f}"])
    text = (f"`python benchmarks/main_job_profile.py --solves {a.solves} --steps {a.steps}` ({machine()}; one "
            f"thread). The main job (`examples/twisted_pair.py`, 2 x 16 elements, exact stick, {a.steps} steps, "
            f"{r['its']} Newton iterations): warm solve **{r['plain']:.3f} s** CPU (least of {a.solves}), "
            f"{r['profiled']:.3f} s under cProfile; the profiled solve's own time by kind of work (per solve; ms "
            "per Newton iteration):\n\n"
            + table(["kind", "s", "share", "calls", "ms / iteration"], rows))
    print(text)
    if not a.no_write:
        write_section("main_job_profile", "## The main job's solve by kind of work (issue 30)\n\n" + text)
    return r


if __name__ == "__main__":
    main()
