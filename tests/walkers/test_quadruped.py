"""Planar quadruped (the 2023 robot-dog post): IK puppet, stepping in place, walking forward and
backward through the compiled rollout, and the Python controller path.

Figures for the report: ``python benchmarks/quadruped.py``.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import planarsim as ps
from walkers import WALKERS
from walkers import quadruped as qd
from walkers.quadruped import controller as C
from walkers.quadruped.model import calf_body, hip_pin, knee_pin
from walkers.quadruped.params import leg_reach
from walkers.quadruped.puppet import IK_FAR, IK_HIP_LIMIT, IK_NEAR, IK_NOT_FINITE

P = qd.QuadrupedParams()
L1, L2 = P.thigh_length, P.calf_length
LIMITS = (P.hip_lower, P.hip_upper, P.knee_lower, P.knee_upper)
D_NEAR, D_FAR = leg_reach(P)


def ik(x, y):
    return qd.leg_ik(x, y, L1, L2, *LIMITS)


def foot_heights(model, traj):
    """(K, 4) lowest point of each round foot above flat ground [m]."""
    q = traj.q
    a = model.arrays
    out = np.zeros((len(q), 4))
    for i in range(4):
        b = calf_body(i)
        cx, cy = a.contact_local[i]
        th = q[:, b, 2]
        out[:, i] = q[:, b, 1] + np.sin(th) * cx + np.cos(th) * cy - a.contact_radius[i]
    return out


# inverse kinematics ------------------------------------------------------------------------------

@settings(max_examples=300, deadline=None)
@given(q1=st.floats(P.hip_lower, P.hip_upper), q2=st.floats(P.knee_lower, P.knee_upper))
def test_ik_reaches_reachable_targets(q1, q2):
    """FK of the IK solution lands on any target the leg can reach (within 1e-9 m), unflagged,
    and recovers the joint angles (the solution is unique within the joint limits)."""
    x, y = qd.leg_fk(q1, q2, L1, L2)
    a1, a2, flag = ik(x, y)
    assert flag == 0
    fx, fy = qd.leg_fk(a1, a2, L1, L2)
    assert math.hypot(fx - x, fy - y) < 1e-9
    assert abs(a2 - q2) < 1e-6 and abs(a1 - q1) < 1e-6


@settings(max_examples=300, deadline=None)
@given(angle=st.floats(-math.pi, math.pi), dist=st.floats(0.0, 5.0))
def test_ik_clamps_unreachable_targets(angle, dist):
    """Any target: finite angles within the joint limits; out-of-reach targets are moved along
    their ray to the nearest reachable distance and flagged."""
    x, y = dist * math.sin(angle), -dist * math.cos(angle)
    q1, q2, flag = ik(x, y)
    assert math.isfinite(q1) and math.isfinite(q2)
    assert P.hip_lower <= q1 <= P.hip_upper and P.knee_lower <= q2 <= P.knee_upper
    fx, fy = qd.leg_fk(q1, q2, L1, L2)
    if dist > D_FAR:
        assert flag & IK_FAR
        assert abs(math.hypot(fx, fy) - D_FAR) < 1e-9
    elif dist < D_NEAR:
        assert flag & IK_NEAR
        assert abs(math.hypot(fx, fy) - D_NEAR) < 1e-9
    else:
        assert not flag & (IK_FAR | IK_NEAR)
    if not flag & IK_HIP_LIMIT and dist > 1e-9:
        # same direction as the target
        assert abs(fx * y - fy * x) < 1e-9 * max(dist, 1.0)
        assert fx * x + fy * y > 0


def test_ik_hip_limit_and_nan_are_flagged():
    # foot far in front and up: the hip would pass its upper limit (1.047 rad)
    q1, q2, flag = ik(0.2, 0.2)
    assert flag & IK_HIP_LIMIT and q1 == P.hip_upper
    for bad in ((math.nan, 0.0), (0.0, math.inf)):
        q1, q2, flag = ik(*bad)
        assert flag == IK_NOT_FINITE and math.isfinite(q1) and math.isfinite(q2)


def test_puppet_matches_the_simulated_robot():
    """Posing the puppet at the model's own torso pose and foot centres gives back the model's
    pin angles: puppet and robot share one geometry."""
    model = qd.build(P)
    q0 = model.q0
    feet = np.zeros((4, 2))
    for i in range(4):
        b = calf_body(i)
        cx, cy = model.arrays.contact_local[i]
        th = q0[b, 2]
        feet[i] = q0[b, 0] + math.cos(th) * cx - math.sin(th) * cy, q0[b, 1] + math.sin(th) * cx + math.cos(th) * cy
    tilt = 0.1   # a tilted torso: move the feet with it
    c, s = math.cos(tilt), math.sin(tilt)
    rel = feet - q0[0, :2]
    feet_t = q0[0, :2] + rel @ np.array([[c, s], [-s, c]])
    angles, flags = qd.puppet_pose(P, (q0[0, 0], q0[0, 1], tilt), feet_t)
    assert not flags.any()
    for i in range(4):
        for j, pin in enumerate((hip_pin(i), knee_pin(i))):
            a, b = model.arrays.pin_body[pin]
            ang = q0[b, 2] - (q0[a, 2] if a >= 0 else 0.0) - model.arrays.pin_ref[pin]
            assert abs(angles[i, j] - ang) < 1e-12
    with pytest.raises(ValueError, match="4 foot targets"):
        qd.puppet_pose(P, (0, 0.27, 0), np.zeros((3, 2)))


# interface -------------------------------------------------------------------------------------

def test_registry_interface_and_model():
    assert WALKERS["quadruped"] == "walkers.quadruped"
    assert qd.NAME == "quadruped" and set(qd.GAITS) == {"stand", "piaffe", "walk"}
    traj, summary, model = qd.simulate(0.5, gait="stand")
    assert {"distance", "mean_speed", "steps", "fell"} <= set(summary)
    assert model.n_body == 9 and model.n_pin == 8 and model.n_act == 8 and model.n_contact == 4
    assert abs(model.arrays.body_mass.sum() - P.total_mass) < 1e-12
    assert 11.5 < P.total_mass < 13.0                    # A1: about 12 kg
    # frame 0 is the start state (modes as built); every step keeps the four feet pinned
    assert np.all(traj.contact_mode[1:] == 1), "standing: all four feet stay pinned"
    with pytest.raises(ValueError, match="gallop"):
        qd.simulate(0.1, gait="gallop")
    with pytest.raises(ValueError, match="plant_delay"):
        qd.QuadrupedParams(plant_delay=-1.0)
    with pytest.raises(ValueError, match="stand_height"):
        qd.QuadrupedParams(stand_height=0.39)


def test_python_controller_path_matches_compiled_rollout():
    dog = qd.Run(gait="walk", record_every=1)
    traj_c = dog.run(0.8)
    model = dog.model
    sim = ps.Simulator(model, ps.make_options("all"))
    ctrl = qd.Controller(model, P, gait="walk")
    traj_p = sim.run(0.8, controller=ctrl, record_every=1)
    assert np.array_equal(traj_c.q, traj_p.q)


# stepping and walking ----------------------------------------------------------------------------

def test_piaffe_60s():
    """Trot in place for 60 s: no fall, pitch within 10 deg, drift under 0.5 m, and the feet
    really step (every foot leaves the ground, the pairs alternate)."""
    dog = qd.Run(gait="piaffe", record_every=10)
    traj = dog.run(60.0)
    s = dog.summary()
    assert not s["fell"] and traj.t[-1] > 59.99
    pitch = np.degrees(np.abs(traj.q[:, 0, 2]))
    assert pitch.max() < 10.0
    x = traj.q[:, 0, 0] - dog.x_start
    assert np.abs(x).max() < 0.5
    assert s["steps"] >= 100                          # pair plantings in 60 s
    h = foot_heights(dog.model, traj)
    assert np.all(h.max(axis=0) > 0.04), "every foot lifts clear of the ground"
    assert np.all((traj.contact_mode == 0).mean(axis=0) > 0.1)
    # diagonal pairs move together: FL with RR, FR with RL
    lab = traj.labels
    assert np.array_equal(lab["state_FL"], lab["state_RR"]) and np.array_equal(lab["state_FR"], lab["state_RL"])
    assert not np.any((lab["state_FL"] != 0) & (lab["state_FR"] != 0))
    print(f"piaffe 60 s: steps {s['steps']}, max pitch {pitch.max():.2f} deg, "
          f"max drift {np.abs(x).max() * 1e3:.1f} mm")


def test_walk_forward_20m():
    """Commanded 0.3 m/s: 20 m without falling, mean speed within 20 % of the command."""
    dog = qd.Run(gait="walk", speed=0.3, record_every=20)
    traj = dog.run(70.0)
    s = dog.summary()
    assert not s["fell"], s
    assert s["distance"] >= 20.0, s
    assert abs(s["mean_speed"] - 0.3) < 0.2 * 0.3, s
    assert np.degrees(np.abs(traj.q[:, 0, 2])).max() < 10.0
    assert s["steps"] > 100
    assert 0.0 < s["cost_of_transport"] < 10.0
    print(f"walk 0.3 m/s: {s['distance']:.2f} m in {s['time']:.0f} s, mean speed "
          f"{s['mean_speed']:.3f} m/s, steps {s['steps']}, max pitch {s['max_pitch_deg']:.2f} deg, "
          f"mechanical CoT {s['cost_of_transport']:.2f}")


def test_walk_backward():
    dog = qd.Run(gait="walk", speed=-0.3, record_every=20)
    traj = dog.run(12.0)
    s = dog.summary()
    assert not s["fell"], s
    assert s["distance"] <= -3.0, s
    assert abs(s["mean_speed"] + 0.3) < 0.2 * 0.3, s
    assert np.degrees(np.abs(traj.q[:, 0, 2])).max() < 10.0


def test_gait_switch_at_run_time():
    """Stand, then trot in place, then walk, then stand again, in one run."""
    dog = qd.Run(gait="stand")
    dog.run(1.0)
    assert dog.summary()["steps"] == 0
    dog.set_gait("piaffe")
    dog.run(3.0)
    n = dog.summary()["steps"]
    assert n >= 4
    dog.set_gait("walk", 0.3)
    dog.run(6.0)
    x = dog.summary()["distance"]
    assert x > 1.0
    dog.set_gait("stand")
    dog.run(3.0)
    s = dog.summary()
    assert not s["fell"] and abs(s["distance"] - x) < 0.5
    assert np.all(dog.memory[C.MEM.state:C.MEM.state + 4] == C.F_GROUND)


def test_live_hook_for_the_viewer():
    """The viewer's hook: Python-path controller, gait keys and speed slider act on the run."""
    spec = qd.live(gait="stand")
    sim, ctrl = spec["sim"], spec["controller"]
    sim.run(0.5, controller=ctrl)
    assert ctrl.memory[C.MEM.step_i] == 0
    spec["on_gait"](spec["gait_keys"]["w"])
    spec["gains"]["speed [m/s]"][3](0.3)
    x0 = float(sim.state.q[0, 0])
    sim.run(2.0, controller=ctrl)
    assert ctrl.memory[C.MEM.step_i] >= 3 and sim.state.q[0, 0] - x0 > 0.2


