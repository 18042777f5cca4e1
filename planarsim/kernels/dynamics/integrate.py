"""Stage 8 (position.py): integrate positions, then Newton-SHAKE position correction.

integrate:  v = v_new,  q = q + h v  (symplectic Euler).
correct_positions: the linearised rows leave a residual O(h^2 w^2 r). Newton on the SHAKE
equation moves q along the START-of-step constraint directions J(q0):
    (J(q+) W J(q0)^T) mu = -c(q+),   q += W J(q0)^T mu,   v += W J(q0)^T mu / h
(correcting along J(q+) instead would dissipate energy every step); W with the joints'
rotors (an armature's row takes part with compliance 1 / a: correction_compliance); on hills a point
mass's ground contact row, which moves positions only, along its normal at q+ (normals_now).
Safeguards: a Newton step that raises the largest error tenfold (nearly dependent rows of a
closed loop through the ground) is taken back and tried once more with such rows dropped;
one that removes less than half of it has stalled on a row dropped as dependent, and ends
the correction.
Corrections of contact normals move positions only: pushing a body out of the ground must not
give it the velocity overlap / h (energy from nowhere). A joint limit the step started on is
corrected as a joint is, its move becoming velocity (moves_without_velocity).
rows_hold_within proves, from the rows the solve already built, when the correction would
find nothing to do (bodies at rest or translating), so the step skips it exactly.
"""
import math

from ...compile import kernel
from ..codes import CONTACT_PAIR, MODE_FREE, MODE_PINNED
from ..info import INFO_NEWTON_TAKEN_BACK, INFO_SHAKE_WHOLE
from ..math2d import update_trig
from ..constraints.limit import limit_side
from ..constraints.row_list import move_row
from ..constraints.joint_friction import is_joint_friction_row
from ..constraints.joints import joint_position_rate
from ..constraints.rows import (add_joint_impulse, eval_rows, is_angular_row, is_contact_row,
                                is_limit_row, is_normal_row, is_soft_row, is_tangent_row,
                                is_unilateral, row_lever)
from ..solver.matrix import (add_to_diagonal, arrange, assemble, factor_ws, solves_pairs,
                             substitute_pair_ws, substitute_ws)
from ..constraints.soft import SOFT_ARMATURE
from ..solver.solve import apply_impulses, row_dot
from ..checks.work import (CONSTRAINT_SHARE, SHAKE_REGIME, correction_force_work,
                           correction_rounding, gravity_work, step_energy_of_forces)
from ..checks.frame import frame_velocity, kinetic_in_frame


# relative pivot below which the position correction drops a row after a Newton step diverged:
# rows within about 1e-2 rad of dependent
LOOSE_PIVOT_TOL = 1e-4
# a Newton step that multiplies the largest error by more than this has diverged (near a
# solution the error falls quadratically; a step may raise it a little where an inconsistent
# row of a closed loop sets the largest error)
DIVERGED_GROWTH = 10.0
# Newton converges quadratically: a step that leaves more than this share of the largest
# error has stalled
STALLED_RATIO = 0.5
# [m or rad] every row within this after a correction pass: the next pass reuses that pass's
# factorisation (a chord step: the rows moved by less than this since it was assembled, so
# the pass still removes all but a share of that order of the error, as a Newton pass would)
CHORD_TOL = 1e-9


# [rad or m] a limit held within this at a step's start stays in the Newton correction
LIMIT_START_TOL = 1e-9


