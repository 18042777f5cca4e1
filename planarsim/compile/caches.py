"""Stale numba caches: numba checks a cached function against its own file only.

A compiled function that calls into another file would keep stale machine code after that
file changes. This is the machinery to find and clear such caches: a hash of a folder's
sources (``sources_hash``), the modules a source file imports (``imported_modules``, read
from its text: lazy imports inside functions too), the folders numba keeps a source folder's
caches in (``cache_folder``: its __pycache__, NUMBA_CACHE_DIR's or numba's user-wide folder)
and ``clear_if_stale``, which clears them when the hash of what their code is built from
changes. Which sources a package's compiled code is built from is the business of the layer
that knows the engine (planarsim/link/caches.py).
"""
from __future__ import annotations

import functools
import hashlib
import os
import re
import tempfile
from pathlib import Path


def sources_hash(folder: Path, extra: str = "", files=None) -> str:
    """Hash of the .py files below `folder` (or of `files`, paths below it) and `extra`."""
    digest = hashlib.blake2b(extra.encode(), digest_size=16)
    for path in sorted(folder.rglob("*.py") if files is None else files):
        digest.update(str(path.relative_to(folder)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def imported_modules(path: Path):
    """(module, names) of each import statement of source file `path`: absolute module names
    (relative imports resolved by the file's folders, up to `level` packages), names None for
    ``import module``."""
    try:
        stat = path.stat()
        return _imports_of(str(path), stat.st_mtime_ns, stat.st_size)
    except OSError:
        return ()


@functools.lru_cache(maxsize=None)
def _imports_of(name: str, mtime_ns: int, size: int) -> tuple:
    return tuple(_parse_imports(Path(name)))


# import statements, wherever they stand (lazy ones inside functions too): "from M import
# names" (names possibly in parentheses over several lines) and "import M[, M2]"
_FROM = re.compile(r"^[ \t]*from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)", re.M)
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n#]+)", re.M)


def _parse_imports(path: Path):
    try:
        text = path.read_text()
    except (OSError, ValueError):
        return
    for level, module, names in _FROM.findall(text):
        names = [n.split()[0] for n in names.strip("()").replace("\\", " ").split(",")
                 if n.split()]
        if level:
            package = dotted(path.parent)
            if package is None:
                continue
            parts = package.split(".")
            if len(level) > len(parts):
                continue
            module = ".".join(parts[:len(parts) - len(level) + 1] + ([module] if module else []))
        yield module, names
    for modules in _IMPORT.findall(text):
        for m in modules.split(","):
            if m.split():
                yield m.split()[0], None


def dotted(folder: Path):
    """Dotted name of the package in `folder` (None if it is not one)."""
    parts = []
    while (folder / "__init__.py").exists():
        parts.insert(0, folder.name)
        folder = folder.parent
    return ".".join(parts) or None


def module_file(module: str, roots):
    base = [root.joinpath(*module.split(".")) for root in roots]
    for b in base:
        for candidate in (b.with_suffix(".py"), b / "__init__.py"):
            if candidate.is_file():
                return candidate
    return None


def cache_folder(source_folder) -> Path:
    """The folder numba keeps the caches of the source files in `source_folder` in: below
    NUMBA_CACHE_DIR if set, else its __pycache__ (numba's user-wide cache folder where that
    cannot be written)."""
    source_folder = Path(os.path.abspath(source_folder))
    folders = _user_cache_folders(source_folder, {source_folder}, recursive=False)
    return folders[0] if folders else source_folder / "__pycache__"


def _in_tree_writable(source_dir: Path) -> bool:
    """Whether numba caches in source_dir's __pycache__ (InTreeCacheLocator): an existing
    writable folder answers at once; else numba's own test (make it, write a file)."""
    return _writable_folder(source_dir / "__pycache__")


def _writable_folder(folder) -> bool:
    """Whether numba can cache in `folder`: an existing writable folder answers at once (no
    file written at import); else numba's own test (make it, write a file there)."""
    folder = Path(folder)
    if folder.is_dir() and os.access(folder, os.W_OK):
        return True
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
        return True
    except OSError:
        return False


_WARNED_CACHE_DIRS = set()


def _warn_unusable_cache_dir(folder) -> None:
    """Say once per folder that NUMBA_CACHE_DIR cannot be written: numba then caches in the
    next place it knows of, without a word."""
    if folder in _WARNED_CACHE_DIRS:
        return
    _WARNED_CACHE_DIRS.add(folder)
    import warnings
    warnings.warn(f"NUMBA_CACHE_DIR={folder!r} cannot be created or written; numba caches "
                  "the compiled engine in the package's __pycache__ (or its user-wide cache "
                  "folder) instead", RuntimeWarning, stacklevel=2)


def _numba_subpath():
    """numba's name for a source file's folder below NUMBA_CACHE_DIR or its user-wide cache
    folder: a function of the file's path."""
    try:
        from numba.core.caching import _CacheLocator
        return _CacheLocator.get_suitable_cache_subpath
    except (ImportError, AttributeError):     # numba's own rule (0.49-0.68), if it moves
        def subpath(py_file):
            folder = os.path.dirname(os.path.abspath(py_file))
            return f"{os.path.basename(folder)}_{hashlib.sha1(folder.encode()).hexdigest()}"
        return subpath


def _outside_root(source_dir: Path):
    """Where numba caches the functions of source_dir's files when not in its __pycache__:
    NUMBA_CACHE_DIR if set and numba can write its folder for source_dir there, numba's
    user-wide cache folder (~/.cache/numba) if __pycache__ cannot be written (a read-only
    install), else None. numba passes over a NUMBA_CACHE_DIR it cannot write without a word;
    this says so (a RuntimeWarning)."""
    from numba.core import config
    if config.CACHE_DIR:
        own = Path(config.CACHE_DIR) / _numba_subpath()(str(source_dir / "__init__.py"))
        if _writable_folder(own):     # numba's test is of this folder (ensure_cache_path)
            return Path(config.CACHE_DIR)
        _warn_unusable_cache_dir(config.CACHE_DIR)
    if _in_tree_writable(source_dir):
        return None
    try:
        from numba.misc.appdirs import AppDirs
        return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)
    except Exception:     # a numba without it caches nowhere else planarsim knows of
        return None


def _user_cache_folders(clear: Path, spellings, recursive=True):
    """The folders outside the source tree (NUMBA_CACHE_DIR's, or the user-wide ones of a
    read-only install: _outside_root) that hold numba's caches of the sources below `clear`;
    none where numba writes them in __pycache__ next to the sources. numba names each after
    the source file's folder as Python imported it, which may be a path through a link:
    `spellings` are the paths `clear` may be reached by."""
    subpath = _numba_subpath()
    roots, folders = {}, set()
    for source in (clear.rglob("*.py") if recursive else [clear / "__init__.py"]):
        if source.parent not in roots:
            roots[source.parent] = _outside_root(source.parent)
        root = roots[source.parent]
        if root is None:
            continue
        for spelling in spellings:
            folders.add(root / subpath(str(spelling / source.relative_to(clear))))
    return sorted(folders)


def _clear_if_changed(stamp: Path, new: str, folders, recursive: bool) -> None:
    """Delete the numba cache files in `folders` (and below, if recursive) unless `stamp`
    holds `new`; then write it."""
    try:
        if stamp.exists() and stamp.read_text() == new:
            return
        for folder in folders:
            for pattern in ("*.nbi", "*.nbc"):
                for f in (folder.rglob(pattern) if recursive else folder.glob(pattern)):
                    f.unlink(missing_ok=True)
        stamp.parent.mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(new)
        os.replace(tmp, stamp)
    except OSError:
        pass  # read-only install: its sources cannot change either


def clear_if_stale(folder, engine: str, clear=None) -> None:
    """Clear numba's caches of the sources below `clear` (default `folder`) unless the hash of
    `folder`'s sources with `engine` (a hash of the other sources their compiled code is
    built from) is the one recorded at the last clearing; then record it. The record is kept
    in folder's __pycache__ and, for caches outside the source tree, in each of their
    folders (named after the path the sources were imported by, so each keeps its own)."""
    given = Path(os.path.abspath(folder if clear is None else clear))
    folder = Path(folder).resolve()
    clear = folder if clear is None else Path(clear).resolve()
    new = sources_hash(folder, engine)
    _clear_if_changed(folder / "__pycache__" / "numba_sources.hash", new, [clear], True)
    for cache in _user_cache_folders(clear, {clear, given}):
        _clear_if_changed(cache / "planarsim_sources.hash", new, [cache], False)
