"""SIMBICON biped (Thachuk 2018): the MJCF character of the thesis, its four-state FSM with PD
joints, torso control through the stance hip and swing-hip balance feedback; tuned by
walkers.tune (planarsim tune, CMA-ES)."""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])

from .params import SimbiconParams, THESIS  # noqa: E402
from .model import build  # noqa: E402
from .controller import Controller, Phase  # noqa: E402
from .rollout import GAITS, Run, live, run, simulate  # noqa: E402

NAME = "simbicon"
SUMMARY_EXTRAS = {
    "distance": ("torso_distance_m", "horizontal displacement of the torso since the start"),
    "speed": ("torso_mean_speed_m_per_s", "torso_distance_m over the simulated time"),
    "effort": ("effort_N2m2s", "time integral of the sum of squared joint torques"),
    "glitch": ("glitch", "the run was stopped because the torso moved faster than a walker can"),
    "min_clearance": ("min_clearance_m", "lowest height of a part other than the feet above the ground"),
    "phase": ("final_phase", "state of the four-state machine at the end"),
    "timeouts": ("timeouts", "states ended by their timeout rather than a foot strike"),
    "steps": ("controller_steps", "swing-foot strikes counted by the controller"),
}
GAIT_DOCS = {"walk": "walks with SIMBICON's four-state machine: PD joints, torso held through the "
                     "stance hip, swing-hip balance feedback"}
Params = SimbiconParams   # the walker's parameters (planarsim params simbicon)

__all__ = ["NAME", "GAITS", "GAIT_DOCS", "simulate", "Run", "run", "live", "build", "Controller", "Phase", "SimbiconParams", "THESIS"]
