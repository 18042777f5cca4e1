"""The shape-pair contact: two colliding shapes touching, as two contact slots.

A pair of shapes that may touch (planarsim/shapes.py) owns two consecutive contacts (slots 0
and 1: a face on a face touches at two points). At the start of each step find_pair runs the
narrow phase (kernels/geometry/collide.py) and gives each manifold point a slot: the slot that held the
same features (State.contact_feature) in the last step, so a contact keeps its mode and its
impulse while the same features touch; a slot whose features changed starts free (the solve
engages it if the motion pushes it in). A slot without a point is free and far.

Each point is held as features fixed in the bodies for the step, so that the position
correction evaluates the exact gap of the same features at any configuration:
  face     a core point p of the incident body (a vertex, a circle's centre, a clipped point
           of an edge) against a face line (unit normal n and a point g) of the reference
           body: gap = n.(p - g) - r_ref - r_inc
  distance two core points (vertex on vertex): gap = |p - g| - r_ref - r_inc, n along p - g
Rows act at the incident body's surface point ps = p - r_inc n (its friction acts there, so a
disk rolls). The reference body is the row's body a (-1: a world shape), the incident body
its body b (ws.contact_bodies); either may be the pair's first shape.

The pair's stages are calls (kernel(inline="never")), not inlined: a model without shapes keeps the
step's hot loops as small as before. Broad phase: each shape's bounding circle and speed
bound are placed once per configuration (place_shapes); a pair whose circles are farther
apart than the step can close (SPECULATIVE_FACTOR times the speed bounds times h, plus
PAIR_MARGIN) skips the narrow phase. Which pairs are tested at all is the sweep's answer
(kernels/geometry/broad_phase.py): O(shapes + nearby pairs) a step, not O(pairs of the model).
"""
import math

from ...compile import kernel, part
from ..codes import CONTACT_PAIR, MODE_FREE
from .collide import collide
from ..math2d import rotate, set_dir, world_point

# [m] manifold points within this gap are kept even at rest (a resting stack's contacts stay
# found while rounding moves them); above it only what the step's motion can close
PAIR_MARGIN = 1e-4
# [m] a free pair contact engages when the motion would push it this far into the other
# shape: far below the audit's DEPTH_TOL (1e-8 m), far above rounding
PAIR_ENGAGE_SLACK = 1e-10
# the speculative distance is this multiple of the distance the bodies can move in a step
SPECULATIVE_FACTOR = 2.0


@kernel
def body_pose(q, cs, b):
    """(x, y, cos, sin) of body b (the world's identity for b < 0)."""
    if b < 0:
        return 0.0, 0.0, 1.0, 0.0
    return q[b, 0], q[b, 1], cs[b, 0], cs[b, 1]


@kernel
def to_local(q, cs, b, px, py):
    """World point (px, py) in body b's frame (unchanged for the world, b < 0)."""
    if b < 0:
        return px, py
    return rotate(cs[b, 0], -cs[b, 1], px - q[b, 0], py - q[b, 1])


@kernel
def _speed_bound(m, v, b, shape):
    """|v_x| + |v_y| + |omega| (|c| + R) [m/s]: a bound on the speed of any point of the shape
    (bounding circle centre c, radius R) of body b under velocities v (0 for the world)."""
    if b < 0:
        return 0.0
    cx = m.shape_bound[shape, 0]
    cy = m.shape_bound[shape, 1]
    lever = math.sqrt(cx * cx + cy * cy) + m.shape_bound[shape, 2]
    return abs(v[b, 0]) + abs(v[b, 1]) + abs(v[b, 2]) * lever


@kernel(inline="always")
def relative_speed(m, v, sa, sb, la, lb):
    """A bound [m/s] on the speed of any point of shape sa relative to any point of shape sb
    under velocities v (the world's are zero): |v_xa - v_xb| + |v_ya - v_yb| + |w_a| la +
    |w_b| lb, la and lb [m] the shapes' levers (their points' farthest distance from their
    bodies' origins). It depends on the bodies' motion relative to each other only, so a
    pair's sweep is decided alike in any frame (a bound on each shape's own speed split a
    pair's impact drifting at 30 m/s and not at rest, and a speculative margin that grew
    with the drift let a spinning box strike a disk its corner never reached)."""
    ba = m.shape_body[sa]
    bb = m.shape_body[sb]
    vax, vay, wa = (v[ba, 0], v[ba, 1], v[ba, 2]) if ba >= 0 else (0.0, 0.0, 0.0)
    vbx, vby, wb = (v[bb, 0], v[bb, 1], v[bb, 2]) if bb >= 0 else (0.0, 0.0, 0.0)
    return abs(vax - vbx) + abs(vay - vby) + abs(wa) * la + abs(wb) * lb


