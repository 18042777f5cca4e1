"""The environments' gymnasium ids, entry points and episode lengths, and their registration
(on import of planarsim.envs, and in each process of a PlanarVectorEnv)."""
import gymnasium

from . import dmc

ENVS = {
    "planarsim/Hopper-v0": ("planarsim.envs.tasks:Hopper", 1000),
    "planarsim/Walker2d-v0": ("planarsim.envs.tasks:Walker2d", 1000),
    "planarsim/HalfCheetah-v0": ("planarsim.envs.tasks:HalfCheetah", 1000),
    "planarsim/InvertedPendulum-v0": ("planarsim.envs.tasks:InvertedPendulum", 1000),
    "planarsim/InvertedDoublePendulum-v0": ("planarsim.envs.tasks:InvertedDoublePendulum", 1000),
    "planarsim/Reacher-v0": ("planarsim.envs.tasks:Reacher", 50),
    "planarsim/Swimmer-v0": ("planarsim.envs.tasks:Swimmer", 1000),
}


# the DeepMind Control Suite's planar tasks (dmc.py): id -> (task, episode steps)
DMC_ENVS = {dmc.env_id(task): (task, dmc.DOMAINS[domain].episode_steps)
            for task, (domain, _) in dmc.TASKS.items()}


def register_all():
    """Register the environments with gymnasium (idempotent)."""
    for env_id, (entry, steps) in ENVS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=entry, max_episode_steps=steps)
    for env_id, (task, steps) in DMC_ENVS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point="planarsim.envs.dmc:DMCEnv",
                               max_episode_steps=steps, kwargs={"task": task})
