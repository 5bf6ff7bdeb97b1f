"""The previous factorisation as a preconditioner (``linsolve.Solver(lagged=)``) on real Newton sequences.

``python benchmarks/lagged_solves.py [--scenes 19,37,61,strand-37,strand-61] [--rounds 2] [--tangents 8]``

Two measurements, one thread, CPU seconds, each scene in its own child process:

(a) **linear solves of a Newton sequence**: the tangents and right-hand sides of a real Newton run,
    recorded (``Solver.factorize`` / ``solve``) and replayed in the same process by a ``Solver`` with
    ``lagged=False`` (a factorisation per tangent, PARDISO's analysis reused while the pattern holds:
    what ``main`` did) and with ``lagged="auto"`` (the default), alternately, ``--rounds`` times
    (least time).  Scenes: ``19``, ``37``, ``61``: the bundles of ``scaling_scenes`` (issue 30's
    targets), stretched from the reference poses (``STRAIN``): the first ``--tangents`` tangents of
    that step (their pre-stress does not let one step converge: the first Newton iterations are the
    sequence a user of these scenes pays); ``strand-37``, ``strand-61``: the whole loaded step of their
    overlap-free twins (``scaling_scenes.strand_model``).  Reported: the sum of the solves, the
    fresh factorisations, lagged solves, GMRES iterations, lagged solves that fell back to a
    factorisation, and the largest difference of a solution from the direct one (relative, 2-norm)
    and relative residual;
(b) **the loaded step** of the strands (``scaling_scenes``: ``bs.solve(steps=1)``), lagged off and on
    (``linsolve.LAGGED``), alternately: CPU s, Newton iterations, median CPU s between iterations.

Markdown on stdout and in the section ``lagged_solves`` of ``docs/benchmarks.md``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()

import json  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

clock = time.process_time


def record(name, n_tangents):
    """``[(K, b), ...]`` of the Newton run of the scene ``name`` (see the module docstring)."""
    import beamsolver as bs
    import scaling_scenes as ss
    from beamsolver.nonlinear import linsolve
    seq, orig, limit = [], linsolve.Solver.factorize, [n_tangents]

    class Enough(Exception):
        pass

    def factorize(self, K):
        if len(seq) >= limit[0]:
            raise Enough
        f = orig(self, K)
        item = [K, None]
        seq.append(item)
        solve = f.solve

        def recorded(b):
            if item[1] is None:
                item[1] = np.array(b, dtype=float)
            return solve(b)
        f.solve = recorded
        return f
    strand = name.startswith("strand")
    limit[0] = n_tangents if not strand else 10_000
    m, wires, length = ss.strand_model(name.split("-")[1]) if strand else ss.scene_model(name)
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
    linsolve.Solver.factorize = factorize
    try:
        bs.solve(m, steps=1, verbose=False, min_step_ratio=ss.STEP_FLOOR, linear_solver="auto")
    except Enough:
        pass
    except Exception:              # noqa: BLE001  (the bundles' step need not converge: the sequence is kept)
        pass
    finally:
        linsolve.Solver.factorize = orig
    return [(K, b) for K, b in seq if b is not None]


def replay(seq, lagged):
    from beamsolver.nonlinear import linsolve
    s = linsolve.Solver(None, lagged=lagged)
    xs, total = [], 0.0
    for K, b in seq:
        t0 = clock()
        x = s.factorize(K).solve(b)
        total += clock() - t0
        xs.append(x)
    stats = dict(s.stats)
    s.close()
    return total, xs, stats


def measure_sequence(name, rounds, n_tangents):
    from scaling import warm_up
    warm_up()
    seq = record(name, n_tangents)
    best = {False: np.inf, "auto": np.inf}
    for _ in range(rounds):
        for lagged in (False, "auto"):
            t, xs, stats = replay(seq, lagged)
            best[lagged] = min(best[lagged], t)
            if lagged is False:
                ref = xs
            else:
                lag_stats, lag_xs = stats, xs
    diff = max(np.linalg.norm(a - c) / np.linalg.norm(a) for a, c in zip(ref, lag_xs))
    res = max(np.linalg.norm(K @ x - b) / np.linalg.norm(b) for (K, b), x in zip(seq, lag_xs))
    return dict(scene=name, unknowns=int(seq[0][0].shape[0]), tangents=len(seq), direct_s=best[False],
                lagged_s=best["auto"], factorizations=lag_stats["factorizations"], lagged=lag_stats["lagged"],
                krylov=lag_stats["krylov_iterations"], failures=lag_stats["lag_failures"], diff=float(diff),
                residual=float(res))


def measure_step(name, lagged):
    import beamsolver as bs
    import scaling_scenes as ss
    from beamsolver.nonlinear import linsolve
    from scaling import warm_up
    warm_up()
    linsolve.LAGGED = lagged
    m, wires, length = ss.strand_model(name.split("-")[1])
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
    stamps = []
    t0 = clock()
    sol = bs.solve(m, steps=1, verbose=False, callback=lambda d: stamps.append((d["t"], clock())),
                   min_step_ratio=ss.STEP_FLOOR)
    step_s = clock() - t0
    gaps = [b[1] - a[1] for a, b in zip(stamps, stamps[1:]) if a[0] == b[0] and a[0] > 0.0]
    return dict(scene=name, lagged=str(lagged), step_s=step_s, iterations=int(sol.stats[-1]["iterations"]),
                it_s=float(np.median(gaps)) if gaps else float("nan"),
                residuals=[float(r) for r in sol.stats[-1]["residuals"]])


def child(args):
    if args[0] == "sequence":
        out = measure_sequence(args[1], int(args[2]), int(args[3]))
    else:
        out = measure_step(args[1], {"False": False, "auto": "auto"}[args[2]])
    print("RESULT " + json.dumps(out))


def run_child(*args):
    p = subprocess.run([sys.executable, __file__, "--child", *map(str, args)], capture_output=True, text=True)
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("RESULT ")]
    if not lines:
        raise RuntimeError(p.stderr[-2000:])
    return json.loads(lines[-1][7:])


def main(argv):
    import argparse
    if argv and argv[0] == "--child":
        return child(argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="19,37,61,strand-37,strand-61")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--tangents", type=int, default=8)
    a = ap.parse_args(argv)
    t_start = time.time()
    scenes = a.scenes.split(",")
    seq_rows = []
    for name in scenes:
        r = run_child("sequence", name, a.rounds, a.tangents)
        print(r, flush=True)
        seq_rows.append([r["scene"], r["unknowns"], r["tangents"], f"{r['direct_s']:.3g}",
                         f"{r['lagged_s']:.3g}",
                         f"{r['direct_s'] / r['tangents']:.3g}", f"{r['lagged_s'] / r['tangents']:.3g}",
                         r["factorizations"], r["lagged"], r["krylov"], r["failures"], f"{r['diff']:.1e}",
                         f"{r['residual']:.1e}"])
    step_rows = []
    for name in [s for s in scenes if s.startswith("strand")]:
        best = {}
        for _ in range(a.rounds):
            for lagged in ("False", "auto"):
                r = run_child("step", name, lagged)
                print(r, flush=True)
                if lagged not in best or r["step_s"] < best[lagged]["step_s"]:
                    best[lagged] = r
        for lagged in ("False", "auto"):
            r = best[lagged]
            step_rows.append([name, lagged, f"{r['step_s']:.3g}", r["iterations"], f"{r['it_s']:.3g}",
                              " ".join(f"{x:.1e}" for x in r["residuals"])])
    about = " ".join(__doc__.split("Two measurements, ", 1)[1].split("Markdown on stdout")[0].split())
    about = about.replace("``", "`").replace(": (a)", ".\n\n(a)").replace("; (b)", ".\n\n(b)")
    text = (f"## Lagged factorisations: the previous factor as a preconditioner (issue 30)\n\n"
            f"`python benchmarks/lagged_solves.py --scenes {a.scenes} --rounds {a.rounds} --tangents {a.tangents}` "
            f"({machine()}; one thread; whole run {time.time() - t_start:.0f} s).  Two measurements, {about}\n\n"
            + table(["scene", "unknowns", "tangents", "solves, direct (s)", "solves, lagged (s)",
                     "per tangent, direct", "per tangent, lagged", "factorisations (lagged run)", "lagged solves",
                     "GMRES iterations", "fell back", "largest relative difference from direct",
                     "largest relative residual"], seq_rows))
    if step_rows:
        text += "\n\n" + table(["scene", "lagged", "loaded step (s)", "Newton iterations", "s per iteration",
                                "residuals"], step_rows)
    print(text)
    write_section("lagged_solves", text)


if __name__ == "__main__":
    main(sys.argv[1:])
