"""Joint limits, joint springs and dampers, dry joint friction, sliders and rods at their
extremes, against closed forms and conservation laws, in the families the other physics tests
leave out.

What is checked, each against what the scheme itself gives:
- limits (plastic, no restitution): a pendulum falling onto its hinge's limit (1e-3..1e3 kg,
  dt 1e-4..1e-2) never passes it, rests on it exactly and is held there for 10^4 steps, the
  limit's impulse then h m g d sin(limit); a link spun onto its limit in zero gravity stops
  dead (its angular momentum about the hinge all removed); two coaxial wheels meeting their
  relative limit, and two free bodies meeting their slider's limit (mass ratios 1e-3..1e3),
  end at the plastic impact's common velocity and energy to rounding; a block meeting a
  slider's limit (1e-3..1e3 kg) stops with the impulse m v0, and one sliding down onto it is
  held there for 10^4 steps with the impulse h m g sin(slope); a joint driven off its limit
  leaves it at once on symplectic Euler's parabola; a limit of zero width locks the joint; a
  limit beyond half a turn holds (the angle is not wrapped); a spring pressing a joint onto
  its limit is held there by an impulse h k (rest - limit);
- springs and dampers: a hinge spring of any stiffness (k 1e-3..1e9, dt 1e-4..1e-2) takes the
  theta-recurrence of kernels/constraints/soft.py to rounding and, where the step does not
  resolve it, never lets the amplitude grow; critically and over-damped springs follow their
  closed forms to O(h w) without overshoot; a damper alone on an off-centre hinge brakes
  its link by backward Euler about the hinge to SHAKE's O((h w)^2); a chain of ten links with spring-dampers in zero
  gravity keeps its angular momentum to rounding, never rises above its first step's energy
  and settles into a rigid spin;
- dry friction (frictionloss) at its threshold, both sides (gravity's torque 1e-6 above and
  below it), and a spring with dry friction, whose swing shrinks by 2 F / k every half
  period and stops within F / k of the rest angle;
- rods: a point mass on a rod round a pivot and a dumbbell (mass ratios 1e-3..1e3, 0.1 and 0.5
  rad a step) take SHAKE's first-step energy rise (1 - sqrt(1 - (h w)^2))^2 / (h w)^2 to
  rounding, keep their length to 1e-12 m and their energy after it; a chain of two rods and
  three point masses of ratios 1e-3..1e3 keeps both momenta to rounding;
- the joints' readouts (planarsim.measure.pin_angle_rate) against the bodies' states: a
  hinge's rate is the finite difference of its angle to rounding, a turning slider's to O(h).

Silent defects found here are xfail(strict=True) with their measurements in DEFECTS: a
damped chain at rest, or turning rigidly, does not balance its springs against gravity or
the spin (rest_bias), a chain of rods with a light middle mass straightening loses angular
momentum and energy (rod_whip). Mended: a limit that the build pose violates was accepted
and ignored (limit_outside_build_pose), and the impulses a limit's impact steps recorded
(State.last_pin_impulse) summed to J w0 (1 + 1.5e-3) at 0.1 rad a step, not to the momentum J
w0 it removed, because the position correction's share of the velocity change was not
recorded (limit_impulse_readout; now to rounding). A loud one is mended: a stiff spring released from a stretch
was stopped by the speed guard as if it had left physics (the speed bound now counts the
springs' energy). Two silent ones are mended: a damper too weak to matter on a hinge spring
whose body's centre lies off the hinge left 1.8e-12 of the energy after 1 s, and a slider's
spring anchored off its body's centre 7.2e-4 (the step judged the springs' angle h w by the
inverse inertia of their row alone, 1 / I about the centre, 1 / m + lever^2 / I across the
slide, not by the inertia the joints leave free to move: about the hinge, 1 / m; judged too
stiff, they took a share of backward Euler that damped them).
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import planarsim as ps
from planarsim import measure
from planarsim.compiled import audit_counts
from planarsim.energy import total_energy

G = 9.81

DEFECTS = {
    "rest_bias": (
        "a chain of links hanging from the world with a spring and damper at every hinge "
        "comes to rest (|v| < 1e-11) in a pose whose springs do not balance gravity: ten "
        "0.2 m, 0.3 kg links, k 5 N m/rad, c 3 N m s/rad (20 at the top), rest angles 0.1 "
        "rad: the torque balance about each hinge is off by up to 4.0 % of its gravity "
        "torque at dt 1e-2 (the lowest hinge), 0.23 % at 3e-3, 0.011 % at 1e-3; two links: "
        "3.3e-5 at dt 1e-2 (7.5e-5 with c 30); one link: 6e-13. At rest the damper should "
        "give no torque and the springs balance gravity exactly. The same in steady rotation: "
        "the ten links floating free in zero gravity, spinning at 1.93 rad/s, settle into "
        "a rigidly turning arc (hinge rates < 1e-9 rad/s) whose springs miss the centrifugal "
        "torque at the end hinges by 17 % (c 5, dt 1e-2), 4.5 % (c 0.5, dt 1e-2), 0.65 % "
        "(c 0.5, dt 3e-3), 0.074 % (c 0.5, dt 1e-3), and whose shape is not symmetric "
        "(end bends 0.0083 and 0.0063 rad at c 5, dt 1e-2). Suspected cause: the "
        "damper acts on the velocity solve's joint rates, which at a fixed point of the "
        "step are not zero: the pins' second-order target is linearized at the predicted "
        "end q + h v_lin (gravity's free fall, which opens the pins), and the rate that "
        "target asks for is then removed by the position correction, so the damper holds "
        "the chain against a rate it never has"),
    "rod_whip": (
        "three point masses (1, 1e-3, 1 kg) joined by two 0.5 m rods, bent 0.3 rad and "
        "straightening (outer masses 1 m/s apart, the whole turning at 1 rad/s, zero "
        "gravity): as the chain snaps straight the light middle mass whips; at dt 1e-3 the "
        "two steps of the snap lose 0.19 % of the angular momentum (rod impulses are central "
        "and keep it at any step) and 81 % of the kinetic energy, with no audit count (dt "
        "1e-4: 8e-15 and +3.5e-5; middle mass 1e-2 at dt 1e-3: 7e-15). A chain of (1, 1e-3, "
        "1) kg started with velocities the rods do not allow loses 0.16 % at its snap at dt "
        "1e-3 (1.7 % at 1e-2, two pin_gap counts). Suspected cause: the snap's steps take "
        "the positions' projection (step_info projections 4) outside SHAKE's whole "
        "correction (shake_whole 0), whose energy bound (integrate.bound_correction_work) "
        "cuts the velocity change the move needs: as in test_known_defects' coarse_whip"),
}


def assert_clean(sim):
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


def _masses_on_two_rods(ms, pts, vs, dt):
    """A Simulator of three point masses ms [kg] at pts [m] moving at vs [m/s], joined by rods
    p0-p1 and p1-p2, in zero gravity without ground, at step dt [s]."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    for i, (m, p, v) in enumerate(zip(ms, pts, vs)):
        b.add_point_mass(f"p{i}", m, pos=tuple(p), vel=tuple(v))
    b.add_rod("r0", "p0", "p1")
    b.add_rod("r1", "p1", "p2")
    return ps.Simulator(b.compile())


def _point_masses_L(sim, ms):
    """Angular momentum [N m s] about the origin of point masses ms [kg] in sim's state."""
    q, v = sim.state.q, sim.state.v
    return np.sum(ms * (q[:, 0] * v[:, 1] - q[:, 1] * v[:, 0]))


