"""Gymnasium environments on planarsim: gymnasium's planar MuJoCo tasks (v5 observation,
action space, rewards, termination, reset noise and frame skip) on planarsim's engine.

Importing this package registers ``planarsim/Hopper-v0``, ``planarsim/Walker2d-v0``,
``planarsim/HalfCheetah-v0``, ``planarsim/InvertedPendulum-v0``,
``planarsim/InvertedDoublePendulum-v0``, ``planarsim/Reacher-v0`` and ``planarsim/Swimmer-v0``
with gymnasium (episode lengths as gymnasium's: 1000 steps, Reacher 50), and the DeepMind
Control Suite's planar tasks with dm_control's rewards, observations, control steps and time
limits (dmc.py): ``planarsim/dmc-<domain>-<task>-v0``, e.g. ``planarsim/dmc-walker-walk-v0``. ``PlanarVectorEnv``
(vector.py) steps many copies of one of them on every core.
"""
try:
    import gymnasium
except ImportError as e:  # pragma: no cover - exercised without gymnasium only
    raise ImportError("planarsim.envs needs gymnasium: pip install -e '.[gym]'") from e

from . import dmc
from .core import GeneralizedCoords, PlanarMujocoEnv
from .dmc import DMCEnv
from .vector import PlanarVectorEnv
from .tasks import (HalfCheetah, Hopper, InvertedDoublePendulum, InvertedPendulum, Reacher, Swimmer,
                    Walker2d)

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


register_all()

__all__ = ["ENVS", "DMC_ENVS", "DMCEnv", "GeneralizedCoords", "PlanarMujocoEnv", "PlanarVectorEnv", "Hopper", "Walker2d", "HalfCheetah",
           "InvertedPendulum", "InvertedDoublePendulum", "Reacher", "Swimmer", "register_all"]
