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

from planarsim.actuators import motor_power
from planarsim.compiled import jit_inline, kernel, pin_angle_rate, height as terrain_height

from walkers.common.work import once_per_step

from .estimator import filter_step, hysteresis
from .motor import drive_motor, torque_constant
from .model import GRAVITY
from .params import RangerParams


# the tables' enums, index layout of k / mem / prog, and table makers (named, not starred)
from .tables import (
    CONST, FR_ABS, FR_NONE, FR_PUSH, FR_SCISSOR, GAIT_GUI, GAIT_STAND, GAIT_WALK, Gait, MEM,
    LOG, N_LOG, PC, PH_DOUBLE, PH_FLIGHT, PH_SINGLE, PH_STANDING, PH_START, PR_FLIP, PR_GUI,
    PR_HOLD, PR_KEEP, PR_LAND, PR_OFF, PR_PUSH, PR_STAND, PR_SWING, make_memory, make_tables,
    set_standing_estimator,
)


# --------------------------------------------------------------------------------------------
@kernel
def update_estimator(m, s, ws, k, mem):
    """Filter each foot's load fraction and update its contact flag; count touchdowns."""
    scale = 1.0 / (k[CONST.dt] * k[CONST.weight])
    for side in range(2):
        raw = ws.contact_impulse[side, 0] * scale
        mem[MEM.raw + side] = raw
        y = filter_step(raw, k, CONST.b0, mem, MEM.filt + 2 * side)
        mem[MEM.sig + side] = y
        old = int(mem[MEM.contact + side])
        new = hysteresis(y, old, k[CONST.est_on], k[CONST.est_off])
        if new == 1 and old == 0:
            mem[MEM.touch + side] += 1
        mem[MEM.contact + side] = new


@kernel
def hip_state(s, k, side):
    """Hip position and velocity [m, m/s] from leg `side` (hip at leg_com above its COM)."""
    th = s.q[side, 2]
    c = k[CONST.leg_com]
    rx = -c * math.sin(th)
    ry = c * math.cos(th)
    w = s.v[side, 2]
    return s.q[side, 0] + rx, s.q[side, 1] + ry, s.v[side, 0] - w * ry, s.v[side, 1] + w * rx


