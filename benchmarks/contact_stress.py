"""A seeded stress corpus of closed contact loops through the ground, no actuation (not a test).

    python benchmarks/contact_stress.py                       # 6 families x 40 seeds x 2 strategies
    python benchmarks/contact_stress.py --quick               # seeds 0-4, one strategy each (20 runs)
    python benchmarks/contact_stress.py --families chain_hills --runs-per-family 10
    python benchmarks/contact_stress.py --only chain_hills:7:all --only mass_ratio:3:alternating
    python benchmarks/contact_stress.py --families shape_pile shape_hills --extreme   # beyond the targets

Families (every scene drawn from numpy.random.default_rng(seed); friction mu in [0.2, 1.2]):

- biped_stance: a 5-link biped (torso, two thighs, two shins) on two box feet (two more
  bodies), both feet flat on flat ground (a closed loop through the ground), then random
  joint-angle offsets (sd 0.03 rad), joint rates (sd 0.3 rad/s) and a small torso velocity;
  the lowest corner starts 0 to 1 mm above the ground. No actuators, so it collapses.
- biped_collapse: the 7-link scenes.biped_collapse (feet are bodies too), perturbed
  the same way.
- chain_hills: 16 boxes pinned end to end (0.2-0.35 m long, 0.5-2 kg each), bent at random
  (sd 0.15 rad per pin) and tilted (+-0.4 rad), moving (up to 1 m/s sideways and 2 m/s down,
  pins turning at sd 0.5 rad/s), dropped from 0.05-1 m onto sine hills (terrain.hills: one
  or two sines, slopes up to about 30 deg).
- mass_ratio: two pinned boxes with a mass ratio of 1 to 1000 at most, hitting flat ground at
  10-100 m/s within 60 deg of straight down, tumbling at up to 10 rad/s.

- shape_pile: 4-12 colliding shapes (boxes, capsules, circles, convex polygons of 3-6
  vertices; 2-40 cm) with masses 10^U(-1.5, 1.5) kg (ratios to 1:1000), stacked loosely with
  random offsets and tilts and thrown down at 1-30 m/s (log-uniform; up to 10 rad/s) onto
  each other and flat ground. --extreme: masses 10^U(-2, 2) (1:10^4) and 1-200 m/s.
- shape_hills: the same onto sine hills (slopes up to about 30 deg).
  Depth there is the deepest overlap of any two shapes (the narrow phase, kernels/collide.py,
  tested against an independent reference in tests/physics/test_collide.py) and of any shape
  below the ground (corners and edges sampled every 5 mm, circles by their centre's gap).

Seed k runs at dt = DTS[k % 5] (1e-4 ... 1e-2 s). A run simulates SECONDS[family] (or --seconds) but at most
MAX_STEPS steps, so runs at small dt cover less time. Every run is recorded at every step and
judged on each end-of-step state (and the start):

- energy gained: max over the run of E(t) - E0, E = kinetic + gravitational potential
  (metrics.energy) [J], against the bound E_tol of energy_bound (the integrator's own
  O(dt) oscillation; see there);
- pin gap: metrics.pin_separation, target PIN_TOL = 1e-9 m;
- depth: the deepest box corner below the ground, target DEPTH_TOL = 1e-8 m (flat ground:
  metrics.lowest_point; hills: see clearance);
- divergence: planarsim.SimulationDiverged, or a non-finite state;
- audit: the engine's own violation counters sim.ws.audit (n/a where the engine has none).

Exit status 1 when any run misses a target, else 0.
"""
from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim import terrain  # noqa: E402
from benchmarks.metrics import (energy, lowest_point, pin_separation,  # noqa: E402
                                     spec_from_model, world_points)
from benchmarks.scenes import G, biped_collapse  # noqa: E402

FAMILIES = ("biped_stance", "biped_collapse", "chain_hills", "mass_ratio", "shape_pile",
            "shape_hills")
SHAPE_FAMILIES = ("shape_pile", "shape_hills")   # bodies touching bodies (colliding shapes)
# their masses 10^U(-d, d) kg and launch speeds 1..speed m/s (log-uniform); --extreme widens them
SHAPE_RANGES = {"mass_decades": 1.5, "speed": 30.0}
EXTREME_SHAPE_RANGES = {"mass_decades": 2.0, "speed": 200.0}
STRATEGIES = ("alternating", "all")
DTS = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2)      # [s] step sizes; seed k runs at DTS[k % 5]
SECONDS = {"biped_stance": 2.0, "biped_collapse": 2.0, "chain_hills": 3.0, "mass_ratio": 1.0,
           "shape_pile": 2.0, "shape_hills": 2.0}  # [s]
