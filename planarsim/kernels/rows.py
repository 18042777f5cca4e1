"""Stage 4: constraint rows J (Jacobian blocks on bodies a, b) and position errors c.

Row kinds: pin x / y (p_b - p_a = 0), rod (|p_b - p_a| - L = 0), joint limit (angle - lower
>= 0, upper - angle >= 0), contact normal (n.(p - g) = 0) and tangent (t.(p - g) = 0); a shape
pair's contact rows act on both its bodies (kernels/pair.py). For a
point p on a body with COM x, J = (d_x, d_y, (p - x) x d) for a row along unit direction d.
A contact's normal row uses the exact gap (a rolling sole: the gap of its centre minus r, which
rotation leaves unchanged); its tangent row holds the material point at the ground point found
at the start of the step (no slip).
Sliding contacts keep only the normal row; their impulse direction F = n - mu s t carries the
Coulomb friction -mu lambda_n s along the tangent t.
"""
import math

from ._jit import kernel
from .math2d import set_dir, world_point
from .codes import CONTACT_PAIR, MODE_PINNED, MODE_SLIDING
from .pair import pair_row
from .terrain import ground_point

ROW_PIN_X = 0
ROW_PIN_Y = 1
ROW_ROD = 2
ROW_LIMIT_LO = 3
ROW_LIMIT_HI = 4
ROW_CONTACT_N = 5
ROW_CONTACT_T = 6
# a row kind's class is asked by name (is_joint_row, is_mode_row), never by its number's order


@kernel
def is_joint_row(kind):
    """An equality of a joint (pin x / y, rod): its impulse is free, its error always held."""
    return kind == ROW_PIN_X or kind == ROW_PIN_Y or kind == ROW_ROD


