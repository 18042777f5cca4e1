"""Stage 6 for shape pairs: the time of impact of two shapes' swept motion (translation and
rotation) by conservative advancement on their distances.

A pair's speculative contact (kernels/geometry/pair.py) linearises the step's motion at its start: the
features closest then are held, and a shape turning fast brings others through unseen (a 1 cm
box at 300 rad/s turns 0.3 rad in a 1 ms step). A pair whose shapes can move, relative to each
other, more than GATE_SHARE of the thinner one's width in the step (pair_is_fast) is swept
along the drift the step's answer gives each body, symplectic Euler's
    q(tau) = q0 + tau v1,   0 <= tau <= h
(v1: the solved velocity; q(h) is where the step ends), translation and rotation together.

Sweep: every core vertex of each shape, a disk of the shape's radius, against the other shape
(two convex rounded cores are closest at a vertex of one of them, so the least of these
distances is the pair's). A vertex within target at the sub-step's start is touching: its
contact holds it and it is not swept; the others are, so a corner that a turn brings in after
its neighbour touched is found too.

Conservative advancement (Mirtich 1996; Box2D's b2TimeOfImpact advances the same way): at the
poses q(t), the narrow phase (kernels/geometry/collide.py) gives the closest features' direction n
(from A to B); the separation along that fixed axis,
    d = min over B of n.x - max over A of n.x - r_a - r_b      (the cores' supports),
is a lower bound on the distance (a separating axis) and equals it at the closest features'
n. A support point moves along n no faster than its body's velocity along n plus |omega| L
(L: its core's farthest vertex from the body's origin; the rounding does not turn it), so d
closes no faster than
    c = n.(V_A - V_B) + |omega_A| L_A + |omega_B| L_B
and the shapes cannot touch before t + d / c. t advances by (d - target / 2) / c until
d <= target (TOUCH_SHARE of the thinner width): about to touch, never overlapping.
"""
import math

from ...compile import kernel
from ..codes import MODE_FREE
from .collide import FLIP_B, collide
from .pair import clear_slot, relative_speed, shape_lever

# a pair is swept when its shapes can move, relative to each other, more than this share of
# the thinner one's width in the step (slower pairs: the speculative contact holds them)
GATE_SHARE = 0.25
# the sweep stops this share of the thinner width from touching (the speculative contact of
# the rest of the step closes that last distance)
TOUCH_SHARE = 0.02
# advancements of one vertex's sweep before it is taken as touching where it stands
# (conservative: an early split)
MAX_PAIR_ADVANCES = 100


@kernel
def core_lever(m, adr, num):
    """The largest distance [m] of core vertices adr..adr+num-1 from their body's origin."""
    lever = 0.0
    for j in range(adr, adr + num):
        lever = max(lever, math.hypot(m.core_vert[j, 0], m.core_vert[j, 1]))
    return lever


@kernel
def drift_pose(s, ws, b, t):
    """(x, y, cos, sin) of body b drifted t [s] at its solved velocity (the world's identity
    for b < 0)."""
    if b < 0:
        return 0.0, 0.0, 1.0, 0.0
    th = s.q[b, 2] + t * ws.v_new[b, 2]
    return s.q[b, 0] + t * ws.v_new[b, 0], s.q[b, 1] + t * ws.v_new[b, 1], math.cos(th), \
        math.sin(th)


@kernel
def drift_velocity(ws, b):
    """(v_x, v_y, omega) of body b's drift (zeros for the world)."""
    if b < 0:
        return 0.0, 0.0, 0.0
    return ws.v_new[b, 0], ws.v_new[b, 1], ws.v_new[b, 2]


@kernel
def support_gap(m, adr_a, num_a, r_a, xa, ya, ca, sna, adr_b, num_b, r_b, xb, yb, cb, snb,
                nx, ny):
    """The separation [m] of two rounded cores (at the poses given) along the unit axis n from
    A to B: min over B's core of n.x - max over A's of n.x - r_a - r_b."""
    hi_a = -math.inf
    for j in range(adr_a, adr_a + num_a):
        lx = m.core_vert[j, 0]
        ly = m.core_vert[j, 1]
        hi_a = max(hi_a, nx * (xa + ca * lx - sna * ly) + ny * (ya + sna * lx + ca * ly))
    lo_b = math.inf
    for j in range(adr_b, adr_b + num_b):
        lx = m.core_vert[j, 0]
        ly = m.core_vert[j, 1]
        lo_b = min(lo_b, nx * (xb + cb * lx - snb * ly) + ny * (yb + snb * lx + cb * ly))
    return lo_b - hi_a - r_a - r_b


