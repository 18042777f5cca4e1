"""Stage 3: the active rows (constraint rows J and position errors c), and the one dispatch on
a row's kind.

Row kinds: pin x / y (p_b - p_a = 0), slider (n.(p_b - p_a) = 0 and theta_b - theta_a - ref
= 0), rod (|p_b - p_a| - L = 0), joint limit (coordinate - lower >= 0, upper - coordinate >= 0),
a joint's soft row (armature and implicit spring-damper, a compliant equality), contact normal
(n.(p - g) = 0) and tangent (t.(p - g) = 0); a shape pair's contact rows act on both its bodies.

Each kind of constraint has its own module that evaluates its rows: pin.py (two equalities,
ROW_PIN_X / ROW_PIN_Y), slider.py (ROW_SLIDE_PERP / ROW_SLIDE_ANGLE), rod.py (ROW_ROD),
limit.py (ROW_LIMIT_LO / ROW_LIMIT_HI, inequalities on a joint's coordinate: a hinge's angle,
a slider's slide), joint_friction.py (ROW_JOINT_FRICTION, a stuck joint's dry friction: its
rate held, its impulse within +-F h), soft.py (ROW_JOINT_SOFT, a joint coordinate's armature and implicit
spring-damper: an equality with a compliance), contacts.py (a ground contact's normal and
tangent rows) and pair.py (a shape pair's, acting on both bodies). This module is the one place
that dispatches on the kind (eval_row, row_lever, last_impulse, store_joint_impulse) and names
the kinds' classes (is_joint_row, is_mode_row, is_unilateral, ...): nothing else compares row
codes or relies on their order. Adding a kind = its module, one arm in each dispatch here, a
builder method.

A row along unit direction d at point p of a body with COM x has J = (d_x, d_y, (p - x) x d).
A contact's normal row uses the exact gap (a rolling sole: the gap of its centre minus r, which
rotation leaves unchanged); its tangent row holds the material point at the ground point found
at the start of the step (no slip). Sliding contacts keep only the normal row; their impulse
direction F = n - mu s t carries the Coulomb friction -mu lambda_n s along the tangent t.
"""
import math

from ...compile import kernel
from ..codes import (CONTACT_EDGE, CONTACT_PAIR, MODE_FREE, MODE_PINNED, MODE_SLIDING,
                     ROW_CONTACT_N, ROW_CONTACT_T, ROW_JOINT_SOFT, ROW_LIMIT_HI, ROW_LIMIT_LO,
                     ROW_PIN_X, ROW_PIN_Y, ROW_ROD, ROW_SLIDE_ANGLE, ROW_SLIDE_PERP)
from .joints import is_free_joint, is_slider, joint_rate_row
from .joint_friction import add_friction_row, friction_row, is_joint_friction_row
from ..geometry.contacts import ground_lever, ground_row, ground_second_order
from .limit import add_limit_rows, limit_row, limit_side
from ..math2d import set_dir, world_point
from ..geometry.pair import pair_row
from .pin import add_pin_rows, pin_axis, pin_lever, pin_row, pin_rows
from .rod import add_rod_row, rod_row
from .row_list import add_row
from .slider import add_slider_rows, slider_angle_row, slider_lever, slider_perp_row
from .soft import add_soft_row, soft_row, start_soft_row


@kernel
def is_joint_row(kind):
    """An equality of a joint (pin x / y, slider, rod; a joint's soft row): its impulse is
    free; its error always held (but a soft row's, which is a compliant velocity equation)."""
    return (kind == ROW_PIN_X or kind == ROW_PIN_Y or kind == ROW_ROD or kind == ROW_SLIDE_PERP
            or kind == ROW_SLIDE_ANGLE or kind == ROW_JOINT_SOFT)


@kernel
def is_soft_row(kind):
    """A joint coordinate's soft row (armature, implicit spring-damper; soft.py): an equality
    with a compliance on its diagonal and no position error to hold."""
    return kind == ROW_JOINT_SOFT


