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

from walkers.common.gaits import gait_number
from walkers.common.pd import clamp
from walkers.common.slots import size, slots
from walkers.common.work import add_positive_work, once_per_step

from .model import HIP_SIGN, N_LEG, PAIR
from .params import FIELD, QuadrupedParams
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

# controller memory mem[...] (float64 vector), the fields in this order
MEM = slots("QuadrupedMemory", (
    "gait", "speed", "step_i", "steps", "fell", "t_update", "ready_at", "x_desired", "x_prev",
    "v_est", "weight", "ik_clamps", "max_pitch", "v_ramp", "work", "plant_t",
    ("state", N_LEG, "foot state, per leg"),
    ("target", 2 * N_LEG, "puppet foot target (x, y) world, per leg: target + 2i, + 1"),
    ("goal", 2 * N_LEG, "foot goal (x, y) world, per leg: goal + 2i, + 1"),
    ("qref", 2 * N_LEG, "puppet joint angles (hip, knee) per leg: qref + 2i, + 1"),
    ("flag", N_LEG, "IK flags per leg"),
    ("work_at", "State.step the motors' work is counted to (count_work; -1: from the next tick)"),
))
N_MEMORY = size(MEM)


@kernel
def foot_centre(s, p, i):
    """World position of the centre of foot i [m] (calf body 2 + 2i, tip at calf_length)."""
    # hip -> knee along the thigh, knee -> foot along the calf
    th = s.q[2 + 2 * i, 2]
    tb = 1 + 2 * i
    l1 = p[FIELD.thigh_length]
    hx, hy = hip_world(s.q[0, 0], s.q[0, 1], s.q[0, 2], HIP_SIGN[i] * p[FIELD.hip_x])
    kx = hx + l1 * math.sin(s.q[tb, 2])
    ky = hy - l1 * math.cos(s.q[tb, 2])
    return kx + p[FIELD.calf_length] * math.sin(th), ky - p[FIELD.calf_length] * math.cos(th)


@kernel
def rest_height(m, p, x):
    """Height [m] of the centre of a round foot resting on the ground near x (r / cos(slope)
    above it), lowered by plant_depth."""
    h, dh, _ = height_derivs(m.terrain_coef, x)
    return h + p[FIELD.foot_radius] * math.sqrt(1.0 + dh * dh) - p[FIELD.plant_depth]


@kernel
def placement_x(m, s, p, mem, i, t_left):
    """Raibert foot placement for leg i: world x of the landing goal [m]."""
    hx, hy = hip_world(s.q[0, 0], s.q[0, 1], s.q[0, 2], HIP_SIGN[i] * p[FIELD.hip_x])
    v, vc = mem[MEM.v_est], mem[MEM.v_ramp]
    lead = vc * t_left + 0.5 * v * p[FIELD.stance_time] + p[FIELD.placement_gain] * (v - vc)
    return hx + clamp(lead, -p[FIELD.lead_max], p[FIELD.lead_max])