@kernel
def core_separation(m, s, ws, adr_a, num_a, r_a, ba, adr_b, num_b, r_b, bb, t, reach):
    """(d, nx, ny): the separation [m] of two rounded cores (vertices adr..adr+num-1, radius r)
    of bodies ba and bb, drifted t [s], along the closest features' direction n (from A to B)
    found by the narrow phase within reach [m]; d = inf when nothing is that close."""
    xa, ya, ca, sna = drift_pose(s, ws, ba, t)
    xb, yb, cb, snb = drift_pose(s, ws, bb, t)
    n = collide(m.core_vert, m.core_norm, m.core_cover, adr_a, num_a, r_a, xa, ya, ca, sna,
                adr_b, num_b, r_b, xb, yb, cb, snb, reach, ws.manifold)
    if n == 0:
        return math.inf, 0.0, 1.0
    k = 1 if n == 2 and ws.manifold[1, 8] < ws.manifold[0, 8] else 0
    nx = ws.manifold[k, 4]
    ny = ws.manifold[k, 5]
    if ws.manifold[k, 0] == FLIP_B:
        nx = -nx
        ny = -ny
    return support_gap(m, adr_a, num_a, r_a, xa, ya, ca, sna, adr_b, num_b, r_b, xb, yb, cb,
                       snb, nx, ny), nx, ny


@kernel
def sweep_cores(m, s, ws, adr_a, num_a, r_a, ba, adr_b, num_b, r_b, bb, t_end, reach, target):
    """First time tau in (0, t_end) [s] at which two rounded cores of bodies ba and bb come
    within target [m] of each other in their drift (conservative advancement: the module's
    docstring), or inf: they do not, or they are within target at the start."""
    la = core_lever(m, adr_a, num_a)
    lb = core_lever(m, adr_b, num_b)
    vax, vay, wa = drift_velocity(ws, ba)
    vbx, vby, wb = drift_velocity(ws, bb)
    t = 0.0
    for it in range(MAX_PAIR_ADVANCES):
        d, nx, ny = core_separation(m, s, ws, adr_a, num_a, r_a, ba, adr_b, num_b, r_b, bb, t,
                                    reach)
        if d <= target:
            return math.inf if it == 0 else t
        if d == math.inf:
            return math.inf          # farther than the whole step's motion
        close = nx * (vax - vbx) + ny * (vay - vby) + abs(wa) * la + abs(wb) * lb
        if not close > 0.0:
            return math.inf          # moving apart along n, turning not at all
        t += (d - 0.5 * target) / close
        if t >= t_end:
            return math.inf
    return t


@kernel
def within_reach(ws, sa, sb, reach):
    """The bounding circles of shapes sa and sb (ws.shape_reach, placed at the sub-step's
    start) are at most reach [m] apart: they may meet in a motion of that size."""
    dx = ws.shape_reach[sb, 0] - ws.shape_reach[sa, 0]
    dy = ws.shape_reach[sb, 1] - ws.shape_reach[sa, 1]
    apart = ws.shape_reach[sa, 2] + ws.shape_reach[sb, 2] + reach
    return dx * dx + dy * dy <= apart * apart


@kernel
def pair_gate(m, i):
    """The share of the thinner width beyond which pair i's relative motion in a step is
    swept: GATE_SHARE, or for a pair with restitution TOUCH_SHARE, so that a bouncing pair a
    gap apart is struck at its own time of impact, not within the same solve as the contacts
    already touching (a speculative contact's impulse would join their impact: a cradle's
    balls 5 mm apart at 10 m/s took the blow together as if touching)."""
    return TOUCH_SHARE if m.contact_restitution[i] > 0.0 else GATE_SHARE


@kernel
def fast_before_solve(m, s, ws, sa, sb, h, gate):
    """(fast, width): whether shapes sa and sb may move, relative to each other, more than
    gate (pair_gate) of the thinner one's width [m] (m.shape_bound[:, 3]) in the step of h [s],
    by the larger of their relative speed bounds (relative_speed, levers to their bounding
    circles' far sides) under the step's start and predicted velocities, with their bounding
    circles placed at the sub-step's start (ws.shape_reach): the same answer at stage 2 and
    stage 6, and in any frame."""
    width = min(m.shape_bound[sa, 3], m.shape_bound[sb, 3])
    la = shape_lever(m, sa)
    lb = shape_lever(m, sb)
    reach = h * max(relative_speed(m, s.v, sa, sb, la, lb),
                    relative_speed(m, ws.v_pred, sa, sb, la, lb))
    return reach > gate * width and within_reach(ws, sa, sb, reach), width


