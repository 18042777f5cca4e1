"""Stage 2: the contact point of every foot, recomputed at the start of each step.

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

from ...compile import kernel
from ..math2d import rotate, set_dir, world_point
from .terrain import ground_point, height_derivs

from ..codes import CONTACT_EDGE, CONTACT_PAIR, CONTACT_POINT, MODE_FREE, MODE_PINNED, MODE_SLIDING
from ..dynamics.forces import point_velocity
from .broad_phase import update_live
from .pair import PAIR_MARGIN, find_pair, place_shapes


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
    it points into arc contact i's angular span, ends included (then the sole's point closest
    to the ground is the centre plus r times it). By the sides of the span's end directions
    (contact_span_dir), no angle computed: within a span of at most half a turn a direction
    lies on the inner side of both ends; within a wider one it does not lie beyond both."""
    dlx, dly = rotate(cs[b, 0], -cs[b, 1], -nx, -ny)
    width = m.contact_span[i, 1] - m.contact_span[i, 0]
    if width >= 2.0 * math.pi:
        return True, dlx, dly
    after_start = m.contact_span_dir[i, 0] * dly - m.contact_span_dir[i, 1] * dlx >= 0.0
    before_end = dlx * m.contact_span_dir[i, 3] - dly * m.contact_span_dir[i, 2] >= 0.0
    if width <= math.pi:
        return after_start and before_end, dlx, dly
    return after_start or before_end, dlx, dly


# bisection steps of an edge's deepest point (the interval shrinks below rounding of u)
EDGE_BISECTIONS = 60
# _edge_by_rate searches an edge in pieces at most this share of the ground's shortest
# wavelength long, each cut at the ground's inflection if it holds one
EDGE_PIECE = 0.125


@kernel
def _edge_rate(coef, x0, y0, dx, dy, u, rounded):
    """The sign of d/du of the ground clearance of p(u) = p0 + u (dx, dy): of its height above
    the ground, dy - h' dx, or (rounded: a capsule's side, whose distance along the normal
    counts) of its distance from the ground, n.(dx, dy) with n the normal at its foot."""
    if rounded:
        gx, gy, nx, ny, gap = ground_point(coef, x0 + u * dx, y0 + u * dy)
        return nx * dx + ny * dy
    return dy - height_derivs(coef, x0 + u * dx)[1] * dx


@kernel
def _edge_minimum(coef, x0, y0, dx, dy, u0, u1, rounded):
    """(u, f): the local minimum of the clearance f(u) of p(u) = p0 + u (dx, dy) on [u0, u1]
    (_edge_rate) where its rate is monotone there and turns from negative to positive
    (bisection); f = inf when it does not."""
    if not (_edge_rate(coef, x0, y0, dx, dy, u0, rounded) < 0.0
            <= _edge_rate(coef, x0, y0, dx, dy, u1, rounded)):
        return u0, math.inf
    lo = u0
    hi = u1
    for _ in range(EDGE_BISECTIONS):
        u = 0.5 * (lo + hi)
        if _edge_rate(coef, x0, y0, dx, dy, u, rounded) < 0.0:
            lo = u
        else:
            hi = u
    u = 0.5 * (lo + hi)
    return u, _edge_clearance(coef, x0, y0, dx, dy, u, rounded)


@kernel
def _edge_segment(m, q, cs, i):
    """(x0, y0, dx, dy, rounded, shortest): edge contact i's core segment in the world at q
    [m] (start and direction, contact_local to its one fallback vertex), whether it is a
    capsule's side (radius > 0), and the ground's shortest wavelength [m] (inf: no sines)."""
    b = m.contact_body[i]
    k = m.contact_vert_adr[i]
    x0, y0 = world_point(q, cs, b, m.contact_local[i, 0], m.contact_local[i, 1])
    x1, y1 = world_point(q, cs, b, m.vert_local[k, 0], m.vert_local[k, 1])
    shortest = math.inf
    for j in range(int(m.terrain_coef[2])):
        shortest = min(shortest, m.terrain_coef[4 + 3 * j])
    return x0, y0, x1 - x0, y1 - y0, m.contact_radius[i] > 0.0, shortest


