"""planarsim.envs.dmc_rewards: each dm_control task's compiled reward gives the float of its
Python reward (dmc.py's ``_reward_<domain>``, rewards.tolerance's float path) bit for bit,
over random values, controls and states; and the compiled tolerance, square and mean are
Python's and numpy's bit for bit."""
import math

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
pytest.importorskip("dm_control", reason="dm_control is not installed (pip install dm_control): "
                                         "it ships the suite's model files")

from planarsim.compiled import jit  # noqa: E402
from planarsim.envs import dmc  # noqa: E402
from planarsim.envs.dmc_rewards import reward_of_values  # noqa: E402
from planarsim.envs.rewards import (SIGMOIDS, float_square, numpy_mean, tolerance,  # noqa: E402
                                    tolerance_at, tolerance_terms)

TASKS = list(dmc.TASKS)
# the reward values that are sizes (tolerance margins or bounds: never negative)
SIZES = {"radius", "radii", "target_size"}


def same(a, b):
    """a and b the same float, bit for bit (NaN equal to NaN)."""
    return np.float64(a).view(np.int64) == np.float64(b).view(np.int64)


@jit
def _tolerances(x, lower, upper, margin, kind, scale, out):
    for i in range(x.shape[0]):
        out[i] = tolerance_at(x[i], lower, upper, margin, kind, scale)


@jit
def _squares(x, out):
    for i in range(x.shape[0]):
        out[i] = float_square(x[i])


@jit
def _mean(a, n):
    return numpy_mean(a, n)


def _draws(rng, n):
    """n floats around the tasks' bounds, over many scales, with both signs."""
    base = rng.choice([0.0, 0.6, 1.0, 1.2, 2.0, 8.0, 10.0, -1.0, 15.0], n)
    return base + rng.standard_normal(n) * 10.0 ** rng.uniform(-3, 1.3, n)


@pytest.mark.parametrize("kind", SIGMOIDS)
def test_compiled_tolerance_is_the_float_path_bit_for_bit(kind):
    rng = np.random.default_rng(SIGMOIDS.index(kind))
    x = np.append(_draws(rng, 20000), [np.nan, np.inf, -np.inf, 0.0, -0.0])
    value = 0.0 if kind in ("cosine", "linear", "quadratic") else 0.1
    for bounds, margin, v in (((0.0, 0.0), 1.0, value), ((1.2, np.inf), 0.6, 0.5 if value else 0.0),
                              ((-0.5, 2.0), 0.0, 0.1), ((0.0, 0.3), 5.0, 0.3)):
        lower, upper, m, scale = tolerance_terms(bounds, margin, kind, v)
        out = np.empty_like(x)
        _tolerances(x, lower, upper, m, SIGMOIDS.index(kind), scale, out)
        ref = np.array([tolerance(float(xi), bounds, margin, kind, v) for xi in x])
        bad = ~(out.view(np.int64) == ref.view(np.int64))
        assert not bad.any(), (kind, bounds, x[bad][:5], out[bad][:5], ref[bad][:5])


def test_compiled_square_is_cpythons_not_x_times_x():
    """x ** 2 of a Python float is libm's pow, which differs from x * x in the last bit now
    and then: the compiled square is pow's (x * x would miss those)."""
    rng = np.random.default_rng(3)
    x = rng.standard_normal(200000) * 10.0 ** rng.integers(-8, 8, 200000)
    out = np.empty_like(x)
    _squares(x, out)
    ref = np.array([xi ** 2 for xi in x.tolist()])
    assert np.array_equal(out.view(np.int64), ref.view(np.int64))
    assert not np.array_equal((x * x).view(np.int64), ref.view(np.int64))    # (the case)


def test_compiled_mean_is_numpys():
    rng = np.random.default_rng(4)
    for n in list(range(1, 40)) + [100, 127, 128]:
        for _ in range(50):
            a = rng.standard_normal(n)
            assert same(_mean(a, n), np.mean(a.tolist())), n
        for zeros in ([-0.0] * n, [0.0] + [-0.0] * (n - 1)):      # (the sign of a zero sum)
            assert same(_mean(np.array(zeros), n), np.mean(zeros)), n


