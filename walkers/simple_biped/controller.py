"""The Simple Biped's hierarchical state machine (Kelly 2014, section 4), compiled.

Top level: the gait STAND / WALK / JUMP, requested through ``memory[M_GAIT]`` (settable from
Python between rollout chunks). Each gait runs its own states:

  STAND        double stance, PD on the hip position (above the middle of the feet)
  WALK_DOUBLE  eq. 1: PD on the front (stance) leg length; eqs. 2-3: tangential force driving
               the front leg rate to that of a pendulum with top speed v_top; the desired hip
               force is split into the two axial leg forces (hip motor off)
  WALK_SINGLE  phase s = (x_com - x_liftoff) / (x_strike - x_liftoff); the swing foot tracks a
               4-point rectangle Bezier (top edge 4/3 clearance) through a virtual leg; the
               stance leg holds its length; gravity compensation everywhere
  CROUCH, THRUST, FLIGHT, LAND   the jump: crouch, push the hip up, hold the legs in the air,
               absorb the landing; then crouch again while the gait is JUMP
Transitions are contact and phase driven (next_state). What a state commands is data: its row
of the state table (make_tables: control law, target, PD gains, feed-forward), so STAND, LAND,
CROUCH and THRUST are one law with different rows. Left/right is data too: ``memory[M_STANCE]``
is the stance (front) foot index, the swing foot is ``1 - stance``.

Deviations from and additions to Kelly's controller, stated:
- eq. 2 is used in its energy-consistent form phi_dot_target = -sqrt(v_top^2 + 2 g l
  (1 - cos phi)) / l (the pendulum passes the top at v_top); v_top is adapted once per step by
  an integral law so that the mean speed over whole steps meets the target speed;
- the double-stance force split keeps eq. 1's normal force first and saturates eq. 3's
  tangential force so that the legs only push (legs/push_hip_pendulum); double stance ends when
  the pendulum energy reaches its target (the legs cannot brake it), the rear leg is at its
  longest, or the hip has passed over the front foot;
- the expected strike height continues the slope seen between the feet (slope_trust = 0 gives
  Kelly's level-ground guess);
- the swing hip torque is saturated so that its reaction does not push the stance foot out of
  a friction cone (legs/limit_hip_torque);
- a step whose hip rolls back before passing the stance foot is abandoned: the swing foot
  goes back down and double stance pushes again (counted as a retry);
- before STAND the walker slows down (top speed stop_speed) and stops in double stance.
"""
import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from planarsim.compiled import jit_inline, kernel, shape_contact_mode

from walkers.common.bezier import rectangle_bezier
from walkers.common.pd import clamp
from . import params as P
from .legs import hold_stance, leg_state, limit_hip_torque, push_hip, push_hip_pendulum, track_foot


class Gait(IntEnum):
    STAND = 0
    WALK = 1
    JUMP = 2


class State(IntEnum):
    STAND = 0
    WALK_DOUBLE = 1
    WALK_SINGLE = 2
    CROUCH = 3
    THRUST = 4
    FLIGHT = 5
    LAND = 6


GAIT_STAND, GAIT_WALK, GAIT_JUMP = 0, 1, 2
ST_STAND, ST_DOUBLE, ST_SINGLE, ST_CROUCH, ST_THRUST, ST_FLIGHT, ST_LAND = 0, 1, 2, 3, 4, 5, 6

# controller memory layout (float64 vector)
M_GAIT = 0        # requested gait
M_STATE = 1       # current state
M_STANCE = 2      # stance (front) foot index
M_T_ENTER = 3     # time the state was entered [s]
M_SPEED = 4       # target speed [m/s] (starts at params.speed; settable at run time)
M_V_TOP = 5       # pendulum top speed of eq. 2, adapted per step [m/s]
M_LIFT_X = 6      # COM x at lift-off [m]
M_STRIKE_X = 7    # expected COM x at the strike [m]
M_SW_X0 = 8       # swing Bezier: start point, end point, top height [m]
M_SW_Y0 = 9
M_SW_X1 = 10
M_SW_Y1 = 11
M_SW_TOP = 12
M_STEPS = 13      # touchdowns in WALK
M_STEP_T = 14     # time and hip x of the last touchdown
M_STEP_X = 15
M_JUMPS = 16      # landings after a flight with both feet off the ground
M_AIRBORNE = 17   # 1 once both feet left the ground in this flight
M_PHASE = 18      # last phase variable (single stance)
M_FALLEN = 19     # set by the rollout's fall monitor
M_SCUFFS = 20     # swing-foot contacts before touchdown_phase
M_SW_AIR = 21     # 1 once the swing foot has left the ground in this single stance
M_ABORT = 22      # 1 when the hip rolled back before the top: the swing foot returns behind
M_RETRIES = 23    # aborted steps
M_WORK = 24       # positive mechanical work of all actuators [J] (kept by the rollout)
N_MEMORY = 28

