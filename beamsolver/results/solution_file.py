"""The file format of a saved ``Solution``: one ``.npz`` file (``Solution.save`` / ``beamsolver.load``).

This module knows arrays and dicts, not classes: ``save`` reads a solution's public
fields, ``read`` returns them as a dict that ``results.load`` turns into a ``Solution``
(imports run one way: ``results`` -> ``solution_file``; ``io.archive`` re-exports both).

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
``off_equilibrium``    bool (optional: older files have none, read as False): the run reached its
                       end off equilibrium (``Solution.status`` ``"off-equilibrium"``)
``resume``             JSON text: stepping state for ``solve(..., restart=)``
``model/<name>``       ``results.describe_model`` arrays (poses0, enodes, radii, ...)
``contact/<key>``      per-step contact tables, concatenated along axis 0, with
``contact_count/<key>`` ``(s,)`` rows per step (-1: the step has no such key)
``contact_state/<k>``  committed history of the last step (restart), ``<k>`` = ``name/key`` per
                       contribution (``Problem.get_state``; older archives: contact keys alone)
``extra/<name>``       optional (older files have none): ``Solution.extra[name]``, the
                       per-step values raveled and concatenated, with
``extra_shape/<name>`` ``(s, 1 + d)`` per step: ``ndim`` (-1: no value, -2: a Python
                       number) then the shape padded with 0
=====================  ===============================================================

Before anything is decompressed the archive's members are checked (``check_members``): a
member whose name is not one of the keys above (or under one of their prefixes) is refused,
as is a member whose declared size (the zip directory's ``file_size``) disagrees with its
``.npy`` header, or an archive whose members declare more than ``MAX_PLAIN`` bytes and more
than ``MAX_EXPANSION`` times the file's size (a crafted 3 MB file declaring gigabytes of
zeros: an archive bomb).  Older readers ignored keys they did not know (``extra``,
``off_equilibrium``); version 1 files without them load here unchanged.

Floats are stored in binary (``poses``, ...) or as shortest-repr JSON
(``stats``): a save -> load round trip is exact.
"""
import json
import os
import struct
import tempfile
import zipfile
import zlib
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..errors import InputError
from .files import follow_umask

__all__ = ["save", "read", "saved_times", "check_archive", "check_members", "FORMAT", "FORMAT_VERSION", "MAX_PLAIN",
           "MAX_EXPANSION"]

FORMAT = "beamsolver-solution"
FORMAT_VERSION = 1
NAMES = ("format", "format_version", "beamsolver_version", "times", "poses", "reactions", "section_forces",
         "strains", "stats", "converged", "off_equilibrium", "message", "resume")
PREFIXES = ("model/", "contact/", "contact_count/", "contact_state/", "extra/", "extra_shape/")
MAX_PLAIN = 2**28          # bytes the members may declare in any case (256 MiB)
MAX_EXPANSION = 250.0      # above MAX_PLAIN: at most this times the file's size (saved results: 1.6 with contact,
                           # 81 for 400 steps at rest; a deflate bomb ~1000: benchmarks/archive_expansion.py)
MAX_HEADER = 2**16         # bytes of a member's .npy header (numpy writes 128-4096)


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


def _pack_values(values, name):
    """Per-step values (arrays, numbers or None) -> ``extra/<name>`` and ``extra_shape/<name>``."""
    arrays = [np.asarray(v) for v in values if v is not None]
    d = max([a.ndim for a in arrays], default=0)
    shape = np.zeros((len(values), 1 + d), dtype=np.int64)
    for i, v in enumerate(values):
        a = None if v is None else np.asarray(v)
        shape[i, 0] = -1 if a is None else (-2 if np.ndim(v) == 0 and not isinstance(v, np.ndarray) else a.ndim)
        if a is not None:
            shape[i, 1:1 + a.ndim] = a.shape
    flat = np.concatenate([a.ravel() for a in arrays]) if arrays else np.zeros(0)
    return {f"extra/{name}": flat, f"extra_shape/{name}": shape}


def _unpack_values(data, s):
    """``extra/<name>`` members -> dict name -> list of ``s`` per-step values (``None``: no value)."""
    out = {}
    for key in data:
        if not key.startswith("extra/"):
            continue
        name, flat, shape = key[6:], np.asarray(data[key]), np.asarray(data["extra_shape/" + key[6:]])
        values, pos = [], 0
        for row in shape:
            nd = int(row[0])
            dims = tuple(int(x) for x in row[1:1 + max(nd, 0)])
            size = int(np.prod(dims)) if nd != -1 else 0
            a = flat[pos:pos + size].reshape(dims) if nd != -1 else None
            values.append(None if a is None else (a.item() if nd == -2 else a))
            pos += size
        out[name] = values
    return out


