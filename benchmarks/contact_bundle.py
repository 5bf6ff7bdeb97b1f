"""One Newton iteration of the 19-wire bundle, part by part: where contact spends its time.

Scene: the 1+6+12 strand of ``benchmarks/scaling.py`` (19 twisted wires, lay 0.1 m,
24 elements per lay, layers overlapping by 0.5 % of R so that the contact points carry
force, 5 Gauss points, mu = 0.3) at about ``n`` elements (default 3000: 158 per wire).
One Newton iteration at the reference poses, by the public pieces a solver calls:

- ``element``: ``System.evaluate`` (elements, loads; contact is a contribution of the
  ``problem.Problem``);
- the contact stages from ``ContactSystem.timings`` (CPU time of each stage, one
  ``evaluate``): search (twists, spheres, broad phase), rules (pair rules, ownership),
  projection (closest points, Gauss-point projections), params (refusals, active set,
  history look-up), kernel (compiled forces and exact tangent), blocks (the local blocks
  handed over); contact assembly: the rest of ``Problem.evaluate`` (``System.assemble_blocks``:
  transforms, residual, COO);
- ``tangent assembly``: ``Problem.tangent`` (CSC); ``linear solve``: each ``linsolve``
  back-end available (factorisation + solve); ``update``: ``Problem.update``.

Times are CPU times of the process (``time.process_time``, least of ``REPEAT`` runs;
the machine is shared), one thread: the first iteration on the bundle (a new pattern of the
tangent: ``System.matrix`` and the ``splu-rcm`` ordering build their maps) and the least of the
``REPEAT`` next ones (the same active pairs, as between most Newton iterations: the maps are
reused).  The iteration uses the default linear solver; the other back-ends are timed after
the iterations.  CPU time includes the kernel's (system) time of page faults on freshly mapped
memory: a new array of tens of MB costs up to 1 s of system time when the machine's memory is
fragmented (the COO -> CSC conversion of scipy, with several 65 MB temporaries per iteration,
took 0.2-1.2 s for that reason; the cached pattern allocates none).

``python benchmarks/contact_bundle.py [n_elements]``
"""
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

from beamsolver import linsolve  # noqa: E402
from beamsolver.problem import Problem  # noqa: E402
from beamsolver.contact.system import TIMED  # noqa: E402
from scaling import bundle_model, bundle_per_wire  # noqa: E402

REPEAT = 3


def _cpu(fn):
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def one_iteration(problem, H):
    """CPU seconds of each part of one Newton iteration (contact evaluated afresh) and the
    number of active contact points."""
    system, c = problem.system, problem.contact
    problem.begin_step(H, 0.0)                     # a new step: nothing kept from the last evaluation
    for k in c.timings:
        c.timings[k] = 0.0
    t = {}
    t["element"], _ = _cpu(lambda: system.evaluate(H, problem.load_factors(1.0), tangent=True))
    total, ev = _cpu(lambda: problem.evaluate(H, 1.0, tangent=True))      # as the solver gets it
    t.update({f"contact {k}": c.timings[k] for k in TIMED})
    t["contact assembly (transforms, COO)"] = max(total - t["element"] - sum(c.timings.values()), 0.0)
    t["tangent assembly (CSC)"], K = _cpu(lambda: problem.tangent(ev))
    rhs = -ev.r[system.free_dofs]
    t[f"linear solve ({linsolve.DEFAULT}, the default)"], dz = _cpu(lambda: linsolve.factorize(K).solve(rhs))
    full = np.zeros(6 * system.n_nodes)
    full[system.free_dofs] = dz
    t["update"], _ = _cpu(lambda: problem.update(H, full.reshape(-1, 6)))
    return t, ev.details["contact"].get("n_active", -1), K, rhs


def main(n=3000):
    small, _ = bundle_model(bundle_per_wire(max(n // 10, 100)))
    warm = Problem.from_model(small)
    one_iteration(warm, warm.system.poses0.copy())        # compiled kernels loaded
    m, _ = bundle_model(bundle_per_wire(n))
    problem = Problem.from_model(m)
    system = problem.system
    H = system.poses0.copy()
    first, points, _, _ = one_iteration(problem, H)      # a new pattern: the tangent's and the ordering's
    runs = [one_iteration(problem, H) for _ in range(REPEAT)]
    best = {k: min(r[0][k] for r in runs) for k in runs[0][0]}
    total = sum(best.values())
    rows = [[k, f"{1e3 * first[k]:.1f}", f"{1e3 * v:.1f}"] for k, v in best.items()]
    rows.append(["one Newton iteration", f"{1e3 * sum(first.values()):.1f}", f"{1e3 * total:.1f}"])
    K, rhs = runs[-1][2:]
    for b in linsolve.available():              # the other back-ends, after the iterations
        if b != linsolve.DEFAULT:
            rows.append([f"(linear solve with {b} instead)", "",
                         f"{1e3 * _cpu(lambda: linsolve.factorize(K, b).solve(rhs))[0]:.1f}"])
    md = table(["part", "CPU ms, new pattern", f"CPU ms, same pattern (least of {REPEAT})"], rows)
    head = (f"19-wire bundle, {system.n_elements} elements, {system.n_free} unknowns, {points} active contact "
            "points; target (issue 14): "
            f"one Newton iteration <= 1 s. {'Met' if total <= 1.0 else 'Not met'}: {total:.2f} s.")
    return best, head + "\n\n" + md


if __name__ == "__main__":
    n = int(float(sys.argv[1])) if len(sys.argv) > 1 else 3000
    best, md = main(n)
    print(md)
    if n >= 3000:
        write_section("contact_bundle", f"""## Contact in the 19-wire bundle: one Newton iteration part by part (issue 14)

`python benchmarks/contact_bundle.py` ({machine()})

The strand of `benchmarks/scaling.py` (1+6+12 wires, 24 elements per lay, layers overlapping by
0.5 % of R, 5 Gauss points, mu = 0.3) at the reference poses; each part's CPU time (least of
{REPEAT} with the same pattern; the first iteration builds the cached pattern of the tangent and the
RCM ordering), the contact stages from `ContactSystem.timings`.

{md}
""")