@kernel
def choose_programs(m, s, k, mem):
    """WALK: phase, stance and the program of each motor (into mem[MEM.prog + j]).

    SINGLE -> DOUBLE at heel strike: the swing foot, seen in the air since it lifted, is seen
    on the ground again ahead of the stance foot; it becomes the stance foot (a step).
    DOUBLE -> SINGLE when the trailing foot leaves or double stance has lasted ds_time: the
    trailing foot becomes the swing foot. No foot down -> FLIGHT; a foot down -> SINGLE on it.
    From rest (STANDING, both feet down) -> START: a double stance like DOUBLE (same motor
    programs) whose trailing push uses start_push_current and which ends when the leading leg
    has passed start_leg_angle (the hip over the leading foot), not after ds_time.
    """
    c0 = int(mem[MEM.contact])
    c1 = int(mem[MEM.contact + 1])
    phase = int(mem[MEM.phase])
    st = int(mem[MEM.stance])
    t = s.time[0]
    if c0 == 0 and c1 == 0:
        if phase != PH_FLIGHT:
            for j in range(3):
                mem[MEM.keep + j] = pin_angle_rate(m, s.q, s.v, j)[0]
        phase = PH_FLIGHT
    elif phase == PH_FLIGHT or phase == PH_STANDING:
        # landing from flight, or starting from standing: the leading foot down is the stance;
        # from standing, the start-up double stance (PH_START) with its own push current
        if c0 == 1 and c1 == 1:
            st = 1 if s.q[3, 0] > s.q[2, 0] else 0
            if phase == PH_STANDING:
                phase = PH_START
                mem[MEM.push_i] = k[CONST.start_i]
            else:
                phase = PH_DOUBLE
            mem[MEM.t_strike] = t
        else:
            st = 0 if c0 == 1 else 1
            phase = PH_SINGLE
        mem[MEM.airborne] = 0
    elif phase == PH_SINGLE:
        sw = 1 - st
        if mem[MEM.contact + sw] == 0:
            mem[MEM.airborne] = 1
        if mem[MEM.contact + st] == 0:
            # the stance foot left while the swing foot is down: swap without a step
            st = sw
            mem[MEM.airborne] = 0
        elif mem[MEM.contact + sw] == 1 and mem[MEM.airborne] == 1 and s.q[2 + sw, 0] > s.q[2 + st, 0]:
            # heel strike: a step
            st = sw
            phase = PH_DOUBLE
            mem[MEM.steps] += 1
            mem[MEM.t_strike] = t
            mem[MEM.mid_done] = 0
            mem[MEM.airborne] = 0
    else:
        # double stance: the trailing foot pushes off, then swings; it swings when it has
        # left, or double stance has lasted ds_time (PH_DOUBLE), or the hip has come over the
        # leading foot (PH_START)
        sw = 1 - st
        if phase == PH_START:
            done = s.q[st, 2] <= k[CONST.start_leg]
        else:
            done = t - mem[MEM.t_strike] > k[CONST.ds_time]
        if mem[MEM.contact + sw] == 0 or done:
            phase = PH_SINGLE
            mem[MEM.airborne] = 1 - mem[MEM.contact + sw]
    mem[MEM.phase] = phase
    mem[MEM.stance] = st
    sw = 1 - st
    th_st = s.q[st, 2]
    th_sw = s.q[sw, 2]
    if phase == PH_FLIGHT:
        mem[MEM.prog] = PR_KEEP
        mem[MEM.prog + 1] = PR_KEEP
        mem[MEM.prog + 2] = PR_KEEP
        return
    # mid-stance: the step-to-step feedback sets this step's push-off current
    if phase == PH_SINGLE and mem[MEM.mid_done] == 0 and th_st <= 0.0:
        hx, hy, vx, vy = hip_state(s, k, st)
        mem[MEM.v_mid] = vx
        ip = k[CONST.push_i0] + k[CONST.push_gain] * (k[CONST.v_target] - vx)
        mem[MEM.push_i] = min(max(ip, 0.0), k[CONST.imax])
        mem[MEM.mid_done] = 1
    if phase == PH_DOUBLE or phase == PH_START:
        mem[MEM.prog] = PR_OFF
        mem[MEM.prog + 1 + st] = PR_HOLD
        mem[MEM.prog + 1 + sw] = PR_PUSH
        return
    mem[MEM.prog] = PR_SWING
    mem[MEM.prog + 1 + st] = PR_PUSH if (mem[MEM.mid_done] == 1 and th_st < k[CONST.push_leg]) else PR_HOLD
    mem[MEM.prog + 1 + sw] = PR_LAND if th_sw - th_st > k[CONST.land_leg] else PR_FLIP


@kernel
def program_current(m, s, k, prog, gui, mem, motor, j, pr, in_air):
    """Current command [A] of motor j (0 hip, 1 + side ankle) running program pr."""
    frame = int(prog[pr, PC.frame])
    target = prog[pr, PC.target]
    kp = prog[pr, PC.kp]
    kd = prog[pr, PC.kd]
    iff = prog[pr, PC.iff]
    if frame == FR_NONE:
        return 0.0
    if pr == PR_GUI:
        target = gui[j, 0]
        kp = gui[j, 1]
        kd = gui[j, 2]
    elif pr == PR_KEEP or pr == PR_STAND:
        target = mem[MEM.keep + j]
    ang, rate = pin_angle_rate(m, s.q, s.v, j)
    if j == 0:
        if frame == FR_SCISSOR:
            st = int(mem[MEM.stance])
            sw = 1 - st
            c = k[CONST.scissor]
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
        return -mem[MEM.push_i]                # toe down at constant current
    if in_air == 1 and pr != PR_GUI and pr != PR_KEEP and pr != PR_STAND:
        return air_current(s, k, motor, foot, target - x, -dx)
    return kp * (target - x) - kd * dx


