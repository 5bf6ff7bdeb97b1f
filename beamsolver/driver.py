"""``solve()``: check the arguments, build the ``Problem``, pick the stepper and the writers, run.

The Newton loop is ``nonlinear.newton`` (``Newton``, ``Convergence``); the stepping (cut-back,
regrowth, landing on the user's grid, keeping what converged when a run stops) is a stepper of
``stepping.STEPPERS`` (``"load"``: ``stepping.steps.Run``, ``"arc-length"``:
``stepping.arclength.ArcLengthRun``); the output a ``io.writers`` composite.
"""
import logging
from dataclasses import replace

import numpy as np

from .stepping import diagnosis
from .nonlinear import linsolve
from .nonlinear.convergence import Convergence, Verdict
from .nonlinear.newton import MAX_ELEMENT_ROTATION, Newton, angle, largest_element_rotation, relative_rotations
from .stepping import steppers
from .stepping.options import RunOptions
from .errors import InputError
from .nonlinear.jit_warmup import warm_up
from .nonlinear.problem import Problem
from .stepping.restart import restart_from
from .stepping.stabilize import from_option as stabilize_option
from .model.validation import check_solve_arguments, check_stability_options, count, real
from .stepping.stability import nonconservative_parts
from .model.sanity import check_sizes


__all__ = ["solve", "Convergence", "Newton", "Verdict"]

log = logging.getLogger("beamsolver")

MIN_STEP_RATIO = 1e-15               # smallest min_step_ratio: below, t + dt rounds to t
STEP_ROUNDOFF = 1e3                  # steps below this many ulps of |t| are not taken (round-off in t + dt)


def _refine_advice(system, H, t, t_start, t_end):
    """How many elements the beams whose elements turn most would need (rotations taken to grow
    in proportion to the pseudo-time), as a message tail."""
    ang = np.zeros(system.n_elements)
    np.maximum.at(ang, system.pair_element, angle(relative_rotations(system, H)))   # per element
    grow = (t_end - t_start) / (t - t_start) if t > t_start else 1.0
    parts = []
    for b in system.model.beams:
        a = float(ang[b.elements].max())
        if a < 0.5 * MAX_ELEMENT_ROTATION:
            continue
        # strictly below pi/2 (floor + 1, with a margin for round-off: a turn of exactly pi/2 per element
        # is not below it)
        need = int(np.floor(b.n_elements * max(a * grow, MAX_ELEMENT_ROTATION) / (0.5 * np.pi) + 1e-6)) + 1
        parts.append(f"Beam {b.id} ({b.n_elements} elements) turns by {a:.3f} rad per element at "
                     f"t = {t:.6g}: about {need} elements keep it below pi/2 at t = {t_end:.6g}")
    return "".join("; " + p for p in parts)


