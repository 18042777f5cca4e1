"""The Simple Biped's hierarchical state machine (Kelly 2014, section 4), compiled.

Top level: the gait STAND / WALK / JUMP, requested through ``memory[MEM.gait]`` (settable from
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
CROUCH and THRUST are one law with different rows. Left/right is data too: ``memory[MEM.stance]``
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
from walkers.common.slots import size, slots
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

# controller memory (float64 vector), one slot per field in this order
MEM = slots("SimpleBipedMemory", (
    ("gait", 'requested gait'),
    ("state", 'current state'),
    ("stance", 'stance (front) foot index'),
    ("t_enter", 'time the state was entered [s]'),
    ("speed", 'target speed [m/s] (starts at params.speed; settable at run time)'),
    ("v_top", 'pendulum top speed of eq. 2, adapted per step [m/s]'),
    ("lift_x", 'COM x at lift-off [m]'),
    ("strike_x", 'expected COM x at the strike [m]'),
    ("sw_x0", 'swing Bezier: start point, end point, top height [m]'),
    ("sw_y0", ""),
    ("sw_x1", ""),
    ("sw_y1", ""),
    ("sw_top", ""),
    ("steps", 'touchdowns in WALK'),
    ("step_t", 'time and hip x of the last touchdown'),
    ("step_x", ""),
    ("jumps", 'landings after a flight with both feet off the ground'),
    ("airborne", '1 once both feet left the ground in this flight'),
    ("phase", 'last phase variable (single stance)'),
    ("fallen", "set by the rollout's fall monitor"),
    ("scuffs", 'swing-foot contacts before touchdown_phase'),
    ("sw_air", '1 once the swing foot has left the ground in this single stance'),
    ("abort", '1 when the hip rolled back before the top: the swing foot returns behind'),
    ("retries", 'aborted steps'),
    ("work", 'positive mechanical work of all actuators [J] (kept by the rollout)'),
))
N_MEMORY = size(MEM)

# control laws, chosen per state by the state table
LAW_HIP = 0       # PD on the hip over the middle of the feet, both legs pushing (push_hip)
LAW_FLIGHT = 1    # both feet held below the hip at a leg length, spread as when standing
LAW_DOUBLE = 2    # walking double stance: eqs. 1-3 on the front leg, split into both legs
LAW_SINGLE = 3    # walking single stance: stance leg holds its length, swing foot tracks the Bezier

# columns of the state table Tables.row[state], in this order
ROW = slots("StateRow", (
    ("law", 'control law (LAW_*)'),
    ("length", 'target [m]: hip height above the mid-feet (LAW_HIP) or leg length (the others)'),
    ("kp", 'gain on that target [1/s^2] (LAW_HIP: hip x; LAW_DOUBLE, LAW_SINGLE: stance leg)'),
    ("kd", 'its rate gain [1/s]'),
    ("kp_y", 'LAW_HIP: hip height gain [1/s^2]'),
    ("kd_y", 'LAW_HIP: hip vertical rate gain [1/s]'),
    ("accel_y", 'LAW_HIP: vertical hip acceleration added [m/s^2]'),
    ("swing_kp", 'swing / flight foot gains (virtual leg) [1/s^2]'),
    ("swing_kd", '[1/s]'),
))
N_ROW = size(ROW)


class Tables(NamedTuple):
    """What the compiled controller reads: the parameter vector and one row per state."""
    p: np.ndarray      # SimpleBipedParams.to_array(), slots params.FIELD
    row: np.ndarray    # (len(State), N_ROW) control data per state, columns ROW


def make_tables(params) -> Tables:
    """Params -> Tables. Per state: STAND and LAND hold the hip at stand_height, CROUCH at
    crouch_height (stand gains); THRUST keeps the hip over the feet and accelerates it up at
    thrust_accel; FLIGHT holds flight_length legs; WALK_DOUBLE / WALK_SINGLE hold walk_length
    on the stance leg with the ds / ss gains."""
    p = params.to_array()
    l0 = p[P.FIELD.leg_length]
    kp, kd = p[P.FIELD.stand_kp], p[P.FIELD.stand_kd]
    swing = (p[P.FIELD.swing_kp], p[P.FIELD.swing_kd])
    row = np.zeros((len(State), N_ROW))
    # columns: law, length, kp, kd, kp_y, kd_y, accel_y, swing kp, swing kd
    row[ST_STAND] = (LAW_HIP, p[P.FIELD.stand_height] * l0, kp, kd, kp, kd, 0.0, 0.0, 0.0)
    row[ST_LAND] = row[ST_STAND]
    row[ST_CROUCH] = (LAW_HIP, p[P.FIELD.crouch_height] * l0, kp, kd, kp, kd, 0.0, 0.0, 0.0)
    row[ST_THRUST] = (LAW_HIP, 0.0, kp, kd, 0.0, 0.0, p[P.FIELD.thrust_accel], 0.0, 0.0)
    row[ST_FLIGHT] = (LAW_FLIGHT, p[P.FIELD.flight_length] * l0, 0.0, 0.0, 0.0, 0.0, 0.0, *swing)
    row[ST_DOUBLE] = (LAW_DOUBLE, p[P.FIELD.walk_length] * l0, p[P.FIELD.ds_kp], p[P.FIELD.ds_kd], 0.0, 0.0, 0.0, 0.0, 0.0)
    row[ST_SINGLE] = (LAW_SINGLE, p[P.FIELD.walk_length] * l0, p[P.FIELD.ss_kp], p[P.FIELD.ss_kd], 0.0, 0.0, 0.0, *swing)
    return Tables(p=p, row=row)


@kernel
def _enter(mem, state, t):
    mem[MEM.state] = state
    mem[MEM.t_enter] = t


@kernel
def _com_x(p, q, v):
    """COM x [m] and x velocity [m/s]."""
    mh = p[P.FIELD.hip_mass]
    mf = p[P.FIELD.foot_mass]
    mt = mh + 2.0 * mf
    return ((mh * q[0, 0] + mf * (q[1, 0] + q[2, 0])) / mt,
            (mh * v[0, 0] + mf * (v[1, 0] + v[2, 0])) / mt)


@kernel
def _start_swing(p, q, v, mem, stance):
    """Lift-off: the swing Bezier from the swing foot to one step ahead of the stance foot."""
    l0 = p[P.FIELD.leg_length]
    sw = 1 - stance
    L = (p[P.FIELD.step_length0] + p[P.FIELD.step_length_per_speed] * mem[MEM.speed]) * l0
    xs = q[stance + 1, 0]
    ys = q[stance + 1, 1]
    dx = xs - q[sw + 1, 0]
    slope = 0.0
    if abs(dx) > 0.05 * l0:
        slope = clamp((ys - q[sw + 1, 1]) / dx, -0.5, 0.5)
    y_ground = ys + p[P.FIELD.slope_trust] * slope * L
    mem[MEM.stance] = stance
    mem[MEM.sw_x0] = q[sw + 1, 0]
    mem[MEM.sw_y0] = q[sw + 1, 1]
    mem[MEM.sw_x1] = xs + L
    mem[MEM.sw_y1] = y_ground - p[P.FIELD.strike_push] * l0
    mem[MEM.sw_top] = max(q[sw + 1, 1], y_ground) + 4.0 / 3.0 * p[P.FIELD.clearance] * l0
    mem[MEM.lift_x] = _com_x(p, q, v)[0]
    mem[MEM.strike_x] = xs + 0.5 * L


@kernel
def _phase(p, q, v, mem):
    """Phase variable s [-] and its rate [1/s] (linear in the COM x)."""
    x, vx = _com_x(p, q, v)
    span = max(mem[MEM.strike_x] - mem[MEM.lift_x], 0.05 * p[P.FIELD.leg_length])
    return (x - mem[MEM.lift_x]) / span, vx / span


@kernel
def _v_top(p, mem):
    """Pendulum top speed [m/s] aimed at: the adapted v_top, or stop_speed when a gait other
    than WALK waits for the walker to slow down."""
    if int(mem[MEM.gait]) != GAIT_WALK:
        return min(mem[MEM.v_top], p[P.FIELD.stop_speed])
    return mem[MEM.v_top]


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
    state = int(mem[MEM.state])
    gait = int(mem[MEM.gait])
    t_in = t - mem[MEM.t_enter]
    if state == ST_STAND:
        if gait == GAIT_WALK and c0 and c1:
            mem[MEM.stance] = 0 if q[1, 0] > q[2, 0] else 1
            mem[MEM.step_t] = t
            mem[MEM.step_x] = q[0, 0]
            mem[MEM.v_top] = 0.8 * mem[MEM.speed]
            _enter(mem, ST_DOUBLE, t)
        elif gait == GAIT_JUMP and c0 and c1 and t_in > 0.3 and abs(v[0, 0]) + abs(v[0, 1]) < 0.2:
            _enter(mem, ST_CROUCH, t)
    elif state == ST_DOUBLE:
        if gait != GAIT_WALK and abs(v[0, 0]) < p[P.FIELD.stop_speed] + 0.1:
            _enter(mem, ST_STAND, t)
            return
        front = int(mem[MEM.stance])
        dx, dy, l, ldot, phi, phidot = leg_state(q, v, front)
        rear_l = leg_state(q, v, 1 - front)[2]
        # top speed squared the front-leg pendulum will have: (l phi_dot)^2 - 2 g l (1 - cos phi)
        v_top2 = (l * phidot) ** 2 - 2.0 * g * l * (1.0 - math.cos(phi))
        # the legs cannot brake the pendulum (the rear leg only pushes): leave as soon as the
        # energy is within tolerance of the target or above it
        err = _v_top(p, mem) ** 2 - v_top2
        # also leave once the hip is over the front foot and still moving on (not a stall)
        over = phi <= 0.0 and v[0, 0] > p[P.FIELD.stop_speed]
        if t_in >= p[P.FIELD.ds_time_min] and (err < p[P.FIELD.ds_energy_tol] or over
                                            or rear_l >= p[P.FIELD.leg_length_max] * p[P.FIELD.leg_length]
                                            or t_in >= p[P.FIELD.ds_time_max]):
            _start_swing(p, q, v, mem, front)
            mem[MEM.sw_air] = 0.0
            mem[MEM.abort] = 0.0
            _enter(mem, ST_SINGLE, t)
    elif state == ST_SINGLE:
        sw = 1 - int(mem[MEM.stance])
        stance = 1 - sw
        if mem[MEM.abort] == 0.0 and q[0, 0] < q[stance + 1, 0] and _com_x(p, q, v)[1] < 0.0:
            mem[MEM.abort] = 1.0
        sw_contact = c1 if sw == 1 else c0
        if mem[MEM.abort] > 0.0 and sw_contact and (mem[MEM.sw_air] > 0.0 or t_in > 0.05):
            # the step was abandoned and the foot is back down: push again from the same leg
            mem[MEM.retries] += 1
            _enter(mem, ST_DOUBLE, t)
            return
        if not sw_contact:
            mem[MEM.sw_air] = 1.0
        elif mem[MEM.sw_air] > 0.0 and mem[MEM.abort] == 0.0:
            ph = _phase(p, q, v, mem)[0]
            if ph < p[P.FIELD.touchdown_phase]:
                mem[MEM.scuffs] += 1
                mem[MEM.sw_air] = 0.0
                return
            # touchdown: the swing foot becomes the front leg; adapt v_top to the step's speed
            mem[MEM.steps] += 1
            if mem[MEM.steps] >= 3 and t > mem[MEM.step_t]:
                v_step = (q[0, 0] - mem[MEM.step_x]) / (t - mem[MEM.step_t])
                if int(mem[MEM.gait]) == GAIT_WALK:
                    mem[MEM.v_top] = clamp(mem[MEM.v_top] + p[P.FIELD.speed_gain] * (mem[MEM.speed] - v_step),
                                         0.05, 1.5 * mem[MEM.speed] + 0.3)
            mem[MEM.step_t] = t
            mem[MEM.step_x] = q[0, 0]
            mem[MEM.stance] = sw
            _enter(mem, ST_DOUBLE, t)
    elif state == ST_CROUCH:
        if gait != GAIT_JUMP:
            _enter(mem, ST_STAND, t)
        elif t_in >= p[P.FIELD.crouch_time]:
            _enter(mem, ST_THRUST, t)
    elif state == ST_THRUST:
        h = q[0, 1] - 0.5 * (q[1, 1] + q[2, 1])
        if h >= p[P.FIELD.takeoff_height] * p[P.FIELD.leg_length] or t_in > 0.5:
            mem[MEM.airborne] = 0.0
            _enter(mem, ST_FLIGHT, t)
    elif state == ST_FLIGHT:
        if not c0 and not c1:
            mem[MEM.airborne] = 1.0
        elif t_in > 0.05:
            if mem[MEM.airborne] > 0.0:
                mem[MEM.jumps] += 1
            _enter(mem, ST_LAND, t)
    elif state == ST_LAND:
        if t_in >= p[P.FIELD.land_time]:
            _enter(mem, ST_CROUCH if gait == GAIT_JUMP else ST_STAND, t)


@kernel
def _hold_hip(p, r, q, v, gx, gy, u):
    """Hip PD toward (mid-feet x, mid-feet y + r[ROW.length]) plus r[ROW.accel_y] upward, both legs
    pushing (state row r)."""
    mh = p[P.FIELD.hip_mass]
    tx = 0.5 * (q[1, 0] + q[2, 0])
    ty = 0.5 * (q[1, 1] + q[2, 1]) + r[ROW.length]
    ax = r[ROW.kp] * (tx - q[0, 0]) - r[ROW.kd] * v[0, 0]
    ay = r[ROW.kp_y] * (ty - q[0, 1]) - r[ROW.kd_y] * v[0, 1] + r[ROW.accel_y]
    push_hip(q, mh * (ax - gx), mh * (ay - gy), p[P.FIELD.leg_force_max], u)


@kernel
def _flight(p, r, q, v, u):
    """Legs at r[ROW.length], feet spread as when standing, in the hip frame (free fall); the hip
    torque is the mean of the two feet's."""
    l0 = p[P.FIELD.leg_length]
    half = 0.5 * p[P.FIELD.stand_width] * l0
    sign = 1.0 if q[2, 0] >= q[1, 0] else -1.0
    u_hip0 = 0.0
    for f in range(2):
        side = -sign if f == 0 else sign
        track_foot(q, v, f, q[0, 0] + side * half, q[0, 1] - r[ROW.length], v[0, 0], v[0, 1],
                   r[ROW.swing_kp], r[ROW.swing_kd], p[P.FIELD.foot_mass], 0.0, 0.0,
                   p[P.FIELD.leg_length_max] * l0, p[P.FIELD.leg_force_max], p[P.FIELD.hip_torque_max], u)
        if f == 0:
            u_hip0 = u[2]
    u[2] = 0.5 * (u[2] + u_hip0)