def _pendulum(m, length, a0, dt, **pin):
    """A thin rod of mass m [kg] and `length` [m] hanging from a world hinge at its end, at
    a0 [rad] from hanging down (its angle = the pin's, ref 0)."""
    b = ps.ModelBuilder(dt=dt)
    b.add_body("rod", m, m * length * length / 12,
               pos=(length / 2 * math.sin(a0), -length / 2 * math.cos(a0)), angle=a0)
    b.add_pin("hinge", None, "rod", anchor_world=(0.0, 0.0), ref_angle=0.0, **pin)
    return b.compile()


def _wheel(dt, inertia, theta0=0.0, omega=0.0, mass=1.0, d=0.0, motor=False, **pin):
    """A body (mass, inertia about its centre) whose centre lies d [m] from a world hinge at
    the origin, at angle theta0 turning at omega, zero gravity; the hinge's keywords `pin`."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("w", mass, inertia, pos=(d * math.cos(theta0), d * math.sin(theta0)), angle=theta0,
               vel=(-omega * d * math.sin(theta0), omega * d * math.cos(theta0)), omega=omega)
    b.add_pin("hinge", None, "w", anchor_world=(0.0, 0.0), ref_angle=0.0, **pin)
    if motor:
        b.add_pin_motor("m", "hinge")
    return b.compile()


# --- limits ----------------------------------------------------------------------------------

@pytest.mark.parametrize("m, dt", [(1e-3, 1e-3), (1.0, 1e-2), (1e3, 1e-4), (1.0, 1e-3)])
def test_a_pendulum_falling_onto_its_limit_stops_there_and_is_held(m, dt):
    """A rod released horizontal falls onto its hinge's lower limit (0.3 rad from hanging)
    at 7.5 rad/s: a limit is plastic, so it never passes it, rests on it (the angle exactly
    the limit, rate 0), gains no energy, and is held there by gravity for 10^4 steps with the
    limit's impulse h m g (L / 2) sin(0.3) a step (the solve meets its equation to rounding).
    Measured: never a bit past the limit, rate 0, the impulse to 1.2e-10 (1e3 kg), 1e-13 else."""
    length, lim = 0.5, 0.3
    model = _pendulum(m, length, math.pi / 2, dt, limit=(lim, 2.0))
    sim = ps.Simulator(model)
    e0 = total_energy(model, sim.state.q, sim.state.v)
    low, high = math.inf, -math.inf
    n = max(10000, int(round(1.0 / dt)))
    for k in range(n):
        sim.step()
        low = min(low, sim.state.q[0, 2])
        if k >= n - 10000:
            high = max(high, total_energy(model, sim.state.q, sim.state.v))
    ang, rate = measure.pin_angle_rate(model, sim.state.q, sim.state.v, "hinge")
    held = dt * m * G * length / 2 * math.sin(lim)
    print(f"m={m} dt={dt}: lowest {low - lim:+.1e}, rest {ang - lim:+.1e} rad at {rate:.1e} "
          f"rad/s, impulse {sim.state.last_pin_impulse[0, 2] / held - 1:+.1e}")
    assert low >= lim - 1e-14
    assert abs(ang - lim) <= 1e-12 and abs(rate) <= 1e-12
    assert high <= e0 + 1e-12 * m * G * length
    assert sim.state.last_pin_impulse[0, 2] == pytest.approx(held, rel=1e-9)
    assert sim.state.limit_active[0, 0] == 1
    assert_clean(sim)


@pytest.mark.parametrize("m, dt, w0", [(1e-3, 1e-3, 5.0), (1.0, 1e-2, 20.0), (1e3, 1e-4, 50.0),
                                       (1.0, 1e-3, 100.0)])
def test_a_link_spun_onto_its_limit_stops_dead(m, dt, w0):
    """A link whose centre lies 0.3 m off a world hinge, spinning at w0 in zero gravity (0.005
    to 0.2 rad a step), meets its limit at 1 rad: the limit stops it dead (a plastic stop: its
    angular momentum J w0 about the hinge all removed, no bounce), on the limit exactly.
    Measured: rate <= 2.4e-14 rad/s, speed <= 1.4e-13 m/s, angle within 2.1e-14 rad."""
    d, inertia = 0.3, 0.01 * m
    model = _wheel(dt, inertia, omega=w0, mass=m, d=d, limit=(-1.0, 1.0))
    sim = ps.Simulator(model)
    top = -math.inf
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        top = max(top, sim.state.q[0, 2])
    print(f"m={m} dt={dt} w0={w0}: passed by {top - 1:.1e}, rests {sim.state.q[0, 2] - 1:+.1e}, "
          f"v {np.abs(sim.state.v).max():.1e}")
    assert top <= 1.0 + 1e-12
    assert abs(sim.state.q[0, 2] - 1.0) <= 1e-12
    assert np.abs(sim.state.v[0, :2]).max() <= 1e-12 * w0 * d
    assert abs(sim.state.v[0, 2]) <= 1e-12 * w0
    assert_clean(sim)


@pytest.mark.parametrize("dt, w0", [(1e-3, 100.0), (1e-2, 20.0), (1e-2, 5.0), (1e-3, 5.0)])
def test_a_limits_recorded_impulses_are_the_momentum_it_removed(dt, w0):
    """The link of test_a_link_spun_onto_its_limit_stops_dead (1 kg): only the limit's
    impulses turn it about the hinge, so the impulses it records over the impact add up to J w0,
    J = I + m d^2, to rounding (measured: 0 and 1.3e-15 at the first two; before the
    correction's share was recorded, 1.5e-3 and 5.4e-4 over)."""
    d, inertia = 0.3, 0.01
    model = _wheel(dt, inertia, omega=w0, d=d, limit=(-1.0, 1.0))
    sim = ps.Simulator(model)
    total = 0.0
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        total += sim.state.last_pin_impulse[0, 3]
    J = inertia + d * d
    print(f"dt={dt} w0={w0}: recorded / (J w0) - 1 = {total / (J * w0) - 1:+.2e}")
    assert abs(sim.state.v[0, 2]) <= 1e-12 * w0
    assert total == pytest.approx(J * w0, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(mass=st.floats(0.01, 100.0), shape=st.floats(1e-3, 1.0), d=st.floats(0.05, 1.0),
       w0=st.floats(-40.0, 40.0), dt=st.sampled_from([1e-4, 1e-3, 1e-2]),
       chain_path=st.booleans())
def test_a_pins_recorded_impulses_are_the_momentum_it_moved(mass, shape, d, w0, dt, chain_path):
    """A link (mass [kg], inertia shape m d^2 about its centre) hung from a world pin d [m]
    from its centre, spun at w0 [rad/s] under gravity for 0.2 s, by the pin-chain path or the
    general stages: the pin alone and gravity move its centre, so the impulses the pin
    records (State.last_pin_impulse, x and y) add up to m (v - v0) - m g t to rounding."""
    g = -9.81
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, g), ground=None)
    b.add_body("link", mass, shape * mass * d * d, pos=(d, 0.0), omega=w0)
    b.add_pin("hinge", None, "link", anchor_world=(0.0, 0.0))
    sim = ps.Simulator(b.compile())
    sim.ws.chain_on[0] = int(chain_path)
    v0 = sim.state.v[0, :2].copy()
    recorded = np.zeros(2)
    n = int(round(0.2 / dt))
    for _ in range(n):
        sim.step()
        recorded += sim.state.last_pin_impulse[0, :2]
    moved = mass * (sim.state.v[0, :2] - v0) - np.array([0.0, mass * g * n * dt])
    scale = mass * (abs(w0) * d + abs(g) * n * dt)
    assert np.abs(recorded - moved).max() <= 1e-12 * n * scale


