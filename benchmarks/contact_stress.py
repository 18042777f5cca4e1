"""A seeded stress corpus of closed contact loops through the ground (not a test); no actuation but in stiff_motors.

    python benchmarks/contact_stress.py                       # 6 families x 40 seeds x 2 strategies
    python benchmarks/contact_stress.py --quick               # seeds 0-4, one strategy each (30 runs)
    python benchmarks/contact_stress.py --families chain_hills --runs-per-family 10
    python benchmarks/contact_stress.py --only chain_hills:7:all --only mass_ratio:3:alternating
    python benchmarks/contact_stress.py --families shape_pile shape_hills --extreme   # beyond the targets
    python benchmarks/contact_stress.py --families extremes --runs-per-family 40 --jobs 1
    python benchmarks/contact_stress.py --families loop_inertia hills_fast ranger_loop stiff_motors

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
  Depth there is the deepest overlap of any two shapes (the narrow phase, kernels/geometry/collide.py,
  tested against an independent reference in tests/physics/test_collide.py) and of any shape
  below the ground (corners and edges sampled every 5 mm, circles by their centre's gap).

Beyond the corpus (EXTREME_FAMILIES, run only when --families names them; `extremes` names
all four; not in the default run, --quick or its test):

- loop_inertia: a free four-bar: four bars (boxes with corner contacts, 0.2-1 m) pinned end to
  end and closed, standing upright 0-0.3 m over flat ground, unactuated. Its inertias are
  10^U(-4, 4) kg m^2 and its masses 10^U(-1, 1) kg, each drawn on its own (radii of gyration
  from 3 mm to 300 m). 40 % of the loops are parallelograms and 30 % kites (lengths that fold
  flat: every bar on the ground, the pin rows dependent), the rest any convex quadrilateral.
  Start velocities: random bar velocities (sd 0.5 m/s, 2 rad/s) with the part that would open
  a pin removed (loop_velocity). Even seeds run at LOOP_DT = 2e-3 s, odd seeds at every DTS in
  turn. What it exposes: energy rising by orders of magnitude while the pins stay closed and
  every audit count is 0.
- hills_fast: four point masses, or three pairs of point masses joined by a rod (0.1-1 m;
  seeds 5-9, 15-19, ...: pairs), 0.1-10 kg, over steep sine hills (one or two sines of
  wavelength 0.3-2 m, the steepest slope 30-60 deg), 1 cm to 2 m above them, thrown at 1-200
  m/s (log-uniform) within 85 deg of straight down (pairs turning at up to 20 rad/s). Point
  contacts on point masses (continuous collision detection). Depth is each point's signed
  distance from the ground curve at every frame (ground_gap); tunnel (see below) the deepest
  point of its path inside a free step. What it exposes: tunnelling and rod pairs' energy jumps.
- ranger_loop: a Ranger-like four-body loop, unactuated and without springs: two legs (0.8-1.1
  m, 3-7 kg) pinned at a hip, each with a light foot (10-300 g) pinned at an ankle with joint
  limits (-U(0.05, 0.6), U(0.05, 0.6)) rad about the build pose, each foot on a circular-arc
  sole (add_arc_contact: radius 0.15-0.3 m, centre 0.08-0.14 m above the ankle, span about
  Ranger's, heel and top vertices) standing on flat ground (a closed loop through the ground),
  then random pin rates (sd 1 rad/s) and leg velocity. Depth is each sole's lowest point
  (contact_clearance). What it exposes: single steps that gain energy where a sliding sole
  meets an ankle leaving its limit (each run's worst step is noted: slide, limit left).
- stiff_motors: a chain of 3-6 boxes (0.5-3 kg, 0.2-0.5 m) pinned end to end, bent, on flat
  ground (seeds 0, 1 mod 4), or biped_stance's 7-body tree on box feet (seeds 2, 3 mod 4), a
  pin motor on every pin saturated at 10^U(2, 3) N m, driven bang-bang at that torque, the
  sign flipping every 1-5 steps (per motor, seeded: commands()), at dt MOTOR_DTS[k % 2] = 1e-2
  or 2e-2 s. The runner applies the commands each step (sim.step(u)). Motors do work, so there
  is no energy target: its runs are judged by pin gap, depth, divergence, audit and speed, a
  body faster than the motors' torque limits can make it (motor_speed_ratio > 1). Its gain
  column is the energy gained beyond the motors' work (motor_work), for information. What
  it exposes: blow-ups (pins opening by metres, bodies at hundreds of m/s) that nothing stops.

The extreme families are stepped one step at a time (run_extreme_case), so that the frames
before an engine error are judged too, and add three targets: step, the largest energy change
of a single step beyond its own gravity term, dE - (dt / 2) g dp_y (the exact change of a step
without impulses; see energy_bound) and the motors' work, against the run's whole E_tol
(contacts only take energy out), less the joints' second-order share of the step's kinetic
energy (CONSTRAINT_SHARE, kernels/checks/work.py: an oscillation the energy target bounds over the
run; or, where more, what the same step gains with no ground, contact_free_gain: a rod
spinning at w gains about (h w)^2 / 4 of its kinetic energy a step by the integrator alone);
tunnel (hills_fast) above DEPTH_TOL, beyond rod_sag for a point on a rod; speed (stiff_motors). A run the engine stops with an
error of its own (planarsim's SimulationDiverged or any planarsim error, naming why) is
"raised"; a run missing a target without one is "silent" (an audit count alone is silent:
nothing stopped the run). The summary gives both per family, the silent misses by cause and
the audit counts by rule.

Seed k runs at dt = DTS[k % 5] (1e-4 ... 1e-2 s) unless its family says otherwise. A run
simulates SECONDS[family] (or --seconds) but at most MAX_STEPS steps, so runs at small dt
cover less time. Every run is recorded at every step and
judged on each end-of-step state (and the start):

- energy gained: max over the run of E(t) - E0, E = kinetic + gravitational potential
  (metrics.energy) [J], against the bound E_tol of energy_bound (the integrator's own
  O(dt) oscillation; see there);
- pin gap: metrics.pin_separation, target PIN_TOL = 1e-9 m;
- depth: the deepest box corner below the ground, target DEPTH_TOL = 1e-8 m (flat ground:
  metrics.lowest_point; hills: see clearance);
- divergence: planarsim.SimulationDiverged, or a non-finite state;
- jump: each step's path, not only its end: every body's centre of mass moves at most
  h max(|v_start|, |v_end|) + JUMP_SLACK (1 cm) in a step of h (path_excess; a step that
  ends on the surface after passing through a hill, or after a correction that pushed a body
  metres along a turned normal, misses it); a step the engine took in parts (time-of-impact
  splits, turn sub-steps) is judged part by part (inside it a body moves at its parts'
  velocities, which may exceed both ends': displacement.parted_step_excess);
- audit: the engine's own violation counters sim.ws.audit (n/a where the engine has none).

Each family's line also counts the runs the engine stopped with an error ('raise') and the
runs missing a target without one ('silent').

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
from planarsim import dense, terrain  # noqa: E402
from benchmarks.metrics import (energy, kinetic, lowest_point, pin_separation,  # noqa: E402
                                     spec_from_model, world_points)
from benchmarks.scenes import G, biped_collapse  # noqa: E402
from benchmarks.displacement import SLACK as JUMP_SLACK, parted, step_excess  # noqa: E402
from planarsim.kernels.checks.work import CONSTRAINT_SHARE  # noqa: E402

FAMILIES = ("biped_stance", "biped_collapse", "chain_hills", "mass_ratio", "shape_pile",
            "shape_hills")
# beyond the default corpus (selected with --families): see the module docstring
EXTREME_FAMILIES = ("loop_inertia", "hills_fast", "ranger_loop", "stiff_motors")
ALL_FAMILIES = FAMILIES + EXTREME_FAMILIES
SHAPE_FAMILIES = ("shape_pile", "shape_hills")   # bodies touching bodies (colliding shapes)
# their masses 10^U(-d, d) kg and launch speeds 1..speed m/s (log-uniform); --extreme widens them
SHAPE_RANGES = {"mass_decades": 1.5, "speed": 30.0}
EXTREME_SHAPE_RANGES = {"mass_decades": 2.0, "speed": 200.0}
STRATEGIES = ("alternating", "all")
DTS = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2)      # [s] step sizes; seed k runs at DTS[k % 5]
SECONDS = {"biped_stance": 2.0, "biped_collapse": 2.0, "chain_hills": 3.0, "mass_ratio": 1.0,
           "shape_pile": 2.0, "shape_hills": 2.0, "loop_inertia": 4.0, "hills_fast": 2.0,
           "ranger_loop": 2.0, "stiff_motors": 2.0}  # [s]
LOOP_DT = 2e-3            # [s] loop_inertia's step at even seeds
MOTOR_DTS = (1e-2, 2e-2)  # [s] stiff_motors' steps: seed k runs at MOTOR_DTS[k % 2]
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


def biped_stance(rng, dt, motor_torques=None):
    """A 5-link biped on two box feet, both flat on flat ground (pose from two-link inverse
    kinematics, knees forward), torso on top. Returns the model. motor_torques (6,) [N m]: a
    pin motor on each pin (hip, knee, ankle of L then R) saturated at +-motor_torques[j]."""
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
    if motor_torques is not None:
        for j, pin in enumerate(("hip_L", "knee_L", "ankle_L", "hip_R", "knee_R", "ankle_R")):
            b.add_pin_motor(f"{pin}_motor", pin, limit=(-motor_torques[j], motor_torques[j]))
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


# --- the extreme families (EXTREME_FAMILIES) ---------------------------------------------------
def loop_velocity(model, q, v):
    """v (n_body, 3) with its pin-violating part removed: the least-squares change of v that
    makes every pin's two anchor points move together at q (closed loops included)."""
    a = model.arrays
    rows = []
    for j in range(model.n_pin):
        row = np.zeros((2, 3 * model.n_body))
        for side, sign in ((0, -1.0), (1, 1.0)):
            body = int(a.pin_body[j, side])
            if body < 0:
                continue
            r = world_points(q[None], body, a.pin_anchor[j, side])[0] - q[body, :2]
            row[:, 3 * body:3 * body + 2] += sign * np.eye(2)
            row[:, 3 * body + 2] += sign * np.array([-r[1], r[0]])
        rows.append(row)
    jac = np.vstack(rows)
    flat = v.reshape(-1)
    # (planarsim.dense: the same bits on every CPU, where numpy's BLAS kernels differ)
    flat = flat - dense.matmul(jac.T, dense.solve(dense.matmul(jac, jac.T), dense.matmul(jac, flat)))
    return flat.reshape(v.shape)


