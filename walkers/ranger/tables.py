"""Ranger controller data: FSM enums, the index layout of the constant vector k, of the
controller memory mem and of the motor-program table, and the functions that fill them from
RangerParams (make_tables: all of them as one Tables). The compiled controller (controller.py)
reads these module-level integers.
"""
from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .estimator import butterworth2
from .model import foot_inertia_com
from .motor import motor_table
from .params import RangerParams


class Gait(IntEnum):
    WALK = 0
    STAND = 1
    GUI = 2


class Phase(IntEnum):
    SINGLE = 0
    DOUBLE = 1
    FLIGHT = 2
    STANDING = 3   # STAND and GUI gaits
    START = 4      # WALK entered from rest: a double stance whose push-off starts the gait


class Program(IntEnum):
    OFF = 0
    HOLD = 1
    PUSH = 2
    FLIP = 3
    SWING = 4
    GUI = 5
    LAND = 6
    KEEP = 7
    STAND = 8


GAIT_WALK, GAIT_STAND, GAIT_GUI = 0, 1, 2
PH_SINGLE, PH_DOUBLE, PH_FLIGHT, PH_STANDING, PH_START = 0, 1, 2, 3, 4
PR_OFF, PR_HOLD, PR_PUSH, PR_FLIP, PR_SWING, PR_GUI, PR_LAND, PR_KEEP, PR_STAND = 0, 1, 2, 3, 4, 5, 6, 7, 8
N_PROG = 9
FR_REL, FR_ABS, FR_SCISSOR, FR_PUSH, FR_NONE = 0, 1, 2, 3, 4
PC_FRAME, PC_TARGET, PC_KP, PC_KD, PC_IFF = 0, 1, 2, 3, 4

# scalar constants k[...]
K_DT, K_WEIGHT, K_EST_ON, K_EST_OFF = 0, 1, 2, 3
K_B0 = 4                       # 5 Butterworth coefficients 4..8
K_FOOT_I, K_FOOT_M, K_FOOT_CX, K_FOOT_CY = 9, 10, 11, 12
K_AIR_W, K_AIR_Z, K_AIR_ACC = 13, 14, 15
K_SCISSOR, K_SCISSOR_OFF = 16, 17
K_LAND_LEG, K_PUSH_LEG = 18, 19
K_PUSH_I0, K_PUSH_GAIN, K_V_TARGET, K_IMAX = 20, 21, 22, 23
K_LEG_COM, K_FALL_H, K_GRAV, K_DS_TIME = 24, 25, 26, 27
K_START_I, K_START_LEG = 28, 29
N_K = 30

# memory mem[...]
M_GAIT, M_PHASE, M_STANCE = 0, 1, 2
M_FILT = 3        # biquad state, 2 per foot: 3..6
M_SIG = 7         # filtered load fraction per foot: 7, 8
M_CONTACT = 9     # estimator flag per foot: 9, 10
M_PUSH_I, M_V_MID, M_MID_DONE, M_STEPS, M_T_STRIKE = 11, 12, 13, 14, 15
M_E = 16          # energies [J]: electrical positive, electrical net, mechanical positive, mechanical net
M_PROG = 20       # program per motor: 20..22
M_CUR = 23        # current per motor [A]: 23..25
M_PEL = 26        # electrical power per motor [W]: 26..28
M_KEEP = 29       # joint angles held in flight: 29..31
M_FELL, M_RAW = 32, 33   # fell flag; raw load fraction per foot 33, 34
M_TOUCH = 35      # estimator touchdowns per foot: 35, 36
M_STRIKE_X = 37   # hip x at the last heel strike
M_AIRBORNE = 38   # 1 once the swing foot has been seen in the air this step
N_MEM = 40
N_LOG = 7         # step log row: t, hip x, 4 energies, push current


def make_constants(p: RangerParams, dt: float) -> np.ndarray:
    k = np.zeros(N_K)
    k[K_DT] = dt
    k[K_WEIGHT] = 9.81 * (2 * p.leg_mass + 2 * p.foot_mass)
    k[K_EST_ON], k[K_EST_OFF] = p.est_on, p.est_off
    k[K_B0:K_B0 + 5] = butterworth2(p.est_cutoff, dt)
    k[K_FOOT_I] = foot_inertia_com(p) + p.foot_mass * (p.foot_com_x ** 2 + p.foot_com_y ** 2)
    k[K_FOOT_M], k[K_FOOT_CX], k[K_FOOT_CY] = p.foot_mass, p.foot_com_x, p.foot_com_y
    k[K_AIR_W], k[K_AIR_Z], k[K_AIR_ACC] = p.air_omega, p.air_zeta, p.free_foot_max_accel
    k[K_SCISSOR], k[K_SCISSOR_OFF] = p.scissor_gain, p.scissor_offset
    k[K_LAND_LEG], k[K_PUSH_LEG] = p.land_leg_angle, p.push_leg_angle
    k[K_PUSH_I0], k[K_PUSH_GAIN], k[K_V_TARGET], k[K_IMAX] = p.push_current, p.push_gain, p.target_speed, p.current_max
    k[K_LEG_COM], k[K_FALL_H], k[K_GRAV] = p.leg_com, p.fall_height, 9.81
    k[K_DS_TIME] = p.ds_time
    k[K_START_I], k[K_START_LEG] = p.start_push_current, p.start_leg_angle
    return k