def _unpack_tables(data, prefix, n_steps):
    tables = [dict() for _ in range(n_steps)]
    for name in list(data):
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
    from ..version import __version__
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    s = solution
    arrays = dict(format=np.array(FORMAT), format_version=np.int64(FORMAT_VERSION),
                  beamsolver_version=np.array(__version__),
                  times=np.array(s.times, dtype=float),
                  poses=np.array(s.poses, dtype=float),
                  reactions=np.array(s.reactions, dtype=float),
                  section_forces=np.array(s.section_forces, dtype=float),
                  strains=np.array(s.strains, dtype=float),
                  stats=_dumps(s.stats), converged=np.bool_(s.converged),
                  off_equilibrium=np.bool_(s.off_equilibrium),
                  message=np.array(str(s.message)), resume=_dumps(s.resume))
    for k, v in s.description.items():
        arrays[f"model/{k}"] = np.asarray(v)
    arrays.update(_pack_tables(s.contacts, "contact"))
    for k, v in s.contact_state.items():
        arrays[f"contact_state/{k}"] = np.asarray(v)
    for k, values in s.extra.items():
        arrays.update(_pack_values(values, k))
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        follow_umask(fd)
        with os.fdopen(fd, "wb") as f:
            np.savez_compressed(f, **arrays)
        os.replace(tmp, path)
    except OSError as e:
        raise InputError(f"save({str(path)!r}): cannot write ({e.strerror or e})") from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
    return path


def _resolve(path):
    """The archive a user names: a file, ``<name>`` for ``<name>.npz``, or a folder's solution.npz."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"load: path must be a file or folder name (str or Path), got {path!r}")
    path = Path(path)
    if path.is_dir():
        if not (path / "solution.npz").is_file():
            raise InputError(f"load({str(path)!r}): no solution.npz in the folder (not a beamsolver output "
                             "folder, or the run saved nothing)")
        return path / "solution.npz"
    if not path.exists() and path.suffix != ".npz" and path.with_name(path.name + ".npz").exists():
        return path.with_name(path.name + ".npz")
    if not path.exists():
        raise InputError(f"load({str(path)!r}): no such file")
    return path


@contextmanager
def _open(path):
    """The opened archive (``np.load``) after checking that it is a beamsolver one (else ``InputError``)."""
    where = f"load({str(path)!r})"
    try:
        f = open(path, "rb")
    except OSError as e:
        raise InputError(f"{where}: cannot read ({e.strerror or e})") from None
    with f:
        head = f.read(4)
        if not head:
            raise InputError(f"{where}: the file is empty: not a beamsolver result")
        if head != b"PK\x03\x04":
            raise InputError(f"{where}: not a beamsolver result (not a .npz archive written by Solution.save)")
        f.seek(0)
        check_members(f, where)
        f.seek(0)
        with np.load(f, allow_pickle=False) as data:
            yield data


def _member_bytes(zf, info, where):
    """Bytes of the array a member's ``.npy`` header declares, checked against the member's declared
    size (only the header is decompressed)."""
    with zf.open(info) as fp:
        try:
            version = np.lib.format.read_magic(fp)
            read = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
            if version not in read:
                raise ValueError(f".npy format version {version}")
            shape, _, dtype = read[version](fp, max_header_size=MAX_HEADER)
        except ValueError as e:
            raise InputError(f"{where}: damaged beamsolver result: member {info.filename!r} is not a .npy "
                             f"array ({e})") from None
        header = fp.tell()
    if dtype.hasobject:
        raise InputError(f"{where}: damaged beamsolver result: member {info.filename!r} holds Python objects")
    nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if info.file_size != header + nbytes:
        raise InputError(f"{where}: damaged beamsolver result: member {info.filename!r} declares "
                         f"{info.file_size} bytes, its header {header + nbytes}")
    return nbytes


def _small(zf, name, where):
    """The small member ``name`` (a format key; ``None`` if absent), read after its size is checked."""
    try:
        info = zf.getinfo(name + ".npy")
    except KeyError:
        return None
    if info.file_size > MAX_HEADER:
        raise InputError(f"{where}: not a beamsolver result: member {info.filename!r} declares {info.file_size} bytes")
    with zf.open(info) as fp:
        return np.lib.format.read_array(fp, allow_pickle=False)


def _check_format(zf, where):
    """``format`` and ``format_version`` of an opened zip: a beamsolver result this version reads."""
    fmt = _small(zf, "format", where)
    if fmt is None or fmt.dtype.kind != "U" or str(fmt) != FORMAT:
        raise InputError(f"{where}: not a beamsolver result (an .npz archive, but not a saved "
                         "beamsolver Solution)")
    version = _small(zf, "format_version", where)
    if version is None or version.dtype.kind not in "iu" or version.size != 1:
        raise InputError(f"{where}: damaged beamsolver result: no integer 'format_version'")
    if int(version) > FORMAT_VERSION:
        raise InputError(f"{where}: format version {int(version)} is newer than this beamsolver reads "
                         f"({FORMAT_VERSION}); upgrade beamsolver")


def check_members(f, where):
    """Refuse (``InputError``) an archive (open binary file ``f``) that is not a beamsolver result of a
    version this reader knows, with a member that is not a key of the format, whose declared size disagrees with its header, or whose members declare more than
    ``MAX_PLAIN`` bytes and ``MAX_EXPANSION`` times the file's size; nothing but headers is read."""
    size = f.seek(0, os.SEEK_END)
    f.seek(0)
    with zipfile.ZipFile(f) as zf:
        infos = zf.infolist()
        _check_format(zf, where)
        for info in infos:
            name = info.filename[:-4] if info.filename.endswith(".npy") else None
            if name is None or not (name in NAMES or (name.startswith(PREFIXES) and name not in PREFIXES)):
                raise InputError(f"{where}: not a beamsolver result: unknown member {info.filename!r} (a saved "
                                 "Solution holds only the keys of beamsolver.results.solution_file)")
        declared = sum(info.file_size for info in infos)
        if declared > max(MAX_PLAIN, MAX_EXPANSION * size):
            raise InputError(f"{where}: refused: its members declare {declared / 2**20:.1f} MiB uncompressed, "
                             f"{declared / max(size, 1):.0f} times the file's {size / 2**20:.2f} MiB (limit "
                             f"solution_file.MAX_EXPANSION = {MAX_EXPANSION:g} above MAX_PLAIN = "
                             f"{MAX_PLAIN / 2**20:.0f} MiB): an archive bomb, not a saved result")
        for info in infos:
            _member_bytes(zf, info, where)


