"""Stage 9: guards. Every q and v component must be finite and below the magnitude bound."""
import math

from ...compile import kernel
from ..codes import CONTACT_ARC, CONTACT_POINT, JOINT_HINGE, MODE_FREE, MODE_PINNED, MODE_SLIDING
from ..math2d import rotate, world_point
from ..constraints.joints import is_slider
from ..constraints.limit import limit_overshoot
from ..dynamics.forces import ACT_BODY_TORQUE, ACT_PIN_TORQUE
from ..geometry.terrain import ground_point
from ..info import INFO_COMMAND, INFO_GUARD_BODY, INFO_GUARD_FIELD
from ..solver.islands import _root
from .frame import frame_displacement, frame_velocity, speed_in_frame

GUARD_OK = 0
GUARD_NONFINITE = 1
GUARD_TOO_LARGE = 2
GUARD_AUDIT = 3           # the step broke a rule of its own audit (StepOptions.audit_raise = 1)
GUARD_GROSS = 4           # a pin open or a contact deep beyond StepOptions.gross_limit at the end
                          # of the step (ws.audit_worst: which, ws.audit_worst_value: how far)
GUARD_ENERGY = 6          # the step gained energy from nowhere beyond StepOptions.energy_limit
                          # (work.judge_energy; ws.audit_last: cause, element, body; audit_value)
GUARD_SPEED = 5           # a body faster than StepOptions.speed_limit (check_speeds)
GUARD_STIFF_ACTUATOR = 7  # a torque too strong for the step (check_actuator_turns; ws.info[INFO_COMMAND]:
                          # the actuator, ws.guard_value: its turn in one step [rad], the inverse
                          # inertia it drives [1/(kg m^2)], the limit [rad]); nothing is stepped
FIELD_SPEED = 6           # ws.info[INFO_GUARD_FIELD] of a body's speed |v| [m/s]
FIELD_TURNING = 7         # ... of its turning speed |omega| r_g [m/s] (r_g its radius of gyration)
GUARD_UNSUPPORTED = 8     # StepOptions.integrator cannot step this model (kernels/dynamics/rattle.py
                          # unsupported; ws.info[INFO_GUARD_FIELD]: what, [INFO_GUARD_BODY]:
                          # which element); nothing is stepped
GUARD_JUMP = 9           # a body moved in the step farther than its velocities explain
                          # (check_displacements; ws.info[INFO_GUARD_BODY]: the body,
                          # [INFO_GUARD_FIELD]: a contact touching it or -1, ws.guard_value:
                          # the distance, what its velocities explain, the allowance [m])
GUARD_ROOM = 10          # a row or complementarity variable of the step did not fit the
                          # workspace's storage (ws.room): the state is put back at the step's
                          # start, and Simulator grows the storage and takes the step again
GUARD_BAD_MODE = 11      # a contact's mode in the State is none of free, pinned, sliding (the
                         # State edited in place: check_state sees only a State put in;
                         # ws.info[INFO_GUARD_BODY]: the contact, ws.guard_value: the mode);
                         # nothing is stepped
GUARD_BAD_COMMANDS = -1   # the commands array does not have one entry per actuator (ws.info[INFO_COMMAND]:
                          # its length); negative, so that no walker's own return code clashes
GUARD_NONFINITE_COMMAND = -2   # a command is NaN or infinite (ws.info[INFO_COMMAND]: its index,
                               # ws.guard_value: the value); nothing is stepped


@kernel(inline="always")
def _guard_code(x, limit):
    """GUARD_NONFINITE if x is NaN or infinite, GUARD_TOO_LARGE if |x| > limit, else GUARD_OK."""
    if not math.isfinite(x):
        return GUARD_NONFINITE
    if abs(x) > limit:
        return GUARD_TOO_LARGE
    return GUARD_OK


