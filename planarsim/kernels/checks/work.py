"""The work [J] each cause does on the bodies in a step: the energy audit's measures
(kernels/checks/audit.py counts what breaks its rules).

  joints      the pins' and rods' impulses at the velocity solve's end velocity,
              sum_r lam_r J_r v: with each row's end-of-step error aimed at c(q + h v*) (the
              second-order target, kernels/solver/solve.fill_row_b) this is -sum_r lam_r c_r(q + h v*) / h,
              the drift of rotating anchors: about (h w)^2 KE in smooth motion (a pendulum:
              tension h m v^2 / L times drift h v^2 / 2L over h); where the impulses are too
              large for that sum to be measured, bounded below from the velocities
  limits      each active joint limit's impulse times its rate at the end velocity: an
              inequality's, like a contact's, is at most rounding
  correction  the position correction's and projection's change of kinetic energy less the
              work of the applied forces along its move, KE(v) - KE(v_solved) - f . (q - q_solved)

The constraints' share of a step's energy: within SHAKE's regime (a step that turns each body
by h w <= SHAKE_REGIME) the joints' second-order terms move the kinetic energy of what turns
by at most about SHAKE_REGIME^2 of it, up or down, and the energy oscillates about its value
(symplectic Euler). Where what turns fastest carries most of the energy (a whip's tip) that
is a larger share of the whole; the joints' target may add up to JOINT_WORK_SHARE of it where
the step ends near the configuration it was linearized at (joints_add_energy), the position
correction CONSTRAINT_SHARE (integrate.bound_correction_work); more is energy from nowhere.
"""
import math

from ...compile import kernel
from ..dynamics.forces import point_velocity
from ..math2d import world_point
from ..constraints.rows import is_joint_row, is_normal_row, is_soft_row, is_tangent_row
from ..solver.solve import row_dot
from .frame import frame_velocity, kinetic_in_frame

# SHAKE's regime: the correction's velocity change dv is at most this share of the velocity
# (mass-weighted norms); it is about h w / 2 there (measured at most 0.02 in smooth motion,
# 0.1 at the 99th percentile of hard impacts at dt = 3 ms)
SHAKE_REGIME = 0.1
# the share of the kinetic energy the constraints' second-order terms may add in a step
CONSTRAINT_SHARE = SHAKE_REGIME * SHAKE_REGIME
# the share of KE(v*) the joints' second-order target may add where it was linearized near
# the step's end (joints_add_energy): 3.7 times the most measured (a 32-link whip's tip:
# 6.7 %); energy from nowhere is orders beyond it (a folded loop's nearly dependent rows:
# 1e4 times the energy in a step; a rod turning a radian in a step: 6e3 times)
JOINT_WORK_SHARE = 0.25
# a joint row whose pivot kept less than this share of its diagonal (ws.joint_pivot) belongs
# to a loop at or near a dependent configuration (a four-bar folded flat: 1e-8 to 3e-4 at the
# steps whose second-order target gained 1 % to 8 % of KE(v*); no step of the shipped walkers
# changed with it):
# there the target's drift along the nearly dependent direction is carried by huge
# impulses, not by motion, and only the constraints' share CONSTRAINT_SHARE is its own
NEAR_DEPENDENT = 1e-3
WORK_REL_TOL = 1e-7      # the accuracy the complementarity solve accepts (lcp.ANSWER_TOL)
# [m/s] a contact velocity this small is the solve's rounding, not motion: it moves a point by
# 1e-8 h m in a step, a hundredth of DEPTH_TOL or less (h <= 1e-2 s), below what the position
# audit can see; the complementarity solve of a resting 16-box chain (condition 3e9) leaves
# velocities of 3e-9 m/s
VELOCITY_FLOOR = 1e-8
# [m] a correction's move this small is closing an error the audit accepts (audit.DEPTH_TOL):
# lifting a body by it against gravity is not energy worth counting
CORRECTION_MOVE_FLOOR = 1e-8
RELATIVE_ROUNDING = 1e-12


@kernel
def kinetic_energy(m, v):
    """sum_i (m_i |v_i|^2 + I_i w_i^2) / 2 [J] of velocities v (n_body, 3)."""
    total = 0.0
    for i in range(v.shape[0]):
        total += m.body_mass[i] * (v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1])
        total += m.body_inertia[i] * v[i, 2] * v[i, 2]
    return 0.5 * total


@kernel
def fastest(v):
    """The largest |v_x| + |v_y| [m/s] of any body in v (n_body, 3)."""
    top = 0.0
    for i in range(v.shape[0]):
        top = max(top, abs(v[i, 0]) + abs(v[i, 1]))
    return top


