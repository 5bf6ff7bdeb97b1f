"""Parameter sweeps on Dask: ``sweep(scene, grid, ...)`` solves every point of a grid in worker processes.

The engine is ``dask.distributed`` (extra ``[distributed]``), imported only
when a sweep runs: ``import beamsolver`` never imports dask.  By default the
sweep starts a ``LocalCluster`` of one single-threaded worker process per
core (BLAS/OpenMP pools pinned to one thread in the workers), secured by TLS
with credentials made for it (``local_client``: no other process of a shared
machine can connect to its scheduler and run code in its workers), and closes it
at the end; ``client=`` an existing ``Client`` or a scheduler address runs
the same sweep on any Dask cluster (``dask-jobqueue`` on SLURM/PBS,
Kubernetes, ``dask scheduler`` + ``dask worker``).  Results go to the study
folder described in ``beamsolver.app.study`` (a path the workers can write:
a shared file system on a cluster).

Failures do not stop a study: ``run_point`` records ``ConvergenceError``,
``InputError`` and unexpected exceptions in the point's row; a point whose
worker dies (``KilledWorker``) is submitted once more, then recorded.
The local cluster's scheduler sends a worker one task at a time
(``worker-saturation`` 1) and gives up on a task at the first death
(``allowed-failures`` 0), so such a point runs twice in all; a remote
scheduler applies its own ``distributed.scheduler.allowed-failures`` first
(default 3; tasks queued on the dead worker count too unless its
``worker-saturation`` is 1).
"""
import contextlib
import os
import sys
import time
import traceback
import uuid
from pathlib import Path

from . import study
from ..errors import ConvergenceError, InputError

__all__ = ["sweep", "local_client", "run_point"]

BLAS_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
             "NUMEXPR_NUM_THREADS")
BARRED_OPTIONS = ("output", "restart")
NO_WORKERS_TIMEOUT = "120s"


def _model_of(built, where):
    from ..model.model import Model
    model = built[0] if isinstance(built, tuple) and built else built
    if not isinstance(model, Model):
        raise InputError(f"sweep: {where} returned {type(built).__name__}, not a Model "
                         "(or a tuple starting with one)")
    return model, (built if isinstance(built, tuple) else (built,))


def _scalars(values, params):
    """The summary's ``values`` as table cells; a key named like a grid parameter of ``params`` (which
    it would overwrite) or a reserved column, or a value that is not a scalar: ``TypeError``."""
    if not isinstance(values, dict):
        raise TypeError(f"summary must return a dict of scalars, got {type(values).__name__}")
    out = {}
    for k, v in values.items():
        v = study.plain(v)
        if k in params:
            raise TypeError(f"summary: entry {k!r} would overwrite the grid parameter {k!r} "
                            "(give the summary entry another name)")
        if not isinstance(k, str) or k in study.RESERVED or not isinstance(v, (int, float, str, bool)):
            raise TypeError(f"summary: entry {k!r}: {v!r} is not a scalar under a free column name")
        out[k] = v
    return out


class SceneLoadError(RuntimeError):
    """The worker could not unpickle the scene or summary (typically: it cannot import their module)."""


def _load(code):
    import pickle
    try:
        return pickle.loads(code)
    except Exception as e:
        raise SceneLoadError(f"the worker cannot load the scene ({type(e).__name__}: {e}): it must import the "
                             "scene's module (install it, put it on the workers' PYTHONPATH, or use "
                             "client.upload_file)") from e