@kernel
def check_guards(s, ws, limit):
    """Return GUARD_*; on failure ws.info[INFO_GUARD_BODY] = body,
    ws.info[INFO_GUARD_FIELD] = field 0..5 (x y th vx vy w); or GUARD_BAD_MODE for a
    contact's mode that is no mode (ws.info[INFO_GUARD_BODY] = the contact)."""
    for i in range(s.q.shape[0]):
        for f in range(6):
            x = s.q[i, f] if f < 3 else s.v[i, f - 3]
            bad = _guard_code(x, limit)
            if bad != GUARD_OK:
                ws.info[INFO_GUARD_BODY] = i
                ws.info[INFO_GUARD_FIELD] = f
                ws.guard_value[0] = x
                return bad
    for i in range(s.contact_mode.shape[0]):
        mode = s.contact_mode[i]
        if mode != MODE_FREE and mode != MODE_PINNED and mode != MODE_SLIDING:
            ws.info[INFO_GUARD_BODY] = i
            ws.guard_value[0] = mode
            return GUARD_BAD_MODE
    return GUARD_OK


@kernel
def check_commands(u, ws):
    """GUARD_NONFINITE_COMMAND if some command u[k] is NaN or infinite (recorded in
    ws.info[INFO_COMMAND] and ws.guard_value), else GUARD_OK."""
    for k in range(u.shape[0]):
        if not math.isfinite(u[k]):
            ws.info[INFO_COMMAND] = k
            ws.guard_value[0] = u[k]
            return GUARD_NONFINITE_COMMAND
    return GUARD_OK


@kernel
def _speed(v, i):
    """Body i's speed [m/s], its centre of mass's, from velocities v (n_body, 3)."""
    return math.sqrt(v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1])


@kernel(inline="always")
def _turning_speed(m, v, i):
    """Body i's turning speed |omega| r_g [m/s] (r_g = sqrt(I / m): check_speeds)."""
    return abs(v[i, 2]) * math.sqrt(m.body_inertia[i] * m.body_inv_mass[i])


@kernel
def check_speeds(m, s, ws, bound):
    """GUARD_SPEED if some body's speed |v| or turning speed |omega| r_g (r_g = sqrt(I / m),
    its radius of gyration: the speed whose kinetic energy equals the body's turning energy)
    exceeds bound [m/s] (recorded: body, FIELD_SPEED or FIELD_TURNING, the speed and the
    bound in ws.guard_value), else GUARD_OK. One bound for both: a body's kinetic energy is at
    most m bound^2."""
    for i in range(s.v.shape[0]):
        speed = _speed(s.v, i)
        turning = _turning_speed(m, s.v, i)
        if speed > bound or turning > bound:
            ws.info[INFO_GUARD_BODY] = i
            ws.info[INFO_GUARD_FIELD] = FIELD_SPEED if speed > bound else FIELD_TURNING
            ws.guard_value[0] = speed if speed > bound else turning
            ws.guard_value[1] = bound
            return GUARD_SPEED
    return GUARD_OK


@kernel
def _pin_arm(m, ws, j, e):
    """(x, y) [m] of pin j's anchor on its body e (0: a, 1: b) from that body's centre of mass,
    in the world frame (ws.body_cs: the angles' cos and sin); (0, 0) for the world."""
    body = m.pin_body[j, e]
    if body < 0:
        return 0.0, 0.0
    return rotate(ws.body_cs[body, 0], ws.body_cs[body, 1], m.pin_anchor[j, e, 0], m.pin_anchor[j, e, 1])


@kernel
def _held_mobility(m, ws, body, skip):
    """(W00, W01, W02, W11, W12, W22): body's mobility M^-1 [1/kg, 1/(kg m), 1/(kg m^2)] in
    (x, y, angle) with its hinges to the world (other than pin `skip`) holding it: W - B S^-1
    B^T over the first such pin (B = W G^T, S = G W G^T of its two rows), all zeros with two
    or more (the body cannot move)."""
    w = m.body_inv_mass[body]
    i = m.body_inv_inertia[body]
    held = -1
    for p in range(m.pin_body.shape[0]):
        if p == skip or m.pin_kind[p] != JOINT_HINGE:
            continue
        if (m.pin_body[p, 0] == body and m.pin_body[p, 1] < 0) or (
                m.pin_body[p, 1] == body and m.pin_body[p, 0] < 0):
            if held >= 0:
                return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            held = p
    if held < 0:
        return w, 0.0, 0.0, w, 0.0, i
    sx, sy = _pin_arm(m, ws, held, 0 if m.pin_body[held, 0] == body else 1)
    det = w * w + w * i * (sx * sx + sy * sy)
    if not det > 0.0:
        return w, 0.0, 0.0, w, 0.0, i
    s00 = (w + sx * sx * i) / det
    s01 = sx * sy * i / det
    s11 = (w + sy * sy * i) / det
    # B's rows (x, y, angle): (w, 0), (0, w), (-sy i, sx i)
    b20 = -sy * i
    b21 = sx * i
    return (w - w * s00 * w, -w * s01 * w, -w * (s00 * b20 + s01 * b21), w - w * s11 * w,
            -w * (s01 * b20 + s11 * b21),
            i - (b20 * (s00 * b20 + s01 * b21) + b21 * (s01 * b20 + s11 * b21)))