@pytest.mark.parametrize("task", TASKS)
def test_compiled_reward_is_the_python_reward_bit_for_bit(task):
    """Over random reward values and controls (the controls beyond ctrlrange too: the
    reward reads the action as given)."""
    env = dmc.DMCEnv(task)
    env.reset(seed=0)
    e = env._arrays
    names = env._readout.value_names
    n_obs = env._n_obs
    rng = np.random.default_rng(sum(map(ord, task)))
    values = np.zeros_like(env._values)
    for i in range(3000):
        x = _draws(rng, len(names))
        for j, name in enumerate(names):
            if name in SIZES:
                x[j] = abs(x[j])
        values[n_obs:] = x
        ctrl = rng.uniform(-1.5, 1.5, len(env._ctrl))
        ctrl[rng.random(len(ctrl)) < 0.2] = 0.0
        env._ctrl[:] = ctrl
        ours = reward_of_values(e.reward_code, values[n_obs:], e.reward_p, env._ctrl, e.scratch)
        ref = env._reward_of(values)
        assert same(ours, ref), (task, dict(zip(names, x)), ctrl, ours, ref)


@pytest.mark.parametrize("task", TASKS)
def test_an_episodes_rewards_are_the_python_rewards(task):
    """Along a random-action episode (and after set_control), env.step's and env.reward()'s
    reward (compiled) equal the Python reward of the same readings."""
    env = dmc.DMCEnv(task)
    env.reset(seed=1)
    rng = np.random.default_rng(1)
    for _ in range(100):
        _, r, _, _, _ = env.step(rng.uniform(env.action_space.low, env.action_space.high))
        assert same(r, env._reward_of(env._values))
        env.set_control(rng.uniform(-2, 2, len(env._ctrl)))
        assert same(env.reward(), env._reward_of(env._values))
    assert math.isfinite(r)


# --- the env step as one compiled call (dmc_step) ---------------------------------------

def _episode(env, actions, seed):
    out = [env.reset(seed=seed)[0]]
    for a in actions:
        obs, r, _, _, _ = env.step(a)
        out.append(np.append(obs, r))
    return np.concatenate(out)


def _unfused(env):
    """env made to step as outside the fast compile mode: Simulator.steps, then dmc_observe."""
    env._step_call = None
    return env


@pytest.mark.parametrize("task", ["walker-walk", "hopper-hop", "finger-turn_hard"])
def test_the_fused_step_is_the_unfused_steps_bit_for_bit(task):
    rng = np.random.default_rng(5)
    env = dmc.DMCEnv(task)
    acts = rng.uniform(env.action_space.low, env.action_space.high, (60, len(env._ctrl)))
    # actions as lists, float32 and strided arrays: converted as before (a copy if needed)
    given = [a.tolist() if i % 3 == 0 else a.astype(np.float32) if i % 3 == 1 else a
             for i, a in enumerate(acts)]
    wide = np.repeat(acts, 2, axis=1)
    given[7] = wide[7, ::2]                                 # (not contiguous: the Python path)
    ours = _episode(env, given, seed=4)
    ref = _episode(_unfused(dmc.DMCEnv(task)), [np.asarray(a, np.float64) for a in given], 4)
    assert np.array_equal(ours.view(np.int64), ref.view(np.int64))


def test_a_bad_action_is_named_and_changes_nothing():
    env, ref = dmc.DMCEnv("cheetah-run"), dmc.DMCEnv("cheetah-run")
    env.reset(seed=0)
    ref.reset(seed=0)
    a = np.full(6, 0.3)
    env.step(a)
    ref.step(a)
    for bad, said in ((np.zeros(5), r"action has shape \(5,\).*takes shape \(6,\)"),
                      (np.zeros((1, 6)), r"action has shape \(1, 6\)"),
                      ([0.1] * 5 + [np.nan], "has NaN or infinite entries"),
                      (np.array([np.inf] + [0.0] * 5), "has NaN or infinite entries")):
        with pytest.raises(ValueError, match=said):
            env.step(bad)
    assert np.array_equal(env.control(), a)
    b = np.full(6, -0.2)
    assert all(np.array_equal(x, y) for x, y in zip(env.step(b)[:2], ref.step(b)[:2]))


def _small_storage(env):
    """env's simulator with solve storage for one envelope entry and one complementarity row
    (kept by its resets): the first step with contacts runs out of room."""
    from planarsim.state import make_workspace
    sim = env.sim
    sim._ws = make_workspace(env.sim_model, 1, 1, 1)
    sim._fresh_ws = None
    sim._repack()
    return env


