"""Ranger controller data: FSM enums, the index layout of the constant vector k, of the
controller memory mem and of the motor-program table, and the functions that fill them from
RangerParams (make_tables: all of them as one Tables). The compiled controller (controller.py)
reads these module-level integers.
"""
from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

import numpy as np

from walkers.common.slots import size, slots

from .estimator import butterworth2
from .model import GRAVITY, foot_inertia_com
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
PC = slots("ProgramColumns", ("frame", "target", "kp", "kd", "iff"))   # of the program table

# scalar constants k[...], the fields in this order
CONST = slots("RangerConstants", (
    ("dt", "step [s]"), ("weight", "weight on the feet [N]"), "est_on", "est_off",
    ("b0", 5, "Butterworth coefficients b0, b1, b2, a1, a2 of the load estimator"),
    "foot_i", "foot_m", "foot_cx", "foot_cy", "air_w", "air_z", "air_acc", "scissor",
    "scissor_off", "land_leg", "push_leg", "push_i0", "push_gain", "v_target", "imax", "leg_com",
    "fall_h", "grav", "ds_time", "start_i", "start_leg",
))
N_K = size(CONST)

# columns of a heel-strike record (the step log's rows, and memory's first and last strikes),
# in this order
LOG = slots("StepLogColumns", (
    ("t", "time of the heel strike [s]"), ("hip_x", "hip x [m]"),
    ("e", 4, "the energies of mem's e [J]"), ("push_i", "push-off current [A]"),
))
N_LOG = size(LOG)

# controller memory mem[...] (float64 vector), the fields in this order
MEM = slots("RangerMemory", (
    "gait", "phase", "stance",
    ("filt", 4, "biquad state, 2 per foot"),
    ("sig", 2, "filtered load fraction per foot"),
    ("contact", 2, "estimator flag per foot"),
    "push_i", "v_mid", "mid_done", "steps", "t_strike",
    ("e", 4, "energies [J]: electrical positive, electrical net, mechanical positive, mechanical net"),
    ("e_at", "State.step the energies are counted to (count_step_energy; -1: from the next tick)"),
    ("prog", 3, "program per motor"),
    ("cur", 3, "current per motor [A]"),
    ("pel", 3, "electrical power per motor [W]"),
    ("keep", 3, "joint angles held in flight [rad]"),
    ("fell", "fell flag"),
    ("raw", 2, "raw load fraction per foot"),
    ("touch", 2, "estimator touchdowns per foot"),
    ("airborne", "1 once the swing foot has been seen in the air this step"),
    # what the whole-step numbers need, kept here so a snapshot of the memory carries them
    ("strike_first", N_LOG, "record (columns LOG) of the second heel strike: whole steps start there"),
    ("strike_last", N_LOG, "record (columns LOG) of the last heel strike"),
    ("push_sum", "push-off currents [A] of the heel strikes from the second on, summed"),
))
N_MEM = size(MEM)


def make_constants(p: RangerParams, dt: float, gravity: float = GRAVITY) -> np.ndarray:
    """(N_K,) constants, slots CONST, of RangerParams, the step dt [s] and the model's gravity
    [m/s^2] (its magnitude)."""
    k = np.zeros(N_K)
    k[CONST.dt] = dt
    k[CONST.weight] = gravity * (2 * p.leg_mass + 2 * p.foot_mass)
    k[CONST.est_on], k[CONST.est_off] = p.est_on, p.est_off
    k[CONST.b0:CONST.b0 + 5] = butterworth2(p.est_cutoff, dt)
    k[CONST.foot_i] = foot_inertia_com(p) + p.foot_mass * (p.foot_com_x ** 2 + p.foot_com_y ** 2)
    k[CONST.foot_m], k[CONST.foot_cx], k[CONST.foot_cy] = p.foot_mass, p.foot_com_x, p.foot_com_y
    k[CONST.air_w], k[CONST.air_z], k[CONST.air_acc] = p.air_omega, p.air_zeta, p.free_foot_max_accel
    k[CONST.scissor], k[CONST.scissor_off] = p.scissor_gain, p.scissor_offset
    k[CONST.land_leg], k[CONST.push_leg] = p.land_leg_angle, p.push_leg_angle
    k[CONST.push_i0], k[CONST.push_gain], k[CONST.v_target], k[CONST.imax] = p.push_current, p.push_gain, p.target_speed, p.current_max
    k[CONST.leg_com], k[CONST.fall_h], k[CONST.grav] = p.leg_com, p.fall_height, gravity
    k[CONST.ds_time] = p.ds_time
    k[CONST.start_i], k[CONST.start_leg] = p.start_push_current, p.start_leg_angle
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
    mem[MEM.e_at] = -1.0
    mem[MEM.gait] = gait
    mem[MEM.phase] = PH_STANDING if gait == GAIT_WALK else PH_SINGLE   # STAND captures on entry
    mem[MEM.stance] = 1
    mem[MEM.t_strike] = -1.0
    return mem


def set_standing_estimator(mem: np.ndarray, k: np.ndarray) -> None:
    """Estimator memory of a robot standing at rest on both feet (each foot carrying half the
    weight, filters at their steady state, both flags on), so a run that starts standing does
    not begin with a spurious flight."""
    b0, b1, b2, a1, a2 = k[CONST.b0:CONST.b0 + 5]
    x = 0.5
    for side in range(2):
        mem[MEM.filt + 2 * side] = x - b0 * x           # y = x at steady state
        mem[MEM.filt + 2 * side + 1] = (b2 - a2) * x
        mem[MEM.sig + side] = x
        mem[MEM.raw + side] = x
        mem[MEM.contact + side] = 1


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
    k: np.ndarray         # (N_K,) constants, slots CONST
    prog: np.ndarray      # (N_PROG, 5) motor programs, columns PC
    motor: np.ndarray     # (3, MOTOR_NPARAM) motor rows: hip, outer ankle, inner ankle
    gui: np.ndarray       # (3, 3) GUI joint target [rad], kp [A/rad], kd [A s/rad] (set at run time)
    steplog: np.ndarray   # (max_steps, N_LOG) one row per heel strike (columns LOG), written by the
                          # controller; NaN where none was written (make_step_log)


def make_tables(p: RangerParams, dt: float, max_steps: int = 20000,
                gravity: float = GRAVITY) -> Tables:
    """RangerParams, the step length dt [s] and the model's gravity [m/s^2] (its magnitude) ->
    Tables, with room to log max_steps steps."""
    return Tables(k=make_constants(p, dt, gravity), prog=make_programs(p), motor=motor_table(p),
                  gui=make_gui(p), steplog=make_step_log(max_steps))


def make_step_log(rows: int) -> np.ndarray:
    """(rows, N_LOG) heel-strike log, columns LOG, every row NaN until the controller writes
    it: a row no strike of this run wrote (the strikes before a restored memory's, which a
    snapshot of state and memory does not carry) reads NaN, never as a strike at t = 0, x = 0."""
    return np.full((int(rows), N_LOG), np.nan)
