"""The step's parts (fast mode): long, rarely run kernels compiled as C functions of their own,
which the step calls through a table of addresses, so that a first-ever start compiles them in
a child process while this one compiles the rest of the step (compile/fast_step.py load_step).

A part is declared with compile/decorators.py's ``part``: its argument types ("model",
"state", "workspace", "options" or a numba scalar type's name) and its return type (a scalar
type's name, or None). The parts are compiled into one C function (Parts: a numba cfunc
cached on disk like the step, its callees inlined into it as into the step) that runs the
part its first argument names. Callers call it by address, read from a table at the call (a
load and an indirect call: nanoseconds, on paths that run rarely); the table is published
under one symbol (TABLE_SYMBOL) before any code that calls a part is compiled or loaded, and
filled once the parts are loaded, before the step runs.

Why: numba's typing, lowering and LLVM's optimisation run on one core. With the contact
solve's complementarity parts compiled beside the step's core on a second core, the first-ever
compile takes the longer of the two, not their sum (README, "First run").

PART_NAMES fixes each part's number: both processes, and every cached caller, agree on it
whatever order the kernel modules are imported in.
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import llvmlite.binding as ll
import numpy as np
from llvmlite import ir
from numba import types
from numba.core.ccallback import CFunc
from numba.core.errors import TypingError
from numba.extending import intrinsic

# every part, by module and name: the index is its slot in the table
PART_NAMES = (
    "planarsim.kernels.complementarity.solve_contacts",
    "planarsim.kernels.complementarity.project_positions",
    "planarsim.kernels.position._settle_measured",
    "planarsim.kernels.pair.find_pair",
)
TABLE_SYMBOL = "planarsim_parts_" + hashlib.blake2b("|".join(PART_NAMES).encode(),
                                                    digest_size=8).hexdigest()
# the parts' C function's address (kept alive for the process: compiled code reads it)
_TABLE = np.zeros(1, np.uint64)
_PARTS = {}          # name -> Part
_PUBLISHED = []
_ENGINE_ARGS = ("model", "state", "workspace", "options")
_SCALARS = ("float64", "int64", "boolean")
CHILD_SWITCH = "PLANARSIM_COMPILE_CHILD"   # "0": never compile parts in a child process
# a child still compiling after this long [s] (a stuck process) is stopped, and the parts are
# compiled here
CHILD_TIMEOUT = 900.0


class Part:
    """One part: its kernel, argument and return types, and its number (`which`)."""

    def __init__(self, name, dispatcher, args, returns):
        self.name = name
        self.dispatcher = dispatcher
        self.args = tuple(args)
        self.returns = returns
        self.index = PART_NAMES.index(name)

    def types(self):
        """The numba types (args, return) of the kernel as declared."""
        from .fast_step import engine_types
        engine = dict(zip(_ENGINE_ARGS, engine_types()))
        args = tuple(engine[a] if a in engine else getattr(types, a) for a in self.args)
        return args, (types.none if self.returns is None else getattr(types, self.returns))

    def slots(self):
        """For each argument, its position among the C function's arguments (after `which`)."""
        counts, out = dict.fromkeys(_SCALARS, 0), []
        width = slot_counts()
        for a in self.args:
            if a in _ENGINE_ARGS:
                out.append(_ENGINE_ARGS.index(a))
            else:
                k = _SCALARS.index(a)
                out.append(len(_ENGINE_ARGS) + sum(width[x] for x in _SCALARS[:k]) + counts[a])
                counts[a] += 1
        return out


def slot_counts():
    """{scalar type: how many arguments of that type the C function takes} (the most any
    part takes)."""
    return {x: max(p.args.count(x) for p in all_parts()) for x in _SCALARS}


