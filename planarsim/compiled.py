"""What compiled code uses from the engine: a walker's controller and rollout, or your own.

Decorators (three; planarsim/compile/decorators.py. All never allocate and keep the NaN checks
that fastmath would drop; jit and jit_inline cache their machine code on disk, a kernel is
cached inside its compiled callers):
    jit          compiled, callable from Python and from compiled code (a rollout);
                 jit(inline="force"): always inlined where compiled code calls it
    jit_inline   the same, inlined into its compiled callers (a controller run every step)
    kernel       compiled code only, inlined (small helpers; calling one from Python raises
                 a TypeError that says so); kernel(inline="never") stays a call
The compiler layer runs in one of three modes, with the same numbers (planarsim/compile/mode.py):
fast (the default), plain numba (PLANARSIM_PLAIN_NUMBA=1, or when numba lacks an internal the
fast mode uses) and Python (NUMBA_DISABLE_JIT=1: a breakpoint inside the step works).

Engine, from compiled code:
    step(m, s, ws, opt, u) -> run code      advance State s by one step of opt.dt (0: m.dt).
                                             The step is one C function, compiled once per
                                             machine and loaded before the first jit function
                                             runs; every caller calls it by address (the
                                             linkage is all in planarsim/link/step.py).
                                             Decorate callers with jit, not numba.njit
    record_frame(s, ws, rec, k)              write frame k of a Recorder (make_recorder)
    height(coef, x), height_derivs(coef, x)  the ground h(x) [m] and (h, h', h'')
    closest_point(coef, px, py)              (gx, gy, nx, ny, gap) of the nearest ground point
    pin_angle_rate(m, q, v, j)               pin j's angle [rad] and rate [rad/s]
    shape_contact_mode(m, s, body)           most holding mode (0 free, 1 pinned, 2 sliding) of
                                             body's shape contacts (on a box, a step, a body)
From Python:
    step_from_python(m, s, ws, opt, u)       the same step (about 1 us a call on top of the
                                             step, as Simulator.step)
    check_run(code, model, ws, options, who) raise for an engine failure, else return code
    audit_counts(ws)                         the step audit's counts by rule
    step_info(ws)                            what the last step did (solves, splits, pivots)
    drop_stale_caches(folder)                call on import of a package with compiled code
    kernel_cache()                           (folder, index files) of the engine's numba cache
    measured_compile(), record_compile(s)    the last first compile measured on this machine [s]
    TYPICAL_COMPILE_S                        a first compile on a quiet two-core machine [s]

Run codes. step returns RUN_OK or an engine failure: RUN_NONFINITE / RUN_TOO_LARGE (the state
blew up), RUN_AUDIT (StepOptions.audit_raise and a rule broken), RUN_BAD_COMMANDS /
RUN_NONFINITE_COMMAND (nothing stepped). A rollout adds its own reasons to stop from
RUN_WALKER up (RUN_FELL, RUN_NO_EVENT, or more of its own), so that one test,
``engine_failed(code)``, tells the two apart everywhere.
"""
import os
from pathlib import Path

from .errors import diverged
from .compile import jit, jit_inline, kernel
from .compile.caches import cache_folder
from .link import caches as _caches
from .link.step import step, step_from_python
from .kernels.checks.audit import audit_counts
from .kernels.dynamics.forces import pin_angle_rate
from .kernels.geometry.pair import shape_contact_mode
from .kernels.info import step_info
from .kernels.checks.guards import (GUARD_AUDIT, GUARD_BAD_COMMANDS, GUARD_NONFINITE,
                                    GUARD_NONFINITE_COMMAND, GUARD_OK, GUARD_TOO_LARGE)
from .kernels.record import record_frame
from .kernels.geometry.terrain import closest_point, gap_of_point, height, height_derivs
from .trajectory import make_recorder

RUN_OK = GUARD_OK
RUN_NONFINITE = GUARD_NONFINITE
RUN_TOO_LARGE = GUARD_TOO_LARGE
RUN_AUDIT = GUARD_AUDIT
RUN_BAD_COMMANDS = GUARD_BAD_COMMANDS
RUN_NONFINITE_COMMAND = GUARD_NONFINITE_COMMAND
RUN_WALKER = 100        # codes from here up are a rollout's own reasons to stop
RUN_FELL = 100          # the walker fell (its own test: hip too low, torso down, ...)
RUN_NO_EVENT = 101      # a step map found no section event (touchdown, mid-stance) in time


