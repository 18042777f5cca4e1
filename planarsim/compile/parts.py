"""The step's parts (fast mode): long kernels, most of them rarely run, compiled into a C
function of their own that the step calls through a table of addresses, so that a first-ever
start compiles them in a child process while this one compiles the rest of the step
(compile/fast_step.py load_step).

A part is declared with compile/decorators.py's ``part``: its argument types ("model",
"state", "workspace", "options" or a numba scalar type's name) and its return type (a scalar
type's name, or None). The parts are compiled into one C function (Parts: a numba cfunc
cached on disk like the step, its callees inlined into it as into the step) that runs the
part its first argument names. Callers call it by address, read from a table at the call (a
load and an indirect call: nanoseconds; the contact solve's parts run rarely, the shape
pairs' search once a step per pair in reach); the table is published under one symbol
(table_symbol()) and filled, by load_step, before any code that calls a part is compiled or
loaded (a part's caller, when typed, calls load_step as the step's does).

Why: numba's typing, lowering and LLVM's optimisation run on one core. With the contact
solve's complementarity parts compiled beside the step's core on a second core, the first-ever
compile takes the longer of the two, not their sum (README: "The first compile").

PART_NAMES fixes each part's number: both processes, and every cached caller, agree on it
whatever order the kernel modules are imported in.
"""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys

import llvmlite.binding as ll
import numpy as np
from llvmlite import ir
from numba import types
from numba.core.ccallback import CFunc
from numba.core.errors import TypingError
from numba.core.typeconv import Conversion
from numba.extending import intrinsic

from .decorators import PART_SCALARS, PART_TABLES

# every part, by module and name: its index is its number (parts_c's `which`)
PART_NAMES = (
    "planarsim.kernels.complementarity.solve_contacts",
    "planarsim.kernels.complementarity.project_positions",
    "planarsim.kernels.position._settle_measured",
    "planarsim.kernels.pair.find_pair",
)
# the parts' C function's address (kept alive for the process: compiled code reads it)
_TABLE = np.zeros(1, np.uint64)
_PARTS = {}          # name -> Part
_PUBLISHED = []
_SYMBOL = []
_PROBE_FAILED = []   # numba moved what load_cached reads: no child, compile() loads or compiles
CHILD_SWITCH = "PLANARSIM_COMPILE_CHILD"   # "0": never compile parts in a child process
# how long a child may still compile once this process has compiled the step: CHILD_WAIT
# times this process's own compile, at least CHILD_WAIT_MIN [s] (the two take about as
# long); a child still running then is taken as stuck
CHILD_WAIT = 2.0
CHILD_WAIT_MIN = 60.0


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
        engine = dict(zip(PART_TABLES, engine_types()))
        args = tuple(engine[a] if a in engine else getattr(types, a) for a in self.args)
        return args, (types.none if self.returns is None else getattr(types, self.returns))

    def slots(self):
        """For each argument, its position among the C function's arguments (after `which`)."""
        counts, out = dict.fromkeys(PART_SCALARS, 0), []
        width = slot_counts()
        for a in self.args:
            if a in PART_TABLES:
                out.append(PART_TABLES.index(a))
            else:
                k = PART_SCALARS.index(a)
                out.append(len(PART_TABLES) + sum(width[x] for x in PART_SCALARS[:k]) + counts[a])
                counts[a] += 1
        return out


def slot_counts():
    """{scalar type: how many arguments of that type the C function takes} (the most any
    part takes)."""
    return {x: max(p.args.count(x) for p in all_parts()) for x in PART_SCALARS}