@kernel
def air_current(s, k, mp, foot, err, derr):
    """Section 6.5: model-based swing-foot control, I = tau / (G K) with
    tau = w0^2 I_f err + 2 zeta w0 I_f derr - tau_gravity (gravity's torque on the foot about
    its ankle, cancelled)."""
    i_f = k[CONST.foot_i]
    w0 = k[CONST.air_w]
    th = s.q[foot, 2]
    # foot COM relative to the ankle, world frame
    rx = math.cos(th) * k[CONST.foot_cx] - math.sin(th) * k[CONST.foot_cy]
    tau_gravity = rx * (-k[CONST.grav] * k[CONST.foot_m])
    tau = w0 * w0 * i_f * err + 2.0 * k[CONST.air_z] * w0 * i_f * derr - tau_gravity
    return tau / torque_constant(mp)


@jit_inline
def count_step_energy(m, s, ws, dt, motor, mem):
    """Add the step that led to s (of dt [s]) to the energies mem[e..e+3] [J] (electrical
    positive and net, mechanical positive and net), once (the rollout calls it after each
    step, control at each tick): each motor's current (mem[cur]) and torque (ws.act_u) held
    over the step, the torque's work the engine's power over it (ws.act_power: the torque
    times the joint's turn over dt), the electrical power at the joint's rate at the step's
    end, which symplectic Euler turns it by (into mem[pel], which the frame after the step
    records). Only the last step where several were taken since the last count
    (walkers/common/work.py once_per_step)."""
    if once_per_step(s, mem, MEM.e_at):
        for j in range(3):
            rate = pin_angle_rate(m, s.q, s.v, j)[1]
            pel = motor_power(mem[MEM.cur + j], rate, motor[j])
            mem[MEM.pel + j] = pel
            pm = ws.act_power[j]
            mem[MEM.e] += dt * max(pel, 0.0)
            mem[MEM.e + 1] += dt * pel
            mem[MEM.e + 2] += dt * max(pm, 0.0)
            mem[MEM.e + 3] += dt * pm


@jit_inline
def control(m, s, ws, tab, mem, u):
    """One control step: estimator, FSM, motor programs, motor model -> u (torques [N m]).
    Also integrates electrical and mechanical energy and records each heel strike
    (log_heel_strike: in the memory and in tab.steplog)."""
    k = tab.k
    prog = tab.prog
    motor = tab.motor
    gui = tab.gui
    steplog = tab.steplog
    count_step_energy(m, s, ws, k[CONST.dt], motor, mem)
    update_estimator(m, s, ws, k, mem)
    gait = int(mem[MEM.gait])
    steps_before = mem[MEM.steps]
    p0 = PR_OFF
    p1 = PR_HOLD
    p2 = PR_HOLD
    if gait == GAIT_WALK:
        choose_programs(m, s, k, mem)
        p0 = int(mem[MEM.prog])
        p1 = int(mem[MEM.prog + 1])
        p2 = int(mem[MEM.prog + 2])
    else:
        if mem[MEM.phase] != PH_STANDING:
            # STAND holds the feet at the absolute angles they have when it begins
            for side in range(2):
                mem[MEM.keep + 1 + side] = s.q[2 + side, 2]
        mem[MEM.phase] = PH_STANDING
        p1 = PR_STAND
        p2 = PR_STAND
        if gait == GAIT_GUI:
            p0 = PR_GUI
            p1 = PR_GUI
            p2 = PR_GUI
    mem[MEM.prog] = p0
    mem[MEM.prog + 1] = p1
    mem[MEM.prog + 2] = p2
    dt = k[CONST.dt]
    for j in range(3):
        pr = int(mem[MEM.prog + j])
        in_air = 0
        if j > 0 and mem[MEM.contact + j - 1] == 0:
            in_air = 1
        cur = program_current(m, s, k, prog, gui, mem, motor[j], j, pr, in_air)
        if in_air == 1:
            # light foot behind a heavy leg: cap the angular acceleration a torque can cause
            cap = k[CONST.foot_i] * k[CONST.air_acc] / torque_constant(motor[j])
            cur = min(max(cur, -cap), cap)
        rate = pin_angle_rate(m, s.q, s.v, j)[1]
        cur, tau, pel = drive_motor(motor[j], cur, rate)
        tau = min(max(tau, m.act_range[j, 0]), m.act_range[j, 1])
        u[j] = tau
        mem[MEM.cur + j] = cur
        mem[MEM.pel + j] = pel
    # fall and heel strike
    hx, hy, vx, vy = hip_state(s, k, 0)
    if hy - height_below(m, hx) < k[CONST.fall_h] or abs(s.q[0, 2]) > 1.2 or abs(s.q[1, 2]) > 1.2:
        mem[MEM.fell] = 1
    if mem[MEM.steps] > steps_before:
        log_heel_strike(s.time[0], hx, mem, steplog)


