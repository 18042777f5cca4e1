"""The guaranteed solves: contact modes and impulses as one complementarity problem.

Velocity stage (solve_contacts): every candidate contact (touching, or one the motion would
push into the ground; every shape pair's point within touch) enters with its normal and
tangent rows, every candidate limit with its row; solve_mixed_lcp finds impulses that push, friction inside its cone and opposing any slip,
joints held; the modes are read off the answer. A contact outside the problem that the new
velocity would still push into the ground joins it and the problem is solved again (at most
once per contact: a finite loop, no cap to reach). If the problem with friction has no answer
on Lemke's path (Painleve-type configurations; rounding), the rule is: solve it without
friction (a positive semidefinite problem, always solvable here, whose inelastic impulses can
only remove energy), and count it in the audit.

Position stage (project_positions): the configuration after integrating, projected onto
closed joints and contacts on or above the ground: the smallest mass-weighted move
dq = W J^T mu with joint errors 0 and gaps >= 0 (mu >= 0 on contacts and limits), a
complementarity problem without friction, linearised at the current configuration and
repeated until every error is below tolerance. Joint corrections also change the velocity by
dq / h (as the Newton correction does); contact corrections move positions only.
"""
import math

from ...compile import kernel, part
from ..checks.audit import AUDIT_FALLBACK, AUDIT_UNSOLVED, note
from ..info import INFO_LCP_PIVOTS, INFO_LCP_SOLVES, INFO_PROJECTIONS
from ..codes import CONTACT_PAIR, MODE_FREE, MODE_PINNED
from ..geometry.contacts import query_contact
from ..geometry.broad_phase import merge_contacts, sweep_pairs
from ..geometry.pair import PAIR_MARGIN, find_pair, place_shapes
from .islands import group_rows
from .lcp import LCP_SOLVED
from ..math2d import update_trig
from .mixed_lcp import assemble_dense, lcp_room, solve_mixed_lcp
from .modes import engage_contacts, engage_limits, gather_contact_impulses, modes_from_solution
from ..constraints.limit import add_violated_limit_rows
from ..constraints.rod import add_rod_row
from ..constraints.row_list import move_row
from ..constraints.rows import (add_contact_rows, add_joint_rows, build_rows, eval_rows,
                                is_joint_row, is_limit_row, is_tangent_row)
from .solve import apply_impulses, fill_row_b, row_dot

# Lemke's path is finite; the cap only stops a path that rounding has sent astray
PIVOTS_PER_VARIABLE = 20
# a projection move that raised the error is halved at most this many times
PROJECTION_HALVINGS = 6
# the projection's trust in its linearisation (a trust region on the move's length): a move
# that removed less than TRUST_LOW of the error it started from (its rows' curvature at that
# scale is as large as their slope: a straight edge pivoting on a crest of radius R dips
# R phi^2 / 2, the next linearisation swings it back, a 2-cycle) has the next move taken at
# half its length; one that removed more than TRUST_HIGH doubles it again (at most whole:
# Newton's quadratic end). The next move is at least 0.5 ** PROJECTION_HALVINGS of Newton's,
# and the back-track's halvings (share) may shorten it as many times again.
TRUST_LOW = 0.25
TRUST_HIGH = 0.75


@kernel
def _drop_tangent_rows(ws, n):
    """Remove the friction rows of the islands that failed (ws.island_failed; the
    frictionless rule) from rows 0..n-1, the other rows keeping their impulses; returns the
    rows left."""
    k = 0
    for r in range(n):
        if is_tangent_row(ws.row_kind[r]) and ws.island_failed[ws.row_island[r]] == 1:
            continue
        if k != r:
            move_row(ws, k, r)
            ws.lam[k] = ws.lam[r]
            ws.row_slip[k] = ws.row_slip[r]
            ws.row_island[k] = ws.row_island[r]
        k += 1
    ws.n_row[0] = k
    return k


