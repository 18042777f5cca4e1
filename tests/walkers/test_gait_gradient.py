"""Gradient tuning of the Simple Biped's gait on its step map's fixed point
(walkers/gait_gradient.py): it raises the tuner's objective from the defaults, its period's
measures are the walk's, and bad input is named."""
import numpy as np
import pytest

from walkers.gait_gradient import GaitObjective, tune_gait
from walkers.simple_biped import objective
from walkers.simple_biped.gait_map import SimpleBipedGaitMap


def test_gradient_tuning_raises_the_objective_from_the_defaults():
    """One gradient step on two gains: a higher score at a stable periodic gait that still
    walks at the speed the controller aims at, its cost of transport lower."""
    r = tune_gait("simple-biped", names=("ds_kd", "energy_gain"), iterations=1)
    assert r.history and not r.stopped
    assert r.best_score > r.start_score
    assert r.best.cost_of_transport < r.start.cost_of_transport
    assert r.best.spectral_radius < 1.0
    target = objective.Params().speed
    assert abs(r.best.speed - target) < 1e-3 * target
    changed = [n for n in objective.Params().names() if r.best_params[n] != getattr(objective.Params(), n)]
    assert set(changed) <= set(r.names) and changed


def test_a_period_of_the_map_is_measured_as_the_walk_measures_it():
    """cycle(x) at the settled section: its speed is the controller's target (the speed loop
    has converged), and a second period from the map's own image measures the same."""
    gm = SimpleBipedGaitMap(settle=10.0)
    first = gm.cycle(gm.x0)
    assert first["duration"] > 0.3 and first["distance"] > 0.3 and first["positive_work"] > 0.0
    assert abs(first["distance"] / first["duration"] - gm.walker.params.speed) < 2e-3
    again = gm.cycle(gm.step_map()(gm.x0))
    for k in ("duration", "distance", "positive_work"):
        assert again[k] == pytest.approx(first[k], rel=1e-2)


def test_bad_input_is_named():
    with pytest.raises(KeyError, match="nobody"):
        GaitObjective("nobody", None)
    with pytest.raises(ValueError, match="gradient tuning takes: simple-biped"):
        GaitObjective("ranger", None)
    with pytest.raises(ValueError, match="hip_mass"):
        GaitObjective("simple-biped", ("hip_mass",))
    with pytest.raises(ValueError, match="iterations=0"):
        tune_gait("simple-biped", iterations=0)
    J = GaitObjective("simple-biped", ("clearance",))
    z = J.z_of(J.base)
    assert np.all((0.0 <= z) & (z <= 1.0))
    assert J.params_at(np.array([2.0])).clearance == J.bounds[0, 1]
