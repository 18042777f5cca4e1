"""Ranger controller (Kelly 2014, section 6): FSM WALK / STAND / GUI over motor programs.

Motor programs are rows of a table ``prog[program] = (frame, target, kp, kd, current_ff)``,
a PD on the motor current (eq. 18) ``I = I_ff + kp (target - x) + kd (0 - dx)``, where the frame
says what x is:
  REL      the pin angle (hip: theta_inner - theta_outer; ankle: theta_foot - theta_leg)
  ABS      the foot's absolute angle (0 level)
  SCISSOR  hip only: x = theta_swing + c theta_stance (the swing leg mirrors the stance leg)
  PUSH     ankle: constant current I_ff (toe down) until the foot reaches the target, then PD
  NONE     zero current (OFF)
Programs OFF, HOLD, PUSH, FLIP, SWING, GUI are Kelly's; LAND (HOLD with the landing target)
and KEEP (hold the joint angles captured when flight began) are two more rows of data.
An ankle whose foot the estimator puts in the air runs the model-based controller of section
6.5 instead of the current PD: a spring-mass-damper of natural frequency w0 and damping ratio
zeta on the foot inertia (kp = w0^2 I, kd = 2 zeta w0 I; Kelly's kd = 2 zeta w0^2 I is not
dimensionally a damping) plus cancellation of gravity's torque on the foot, and its current is
saturated to I_foot * free_foot_max_accel / (G K) (Kelly's light-foot torque limit).

WALK (stance side s, swing side w = 1 - s, chosen by the contact estimator):
  DOUBLE (both feet down): stance = the foot that landed (leading) HOLD, trailing PUSH, hip OFF
  SINGLE: stance HOLD, or PUSH once its leg is past push_leg_angle behind vertical; hip SWING;
          swing ankle FLIP (toe up, clears the ground) until the legs are land_leg_angle apart
          (swing leg ahead), then LAND
  FLIGHT (no foot down): every joint KEEPs its angle.
  START (WALK entered at rest, from STAND or the start of a run): DOUBLE's programs with the
          start-up push current, until the leading leg is start_leg_angle past vertical.
Step-to-step feedback (Kelly 2014, 6.6, "increase the push-off"): at mid-stance (stance leg passing
vertical) the hip speed v is measured and the push-off current of that step's push is set to
I_push = clip(push_current + push_gain (target_speed - v), 0, Imax).
"""
from __future__ import annotations

import math

import numpy as np

from planarsim.compiled import jit_inline, kernel, pin_angle_rate, height as terrain_height

from .estimator import filter_step, hysteresis
from .motor import drive_motor, torque_constant
from .params import RangerParams


# the tables' enums, index layout of k / mem / prog, and table makers (named, not starred)
from .tables import (
    FR_ABS, FR_NONE, FR_PUSH, FR_SCISSOR, GAIT_GUI, GAIT_STAND, GAIT_WALK, Gait, K_AIR_ACC,
    K_AIR_W, K_AIR_Z, K_B0, K_DS_TIME, K_DT, K_EST_OFF, K_EST_ON, K_FALL_H, K_FOOT_CX,
    K_FOOT_CY, K_FOOT_I, K_FOOT_M, K_GRAV, K_IMAX, K_LAND_LEG, K_LEG_COM, K_PUSH_GAIN,
    K_PUSH_I0, K_PUSH_LEG, K_SCISSOR, K_START_I, K_START_LEG, K_V_TARGET, K_WEIGHT, M_AIRBORNE,
    M_CONTACT, M_CUR, M_E, M_FELL, M_FILT, M_GAIT, M_KEEP, M_MID_DONE, M_PEL, M_PHASE, M_PROG,
    M_PUSH_I, M_RAW, M_SIG, M_STANCE, M_STEPS, M_TOUCH, M_T_STRIKE, M_V_MID, N_LOG,
    PC_FRAME, PC_IFF, PC_KD, PC_KP, PC_TARGET, PH_DOUBLE, PH_FLIGHT, PH_SINGLE, PH_STANDING,
    PH_START, PR_FLIP, PR_GUI, PR_HOLD, PR_KEEP, PR_LAND, PR_OFF, PR_PUSH, PR_STAND, PR_SWING,
    make_memory, make_tables, set_standing_estimator)