class Parts:
    """The parts' one C function: parts_c(which, model, state, workspace, options, float64...,
    int64..., boolean...) -> float64 runs part `which` (PART_NAMES' order) on the arguments
    it takes and returns its result as a float64 (0 for none; an int64's counts are exact).
    One C function, so that LLVM optimises and emits the kernels the parts share once."""

    def __init__(self):
        self.cfunc = None
        self._wrapper = None

    def signature(self):
        from .fast_step import engine_types
        width = slot_counts()
        scalars = [getattr(types, x) for x in _SCALARS for _ in range(width[x])]
        return (types.int64, *engine_types(), *scalars), types.float64

    def wrapper(self):
        """The Python function the C function is compiled from (a function of this file, so
        that numba caches it)."""
        if self._wrapper is None:
            width = slot_counts()
            names = ["m", "s", "ws", "opt"] + [f"{x[0]}{k}" for x in _SCALARS
                                               for k in range(width[x])]
            lines = [f"def parts_c(which, {', '.join(names)}):"]
            space = {"__name__": __name__}
            for p in all_parts():
                space[f"part{p.index}"] = p.dispatcher
                call = f"part{p.index}({', '.join(names[k] for k in p.slots())})"
                lines.append(f"    if which == {p.index}:")
                lines.append(f"        return float({call})" if p.returns else
                             f"        {call}\n        return 0.0")
            lines.append("    return 0.0")
            exec(compile("\n".join(lines) + "\n", __file__, "exec"), space)
            self._wrapper = space["parts_c"]
        return self._wrapper

    def load_cached(self) -> bool:
        """Load the C function from numba's cache; False if it is not cached."""
        if self.cfunc is None:
            c = new_cfunc(self.wrapper(), *self.signature())
            if load_cached(c):
                self._set(c)
        return self.cfunc is not None

    def compile(self):
        """Compile the C function here (or load it from the cache)."""
        if self.cfunc is None:
            c = new_cfunc(self.wrapper(), *self.signature())
            c.compile()
            self._set(c)

    def _set(self, c):
        self.cfunc = c
        _TABLE[0] = c.address


PARTS = Parts()


def new_cfunc(pyfunc, args, ret):
    """numba's C function of pyfunc for numba types args -> ret, cached, not yet compiled."""
    from .fast import KERNEL_OPTIONS
    c = CFunc(pyfunc, (args, ret), {}, dict(KERNEL_OPTIONS))
    c.enable_caching()
    return c


def load_cached(c) -> bool:
    """Load C function c (new_cfunc) from numba's cache, as its compile() does on a hit;
    False, and nothing compiled, on a miss (or where a numba release moved the attributes
    used: compile() then loads or compiles it)."""
    try:
        cres = c._cache.load_overload(c._sig, c._targetdescr.target_context)
        if cres is None:
            return False
        c._cache_hits += 1
        c._library = cres.library
        c._wrapper_name = cres.fndesc.llvm_cfunc_wrapper_name
        c._wrapper_address = c._library.get_pointer_to_function(c._wrapper_name)
    except AttributeError:
        return False
    return True


def publish_table():
    """Publish the table's address under TABLE_SYMBOL (once per process): before any code
    that calls a part is compiled or loaded."""
    if not _PUBLISHED:
        ll.add_symbol(TABLE_SYMBOL, _TABLE.ctypes.data)
        _PUBLISHED.append(True)


def all_parts():
    """Every Part, in PART_NAMES' order (their kernel modules imported)."""
    import importlib
    for name in PART_NAMES:
        if name not in _PARTS:
            importlib.import_module(name.rsplit(".", 1)[0])
    return [_PARTS[name] for name in PART_NAMES]


