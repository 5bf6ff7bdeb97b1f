"""Contact search under mesh refinement: candidates and time per slave point, twisted pair 16 -> 256 el/wire.

``python benchmarks/search_scaling.py [--sizes 16,32,64,128,256] [--fine 256,1024,4096] [--no-write]``

(a) **Newton iterations** of the main job's scene (``examples/twisted_pair.build``: two wires, 2 turns in
    16 steps, default solver), per el/wire, solved once warm: slave points, element pairs per slave
    element (broad phase and pair rules), Gauss-point projections per slave point (Newton solves of
    ``projection.gauss_projections``), contact points per slave point, Newton iterations, CPU ms per
    iteration (all; the contact search = ``ContactSystem.timings`` search + rules + projection; the
    contact kernels = params + kernel; the linear solver's factorisations and solves), and the first
    iteration of a step (new step: pairs appearing, the matrix pattern new) against the later ones
    (medians of the intervals between the solver's callbacks).
(b) **Search alone** at the poses of a quarter turn (2 steps), finer meshes: element pairs per slave
    element, projections per slave point with and without the cull of line rows whose section plane
    misses the master (``gauss_projections(window=)``), and the search's least CPU time per slave
    point, with and without the cull.

Single thread, CPU time (``time.process_time``); Markdown on stdout and in the section
``search_scaling`` of ``docs/benchmarks.md``.
"""
import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))

import beamsolver as bs  # noqa: E402
from beamsolver.contact import system as contact_system  # noqa: E402
from beamsolver.nonlinear import linsolve  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402
import twisted_pair  # noqa: E402

clock = time.process_time


class Counters:
    """Counts and times of the search and the linear solver, by wrapping what ``ContactSystem`` calls
    (the module attributes it looks up at each call) and ``linsolve.Solver.factorize`` (and the factors'
    ``solve``)."""

    def __init__(self, cull=True):
        self.cull = cull
        self.pairs, self.rows, self.contacts = [], [], []
        self.solver_time = 0.0
        self.systems = []

    def __enter__(self):
        c = self
        self._saved = (contact_system.broad_pairs, contact_system.gauss_projections, contact_system.ContactSystem.pairs,
                       contact_system.ContactSystem.__init__, linsolve.Solver.factorize)
        broad, gauss, pairs, init, factorize = self._saved

        def broad_pairs(*a, **k):
            out = broad(*a, **k)
            c.pairs.append(len(out[0]))
            return out

        def gauss_projections(*a, **k):
            out = gauss(*a, **dict(k, window=k.get("window") if c.cull else None))
            c.rows.append(len(out[0]))
            return out

        def all_pairs(self, H):
            P = pairs(self, H)
            c.contacts.append(0 if P is None else len(P))
            return P

        def new_init(self, *a, **k):
            init(self, *a, **k)
            c.systems.append(self)

        def timed(f):
            def g(*a, **k):
                t0 = clock()
                try:
                    return f(*a, **k)
                finally:
                    c.solver_time += clock() - t0
            return g

        def factorized(solver, K):
            lu = timed(factorize)(solver, K)
            lu.solve = timed(lu.solve)          # the factor's own solve, timed
            return lu

        contact_system.broad_pairs, contact_system.gauss_projections = broad_pairs, gauss_projections
        contact_system.ContactSystem.pairs, contact_system.ContactSystem.__init__ = all_pairs, new_init
        linsolve.Solver.factorize = factorized
        return self

    def __exit__(self, *exc):
        (contact_system.broad_pairs, contact_system.gauss_projections, contact_system.ContactSystem.pairs,
         contact_system.ContactSystem.__init__, linsolve.Solver.factorize) = self._saved


def slave_counts(model):
    """Slave elements and slave points of the model's contact declarations."""
    c = Problem.from_model(model, check_rigid_modes=False).contact
    n_el = sum(len(d.slave_el) for d in c.decls)
    return n_el, sum(len(d.slave_el) * d.n_gp for d in c.decls)


def newton_row(n):
    """Table (a)'s row of the twisted pair with ``n`` elements per wire."""
    model, _, _ = twisted_pair.build(n_elements=n)
    n_el, n_pts = slave_counts(model)
    stamps = []
    with Counters() as cnt:
        t0 = clock()
        sol = bs.solve(model, steps=16, callback=lambda info: stamps.append((info["t"], info["iteration"], clock())))
        total = clock() - t0
    its = sum(s["iterations"] for s in sol.stats)
    first, later = [], []
    for (t_a, i_a, c_a), (t_b, i_b, c_b) in zip(stamps[:-1], stamps[1:]):
        if t_a == t_b and i_b == i_a + 1 and t_a > 0:
            (first if i_a == 0 else later).append(1e3 * (c_b - c_a))
    tm = cnt.systems[-1].timings
    search = tm["search"] + tm["rules"] + tm["projection"]
    kernels = tm["params"] + tm["kernel"]
    ms = lambda v: 1e3 * v / its        # noqa: E731
    f, r = float(np.median(first)), float(np.median(later))
    return (n, n_pts, float(np.mean(cnt.pairs)) / n_el, float(np.mean(cnt.rows)) / n_pts,
            float(np.mean(cnt.contacts)) / n_pts, its, ms(total), ms(search), ms(kernels), ms(cnt.solver_time),
            f, r, f / r)