# --------------------------------------------------------------------------------------------
@kernel
def update_estimator(m, s, ws, k, mem):
    """Filter each foot's load fraction and update its contact flag; count touchdowns."""
    scale = 1.0 / (k[K_DT] * k[K_WEIGHT])
    for side in range(2):
        raw = ws.contact_impulse[side, 0] * scale
        mem[M_RAW + side] = raw
        y = filter_step(raw, k, K_B0, mem, M_FILT + 2 * side)
        mem[M_SIG + side] = y
        old = int(mem[M_CONTACT + side])
        new = hysteresis(y, old, k[K_EST_ON], k[K_EST_OFF])
        if new == 1 and old == 0:
            mem[M_TOUCH + side] += 1
        mem[M_CONTACT + side] = new


@kernel
def hip_state(s, k, side):
    """Hip position and velocity [m, m/s] from leg `side` (hip at leg_com above its COM)."""
    th = s.q[side, 2]
    c = k[K_LEG_COM]
    rx = -c * math.sin(th)
    ry = c * math.cos(th)
    w = s.v[side, 2]
    return s.q[side, 0] + rx, s.q[side, 1] + ry, s.v[side, 0] - w * ry, s.v[side, 1] + w * rx


@kernel
def choose_programs(m, s, k, mem):
    """WALK: phase, stance and the program of each motor (into mem[M_PROG + j]).

    SINGLE -> DOUBLE at heel strike: the swing foot, seen in the air since it lifted, is seen
    on the ground again ahead of the stance foot; it becomes the stance foot (a step).
    DOUBLE -> SINGLE when the trailing foot leaves or double stance has lasted ds_time: the
    trailing foot becomes the swing foot. No foot down -> FLIGHT; a foot down -> SINGLE on it.
    From rest (STANDING, both feet down) -> START: a double stance like DOUBLE (same motor
    programs) whose trailing push uses start_push_current and which ends when the leading leg
    has passed start_leg_angle (the hip over the leading foot), not after ds_time.
    """
    c0 = int(mem[M_CONTACT])
    c1 = int(mem[M_CONTACT + 1])
    phase = int(mem[M_PHASE])
    st = int(mem[M_STANCE])
    t = s.time[0]
    if c0 == 0 and c1 == 0:
        if phase != PH_FLIGHT:
            for j in range(3):
                mem[M_KEEP + j] = pin_angle_rate(m, s.q, s.v, j)[0]
        phase = PH_FLIGHT
    elif phase == PH_FLIGHT or phase == PH_STANDING:
        # landing from flight, or starting from standing: the leading foot down is the stance;
        # from standing, the start-up double stance (PH_START) with its own push current
        if c0 == 1 and c1 == 1:
            st = 1 if s.q[3, 0] > s.q[2, 0] else 0
            if phase == PH_STANDING:
                phase = PH_START
                mem[M_PUSH_I] = k[K_START_I]
            else:
                phase = PH_DOUBLE
            mem[M_T_STRIKE] = t
        else:
            st = 0 if c0 == 1 else 1
            phase = PH_SINGLE
        mem[M_AIRBORNE] = 0
    elif phase == PH_SINGLE:
        sw = 1 - st
        if mem[M_CONTACT + sw] == 0:
            mem[M_AIRBORNE] = 1
        if mem[M_CONTACT + st] == 0:
            # the stance foot left while the swing foot is down: swap without a step
            st = sw
            mem[M_AIRBORNE] = 0
        elif mem[M_CONTACT + sw] == 1 and mem[M_AIRBORNE] == 1 and s.q[2 + sw, 0] > s.q[2 + st, 0]:
            # heel strike: a step
            st = sw
            phase = PH_DOUBLE
            mem[M_STEPS] += 1
            mem[M_T_STRIKE] = t
            mem[M_MID_DONE] = 0
            mem[M_AIRBORNE] = 0
    else:
        # double stance: the trailing foot pushes off, then swings; it swings when it has
        # left, or double stance has lasted ds_time (PH_DOUBLE), or the hip has come over the
        # leading foot (PH_START)
        sw = 1 - st
        if phase == PH_START:
            done = s.q[st, 2] <= k[K_START_LEG]
        else:
            done = t - mem[M_T_STRIKE] > k[K_DS_TIME]
        if mem[M_CONTACT + sw] == 0 or done:
            phase = PH_SINGLE
            mem[M_AIRBORNE] = 1 - mem[M_CONTACT + sw]
    mem[M_PHASE] = phase
    mem[M_STANCE] = st
    sw = 1 - st
    th_st = s.q[st, 2]
    th_sw = s.q[sw, 2]
    if phase == PH_FLIGHT:
        mem[M_PROG] = PR_KEEP
        mem[M_PROG + 1] = PR_KEEP
        mem[M_PROG + 2] = PR_KEEP
        return
    # mid-stance: the step-to-step feedback sets this step's push-off current
    if phase == PH_SINGLE and mem[M_MID_DONE] == 0 and th_st <= 0.0:
        hx, hy, vx, vy = hip_state(s, k, st)
        mem[M_V_MID] = vx
        ip = k[K_PUSH_I0] + k[K_PUSH_GAIN] * (k[K_V_TARGET] - vx)
        mem[M_PUSH_I] = min(max(ip, 0.0), k[K_IMAX])
        mem[M_MID_DONE] = 1
    if phase == PH_DOUBLE or phase == PH_START:
        mem[M_PROG] = PR_OFF
        mem[M_PROG + 1 + st] = PR_HOLD
        mem[M_PROG + 1 + sw] = PR_PUSH
        return
    mem[M_PROG] = PR_SWING
    mem[M_PROG + 1 + st] = PR_PUSH if (mem[M_MID_DONE] == 1 and th_st < k[K_PUSH_LEG]) else PR_HOLD
    mem[M_PROG + 1 + sw] = PR_LAND if th_sw - th_st > k[K_LAND_LEG] else PR_FLIP