@kernel(inline="always")
def shape_lever(m, k):
    """|c| + R [m]: the farthest any point of shape k lies from its body's origin (c, R: its
    bounding circle's centre in the body and its radius)."""
    cx = m.shape_bound[k, 0]
    cy = m.shape_bound[k, 1]
    return math.sqrt(cx * cx + cy * cy) + m.shape_bound[k, 2]


@kernel
def place_shapes(m, q, cs, v0, v1, ws):
    """ws.shape_reach: every shape's bounding circle at q (cs its cos / sin) and a bound on
    its points' speed under velocities v0 and v1 (the larger), once per configuration: the
    pairs' broad phase then costs a few flops each."""
    for k in range(m.shape_body.shape[0]):
        b = m.shape_body[k]
        x, y = world_point(q, cs, b, m.shape_bound[k, 0], m.shape_bound[k, 1])
        ws.shape_reach[k, 0] = x
        ws.shape_reach[k, 1] = y
        ws.shape_reach[k, 2] = m.shape_bound[k, 2]
        ws.shape_reach[k, 3] = max(_speed_bound(m, v0, b, k), _speed_bound(m, v1, b, k))


@kernel
def pair_apart(ws, i_a, i_b, margin):
    """The bounding circles of shapes i_a and i_b (ws.shape_reach, placed) are more than
    margin [m] apart (no square root)."""
    dx = ws.shape_reach[i_b, 0] - ws.shape_reach[i_a, 0]
    dy = ws.shape_reach[i_b, 1] - ws.shape_reach[i_a, 1]
    reach = ws.shape_reach[i_a, 2] + ws.shape_reach[i_b, 2] + margin
    return dx * dx + dy * dy > reach * reach


@kernel
def manifold(m, q, cs, ws, i, margin):
    """The narrow phase of pair contact i (slot 0) at q: points with gap <= margin in
    ws.manifold (collide's layout); returns their number."""
    sa = m.contact_pair[i, 0]
    sb = m.contact_pair[i, 1]
    xa, ya, ca, sna = body_pose(q, cs, m.shape_body[sa])
    xb, yb, cb, snb = body_pose(q, cs, m.shape_body[sb])
    return collide(m.core_vert, m.core_norm, m.core_cover,
                   m.shape_vert_adr[sa], m.shape_vert_num[sa], m.shape_radius[sa], xa, ya, ca, sna,
                   m.shape_vert_adr[sb], m.shape_vert_num[sb], m.shape_radius[sb], xb, yb, cb, snb,
                   margin, ws.manifold)


@kernel
def _store_point(m, q, cs, ws, c, k):
    """Contact c takes manifold point k: bodies, features in the bodies' frames, the surface
    points, normal and gap at q."""
    i = c - m.contact_pair[c, 2]        # slot 0
    sa = m.contact_pair[i, 0]
    sb = m.contact_pair[i, 1]
    out = ws.manifold
    if out[k, 0] == 0.0:
        ref = m.shape_body[sa]
        inc = m.shape_body[sb]
        r_ref = m.shape_radius[sa]
        r_inc = m.shape_radius[sb]
    else:
        ref = m.shape_body[sb]
        inc = m.shape_body[sa]
        r_ref = m.shape_radius[sb]
        r_inc = m.shape_radius[sa]
    px = out[k, 2]
    py = out[k, 3]
    nx = out[k, 4]
    ny = out[k, 5]
    gx = out[k, 6]
    gy = out[k, 7]
    ws.contact_bodies[c, 0] = ref
    ws.contact_bodies[c, 1] = inc
    ws.contact_dist[c] = 1 if out[k, 1] == 1.0 else 0
    ws.contact_radii[c, 0] = r_ref
    ws.contact_radii[c, 1] = r_inc
    lx, ly = to_local(q, cs, inc, px, py)
    ws.contact_anchor[c, 0] = lx
    ws.contact_anchor[c, 1] = ly
    if ref >= 0:
        lnx, lny = rotate(cs[ref, 0], -cs[ref, 1], nx, ny)
    else:
        lnx, lny = nx, ny
    ws.contact_face[c, 0] = lnx
    ws.contact_face[c, 1] = lny
    lgx, lgy = to_local(q, cs, ref, gx, gy)
    ws.contact_face[c, 2] = lgx
    ws.contact_face[c, 3] = lgy
    # surface points: the incident body's (where the rows act) and the reference body's
    ws.contact_point[c, 0] = px - r_inc * nx
    ws.contact_point[c, 1] = py - r_inc * ny
    sx = gx + r_ref * nx
    sy = gy + r_ref * ny
    ws.contact_ground[c, 0] = sx
    ws.contact_ground[c, 1] = sy
    rx, ry = to_local(q, cs, ref, sx, sy)
    ws.contact_refpt[c, 0] = rx
    ws.contact_refpt[c, 1] = ry
    ix, iy = to_local(q, cs, inc, ws.contact_point[c, 0], ws.contact_point[c, 1])
    ws.contact_refpt[c, 2] = ix
    ws.contact_refpt[c, 3] = iy
    # the turn the round side rolls through is measured from here (pair_row)
    ws.contact_refpt[c, 4] = r_inc * (_angle(q, inc) - _angle(q, ref))
    ws.contact_normal[c, 0] = nx
    ws.contact_normal[c, 1] = ny
    ws.contact_gap[c] = out[k, 8]
    ws.contact_on_arc[c] = 0
    ws.contact_stale[c] = 0