def run_point(code, params, pid, folder, options, paraview=False):
    """Build, solve and record one point (runs in a worker); returns its row (see ``beamsolver.app.study``).

    ``code``: the pickled pair ``(scene, summary)`` (``pack``), loaded here so that a scene the worker
    cannot import is recorded as the point's failure instead of breaking the worker.
    """
    from ..driver import solve
    t0 = time.perf_counter()
    row = dict(id=pid, **params, status="converged", iterations=0, steps=0, wall=0.0)
    point = Path(folder) / pid if folder is not None else None
    record = dict(params=params, options=study.canonical(options), paraview=bool(paraview))
    sol = built = summary = None
    try:
        scene, summary = _load(code)
        model, built = _model_of(scene(**params), "scene(**params)")
        kw = {"verbose": False, **options}
        sol = solve(model, output=str(point) if paraview and point is not None else None, **kw)
    except ConvergenceError as e:
        row["status"], sol = "ConvergenceError", e.solution
        row["message"] = str(e)
    except Exception as e:          # recorded; the study goes on
        row["status"] = "InputError" if isinstance(e, InputError) else type(e).__name__
        row["message"] = str(e)
        if not isinstance(e, InputError):
            record["traceback"] = traceback.format_exc()
    if sol is not None and row["status"] == "converged" and sol.status == "off-equilibrium":
        row["status"], row["message"] = sol.status, sol.message
    if sol is not None and len(sol):       # a point stopped at t_start has no step to count or save
        row["iterations"], row["steps"] = int(sol.iterations.sum()), int(sol.n_steps)
        if point is not None and not paraview:
            sol.save(point / "solution.npz")
    if row["status"] in ("converged", "off-equilibrium") and summary is not None:
        try:
            row.update(_scalars(summary(sol, *built), params))
        except Exception as e:
            row["status"], row["message"] = type(e).__name__, f"summary: {e}"
            record["traceback"] = traceback.format_exc()
    row.setdefault("message", "")
    row["wall"] = time.perf_counter() - t0
    if point is not None:
        point.mkdir(parents=True, exist_ok=True)
        study.write_json(point / study.POINT, dict(record, row=row))
    return row


def _import_distributed():
    try:
        import distributed
    except ImportError:
        raise ImportError('beamsolver.sweep needs dask.distributed: pip install "beamsolver[distributed]"') \
            from None
    return distributed


def _temporary_security(distributed):
    """Dask's ``Security.temporary()``: a self-signed CA, certificate and key made for this cluster, kept in
    memory (TLS with mutual authentication: only this process and its workers hold them)."""
    try:
        return distributed.security.Security.temporary()
    except ImportError:
        raise ImportError('beamsolver.sweep secures its local Dask cluster with TLS, which needs the '
                          '"cryptography" package: pip install "beamsolver[distributed]" (or local_client(secure='
                          'False) on a machine no one else uses)') from None


def unguarded_main_call(stack=None):
    """``"<script>, line N"`` when the running main script (a file) reaches this call from its module-level
    code outside ``if __name__ == "__main__":`` (the spawned workers of a local cluster import it again and
    would each start a sweep: ~500 lines of Dask tracebacks before any message); else ``""``."""
    import ast
    import inspect
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if not path or not os.path.isfile(path):
        return ""               # interactive, python -c, a notebook: the workers do not import a script
    for frame in stack or inspect.stack(context=0):
        if frame.frame.f_globals is vars(main) and frame.frame.f_code.co_name == "<module>":
            line = frame.frame.f_lineno
            break
    else:
        return ""
    try:
        tree = ast.parse(open(path, encoding="utf-8").read())
    except (OSError, SyntaxError, ValueError):
        return ""
    for node in tree.body:
        if node.lineno <= line <= (node.end_lineno or node.lineno):
            guarded = isinstance(node, ast.If) and "__name__" in ast.unparse(node.test) and \
                "__main__" in ast.unparse(node.test)
            return "" if guarded else f"{os.path.basename(path)}, line {line},"
    return ""


def local_client(n_workers=None, secure=True, **cluster_options):
    """A ``Client`` on a new ``LocalCluster``: ``n_workers`` (default: one per core) single-threaded
    worker processes with one BLAS thread each, on 127.0.0.1; closing the client closes the cluster.

    ``secure``: the scheduler, workers and client talk TLS with credentials made for this cluster
    (``_temporary_security``): another process of the machine cannot connect and run code in the
    workers, which a plain ``tcp://`` scheduler on 127.0.0.1 lets any local user do.  ``False``:
    plain TCP (faster to start and per task: docs/benchmarks.md, ``dask_tls``), for
    a machine no one else uses."""
    import multiprocessing
    if multiprocessing.parent_process() is not None or getattr(multiprocessing.current_process(), "_inheriting", False):
        raise RuntimeError("beamsolver.sweep: a worker process started a sweep: put the code that calls "
                           "sweep under `if __name__ == \"__main__\":` (the workers import the main script)")
    unguarded = unguarded_main_call()
    if unguarded:
        raise RuntimeError(f"beamsolver.sweep: {unguarded} calls sweep outside `if __name__ == \"__main__\":`; "
                           "put it under that guard (the local cluster's workers import the main script, which "
                           "would start a sweep in each of them)")
    distributed = _import_distributed()
    import dask
    opts = dict(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                host="127.0.0.1", dashboard_address="127.0.0.1:0", env={v: "1" for v in BLAS_VARS})
    if secure:
        opts.update(security=_temporary_security(distributed), protocol="tls://")
    opts.update(cluster_options)
    # a worker holds only the task it runs (saturation 1), so a death marks that task alone: KilledWorker at
    # the first death (allowed-failures 0), and _run submits the point once more
    # and tasks fail (recorded) rather than wait forever should every worker be gone for NO_WORKERS_TIMEOUT
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0,
                          "distributed.scheduler.no-workers-timeout": NO_WORKERS_TIMEOUT}):
        try:
            cluster = distributed.LocalCluster(**opts)
        except RuntimeError as e:
            raise RuntimeError(f"beamsolver.sweep: the local Dask cluster did not start ({e}); a script that "
                               "calls sweep must do so under `if __name__ == \"__main__\":`") from e
    client = distributed.Client(cluster)
    client._beamsolver_cluster = cluster       # closed with the client by _engine
    return client