@pytest.mark.parametrize("ratio, dt", [(1e-3, 1e-3), (1.0, 1e-2), (1e3, 1e-3)])
def test_coaxial_wheels_meeting_their_limit_end_at_the_plastic_closed_form(ratio, dt):
    """Two wheels on one axle (a hinge through both centres, zero gravity) turning at -2 and 5
    rad/s meet their relative limit: a plastic impact, so they end turning together at
    (Ia wa + Ib wb) / (Ia + Ib) with the kinetic energy (Ia + Ib) w^2 / 2 (the loss Ia Ib /
    (Ia + Ib) (wa - wb)^2 / 2), the relative angle on the limit, the axle still. Measured:
    rates and energy to 2.2e-16, the angle to 7.6e-14 rad."""
    ia, ib, wa, wb = 0.1, 0.1 * ratio, -2.0, 5.0
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", 1.0, ia, omega=wa)
    b.add_body("b", ratio, ib, omega=wb)
    b.add_pin("axle", "a", "b", anchor_world=(0.0, 0.0), limit=(-0.5, 0.5))
    sim = ps.Simulator(b.compile())
    sim.steps(int(round(2.0 / dt)))
    v, q = sim.state.v, sim.state.q
    w = (ia * wa + ib * wb) / (ia + ib)
    ke = 0.5 * (ia * v[0, 2] ** 2 + ib * v[1, 2] ** 2)
    assert v[0, 2] == pytest.approx(w, rel=1e-12) and v[1, 2] == pytest.approx(w, rel=1e-12)
    assert ke == pytest.approx(0.5 * (ia + ib) * w * w, rel=1e-12)
    assert abs(q[1, 2] - q[0, 2] - 0.5) <= 1e-12
    assert np.abs(q[:, :2]).max() <= 1e-12 and np.abs(v[:, :2]).max() <= 1e-12
    assert_clean(sim)


@pytest.mark.parametrize("ratio, dt", [(1e-3, 1e-3), (1.0, 1e-2), (1e3, 1e-3)])
def test_a_slider_pair_meeting_its_limit_ends_at_the_plastic_closed_form(ratio, dt):
    """Two free bodies on a slider along x (1 kg at -1 m/s, `ratio` kg at 3 m/s, zero
    gravity) meet the slider's upper limit: they end moving together at the momentum's
    velocity (ma va + mb vb) / (ma + mb), the slide on the limit, nothing off the axis.
    Measured: velocities to 2.2e-16, the slide to 1e-14 m."""
    ma, mb, va, vb = 1.0, ratio, -1.0, 3.0
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", ma, 0.1 * ma, vel=(va, 0.0))
    b.add_body("b", mb, 0.1 * mb, pos=(0.2, 0.0), vel=(vb, 0.0))
    b.add_slider("rail", "a", "b", axis=(1.0, 0.0), limit=(-0.1, 0.5))
    model = b.compile()
    sim = ps.Simulator(model)
    sim.steps(int(round(1.0 / dt)))
    vc = (ma * va + mb * vb) / (ma + mb)
    s, rate = measure.pin_angle_rate(model, sim.state.q, sim.state.v, "rail")
    assert sim.state.v[:, 0] == pytest.approx([vc, vc], rel=1e-12)
    assert abs(s - 0.5) <= 1e-12 and abs(rate) <= 1e-12 * abs(vb - va)
    assert np.abs(sim.state.v[:, 1:]).max() <= 1e-12 and np.abs(sim.state.q[:, 1:]).max() <= 1e-12
    assert_clean(sim)


@pytest.mark.parametrize("m, dt", [(1e-3, 1e-2), (1.0, 1e-3), (1e3, 1e-4)])
def test_a_block_meeting_its_sliders_limit_stops_with_the_impulse_m_v0(m, dt):
    """A block on a slider to the world at 2 m/s meets its limit at 0.5 m: it stops dead on
    the limit, and the limit's impulses add up to its momentum m v0 (a world slider along x:
    nothing else acts along it). Measured: exactly 0 m past, speed 2.2e-16, impulse exact."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", m, 0.1 * m, vel=(2.0, 0.0))
    b.add_slider("rail", None, "a", axis=(1.0, 0.0), limit=(-0.1, 0.5))
    sim = ps.Simulator(b.compile())
    total, far = 0.0, -math.inf
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        total += sim.state.last_pin_impulse[0, 3]
        far = max(far, sim.state.q[0, 0])
    assert far <= 0.5 + 1e-12 and abs(sim.state.q[0, 0] - 0.5) <= 1e-12
    assert np.abs(sim.state.v[0]).max() <= 1e-12
    assert total == pytest.approx(2.0 * m, rel=1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("m, dt", [(1e-3, 1e-2), (1.0, 1e-3), (1e3, 1e-4)])
def test_a_block_sliding_down_onto_its_limit_is_held_there(m, dt):
    """A block on a world slider descending at 30 degrees (its anchor on its centre) slides
    0.05 m down onto the slider's limit, then is held there by gravity for 10^4 steps: never
    past it, at rest on it, its angle kept, the limit's impulse h m g sin(30 deg) a step.
    Measured: 9e-17 m past, speed 4e-14 m/s, the impulse to 2.2e-16."""
    a = math.radians(30.0)
    b = ps.ModelBuilder(dt=dt)
    b.add_body("block", m, 0.1 * m, pos=(0.0, 1.0), angle=0.2)
    b.add_slider("rail", None, "block", axis=(math.cos(a), -math.sin(a)), limit=(-1.0, 0.05))
    model = b.compile()
    sim = ps.Simulator(model)
    far = -math.inf
    for _ in range(10000 + int(round(0.5 / dt))):
        sim.step()
        far = max(far, measure.pin_angle_rate(model, sim.state.q, sim.state.v, "rail")[0])
    s, rate = measure.pin_angle_rate(model, sim.state.q, sim.state.v, "rail")
    assert far <= 0.05 + 1e-12 and abs(s - 0.05) <= 1e-12 and abs(rate) <= 1e-12
    assert np.abs(sim.state.v[0]).max() <= 1e-12 and sim.state.q[0, 2] == 0.2
    assert sim.state.last_pin_impulse[0, 3] == pytest.approx(dt * m * G * math.sin(a), rel=1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("inertia, dt", [(0.1, 1e-3), (1e-3, 1e-2), (1e3, 1e-4)])
def test_a_joint_driven_off_its_limit_leaves_it_at_once(inertia, dt):
    """A motor holds a wheel on its hinge's upper limit, then reverses: a limit only pushes,
    so from the first step the wheel turns away on symplectic Euler's parabola
    theta_n = -h^2 tau / J n (n + 1) / 2 exactly (measured: to 3.3e-16 rad)."""
    model = _wheel(dt, inertia, motor=True, limit=(-0.5, 0.0))
    sim = ps.Simulator(model)
    sim.steps(100, np.array([inertia * 10.0]))
    assert sim.state.limit_active[0, 1] == 1 and sim.state.q[0, 2] == pytest.approx(0.0, abs=1e-14)
    tau = -20.0 * inertia
    err = 0.0
    n = int(math.sqrt(0.4 * 2 / (20.0 * dt * dt)))      # until 0.4 rad, short of the other side
    for k in range(1, n + 1):
        sim.step(np.array([tau]))
        err = max(err, abs(sim.state.q[0, 2] - dt * dt * tau / inertia * k * (k + 1) / 2))
    print(f"I={inertia} dt={dt}: {n} steps off the limit, largest error {err:.1e} rad")
    assert err <= 1e-13
    assert_clean(sim)


def test_a_limit_of_zero_width_locks_the_joint():
    """limit=(a, a) at the build pose locks a pendulum 0.3 rad from hanging: held there by
    both sides for 10^4 steps (measured: the angle exact, the speed 1e-14 m/s)."""
    model = _pendulum(1.0, 0.5, 0.3, 1e-3, limit=(0.3, 0.3))
    sim = ps.Simulator(model)
    sim.steps(10000)
    assert abs(sim.state.q[0, 2] - 0.3) <= 1e-12
    assert np.abs(sim.state.v[0]).max() <= 1e-12
    assert_clean(sim)


def test_a_limit_beyond_half_a_turn_holds():
    """A hinge's angle is not wrapped: a wheel spinning at 10 rad/s with limits at +-10 rad
    turns 1.6 times round and stops on its limit at exactly 10 rad."""
    model = _wheel(1e-3, 0.1, omega=10.0, limit=(-10.0, 10.0))
    sim = ps.Simulator(model)
    sim.steps(3000)
    assert abs(sim.state.q[0, 2] - 10.0) <= 1e-12 and abs(sim.state.v[0, 2]) <= 1e-12
    assert_clean(sim)


@pytest.mark.parametrize("inertia, k, c, dt", [(0.1, 2.0, 0.0, 1e-3), (0.1, 2.0, 0.5, 1e-3),
                                               (1e-3, 1e4, 0.0, 1e-2), (1e3, 1e6, 10.0, 1e-3)])
def test_a_spring_pressing_a_joint_onto_its_limit_is_held_by_h_k_stretch(inertia, k, c, dt):
    """A hinge spring whose rest angle (1 rad) lies beyond the upper limit (0.2 rad): with or
    without a damper, resolved or not, the wheel swings onto the limit, never passes it and
    rests there, the limit's impulse h k (1 - 0.2) a step (measured: to 9e-15)."""
    model = _wheel(dt, inertia, limit=(-0.3, 0.2), stiffness=k, damping=c, rest_angle=1.0)
    sim = ps.Simulator(model, ps.make_options(speed_limit=0.0))
    top = -math.inf
    for _ in range(int(round(3.0 / dt))):
        sim.step()
        top = max(top, sim.state.q[0, 2])
    assert top <= 0.2 + 1e-12
    assert abs(sim.state.q[0, 2] - 0.2) <= 1e-12 and abs(sim.state.v[0, 2]) <= 1e-12
    assert sim.state.last_pin_impulse[0, 3] == pytest.approx(dt * k * 0.8, rel=1e-12)
    assert_clean(sim)