@kernel
def hinge_turn_gain(m, ws, j):
    """1 / [kg m^2]: g M_c^-1 g^T of hinge j's angle (g: the rate of theta_b - theta_a) with
    the hinge's own pin holding its two bodies, each body also held by its hinge to the world
    if it has one (_held_mobility), and nothing else acting: g W g^T - c^T A^-1 c,
    A = G W G^T of the pin's two rows, c = G W g^T. A link hinged to the world turns as about
    its hinge, 1 / (I + m d^2). The model's other joints and contacts only add constraints,
    which lower it: an upper bound of the turn. 1/I_a + 1/I_b where the pin's rows are
    degenerate (point masses)."""
    ggt = 0.0
    c1 = 0.0
    c2 = 0.0
    a11 = 0.0
    a12 = 0.0
    a22 = 0.0
    free = 0.0
    for e in range(2):
        body = m.pin_body[j, e]
        if body < 0:
            continue
        free += m.body_inv_inertia[body]
        p, q, r, s, t, u = _held_mobility(m, ws, body, j)
        rx, ry = _pin_arm(m, ws, j, e)
        ggt += u
        # G_e = +-[[1, 0, -ry], [0, 1, rx]], g_e = -+(0, 0, 1): c_e = -(r - ry u, t + rx u)
        c1 -= r - ry * u
        c2 -= t + rx * u
        a11 += p - 2.0 * ry * r + ry * ry * u
        a22 += s + 2.0 * rx * t + rx * rx * u
        a12 += q - ry * t + rx * r - rx * ry * u
    det = a11 * a22 - a12 * a12
    if not det > 1e-12 * (a11 * a22) or not math.isfinite(det):
        return free
    held = (a22 * c1 * c1 - 2.0 * a12 * c1 * c2 + a11 * c2 * c2) / det
    return max(ggt - held, 0.0)


@kernel
def turn_gain(m, ws, k, held, h):
    """1 / [kg m^2]: how fast torque actuator k turns what it drives in a step of h [s] from
    rest: of its hinge's angle with that hinge's pin holding its two bodies where `held`
    (hinge_turn_gain), else as if they were free (1/I_a + 1/I_b: larger, and cheap); a
    joint's armature a and damping c give kappa / (1 + (a + h c) kappa) (the damper is
    implicit, constraints/soft.py: the step's rate from rest is h u kappa / (1 + (a + h c)
    kappa)); of its body's angle (1/I); 0 for the actuators that push (forces, point-mass
    hips, sliders). The other joints and contacts only slow the turn: an upper bound."""
    kind = m.act_kind[k]
    if kind == ACT_BODY_TORQUE:
        return m.body_inv_inertia[m.act_body[k, 0]]
    if kind != ACT_PIN_TORQUE:
        return 0.0
    j = m.act_ref[k]
    kappa = 0.0
    if held and m.pin_kind[j] == JOINT_HINGE:
        kappa = hinge_turn_gain(m, ws, j)
    else:
        for e in range(2):
            if m.pin_body[j, e] >= 0:
                kappa += m.body_inv_inertia[m.pin_body[j, e]]
    return kappa / (1.0 + (m.pin_armature[j] + h * m.pin_damping[j]) * kappa)


