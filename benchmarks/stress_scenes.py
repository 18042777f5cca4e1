"""Box2D's classic stress scenes and contact-rich scenes, described once in engine-neutral
form (`Scene`) and built natively by planarsim (`build_model`) and by the peers
(peers/box2d_peer.ShapeWorld, peers/pymunk_peer.ShapeWorld, peers/mujoco_peer.ShapeWorld).

Stress scenes (planarsim must hold them exactly: pins <= 1e-9 m, overlaps <= 1e-8 m):
- bridge160: 160 planks 0.25 x 0.05 m, 0.5 kg, pinned end to end, both ends pinned to the
  world, starting at rest on a circular arc that sags 2 m; it swings toward its hanging shape.
- bridge160_taut: Box2D's own bridge: the same planks straight, spanning the gap exactly (a
  taut chain of rigid pins: its pins' rows are dependent along the bridge and its tension
  unbounded; Box2D's soft joints stretch).
- chain_ball: 40 capsule links (0.25 m, 0.5 kg) pinned end to end from a world pin, a 50 kg
  disk (100 x a link) pinned at the free end, all horizontal at rest: it falls and swings.
- card_house: cards 0.4 x 0.004 m, 10 g, leaning in A shapes on flat ground (one leaning
  0.45 rad, its top corner on the face of the other, leaning 0.43 rad), a flat card across
  each level's A's, 3 levels (3, 2, 1 A's: 14 cards), friction 0.8.
- mass_ratio: a 100 kg box 1.2 x 0.4 m resting on three 1 kg cubes 0.2 m.
- stack20: 20 cubes 0.2 m, 1 kg, stacked on flat ground.
Contact-rich scenes:
- dominoes20: 20 dominoes 0.02 x 0.2 m, 0.1 kg, 0.1 m apart; the first tipping forward at
  4 rad/s about its front foot.
- pour50: 50 circles (r 5 cm) and capsules (0.1 m + 2 x 4 cm), 0.2 kg each, in a 5 x 10
  grid above a static U of three boxes (no ground), falling into it from rest.
- pyramid55: 55 cubes 0.2 m in 10 rows (2 cm apart in a row, each row on the one below), from
  rest on flat ground.

Every body's shapes are centred on its centre of mass (boxes, circles, capsules along the
body's x axis), its mass given and its inertia that of its solid shapes, so every engine gets
the same masses, inertias, start poses and velocities. Flat ground (y = 0) where `ground` says
so; pinned bodies touch nothing else and do not collide with each other.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import planarsim as ps
from planarsim.shapes import shape_area


@dataclass(frozen=True)
class Part:
    """One body. shapes: ("box", w, h) | ("circle", r) | ("capsule", half_length, r), centred on
    the COM (capsule along the body's x axis) [m]; mass [kg]; pos [m], angle [rad]; start
    velocity vel [m/s] and omega [rad/s]."""
    name: str
    pos: tuple
    shape: tuple
    mass: float
    angle: float = 0.0
    vel: tuple = (0.0, 0.0)
    omega: float = 0.0


@dataclass(frozen=True)
class Scene:
    """A scene in engine-neutral form (SI units). statics: static boxes (centre, w, h) in the
    world; pins: (body a, body b, world anchor at the start pose), -1 for the world; ground:
    flat ground at y = 0; resting: every body should stay where it starts; mu: friction of
    every shape (pairs: the same mu); seconds: the run of the benchmark and the tests' run."""
    name: str
    parts: tuple
    pins: tuple = ()
    statics: tuple = ()
    ground: bool = True
    resting: bool = False
    mu: float = 0.6
    dt: float = 1e-3
    seconds: float = 1.0
    test_seconds: float = 0.5

    @property
    def n_body(self) -> int:
        return len(self.parts)

    @property
    def inertias(self) -> tuple:
        """Each part's moment of inertia about its COM [kg m^2] (its solid shape's)."""
        return tuple(inertia(p) for p in self.parts)

    @property
    def pinned(self) -> set:
        """Bodies that a pin names: they touch nothing (bridges, chains)."""
        return {int(b) for pin in self.pins for b in pin[:2] if b >= 0}


def builder_shape(shape) -> tuple:
    """A Part's shape as ModelBuilder.add_shape takes it (kind, *params), centred at (0, 0)."""
    kind = shape[0]
    if kind == "box":
        return ("box", (0.0, 0.0), float(shape[1]), float(shape[2]))
    if kind == "circle":
        return ("circle", (0.0, 0.0), float(shape[1]))
    if kind == "capsule":
        half = float(shape[1])
        return ("capsule", (-half, 0.0), (half, 0.0), float(shape[2]))
    raise ValueError(f"unknown shape kind {kind!r}")


def inertia(part: Part) -> float:
    """Moment of inertia [kg m^2] about the COM of the part's solid shape of its mass."""
    kind, *params = builder_shape(part.shape)
    area, _, j = shape_area(kind, params)
    return part.mass * j / area


# ---- scenes -------------------------------------------------------------------------------
def arc_points(n, length, sag):
    """n + 1 points of a circular arc [m] whose n chords are each `length` long, the ends at
    the same height and the middle `sag` below them; the first point at x = 0, y = 0."""
    def sag_of(radius):
        half = n * math.asin(length / (2 * radius))
        return radius * (1 - math.cos(half))
    lo, hi = n * length / math.pi / 2 * 1.0001, 1e9          # sag falls as the radius grows
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if sag_of(mid) > sag else (lo, mid)
    radius = math.sqrt(lo * hi)
    step = 2 * math.asin(length / (2 * radius))
    start = -math.pi / 2 - n * step / 2
    centre = (-radius * math.cos(start), -radius * math.sin(start))
    return [(centre[0] + radius * math.cos(start + k * step), centre[1] + radius * math.sin(start + k * step))
            for k in range(n + 1)]


def pinned_chain(name, points, shape, mass, ends_pinned):
    """Parts along a polyline (one per segment, centred on it, turned along it) and the pins
    joining them at the points: the first point to the world, and the last if ends_pinned."""
    parts, pins = [], []
    for k, (p, q) in enumerate(zip(points[:-1], points[1:])):
        angle = math.atan2(q[1] - p[1], q[0] - p[0])
        parts.append(Part(f"{name}{k}", ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2), shape, mass, angle))
        pins.append((k - 1, k, p))
    if ends_pinned:
        pins.append((len(parts) - 1, -1, points[-1]))
    return parts, pins


