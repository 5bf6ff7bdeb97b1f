"""Scaling of one Newton iteration with the model size, part by part, 1e2 .. 1e5 elements.

``python benchmarks/scaling.py [max_elements] [--bundle-cap N]``; ``python benchmarks/scaling.py --scenes
19,37,61,rope-20,rope-40`` instead runs the bundles of 19, 37 and 61 wires and pieces of a rope
(issue 30: one Newton iteration by parts and a loaded step each, ``scaling_scenes.py``).

Two scenes, sizes ~1e2, 3e2, 1e3, ... up to ``max_elements`` (default 1e5):

(a) **cable**: one long clamped cable (a gentle helix, curved and twisted
    elements) with a dead tip load, in a deformed state; no contact.
(b) **bundle**: a 1+6+12 strand of 19 twisted wires (equal lay 0.1 m, 24
    elements per lay, wire radius 1 mm, pitch radii 0.5 % tight so that
    neighbouring layers overlap), contact declared layer on layer below and
    between touching neighbours of a layer (as ``cables.build_strand``), 5
    Gauss points, mu = 0.3; the size grows with the length.

Each part is timed by calling what one Newton iteration calls through the
public ``problem.Problem`` interface and its ``System``, once per Newton iteration:

- ``element``: ``System.evaluate`` (element kernels, transforms, loads,
  residual scatter; contact is a separate contribution of the ``Problem``);
- ``contact search`` (search + rules + projection of the public
  ``ContactSystem.timings``), ``contact kernels`` (params + kernel: refusals, active
  set, history look-up and the compiled kernel) and ``contact other`` (the rest of
  ``ContactSystem.evaluate`` and the generic assembler ``System.assemble_blocks``:
  transforms, residual and COO build); ``benchmarks/contact_bundle.py`` shows every stage;
- ``assembly``: ``System.matrix`` (CSC scatter of the element values and the
  contact COO);
- ``solve``: ``linsolve`` factorisation + solve with the default back-end
  (scipy ``splu``);
- ``update`` (``Problem.update``) and ``residual`` (``Problem.evaluate(...,
  tangent=False)``, the line search's evaluation, with contact);
- ``output``: ``io.vtk.StepWriter.write`` of one step (default refine 8, zlib),
  a per-step cost, and for the bundle ``commit`` (friction history +
  result table of a converged step), also per step.

Contact is the slow part today, so the bundle runs the contact code only up
to ``--bundle-cap`` elements (default 3000), or less if a contact evaluation
is predicted (linearly) to take more than ``CONTACT_BUDGET`` s.  Above the
cap the bundle's contact tangent is *replicated*: the strand is periodic in
``z`` with the lay length (every wire, core included, has 24 elements per
lay and translating by one lay maps each wire onto itself, frames included),
and body-frame contact tangents do not change under a rigid motion, so the
contact blocks of one interior lay (computed for real on a 1.5-lay strand)
are copied to every lay (pre-summed per matrix entry).  The matrices that
``assembly`` and the linear solvers see then have the pattern and values of
the real bundle (checked against the real one at the largest contact size:
``replica_error``), but contact search/kernel times are not measured there.

Also measured in the same run: ``splu`` vs ``pardiso`` (pypardiso, if
installed) on both scenes: first factorisation (ordering + symbolic +
numeric) and a re-factorisation with the same pattern (what a Newton
iteration costs with ``linsolve.Solver``, which reuses PARDISO's analysis),
plus factor sizes; peak memory (``ru_maxrss``) of a child process per size
(each size runs in its own process); and "a scene without contact or output
pays nothing": one ``bs.solve`` Newton iteration of the cable against the
sum of its parts, and which contact/output modules were loaded.

Single thread (BLAS/OpenMP/MKL pools pinned to one thread before numpy is
imported), so PARDISO runs on one core like SuperLU; times are CPU times of
the measuring process (``time.process_time``), which other jobs on a shared
machine disturb much less than wall-clock times.  Markdown tables on
stdout and in the section ``scaling`` of ``docs/benchmarks.md``, CSV in
``benchmarks/results/scaling.csv``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, section_rows, single_thread, table, write_csv, write_section  # noqa: E402
import os  # noqa: E402

single_thread()
if os.environ.get("SCALING_THREADS"):          # --step-parts --threads: a child with more MKL/OpenMP threads
    for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[_var] = os.environ["SCALING_THREADS"]

import json  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

CABLE_SIZES = (100, 300, 1_000, 3_000, 10_000, 30_000, 100_000)
BUNDLE_CAP = 3_000          # elements: largest bundle run through the contact code
CONTACT_BUDGET = 90.0       # s: skip the contact code when one evaluation is predicted to take longer
LAY = 0.1                   # lay length of the bundle (m)
PER_LAY = 24                # elements per lay
WIRE_R = 1e-3
TIGHT = 0.995               # pitch radii scaled by this: neighbouring layers overlap by ~0.5 % of R
N_WIRES = 19                # 1 + 6 + 12
UNIT = 36                   # elements per wire of the strand whose contact tangent is replicated
UNIT_LO = 6                 # its interior lay: slave elements UNIT_LO .. UNIT_LO + PER_LAY - 1
SOLVER_BUDGET = 60.0        # s: skip a linear solver predicted (from the smaller sizes) to take longer
clock = time.process_time   # CPU time of this (single-threaded) process: robust to other load on a shared machine
PARTS = ("element", "contact_search", "contact_kernels", "contact_other", "assembly", "solve", "update",
         "residual")


# ------------------------------------------------------------------ scenes
def cable(n):
    """A clamped cable of ``n`` elements along a gentle helix (10 m, 1 turn per 2 m), deformed."""
    import beamsolver as bs
    from beamsolver.assembly.system import System
    sec = bs.Section.circular(radius=0.005, E=2e11)
    m = bs.Model()
    beam = m.add_beam(bs.geometry.helix(radius=0.5, pitch=2.0, length=10.0, n_elements=n), sec)
    m.clamp(beam.first)
    m.add_load(beam.last, force=(0.1, -0.2, 0.3))
    system = System(m)
    rng = np.random.default_rng(0)
    dz = 1e-3 * rng.standard_normal((system.n_nodes, 6))
    dz[:, :3] *= 0.01
    H = system.update(system.poses0, dz, chains=False)
    return m, system, H


def bundle_model(per_wire, mu=0.3, gauss_points=5, n_layers=2):
    """The 1+6+12 strand (``n_layers`` = 2; 3: 37 wires, 1+6+12+18; 4: 61 wires), ``per_wire``
    elements per wire (length ``per_wire / 24`` lays); layer ``k`` has ``6 k`` wires."""
    import beamsolver as bs
    length = LAY * per_wire / PER_LAY
    sec = bs.Section.circular(radius=WIRE_R, E=2e11)
    m = bs.Model()
    layers = [[m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, length), per_wire), sec, name="core")]]
    for k, nw in ((k, 6 * k) for k in range(1, n_layers + 1)):
        r = 2.0 * WIRE_R * k * TIGHT
        layers.append([m.add_beam(bs.geometry.helix(radius=r, pitch=LAY, length=length, n_elements=per_wire,
                                                    phase=2.0 * np.pi * i / nw), sec, name=f"layer {k} wire {i}")
                       for i in range(nw)])
    opts = dict(mu=mu, gauss_points=gauss_points)
    for k in range(1, n_layers + 1):
        m.add_contact(layers[k], layers[k - 1], **opts)
        nw = len(layers[k])
        r = 2.0 * WIRE_R * k * TIGHT
        if 2.0 * r * np.sin(np.pi / nw) <= 2.0 * WIRE_R * 1.05:      # touching neighbours (5 % tolerance)
            for i in range(nw):
                m.add_contact(layers[k][i], layers[k][(i + 1) % nw], **opts)
    wires = [w for layer in layers for w in layer]
    for w in wires:
        m.clamp(w.first)
    return m, wires


def bundle_per_wire(n):
    return max(3, int(round(n / N_WIRES)))


# ------------------------------------------------------------------ timing helpers
def _best(fn, min_time=0.3, max_repeat=5):
    best, total, k, out = np.inf, 0.0, 0, None
    while (total < min_time or k < 1) and k < max_repeat:
        t0 = clock()
        out = fn()
        dt = clock() - t0
        best, total, k = min(best, dt), total + dt, k + 1
    return best, out


def _median(fn, repeat=7):
    ts, out = [], None
    for _ in range(repeat):
        t0 = clock()
        out = fn()
        ts.append(clock() - t0)
    return float(np.median(ts)), out


def _maxrss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def contact_parts(problem, H, tangent=True):
    """One contact evaluation and its assembly (``System.assemble_blocks``), timed by stage from
    ``ContactSystem.timings`` (CPU time); returns (rc, coo, info, times)."""
    system, c = problem.system, problem.contact
    for k in c.timings:
        c.timings[k] = 0.0
    t0 = clock()
    blocks, info = c.evaluate(H, tangent=tangent)
    rc, coo, _, _ = system.assemble_blocks(H, blocks)
    total = clock() - t0
    t = c.timings
    times = dict(contact_search=t["search"] + t["rules"] + t["projection"], contact_kernels=t["params"] + t["kernel"])
    times["contact_other"] = max(total - times["contact_search"] - times["contact_kernels"], 0.0)
    times["contact_total"] = total
    return rc, coo, info, times


def linear_solvers(K, rhs, out, skip=()):
    """splu, splu-rcm and pardiso on ``K``: factorisation + solve; pardiso also re-factorised (same pattern)."""
    from beamsolver.nonlinear import linsolve
    for b, key in (("splu", "splu"), ("splu-rcm", "splu_rcm")):
        if b in skip:
            out[f"{key}_s"] = out[f"{key}_factor_nnz"] = np.nan
            continue
        t, x = _best(lambda: linsolve.factorize(K, b).solve(rhs), min_time=1.0, max_repeat=3)
        out[f"{key}_s"] = t
        out[f"{key}_factor_nnz"] = linsolve.factorize(K, b).factor_nnz
        out[f"{key}_residual"] = float(np.linalg.norm(K @ x - rhs) / np.linalg.norm(rhs))
        out[f"rss_after_{key}_mb"] = _maxrss_mb()
    if "pardiso" not in linsolve.available():
        out.update(pardiso_first_s=np.nan, pardiso_refactor_s=np.nan, pardiso_factor_nnz=np.nan,
                   pardiso_peak_mb=np.nan)
        return
    s = linsolve.Solver("pardiso")
    t0 = clock()
    f = s.factorize(K)
    x = f.solve(rhs)
    out["pardiso_first_s"] = clock() - t0
    out["pardiso_factor_nnz"] = f.factor_nnz
    out["pardiso_peak_mb"] = f.peak_kb / 1024.0
    K2 = K.copy()
    K2.data *= 1.0 + 1e-3 * np.cos(np.arange(K2.nnz))          # new values, same pattern
    t, _ = _best(lambda: s.factorize(K2).solve(rhs), max_repeat=3)
    out["pardiso_refactor_s"] = t
    out["pardiso_analyses"] = s.stats["analyses"]
    out["pardiso_residual"] = float(np.linalg.norm(K @ x - rhs) / np.linalg.norm(rhs))
    s.close()
    out["rss_after_pardiso_mb"] = _maxrss_mb()


def output_step(sol, system, step):
    from beamsolver.io.vtk import StepWriter
    with tempfile.TemporaryDirectory() as d:
        w = StepWriter(d, system, checkpoint=None)
        t, _ = _best(lambda: w.write(sol, step), min_time=0.2, max_repeat=3)
    return t


def warm_up():
    """Import and first-call costs out of the timings (MKL initialisation, meshio import)."""
    import scipy.sparse as sp

    from beamsolver.nonlinear import linsolve
    K = sp.csc_matrix(sp.eye(50) * 2.0 + sp.eye(50, k=1))
    for b in linsolve.available():
        linsolve.factorize(K, b).solve(np.ones(50))
    import meshio  # noqa: F401


# ------------------------------------------------------------------ one size (child process)
def measure_cable(n, skip=()):
    from beamsolver.results.solution import Solution
    warm_up()
    m, system, H = cable(n)
    lf = system.load_factors(1.0)
    out = dict(scene="cable", n_elements=system.n_elements, n_dofs=system.n_free, rss_setup_mb=_maxrss_mb())
    out["element"], (r, kvals, info) = _best(lambda: system.evaluate(H, lf, tangent=True))
    out["assembly"], K = _best(lambda: system.matrix(kvals))
    out["nnz_per_col"] = K.nnz / K.shape[0]
    rhs = -r[system.free_dofs]
    out["rss_before_solve_mb"] = _maxrss_mb()
    linear_solvers(K, rhs, out, skip)
    out["solve"] = out["splu_s"]
    dz = np.zeros(6 * system.n_nodes)
    from beamsolver.nonlinear import linsolve
    dz[system.free_dofs] = linsolve.factorize(K).solve(rhs)
    dz = dz.reshape(-1, 6)
    out["update"], H1 = _best(lambda: system.update(H, dz))
    out["residual"], _ = _best(lambda: system.evaluate(H1, lf, tangent=False))
    for p in ("contact_search", "contact_kernels", "contact_other"):
        out[p] = 0.0
    sol = Solution(m, system)
    sol.append(0.0, H, system.reactions(H, r), info["state"].sigma, info["state"].strain, dict(iterations=0))
    out["output"] = output_step(sol, system, 0)
    out["commit"] = 0.0
    out["rss_mb"] = _maxrss_mb()
    return out


def replicated_contact(system, wires, per_wire, unit=None):
    """Contact COO of the long bundle from the interior lay of a 1.5-lay one (see module docstring)."""
    import scipy.sparse as sp

    from beamsolver.nonlinear.problem import Problem
    if unit is None:
        um, uw = bundle_model(UNIT)
        up = Problem.from_model(um)
        us = up.system
        cache = os.environ.get("SCALING_UNIT_CACHE")
        if cache and os.path.exists(cache):
            z = np.load(cache)
            coo = (z["rows"], z["cols"], z["vals"])
        else:
            H = us.poses0.copy()
            up.contact.begin_step(H, 0.0)
            _, coo, _, _ = us.assemble_blocks(H, up.contact.evaluate(H, tangent=True)[0])
            coo = (np.ravel(coo[0]), np.ravel(coo[1]), coo[2])
            if cache:
                np.savez(cache, rows=coo[0], cols=coo[1], vals=coo[2])
        unit = (us, uw, coo)
    us, uw, (rows, cols, vals) = unit
    nodes = rows.reshape(-1, 576)[:, ::24][:, ::6] // 6        # (pairs, 4): A1, B1, A2, B2
    wire_of = np.empty(us.n_nodes, dtype=int)
    local = np.empty(us.n_nodes, dtype=int)
    for k, w in enumerate(uw):
        wire_of[w.nodes] = k
        local[w.nodes] = np.arange(len(w.nodes))
    js = local[nodes[:, 0]]
    keep = (js >= UNIT_LO) & (js < UNIT_LO + PER_LAY)
    sel = np.repeat(keep, 576)
    A = sp.coo_matrix((vals[sel], (rows[sel], cols[sel])), shape=(6 * us.n_nodes,) * 2).tocsr().tocoo()
    rn, cn = A.row // 6, A.col // 6
    rw, rj, rk = wire_of[rn], local[rn], A.row % 6
    cw, cj, ck = wire_of[cn], local[cn], A.col % 6
    long_nodes = np.stack([w.nodes for w in wires])             # (wires, per_wire + 1)
    nn = per_wire + 1
    R, C, V = [], [], []
    for s in range(-1, per_wire // PER_LAY + 1):
        a, b = rj + PER_LAY * s, cj + PER_LAY * s
        ok = (a >= 0) & (a < nn) & (b >= 0) & (b < nn)
        if not ok.any():
            continue
        R.append(6 * long_nodes[rw[ok], a[ok]] + rk[ok])
        C.append(6 * long_nodes[cw[ok], b[ok]] + ck[ok])
        V.append(A.data[ok])
    return (np.concatenate(R), np.concatenate(C), np.concatenate(V)), unit


def measure_bundle(n, cap, predicted_contact, skip=()):
    from beamsolver.nonlinear.problem import Problem
    from beamsolver.results.solution import Solution
    warm_up()
    per_wire = bundle_per_wire(n)
    m, wires = bundle_model(per_wire)
    problem = Problem.from_model(m)
    system = problem.system
    H = system.poses0.copy()
    lf = system.load_factors(1.0)
    out = dict(scene="bundle", n_elements=system.n_elements, n_dofs=system.n_free, rss_setup_mb=_maxrss_mb())
    out["element"], (r, kvals, info) = _best(lambda: system.evaluate(H, lf, tangent=True))  # elements alone
    real = n <= cap and predicted_contact <= CONTACT_BUDGET
    out["contact_measured"] = bool(real)
    problem.begin_step(H, 0.0)
    if real:
        rc, coo, cinfo, ct = contact_parts(problem, H)
        out.update(ct)
        out["contact_points"] = int(cinfo.get("n_active", 0))
        out["contact_coo_entries"] = int(len(coo[2]))
        r = r + rc
        # after begin_step: contact keeps its last evaluation for the same poses and state
        out["residual"], _ = _best(lambda: (problem.begin_step(H, 0.0), problem.evaluate(H, 1.0, tangent=False)),
                                   min_time=0.0, max_repeat=1)
    else:
        coo, _ = replicated_contact(system, wires, per_wire)
        for p in ("contact_search", "contact_kernels", "contact_other", "contact_total", "residual"):
            out[p] = np.nan
        out["contact_points"] = -1
        out["contact_coo_entries"] = int(len(coo[2]))      # pre-summed per matrix entry
    extra = coo
    out["assembly"], K = _best(lambda: system.matrix(kvals, extra))
    out["assembly_no_contact"], _ = _best(lambda: system.matrix(kvals, None))
    out["nnz_per_col"] = K.nnz / K.shape[0]
    if real and n == max([s for s in CABLE_SIZES if s <= cap], default=0):
        # the replica against the real contact tangent, at the largest real size
        crep, _ = replicated_contact(system, wires, per_wire)
        Krep = system.matrix(kvals, crep)
        D = (K - Krep).tocsr()
        interior = np.ones(K.shape[0], dtype=bool)
        node_of = system.free_dofs // 6
        loc = np.empty(system.n_nodes, dtype=int)
        for w in wires:
            loc[w.nodes] = np.arange(len(w.nodes))
        interior = (loc[node_of] >= 2) & (loc[node_of] <= per_wire - 2)
        Di = D[interior]
        out["replica_error"] = float(np.sqrt(Di.multiply(Di).sum()) / np.sqrt(K[interior].multiply(K[interior]).sum()))
        out["replica_pattern_nnz"] = f"{Krep.nnz}/{K.nnz}"
    rhs = -r[system.free_dofs]
    out["rss_before_solve_mb"] = _maxrss_mb()
    linear_solvers(K, rhs, out, skip)
    out["solve"] = out["splu_s"]
    rng = np.random.default_rng(1)
    dz = 1e-6 * rng.standard_normal((system.n_nodes, 6))
    out["update"], _ = _best(lambda: problem.update(H, dz))
    sol = Solution(m, system)
    contact_data = None
    if real:
        t0 = clock()
        contact_data = problem.commit(H)
        out["commit"] = clock() - t0
    else:
        out["commit"] = np.nan
    sol.append(0.0, H, system.reactions(H, r), info["state"].sigma, info["state"].strain, dict(iterations=0),
               contact_data)
    out["output"] = output_step(sol, system, 0)
    out["rss_mb"] = _maxrss_mb()
    return out


def measure_pays_nothing(n=10_000):
    """One Newton iteration of ``bs.solve`` on the cable (no contact, no output) vs the sum of its parts
    (called through the public ``problem.Problem``) and the solve's own ``stats["timings"]``."""
    import beamsolver as bs
    from beamsolver.nonlinear import linsolve
    from beamsolver.nonlinear.problem import Problem
    m, system, H = cable(n)
    problem = Problem(system)
    med = _median
    t_eval, ev = med(lambda: problem.evaluate(H, 1.0, tangent=True))
    t_mat, K = med(lambda: problem.tangent(ev))
    rhs = -ev.r[system.free_dofs]
    t_sol, x = med(lambda: linsolve.factorize(K).solve(rhs))
    dz = np.zeros(6 * system.n_nodes)
    dz[system.free_dofs] = x
    t_upd, H1 = med(lambda: problem.update(H, dz.reshape(-1, 6)))
    t_res, _ = med(lambda: problem.evaluate(H1, 1.0, tangent=False))
    stamps = []
    t0 = clock()
    sol = bs.solve(m, steps=1, verbose=False, callback=lambda d: stamps.append(clock()))
    wall = clock() - t0
    it = np.diff(stamps)
    st = sol.stats[-1]
    per_it = {k: v / max(int(st["iterations"]), 1) for k, v in st["timings"].items()}
    mods = sorted(k for k in sys.modules if k.startswith("beamsolver.contact."))
    cs = sys.modules.get("beamsolver.contact.system")
    return dict(n_elements=n, iterations=int(st["iterations"]), solve_wall_s=wall,
                cutbacks=int(st["cutbacks"]), meshio_imported="meshio" in sys.modules,
                iteration_median_s=float(np.median(it)) if len(it) else np.nan,
                parts_sum_s=t_eval + t_mat + t_sol + t_upd + t_res,
                parts=dict(element=t_eval, assembly=t_mat, solve=t_sol, update=t_upd, residual=t_res),
                timings_per_iteration=per_it, contact_system_imported=cs is not None,
                no_contributions=not problem.contributions, modules_loaded=mods)


