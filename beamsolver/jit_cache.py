"""Stale compiled code: numba's disk cache stamps a function with its own source file only.

A cached function (``cache=True``) is reloaded as long as *its own* source file is unchanged,
even when a compiled function it calls or inlines from another module (``se3_jit`` in
``element_jit``) or a constant it freezes (``law.PENALTY_T_MIN`` in ``kernel_jit``) was edited:
after a ``git pull`` or an edit of an editable install it would run the old maths.  And it is
compiled again after any edit of its file that moves its first line.

``install`` puts locators in front of numba's own whose source stamp is the digest of exactly
the code a compiled function depends on (``dependencies``): the function's own statement
(decorators included) and, transitively, every top-level statement of the package that it names
(functions it calls or inlines, constants it freezes, the decorator's options), followed across
``from .x import y`` and ``module.name``.  Statements are read with ``ast`` (nothing is run), and a
name is resolved wherever it is used in the statement (a local variable that shadows a global
only adds a dependency).  So

- an edit of anything a compiled function names, however deep, gives a new stamp: numba
  compiles afresh and overwrites the entry (statements are compared as syntax trees, so comments,
  docstrings and layout do not count);
- an edit elsewhere (another function of the same module, a plain-Python module) keeps the
  cache: the entry's file name carries the function's name and its rank among the same-named
  definitions of the file instead of numba's line number;
- the sources are read once per process, at the first decoration that needs them, i.e. for the
  code this process runs: a process still running old code that saves after the files changed
  stamps its entries with the old digest, which the next process refuses.

Walking the syntax trees costs ~0.2 s of CPU per process (172 functions at ``import beamsolver``),
so the digests are kept between processes (``_Store``): one file beside the numba cache
(``jit_digests.<package>.json``), valid for the exact sources it was computed from (keyed by the
SHA-256 of every source file of the package, read once, the same texts the digests are computed
from); any edit computes them again.

A function made from another's code object (``kernel_jit.make_kernel``'s per-law kernels) is
stamped by the statement its code comes from.  The cache stays where numba would put it
(``NUMBA_CACHE_DIR``, the in-tree ``__pycache__``, else the user-wide cache for read-only installs).
"""
import ast
import atexit
import hashlib
import json
import os
from functools import lru_cache
from pathlib import Path

__all__ = ["dependencies", "digest", "install", "function_digest", "forget"]

_ROOTS = set()


class _Module:
    """Top-level statements of one source file: what each name is bound to."""

    def __init__(self, path, root):
        self.path = path
        self.rel = path.relative_to(root).as_posix()
        self.text = _store(root).texts.get(path)
        if self.text is None:
            self.text = path.read_text()
        tree = ast.parse(self.text, str(path))
        self.defs = {}          # name -> [statement], in file order
        self.imports = {}       # name -> (module path, attribute or None for the module itself)
        self.functions = {}     # function name -> [(first line, statement)] of every def of that name
        self._dumps, self._refs = {}, {}
        here = path.relative_to(root).parent.parts
        for node in tree.body:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                self._bind_import(node, here, root)
                continue
            for name in _bound(node):
                self.defs.setdefault(name, []).append(node)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([node.lineno] + [d.lineno for d in node.decorator_list])
                self.functions.setdefault(node.name, []).append((first, node))

    def _bind_import(self, node, here, root):
        package = root.name
        for a in node.names:
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = here[:len(here) - (node.level - 1)] if node.level > 1 else here
                    parts = list(base) + (node.module.split(".") if node.module else [])
                elif node.module and (node.module == package or node.module.startswith(package + ".")):
                    parts = node.module.split(".")[1:]
                else:
                    continue
                sub = _file(root, parts + [a.name])
                target = (sub, None) if sub is not None else (_file(root, parts), a.name)
            elif a.name == package or a.name.startswith(package + "."):
                if a.asname is None:
                    continue            # ``import beamsolver.x`` binds the package name, read as an attribute chain
                target = (_file(root, a.name.split(".")[1:]), None)
            else:
                continue
            if target[0] is not None and a.name != "*":
                self.imports[a.asname or a.name] = target

    def source(self, node):
        """The statement's syntax tree as text: comments, docstrings and layout do not count."""
        key = (node.lineno, node.col_offset)
        if key not in self._dumps:
            held = []                    # docstrings taken out for the dump, put back after
            for sub in ast.walk(node):
                body = getattr(sub, "body", None)
                if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and body \
                        and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                        and isinstance(body[0].value.value, str):
                    held.append((sub, body))
                    sub.body = body[1:] or [ast.Pass()]
            try:
                self._dumps[key] = ast.dump(node)
            finally:
                for sub, body in held:
                    sub.body = body
        return self._dumps[key]

    def references(self, node):
        """``_references`` of a statement of this module, computed once."""
        key = (node.lineno, node.col_offset)
        if key not in self._refs:
            self._refs[key] = _references(node)
        return self._refs[key]


