"""Stage 3: the contact point of every foot, recomputed at the start of each step.

Point contact: the material point itself. Arc contact (curved sole): the circle point closest
to the ground, c - r n, where n is the ground normal at the ground point closest to the arc
centre c; used when that direction lies inside the sole's angular span, otherwise the lowest of
the fallback vertices and the arc's end points (heel, toe). The material point found this way
(contact_anchor, body frame) is held fixed for the step, so a curved foot rolls. On a sole,
the normal row constrains the arc centre's distance from the ground (n.(c - g) = r), which a
rotation leaves unchanged; a fixed material point would rise by r dphi^2 / 2 as the foot rolls
and let the foot sink by as much every step.
On hills, a free point contact whose last ground query proves it still clear (its gap then, minus how
far its point can have moved since) is not queried again: its material point is placed (cheap),
its gap is kept as that lower bound and it is marked stale. Whoever needs its ground point or
normal (modes.engage_contacts, when the bound no longer proves it clear) queries it first
(refresh_contact), at the same configuration, so the step's numbers are those of querying
every contact every step.
"""
import math

from ._jit import kernel, kernel_call
from .math2d import rotate, world_point
from .terrain import ground_point

from .codes import CONTACT_PAIR, CONTACT_POINT, MODE_FREE, MODE_PINNED, MODE_SLIDING
from .forces import point_velocity
from .pair import find_pair


@kernel
def _store(ws, i, px, py, gx, gy, nx, ny, gap, lx, ly, on_arc):
    ws.contact_on_arc[i] = on_arc
    ws.contact_point[i, 0] = px
    ws.contact_point[i, 1] = py
    ws.contact_ground[i, 0] = gx
    ws.contact_ground[i, 1] = gy
    ws.contact_normal[i, 0] = nx
    ws.contact_normal[i, 1] = ny
    ws.contact_gap[i] = gap
    ws.contact_anchor[i, 0] = lx
    ws.contact_anchor[i, 1] = ly


@kernel
def _try_vertex(m, q, ws, i, b, lx, ly, best):
    """Use local vertex (lx, ly) for contact i if its gap is below `best`; return the new best."""
    px, py = world_point(q, ws.body_cs, b, lx, ly)
    gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
    if gap < best:
        _store(ws, i, px, py, gx, gy, nx, ny, gap, lx, ly, 0)
        return gap
    return best


@kernel
def sole_facing(m, cs, b, i, nx, ny):
    """(in_span, dlx, dly): the direction -n (ground normal n) in body b's frame, and whether
    it points into arc contact i's angular span (then the sole's point closest to the ground
    is the centre plus r times it)."""
    dlx, dly = rotate(cs[b, 0], -cs[b, 1], -nx, -ny)
    a = math.atan2(dly, dlx)
    a0 = m.contact_span[i, 0]
    while a < a0:
        a += 2.0 * math.pi
    while a >= a0 + 2.0 * math.pi:
        a -= 2.0 * math.pi
    return a <= m.contact_span[i, 1], dlx, dly


@kernel
def find_contact(m, q, ws, i):
    """Contact point, ground point, normal and gap of contact i at configuration q."""
    b = m.contact_body[i]
    lx = m.contact_local[i, 0]
    ly = m.contact_local[i, 1]
    if m.contact_kind[i] == CONTACT_POINT:
        _try_vertex(m, q, ws, i, b, lx, ly, math.inf)
        return
    # arc: ground point closest to the centre, sole point opposite the normal
    r = m.contact_radius[i]
    cx, cy = world_point(q, ws.body_cs, b, lx, ly)
    gx, gy, nx, ny, cgap = ground_point(m.terrain_coef, cx, cy)
    in_span, dlx, dly = sole_facing(m, ws.body_cs, b, i, nx, ny)
    a0 = m.contact_span[i, 0]
    a1 = m.contact_span[i, 1]
    best = math.inf
    if in_span:
        px = cx - r * nx
        py = cy - r * ny
        _store(ws, i, px, py, gx, gy, nx, ny, cgap - r, lx + r * dlx, ly + r * dly, 1)
        best = cgap - r
    else:
        # the sole is turned away from the ground: arc end points and fallback vertices
        for e in range(2):
            ang = a0 if e == 0 else a1
            best = _try_vertex(m, q, ws, i, b, lx + r * math.cos(ang), ly + r * math.sin(ang), best)
    adr = m.contact_vert_adr[i]
    for k in range(adr, adr + m.contact_vert_num[i]):
        best = _try_vertex(m, q, ws, i, b, m.vert_local[k, 0], m.vert_local[k, 1], best)


