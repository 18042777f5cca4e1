"""Passive walkers on a slope, no actuators: the simplest walking model (Garcia et al. 1998),
the compass gait with rigid-body legs, and the rimless wheel. They validate the engine against
published and closed-form limit cycles through planarsim.analysis.

The command-line names are the submodules ``walkers.passive.simplest``,
``walkers.passive.compass_gait`` and ``walkers.passive.rimless_wheel`` (each exposing NAME,
GAITS and simulate(...)).
"""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])

from .gait import PassiveWalker  # noqa: E402
from .params import CompassParams, RimlessParams, SimplestParams  # noqa: E402

__all__ = ["PassiveWalker", "SimplestParams", "CompassParams", "RimlessParams"]