def loop_inertia(rng, dt):
    """A free four-bar: four bars (boxes with corner contacts) pinned end to end and closed,
    standing upright over flat ground; inertias 10^U(-4, 4) kg m^2, masses 10^U(-1, 1) kg,
    each drawn on its own. Returns the model."""
    b = ps.ModelBuilder(dt=dt)
    mu = rng.uniform(0.2, 1.2)
    kind = rng.random()
    if kind < 0.7:      # a parallelogram or a kite: lengths that fold flat, every bar on the ground
        la, lb, turn = rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.0), rng.uniform(0.3, math.pi - 0.3)
        tilt = rng.uniform(-0.5, 0.5)
        ea, eb = (np.array([math.cos(tilt + t), math.sin(tilt + t)]) for t in (0.0, turn))
        if kind < 0.4:
            corner = np.array([(0, 0), la * ea, la * ea + lb * eb, lb * eb])
        else:           # kite: la, la, lb, lb about the diagonal from corner 0 to corner 2
            tip = la * ea + la * eb
            far = tip + lb * (tip / np.hypot(*tip))
            side = np.array([-tip[1], tip[0]]) / np.hypot(*tip)
            half = math.sqrt(max(la ** 2 - (np.hypot(*tip) / 2) ** 2, 0.0))
            mid = tip / 2
            corner = np.array([(0.0, 0.0), mid + half * side, far, mid - half * side])
            # sides 0-1 and 3-0 are la; 1-2 and 2-3 are equal (the kite's other pair)
        corner = corner - corner.mean(axis=0) + (0.0, 1.0)
    else:               # a convex quadrilateral of any lengths
        gaps = rng.uniform(0.6, 1.0, size=4)
        ang = rng.uniform(0, 2 * math.pi) + np.cumsum(gaps / gaps.sum() * 2 * math.pi)
        rad = rng.uniform(0.2, 0.6, size=4)
        corner = np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=1) + (0.0, 1.0)
    height = rng.uniform(0.02, 0.06)
    bars = []
    for i in range(4):
        p0, p1 = corner[i], corner[(i + 1) % 4]
        d = p1 - p0
        name = f"bar{i}"
        body = b.add_body(name, 10.0 ** rng.uniform(-1, 1), 10.0 ** rng.uniform(-4, 4),
                          pos=tuple((p0 + p1) / 2), angle=math.atan2(d[1], d[0]))
        b.add_box_contacts(f"{name}_c", body, (0.0, 0.0), float(np.hypot(*d)), height, mu=mu)
        bars.append(body)
    for i in range(1, 4):
        b.add_pin(f"pin{i}", bars[i - 1], bars[i], anchor_world=tuple(corner[i]))
    b.add_pin("pin0", bars[3], bars[0], anchor_world=tuple(corner[0]))   # closes the loop
    return b.compile()


