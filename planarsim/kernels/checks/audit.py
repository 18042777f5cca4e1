"""Stage 7: the step audits its own answer and counts what breaks the rules (ws.audit); the
positions' rules at the end of stage 8.

After the velocity stage (impulses as applied):
  pull      a contact's normal impulse pulls (lambda_n < 0)
  cone      friction outside its cone (|lambda_t| > mu lambda_n)
            (both beyond rounding: IMPULSE_REL_TOL of the contact's own impulse plus
            IMPULSE_FLOOR of the step's largest, in each component: (mu + max(mu, 1))
            times that for the cone, which a sliding contact's friction -mu s lambda_n
            moves by 2 mu times its lambda_n's rounding)
  work      a contact's impulse does positive work at the step's end velocity
            (lambda_n v_n + lambda_t v_t > 0: it would add energy) beyond rounding: more
            than |lambda| (WORK_REL_TOL |v| + VELOCITY_FLOOR), |v| the contact's speed, free
            and constrained, and the fastest body's
  joint_work  the pins' and rods' impulses add more kinetic energy than their second-order
            terms may (kernels/checks/work.joints_add_energy), even after the step
            aimed them at J v = 0 (the step's own remedy, kernels/step.py)
  limit_work  a joint limit's impulse does positive work at the end velocity beyond rounding
  joint_friction  a joint's dry friction outside its bound (|p| > F h) or pushing the motion
            (p g v_new > 0, or a slipping joint's rate reversed against its friction) beyond
            rounding (kernels/constraints/joint_friction.py)
After the position stage (the configuration the step ends at):
  pin_gap   a pin joint open, or a rod's length off, by more than PIN_GAP_TOL
  depth     a contact point below the ground, or two shapes overlapping, by more than
            DEPTH_TOL
  limit_gap a joint outside its limit by more than PIN_GAP_TOL [rad or m]
  correction_work  the position correction or projection added energy (kinetic, less the
            applied forces' work along its move) beyond what bound_correction_work allows
            (kernels/dynamics/integrate.py): rounding only, once it has bounded its velocity change
And of the solver itself:
  fallback  the complementarity solve with friction found no answer and the frictionless
            rule was used (it can only remove energy)
  unsolved  no consistent answer at all (impulses left as the last solve gave them)
Each count is cumulative over the workspace's life; ws.audit_last holds the step, kind, the
contact or pin, and the body of the last violation, ws.audit_value its size. With
StepOptions.audit_raise = 1 a violation ends the step with GUARD_AUDIT, which
planarsim.errors.diverged turns into an AuditViolation naming all of it.
"""
import math

from ...compile import kernel
from ..info import INFO_CCD_SPLITS
from ..codes import CONTACT_ARC, CONTACT_EDGE, CONTACT_PAIR, CONTACT_POINT, ROW_ROD
from ..geometry.contacts import contact_velocity, edge_deepest, point_reach, sole_facing
from ..math2d import world_point
from ..geometry.broad_phase import sweep_pairs
from ..geometry.pair import pair_gap_now, place_shapes
from ..constraints.rows import is_limit_row, is_normal_row
from ..constraints.joint_friction import (FRICTION_REL_TOL, friction_rate, is_joint_friction_row,
                                          slip_reversed)
from ..constraints.joints import is_free_joint, is_slider
from ..constraints.limit import limit_overshoot
from ..constraints.slider import slider_gap
from ..geometry.terrain import ground_point
from .work import (VELOCITY_FLOOR, WORK_REL_TOL, fastest, joints_add_energy, judge_energy,
                   limit_work)

AUDIT_PULL = 0
AUDIT_CONE = 1
AUDIT_WORK = 2
AUDIT_PIN_GAP = 3
AUDIT_DEPTH = 4
AUDIT_FALLBACK = 5
AUDIT_UNSOLVED = 6
AUDIT_JOINT_WORK = 7
AUDIT_LIMIT_WORK = 8
AUDIT_CORRECTION_WORK = 9
AUDIT_JOINT_FRICTION = 10
AUDIT_LIMIT_GAP = 11
N_AUDIT = 12
AUDIT_NAMES = ("pull", "cone", "work", "pin_gap", "depth", "fallback", "unsolved",
               "joint_work", "limit_work", "correction_work", "joint_friction", "limit_gap")