# a free point contact is left unqueried while its proven gap is above this share of the gap
# it was last queried at (the bound loosens as the body moves; a loose bound would only make
# the engage test query it anyway)
CLEAR_SHARE = 0.5


@kernel
def point_reach(q, b, x0, y0, th0, lx, ly):
    """A bound [m] on how far the point (lx, ly) of body b has moved between the pose
    (x0, y0, th0) and q: |dx| + |dy| + |dtheta| r, r its distance from the COM."""
    return (abs(q[b, 0] - x0) + abs(q[b, 1] - y0)
            + abs(q[b, 2] - th0) * math.sqrt(lx * lx + ly * ly))


@kernel
def query_contact(m, q, ws, i):
    """find_contact, and the pose and gap it was done at (the reference of _stays_clear's
    bound)."""
    find_contact(m, q, ws, i)
    b = m.contact_body[i]
    ws.contact_found[i, 0] = q[b, 0]
    ws.contact_found[i, 1] = q[b, 1]
    ws.contact_found[i, 2] = q[b, 2]
    ws.contact_found[i, 3] = ws.contact_gap[i]
    ws.contact_stale[i] = 0


@kernel_call
def _stays_clear(m, q, ws, i):
    """Point contact i is surely above the ground at q: its gap when last queried minus how far
    its point can have moved since (point_reach; the signed distance to the ground changes by at
    most the point's move) is above CLEAR_SHARE of that gap. Places
    its material point and keeps that bound as its gap (stale)."""
    if m.contact_kind[i] != CONTACT_POINT:
        return False
    gap0 = ws.contact_found[i, 3]
    if not gap0 > 0.0:
        return False
    b = m.contact_body[i]
    lx = m.contact_local[i, 0]
    ly = m.contact_local[i, 1]
    bound = gap0 - point_reach(q, b, ws.contact_found[i, 0], ws.contact_found[i, 1],
                               ws.contact_found[i, 2], lx, ly)
    if not bound > CLEAR_SHARE * gap0:
        return False
    px, py = world_point(q, ws.body_cs, b, lx, ly)
    ws.contact_point[i, 0] = px
    ws.contact_point[i, 1] = py
    ws.contact_anchor[i, 0] = lx
    ws.contact_anchor[i, 1] = ly
    ws.contact_on_arc[i] = 0
    ws.contact_gap[i] = bound
    ws.contact_stale[i] = 1
    return True


@kernel
def refresh_contact(m, s, ws, i):
    """Query contact i's ground point now if find_contacts left it stale (same configuration,
    same numbers as querying it there)."""
    if ws.contact_stale[i] == 1:
        query_contact(m, s.q, ws, i)


@kernel
def engage_contact(m, s, ws, i, vn, vt):
    """Bring free contact i into touch, approaching at normal velocity vn and tangential vt
    [m/s]: sliding along vt when |vt| > mu |vn| (an impact's friction impulse, at most mu
    times its normal impulse, cannot stop that slip), else pinned. The checks after the solve
    then settle it: a pinned contact outside the friction cone slides, a sliding one whose slip
    reverses sticks, so an impact ends up sticking exactly when Coulomb's law says so."""
    if abs(vt) > m.contact_mu[i] * abs(vn) and abs(vt) > 1e-9:
        s.contact_mode[i] = MODE_SLIDING
        s.contact_slip[i] = 1.0 if vt > 0.0 else -1.0
    else:
        s.contact_mode[i] = MODE_PINNED
    ws.contact_new[i] = 1
    ws.contact_bounce[i] = bounce_of(m, s, ws, i)