def _bound(node):
    """Names a top-level statement binds or changes (``X[...] = ...``, ``X.a = ...``, ``X.f(...)``
    count as changes of ``X``)."""
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return [node.name]
    if isinstance(node, ast.Expr):
        f = node.value.func if isinstance(node.value, ast.Call) else None
        return [_root(f.value)] if isinstance(f, ast.Attribute) and _root(f.value) else []
    names = []
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name) and isinstance(sub.ctx, ast.Store):
            names.append(sub.id)
        elif isinstance(sub, (ast.Subscript, ast.Attribute)) and isinstance(sub.ctx, ast.Store) and _root(sub):
            names.append(_root(sub))
        elif isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and sub is not node:
            names.append(sub.name)
    return names


def _root(node):
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _file(root, parts):
    if not parts:
        return None
    target = root.joinpath(*parts)
    for cand in (target.with_suffix(".py"), target / "__init__.py"):
        if cand.is_file():
            return cand.resolve()
    return None


@lru_cache(maxsize=None)
def _module(path, root):
    return _Module(path, root)


def _references(node):
    """Global names a statement reads: ``(name, None)`` and ``(name, attribute)`` for ``name.attribute``."""
    out = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name) and isinstance(sub.ctx, ast.Load):
            out.add((sub.id, None))
        elif isinstance(sub, ast.Attribute) and isinstance(sub.value, ast.Name):
            out.add((sub.value.id, sub.attr))
    return out


def _resolve(mod, name, root, depth=0):
    """``(module, name)`` defining ``name`` as seen from ``mod``, following re-exports; ``(module, None)``
    for a package module; ``None`` outside the package (numpy, builtins, locals)."""
    if name in mod.defs:
        return mod, name
    if name in mod.imports and depth < 20:
        path, attr = mod.imports[name]
        target = _module(path, root)
        return (target, None) if attr is None else _resolve(target, attr, root, depth + 1)
    return None


def _statements(mod, node, root):
    """Every top-level statement ``node`` (a statement of ``mod``) depends on, itself included:
    ``{(relative path, first line): (module, statement)}``."""
    seen = {}
    todo = [(mod, node)]
    while todo:
        m, n = todo.pop()
        key = (m.rel, n.lineno, n.col_offset)
        if key in seen:
            continue
        seen[key] = (m, n)
        for name, attr in m.references(n):
            hit = _resolve(m, name, root)
            if hit is None:
                continue
            target, tname = hit
            if tname is None:                      # a module: its attribute, if read as one
                if attr is None:
                    continue
                hit = _resolve(target, attr, root)
                if hit is None or hit[1] is None:
                    continue
                target, tname = hit
            todo += [(target, s) for s in target.defs[tname]]
    return seen


def _function_node(mod, py_func):
    """The ``def`` statement of ``py_func`` in ``mod`` (by its code object's name and first line)
    and its rank among the file's definitions of that name; ``(None, None)`` if not found."""
    code = py_func.__code__
    defs = mod.functions.get(code.co_name, [])
    for rank, (first, node) in enumerate(sorted(defs, key=lambda d: d[0])):
        if code.co_firstlineno in (first, node.lineno):
            return node, rank
    return None, None


