"""gymnasium's planar v5 models driven by their motors, against MuJoCo as the oracle.

From random states (every limited joint within the middle 40 % of its range, the walkers'
roots lifted 1 m; states where MuJoCo meets a contact or limit within the span are left out) and constant controls of 0.3 and 1.0 (random signs),
the joint velocities after 0.02 s are compared with MuJoCo's RK4 at dt = 1e-5 (the exact
motion, to ~1e-9): planarsim at dt / 100 errs at least 20x less than the first-order error
at dt (ours, or MuJoCo's Euler's where ours happens to cancel), and at the file's dt at most RATIO times what MuJoCo's own Euler errs at that
dt. Both are first-order schemes, MuJoCo's in joint coordinates, ours in the bodies'
(maximal) coordinates with the joints held at the step's end; their error constants differ.
Measured over 250 random states per model (`python -m benchmarks.torque_parity`,
benchmarks/results/torque-parity.txt): our error over MuJoCo's Euler's has a median of
0.4-1.0 and a 90th percentile of 0.8-2.5 on every model (HalfCheetah largest 1.23, Reacher
1.00, Walker2d 1.63, Swimmer 3.00), but single states reach 3.2 (Hopper, 2 of 249 above 3),
6.9 (InvertedPendulum, 2 above 3) and 14.6 (InvertedDoublePendulum, 17 above 3, 1 above 8).
RATIO = 8 holds the states this test draws (derandomized in CI), not every state. They are the
schemes' different error constants, not a defect that vanishes as dt shrinks: ours is SHAKE
in the bodies' coordinates (its positions are Verlet's, the Coriolis forces come from the
pins held at the step's end), MuJoCo's Euler takes them at the step's start; each scheme's
error is the sum of a few first-order terms of both signs, and the largest ratios are states
where MuJoCo's happen to cancel (InvertedDoublePendulum's worst: 6e-4 rad/s, a ninth of its
median error, against our 9e-3, about our median); measured at dt / 64 on two of
InvertedDoublePendulum's states the ratio's limit is 2.7 and 6.0. Not even a second-order
scheme meets 3x there: our step read as the leapfrog it is (the start's velocity moved back
and the end's read on by half a kick), second order without the file's damping, errs 5.7
times MuJoCo Euler's at the file's dt on the worst of 80 states
(`python -m benchmarks.torque_parity_orders --no-damping`). Before the position
correction moved the rotors with their links HalfCheetah reached 6.0 (17 of 250 above 3;
test_a_heavy_rotor_...). Before the soft rows
took part in the prediction, the ratio was 47 (Hopper) and Reacher at dt 1e-4 did not
converge at all (its error grew as dt shrank), which both assertions catch. The
armature (a rotor's inertia on a joint's coordinate) is what makes these models hard: a pin
next to a heavy rotor on a light link (Reacher's arm) turns much less than the applied
torque alone would turn it."""
import sys
import types

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed")
sys.modules.setdefault("imageio", types.ModuleType("imageio"))   # (its video recorder only)
import planarsim.envs  # noqa: E402,F401  (registers the environments)
from benchmarks.torque_parity import our_qvel as parity_qvel, start_state  # noqa: E402

NAMES = ["Hopper", "Walker2d", "HalfCheetah", "InvertedPendulum", "InvertedDoublePendulum",
         "Reacher", "Swimmer"]
WALKERS = ("Hopper", "Walker2d", "HalfCheetah")   # a free root: lifted off the ground
SPAN = 0.02                                       # [s] simulated from the start
RATIO = 8.0                                       # see the module's docstring
REFERENCES = {}


def reference(name):
    """(gymnasium's own MuJoCo env for `name`, one per test session; its file's dt [s])."""
    if name not in REFERENCES:
        env = gym.make(f"{name}-v5").unwrapped
        REFERENCES[name] = env, float(env.model.opt.timestep)
    return REFERENCES[name]


def mujoco_qvel(ref, qp, qv, u, dt, integrator):
    """MuJoCo's joint velocities after SPAN at step dt; and how many constraint rows it met."""
    from mujoco_oracle import mujoco_qvel as oracle
    return oracle(mujoco, ref.model, qp, qv, u, dt, integrator, SPAN, data=ref.data)


def our_qvel(name, qp, qv, u, dt):
    """planarsim's joint velocities after SPAN at step dt; and whether a contact or a joint
    limit acted at any of its steps (benchmarks.torque_parity.our_qvel, its audit 0)."""
    qvel, touched, audit = parity_qvel(name, qp, qv, u, dt)
    assert audit == 0
    return qvel, touched


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=int(__import__("os").environ.get("PARITY_EXAMPLES", 4)), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fractions=st.lists(st.floats(0.3, 0.7), min_size=12, max_size=12),
       speeds=st.lists(st.floats(-1.0, 1.0), min_size=12, max_size=12),
       level=st.sampled_from([0.3, 1.0]),
       signs=st.lists(st.sampled_from([-1.0, 1.0]), min_size=6, max_size=6))