# control laws, chosen per state by the state table
LAW_HIP = 0       # PD on the hip over the middle of the feet, both legs pushing (push_hip)
LAW_FLIGHT = 1    # both feet held below the hip at a leg length, spread as when standing
LAW_DOUBLE = 2    # walking double stance: eqs. 1-3 on the front leg, split into both legs
LAW_SINGLE = 3    # walking single stance: stance leg holds its length, swing foot tracks the Bezier

# columns of the state table Tables.row[state]
R_LAW = 0         # control law (LAW_*)
R_LENGTH = 1      # target [m]: hip height above the mid-feet (LAW_HIP) or leg length (the others)
R_KP = 2          # gain on that target [1/s^2] (LAW_HIP: hip x; LAW_DOUBLE, LAW_SINGLE: stance leg)
R_KD = 3          # its rate gain [1/s]
R_KP_Y = 4        # LAW_HIP: hip height gain [1/s^2]
R_KD_Y = 5        # LAW_HIP: hip vertical rate gain [1/s]
R_ACCEL_Y = 6     # LAW_HIP: vertical hip acceleration added [m/s^2]
R_SWING_KP = 7    # swing / flight foot gains (virtual leg) [1/s^2]
R_SWING_KD = 8    # [1/s]
N_ROW = 9


class Tables(NamedTuple):
    """What the compiled controller reads: the parameter vector and one row per state."""
    p: np.ndarray      # (N_PARAMS,) SimpleBipedParams.to_array(), indices params.I_<FIELD>
    row: np.ndarray    # (len(State), N_ROW) control data per state, columns R_*


def make_tables(params) -> Tables:
    """Params -> Tables. Per state: STAND and LAND hold the hip at stand_height, CROUCH at
    crouch_height (stand gains); THRUST keeps the hip over the feet and accelerates it up at
    thrust_accel; FLIGHT holds flight_length legs; WALK_DOUBLE / WALK_SINGLE hold walk_length
    on the stance leg with the ds / ss gains."""
    p = params.to_array()
    l0 = p[P.I_LEG_LENGTH]
    kp, kd = p[P.I_STAND_KP], p[P.I_STAND_KD]
    swing = (p[P.I_SWING_KP], p[P.I_SWING_KD])
    row = np.zeros((len(State), N_ROW))
    # columns: law, length, kp, kd, kp_y, kd_y, accel_y, swing kp, swing kd
    row[ST_STAND] = (LAW_HIP, p[P.I_STAND_HEIGHT] * l0, kp, kd, kp, kd, 0.0, 0.0, 0.0)
    row[ST_LAND] = row[ST_STAND]
    row[ST_CROUCH] = (LAW_HIP, p[P.I_CROUCH_HEIGHT] * l0, kp, kd, kp, kd, 0.0, 0.0, 0.0)
    row[ST_THRUST] = (LAW_HIP, 0.0, kp, kd, 0.0, 0.0, p[P.I_THRUST_ACCEL], 0.0, 0.0)
    row[ST_FLIGHT] = (LAW_FLIGHT, p[P.I_FLIGHT_LENGTH] * l0, 0.0, 0.0, 0.0, 0.0, 0.0, *swing)
    row[ST_DOUBLE] = (LAW_DOUBLE, p[P.I_WALK_LENGTH] * l0, p[P.I_DS_KP], p[P.I_DS_KD], 0.0, 0.0, 0.0, 0.0, 0.0)
    row[ST_SINGLE] = (LAW_SINGLE, p[P.I_WALK_LENGTH] * l0, p[P.I_SS_KP], p[P.I_SS_KD], 0.0, 0.0, 0.0, *swing)
    return Tables(p=p, row=row)


