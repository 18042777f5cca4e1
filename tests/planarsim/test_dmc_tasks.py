"""planarsim.envs.dmc: the DeepMind Control Suite's planar tasks on planarsim, against
dm_control (the oracle: it is not imported by planarsim itself).

For every registered task: the observation and action spaces and the episode length equal
dm_control's ``suite.load(domain, task)``; gymnasium's env checker passes; a seed gives one
episode bit for bit; reset(seed=s) starts from dm_control's initial state for random=s (the
same draws; cheetah then settles on each engine, so only its draws are compared); and from
the same physical state (dm_control's reset state perturbed, put in both), reward and
observation equal dm_control's to 1e-9, over states whose rewards are not all saturated.
"""
import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
suite = pytest.importorskip("dm_control.suite",
                            reason="dm_control is not installed (pip install dm_control): it is "
                                   "the oracle and ships the suite's model files")

mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed (pip install -e '.[test]')")


def _dm_control_index_compat():
    """dm_control 1.0.50's named indexers list MjModel / MjData fields newer MuJoCo releases
    dropped (mujoco 4.0: flex_vertedge, ...); every ``physics.named`` (which the suite's tasks
    read) then raises AttributeError. Drop the fields this mujoco does not have."""
    from dm_control.mujoco.wrapper.mjbindings import sizes
    for struct, cls in (("mjmodel", mujoco.MjModel), ("mjdata", mujoco.MjData)):
        table = sizes.array_sizes[struct]
        for name in [f for f in table if not hasattr(cls, f)]:
            del table[name]


_dm_control_index_compat()

import planarsim.envs  # noqa: E402,F401  (registers the environments)
from planarsim.envs import dmc  # noqa: E402
from planarsim.envs.rewards import tolerance  # noqa: E402

TASKS = list(dmc.TASKS)
TOL = 1e-9
# tasks whose reward is an indicator (tolerance with margin 0): 0 or 1 only
BINARY = {"pendulum-swingup", "reacher-easy", "reacher-hard", "finger-spin", "finger-turn_easy",
          "finger-turn_hard"}


def dm_load(task, seed=0):
    domain, name = task.split("-", 1)
    return suite.load(domain, name, task_kwargs={"random": seed})


def flat(obs):
    return np.concatenate([np.asarray(v, float).ravel() for v in obs.values()])


def dm_target(physics, env):
    """dm_control's target (reacher's and swimmer's geom, finger's site) in env's plane [m]."""
    model = physics.named.model
    pos = model.geom_pos if "target" in env.frames.geom else model.site_pos
    return pos["target"][list(env.plane_axes)]


def test_every_task_is_registered_and_the_unsupported_are_refused(monkeypatch):
    assert set(dmc.TASKS) == {"cheetah-run", "walker-stand", "walker-walk", "walker-run",
                              "hopper-stand", "hopper-hop", "acrobot-swingup", "cartpole-balance",
                              "cartpole-swingup", "pendulum-swingup", "reacher-easy",
                              "reacher-hard", "swimmer-swimmer6", "point_mass-easy",
                              "finger-spin", "finger-turn_easy", "finger-turn_hard"}
    for task in dmc.TASKS:
        assert f"planarsim/dmc-{task}-v0" in gym.registry
    assert dmc.UNSUPPORTED == {}       # the suite's planar tasks all run
    monkeypatch.setitem(dmc.UNSUPPORTED, "finger-spin", "its joint friction is not modelled")
    with pytest.raises(NotImplementedError, match="'finger-spin' cannot run.*joint friction"):
        dmc.DMCEnv("finger-spin")
    with pytest.raises(ValueError, match="unknown dm_control task 'walker-fly'"):
        dmc.DMCEnv("walker-fly")