@contextlib.contextmanager
def _engine(client):
    """Yield a ``Client``: a new local one (closed at the end), one on ``client`` (an address), or ``client``."""
    if client is None:
        c = local_client()
    elif isinstance(client, str):
        c = _import_distributed().Client(client)
    elif hasattr(client, "submit") and hasattr(client, "scheduler_info"):
        yield client
        return
    else:
        raise InputError(f"sweep: client must be None, a dask.distributed.Client or a scheduler address, "
                         f"got {client!r}")
    try:
        yield c
    finally:
        cluster = getattr(c, "_beamsolver_cluster", None)
        c.close()
        if cluster is not None:
            cluster.close()


def pack(scene, summary):
    """``(scene, summary)`` pickled by cloudpickle (functions of ``__main__``, closures, lambdas by value)."""
    import cloudpickle
    try:
        return cloudpickle.dumps((scene, summary))
    except Exception as e:
        raise InputError(f"sweep: scene or summary cannot be sent to the workers: {type(e).__name__}: {e}") \
            from None


def _check(scene, summary, solve_options):
    if not callable(scene):
        raise InputError(f"sweep: scene must be callable as scene(**params), got {scene!r}")
    if summary is not None and not callable(summary):
        raise InputError(f"sweep: summary must be callable as summary(solution, *built), got {summary!r}")
    opts = dict(solve_options or {})
    for k in BARRED_OPTIONS:
        if k in opts:
            raise InputError(f"sweep: solve_options may not contain {k!r} (results go to output/<point id>/)")
    import inspect
    from ..driver import solve
    known = inspect.signature(solve).parameters
    for k in opts:
        if k not in known or k == "model":
            raise InputError(f"sweep: solve_options has {k!r}, not an argument of beamsolver.solve")
    return opts


def sweep(scene, grid, *, summary=None, client=None, output=None, solve_options=None, paraview=False,
          verbose=None):
    """Solve ``scene(**params)`` for every point of ``grid`` on Dask; returns the rows in grid order.

    ``scene(**params)`` returns a ``Model`` or a tuple starting with one (as a
    scene script's ``build()``); ``grid``: a dict of parameter lists (their
    product) or a list of dicts; ``summary(solution, *built)`` (optional,
    converged and off-equilibrium points only) returns a dict of scalars to tabulate, ``built`` being
    what ``scene`` returned (as a tuple).  ``client``: ``None`` (a local cluster,
    ``local_client``), a ``dask.distributed.Client`` or a scheduler address
    (``"tcp://host:8786"``).  ``output``: the study folder (``None``: nothing
    written, nothing resumed); points already complete there are not solved
    again.  ``solve_options``: keyword arguments of ``beamsolver.solve``.
    ``paraview``: also write each point's VTU/PVD files.  ``verbose``: progress
    bar over points (``None``: on a terminal; ``False``: silent, and no
    dashboard address).  Scene and summary must pickle (cloudpickle): module
    functions, closures and lambdas do.

    Row: ``id``, the parameters, ``status``, ``iterations``, ``steps``, ``wall``,
    the summary scalars, ``message`` (see ``beamsolver.app.study``).
    """
    pts = study.points(grid)
    opts = _check(scene, summary, solve_options)
    study.check_names(scene, study.param_names(pts), "scene")
    ids = study.point_ids(pts)
    names = study.param_names(pts)
    rows = [None] * len(pts)
    folder = None
    if output is not None:
        folder = Path(output)
        folder.mkdir(parents=True, exist_ok=True)
        from ..version import __version__
        study.write_json(folder / study.STUDY, dict(
            names=names, options=study.canonical(opts), paraview=bool(paraview), beamsolver_version=__version__,
            points=[dict(id=i, params=p) for i, p in zip(ids, pts)]))
        for i, (pid, p) in enumerate(zip(ids, pts)):
            rec = study.read_point(folder, pid)
            if study.is_complete(rec, p, opts, paraview):
                rows[i] = rec["row"]
    todo = [i for i, r in enumerate(rows) if r is None]
    if todo:
        _import_distributed()
        task = dict(code=pack(scene, summary), folder=None if folder is None else str(folder.resolve()),
                    options=opts, paraview=bool(paraview))
        with _engine(client) as c:
            _run(c, task, pts, ids, todo, rows, names, folder, verbose)
    if folder is not None:
        study.write_summary(folder, rows, names)
    return rows


