"""The step's linkage: one C function, published once per process, that all code calls.

The step (kernels/step.py) is compiled once, as a C function (a numba cfunc, cached on disk),
and every compiled caller (run_steps, run_recorded, step_entry, each walker's rollout, your
own) calls it by address through the intrinsic ``step``. A plain numba call would link the
step's code into each caller, where LLVM optimises and compiles it again: that was most of
the first-ever start-up (about 15 s per rollout).

A caller's machine code names the step by a symbol (``planarsim_step_<hash of the engine
types>``) that LLVM resolves when the caller is compiled or loaded from the numba cache. The
symbol is therefore published (load_step) before any such code exists in a process: by the
dispatcher of every `jit` function before it compiles or loads code (_jit.CallerDispatcher),
and by the intrinsic when a caller is typed. Loading takes about 0.1 s from the cache plus
numba's own set-up on the first compile of a process; the first-ever compile takes most of
the cold start. Importing this module compiles nothing, so a command that only imports
walkers (to list them, say) is quick. Decorate your own code that calls ``step`` with
planarsim.compiled.jit: a plain numba.njit(cache=True) function loaded from the cache in a
new process would name a symbol nothing has published yet.
"""
import hashlib
import threading
from typing import NamedTuple

import llvmlite.binding as ll
import numpy as np
from llvmlite import ir
from numba import cfunc, types
from numba.core import cgutils
from numba.core.compiler_lock import global_compiler_lock
from numba.core.errors import TypingError
from numba.extending import intrinsic

from ..model import ModelArrays
from ..options import StepOptions, check_options
from ..state import State, Workspace, forget_ground_queries
from . import refs
from ._jit import KERNEL_OPTIONS, code_layout, jit
from .guards import GUARD_BAD_COMMANDS, check_commands
from .info import INFO_COMMAND
from .record import record_frame
from .step import _step

_ENGINE = {}
_LOADING = []     # this thread is compiling the step (see load_step)


def engine_types():
    """(model, state, workspace, options) numba types the step is compiled for."""
    if "types" not in _ENGINE:
        from ..builder import ModelBuilder
        from ..state import make_state, make_workspace
        b = ModelBuilder()
        body = b.add_body("b", 1.0, 1.0)
        b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
        b.add_point_contact("c", body, (0.0, 0.0))
        b.add_pin_motor("m", "p")
        model = b.compile()
        samples = (model.arrays, make_state(model), make_workspace(model), StepOptions())
        found = tuple(refs.TableRef(refs.layout_of(x)) for x in samples)
        text = "|".join(t.name for t in found)
        symbol = "planarsim_step_" + hashlib.blake2b(text.encode(), digest_size=8).hexdigest()
        _ENGINE.update(symbol=symbol, types=found)     # one update: another thread sees both or none
    return _ENGINE["types"]


def _step_c(m, s, ws, opt, u_data, n_u):
    if n_u != m.act_kind.shape[0]:
        ws.info[INFO_COMMAND] = n_u   # nothing is read or changed: the actuators would read past u
        return GUARD_BAD_COMMANDS
    u = refs.array_1d(u_data, n_u)
    code = check_commands(u, ws)
    if code != 0:
        return code
    return _step(m, s, ws, opt, u)


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
                sig = types.int64(*engine_types(), types.CPointer(types.float64), types.int64)
                with code_layout():
                    entry = cfunc(sig, cache=True, **KERNEL_OPTIONS)(_step_c)
                ll.add_symbol(_ENGINE["symbol"], entry.address)
                _ENGINE["cfunc"] = entry
            finally:
                _LOADING.clear()
    engine_types()
    return _ENGINE["symbol"]