@kernel
def _enter(mem, state, t):
    mem[M_STATE] = state
    mem[M_T_ENTER] = t


@kernel
def _com_x(p, q, v):
    """COM x [m] and x velocity [m/s]."""
    mh = p[P.I_HIP_MASS]
    mf = p[P.I_FOOT_MASS]
    mt = mh + 2.0 * mf
    return ((mh * q[0, 0] + mf * (q[1, 0] + q[2, 0])) / mt,
            (mh * v[0, 0] + mf * (v[1, 0] + v[2, 0])) / mt)


@kernel
def _start_swing(p, q, v, mem, stance):
    """Lift-off: the swing Bezier from the swing foot to one step ahead of the stance foot."""
    l0 = p[P.I_LEG_LENGTH]
    sw = 1 - stance
    L = (p[P.I_STEP_LENGTH0] + p[P.I_STEP_LENGTH_PER_SPEED] * mem[M_SPEED]) * l0
    xs = q[stance + 1, 0]
    ys = q[stance + 1, 1]
    dx = xs - q[sw + 1, 0]
    slope = 0.0
    if abs(dx) > 0.05 * l0:
        slope = clamp((ys - q[sw + 1, 1]) / dx, -0.5, 0.5)
    y_ground = ys + p[P.I_SLOPE_TRUST] * slope * L
    mem[M_STANCE] = stance
    mem[M_SW_X0] = q[sw + 1, 0]
    mem[M_SW_Y0] = q[sw + 1, 1]
    mem[M_SW_X1] = xs + L
    mem[M_SW_Y1] = y_ground - p[P.I_STRIKE_PUSH] * l0
    mem[M_SW_TOP] = max(q[sw + 1, 1], y_ground) + 4.0 / 3.0 * p[P.I_CLEARANCE] * l0
    mem[M_LIFT_X] = _com_x(p, q, v)[0]
    mem[M_STRIKE_X] = xs + 0.5 * L


@kernel
def _phase(p, q, v, mem):
    """Phase variable s [-] and its rate [1/s] (linear in the COM x)."""
    x, vx = _com_x(p, q, v)
    span = max(mem[M_STRIKE_X] - mem[M_LIFT_X], 0.05 * p[P.I_LEG_LENGTH])
    return (x - mem[M_LIFT_X]) / span, vx / span


@kernel
def _v_top(p, mem):
    """Pendulum top speed [m/s] aimed at: the adapted v_top, or stop_speed when a gait other
    than WALK waits for the walker to slow down."""
    if int(mem[M_GAIT]) != GAIT_WALK:
        return min(mem[M_V_TOP], p[P.I_STOP_SPEED])
    return mem[M_V_TOP]


@kernel
def _rate_target(v_top, l, phi, g):
    """Eq. 2 (energy form): leg rate [rad/s] of a pendulum of length l that passes the top at v_top."""
    return -math.sqrt(v_top * v_top + 2.0 * g * l * (1.0 - math.cos(phi))) / l


@kernel
def foot_contact(m, s, foot):
    """The most holding mode of foot `foot`'s contacts (0 free, 1 pinned, 2 sliding; pinned
    first): its ground contact (contact `foot`) and the shape contacts of its body (steps,
    obstacles a scene adds)."""
    own = s.contact_mode[foot] if s.contact_enabled[foot] != 0 else 0
    shapes = shape_contact_mode(m, s, foot + 1)
    if own == 1 or shapes == 1:
        return 1
    return max(own, shapes)