def hills_fast(rng, dt, pairs):
    """Four point masses, or three pairs of point masses joined by a rod, over steep sine
    hills (slopes up to 30-60 deg, wavelengths 0.3-2 m), thrown at the ground at 1-200 m/s.
    Returns the model and the start velocities (n_body, 3)."""
    n_sines = int(rng.integers(1, 3))
    lam = rng.uniform(0.3, 2.0, size=n_sines)
    steepest = math.tan(math.radians(rng.uniform(30.0, 60.0)))
    share = rng.uniform(0.3, 1.0, size=n_sines)
    amp = steepest * share / share.sum() * lam / (2 * math.pi)      # max slope <= steepest
    ground = terrain.hills(amp, lam, rng.uniform(0, 2 * math.pi, size=n_sines))
    b = ps.ModelBuilder(dt=dt, terrain=ground)
    mu = rng.uniform(0.2, 1.2)
    v = []
    for i in range(3 if pairs else 4):
        x = 1.5 * i + rng.uniform(-0.5, 0.5)
        gap = 10.0 ** rng.uniform(-2.0, 0.3)                            # 1 cm .. 2 m
        speed = 10.0 ** rng.uniform(0.0, math.log10(200.0))
        heading = -math.pi / 2 + rng.uniform(-1.48, 1.48)                # within 85 deg of down
        vel = np.array([speed * math.cos(heading), speed * math.sin(heading)])
        if not pairs:
            pos = np.array([x, ground.height(x) + gap])
            body = b.add_point_mass(f"mass{i}", 10.0 ** rng.uniform(-1, 1), pos=tuple(pos), vel=tuple(vel))
            b.add_point_contact(f"mass{i}_c", body, mu=mu)
            v.append((*vel, 0.0))
            continue
        length, turn, rate = rng.uniform(0.1, 1.0), rng.uniform(-math.pi, math.pi), rng.uniform(-20, 20)
        e = np.array([math.cos(turn), math.sin(turn)]) * length / 2     # mid to end 1
        lift = max(ground.height(x + sx * e[0]) + gap - sx * e[1] for sx in (-1.0, 1.0))
        ends = []
        for k, sx in enumerate((-1.0, 1.0)):                            # turning about the mid
            p = np.array([x, lift]) + sx * e
            pv = vel + rate * sx * np.array([-e[1], e[0]])
            body = b.add_point_mass(f"pair{i}_{k}", 10.0 ** rng.uniform(-1, 1), pos=tuple(p), vel=tuple(pv))
            b.add_point_contact(f"pair{i}_{k}_c", body, mu=mu)
            ends.append(body)
            v.append((*pv, 0.0))
        b.add_rod(f"rod{i}", ends[0], ends[1])
    return b.compile(), np.array(v)


def ranger_loop(rng, dt):
    """A Ranger-like four-body loop (see the module docstring), both feet on flat ground;
    returns the model."""
    b = ps.ModelBuilder(dt=dt)
    mu = rng.uniform(0.2, 1.2)
    length, leg_com = rng.uniform(0.8, 1.1), rng.uniform(0.1, 0.3)      # [m] hip to ankle, to COM
    r, d = rng.uniform(0.15, 0.3), rng.uniform(0.08, 0.14)              # sole radius, centre height
    a0, a1 = rng.uniform(-1.9, -1.5), rng.uniform(-1.1, -0.8)           # sole span [rad]
    fx, fy = rng.uniform(0.0, 0.06), rng.uniform(-0.04, 0.0)            # foot COM from the ankle
    # foot angles whose lowest sole point lies inside the span: -pi/2 - phi in (a0, a1)
    phi = rng.uniform(-math.pi / 2 - a1 + 0.05, -math.pi / 2 - a0 - 0.05, size=2)
    th_front = rng.uniform(0.15, 0.4)
    ankle_y = r - d * np.cos(phi)                                        # soles touching y = 0
    hip = np.array([-length * math.sin(th_front), ankle_y[1] + length * math.cos(th_front)])
    c = (hip[1] - ankle_y[0]) / length
    if c >= 1.0:                         # the rear foot cannot reach: turn it like the front one
        phi[0] = phi[1]
        ankle_y[0] = ankle_y[1]
        c = (hip[1] - ankle_y[0]) / length
    angles = (-math.acos(c), th_front)                                   # rear (outer), front (inner)
    legs, ankles = [], []
    for s, th in enumerate(angles):
        e = np.array([math.sin(th), -math.cos(th)])
        legs.append(b.add_body(("outer_leg", "inner_leg")[s], rng.uniform(3.0, 7.0), rng.uniform(0.2, 0.7),
                               pos=tuple(hip + leg_com * e), angle=th,
                               shapes=[("capsule", (0.0, leg_com), (0.0, leg_com - length), 0.02,
                                        {"collide": False})]))
        ankles.append(hip + length * e)
    feet = []
    for s in range(2):
        cf, sf = math.cos(phi[s]), math.sin(phi[s])
        feet.append(b.add_body(("outer_foot", "inner_foot")[s], 10.0 ** rng.uniform(-2, -0.5),
                               10.0 ** rng.uniform(-3.5, -2),
                               pos=(ankles[s][0] + cf * fx - sf * fy, ankles[s][1] + sf * fx + cf * fy),
                               angle=phi[s]))
    b.add_pin("hip", legs[0], legs[1], anchor_world=tuple(hip))
    for s in range(2):
        b.add_pin(("outer_ankle", "inner_ankle")[s], legs[s], feet[s], anchor_world=tuple(ankles[s]),
                  limit=(-rng.uniform(0.05, 0.6), rng.uniform(0.05, 0.6)))
    for s in range(2):
        centre = np.array([-fx, -fy + d])                                # ankle at (-fx, -fy)
        # a back corner behind the heel and a top (inside the circle, as Ranger's are)
        verts = [tuple(centre + 0.92 * r * np.array([math.cos(a0 - 0.15), math.sin(a0 - 0.15)])),
                 tuple(centre + 0.65 * r * np.array([math.cos(a1 + 0.5), math.sin(a1 + 0.5)]))]
        b.add_arc_contact(("outer_sole", "inner_sole")[s], feet[s], center=tuple(centre), radius=r,
                          span=(a0, a1), vertices=verts, mu=mu)
    return b.compile()


def motor_chain(rng, dt, torques):
    """3-6 boxes pinned end to end, bent and tilted, over flat ground, a pin motor on every pin
    saturated at +-torques[j] [N m]; returns the model."""
    b = ps.ModelBuilder(dt=dt)
    mu = rng.uniform(0.2, 1.2)
    length, height, tilt = rng.uniform(0.2, 0.5), rng.uniform(0.03, 0.08), rng.uniform(-0.3, 0.3)
    e = np.array([math.cos(tilt), math.sin(tilt)])
    prev = None
    for i in range(len(torques) + 1):
        link = box(b, f"link{i}", rng.uniform(0.5, 3.0), length, height,
                   ((i + 0.5) * length * e[0], (i + 0.5) * length * e[1]), tilt, mu)
        if prev is not None:
            b.add_pin(f"pin{i}", prev, link, anchor_world=(i * length * e[0], i * length * e[1]))
            b.add_pin_motor(f"pin{i}_motor", f"pin{i}", limit=(-torques[i - 1], torques[i - 1]))
        prev = link
    return b.compile()


