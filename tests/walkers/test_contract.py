"""Every shipped walker meets the walker contract (walkers/base.py): the same module attributes,
the same simulate() keywords, a summary the common summary can read."""
import pytest

import walkers
from walkers.base import contract_problems
from walkers.common.summary import REPLACED


@pytest.mark.parametrize("name", sorted(walkers.WALKERS))
def test_every_walker_meets_the_contract(name):
    mod = walkers.load(name)
    assert contract_problems(name, mod) == []
    traj, summary, model = mod.simulate(0.2)
    assert "fell" in summary and "audit" in summary and ("time" in summary or "duration" in summary)
    undeclared = [k for k in summary if k not in REPLACED and k not in mod.SUMMARY_EXTRAS]
    assert not undeclared
    assert len(traj.t) > 0 and model.n_body > 0


def test_the_contract_check_names_what_is_missing():
    import types
    fake = types.SimpleNamespace(NAME="other", GAITS=("walk",), Params=object, SUMMARY_EXTRAS={"x": ("x_m",)},
                                 simulate=lambda duration, gait="run": None)
    problems = contract_problems("fake", fake)
    assert any("registered as 'fake'" in p for p in problems)
    assert any("lacks the keywords" in p for p in problems)
    assert any("WalkerParams" in p for p in problems)
    assert any("SUMMARY_EXTRAS['x']" in p for p in problems)
