"""Narrow phase: the contact manifold of two convex rounded cores.

Every collision shape is a convex core grown by a radius r >= 0 [m]: one vertex (a circle),
two (a capsule: the segment v0 -> v1) or n >= 3 in counter-clockwise order (a polygon or a
box, usually r = 0). The cores live in shared arrays in their body's frame: `vert (N, 2)` [m]
the vertices, `norm (N, 2)` the unit outward normal of edge k (vertex k to vertex k+1 mod
num; see core_normals), shape s using rows adr..adr+num-1. A body's pose is its position
(x, y) [m] and the cosine and sine (c, s) of its angle: world = (x, y) + R(c, s) local.

The method is the separating axis test followed by clipping, as in Box2D's b2CollidePolygons
(read for the method, written anew):
  1. separation of face k of core P against core Q: sep_k = min over Q's vertices q of
     n_k.(q - p_k). The largest over both cores' faces is the reference face, its core the
     reference, the other the incident core. sep > margin + r_a + r_b: no contact.
  2. cores overlapping (sep <= 0): the incident edge (the one whose normal is most opposed
     to the reference normal n) is clipped to the reference edge's extent (Sutherland-Hodgman
     against its two side lines); each clipped point p is a FACE point with
     gap = n.(p - v_ref) - r_a - r_b. The deepest one has gap = sep - r: minus the SAT
     penetration depth.
  3. cores apart (sep > 0): where the incident core's vertex closest to the reference line
     projects onto the reference edge, the cores' distance is sep and the manifold is that
     of 2. Elsewhere the closest features are found by brute force (every vertex against
     every edge, both ways): a vertex pair gives one DIST point with
     gap = |p - g| - r_a - r_b and normal (p - g)/|p - g|; a vertex over an edge's interior
     is again the clipped manifold of 2, and so is a vertex pair whose distance the clipped
     manifold reaches (edges face to face with their ends in line, as equal boxes stacked:
     a vertex pair only by rounding).
Two segments, or a point and a segment, have a degenerate Minkowski difference whose edge
normals miss the separating axis along a segment (a circle in line with a capsule, beyond its
end); for those pairs the segment directions are tested too (_cap_separation).

Output: out (2, 10) float64, one row per manifold point k (see collide). The gaps are signed
distances along n between the rounded shapes [m], negative where they overlap.
Cost: O(num_a num_b) (the brute force of 3 only for cores apart whose closest features are
not over the reference face); no allocation.
"""
import math

import numpy as np

from ...compile import kernel
from ..math2d import rotate

# out[k, 0]: which core holds the reference feature (n points away from it)
FLIP_A = 0
FLIP_B = 1
# out[k, 1]: how the gap is measured
KIND_FACE = 0   # from the incident core point p to the reference edge's line, along its normal
KIND_DIST = 1   # vertex to vertex: gap = |p - g| - r_a - r_b
# the clip side in the feature id of a FACE point
CLIP_NONE = 0   # p is the incident vertex itself
CLIP_START = 1  # p: the incident edge crossing the side line through the reference edge's start
CLIP_END = 2    # ... through its end
# feature id = ((flip*2 + kind) * MAX_CORE_VERTICES + ref) * (4 * MAX_CORE_VERTICES) + inc*4 + clip
# ref: the reference edge (FACE) or vertex (DIST); inc: the incident vertex (CLIP_NONE, DIST) or
# the incident edge (clipped points), all as indices within their core
MAX_CORE_VERTICES = 1024
# B's face is the reference only when it separates more than A's best by this [m] plus this
# share of |sep|: nearly parallel faces (a box resting on a box) then keep the same reference
# face from step to step instead of flip-flopping on rounding. Within it the smallest gap can
# be this much below the exact distance (conservative: never above it)
REFERENCE_TOL = 1e-9
# [m] an incident vertex this close outside the reference edge's slab counts as inside it
# (_clip_end): boxes of one width stacked flush keep their corners' names (a renamed contact
# starts free, and the stack's next solve then lacks a corner: measured, a 40-box column's
# first steps fell to the complementarity solve with 200-700 pivots each). Far below
# DEPTH_TOL: the point stands where the clipped one would, to this much
SLAB_TOL = 1e-12
# 1 - cos of the angle [rad^2 / 2] within which a contact's normal at a floor tile's corner at a
# seam counts as its open face's (about 4.5e-5 rad): a box lying flat across the seam keeps its
# own face as the reference
COVER_PARALLEL = 1e-9
# [m] how far beyond a covered part of an edge the shape facing it may reach and still face
# that part only (_meets_on_cover)
COVER_SLAB = 1e-9
# [m] how far below the floor's surface at a covered end a point counts as on its open side
# (_in_free_region): rounding and the solve's tolerances, far below any tile's thickness
COVER_FREE_TOL = 1e-6
# how far [sin of the angle] a normal may lie outside a crest's cone and count as in it
COVER_ARC = 1e-9
# [m] how far a covered shape's admissible faces may overstate a pair's penetration before
# the pair is left to its neighbours (a fixed slop: not the speculative margin, which at
# 50 m/s and dt 1e-2 reaches a metre and kept a slab's bottom as a reference)
OVERSTATE_TOL = 1e-4


