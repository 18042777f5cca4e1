"""Stage 5: the rules of contacts and limits, and the checks of a solve's answer against them.

Rules (Kelly 2014, section 5 plus the sliding mode of its footnote), which a consistent answer
meets for every contact and limit at once:
  pinned   its normal impulse pushes (lambda_n >= 0) and friction is inside the cone
           (|lambda_t| <= mu lambda_n); the point does not move along the ground
  sliding  it pushes; friction -mu lambda_n s at the cone's edge, opposite the slip s, and the
           slip does not reverse within the step
  free     no impulse, and the point does not end the step below the ground
  limits   a limit's impulse pushes; an inactive limit is not passed
  joint friction  a stuck joint's impulse within F h; a slipping joint's rate not reversed
           (joint_friction.py)
rule_breaks checks a guess's answer (the modes carried over), each contact by contact_rule,
beyond the solve's rounding; switch_broken switches the contacts (and limits) that break a rule
by those same tolerances (the switching rounds); engage_* bring contacts and limits the motion
would push through into the problem; seed_rule is the alternating strategy's one-contact
re-examination by the rules' bare signs (check_contact: release if it pulls, slide outside the
cone, stick on reversal); modes_from_solution reads the modes off a complementarity solution.
"""
import math

from ...compile import kernel
from ..info import INFO_GUESS_EQUATIONS
from ..codes import (BROKE_CONE, BROKE_EQUATION, BROKE_LIMIT, BROKE_PULL, BROKE_REVERSAL,
                     CONTACT_PAIR, GUESS_PENDING, MODE_FREE, MODE_PINNED, MODE_SLIDING,
                     N_BROKEN)
from ..geometry.contacts import contact_velocity, engage_contact, pair_motion_scale, refresh_contact
from ..geometry.pair import PAIR_ENGAGE_SLACK, pair_speed
from ..checks.audit import IMPULSE_FLOOR
from ..checks.work import VELOCITY_FLOOR
from .mixed_lcp import is_sliding_solution
from ..constraints.limit import limit_side
from ..constraints.joints import is_slider, joint_position_rate
from ..constraints.joint_friction import friction_breaks
from ..constraints.rows import (has_mode_rows, is_limit_row, is_normal_row, is_soft_row,
                                is_tangent_row)
from ..constraints.soft import soft_compliance
from .solve import row_dot

# a solve's answer breaks a rule when it misses it by more than this share of its own scale
SOLVE_REL_TOL = 1e-9
SLIP_ROUNDING = 1e-12


