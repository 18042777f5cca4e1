"""SIMBICON biped (Thachuk 2018): the MJCF character of the thesis, its four-state FSM with PD
joints, torso control through the stance hip and swing-hip balance feedback; tuned by
planarsim.tune (CMA-ES)."""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])

from .params import SimbiconParams, THESIS  # noqa: E402
from .model import build  # noqa: E402
from .controller import Controller, Phase  # noqa: E402
from .rollout import run, simulate  # noqa: E402

NAME = "simbicon"
Params = SimbiconParams   # the walker's parameters (planarsim params simbicon)
GAITS = ("walk",)

__all__ = ["NAME", "GAITS", "simulate", "run", "build", "Controller", "Phase", "SimbiconParams", "THESIS"]