def _kinetic(model, v):
    """Kinetic energy [J] of the bodies at velocities v."""
    a = model.arrays
    return 0.5 * float(np.sum(a.body_mass * (v[:, 0] ** 2 + v[:, 1] ** 2)
                              + a.body_inertia * v[:, 2] ** 2))


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
@pytest.mark.parametrize("a0, limit, w0", [
    (0.5, (-0.2, 0.2), 0.0), (-0.5, (-0.2, 0.2), 0.0), (2.0, (-0.2, 0.2), 0.0),
    (0.5, (0.6, 1.0), 0.0), (0.5, (-0.2, 0.2), 3.0), (0.5, (-0.2, 0.2), -3.0)])
def test_a_hinge_built_outside_its_limit_is_put_onto_it_by_the_first_step(a0, limit, w0, dt):
    """A 0.5 m rod on a world hinge built a0 [rad] from hanging, outside its limit, at rest or
    turning w0 [rad/s] (away from the limit or towards it): the Simulator warns naming the
    joint; the first step ends on the limit (within 1e-9 rad) with the pin closed; the
    move onto it adds no kinetic energy (the step's free motion's, at most: from rest, the
    fall h g; turning away, the turn is stopped, plastic as a limit is); then the rod stays
    within its limit for a second with no audit count. (It swung freely outside before:
    0.429 rad after 0.1 s with limit (-0.2, 0.2), no audit count.)"""
    m, length, g = 1.0, 0.5, 9.81
    b = ps.ModelBuilder(dt=dt)
    d = length / 2
    b.add_body("rod", m, m * length * length / 12, pos=(d * math.sin(a0), -d * math.cos(a0)),
               angle=a0, vel=(d * math.cos(a0) * w0, d * math.sin(a0) * w0), omega=w0)
    b.add_pin("hinge", None, "rod", anchor_world=(0.0, 0.0), ref_angle=0.0, limit=limit)
    model = b.compile()
    with pytest.warns(UserWarning, match=r"joint 'hinge' \(0\) starts at .* outside its limit"):
        sim = ps.Simulator(model)
    e0 = _kinetic(model, sim.state.v)
    sim.step()
    ang = sim.state.q[0, 2]
    side = limit[0] if a0 < limit[0] else limit[1]
    assert abs(ang - side) <= 1e-9, ang
    free = 0.5 * m * (abs(w0) * d + g * dt) ** 2 + 0.5 * (m * length * length / 12) * w0 ** 2
    assert _kinetic(model, sim.state.v) <= free * (1.0 + 1e-9) + 1e-15
    if w0 * (1 if side == limit[1] else -1) > 0:        # turning away: stopped dead
        assert _kinetic(model, sim.state.v) <= 0.5 * m * (g * dt) ** 2 + 1e-12
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        assert limit[0] - 1e-9 <= sim.state.q[0, 2] <= limit[1] + 1e-9
    assert_clean(sim)


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_slider_and_a_chain_built_outside_their_limits_are_put_onto_them(dt):
    """A block on a world slider whose slide starts 0.2 m below its limit (0.2, 0.5), and a
    hanging two-link chain whose lower hinge starts 0.4 rad past its upper limit: after one
    step the slide is on its limit (1e-9 m) and the hinge within its (the projection turns
    both links: measured 0.180 rad at dt 1e-3), every pin and the slider closed, no
    kinetic energy beyond the fall's h g; then a second within the limits, no audit count."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, -9.81))
    b.add_body("block", 2.0, 0.05, pos=(0.0, 1.0))
    b.add_slider("rail", None, "block", axis=(0.0, 1.0), limit=(0.2, 0.5))
    b.add_body("upper", 1.0, 0.02, pos=(2.0, 0.75))
    b.add_pin("top", None, "upper", anchor_world=(2.0, 1.0))
    a = 0.6
    b.add_body("lower", 1.0, 0.02, pos=(2.0 + 0.25 * math.sin(a), 0.5 - 0.25 * math.cos(a)),
               angle=a)
    b.add_pin("knee", "upper", "lower", anchor_world=(2.0, 0.5), ref_angle=0.0, limit=(-0.2, 0.2))
    model = b.compile()
    with pytest.warns(UserWarning, match=r"joint .knee. \(2\) starts at 0.6 rad, 0.4 rad outside its limit .* \(and 1 more joint\)"):
        sim = ps.Simulator(model)
    sim.step()
    q = sim.state.q
    assert abs((q[0, 1] - 1.0) - 0.2) <= 1e-9, q[0]
    assert 0.0 < q[2, 2] - q[1, 2] <= 0.2 + 1e-9, q[2, 2] - q[1, 2]
    free = 0.5 * float(np.sum(model.arrays.body_mass)) * (9.81 * dt) ** 2
    assert _kinetic(model, sim.state.v) <= free * (1.0 + 1e-9)
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        q = sim.state.q
        assert 0.2 - 1e-9 <= q[0, 1] - 1.0 <= 0.5 + 1e-9
        assert -0.2 - 1e-9 <= q[2, 2] - q[1, 2] <= 0.2 + 1e-9
    assert_clean(sim)


# --- springs and dampers ---------------------------------------------------------------------

def _theta_recurrence(inertia, k, c, dt, x0, n):
    """kernels/constraints/soft.py's step of a wheel on a world hinge at its centre: C = h^2 k
    / I, theta = max(0, 1/2 - 1 / (4 C)), w' = (I w - h k x) / (I + h c + theta h^2 k),
    x' = x + h w'; the angles x_1..x_n."""
    C = dt * dt * k / inertia
    theta = max(0.0, 0.5 - 0.25 / C)
    x, w, out = x0, 0.0, np.empty(n)
    for i in range(n):
        w = (inertia * w - dt * k * x) / (inertia + dt * c + theta * dt * dt * k)
        x += dt * w
        out[i] = x
    return out


@pytest.mark.parametrize("inertia, k, c, dt", [
    (1.0, 1e9, 0.0, 1e-2), (1e-3, 1e3, 0.0, 1e-2), (1.0, 1e9, 0.0, 1e-4), (1e-3, 1e-3, 1e-6, 1e-2),
    (0.02, 1e5, 0.0, 1e-3), (0.02, 1e5, 1.0, 1e-3), (1.0, 1e9, 1e3, 1e-3)])
def test_a_hinge_spring_of_any_stiffness_takes_the_theta_recurrence(inertia, k, c, dt):
    """A wheel on a world hinge through its centre, spring k (1e-3..1e9 N m/rad) and damper
    c, released at rest at 0.1 rad, steps C = (h w)^2 from 1e-4 to 1e5: the step is the
    theta-recurrence its docstring gives (_theta_recurrence) to rounding (measured: 1.7e-13
    of the amplitude at k 1e9, dt 1e-2), and where the step does not resolve the spring (C >
    1/2, theta > 0) the amplitude never grows: |x| <= x0, the scheme stable at any step.
    (speed_limit 0: the speed guard does not count a spring's energy; DEFECTS.)"""
    x0, n = 0.1, 2000
    model = _wheel(dt, inertia, theta0=x0, stiffness=k, damping=c)
    sim = ps.Simulator(model, ps.make_options(speed_limit=0.0))
    xs = np.empty(n)
    for i in range(n):
        sim.step()
        xs[i] = sim.state.q[0, 2]
    err = np.max(np.abs(xs - _theta_recurrence(inertia, k, c, dt, x0, n)))
    print(f"I={inertia} k={k} c={c} dt={dt} (C {dt * dt * k / inertia:.1e}): {err / x0:.1e}")
    assert err <= 1e-11 * x0
    if dt * dt * k / inertia > 0.5:
        assert np.max(np.abs(xs)) <= x0 * (1 + 1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("k, theta0", [(1e9, 0.1), (1e7, 1.0), (1e9, -0.5)])
def test_a_stiff_spring_released_from_a_stretch_is_not_stopped_by_the_speed_guard(k, theta0):
    """A wheel (1 kg, 1 kg m^2) on a world hinge spring of k, released at theta0 (dt 1e-4),
    with the default speed bound: the spring's stored energy explains its speed (sqrt(k / I)
    theta0), so the run goes on, on the spring's recurrence (measured before the bound
    counted springs: k 1e9 from 0.1 rad stopped at its first step with SimulationDiverged,
    'turning speed of 1739 m/s', the bound being 100 m/s)."""
    model = _wheel(1e-4, 1.0, theta0=theta0, stiffness=k)
    sim = ps.Simulator(model)
    sim.steps(100)
    assert np.isfinite(sim.state.q).all()
    assert abs(sim.state.q[0, 2]) <= abs(theta0) * (1 + 1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("m, inertia, d, c, dt, w0", [
    (1.0, 0.01, 0.3, 0.1, 1e-3, 5.0), (1.0, 0.01, 0.3, 0.1, 1e-2, 5.0),
    (1e3, 1.0, 0.5, 1e3, 1e-3, 2.0), (1e-3, 1e-5, 0.2, 1e-4, 1e-2, 1.0)])
def test_a_damper_on_an_off_centre_hinge_brakes_its_link_by_backward_euler(m, inertia, d, c, dt, w0):
    """A link whose centre lies d off a world hinge with a damper alone, spinning at w0 in
    zero gravity: the damper is implicit in the velocity solve with the pin's rows, so the
    rate follows backward Euler about the hinge, w' = w J / (J + h c), J = I + m d^2, to
    SHAKE's chord, O((h w0)^2) (measured 0.12..0.16 (h w0)^2)."""
    model = _wheel(dt, inertia, omega=w0, mass=m, d=d, damping=c)
    sim = ps.Simulator(model)
    J = inertia + m * d * d
    w, err = w0, 0.0
    for _ in range(int(round(1.0 / dt))):
        sim.step()
        w *= J / (J + dt * c)
        err = max(err, abs(sim.state.v[0, 2] - w))
    print(f"m={m} dt={dt} h w0={dt * w0}: {err / w0:.1e} of w0, {err / w0 / (dt * w0) ** 2:.2f} (h w0)^2")
    assert err <= 0.5 * (dt * w0) ** 2 * w0
    assert_clean(sim)


@pytest.mark.parametrize("zeta, dt", [(1.0, 1e-3), (1.0, 1e-4), (3.0, 1e-3)])
def test_critically_and_over_damped_springs_follow_their_closed_forms(zeta, dt):
    """I 0.02 kg m^2, k 2 N m/rad (w 10 rad/s), damping ratio 1 and 3, released at rest at
    0.5 rad: x = x0 (1 + w t) e^(-w t), and the over-damped sum of two exponentials, to first
    order in h (the damper implicit, the spring at the step's start): within h w of x0
    (measured 0.09 h w and 0.03 h w), and the angle falls monotonically to 0 without
    overshoot, as the closed forms do."""
    inertia, k, x0 = 0.02, 2.0, 0.5
    w = math.sqrt(k / inertia)
    c = 2 * zeta * math.sqrt(k * inertia)
    model = _wheel(dt, inertia, theta0=x0, stiffness=k, damping=c)
    sim = ps.Simulator(model)
    n = int(round(2.0 / dt))
    xs = np.empty(n)
    for i in range(n):
        sim.step()
        xs[i] = sim.state.q[0, 2]
    t = (np.arange(n) + 1) * dt
    if zeta == 1.0:
        exact = x0 * (1 + w * t) * np.exp(-w * t)
    else:
        r1 = -w * (zeta - math.sqrt(zeta * zeta - 1))
        r2 = -w * (zeta + math.sqrt(zeta * zeta - 1))
        exact = x0 * (r2 * np.exp(r1 * t) - r1 * np.exp(r2 * t)) / (r2 - r1)
    err = np.max(np.abs(xs - exact))
    print(f"zeta {zeta} dt {dt}: {err / x0 / (w * dt):.2f} h w")
    assert err <= x0 * w * dt
    assert np.all(np.diff(xs) <= 0.0) and xs.min() > 0.0
    assert_clean(sim)


N_LINKS, LINK, LINK_M = 10, 0.2, 0.3


def _chain(dt, gravity, c, c_top, rest, a0=0.4, omega=0.0, bend=0.0):
    """Ten 0.2 m, 0.3 kg rods in a line from a hinge at the origin, each hinge with a spring
    5 N m/rad and damper c (c_top at the top one; None: no top hinge, a free chain), rest
    angle `rest`; link i at angle a0 + i bend, the chain turning rigidly at omega about the
    origin."""
    b = ps.ModelBuilder(dt=dt, gravity=gravity, ground=None)
    p, prev = np.zeros(2), None
    for i in range(N_LINKS):
        a = a0 + i * bend
        d = np.array([math.sin(a), -math.cos(a)])
        com = p + d * LINK / 2
        b.add_body(f"l{i}", LINK_M, LINK_M * LINK * LINK / 12, pos=com, angle=a,
                   vel=(-omega * com[1], omega * com[0]), omega=omega)
        if prev is not None or c_top is not None:
            b.add_pin(f"j{i}", prev, f"l{i}", anchor_world=p, stiffness=5.0,
                      damping=c if prev is not None else c_top, rest_angle=rest,
                      ref_angle=0.0 if prev is None else None)
        prev, p = f"l{i}", p + d * LINK
    return b.compile()


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_free_spring_damper_chain_keeps_its_angular_momentum_and_settles(dt):
    """The ten links with no top hinge, floating in zero gravity, bent 0.15 rad at each of
    its nine hinges and spinning at 2 rad/s about its top end: springs and dampers are
    internal, so the angular momentum is kept to rounding; after the first step (SHAKE's
    chord, which raises a rigid spin's energy) the dampers (c 0.5) only remove energy, the
    springs (resolved, theta = 0) and SHAKE exchanging O((h w)^2) of it with the motion, so
    the energy (kinetic and the springs') never exceeds the first step's by (h w)^2 and ends
    below it; after 20 s the chain turns rigidly (its hinges' rates within 1e-6 rad/s).
    Measured: L to 1.4e-13, the highest energy 6.9e-7 below the first step's at dt 1e-2."""
    model = _chain(dt, (0.0, 0.0), 0.5, None, 0.0, omega=2.0, bend=0.15)
    sim = ps.Simulator(model)
    m, inertia = model.arrays.body_mass, model.arrays.body_inertia

    def momentum():
        q, v = sim.state.q, sim.state.v
        return np.sum(m * (q[:, 0] * v[:, 1] - q[:, 1] * v[:, 0]) + inertia * v[:, 2])

    def rates():
        return np.array([measure.pin_angle_rate(model, sim.state.q, sim.state.v, f"j{i}")[1]
                         for i in range(1, N_LINKS)])
    L0 = momentum()
    sim.step()
    e1 = total_energy(model, sim.state.q, sim.state.v)
    top = -math.inf
    for _ in range(int(round(20.0 / dt))):
        sim.step()
        top = max(top, total_energy(model, sim.state.q, sim.state.v))
    e = total_energy(model, sim.state.q, sim.state.v)
    print(f"dt {dt}: L {momentum() / L0 - 1:+.1e}, highest energy {top / e1 - 1:+.1e} of the "
          f"first step's, last {e / e1 - 1:+.1e}, rates {np.abs(rates()).max():.1e}")
    assert abs(momentum() / L0 - 1) <= 1e-12
    assert top <= e1 * (1 + (2.0 * dt) ** 2)
    assert e < e1
    assert np.abs(rates()).max() <= 1e-6
    assert_clean(sim)


def _balance(model, q):
    """Each hinge i of the hanging chain: (k (x_i - rest) - gravity's torque on links i..9
    about hinge i) / that torque: zero where the springs hold the chain up."""
    out = []
    tops = [q[i, :2] - LINK / 2 * np.array([math.sin(q[i, 2]), -math.cos(q[i, 2])])
            for i in range(N_LINKS)]
    for i in range(N_LINKS):
        x, _ = measure.pin_angle_rate(model, q, np.zeros_like(q), f"j{i}")
        torque = sum(-(q[j, 0] - tops[i][0]) * LINK_M * G for j in range(i, N_LINKS))
        out.append((5.0 * (x - 0.1) - torque) / abs(torque))
    return np.array(out)


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["rest_bias"])
@pytest.mark.parametrize("dt", [1e-2, 3e-3])
def test_a_damped_spring_chain_at_rest_balances_gravity(dt):
    """The ten links hanging from the world, springs 5 N m/rad toward 0.1 rad, dampers 3 (20
    at the top), released at 0.4 rad: after 120 s the chain is at rest (|v| < 1e-9), and at
    rest the dampers give nothing, so at every hinge the spring's torque is gravity's torque
    on the links below it (statics), to 1e-6 of it."""
    model = _chain(dt, (0.0, -G), 3.0, 20.0, 0.1)
    sim = ps.Simulator(model)
    sim.steps(int(round(120.0 / dt)))
    assert np.abs(sim.state.v).max() <= 1e-9
    off = _balance(model, sim.state.q)
    print(f"dt {dt}: torque balance off by up to {np.abs(off).max():.2e}")
    assert np.abs(off).max() <= 1e-6


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["rest_bias"])
@pytest.mark.parametrize("dt, c", [(1e-2, 5.0), (3e-3, 0.5)])
def test_a_spinning_spring_damper_chain_settles_where_its_springs_balance_the_spin(dt, c):
    """The free chain of test_a_free_spring_damper_chain_keeps_its_angular_momentum_and_
    settles, dampers c: once it turns rigidly at w about its centre of mass (hinge rates
    below 1e-9 rad/s) the dampers give nothing, so at every hinge the spring's torque k x_i
    balances the centrifugal forces m w^2 (r_j - c) on the links beyond it (about the hinge),
    to 1e-6 of it."""
    model = _chain(dt, (0.0, 0.0), c, None, 0.0, omega=2.0, bend=0.15)
    sim = ps.Simulator(model)
    sim.steps(int(round(20.0 / dt)))
    q, v = sim.state.q, sim.state.v
    m = model.arrays.body_mass
    w = v[0, 2]
    centre = (m[:, None] * q[:, :2]).sum(0) / m.sum()
    tops = [q[i, :2] - LINK / 2 * np.array([math.sin(q[i, 2]), -math.cos(q[i, 2])])
            for i in range(N_LINKS)]
    off = []
    for i in range(1, N_LINKS):
        x, rate = measure.pin_angle_rate(model, q, v, f"j{i}")
        assert abs(rate) <= 1e-9
        arm = [q[j, :2] - tops[i] for j in range(i, N_LINKS)]
        push = [m[j] * w * w * (q[j, :2] - centre) for j in range(i, N_LINKS)]
        torque = sum(a[0] * f[1] - a[1] * f[0] for a, f in zip(arm, push))
        off.append((torque - 5.0 * x) / abs(5.0 * x))
    print(f"dt {dt} c {c}: balance off by up to {np.abs(off).max():.2e}")
    assert np.abs(off).max() <= 1e-6


def _energy_kept(model, steps):
    """model's total energy after `steps` steps over its start's (its audit clean)."""
    sim = ps.Simulator(model)
    e0 = total_energy(model, sim.state.q, sim.state.v)
    sim.steps(steps)
    assert_clean(sim)
    return total_energy(model, sim.state.q, sim.state.v) / e0


@pytest.mark.parametrize("inertia, k", [(1e-3, 2e4), (1e-2, 1e5)])
def test_a_slider_spring_anchored_off_the_centre_keeps_its_energy(inertia, k):
    """A 1 kg block on a world slider along x (the slider holds its angle), its anchor 0.3 m
    across the axis from its centre of mass, spring k (h w = 0.14 and 0.32 at dt 1e-3,
    resolved), at 1 m/s in zero gravity: where the anchor sits does not change the motion
    (the block cannot turn), so after 1 s the energy is the anchor-on-centre run's
    (symplectic Euler's oscillation, 1.024 and 1.083 of its start) to 1e-9."""
    def energy_after(off):
        b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0), ground=None)
        b.add_body("block", 1.0, inertia, vel=(1.0, 0.0))
        b.add_slider("rail", None, "block", axis=(1.0, 0.0), anchor_world=(0.0, off), stiffness=k)
        return _energy_kept(b.compile(), 1000)
    centred, off = energy_after(0.0), energy_after(0.3)
    print(f"I {inertia} k {k}: energy after 1 s {centred:.3f} anchored on the centre, {off:.1e} off it")
    assert abs(off - centred) <= 1e-9


