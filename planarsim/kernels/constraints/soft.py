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
  the spring-damper: the damper implicit (backward Euler in the joint's rate, MuJoCo's
    implicit damping), the spring at a stretch between the step's start and its end,
    mu_s = -h (k (x - x0 + theta h g v_new) + c g v_new), theta = max(0, 1/2 - 1/(4 C)),
    C = h^2 k kappa / (1 + a kappa) the square of the step's angle h omega of the joint's
    spring on its two bodies and rotor (kappa = forces.joint_kappa, their inverse inertia
    along g as the joint's other rows leave them free to move: a hinge to the world turns its
    body about the hinge, not its centre, and a slider's body does not turn; g W g^T of the
    row alone judged a resolved spring stiff, and its theta damped it).
    Where the spring is resolved (C <= 1/2) it is explicit (theta = 0), the symplectic Euler
    of the rest of the step and of MuJoCo's Euler (taken at the step's end it damped a stiff
    joint by an extra h k: HalfCheetah's springs under torque erred 2.5x MuJoCo's Euler).
    Stiffer than that, theta rises towards 1/2 and the scheme stays stable at any step: a
    spring of the step's angle C' is stable while C' (1 - 2 theta) <= 4, here C' <= 8 C,
    margin enough for the rest of the system (which only adds inertia to a joint) and for
    neighbouring springs. The spring's work over the step is its energy's fall plus
    (1/2 - theta) h^2 k (g v_new)^2: symplectic Euler's bounded exchange with the motion at
    theta = 0, none at 1/2; the damper only removes. A joint's spring without rotor or
    damper (a = c = 0) has no row where theta = 0 (D = 0): it is then an explicit force of
    stage 1 (forces.spring_as_force, add_spring_forces), as in MuJoCo's Euler; where the step
    does not resolve it, theta rises from 0 as for the others (D = theta h^2 k > 0), so the
    scheme is continuous in the step.
Together: D (g v_new) + mu = a (g v) - h k (x - x0), D = a + h (theta h k + c). As a row of the
velocity solve, w = A mu + b with
    A_rr = g W g^T + gamma,   gamma = 1 / D   (its compliance),
    b = g v* - gamma (a (g v) - h k (x - x0)),