def bridge(n=160, plank=(0.25, 0.05), mass=0.5, sag=2.0):
    """n planks pinned end to end, both ends pinned to the world 10 m up, on a circular arc
    that sags `sag` [m]; sag 0: straight and taut, Box2D's own bridge (the planks span the
    gap exactly)."""
    points = arc_points(n, plank[0], sag) if sag > 0 else [(k * plank[0], 0.0) for k in range(n + 1)]
    points = [(x, y + 10.0) for x, y in points]
    parts, pins = pinned_chain("plank", points, ("box",) + plank, mass, ends_pinned=True)
    return Scene(f"bridge{n}" + ("" if sag > 0 else "_taut"), tuple(parts), tuple(pins), ground=False,
                 seconds=1.0, test_seconds=0.3)


def chain_ball(n=40, link=0.25, link_mass=0.5, radius=0.4, ratio=100.0):
    points = [(k * link, 10.0) for k in range(n + 1)]
    parts, pins = pinned_chain("link", points, ("capsule", link / 2, 0.02), link_mass, ends_pinned=False)
    end = points[-1]
    parts.append(Part("ball", (end[0] + radius, end[1]), ("circle", radius), ratio * link_mass))
    pins.append((n - 1, n, end))
    return Scene("chain_ball", tuple(parts), tuple(pins), ground=False, seconds=1.0, test_seconds=0.5)


