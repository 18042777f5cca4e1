"""The one decorator every kernel uses, and the guard against stale numba caches.

cache=True: compiled once per machine, loaded from disk afterwards.
fastmath=False: fastmath lets LLVM assume no NaNs and would remove the isfinite guards.
_nrt=False: kernels never allocate; without the runtime's reference counting, passing the
model/state/workspace NamedTuples (dozens of arrays) between stages costs nothing, where
with it every call increments and decrements every array (about 1 us per call).

Numba checks a cached function against its own file only; a kernel that calls into another
file would keep stale machine code after that file changes. ``_drop_stale_caches`` hashes all
kernel sources and clears the numba caches of planarsim and walkers when the hash changes.
"""
import hashlib
import os
from pathlib import Path

from numba import njit
from numba.core.registry import CPUDispatcher

_OPTIONS = dict(cache=True, fastmath=False, nogil=True, error_model="numpy", _nrt=False)

jit = njit(**_OPTIONS)
# for numba.cfunc (the step's C entry, cached by its own argument): a C function holds no GIL
KERNEL_OPTIONS = {k: v for k, v in _OPTIONS.items() if k not in ("cache", "nogil")}
# PLANARSIM_KERNEL_CALLS=1 keeps kernels as calls, so that a profiler sees each stage
# (benchmarks/profile_kernels.py sets it, with a cache of its own)
_KERNEL_CALLS = os.environ.get("PLANARSIM_KERNEL_CALLS") == "1"
# kernel: a function called only from other compiled code. numba then builds neither its Python
# wrapper (which unboxes every array of the model, state and workspace: thousands of lines of
# LLVM IR per function) nor its C wrapper; this halves the first-ever compile of the step.
# Anything called from Python (rollouts, run_recorded, step_entry, terrain queries) keeps `jit`.
class KernelDispatcher(CPUDispatcher):
    """Dispatcher of a kernel. Compiled code calls it directly; a call from Python is refused
    with a clear error (numba would jump into the Python wrapper that was never built)."""

    def __call__(self, *args, **kwargs):
        name = self.py_func.__qualname__
        raise TypeError(f"{self.py_func.__module__}.{name} is a compiled kernel: call it from "
                        "compiled code (a rollout decorated with planarsim.kernels._jit.jit); "
                        "from Python use Simulator.step / steps or planarsim.kernels.step.step_entry")


def _kernel_decorator(**extra):
    options = dict(_OPTIONS, nopython=True, boundscheck=None, no_cpython_wrapper=True,
                   no_cfunc_wrapper=True, **extra)
    options.pop("cache")

    def decorate(fn):
        disp = KernelDispatcher(py_func=fn, locals={}, targetoptions=dict(options))
        disp.enable_caching()
        return disp
    return decorate


# kernel: inlined by LLVM into its compiled callers (forceinline). A call passes model, state and
# workspace as three pointers (kernels/refs.py), so LLVM's inliner no longer sees much to gain
# and left small hot kernels as calls (a fifth slower on the smallest models).
kernel = _kernel_decorator(forceinline=not _KERNEL_CALLS)
kernel_inline = _kernel_decorator(inline="always")
# callable from Python and inlined into compiled callers (a walker's controller: the Python
# controller path calls it, its rollout inlines it, which saves passing ~40 arrays each step)
jit_inline = njit(inline="always", **_OPTIONS)


def _sources_hash(folder: Path, extra: str = "") -> str:
    digest = hashlib.blake2b(extra.encode(), digest_size=16)
    for path in sorted(folder.rglob("*.py")):
        digest.update(str(path.relative_to(folder)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


# the kernels compile differently with PLANARSIM_KERNEL_CALLS=1: a switch clears the caches
KERNEL_HASH = _sources_hash(Path(__file__).resolve().parent, "calls" if _KERNEL_CALLS else "")


def drop_stale_caches(folder, clear=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources of `folder`
    or of planarsim's kernels changed since the caches were written.

    Walker packages call this on import with their own folder, since their rollout kernels
    link the engine's step and their controller files.
    """
    folder = Path(folder).resolve()
    clear = folder if clear is None else Path(clear).resolve()
    new = _sources_hash(folder, KERNEL_HASH)
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


drop_stale_caches(Path(__file__).resolve().parent, clear=Path(__file__).resolve().parent.parent)