def child(argv):
    kind = argv[0]
    if kind == "baseline":
        import beamsolver  # noqa: F401
        import scipy.sparse.linalg  # noqa: F401
        warm_up()
        out = dict(rss_mb=_maxrss_mb())
    elif kind == "cable":
        out = measure_cable(int(argv[1]), argv[2].split(","))
    elif kind == "bundle":
        out = measure_bundle(int(argv[1]), int(argv[2]), float(argv[3]), argv[4].split(","))
    elif kind == "nothing":
        out = measure_pays_nothing(int(argv[1]))
    elif kind == "step-parts":
        import step_parts
        out = step_parts.measure(argv[1], argv[2], argv[3], _maxrss_mb)
    elif kind == "scene":
        import scaling_scenes
        out = scaling_scenes.measure_scene(argv[1], _maxrss_mb)
    else:
        raise SystemExit(f"unknown child {kind}")
    print("JSON " + json.dumps(out, default=float))


def run_child(*args, timeout=900, env=None):
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, __file__, "--child", *map(str, args)], capture_output=True, text=True,
                       timeout=timeout, env=None if env is None else {**os.environ, **env})
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("JSON ")]
    if p.returncode != 0 or not lines:
        raise RuntimeError(f"child {args} failed (status {p.returncode}):\n{p.stderr[-3000:]}")
    out = json.loads(lines[-1][5:])
    out["child_wall_s"] = time.perf_counter() - t0
    print(f"  {args[0]} {args[1] if len(args) > 1 else ''}: {out['child_wall_s']:.1f} s", file=sys.stderr, flush=True)
    return out


