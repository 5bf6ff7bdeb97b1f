"""One Newton iteration of the 19-wire bundle, part by part: where contact spends its time.

Scene: the 1+6+12 strand of ``benchmarks/scaling.py`` (19 twisted wires, lay 0.1 m,
24 elements per lay, layers overlapping by 0.5 % of R so that the contact points carry
force, 5 Gauss points, mu = 0.3) at about ``n`` elements (default 3000: 158 per wire).
One Newton iteration at the reference poses, by the public pieces a solver calls:

- ``element``: ``System.evaluate`` minus its contact part;
- the contact parts from ``ContactSystem.timings`` (CPU time of each stage, one
  ``evaluate``): search (twists, spheres, broad phase), rules (pair rules, ownership),
  projection (closest points, Gauss-point projections), params (refusals, active set,
  history look-up), kernel (compiled forces and exact tangent), scatter (residual and
  COO triplets);
- ``assembly``: ``System.matrix``; ``linear solve``: each ``linsolve`` back-end available
  (factorisation + solve); ``update``: ``System.update``.

Times are CPU times of the process (``time.process_time``, least of ``REPEAT`` runs;
the machine is shared), one thread.

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
from beamsolver.assembly import System  # noqa: E402
from beamsolver.contact.system import TIMED  # noqa: E402
from scaling import bundle_model, bundle_per_wire  # noqa: E402

REPEAT = 3


def one_iteration(system, H, lf):
    """CPU seconds of each part of one Newton iteration (contact evaluated afresh)."""
    c = system.contact
    c.begin_step(H, 0.0)                     # a new step: nothing cached
    for k in c.timings:
        c.timings[k] = 0.0
    t = {}
    t0 = time.process_time()
    r, kvals, info = system.evaluate(H, lf, tangent=True)
    total = time.process_time() - t0
    t.update({f"contact {k}": c.timings[k] for k in TIMED})
    t["element"] = max(total - sum(c.timings.values()), 0.0)
    t0 = time.process_time()
    K = system.matrix(kvals, info["extra"])
    t["assembly"] = time.process_time() - t0
    rhs = -r[system.free_dofs]
    for b in linsolve.available():
        t0 = time.process_time()
        dz = linsolve.factorize(K, b).solve(rhs)
        t[f"linear solve ({b})"] = time.process_time() - t0
    full = np.zeros(6 * system.n_nodes)
    full[system.free_dofs] = dz
    t0 = time.process_time()
    system.update(H, full.reshape(-1, 6))
    t["update"] = time.process_time() - t0
    return t, info.get("contact", {}).get("n_active", -1)


def main(n=3000):
    m, _ = bundle_model(bundle_per_wire(n))
    system = System(m)
    H = system.poses0.copy()
    lf = system.load_factors(1.0)
    _, points = one_iteration(system, H, lf)             # compiled kernels loaded, caches warm
    runs = [one_iteration(system, H, lf)[0] for _ in range(REPEAT)]
    best = {k: min(r[k] for r in runs) for k in runs[0]}
    solvers = [k for k in best if k.startswith("linear solve")]
    fastest = min(solvers, key=best.get)
    rest = sum(v for k, v in best.items() if k not in solvers)
    rows = [[k, f"{1e3 * v:.1f}"] for k, v in best.items()]
    rows.append([f"one Newton iteration (best solver: {fastest[14:-1]})", f"{1e3 * (rest + best[fastest]):.1f}"])
    md = table(["part", "CPU ms"], rows)
    head = (f"19-wire bundle, {system.n_elements} elements, {system.n_free} unknowns, {points} active contact "
            "points; target (issue 14): "
            f"one Newton iteration <= 1 s. {'Met' if rest + best[fastest] <= 1.0 else 'Not met'}: "
            f"{rest + best[fastest]:.2f} s.")
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
{REPEAT}), the contact stages from `ContactSystem.timings`.

{md}
""")
