"""The fast mode's step linkage (compile/mode.py): one C function, published once per process,
that all compiled code calls.

The step (kernels/step.py) is compiled once, as a C function (a numba cfunc, cached on disk),
and every compiled caller (run_steps, run_recorded, step_entry, each walker's rollout, your
own) calls it by address through the intrinsic ``step``. A plain numba call would link the
step's code into each caller, where LLVM optimises and compiles it again: that was most of
the first-ever start-up (about 15 s per rollout). The step's long parts (most run rarely,
PART_NAMES) are a C function of their own that it calls through a table (compile/parts.py,
bound here): a first-ever start compiles them in a child process while this one compiles the
rest (_load_or_compile).

A caller's machine code names the step by a symbol (``planarsim_step_<hash of the engine
types>``) that LLVM resolves when the caller is compiled or loaded from the numba cache. The
symbol is therefore published (load_step) before any such code exists in a process: by the
dispatcher of every `jit` function before it compiles or loads code (load_step is a
before_compile hook of compile/fast.py), and by the intrinsic when a caller is typed. Loading takes about 0.1 s from the cache plus
numba's own set-up on the first compile of a process; the first-ever compile takes most of
the cold start. Importing this module compiles nothing, so a command that only imports
walkers (to list them, say) is quick. Decorate your own code that calls ``step`` with
planarsim.compiled.jit: a plain numba.njit(cache=True) function loaded from the cache in a
new process would name a symbol nothing has published yet.
"""
import hashlib
import os
import time

import llvmlite.binding as ll
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.compiler_lock import global_compiler_lock
from numba.extending import intrinsic

from ..compile import parts, refs
from ..compile.fast import before_compile, code_layout
from ..kernels.solver import complementarity  # noqa: F401
from ..kernels.geometry import pair  # noqa: F401
from ..kernels.dynamics import position   # noqa: F401  (the parts' modules)
from ..kernels.checks.guards import GUARD_BAD_COMMANDS, check_commands
from ..kernels.info import INFO_COMMAND
from ..kernels.step import _step
from . import caches
from .engine import check_step_types
from .engine import engine_types as _engine_types

_ENGINE = {}
_LOADING = []     # this thread is compiling the step (see load_step)

# the step's parts, by module and name: its index is its number (compile/parts.py)
PART_NAMES = (
    "planarsim.kernels.solver.complementarity.solve_contacts",
    "planarsim.kernels.solver.complementarity.project_positions",
    "planarsim.kernels.dynamics.position._settle_measured",
    "planarsim.kernels.geometry.pair.find_pair",
)


def engine_types():
    """(model, state, workspace, options) numba types the step is compiled for."""
    if "types" not in _ENGINE:
        found = _engine_types()
        text = "|".join(t.name for t in found)
        symbol = "planarsim_step_" + hashlib.blake2b(text.encode(), digest_size=8).hexdigest()
        _ENGINE.update(symbol=symbol, types=found)     # one update: another thread sees both or none
    return _ENGINE["types"]


def _child_env():
    return {caches.CHILD_HASH: caches.ENGINE_HASH}   # the sources this process compiles from


parts.bind(parts.Binding(PART_NAMES, engine_types, __name__, _child_env))


def _step_c(m, s, ws, opt, u_data, n_u):
    if n_u != m.act_kind.shape[0]:
        ws.info[INFO_COMMAND] = n_u   # nothing is read or changed: the actuators would read past u
        return GUARD_BAD_COMMANDS
    u = refs.array_1d(u_data, n_u)
    code = check_commands(u, ws)
    if code != 0:
        return code
    return _step(m, s, ws, opt, u)


@before_compile
def load_step():
    """Compile the step's C function (or load it from the cache) and publish its address
    under the symbol returned (once per process; see the module's docstring). Under numba's
    compiler lock, so that another thread's compile waits for the symbol; a call from inside
    the step's own compile (it compiles jit functions, whose dispatchers come here) returns
    at once: that code does not call the step."""
    if "cfunc" in _ENGINE:
        return _ENGINE["symbol"]
    with global_compiler_lock:
        if "cfunc" not in _ENGINE and not _LOADING:
            _LOADING.append(True)
            try:
                entry = _load_or_compile()
                ll.add_symbol(_ENGINE["symbol"], entry.address)
                _ENGINE["cfunc"] = entry
            finally:
                _LOADING.clear()
    engine_types()
    return _ENGINE["symbol"]


def _load_or_compile():
    """The step's C function, its parts (compile/parts.py) loaded and their table filled: from
    numba's cache, or compiled, the parts in a child process while this one compiles the rest
    of the step when both are missing."""
    missing = parts.missing_parts()       # (publishes the parts' table first)
    entry = parts.new_cfunc(_step_c, (*engine_types(), types.CPointer(types.float64), types.int64),
                            types.int64)
    if parts.load_cached(entry):
        with code_layout():
            parts.finish(missing, None)
        return entry
    child = parts.start_child(missing)
    try:
        with code_layout():
            started = time.perf_counter()
            entry.compile()
            parts.finish(missing, child, time.perf_counter() - started)
    except BaseException:
        parts.stop_child(child)
        raise
    return entry


@intrinsic
def step(typingctx, m, s, ws, opt, u):
    """step(m, s, ws, opt, u) -> guard code: advance State s by one step of opt.dt (0: m.dt)
    under actuator commands u (float64, C-contiguous, one per actuator). Callable from compiled code.
    Returns 0 ok, 1 non-finite, 2 too large (kernels/checks/guards.py), -1 when u does not have one
    entry per actuator, -2 when a command is NaN or infinite (for both nothing is changed;
    planarsim.errors.diverged explains any code)."""
    check_step_types((m, s, ws, opt, u), engine_types())
    symbol = load_step()

    def codegen(context, builder, signature, args):
        i64 = ir.IntType(64)
        fnty = ir.FunctionType(i64, [cgutils.voidptr_t] * 4 + [ir.DoubleType().as_pointer(), i64])
        fn = cgutils.get_or_insert_function(builder.module, fnty, symbol)
        commands = context.make_array(u)(context, builder, args[4])
        n_u = cgutils.unpack_tuple(builder, commands.shape)[0]
        return builder.call(fn, list(args[:4]) + [commands.data, n_u])
    return types.int64(m, s, ws, opt, u), codegen


def child_main():
    """The child process of compile/parts.py: compile the parts' C function into numba's
    cache, from the sources its parent compiles the step from (an engine edited meanwhile:
    exit 3, and the parent compiles them; caches.py leaves the caches alone in such a
    child)."""
    if os.environ.get(caches.CHILD_HASH, caches.ENGINE_HASH) != caches.ENGINE_HASH:
        raise SystemExit(3)
    _LOADING.append(True)    # the parts never call the step: do not compile it here
    parts.publish_table()
    with code_layout():
        parts.PARTS.compile()