PIN_GAP_TOL = 1e-9       # [m]
DEPTH_TOL = 1e-8         # [m]
# impulses and work are judged relative to their own size (rounding of the solve)
IMPULSE_REL_TOL = 1e-8
# ... and an impulse below this share of the step's largest contact impulse is rounding: a
# statically indeterminate contact (a box resting on two boxes) carries none, and the solve
# leaves it about 1e-16 of the load, of either sign
IMPULSE_FLOOR = 1e-10


@kernel
def audit_total(ws):
    """All violations counted so far."""
    total = 0
    for k in range(ws.audit.shape[0]):
        total += ws.audit[k]
    return total


@kernel
def note(ws, step, kind, who, body, value):
    """Count one violation of `kind` and remember it."""
    ws.audit[kind] += 1
    ws.audit_last[0] = step
    ws.audit_last[1] = kind
    ws.audit_last[2] = who
    ws.audit_last[3] = body
    ws.audit_value[0] = value
    if (kind == AUDIT_PIN_GAP or kind == AUDIT_DEPTH or kind == AUDIT_LIMIT_GAP) and value > ws.audit_worst_value[0]:
        ws.audit_worst[0] = step
        ws.audit_worst[1] = kind
        ws.audit_worst[2] = who
        ws.audit_worst[3] = body
        ws.audit_worst_value[0] = value


@kernel
def _impulse_floor(ws):
    """IMPULSE_FLOOR of the step's largest normal contact impulse [N s]."""
    largest = 0.0
    for k in range(ws.n_live[0]):
        largest = max(largest, abs(ws.contact_impulse[ws.live[k], 0]))
    return IMPULSE_FLOOR * largest


@kernel
def _speed_scale(ws):
    """The largest |v_x| + |v_y| [m/s] of any body, free or constrained, in the step."""
    top = 0.0
    for b in range(ws.v_new.shape[0]):
        top = max(top, abs(ws.v_new[b, 0]) + abs(ws.v_new[b, 1]),
                  abs(ws.v_pred[b, 0]) + abs(ws.v_pred[b, 1]))
    return top


@kernel
def audit_impulses(m, s, ws, opt, h):
    """Pulling contacts, friction outside its cone and positive contact work, from
    ws.contact_impulse and the constrained velocity ws.v_new. Returns the violations found."""
    found = 0
    step = s.step[0]
    floor = -1.0        # IMPULSE_FLOOR of the largest impulse, found when first needed
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        ln = ws.contact_impulse[i, 0]
        lt = ws.contact_impulse[i, 1]
        if ln == 0.0 and lt == 0.0:
            continue
        size = abs(ln) + abs(lt)
        b = m.contact_body[i]
        if ln < -IMPULSE_REL_TOL * size or abs(lt) > m.contact_mu[i] * ln + IMPULSE_REL_TOL * size:
            if floor < 0.0:
                floor = _impulse_floor(ws)
            if ln < -(IMPULSE_REL_TOL * size + floor):
                note(ws, step, AUDIT_PULL, i, b, ln)
                found += 1
        # each component's rounding moves |lambda_t| - mu lambda_n by (1 + mu) times it, and
        # a sliding contact's friction -mu s lambda_n follows its lambda_n: 2 mu times it. So a
        # sliding contact whose lambda_n rounds below zero, within the pull rule, is on its cone
        mu = m.contact_mu[i]
        if abs(lt) > mu * ln + (mu + max(mu, 1.0)) * (IMPULSE_REL_TOL * size + max(floor, 0.0)):
            note(ws, step, AUDIT_CONE, i, b, abs(lt) - mu * ln)
            found += 1
        vn, vt = contact_velocity(m, s, ws, i, ws.v_new)
        # restitution's rebound (at most e times the approach speed) and a held contact's
        # second-order target (solve.held_contact_curve) are work it may do
        work = ln * (vn - ws.contact_bounce[i] - ws.contact_curve[i]) + lt * vt
        scale = WORK_REL_TOL * (abs(vn) + abs(vt)) + VELOCITY_FLOOR
        if work > size * scale and floor < 0.0:
            floor = _impulse_floor(ws)
        # an impulse of rounding size (below the floor) does rounding work at any speed
        if work > size * scale + max(floor, 0.0) * (abs(vn) + abs(vt)):
            # the tolerance also scales with the free motion's speed (computed only here)
            vp_n, vp_t = contact_velocity(m, s, ws, i, ws.v_pred)
            # ... and with the fastest body's (a resting contact under a falling pile: the
            # solve's rounding is relative to the largest velocities it handles)
            if work > (size * (scale + WORK_REL_TOL * (abs(vp_n) + abs(vp_t) + _speed_scale(ws)))
                       + max(floor, 0.0) * (abs(vn) + abs(vt))):
                note(ws, step, AUDIT_WORK, i, b, work)
                found += 1
    return found + audit_joints(m, s, ws, opt, h)