MAX_STEPS = 3000          # cap on steps per run (dt = 1e-4 s: 0.3 s simulated)
RUNS_PER_FAMILY = 40      # seeds per family of the default corpus
QUICK_RUNS = 5            # seeds per family with --quick (one strategy each, in turn)
PIN_TOL = 1e-9            # [m] largest pin gap allowed at the end of a step
DEPTH_TOL = 1e-8          # [m] largest depth below the ground allowed at the end of a step


# --- start states ------------------------------------------------------------------------------
def box(b, name, mass, w, h, pos, angle, mu):
    """A w x h [m] box of `mass` [kg] (uniform density) with its four corner contacts."""
    body = b.add_body(name, mass, mass * (w * w + h * h) / 12, pos=pos, angle=angle)
    b.add_box_contacts(f"{name}_c", body, (0.0, 0.0), w, h, mu=mu)
    return body


def joint_pose(model, dangle, rates, root_v):
    """Start q (n_body, 3) and v (n_body, 3) of a model whose pins form a tree rooted at body 0,
    listed parent first (body a of each pin is already reached): from the build pose, the
    child side of pin j is turned by dangle[j] [rad] about the pin; then body 0 gets velocity
    root_v = (vx, vy, omega) [m/s, m/s, rad/s] and pin j turns at rates[j] [rad/s]. Pins stay
    closed and the velocities satisfy them."""
    a = model.arrays
    q = np.array(model.q0, dtype=float)
    v = np.zeros_like(q)
    v[0] = root_v
    below = [{int(a.pin_body[j, 1])} for j in range(model.n_pin)]      # subtree of each pin
    for j in reversed(range(model.n_pin)):
        for k in range(j + 1, model.n_pin):
            if int(a.pin_body[k, 0]) in below[j]:
                below[j] |= below[k]
    reached = {0}
    for j in range(model.n_pin):
        pa, pb = (int(x) for x in a.pin_body[j])
        assert pa in reached and pb not in reached, "pins must form a tree from body 0, parent first"
        reached.add(pb)
        p = world_points(q[None], pa, a.pin_anchor[j, 0])[0]
        c, s = math.cos(dangle[j]), math.sin(dangle[j])
        for body in below[j]:
            d = q[body, :2] - p
            q[body, :2] = p + (c * d[0] - s * d[1], s * d[0] + c * d[1])
            q[body, 2] += dangle[j]
    for j in range(model.n_pin):
        pa, pb = (int(x) for x in a.pin_body[j])
        p = world_points(q[None], pa, a.pin_anchor[j, 0])[0]
        ra, rb = p - q[pa, :2], q[pb, :2] - p
        v[pb, 2] = v[pa, 2] + rates[j]
        v[pb, :2] = v[pa, :2] + v[pa, 2] * np.array([-ra[1], ra[0]]) + v[pb, 2] * np.array([-rb[1], rb[0]])
    return q, v


def clearance(spec, ground, q):
    """(K,) smallest height of any box corner above the ground over frames q (K, n_body, 3) [m]
    (negative: below). Level ground at y = 0 is metrics.lowest_point; elsewhere the
    vertical height over the terrain times cos(slope), the distance along the ground normal to
    first order (exact on a line; off by about d^2 x curvature, far below 1e-8 m here)."""
    c = ground.coef
    if c[0] == 0.0 and c[1] == 0.0 and c[2] == 0:
        return lowest_point(spec, q)
    low = np.full(q.shape[0], np.inf)
    for body in range(spec.n_body):
        w, h = spec.box[body]
        for dx in (-w / 2, w / 2):
            for dy in (-h / 2, h / 2):
                x, y = world_points(q, body, (dx, dy)).T
                low = np.minimum(low, (y - ground.height(x)) / np.sqrt(1.0 + ground.slope(x) ** 2))
    return low


def place(model, ground, q, gap):
    """Shift q up so that its lowest box corner is `gap` [m] above the ground."""
    spec = spec_from_model("place", model, 0.0)
    q = q.copy()
    for _ in range(3):   # on a slope, lifting by dy lifts the clearance by dy cos(slope)
        q[:, 1] += gap - clearance(spec, ground, q[None])[0]
    return q