def core_normals(vertices) -> np.ndarray:
    """Unit outward normals (num, 2) of a core's edges (edge k: vertex k to vertex k+1 mod num).

    One vertex: a zero row (a circle's core has no edge). Two (a segment v0 -> v1): row 0 the
    right-hand perpendicular ((v1 - v0).y, -(v1 - v0).x) / |v1 - v0|, row 1 its opposite (edge
    1 runs back v1 -> v0). Three or more (convex, counter-clockwise): (dy, -dx) / |d| of each
    edge d. Raises ValueError on a zero-length edge, or a polygon that is not convex and
    counter-clockwise.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 2)
    num = v.shape[0]
    out = np.zeros((num, 2))
    if num <= 1:
        return out
    d = (np.roll(v, -1, axis=0) - v)[: 1 if num == 2 else num]
    length = np.hypot(d[:, 0], d[:, 1])
    if not np.all(length > 0.0):
        raise ValueError(f"core has a zero-length edge: vertices {v.tolist()}")
    out[: d.shape[0], 0] = d[:, 1] / length
    out[: d.shape[0], 1] = -d[:, 0] / length
    if num == 2:
        out[1] = -out[0]
        return out
    # a left turn (or straight on) at every vertex, within rounding of the edge lengths
    turn = d[:, 0] * np.roll(d[:, 1], -1) - d[:, 1] * np.roll(d[:, 0], -1)
    if np.any(turn < -1e-12 * length * np.roll(length, -1)) or not np.sum(turn) > 0.0:
        raise ValueError(f"polygon core must be convex and counter-clockwise: {v.tolist()}")
    return out


def split_feature_id(fid):
    """(flip, kind, ref, inc, clip) of a feature id written by collide."""
    fid = int(fid)
    inc, clip = divmod(fid % (4 * MAX_CORE_VERTICES), 4)
    rest = fid // (4 * MAX_CORE_VERTICES)
    flip_kind, ref = divmod(rest, MAX_CORE_VERTICES)
    return flip_kind // 2, flip_kind % 2, ref, inc, clip


@kernel
def core_point_world(vert, k, x, y, c, s):
    """World position [m] of core vertex row k of a body at pose (x, y, c, s)."""
    wx, wy = rotate(c, s, vert[k, 0], vert[k, 1])
    return x + wx, y + wy


@kernel
def _feature_id(flip, kind, ref, inc, clip):
    return float(((flip * 2 + kind) * MAX_CORE_VERTICES + ref) * (4 * MAX_CORE_VERTICES)
                 + inc * 4 + clip)


@kernel
def _write(out, k, flip, kind, px, py, nx, ny, gx, gy, gap, fid, ox, oy):
    """Row k of the manifold; p and g are given relative to (ox, oy), A's position."""
    out[k, 0] = flip
    out[k, 1] = kind
    out[k, 2] = ox + px
    out[k, 3] = oy + py
    out[k, 4] = nx
    out[k, 5] = ny
    out[k, 6] = ox + gx
    out[k, 7] = oy + gy
    out[k, 8] = gap
    out[k, 9] = fid


@kernel
def _direction(dx, dy):
    """The unit vector along (dx, dy), scaled first so that tiny (subnormal) vectors keep unit
    length; (0, 1) for the zero vector."""
    m = max(abs(dx), abs(dy))
    if m == 0.0:
        return 0.0, 1.0
    dx /= m
    dy /= m
    h = math.hypot(dx, dy)
    return dx / h, dy / h


@kernel
def _circle_pair(vert, adr_a, ca, sa, adr_b, xb, yb, cb, sb, r, margin, ox, oy, out):
    """Two one-vertex cores: one DIST point from A's centre to B's; coincident centres take
    the normal (0, 1)."""
    gx, gy = core_point_world(vert, adr_a, 0.0, 0.0, ca, sa)
    px, py = core_point_world(vert, adr_b, xb, yb, cb, sb)
    d = math.hypot(px - gx, py - gy)
    if d - r > margin:
        return 0
    nx, ny = _direction(px - gx, py - gy)
    _write(out, 0, FLIP_A, KIND_DIST, px, py, nx, ny, gx, gy, d - r,
           _feature_id(FLIP_A, KIND_DIST, 0, 0, CLIP_NONE), ox, oy)
    return 1