@kernel
def _double_stance(p, r, s, mem, gx, gy, g, front_mode, u):
    """Eq. 1 normal force on the front leg toward r[ROW.length], eqs. 2-3 tangential force, split
    into the two legs."""
    q = s.q
    v = s.v
    mh = p[P.FIELD.hip_mass]
    front = int(mem[MEM.stance])
    dx, dy, l, ldot, phi, phidot = leg_state(q, v, front)
    nx = -dx / l
    ny = -dy / l
    a_n = r[ROW.kp] * (r[ROW.length] - l) - r[ROW.kd] * ldot - l * phidot * phidot
    a_t = p[P.FIELD.energy_gain] * l * (_rate_target(_v_top(p, mem), l, phi, g) - phidot)
    a_t = clamp(a_t, -p[P.FIELD.ds_accel_max] * g, p[P.FIELD.ds_accel_max] * g)
    # tangent t = (-ny, nx): the hip's direction of motion for increasing phi; weight
    # compensation -mh g split into its n and t parts
    f_n = mh * (a_n - (gx * nx + gy * ny))
    f_t = mh * (a_t - (-gx * ny + gy * nx))
    if front_mode != 1 and f_t < 0.0:
        f_t = 0.0  # front foot not stuck (sliding or free): no forward push onto it
    push_hip_pendulum(q, front, f_n, f_t, p[P.FIELD.ds_front_load] * mh * g,
                      min(p[P.FIELD.leg_force_max], p[P.FIELD.ds_force_max] * (mh + 2.0 * p[P.FIELD.foot_mass]) * g), u)