@kernel
def clear_slot(s, ws, c):
    """Contact c has no manifold point: free, no features, out of reach (gap inf: nothing
    engages it before the next narrow phase, whose margin covers the step's motion)."""
    ws.contact_gap[c] = math.inf
    ws.contact_stale[c] = 0
    ws.contact_on_arc[c] = 0
    s.contact_mode[c] = MODE_FREE
    s.contact_feature[c] = -1
    s.last_contact_impulse[c, 0] = 0.0
    s.last_contact_impulse[c, 1] = 0.0


@part("model", "state", "workspace", "int64", "float64", "float64", "boolean")
def find_pair(m, s, ws, i, h, margin_floor, keep_modes):
    """Stage 2 for the pair whose slot 0 is contact i, at s.q (ws.body_cs current, the
    shapes placed there: place_shapes): the
    manifold within the step's reach (PAIR_MARGIN, or margin_floor if larger, plus what
    SPECULATIVE_FACTOR times the shapes' relative speed bound, under the step's start and
    predicted velocities, can close in h) and its points given to
    the two slots by their features. keep_modes: only the geometry (the position projection,
    which must not change modes)."""
    q = s.q
    cs = ws.body_cs
    sa = m.contact_pair[i, 0]
    sb = m.contact_pair[i, 1]
    la = shape_lever(m, sa)
    lb = shape_lever(m, sb)
    speed = max(relative_speed(m, s.v, sa, sb, la, lb),
                relative_speed(m, ws.v_pred, sa, sb, la, lb))
    margin = max(PAIR_MARGIN, margin_floor) + SPECULATIVE_FACTOR * h * speed
    n = 0
    if not pair_apart(ws, sa, sb, margin):
        n = manifold(m, q, cs, ws, i, margin)
    # slots that keep their features keep their points
    taken0 = -1
    taken1 = -1
    for k in range(n):
        f = int(ws.manifold[k, 9])
        if taken0 < 0 and f == s.contact_feature[i]:
            taken0 = k
        elif taken1 < 0 and f == s.contact_feature[i + 1]:
            taken1 = k
    for k in range(n):
        if k == taken0 or k == taken1:
            continue
        if taken0 < 0:
            taken0 = k
        elif taken1 < 0:
            taken1 = k
    for e in range(2):
        c = i + e
        k = taken0 if e == 0 else taken1
        if k < 0:
            if not keep_modes:
                clear_slot(s, ws, c)
            else:
                ws.contact_gap[c] = math.inf
            continue
        _store_point(m, q, cs, ws, c, k)
        f = int(ws.manifold[k, 9])
        if not keep_modes and f != s.contact_feature[c]:
            # other features: another contact, which starts free (engaged if pushed in)
            s.contact_mode[c] = MODE_FREE
            s.contact_feature[c] = f
            s.last_contact_impulse[c, 0] = 0.0
            s.last_contact_impulse[c, 1] = 0.0


@kernel(inline="always")
def _angle(q, b):
    """Body b's angle [rad] (0 for the world, b < 0)."""
    return q[b, 2] if b >= 0 else 0.0


@kernel
def pair_surface_point(q, cs, ws, o):
    """World surface point ps [m] of pair contact o's incident body and the normal (nx, ny)
    at q (the features held fixed: kernels/geometry/pair.py)."""
    a = ws.contact_bodies[o, 0]
    b = ws.contact_bodies[o, 1]
    px, py = world_point(q, cs, b, ws.contact_anchor[o, 0], ws.contact_anchor[o, 1])
    gx, gy = world_point(q, cs, a, ws.contact_face[o, 2], ws.contact_face[o, 3])
    if ws.contact_dist[o] == 1:
        dx = px - gx
        dy = py - gy
        d = math.sqrt(dx * dx + dy * dy)
        if d > 0.0:
            nx = dx / d
            ny = dy / d
        else:
            nx, ny = ws.contact_normal[o, 0], ws.contact_normal[o, 1]
        gap = d - ws.contact_radii[o, 0] - ws.contact_radii[o, 1]
    else:
        if a >= 0:
            nx, ny = rotate(cs[a, 0], cs[a, 1], ws.contact_face[o, 0], ws.contact_face[o, 1])
        else:
            nx, ny = ws.contact_face[o, 0], ws.contact_face[o, 1]
        gap = nx * (px - gx) + ny * (py - gy) - ws.contact_radii[o, 0] - ws.contact_radii[o, 1]
    r_inc = ws.contact_radii[o, 1]
    return px - r_inc * nx, py - r_inc * ny, nx, ny, gap


