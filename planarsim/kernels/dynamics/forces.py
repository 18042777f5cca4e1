"""Stage 1: applied forces (gravity, actuators, pushes) and v* = v + h M^-1 f.

Actuator kinds (see planarsim/model.py): pin torque, axial force between anchors, hip torque
between point-mass legs (as perpendicular forces), body force along a world direction, body
torque, force along a slider's axis. Commands are saturated to act_range; act_power records
the mechanical power [W]. Joint springs, dampers and armature are not forces here: they act
implicitly in the velocity solve (soft.py); but a slider's rotor, whose row turns with the
rail, adds its velocity-product forces here (slider.add_rotor_forces), and a joint's spring
without rotor or damper that the step resolves is a force here (spring_as_force).
"""
import math

from ...compile import kernel
from ..codes import JOINT_SLIDE_BIT
from .fluid import apply_fluid
from ..math2d import cross2, update_trig, world_point
from ..constraints.slider import add_rotor_forces, slide_position_rate, slider_frame

ACT_PIN_TORQUE = 0
ACT_AXIAL = 1
ACT_HIP_TORQUE = 2
ACT_BODY_FORCE = 3
ACT_BODY_TORQUE = 4
ACT_SLIDER_FORCE = 5


@kernel
def point_velocity(q, v, body, px, py):
    """World velocity [m/s] of the world point (px, py) moving with `body` (0 for the world)."""
    if body < 0:
        return 0.0, 0.0
    rx = px - q[body, 0]
    ry = py - q[body, 1]
    return v[body, 0] - v[body, 2] * ry, v[body, 1] + v[body, 2] * rx


@kernel
def add_point_force(q, f, body, px, py, fx, fy):
    """Add force (fx, fy) [N] applied at world point (px, py) of `body` (ignored for the world)."""
    if body < 0:
        return
    f[body, 0] += fx
    f[body, 1] += fy
    f[body, 2] += cross2(px - q[body, 0], py - q[body, 1], fx, fy)


@kernel
def pin_angle(m, q, j):
    """Pin angle theta_b - theta_a - ref [rad] (the one place it is computed in compiled code)."""
    a = m.pin_body[j, 0]
    ang = q[m.pin_body[j, 1], 2] - m.pin_ref[j]
    if a >= 0:
        ang -= q[a, 2]
    return ang


@kernel
def pin_angle_rate(m, q, v, j):
    """Pin angle theta_b - theta_a - ref [rad] and its rate [rad/s]."""
    a = m.pin_body[j, 0]
    rate = v[m.pin_body[j, 1], 2]
    if a >= 0:
        rate -= v[a, 2]
    return pin_angle(m, q, j), rate


@kernel
def joint_kappa(m, q, cs, j):
    """An upper bound [1 / (kg m^2) or 1 / kg] of how fast joint j's coordinate answers a
    push on it, at q (cs its cos / sin): a hinge to the world turns its body about the hinge,
    1 / (I + m d^2) (d the anchor's distance from its centre of mass: the pin's rows hold
    it there); a hinge between two bodies 1 / I_a + 1 / I_b (g W g^T, as if the pin did not
    hold them: more than it is); a slider to the world moves its body along the slide without
    turning it (its angle row holds the turn), 1 / m; a slider between two bodies g W g^T
    along its slide (blocks at anchor b: slider.py; as if the angle row did not hold them:
    more than it is). Other joints and contacts only lower it."""
    a = m.pin_body[j, 0]
    b = m.pin_body[j, 1]
    if (m.pin_kind[j] & JOINT_SLIDE_BIT) == 0:
        if a < 0 or b < 0:
            e = 1 if a < 0 else 0
            body = m.pin_body[j, e]
            d2 = m.pin_anchor[j, e, 0] ** 2 + m.pin_anchor[j, e, 1] ** 2
            wi = m.body_inv_inertia[body]
            return wi / (1.0 + wi * d2 / m.body_inv_mass[body])
        return m.body_inv_inertia[a] + m.body_inv_inertia[b]
    if a < 0 or b < 0:
        return m.body_inv_mass[b if a < 0 else a]
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, j, a, b)
    kappa = 0.0
    for e in range(2):
        body = a if e == 0 else b
        if body >= 0:
            lever = cross2(bx - q[body, 0], by - q[body, 1], dx, dy)
            kappa += (dx * dx + dy * dy) * m.body_inv_mass[body] + lever * lever * m.body_inv_inertia[body]
    return kappa