@kernel
def _edge_curvature(coef, x0, y0, dx, dy, u, rounded):
    """The ground's curvature h'' [1/m] that sets the sign of the clearance's second
    derivative at p(u) = p0 + u (dx, dy): under the point (its height), or at the foot of its
    normal (rounded: a capsule's side, whose clearance is its distance along the normal; the
    foot lies up to r sin(slope) aside, where the curvature may already have turned)."""
    if rounded:
        gx = ground_point(coef, x0 + u * dx, y0 + u * dy)[0]
        return height_derivs(coef, gx)[2]
    return height_derivs(coef, x0 + u * dx)[2]


@kernel
def _edge_by_rate(m, q, cs, i):
    """(inside, px, py): the point of edge contact i's core segment (contact_local to its one
    fallback vertex, body frame) lowest above the ground, and whether it lies strictly inside
    the segment (else the segment's ends, the shape's corners or end circles, are lowest).
    Along the segment the height above the ground f(u) = y(u) - h(x(u)) has the rate
    f' = dy - h' dx, monotone between the ground's inflections (h'' = 0): the segment is cut
    in pieces of EDGE_PIECE of the shortest wavelength, each at its inflection if it holds
    one, and where f' turns from negative to positive on a monotone part the local minimum
    is found by bisection; the lowest of them is returned. For a capsule's side (radius > 0)
    the distance along the ground's normal is minimised instead (its surface lies r along
    the normal from the deepest point of its core); its rate n . (dx, dy) turns where the
    curvature at the normal's foot does, which the cuts follow (_edge_curvature)."""
    coef = m.terrain_coef
    x0, y0, dx, dy, rounded, shortest = _edge_segment(m, q, cs, i)
    pieces = 1 if shortest == math.inf else int(math.ceil(abs(dx) / (EDGE_PIECE * shortest))) + 1
    best = math.inf
    best_u = 0.0
    for piece in range(pieces):
        ua = piece / pieces
        ub = (piece + 1) / pieces
        ca = _edge_curvature(coef, x0, y0, dx, dy, ua, rounded)
        cb = _edge_curvature(coef, x0, y0, dx, dy, ub, rounded)
        ue = ub
        if ca * cb < 0.0:
            # an inflection: f' turns back there; the two sides are monotone
            lo = ua
            hi = ub
            for _ in range(EDGE_BISECTIONS):
                u = 0.5 * (lo + hi)
                if _edge_curvature(coef, x0, y0, dx, dy, u, rounded) * ca > 0.0:
                    lo = u
                else:
                    hi = u
            ue = 0.5 * (lo + hi)
            u, f = _edge_minimum(coef, x0, y0, dx, dy, ua, ue, rounded)
            if f < best:
                best = f
                best_u = u
            ua = ue
        u, f = _edge_minimum(coef, x0, y0, dx, dy, ua, ub, rounded)
        if f < best:
            best = f
            best_u = u
    inside = best < math.inf and 0.0 < best_u < 1.0
    return inside, x0 + best_u * dx, y0 + best_u * dy


# samples of an edge's clearance per shortest wavelength of the ground; golden-section steps
# of the refinement around the lowest sample (the bracket shrinks by 0.618 a step)
EDGE_SAMPLES_PER_WAVELENGTH = 64
EDGE_MIN_SAMPLES = 16
EDGE_GOLDEN_STEPS = 60
GOLDEN = 0.6180339887498949


@kernel
def _edge_clearance(coef, x0, y0, dx, dy, u, rounded):
    """Clearance [m] of the point p(u) = p0 + u (dx, dy) above the ground: its distance along
    the normal (rounded: a capsule's side, whose surface lies r along it) or its height."""
    if rounded:
        return ground_point(coef, x0 + u * dx, y0 + u * dy)[4]
    return y0 + u * dy - height_derivs(coef, x0 + u * dx)[0]


