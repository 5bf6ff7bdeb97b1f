"""Parameter studies on disk: the points of a grid, their ids, and the study folder (no Dask here).

A grid is a dict of parameter lists (their product, the last name varying
fastest) or an explicit list of dicts.  Each point has an id made of its
parameters (``mu=0.1_lay_angle=8``; a hash ``point-<sha1>`` when a value does
not make a file name), so a rerun finds the results of the same point again.

Study folder (``beamsolver.sweep(..., output=folder)``):

- ``study.json``: the points (id, parameters), the solve options, the version;
- ``summary.csv``: one row per finished point, in grid order; rewritten
  (temporary file + rename) after every point;
- ``<point id>/solution.npz``: the point's ``Solution`` (the converged steps
  of a point stopped by ``ConvergenceError``); ``beams_*.vtu``, ``beams.pvd``
  with ``sweep(..., paraview=True)``;
- ``<point id>/point.json``: the point's row, its solve options and, for an
  unexpected error, the traceback; written last and atomically.  A point is
  *complete* when it has one with a final status (``FINAL``), the same
  parameters and solve options (and ParaView files if asked for): reruns skip it.

Row fields: ``id``, the parameters, ``status`` (``"converged"``, ``"off-equilibrium"``
(the run reached its end, but not in equilibrium: ``Solution.status``),
``"ConvergenceError"``, ``"InputError"``, ``"KilledWorker"`` for a worker that
died twice, or the name of an unexpected exception), ``iterations`` (Newton,
total), ``steps`` (converged steps), ``wall`` (seconds in the worker: build,
solve, save), the summary scalars, ``message``.
"""
import csv
import hashlib
import io
import itertools
import json
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..results.files import follow_umask

__all__ = ["points", "point_id", "point_ids", "FINAL", "RESERVED", "param_names", "table_columns", "write_json",
           "write_summary", "read_point", "is_complete", "is_study", "load_study", "report", "check_names"]

FINAL = ("converged", "off-equilibrium", "ConvergenceError", "InputError")
RESERVED = ("id", "status", "iterations", "steps", "wall", "message")
STUDY, SUMMARY, POINT = "study.json", "summary.csv", "point.json"
_SAFE = re.compile(r"^[A-Za-z0-9.+-]+$")
MAX_ID = 100


