"""Collision shapes as the kernels see them: a convex core and a radius.

Every shape is a convex core plus a radius r >= 0 (its points within r of the core):
  circle    one core vertex (the centre), r > 0
  capsule   two core vertices (the segment's ends), r > 0
  box       four core vertices (counter-clockwise), r = 0
  polygon   n >= 3 core vertices (convex, counter-clockwise), r = 0
so one manifold routine (kernels/geometry/collide.py) serves every pair. Coordinates are the body's
local frame [m] (the world's for a static shape, body -1).

Which pairs of shapes can touch is decided once, here, when the model is compiled
(``collision_pairs``): two shapes collide when they lie on different bodies (not both the
world), their category and mask bits accept each other (``cat_a & mask_b`` and
``cat_b & mask_a`` non-zero, as Box2D and MuJoCo's contype/conaffinity), and their bodies are
not parts of one mechanism (bodies linked by pins or rods, directly or through others, do
not collide with each other unless the pair is enabled by ``ModelBuilder.enable_collision``;
actuators link bodies too: the Simple Biped's legs are forces between its point masses).
"""
from __future__ import annotations

import math

import numpy as np

from .disjoint_sets import DisjointSets
from .errors import ModelError

SHAPE_KINDS = ("circle", "capsule", "box", "polygon")
# two core vertices closer than this are one point [m]; a polygon's turn at a vertex below
# this share of its edges' lengths is no turn (collinear)
CORE_TOL = 1e-12


def shape_who(kind, idx, name=None, body=False) -> str:
    """How messages name a shape: its name= where it has one, its kind and index, its body:
    "shape 'heel' (circle 0) of body 'shin_L'", "circle shape (3) of body 'shin_L'", "static
    box shape (2)". body: the body's name, None for a static shape (fixed in the world), False
    when not known (the shape's body is what is wrong)."""
    who = f"shape {name!r} ({kind} {idx})" if name else f"{kind} shape ({idx})"
    if body is False:
        return who
    return f"static {who}" if body is None else f"{who} of body {body!r}"


def box_vertices(center, width, height, angle=0.0):
    """The four corners (4, 2) [m] of a box, counter-clockwise from (-w/2, -h/2)."""
    ca, sa = math.cos(angle), math.sin(angle)
    out = []
    for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        lx, ly = 0.5 * width * sx, 0.5 * height * sy
        out.append((center[0] + ca * lx - sa * ly, center[1] + sa * lx + ca * ly))
    return np.array(out, dtype=np.float64)


def convex_ccw(vertices, who):
    """The vertices (n, 2) of a convex polygon in counter-clockwise order (a clockwise one is
    reversed). ModelError naming `who` when there are fewer than 3, two coincide, three are
    collinear, or the polygon is not convex (or winds around more than once)."""
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 2:
        raise ModelError(f"{who}: vertices must be a list of (x, y) pairs, got shape {v.shape}")
    if v.shape[0] < 3:
        raise ModelError(f"{who}: a polygon needs at least 3 vertices, got {v.shape[0]}")
    if not np.all(np.isfinite(v)):
        raise ModelError(f"{who}: vertices must be finite")
    edges = np.roll(v, -1, axis=0) - v
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    scale = float(np.max(np.abs(v))) + 1.0
    if np.any(lengths <= CORE_TOL * scale):
        k = int(np.argmin(lengths))
        raise ModelError(f"{who}: vertices {k} and {(k + 1) % len(v)} coincide")
    turns = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
    area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    sign = 1.0 if area2 > 0 else -1.0
    flat = np.abs(turns) <= CORE_TOL * lengths * np.roll(lengths, -1)
    if np.any(flat):
        k = int(np.argmax(flat))
        raise ModelError(f"{who}: vertex {(k + 1) % len(v)} lies on the line of its neighbours "
                         "(drop it)")
    if np.any(turns * sign < 0):
        k = int(np.argmax(turns * sign < 0))
        raise ModelError(f"{who}: the polygon is not convex (it turns the other way at vertex "
                         f"{(k + 1) % len(v)}); split it into convex pieces")
    # convex turns all one way but winding twice (a star drawn in one stroke)
    angles = np.arctan2(edges[:, 1], edges[:, 0])
    total = np.sum(np.angle(np.exp(1j * (np.roll(angles, -1) - angles))))
    if abs(abs(total) - 2 * math.pi) > 1e-6:
        raise ModelError(f"{who}: the polygon winds around {abs(total) / (2 * math.pi):.0f} times; "
                         "give its vertices once, in order")
    return v if sign > 0 else v[::-1].copy()


