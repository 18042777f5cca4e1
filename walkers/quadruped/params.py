"""Parameters of the planar quadruped: an A1-like robot dog in the sagittal
plane, its puppet (IK) and its trot controller.

One frozen dataclass; every field carries doc, unit and bounds in its metadata. ``to_array()``
gives the float64 vector the compiled controller reads through the module-level indices
``I_<FIELD>`` (generated from the field order below, so the two cannot disagree).

Sources of the robot numbers: the Unitree A1 model of MuJoCo Menagerie
(google-deepmind/mujoco_menagerie, unitree_a1/a1.xml, derived from Unitree's URDF), and the
A1's published trunk size 0.267 x 0.194 x 0.114 m:
  trunk 4.713 kg, I_yy 0.0378 kg m^2; four hip (abduction) housings 0.696 kg each at
  x = +-0.183 m (hip-to-hip 0.366 m); thigh 1.013 kg, COM 0.027 m below the hip,
  I_yy 0.00514 kg m^2, length 0.2 m; calf + foot 0.226 kg, COM 0.132 m below the knee,
  I_yy 0.0034 kg m^2, length 0.2 m; foot sphere radius 0.02 m; motors +-33.5 N m, armature
  0.01 kg m^2, position gain 100 N m/rad; thigh range [-1.0472, 4.18879] rad, calf range
  [-2.69653, -0.916298] rad; home pose thigh 0.9, calf -1.8 rad at trunk height 0.27 m.
Planar reduction (CHOSEN): abduction locked, so each hip housing is part of the torso
(torso 4.713 + 4 x 0.696 = 7.497 kg, pitch inertia 0.0378 + 4 x 0.696 x 0.183^2 = 0.131 kg m^2);
left and right legs of one end share the hip point and overlap in the plane. Total 12.45 kg.
Angle convention (ours): counter-clockwise positive, x forward, y up. A leg segment at
absolute angle phi points along (sin phi, -cos phi): 0 is straight down. Hip pin angle =
thigh angle - torso angle; knee pin angle = calf angle - thigh angle (> 0: knee behind the
foot, as on the A1). The A1's joint angles map as hip = -thigh_A1, knee = -calf_A1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from walkers.common.params import WalkerParams, param as _p
from walkers.common.slots import param_slots




@dataclass(frozen=True)
class QuadrupedParams(WalkerParams):
    # fields planarsim tune varies (the controller's gains and settings; the model stays)
    TUNABLE = ("kp", "kd", "weight_ff", "foot_step", "lift_height", "plant_delay", "placement_gain",
               "stance_time", "torso_track_max")

    # body (A1, Menagerie) ------------------------------------------------------------------------
    torso_mass: float = _p(7.497, "kg", "trunk 4.713 + four hip housings 0.696 (abduction locked)", 0.1, 100.0)
    torso_inertia: float = _p(0.131, "kg m^2", "torso pitch inertia about its COM (trunk + hips at +-0.183 m)", 1e-4, 10.0)
    torso_length: float = _p(0.267, "m", "trunk length (its box touches only bodies a scene adds)", 0.01, 2.0)
    torso_height: float = _p(0.114, "m", "trunk height (drawing only)", 0.01, 1.0)
    hip_x: float = _p(0.183, "m", "hip pins at x = +-hip_x from the torso COM (hip-to-hip 0.366 m)", 0.01, 1.0)
    thigh_length: float = _p(0.2, "m", "hip pin to knee pin", 0.01, 1.0)
    calf_length: float = _p(0.2, "m", "knee pin to foot centre", 0.01, 1.0)
    thigh_mass: float = _p(1.013, "kg", "thigh mass (knee motor included)", 0.01, 20.0)
    thigh_com: float = _p(0.027, "m", "thigh COM distance from the hip along the thigh", 0.0, 1.0)
    thigh_inertia: float = _p(0.00514, "kg m^2", "thigh inertia about its COM", 1e-6, 1.0)
    calf_mass: float = _p(0.226, "kg", "calf + foot mass", 0.01, 10.0)
    calf_com: float = _p(0.132, "m", "calf COM distance from the knee along the calf", 0.0, 1.0)
    calf_inertia: float = _p(0.0034, "kg m^2", "calf inertia about its COM", 1e-6, 1.0)
    armature: float = _p(0.01, "kg m^2", "reflected rotor inertia of each joint (Menagerie armature), "
                         "added to the distal body's inertia: exact while the proximal body does "
                         "not rotate (CHOSEN approximation)", 0.0, 1.0)
    foot_radius: float = _p(0.02, "m", "round foot (full circle at the calf tip)", 0.001, 0.1)
    friction: float = _p(0.8, "-", "foot-ground Coulomb coefficient (Menagerie foot 0.8)", 0.0, 3.0)
    hip_lower: float = _p(-4.18879, "rad", "hip pin lower limit (= -A1 thigh upper)", -6.3, 0.0)
    hip_upper: float = _p(1.0472, "rad", "hip pin upper limit (= -A1 thigh lower)", 0.0, 6.3)
    knee_lower: float = _p(0.916298, "rad", "knee pin lower limit (most extended; = -A1 calf upper)", 0.0, 3.1)
    knee_upper: float = _p(2.69653, "rad", "knee pin upper limit (most bent; = -A1 calf lower)", 0.0, 3.1)
    torque_limit: float = _p(33.5, "N m", "motor torque saturation (A1)", 0.1, 500.0)
    # joint servo -----------------------------------------------------------------------------------
    kp: float = _p(100.0, "N m/rad", "PD stiffness tracking the puppet's joint angles (Menagerie 100)", 0.0, 1e4)
    kd: float = _p(2.0, "N m s/rad", "PD damping on the joint rate (Menagerie joint damping 2)", 0.0, 100.0)
    weight_ff: float = _p(1.0, "-", "fraction of the weight fed forward as J^T F on the legs whose "
                          "feet are on the ground (0: pure PD, as in the post)", 0.0, 2.0)
    # puppet and stepping (the 2023 robot-dog post) ---------------------------------------------------
    stand_height: float = _p(0.27, "m", "torso COM height above the ground (Menagerie home pose)", 0.1, 0.4)
    update_rate: float = _p(30.0, "Hz", "rate of the foot state machine update (the post's step())", 1.0, 1000.0)
    foot_step: float = _p(0.05, "m", "largest move of a puppet foot towards its goal per update "
                          "(the post: 0.05 m; spread evenly over the update period)", 0.001, 1.0)
    lift_height: float = _p(0.1, "m", "foot centre height of the lift goal above the ground (the post: 0.1)", 0.03, 0.2)
    plant_depth: float = _p(0.0, "m", "plant goal below the resting foot centre (foot radius above "
                            "ground; seed 0.02 m = its foot radius)", 0.0, 0.05)
    plant_delay: float = _p(0.1, "s", "wait after planting before the next pair lifts (the post's fix "
                            "for bouncing hard feet)", 0.0, 2.0)
    touch_timeout: float = _p(0.1, "s", "PLANT -> GROUND waits for the real foot's touch at most this "
                              "long after the plant began (0: the post's puppet-only switch)", 0.0, 2.0)
    settle_time: float = _p(0.3, "s", "standing still after the start before the first step", 0.0, 5.0)
    goal_tol: float = _p(0.001, "m", "a puppet foot has reached its goal within this distance (the post)", 1e-6, 0.05)
    # feedback the post lacks ---------------------------------------------------------------------------
    speed: float = _p(0.3, "m/s", "commanded forward speed in WALK (negative: backward)", -1.0, 1.0)
    accel: float = _p(0.5, "m/s^2", "the puppet torso's speed ramps towards the command at this rate, "
                      "starting after settle_time", 0.01, 10.0)
    stance_time: float = _p(0.33, "s", "expected stance duration of a foot (Raibert neutral point "
                            "v T_st / 2); the default FSM timing gives ~0.33 s", 0.0, 2.0)
    placement_gain: float = _p(0.05, "s", "Raibert foot placement: extra step per m/s of speed above "
                               "the command", 0.0, 1.0)
    lead_max: float = _p(0.12, "m", "foot placement limited to +-lead_max from the hip", 0.0, 0.3)
    torso_track_max: float = _p(0.03, "m", "the puppet torso leads the measured torso by at most this "
                                "(x); keeps the stance-leg position feedback bounded", 0.0, 0.5)
    # failure ----------------------------------------------------------------------------------------
    fall_height: float = _p(0.12, "m", "fallen when the torso COM is below this height above ground", 0.0, 0.4)
    fall_pitch: float = _p(0.8, "rad", "fallen when |torso pitch| exceeds this", 0.1, 3.1)

    def __post_init__(self):
        super().__post_init__()
        if self.knee_lower >= self.knee_upper:
            raise ValueError(f"QuadrupedParams.knee_lower={self.knee_lower} must be below knee_upper={self.knee_upper}")
        lo, hi = leg_reach(self)
        for name, d in (("stand_height", self.stand_height - self.foot_radius),
                        ("lift_height", self.stand_height - self.lift_height)):
            if not lo <= d <= hi:
                raise ValueError(f"QuadrupedParams.{name}: hip-to-foot distance {d:.3f} m outside the "
                                 f"leg's reach [{lo:.3f}, {hi:.3f}] m (knee limits)")

    @property
    def total_mass(self) -> float:
        """[kg]"""
        return self.torso_mass + 4 * (self.thigh_mass + self.calf_mass)


def leg_reach(p: QuadrupedParams):
    """(shortest, longest) hip-to-foot distance allowed by the knee limits [m]."""
    l1, l2 = p.thigh_length, p.calf_length
    d = lambda q: math.sqrt(l1 * l1 + l2 * l2 + 2 * l1 * l2 * math.cos(q))  # noqa: E731
    return d(p.knee_upper), d(p.knee_lower)


# the slot of each field in to_array(), by name: compiled code reads p[FIELD.torso_mass]
FIELD = param_slots(QuadrupedParams)
