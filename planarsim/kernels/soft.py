"""The joint coordinate's soft row (ROW_JOINT_SOFT): armature and an implicit spring-damper.

A joint j (hinge or slider; joints.py) with coordinate x, rate g v (g = joint_rate_row's
Jacobian), armature a [kg m^2 or kg], stiffness k [N m/rad or N/m], damping c [N m s/rad or
N s/m] and rest x0 gets one row along g whose impulse mu [N m s or N s] is the sum of:
  the armature: a rotor of inertia a turning at the joint's rate (rigidly coupled to it, as a
    geared motor's rotor): its momentum changes by -mu_a, a (g v_new - g v) = -mu_a. This is
    exactly MuJoCo's M_joint += armature in maximal coordinates: eliminating mu_a gives
    (M + a g^T g)(v_new - v) = h f + J^T lambda, the mass matrix seen by the velocity solve
    (applied forces included: they act on M + a g^T g through v* = v + h M^-1 f and this row).
    Its kinetic energy is a (g v)^2 / 2 (planarsim.energy);
  the spring-damper, implicit (backward Euler in the joint's rate and stretch, the soft
    constraint of Box2D and MuJoCo's implicit damping): mu_s = -h (k (x - x0 + h g v_new)
    + c g v_new), so a stiff spring or damper stays stable at any step (it removes energy,
    never adds it: at small h it is the explicit force to first order).
Together: D (g v_new) + mu = a (g v) - h k (x - x0), D = a + h (h k + c). As a row of the
velocity solve, w = A mu + b with
    A_rr = g W g^T + gamma,   gamma = 1 / D   (its compliance),
    b = g v* - gamma (a (g v) - h k (x - x0)),
and w = 0. The row is an equality (joints.py's class: its impulse is free) with a positive
compliance, so it never depends on the others and is never dropped; the position correction
leaves it out (it has no position error to remove).
ws.row_soft[r] holds (a, k, c, g v at the step's start, gamma of the last fill_row_b).
Not covered: the position correction's velocity change (integrate.py, SHAKE's second-order
c / h) and its kinetic-energy bound weigh the bodies' masses only, without the rotors'.
"""
from ..compile import kernel
from .codes import ROW_JOINT_SOFT
from .joints import joint_rate_row
from .row_list import add_row

SOFT_ARMATURE = 0
SOFT_STIFFNESS = 1
SOFT_DAMPING = 2
SOFT_RATE = 3
SOFT_GAMMA = 4


@kernel
def has_soft_row(m, j):
    """Joint j has an armature, a spring or a damper."""
    return m.pin_armature[j] > 0.0 or m.pin_stiffness[j] > 0.0 or m.pin_damping[j] > 0.0


@kernel
def add_soft_row(m, ws, n, j):
    """Append joint j's soft row at slot n if it has one; returns the next free slot."""
    if has_soft_row(m, j):
        n = add_row(ws, n, ROW_JOINT_SOFT, j, m.pin_body[j, 0], m.pin_body[j, 1])
    return n


@kernel
def soft_row(m, q, cs, o, J):
    """Jacobian blocks J (2, 3) (joint o's rate) and stretch x - x0 [rad or m] of its soft row."""
    return joint_rate_row(m, q, cs, o, J) - m.pin_rest[o]


@kernel
def start_soft_row(m, s, ws, r):
    """ws.row_soft[r]: joint's armature, stiffness, damping, and its rate g v at the step's
    start (s.v; row r's J evaluated at s.q)."""
    o = ws.row_owner[r]
    ws.row_soft[r, SOFT_ARMATURE] = m.pin_armature[o]
    ws.row_soft[r, SOFT_STIFFNESS] = m.pin_stiffness[o]
    ws.row_soft[r, SOFT_DAMPING] = m.pin_damping[o]
    rate = 0.0
    for e in range(2):
        b = ws.row_body[r, e]
        if b < 0:
            continue
        for k in range(3):
            rate += ws.row_J[r, e, k] * s.v[b, k]
    ws.row_soft[r, SOFT_RATE] = rate
    ws.row_soft[r, SOFT_GAMMA] = 0.0


@kernel
def soft_row_b(ws, r, h, jv_pred):
    """Row r's b = g v* - gamma (a g v - h k (x - x0)) [rad/s or m/s] for a step of h [s]
    (jv_pred = g v*); stores its compliance gamma in ws.row_soft[r, SOFT_GAMMA]."""
    a = ws.row_soft[r, SOFT_ARMATURE]
    k = ws.row_soft[r, SOFT_STIFFNESS]
    c = ws.row_soft[r, SOFT_DAMPING]
    gamma = 1.0 / (a + h * (h * k + c))
    ws.row_soft[r, SOFT_GAMMA] = gamma
    return jv_pred - gamma * (a * ws.row_soft[r, SOFT_RATE] - h * k * ws.row_c[r])


@kernel
def soft_compliance(ws, r):
    """Row r's compliance gamma (set by soft_row_b for this step)."""
    return ws.row_soft[r, SOFT_GAMMA]