@jit
def update_feet(m, s, p, mem):
    """The post's step(): switch LIFT -> PLANT -> GROUND when the moving pair's puppet feet have
    reached their goals, start the next step when all four are down (and the plant delay has
    passed), then refresh the goals of the moving feet (placement from the body velocity)."""
    t = s.time[0]
    pair = int(mem[MEM.step_i]) % 2
    # the moving pair reached its goals: next state
    reached = True
    n_lift = 0
    n_plant = 0
    for i in range(N_LEG):
        st = mem[MEM.state + i]
        if PAIR[i] != pair or st == F_GROUND:
            continue
        n_lift += st == F_LIFT
        n_plant += st == F_PLANT
        if math.hypot(mem[MEM.goal + 2 * i] - mem[MEM.target + 2 * i],
                      mem[MEM.goal + 2 * i + 1] - mem[MEM.target + 2 * i + 1]) >= p[FIELD.goal_tol]:
            reached = False
        elif st == F_PLANT and s.contact_mode[i] == 0 and t < mem[MEM.plant_t] + p[FIELD.touch_timeout]:
            reached = False     # ours: the real foot must touch too (or time out)
    if reached and n_lift + n_plant > 0:
        for i in range(N_LEG):
            if PAIR[i] != pair or mem[MEM.state + i] == F_GROUND:
                continue
            if n_lift > 0:
                mem[MEM.state + i] = F_PLANT
                mem[MEM.plant_t] = t
            else:
                mem[MEM.state + i] = F_GROUND
                mem[MEM.ready_at] = t + p[FIELD.plant_delay]
        if n_lift == 0:
            mem[MEM.steps] += 1.0     # a pair has landed: one step
    # all four feet down: the next pair lifts
    n_ground = 0
    for i in range(N_LEG):
        n_ground += mem[MEM.state + i] == F_GROUND
    if n_ground == N_LEG and mem[MEM.gait] != G_STAND and t >= mem[MEM.ready_at]:
        mem[MEM.step_i] += 1.0
        for i in range(N_LEG):
            if PAIR[i] == int(mem[MEM.step_i]) % 2:
                mem[MEM.state + i] = F_LIFT
    # goals of the moving feet follow the body
    foot_speed = p[FIELD.foot_step] * p[FIELD.update_rate]
    for i in range(N_LEG):
        st = mem[MEM.state + i]
        if st == F_GROUND:
            continue
        tx, ty = mem[MEM.target + 2 * i], mem[MEM.target + 2 * i + 1]
        # time the puppet foot still needs to reach the ground (heights above the ground)
        up = ty - height(m.terrain_coef, tx)
        rest = rest_height(m, p, tx) - height(m.terrain_coef, tx)
        path = (p[FIELD.lift_height] - up) + (p[FIELD.lift_height] - rest) if st == F_LIFT else up - rest
        t_left = max(path, 0.0) / foot_speed
        gx = placement_x(m, s, p, mem, i, t_left)
        mem[MEM.goal + 2 * i] = gx
        mem[MEM.goal + 2 * i + 1] = (height(m.terrain_coef, gx) + p[FIELD.lift_height] if st == F_LIFT
                                   else rest_height(m, p, gx))


@kernel
def move_targets(m, s, p, mem):
    """Move each puppet foot towards its goal at foot_step * update_rate [m/s]."""
    dmax = p[FIELD.foot_step] * p[FIELD.update_rate] * m.dt
    for i in range(N_LEG):
        if mem[MEM.state + i] == F_GROUND:
            continue
        dx = mem[MEM.goal + 2 * i] - mem[MEM.target + 2 * i]
        dy = mem[MEM.goal + 2 * i + 1] - mem[MEM.target + 2 * i + 1]
        d = math.hypot(dx, dy)
        f = 1.0 if d <= dmax else dmax / d
        mem[MEM.target + 2 * i] += f * dx
        mem[MEM.target + 2 * i + 1] += f * dy


@jit
def command_speed(mem):
    """Commanded forward speed of the current gait [m/s] (0 in STAND and PIAFFE)."""
    return mem[MEM.speed] if mem[MEM.gait] == G_WALK else 0.0


@kernel
def ramp_speed(m, s, p, mem):
    """The puppet torso's speed [m/s]: 0 until settle_time, then towards the command at accel."""
    if s.time[0] >= p[FIELD.settle_time]:
        dv = p[FIELD.accel] * m.dt
        mem[MEM.v_ramp] = clamp(command_speed(mem), mem[MEM.v_ramp] - dv, mem[MEM.v_ramp] + dv)
    return mem[MEM.v_ramp]


@kernel
def stance_forces(s, p, mem, xc):
    """Vertical ground force per foot on the ground [N], front and rear end (lever rule about
    the torso COM x = xc; all of it on one end when only that end is down)."""
    xf, xr, nf, nr = 0.0, 0.0, 0, 0
    for i in range(N_LEG):
        if mem[MEM.state + i] != F_GROUND:
            continue
        x, _ = foot_centre(s, p, i)
        if HIP_SIGN[i] > 0:
            xf += x
            nf += 1
        else:
            xr += x
            nr += 1
    w = p[FIELD.weight_ff] * mem[MEM.weight]
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


@kernel
def count_work(s, ws, mem, dt):
    """Add the step that led to s (of dt [s]) to the motors' positive mechanical work mem[work]
    [J], once (walkers/common/work.py: the rollout calls it after each step, control at each
    tick). Only the last step where several were taken since the last count."""
    if once_per_step(s, mem, MEM.work_at):
        add_positive_work(ws, mem, MEM.work, dt)