@pytest.mark.parametrize("k", [6e4, 1e5])
def test_a_negligible_damper_does_not_damp_an_off_centre_hinge_spring(k):
    """A 1 kg, 1 m rod hinged at its end to the world, spring k (h w about the hinge 0.42 and
    0.55 at dt 1e-3: resolved, an explicit force), spinning from 1 rad/s in zero gravity: a
    damper of 1e-9 N m s/rad takes at most c w^2 t, nothing, so its energy after 1 s is the
    undamped run's to 1e-6."""
    def energy_after(c):
        b = ps.ModelBuilder(dt=1e-3, ground=None, gravity=(0.0, 0.0))
        b.add_body("rod", mass=1.0, inertia=1 / 12, pos=(0.5, 0.0), omega=1.0, vel=(0.0, 0.5))
        b.add_pin("hinge", None, "rod", anchor_world=(0.0, 0.0), stiffness=k, damping=c)
        return _energy_kept(b.compile(), 1000)
    free, damped = energy_after(0.0), energy_after(1e-9)
    print(f"k {k}: energy after 1 s {free:.3f} undamped, {damped:.1e} with c = 1e-9")
    assert abs(damped - free) <= 1e-6


# --- dry joint friction ----------------------------------------------------------------------

@pytest.mark.parametrize("rel", [1 - 1e-6, 1 + 1e-6, 1 - 1e-3, 1 + 1e-3])
def test_dry_friction_at_its_threshold_holds_below_and_slips_above(rel):
    """A 0.5 m, 1 kg rod at 0.6 rad from hanging on a hinge whose frictionloss is its gravity
    torque over `rel`: 1e-6 below the torque it holds exactly at rest; 1e-6 above it slips
    as I_pivot x'' = -m g (L/2) sin x + F does (friction against the motion), symplectic
    Euler's recurrence of that equation to 1e-9 of its 0.1 s turn, or the rounding of the
    angle (measured: 8.9e-16 rad of a 8.2e-8 rad turn, 0 of 8.2e-5)."""
    length, m, th, dt = 0.5, 1.0, 0.6, 1e-3
    ip = m * length * length / 3
    tau = m * G * length / 2 * math.sin(th)
    friction = tau / rel
    model = _pendulum(m, length, th, dt, frictionloss=friction)
    sim = ps.Simulator(model)
    n = 100
    sim.steps(n)
    x, w = th, 0.0
    for _ in range(n):
        w_new = w + dt * (-m * G * length / 2 * math.sin(x) + friction) / ip
        w = min(w_new, 0.0)                 # friction never turns it back
        x += dt * w
    print(f"rel {rel}: angle {sim.state.q[0, 2] - th:+.3e} (recurrence {x - th:+.3e})")
    if rel < 1:
        assert sim.state.q[0, 2] == th and sim.state.v[0, 2] == 0.0
    else:
        assert sim.state.q[0, 2] < th
        assert abs(sim.state.q[0, 2] - x) <= 1e-9 * abs(x - th) + n * np.finfo(float).eps * th
    assert_clean(sim)


