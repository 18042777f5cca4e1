"""ModelBuilder: describe bodies, pins, sliders, a free body's coordinates, rods, feet,
actuators and fluid drag, then ``compile()`` a Model.

Every ``add_*`` returns a small integer id. All checking happens here; errors are
``ModelError`` naming the element kind, its name and index, the field, the value and the rule.

>>> from planarsim import ModelBuilder
>>> b = ModelBuilder(dt=1e-3)
>>> rod = b.add_body("rod", mass=1.0, inertia=1.0 / 12, pos=(0.5, 0.0))
>>> pivot = b.add_pin("pivot", rod, None, anchor_world=(0.0, 0.0))
>>> model = b.compile()
>>> model.n_body, model.n_pin
(1, 1)
"""
from __future__ import annotations

import math

import numpy as np

from . import model as M
from .kernels.codes import (CONTACT_ARC, CONTACT_EDGE, CONTACT_PAIR, CONTACT_POINT,
                            JOINT_FREE_HINGE, JOINT_FREE_SLIDE, JOINT_HINGE, JOINT_SLIDE_BIT,
                            JOINT_SLIDER)
from .checks import flag, holds_bool, is_bool, number
from .errors import ModelError, plain as _plain
from .kernels.geometry.collide import core_normals
from .kernels.solver.modes import SOLVE_REL_TOL
from .shapes import (collision_core, collision_pairs, combine_masses, shape_area, shape_bounds,
                     shape_who, shifted)
from .terrain import Terrain, flat

PIN_ANCHOR_TOL = 1e-6  # [m] largest allowed gap between a pin's two anchors at build time



def _shown(values) -> tuple:
    """A vector as a message prints it: plain floats, (0.5, 0.0) (not np.float64(0.5))."""
    return tuple(float(x) for x in np.ravel(values))

def _who(kind, name, idx):
    """How errors name an element: "pin 'knee' (2)", or "fluid box (3)" for unnamed ones; idx
    None: `kind` is the whole description already (a shape's: shapes.shape_who)."""
    if idx is None:
        return kind
    return f"{kind} ({idx})" if name is None else f"{kind} {name!r} ({idx})"


def _finite(kind, name, idx, fieldname, value):
    if holds_bool(value):
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={_plain(value)!r} must be numbers, "
                         "not True or False")
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={_plain(value)} must be finite")
    return arr


def _vec2(kind, name, idx, fieldname, value):
    if holds_bool(value):
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={_plain(value)!r} must be a pair "
                         "(x, y) of numbers, not True or False")
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(2)
    except (TypeError, ValueError):
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={_plain(value)!r} must be a pair "
                         "(x, y)") from None
    return _finite(kind, name, idx, fieldname, arr)


def _scalar(kind, name, idx, fieldname, value):
    """A finite number (not a bool: mass=True built a 1 kg body), or a ModelError naming it."""
    return number(f"{_who(kind, name, idx)}: {fieldname}", value, error=ModelError)


def _length(kind, name, idx, fieldname, value, zero_ok=False):
    """A size [m]: finite and > 0 (>= 0 if zero_ok)."""
    x = _scalar(kind, name, idx, fieldname, value)
    if x < 0 or (x == 0 and not zero_ok):
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={x} must be {'>= 0' if zero_ok else '> 0'}")
    return x


def _pair(kind, name, idx, fieldname, value, parts=("min", "max")):
    """A (lo, hi) pair as two floats: two numbers, neither NaN, lo < inf and hi > -inf (either
    may be infinite the other way: no bound). The order of lo and hi is the caller's rule."""
    try:
        arr = None if holds_bool(value) else np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    who = _who(kind, name, idx)
    if arr is None or arr.shape != (2,):
        raise ModelError(f"{who}: {fieldname}={_plain(value)!r} must be a pair ({', '.join(parts)}) "
                         "of numbers")
    lo, hi = float(arr[0]), float(arr[1])
    if math.isnan(lo) or math.isnan(hi):
        raise ModelError(f"{who}: {fieldname}=({lo}, {hi}) must not be NaN")
    if lo == math.inf or hi == -math.inf:
        raise ModelError(f"{who}: {fieldname}=({lo}, {hi}) must have {parts[0]} < inf and "
                         f"{parts[1]} > -inf")
    return lo, hi


SHAPE_PARAMS = {"capsule": ("p0", "p1", "radius"), "circle": ("center", "radius"),
                "box": ("center", "width", "height", "angle"),  # box: angle optional
                "polygon": ("vertices",)}


def _check_shape(kind, who, params):
    """Parameters of a drawing shape: points (x, y) [m], radius [m] >= 0, box width and
    height [m] > 0, angle [rad]; all finite. Errors name `who` (shapes.shape_who)."""
    fields = SHAPE_PARAMS[kind]
    if not (len(fields) - (kind == "box") <= len(params) <= len(fields)):
        raise ModelError(f"{who}: params={_plain(params)!r} must be ({', '.join(fields)})")
    for f, p in zip(fields, params):
        if f == "vertices":
            try:
                n = len(p)
            except TypeError:
                raise ModelError(f"{who}: vertices={_plain(p)!r} must be a list of (x, y) "
                                 "pairs") from None
            for k in range(n):
                _vec2(who, None, None, f"vertices[{k}]", p[k])
        elif f in ("p0", "p1", "center"):
            _vec2(who, None, None, f, p)
        elif f == "angle":
            _scalar(who, None, None, f, p)
        else:
            _length(who, None, None, f, p, zero_ok=f == "radius")


# the narrowest friction cone the contact solve resolves: it checks Coulomb's rule |lambda_t| <=
# mu lambda_n to SOLVE_REL_TOL of the impulses, so a contact whose mu is below this is
# compiled frictionless (no tangential row; its friction, at most mu lambda_n, is below the
# solve's rounding). Compiled as given, such a cone was not told from a sticking contact: a
# box with mu = 1e-15 was held sticking and dragged 12 cm along the ground by its position
# correction
MU_RESOLUTION = SOLVE_REL_TOL


def resolved_friction(mu):
    """The friction coefficient a contact of coefficient mu is compiled with: mu, or 0 below
    MU_RESOLUTION."""
    return mu if mu >= MU_RESOLUTION else 0.0



# [-] a straight side over hills is held in pieces of at most this share of the ground's
# shortest wavelength: a piece then spans one crest at most (of one sine: crests lie a
# wavelength apart), and each piece's contact holds its crest's point in the velocity solve
EDGE_PIECE_OF_WAVELENGTH = 0.5
# [-] each piece searches this share of its length beyond a cut (not beyond the side's ends)
EDGE_PIECE_REACH = 0.25


def edge_pieces(start, end, ground) -> list:
    """A straight side from `start` to `end` (body frame [m]) as the edge contacts that hold
    it over `ground`: [(search start, search end, own share)]. One piece (own (0, 0): the whole
    segment, its ends the shape's corners, whose own contacts hold them) where the side is
    at most EDGE_PIECE_OF_WAVELENGTH of the shortest wavelength long; else equal pieces, each
    searching EDGE_PIECE_REACH of its length beyond its cuts and reporting its deepest point
    only where that lies in its own part [lo, hi) of the search: its share of the side and
    half its reach past each cut (a crest near a cut is held by both pieces). With one
    contact for the whole side, a plank resting on three crests had one of them in the
    velocity solve: it fell about it while the position correction held it up, gaining 3 J
    in 0.25 s with no audit."""
    coef = ground.coef
    n_sines = int(coef[2])
    length = float(np.hypot(*(end - start)))
    if n_sines == 0 or length == 0.0:
        return [(start, end, (0.0, 0.0))]
    shortest = min(float(coef[4 + 3 * j]) for j in range(n_sines))
    n = int(math.ceil(length / (EDGE_PIECE_OF_WAVELENGTH * shortest)))
    if n <= 1:
        return [(start, end, (0.0, 0.0))]
    out = []
    for j in range(n):
        lo = j / n - (EDGE_PIECE_REACH / n if j > 0 else 0.0)
        hi = (j + 1) / n + (EDGE_PIECE_REACH / n if j + 1 < n else 0.0)
        span = hi - lo
        # its own part, and half its reach past each cut: a crest near a cut is held by
        # both pieces over that band, so it passes from one to the next with a step or more
        # of both holding it (each piece finds a flat minimum to about 1e-9 m of its own:
        # owned parts that met at the cut let a crest within that of it flick between the
        # two, or neither, each hand-over a new contact starting free)
        share = 0.5 * EDGE_PIECE_REACH / n
        own = ((max(j / n - share, 0.0) - lo) / span, (min((j + 1) / n + share, 1.0) - lo) / span)
        out.append((start + lo * (end - start), start + hi * (end - start), own))
    return out

# [m] a world shape's edge is covered by the other world shapes whose cores, grown by this,
# hold its pieces end to end (each with the outside of its piece's midpoint in it)
COVER_TOL = 1e-9


TWO_PI = 2.0 * math.pi
# [rad] sectors this close are one; a free arc this close to a half turn is a flat run
COVER_ANGLE_TOL = 1e-9


def _angle(d):
    """The direction of vector d [rad] in [0, 2 pi)."""
    return math.atan2(d[1], d[0]) % TWO_PI


def _sector_at(core, normals, v, tol):
    """The sector (start, length) [rad] a convex core fills around point v, counter-clockwise
    from start: its interior angle at a vertex, a half turn on a face's interior, a whole
    turn inside it (length 2 pi); None off it."""
    num = len(core)
    depth = max(float(normals[k] @ (v - core[k])) for k in range(num))
    if depth > tol:
        return None
    for k in range(num):
        if math.hypot(*(core[k] - v)) <= tol:
            start = _angle(core[(k + 1) % num] - v)
            return start, (_angle(core[k - 1] - v) - start) % TWO_PI
    if depth < -tol:
        return 0.0, TWO_PI
    for k in range(num):
        if abs(float(normals[k] @ (v - core[k]))) <= tol:
            return _angle(core[(k + 1) % num] - core[k]), math.pi
    return None