# [m/s] restitution acts on impacts faster than this (slower ones are plastic: a body coming
# to rest does not bounce forever in ever smaller hops)
BOUNCE_SPEED = 1e-3


@kernel
def contact_velocity(m, s, ws, i, vel):
    """Normal and tangential velocity [m/s] of contact i's material point under `vel`
    (relative to the other body's coincident point for a shape pair)."""
    a = ws.contact_bodies[i, 0]
    b = ws.contact_bodies[i, 1]
    if m.contact_kind[i] == CONTACT_PAIR:
        px = ws.contact_point[i, 0]
        py = ws.contact_point[i, 1]
    else:
        px, py = world_point(s.q, ws.body_cs, b, ws.contact_anchor[i, 0], ws.contact_anchor[i, 1])
    vx, vy = point_velocity(s.q, vel, b, px, py)
    ux, uy = point_velocity(s.q, vel, a, px, py)
    vx -= ux
    vy -= uy
    nx = ws.contact_normal[i, 0]
    ny = ws.contact_normal[i, 1]
    return nx * vx + ny * vy, ny * vx - nx * vy


@kernel
def pair_motion_scale(s, ws, i, vel):
    """|v_b(p)| + |v_a(p)| (L1) [m/s] of a pair contact's two bodies at its point under vel:
    the scale of the rounding in its relative velocity (both bodies may move together, their
    relative motion then being rounding alone)."""
    px = ws.contact_point[i, 0]
    py = ws.contact_point[i, 1]
    vx, vy = point_velocity(s.q, vel, ws.contact_bodies[i, 1], px, py)
    ux, uy = point_velocity(s.q, vel, ws.contact_bodies[i, 0], px, py)
    return abs(vx) + abs(vy) + abs(ux) + abs(uy)


@kernel
def bounce_of(m, s, ws, i):
    """The normal velocity [m/s] restitution asks of contact i after an impact: e times its
    approach speed at the step's start, 0 below BOUNCE_SPEED."""
    e = m.contact_restitution[i]
    if e == 0.0:
        return 0.0
    vn, vt = contact_velocity(m, s, ws, i, s.v)
    return e * -vn if -vn > BOUNCE_SPEED else 0.0


@kernel
def find_contacts(m, s, ws, h):
    """Stage 3 for every contact (a free point contact surely clear of the ground is left
    unqueried: see the module's docstring; a shape pair's two slots by kernels/pair.py); a
    disabled contact is forced free. A contact that a time-of-impact split brought into touch
    (contact_new == 2) is engaged here, where its ground normal is known."""
    # on flat or sloped ground a query costs no more than the bound that would spare it
    lazy = m.terrain_coef[2] != 0.0
    for i in range(m.contact_body.shape[0]):
        if m.contact_kind[i] == CONTACT_PAIR:
            if m.contact_pair[i, 2] == 0:
                find_pair(m, s, ws, i, h, 0.0, False)
            if s.contact_enabled[i] == 0:
                s.contact_mode[i] = MODE_FREE
            else:
                ws.contact_bounce[i] = bounce_of(m, s, ws, i)
            continue
        if (lazy and s.contact_mode[i] == MODE_FREE and s.contact_enabled[i] == 1
                and ws.contact_new[i] == 0 and _stays_clear(m, s.q, ws, i)):
            continue
        query_contact(m, s.q, ws, i)
        if s.contact_enabled[i] == 0:
            s.contact_mode[i] = MODE_FREE
        elif ws.contact_new[i] == 2:
            b = m.contact_body[i]
            vx = s.v[b, 0] - s.v[b, 2] * (ws.contact_point[i, 1] - s.q[b, 1])
            vy = s.v[b, 1] + s.v[b, 2] * (ws.contact_point[i, 0] - s.q[b, 0])
            nx = ws.contact_normal[i, 0]
            ny = ws.contact_normal[i, 1]
            engage_contact(m, s, ws, i, nx * vx + ny * vy, ny * vx - nx * vy)
        else:
            ws.contact_bounce[i] = bounce_of(m, s, ws, i)
