"""Stale numba caches: numba checks a cached function against its own file only.

A kernel that calls into another file would keep stale machine code after that file changes.
``drop_stale_caches`` hashes a folder's sources with the engine sources its compiled code is
built from, and clears the folder's numba caches when the hash changes. planarsim's own
caches (the step among them) follow all engine sources: kernels/ and compile/, and the mode.
A package of compiled callers (a walker) follows compile/ and only the kernel modules its
compiled code can inline: those it imports (from planarsim.compiled or planarsim.kernels)
and the modules they import in turn. In the fast mode its code reaches the step by address,
so an edit of a kernel only the step uses (the contact solve, say) recompiles the step and
leaves the walkers' rollouts cached; in the other modes the step is inlined into every
caller, which then follows all engine sources.
"""
from __future__ import annotations

import ast
import hashlib
import os
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


def _imported_modules(path: Path):
    """(module, names) of each import statement of source file `path`: absolute module names,
    names None for ``import module``; relative imports resolved within planarsim.kernels
    (the only package whose relative imports matter here)."""
    try:
        tree = ast.parse(path.read_text(), str(path))
    except (OSError, SyntaxError, ValueError):
        return
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, None
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                if path.parent != _PLANARSIM / "kernels" or node.level != 1:
                    continue
                module = f"{_KERNELS}.{module}" if module else _KERNELS
            yield module, [alias.name for alias in node.names]


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


def caller_kernels(folder) -> set:
    """The kernel modules (short names: "terrain") whose code compiled functions of the .py
    files below `folder` may inline (fast mode: the step itself is reached by address):
    those imported from planarsim.kernels or through planarsim.compiled, and, in turn, every
    kernel module those import."""
    wanted = set()
    for path in Path(folder).rglob("*.py"):
        for module, names in _imported_modules(path):
            if module == "planarsim.compiled":
                wanted |= _exported_kernels(names)
            elif module == "planarsim" and names and "compiled" in names:
                wanted |= _exported_kernels()
            elif module == _KERNELS:
                wanted |= set(names or ())
            elif module.startswith(_KERNELS + "."):
                wanted.add(module[len(_KERNELS) + 1:].split(".")[0])
    todo, closure = list(wanted), set()
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
    return closure


def _caller_engine_hash(folder: Path) -> str:
    """ENGINE_HASH as it matters to the compiled callers below `folder` (module docstring)."""
    if MODE != FAST:
        return ENGINE_HASH
    kernels = _PLANARSIM / "kernels"
    files = [kernels / f"{name}.py" for name in sorted(caller_kernels(folder))]
    return _sources_hash(_PLANARSIM / "compile", _sources_hash(kernels, _mode_tag(), files))


def drop_stale_caches(folder, clear=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources of `folder`
    or the engine sources its compiled code is built from changed since the caches were
    written (the module's docstring; nothing under NUMBA_DISABLE_JIT=1, which neither reads
    nor writes them).

    Walker packages call this on import with their own folder, since their rollouts inline
    their controller files and the engine kernels they import.
    """
    if MODE == PYTHON:
        return
    folder = Path(folder).resolve()
    clear = folder if clear is None else Path(clear).resolve()
    engine = ENGINE_HASH if clear == _PLANARSIM else _caller_engine_hash(folder)
    new = _sources_hash(folder, engine)
    stamp = folder / "__pycache__" / "numba_sources.hash"
    try:
        if stamp.exists() and stamp.read_text() == new:
            return
        for pattern in ("*.nbi", "*.nbc"):
            for f in clear.rglob(pattern):
                f.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(new)
        os.replace(tmp, stamp)
    except OSError:
        pass  # read-only install: its sources cannot change either


drop_stale_caches(_PLANARSIM / "compile", clear=_PLANARSIM)
