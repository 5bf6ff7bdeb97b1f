"""Cost of recording steps in a ``Solution``: ``append`` per step, and reading ``sol.poses``.

A ``Solution`` of a straight beam of ``n`` elements is filled with ``S`` steps by
``Solution.append`` (what ``solve`` does after every converged step, checks included); the
table gives the mean time per append, the first read of ``sol.poses`` once all steps are in
(it joins the chunks the steps were written to), later reads, and ``sol.position(node, k)``.  For comparison, the same steps kept as
lists of copies (how ``Solution`` stored them before it grew arrays): the time per step of
those copies, and of stacking them ``np.array(list)`` (what every read of ``sol.poses`` cost then).
Each number is the best of ``REPEATS`` runs (the machine is shared; the best is the least
disturbed).  Run: ``python benchmarks/solution_append.py``; prints a table.
"""
import time

import numpy as np

import beamsolver as bs
from beamsolver.results.solution import Solution

REPEATS = 3


def filled(model, n_steps):
    """A ``Solution`` of ``model`` with ``n_steps`` steps, time per append, time of the first read."""
    H = np.array(model.poses0)
    R = np.zeros((len(H), 6))
    S = np.zeros((len(H) - 1, 6))
    sol = Solution(model)
    t0 = time.perf_counter()
    for k in range(n_steps):
        sol.append(float(k), H, R, S, S, dict(iterations=3))
    t1 = time.perf_counter()
    sol.poses
    return sol, (t1 - t0) / n_steps, time.perf_counter() - t1


def beam(n_elements):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n_elements), bs.Section.circular(1e-3, E=200e9))
    m.clamp(b.first)
    return m


def lists(sol):
    """The former storage: per-step time of its append (a copy of each array into a list), and
    of its first read of ``poses`` (stacking the list into new memory, as ``filled`` measures)."""
    out = ([], [], [], [])
    t0 = time.perf_counter()
    for k in range(len(sol)):
        for lst, a in zip(out, (sol.poses[k], sol.reactions[k], sol.section_forces[k], sol.strains[k])):
            lst.append(np.array(a))
    t1 = time.perf_counter()
    np.array(out[0])
    return (t1 - t0) / len(sol), time.perf_counter() - t1


def best(fn, repeats=5):
    out = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - t0)
    return out


def main():
    head = ("elements", "steps", "append [us/step]", "first read [ms]", "read poses [us]", "position [us]",
            "lists: append [us/step]", "lists: read poses [ms]")
    print(" | ".join(head))
    for n_elements in (10, 1000):
        model = beam(n_elements)
        for n_steps in (100, 1000, 3000):
            per = first = np.inf
            for _ in range(REPEATS):           # one solution alive at a time (memory reused, as for the lists)
                sol = None
                sol, p, f = filled(model, n_steps)
                per, first = min(per, p), min(first, f)
            old = [lists(sol) for _ in range(REPEATS)]
            per_list, first_list = min(r[0] for r in old), min(r[1] for r in old)
            print(" | ".join([f"{n_elements:8d}", f"{n_steps:5d}", f"{1e6 * per:16.1f}", f"{1e3 * first:15.2f}",
                              f"{1e6 * best(lambda: sol.poses):15.2f}",
                              f"{1e6 * best(lambda: sol.position(0, n_steps // 2)):13.2f}",
                              f"{1e6 * per_list:23.1f}", f"{1e3 * first_list:22.2f}"]))


if __name__ == "__main__":
    main()