@kernel(inline="never")
def pair_row(q, cs, ws, o, J, tangent):
    """Jacobian blocks J (2, 3) and error of pair contact o's normal row (its exact gap [m]
    at q) or tangent row (tangent: the slip [m] along t = (n_y, -n_x) since the step's start,
    of the incident body's surface against the reference body's material point that touched
    there at the step's start). A vertex's surface point is its material point. A round side
    on a face (a disk, a capsule's end or side: radius r > 0) rolls: its surface point
    p - r n is not a material point, and its slip is that point's move plus the arc
    r (dtheta_inc - dtheta_ref) it rolled, exactly 0 for a disk rolling on a face, as the
    ground's round contacts have it (contacts.ground_row). Holding the material point that
    touched instead left r (phi - sin phi) for a roll of phi, which the correction turned into
    velocity (phi^3 r / 6 h a step): a disk rolling down a static box at dt 1e-2 spun 4 %
    faster than it rolled and gained 0.13 J in 1.5 s. Two round sides (contact_dist) keep the
    material points."""
    a = ws.contact_bodies[o, 0]
    b = ws.contact_bodies[o, 1]
    sx, sy, nx, ny, gap = pair_surface_point(q, cs, ws, o)
    if not tangent:
        set_dir(q, a, sx, sy, nx, ny, -1.0, J[0])
        set_dir(q, b, sx, sy, nx, ny, 1.0, J[1])
        return gap
    tx = ny
    ty = -nx
    rx, ry = world_point(q, cs, a, ws.contact_refpt[o, 0], ws.contact_refpt[o, 1])
    set_dir(q, a, sx, sy, tx, ty, -1.0, J[0])
    set_dir(q, b, sx, sy, tx, ty, 1.0, J[1])
    r_inc = ws.contact_radii[o, 1]
    if ws.contact_dist[o] == 0 and r_inc > 0.0:
        rolled = r_inc * (_angle(q, b) - _angle(q, a)) - ws.contact_refpt[o, 4]
        return tx * (sx - rx) + ty * (sy - ry) + rolled
    ix, iy = world_point(q, cs, b, ws.contact_refpt[o, 2], ws.contact_refpt[o, 3])
    return tx * (ix - rx) + ty * (iy - ry)


@kernel
def pair_speed(m, ws, i, vel):
    """A bound [m/s] on how fast pair contact i's gap can close under vel: the speed bounds of
    both shapes' bodies."""
    sa = m.contact_pair[i - m.contact_pair[i, 2], 0]
    sb = m.contact_pair[i - m.contact_pair[i, 2], 1]
    return _speed_bound(m, vel, m.shape_body[sa], sa) + _speed_bound(m, vel, m.shape_body[sb], sb)


@kernel(inline="never")
def pair_gap_now(m, q, cs, ws, i):
    """The signed gap [m] of pair contact i's shapes at q (the shapes placed there:
    place_shapes), measured afresh (the audit): the
    deepest point of the manifold on slot 0, +inf on slot 1 (a pair is measured once) and
    where nothing touches."""
    if m.contact_pair[i, 2] != 0:
        return math.inf
    if pair_apart(ws, m.contact_pair[i, 0], m.contact_pair[i, 1], 0.0):
        return math.inf
    n = manifold(m, q, cs, ws, i, 0.0)
    best = math.inf
    for k in range(n):
        best = min(best, ws.manifold[k, 8])
    return best


@kernel
def shape_contact_mode(m, s, body):
    """The most holding mode of the enabled shape-pair contacts of `body` (0 free, 1 pinned,
    2 sliding; pinned first): whether it stands on, or leans on, another body's shape or a
    world shape (a controller's touchdown test beside its own ground contacts)."""
    best = 0
    if m.n_shape_pair == 0:
        return best
    for k in range(m.contact_body.shape[0]):
        if m.contact_kind[k] != CONTACT_PAIR or s.contact_enabled[k] == 0:
            continue
        if m.contact_body[k] != body and m.contact_other[k] != body:
            continue
        mode = s.contact_mode[k]
        if mode == 1 or (mode == 2 and best == 0):
            best = mode
    return best