@kernel
def log_heel_strike(t, hip_x, mem, steplog):
    """Record the heel strike just counted, at time t [s] with the hip at x = hip_x [m]: its
    record (columns LOG: t, hip x, the energies mem[e] [J], the push-off current [A]) becomes
    memory's last strike, the second strike's also memory's first (whole steps start there),
    and from the second strike on its push-off current is summed; so the whole-step numbers
    come from the memory alone, and a snapshot of state and memory carries them. The record is
    also the strike's row of the step log while the log has room."""
    n = int(mem[MEM.steps]) - 1                    # this strike's row (0: the start-up strike)
    last = MEM.strike_last
    mem[last + LOG.t] = t
    mem[last + LOG.hip_x] = hip_x
    for e in range(4):
        mem[last + LOG.e + e] = mem[MEM.e + e]
    mem[last + LOG.push_i] = mem[MEM.push_i]
    if n >= 1:
        mem[MEM.push_sum] += mem[MEM.push_i]
    for c in range(N_LOG):
        if n == 1:
            mem[MEM.strike_first + c] = mem[last + c]
        if n < steplog.shape[0]:
            steplog[n, c] = mem[last + c]


@kernel
def height_below(m, x):
    """Terrain height [m] at x."""
    return terrain_height(m.terrain_coef, x)


# --------------------------------------------------------------------------------------------
class Controller:
    """Python-side holder of the compiled controller's tables and memory.

    ``Controller(params, dt, gravity=model's [m/s^2])``; ``set_gait("walk"|"stand"|"gui")``; ``set_gui(joint, target,
    kp, kd)`` (joint 0 hip, 1 outer ankle, 2 inner ankle; REL pin angles [rad], gains [A/rad],
    [A s/rad]); ``__call__(sim) -> u`` runs one control step on a Simulator (the Python path).
    ``reset`` refills the memory in place (a run holding it sees the new values). On the
    Python path the memory's energies count each step at the call after it (the step that
    led there): a run's last step is left out, and with a controller called every k steps,
    only those steps are counted (Run's rollout counts every step as it is taken).
    """

    GAITS = {"walk": GAIT_WALK, "stand": GAIT_STAND, "gui": GAIT_GUI}

    def __init__(self, params: RangerParams | None = None, dt: float = 1e-3, max_steps: int = 20000,
                 gravity: float = GRAVITY):
        self.params = params if params is not None else RangerParams()
        self.tables = make_tables(self.params, dt, max_steps, gravity)
        self.mem = make_memory()
        self.reset()

    def reset(self, gait: str = "walk") -> None:
        self.mem[:] = make_memory(self._gait_id(gait))
        set_standing_estimator(self.mem, self.tables.k)      # every run starts standing at rest
        p = self.params
        self.mem[MEM.push_i] = min(p.push_current + p.push_gain * p.target_speed, p.current_max)
        self.tables.steplog[:] = np.nan       # no strike logged yet (tables.make_step_log)

    def _gait_id(self, gait) -> int:
        if isinstance(gait, str):
            if gait not in self.GAITS:
                raise ValueError(f"Ranger gait {gait!r} unknown; use one of {sorted(self.GAITS)}")
            return self.GAITS[gait]
        return int(Gait(gait))

    def set_gait(self, gait) -> None:
        self.mem[MEM.gait] = self._gait_id(gait)

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