def resting_grid(rows, size, mass, gap, base=0.0):
    """Cubes `size` [m] in rows of len(rows) levels: rows[k] cubes on level k, centred on
    x = 0, `gap` apart in a row, each level resting exactly on the one below."""
    parts = []
    for level, count in enumerate(rows):
        for j in range(count):
            x = (j - (count - 1) / 2) * (size + gap)
            parts.append(Part(f"box{len(parts)}", (x, base + size / 2 + level * size), ("box", size, size), mass))
    return parts


def stack(n=20, size=0.2, mass=1.0):
    return Scene(f"stack{n}", tuple(resting_grid([1] * n, size, mass, 0.0)), resting=True,
                 seconds=1.0, test_seconds=0.5)


def pyramid(rows=10, size=0.2, mass=1.0, gap=0.02):
    return Scene(f"pyramid{rows * (rows + 1) // 2}",
                 tuple(resting_grid(range(rows, 0, -1), size, mass, gap)), resting=True,
                 seconds=1.0, test_seconds=0.5)


def mass_ratio(ratio=100.0, small=0.2, big=(1.2, 0.4), n_small=3, mass=1.0):
    parts = [Part(f"small{k}", ((k - (n_small - 1) / 2) * (big[0] - small) / (n_small - 1), small / 2),
                  ("box", small, small), mass) for k in range(n_small)]
    parts.append(Part("heavy", (0.0, small + big[1] / 2), ("box",) + big, ratio * mass))
    return Scene("mass_ratio", tuple(parts), resting=True, seconds=1.0, test_seconds=0.5)


def leaning_pair(x0, y0, length, thickness, lean, steep):
    """Two cards [m] leaning on each other, standing on the line y = y0 from x = x0 on: the left
    one leans right by `lean` [rad] from vertical, its top inner corner on the face of the
    right one, which leans left by `steep` < `lean` and so reaches higher. Returns the two
    (centre, angle) of cards upright at angle 0, the right card's foot x and the highest
    point (x, y) of the pair (the right card's top outer corner)."""
    t, half = thickness, length / 2
    # left card turned by -lean: its lowest corner is its bottom-right (inner) one
    left_c = (x0 + half * math.sin(lean) - t / 2 * math.cos(lean),
              y0 + half * math.cos(lean) + t / 2 * math.sin(lean))
    top = (x0 + length * math.sin(lean), y0 + length * math.cos(lean))     # its top inner corner
    # right card turned by +steep: its inner face runs from its foot (foot, y0) up-left
    s = length * math.cos(lean) / math.cos(steep)     # where along that face the corner rests
    foot = top[0] + s * math.sin(steep)
    right_c = (foot - half * math.sin(steep) + t / 2 * math.cos(steep),
               y0 + half * math.cos(steep) + t / 2 * math.sin(steep))
    peak = (foot + t * math.cos(steep) - length * math.sin(steep),      # its top outer corner
            y0 + t * math.sin(steep) + length * math.cos(steep))
    return (left_c, -lean), (right_c, steep), foot - x0, peak


def card_house(levels=3, length=0.4, thickness=0.004, mass=0.01, lean=0.45, steep=0.43, spread=0.03,
               overhang=0.05):
    """Levels of A's (levels, levels - 1, ... 1 of them), `spread` [m] between one A's right foot
    and the next one's left foot; on each level of two or more A's a flat card (a floor as
    long as the A's peaks are apart plus `overhang` at each end, its mass in proportion)
    resting on all their peaks, the next level's A's standing on it, centred."""
    parts = []

    def add(center, angle, size):
        parts.append(Part(f"card{len(parts)}", center, ("box", thickness, size),
                          mass * size / length, angle))
    x0, y0 = 0.0, 0.0
    for level in range(levels):
        n = levels - level
        peaks = []
        for k in range(n):
            left, right, span, peak = leaning_pair(x0, y0, length, thickness, lean, steep)
            add(*left, length)
            add(*right, length)
            peaks.append(peak)
            x0 += span + spread
        if n == 1:
            break
        floor = peaks[-1][0] - peaks[0][0] + 2 * overhang
        middle = (peaks[0][0] + peaks[-1][0]) / 2
        add((middle, peaks[0][1] + thickness / 2), math.pi / 2, floor)
        x0 = middle - ((n - 1) * (span + spread) - spread) / 2
        y0 = peaks[0][1] + thickness
    return Scene("card_house", tuple(parts), resting=True, mu=0.8, seconds=1.0, test_seconds=0.5)


