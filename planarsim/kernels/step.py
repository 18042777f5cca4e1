"""The compiled step: a table of contents of the stages (docs/engine.md, "How the engine works").

step(m, s, ws, opt, u) advances State s in place by one step of opt.dt (0: the model's m.dt)
and returns a guard code (0 ok, 1 non-finite, 2 too large). Model, state, workspace and
options arrive as one pointer each (compile/refs.py). The stages are compiled into one C
function (inlined, but for a few long or rarely run parts kept as calls: build_and_solve, the
complementarity solve, the skip test of the correction, the measured end-of-step audit),
compiled once per machine and called by address from every compiled caller (a walker's
rollout, run_steps; link/step.py). A time-of-impact split (CCD) repeats
stages 1-5 for the remainder of the step with the new contact pinned. Each stage lives in its
module (kernels/stages.py lists them); this file only orders them, and
solve_modes, the guess-check-solve of stages 3-5. StepOptions.integrator other than the default
wraps the same stages (step_of_length) in RATTLE's half kicks and projection, or in its
five-stage composition (accurate_step; kernels/dynamics/rattle.py).
"""
import math

import numpy as np

from ..compile import kernel
from .checks.audit import PIN_GAP_TOL, audit_impulses, audit_total
from .geometry.broad_phase import FLAG_LIVE, widen_for_answer
from .geometry.ccd import split_at_impact, stop_at_impact
from .codes import GUESS_PENDING, INTEGRATOR_EULER, MODE_FREE, MODE_PINNED, MODES_ALTERNATING
from .solver.complementarity import solve_contacts
from .geometry.contacts import bounce_of, find_contacts
from .dynamics.forces import apply_forces, end_power, predict_velocity
from .checks.guards import (GUARD_AUDIT, GUARD_ENERGY, GUARD_GROSS, GUARD_JUMP, GUARD_ROOM,
                            check_actuator_turns, check_displacements, check_guards, check_moves,
                            check_speeds, add_part_path, finish_path, keep_step_path,
                            end_checks_alone, note_start_depths, note_start_limits,
                            start_path)
from .info import (INFO_CHAIN_PATH, INFO_SOLVES, INFO_SWITCH_ROUNDS, INFO_TURN_SUBSTEPS,
                   STEP_COUNTS)
from .dynamics.integrate import (bound_correction_work, commit_moved_impulses, integrate_positions,
                                 predict_configuration)
from .constraints.joint_friction import start_joint_friction, stick_all, switch_joint_friction
from .math2d import update_trig
from .solver.modes import (engage_contacts, engage_limits, switch_broken, gather_contact_impulses,
                           rule_breaks, seed_rule)
from .geometry.pair import PAIR_MARGIN
from .solver.pin_chain import (chain_prediction, lever_correct, lever_joint_work,
                               lever_velocity_solve)
from .checks.frame import frame_velocity, kinetic_in_frame
from .solver.rebound import rebound_gain, rebounding
from .prev_copy import add_synced, back_to_prev, copy_state, keep_prev, keep_prev_bodies
from .geometry.pair_toi import hold_off_fast_pairs
from .dynamics.position import ROWS_HELD_SHARE, position_stage
from .constraints.rows import build_rows
from .constraints.soft import soft_prediction
from .solver.solve import solve_impulses
from .dynamics.rattle import (longest_stage, rattle_begin, rattle_end, stage_count, stage_weight,
                              unsupported)
from .solver.warm_start import remember_impulses
from .checks.work import (CONSTRAINT_SHARE, NEAR_DEPENDENT, joints_add_energy, joints_excess,
                          kinetic_gain, prediction_turn)


@kernel(inline="never")
def build_and_solve(m, s, ws, opt, h):
    """Stages 3-4: the active rows at the current configuration and their impulses under the
    modes as they stand. Returns True if the answer's equations need checking (a dependent
    row was dropped, or the system was not symmetric). A call (one copy of its code for both
    solves of solve_modes): its work is microseconds, the call a few nanoseconds."""
    sliding = build_rows(m, s, ws, h)
    dropped = solve_impulses(m, s, ws, h, opt.pivot_tol, sliding == 0, opt.keep_factors == 1)
    ws.least_change[1] = dropped
    return dropped > 0 or sliding > 0


@kernel(inline="never")
def answer_check(m, s, ws, h, include_ccd, equalities):
    """(rules the last solve's answer breaks (modes.rule_breaks), contacts and limits left
    outside the problem that its velocity would push through, which are engaged now)."""
    breaks = rule_breaks(m, s, ws, h, equalities)
    engaged = engage_contacts(m, s, ws, h, include_ccd, ws.v_new) + engage_limits(
        m, s, ws, h, ws.v_new)
    return breaks, engaged


# least-change answers whose modes a step may correct by the contact rules before it gives up
# on them (solve_and_check), and least-change answers a step may try: a contact released by
# the rules that the answer's velocity engages again would otherwise cycle
LEAST_CHANGE_MODE_ROUNDS = 4
LEAST_CHANGE_CALLS = 16