@kernel(inline="never")
def hold_off_fast_pairs(m, s, ws, h):
    """Stage 2: a pair whose shapes are fast before the solve (fast_before_solve) and farther
    apart than the touch target (its manifold's smallest gap above TOUCH_SHARE of the
    thinner width) gets no speculative contact: both slots are cleared (free, no features, no
    impulse, gap inf) and the sweep after the solve (pair_impact_time) splits the step where
    the pair touches, or, its splits used up, ends it there (ccd.stop_at_impact). A speculative contact's
    impulse would act from the step's start, at the features closest then: on a fast turning
    thin body it stops a point that would have missed, or turns the body through the wall."""
    for k in range(ws.n_live_pairs[0]):
        i = ws.live_pairs[k]
        fast, width = fast_before_solve(m, s, ws, m.contact_pair[i, 0], m.contact_pair[i, 1], h,
                                        pair_gate(m, i))
        if fast and min(ws.contact_gap[i], ws.contact_gap[i + 1]) > TOUCH_SHARE * width:
            clear_slot(s, ws, i)
            clear_slot(s, ws, i + 1)


@kernel
def pair_is_fast(m, s, ws, sa, sb, h, gate):
    """(fast, reach, width): whether shapes sa and sb must be swept over h [s]: they can move,
    relative to each other, more than gate (pair_gate) of the thinner width in their drift
    (reach [m]: that motion's bound, relative_speed under the drift's velocities, so the same
    in any frame), or they were fast before the solve (their speculative contact may have
    been held off), and their bounding circles are within the reach; and the thinner width
    [m]."""
    reach = h * relative_speed(m, ws.v_new, sa, sb, m.shape_bound[sa, 4], m.shape_bound[sb, 4])
    held, width = fast_before_solve(m, s, ws, sa, sb, h, gate)
    fast = (held or reach > gate * width) and reach > 0.0
    return fast and within_reach(ws, sa, sb, reach), reach, width


@kernel
def sweep_pair(m, s, ws, sa, sb, t_end, reach, target):
    """First time tau in (0, t_end) [s] at which a core vertex of shape sa or sb that is not
    touching at the start (farther than target [m]) comes within target of the other shape in
    the drift (sweep_cores), or inf."""
    best = t_end
    for side in range(2):
        own = sa if side == 0 else sb
        other = sb if side == 0 else sa
        if side == 1 and m.shape_vert_num[sa] == 1 and m.shape_vert_num[sb] == 1:
            break                    # two disks: one sweep
        adr = m.shape_vert_adr[own]
        for j in range(adr, adr + m.shape_vert_num[own]):
            tau = sweep_cores(m, s, ws, j, 1, m.shape_radius[own], m.shape_body[own],
                              m.shape_vert_adr[other], m.shape_vert_num[other],
                              m.shape_radius[other], m.shape_body[other], best, reach, target)
            best = min(best, tau)
    return best if best < t_end else math.inf


@kernel
def turn_horizon(m, s, ws, i, sa, sb, h, splits_left, target):
    """The time [s] within which the drift's turn keeps pair contact i's engaged points (held
    by rows linearised at the sub-step's start) within target [m] of their linear motion: a
    point at lever L turning by phi leaves its tangent by at most L phi^2 / 2, so
    sqrt(2 target / sum L w^2); but no shorter than an even share of the step among the
    splits left (the rest of the step would else be one long sub-step). inf when no slot is
    engaged."""
    if s.contact_mode[i] == MODE_FREE and s.contact_mode[i + 1] == MODE_FREE:
        return math.inf
    curve = 0.0
    for k in (sa, sb):
        b = m.shape_body[k]
        if b >= 0:
            w = ws.v_new[b, 2]
            curve += m.shape_bound[k, 4] * w * w
    if curve == 0.0:
        return math.inf
    return max(math.sqrt(2.0 * target / curve), h / (splits_left + 1))


@kernel(inline="never")
def pair_impact_time(m, s, ws, h, splits_left):
    """The earliest time [s] at which the step of h [s] is split for a shape pair, or inf:
    over the step's listed pairs that are enabled and fast (pair_is_fast), the first touch
    of a vertex not touching at the start (sweep_pair), or for a pair touching already, the
    end of its turn's horizon (turn_horizon, given the splits_left of the step). ws.shape_reach
    must hold the shapes placed at s.q (stage 2 did)."""
    best = math.inf
    for k in range(ws.n_live_pairs[0]):
        i = ws.live_pairs[k]
        if s.contact_enabled[i] == 0 and s.contact_enabled[i + 1] == 0:
            continue
        sa = m.contact_pair[i, 0]
        sb = m.contact_pair[i, 1]
        fast, reach, width = pair_is_fast(m, s, ws, sa, sb, h, pair_gate(m, i))
        if fast:
            target = TOUCH_SHARE * width
            best = min(best, turn_horizon(m, s, ws, i, sa, sb, h, splits_left, target))
            best = min(best, sweep_pair(m, s, ws, sa, sb, min(h, best), reach, target))
    return best