@kernel
def joint_element(m, ws, r):
    """The audit's element of joint or limit row r: pin j, or n_pin + j for rod j."""
    if ws.row_kind[r] == ROW_ROD:
        return m.pin_body.shape[0] + ws.row_owner[r]
    return ws.row_owner[r]


@kernel
def audit_joint_friction(m, s, ws):
    """Joints' dry friction outside its bound F h, or pushing the motion at the end velocity
    (a stuck row's impulse doing positive work beyond rounding, a slipping joint's rate
    reversed against its friction); returns how many."""
    found = 0
    step = s.step[0]
    for r in range(ws.n_row[0]):
        if not is_joint_friction_row(ws.row_kind[r]):
            continue
        j = ws.row_owner[r]
        bound = ws.friction_bound[j]
        lam = ws.lam[r]
        rate = friction_rate(m, ws, j, ws.v_new)
        free = friction_rate(m, ws, j, ws.v_pred)
        over = abs(lam) - bound
        work = lam * rate
        if over > FRICTION_REL_TOL * bound:
            note(ws, step, AUDIT_JOINT_FRICTION, j, m.pin_body[j, 1], over)
            found += 1
        elif work > abs(lam) * (WORK_REL_TOL * (abs(rate) + abs(free)) + VELOCITY_FLOOR):
            note(ws, step, AUDIT_JOINT_FRICTION, j, m.pin_body[j, 1], work)
            found += 1
    for j in range(m.pin_body.shape[0]):
        if ws.friction_slip[j] != 0.0 and slip_reversed(m, ws, j):
            note(ws, step, AUDIT_JOINT_FRICTION, j, m.pin_body[j, 1],
                 ws.friction_bound[j] * abs(friction_rate(m, ws, j, ws.v_new)))
            found += 1
    return found


@kernel
def audit_joints(m, s, ws, opt, h):
    """Joint limits whose impulse does positive work at the end velocity, and joints whose
    impulses added energy (work.joints_add_energy), beyond rounding; returns how many."""
    found = audit_joint_friction(m, s, ws)
    step = s.step[0]
    speed = -1.0
    for r in range(ws.n_row[0]):
        if not is_limit_row(ws.row_kind[r]):
            continue
        if speed < 0.0:
            speed = fastest(ws.v_new) + fastest(ws.v_pred)
        work, rounding = limit_work(ws, r, speed)
        if work > rounding:
            note(ws, step, AUDIT_LIMIT_WORK, ws.row_owner[r], ws.row_body[r, 1], work)
            found += 1
    if m.pin_body.shape[0] + m.rod_body.shape[0] > 0:
        if ws.joint_gain[2] == 1.0:
            # measured by the step for this very answer (step.second_order_gains)
            excess = ws.joint_gain[0]
            r = int(ws.joint_gain[1])
        else:
            excess, r = joints_add_energy(m, s, ws, h)
        if excess > 0.0 and r >= 0:
            note(ws, step, AUDIT_JOINT_WORK, joint_element(m, ws, r), ws.row_body[r, 1], excess)
            judge_energy(m, ws, opt, h, excess)
            found += 1
    return found