@kernel
def _cornered(cover, adr, num, j):
    """Core vertex j (of the core at adr, num vertices) ends a covered part of an edge
    (builder.covered_edges): a floor tile's corner at a seam."""
    return cover[adr + j, 6] != 0.0 or cover[adr + (j - 1) % num, 7] != 0.0


@kernel
def _concave(cover, adr, num, j):
    """Core vertex j is a concave corner of the floor its shape belongs to."""
    return num >= 3 and cover[adr + j, 3] != 0.0


@kernel
def _normal_admitted(vert, norm, cover, adr, num, c, s, j, ux, uy):
    """Whether a contact may press on core vertex j along the world direction (ux, uy), the
    core's outward normal there. At a vertex that ends a covered edge, only within the
    outward normal cone of the floor it belongs to (builder.covered_edges): from p to q
    counter-clockwise, a single direction where the floor runs on flat through the seam
    (or turns concave there), none inside the floor; elsewhere any."""
    if num < 3 or not _cornered(cover, adr, num, j):
        return True
    if cover[adr + j, 1] == 0.0 and cover[adr + j, 2] == 0.0:
        return False            # inside the floor
    px, py = rotate(c, s, cover[adr + j, 4], cover[adr + j, 5])
    qx, qy = rotate(c, s, cover[adr + j, 1], cover[adr + j, 2])
    if px * qx + py * qy >= 1.0 - COVER_PARALLEL:
        return px * ux + py * uy >= 1.0 - COVER_PARALLEL
    # the short arc from p to q (a crest between two faces)
    turn = px * qy - py * qx
    return ((px * uy - py * ux) * turn >= -COVER_ARC and (ux * qy - uy * qx) * turn >= -COVER_ARC
            and ux * (px + qx) + uy * (py + qy) > 0.0)


@kernel
def _meets_on_cover(vert, cover, adr, num, k, x, y, c, s, gx0, gy0, gx1, gy1):
    """Edge k of the core at adr (pose x, y [m], c, s) faces the segment g0 -> g1 (world [m];
    a point where g0 = g1) on its covered part only (builder.covered_edges): the segment's
    projection onto the edge's line lies within the part covered from its start, or to its
    end (past that end too: a body beyond a tile's corner). Then no contact there is the
    edge's: the floor goes on beyond it."""
    head = cover[adr + k, 6]
    tail = cover[adr + k, 7]
    if cover[adr + k, 0] != 0.0:
        return True
    ax, ay = core_point_world(vert, adr + k, x, y, c, s)
    bx, by = core_point_world(vert, adr + (k + 1) % num, x, y, c, s)
    ex = bx - ax
    ey = by - ay
    e2 = ex * ex + ey * ey
    u0 = ((gx0 - ax) * ex + (gy0 - ay) * ey) / e2
    u1 = ((gx1 - ax) * ex + (gy1 - ay) * ey) / e2
    grow = COVER_SLAB / math.sqrt(e2)
    lo = min(u0, u1) - grow
    hi = max(u0, u1) + grow
    return (head > 0.0 and hi <= head) or (tail > 0.0 and lo >= 1.0 - tail)


@kernel
def _in_free_region(cover, adr, v, vx, vy, c, s, gx, gy, r):
    """The world point g [m] and a disk of radius r [m] about it lie on the open side of a
    flat floor at core vertex v (world position vx, vy), which ends a covered part: above
    the floor's line there, within COVER_FREE_TOL. Only where the floor runs on flat
    through v (its normal cone one direction, not concave); at a crest the open side of
    each face reaches in front of the other's, and no point counts."""
    if cover[adr + v, 3] != 0.0:
        return False
    if cover[adr + v, 1] == 0.0 and cover[adr + v, 2] == 0.0:
        return False
    px, py = rotate(c, s, cover[adr + v, 4], cover[adr + v, 5])
    qx, qy = rotate(c, s, cover[adr + v, 1], cover[adr + v, 2])
    if px * qx + py * qy < 1.0 - COVER_PARALLEL:
        return False
    return px * (gx - vx) + py * (gy - vy) >= r - COVER_FREE_TOL


