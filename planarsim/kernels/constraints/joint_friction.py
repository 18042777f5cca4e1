"""A joint's dry friction (MuJoCo's frictionloss): a Coulomb friction row on the joint's rate.

Joint j (hinge or slider; joints.py) with friction loss F [N m or N] (m.pin_frictionloss)
takes, over a step of h [s], a friction impulse p [N m s or N s] along its rate row g
(joints.joint_rate_row) with
  |p| <= F h, and either g v_new = 0 (stuck) or p = -F h sign(g v_new) (slipping),
Coulomb's law with a constant normal force, exact (no regularisation). Its mode this step is
ws.friction_slip[j] (the contact modes' scheme, kernels/solver/modes.py):
  stuck (0)        a row ROW_JOINT_FRICTION: g v_new = 0 (no position error), whose impulse
                   must stay within F h (else it slips, opposite to the impulse's sign);
  slipping (+-1)   no row: the known impulse -F h slip along g is part of the free velocity
                   v* (ws.v_pred), and the joint's rate at the step's end must not reverse
                   (else it sticks).
The guess each step is the joint's rate at the step's start: 0 (a joint that stuck last step
ends it at exactly 0) stuck, else slipping that way (start_joint_friction). In the
complementarity solve every frictional joint enters stuck, its row a box |p| <= F h
(mixed_lcp.py: Stewart-Trinkle's friction variables with the constant bound F h). The
position correction leaves the row out (friction acts on velocities only).
"""
from ...compile import kernel
from ..codes import ROW_JOINT_FRICTION
from .joints import joint_rate_row, rate_along
from .row_list import add_row

# an impulse beyond its bound by this share of the bound is a break (rounding below it)
FRICTION_REL_TOL = 1e-9
# a slipping joint's rate against its slip by less than this share of its free and end
# rates is rounding, not a reversal (modes.SLIP_ROUNDING of a sliding contact)
FRICTION_SLIP_ROUNDING = 1e-12


@kernel
def is_joint_friction_row(kind):
    """A stuck joint's friction row (its rate held, impulse within +-F h)."""
    return kind == ROW_JOINT_FRICTION


@kernel
def has_joint_friction(m, j):
    """Joint j has a dry friction (frictionloss > 0)."""
    return m.pin_frictionloss[j] > 0.0


@kernel
def add_friction_row(m, ws, n, j):
    """Append joint j's friction row at slot n if it has friction and is stuck; returns the
    next free slot."""
    if has_joint_friction(m, j) and ws.friction_slip[j] == 0.0:
        n = add_row(ws, n, ROW_JOINT_FRICTION, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return n


@kernel
def friction_row(m, q, cs, o, J):
    """Jacobian blocks J (2, 3) of joint o's friction row (its rate); error 0 (a velocity row)."""
    joint_rate_row(m, q, cs, o, J)
    return 0.0


@kernel
def friction_rate(m, ws, j, vel):
    """Joint j's rate g vel [rad/s or m/s] along its row at the step's start (ws.friction_J)."""
    return rate_along(m.pin_body[j], ws.friction_J[j], vel)


@kernel
def _push(m, ws, j, impulse, vel):
    """vel += W g^T impulse [N m s or N s] along joint j's rate row."""
    for e in range(2):
        b = m.pin_body[j, e]
        if b < 0:
            continue
        vel[b, 0] += m.body_inv_mass[b] * ws.friction_J[j, e, 0] * impulse
        vel[b, 1] += m.body_inv_mass[b] * ws.friction_J[j, e, 1] * impulse
        vel[b, 2] += m.body_inv_inertia[b] * ws.friction_J[j, e, 2] * impulse


@kernel
def set_friction_slip(m, ws, j, slip):
    """Joint j's mode to slip (0 stuck, +-1 slipping that way): the slipping friction
    -F h slip in v_pred moved to match. Returns 1 if the mode changed, else 0."""
    old = ws.friction_slip[j]
    if old == slip:
        return 0
    _push(m, ws, j, -ws.friction_bound[j] * (slip - old), ws.v_pred)
    ws.friction_slip[j] = slip
    return 1


@kernel
def start_joint_friction(m, s, ws, h):
    """After v* (stage 1): each frictional joint's row g at s.q, its bound F h, and its guessed
    mode (the sign of its rate at the step's start; 0: stuck), a slipping one's friction in
    v*. Returns how many joints have friction."""
    count = 0
    for j in range(m.pin_body.shape[0]):
        ws.friction_slip[j] = 0.0
        if not has_joint_friction(m, j):
            ws.friction_bound[j] = 0.0
            continue
        count += 1
        joint_rate_row(m, s.q, ws.body_cs, j, ws.friction_J[j])
        ws.friction_bound[j] = m.pin_frictionloss[j] * h
        rate = friction_rate(m, ws, j, s.v)
        if rate != 0.0:
            set_friction_slip(m, ws, j, 1.0 if rate > 0.0 else -1.0)
    return count


@kernel
def stick_all(m, ws):
    """Every frictional joint stuck (its row in the problem; the complementarity solve's
    start). Returns how many changed."""
    changed = 0
    for j in range(m.pin_body.shape[0]):
        if has_joint_friction(m, j):
            changed += set_friction_slip(m, ws, j, 0.0)
    return changed


@kernel
def slip_reversed(m, ws, j):
    """Slipping joint j's rate at the answer (ws.v_new) runs against its slip beyond rounding
    of its free rate: its friction would push the motion."""
    rate = friction_rate(m, ws, j, ws.v_new)
    scale = abs(friction_rate(m, ws, j, ws.v_pred)) + abs(rate)
    return rate * ws.friction_slip[j] < -FRICTION_SLIP_ROUNDING * scale


@kernel
def friction_breaks(m, ws):
    """How many frictional joints break their rule in the last solve's answer: a stuck one's
    impulse beyond F h, a slipping one's rate reversed."""
    breaks = 0
    for r in range(ws.n_row[0]):
        if is_joint_friction_row(ws.row_kind[r]):
            bound = ws.friction_bound[ws.row_owner[r]]
            if abs(ws.lam[r]) > bound * (1.0 + FRICTION_REL_TOL):
                breaks += 1
    for j in range(m.pin_body.shape[0]):
        if ws.friction_slip[j] != 0.0 and slip_reversed(m, ws, j):
            breaks += 1
    return breaks


@kernel
def switch_joint_friction(m, ws):
    """The friction rule applied to every frictional joint after a solve: a stuck joint whose
    impulse exceeds F h slips (opposite to the impulse), a slipping joint whose rate reversed
    sticks. Returns how many changed."""
    changed = 0
    for r in range(ws.n_row[0]):
        if is_joint_friction_row(ws.row_kind[r]):
            j = ws.row_owner[r]
            if abs(ws.lam[r]) > ws.friction_bound[j] * (1.0 + FRICTION_REL_TOL):
                # (the row's slot is kept until the next build: ws.friction_slip only)
                changed += set_friction_slip(m, ws, j, -1.0 if ws.lam[r] > 0.0 else 1.0)
    for j in range(m.pin_body.shape[0]):
        if ws.friction_slip[j] != 0.0 and slip_reversed(m, ws, j):
            changed += set_friction_slip(m, ws, j, 0.0)
    return changed