def collision_core(kind, params, who):
    """(core (n, 2), radius) of a colliding shape's parameters, validated: radii > 0, box
    sides > 0, a capsule's ends apart, a polygon convex with at least 3 distinct vertices;
    errors name `who` (shape_who)."""
    if kind == "circle":
        center, radius = params[0], float(params[1])
        if not radius > 0:
            raise ModelError(f"{who}: radius={radius} must be > 0 for a shape that collides")
        return np.array([center], dtype=np.float64), radius
    if kind == "capsule":
        p0, p1, radius = np.asarray(params[0], float), np.asarray(params[1], float), float(params[2])
        if not radius > 0:
            raise ModelError(f"{who}: radius={radius} must be > 0 for a shape that collides")
        if math.hypot(*(p1 - p0)) <= CORE_TOL * (1.0 + np.max(np.abs(np.r_[p0, p1]))):
            raise ModelError(f"{who}: p0 and p1 coincide; use a circle")
        return np.array([p0, p1], dtype=np.float64), radius
    if kind == "box":
        angle = float(params[3]) if len(params) > 3 else 0.0
        return box_vertices(params[0], float(params[1]), float(params[2]), angle), 0.0
    if kind == "polygon":
        return convex_ccw(params[0], who), 0.0
    raise ModelError(f"{who}: kind must be one of {', '.join(SHAPE_KINDS)}")


# mass properties -----------------------------------------------------------------------------
def shape_area(kind, params, who="shape") -> tuple:
    """(area A [m^2], centroid (2,) [m], polar second moment of area about the centroid
    J [m^4]) of a shape given as add_shape takes it (a solid of unit area density: its mass is
    A, its moment of inertia J). Capsule: a rectangle of the segment's length L and width 2r
    plus two half disks (Box2D's b2ComputeCapsuleMass); convex polygon: triangles from an
    inner point."""
    if kind == "circle":
        r = float(params[1])
        area = math.pi * r * r
        return area, np.asarray(params[0], dtype=np.float64).reshape(2), 0.5 * area * r * r
    if kind == "capsule":
        p0 = np.asarray(params[0], dtype=np.float64).reshape(2)
        p1 = np.asarray(params[1], dtype=np.float64).reshape(2)
        r = float(params[2])
        length = math.hypot(*(p1 - p0))
        rect, disk = 2.0 * r * length, math.pi * r * r
        arm = 4.0 * r / (3.0 * math.pi)     # a half disk's centroid from its flat side
        # rectangle (L^2 + 4 r^2)/12; half disks: r^2/2 about their centre, shifted out by L/2
        j = (rect * (length * length + 4.0 * r * r) / 12.0
             + disk * (0.5 * r * r + 0.25 * length * length + length * arm))
        return rect + disk, 0.5 * (p0 + p1), j
    if kind == "box":
        w, h = float(params[1]), float(params[2])
        return w * h, np.asarray(params[0], dtype=np.float64).reshape(2), w * h * (w * w + h * h) / 12.0
    if kind == "polygon":
        v = convex_ccw(params[0], who)
        o = v.mean(axis=0)                  # an inner point: the triangles' common vertex
        e1, e2 = v - o, np.roll(v, -1, axis=0) - o
        cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        area = 0.5 * float(np.sum(cross))
        c = np.sum(cross[:, None] * (e1 + e2), axis=0) / (6.0 * area)
        j_o = float(np.sum(cross * (np.sum(e1 * e1, axis=1) + np.sum(e1 * e2, axis=1)
                                    + np.sum(e2 * e2, axis=1)))) / 12.0
        return area, o + c, j_o - area * float(c @ c)
    raise ModelError(f"{who}: kind={kind!r} must be one of {', '.join(SHAPE_KINDS)}")


def combine_masses(parts) -> tuple:
    """(mass [kg], centre of mass (2,) [m], inertia about it [kg m^2]) of rigidly joined parts
    (mass, centre (2,), inertia about that centre): the parallel-axis theorem."""
    parts = list(parts)
    mass = sum(m for m, _, _ in parts)
    if not mass > 0:
        return 0.0, np.zeros(2), 0.0
    c = sum(m * np.asarray(p, dtype=np.float64) for m, p, _ in parts) / mass
    inertia = sum(i + m * float((np.asarray(p) - c) @ (np.asarray(p) - c)) for m, p, i in parts)
    return float(mass), c, float(inertia)