def biped_stance(rng, dt):
    """A 5-link biped on two box feet, both flat on flat ground (pose from two-link inverse
    kinematics, knees forward), torso on top. Returns the model."""
    b = ps.ModelBuilder(dt=dt)
    mu = rng.uniform(0.2, 1.2)
    scale = rng.uniform(0.8, 1.2, size=4)                 # mass factors
    lt, ls = rng.uniform(0.38, 0.46, size=2)              # thigh, shin length [m]
    fw, fh = 0.22, 0.05                                   # foot [m]
    ankle_dx = -0.03                                      # ankle behind the foot's centre [m]
    half = rng.uniform(0.05, 0.2)                         # half the stance width [m]
    hip = np.array([rng.uniform(-0.05, 0.05), fh + rng.uniform(0.82, 0.94) * (lt + ls)])
    lean = rng.uniform(-0.15, 0.15)
    torso = box(b, "torso", 20.0 * scale[0], 0.15, 0.6,
                (hip[0] - 0.3 * math.sin(lean), hip[1] + 0.3 * math.cos(lean)), lean, mu)
    for side, sx in (("L", -1.0), ("R", 1.0)):
        ankle = np.array([sx * half, fh])
        d = ankle - hip
        dist = float(np.hypot(*d))
        # knee on the circle |knee - hip| = lt, |knee - ankle| = ls, on the +x side of hip->ankle
        along = (dist * dist + lt * lt - ls * ls) / (2 * dist)
        out = math.sqrt(max(lt * lt - along * along, 0.0))
        u = d / dist
        knee = hip + along * u + out * np.array([-u[1], u[0]])   # hip->ankle points down: +x
        th_t = math.atan2(knee[0] - hip[0], hip[1] - knee[1])
        th_s = math.atan2(ankle[0] - knee[0], knee[1] - ankle[1])
        thigh = box(b, f"thigh_{side}", 7.0 * scale[1], 0.07, lt, (hip + knee) / 2, th_t, mu)
        shin = box(b, f"shin_{side}", 4.0 * scale[2], 0.06, ls, (knee + ankle) / 2, th_s, mu)
        foot = box(b, f"foot_{side}", 1.0 * scale[3], fw, fh, (ankle[0] - ankle_dx, fh / 2), 0.0, mu)
        b.add_pin(f"hip_{side}", torso, thigh, anchor_world=hip)
        b.add_pin(f"knee_{side}", thigh, shin, anchor_world=knee)
        b.add_pin(f"ankle_{side}", shin, foot, anchor_world=ankle)
    return b.compile()


def chain_hills(rng, dt):
    """16 boxes pinned end to end on sine hills; returns the model (straight, tilted)."""
    n_sines = int(rng.integers(1, 3))
    lam = rng.uniform(2.0, 6.0, size=n_sines)
    amp = rng.uniform(0.2, 1.0, size=n_sines) * 0.09 * lam / n_sines   # slope <= 0.57 (30 deg)
    ground = terrain.hills(amp, lam, rng.uniform(0, 2 * math.pi, size=n_sines))
    b = ps.ModelBuilder(dt=dt, terrain=ground)
    mu = rng.uniform(0.2, 1.2)
    length, height, tilt = rng.uniform(0.2, 0.35), rng.uniform(0.03, 0.08), rng.uniform(-0.4, 0.4)
    e = np.array([math.cos(tilt), math.sin(tilt)])
    x0 = rng.uniform(-2.0, 2.0)
    prev = None
    for i in range(16):
        link = box(b, f"link{i}", rng.uniform(0.5, 2.0), length, height,
                   (x0 + (i + 0.5) * length * e[0], (i + 0.5) * length * e[1]), tilt, mu)
        if prev is not None:
            b.add_pin(f"pin{i}", prev, link, anchor_world=(x0 + i * length * e[0], i * length * e[1]))
        prev = link
    return b.compile()


def mass_ratio(rng, dt):
    """Two boxes pinned end to end (mass ratio 1 to 10^U(0, 3), either one the heavy one) over
    flat ground, the pair turned by a random angle; returns the model."""
    b = ps.ModelBuilder(dt=dt)
    mu = rng.uniform(0.2, 1.2)
    m_a = rng.uniform(0.5, 5.0)
    ratio = 10.0 ** rng.uniform(0.0, 3.0)
    m_b = m_a * ratio if rng.random() < 0.5 else m_a / ratio
    (wa, ha), (wb, hb) = rng.uniform((0.1, 0.05), (0.5, 0.3), size=(2, 2))
    turn = rng.uniform(-math.pi, math.pi)
    e = np.array([math.cos(turn), math.sin(turn)])
    a = box(b, "a", m_a, wa, ha, (0.0, 0.0), turn, mu)
    bb = box(b, "b", m_b, wb, hb, (wa + wb) / 2 * e, turn, mu)
    b.add_pin("pin", a, bb, anchor_world=wa / 2 * e)
    return b.compile()


