"""The scenes of issue 30 for ``benchmarks/scaling.py --scenes``: 19-, 37-, 61-wire bundles and a rope.

Each scene runs in its own child process (``scaling.py --child scene NAME``) and reports:

- the model: elements, unknowns, active contact points, the stick of its frictional contact (``exact``, the
  default, or ``penalty``) and its Newton system (``newton_direction``: ``tangent``; exact stick's ``augmented``
  saddle solve, GMRES on ``A = K' + Kq E Kl``, or ``saddle``, the bordered system factorised directly) with its
  multiplier rows and GMRES iterations;
- one Newton iteration at the reference poses by parts (CPU s): ``element`` (``System.evaluate``),
  ``contact`` (the rest of ``Problem.evaluate``: search, kernels, blocks, their assembly into the
  residual and COO), ``assembly`` (the Newton system: ``Problem.tangent``, CSC; exact stick's condensation and
  ``A``), ``solve`` (the default ``linsolve.Solver`` without lagging: a factorisation of the tangent or of ``A``
  and the solve or GMRES; its back-end, fill and flops, the flops reported by
  PARDISO or counted from SuperLU's factors) and ``update``: their sum is ``iteration``, what
  ``Newton.iterate`` pays per iteration (an accepted full step is evaluated once, with the tangent:
  the next iteration's evaluation); the first iteration (a new pattern: PARDISO's analysis, the maps
  of the tangent, and the process's first touch of its buffers) and a second one on the same pattern (analysis
  reused); ``iteration (new pattern)``: one of a second ``Problem`` of the same model in the same process
  (``new_pattern``: a new pattern, buffers and compiled code warm); ``residual (trial)``: a
  residual-only evaluation, what each backtracked line-search trial adds (not in ``iteration``);
- a loaded step: ``bs.solve(model, steps=1)`` stretching the scene by ``STRAIN`` (every wire end at
  the top moved along ``e_z``, the bottom clamped): Newton iterations, CPU s.  The bundles of
  ``scaling.bundle_model`` overlap by design (0.5 % of R: a pre-stress of ~3e7 N at 19 wires, from
  which one step does not converge), so the step runs on their overlap-free twins
  (``strand_model``: ``build_strand``, same wires, lay and length, core enlarged to close the first
  layer, contact layer on layer as ``examples/seven_wire_strand.py``); the rope is overlap-free by
  construction; at most three halvings of the step (``STEP_FLOOR``), then reported as failed;
  ``s per iteration, step``: the median CPU time between the Newton callbacks of the loaded step
  (the loop's own iterations, line search included);
- peak memory: ``ru_maxrss`` of the child (MB).

``SCALING_NO_STEP=rope-600,...`` (environment): scenes whose loaded step is not run (one iteration only);
``SCALING_NO_NEW=...``: scenes without ``iteration (new pattern)`` (a second ``Problem``: its memory).

The bundles are those of ``scaling.bundle_model`` at ``PER_WIRE`` = 158 elements per wire (the
issue's 3002 / 5846 / 9638 elements).  The rope (``cables.build_rope``): ``ROPE_STRAND`` strands
(1+6+12, wires 0.55 / 0.5 mm) six times around a 1+6+12 wire strand core (0.6 / 0.55 mm), 133
wires, rope lay ``ROPE_LAY``, 48 elements per shortest lay (``ROPE_PER_LAY``): a rope of
``ROPE_FULL`` m has about 1e5 elements, too many for this machine's memory (see the report);
shorter pieces of the same rope are run (``rope-<length in mm>``) and the cost per element
extrapolated (the rope is long and thin: fill, flops and contact points per element settle once the
piece is longer than a few elements, so time and memory grow linearly with the length).
"""
import os
import time

import numpy as np