def test_motion_under_torque_converges_to_mujoco(name, fractions, speeds, level, signs):
    ref, dt = reference(name)
    qp, qv = start_state(ref, fractions, speeds, 1.0 if name in WALKERS else 0.0)
    u = level * np.asarray(signs[:ref.action_space.shape[0]])
    exact, rows = mujoco_qvel(ref, qp, qv, u, 1e-5, mujoco.mjtIntegrator.mjINT_RK4)
    euler, more = mujoco_qvel(ref, qp, qv, u, dt, mujoco.mjtIntegrator.mjINT_EULER)
    coarse, touched = our_qvel(name, qp, qv, u, dt)
    fine, touched_fine = our_qvel(name, qp, qv, u, dt / 100)
    # nothing touched (a folded leg's foot on its thigh), no limit reached, in either engine:
    # motion under torque alone
    assume(rows + more == 0 and not touched and not touched_fine)
    ours = np.abs(coarse - exact).max()
    finer = np.abs(fine - exact).max()
    theirs = np.abs(euler - exact).max()
    assert ours <= RATIO * theirs, (ours, theirs)
    # (the scale of a first-order error at dt: ours, or MuJoCo's where ours happens to cancel)
    assert finer * 20.0 <= max(ours, theirs), (finer, ours, theirs)


@pytest.mark.parametrize("action", [(1.0, 0.0), (0.3, -0.3)])
def test_reacher_at_a_fine_step_ends_an_env_step_where_mujoco_does(action):
    """Reacher at dt 1e-4, 200 frames (one env step, 0.02 s) from rest: the joint velocities
    within 5 % of MuJoCo's at the same dt (a linearization at the prediction without the
    rotors once ended this step at -121.5 rad/s where MuJoCo gives 3.96)."""
    ref, _ = reference("Reacher")
    qp, qv = ref.init_qpos.copy(), np.zeros(ref.model.nv)
    theirs, rows = mujoco_qvel(ref, qp, qv, np.asarray(action), 1e-4,
                               mujoco.mjtIntegrator.mjINT_EULER)
    ours, touched = our_qvel("Reacher", qp, qv, np.asarray(action), 1e-4)
    assert rows == 0 and not touched
    assert np.abs(ours[:2] - theirs[:2]).max() <= 0.05 * np.abs(theirs[:2]).max()


# A light link next to a heavy rotor: the distal link's inertia about its hinge is about a
# hundredth of the rotor's (armature 0.2 kg m^2), the rest of the chain an ordinary pendulum
ROTOR_CHAIN = """<mujoco model="rotor_chain">
  <option timestep="0.01" gravity="0 0 -9.81"/>
  <worldbody>
    <body name="upper" pos="0 0 0">
      <joint name="shoulder" type="hinge" axis="0 1 0" damping="0.1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>
      <body name="lower" pos="0 0 -0.5">
        <joint name="elbow" type="hinge" axis="0 1 0" armature="0.2"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.012"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" gear="20"/>
    <motor joint="elbow" gear="5"/>
  </actuator>
</mujoco>"""
# measured on these 16 states each (seed 0): largest ratio 1.16 (HalfCheetah; 1.23 over 250
# states) and 1.06 (the chain); 6.0 and 42.5 before the correction moved the rotors with their
# links (HalfCheetah's feet and the chain's elbow took its whole velocity change)
ROTOR_RATIO = 1.5


def _random_cases(ref, count, seed):
    """count (qpos, qvel, ctrl) drawn as the hypothesis test draws them."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        fractions, speeds = rng.uniform(0.3, 0.7, 12), rng.uniform(-1.0, 1.0, 12)
        level, signs = rng.choice([0.3, 1.0]), rng.choice([-1.0, 1.0], 6)
        qp, qv = start_state(ref, fractions, speeds, 0.0)
        yield qp, qv, level * signs[:ref.model.nu]


def _rotor_chain_qvel(qp, qv, u, dt):
    from planarsim.envs.core import PlanarMujocoEnv
    env = PlanarMujocoEnv(ROTOR_CHAIN, frame_skip=1)
    env.set_state(qp, qv)
    for _ in range(int(round(SPAN / dt))):
        env.do_simulation(u, 1)
    assert env.sim.ws.audit.sum() == 0
    return env.data.qvel.copy()


@pytest.mark.parametrize("name", ["HalfCheetah", "rotor chain"])
def test_a_heavy_rotor_shares_the_position_corrections_velocity_change(name):
    """The Newton-SHAKE correction's velocity change (the pins' second-order gap / h) is shared
    by the bodies and the rotors, as the velocity solve shares the impulses: a light link next
    to a heavy rotor then errs as MuJoCo's Euler does (within ROTOR_RATIO on every state), where
    moving the link alone erred up to 6.0x (HalfCheetah's feet) and 42.5x (the chain's elbow)."""
    if name == "HalfCheetah":
        ref, dt = reference(name)
        ref = types.SimpleNamespace(model=ref.model, data=ref.data, init_qpos=ref.init_qpos)
        mm, lift = ref.model, 1.0
    else:
        mm = mujoco.MjModel.from_xml_string(ROTOR_CHAIN)
        ref = types.SimpleNamespace(model=mm, data=mujoco.MjData(mm), init_qpos=np.zeros(mm.nq))
        dt, lift = 0.01, 0.0
    worst = 0.0
    for qp, qv, u in _random_cases(ref, 16, 0):
        qp[1] += lift if name == "HalfCheetah" else 0.0
        exact, rows = mujoco_qvel(ref, qp, qv, u, 1e-5, mujoco.mjtIntegrator.mjINT_RK4)
        euler, more = mujoco_qvel(ref, qp, qv, u, dt, mujoco.mjtIntegrator.mjINT_EULER)
        if name == "HalfCheetah":
            ours, touched = our_qvel(name, qp, qv, u, dt)
        else:
            ours, touched = _rotor_chain_qvel(qp, qv, u, dt), False
        if rows + more or touched:
            continue
        ratio = np.abs(ours - exact).max() / np.abs(euler - exact).max()
        worst = max(worst, ratio)
    assert 0.0 < worst <= ROTOR_RATIO, worst
