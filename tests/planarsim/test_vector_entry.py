"""The environments' vector entry point (planarsim.envs.batched.BatchedVectorEnv, what
gymnasium.make_vec makes by default): the same episodes bit for bit as gymnasium's
SyncVectorEnv of the same id, seed and actions, across autoresets; the copies' physics in
one compiled call; clear errors for a bad num_envs."""
import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
import planarsim.envs  # noqa: E402,F401
from gymnasium.vector import AutoresetMode, VectorEnv  # noqa: E402
from planarsim.compile import FAST, MODE  # noqa: E402
from planarsim.envs.batched import BatchedVectorEnv  # noqa: E402
from planarsim.envs.registry import DMC_ENVS, ENVS  # noqa: E402
from planarsim.sim import Simulator  # noqa: E402

N = 4


def make_pair(env_id, **kwargs):
    """(vector entry point, gymnasium's SyncVectorEnv) of N copies of env_id."""
    ours = gym.make_vec(env_id, num_envs=N, vectorization_mode="vector_entry_point", **kwargs)
    ref = gym.make_vec(env_id, num_envs=N, vectorization_mode="sync", **kwargs)
    return ours, ref


def assert_same(r1, r2):
    """Two vector steps' (or resets') arrays and infos (the last entry) equal bit for bit."""
    for x, y in zip(r1[:-1], r2[:-1]):
        assert x.dtype == y.dtype
        assert np.array_equal(x, y)
    assert r1[-1].keys() == r2[-1].keys()
    for key in r1[-1]:
        assert np.array_equal(r1[-1][key], r2[-1][key]), key


# (id, its keywords, action scale, steps): each drives an episode to its end (InvertedPendulum
# and Hopper fall; Reacher and the dm_control task run into a short time limit)
CASES = [("planarsim/InvertedPendulum-v0", {}, 3.0, 40),
         ("planarsim/Hopper-v0", {}, 1.0, 60),
         ("planarsim/Reacher-v0", {"max_episode_steps": 7}, 1.0, 20),
         ("planarsim/dmc-cartpole-balance-v0", {"max_episode_steps": 9}, 1.0, 25)]


@pytest.mark.parametrize("env_id, kwargs, scale, steps", CASES)
def test_same_episodes_as_sync_vector_env(env_id, kwargs, scale, steps):
    ours, ref = make_pair(env_id, **kwargs)
    try:
        assert isinstance(ours, BatchedVectorEnv) and isinstance(ours, VectorEnv)
        assert ours.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
        assert ours.observation_space == ref.observation_space
        assert ours.action_space == ref.action_space
        assert ours.single_observation_space == ref.single_observation_space
        assert ours.single_action_space == ref.single_action_space
        assert_same(ours.reset(seed=5), ref.reset(seed=5))
        rng = np.random.default_rng(0)
        ended = 0
        for _ in range(steps):
            a = (scale * rng.uniform(-1, 1, size=ours.action_space.shape)).astype(np.float32)
            r1, r2 = ours.step(a), ref.step(a)
            assert_same(r1, r2)
            ended += int(r1[2].sum() + r1[3].sum())
        assert ended > 0                   # an autoreset was exercised
        assert ours.get_attr("dt") == ref.get_attr("dt")
    finally:
        ours.close()
        ref.close()


def test_default_vectorization_is_the_entry_point():
    for env_id in [*ENVS, *DMC_ENVS]:
        assert gym.spec(env_id).vector_entry_point is not None, env_id
    envs = gym.make_vec("planarsim/InvertedPendulum-v0", num_envs=2)
    try:
        assert isinstance(envs, BatchedVectorEnv)
        assert envs.num_envs == 2
        envs.set_attr("frame_skip", [2, 2])
        assert envs.get_attr("frame_skip") == (2, 2)
        assert envs.call("obs_size") == (4, 4)
    finally:
        envs.close()


@pytest.mark.skipif(MODE != FAST, reason="the compiled batch runs in the fast compile mode")
def test_physics_in_one_compiled_call(monkeypatch):
    envs = gym.make_vec("planarsim/Hopper-v0", num_envs=3)
    try:
        envs.reset(seed=0)
        calls = []
        steps = Simulator.steps
        monkeypatch.setattr(Simulator, "steps", lambda self, *a: calls.append(a) or steps(self, *a))
        for _ in range(3):
            _, _, term, trunc, _ = envs.step(np.zeros(envs.action_space.shape, np.float32))
            assert not (term.any() or trunc.any())
        assert calls == []
    finally:
        envs.close()


