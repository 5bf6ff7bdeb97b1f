"""Stale compiled code: numba's disk cache knows one source file per function, not the package.

A cached function (``cache=True``) is reloaded as long as *its own* source file is unchanged,
even when a compiled function it calls or inlines from another module (``se3_jit`` in
``element_jit``, ``kernel_jit`` in ``projection``) was edited: after a ``git pull`` or an edit
of an editable install it would run the old maths.  ``drop_stale`` keeps a digest of every
compiled module's source next to the cache files and, when it differs, deletes the package's
cache files there (``<module>.*.nbi``/``.nbc``) before anything is loaded; the next call
compiles afresh.  Run once, at the import of ``_jit``; a directory that cannot be written is
left alone (numba then caches elsewhere or not at all).
"""
import hashlib
import os
import re
from pathlib import Path

__all__ = ["compiled_modules", "digest", "drop_stale", "STAMP"]

STAMP = "beamsolver-jit-sources.sha256"      # file name of the digest in each cache directory
_USES_JIT = re.compile(rb"^from \.+_jit import ", re.MULTILINE)


def compiled_modules(root):
    """Sorted source files under ``root`` that import the package's numba decorators."""
    return sorted(p for p in Path(root).rglob("*.py") if _USES_JIT.search(p.read_bytes()))


def digest(files, root):
    """SHA-256 of the files' paths relative to ``root`` and contents."""
    h = hashlib.sha256()
    for p in files:
        h.update(str(p.relative_to(root)).encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def _cache_dir(py_file):
    """The directory numba would cache ``py_file``'s functions in (its own locators), else the
    in-tree ``__pycache__``."""
    try:
        from numba.core.caching import CacheImpl
        for cls in CacheImpl._locator_classes:
            loc = cls.from_function(_cache_dir, str(py_file))
            if loc is not None:
                return Path(loc.get_cache_path())
    except Exception:        # numba's internals moved: the in-tree default
        pass
    return Path(py_file).parent / "__pycache__"


def drop_stale(root=Path(__file__).parent):
    """Delete the cache files of ``root``'s compiled modules wherever their digest is not the
    current one; returns the number of files deleted."""
    files = compiled_modules(root)
    if not files:
        return 0
    current = digest(files, root)
    dirs = {}
    for p in files:
        dirs.setdefault(_cache_dir(p), []).append(p.stem)
    deleted = 0
    for d, stems in dirs.items():
        stamp = d / STAMP
        try:
            if stamp.is_file() and stamp.read_text() == current:
                continue
            for stem in stems:
                for f in list(d.glob(f"{stem}.*.nbi")) + list(d.glob(f"{stem}.*.nbc")):
                    f.unlink(missing_ok=True)
                    deleted += 1
            d.mkdir(parents=True, exist_ok=True)
            tmp = d / f"{STAMP}.{os.getpid()}"
            tmp.write_text(current)
            os.replace(tmp, stamp)        # atomic: a concurrent import reads the old or the new
        except OSError:                   # read-only install: numba's own locator copes
            continue
    return deleted