# ------------------------------------------------------------------ report
def slope(ns, ts, lo=0):
    ns, ts = np.asarray(ns, float), np.asarray(ts, float)
    ok = (ns >= lo) & np.isfinite(ts) & (ts > 0)
    if ok.sum() < 2:
        return np.nan
    return float(np.polyfit(np.log(ns[ok]), np.log(ts[ok]), 1)[0])


def ms(v):
    return "-" if v is None or not np.isfinite(v) else (f"{1e3 * v:.3g}" if v < 10 else f"{1e3 * v:.0f}")


def _fit_rows(rs, base, hi):
    ns = [r["n_elements"] for r in rs]
    fit = [("element", "element"), ("contact search", "contact_search"), ("contact kernels", "contact_kernels"),
           ("contact other", "contact_other"), ("assembly", "assembly"), ("solve splu (default)", "splu_s"),
           ("solve splu-rcm", "splu_rcm_s"), ("solve pardiso refactor", "pardiso_refactor_s"),
           ("update", "update"), ("residual", "residual"), ("iteration, splu", "iteration_splu"),
           ("iteration, best solver", "iteration_best"), ("output / step", "output"),
           ("commit / step", "commit"), ("peak memory above baseline", "rss_mb")]
    out = []
    for name, key in fit:
        ts = [r.get(key, np.nan) for r in rs]
        if key == "rss_mb":
            ts = [max(t - base["rss_mb"], 1e-3) for t in ts]
        a, b = slope(ns, ts), slope(ns, ts, hi)
        if np.isfinite(a) and any(t > 0 for t in ts if np.isfinite(t)):
            out.append([name, f"{a:.2f}", f"{b:.2f}" if np.isfinite(b) else "-"])
    return out