@kernel
def anchor_distance(q, cs, bodies, anchors, j):
    """Distance [m] between the two anchors of joint j (bodies (n, 2), anchors (n, 2, 2) in
    the bodies' frames) at configuration q."""
    ax, ay = world_point(q, cs, bodies[j, 0], anchors[j, 0, 0], anchors[j, 0, 1])
    bx, by = world_point(q, cs, bodies[j, 1], anchors[j, 1, 0], anchors[j, 1, 1])
    return math.sqrt((bx - ax) ** 2 + (by - ay) ** 2)


@kernel
def pin_gap(m, q, cs, j):
    """Distance [m] between the two anchors of pin j at configuration q (a slider: its anchor
    b's distance from its axis line; 0 for a free body's coordinate, which holds nothing)."""
    if is_free_joint(m, j):
        return 0.0
    if is_slider(m, j):
        return slider_gap(m, q, cs, j)
    return anchor_distance(q, cs, m.pin_body, m.pin_anchor, j)


@kernel
def rod_error(m, q, cs, j):
    """|distance - length| [m] of rod j's anchors at configuration q."""
    return abs(anchor_distance(q, cs, m.rod_body, m.rod_anchor, j) - m.rod_length[j])


@kernel
def point_gap(m, q, cs, b, lx, ly):
    px, py = world_point(q, cs, b, lx, ly)
    gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
    return gap


@kernel
def contact_gap(m, q, cs, i):
    """Signed gap [m] of contact i at configuration q: its point (a point contact), or the
    lowest of its sole, arc ends and fallback vertices (an arc contact)."""
    b = m.contact_body[i]
    lx = m.contact_local[i, 0]
    ly = m.contact_local[i, 1]
    if m.contact_kind[i] == CONTACT_POINT:
        return point_gap(m, q, cs, b, lx, ly)
    if m.contact_kind[i] == CONTACT_EDGE:
        inside, px, py = edge_deepest(m, q, cs, i)
        if not inside:
            return math.inf     # the ends are lowest: their own contacts are measured
        gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
        return gap - m.contact_radius[i]
    r = m.contact_radius[i]
    cx, cy = world_point(q, cs, b, lx, ly)
    gx, gy, nx, ny, cgap = ground_point(m.terrain_coef, cx, cy)
    in_span, dlx, dly = sole_facing(m, cs, b, i, nx, ny)
    best = cgap - r if in_span else math.inf
    for e in range(2):
        ang = m.contact_span[i, e]
        best = min(best, point_gap(m, q, cs, b, lx + r * math.cos(ang), ly + r * math.sin(ang)))
    adr = m.contact_vert_adr[i]
    for k in range(adr, adr + m.contact_vert_num[i]):
        best = min(best, point_gap(m, q, cs, b, m.vert_local[k, 0], m.vert_local[k, 1]))
    return best


@kernel(inline="never")
def contact_depth(m, s, ws, i):
    """How far [m] contact i is below the ground, or a shape pair's shapes overlap, at s.q
    (ws.body_cs current); negative: clear by that much."""
    if m.contact_kind[i] == CONTACT_PAIR:
        return -pair_gap_now(m, s.q, ws.body_cs, ws, i)
    return -contact_gap(m, s.q, ws.body_cs, i)


@kernel
def _audit_depth(m, s, ws, step, i):
    """Contact i (enabled) deeper than DEPTH_TOL: noted; returns 1 if so, else 0."""
    if s.contact_enabled[i] == 0:
        return 0
    d = contact_depth(m, s, ws, i)
    if d > DEPTH_TOL:
        note(ws, step, AUDIT_DEPTH, i, m.contact_body[i], d)
        return 1
    return 0


@kernel
def near_pairs(m, s, ws):
    """The pairs (slot-0 contacts) whose shapes' bounding circles touch or overlap at s.q, in
    ws.sweep_pairs (the shapes placed there; kernels/geometry/broad_phase.py); returns how many (0
    without shapes). Every other pair is apart: its depth is negative, nothing to audit."""
    if m.n_shape_pair == 0:
        return 0
    place_shapes(m, s.q, ws.body_cs, s.v, s.v, ws)
    return sweep_pairs(ws, 0.0, 0.0, ws.sweep_pairs)