@kernel
def row_rounding(ws, r, speed):
    """The work [J] row r's impulse may do by rounding alone: |lam| (WORK_REL_TOL speed +
    VELOCITY_FLOOR), speed [m/s] the step's largest."""
    return abs(ws.lam[r]) * (WORK_REL_TOL * speed + VELOCITY_FLOOR)


@kernel
def joint_work(m, ws, v):
    """(work [J] of the pins', sliders' and rods' impulses ws.lam at velocity v, its rounding
    [J], the row doing the most work or -1): rows 0..n_row-1 (F = J for joints)."""
    speed = fastest(v) + fastest(ws.v_pred)
    total = 0.0
    rounding = 0.0
    most = 0.0
    row = -1
    for r in range(ws.n_row[0]):
        if not is_joint_row(ws.row_kind[r]) or is_soft_row(ws.row_kind[r]):
            continue    # a soft row's work is its spring's and damper's (soft.py)
        w = ws.lam[r] * row_dot(ws, r, ws.row_J, v)
        total += w
        rounding += row_rounding(ws, r, speed)
        if w > most:
            most = w
            row = r
    return total, rounding, row


@kernel
def _rod_rate(s, v, a, b, ax, ay, bx, by):
    """(p_b - p_a) x (v_b - v_a) [m^2/s] of anchors p_a, p_b on bodies a, b under velocity v:
    the rod's turning rate times its length squared."""
    vax, vay = point_velocity(s.q, v, a, ax, ay)
    vbx, vby = point_velocity(s.q, v, b, bx, by)
    return (bx - ax) * (vby - vay) - (by - ay) * (vbx - vax)


@kernel
def prediction_turn(m, s, ws, h):
    """The largest angle [rad] by which the step's end, integrated with the solve's velocity
    ws.v_new, turns away from the predicted end q + h v_lin at which the joints' second-order
    target was linearized (ws.q_pred, soft.soft_prediction): h |w - w_lin| of a body, and
    for a rod, h |dv_perp| / L of the change of its anchors' relative velocity across it. A pin's or rod's error is
    nonlinear in these turns only (linear in translations), so the target's error is of
    order (this turn) x (the drift it aims at)."""
    top = 0.0
    for i in range(s.v.shape[0]):
        top = max(top, abs(h) * abs(ws.v_new[i, 2] - ws.v_lin[i, 2]))
    for j in range(m.rod_body.shape[0]):
        a = m.rod_body[j, 0]
        b = m.rod_body[j, 1]
        ax, ay = world_point(s.q, ws.body_cs, a, m.rod_anchor[j, 0, 0], m.rod_anchor[j, 0, 1])
        bx, by = world_point(s.q, ws.body_cs, b, m.rod_anchor[j, 1, 0], m.rod_anchor[j, 1, 1])
        length2 = (bx - ax) ** 2 + (by - ay) ** 2
        if length2 > 0.0:
            change = (_rod_rate(s, ws.v_new, a, b, ax, ay, bx, by)
                      - _rod_rate(s, ws.v_lin, a, b, ax, ay, bx, by))
            top = max(top, abs(h) * abs(change) / length2)
    return top


@kernel
def joints_excess(m, s, ws, h, work, rounding, gain, scale):
    """The joints' energy beyond their share [J] (joints_add_energy's rule): their work
    (its rounding, and gain, a lower bound of it from the velocities or -inf) beyond
    CONSTRAINT_SHARE of scale, KE(v_lin); beyond JOINT_WORK_SHARE of it where the rows are
    not nearly dependent and the step ends within SHAKE_REGIME of its prediction."""
    excess = max(work - CONSTRAINT_SHARE * scale - rounding, gain - CONSTRAINT_SHARE * scale)
    if (excess > 0.0 and ws.joint_pivot[0] >= NEAR_DEPENDENT
            and prediction_turn(m, s, ws, h) <= SHAKE_REGIME):
        excess = max(work - JOINT_WORK_SHARE * scale - rounding,
                     gain - JOINT_WORK_SHARE * scale)
    return excess


