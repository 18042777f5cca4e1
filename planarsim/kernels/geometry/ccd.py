"""Stage 6: continuous collision detection for point masses (and the split at a shape pair's
time of impact, found by kernels/geometry/pair_toi.py).

Within-step path model of a free point (the motion a sub-step of length tau would produce,
with the step's constrained average acceleration a = (v1 - v0) / h):
    p(tau) = p0 + tau v0 + tau^2 a,      0 <= tau <= h
so p(h) = p0 + h v1 is exactly where the full step would end. The time of impact is the first
root of the analytic gap g(tau) = gap(p(tau)): bracketed by sampling (so a fast point cannot
cross a crest and out again unseen), then refined by the Illinois regula falsi to machine
precision. The step is then split at tau (Kelly 2014, section 3).
"""
import math

from ...compile import kernel
from ..codes import MODE_FREE
from .contacts import contact_velocity
from ..info import INFO_CCD_SPLITS, INFO_CCD_STOPS
from .pair_toi import pair_impact_time
from .terrain import ground_point, height_derivs, max_curvature, max_slope

N_SAMPLES = 8
# [m] per metre of coordinates: a path whose height above the ground falls this low while it
# approaches the ground touches it (rounding of the height at those coordinates)
TOUCH_GAP = 1e-12
# conservative advancement's steps on hills before it takes the point as touching
MAX_ADVANCES = 500


@kernel
def _path_gap(m, s, ws, b, h, tau):
    ax = (ws.v_new[b, 0] - s.v[b, 0]) / h
    ay = (ws.v_new[b, 1] - s.v[b, 1]) / h
    px = s.q[b, 0] + tau * s.v[b, 0] + tau * tau * ax
    py = s.q[b, 1] + tau * s.v[b, 1] + tau * tau * ay
    return ground_point(m.terrain_coef, px, py)[4]


@kernel
def _height_gap(coef, x0, y0, vx, vy, ax, ay, tau):
    """The path's height above the ground f(tau) = y(tau) - h(x(tau)) [m] and its rate
    f'(tau) [m/s] (the same sign as the gap: the ground is a height field)."""
    x = x0 + tau * vx + tau * tau * ax
    y = y0 + tau * vy + tau * tau * ay
    hgt, dh, ddh = height_derivs(coef, x)
    return y - hgt, (vy + 2.0 * tau * ay) - dh * (vx + 2.0 * tau * ax), abs(x) + abs(y)


@kernel
def _impact_on_hills(m, s, ws, b, h):
    """First time tau in [0, h] [s] at which point-mass body b's path touches sine hills, or
    inf: conservative advancement on the path's height above the ground f(tau). With K a bound
    of |f''| over the step (the path's acceleration and speed, the hills' largest slope and
    curvature), f(t + u) >= f(t) + f'(t) u - K u^2 / 2, so no root lies before the first
    zero u* of that bound: tau advances by u* and f is evaluated again. Far from the ground
    the steps are long; towards a crossing they shrink as Newton's do, from the near side, so
    a fast point can neither cross a crest and out again unseen nor be placed beyond its first
    contact. A point that skims the ground within TOUCH_GAP while approaching it touches."""
    coef = m.terrain_coef
    x0 = s.q[b, 0]
    y0 = s.q[b, 1]
    vx = s.v[b, 0]
    vy = s.v[b, 1]
    ax = (ws.v_new[b, 0] - vx) / h
    ay = (ws.v_new[b, 1] - vy) / h
    slope = max_slope(coef)
    speed_x = abs(vx) + 2.0 * h * abs(ax)
    bound = 2.0 * abs(ay) + max_curvature(coef) * speed_x * speed_x + 2.0 * slope * abs(ax)
    t = 0.0
    for _ in range(MAX_ADVANCES):
        f, rate, size = _height_gap(coef, x0, y0, vx, vy, ax, ay, t)
        if f <= TOUCH_GAP * (1.0 + size) and rate <= 0.0:
            return t
        if bound > 0.0:
            u = (rate + math.sqrt(max(rate * rate + 2.0 * bound * f, 0.0))) / bound
        elif rate < 0.0:
            u = f / -rate
        else:
            return math.inf
        t += max(u, 0.0)
        if t >= h:
            return math.inf
    return t        # still advancing after MAX_ADVANCES: touching here, conservatively