@kernel
def _solve_island(m, ws, k, vars_per_row, floor):
    """The complementarity problem of island k (kernels/solver/islands.py, grouped), its answer
    checked at a scale of at least floor; Lemke's path capped at PIVOTS_PER_VARIABLE per
    possible variable (vars_per_row per row). Its own scale into ws.island_scale[k]. Returns
    True if solved; False too for an island beyond the dense storage (lcp_room: the step
    begins again with more, or it has more rows than the storage may grow to hold)."""
    start = ws.island_start[k]
    count = ws.island_start[k + 1] - start
    if not lcp_room(ws, count):
        ws.island_scale[k] = 0.0
        return False
    assemble_dense(m, ws, ws.island_rows, start, count)
    cap = PIVOTS_PER_VARIABLE * (vars_per_row * count + 10)
    status, pivots, scale = solve_mixed_lcp(m, ws, ws.island_rows, start, count, cap, floor)
    ws.info[INFO_LCP_PIVOTS] += pivots
    ws.island_scale[k] = scale
    return status == LCP_SOLVED


@kernel(inline="never")
def _solve_islands(m, ws, n_island, vars_per_row, only_failed):
    """Each island's problem (only those marked in ws.island_failed if only_failed); an island
    without an answer at its own scale is solved again at the largest island's, the scale its
    answer would be checked at inside one problem of all islands. Marks ws.island_failed;
    returns how many islands have no answer."""
    top = 0.0
    for k in range(n_island):
        if only_failed and ws.island_failed[k] == 0:
            top = max(top, ws.island_scale[k])
            continue
        ws.island_failed[k] = 0 if _solve_island(m, ws, k, vars_per_row, 0.0) else 1
        top = max(top, ws.island_scale[k])
    failed = 0
    for k in range(n_island):
        if ws.island_failed[k] == 1 and ws.island_scale[k] < top:
            if _solve_island(m, ws, k, vars_per_row, top):
                ws.island_failed[k] = 0
        failed += ws.island_failed[k]
    return failed


@kernel
def _solve_by_islands(m, ws, n, vars_per_row):
    """Rows 0..n-1 grouped by island (kernels/solver/islands.py) and every island's problem solved
    (_solve_islands). Where one has no answer and there are others, all rows are solved as
    one problem once more: Lemke's path through the joint problem is another path (its
    covering vector differs on each island), which may end where the island's alone did not.
    Returns (islands, how many have no answer; ws.island_failed marks them, and the rows stay
    grouped)."""
    n_island = group_rows(ws, n)
    failed = _solve_islands(m, ws, n_island, vars_per_row, False)
    if failed == 0 or n_island == 1 or not lcp_room(ws, n):
        return n_island, failed
    for r in range(n):
        ws.island_rows[r] = r
    assemble_dense(m, ws, ws.island_rows, 0, n)
    status, pivots, scale = solve_mixed_lcp(m, ws, ws.island_rows, 0, n,
                                            PIVOTS_PER_VARIABLE * (vars_per_row * n + 10), 0.0)
    ws.info[INFO_LCP_PIVOTS] += pivots
    group_rows(ws, n)
    if status == LCP_SOLVED:
        for k in range(n_island):
            ws.island_failed[k] = 0
        return n_island, 0
    # the joint solve left every impulse at 0: each island's answer again
    return n_island, _solve_islands(m, ws, n_island, vars_per_row, False)


@kernel
def touching_pair(m, s, ws, i):
    """Contact i is an enabled shape pair's point touching (within PAIR_MARGIN): a candidate
    of the complementarity problem even while free. Bodies resting on bodies move alike, so
    the motion pushes none of them in until the one below has stopped: engaged one by one a
    column of N boxes would take N solves, while as candidates those not needed end free."""
    return (m.contact_kind[i] == CONTACT_PAIR and s.contact_enabled[i] == 1
            and ws.contact_gap[i] <= PAIR_MARGIN)