@kernel
def keep_correction_rows(s, ws):
    """Keep the rows the Newton correction holds: joints, active limits, the normal row of
    every touching contact and the tangent row of every sticking one (a sticking foot does
    not creep along the ground while the correction closes the joints). Rows of contacts the
    solve set free or that rebound (restitution), the tangent rows of sliding ones, the
    joints' dry friction rows and the soft rows of joints without armature (a spring-damper
    has no position error) are dropped. A joint's armature row stays: it has no error of
    its own either (its target is 0), but its rotor turns with the joint, so the correction
    moves the bodies and the rotors by (M + A)^-1 J^T mu, A the rotors' inertia
    (correction_compliance), as the solve moves their velocities. An active limit that the
    step started outside of by more than LIMIT_START_TOL is dropped too: its joint is put
    back onto it by the projection (position.settle_positions), which does not turn that move into
    velocity. Returns how many were dropped."""
    k = 0
    for r in range(ws.n_row[0]):
        kind = ws.row_kind[r]
        o = ws.row_owner[r]
        if is_tangent_row(kind) and s.contact_mode[o] != MODE_PINNED:
            continue
        if is_normal_row(kind) and s.contact_mode[o] == MODE_FREE:
            continue
        if is_contact_row(kind) and ws.contact_bounce[o] > 0.0:
            continue    # rebounding (restitution): it leaves the surface, not held to it
        if is_limit_row(kind) and (s.limit_active[o, limit_side(kind)] == 0
                                   or ws.row_c[r] < -LIMIT_START_TOL):
            continue    # (a joint that started outside its limit: the projection puts it
                        # back without turning the move into velocity, settle_positions)
        if is_soft_row(kind) and ws.row_soft[r, SOFT_ARMATURE] == 0.0:
            continue    # a joint's spring-damper: no position error and no inertia
        if is_joint_friction_row(kind):
            continue    # a joint's dry friction: no position error
        if k != r:
            move_row(ws, k, r)
        k += 1
    dropped = ws.n_row[0] - k
    ws.n_row[0] = k
    return dropped


@kernel
def normals_now(m, ws, n):
    """On hills a point mass's ground contact row moves it along the normal at the
    configuration being corrected (row_J[r] <- row_Jp[r]), not at the step's start: its gap
    is a distance along that normal, so the move is the gap itself. Along a start normal
    turned by an angle a from it (a point sliding over a crest of tight hills turns its
    normal by tens of degrees in a step) the move would be 1 / cos(a) times the gap: metres
    near a = 90 deg (measured: 4.6 m in one step), and away from the ground beyond it.
    Moves positions only (the row is unilateral), so no energy enters. A rigid body's rows
    keep the start's directions (SHAKE), as on flat or sloped ground, where a normal never
    turns: along the current rows a body spinning at h w ~ 1 rad per step has been thrown
    further (a shape on hills moved 2.4 m in a step)."""
    if m.terrain_coef[2] == 0.0:
        return
    for r in range(n):
        if not is_normal_row(ws.row_kind[r]) or m.contact_kind[ws.row_owner[r]] == CONTACT_PAIR:
            continue
        b = ws.row_body[r, 1]
        if b < 0 or m.body_inv_inertia[b] != 0.0:
            continue
        for e in range(2):
            for k in range(3):
                ws.row_J[r, e, k] = ws.row_Jp[r, e, k]


@kernel
def integrate_positions(s, ws, vel, h):
    """v = vel; q += h v; ws.v_solved = vel, ws.q_solved = q (bound_correction_work measures
    from them)."""
    for i in range(s.q.shape[0]):
        for k in range(3):
            s.v[i, k] = vel[i, k]
            ws.v_solved[i, k] = vel[i, k]
            s.q[i, k] += h * vel[i, k]
            ws.q_solved[i, k] = s.q[i, k]