@kernel
def is_angular_row(m, ws, r):
    """Row r constrains an angle only (a hinge's limit, a slider's angle row): its error is
    linear in the bodies' angles."""
    kind = ws.row_kind[r]
    if kind == ROW_SLIDE_ANGLE:
        return True
    return is_limit_row(kind) and not is_slider(m, ws.row_owner[r])


@kernel
def is_mode_row(kind):
    """A row with a rule a solve can break (a joint limit, a contact's normal or tangent)."""
    return not is_joint_row(kind)


@kernel
def is_limit_row(kind):
    """A joint limit's row (either side)."""
    return kind == ROW_LIMIT_LO or kind == ROW_LIMIT_HI


@kernel
def is_normal_row(kind):
    """A contact's normal row (its impulse pushes; a ground or a shape contact)."""
    return kind == ROW_CONTACT_N


@kernel
def is_tangent_row(kind):
    """A sticking contact's tangent (friction) row; it follows its normal row."""
    return kind == ROW_CONTACT_T


@kernel
def is_contact_row(kind):
    """A contact's normal or tangent row."""
    return kind == ROW_CONTACT_N or kind == ROW_CONTACT_T


@kernel
def is_unilateral(kind):
    """Contact normal and joint-limit rows: their impulses only push, their corrections
    remove overlap, not velocity."""
    return is_normal_row(kind) or is_limit_row(kind)


@kernel
def has_mode_rows(ws, n):
    """Some row among 0..n-1 belongs to a contact or a joint limit (whose rule a solve can
    break); otherwise the rows are joints only."""
    for r in range(n):
        if is_mode_row(ws.row_kind[r]):
            return True
    return False


@kernel
def eval_row(m, q, cs, ws, r, J, found):
    """Jacobian blocks J (2, 3) and error c of row r at configuration q (cs: its cos / sin,
    math2d.update_trig); returns c. found: the contacts' ground points, normals and gaps in ws
    were found at this q (stage 2), so a normal row reuses them instead of asking the
    terrain again (the same numbers)."""
    kind = ws.row_kind[r]
    o = ws.row_owner[r]
    a = ws.row_body[r, 0]
    b = ws.row_body[r, 1]
    if kind == ROW_PIN_X or kind == ROW_PIN_Y:
        return pin_row(m, q, cs, o, a, b, pin_axis(kind), J)
    if kind == ROW_ROD:
        return rod_row(m, q, cs, o, a, b, J)
    if kind == ROW_SLIDE_PERP:
        return slider_perp_row(m, q, cs, o, a, b, J)
    if kind == ROW_SLIDE_ANGLE:
        return slider_angle_row(m, q, o, a, b, J)
    if kind == ROW_JOINT_SOFT:
        return soft_row(m, q, cs, o, J)
    if is_joint_friction_row(kind):
        return friction_row(m, q, cs, o, J)
    if is_limit_row(kind):
        if is_slider(m, o):
            return slide_limit_row(m, q, cs, o, limit_side(kind), J)
        return limit_row(m, q, o, a, b, limit_side(kind), J)
    if m.contact_kind[o] == CONTACT_PAIR:
        return pair_row(q, cs, ws, o, J, kind == ROW_CONTACT_T)
    return ground_row(m, q, cs, ws, o, b, kind == ROW_CONTACT_T, J, found)


@kernel
def slide_limit_row(m, q, cs, o, side, J):
    """Jacobian blocks J (2, 3) and error [m] (distance inside the limit) of slider o's limit
    row on `side` (0: s - lower >= 0, 1: upper - s >= 0)."""
    x = joint_rate_row(m, q, cs, o, J)
    if side == 0:
        return x - m.pin_limit[o, 0]
    for e in range(2):
        for k in range(3):
            J[e, k] = -J[e, k]
    return m.pin_limit[o, 1] - x