@kernel
def foot_radius(m, i):
    """The farthest [m] a material point of arc contact i's foot lies from its body's COM:
    |centre| + r (its arc), or a fallback vertex's distance where farther."""
    cx = m.contact_local[i, 0]
    cy = m.contact_local[i, 1]
    far = math.sqrt(cx * cx + cy * cy) + m.contact_radius[i]
    adr = m.contact_vert_adr[i]
    for k in range(adr, adr + m.contact_vert_num[i]):
        far = max(far, math.sqrt(m.vert_local[k, 0] ** 2 + m.vert_local[k, 1] ** 2))
    return far


@kernel
def surely_clear(m, s, ws, i):
    """Contact i cannot be below the ground at s.q: its gap at the start of the step
    (ws.contact_gap, found at ws.prev.q or a lower bound of it; no time-of-impact split)
    exceeds how far its points can have moved since (contacts.point_reach; the signed
    distance to the ground changes by at most a point's move). A point contact's point; an
    arc contact's every point (foot_radius from the COM) on flat or sloped ground, where its
    gap at the start is the lowest of its material points' (its sole's lowest point, arc
    ends, vertices) and so is contact_gap's at s.q. Saves the ground query of contacts well
    clear of it."""
    if ws.info[INFO_CCD_SPLITS] != 0:
        return False
    b = m.contact_body[i]
    if m.contact_kind[i] == CONTACT_POINT:
        reach = point_reach(s.q, b, ws.prev.q[b, 0], ws.prev.q[b, 1], ws.prev.q[b, 2],
                            m.contact_local[i, 0], m.contact_local[i, 1])
        return ws.contact_gap[i] > reach
    if m.contact_kind[i] != CONTACT_ARC or m.terrain_coef[2] != 0.0:
        return False
    reach = (abs(s.q[b, 0] - ws.prev.q[b, 0]) + abs(s.q[b, 1] - ws.prev.q[b, 1])
             + abs(s.q[b, 2] - ws.prev.q[b, 2]) * foot_radius(m, i))
    return ws.contact_gap[i] > reach


@kernel
def vertices_within_arc(m, i):
    """Every fallback vertex of arc contact i lies inside its circle (with a margin far above
    rounding): then on flat or sloped ground no part of the foot is lower than the circle's
    lowest point (the arc's ends lie on the circle)."""
    r = m.contact_radius[i]
    cx = m.contact_local[i, 0]
    cy = m.contact_local[i, 1]
    adr = m.contact_vert_adr[i]
    for k in range(adr, adr + m.contact_vert_num[i]):
        dx = m.vert_local[k, 0] - cx
        dy = m.vert_local[k, 1] - cy
        if dx * dx + dy * dy > (1.0 - 1e-9) * r * r:
            return False
    return True


@kernel
def held_row_is_depth(m, ws, i):
    """Contact i's normal row bounds its depth when held: a point contact's row is its
    point's gap; an arc contact's row on the sole is the circle's gap (centre's gap - r), a
    bound on the whole foot's when its vertices lie inside the circle (vertices_within_arc).
    Flat or sloped ground (rows_held implies it)."""
    if m.contact_kind[i] == CONTACT_POINT:
        return True
    if m.contact_kind[i] == CONTACT_PAIR or m.contact_kind[i] == CONTACT_EDGE:
        return False    # other features, or another point of the edge, may touch
    return ws.contact_on_arc[i] == 1 and vertices_within_arc(m, i)


@kernel
def depth_known(m, s, ws, i, bounded, rows_held):
    """Contact i's depth needs no ground query: it is disabled, or (rows_held) its normal row
    was held by the position correction (ws.contact_held) and bounds its depth
    (held_row_is_depth), or (bounded) it is surely clear of the ground."""
    if s.contact_enabled[i] == 0:
        return True
    if rows_held and ws.contact_held[i] == 1 and held_row_is_depth(m, ws, i):
        return True
    return bounded and surely_clear(m, s, ws, i)