@kernel
def bound_correction_work(m, s, ws, h, symplectic):
    """The position correction's velocity change dv = s.v - ws.v_solved (SHAKE: a joint's
    correction / h) kept as far as the step as a whole adds no energy beyond its allowance:
    v = v_solved + k dv with the largest k in [0, 1] such that

        KE(v) - KE(v_solved) - f . (q - q_solved) <= allowance

    (kinetic energy gained plus the move's work against the applied forces f). Within
    SHAKE's regime, |dv| <= SHAKE_REGIME |v_solved| (mass-weighted), the correction is a
    second-order term of a step that turns each body by h w << 1; it keeps the integrator
    symplectic (energy oscillates, momenta are kept), and the step's constraints (the velocity
    solve and the correction together) may move the energy by CONSTRAINT_SHARE (work.py) of
    the smaller of the step's kinetic energies at its start and after its solve: the
    allowance is that share less what the velocity stage already gained
    (velocity_stage_gain; h [s] the integrated step's). Beyond the regime the allowance is 0.
    A move whose own lift against the forces exceeds the allowance even at the k of least
    energy (a contact point pushed out of the ground by a turning body's (h w)^2 r dip, a
    loop's pin gap closed at a dead point through its contacts) has the rest paid by the
    velocity stage's loss, then by the motion (pay_from_motion). Returns the energy [J] the
    correction still adds beyond all that (a motion too slow to pay for its lift).

    A body turning by h w ~ 1 in one step (a light body spinning after a hard impact)
    leaves first-order errors; Newton can then end on a far solution of the joint
    equations, and its move / h would be energy from nowhere (measured: a 11 g box pinned
    to a 1.6 kg one went from 222 to 6089 rad/s in one 3 ms step, |dv| = 2.5 |v|). In a
    closed loop of bodies whose inertias differ by 1e8 the correction's impulses, set by the
    light bodies' drift, turn a heavy body: a small dv of large momentum (measured: +8 J of
    1136 J in one 10 ms step).
    KE(v_solved + k dv) - KE(v_solved) = k a + k^2 b (a = v_solved . M dv, b = dv . M dv / 2,
    M the bodies' masses and the joints' rotors: a a g^T g term per joint with armature a).

    symplectic: a stage of the accurate integrators (kernels/dynamics/rattle.py), whose velocity must
    be the move (q+ - q) / h for RATTLE to stay symplectic, or a default step of hard joints
    alone (position.joints_alone), which is SHAKE: within SHAKE's regime the correction is
    kept whole (the energy oscillates by about (h w)^2 of it and comes back; cutting the rises
    alone ratcheted a coarse step's energy down: RATTLE -50 % in 10 s, a double pendulum at
    dt 0.02 by the default step -22 J of 30 J in 60 s)."""
    ws.correction_kept[0] = 1.0
    a = 0.0
    b = 0.0
    kinetic = 0.0
    momentum = 0.0
    # velocities in the frame of the step's checks (checks/frame.py: a free model's centre of
    # mass), so that a free model's correction is judged alike however fast it drifts
    fx, fy = frame_velocity(m, ws, ws.v_pred)
    for i in range(s.v.shape[0]):
        mass = m.body_mass[i]
        inertia = m.body_inertia[i]
        dx = s.v[i, 0] - ws.v_solved[i, 0]
        dy = s.v[i, 1] - ws.v_solved[i, 1]
        dw = s.v[i, 2] - ws.v_solved[i, 2]
        ux = ws.v_solved[i, 0] - fx
        uy = ws.v_solved[i, 1] - fy
        a += mass * (ux * dx + uy * dy) + inertia * ws.v_solved[i, 2] * dw
        b += 0.5 * (mass * (dx * dx + dy * dy) + inertia * dw * dw)
        kinetic += 0.5 * (mass * (ux ** 2 + uy ** 2) + inertia * ws.v_solved[i, 2] ** 2)
        momentum += mass * (abs(dx) + abs(dy) + abs(ux) + abs(uy))
    # the joints' rotors (armature): they share the correction's move (correction_compliance)
    # and their kinetic energy a (g v)^2 / 2 is the system's
    for j in range(m.pin_armature.shape[0]):
        arm = m.pin_armature[j]
        if arm == 0.0:
            continue
        rate = joint_position_rate(m, s.q, ws.body_cs, ws.v_solved, j)[1]
        d = joint_position_rate(m, s.q, ws.body_cs, s.v, j)[1] - rate
        a += arm * rate * d
        b += 0.5 * arm * d * d
        kinetic += 0.5 * arm * rate * rate
    in_regime = b <= SHAKE_REGIME * SHAKE_REGIME * kinetic
    if symplectic and in_regime:
        ws.info[INFO_SHAKE_WHOLE] += 1
        return 0.0
    start_kinetic, gained = velocity_stage_gain(m, ws, ws.v_solved, h)
    # the step's share: of the smaller kinetic energy, less what its velocity stage gained
    share = max(CONSTRAINT_SHARE * min(kinetic, start_kinetic) - max(gained, 0.0), 0.0)
    force_work = correction_force_work(s, ws)
    # what the correction may gain, k a + k^2 b - force_work (the move's lift against the
    # forces counts against the same share), with k = 1 if it can
    room = (share if in_regime else 0.0) + force_work + correction_rounding(
        m, ws, momentum, kinetic + abs(a) + b)
    if a + b <= room:
        return 0.0
    # the largest k in [0, 1] with b k^2 + a k <= room; none: the k of least energy
    disc = a * a + 4.0 * b * room
    k = (-a + math.sqrt(disc)) / (2.0 * b) if disc >= 0.0 and b > 0.0 else -1.0
    short = k < 0.0 or (disc >= 0.0 and b > 0.0 and -a - math.sqrt(disc) > 2.0 * b)
    if short:
        k = -a / (2.0 * b) if b > 0.0 else 1.0
    k = min(max(k, 0.0), 1.0)
    ws.correction_kept[0] = k
    for i in range(s.v.shape[0]):
        for c in range(3):
            s.v[i, c] = ws.v_solved[i, c] + k * (s.v[i, c] - ws.v_solved[i, c])
    if not short:
        return 0.0
    # what is left is the move's own lift against gravity. The velocity stage's loss in this
    # step, as the step's energy measures it (velocity_stage_gain), pays for it first (a box
    # pushed out of the overlap it hit gains nothing); a body's lift out of an overlap it
    # began the step in is the start's (start_lift: a start below the ground, a terrain put
    # in); the step's first-order error under the forces other than gravity is its own
    # (work.step_energy_of_forces: a motor's turn; gravity's is exact in the step's measure).
    # The motion pays for the rest (pay_from_motion: a loop near a dead point, where a pin
    # gap of 1e-8 m takes a move of 1e-4 m to close). The other forces' work along the
    # move (a motor's torque) is no energy the step stores
    left = (k * a + k * k * b - ((share if in_regime else 0.0) + gravity_work(m, s, ws))
            - max(-gained, 0.0) - start_lift(ws) - step_energy_of_forces(m, ws, h, 0.0))
    if left <= 0.0:
        return 0.0
    return pay_from_motion(m, s, ws, left)


