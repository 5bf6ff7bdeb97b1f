"""The ``beamsolver`` command: run a scene script, summarise or render a saved result, export VTK.

``beamsolver run SCRIPT [--output DIR] [--steps N] [--t-end T] [--restart RESULT] [--checkpoint S] [--quiet]``
    Runs ``SCRIPT`` (a Python file) with ``__name__ == "__beamsolver__"`` (its
    ``if __name__ == "__main__":`` block does not run), then takes the scene from
    it, first match wins:

    1. a global ``model`` (a ``beamsolver.Model``);
    2. a function ``build()`` called without arguments, returning a ``Model``
       or a tuple whose first item is one (``model, beam_a, ...``); a ``build``
       with required arguments is refused with a one-line message.

    An optional global dict ``solve_options`` gives keyword arguments of
    ``beamsolver.solve`` (``steps``, ``t_end``, ``rtol``, ...); ``--steps`` and
    ``--t-end`` override it.  Output (VTU/PVD and ``solution.npz``) goes to
    ``DIR`` (default: ``<script name>_run`` in the current directory; not the ``<name>_output`` a script's
    own ``__main__`` writes, e.g. the main job's ``twisted_pair_output``).
    Exit status 0 when every step converged, 2 on ``ConvergenceError`` (the
    converged steps are written), 3 when the run reached its end off equilibrium
    (``Solution.status`` ``"off-equilibrium"``: a stabilised run whose damping still
    carries load; written, with the reason on stderr), 1 on bad input, 130 on Ctrl-C
    (one line; the converged steps are saved, ``--restart DIR`` continues).
``beamsolver info RESULT [--all]``
    ``RESULT``: a ``.npz`` file or an output folder.  Prints steps, Newton
    iterations, wall time, contact force, smallest gap / largest
    penetration per step and the reactions of the constrained nodes; the
    status line says ``converged``, ``STOPPED`` (a ``ConvergenceError``),
    ``OFF-EQUILIBRIUM`` (the final state is not an equilibrium: ``Solution.status``; a stabilised
    run's table shows each step's undamped residual and whether it is an equilibrium) or
    ``stopped at t = ... of ...`` (a checkpoint of a run interrupted).
``beamsolver render RESULT [--step K] -o PNG [--color-by FIELD] [--size W H]``
    Draws the beams as tubes (needs ``beamsolver[viz]``).
``beamsolver export RESULT DIR``
    Writes the VTU/PVD files of a saved result.
``beamsolver sweep SCRIPT --param NAME=V1,V2 ... [-o DIR] [--scheduler ADDRESS]``
    Solves ``build(**params)`` of ``SCRIPT`` over the grid on Dask
    (``beamsolver.app.sweep_cli``); ``beamsolver info DIR`` summarises the study.
"""
import argparse
import inspect
import os
import runpy
import sys
from pathlib import Path

import numpy as np

__all__ = ["main"]


