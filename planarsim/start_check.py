"""Where a run starts: no body or contact may start below the ground, no two colliding shapes
inside each other.

The step lifts a contact found below the ground onto it (the position projection), so a body
built 1 m inside a hill would jump to the surface in the first step with no word. A simulator
(planarsim.Simulator, a walker's run) refuses that start instead: a ModelError naming the
contact, its body and how deep it is, unless the caller allows it. Two shapes that may collide
(their category and mask accept each other, their bodies are not of one mechanism) and start
overlapping would likewise be pushed apart in the first step: a Simulator refuses that start
too (a ModelError naming both shapes and the depth) unless allow_overlap=True.

Depths are measured here in plain numpy from the model's terrain (not by the compiled
contact search): a point's depth along the ground's normal at its x, an arc sole's and a
straight side's deepest sample (every 0.5 degrees of arc, 200 points of a side), which is
exact to far below the tolerance. A pair of shapes' depth is exact: the separating axis test
on their cores (every edge's normal, a segment's direction too) where the cores overlap, the
distance between their closest features where they do not, less both radii (shape_gap).
"""
from __future__ import annotations

import numpy as np

from .errors import FIELD_NAMES, ModelError
from .kernels.codes import (CONTACT_ARC, CONTACT_EDGE, CONTACT_PAIR, CONTACT_POINT,
                           JOINT_SLIDE_BIT)
from .terrain import from_coef

START_TOLERANCE = 1e-3   # [m] a contact may start this far below the ground (rounding, a foot
                         #   set on hills by hand), no further
ARC_SAMPLES = 721        # points on a full circle (0.5 degree apart)
EDGE_SAMPLES = 201       # points along a straight side


def _world(q, b, local):
    """World points of body b at configuration q, local (n, 2) [m]."""
    x, y, th = q[b]
    c, s = np.cos(th), np.sin(th)
    local = np.atleast_2d(local)
    return np.stack([x + c * local[:, 0] - s * local[:, 1], y + s * local[:, 0] + c * local[:, 1]], axis=1)


def _depth(terrain, pts) -> np.ndarray:
    """Depth [m] of world points below the ground along its normal (negative: above)."""
    h = terrain.height(pts[:, 0])
    d = terrain.slope(pts[:, 0])
    return (h - pts[:, 1]) / np.sqrt(1.0 + d * d)


def _contact_local_points(model, i) -> tuple:
    """(local points (n, 2) [m], radius grown around them [m]) sampling contact i's surface."""
    a = model.arrays
    kind = int(a.contact_kind[i])
    local = np.asarray(a.contact_local[i], dtype=np.float64)
    r = float(a.contact_radius[i])
    adr, num = int(a.contact_vert_adr[i]), int(a.contact_vert_num[i])
    verts = np.asarray(a.vert_local[adr:adr + num], dtype=np.float64).reshape(num, 2)
    if kind == CONTACT_POINT:
        return local[None, :], 0.0
    if kind == CONTACT_ARC:
        a0, a1 = a.contact_span[i]
        n = max(2, int(np.ceil(ARC_SAMPLES * (a1 - a0) / (2 * np.pi))))
        ang = np.linspace(a0, a1, n)
        arc = local + r * np.stack([np.cos(ang), np.sin(ang)], axis=1)
        return np.vstack([arc, verts]), 0.0
    if kind == CONTACT_EDGE:
        u = np.linspace(0.0, 1.0, EDGE_SAMPLES)[:, None]
        return local + u * (verts[0] - local), r
    return np.zeros((0, 2)), 0.0     # a pair of shapes: not the ground's


def contact_depths(model, q, enabled=None) -> list:
    """[(contact index, depth [m], x [m])] of every enabled ground contact at configuration q
    (n_body, 3): how far its deepest point is below the ground (negative: clear by that
    much) and where."""
    out = []
    if model.terrain is None:
        return out          # no ground (ModelBuilder(ground=None)): nothing to be below
    q = np.asarray(q, dtype=np.float64)
    ground = from_coef(model.arrays.terrain_coef, "ground")
    for i in range(model.n_contact):
        if enabled is not None and not enabled[i]:
            continue
        local, grow = _contact_local_points(model, i)
        if not len(local):
            continue
        pts = _world(q, int(model.arrays.contact_body[i]), local)
        depth = _depth(ground, pts) + grow
        k = int(np.argmax(depth))
        out.append((i, float(depth[k]), float(pts[k, 0])))
    return out