@kernel
def _lcp_once(m, s, ws, h):
    """Build the rows of every candidate (contacts pinned: normal and tangent rows) and solve
    the complementarity problem; v_new from its impulses. Returns True if solved."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        ws.contact_candidate[i] = 0
        if s.contact_mode[i] != MODE_FREE or touching_pair(m, s, ws, i):
            s.contact_mode[i] = MODE_PINNED
            ws.contact_candidate[i] = 1
    for j in range(m.pin_body.shape[0]):
        ws.limit_candidate[j, 0] = s.limit_active[j, 0]
        ws.limit_candidate[j, 1] = s.limit_active[j, 1]
    build_rows(m, s, ws, h)
    n = ws.n_row[0]
    fill_row_b(m, ws, h, n)
    ws.info[INFO_LCP_SOLVES] += 1
    ws.joint_pivot[0] = 1.0         # (the islands' joint blocks: mixed_lcp.solve_mixed_lcp)
    n_island, failed = _solve_by_islands(m, ws, n, 4)
    solved = failed == 0
    if not solved:
        # an island without an answer with friction on Lemke's path: the frictionless rule
        for k in range(n_island):
            ws.island_fallback[k] = ws.island_failed[k]
        n = _drop_tangent_rows(ws, n)
        group_rows(ws, n)       # the same islands (a tangent row's bodies are its normal's)
        solved = _solve_islands(m, ws, n_island, 4, True) == 0
        for k in range(n_island):
            if ws.island_fallback[k] == 1:
                body = ws.row_body[ws.island_rows[ws.island_start[k]], 1]
                kind = AUDIT_UNSOLVED if ws.island_failed[k] == 1 else AUDIT_FALLBACK
                note(ws, s.step[0], kind, 0, body, 0.0)
    for i in range(ws.v_new.shape[0]):
        for k in range(3):
            ws.v_new[i, k] = ws.v_pred[i, k]
    apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.v_new, 1.0)
    return solved


@part("model", "state", "workspace", "float64", "boolean")
def solve_contacts(m, s, ws, h, include_ccd):
    """The velocity stage as one complementarity problem (see the module's docstring)."""
    for attempt in range(m.contact_body.shape[0] + 2 * m.pin_body.shape[0] + 1):
        _lcp_once(m, s, ws, h)
        modes_from_solution(m, s, ws)
        if engage_contacts(m, s, ws, h, include_ccd, ws.v_new) + engage_limits(
                m, s, ws, h, ws.v_new) == 0:
            break
    gather_contact_impulses(m, s, ws)
    for k in range(ws.n_live[0]):
        ws.contact_candidate[ws.live[k]] = 0
    for j in range(m.pin_body.shape[0]):
        ws.limit_candidate[j, 0] = 0
        ws.limit_candidate[j, 1] = 0


# contacts within this gap [m] of the ground take part in the position projection (their
# row may become active as others move); a ground contact also within the reach of the
# projection's last move (_last_move)
PROJECTION_MARGIN = 1e-6


@kernel
def _contact_lever(m, i):
    """A bound [m] on the distance from its body's COM of any point ground contact i may
    hold: its point, arc centre or edge start, and its fallback vertices (an edge's end),
    plus its radius (a sole's, a capsule side's)."""
    lever = math.hypot(m.contact_local[i, 0], m.contact_local[i, 1])
    for k in range(m.contact_vert_adr[i], m.contact_vert_adr[i] + m.contact_vert_num[i]):
        lever = max(lever, math.hypot(m.vert_local[k, 0], m.vert_local[k, 1]))
    return lever + m.contact_radius[i]


@kernel
def _moved(dq, b, lever):
    """|dx| + |dy| + |dtheta| lever [m]: a bound on how far move dq carried a point of body b
    at that distance [m] from its COM (0 for the world, b < 0)."""
    if b < 0:
        return 0.0
    return abs(dq[b, 0]) + abs(dq[b, 1]) + abs(dq[b, 2]) * lever


@kernel
def _last_move(m, ws, i):
    """A bound [m] on how far the projection's last move (ws.dq_correction) can have closed
    contact i: its point's move (_contact_lever), or for a shape pair the two shapes' moves
    (each core's farthest vertex plus its radius)."""
    dq = ws.dq_correction
    if m.contact_kind[i] != CONTACT_PAIR:
        return _moved(dq, m.contact_body[i], _contact_lever(m, i))
    slot0 = i - m.contact_pair[i, 2]
    sa = m.contact_pair[slot0, 0]
    sb = m.contact_pair[slot0, 1]
    return (_moved(dq, m.shape_body[sa], m.shape_bound[sa, 4] + m.shape_radius[sa])
            + _moved(dq, m.shape_body[sb], m.shape_bound[sb, 4] + m.shape_radius[sb]))


@kernel
def _projection_contact(m, s, ws, n, i):
    """Append contact i's normal row at slot n if it is enabled and within PROJECTION_MARGIN
    of the ground or of its pair's other shape, plus the reach of the projection's last
    move (_last_move: a body that one row lifts by turning may bring its other corners, or a
    shape on it, as far down; their rows then hold them in the next move, where a margin of
    rounding alone let the moves cycle between the edge contact of a thin polygon rocking on
    a hill, its corners and a ball rolling on it); a ground contact is found again here
    first. Returns the next free slot."""
    if s.contact_enabled[i] == 0:
        return n
    if m.contact_kind[i] != CONTACT_PAIR:
        query_contact(m, s.q, ws, i)
    if ws.contact_gap[i] < PROJECTION_MARGIN + _last_move(m, ws, i):
        n = add_contact_rows(ws, n, i, True, False)
    return n


@kernel
def _projection_rows(m, s, ws, h):
    """Rows at the current configuration for the position projection: every joint, active
    limits and the sides of limits the joint lies outside of, the normal row of every
    enabled contact closer to the ground than the margin (contact points found again here).
    Returns the number of rows."""
    update_trig(s.q, ws.body_cs)
    n = 0
    for j in range(m.pin_body.shape[0]):
        n = add_joint_rows(m, ws, n, j)
        n = add_violated_limit_rows(m, s, ws, n, j)
    for j in range(m.rod_body.shape[0]):
        n = add_rod_row(m, ws, n, j)
    n_near = 0
    if m.n_shape_pair > 0:
        # the features touching now (modes left as they are) of the pairs within reach; the
        # step's other pairs have none
        place_shapes(m, s.q, ws.body_cs, s.v, s.v, ws)
        for k in range(ws.n_live_pairs[0]):
            i = ws.live_pairs[k]
            if s.contact_enabled[i] == 1:
                ws.contact_gap[i] = math.inf
                ws.contact_gap[i + 1] = math.inf
        n_near = sweep_pairs(ws, max(PAIR_MARGIN, PROJECTION_MARGIN), h, ws.sweep_pairs)
        for k in range(n_near):
            i = ws.sweep_pairs[k]
            if s.contact_enabled[i] == 1:
                find_pair(m, s, ws, i, h, PROJECTION_MARGIN + _last_move(m, ws, i), True)
    # in the contacts' order: the ground contacts and the slots of the pairs within reach
    for k in range(merge_contacts(ws.ground_contacts, ws.sweep_pairs, n_near, ws.near_contacts)):
        n = _projection_contact(m, s, ws, n, ws.near_contacts[k])
    ws.n_row[0] = n
    eval_rows(m, s.q, ws.body_cs, ws, ws.row_J, ws.row_c, n, True)
    return n


@kernel
def _largest_error(ws, n):
    worst = 0.0
    for r in range(n):
        c = ws.row_c[r]
        if is_joint_row(ws.row_kind[r]):
            worst = max(worst, abs(c))
        else:
            worst = max(worst, -c)
    return worst


@kernel
def _limit_pushed(ws, n, tol):
    """A joint limit's row of the projection violated by more than tol [rad or m]: a joint
    that started the step outside its limit (add_violated_limit_rows)."""
    for r in range(n):
        if is_limit_row(ws.row_kind[r]) and ws.row_c[r] < -tol:
            return True
    return False


@kernel
def _project_velocity(m, s, ws, h):
    """After a projection that pushed a joint onto its limit: the velocity made to keep the
    joints at the configuration reached, and not to drive the touching contacts and limits
    in (rows at gap <= 0), by the mass-weighted least change v += W J^T mu (it can only
    remove kinetic energy): the pins' share of the push became no velocity."""
    n = _projection_rows(m, s, ws, h)
    for r in range(n):
        jv = row_dot(ws, r, ws.row_J, s.v)
        if is_joint_row(ws.row_kind[r]) or ws.row_c[r] <= 0.0:
            ws.row_b[r] = jv
        else:
            ws.row_b[r] = abs(jv) + 1.0     # apart: not a row of this projection
    if _solve_by_islands(m, ws, n, 1)[1] > 0:
        return
    apply_impulses(m, ws, ws.row_J, ws.lam, n, s.v, 1.0)


@part("model", "state", "workspace", "float64", "int64", "float64", returns="float64")
def project_positions(m, s, ws, h, iters, tol):
    """Project the configuration onto closed joints and contacts not below the ground (see
    the module's docstring). Returns the largest remaining error [m or rad]. A move that
    leaves a larger error than it started from (its linearisation crossed a change of the
    touching features, a light body wedged between heavy ones) is halved, up to
    PROJECTION_HALVINGS times, before the next one is solved; each move is taken at the
    length its linearisation last bore out (TRUST_LOW: whole while moves remove what they
    promise)."""
    worst = 0.0
    best = math.inf         # the error where the last move started (q_keep)
    share = 1.0             # of the last move taken
    reach = 1.0             # the share of Newton's move the next one takes (TRUST_LOW)
    ws.dq_correction[:] = 0.0   # no move yet (the rows' margin reads the last one)
    pushed = False          # a joint put back onto its limit: its moves carry no velocity
    for it in range(iters + 1):
        n = _projection_rows(m, s, ws, h)
        worst = _largest_error(ws, n)
        if it == 0:
            pushed = _limit_pushed(ws, n, tol)
        if worst <= tol or it == iters:
            break
        if worst > best and share > 0.5 ** PROJECTION_HALVINGS:
            share *= 0.5
            for i in range(s.q.shape[0]):
                for k in range(3):
                    s.q[i, k] = ws.q_keep[i, k] + share * ws.dq_correction[i, k]
                    s.v[i, k] = ws.v_keep[i, k] + share * ws.dv_correction[i, k]
            continue
        if share == 1.0 and best < math.inf:
            # the last move, taken as solved, against what its linearisation promised (the
            # share `reach` of the error it started from)
            if best - worst < TRUST_LOW * reach * best:
                reach = max(0.5 * reach, 0.5 ** PROJECTION_HALVINGS)
            elif best - worst > TRUST_HIGH * reach * best:
                reach = min(2.0 * reach, 1.0)
        best = worst
        share = 1.0
        for r in range(n):
            ws.row_b[r] = ws.row_c[r]
        ws.info[INFO_PROJECTIONS] += 1
        if _solve_by_islands(m, ws, n, 1)[1] > 0:
            break
        for i in range(s.q.shape[0]):
            for k in range(3):
                ws.dq_correction[i, k] = 0.0
                ws.dv_correction[i, k] = 0.0
        apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dq_correction, reach)
        # joint corrections change the velocity too (dq / h), contact and limit corrections
        # do not; nor does any where a limit was pushed (below)
        for r in range(n):
            if pushed or not is_joint_row(ws.row_kind[r]):
                ws.lam[r] = 0.0
        apply_impulses(m, ws, ws.row_J, ws.lam, n, ws.dv_correction, reach / h)
        for i in range(s.q.shape[0]):
            for k in range(3):
                ws.q_keep[i, k] = s.q[i, k]
                ws.v_keep[i, k] = s.v[i, k]
                s.q[i, k] += ws.dq_correction[i, k]
                s.v[i, k] += ws.dv_correction[i, k]
    if pushed:
        _project_velocity(m, s, ws, h)
    return worst
