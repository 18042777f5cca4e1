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


def _link_angles_rates(q, v):
    """The double pendulum's joint angles and rates from the links' geometry alone (where the
    centres of mass lie and how they move), not from the bodies' angle coordinates: the upper
    link points from the shoulder (0, 1) to its centre, the lower from the elbow (0.25 m
    beyond the upper centre) to its centre; a rate is r x v / |r|^2 of that direction."""
    def cross(a, b):
        return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    r_u = q[:, 0, :2] - np.array([0.0, 1.0])
    w_u = cross(r_u, v[:, 0, :2]) / (r_u * r_u).sum(1)
    elbow = q[:, 0, :2] + r_u                     # the upper link's centre is its middle
    v_elbow = 2.0 * v[:, 0, :2]                   # the shoulder is fixed
    r_l = q[:, 1, :2] - elbow
    w_l = cross(r_l, v[:, 1, :2] - v_elbow) / (r_l * r_l).sum(1)
    phi_u, phi_l = np.arctan2(r_u[:, 1], r_u[:, 0]), np.arctan2(r_l[:, 1], r_l[:, 0])
    # both links start along +x (pin references 0)
    return {"shoulder": (phi_u, w_u), "elbow": (phi_l - phi_u, w_l - w_u)}


def test_joint_angles_of_a_recording_match_the_links_geometry_at_each_frame():
    model = _double_pendulum()
    sim = ps.Simulator(model)
    traj = sim.run(1.0, record_every=10)
    series = measure.joint_angles(traj, model)
    assert set(series) == {"shoulder", "elbow"}
    geometry = _link_angles_rates(traj.q, traj.v)
    for name in ("shoulder", "elbow"):
        ang, rate = series[name]
        want_ang, want_rate = geometry[name]
        # the same angle up to whole turns (the geometry's atan2 wraps, the coordinates do not)
        turns = (ang - want_ang) / (2 * math.pi)
        assert np.abs(turns - np.round(turns)).max() * 2 * math.pi < 1e-9, name
        # the recorded velocities meet the pins' velocity rows to first order in dt at the
        # recorded positions, not exactly (measured: 5.9e-5 and 3.1e-4 rad/s off at rates up to
        # 7.1 and 10.6 rad/s); a rate missing the parent link's would be off by whole rad/s
        assert np.abs(rate - want_rate).max() < 1e-4 * (1.0 + np.abs(want_rate).max()), name
        # one frame alone gives the recording's figures
        for k in (0, len(traj.t) // 2, len(traj.t) - 1):
            assert measure.pin_angle_rate(model, traj.q[k], traj.v[k], name) == pytest.approx(
                (ang[k], rate[k]), abs=1e-12)
    # the elbow bends: the lower link swings further than the upper one
    assert np.ptp(series["elbow"][0]) > 0.1
    with pytest.raises(KeyError, match="wrist"):
        measure.pin_angle_rate(model, traj.q[0], traj.v[0], "wrist")


def test_pin_angle_rate_of_a_wrong_shaped_state_names_it():
    """q of one body's row, or a recording's frames (K, n_body, 3), raised numpy's "too many
    indices for array" or "only 0-dimensional arrays can be converted to Python scalars"."""
    model = _double_pendulum()
    with pytest.raises(ValueError, match=r"measure\.pin_angle_rate: q has shape \(3,\); it must "
                                         r"be \(2, 3\)"):
        measure.pin_angle_rate(model, np.zeros(3), model.v0, "elbow")
    frames = np.stack([model.q0] * 4)
    with pytest.raises(ValueError, match=r"measure\.pin_angle_rate: v has shape \(4, 2, 3\)"):
        measure.pin_angle_rate(model, model.q0, frames, "elbow")


@pytest.mark.parametrize("who", ["centre_of_mass", "energy", "summary", "joint_angles",
                                 "cost_of_transport"])
def test_a_measure_without_a_model_or_trajectory_names_it(who):
    """measure.energy(traj, None) raised "'NoneType' object has no attribute 'n_body'"."""
    model = _double_pendulum()
    traj = ps.Simulator(model).run(0.01)
    with pytest.raises(TypeError, match=rf"measure\.{who}: model=None must be the planarsim "
                                        r"Model"):
        getattr(measure, who)(traj, None)
    with pytest.raises(TypeError, match=rf"measure\.{who}: traj=Model must be a planarsim "
                                        r"Trajectory"):
        getattr(measure, who)(model, model)


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


@pytest.mark.parametrize("who", ["centre_of_mass", "centre_of_mass_velocity", "energy",
                                 "summary", "joint_angles", "cost_of_transport"])
def test_a_measure_of_another_models_recording_names_the_mismatch(who):
    """A recording of a 2-body model measured with a 1-body model raised numpy's broadcast
    error from deep inside."""
    traj = ps.Simulator(_double_pendulum()).run(0.01)
    b = ps.ModelBuilder(dt=1e-3)
    b.add_body("only", mass=1.0, inertia=0.1)
    with pytest.raises(ValueError, match=rf"measure\.{who}: .* 2 bodies per frame but the "
                                         r"model has 1 .*wrong model"):
        getattr(measure, who)(traj, b.compile())


def test_cost_of_transport_of_a_run_in_place_is_nan():
    """A gait in place (the quadruped's piaffe drifted 3 mm while its motors did 39 J)
    reported a CoT of 117: below min_distance (0.1 m, as the walkers' summaries) it is nan."""
    model = _double_pendulum()
    traj = ps.Simulator(model).run(0.05)
    com = traj.com(model)
    moved = abs(com[-1, 0] - com[0, 0])
    assert 1e-12 < moved < measure.MIN_TRANSPORT
    power = np.ones(len(traj.t))
    assert math.isnan(measure.cost_of_transport(traj, model, power)[1])
    work = float(np.sum(power[1:] * np.diff(traj.t)))
    weight = model.total_mass * float(np.hypot(*model.arrays.gravity))
    assert measure.cost_of_transport(traj, model, power, min_distance=0.0)[1] == pytest.approx(
        work / (weight * moved))
    with pytest.raises(ValueError, match=r"min_distance=-1.0 m must be a finite number"):
        measure.cost_of_transport(traj, model, power, min_distance=-1.0)