def report(rows, base, nothing, max_elements, cap, wall):
    lines = []
    out = lines.append
    out(f"`python benchmarks/scaling.py {max_elements}` ({machine()}; one thread; whole run {wall:.0f} s). "
        "Cost of one Newton iteration split into its parts, in ms of CPU time (one thread), each part timed "
        "by calling what one Newton iteration calls through `problem.Problem` (best of up to 5 calls); "
        "`output` (one VTU step, refine 8, zlib) and "
        "`commit` (contact history + point table) are per converged step, not per iteration. "
        "`residual` is the line search's residual-only evaluation (contact included). "
        "`iteration` = element + contact + assembly + solve + update + residual. "
        "Peak memory: `ru_maxrss` of the child process that measured the size "
        f"(baseline after imports {base['rss_mb']:.0f} MB).")
    for scene in ("cable", "bundle"):
        rs = [r for r in rows if r["scene"] == scene]
        if not rs:
            continue
        for r in rs:
            parts = [r.get(p, np.nan) for p in PARTS if p != "solve"]
            solvers = [r.get(k, np.nan) for k in ("splu_s", "splu_rcm_s", "pardiso_refactor_s")]
            fin = [t for t in solvers if np.isfinite(t)]
            base_t = float(np.sum(parts)) if np.all(np.isfinite(parts)) else np.nan
            r["iteration_splu"] = base_t + r.get("splu_s", np.nan)
            r["iteration_best"] = base_t + min(fin) if fin else np.nan
        if scene == "cable":
            out("\n**(a) Cable**: one clamped cable (helix, 10 m), dead tip load, deformed state, no contact.\n")
        else:
            real = [r["n_elements"] for r in rs if r["contact_measured"]]
            out(f"\n**(b) Bundle**: 1+6+12 strand of 19 twisted wires (lay 0.1 m, 24 elements per lay, "
                "layers overlapping by 0.5 % of R), 5 Gauss points, mu = 0.3; longer strand for more "
                f"elements. The contact code ran up to {max(real, default=0)} elements (`--bundle-cap {cap}`, "
                f"or a contact evaluation predicted over {CONTACT_BUDGET:.0f} s); above, the contact tangent "
                "is replicated lay by lay (module docstring): contact times are not measured there (`-`) and "
                "`assembly` sees pre-summed contact entries.\n")
        hdr = ["elements", "contact points", "element", "contact search", "contact kernels", "contact other",
               "assembly", "solve splu (default)", "solve splu-rcm", "solve pardiso (refactor)", "update",
               "residual", "iteration, splu", "iteration, best solver", "output / step", "commit / step",
               "peak MB"]
        body = []
        for r in rs:
            cp = r.get("contact_points", 0)
            body.append([r["n_elements"], "-" if cp is None or cp < 0 else cp]
                        + [ms(r.get(k, np.nan)) for k in ("element", "contact_search", "contact_kernels",
                                                          "contact_other", "assembly", "splu_s", "splu_rcm_s",
                                                          "pardiso_refactor_s", "update", "residual",
                                                          "iteration_splu", "iteration_best", "output", "commit")]
                        + [f"{r['rss_mb']:.0f}"])
        out(table(hdr, body))
        hi = 10_000 if scene == "cable" else 1_000
        out(f"\nFitted exponent p of time ~ n^p ({scene}; least squares in log-log over the sizes where the "
            "part was measured):\n")
        out(table(["part", "all sizes", f"n >= {hi}"], _fit_rows(rs, base, hi)))
    # linear solvers
    srows = []
    for r in rows:
        sp_, rcm = r.get("splu_s", np.nan), r.get("splu_rcm_s", np.nan)
        pf, pr = r.get("pardiso_first_s", np.nan), r.get("pardiso_refactor_s", np.nan)

        def ratio(a, b):
            return f"{a / b:.2f}" if np.isfinite(a) and np.isfinite(b) else "-"

        def mnz(k):
            v = r.get(k, np.nan)
            return f"{v / 1e6:.3g}" if v is not None and np.isfinite(v) else "-"
        srows.append([r["scene"], r["n_elements"], r["n_dofs"], f"{r['nnz_per_col']:.0f}", ms(sp_), ms(rcm), ms(pf),
                      ms(pr), ratio(sp_, pf), ratio(sp_, pr), ratio(rcm, pr), mnz("splu_factor_nnz"),
                      mnz("splu_rcm_factor_nnz"), mnz("pardiso_factor_nnz"),
                      f"{r['pardiso_peak_mb']:.0f}" if np.isfinite(r.get("pardiso_peak_mb", np.nan)) else "-"])
    out("\n**Linear solvers on the same matrices** (same run, one thread, ms for factorisation + one solve). "
        "`splu`: scipy SuperLU, MMD_AT_PLUS_A (the default back-end); `splu-rcm`: reverse Cuthill-McKee "
        "pre-ordering + SuperLU, natural column order; `pardiso first`: ordering + symbolic + numeric; "
        "`pardiso refactor`: same pattern, new values, analysis reused (what `linsolve.Solver` does between "
        f"Newton iterations while the contact set is unchanged). `-`: skipped, predicted over {SOLVER_BUDGET:.0f} s "
        "from the smaller sizes. Ratios > 1: pardiso faster.\n")
    out(table(["scene", "elements", "dofs", "nnz/col", "splu", "splu-rcm", "pardiso first", "pardiso refactor",
               "splu / pardiso first", "splu / pardiso refactor", "splu-rcm / pardiso refactor",
               "fill splu (1e6)", "fill splu-rcm (1e6)", "fill pardiso (1e6)", "pardiso peak MB"], srows))
    mrows = []
    for r in rows:
        def mb(k):
            v = r.get(k, np.nan)
            return f"{v:.0f}" if v is not None and np.isfinite(v) else "-"
        coo = r.get("contact_coo_entries", 0)
        mrows.append([r["scene"], r["n_elements"], mb("rss_setup_mb"), mb("rss_before_solve_mb"),
                      mb("rss_after_splu_mb"), mb("rss_after_splu_rcm_mb"), mb("rss_after_pardiso_mb"),
                      mb("rss_mb"), f"{24e-6 * coo:.0f}" if r.get("contact_measured") and coo else "-"])
    out("\n**Peak memory** (MB, `ru_maxrss` of the child process, a running maximum: each column includes the "
        f"previous ones; import baseline {base['rss_mb']:.0f} MB). `contact COO` is the size of the contact "
        "tangent triplets (int64 rows, int64 cols, float64 values: 576 per contact point) handed to "
        "`System.matrix`.\n")
    out(table(["scene", "elements", "model built", "+ element, contact, assembly", "+ splu", "+ splu-rcm",
               "+ pardiso", "+ output (peak)", "contact COO MB"], mrows))
    rep = [r for r in rows if "replica_error" in r]
    if rep:
        r = rep[0]
        out(f"\nReplicated vs real contact tangent at {r['n_elements']} elements (interior rows): relative "
            f"Frobenius difference {r['replica_error']:.2g}, nnz {r['replica_pattern_nnz']} (replica/real).")
    nt = nothing
    out(f"\n**A scene without contact or output pays nothing** (cable, {nt['n_elements']} elements, "
        f"`bs.solve(model, steps=1)`): {nt['iterations']} Newton iterations ({nt['cutbacks']} cut-backs), "
        f"median {ms(nt['iteration_median_s'])} ms per iteration (between `callback` calls) against "
        f"{ms(nt['parts_sum_s'])} ms for the sum of its parts measured alone (medians of 7: element "
        f"{ms(nt['parts']['element'])}, assembly {ms(nt['parts']['assembly'])}, solve {ms(nt['parts']['solve'])}, "
        f"update {ms(nt['parts']['update'])}, residual {ms(nt['parts']['residual'])}); the solve's own "
        f"`stats['timings']` per iteration: assembly {ms(nt['timings_per_iteration']['assembly'])}, linear solve "
        f"{ms(nt['timings_per_iteration']['linear_solve'])}. "
        f"`Problem` without contributions: {nt['no_contributions']}; `beamsolver.contact.system` imported: "
        f"{nt['contact_system_imported']} (modules of `beamsolver.contact` loaded: "
        f"{', '.join(nt['modules_loaded']) or 'none'}; `kinematics` is the public `bs.contact.slip_increment`); "
        f"meshio imported: {nt['meshio_imported']}.")
    return "\n".join(lines)