def _starting_point(restart, model, problem, t_start, t_end):
    """``(solution to continue or None, t_start)``: a restart starts at its first saved time."""
    sol = None
    if restart is not None:
        sol = restart_from(restart, model, problem)
        t_start = float(sol.times[0])
    if not (np.isfinite(t_end) and np.isfinite(t_start) and t_end > t_start):
        raise InputError(f"solve: need t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    return sol, t_start


def solve(model, steps=20, t_end=1.0, output=None, *, t_start=0.0, rtol=1e-8, dtol=1e-11,
          max_iter=30, line_search=True, min_step_ratio=2.0**-12, callback=None,
          check_rigid_modes=True, verbose=None, initial_poses=None, restart=None, checkpoint=60.0,
          linear_solver=None, allow_unmet_tolerance=False, check_stability=None, modes=0,
          branch_switching=False, stabilize=None, path="load", arc_length=None, convergence=None):
    """Quasi-static solve of ``model`` from ``t_start`` to ``t_end`` in ``steps`` equal steps.

    Every converged (sub)step is recorded in the returned ``Solution``.  Step 0 is
    the state at ``t_start``: the reference (or ``initial_poses``) when no load,
    prescribed motion or ``fix`` value acts there, else the equilibrium solved
    there (its Newton statistics in ``stats[0]``).  A step
    that fails is halved down to ``min_step_ratio`` times the user's step, then
    ``ConvergenceError`` is raised with the last converged ``Solution``
    (``.solution``) and the typed reason (``.failure``).  A step over which a
    prescribed rotation turns by more than ``motion_path.MAX_MOTION_ROTATION``
    is shortened first, so motions are followed as continuous paths.

    ``output``: folder for ParaView files and ``solution.npz`` (``None``: no
    output; see ``beamsolver.io.vtk`` and, for the formats, ``beamsolver.io.writers``), the
    latter saved at the end, whenever
    the run stops (also by Ctrl-C or an exception) and every ``checkpoint``
    seconds (0: every step; ``None``: only at the end or stop); or a writer
    object with ``write(solution, step)`` and ``close()`` such as ``io.vtk.StepWriter``.
    Any exception leaving ``solve`` carries the converged steps as ``.solution``.
    ``callback(info)`` is called at every Newton iteration with ``t``,
    ``iteration``, ``residual`` (scaled) and ``poses``.
    ``verbose``: progress bar / lines (see ``progress.Progress``); ``None`` shows a bar on a terminal.
    ``restart``: a ``Solution`` (or the path of a saved one) of this model; the
    run continues from its last step on the grid ``linspace(restart.times[0],
    t_end, steps + 1)`` with its stepping state and contact history, so the
    same arguments give the same final state as a run never interrupted.
    ``linear_solver``: sparse direct solver of the Newton systems, ``"auto"``
    (default: scipy ``"splu"`` for beams and small scenes; for large bundles
    of wires in contact ``"pardiso"`` if pypardiso is installed, ``pip install
    "beamsolver[fast]"``, else ``"splu-rcm"``, scipy after an RCM ordering),
    or one of those by name, or ``"dense"`` (LAPACK's LU of every system made dense: for small systems only,
    less accurate on a slender beam's band; see ``beamsolver.nonlinear.linsolve``).
    ``allow_unmet_tolerance``: accept a step whose contact penetration still
    exceeds ``add_contact(tolerance=)`` after the augmented-Lagrangian updates,
    with a warning in ``stats[k]["warnings"]`` and ``Solution.message``
    (default: a ``ConvergenceError``).
    ``check_stability``: ``None`` (default) or ``True``: every converged step
    (step 0 included) records in ``stats`` whether it is a stable equilibrium,
    ``stable`` (``True``: the symmetric tangent is positive definite, the
    state a strict minimum of the potential energy; ``False``: it has
    negative eigenvalues), ``negative_eigenvalues`` and ``lowest_eigenvalue``
    (scaled; ``None`` where not computed), and the first unstable state of a
    run is warned about (``StabilityWarning``, naming the step, its ``t`` and
    the count; also in ``Solution.message``).  The tangent of the converged
    state is assembled already; a banded Cholesky or sparse LDL^T of it
    (``definiteness.Inertia``) cost 0.5 % of the solve's CPU time on the
    frictionless main job and Argyris' frame, 3.4 % on a 256-element beam
    (2-3 Newton iterations a step), 5.2 % on a frictionless 19-wire strand;
    nothing on frictional scenes (``benchmarks/stability_check.py --scenes``,
    docs/benchmarks.md).  With friction, follower
    loads or a contribution without a potential there is no potential and
    the tangent is unsymmetric: ``stable=None`` and ``stats[k]["stable_note"]``
    says why (``check_stability=True`` there warns once).  With ``stabilize``
    the model's own tangent, without the damping, is checked (the note says
    so).  ``False``: nothing is checked, ``stable=None`` with the note.
    Options that would do nothing together are refused (``InputError``):
    ``modes``/``branch_switching`` with ``check_stability=False`` or without
    a potential, ``branch_switching`` with ``stabilize``
    (``stepping.stability``).
    ``modes``: with it (a count ``k``), the ``k`` lowest eigenpairs of the
    scaled tangent (``modes.lowest_modes``) of every checked step, in
    ``stats[k]["mode_eigenvalues"]`` and ``stats[k]["modes"]`` ``(k, n_nodes, 6)``
    (global displacement and rotation vector per node, unit-free size 1:
    ``bifurcation``); ``Solution.modes(step)``; VTU point fields ``mode_1_u``,
    ``mode_1_rotation``, ...  ``branch_switching``: ``"auto"`` at a step where
    the count of negative eigenvalues went up (a bifurcation or limit point
    crossed; where one step passed several critical loads, the switch is made
    between the first two and recorded as its own step: ``branching.locate``),
    ``True`` at every step with negative eigenvalues, the amplitude along the
    lowest mode is raised from ``bifurcation.AMPLITUDE`` at the same load, the
    other unknowns relaxed, down the energy onto a stable branch
    (``bifurcation.descend``); ``stats[k]["branch_switch"]`` records the mode,
    the crossing, the descent and the counts before and after, and a state
    still unstable after it is warned about.

    ``stabilize``: artificial viscous damping in pseudo-time (Abaqus ``*STATIC, STABILIZE``) to pass
    instabilities under load control: ``True`` (dissipated-energy fraction 2e-4), a fraction, or
    ``dict(fraction=, factor=, warn=)``; the energy it dissipates is recorded per step in
    ``stats[k]["stabilization"]`` and warned about above ``warn`` (``beamsolver.stabilize``).

    ``path``: ``"load"`` (default) steps the pseudo-time on the grid above;
    ``"arc-length"`` follows the equilibrium path by arc length through limit
    points and snap-backs, ``t`` going down as well as up
    (``beamsolver.stepping.arclength``; options ``arc_length``, a dict or
    ``arclength.ArcLength``: ``initial``, ``min``, ``max``,
    ``target_iterations``, ``max_steps``, ``psi``).  Its ``times`` are not
    monotonic; ``stats[k]`` adds ``arc_length``, ``t`` and ``linearised``;
    ``restart``, ``branch_switching`` and ``stabilize`` are refused with it.  Other names: the
    steppers registered in ``beamsolver.stepping.steppers`` (``register``).

    ``convergence``: the stopping rule of the Newton loop as a ``Convergence`` (``rtol``, ``dtol``,
    ``max_iter``, ``divergence``) in place of ``rtol=``, ``dtol=``, ``max_iter=`` (giving both, with
    values other than the defaults, is refused).

    ``Solution.stats[k]["timings"]``: wall time of the step's ``assembly``
    (residuals, tangents, sparse matrices), of each contribution to it (``contact``
    for scenes with contact, part of assembly) and ``linear_solve``
    (factorisations and solves), in seconds.
    """
    conv = _convergence(convergence, rtol, dtol, max_iter)
    check_solve_arguments(model, steps=steps, t_end=t_end, t_start=t_start, rtol=conv.rtol, dtol=conv.dtol,
                          max_iter=conv.max_iter, min_step_ratio=min_step_ratio, checkpoint=checkpoint,
                          initial_poses=initial_poses, restart=restart, callback=callback, output=output)
    stepper = steppers.stepper(path)
    path_options = stepper.path_options(arc_length, restart, branch_switching, stabilize)
    if restart is None:
        check_sizes(model)      # implausible radii or lengths: a GeometryWarning before anything is compiled
    warm_up(model)          # a first run: compile before step 0, in two processes (jit_warmup)
    problem = Problem.from_model(model, check_rigid_modes=check_rigid_modes)
    system = problem.system
    sol, t_start = _starting_point(restart, model, problem, t_start, t_end)
    grid = np.linspace(t_start, t_end, int(steps) + 1)
    dt_min = _step_floor(min_step_ratio, grid)
    newton = Newton(problem, conv, line_search, callback)
    newton.linsolver = linsolve.Solver(linear_solver)
    options = _run_options(problem, t_start, t_end, allow_unmet_tolerance, check_stability, modes,
                           branch_switching, stabilize, problem.failure_hint(), path_options)
    if sol is not None and options.stabilizer is not None:
        options.stabilizer.resume(sol)
    run = None
    try:
        run = stepper(problem, newton, _writer(output, system, checkpoint), grid, dt_min, verbose, options)
        run.start(sol, initial_poses)
        run.loop()
        return run.finish()         # inside: a failure of the output's last files carries .solution too
    except BaseException as e:
        if run is not None:
            run.abort(e)
        raise


def _convergence(convergence, rtol, dtol, max_iter):
    """The ``Convergence`` of ``solve``: a copy of ``convergence`` (its fields checked), else one of
    ``rtol``, ``dtol``, ``max_iter``; both with values other than the defaults: ``InputError``."""
    if convergence is None:
        return Convergence(rtol=rtol, dtol=dtol, max_iter=max_iter)
    if not isinstance(convergence, Convergence):
        raise InputError(f"solve: convergence must be a beamsolver.Convergence or None, got {convergence!r}")
    default = Convergence()
    given = [f"{k}={v!r}" for k, v in (("rtol", rtol), ("dtol", dtol), ("max_iter", max_iter))
             if v != getattr(default, k)]
    if given:
        raise InputError(f"solve: give either convergence= or {', '.join(given)}, not both "
                         f"(convergence={convergence!r})")
    real(convergence.rtol, "convergence.rtol", "solve", above=0.0)
    real(convergence.dtol, "convergence.dtol", "solve", minimum=0.0)
    count(convergence.max_iter, "convergence.max_iter", "solve")
    real(convergence.divergence, "convergence.divergence", "solve", above=0.0)
    return replace(convergence)


def _run_options(problem, t_start, t_end, allow_unmet_tolerance, check_stability, modes, branch_switching,
                 stabilize, penalty_hint="", path_options=None):
    """The ``RunOptions`` of the stepper; a stabilisation joins ``problem``'s contributions;
    ``penalty_hint``: the tail of a ``ConvergenceError`` the contributions give
    (``Problem.failure_hint``: a stiff penalty named), in place of the generic advice;
    ``path_options``: the stepper's own (``Stepper.path_options``)."""
    modes, branch_switching = check_stability_options(modes, branch_switching, check_stability, stabilize,
                                                      nonconservative_parts(problem))
    stabilizer = stabilize_option(problem.system, stabilize, check=problem.conservative)
    if stabilizer is not None:
        problem.contributions.append(stabilizer)
    return RunOptions(advice=_advice(problem, t_start, t_end, penalty_hint), penalty_hint=penalty_hint,
                      allow_unmet_tolerance=allow_unmet_tolerance,
                      check_stability=check_stability, modes=modes,
                      branch_switching=branch_switching, stabilizer=stabilizer, path=path_options)


def _step_floor(min_step_ratio, grid):
    """Smallest step: ``min_step_ratio`` times the user's, raised to ``STEP_ROUNDOFF`` ulps of the
    largest ``|t|`` (shorter steps vanish in round-off).  Only a user's step that is itself not
    representable is refused: a short interval (e.g. bisecting for a critical load) is attempted,
    only its cut-backs are limited."""
    dt_user = grid[1] - grid[0]
    try:
        ratio = float(min_step_ratio)
    except (TypeError, ValueError):
        raise InputError(f"solve: min_step_ratio must be a number in [{MIN_STEP_RATIO:g}, 1], "
                         f"got {min_step_ratio!r}") from None
    if not MIN_STEP_RATIO <= ratio <= 1.0:
        raise InputError(f"solve: min_step_ratio must lie in [{MIN_STEP_RATIO:g}, 1] (smaller steps vanish "
                         f"in round-off), got {min_step_ratio!r}")
    t_max = float(np.abs(grid).max())
    floor = STEP_ROUNDOFF * np.finfo(float).eps * t_max
    if dt_user <= floor:
        raise InputError(f"solve: the step {dt_user:.3g} ((t_end - t_start) / steps) vanishes in round-off at "
                         f"t = {t_max:.6g} (it must exceed {floor:.3g}): use fewer steps or a longer interval")
    return max(dt_user * ratio, floor)


def _writer(output, system, checkpoint):
    if output is None:
        return None
    if hasattr(output, "write"):
        return output                     # e.g. io.vtk.StepWriter(folder, refine=4, compression=None)
    if checkpoint is not None and not (isinstance(checkpoint, (int, float)) and checkpoint >= 0):
        raise InputError(f"solve: checkpoint must be a number of seconds >= 0 or None, got {checkpoint!r}")
    from .io.writers import open_output   # solution.npz (its own writer) and every default format
    return open_output(output, system, checkpoint)


def _advice(problem, t_start, t_end, penalty_hint=""):
    """``advice(failure, rotation_limit, H, t)``: the tail of a ``ConvergenceError`` message
    (``penalty_hint``, if any, in place of the tangent's diagnosis)."""
    system = problem.system

    def advice(failure, rotation_limit, H, t):
        msg = str(failure)
        hint = "" if rotation_limit is None or rotation_limit == msg else \
            f"; a larger step had failed because {rotation_limit}"
        turned = largest_element_rotation(system, H)
        if not hint and turned > 0.75 * MAX_ELEMENT_ROTATION and not failure.rotation:
            hint = (f"; elements already turn by up to {turned:.2f} rad within one element "
                    f"(limit {MAX_ELEMENT_ROTATION:.2f}): refine the mesh")
        if failure.rotation or rotation_limit is not None or turned > 0.75 * MAX_ELEMENT_ROTATION:
            hint += _refine_advice(system, H, t, t_start, t_end)
        if penalty_hint:
            return hint + penalty_hint
        if not hint:
            hint = diagnosis.advice(failure, problem, H, t)
        return hint
    return advice