@jit_inline
def control(m, s, ws, p, mem, u):
    """One control tick (p: the parameter vector, the quadruped's table): fall monitor, the 30 Hz foot update, puppet feet, puppet pose (IK),
    PD + weight feed-forward into u (n_act,) [N m]. Pin/actuator j = 2 leg + (0 hip, 1 knee)."""
    t, dt = s.time[0], m.dt
    tx, ty, th = s.q[0, 0], s.q[0, 1], s.q[0, 2]
    count_work(s, ws, mem, dt)
    # fall monitor
    if ty - height(m.terrain_coef, tx) < p[FIELD.fall_height] or abs(th) > p[FIELD.fall_pitch]:
        mem[MEM.fell] = 1.0
    mem[MEM.max_pitch] = max(mem[MEM.max_pitch], abs(th))
    # the post's step() at update_rate, with the torso speed over the last period
    if t >= mem[MEM.t_update] - 1e-9:
        period = 1.0 / p[FIELD.update_rate]
        mem[MEM.v_est] = (tx - mem[MEM.x_prev]) / period
        mem[MEM.x_prev] = tx
        mem[MEM.t_update] += period
        update_feet(m, s, p, mem)
    move_targets(m, s, p, mem)
    # the puppet's torso: x_d runs at the command, tied to the measured torso
    lead = p[FIELD.torso_track_max]
    xd = clamp(mem[MEM.x_desired] + ramp_speed(m, s, p, mem) * dt, tx - lead, tx + lead)
    mem[MEM.x_desired] = xd
    yd = height(m.terrain_coef, xd) + p[FIELD.stand_height]
    f_front, f_rear = stance_forces(s, p, mem, tx)
    l1, l2 = p[FIELD.thigh_length], p[FIELD.calf_length]
    kp, kd, lim = p[FIELD.kp], p[FIELD.kd], p[FIELD.torque_limit]
    for i in range(N_LEG):
        ground = mem[MEM.state + i] == F_GROUND
        # stance legs: posed to the desired torso; swing legs: to the measured torso
        px, py, pth = (xd, yd, 0.0) if ground else (tx, ty, th)
        q1, q2, flag = leg_angles_for(mem[MEM.target + 2 * i], mem[MEM.target + 2 * i + 1], px, py, pth,
                                      HIP_SIGN[i] * p[FIELD.hip_x], l1, l2, p[FIELD.hip_lower], p[FIELD.hip_upper],
                                      p[FIELD.knee_lower], p[FIELD.knee_upper])
        mem[MEM.qref + 2 * i] = q1
        mem[MEM.qref + 2 * i + 1] = q2
        mem[MEM.flag + i] = flag
        if flag != 0:
            mem[MEM.ik_clamps] += 1.0
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
            u[pin] = clamp(kp * (mem[MEM.qref + pin] - ang) - kd * rate + ff, -lim, lim)


def make_memory(model, params: QuadrupedParams, gait: int, speed: float) -> np.ndarray:
    """Controller memory for a run starting from the model's build pose."""
    mem = np.zeros(N_MEMORY)
    mem[MEM.work_at] = -1.0
    mem[MEM.gait] = gait
    mem[MEM.speed] = speed
    mem[MEM.weight] = 9.81 * float(np.sum(model.arrays.body_mass))
    mem[MEM.ready_at] = params.settle_time
    x0 = float(model.q0[0, 0])
    mem[MEM.x_desired] = mem[MEM.x_prev] = x0
    p = params.to_array()

    class _S:  # the build pose as a state-like object for foot_centre
        q = np.ascontiguousarray(model.q0)
    for i in range(N_LEG):
        mem[MEM.target + 2 * i], mem[MEM.target + 2 * i + 1] = foot_centre.py_func(_S, p, i)
        mem[MEM.goal + 2 * i], mem[MEM.goal + 2 * i + 1] = mem[MEM.target + 2 * i], mem[MEM.target + 2 * i + 1]
    return mem


class Controller:
    """Python path: ``u = controller(sim)`` each step (the compiled ``control`` underneath).
    The memory's motor work counts each step at the call after it (the step that led there):
    a run's last step is left out, and with a controller called every k steps, only those
    steps are counted (Run's rollout counts every step as it is taken).

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
    return gait_number(Gait, gait, "quadruped")
