"""The step's parts (fast mode): long, rarely run kernels compiled as C functions of their own,
which the step calls through a table of addresses, so that a first-ever start compiles them in
a child process while this one compiles the rest of the step (compile/fast_step.py load_step).

A part is declared with compile/decorators.py's ``part``: its argument types ("model",
"state", "workspace", "options" or a numba scalar type's name) and its return type (a scalar
type's name, or None). Its callers then call it by address, read from the table at the call
(a load and an indirect call: nanoseconds, on paths that run rarely); the table is published
under one symbol (TABLE_SYMBOL) before any code that calls a part is compiled or loaded, and
filled once the parts are loaded, before the step runs. Each part is a numba cfunc cached on
disk like the step; its callees are inlined into it as into the step.

Why: numba's typing, lowering and LLVM's optimisation run on one core. With the contact
solve's complementarity parts compiled beside the step's core on a second core, the first-ever
compile takes the longer of the two, not their sum (README, "First run").

PART_NAMES fixes each part's slot in the table: both processes, and every cached caller,
agree on it whatever order the kernel modules are imported in.
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
)
TABLE_SYMBOL = "planarsim_parts_" + hashlib.blake2b("|".join(PART_NAMES).encode(),
                                                    digest_size=8).hexdigest()
# the table of the parts' addresses (kept alive for the process: compiled code reads it)
_TABLE = np.zeros(len(PART_NAMES), np.uint64)
_PARTS = {}          # name -> Part
_PUBLISHED = []
_ENGINE_ARGS = ("model", "state", "workspace", "options")
CHILD_SWITCH = "PLANARSIM_COMPILE_CHILD"   # "0": never compile parts in a child process
# a child still compiling after this long [s] (a stuck process) is stopped, and its parts are
# compiled here
CHILD_TIMEOUT = 900.0


class Part:
    """One part: its kernel, argument and return types, slot, and its C function once loaded."""

    def __init__(self, name, dispatcher, args, returns):
        self.name = name
        self.dispatcher = dispatcher
        self.args = tuple(args)
        self.returns = returns
        self.index = PART_NAMES.index(name)
        self.cfunc = None
        self._wrapper = None

    def signature(self):
        """The numba types (args, return) of the part's C function."""
        from .fast_step import engine_types
        engine = dict(zip(_ENGINE_ARGS, engine_types()))
        args = tuple(engine[a] if a in engine else getattr(types, a) for a in self.args)
        ret = types.int64 if self.returns is None else getattr(types, self.returns)
        return args, ret

    def wrapper(self):
        """The Python function the C function is compiled from: a call of the kernel (a
        function of this file, so that numba caches it; its name is the part's)."""
        if self._wrapper is None:
            names = [f"a{i}" for i in range(len(self.args))]
            call = f"kernel({', '.join(names)})"
            body = f"    return {call}\n" if self.returns else f"    {call}\n    return 0\n"
            qualname = "part_" + self.name.rsplit(".", 2)[-2] + "_" + self.name.rsplit(".", 1)[-1]
            space = {"kernel": self.dispatcher, "__name__": __name__}
            exec(compile(f"def {qualname}({', '.join(names)}):\n{body}", __file__, "exec"), space)
            self._wrapper = space[qualname]
        return self._wrapper

    def load_cached(self) -> bool:
        """Load the part's C function from numba's cache; False if it is not cached."""
        if self.cfunc is None:
            args, ret = self.signature()
            c = new_cfunc(self.wrapper(), args, ret)
            if load_cached(c):
                self._set(c)
        return self.cfunc is not None

    def compile(self):
        """Compile the part's C function here (or load it from the cache)."""
        if self.cfunc is None:
            args, ret = self.signature()
            c = new_cfunc(self.wrapper(), args, ret)
            c.compile()
            self._set(c)

    def _set(self, c):
        self.cfunc = c
        _TABLE[self.index] = c.address


def new_cfunc(pyfunc, args, ret):
    """numba's C function of pyfunc for numba types args -> ret, cached, not yet compiled."""
    from .fast import KERNEL_OPTIONS
    c = CFunc(pyfunc, (args, ret), {}, dict(KERNEL_OPTIONS))
    c.enable_caching()
    return c


def load_cached(c) -> bool:
    """Load C function c (new_cfunc) from numba's cache, as its compile() does on a hit;
    False, and nothing compiled, on a miss."""
    cres = c._cache.load_overload(c._sig, c._targetdescr.target_context)
    if cres is None:
        return False
    c._cache_hits += 1
    c._library = cres.library
    c._wrapper_name = cres.fndesc.llvm_cfunc_wrapper_name
    c._wrapper_address = c._library.get_pointer_to_function(c._wrapper_name)
    return True