def below_ground(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator"):
    """(how many contacts start more than `tolerance` [m] below the ground at `state`, a
    sentence naming the deepest: its body, depth and x; '' when none)."""
    deep = [c for c in contact_depths(model, state.q, state.contact_enabled) if c[1] > tolerance]
    if not deep:
        return 0, ""
    i, depth, x = max(deep, key=lambda c: c[1])
    b = int(model.arrays.contact_body[i])
    more = len(deep) - 1
    others = f" (and {more} more contact{'s' if more > 1 else ''})" if more else ""
    return len(deep), (f"{who}: contact {model.contact_names[i]!r} ({i}) of body "
                       f"{model.body_names[b]!r} ({b}) starts {depth:.4g} m below the ground at "
                       f"x={x:.4g} m{others}, more than {tolerance:g} m")


def check_start(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator") -> None:
    """ModelError naming the deepest contact that starts more than `tolerance` [m] below the
    ground at `state` (its body, depth and x), else nothing."""
    count, said = below_ground(model, state, tolerance, who)
    if count:
        raise ModelError(f"{said}; the first step would move it to the surface. Build the body "
                         f"higher (its pos), or pass allow_below_ground=True to start it there")


# shapes inside each other -------------------------------------------------------------------
def _segments(core) -> tuple:
    """(starts, ends) (m, 2) of a core's sides: a circle's one point (a segment of length 0),
    a capsule's segment, a polygon's edges."""
    if len(core) <= 2:
        return core[:1], core[-1:]
    return core, np.roll(core, -1, axis=0)


def _point_segment_distance(p, a, b) -> np.ndarray:
    """Distances [m] from points p (n, 2) to every segment a -> b (m, 2): (n, m)."""
    ab = b - a
    ap = p[:, None, :] - a[None, :, :]
    len2 = np.sum(ab * ab, axis=1)
    u = np.clip(np.sum(ap * ab[None], axis=2) / np.where(len2 > 0, len2, 1.0), 0.0, 1.0)
    d = ap - u[:, :, None] * ab[None]
    return np.hypot(d[..., 0], d[..., 1])


def _axes(core_a, core_b) -> np.ndarray:
    """Unit directions (k, 2) on which two convex cores, if apart, show a gap: every side's
    normal, a segment's direction, and two points' joining line."""
    out = []
    for core in (core_a, core_b):
        starts, ends = _segments(core)
        e = ends - starts
        out += [np.stack([e[:, 1], -e[:, 0]], axis=1)]
        if len(core) == 2:
            out.append(e)
    if len(core_a) == 1 and len(core_b) == 1:
        out.append(core_b - core_a)
    axes = np.concatenate(out)
    n = np.hypot(axes[:, 0], axes[:, 1])
    return axes[n > 0] / n[n > 0, None]


def shape_gap(core_a, radius_a, core_b, radius_b) -> float:
    """Signed distance [m] between two rounded convex shapes given by their cores (n, 2) in
    world coordinates and radii [m]: the gap between them, negative by the depth by which they
    overlap (the shortest translation that separates them)."""
    core_a = np.asarray(core_a, dtype=np.float64).reshape(-1, 2)
    core_b = np.asarray(core_b, dtype=np.float64).reshape(-1, 2)
    axes = _axes(core_a, core_b)
    sep = 0.0               # two coincident points: cores touching
    if len(axes):
        pa, pb = core_a @ axes.T, core_b @ axes.T
        sep = float(np.max(np.maximum(pb.min(axis=0) - pa.max(axis=0),
                                      pa.min(axis=0) - pb.max(axis=0))))
    if sep > 0.0:           # cores apart: the distance of their closest features
        sa, sb = _segments(core_a), _segments(core_b)
        sep = float(min(_point_segment_distance(core_a, *sb).min(),
                        _point_segment_distance(core_b, *sa).min()))
    return sep - radius_a - radius_b


def _shape_world(model, q, i) -> np.ndarray:
    """Core vertices (n, 2) [m] of colliding shape i in the world at configuration q."""
    a = model.arrays
    adr, num, b = int(a.shape_vert_adr[i]), int(a.shape_vert_num[i]), int(a.shape_body[i])
    core = np.asarray(a.core_vert[adr:adr + num], dtype=np.float64)
    return core if b < 0 else _world(q, b, core)


def shape_overlaps(model, q, enabled=None) -> list:
    """[(depth [m], shape i, shape j)] of every pair of shapes that may collide (an enabled pair
    contact of the model) and overlap at configuration q (n_body, 3); depth > 0."""
    a = model.arrays
    q = np.asarray(q, dtype=np.float64)
    pairs = {}
    for c in np.flatnonzero(np.asarray(a.contact_kind) == CONTACT_PAIR):
        if enabled is None or enabled[c]:
            pairs[(int(a.contact_pair[c, 0]), int(a.contact_pair[c, 1]))] = True
    if not pairs:
        return []
    ij = np.array(list(pairs), dtype=np.int64).reshape(-1, 2)
    # bounding circles first: only the pairs whose circles overlap are measured
    bound = np.asarray(a.shape_bound, dtype=np.float64)
    body = np.asarray(a.shape_body)
    pose = np.where(body[:, None] >= 0, q[np.maximum(body, 0)], 0.0)   # static: the world's
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    centre = pose[:, :2] + np.stack([c * bound[:, 0] - s * bound[:, 1],
                                     s * bound[:, 0] + c * bound[:, 1]], axis=1)
    dist = np.hypot(*(centre[ij[:, 0]] - centre[ij[:, 1]]).T)
    out = []
    for i, j in ij[dist < bound[ij[:, 0], 2] + bound[ij[:, 1], 2]]:
        gap = shape_gap(_shape_world(model, q, i), float(a.shape_radius[i]),
                        _shape_world(model, q, j), float(a.shape_radius[j]))
        if gap < 0.0:
            out.append((-gap, int(i), int(j)))
    return out


def _shape_who(model, i) -> str:
    """How messages name colliding shape i (its body, and its name= where it has one)."""
    names = getattr(model, "shape_names", ())
    if i < len(names):
        return names[i]
    b = int(model.arrays.shape_body[i])
    return f"shape ({i}) of " + ("the world (static)" if b < 0 else f"body {model.body_names[b]!r}")


def overlapping(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator"):
    """(how many pairs of shapes that may collide overlap by more than `tolerance` [m] at
    `state`, a sentence naming the deepest pair and its depth; '' when none)."""
    deep = [o for o in shape_overlaps(model, state.q, state.contact_enabled) if o[0] > tolerance]
    if not deep:
        return 0, ""
    depth, i, j = max(deep)
    more = len(deep) - 1
    others = f" (and {more} more pair{'s' if more > 1 else ''})" if more else ""
    return len(deep), (f"{who}: {_shape_who(model, i)} and {_shape_who(model, j)} start "
                       f"overlapping by {depth:.4g} m{others}, more than {tolerance:g} m")


def check_overlap(model, state, tolerance: float = START_TOLERANCE, who: str = "simulator") -> None:
    """ModelError naming the deepest pair of colliding shapes that start overlapping by more
    than `tolerance` [m] at `state` (both shapes, their bodies, the depth), else nothing."""
    count, said = overlapping(model, state, tolerance, who)
    if count:
        raise ModelError(f"{said}; the first step would push them apart. Build them apart, or "
                         f"pass allow_overlap=True to start them there")


def joint_coordinate(model, q, j) -> float:
    """Joint j's coordinate at configuration q: a hinge's angle theta_b - theta_a - ref [rad],
    a slider's slide along its axis d . (p_b - p_a) [m] (kernels/constraints/slider.py)."""
    a = model.arrays
    ba, bb = int(a.pin_body[j, 0]), int(a.pin_body[j, 1])
    if not int(a.pin_kind[j]) & JOINT_SLIDE_BIT:
        return float(q[bb, 2] - a.pin_ref[j] - (q[ba, 2] if ba >= 0 else 0.0))
    axis = np.asarray(a.pin_axis[j], dtype=np.float64)
    if ba >= 0:
        c, s = np.cos(q[ba, 2]), np.sin(q[ba, 2])
        axis = np.array([c * axis[0] - s * axis[1], s * axis[0] + c * axis[1]])
    pa = _world(q, ba, a.pin_anchor[j, 0])[0] if ba >= 0 else np.asarray(a.pin_anchor[j, 0], float)
    pb = _world(q, bb, a.pin_anchor[j, 1])[0]
    return float(axis @ (pb - pa))


def outside_limits(model, state, who: str = "simulator"):
    """(how many joints lie outside their limits at `state`, a sentence naming the farthest,
    where it is and its limit; '' when none). The first step moves such a joint onto its
    limit (the position projection: a move, no velocity); MuJoCo's files may build a joint
    there (dm_control's hopper builds its knee at 0, outside (-150, -5) degrees)."""
    a = model.arrays
    out = []
    for j in range(len(model.pin_names)):
        lo, hi = float(a.pin_limit[j, 0]), float(a.pin_limit[j, 1])
        if lo == -np.inf and hi == np.inf:
            continue
        x = joint_coordinate(model, state.q, j)
        over = max(lo - x, x - hi)
        if over > 1e-9:
            out.append((over, j, x, lo, hi))
    if not out:
        return 0, ""
    over, j, x, lo, hi = max(out)
    unit = "m" if int(a.pin_kind[j]) & JOINT_SLIDE_BIT else "rad"
    more = len(out) - 1
    others = f" (and {more} more joint{'s' if more > 1 else ''})" if more else ""
    return len(out), (f"{who}: joint {model.pin_names[j]!r} ({j}) starts at {x:.6g} {unit}, "
                      f"{over:.4g} {unit} outside its limit ({lo:g}, {hi:g}){others}")


# the units of a body's coordinates and velocities, in errors.FIELD_NAMES' order
_FIELD_UNITS = ("m", "m", "rad", "m/s", "m/s", "rad/s")


def check_guard_limit(model, state, guard_limit: float) -> None:
    """Raise ModelError naming the body and field if a state's position or velocity is beyond
    StepOptions.guard_limit (the step stops any state beyond it: a Simulator built on such a
    state would report a divergence at its first step)."""
    values = np.concatenate([np.asarray(state.q, float), np.asarray(state.v, float)], axis=1)
    beyond = np.argwhere(np.abs(values) > guard_limit)
    if beyond.size:
        b, f = (int(k) for k in beyond[0])
        field, unit = FIELD_NAMES[f], _FIELD_UNITS[f]
        remedy = "move the scene nearer the origin" if f < 3 else "start it slower"
        raise ModelError(f"body {model.body_names[b]!r} has {field} = {values[b, f]:g} "
                         f"{unit}, beyond StepOptions.guard_limit {guard_limit:g} (the "
                         f"step stops any state beyond it: {remedy}, or raise guard_limit)")
