"""planarsim's compile flags, hashed and compared without rebuilding them (the fast mode,
compile/mode.py), in planarsim's own compiles only.

Typing a call to any of numba's @overload functions (min, max, int, math, numpy) looks its
implementation up in a cache keyed by the compile flags (a numba TargetConfig: the flags on
top of numba's ConfigStack while a function compiles). numba hashes and compares flags by
building a dict of all ~40 options, every time: measured on the cold start, 184 000 such
hashes and comparisons took 8 s of the step's 52 s first compile.

QuickFlags is numba's Flags with a quicker hash and equality, which give numba's own answers
for any flags. numba's hash is that of the sorted option *names*
(``hash(tuple(sorted(self.values())))`` sorts the dict's keys), the same for every flags
object of a class; here it is computed once per class. An option a flags object has not set
reads its class default, so two flags objects of one class are equal when the options set in
either read the same in both: equality compares those few instead of building two dicts of
all the options. Only planarsim's own dispatchers and C functions compile with QuickFlags
(their compiler's ``_customize_flags`` hands them to numba's pipeline, which pushes a copy of
them, of the same class, on its ConfigStack); numba's classes are left as they are, so any
other numba code in the process compiles exactly as without planarsim. Functions numba
compiles of its own accord inside a planarsim compile (an @overload's implementation) start
from numba's own Flags and use numba's hash and equality.
"""
from numba.core.ccallback import CFunc, _CFuncCompiler
from numba.core.compiler import Flags
from numba.core.dispatcher import _FunctionCompiler

_HASHES = {}


class QuickFlags(Flags):
    """numba's Flags, hashed once per class and compared by the options set (module
    docstring)."""

    __slots__ = ()

    def __hash__(self):
        cls = type(self)
        h = _HASHES.get(cls)
        if h is None:
            h = _HASHES[cls] = hash(tuple(sorted(cls.options)))
        return h

    def __eq__(self, other):
        if type(other) is not type(self):
            return Flags.__eq__(self, other)
        mine, theirs = self._values, other._values
        if mine == theirs:
            return True
        # an option set in neither reads its class default in both: only those set in either
        # can differ (numba's getter is ``_values.get(name, option.default)``)
        options = type(self).options
        for name in mine.keys() | theirs.keys():
            default = options[name].default
            if mine.get(name, default) != theirs.get(name, default):
                return False
        return True


# named as numba's: the class name is part of the flags' summary, which numba mangles into
# the symbol of every function compiled with them (so the symbols stay numba's own)
QuickFlags.__name__ = QuickFlags.__qualname__ = Flags.__name__


def quick(flags):
    """A QuickFlags copy of numba flags `flags` (the same options set)."""
    return flags if type(flags) is QuickFlags else QuickFlags(flags)


class QuickFunctionCompiler(_FunctionCompiler):
    """numba's function compiler, compiling with QuickFlags."""

    def _customize_flags(self, flags):
        return quick(super()._customize_flags(flags))


class QuickCFuncCompiler(_CFuncCompiler):
    """numba's C function compiler, compiling with QuickFlags."""

    def _customize_flags(self, flags):
        return quick(super()._customize_flags(flags))


def quick_compiler(compiler, cls=QuickFunctionCompiler):
    """`compiler` (a dispatcher's numba _FunctionCompiler, not yet used) as a `cls`."""
    return cls(compiler.py_func, compiler.targetdescr, compiler.targetoptions, compiler.locals,
               compiler.pipeline_class)


class QuickCFunc(CFunc):
    """numba's C function (numba.cfunc), compiled with QuickFlags."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._compiler = quick_compiler(self._compiler, QuickCFuncCompiler)