def publish_table():
    """Publish the table's address under TABLE_SYMBOL (once per process): before any code
    that calls a part is compiled or loaded."""
    if not _PUBLISHED:
        ll.add_symbol(TABLE_SYMBOL, _TABLE.ctypes.data)
        _PUBLISHED.append(True)


def all_parts():
    """Every Part, in table order (their kernel modules imported)."""
    import importlib
    for name in PART_NAMES:
        if name not in _PARTS:
            importlib.import_module(name.rsplit(".", 1)[0])
    return [_PARTS[name] for name in PART_NAMES]


def _caller(p: Part):
    """The intrinsic that compiled code calls part p by: its address read from the table."""
    names = [f"a{i}" for i in range(len(p.args))]

    def typer(typingctx, *given):
        want, ret = p.signature()
        for k, (have, need) in enumerate(zip(given, want)):
            if have != need and not (isinstance(need, (types.Number, types.Boolean))
                                     and isinstance(have, (types.Number, types.Boolean))):
                raise TypingError(f"{p.name}: argument {k + 1} is {have}, the part takes {need}")
        shown = types.none if p.returns is None else ret

        def codegen(context, builder, signature, args):
            i64 = ir.IntType(64)
            table = context.get_c_value(builder, ir.ArrayType(i64, len(PART_NAMES)), TABLE_SYMBOL)
            slot = builder.gep(table, [ir.Constant(ir.IntType(32), 0),
                                       ir.Constant(ir.IntType(32), p.index)])
            fnty = ir.FunctionType(context.get_value_type(ret),
                                   [context.get_value_type(t) for t in want])
            fn = builder.inttoptr(builder.load(slot), fnty.as_pointer())
            cast = [context.cast(builder, v, have, need)
                    for v, have, need in zip(args, signature.args, want)]
            out = builder.call(fn, cast)
            return context.get_dummy_value() if p.returns is None else out
        return shown(*given), codegen

    space = {"typer": typer}
    exec(f"def call(typingctx, {', '.join(names)}):\n    return typer(typingctx, {', '.join(names)})\n",
         space)
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
        if a not in _ENGINE_ARGS and not isinstance(getattr(types, a, None), (types.Number, types.Boolean)):
            raise ValueError(f"part {name}: argument type {a!r} is not an engine table or a "
                             "numba scalar type's name")
    p = Part(name, dispatcher, args, returns)
    _PARTS[name] = p
    caller = _caller(p)
    caller.py_func = fn
    caller.part = p
    return caller


# ---- compiling the parts beside the step --------------------------------------------------

def missing_parts():
    """The parts not yet loaded, after trying numba's cache for each."""
    publish_table()
    return [p for p in all_parts() if not p.load_cached()]


def start_child(parts):
    """Start a child process compiling `parts` into numba's cache; None where that cannot
    help (switched off, no interpreter to start, or an error starting it)."""
    if (not parts or os.environ.get(CHILD_SWITCH, "") == "0" or not sys.executable
            or getattr(sys, "frozen", False)):   # (a frozen app's executable is the app)
        return None
    root = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([root] + [p for p in sys.path if p]))
    env[CHILD_SWITCH] = "0"     # the child compiles, it does not start one of its own
    try:
        return subprocess.Popen([sys.executable, "-c",
                                 "from planarsim.compile.parts import child_main; child_main()",
                                 *(p.name for p in parts)], env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None


def finish(parts, child):
    """Load `parts` once `child` (or None) has ended: from the cache it wrote, or, for any it
    did not write (it failed, or the cache cannot be written), compiled here."""
    if child is not None:
        try:
            child.wait(timeout=CHILD_TIMEOUT)
        except subprocess.TimeoutExpired:
            pass
        stop_child(child)
    for p in parts:
        if child is None or not p.load_cached():
            p.compile()


def stop_child(child):
    """Stop `child` (this process's compile failed or was interrupted)."""
    if child is None:
        return
    if child.poll() is None:
        child.kill()
        child.wait()


def child_main():
    """The child process: compile the parts named on the command line into numba's cache."""
    from . import fast_step
    from .fast import code_layout
    fast_step._LOADING.append(True)    # the parts never call the step: do not compile it here
    publish_table()
    wanted = set(sys.argv[1:])
    with code_layout():
        for p in all_parts():
            if p.name in wanted:
                p.compile()