@kernel
def next_state(p, s, mem, g, c0, c1):
    """Transitions of the state machine (writes mem); g is the gravity magnitude [m/s^2]; c0,
    c1: the feet touch something (foot_contact)."""
    q = s.q
    v = s.v
    t = s.time[0]
    state = int(mem[M_STATE])
    gait = int(mem[M_GAIT])
    t_in = t - mem[M_T_ENTER]
    if state == ST_STAND:
        if gait == GAIT_WALK and c0 and c1:
            mem[M_STANCE] = 0 if q[1, 0] > q[2, 0] else 1
            mem[M_STEP_T] = t
            mem[M_STEP_X] = q[0, 0]
            mem[M_V_TOP] = 0.8 * mem[M_SPEED]
            _enter(mem, ST_DOUBLE, t)
        elif gait == GAIT_JUMP and c0 and c1 and t_in > 0.3 and abs(v[0, 0]) + abs(v[0, 1]) < 0.2:
            _enter(mem, ST_CROUCH, t)
    elif state == ST_DOUBLE:
        if gait != GAIT_WALK and abs(v[0, 0]) < p[P.I_STOP_SPEED] + 0.1:
            _enter(mem, ST_STAND, t)
            return
        front = int(mem[M_STANCE])
        dx, dy, l, ldot, phi, phidot = leg_state(q, v, front)
        rear_l = leg_state(q, v, 1 - front)[2]
        # top speed squared the front-leg pendulum will have: (l phi_dot)^2 - 2 g l (1 - cos phi)
        v_top2 = (l * phidot) ** 2 - 2.0 * g * l * (1.0 - math.cos(phi))
        # the legs cannot brake the pendulum (the rear leg only pushes): leave as soon as the
        # energy is within tolerance of the target or above it
        err = _v_top(p, mem) ** 2 - v_top2
        # also leave once the hip is over the front foot and still moving on (not a stall)
        over = phi <= 0.0 and v[0, 0] > p[P.I_STOP_SPEED]
        if t_in >= p[P.I_DS_TIME_MIN] and (err < p[P.I_DS_ENERGY_TOL] or over
                                            or rear_l >= p[P.I_LEG_LENGTH_MAX] * p[P.I_LEG_LENGTH]
                                            or t_in >= p[P.I_DS_TIME_MAX]):
            _start_swing(p, q, v, mem, front)
            mem[M_SW_AIR] = 0.0
            mem[M_ABORT] = 0.0
            _enter(mem, ST_SINGLE, t)
    elif state == ST_SINGLE:
        sw = 1 - int(mem[M_STANCE])
        stance = 1 - sw
        if mem[M_ABORT] == 0.0 and q[0, 0] < q[stance + 1, 0] and _com_x(p, q, v)[1] < 0.0:
            mem[M_ABORT] = 1.0
        sw_contact = c1 if sw == 1 else c0
        if mem[M_ABORT] > 0.0 and sw_contact and (mem[M_SW_AIR] > 0.0 or t_in > 0.05):
            # the step was abandoned and the foot is back down: push again from the same leg
            mem[M_RETRIES] += 1
            _enter(mem, ST_DOUBLE, t)
            return
        if not sw_contact:
            mem[M_SW_AIR] = 1.0
        elif mem[M_SW_AIR] > 0.0 and mem[M_ABORT] == 0.0:
            ph = _phase(p, q, v, mem)[0]
            if ph < p[P.I_TOUCHDOWN_PHASE]:
                mem[M_SCUFFS] += 1
                mem[M_SW_AIR] = 0.0
                return
            # touchdown: the swing foot becomes the front leg; adapt v_top to the step's speed
            mem[M_STEPS] += 1
            if mem[M_STEPS] >= 3 and t > mem[M_STEP_T]:
                v_step = (q[0, 0] - mem[M_STEP_X]) / (t - mem[M_STEP_T])
                if int(mem[M_GAIT]) == GAIT_WALK:
                    mem[M_V_TOP] = clamp(mem[M_V_TOP] + p[P.I_SPEED_GAIN] * (mem[M_SPEED] - v_step),
                                         0.05, 1.5 * mem[M_SPEED] + 0.3)
            mem[M_STEP_T] = t
            mem[M_STEP_X] = q[0, 0]
            mem[M_STANCE] = sw
            _enter(mem, ST_DOUBLE, t)
    elif state == ST_CROUCH:
        if gait != GAIT_JUMP:
            _enter(mem, ST_STAND, t)
        elif t_in >= p[P.I_CROUCH_TIME]:
            _enter(mem, ST_THRUST, t)
    elif state == ST_THRUST:
        h = q[0, 1] - 0.5 * (q[1, 1] + q[2, 1])
        if h >= p[P.I_TAKEOFF_HEIGHT] * p[P.I_LEG_LENGTH] or t_in > 0.5:
            mem[M_AIRBORNE] = 0.0
            _enter(mem, ST_FLIGHT, t)
    elif state == ST_FLIGHT:
        if not c0 and not c1:
            mem[M_AIRBORNE] = 1.0
        elif t_in > 0.05:
            if mem[M_AIRBORNE] > 0.0:
                mem[M_JUMPS] += 1
            _enter(mem, ST_LAND, t)
    elif state == ST_LAND:
        if t_in >= p[P.I_LAND_TIME]:
            _enter(mem, ST_CROUCH if gait == GAIT_JUMP else ST_STAND, t)