class Parts:
    """The parts' one C function: parts_c(which, model, state, workspace, options, float64...,
    int64..., boolean...) -> float64 runs part `which` (PART_NAMES' order) on the arguments
    it takes and returns its result as a float64 (0 for none; an int64's counts are exact).
    One C function, so that LLVM optimises and emits the kernels the parts share once."""

    def __init__(self):
        self.cfunc = None
        self.missed = False       # not in numba's cache when loaded: compiled in this run
        self._wrapper = None

    def signature(self):
        from .fast_step import engine_types
        width = slot_counts()
        scalars = [getattr(types, x) for x in PART_SCALARS for _ in range(width[x])]
        return (types.int64, *engine_types(), *scalars), types.float64

    def wrapper(self):
        """The Python function the C function is compiled from (a function of this file, so
        that numba caches it)."""
        if self._wrapper is None:
            width = slot_counts()
            names = ["m", "s", "ws", "opt"] + [f"{x[0]}{k}" for x in PART_SCALARS
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
    except (AttributeError, TypeError):
        _PROBE_FAILED.append(True)
        return False
    return True


def table_symbol() -> str:
    """The table's symbol: named after every part's name, argument and return types, which
    set the C function's arguments, so that compiled code built for other parts never links."""
    if not _SYMBOL:
        text = "|".join(f"{p.name}{p.args}{p.returns}" for p in all_parts())
        digest = hashlib.blake2b(text.encode(), digest_size=8).hexdigest()
        _SYMBOL.append("planarsim_parts_" + digest)
    return _SYMBOL[0]


def publish_table():
    """Publish the table's address under table_symbol() (once per process): before any code
    that calls a part is compiled or loaded."""
    if not _PUBLISHED:
        ll.add_symbol(table_symbol(), _TABLE.ctypes.data)
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
        from .fast_step import load_step
        load_step()     # the table published and filled before code that reads it links
        want, ret = p.types()
        for k, (have, need) in enumerate(zip(given, want)):
            conversion = typingctx.can_convert(have, need)
            if have != need and (conversion is None or conversion > Conversion.safe):
                raise TypingError(f"{p.name}: argument {k + 1} is {have}, the part takes {need}")

        def codegen(context, builder, signature, args):
            c_args, c_ret = PARTS.signature()
            table = context.get_c_value(builder, ir.ArrayType(ir.IntType(64), 1),
                                        table_symbol())
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
    """The callable compiled code calls part `fn` by (its kernel `dispatcher`; args and
    returns as decorators.part checked them); see the module's docstring."""
    name = f"{fn.__module__}.{fn.__qualname__}"
    if name not in PART_NAMES:
        raise ValueError(f"part {name} has no slot: add it to compile/parts.py PART_NAMES")
    p = Part(name, dispatcher, args, returns)
    _PARTS[name] = p
    caller = _caller(p)
    caller.py_func = fn
    caller.part = p
    return caller


# ---- compiling the parts beside the step --------------------------------------------------

def missing_parts():
    """None if the parts' C function is loaded (from numba's cache), else PARTS, to build
    (PARTS.missed says which, for a report of what compiled)."""
    publish_table()
    PARTS.missed = not PARTS.load_cached()
    return PARTS if PARTS.missed else None


def _cores() -> int:
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def start_child(parts):
    """Start a child process compiling `parts` (PARTS, or None: nothing to do) into numba's
    cache; None where that cannot help: switched off, one CPU, no interpreter to start (a
    frozen app), numba's cache not readable as planarsim reads it, or an error starting it.
    The child imports from this process's sys.path, in its order."""
    if (parts is None or os.environ.get(CHILD_SWITCH, "") == "0" or _cores() < 2
            or not sys.executable or getattr(sys, "frozen", False) or _PROBE_FAILED):
        return None
    from .caches import CHILD_HASH, ENGINE_HASH
    try:
        env = dict(os.environ, PYTHONSAFEPATH="1")   # not the working folder first: sys.path's
        env[CHILD_SWITCH] = "0"          # the child compiles, it does not start one of its own
        env[_CHILD_PATH] = json.dumps([p for p in sys.path if isinstance(p, str)])
        env[CHILD_HASH] = ENGINE_HASH   # the sources this process compiles the step from
        return subprocess.Popen([sys.executable, "-c", _CHILD_CODE], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
    except Exception:
        return None


_CHILD_PATH = "PLANARSIM_CHILD_SYS_PATH"
_CHILD_CODE = ("import json, os, sys; sys.path[:] = json.loads(os.environ['" + _CHILD_PATH + "']); "
               "from planarsim.compile.parts import child_main; child_main()")


def finish(parts, child, waited=0.0):
    """Load `parts` (None: nothing to do) once `child` (or None) has ended: from the cache it
    wrote, or, where it did not (it failed, or the cache cannot be written), compiled here. A
    child still running CHILD_WAIT times `waited` [s] (this process's own compile) later, and
    at least CHILD_WAIT_MIN [s], is taken as stuck: stopped, and the parts compiled here."""
    if child is not None:
        try:
            child.wait(timeout=max(CHILD_WAIT_MIN, CHILD_WAIT * waited))
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
    """The child process: compile the parts' C function into numba's cache, from the sources
    its parent compiles the step from (an engine edited meanwhile: exit 3, and the parent
    compiles them; caches.py leaves the caches alone in such a child)."""
    from .caches import CHILD_HASH, ENGINE_HASH
    if os.environ.get(CHILD_HASH, ENGINE_HASH) != ENGINE_HASH:
        raise SystemExit(3)
    from . import fast_step
    from .fast import code_layout
    fast_step._LOADING.append(True)    # the parts never call the step: do not compile it here
    publish_table()
    with code_layout():
        PARTS.compile()
