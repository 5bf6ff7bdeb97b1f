"""Resident memory of Newton iterations on the issue-30 scenes, stage by stage (issue 30, item 1).

``python benchmarks/iteration_memory.py [--scene 61] [--iterations 3]``

Builds the scene of ``scaling_scenes.scene_model`` (``19``, ``37``, ``61``, ``rope-<mm>``) and runs
``--iterations`` Newton iterations at the reference poses as ``Newton.iterate`` does them:
``Problem.begin_step``, the evaluation with tangent, the Newton system (``Problem.tangent``, CSC; exact stick:
``Problem.augmented_system``, the tangent ``K'`` and ``A = K' + Kq E Kl``), the factorisation and solve (exact
stick: GMRES preconditioned by the factor of ``A``) with the default
``linsolve.Solver`` (``--lagged off``: without lagged solves; the iterations share their poses, so the lagged ones take one GMRES iteration), ``Evaluation.drop_tangent``, then a residual-only
evaluation at slightly moved poses (a line-search trial).  After each stage it reads
``/proc/self/status``: the resident memory ``VmRSS`` and the peak since the previous stage
(``VmHWM``, reset by writing ``5`` to ``/proc/self/clear_refs``), in MB.  One thread (MKL pinned).
Linux only.  Markdown table on stdout.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, memory_status, reset_peak, single_thread, table  # noqa: E402

single_thread()

import numpy as np  # noqa: E402


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="61")
    ap.add_argument("--iterations", type=int, default=3)
    ap.add_argument("--lagged", default="auto", choices=("auto", "off"),
                    help="linsolve.Solver(lagged=): the default, or a factorisation per iteration")
    a = ap.parse_args(argv)
    import scaling_scenes
    from scaling import warm_up

    from beamsolver.nonlinear import linsolve, newton as newton_
    from beamsolver.nonlinear.problem import Problem
    rows = []

    def mark(label):
        s = memory_status()
        rows.append([label, f"{s['VmRSS']:.0f}", f"{s['VmHWM']:.0f}"])
        reset_peak()

    warm_up()
    mark("imports, warm-up")
    m, wires, _ = scaling_scenes.scene_model(a.scene)
    if a.scene.startswith("rope"):
        for w in wires:
            m.clamp(w.first)
    problem = Problem.from_model(m)
    system = problem.system
    mark("model and problem built")
    H = system.poses0.copy()
    solver = linsolve.Solver(lagged=a.lagged if a.lagged == "auto" else False)
    rng = np.random.default_rng(1)
    for it in range(a.iterations):
        problem.begin_step(H, 0.0)
        ev = problem.evaluate(H, 1.0, tangent=True)
        mark(f"{it}: evaluate (tangent)")
        t = {}
        if problem.augments(ev):         # exact stick: the Newton system and its solve as ``Newton.direction``
            aug = problem.augmented_system(ev)
            if newton_.DROP_BEFORE_SOLVE:        # as ``Newton.direction``
                ev.drop_tangent()
            mark(f"{it}: Newton system (tangent K', augmented A)")
            f = aug.solve(solver)
            problem.multiplier_step(ev, problem.split_solution(ev, f)[1])
            del aug
            ev.drop_tangent()
            mark(f"{it}: factorise + solve")
        else:
            f, _ = scaling_scenes.newton_direction(problem, ev, solver, t)
            ev.drop_tangent()
            mark(f"{it}: Newton system, factorise + solve")
        problem.evaluate(system.update(H, 1e-9 * rng.standard_normal((system.n_nodes, 6))), 1.0, tangent=False)
        mark(f"{it}: residual (trial)")
        del ev, f
    solver.close()
    print(f"`python benchmarks/iteration_memory.py --scene {a.scene} --iterations {a.iterations} --lagged {a.lagged}` "
          f"({machine()}; "
          f"{system.n_elements} elements, {system.n_free} unknowns): MB after each stage\n")
    print(table(["stage", "resident (VmRSS)", "peak during the stage (VmHWM)"], rows))


if __name__ == "__main__":
    main(sys.argv[1:])