@kernel
def _hold_hip(p, r, q, v, gx, gy, u):
    """Hip PD toward (mid-feet x, mid-feet y + r[R_LENGTH]) plus r[R_ACCEL_Y] upward, both legs
    pushing (state row r)."""
    mh = p[P.I_HIP_MASS]
    tx = 0.5 * (q[1, 0] + q[2, 0])
    ty = 0.5 * (q[1, 1] + q[2, 1]) + r[R_LENGTH]
    ax = r[R_KP] * (tx - q[0, 0]) - r[R_KD] * v[0, 0]
    ay = r[R_KP_Y] * (ty - q[0, 1]) - r[R_KD_Y] * v[0, 1] + r[R_ACCEL_Y]
    push_hip(q, mh * (ax - gx), mh * (ay - gy), p[P.I_LEG_FORCE_MAX], u)


@kernel
def _flight(p, r, q, v, u):
    """Legs at r[R_LENGTH], feet spread as when standing, in the hip frame (free fall); the hip
    torque is the mean of the two feet's."""
    l0 = p[P.I_LEG_LENGTH]
    half = 0.5 * p[P.I_STAND_WIDTH] * l0
    sign = 1.0 if q[2, 0] >= q[1, 0] else -1.0
    u_hip0 = 0.0
    for f in range(2):
        side = -sign if f == 0 else sign
        track_foot(q, v, f, q[0, 0] + side * half, q[0, 1] - r[R_LENGTH], v[0, 0], v[0, 1],
                   r[R_SWING_KP], r[R_SWING_KD], p[P.I_FOOT_MASS], 0.0, 0.0,
                   p[P.I_LEG_LENGTH_MAX] * l0, p[P.I_LEG_FORCE_MAX], p[P.I_HIP_TORQUE_MAX], u)
        if f == 0:
            u_hip0 = u[2]
    u[2] = 0.5 * (u[2] + u_hip0)


@kernel
def _double_stance(p, r, s, mem, gx, gy, g, front_mode, u):
    """Eq. 1 normal force on the front leg toward r[R_LENGTH], eqs. 2-3 tangential force, split
    into the two legs."""
    q = s.q
    v = s.v
    mh = p[P.I_HIP_MASS]
    front = int(mem[M_STANCE])
    dx, dy, l, ldot, phi, phidot = leg_state(q, v, front)
    nx = -dx / l
    ny = -dy / l
    a_n = r[R_KP] * (r[R_LENGTH] - l) - r[R_KD] * ldot - l * phidot * phidot
    a_t = p[P.I_ENERGY_GAIN] * l * (_rate_target(_v_top(p, mem), l, phi, g) - phidot)
    a_t = clamp(a_t, -p[P.I_DS_ACCEL_MAX] * g, p[P.I_DS_ACCEL_MAX] * g)
    # tangent t = (-ny, nx): the hip's direction of motion for increasing phi; weight
    # compensation -mh g split into its n and t parts
    f_n = mh * (a_n - (gx * nx + gy * ny))
    f_t = mh * (a_t - (-gx * ny + gy * nx))
    if front_mode != 1 and f_t < 0.0:
        f_t = 0.0  # front foot not stuck (sliding or free): no forward push onto it
    push_hip_pendulum(q, front, f_n, f_t, p[P.I_DS_FRONT_LOAD] * mh * g,
                      min(p[P.I_LEG_FORCE_MAX], p[P.I_DS_FORCE_MAX] * (mh + 2.0 * p[P.I_FOOT_MASS]) * g), u)