@kernel
def row_lever(m, ws, r, e):
    """An upper bound |x| + |y| [m] on the distance from its body's COM of the point whose
    motion row r constrains on body slot e (a pin's anchor, a contact's material point or its
    sole's centre); no square root. inf where no such bound holds (a shape pair's face turns
    with its body; a rod's direction turns), 0 for a limit (angular)."""
    kind = ws.row_kind[r]
    o = ws.row_owner[r]
    if kind == ROW_PIN_X or kind == ROW_PIN_Y:
        return pin_lever(m, o, e)
    if kind == ROW_SLIDE_ANGLE:
        return 0.0
    if kind == ROW_SLIDE_PERP:
        return slider_lever(m, o, e)
    if is_limit_row(kind) or is_joint_friction_row(kind):
        return slider_lever(m, o, e) if is_slider(m, o) else 0.0
    if is_contact_row(kind):
        if m.contact_kind[o] == CONTACT_PAIR:
            return math.inf
        return ground_lever(m, ws, o, kind == ROW_CONTACT_T)
    return math.inf


@kernel(inline="always")
def dependent_bit(kind):
    """The bit of State.contact_dependent that a row of `kind` stands for: 1 a contact's
    normal row, 2 its friction row, 0 any other row."""
    if kind == ROW_CONTACT_N:
        return 1
    if kind == ROW_CONTACT_T:
        return 2
    return 0


@kernel
def last_impulse(s, ws, r):
    """Row r's impulse in the last step (State.last_*_impulse; 0 where it had none). A sliding
    contact's single row (impulse lambda_n along n - mu s t) starts at lambda_n."""
    o = ws.row_owner[r]
    kind = ws.row_kind[r]
    if kind == ROW_CONTACT_N:
        return s.last_contact_impulse[o, 0]
    if kind == ROW_CONTACT_T:
        return s.last_contact_impulse[o, 1]
    table, o, col = joint_impulse_slot(ws, r)
    if table == 0:
        return s.last_pin_impulse[o, col]
    if table == 1:
        return s.last_rod_impulse[o]
    return 0.0


@kernel(inline="always")
def joint_impulse_slot(ws, r):
    """Where row r's impulse is kept: (table, owner, column), table 0 for the pins' (State.
    last_pin_impulse's layout: pins, sliders, limits), 1 for the rods' (column 0), -1 for a
    row whose impulse is kept per contact (modes.gather_contact_impulses) or not at all (a
    soft row)."""
    o = ws.row_owner[r]
    kind = ws.row_kind[r]
    if kind == ROW_PIN_X or kind == ROW_PIN_Y:
        return 0, o, pin_axis(kind)
    if kind == ROW_SLIDE_PERP:
        return 0, o, 0
    if kind == ROW_SLIDE_ANGLE:
        return 0, o, 1
    if is_limit_row(kind):
        return 0, o, 2 + limit_side(kind)
    if kind == ROW_ROD:
        return 1, o, 0
    return -1, o, 0


@kernel
def add_joint_impulse(pins, rods, ws, r, lam, add):
    """Joint row r's impulse lam [N s or N m s] into its slot (joint_impulse_slot) of pins
    (n_pin, 4) and rods (n_rod,): added to it (add) or in place of it."""
    table, o, col = joint_impulse_slot(ws, r)
    if table == 0:
        pins[o, col] = pins[o, col] + lam if add else lam
    elif table == 1:
        rods[o] = rods[o] + lam if add else lam


@kernel
def store_joint_impulse(s, ws, r, lam):
    """Joint row r's impulse lam [N s] into the State (pins, sliders, limits, rods; a contact's
    are gathered per contact, modes.gather_contact_impulses; a soft row's is not kept)."""
    add_joint_impulse(s.last_pin_impulse, s.last_rod_impulse, ws, r, lam, False)