def _free_arcs(sectors):
    """The arcs (start, length) [rad] around a point that no sector fills."""
    if any(length >= TWO_PI - COVER_ANGLE_TOL for _, length in sectors):
        return []
    # cut the circle at the first sector's start (which that sector fills: no free arc
    # runs through the cut)
    base = sectors[0][0]
    spans = []
    for a, length in sectors:
        lo = (a - base) % TWO_PI
        spans.append((lo, lo + length))
        if lo + length > TWO_PI:
            # a sector across the cut (one starting a hair before the first) fills the start
            # of the circle too
            spans.append((0.0, lo + length - TWO_PI))
    spans.sort()
    free = []
    reach = 0.0
    for lo, hi in spans:
        if lo > reach + COVER_ANGLE_TOL:
            free.append((reach, lo - reach))
        reach = max(reach, hi)
    if reach < TWO_PI - COVER_ANGLE_TOL:
        free.append((reach, TWO_PI - reach))
    return [((a + base) % TWO_PI, length) for a, length in free]


def _vertex_cone(v, n_open, shapes_here, tol, more=()):
    """(p, q, concave) at a vertex of the floor that several world shapes (shapes_here:
    (core, normals)) fill around v: the outward normal cone of their union there, from p to
    q counter-clockwise. A convex corner (the free arc wider than a half turn): the normals
    of the two faces bounding it; a flat run: p = q, the surface's normal; a concave corner
    (a flat run meeting a ramp up): p = q = n_open, concave 1 (a body meets it along the
    faces); inside the floor (no free arc): p = q = 0. Of several free arcs (shapes touching
    at a corner only), the one bounded by the face whose normal is n_open. `more`: further
    sectors (start, length) [rad] filled there (the analytic ground's: _ground_sector)."""
    sectors = [sec for core, normals in shapes_here
               for sec in [_sector_at(core, normals, v, tol)] if sec is not None] + list(more)
    free = _free_arcs(sectors) if sectors else []
    if not free:
        return np.zeros(2), np.zeros(2), 0.0
    arc = free[0]
    for a, length in free:
        ua = np.array([math.cos(a), math.sin(a)])
        ub = np.array([math.cos(a + length), math.sin(a + length)])
        if max(float(n_open @ np.array([-ua[1], ua[0]])),
               float(n_open @ np.array([ub[1], -ub[0]]))) > 1.0 - 1e-9:
            arc = (a, length)
    a, length = arc
    ua = np.array([math.cos(a), math.sin(a)])
    ub = np.array([math.cos(a + length), math.sin(a + length)])
    p = np.array([-ua[1], ua[0]])           # the face along ua: material clockwise of it
    q = np.array([ub[1], -ub[0]])           # the face along ub: material counter-clockwise
    if length < math.pi - COVER_ANGLE_TOL:
        return n_open, n_open, 1.0
    if length <= math.pi + COVER_ANGLE_TOL:
        return p, p, 0.0
    return p, q, 0.0


# samples per shortest wavelength of hills when the ground's hold on a side is found by samples
COVER_GROUND_SAMPLES = 64


def _ground_piece(ground, a, b, outward, tol):
    """The parts of the edge a -> b [m] (outward unit normal `outward`) that the analytic
    ground holds, as (head, tail): the shares of its length from its start and to its end
    that lie within tol [m] of the ground or below it, with the ground on the edge's outside
    there. Exact for flat ground and slopes (a half-plane); by samples over hills."""
    coef = ground.coef
    d = b - a
    length = math.hypot(*d)
    if int(coef[2]) == 0:
        # below the line y = h0 + s x: n . p <= n . (0, h0), n = (-s, 1) / |.|
        norm = math.hypot(coef[1], 1.0)
        planes = [(-coef[1] / norm, 1.0 / norm, coef[0] / norm)]
        t0, t1 = _piece_inside(float(a[0]), float(a[1]), float(d[0]), float(d[1]), planes, tol)
        if t1 <= t0:
            return 0.0, 0.0
        mid = a + 0.5 * (t0 + t1) * d + 1e-6 * (t1 - t0) * length * outward
        if float(ground.height(mid[0])) - float(mid[1]) <= 0.0:
            return 0.0, 0.0         # the ground is not on its outside
        slack = tol / length
        return (t1 if t0 <= slack else 0.0), (1.0 - t0 if t1 >= 1.0 - slack else 0.0)
    shortest = min(float(coef[4 + 3 * k]) for k in range(int(coef[2])))
    n = int(min(4096, max(COVER_GROUND_SAMPLES,
                          math.ceil(COVER_GROUND_SAMPLES * length / shortest))))
    t = np.linspace(0.0, 1.0, n + 1)
    points = a[None, :] + t[:, None] * d[None, :]
    held = points[:, 1] <= ground.height(points[:, 0]) + tol
    mids = 0.5 * (points[1:] + points[:-1]) + 1e-6 * length / n * outward
    inside = mids[:, 1] < ground.height(mids[:, 0])
    good = held[:-1] & held[1:] & inside        # each sample interval held with its outside
    head = 0
    while head < n and good[head]:
        head += 1
    tail = 0
    while tail < n and good[n - 1 - tail]:
        tail += 1
    return head / n, tail / n


def _ground_sector(ground, v, tol):
    """The sector (start, length) [rad] the analytic ground fills around point v [m]: a half
    turn below its tangent where v lies on it (within tol), a whole turn below it, None
    above it."""
    depth = float(ground.height(v[0])) - float(v[1])
    if depth < -tol:
        return None
    if depth > tol:
        return 0.0, TWO_PI
    slope = float(ground.slope(v[0]))
    # walking the surface towards -x, the ground lies on the left
    return _angle(np.array([-1.0, -slope])), math.pi


def covered_edges(shapes, ground=None) -> np.ndarray:
    """(n_core, 8) over the shapes' core vertices: column 0 is 1 where the edge from that
    vertex is a world shape's face covered whole by other world shapes (never a reference
    face: kernels/geometry/collide.py); columns 6 and 7 the shares of its length covered from
    its start and to its end (a thick tile beside a thin one: the top of its side; 1 and 1
    where whole), where it is no reference face for a point over that part. At a vertex
    that ends a covered part, the outward normal cone of the floor there
    (collide._normal_admitted), from columns 4-5 counter-clockwise to columns 1-2 ((0, 0):
    none, the vertex is inside the floor), column 3 is 1 where the vertex is a concave corner
    of the floor (a flat run meeting a ramp up). The cone is made of every world shape of the
    same category and mask that fills some of the turn around the vertex (a strip of
    triangles meets in threes). A floor of static boxes laid edge to edge has its tiles'
    upright faces at the seams inside the floor; a body sliding over a seam must not meet
    them, and at a crest the cone spans both faces' normals. Polygons of radius 0 only; an
    edge's part counts as covered where other shapes that collide with what it does (the
    same category and mask) hold it between them: each the piece of it that lies within
    COVER_TOL of its core, with the point just outside that piece's midpoint inside it
    (_covered_spans)."""
    cores = [np.asarray(sh["core"], dtype=np.float64).reshape(-1, 2) for sh in shapes]
    out = [np.zeros((len(c), 8)) for c in cores]
    world = [i for i, sh in enumerate(shapes)
             if sh["body"] < 0 and len(cores[i]) >= 3 and sh["radius"] == 0.0]
    if len(world) < (1 if ground is not None else 2):
        return np.concatenate(out) if out else np.zeros((0, 8))
    normals = {i: core_normals(cores[i]) for i in world}
    grid = _Grid(cores, world)
    for i, k, head, tail in _covered_spans(shapes, cores, normals, world, grid, ground):
        out[i][k, 0] = 1.0 if head == 1.0 else 0.0
        out[i][k, 6] = head
        out[i][k, 7] = tail
    for i in world:
        ci, ni, num = cores[i], normals[i], len(cores[i])
        tol = COVER_TOL + 1e-12 * (1.0 + float(np.abs(ci).max()))
        for v_index in range(num):
            before = (v_index - 1) % num
            # the edge from the vertex covered at its start, the edge into it at its end
            from_v = out[i][v_index, 6] > 0.0
            into_v = out[i][before, 7] > 0.0
            if not from_v and not into_v:
                continue
            if from_v and into_v:
                continue                   # both faces covered there: inside the floor
            open_face = before if from_v else v_index
            v = ci[v_index]
            here = [(cores[j], normals[j]) for j in grid.near(v, tol)
                    if _same_filter(shapes[i], shapes[j])]
            sector = _ground_sector(ground, v, tol) if ground is not None else None
            p, q, concave = _vertex_cone(v, ni[open_face], here, tol,
                                         [] if sector is None else [sector])
            out[i][v_index, 1:3] = q
            out[i][v_index, 3] = concave
            out[i][v_index, 4:6] = p
    return np.concatenate(out)


def _same_filter(a, b):
    """Two shapes collide with the same shapes (category and mask)."""
    return (a["category"], a["mask"]) == (b["category"], b["mask"])


class _Grid:
    """World shapes binned on a grid of their median size (covered_edges): near(point) lists
    the shapes whose bounding box may hold the point."""

    def __init__(self, cores, world):
        lo = {i: cores[i].min(axis=0) for i in world}
        hi = {i: cores[i].max(axis=0) for i in world}
        self.box = {i: (float(lo[i][0]), float(lo[i][1]), float(hi[i][0]), float(hi[i][1]))
                    for i in world}
        cell = float(np.median([max(hi[i][0] - lo[i][0], hi[i][1] - lo[i][1]) for i in world]))
        self.cell = max(cell, 1e-6)
        self.bins = {}
        self.wide = []                     # shapes spanning too many cells: tried everywhere
        for i in world:
            x0, y0 = np.floor(lo[i] / self.cell).astype(np.int64)
            x1, y1 = np.floor(hi[i] / self.cell).astype(np.int64)
            if (x1 - x0 + 1) * (y1 - y0 + 1) > 64:
                self.wide.append(i)
                continue
            for gx in range(x0, x1 + 1):
                for gy in range(y0, y1 + 1):
                    self.bins.setdefault((gx, gy), []).append(i)

    def near_box(self, lo, hi, tol):
        """The shapes whose bounding box may meet the box lo..hi [m] (grown by tol)."""
        x0, y0 = math.floor((lo[0] - tol) / self.cell), math.floor((lo[1] - tol) / self.cell)
        x1, y1 = math.floor((hi[0] + tol) / self.cell), math.floor((hi[1] + tol) / self.cell)
        if (x1 - x0 + 1) * (y1 - y0 + 1) > 4096:
            found = set(self.box)           # a box over many cells: every shape
        else:
            found = set(self.wide)
            for gx in range(x0, x1 + 1):
                for gy in range(y0, y1 + 1):
                    found.update(self.bins.get((gx, gy), ()))
        box = self.box
        return [j for j in sorted(found)
                if box[j][0] - tol <= hi[0] and box[j][1] - tol <= hi[1]
                and lo[0] <= box[j][2] + tol and lo[1] <= box[j][3] + tol]

    def near(self, point, tol):
        return self.near_box(point, point, tol)