def _predict(done, key, n):
    """Time of ``key`` at ``n`` elements from the last sizes (local log-log slope, at least 1)."""
    pts = [(r["n_elements"], r.get(key, np.nan)) for r in done]
    pts = [(a, b) for a, b in pts if np.isfinite(b) and b > 0]
    if len(pts) < len(done) and done:      # skipped before: stays skipped
        return np.inf
    if not pts:
        return 0.0
    (n1, t1) = pts[-1]
    p = 1.0
    if len(pts) >= 2:
        n0, t0 = pts[-2]
        p = max(1.0, np.log(t1 / t0) / np.log(n1 / n0))
    return t1 * (n / n1) ** p


def main(argv):
    if argv and argv[0] == "--child":
        return child(argv[1:])
    import argparse
    ap = argparse.ArgumentParser(description="Scaling of one Newton iteration, part by part.")
    ap.add_argument("max_elements", nargs="?", type=float, default=100_000)
    ap.add_argument("--bundle-cap", type=float, default=BUNDLE_CAP,
                    help="largest bundle (elements) run through the contact code")
    ap.add_argument("--scenes", default=None,
                    help="instead: the scenes of issue 30, e.g. 19,37,61,rope-20,rope-40 (scaling_scenes.py)")
    ap.add_argument("--write-docs", action="store_true",
                    help="with --scenes or --step-parts: replace the docs section even if rows of other scenes are "
                         "dropped")
    ap.add_argument("--step-parts", default=None,
                    help="instead: Newton iterations of a loaded step by parts, held pattern off/on, e.g. "
                         "19,37,61,strand-61 (step_parts.py)")
    ap.add_argument("--threads", default="1", help="with --step-parts: PARDISO/MKL threads, e.g. 1,2")
    ap.add_argument("--hold", default="False,True", help="with --step-parts: System.hold_pattern values")
    a = ap.parse_args(argv)
    if a.step_parts:
        return step_parts_rows(a.step_parts.split(","), a.threads.split(","), a.hold.split(","), a.write_docs)
    if a.scenes:
        return scenes(a.scenes.split(","), a.write_docs)
    max_elements, cap = int(a.max_elements), int(a.bundle_cap)
    t_start = time.perf_counter()
    tmp = tempfile.TemporaryDirectory()
    os.environ["SCALING_UNIT_CACHE"] = os.path.join(tmp.name, "unit_contact.npz")
    base = run_child("baseline")
    nothing = run_child("nothing", min(10_000, max_elements))
    rows = []
    for scene in ("cable", "bundle"):
        done = []
        for n in CABLE_SIZES:
            if n > max_elements:
                continue
            ne = n if scene == "cable" else N_WIRES * bundle_per_wire(n)
            skip = ",".join(b for b in ("splu", "splu-rcm") if _predict(done, f"{b.replace('-', '_')}_s", ne)
                            > SOLVER_BUDGET) or "none"
            if scene == "cable":
                r = run_child("cable", n, skip)
            else:
                last = done[-1] if done else None
                predicted = 0.0
                if last is not None:
                    t = last.get("contact_total", np.nan)
                    predicted = t * ne / last["n_elements"] if np.isfinite(t) else np.inf
                r = run_child("bundle", n, cap, predicted, skip)
            rows.append(r)
            done.append(r)
    wall = time.perf_counter() - t_start
    text = report(rows, base, nothing, max_elements, cap, wall)
    print(text)
    write_csv("scaling", rows, cell=_csv)
    write_section("scaling", "## Scaling of a Newton iteration (issue 6)\n\n" + text)
    return rows


