"""The Simple Biped walks, stands and jumps in simulation.

Every test uses the shipped default parameters (``SimpleBipedParams()``); only the commanded
gait, the target speed and the terrain differ. The walker always starts at rest, standing.
"""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain as T
from walkers import simple_biped as sb
from walkers.simple_biped.controller import MEM, Controller, State

PARAMS = sb.SimpleBipedParams()
L0 = PARAMS.leg_length


def walk_until(walker, distance, t_max, chunk=5.0):
    """Run `walker` in chunks until its hip has advanced `distance` [m], it fell, or t_max [s]."""
    while (walker.state.t < t_max and not walker.fell
           and walker.state.q[0, 0] - walker.x_start < distance):
        walker.run(chunk)
    return walker.trajectory()


def hip_clearance(traj, model):
    """Hip height above the ground below it [m], per frame."""
    return traj.q[:, 0, 1] - model.terrain.height(traj.q[:, 0, 0])


def assert_walked(walker, traj, distance):
    x = traj.q[:, 0, 0]
    assert not walker.fell, f"fell at t={walker.state.t:.2f} s, x={x[-1]:.2f} m"
    assert x[-1] - x[0] >= distance, f"covered only {x[-1] - x[0]:.2f} m in {traj.t[-1]:.1f} s"
    # the hip never came down toward the ground; the feet are the model's only contacts
    assert hip_clearance(traj, walker.model).min() > 0.6 * L0
    assert walker.model.contact_names == ("foot0", "foot1")
    # walking means stepping, with both feet on the ground in turn
    assert walker.summary()["steps"] >= distance / (2 * PARAMS.step_length(walker.memory[MEM.speed]))


def speed_over_last(traj, distance):
    """Mean hip speed [m/s] over the last `distance` metres of the trajectory."""
    x, t = traj.q[:, 0, 0], traj.t
    i = np.searchsorted(x, x[-1] - distance)
    return (x[-1] - x[i]) / (t[-1] - t[i])


@pytest.mark.parametrize("speed", [0.5, 1.0, 1.5])
def test_walks_100m_on_flat_ground_at_the_target_speed(speed):
    w = sb.Run(gait="walk", speed=speed)
    traj = walk_until(w, 100.0, t_max=100.0 / speed * 2 + 20)
    assert_walked(w, traj, 100.0)
    v = speed_over_last(traj, 50.0)
    assert abs(v - speed) <= 0.1 * speed, f"mean speed over the last 50 m {v:.3f} m/s, target {speed}"


def steep_hills():
    """Sum of sines with slopes up to 12 degrees and about a third of a leg length between
    crest and trough (default_hills scaled up slightly)."""
    return T.hills([0.1245, 0.0467], [7.0, 2.9], [0.0, 1.3])


def test_hills_terrain_is_as_steep_as_the_seed_claims():
    terr = steep_hills()
    x = np.linspace(-20.0, 150.0, 400001)
    assert T.max_slope_deg(terr, -20.0, 150.0) >= 12.0
    assert np.ptp(terr.height(x)) >= L0 / 3


@pytest.mark.parametrize("speed", [0.5, 1.0, 1.5])
@pytest.mark.parametrize("terrain", [steep_hills(), T.slope(5.0), T.slope(-5.0)],
                         ids=["hills-12deg", "up-5deg", "down-5deg"])
def test_walks_100m_over_hills_and_slopes_from_rest(terrain, speed):
    w = sb.Run(gait="walk", terrain=terrain, speed=speed)
    traj = walk_until(w, 100.0, t_max=100.0 / speed * 2 + 20)
    assert_walked(w, traj, 100.0)


def test_stands_30s_with_the_hip_at_its_set_height():
    w = sb.Run(gait="stand")
    traj = w.run(30.0)
    assert not w.fell
    settled = traj.t > 2.0
    set_height = 0.5 * (traj.q[:, 1, 1] + traj.q[:, 2, 1]) + PARAMS.stand_height * L0
    err = np.abs(traj.q[settled, 0, 1] - set_height[settled])
    assert err.max() < 0.01, f"hip off its set height by {err.max():.4f} m"
    assert np.all(traj.contact_mode[settled] == 1)  # both feet stay planted
    assert np.all(traj.labels["state"] == State.STAND)


