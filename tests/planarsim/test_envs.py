"""planarsim.envs: gymnasium's planar v5 tasks on planarsim. The env checker passes; a seed
fixes an episode bit for bit; bad actions raise; and against gymnasium's MuJoCo envs: the
coordinate mapping (body poses and observations for the same qpos/qvel) and, before any
contact, the motion of both pendulums."""
import sys
import types

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
import planarsim.envs  # noqa: E402,F401  (registers the environments)

NAMES = ["Hopper", "Walker2d", "HalfCheetah", "InvertedPendulum", "InvertedDoublePendulum",
         "Reacher", "Swimmer"]


def make(name, **kw):
    return gym.make(f"planarsim/{name}-v0", **kw)


def mujoco_env(name):
    """gymnasium's own v5 env (needs mujoco; imageio only for its video recorder)."""
    mujoco = pytest.importorskip("mujoco", reason="mujoco is not installed")
    sys.modules.setdefault("imageio", types.ModuleType("imageio"))
    return mujoco, gym.make(f"{name}-v5").unwrapped


@pytest.mark.parametrize("name", NAMES)
def test_env_checker_passes(name):
    from gymnasium.utils.env_checker import check_env
    env = make(name)
    check_env(env.unwrapped, skip_render_check=True)


@pytest.mark.parametrize("name", NAMES)
def test_same_seed_same_episode(name):
    def episode():
        env = make(name)
        obs, _ = env.reset(seed=123)
        env.action_space.seed(7)
        out = [obs]
        for _ in range(50):
            obs, r, term, trunc, _ = env.step(env.action_space.sample())
            out.append(np.append(obs, r))
            if term or trunc:
                obs, _ = env.reset()
                out.append(obs)
        return out
    a, b = episode(), episode()
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))
    env = make(name)
    assert not np.array_equal(env.reset(seed=1)[0], env.reset(seed=2)[0])


@pytest.mark.parametrize("name", ["Hopper", "HalfCheetah", "Reacher"])
def test_reset_forgets_the_last_episode(name):
    """A reset is as a new environment: the same seed gives the same episode after any
    history (no contact modes, warm starts or ground queries carry over)."""
    def episode(env, seed, n=40):
        out = [env.reset(seed=seed)[0]]
        rng = np.random.default_rng(seed)
        for _ in range(n):
            out.append(env.step(rng.uniform(-1, 1, env.action_space.shape))[0])
        return out
    fresh = episode(make(name).unwrapped, 5)
    used = make(name).unwrapped
    episode(used, 99, 60)
    assert all(np.array_equal(a, b) for a, b in zip(fresh, episode(used, 5)))