@kernel
def _above_covered_end(vert, norm, cover, adr, num, k, x, y, c, s, gx0, gy0, gx1, gy1, r):
    """Edge k of the core at adr (pose x, y [m], c, s), covered at an end whose floor does not
    run on along the edge (the edge's normal outside that vertex's cone), faces the segment
    g0 -> g1 [m], grown by radius r [m], from the open side of a flat floor there: the
    segment lies above the covering shape, not over the edge (a thick tile's side slanting
    back under a thinner tile: the flat top beyond the seam projects onto the side's open
    part, through the thin tile)."""
    head = cover[adr + k, 6]
    tail = cover[adr + k, 7]
    nx, ny = rotate(c, s, norm[adr + k, 0], norm[adr + k, 1])
    for end in range(2):
        if (head if end == 0 else tail) == 0.0:
            continue
        v = k if end == 0 else (k + 1) % num
        if _normal_admitted(vert, norm, cover, adr, num, c, s, v, nx, ny):
            continue
        vx, vy = core_point_world(vert, adr + v, x, y, c, s)
        if (_in_free_region(cover, adr, v, vx, vy, c, s, gx0, gy0, r)
                and _in_free_region(cover, adr, v, vx, vy, c, s, gx1, gy1, r)):
            return True
    return False


@kernel
def _covered_here(vert, norm, cover, adr, num, k, x, y, c, s, gx0, gy0, gx1, gy1, r):
    """Edge k faces the segment g0 -> g1 on its covered part only (_meets_on_cover) or from
    above the floor at a covered end (_above_covered_end)."""
    if cover[adr + k, 6] == 0.0 and cover[adr + k, 7] == 0.0:
        return False
    return (_meets_on_cover(vert, cover, adr, num, k, x, y, c, s, gx0, gy0, gx1, gy1)
            or _above_covered_end(vert, norm, cover, adr, num, k, x, y, c, s,
                                  gx0, gy0, gx1, gy1, r))


@kernel
def _facing_cover(vert, norm, cover, adr_r, num_r, k, xr, yr, cr, sr, nx, ny,
                  adr_i, num_i, xi, yi, ci, si, support, r):
    """Face k of core R (world normal n) and core I's incident edge (most opposed to n; I's
    vertex `support` where I has fewer than two) face each other only where one of them is
    covered (_covered_here): a box sliding over a seam has its front face facing the next
    tile's side, which a thinner tile before it covers at the top; neither is a surface
    there. Judged by edges, not by the support vertex alone: the box's front corners, or the
    side's two ends, are equally far along n, and either may be the support."""
    if num_i < 2:
        px, py = core_point_world(vert, adr_i + support, xi, yi, ci, si)
        return _covered_here(vert, norm, cover, adr_r, num_r, k, xr, yr, cr, sr,
                             px, py, px, py, r)
    e = _incident_edge(norm, adr_i, num_i, ci, si, nx, ny)
    p0x, p0y = core_point_world(vert, adr_i + e, xi, yi, ci, si)
    p1x, p1y = core_point_world(vert, adr_i + (e + 1) % num_i, xi, yi, ci, si)
    if _covered_here(vert, norm, cover, adr_r, num_r, k, xr, yr, cr, sr, p0x, p0y, p1x, p1y, r):
        return True
    if num_i < 3:
        return False
    ax, ay = core_point_world(vert, adr_r + k, xr, yr, cr, sr)
    bx, by = core_point_world(vert, adr_r + (k + 1) % num_r, xr, yr, cr, sr)
    return _covered_here(vert, norm, cover, adr_i, num_i, e, xi, yi, ci, si, ax, ay, bx, by, r)


@kernel
def _max_separation(vert, norm, cover, adr_r, num_r, xr, yr, cr, sr, adr_i, num_i, xi, yi, ci,
                    si, limit, r):
    """(sep_all, sep, face, support): sep_all the largest over P's faces k of sep_k = min over
    Q's vertices q of n_k.(q - p_k) [m] (stopping at the first face with sep_k > limit: a
    separating axis, no contact); sep the largest over the faces that may be a reference
    (not covered, Q's vertex reaching the minimum admitting n_k, and the face and Q's
    incident edge not facing each other on a covered part only: _normal_admitted,
    _facing_cover), the face
    and the vertex of Q reaching it (-inf, 0, 0: none)."""
    best_all = -math.inf
    best = -math.inf
    face = 0
    support = 0
    for k in range(num_r):
        nx, ny = rotate(cr, sr, norm[adr_r + k, 0], norm[adr_r + k, 1])
        px, py = core_point_world(vert, adr_r + k, xr, yr, cr, sr)
        # n in Q's frame: two products per vertex of Q
        lx, ly = rotate(ci, -si, nx, ny)
        lo = math.inf
        arg = 0
        for j in range(num_i):
            h = lx * vert[adr_i + j, 0] + ly * vert[adr_i + j, 1]
            if h < lo:
                lo = h
                arg = j
        sep = lo + nx * (xi - px) + ny * (yi - py)
        best_all = max(best_all, sep)
        if sep > limit:
            break
        if (sep > best and cover[adr_r + k, 0] == 0.0
                and _normal_admitted(vert, norm, cover, adr_i, num_i, ci, si, arg, -nx, -ny)
                and not _facing_cover(vert, norm, cover, adr_r, num_r, k, xr, yr, cr, sr,
                                      nx, ny, adr_i, num_i, xi, yi, ci, si, arg, r)):
            best = sep
            face = k
            support = arg
    return best_all, best, face, support