@kernel(inline="never")
def eval_rows(m, q, cs, ws, J, c, n, found):
    """J[r] and c[r] of rows 0..n-1 at configuration q (cs holds its cos / sin; found: see
    eval_row). A pin's x row is always followed by its y row (build_rows), so both come from
    one evaluation."""
    r = 0
    while r < n:
        if ws.row_kind[r] == ROW_PIN_X:
            pin_rows(q, cs, m.pin_anchor, ws.row_owner[r], ws.row_body[r, 0],
                     ws.row_body[r, 1], J, c, r)
            r += 2
        else:
            c[r] = eval_row(m, q, cs, ws, r, J[r], found)
            r += 1


@kernel
def predict_joint_errors(m, ws, n):
    """row_c_pred[r] = c(q_pred) of the pin, slider and rod rows (the velocity solve's target);
    contact, limit and soft rows are left alone (row_Jp is scratch here)."""
    r = 0
    while r < n:
        kind = ws.row_kind[r]
        if kind == ROW_PIN_X:
            pin_rows(ws.q_pred, ws.cs_pred, m.pin_anchor, ws.row_owner[r], ws.row_body[r, 0],
                     ws.row_body[r, 1], ws.row_Jp, ws.row_c_pred, r)
            r += 2
            continue
        if kind == ROW_ROD or kind == ROW_SLIDE_PERP or kind == ROW_SLIDE_ANGLE:
            ws.row_c_pred[r] = eval_row(m, ws.q_pred, ws.cs_pred, ws, r, ws.row_Jp[r], False)
        r += 1


# [m] a contact free at the step's start but within this of its surface is held through the
# step (held_contact), unless its start velocity approaches the surface (an impact)
HELD_GAP = 1e-9


@kernel(inline="always")
def held_contact(m, ws, i):
    """Ground contact i may be held through the step: touching at its start (its mode then
    not free) or within HELD_GAP [m] of its surface (solve.held_contact_curve adds: and not
    approaching it). Never a straight edge over curved ground: its contact is the edge's
    deepest point, which slides along the edge as it turns, held as a material point for the
    step only (geometry/contacts.find_edge), so that point's second-order motion is not the
    edge's. Nor a pair of shapes (not yet: the second-order part of a gap between two turning
    bodies)."""
    if m.contact_kind[i] == CONTACT_EDGE or m.contact_kind[i] == CONTACT_PAIR:
        return False
    return ws.prev.contact_mode[i] != MODE_FREE or abs(ws.contact_gap[i]) <= HELD_GAP


@kernel
def predict_contact_parts(m, s, ws, n, h):
    """row_c_pred[r] of a held ground contact's normal row (held_contact): the second-order
    part of its gap over the step at the start's velocity (contacts.ground_second_order;
    solve.held_contact_curve makes it part of the target)."""
    for r in range(n):
        if is_normal_row(ws.row_kind[r]) and held_contact(m, ws, ws.row_owner[r]):
            ws.row_c_pred[r] = ground_second_order(m, s.q, ws.body_cs, s.v, ws,
                                                   ws.row_owner[r], h)


@kernel
def add_contact_rows(ws, n, i, normal, tangent):
    """Append contact i's normal row (if normal) and tangent row (if tangent) at slot n, on
    its bodies as found this step (ws.contact_bodies); returns the next free slot."""
    a = ws.contact_bodies[i, 0]
    b = ws.contact_bodies[i, 1]
    if normal:
        n = add_row(ws, n, ROW_CONTACT_N, i, a, b)
    if tangent:
        n = add_row(ws, n, ROW_CONTACT_T, i, a, b)
    return n


@kernel
def add_joint_rows(m, ws, n, j):
    """Append joint j's equality rows at slot n (a hinge's pin rows, a slider's; none for a
    free body's coordinate); returns the next free slot."""
    if is_free_joint(m, j):
        return n
    if is_slider(m, j):
        return add_slider_rows(m, ws, n, j)
    return add_pin_rows(m, ws, n, j)


