"""Parts (fast mode): long kernels, most of them rarely run, compiled into a C function of
their own that compiled code calls through a table of addresses, so that a first-ever start
can compile them in a child process while this one compiles the rest of the code that calls
them (planarsim/link/fast_step.py: the step's parts beside the step).

A part is declared with compile/decorators.py's ``part``: its argument types (the names of
the tables the layer above binds, "model", "state", "workspace", "options", or a numba scalar
type's name) and its return type (a scalar type's name, or None). The parts are compiled into
one C function (Parts: a numba cfunc cached on disk, its callees inlined into it) that runs
the part its first argument names. Callers call it by address, read from a table at the call
(a load and an indirect call: nanoseconds); the table is published under one symbol
(table_symbol()) and filled before any code that calls a part is compiled or loaded (a
part's caller, when typed, runs the before_compile hooks of compile/fast.py, where the layer
above loads or compiles the parts).

This module knows no part and no table type: the layer above binds them (``bind``: every
part's name in a fixed order, which numbers them, the numba types of the tables and the
module whose ``child_main`` a child process runs). Why a child: numba's typing, lowering and
LLVM's optimisation run on one core; with the parts compiled beside the rest on a second
core, the first-ever compile takes the longer of the two, not their sum.
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
from numba.core.errors import TypingError
from numba.core.typeconv import Conversion
from numba.extending import intrinsic

from .fast import KERNEL_OPTIONS, prepare_compile
from .flags import QuickCFunc
from .part_types import PART_SCALARS, PART_TABLES


class Binding:
    """What the layer above binds the parts to: `names` ("module.function" of every part, in
    an order that numbers them: both processes, and every cached caller, agree on it whatever
    order the modules are imported in), `table_types()` (the numba types of PART_TABLES, in
    order), `child_module` (its child_main() compiles the parts in a child process) and
    `child_env()` (environment variables the child is started with)."""

    def __init__(self, names, table_types, child_module, child_env=dict):
        self.names = tuple(names)
        self.table_types = table_types
        self.child_module = child_module
        self.child_env = child_env


_BINDING = []


def bind(binding: Binding):
    """Bind the parts to `binding` (once per process; the parts already registered must be
    among its names)."""
    if _BINDING and _BINDING[0].names != binding.names:
        raise ValueError("parts: bound twice, to different parts")
    _BINDING[:] = [binding]
    for name in _PARTS:
        _check_listed(name)


def binding() -> Binding:
    if not _BINDING:
        raise RuntimeError("parts: nothing bound them (planarsim/link/fast_step.py binds the "
                           "step's parts on import)")
    return _BINDING[0]


def _check_listed(name):
    if _BINDING and name not in _BINDING[0].names:
        raise ValueError(f"part {name} has no slot: add it to the parts' names "
                         "(planarsim/link/fast_step.py PART_NAMES)")


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

    @property
    def index(self):
        """Its number (parts_c's `which`): its place among the bound names."""
        return binding().names.index(self.name)

    def types(self):
        """The numba types (args, return) of the kernel as declared."""
        engine = dict(zip(PART_TABLES, binding().table_types()))
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
    int64..., boolean...) -> float64 runs part `which` (the bound names' order) on the arguments
    it takes and returns its result as a float64 (0 for none; an int64's counts are exact).
    One C function, so that LLVM optimises and emits the kernels the parts share once."""

    def __init__(self):
        self.cfunc = None
        self.missed = False       # not in numba's cache when loaded: compiled in this run
        self._wrapper = None

    def signature(self):
        width = slot_counts()
        scalars = [getattr(types, x) for x in PART_SCALARS for _ in range(width[x])]
        return (types.int64, *binding().table_types(), *scalars), types.float64

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
    c = QuickCFunc(pyfunc, (args, ret), {}, dict(KERNEL_OPTIONS))
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
    """Every Part, in the bound names' order (the layer above imports their modules)."""
    names = binding().names
    missing = [name for name in names if name not in _PARTS]
    if missing:
        raise RuntimeError(f"parts: {', '.join(missing)} bound but never declared with part()")
    return [_PARTS[name] for name in names]


def _caller(p: Part):
    """The intrinsic that compiled code calls part p by: the parts' C function, its address
    read from the table, with which = p's number."""
    names = [f"a{i}" for i in range(len(p.args))]

    def typer(typingctx, *given):
        prepare_compile()   # the table published and filled before code that reads it links
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
    _check_listed(name)
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
    The child imports from this process's sys.path, in its order, and runs the bound
    child_module's child_main()."""
    if (parts is None or os.environ.get(CHILD_SWITCH, "") == "0" or _cores() < 2
            or not sys.executable or getattr(sys, "frozen", False) or _PROBE_FAILED):
        return None
    try:
        bound = binding()
        env = dict(os.environ, PYTHONSAFEPATH="1")   # not the working folder first: sys.path's
        env.update(bound.child_env())
        env[CHILD_SWITCH] = "0"          # the child compiles, it does not start one of its own
        env[_CHILD_PATH] = json.dumps([p for p in sys.path if isinstance(p, str)])
        code = (f"import json, os, sys; sys.path[:] = json.loads(os.environ['{_CHILD_PATH}']); "
                f"from {bound.child_module} import child_main; child_main()")
        return subprocess.Popen([sys.executable, "-c", code], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
    except Exception:
        return None


_CHILD_PATH = "PLANARSIM_CHILD_SYS_PATH"


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
