"""The narrow phase (kernels/geometry/collide.py) against an independent numpy reference: the smallest
gap of a manifold is the exact distance between the rounded shapes when their cores are apart,
minus the separating-axis penetration depth when they overlap; the manifold does not depend on
which shape comes first or where the pair stands; face on face gives two exact points; every
point is consistent (on the incident core, gap = n.(p - g) - r, unit normal, within margin)."""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st
from numba import njit

from planarsim.compile import options as compile_options
from planarsim.kernels.geometry.collide import (FLIP_A, FLIP_B, KIND_DIST, KIND_FACE, REFERENCE_TOL,
                                                collide, core_normals, core_point_world,
                                                split_feature_id)
from strategies import angles, reals, vectors

# not cached: numba checks a cached function against its own file only
jit = njit(**dict(compile_options(), cache=False))


@jit
def _collide_covered(vert, norm, cover, adr_a, num_a, r_a, xa, ya, ca, sa,
                     adr_b, num_b, r_b, xb, yb, cb, sb, margin, out):
    return collide(vert, norm, cover, adr_a, num_a, r_a, xa, ya, ca, sa,
                   adr_b, num_b, r_b, xb, yb, cb, sb, margin, out)


def _collide(vert, norm, *args):
    """collide with no covered edge."""
    return _collide_covered(vert, norm, np.zeros((vert.shape[0], 8)), *args)


@jit
def _point(vert, k, x, y, c, s):
    return core_point_world(vert, k, x, y, c, s)


# ---------------------------------------------------------------- shapes and the call

def circle(r, cx=0.0, cy=0.0):
    return np.array([[cx, cy]]), r


def capsule(half, r, angle=0.0, cx=0.0, cy=0.0):
    d = half * np.array([math.cos(angle), math.sin(angle)])
    return np.array([[cx, cy]]) + np.array([-d, d]), r


def box(hw, hh, r=0.0):
    return np.array([[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]]), r


def hull(points):
    """Convex hull, counter-clockwise (Andrew's monotone chain), collinear points dropped."""
    pts = sorted(map(tuple, points))

    def half(seq):
        h = []
        for p in seq:
            while len(h) >= 2 and ((h[-1][0] - h[-2][0]) * (p[1] - h[-2][1])
                                   - (h[-1][1] - h[-2][1]) * (p[0] - h[-2][0])) <= 0:
                h.pop()
            h.append(p)
        return h
    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


@st.composite
def polygons(draw, size):
    """A convex polygon core of 3 to 8 vertices about a centre within 0.3 size of the origin,
    of diameter about 2 size [m]: vertices at drawn radii (0.3 to 1 size) and angles (gaps of
    0.05 to 1 in proportion around the turn, from a drawn start), the y axis squeezed by a
    drawn 0.3 to 1."""
    n = draw(st.integers(3, 8))
    gaps = np.array(draw(st.lists(reals(0.05, 1.0), min_size=n, max_size=n)))
    ang = draw(angles()) + 2.0 * np.pi * np.cumsum(gaps) / gaps.sum()
    rad = size * draw(vectors(n, 0.3, 1.0))
    stretch = draw(reals(0.3, 1.0))
    pts = np.stack([rad * np.cos(ang), stretch * rad * np.sin(ang)], 1)
    core = hull(pts + size * draw(vectors(2, -0.3, 0.3)))
    assume(len(core) >= 3)          # (three vertices in a line: not a polygon)
    return core


def run(shape_a, pose_a, shape_b, pose_b, margin=1e3):
    """collide on two shapes ((local core vertices, r), pose (x, y, angle)): the rows written."""
    (va, ra), (vb, rb) = shape_a, shape_b
    vert = np.concatenate([va, vb]).astype(np.float64)
    norm = np.concatenate([core_normals(va), core_normals(vb)])
    out = np.full((2, 10), np.nan)
    n = _collide(vert, norm, 0, len(va), float(ra), float(pose_a[0]), float(pose_a[1]),
                 math.cos(pose_a[2]), math.sin(pose_a[2]), len(va), len(vb), float(rb),
                 float(pose_b[0]), float(pose_b[1]), math.cos(pose_b[2]), math.sin(pose_b[2]),
                 float(margin), out)
    assert 0 <= n <= 2
    return out[:n].copy()