@kernel
def needs_ground_query(m, s, ws):
    """Some contact's depth needs a ground query after a correction that held its rows
    (depth_known, bounded; ws.contact_held marked): otherwise worst_violation would find
    nothing."""
    for k in range(ws.ground_contacts.shape[0]):
        if not depth_known(m, s, ws, ws.ground_contacts[k], True, True):
            return True
    for k in range(near_pairs(m, s, ws)):
        if s.contact_enabled[ws.sweep_pairs[k]] == 1:
            return True
    return False


@kernel(inline="never")
def worst_violation(m, s, ws, bounded, rows_held):
    """Largest pin gap and largest depth below the ground [m] of enabled contacts at the
    current configuration (ws.body_cs must match s.q). bounded: skip point contacts that
    are surely clear (valid while ws.contact_gap is the start of the step's). rows_held: the
    position correction proved every row it kept within PIN_GAP_TOL / 10 (flat or sloped
    ground, where a point contact's row is its exact gap): skip the joints, and the contacts
    whose normal row it kept (ws.contact_held) where that row bounds the depth."""
    gap = 0.0
    if not rows_held:
        for j in range(m.pin_body.shape[0]):
            gap = max(gap, pin_gap(m, s.q, ws.body_cs, j))
        for j in range(m.rod_body.shape[0]):
            gap = max(gap, rod_error(m, s.q, ws.body_cs, j))
    depth = 0.0
    for k in range(ws.ground_contacts.shape[0]):
        i = ws.ground_contacts[k]
        if not depth_known(m, s, ws, i, bounded, rows_held):
            depth = max(depth, contact_depth(m, s, ws, i))
    for k in range(near_pairs(m, s, ws)):
        i = ws.sweep_pairs[k]
        if s.contact_enabled[i] == 1:
            depth = max(depth, contact_depth(m, s, ws, i))
    return gap, depth


@kernel
def worst_limit_overshoot(m, s, ws):
    """The largest distance [rad or m] of a joint outside its limit at s.q (0: none; ws.body_cs
    must match s.q where a slider has a limit)."""
    worst = 0.0
    for j in range(m.pin_body.shape[0]):
        worst = max(worst, limit_overshoot(m, s.q, ws.body_cs, s.v, j))
    return worst


@kernel
def mark_held_contacts(m, ws):
    """ws.contact_held[i] = 1 if contact i's normal row is among the rows 0..n_row-1."""
    for k in range(ws.n_live[0]):
        ws.contact_held[ws.live[k]] = 0
    for r in range(ws.n_row[0]):
        if is_normal_row(ws.row_kind[r]):
            ws.contact_held[ws.row_owner[r]] = 1


@kernel
def audit_positions(m, s, ws, step):
    """Pins open by more than PIN_GAP_TOL, joints outside their limits by more than
    PIN_GAP_TOL and contacts deeper than DEPTH_TOL at the current configuration; returns the
    violations found."""
    found = 0
    for j in range(m.pin_body.shape[0]):
        g = pin_gap(m, s.q, ws.body_cs, j)
        if g > PIN_GAP_TOL:
            note(ws, step, AUDIT_PIN_GAP, j, m.pin_body[j, 1], g)
            found += 1
    n_pin = m.pin_body.shape[0]
    for j in range(m.rod_body.shape[0]):
        g = rod_error(m, s.q, ws.body_cs, j)
        if g > PIN_GAP_TOL:
            note(ws, step, AUDIT_PIN_GAP, n_pin + j, m.rod_body[j, 1], g)
            found += 1
    for j in range(m.pin_body.shape[0]):
        g = limit_overshoot(m, s.q, ws.body_cs, s.v, j)
        if g > PIN_GAP_TOL:
            note(ws, step, AUDIT_LIMIT_GAP, j, m.pin_body[j, 1], g)
            found += 1
    for k in range(ws.ground_contacts.shape[0]):
        found += _audit_depth(m, s, ws, step, ws.ground_contacts[k])
    for k in range(near_pairs(m, s, ws)):
        found += _audit_depth(m, s, ws, step, ws.sweep_pairs[k])
    return found


def audit_counts(ws) -> dict:
    """{rule: violations counted} of a workspace (Python side; for summaries)."""
    return {name: int(ws.audit[k]) for k, name in enumerate(AUDIT_NAMES)}
