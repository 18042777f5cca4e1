"""Trot controller of the planar quadruped (after the 2023 robot-dog post): a per-foot state machine
GROUND -> LIFT -> PLANT -> GROUND on diagonal pairs, a kinematic puppet posed by IK, and PD
tracking of the puppet's joint angles by the motors (compiled).

The post's step() (run at update_rate = 30 Hz):
  * the next step starts only when all four feet are GROUND (and, ours, plant_delay seconds
    after the last plant: the post's delay for hard, bouncing feet); it selects the pair
    step_i % 2 (even: FL + RR) and puts both feet in LIFT with a goal lift_height above ground;
  * puppet feet move towards their goals by at most foot_step per update (ours: spread evenly
    over the update period, so the servo targets have no jumps);
  * when both selected feet are within goal_tol of their goals: LIFT -> PLANT (goal on the
    ground), PLANT -> GROUND; ours: PLANT -> GROUND also waits until the real feet touch
    (the engine's contact mode as a foot contact sensor), at most touch_timeout after the
    plant began. Without it the puppet "planted" some 10-30 ms before the real feet landed,
    the weight feed-forward was split onto feet still in the air and the other foot of their
    end hopped.
The post's walker fell when asked to move forward while stepping. Feedback added here:
  1. foot placement from body velocity (Raibert): the swing feet's goals are recomputed at every
     update at x_hip + v_cmd t_left + v T_st / 2 + k_v (v - v_cmd), limited to +-lead_max
     around the hip; v is the torso speed measured over the last update period and t_left the
     time the puppet foot still needs to reach the ground, v_cmd the puppet torso's speed
     (ramped up from rest at accel after settle_time);
  2. torso pose correction through the stance legs: legs whose feet are on the ground are
     posed by IK from their planted foot targets to the *desired* torso pose (x_d, ground +
     stand_height, pitch 0), so their joint targets push the torso back to level and to its
     height (pitch and height feedback). x_d advances at v_cmd and stays within
     torso_track_max of the measured torso x (bounded position feedback; in place it holds
     the start position). Swing legs are posed from the *measured* torso so their feet land
     where the placement rule says.
  3. weight feed-forward: stance legs add tau = -J^T F with F the share of the weight of the
     feet on the ground (front/rear split by the lever rule about the torso COM).
No COM shift is used. What each feedback buys (python benchmarks/quadruped.py --ablation):
in the sagittal plane a diagonal pair is one front and one rear foot, so the trunk always
stands on a support interval, and the post's failure (tilt and fall when moving forward) did
not appear at 0.3 m/s even "post-like" (placement off: feet planted under the hips; torso tie
loosened to 0.5 m). It appears at 0.5 m/s (post-like fell after 4.7 s; shipped walks), and
under pushes: the largest 0.2 s push at the torso survived while walking at 0.3 m/s was
forward/backward 100/140 N shipped, 60/100 N without placement, 60/60 N post-like.
Motor command per joint:
    u = kp (q_puppet - q) - kd dq/dt + tau_ff,   |u| <= torque_limit
Gaits: STAND (no stepping), PIAFFE (trot in place: v_cmd = 0), WALK (v_cmd = speed).
"""
from __future__ import annotations

import math
from enum import IntEnum

import numpy as np

from planarsim.compiled import jit, jit_inline, kernel, pin_angle_rate, height, height_derivs

from walkers.common.pd import clamp

from .model import HIP_SIGN, N_LEG, PAIR
from .params import (I_ACCEL, I_CALF_LENGTH, I_FALL_HEIGHT, I_FALL_PITCH, I_FOOT_RADIUS, I_FOOT_STEP,
                     I_GOAL_TOL, I_HIP_LOWER, I_HIP_UPPER, I_HIP_X, I_KD, I_KNEE_LOWER,
                     I_KNEE_UPPER, I_KP, I_LEAD_MAX, I_LIFT_HEIGHT, I_PLACEMENT_GAIN,
                     I_PLANT_DELAY, I_PLANT_DEPTH, I_SETTLE_TIME, I_STAND_HEIGHT, I_STANCE_TIME,
                     I_THIGH_LENGTH, I_TORQUE_LIMIT, I_TOUCH_TIMEOUT, I_TORSO_TRACK_MAX, I_UPDATE_RATE,
                     I_WEIGHT_FF, QuadrupedParams)
from .puppet import hip_world, leg_angles_for


class Gait(IntEnum):
    STAND = 0
    PIAFFE = 1
    WALK = 2


class FootState(IntEnum):
    GROUND = 0
    LIFT = 1
    PLANT = 2


G_STAND, G_PIAFFE, G_WALK = 0, 1, 2
F_GROUND, F_LIFT, F_PLANT = 0, 1, 2