# ---------------------------------------------------------------- the numpy reference

def world(shape, pose):
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    v = shape[0]
    return np.stack([x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]], 1)


def edges(P):
    if len(P) == 1:
        return []
    if len(P) == 2:
        return [(P[0], P[1])]
    return [(P[k], P[(k + 1) % len(P)]) for k in range(len(P))]


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def point_segment(p, a, b):
    e = b - a
    u = np.clip(np.dot(p - a, e) / np.dot(e, e), 0.0, 1.0)
    return float(np.hypot(*(p - a - u * e)))


def segments_cross(a, b, c, d):
    d1, d2 = cross(b - a, c - a), cross(b - a, d - a)
    d3, d4 = cross(d - c, a - c), cross(d - c, b - c)
    if ((d1 > 0 and d2 < 0) or (d1 < 0 and d2 > 0)) and ((d3 > 0 and d4 < 0) or (d3 < 0 and d4 > 0)):
        return True
    return min(point_segment(c, a, b), point_segment(d, a, b),
               point_segment(a, c, d), point_segment(b, c, d)) == 0.0


def inside(P, p):
    return len(P) >= 3 and all(cross(b - a, p - a) >= 0.0 for a, b in edges(P))


def cores_intersect(P, Q):
    if len(P) == 1 and len(Q) == 1:
        return bool(np.all(P[0] == Q[0]))
    if any(inside(Q, p) for p in P) or any(inside(P, q) for q in Q):
        return True
    for p in P:
        if any(point_segment(p, a, b) == 0.0 for a, b in edges(Q)):
            return True
    for q in Q:
        if any(point_segment(q, a, b) == 0.0 for a, b in edges(P)):
            return True
    return any(segments_cross(a, b, c, d) for a, b in edges(P) for c, d in edges(Q))


def core_distance(P, Q):
    """Distance [m] between two disjoint convex cores: every vertex against every edge."""
    d = [float(np.hypot(*(p - q))) for p in P for q in Q]
    d += [point_segment(p, a, b) for p in P for a, b in edges(Q)]
    d += [point_segment(q, a, b) for q in Q for a, b in edges(P)]
    return min(d)


def face_normals(P):
    out = []
    for a, b in edges(P):
        e = b - a
        n = np.array([e[1], -e[0]]) / np.hypot(*e)
        out.append((a, n))
        if len(P) == 2:
            out.append((b, -n))
    return out


def sat_separation(P, Q):
    """Largest over both cores' edge normals of the separation (minus the SAT depth)."""
    seps = [min(np.dot(q - a, n) for q in Q) for a, n in face_normals(P)]
    seps += [min(np.dot(p - a, n) for p in P) for a, n in face_normals(Q)]
    return max(seps)


def sat_tie(P, Q):
    """Two faces (of either core) within rounding of the largest separation whose normals,
    taken from P towards Q, differ: the reference is then a matter of rounding."""
    faces = [(min(np.dot(q - a, n) for q in Q), n) for a, n in face_normals(P)]
    faces += [(min(np.dot(p - a, n) for p in P), -n) for a, n in face_normals(Q)]
    if not faces:
        return False
    top = max(f[0] for f in faces)
    near = [n for sep, n in faces if sep >= top - 1e-9 * (1.0 + abs(top))]
    return any(np.hypot(*(n - near[0])) > 1e-9 for n in near)