@pytest.mark.parametrize("kind, margin, value", [
    ("gaussian", 1.0, 0.1), ("hyperbolic", 0.5, 0.3), ("long_tail", 0.5, 0.1),
    ("reciprocal", 2.0, 0.2), ("cosine", 1.0, 0.0), ("linear", 10.0, 0.0), ("linear", 0.5, 0.5),
    ("quadratic", 1.0, 0.0), ("tanh_squared", 1.5, 0.4)])
def test_tolerance_is_dm_controls(kind, margin, value):
    from dm_control.utils import rewards
    x = np.linspace(-4, 4, 301)
    for bounds in ((0.0, 0.0), (-0.5, 1.0), (1.0, np.inf)):
        ours = tolerance(x, bounds, margin, kind, value)
        theirs = rewards.tolerance(x, bounds, margin, kind, value)

        def theirs_at(xi):
            with np.errstate(invalid="ignore"):          # (theirs at x = inf: inf - inf)
                return rewards.tolerance(xi, bounds, margin, kind, value)
        assert np.array_equal(ours, theirs), (kind, bounds)
        # a float takes math's functions (a dmc step's readings are floats): to an ulp or two
        for xi in np.append(x[::7] + 0.013, [np.nan, np.inf, -np.inf]):
            mine, ref = tolerance(float(xi), bounds, margin, kind, value), theirs_at(xi)
            assert isinstance(mine, float) and (abs(mine - ref) <= 1e-15
                                                or np.isnan(mine) and np.isnan(ref)), (xi, mine, ref)
    with pytest.raises(ValueError, match="lower bound 1 > upper bound 0"):
        tolerance(0.0, (1, 0))


@pytest.mark.parametrize("task", TASKS)
def test_spaces_and_time_limit_are_dm_controls(task):
    theirs = dm_load(task)
    env = gym.make(dmc.env_id(task))
    aspec = theirs.action_spec()
    assert env.action_space.shape == aspec.shape and env.action_space.dtype == aspec.dtype
    assert np.array_equal(env.action_space.low, aspec.minimum)
    assert np.array_equal(env.action_space.high, aspec.maximum)
    n_obs = sum(int(np.prod(s.shape)) for s in theirs.observation_spec().values())
    assert env.observation_space.shape == (n_obs,)
    # observation() names its entries as dm_control's get_observation does, in its order and
    # shapes (a scalar entry a 0-d array)
    env.reset(seed=0)
    ours = {k: v.shape for k, v in env.unwrapped.observation().items()}
    assert list(ours.items()) == [(k, s.shape) for k, s in theirs.observation_spec().items()]
    assert np.all(env.observation_space.low == -np.inf) and np.all(env.observation_space.high == np.inf)
    # dm_control's episode: steps until its count reaches time limit / control step
    assert env.spec.max_episode_steps == int(np.ceil(theirs._step_limit))
    u = env.unwrapped
    assert u.frame_skip == theirs._n_sub_steps
    assert u.dt == pytest.approx(theirs.control_timestep(), rel=1e-12)
    assert u.timestep == theirs.physics.timestep()


@pytest.mark.parametrize("task", TASKS)
def test_env_checker_passes(task):
    from gymnasium.utils.env_checker import check_env
    check_env(gym.make(dmc.env_id(task)).unwrapped, skip_render_check=True)


@pytest.mark.parametrize("task", TASKS)
def test_a_whole_episode_of_random_full_commands_runs(task):
    """Random actions, each at its full range half the time (bang-bang), for a whole episode:
    no error (reacher's wrist, 0.05 N m on 8.33e-5 kg m^2 at dt 0.02, stopped such a run at
    its 675th step while the motor guard left the joint's damper out), and the episode ends
    by dm_control's time limit with finite observations and rewards."""
    env = gym.make(dmc.env_id(task))
    env.reset(seed=5)
    rng = np.random.default_rng(5)
    low, high = env.action_space.low, env.action_space.high
    for steps in range(1, 100_000):
        a = rng.uniform(low, high)
        if rng.random() < 0.5:
            a = np.where(a > 0, high, low)
        obs, r, term, trunc, _ = env.step(a)
        assert np.all(np.isfinite(obs)) and np.isfinite(r) and not term
        if trunc:
            break
    assert steps == env.unwrapped.domain.episode_steps