@kernel
def spring_as_force(m, q, cs, j, h):
    """Joint j's spring acts as an explicit force in a step of h [s] from q (add_spring_forces):
    a spring with neither rotor nor damper that the step resolves, h^2 k kappa <= 1/2 (kappa =
    joint_kappa: the soft row's theta would be 0). Symplectic Euler's own spring, as MuJoCo's
    Euler takes it; kept at the step's end (theta = 1, backward Euler) it was damped by the
    scheme (a random MJCF tree's hinge spring of h w = 0.05 erred 43x MuJoCo Euler's after
    0.2 s, 1.0x with a damper of 1e-9)."""
    k = m.pin_stiffness[j]
    if k == 0.0 or m.pin_armature[j] > 0.0 or m.pin_damping[j] > 0.0:
        return False
    return h * h * k * joint_kappa(m, q, cs, j) <= 0.5


@kernel
def add_spring_forces(m, q, cs, f, h):
    """Add to f [N, N m] the forces of the joints' springs that are forces in a step of h [s]
    (spring_as_force): -k (x - rest) along the coordinate's row (a hinge's torque on body b
    and its opposite on body a; a slider's force along its axis at anchor b, as a slider
    motor's)."""
    for j in range(m.pin_stiffness.shape[0]):
        if not spring_as_force(m, q, cs, j, h):
            continue
        a = m.pin_body[j, 0]
        b = m.pin_body[j, 1]
        if (m.pin_kind[j] & JOINT_SLIDE_BIT) == 0:
            torque = -m.pin_stiffness[j] * (pin_angle(m, q, j) - m.pin_rest[j])
            f[b, 2] += torque
            if a >= 0:
                f[a, 2] -= torque
            continue
        dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, j, a, b)
        push = -m.pin_stiffness[j] * (dx * (bx - ax) + dy * (by - ay) - m.pin_rest[j])
        add_point_force(q, f, b, bx, by, push * dx, push * dy)
        add_point_force(q, f, a, bx, by, -push * dx, -push * dy)


@kernel(inline="always")
def apply_actuator(m, q, cs, v, f, k, u):
    """Add actuator k's saturated command u to f; return its mechanical power [W]."""
    kind = m.act_kind[k]
    a = m.act_body[k, 0]
    b = m.act_body[k, 1]
    if kind == ACT_PIN_TORQUE:
        j = m.act_ref[k]
        pa = m.pin_body[j, 0]
        pb = m.pin_body[j, 1]
        f[pb, 2] += u
        if pa >= 0:
            f[pa, 2] -= u
        return u * pin_angle_rate(m, q, v, j)[1]
    if kind == ACT_AXIAL:
        ax, ay = world_point(q, cs, a, m.act_anchor[k, 0, 0], m.act_anchor[k, 0, 1])
        bx, by = world_point(q, cs, b, m.act_anchor[k, 1, 0], m.act_anchor[k, 1, 1])
        dx = bx - ax
        dy = by - ay
        L = math.sqrt(dx * dx + dy * dy)
        if L < 1e-12:
            return 0.0
        ex = dx / L
        ey = dy / L
        add_point_force(q, f, b, bx, by, u * ex, u * ey)
        add_point_force(q, f, a, ax, ay, -u * ex, -u * ey)
        vax, vay = point_velocity(q, v, a, ax, ay)
        vbx, vby = point_velocity(q, v, b, bx, by)
        return u * (ex * (vbx - vax) + ey * (vby - vay))
    if kind == ACT_HIP_TORQUE:
        h = m.act_body[k, 2]
        power = 0.0
        for side in range(2):
            leg = a if side == 0 else b
            sign = -1.0 if side == 0 else 1.0
            dx = q[leg, 0] - q[h, 0]
            dy = q[leg, 1] - q[h, 1]
            d2 = dx * dx + dy * dy
            if d2 < 1e-24:
                continue
            # force perpendicular to the leg giving torque sign*u about the hip
            fx = -sign * u * dy / d2
            fy = sign * u * dx / d2
            f[leg, 0] += fx
            f[leg, 1] += fy
            f[h, 0] -= fx
            f[h, 1] -= fy
            w = cross2(dx, dy, v[leg, 0] - v[h, 0], v[leg, 1] - v[h, 1]) / d2
            power += sign * u * w
        return power
    if kind == ACT_SLIDER_FORCE:
        # +u d on body b and -u d on body a, both at anchor b: the slide's generalised force
        j = m.act_ref[k]
        ja = m.pin_body[j, 0]
        jb = m.pin_body[j, 1]
        dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, j, ja, jb)
        add_point_force(q, f, jb, bx, by, u * dx, u * dy)
        add_point_force(q, f, ja, bx, by, -u * dx, -u * dy)
        return u * slide_position_rate(m, q, cs, v, j)[1]
    if kind == ACT_BODY_FORCE:
        f[a, 0] += u * m.act_dir[k, 0]
        f[a, 1] += u * m.act_dir[k, 1]
        return u * (m.act_dir[k, 0] * v[a, 0] + m.act_dir[k, 1] * v[a, 1])
    # ACT_BODY_TORQUE
    if m.body_inv_inertia[a] > 0.0:
        f[a, 2] += u
    return u * v[a, 2]


