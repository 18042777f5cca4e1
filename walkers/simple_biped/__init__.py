"""The Simple Biped (Kelly 2014, sections 3-4): three point masses, STAND / WALK / JUMP.

>>> from walkers import simple_biped as sb              # doctest: +SKIP
>>> traj, summary, model = sb.simulate(20.0, gait="walk", speed=1.0)
>>> w = sb.Run(gait="stand"); w.run(2.0); w.set_gait("jump"); w.run(5.0)
"""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])

from .controller import Gait, State, Tables, make_tables  # noqa: E402
from .model import build  # noqa: E402
from .params import SimpleBipedParams  # noqa: E402
from .rollout import Run, live, rollout_simple_biped, simulate  # noqa: E402

NAME = "simple-biped"
SUMMARY_EXTRAS = {
    "distance": ("hip_distance_m", "horizontal displacement of the hip mass since the start"),
    "mean_speed": ("hip_mean_speed_m_per_s", "hip_distance_m over the simulated time"),
    "positive_work": ("positive_work_J", "positive work of the actuators over the run"),
    "cost_of_transport": ("cost_of_transport", "positive actuator work per weight and distance, over the run"),
    "steps": ("controller_steps", "steps counted by the state machine"),
    "jumps": ("jumps", "jumps completed"),
    "scuffs": ("scuffs", "swing-foot contacts early in the swing, not counted as steps"),
    "retries": ("retries", "steps the state machine aborted and began again"),
    "state": ("final_state", "state machine state at the end"),
}
Params = SimpleBipedParams   # the walker's parameters (planarsim params simple-biped)
GAITS = tuple(g.name.lower() for g in Gait)
GAIT_DOCS = {
    "stand": "stands in double stance, the hip held above the middle of the feet",
    "walk": "walks forward: double and single stance by Kelly's state machine",
    "jump": "jumps in place again and again: crouch, thrust, flight with both feet up, landing",
}

__all__ = ["NAME", "GAITS", "GAIT_DOCS", "Gait", "State", "Tables", "make_tables", "SimpleBipedParams", "Run", "build", "simulate", "live",
           "rollout_simple_biped"]