@pytest.mark.parametrize("task", TASKS)
def test_same_seed_same_episode(task):
    def episode():
        env = gym.make(dmc.env_id(task))
        out = [env.reset(seed=11)[0]]
        env.action_space.seed(3)
        for _ in range(20):
            obs, r, term, trunc, _ = env.step(env.action_space.sample())
            out.append(np.append(obs, r))
        return out
    a, b = episode(), episode()
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    env = gym.make(dmc.env_id(task))
    assert not np.array_equal(env.reset(seed=1)[0], env.reset(seed=2)[0])


@pytest.mark.parametrize("task", TASKS)
def test_reset_draws_dm_controls_initial_state(task):
    theirs = dm_load(task, seed=5)
    ts = theirs.reset()
    env = dmc.DMCEnv(task)
    obs, _ = env.reset(seed=5)
    if task == "cheetah-run":
        # the draws match; the 200 settling steps run on each engine: compare before them
        env.settle, qpos = 0, env.init_qpos.copy()
        dmc._init_cheetah(env, np.random.RandomState(5), qpos, np.zeros(env.model.nv), {})
        fresh = theirs.physics.model.qpos0.copy()
        rs = np.random.RandomState(5)
        limited = theirs.physics.model.jnt_limited == 1
        fresh[limited] = rs.uniform(*theirs.physics.model.jnt_range[limited].T)
        assert np.allclose(qpos, fresh, rtol=0, atol=1e-12)
        return
    q, v = theirs.physics.data.qpos, theirs.physics.data.qvel
    assert np.allclose(env.qpos, q, rtol=0, atol=1e-12) and np.allclose(env.qvel, v, rtol=0, atol=1e-12)
    want = flat(ts.observation)
    # hopper's touch: contact forces (MuJoCo's of the state, planarsim's of the last step);
    # finger starts with no contact (drawn so), its touch 0 in both: compared
    n = len(want) - (2 if task.startswith("hopper") else 0)
    assert np.allclose(obs[:n], want[:n], rtol=0, atol=1e-9), np.abs(obs[:n] - want[:n]).max()
    if env.target is not None:
        assert np.allclose(env.target[list(env.plane_axes)], dm_target(theirs.physics, env))
    # the next episode (no seed) continues the same draws, as dm_control's task does
    theirs.reset()
    env.reset()
    assert np.allclose(env.qpos, theirs.physics.data.qpos, rtol=0, atol=1e-12)
    assert np.allclose(env.qvel, theirs.physics.data.qvel, rtol=0, atol=1e-12)