def expected_gap(shape_a, pose_a, shape_b, pose_b):
    """The smallest gap [m] the manifold must hold: the distance between the rounded shapes
    (cores apart) or the SAT separation minus the radii (cores overlapping)."""
    P, Q = world(shape_a, pose_a), world(shape_b, pose_b)
    r = shape_a[1] + shape_b[1]
    if (len(P) == 1 and len(Q) == 1) or not cores_intersect(P, Q):
        return core_distance(P, Q) - r
    return sat_separation(P, Q) - r


def scale_of(*things):
    return max([1.0] + [float(np.max(np.abs(np.asarray(t)))) for t in things])


def close(a, b, scale=1.0):
    return abs(a - b) <= 1e-9 * abs(b) + 1e-12 * scale


# ---------------------------------------------------------------- hypothesis strategies

@st.composite
def shapes(draw, kinds=("circle", "capsule", "box", "polygon", "rounded_box"), sizes=(5e-4, 5.0),
           offset=1.0, radii=(1e-3, 2.0)):
    """(core, r): one of `kinds` of size in `sizes` [m]; a circle's or capsule's centre within
    `offset` [m] of the origin along each axis, a capsule's radius in `radii` [m] and its angle,
    a box's aspect (0.05 to 1) and a rounded box's radius (1 mm to 0.5 m), a polygon's
    vertices drawn."""
    kind = draw(st.sampled_from(kinds))
    size = draw(reals(*sizes))
    off = draw(st.tuples(reals(-offset, offset), reals(-offset, offset)))
    if kind == "circle":
        return circle(size, off[0], off[1])
    if kind == "capsule":
        return capsule(size, draw(reals(*radii)), draw(angles()), off[0], off[1])
    if kind in ("box", "rounded_box"):
        aspect = draw(reals(0.05, 1.0))
        r = draw(reals(1e-3, 0.5)) if kind == "rounded_box" else 0.0
        return box(size, aspect * size, r)
    return draw(polygons(size)), 0.0


def bound(shape):
    return float(np.max(np.hypot(shape[0][:, 0], shape[0][:, 1]))) + shape[1]


@st.composite
def pairs(draw):
    """Two shapes at poses near each other: apart, touching through their radii, overlapping."""
    a, b = draw(shapes()), draw(shapes())
    pose_a = (draw(st.floats(-5.0, 5.0)), draw(st.floats(-5.0, 5.0)),
              draw(st.floats(-math.pi, math.pi)))
    dist = draw(st.floats(0.0, 1.2)) * (bound(a) + bound(b))
    phi = draw(st.floats(-math.pi, math.pi))
    pose_b = (pose_a[0] + dist * math.cos(phi), pose_a[1] + dist * math.sin(phi),
              draw(st.floats(-math.pi, math.pi)))
    return a, pose_a, b, pose_b


def check_points(rows, shape_a, pose_a, shape_b, pose_b, margin):
    """Every written point: finite, gap <= margin, unit normal, gap = n.(p - g) - r, p on the
    incident core, g on the reference edge's line (FACE) or a reference vertex (DIST)."""
    assert np.all(np.isfinite(rows))
    P, Q = world(shape_a, pose_a), world(shape_b, pose_b)
    r = shape_a[1] + shape_b[1]
    scale = scale_of(P, Q)
    for row in rows:
        flip, kind, p, n, g, gap = row[0], row[1], row[2:4], row[4:6], row[6:8], row[8]
        assert flip in (FLIP_A, FLIP_B) and kind in (KIND_FACE, KIND_DIST)
        assert gap <= margin
        assert abs(np.hypot(*n) - 1.0) < 1e-12
        assert abs(np.dot(n, p - g) - r - gap) <= 1e-12 * scale
        ref, inc = (P, Q) if flip == FLIP_A else (Q, P)
        fl, kd, ref_k, inc_k, clip = split_feature_id(row[9])
        assert (fl, kd) == (flip, kind)
        if kind == KIND_DIST:
            assert np.allclose(p, inc[inc_k], rtol=0.0, atol=1e-12 * scale)
            assert np.allclose(g, ref[ref_k], rtol=0.0, atol=1e-12 * scale)
        else:
            # n: the outward normal of reference edge ref_k (vertex ref_k to the next)
            a, e = ref[ref_k], ref[(ref_k + 1) % len(ref)] - ref[ref_k]
            # the reference normal from world vertices: rounding of e = b - a at the
            # coordinates' scale, relative to the edge's length (a 60 um edge at 1 m: 4e-12)
            tol = 1e-12 + 8 * np.finfo(float).eps * scale / np.hypot(*e)
            assert np.allclose(n, np.array([e[1], -e[0]]) / np.hypot(*e), rtol=0.0, atol=tol)
            assert abs(np.dot(n, g - a)) <= 1e-12 * scale
            on = min([point_segment(p, c, d) for c, d in edges(inc)]
                     + [float(np.hypot(*(p - v))) for v in inc])
            assert on <= 1e-12 * scale


