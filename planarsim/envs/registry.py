"""The environments' gymnasium ids, entry points and episode lengths, and their registration
(on import of planarsim.envs, and in each process of a PlanarVectorEnv)."""
import functools

import gymnasium

from . import dmc
from .batched import make_batched

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
    """Register the environments with gymnasium (idempotent), each with its vector entry
    point (batched.py: gymnasium.make_vec's default for them)."""
    for env_id, (entry, steps) in ENVS.items():
        _register(env_id, entry, steps, {})
    for env_id, (task, steps) in DMC_ENVS.items():
        _register(env_id, "planarsim.envs.dmc:DMCEnv", steps, {"task": task})


def _register(env_id, entry, steps, kwargs):
    """Register one id (unless it is already): its entry point, episode steps, keywords and
    the batched vector entry point."""
    if env_id not in gymnasium.registry:
        gymnasium.register(id=env_id, entry_point=entry, max_episode_steps=steps, kwargs=kwargs,
                           vector_entry_point=functools.partial(make_batched, env_id))