def perturbed_states(task, theirs, n, rng):
    """n (qpos, qvel, ctrl) near dm_control's reset state: joints turned, speeds set, the
    root's forward speed spread over the task's reward ramp; hopper lifted clear of the floor
    and finger's drawn again until MuJoCo finds no contact (their touch sensors, contact
    forces, then read 0 in both: planarsim's is the force of its last step, none after
    set_state); finger's spinner every other state spun past spin's threshold or turned to
    the target (reward 1)."""
    m = theirs.physics.model
    physics = theirs.physics
    names = [m.id2name(j, "joint") for j in range(m.njnt)]
    base_q, out = physics.data.qpos.copy(), []
    for k in range(n):
        qpos = base_q + rng.normal(0, 0.3, m.nq)
        qvel = rng.normal(0, 1.0, m.nv)
        if task.startswith("finger"):
            hinge = names.index("hinge")
            if k % 2 and task == "finger-spin":
                qvel[hinge] = -rng.uniform(15, 30)
            elif k % 2:
                tx, tz = physics.target_position()
                qpos[hinge] = -np.arctan2(tx, tz) + rng.normal(0, 0.05)
            while True:
                physics.data.qpos[:] = qpos
                physics.forward()
                if physics.data.ncon == 0:
                    break
                qpos[:hinge] = base_q[:hinge] + rng.normal(0, 0.3, hinge)
        ctrl = rng.uniform(-1.2, 1.2, m.nu)
        if "rootx" in names and task.split("-")[0] in ("cheetah", "walker", "hopper"):
            top = {"cheetah-run": 12, "walker-run": 9, "hopper-hop": 2.5}.get(task, 1.5)
            qvel[names.index("rootx")] = rng.uniform(0, top)
        if task.startswith("hopper"):
            qpos[names.index("rootz")] += 0.5     # in the air: no contact force in either
        if task == "pendulum-swingup" and k % 2:
            qpos[:] = rng.normal(0, 0.1, 1)                 # upright: reward 1
        if task == "point_mass-easy" and k % 2:
            qpos[:] = rng.normal(0, 0.015, 2)               # near the target: reward > 0
        out.append((qpos, qvel, ctrl))
    return out


@pytest.mark.parametrize("task", TASKS)
def test_reward_and_observation_equal_dm_controls_from_the_same_state(task):
    rng = np.random.default_rng(2024)
    rewards, worst_r, worst_o = [], 0.0, 0.0
    for seed in (0, 1, 2):
        theirs = dm_load(task, seed)
        theirs.reset()
        env = dmc.DMCEnv(task)
        env.reset(seed=seed)
        physics = theirs.physics
        for i, (qpos, qvel, ctrl) in enumerate(perturbed_states(task, theirs, 4, rng)):
            physics.data.qpos[:], physics.data.qvel[:] = qpos, qvel
            physics.set_control(ctrl)
            physics.forward()
            if task.startswith("reacher") and i % 2:
                # the target on the finger (+- a little): reward 1 in the indicator
                tip = physics.named.data.geom_xpos["finger", :2] + rng.normal(0, 0.003, 2)
                physics.named.model.geom_pos["target", :2] = tip
                physics.forward()
            if env.target is not None:
                env.set_target(*dm_target(physics, env))
            env.set_state(qpos, qvel)
            env.set_control(ctrl)
            r_dm = theirs.task.get_reward(physics)
            r = env.reward()
            o_dm, o = flat(theirs.task.get_observation(physics)), env._get_obs()
            worst_r = max(worst_r, abs(r - r_dm))
            worst_o = max(worst_o, float(np.abs(o - o_dm).max()))
            rewards.append(r_dm)
    print(f"{task}: reward max |diff| {worst_r:.3g}, observation {worst_o:.3g}")
    assert worst_r <= TOL and worst_o <= TOL, (worst_r, worst_o)
    rewards = np.array(rewards)
    if task in BINARY:
        assert set(rewards) == {0.0, 1.0}, rewards
    else:
        assert np.any((rewards > 0.01) & (rewards < 0.99)), rewards


@pytest.mark.parametrize("task", ["cheetah-run", "walker-walk", "hopper-hop", "swimmer-swimmer6",
                                  "finger-turn_easy"])
def test_sensors_equal_dm_controls_from_the_same_state(task):
    """env.sensor(name) of every sensor of the file but touch (MuJoCo's soft contact force)
    equals dm_control's physics.named.data.sensordata[name] to 1e-9 from perturbed states:
    subtreelinvel, velocimeter, gyro, framepos, framexaxis, frameyaxis, jointpos, jointvel."""
    rng = np.random.default_rng(7)
    theirs = dm_load(task, 0)
    theirs.reset()
    env = dmc.DMCEnv(task)
    env.reset(seed=0)
    physics = theirs.physics
    names = [(kind, name) for kind, name, _ in env.frames.sensors if kind != "touch"]
    assert names
    worst = 0.0
    for qpos, qvel, _ in perturbed_states(task, theirs, 4, rng):
        physics.data.qpos[:], physics.data.qvel[:] = qpos, qvel
        physics.forward()
        if env.target is not None:
            env.set_target(*dm_target(physics, env))
        env.set_state(qpos, qvel)
        for kind, name in names:
            ours = np.atleast_1d(env.sensor(name))
            ref = np.asarray(physics.named.data.sensordata[name])
            assert ours.shape == ref.shape, (name, ours.shape, ref.shape)
            worst = max(worst, float(np.abs(ours - ref).max()))
    print(f"{task}: sensors {sorted({k for k, _ in names})} max |diff| {worst:.3g}")
    assert worst <= TOL, worst