def scenes(names, write_docs=False):
    """``--scenes``: one Newton iteration by parts and a loaded step per scene (``scaling_scenes``).  The docs
    section is replaced only if no scene of its table is left out (``_dropped_rows``), or with ``write_docs``."""
    import scaling_scenes
    t_start = time.perf_counter()
    base = run_child("baseline")
    rows = []
    for name in names:
        try:
            rows.append(run_child("scene", name, timeout=3000))
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            rows.append(dict(scene=name, error=str(e).splitlines()[-1][:100] if str(e) else type(e).__name__))
    wall = time.perf_counter() - t_start
    text = (f"`python benchmarks/scaling.py --scenes {','.join(names)}` ({machine()}; one thread; whole run "
            f"{wall:.0f} s). The scenes of issue 30 (`benchmarks/scaling_scenes.py`): one Newton iteration at the "
            "reference poses by parts, CPU s, on the same pattern as the iteration before (`iteration (1st)`: "
            "the first, with the pattern's analysis and the process's first touch of its buffers; `iteration (new "
            "pattern)`: a second `Problem` of the model in the same process); `iteration` = element + contact + "
            "assembly (the Newton system) + solve + update, what `Newton.iterate` pays (an accepted full step is "
            "evaluated once, with its tangent); stick: the scene's (exact: the augmented saddle solve, its "
            "multiplier rows and GMRES iterations); `residual "
            "(trial)`: a residual-only evaluation, what a backtracked line-search trial adds; solver: the default "
            "`linsolve.Solver` (`auto`), a factorisation per iteration; fill: "
            "factor entries; flops of the factorisation (PARDISO's report, or counted from SuperLU's factors); "
            f"loaded step: `bs.solve(steps=1)` stretching by {scaling_scenes.STRAIN:g}, CPU s (Newton "
            f"iterations; `s per iteration, step`: median CPU s between its Newton iterations); peak MB: "
            f"`ru_maxrss` of the child after the two iterations and after the loaded step "
            f"too (import baseline {base['rss_mb']:.0f} MB).\n\n"
            + scaling_scenes.report(rows, base["rss_mb"], table))
    print(text)
    write_csv("scaling_scenes", rows, cell=_csv)
    _replace_section("scaling_scenes", "## Bundles of 19, 37, 61 wires and a rope (issue 30)\n\n" + text, names,
                     write_docs)
    return rows