@kernel
def check_actuator_turns(m, ws, h, limit):
    """GUARD_STIFF_ACTUATOR if some torque actuator's saturated command (ws.act_u) alone would
    turn what it drives by more than `limit` [rad] in one step of h [s] from rest,
    h^2 |u| kappa (turn_gain): a torque that acts faster than the step can resolve (the
    joints' and contacts' corrections hold only turns of a few tenths of a radian per step).
    Recorded: the actuator (ws.info[INFO_COMMAND]), the turn, kappa and limit (ws.guard_value).
    The free bodies' gain bounds the held one: only a command that passes the limit by it pays
    for the held one (hinge_turn_gain scans the pins)."""
    for k in range(m.act_kind.shape[0]):
        if h * h * abs(ws.act_u[k]) * turn_gain(m, ws, k, False, h) <= limit:
            continue
        kappa = turn_gain(m, ws, k, True, h)
        turn = h * h * abs(ws.act_u[k]) * kappa
        if turn > limit:
            ws.info[INFO_COMMAND] = k
            ws.guard_value[0] = turn
            ws.guard_value[1] = kappa
            ws.guard_value[2] = limit
            return GUARD_STIFF_ACTUATOR
    return GUARD_OK


@kernel
def start_depth(m, q, b):
    """How deep [m] body b's deepest ground contact (a point, an arc sole's circle or a
    fallback vertex) is below the ground at configuration q (0: none below): at the step's
    start, a violation the step's correction lifts the body out of (a start allowed below
    the ground). Shapes' overlaps at the start: note_start_depths."""
    c = math.cos(q[b, 2])
    sn = math.sin(q[b, 2])
    deepest = 0.0
    for i in range(m.contact_body.shape[0]):
        kind = m.contact_kind[i]
        if m.contact_body[i] != b or not (kind == CONTACT_POINT or kind == CONTACT_ARC):
            continue
        lx = m.contact_local[i, 0]
        ly = m.contact_local[i, 1]
        gap = ground_point(m.terrain_coef, q[b, 0] + c * lx - sn * ly,
                           q[b, 1] + sn * lx + c * ly)[4]
        if kind == CONTACT_ARC:
            gap -= m.contact_radius[i]
        deepest = max(deepest, -gap)
        adr = m.contact_vert_adr[i]
        for k in range(adr, adr + m.contact_vert_num[i]):
            lx = m.vert_local[k, 0]
            ly = m.vert_local[k, 1]
            gap = ground_point(m.terrain_coef, q[b, 0] + c * lx - sn * ly,
                               q[b, 1] + sn * lx + c * ly)[4]
            deepest = max(deepest, -gap)
    return deepest


@kernel
def _touching_contact(m, s, ws, b):
    """A contact on body b that touches at the end of the step (else one of its enabled
    contacts; -1: it has none)."""
    some = -1
    for i in range(m.contact_body.shape[0]):
        if ws.contact_bodies[i, 0] != b and ws.contact_bodies[i, 1] != b:
            continue
        if s.contact_enabled[i] == 1 and s.contact_mode[i] != MODE_FREE:
            return i
        if some < 0 and s.contact_enabled[i] == 1:
            some = i
    return some


@kernel
def start_path(m, s, ws):
    """A step starts: no path yet, each body's part starts at its speed (in the frame of the
    step's checks, checks/frame.py), no depth known yet (ws.path_explained)."""
    vx, vy = frame_velocity(m, ws, s.v)
    for i in range(s.v.shape[0]):
        ws.path_explained[i, 0] = 0.0
        ws.path_explained[i, 1] = speed_in_frame(s.v, i, vx, vy)
        ws.path_explained[i, 2] = 0.0


