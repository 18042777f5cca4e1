"""The actuators against closed forms and conservation laws: pin motors (with and without a
hinge's rotor, armature), slider motors, axial forces, hip torques, body forces and torques,
and the DC motor model of planarsim.actuators driving a flywheel through a pin motor.

What is checked, each against what the scheme itself gives:
- a constant torque on a flywheel (inertia 1e-3..1e3 kg m^2, armature 0..1e3 times it, dt
  1e-4..1e-2): symplectic Euler's w_n = n h tau / J and theta_n = h^2 tau / J n (n + 1) / 2
  to rounding (J = I + armature), and the kinetic energy equal to the motor's work taken at
  each step's mean rate; the continuous theta = tau t^2 / (2 J) to O(h): (n + 1) / n;
- a torque on a link hinged off its centre: the angular momentum about the hinge is tau t to
  rounding (the pin's impulses act through the hinge), its rate within the chord's
  O((h w)^2) of tau t / (I + m d^2 + armature);
- an arm's angular momentum about its shoulder is the shoulder motor's impulse (the elbow
  motor's reaction taken by the upper arm);
- internal actuators (a motor between two free pinned bodies, a slider motor between two
  free bodies, with rotors, mass ratios 1e-3..1e3, spinning or not; hip torques; axial
  forces): linear and angular momentum kept to rounding, and the actuators' recorded work
  equal to the change of kinetic energy to first order in dt, there and for motors driving
  rotors on a turning slider and hinge and a closed four-bar loop;
- the DC motor model (current command, viscous, Coulomb and load friction): a flywheel spun
  up to its no-load speed G K I / c1 takes the step's recurrence to rounding and the
  exponential with time constant (J + G^2 Jm) / c1 to O(h / T); with Coulomb and load
  friction it settles on the root of the torque balance; a current beyond Imax acts as Imax;
- a motor with a damper (the semi-implicit recurrence), with joint friction ((tau - f) / J),
  against a limit (held there, the limit's impulse h tau), with a spring and damper (the
  static deflection tau / k); a motor holding a spinning pair's hinge on its limit (the
  angular momentum kept); a torque rolling a disk on the ground, or skidding it;
- a state's velocity converted to the step's and back (planarsim.half_step) makes the step
  the leapfrog, exact under constant actuators;
- RATTLE's integrators (second, fourth and sixth order) put a body under a constant torque or
  force on the exact parabola, to rounding;
- saturation: a command beyond an actuator's range moves bit for bit as the range's bound;
  mirror symmetry: a mechanism of every actuator kind and its mirror image under mirrored
  commands move as mirror images bit for bit; a drift of up to 1 km/s changes nothing.

A silent defect found here is xfail(strict=True) with its measurements in DEFECTS: a motor
spinning a link that its hinge holds off its centre loses angular momentum from 0.2 rad a
step (driven_fast_turn). A spinning pair whose slider rests on its limit lost angular momentum
at first order in dt (9 % in 10 s at dt 1e-3) until a held limit's correction moved the
velocities with the positions. Two more are refused now:
planarsim.half_step's velocity conversions gave a hinge's rotor the motor's half kick as if
it were absent (a flywheel with a rotor of its own inertia ended 2 % short of its angle);
they refuse rotors, naming the joint. And a motor, spring, damper, limit, armature or dry
friction on a hinge to a point mass (which does not turn) acted with no reaction (a motor of
0.1 N m gave a free pair -0.1 N m s of angular momentum in 1 s, a damper braked its free spin
by half); the builder now refuses them, naming the point mass."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim.actuators import make_motor, motor_torque, saturate_current
from planarsim.compiled import audit_counts, step_info
from planarsim.energy import kinetic_energy
from planarsim.errors import ModelError
from planarsim.half_step import to_instant_velocity, to_step_velocity

DEFECTS = {
    "driven_fast_turn": (
        "a pin motor spinning up a link that its hinge holds off the link's centre of mass "
        "loses angular momentum, uncounted (no audit), once the link turns 0.2 rad a step, "
        "below the half radian a step up to which a free rotor keeps it: a 1 kg link with "
        "1e-3 kg m^2 about its centre, 0.3 m from a world hinge, dt 1e-2, zero gravity: "
        "2.73 N m (0.003 rad a step per step) keeps L = tau t to rounding until 0.67 s (0.2 "
        "rad a step), then its rate stalls near 20 rad/s: 34.6 % of tau t short at 1 s, "
        "50 % at 1.33 s (the motor's recorded work 55.1 J, the kinetic energy 18.5 J); "
        "9.1 N m: from 0.2 rad a step, 32 % short at 0.4 s; 0.91 N m (0.001 per step) "
        "only from 0.35 rad a step (22 % short at 4 s). The same per-step scaling at dt "
        "1e-3 gives the same figures. A free pair (1 kg base, a 0.01 kg link of 1e-5 kg "
        "m^2, its centre 0.3 m from the pin) driven by its internal motor gains an angular "
        "momentum of 38-56 % of tau t from 0.2 rad a step. Suspected cause: the predicted "
        "velocity v* = v + h M^-1 f turns the link about its own centre (1/I), not about its "
        "hinge (1/(I + m d^2)): h^2 tau (1/I - 1/J) = 0.27 rad away from where the step "
        "ends, beyond SHAKE_REGIME (0.1), so the joints' energy check "
        "(checks/work.joints_excess) allows only CONSTRAINT_SHARE of KE(v_lin) to the "
        "joints' second-order target; past 0.2 rad a step the target's work exceeds it, the "
        "velocity solve is taken again as a projection (step_info solves = 2, shake_whole "
        "= 0) and the position correction's energy bound cuts the velocity the hinge "
        "should give. The turn check (turn_limit 0.2) passes the motor: it measures the "
        "hinge's turn h^2 tau / (I + m d^2) = 0.003 rad, where a body torque of the same "
        "size on the same link is stopped (h^2 tau / I = 0.27 rad). RATTLE keeps L = tau t "
        "here but counts joint_work every step"),
}


def _driven_for_a_second(model, dt, amp, freq):
    """model's one actuator commanded amp sin(freq t) for 1 s at step dt [s], 50 frames:
    (its Simulator, the trajectory, linear and angular momentum per frame, their scale plus
    amp)."""
    sim = ps.Simulator(model)
    n = int(round(1.0 / dt))
    traj = sim.run(n_steps=n, controller=lambda s: np.array([amp * math.sin(freq * s.t)]),
                   record_every=max(1, n // 50))
    p, L = _momenta(traj.q, traj.v, model)
    return sim, traj, p, L, _momentum_scale(traj.q, traj.v, model) + amp


def _momenta(q, v, model):
    """Linear momentum (2,) and angular momentum about the origin of frames q, v."""
    m, inertia = model.arrays.body_mass, model.arrays.body_inertia
    L = np.sum(m * (q[..., 0] * v[..., 1] - q[..., 1] * v[..., 0]) + inertia * v[..., 2], axis=-1)
    p = np.stack([np.sum(m * v[..., 0], axis=-1), np.sum(m * v[..., 1], axis=-1)], axis=-1)
    return p, L


def _momentum_scale(q, v, model):
    """sum m |v| + I |w| + m |r x v| over bodies and frames: the size of the momenta."""
    m, inertia = model.arrays.body_mass, model.arrays.body_inertia
    return float(np.max(np.sum(m * np.hypot(v[..., 0], v[..., 1]) * (1.0 + np.hypot(q[..., 0], q[..., 1]))
                               + inertia * np.abs(v[..., 2]), axis=-1)))


def assert_clean(sim):
    assert sum(audit_counts(sim.ws).values()) == 0, audit_counts(sim.ws)


def _wheel(dt, inertia, mass=1.0, d=0.0, motor_limit=(-math.inf, math.inf), **pin):
    """A body (mass [kg], inertia [kg m^2] about its centre) whose centre lies d [m] from a
    world hinge at the origin (add_pin's keywords `pin`), driven by a pin motor at the hinge
    (its range motor_limit [N m]); zero gravity."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("w", mass, inertia, pos=(d, 0.0))
    b.add_pin("axle", None, "w", anchor_world=(0.0, 0.0), **pin)
    b.add_pin_motor("m", "axle", limit=motor_limit)
    return b.compile()


# --- a torque on a flywheel ----------------------------------------------------------------

@pytest.mark.parametrize("inertia", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
@pytest.mark.parametrize("arm", [0.0, 1e-3, 1e3])
def test_a_constant_torque_spins_a_flywheel_as_symplectic_euler_does(inertia, dt, arm):
    """A flywheel on a hinge at its centre, inertia I, armature `arm` times I, under a
    constant torque tau (a thousandth of a radian a step per step): w_n = n h tau / J and
    theta_n = h^2 tau / J n (n + 1) / 2 with J = I + armature, to rounding (measured
    <= 1.2e-13, the armature's soft row at 1e3); theta is the continuous tau t^2 / (2 J)
    times (n + 1) / n, first order in h. The kinetic energy (the rotor's included) is the
    motor's work at each step's mean rate, h tau (w_n + w_n+1) / 2 summed, to rounding. The
    recorded power over each step times h is the torque's work on the step's turn, h tau
    w_n+1 (tau theta_n in all), which exceeds the kinetic energy by n h^2 tau^2 / (2 J):
    symplectic Euler's energy error under the torque, not a miscount (the power at the
    step's start rate, recorded before, fell short of the energy by as much)."""
    J = inertia * (1.0 + arm)
    model = _wheel(dt, inertia, armature=arm * inertia)
    sim = ps.Simulator(model)
    tau = 1e-3 * J / dt ** 2
    n = 200
    traj = sim.run(n_steps=n, u=np.array([tau]))
    w, theta = traj.v[-1, 0, 2], traj.q[-1, 0, 2]
    k = np.arange(n + 1)
    assert np.abs(traj.v[:, 0, 2] / (np.maximum(k, 1) * dt * tau / J) - np.minimum(k, 1)).max() <= 1e-12
    assert theta == pytest.approx(dt * dt * tau / J * n * (n + 1) / 2, rel=1e-12)
    assert theta / (tau * (n * dt) ** 2 / (2 * J)) == pytest.approx((n + 1) / n, rel=1e-12)
    ke = kinetic_energy(model, traj.q, traj.v)
    mean_rate_work = dt * tau * np.sum(0.5 * (traj.v[:-1, 0, 2] + traj.v[1:, 0, 2]))
    assert ke[-1] == pytest.approx(0.5 * J * w * w, rel=1e-12)
    assert ke[-1] == pytest.approx(mean_rate_work, rel=1e-12)
    recorded = dt * traj.act_power[1:, 0].sum()
    assert recorded == pytest.approx(tau * theta, rel=1e-12)
    assert recorded - ke[-1] == pytest.approx(n * dt * dt * tau * tau / (2 * J), rel=1e-9)
    assert_clean(sim)


@pytest.mark.parametrize("mass, inertia, arm", [(1.0, 0.01, 0.0), (1.0, 0.01, 0.05),
                                                (1e-3, 1e-5, 0.0), (1e3, 10.0, 0.0),
                                                (1.0, 0.01, 100.0)])
@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
def test_a_torque_on_a_link_hinged_off_its_centre_gives_the_hinge_angular_momentum_tau_t(mass, inertia, arm, dt):
    """A link (mass m, inertia I about its centre) hinged 0.3 m from its centre to the
    world, armature a on the hinge, zero gravity, a constant motor torque turning it 3 rad in
    0.5 s (up to 0.12 rad a step): the pin's impulses act through the hinge, so the angular
    momentum about it, m r x v + I w + a w, is tau t at every step to rounding (measured
    <= 7e-13). The rate is tau t / (I + m d^2 + a) but for the chord: the velocity of the
    centre is the step's chord, a turn shorter than the arc, so w exceeds it by about
    (h w)^2 / 6 m d^2 / J (measured 2.2e-3 at dt 1e-2)."""
    d = 0.3
    J = inertia + mass * d * d + arm
    tau = 2 * 3.0 * J / 0.5 ** 2
    n = int(round(0.5 / dt))
    model = _wheel(dt, inertia, mass, d, armature=arm)
    sim = ps.Simulator(model)
    traj = sim.run(n_steps=n, u=np.array([tau]), record_every=max(1, n // 50))
    _, L = _momenta(traj.q, traj.v, model)
    L = L + arm * traj.v[:, 0, 2]
    assert np.abs(L - tau * traj.t).max() <= 1e-11 * tau * traj.t[-1]
    w = traj.v[-1, 0, 2]
    chord = (dt * w) ** 2 / 6 * mass * d * d / J
    assert 0.0 <= w / (tau * traj.t[-1] / J) - 1 <= 1.05 * chord + 1e-12
    assert_clean(sim)


# --- internal actuators keep the momenta --------------------------------------------------

@pytest.mark.parametrize("ratio", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("arm", [0.0, 0.05])
@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
@pytest.mark.parametrize("w0", [0.0, 5.0])
def test_an_internal_pin_motor_keeps_a_free_pairs_momenta(ratio, arm, dt, w0):
    """Two free bodies pinned together (the second `ratio` times the first's mass and
    inertia), a rotor `arm` on the pin, spinning rigidly at w0 or at rest in zero gravity,
    driven for 1 s by a motor between them, tau = 0.2 min(1, ratio) sin(7 t): +tau on one,
    -tau on the other, and the pin's impulses internal, so the linear and the angular
    momentum (the rotor's armature on the relative angle adds none) stay as they were, to
    rounding (measured <= 9e-13 of the scale)."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", 1.0, 0.02, pos=(-0.25, 0.0), vel=(0.0, -0.25 * w0), omega=w0)
    b.add_body("b", ratio, 0.02 * ratio, pos=(0.25, 0.0), vel=(0.0, 0.25 * w0), omega=w0)
    b.add_pin("hinge", "a", "b", anchor_world=(0.0, 0.0), armature=arm)
    b.add_pin_motor("m", "hinge")
    sim, traj, p, L, scale = _driven_for_a_second(b.compile(), dt, 0.2 * min(1.0, ratio), 7.0)
    assert np.abs(L - L[0]).max() <= 1e-11 * scale
    assert np.abs(p - p[0]).max() <= 1e-12 * scale
    assert np.abs(traj.v[:, 1, 2] - traj.v[:, 0, 2]).max() > 1e-5   # the motor did turn them
    assert_clean(sim)


@pytest.mark.parametrize("ratio", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("arm", [0.0, 0.5])
@pytest.mark.parametrize("off", [0.0, 0.2])
@pytest.mark.parametrize("dt, w0", [(1e-3, 0.0), (1e-3, 3.0), (1e-2, 3.0)])
def test_an_internal_slider_motor_keeps_a_free_pairs_momenta(ratio, arm, off, dt, w0):
    """Two free bodies on a slider (the axis along body a's x, anchor b `off` beside it, a
    rotor `arm` on the slide), turning rigidly at w0 or at rest, driven for 1 s by the
    slider's motor, f = 0.3 min(1, ratio) sin(5 t): +f on b and -f on a at the same point, so
    no net force or torque, and the momenta stay to rounding (measured <= 6e-15 of the
    scale), however the turning rail's rotor and the off-axis push turn the pair."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    pa, pb = np.array([-0.3, 0.0]), np.array([0.3, off])
    b.add_body("a", 1.0, 0.05, pos=tuple(pa), omega=w0, vel=(-w0 * pa[1], w0 * pa[0]))
    b.add_body("b", ratio, 0.05 * ratio, pos=tuple(pb), omega=w0, vel=(-w0 * pb[1], w0 * pb[0]))
    b.add_slider("rail", "a", "b", axis=(1.0, 0.0), armature=arm)
    b.add_slider_motor("f", "rail")
    sim, traj, p, L, scale = _driven_for_a_second(b.compile(), dt, 0.3 * min(1.0, ratio), 5.0)
    assert np.abs(L - L[0]).max() <= 1e-12 * scale
    assert np.abs(p - p[0]).max() <= 1e-12 * scale
    assert_clean(sim)


@pytest.mark.parametrize("ratio", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("arm", [0.0, 0.02])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_an_arms_angular_momentum_about_its_shoulder_is_the_shoulder_motors_impulse(ratio, arm, dt):
    """A two-link arm (0.5 m thin rods, the forearm `ratio` times the upper arm's 1 kg) hinged
    to the world at its shoulder, in zero gravity, rotors `arm` on both hinges, its elbow
    motor and shoulder motor driven for 1 s: the elbow motor's torque on the forearm comes
    back on the upper arm, and the shoulder pin's impulses act through the shoulder, so the
    angular momentum about the shoulder (the shoulder rotor's a w included; the elbow
    rotor's, on a relative rate, is internal) is the shoulder motor's impulse, h sum tau,
    to rounding (measured <= 2.3e-13 of the scale)."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("upper", 1.0, 1 / 48, pos=(0.25, 0.0))
    b.add_body("lower", ratio, ratio / 48, pos=(0.75, 0.0))
    b.add_pin("shoulder", None, "upper", anchor_world=(0.0, 0.0), armature=arm)
    b.add_pin("elbow", "upper", "lower", anchor_world=(0.5, 0.0), armature=arm)
    b.add_pin_motor("elbow", "elbow")
    b.add_pin_motor("shoulder", "shoulder")
    model = b.compile()
    sim = ps.Simulator(model)
    amp = 0.3 * min(1.0, ratio)
    traj = sim.run(1.0, controller=lambda s: np.array([amp * math.sin(6 * s.t),
                                                        0.5 * amp * math.cos(4 * s.t)]))
    _, L = _momenta(traj.q, traj.v, model)
    L = L + arm * traj.v[:, 0, 2]
    impulse = np.r_[0.0, dt * np.cumsum(traj.act_u[1:, 1])]
    assert np.abs(L - impulse).max() <= 1e-12 * (np.abs(L).max() + amp)
    assert np.abs(traj.v[:, 1, 2] - traj.v[:, 0, 2]).max() > 1e-3     # the elbow turned
    assert_clean(sim)


def _hip_and_axial(dt):
    """Zero gravity, no ground: a hip point mass with two legs (rods) to foot point masses
    (0.5 and 0.05 kg) driven by a hip torque; a point mass and a spinning rigid body pushed
    apart by an axial force between the mass and a point 0.1 m off the body's centre."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_point_mass("hip", 2.0, pos=(0.0, 0.0))
    b.add_point_mass("fa", 0.5, pos=(0.3, -0.9))
    b.add_point_mass("fb", 0.05, pos=(-0.2, -0.95))
    b.add_rod("la", "hip", "fa")
    b.add_rod("lb", "hip", "fb")
    b.add_hip_torque("hip torque", "hip", "fa", "fb")
    b.add_point_mass("p", 1.0, pos=(3.0, 0.0), vel=(0.0, -0.5))
    b.add_body("q", 0.1, 0.01, pos=(4.0, 0.2), vel=(0.0, 2.0), omega=1.0)
    b.add_axial("axial", "p", "q", anchor_b=(0.1, 0.0))
    return b.compile()


def test_hip_torques_and_axial_forces_keep_the_momenta_and_their_work_is_the_energy_to_first_order():
    """A hip torque (0.3 cos 4t N m) between two legs of point masses and an axial force
    (2 cos 3t N) between a point mass and a spinning body, each system free in zero gravity:
    internal forces, so each keeps its linear and angular momentum to rounding (measured
    <= 1e-14). The actuators' recorded work (their power at each step's start velocity,
    times h) meets each system's change of kinetic energy to first order in dt: the largest
    mismatch over 1 s shrinks tenfold from dt 1e-3 to 1e-4 (measured 8.9e-3 and 9.0e-4 of
    the hip's largest kinetic energy, 3.1e-3 and 3.1e-4 of the axial pair's)."""
    mismatch = {}
    for dt in (1e-3, 1e-4):
        model = _hip_and_axial(dt)
        sim = ps.Simulator(model)
        traj = sim.run(1.0, controller=lambda s: np.array([0.3 * math.cos(4 * s.t),
                                                            2.0 * math.cos(3 * s.t)]))
        for k, bodies in enumerate(((0, 1, 2), (3, 4))):
            q, v = traj.q[:, bodies], traj.v[:, bodies]
            m = model.arrays.body_mass[list(bodies)]
            inertia = model.arrays.body_inertia[list(bodies)]
            L = np.sum(m * (q[..., 0] * v[..., 1] - q[..., 1] * v[..., 0]) + inertia * v[..., 2], axis=-1)
            p = np.stack([np.sum(m * v[..., 0], axis=-1), np.sum(m * v[..., 1], axis=-1)], axis=-1)
            scale = float(np.max(np.sum(m * np.hypot(v[..., 0], v[..., 1]) * (1 + np.hypot(q[..., 0], q[..., 1]))
                                        + inertia * np.abs(v[..., 2]), axis=-1)))
            assert np.abs(L - L[0]).max() <= 1e-12 * scale
            assert np.abs(p - p[0]).max() <= 1e-12 * scale
            ke = 0.5 * np.sum(m * (v[..., 0] ** 2 + v[..., 1] ** 2) + inertia * v[..., 2] ** 2, axis=-1)
            work = np.r_[0.0, dt * np.cumsum(traj.act_power[1:, k])]
            mismatch[k, dt] = np.abs(ke - ke[0] - work).max() / ke.max()
        assert_clean(sim)
    for k in range(2):
        assert mismatch[k, 1e-3] <= 0.02
        assert 7.0 <= mismatch[k, 1e-3] / mismatch[k, 1e-4] <= 13.0, mismatch


def _rotor_pairs(dt):
    """Zero gravity, no ground: two free bodies on a slider (anchor 0.2 m off body b's
    centre) with a rotor of 0.5 kg on the slide and its motor, turning at 3 rad/s; two free
    bodies on a hinge with a rotor of 0.5 kg m^2 and its motor, turning at 2 rad/s."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    pa, pb = np.array([-0.3, 0.0]), np.array([0.3, 0.2])
    b.add_body("a", 1.0, 0.05, pos=tuple(pa), omega=3.0, vel=(-3.0 * pa[1], 3.0 * pa[0]))
    b.add_body("b", 0.3, 0.02, pos=tuple(pb), omega=3.0, vel=(-3.0 * pb[1], 3.0 * pb[0]))
    b.add_slider("rail", "a", "b", axis=(1.0, 0.0), armature=0.5)
    b.add_slider_motor("push", "rail")
    b.add_body("c", 1.0, 0.05, pos=(5.0, 0.0), omega=2.0)
    b.add_body("d", 0.2, 0.01, pos=(5.4, 0.0), vel=(0.0, 0.8), omega=2.0)
    b.add_pin("hinge", "c", "d", anchor_world=(5.2, 0.0), armature=0.5)
    b.add_pin_motor("turn", "hinge")
    return b.compile(), lambda s: np.array([0.5 * math.sin(5 * s.t), 0.1 * math.cos(6 * s.t)])


def _four_bar(dt):
    """A crank-rocker in zero gravity (ground pivots 1 m apart; crank 0.3 m, 0.5 kg; coupler
    1 m, 1 kg; rocker 0.8 m, 0.8 kg: thin rods), a closed loop, its crank driven by a
    constant 3 N m from rest up to 92 rad/s in 2 s (0.09 rad a step at dt 1e-3)."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    A = 0.3 * np.array([math.cos(1.0), math.sin(1.0)])
    O4 = np.array([1.0, 0.0])
    d = float(np.linalg.norm(O4 - A))
    along = (1.0 - 0.64 + d * d) / (2 * d)
    B = A + along * (O4 - A) / d + math.sqrt(1.0 - along * along) * np.array([A[1], 1.0 - A[0]]) / d

    def link(name, p, q, mass):
        length = float(np.linalg.norm(q - p))
        return b.add_body(name, mass, mass * length * length / 12, pos=tuple((p + q) / 2),
                          angle=math.atan2(q[1] - p[1], q[0] - p[0]))
    crank = link("crank", np.zeros(2), A, 0.5)
    coupler = link("coupler", A, B, 1.0)
    rocker = link("rocker", O4, B, 0.8)
    b.add_pin("O2", None, crank, anchor_world=(0.0, 0.0))
    b.add_pin("A", crank, coupler, anchor_world=tuple(A))
    b.add_pin("B", coupler, rocker, anchor_world=tuple(B))
    b.add_pin("O4", None, rocker, anchor_world=tuple(O4))
    b.add_pin_motor("crank", "O2")
    return b.compile(), lambda s: np.array([3.0])


@pytest.mark.parametrize("scene, bound", [(_rotor_pairs, 2e-3), (_four_bar, 2e-2)])
def test_the_motors_work_is_the_kinetic_energy_with_the_rotors_share_to_first_order(scene, bound):
    """Motors driving rotors on a turning slider and hinge (their velocity-product forces
    included) and a closed four-bar loop: the motors' recorded work (power at each step's
    start velocity, times h) meets the change of kinetic energy, the rotors' a rate^2 / 2
    included, to first order in dt: the largest mismatch over the run, as a share of the
    largest kinetic energy, is below `bound` at dt 1e-3 and shrinks at least fivefold at
    dt 1e-4 (measured 6.6e-4 -> 6.6e-5 and 8.8e-3 -> 1.5e-4)."""
    mismatch = []
    for dt in (1e-3, 1e-4):
        model, control = scene(dt)
        sim = ps.Simulator(model)
        traj = sim.run(2.0 if scene is _four_bar else 1.0, controller=control)
        ke = kinetic_energy(model, traj.q, traj.v)
        work = np.r_[0.0, dt * np.cumsum(traj.act_power[1:].sum(axis=1))]
        mismatch.append(np.abs(ke - ke[0] - work).max() / ke.max())
        assert_clean(sim)
    assert mismatch[0] <= bound
    assert mismatch[1] <= mismatch[0] / 5, mismatch


# --- the DC motor model ---------------------------------------------------------------------

def _motor_flywheel(dt, gear, rotor, inertia, **friction):
    """A flywheel (inertia [kg m^2]) at a world hinge carrying the reflected rotor G^2 Jm as
    its armature, and the motor row (K 0.018 N m/A, Imax 6 A, R 1.3 ohm, Vc 0.7 V)."""
    mp = make_motor(gear=gear, torque_const=0.018, resistance=1.3, contact_voltage=0.7,
                    current_max=6.0, rotor_inertia=rotor, **friction)
    return _wheel(dt, inertia, armature=gear * gear * rotor), mp, inertia + gear * gear * rotor


def _spin_up(model, mp, current, n):
    """Run n steps with the motor's torque at the current command [A] (saturated) and the
    step's start rate, as a walker's controller drives it; returns the trajectory."""
    sim = ps.Simulator(model)
    traj = sim.run(n_steps=n, controller=lambda s: np.array(
        [motor_torque(saturate_current(current, mp), s.state.v[0, 2], mp)]))
    assert_clean(sim)
    return traj


@pytest.mark.parametrize("gear, rotor, inertia, viscous, dt", [
    (34.0, 1.6e-6, 2e-3, 0.01, 1e-3),      # Ranger's hip motor
    (1000.0, 1e-7, 1e-3, 0.5, 1e-3),       # a large gear: the rotor 100x the flywheel
    (10.0, 1e-5, 1.0, 0.2, 1e-2),
    (34.0, 1.6e-6, 2e-3, 0.01, 1e-4)])
def test_a_dc_motor_spins_a_flywheel_up_to_its_no_load_speed_exponentially(gear, rotor, inertia, viscous, dt):
    """A current command I = 3 A into the motor model with viscous friction c1 alone: the
    torque G K I - c1 w taken at each step's start rate gives w_n+1 = w_n + h (G K I - c1
    w_n) / J, J = I_fly + G^2 Jm, whose solution w_n = w_inf (1 - (1 - h / T)^n) (w_inf = G K
    I / c1, T = J / c1) the run meets to rounding (measured <= 1.7e-13 of w_inf); the
    continuous w_inf (1 - exp(-t / T)) within its first-order error, at most (h / T) / (2 e)
    of w_inf (measured at that bound, to 0.1 %)."""
    model, mp, J = _motor_flywheel(dt, gear, rotor, inertia, viscous=viscous)
    T = J / viscous
    w_inf = gear * 0.018 * 3.0 / viscous
    n = int(round(3 * T / dt))
    traj = _spin_up(model, mp, 3.0, n)
    w = traj.v[:, 0, 2]
    k = np.arange(n + 1)
    recurrence = w_inf * (1 - (1 - dt / T) ** k)
    continuous = w_inf * (1 - np.exp(-k * dt / T))
    assert np.abs(w - recurrence).max() <= 1e-12 * w_inf
    err = np.abs(w - continuous).max() / w_inf
    assert err <= 1.02 * (dt / T) / (2 * math.e) + 1e-12
    assert w[-1] == pytest.approx(w_inf * (1 - math.exp(-3.0)), rel=5 * dt / T)


def test_a_dc_motor_with_coulomb_and_load_friction_settles_on_its_torque_balance():
    """With Coulomb (c0 0.01 N m) and load friction (mu 0.1) too, each smoothed by w / sqrt(w^2
    + w0^2): the flywheel settles where G K I = c1 w + (c0 + mu G K |I|) w / sqrt(w^2 + w0^2)
    (the root found by bisection), to rounding; a command of 100 A runs bit for bit as 6 A
    (Imax), and -6 A as the mirror image of +6 A."""
    model, mp, J = _motor_flywheel(1e-3, 34.0, 1.6e-6, 2e-3, viscous=0.01, coulomb=0.01,
                                   load_friction=0.1)
    n = int(round(40 * J / 0.01 / 1e-3))        # 40 time constants: exp(-40) ~ 4e-18
    ends = {}
    for current in (100.0, 6.0, -6.0, 2.0):
        ends[current] = _spin_up(model, mp, current, n)
    gk = 34.0 * 0.018

    def balance(w, i):
        return gk * i - 0.01 * w - (0.01 + 0.1 * gk * abs(i)) * w / math.sqrt(w * w + 0.25)
    for current in (6.0, 2.0):
        lo, hi = 0.0, gk * current / 0.01
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if balance(mid, current) > 0 else (lo, mid)
        assert ends[current].v[-1, 0, 2] == pytest.approx(lo, rel=1e-12)   # measured 1.7e-14
    assert np.array_equal(ends[100.0].v, ends[6.0].v)
    assert np.array_equal(ends[-6.0].v, -ends[6.0].v)


# --- a motor with the hinge's passive elements ----------------------------------------------

@pytest.mark.parametrize("inertia, c, arm, dt", [(0.1, 0.5, 0.0, 1e-3), (0.1, 0.5, 0.3, 1e-2),
                                                 (1e-3, 10.0, 0.0, 1e-2), (1e3, 1.0, 0.0, 1e-4),
                                                 (0.1, 1e3, 0.0, 1e-3)])
def test_a_motor_against_a_damper_takes_the_semi_implicit_recurrence(inertia, c, arm, dt):
    """A flywheel on a hinge with a damper c (implicit in the velocity solve) and a rotor a,
    under a constant torque: w_n+1 = (J w_n + h tau) / (J + h c), J = I + a, to rounding
    (measured <= 9e-15 of tau / c), at any h c / J (1e-7..100); the continuous (tau / c)(1 -
    exp(-c t / J)) within the backward Euler's error, at most h c / J of tau / c."""
    model = _wheel(dt, inertia, damping=c, armature=arm)
    sim = ps.Simulator(model)
    tau, n, J = 0.7, 300, inertia + arm
    traj = sim.run(n_steps=n, u=np.array([tau]))
    w = traj.v[:, 0, 2]
    rec = np.zeros(n + 1)
    for k in range(n):
        rec[k + 1] = (J * rec[k] + dt * tau) / (J + dt * c)
    assert np.abs(w - rec).max() <= 1e-13 * tau / c
    continuous = tau / c * (1 - np.exp(-c * np.arange(n + 1) * dt / J))
    assert np.abs(w - continuous).max() <= min(1.0, dt * c / J) * tau / c
    assert_clean(sim)


@pytest.mark.parametrize("inertia, fl, tau, dt", [(0.1, 0.5, 0.4, 1e-3), (0.1, 0.5, 0.7, 1e-3),
                                                  (1e-3, 0.5, 0.7, 1e-2), (0.1, 0.5, -0.7, 1e-3)])
def test_a_motor_against_joint_friction_turns_at_torque_less_friction(inertia, fl, tau, dt):
    """A flywheel on a hinge with dry friction fl: a torque within it holds the wheel
    exactly at rest, one beyond it spins it at (tau - fl sgn tau) t / I, to rounding."""
    model = _wheel(dt, inertia, frictionloss=fl)
    sim = ps.Simulator(model)
    n = int(round(1.0 / dt))
    traj = sim.run(n_steps=n, u=np.array([tau]))
    expected = math.copysign(max(abs(tau) - fl, 0.0), tau) * np.arange(n + 1) * dt / inertia
    assert np.abs(traj.v[:, 0, 2] - expected).max() <= 1e-13 * max(1.0, abs(expected[-1]))
    assert_clean(sim)


@pytest.mark.parametrize("inertia, tau, dt", [(0.1, 2.0, 1e-3), (1e-3, 0.1, 1e-2), (1.0, 50.0, 1e-3)])
def test_a_motor_pressing_a_hinge_on_its_limit_holds_it_there(inertia, tau, dt):
    """A constant torque drives a flywheel onto its hinge's limit at 0.5 rad: it never passes
    it (to 1e-12 rad), rests on it, and the limit's impulse is then h tau a step."""
    model = _wheel(dt, inertia, limit=(-0.5, 0.5))
    sim = ps.Simulator(model)
    traj = sim.run(n_steps=int(round(2.0 / dt)), u=np.array([tau]))
    assert traj.q[:, 0, 2].max() <= 0.5 + 1e-12
    assert sim.state.q[0, 2] == pytest.approx(0.5, abs=1e-12)
    assert abs(sim.state.v[0, 2]) <= 1e-12
    assert sim.state.last_pin_impulse[0, 3] == pytest.approx(dt * tau, rel=1e-9)
    assert_clean(sim)


@pytest.mark.parametrize("inertia, k, c, dt", [(0.1, 5.0, 0.5, 1e-3), (0.01, 1e4, 5.0, 1e-2)])
def test_a_motor_against_a_spring_damper_rests_at_the_static_deflection(inertia, k, c, dt):
    """A constant torque tau against a hinge spring k and damper c comes to rest at tau / k."""
    model = _wheel(dt, inertia, stiffness=k, damping=c)
    sim = ps.Simulator(model)
    sim.steps(int(20 * inertia / c / dt) + 2000, np.array([0.7]))
    assert sim.state.q[0, 2] == pytest.approx(0.7 / k, rel=1e-7)
    assert abs(sim.state.v[0, 2]) <= 1e-6 * 0.7 / k / dt
    assert_clean(sim)


# --- velocities at an instant (planarsim.half_step) -----------------------------------------

def _converted_flywheel(arm, dt=1e-2, n=50, tau=0.5):
    """A flywheel (1 kg, 0.1 kg m^2) at a world hinge with a rotor `arm`, a body on a free
    coordinate pushed by a body force and a body torque; at rest at an instant, its velocity
    converted to the step's, n steps of tau [N m] (and 0.3 N, 0.02 N m), converted back:
    (theta and w of the flywheel, x, vx, angle and w of the body) and J = 0.1 + arm."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("w", 1.0, 0.1)
    b.add_pin("axle", None, "w", anchor_world=(0.0, 0.0), armature=arm)
    b.add_pin_motor("m", "axle")
    free = b.add_body("free", 0.7, 0.04, pos=(3.0, 0.0))
    b.add_body_force("push", free)
    b.add_body_torque("twist", free)
    model = b.compile()
    sim = ps.Simulator(model)
    u = np.array([tau, 0.3, 0.02])
    to_step_velocity(model, sim.state, sim.ws, dt, u)
    sim.steps(n, u)
    to_instant_velocity(model, sim.state, sim.ws, dt, u)
    q, v = sim.state.q, sim.state.v
    return (q[0, 2], v[0, 2], q[1, 0] - 3.0, v[1, 0], q[1, 2], v[1, 2]), 0.1 + arm, n * dt


def test_actuated_bodies_converted_to_instants_follow_the_exact_parabola():
    """With the state's velocity converted to the step's on the way in and to the instant's on
    the way out (half a kick of the applied forces, the actuators' included), symplectic
    Euler is the leapfrog, exact for a constant force: a flywheel under a motor torque and a
    free body under a body force and torque land on theta = tau t^2 / (2 I), w = tau t / I
    (x = F t^2 / (2 m), v = F t / m) to rounding (measured <= 5e-16)."""
    (th, w, x, vx, ang, wb), J, t = _converted_flywheel(0.0)
    got = np.array([th, w, x, vx, ang, wb])
    exact = np.array([0.5 * t * t / 2 / J, 0.5 * t / J, 0.3 * t * t / 2 / 0.7, 0.3 * t / 0.7,
                      0.02 * t * t / 2 / 0.04, 0.02 * t / 0.04])
    assert np.abs(got / exact - 1).max() <= 1e-12


# --- RATTLE: a constant force's parabola is exact ------------------------------------------

@pytest.mark.parametrize("integrator", ["euler", "rattle", "rattle4", "rattle6"])
@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
def test_constant_actuators_give_the_parabola_exactly_under_rattle(integrator, dt):
    """A flywheel on a hinge (pin motor 0.8 N m), a block on a slider inclined 0.3 rad (its
    motor 1.5 N), a free body (a body force 0.6 N along (1, 1) and a body torque 0.05 N m),
    zero gravity, 0.5 s: velocity Verlet integrates a constant force exactly, so RATTLE and its
    compositions put each coordinate on x = F t^2 / (2 m) to rounding (measured <= 3e-13);
    symplectic Euler on (n + 1) / n times it. The rates are F t / m in all four."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("w", 2.0, 0.5)
    b.add_pin("axle", None, "w", anchor_world=(0.0, 0.0))
    b.add_pin_motor("m", "axle")
    b.add_body("blk", 3.0, 0.1, pos=(0.0, 2.0))
    b.add_slider("rail", None, "blk", axis=(math.cos(0.3), math.sin(0.3)))
    b.add_slider_motor("f", "rail")
    b.add_body("free", 0.7, 0.04, pos=(5.0, 0.0))
    b.add_body_force("bf", "free", direction=(1.0, 1.0))
    b.add_body_torque("bt", "free")
    model = b.compile()
    sim = ps.Simulator(model, ps.make_options(integrator=integrator))
    n = int(round(0.5 / dt))
    t = n * dt
    sim.steps(n, np.array([0.8, 1.5, 0.6, 0.05]))
    q, v = sim.state.q, sim.state.v
    got = np.array([q[0, 2], math.hypot(q[1, 0], q[1, 1] - 2.0), q[2, 0] - 5.0, q[2, 1], q[2, 2]])
    acc = np.array([0.8 / 0.5, 1.5 / 3.0, 0.6 / math.sqrt(2) / 0.7, 0.6 / math.sqrt(2) / 0.7, 0.05 / 0.04])
    factor = 1.0 if integrator != "euler" else (n + 1) / n
    assert np.abs(got / (acc * t * t / 2) - factor).max() <= 2e-12
    rates = np.array([v[0, 2], math.hypot(v[1, 0], v[1, 1]), v[2, 0], v[2, 1], v[2, 2]])
    assert np.abs(rates / (acc * t) - 1).max() <= 2e-12
    assert_clean(sim)


# --- a driven wheel on the ground ----------------------------------------------------------

@pytest.mark.parametrize("mu, tau", [(1.0, -0.05), (1.0, -0.5), (0.1, -0.05), (1.0, -2.0), (0.1, -0.5)])
@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_torque_on_a_disk_rolls_it_or_skids_it_as_the_closed_form_says(mu, tau, dt):
    """A 1 kg disk (radius 0.1 m, I = m r^2 / 2) on flat ground under a body torque tau for
    1 s: where the friction it needs, m a, is within mu m g it rolls at a = -tau r / (I + m
    r^2) (w = -v / r); beyond, it skids, the ground's friction mu m g pushing it on
    (v = mu g t) and braking its spin (w = (tau + mu m g r) t / I). Both to rounding
    (measured <= 3e-14), the contact pinned or sliding as it says."""
    r, m, g = 0.1, 1.0, 9.81
    inertia = 0.5 * m * r * r
    b = ps.ModelBuilder(dt=dt)
    disk = b.add_body("disk", m, inertia, pos=(0.0, r), shapes=[("circle", (0.0, 0.0), r, {"mu": mu})])
    b.add_body_torque("drive", disk)
    sim = ps.Simulator(b.compile())
    sim.run(1.0, u=np.array([tau]))
    a_roll = -tau * r / (inertia + m * r * r)
    rolls = m * a_roll <= mu * m * g
    v, w = (a_roll, -a_roll / r) if rolls else (mu * g, (tau + mu * m * g * r) / inertia)
    assert sim.state.v[0, 0] == pytest.approx(v, rel=1e-12)
    assert sim.state.v[0, 2] == pytest.approx(w, rel=1e-12)
    assert abs(sim.state.q[0, 1] - r) <= 1e-12 and abs(sim.state.v[0, 1]) <= 1e-12
    assert sim.state.contact_mode[0] == (1 if rolls else 2)
    assert_clean(sim)


# --- a motor pressing a spinning pair's joint onto its limit --------------------------------

def _spinning_pair_on_a_limit(dt, slider, w0=10.0):
    """A 1 kg body (0.05 kg m^2) and a 0.3 kg body (0.01 kg m^2) 0.5 m apart, turning rigidly
    at w0 [rad/s] about the origin in zero gravity, joined by a hinge (0.25 m from the first's
    centre) or a slider (along the line of their centres) limited to +-0.3, and its motor."""
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", 1.0, 0.05, pos=(-0.2, 0.0), vel=(0.0, -0.2 * w0), omega=w0)
    b.add_body("b", 0.3, 0.01, pos=(0.3, 0.0), vel=(0.0, 0.3 * w0), omega=w0)
    if slider:
        b.add_slider("joint", "a", "b", axis=(1.0, 0.0), limit=(-0.3, 0.3))
        b.add_slider_motor("m", "joint")
    else:
        b.add_pin("joint", "a", "b", anchor_world=(0.05, 0.0), limit=(-0.3, 0.3))
        b.add_pin_motor("m", "joint")
    return b.compile()


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_motor_pressing_a_spinning_pairs_hinge_onto_its_limit_keeps_the_angular_momentum(dt):
    """The spinning pair joined by a hinge, its motor (0.5 N m) turning it onto its limit and
    holding it there for 10 s: the motor's torques and the limit's impulses are internal, so
    the angular momentum stays to rounding (measured <= 8e-13)."""
    model = _spinning_pair_on_a_limit(dt, slider=False)
    sim = ps.Simulator(model)
    traj = sim.run(10.0, u=np.array([0.5]), record_every=int(round(0.1 / dt)))
    _, L = _momenta(traj.q, traj.v, model)
    assert np.abs(L / L[0] - 1).max() <= 1e-11
    assert sim.state.limit_active[0].any()                 # it rests on its limit
    assert_clean(sim)


# --- saturation, mirror symmetry, drift -----------------------------------------------------

def test_a_command_beyond_its_range_moves_as_the_ranges_bound_and_a_nonfinite_one_is_refused():
    """A pin motor limited to (-2, 5) N m: commands of 7, 1e300 and 5 give the same run bit for
    bit, as do -2 and -1e300; the recorded command is the bound; NaN and inf are refused before
    any step (a ValueError naming the actuator)."""
    model = _wheel(1e-3, 0.1, motor_limit=(-2.0, 5.0))
    runs = {}
    for u in (7.0, 1e300, 5.0, -2.0, -1e300):
        runs[u] = ps.Simulator(model).run(n_steps=100, u=np.array([u]))
    for a, b_ in ((7.0, 5.0), (1e300, 5.0), (-1e300, -2.0)):
        assert np.array_equal(runs[a].q, runs[b_].q) and np.array_equal(runs[a].v, runs[b_].v)
    assert np.all(runs[1e300].act_u[1:] == 5.0) and np.all(runs[-1e300].act_u[1:] == -2.0)
    assert runs[5.0].v[-1, 0, 2] == pytest.approx(100 * 1e-3 * 5.0 / 0.1, rel=1e-12)
    for bad in (math.nan, math.inf):
        sim = ps.Simulator(model)
        with pytest.raises(ValueError, match="'m'"):
            sim.step(np.array([bad]))
        assert sim.state.step[0] == 0


def _every_actuator(sign, dt, arm):
    """A double pendulum under gravity driven at both hinges (one with a range), a cart on a
    slider inclined 0.4 rad with a pole on a driven hinge, a free two-legged hip of point
    masses, a point mass pushing a body axially, a free body under a body force and torque;
    sign -1 mirrors it all in x."""
    b = ps.ModelBuilder(dt=dt)
    c, s = math.cos(0.3), math.sin(0.3)
    b.add_body("upper", 1.0, 1 / 48, pos=(sign * 0.25 * c, 1.0 - 0.25 * s), angle=-sign * 0.3)
    b.add_body("lower", 0.3, 0.01, pos=(sign * (0.5 * c + 0.2), 1.0 - 0.5 * s))
    b.add_pin("shoulder", None, "upper", anchor_world=(0.0, 1.0), armature=arm)
    b.add_pin("elbow", "upper", "lower", anchor_world=(sign * 0.5 * c, 1.0 - 0.5 * s), armature=arm)
    b.add_pin_motor("shoulder", "shoulder")
    b.add_pin_motor("elbow", "elbow", limit=(-1.0, 1.0))
    b.add_body("cart", 0.5, 0.02, pos=(sign * 2.0, 1.5))
    b.add_slider("rail", None, "cart", axis=(sign * math.cos(0.4), math.sin(0.4)), armature=arm)
    b.add_slider_motor("rail", "rail")
    b.add_body("pole", 0.2, 0.01, pos=(sign * 2.2, 1.5))
    b.add_pin("pole", "cart", "pole", anchor_world=(sign * 2.0, 1.5))
    b.add_pin_motor("pole", "pole")
    b.add_point_mass("hip", 2.0, pos=(sign * 4.0, 2.0))
    b.add_point_mass("fa", 0.5, pos=(sign * 4.3, 1.1))
    b.add_point_mass("fb", 0.05, pos=(sign * 3.8, 1.05))
    b.add_rod("la", "hip", "fa")
    b.add_rod("lb", "hip", "fb")
    b.add_hip_torque("hip", "hip", "fa", "fb")
    b.add_point_mass("p", 1.0, pos=(sign * 6.0, 2.0))
    b.add_body("q", 0.1, 0.01, pos=(sign * 7.0, 2.2), omega=sign * 1.0)
    b.add_axial("axial", "p", "q", anchor_b=(sign * 0.1, 0.0))
    b.add_body("free", 0.7, 0.04, pos=(sign * 9.0, 3.0), angle=sign * 0.2)
    b.add_body_force("push", "free", direction=(sign * 1.0, 2.0))
    b.add_body_torque("twist", "free")
    return b.compile()


@pytest.mark.parametrize("dt, arm", [(1e-3, 0.0), (1e-2, 0.01)])
def test_a_mechanism_and_its_mirror_image_move_as_mirror_images_bit_for_bit(dt, arm):
    """Every actuator kind in one model (_every_actuator) and its mirror image in x, the
    torques' commands negated (the forces' not: their directions are mirrored), 2 s under
    gravity: the mirror's q and v are (-x, y, -theta) and (-vx, vy, -w) of the original's,
    bit for bit (the step's arithmetic is odd in x)."""
    runs = []
    for sign in (1.0, -1.0):
        model = _every_actuator(sign, dt, arm)
        sim = ps.Simulator(model)

        def control(s, sign=sign):
            t = s.t
            return np.array([sign * 2 * math.sin(3 * t), sign * 3 * math.cos(5 * t),
                             4 * math.sin(2 * t), sign * 0.3 * math.sin(7 * t),
                             sign * 0.2 * math.cos(4 * t), 2 * math.cos(3 * t),
                             5 * math.sin(t), sign * 0.05 * math.cos(6 * t)])
        runs.append(sim.run(2.0, controller=control))
        assert_clean(sim)
    a, m = runs
    flip = np.array([-1.0, 1.0, -1.0])
    assert np.array_equal(a.q, m.q * flip) and np.array_equal(a.v, m.v * flip)
    assert np.abs(a.v).max() > 1.0                      # it did move


@pytest.mark.parametrize("slider", [False, True])
@pytest.mark.parametrize("dt, ratio, arm", [(1e-3, 1.0, 0.0), (1e-2, 0.01, 0.0), (1e-2, 1.0, 0.05)])
def test_an_internally_driven_pair_drifting_at_1_km_s_moves_as_at_rest(slider, dt, ratio, arm):
    """Two free bodies joined by a driven pin (or slider), with or without a rotor, drifting
    at 1000 m/s (and 300 m/s across) moves relative to its drift as at rest, to 1e-9 of its
    velocities (measured <= 1.1e-10)."""
    def run(drift):
        b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
        b.add_body("a", 1.0, 0.05, vel=(drift, 0.3 * drift))
        b.add_body("b", ratio, 1e-2 * ratio, pos=(0.3, 0.0), vel=(drift, 0.3 * drift))
        if slider:
            b.add_slider("joint", "a", "b", axis=(1.0, 0.0), armature=arm)
            b.add_slider_motor("m", "joint")
        else:
            b.add_pin("joint", "a", "b", anchor_world=(0.0, 0.0), armature=arm)
            b.add_pin_motor("m", "joint")
        sim = ps.Simulator(b.compile())
        amp = 0.5 * min(1.0, ratio)
        traj = sim.run(1.0, controller=lambda s: np.array([amp * math.sin(3 * s.t)]))
        assert_clean(sim)
        v = traj.v - np.array([drift, 0.3 * drift, 0.0])
        return v
    rest, drifting = run(0.0), run(1000.0)
    assert np.abs(drifting - rest).max() <= 1e-9 * np.abs(rest).max()


# --- known defects --------------------------------------------------------------------------

@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["driven_fast_turn"])
@pytest.mark.parametrize("per_step, duration", [(0.003, 1.0), (0.01, 0.4)])
def test_a_motor_spinning_a_link_about_its_hinge_keeps_the_hinge_angular_momentum_tau_t(per_step, duration):
    """The link of the test above, now 1 kg with 1e-3 kg m^2 about its centre, 0.3 m from the
    hinge, at dt 1e-2: a torque that adds `per_step` rad a step to its turn each step (2.73 and
    9.1 N m, far within the turn check's 0.2 rad) brings it to 0.3 and 0.4 rad a step; the
    angular momentum about the hinge stays tau t to rounding, or the run stops."""
    mass, inertia, d, dt = 1.0, 1e-3, 0.3, 1e-2
    J = inertia + mass * d * d
    tau = per_step * J / dt ** 2
    model = _wheel(dt, inertia, mass, d)
    sim = ps.Simulator(model)
    try:
        traj = sim.run(duration, u=np.array([tau]))
    except ps.SimulationDiverged:
        return
    _, L = _momenta(traj.q, traj.v, model)
    short = 1 - L[-1] / (tau * traj.t[-1])
    print(f"tau {tau:.3g} N m: w {traj.v[-1, 0, 2]:.2f} rad/s, L short by {short:.3f}, "
          f"solves {step_info(sim.ws)['solves']}")
    assert np.abs(L - tau * traj.t).max() <= 1e-11 * tau * traj.t[-1]


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=DEFECTS["driven_fast_turn"])
def test_an_internal_motor_spinning_a_light_link_keeps_a_free_pairs_angular_momentum():
    """A 1 kg base (0.05 kg m^2) and a 0.01 kg link (1e-5 kg m^2) whose centre lies 0.3 m from
    the pin joining them, free in zero gravity at dt 1e-2: their motor (0.0273 N m) spins the
    link to 0.45 rad a step relative to the base. The motor's torques are internal: the
    angular momentum stays zero to rounding, or the run stops."""
    dt = 1e-2
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0), ground=None)
    b.add_body("base", 1.0, 0.05)
    b.add_body("link", 0.01, 1e-5, pos=(0.3, 0.0))
    b.add_pin("hinge", "base", "link", anchor_world=(0.0, 0.0))
    b.add_pin_motor("m", "hinge")
    model = b.compile()
    sim = ps.Simulator(model)
    tau = 0.003 * (1e-5 + 0.01 * 0.09) / dt ** 2
    try:
        traj = sim.run(n_steps=150, u=np.array([tau]))
    except ps.SimulationDiverged:
        return
    _, L = _momenta(traj.q, traj.v, model)
    print(f"largest |L| / (tau t): {np.abs(L).max() / (tau * traj.t[-1]):.3f}")
    assert np.abs(L).max() <= 1e-11 * tau * traj.t[-1]


@pytest.mark.parametrize("acting", [dict(motor=True), dict(motor=True, armature=0.01),
                                    dict(stiffness=2.0), dict(damping=0.05),
                                    dict(limit=(-1.0, 1.0)), dict(frictionloss=0.1)])
@pytest.mark.parametrize("world", [False, True])
def test_what_acts_on_a_hinge_to_a_point_mass_is_refused_naming_it(acting, world):
    """A point mass does not turn, so the angle of a hinge to one is not a relative angle of
    two bodies: a motor, spring, damper, limit, armature or dry friction on it would act with
    no reaction (measured before the builder refused them: a body of 1 kg, 0.02 kg m^2 and a
    0.5 kg point mass pinned 0.3 m from its centre, free in zero gravity, a motor of 0.1 N m
    for 1 s gave the pair -0.1000 N m s of angular momentum, as an outside torque would; a
    damper of 0.05 N m s/rad braked their free spin of 3 rad/s to 1.1 rad/s in 1 s). The
    builder refuses each, naming the point mass; the bare hinge is a plain pin."""
    acting = dict(acting)
    motor = acting.pop("motor", False)
    b = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0), ground=None)
    b.add_body("a", 1.0, 0.02)
    b.add_point_mass("p", 0.5, pos=(0.3, 0.0))
    with pytest.raises(ModelError, match="point mass 'p', which does not turn"):
        b.add_pin("h", None if world else "a", "p", anchor_world=(0.3, 0.0), **acting)
        if motor:
            b.add_pin_motor("m", "h")
    plain = ps.ModelBuilder(dt=1e-3, gravity=(0.0, 0.0), ground=None)
    plain.add_body("a", 1.0, 0.02)
    plain.add_point_mass("p", 0.5, pos=(0.3, 0.0))
    plain.add_pin("h", None if world else "a", "p", anchor_world=(0.3, 0.0))
    assert plain.compile().n_pin == 1


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_motor_pressing_a_spinning_pairs_slider_onto_its_limit_keeps_the_angular_momentum(dt):
    """The spinning pair of the hinge test above joined by a slider instead, its motor (1 N)
    pushing the slide onto its limit and holding it there for 10 s: the motor's forces and
    the limit's impulses act on both bodies at one point, equal and opposite, so the angular
    momentum stays to rounding. (Measured before a held limit's correction moved the
    velocities with the positions: 9.0 % lost in 10 s at dt 1e-3, 41 % at 1e-2.)"""
    model = _spinning_pair_on_a_limit(dt, slider=True)
    sim = ps.Simulator(model)
    traj = sim.run(10.0, u=np.array([1.0]), record_every=int(round(0.1 / dt)))
    _, L = _momenta(traj.q, traj.v, model)
    print(f"dt {dt}: angular momentum lost in 10 s {1 - L[-1] / L[0]:.3f}")
    assert sim.state.limit_active[0].any()
    assert np.abs(L / L[0] - 1).max() <= 1e-11


@pytest.mark.parametrize("ratio", [1.0, 10.0])
def test_a_flywheel_with_a_rotor_is_refused_by_the_half_step_conversions(ratio):
    """The converted flywheel of the test above with a rotor of `ratio` times its inertia on
    its hinge: the half kick and the projection weigh the bodies alone (measured before the
    conversions refused rotors: 2.0 % short of theta = tau t^2 / (2 (I + a)) at a = I, 20 %
    at a = 10 I), so the conversions refuse it, naming the joint."""
    with pytest.raises(ModelError, match="has a rotor"):
        _converted_flywheel(0.1 * ratio)


# --- the recorded power of every actuator kind ------------------------------------------------

def _turned(q, body, local):
    """World points [m] of `local` on `body` over frames q."""
    c, s = np.cos(q[:, body, 2]), np.sin(q[:, body, 2])
    return q[:, body, :2] + np.stack([c * local[0] - s * local[1], s * local[0] + c * local[1]], 1)


def _actuated(kind, dt):
    """(model, command as a function of t, the actuator's coordinate over frames q) of a small
    zero-gravity scene that turns and moves what the actuator pushes on."""
    b = ps.ModelBuilder(dt=dt, ground=None, gravity=(0.0, 0.0))
    if kind == "pin torque":
        arm = b.add_body("arm", mass=1.0, inertia=0.05, pos=(0.3, 0.0))
        b.add_pin("p", None, arm, anchor_world=(0.0, 0.0))
        b.add_pin_motor("m", "p")
        return b.compile(), lambda t: 3.0 * math.sin(5 * t), lambda q: q[:, 0, 2]
    if kind == "axial":
        a = b.add_body("a", mass=1.0, inertia=0.02, pos=(0.0, 0.0), omega=2.0)
        c = b.add_body("b", mass=2.0, inertia=0.03, pos=(1.0, 0.2), omega=-3.0, vel=(0.1, 0.5))
        b.add_axial("ax", a, c, anchor_a=(0.1, 0.05), anchor_b=(-0.1, 0.0))
        return (b.compile(), lambda t: 5.0 * math.sin(3 * t) + 1.0,
                lambda q: np.hypot(*(_turned(q, 1, (-0.1, 0.0)) - _turned(q, 0, (0.1, 0.05))).T))
    if kind == "hip torque":
        hip = b.add_point_mass("hip", 5.0, pos=(0.0, 1.0))
        la = b.add_point_mass("fa", 1.0, pos=(0.3, 0.1), vel=(0.5, 0.0))
        lb = b.add_point_mass("fb", 1.0, pos=(-0.3, 0.1), vel=(0.0, -0.3))
        b.add_rod("ra", hip, la)
        b.add_rod("rb", hip, lb)
        b.add_hip_torque("ht", hip, la, lb)

        def angle(q):
            da, db = q[:, 1, :2] - q[:, 0, :2], q[:, 2, :2] - q[:, 0, :2]
            return np.unwrap(np.arctan2(db[:, 1], db[:, 0]) - np.arctan2(da[:, 1], da[:, 0]))
        return b.compile(), lambda t: 2.0 * math.sin(4 * t) + 0.5, angle
    if kind == "body force":
        a = b.add_body("a", mass=1.0, inertia=0.05, pos=(0.0, 0.0), vel=(0.2, 1.0), omega=3.0)
        b.add_body_force("f", a, direction=(0.6, 0.8))
        return b.compile(), lambda t: 4.0 * math.cos(2 * t), lambda q: 0.6 * q[:, 0, 0] + 0.8 * q[:, 0, 1]
    if kind == "body torque":
        a = b.add_body("a", mass=1.0, inertia=0.05, pos=(0.0, 0.0), omega=1.0)
        b.add_body_torque("t", a)
        return b.compile(), lambda t: 0.3 * math.cos(2 * t), lambda q: q[:, 0, 2]
    base = b.add_body("base", mass=2.0, inertia=0.2, pos=(0.0, 0.0), omega=1.5)     # slider
    car = b.add_body("car", mass=0.5, inertia=0.01, pos=(0.3, 0.0))
    b.add_pin("bp", None, base, anchor_world=(0.0, 0.0))
    b.add_slider("s", base, car, axis=(1.0, 0.0))
    b.add_slider_motor("sm", "s")

    def slide(q):
        axis = np.stack([np.cos(q[:, 0, 2]), np.sin(q[:, 0, 2])], 1)
        return np.sum((q[:, 1, :2] - q[:, 0, :2]) * axis, axis=1)
    return b.compile(), lambda t: math.sin(3 * t), slide


@pytest.mark.parametrize("integrator", ["euler", "rattle4"])
@pytest.mark.parametrize("kind", ["pin torque", "axial", "hip torque", "body force", "body torque",
                                  "slider"])
def test_the_recorded_power_times_dt_is_the_commands_work_in_the_step(kind, integrator):
    """Every actuator kind, turning and moving at up to 0.1 rad a step (dt 1e-2): act_power
    times dt is, step by step, the saturated command times its coordinate's move (joint angle,
    anchors' distance, the legs' angle at the hip, position along the force, slide), to
    rounding, whatever the integrator (taken at the step's start rates, the axial force's work
    between the spinning bodies came out 6 % short)."""
    model, command, coordinate = _actuated(kind, 1e-2)
    sim = ps.Simulator(model, ps.make_options(integrator=integrator))
    traj = sim.run(n_steps=300, controller=lambda s: np.array([command(s.t)]))
    work = traj.act_power[1:, 0] * np.diff(traj.t)
    moved = traj.act_u[1:, 0] * np.diff(coordinate(traj.q))
    assert np.abs(moved).max() > 1e-3
    np.testing.assert_allclose(work, moved, rtol=0.0, atol=1e-12 * np.abs(moved).max())


@pytest.mark.parametrize("every", [3, 7])
def test_sparse_frames_hold_the_mean_power_since_the_frame_before(every):
    """Recorded every few steps, a frame's act_power is the mean over the steps since the frame
    before: the time between frames times it is the work of those steps, the same as summed
    from a run that records every step (a frame holding its last step's power alone made a
    quadruped's energy spent 17 % high at every tenth step), and a second run continues from
    its own first frame."""
    model, command, _ = _actuated("axial", 1e-2)
    runs = []
    for k in (1, every):
        sim = ps.Simulator(model)
        control = lambda s: np.array([command(s.t)])
        first = sim.run(n_steps=21 * every, controller=control, record_every=k)
        second = sim.run(n_steps=21 * every, controller=control, record_every=k)
        runs.append([float(np.sum(t.act_power[1:, 0] * np.diff(t.t))) for t in (first, second)])
    assert abs(runs[0][0]) > 0.1 and abs(runs[0][1]) > 0.1
    np.testing.assert_allclose(runs[1], runs[0], rtol=1e-12)
