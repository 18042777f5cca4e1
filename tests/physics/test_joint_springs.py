"""Joint springs and dampers, implicit in the velocity solve (kernels/constraints/soft.py): stable where
explicit forces diverge, and the damped oscillator's closed form at small steps."""
import math

import numpy as np
import pytest

import planarsim as ps
from planarsim import measure
from planarsim.energy import total_energy


def wheel(dt, k, c, theta0, inertia=0.02):
    """A wheel pinned at its COM to the world (gravity exerts no torque about it) with a
    spring k [N m/rad] and damper c [N m s/rad] toward angle 0, released at rest at theta0."""
    b = ps.ModelBuilder(dt=dt)
    w = b.add_body("wheel", mass=1.0, inertia=inertia, angle=theta0)
    b.add_pin("axle", None, w, anchor_world=(0.0, 0.0), stiffness=k, damping=c, ref_angle=0.0)
    return b.compile()


def oscillator(t, k, c, inertia, theta0):
    """Closed form of I x'' + c x' + k x = 0, x(0) = theta0, x'(0) = 0 (underdamped)."""
    wn = math.sqrt(k / inertia)
    zeta = c / (2 * math.sqrt(k * inertia))
    wd = wn * math.sqrt(1 - zeta * zeta)
    return theta0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


def explicit(dt, n, k, c, inertia, theta0):
    """The same oscillator with the spring and damper as explicit forces (symplectic Euler:
    what the engine did before they were implicit)."""
    x, w = theta0, 0.0
    out = [x]
    for _ in range(n):
        w += dt * (-k * x - c * w) / inertia
        x += dt * w
        out.append(x)
    return np.array(out)


def test_implicit_spring_damper_matches_closed_form_to_first_order():
    """k 2 N m/rad, c 0.02 N m s/rad, I 0.02 kg m^2 (10 rad/s, damping ratio 0.05) over 3 s:
    the implicit spring-damper's largest error against the closed form halves with dt (first
    order). Its leading error is the damping h k that backward Euler adds to c (an amplitude
    decay rate h k / (2 I)), so the error stays below theta0 h k T / (2 I) (0.075 rad at dt
    1e-3); the explicit forces' trajectory is as close (the two differ at O(h) too)."""
    k, c, inertia, theta0, T = 2.0, 0.02, 0.02, 0.5, 3.0
    err = {}
    for dt in (2e-3, 1e-3):
        model = wheel(dt, k, c, theta0, inertia)
        traj = ps.Simulator(model).run(T, record_every=1)
        x = measure.joint_angles(traj, model)["axle"][0]
        t = np.asarray(traj.t)
        err[dt] = np.max(np.abs(x - oscillator(t, k, c, inertia, theta0)))
        ex = explicit(dt, len(t) - 1, k, c, inertia, theta0)
        err_explicit = np.max(np.abs(ex - oscillator(t, k, c, inertia, theta0)))
        assert np.max(np.abs(x - ex)) < 2 * (err[dt] + err_explicit)
    assert err[1e-3] < theta0 * 1e-3 * k * T / (2 * inertia)
    assert 0.4 < err[1e-3] / err[2e-3] < 0.6