def mass_properties(shapes, density) -> tuple:
    """(mass [kg], centroid (2,) [m], moment of inertia about the centroid [kg m^2]) of solid
    shapes of area density `density` [kg/m^2] (one number, or one per shape), as Box2D and
    pymunk compute them. shapes: tuples (kind, *params) as ModelBuilder.add_shape takes them,
    in one frame: ``mass_properties([("circle", (0, 0), 0.1)], 1000.0)`` is a disk of
    m = 1000 pi 0.1^2 with I = m r^2 / 2."""
    shapes = [tuple(s) for s in shapes]
    rho = np.broadcast_to(np.asarray(density, dtype=np.float64), (len(shapes),))
    if not np.all(np.isfinite(rho) & (rho > 0)):
        raise ModelError(f"mass_properties: density={np.asarray(density).tolist()} must be finite "
                         "and > 0")
    parts = []
    for k, (s, d) in enumerate(zip(shapes, rho)):
        area, c, j = shape_area(s[0], s[1:], f"shape {k}")
        parts.append((float(d) * area, c, float(d) * j))
    return combine_masses(parts)


def shifted(kind, params, d) -> tuple:
    """A shape's parameters moved by -d [m] (the same shape seen from a frame whose origin is
    at d)."""
    d = np.asarray(d, dtype=np.float64)
    if kind == "polygon":
        return (tuple(tuple(np.asarray(v, dtype=np.float64) - d) for v in params[0]),)
    if kind == "capsule":
        return (tuple(np.asarray(params[0], float) - d), tuple(np.asarray(params[1], float) - d),
                *params[2:])
    return (tuple(np.asarray(params[0], float) - d),) + tuple(params[1:])     # circle, box


def bounding_circle(core, radius):
    """(cx, cy, R): a circle [m] in the shape's frame holding the whole shape (centre: the
    middle of the core's bounding box)."""
    lo = core.min(axis=0)
    hi = core.max(axis=0)
    c = 0.5 * (lo + hi)
    return float(c[0]), float(c[1]), float(np.max(np.hypot(*(core - c).T))) + radius


def shape_bounds(core, normals, radius):
    """(cx, cy, R, width, lever): the bounding circle (bounding_circle), the shape's width [m]
    (its core's smallest extent across a face, 0 for a point or a segment, plus twice its
    radius) and the largest distance [m] of a core vertex from the frame's origin (the body's:
    the lever of a turn; kernels/geometry/pair_toi.py)."""
    core = np.asarray(core, dtype=np.float64).reshape(-1, 2)
    width = 0.0
    if len(core) >= 3:
        # face k's normal against every vertex: the extent inwards from that face
        depth = np.einsum("kd,kd->k", normals, core)[:, None] - normals @ core.T
        width = float(np.min(np.max(depth, axis=1)))
    lever = float(np.max(np.hypot(core[:, 0], core[:, 1])))
    return (*bounding_circle(core, radius), width + 2.0 * radius, lever)


def mechanism_of(n_body, joints):
    """Component label (n_body,) of the graph whose edges are `joints` (pairs of body ids,
    -1 = the world, which joins nothing): bodies with one label form one mechanism."""
    sets = DisjointSets(n_body)
    for a, b in joints:
        if a >= 0 and b >= 0:
            sets.join(a, b)
    return [sets.root(i) for i in range(n_body)]


def collision_pairs(shapes, n_body, joints, enabled):
    """Pairs (i, j), i < j, of colliding shapes that may touch (see the module's docstring).
    shapes: dicts with body, category, mask; joints: (a, b) body pairs of pins and rods;
    enabled: set of frozenset({body_a, body_b}) enabled although in one mechanism."""
    label = mechanism_of(n_body, joints)
    pairs = []
    for i, si in enumerate(shapes):
        for j in range(i + 1, len(shapes)):
            sj = shapes[j]
            a, b = si["body"], sj["body"]
            if a == b:
                continue        # one body (or both static)
            if not (si["category"] & sj["mask"]) or not (sj["category"] & si["mask"]):
                continue
            if a >= 0 and b >= 0 and label[a] == label[b] and frozenset((a, b)) not in enabled:
                continue
            pairs.append((i, j))
    return pairs