@kernel
def apply_forces(m, s, ws, u, h):
    """f = m g + pushes + fluid drag + the velocity-product forces of sliders' rotors
    (slider.add_rotor_forces) + the joint springs a step of h [s] takes as forces
    (spring_as_force) + saturated actuator commands u (the other joint springs, dampers and
    the rotors' inertia: soft.py)."""
    q = s.q
    v = s.v
    f = ws.force
    for i in range(q.shape[0]):
        f[i, 0] = m.body_mass[i] * m.gravity[0] + s.ext_force[i, 0]
        f[i, 1] = m.body_mass[i] * m.gravity[1] + s.ext_force[i, 1]
        f[i, 2] = s.ext_force[i, 2] if m.body_inv_inertia[i] > 0.0 else 0.0
    if m.fluid_body.shape[0] > 0:
        apply_fluid(m, q, ws.body_cs, v, f)
    add_rotor_forces(m, q, ws.body_cs, v, f)
    add_spring_forces(m, q, ws.body_cs, f, h)
    # actuators, saturated
    for k in range(m.act_kind.shape[0]):
        uk = u[k]
        if uk < m.act_range[k, 0]:
            uk = m.act_range[k, 0]
        elif uk > m.act_range[k, 1]:
            uk = m.act_range[k, 1]
        ws.act_u[k] = uk
        ws.act_power[k] = apply_actuator(m, q, ws.body_cs, v, f, k, uk)


@kernel(inline="always")
def _leg_turn(q0, q1, leg, hip):
    """The angle [rad] a point-mass leg's vector from the hip turned from q0 to q1 (0 for a
    leg at its hip, as apply_actuator applies it no force)."""
    ax = q0[leg, 0] - q0[hip, 0]
    ay = q0[leg, 1] - q0[hip, 1]
    bx = q1[leg, 0] - q1[hip, 0]
    by = q1[leg, 1] - q1[hip, 1]
    if ax * ax + ay * ay < 1e-24 or bx * bx + by * by < 1e-24:
        return 0.0
    return math.atan2(cross2(ax, ay, bx, by), ax * bx + ay * by)


@kernel(inline="always")
def _axial_length(m, q, cs, k):
    """Distance [m] between actuator k's two anchors at q (cs its cos / sin)."""
    ax, ay = world_point(q, cs, m.act_body[k, 0], m.act_anchor[k, 0, 0], m.act_anchor[k, 0, 1])
    bx, by = world_point(q, cs, m.act_body[k, 1], m.act_anchor[k, 1, 0], m.act_anchor[k, 1, 1])
    return math.sqrt((bx - ax) ** 2 + (by - ay) ** 2)