def _guarded(path, read):
    """``read(path)``, with any error from a damaged file turned into an ``InputError`` naming it."""
    try:
        return read(path)
    except InputError:
        raise
    except (zipfile.BadZipFile, zlib.error, EOFError, struct.error) as e:
        raise InputError(f"load({str(path)!r}): damaged beamsolver result: truncated or corrupted ({e})") from None
    except (OSError, KeyError, ValueError, TypeError, IndexError) as e:
        raise InputError(f"load({str(path)!r}): damaged beamsolver result ({type(e).__name__}: {e})") from None


def saved_times(path):
    """The ``times`` of a saved solution (only that array is read); ``InputError`` if damaged."""
    path = _resolve(path)

    def read(p):
        with _open(p) as data:
            times = _check_times(data, f"load({str(p)!r})")
        return times
    return _guarded(path, read)


def read(path):
    """The fields of a ``Solution`` written by ``Solution.save``, as a dict (``beamsolver.load`` builds it).

    ``path``: the ``.npz`` file (the suffix may be left out) or an output folder.  A file that
    is not such an archive, or is truncated, corrupted or inconsistent, raises ``InputError``
    naming it and what is wrong (``check_archive``).  Keys: the arguments of
    ``Solution.from_steps``: ``description, times, poses, reactions, section_forces, strains,
    stats, contacts, extra, converged, message, resume, contact_state, off_equilibrium``.
    """
    path = _resolve(path)
    return _guarded(path, _read)


def _read(path):
    with _open(path) as data:
        arrays = check_archive(data, f"load({str(path)!r})")
    desc = {k[6:]: v for k, v in arrays.items() if k.startswith("model/")}
    for k in ("beam_name", "constraint_kind"):
        if k in desc:
            desc[k] = desc[k].astype(str)
    desc["n_contact_declarations"] = np.int64(desc.get("n_contact_declarations", 0))
    times = arrays["times"]
    return dict(description=desc, times=times, poses=arrays["poses"], reactions=arrays["reactions"],
                section_forces=arrays["section_forces"], strains=arrays["strains"], stats=arrays["stats"],
                contacts=_unpack_tables(arrays, "contact", len(times)), extra=_unpack_values(arrays, len(times)),
                converged=bool(arrays["converged"]), off_equilibrium=bool(arrays.get("off_equilibrium", False)),
                message=str(arrays["message"]), resume=arrays["resume"],
                contact_state={k[14:]: v for k, v in arrays.items() if k.startswith("contact_state/")})