def _run(client, task, pts, ids, todo, rows, names, folder, verbose):
    """Submit the points ``todo``, collect rows as they finish (a dead worker's point once more)."""
    from distributed import as_completed
    from distributed.scheduler import KilledWorker
    tag = uuid.uuid4().hex[:8]

    def submit(i, attempt):
        f = client.submit(run_point, task["code"], pts[i], ids[i], task["folder"],
                          task["options"], task["paraview"], key=f"beamsolver-{ids[i]}-{tag}-{attempt}",
                          pure=False)
        meta[f.key] = (i, attempt, f)
        return f

    meta = {}
    progress = _Progress(verbose, rows, client)
    futures = as_completed([submit(i, 0) for i in todo])
    try:
        for f in futures:
            i, attempt, _ = meta.pop(f.key)
            try:
                row = f.result()
            except KilledWorker as e:
                if attempt == 0:
                    futures.add(submit(i, 1))
                    continue
                row = _engine_failure(folder, ids[i], pts[i], task["options"], "KilledWorker",
                                      f"the worker died twice running this point ({e})")
            except Exception as e:  # the engine's own failures (e.g. no workers left): recorded
                row = _engine_failure(folder, ids[i], pts[i], task["options"], type(e).__name__, str(e))
            rows[i] = row
            if folder is not None:
                study.write_summary(folder, rows, names)
            progress.update(row["status"] == "converged", len(meta))
    finally:
        progress.close()
        if meta:                   # interrupted: the points not finished stay to be resumed
            client.cancel([m[2] for m in meta.values()], force=True)


def _engine_failure(folder, pid, params, options, status, message):
    """Row (and point record) of a point that Dask could not run; such points run again on a rerun."""
    row = dict(id=pid, **params, status=status, iterations=0, steps=0, wall=0.0, message=message)
    if folder is not None:
        (folder / pid).mkdir(exist_ok=True)
        study.write_json(folder / pid / study.POINT, dict(params=params, options=study.canonical(options), row=row))
    return row


class _Progress:
    """tqdm bar over points (done / failed / running), or one line per point with ``verbose=True``."""

    def __init__(self, verbose, rows, client):
        import sys
        tty = sys.stderr.isatty()
        self.bar = None
        self.lines = verbose is True and not tty
        finished = [r for r in rows if r is not None]
        self.done = sum(r["status"] == "converged" for r in finished)
        self.failed, self.total = len(finished) - self.done, len(rows)
        self.slots = max(1, sum(client.nthreads().values()))
        if verbose is False:
            return
        link = _dashboard(client)
        if link:
            print(f"beamsolver sweep: Dask dashboard at {link}", file=sys.stderr)
        if tty:
            from tqdm import tqdm
            self.bar = tqdm(total=self.total, initial=len(finished), desc="sweep", unit="point",
                            dynamic_ncols=True)
            self._postfix(self.total - len(finished))

    def _postfix(self, pending):
        self.bar.set_postfix_str(f"done {self.done}, failed {self.failed}, "
                                 f"running {min(pending, self.slots)}", refresh=False)

    def update(self, ok, pending):
        self.done += ok
        self.failed += not ok
        if self.bar is not None:
            self._postfix(pending)
            self.bar.update(1)
        elif self.lines:
            print(f"sweep: {self.done + self.failed}/{self.total} points, failed {self.failed}")

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def _dashboard(client):
    """The dashboard address of ``client``'s scheduler (``None`` when it serves none), with a note when
    the scheduler runs here without bokeh (it then serves only an "install bokeh" page)."""
    import importlib.util
    try:
        if "dashboard" not in client.scheduler_info().get("services", {}):
            return None
        link = client.dashboard_link
    except Exception:       # a scheduler that does not report its services
        return None
    if getattr(client, "_beamsolver_cluster", None) is not None and importlib.util.find_spec("bokeh") is None:
        link += " (install bokeh>=3.1 to see it)"
    return link