def dominoes(n=20, w=0.02, h=0.2, mass=0.1, spacing=0.1, omega=-4.0):
    parts = []
    for k in range(n):
        # the first turns about its front foot F = COM + (w/2, -h/2): v = omega z x (COM - F)
        first = k == 0
        parts.append(Part(f"domino{k}", (k * spacing, h / 2), ("box", w, h), mass,
                          vel=(-omega * h / 2, -omega * w / 2) if first else (0.0, 0.0),
                          omega=omega if first else 0.0))
    return Scene(f"dominoes{n}", tuple(parts), seconds=1.0, test_seconds=0.5)


def pour(n=50, columns=5, radius=0.05, capsule=(0.05, 0.04), mass=0.2, width=1.2, wall=0.1):
    """Circles and capsules alternating in a grid 0.25 m apart above a U of three static
    boxes: a floor (width x wall) at y = 0 and two walls 1 m tall."""
    statics = (((0.0, -wall / 2), width + 2 * wall, wall),
               ((-(width + wall) / 2, 0.5), wall, 1.0),
               ((+(width + wall) / 2, 0.5), wall, 1.0))
    parts = []
    for k in range(n):
        row, col = divmod(k, columns)
        shape = ("circle", radius) if k % 2 == 0 else ("capsule",) + capsule
        x = (col - (columns - 1) / 2) * 0.22 + 0.03 * (row % 2)
        parts.append(Part(f"bit{k}", (x, 0.3 + 0.25 * row), shape, mass, angle=0.4 * (k % 3)))
    return Scene(f"pour{n}", tuple(parts), statics=statics, ground=False, seconds=1.0, test_seconds=0.5)


STRESS_SCENES = {s.name: s for s in (bridge(), bridge(sag=0.0), chain_ball(), card_house(), mass_ratio(), stack(),
                                     dominoes(), pour(), pyramid())}


# ---- worlds of many boxes at rest (benchmarks/worlds.py's, as scenes the peers build) -------
WORLD_BOX = 0.2      # [m]
WORLD_MASS = 4.0     # [kg] a 0.2 m box of density 100 kg/m^2 (a brick 0.4 m: twice)


def columns(n_columns=10, n_rows=10):
    """n_columns columns of n_rows boxes, 0.4 m apart."""
    parts = [Part(f"box{c}_{r}", (2 * WORLD_BOX * c, WORLD_BOX / 2 + WORLD_BOX * r),
                  ("box", WORLD_BOX, WORLD_BOX), WORLD_MASS)
             for c in range(n_columns) for r in range(n_rows)]
    return Scene(f"columns{n_columns}x{n_rows}", tuple(parts), resting=True, seconds=0.05)


def box_pyramid(rows):
    """rows levels of boxes touching side by side, each on two below."""
    return Scene(f"world_pyramid{rows}",
                 tuple(resting_grid(range(rows, 0, -1), WORLD_BOX, WORLD_MASS, 0.0)),
                 resting=True, seconds=0.05)


def brick_wall(n_columns=40, n_rows=10):
    """A staggered wall of 0.4 x 0.2 m bricks: odd rows shifted by half a brick."""
    parts = [Part(f"brick{r}_{c}", (2 * WORLD_BOX * c + (WORLD_BOX if r % 2 else 0.0),
                                    WORLD_BOX / 2 + WORLD_BOX * r),
                  ("box", 2 * WORLD_BOX, WORLD_BOX), 2 * WORLD_MASS)
             for r in range(n_rows) for c in range(n_columns)]
    return Scene(f"wall{n_columns}x{n_rows}", tuple(parts), resting=True, seconds=0.05)