# ---------------------------------------------------------------- properties

@settings(max_examples=300, deadline=None)
@given(pairs())
def test_smallest_gap_is_distance_or_minus_depth(pair):
    a, pose_a, b, pose_b = pair
    want = expected_gap(a, pose_a, b, pose_b)
    scale = scale_of(world(a, pose_a), world(b, pose_b))
    margin = max(want, 0.0) * 1.001 + 1e-9
    rows = run(a, pose_a, b, pose_b, margin)
    assert len(rows) >= 1
    got = rows[:, 8].min()
    # exact, but where A's face was kept as the reference against a face of B separating by
    # less than REFERENCE_TOL more: then up to that much below (never above)
    tie = REFERENCE_TOL * (1.0 + abs(want + a[1] + b[1]))
    assert close(got, want, scale) or want - tie - 1e-12 * scale <= got <= want, (rows[:, 8], want)
    check_points(rows, a, pose_a, b, pose_b, margin)
    # just inside the margin: nothing
    if want > 1e-9:
        assert len(run(a, pose_a, b, pose_b, 0.999 * want)) == 0


def normals_a_to_b(rows):
    return np.where(rows[:, :1] == FLIP_A, rows[:, 4:6], -rows[:, 4:6])


@settings(max_examples=300, deadline=None)
@given(pairs())
def test_swapping_shapes_swaps_the_reference(pair):
    a, pose_a, b, pose_b = pair
    scale = scale_of(world(a, pose_a), world(b, pose_b))
    ab = run(a, pose_a, b, pose_b)
    ba = run(b, pose_b, a, pose_a)
    check_points(ab, a, pose_a, b, pose_b, 1e3)
    check_points(ba, b, pose_b, a, pose_a, 1e3)
    assert len(ab) >= 1 and len(ba) >= 1
    if sat_tie(world(a, pose_a), world(b, pose_b)):
        # the reference face is then a matter of rounding and REFERENCE_TOL, and so are the
        # other points
        assert close(ab[:, 8].min(), ba[:, 8].min(), scale) or abs(
            ab[:, 8].min() - ba[:, 8].min()) <= REFERENCE_TOL * (1.0 + abs(ab[:, 8].min()) + a[1] + b[1])
        return
    assert len(ab) == len(ba)
    assert all(close(x, y, scale) for x, y in zip(sorted(ab[:, 8]), sorted(ba[:, 8])))
    # the normal from A to B at the deepest point (but for coincident circle centres, whose
    # fixed normal (0, 1) points from whichever comes first)
    k_ab, k_ba = np.argmin(ab[:, 8]), np.argmin(ba[:, 8])
    if np.any(ab[k_ab, 2:4] != ab[k_ab, 6:8]):
        assert np.allclose(normals_a_to_b(ab)[k_ab], -normals_a_to_b(ba)[k_ba], rtol=0.0, atol=1e-9)