and w = 0. The row is an equality (joints.py's class: its impulse is free) with a positive
compliance, so it never depends on the others and is never dropped. It has no position error
to remove: the position correction leaves it out, but for its armature (below).
ws.row_soft[r] holds (a, k, c, g v at the step's start, gamma of the last fill_row_b, kappa).
In the position correction (integrate.py) a joint with armature keeps this row with target 0
and compliance 1 / a: the Newton-SHAKE move and its velocity change c / h are shared by the
bodies and the rotors, (M + A)^-1 J^T mu, as in the solve (without it a light link next to a
heavy rotor took the whole change: HalfCheetah's feet under torque erred up to 6.0x MuJoCo's
Euler, 1.23x with it); its kinetic-energy bound (bound_correction_work) counts the rotors'
energy with the bodies'.
"""
from ...compile import kernel
from ..codes import ROW_JOINT_SOFT
from ..dynamics.forces import joint_kappa, spring_as_force
from .joints import joint_rate_row, rate_along
from .row_list import add_row

SOFT_ARMATURE = 0
SOFT_STIFFNESS = 1
SOFT_DAMPING = 2
SOFT_RATE = 3
SOFT_GAMMA = 4
SOFT_KAPPA = 5


@kernel
def soft_gamma(a, k, c, kappa, h):
    """A soft row's compliance 1 / D [1 / (kg m^2) or 1 / kg] for a step of h [s]: armature a,
    stiffness k, damping c, kappa = g W g^T of its bodies (the spring's theta: module
    docstring)."""
    resolved = h * h * k * kappa / (1.0 + a * kappa)
    theta = max(0.0, 0.5 - 0.25 / resolved) if resolved > 0.0 else 0.0
    return 1.0 / (a + h * (theta * h * k + c))


@kernel
def has_soft_row(m, q, cs, j, h):
    """Joint j has an armature, a damper, or a spring that is not a force in a step of h [s]
    from q (cs its cos / sin; forces.spring_as_force)."""
    return (m.pin_armature[j] > 0.0 or m.pin_damping[j] > 0.0
            or (m.pin_stiffness[j] > 0.0 and not spring_as_force(m, q, cs, j, h)))


@kernel
def add_soft_row(m, s, ws, n, j, h):
    """Append joint j's soft row at slot n if it has one in a step of h [s] from s.q; returns
    the next free slot."""
    if has_soft_row(m, s.q, ws.body_cs, j, h):
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
    ws.row_soft[r, SOFT_RATE] = rate_along(ws.row_body[r], ws.row_J[r], s.v)
    ws.row_soft[r, SOFT_GAMMA] = 0.0
    ws.row_soft[r, SOFT_KAPPA] = joint_kappa(m, s.q, ws.body_cs, o)


@kernel
def soft_row_b(ws, r, h, jv_pred):
    """Row r's b = g v* - gamma (a g v - h k (x - x0)) [rad/s or m/s] for a step of h [s]
    (jv_pred = g v*); stores its compliance gamma in ws.row_soft[r, SOFT_GAMMA]."""
    a = ws.row_soft[r, SOFT_ARMATURE]
    k = ws.row_soft[r, SOFT_STIFFNESS]
    c = ws.row_soft[r, SOFT_DAMPING]
    gamma = soft_gamma(a, k, c, ws.row_soft[r, SOFT_KAPPA], h)
    ws.row_soft[r, SOFT_GAMMA] = gamma
    return jv_pred - gamma * (a * ws.row_soft[r, SOFT_RATE] - h * k * ws.row_c[r])


@kernel
def soft_compliance(ws, r):
    """Row r's compliance gamma (set by soft_row_b for this step)."""
    return ws.row_soft[r, SOFT_GAMMA]


@kernel
def _soft_entry(m, ws, t, u):
    """Joint-rate rows t, u of the soft prediction: g_t W g_u^T over the bodies they share
    (their envelope entry before the compliance)."""
    acc = 0.0
    for e in range(2):
        b = ws.soft_body[t, e]
        if b < 0:
            continue
        for f in range(2):
            if ws.soft_body[u, f] != b:
                continue
            acc += (ws.soft_J[t, e, 0] * ws.soft_J[u, f, 0]
                    + ws.soft_J[t, e, 1] * ws.soft_J[u, f, 1]) * m.body_inv_mass[b]
            acc += ws.soft_J[t, e, 2] * ws.soft_J[u, f, 2] * m.body_inv_inertia[b]
    return acc


@kernel
def soft_prediction(m, s, ws, h):
    """ws.v_lin: the velocity at which the joints' second-order target is linearized (the
    predicted end q + h v_lin, integrate.predict_configuration). Without soft rows it is
    v* = ws.v_pred. With them it is v* and the soft rows' own answer: their impulses mu
    solved alone, (G W G^T + Gamma) mu = -b (each row's A and b as in the velocity solve),
    v_lin = v* + W G^T mu. An armature's rotor takes its share of the applied torques
    there, as it does in the solve: linearized at v* instead, the target of a pin next to a
    heavy rotor on a light link aims at a turn the link never makes (Reacher's arm at dt
    1e-4: the wrong velocities from the first step). Exact elimination of the symmetric
    positive definite system (its diagonal holds each row's compliance > 0) in the
    envelope of the joints' order (ws.soft_first; workspace sized at its creation: a model
    whose soft rows outgrow it is linearized at v*, as without soft rows). Returns the
    number of soft rows."""
    nb = s.v.shape[0]
    for i in range(nb):
        for k in range(3):
            ws.v_lin[i, k] = ws.v_pred[i, k]
    n = 0
    for j in range(m.pin_body.shape[0]):
        if has_soft_row(m, s.q, ws.body_cs, j, h):
            ws.soft_joint[n] = j
            n += 1
    if n == 0:
        return 0
    for i in range(nb):
        ws.soft_mark[i] = -1
    size = 0
    for t in range(n):
        j = ws.soft_joint[t]
        first = t
        for e in range(2):
            b = m.pin_body[j, e]
            ws.soft_body[t, e] = b
            if b < 0:
                continue
            if ws.soft_mark[b] < 0:
                ws.soft_mark[b] = t
            else:
                first = min(first, ws.soft_mark[b])
        ws.soft_first[t] = first
        ws.soft_start[t] = size
        size += t - first + 1
    if size > ws.soft_env.shape[0]:
        return 0
    for t in range(n):
        j = ws.soft_joint[t]
        stretch = joint_rate_row(m, s.q, ws.body_cs, j, ws.soft_J[t])
        rate = rate_along(ws.soft_body[t], ws.soft_J[t], s.v)
        rate_pred = rate_along(ws.soft_body[t], ws.soft_J[t], ws.v_pred)
        a = m.pin_armature[j]
        stiff = m.pin_stiffness[j]
        gamma = soft_gamma(a, stiff, m.pin_damping[j], _soft_entry(m, ws, t, t), h)
        ws.soft_rhs[t] = -(rate_pred - gamma * (a * rate - h * stiff * (stretch - m.pin_rest[j])))
        # row t of the envelope, eliminated as it is filled (L D L^T, up-looking)
        base = ws.soft_start[t]
        for u in range(ws.soft_first[t], t + 1):
            value = _soft_entry(m, ws, t, u) + (gamma if u == t else 0.0)
            lo = max(ws.soft_first[t], ws.soft_first[u])
            ub = ws.soft_start[u] - ws.soft_first[u]
            for w in range(lo, u):
                value -= (ws.soft_env[base + w - ws.soft_first[t]] * ws.soft_env[ub + w]
                          * ws.soft_env[ws.soft_start[w] + w - ws.soft_first[w]])
            if u < t:
                value /= ws.soft_env[ws.soft_start[u] + u - ws.soft_first[u]]
            ws.soft_env[base + u - ws.soft_first[t]] = value
    # L y = rhs, D z = y, L^T mu = z
    for t in range(n):
        base = ws.soft_start[t] - ws.soft_first[t]
        value = ws.soft_rhs[t]
        for w in range(ws.soft_first[t], t):
            value -= ws.soft_env[base + w] * ws.soft_rhs[w]
        ws.soft_rhs[t] = value
    for t in range(n):
        ws.soft_rhs[t] /= ws.soft_env[ws.soft_start[t] + t - ws.soft_first[t]]
    for t in range(n - 1, -1, -1):
        base = ws.soft_start[t] - ws.soft_first[t]
        mu = ws.soft_rhs[t]
        for w in range(ws.soft_first[t], t):
            ws.soft_rhs[w] -= ws.soft_env[base + w] * mu
    for t in range(n):
        mu = ws.soft_rhs[t]
        for e in range(2):
            b = ws.soft_body[t, e]
            if b < 0:
                continue
            ws.v_lin[b, 0] += m.body_inv_mass[b] * ws.soft_J[t, e, 0] * mu
            ws.v_lin[b, 1] += m.body_inv_mass[b] * ws.soft_J[t, e, 1] * mu
            ws.v_lin[b, 2] += m.body_inv_inertia[b] * ws.soft_J[t, e, 2] * mu
    return n