@kernel(inline="always")
def _slide(m, q, cs, j):
    """Slider j's slide [m]: anchor b's distance from anchor a along the axis, at q."""
    dx, dy, ax, ay, bx, by = slider_frame(m, q, cs, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return dx * (bx - ax) + dy * (by - ay)


@kernel
def actuator_move(m, q0, cs0, q1, cs1, k):
    """How far actuator k's coordinate moved from q0 to q1 (cs0, cs1 their cos / sin), the
    coordinate its command pushes along: the joint's angle [rad] (pin torque), the distance
    between its anchors [m] (axial force), the legs' turns about the hip, the second's less
    the first's (hip torque), the body's position along the force's direction [m] (body
    force), its angle (body torque), the slide [m] (slider force). Its command times it is
    the work [J] the command did."""
    kind = m.act_kind[k]
    a = m.act_body[k, 0]
    if kind == ACT_PIN_TORQUE:
        j = m.act_ref[k]
        return pin_angle(m, q1, j) - pin_angle(m, q0, j)
    if kind == ACT_AXIAL:
        L0 = _axial_length(m, q0, cs0, k)
        if L0 < 1e-12:
            return 0.0
        return _axial_length(m, q1, cs1, k) - L0
    if kind == ACT_HIP_TORQUE:
        hip = m.act_body[k, 2]
        return _leg_turn(q0, q1, m.act_body[k, 1], hip) - _leg_turn(q0, q1, a, hip)
    if kind == ACT_SLIDER_FORCE:
        j = m.act_ref[k]
        return _slide(m, q1, cs1, j) - _slide(m, q0, cs0, j)
    if kind == ACT_BODY_FORCE:
        return (m.act_dir[k, 0] * (q1[a, 0] - q0[a, 0])
                + m.act_dir[k, 1] * (q1[a, 1] - q0[a, 1]))
    return q1[a, 2] - q0[a, 2]     # ACT_BODY_TORQUE


@kernel
def end_power(m, s, ws, q_start, h):
    """ws.act_power [W] of a step of h [s] that has ended, from q_start to s.q: each
    actuator's saturated command (ws.act_u) times its coordinate's move over the step
    (actuator_move), over h. So h times it is the work the command did in the step, whatever
    the sub-steps, splits or integrator; apply_forces' power, at the rates the step started
    with, is not (a walking quadruped's motors did 3 % more positive work than it counted,
    and a net work of the other sign). An axial or slider force's move needs the bodies'
    cos / sin: the start's go into ws.cs_pred (scratch after the step: the next step
    computes it afresh). The work is also added to
    ws.act_work, and h to ws.act_work_time, for the next recorded frame (record_frame)."""
    for k in range(m.act_kind.shape[0]):      # (only anchors' and slides' moves turn)
        if m.act_kind[k] == ACT_AXIAL or m.act_kind[k] == ACT_SLIDER_FORCE:
            update_trig(s.q, ws.body_cs)
            update_trig(q_start, ws.cs_pred)
            break
    for k in range(m.act_kind.shape[0]):
        work = ws.act_u[k] * actuator_move(m, q_start, ws.cs_pred, s.q, ws.body_cs, k)
        ws.act_power[k] = work / h
        ws.act_work[k] += work
    ws.act_work_time[0] += h


@kernel
def kick(m, s, ws, u, h, step):
    """s.v += h M^-1 f [m/s, rad/s] with f the applied forces at s.q under commands u (h may be
    negative; a half kick of the step-to-instant conversions and of RATTLE). Uses ws's force
    scratch (the next step computes it again) and leaves ws.act_power at the velocity it was
    called with. step [s]: the length of the step whose forces these are (a spring is a
    force here where that step takes it as one: spring_as_force)."""
    update_trig(s.q, ws.body_cs)
    apply_forces(m, s, ws, u, step)
    for i in range(s.v.shape[0]):
        s.v[i, 0] += h * m.body_inv_mass[i] * ws.force[i, 0]
        s.v[i, 1] += h * m.body_inv_mass[i] * ws.force[i, 1]
        s.v[i, 2] += h * m.body_inv_inertia[i] * ws.force[i, 2]


@kernel
def predict_velocity(m, s, ws, h):
    """v* = v + h M^-1 f (point masses keep zero angular velocity)."""
    for i in range(s.v.shape[0]):
        ws.v_pred[i, 0] = s.v[i, 0] + h * m.body_inv_mass[i] * ws.force[i, 0]
        ws.v_pred[i, 1] = s.v[i, 1] + h * m.body_inv_mass[i] * ws.force[i, 1]
        ws.v_pred[i, 2] = s.v[i, 2] + h * m.body_inv_inertia[i] * ws.force[i, 2]