@kernel
def joints_add_energy(m, s, ws, h):
    """The joints' impulses of the velocity solve (a step of h [s]) added more kinetic energy
    than their second-order target can, beyond rounding: returns the excess [J] (<= 0: none)
    and the row doing the most work. The target aims each row at its drift at the predicted
    end q + h v_lin (v* but where soft rows or step.relinearize moved it), and the shares
    below are of KE(v_lin); where the step ends near it (prediction_turn within SHAKE_REGIME) the
    target is right to third order and its work is the drift's own, an oscillation of
    about (h w)^2 of the energy of what turns, which a whip's tip concentrates (measured: 7 %
    of a 32-link chain's KE(v*) at a step, 0.02 % net over 10 s): only a gain beyond
    JOINT_WORK_SHARE of KE(v*) is energy from nowhere. Where the end turns further from the
    prediction (an armature or stiff spring that the velocity solve, not v*, holds back) the
    target was linearized at the wrong place, and where the joint rows are nearly dependent
    (ws.joint_pivot below NEAR_DEPENDENT: a closed loop at or near a dead point) its drift
    along the direction they can hardly move is carried by huge impulses, not by motion:
    beyond CONSTRAINT_SHARE of KE(v*) is from nowhere.
    Where the impulses are so large that their work's rounding exceeds that share, the
    velocities' lower bound of that work (gain_from_velocities) is judged too."""
    work, rounding, row = joint_work(m, ws, ws.v_new)
    # energies in the frame of the step's checks (frame.py: a free model's centre of mass)
    fx, fy = frame_velocity(m, ws, ws.v_pred)
    kinetic = kinetic_in_frame(m, ws.v_pred, fx, fy)
    # the shares are of the energy of the motion the target was linearized at: KE(v*), but
    # KE(v_lin) where soft rows moved it (v* lets the applied torques spin a light link
    # that its rotors hold back: a yardstick 5x too large passed a target that kicked such
    # a link by 2.7 rad/s a step) or a second linearization did (step.relinearize)
    scale = kinetic_in_frame(m, ws.v_lin, fx, fy)
    # impulses so large that their work's rounding alone hides the share (a folded loop's
    # self-stress of 1e5 N s at 1e-5 J of motion): the velocities bound what they added
    gain = -math.inf
    if rounding > CONSTRAINT_SHARE * scale:
        gain = gain_from_velocities(m, ws, h, kinetic, fx, fy)
    excess = joints_excess(m, s, ws, h, work, rounding, gain, scale)
    if excess > 0.0 and row < 0:
        row = largest_joint_impulse(ws)
    return excess, row


@kernel
def gain_from_velocities(m, ws, h, kinetic, fx, fy):
    """A lower bound [J] of the joints' work at the answer (joint_work), from velocities:
    KE(v_new) - KE(v*) (kinetic: KE(v*); both seen from a frame moving at (fx, fy) [m/s])
    less what the other rows' impulses do at v_new.
    With v_new - v* = W F^T lam, KE(v_new) - KE(v*) = sum_r lam_r F_r v_new - |v_new - v*|^2 / 2
    (mass-weighted), so the joints do at least the gain less the other rows' work, each
    bounded from above: a contact's normal row or a limit's does -lam c / h <= 0 (a violated
    row's c is taken as 0) plus rounding (row_rounding); a tangent row, sticking or sliding
    (friction opposes the slip), at most |lam c| / h plus rounding; a soft row exactly its own
    work (its spring's and damper's). Unlike joint_work, it stays exact where the joints'
    impulses are huge and their work's rounding (|lam| times the solve's accuracy) is not.
    -inf where a contact bounces (its target is the rebound, not -c / h)."""
    speed = fastest(ws.v_new) + fastest(ws.v_pred)
    allowed = 0.0
    for r in range(ws.n_row[0]):
        kind = ws.row_kind[r]
        if is_soft_row(kind):
            allowed += ws.lam[r] * row_dot(ws, r, ws.row_J, ws.v_new)
        elif not is_joint_row(kind):
            if is_normal_row(kind) and ws.contact_bounce[ws.row_owner[r]] > 0.0:
                return -math.inf
            allowed += row_rounding(ws, r, speed)
            if is_tangent_row(kind):
                allowed += abs(ws.lam[r] * ws.row_c[r]) / h
    return kinetic_gain(m, ws, kinetic, fx, fy, allowed)


@kernel(inline="always")
def kinetic_gain(m, ws, kinetic, fx, fy, allowed):
    """gain_from_velocities' bound from its parts: KE(v_new) less kinetic (KE(v*)), both in
    the frame moving at (fx, fy) [m/s], less allowed [J] (what rows other than the joints'
    may do) and the energies' rounding."""
    final = kinetic_in_frame(m, ws.v_new, fx, fy)
    return final - kinetic - allowed - RELATIVE_ROUNDING * (final + kinetic)


@kernel
def largest_joint_impulse(ws):
    """The pin, slider or rod row (not a soft row) with the largest |impulse| (-1 if none)."""
    best = -1.0
    row = -1
    for r in range(ws.n_row[0]):
        if is_joint_row(ws.row_kind[r]) and not is_soft_row(ws.row_kind[r]):
            if abs(ws.lam[r]) > best:
                best = abs(ws.lam[r])
                row = r
    return row