def make_programs(p: RangerParams) -> np.ndarray:
    """(N_PROG, 5) motor program table: frame, target, kp [A/rad], kd [A s/rad], I_ff [A]."""
    t = np.zeros((N_PROG, 5))
    t[PR_OFF] = (FR_NONE, 0, 0, 0, 0)
    t[PR_HOLD] = (FR_ABS, 0.0, p.hold_kp, p.hold_kd, 0)
    t[PR_PUSH] = (FR_PUSH, p.push_limit_angle, p.hold_kp, p.hold_kd, 0)   # I_ff from memory
    t[PR_FLIP] = (FR_REL, p.flip_angle, p.hold_kp, p.hold_kd, 0)
    t[PR_SWING] = (FR_SCISSOR, p.scissor_offset, p.hip_kp, p.hip_kd, 0)
    t[PR_GUI] = (FR_REL, 0, 0, 0, 0)                                        # from the gui table
    t[PR_LAND] = (FR_ABS, p.land_angle, p.hold_kp, p.hold_kd, 0)
    t[PR_KEEP] = (FR_REL, 0, p.flight_kp, p.flight_kd, 0)                  # target from memory
    t[PR_STAND] = (FR_ABS, 0, p.hold_kp, p.hold_kd, 0)                      # target from memory
    return t


def make_memory(gait: int = GAIT_WALK) -> np.ndarray:
    mem = np.zeros(N_MEM)
    mem[M_GAIT] = gait
    mem[M_PHASE] = PH_STANDING if gait == GAIT_WALK else PH_SINGLE   # STAND captures on entry
    mem[M_STANCE] = 1
    mem[M_T_STRIKE] = -1.0
    return mem


def set_standing_estimator(mem: np.ndarray, k: np.ndarray) -> None:
    """Estimator memory of a robot standing at rest on both feet (each foot carrying half the
    weight, filters at their steady state, both flags on), so a run that starts standing does
    not begin with a spurious flight."""
    b0, b1, b2, a1, a2 = k[K_B0:K_B0 + 5]
    x = 0.5
    for side in range(2):
        mem[M_FILT + 2 * side] = x - b0 * x           # y = x at steady state
        mem[M_FILT + 2 * side + 1] = (b2 - a2) * x
        mem[M_SIG + side] = x
        mem[M_RAW + side] = x
        mem[M_CONTACT + side] = 1


def make_gui(p: RangerParams) -> np.ndarray:
    """(3, 3) GUI table per joint (hip, outer ankle, inner ankle): target [rad], kp, kd."""
    g = np.zeros((3, 3))
    g[:, 1] = (p.hip_kp, p.hold_kp, p.hold_kp)
    g[:, 2] = (p.hip_kd, p.hold_kd, p.hold_kd)
    g[0, 0] = p.stand_front_angle - p.stand_rear_angle          # the STAND pose's pin angles
    g[1, 0] = -p.stand_rear_angle
    g[2, 0] = -p.stand_front_angle
    return g


class Tables(NamedTuple):
    """What the compiled controller reads, as one argument (and the step log it writes)."""
    k: np.ndarray         # (N_K,) constants, indices K_*
    prog: np.ndarray      # (N_PROG, 5) motor programs, columns PC_*
    motor: np.ndarray     # (3, MOTOR_NPARAM) motor rows: hip, outer ankle, inner ankle
    gui: np.ndarray       # (3, 3) GUI joint target [rad], kp [A/rad], kd [A s/rad] (set at run time)
    steplog: np.ndarray   # (max_steps, N_LOG) one row per heel strike, written by the controller


def make_tables(p: RangerParams, dt: float, max_steps: int = 20000) -> Tables:
    """RangerParams and the step length dt [s] -> Tables, with room to log max_steps steps."""
    return Tables(k=make_constants(p, dt), prog=make_programs(p), motor=motor_table(p),
                  gui=make_gui(p), steplog=np.zeros((int(max_steps), N_LOG)))