def plain(value):
    """``value`` with numpy scalars / arrays turned into Python numbers / lists (for JSON and CSV)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def canonical(obj):
    """JSON text of ``obj`` with sorted keys; values JSON cannot hold are written as their ``repr``."""
    return json.dumps(plain(obj), sort_keys=True, default=repr)


def _check_params(p, where):
    if not isinstance(p, dict) or not p:
        raise InputError(f"sweep: {where} must be a non-empty dict of parameters, got {p!r}")
    for k, v in p.items():
        if not isinstance(k, str) or not k.isidentifier():
            raise InputError(f"sweep: parameter name {k!r} in {where} is not a Python identifier")
        if k in RESERVED:
            raise InputError(f"sweep: parameter name {k!r} in {where} is reserved for a table column")
        try:
            json.dumps(plain(v))
        except (TypeError, ValueError):
            raise InputError(f"sweep: parameter {k}={v!r} in {where} is not a number, string, bool "
                             "or list of them") from None
    return {k: plain(v) for k, v in p.items()}


def points(grid):
    """The points of ``grid`` as a list of parameter dicts, in grid order (validated)."""
    if isinstance(grid, dict):
        if not grid:
            raise InputError("sweep: grid is empty")
        for k, v in grid.items():
            if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or len(v) == 0:
                raise InputError(f"sweep: grid[{k!r}] must be a non-empty list of values, got {v!r}")
        names = list(grid)
        pts = [dict(zip(names, combo)) for combo in itertools.product(*(list(grid[k]) for k in names))]
    elif isinstance(grid, (list, tuple)) and grid:
        pts = list(grid)
    else:
        raise InputError(f"sweep: grid must be a dict of parameter lists or a non-empty list of dicts, "
                         f"got {grid!r}")
    pts = [_check_params(p, f"grid point {i}") for i, p in enumerate(pts)]
    seen = {}
    for i, p in enumerate(pts):
        key = canonical(p)
        if key in seen:
            raise InputError(f"sweep: grid point {i} {p} repeats point {seen[key]}")
        seen[key] = i
    return pts


def _text(v):
    return repr(v) if isinstance(v, float) else str(v)


def point_id(params):
    """Folder name of a point: ``name=value`` joined by ``_``, or ``point-<hash>`` when not file-safe."""
    parts = [(k, _text(v)) for k, v in params.items()]
    slug = "_".join(f"{k}={t}" for k, t in parts)
    if len(slug) <= MAX_ID and all(_SAFE.match(t) for _, t in parts):
        return slug
    return "point-" + hashlib.sha1(canonical(params).encode()).hexdigest()[:12]


def point_ids(pts):
    """``point_id`` of every point; points whose ids would coincide (``1`` and ``"1"``) get their hash."""
    ids = [point_id(p) for p in pts]
    count = {}
    for i in ids:
        count[i] = count.get(i, 0) + 1
    return [i if count[i] == 1 else "point-" + hashlib.sha1(canonical(p).encode()).hexdigest()[:12]
            for i, p in zip(ids, pts)]


def _atomic_text(path, text):
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        follow_umask(fd)
        with os.fdopen(fd, "w", newline="") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_json(path, obj):
    """Write ``obj`` as JSON to ``path`` atomically (temporary file + rename)."""
    _atomic_text(path, json.dumps(plain(obj), indent=1, default=repr, allow_nan=True) + "\n")


def param_names(pts):
    """Parameter names of a list of points, in order of first appearance."""
    return list(dict.fromkeys(k for p in pts for k in p))


def table_columns(rows, names):
    """Column order: id, parameters ``names``, status, iterations, steps, wall, summary scalars, message."""
    fixed = set(RESERVED) | set(names)
    extra = list(dict.fromkeys(k for r in rows for k in r if k not in fixed))
    return ["id"] + list(names) + ["status", "iterations", "steps", "wall"] + extra + ["message"]


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (list, dict)):
        return json.dumps(v)
    return str(v)


def write_summary(folder, rows, names):
    """Atomically write ``folder/summary.csv``: the finished rows (``None`` entries skipped) in order."""
    done = [r for r in rows if r is not None]
    cols = table_columns(done, names)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for r in done:
        w.writerow([_cell(r.get(c)) for c in cols])
    _atomic_text(Path(folder) / SUMMARY, buf.getvalue())
    return Path(folder) / SUMMARY


def read_point(folder, pid):
    """The record of point ``pid`` in ``folder`` (dict with ``row``, ``options``, ...) or ``None``."""
    path = Path(folder) / pid / POINT
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def is_complete(record, params, options, paraview=False):
    """Whether a point record has a final status for the same parameters and solve options (and
    ParaView files when ``paraview``)."""
    if not record or "row" not in record:
        return False
    return (record["row"].get("status") in FINAL and canonical(record.get("params")) == canonical(params)
            and record.get("options") == canonical(options) and (record.get("paraview", False) or not paraview))


def is_study(path):
    """Whether ``path`` is a study folder written by ``sweep``."""
    return Path(path).is_dir() and (Path(path) / STUDY).is_file()


def check_names(function, names, where):
    """Refuse (``InputError``) parameter ``names`` that ``function`` (a scene's build) does not take:
    a misspelled name would fail every point of the grid.  Functions taking ``**kwargs``, or
    without a signature, pass."""
    import inspect
    try:
        params = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return
    if any(p.kind == p.VAR_KEYWORD for p in params.values()):
        return
    takes = [n for n, p in params.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    unknown = [n for n in names if n not in takes]
    if unknown:
        raise InputError(f"sweep: {where} has no parameter {', '.join(map(repr, unknown))} (it takes "
                         f"{', '.join(takes) or 'none'})")


def _study_meta(folder):
    """The checked contents of ``folder/study.json`` (``names``, ``options``, ``points`` of ``id``, ``params``)."""
    try:
        meta = json.loads((folder / STUDY).read_text())
    except (OSError, ValueError) as e:
        raise InputError(f"study {str(folder)!r}: no readable {STUDY} ({e})") from None
    missing = [k for k in ("names", "options", "points") if not isinstance(meta, dict) or k not in meta]
    if missing:
        raise InputError(f"study {str(folder)!r}: {STUDY} is incomplete: no {', '.join(map(repr, missing))} "
                         "(a partial or foreign file; rerun the sweep to rewrite it)")
    bad = [i for i, p in enumerate(meta["points"]) if not (isinstance(p, dict) and "id" in p and "params" in p)]
    if not isinstance(meta["points"], list) or not isinstance(meta["names"], list) or bad:
        raise InputError(f"study {str(folder)!r}: {STUDY} is damaged: 'points' must be a list of "
                         f"{{id, params}} and 'names' a list" + (f" (point {bad[0]} is not)" if bad else ""))
    return meta


def load_study(path):
    """``(meta, rows)`` of a study folder: ``rows[i]`` is the row of point ``i`` or ``None`` (not run)."""
    folder = Path(path)
    meta = _study_meta(folder)
    rows = []
    for p in meta["points"]:
        rec = read_point(folder, str(p["id"]))
        ok = isinstance(rec, dict) and isinstance(rec.get("row"), dict) and "status" in rec["row"] and \
            canonical(rec.get("params")) == canonical(p["params"])
        rows.append(rec["row"] if ok else None)
    return meta, rows


def report(path, all_rows=False):
    """Text summary of a study folder (``beamsolver info study``)."""
    meta, rows = load_study(path)
    n = len(rows)
    counts = {}
    for r in rows:
        s = "not run" if r is None else r["status"]
        counts[s] = counts.get(s, 0) + 1
    lines = [f"{path}: study of {n} points over {', '.join(meta['names'])} "
             f"(solve options {meta['options']}); "
             + ", ".join(f"{v} {k}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1]))]
    done = [r for r in rows if r is not None]
    if done:
        cols = [c for c in table_columns(done, meta["names"]) if c not in ("id", "message")]
        shown = done if all_rows or len(done) <= 30 else done[:15] + [None] + done[-15:]
        cells = [[_short(r.get(c)) for c in cols] if r else ["..."] * len(cols) for r in shown]
        widths = [max([len(c)] + [len(x[j]) for x in cells]) for j, c in enumerate(cols)]
        lines.append("  ".join(c.rjust(w) for c, w in zip(cols, widths)))
        lines += ["  ".join(x.rjust(w) for x, w in zip(row, widths)) for row in cells]
        walls = [r["wall"] for r in done if isinstance(r.get("wall"), (int, float))]
        lines.append(f"wall time in the workers: total {sum(walls):.1f} s, largest {max(walls, default=0):.1f} s")
    for r in done:
        if r["status"] != "converged":
            lines.append(f"{r['id']}: {r['status']}: {r.get('message', '')}")
    lines.append(f"table: {Path(path) / SUMMARY}; per point: {Path(path)}/<id>/solution.npz")
    return "\n".join(lines)


def _short(v):
    if isinstance(v, float):
        return f"{v:.5g}"
    return "" if v is None else str(v)