def test_bad_action_is_the_copies_error_and_the_copies_stay_in_step():
    ours, ref = make_pair("planarsim/Reacher-v0")
    try:
        ours.reset(seed=3)
        ref.reset(seed=3)
        a = np.zeros(ours.action_space.shape, np.float32)
        a[2, 1] = np.nan
        for envs in (ours, ref):
            with pytest.raises(ValueError, match="NaN or infinite"):
                envs.step(a)
        a = np.full(ours.action_space.shape, 0.5, np.float32)
        assert_same(ours.step(a), ref.step(a))
    finally:
        ours.close()
        ref.close()


@pytest.mark.parametrize("num_envs", [0, -1, 2.5, True])
def test_bad_num_envs_is_named(num_envs):
    with pytest.raises(ValueError, match=f"num_envs={num_envs!r} must be a positive integer"):
        gym.make_vec("planarsim/Hopper-v0", num_envs=num_envs, vectorization_mode="vector_entry_point")


def test_a_copy_whose_step_runs_out_of_room_grows_and_keeps_the_bits(monkeypatch):
    """Workspaces made with room for one contact: a copy's batched step that needs more is
    undone, its storage grows and its steps finish from Python (as Simulator.steps does),
    with the bits of SyncVectorEnv's copies that grow alike."""
    from planarsim import state as state_module
    monkeypatch.setattr(state_module, "contact_capacity", lambda m: 1)
    finished = []
    finish = BatchedVectorEnv._finish
    monkeypatch.setattr(BatchedVectorEnv, "_finish",
                        lambda self, *a: finished.append(a) or finish(self, *a))
    ours, ref = make_pair("planarsim/HalfCheetah-v0")      # feet and shins land: more than one
    try:
        assert_same(ours.reset(seed=2), ref.reset(seed=2))
        rng = np.random.default_rng(1)
        grown = [1]
        for _ in range(400):                       # (until some copy grew, and 10 steps on)
            a = rng.uniform(-1, 1, size=ours.action_space.shape).astype(np.float32)
            assert_same(ours.step(a), ref.step(a))
            if max(grown) == 1:
                grown = [state_module.workspace_capacity(c.sim_model, c.sim.ws)[0]
                         for c in ours._copies]
                more = 10
            else:
                more -= 1
                if more == 0:
                    break
        assert max(grown) > 1
        if MODE == FAST:
            assert finished                # (grown after a batched step ran out of room)
    finally:
        ours.close()
        ref.close()


def test_a_diverging_copy_raises_as_in_sync_vector_env():
    from planarsim.errors import SimulationDiverged
    ours, ref = make_pair("planarsim/InvertedPendulum-v0")
    try:
        for envs in (ours, ref):
            envs.reset(seed=0)
            copy = envs.envs[1].unwrapped
            copy.set_state(copy.init_qpos, np.full(copy.model.nv, 1e200))
            with pytest.raises(SimulationDiverged):
                envs.step(np.zeros(envs.action_space.shape, np.float32))
    finally:
        ours.close()
        ref.close()


PARITY_SCRIPT = """
import numpy as np, gymnasium, planarsim.envs
from planarsim.envs import batched
ours, ref = (gymnasium.make_vec("planarsim/InvertedPendulum-v0", num_envs=3,
                                vectorization_mode=mode) for mode in ("vector_entry_point", "sync"))
assert batched.MODE == "python" and ours._step_batch is None
assert np.array_equal(ours.reset(seed=1)[0], ref.reset(seed=1)[0])
rng = np.random.default_rng(0)
ended = 0
for _ in range(20):
    a = rng.uniform(-3, 3, size=ours.action_space.shape).astype(np.float32)
    r1, r2 = ours.step(a), ref.step(a)
    assert all(np.array_equal(x, y) for x, y in zip(r1[:4], r2[:4]))
    ended += int(r1[2].sum())
assert ended > 0
print("same")
"""


def test_without_the_fast_mode_the_copies_step_one_by_one_with_the_same_bits():
    """Under NUMBA_DISABLE_JIT (a process of its own) the copies' physics run from Python,
    one after another: the same episodes as SyncVectorEnv's."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = str(Path(__file__).resolve().parents[2])          # this checkout's planarsim
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1",
           "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", PARITY_SCRIPT], env=env, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("same")