PER_WIRE = 158
WARM = 24                   # elements per wire of ``warm_contact``'s 7-wire bundle
LAYERS = {"19": 2, "37": 3, "61": 4}
STRAIN = 1e-4               # of the loaded step
STEP_FLOOR = 2.0 ** -3      # of the loaded step: at most three halvings, then reported as not converged
ROPE_LAY = 0.1              # m
ROPE_PER_LAY = 48
ROPE_FULL = 0.6             # m: about 1e5 elements
clock = time.process_time


def rope_model(length):
    import beamsolver as bs
    L = bs.cables.Layer
    core = [L(0.6e-3), L(0.55e-3, 6, lay_length=0.05), L(0.55e-3, 12, lay_length=0.05)]
    strand = [L(0.55e-3), L(0.5e-3, 6, lay_length=0.04, direction="left"),
              L(0.5e-3, 12, lay_length=0.04, direction="left")]
    rope = bs.cables.build_rope(strand, length=length, E=2e11, lay_length=ROPE_LAY, core=core,
                                elements_per_lay=ROPE_PER_LAY, mu=0.3, contact_options=dict(gauss_points=5))
    return rope.model, rope.all_wires, rope


def strand_model(name):
    """The bundle ``name`` without overlaps, for the loaded step: ``build_strand`` of 1+6+12(+18+24)
    wires of the bundle's radius, the bundle's lay and length, layers touching, the core enlarged
    so that the first layer closes (``fit_core``), contact layer on layer only (``touch_tol=-0.5``)."""
    import beamsolver as bs
    from scaling import LAY, PER_LAY, WIRE_R
    L = bs.cables.Layer
    layers = [L(WIRE_R)] + [L(WIRE_R, 6 * k, lay_length=LAY) for k in range(1, LAYERS[name] + 1)]
    st = bs.cables.build_strand(layers, LAY * PER_WIRE / PER_LAY, E=2e11, elements_per_lay=PER_LAY, mu=0.3,
                                contact_options=dict(gauss_points=5), fit_core=True, touch_tol=-0.5)
    st.clamp("bottom")
    return st.model, st.all_wires, st.length


def scene_model(name):
    if name.startswith("rope"):
        length = float(name.split("-")[1]) * 1e-3 if "-" in name else ROPE_FULL
        m, wires, _ = rope_model(length)
        return m, wires, length
    from scaling import LAY, PER_LAY, bundle_model
    m, wires = bundle_model(PER_WIRE, n_layers=LAYERS[name])
    return m, wires, LAY * PER_WIRE / PER_LAY


def _solver_info(f):
    """Back-end, fill and flops of a ``linsolve`` factor."""
    from linear_solvers import lu_flops
    out = dict(backend=getattr(f, "backend", "?"), fill=float(getattr(f, "factor_nnz", np.nan)))
    if out["backend"] == "pardiso":
        out["flops"] = float(getattr(f, "flops", np.nan))
    elif hasattr(f, "_lu"):
        out["flops"] = lu_flops(f._lu.L, f._lu.U)
    return out


def _stick(contact):
    """``exact``, ``penalty`` or ``mixed``: the stick of the scene's frictional contact declarations."""
    if contact is None:
        return "-"
    kinds = {"exact" if d.exact else "penalty" for d in contact.decls if d.mu > 0}
    return kinds.pop() if len(kinds) == 1 else ("mixed" if kinds else "frictionless")