@kernel
def _interval(vert, adr, num, x, y, c, s, tx, ty):
    """(lo, hi): the projections [m] of a core's vertices on the direction (tx, ty)."""
    lo = math.inf
    hi = -math.inf
    for k in range(adr, adr + num):
        px, py = core_point_world(vert, k, x, y, c, s)
        h = tx * px + ty * py
        lo = min(lo, h)
        hi = max(hi, h)
    return lo, hi


@kernel
def _cap_separation(vert, norm, adr_a, num_a, xa, ya, ca, sa, adr_b, num_b, xb, yb, cb, sb):
    """Separation [m] of two cores of one or two vertices along the direction of each segment
    among them (positive: apart beyond a segment's end, which no edge normal shows)."""
    best = -math.inf
    for side in range(2):
        adr = adr_a if side == 0 else adr_b
        if (num_a if side == 0 else num_b) != 2:
            continue
        c = ca if side == 0 else cb
        s = sa if side == 0 else sb
        # the segment's direction: its normal turned a quarter turn counter-clockwise
        nx, ny = rotate(c, s, norm[adr, 0], norm[adr, 1])
        lo_a, hi_a = _interval(vert, adr_a, num_a, xa, ya, ca, sa, -ny, nx)
        lo_b, hi_b = _interval(vert, adr_b, num_b, xb, yb, cb, sb, -ny, nx)
        best = max(best, lo_b - hi_a, lo_a - hi_b)
    return best


@kernel
def _segment_point(ax, ay, bx, by, px, py):
    """(d2, u): squared distance [m^2] from p to the segment a-b, and the closest point's
    parameter u in [0, 1] (the end points themselves at u = 0 and 1)."""
    ex = bx - ax
    ey = by - ay
    ee = ex * ex + ey * ey
    u = ((px - ax) * ex + (py - ay) * ey) / ee if ee > 0.0 else 0.0
    if u <= 0.0:
        return (px - ax) ** 2 + (py - ay) ** 2, 0.0
    if u >= 1.0:
        return (px - bx) ** 2 + (py - by) ** 2, 1.0
    dx = px - (ax + u * ex)
    dy = py - (ay + u * ey)
    return dx * dx + dy * dy, u


@kernel
def _closest_features(vert, adr_r, num_r, xr, yr, cr, sr, adr_i, num_i, xi, yi, ci, si):
    """(d2, vr, vi, interior): the smallest squared distance [m^2] between two disjoint cores,
    every vertex of each against every edge of the other; interior: the closest point lies
    inside an edge (else it is the vertex pair vr of R and vi of I)."""
    best = math.inf
    vr = 0
    vi = 0
    interior = False
    for side in range(2):
        adr_e, num_e, xe, ye, ce, se = (adr_r, num_r, xr, yr, cr, sr) if side == 0 else \
            (adr_i, num_i, xi, yi, ci, si)
        adr_v, num_v, xv, yv, cv, sv = (adr_i, num_i, xi, yi, ci, si) if side == 0 else \
            (adr_r, num_r, xr, yr, cr, sr)
        # a segment's second edge is its first run backwards
        n_edge = 0 if num_e < 2 else (1 if num_e == 2 else num_e)
        for k in range(n_edge):
            k1 = (k + 1) % num_e
            ax, ay = core_point_world(vert, adr_e + k, xe, ye, ce, se)
            bx, by = core_point_world(vert, adr_e + k1, xe, ye, ce, se)
            for j in range(num_v):
                px, py = core_point_world(vert, adr_v + j, xv, yv, cv, sv)
                d2, u = _segment_point(ax, ay, bx, by, px, py)
                if d2 < best:
                    best = d2
                    interior = 0.0 < u < 1.0
                    ve = k if u < 0.5 else k1
                    vr = ve if side == 0 else j
                    vi = j if side == 0 else ve
    return best, vr, vi, interior