@kernel
def impact_time(m, s, ws, b, h):
    """First root tau in [0, h] of the path gap of point-mass body b, or inf if none."""
    t_lo = 0.0
    g_lo = _path_gap(m, s, ws, b, h, 0.0)
    # the gap is a distance (1-Lipschitz) and the path stays within h |v0| + h^2 |a| of p0:
    # a point farther from the ground than that cannot reach it within the step
    reach = h * math.hypot(s.v[b, 0], s.v[b, 1]) + h * math.hypot(ws.v_new[b, 0] - s.v[b, 0],
                                                                   ws.v_new[b, 1] - s.v[b, 1])
    if g_lo > reach + 1e-12:
        return math.inf
    g_end = _path_gap(m, s, ws, b, h, h)
    if g_lo <= 0.0:
        return 0.0 if g_end < 0.0 else math.inf
    if m.terrain_coef[2] != 0.0:
        return _impact_on_hills(m, s, ws, b, h)
    t_hi = -1.0
    g_hi = 0.0
    for k in range(1, N_SAMPLES + 1):
        t = h * k / N_SAMPLES
        g = g_end if k == N_SAMPLES else _path_gap(m, s, ws, b, h, t)
        if g < 0.0:
            t_hi = t
            g_hi = g
            break
        t_lo = t
        g_lo = g
    if t_hi < 0.0:
        return math.inf
    # Illinois regula falsi on [t_lo, t_hi] with g_lo > 0 > g_hi
    side = 0
    for _ in range(200):
        t = (t_lo * g_hi - t_hi * g_lo) / (g_hi - g_lo)
        if not (t_lo < t < t_hi):
            t = 0.5 * (t_lo + t_hi)
        g = _path_gap(m, s, ws, b, h, t)
        if g == 0.0:
            return t
        if g > 0.0:
            t_lo = t
            g_lo = g
            if side == 1:
                g_hi *= 0.5
            side = 1
        else:
            t_hi = t
            g_hi = g
            if side == -1:
                g_lo *= 0.5
            side = -1
        if t_hi - t_lo <= 4e-16 * h:
            break
    return t_hi


@kernel
def time_of_impact(m, s, ws, h):
    """Earliest impact (tau, contact) over free, enabled CCD contacts; contact -1 if none."""
    best = math.inf
    which = -1
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if m.contact_ccd[i] == 0 or s.contact_mode[i] != MODE_FREE or s.contact_enabled[i] == 0:
            continue
        tau = impact_time(m, s, ws, m.contact_body[i], h)
        if tau < best:
            best = tau
            which = i
    return best, which


@kernel
def advance_to_impact(s, ws, h, tau, drift):
    """Move every body along its within-step path to tau: v = v0 + tau a, q += tau v; or
    (drift: a shape pair's impact, kernels/geometry/pair_toi.py) q += tau v1, the step's drift at its
    solved velocity v1 = ws.v_new, whose path the pair's sweep followed, and
        v = v1 - (1 - tau / h) (v* - v0)      (v* = ws.v_pred = v0 + h M^-1 f)
    the forces for the time taken, the solve's impulses whole: an impact at the sub-step's
    start is over at once, and a speculative contact's impulse leaves its pair closing no
    faster than the rest of the sub-step can close its gap. (Taking the impulses by the
    share tau / h left a pair the turn horizon split still approaching at nearly its speed
    before the impact, to touch and be split again: a 6 mm polygon at 290 m/s spent the 16
    splits of its first step so and went through a 5 cm slab, benchmarks/thin_walls.py
    312:slab:0.01.)"""
    for i in range(s.q.shape[0]):
        for k in range(3):
            if drift:
                s.v[i, k] = ws.v_new[i, k] - (1.0 - tau / h) * (ws.v_pred[i, k] - s.v[i, k])
                s.q[i, k] += tau * ws.v_new[i, k]
            else:
                vk = s.v[i, k] + tau * (ws.v_new[i, k] - s.v[i, k]) / h
                s.v[i, k] = vk
                s.q[i, k] += tau * vk