@kernel
def start_lift(ws):
    """An upper bound [J] of the work against the applied forces of moving each body out of
    the overlap it began the step in (ws.path_explained[:, 2], guards.note_start_depths)."""
    total = 0.0
    for i in range(ws.force.shape[0]):
        total += (abs(ws.force[i, 0]) + abs(ws.force[i, 1])) * ws.path_explained[i, 2]
    return total


@kernel
def pay_from_motion(m, s, ws, energy):
    """Take energy [J] out of the bodies' motion, v <- alpha v for every body (v about the
    frame of the step's checks: a free model keeps its momentum): every homogeneous velocity
    constraint (a pin to the world, a sticking contact, J v = 0) is kept as it was. Returns
    what it could not take (the motion had less)."""
    fx, fy = frame_velocity(m, ws, s.v)
    kinetic = kinetic_in_frame(m, s.v, fx, fy)
    alpha = math.sqrt(1.0 - energy / kinetic) if kinetic > energy else 0.0
    for i in range(s.v.shape[0]):
        s.v[i, 0] = fx + alpha * (s.v[i, 0] - fx)
        s.v[i, 1] = fy + alpha * (s.v[i, 1] - fy)
        s.v[i, 2] *= alpha
    return max(energy - kinetic, 0.0)


@kernel
def velocity_stage_gain(m, ws, vel, h):
    """(KE at the step's start [J], the energy [J] its velocity stage gained beyond what the
    applied forces explain): with v0 = v_pred - h M^-1 f the velocity at the start of the
    integrated step of h [s] and vel its solve's answer (q1 = q0 + h vel),

        KE(vel) - KE(v0) - f . (q1 - q0) + (h / 2) f' . (vel - v0) - G(dp),

    f' the forces other than gravity, dp the bodies' momentum change along -g and M their
    mass: symplectic Euler's own term under constant forces, exactly 0 for a step without
    impulses and for a body at rest on the ground; gravity's is G(dp) = max((h / 2) |g| dp,
    -dp^2 / (2 M)) (benchmarks/folded_loops.py gravity_term: a body rising at less than
    |g| h that its contacts stop within the step loses its kinetic energy, at least the
    centre of mass's dp^2 / (2 M), and gains nothing). Velocities and moves are measured in
    the frame of the step's checks (checks/frame.py), which changes nothing but the rounding
    and the start's kinetic energy (a share of which the constraints may move)."""
    start = 0.0
    end = 0.0
    power = 0.0
    mass = 0.0
    dp = 0.0
    g = math.hypot(m.gravity[0], m.gravity[1])
    ux = -m.gravity[0] / g if g > 0.0 else 0.0
    uy = -m.gravity[1] / g if g > 0.0 else 0.0
    fx, fy = frame_velocity(m, ws, ws.v_pred)     # (checks/frame.py; zero for most models)
    for i in range(vel.shape[0]):
        mass += m.body_mass[i]
        for k in range(3):
            inertia = m.body_mass[i] if k < 2 else m.body_inertia[i]
            inverse = m.body_inv_mass[i] if k < 2 else m.body_inv_inertia[i]
            frame = fx if k == 0 else (fy if k == 1 else 0.0)
            v0 = ws.v_pred[i, k] - h * inverse * ws.force[i, k] - frame
            v1 = vel[i, k] - frame
            start += inertia * v0 * v0
            end += inertia * v1 * v1
            # -f . (q1 - q0) = -h f . v1 (the frame's move taken off both)
            power -= h * ws.force[i, k] * v1
            other = ws.force[i, k] - (m.body_mass[i] * m.gravity[k] if k < 2 else 0.0)
            power += 0.5 * h * other * (v1 - v0)
            if k < 2:
                dp += m.body_mass[i] * (v1 - v0) * (ux if k == 0 else uy)
    owed = max(0.5 * h * g * dp, -dp * dp / (2.0 * mass)) if mass > 0.0 else 0.0
    return 0.5 * start, 0.5 * end - 0.5 * start + power - owed