@pytest.mark.parametrize("dt", [1e-4, 1e-3])
def test_a_spring_with_dry_friction_loses_2f_over_k_a_half_swing_and_stops_in_its_dead_band(dt):
    """A wheel on a hinge with spring k 2 N m/rad and frictionloss F 0.05 N m (I 0.02 kg
    m^2), released at rest at 0.51 rad: Coulomb friction against a spring takes 2 F / k =
    0.05 rad off each half swing's amplitude (0.51, -0.46, 0.41, ...) and the wheel stops at
    the first extreme within F / k of its rest angle, the tenth, +0.01 rad, its rate then
    exactly 0. The
    extremes are symplectic Euler's to O(h w): within 2 h w of 0.05 (measured 2.2e-7 at dt
    1e-4, 3.3e-5 at 1e-3)."""
    inertia, k, F, x0 = 0.02, 2.0, 0.05, 0.51
    model = _wheel(dt, inertia, theta0=x0, stiffness=k, frictionloss=F)
    sim = ps.Simulator(model)
    n = int(round(4.0 / dt))
    xs, ws = np.empty(n), np.empty(n)
    for i in range(n):
        sim.step()
        xs[i], ws[i] = sim.state.q[0, 2], sim.state.v[0, 2]
    turns = [xs[i] for i in range(1, n) if ws[i - 1] != 0.0 and (ws[i] == 0.0 or ws[i] * ws[i - 1] < 0)]
    expected = [(x0 - 2 * F / k * j) * (-1) ** j for j in range(1, 11)]
    err = max(abs(a - b) for a, b in zip(turns, expected))
    print(f"dt {dt}: extremes {np.round(turns, 4)}, largest error {err:.1e}; rest {xs[-1]:+.3e}")
    assert len(turns) >= 10
    assert err <= 2 * dt * math.sqrt(k / inertia) * 2 * F / k
    assert abs(xs[-1] - 0.01) <= 2 * dt * math.sqrt(k / inertia) * 2 * F / k
    assert abs(xs[-1]) <= F / k and ws[-1] == 0.0
    assert_clean(sim)