def newton_direction(problem, ev, solver, t):
    """The Newton direction of ``ev`` as ``Newton.direction`` computes it (``INNER_SWITCHES`` = 0): with exact
    stick's multipliers the augmented saddle solve (``Problem.augmented_system``, GMRES preconditioned by a
    factorisation of ``A = K' + Kq E Kl``) or the condensed bordered system factorised directly, else the tangent;
    CPU s into ``t``: ``assembly`` (the Newton system: CSC tangent, condensation, ``A``), ``solve`` (factorisation,
    GMRES or solve, the split of the solution and the multipliers' step).  Returns ``(factor, info)``: ``info``
    the Newton system's ``nnz``, ``system`` (``tangent``, ``augmented`` or ``saddle``), unknowns, multiplier rows,
    GMRES iterations and fallbacks."""
    from beamsolver.nonlinear import linsolve, newton as newton_
    t0 = clock()
    aug = problem.augmented_system(ev) if problem.augments(ev) else None
    if aug is None:
        K, rhs = problem.linear_system(ev)
    elif getattr(newton_, "DROP_BEFORE_SOLVE", False):
        ev.drop_tangent()                       # as ``Newton.direction``: the tangent's values are in K' and A
    t["assembly"] = clock() - t0
    t0 = clock()
    st0 = {k: solver.stats.get(k, 0) for k in ("saddle_iterations", "saddle_fallbacks")}
    if aug is not None:
        x = aug.solve(solver)
        f = aug.factor
        info = dict(system="augmented", nnz=aug.A.nnz, multiplier_rows=len(aug.D))
    else:
        f = linsolve.factorize_tangent(K, solver, saddle=ev.mult is not None)
        x = f.solve(rhs)
        info = dict(system="tangent" if ev.mult is None else "saddle", nnz=K.nnz,
                    multiplier_rows=K.shape[0] - problem.system.n_free)
    if ev.mult is not None:
        dzf, dlam = problem.split_solution(ev, x)
        problem.multiplier_step(ev, dlam)
    t["solve"] = clock() - t0
    info.update(gmres=solver.stats.get("saddle_iterations", 0) - st0["saddle_iterations"],
                fallbacks=solver.stats.get("saddle_fallbacks", 0) - st0["saddle_fallbacks"])
    return f, info


def warm_contact():
    """The process's first-call costs of the contact path (compiled kernels loaded from numba's cache, scipy's and
    PARDISO's first calls) out of the timings: one Newton direction of a small 7-wire bundle (``WARM`` elements a
    wire, 15 % of the 19-wire scene's, with its own patterns), so that ``iteration (1st)`` does not pay their loading
    (it still pays the first touch of the buffers: ``new_pattern``).  Returns ``warm_s``: its CPU s."""
    from beamsolver.nonlinear import linsolve
    from beamsolver.nonlinear.problem import Problem
    from scaling import bundle_model
    t0 = clock()
    m, _ = bundle_model(WARM, n_layers=1)
    problem = Problem.from_model(m)
    H = problem.system.poses0.copy()
    problem.begin_step(H, 0.0)
    ev = problem.evaluate(H, 1.0, tangent=True)
    solver = linsolve.Solver(lagged=False)
    newton_direction(problem, ev, solver, {})
    problem.evaluate(H, 1.0, tangent=False)
    solver.close()
    return dict(warm_s=clock() - t0)


def new_pattern(m, H, solver_kind):
    """One Newton iteration (``it3_*``, CPU s: evaluation with tangent, Newton system, solve) of a second
    ``Problem`` of the model ``m`` at ``H``, with a fresh solver, in the same process: a new pattern (the groups,
    the held tangent pattern and PARDISO's analysis built anew) with the process's compiled code and kept buffers
    warm, what a Newton iteration pays when the contact pattern changes (``iteration (1st)`` also pays the
    process's first touch of its buffers)."""
    from beamsolver.nonlinear.problem import Problem
    problem = Problem.from_model(m)
    solver = solver_kind(lagged=False)
    t = {}
    problem.begin_step(H, 0.0)
    t0 = clock()
    ev = problem.evaluate(H, 1.0, tangent=True)
    t["evaluation"] = clock() - t0
    f, _ = newton_direction(problem, ev, solver, t)
    t["iteration"] = sum(t.values())
    del f, ev
    solver.close()
    return {f"it3_{k}": v for k, v in t.items()}