@settings(max_examples=300, deadline=None)
@given(pairs(), st.floats(-50.0, 50.0), st.floats(-50.0, 50.0), st.floats(-math.pi, math.pi))
def test_gaps_do_not_depend_on_where_the_pair_stands(pair, tx, ty, turn):
    a, pose_a, b, pose_b = pair
    c, s = math.cos(turn), math.sin(turn)

    def moved(pose):
        return (tx + c * pose[0] - s * pose[1], ty + s * pose[0] + c * pose[1], pose[2] + turn)
    scale = scale_of(world(a, pose_a), world(b, pose_b), [tx, ty])
    here = run(a, pose_a, b, pose_b)
    there = run(a, moved(pose_a), b, moved(pose_b))
    assert len(here) >= 1 and len(there) >= 1
    if sat_tie(world(a, pose_a), world(b, pose_b)):
        # the reference face is then a matter of rounding and REFERENCE_TOL
        assert close(here[:, 8].min(), there[:, 8].min(), scale) or abs(
            here[:, 8].min() - there[:, 8].min()) <= REFERENCE_TOL * (1.0 + abs(here[:, 8].min()) + a[1] + b[1])
        return
    assert len(here) == len(there)
    assert all(close(x, y, scale) for x, y in zip(sorted(here[:, 8]), sorted(there[:, 8])))
    assert np.array_equal(here[:, :2], there[:, :2])


def generic_shapes():
    """Shapes of 1 cm to 3 m, centres within 0.5 m, capsule radii 1 cm to 1 m, no rounded box."""
    return shapes(kinds=("circle", "capsule", "box", "polygon"), sizes=(0.01, 3.0), offset=0.5,
                  radii=(0.01, 1.0))


@settings(max_examples=300, deadline=None)
@given(generic_shapes(), generic_shapes(), vectors(3, -3.0, 3.0), reals(0.0, 1.1), reals(-3.0, 3.0),
       reals(-3.0, 3.0))
def test_feature_ids_hold_under_a_tiny_move(a, b, pose_a, reach, phi, angle_b):
    """Two drawn shapes, B at a drawn direction phi from A and a distance of 0 to 1.1 times
    the sum of their bounding radii, in a generic configuration: a 1e-9 m move of B keeps
    every id. Generic (as a continuous random draw almost surely is, and a shrunk draw often
    is not: a circle centred on a capsule's core): no feature switch within 1e-6 m of B's
    place, seen as ids unchanged by 1e-6 m moves either way along two directions 1 rad apart."""
    pose_a = tuple(pose_a)
    dist = reach * (bound(a) + bound(b))
    pose_b = (pose_a[0] + dist * math.cos(phi), pose_a[1] + dist * math.sin(phi), angle_b)

    def moved_by(length, direction):
        return run(a, pose_a, b, (pose_b[0] + length * math.cos(direction),
                                  pose_b[1] + length * math.sin(direction), pose_b[2]))
    rows = run(a, pose_a, b, pose_b)
    for direction in (phi + 2.0, phi + 3.0):
        for length in (1e-6, -1e-6):
            assume(list(moved_by(length, direction)[:, 9]) == list(rows[:, 9]))
    moved = moved_by(1e-9, phi + 1.0)
    assert list(rows[:, 9]) == list(moved[:, 9])
    # the distance and the SAT separation move no more than the shape
    assert abs(rows[:, 8].min() - moved[:, 8].min()) <= 1.001e-9


@settings(max_examples=300, deadline=None)
@given(st.floats(5e-4, 5.0), st.floats(0.05, 1.0), st.floats(5e-4, 5.0), st.floats(0.05, 1.0),
       st.floats(-0.9, 0.9), st.floats(-0.01, 0.01), st.floats(-math.pi, math.pi),
       st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), st.booleans())
