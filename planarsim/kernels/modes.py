"""Stage 6: contact-mode and joint-limit checks after a solve.

Rules (seed 002 section 5 plus the sliding mode of its footnote):
  pinned  -> free     if the normal impulse pulls (lambda_n < 0)
  pinned  -> sliding  if |lambda_t| > mu lambda_n (slip opposite to the friction impulse)
  sliding -> pinned   if the slip velocity at the end of the step has stopped or reversed
  sliding -> free     if lambda_n < 0
  free    -> touching if the contact would end the step below the ground (every step, every
                      contact: penetration is never tolerated; point masses use CCD instead);
                      sliding if its point moves along the ground, else pinned
Which pinned/sliding contacts are checked is the strategy: MODES_ALTERNATING checks the one
under the round-robin cursor, once per step, plus any contact engaged during this step (an
impact must be allowed to slide at once, or a pinned impact would stop a sliding body dead);
and every sliding contact whose friction would reverse its slip sticks at once, in every
round (an overshooting friction impulse adds energy). MODES_ALL checks every contact in
every round.
Joint limits engage when the angle would pass the limit and release when their impulse pulls.
"""
from ._jit import kernel
from .contacts import MODE_FREE, MODE_PINNED, MODE_SLIDING, engage_contact
from .forces import point_velocity
from .math2d import world_point
from .rows import ROW_CONTACT_N, ROW_CONTACT_T, ROW_LIMIT_HI, ROW_LIMIT_LO

MODES_ALTERNATING = 0
MODES_ALL = 1


@kernel
def gather_contact_impulses(m, s, ws):
    """ws.contact_impulse[i] = (lambda_n, lambda_t) from the last solve (zero when free)."""
    for i in range(ws.contact_impulse.shape[0]):
        ws.contact_impulse[i, 0] = 0.0
        ws.contact_impulse[i, 1] = 0.0
    for r in range(ws.n_row[0]):
        o = ws.row_owner[r]
        if ws.row_kind[r] == ROW_CONTACT_N:
            ws.contact_impulse[o, 0] = ws.lam[r]
            if s.contact_mode[o] == MODE_SLIDING:
                ws.contact_impulse[o, 1] = -m.contact_mu[o] * s.contact_slip[o] * ws.lam[r]
        elif ws.row_kind[r] == ROW_CONTACT_T:
            ws.contact_impulse[o, 1] = ws.lam[r]


@kernel
def contact_velocity(m, s, ws, i, vel):
    """Normal and tangential velocity [m/s] of contact i's material point under `vel`."""
    b = m.contact_body[i]
    px, py = world_point(s.q, ws.body_cs, b, ws.contact_anchor[i, 0], ws.contact_anchor[i, 1])
    vx, vy = point_velocity(s.q, vel, b, px, py)
    nx = ws.contact_normal[i, 0]
    ny = ws.contact_normal[i, 1]
    return nx * vx + ny * vy, ny * vx - nx * vy


@kernel
def check_contact(m, s, ws, i):
    """Apply the release / slide / stick rules to contact i; return 1 if its mode changed."""
    mode = s.contact_mode[i]
    ln = ws.contact_impulse[i, 0]
    lt = ws.contact_impulse[i, 1]
    if mode == MODE_PINNED:
        if ln < 0.0:
            s.contact_mode[i] = MODE_FREE
            return 1
        if abs(lt) > m.contact_mu[i] * ln * (1.0 + 1e-12):
            s.contact_mode[i] = MODE_SLIDING
            s.contact_slip[i] = -1.0 if lt > 0.0 else 1.0
            return 1
    elif mode == MODE_SLIDING:
        if ln < 0.0:
            s.contact_mode[i] = MODE_FREE
            return 1
        vn, vt = contact_velocity(m, s, ws, i, ws.v_new)
        if vt * s.contact_slip[i] <= 0.0:
            s.contact_mode[i] = MODE_PINNED
            return 1
    return 0


@kernel
def engage_contacts(m, s, ws, h, include_ccd):
    """Pin every enabled free contact that would end the step below the ground (contacts with
    CCD are left to the time-of-impact split unless include_ccd)."""
    changed = 0
    for i in range(m.contact_body.shape[0]):
        if s.contact_mode[i] != MODE_FREE or s.contact_enabled[i] == 0:
            continue
        if m.contact_ccd[i] == 1 and not include_ccd:
            continue
        vn, vt = contact_velocity(m, s, ws, i, ws.v_new)
        if ws.contact_gap[i] + h * vn < 0.0:
            engage_contact(m, s, ws, i, vn, vt)
            changed += 1
    return changed


@kernel
def check_limits(m, s, ws, h):
    """Engage limits the angle would pass; release limits whose impulse pulls."""
    changed = 0
    for r in range(ws.n_row[0]):
        kind = ws.row_kind[r]
        if (kind == ROW_LIMIT_LO or kind == ROW_LIMIT_HI) and ws.lam[r] < 0.0:
            s.limit_active[ws.row_owner[r], kind - ROW_LIMIT_LO] = 0
            changed += 1
    for j in range(m.pin_body.shape[0]):
        lo = m.pin_limit[j, 0]
        hi = m.pin_limit[j, 1]
        a = m.pin_body[j, 0]
        b = m.pin_body[j, 1]
        ang = s.q[b, 2] - m.pin_ref[j] + h * ws.v_new[b, 2]
        if a >= 0:
            ang -= s.q[a, 2] + h * ws.v_new[a, 2]
        if s.limit_active[j, 0] == 0 and ang < lo:
            s.limit_active[j, 0] = 1
            changed += 1
        if s.limit_active[j, 1] == 0 and ang > hi:
            s.limit_active[j, 1] = 1
            changed += 1
    return changed


@kernel
def update_modes(m, s, ws, h, strategy, first_round, include_ccd):
    """One round of mode checks after a solve; return the number of changes."""
    gather_contact_impulses(m, s, ws)
    changed = engage_contacts(m, s, ws, h, include_ccd) + check_limits(m, s, ws, h)
    nc = m.contact_body.shape[0]
    if nc == 0:
        return changed
    if strategy == MODES_ALL:
        for i in range(nc):
            if s.contact_enabled[i]:
                changed += check_contact(m, s, ws, i)
    else:
        # the contact under the cursor in the first round; contacts engaged during this
        # step in every round, so an impact can start sliding at once; and in every round
        # any sliding contact whose friction would reverse its slip (that would add energy)
        cursor = s.mode_cursor[0] % nc
        for i in range(nc):
            if s.contact_enabled[i] == 0:
                continue
            if (first_round and i == cursor) or ws.contact_new[i] == 1:
                changed += check_contact(m, s, ws, i)
            elif s.contact_mode[i] == MODE_SLIDING:
                vn, vt = contact_velocity(m, s, ws, i, ws.v_new)
                if vt * s.contact_slip[i] <= 0.0:
                    s.contact_mode[i] = MODE_PINNED
                    changed += 1
    return changed