@kernel
def predict_configuration(m, s, ws, h):
    """ws.q_pred = q + h v_lin (the end of the step without constraint impulses but the soft
    rows', soft.soft_prediction) and its cos / sin: the joints' errors there give the velocity
    solve its second-order term."""
    if m.pin_body.shape[0] + m.rod_body.shape[0] == 0:
        return
    for i in range(s.q.shape[0]):
        for k in range(3):
            ws.q_pred[i, k] = s.q[i, k] + h * ws.v_lin[i, k]
    update_trig(ws.q_pred, ws.cs_pred)


# relative rounding of a row evaluated at coordinates of size x: about eps x per operation;
# a few operations, with margin
ROUNDING = 16 * 2.220446049250313e-16


@kernel(inline="never")
def rows_hold_within(m, s, ws, h, limit):
    """True if every row's error after integrating is provably at most `limit` [m or rad],
    without evaluating the rows again: the error predicted to first order, c + h J v (rows
    and J at the step's start, v the new velocity), plus the second-order motion of each
    row's point on a body turning by d = h w, at most (d^2 / 2 + |d|^3 / 6) times its
    distance from the COM (bounded by _lever), plus the rounding of evaluating the row at
    the body's coordinates. A bound for pins, joint limits and contacts on flat or sloped
    ground (their errors are linear in the points); never claimed where curvature enters
    otherwise (rods, hills). Stops at the first row that may exceed the limit, the
    first-order errors of all rows checked first (they are cheaper)."""
    if m.terrain_coef[2] != 0.0 or m.rod_body.shape[0] > 0:
        return False
    n = ws.n_row[0]
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            continue                # an armature's row: no error of its own
        ws.rhs[r] = abs(ws.row_c[r] + h * row_dot(ws, r, ws.row_J, s.v))
        if ws.rhs[r] > limit:
            return False
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            continue
        err = ws.rhs[r]
        angular = is_angular_row(m, ws, r)
        for e in range(2):
            b = ws.row_body[r, e]
            if b < 0:
                continue
            if angular:
                err += ROUNDING * (1.0 + abs(s.q[b, 2]))
                continue
            lever = row_lever(m, ws, r, e)
            if lever == math.inf:
                return False   # (0 * inf would give NaN, which compares as within the limit)
            d = abs(h * s.v[b, 2])
            err += (0.5 * d * d + d * d * d / 6.0) * lever
            err += ROUNDING * (1.0 + abs(s.q[b, 0]) + abs(s.q[b, 1]) + lever)
        if err > limit:
            return False
    return True


@kernel
def pull_allowance(m, s, ws, r, h):
    """How far [m] the correction may pull the open unilateral row r (a touching contact's
    normal) back onto its surface: the second-order motion of its points on bodies turning
    by d = h w over the step of h [s], (d^2 / 2 + |d|^3 / 6) times their distance from the
    COM (a pivoting foot's tip lifted by L (h w)^2 / 2, which the continuous motion keeps
    on the ground: SHAKE holds it there), plus rounding. A contact open by more is leaving
    its surface (a point that hit a crest flying on over it) and is not pulled back."""
    allow = 0.0
    for e in range(2):
        b = ws.row_body[r, e]
        if b < 0:
            continue
        lever = row_lever(m, ws, r, e)
        if lever == math.inf:
            return math.inf
        # and the turn the step added to the start's: a held contact's target takes the
        # start's turn to second order (contacts.ground_second_order)
        d = abs(h * s.v[b, 2]) + abs(h * (s.v[b, 2] - ws.prev.v[b, 2]))
        allow += (0.5 * d * d + d * d * d / 6.0) * lever
        allow += ROUNDING * (1.0 + abs(s.q[b, 0]) + abs(s.q[b, 1]) + lever)
    return allow