def _piece_inside(ax, ay, dx, dy, planes, tol):
    """(t0, t1): the part (ax, ay) + t (dx, dy), t in [0, 1], of a segment [m] that lies within
    tol [m] of a convex core given by its faces' planes (nx, ny, n . vertex) (t0 >= t1:
    none). Plain floats: a core has a handful of faces."""
    t0, t1 = 0.0, 1.0
    for nx, ny, off in planes:
        # the face's half-plane n . (a + t d) - off <= tol
        h = nx * ax + ny * ay - off - tol
        slope = nx * dx + ny * dy
        if slope == 0.0:
            if h > 0.0:
                return 1.0, 0.0
        elif slope > 0.0:
            t1 = min(t1, -h / slope)
        else:
            t0 = max(t0, -h / slope)
        if t0 >= t1:
            return t0, t1
    return t0, t1


def _covered_spans(shapes, cores, normals, world, grid, ground=None):
    """(i, k, head, tail): edge k of world shape i held by other world shapes (covered_edges'
    rule), from its start to the share `head` of its length and from 1 - `tail` to its end
    (head = tail = 1: held whole; pieces held in its middle only are not counted). The pieces
    of it that lie in other shapes of the same filter, each with that shape on the edge's
    outside (the point just outside the piece's midpoint inside it), are merged: a tall tile
    beside a column of two stacked ones has its side held by the two together, beside a
    thinner tile its side's top part."""
    planes = {i: [(float(n[0]), float(n[1]), float(n @ c)) for n, c in zip(normals[i], cores[i])]
              for i in world}
    for i in world:
        ci, ni = cores[i], normals[i]
        tol = COVER_TOL + 1e-12 * (1.0 + float(np.abs(ci).max()))
        for k in range(len(ci)):
            a, b = ci[k], ci[(k + 1) % len(ci)]
            ax, ay = float(a[0]), float(a[1])
            dx, dy = float(b[0] - a[0]), float(b[1] - a[1])
            length = math.hypot(dx, dy)
            if length == 0.0:
                continue
            ox, oy = 1e-6 * length * float(ni[k][0]), 1e-6 * length * float(ni[k][1])
            pieces = []
            for j in grid.near_box(np.minimum(a, b), np.maximum(a, b), tol):
                if j == i or not _same_filter(shapes[i], shapes[j]):
                    continue
                t0, t1 = _piece_inside(ax, ay, dx, dy, planes[j], tol)
                if t1 <= t0:
                    continue
                mid = 0.5 * (t0 + t1)
                px = ax + mid * dx + (t1 - t0) * ox
                py = ay + mid * dy + (t1 - t0) * oy
                if max(nx * px + ny * py - off for nx, ny, off in planes[j]) < 0.0:
                    pieces.append((t0, t1))
            if ground is not None:
                head, tail = _ground_piece(ground, a, b, ni[k], tol)
                if head > 0.0:
                    pieces.append((0.0, head))
                if tail > 0.0:
                    pieces.append((1.0 - tail, 1.0))
            slack = tol / length
            merged = []                     # the union of the pieces, as disjoint spans
            for t0, t1 in sorted(pieces):
                if merged and t0 <= merged[-1][1] + slack:
                    merged[-1][1] = max(merged[-1][1], t1)
                else:
                    merged.append([t0, t1])
            if not merged:
                continue
            head = merged[0][1] if merged[0][0] <= slack else 0.0
            tail = 1.0 - merged[-1][0] if merged[-1][1] >= 1.0 - slack else 0.0
            if head >= 1.0 - slack:
                head = tail = 1.0
            if head > 0.0 or tail > 0.0:
                yield i, k, min(head, 1.0), min(tail, 1.0)