@kernel
def _single_stance(p, r, q, v, mem, gx, gy, g, u):
    """The stance leg holds r[R_LENGTH]; the swing foot tracks the swing Bezier at the phase."""
    l0 = p[P.I_LEG_LENGTH]
    mh = p[P.I_HIP_MASS]
    mf = p[P.I_FOOT_MASS]
    stance = int(mem[M_STANCE])
    sw = 1 - stance
    ph, ph_dot = _phase(p, q, v, mem)
    mem[M_PHASE] = ph
    sb = clamp(ph, 0.0, 1.0)
    tx, ty, dtx, dty = rectangle_bezier(mem[M_SW_X0], mem[M_SW_Y0], mem[M_SW_X1], mem[M_SW_Y1],
                                        mem[M_SW_TOP], sb)
    tvx = dtx * ph_dot
    tvy = dty * ph_dot
    if ph >= 1.0:
        # past the expected strike: keep lowering the foot until it finds the ground
        tvx = 0.0
        ty -= p[P.I_DESCENT_RATE] * l0 * (ph - 1.0)
        tvy = -p[P.I_DESCENT_RATE] * l0 * ph_dot
    elif ph < 0.0:
        tvx = 0.0
        tvy = 0.0
    if mem[M_ABORT] > 0.0:
        # rolled back before the top: put the swing foot down where it lifted off
        tx = mem[M_SW_X0]
        ty = mem[M_SW_Y0] - p[P.I_STRIKE_PUSH] * l0
        tvx = 0.0
        tvy = 0.0
    hold_stance(q, v, stance, r[R_LENGTH], r[R_KP], r[R_KD], mh + mf, gx, gy, p[P.I_LEG_FORCE_MAX], u)
    track_foot(q, v, sw, tx, ty, tvx, tvy, r[R_SWING_KP], r[R_SWING_KD], mf, gx, gy,
               p[P.I_LEG_LENGTH_MAX] * l0, p[P.I_LEG_FORCE_MAX], p[P.I_HIP_TORQUE_MAX], u)
    limit_hip_torque(q, stance, p[P.I_STANCE_MU], mf * g, u)


@jit_inline
def control(m, s, ws, tab, mem, u):
    """Commands u (n_act = 3: leg0 [N], leg1 [N], hip [N m]): the state machine's transition,
    then the control law of the state's row in tab.row."""
    p = tab.p
    gx = m.gravity[0]
    gy = m.gravity[1]
    g = math.sqrt(gx * gx + gy * gy)
    c0 = foot_contact(m, s, 0)
    c1 = foot_contact(m, s, 1)
    next_state(p, s, mem, g, c0 != 0, c1 != 0)
    r = tab.row[int(mem[M_STATE])]
    law = int(r[R_LAW])
    if law == LAW_HIP:
        _hold_hip(p, r, s.q, s.v, gx, gy, u)
    elif law == LAW_FLIGHT:
        _flight(p, r, s.q, s.v, u)
    elif law == LAW_DOUBLE:
        _double_stance(p, r, s, mem, gx, gy, g, c1 if int(mem[M_STANCE]) == 1 else c0, u)
    else:
        _single_stance(p, r, s.q, s.v, mem, gx, gy, g, u)


class Controller:
    """Python path: ``Controller(params)(sim) -> u`` runs the same compiled ``control`` once per
    call (use with ``Simulator.run(controller=..., control_every=1)``); ``gait`` and ``speed``
    can be changed between calls."""

    def __init__(self, params, gait: int = GAIT_WALK, speed: float | None = None):
        self.params = params
        self.tables = make_tables(params)
        self.memory = np.zeros(N_MEMORY)
        self.u = np.zeros(3)
        self.reset(gait, speed)

    def reset(self, gait: int = GAIT_WALK, speed: float | None = None) -> None:
        self.memory[:] = 0.0
        self.memory[M_STATE] = ST_STAND
        self.memory[M_GAIT] = int(gait)
        self.memory[M_SPEED] = self.params.speed if speed is None else float(speed)

    def __call__(self, sim) -> np.ndarray:
        control(sim.model.arrays, sim.state, sim.ws, self.tables, self.memory, self.u)
        return self.u.copy()

    def labels(self, sim) -> dict:
        """Per-frame labels for ``Simulator.run(labels=...)``."""
        return {"gait": self.memory[M_GAIT], "state": self.memory[M_STATE],
                "stance": self.memory[M_STANCE], "phase": self.memory[M_PHASE]}