@kernel
def program_current(m, s, k, prog, gui, mem, motor, j, pr, in_air):
    """Current command [A] of motor j (0 hip, 1 + side ankle) running program pr."""
    frame = int(prog[pr, PC_FRAME])
    target = prog[pr, PC_TARGET]
    kp = prog[pr, PC_KP]
    kd = prog[pr, PC_KD]
    iff = prog[pr, PC_IFF]
    if frame == FR_NONE:
        return 0.0
    if pr == PR_GUI:
        target = gui[j, 0]
        kp = gui[j, 1]
        kd = gui[j, 2]
    elif pr == PR_KEEP or pr == PR_STAND:
        target = mem[M_KEEP + j]
    ang, rate = pin_angle_rate(m, s.q, s.v, j)
    if j == 0:
        if frame == FR_SCISSOR:
            st = int(mem[M_STANCE])
            sw = 1 - st
            c = k[K_SCISSOR]
            x = s.q[sw, 2] + c * s.q[st, 2]
            dx = s.v[sw, 2] + c * s.v[st, 2]
            sign = 1.0 if sw == 1 else -1.0     # the hip torque turns the inner leg (+)
            return sign * (kp * (target - x) - kd * dx)
        return kp * (target - ang) - kd * rate
    foot = 1 + j
    if frame == FR_ABS or frame == FR_PUSH:
        x = s.q[foot, 2]
        dx = s.v[foot, 2]
    else:
        x = ang
        dx = rate
    if frame == FR_PUSH and x > target:
        return -mem[M_PUSH_I]                # toe down at constant current
    if in_air == 1 and pr != PR_GUI and pr != PR_KEEP and pr != PR_STAND:
        return air_current(s, k, motor, foot, target - x, -dx)
    return kp * (target - x) - kd * dx


@kernel
def air_current(s, k, mp, foot, err, derr):
    """Section 6.5: model-based swing-foot control, I = tau / (G K) with
    tau = w0^2 I_f err + 2 zeta w0 I_f derr - tau_gravity (gravity's torque on the foot about
    its ankle, cancelled)."""
    i_f = k[K_FOOT_I]
    w0 = k[K_AIR_W]
    th = s.q[foot, 2]
    # foot COM relative to the ankle, world frame
    rx = math.cos(th) * k[K_FOOT_CX] - math.sin(th) * k[K_FOOT_CY]
    tau_gravity = rx * (-k[K_GRAV] * k[K_FOOT_M])
    tau = w0 * w0 * i_f * err + 2.0 * k[K_AIR_Z] * w0 * i_f * derr - tau_gravity
    return tau / torque_constant(mp)