@kernel
def gather_contact_impulses(m, s, ws):
    """ws.contact_impulse[i] = (lambda_n, lambda_t) from the last solve (zero when free)."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        ws.contact_impulse[i, 0] = 0.0
        ws.contact_impulse[i, 1] = 0.0
    for r in range(ws.n_row[0]):
        o = ws.row_owner[r]
        if is_normal_row(ws.row_kind[r]):
            ws.contact_impulse[o, 0] = ws.lam[r]
            if s.contact_mode[o] == MODE_SLIDING:
                ws.contact_impulse[o, 1] = -m.contact_mu[o] * s.contact_slip[o] * ws.lam[r]
        elif is_tangent_row(ws.row_kind[r]):
            ws.contact_impulse[o, 1] = ws.lam[r]


# the rule a contact breaks in an answer (contact_rule), each calling for its switch
RULE_KEPT = 0
RULE_PULLS = 1      # its normal impulse pulls: released
RULE_CONE = 2       # pinned, its friction beyond the cone: slides against its friction
RULE_REVERSED = 3   # sliding, its slip reversed: sticks


@kernel
def _switch(s, o, rule, lt):
    """Contact o switched by the rule it breaks (RULE_*; lt [N s] its friction impulse, against
    which it slides when it leaves the cone)."""
    if rule == RULE_PULLS:
        s.contact_mode[o] = MODE_FREE
    elif rule == RULE_CONE:
        s.contact_mode[o] = MODE_SLIDING
        s.contact_slip[o] = -1.0 if lt > 0.0 else 1.0
    elif rule == RULE_REVERSED:
        s.contact_mode[o] = MODE_PINNED


@kernel
def check_contact(m, s, ws, i):
    """Apply the release / slide / stick rules to contact i by their bare signs (ws.
    contact_impulse); return 1 if its mode changed."""
    mode = s.contact_mode[i]
    ln = ws.contact_impulse[i, 0]
    lt = ws.contact_impulse[i, 1]
    rule = RULE_KEPT
    if mode != MODE_FREE and ln < 0.0:
        rule = RULE_PULLS
    elif mode == MODE_PINNED and abs(lt) > m.contact_mu[i] * ln * (1.0 + 1e-12):
        rule = RULE_CONE
    elif mode == MODE_SLIDING and m.contact_mu[i] != 0.0:   # (frictionless: it slides
        vn, vt = contact_velocity(m, s, ws, i, ws.v_new)    # whichever way it moves)
        if vt * s.contact_slip[i] <= 0.0:
            rule = RULE_REVERSED
    _switch(s, i, rule, lt)
    return 0 if rule == RULE_KEPT else 1


@kernel
def engage_contacts(m, s, ws, h, include_ccd, vel):
    """Bring into touch every enabled free contact, not yet in the complementarity problem,
    that would end the step below the ground under velocity vel (contacts with CCD are left to
    the time-of-impact split unless include_ccd). Returns how many."""
    changed = 0
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if s.contact_mode[i] != MODE_FREE or s.contact_enabled[i] == 0:
            continue
        if ws.contact_candidate[i] == 1:
            continue
        if m.contact_ccd[i] == 1 and not include_ccd:
            continue
        if not may_reach_ground(m, ws, i, h, vel):
            continue
        if ws.contact_stale[i] == 1:
            # its gap was a lower bound: query it, and test it again with its real gap
            refresh_contact(m, s, ws, i)
            if not may_reach_ground(m, ws, i, h, vel):
                continue
        vn, vt = contact_velocity(m, s, ws, i, vel)
        # a shape pair touching at rest sees its relative velocity as rounding of either
        # sign (both bodies move alike): it engages when pushed in beyond PAIR_ENGAGE_SLACK,
        # else a contact carrying no load would be released and engaged again without end
        slack = PAIR_ENGAGE_SLACK if m.contact_kind[i] == CONTACT_PAIR else 0.0
        if ws.contact_gap[i] + h * vn < -slack:
            engage_contact(m, s, ws, i, vn, vt)
            changed += 1
    return changed


@kernel
def may_reach_ground(m, ws, i, h, vel):
    """False when contact i's point surely stays above the ground for a step of h under
    vel: its gap exceeds h (|v_x| + |v_y| + |omega| r), r its distance from the COM (a
    bound on its speed; no trigonometry)."""
    if m.contact_kind[i] == CONTACT_PAIR:
        # a slot without a point (gap inf) is out of reach until the next narrow phase
        return ws.contact_gap[i] < math.inf and ws.contact_gap[i] <= h * pair_speed(m, ws, i, vel)
    b = m.contact_body[i]
    ax = ws.contact_anchor[i, 0]
    ay = ws.contact_anchor[i, 1]
    speed = abs(vel[b, 0]) + abs(vel[b, 1]) + abs(vel[b, 2]) * math.sqrt(ax * ax + ay * ay)
    return ws.contact_gap[i] <= h * speed


@kernel
def engage_limits(m, s, ws, h, vel):
    """Engage every joint limit, not yet in the complementarity problem, that the joint's
    coordinate (a hinge's angle, a slider's slide) would pass under velocity vel. Returns how
    many."""
    changed = 0
    for j in range(m.pin_body.shape[0]):
        lo = m.pin_limit[j, 0]
        hi = m.pin_limit[j, 1]
        if lo == -math.inf and hi == math.inf:
            continue        # no limit to engage
        if is_slider(m, j):
            # the slide at the end of the step, to first order
            x, rate = joint_position_rate(m, s.q, ws.body_cs, vel, j)
            ang = x + h * rate
        else:
            a = m.pin_body[j, 0]
            b = m.pin_body[j, 1]
            ang = s.q[b, 2] - m.pin_ref[j] + h * vel[b, 2]
            if a >= 0:
                ang -= s.q[a, 2] + h * vel[a, 2]
        if s.limit_active[j, 0] == 0 and ws.limit_candidate[j, 0] == 0 and ang < lo:
            s.limit_active[j, 0] = 1
            changed += 1
        if s.limit_active[j, 1] == 0 and ws.limit_candidate[j, 1] == 0 and ang > hi:
            s.limit_active[j, 1] = 1
            changed += 1
    return changed


@kernel
def _contact_size(m, s, ws, r):
    """|lambda_n| + |lambda_t| [N s] of the contact whose normal row is r (its tangent row
    follows it; a sliding contact has none, its friction is mu lambda_n)."""
    if r + 1 < ws.n_row[0] and is_tangent_row(ws.row_kind[r + 1]):
        return abs(ws.lam[r]) + abs(ws.lam[r + 1])
    return abs(ws.lam[r]) * (1.0 + m.contact_mu[ws.row_owner[r]])


@kernel
def impulse_floor(ws):
    """The rounding [N s] of a contact that carries no load in the last answer (a
    statically indeterminate pile: a box on two): IMPULSE_FLOOR of its largest normal
    impulse."""
    big = 0.0
    for r in range(ws.n_row[0]):
        if is_normal_row(ws.row_kind[r]):
            big = max(big, abs(ws.lam[r]))
    return IMPULSE_FLOOR * big


@kernel
def _slip_reversed(m, s, ws, o):
    """Sliding contact o's slip reversed in the answer ws.v_new beyond rounding.
    Friction along a reversed slip would add energy: only a reversal at the rounding level
    passes, the solve's (VELOCITY_FLOOR: a contact velocity the audit's work rule takes for
    rounding) and that of the contact's free motion (of a shape pair, of both bodies'
    motion: falling together, their relative motion is rounding). A contact at its cone's
    edge in a pile at rest otherwise switched between pinned (friction 1e-6 beyond the
    cone) and sliding (its slip reversed at 1e-14 to 1e-11 m/s) at every step, each step
    then a complementarity solve of the whole pile."""
    vn, vt = contact_velocity(m, s, ws, o, ws.v_new)
    vn_free, vt_free = contact_velocity(m, s, ws, o, ws.v_pred)
    scale = abs(vn_free) + abs(vt_free)
    if m.contact_kind[o] == CONTACT_PAIR:
        scale += pair_motion_scale(s, ws, o, ws.v_pred)
    return vt * s.contact_slip[o] < -(VELOCITY_FLOOR + SLIP_ROUNDING * scale)


@kernel
def _pulls(m, s, ws, r, floor):
    """The contact of normal row r pulls, judged against its own impulse (as the audit
    judges it) and floor (impulse_floor)."""
    return ws.lam[r] < -(SOLVE_REL_TOL * _contact_size(m, s, ws, r) + floor)


@kernel
def _beyond_cone(m, ws, r, floor):
    """The friction of tangent row r (its normal row r - 1) leaves the cone beyond rounding."""
    size = abs(ws.lam[r]) + abs(ws.lam[r - 1])
    bound = m.contact_mu[ws.row_owner[r]] * ws.lam[r - 1]
    return abs(ws.lam[r]) > bound + SOLVE_REL_TOL * size + floor


@kernel
def contact_rule(m, s, ws, r, floor):
    """The rule (RULE_*) the contact of normal row r breaks in the last answer, by
    rule_breaks' tolerances (floor: impulse_floor), RULE_KEPT if none."""
    if _pulls(m, s, ws, r, floor):
        return RULE_PULLS
    o = ws.row_owner[r]
    if s.contact_mode[o] == MODE_SLIDING:
        if _slip_reversed(m, s, ws, o):
            return RULE_REVERSED
    elif r + 1 < ws.n_row[0] and is_tangent_row(ws.row_kind[r + 1]):
        if _beyond_cone(m, ws, r + 1, floor):
            return RULE_CONE
    return RULE_KEPT