def commands(family, seed, model, steps):
    """(steps, n_act) commands [N m] of a run: for stiff_motors each motor bang-bang at its
    torque limit, the sign flipping every 1-5 steps (per motor, seeded, random phase); None
    for the unactuated families."""
    if family != "stiff_motors":
        return None
    rng = np.random.default_rng([seed, 7])          # its own stream: the scene's draws are kept
    u = np.empty((steps, model.n_act))
    k = np.arange(steps)
    for j in range(model.n_act):
        period = int(rng.integers(1, 6))
        phase = int(rng.integers(0, period))
        sign = 1.0 if rng.random() < 0.5 else -1.0
        u[:, j] = model.arrays.act_range[j, 1] * sign * (-1.0) ** ((k + phase) // period)
    return u


def build(family, seed):
    """(model, ground, q0, v0) of one corpus case; q0, v0 the start state [m, rad, m/s, rad/s]."""
    rng = np.random.default_rng(seed)
    dt = DTS[seed % len(DTS)]       # every five seeds cover every step size
    if family == "loop_inertia":    # even seeds at LOOP_DT, odd ones at every DTS in turn
        dt = LOOP_DT if seed % 2 == 0 else DTS[(seed // 2) % len(DTS)]
    elif family == "stiff_motors":
        dt = MOTOR_DTS[seed % len(MOTOR_DTS)]
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
    elif family == "loop_inertia":
        model = loop_inertia(rng, dt)
        v = np.zeros((model.n_body, 3))
        v[:, :2] = rng.normal(0.0, 0.5, size=(model.n_body, 2))
        v[:, 2] = rng.normal(0.0, 2.0, size=model.n_body)          # bars turning: pins at ~2-3 rad/s
        q = model.q0.copy()
        v = loop_velocity(model, q, v)
        gap = rng.uniform(0.0, 0.3)
    elif family == "hills_fast":
        model, v = hills_fast(rng, dt, pairs=bool((seed // len(DTS)) % 2))
        return model, model.terrain, model.q0.copy(), v
    elif family == "ranger_loop":
        model = ranger_loop(rng, dt)
        root_v = (rng.normal(0, 0.2), rng.normal(0, 0.1), rng.normal(0, 0.5))
        q, v = joint_pose(model, np.zeros(model.n_pin), rng.normal(0, 1.0, model.n_pin), root_v)
        return model, model.terrain, q, v
    elif family == "stiff_motors":
        if seed % 4 < 2:    # a chain of 3-6 boxes; else the biped on box feet
            n_motor = int(rng.integers(2, 6))
            model = motor_chain(rng, dt, 10.0 ** rng.uniform(2, 3, size=n_motor))
            spread, rate = 0.3, 0.5
        else:
            model = biped_stance(rng, dt, motor_torques=10.0 ** rng.uniform(2, 3, size=6))
            spread, rate = 0.03, 0.3
        root_v = (rng.normal(0, 0.1), rng.normal(0, 0.1), rng.normal(0, 0.3))
        q, v = joint_pose(model, rng.normal(0, spread, model.n_pin), rng.normal(0, rate, model.n_pin), root_v)
        gap = rng.uniform(0.0, 0.2) if rng.random() < 0.5 else 0.0
    elif family == "mass_ratio":
        model = mass_ratio(rng, dt)
        speed, heading = rng.uniform(10, 100), rng.uniform(-math.pi / 3, math.pi / 3)
        root_v = (speed * math.sin(heading), -speed * math.cos(heading), rng.uniform(-10, 10))
        q, v = joint_pose(model, rng.uniform(-1.0, 1.0, 1), rng.uniform(-10, 10, 1), root_v)
        gap = rng.uniform(0.01, 0.3)
    else:
        raise ValueError(f"family {family!r} unknown; choose from {', '.join(ALL_FAMILIES)}")
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
        from planarsim.compile import options as compile_options
        from planarsim.kernels.geometry.collide import collide

        @njit(**dict(compile_options(), cache=False))
        def overlap(vert, norm, cover, adr, num, rad, body, pairs, q, out, scratch):
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
                    n = collide(vert, norm, cover,
                                adr[sa], num[sa], rad[sa], xa, ya, ca, sna,
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
        # (no covered faces: the judge measures the shapes' true overlap)
        _overlap_kernel()(a.core_vert, a.core_norm, np.zeros((len(a.core_vert), 8)),
                          a.shape_vert_adr, a.shape_vert_num,
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
    """Names of the engine's audit counters (kernels.checks.audit.AUDIT_NAMES when it exists)."""
    try:
        from planarsim.kernels.checks.audit import AUDIT_NAMES
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
    if family in EXTREME_FAMILIES:
        return run_extreme_case(family, seed, strategy, seconds, max_steps)
    t_start = time.perf_counter()
    model, ground, q0, v0 = build(family, seed)
    dt = model.dt
    steps = min(int(round((SECONDS[family] if seconds is None else seconds) / dt)), max_steps)
    spec = (shape_spec(family, model, steps * dt) if family in SHAPE_FAMILIES
            else spec_from_model(family, model, steps * dt))
    sim = ps.Simulator(model, ps.make_options(strategy), ps.make_state(model, q0, v0))
    out = dict(family=family, seed=seed, strategy=strategy, dt=dt, steps=steps,
               e0=float(energy(spec, q0[None], v0[None])[0]), e_tol=energy_bound(spec, ground, q0, v0),
               gain=math.nan, pin=math.nan, depth=math.nan, diverged="", jump=math.nan)
    try:
        # frames: the start, then steps 1..steps; the path explained in steps taken in parts
        q, v = np.empty((steps + 1, model.n_body, 3)), np.empty((steps + 1, model.n_body, 3))
        paths = np.full((steps, model.n_body), np.nan)
        q[0], v[0] = sim.state.q, sim.state.v
        for k in range(steps):
            sim.step()
            q[k + 1], v[k + 1] = sim.state.q, sim.state.v
            if parted(sim):
                paths[k] = sim.ws.step_path
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
            out["diverged"] = "non-finite state"
        else:
            out["gain"] = float(np.max(energy(spec, q, v) - out["e0"]))
            out["pin"] = pin_separation(spec, q)
            low = (shape_clearance(model, q) if family in SHAPE_FAMILIES
                   else clearance(spec, ground, q))
            out["depth"] = max(0.0, -float(np.min(low)))
            out["jump"] = path_excess(q, v, dt, paths)
    except ps.SimulationDiverged as exc:
        out["diverged"] = str(exc).splitlines()[0][:160]
        out["raised"] = out["diverged"]
    counts = getattr(sim.ws, "audit", None)
    out["audit"] = None if counts is None else dict(zip(audit_names(len(counts)), (int(c) for c in counts)))
    out["failed"] = [name for name, bad in (
        ("energy", out["gain"] > out["e_tol"]), ("pin", out["pin"] > PIN_TOL),
        ("depth", out["depth"] > DEPTH_TOL), ("jump", out["jump"] > JUMP_SLACK),
        ("diverged", bool(out["diverged"])),
        ("audit", out["audit"] is not None and sum(out["audit"].values()) > 0)) if bad]
    out["wall"] = time.perf_counter() - t_start
    return out


def path_excess(q, v, dt, paths=None):
    """The largest distance [m] any body's centre of mass moved in one step beyond
    h max(|v_start|, |v_end|) over the frames q, v (K, n_body, 3) of steps of dt [s]
    (displacement.step_excess); -inf for fewer than two frames. paths (K - 1, n_body): for a
    step the engine took in parts (time-of-impact splits, turn sub-steps) the path its
    velocities explain part by part (Workspace.step_path; displacement.parted_step_excess),
    NaN for a whole step: inside a parted step a body moves at its parts' velocities, which
    may exceed both ends' (a body struck and stopped again within the step)."""
    worst = -math.inf
    for k in range(len(q) - 1):
        if paths is not None and not np.isnan(paths[k, 0]):
            moved = np.hypot(q[k + 1, :, 0] - q[k, :, 0], q[k + 1, :, 1] - q[k, :, 1])
            worst = max(worst, float(np.max(moved - paths[k])))
        else:
            worst = max(worst, float(np.max(step_excess(q[k], v[k], q[k + 1], v[k + 1], dt))))
    return worst


def ground_gap(ground, x, y):
    """Signed distance [m] of the points (x, y) from the ground curve (negative: below). Level
    and sloped ground: exact. Hills: above the ground, the vertical height times cos(slope)
    (only its sign matters there); below it, the smallest distance to any of: the ground point
    straight above, ground_distance's Newton foot point, and 201 ground points sampled within
    the vertical depth either side. Each is a point of the curve, so the depth given is never
    below the true one and equals it for the shallow depths a step can leave (Newton's)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    c = ground.coef
    vert = y - ground.height(x)
    if int(c[2]) == 0:
        return vert / math.sqrt(1.0 + c[1] ** 2)
    out = vert / np.sqrt(1.0 + ground.slope(x) ** 2)
    below = np.nonzero(vert < 0.0)[0]
    if len(below):
        xb, yb, db = x[below], y[below], -vert[below]
        depth = np.fmin(db, np.abs(ground_distance(ground, xb, yb)))
        u = np.linspace(-1.0, 1.0, 201)
        xs = xb[:, None] + db[:, None] * u[None, :]
        depth = np.fmin(depth, np.min(np.hypot(xs - xb[:, None], ground.height(xs) - yb[:, None]), axis=1))
        out[below] = -depth
    return out


def contact_clearance(model, q):
    """(K,) smallest signed distance [m] of any ground contact from the ground over frames q
    (negative: below): a point contact's point (ground_gap); an arc sole (level ground only)
    by its lowest point, the circle's bottom when that direction lies inside the sole's span,
    else its end points, and its fallback vertices."""
    from planarsim.kernels.codes import CONTACT_ARC, CONTACT_POINT
    a = model.arrays
    ground = model.terrain
    low = np.full(q.shape[0], np.inf)
    for i in range(model.n_contact):
        body, kind = int(a.contact_body[i]), int(a.contact_kind[i])
        if kind == CONTACT_POINT:
            x, y = world_points(q, body, a.contact_local[i]).T
            low = np.minimum(low, ground_gap(ground, x, y))
            continue
        if kind != CONTACT_ARC or np.any(ground.coef[1:] != 0.0):
            raise ValueError(f"contact_clearance: contact {model.contact_names[i]!r} of kind {kind} "
                             "(only points anywhere, arcs on level ground)")
        r = a.contact_radius[i]
        a0, a1 = a.contact_span[i]
        cx, cy = world_points(q, body, a.contact_local[i]).T
        down = np.mod(-math.pi / 2 - q[:, body, 2] - a0, 2 * math.pi) + a0   # body-frame angle
        gap = np.where(down <= a1, cy - r, np.inf)
        pts = [a.contact_local[i] + r * np.array([math.cos(t), math.sin(t)]) for t in (a0, a1)]
        adr, num = int(a.contact_vert_adr[i]), int(a.contact_vert_num[i])
        pts += list(a.vert_local[adr:adr + num])
        for p in pts:
            gap = np.minimum(gap, world_points(q, body, p)[:, 1])
        low = np.minimum(low, gap - ground.coef[0])
    return low


def tunnel_depth(model, q, v, mode, dt, samples=128):
    """Deepest point [m] below the ground of any point mass's path within a step that began
    and ended clear of the ground with its contact free (mode 0 at both frames) and ended where
    the plain step puts it (q1 = q0 + h v1, no time-of-impact split): the engine's own path
    model p(tau) = p0 + tau v0 + tau^2 (v1 - v0) / h (kernels/geometry/ccd.py), sampled at `samples`
    points of the step. A point that crosses a crest and comes out again between two frames,
    which no frame's depth shows, is a tunnel."""
    a = model.arrays
    worst = 0.0
    tau = np.linspace(0.0, dt, samples)[None, :]
    for i in range(model.n_contact):
        body = int(a.contact_body[i])
        if not model.is_point(body):
            continue
        p0, p1, v0, v1 = q[:-1, body, :2], q[1:, body, :2], v[:-1, body, :2], v[1:, body, :2]
        plain = np.all(np.abs(p1 - (p0 + dt * v1)) <= 1e-9 * (1.0 + np.abs(p1)), axis=1)
        free = (mode[:-1, i] == 0) & (mode[1:, i] == 0) & plain
        ks = np.nonzero(free)[0]
        if not len(ks):
            continue
        acc = (v1[ks] - v0[ks]) / dt
        x = p0[ks, 0, None] + tau * v0[ks, 0, None] + tau * tau * acc[:, 0, None]
        y = p0[ks, 1, None] + tau * v0[ks, 1, None] + tau * tau * acc[:, 1, None]
        dip = -np.min(ground_gap(model.terrain, x.ravel(), y.ravel()).reshape(x.shape), axis=1)
        worst = max(worst, float(np.max(dip - rod_sag(model, q, v, body, dt)[ks])))
    return max(worst, 0.0)


#: steps of a run whose energy change beyond the flat share is measured again contact-free
MAX_FREE_STEPS = 20
#: how far a step's state is lifted to touch no ground [m]
LIFT = 1e4


def contact_free_gain(model, q, v, u=None):
    """The energy [J] one step gains beyond its gravity term, (E' - E) - (dt / 2) g dp_y, from
    the state (q, v) lifted LIFT above the ground (the same motion without its ground contacts):
    the integrator's own change of energy at that motion (a rod spinning freely at w gains
    (h w)^2 / 4 of its kinetic energy a step: tests/physics/test_contact_stress.py)."""
    a = model.arrays
    lifted = np.array(q, float)
    lifted[:, 1] += LIFT
    sim = ps.Simulator(model, ps.make_options(jump_limit=0.0, gross_limit=0.0),
                       ps.make_state(model, lifted, v))
    try:
        sim.step(u)
    except ps.SimulationDiverged:
        return 0.0
    q1, v1 = sim.state.q[:model.n_body], sim.state.v[:model.n_body]
    m = a.body_mass
    gravity = G * float(np.sum(m * (q1[:, 1] - lifted[:, 1])))
    dp = float(np.sum(m * (v1[:, 1] - v[:, 1])))
    return (float(kinetic(m, a.body_inertia, v1)) - float(kinetic(m, a.body_inertia, v)) + gravity
            - 0.5 * model.dt * G * dp)


def fastest_turn(model, q, v):
    """(K,) the fastest turning rate [rad/s] at each frame: of a body (|omega|) or of a rod
    (|d x dv| / |d|^2 of its bodies' centres)."""
    a = model.arrays
    fastest = np.max(np.abs(v[..., 2]), axis=-1)
    for j in range(a.rod_body.shape[0]):
        i, k = (int(x) for x in a.rod_body[j])
        d = q[:, k, :2] - (q[:, i, :2] if i >= 0 else 0.0)
        dv = v[:, k, :2] - (v[:, i, :2] if i >= 0 else 0.0)
        d2 = np.maximum(np.sum(d * d, axis=-1), 1e-300)
        fastest = np.maximum(fastest, np.abs(d[:, 0] * dv[:, 1] - d[:, 1] * dv[:, 0]) / d2)
    return fastest


def rod_sag(model, q, v, body, dt):
    """(K - 1,) how far [m] the path a tunnel is measured on may stray from the motion the
    engine integrated, per step: for a point on a rod of length L turning at omega, the
    rod's position correction moves it by up to L (h omega)^2 / 2 (what the rod lengthens
    when its ends move straight while it turns by h omega) after the engine's own
    time-of-impact search, which ran on the path before that correction (the path measured
    here, from the corrected velocity, differs from it by tau^2 / h^2 of that move); 0 for a
    free point."""
    a = model.arrays
    sag = np.zeros(q.shape[0] - 1)
    for j in range(a.rod_body.shape[0]):
        ends = [int(x) for x in a.rod_body[j]]
        if body not in ends:
            continue
        d = q[1:, ends[1], :2] - q[1:, ends[0], :2]
        dv = v[1:, ends[1], :2] - v[1:, ends[0], :2]
        length = np.hypot(d[:, 0], d[:, 1])
        omega = (d[:, 0] * dv[:, 1] - d[:, 1] * dv[:, 0]) / np.maximum(length, 1e-300) ** 2
        sag = np.maximum(sag, length * (dt * omega) ** 2 / 2.0)
    return sag


def joint_gap(model, q):
    """Largest pin opening or rod length error [m] over frames q."""
    spec = shape_spec("gap", model, 0.0)
    worst = pin_separation(spec, q) if model.n_pin else 0.0
    a = model.arrays
    for j in range(model.n_rod):
        pa = world_points(q, int(a.rod_body[j, 0]), a.rod_anchor[j, 0])
        pb = world_points(q, int(a.rod_body[j, 1]), a.rod_anchor[j, 1])
        worst = max(worst, float(np.max(np.abs(np.hypot(*(pb - pa).T) - a.rod_length[j]))))
    return worst


def motor_work(model, q, u):
    """(K,) work [J] the pin motors did from frame 0 to each frame: sum over steps and motors
    of the command times the pin angle's change over the step (the work symplectic Euler's
    motor impulse does at the step's end velocity)."""
    a = model.arrays
    work = np.zeros(q.shape[0])
    for j in range(model.n_act):
        pa, pb = (int(x) for x in a.pin_body[int(a.act_ref[j])])
        rel = q[:, pb, 2] - (q[:, pa, 2] if pa >= 0 else 0.0)
        work[1:] += u[:q.shape[0] - 1, j] * np.diff(rel)
    return np.cumsum(work)


def motor_speed_ratio(model, spec, q, v, dt):
    """max over frames of sqrt(E'(t)) / (sqrt(E'(0)) + C t): how far a run's energy above its
    floor, E' = E - M g y_floor (>= the kinetic energy while no box corner is below the
    ground), exceeds what the motors can give. A motor's power is at most tau (|omega_a| +
    |omega_b|) <= tau sqrt(2 E') (I_a^-1/2 + I_b^-1/2), contacts take energy out, pins do no
    work, so sqrt(E') grows at most at C / 2, C = sum_j sqrt(2) tau_j (I_a^-1/2 + I_b^-1/2)
    (twice that is allowed here for the discrete steps). Any body's speed is at most
    sqrt(2 E' / m): a ratio above 1 is a body faster than the motors' torque limits allow."""
    a = model.arrays
    c = 0.0
    for j in range(model.n_act):
        tau = float(np.max(np.abs(a.act_range[j])))
        for body in a.pin_body[int(a.act_ref[j])]:
            if body >= 0:
                c += math.sqrt(2.0) * tau / math.sqrt(a.body_inertia[body])
    floor = G * float(spec.mass.sum()) * float(model.terrain.coef[0])
    above = np.maximum(energy(spec, q, v) - floor, 0.0)
    t = dt * np.arange(q.shape[0])
    return float(np.max(np.sqrt(above) / (math.sqrt(above[0]) + c * t + 1e-300)))


def run_extreme_case(family, seed, strategy, seconds=None, max_steps=MAX_STEPS) -> dict:
    """run_case for EXTREME_FAMILIES: stepped one step at a time (sim.step(u): stiff_motors'
    commands change every step), so that the frames before an engine error are judged too.
    Adds to run_case's dict: raised ('' or the planarsim error that stopped the run), speed
    (fastest body [m/s]), speed_ratio (stiff_motors: motor_speed_ratio; else nan), step_gain
    (largest single-step energy change beyond the step's own gravity term and the motors'
    work [J], see the module docstring) at step step_k, and step_note (ranger_loop: whether a
    sole slid and an ankle left its limit in that step)."""
    t_start = time.perf_counter()
    model, ground, q0, v0 = build(family, seed)
    dt = model.dt
    steps = min(int(round((SECONDS[family] if seconds is None else seconds) / dt)), max_steps)
    spec = shape_spec(family, model, steps * dt)
    u = commands(family, seed, model, steps)
    sim = ps.Simulator(model, ps.make_options(strategy), ps.make_state(model, q0, v0))
    e0 = float(energy(spec, q0[None], v0[None])[0])
    out = dict(family=family, seed=seed, strategy=strategy, dt=dt, steps=steps, e0=e0,
               e_tol=math.nan if u is not None else energy_bound(spec, ground, q0, v0),
               gain=math.nan, pin=math.nan, depth=math.nan, diverged="", raised="", speed=math.nan,
               speed_ratio=math.nan, step_gain=math.nan, step_k=-1, step_note="", tunnel=math.nan,
               turn_steps=0, turn_max=0.0,
               slide_leave_gain=math.nan, slide_leave_k=-1, jump=math.nan)
    nb, nc, npin = model.n_body, model.n_contact, model.n_pin
    q, v = np.empty((steps + 1, nb, 3)), np.empty((steps + 1, nb, 3))
    mode, limit = np.empty((steps + 1, nc), np.int64), np.empty((steps + 1, npin, 2), np.int64)
    paths = np.full((steps, model.n_body), np.nan)
    s = sim.state
    q[0], v[0], mode[0], limit[0] = s.q, s.v, s.contact_mode, s.limit_active
    n = steps + 1
    k = 0
    try:
        for k in range(1, steps + 1):
            sim.step(None if u is None else u[k - 1])
            s = sim.state
            q[k], v[k], mode[k], limit[k] = s.q, s.v, s.contact_mode, s.limit_active
            if parted(sim):
                paths[k - 1] = sim.ws.step_path
    except Exception as exc:          # an error of the engine's, naming why: raised, not silent
        if not type(exc).__module__.startswith("planarsim"):
            raise
        out["raised"] = out["diverged"] = f"{type(exc).__name__}: {str(exc).splitlines()[0][:160]}"
        n = k
    finite = np.all(np.isfinite(q[:n]), axis=(1, 2)) & np.all(np.isfinite(v[:n]), axis=(1, 2))
    if not finite.all():
        n = int(np.argmin(finite))
        out["diverged"] = out["diverged"] or "non-finite state"
    q, v, mode, limit = q[:n], v[:n], mode[:n], limit[:n]
    if n >= 1:
        work = motor_work(model, q, u) if u is not None else np.zeros(n)
        net = energy(spec, q, v) - e0 - work
        out["gain"] = float(np.max(net))
        out["pin"] = joint_gap(model, q)
        out["depth"] = max(0.0, -float(np.min(contact_clearance(model, q))))
        if family == "hills_fast" and n >= 2:
            out["tunnel"] = tunnel_depth(model, q, v, mode, dt)
        out["jump"] = path_excess(q, v, dt, paths[:n - 1])
        out["speed"] = float(np.max(np.hypot(v[..., 0], v[..., 1])))
        if u is not None:
            out["speed_ratio"] = motor_speed_ratio(model, spec, q, v, dt)
    if n >= 2:
        py = np.sum(spec.mass * v[..., 1], axis=1)
        excess = np.diff(net) - 0.5 * dt * G * np.diff(py)
        if model.n_pin + model.arrays.rod_body.shape[0] > 0:
            # the joints' second-order terms move a step's energy by up to CONSTRAINT_SHARE
            # of its kinetic energy, up or down (symplectic: it oscillates, the energy target
            # above holds the run's drift). A step beyond that is judged against what the
            # integrator itself gains from its start state with nothing to touch
            # (contact_free_gain: a rod spinning at w gains about (h w)^2 / 4 of it); a gain the
            # contacts add beyond it is a miss
            ke = kinetic(spec.mass, spec.inertia, v[:-1])
            allowance = CONSTRAINT_SHARE * ke
            beyond = np.nonzero(excess - allowance > out["e_tol"])[0]
            for k in beyond[:MAX_FREE_STEPS]:
                own = contact_free_gain(model, q[k], v[k], None if u is None else u[k])
                if own > allowance[k]:
                    allowance[k] = own * (1.0 + 1e-9) + 1e-12 * ke[k]
            needs = (excess - CONSTRAINT_SHARE * ke > out["e_tol"]) & (excess - allowance <= out["e_tol"])
            out["turn_steps"] = int(np.count_nonzero(needs))
            turn = dt * fastest_turn(model, q[:-1], v[:-1])
            out["turn_max"] = float(np.max(turn[needs])) if out["turn_steps"] else 0.0
            excess = excess - allowance
        k = int(np.argmax(excess))
        out["step_gain"], out["step_k"] = float(excess[k]), k + 1
        if family == "ranger_loop":
            slid = bool(np.any(mode[k + 1] == int(ps.ContactMode.SLIDING)) or
                        np.any(mode[k] == int(ps.ContactMode.SLIDING)))
            left = bool(np.any((limit[k] == 1) & (limit[k + 1] == 0)))
            out["step_note"] = (("slide" if slid else "no slide") + ", " +
                                ("ankle left its limit" if left else "no limit left"))
            sliding = np.any(mode == int(ps.ContactMode.SLIDING), axis=1)
            leaving = np.any((limit[:-1] == 1) & (limit[1:] == 0), axis=(1, 2))
            both = np.nonzero(leaving & (sliding[1:] | sliding[:-1]))[0]
            if len(both):
                j = both[int(np.argmax(excess[both]))]
                out["slide_leave_gain"], out["slide_leave_k"] = float(excess[j]), int(j) + 1
    counts = getattr(sim.ws, "audit", None)
    out["audit"] = None if counts is None else dict(zip(audit_names(len(counts)), (int(c) for c in counts)))
    out["failed"] = [name for name, bad in (
        ("energy", out["gain"] > out["e_tol"]), ("step", out["step_gain"] > out["e_tol"]),
        ("pin", out["pin"] > PIN_TOL), ("depth", out["depth"] > DEPTH_TOL),
        ("tunnel", out["tunnel"] > DEPTH_TOL), ("jump", out["jump"] > JUMP_SLACK),
        ("speed", out["speed_ratio"] > 1.0),
        ("diverged", bool(out["diverged"])),
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


def _silent(r):
    """True when run r misses a target and the engine did not stop it with an error."""
    return bool(r["failed"]) and not r.get("raised")


def report(results, n_worst=8) -> bool:
    """Print one line per family (runs, runs missing any target, runs above E0 + E_tol, runs
    the engine stopped with an error naming why ('raise') and runs missing a target without
    one ('silent'), ...), its silent misses by cause, its audit counts by rule, and the worst
    runs; True when every run meets every target."""
    print(f"targets: energy gained <= E_tol (energy_bound), pin gap <= {PIN_TOL:g} m, depth <= "
          f"{DEPTH_TOL:g} m, no step moving a body beyond h max|v| + {JUMP_SLACK:g} m, no "
          f"divergence, no audit violation"
          + ("; stiff_motors: no energy target, speed ratio <= 1 (motor_speed_ratio)"
             if any(r["family"] == "stiff_motors" for r in results) else ""))
    head = (f"{'family':15s} {'runs':>4s} {'miss':>4s} {'>E0':>4s} {'worst gain J (of E0)':>21s} {'pin gap m':>9s} "
            f"{'depth m':>9s} {'div':>4s} {'raise':>5s} {'silent':>6s} {'audit':>6s}  E_tol [J] (of E0)")
    print(head)
    print("-" * len(head))
    for family in dict.fromkeys(r["family"] for r in results):
        rs = [r for r in results if r["family"] == family]
        above = [r for r in rs if "energy" in r["failed"]]
        gain = max(rs, key=lambda r: -math.inf if math.isnan(r["gain"]) else r["gain"])
        audits = [r["audit"] for r in rs if r["audit"] is not None]
        audit = "n/a" if not audits else str(sum(sum(a.values()) for a in audits))
        tol = [r["e_tol"] for r in rs if not math.isnan(r["e_tol"])]
        share = [r["e_tol"] / r["e0"] for r in rs if r["e0"] > 0 and not math.isnan(r["e_tol"])]
        bound = (f"{min(tol):.2g}..{max(tol):.2g} ({min(share):.1g}..{max(share):.1g})" if tol
                 else "none (motors do work)")
        silent = [r for r in rs if _silent(r)]
        print(f"{family:15s} {len(rs):4d} {sum(bool(r['failed']) for r in rs):4d} {len(above):4d} "
              f"{gain['gain']:10.3g} ({gain['gain'] / gain['e0']:8.2g}) "
              f"{_worst(r['pin'] for r in rs):9.2g} {_worst(r['depth'] for r in rs):9.2g} "
              f"{sum(bool(r['diverged']) for r in rs):4d} {sum(bool(r.get('raised')) for r in rs):5d} "
              f"{len(silent):6d} {audit:>6s}  {bound}")
        if silent:
            causes = {c: sum(c in r["failed"] for r in silent)
                      for c in ("energy", "step", "pin", "depth", "tunnel", "jump", "speed", "diverged",
                                "audit")}
            print(f"{'':15s} silent misses by cause: "
                  + ", ".join(f"{c if c != 'diverged' else 'non-finite'} {n}" for c, n in causes.items()))
        print(f"{'':15s} worst step path: a body moved {_worst(r['jump'] for r in rs):.3g} m beyond "
              f"h max(|v_start|, |v_end|) ({sum('jump' in r['failed'] for r in rs)} runs beyond "
              f"{JUMP_SLACK:g} m)")
        raised = [r for r in rs if r.get("raised")]
        if raised:
            kinds = {}
            for r in raised:
                name = r["raised"].split(":")[0] if family in EXTREME_FAMILIES else "SimulationDiverged"
                kinds[name] = kinds.get(name, 0) + 1
            print(f"{'':15s} raised: " + ", ".join(f"{k} {n}" for k, n in kinds.items()))
        if audits:
            kinds = {k: sum(a[k] for a in audits) for k in audits[0]}
            print(f"{'':15s} audit by rule: " + ", ".join(f"{k} {n}" for k, n in kinds.items()))
        turned = [r for r in rs if r.get("turn_steps", 0)]
        print(f"{'':15s} steps beyond {CONSTRAINT_SHARE:.0%} of KE + E_tol that the integrator's "
              f"own contact-free gain explains: "
              + (f"{sum(r['turn_steps'] for r in turned)} in {len(turned)} runs, largest h w "
                 f"{max(r['turn_max'] for r in turned):.3g} rad" if turned else "none"))
        if family in EXTREME_FAMILIES:
            step = max(rs, key=lambda r: -math.inf if math.isnan(r["step_gain"]) else r["step_gain"])
            line = (f"worst speed {_worst(r['speed'] for r in rs):.3g} m/s; worst single-step gain "
                    f"{step['step_gain']:.3g} J ({family}:{step['seed']}:{step['strategy']} step "
                    f"{step['step_k']})")
            if family == "stiff_motors":
                line += f"; worst speed ratio {_worst(r['speed_ratio'] for r in rs):.3g}"
            if family == "hills_fast":
                line += f"; worst tunnel {_worst(r['tunnel'] for r in rs):.3g} m"
            if family == "ranger_loop":
                both = sorted((r for r in rs if r["slide_leave_gain"] > 0.0),
                              key=lambda r: -r["slide_leave_gain"] / r["e_tol"])
                line += (f"\n{'':15s} steps with a sliding sole and an ankle leaving its limit that "
                         f"gain energy: in {len(both)} runs; the largest gains:" + "".join(
                             f"\n{'':17s}{r['family']}:{r['seed']}:{r['strategy']} step {r['slide_leave_k']} "
                             f"gains {r['slide_leave_gain']:.3g} J (E_tol {r['e_tol']:.2g})" for r in both[:4]))
            print(f"{'':15s} {line}")
    bad = [r for r in results if r["failed"]]
    if bad:
        def badness(r):
            ratios = [r["gain"] / r["e_tol"], r["pin"] / PIN_TOL, r["depth"] / DEPTH_TOL]
            worst = max((x for x in ratios if not math.isnan(x)), default=0.0)
            return bool(r["diverged"]), len(r["failed"]), worst
        print(f"worst runs (of {len(bad)} missing a target, {sum(_silent(r) for r in bad)} silent; "
              f"rerun one with --only family:seed:strategy):")
        for r in sorted(bad, key=badness, reverse=True)[:n_worst]:
            audit = "n/a" if r["audit"] is None else {k: n for k, n in r["audit"].items() if n}
            extra = ""
            if r["family"] in EXTREME_FAMILIES:
                extra = f"  speed {r['speed']:.3g} m/s  step gain {r['step_gain']:.3g} J at step {r['step_k']}"
                if r["step_note"]:
                    extra += f" ({r['step_note']})"
            print(f"  {r['family']}:{r['seed']}:{r['strategy']}  dt={r['dt']:g} s x {r['steps']}  "
                  f"gain {r['gain']:.3g} J (E_tol {r['e_tol']:.2g})  pin {r['pin']:.2g} m  "
                  f"depth {r['depth']:.2g} m  audit {audit}  misses {'/'.join(r['failed'])}"
                  + (" RAISED" if r.get("raised") else " SILENT") + extra
                  + (f"  [{r['diverged']}]" if r["diverged"] else ""))
    return not bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--families", nargs="+", choices=ALL_FAMILIES + ("extremes",), default=list(FAMILIES),
                    help=f"families to run (default the six of the corpus; 'extremes': "
                         f"{' '.join(EXTREME_FAMILIES)})")
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
            if family not in ALL_FAMILIES or strategy not in STRATEGIES:
                ap.error(f"--only {text!r}: want family:seed:strategy, family in {ALL_FAMILIES}, "
                         f"strategy in {STRATEGIES}")
            cases.append((family, int(seed), strategy))
    else:
        families = [f for name in args.families
                    for f in (EXTREME_FAMILIES if name == "extremes" else (name,))]
        cases = corpus(args.quick, list(dict.fromkeys(families)), args.runs_per_family, args.strategy)
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
