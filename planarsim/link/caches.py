"""Which sources the engine's compiled code is built from, and its stale caches cleared.

numba checks a cached function against its own file only (compile/caches.py). planarsim's own
caches (the step among them) follow all engine sources: kernels/, compile/ and link/, and the
mode; they are cleared on import when any of those changed (the call at the bottom of this
file: before any compiled function of planarsim is compiled or loaded).

A package of compiled callers (a walker) follows compile/, link/ and only the kernel modules
its compiled code can inline: those it imports (from planarsim.compiled or planarsim.kernels)
and the modules they import in turn; and the other sources it can inline: planarsim's modules
with compiled code that it imports, and the modules of its own top-level package outside its
folder (a walker's shared helpers), with what they import. In the fast mode its code reaches
the step by address, so an edit of a kernel only the step uses (the contact solve, say)
recompiles the step and leaves the walkers' rollouts cached; in the other modes the step is
inlined into every caller, which then follows all engine sources.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

from ..compile.caches import clear_if_stale, imported_modules, module_file, sources_hash
from ..compile.mode import FAST, MODE, PYTHON

if MODE == FAST:      # (compile/fast.py reads numba internals that only the fast mode needs)
    from ..compile.fast import KERNEL_CALLS

_PLANARSIM = Path(__file__).resolve().parent.parent
_KERNELS = "planarsim.kernels"
# the layers whose sources every compiled caller's code is built from, hashed whole
_LAYERS = ("compile", "link")


def _mode_tag() -> str:
    if MODE != FAST:
        return MODE
    return "calls" if KERNEL_CALLS else ""   # the kernels compile differently with it


def _layers_hash(extra: str) -> str:
    for layer in _LAYERS:
        extra = sources_hash(_PLANARSIM / layer, extra)
    return extra


# the engine's compiled code changes with its kernels, the compiler and link layers and the mode
ENGINE_HASH = _layers_hash(sources_hash(_PLANARSIM / "kernels", _mode_tag()))
# parts.py hands its child the hash it compiles the step from (the child compares its own)
CHILD_HASH = "PLANARSIM_CHILD_ENGINE_HASH"


def _has_compiled_code(path: Path) -> bool:
    text = path.read_text()
    return "@jit" in text or "@kernel" in text or "@part" in text


def _kernel_file(name: str):
    """The source of kernel module `name` (dotted below planarsim.kernels: "codes",
    "geometry.terrain"; a package's __init__.py), None where there is none."""
    base = _PLANARSIM.joinpath("kernels", *name.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _kernel_modules(module: str, names) -> set:
    """The kernel modules (dotted below planarsim.kernels) that `from module import names`
    imports (names None: `import module`): the module itself, and those of `names` that are
    modules of it (`from planarsim.kernels.geometry import terrain`)."""
    rest = module[len(_KERNELS) + 1:]
    found = {rest} if rest else set()
    for name in names or ():
        below = f"{rest}.{name}" if rest else name
        if _kernel_file(below) is not None:
            found.add(below)
    return found


def caller_sources(folder, exported_kernels) -> tuple:
    """(kernel modules, other files) that compiled functions of the .py files below `folder`
    may inline, besides the folder's own files (fast mode: the step itself is reached by
    address). Kernel modules (named below planarsim.kernels with their folder:
    "geometry.terrain", "codes"): those imported from planarsim.kernels or through
    planarsim.compiled (`exported_kernels(names)`: the kernel modules of those of its names,
    None: of all), or by planarsim's modules with compiled code that are imported
    (planarsim/half_step.py: dynamics.forces), and in turn every kernel module those import.
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
        for module, names in imported_modules(todo.pop()):
            if module == "planarsim.compiled":
                kernels |= exported_kernels(names)
            elif module == "planarsim" and names and "compiled" in names:
                kernels |= exported_kernels(None)
            elif module == _KERNELS or module.startswith(_KERNELS + "."):
                kernels |= _kernel_modules(module, names)
            elif module == "planarsim" or any(module == f"planarsim.{layer}" or
                                               module.startswith(f"planarsim.{layer}.")
                                               for layer in _LAYERS):
                continue       # the package's front (everything) / the layers (hashed whole)
            else:
                path = module_file(module, roots)
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
        path = _kernel_file(name)
        if name in closure or path is None:
            continue
        closure.add(name)
        for module, names in imported_modules(path):
            if module == _KERNELS or module.startswith(_KERNELS + "."):
                todo += _kernel_modules(module, names)
    return closure, files


def _caller_engine_hash(folder: Path, exported_kernels) -> str:
    """ENGINE_HASH as it matters to the compiled callers below `folder` (module docstring),
    with the other files they may inline (caller_sources)."""
    kernel_names, files = caller_sources(folder, exported_kernels)
    others = hashlib.blake2b(digest_size=16)
    for path in sorted(files):
        others.update(f"{path.parent.name}/{path.name}".encode())   # a moved checkout keeps it
        others.update(path.read_bytes())
    if MODE != FAST:
        return ENGINE_HASH + others.hexdigest()
    kernels = _PLANARSIM / "kernels"
    inlined = [_kernel_file(name) for name in sorted(kernel_names)]
    return _layers_hash(sources_hash(kernels, _mode_tag() + others.hexdigest(), inlined))


def drop_stale_caches(folder, clear=None, exported_kernels=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources below `folder`
    or the engine sources their compiled code is built from (module docstring) changed since
    the last call (numba checks a cached function against its own file only, so without this
    a kernel's edit, or a new planarsim release, would run the step's stale machine code).
    exported_kernels: planarsim.compiled's names -> their kernel modules (caller_sources);
    planarsim.compiled.drop_stale_caches passes its own.

    Walker packages call planarsim.compiled.drop_stale_caches on import with their own folder,
    since their rollouts inline their controller files and the engine kernels they import.
    """
    if MODE == PYTHON or os.environ.get(CHILD_HASH, ENGINE_HASH) != ENGINE_HASH:
        return   # (a child compiling the step's parts for sources since edited: parts.py)
    if Path(folder if clear is None else clear).resolve() == _PLANARSIM:
        engine = ENGINE_HASH
    else:
        engine = _caller_engine_hash(Path(folder).resolve(), exported_kernels or (lambda names: set()))
    clear_if_stale(folder, engine, clear)


# planarsim's own caches, cleared before any of its compiled functions is compiled or loaded
_HERE = Path(os.path.abspath(__file__)).parent      # as imported (a link is not resolved)
drop_stale_caches(_HERE, clear=_HERE.parent)