@pytest.mark.parametrize("spec", ["hills", "slope:5", "slope:-5"])
def test_walk_on_uneven_ground(spec):
    """Foot goals follow the terrain (plant height r / cos(slope) above the ground)."""
    dog = qd.Run(gait="walk", speed=0.3, terrain=spec, record_every=50)
    traj = dog.run(15.0)
    s = dog.summary()
    assert not s["fell"], s
    assert abs(s["mean_speed"] - 0.3) < 0.2 * 0.3, s
    assert np.degrees(np.abs(traj.q[:, 0, 2])).max() < 10.0


def test_no_foot_pulls_under_either_strategy():
    """Both contact-mode strategies end every step at a consistent answer: no foot that is in
    contact pulls on the ground on any step (the seed's alternating check alone left lifting
    feet pinned and pulling for up to 3 steps), and the step's own audit counts nothing."""
    pulls = {}
    for strategy in ("all", "alternating"):
        dog = qd.Run(gait="walk", speed=0.3, strategy=strategy, record_every=1)
        traj = dog.run(8.0)
        assert not dog.fell
        normal = traj.contact_impulse[1:, :, 0]
        pulls[strategy] = int(np.sum(normal < -1e-12))
        assert sum(dog.summary()["audit"].values()) == 0, dog.summary()["audit"]
    assert pulls == {"all": 0, "alternating": 0}, pulls


def test_motor_work_is_the_commands_times_the_joints_turns():
    """The positive work a walker reports is what its commands did on the joints' turns,
    sum max(u_k (theta_k+1 - theta_k), 0) over the steps (every step recorded), to rounding
    (counted at the joints' start rates it was 3 % low, and the net work negative); the
    engine's act_power times dt is that work step by step."""
    from planarsim import measure
    run = qd.Run(record_every=1)
    run.run(8.0)
    traj, model = run.trajectory(), run.model
    angles = measure.joint_angles(traj, model)
    theta = np.stack([angles[name][0] for name in model.pin_names], axis=1)
    turns = traj.act_u[1:] * np.diff(theta, axis=0)
    per_step = np.clip(turns, 0.0, None).sum(axis=1)
    done = float(per_step.sum())
    assert run.summary()["motor_work_positive"] == pytest.approx(done, rel=1e-9)
    assert float(turns.sum()) > 0.0         # (the net work: it was negative)
    power = np.clip(traj.act_power[1:], 0.0, None).sum(axis=1) * np.diff(traj.t)
    np.testing.assert_allclose(power, per_step, rtol=1e-6, atol=1e-9 * done)
