"""The robot dog of the 2023 robot-dog post in the sagittal plane: an A1-like quadruped driven through an
inverse-kinematics puppet, trotting with diagonal pairs (STAND / PIAFFE / WALK).

>>> from walkers import quadruped as qd                       # doctest: +SKIP
>>> traj, summary, model = qd.simulate(20.0, gait="walk", speed=0.3)
>>> dog = qd.Run(gait="piaffe"); dog.run(5.0); dog.set_gait("walk", 0.3); dog.run(10.0)
"""
from planarsim.compiled import drop_stale_caches

drop_stale_caches(__path__[0])

from .controller import Controller, FootState, Gait  # noqa: E402
from .model import LEG_NAMES, PAIR, build  # noqa: E402
from .params import QuadrupedParams  # noqa: E402
from .puppet import leg_fk, leg_ik, puppet_pose  # noqa: E402
from .rollout import GAITS, Run, live, rollout_quadruped, simulate  # noqa: E402

NAME = "quadruped"
FEET = (("FL_foot", "RR_foot"), ("FR_foot", "RL_foot"))   # a trot: diagonal pairs land together
SUMMARY_EXTRAS = {
    "distance": ("torso_distance_m", "horizontal displacement of the torso since the start"),
    "mean_speed": ("torso_mean_speed_m_per_s", "torso_distance_m over the simulated time"),
    "motor_work_positive": ("motor_work_positive_J", "positive work of the joint motors over the run"),
    "cost_of_transport": ("cost_of_transport", "positive motor work per weight and distance, over the run"),
    "max_pitch_deg": ("max_pitch_deg", "largest torso pitch"),
    "ik_clamps": ("ik_clamps", "foot targets out of the legs' reach, clamped by the puppet"),
    "speed_command": ("speed_command_m_per_s", "commanded forward speed"),
    "steps": ("controller_steps", "pair lifts counted by the stepping state machine"),
}
GAIT_DOCS = {
    "stand": "stands on all four feet, no stepping",
    "piaffe": "trots in place: diagonal pairs of feet lift and land where they were (speed 0)",
    "walk": "trots forward, diagonal pairs of feet together, at the commanded speed",
}
Params = QuadrupedParams   # the walker's parameters (planarsim params quadruped)

__all__ = ["NAME", "GAITS", "GAIT_DOCS", "simulate", "Run", "QuadrupedParams", "Controller", "Gait",
           "FootState", "build", "leg_fk", "leg_ik", "puppet_pose", "rollout_quadruped",
           "LEG_NAMES", "PAIR", "live"]