def search_row(n, repeat=10):
    """Table (b)'s row: the search alone at the poses of a quarter turn, ``n`` elements per wire."""
    model, _, _ = twisted_pair.build(n_elements=n, turns=0.25)
    H = bs.solve(model, steps=2).poses[-1]
    n_el, n_pts = slave_counts(model)
    out = [n, n_pts]
    times = []
    for cull in (True, False):
        with Counters(cull) as cnt:
            c = Problem.from_model(model, check_rigid_modes=False).contact
            c.commit(H)
            best = {}
            for _ in range(repeat):
                c.timings = dict.fromkeys(c.timings, 0.0)
                t0 = clock()
                c.pairs(H)
                d = dict(c.timings, total=clock() - t0)
                best = {k: min(best.get(k, np.inf), v) for k, v in d.items()}
        if cull:
            out.append(cnt.pairs[-1] / n_el)
        out.append(cnt.rows[-1] / n_pts)
        times += [1e6 * best["total"] / n_pts, 1e6 * best["projection"] / n_pts]
    return tuple(out + times)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,32,64,128,256", help="el/wire of table (a)")
    ap.add_argument("--fine", default="256,1024,4096", help="el/wire of table (b)")
    ap.add_argument("--no-write", action="store_true", help="do not write docs/benchmarks.md")
    a = ap.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",") if s]
    fine = [int(s) for s in a.fine.split(",") if s]
    # warm: kernels loaded, and PARDISO (MKL) loaded if the default solver picks it at the larger sizes
    warm = "pardiso" if "pardiso" in linsolve.available() else "auto"
    bs.solve(twisted_pair.build(n_elements=16, turns=0.25)[0], steps=2, linear_solver=warm)
    rows_a = []
    for n in sizes:
        rows_a.append(newton_row(n))
        print(rows_a[-1], flush=True)
    rows_b = []
    for n in fine:
        rows_b.append(search_row(n))
        print(rows_b[-1], flush=True)
    text = [f"`python benchmarks/search_scaling.py --sizes {a.sizes} --fine {a.fine}`; {machine()}; single "
            "thread, CPU time.\n",
            "**(a) Twisted pair, 2 turns in 16 steps** (the main job's scene, default solver): counts per slave "
            "element / point averaged over the searches; ms per Newton iteration: all, of which the contact search "
            "(search + rules + projection), the contact kernels (params + kernel) and the linear solver; first "
            "iteration of a step against the later ones (medians).  Warm: the kernels and PARDISO loaded first (the "
            "default solver picks PARDISO from 1500 unknowns, 128 el/wire and up; a process loading it pays ~0.6 s "
            "once, at its first factorisation: 6 ms per iteration of this run at 128 el/wire).\n",
            table(["el/wire", "slave points", "element pairs / slave el.", "projections / slave pt",
                   "contact pts / slave pt", "Newton it.", "ms / it.", "search", "kernels", "linear solver",
                   "first it. [ms]", "later it. [ms]", "first / later"], rows_a,
                  fmt={2: ".2f", 3: ".2f", 4: ".2f", 6: ".2f", 7: ".3f", 8: ".3f", 9: ".3f", 10: ".2f", 11: ".2f",
                       12: ".2f"}),
            "\n**(b) Search alone** at the poses of a quarter turn (least of 10 searches): element pairs per slave "
            "element, Gauss-point projections per slave point with the cull of line rows whose section plane "
            "misses the master (`gauss_projections(window=)`) and without; search and projection CPU time in us "
            "per slave point, with and without.\n",
            table(["el/wire", "slave points", "element pairs / slave el.", "projections / slave pt",
                   "without cull", "search [us/pt]", "of which projection", "search without cull",
                   "of which projection"], rows_b,
                  fmt={2: ".2f", 3: ".2f", 4: ".2f", 5: ".3f", 6: ".3f", 7: ".3f", 8: ".3f"})]
    md = "\n".join(text)
    print(md)
    if not a.no_write:
        write_section("search_scaling", md)


if __name__ == "__main__":
    main()