def dependencies(py_file, name, root):
    """Sorted ``(relative path, first line)`` of the top-level statements the top-level name ``name``
    of ``py_file`` depends on, itself included (the statements binding ``name``)."""
    root = Path(root).resolve()
    mod = _module(Path(py_file).resolve(), root)
    seen = {}
    for n in mod.defs.get(name, []):
        seen.update(_statements(mod, n, root))
    return sorted((m.rel, n.lineno) for m, n in seen.values())


def digest(items):
    """SHA-256 of ``(relative path, source)`` items."""
    h = hashlib.sha256()
    for rel, text in items:
        h.update(rel.encode() + b"\0" + text.encode() + b"\0")
    return h.hexdigest()


class _Store:
    """The package's sources as this process reads them (once) and the digests computed from them,
    kept between processes in one JSON file keyed by the SHA-256 of those sources (module docstring)."""

    def __init__(self, root):
        self.texts = {p.resolve(): p.read_text() for p in sorted(root.rglob("*.py"))}
        h = hashlib.sha256()
        for path, text in self.texts.items():
            h.update(path.relative_to(root).as_posix().encode() + b"\0" + text.encode() + b"\0")
        self.key, self.entries, self.dirty = h.hexdigest(), {}, False
        cache_dir = os.environ.get("NUMBA_CACHE_DIR")
        self.path = (Path(cache_dir) if cache_dir else root / "__pycache__") / f"jit_digests.{root.name}.json"
        try:
            data = json.loads(self.path.read_text())
            if data.get("sources") == self.key:
                self.entries = data["digests"]
        except (OSError, ValueError, KeyError, TypeError):
            pass
        atexit.register(self.save)

    def get(self, key, compute):
        if key not in self.entries:
            self.entries[key], self.dirty = list(compute()), True
        return tuple(self.entries[key])

    def save(self):
        """Write the digests (atomically; nothing if none is new or the folder is not writable)."""
        if not self.dirty:
            return
        try:
            self.path.parent.mkdir(exist_ok=True)
            tmp = self.path.with_name(f"{self.path.name}.{os.getpid()}.tmp")
            tmp.write_text(json.dumps(dict(sources=self.key, digests=self.entries)))
            tmp.replace(self.path)
            self.dirty = False
        except OSError:
            pass


@lru_cache(maxsize=None)
def _store(root):
    return _Store(root)


def forget():
    """Read the sources again at the next digest, as a new process would (tests edit sources)."""
    _module.cache_clear()
    _store.cache_clear()


def function_digest(py_func, py_file, root):
    """``(digest, rank)`` of a compiled function: the digest of its dependencies and its rank among
    the same-named definitions of its file (if its ``def`` is not found: the digest of every statement
    of its file and their dependencies, and its first line); kept between processes (``_Store``)."""
    root = Path(root).resolve()
    py_file = Path(py_file).resolve()
    code = py_func.__code__
    key = f"{py_file.relative_to(root).as_posix()}:{code.co_name}:{code.co_firstlineno}"
    return _store(root).get(key, lambda: _function_digest(py_func, py_file, root))


def _function_digest(py_func, py_file, root):
    mod = _module(Path(py_file).resolve(), root)
    node, rank = _function_node(mod, py_func)
    nodes = [n for defs in mod.defs.values() for n in defs] if node is None else [node]
    seen = {}
    for n in nodes:
        seen.update(_statements(mod, n, root))
    items = sorted((m.rel, m.source(n)) for m, n in seen.values())
    return digest(items), (f"l{py_func.__code__.co_firstlineno}" if node is None else rank)


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
                return self._stamp

            def get_disambiguator(self):
                return f"d{self._rank}"

            @classmethod
            def from_function(cls, py_func, py_file):
                root = _root_of(Path(py_file).resolve())
                if root is None:
                    return None
                stamp, rank = function_digest(py_func, py_file, root)
                self = super().from_function(py_func, py_file)
                if self is not None:
                    self._stamp, self._rank = stamp, rank
                return self
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
