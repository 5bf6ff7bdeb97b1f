"""``beamsolver sweep``: a scene script solved over a grid of parameters (``beamsolver.sweep``).

``beamsolver sweep SCRIPT --param NAME=V1,V2,... [--param ...] [-o DIR] [--scheduler ADDRESS]
[--steps N] [--t-end T] [--paraview] [--quiet]``

``SCRIPT`` defines ``build(**params)`` returning a ``Model`` (or a tuple
starting with one), optionally ``summary(solution, *built)`` returning a dict
of scalars and a dict ``solve_options``; it runs with ``__name__ ==
"__beamsolver__"``.  Values are Python literals (``0.1``, ``8``, ``'left'``,
``True``), anything else is taken as a string.  The script's text travels
with every task, so remote workers need no copy of the file (they do need
to write to ``DIR``).  Exit status 0 when every point converged, 2 when some
did not (recorded in ``DIR/summary.csv``), 1 on bad input.
"""
import ast
import sys
from pathlib import Path

from ..errors import InputError

__all__ = ["SceneScript", "parse_param", "add_parser", "cmd_sweep"]


class SceneScript:
    """A scene script for sweeps; pickles as its source text, run once per process on first use."""

    def __init__(self, path):
        self.path = str(path)
        self.source = Path(path).read_text()
        self._ns = None

    def __getstate__(self):
        return {"path": self.path, "source": self.source}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._ns = None

    def namespace(self):
        if self._ns is None:
            ns = {"__name__": "__beamsolver__", "__file__": self.path}
            exec(compile(self.source, self.path, "exec"), ns)
            self._ns = ns
        return self._ns

    def build(self, **params):
        build = self.namespace().get("build")
        if not callable(build):
            raise InputError(f"beamsolver sweep: {self.path} defines no function build(**params)")
        return build(**params)

    def summary(self, solution, *built):
        return self.namespace()["summary"](solution, *built)

    @property
    def has_summary(self):
        return callable(self.namespace().get("summary"))

    @property
    def solve_options(self):
        return dict(self.namespace().get("solve_options") or {})


def _value(text):
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def parse_param(text):
    """``"mu=0.1,0.2"`` -> ``("mu", [0.1, 0.2])``."""
    name, sep, values = text.partition("=")
    name = name.strip()
    if not sep or not name.isidentifier() or not values.strip():
        raise InputError(f"beamsolver sweep: --param {text!r} is not NAME=VALUE[,VALUE...]")
    return name, [_value(v.strip()) for v in values.split(",")]


def add_parser(sub):
    """Add the ``sweep`` subcommand to the ``beamsolver`` command's subparsers."""
    s = sub.add_parser("sweep", help="solve a scene script over a grid of parameters (beamsolver[distributed])")
    s.add_argument("script")
    s.add_argument("--param", "-p", action="append", required=True, metavar="NAME=V1,V2,...",
                   help="a parameter of build() and its values (repeat: the grid is the product)")
    s.add_argument("--output", "-o", help="study folder (default <script>_study)")
    s.add_argument("--scheduler", help="address of a Dask scheduler, tcp://host:8786 (default: a local cluster)")
    s.add_argument("--steps", type=int, help="number of pseudo-time steps")
    s.add_argument("--t-end", type=float, help="end of the pseudo-time")
    s.add_argument("--paraview", action="store_true", help="also write each point's VTU/PVD files")
    s.add_argument("--quiet", "-q", action="store_true", help="no progress bar, no table")
    s.set_defaults(func=cmd_sweep)


def cmd_sweep(args):
    from . import study
    from .sweep_engine import sweep
    script = Path(args.script)
    if not script.is_file():
        print(f"beamsolver sweep: no such script {script}", file=sys.stderr)
        return 1
    scene = SceneScript(script)
    if not callable(scene.namespace().get("build")):
        print(f"beamsolver sweep: {script} defines no function build(**params)", file=sys.stderr)
        return 1
    grid = {}
    for text in args.param:
        name, values = parse_param(text)
        if name in grid:
            raise InputError(f"beamsolver sweep: --param {name} is given twice ({name}={grid[name]} and "
                             f"{text!r}); give all its values in one --param {name}=V1,V2,...")
        grid[name] = values
    study.check_names(scene.namespace()["build"], list(grid), f"build() in {script}")
    opts = scene.solve_options
    if args.steps is not None:
        opts["steps"] = args.steps
    if args.t_end is not None:
        opts["t_end"] = args.t_end
    out = Path(args.output) if args.output else Path(f"{script.stem}_study")
    try:
        rows = sweep(scene.build, grid, summary=scene.summary if scene.has_summary else None,
                     client=args.scheduler, output=out, solve_options=opts, paraview=args.paraview,
                     verbose=False if args.quiet else None)
    except ImportError as e:
        print(f"beamsolver sweep: {e}", file=sys.stderr)
        return 1
    if not args.quiet:
        print(study.report(out))
    return 0 if all(r["status"] == "converged" for r in rows) else 2