@kernel
def is_mode_row(kind):
    """A row with a rule a solve can break (a joint limit, a contact's normal or tangent)."""
    return not is_joint_row(kind)


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
    were found at this q (stage 3), so a normal row reuses them instead of asking the
    terrain again (the same numbers)."""
    kind = ws.row_kind[r]
    o = ws.row_owner[r]
    a = ws.row_body[r, 0]
    b = ws.row_body[r, 1]
    if kind == ROW_PIN_X or kind == ROW_PIN_Y:
        ax, ay = world_point(q, cs, a, m.pin_anchor[o, 0, 0], m.pin_anchor[o, 0, 1])
        bx, by = world_point(q, cs, b, m.pin_anchor[o, 1, 0], m.pin_anchor[o, 1, 1])
        dx = 1.0 if kind == ROW_PIN_X else 0.0
        dy = 1.0 - dx
        set_dir(q, a, ax, ay, dx, dy, -1.0, J[0])
        set_dir(q, b, bx, by, dx, dy, 1.0, J[1])
        return (bx - ax) * dx + (by - ay) * dy
    if kind == ROW_ROD:
        ax, ay = world_point(q, cs, a, m.rod_anchor[o, 0, 0], m.rod_anchor[o, 0, 1])
        bx, by = world_point(q, cs, b, m.rod_anchor[o, 1, 0], m.rod_anchor[o, 1, 1])
        ex = bx - ax
        ey = by - ay
        L = math.sqrt(ex * ex + ey * ey)
        ex /= L
        ey /= L
        set_dir(q, a, ax, ay, ex, ey, -1.0, J[0])
        set_dir(q, b, bx, by, ex, ey, 1.0, J[1])
        return L - m.rod_length[o]
    if kind == ROW_LIMIT_LO or kind == ROW_LIMIT_HI:
        sign = 1.0 if kind == ROW_LIMIT_LO else -1.0
        ang = q[b, 2] - m.pin_ref[o]
        if a >= 0:
            ang -= q[a, 2]
        for k in range(3):
            J[0, k] = 0.0
            J[1, k] = 0.0
        if a >= 0:
            J[0, 2] = -sign
        J[1, 2] = sign
        if kind == ROW_LIMIT_LO:
            return ang - m.pin_limit[o, 0]
        return m.pin_limit[o, 1] - ang
    # contact rows
    if m.contact_kind[o] == CONTACT_PAIR:
        return pair_row(q, cs, ws, o, J, kind == ROW_CONTACT_T)
    for k in range(3):
        J[0, k] = 0.0
    if kind == ROW_CONTACT_N:
        # exact gap of the material point (or of the sole's centre, minus r) at q, along the
        # normal of its closest ground point: the same as the start-of-step values at q0, and
        # exact on curved ground when the position correction evaluates it at q+
        if ws.contact_on_arc[o] == 1:
            px, py = world_point(q, cs, b, m.contact_local[o, 0], m.contact_local[o, 1])
        else:
            px, py = world_point(q, cs, b, ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
        if found:
            # find_contact's query at this q: its gap is already the sole's (centre's - r)
            set_dir(q, b, px, py, ws.contact_normal[o, 0], ws.contact_normal[o, 1], 1.0, J[1])
            return ws.contact_gap[o]
        gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
        set_dir(q, b, px, py, nx, ny, 1.0, J[1])
        if ws.contact_on_arc[o] == 1:
            return gap - m.contact_radius[o]
        return gap
    # tangent row: the material point stays at the ground point found at the step's start
    px, py = world_point(q, cs, b, ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
    tx = ws.contact_normal[o, 1]
    ty = -ws.contact_normal[o, 0]
    set_dir(q, b, px, py, tx, ty, 1.0, J[1])
    return tx * (px - ws.contact_ground[o, 0]) + ty * (py - ws.contact_ground[o, 1])


@kernel
def _pin_rows(q, cs, anchor, o, a, b, J, c, r):
    """Rows r (x) and r + 1 (y) of pin o between bodies a and b: both from one evaluation of
    the two anchor points (the same arithmetic as eval_row, half the work)."""
    ax, ay = world_point(q, cs, a, anchor[o, 0, 0], anchor[o, 0, 1])
    bx, by = world_point(q, cs, b, anchor[o, 1, 0], anchor[o, 1, 1])
    set_dir(q, a, ax, ay, 1.0, 0.0, -1.0, J[r, 0])
    set_dir(q, b, bx, by, 1.0, 0.0, 1.0, J[r, 1])
    c[r] = (bx - ax) * 1.0 + (by - ay) * 0.0
    set_dir(q, a, ax, ay, 0.0, 1.0, -1.0, J[r + 1, 0])
    set_dir(q, b, bx, by, 0.0, 1.0, 1.0, J[r + 1, 1])
    c[r + 1] = (bx - ax) * 0.0 + (by - ay) * 1.0


@kernel
def eval_rows(m, q, cs, ws, J, c, n, found):
    """J[r] and c[r] of rows 0..n-1 at configuration q (cs holds its cos / sin; found: see
    eval_row). A pin's x row is always followed by its y row (build_rows), so both come from
    one evaluation."""
    r = 0
    while r < n:
        if ws.row_kind[r] == ROW_PIN_X:
            _pin_rows(q, cs, m.pin_anchor, ws.row_owner[r], ws.row_body[r, 0],
                      ws.row_body[r, 1], J, c, r)
            r += 2
        else:
            c[r] = eval_row(m, q, cs, ws, r, J[r], found)
            r += 1


@kernel
def predict_joint_errors(m, ws, n):
    """row_c_pred[r] = c(q_pred) of the pin and rod rows (the velocity solve's target);
    contact and limit rows are left alone (row_Jp is scratch here)."""
    r = 0
    while r < n:
        kind = ws.row_kind[r]
        if kind == ROW_PIN_X:
            _pin_rows(ws.q_pred, ws.cs_pred, m.pin_anchor, ws.row_owner[r], ws.row_body[r, 0],
                      ws.row_body[r, 1], ws.row_Jp, ws.row_c_pred, r)
            r += 2
            continue
        if kind == ROW_ROD:
            ws.row_c_pred[r] = eval_row(m, ws.q_pred, ws.cs_pred, ws, r, ws.row_Jp[r], False)
        r += 1


@kernel
def move_row(ws, k, r):
    """Row r's kind, owner, bodies, error, Jacobian and impulse direction into slot k <= r
    (compacting the row list in place)."""
    ws.row_kind[k] = ws.row_kind[r]
    ws.row_owner[k] = ws.row_owner[r]
    ws.row_body[k, 0] = ws.row_body[r, 0]
    ws.row_body[k, 1] = ws.row_body[r, 1]
    ws.row_c[k] = ws.row_c[r]
    ws.row_c_pred[k] = ws.row_c_pred[r]
    ws.row_b[k] = ws.row_b[r]
    for e in range(2):
        for c in range(3):
            ws.row_J[k, e, c] = ws.row_J[r, e, c]
            ws.row_F[k, e, c] = ws.row_F[r, e, c]


@kernel
def add_row(ws, n, kind, owner, a, b):
    ws.row_kind[n] = kind
    ws.row_owner[n] = owner
    ws.row_body[n, 0] = a
    ws.row_body[n, 1] = b
    return n + 1


@kernel
def _later_body(bodies, j):
    """Body after which the rows of joint j (a pin or rod; bodies (n, 2)) go: the later of its
    two bodies (in a chain or tree built parent first, the child)."""
    return max(bodies[j, 0], bodies[j, 1])


@kernel
def build_rows(m, s, ws):
    """Fill the active rows at the current configuration: J, F (impulse directions) and c;
    return how many are sliding-contact rows (F != J there; none: J W F^T is symmetric).

    Rows go body by body: a pin's (and its limits') and a rod's rows after the later of their
    two bodies, a contact's after its body, pins and rods first (a merge of the three lists in
    their model order, O(rows)). For a chain or walker built parent first every row then shares
    bodies only with rows close to it, and the solve's envelope stays narrow; contact rows
    placed after all the joints would couple every joint row to them (a dense block).
    """
    n = 0
    n_pin = m.pin_body.shape[0]
    n_rod = m.rod_body.shape[0]
    n_con = m.contact_body.shape[0]
    big = m.body_inv_mass.shape[0] + 1
    jp = 0
    jr = 0
    ic = 0
    while jp < n_pin or jr < n_rod or ic < n_con:
        kp = _later_body(m.pin_body, jp) if jp < n_pin else big
        kr = _later_body(m.rod_body, jr) if jr < n_rod else big
        kc = max(m.contact_body[ic], m.contact_other[ic]) if ic < n_con else big
        if kp <= kr and kp <= kc:
            j = jp
            n = add_row(ws, n, ROW_PIN_X, j, m.pin_body[j, 0], m.pin_body[j, 1])
            n = add_row(ws, n, ROW_PIN_Y, j, m.pin_body[j, 0], m.pin_body[j, 1])
            if s.limit_active[j, 0]:
                n = add_row(ws, n, ROW_LIMIT_LO, j, m.pin_body[j, 0], m.pin_body[j, 1])
            if s.limit_active[j, 1]:
                n = add_row(ws, n, ROW_LIMIT_HI, j, m.pin_body[j, 0], m.pin_body[j, 1])
            jp += 1
        elif kr <= kc:
            n = add_row(ws, n, ROW_ROD, jr, m.rod_body[jr, 0], m.rod_body[jr, 1])
            jr += 1
        else:
            i = ic
            mode = s.contact_mode[i]
            a = ws.contact_bodies[i, 0]
            b = ws.contact_bodies[i, 1]
            if mode == MODE_PINNED or mode == MODE_SLIDING:
                n = add_row(ws, n, ROW_CONTACT_N, i, a, b)
            if mode == MODE_PINNED:
                n = add_row(ws, n, ROW_CONTACT_T, i, a, b)
            ic += 1
    ws.n_row[0] = n
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_J, ws.row_c, n, True)
    predict_joint_errors(m, ws, n)
    sliding = 0
    for r in range(n):
        for e in range(2):
            for k in range(3):
                ws.row_F[r, e, k] = ws.row_J[r, e, k]
        o = ws.row_owner[r]
        if ws.row_kind[r] == ROW_CONTACT_N and s.contact_mode[o] == MODE_SLIDING:
            sliding += 1
            # impulse lambda_n (n - mu s t): t = (n_y, -n_x)
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
