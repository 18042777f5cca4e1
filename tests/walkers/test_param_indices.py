"""The controllers read parameters through I_<FIELD> index constants written out in each
walker's params.py; they must match the dataclass's field order (a new or moved field without
its constant would read the wrong number)."""
import importlib

import pytest

from walkers.common.params import index_constants


@pytest.mark.parametrize("module, cls", [("walkers.simple_biped.params", "SimpleBipedParams"),
                                         ("walkers.quadruped.params", "QuadrupedParams")])
def test_index_constants_match_the_field_order(module, cls):
    mod = importlib.import_module(module)
    expected = index_constants(getattr(mod, cls))
    written = {k: getattr(mod, k, None) for k in expected}
    assert written == expected
    # and no stale constant of a removed field is left behind
    stale = {k for k in vars(mod) if k.startswith("I_") and k not in expected}
    assert not stale
