"""compile/flags.py: planarsim's compile flags, hashed and compared quickly, give numba's own
answers, and numba's own classes are left as they are."""
import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from planarsim.compile import FAST, MODE

if MODE != FAST:
    pytest.skip("flags.py is the fast mode's only", allow_module_level=True)

from numba.core.compiler import Flags  # noqa: E402
from numba.core.targetconfig import TargetConfig  # noqa: E402

from planarsim.compile import flags  # noqa: E402


def _flags(cls=flags.QuickFlags, **set_options):
    f = cls()
    for name, value in set_options.items():
        setattr(f, name, value)
    return f


# set options: none, some at their default value (set, yet equal to unset), some changed
SETTINGS = [{}, {"nrt": False}, {"nrt": True}, {"nrt": True, "boundscheck": True},
            {"boundscheck": True}, {"no_cpython_wrapper": True, "nrt": True},
            {"error_model": "numpy"}, {"error_model": "python"}]


def test_numbas_classes_keep_their_own_methods():
    """planarsim's quick hash and equality are its own class's: numba's TargetConfig and
    Flags hash and compare as numba wrote them, for every other compile in the process."""
    source = TargetConfig.__hash__.__module__, TargetConfig.__eq__.__module__
    assert source == ("numba.core.targetconfig", "numba.core.targetconfig")
    assert "__hash__" not in Flags.__dict__ and "__eq__" not in Flags.__dict__
    assert flags.QuickFlags.__hash__ is not TargetConfig.__hash__


@pytest.mark.parametrize("a, b", list(itertools.product(SETTINGS, repeat=2)))
def test_equality_and_hash_answer_as_numbas_own(a, b):
    x, y = _flags(**a), _flags(**b)
    plain_x, plain_y = _flags(Flags, **a), _flags(Flags, **b)
    assert (x == y) == (x.values() == y.values()) == (plain_x == plain_y)   # numba's own equality
    assert (x == y) == (y == x)
    assert (x == plain_y) == (plain_y == x) == (plain_x == plain_y)          # mixed with numba's
    if x == y:
        assert hash(x) == hash(y)
    assert hash(x) == hash(tuple(sorted(x.values()))) == hash(plain_x)      # numba's own hash


def test_flags_differing_only_in_options_set_to_their_defaults_are_equal():
    assert _flags() == _flags(nrt=False)                      # nrt's default is False
    assert _flags() != _flags(nrt=True)
    assert _flags().__eq__(object()) is NotImplemented


def test_a_quick_copy_keeps_the_options_and_numbas_symbol_mangling():
    plain = _flags(Flags, nrt=True, boundscheck=True)
    quick = flags.quick(plain)
    assert type(quick) is flags.QuickFlags and quick.values() == plain.values()
    assert type(quick.copy()) is flags.QuickFlags          # numba's pipeline pushes a copy
    assert quick.get_mangle_string() == plain.get_mangle_string()
    assert flags.quick(quick) is quick


def test_planarsims_dispatchers_compile_with_quick_flags():
    from planarsim.compile import fast, parts

    @fast._caller_decorator(cache=False)
    def twice(x):
        return 2.0 * x

    assert twice(1.5) == 3.0
    assert isinstance(twice._compiler, flags.QuickFunctionCompiler)
    assert type(twice._compiler._customize_flags(Flags())) is flags.QuickFlags
    c = parts.new_cfunc(lambda x: x, ((), None), None) if False else None   # (C functions: below)
    assert c is None
    cfunc = flags.QuickCFunc(lambda: 1, ((), __import__("numba").int64), {}, {})
    assert isinstance(cfunc._compiler, flags.QuickCFuncCompiler)
    assert type(cfunc._compiler._customize_flags(Flags())) is flags.QuickFlags


_BOOL_OPTIONS = sorted(name for name, option in Flags.options.items() if option.type is bool)


@given(st.dictionaries(st.sampled_from(_BOOL_OPTIONS), st.booleans(), max_size=6),
       st.dictionaries(st.sampled_from(_BOOL_OPTIONS), st.booleans(), max_size=6))
def test_equality_over_any_set_options_answers_as_numbas_own(a, b):
    x, y = _flags(**a), _flags(**b)
    assert (x == y) == (x.values() == y.values())
    assert (x == y) == (y == x)