@kernel(inline="never")
def drop_leaving_rows(m, s, ws, h):
    """Before the correction: drop the rows of each contact (its normal and a sticking
    contact's tangent row) and limit that the configuration being corrected has opened by
    more than the step's turning explains (pull_allowance): the body is leaving the
    surface (a point that hit a crest flying on over it), and holding the row would pull it
    back down. Evaluates the rows at s.q (ws.row_Jp, ws.rhs: scratch here); returns how
    many rows were dropped."""
    update_trig(s.q, ws.body_cs)
    n = ws.n_row[0]
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_Jp, ws.rhs, n, False)
    for r in range(n):
        c = ws.rhs[r]
        if c > 0.0 and is_unilateral(ws.row_kind[r]) and c > pull_allowance(m, s, ws, r, h):
            ws.rhs[r] = math.nan        # leaving
    k = 0
    for r in range(n):
        leaving = ws.rhs[r] != ws.rhs[r]
        if (not leaving and is_tangent_row(ws.row_kind[r]) and r > 0
                and is_normal_row(ws.row_kind[r - 1])
                and ws.row_owner[r - 1] == ws.row_owner[r]):
            leaving = ws.rhs[r - 1] != ws.rhs[r - 1]    # its contact's normal row leaves
        if leaving:
            continue
        if k != r:
            move_row(ws, k, r)
        k += 1
    ws.n_row[0] = k
    return n - k


@kernel
def targets_of(ws, n):
    """The correction's targets from the rows' errors c in ws.rhs (rows 0..n-1): ws.rhs <- -c;
    returns the largest |c|. An armature's row (keep_correction_rows) has target 0 and no
    error: its rotor only shares the move."""
    worst = 0.0
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            ws.rhs[r] = 0.0
            continue
        c = ws.rhs[r]
        ws.rhs[r] = -c
        if abs(c) > worst:
            worst = abs(c)
    return worst


@kernel
def correction_compliance(ws, n):
    """A[r, r] += 1 / a for each armature row r (a: its rotor's inertia [kg m^2 or kg]) of
    the correction's matrix: the row's impulse nu moves the rotor by -nu / a and the bodies
    by W g^T nu, and its target g dq + nu / a = 0 turns the rotor with the joint, so the
    bodies and rotors move together by (M + A)^-1 J^T mu (A = sum a g^T g), the inertia the
    velocity solve gives them (soft.py)."""
    for r in range(n):
        if is_soft_row(ws.row_kind[r]):
            add_to_diagonal(ws, r, 1.0 / ws.row_soft[r, SOFT_ARMATURE])


@kernel(inline="never")
def max_residual(m, s, ws):
    """Largest |c| over the active rows at the current configuration (fills ws.row_Jp, ws.rhs
    with the correction's target -c)."""
    update_trig(s.q, ws.body_cs)
    n = ws.n_row[0]
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_Jp, ws.rhs, n, False)
    return targets_of(ws, n)


@kernel(inline="always")
def keep_targets(ws, n):
    """ws.row_c <- the correction's targets -c in ws.rhs (rows 0..n-1; row_c is free then),
    kept for its velocity solve; returns how many rows move positions only
    (moves_without_velocity)."""
    still = 0
    for r in range(n):
        ws.row_c[r] = ws.rhs[r]
        still += moves_without_velocity(ws.row_kind[r])
    return still


@kernel(inline="always")
def moves_without_velocity(kind):
    """A contact's normal row: its correction removes overlap, and that move does not become
    velocity (it would be energy from nowhere). A joint limit's row in the correction is one
    the step started on (keep_correction_rows), held like a joint's equality: its move
    (the second-order term of a limited joint turning with its bodies, a slide held out
    on its limit by a spin) becomes velocity as a pin's does, so that its impulses, which
    act between the two bodies, keep the momenta as SHAKE's do."""
    return is_normal_row(kind)