def measure_scene(name, rss_mb):
    import beamsolver as bs
    from beamsolver.nonlinear import linsolve
    from beamsolver.nonlinear.problem import Problem
    from scaling import warm_up
    warm_up()                                   # MKL's and meshio's first-call costs out of the timings
    out_warm = warm_contact()
    t0 = clock()
    m, wires, length = scene_model(name)
    if name.startswith("rope"):
        for w in wires:                         # (the bundles come clamped)
            m.clamp(w.first)
    problem = Problem.from_model(m)
    system = problem.system
    out = dict(scene=name, build_s=clock() - t0, elements=system.n_elements, unknowns=system.n_free,
               length_m=length, **out_warm)
    H = system.poses0.copy()
    # a factorisation per iteration: the second tangent, at the same poses, equals the first, and a lagged
    # solve (the default ``Solver``'s, preconditioned by the first factor) would take one GMRES iteration, not
    # what a Newton iteration pays; lagged solves over real Newton sequences: ``lagged_solves.py``
    solver = linsolve.Solver(lagged=False)
    c = problem.contact
    out["stick"] = _stick(c)
    for it in (1, 2):
        t = {}
        problem.begin_step(H, 0.0)
        t0 = clock()
        system.evaluate(H, problem.load_factors(1.0), tangent=True)
        t["element"] = clock() - t0
        problem.begin_step(H, 0.0)
        t0 = clock()
        ev = problem.evaluate(H, 1.0, tangent=True)
        t["contact"] = max(clock() - t0 - t["element"], 0.0)
        f, g = newton_direction(problem, ev, solver, t)
        ev.drop_tangent()                       # as ``Newton.iterate`` once the tangent is factorised
        # update and residual timed on a tiny increment (as scaling.py): the full Newton increment of
        # the pre-stressed bundles at the reference poses pushes wires through each other
        dz = 1e-9 * np.random.default_rng(1).standard_normal((system.n_nodes, 6))
        t0 = clock()
        H1 = problem.update(H, dz)
        t["update"] = clock() - t0
        t0 = clock()
        problem.evaluate(H1, 1.0, tangent=False)
        t["residual"] = clock() - t0
        # a Newton iteration: evaluation with tangent, Newton system (assembly), factorisation + solve, update;
        # the residual-only evaluation is a backtracked line-search trial (an accepted full step is evaluated
        # with its tangent, the next iteration's evaluation), not part of every iteration
        t["iteration"] = sum(v for k, v in t.items() if k != "residual")
        out.update({f"it{it}_{k}": v for k, v in t.items()})
        out["contact_points"] = int(ev.details["contact"].get("n_active", -1))
        out["nnz"] = int(g["nnz"])
        out.update({k: v for k, v in g.items() if k != "nnz"})
        out.update(_solver_info(f))
        out[f"rss_it{it}_mb"] = rss_mb()
        del f, ev
    out["analyses"] = solver.stats["analyses"]
    solver.close()
    del problem, system
    if name not in os.environ.get("SCALING_NO_NEW", "").split(","):
        out.update(new_pattern(m, H, solver_kind=linsolve.Solver))
    out["rss_mb"] = rss_mb()
    if name in os.environ.get("SCALING_NO_STEP", "").split(","):
        out.update(step_iterations=0, step_status="not run", step_s=float("nan"), step_it_s=float("nan"))
        return out
    # a loaded step: stretch by STRAIN (the bundles: their overlap-free twins, ``strand_model``)
    if not name.startswith("rope"):
        m, wires, length = strand_model(name)
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, STRAIN * length * t)))
    stamps = []
    t0 = clock()
    try:
        sol = bs.solve(m, steps=1, verbose=False, callback=lambda d: stamps.append((d["t"], clock())),
                       min_step_ratio=STEP_FLOOR)
        st = sol.stats[-1]
        out.update(step_iterations=int(st["iterations"]), step_cutbacks=int(st["cutbacks"]), step_status="ok")
    except Exception as e:                      # noqa: BLE001  (reported, the table goes on)
        out.update(step_iterations=len(stamps), step_status=type(e).__name__)
    out["step_s"] = clock() - t0
    # CPU s per Newton iteration of the loaded step: between the iterations' callbacks of the same t
    gaps = [b[1] - a[1] for a, b in zip(stamps, stamps[1:]) if a[0] == b[0] and a[0] > 0.0]
    out["step_it_s"] = float(np.median(gaps)) if gaps else float("nan")
    out["rss_mb"] = rss_mb()
    return out