def _replace_section(section, text, names, write_docs):
    """Replace the docs ``section`` by ``text`` unless the run of ``names`` left out scenes of its table (then it
    is kept and they are named), or with ``write_docs``."""
    dropped = _dropped_rows(names, section)
    if dropped and not write_docs:
        print(f"docs/benchmarks.md: section {section} kept (its rows {', '.join(dropped)} were not run; "
              "--write-docs replaces it)")
    else:
        write_section(section, text)


def _dropped_rows(names, section="scaling_scenes", doc=None):
    """Scenes of the docs section's table that a run of ``names`` would drop, once each, in the table's order."""
    rows = section_rows(section) if doc is None else section_rows(section, doc)
    return list(dict.fromkeys(c for c in rows if c not in names))


def step_parts_rows(names, threads, holds, write_docs=False):
    """``--step-parts``: Newton iterations of a loaded step by parts (``step_parts``), one child per row.  The docs
    section is replaced only if no scene of its table is left out, or with ``write_docs`` (as ``scenes``)."""
    import step_parts
    t_start = time.perf_counter()
    rows = []
    for name in names:
        for th in threads:
            for hold in holds:
                try:
                    rows.append(run_child("step-parts", name, hold, th, timeout=3000,
                                          env=dict(SCALING_THREADS=th)))
                except (RuntimeError, subprocess.TimeoutExpired) as e:
                    rows.append(dict(scene=name, hold=hold, threads=th,
                                     error=str(e).splitlines()[-1][:100] if str(e) else type(e).__name__))
    wall = time.perf_counter() - t_start
    text = (f"`python benchmarks/scaling.py --step-parts {','.join(names)} --threads {','.join(threads)}` "
            f"({machine()}; whole run {wall:.0f} s). Newton iterations of a real loaded step by parts "
            "(`benchmarks/step_parts.py`): CPU s per iteration with one thread; with two threads (PARDISO/MKL) "
            "the parts are wall s (CPU s of both threads in brackets), `total` CPU s, `total wall` wall s; "
            f"load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores.\n\n"
            + step_parts.report(rows, table))
    print(text)
    write_csv("scaling_step_parts", [{k: v for k, v in r.items() if not isinstance(v, dict)} for r in rows],
              cell=_csv)
    _replace_section("scaling_step_parts", "## Newton iterations of a loaded step by parts, held pattern (issue 30)"
                     "\n\n" + text, names, write_docs)
    return rows


def _csv(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v).replace(",", ";")


if __name__ == "__main__":
    main(sys.argv[1:])