def test_point_mass_episode_is_dm_controls_until_a_slide_reaches_its_limit():
    """point_mass-easy has no contacts and moves linearly (a damped mass under constant
    forces): planarsim's step is MuJoCo's Euler step, so an episode away from the slides'
    limits (+-0.29 m; MuJoCo's are soft, planarsim's hard) equals dm_control's to 1e-12."""
    theirs = dm_load("point_mass-easy", 3)
    ts = theirs.reset()
    env = dmc.DMCEnv("point_mass-easy")
    obs, _ = env.reset(seed=3)
    rng = np.random.default_rng(3)
    assert np.allclose(obs, flat(ts.observation), rtol=0, atol=1e-12)
    for _ in range(200):
        action = rng.uniform(-0.3, 0.3, 2)
        ts = theirs.step(action)
        obs, reward, *_ = env.step(action)
        assert not env.sim.state.limit_active.any()
        assert np.allclose(obs, flat(ts.observation), rtol=0, atol=1e-12)
        assert abs(reward - ts.reward) <= 1e-12


def test_hopper_touch_sensors_carry_its_weight_on_the_floor_and_read_zero_in_the_air():
    """hopper's touch (log1p of the toe's and heel's normal force): standing straight on its
    foot, the two carry its weight (within 5 %) at the first step, the toe's share the
    one nearer the centre of mass's side; lifted, both are 0."""
    env = dmc.DMCEnv("hopper-stand")
    env.reset(seed=0)
    qpos, qvel = env.init_qpos.copy(), np.zeros(env.model.nv)
    env.set_state(qpos, qvel)
    qpos[env.qindex("rootz")] -= env.xpos("foot")[2] - 0.04     # the capsule on the floor
    env.set_state(qpos, qvel)
    env.do_simulation(np.zeros(4), 1)
    toe, heel = np.expm1(env._get_obs()[-2:])
    weight = env._mass.sum() * 9.81
    assert toe > 0 and heel > 0 and abs(toe + heel - weight) <= 0.05 * weight, (toe, heel, weight)
    # the heel (x = -0.08) is nearer the centre of mass (x ~ 0) than the toe (x = 0.17)
    assert heel > toe
    qpos[env.qindex("rootz")] += 0.5
    env.set_state(qpos, qvel)
    env.do_simulation(np.zeros(4), 1)
    assert np.array_equal(env._get_obs()[-2:], [0.0, 0.0])


def test_cross_entropy_learns_cartpole_balance():
    """examples/learn_dmc_cartpole.py on a small budget (3 iterations of 12 policies over
    200-step episodes, ~2 s): the learned linear policy returns at least 280 of 300 on unseen
    300-step episodes; random actions (105-207 measured) and no action (~215) do not."""
    import importlib
    import sys
    from pathlib import Path
    examples = str(Path(__file__).resolve().parents[2] / "examples")
    if examples not in sys.path:
        sys.path.insert(0, examples)
    ex = importlib.import_module("learn_dmc_cartpole")
    out = ex.learn(iterations=3, population=12, elite=4, horizon=200, eval_episodes=2,
                   eval_horizon=300, progress=False)
    assert min(out["eval_returns"]) >= 280.0, out["eval_returns"]
    assert ex.random_return(episodes=3, horizon=300) < 280.0
    env = gym.make(ex.ENV)
    assert ex.episode_return(env, np.zeros(len(ex.FEATURES)), 10_000, 300) < 280.0
    means = [m for _, m, _ in out["history"]]
    assert means[-1] > means[0], means


