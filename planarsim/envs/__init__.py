"""Gymnasium environments on planarsim: gymnasium's planar MuJoCo tasks (v5 observation,
action space, rewards, termination, reset noise and frame skip) on planarsim's engine.

Importing this package registers ``planarsim/Hopper-v0``, ``planarsim/Walker2d-v0``,
``planarsim/HalfCheetah-v0``, ``planarsim/InvertedPendulum-v0``,
``planarsim/InvertedDoublePendulum-v0``, ``planarsim/Reacher-v0`` and ``planarsim/Swimmer-v0``
with gymnasium (episode lengths as gymnasium's: 1000 steps, Reacher 50), and the DeepMind
Control Suite's planar tasks with dm_control's rewards, observations, control steps and time
limits (dmc.py): ``planarsim/dmc-<domain>-<task>-v0``, e.g. ``planarsim/dmc-walker-walk-v0``. ``PlanarVectorEnv``
(vector.py) steps many copies of one of them on every core; ``gymnasium.make_vec`` makes a
``BatchedVectorEnv`` (batched.py: the copies' physics in one compiled call, in this process).
"""
try:
    import gymnasium
except ImportError as e:  # pragma: no cover - exercised without gymnasium only
    raise ImportError("planarsim.envs needs gymnasium: pip install -e '.[gym]'") from e

from . import dmc
from .core import GeneralizedCoords, PlanarMujocoEnv
from .dmc import DMCEnv
from .registry import DMC_ENVS, ENVS, register_all
from .batched import BatchedVectorEnv
from .vector import PlanarVectorEnv
from .tasks import (HalfCheetah, Hopper, InvertedDoublePendulum, InvertedPendulum, Reacher, Swimmer,
                    Walker2d)

register_all()

__all__ = ["ENVS", "DMC_ENVS", "BatchedVectorEnv", "DMCEnv", "GeneralizedCoords", "PlanarMujocoEnv", "PlanarVectorEnv", "Hopper", "Walker2d", "HalfCheetah",
           "InvertedPendulum", "InvertedDoublePendulum", "Reacher", "Swimmer", "register_all"]