@kernel(inline="always")
def move_by_correction(m, s, ws, h, n, still):
    """Move the bodies by the correction whose matrix ws holds factored and whose targets -c
    are in ws.rhs (ws.row_c: a copy of them): positions by W J^T lam, velocities by the same
    over h, or, with contact normal rows among them (moves_without_velocity), by -c / h on
    the other rows and not at all along the normals."""
    for i in range(ws.dq_correction.shape[0]):
        for k in range(3):
            ws.dq_correction[i, k] = 0.0
            ws.dv_correction[i, k] = 0.0
    if still > 0 and solves_pairs(ws):
        # (both solves below in one substitution, the velocity's in ws.sp_x / sp_y)
        for r in range(n):
            ws.sp_x[r] = 0.0 if moves_without_velocity(ws.row_kind[r]) else ws.row_c[r] / h
        substitute_pair_ws(ws, ws.rhs, ws.lam, ws.sp_x, ws.sp_y, n)
        apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dq_correction, 1.0)
        for r in range(n):
            ws.lam[r] = ws.sp_y[r]
        apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dv_correction, 1.0)
    else:
        substitute_ws(ws, ws.rhs, ws.lam, n, False)
        apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dq_correction, 1.0)
        if still == 0:
            # velocities by the same correction / h
            apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dv_correction, 1.0 / h)
        else:
            # velocities: the other rows change by -c / h, contact normals not at all (a
            # separate solve: zeroing the unilateral impulses of the position solve instead
            # leaves a pinned foot, held by its contact against a rod, moving at rod-fix / h)
            # (same matrix: its factors are reused)
            for r in range(n):
                ws.rhs[r] = 0.0 if moves_without_velocity(ws.row_kind[r]) else ws.row_c[r] / h
            substitute_ws(ws, ws.rhs, ws.lam, n, False)
            apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dv_correction, 1.0)
    record_moved_impulses(ws, n, velocity_share(h, still))
    for i in range(s.q.shape[0]):
        for k in range(3):
            s.q[i, k] += ws.dq_correction[i, k]
            s.v[i, k] += ws.dv_correction[i, k]


@kernel(inline="always")
def velocity_share(h, still):
    """What move_by_correction's ws.lam is multiplied by to give its velocity impulses [1/s
    or 1]: 1 / h where the move itself became velocity, 1 where a second solve gave it."""
    return 1.0 / h if still == 0 else 1.0


@kernel
def record_moved_impulses(ws, n, scale):
    """The joint rows' impulses ws.lam (rows 0..n-1) times scale added to the step's
    correction impulses (ws.pin_impulse_moved, ws.rod_impulse_moved): a correction's
    velocity change (scale -1 / h or -1: one taken back)."""
    for r in range(n):
        add_joint_impulse(ws.pin_impulse_moved, ws.rod_impulse_moved, ws, r,
                          scale * ws.lam[r], True)


@kernel
def clear_moved_impulses(ws):
    """No correction impulses yet this step (record_moved_impulses)."""
    ws.pin_impulse_moved[:] = 0.0
    ws.rod_impulse_moved[:] = 0.0
    ws.correction_kept[0] = 1.0


@kernel
def commit_moved_impulses(s, ws):
    """The correction's velocity impulses, at the share of its velocity change that
    bound_correction_work kept, added to the impulses the step records (State.last_pin_impulse,
    last_rod_impulse: the velocity solve's), so that they are the joints' whole impulses."""
    kept = ws.correction_kept[0]
    for j in range(s.last_pin_impulse.shape[0]):
        for k in range(4):
            s.last_pin_impulse[j, k] += kept * ws.pin_impulse_moved[j, k]
    for j in range(s.last_rod_impulse.shape[0]):
        s.last_rod_impulse[j] += kept * ws.rod_impulse_moved[j]


@kernel(inline="always")
def take_back_pass(m, s, ws, h, n, still):
    """A correction pass taken back: q and v as before it (ws.q_keep, ws.v_keep), its
    impulses (ws.lam: its own) off the step's, counted in ws.info; returns the largest
    |c| there (ws.rhs: its targets again)."""
    for i in range(s.q.shape[0]):
        for k in range(3):
            s.q[i, k] = ws.q_keep[i, k]
            s.v[i, k] = ws.v_keep[i, k]
    record_moved_impulses(ws, n, -velocity_share(h, still))
    ws.info[INFO_NEWTON_TAKEN_BACK] += 1
    return max_residual(m, s, ws)