def test_vector_env_steps_a_dmc_task_as_sync_vector_env_does():
    """PlanarVectorEnv (two processes) and gymnasium's SyncVectorEnv give walker-walk's
    copies the same episodes bit for bit."""
    from gymnasium.vector import AutoresetMode, SyncVectorEnv
    from planarsim.envs.vector import PlanarVectorEnv
    eid = dmc.env_id("walker-walk")
    ours = PlanarVectorEnv(eid, num_envs=4, workers=2)
    sync = SyncVectorEnv([lambda: gym.make(eid) for _ in range(4)],
                         autoreset_mode=AutoresetMode.NEXT_STEP)
    try:
        assert np.array_equal(ours.reset(seed=3)[0], sync.reset(seed=3)[0])
        rng = np.random.default_rng(0)
        for _ in range(10):
            act = rng.uniform(-1, 1, (4, 6))
            a, b = ours.step(act), sync.step(act)
            assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    finally:
        ours.close()
        sync.close()


@pytest.mark.parametrize("task", ["finger-spin", "finger-turn_hard"])
def test_finger_reset_redraws_as_dm_control_until_no_contact(task):
    """finger's start: dm_control draws the joint angles again while MuJoCo finds a contact;
    planarsim redraws while two of its colliding shapes overlap (their exact gap). Over 40
    seeds the starts equal dm_control's, some of them after a redraw, and none overlaps."""
    from planarsim.start_check import shape_overlaps
    env = dmc.DMCEnv(task)
    redrawn = 0
    for seed in range(40):
        theirs = dm_load(task, seed)
        theirs.reset()
        env.reset(seed=seed)
        assert np.allclose(env.qpos, theirs.physics.data.qpos, rtol=0, atol=1e-12), seed
        assert theirs.physics.data.ncon == 0
        assert not shape_overlaps(env.sim_model, env.sim.state.q), seed
        rs = np.random.RandomState(seed)
        if task != "finger-spin":
            rs.uniform(-np.pi, np.pi)                  # the target's angle
        lo, hi = theirs.physics.model.jnt_range[:2].T
        first = [rs.uniform(lo[0], hi[0]), rs.uniform(lo[1], hi[1]), rs.uniform(-np.pi, np.pi)]
        redrawn += not np.array_equal(first, env.qpos)
    assert redrawn >= 2, redrawn


def test_finger_touch_reads_the_fingertips_push_on_the_spinner():
    """finger's touch (log1p of the normal force [N] in each fingertip site): the fingertip's
    end set on the spinner's flat side level with its hinge (the force's line through the
    proximal joint and the hinge: the spinner stays), the distal motor pressing with a
    torque of 20 N times the distal joint's lever arm: after 2 s touchtop reads that force
    within 1 % and touchbottom, whose site the contact is outside, 0; pulled back, both 0."""
    from scipy.optimize import least_squares
    env = dmc.DMCEnv("finger-turn_easy")
    env.reset(seed=0)
    qpos, qvel = env.init_qpos.copy(), np.zeros(env.model.nv)
    tip_end = (-0.2, 0.4 - 0.18 - 0.161)         # the fingertip capsule's end, file pose [m]
    face = 0.2 - 0.02 - 0.04                     # cap2's flat side at hinge angle 0 [m]
    goal = np.array([face - 0.03 - 1e-4, 0.4])   # its sphere 0.1 mm clear of the side

    def miss(x):
        qpos[:2] = x
        env.set_state(qpos, qvel)
        return env.point("distal", tip_end) - goal
    qpos[:2] = least_squares(miss, [0.5, -0.5]).x
    assert np.abs(miss(qpos[:2])).max() < 1e-6     # [m], against the 0.1 mm clearance
    force = 20.0
    arm = env.xpos("distal")[2] - goal[1]         # the distal joint above the force's line
    press = force * arm / 15.0                    # the distal motor's gear: 15 N m
    env.set_state(qpos, qvel)
    for _ in range(100):
        obs = env.step(np.array([0.0, press]))[0]
    top, bottom = np.expm1(obs[7:9])
    print(f"finger touch: top {top:.4f} N for {force} N, bottom {bottom}, "
          f"hinge {env.qvel[2]:.2g} rad/s")
    assert abs(top - force) <= 0.01 * force and bottom == 0.0, (top, bottom)
    assert abs(env.qvel[env.qindex("hinge")]) < 1e-3
    env.set_state(qpos, qvel)
    for _ in range(20):
        obs = env.step(np.array([0.0, -press]))[0]
    assert np.array_equal(obs[7:9], [0.0, 0.0])