def test_a_step_out_of_room_grows_and_keeps_the_bits(monkeypatch):
    """A fused step that runs out of solve storage is undone, the storage grows and the step
    finishes from Python (as Simulator.steps does), with the bits of the unfused step (which
    grows alike)."""
    from planarsim.compile import FAST, MODE
    from planarsim.state import workspace_capacity
    finished = []
    finish = dmc.DMCEnv._finish_step
    monkeypatch.setattr(dmc.DMCEnv, "_finish_step",
                        lambda self, *a: finished.append(a[2:]) or finish(self, *a))
    rng = np.random.default_rng(2)
    env = _small_storage(dmc.DMCEnv("walker-walk"))
    acts = rng.uniform(-1, 1, (100, len(env._ctrl)))
    ours = _episode(env, acts, seed=1)
    ref_env = _unfused(_small_storage(dmc.DMCEnv("walker-walk")))
    ref = _episode(ref_env, acts, seed=1)
    assert np.array_equal(ours.view(np.int64), ref.view(np.int64))
    assert workspace_capacity(env.sim_model, env.sim.ws)[1] > 1          # (it grew)
    assert ref_env._step_call is None
    if MODE == FAST:
        assert finished and all(code == dmc.GUARD_ROOM for code, _ in finished)


@pytest.mark.parametrize("fused", [True, False])
def test_a_diverged_step_raises_naming_it(fused):
    """A physics step that the guards stop (here a speed of 1e200 m/s put in by set_state)
    raises SimulationDiverged from env.step, fused or not, and leaves the last control and
    readings as they were."""
    import planarsim as ps
    env = dmc.DMCEnv("walker-walk")
    if not fused:
        _unfused(env)
    env.reset(seed=0)
    a = np.full(len(env._ctrl), 0.25)
    env.step(a)
    qpos, qvel = env.data.qpos.copy(), env.data.qvel.copy()
    qvel[0] = 1e200
    env.set_state(qpos, qvel)
    readings = env._obs_values.copy()
    with pytest.raises(ps.SimulationDiverged, match=r"body .torso.* exceeds 1e\+10"):
        env.step(np.full(len(env._ctrl), -0.5))
    assert np.array_equal(env.control(), a)
    assert np.array_equal(env._obs_values, readings)


def test_a_batched_copy_stepping_alone_commands_its_own_row(monkeypatch):
    """A batched vector env gives each copy's commands a row of one array; a copy that then
    steps alone (its frame_skip set apart: the batched step leaves it to the copy) and runs
    out of solve storage finishes its step under its own commands, bit for bit the steps of
    a lone env (before: the fused step wrote the commands to the array the copy had at its
    making, and the finish ran the row's, the last batched step's)."""
    from planarsim.compile import FAST, MODE
    from planarsim.envs.batched import make_batched
    finished = []
    finish = dmc.DMCEnv._finish_step
    monkeypatch.setattr(dmc.DMCEnv, "_finish_step",
                        lambda self, *a: finished.append(a[2:]) or finish(self, *a))
    acts = np.random.default_rng(0).uniform(-1, 1, (40, 6))
    vec = make_batched(dmc.env_id("walker-walk"), num_envs=1)
    copy = vec._copies[0]
    ref = dmc.DMCEnv("walker-walk")
    vec.reset(seed=1)
    ref.reset(seed=1)
    for a in acts[:5]:
        vec.step(a[None])
        ref.step(a)
    vec.set_attr("frame_skip", 7)
    ref.frame_skip = 7
    _small_storage(copy)
    _unfused(_small_storage(ref))
    for a in acts[5:]:
        ours, theirs = vec.step(a[None])[0][0], ref.step(a)[0]
        assert np.array_equal(ours.view(np.int64), theirs.view(np.int64))
    if MODE == FAST:
        assert finished and all(code == dmc.GUARD_ROOM for code, _ in finished)


@pytest.mark.parametrize("task", ["walker-walk", "hopper-stand", "cartpole-swingup"])
def test_task_parameters_are_read_at_each_reset(task):
    """env.params changed between episodes: the next reset's compiled reward reads them, and
    equals the Python reward of the same values."""
    env = dmc.DMCEnv(task)
    env.reset(seed=0)
    key = {"walker-walk": "stand_height", "hopper-stand": "stand_height",
           "cartpole-swingup": None}[task]
    if key is not None:
        env.params[key] = 1.5 * env.params[key]
    env.reset(seed=0)
    for a in np.random.default_rng(1).uniform(-1, 1, (20, len(env._ctrl))):
        reward = env.step(a)[1]
        assert reward == env._reward_of(env._values)