@kernel
def _golden_minimum(coef, x0, y0, dx, dy, lo, hi, rounded):
    """(u, f): the minimum of the clearance on [lo, hi] by golden-section search (a single
    dip assumed there)."""
    u1 = hi - GOLDEN * (hi - lo)
    u2 = lo + GOLDEN * (hi - lo)
    f1 = _edge_clearance(coef, x0, y0, dx, dy, u1, rounded)
    f2 = _edge_clearance(coef, x0, y0, dx, dy, u2, rounded)
    for _ in range(EDGE_GOLDEN_STEPS):
        if f1 <= f2:
            hi = u2
            u2 = u1
            f2 = f1
            u1 = hi - GOLDEN * (hi - lo)
            f1 = _edge_clearance(coef, x0, y0, dx, dy, u1, rounded)
        else:
            lo = u1
            u1 = u2
            f1 = f2
            u2 = lo + GOLDEN * (hi - lo)
            f2 = _edge_clearance(coef, x0, y0, dx, dy, u2, rounded)
        if hi - lo <= 1e-15:
            break
    if f1 <= f2:
        return u1, f1
    return u2, f2


@kernel
def _edge_by_samples(m, q, cs, i):
    """edge_deepest by the clearance sampled along the segment (EDGE_SAMPLES_PER_WAVELENGTH
    of the shortest wavelength, at least EDGE_MIN_SAMPLES), every sample lower than its
    neighbours refined by golden-section search between them: no assumption on where the
    ground's curvature turns (a capsule nearly along a flank dips between samples)."""
    coef = m.terrain_coef
    x0, y0, dx, dy, rounded, shortest = _edge_segment(m, q, cs, i)
    n = EDGE_MIN_SAMPLES if shortest == math.inf else max(
        EDGE_MIN_SAMPLES, int(math.ceil(abs(dx) * EDGE_SAMPLES_PER_WAVELENGTH / shortest)) + 1)
    f_start = _edge_clearance(coef, x0, y0, dx, dy, 0.0, rounded)
    f_end = _edge_clearance(coef, x0, y0, dx, dy, 1.0, rounded)
    best = math.inf
    best_u = 0.0
    f_prev = f_start
    f_here = f_start
    for j in range(n + 1):
        f_next = f_end if j + 1 == n else (
            _edge_clearance(coef, x0, y0, dx, dy, (j + 1) / n, rounded) if j + 1 < n else math.inf)
        if f_here <= f_prev and f_here <= f_next:
            # a dip at sample j (at an end: just inside it) refined between its neighbours
            u, f = _golden_minimum(coef, x0, y0, dx, dy, max(j - 1, 0) / n, min(j + 1, n) / n,
                                   rounded)
            if f < best and 0.0 < u < 1.0:
                best = f
                best_u = u
        f_prev = f_here
        f_here = f_next
    inside = best < min(f_start, f_end)
    return inside, x0 + best_u * dx, y0 + best_u * dy


@kernel(inline="never")
def edge_deepest(m, q, cs, i):
    """(inside, px, py): the point of edge contact i's core segment (contact_local to its one
    fallback vertex, body frame) lowest above the ground, and whether it lies strictly inside
    the segment (else an end, the shape's corner or end circle, is lowest: its own contact
    holds it). Two searches, the deeper answer kept: the rate's sign changes between the
    ground's inflections (_edge_by_rate: exact where the rate is monotone in its pieces) and
    the sampled clearance refined by golden section (_edge_by_samples: no assumption on the
    curvature; it can miss a dip narrower than its spacing next to an end)."""
    in_a, ax, ay = _edge_by_rate(m, q, cs, i)
    in_b, bx, by = _edge_by_samples(m, q, cs, i)
    if not in_b:
        return _owned(m, q, cs, i, in_a, ax, ay), ax, ay
    if not in_a:
        return _owned(m, q, cs, i, in_b, bx, by), bx, by
    rounded = m.contact_radius[i] > 0.0
    fa = _edge_clearance(m.terrain_coef, ax, ay, 0.0, 0.0, 0.0, rounded)
    fb = _edge_clearance(m.terrain_coef, bx, by, 0.0, 0.0, 0.0, rounded)
    if fb < fa:
        return _owned(m, q, cs, i, in_b, bx, by), bx, by
    return _owned(m, q, cs, i, in_a, ax, ay), ax, ay


