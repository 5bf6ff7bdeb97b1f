"""Saved results: one ``.npz`` file per ``Solution`` (``Solution.save`` / ``beamsolver.load``).

Format ``beamsolver-solution``, version ``FORMAT_VERSION`` (plain numpy
arrays, readable with ``np.load(path)`` and no pickle):

=====================  ===============================================================
key                    content
=====================  ===============================================================
``format``             ``"beamsolver-solution"``
``format_version``     integer; a reader refuses newer versions
``beamsolver_version`` version that wrote the file
``times``              ``(s,)`` pseudo-times of the ``s`` recorded steps (step 0 = start)
``poses``              ``(s, n, 4, 4)`` node poses
``reactions``          ``(s, n, 6)`` global force and moment on every node
``section_forces``     ``(s, n_el, 6)`` ``N, Q2, Q3, T, M2, M3``
``strains``            ``(s, n_el, 6)`` ``h / L`` per element
``stats``              JSON text: list of per-step dicts (``iterations``, ``residuals``, ...)
``converged``          bool; ``message`` the failure message (str)
``resume``             JSON text: stepping state for ``solve(..., restart=)``
``model/<name>``       ``results.describe_model`` arrays (poses0, enodes, radii, ...)
``contact/<key>``      per-step contact tables, concatenated along axis 0, with
``contact_count/<key>`` ``(s,)`` rows per step (-1: the step has no such key)
``contact_state/<k>``  committed contact history of the last step (restart)
=====================  ===============================================================

Floats are stored in binary (``poses``, ...) or as shortest-repr JSON
(``stats``): a save -> load round trip is exact.
"""
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import InputError

__all__ = ["save", "load", "FORMAT", "FORMAT_VERSION"]

FORMAT = "beamsolver-solution"
FORMAT_VERSION = 1


def _json_default(x):
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.floating):
        return float(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"cannot store {type(x).__name__} in a saved Solution")


def _dumps(obj):
    return np.array(json.dumps(obj, default=_json_default, allow_nan=True))


def _pack_tables(tables, prefix):
    """Per-step dicts of arrays -> concatenated arrays plus per-step row counts."""
    out = {}
    keys = sorted({k for t in tables for k in t})
    for k in keys:
        present = [np.asarray(t[k]) for t in tables if k in t]
        counts = np.array([len(np.asarray(t[k])) if k in t else -1 for t in tables], dtype=np.int64)
        out[f"{prefix}/{k}"] = np.concatenate(present) if present else np.zeros(0)
        out[f"{prefix}_count/{k}"] = counts
    return out


def _unpack_tables(data, prefix, n_steps):
    tables = [dict() for _ in range(n_steps)]
    for name in data.files:
        if not name.startswith(prefix + "/"):
            continue
        k = name[len(prefix) + 1:]
        arr = data[name]
        counts = data[f"{prefix}_count/{k}"]
        pos = 0
        for i, c in enumerate(counts):
            if c >= 0:
                tables[i][k] = arr[pos:pos + c]
                pos += c
    return tables


def save(solution, path):
    """Write ``solution`` to ``path`` (``.npz`` is appended if missing); returns the ``Path``."""
    from .. import __version__
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    s = solution
    arrays = dict(format=np.array(FORMAT), format_version=np.int64(FORMAT_VERSION),
                  beamsolver_version=np.array(__version__),
                  times=np.array(s._times, dtype=float),
                  poses=np.array(s._poses, dtype=float),
                  reactions=np.array(s._reactions, dtype=float),
                  section_forces=np.array(s._sigma, dtype=float),
                  strains=np.array(s._strain, dtype=float),
                  stats=_dumps(s.stats), converged=np.bool_(s.converged),
                  message=np.array(str(s.message)), resume=_dumps(s.resume))
    for k, v in s.description.items():
        arrays[f"model/{k}"] = np.asarray(v)
    arrays.update(_pack_tables(s.contacts, "contact"))
    for k, v in s.contact_state.items():
        arrays[f"contact_state/{k}"] = np.asarray(v)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez_compressed(f, **arrays)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def load(path):
    """Read a ``Solution`` written by ``Solution.save`` (``model`` and ``system`` are ``None``)."""
    from ..results import Solution
    path = Path(path)
    if path.is_dir():
        path = path / "solution.npz"
    if not path.exists() and path.suffix != ".npz" and path.with_name(path.name + ".npz").exists():
        path = path.with_name(path.name + ".npz")
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as e:
        raise InputError(f"load({str(path)!r}): not a readable .npz file ({e})") from None
    with data:
        if "format" not in data.files or str(data["format"]) != FORMAT:
            raise InputError(f"load({str(path)!r}): not a saved beamsolver Solution")
        version = int(data["format_version"])
        if version > FORMAT_VERSION:
            raise InputError(f"load({str(path)!r}): format version {version} is newer than this "
                             f"beamsolver reads ({FORMAT_VERSION}); upgrade beamsolver")
        desc = {k[6:]: data[k] for k in data.files if k.startswith("model/")}
        for k in ("beam_name", "constraint_kind"):
            if k in desc:
                desc[k] = desc[k].astype(str)
        desc["n_contact_declarations"] = np.int64(desc.get("n_contact_declarations", 0))
        sol = Solution(None, None, desc)
        times, poses = data["times"], data["poses"]
        sol._times = [float(t) for t in times]
        sol._poses = list(poses)
        sol._reactions = list(data["reactions"])
        sol._sigma = list(data["section_forces"])
        sol._strain = list(data["strains"])
        sol.stats = json.loads(str(data["stats"]))
        sol.contacts = _unpack_tables(data, "contact", len(times))
        sol.converged = bool(data["converged"])
        sol.message = str(data["message"])
        sol.resume = json.loads(str(data["resume"]))
        sol.contact_state = {k[14:]: data[k] for k in data.files if k.startswith("contact_state/")}
    return sol