def _cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def random_shape(rng):
    """(kind, params, mass [kg], inertia [kg m^2]) of a random colliding shape centred on its
    body's COM (uniform density; a polygon's vertices about its centroid)."""
    kind = ("box", "capsule", "circle", "polygon")[int(rng.integers(4))]
    decades = SHAPE_RANGES["mass_decades"]
    mass = 10.0 ** rng.uniform(-decades, decades)
    if kind == "box":
        w, h = rng.uniform(0.02, 0.4, size=2)
        return kind, ((0.0, 0.0), w, h), mass, mass * (w * w + h * h) / 12
    if kind == "circle":
        r = rng.uniform(0.02, 0.2)
        return kind, ((0.0, 0.0), r), mass, 0.5 * mass * r * r
    if kind == "capsule":
        half, r = rng.uniform(0.02, 0.2), rng.uniform(0.01, 0.08)
        return (kind, ((-half, 0.0), (half, 0.0), r), mass,
                mass * ((2 * half) ** 2 / 12 + r * r / 2))
    n = int(rng.integers(3, 7))
    ang = np.sort(rng.uniform(0, 2 * math.pi, size=n))
    rad = rng.uniform(0.05, 0.2, size=n)
    pts = np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=1)
    # keep the convex hull (Andrew's monotone chain), then centre it on its centroid
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
    def half_hull(points):
        out = []
        for p in points:
            while len(out) >= 2 and _cross2(out[-1] - out[-2], p - out[-2]) <= 1e-9:
                out.pop()
            out.append(p)
        return out
    hull = np.array(half_hull(pts)[:-1] + half_hull(pts[::-1])[:-1])
    if len(hull) < 3:
        w = rng.uniform(0.05, 0.3)
        return "box", ((0.0, 0.0), w, w), mass, mass * w * w / 6
    x, y = hull[:, 0], hull[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = cross.sum() / 2
    cx = ((x + np.roll(x, -1)) * cross).sum() / (6 * area)
    cy = ((y + np.roll(y, -1)) * cross).sum() / (6 * area)
    hull = hull - (cx, cy)
    x, y = hull[:, 0], hull[:, 1]
    second = (x * x + x * np.roll(x, -1) + np.roll(x, -1) ** 2
              + y * y + y * np.roll(y, -1) + np.roll(y, -1) ** 2)
    inertia = mass * (cross * second).sum() / (12 * area)
    return kind, ([tuple(p) for p in hull],), mass, inertia


def shape_scene(rng, dt, hills):
    """4-12 random shapes in a loose column over flat ground or sine hills; returns the model
    and the start velocities (n_body, 3)."""
    if hills:
        n_sines = int(rng.integers(1, 3))
        lam = rng.uniform(2.0, 6.0, size=n_sines)
        amp = rng.uniform(0.2, 1.0, size=n_sines) * 0.09 * lam / n_sines
        ground = terrain.hills(amp, lam, rng.uniform(0, 2 * math.pi, size=n_sines))
    else:
        ground = terrain.flat()
    b = ps.ModelBuilder(dt=dt, terrain=ground)
    mu = rng.uniform(0.2, 1.2)
    x0 = rng.uniform(-2.0, 2.0)
    y = ground.height(x0) + 0.45
    v = []
    for k in range(int(rng.integers(4, 13))):
        kind, params, mass, inertia = random_shape(rng)
        b.add_body(f"s{k}", mass, inertia, pos=(x0 + rng.uniform(-0.15, 0.15), y),
                   angle=rng.uniform(-math.pi, math.pi), shapes=[(kind, *params, {"mu": mu})])
        y += 0.45
        speed = 10.0 ** rng.uniform(0.0, math.log10(SHAPE_RANGES["speed"]))
        heading = rng.uniform(-math.pi / 4, math.pi / 4)
        v.append((speed * math.sin(heading), -speed * math.cos(heading), rng.uniform(-10, 10)))
    return b.compile(), np.array(v)


def build(family, seed):
    """(model, ground, q0, v0) of one corpus case; q0, v0 the start state [m, rad, m/s, rad/s]."""
    rng = np.random.default_rng(seed)
    dt = DTS[seed % len(DTS)]       # every five seeds cover every step size
    if family in ("biped_stance", "biped_collapse"):
        model = biped_stance(rng, dt) if family == "biped_stance" else biped_collapse(dt)
        root_v = (rng.normal(0, 0.1), rng.normal(0, 0.1), rng.normal(0, 0.3))
        q, v = joint_pose(model, rng.normal(0, 0.03, model.n_pin), rng.normal(0, 0.3, model.n_pin), root_v)
        gap = rng.uniform(0.0, 1e-3) if rng.random() < 0.5 else 0.0
    elif family == "chain_hills":
        model = chain_hills(rng, dt)
        root_v = (rng.uniform(-1, 1), rng.uniform(-2, 0), rng.normal(0, 0.5))
        q, v = joint_pose(model, rng.normal(0, 0.15, model.n_pin), rng.normal(0, 0.5, model.n_pin), root_v)
        gap = rng.uniform(0.05, 1.0)
    elif family in SHAPE_FAMILIES:
        model, v = shape_scene(rng, dt, family == "shape_hills")
        return model, model.terrain, model.q0.copy(), v
    elif family == "mass_ratio":
        model = mass_ratio(rng, dt)
        speed, heading = rng.uniform(10, 100), rng.uniform(-math.pi / 3, math.pi / 3)
        root_v = (speed * math.sin(heading), -speed * math.cos(heading), rng.uniform(-10, 10))
        q, v = joint_pose(model, rng.uniform(-1.0, 1.0, 1), rng.uniform(-10, 10, 1), root_v)
        gap = rng.uniform(0.01, 0.3)
    else:
        raise ValueError(f"family {family!r} unknown; choose from {', '.join(FAMILIES)}")
    ground = model.terrain
    return model, ground, place(model, ground, q, gap), v


# --- judging -----------------------------------------------------------------------------------
def shape_spec(name, model, seconds):
    """The SceneSpec of a shape scene (masses, inertias; no boxes for the peers)."""
    from benchmarks.metrics import SceneSpec
    a = model.arrays
    nb = model.n_body
    return SceneSpec(name=name, dt=float(a.dt), mass=a.body_mass.copy(),
                     inertia=a.body_inertia.copy(), q0=model.q0.copy(),
                     box=np.full((nb, 2), np.nan), pin_body=a.pin_body.copy(),
                     pin_anchor=a.pin_anchor.copy(), ground=True, seconds=seconds,
                     energy_scale=1.0)


_OVERLAP = None


def _overlap_kernel():
    """A compiled loop over frames and shape pairs: the deepest overlap [m] per frame."""
    global _OVERLAP
    if _OVERLAP is None:
        from numba import njit
        from planarsim.kernels._jit import _OPTIONS
        from planarsim.kernels.collide import collide

        @njit(**dict(_OPTIONS, cache=False))
        def overlap(vert, norm, adr, num, rad, body, pairs, q, out, scratch):
            for k in range(q.shape[0]):
                worst = 0.0
                for p in range(pairs.shape[0]):
                    sa = pairs[p, 0]
                    sb = pairs[p, 1]
                    ba = body[sa]
                    bb = body[sb]
                    xa, ya, ca, sna = 0.0, 0.0, 1.0, 0.0
                    xb, yb, cb, snb = 0.0, 0.0, 1.0, 0.0
                    if ba >= 0:
                        xa, ya = q[k, ba, 0], q[k, ba, 1]
                        ca, sna = np.cos(q[k, ba, 2]), np.sin(q[k, ba, 2])
                    if bb >= 0:
                        xb, yb = q[k, bb, 0], q[k, bb, 1]
                        cb, snb = np.cos(q[k, bb, 2]), np.sin(q[k, bb, 2])
                    n = collide(vert, norm, adr[sa], num[sa], rad[sa], xa, ya, ca, sna,
                                adr[sb], num[sb], rad[sb], xb, yb, cb, snb, 0.0, scratch)
                    for j in range(n):
                        worst = max(worst, -scratch[j, 8])
                out[k] = worst
        _OVERLAP = overlap
    return _OVERLAP


def shape_clearance(model, q):
    """(K,) smallest clearance [m] over frames q of a shape scene (negative: overlap): every
    pair of shapes that may touch (the narrow phase at each frame) and every shape against
    the ground (polygon and capsule edges sampled every 5 mm, a circle or capsule by the
    distance of its core from the ground minus its radius, to first order in the slope)."""
    a = model.arrays
    ground = model.terrain
    pairs = a.contact_pair[(a.contact_kind == 2) & (a.contact_pair[:, 2] == 0), :2].copy()
    worst = np.zeros(q.shape[0])
    if len(pairs):
        _overlap_kernel()(a.core_vert, a.core_norm, a.shape_vert_adr, a.shape_vert_num,
                          a.shape_radius, a.shape_body, np.ascontiguousarray(pairs),
                          np.ascontiguousarray(q), worst, np.zeros((2, 10)))
    low = -worst
    for s in range(len(a.shape_body)):
        body = a.shape_body[s]
        if body < 0:
            continue
        core = a.core_vert[a.shape_vert_adr[s]:a.shape_vert_adr[s] + a.shape_vert_num[s]]
        edges = [(core[k], core[(k + 1) % len(core)]) for k in range(len(core))]
        pts = [core[0]] if len(core) == 1 else []
        for p0, p1 in edges:
            n = max(2, int(np.hypot(*(p1 - p0)) / 0.005) + 1)
            pts.extend(p0 + (p1 - p0) * u for u in np.linspace(0.0, 1.0, n))
        for p in pts:
            x, y = world_points(q, body, p).T
            low = np.minimum(low, ground_distance(ground, x, y) - a.shape_radius[s])
    return low


def ground_distance(ground, x, y, iters=12):
    """Signed distance [m] of the points (x, y) from the ground curve (negative: below),
    by Newton on the foot point x' (d/dx' of |(x', h(x')) - (x, y)|^2 / 2 = 0), from x' = x;
    exact for points within a fraction of the curvature radius (all that depth needs)."""
    xs = np.array(x, dtype=float)
    c = ground.coef
    for _ in range(iters):
        h, dh, ddh = ground.height(xs), ground.slope(xs), 0.0 * xs
        for k in range(int(c[2])):
            a, w, phi = c[3 + 3 * k], 2 * math.pi / c[4 + 3 * k], c[5 + 3 * k]
            ddh = ddh - a * w * w * np.sin(w * xs + phi)
        f = (xs - x) + (h - y) * dh
        df = 1.0 + dh * dh + (h - y) * ddh
        xs = xs - f / np.where(np.abs(df) > 1e-12, df, 1e-12)
    d = np.hypot(xs - x, ground.height(xs) - y)
    return np.where(y >= ground.height(x), d, -d)


def energy_bound(spec, ground, q0, v0):
    """E_tol [J]: how far symplectic Euler's own energy error may take a dissipative run above E0.

    With v' = v + dt g + M^-1 J^T lambda and q' = q + dt v' (gravity g the only force), a
    step changes E = kinetic + potential by exactly (dt / 2) g (p_y' - p_y) plus the work of
    the impulses lambda (p_y = sum m v_y, vertical momentum [kg m/s]). Contacts can only take
    energy out; pins (and the position correction) do O(dt) work, measured in free flight
    (this corpus with its contacts disabled, 1 s): at most 0.2 % of E_tol. So
    E(t) - E0 <= (dt / 2) g (p_y(t) - p_y(0)), and p_y can rise by at most M |v_y0| (the start's
    fall stopped) plus M |v_com| <= sqrt(2 M (E0 - V_floor)) (all energy above the floor
    V_floor = M g y_floor turned into upward motion; y_floor the lowest ground height [m]):
        E_tol = (dt / 2) g (M |v_y0| + sqrt(2 M (E0 - V_floor))).
    """
    m = spec.mass
    total = float(m.sum())
    c = ground.coef
    y_floor = c[0] - sum(abs(c[3 + 3 * k]) for k in range(int(c[2])))
    e0 = float(energy(spec, q0[None], v0[None])[0])
    vy0 = abs(float(np.sum(m * v0[:, 1]))) / total
    up = total * vy0 + math.sqrt(2.0 * total * max(e0 - G * total * y_floor, 0.0))
    return 0.5 * spec.dt * G * up


def audit_names(n):
    """Names of the engine's audit counters (kernels.audit.AUDIT_NAMES when it exists)."""
    try:
        from planarsim.kernels.audit import AUDIT_NAMES
        if len(AUDIT_NAMES) == n:
            return tuple(AUDIT_NAMES)
    except ImportError:
        pass
    return tuple(f"audit{k}" for k in range(n))


def run_case(family, seed, strategy, seconds=None, max_steps=MAX_STEPS) -> dict:
    """Build case (family, seed), run it under `strategy` for `seconds` [s] (default
    SECONDS[family]) but at most `max_steps` steps, recording every step, and judge it.

    Returns a dict: family, seed, strategy, dt [s], steps, e0 [J], gain [J] (max E - E0),
    e_tol [J], pin [m], depth [m] (>= 0), diverged ('' or the message), audit (dict of counts,
    or None when the engine has no ws.audit), wall [s], failed (list of missed targets).
    """
    t_start = time.perf_counter()
    model, ground, q0, v0 = build(family, seed)
    dt = model.dt
    steps = min(int(round((SECONDS[family] if seconds is None else seconds) / dt)), max_steps)
    spec = (shape_spec(family, model, steps * dt) if family in SHAPE_FAMILIES
            else spec_from_model(family, model, steps * dt))
    sim = ps.Simulator(model, ps.make_options(strategy), ps.make_state(model, q0, v0))
    out = dict(family=family, seed=seed, strategy=strategy, dt=dt, steps=steps,
               e0=float(energy(spec, q0[None], v0[None])[0]), e_tol=energy_bound(spec, ground, q0, v0),
               gain=math.nan, pin=math.nan, depth=math.nan, diverged="")
    try:
        traj = sim.run(n_steps=steps, record_every=1)   # frames: the start, then steps 1..steps
        q, v = traj.q, traj.v
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
            out["diverged"] = "non-finite state"
        else:
            out["gain"] = float(np.max(energy(spec, q, v) - out["e0"]))
            out["pin"] = pin_separation(spec, q)
            low = (shape_clearance(model, q) if family in SHAPE_FAMILIES
                   else clearance(spec, ground, q))
            out["depth"] = max(0.0, -float(np.min(low)))
    except ps.SimulationDiverged as exc:
        out["diverged"] = str(exc).splitlines()[0][:160]
    counts = getattr(sim.ws, "audit", None)
    out["audit"] = None if counts is None else dict(zip(audit_names(len(counts)), (int(c) for c in counts)))
    out["failed"] = [name for name, bad in (
        ("energy", out["gain"] > out["e_tol"]), ("pin", out["pin"] > PIN_TOL),
        ("depth", out["depth"] > DEPTH_TOL), ("diverged", bool(out["diverged"])),
        ("audit", out["audit"] is not None and sum(out["audit"].values()) > 0)) if bad]
    out["wall"] = time.perf_counter() - t_start
    return out


def corpus(quick=False, families=FAMILIES, runs_per_family=None, strategy="both"):
    """The cases [(family, seed, strategy)]: seeds 0..n-1 of each family (n = runs_per_family,
    default RUNS_PER_FAMILY) under each strategy; quick: n = QUICK_RUNS (one of each dt) and,
    for "both", the strategies in turn (seed even: alternating, odd: all)."""
    n = runs_per_family if runs_per_family is not None else (QUICK_RUNS if quick else RUNS_PER_FAMILY)
    if strategy != "both":
        return [(f, seed, strategy) for f in families for seed in range(n)]
    if quick:
        return [(f, seed, STRATEGIES[seed % 2]) for f in families for seed in range(n)]
    return [(f, seed, s) for f in families for seed in range(n) for s in STRATEGIES]


def _run(case_seconds):
    case, seconds = case_seconds
    return run_case(*case, seconds=seconds)


def run_all(cases, seconds=None, jobs=2):
    """run_case over cases, on `jobs` processes (forked after compiling in this one)."""
    run_case(*cases[0], seconds=1e-2)                # compile (or load) the step once, here
    work = [(c, seconds) for c in cases]
    if jobs <= 1 or len(cases) < 2:
        return [_run(w) for w in work]
    with multiprocessing.get_context("fork").Pool(jobs) as pool:
        return pool.map(_run, work, chunksize=1)


# --- report ------------------------------------------------------------------------------------
def _worst(values):
    values = [x for x in values if not math.isnan(x)]
    return max(values) if values else math.nan


def report(results, n_worst=8) -> bool:
    """Print one line per family (runs, runs missing any target, runs above E0 + E_tol, ...)
    and the worst runs; True when every run meets every target."""
    print(f"targets: energy gained <= E_tol (energy_bound), pin gap <= {PIN_TOL:g} m, depth <= "
          f"{DEPTH_TOL:g} m, no divergence, no audit violation")
    head = (f"{'family':15s} {'runs':>4s} {'miss':>4s} {'>E0':>4s} {'worst gain J (of E0)':>21s} {'pin gap m':>9s} "
            f"{'depth m':>9s} {'div':>4s} {'audit':>6s}  E_tol [J] (of E0)")
    print(head)
    print("-" * len(head))
    for family in dict.fromkeys(r["family"] for r in results):
        rs = [r for r in results if r["family"] == family]
        above = [r for r in rs if "energy" in r["failed"]]
        gain = max(rs, key=lambda r: -math.inf if math.isnan(r["gain"]) else r["gain"])
        audits = [r["audit"] for r in rs if r["audit"] is not None]
        audit = "n/a" if not audits else str(sum(sum(a.values()) for a in audits))
        tol = [r["e_tol"] for r in rs]
        share = [r["e_tol"] / r["e0"] for r in rs if r["e0"] > 0]
        print(f"{family:15s} {len(rs):4d} {sum(bool(r['failed']) for r in rs):4d} {len(above):4d} "
              f"{gain['gain']:10.3g} ({gain['gain'] / gain['e0']:8.2g}) "
              f"{_worst(r['pin'] for r in rs):9.2g} {_worst(r['depth'] for r in rs):9.2g} "
              f"{sum(bool(r['diverged']) for r in rs):4d} {audit:>6s}  {min(tol):.2g}..{max(tol):.2g} "
              f"({min(share):.1g}..{max(share):.1g})")
        if audits:
            kinds = {k: sum(a[k] for a in audits) for k in audits[0]}
            print(f"{'':15s} audit by rule: " + ", ".join(f"{k} {n}" for k, n in kinds.items()))
    bad = [r for r in results if r["failed"]]
    if bad:
        def badness(r):
            ratios = [r["gain"] / r["e_tol"], r["pin"] / PIN_TOL, r["depth"] / DEPTH_TOL]
            worst = max((x for x in ratios if not math.isnan(x)), default=0.0)
            return bool(r["diverged"]), len(r["failed"]), worst
        print(f"worst runs (of {len(bad)} missing a target; rerun one with --only family:seed:strategy):")
        for r in sorted(bad, key=badness, reverse=True)[:n_worst]:
            audit = "n/a" if r["audit"] is None else {k: n for k, n in r["audit"].items() if n}
            print(f"  {r['family']}:{r['seed']}:{r['strategy']}  dt={r['dt']:g} s x {r['steps']}  "
                  f"gain {r['gain']:.3g} J (E_tol {r['e_tol']:.2g})  pin {r['pin']:.2g} m  "
                  f"depth {r['depth']:.2g} m  audit {audit}  misses {'/'.join(r['failed'])}"
                  + (f"  [{r['diverged']}]" if r["diverged"] else ""))
    return not bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--families", nargs="+", choices=FAMILIES, default=list(FAMILIES))
    ap.add_argument("--runs-per-family", type=int, default=None,
                    help=f"seeds per family (default {RUNS_PER_FAMILY}, {QUICK_RUNS} with --quick)")
    ap.add_argument("--quick", action="store_true", help="a small subset")
    ap.add_argument("--strategy", choices=("alternating", "all", "both"), default="both")
    ap.add_argument("--seconds", type=float, default=None,
                    help=f"simulated time per run [s] (default per family {SECONDS}); "
                         f"at most {MAX_STEPS} steps")
    ap.add_argument("--only", action="append", default=[], metavar="FAMILY:SEED:STRATEGY",
                    help="run just these cases (repeatable)")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1), help="processes")
    ap.add_argument("--extreme", action="store_true",
                    help="shape families at mass ratios to 1:10^4 and speeds to 200 m/s")
    args = ap.parse_args(argv)
    if args.extreme:
        SHAPE_RANGES.update(EXTREME_SHAPE_RANGES)
    if args.only:
        cases = []
        for text in args.only:
            family, seed, strategy = text.split(":")
            if family not in FAMILIES or strategy not in STRATEGIES:
                ap.error(f"--only {text!r}: want family:seed:strategy, family in {FAMILIES}, "
                         f"strategy in {STRATEGIES}")
            cases.append((family, int(seed), strategy))
    else:
        cases = corpus(args.quick, args.families, args.runs_per_family, args.strategy)
    t0 = time.perf_counter()
    results = run_all(cases, args.seconds, args.jobs)
    wall = time.perf_counter() - t0
    ok = report(results)
    busy = sum(r["wall"] for r in results)
    print(f"{len(results)} runs in {wall:.1f} s wall, compile or cache load included "
          f"({busy:.1f} s of runs on {args.jobs} processes)")
    print("PASS: every run meets every target" if ok else
          f"FAIL: {sum(bool(r['failed']) for r in results)} of {len(results)} runs miss a target (exit 1)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