@pytest.mark.parametrize("slide", [False, True], ids=["hinge", "slider"])
def test_a_spring_without_damper_or_rotor_keeps_its_energy(slide):
    """A spring alone (no damper, no rotor) that the step resolves is symplectic Euler's
    explicit force, as MuJoCo's Euler takes it: over 20 s (about 32 periods) of a 10 rad/s
    oscillator at dt 1e-3 its energy oscillates within h w of its start (measured 0.50 %) and
    does not drift. Kept at the step's end (backward Euler, an added damping h k) it would
    lose 1 - exp(-h k T / I) = 86 % of it."""
    k, inertia, theta0, dt = 2.0, 0.02, 0.5, 1e-3
    b = ps.ModelBuilder(dt=dt, gravity=(0.0, 0.0))
    if slide:
        w = b.add_body("cart", mass=inertia, inertia=1.0, pos=(theta0, 0.0))
        b.add_slider("rail", None, w, axis=(1.0, 0.0), anchor_world=(theta0, 0.0),
                     stiffness=k, rest=-theta0)
    else:
        w = b.add_body("wheel", mass=1.0, inertia=inertia, angle=theta0)
        b.add_pin("axle", None, w, anchor_world=(0.0, 0.0), stiffness=k, ref_angle=0.0)
    model = b.compile()
    traj = ps.Simulator(model).run(20.0, record_every=10)
    energy = np.array([total_energy(model, q, v) for q, v in zip(traj.q, traj.v)])
    start = 0.5 * k * theta0 ** 2
    assert abs(energy[0] - start) <= 1e-12 * start
    assert np.max(np.abs(energy - start)) <= dt * math.sqrt(k / inertia) * start
    late = energy[len(energy) // 2:]
    assert abs(late.mean() - energy[:len(energy) // 2].mean()) <= 1e-3 * start


def light_link(dt, k=240.0, c=6.0, theta0=0.5, length=0.1):
    """A 1 kg rod of `length` [m] pinned at its end to the world, spring k and damper c toward
    hanging down, released at rest theta0 [rad] from hanging."""
    b = ps.ModelBuilder(dt=dt)
    d = length / 2
    link = b.add_body("link", mass=1.0, inertia=length ** 2 / 12,
                      pos=(d * math.sin(theta0), -d * math.cos(theta0)), angle=theta0)
    b.add_pin("hip", None, link, anchor_world=(0.0, 0.0), stiffness=k, damping=c, ref_angle=0.0)
    return b.compile()


def test_stiff_spring_damper_at_a_large_step_is_stable_and_decays():
    """240 N m/rad and 6 N m s/rad on a 1 kg, 0.1 m link (I = 1/300 kg m^2 about the pin) at
    dt 1e-2: explicit forces diverge here (h c / I = 18 and h w_n = 2.7, far outside symplectic
    Euler's stability); implicit, the angle decays monotonically in amplitude to the
    equilibrium (0, where gravity and the spring agree) and the energy never rises."""
    dt, k, c, theta0 = 1e-2, 240.0, 6.0, 0.5
    inertia = 1.0 / 300.0
    # the explicit recurrence's amplification on the linearised spring-damper exceeds 1
    # (w, x) -> after one step, w first (symplectic Euler)
    A = np.array([[1 - dt * c / inertia, -dt * k / inertia],
                  [dt * (1 - dt * c / inertia), 1 - dt * dt * k / inertia]])
    assert np.max(np.abs(np.linalg.eigvals(A))) > 1.0
    model = light_link(dt, k, c, theta0)
    sim = ps.Simulator(model)
    traj = sim.run(2.0, record_every=1)
    x = measure.joint_angles(traj, model)["hip"][0]
    assert np.all(np.isfinite(x))
    assert np.max(np.abs(x)) <= theta0 + 1e-12
    assert abs(x[-1]) < 1e-9
    E = total_energy(model, traj.q, traj.v)
    assert np.all(np.diff(E) <= 1e-9 * abs(E[0]) + 1e-12)
    assert sim.ws.audit.sum() == 0


def test_slider_spring_damper_rests_at_its_static_deflection():
    """A 2 kg block hanging on a vertical slider with a 500 N/m spring and 20 N s/m damper:
    it settles at the static deflection m g / k below the rest position."""
    b = ps.ModelBuilder(dt=1e-2)
    blk = b.add_body("block", mass=2.0, inertia=0.1)
    b.add_slider("rail", None, blk, axis=(0.0, -1.0), stiffness=500.0, damping=20.0)
    model = b.compile()
    sim = ps.Simulator(model)
    sim.run(5.0)
    s, rate = measure.pin_angle_rate(model, sim.state.q, sim.state.v, "rail")
    assert s == pytest.approx(2.0 * 9.81 / 500.0, rel=1e-9)
    assert abs(rate) < 1e-9


def test_springy_armature_leg_on_the_ground_breaks_no_rule():
    """A box with a leg on a hinge with spring, damper and armature, thrown sideways onto the
    ground with friction 0.3 (its corners slide, then stick): the soft row enters the solves
    with sliding contacts (the equations checked row by row, the compliance included) and the
    complementarity solve; no audit rule breaks, the joints stay closed, and the mechanical
    energy (the rotor's counted) never rises by more than rounding."""
    b = ps.ModelBuilder(dt=2e-3)
    box = b.add_body("box", mass=3.0, inertia=0.05, pos=(0.0, 0.4), vel=(2.0, 0.0), omega=1.0,
                     shapes=[("box", (0.0, 0.0), 0.3, 0.2, 0.0, {"mu": 0.3})])
    leg = b.add_body("leg", mass=0.5, inertia=0.01, pos=(0.0, 0.2),
                     shapes=[("capsule", (0.0, -0.1), (0.0, 0.1), 0.02, {"mu": 0.3})])
    b.add_pin("hip", box, leg, anchor_world=(0.0, 0.3), stiffness=40.0, damping=0.5,
              armature=0.02, limit=(-0.8, 0.8))
    model = b.compile()
    sim = ps.Simulator(model)
    traj = sim.run(3.0, record_every=1)
    assert sim.ws.audit.sum() == 0
    E = total_energy(model, traj.q, traj.v)
    assert np.all(np.isfinite(E))
    assert np.max(np.diff(E)) <= 1e-9 * E[0]
    assert E[-1] < E[0]
    assert (np.asarray(traj.contact_mode) == 2).any()      # some corner slid
    # the rest: on the ground, still
    assert np.max(np.abs(traj.v[-1])) < 1e-6


@pytest.mark.parametrize("where", ["world", "link"])
def test_a_hinge_spring_the_step_resolves_is_a_force_about_the_pin(where):
    """A 1 m rod pinned at its end, with an undamped hinge spring of 1e5 N m/rad: about the
    pin (I + m d^2 = 1/3 kg m^2) it turns at h w = 0.55 a step at dt 1e-3, which symplectic
    Euler resolves (an explicit force, energy oscillating without drift). Judged by the rod's
    inertia about its centre (1/12: h w = 1.1) it was taken implicitly and its energy damped
    to 1e-28 of itself in 5 s. A hinge between two links keeps 1 / I_a + 1 / I_b (an upper
    bound that does not depend on the pose)."""
    b = ps.ModelBuilder(dt=1e-3, ground=None, gravity=(0, 0))
    rod = b.add_body("rod", mass=1.0, inertia=1 / 12, pos=(0.5, 0), omega=1.0, vel=(0, 0.5))
    if where == "world":
        b.add_pin("hinge", None, rod, anchor_world=(0, 0), stiffness=1e5)
    else:
        base = b.add_body("base", mass=1e9, inertia=1e9, pos=(-0.5, 0))
        b.add_pin("hinge", base, rod, anchor_world=(0, 0), stiffness=1e5)
    m = b.compile()
    sim = ps.Simulator(m)
    start = total_energy(m, sim.state.q, sim.state.v)
    energies = []
    for _ in range(100):
        sim.steps(50)
        energies.append(total_energy(m, sim.state.q, sim.state.v))
    if where == "world":
        # an oscillation about the start's energy, no decay: the last second's mean within
        # a few percent of the first's (symplectic Euler's O(h w) wobble, here 0.55)
        assert min(energies) > 0.5 * start, min(energies)
        assert abs(np.mean(energies[-20:]) - np.mean(energies[:20])) < 0.05 * start
    else:
        # 1 / I_rod = 12 puts it beyond the bound: implicit, damped (as before); no blow-up
        assert max(energies) <= start * (1 + 1e-9)