# memory layout mem[...]
M_GAIT, M_SPEED, M_STEP_I, M_STEPS, M_FELL = 0, 1, 2, 3, 4
M_T_UPDATE, M_READY_AT, M_X_DESIRED, M_X_PREV, M_V_EST = 5, 6, 7, 8, 9
M_WEIGHT, M_IK_CLAMPS, M_MAX_PITCH, M_V_RAMP, M_WORK, M_PLANT_T = 10, 11, 12, 13, 14, 15
M_STATE = 16      # foot state, per leg 16..19
M_TARGET = 20     # puppet foot target (x, y) world, per leg: 20 + 2i, 21 + 2i
M_GOAL = 28       # foot goal (x, y) world, per leg: 28 + 2i, 29 + 2i
M_QREF = 36       # puppet joint angles (hip, knee) per leg: 36 + 2i, 37 + 2i
M_FLAG = 44       # IK flags per leg 44..47
N_MEMORY = 48


@kernel
def foot_centre(s, p, i):
    """World position of the centre of foot i [m] (calf body 2 + 2i, tip at calf_length)."""
    # hip -> knee along the thigh, knee -> foot along the calf
    th = s.q[2 + 2 * i, 2]
    tb = 1 + 2 * i
    l1 = p[I_THIGH_LENGTH]
    hx, hy = hip_world(s.q[0, 0], s.q[0, 1], s.q[0, 2], HIP_SIGN[i] * p[I_HIP_X])
    kx = hx + l1 * math.sin(s.q[tb, 2])
    ky = hy - l1 * math.cos(s.q[tb, 2])
    return kx + p[I_CALF_LENGTH] * math.sin(th), ky - p[I_CALF_LENGTH] * math.cos(th)


@kernel
def rest_height(m, p, x):
    """Height [m] of the centre of a round foot resting on the ground near x (r / cos(slope)
    above it), lowered by plant_depth."""
    h, dh, _ = height_derivs(m.terrain_coef, x)
    return h + p[I_FOOT_RADIUS] * math.sqrt(1.0 + dh * dh) - p[I_PLANT_DEPTH]


@kernel
def placement_x(m, s, p, mem, i, t_left):
    """Raibert foot placement for leg i: world x of the landing goal [m]."""
    hx, hy = hip_world(s.q[0, 0], s.q[0, 1], s.q[0, 2], HIP_SIGN[i] * p[I_HIP_X])
    v, vc = mem[M_V_EST], mem[M_V_RAMP]
    lead = vc * t_left + 0.5 * v * p[I_STANCE_TIME] + p[I_PLACEMENT_GAIN] * (v - vc)
    return hx + clamp(lead, -p[I_LEAD_MAX], p[I_LEAD_MAX])


@jit
def update_feet(m, s, p, mem):
    """The post's step(): switch LIFT -> PLANT -> GROUND when the moving pair's puppet feet have
    reached their goals, start the next step when all four are down (and the plant delay has
    passed), then refresh the goals of the moving feet (placement from the body velocity)."""
    t = s.time[0]
    pair = int(mem[M_STEP_I]) % 2
    # the moving pair reached its goals: next state
    reached = True
    n_lift = 0
    n_plant = 0
    for i in range(N_LEG):
        st = mem[M_STATE + i]
        if PAIR[i] != pair or st == F_GROUND:
            continue
        n_lift += st == F_LIFT
        n_plant += st == F_PLANT
        if math.hypot(mem[M_GOAL + 2 * i] - mem[M_TARGET + 2 * i],
                      mem[M_GOAL + 2 * i + 1] - mem[M_TARGET + 2 * i + 1]) >= p[I_GOAL_TOL]:
            reached = False
        elif st == F_PLANT and s.contact_mode[i] == 0 and t < mem[M_PLANT_T] + p[I_TOUCH_TIMEOUT]:
            reached = False     # ours: the real foot must touch too (or time out)
    if reached and n_lift + n_plant > 0:
        for i in range(N_LEG):
            if PAIR[i] != pair or mem[M_STATE + i] == F_GROUND:
                continue
            if n_lift > 0:
                mem[M_STATE + i] = F_PLANT
                mem[M_PLANT_T] = t
            else:
                mem[M_STATE + i] = F_GROUND
                mem[M_READY_AT] = t + p[I_PLANT_DELAY]
        if n_lift == 0:
            mem[M_STEPS] += 1.0     # a pair has landed: one step
    # all four feet down: the next pair lifts
    n_ground = 0
    for i in range(N_LEG):
        n_ground += mem[M_STATE + i] == F_GROUND
    if n_ground == N_LEG and mem[M_GAIT] != G_STAND and t >= mem[M_READY_AT]:
        mem[M_STEP_I] += 1.0
        for i in range(N_LEG):
            if PAIR[i] == int(mem[M_STEP_I]) % 2:
                mem[M_STATE + i] = F_LIFT
    # goals of the moving feet follow the body
    foot_speed = p[I_FOOT_STEP] * p[I_UPDATE_RATE]
    for i in range(N_LEG):
        st = mem[M_STATE + i]
        if st == F_GROUND:
            continue
        tx, ty = mem[M_TARGET + 2 * i], mem[M_TARGET + 2 * i + 1]
        # time the puppet foot still needs to reach the ground (heights above the ground)
        up = ty - height(m.terrain_coef, tx)
        rest = rest_height(m, p, tx) - height(m.terrain_coef, tx)
        path = (p[I_LIFT_HEIGHT] - up) + (p[I_LIFT_HEIGHT] - rest) if st == F_LIFT else up - rest
        t_left = max(path, 0.0) / foot_speed
        gx = placement_x(m, s, p, mem, i, t_left)
        mem[M_GOAL + 2 * i] = gx
        mem[M_GOAL + 2 * i + 1] = (height(m.terrain_coef, gx) + p[I_LIFT_HEIGHT] if st == F_LIFT
                                   else rest_height(m, p, gx))