@intrinsic
def step(typingctx, m, s, ws, opt, u):
    """step(m, s, ws, opt, u) -> guard code: advance State s by one step of opt.dt (0: m.dt)
    under actuator commands u (float64, C-contiguous, one per actuator). Callable from compiled code.
    Returns 0 ok, 1 non-finite, 2 too large (kernels/guards.py), -1 when u does not have one
    entry per actuator, -2 when a command is NaN or infinite (for both nothing is changed;
    planarsim.errors.diverged explains any code)."""
    expected = engine_types()
    for name, got, want in zip(("model", "state", "workspace", "options"), (m, s, ws, opt), expected):
        if got != want:
            raise TypingError(f"step: {name} is {got}; the step is compiled for {want} "
                              "(pass model.arrays, a State, a Workspace and StepOptions)")
    if not (isinstance(u, types.Array) and u.dtype == types.float64 and u.ndim == 1 and u.layout == "C"):
        raise TypingError(f"step: commands u must be a C-contiguous 1-d float64 array, got {u}")
    symbol = load_step()

    def codegen(context, builder, signature, args):
        i64 = ir.IntType(64)
        fnty = ir.FunctionType(i64, [cgutils.voidptr_t] * 4 + [ir.DoubleType().as_pointer(), i64])
        fn = cgutils.get_or_insert_function(builder.module, fnty, symbol)
        commands = context.make_array(u)(context, builder, args[4])
        n_u = cgutils.unpack_tuple(builder, commands.shape)[0]
        return builder.call(fn, list(args[:4]) + [commands.data, n_u])
    return types.int64(m, s, ws, opt, u), codegen


@refs.register
class StepArgs(NamedTuple):
    """Everything a step reads and writes but the commands, as one table (Simulator.step)."""
    m: ModelArrays
    s: State
    ws: Workspace
    opt: StepOptions


@jit
def run_steps(args, u, n):
    """n steps of StepArgs args under commands u; returns (guard code, steps completed)."""
    for k in range(n):
        code = step(args.m, args.s, args.ws, args.opt, u)
        if code != 0:
            return code, k
    return 0, n


@jit
def step_entry(m, s, ws, opt, u):
    """`step` callable from Python (step itself is an intrinsic that only compiled code calls)."""
    return step(m, s, ws, opt, u)


# step_from_python's bound entries, by the identity of (model arrays, state, workspace):
# NamedTuples cannot change, so a handle packed once stays right while it is held; a new
# StepOptions (options._replace(dt=...), say) only rewrites the options' few slots
_BOUND = {}
_WS_MODEL = {}   # workspace (its contact_found array) -> the model arrays it last stepped
_BOUND_SIZE = 32
_BOUND_LOCK = threading.Lock()


def step_from_python(m, s, ws, opt, u):
    """One step of `step` from Python for a model's arrays, State, Workspace and StepOptions of
    your own; returns the guard code (0 ok; planarsim.errors.diverged explains any other).
    The four are packed into one handle on their first call and the compiled loop is called
    without numba's type dispatch (about 1 us a call on top of the step, like Simulator.step)."""
    key = (id(m), id(s), id(ws))
    hit = _BOUND.get(key)
    given = opt
    if hit is None or hit[3] is not given:
        opt = check_options(given)       # a NaN or negative dt, say, named here
    if hit is None or hit[0][0] is not m or hit[0][1] is not s or hit[0][2] is not ws:
        with _BOUND_LOCK:
            last = _WS_MODEL.get(id(ws.contact_found))
            if last is not None and last is not m:
                # a workspace stepped with another model: its ground queries were of that one
                forget_ground_queries(ws)
            _WS_MODEL[id(ws.contact_found)] = m
            while len(_WS_MODEL) > _BOUND_SIZE:
                _WS_MODEL.pop(next(iter(_WS_MODEL)), None)
        handle = refs.TableHandle(StepArgs(m, s, ws, opt))
        entry = run_steps.compile((handle.numba_type, types.float64[::1], types.int64))
        hit = [(m, s, ws), handle, entry, given]
        with _BOUND_LOCK:
            _BOUND[key] = hit
            while len(_BOUND) > _BOUND_SIZE:
                _BOUND.pop(next(iter(_BOUND)), None)
    elif hit[3] is not opt:
        field = hit[1].layout.by_name["opt"]
        refs.fill(opt, field[6], hit[1].table, field[5])
        hit[3] = given
    if not (type(u) is np.ndarray and u.dtype == np.float64 and u.ndim == 1 and u.flags.c_contiguous):
        u = np.ascontiguousarray(u, dtype=np.float64)
        if u.ndim != 1:
            raise ValueError("step_from_python: commands u must be 1-d (one per actuator), "
                             f"got shape {u.shape}")
    return hit[2](hit[1], u, 1)[0]


@jit
def run_recorded(m, s, ws, opt, u, n, every, rec, k0):
    """n steps under constant u, recording every `every`-th step into rec from frame k0.
    Returns (guard code, steps completed, next frame index)."""
    k = k0
    for i in range(n):
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i, k
        if (s.step[0] % every) == 0 and k < rec.t.shape[0]:
            record_frame(s, ws, rec, k)
            k += 1
    return 0, n, k