@kernel(inline="always")
def _owned(m, q, cs, i, inside, px, py):
    """inside, and for a piece of a side (builder.edge_pieces: contact_span (lo, hi), lo < hi)
    its point (px, py) in the piece's own part of its segment, lo <= u < hi."""
    lo = m.contact_span[i, 0]
    hi = m.contact_span[i, 1]
    if not inside or not lo < hi:
        return inside
    x0, y0, dx, dy, rounded, shortest = _edge_segment(m, q, cs, i)
    u = ((px - x0) * dx + (py - y0) * dy) / (dx * dx + dy * dy)
    return lo <= u < hi


@kernel(inline="never")
def find_edge(m, q, ws, i):
    """Edge contact i at q: its deepest core point, pushed out by the shape's radius along the
    ground normal (a capsule's side), as a material point held for the step; gap inf where the
    segment's ends are its lowest points (their own contacts hold them)."""
    inside, px, py = edge_deepest(m, q, ws.body_cs, i)
    if not inside:
        ws.contact_gap[i] = math.inf
        ws.contact_on_arc[i] = 0
        return
    r = m.contact_radius[i]
    gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
    sx = px - r * nx
    sy = py - r * ny
    b = m.contact_body[i]
    lx, ly = rotate(ws.body_cs[b, 0], -ws.body_cs[b, 1], sx - q[b, 0], sy - q[b, 1])
    _store(ws, i, sx, sy, gx, gy, nx, ny, gap - r, lx, ly, 0)


@kernel
def find_contact(m, q, ws, i):
    """Contact point, ground point, normal and gap of contact i at configuration q."""
    b = m.contact_body[i]
    lx = m.contact_local[i, 0]
    ly = m.contact_local[i, 1]
    if m.contact_kind[i] == CONTACT_POINT:
        _try_vertex(m, q, ws, i, b, lx, ly, math.inf)
        return
    if m.contact_kind[i] == CONTACT_EDGE:
        find_edge(m, q, ws, i)
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


@kernel(inline="never")
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
    times its normal impulse, cannot stop that slip), else pinned; a frictionless contact
    (mu = 0) always slides, with slip 0 and no friction. The checks after the solve
    then settle it: a pinned contact outside the friction cone slides, a sliding one whose slip
    reverses sticks, so an impact ends up sticking exactly when Coulomb's law says so."""
    if m.contact_mu[i] == 0.0:
        # frictionless: touching is sliding with no friction (slip 0; no tangent row)
        s.contact_mode[i] = MODE_SLIDING
        s.contact_slip[i] = 0.0
    elif abs(vt) > m.contact_mu[i] * abs(vn) and abs(vt) > 1e-9:
        s.contact_mode[i] = MODE_SLIDING
        s.contact_slip[i] = 1.0 if vt > 0.0 else -1.0
    else:
        s.contact_mode[i] = MODE_PINNED
    ws.contact_new[i] = 1
    if m.contact_restitution[i] != 0.0:
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