@kernel
def keep_modes(s, ws):
    """Each listed contact's mode and slip direction (-1, 0 or 1) into ws.near_contacts (a
    scratch list the projection fills later in the step): mode + 3 (slip + 1)."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        slip = s.contact_slip[i]
        sign = 2 if slip > 0.0 else (0 if slip < 0.0 else 1)
        ws.near_contacts[k] = s.contact_mode[i] + 3 * sign


@kernel
def restore_modes(s, ws):
    """The modes and slip directions keep_modes kept."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        code = ws.near_contacts[k]
        s.contact_mode[i] = code % 3
        s.contact_slip[i] = float(code // 3 - 1)


# a contact whose least-change normal impulse is below this share of the largest carries a
# load the least change spread over it, not one it must carry: its friction beyond the cone
# releases it (a staggered wall's corner loaded with 1e-5 of a brick's weight and friction
# 1.2 times that)
LIGHT_LOAD = 1e-3


@kernel
def largest_normal_impulse(s, ws):
    """The largest normal impulse [N s] of the listed contacts (ws.contact_impulse)."""
    top = 0.0
    for k in range(ws.n_live[0]):
        top = max(top, ws.contact_impulse[ws.live[k], 0])
    return top


@kernel(inline="never")
def least_change_answer(m, s, ws, opt, h, include_ccd):
    """The step's answer solved again with the least change of impulses (the last solve
    dropped dependent rows and broke a rule). Where it still breaks one (a box loaded off
    its middle by the box above: the least change of a load spread over four corners can
    pull at the far one), every pinned listed contact that pulls, or that carries under
    LIGHT_LOAD of the largest load with its friction beyond the cone, is released at once
    and it is solved again, up to LEAST_CHANGE_MODE_ROUNDS times (friction beyond the cone of
    a loaded contact is left to the complementarity solve). Returns (contacts and limits its
    velocity engages, or -1 if no answer kept every rule: the modes and the least-change
    switch are then put back as they were; solves)."""
    was_on = ws.least_change[0]
    ws.least_change[0] = 1
    keep_modes(s, ws)
    equalities = build_and_solve(m, s, ws, opt, h)
    solves = 1
    for attempt in range(LEAST_CHANGE_MODE_ROUNDS + 1):
        if rule_breaks(m, s, ws, h, equalities) == 0:
            return engage_contacts(m, s, ws, h, include_ccd, ws.v_new) + engage_limits(
                m, s, ws, h, ws.v_new), solves
        if attempt == LEAST_CHANGE_MODE_ROUNDS:
            break
        gather_contact_impulses(m, s, ws)
        changed = 0
        light = LIGHT_LOAD * largest_normal_impulse(s, ws)
        for k in range(ws.n_live[0]):
            i = ws.live[k]
            if s.contact_mode[i] != MODE_PINNED:
                continue
            normal = ws.contact_impulse[i, 0]
            if normal < 0.0 or (normal < light and abs(ws.contact_impulse[i, 1])
                                > m.contact_mu[i] * normal):
                s.contact_mode[i] = MODE_FREE
                changed += 1
        if changed == 0:
            break
        equalities = build_and_solve(m, s, ws, opt, h)
        solves += 1
    restore_modes(s, ws)
    ws.least_change[0] = was_on
    return -1, solves


@kernel(inline="always")
def solve_and_check(m, s, ws, opt, h, include_ccd):
    """One linear solve under the modes as they stand and its check (answer_check); returns
    (rule breaks, contacts and limits engaged, solves taken). An answer that breaks a rule
    where the solve dropped dependent rows (a statically indeterminate pile, whose dropped
    rows' load the elimination order split: a box on two hanging from one corner) is solved
    again with the least change of impulses (least_change_answer). If that answer, or one
    the contact rules correct, keeps every rule it stands, and the step's later solves take
    the least change too; otherwise the first answer is solved again and stands."""
    equalities = build_and_solve(m, s, ws, opt, h)
    if ws.room[0] == 1:
        return 0, 0, 1          # (no room: the step begins again with more)
    breaks, engaged = answer_check(m, s, ws, h, include_ccd, equalities)
    if breaks == 0 or ws.least_change[1] == 0 or ws.least_change[2] >= LEAST_CHANGE_CALLS:
        return breaks, engaged, 1
    ws.least_change[2] += 1
    more, solves = least_change_answer(m, s, ws, opt, h, include_ccd)
    if more >= 0:
        return 0, engaged + more, 1 + solves
    build_and_solve(m, s, ws, opt, h)
    return breaks, engaged, 2 + solves


# rounds of the joints' friction rule (friction_rounds) a step tries before the contacts'
# strategies and the complementarity solve
FRICTION_ROUNDS = 8


@kernel
def refresh_prediction(m, s, ws, h):
    """v_lin and the predicted configuration again from v* (a joint's friction mode moved it;
    joint_friction.py): the answer is then the one a right guess would have given."""
    soft_prediction(m, s, ws, h)
    predict_configuration(m, s, ws, h)


@kernel(inline="never")
def friction_rounds(m, s, ws, opt, h, include_ccd):
    """After an answer that broke a rule: every frictional joint that breaks its own
    (joint_friction.switch_joint_friction: stuck beyond F h slips, a reversed slip sticks)
    switched and the step solved again (with the contacts and limits its answer engages), up
    to FRICTION_ROUNDS times, while a switch is left to make. Returns (an answer stands,
    solves)."""
    solves = 0
    for _ in range(FRICTION_ROUNDS):
        if switch_joint_friction(m, ws) == 0:
            break
        refresh_prediction(m, s, ws, h)
        breaks, engaged, more = solve_and_check(m, s, ws, opt, h, include_ccd)
        solves += more
        while breaks == 0 and engaged > 0 and ws.room[0] == 0:
            breaks, engaged, more = solve_and_check(m, s, ws, opt, h, include_ccd)
            solves += more
        if ws.room[0] == 1 or (breaks == 0 and engaged == 0):
            return True, solves
    return False, solves


# rounds of the simultaneous check (switch_rounds) a step tries after the guess and the
# alternating check, before the complementarity solve; rounds without fewer broken rules
# after which only the first contact that breaks one is switched (Murty's least index)
SWITCH_ROUNDS = 48
SWITCH_STALL = 3


@kernel(inline="always")
def _mix(key, x):
    """key with the integer x mixed in (splitmix64's finaliser on their sum)."""
    z = (key ^ np.uint64(x)) + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@kernel
def modes_key(s, ws, stall, fewest):
    """A 64-bit key of what decides switch_rounds' rounds from here: the listed contacts with
    their modes and slip directions, the limits engaged, the rounds without fewer broken
    rules (up to SWITCH_STALL: the switching rule) and the fewest so far, and the
    least-change answers' state (solve_and_check)."""
    key = _mix(np.uint64(0), ws.n_live[0])
    key = _mix(key, stall)
    key = _mix(key, fewest & 0xFFFFFFFF)
    key = _mix(key, ws.least_change[1])
    key = _mix(key, min(ws.least_change[2], LEAST_CHANGE_CALLS))
    for j in range(s.limit_active.shape[0]):
        key = _mix(key, j * 4 + s.limit_active[j, 0] * 2 + s.limit_active[j, 1])
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        slip = s.contact_slip[i]
        sign = 2 if slip > 0.0 else (0 if slip < 0.0 else 1)
        key = _mix(key, i * 9 + s.contact_mode[i] * 3 + sign)
    return key


@kernel(inline="never")
def switch_rounds(m, s, ws, opt, h, include_ccd):
    """After the guess and the alternating check broke a rule: the contacts that break one switched
    by the rules and solved again, up to SWITCH_ROUNDS times: every one at once (block principal
    pivoting, Judice and Pires 1994), and once SWITCH_STALL rounds in a row did not lower the
    number of broken rules, one at a time, the breaking contact of least index, then a limit
    (Murty's least-index rule, which cannot cycle where the problem is a P-matrix's). An answer
    that breaks none but pushes further contacts into touch is solved again with them, as in
    solve_modes. A pile settling with many contacts that start or stop sliding in one step (a
    pour of 50 shapes) finds its modes in linear solves, where the complementarity solve over
    its island took thousands of pivots. The rounds end early where they stall (the least-index
    rule) on a solve that dropped dependent rows: the rule's end is promised for a P-matrix
    only. Where no round's answer keeps every rule, the contacts' modes are put back as they
    were (the complementarity solve starts from them); a limit the rounds released stays
    released, and the complementarity solve engages it again where its answer pushes through it.
    Returns (an answer stands, solves)."""
    keep_modes(s, ws)
    solves = 0
    breaks = 1
    fewest = 1 << 62
    stall = 0
    # Brent's cycle finding on the rounds' keys (modes_key: what decides the rounds from
    # there): a key met again means the rounds repeat the same modes to the last without an
    # answer, so they end at once (the complementarity solve takes the step, as it would
    # after the last round)
    marked = np.uint64(0)
    since = 0
    span = 1
    for r in range(SWITCH_ROUNDS):
        # (modes.switch_broken reads the answer's rows, not ws.contact_impulse)
        if breaks > 0 and switch_broken(m, s, ws, stall >= SWITCH_STALL) == 0:
            break
        key = modes_key(s, ws, min(stall, SWITCH_STALL), fewest)
        if r > 0 and key == marked:
            break
        ws.info[INFO_SWITCH_ROUNDS] += 1
        since += 1
        if since == span:
            marked = key
            span *= 2
            since = 0
        breaks, engaged, more = solve_and_check(m, s, ws, opt, h, include_ccd)
        solves += more
        if ws.room[0] == 1 or (breaks == 0 and engaged == 0):
            return True, solves
        if breaks < fewest:
            fewest = breaks
            stall = 0
        else:
            stall += 1
        if stall >= SWITCH_STALL and ws.least_change[1] > 0:
            # the least-index rule ends where the problem's matrix is a P-matrix's; rows
            # dropped as dependent make it singular, and the rounds may cycle through
            # least-change answers to the last (a cheetah's limits with a foot's
            # contacts: 48 rounds of 5 solves, then the complementarity solve anyway)
            break
    restore_modes(s, ws)
    return False, solves


@kernel(inline="always")
def has_limits(m):
    """Some joint of the model has a limit."""
    for j in range(m.pin_limit.shape[0]):
        if m.pin_limit[j, 0] != -math.inf or m.pin_limit[j, 1] != math.inf:
            return True
    return False


@kernel(inline="always")
def solve_modes(m, s, ws, opt, h, include_ccd):
    """Stages 3-5: rows, impulses and contact modes that meet every rule (modes.rule_breaks).

    The modes carried over from the last step (plus contacts the free motion would push into
    the ground) are a guess: one linear solve, then its answer
    is checked against every rule. An answer that breaks none but whose velocity pushes
    further contacts or limits through is solved again with them engaged, as long as each
    solve engages more (at most once per contact and limit: a stack landing or settling
    engages one level per solve, each solve linear in its size). Alternating strategy: an
    answer that breaks a rule has the contact under the cursor re-examined by the
    alternating rule and is solved once more (where that changed a mode); one that still
    breaks a rule has every contact
    that breaks one switched at once, up to SWITCH_ROUNDS times (switch_rounds). An answer
    that still breaks a rule has its frictional joints switched by their rule (friction_rounds),
    then the contacts' strategies; one that still breaks a rule goes to the complementarity
    solve, which ends at a consistent
    answer (complementarity.solve_contacts). Returns
    True if a linear solve's answer stood (its rows, and their envelope where there are rows,
    are in ws), False if the complementarity solve replaced it."""
    ws.joint_gain[2] = 0.0      # a new answer: the joints' work is not known yet
    ws.least_change[0] = 0
    ws.least_change[2] = 0
    # a joint limit is engaged by an answer whose velocity carries its joint past it
    # (answer_check), not by the free motion v*: v* turns each body alone, without the pins
    # or the rotors (armature) that it shares a joint's torque with, and so pushed a
    # cheetah's joints past limits that the answers then pulled on (in 588 of 600 steps under
    # random actions the guess broke a rule, mostly such a limit: 3.9 solves a step, 2.2 now)
    engage_contacts(m, s, ws, h, include_ccd, ws.v_pred)
    ws.broken_rules[GUESS_PENDING] = 1      # (the check of this answer counts as the guess's)
    breaks, engaged, rounds = solve_and_check(m, s, ws, opt, h, include_ccd)
    while breaks == 0 and engaged > 0:
        breaks, engaged, more = solve_and_check(m, s, ws, opt, h, include_ccd)
        rounds += more
    ok = breaks == 0 and engaged == 0
    if ws.room[0] == 1:
        return True             # (no room: the step begins again with more)
    more = 0
    if not ok:
        ok, more = friction_rounds(m, s, ws, opt, h, include_ccd)
        rounds += more
        if ws.room[0] == 1:
            return True
    nc = m.contact_body.shape[0]
    if not ok and opt.mode_strategy == MODES_ALTERNATING and nc > 0:
        # the answer in ws is of the modes as they stand where the alternating check changes
        # none and nothing was engaged since it was solved: solved again, it would be the
        # same answer, breaking the same rules (a broken limit rule, or a contact away from
        # the cursor's: the rounds switch those)
        if seed_rule(m, s, ws, s.mode_cursor[0] % nc) > 0 or engaged > 0 or more > 0:
            equalities = build_and_solve(m, s, ws, opt, h)
            rounds += 1
            breaks, engaged = answer_check(m, s, ws, h, include_ccd, equalities)
            ok = breaks == 0 and engaged == 0
    # (the rounds switch limits too: a model with limits and no contact takes them as well)
    if not ok and opt.mode_strategy == MODES_ALTERNATING and (nc > 0 or has_limits(m)):
        ok, more = switch_rounds(m, s, ws, opt, h, include_ccd)
        rounds += more
    if ok:
        gather_contact_impulses(m, s, ws)
    else:
        if stick_all(m, ws) > 0:        # frictional joints enter as box rows
            refresh_prediction(m, s, ws, h)
        solve_contacts(m, s, ws, h, include_ccd)
    remember_impulses(s, ws)
    ws.info[INFO_SOLVES] += rounds
    return ok


@kernel
def scale_rebounds(m, s, ws, scale):
    """Every listed contact's rebound target (contacts.bounce_of) at `scale` of its own."""
    ws.bounce_scale[0] = scale
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if m.contact_restitution[i] != 0.0:
            ws.contact_bounce[i] = bounce_of(m, s, ws, i)


@kernel
def rebound_answer(m, s, ws, opt, h, include_ccd, scale):
    """The step's answer (solve_modes) with the rebounds at `scale`: (whether a linear
    solve's answer stood, the modified energy its contacts add beyond rounding [J]:
    rebound.rebound_gain)."""
    scale_rebounds(m, s, ws, scale)
    answered = solve_modes(m, s, ws, opt, h, include_ccd)
    return answered, rebound_gain(m, ws, h)


# answers bound_rebound tries at most besides the plastic one, and how close below zero
# (a share of the kinetic energy) the energy the rebounds add must come to end the search
REBOUND_TRIES = 8
REBOUND_CLOSE = 1e-6


@kernel(inline="never")
def bound_rebound(m, s, ws, opt, h, include_ccd, answered):
    """The energetic bound on the step's rebounds (kernels/solver/rebound.py): where the contacts of
    the answer with the rebounds restitution asks for add kinetic energy, the step's answer
    is taken again with every rebound scaled by the largest factor that adds none. The
    energy the contacts add is quadratic in the factor while the contacts keep their modes
    and piecewise so where they change (a sticking contact begins to slide): its root is
    bracketed between the plastic answer (factor 0, which adds none) and the full one, and
    found by regula falsi with Illinois' halving (at most REBOUND_TRIES answers, ending
    within REBOUND_CLOSE of the kinetic energy below zero); the answer kept is the last one
    that added none. Where even the plastic answer adds energy the rebounds are not its
    cause: that answer is kept (the audit judges it). Returns what solve_modes returns for
    the answer kept."""
    if not rebounding(s, ws):
        return answered
    hi_g = rebound_gain(m, ws, h)
    if hi_g <= 0.0:
        return answered
    vx, vy = frame_velocity(m, ws, ws.v_pred)
    close = REBOUND_CLOSE * kinetic_in_frame(m, ws.v_pred, vx, vy)
    answered, lo_g = rebound_answer(m, s, ws, opt, h, include_ccd, 0.0)
    if lo_g > 0.0 or ws.room[0] == 1:
        ws.bounce_scale[0] = 1.0
        return answered
    lo = 0.0
    hi = 1.0
    last = 0.0                  # the factor of the answer in ws
    side = 0
    for _ in range(REBOUND_TRIES):
        x = (lo * hi_g - hi * lo_g) / (hi_g - lo_g)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        answered, g = rebound_answer(m, s, ws, opt, h, include_ccd, x)
        last = x
        if ws.room[0] == 1:
            break
        if g <= 0.0:
            lo, lo_g = x, g
            if g >= -close:
                break
            if side == -1:
                hi_g *= 0.5         # (Illinois: the end kept twice running is halved)
            side = -1
        else:
            hi, hi_g = x, g
            if side == 1:
                lo_g *= 0.5
            side = 1
    if last != lo and ws.room[0] == 0:
        answered, g = rebound_answer(m, s, ws, opt, h, include_ccd, lo)
    ws.bounce_scale[0] = 1.0
    return answered


@kernel
def forget_impulses(s, ws):
    """Zero the State's last impulses: a solve repeated with the joints aimed at J v = 0
    starts from zero, so that a row dropped as dependent keeps none (the first solve's
    impulses, or an earlier step's, could do work at this step's velocities)."""
    s.last_contact_impulse[:] = 0.0
    s.last_pin_impulse[:] = 0.0
    s.last_rod_impulse[:] = 0.0
    ws.prev_whole[0] = 1        # (every slot changed: prev_copy.py)


@kernel
def second_order_gains(m, s, ws, h):
    """The joints' second-order target (solve.fill_row_b, linearized at q + h v_lin) made
    their impulses add energy beyond what it may (work.joints_add_energy, against
    KE(v_lin)): a closed loop near a dead point, whose nearly dependent rows turn an
    inconsistent drift into huge impulses, a rod turning by
    a radian in the step, or an armature whose velocity solve ends far from q + h v*. The
    step then solves again with the joints aimed at J v = 0 (a projection, which cannot add
    energy) and leaves the drift to the position correction, whose work is bounded
    (integrate.bound_correction_work)."""
    if m.pin_body.shape[0] + m.rod_body.shape[0] == 0:
        return False
    excess, row = joints_add_energy(m, s, ws, h)
    # the audit of this very answer reads it from here (audit.audit_joints)
    ws.joint_gain[0] = excess
    ws.joint_gain[1] = row
    ws.joint_gain[2] = 1.0
    return excess > 0.0


# a step's end this far [rad] from where the joints' target was linearized (work.
# prediction_turn) is linearized again at it before the target is given up
RELINEARIZE_TURN = 1e-3


@kernel
def relinearize(m, s, ws, h):
    """The joints' second-order target added energy (second_order_gains) while linearized
    at q + h v_lin (soft rows moved it from v*; without them the projection stands, as
    validated on the stress corpus) RELINEARIZE_TURN or more from the answer's end, with
    joint rows that are not nearly dependent (ws.joint_pivot; a loop near a dead point gets
    its projection):
    the target is linearized again at the answer, v_lin = v_new, for one more solve. A light
    link between heavy rotors ends far from where the soft rows alone predicted (the pins
    move it too); the projection (J v = 0) would leave its first-order drift to the position
    correction. Returns True if it did."""
    if ws.joint_pivot[0] < NEAR_DEPENDENT or prediction_turn(m, s, ws, h) < RELINEARIZE_TURN:
        return False
    moved = False           # (without soft rows, v* is the prediction: projection as before)
    for i in range(s.v.shape[0]):
        for k in range(3):
            moved = moved or ws.v_lin[i, k] != ws.v_pred[i, k]
    if not moved:
        return False
    for i in range(s.v.shape[0]):
        for k in range(3):
            ws.v_lin[i, k] = ws.v_new[i, k]
    predict_configuration(m, s, ws, h)
    forget_impulses(s, ws)
    return True


@kernel
def reset_counts(ws):
    """Zero the counts of what a step did (info.STEP_COUNTS; step_info reads them)."""
    for k in STEP_COUNTS:
        ws.info[k] = 0


@kernel
def keep_pairs(ws):
    """Keep the broad phase's pair list at the step's start (ws.room[1]: a workspace that may
    run out of room), so that a step begun again (put_back) lists its pairs as the first
    attempt did."""
    if ws.room[1] == 0:
        return
    n = ws.n_live_pairs[0]
    for k in range(n):
        ws.start_pairs[k] = ws.last_pairs[k]
    ws.n_start_pairs[0] = n


@kernel
def begin_step(ws):
    """Before a step: the audit's counts and the broad phase's pair list kept (put_back
    restores them), no shortage of room yet."""
    for k in range(ws.audit.shape[0]):
        ws.audit_keep[k] = ws.audit[k]
    ws.room[0] = 0
    keep_pairs(ws)


@kernel
def _audit_back(ws):
    """The audit's counts as they were at the step's start (begin_step)."""
    for k in range(ws.audit.shape[0]):
        ws.audit[k] = ws.audit_keep[k]


@kernel
def begin_again(s, ws):
    """The State at the step's start (ws.prev) and the audit's counts as they were, to take
    the step again (in sub-steps)."""
    back_to_prev(s, ws)
    _audit_back(ws)


@kernel
def begin_again_from(s, ws, start):
    """begin_again from `start` (ws.start: the start of a step taken in sub-steps); the
    State then differs from ws.prev beyond the listed pairs (prev_copy.py)."""
    copy_state(start, s)
    ws.prev_whole[0] = 1
    _audit_back(ws)


@kernel
def _pairs_back(s, ws):
    """The broad phase's pair list as it was at the step's start (keep_pairs)."""
    for k in range(ws.n_live_pairs[0]):
        ws.pair_flag[ws.last_pairs[k]] = 0
    n = ws.n_start_pairs[0]
    for k in range(n):
        ws.last_pairs[k] = ws.start_pairs[k]
        ws.pair_flag[ws.start_pairs[k]] = FLAG_LIVE
        add_synced(s, ws, ws.start_pairs[k])
    ws.n_live_pairs[0] = n


@kernel
def put_back(s, ws):
    """A step that ran out of room (GUARD_ROOM) undone: the State at its start (ws.prev),
    the audit's counts and the broad phase's pair list (keep_pairs) as they were."""
    begin_again(s, ws)
    _pairs_back(s, ws)


@kernel
def put_back_from(s, ws, start):
    """put_back from `start` (ws.start: the start of a step taken in sub-steps)."""
    begin_again_from(s, ws, start)
    _pairs_back(s, ws)


@kernel(inline="never")
def step_of_length(m, s, ws, opt, u, step_length, stage):
    """Advance s by one default step of step_length [s] under actuator commands u; return the
    guard code. A call (one copy of its code for the default step and for every stage of the
    accurate integrators, kernels/dynamics/rattle.py). stage: a stage of an accurate step, which keeps
    the step's start in ws.prev, has checked the actuators' turns for all its stages and
    counts what they all did (step_info)."""
    if not stage:
        keep_prev(s, ws)
    # a state handed in from outside (restored, edited) is checked before it is used
    code = check_guards(s, ws, opt.guard_limit)
    if code != 0:
        return code
    if not stage:
        reset_counts(ws)            # (an accurate step counts over all its stages)
        start_path(m, s, ws)        # (the path its velocities explain: check_displacements)
    ws.lcp_eps[0] = 0.0
    ws.audit_worst_value[0] = 0.0
    ws.first_order[0] = 0
    ws.energy_stop[0] = 0
    audited = audit_total(ws)
    for k in range(ws.n_live[0]):
        ws.contact_new[ws.live[k]] = 0
    h = step_length
    for split in range(opt.max_ccd_splits + 1):
        update_trig(s.q, ws.body_cs)                        # cos / sin of the angles
        apply_forces(m, s, ws, u, h)                        # 1. forces
        if split == 0 and opt.turn_limit > 0.0 and not stage:  # a torque the step cannot
            code = check_actuator_turns(m, ws, h, opt.turn_limit)   # resolve: stop before it
            if code != 0:
                return code
        predict_velocity(m, s, ws, h)                       #    v* = v + h M^-1 f
        start_joint_friction(m, s, ws, h)                   #    slipping joints' friction
        soft_prediction(m, s, ws, h)                        #    v_lin: v* and soft rows
        predict_configuration(m, s, ws, h)                  #    q + h v_lin (joints' drift)
        find_contacts(m, s, ws, h)                          # 2. contacts
        if split == 0 and not stage:
            note_start_depths(ws)                           #    (check_displacements)
            note_start_limits(m, s, ws)
        ccd_on = split < opt.max_ccd_splits
        if m.n_shape_pair > 0:                              #    fast shape pairs apart: left
            hold_off_fast_pairs(m, s, ws, h)                #    to the sweep of stage 6
        for attempt in range(3):                            # 3-5. rows, impulses, modes
            answered = solve_modes(m, s, ws, opt, h, not ccd_on)
            if attempt == 2 or ws.first_order[0] == 1 or opt.integrator != INTEGRATOR_EULER:
                break                                       #    (RATTLE keeps its target)
            if not second_order_gains(m, s, ws, h):
                break
            if attempt == 0 and relinearize(m, s, ws, h):   #    again, the target at the
                continue                                    #    answer's end (once), or
            if attempt == 1:                                #    (the soft rows' prediction
                soft_prediction(m, s, ws, h)                #    back: the audit measures
                predict_configuration(m, s, ws, h)          #    the projection against it)
            ws.first_order[0] = 1                           #    with joint rows at J v = 0,
            forget_impulses(s, ws)                              #    from zero impulses
        if ws.room[0] == 0:                                 #    rebounds that add energy
            answered = bound_rebound(m, s, ws, opt, h, not ccd_on, answered)   # scaled down
        if ws.room[0] == 1:                                 #    rows beyond the storage:
            return GUARD_ROOM                               #    again with more (_step)
        if ccd_on and m.n_shape_pair > 0:                   #    shapes the answer moves
            widen_for_answer(m, s, ws, h, PAIR_MARGIN)      #    into, unlisted at stage 2
        if ccd_on:
            tau = split_at_impact(m, s, ws, h, opt.max_ccd_splits - split)  # 6. impact
            if tau >= 0.0:                                  #    mid-step: the rest again
                if not stage:
                    add_part_path(m, s, ws, tau)
                h -= tau
                continue
        else:                                               #    splits used up: the part
            tau = stop_at_impact(m, s, ws, h)               #    ends at a fast pair's impact
            if tau >= 0.0:                                  #    or turn horizon, the rest of
                h = tau                                     #    the step's time dropped
        audit_impulses(m, s, ws, opt, h)                    # 7. audit of the impulses
        position_stage(m, s, ws, opt, h, answered)          # 8. positions: integrate,
        break                                               #    correct, settle
    if ws.room[0] == 1:
        return GUARD_ROOM
    s.time[0] = ws.prev.time[0] + step_length
    s.step[0] += 1
    if m.contact_body.shape[0] > 0:
        s.mode_cursor[0] = (s.mode_cursor[0] + 1) % m.contact_body.shape[0]
    code = check_guards(s, ws, opt.guard_limit)             # 9. guards
    if code == 0 and opt.speed_limit > 0.0:
        code = check_speeds(m, s, ws, opt.speed_limit)
    if code == 0 and opt.gross_limit > 0.0 and ws.audit_worst_value[0] > opt.gross_limit:
        return GUARD_GROSS
    if code == 0 and ws.energy_stop[0] == 1:
        return GUARD_ENERGY
    if code == 0 and opt.audit_raise == 1 and audit_total(ws) > audited:
        return GUARD_AUDIT
    if not stage:
        finish_path(m, s, ws, h)                            #    h: the last part's
        if code == 0 and opt.jump_limit > 0.0:
            code = check_displacements(m, s, ws, opt.jump_limit)
    return code


@kernel(inline="never")
def accurate_step(m, s, ws, opt, u, step_length):
    """One step of step_length [s] of StepOptions.integrator's RATTLE or its composition
    (kernels/dynamics/rattle.py): per stage a half kick back, the default step, a half kick forward;
    the velocity projected onto the joints at the end. The State counts one step. ws.prev
    holds the step's start throughout (an error reports it as the failed step's start); the
    actuators' turns are checked once, before any stage, over the longest stage (a stage of
    rattle6 is 1.32 steps long); a failing stage's guard code is returned at once. step_info
    counts what all the stages did."""
    code = unsupported(m, ws)
    if code != 0:
        return code
    keep_prev(s, ws)
    begin_step(ws)
    reset_counts(ws)
    start_path(m, s, ws)
    if opt.turn_limit > 0.0:
        update_trig(s.q, ws.body_cs)
        apply_forces(m, s, ws, u, step_length)
        code = check_actuator_turns(m, ws, longest_stage(opt.integrator) * step_length,
                                    opt.turn_limit)
        if code != 0:
            return code
    t0 = s.time[0]
    count = s.step[0]
    n = stage_count(opt.integrator)
    for k in range(n):
        h = stage_weight(opt.integrator, k) * step_length
        s.step[0] = count                                   # an error names this step
        rattle_begin(m, s, ws, u, h)
        code = step_of_length(m, s, ws, opt, u, h, True)
        if code == GUARD_ROOM:
            put_back(s, ws)
        if code != 0:
            return code
        rattle_end(m, s, ws, u, h, opt.pivot_tol, k == n - 1)
    s.time[0] = t0 + step_length
    s.step[0] = count + 1
    code = check_guards(s, ws, opt.guard_limit)
    finish_path(m, s, ws, step_length)
    keep_step_path(ws, False)
    if code == 0 and opt.jump_limit > 0.0:
        code = check_displacements(m, s, ws, opt.jump_limit)
    return code


# [m] how far a joint's anchor or a touching ground contact's point may leave its linearised
# motion in a step by its body's turn (a tenth of StepOptions.jump_limit's default slack), or
# TURN_SHARE of its lever where that is more; beyond it the step is taken in sub-steps
# (turn_substeps)
TURN_TARGET = 1e-3
# a lever's share, L (h w)^2 / 2 <= TURN_SHARE L: a turn of up to 0.1 rad a step, the regime
# the engine's docs give for a step. Without it a long lever (a 5 m rocker's sole, its centre
# 4.5 m from the centre of mass) was split at 0.026 rad a step, in the fast part of each swing
# only, and each switch between h and h / 2 moved symplectic Euler's energy by its O(h) term
# the same way: it lost a third of its swing's energy in 30 swings at dt 0.01
TURN_SHARE = 5e-3


@kernel
def touching_ground(s, ws):
    """Some listed ground contact of s is not free (a shape pair's are not judged)."""
    for k in range(ws.ground_contacts.shape[0]):
        if s.contact_mode[ws.ground_contacts[k]] != MODE_FREE:
            return True
    return False


@kernel(inline="always")
def _turn_need(curve, lever, h):
    """(sub-steps needed)^2 for a point whose linearised motion a step of h [s] misses by
    curve h^2 / 2 [m] (curve = sum of L w^2 over its levers L [m] and turning rates w
    [rad/s]) to miss by at most TURN_TARGET, or TURN_SHARE of the lever where that is more."""
    return curve * h * h / (2.0 * max(TURN_TARGET, TURN_SHARE * lever))


@kernel
def turn_substeps(m, s, ws, h, most):
    """How many equal sub-steps the step of h [s] is taken in (1..most): a point at lever L
    [m] on a body turning at w [rad/s] leaves the motion its rows linearise by at most
    L (h w)^2 / 2, so where a pin's anchors (while a ground contact touches) or a touching
    (not free) ground contact's point
    would leave it by more than TURN_TARGET, or TURN_SHARE of its lever where that is more,
    the step is cut to sub-steps that keep it within (w and the modes of the state s: the
    step's start, and again its answer). Taken whole, a 1.2 t box turning 0.57 rad a step on its corners drove a corner 5 cm into the ground
    and the correction threw the box 2-29 cm farther than its velocities explain
    (contact_stress mass_ratio:13). A walker (L w ~ 5 m/s at dt 1 ms: 1e-5 m) takes 1."""
    most_need = 0.0        # the largest (sub-steps needed)^2
    # pins alone are not counted: their correction holds them at any turn, and a count that
    # followed a swing's turning rate switched a pendulum between h and h / 2 as it sped up and
    # slowed down, each switch moving symplectic Euler's energy by its O(h) term with the same
    # sign both ways (a rigid pendulum at dt 0.02 lost a quarter of its swing's energy in 60 s)
    pins = m.pin_body.shape[0] if touching_ground(s, ws) else 0
    for j in range(pins):
        c = 0.0
        lever = 0.0
        for e in range(2):
            b = m.pin_body[j, e]
            if b >= 0:
                w = s.v[b, 2]
                L = abs(m.pin_anchor[j, e, 0]) + abs(m.pin_anchor[j, e, 1])
                c += L * w * w
                lever += L
        most_need = max(most_need, _turn_need(c, lever, h))
    for k in range(ws.ground_contacts.shape[0]):
        i = ws.ground_contacts[k]      # (a shape pair's contacts are not judged here)
        # touching (a contact that touches within the step is seen when the step's answer
        # is judged: _step); its lever bounded by |x| + |y|
        if s.contact_mode[i] == MODE_FREE:
            continue
        w = s.v[m.contact_body[i], 2]
        L = abs(m.contact_local[i, 0]) + abs(m.contact_local[i, 1])
        most_need = max(most_need, _turn_need(L * w * w, L, h))
    if not most_need > 1.0:
        return 1
    n = int(math.ceil(math.sqrt(most_need)))
    return max(1, min(n, most))


# chain_part's answers besides 0: the part cannot be taken by the chain path, from its start
# as it is (CHAIN_GENERAL) or after putting it back (CHAIN_AGAIN, from ws.prev)
CHAIN_GENERAL = -100
CHAIN_AGAIN = -101


@kernel
def chain_joints_gain(m, s, ws, h):
    """second_order_gains on the chain path (work.joints_add_energy's rule on the pins'
    levers): True if the velocity solve's impulses added energy beyond their share (the
    general stages then take the step, and their remedy); else the excess (<= 0) is kept for
    the audit (ws.joint_gain). Where the work's rounding hides the share (a free chain
    falling as one body: no motion in its frame, a share of 0), the velocities' lower bound
    of that work is judged too, as joints_add_energy judges it (work.kinetic_gain: the pins
    are the only rows, so nothing else is allowed for)."""
    work, rounding, row = lever_joint_work(m, ws, ws.v_new)
    fx, fy = frame_velocity(m, ws, ws.v_pred)       # (checks/frame.py)
    scale = kinetic_in_frame(m, ws.v_lin, fx, fy)
    gain = -math.inf
    if rounding > CONSTRAINT_SHARE * scale:
        gain = kinetic_gain(m, ws, kinetic_in_frame(m, ws.v_pred, fx, fy), fx, fy, 0.0)
    excess = joints_excess(m, s, ws, h, work, rounding, gain, scale)
    ws.joint_gain[0] = excess
    ws.joint_gain[1] = row
    ws.joint_gain[2] = 1.0
    return excess > 0.0


@kernel
def remember_pin_impulses(s, ws):
    """warm_start.remember_impulses for a model of pins alone: the velocity solve's impulses
    (ws.lam, rows 2j and 2j + 1 of pin j) into State.last_pin_impulse, no limit's."""
    for j in range(s.last_pin_impulse.shape[0]):
        s.last_pin_impulse[j, 0] = ws.lam[2 * j]
        s.last_pin_impulse[j, 1] = ws.lam[2 * j + 1]
        s.last_pin_impulse[j, 2] = 0.0
        s.last_pin_impulse[j, 3] = 0.0


@kernel(inline="never")
def chain_part(m, s, ws, opt, u, h):
    """One part of h [s] (the step, or a turn sub-step) of a model whose only rows are the
    pins of open chains (ws.chain_on; planarsim/pin_chains.py): the stages step_of_length
    runs for such a model, in its order, with the velocity solve and the correction by block
    elimination along the chains (kernels/solver/pin_chain.py) and every check of the general
    step. Where the general step would do more than this (a row its solve would drop as
    dependent, the joints' energy check or the correction's energy bound taking effect, a correction that
    stalls or ends above refine_tol, a guard, an audit) it returns CHAIN_GENERAL or
    CHAIN_AGAIN; else 0."""
    keep_prev_bodies(s, ws)
    if check_guards(s, ws, opt.guard_limit) != 0:
        return CHAIN_GENERAL
    reset_counts(ws)
    start_path(m, s, ws)
    ws.lcp_eps[0] = 0.0
    ws.audit_worst_value[0] = 0.0
    ws.first_order[0] = 0
    ws.energy_stop[0] = 0
    audited = audit_total(ws)
    update_trig(s.q, ws.body_cs)
    apply_forces(m, s, ws, u, h)                            # 1. forces
    if opt.turn_limit > 0.0 and check_actuator_turns(m, ws, h, opt.turn_limit) != 0:
        return CHAIN_GENERAL
    predict_velocity(m, s, ws, h)
    soft_prediction(m, s, ws, h)                            #    (v_lin = v*)
    chain_prediction(s, ws, h)
    ws.least_change[0] = 0                                  # 3-4. rows, impulses
    ws.least_change[1] = 0
    ws.least_change[2] = 0
    ws.joint_pivot[0] = lever_velocity_solve(m, s, ws, h)
    ws.info[INFO_SOLVES] += 1
    if ws.joint_pivot[0] <= opt.pivot_tol:          # (a row the general solve would drop)
        return CHAIN_GENERAL
    if chain_joints_gain(m, s, ws, h):
        return CHAIN_GENERAL
    remember_pin_impulses(s, ws)
    integrate_positions(s, ws, ws.v_new, h)                 # 8. positions
    worst, passes = lever_correct(m, s, ws, h, opt.refine_iters, opt.refine_tol,
                                  opt.refine_pivot_tol)
    if not (worst >= 0.0 and worst <= opt.refine_tol):
        return CHAIN_AGAIN
    # (without a pass v is the solve's: the bound has nothing to keep)
    if passes > 0 and bound_correction_work(
            m, s, ws, h, ws.joints_open[0] == 1 and ws.joint_pivot[0] >= NEAR_DEPENDENT) > 0.0:
        return CHAIN_AGAIN
    commit_moved_impulses(s, ws)
    s.time[0] = ws.prev.time[0] + h
    s.step[0] += 1
    if (end_checks_alone(m, s, ws, h, opt.guard_limit, opt.speed_limit,    # 9. guards
                         opt.jump_limit) or audit_total(ws) > audited):
        return CHAIN_AGAIN
    return 0


@kernel(inline="never")
def chain_step(m, s, ws, opt, u, step_length):
    """_step for a model of pin chains (ws.chain_on): the whole step, or the turn sub-steps
    _step would take it in, by chain_part. Returns 0, or CHAIN_GENERAL with s as it was at
    the step's start (the general stages then take the step: their answer differs from
    this path's by rounding only, their checks are the same)."""
    if opt.refine_iters == 0 or not 0.0 < opt.refine_tol <= ROWS_HELD_SHARE * PIN_GAP_TOL:
        return CHAIN_GENERAL
    most = opt.max_substeps
    n = turn_substeps(m, s, ws, step_length, most)
    if n == 1:
        code = chain_part(m, s, ws, opt, u, step_length)
        if code != 0:
            if code == CHAIN_AGAIN:
                begin_again(s, ws)
            return CHAIN_GENERAL
        n = turn_substeps(m, s, ws, step_length, most)
        if n == 1:
            ws.info[INFO_TURN_SUBSTEPS] = 1
            keep_step_path(ws, False)
            return 0
        n = max(n, 2)
        begin_again(s, ws)
    count = s.step[0]
    t0 = s.time[0]
    copy_state(s, ws.start)
    code = 0
    for k in range(n):
        s.step[0] = count
        code = chain_part(m, s, ws, opt, u, step_length / n)
        if code != 0:
            break
        keep_step_path(ws, k > 0)
    if code == 0 and opt.jump_limit > 0.0:
        code = check_moves(m, s, ws, ws.start.q, True, opt.jump_limit)
    if code != 0:
        begin_again_from(s, ws, ws.start)
        return CHAIN_GENERAL
    s.step[0] = count + 1
    s.time[0] = t0 + step_length
    ws.info[INFO_TURN_SUBSTEPS] = n
    return 0


@kernel(inline="always")
def _step(m, s, ws, opt, u):
    """Advance s by one step of opt.dt (0: the model's m.dt) under actuator commands u with
    StepOptions.integrator; return the guard code. A step that stands ends with
    ws.act_power over its move (forces.end_power: h times it is the work of the commands in
    the step)."""
    code = _advance(m, s, ws, opt, u)
    if code == 0 and m.act_kind.shape[0] > 0:
        # the step's start: ws.start where an Euler step was taken in sub-steps, else ws.prev
        # (an accurate step's stages keep it there throughout)
        parts = opt.integrator == INTEGRATOR_EULER and ws.info[INFO_TURN_SUBSTEPS] > 1
        end_power(m, s, ws, ws.start.q if parts else ws.prev.q,
                  opt.dt if opt.dt > 0.0 else m.dt)
    return code


@kernel(inline="always")
def _advance(m, s, ws, opt, u):
    """_step's step, its actuators' power at the step's start rates."""
    step_length = opt.dt if opt.dt > 0.0 else m.dt
    ws.info[INFO_CHAIN_PATH] = 0
    if opt.integrator == INTEGRATOR_EULER:
        begin_step(ws)
        if ws.chain_on[0] == 1 and chain_step(m, s, ws, opt, u, step_length) == 0:
            ws.info[INFO_CHAIN_PATH] = 1
            return 0
        most = opt.max_substeps
        # joints alone (no ground contact touching at the start): a step that leaves a pin
        # open beyond gross_limit is taken again in sub-steps, twice as many each time
        alone = not touching_ground(s, ws)
        n = turn_substeps(m, s, ws, step_length, most)
        if n == 1:
            code = step_of_length(m, s, ws, opt, u, step_length, False)
            if code == GUARD_ROOM:
                put_back(s, ws)
                return code
            # a body that began turning fast within the step (an impact spinning a light
            # link up) is judged at the step's answer: taken again, in sub-steps; so is a
            # step whose correction moved a body farther than its velocities explain, and
            # one of joints alone that left a pin open
            n = turn_substeps(m, s, ws, step_length, most)
            if n == 1 and not ((code == GUARD_JUMP or (code == GUARD_GROSS and alone))
                               and most > 1):
                ws.info[INFO_TURN_SUBSTEPS] = 1
                keep_step_path(ws, False)
                return code
            n = max(n, 2)
            begin_again(s, ws)
        # sub-steps, each a whole step of its own (solve, positions, audit, guards), that
        # count as one: an error names this step. A sub-step whose correction moves a body
        # farther than its velocities explain (a loop near a dead point closing its drift, a
        # turn the count above did not foresee) has the step taken again in twice as many
        # (at most max_substeps) before the error stands
        count = s.step[0]
        t0 = s.time[0]
        copy_state(s, ws.start)
        while True:
            for k in range(n):
                s.step[0] = count
                code = step_of_length(m, s, ws, opt, u, step_length / n, False)
                keep_step_path(ws, k > 0)
                if code == GUARD_ROOM:
                    put_back_from(s, ws, ws.start)
                if code != 0:
                    break
            # over the whole step too: the sub-steps' summed paths plus jump_limit once
            if code == 0 and opt.jump_limit > 0.0:
                code = check_moves(m, s, ws, ws.start.q, True, opt.jump_limit)
            if (code == GUARD_JUMP or (code == GUARD_GROSS and alone)) and n < most:
                if ws.room[1] == 1:
                    put_back_from(s, ws, ws.start)       # (the broad phase's pairs too)
                else:
                    begin_again_from(s, ws, ws.start)
                n = min(2 * n, most)
                continue
            if code != 0:
                if code != GUARD_ROOM:
                    copy_state(ws.start, ws.prev)   # (the error names the step's start)
                    ws.prev_whole[0] = 1
                return code
            break
        s.step[0] = count + 1
        s.time[0] = t0 + step_length
        ws.info[INFO_TURN_SUBSTEPS] = n
        return 0
    return accurate_step(m, s, ws, opt, u, step_length)
