"""Cornell Ranger (Kelly 2014, sections 5-6): four rigid bodies with curved feet, the Ranger motor
model, FSM WALK / STAND / GUI with a step-to-step push-off feedback, cost of transport.

>>> from walkers import ranger
>>> traj, summary, model = ranger.simulate(10.0, gait="walk")   # doctest: +SKIP

Choices (numbers in params.py, each with its reason):
- Contact-mode strategy: Kelly's "alternating" by default (Run(strategy=...)); "all"
  also walks 1000 steps, fresh or after 0.3 s / 2 s of STAND (measured on a6cac2a).
- Rotor inertia: the ankle rotor's G^2 Jm is added to the foot body (armature), and ankle
  currents on a foot in the air are capped (free_foot_max_accel), see model.py/controller.py.
- Poses: every run starts at rest in the STAND pose (hip centred over feet 0.19 m apart). WALK
  gets going from it through the controller's START phase (a double stance whose rear-foot
  push uses start_push_current until the front leg is past start_leg_angle), whether WALK is
  asked for at the start or set on a running STAND (Controller.set_gait).
- Step options: the engine defaults, rollout.step_options(). A landing foot that comes down
  on its heel (the sole arc's back end, a vertex) while sliding forward is in Painleve's
  configuration (sliding friction would drive it into the ground: A_nn < mu A_nt; measured
  A_nn 0.10, A_nt 0.30 [1/kg] at mu 0.8): the step's contact problem then has no answer with
  friction, and the engine's frictionless rule gives the foot a normal impulse for that step
  (planarsim/kernels/solver/complementarity.py; the audit's `fallback` counts it).
- Figures: ``python benchmarks/ranger.py --repeats 3 --steps 1000``.
"""
from pathlib import Path as _Path

from planarsim.compiled import drop_stale_caches as _drop


def _drop_caches():
    # our kernels also inline planarsim/actuators.py: fold it into the source hash
    import hashlib
    import planarsim
    here = _Path(__path__[0])
    act = _Path(planarsim.__file__).resolve().parent / "actuators.py"
    digest = hashlib.blake2b(act.read_bytes(), digest_size=8).hexdigest()
    stamp = here / "__pycache__" / "actuators.hash"
    try:
        if not stamp.exists() or stamp.read_text() != digest:
            for pattern in ("*.nbi", "*.nbc"):
                for f in list(here.rglob(pattern)) + list(act.parent.glob(f"__pycache__/actuators*{pattern[1:]}")):
                    f.unlink(missing_ok=True)
            stamp.parent.mkdir(exist_ok=True)
            stamp.write_text(digest)
    except OSError:
        pass
    _drop(here)


_drop_caches()

from .params import RangerParams  # noqa: E402
from .model import build  # noqa: E402
from .controller import Controller  # noqa: E402
from .tables import Gait, Phase, Program, Tables, make_tables  # noqa: E402
from .rollout import GAITS, Run, instantaneous_cot, live, simulate  # noqa: E402

NAME = "ranger"
SUMMARY_EXTRAS = {
    "distance": ("outer_legs_distance_m", "horizontal displacement of the outer legs' centre of mass (the model's first body) since the start"),
    "mean_speed": ("outer_legs_mean_speed_m_per_s", "outer_legs_distance_m over the simulated time"),
    "step_length": ("heel_strike_step_length_m", "the hip's advance per step between the controller's heel strikes, whole steps after the start-up step (the costs of transport's distance)"),
    "step_period": ("heel_strike_step_period_s", "time per step between the controller's heel strikes, whole steps after the start-up step"),
    "step_speed": ("heel_strike_step_speed_m_per_s", "heel_strike_step_length_m over heel_strike_step_period_s"),
    "cost_of_transport": ("cost_of_transport", "electrical energy plus the computers' 4.5 W, per weight and distance, over whole steps (Ranger's figure of merit)"),
    "cost_of_transport_electrical": ("cost_of_transport_electrical", "positive electrical motor energy per weight and distance, whole steps"),
    "cost_of_transport_electrical_net": ("cost_of_transport_electrical_net", "net electrical motor energy per weight and distance, whole steps"),
    "cost_of_transport_mechanical": ("cost_of_transport_mechanical", "positive motor shaft work per weight and distance, whole steps"),
    "cost_of_transport_mechanical_net": ("cost_of_transport_mechanical_net", "net motor shaft work per weight and distance, whole steps"),
    "push_current_mean": ("push_current_mean_A", "mean push-off current of the ankle motors"),
    "steps": ("controller_steps", "heel strikes counted by the controller"),
}
GAIT_DOCS = {
    "walk": "walks: push-off and swing by Kelly's state machine, step-to-step push-off feedback",
    "stand": "stands still on both feet, holding the pose it has when STAND begins",
    "gui": ("Kelly's test mode: each joint (hip, both ankles) held by PD at a target set by "
            "hand (the viewer's sliders); from the command line the targets are the stand "
            "pose, so it stands"),
}
Params = RangerParams   # the walker's parameters (planarsim params ranger)

__all__ = ["NAME", "GAITS", "GAIT_DOCS", "simulate", "Run", "RangerParams", "build", "Controller", "Tables", "make_tables", "Gait", "Phase",
           "Program", "instantaneous_cot", "live"]