@kernel
def split_at_impact(m, s, ws, h, splits_left):
    """The time-of-impact split: if a free CCD contact would hit the ground inside the step of
    h [s] (not at its very end, which the next step takes: tau = 0 there), or two fast shapes
    would touch or turn too far about a touching point (kernels/geometry/pair_toi.py; splits_left:
    the splits the step may still take, this one included), move every body to the earlier
    time (advance_to_impact) and return the time tau >= 0 [s] taken; -1 when the step is not
    split. A point contact is engaged at the next sub-step's find_contacts (contact_new = 2);
    a pair is found there, about to touch, by its narrow phase (its contacts engage when the
    motion pushes them in)."""
    tau, hit = time_of_impact(m, s, ws, h)
    if m.n_shape_pair > 0:
        tau_pair = pair_impact_time(m, s, ws, h, splits_left)
        if tau_pair < tau:
            tau = tau_pair
            hit = m.contact_body.shape[0]       # no point contact to engage
    if hit < 0 or not tau < h * (1.0 - 1e-9):
        return -1.0
    advance_to_impact(s, ws, h, tau, hit == m.contact_body.shape[0])
    s.time[0] += tau
    ws.impact_time[0] = s.time[0]
    if hit < m.contact_body.shape[0]:
        ws.contact_new[hit] = 2
    ws.info[INFO_CCD_SPLITS] += 1
    return tau


# splits_left that gives pair_impact_time's turn horizon no floor (an even share of nothing)
NO_SPLIT_FLOOR = 1 << 52


@kernel
def stop_at_impact(m, s, ws, h):
    """The last part of a step that has used up its splits (StepOptions.max_ccd_splits), of h
    [s], solved: the time tau [s] it is cut to, or -1 (taken whole). Cut where a fast shape
    pair would touch within it (pair_impact_time's sweep), or where a touching one's turn
    takes its held points more than the touch target off their linearised motion (its turn
    horizon, without the even share of splits left that floors it while the step may still
    split). Taken whole, a thin body turning 10-20 rad within the part was thrown through a
    5 cm slab by the position correction of its contact's linearised rows
    (benchmarks/thin_walls.py --max-splits 2: 35 of 2,400 cases). Cut, the part moves
    every body for tau at its solved velocity, the forces' share of the time not taken
    removed (v1 - (1 - tau / h) (v* - v0)), and the rest of the step's time, h - tau, is
    dropped: its clock still advances by the whole step; counted in ws.info[INFO_CCD_STOPS]."""
    if m.n_shape_pair == 0:
        return -1.0
    tau = pair_impact_time(m, s, ws, h, NO_SPLIT_FLOOR)
    if not tau < h * (1.0 - 1e-9):
        return -1.0
    for i in range(s.v.shape[0]):
        for k in range(3):
            ws.v_new[i, k] -= (1.0 - tau / h) * (ws.v_pred[i, k] - s.v[i, k])
    # a contact the solve engaged for the whole part that its motion cannot close within
    # tau is not held by the position correction of the cut part (holding it at gap 0 pulled
    # a capsule's far end, 18 cm from the wall, onto it and the capsule through it)
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if s.contact_mode[i] != MODE_FREE and ws.contact_gap[i] > 0.0:
            vn, vt = contact_velocity(m, s, ws, i, ws.v_new)
            if ws.contact_gap[i] + tau * vn > 0.0:
                s.contact_mode[i] = MODE_FREE
    ws.info[INFO_CCD_STOPS] += 1
    return tau