@kernel
def _incident_edge(norm, adr_i, num_i, ci, si, nx, ny):
    """The incident core's edge whose normal is most opposed to the reference normal n."""
    lx, ly = rotate(ci, -si, nx, ny)
    best = math.inf
    edge = 0
    for k in range(num_i if num_i >= 2 else 0):
        h = lx * norm[adr_i + k, 0] + ly * norm[adr_i + k, 1]
        if h < best:
            best = h
            edge = k
    return edge


@kernel
def _clip_end(px, py, qx, qy, sp, sq, length):
    """(x, y, clip, kept): the point of the incident edge p -> q nearest to p inside the
    reference edge's slab 0 <= t.(x - v_ref) <= length (sp, sq: t.(p - v_ref), t.(q - v_ref)).
    A p within SLAB_TOL of a side line is p itself (CLIP_NONE): a box on a box of its width has
    its corners on the side lines, and rounding must not rename them from step to step."""
    if sp < -SLAB_TOL:
        if sq < 0.0:
            return px, py, CLIP_NONE, False
        f = -sp / (sq - sp)
        return px + f * (qx - px), py + f * (qy - py), CLIP_START, True
    if sp > length + SLAB_TOL:
        if sq > length:
            return px, py, CLIP_NONE, False
        f = (length - sp) / (sq - sp)
        return px + f * (qx - px), py + f * (qy - py), CLIP_END, True
    return px, py, CLIP_NONE, True


@kernel
def _face_point(out, k, flip, face, inc, clip, px, py, nx, ny, ax, ay, r, margin, ox, oy):
    """Write the FACE point p against the reference line through a with normal n when its gap
    n.(p - a) - r is within the margin; return the number of points written so far."""
    h = nx * (px - ax) + ny * (py - ay)
    if h - r > margin:
        return k
    _write(out, k, flip, KIND_FACE, px, py, nx, ny, px - h * nx, py - h * ny, h - r,
           _feature_id(flip, KIND_FACE, face, inc, clip), ox, oy)
    return k + 1


@kernel
def _face_manifold(vert, norm, flip, adr_r, num_r, xr, yr, cr, sr, face,
                   adr_i, num_i, xi, yi, ci, si, r, margin, ox, oy, out):
    """The incident edge clipped to the reference edge `face` (step 2 of the module docstring):
    (count, h_min), up to two FACE points written in the order of the incident edge's
    vertices, and the smallest n.(p - v_ref) [m] of the clipped points, written or not (inf
    when the incident edge misses the reference edge's slab)."""
    nx, ny = rotate(cr, sr, norm[adr_r + face, 0], norm[adr_r + face, 1])
    ax, ay = core_point_world(vert, adr_r + face, xr, yr, cr, sr)
    bx, by = core_point_world(vert, adr_r + (face + 1) % num_r, xr, yr, cr, sr)
    # the reference edge runs along t = n turned a quarter turn counter-clockwise
    tx = -ny
    ty = nx
    length = tx * (bx - ax) + ty * (by - ay)
    e = _incident_edge(norm, adr_i, num_i, ci, si, nx, ny)
    e1 = (e + 1) % num_i
    p0x, p0y = core_point_world(vert, adr_i + e, xi, yi, ci, si)
    p1x, p1y = core_point_world(vert, adr_i + e1, xi, yi, ci, si)
    s0 = tx * (p0x - ax) + ty * (p0y - ay)
    s1 = tx * (p1x - ax) + ty * (p1y - ay)
    # a clipped point is named by the incident edge and the side line that cut it
    x0, y0, clip0, kept0 = _clip_end(p0x, p0y, p1x, p1y, s0, s1, length)
    x1, y1, clip1, kept1 = _clip_end(p1x, p1y, p0x, p0y, s1, s0, length)
    kept1 = kept1 and num_i >= 2
    # one point when the edge meets the slab at a single point (an end on a side line)
    kept1 = kept1 and not (kept0 and x1 == x0 and y1 == y0)
    count = 0
    if kept0:
        count = _face_point(out, count, flip, face, e, clip0, x0, y0, nx, ny,
                            ax, ay, r, margin, ox, oy)
    if kept1:
        count = _face_point(out, count, flip, face, e if clip1 else e1, clip1, x1, y1, nx, ny,
                            ax, ay, r, margin, ox, oy)
    h_min = math.inf
    if kept0:
        h_min = nx * (x0 - ax) + ny * (y0 - ay)
    if kept1:
        h_min = min(h_min, nx * (x1 - ax) + ny * (y1 - ay))
    if not (kept0 or kept1):
        # the whole incident edge outside the slab (only near a tie of reference faces): its
        # deeper vertex, measured to the reference line
        h0 = nx * (p0x - ax) + ny * (p0y - ay)
        h1 = nx * (p1x - ax) + ny * (p1y - ay)
        if h1 < h0:
            count = _face_point(out, 0, flip, face, e1, CLIP_NONE, p1x, p1y, nx, ny, ax, ay,
                                r, margin, ox, oy)
        else:
            count = _face_point(out, 0, flip, face, e, CLIP_NONE, p0x, p0y, nx, ny, ax, ay,
                                r, margin, ox, oy)
    return count, h_min