def test_box_on_box_gives_two_exact_points(wa, aa, wb, ab, frac, rel_gap, th, xa, ya, swap):
    """Same angle, overlapping extents along the face: two FACE points with the vertical gap,
    at the ends of the overlap of the two faces."""
    ha, hb = aa * wa, ab * wb
    u = frac * (wa + wb)
    gap = rel_gap * min(wa, ha, wb, hb)
    c, s = math.cos(th), math.sin(th)
    lx, ly = u, ha + hb + gap
    pose_a = (xa, ya, th)
    pose_b = (xa + c * lx - s * ly, ya + s * lx + c * ly, th)
    A, B = box(wa, ha), box(wb, hb)
    margin = max(gap, 0.0) + 1e-3 * min(ha, hb)
    rows = run(B, pose_b, A, pose_a, margin) if swap else run(A, pose_a, B, pose_b, margin)
    scale = scale_of([xa, ya, wa, wb, ha, hb])
    assert len(rows) == 2
    assert np.all(rows[:, 1] == KIND_FACE)
    assert all(close(g, gap, scale) for g in rows[:, 8])
    # the points along A's face, in A's frame
    x_local = c * (rows[:, 2] - xa) + s * (rows[:, 3] - ya)
    ends = [max(-wa, u - wb), min(wa, u + wb)]
    assert np.allclose(sorted(x_local), ends, rtol=0.0, atol=1e-12 * scale)
    check_points(rows, *((B, pose_b, A, pose_a) if swap else (A, pose_a, B, pose_b)), margin)


# ---------------------------------------------------------------- hand cases

def test_box_stacked_on_box():
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), box(0.5, 0.1), (0.0, 0.2, 0.0), 1e-3)
    assert len(rows) == 2
    assert np.all(rows[:, 0] == FLIP_A) and np.all(rows[:, 1] == KIND_FACE)
    assert np.allclose(rows[:, 8], 0.0, atol=1e-15)
    assert np.allclose(rows[:, 4:6], [[0.0, 1.0]] * 2)
    assert np.allclose(sorted(rows[:, 2]), [-0.5, 0.5]) and np.allclose(rows[:, 3], 0.1)
    assert len({split_feature_id(f) for f in rows[:, 9]}) == 2


def test_tilted_box_on_its_corner_gives_one_point():
    th = math.radians(30.0)
    corner = np.array([-0.25, -0.05])   # lowest corner of the tilted box, in its frame
    c, s = math.cos(th), math.sin(th)
    low = np.array([c * corner[0] - s * corner[1], s * corner[0] + c * corner[1]])
    pose_b = (0.1 - low[0], 0.1 - low[1] + 1e-4, th)
    rows = run(box(1.0, 0.1), (0.0, 0.0, 0.0), box(0.25, 0.05), pose_b, 1e-3)
    assert len(rows) == 1
    assert rows[0, 1] == KIND_FACE and abs(rows[0, 8] - 1e-4) < 1e-15
    assert np.allclose(rows[0, 2:4], [0.1, 0.1 + 1e-4]) and np.allclose(rows[0, 6:8], [0.1, 0.1])


def test_circle_resting_on_box():
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), circle(0.1), (0.2, 0.21, 0.0), 0.05)
    assert len(rows) == 1
    flip, kind = rows[0, :2]
    assert (flip, kind) == (FLIP_A, KIND_FACE)
    assert np.allclose(rows[0, 2:8], [0.2, 0.21, 0.0, 1.0, 0.2, 0.1])
    assert abs(rows[0, 8] - 0.01) < 1e-15
    # the same with the circle first: the box stays the reference
    rows = run(circle(0.1), (0.2, 0.21, 0.0), box(0.5, 0.1), (0.0, 0.0, 0.0), 0.05)
    assert rows[0, 0] == FLIP_B and np.allclose(rows[0, 4:6], [0.0, 1.0])
    # centre inside the box: the face of least penetration (the right face, 0.05 away)
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), circle(0.02), (0.45, 0.0, 0.0), 0.0)
    assert len(rows) == 1 and np.allclose(rows[0, 4:6], [1.0, 0.0])
    assert abs(rows[0, 8] - (-0.05 - 0.02)) < 1e-15