@kernel(inline="never")
def bounce_of(m, s, ws, i):
    """The normal velocity [m/s] restitution asks of contact i after an impact: e times its
    approach speed at the step's start, 0 below BOUNCE_SPEED; times ws.bounce_scale (1 but
    where the energetic bound scales the step's rebounds down: kernels/solver/rebound.py)."""
    e = m.contact_restitution[i]
    if e == 0.0:
        return 0.0
    vn, vt = contact_velocity(m, s, ws, i, s.v)
    return ws.bounce_scale[0] * (e * -vn) if -vn > BOUNCE_SPEED else 0.0


@kernel
def find_contacts(m, s, ws, h):
    """Stage 2 for every contact (a free point contact surely clear of the ground is left
    unqueried: see the module's docstring; a shape pair's two slots by kernels/geometry/pair.py); a
    disabled contact is forced free. A contact that a time-of-impact split brought into touch
    (contact_new == 2) is engaged here, where its ground normal is known."""
    # on flat or sloped ground a query costs no more than the bound that would spare it
    lazy = m.terrain_coef[2] != 0.0
    if m.n_shape_pair > 0:
        place_shapes(m, s.q, ws.body_cs, s.v, ws.v_pred, ws)
        update_live(m, s, ws, PAIR_MARGIN, h)
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        if m.contact_kind[i] == CONTACT_PAIR:
            if m.contact_pair[i, 2] == 0:
                find_pair(m, s, ws, i, h, 0.0, False)
            if s.contact_enabled[i] == 0:
                s.contact_mode[i] = MODE_FREE
            elif m.contact_restitution[i] != 0.0:
                ws.contact_bounce[i] = bounce_of(m, s, ws, i)
            continue
        if (lazy and s.contact_mode[i] == MODE_FREE and s.contact_enabled[i] == 1
                and ws.contact_new[i] == 0 and _stays_clear(m, s.q, ws, i)):
            continue
        query_contact(m, s.q, ws, i)
        if s.contact_enabled[i] == 0 or ws.contact_gap[i] == math.inf:
            s.contact_mode[i] = MODE_FREE     # disabled, or an edge whose ends are lowest
        elif ws.contact_new[i] == 2:
            b = m.contact_body[i]
            vx = s.v[b, 0] - s.v[b, 2] * (ws.contact_point[i, 1] - s.q[b, 1])
            vy = s.v[b, 1] + s.v[b, 2] * (ws.contact_point[i, 0] - s.q[b, 0])
            nx = ws.contact_normal[i, 0]
            ny = ws.contact_normal[i, 1]
            engage_contact(m, s, ws, i, nx * vx + ny * vy, ny * vx - nx * vy)
        elif m.contact_restitution[i] != 0.0:
            ws.contact_bounce[i] = bounce_of(m, s, ws, i)