@kernel(inline="always")
def correct_positions(m, s, ws, h, iters, tol, pivot_tol, envelope_ready):
    """Newton-SHAKE; returns the final max residual [m or rad]. A pass after one that left
    every row within CHORD_TOL reuses that pass's factors (a chord pass; one that does not
    halve the error is taken back and taken again on a fresh matrix). envelope_ready: the rows are
    those of the velocity solve's envelope (ws.row_first / row_reach): none was dropped since
    and no complementarity solve changed them."""
    if ws.n_row[0] == 0:
        return 0.0
    dropped = drop_leaving_rows(m, s, ws, h)     # (evaluates the rows: c in ws.rhs)
    n = ws.n_row[0]
    if n == 0:
        return 0.0
    if dropped > 0 or not envelope_ready:
        # the envelope of the rows as they are now (keep_correction_rows or drop_leaving_rows
        # compacted them; after a complementarity solve they are not the guess's rows)
        if not arrange(s.q, ws, n, s.q.shape[0], s.contact_dependent, False):
            return max_residual(m, s, ws)       # (no room: the step begins again with more)
    # the velocity solve's sparse factors left out rows the last step dropped as dependent
    # (solve.excluded_rows_hold checked their velocity equations); a correction factors
    # every row, so their gaps are closed too, if it takes place at all
    partial = ws.sp_factored[0] < n
    # the rows kept are as drop_leaving_rows evaluated them unless it moved some
    worst = max_residual(m, s, ws) if dropped > 0 else targets_of(ws, n)
    ptol = pivot_tol
    newton = 0        # corrections taken while Newton converged (0: none, or it did not)
    fresh = True      # the next pass assembles and factors its matrix (else: a chord pass)
    taken_at = 0.0    # the largest |c| the last pass kept was taken at
    for _ in range(iters):
        if worst <= tol:
            break
        if partial:
            if not arrange(s.q, ws, n, s.q.shape[0], s.contact_dependent, False):
                return worst                    # (no room: the step begins again with more)
            partial = False
        for i in range(s.q.shape[0]):
            for k in range(3):
                ws.q_keep[i, k] = s.q[i, k]
                ws.v_keep[i, k] = s.v[i, k]
        still = keep_targets(ws, n)
        chord = not fresh
        if fresh:
            normals_now(m, ws, n)
            assemble(m, ws, ws.row_Jp, ws.row_J, n, False)
            correction_compliance(ws, n)
            factor_ws(ws, n, ptol, False)
        move_by_correction(m, s, ws, h, n, still)
        after = max_residual(m, s, ws)
        if after <= STALLED_RATIO * worst:
            taken_at = worst
            worst = after
            newton += 1
            # every row within CHORD_TOL: the next pass (and the last, below) reuses these
            # factors, as the pin-chain path does (a walker's second factorisation a step)
            fresh = after > CHORD_TOL
            continue
        if chord:
            # a chord pass that did not halve the error: taken back, and the pass taken
            # again on a fresh matrix
            worst = take_back_pass(m, s, ws, h, n, still)
            fresh = True
            continue
        newton = 0
        if after <= DIVERGED_GROWTH * worst:
            # stalled: the largest error belongs to a row dropped as dependent (a closed loop
            # through the ground) whose error the others cannot remove; more steps would
            # only repeat this one
            worst = after
            break
        # Newton diverged: rows nearly dependent (a closed loop through the ground near a
        # dead point) whose errors disagree give a huge step. Take it back and try once
        # more with such rows dropped; if that fails too, keep the configuration before it
        # (the next step's solve sees the rest as c / h).
        worst = take_back_pass(m, s, ws, h, n, still)
        if ptol >= LOOSE_PIVOT_TOL:
            break
        ptol = LOOSE_PIVOT_TOL
    if newton > 0 and 0.0 < worst <= tol and taken_at > CHORD_TOL:
        # one more step on the last factors (no new matrix, a substitution): the end moves
        # by about the residual left (below tol), and its derivative becomes the converged
        # correction's. A last step taken at a residual r leaves the end's derivative with
        # respect to the step's start and commands off by about r / (the bodies' size):
        # 1e-6 where Newton's last step was taken at r ~ sqrt(tol) (tol 1e-12), what
        # derivatives.step_jacobian, exact for the converged correction, would disagree by,
        # and about the square of that after this one. After a last pass taken at
        # r <= CHORD_TOL (a walker's usual second pass, a chord pass; or a fresh pass that
        # began there) it is off by 1e-8 at most already, and this step is left out. The
        # residual returned is the one before this step (it only shrinks).
        move_by_correction(m, s, ws, h, n, keep_targets(ws, n))
        update_trig(s.q, ws.body_cs)
    return worst