#: the worlds of `planarsim bench --parts worlds`, smallest first (10 to 1,035 bodies)
WORLD_SCENES = {s.name: s for s in (box_pyramid(4), columns(10, 10), box_pyramid(20),
                                    brick_wall(40, 10), box_pyramid(45))}
ALL_SCENES = {**STRESS_SCENES, **WORLD_SCENES}


# ---- planarsim ----------------------------------------------------------------------------
def build_model(scene: Scene):
    """The planarsim Model of the scene."""
    b = ps.ModelBuilder(dt=scene.dt, ground=True if scene.ground else None)
    for p in scene.parts:
        b.add_body(p.name, p.mass, inertia(p), pos=p.pos, angle=p.angle, vel=p.vel, omega=p.omega,
                   shapes=[builder_shape(p.shape) + ({"mu": scene.mu},)])
    for center, w, h in scene.statics:
        b.add_shape(None, "box", center, w, h, mu=scene.mu)
    for j, (a, c, anchor) in enumerate(scene.pins):
        b.add_pin(f"pin{j}", None if a < 0 else a, None if c < 0 else c, anchor_world=anchor)
    return b.compile()


# ---- accuracy -----------------------------------------------------------------------------
def pin_gap(model, q) -> float:
    """Largest distance [m] between the two anchors of any pin over frames q (K, n_body, 3)."""
    from benchmarks.metrics import world_points
    a = model.arrays
    worst = 0.0
    for j in range(model.n_pin):
        pa = world_points(q, a.pin_body[j, 0], a.pin_anchor[j, 0])
        pb = world_points(q, a.pin_body[j, 1], a.pin_anchor[j, 1])
        worst = max(worst, float(np.max(np.hypot(*(pb - pa).T))))
    return worst


def overlap(model, q) -> float:
    """Largest overlap [m] over frames q of any two shapes that may touch (the narrow phase,
    static shapes included) and of any shape below the flat ground y = 0 (its lowest core
    vertex minus its radius: exact for flat ground)."""
    from benchmarks.contact_stress import _overlap_kernel
    from benchmarks.metrics import world_points
    a = model.arrays
    pairs = a.contact_pair[a.contact_kind == 2, :2]
    pairs = np.unique(pairs, axis=0) if len(pairs) else pairs
    worst = np.zeros(q.shape[0])
    if len(pairs):
        # (no covered faces: the shapes' true overlap)
        _overlap_kernel()(a.core_vert, a.core_norm, np.zeros((len(a.core_vert), 8)),
                          a.shape_vert_adr, a.shape_vert_num, a.shape_radius,
                          a.shape_body, np.ascontiguousarray(pairs), np.ascontiguousarray(q), worst,
                          np.zeros((2, 10)))
    deepest = float(np.max(worst))
    if model.terrain is None:
        return deepest
    for s, body in enumerate(a.shape_body):
        if body < 0:
            continue
        core = a.core_vert[a.shape_vert_adr[s]:a.shape_vert_adr[s] + a.shape_vert_num[s]]
        for p in core:
            deepest = max(deepest, float(np.max(a.shape_radius[s] - world_points(q, body, p)[:, 1])))
    return deepest


def rest_drift(q) -> float:
    """Largest distance [m] any body's COM gets from its start over frames q."""
    return float(np.max(np.hypot(q[..., 0] - q[0, :, 0], q[..., 1] - q[0, :, 1])))


def accuracy(scene: Scene, model, q) -> dict:
    """pin_gap_m, overlap_m and (resting scenes) rest_drift_m of recorded frames q."""
    out = {"pin_gap_m": pin_gap(model, q) if model.n_pin else math.nan, "overlap_m": overlap(model, q)}
    out["rest_drift_m"] = rest_drift(q) if scene.resting else math.nan
    return out
