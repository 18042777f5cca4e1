"""The step as compiled code calls it, and its entries from Python: the same in every mode
(compile/mode.py).

``step(m, s, ws, opt, u)`` advances a State by one step. In the fast mode it is one C function
compiled once and called by address (link/fast_step.py); on plain numba and under
NUMBA_DISABLE_JIT=1 it is an ordinary kernel (in Python, a function pdb can step into).
run_steps, step_entry and run_recorded call it from a loop; step_from_python and the Simulator
reach those through a handle bound once (bind_steps, bind).
"""
import threading
from typing import NamedTuple

import numpy as np
from numba import types
from numba.extending import overload

from ..compile import FAST, MODE, PYTHON, TABLES, jit, kernel, register
from ..kernels.checks.guards import GUARD_BAD_COMMANDS, check_commands
from ..kernels.info import INFO_COMMAND
from ..kernels.record import record_frame
from ..kernels.step import _step
from ..model import ModelArrays
from ..options import StepOptions, check_options
from ..state import State, Workspace, forget_ground_queries
from .engine import check_step_types, engine_types

if TABLES:     # (compile/refs.py uses numba's extension API, which TABLES says is there)
    from ..compile.refs import TableHandle
if MODE == FAST:   # (the fast mode's step uses numba internals the other modes may lack)
    from .fast_step import _ENGINE, load_step, step   # noqa: F401  (re-exported)
    Handle = TableHandle
else:
    _ENGINE = {}

    def load_step():
        """Nothing to publish: the step is an ordinary kernel here."""
        return None

    @kernel
    def _step_checked(m, s, ws, opt, u):
        n_u = u.shape[0]
        if n_u != m.act_kind.shape[0]:
            ws.info[INFO_COMMAND] = n_u   # nothing is read or changed
            return GUARD_BAD_COMMANDS
        code = check_commands(u, ws)
        if code != 0:
            return code
        return _step(m, s, ws, opt, u)

    if MODE == PYTHON:
        step = _step_checked
    else:
        def step(m, s, ws, opt, u):
            """step(m, s, ws, opt, u) -> guard code: advance State s by one step of opt.dt (0:
            m.dt) under actuator commands u (one per actuator). Returns 0 ok, 1 non-finite,
            2 too large (kernels/checks/guards.py), -1 when u does not have one entry per actuator,
            -2 when a command is NaN or infinite (for both nothing is changed)."""
            return _step_checked(m, s, ws, opt, u)

        @overload(step)
        def _step_typed(m, s, ws, opt, u):
            """Name a wrong argument when a caller is typed (as the fast mode's intrinsic)."""
            check_step_types((m, s, ws, opt, u), engine_types())
            return lambda m, s, ws, opt, u: _step_checked(m, s, ws, opt, u)

    if TABLES:
        Handle = TableHandle
    else:
        class Handle:
            """The StepArgs a loop is called with (packed into a table where TABLES)."""
            __slots__ = ("obj",)

            def __init__(self, obj):
                self.obj = obj

            def repack(self, obj):
                self.obj = obj

            def refill(self, obj, name):
                self.obj = obj


@register
class StepArgs(NamedTuple):
    """Everything a step reads and writes but the commands, as one table (Simulator.step)."""
    m: ModelArrays
    s: State
    ws: Workspace
    opt: StepOptions


@jit
def run_steps(args, u, n):
    """n steps of StepArgs args under commands u; returns (guard code, steps completed)."""
    # each call's first step keeps every contact slot as its start, and so does the step
    # after it returns: the State may be changed in place between calls (prev_copy.py)
    args.ws.prev_whole[0] = 1
    code, done = 0, n
    for k in range(n):
        code = step(args.m, args.s, args.ws, args.opt, u)
        if code != 0:
            done = k
            break
    args.ws.prev_whole[0] = 1
    return code, done


@jit
def step_entry(m, s, ws, opt, u):
    """`step` callable from Python (step itself is an intrinsic that only compiled code calls)."""
    code = step(m, s, ws, opt, u)
    ws.prev_whole[0] = 1           # (the State may be changed before the next: prev_copy.py)
    return code


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
    without numba's type dispatch (fast mode: about 1 us a call on top of the step, like
    Simulator.step)."""
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
        handle = Handle(StepArgs(m, s, ws, opt))
        hit = [(m, s, ws), handle, bind_steps(handle), given]
        with _BOUND_LOCK:
            _BOUND[key] = hit
            while len(_BOUND) > _BOUND_SIZE:
                _BOUND.pop(next(iter(_BOUND)), None)
    elif hit[3] is not opt:
        hit[1].refill(StepArgs(m, s, ws, opt), "opt")
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
    ws.prev_whole[0] = 1           # (as run_steps: the State may be changed between calls)
    for i in range(n):
        code = step(m, s, ws, opt, u)
        if code != 0:
            ws.prev_whole[0] = 1
            return code, i, k
        if (s.step[0] % every) == 0 and k < rec.t.shape[0]:
            record_frame(s, ws, rec, k)
            k += 1
    ws.prev_whole[0] = 1
    return 0, n, k


def bind_steps(handle):
    """run_steps for a Handle of StepArgs, called as entry(handle, u, n) without numba's type
    dispatch where the mode allows (the handle's type never changes)."""
    if MODE == FAST:
        return run_steps.compile((handle.numba_type, types.float64[::1], types.int64))
    if TABLES:
        return run_steps
    return lambda h, u, n: run_steps(h.obj, u, n)


def bind(fn, args):
    """Compiled function `fn` for the types of `args`, to be called directly (fast mode: no
    numba type dispatch on each call); `fn` itself in the other modes."""
    if MODE == FAST:
        return fn.compile(tuple(fn.typeof_pyval(a) for a in args))
    return fn
