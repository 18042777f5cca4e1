"""numba's compile flags, compared without rebuilding them (the fast mode, compile/mode.py).

Typing a call to any of numba's @overload functions (min, max, int, math, numpy) looks its
implementation up in a cache keyed by the compile flags (a numba TargetConfig). numba hashes
and compares flags by building a dict of all ~40 options, every time: measured on the cold
start, 184 000 such hashes and comparisons took 8 s of the step's 52 s first compile.

Its hash is that of the sorted option *names* (``hash(tuple(sorted(self.values())))`` sorts
the dict's keys), the same for every flags object of a class; here it is computed once per
class. An option a flags object has not set reads its class default, so two flags objects
of one class are equal when the options set in either read the same in both: equality
compares those few instead of building two dicts of all the options (which, with every
flags object of a class hashing alike, took 2 s of the cold start in typing's cache
lookups). Both give what
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
    if type(other) is not type(self):
        return _PLAIN_EQ(self, other)
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


def install():
    """Replace TargetConfig's hash and equality by the quick ones (once per process)."""
    if TargetConfig.__hash__ is not _hash:
        TargetConfig.__hash__ = _hash
        TargetConfig.__eq__ = _eq
