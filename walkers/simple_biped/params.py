"""Parameters of the Simple Biped (Kelly 2014, sections 3-4): model, actuator limits and gains.

One frozen dataclass; every field carries doc, unit and bounds in its metadata. ``to_array()``
gives the float64 vector the compiled controller reads through the module-level indices
``I_<FIELD>`` (written out below; a test checks them against the field order).

Gains are written per unit mass (accelerations): a PD gain kp [1/s^2] multiplies a position
error [m] to give an acceleration [m/s^2], which the controller multiplies by the mass that the
actuator moves. Defaults are the ones every test uses.
"""
from __future__ import annotations

from dataclasses import dataclass

from walkers.common.params import WalkerParams, param as _p
from walkers.common.slots import param_slots


@dataclass(frozen=True)
class SimpleBipedParams(WalkerParams):
    # fields planarsim tune varies (the controller's gains and settings; the model stays)
    TUNABLE = ("step_length0", "step_length_per_speed", "clearance", "strike_push", "speed_gain",
               "walk_length", "ds_kp", "ds_kd", "energy_gain", "ds_front_load", "ss_kp",
               "ss_kd", "swing_kp", "swing_kd")

    # model ---------------------------------------------------------------------------------
    hip_mass: float = _p(10.0, "kg", "point mass of the hip (the whole upper body)", 0.1, 1e3)
    foot_mass: float = _p(1.0, "kg", "point mass of each foot (legs themselves are massless)", 0.01, 1e2)
    leg_length: float = _p(1.0, "m", "nominal leg length l0 (the unit of every length below)", 0.1, 10.0)
    leg_length_max: float = _p(1.2, "l0", "longest leg the controller uses (a double stance ends "
                               "when the rear leg reaches it; swing targets stay within it)", 0.9, 1.5)
    mu: float = _p(0.9, "-", "Coulomb friction coefficient of the feet", 0.0, 5.0)
    leg_force_max: float = _p(2000.0, "N", "axial leg actuator limit (push and pull)", 1.0, 1e5)
    hip_torque_max: float = _p(250.0, "N m", "hip torque actuator limit", 1.0, 1e4)
    # stand ---------------------------------------------------------------------------------
    stand_height: float = _p(0.95, "l0", "hip height above the mean foot height when standing", 0.5, 1.1)
    stand_width: float = _p(0.3, "l0", "foot spacing of the initial standing pose", 0.0, 1.0)
    stand_kp: float = _p(100.0, "1/s^2", "hip position gain in double stance (STAND, LAND)", 0.0, 1e4)
    stand_kd: float = _p(20.0, "1/s", "hip velocity gain in double stance (STAND, LAND)", 0.0, 1e3)
    # walk: speed and step --------------------------------------------------------------------
    speed: float = _p(1.0, "m/s", "target walking speed (mean over whole steps)", 0.0, 3.0)
    step_length0: float = _p(0.3, "l0", "step length at zero speed", 0.05, 1.0)
    step_length_per_speed: float = _p(0.3, "l0 s/m", "step length increase per unit speed", 0.0, 1.0)
    clearance: float = _p(0.08, "l0", "swing-foot clearance (Bezier top edge at 4/3 of it)", 0.0, 0.5)
    slope_trust: float = _p(1.0, "-", "fraction of the slope seen between the feet assumed to "
                            "continue under the next step (0: Kelly's level-ground guess)", 0.0, 1.0)
    strike_push: float = _p(0.05, "l0", "Bezier end point below the expected ground, so the foot "
                            "strikes with downward speed", 0.0, 0.3)
    descent_rate: float = _p(0.5, "l0", "extra lowering of the swing target per unit phase past 1", 0.0, 5.0)
    speed_gain: float = _p(0.5, "-", "integral gain: energy-target speed change per speed error "
                           "of one step", 0.0, 5.0)
    stop_speed: float = _p(0.25, "m/s", "pendulum top speed while slowing down to stand", 0.0, 1.0)
    # walk: double stance (eqs. 1-3) -----------------------------------------------------------
    walk_length: float = _p(0.95, "l0", "stance leg length target in walking", 0.5, 1.1)
    ds_kp: float = _p(200.0, "1/s^2", "eq. 1: stance leg-length gain (double stance)", 0.0, 1e4)
    ds_kd: float = _p(25.0, "1/s", "eq. 1: stance leg-length rate gain (double stance)", 0.0, 1e3)
    energy_gain: float = _p(30.0, "1/s", "eq. 3: tangential gain on the leg-rate error", 0.0, 1e3)
    ds_front_load: float = _p(0.3, "-", "least front-leg force in double stance, as a fraction of "
                              "the hip weight (keeps the new stance foot planted)", 0.0, 1.0)
    ds_accel_max: float = _p(1.0, "g", "limit of the tangential hip acceleration of eq. 3", 0.0, 10.0)
    ds_force_max: float = _p(4.0, "weights", "leg force limit in walking double stance, in "
                             "units of the total weight", 0.5, 50.0)
    ds_time_min: float = _p(0.02, "s", "shortest double stance", 0.0, 1.0)
    ds_time_max: float = _p(0.25, "s", "longest double stance", 0.0, 5.0)
    ds_energy_tol: float = _p(0.02, "m^2/s^2", "double stance ends once the predicted top speed "
                              "squared is above v_top^2 minus this", 0.0, 10.0)

    # walk: single stance ------------------------------------------------------------------
    ss_kp: float = _p(200.0, "1/s^2", "stance leg-length gain (single stance)", 0.0, 1e4)
    ss_kd: float = _p(25.0, "1/s", "stance leg-length rate gain (single stance)", 0.0, 1e3)
    swing_kp: float = _p(900.0, "1/s^2", "virtual swing leg: length and angle gain", 0.0, 1e5)
    swing_kd: float = _p(60.0, "1/s", "virtual swing leg: length and angle rate gain", 0.0, 1e4)
    stance_mu: float = _p(0.6, "-", "the hip torque may push the stance foot at most this "
                          "friction ratio (about the vertical) off the ground", 0.0, 5.0)
    touchdown_phase: float = _p(0.5, "-", "a swing-foot contact before this phase is a scuff, not a step", 0.0, 1.0)
    # jump ----------------------------------------------------------------------------------
    crouch_height: float = _p(0.75, "l0", "hip height of the crouch before a jump", 0.4, 1.0)
    crouch_time: float = _p(0.4, "s", "time spent crouching before the thrust", 0.0, 5.0)
    thrust_accel: float = _p(15.0, "m/s^2", "upward hip acceleration during the thrust", 0.0, 100.0)
    takeoff_height: float = _p(1.0, "l0", "hip height above the feet at which the thrust ends", 0.5, 1.3)
    flight_length: float = _p(0.9, "l0", "leg length held in flight", 0.4, 1.2)
    land_time: float = _p(0.5, "s", "time spent absorbing a landing before the next crouch", 0.0, 5.0)
    fall_height: float = _p(0.6, "l0", "hip below this height above the ground counts as a fall", 0.0, 1.0)
    fall_leg_length: float = _p(1.5, "l0", "a leg longer than this counts as a fall (the walker "
                                "came apart)", 1.0, 10.0)

    def step_length(self, speed: float | None = None) -> float:
        """Step length [m] at `speed` [m/s] (default: the target speed)."""
        v = self.speed if speed is None else speed
        return (self.step_length0 + self.step_length_per_speed * v) * self.leg_length


# the slot of each field in to_array(), by name: compiled code reads p[FIELD.hip_mass]
FIELD = param_slots(SimpleBipedParams)