@pytest.mark.parametrize("name", ["Hopper", "InvertedPendulum", "Reacher", "Swimmer"])
def test_bad_actions_raise(name):
    env = make(name)
    env.reset(seed=0)
    n = env.action_space.shape[0]
    with pytest.raises(ValueError, match=r"action has shape \(\d+,\).*takes shape"):
        env.step(np.zeros(n + 1))
    nan = np.zeros(n)
    nan[0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        env.step(nan)


def test_import_without_gymnasium_says_how_to_install(monkeypatch):
    for mod in [m for m in sys.modules if m == "planarsim.envs" or m.startswith("planarsim.envs.")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setitem(sys.modules, "gymnasium", None)
    with pytest.raises(ImportError, match=r"pip install -e '\.\[gym\]'"):
        import planarsim.envs  # noqa: F401


@pytest.mark.parametrize("name", NAMES)
def test_coordinates_and_observation_match_mujoco(name):
    """For the same qpos/qvel (the noise-free start, and a random one): MuJoCo's and our
    observations agree to 1e-9, and each planarsim body's COM and angle are MuJoCo's."""
    mujoco, ref = mujoco_env(name)
    env = make(name).unwrapped
    assert env.coords.names == [mujoco.mj_id2name(ref.model, mujoco.mjtObj.mjOBJ_JOINT, j)
                                for j in range(ref.model.njnt)]
    assert np.array_equal(env.action_space.low, ref.action_space.low)
    assert np.array_equal(env.action_space.high, ref.action_space.high)
    assert env.dt == pytest.approx(ref.dt, rel=1e-12)
    ref.set_state(ref.init_qpos, ref.init_qvel)
    xmat0 = ref.data.xmat.copy()            # the file's pose: planarsim's build pose
    rng = np.random.default_rng(0)
    for qp, qv in [(ref.init_qpos, ref.init_qvel),
                   (ref.init_qpos + rng.uniform(-0.2, 0.2, ref.model.nq), rng.uniform(-1, 1, ref.model.nv))]:
        ref.set_state(qp, qv)
        env.set_state(qp, qv)
        np.testing.assert_allclose(env._get_obs(), ref._get_obs(), rtol=0, atol=1e-9)
        # the compiled map (from the joint table) is the Python one
        st = env.sim.state
        for ours, theirs in zip(env.coords.values(st.q, st.v), env.coords.from_maximal(st.q, st.v)):
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
        # the mapping itself: body COM (mass-weighted over welded MJCF bodies) and angle
        (i1, i2) = (0, 2) if env.loaded.plane == "x-z" else (0, 1)
        q = env.sim.state.q
        for bid, rb in env.loaded.rigid.items():
            ids = [mujoco.mj_name2id(ref.model, mujoco.mjtObj.mjOBJ_BODY, n) for n in rb.mjcf_bodies]
            m = ref.model.body_mass[ids]
            com = (m[:, None] * ref.data.xipos[ids]).sum(0) / m.sum()
            np.testing.assert_allclose(q[bid, :2], (com[i1], com[i2]), atol=1e-9, err_msg=rb.name)
            # rotation since the file's pose, about -y (counter-clockwise in our x-z plane)
            # or +z (x-y plane)
            R = ref.data.xmat[ids[0]].reshape(3, 3) @ xmat0[ids[0]].reshape(3, 3).T
            ang = np.arctan2(R[i2, i1], R[i1, i1])
            d = (q[bid, 2] - env.sim_model.q0[bid, 2]) - ang
            assert abs((d + np.pi) % (2 * np.pi) - np.pi) < 1e-9, rb.name
        # velocities: the derivative of the position map
        e = 1e-7
        q1, _ = env.coords.to_maximal(qp + e * qv, qv)
        q0, v0 = env.coords.to_maximal(qp, qv)
        np.testing.assert_allclose((q1 - q0) / e, v0, atol=1e-5)
    if name == "InvertedDoublePendulum":
        np.testing.assert_allclose(env.tip(), ref.data.site_xpos[0][[0, 2]], atol=1e-9)
    if name == "Reacher":       # the reward's distance and its terms
        ref.set_state(qp, qv)
        env.set_state(qp, qv)
        a = np.array([0.3, -0.2])
        assert env._get_rew(a)[0] == pytest.approx(ref._get_rew(a)[0], abs=1e-9)


# (name, start qpos offsets, start qvel, action, which obs entry must move by > 0.1)
MOTIONS = [("InvertedPendulum", {1: 0.01}, {}, 0.0, 1),
           ("InvertedDoublePendulum", {1: 0.01}, {}, 0.0, 1),
           # the arm swung by its motors (no contact in the file); its hinges' damping and
           # armature implicit in both
           ("Reacher", {0: 0.3, 1: -0.5}, {0: 1.0, 1: -2.0}, 0.0, 0),
           # a swimmer coasting and turning through the fluid: the drag slows every link
           ("Swimmer", {2: 0.3, 3: -0.4}, {0: 0.5, 1: -0.3, 2: 0.2, 3: 1.0, 4: -1.0}, 0.0, 3)]


def start(env, dq, dv):
    """The env's initial qpos, qvel offset by dq, dv ({index: offset})."""
    qp, qv = env.init_qpos.copy(), env.init_qvel.copy()
    for i, x in dq.items():
        qp[i] += x
    for i, x in dv.items():
        qv[i] += x
    return qp, qv


def ours_run(env, qp, qv, u, n=20):
    env.set_state(qp, qv)
    return np.array([env.step(u)[0] for _ in range(n)])


def mujoco_euler_run(mujoco, ref, qp, qv, u, timestep, frame_skip, n=20):
    """gymnasium's MuJoCo env stepped with MuJoCo's Euler integrator at `timestep`."""
    ref.model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    ref.model.opt.timestep = timestep
    ref.frame_skip = frame_skip
    ref.set_state(qp, qv)
    return np.array([ref.step(u)[0] for _ in range(n)])


@pytest.mark.parametrize("name, dq, dv, action, moving", MOTIONS)
def test_motion_before_contact_matches_mujoco_euler(name, dq, dv, action, moving):
    """Constant actions from an offset start, 20 env steps, no contact and no limit
    reached: our observations against MuJoCo with its Euler integrator at the same step h.
    Both are first-order, so each is off the exact motion by about 2 |M(h) - M(h/2)|
    (Richardson); the bound is twice that: |ours - M(h)| <= 4 max |M(h) - M(h/2)|."""
    mujoco, ref = mujoco_env(name)
    env = make(name).unwrapped
    qp, qv = start(env, dq, dv)
    u = np.full(env.action_space.shape, action)
    ours = ours_run(env, qp, qv, u)
    m1, m2 = (mujoco_euler_run(mujoco, ref, qp, qv, u, env.timestep / k, env.frame_skip * k)
              for k in (1, 2))
    assert np.abs(ours[0, moving] - ours[:, moving]).max() > 0.1     # it really moved
    err, delta = np.abs(ours - m1).max(), np.abs(m1 - m2).max()
    assert err <= 4 * delta, (err, delta)


def test_rgb_array_render():
    env = make("Hopper", render_mode="rgb_array", width=96, height=64)
    env.reset(seed=0)
    img = env.render()
    assert img.shape == (64, 96, 3) and img.dtype == np.uint8 and img.std() > 0


@pytest.mark.parametrize("name, dq, dv, action, moving", MOTIONS[2:])
def test_difference_from_mujoco_euler_halves_with_the_step(name, dq, dv, action, moving):
    """Reacher and Swimmer (no contact at all): ours and MuJoCo's Euler, both at step h / k
    over the same 20 env steps, differ by O(h): halving the step halves the difference (both
    first-order methods converge to one motion: damping, armature and drag included)."""
    mujoco, ref = mujoco_env(name)
    base = make(name).unwrapped
    diffs = []
    for k in (1, 2, 4):
        env = make(name, dt=base.timestep / k, frame_skip=base.frame_skip * k).unwrapped
        qp, qv = start(env, dq, dv)
        u = np.full(env.action_space.shape, action)
        theirs = mujoco_euler_run(mujoco, ref, qp, qv, u, env.timestep, env.frame_skip)
        diffs.append(np.abs(ours_run(env, qp, qv, u) - theirs).max())
    assert diffs[0] > 1e-4                       # a difference to watch shrink
    for a, b in zip(diffs, diffs[1:]):
        assert 0.4 < b / a < 0.6, diffs


def test_bad_inputs_name_the_culprit():
    """An unknown gym.make keyword names the environment and what it takes (not
    ModelBuilder.__init__); set_state with a NaN names the entry (not 'joints hang from no
    body'); the double pendulum's file is read and closed (no ResourceWarning)."""
    import warnings
    with pytest.raises(TypeError, match=r"Reacher: unknown keyword\(s\) \['bogus'\]"):
        gym.make("planarsim/Reacher-v0", bogus=1)
    env = gym.make("planarsim/Hopper-v0").unwrapped
    env.reset(seed=0)
    qpos = env.init_qpos.copy()
    qpos[2] = np.nan
    with pytest.raises(ValueError, match=r"qpos\[2\] = nan is not finite"):
        env.set_state(qpos, env.init_qvel)
    qvel = env.init_qvel.copy()
    qvel[0] = np.inf
    with pytest.raises(ValueError, match=r"qvel\[0\] = inf is not finite"):
        env.set_state(env.init_qpos, qvel)
    import gc
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ResourceWarning)
        env = gym.make("planarsim/InvertedDoublePendulum-v0")
        env.close()
        del env
        gc.collect()
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)]