class ModelBuilder:
    """Mutable description of a planar model; see the module docstring.

    Parameters
    ----------
    dt : float        step size [s], > 0
    gravity : (2,)    gravity vector [m/s^2]
    terrain : Terrain ground profile (default: flat ground at y = 0)
    ground : True (default): the world has that analytic ground; None: it has none (no
        terrain): shapes touch only other shapes (static ones make the floor, an incline, a
        bowl), and the contacts that touch only the ground (add_point_contact,
        add_arc_contact, add_box_contacts) are a ModelError
    """

    def __init__(self, dt: float = 1e-3, gravity=(0.0, -9.81), terrain: Terrain | None = None,
                 ground=True):
        if ground is not True and ground is not None:
            raise ModelError(f"model: ground={ground!r} must be True (the analytic ground) or None "
                             "(no ground)")
        if ground is None and terrain is not None:
            raise ModelError(f"model: terrain={getattr(terrain, 'name', terrain)!r} given with "
                             "ground=None; a world without ground has no terrain")
        self.dt = dt
        self.gravity = gravity
        self.ground = ground is True
        self.terrain = (terrain if terrain is not None else flat()) if self.ground else None
        self._bodies, self._pins, self._rods, self._contacts, self._acts = [], [], [], [], []
        self._shapes = []
        self._fluid = []            # (body, fluid_coef row): kernels/dynamics/fluid.py
        self._collide = []          # colliding shapes: dicts (shape, body, core, radius, ...)
        self._enabled_pairs = set()
        self._names = {"body": {}, "pin": {}, "rod": {}, "contact": {}, "actuator": {}}

    # naming ---------------------------------------------------------------------------------
    def _register(self, kind, name, idx):
        if not isinstance(name, str) or not name:
            raise ModelError(f"{kind} ({idx}): name={name!r} must be a non-empty string")
        if name in self._names[kind]:
            raise ModelError(f"{kind} {name!r} ({idx}): duplicate name (already used by {kind} "
                             f"{self._names[kind][name]})")
        self._names[kind][name] = idx

    def _body_id(self, kind, name, idx, fieldname, body, allow_world=False):
        if body is None and allow_world:
            return -1
        if isinstance(body, str):
            if body not in self._names["body"]:
                raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={body!r} names no body")
            return self._names["body"][body]
        # (True is no body id, though Python takes it for 1: the second body)
        an_id = isinstance(body, (int, np.integer)) and not is_bool(body)
        if an_id and 0 <= body < len(self._bodies):
            return int(body)
        if an_id and body == -1 and allow_world:
            return -1
        raise ModelError(f"{_who(kind, name, idx)}: {fieldname}={body!r} is not a body id "
                         f"(0..{len(self._bodies) - 1}){' or None for the world' if allow_world else ''}")

    # bodies ---------------------------------------------------------------------------------
    def add_body(self, name, mass=None, inertia=None, pos=(0.0, 0.0), angle=0.0, vel=(0.0, 0.0),
                 omega=0.0, shapes=(), density=None) -> int:
        """Rigid body: mass [kg] > 0 and inertia about its centre of mass (COM) [kg m^2] > 0,
        pos [m] and angle [rad] the pose of its COM; vel [m/s] and omega [rad/s] its start
        velocity (the State's v at time 0: the velocity over the step before it, see "How the
        engine works" in the documentation, docs/engine.md). shapes: tuples (kind, *params) as add_shape takes them, each
        optionally ending with a dict of add_shape's keywords, e.g.
        ``("box", (0, 0), 0.2, 0.1, {"mu": 0.5})``; they collide unless that dict says
        ``"collide": False``.

        Or, instead of mass and inertia, density [kg/m^2] > 0 (an area density, as Box2D's and
        pymunk's): the mass, COM and inertia are those of the solid shapes (planarsim.shapes.
        mass_properties; a shape's dict may give its own "density"). Then pos and angle are
        the pose of the body's frame in which the shapes are given (and every later local
        point of the body: anchors, contact points, shapes), and the builder puts the body's
        pose q, which is always its COM's, at the shapes' centroid: q = pos + R(angle) c. The
        shapes stay where they were given in the world; vel is the COM's velocity."""
        idx = len(self._bodies)
        shapes = self._shape_list(name, idx, shapes)
        self._register("body", name, idx)
        q = np.r_[_vec2("body", name, idx, "pos", pos), _scalar("body", name, idx, "angle", angle)]
        v = np.r_[_vec2("body", name, idx, "vel", vel), _scalar("body", name, idx, "omega", omega)]
        if density is None and (mass is not None or inertia is not None):
            mass = _scalar("body", name, idx, "mass", mass)
            inertia = _scalar("body", name, idx, "inertia", inertia)
            if not mass > 0:
                raise ModelError(f"body {name!r} ({idx}): mass={mass} must be finite and > 0")
            if not inertia > 0:
                raise ModelError(f"body {name!r} ({idx}): inertia={inertia} must be finite and > 0 "
                                 f"(use add_point_mass for a body without rotation)")
            origin = None
        else:
            if mass is not None or inertia is not None:
                raise ModelError(f"body {name!r} ({idx}): mass={mass} and inertia={inertia} given "
                                 f"with density={density}; give mass and inertia, or a density")
            if density is not None:
                density = _scalar("body", name, idx, "density", density)
                if not density > 0:
                    raise ModelError(f"body {name!r} ({idx}): density={density} must be finite and "
                                     "> 0 [kg/m^2]")
            mass, inertia, origin = 0.0, 0.0, np.zeros(2)   # from its shapes' densities
        self._bodies.append(dict(name=name, mass=mass, inertia=inertia, q=q, v=v, point=False,
                                 origin=origin))
        kept = len(self._shapes), len(self._collide)
        try:
            for s in shapes:
                s = tuple(s)
                options = dict(s[-1]) if s and isinstance(s[-1], dict) else {}
                if density is not None:
                    options.setdefault("density", density)
                self.add_shape(idx, *(s[:-1] if s and isinstance(s[-1], dict) else s), **options)
        except ModelError:          # a refused shape: neither the body nor its shapes are kept
            del self._bodies[idx:], self._shapes[kept[0]:], self._collide[kept[1]:]
            del self._names["body"][name]
            raise
        return idx

    @staticmethod
    def _shape_list(name, idx, shapes) -> list:
        """add_body's shapes as a list, each checked to be a tuple (kind, *params[, dict])."""
        try:
            out = list(shapes) if not isinstance(shapes, (str, bytes, dict)) else None
        except TypeError:
            out = None
        if out is None:
            raise ModelError(f"body {name!r} ({idx}): shapes={_plain(shapes)!r} must be a list of "
                             "shapes")
        for k, s in enumerate(out):
            if not (isinstance(s, (tuple, list)) and s and isinstance(s[0], str)):
                raise ModelError(f"body {name!r} ({idx}): shapes[{k}]={_plain(s)!r} must be a tuple "
                                 "(kind, *params) as add_shape takes them, e.g. "
                                 "('circle', (0, 0), 0.1)")
        return out

    def _local_point(self, bid, p):
        """A local point [m] given in body bid's frame (origin at its pos) -> the COM frame
        the model keeps (the same point unless the body's mass came from densities)."""
        origin = self._bodies[bid]["origin"] if bid >= 0 else None
        return p if origin is None else np.asarray(p, dtype=np.float64) + origin

    def _attached(self, bid) -> list:
        """What other than shapes names body bid (pins, rods, contacts, actuators, fluid boxes)."""
        out = [f"pin {p['name']!r}" for p in self._pins if bid in p["body"]]
        out += [f"rod {r['name']!r}" for r in self._rods if bid in r["body"]]
        out += [f"contact {c['name']!r}" for c in self._contacts if c["body"] == bid]
        out += [f"actuator {a['name']!r}" for a in self._acts if bid in a["bodies"]]
        out += ["a fluid box" for b, _ in self._fluid if b == bid]
        return out

    def _with_shape_mass(self, bid, who, kind, params, density) -> tuple:
        """(mass [kg], shift of the COM (2,) [m], inertia [kg m^2]) of body bid once a shape
        (params in the COM frame, density [kg/m^2]) joins it; ModelError naming the shape
        and body where they overflow (are not finite)."""
        body = self._bodies[bid]
        area, c, j = shape_area(kind, params, who)
        with np.errstate(over="ignore", invalid="ignore"):
            mass, d, inertia = combine_masses([(body["mass"], np.zeros(2), body["inertia"]),
                                               (density * area, c, density * j)])
        if not (math.isfinite(mass) and math.isfinite(inertia) and np.all(np.isfinite(d))):
            raise ModelError(f"{who}: density={density:g} kg/m^2 on its {area:g} m^2 gives body "
                             f"{body['name']!r} a mass of {mass:g} kg and an inertia of "
                             f"{inertia:g} kg m^2; both must be finite (a smaller density or shape)")
        return mass, d, inertia

    def _add_shape_mass(self, bid, mass, d, inertia):
        """Give body bid its new mass and inertia (_with_shape_mass), then move its frame to
        the new COM (by d): q, the frame's origin and its shapes follow, so that everything
        stays where it is in the world."""
        body = self._bodies[bid]
        body["mass"], body["inertia"] = mass, inertia
        th = body["q"][2]
        body["q"][:2] += (math.cos(th) * d[0] - math.sin(th) * d[1],
                          math.sin(th) * d[0] + math.cos(th) * d[1])
        body["origin"] = body["origin"] - d
        for k, sh in enumerate(self._shapes):
            if sh.body == bid:
                self._shapes[k] = M.Shape(bid, sh.kind, shifted(sh.kind, sh.params, d))
        for sh in self._collide:
            if sh["body"] == bid:
                sh["core"] = sh["core"] - d

    def add_point_mass(self, name, mass, pos=(0.0, 0.0), vel=(0.0, 0.0), radius=None) -> int:
        """Point mass [kg] > 0 at pos [m]: no rotational degree of freedom, takes no torque.
        radius [m] >= 0 is only drawn (default: grows with the cube root of the mass)."""
        idx = len(self._bodies)
        self._register("body", name, idx)
        mass = _scalar("body", name, idx, "mass", mass)
        if not mass > 0:
            raise ModelError(f"body {name!r} ({idx}): mass={mass} must be finite and > 0")
        r = (0.04 * (mass / 1.0) ** (1 / 3) if radius is None
             else _length("body", name, idx, "radius", radius, zero_ok=True))
        q = np.r_[_vec2("body", name, idx, "pos", pos), 0.0]
        v = np.r_[_vec2("body", name, idx, "vel", vel), 0.0]
        self._bodies.append(dict(name=name, mass=mass, inertia=0.0, q=q, v=v, point=True, origin=None))
        self._shapes.append(M.Shape(idx, "circle", ((0.0, 0.0), r)))
        return idx

    def add_shape(self, body, kind, *params, collide=True, mu=1.0, restitution=0.0, category=1,
                  mask=0xFFFF, ground=True, name=None, density=None) -> int:
        """A shape on a body (local frame [m]), or fixed in the world (body None: world
        coordinates; steps, kerbs, walls): ('circle', center, radius) | ('capsule', p0, p1,
        radius) | ('box', center, width, height[, angle]) | ('polygon', [(x, y), ...]) (convex,
        either winding). Returns the shape's id.

        It collides with the ground and with other bodies' shapes unless collide=False (then
        it is only drawn). mu: its friction coefficient (a pair uses sqrt(mu_a mu_b), the
        ground the shape's mu); restitution in [0, 1] (a pair uses the larger, default 0: a
        plastic impact; a disk dropped with e rebounds to e^2 of its height). category and
        mask: filter bits (a pair collides when each one's category meets the other's mask);
        ground=False: it touches other shapes but not the analytic ground (a foot whose own
        contacts already touch it).
        Bodies of one mechanism (linked by pins, rods or actuators) do not collide with each
        other unless enable_collision names the pair.
        density [kg/m^2] > 0: the shape's solid mass and inertia join its body's (a body built
        without mass and inertia, add_body), whose COM and pose then move to the new centroid,
        the shapes staying where they are in the world; before pins, rods, contacts,
        actuators or fluid boxes name the body. Without density a shape adds no mass."""
        idx = len(self._shapes)
        bid = self._body_id(shape_who(kind, idx, name if isinstance(name, str) else None), None,
                            None, "body", body,
                            allow_world=body is None)
        body_name = self._bodies[bid]["name"] if bid >= 0 else None
        if name is not None and (not isinstance(name, str) or not name):
            raise ModelError(f"{shape_who(kind, idx, None, body_name)}: name={name!r} must be a "
                             "non-empty string")
        who = shape_who(kind, idx, name, body_name)
        if kind not in SHAPE_PARAMS:
            raise ModelError(f"{who}: kind={kind!r} must be one of {', '.join(SHAPE_PARAMS)}")
        _check_shape(kind, who, params)
        if density is not None:
            density = self._shape_density(bid, who, density)
        if bid >= 0 and self._bodies[bid]["origin"] is not None:
            params = shifted(kind, params, -self._bodies[bid]["origin"])
        if density is not None:     # checked before the shape is kept
            added = self._with_shape_mass(bid, who, kind, params, density)
        flag(f"{who}: collide", collide, ModelError)
        if bid < 0 and not collide:
            raise ModelError(f"{who}: a static shape (body None) must collide")
        if collide:
            flag(f"{who}: ground", ground, ModelError)
            self._collide.append(self._collision_shape(idx, who, bid, kind, params, mu,
                                                       restitution, category, mask, name))
            self._collide[-1]["ground"] = bool(ground)
        self._shapes.append(M.Shape(bid, kind, tuple(params)))
        if density is not None:
            self._add_shape_mass(bid, *added)
        return idx

    def _shape_density(self, bid, who, density):
        """density [kg/m^2] of a shape, checked: finite, > 0, on a body whose mass comes from
        densities and that nothing but shapes names yet."""
        density = _scalar(who, None, None, "density", density)
        if not density > 0:
            raise ModelError(f"{who}: density={density} must be finite and > 0 [kg/m^2]")
        if bid < 0:
            raise ModelError(f"{who}: density={density} on a static shape (body None), which has "
                             "no mass")
        body = self._bodies[bid]
        if body["origin"] is None:
            raise ModelError(f"{who}: density={density} on body {body['name']!r}, whose mass and "
                             "inertia were given (add_body(..., density=...) or without mass and "
                             "inertia builds a body from its shapes' densities)")
        attached = self._attached(bid)
        if attached:
            raise ModelError(f"{who}: density={density} would move the centre of mass of body "
                             f"{body['name']!r}, which {', '.join(attached)} already use(s); add "
                             "its shapes with density first")
        return density

    def _collision_shape(self, idx, who, bid, kind, params, mu, restitution, category, mask, name):
        """The record compile() turns into shape_* arrays and contacts (validated here)."""
        mu = _scalar(who, None, None, "mu", mu)
        if mu < 0:
            raise ModelError(f"{who}: mu={mu} must be >= 0")
        e = _scalar(who, None, None, "restitution", restitution)
        if not 0.0 <= e <= 1.0:
            raise ModelError(f"{who}: restitution={e} must be in [0, 1]")
        for field, bits in (("category", category), ("mask", mask)):
            if isinstance(bits, (bool, np.bool_)) or not isinstance(bits, (int, np.integer)) or bits < 0:
                raise ModelError(f"{who}: {field}={_plain(bits)!r} must be a non-negative integer "
                                 "(bits)")
        core, radius = collision_core(kind, params, who)
        label = name or f"{self._bodies[bid]['name'] if bid >= 0 else 'world'}.{kind}{idx}"
        return dict(shape=idx, body=bid, kind=kind, core=core, radius=radius, mu=mu,
                    restitution=e, category=int(category), mask=int(mask), label=label, who=who)

    def enable_collision(self, body_a, body_b):
        """Let two bodies of one mechanism (linked by pins, rods or actuators, which keeps them
        apart by default) collide: their colliding shapes then touch each other."""
        a = self._body_id("collision pair", None, 0, "body_a", body_a)
        b = self._body_id("collision pair", None, 0, "body_b", body_b)
        if a == b:
            raise ModelError(f"collision pair: body_a and body_b are the same ({a})")
        self._enabled_pairs.add(frozenset((a, b)))

    # world <-> local ------------------------------------------------------------------------
    def _local(self, body, p_world):
        if body < 0:
            return np.asarray(p_world, dtype=np.float64)
        x, y, th = self._bodies[body]["q"]
        c, s = math.cos(th), math.sin(th)
        dx, dy = p_world[0] - x, p_world[1] - y
        return np.array([c * dx + s * dy, -s * dx + c * dy])

    def _world(self, body, p_local):
        if body < 0:
            return np.asarray(p_local, dtype=np.float64)
        x, y, th = self._bodies[body]["q"]
        c, s = math.cos(th), math.sin(th)
        return np.array([x + c * p_local[0] - s * p_local[1], y + s * p_local[0] + c * p_local[1]])

    def _angle(self, body):
        return 0.0 if body < 0 else self._bodies[body]["q"][2]

    def _anchors(self, kind, name, idx, a, b, anchor_world, anchor_a, anchor_b):
        if anchor_world is not None:
            pw = _vec2(kind, name, idx, "anchor_world", anchor_world)
            la = (self._local(a, pw) if anchor_a is None
                  else self._local_point(a, _vec2(kind, name, idx, "anchor_a", anchor_a)))
            lb = (self._local(b, pw) if anchor_b is None
                  else self._local_point(b, _vec2(kind, name, idx, "anchor_b", anchor_b)))
        else:
            la = self._local_point(a, np.zeros(2) if anchor_a is None
                                   else _vec2(kind, name, idx, "anchor_a", anchor_a))
            lb = self._local_point(b, np.zeros(2) if anchor_b is None
                                   else _vec2(kind, name, idx, "anchor_b", anchor_b))
        for body, lp, f in ((a, la, "anchor_a"), (b, lb, "anchor_b")):
            if body >= 0 and self._bodies[body]["point"] and np.any(lp != 0.0):
                if np.hypot(*lp) > 1e-12:
                    raise ModelError(f"{kind} {name!r} ({idx}): {f}={_shown(lp)} must be (0, 0) on "
                                     f"point mass {self._bodies[body]['name']!r}")
        return la, lb

    # joints ---------------------------------------------------------------------------------
    def add_pin(self, name, body_a, body_b, anchor_world=None, anchor_a=None, anchor_b=None,
                limit=None, stiffness=0.0, damping=0.0, rest_angle=0.0, ref_angle=None,
                armature=0.0, frictionloss=0.0) -> int:
        """Pin joint between body_a and body_b (None: the world).

        Anchors: give ``anchor_world`` (a point both bodies share at the build pose), or local
        ``anchor_a`` / ``anchor_b``. The pin angle is theta_b - theta_a - ref_angle [rad];
        ref_angle defaults to the relative angle at the build pose (pin angle 0 there).
        ``limit=(lower, upper)`` [rad] adds unilateral limits; stiffness [N m/rad] and
        damping [N m s/rad] add a passive spring-damper toward ``rest_angle`` (implicit in the
        velocity solve, kernels/constraints/soft.py; a spring alone that the step resolves is an
        explicit force, kernels/dynamics/forces.py spring_as_force); armature [kg m^2] a reflected rotor inertia on the
        pin angle (M_joint += armature, as MuJoCo's); frictionloss [N m] a dry friction on the
        pin angle (MuJoCo's frictionloss: the joint sticks while the torque holding it stays
        within it, else slips against it; kernels/constraints/joint_friction.py).
        """
        idx, a, b = self._joint_bodies("pin", name, body_a, body_b, world_b=True)
        if a < 0 and b < 0:
            raise ModelError(f"pin {name!r} ({idx}): cannot pin the world to itself")
        if a >= 0 and b < 0:  # keep the world as body a
            a, b = b, a
            anchor_a, anchor_b = anchor_b, anchor_a
        la, lb = self._anchors("pin", name, idx, a, b, anchor_world, anchor_a, anchor_b)
        gap = np.hypot(*(self._world(a, la) - self._world(b, lb)))
        if gap > PIN_ANCHOR_TOL:
            raise ModelError(f"pin {name!r} ({idx}): anchors are {gap:.3g} m apart at the build pose "
                             f"(must be <= {PIN_ANCHOR_TOL:g} m)")
        ref = self._angle(b) - self._angle(a) if ref_angle is None else _scalar("pin", name, idx, "ref_angle", ref_angle)
        lo, hi = self._joint_limit("pin", name, idx, limit)
        k, c, arm = self._joint_passive("pin", name, idx, stiffness, damping, armature)
        fl = self._joint_friction("pin", name, idx, frictionloss)
        acting = [f for f, on in (("limit", bool(np.isfinite(lo) or np.isfinite(hi))), ("stiffness", k != 0.0),
                                  ("damping", c != 0.0), ("armature", arm != 0.0),
                                  ("frictionloss", fl != 0.0)) if on]
        if acting:
            self._pin_angle_turns(f"pin {name!r} ({idx})", a, b, ", ".join(acting))
        self._pins.append(dict(name=name, body=(a, b), anchor=(la, lb), ref=ref, limit=(lo, hi),
                               k=k, c=c, rest=_scalar("pin", name, idx, "rest_angle", rest_angle),
                               kind=JOINT_HINGE, axis=(0.0, 0.0), armature=arm, frictionloss=fl))
        return idx

    def _pin_angle_turns(self, what, a, b, acting):
        """ModelError if body a or b of a hinge is a point mass: a point mass does not turn, so
        the hinge's angle theta_b - theta_a is not a relative angle of two bodies, and what
        acts on it (`acting`: a motor, a spring, a limit, ...) would have no body to react on
        (an outside torque on the other body, or nothing)."""
        for body in (a, b):
            if body >= 0 and self._bodies[body]["point"]:
                raise ModelError(f"{what}: {acting} on a hinge to point mass "
                                 f"{self._bodies[body]['name']!r}, which does not turn: no body "
                                 "would take the reaction (give it an inertia, or drive the "
                                 "other body with add_body_torque)")

    def _joint_bodies(self, kind, name, body_a, body_b, world_b):
        """Register joint `name` in the pin table: (its index, body a, body b) checked (ids;
        None or -1 the world for a, for b too where world_b; two different bodies)."""
        idx = len(self._pins)
        self._register("pin", name, idx)
        a = self._body_id(kind, name, idx, "body_a", body_a, allow_world=True)
        b = self._body_id(kind, name, idx, "body_b", body_b, allow_world=world_b)
        if a == b:
            raise ModelError(f"{kind} {name!r} ({idx}): body_a and body_b are the same ({a})")
        return idx, a, b

    def add_free_coordinate(self, name, body, kind="slide", axis=(1.0, 0.0), anchor_world=None,
                            limit=None, stiffness=0.0, damping=0.0, rest=0.0, armature=0.0,
                            frictionloss=0.0) -> int:
        """One coordinate of a body otherwise free in the plane, measured from the world and
        holding nothing (no constraint rows): what acts on it acts as on a joint's coordinate.

        kind "slide": s = d.(p - p0) [m], the displacement along the world axis ``axis`` of
        the body's point at ``anchor_world`` (default its COM) from where it is at the build
        pose; kind "hinge": the body's turn theta - theta0 [rad] (anchor_world is only drawn).
        ``limit`` [m or rad] adds unilateral limits, stiffness / damping a passive
        spring-damper toward ``rest`` (implicit; a spring alone that the step resolves is an
        explicit force), armature [kg or kg m^2] a reflected inertia on the
        coordinate (as MuJoCo's on a free root's slide or hinge: M_joint += armature),
        frictionloss [N or N m] a dry friction on it (kernels/constraints/joint_friction.py), and
        add_slider_motor / add_pin_motor a force [N] along the axis at the anchor / a torque
        [N m]. An MJCF free root (two slides and a hinge) is three of these on one body.
        It shares the pins' table with kind JOINT_FREE_SLIDE or JOINT_FREE_HINGE.
        """
        if kind not in ("slide", "hinge"):
            raise ModelError(f"free coordinate {name!r}: kind={kind!r} must be 'slide' or 'hinge'")
        idx, a, b = self._joint_bodies("free coordinate", name, None, body, world_b=False)
        if kind == "hinge" and self._bodies[b]["point"]:
            raise ModelError(f"free coordinate {name!r} ({idx}): a point mass does not turn")
        if anchor_world is None:
            anchor_world = self._world(b, np.zeros(2))
        la, lb = self._anchors("free coordinate", name, idx, a, b, anchor_world, None, None)
        d = (0.0, 0.0)
        if kind == "slide":
            d = _vec2("free coordinate", name, idx, "axis", axis)
            norm = float(np.hypot(*d))
            if not norm > 1e-12:
                raise ModelError(f"free coordinate {name!r} ({idx}): axis={_shown(d)} "
                                 f"must not be zero")
            d = tuple(d / norm)
        lo, hi = self._joint_limit("free coordinate", name, idx, limit)
        k, c, arm = self._joint_passive("free coordinate", name, idx, stiffness, damping, armature)
        fl = self._joint_friction("free coordinate", name, idx, frictionloss)
        self._pins.append(dict(name=name, body=(a, b), anchor=(la, lb), ref=self._angle(b),
                               limit=(lo, hi), k=k, c=c,
                               rest=_scalar("free coordinate", name, idx, "rest", rest),
                               kind=JOINT_FREE_SLIDE if kind == "slide" else JOINT_FREE_HINGE,
                               axis=d, armature=arm, frictionloss=fl))
        return idx

    def add_fluid_box(self, body, size, viscosity=0.0, density=0.0, local=(0.0, 0.0),
                      angle=0.0) -> int:
        """Drag of a still fluid on a box fixed to `body` (MuJoCo's inertia-box fluid model
        in the plane, kernels/dynamics/fluid.py): full sides size = (l1, l2, ln) [m] > 0 (l1 along the
        box's first in-plane axis, at ``angle`` [rad] in the body's frame; ln along the plane's
        normal), centre at ``local`` [m]; the fluid's viscosity [Pa s] >= 0 (linear drag) and
        density [kg/m^3] >= 0 (quadratic drag). Returns the box's index."""
        b = self._body_id("fluid box", None, len(self._fluid), "body", body)
        who = f"fluid box on body {self._bodies[b]['name']!r}"
        if isinstance(size, (str, bytes)) or np.shape(size) != (3,):
            raise ModelError(f"{_who(who, None, len(self._fluid))}: size={_plain(size)!r} must be "
                             "three lengths (l1, l2, ln) [m]")
        l1, l2, ln = (_length(who, None, len(self._fluid), f"size[{i}]", x)
                      for i, x in enumerate(size))
        mu = _length(who, None, len(self._fluid), "viscosity", viscosity, zero_ok=True)
        rho = _length(who, None, len(self._fluid), "density", density, zero_ok=True)
        c = self._local_point(b, _vec2(who, None, len(self._fluid), "local", local))
        th = _scalar(who, None, len(self._fluid), "angle", angle)
        d = (l1 + l2 + ln) / 3.0
        self._fluid.append((b, (c[0], c[1], th, 3.0 * math.pi * d * mu, math.pi * d ** 3 * mu,
                                0.5 * rho * l2 * ln, 0.5 * rho * l1 * ln,
                                rho * ln * (l1 ** 4 + l2 ** 4) / 64.0)))
        return len(self._fluid) - 1

    @staticmethod
    def _joint_limit(kind, name, idx, limit):
        lo, hi = ((-math.inf, math.inf) if limit is None
                  else _pair(kind, name, idx, "limit", limit, ("lower", "upper")))
        if lo > hi:
            raise ModelError(f"{kind} {name!r} ({idx}): limit lower={lo} > upper={hi}")
        return lo, hi

    @staticmethod
    def _joint_passive(kind, name, idx, stiffness, damping, armature):
        k = _scalar(kind, name, idx, "stiffness", stiffness)
        c = _scalar(kind, name, idx, "damping", damping)
        if k < 0 or c < 0:
            raise ModelError(f"{kind} {name!r} ({idx}): stiffness={k} and damping={c} must be >= 0")
        arm = _scalar(kind, name, idx, "armature", armature)
        if arm < 0:
            raise ModelError(f"{kind} {name!r} ({idx}): armature={arm} must be >= 0")
        return k, c, arm

    @staticmethod
    def _joint_friction(kind, name, idx, frictionloss):
        fl = _scalar(kind, name, idx, "frictionloss", frictionloss)
        if fl < 0:
            raise ModelError(f"{kind} {name!r} ({idx}): frictionloss={fl} must be >= 0")
        return fl

    def add_slider(self, name, body_a, body_b, axis=(1.0, 0.0), anchor_world=None, anchor_a=None,
                   anchor_b=None, limit=None, stiffness=0.0, damping=0.0, rest=0.0,
                   ref_angle=None, armature=0.0, frictionloss=0.0) -> int:
        """Slider (prismatic) joint: body_b moves along ``axis`` of body_a (None: the world)
        and keeps its angle relative to body_a.

        ``axis`` (ax, ay) is a direction in body_a's frame (the world's if body_a is None),
        normalised here. Anchors: ``anchor_world`` (a point both bodies share at the build
        pose), or local ``anchor_a`` / ``anchor_b``; by default body_b's COM at the build pose.
        Anchor b must lie on the line through anchor a along the axis (within 1e-6 m). The
        slide s = d.(p_b - p_a) [m] (d the axis in the world) is the joint's coordinate:
        ``limit=(lower, upper)`` [m] adds unilateral limits on it, stiffness [N/m] and damping
        [N s/m] a passive spring-damper toward ``rest`` [m] (implicit, kernels/constraints/soft.py; a
        spring alone that the step resolves is an explicit force: spring_as_force),
        armature [kg] a reflected rotor inertia on it, frictionloss [N] a dry friction on it
        (MuJoCo's frictionloss; kernels/constraints/joint_friction.py). The relative angle held is
        theta_b - theta_a = ref_angle [rad] (default: as at the build pose). The slider shares
        the pins' table (names, State.limit_active, State.last_pin_impulse: perpendicular,
        angle, lower, upper impulse) with kind JOINT_SLIDER.
        """
        idx, a, b = self._joint_bodies("slider", name, body_a, body_b, world_b=False)
        if self._bodies[b]["point"] or (a >= 0 and self._bodies[a]["point"]):
            raise ModelError(f"slider {name!r} ({idx}): a slider holds an angle: its bodies must "
                             f"not be point masses")
        d = _vec2("slider", name, idx, "axis", axis)
        norm = float(np.hypot(*d))
        if not norm > 1e-12:
            raise ModelError(f"slider {name!r} ({idx}): axis={_shown(d)} must not be zero")
        d = d / norm
        if anchor_world is None and anchor_a is None and anchor_b is None:
            anchor_world = self._world(b, np.zeros(2))
        la, lb = self._anchors("slider", name, idx, a, b, anchor_world, anchor_a, anchor_b)
        th_a = self._angle(a)
        dw = np.array([math.cos(th_a) * d[0] - math.sin(th_a) * d[1],
                       math.sin(th_a) * d[0] + math.cos(th_a) * d[1]])
        e = self._world(b, lb) - self._world(a, la)
        off = abs(float(-dw[1] * e[0] + dw[0] * e[1]))
        if off > PIN_ANCHOR_TOL:
            raise ModelError(f"slider {name!r} ({idx}): anchor b is {off:.3g} m off the axis line "
                             f"at the build pose (must be <= {PIN_ANCHOR_TOL:g} m)")
        ref = (self._angle(b) - th_a if ref_angle is None
               else _scalar("slider", name, idx, "ref_angle", ref_angle))
        lo, hi = self._joint_limit("slider", name, idx, limit)
        k, c, arm = self._joint_passive("slider", name, idx, stiffness, damping, armature)
        fl = self._joint_friction("slider", name, idx, frictionloss)
        self._pins.append(dict(name=name, body=(a, b), anchor=(la, lb), ref=ref, limit=(lo, hi),
                               k=k, c=c, rest=_scalar("slider", name, idx, "rest", rest),
                               kind=JOINT_SLIDER, axis=tuple(d), armature=arm, frictionloss=fl))
        return idx

    def add_rod(self, name, body_a, body_b, anchor_a=(0.0, 0.0), anchor_b=(0.0, 0.0), length=None) -> int:
        """Massless rigid rod: keeps |p_b - p_a| = length [m] (default: the build-pose distance)."""
        idx = len(self._rods)
        self._register("rod", name, idx)
        a = self._body_id("rod", name, idx, "body_a", body_a, allow_world=True)
        b = self._body_id("rod", name, idx, "body_b", body_b, allow_world=True)
        if a == b:
            raise ModelError(f"rod {name!r} ({idx}): body_a and body_b are the same ({a})")
        la, lb = self._anchors("rod", name, idx, a, b, None, anchor_a, anchor_b)
        dist = float(np.hypot(*(self._world(b, lb) - self._world(a, la))))
        length = dist if length is None else _scalar("rod", name, idx, "length", length)
        if not length > 1e-9:
            raise ModelError(f"rod {name!r} ({idx}): length={length} must be > 0")
        if abs(length - dist) > 1e-9 * max(1.0, length):
            # the first step would have to close the difference in one move (and then name
            # the step size, not the rod)
            raise ModelError(f"rod {name!r} ({idx}): length={length:g} m, but its anchors are "
                             f"{dist:g} m apart in the build pose; place the bodies so that the "
                             "rod holds (or leave length out: the build-pose distance)")
        self._rods.append(dict(name=name, body=(a, b), anchor=(la, lb), length=length))
        return idx

    # contacts -------------------------------------------------------------------------------
    def _needs_ground(self, method, name):
        """ModelError naming the contact when the model has no ground (ground=None)."""
        if not self.ground:
            raise ModelError(f"contact {name!r} ({len(self._contacts)}): {method} touches only "
                             "the ground, and this model has none (ModelBuilder(ground=None)); "
                             "give the body a shape (add_shape) to touch other shapes")

    def _contact(self, name, body, kind, local, radius, span, mu, verts):
        idx = len(self._contacts)
        self._register("contact", name, idx)
        bid = self._body_id("contact", name, idx, "body", body)
        mu = _scalar("contact", name, idx, "mu", mu)
        if mu < 0:
            raise ModelError(f"contact {name!r} ({idx}): mu={mu} must be >= 0")
        local = self._local_point(bid, _vec2("contact", name, idx, "local", local))
        verts = [self._local_point(bid, _vec2("contact", name, idx, f"vertex[{i}]", v))
                 for i, v in enumerate(verts)]
        point = self._bodies[bid]["point"]
        if point and (kind != CONTACT_POINT or np.hypot(*local) > 1e-12):
            raise ModelError(f"contact {name!r} ({idx}): a point mass can only carry a point contact at (0, 0)")
        self._contacts.append(dict(name=name, body=bid, kind=kind, local=local, radius=radius,
                                   span=span, mu=mu, verts=verts,
                                   ccd=1 if point else 0, other=-1, pair=(-1, -1, -1),
                                   restitution=0.0))
        return idx

    def add_point_contact(self, name, body, local=(0.0, 0.0), mu=1.0) -> int:
        """A point of `body` (local [m]) that touches the ground; on a point mass it uses
        continuous collision detection."""
        self._needs_ground("add_point_contact", name)
        return self._contact(name, body, CONTACT_POINT, local, 0.0, (0.0, 0.0), mu, [])

    def add_arc_contact(self, name, body, center, radius, span=(-math.pi, math.pi), vertices=(),
                        mu=1.0) -> int:
        """Circular-arc sole: centre (local [m]), radius [m] > 0, span (a0, a1) [rad] of body-frame
        directions from the centre to the sole (full circle by default). Where the sole's lowest
        point lies outside the span, the lowest of `vertices` (heel, toe, back; local [m]) is
        used instead, so a tipped foot rests on its corners. The foot rolls."""
        self._needs_ground("add_arc_contact", name)
        idx = len(self._contacts)
        r = _scalar("contact", name, idx, "radius", radius)
        if not r > 0:
            raise ModelError(f"contact {name!r} ({idx}): radius={r} must be > 0")
        a0, a1 = _pair("contact", name, idx, "span", span, ("a0", "a1"))
        _finite("contact", name, idx, "span", (a0, a1))
        if not a1 > a0:
            raise ModelError(f"contact {name!r} ({idx}): span=({a0}, {a1}) must have span[1] > span[0]")
        if isinstance(vertices, (str, bytes, dict)) or not hasattr(vertices, "__iter__"):
            raise ModelError(f"contact {name!r} ({idx}): vertices={_plain(vertices)!r} must be a "
                             "list of (x, y) points (heel, toe, ...)")
        cid = self._contact(name, body, CONTACT_ARC, center, r, (a0, a1), mu, list(vertices))
        b = self._contacts[cid]["body"]
        self._shapes.append(M.Shape(b, "arc", (tuple(self._contacts[cid]["local"]), r, (a0, a1),
                                                tuple(tuple(v) for v in self._contacts[cid]["verts"]))))
        return cid

    def add_box_contacts(self, name, body, center, width, height, mu=1.0, angle=0.0) -> list:
        """Four corner point contacts of a box (local centre [m], width x height [m]).
        Returns the four contact ids, named ``name/0..3``; also draws the box. width and
        height must be > 0."""
        self._needs_ground("add_box_contacts", name)
        idx = len(self._contacts)
        c = _vec2("box", name, idx, "center", center)
        width = _length("box", name, idx, "width", width)
        height = _length("box", name, idx, "height", height)
        angle = _scalar("box", name, idx, "angle", angle)
        ca, sa = math.cos(angle), math.sin(angle)
        ids = []
        for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
            lx, ly = 0.5 * width * sx, 0.5 * height * sy
            ids.append(self.add_point_contact(f"{name}/{i}", body,
                                              (c[0] + ca * lx - sa * ly, c[1] + sa * lx + ca * ly), mu))
        self.add_shape(self._contacts[ids[0]]["body"], "box", tuple(c), width, height, angle,
                       collide=False)   # drawn: its corners are the contacts
        return ids

    # actuators ------------------------------------------------------------------------------
    def _act(self, name, kind, bodies=(-1, -1, -1), ref=-1, anchors=None, direction=(0.0, 0.0),
             limit=(-math.inf, math.inf)):
        idx = len(self._acts)
        lo, hi = _pair("actuator", name, idx, "limit", limit)
        if lo > hi:
            raise ModelError(f"actuator {name!r} ({idx}): limit=({lo}, {hi}) must have min <= max")
        self._register("actuator", name, idx)
        self._acts.append(dict(name=name, kind=kind, bodies=bodies, ref=ref,
                               anchors=anchors if anchors is not None else (np.zeros(2), np.zeros(2)),
                               dir=np.asarray(direction, dtype=np.float64), limit=(lo, hi)))
        return idx

    def add_pin_motor(self, name, pin, limit=(-math.inf, math.inf)) -> int:
        """Torque [N m] at a pin: +tau on body b, -tau on body a; saturated to limit."""
        idx = len(self._acts)
        if isinstance(pin, str):
            if pin not in self._names["pin"]:
                raise ModelError(f"actuator {name!r} ({idx}): pin={pin!r} names no pin")
            pin = self._names["pin"][pin]
        if is_bool(pin) or not (isinstance(pin, (int, np.integer)) and 0 <= pin < len(self._pins)):
            raise ModelError(f"actuator {name!r} ({idx}): pin={pin!r} is not a pin id")
        if self._pins[pin]["kind"] & JOINT_SLIDE_BIT:
            raise ModelError(f"actuator {name!r} ({idx}): pin={self._pins[pin]['name']!r} is a "
                             f"slider (use add_slider_motor)")
        a, b = self._pins[pin]["body"]
        self._pin_angle_turns(f"actuator {name!r} ({idx})", a, b,
                              f"a torque at pin {self._pins[pin]['name']!r}")
        return self._act(name, M.ACT_PIN_TORQUE, (a, b, -1), int(pin), limit=limit)

    def add_slider_motor(self, name, slider, limit=(-math.inf, math.inf)) -> int:
        """Force [N] along a slider's axis: +f on body b at its anchor, -f on body a at the
        same point (it does work f ds/dt); saturated to limit."""
        idx = len(self._acts)
        if isinstance(slider, str):
            if slider not in self._names["pin"]:
                raise ModelError(f"actuator {name!r} ({idx}): slider={slider!r} names no slider")
            slider = self._names["pin"][slider]
        if is_bool(slider) or not (isinstance(slider, (int, np.integer)) and 0 <= slider < len(self._pins)
                and self._pins[slider]["kind"] & JOINT_SLIDE_BIT):
            raise ModelError(f"actuator {name!r} ({idx}): slider={slider!r} is not a slider id")
        a, b = self._pins[slider]["body"]
        return self._act(name, M.ACT_SLIDER_FORCE, (a, b, -1), int(slider), limit=limit)

    def add_axial(self, name, body_a, body_b, anchor_a=(0.0, 0.0), anchor_b=(0.0, 0.0),
                  limit=(-math.inf, math.inf)) -> int:
        """Force [N] along the line between two anchors; positive pushes them apart (a leg
        actuator between a hip and a foot point mass)."""
        idx = len(self._acts)
        a = self._body_id("actuator", name, idx, "body_a", body_a)
        b = self._body_id("actuator", name, idx, "body_b", body_b)
        if a == b:
            raise ModelError(f"actuator {name!r} ({idx}): body_a and body_b are the same body "
                             f"({a}): an axial force between a body and itself does nothing")
        la, lb = self._anchors("actuator", name, idx, a, b, None, anchor_a, anchor_b)
        if not np.hypot(*(self._world(b, lb) - self._world(a, la))) > 0.0:
            raise ModelError(f"actuator {name!r} ({idx}): its anchors coincide in the build pose, "
                             "so the force has no direction; place them apart")
        return self._act(name, M.ACT_AXIAL, (a, b, -1), anchors=(la, lb), limit=limit)

    def add_hip_torque(self, name, hip, leg_a, leg_b, limit=(-math.inf, math.inf)) -> int:
        """Torque [N m] between two massless legs hip->leg_a and hip->leg_b (point masses),
        realised as forces perpendicular to the legs: +tau turns leg b counter-clockwise
        relative to leg a; net force and net torque on the system are zero."""
        idx = len(self._acts)
        h = self._body_id("actuator", name, idx, "hip", hip)
        a = self._body_id("actuator", name, idx, "leg_a", leg_a)
        b = self._body_id("actuator", name, idx, "leg_b", leg_b)
        if len({h, a, b}) < 3:
            raise ModelError(f"actuator {name!r} ({idx}): hip, leg_a and leg_b must be three "
                             f"different bodies (got {h}, {a}, {b}): a leg runs from the hip to "
                             "its own foot")
        return self._act(name, M.ACT_HIP_TORQUE, (a, b, h), limit=limit)

    def add_body_force(self, name, body, direction=(1.0, 0.0), limit=(-math.inf, math.inf)) -> int:
        """Force [N] at the body's COM along a fixed unit world direction."""
        idx = len(self._acts)
        bid = self._body_id("actuator", name, idx, "body", body)
        d = _vec2("actuator", name, idx, "direction", direction)
        n = np.hypot(*d)
        if not n > 0:
            raise ModelError(f"actuator {name!r} ({idx}): direction={_shown(d)} must be non-zero")
        return self._act(name, M.ACT_BODY_FORCE, (bid, -1, -1), direction=d / n, limit=limit)

    def add_body_torque(self, name, body, limit=(-math.inf, math.inf)) -> int:
        """Torque [N m] on one rigid body."""
        idx = len(self._acts)
        bid = self._body_id("actuator", name, idx, "body", body)
        if self._bodies[bid]["point"]:
            raise ModelError(f"actuator {name!r} ({idx}): body "
                             f"{self._bodies[bid]['name']!r} is a point mass, which does not "
                             "turn: a torque on it does nothing")
        return self._act(name, M.ACT_BODY_TORQUE, (bid, -1, -1), limit=limit)

    # colliding shapes -> contacts ------------------------------------------------------------
    def _shape_contacts(self):
        """The contacts of the colliding shapes (compile adds them after the user's): a
        polygon's corners and a circle's or capsule's end circles against the ground, and two
        slots (a face on a face touches at two points) for every pair of shapes that may touch
        (shapes.collision_pairs), ordered by the later of their bodies (the rows' order)."""
        out = []

        def contact(name, body, kind, local=(0.0, 0.0), radius=0.0, span=(0.0, 0.0), mu=1.0,
                    other=-1, pair=(-1, -1, -1), restitution=0.0):
            return dict(name=name, body=body, kind=kind, local=np.asarray(local, float),
                        radius=radius, span=span, mu=mu, verts=[], ccd=0, other=other, pair=pair,
                        restitution=restitution)

        curved = self.ground and self.terrain.coef[2] != 0   # hills: a straight side can touch a crest
        for sh in self._collide:
            if sh["body"] < 0 or not sh["ground"] or not self.ground:
                continue        # world shapes meet bodies, not the ground (nor, if none, any)
            common = dict(mu=sh["mu"], restitution=sh["restitution"])
            core = sh["core"]
            if sh["kind"] in ("box", "polygon"):
                for k, v in enumerate(core):
                    out.append(contact(f"{sh['label']}/ground{k}", sh["body"], CONTACT_POINT, v,
                                       **common))
            else:
                for k, v in enumerate(core):
                    out.append(contact(f"{sh['label']}/ground{k}", sh["body"], CONTACT_ARC, v,
                                       sh["radius"], (-math.pi, math.pi), **common))
            if curved and len(core) >= 2:
                # each straight side: its point nearest the ground where that is not an end;
                # a side that may span more than one crest, in pieces (edge_pieces)
                for k in range(len(core) if len(core) > 2 else 1):
                    start = np.asarray(core[k], float)
                    end = np.asarray(core[(k + 1) % len(core)], float)
                    pieces = edge_pieces(start, end, self.terrain)
                    for j, (a, b, own) in enumerate(pieces):
                        label = f"edge{k}" if len(pieces) == 1 else f"edge{k}.{j}"
                        c = contact(f"{sh['label']}/{label}", sh["body"], CONTACT_EDGE, a,
                                    sh["radius"], span=own, **common)
                        c["verts"] = [b]
                        out.append(c)
        # a mechanism: bodies linked by pins, rods or actuators (a leg that is a force)
        joints = [p["body"] for p in self._pins] + [r["body"] for r in self._rods]
        for a in self._acts:
            bodies = [x for x in a["bodies"] if x >= 0]
            joints += [(x, y) for k, x in enumerate(bodies) for y in bodies[k + 1:]]
        for i, j in collision_pairs(self._collide, len(self._bodies), joints, self._enabled_pairs):
            if self._collide[i]["body"] < 0:
                i, j = j, i     # the world's shape second: contact_body is always a body
            a, b = self._collide[i], self._collide[j]
            for k in range(2):
                out.append(contact(f"{a['label']}|{b['label']}/{k}", a["body"], CONTACT_PAIR,
                                   radius=a["radius"] + b["radius"],
                                   mu=math.sqrt(a["mu"] * b["mu"]), other=b["body"],
                                   pair=(i, j, k),
                                   restitution=max(a["restitution"], b["restitution"])))
        out.sort(key=lambda c: max(c["body"], c["other"]))   # stable: a pair's slots stay together
        names = {c["name"] for c in self._contacts}
        for c in out:
            if c["name"] in names:
                raise ModelError(f"contact {c['name']!r}: a shape's contact has the name of a "
                                 "contact added before; rename the shape (name=...)")
            names.add(c["name"])
        return out

    def _shape_arrays(self, ro):
        """shape_* arrays of the colliding shapes (kernels/geometry/collide.py: a core and a radius)."""
        cores = [sh["core"] for sh in self._collide]
        adr = np.cumsum([0] + [len(c) for c in cores])[:-1]
        core = np.concatenate(cores) if cores else np.zeros((0, 2))
        norm = np.concatenate([core_normals(c) for c in cores]) if cores else np.zeros((0, 2))
        ns = len(cores)
        return dict(
            shape_body=ro([sh["body"] for sh in self._collide], np.int64).reshape(ns),
            shape_vert_adr=ro(adr, np.int64).reshape(ns),
            shape_vert_num=ro([len(c) for c in cores], np.int64).reshape(ns),
            shape_radius=ro([sh["radius"] for sh in self._collide]).reshape(ns),
            shape_bound=ro([shape_bounds(sh["core"], core_normals(sh["core"]), sh["radius"])
                            for sh in self._collide] or np.zeros((0, 5))).reshape(ns, 5),
            core_vert=ro(core).reshape(len(core), 2),
            core_norm=ro(norm).reshape(len(core), 2),
            core_cover=ro(covered_edges(self._collide, self.terrain if self.ground else None))
            .reshape(len(core), 8))

    # compile --------------------------------------------------------------------------------
    def compile(self, **meta) -> M.Model:
        """Validate and freeze into a Model."""
        dt = number("model: dt", self.dt, finite=False, error=ModelError)
        if not (math.isfinite(dt) and 0 < dt <= 1.0):
            # (StepOptions.dt keeps to the same (0, 1] s: a model's own step beyond it built
            # and stepped where the same step given as an option was refused)
            raise ModelError(f"model: dt={dt} must be a step in (0, 1] s")
        try:
            g = None if holds_bool(self.gravity) else np.asarray(self.gravity, dtype=np.float64).reshape(2)
        except (TypeError, ValueError):
            g = None
        if g is None:
            raise ModelError(f"model: gravity={self.gravity!r} must be a pair (gx, gy) of numbers")
        if not np.all(np.isfinite(g)):
            raise ModelError(f"model: gravity={_shown(g)} must be finite")
        if self.ground and not isinstance(self.terrain, Terrain):
            raise ModelError(f"model: terrain={self.terrain!r} must be a planarsim.terrain.Terrain")
        if not self.ground and self.terrain is not None:
            raise ModelError(f"model: terrain={getattr(self.terrain, 'name', self.terrain)!r} set on "
                             "a builder made with ground=None; a world without ground has no terrain")
        if not self._bodies:
            raise ModelError("model: no bodies; add at least one with add_body or add_point_mass")
        for i, body in enumerate(self._bodies):
            if not body["mass"] > 0:
                raise ModelError(f"body {body['name']!r} ({i}): no mass: none of its shapes has a "
                                 "density; give mass= and inertia=, or density= (the body's or a "
                                 "shape's)")
        contacts = self._contacts + self._shape_contacts()
        nb, npin, nr, nc, na = (len(x) for x in (self._bodies, self._pins, self._rods, contacts, self._acts))

        def ro(a, dtype=np.float64):
            a = np.ascontiguousarray(np.asarray(a, dtype=dtype))
            a.setflags(write=False)
            return a

        mass = np.array([b["mass"] for b in self._bodies])
        inertia = np.array([b["inertia"] for b in self._bodies])
        inv_inertia = np.where(inertia > 0, 1.0 / np.where(inertia > 0, inertia, 1.0), 0.0)
        verts, vadr, vnum = [], [], []
        for c in contacts:
            vadr.append(len(verts))
            vnum.append(len(c["verts"]))
            verts.extend(c["verts"])
        arrays = M.ModelArrays(
            dt=dt, n_shape_pair=int(sum(c["kind"] == CONTACT_PAIR for c in contacts) // 2),
            gravity=ro(g),
            body_mass=ro(mass), body_inertia=ro(inertia), body_inv_mass=ro(1.0 / mass),
            body_inv_inertia=ro(inv_inertia),
            pin_body=ro([p["body"] for p in self._pins] or np.zeros((0, 2)), np.int64).reshape(npin, 2),
            pin_anchor=ro([p["anchor"] for p in self._pins] or np.zeros((0, 2, 2))).reshape(npin, 2, 2),
            pin_ref=ro([p["ref"] for p in self._pins]).reshape(npin),
            pin_limit=ro([p["limit"] for p in self._pins] or np.zeros((0, 2))).reshape(npin, 2),
            pin_stiffness=ro([p["k"] for p in self._pins]).reshape(npin),
            pin_damping=ro([p["c"] for p in self._pins]).reshape(npin),
            pin_rest=ro([p["rest"] for p in self._pins]).reshape(npin),
            pin_kind=ro([p["kind"] for p in self._pins], np.int64).reshape(npin),
            pin_axis=ro([p["axis"] for p in self._pins] or np.zeros((0, 2))).reshape(npin, 2),
            pin_armature=ro([p["armature"] for p in self._pins]).reshape(npin),
            pin_frictionloss=ro([p["frictionloss"] for p in self._pins]).reshape(npin),
            rod_body=ro([r["body"] for r in self._rods] or np.zeros((0, 2)), np.int64).reshape(nr, 2),
            rod_anchor=ro([r["anchor"] for r in self._rods] or np.zeros((0, 2, 2))).reshape(nr, 2, 2),
            rod_length=ro([r["length"] for r in self._rods]).reshape(nr),
            contact_body=ro([c["body"] for c in contacts], np.int64).reshape(nc),
            contact_kind=ro([c["kind"] for c in contacts], np.int64).reshape(nc),
            contact_local=ro([c["local"] for c in contacts] or np.zeros((0, 2))).reshape(nc, 2),
            contact_radius=ro([c["radius"] for c in contacts]).reshape(nc),
            contact_span=ro([c["span"] for c in contacts] or np.zeros((0, 2))).reshape(nc, 2),
            contact_span_dir=ro([(math.cos(c["span"][0]), math.sin(c["span"][0]),
                                  math.cos(c["span"][1]), math.sin(c["span"][1]))
                                 for c in contacts] or np.zeros((0, 4))).reshape(nc, 4),
            contact_mu=ro([resolved_friction(c["mu"]) for c in contacts]).reshape(nc),
            contact_ccd=ro([c["ccd"] for c in contacts], np.int64).reshape(nc),
            contact_vert_adr=ro(vadr, np.int64).reshape(nc),
            contact_vert_num=ro(vnum, np.int64).reshape(nc),
            contact_other=ro([c["other"] for c in contacts], np.int64).reshape(nc),
            contact_pair=ro([c["pair"] for c in contacts] or np.zeros((0, 3)), np.int64).reshape(nc, 3),
            contact_restitution=ro([c["restitution"] for c in contacts]).reshape(nc),
            vert_local=ro(verts or np.zeros((0, 2))).reshape(len(verts), 2),
            act_kind=ro([a["kind"] for a in self._acts], np.int64).reshape(na),
            act_body=ro([a["bodies"] for a in self._acts] or np.zeros((0, 3)), np.int64).reshape(na, 3),
            act_ref=ro([a["ref"] for a in self._acts], np.int64).reshape(na),
            act_anchor=ro([a["anchors"] for a in self._acts] or np.zeros((0, 2, 2))).reshape(na, 2, 2),
            act_dir=ro([a["dir"] for a in self._acts] or np.zeros((0, 2))).reshape(na, 2),
            act_range=ro([a["limit"] for a in self._acts] or np.zeros((0, 2))).reshape(na, 2),
            fluid_body=ro([b for b, _ in self._fluid], np.int64).reshape(len(self._fluid)),
            fluid_coef=ro([c for _, c in self._fluid] or np.zeros((0, 8))).reshape(len(self._fluid), 8),
            terrain_coef=ro((self.terrain if self.ground else flat()).coef),  # no ground: no contact reads it
            **self._shape_arrays(ro),
        )
        q0 = np.array([b["q"] for b in self._bodies])
        v0 = np.array([b["v"] for b in self._bodies])
        for arr in (q0, v0):
            arr.setflags(write=False)
        return M.Model(arrays=arrays,
                       body_names=tuple(b["name"] for b in self._bodies),
                       pin_names=tuple(p["name"] for p in self._pins),
                       rod_names=tuple(r["name"] for r in self._rods),
                       contact_names=tuple(c["name"] for c in contacts),
                       act_names=tuple(a["name"] for a in self._acts),
                       q0=q0, v0=v0, shapes=tuple(self._shapes), terrain=self.terrain, meta=dict(meta),
                       shape_names=tuple(sh["who"] for sh in self._collide))