# --- rods ------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["rod", "dumbbell"])
@pytest.mark.parametrize("ratio", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("turn", [0.1, 0.5])
def test_a_spinning_rod_takes_shakes_first_step_and_keeps_its_length(kind, ratio, turn):
    """A point mass on a 1 m rod round a fixed pivot ("rod", mass `ratio`), or two point
    masses (1 and `ratio` kg) on a 1 m rod spinning about their centre of mass ("dumbbell"),
    turning `turn` rad a step at dt 1e-2 in zero gravity: SHAKE's first step makes the
    velocity the step's chord, which raises the kinetic energy by (1 - sqrt(1 - (h w)^2))^2 /
    (h w)^2 (+0.25 % at 0.1 rad a step, +7.2 % at 0.5) whatever the masses; then the energy
    and the rod's length stay (measured: the rise to 5.5e-14 of itself, the length to 2.2e-16
    m, the energy to 1.6e-14 over 300 steps)."""
    dt = 1e-2
    w = turn / dt
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    if kind == "rod":
        b.add_point_mass("p", ratio, pos=(1.0, 0.0), vel=(0.0, w))
        b.add_rod("rod", None, "p")
    else:
        c = ratio / (1 + ratio)
        b.add_point_mass("a", 1.0, pos=(-c, 0.0), vel=(0.0, -w * c))
        b.add_point_mass("b", ratio, pos=(1 - c, 0.0), vel=(0.0, w * (1 - c)))
        b.add_rod("rod", "a", "b")
    model = b.compile()
    sim = ps.Simulator(model)
    m = model.arrays.body_mass

    def ke():
        return 0.5 * np.sum(m * (sim.state.v[:, 0] ** 2 + sim.state.v[:, 1] ** 2))

    def length():
        q = sim.state.q
        return np.hypot(*q[0, :2]) if kind == "rod" else np.hypot(*(q[1, :2] - q[0, :2]))
    k0 = ke()
    sim.step()
    k1 = ke()
    rise = (1 - math.sqrt(1 - turn * turn)) ** 2 / (turn * turn)
    worst = 0.0
    for _ in range(300):
        sim.step()
        worst = max(worst, abs(length() - 1.0))
    assert (k1 / k0 - 1) == pytest.approx(rise, rel=1e-11)
    assert worst <= 1e-12
    assert ke() == pytest.approx(k1, rel=1e-12)
    assert_clean(sim)


@pytest.mark.parametrize("masses, dt", [((1.0, 1e-3, 1e3), 1e-3), ((1e3, 1.0, 1e-3), 1e-2),
                                        ((1e-3, 1e3, 1.0), 1e-3), ((1.0, 1e3, 1.0), 1e-2)])
def test_a_rod_chain_of_any_mass_ratio_keeps_its_momenta(masses, dt):
    """Three point masses on two 0.5 m rods (mass ratios 1e-3..1e3), turning at 3 rad/s
    about their centre of mass while both ends fold (velocities the rods allow), zero
    gravity, 2 s: the rods' impulses are central, so the linear and angular momenta are
    kept to rounding and the rods' lengths to 1e-12 m (measured: L to 5.9e-11 at the worst
    case (1, 1e-3, 1e3) at dt 1e-3, 8e-15 elsewhere; lengths to 6.5e-13 m)."""
    pts = np.array([(0.0, 0.0), (0.5, 0.0), (0.8, 0.4)])
    ms = np.array(masses)
    c = (ms[:, None] * pts).sum(0) / ms.sum()
    vs = np.array([[-3.0 * (p[1] - c[1]), 3.0 * (p[0] - c[0])] for p in pts])
    r0, r1 = pts[1] - pts[0], pts[2] - pts[1]
    vs[0] += 2.0 * np.array([-r0[1], r0[0]])
    vs[2] += -4.0 * np.array([-r1[1], r1[0]])
    sim = _masses_on_two_rods(ms, pts, vs, dt)

    def momenta():
        v = sim.state.v
        return _point_masses_L(sim, ms), np.array([np.sum(ms * v[:, 0]), np.sum(ms * v[:, 1])])
    L0, p0 = momenta()
    worst = 0.0
    for _ in range(int(round(2.0 / dt))):
        sim.step()
        q = sim.state.q
        worst = max(worst, abs(np.hypot(*(q[1, :2] - q[0, :2])) - 0.5),
                    abs(np.hypot(*(q[2, :2] - q[1, :2])) - 0.5))
    L, p = momenta()
    print(f"{masses} dt {dt}: L {L / L0 - 1:+.1e}, p {np.abs(p - p0).max():.1e}, length {worst:.1e}")
    assert abs(L / L0 - 1) <= 1e-9
    assert np.abs(p - p0).max() <= 1e-12 * np.sum(ms * np.hypot(vs[:, 0], vs[:, 1]))
    assert worst <= 1e-12
    assert_clean(sim)


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["rod_whip"])
def test_a_rod_chain_snapping_straight_keeps_its_angular_momentum():
    """Three point masses (1, 1e-3, 1 kg) on two 0.5 m rods, bent 0.3 rad from straight, the
    outer masses 1 m/s apart and the whole turning at 1 rad/s (zero gravity, dt 1e-3): as it
    snaps straight the light middle mass whips; the rods' impulses are central, so the
    angular momentum is kept to rounding through it (as at dt 1e-4, measured 8e-15)."""
    bend, u, w, dt = 0.3, 1.0, 1.0, 1e-3
    a, h = 0.5 * math.cos(bend), 0.5 * math.sin(bend)
    pts = np.array([(-a, 0.0), (0.0, -h), (a, 0.0)])
    ms = np.array([1.0, 1e-3, 1.0])
    c = (ms[:, None] * pts).sum(0) / ms.sum()
    vs = np.array([(-u, 0.0), (0.0, u * a / h), (u, 0.0)])
    vs += np.array([[-w * (p[1] - c[1]), w * (p[0] - c[0])] for p in pts])
    sim = _masses_on_two_rods(ms, pts, vs, dt)

    def momentum():
        return _point_masses_L(sim, ms)
    L0 = momentum()
    sim.steps(1000)
    print(f"L / L0 - 1 = {momentum() / L0 - 1:+.2e}")
    assert_clean(sim)
    assert abs(momentum() / L0 - 1) <= 1e-9