# hopper.xml's toe site and touch sensor, and the file changed at one of them
TOE_SITE = '<site name="touch_toe" pos=".17 0 0"/>'
TOE_TOUCH = '<touch name="touch_toe" site="touch_toe"/>'
CHANGED_HOPPER = {
    # (an ellipsoid: a touch on a sphere reads the same at any rotation and is read)
    "ellipsoid": (TOE_SITE, '<site name="touch_toe" pos=".17 0 0" euler="0 30 0" '
                            'type="ellipsoid" size=".05 .03 .03"/>'),
    "sphere": (TOE_SITE, '<site name="touch_toe" pos=".17 0 0" euler="0 30 0"/>'),
    # a geom set by fromto is turned to its axis
    "fromto": (TOE_TOUCH, TOE_TOUCH + '\n    <framexaxis name="foot_x" objtype="geom" '
                                      'objname="foot"/>'),
    # a frame read relative to another object (it was read in the world's)
    "relative": (TOE_TOUCH, TOE_TOUCH + '\n    <framepos name="toe_rel" objtype="site" '
                                        'objname="touch_toe" reftype="body" refname="torso"/>'),
}


def test_a_sensor_on_a_rotated_site_is_refused_by_name(tmp_path):
    """A touch (or velocimeter, gyro, frame axis) sensor reads its site's frame; planarsim's
    readings take a site's frame to be its body's, so a site rotated in its body (or set by
    fromto) is refused, naming the file, the sensor and the site, rather than read wrongly
    (a velocimeter on a site with euler="0 30 0" read 3 m/s off before); so is a frame read
    relative to another object."""
    import pathlib
    import shutil

    import dm_control
    suite = tmp_path / "suite"
    shutil.copytree(pathlib.Path(dm_control.__file__).parent / "suite", suite)
    hopper = suite / "hopper.xml"
    text = hopper.read_text()

    def read(change, sensor):
        if change is not None:
            old, new = CHANGED_HOPPER[change]
            assert old in text
        hopper.write_text(text if change is None else text.replace(old, new))
        env = dmc.DMCEnv("hopper-hop", suite_dir=str(suite))
        env.reset(seed=0)
        return env.sensor(sensor)

    for change, sensor, refusal in (
            ("ellipsoid", "touch_toe", r"hopper\.xml.*site 'touch_toe'.*rotated"),
            ("fromto", "foot_x", r"'foot_x'.*geom 'foot'.*fromto"),
            ("relative", "toe_rel", r"'toe_rel'.*relative to body 'torso'")):
        with pytest.raises(NotImplementedError, match=refusal):
            read(change, sensor)
    # a rotated sphere reads as an unrotated one, which reads as the file as shipped
    assert np.all(np.isfinite(read(None, "touch_toe")))
    assert np.array_equal(read("sphere", "touch_toe"), read(None, "touch_toe"))