@pytest.mark.parametrize("kw, said", [
    (dict(ctrl_cost_weight=float("nan")), r"Hopper: ctrl_cost_weight=nan must be a finite number"),
    (dict(forward_reward_weight="abc"), r"Hopper: forward_reward_weight='abc' must be a finite number"),
    (dict(healthy_reward=True), r"Hopper: healthy_reward=True must be a finite number"),
    (dict(healthy_z_range=(2.0, 0.7)), r"Hopper: healthy_z_range=\(2.0, 0.7\) must have low < high"),
    (dict(healthy_z_range=(0.7, 1.0, 3.0)), r"Hopper: healthy_z_range=\(0.7, 1.0, 3.0\) must be a pair"),
    (dict(healthy_z_range=(False, True)), r"Hopper: healthy_z_range=\(False, True\) must be a pair"),
    (dict(healthy_angle_range=(float("nan"), 0.2)), r"Hopper: healthy_angle_range=\(nan, 0.2\) must have low < high"),
    (dict(terminate_when_unhealthy="no"), r"Hopper: terminate_when_unhealthy='no' must be True or False"),
    (dict(exclude_current_positions_from_observation="no"),
     r"Hopper: exclude_current_positions_from_observation='no' must be True or False"),
])
def test_bad_task_keywords_name_the_culprit(kw, said):
    """A NaN weight gave NaN rewards, a reversed healthy range ended every episode at its first
    step and a string switch was read as True, all silently; exclude_current_positions_from_
    observation='no' raised int()'s "invalid literal for int() with base 10"."""
    with pytest.raises(ValueError, match=said):
        gym.make("planarsim/Hopper-v0", **kw)
    gym.make("planarsim/Hopper-v0", forward_reward_weight=2, healthy_z_range=[0.5, 3.0],
             terminate_when_unhealthy=np.bool_(False)).close()      # whole numbers, lists, numpy


@pytest.mark.parametrize("name", ["InvertedPendulum", "Reacher"])
def test_compiled_step_observation_is_the_tasks_own_to_the_bit(name):
    """The compiled observations of step() (tasks.joined_finite, tasks.reacher_obs) give the
    task's _get_obs() and reward to the bit, over random actions."""
    env = gym.make(f"planarsim/{name}-v0").unwrapped
    env.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(40):
        a = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, reward, terminated, *_ = env.step(a)
        assert np.array_equal(obs, env._get_obs())
        if name == "Reacher":
            assert reward == env._get_rew(a)[0]
        if terminated:
            env.reset(seed=4)
