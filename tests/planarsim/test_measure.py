"""planarsim.measure on a model of the user's own: joint angles agree with the state, the
whole-step summary of a passive walker's record gives sin(slope) as cost of transport."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import measure


def _double_pendulum():
    b = ps.ModelBuilder(dt=1e-3)
    a = b.add_body("upper", mass=1.0, inertia=0.02, pos=(0.25, 1.0))
    c = b.add_body("lower", mass=1.0, inertia=0.02, pos=(0.75, 1.0))
    b.add_pin("shoulder", None, a, anchor_world=(0.0, 1.0))
    b.add_pin("elbow", a, c, anchor_world=(0.5, 1.0))
    return b.compile()


def test_joint_angles_of_a_recording_match_the_state_at_each_frame():
    model = _double_pendulum()
    sim = ps.Simulator(model)
    traj = sim.run(1.0, record_every=10)
    series = measure.joint_angles(traj, model)
    assert set(series) == {"shoulder", "elbow"}
    for k in (0, len(traj.t) // 2, len(traj.t) - 1):
        for name in ("shoulder", "elbow"):
            ang, rate = measure.pin_angle_rate(model, traj.q[k], traj.v[k], name)
            assert series[name][0][k] == pytest.approx(ang, abs=1e-12)
            assert series[name][1][k] == pytest.approx(rate, abs=1e-12)
    # the elbow bends: the lower link swings further than the upper one
    assert np.ptp(series["elbow"][0]) > 0.1
    with pytest.raises(KeyError, match="wrist"):
        measure.pin_angle_rate(model, traj.q[0], traj.v[0], "wrist")


def test_summary_of_a_passive_walk_gives_sin_slope():
    import walkers
    mod = walkers.load("simplest-walker")
    # 10 s: the first landing ends a swing that began before the run (no lift before it), so
    # it is not a whole step's start
    traj, raw, model = mod.simulate(10.0)
    s = measure.summary(traj, model, min_air=0.0)
    slope = mod.Params().slope
    assert s["whole_steps"] >= 5
    # the energy the walk loses per weight and horizontal distance: tan(slope) horizontally
    assert s["cost_of_transport"] == pytest.approx(math.tan(slope), rel=0.02)
    assert s["distance"] > 0 and s["mean_speed"] > 0