def _caller(p: Part):
    """The intrinsic that compiled code calls part p by: the parts' C function, its address
    read from the table, with which = p's number."""
    names = [f"a{i}" for i in range(len(p.args))]

    def typer(typingctx, *given):
        want, ret = p.types()
        for k, (have, need) in enumerate(zip(given, want)):
            if have != need and not (isinstance(need, (types.Number, types.Boolean))
                                     and isinstance(have, (types.Number, types.Boolean))):
                raise TypingError(f"{p.name}: argument {k + 1} is {have}, the part takes {need}")

        def codegen(context, builder, signature, args):
            c_args, c_ret = PARTS.signature()
            table = context.get_c_value(builder, ir.ArrayType(ir.IntType(64), 1), TABLE_SYMBOL)
            slot = builder.gep(table, [ir.Constant(ir.IntType(32), 0)] * 2)
            fnty = ir.FunctionType(context.get_value_type(c_ret),
                                   [context.get_value_type(t) for t in c_args])
            fn = builder.inttoptr(builder.load(slot), fnty.as_pointer())
            values = [ir.Constant(ty, None) for ty in fnty.args]   # arguments p does not take
            values[0] = ir.Constant(fnty.args[0], p.index)
            for k, (v, have, need) in zip(p.slots(), zip(args, signature.args, want)):
                values[1 + k] = context.cast(builder, v, have, need)
            out = builder.call(fn, values)
            if p.returns is None:
                return context.get_dummy_value()
            return context.cast(builder, out, c_ret, ret)
        return ret(*given), codegen

    space = {"typer": typer}
    listed = ", ".join(names)
    exec(f"def call(typingctx, {listed}):\n    return typer(typingctx, {listed})\n", space)
    call = space["call"]
    call.__name__ = call.__qualname__ = p.name.rsplit(".", 1)[-1]
    return intrinsic(call)


def register(fn, dispatcher, args, returns):
    """The callable compiled code calls part `fn` by (its kernel `dispatcher`); see the
    module's docstring."""
    name = f"{fn.__module__}.{fn.__qualname__}"
    if name not in PART_NAMES:
        raise ValueError(f"part {name} has no slot: add it to compile/parts.py PART_NAMES")
    for a in args:
        if a not in _ENGINE_ARGS + _SCALARS:
            raise ValueError(f"part {name}: argument type {a!r} is none of "
                             f"{', '.join(_ENGINE_ARGS + _SCALARS)}")
    if returns not in (None, "float64", "int64"):
        raise ValueError(f"part {name}: returns {returns!r}; a part returns float64, int64 or None")
    p = Part(name, dispatcher, args, returns)
    _PARTS[name] = p
    caller = _caller(p)
    caller.py_func = fn
    caller.part = p
    return caller


# ---- compiling the parts beside the step --------------------------------------------------

def missing_parts():
    """None if the parts' C function is loaded (from numba's cache), else PARTS, to build."""
    publish_table()
    return None if PARTS.load_cached() else PARTS


def start_child(parts):
    """Start a child process compiling `parts` (PARTS, or None: nothing to do) into numba's
    cache; None where that cannot help (switched off, no interpreter to start, or an error
    starting it)."""
    if (parts is None or os.environ.get(CHILD_SWITCH, "") == "0" or not sys.executable
            or getattr(sys, "frozen", False)):   # (a frozen app's executable is the app)
        return None
    root = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([root] + [p for p in sys.path if p]))
    env[CHILD_SWITCH] = "0"     # the child compiles, it does not start one of its own
    try:
        return subprocess.Popen([sys.executable, "-c",
                                 "from planarsim.compile.parts import child_main; child_main()"],
                                env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None


def finish(parts, child):
    """Load `parts` (None: nothing to do) once `child` (or None) has ended: from the cache it
    wrote, or, where it did not (it failed, or the cache cannot be written), compiled here."""
    if child is not None:
        try:
            child.wait(timeout=CHILD_TIMEOUT)
        except subprocess.TimeoutExpired:
            pass
        stop_child(child)
    if parts is not None and (child is None or not parts.load_cached()):
        parts.compile()


def stop_child(child):
    """Stop `child` (this process's compile failed or was interrupted)."""
    if child is not None and child.poll() is None:
        child.kill()
        child.wait()


def child_main():
    """The child process: compile the parts' C function into numba's cache."""
    from . import fast_step
    from .fast import code_layout
    fast_step._LOADING.append(True)    # the parts never call the step: do not compile it here
    publish_table()
    with code_layout():
        PARTS.compile()