def kernel_cache():
    """(folder, sorted index files) of the engine kernels' numba cache: no files means the next
    run compiles (measured_compile() says how long that took on this machine last time)."""
    folder = cache_folder(Path(_caches.__file__).parent)     # NUMBA_CACHE_DIR's, where set
    # (not the step's parts, which a child process caches while the step still compiles)
    return folder, sorted(f for f in folder.glob("*.nbi") if not f.name.startswith("parts."))


COMPILE_RECORD = "first_compile_s.txt"   # in kernel_cache()'s folder: the last first compile [s]
# what a first compile takes where none was measured yet [s]: import to a walker's first step
# with an empty numba cache on a quiet two-core machine, both cores compiling (AMD EPYC,
# numba 0.68; benchmarks/startup.py); a busy machine takes longer
TYPICAL_COMPILE_S = 20.0


def measured_compile():
    """Seconds the last first compile (a cold cache) took on this machine, as recorded by
    record_compile, or None if none was recorded."""
    try:
        text = (kernel_cache()[0] / COMPILE_RECORD).read_text().split()
        seconds = float(text[0])
    except (OSError, ValueError, IndexError):
        return None
    return seconds if seconds >= 0 else None


def record_compile(seconds: float) -> None:
    """Keep `seconds` [s], a first compile just measured, beside the cache (numba's cache
    clearing leaves it); nothing where the install is read-only."""
    folder = kernel_cache()[0]
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f"{COMPILE_RECORD}.{os.getpid()}.tmp"
        tmp.write_text(f"{float(seconds):.3f}\n")
        os.replace(tmp, folder / COMPILE_RECORD)
    except OSError:
        pass


def _exported_kernels(names=None) -> set:
    """Kernel modules (named below planarsim.kernels with their folder: "geometry.terrain") of
    the compiled functions this module exports (`names` of them; None: all)."""
    found = set()
    for name in __all__ if names is None else names:
        fn = globals().get(name)
        module = getattr(getattr(fn, "py_func", None), "__module__", "") or ""
        if module.startswith("planarsim.kernels."):
            found.add(module[len("planarsim.kernels."):])
    return found


def caller_sources(folder) -> tuple:
    """(kernel modules, other files) that compiled code below `folder` may inline besides its
    own files (planarsim/link/caches.py caller_sources), for what it imports from here too."""
    return _caches.caller_sources(folder, _exported_kernels)


def drop_stale_caches(folder, clear=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources below `folder`,
    or the engine sources its compiled code can inline (planarsim/link/caches.py), changed
    since the last call: numba checks a cached function against its own file only. A package
    with compiled code (a walker) calls it on import with its own folder."""
    _caches.drop_stale_caches(folder, clear, _exported_kernels)


def engine_failed(code) -> bool:
    """True for the engine's failure codes (the state blew up, an audit rule broke, bad
    commands), False for RUN_OK and a rollout's own codes (RUN_WALKER and up)."""
    return code != RUN_OK and code < RUN_WALKER


def check_run(code, model, ws, options, who="simulation") -> int:
    """Raise the engine's error for a failure code (planarsim.errors.diverged: a
    SimulationDiverged naming step, time, body and value; an AuditViolation; a ValueError for
    bad commands); return any other code unchanged."""
    code = int(code)
    if engine_failed(code):
        raise diverged(model, ws, code, options.guard_limit, who)
    return code


__all__ = ["jit", "jit_inline", "kernel", "step", "step_from_python", "record_frame",
           "make_recorder", "height", "height_derivs", "closest_point", "gap_of_point",
           "pin_angle_rate", "shape_contact_mode", "audit_counts", "step_info", "drop_stale_caches",
           "kernel_cache", "measured_compile", "record_compile", "TYPICAL_COMPILE_S",
           "check_run", "engine_failed",
           "RUN_OK", "RUN_NONFINITE", "RUN_TOO_LARGE", "RUN_AUDIT", "RUN_BAD_COMMANDS",
           "RUN_NONFINITE_COMMAND", "RUN_WALKER", "RUN_FELL", "RUN_NO_EVENT"]
