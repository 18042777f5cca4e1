"""compile/flags.py: numba's compile flags hashed and compared quickly give numba's own answers."""
import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from planarsim.compile import FAST, MODE

if MODE != FAST:
    pytest.skip("flags.py is installed by the fast mode only", allow_module_level=True)

from numba.core.compiler import Flags  # noqa: E402
from numba.core.targetconfig import TargetConfig  # noqa: E402

from planarsim.compile import flags  # noqa: E402


def _flags(**set_options):
    f = Flags()
    for name, value in set_options.items():
        setattr(f, name, value)
    return f


# set options: none, some at their default value (set, yet equal to unset), some changed
SETTINGS = [{}, {"nrt": False}, {"nrt": True}, {"nrt": True, "boundscheck": True},
            {"boundscheck": True}, {"no_cpython_wrapper": True, "nrt": True},
            {"error_model": "numpy"}, {"error_model": "python"}]


def test_the_quick_methods_are_installed_in_the_fast_mode():
    assert TargetConfig.__hash__ is flags._hash and TargetConfig.__eq__ is flags._eq


@pytest.mark.parametrize("a, b", list(itertools.product(SETTINGS, repeat=2)))
def test_equality_and_hash_answer_as_numbas_own(a, b):
    x, y = _flags(**a), _flags(**b)
    assert (x == y) == (x.values() == y.values())          # numba's own equality
    assert (x == y) == (y == x)
    if x == y:
        assert hash(x) == hash(y)
    assert hash(x) == hash(tuple(sorted(x.values())))       # numba's own hash


def test_flags_differing_only_in_options_set_to_their_defaults_are_equal():
    assert _flags() == _flags(nrt=False)                      # nrt's default is False
    assert _flags() != _flags(nrt=True)
    assert _flags().__eq__(object()) is NotImplemented


_BOOL_OPTIONS = sorted(name for name, option in Flags.options.items() if option.type is bool)


@given(st.dictionaries(st.sampled_from(_BOOL_OPTIONS), st.booleans(), max_size=6),
       st.dictionaries(st.sampled_from(_BOOL_OPTIONS), st.booleans(), max_size=6))
def test_equality_over_any_set_options_answers_as_numbas_own(a, b):
    x, y = _flags(**a), _flags(**b)
    assert (x == y) == (x.values() == y.values())
    assert (x == y) == (y == x)
