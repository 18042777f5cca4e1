"""Rolling and terrain contact against closed forms and conservation laws: disks and hoops
(an arc sole and a circle shape, r 1e-3..10 m, dt 1e-4..1e-2) rolling down slopes from 1e-4 to
88.9 degrees, a wheel carrying an axle load 1e-3..1e3 times its mass, the thresholds between
rolling and rolling with slip and between sticking and sliding (both sides, 1e-6 from them),
a disk skidding with spin on a slope until it rolls, a disk thrown spinning at a slope
(landing plastically, or bouncing with restitution up to 0.9), a disk rolling on flat ground,
a rocker's small-amplitude period on flat ground and about its tilted rest on a slope, a disk
rolling over sum-of-sines hills (its turn, its gap, its energy), mirror and translation
invariance of curved feet and disks on slopes and hills (moved by whole wavelengths), the
energy of a rocker and of bodies moving over hills, and a point sliding over a crest.

On a slope every row is linear in the positions, so symplectic Euler's recurrence is known in
closed form: a constant acceleration a gives the velocity a t and the distance
a t^2 / 2 + a h t / 2 after t = n h, which the engine meets to rounding. On curved ground and
under a rolling sole a contact held through the step aims at the second-order part of its gap
(kernels/solver/solve.py held_contact_curve): with a first-order target a rocker and a body
moving over hills lost energy at a steady rate, first order in dt, and a point sliding over a
crest where the ground still pushes read free in most of its steps, at any dt (the tests below
give the figures of both)."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import terrain
from planarsim.compiled import audit_counts
from planarsim.kernels.codes import MODE_PINNED, MODE_SLIDING

G = 9.81
HILLS = ([0.12, 0.045], [7.0, 2.9], [0.0, 1.3])          # the default hills (max slope 12 deg)

def assert_clean(sim):
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


def _disk(ter, r, k, mu, dt, kind, pos, vel=(0.0, 0.0), omega=0.0, m=1.0, load=None):
    """A disk (I = k m r^2) as an arc sole or a circle shape; load: the mass of a point pinned
    at its centre (an axle's load)."""
    b = ps.ModelBuilder(dt=dt, terrain=ter)
    if kind == "arc":
        d = b.add_body("disk", mass=m, inertia=k * m * r * r, pos=pos, vel=vel, omega=omega)
        b.add_arc_contact("rim", d, (0.0, 0.0), r, mu=mu)
    else:
        d = b.add_body("disk", mass=m, inertia=k * m * r * r, pos=pos, vel=vel, omega=omega,
                       shapes=[("circle", (0.0, 0.0), r, {"mu": mu})])
    if load is not None:
        p = b.add_point_mass("load", load, pos=pos, vel=vel)
        b.add_pin("axle", d, p, anchor_world=pos)
    return ps.Simulator(b.compile())


def _on_slope(deg, r):
    """(down-slope unit vector s, upward normal n, centre of a disk of radius r touching) of
    terrain.slope(-deg), which falls toward +x."""
    a = math.radians(deg)
    s = np.array([math.cos(a), -math.sin(a)])
    n = np.array([math.sin(a), math.cos(a)])
    return s, n, r * n


def _roll_for_a_second(sim, a, k, r, c, s, dt):
    """1 s of a unit-mass disk (I = k r^2) rolling from rest at c down a slope of a [rad]
    (down-slope unit vector s): (steps, t, q, v, the rolling acceleration, the distance
    travelled and symplectic Euler's a t^2 / 2 + a h t / 2, the speed along s, the rolling
    kinetic energy, the energy from the start)."""
    steps = int(round(1.0 / dt))
    sim.steps(steps)
    t = steps * dt
    q, v = sim.state.q[0], sim.state.v[0]
    acc = G * math.sin(a) / (1.0 + k)
    travelled = float((q[:2] - c) @ s)
    expected = 0.5 * acc * t * t + 0.5 * acc * dt * t
    speed = float(v[:2] @ s)
    kinetic = 0.5 * (1.0 + k) * speed * speed
    energy = 0.5 * (v[0] ** 2 + v[1] ** 2) + 0.5 * k * r * r * v[2] ** 2 + G * (q[1] - c[1])
    return steps, t, q, v, acc, travelled, expected, speed, kinetic, energy


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("deg, r, k, dt, mu", [
    (10.0, 0.1, 0.5, 1e-3, 1.0), (10.0, 0.1, 1.0, 1e-3, 1.0), (10.0, 1e-3, 0.5, 1e-4, 1.0),
    (10.0, 10.0, 0.5, 1e-2, 1.0), (1e-4, 0.1, 0.5, 1e-3, 1.0), (30.0, 0.1, 0.5, 1e-2, 0.2),
    (30.0, 0.1, 1.0, 1e-3, 0.3), (45.0, 0.5, 1.0, 1e-2, 0.6), (30.0, 1e-3, 0.5, 1e-2, 1.0),
    (88.9, 0.1, 0.5, 1e-2, 40.0)])
def test_a_disk_or_hoop_rolls_down_a_slope_at_the_rolling_acceleration_keeping_its_energy(
        kind, deg, r, k, dt, mu):
    """From rest a disk (k = 1/2) or hoop (k = 1) rolls at a = g sin(alpha) / (1 + k) where
    tan(alpha) <= mu (1 + k) / k (0.2 and 0.3 at 30 degrees are 4 % inside, 0.6 at 45 degrees
    20 %). Symplectic
    Euler's velocity is a t and its distance a t^2 / 2 + a h t / 2; its energy is the
    modified one, E = -(h / t) KE (the positions use the step's end velocity): all to
    rounding, with no slip and the rim on the slope; at 88.9 degrees (the steepest slope a
    terrain takes) and at 33 rad a step (r = 1 mm at dt 1e-2) too. Measured: 1e-13 relative
    at most (the energy at 1e-4 degrees, whose kinetic energy is 1e-10 J, to the rounding of
    g y)."""
    a = math.radians(deg)
    s, n, c = _on_slope(deg, r)
    sim = _disk(terrain.slope(-deg), r, k, mu, dt, kind, tuple(c))
    steps, t, q, v, acc, travelled, expected, speed, kinetic, energy = _roll_for_a_second(
        sim, a, k, r, c, s, dt)
    print(f"{kind} {deg} deg r={r} k={k} dt={dt}: distance {travelled / expected - 1:+.1e}, "
          f"speed {speed / (acc * t) - 1:+.1e}, energy {(energy + dt / t * kinetic) / kinetic:+.1e}")
    assert abs(travelled - expected) <= 1e-11 * expected
    assert abs(speed - acc * t) <= 1e-11 * acc * t
    assert abs(speed + v[2] * r) <= 1e-11 * speed                      # no slip
    assert abs(float((q[:2] - c) @ n)) <= 1e-12 * max(r, 1.0)          # on the slope
    rounding = steps * 2.2e-16 * G * (abs(q[1]) + abs(c[1]))          # of the heights summed
    assert abs(energy + dt / t * kinetic) <= 1e-9 * kinetic + rounding
    assert np.all(sim.state.contact_mode == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("deg, r, k, dt, mu", [
    (10.0, 0.1, 0.5, 1e-3, 1.0), (10.0, 0.1, 1.0, 1e-2, 1.0), (30.0, 0.1, 0.5, 1e-2, 1.0),
    (30.0, 0.1, 0.5, 1e-3, 0.3), (45.0, 0.5, 1.0, 1e-2, 0.6), (30.0, 1e-3, 0.5, 1e-2, 1.0),
    (60.0, 0.05, 0.5, 1e-2, 2.0)])
def test_a_disk_rolls_down_a_static_box_as_down_the_slope(deg, r, k, dt, mu):
    """The same closed forms on a slope made of a static box (a shape pair: the disk is the
    incident shape on the box's face) instead of the terrain: the disk's surface point is
    not a material point, and the sticking contact's slip counts the arc it rolled (pair.
    pair_row). Holding the material point that touched at the step's start instead left
    r (phi - sin phi) a step, which the correction turned into velocity: at 30 degrees and
    dt 1e-2 the disk spun 4 % faster than it rolled (v 4.835, w r 5.046 m/s after 1.5 s)
    and gained 0.13 J."""
    a = math.radians(deg)
    s, n, c = _on_slope(deg, r)
    b = ps.ModelBuilder(dt=dt, ground=None)
    b.add_shape(None, "box", tuple(-0.1 * n + 9.0 * s), 20.0, 0.2, -a, mu=mu)
    b.add_body("disk", mass=1.0, inertia=k * r * r, pos=tuple(c),
               shapes=[("circle", (0.0, 0.0), r, {"mu": mu})])
    sim = ps.Simulator(b.compile())
    steps, t, q, v, acc, travelled, expected, speed, kinetic, energy = _roll_for_a_second(
        sim, a, k, r, c, s, dt)
    assert abs(travelled - expected) <= 1e-9 * travelled
    assert abs(speed - acc * t) <= 1e-9 * acc * t
    assert abs(speed + v[2] * r) <= 1e-9 * speed                       # no slip
    assert abs(energy + dt / t * kinetic) <= 1e-9 * kinetic
    assert sim.state.contact_mode[0] == MODE_PINNED
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("load, deg, dt, r", [
    (1e-3, 10.0, 1e-3, 0.1), (1e3, 10.0, 1e-3, 0.1), (1e3, 30.0, 1e-2, 1.0), (1e-3, 1e-3, 1e-4, 1e-3),
    (1.0, 45.0, 1e-3, 10.0)])
def test_a_wheel_carrying_an_axle_load_rolls_at_the_closed_form_acceleration(kind, load, deg, dt, r):
    """A 1 kg disk (I = m r^2 / 2) carrying a point mass `load` pinned at its centre rolls
    down the slope at a = g sin(alpha) (m + M) / (m + M + I / r^2), load ratios 1e-3..1e3:
    the pin's impulses are internal and pass through the centre, so the recurrence is the
    disk's own, to rounding. Measured: 1e-13 relative at most."""
    a = math.radians(deg)
    s, n, c = _on_slope(deg, r)
    sim = _disk(terrain.slope(-deg), r, 0.5, 2.0, dt, kind, tuple(c), load=load)
    steps = int(round(1.0 / dt))
    sim.steps(steps)
    t = steps * dt
    q, v = sim.state.q, sim.state.v
    acc = G * math.sin(a) * (1.0 + load) / (1.5 + load)
    speed = float(v[0, :2] @ s)
    travelled = float((q[0, :2] - c) @ s)
    expected = 0.5 * acc * t * t + 0.5 * acc * dt * t
    assert abs(speed - acc * t) <= 1e-11 * acc * t, speed / (acc * t) - 1
    assert abs(travelled - expected) <= 1e-11 * expected, travelled / expected - 1
    assert abs(speed + v[0, 2] * r) <= 1e-11 * speed
    assert np.abs(q[1, :2] - q[0, :2]).max() <= 1e-12 * max(r, 1.0)
    assert np.all(sim.state.contact_mode == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("deg, k", [(5.0, 0.4), (20.0, 0.5), (45.0, 1.0), (60.0, 0.5)])
@pytest.mark.parametrize("eps", [1e-3, 1e-6, -1e-6, -1e-3, -0.3])
@pytest.mark.parametrize("dt", [1e-4, 1e-2])
def test_a_disk_rolls_or_slips_on_either_side_of_its_friction_threshold(kind, deg, k, eps, dt):
    """A disk released on a slope rolls (a = g sin / (1 + k), no slip) when
    tan(alpha) <= mu (1 + k) / k, and otherwise slips with friction at the cone's edge:
    a = g (sin - mu cos), angular acceleration mu g cos / (k r). mu is set a relative eps from
    the threshold (1e-6 on both sides: 1e-6 of the normal impulse, well above the solve's 1e-9
    check of Coulomb's rule). Both closed forms hold to rounding. Measured: 3e-13."""
    a = math.radians(deg)
    r = 0.1
    mu = math.tan(a) * k / (1.0 + k) * (1.0 + eps)
    s, n, c = _on_slope(deg, r)
    sim = _disk(terrain.slope(-deg), r, k, mu, dt, kind, tuple(c))
    steps = int(round(0.5 / dt))
    sim.steps(steps)
    t = steps * dt
    v = sim.state.v[0]
    if eps > 0:
        acc, spin, mode = G * math.sin(a) / (1.0 + k), -G * math.sin(a) / (1.0 + k) / r * t, MODE_PINNED
    else:
        acc = G * (math.sin(a) - mu * math.cos(a))
        spin, mode = -mu * G * math.cos(a) / (k * r) * t, MODE_SLIDING
    speed = float(v[:2] @ s)
    assert np.all(sim.state.contact_mode == mode), sim.state.contact_mode
    assert abs(speed - acc * t) <= 1e-11 * acc * t, speed / (acc * t) - 1
    assert abs(v[2] - spin) <= 1e-11 * abs(spin), v[2] / spin - 1
    assert_clean(sim)


@pytest.mark.parametrize("body, deg", [("point", 1.0), ("point", 20.0), ("point", 45.0), ("point", 80.0),
                                       ("point", 88.9), ("box", 1.0), ("box", 20.0), ("box", 45.0),
                                       ("box", 80.0)])
@pytest.mark.parametrize("eps", [1e-3, 1e-6, -1e-6, -1e-3])
@pytest.mark.parametrize("dt", [1e-4, 1e-2])
def test_a_point_or_block_sticks_or_slides_on_either_side_of_the_friction_angle(body, deg, eps, dt):
    """Released on a slope, a point mass or a block (four corner contacts) sticks when
    tan(alpha) <= mu and otherwise slides at a = g (sin - mu cos), here mu a relative eps from
    tan(alpha): symplectic Euler's distance after n steps is a h^2 n (n + 1) / 2, to rounding
    (a sticking body does not creep by a picometre; measured: 3e-15 m in 1 s). A block's two
    touching corners share its friction, so one of them may read sliding at its cone's edge
    while the block holds. At 1e-8 from the threshold at 1 degree the excess force is 2e-10
    of the normal one, below the solve's 1e-9 check of Coulomb's rule, and the point sticks:
    that is the solve's resolution, not tested here."""
    a = math.radians(deg)
    mu = math.tan(a) * (1.0 + eps)
    b = ps.ModelBuilder(dt=dt, terrain=terrain.slope(-deg))
    if body == "point":
        p = b.add_point_mass("p", 1.0, pos=(0.0, 0.0))
        b.add_point_contact("p", p, mu=mu)
        start = np.zeros(2)
    else:
        w, hh = 1.0, 0.1                       # it would tip over beyond atan(w / hh), 84 deg
        start = 0.5 * hh * np.array([math.sin(a), math.cos(a)])
        box = b.add_body("box", mass=3.0, inertia=3.0 * (w * w + hh * hh) / 12, pos=tuple(start),
                         angle=-a)
        b.add_box_contacts("box", box, (0.0, 0.0), w, hh, mu=mu)
    sim = ps.Simulator(b.compile())
    steps = int(round(1.0 / dt))
    sim.steps(steps)
    along = float((sim.state.q[0, :2] - start) @ np.array([math.cos(a), -math.sin(a)]))
    acc = max(0.0, G * (math.sin(a) - mu * math.cos(a)))
    expected = acc * dt * dt * steps * (steps + 1) / 2
    print(f"{body} {deg} deg eps={eps} dt={dt}: {along!r} m, expected {expected!r} m")
    assert abs(along - expected) <= 1e-9 * expected + 1e-12
    touching = sim.state.contact_mode[sim.state.contact_mode != 0]
    if eps < 0:
        assert len(touching) >= 1 and np.all(touching == MODE_SLIDING)
    else:       # a block's two corners share its friction: one may sit at its cone's edge
        assert np.any(touching == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("deg, k, mu, v0, w0r, dt, m, r", [
    (10.0, 0.5, 0.3, 3.0, 5.0, 1e-3, 1.0, 0.1), (10.0, 0.5, 0.3, -3.0, 5.0, 1e-2, 1.0, 0.1),
    (30.0, 1.0, 0.4, 0.0, -8.0, 1e-4, 1e-3, 1e-3), (0.0, 0.5, 0.2, 2.0, 4.0, 1e-2, 1e4, 10.0),
    (20.0, 0.4, 0.9, 5.0, -20.0, 1e-3, 1.0, 0.5), (5.0, 0.5, 0.05, -2.0, -1.0, 1e-3, 1.0, 0.1)])
def test_a_disk_skidding_with_spin_on_a_slope_rolls_from_the_closed_form_time_and_speed(
        kind, deg, k, mu, v0, w0r, dt, m, r):
    """A disk set down on a slope at v0 along it (down-slope positive) spinning at w0 = w0r / r
    slips at u = v + r w, friction mu g cos against it: v' = g sin -+ mu g cos and
    u' = g sin -+ mu g cos (1 + 1/k), so the slip ends at t* = -u0 / u' and the disk rolls on at
    a = g sin / (1 + k). Friction acts at the contact, so m v - I w / r grows by m g sin t
    whatever the friction: once rolling v = (v0 - k r w0 + g sin t) / (1 + k), to rounding. The
    contact slides up to the step holding t* and is pinned from its end on; the distance is
    within a step's travel of the closed form (h max|v|: symplectic Euler's positions use the
    step's end velocity, and the step holding t* mixes the two phases). Measured: 0.51 h max|v|."""
    a = math.radians(deg)
    w0 = w0r / r
    s, n, c = _on_slope(deg, r)
    sim = _disk(terrain.slope(-deg), r, k, mu, dt, kind, tuple(c), vel=tuple(v0 * s), omega=w0, m=m)
    u0 = v0 + w0 * r
    sign = math.copysign(1.0, u0)
    acc_slip = G * math.sin(a) - sign * mu * G * math.cos(a)
    t_roll = -u0 / (G * math.sin(a) - sign * mu * G * math.cos(a) * (1.0 + 1.0 / k))
    v_roll = v0 + acc_slip * t_roll
    acc_roll = G * math.sin(a) / (1.0 + k)
    steps = int(round((t_roll + 0.5) / dt))
    traj = sim.run(steps * dt, record_every=1)
    t = traj.t[-1]
    modes = traj.contact_mode[1:, 0]
    first = int(np.argmax(modes == MODE_PINNED)) + 1              # frame of the first rolling end
    assert traj.t[first] - dt < t_roll <= traj.t[first] + 1e-12, (traj.t[first], t_roll)
    assert np.all(modes[:first - 1] == MODE_SLIDING) and np.all(modes[first - 1:] == MODE_PINNED)
    v = traj.v[-1, 0]
    speed = float(v[:2] @ s)
    expected = (v0 - k * r * w0 + G * math.sin(a) * t) / (1.0 + k)
    scale = max(abs(v0), abs(w0r), abs(expected))
    assert abs(speed - expected) <= 1e-12 * scale, (speed, expected)
    assert abs(speed + v[2] * r) <= 1e-11 * scale                 # rolling
    travelled = float((traj.q[-1, 0, :2] - c) @ s)
    expected_x = (v0 * t_roll + 0.5 * acc_slip * t_roll ** 2 + v_roll * (t - t_roll)
                  + 0.5 * acc_roll * (t - t_roll) ** 2)
    vmax = max(abs(v0), abs(v_roll), abs(speed))
    print(f"{kind}: rolls from {traj.t[first]:.4f} s (t* {t_roll:.4f}), distance off by "
          f"{(travelled - expected_x) / (dt * vmax):+.3f} h max|v|")
    assert abs(travelled - expected_x) <= dt * vmax
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("deg, k, mu, vs0, vn0, w0r, height, dt, r", [
    (10.0, 0.5, 0.5, 2.0, -1.0, -6.0, 0.3, 1e-3, 0.1), (20.0, 1.0, 0.3, -1.0, -5.0, 4.0, 0.05, 1e-2, 0.1),
    (5.0, 0.4, 1.0, 0.5, -20.0, 0.0, 0.5, 1e-3, 0.05), (30.0, 0.5, 1.2, 3.0, -2.0, 8.0, 1.0, 1e-4, 1e-3),
    (10.0, 0.5, 0.5, 2.0, -1.0, -6.0, 0.3, 1e-2, 10.0)])
def test_a_disk_dropped_spinning_onto_a_slope_rolls_at_the_speed_its_contact_momentum_gives(
        kind, deg, k, mu, vs0, vn0, w0r, height, dt, r):
    """A spinning disk thrown at a slope (vs0 along it, vn0 toward it, from `height` above it)
    lands plastically, skids and rolls: the landing's normal impulse passes through the centre
    and friction acts at the contact, so m v_s - I w / r grows by m g sin t through flight,
    impact and skid alike, and once rolling v_s = (vs0 - k r w0 + g sin t) / (1 + k), with no
    normal velocity left: to rounding at the end of every step, a time-of-impact split
    included. Measured: 2e-13."""
    a = math.radians(deg)
    s, n, c = _on_slope(deg, r)
    w0 = w0r / r
    sim = _disk(terrain.slope(-deg), r, k, mu, dt, kind, tuple(c + height * n),
                vel=tuple(vs0 * s + vn0 * n), omega=w0)
    steps = int(round(2.0 / dt))
    sim.steps(steps)
    t = steps * dt
    v = sim.state.v[0]
    expected = (vs0 - k * r * w0 + G * math.sin(a) * t) / (1.0 + k)
    scale = max(abs(vs0), abs(vn0), abs(w0r), abs(expected))
    assert abs(float(v[:2] @ s) - expected) <= 1e-12 * scale, (float(v[:2] @ s), expected)
    assert abs(float(v[:2] @ n)) <= 1e-12 * scale
    assert abs(float(v[:2] @ s) + v[2] * r) <= 1e-11 * scale
    assert np.all(sim.state.contact_mode == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("e", [0.0, 0.5, 0.9])
@pytest.mark.parametrize("deg, k, mu, vs0, vn0, w0r, height, dt, r", [
    (10.0, 0.5, 0.5, 2.0, -1.0, -6.0, 0.3, 1e-3, 0.1), (20.0, 1.0, 0.3, -1.0, -5.0, 4.0, 0.05, 1e-2, 0.1),
    (5.0, 0.4, 1.0, 0.5, -3.0, 0.0, 0.5, 1e-3, 0.05)])
def test_a_disk_bouncing_on_a_slope_keeps_its_contact_momentum_law_through_every_bounce(
        e, deg, k, mu, vs0, vn0, w0r, height, dt, r):
    """A spinning disk (a circle shape of restitution e) thrown at a slope bounces, skids and
    spins: every impulse the slope gives passes through the centre (normal) or acts at the
    contact (friction, within or at the cone's edge), so v_s - k r w = vs0 - k r w0 +
    g sin(alpha) t at the end of every step, whatever the bounces, the rebound's energy bound
    and the slides, to rounding. Measured: 6e-13."""
    a = math.radians(deg)
    s, n, c = _on_slope(deg, r)
    w0 = w0r / r
    b = ps.ModelBuilder(dt=dt, terrain=terrain.slope(-deg))
    b.add_body("disk", mass=1.0, inertia=k * r * r, pos=tuple(c + height * n),
               vel=tuple(vs0 * s + vn0 * n), omega=w0,
               shapes=[("circle", (0.0, 0.0), r, {"mu": mu, "restitution": e})])
    sim = ps.Simulator(b.compile())
    traj = sim.run(int(round(2.0 / dt)) * dt, record_every=1)
    law = traj.v[:, 0, :2] @ s - k * r * traj.v[:, 0, 2]
    expected = vs0 - k * r * w0 + G * math.sin(a) * traj.t
    scale = max(abs(vs0), abs(vn0), abs(w0r), float(np.abs(expected).max()))
    modes = traj.contact_mode[1:, 0]
    assert np.any(modes != 0) and (e == 0.0 or np.any(modes[int(np.argmax(modes != 0)):] == 0))
    assert np.abs(law - expected).max() <= 1e-12 * scale, np.abs(law - expected).max()
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("v0, dt, r", [(1e-3, 1e-2, 1e-3), (5.0, 1e-4, 10.0), (50.0, 1e-2, 0.01),
                                       (-3.0, 1e-3, 0.5)])
def test_a_disk_rolling_on_flat_ground_keeps_its_speed(kind, v0, dt, r):
    """A disk rolling on flat ground (no slip at the start) keeps its speed and spin exactly,
    travels v0 t and stays at height r: every row is linear and no force acts along the
    ground. Measured: rounding (1e-15 relative)."""
    sim = _disk(terrain.flat(), r, 0.5, 0.5, dt, kind, (0.0, r), vel=(v0, 0.0), omega=-v0 / r)
    steps = int(round(1.0 / dt))
    sim.steps(steps)
    q, v = sim.state.q[0], sim.state.v[0]
    assert abs(v[0] - v0) <= 1e-12 * abs(v0) and abs(v[1]) <= 1e-12 * abs(v0)
    assert abs(v[2] + v0 / r) <= 1e-12 * abs(v0) / r
    assert abs(q[0] - v0 * steps * dt) <= 1e-11 * abs(v0) and abs(q[1] - r) <= 1e-12 * max(r, 1.0)
    assert np.all(sim.state.contact_mode == MODE_PINNED)
    assert_clean(sim)


def rocker_period(R, d, m, inertia, amplitude, nodes=200):
    """The exact period [s] of a rocker (an arc sole of radius R whose centre lies d above the
    centre of mass) rolling without slip on flat ground from rest at `amplitude` [rad]:
    4 int_0^a0 sqrt(M(th) / (2 m g d (cos th - cos a0))) dth with M the inertia about the
    contact point, I + m (R^2 + d^2 - 2 R d cos th); th = a0 sin(phi) removes the root's
    singularity, and Gauss-Legendre sums the smooth rest."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    phi = (x + 1.0) * math.pi / 4.0
    th = amplitude * np.sin(phi)
    mass = inertia + m * (R * R + d * d - 2.0 * R * d * np.cos(th))
    drop = 4.0 * m * G * d * np.sin(0.5 * (amplitude + th)) * np.sin(0.5 * (amplitude - th))
    return float(4.0 * np.sum(np.sqrt(mass / drop) * amplitude * np.cos(phi) * w) * math.pi / 4.0)


def _rocker(kind, R, d, m, inertia, amplitude, dt):
    """A rocker released from rest rolled by `amplitude` on flat ground: its sole's centre at
    (-R a0, R), the centre of mass d below it along the body's turned axis."""
    b = ps.ModelBuilder(dt=dt)
    cx, cy = -R * amplitude, R
    pos = (cx + d * math.sin(amplitude), cy - d * math.cos(amplitude))
    if kind == "arc":
        body = b.add_body("rocker", mass=m, inertia=inertia, pos=pos, angle=amplitude)
        b.add_arc_contact("sole", body, (0.0, d), R, span=(-math.pi / 2 - 0.8, -math.pi / 2 + 0.8))
    else:
        b.add_body("rocker", mass=m, inertia=inertia, pos=pos, angle=amplitude,
                   shapes=[("circle", (0.0, d), R)])
    return ps.Simulator(b.compile())


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("R, d, m, inertia, amplitude, dt", [
    (0.5, 0.3, 1.0, 0.02, 0.01, 1e-3), (0.5, 0.3, 1.0, 0.02, 0.01, 1e-4), (1.0, 0.9, 2.0, 0.01, 0.01, 1e-3),
    (0.01, 0.005, 1.0, 1e-5, 0.01, 1e-4), (10.0, 2.0, 1.0, 1.0, 0.01, 1e-2)])
def test_a_rocker_rocks_with_its_closed_form_period(kind, R, d, m, inertia, amplitude, dt):
    """A rocker (sole radius R, its centre d above the centre of mass) rocking at small
    amplitude: period 2 pi sqrt((I + m (R - d)^2) / (m g d)), or exactly rocker_period at the
    amplitude. Symplectic Euler's oscillation is slower by its own frequency error,
    (w h)^2 / 24; the period measured over five swings (zero crossings, interpolated) meets the
    exact period within (w h)^2 / 12. Measured: -(w h)^2 / 24 to 5 %, rolling without slip
    throughout (the rocker's centre moves -R dtheta to 1e-12 m)."""
    sim = _rocker(kind, R, d, m, inertia, amplitude, dt)
    period = rocker_period(R, d, m, inertia, amplitude)
    small = 2 * math.pi * math.sqrt((inertia + m * (R - d) ** 2) / (m * G * d))
    assert abs(period / small - 1) < amplitude                   # the amplitude's correction
    traj = sim.run(5.2 * period, record_every=1)
    th, t = traj.q[:, 0, 2], traj.t
    down = np.nonzero((th[:-1] > 0) & (th[1:] <= 0))[0]
    crossing = t[down] + th[down] / (th[down] - th[down + 1]) * dt
    measured = float(np.mean(np.diff(crossing)))
    wh = 2 * math.pi / period * dt
    print(f"{kind} R={R} d={d} dt={dt}: period {measured / period - 1:+.3e} "
          f"((w h)^2/24 = {wh * wh / 24:.3e})")
    assert len(crossing) == 5
    assert abs(measured / period - 1) <= wh * wh / 12 + 1e-9
    centre_x = traj.q[:, 0, 0] - d * np.sin(th)
    assert np.abs(centre_x + R * th - centre_x[0] - R * th[0]).max() <= 1e-10 * max(R, 1.0)
    assert np.all(traj.contact_mode[1:, 0] == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("R, d, deg, dt", [(0.5, 0.3, 10.0, 1e-3), (0.5, 0.3, -20.0, 1e-4),
                                           (1.0, 0.9, 30.0, 1e-3)])
def test_a_rocker_on_a_slope_rocks_about_its_tilted_rest_with_the_closed_form_period(kind, R, d, deg, dt):
    """On a slope rising at alpha a rocker rests where its centre of mass is above the contact
    point: tilted by theta* = asin(R sin(alpha) / d). Rolled 1e-3 rad off it and released, it
    rocks about theta* at w^2 = m g d cos(theta*) / I_p, I_p = I + m |R n + d (sin theta*,
    -cos theta*)|^2 its inertia about the contact point: the period within (w h)^2 / 12
    (symplectic Euler's own shift, (w h)^2 / 24) plus amp^2 (the amplitude's, the potential
    being lopsided), and its swing's extremes within 1e-3 of +-amp about theta*.
    Measured: the period within 1.2e-6..2.8e-6 (6.4e-7 at dt 1e-4), the swing within 2.3e-4."""
    m, inertia, amp = 1.0, 0.02, 1e-3
    al = math.radians(deg)
    t = np.array([math.cos(al), math.sin(al)])
    n = np.array([-math.sin(al), math.cos(al)])
    rest = math.asin(R * math.sin(al) / d)
    th0 = rest + amp
    centre = R * n - R * amp * t                      # rolled by amp from touching at the origin
    com = centre + d * np.array([math.sin(th0), -math.cos(th0)])
    b = ps.ModelBuilder(dt=dt, terrain=terrain.slope(deg))
    if kind == "arc":
        body = b.add_body("rocker", mass=m, inertia=inertia, pos=tuple(com), angle=th0)
        b.add_arc_contact("sole", body, (0.0, d), R, mu=5.0)
    else:
        b.add_body("rocker", mass=m, inertia=inertia, pos=tuple(com), angle=th0,
                   shapes=[("circle", (0.0, d), R, {"mu": 5.0})])
    sim = ps.Simulator(b.compile())
    lever = R * n + d * np.array([math.sin(rest), -math.cos(rest)])
    w = math.sqrt(m * G * d * math.cos(rest) / (inertia + m * float(lever @ lever)))
    period = 2 * math.pi / w
    traj = sim.run(5.2 * period, record_every=1)
    th = traj.q[:, 0, 2] - rest
    down = np.nonzero((th[:-1] > 0) & (th[1:] <= 0))[0]
    crossing = traj.t[down] + th[down] / (th[down] - th[down + 1]) * dt
    measured = float(np.mean(np.diff(crossing)))
    wh = w * dt
    print(f"{kind} {deg} deg dt={dt}: period {measured / period - 1:+.2e} ((w h)^2/24 = "
          f"{wh * wh / 24:.1e}), swing {th.max() / amp - 1:+.1e}, {th.min() / amp + 1:+.1e}")
    assert len(crossing) == 5
    assert abs(measured / period - 1) <= wh * wh / 12 + amp * amp
    assert abs(th.max() - amp) <= 1e-3 * amp and abs(th.min() + amp) <= 1e-3 * amp
    assert np.all(traj.contact_mode[1:, 0] == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("amplitude, dt, R, d, inertia", [
    (0.3, 1e-3, 0.5, 0.3, 0.02), (0.7, 1e-2, 0.5, 0.3, 0.02),
    # sub-steps switched on in the fast part of each swing only (a long lever's turn judged
    # in metres, step.TURN_SHARE): -35 % at the 5 m rocker's dt 1e-2 (band 7 %)
    (0.6, 1e-2, 5.0, 4.5, 2.025), (0.6, 1e-3, 0.5, 0.45, 0.02025),
    # with its centre of mass 5 cm over the ground, the 0.5 m rocker's sole is held by a
    # correction that moves positions only, and its mean drifts as h^3 with no sub-step taken:
    # -0.06 % at dt 1e-3, -0.46 % at 2e-3, -6.7 % at 5e-3 (band 4.4 %)
    pytest.param(0.6, 5e-3, 0.5, 0.45, 0.02025, marks=pytest.mark.xfail(
        strict=True, reason="a held contact's position correction drifts the energy as h^3"))])
def test_a_rocker_rocking_without_slip_keeps_its_energy(amplitude, dt, R, d, inertia):
    """A rocker rolling without slip on flat ground is conservative (rolling is holonomic
    here: the sole's centre moves -R dtheta). Symplectic Euler's energy oscillates in a band
    of order w h about a modified energy and does not drift: the mean energy over the last of
    30 periods lies within that band (the first period's range) of the first period's mean.
    Measured, of the swing energy: -2.7e-6 at a0 0.3, dt 1e-3 (band 6.6e-3) and -1.3e-2 at
    a0 0.7, dt 1e-2 (band 5.5e-2); with a held contact's first-order target -5.5 % and -72 %
    (its correction, which moves a contact's positions only, took the energy)."""
    m = 1.0
    sim = _rocker("arc", R, d, m, inertia, amplitude, dt)
    period = rocker_period(R, d, m, inertia, amplitude)
    traj = sim.run(30 * period, record_every=1)
    q, v = traj.q[:, 0], traj.v[:, 0]
    energy = 0.5 * m * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * inertia * v[:, 2] ** 2 + m * G * q[:, 1]
    energy /= m * G * d * (1 - math.cos(amplitude))
    per = int(period / dt)
    first, last = energy[:per], energy[-per:]
    print(f"a0={amplitude} dt={dt}: band {first.max() - first.min():.2e}, mean moved "
          f"{last.mean() - first.mean():+.2e} of the swing energy in 30 periods")
    assert np.all(traj.contact_mode[1:, 0] == MODE_PINNED)
    assert_clean(sim)
    assert abs(last.mean() - first.mean()) <= first.max() - first.min()


def _hills_start(r):
    """(hills, start point on them, tangent there, centre of a disk of radius r touching)."""
    ter = terrain.hills(*HILLS)
    x0 = 0.3
    ground = np.array([x0, float(ter.height(x0))])
    return ter, ground, ter.tangent(x0), ground + r * ter.normal(x0)


def _centre_gap(ter, x, y, r):
    """Distance [m] of centres (x, y) from the hills minus r, by Newton on the foot of the
    perpendicular (independent of the engine's query; r times the hills' largest curvature
    below 1: one foot, and Newton's derivative 1 + h'^2 + (h - y) h'' stays positive)."""
    u = np.array(x, dtype=float)
    for _ in range(30):
        h, dh = ter.height(u), ter.slope(u)
        ddh = sum(-a * (2 * math.pi / lam) ** 2 * np.sin(2 * math.pi / lam * u + p)
                  for a, lam, p in zip(*HILLS))
        f = (u - x) + (h - y) * dh
        u = u - f / (1 + dh * dh + (h - y) * ddh)
    return np.hypot(u - x, ter.height(u) - y) * np.sign(y - ter.height(x)) - r


def _max_curvature():
    return sum(a * (2 * math.pi / lam) ** 2 for a, lam in zip(HILLS[0], HILLS[1]))


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("r, v0, dt, k", [(0.1, 2.0, 1e-3, 0.5), (0.1, 2.0, 1e-4, 0.5), (0.3, 2.0, 1e-3, 1.0),
                                          (0.01, 1.0, 1e-3, 0.5), (0.1, 2.0, 1e-2, 0.5),
                                          (2.0, 2.0, 1e-3, 0.5)])
def test_a_disk_rolling_over_hills_turns_by_its_paths_length_over_r_and_never_sinks(kind, r, v0, dt, k):
    """A disk rolling without slip over hills: its contact point is at rest, so its centre
    moves at |w| r along the curve parallel to the ground, and its turn is minus the centre's
    path length over r (signed). The energy, 1/2 m (1 + k) v^2 + m g y, oscillates within
    O(h) over 10 s; its centre stays r from the ground: never below it, and above it at most
    h^2 v^2 kappa (the step's chord over a crest, which the correction leaves: it never pulls
    a contact down). r = 2 m takes the engine's sampled closest-point search (the centre far
    from the ground for its curvature). Measured: the turn within 5e-6 rad (second order:
    3.5e-8 at dt 1e-4), the energy band 1.5 h [1/s] of its kinetic energy (2.9 h for
    r = 0.01 m at 1 m/s), the gap -4e-13..0.6 h^2 v^2 kappa."""
    ter, ground, tangent, c = _hills_start(r)
    sim = _disk(ter, r, k, 3.0, dt, kind, tuple(c), vel=tuple(v0 * tangent), omega=-v0 / r)
    traj = sim.run(10.0, record_every=1)
    q, v = traj.q[:, 0], traj.v[:, 0]
    dx, dy = np.diff(q[:, 0]), np.diff(q[:, 1])
    path = np.concatenate([[0.0], np.cumsum(np.sign(dx) * np.hypot(dx, dy))])
    turn_error = np.abs(q[:, 2] - q[0, 2] + path / r).max()
    energy = 0.5 * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * k * r * r * v[:, 2] ** 2 + G * q[:, 1]
    band = (energy.max() - energy.min()) / (0.5 * (1 + k) * v0 * v0)
    gap = _centre_gap(ter, q[::10, 0], q[::10, 1], r)
    lift = dt * dt * v0 * v0 * _max_curvature()
    print(f"{kind} r={r} v0={v0} dt={dt}: turn off by {turn_error:.1e} rad, energy band "
          f"{band / dt:.2f} h, gap {gap.min():.1e}..{gap.max() / lift:.2f} h^2 v^2 kappa")
    assert q[-1, 0] > 5.0                                         # it went over the hills
    assert turn_error <= 20 * dt * dt
    assert band <= 5 * dt
    assert gap.min() >= -1e-9 and gap.max() <= lift
    assert np.all(traj.contact_mode[1:, 0] == MODE_PINNED)
    assert_clean(sim)


@pytest.mark.parametrize("body", ["rolling disk", "frictionless point"])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_body_moving_over_hills_without_loss_keeps_its_energy(body, dt):
    """A disk rolling without slip, or a point mass sliding without friction, over the hills
    from 3 m/s, touching throughout: conservative (a holonomic constraint while the contact
    holds). Symplectic Euler's energy oscillates in a band of order h and does not drift: the
    mean energy over the last 5 s of 40 s lies within the first 5 s's band of their mean.
    Measured, of the start's kinetic energy at dt 1e-3 and 1e-2: the disk +6.8e-6 and +4.9e-5,
    the point +5.1e-5 and +4.6e-4; with a held contact's first-order target -0.41 % and -4.0 %,
    -0.70 % and -6.7 % (bands 0.09 % and 0.9 %, 0.14 % and 1.4 %)."""
    v0, r = 3.0, 0.1
    if body == "rolling disk":
        ter, ground, tangent, c = _hills_start(r)
        sim = _disk(ter, r, 0.5, 3.0, dt, "arc", tuple(c), vel=tuple(v0 * tangent), omega=-v0 / r)
        k = 0.5
    else:
        ter, ground, tangent, c = _hills_start(0.0)
        b = ps.ModelBuilder(dt=dt, terrain=ter)
        p = b.add_point_mass("p", 1.0, pos=tuple(ground), vel=tuple(v0 * tangent))
        b.add_point_contact("p", p, mu=0.0)
        sim = ps.Simulator(b.compile())
        k, r = 0.0, 0.0
    traj = sim.run(40.0, record_every=1)
    q, v = traj.q[:, 0], traj.v[:, 0]
    energy = 0.5 * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * k * r * r * v[:, 2] ** 2 + G * q[:, 1]
    energy /= 0.5 * (1 + k) * v0 * v0
    n5 = int(round(5.0 / dt))
    first, last = energy[:n5], energy[-n5:]
    print(f"{body} dt={dt}: band {first.max() - first.min():.2e}, mean moved "
          f"{last.mean() - first.mean():+.2e} of the start's kinetic energy in 40 s")
    modes = traj.contact_mode[1:, 0]
    assert np.all(modes == modes[0]) and modes[0] != 0               # touching throughout
    assert_clean(sim)
    assert abs(last.mean() - first.mean()) <= first.max() - first.min()


def _foot(ter, sign, dt, shift=0.0, kind="arc"):
    """An asymmetric curved foot (sole radius 0.3 m, its centre (0.05, 0.2) off the centre of
    mass, a heel and a toe) dropped 1 cm onto `ter` above x = shift, turning and moving; sign
    -1: its mirror image (x, theta, vx, omega negated; the span and vertices mirrored)."""
    b = ps.ModelBuilder(dt=dt, terrain=ter)
    off, R = (sign * 0.05, 0.2), 0.3
    a0, a1 = -math.pi / 2 - 0.9, -math.pi / 2 + 0.6
    if sign < 0:
        a0, a1 = -math.pi - a1, -math.pi - a0
    th = sign * 0.2
    c, s = math.cos(th), math.sin(th)
    pos = (shift - (c * off[0] - s * off[1]),
           float(ter.height(shift)) + R + 0.01 - (s * off[0] + c * off[1]))
    kw = dict(mass=2.0, inertia=0.05, pos=pos, angle=th, vel=(sign * 0.7, 0.0), omega=sign * 1.5)
    if kind == "arc":
        body = b.add_body("foot", **kw)
        b.add_arc_contact("sole", body, off, R, span=(a0, a1),
                          vertices=[(sign * 0.2, -0.05), (-sign * 0.2, -0.05)], mu=0.8)
    else:
        b.add_body("foot", **kw, shapes=[("circle", off, R, {"mu": 0.8})])
    return ps.Simulator(b.compile())


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("ground", ["slope", "hills"])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_curved_foot_on_the_mirrored_ground_moves_as_the_mirror_image(kind, ground, dt):
    """The mirror image (x -> -x) of a curved foot landing, rolling, slipping and rocking on a
    slope rising toward +x moves on the slope rising toward -x as the mirror image of the
    first run, contact mode for contact mode; on the hills mirrored (h(-x): phases pi - phi)
    too. On a slope every number is the mirror of the other's: bit for bit. On hills the
    sines of mirrored arguments round apart: within 1e-11 m over 3 s. Measured: bitwise on
    the slope, 1.6e-12 on the hills."""
    if ground == "slope":
        ter, mirrored, tol = terrain.slope(12.0), terrain.slope(-12.0), 0.0
    else:
        a, lam, phi = HILLS
        ter = terrain.hills(a, lam, phi)
        mirrored, tol = terrain.hills(a, lam, [math.pi - p for p in phi]), 1e-11
    one, two = _foot(ter, 1, dt, kind=kind), _foot(mirrored, -1, dt, kind=kind)
    t1, t2 = one.run(3.0, record_every=1), two.run(3.0, record_every=1)
    assert len(np.unique(t1.contact_mode[1:, 0])) >= 2                 # it lands and moves
    assert np.array_equal(t1.contact_mode, t2.contact_mode)
    assert np.abs(t1.q[:, 0, 0] + t2.q[:, 0, 0]).max() <= tol
    assert np.abs(t1.q[:, 0, 1] - t2.q[:, 0, 1]).max() <= tol
    assert np.abs(t1.q[:, 0, 2] + t2.q[:, 0, 2]).max() <= 10 * tol
    assert np.array_equal(audit_counts(one.ws), audit_counts(two.ws))


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("shift", [1e3, -37.25])
def test_a_disk_rolling_down_a_slope_moved_along_it_moves_alike(kind, shift):
    """A disk rolling down a slope, and the same disk started `shift` metres farther along
    the slope: the same motion moved by the shift (translation invariance), to the rounding of
    coordinates of that size (a few ulps of them a step over 2000 steps). Measured: 5.7e-10 m
    at 1 km (1.3 ulps a step), 5e-12 m at 37 m."""
    deg, r, dt = 12.0, 0.1, 1e-3
    s, n, c = _on_slope(deg, r)
    runs = []
    for offset in (0.0, shift):
        start = c + offset * s
        sim = _disk(terrain.slope(-deg), r, 0.5, 1.0, dt, kind, tuple(start), vel=tuple(1.5 * s),
                    omega=-1.5 / r)
        traj = sim.run(2.0, record_every=1)
        runs.append(traj.q[:, 0] - np.array([start[0], start[1], 0.0]))
        assert_clean(sim)
    tol = 2000 * 4 * 2.2e-16 * (abs(shift) + 10.0)      # four ulps of the coordinates a step
    assert np.abs(runs[1] - runs[0]).max() <= tol, np.abs(runs[1] - runs[0]).max()


@pytest.mark.parametrize("ratio", [0.3, 0.5, 0.6, 0.8, 0.9])
@pytest.mark.parametrize("dt", [1e-3, 1e-4])
def test_a_point_sliding_over_a_crest_touches_it_while_the_ground_pushes(ratio, dt):
    """A frictionless point leaves the top of a crest of curvature k at speed v with
    v^2 k = ratio g: below g the ground pushes with N = m (g - v^2 k) > 0 (and on for the
    next 0.02 s, N >= 0.2 m g at 0.8), so the point touches it in every step (mode sliding,
    a normal impulse each step) and stays on it to the step's chord over the crest,
    k v^2 h^2 / 2. Measured: no step free and the point never above the ground at 0.3-0.9 g,
    dt 1e-3 and 1e-4; with a held contact's first-order target (its normal velocity held along
    the start's normal, which the next start's has turned from by k v h) 60 % of the steps
    read free at 0.8 g and 79-80 % at 0.9 g, at either dt, in hops up to 1.4 h^2 v^2 k high."""
    amplitude, wavelength = 0.1, 4.0
    k = amplitude * (2 * math.pi / wavelength) ** 2
    ter = terrain.hills([amplitude], [wavelength], [math.pi / 2])     # the crest's top at x = 0
    v0 = math.sqrt(ratio * G / k)
    b = ps.ModelBuilder(dt=dt, terrain=ter)
    p = b.add_point_mass("p", 1.0, pos=(0.0, amplitude), vel=(v0, 0.0))
    b.add_point_contact("p", p, mu=0.0)
    sim = ps.Simulator(b.compile())
    traj = sim.run(int(round(0.02 / dt)) * dt, record_every=1)
    q = traj.q[:, 0]
    gap = q[:, 1] - ter.height(q[:, 0])
    modes = traj.contact_mode[1:, 0]
    print(f"v^2 k = {ratio} g, dt={dt}: {np.mean(modes == 0):.0%} of the steps free, hops up to "
          f"{gap.max() / (dt * dt * v0 * v0 * k):.2f} h^2 v^2 k")
    assert_clean(sim)
    assert gap.min() >= -1e-12
    assert np.all(modes == MODE_SLIDING)
    assert gap.max() <= 0.5 * (1 + 1e-3) * dt * dt * v0 * v0 * k


@pytest.mark.parametrize("kind", ["arc", "circle"])
@pytest.mark.parametrize("periods", [3, -100])
def test_a_disk_rolling_over_periodic_hills_moved_by_whole_wavelengths_moves_alike(kind, periods):
    """One sine repeats every wavelength L: a disk rolling over it from x0 and from x0 + n L
    moves alike, shifted by n L, to the rounding of the sines' arguments (of size w n L).
    Measured: 1.1e-12 m and 6.8e-12 rad at n = -100 over 3 s."""
    wavelength, r, v0 = 3.0, 0.1, 2.0
    ter = terrain.hills([0.1], [wavelength], [0.4])
    runs = []
    for shift in (0.0, periods * wavelength):
        x0 = 0.3 + shift
        c = np.array([x0, float(ter.height(x0))]) + r * ter.normal(x0)
        sim = _disk(ter, r, 0.5, 1.0, 1e-3, kind, tuple(c), vel=tuple(v0 * ter.tangent(x0)),
                    omega=-v0 / r)
        traj = sim.run(3.0, record_every=1)
        assert np.all(traj.contact_mode[1:, 0] == MODE_PINNED)
        assert_clean(sim)
        runs.append(traj.q[:, 0] - np.array([shift, 0.0, 0.0]))
    tol = 3000 * 4 * 2.2e-16 * (abs(periods) * wavelength + 10.0)
    assert np.abs(runs[1] - runs[0]).max() <= tol, np.abs(runs[1] - runs[0]).max()