@kernel
def limit_work(ws, r, speed):
    """(work [J] of limit row r's impulse at the end velocity ws.v_new, its rounding [J])."""
    return ws.lam[r] * row_dot(ws, r, ws.row_J, ws.v_new), row_rounding(ws, r, speed)


@kernel
def correction_force_work(s, ws):
    """f . (q - q_solved) [J]: the applied forces' (ws.force) work along the position
    correction's and projection's move."""
    total = 0.0
    for i in range(s.q.shape[0]):
        for k in range(3):
            total += ws.force[i, k] * (s.q[i, k] - ws.q_solved[i, k])
    return total



@kernel
def correction_rounding(m, ws, momentum, energy):
    """The energy [J] a position correction may change by rounding: its velocities exact to
    VELOCITY_FLOOR (momentum: sum_i m_i (|dv_i| + |v_i|) [kg m/s]), its moves to
    CORRECTION_MOVE_FLOOR against the applied forces (ws.force), and its sums (energy [J],
    the size of the terms summed) to RELATIVE_ROUNDING."""
    forces = 0.0
    for i in range(ws.force.shape[0]):
        forces += abs(ws.force[i, 0]) + abs(ws.force[i, 1])
    return VELOCITY_FLOOR * momentum + CORRECTION_MOVE_FLOOR * forces + RELATIVE_ROUNDING * energy


@kernel
def force_step_energy(m, ws, h):
    """(h^2 / 2) f . M^-1 f [J]: how far one symplectic Euler step of h [s] under the applied
    forces ws.force moves the energy by itself (exactly, for constant forces: a falling body's
    step gains (h / 2) g dp_y); a position correction moving bodies by this step's own
    first-order error trades about this much energy with the forces."""
    return step_energy_of_forces(m, ws, h, 1.0)


@kernel
def step_energy_of_forces(m, ws, h, gravity):
    """force_step_energy of the applied forces less (1 - gravity) times gravity's: gravity
    1.0 all of them, 0.0 those other than gravity (a motor's torque, a spring, a push)."""
    total = 0.0
    for i in range(ws.force.shape[0]):
        fx = ws.force[i, 0] - (1.0 - gravity) * m.body_mass[i] * m.gravity[0]
        fy = ws.force[i, 1] - (1.0 - gravity) * m.body_mass[i] * m.gravity[1]
        total += m.body_inv_mass[i] * (fx * fx + fy * fy)
        total += m.body_inv_inertia[i] * ws.force[i, 2] ** 2
    return 0.5 * h * h * total


@kernel
def most_gaining_body(m, s, ws):
    """The body whose kinetic energy the position correction raised the most (s.v against
    ws.v_solved), or -1 if none gained."""
    best = 0.0
    body = -1
    for i in range(s.v.shape[0]):
        gain = 0.0
        for k in range(3):
            inertia = m.body_mass[i] if k < 2 else m.body_inertia[i]
            gain += 0.5 * inertia * (s.v[i, k] * s.v[i, k] - ws.v_solved[i, k] * ws.v_solved[i, k])
        if gain > best:
            best = gain
            body = i
    return body


@kernel
def judge_energy(m, ws, opt, h, excess):
    """An energy gain from nowhere of `excess` [J] in this step of h [s] is gross when it
    exceeds StepOptions.energy_limit times the energy the step had to work with: the kinetic
    energy it solved for (ws.v_solved) plus its own error under the forces
    (force_step_energy), in the frame of the step's checks (frame.py). A gross one marks the
    step (ws.energy_stop): it ends with GUARD_ENERGY, the run stops naming the cause
    (ws.audit_last)."""
    if opt.energy_limit <= 0.0:
        return
    fx, fy = frame_velocity(m, ws, ws.v_pred)
    if excess > opt.energy_limit * (kinetic_in_frame(m, ws.v_solved, fx, fy)
                                    + force_step_energy(m, ws, h)):
        ws.energy_stop[0] = 1


@kernel
def gravity_work(m, s, ws):
    """Gravity's work [J] along the position correction's and projection's move,
    sum_i m_i g . (q_i - q_solved_i) (negative: the bodies were lifted)."""
    work = 0.0
    for i in range(s.q.shape[0]):
        work += m.body_mass[i] * (m.gravity[0] * (s.q[i, 0] - ws.q_solved[i, 0])
                                  + m.gravity[1] * (s.q[i, 1] - ws.q_solved[i, 1]))
    return work


@kernel
def gravity_lift(m, s, ws):
    """The energy [J] the position correction's move gave the bodies against gravity,
    max(0, -gravity_work): a body pushed out of the ground."""
    return max(0.0, -gravity_work(m, s, ws))