@kernel
def move_targets(m, s, p, mem):
    """Move each puppet foot towards its goal at foot_step * update_rate [m/s]."""
    dmax = p[I_FOOT_STEP] * p[I_UPDATE_RATE] * m.dt
    for i in range(N_LEG):
        if mem[M_STATE + i] == F_GROUND:
            continue
        dx = mem[M_GOAL + 2 * i] - mem[M_TARGET + 2 * i]
        dy = mem[M_GOAL + 2 * i + 1] - mem[M_TARGET + 2 * i + 1]
        d = math.hypot(dx, dy)
        f = 1.0 if d <= dmax else dmax / d
        mem[M_TARGET + 2 * i] += f * dx
        mem[M_TARGET + 2 * i + 1] += f * dy


@jit
def command_speed(mem):
    """Commanded forward speed of the current gait [m/s] (0 in STAND and PIAFFE)."""
    return mem[M_SPEED] if mem[M_GAIT] == G_WALK else 0.0


@kernel
def ramp_speed(m, s, p, mem):
    """The puppet torso's speed [m/s]: 0 until settle_time, then towards the command at accel."""
    if s.time[0] >= p[I_SETTLE_TIME]:
        dv = p[I_ACCEL] * m.dt
        mem[M_V_RAMP] = clamp(command_speed(mem), mem[M_V_RAMP] - dv, mem[M_V_RAMP] + dv)
    return mem[M_V_RAMP]


@kernel
def stance_forces(s, p, mem, xc):
    """Vertical ground force per foot on the ground [N], front and rear end (lever rule about
    the torso COM x = xc; all of it on one end when only that end is down)."""
    xf, xr, nf, nr = 0.0, 0.0, 0, 0
    for i in range(N_LEG):
        if mem[M_STATE + i] != F_GROUND:
            continue
        x, _ = foot_centre(s, p, i)
        if HIP_SIGN[i] > 0:
            xf += x
            nf += 1
        else:
            xr += x
            nr += 1
    w = p[I_WEIGHT_FF] * mem[M_WEIGHT]
    if nf == 0 and nr == 0:
        return 0.0, 0.0
    if nr == 0:
        return w / nf, 0.0
    if nf == 0:
        return 0.0, w / nr
    xf /= nf
    xr /= nr
    front = w * clamp((xc - xr) / max(xf - xr, 1e-3), 0.0, 1.0)
    return front / nf, (w - front) / nr