def test_circle_near_box_corner_is_vertex_to_vertex():
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), circle(0.1), (0.8, 0.5, 0.0), 1.0)
    assert len(rows) == 1 and rows[0, 1] == KIND_DIST
    assert abs(rows[0, 8] - (0.5 - 0.1)) < 1e-15
    assert np.allclose(rows[0, 4:6], [0.6, 0.8]) and np.allclose(rows[0, 6:8], [0.5, 0.1])


def test_box_corner_near_box_corner():
    rows = run(box(0.5, 0.5), (0.0, 0.0, 0.0), box(0.5, 0.5), (1.3, 1.4, 0.0), 1.0)
    assert len(rows) == 1 and rows[0, 1] == KIND_DIST
    assert abs(rows[0, 8] - 0.5) < 1e-15
    assert np.allclose(rows[0, 4:6], [0.6, 0.8])


def test_capsule_lying_on_box():
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.3, 0.05), (0.1, 0.149, 0.0), 1e-3)
    assert len(rows) == 2 and np.all(rows[:, 1] == KIND_FACE)
    assert np.allclose(rows[:, 8], -0.001, rtol=0.0, atol=1e-15)
    assert np.allclose(sorted(rows[:, 2]), [-0.2, 0.4])
    # overhanging the box's end: clipped at its corner
    rows = run(box(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.3, 0.05), (0.4, 0.15, 0.0), 1e-3)
    assert len(rows) == 2 and np.allclose(sorted(rows[:, 2]), [0.1, 0.5])


def test_two_parallel_capsules():
    rows = run(capsule(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.5, 0.05), (0.3, 0.14, 0.0), 1e-3)
    assert len(rows) == 2 and np.allclose(rows[:, 8], -0.01, atol=1e-15)
    assert np.allclose(np.abs(rows[:, 5]), 1.0)


def test_circles():
    rows = run(circle(0.1), (0.0, 0.0, 0.0), circle(0.2), (0.3, 0.4, 1.0), 0.5)
    assert len(rows) == 1 and rows[0, 1] == KIND_DIST
    assert abs(rows[0, 8] - 0.2) < 1e-15 and np.allclose(rows[0, 4:6], [0.6, 0.8])
    assert len(run(circle(0.1), (0.0, 0.0, 0.0), circle(0.2), (0.3, 0.4, 1.0), 0.1)) == 0
    # coincident centres: the fixed normal (0, 1)
    rows = run(circle(0.1), (1.0, 2.0, 0.0), circle(0.2), (1.0, 2.0, 0.0), 0.0)
    assert np.allclose(rows[0, 4:6], [0.0, 1.0]) and abs(rows[0, 8] + 0.3) < 1e-15
    # an off-centre core vertex turns with its body
    rows = run(circle(0.1, 1.0, 0.0), (0.0, 0.0, math.pi / 2), circle(0.1), (0.0, 1.5, 0.0), 1.0)
    assert abs(rows[0, 8] - 0.3) < 1e-15 and np.allclose(rows[0, 6:8], [0.0, 1.0])