@kernel
def switch_broken(m, s, ws, only_first):
    """The contacts whose rules the last answer breaks (by rule_breaks' tolerances)
    switched by the rule each breaks, then the engaged limits that pull beyond them: every
    one, or only_first the contact of least index (else the first such limit). A contact
    that keeps its rules to those tolerances keeps its mode: switched on any reversal of its
    slip (rounding: 1e-15 m/s), two contacts at their cones' edges in a pile took turns
    breaking their cones, round after round, until the complementarity solve of the whole
    pile. Returns how many changed."""
    floor = impulse_floor(ws)
    n = ws.n_row[0]
    first = -1
    first_lt = 0.0
    first_rule = RULE_KEPT
    changed = 0
    for r in range(n):
        if not is_normal_row(ws.row_kind[r]):
            continue
        rule = contact_rule(m, s, ws, r, floor)
        if rule == RULE_KEPT:
            continue
        o = ws.row_owner[r]
        lt = ws.lam[r + 1] if rule == RULE_CONE else 0.0    # (its tangent row follows)
        if only_first:
            if first < 0 or o < first:
                first = o
                first_lt = lt
                first_rule = rule
            continue
        _switch(s, o, rule, lt)
        changed += 1
    if first >= 0:
        _switch(s, first, first_rule, first_lt)
        return 1
    tol_lam = SOLVE_REL_TOL * largest_impulse(ws)
    for r in range(n):
        kind = ws.row_kind[r]
        if is_limit_row(kind) and ws.lam[r] < -tol_lam:
            s.limit_active[ws.row_owner[r], limit_side(kind)] = 0
            changed += 1
            if only_first:
                break
    return changed