def flights(traj, model, min_gap=0.01):
    """Number of separate intervals with both feet off the ground by more than min_gap [m]."""
    gap = traj.q[:, 1:, 1] - model.terrain.height(traj.q[:, 1:, 0])
    airborne = np.all(traj.contact_mode == 0, axis=1) & np.all(gap > min_gap, axis=1)
    return int(np.sum(airborne[1:] & ~airborne[:-1]) + airborne[0])


def test_jumps_then_walks_then_stands_switched_at_run_time():
    w = sb.Run(gait="stand")
    w.run(1.0)
    w.set_gait("jump")
    jumps = w.run(9.0)
    assert flights(jumps, w.model) >= 5
    assert w.summary()["jumps"] >= 5
    assert not w.fell
    w.set_gait("walk")
    walk = w.run(20.0)
    assert not w.fell
    assert walk.q[-1, 0, 0] - walk.q[0, 0, 0] > 5.0
    assert np.any(walk.labels["state"] == State.WALK_SINGLE)
    w.set_gait("stand")
    stand = w.run(10.0)
    assert not w.fell
    assert stand.labels["state"][-1] == State.STAND
    assert abs(stand.v[-1, 0]).max() < 1e-3  # at rest
    set_height = 0.5 * (stand.q[-1, 1, 1] + stand.q[-1, 2, 1]) + PARAMS.stand_height * L0
    assert abs(stand.q[-1, 0, 1] - set_height) < 0.01
    # the recorded labels follow the requested gaits
    whole = w.trajectory()
    gait = whole.labels["gait"].astype(int)
    switches = gait[np.r_[True, gait[1:] != gait[:-1]]]
    assert switches.tolist() == [sb.Gait.STAND, sb.Gait.JUMP, sb.Gait.WALK, sb.Gait.STAND]
    assert hip_clearance(whole, w.model).min() > 0.6 * L0


def test_simulate_returns_trajectory_summary_and_model():
    traj, summary, model = sb.simulate(5.0, gait="walk", terrain="flat")
    assert summary["distance"] > 1.0 and not summary["fell"]
    assert summary["steps"] > 2
    # the actuators did at least the work that became kinetic energy of the walking body
    ke = 0.5 * model.arrays.body_mass @ np.sum(traj.v[-1, :, :2] ** 2, axis=1)
    assert summary["positive_work"] >= ke
    assert 0.0 < summary["cost_of_transport"] < 5.0
    assert set(traj.labels) >= {"gait", "state", "stance", "phase"}
    assert len(traj.labels["state"]) == len(traj.t)
    assert model.act_names == ("leg0", "leg1", "hip")
    assert sb.NAME == "simple-biped" and sb.GAITS == ("stand", "walk", "jump")


def test_compiled_rollout_and_python_controller_give_the_same_run():
    w = sb.Run(gait="walk", record_every=1)
    fast = w.run(3.0)
    sim = ps.Simulator(w.model)
    ctrl = Controller(PARAMS, gait=sb.Gait.WALK)
    slow = sim.run(3.0, controller=ctrl, control_every=1, record_every=1)
    np.testing.assert_array_equal(fast.q, slow.q)
    np.testing.assert_array_equal(fast.act_u, slow.act_u)


def test_leg_actuators_and_hip_torque_are_internal_forces():
    # in free fall (no ground below), actuators cannot move the centre of mass off its parabola
    w = sb.Run(gait="jump", record_every=1)
    w.state.q[:, 1] += 50.0  # lift the standing walker high above the ground
    com0 = w.model.arrays.body_mass @ w.state.q[:, :2] / w.model.total_mass
    traj = w.run(0.5)
    com = traj.com(w.model)
    g = w.model.arrays.gravity
    n = np.round(traj.t / w.model.dt)
    expected = com0 + g * w.model.dt ** 2 * (n * (n + 1) / 2)[:, None]  # symplectic Euler
    assert np.abs(com - expected).max() < 1e-9
    assert np.abs(traj.act_u).max() > 1.0  # the controller did act


def test_bad_gait_and_parameters_are_rejected_by_name():
    with pytest.raises(ValueError, match="hop"):
        sb.Run(gait="hop")
    with pytest.raises(ValueError, match="stand_height"):
        sb.SimpleBipedParams(stand_height=math.nan)
