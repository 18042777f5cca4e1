"""Ranger parameters: one frozen dataclass, every number with doc, unit, default and bounds.

Sources: Ranger's published numbers (Bhounsule et al., "Low-bandwidth reflex-based control for
lower power walking: 65 km on a single battery charge", IJRR 2014) and M. P. Kelly's public
Ranger simulator. Values marked CHOSEN are ours, with the reason in their doc.
Angles: body angles are counter-clockwise from the build pose, a leg at 0 is vertical (hip
above ankle), a foot at 0 is level (sole bottom directly below the ankle). The robot walks
towards +x, so a stance leg goes from positive (foot ahead) to negative (foot behind).
"""
from __future__ import annotations

from dataclasses import dataclass

from walkers.common.params import WalkerParams, param


def _p(default, doc, unit, lo, hi):
    """A parameter field (doc before unit, as this file lists them)."""
    return param(default, unit, doc, lo, hi)


@dataclass(frozen=True)
class RangerParams(WalkerParams):
    # fields planarsim tune varies (the controller's gains and settings; the model stays)
    TUNABLE = ("hold_kp", "hold_kd", "hip_kp", "hip_kd", "scissor_gain", "scissor_offset", "land_angle",
               "land_leg_angle", "push_leg_angle", "push_current", "push_gain",
               "target_speed", "air_omega", "air_zeta")

    # geometry and mass (ranger.md) -------------------------------------------------------------
    leg_length: float = _p(0.96, "hip joint to ankle joint", "m", 0.5, 1.5)
    leg_mass: float = _p(4.96, "mass of each planar leg (outer pair as one, inner pair as one)", "kg", 1.0, 20.0)
    leg_com: float = _p(0.15, "distance along the leg from the hip to the leg COM", "m", 0.0, 0.5)
    leg_inertia: float = _p(0.45, "leg moment of inertia about its COM", "kg m^2", 0.01, 5.0)
    foot_mass: float = _p(0.02, "foot mass (Kelly 2014)", "kg", 0.001, 1.0)
    foot_inertia: float = _p(0.002, "foot moment of inertia about the ankle joint", "kg m^2", 1e-5, 0.1)
    foot_com_x: float = _p(0.035, "CHOSEN: foot COM from the ankle, forward (centroid of Kelly's foot outline)", "m", -0.1, 0.1)
    foot_com_y: float = _p(-0.025, "CHOSEN: foot COM from the ankle, up (centroid of Kelly's foot outline)", "m", -0.1, 0.1)
    sole_radius: float = _p(0.2, "radius of the circular sole", "m", 0.05, 0.5)
    sole_center_height: float = _p(0.14, "ankle joint to the sole's centre ('virtual centre'), straight up on a level foot", "m", 0.0, 0.3)
    sole_span_back: float = _p(-1.66, "CHOSEN: sole arc start, direction from the centre (-95 deg: 17 mm behind the ankle, Kelly's outline)", "rad", -3.1, 0.0)
    sole_span_front: float = _p(-1.0, "CHOSEN: sole arc end (-57 deg: the toe, 107 mm ahead of the ankle)", "rad", -3.1, 0.0)
    foot_back_x: float = _p(-0.026, "CHOSEN: back-bottom corner of the foot from the ankle (Kelly's outline)", "m", -0.2, 0.0)
    foot_back_y: float = _p(-0.042, "CHOSEN: back-bottom corner height from the ankle", "m", -0.2, 0.1)
    foot_top_x: float = _p(0.036, "CHOSEN: top of the foot from the ankle (Kelly's outline)", "m", -0.2, 0.2)
    foot_top_y: float = _p(0.018, "CHOSEN: top of the foot height from the ankle", "m", -0.2, 0.2)
    friction: float = _p(0.8, "CHOSEN: foot-ground Coulomb coefficient (rubber sole on a hard floor)", "-", 0.0, 3.0)
    stand_front_angle: float = _p(0.1, "CHOSEN: STAND pose, front (inner) leg angle (feet 0.19 m apart, hip centred)", "rad", -0.3, 0.4)
    stand_rear_angle: float = _p(-0.1, "CHOSEN: STAND pose, rear (outer) leg angle", "rad", -0.4, 0.0)
    # motors (ranger.md) ------------------------------------------------------------------------
    hip_gear: float = _p(66.0, "hip gear ratio G", "-", 1.0, 500.0)
    ankle_gear: float = _p(34.0, "ankle gear ratio G", "-", 1.0, 500.0)
    torque_const: float = _p(0.018, "motor torque constant K", "N m/A", 1e-3, 1.0)
    resistance: float = _p(1.3, "terminal resistance R", "ohm", 0.0, 10.0)
    contact_voltage: float = _p(0.7, "brush contact voltage drop Vc (Kelly's V0)", "V", 0.0, 5.0)
    current_smooth: float = _p(0.01, "CHOSEN: I0 of the smoothed |I| (Kelly 2014, eq. 15); small against working currents", "A", 1e-4, 1.0)
    viscous_friction: float = _p(0.0, "viscous friction c1 (Kelly's C_d)", "N m s/rad", 0.0, 1.0)
    coulomb_friction: float = _p(0.01, "constant friction c0 (Kelly's C)", "N m", 0.0, 1.0)
    load_friction: float = _p(0.1, "current-dependent friction mu (Kelly's C_tau)", "-", 0.0, 1.0)
    rotor_inertia: float = _p(1.6e-6, "rotor inertia Jm (reflected: G^2 Jm)", "kg m^2", 0.0, 1e-3)
    current_max: float = _p(6.0, "current limit Imax (3.1 A continuous, 8 A peak)", "A", 0.1, 20.0)
    rate_smooth: float = _p(0.5, "w0 of the smoothed sgn(w) (Kelly's smoothing alpha = 0.5)", "rad/s", 0.01, 10.0)
    hip_spring: float = _p(8.045, "hip parallel spring", "N m/rad", 0.0, 50.0)
    hip_spring_rest: float = _p(0.0, "hip spring rest angle (legs together)", "rad", -1.0, 1.0)
    ankle_spring: float = _p(0.134, "ankle parallel spring", "N m/rad", 0.0, 5.0)
    ankle_spring_rest: float = _p(1.662, "ankle spring rest angle in the robot's convention", "rad", 0.0, 3.2)
    ankle_offset: float = _p(1.85, "Phi: robot ankle angle = Phi + our ankle pin angle (ASSUMED sign convention)", "rad", 0.0, 3.2)
    hip_torque_peak: float = _p(6.0, "hip torque saturation (peak; 4.5 continuous)", "N m", 0.1, 50.0)
    ankle_torque_peak: float = _p(4.8, "ankle torque saturation (peak; 3.6 continuous)", "N m", 0.1, 50.0)
    overhead_power: float = _p(4.5, "electrical power of computers and sensors", "W", 0.0, 50.0)
    rotor_on_foot: float = _p(1.0, "CHOSEN: 1 adds the ankle rotor's G^2 Jm to the foot inertia (armature), 0 leaves it out", "-", 0.0, 1.0)
    # light-foot guard (a light foot behind a heavy leg) -------------------------------------------------------------
    free_foot_max_accel: float = _p(2000.0, "CHOSEN: ankle torque on a foot in the air is saturated to I_foot times this", "rad/s^2", 10.0, 1e6)
    # contact estimator --------------------------------------------------------------------------
    est_cutoff: float = _p(15.0, "CHOSEN: Butterworth low-pass cutoff of the contact signal", "Hz", 0.5, 200.0)
    est_on: float = _p(0.25, "CHOSEN: filtered load fraction above which a foot counts as on the ground", "-", 0.0, 2.0)
    est_off: float = _p(0.08, "CHOSEN: filtered load fraction below which a foot counts as in the air", "-", 0.0, 2.0)
    # motor programs (PD on current, eq. 18) ---------------------------------------------------------
    hold_kp: float = _p(4.917, "CHOSEN: HOLD, ankle on the ground: current per rad of foot tilt", "A/rad", 0.0, 200.0)
    hold_kd: float = _p(0.733, "CHOSEN: HOLD, ankle on the ground", "A s/rad", 0.0, 20.0)
    hip_kp: float = _p(27.543, "SWING hip gain (Kelly's 25 N m/rad / (G K))", "A/rad", 0.0, 200.0)
    hip_kd: float = _p(3.269, "SWING hip gain (Kelly's 3 N m s/rad / (G K))", "A s/rad", 0.0, 20.0)
    scissor_gain: float = _p(1.015, "SWING: the swing leg tracks -c times the stance leg angle", "-", 0.0, 3.0)
    scissor_offset: float = _p(0.0, "SWING: added to the swing leg target", "rad", -1.0, 1.0)
    flip_angle: float = _p(1.342, "CHOSEN: FLIP target, ankle angle (foot relative to leg, toe up)", "rad", 0.0, 2.5)
    land_angle: float = _p(0.068, "CHOSEN: HOLD target of the swing foot before touchdown, absolute (0 level, < 0 toe down)", "rad", -0.6, 0.6)
    land_leg_angle: float = _p(0.174, "CHOSEN: angle between the legs (swing ahead) past which the swing foot is set for landing: sets the step length", "rad", 0.0, 1.2)
    push_leg_angle: float = _p(-0.087, "CHOSEN: stance leg angle (behind vertical) at which push-off starts", "rad", -0.8, 0.3)
    ds_time: float = _p(0.018, "CHOSEN: longest double stance; then the trailing foot swings (Ranger's is ~0.04 s)", "s", 0.0, 1.0)
    push_current: float = _p(2.328, "CHOSEN: nominal push-off current (toe down)", "A", 0.0, 20.0)
    push_limit_angle: float = _p(-0.8, "CHOSEN: foot angle (toe down) where push-off stops and holds", "rad", -1.5, 0.0)
    push_gain: float = _p(10.44, "CHOSEN: step-to-step feedback, push current per m/s of mid-stance speed deficit", "A s/m", 0.0, 100.0)
    target_speed: float = _p(0.575, "CHOSEN: mid-stance hip speed the push-off feedback aims at", "m/s", 0.0, 2.0)
    start_push_current: float = _p(4.075, "CHOSEN: START (WALK entered from standing at rest): the rear foot's push-off current (toe down) in the start-up double stance", "A", 0.0, 20.0)
    start_leg_angle: float = _p(-0.02, "CHOSEN: START ends (the rear leg swings) once the front leg is this far past vertical: the hip is over the front foot", "rad", -0.4, 0.3)
    air_omega: float = _p(34.95, "swing-foot model-based controller natural frequency (section 6.5)", "rad/s", 1.0, 300.0)
    air_zeta: float = _p(0.8, "swing-foot model-based controller damping ratio", "-", 0.0, 3.0)
    flight_kp: float = _p(10.0, "flight fallback: hold the joint angles, current gain", "A/rad", 0.0, 200.0)
    flight_kd: float = _p(0.5, "flight fallback", "A s/rad", 0.0, 20.0)
    fall_height: float = _p(0.75, "the walker has fallen when the hip drops below this height above ground", "m", 0.1, 1.2)

    def __post_init__(self):
        super().__post_init__()
        if self.est_off >= self.est_on:
            raise ValueError(f"RangerParams.est_off={self.est_off} must be below est_on={self.est_on}")
        if self.sole_span_front <= self.sole_span_back:
            raise ValueError("RangerParams.sole_span_front must exceed sole_span_back")