def test_circle_and_capsule():
    cap = capsule(0.5, 0.1)
    # over the side: FACE from the capsule's segment
    rows = run(cap, (0.0, 0.0, 0.0), circle(0.1), (0.2, -0.3, 0.0), 1.0)
    assert len(rows) == 1 and tuple(rows[0, :2]) == (FLIP_A, KIND_FACE)
    assert abs(rows[0, 8] - 0.1) < 1e-15 and np.allclose(rows[0, 4:8], [0.0, -1.0, 0.2, 0.0])
    # past the end: vertex to vertex
    rows = run(circle(0.1), (0.9, 0.3, 0.0), cap, (0.0, 0.0, 0.0), 1.0)
    assert len(rows) == 1 and tuple(rows[0, :2]) == (FLIP_B, KIND_DIST)
    assert abs(rows[0, 8] - 0.3) < 1e-15 and np.allclose(rows[0, 4:6], [0.8, 0.6])
    # in line with the segment, beyond its end (edge normals alone would call this touching)
    rows = run(cap, (0.0, 0.0, 0.0), circle(0.1), (0.8, 0.0, 0.0), 1.0)
    assert len(rows) == 1 and rows[0, 1] == KIND_DIST
    assert abs(rows[0, 8] - 0.1) < 1e-15 and np.allclose(rows[0, 4:6], [1.0, 0.0])
    # centre on the segment
    rows = run(cap, (0.0, 0.0, 0.0), circle(0.1), (0.2, 0.0, 0.0), 0.0)
    assert len(rows) == 1 and abs(rows[0, 8] + 0.2) < 1e-15


def test_capsules_in_line_and_crossed():
    rows = run(capsule(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.5, 0.1), (1.5, 0.0, 0.0), 1.0)
    assert len(rows) == 1 and rows[0, 1] == KIND_DIST and abs(rows[0, 8] - 0.3) < 1e-15
    rows = run(capsule(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.5, 0.1), (0.0, 0.1, math.pi / 2), 0.0)
    assert len(rows) >= 1 and abs(rows[:, 8].min() - (-0.4 - 0.2)) < 1e-15


def test_degenerate_contacts_stay_finite():
    """Touching corners, identical boxes on top of each other, zero-size overlaps."""
    cases = [(box(0.5, 0.5), (0.0, 0.0, 0.0), box(0.5, 0.5), (1.0, 1.0, 0.0)),
             (box(0.5, 0.5), (0.0, 0.0, 0.0), box(0.5, 0.5), (0.0, 0.0, 0.0)),
             (box(0.5, 0.5), (0.0, 0.0, 0.0), box(0.5, 0.5), (1.0, 0.0, 0.0)),
             (capsule(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.5, 0.1), (0.0, 0.0, 0.0)),
             (capsule(0.5, 0.1), (0.0, 0.0, 0.0), capsule(0.5, 0.1), (1.0, 0.0, 0.0)),
             (circle(0.1), (0.0, 0.0, 0.0), box(0.5, 0.5), (0.0, 0.0, 0.0)),
             (circle(0.1), (0.5, 0.5, 0.0), box(0.5, 0.5), (0.0, 0.0, 0.0))]
    for a, pa, b, pb in cases:
        for order in ((a, pa, b, pb), (b, pb, a, pa)):
            rows = run(*order)
            assert len(rows) >= 1
            check_points(rows, *order, 1e3)
            assert abs(rows[:, 8].min() - expected_gap(*order)) < 1e-12


def test_core_normals_and_world_point():
    assert np.array_equal(core_normals([[0.3, 0.4]]), [[0.0, 0.0]])
    assert np.allclose(core_normals([[0.0, 0.0], [2.0, 0.0]]), [[0.0, -1.0], [0.0, 1.0]])
    assert np.allclose(core_normals(box(1.0, 0.5)[0]), [[0, -1], [1, 0], [0, 1], [-1, 0]])
    with pytest.raises(ValueError):
        core_normals(box(1.0, 0.5)[0][::-1])    # clockwise
    with pytest.raises(ValueError):
        core_normals([[0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(ValueError):
        core_normals([[0, 0], [2, 0], [1, 0.2], [1, 1]])   # not convex
    vert = np.array([[3.0, 4.0], [0.0, 1.0], [-1.0, 0.0]])
    wx, wy = _point(vert, 1, 2.0, 3.0, 0.0, 1.0)
    assert (wx, wy) == (1.0, 3.0)
