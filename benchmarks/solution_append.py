"""Cost of recording steps in a ``Solution``: ``append`` per step, and reading ``sol.poses``.

A ``Solution`` of a straight beam of ``n`` elements is filled with ``S`` steps by
``Solution.append`` (what ``solve`` does after every converged step, checks included); the
table gives the mean time per append, the first read of ``sol.poses`` once all steps are in
(it joins the chunks the steps were written to), later reads, and ``sol.position(node, k)``.  For comparison, the same steps kept as
lists of copies (how ``Solution`` stored them before it grew arrays): the time per step of
those copies, and of one stacking ``np.array(list)`` (what reading ``sol.poses`` cost then).
Run: ``python benchmarks/solution_append.py``; prints a table.
"""
import time

import numpy as np

import beamsolver as bs
from beamsolver.results import Solution


def filled(n_elements, n_steps):
    sec = bs.Section.circular(radius=1e-3, E=200e9)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n_elements), sec)
    m.clamp(b.first)
    H = np.array(m.poses0)
    R = np.zeros((len(H), 6))
    S = np.zeros((n_elements, 6))
    sol = Solution(m)
    t0 = time.perf_counter()
    for k in range(n_steps):
        sol.append(float(k), H, R, S, S, dict(iterations=3))
    t1 = time.perf_counter()
    sol.poses
    return sol, (t1 - t0) / n_steps, time.perf_counter() - t1


def lists(sol):
    """Per-step time of the former append (a copy of each array into a list), and the lists."""
    out = ([], [], [], [])
    t0 = time.perf_counter()
    for k in range(len(sol)):
        for lst, a in zip(out, (sol.poses[k], sol.reactions[k], sol.section_forces[k], sol.strains[k])):
            lst.append(np.array(a))
    return (time.perf_counter() - t0) / len(sol), out[0]


def best(fn, repeats=5):
    out = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - t0)
    return out


def main():
    head = ("elements", "steps", "append [us/step]", "first read [ms]", "read poses [us]", "position [us]", "lists: append [us/step]",
            "lists: read poses [ms]")
    print(" | ".join(head))
    for n_elements in (10, 1000):
        for n_steps in (100, 1000, 5000):
            sol, per, first = filled(n_elements, n_steps)
            per_list, steps = lists(sol)
            print(" | ".join([f"{n_elements:8d}", f"{n_steps:5d}", f"{1e6 * per:16.1f}", f"{1e3 * first:15.2f}",
                              f"{1e6 * best(lambda: sol.poses):15.2f}",
                              f"{1e6 * best(lambda: sol.position(0, n_steps // 2)):13.2f}",
                              f"{1e6 * per_list:23.1f}", f"{1e3 * best(lambda: np.array(steps)):22.2f}"]))


if __name__ == "__main__":
    main()