@jit_inline
def control(m, s, ws, p, mem, u):
    """One control tick (p: the parameter vector, the quadruped's table): fall monitor, the 30 Hz foot update, puppet feet, puppet pose (IK),
    PD + weight feed-forward into u (n_act,) [N m]. Pin/actuator j = 2 leg + (0 hip, 1 knee)."""
    t, dt = s.time[0], m.dt
    tx, ty, th = s.q[0, 0], s.q[0, 1], s.q[0, 2]
    # fall monitor
    if ty - height(m.terrain_coef, tx) < p[I_FALL_HEIGHT] or abs(th) > p[I_FALL_PITCH]:
        mem[M_FELL] = 1.0
    mem[M_MAX_PITCH] = max(mem[M_MAX_PITCH], abs(th))
    # the post's step() at update_rate, with the torso speed over the last period
    if t >= mem[M_T_UPDATE] - 1e-9:
        period = 1.0 / p[I_UPDATE_RATE]
        mem[M_V_EST] = (tx - mem[M_X_PREV]) / period
        mem[M_X_PREV] = tx
        mem[M_T_UPDATE] += period
        update_feet(m, s, p, mem)
    move_targets(m, s, p, mem)
    # the puppet's torso: x_d runs at the command, tied to the measured torso
    lead = p[I_TORSO_TRACK_MAX]
    xd = clamp(mem[M_X_DESIRED] + ramp_speed(m, s, p, mem) * dt, tx - lead, tx + lead)
    mem[M_X_DESIRED] = xd
    yd = height(m.terrain_coef, xd) + p[I_STAND_HEIGHT]
    f_front, f_rear = stance_forces(s, p, mem, tx)
    l1, l2 = p[I_THIGH_LENGTH], p[I_CALF_LENGTH]
    kp, kd, lim = p[I_KP], p[I_KD], p[I_TORQUE_LIMIT]
    for i in range(N_LEG):
        ground = mem[M_STATE + i] == F_GROUND
        # stance legs: posed to the desired torso; swing legs: to the measured torso
        px, py, pth = (xd, yd, 0.0) if ground else (tx, ty, th)
        q1, q2, flag = leg_angles_for(mem[M_TARGET + 2 * i], mem[M_TARGET + 2 * i + 1], px, py, pth,
                                      HIP_SIGN[i] * p[I_HIP_X], l1, l2, p[I_HIP_LOWER], p[I_HIP_UPPER],
                                      p[I_KNEE_LOWER], p[I_KNEE_UPPER])
        mem[M_QREF + 2 * i] = q1
        mem[M_QREF + 2 * i + 1] = q2
        mem[M_FLAG + i] = flag
        if flag != 0:
            mem[M_IK_CLAMPS] += 1.0
        # weight feed-forward tau = -J^T (0, F) of a foot on the ground
        fy = 0.0
        if ground:
            fy = f_front if HIP_SIGN[i] > 0 else f_rear
        s1 = math.sin(s.q[1 + 2 * i, 2])
        s12 = math.sin(s.q[2 + 2 * i, 2])
        ff_hip = -(l1 * s1 + l2 * s12) * fy
        ff_knee = -l2 * s12 * fy
        for j in range(2):
            pin = 2 * i + j
            ang, rate = pin_angle_rate(m, s.q, s.v, pin)
            ff = ff_hip if j == 0 else ff_knee
            u[pin] = clamp(kp * (mem[M_QREF + pin] - ang) - kd * rate + ff, -lim, lim)
            # positive mechanical work of the motors [J] (power at the start of the step)
            mem[M_WORK] += max(u[pin] * rate, 0.0) * dt


def make_memory(model, params: QuadrupedParams, gait: int, speed: float) -> np.ndarray:
    """Controller memory for a run starting from the model's build pose."""
    mem = np.zeros(N_MEMORY)
    mem[M_GAIT] = gait
    mem[M_SPEED] = speed
    mem[M_WEIGHT] = 9.81 * float(np.sum(model.arrays.body_mass))
    mem[M_READY_AT] = params.settle_time
    x0 = float(model.q0[0, 0])
    mem[M_X_DESIRED] = mem[M_X_PREV] = x0
    p = params.to_array()

    class _S:  # the build pose as a state-like object for foot_centre
        q = np.ascontiguousarray(model.q0)
    for i in range(N_LEG):
        mem[M_TARGET + 2 * i], mem[M_TARGET + 2 * i + 1] = foot_centre.py_func(_S, p, i)
        mem[M_GOAL + 2 * i], mem[M_GOAL + 2 * i + 1] = mem[M_TARGET + 2 * i], mem[M_TARGET + 2 * i + 1]
    return mem


class Controller:
    """Python path: ``u = controller(sim)`` each step (the compiled ``control`` underneath).

    >>> c = Controller(model, QuadrupedParams(), gait="piaffe")     # doctest: +SKIP
    >>> traj = sim.run(5.0, controller=c)
    """

    def __init__(self, model, params: QuadrupedParams | None = None, gait="walk", speed=None):
        self.model = model
        self.params = params if params is not None else QuadrupedParams()
        self.p = self.params.to_array()
        self.u = np.zeros(model.n_act)
        self.reset(gait, speed)

    def reset(self, gait="walk", speed=None):
        self.memory = make_memory(self.model, self.params, gait_id(gait),
                                  self.params.speed if speed is None else float(speed))

    def __call__(self, sim):
        control(self.model.arrays, sim.state, sim.ws, self.p, self.memory, self.u)
        return self.u


def gait_id(gait) -> int:
    """Gait number from a name ('stand', 'piaffe', 'walk') or a Gait."""
    if isinstance(gait, str):
        try:
            return int(Gait[gait.upper()])
        except KeyError:
            raise ValueError(f"unknown quadruped gait {gait!r}; use one of "
                             f"{[g.name.lower() for g in Gait]}") from None
    return int(Gait(gait))
