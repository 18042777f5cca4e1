"""planarsim.envs.vector.PlanarVectorEnv: a gymnasium VectorEnv whose copies, spread over
worker processes, give the same episodes bit for bit as gymnasium's SyncVectorEnv of the same
copies and seeds (autoreset included); bad actions are clear errors before any copy steps."""
import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed (pip install -e '.[gym]')")
import planarsim.envs  # noqa: E402,F401
from gymnasium.vector import AutoresetMode, SyncVectorEnv, VectorEnv  # noqa: E402
from planarsim.envs.vector import PlanarVectorEnv  # noqa: E402


@pytest.mark.parametrize("name, workers", [("InvertedPendulum", 2), ("Swimmer", 2), ("Reacher", 1)])
def test_same_episodes_as_sync_vector_env(name, workers):
    env_id = f"planarsim/{name}-v0"
    n = 5
    ours = PlanarVectorEnv(env_id, n, workers=workers)
    ref = SyncVectorEnv([lambda: gym.make(env_id) for _ in range(n)])
    try:
        assert isinstance(ours, VectorEnv)
        assert ours.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
        assert ours.observation_space == ref.observation_space
        assert ours.action_space == ref.action_space
        assert ours.single_action_space == ref.single_action_space
        o1, i1 = ours.reset(seed=11)
        o2, i2 = ref.reset(seed=11)
        assert np.array_equal(o1, o2)
        rng = np.random.default_rng(0)
        ended = 0
        for _ in range(60):
            a = rng.uniform(-3, 3, size=ours.action_space.shape).astype(np.float32)
            r1, r2 = ours.step(a), ref.step(a)
            for x, y in zip(r1[:4], r2[:4]):
                assert np.array_equal(x, y)
            assert r1[4].keys() == r2[4].keys()
            for k in r1[4]:
                assert np.array_equal(r1[4][k], r2[4][k]), k
            ended += int(r1[2].sum() + r1[3].sum())
        if name == "InvertedPendulum":
            assert ended > 0              # the autoreset was exercised
        assert ours.call("dt") == ref.call("dt")
    finally:
        ours.close()
        ref.close()


def test_bad_actions_are_clear_errors():
    envs = PlanarVectorEnv("planarsim/Reacher-v0", 4, workers=2)
    try:
        envs.reset(seed=0)
        with pytest.raises(ValueError, match=r"actions have shape \(4, 3\).*take shape \(4, 2\)"):
            envs.step(np.zeros((4, 3)))
        a = np.zeros((4, 2))
        a[2, 1] = np.nan
        with pytest.raises(ValueError, match=r"actions of copies \[2\] have NaN"):
            envs.step(a)
        envs.step(np.zeros((4, 2)))       # still usable
    finally:
        envs.close()
    with pytest.raises(ValueError, match="num_envs=0 must be a positive integer"):
        PlanarVectorEnv("planarsim/Reacher-v0", 0)


def test_works_under_gymnasiums_vector_wrappers():
    """gymnasium's own vector wrappers take it: episode statistics (they read the autoreset
    mode and the batched infos) and normalised observations."""
    from gymnasium.wrappers.vector import NormalizeObservation, RecordEpisodeStatistics
    envs = RecordEpisodeStatistics(NormalizeObservation(
        PlanarVectorEnv("planarsim/InvertedPendulum-v0", 4, workers=2)))
    try:
        envs.reset(seed=0)
        rng = np.random.default_rng(1)
        lengths = []
        for _ in range(80):
            *_, info = envs.step(rng.uniform(-3, 3, size=(4, 1)))
            if "episode" in info:
                lengths += info["episode"]["l"][info["_episode"]].tolist()
        assert lengths and all(n >= 1 for n in lengths)
    finally:
        envs.close()