@kernel
def ground_row(m, q, cs, ws, o, b, tangent, J, found):
    """Jacobian blocks J (2, 3) and error [m] of ground contact o (on body b): its normal row
    (tangent False: the exact gap of the material point, or of the sole's centre minus r, along
    the normal of its closest ground point; the same as the start-of-step values at q0 and
    exact on curved ground when the position correction evaluates it at q+) or its tangent row
    (the material point stays at the ground point found at the step's start; a rolling sole's
    arc rolls on it without slipping instead). found: this q
    is the one the contact was found at (stage 2), whose gap and normal are reused."""
    for k in range(3):
        J[0, k] = 0.0
    if not tangent:
        if ws.contact_on_arc[o] == 1:
            px, py = world_point(q, cs, b, m.contact_local[o, 0], m.contact_local[o, 1])
        else:
            px, py = world_point(q, cs, b, ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
        if found:
            # find_contact's query at this q: its gap is already the sole's (centre's - r)
            set_dir(q, b, px, py, ws.contact_normal[o, 0], ws.contact_normal[o, 1], 1.0, J[1])
            return ws.contact_gap[o]
        gx, gy, nx, ny, gap = ground_point(m.terrain_coef, px, py)
        set_dir(q, b, px, py, nx, ny, 1.0, J[1])
        if ws.contact_on_arc[o] == 1:
            return gap - m.contact_radius[o]
        return gap
    tx = ws.contact_normal[o, 1]
    ty = -ws.contact_normal[o, 0]
    if ws.contact_on_arc[o] == 1:
        # a rolling sole: no slip holds the arc length it rolls, not its material point (which
        # would pivot the sole about the start's contact point: r sin(dtheta) a step along
        # the ground where rolling takes r dtheta). The point under the centre moves along t
        # by t . dc, and the sole's arc under it by r dtheta: their sum stays t . (p0 - g)
        # (p0 the start's material point, below the centre), linear in theta; the same row
        # and error as the material point's at the start's pose (contact_found)
        cx, cy = world_point(q, cs, b, m.contact_local[o, 0], m.contact_local[o, 1])
        set_dir(q, b, cx, cy, tx, ty, 1.0, J[1])
        r = m.contact_radius[o]
        J[1, 2] += r
        return (tx * (cx - ws.contact_ground[o, 0]) + ty * (cy - ws.contact_ground[o, 1])
                + r * (q[b, 2] - ws.contact_found[o, 2]))
    px, py = world_point(q, cs, b, ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
    set_dir(q, b, px, py, tx, ty, 1.0, J[1])
    return tx * (px - ws.contact_ground[o, 0]) + ty * (py - ws.contact_ground[o, 1])


@kernel(inline="always")
def turn_less_linear(t):
    """(cos t - 1, sin t - t) for a turn t [rad]: a turn's second-order parts, exactly 0 at
    t = 0 (cos t - 1 as -2 sin^2(t / 2), without cancellation)."""
    half = math.sin(0.5 * t)
    return -2.0 * half * half, math.sin(t) - t


@kernel
def ground_second_order(m, q, cs, v, ws, o, h):
    """The second-order part [m] of ground contact o's gap over a step of h [s] at velocity
    v: gap(p(q + h v)) - gap(p(q)) - h J v, p its normal row's body point (a material point,
    or a rolling sole's centre) and J the row at q (ground_row). Two parts, each computed
    from small numbers, so that it is exact, and 0, where the motion is linear: the turn's,
    n . ((cos t - 1) a + (sin t - t) a_perp) with t = h w and a the point's arm (the arm's
    chord less its tangent), and on hills the ground's curvature, gap(p + e) - gap(p) - n . e
    for the point's whole move e (flat and sloped ground have none)."""
    b = m.contact_body[o]
    if ws.contact_on_arc[o] == 1:
        ax, ay = rotate(cs[b, 0], cs[b, 1], m.contact_local[o, 0], m.contact_local[o, 1])
    else:
        ax, ay = rotate(cs[b, 0], cs[b, 1], ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
    c1, s1 = turn_less_linear(h * v[b, 2])
    dx = c1 * ax - s1 * ay
    dy = c1 * ay + s1 * ax
    px = q[b, 0] + ax
    py = q[b, 1] + ay
    _, _, nx, ny, gap0 = ground_point(m.terrain_coef, px, py)
    part = nx * dx + ny * dy
    if m.terrain_coef[2] != 0.0:
        ex = h * (v[b, 0] - v[b, 2] * ay) + dx
        ey = h * (v[b, 1] + v[b, 2] * ax) + dy
        gap1 = ground_point(m.terrain_coef, px + ex, py + ey)[4]
        part += gap1 - gap0 - (nx * ex + ny * ey)
    return part


@kernel
def ground_lever(m, ws, o, tangent):
    """|x| + |y| [m] from its body's COM of the point ground contact o's row moves: the sole's
    centre for a rolling sole's rows (its tangent row's error is linear in the turn about the
    centre), the material point otherwise."""
    if ws.contact_on_arc[o] == 1:
        return abs(m.contact_local[o, 0]) + abs(m.contact_local[o, 1])
    return abs(ws.contact_anchor[o, 0]) + abs(ws.contact_anchor[o, 1])