@kernel
def _support_over_face(vert, norm, adr_r, num_r, xr, yr, cr, sr, face,
                       adr_i, xi, yi, ci, si, support):
    """The incident vertex `support` projects onto the reference edge `face` (not past its
    ends): then its distance to that edge is the face's separation."""
    nx, ny = rotate(cr, sr, norm[adr_r + face, 0], norm[adr_r + face, 1])
    ax, ay = core_point_world(vert, adr_r + face, xr, yr, cr, sr)
    bx, by = core_point_world(vert, adr_r + (face + 1) % num_r, xr, yr, cr, sr)
    px, py = core_point_world(vert, adr_i + support, xi, yi, ci, si)
    h = -ny * (px - ax) + nx * (py - ay)
    return 0.0 <= h <= -ny * (bx - ax) + nx * (by - ay)


@kernel
def _manifold(vert, norm, cover, flip, sep, face, support, cap, adr_r, num_r, xr, yr, cr, sr,
              adr_i, num_i, xi, yi, ci, si, r, margin, ox, oy, out):
    """Steps 2 and 3 of the module docstring, given the reference face `face` of core R
    (separation sep [m], the incident vertex `support` reaching it) and cap, the separation
    along the segments of a pair of one- or two-vertex cores (-inf otherwise)."""
    # cores apart and the closest incident vertex not over the reference face: the closest
    # features may be two vertices
    vertex_pair = False
    d = 0.0
    vr = 0
    vi = 0
    if cap > 0.0 or (sep > 0.0 and not _support_over_face(
            vert, norm, adr_r, num_r, xr, yr, cr, sr, face, adr_i, xi, yi, ci, si, support)):
        d2, vr, vi, interior = _closest_features(vert, adr_r, num_r, xr, yr, cr, sr,
                                                 adr_i, num_i, xi, yi, ci, si)
        d = math.sqrt(d2)
        if d - r > margin:
            return 0
        vertex_pair = not interior and d > 0.0
    count, h_min = _face_manifold(vert, norm, flip, adr_r, num_r, xr, yr, cr, sr, face,
                                  adr_i, num_i, xi, yi, ci, si, r, margin, ox, oy, out)
    if not vertex_pair:
        return count
    gx, gy = core_point_world(vert, adr_r + vr, xr, yr, cr, sr)
    px, py = core_point_world(vert, adr_i + vi, xi, yi, ci, si)
    # the clipped face reaches the distance (a vertex pair only by rounding: edges lying face
    # to face, their ends in line): keep its points, as for a vertex over the face
    if h_min <= d + 1e-12 * (d + abs(gx) + abs(gy) + abs(px) + abs(py)):
        return count
    d = math.hypot(px - gx, py - gy)
    if d - r > margin:
        return 0
    nx, ny = _direction(px - gx, py - gy)
    # a floor tile's corner at a seam is no corner of the floor: touched along a direction
    # its open face does not have, the touch is the neighbouring tile's (or its face's)
    if not (_normal_admitted(vert, norm, cover, adr_r, num_r, cr, sr, vr, nx, ny)
            and _normal_admitted(vert, norm, cover, adr_i, num_i, ci, si, vi, -nx, -ny)):
        # the face's points where it has some over its extent; else, at a flat seam, none
        # (the extended face's stand-in point would duplicate the neighbouring tile's own),
        # at a concave corner the stand-in (a body about to meet the ramp that rises there)
        if h_min < math.inf or _concave(cover, adr_r, num_r, vr) or _concave(
                cover, adr_i, num_i, vi):
            return count
        return 0
    _write(out, 0, flip, KIND_DIST, px, py, nx, ny, gx, gy, d - r,
           _feature_id(flip, KIND_DIST, vr, vi, CLIP_NONE), ox, oy)
    return 1