@kernel
def largest_impulse(ws):
    """The largest |impulse| [N s or N m s] of the last answer's rows."""
    big = 0.0
    for r in range(ws.n_row[0]):
        big = max(big, abs(ws.lam[r]))
    return big


@kernel
def _tally(ws):
    """The counts of a check of the step's guess (ws.broken_rules[GUESS_PENDING] set by
    step.solve_modes) added to the step's INFO_GUESS_* (summed over its parts)."""
    if ws.broken_rules[GUESS_PENDING] == 1:
        ws.broken_rules[GUESS_PENDING] = 0
        for k in range(N_BROKEN):
            ws.info[INFO_GUESS_EQUATIONS + k] += ws.broken_rules[k]


@kernel
def rule_breaks(m, s, ws, h, equalities):
    """How many rows of the last solve break a rule of contact and limits (the solve took the
    modes as given; this checks its answer): an equality row not met (a dependent row dropped
    whose residual the others do not remove), a normal or limit impulse that pulls, friction
    outside its cone, a sliding contact whose slip reversed. Tolerances are relative to the
    impulses' and velocities' own size (rounding, not physics): a contact's own impulse for
    its pull and cone rules (an answer that passes here passes the audit's). equalities: also
    check every row's equation (needed where the solve dropped a dependent row or had no
    symmetric factorisation; a backward-stable L D L^T of all rows meets them to rounding).
    The count of each rule but the joints' friction goes to ws.broken_rules (BROKE_*)."""
    n = ws.n_row[0]
    for k in range(N_BROKEN):
        ws.broken_rules[k] = 0
    # a frictional joint's rule (joint_friction.py): a stuck one's impulse within F h, a
    # slipping one's rate not reversed (a slipping joint has no row)
    friction = friction_breaks(m, ws)
    if not equalities and not has_mode_rows(ws, n):
        _tally(ws)
        return friction     # joints only, their equations met by the solve
    big_b = 0.0
    for r in range(n):
        big_b = max(big_b, abs(ws.row_b[r]))
    tol_lam = SOLVE_REL_TOL * largest_impulse(ws)
    floor = impulse_floor(ws)
    tol_w = SOLVE_REL_TOL * (big_b + 1.0)
    breaks = friction
    for r in range(n):
        kind = ws.row_kind[r]
        o = ws.row_owner[r]
        # residual w = J (v_new - v*) + b of the row as solved (an equality here)
        if equalities:
            w = (row_dot(ws, r, ws.row_J, ws.v_new) - row_dot(ws, r, ws.row_J, ws.v_pred)
                 + ws.row_b[r])
            if is_soft_row(kind):
                w += soft_compliance(ws, r) * ws.lam[r]
            if abs(w) > tol_w:
                ws.broken_rules[BROKE_EQUATION] += 1
        if is_limit_row(kind):
            if ws.lam[r] < -tol_lam:
                ws.broken_rules[BROKE_LIMIT] += 1
        elif is_normal_row(kind):
            if _pulls(m, s, ws, r, floor):
                ws.broken_rules[BROKE_PULL] += 1
            if s.contact_mode[o] == MODE_SLIDING and _slip_reversed(m, s, ws, o):
                ws.broken_rules[BROKE_REVERSAL] += 1
        elif is_tangent_row(kind):
            if _beyond_cone(m, ws, r, floor):
                ws.broken_rules[BROKE_CONE] += 1
    for k in range(N_BROKEN):
        breaks += ws.broken_rules[k]
    _tally(ws)
    return breaks