@jit_inline
def control(m, s, ws, tab, mem, u):
    """One control step: estimator, FSM, motor programs, motor model -> u (torques [N m]).
    Also integrates electrical and mechanical energy and logs each heel strike (tab.steplog)."""
    k = tab.k
    prog = tab.prog
    motor = tab.motor
    gui = tab.gui
    steplog = tab.steplog
    update_estimator(m, s, ws, k, mem)
    gait = int(mem[M_GAIT])
    steps_before = mem[M_STEPS]
    p0 = PR_OFF
    p1 = PR_HOLD
    p2 = PR_HOLD
    if gait == GAIT_WALK:
        choose_programs(m, s, k, mem)
        p0 = int(mem[M_PROG])
        p1 = int(mem[M_PROG + 1])
        p2 = int(mem[M_PROG + 2])
    else:
        if mem[M_PHASE] != PH_STANDING:
            # STAND holds the feet at the absolute angles they have when it begins
            for side in range(2):
                mem[M_KEEP + 1 + side] = s.q[2 + side, 2]
        mem[M_PHASE] = PH_STANDING
        p1 = PR_STAND
        p2 = PR_STAND
        if gait == GAIT_GUI:
            p0 = PR_GUI
            p1 = PR_GUI
            p2 = PR_GUI
    mem[M_PROG] = p0
    mem[M_PROG + 1] = p1
    mem[M_PROG + 2] = p2
    dt = k[K_DT]
    for j in range(3):
        pr = int(mem[M_PROG + j])
        in_air = 0
        if j > 0 and mem[M_CONTACT + j - 1] == 0:
            in_air = 1
        cur = program_current(m, s, k, prog, gui, mem, motor[j], j, pr, in_air)
        if in_air == 1:
            # light foot behind a heavy leg: cap the angular acceleration a torque can cause
            cap = k[K_FOOT_I] * k[K_AIR_ACC] / torque_constant(motor[j])
            cur = min(max(cur, -cap), cap)
        rate = pin_angle_rate(m, s.q, s.v, j)[1]
        cur, tau, pel = drive_motor(motor[j], cur, rate)
        tau = min(max(tau, m.act_range[j, 0]), m.act_range[j, 1])
        u[j] = tau
        mem[M_CUR + j] = cur
        mem[M_PEL + j] = pel
        pm = tau * rate
        mem[M_E] += dt * max(pel, 0.0)
        mem[M_E + 1] += dt * pel
        mem[M_E + 2] += dt * max(pm, 0.0)
        mem[M_E + 3] += dt * pm
    # fall and step log
    hx, hy, vx, vy = hip_state(s, k, 0)
    if hy - height_below(m, hx) < k[K_FALL_H] or abs(s.q[0, 2]) > 1.2 or abs(s.q[1, 2]) > 1.2:
        mem[M_FELL] = 1
    if mem[M_STEPS] > steps_before:
        n = int(mem[M_STEPS]) - 1
        if n < steplog.shape[0]:
            steplog[n, 0] = s.time[0]
            steplog[n, 1] = hx
            for e in range(4):
                steplog[n, 2 + e] = mem[M_E + e]
            steplog[n, 6] = mem[M_PUSH_I]


@kernel
def height_below(m, x):
    """Terrain height [m] at x."""
    return terrain_height(m.terrain_coef, x)


# --------------------------------------------------------------------------------------------
class Controller:
    """Python-side holder of the compiled controller's tables and memory.

    ``Controller(params, dt)``; ``set_gait("walk"|"stand"|"gui")``; ``set_gui(joint, target,
    kp, kd)`` (joint 0 hip, 1 outer ankle, 2 inner ankle; REL pin angles [rad], gains [A/rad],
    [A s/rad]); ``__call__(sim) -> u`` runs one control step on a Simulator (the Python path).
    ``reset`` refills the memory in place (a run holding it sees the new values).
    """

    GAITS = {"walk": GAIT_WALK, "stand": GAIT_STAND, "gui": GAIT_GUI}

    def __init__(self, params: RangerParams | None = None, dt: float = 1e-3, max_steps: int = 20000):
        self.params = params if params is not None else RangerParams()
        self.tables = make_tables(self.params, dt, max_steps)
        self.mem = make_memory()
        self.reset()

    def reset(self, gait: str = "walk") -> None:
        self.mem[:] = make_memory(self._gait_id(gait))
        set_standing_estimator(self.mem, self.tables.k)      # every run starts standing at rest
        p = self.params
        self.mem[M_PUSH_I] = min(p.push_current + p.push_gain * p.target_speed, p.current_max)
        self.tables.steplog[:] = 0.0

    def _gait_id(self, gait) -> int:
        if isinstance(gait, str):
            if gait not in self.GAITS:
                raise ValueError(f"Ranger gait {gait!r} unknown; use one of {sorted(self.GAITS)}")
            return self.GAITS[gait]
        return int(Gait(gait))

    def set_gait(self, gait) -> None:
        self.mem[M_GAIT] = self._gait_id(gait)

    def set_gui(self, joint: int, target: float, kp: float | None = None, kd: float | None = None) -> None:
        if joint not in (0, 1, 2):
            raise ValueError(f"GUI joint {joint!r} must be 0 (hip), 1 (outer ankle) or 2 (inner ankle)")
        gui = self.tables.gui
        gui[joint, 0] = float(target)
        if kp is not None:
            gui[joint, 1] = float(kp)
        if kd is not None:
            gui[joint, 2] = float(kd)

    def __call__(self, sim) -> np.ndarray:
        u = np.zeros(3)
        control(sim.model.arrays, sim.state, sim.ws, self.tables, self.mem, u)
        return u