@kernel
def _later_body(bodies, j):
    """Body after which the rows of joint j (a pin or rod; bodies (n, 2)) go: the later of its
    two bodies (in a chain or tree built parent first, the child)."""
    return max(bodies[j, 0], bodies[j, 1])


@kernel(inline="never")
def build_rows(m, s, ws, h):
    """Fill the active rows at the current configuration for a step of h [s] (a joint's spring
    may be a force instead of a row: forces.spring_as_force): J, F (impulse directions) and c;
    return how many are sliding-contact rows (F != J there; none: J W F^T is symmetric).

    Rows go body by body: a pin's or slider's (and its limits' and soft row's) and a rod's
    rows after the later of their
    two bodies, a contact's after its body, pins and rods first (a merge of the three lists in
    their model order, O(rows)). For a chain or walker built parent first every row then shares
    bodies only with rows close to it, and the solve's envelope stays narrow; contact rows
    placed after all the joints would couple every joint row to them (a dense block).
    """
    n = 0
    n_pin = m.pin_body.shape[0]
    n_rod = m.rod_body.shape[0]
    n_con = ws.n_live[0]            # (a contact off the broad phase's list is free)
    big = m.body_inv_mass.shape[0] + 1
    jp = 0
    jr = 0
    k = 0
    while jp < n_pin or jr < n_rod or k < n_con:
        ic = ws.live[k] if k < n_con else 0
        kp = _later_body(m.pin_body, jp) if jp < n_pin else big
        kr = _later_body(m.rod_body, jr) if jr < n_rod else big
        kc = max(m.contact_body[ic], m.contact_other[ic]) if k < n_con else big
        if kp <= kr and kp <= kc:
            n = add_joint_rows(m, ws, n, jp)
            n = add_limit_rows(m, s, ws, n, jp)
            n = add_soft_row(m, s, ws, n, jp, h)
            n = add_friction_row(m, ws, n, jp)
            jp += 1
        elif kr <= kc:
            n = add_rod_row(m, ws, n, jr)
            jr += 1
        else:
            k += 1
            mode = s.contact_mode[ic]
            # a frictionless contact (mu = 0) has no tangent row in any mode
            n = add_contact_rows(ws, n, ic, mode == MODE_PINNED or mode == MODE_SLIDING,
                                 mode == MODE_PINNED and m.contact_mu[ic] > 0.0)
    ws.n_row[0] = n
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_J, ws.row_c, n, True)
    predict_joint_errors(m, ws, n)
    if m.contact_body.shape[0] > 0:
        predict_contact_parts(m, s, ws, n, h)
    sliding = 0
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            start_soft_row(m, s, ws, r)
        for e in range(2):
            for k in range(3):
                ws.row_F[r, e, k] = ws.row_J[r, e, k]
        o = ws.row_owner[r]
        if (ws.row_kind[r] == ROW_CONTACT_N and s.contact_mode[o] == MODE_SLIDING
                and m.contact_mu[o] * s.contact_slip[o] != 0.0):
            sliding += 1
            # impulse lambda_n (n - mu s t): t = (n_y, -n_x); frictionless (mu s = 0): F = J
            b = ws.row_body[r, 1]
            nx = ws.contact_normal[o, 0]
            ny = ws.contact_normal[o, 1]
            ms = m.contact_mu[o] * s.contact_slip[o]
            if m.contact_kind[o] == CONTACT_PAIR:
                # at the surface point found at this q; equal and opposite on the reference body
                px = ws.contact_point[o, 0]
                py = ws.contact_point[o, 1]
                set_dir(s.q, ws.row_body[r, 0], px, py, nx - ms * ny, ny + ms * nx, -1.0,
                        ws.row_F[r, 0])
            else:
                px, py = world_point(s.q, ws.body_cs, b, ws.contact_anchor[o, 0],
                                     ws.contact_anchor[o, 1])
            set_dir(s.q, b, px, py, nx - ms * ny, ny + ms * nx, 1.0, ws.row_F[r, 1])
    return sliding
