"""numba's compile flags, compared without rebuilding them (the fast mode, compile/mode.py).

Typing a call to any of numba's @overload functions (min, max, int, math, numpy) looks its
implementation up in a cache keyed by the compile flags (a numba TargetConfig). numba hashes
and compares flags by building a dict of all ~40 options, every time: measured on the cold
start, 184 000 such hashes and comparisons took 8 s of the step's 52 s first compile.

Its hash is that of the sorted option *names* (``hash(tuple(sorted(self.values())))`` sorts
the dict's keys), the same for every flags object of a class; here it is computed once per
class. Two flags objects whose explicitly set options are equal have equal values, so
equality answers from those first and builds the dicts only when they differ. Both give what
numba's own methods give, for any flags: the same caches hit, the same code is compiled.
"""
from numba.core.targetconfig import TargetConfig

_PLAIN_EQ = TargetConfig.__eq__
_HASHES = {}


def _hash(self):
    cls = type(self)
    h = _HASHES.get(cls)
    if h is None:
        h = _HASHES[cls] = hash(tuple(sorted(cls.options)))
    return h


def _eq(self, other):
    if type(other) is type(self) and self._values == other._values:
        return True
    return _PLAIN_EQ(self, other)


def install():
    """Replace TargetConfig's hash and equality by the quick ones (once per process)."""
    if TargetConfig.__hash__ is not _hash:
        TargetConfig.__hash__ = _hash
        TargetConfig.__eq__ = _eq