# --- readouts --------------------------------------------------------------------------------

def test_the_joint_readouts_are_the_bodies_states_finite_differences():
    """A slider on a spinning free body, a second body hinged to the slider's block (zero
    gravity, dt 1e-3, 2 s): the hinge's rate as measure.pin_angle_rate reads it is the
    finite difference of its angle over the step to rounding (the step's velocity is its
    move: SHAKE's correction whole); the slide's rate that of the slide to O(h) (the slide
    is not linear in the bodies' coordinates as the rail turns: within h (w |rate| + |s''|)
    where measured 9.4e-4 m/s); and the slide is d . (p_b - p_a) from the bodies' states."""
    dt = 1e-3
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", 1.0, 0.1, omega=3.0)
    b.add_body("b", 0.5, 0.05, pos=(0.3, 0.0), omega=3.0, vel=(0.4, 0.9))
    b.add_slider("s", "a", "b", axis=(1.0, 0.0))
    b.add_body("c", 0.7, 0.02, pos=(0.3, -0.2), omega=-1.0)
    b.add_pin("h", "b", "c", anchor_world=(0.3, -0.1))
    model = b.compile()
    sim = ps.Simulator(model)

    def read(name):
        return measure.pin_angle_rate(model, sim.state.q, sim.state.v, name)
    s0, h0 = read("s"), read("h")
    slide_err = hinge_err = direct = 0.0
    for _ in range(2000):
        sim.step()
        s1, h1 = read("s"), read("h")
        slide_err = max(slide_err, abs((s1[0] - s0[0]) / dt - s1[1]))
        hinge_err = max(hinge_err, abs((h1[0] - h0[0]) / dt - h1[1]))
        q = sim.state.q
        d = np.array([math.cos(q[0, 2]), math.sin(q[0, 2])])
        direct = max(direct, abs(d @ (q[1, :2] - q[0, :2]) - 0.3 - s1[0]))
        s0, h0 = s1, h1
    print(f"hinge {hinge_err:.1e} rad/s, slide {slide_err:.1e} m/s, slide direct {direct:.1e} m")
    assert hinge_err <= 1e-9
    assert slide_err <= dt * 3.0 * 5.0
    assert direct <= 1e-12
    assert_clean(sim)