def _check_no_arguments(build, script):
    """Refuse, in one line, a ``build()`` that cannot be called without arguments."""
    try:
        inspect.signature(build).bind()
    except TypeError:
        need = [n for n, p in inspect.signature(build).parameters.items()
                if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
        raise SystemExit(f"beamsolver run: build() in {script} needs arguments ({', '.join(need)}); give them "
                         "defaults, or define a Model named 'model'") from None
    except ValueError:          # no signature (a builtin): let the call decide
        pass


def _scene(script):
    from ..model.model import Model
    ns = runpy.run_path(str(script), run_name="__beamsolver__")
    model = ns.get("model")
    if not isinstance(model, Model):
        build = ns.get("build")
        if not callable(build):
            raise SystemExit(f"beamsolver run: {script} defines neither a Model named 'model' nor a "
                             "function build() returning one")
        _check_no_arguments(build, script)
        out = build()
        model = out[0] if isinstance(out, tuple) and out else out
        if not isinstance(model, Model):
            raise SystemExit(f"beamsolver run: build() in {script} returned {type(out).__name__}, "
                             "not a Model (or a tuple starting with one)")
    return model, _solve_options(ns.get("solve_options"), script)


def _solve_options(opts, script):
    """A script's ``solve_options`` checked: a dict of ``beamsolver.solve``'s keyword arguments."""
    from ..driver import solve
    if opts is None:
        return {}
    if not isinstance(opts, dict):
        raise SystemExit(f"beamsolver run: solve_options in {script} must be a dict, got {type(opts).__name__}")
    known = [n for n in inspect.signature(solve).parameters if n != "model"]
    unknown = [k for k in opts if k not in known]
    if unknown:
        raise SystemExit(f"beamsolver run: solve_options in {script} has {', '.join(map(repr, unknown))}, not "
                         f"an argument of beamsolver.solve (it takes {', '.join(known)})")
    return dict(opts)


def cmd_run(args):
    import beamsolver as bs
    script = Path(args.script)
    if not script.is_file():
        print(f"beamsolver run: no such script {script}", file=sys.stderr)
        return 1
    try:
        model, opts = _scene(script)
    except bs.InputError as e:
        print(f"beamsolver run: {e}", file=sys.stderr)
        return 1
    if args.steps is not None:
        opts["steps"] = args.steps
    if args.t_end is not None:
        opts["t_end"] = args.t_end
    out = Path(args.output) if args.output else Path(f"{script.stem}_run")     # not the script's own <name>_output
    opts["output"] = str(out)
    opts.setdefault("verbose", False if args.quiet else None)
    if args.restart:
        opts["restart"] = args.restart
    if args.checkpoint is not None:
        opts["checkpoint"] = args.checkpoint
    try:
        sol = bs.solve(model, **opts)
    except bs.ConvergenceError as e:
        print(f"beamsolver run: {e}", file=sys.stderr)
        if not args.quiet:
            print(f"converged steps written to {out}/ (beams.pvd, solution.npz)")
        return 2
    except bs.InputError as e:
        print(f"beamsolver run: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as e:
        done = getattr(e, "solution", None)
        at = f" at t = {done.times[-1]:.6g} ({done.n_steps} steps saved)" if done is not None else ""
        print(f"beamsolver run: interrupted{at}; continue with: beamsolver run {script} --output {out} "
              f"--restart {out}", file=sys.stderr)
        return 130
    if not args.quiet:
        print(sol.summary())
        pvd = f"{out}/beams.pvd" + (f", {out}/contact.pvd" if model.contacts else "")
        print(f"written: {pvd} (ParaView), {out}/solution.npz")
    if sol.status == "off-equilibrium":
        print(f"beamsolver run: not an equilibrium: {sol.message}", file=sys.stderr)
        return 3
    return 0


def _row(cells, widths):
    return "  ".join(str(c).rjust(w) for c, w in zip(cells, widths))


def _status(sol):
    """``converged``, ``OFF-EQUILIBRIUM: <why>``, ``STOPPED: <why>`` or, for a run interrupted (Ctrl-C, a kill) after a
    checkpoint, ``stopped at t = ... of ...``."""
    if sol.status == "off-equilibrium":
        return f"OFF-EQUILIBRIUM: {sol.message}"
    if not sol.converged:
        return f"STOPPED: {sol.message}"
    t, t0, t_end = float(sol.times[-1]), float(sol.times[0]), sol.resume.get("t_end")
    if t_end is not None and t < t_end - 1e-9 * abs(t_end - t0):
        return (f"stopped at t = {t:.6g} of {t_end:.6g} (interrupted; `beamsolver run SCRIPT --restart "
                "RESULT` continues it)")
    return "converged"


def cmd_info(args):
    import beamsolver as bs
    from . import study
    if study.is_study(args.result):              # a folder written by `beamsolver sweep` / bs.sweep
        print(study.report(args.result, all_rows=args.all))
        return 0
    sol = bs.load(args.result)
    d = sol.description
    n = len(sol)
    print(f"{args.result}: {len(d['beam_radius'])} beams, {len(d['poses0'])} nodes, {len(d['enodes'])} elements, "
          f"{int(d['n_contact_declarations'])} contact declarations")
    print(f"{sol.summary()}; {_status(sol)}")
    contact = int(d["n_contact_declarations"]) > 0
    head = ["step", "t", "iterations", "residual", "cut-backs", "wall [s]"]
    widths = [5, 10, 10, 9, 9, 9]
    if contact:
        head += ["contacts", "contact force", "min gap"]
        widths += [8, 13, 11]
    checked = any("stable" in s for s in sol.stats)
    if checked:
        head += ["stable", "neg. eig.", "lowest eig.", "switched"]
        widths += [6, 9, 11, 8]
    damped = any("undamped_residual" in s.get("stabilization", {}) for s in sol.stats)
    if damped:
        head += ["undamped", "equilibrium"]
        widths += [9, 11]
    print(_row(head, widths))
    steps = range(n) if args.all or n <= 22 else list(range(10)) + [None] + list(range(n - 10, n))
    for k in steps:
        if k is None:
            print(_row(["..."] * len(head), widths))
            continue
        s = sol.stats[k]
        res = s.get("residuals") or []
        cells = [k, f"{sol.times[k]:.4g}", s.get("iterations", 0), f"{res[-1]:.1e}" if res else "-",
                 s.get("cutbacks", 0), f"{s.get('wall_time', 0.0):.3f}"]
        if contact:
            c = sol.contacts[k]
            gap = np.asarray(c.get("gap", np.zeros(0)))
            fn = np.asarray(c.get("normal_force", np.zeros(0)))
            cells += [int(np.sum(fn > 0)), f"{fn.sum():.4g}", f"{gap.min():.3g}" if len(gap) else "-"]
        if checked:
            cells += _stability_cells(s)
        if damped:
            rec = s.get("stabilization", {})
            ok = rec.get("equilibrium")
            cells += [f"{rec['undamped_residual']:.1e}" if "undamped_residual" in rec else "-",
                      "-" if ok is None else ("yes" if ok else "NO") + (" (settled)" if "settle" in s and ok else "")]
        print(_row(cells, widths))
    gaps = [np.min(c["gap"]) for c in sol.contacts if len(c.get("gap", ()))]
    if gaps:
        print(f"smallest gap over the run {min(gaps):.4g} (largest penetration {max(-min(gaps), 0.0):.4g})")
    nodes, kinds = d["constrained_nodes"], d["constraint_kind"]
    if len(nodes):
        print("reactions at the last step (global force, moment about the node):")
        print(_row(["node", "kind", "Fx", "Fy", "Fz", "Mx", "My", "Mz"], [5, 9] + [11] * 6))
        R = sol.reactions[-1]
        for node, kind in zip(nodes, kinds):
            print(_row([int(node), kind] + [f"{v:.4g}" for v in R[node]], [5, 9] + [11] * 6))
    return 0


def _stability_cells(s):
    """``stable``, negative eigenvalue count, lowest (scaled) eigenvalue and branch switch of a step's
    stats (``solve(check_stability=True, modes=, branch_switching=)``; ``-``: not checked)."""
    stable = {True: "yes", False: "NO", None: "-"}[s.get("stable")]
    lowest = (s.get("mode_eigenvalues") or [s.get("lowest_eigenvalue")])[0]
    switch = s.get("branch_switch")
    switched = "-" if switch is None else ("failed" if "failed" in switch else f"mode {switch['mode']}")
    return [stable, s.get("negative_eigenvalues", "-"), "-" if lowest is None else f"{lowest:.3g}", switched]


def cmd_render(args):
    import beamsolver as bs
    from . import viz
    sol = bs.load(args.result)
    color = None if args.color_by == "none" else args.color_by
    try:
        viz.render(sol, step=args.step, path=args.output, color_by=color, window_size=tuple(args.size),
                   view=args.view, zoom=args.zoom, scale=args.scale)
    except ImportError as e:                         # one line, as `beamsolver sweep` without dask
        print(f"beamsolver render: {e}", file=sys.stderr)
        return 1
    print(f"written: {args.output}")
    return 0


def cmd_export(args):
    import beamsolver as bs
    from ..io import write_vtk
    pvd = write_vtk(bs.load(args.result), args.folder)
    folder = pvd.parent
    written = [p for p in (pvd, folder / "contact.pvd") if p.is_file()]
    n_vtu = len(list(folder.glob("*.vtu")))
    print(f"written: {', '.join(map(str, written))} ({n_vtu} .vtu files in {folder})")
    return 0


def cmd_paraview(args):
    from ..io.paraview import paraview_script, screenshot
    script = paraview_script(args.folder, color_by=args.color_by)
    print(f"written: {script}  (open it with: paraview --script={script})")
    if args.screenshot:
        try:
            print(f"written: {screenshot(script, args.screenshot, step=args.step)}")
        except RuntimeError as exc:                   # ParaView's own failure, its messages inside
            print(f"beamsolver paraview: {exc}", file=sys.stderr)
            return 1
    return 0


def main(argv=None):
    from ..version import __version__
    p = argparse.ArgumentParser(prog="beamsolver", description="Geometrically exact beams with contact.")
    p.add_argument("--version", action="version", version=f"beamsolver {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a scene script (defines `model` or `build()`)")
    r.add_argument("script")
    r.add_argument("--output", "-o", help="output folder (default <script>_run)")
    r.add_argument("--steps", type=int, help="number of pseudo-time steps")
    r.add_argument("--t-end", type=float, help="end of the pseudo-time")
    r.add_argument("--restart", help="continue from a saved result (.npz or output folder)")
    r.add_argument("--checkpoint", type=float, metavar="SECONDS",
                   help="save solution.npz every SECONDS of wall time (0: every step; default 60)")
    r.add_argument("--quiet", "-q", action="store_true", help="no progress bar, no summary")
    r.set_defaults(func=cmd_run)
    i = sub.add_parser("info", help="summary table of a saved result")
    i.add_argument("result")
    i.add_argument("--all", action="store_true", help="every step (default: first and last ten)")
    i.set_defaults(func=cmd_info)
    d = sub.add_parser("render", help="PNG picture of a saved result (needs beamsolver[viz])")
    d.add_argument("result")
    d.add_argument("--step", type=int, default=-1)
    d.add_argument("--output", "-o", required=True, help="PNG file")
    d.add_argument("--color-by", default="displacement",
                   help="displacement, radius, beam_id, N, Q2, Q3, T, M2, M3, strain or none")
    d.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("W", "H"))
    d.add_argument("--view", choices=("auto", "xy", "xz", "yz", "iso"), default="auto",
                   help="direction of view (default: along the normal of a flat scene, else isometric)")
    d.add_argument("--zoom", type=float, default=1.0, help="magnification (> 1 zooms in)")
    d.add_argument("--scale", type=float, nargs=3, metavar=("SX", "SY", "SZ"),
                   help="stretch the drawing along x, y, z (e.g. 1 1 0.02 to see the lay of a long cable)")
    d.set_defaults(func=cmd_render)
    e = sub.add_parser("export", help="write VTU/PVD files of a saved result")
    e.add_argument("result")
    e.add_argument("folder")
    e.set_defaults(func=cmd_export)
    v = sub.add_parser("paraview", help="write OUT/view.py, a ParaView script: smooth tubes at the real radii, "
                                        "contact points coloured by stick/slip, a camera across the scene")
    v.add_argument("folder", help="output folder with beams.pvd")
    v.add_argument("--color-by", choices=("N", "Q2", "Q3", "T", "M2", "M3", "utilisation", "equivalent_strain"),
                   help="field of the tubes (default: utilisation where sections have a yield limit, "
                        "else the largest moment)")
    v.add_argument("--screenshot", metavar="PNG", help="also run it in pvbatch and save this picture")
    v.add_argument("--step", type=int, default=-1, help="step of the screenshot (default: the last)")
    v.set_defaults(func=cmd_paraview)
    from .sweep_cli import add_parser as add_sweep
    add_sweep(sub)
    args = p.parse_args(argv)
    try:
        return args.func(args)
    except (FileNotFoundError, ValueError) as exc:   # InputError is a ValueError
        print(f"beamsolver {args.command}: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:                          # `beamsolver info out | head`
        sys.stdout = open(os.devnull, "w")
        return 0


if __name__ == "__main__":
    sys.exit(main())