@kernel
def note_start_depths(ws):
    """After the step's first contact search: each body's largest overlap [m] among the live
    contacts found at the step's start (a shape started in the ground or inside another
    shape, which the step's correction pushes out: ws.path_explained[:, 2])."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        depth = -ws.contact_gap[i]
        if not depth > 0.0:
            continue
        for e in range(2):
            b = ws.contact_bodies[i, e]
            if b >= 0 and depth > ws.path_explained[b, 2]:
                ws.path_explained[b, 2] = depth


@kernel
def note_start_limits(m, s, ws):
    """After note_start_depths: a joint that starts the step outside its limit (a state put
    in from outside, a build pose) is moved onto it by the position projection; each of its
    bodies may then move as far as the joint's overshoot o turns or slides the bodies joined
    to it: o [m] for a slider, o [rad] times the farthest centre of mass from the hinge for a
    hinge (ws.path_explained[:, 2], which joined_start_depth spreads over them). ws.body_cs
    must match s.q."""
    for j in range(m.pin_body.shape[0]):
        over = limit_overshoot(m, s.q, ws.body_cs, s.v, j)
        if not over > 0.0:
            continue
        if not is_slider(m, j):
            px, py = world_point(s.q, ws.body_cs, m.pin_body[j, 1], m.pin_anchor[j, 1, 0],
                                 m.pin_anchor[j, 1, 1])
            reach = 0.0
            for b in range(s.q.shape[0]):
                reach = max(reach, math.hypot(s.q[b, 0] - px, s.q[b, 1] - py))
            over *= reach
        for e in range(2):
            b = m.pin_body[j, e]
            if b >= 0 and over > ws.path_explained[b, 2]:
                ws.path_explained[b, 2] = over


@kernel
def add_part_path(m, s, ws, tau):
    """A part of tau [s] ended at a time-of-impact split (ccd.advance_to_impact moved each body
    by tau times its velocity at the split, s.v, or its part's solved velocity ws.v_new): add
    tau max(|v_start|, |v_split|, |v_new|) to the path its velocities explain; the next part
    starts at |v_split| (speeds in the frame of the step's checks, checks/frame.py)."""
    vx, vy = frame_velocity(m, ws, s.v)
    wx, wy = frame_velocity(m, ws, ws.v_new)
    for i in range(s.v.shape[0]):
        speed = speed_in_frame(s.v, i, vx, vy)
        ws.path_explained[i, 0] += tau * max(ws.path_explained[i, 1], speed,
                                             speed_in_frame(ws.v_new, i, wx, wy))
        ws.path_explained[i, 1] = speed


@kernel(inline="always")
def _add_path(ws, i, h, speed):
    """Body i's part of h [s] ended at speed [m/s]: h max(|v_start|, |v_end|) added to the
    path its velocities explain; the next part starts at speed (finish_path)."""
    ws.path_explained[i, 0] += h * max(ws.path_explained[i, 1], speed)
    ws.path_explained[i, 1] = speed


@kernel
def finish_path(m, s, ws, h):
    """The step's last part, of h [s], ended: add h max(|v_start|, |v_end|) to the path each
    body's velocities explain (ws.path_explained[:, 0] then holds the whole step's; speeds
    in the frame of the step's checks, checks/frame.py)."""
    vx, vy = frame_velocity(m, ws, s.v)
    for i in range(s.v.shape[0]):
        _add_path(ws, i, h, speed_in_frame(s.v, i, vx, vy))


@kernel
def keep_step_path(ws, add):
    """The step's (add: a sub-step's) path, ws.path_explained[:, 0], into (added to)
    ws.step_path."""
    for i in range(ws.step_path.shape[0]):
        ws.step_path[i] = ws.path_explained[i, 0] + (ws.step_path[i] if add else 0.0)


@kernel
def joined_start_depth(m, ws, start_q, i):
    """The largest overlap [m] at the step's start (positions start_q: start_depth;
    note_start_depths) of body i and of every body joined to it by pins and rods: a
    correction pushing one body out of the ground moves the bodies joined to it as far (of a
    step taken in sub-steps, the last one's shape overlaps). Only for a body beyond its
    first bound: a union-find over the joints (islands._root) in ws.island_parent, whose
    islands the step's solve is done with."""
    parent = ws.island_parent
    for b in range(parent.shape[0]):
        parent[b] = b
    for j in range(m.pin_body.shape[0] + m.rod_body.shape[0]):
        if j < m.pin_body.shape[0]:
            a, b = m.pin_body[j, 0], m.pin_body[j, 1]
        else:
            a, b = m.rod_body[j - m.pin_body.shape[0], 0], m.rod_body[j - m.pin_body.shape[0], 1]
        if a >= 0 and b >= 0:
            ra = _root(parent, a)
            rb = _root(parent, b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    ri = _root(parent, i)
    depth = 0.0
    for b in range(parent.shape[0]):
        if _root(parent, b) == ri:
            depth = max(depth, start_depth(m, start_q, b), ws.path_explained[b, 2])
    return depth


@kernel
def end_checks_alone(m, s, ws, h, guard_limit, speed_limit, jump_limit):
    """finish_path and the checks at a step's end, check_guards, check_speeds (speed_limit >
    0) and check_displacements (jump_limit > 0), in one pass over the bodies, for a model
    without contacts (the pin-chain path: no depth to allow for): True if some check fails.
    Nothing is recorded: the general stages then take the step again and name the culprit."""
    bad = False
    vx, vy = frame_velocity(m, ws, s.v)
    dx, dy = frame_displacement(m, ws, s.q, ws.prev.q)
    for i in range(s.q.shape[0]):
        for f in range(3):
            if (_guard_code(s.q[i, f], guard_limit) != GUARD_OK
                    or _guard_code(s.v[i, f], guard_limit) != GUARD_OK):
                bad = True
        speed = _speed(s.v, i)
        _add_path(ws, i, h, speed_in_frame(s.v, i, vx, vy))
        if speed_limit > 0.0 and (speed > speed_limit
                                  or _turning_speed(m, s.v, i) > speed_limit):
            bad = True
        if jump_limit > 0.0 and (_moved(s.q, ws.prev.q, i, dx, dy)
                                 > ws.path_explained[i, 0] + jump_limit):
            bad = True
    return bad


@kernel
def check_displacements(m, s, ws, slack):
    """GUARD_JUMP if some body's centre of mass moved over the step (from ws.prev, the step's
    start) farther than its velocities explain plus slack [m] (plus the depth its contacts,
    or those of a body joined to it, started the step below the ground or inside another
    shape, which the step pushes out: joined_start_depth). What they explain: per part of the
    step (the whole step unless it was split at a time of impact), its length times the
    largest speed the body had in it, max(|v_start|, |v_end|) for the last part
    (ws.path_explained[:, 0]: start_path, add_part_path, finish_path). Symplectic Euler moves a body by h |v_end|; a longer move is the position
    correction's: a correction larger than the violation it corrects (a body turning by
    h w ~ 1 rad in the step, a rod or a normal that turned within it), or a body driven deep
    into the ground within the step and pushed out (a shape turning through a hill).
    Recorded: body, a contact touching it (_touching_contact), the distance, what its
    velocities explain, the allowance. O(bodies) per step; depths are measured only for a
    body beyond the first bound."""
    return check_moves(m, s, ws, ws.prev.q, False, slack)


@kernel(inline="always")
def _moved(q, start_q, i, dx, dy):
    """How far [m] body i's centre of mass is at q from start_q, less the frame's move
    (dx, dy) [m] (frame.frame_displacement)."""
    ux = q[i, 0] - start_q[i, 0] - dx
    uy = q[i, 1] - start_q[i, 1] - dy
    return math.sqrt(ux * ux + uy * uy)


@kernel
def check_moves(m, s, ws, start_q, whole, slack):
    """check_displacements from positions start_q: over the step's last part (whole False:
    ws.path_explained[:, 0], from ws.prev) or over a step taken in sub-steps (whole True:
    their summed paths, ws.step_path, from the step's start)."""
    dx, dy = frame_displacement(m, ws, s.q, start_q)
    for i in range(s.q.shape[0]):
        moved = _moved(s.q, start_q, i, dx, dy)
        explained = ws.step_path[i] if whole else ws.path_explained[i, 0]
        if not moved > explained + slack:
            continue
        allowed = slack + joined_start_depth(m, ws, start_q, i)
        if moved > explained + allowed:
            ws.info[INFO_GUARD_BODY] = i
            ws.info[INFO_GUARD_FIELD] = _touching_contact(m, s, ws, i)
            ws.guard_value[0] = moved
            ws.guard_value[1] = explained
            ws.guard_value[2] = allowed
            return GUARD_JUMP
    return GUARD_OK