@kernel
def collide(vert, norm, cover, adr_a, num_a, r_a, xa, ya, ca, sa,
            adr_b, num_b, r_b, xb, yb, cb, sb, margin, out):
    """Contact manifold of two rounded cores, A (rows adr_a.., num_a vertices, radius r_a [m],
    pose xa, ya [m], ca, sa) and B; returns the number of points written to out (0, 1 or 2).
    cover (n_core, 8): the covered edges of world shapes and their ends' normal cones
    (builder.covered_edges): a covered edge is never a reference face (a partly covered one
    not for a vertex over its covered part), and its end vertices are pressed only within
    the floor's normal cone there.

    out[k] = (flip, kind, px, py, nx, ny, gx, gy, gap, id): flip FLIP_A (0) when the reference
    feature is A's (p on B's core) or FLIP_B (1); kind KIND_FACE (0: n the reference edge's
    world normal, g the foot of p on its line) or KIND_DIST (1: g the reference vertex,
    n = (p - g)/|p - g|); p [m] a point of the incident core; n the unit normal from the
    reference shape to the incident; gap [m] = n.(p - g) - r_a - r_b, the signed distance of
    the rounded shapes there; id the feature id (see _feature_id and split_feature_id), the
    same while the same features touch. Only points with gap <= margin [m] are written; two
    points come in the order of the incident edge's vertices.
    """
    r = r_a + r_b
    # B's position relative to A's: coordinates stay the size of the shapes
    dx = xb - xa
    dy = yb - ya
    if num_a < 2 and num_b < 2:
        return _circle_pair(vert, adr_a, ca, sa, adr_b, dx, dy, cb, sb, r, margin, xa, ya, out)
    limit = margin + r
    sep_a = -math.inf
    all_a = -math.inf
    face_a = 0
    support_a = 0
    if num_a >= 2:
        all_a, sep_a, face_a, support_a = _max_separation(
            vert, norm, cover, adr_a, num_a, 0.0, 0.0, ca, sa, adr_b, num_b, dx, dy, cb, sb, limit,
            r)
        if all_a > limit:
            return 0
    sep_b = -math.inf
    all_b = -math.inf
    face_b = 0
    support_b = 0
    if num_b >= 2:
        all_b, sep_b, face_b, support_b = _max_separation(
            vert, norm, cover, adr_b, num_b, dx, dy, cb, sb, adr_a, num_a, 0.0, 0.0, ca, sa, limit,
            r)
        if all_b > limit:
            return 0
    cap = -math.inf
    if num_a <= 2 and num_b <= 2:
        cap = _cap_separation(vert, norm, adr_a, num_a, 0.0, 0.0, ca, sa,
                              adr_b, num_b, dx, dy, cb, sb)
        if cap > limit:
            return 0
    # no face may be a reference (a shape inside the floor); or every face that may would
    # overstate the pair's penetration, which its largest separation over every axis bounds
    # (min(all, 0)), by more than OVERSTATE_TOL: the body is across a covered side, where the
    # neighbouring shape answers for it (a triangle of a strip whose both upper sides are
    # covered would measure a disk on its apex from its bottom: a contact 1.1 m deep). Not
    # at the foot of a ramp, whose face, met a step ahead, is the reference it must be
    best = max(sep_a, sep_b)
    top = max(all_a, all_b)
    slop = OVERSTATE_TOL + REFERENCE_TOL * (1.0 + abs(best))
    if best == -math.inf or best < min(top, 0.0) - slop:
        return 0
    # the reference: A's best face unless B's separates clearly more (REFERENCE_TOL); one
    # call below, so that callers inline the manifold once
    if num_a < 2 or sep_a == -math.inf or sep_b > sep_a + REFERENCE_TOL * (1.0 + abs(sep_a)):
        flip, sep, face, support = FLIP_B, sep_b, face_b, support_b
        adr_r, num_r, xr, yr, cr, sr = adr_b, num_b, dx, dy, cb, sb
        adr_i, num_i, xi, yi, ci, si = adr_a, num_a, 0.0, 0.0, ca, sa
    else:
        flip, sep, face, support = FLIP_A, sep_a, face_a, support_a
        adr_r, num_r, xr, yr, cr, sr = adr_a, num_a, 0.0, 0.0, ca, sa
        adr_i, num_i, xi, yi, ci, si = adr_b, num_b, dx, dy, cb, sb
    count = _manifold(vert, norm, cover, flip, sep, face, support, cap, adr_r, num_r, xr, yr,
                      cr, sr, adr_i, num_i, xi, yi, ci, si, r, margin, xa, ya, out)
    # the same rule on the manifold's points, where a face short of the largest separation is
    # the reference (a covered one refused): a rounded pair's gap is at least top - r (a disk
    # 3 cm above a buried layer's covered top, measured from its slanted side 2 to 5 cm
    # deep, was launched). The clipped points, not the face's separation: measured from a
    # vertex beyond the face's extent, that understates a face met truly (a capsule across a
    # seam above a crest)
    if best < top - slop:
        bound = min(top - r, 0.0) - slop
        for k in range(count):
            if out[k, 8] < bound:
                return 0
    return count
