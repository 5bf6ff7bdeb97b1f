"""The Newton system's build on a new contact pattern against a held one, on the rope pieces (issue 30 item 2).

For each rope piece (``scaling_scenes.rope_model``, ``--lengths`` in mm) one evaluation with tangent at the
reference poses, then, alternating the variants ``--rounds`` times (least CPU s, ``time.process_time``):

- ``held``: ``System.matrix`` on the pattern held from the previous call (what a repeated iteration pays);
- ``new``: ``System.matrix`` with no pattern held (``HeldPattern`` built: node graph, dof pattern, element
  positions, grown by the contact blocks, values), what a new contact pattern pays;
- ``keys``: of ``new``, the node-pair keys alone (the element pattern's and the blocks'; ``node_keys`` or numpy).

Variants: ``held_pattern.LINEAR_KEYS`` on (``linear``) and off (``numpy``: ``np.unique`` / ``union1d`` /
``setdiff1d`` / ``isin``).  Prints a markdown table; the matrices of both variants are compared entry for entry.
``python benchmarks/new_pattern_cost.py --lengths 80,150,300 --rounds 3``
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
clock = time.process_time


def measure(length_mm, rounds):
    from scaling_scenes import rope_model
    from beamsolver.assembly import held_pattern, node_keys
    from beamsolver.nonlinear.problem import Problem
    m, wires, _ = rope_model(length_mm * 1e-3)
    for w in wires:
        m.clamp(w.first)
    problem = Problem.from_model(m)
    s = problem.system
    H = s.poses0.copy()
    problem.begin_step(H, 0.0)
    ev = problem.evaluate(H, 1.0, tangent=True)
    node = s._block_nodes(s._coo_index[0])
    k = node.shape[1]
    vals = ev.extra[2][:s._coo_index[1].size].reshape(-1, 6 * k, 6 * k)
    best = {}
    mats = {}
    for r in range(rounds):
        for variant in ("numpy", "linear"):
            held_pattern.LINEAR_KEYS = variant == "linear"
            s._held_cache = None
            t0 = clock()
            K = s.matrix(ev.kvals, ev.extra)
            t_new = clock() - t0
            t0 = clock()
            K2 = s.matrix(ev.kvals, ev.extra)
            t_held = clock() - t0
            p = s.held_pattern
            t0 = clock()
            if variant == "linear":
                node_keys.element_keys(s.indptr, s.indices, np.flatnonzero(s.red >= 0) // 6, p.n_nodes)
                node_keys.block_keys(node, vals, p.nfree, p.n_nodes)
            else:
                node_of = np.flatnonzero(s.red >= 0) // 6
                col = np.repeat(np.arange(s.n_free), np.diff(s.indptr))
                np.unique(node_of[col] * p.n_nodes + node_of[s.indices])
                held_pattern._pair_keys(node, vals, p.nfree, p.n_nodes)
            t_keys = clock() - t0
            for key, v in (("new", t_new), ("held", t_held), ("keys", t_keys)):
                best[variant, key] = min(best.get((variant, key), np.inf), v)
            mats[variant] = K
            del K2
    a, b = mats["numpy"], mats["linear"]
    same = (np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.data, b.data))
    return dict(length=length_mm, elements=s.n_elements, nnz=a.nnz, same=same, **{f"{v}_{k}": t for (v, k), t in best.items()})


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lengths", default="80,150,300")
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    from scaling import warm_up
    warm_up()
    rows = [measure(float(L), a.rounds) for L in a.lengths.split(",")]
    print("| rope piece | elements | nnz | keys: numpy / linear [s] | new pattern: numpy / linear [s] "
          "| held pattern [s] | new / held (linear) | same matrix |")
    print("|---|---:|---:|---|---|---|---:|---|")
    for r in rows:
        print(f"| {r['length']:g} mm | {r['elements']} | {r['nnz']:.3g} | {r['numpy_keys']:.3f} / {r['linear_keys']:.3f} "
              f"| {r['numpy_new']:.3f} / {r['linear_new']:.3f} | {min(r['numpy_held'], r['linear_held']):.3f} "
              f"| {r['linear_new'] / min(r['numpy_held'], r['linear_held']):.2f} | {r['same']} |", flush=True)


if __name__ == "__main__":
    main()