MODEL_KEYS = ("poses0", "enodes", "L", "eps0", "element_beam", "node_beam", "beam_first_node", "beam_n_nodes",
              "beam_radius", "beam_C", "beam_name", "constrained_nodes", "constraint_kind", "load_nodes", "joins")
REQUIRED = ("times", "poses", "reactions", "section_forces", "strains", "stats", "converged", "message",
            "resume") + tuple(f"model/{k}" for k in MODEL_KEYS)


def _damaged(where, what):
    return InputError(f"{where}: damaged beamsolver result: {what}")


def _check_times(data, where):
    if "times" not in data:
        raise _damaged(where, "missing 'times'")
    times = np.asarray(data["times"])
    if times.ndim != 1 or times.dtype.kind not in "iuf" or not np.all(np.isfinite(times)):
        raise _damaged(where, f"'times' must be a 1-D array of finite numbers, got shape {times.shape}")
    return times.astype(float)


def _json(arrays, key, kind, where):
    try:
        value = json.loads(str(arrays[key]))
    except json.JSONDecodeError as e:
        raise _damaged(where, f"'{key}' is not valid JSON ({e})") from None
    if not isinstance(value, kind):
        raise _damaged(where, f"'{key}' must hold a JSON {kind.__name__}, got {type(value).__name__}")
    return value


def _shape(arrays, key, expected, where):
    a = np.asarray(arrays[key])
    if a.shape != expected:
        raise _damaged(where, f"'{key}' has shape {a.shape}, expected {expected}")


def check_archive(data, where):
    """All members of an opened archive as a dict, checked for presence and consistency.

    ``stats`` and ``resume`` are returned parsed.  Raises ``InputError`` (``where: damaged
    beamsolver result: ...``) on a missing key, bad JSON or lengths that disagree.
    """
    missing = [k for k in REQUIRED if k not in data.files]
    if missing:
        raise _damaged(where, "missing " + ", ".join(repr(k) for k in missing))
    arrays = {k: data[k] for k in data.files}
    times = _check_times(arrays, where)
    s = len(times)
    if s == 0:
        raise _damaged(where, "no steps (a saved solution holds at least its step 0)")
    n, n_el = len(arrays["model/poses0"]), len(arrays["model/enodes"])
    _shape(arrays, "model/poses0", (n, 4, 4), where)
    _shape(arrays, "model/enodes", (n_el, 2), where)
    if n_el and not (0 <= arrays["model/enodes"].min() and arrays["model/enodes"].max() < n):
        raise _damaged(where, f"'model/enodes' refers to nodes outside 0..{n - 1}")
    poses = arrays["poses"]
    if poses.ndim >= 1 and len(poses) != s:
        raise _damaged(where, f"inconsistent: {s} times but {len(poses)} steps of poses")
    for key, shape in (("poses", (s, n, 4, 4)), ("reactions", (s, n, 6)), ("section_forces", (s, n_el, 6)),
                       ("strains", (s, n_el, 6))):
        _shape(arrays, key, shape, where)
    bad = np.flatnonzero(~np.all(np.isfinite(poses.reshape(s, -1)), axis=1))
    if len(bad):
        raise _damaged(where, f"'poses' is not finite at step {int(bad[0])}")
    arrays["stats"] = _json(arrays, "stats", list, where)
    if len(arrays["stats"]) != s or not all(isinstance(x, dict) for x in arrays["stats"]):
        raise _damaged(where, f"'stats' must be a list of {s} dicts (one per step for {s} steps)")
    arrays["resume"] = _json(arrays, "resume", dict, where)
    for key in [k for k in arrays if k.startswith("contact/")]:
        cname = "contact_count/" + key[len("contact/"):]
        counts = np.asarray(arrays.get(cname, np.zeros(0)))
        if cname not in arrays or counts.shape != (s,):
            raise _damaged(where, f"'{cname}' has {counts.size} entries for {s} steps")
        if counts.dtype.kind not in "iu" or counts[counts >= 0].sum() != len(arrays[key]):
            raise _damaged(where, f"'{key}' has {len(arrays[key])} rows but '{cname}' counts "
                           f"{int(counts[counts >= 0].sum()) if counts.dtype.kind in 'iu' else counts.tolist()}")
    for key in [k for k in arrays if k.startswith("extra/")]:
        sname = "extra_shape/" + key[len("extra/"):]
        shape = np.asarray(arrays.get(sname, np.zeros(0)))
        if shape.ndim != 2 or len(shape) != s or shape.shape[1] < 1 or shape.dtype.kind not in "iu":
            raise _damaged(where, f"'{sname}' must be an integer table with one row per step ({s} steps)")
    return arrays
