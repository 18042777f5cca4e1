"""Parameters of the 2D SIMBICON biped (Thachuk 2018: Tables 3 and 4, eqs. 1-3).

One frozen dataclass; each field carries doc, unit, bounds and whether the tuner may change it
(``tune``) in its metadata. Angles follow the thesis' Table 3 sign convention, which is also
ours (counter-clockwise positive, x forward): hip > 0 swings the thigh forward, knee < 0 bends
the knee, ankle > 0 lifts the toe. Targets come in two sets, one per half of a step: ``_0``
for the timed states 0 and 2, ``_1`` for the contact-ended states 1 and 3; the left/right
mirror is data (controller.py), so there is one table, not four copies.

``THESIS`` holds the thesis' own values (Tables 3 and 4, kp = 800 N m/rad, kd = 80 N m s/rad
everywhere). The dataclass defaults are the shipped, tuned values: see ``SHIPPED_NOTE``.
"""
from __future__ import annotations

from dataclasses import dataclass

from walkers.common.params import WalkerParams, param


def _p(default, unit, doc, lo, hi, tune=True):
    """A parameter field; tune=False keeps it out of the tuner's vector."""
    return param(default, unit, doc, lo, hi, tune=tune)


@dataclass(frozen=True)
class SimbiconParams(WalkerParams):
    # FSM timing ------------------------------------------------------------------------------
    state_time: float = _p(0.2444, "s", "duration of the timed states 0 and 2 (Table 1)", 0.1, 0.6)
    contact_timeout: float = _p(0.6, "s", "states 1 and 3 end after this long even without a "
                                "swing-foot contact, so the FSM never stalls", 0.05, 2.0, tune=False)
    min_contact_time: float = _p(0.0, "s", "a swing-foot contact earlier than this in states 1/3 "
                                 "is a scuff and does not end the state", 0.0, 0.3, tune=False)
    # Table 3: target angles -----------------------------------------------------------------
    torso: float = _p(-0.2882, "rad", "torso pitch target in the world frame (all states)", -0.3, 0.3)
    swing_hip_0: float = _p(1.0299, "rad", "swing thigh angle, world frame, states 0/2", 0.0, 1.4)
    swing_knee_0: float = _p(-1.4623, "rad", "swing knee, states 0/2", -1.57, 0.0)
    swing_ankle_0: float = _p(0.0407, "rad", "swing ankle, states 0/2", -1.0, 0.26)
    stance_knee_0: float = _p(-0.012, "rad", "stance knee, states 0/2", -1.0, 0.0)
    stance_ankle_0: float = _p(0.0186, "rad", "stance ankle, states 0/2", -1.0, 0.26)
    swing_hip_1: float = _p(-0.356, "rad", "swing thigh angle, world frame, states 1/3", -1.0, 1.0)
    swing_knee_1: float = _p(-0.4052, "rad", "swing knee, states 1/3", -1.57, 0.0)
    swing_ankle_1: float = _p(-0.2301, "rad", "swing ankle, states 1/3", -1.0, 0.26)
    stance_knee_1: float = _p(-0.176, "rad", "stance knee, states 1/3", -1.0, 0.0)
    stance_ankle_1: float = _p(0.2562, "rad", "stance ankle, states 1/3", -1.0, 0.26)
    # Table 4: balance feedback (eq. 3) -------------------------------------------------------
    cd_0: float = _p(3.7784, "rad/m", "eq. 3 gain on d (torso ahead of stance ankle), states 0/2", -1.0, 4.0)
    cv_0: float = _p(0.0343, "rad s/m", "eq. 3 gain on v (torso forward speed), states 0/2", -1.0, 2.0)
    cd_1: float = _p(-0.8703, "rad/m", "eq. 3 gain on d, states 1/3", -1.0, 4.0)
    cv_1: float = _p(-0.4305, "rad s/m", "eq. 3 gain on v, states 1/3", -1.0, 2.0)
    # Table 4: PD gains (eq. 1) --------------------------------------------------------------
    kp_hip: float = _p(766.7453, "N m/rad", "swing hip gain (world-frame thigh angle)", 50.0, 2000.0)
    kd_hip: float = _p(148.6531, "N m s/rad", "swing hip damping", 2.0, 200.0)
    kp_knee: float = _p(653.3073, "N m/rad", "knee gain", 50.0, 2000.0)
    kd_knee: float = _p(74.2015, "N m s/rad", "knee damping", 2.0, 200.0)
    kp_ankle: float = _p(70.2546, "N m/rad", "ankle gain", 10.0, 2000.0)
    kd_ankle: float = _p(3.3244, "N m s/rad", "ankle damping", 0.5, 200.0)
    kp_torso: float = _p(2973.7945, "N m/rad", "virtual torso gain (eq. 2, via the stance hip)", 50.0, 3000.0)
    kd_torso: float = _p(233.052, "N m s/rad", "virtual torso damping", 2.0, 300.0)
    # model ------------------------------------------------------------------------------------
    hip_torque_max: float = _p(400.0, "N m", "hip motor limit", 1.0, 5000.0, tune=False)
    knee_torque_max: float = _p(400.0, "N m", "knee motor limit", 1.0, 5000.0, tune=False)
    ankle_torque_max: float = _p(200.0, "N m", "ankle motor limit", 1.0, 5000.0, tune=False)
    mu: float = _p(1.0, "-", "Coulomb friction of the foot corners", 0.0, 5.0, tune=False)
    start_lean: float = _p(0.05, "rad", "start pose: straight legs tilted forward about the ankles "
                           "(at rest), so the character begins by falling forward", 0.0, 0.25, tune=False)
    start_speed: float = _p(0.0, "m/s", "start: forward speed of every body (0: from rest)",
                            0.0, 2.0, tune=False)
    fall_height: float = _p(0.7, "m", "torso COM below this height above the ground is a fall",
                            0.0, 1.5, tune=False)


THESIS = SimbiconParams(
    state_time=0.3, torso=0.0,
    swing_hip_0=0.7, swing_knee_0=-1.3, swing_ankle_0=0.2, stance_knee_0=-0.05, stance_ankle_0=0.2,
    swing_hip_1=-0.7, swing_knee_1=-0.05, swing_ankle_1=0.2, stance_knee_1=-0.1, stance_ankle_1=0.2,
    cd_0=0.0, cv_0=0.2, cd_1=2.2, cv_1=0.0,
    kp_hip=800.0, kd_hip=80.0, kp_knee=800.0, kd_knee=80.0, kp_ankle=800.0, kd_ankle=80.0,
    kp_torso=800.0, kd_torso=80.0)
"""Tables 3 and 4 of the thesis, unchanged (one kp/kd pair for every joint)."""

SHIPPED_NOTE = (
    "The dataclass defaults are the thesis' Tables 3/4 after three CMA-ES stages (planarsim tune) "
    "in this engine: (1) from SIMBICON-like targets (swing hip 0.5/-0.1, knee -1.1/-0.05, stance "
    "ankle 0, ankle gains 300/30), 1584 evaluations of 10 s walks (seed 3); (2) 640 evaluations "
    "of 20 s walks with +-60 N pushes (seed 5); (3) from (2), 20 s walks with +-60/80/100 N "
    "pushes (seed 11): the best after 176 evaluations, kept because it still walks and recovers "
    "when its values are rounded (the stage's final best did not survive rounding to 1e-4). "
    "Tunable fields rounded to 1e-4. The thesis' own values walk backwards and fall here.")
