"""Stale compiled code: numba's disk cache stamps a function with its own source file only.

A cached function (``cache=True``) is reloaded as long as *its own* source file is unchanged,
even when a compiled function it calls or inlines from another module (``se3_jit`` in
``element_jit``) or a constant it freezes (``contact.pairs.PENALTY_T_MIN`` in ``kernel_jit``)
was edited: after a ``git pull`` or an edit of an editable install it would run the old maths.

``install`` puts locators in front of numba's own whose source stamp is the digest of
everything a compiled module depends on: the module and, transitively, every module of the
package it imports (module level or inside functions).  So

- an edit of a module a compiled function depends on gives a new stamp: numba compiles afresh
  and overwrites the entry;
- an edit elsewhere (a plain-Python module the compiled module does not import) keeps the
  cache;
- the digest is taken once per process, when the module's first function is decorated, i.e.
  for the code this process runs: a process still running old code that saves after the files
  changed stamps its entries with the old digest, which the next process refuses.

The cache stays where numba would put it (``NUMBA_CACHE_DIR``, the in-tree ``__pycache__``,
else the user-wide cache for read-only installs).
"""
import ast
import hashlib
from functools import lru_cache
from pathlib import Path

__all__ = ["dependencies", "digest", "install", "source_digest"]

_ROOTS = set()


def _imports(path, root):
    """Package modules (paths under ``root``) named by the import statements of ``path``."""
    tree = ast.parse(Path(path).read_bytes(), str(path))
    package = root.name
    here = Path(path).resolve().relative_to(root).parent.parts
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[:len(here) - (node.level - 1)] if node.level > 1 else here
                parts = list(base) + (node.module.split(".") if node.module else [])
            elif node.module and (node.module == package or node.module.startswith(package + ".")):
                parts = node.module.split(".")[1:]
            else:
                continue
            out.append(parts)
            out += [parts + [a.name] for a in node.names]          # names that are modules
        elif isinstance(node, ast.Import):
            out += [a.name.split(".")[1:] for a in node.names
                    if a.name == package or a.name.startswith(package + ".")]
    files = []
    for parts in out:
        target = root.joinpath(*parts)
        for cand in (target.with_suffix(".py"), target / "__init__.py"):
            if parts and cand.is_file():
                files.append(cand.resolve())
    return files


def dependencies(path, root):
    """Sorted source files ``path`` depends on: itself and the package modules it imports,
    transitively."""
    root = Path(root).resolve()
    seen, todo = set(), [Path(path).resolve()]
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        todo += [q for q in _imports(p, root) if q not in seen]
    return sorted(seen)


def digest(files, root):
    """SHA-256 of the files' paths relative to ``root`` and contents."""
    h = hashlib.sha256()
    for p in files:
        h.update(str(Path(p).resolve().relative_to(Path(root).resolve())).encode() + b"\0"
                 + Path(p).read_bytes() + b"\0")
    return h.hexdigest()


@lru_cache(maxsize=None)
def source_digest(py_file):
    """Digest of ``py_file`` and its package dependencies, taken once per process."""
    path = Path(py_file).resolve()
    root = _root_of(path)
    return digest(dependencies(path, root), root)


def _root_of(path):
    for r in _ROOTS:
        if r == path or r in path.parents:
            return r
    return None


def _locators():
    from numba.core import caching

    def digest_stamped(base):
        class Locator(base):
            def get_source_stamp(self):
                return source_digest(self._py_file)

            @classmethod
            def from_function(cls, py_func, py_file):
                if _root_of(Path(py_file).resolve()) is None:
                    return None
                return super().from_function(py_func, py_file)
        Locator.__name__ = Locator.__qualname__ = "Digest" + base.__name__
        return Locator
    return [digest_stamped(b) for b in (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                                        caching.UserWideCacheLocator)]


def install(root=Path(__file__).parent):
    """Stamp the cached functions of the modules under ``root`` with their dependency digests
    (idempotent; run by ``_jit`` before any function is compiled)."""
    from numba.core.caching import CacheImpl
    root = Path(root).resolve()
    if root in _ROOTS:
        return
    _ROOTS.add(root)
    if not any(c.__name__.startswith("Digest") for c in CacheImpl._locator_classes):
        CacheImpl._locator_classes[:0] = _locators()
