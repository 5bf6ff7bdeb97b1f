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

``--iterations``: whole Newton iterations instead, each (piece, variant) in its own child process, the variants
alternating, ``--rounds`` times (least CPU s of each part): as ``scaling_scenes`` (compiled code warmed on a small
bundle first), a ``Problem``'s first iteration and its second (``repeated``: pattern and PARDISO's analysis
reused), then a second ``Problem`` of the model (``new pattern``: groups, held pattern and PARDISO's analysis
anew, buffers warm), each ``evaluation`` (with tangent) + ``assembly`` (the Newton system) + ``solve``
(factorisation of ``A``, GMRES).  ``python benchmarks/new_pattern_cost.py --iterations --lengths 80,150,300``;
``--variants numpy,linear,linear-nomatch``: the last with PARDISO's analysis without weighted matching from
``NOMATCH_MIN`` unknowns (``linsolve.MATCHING_OFF_MIN``).
"""
import json
import subprocess
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
    node, vals = s.contact_blocks(ev.extra)
    best = {}
    mats = {}
    for r in range(rounds):
        for variant in ("numpy", "linear"):
            held_pattern.LINEAR_KEYS = variant == "linear"
            s.forget_held_pattern()
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


def _iteration(problem, solver, H):
    """CPU s of one Newton iteration at ``H``: evaluation, assembly, solve (``scaling_scenes.newton_direction``)."""
    from scaling_scenes import newton_direction
    problem.begin_step(H, 0.0)
    t = {}
    t0 = clock()
    ev = problem.evaluate(H, 1.0, tangent=True)
    t["evaluation"] = clock() - t0
    f, _ = newton_direction(problem, ev, solver, t)
    ev.drop_tangent()
    del f, ev
    t["iteration"] = sum(t.values())
    return t


def child(length_mm, variant):
    """JSON: the iterations of ``--iterations`` for one piece and variant."""
    from scaling import warm_up
    from scaling_scenes import rope_model, warm_contact
    from beamsolver.assembly import held_pattern
    from beamsolver.nonlinear import linsolve
    from beamsolver.nonlinear.problem import Problem
    held_pattern.LINEAR_KEYS = variant.startswith("linear")
    if variant.endswith("-nomatch"):           # PARDISO's analysis without weighted matching (``linsolve``)
        linsolve.MATCHING_OFF_MIN = NOMATCH_MIN
    warm_up()
    warm_contact()
    m, wires, _ = rope_model(length_mm * 1e-3)
    for w in wires:
        m.clamp(w.first)
    out = {}
    for name, its in (("first", ("first", "repeated")), ("second", ("new pattern", "repeated 2"))):
        problem = Problem.from_model(m)
        H = problem.system.poses0.copy()
        solver = linsolve.Solver(lagged=False)
        for it in its:
            out[it] = _iteration(problem, solver, H)
        out["elements"] = problem.system.n_elements
        solver.close()
        del problem
    print("JSON " + json.dumps(out))


NOMATCH_MIN = 50_000          # the ``-nomatch`` variants' ``linsolve.MATCHING_OFF_MIN``


def iterations(lengths, rounds, variants):
    best = {}
    for r in range(rounds):
        for L in lengths:
            for variant in variants:
                res = subprocess.run([sys.executable, __file__, "--child", str(L), variant], capture_output=True,
                                     text=True, env=dict(os.environ, OMP_NUM_THREADS="1", MKL_NUM_THREADS="1"))
                line = [x for x in res.stdout.splitlines() if x.startswith("JSON ")]
                if not line:
                    print(res.stderr[-2000:])
                    continue
                out = json.loads(line[0][5:])
                for it, parts in out.items():
                    if it == "elements":
                        best[L, "elements"] = parts
                        continue
                    for k, v in parts.items():
                        key = (L, variant, it, k)
                        best[key] = min(best.get(key, np.inf), v)
                print(f"round {r} {L} mm {variant}: " + ", ".join(f"{it} {p['iteration']:.3f}" for it, p in out.items()
                                                                  if it != "elements"), flush=True)
    print("\n| rope piece | variant | iteration | evaluation | assembly | solve | total | new / repeated |")
    print("|---|---|---|---:|---:|---:|---:|---:|")
    for L in lengths:
        for variant in variants:
            rep = best.get((L, variant, "repeated", "iteration"), np.nan)
            for it in ("first", "repeated", "new pattern"):
                g = [best.get((L, variant, it, k), np.nan) for k in ("evaluation", "assembly", "solve", "iteration")]
                ratio = f"{g[3] / rep:.2f}" if it == "new pattern" else ""
                print(f"| {L:g} mm ({best.get((L, 'elements'), '?')} el.) | {variant} | {it} | {g[0]:.3f} | {g[1]:.3f} "
                      f"| {g[2]:.3f} | {g[3]:.3f} | {ratio} |")


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        return child(float(sys.argv[2]), sys.argv[3])
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lengths", default="80,150,300")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--iterations", action="store_true", help="whole Newton iterations, child processes")
    ap.add_argument("--variants", default="numpy,linear", help="--iterations: numpy, linear, linear-nomatch")
    a = ap.parse_args()
    if a.iterations:
        return iterations([float(L) for L in a.lengths.split(",")], a.rounds, a.variants.split(","))
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
