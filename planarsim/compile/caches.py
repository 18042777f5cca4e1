"""Stale numba caches: numba checks a cached function against its own file only.

A kernel that calls into another file would keep stale machine code after that file changes.
``drop_stale_caches`` hashes a folder's sources with the engine sources its compiled code is
built from, and clears the folder's numba caches when the hash changes. planarsim's own
caches (the step among them) follow all engine sources: kernels/ and compile/, and the mode.
A package of compiled callers (a walker) follows compile/ and only the kernel modules its
compiled code can inline: those it imports (from planarsim.compiled or planarsim.kernels)
and the modules they import in turn; and the other sources it can inline: planarsim's modules
with compiled code that it imports, and the modules of its own top-level package outside its
folder (a walker's shared helpers), with what they import. In the fast mode its code
reaches the step by address, so an edit of a kernel only the step uses (the contact solve,
say) recompiles the step and leaves the walkers' rollouts cached; in the other modes the step
is inlined into every caller, which then follows all engine sources.
"""
from __future__ import annotations

import functools
import hashlib
import os
import re
import tempfile
from pathlib import Path

from .mode import FAST, MODE, PYTHON

_PLANARSIM = Path(__file__).resolve().parent.parent


def _sources_hash(folder: Path, extra: str = "", files=None) -> str:
    """Hash of the .py files below `folder` (or of `files`, paths below it) and `extra`."""
    digest = hashlib.blake2b(extra.encode(), digest_size=16)
    for path in sorted(folder.rglob("*.py") if files is None else files):
        digest.update(str(path.relative_to(folder)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _mode_tag() -> str:
    if MODE != FAST:
        return MODE
    from .fast import KERNEL_CALLS   # the kernels compile differently with it: a switch clears
    return "calls" if KERNEL_CALLS else ""


# the engine's compiled code changes with its kernels, this compiler layer and the mode
ENGINE_HASH = _sources_hash(_PLANARSIM / "compile",
                            _sources_hash(_PLANARSIM / "kernels", _mode_tag()))
_KERNELS = "planarsim.kernels"
# parts.py hands its child the hash it compiles the step from (the child compares its own)
CHILD_HASH = "PLANARSIM_CHILD_ENGINE_HASH"


def _imported_modules(path: Path):
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
            package = _dotted(path.parent)
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


def _dotted(folder: Path):
    """Dotted name of the package in `folder` (None if it is not one)."""
    parts = []
    while (folder / "__init__.py").exists():
        parts.insert(0, folder.name)
        folder = folder.parent
    return ".".join(parts) or None


def _module_file(module: str, roots):
    base = [root.joinpath(*module.split(".")) for root in roots]
    for b in base:
        for candidate in (b.with_suffix(".py"), b / "__init__.py"):
            if candidate.is_file():
                return candidate
    return None


def _exported_kernels(names=None) -> set:
    """Kernel modules (short names) of the compiled functions planarsim.compiled exports
    (`names` of them; None: all)."""
    from .. import compiled
    found = set()
    for name in compiled.__all__ if names is None else names:
        fn = getattr(compiled, name, None)
        module = getattr(getattr(fn, "py_func", None), "__module__", "") or ""
        if module.startswith(_KERNELS + "."):
            found.add(module[len(_KERNELS) + 1:])
    return found


def _has_compiled_code(path: Path) -> bool:
    text = path.read_text()
    return "@jit" in text or "@kernel" in text or "@part" in text


def caller_sources(folder) -> tuple:
    """(kernel modules, other files) that compiled functions of the .py files below `folder`
    may inline, besides the folder's own files (fast mode: the step itself is reached by
    address). Kernel modules (short names: "terrain"): those imported from planarsim.kernels
    or through planarsim.compiled, or by planarsim's modules with compiled code that are
    imported (planarsim/half_step.py: forces), and in turn every kernel module those import.
    Other files: planarsim's modules with compiled code that are imported
    (planarsim/actuators.py), and the modules of the folder's own top-level package outside
    it (walkers/common/pd.py for a walker) with, in turn, what those import."""
    folder = Path(folder).resolve()
    root = folder
    while (root / "__init__.py").exists():
        root = root.parent
    roots = (root, _PLANARSIM.parent)
    kernels, files = set(), set()
    todo = list(folder.rglob("*.py"))
    seen = set(todo)
    while todo:
        for module, names in _imported_modules(todo.pop()):
            if module == "planarsim.compiled":
                kernels |= _exported_kernels(names)
            elif module == "planarsim" and names and "compiled" in names:
                kernels |= _exported_kernels()
            elif module == _KERNELS:
                kernels |= set(names or ())
            elif module.startswith(_KERNELS + "."):
                kernels.add(module[len(_KERNELS) + 1:].split(".")[0])
            elif module == "planarsim" or module.startswith("planarsim.compile"):
                continue       # the package's front (everything) / the compiler (hashed whole)
            else:
                path = _module_file(module, roots)
                if path is None or path in seen or folder in path.parents:
                    continue
                seen.add(path)
                if _PLANARSIM in path.parents:
                    if _has_compiled_code(path):
                        files.add(path)         # and the kernels its compiled code inlines
                        todo.append(path)
                else:
                    files.add(path)
                    todo.append(path)
    todo, closure = list(kernels), set()
    while todo:
        name = todo.pop()
        path = _PLANARSIM / "kernels" / f"{name}.py"
        if name in closure or not path.exists():
            continue
        closure.add(name)
        for module, names in _imported_modules(path):
            if module == _KERNELS:
                todo += list(names or ())
            elif module.startswith(_KERNELS + "."):
                todo.append(module[len(_KERNELS) + 1:].split(".")[0])
    return closure, files


def _caller_engine_hash(folder: Path) -> str:
    """ENGINE_HASH as it matters to the compiled callers below `folder` (module docstring),
    with the other files they may inline (caller_sources)."""
    kernel_names, files = caller_sources(folder)
    others = hashlib.blake2b(digest_size=16)
    for path in sorted(files):
        others.update(f"{path.parent.name}/{path.name}".encode())   # a moved checkout keeps it
        others.update(path.read_bytes())
    if MODE != FAST:
        return ENGINE_HASH + others.hexdigest()
    kernels = _PLANARSIM / "kernels"
    inlined = [kernels / f"{name}.py" for name in sorted(kernel_names)]
    return _sources_hash(_PLANARSIM / "compile",
                         _sources_hash(kernels, _mode_tag() + others.hexdigest(), inlined))


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


def drop_stale_caches(folder, clear=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources of `folder`
    or the engine sources its compiled code is built from changed since the caches were
    written (the module's docstring; nothing under NUMBA_DISABLE_JIT=1, which neither reads
    nor writes them). With NUMBA_CACHE_DIR set (or, for a read-only install, in its user-wide
    cache folder) numba keeps those caches there instead, one folder per source folder and
    per path it was imported by: each such folder (for the
    resolved path and the one given) holds a stamp of its own (numba checks each function
    against its own file only, so without this a kernel's edit, or a new planarsim release,
    would run the step's stale machine code from there).

    Walker packages call this on import with their own folder, since their rollouts inline
    their controller files and the engine kernels they import.
    """
    if MODE == PYTHON or os.environ.get(CHILD_HASH, ENGINE_HASH) != ENGINE_HASH:
        return   # (a child compiling the step's parts for sources since edited: parts.py)
    given = Path(os.path.abspath(folder if clear is None else clear))
    folder = Path(folder).resolve()
    clear = folder if clear is None else Path(clear).resolve()
    engine = ENGINE_HASH if clear == _PLANARSIM else _caller_engine_hash(folder)
    new = _sources_hash(folder, engine)
    _clear_if_changed(folder / "__pycache__" / "numba_sources.hash", new, [clear], True)
    # one stamp in each of NUMBA_CACHE_DIR's folders: a folder is named after the path the
    # sources were imported by, so each keeps its own record of the sources its code is of
    for cache in _user_cache_folders(clear, {clear, given}):
        _clear_if_changed(cache / "planarsim_sources.hash", new, [cache], False)


_COMPILE = Path(os.path.abspath(__file__)).parent     # as imported (a link is not resolved)
drop_stale_caches(_COMPILE, clear=_COMPILE.parent)