def report(rows, base_mb, table):
    """Markdown: the scenes table and the rope's extrapolation to ``ROPE_FULL``."""
    def g(v, f="{:.3g}"):
        return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f.format(v)
    head = ["scene", "elements", "unknowns", "contact points", "stick (Newton system: multiplier rows, GMRES its)",
            "solver", "fill (1e6)", "flops (1e9)",
            "element", "contact", "assembly", "solve", "update", "iteration (1st)", "iteration (new pattern)",
            "iteration",
            "residual (trial)", "loaded step (its)", "s per iteration, step", "peak MB, iteration",
            "peak MB, with the step"]
    body = []
    for r in rows:
        if "error" in r:
            body.append([r["scene"], r["error"]] + ["-"] * (len(head) - 2))
            continue
        sysd = r.get("system", "tangent")
        stick = f"{r.get('stick', '?')} ({sysd}" + (f": {r.get('multiplier_rows', 0)}, {r.get('gmres', 0)}"
                                                    if sysd != "tangent" else "") + ")"
        body.append([r["scene"], r["elements"], r["unknowns"], r["contact_points"], stick, r["backend"],
                     g(r["fill"] / 1e6), g(r.get("flops", np.nan) / 1e9)]
                    + [g(r[f"it2_{k}"]) for k in ("element", "contact", "assembly", "solve", "update")]
                    + [g(r["it1_iteration"]), g(r.get("it3_iteration", np.nan)), g(r["it2_iteration"]),
                       g(r["it2_residual"]),
                       f"{g(r['step_s'])} ({r['step_iterations']}"
                       f"{'' if r['step_status'] == 'ok' else ', ' + r['step_status']})",
                       g(r.get("step_it_s", np.nan)), f"{r['rss_it2_mb']:.0f}", f"{r['rss_mb']:.0f}"])
    lines = [table(head, body)]
    ropes = [r for r in rows if r["scene"].startswith("rope") and "error" not in r]
    if len(ropes) >= 2 and ropes[-1]["length_m"] < ROPE_FULL - 1e-9:     # (else the full rope is in the table)
        n = np.array([r["elements"] for r in ropes], float)
        full = ROPE_FULL / ropes[-1]["length_m"] * n[-1]

        def fit(key, lo=0.0):
            y = np.array([r[key] for r in ropes], float) - lo
            slope = np.polyfit(np.log(n), np.log(np.maximum(y, 1e-9)), 1)[0]
            return y[-1] * (full / n[-1]) ** max(slope, 1.0) + lo, slope
        it, p_it = fit("it2_iteration")
        sv, p_sv = fit("it2_solve")
        mem, p_mem = fit("rss_it2_mb", base_mb)
        pts = ropes[-1]["contact_points"] / n[-1] * full
        fill = ropes[-1]["fill"] / n[-1] * full
        lines.append(
            f"\nThe rope of {ROPE_FULL:g} m ({full:.3g} elements, ~{pts:.2g} contact points), extrapolated from "
            f"the pieces above (log-log slope over them, at least 1): one Newton iteration ~{it:.3g} s "
            f"(slope {p_it:.2f}; of which the linear solve ~{sv:.3g} s, slope {p_sv:.2f}), peak memory of the "
            f"iteration ~{mem / 1024:.3g} GB (slope {p_mem:.2f} above the {base_mb:.0f} MB baseline), fill "
            f"~{fill:.3g} "
            f"factor entries ({12 * fill / 2**30:.3g} GB at 12 bytes each), and the contact tangent's COO "
            f"triplets alone {24 * 576 * pts / 2**30:.3g} GB (576 entries per point, 24 bytes each).")
    return "\n".join(lines)