@kernel
def _single_stance(p, r, q, v, mem, gx, gy, g, u):
    """The stance leg holds r[ROW.length]; the swing foot tracks the swing Bezier at the phase."""
    l0 = p[P.FIELD.leg_length]
    mh = p[P.FIELD.hip_mass]
    mf = p[P.FIELD.foot_mass]
    stance = int(mem[MEM.stance])
    sw = 1 - stance
    ph, ph_dot = _phase(p, q, v, mem)
    mem[MEM.phase] = ph
    sb = clamp(ph, 0.0, 1.0)
    tx, ty, dtx, dty = rectangle_bezier(mem[MEM.sw_x0], mem[MEM.sw_y0], mem[MEM.sw_x1], mem[MEM.sw_y1],
                                        mem[MEM.sw_top], sb)
    tvx = dtx * ph_dot
    tvy = dty * ph_dot
    if ph >= 1.0:
        # past the expected strike: keep lowering the foot until it finds the ground
        tvx = 0.0
        ty -= p[P.FIELD.descent_rate] * l0 * (ph - 1.0)
        tvy = -p[P.FIELD.descent_rate] * l0 * ph_dot
    elif ph < 0.0:
        tvx = 0.0
        tvy = 0.0
    if mem[MEM.abort] > 0.0:
        # rolled back before the top: put the swing foot down where it lifted off
        tx = mem[MEM.sw_x0]
        ty = mem[MEM.sw_y0] - p[P.FIELD.strike_push] * l0
        tvx = 0.0
        tvy = 0.0
    hold_stance(q, v, stance, r[ROW.length], r[ROW.kp], r[ROW.kd], mh + mf, gx, gy, p[P.FIELD.leg_force_max], u)
    track_foot(q, v, sw, tx, ty, tvx, tvy, r[ROW.swing_kp], r[ROW.swing_kd], mf, gx, gy,
               p[P.FIELD.leg_length_max] * l0, p[P.FIELD.leg_force_max], p[P.FIELD.hip_torque_max], u)
    limit_hip_torque(q, stance, p[P.FIELD.stance_mu], mf * g, u)


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
    r = tab.row[int(mem[MEM.state])]
    law = int(r[ROW.law])
    if law == LAW_HIP:
        _hold_hip(p, r, s.q, s.v, gx, gy, u)
    elif law == LAW_FLIGHT:
        _flight(p, r, s.q, s.v, u)
    elif law == LAW_DOUBLE:
        _double_stance(p, r, s, mem, gx, gy, g, c1 if int(mem[MEM.stance]) == 1 else c0, u)
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
        self.memory[MEM.state] = ST_STAND
        self.memory[MEM.gait] = int(gait)
        self.memory[MEM.speed] = self.params.speed if speed is None else float(speed)

    def __call__(self, sim) -> np.ndarray:
        control(sim.model.arrays, sim.state, sim.ws, self.tables, self.memory, self.u)
        return self.u.copy()

    def labels(self, sim) -> dict:
        """Per-frame labels for ``Simulator.run(labels=...)``."""
        return {"gait": self.memory[MEM.gait], "state": self.memory[MEM.state],
                "stance": self.memory[MEM.stance], "phase": self.memory[MEM.phase]}