@kernel
def seed_rule(m, s, ws, i):
    """The alternating check (Kelly 2014) of one contact: release it if it pulls, let it slide if
    its friction leaves the cone, stick it if its slip reversed. The same check goes to every
    contact engaged during this step by the free motion's prediction (ws.contact_new == 1):
    the free motion pushes a point resting a hair above the ground into it every step, while
    the impulses of the other contacts may hold it clear. Returns how many changed."""
    gather_contact_impulses(m, s, ws)
    changed = check_contact(m, s, ws, i)
    for j in range(ws.n_live[0]):
        k = ws.live[j]
        if k != i and ws.contact_new[k] == 1:
            changed += check_contact(m, s, ws, k)
    return changed


@kernel
def modes_from_solution(m, s, ws):
    """Contact modes and limits from a complementarity solution over rows 0..n-1 (every
    candidate contact had its normal and tangent rows): free where the normal impulse is 0,
    sliding where the slip speed is positive (friction at the cone's edge, slip s opposite to
    it), pinned otherwise; a limit whose impulse is 0 is released."""
    n = ws.n_row[0]
    for r in range(n):
        kind = ws.row_kind[r]
        o = ws.row_owner[r]
        if is_normal_row(kind) and (r + 1 == n or not is_tangent_row(ws.row_kind[r + 1])):
            # solved without friction (the frictionless rule): F = n, a slip of 0
            if ws.lam[r] <= 0.0:
                s.contact_mode[o] = MODE_FREE
            else:
                s.contact_mode[o] = MODE_SLIDING
                s.contact_slip[o] = 0.0
        elif is_tangent_row(kind):
            if ws.lam[r - 1] <= 0.0:
                s.contact_mode[o] = MODE_FREE
            elif is_sliding_solution(m, s, ws, r) and ws.lam[r] != 0.0:
                s.contact_mode[o] = MODE_SLIDING
                s.contact_slip[o] = -1.0 if ws.lam[r] > 0.0 else 1.0
            else:
                s.contact_mode[o] = MODE_PINNED
        elif is_limit_row(kind):
            if ws.lam[r] <= 0.0:
                s.limit_active[o, limit_side(kind)] = 0
