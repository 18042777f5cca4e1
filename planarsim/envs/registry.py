"""The environments' gymnasium ids, entry points and episode lengths, and their registration
(on import of planarsim.envs, and in each process of a PlanarVectorEnv)."""
import gymnasium

ENVS = {
    "planarsim/Hopper-v0": ("planarsim.envs.tasks:Hopper", 1000),
    "planarsim/Walker2d-v0": ("planarsim.envs.tasks:Walker2d", 1000),
    "planarsim/HalfCheetah-v0": ("planarsim.envs.tasks:HalfCheetah", 1000),
    "planarsim/InvertedPendulum-v0": ("planarsim.envs.tasks:InvertedPendulum", 1000),
    "planarsim/InvertedDoublePendulum-v0": ("planarsim.envs.tasks:InvertedDoublePendulum", 1000),
    "planarsim/Reacher-v0": ("planarsim.envs.tasks:Reacher", 50),
    "planarsim/Swimmer-v0": ("planarsim.envs.tasks:Swimmer", 1000),
}


def register_all():
    """Register the environments with gymnasium (idempotent)."""
    for env_id, (entry, steps) in ENVS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry, max_episode_steps=steps)
